/* lib/meshio/mesh_io_obj.c — Wavefront OBJ: reading v and f statements, writing.
 *
 * Only geometry matters to this project: `v x y z [w | r g b]` and
 * `f` with corners `a`, `a/b`, `a//c`, `a/b/c` (1-based, or negative =
 * relative to the vertices defined so far). Texture, normal, grouping and
 * material statements (vt vn vp g o s usemtl mtllib l p) are skipped; other
 * statements are skipped with one warning. A backslash at the end of a line
 * joins the next line (OBJ spec, "Wavefront Advanced Visualizer" appendix B).
 * Polygons are fan-triangulated from their first corner, (c0, ci, ci+1),
 * with one warning per file. Forward references (an index above the count
 * read so far) are allowed and checked against the file's final count.
 *
 * The parser is one pass over the bytes with no per-line copies; this is the
 * hot path when a study ingests thousands of meshes (target: >= 150 MB/s).
 */
#include "meshio/meshio_pkg.h"

#include <inttypes.h>
#include <math.h>

typedef struct objp {
    es_ctx *ctx;
    const char *name;
    const char *p, *end;
    int64_t line;
    es__mdbuild b;
    int64_t fwd_max, fwd_line;   /* largest forward reference and its line */
    int64_t npoly, poly_line;
    int64_t nunknown, unknown_line;
} objp;

/* Spaces within a line, and backslash-newline continuations. */
static inline void skip_ws(objp *P)
{
    const char *p = P->p, *end = P->end;
    while (p < end) {
        char c = *p;
        if (c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f') {
            p++;
        } else if (c == '\\' && p + 1 < end && p[1] == '\n') {
            p += 2;
            P->line++;
        } else if (c == '\\' && p + 2 < end && p[1] == '\r' && p[2] == '\n') {
            p += 3;
            P->line++;
        } else {
            break;
        }
    }
    P->p = p;
}

static inline bool at_eol(const objp *P)
{
    return P->p >= P->end || *P->p == '\n' || *P->p == '#';
}

/* To the start of the next line, through continuations. */
static void skip_line(objp *P)
{
    const char *p = P->p, *end = P->end;
    while (p < end && *p != '\n') {
        if (*p == '\\' && p + 1 < end && p[1] == '\n') {
            P->line++;
            p++;
        }
        p++;
    }
    if (p < end) {
        p++;
        P->line++;
    }
    P->p = p;
}

/* The token at p, quoted for a message (at most 40 bytes). */
static const char *token(const objp *P, char *buf, size_t n)
{
    size_t k = 0;
    const char *p = P->p;
    while (p + k < P->end && k + 1 < n && k < 40 && p[k] != ' ' && p[k] != '\t' &&
           p[k] != '\n' && p[k] != '\r')
        k++;
    memcpy(buf, p, k);
    buf[k] = '\0';
    return buf;
}

static es_status vertex(objp *P)
{
    double v[3];
    char tok[48];
    for (int k = 0; k < 3; k++) {
        const char *q;
        skip_ws(P);
        if (at_eol(P))
            ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": vertex has %d coordinates, need 3",
                    P->name, P->line, k);
        q = es__parse_double(P->p, P->end, &v[k]);
        if (!q)
            ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": bad number '%s' in vertex", P->name,
                    P->line, token(P, tok, sizeof tok));
        if (!isfinite(v[k]))
            ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": non-finite coordinate '%s' (NaN or "
                    "inf)", P->name, P->line, token(P, tok, sizeof tok));
        P->p = q;
    }
    /* w or per-vertex colours may follow; geometry does not need them */
    skip_line(P);
    return es__mdbuild_vertex(&P->b, v[0], v[1], v[2]);
}

/* An optional texture/normal index after '/' (value ignored). */
static inline bool skip_opt_index(objp *P)
{
    int64_t dummy;
    const char *q;
    if (P->p < P->end && (*P->p == '-' || *P->p == '+' || (unsigned)(*P->p - '0') < 10)) {
        if (!(q = es__parse_int64(P->p, P->end, &dummy))) return false;
        P->p = q;
    }
    return true;
}

static es_status face(objp *P)
{
    int64_t n = 0, c0 = 0, prev = 0, idx, r, line0 = P->line;
    const int64_t nv = P->b.md->nverts;
    char tok[48];
    for (;;) {
        const char *q, *start;
        skip_ws(P);
        if (at_eol(P)) break;
        start = P->p;
        q = es__parse_int64(P->p, P->end, &idx);
        if (!q)
            ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": bad vertex index '%s' in face",
                    P->name, P->line, token(P, tok, sizeof tok));
        P->p = q;
        if (P->p < P->end && *P->p == '/') {
            P->p++;
            if (!skip_opt_index(P)) goto bad_corner;
            if (P->p < P->end && *P->p == '/') {
                P->p++;
                if (!skip_opt_index(P)) goto bad_corner;
            }
        }
        if (P->p < P->end && !es__is_delim(*P->p)) goto bad_corner;
        if (idx == 0)
            ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": vertex index 0 in face (OBJ indices "
                    "start at 1)", P->name, P->line);
        if (idx < 0) {
            r = nv + idx;
            if (r < 0)
                ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": relative vertex index %" PRId64
                        " out of range (%" PRId64 " vertices so far)", P->name, P->line, idx,
                        nv);
        } else {
            r = idx - 1;
            if (r >= nv && idx > P->fwd_max) {
                P->fwd_max = idx;
                P->fwd_line = P->line;
            }
        }
        if (n == 0) {
            c0 = r;
        } else if (n >= 2) {
            es_status rc = es__mdbuild_face(&P->b, c0, prev, r);
            if (rc != ES_OK) return rc;
        }
        prev = r;
        n++;
        continue;
    bad_corner:
        P->p = start;
        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": bad face corner '%s' (want a, a/b, a//c "
                "or a/b/c)", P->name, P->line, token(P, tok, sizeof tok));
    }
    if (n < 3)
        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": face has %" PRId64 " corner%s, need at "
                "least 3", P->name, line0, n, n == 1 ? "" : "s");
    if (n > 3 && P->npoly++ == 0) P->poly_line = line0;
    skip_line(P);
    return ES_OK;
}

static bool is_ignored(const char *kw, size_t n)
{
    static const char *const known[] = {
        "vt", "vn", "vp", "g", "o", "s", "usemtl", "mtllib", "l", "p",
        /* free-form geometry and its attributes: not meshes, skipped */
        "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
        "scrv", "sp", "end", "con", "mg", "bevel", "c_interp", "d_interp", "lod",
        "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap"};
    for (size_t i = 0; i < sizeof known / sizeof *known; i++)
        if (strlen(known[i]) == n && !memcmp(known[i], kw, n)) return true;
    return false;
}

es_status es__obj_parse(es_ctx *ctx, const char *name, const char *buf, size_t len,
                        es_meshdata *md)
{
    objp P = {0};
    es_status rc = ES_OK;
    P.ctx = ctx;
    P.name = name;
    P.p = buf;
    P.end = buf + len;
    P.line = 1;
    es__mdbuild_init(&P.b, ctx, md);
    /* Size the arrays from a count of the lines that start with "v " and
     * "f " (a memchr pass costs a few percent of the parse): no growth and
     * no shrink copies, and each page of the result is touched once, which
     * matters where fresh pages are expensive (virtual machines). */
    {
        int64_t nv = 0, nf = 0;
        const char *p = buf, *end = buf + len;
        while (p < end) {
            const char *nl;
            if (end - p > 1 && (p[1] == ' ' || p[1] == '\t')) {
                nv += p[0] == 'v';
                nf += p[0] == 'f';
            }
            nl = memchr(p, '\n', (size_t)(end - p));
            p = nl ? nl + 1 : end;
        }
        if ((rc = es__mdbuild_reserve_verts(&P.b, nv + 1)) != ES_OK ||
            (rc = es__mdbuild_reserve_faces(&P.b, nf + 1)) != ES_OK)
            return rc;
    }

    while (P.p < P.end) {
        skip_ws(&P);
        if (P.p >= P.end) break;
        char c = *P.p;
        if (c == '\n') {
            P.p++;
            P.line++;
            continue;
        }
        if (c == '#') {
            while (P.p < P.end && *P.p != '\n') P.p++;
            continue;
        }
        const char *kw = P.p;
        while (P.p < P.end && *P.p != ' ' && *P.p != '\t' && *P.p != '\n' && *P.p != '\r' &&
               *P.p != '\\')
            P.p++;
        size_t n = (size_t)(P.p - kw);
        if (n == 1 && c == 'v') {
            rc = vertex(&P);
        } else if (n == 1 && c == 'f') {
            rc = face(&P);
        } else {
            if (!is_ignored(kw, n) && P.nunknown++ == 0) P.unknown_line = P.line;
            skip_line(&P);
        }
        if (rc != ES_OK) return rc;
    }
    if (P.fwd_max > md->nverts)
        ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": vertex index %" PRId64 " out of range (the "
                "file has %" PRId64 " vertices)", name, P.fwd_line, P.fwd_max, md->nverts);
    md->n_polygons_split = P.npoly;
    if (P.npoly)
        es__warn(ctx, "%s: %" PRId64 " polygon%s with more than 3 corners fan-triangulated "
                 "from the first corner (first at line %" PRId64 ")", name, P.npoly,
                 P.npoly == 1 ? "" : "s", P.poly_line);
    if (P.nunknown)
        es__warn(ctx, "%s: %" PRId64 " unknown statement%s skipped (first at line %" PRId64
                 ")", name, P.nunknown, P.nunknown == 1 ? "" : "s", P.unknown_line);
    es__mdbuild_finish(&P.b);
    return ES_OK;
}

/* ---------------------------------------------------------------- writer */

es_status es__obj_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts,
                        int64_t nfaces, const int64_t *faces, const double *xyz)
{
    (void)ctx;
    (void)path;
    fprintf(f, "# edgespace %s\n", es_version());
    for (int64_t i = 0; i < nverts; i++)
        fprintf(f, "v %.17g %.17g %.17g\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    for (int64_t i = 0; i < nfaces; i++)
        fprintf(f, "f %" PRId64 " %" PRId64 " %" PRId64 "\n", faces[3 * i] + 1,
                faces[3 * i + 1] + 1, faces[3 * i + 2] + 1);
    return ES_OK;
}
