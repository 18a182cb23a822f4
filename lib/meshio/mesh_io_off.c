/* lib/meshio/mesh_io_off.c — Object File Format (OFF, Geomview): reading, writing.
 *
 * Accepted: an optional keyword line `OFF` (also `COFF`, `NOFF`, `CNOFF`,
 * `STOFF`, ... whose extra per-vertex values are ignored), with the counts
 * `nv nf [ne]` either on the same line or on the next one, or no keyword at
 * all (the file starts with the counts); `#` comments anywhere; blank
 * lines. Then nv vertex lines (x y z, extra values ignored) and nf face
 * lines `n i1 .. in` (0-based, trailing colour values ignored). Polygons are
 * fan-triangulated from the first corner. Geomview's `nOFF` (other
 * dimensions), `4OFF` and `OFF BINARY` are refused with a message. Line
 * based: each vertex and each face sits on its own line, as every writer we
 * know of produces.
 */
#include "meshio/meshio_pkg.h"

#include <inttypes.h>
#include <math.h>

typedef struct offp {
    es_ctx *ctx;
    const char *name;
    const char *p, *end;
    int64_t line;       /* line of p */
    const char *eol;    /* end of the current content line (comment stripped) */
} offp;

/* Move to the next line holding something other than blanks and a
 * comment; false at the end of the file. p is at its first token. */
static bool next_line(offp *P, bool first)
{
    if (!first) {
        const char *nl = memchr(P->p, '\n', (size_t)(P->end - P->p));
        if (!nl) {
            P->p = P->end;
            return false;
        }
        P->p = nl + 1;
        P->line++;
    }
    for (;;) {
        const char *p = P->p;
        while (p < P->end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\v' || *p == '\f'))
            p++;
        if (p >= P->end) {
            P->p = p;
            return false;
        }
        if (*p == '\n' || *p == '#') {
            const char *nl = memchr(p, '\n', (size_t)(P->end - p));
            if (!nl) {
                P->p = P->end;
                return false;
            }
            P->p = nl + 1;
            P->line++;
            continue;
        }
        P->p = p;
        P->eol = p;
        while (P->eol < P->end && *P->eol != '\n' && *P->eol != '#') P->eol++;
        return true;
    }
}

/* Next token within the current line; false at its end. */
static bool tok(offp *P, const char **w, size_t *n)
{
    const char *p = P->p;
    while (p < P->eol && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\v' || *p == '\f'))
        p++;
    P->p = p;
    if (p >= P->eol) return false;
    *w = p;
    while (p < P->eol && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\v' && *p != '\f') p++;
    *n = (size_t)(p - *w);
    return true;
}

static bool int_token(offp *P, int64_t *v, const char **w, size_t *n)
{
    if (!tok(P, w, n)) return false;
    if (es__parse_int64(*w, *w + *n, v) != *w + *n) return false;
    P->p = *w + *n;
    return true;
}

static es_status counts(offp *P, int64_t *nv, int64_t *nf)
{
    const char *w = P->p;
    size_t n = 0;
    int64_t ne;
    if (!int_token(P, nv, &w, &n) || !int_token(P, nf, &w, &n))
        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": bad counts line (want 'nv nf [ne]')",
                P->name, P->line);
    if (tok(P, &w, &n)) {
        if (!int_token(P, &ne, &w, &n) || tok(P, &w, &n))
            ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": bad counts line (want 'nv nf [ne]')",
                    P->name, P->line);
    }
    if (*nv < 0 || *nf < 0)
        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": negative vertex or face count", P->name,
                P->line);
    return ES_OK;
}

es_status es__off_parse(es_ctx *ctx, const char *name, const char *buf, size_t len,
                        es_meshdata *md)
{
    offp P = {ctx, name, buf, buf + len, 1, buf};
    es__mdbuild b;
    es_status rc;
    int64_t nv, nf, npoly = 0, poly_line = 0;
    const char *w = buf;
    size_t n = 0;

    es__mdbuild_init(&b, ctx, md);
    if (!next_line(&P, true)) ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": empty file", name, P.line);
    tok(&P, &w, &n);
    if (n >= 3 && !memcmp(w + n - 3, "OFF", 3)) {
        /* prefixes in Geomview's order: [ST][C][N][4][n]OFF */
        const char *q = w, *kend = w + n - 3;
        if (kend - q >= 2 && q[0] == 'S' && q[1] == 'T') q += 2;
        if (q < kend && *q == 'C') q++;
        if (q < kend && *q == 'N') q++;
        if (q < kend && (*q == '4' || *q == 'n'))
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": '%.*s': only 3-dimensional OFF is "
                    "supported", name, P.line, (int)n, w);
        if (q != kend)
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": unknown keyword '%.*s' (want OFF)", name,
                    P.line, (int)(n > 40 ? 40 : n), w);
        P.p = w + n;
        if (tok(&P, &w, &n) && n == 6 && !memcmp(w, "BINARY", 6))
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": binary OFF is not supported", name,
                    P.line);
        if (!tok(&P, &w, &n) && !next_line(&P, false))
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": file ends before the counts line", name,
                    P.line);
    } else if (!(n > 0 && ((unsigned)(w[0] - '0') < 10 || w[0] == '+'))) {
        ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": not an OFF file (starts with '%.*s')", name,
                P.line, (int)(n > 40 ? 40 : n), w);
    }
    if ((rc = counts(&P, &nv, &nf)) != ES_OK) return rc;
    /* each vertex line takes at least 6 bytes and each face line 8: a
     * count the file cannot hold reserves no more than the file could, and
     * fails as truncated when the lines run out */
    if ((rc = es__mdbuild_reserve_verts(&b, nv < (P.end - P.p) / 6 ? nv : (P.end - P.p) / 6)) !=
            ES_OK ||
        (rc = es__mdbuild_reserve_faces(&b, nf < (P.end - P.p) / 8 ? nf : (P.end - P.p) / 8)) !=
            ES_OK)
        return rc;

    for (int64_t i = 0; i < nv; i++) {
        double v[3];
        if (!next_line(&P, false))
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": file truncated: %" PRId64 " of %" PRId64
                    " vertices", name, P.line, i, nv);
        for (int k = 0; k < 3; k++) {
            const char *q;
            if (!tok(&P, &w, &n))
                ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": vertex %" PRId64 " has %d "
                        "coordinates, need 3", name, P.line, i, k);
            q = es__parse_double(w, w + n, &v[k]);
            if (q != w + n)
                ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": bad number '%.*s' in vertex %" PRId64,
                        name, P.line, (int)(n > 40 ? 40 : n), w, i);
            if (!isfinite(v[k]))
                ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": non-finite coordinate '%.*s' (NaN or "
                        "inf) in vertex %" PRId64, name, P.line, (int)(n > 40 ? 40 : n), w, i);
            P.p = q;
        }
        if ((rc = es__mdbuild_vertex(&b, v[0], v[1], v[2])) != ES_OK) return rc;
    }
    for (int64_t i = 0; i < nf; i++) {
        int64_t cnt, c0 = 0, prev = 0;
        if (!next_line(&P, false))
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": file truncated: %" PRId64 " of %" PRId64
                    " faces", name, P.line, i, nf);
        if (!int_token(&P, &cnt, &w, &n))
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": bad corner count '%.*s' in face %" PRId64,
                    name, P.line, (int)(n > 40 ? 40 : n), w, i);
        if (cnt < 3)
            ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": face %" PRId64 " has %" PRId64 " corners, "
                    "need at least 3", name, P.line, i, cnt);
        if (cnt > 3 && npoly++ == 0) poly_line = P.line;
        for (int64_t c = 0; c < cnt; c++) {
            int64_t v;
            if (!tok(&P, &w, &n))
                ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": face %" PRId64 " has %" PRId64
                        " of its %" PRId64 " indices", name, P.line, i, c, cnt);
            if (!int_token(&P, &v, &w, &n))
                ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": bad vertex index '%.*s' in face %"
                        PRId64, name, P.line, (int)(n > 40 ? 40 : n), w, i);
            if (v < 0 || v >= nv)
                ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": face %" PRId64 ": vertex index %"
                        PRId64 " out of range (%" PRId64 " vertices, 0-based)", name, P.line, i,
                        v, nv);
            if (c == 0) c0 = v;
            else if (c >= 2 && (rc = es__mdbuild_face(&b, c0, prev, v)) != ES_OK) return rc;
            prev = v;
        }
    }
    if (next_line(&P, false))
        ES_FAIL(ctx, ES_EFORMAT, "%s:%" PRId64 ": unexpected data after the last face", name,
                P.line);
    md->n_polygons_split = npoly;
    if (npoly)
        es__warn(ctx, "%s: %" PRId64 " polygon%s with more than 3 corners fan-triangulated "
                 "from the first corner (first at line %" PRId64 ")", name, npoly,
                 npoly == 1 ? "" : "s", poly_line);
    es__mdbuild_finish(&b);
    return ES_OK;
}

es_status es__off_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts,
                        int64_t nfaces, const int64_t *faces, const double *xyz)
{
    (void)ctx;
    (void)path;
    fprintf(f, "OFF\n# edgespace %s\n%" PRId64 " %" PRId64 " 0\n", es_version(), nverts, nfaces);
    for (int64_t i = 0; i < nverts; i++)
        fprintf(f, "%.17g %.17g %.17g\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    for (int64_t i = 0; i < nfaces; i++)
        fprintf(f, "3 %" PRId64 " %" PRId64 " %" PRId64 "\n", faces[3 * i], faces[3 * i + 1],
                faces[3 * i + 2]);
    return ES_OK;
}
