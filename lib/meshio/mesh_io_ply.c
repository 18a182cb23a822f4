/* lib/meshio/mesh_io_ply.c — Stanford PLY: ascii, binary little and big endian.
 *
 * The header may declare any elements with any properties (Turk 1994, "The
 * PLY polygon file format"); bodies are walked element by element and what
 * is not geometry is skipped by its declared size, so binary files with
 * normals, colours, edges or materials read correctly. Geometry is the
 * `vertex` element's x, y, z (any numeric type) and the `face` element's
 * list `vertex_indices` (or `vertex_index`) with any integer count and index
 * types; polygons are fan-triangulated from the first corner. Counts in the
 * header are checked against the bytes that follow before anything is
 * allocated, so a lying header fails as truncated instead of exhausting
 * memory. Messages name the header line, the body line (ascii) or the byte
 * offset and element index (binary).
 *
 * The writer emits double x, y, z (exact round trip), optional uchar
 * red/green/blue, and `list uchar int vertex_indices`.
 */
#include "meshio/meshio_pkg.h"

#include <inttypes.h>
#include <math.h>

enum ptype { T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };
static const int type_size[] = {1, 1, 2, 2, 4, 4, 4, 8};
static const struct { const char *name; enum ptype t; } type_names[] = {
    {"char", T_I8}, {"int8", T_I8}, {"uchar", T_U8}, {"uint8", T_U8},
    {"short", T_I16}, {"int16", T_I16}, {"ushort", T_U16}, {"uint16", T_U16},
    {"int", T_I32}, {"int32", T_I32}, {"uint", T_U32}, {"uint32", T_U32},
    {"float", T_F32}, {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};

enum role { R_SKIP, R_X, R_Y, R_Z, R_FACE };

#define MAX_ELEMS 32
#define MAX_PROPS 64
#define MAX_NAME 64

typedef struct prop {
    enum ptype type, count_type;
    bool is_list;
    enum role role;
} prop;

typedef struct elem {
    char name[MAX_NAME];
    int64_t count;
    int nprops;
    prop props[MAX_PROPS];
} elem;

enum fmt { F_ASCII, F_LE, F_BE };

typedef struct plyp {
    es_ctx *ctx;
    const char *name;
    const char *buf, *end, *p;
    int64_t line;
    enum fmt fmt;
    int nelems;
    elem *elems;
    int vertex_elem, face_elem;
    int64_t nverts_decl;
    es__mdbuild b;
    int64_t npoly, poly_elem;
} plyp;

/* ---------------------------------------------------------------- header */

/* Next whitespace-separated word of the header line [p, eol). */
static bool word(const char **p, const char *eol, const char **w, size_t *n)
{
    const char *q = *p;
    while (q < eol && (*q == ' ' || *q == '\t' || *q == '\r')) q++;
    if (q >= eol) return false;
    *w = q;
    while (q < eol && *q != ' ' && *q != '\t' && *q != '\r') q++;
    *n = (size_t)(q - *w);
    *p = q;
    return true;
}

static bool word_is(const char *w, size_t n, const char *s)
{
    return strlen(s) == n && !memcmp(w, s, n);
}

static bool parse_type(const char *w, size_t n, enum ptype *t)
{
    for (size_t i = 0; i < sizeof type_names / sizeof *type_names; i++)
        if (word_is(w, n, type_names[i].name)) {
            *t = type_names[i].t;
            return true;
        }
    return false;
}

#define HFAIL(...) do { char m_[256]; snprintf(m_, sizeof m_, __VA_ARGS__); \
    ES_FAIL(P->ctx, ES_EFORMAT, "%s: header line %" PRId64 ": %s", P->name, P->line, m_); \
    } while (0)

static es_status header(plyp *P)
{
    const char *p = P->buf, *end = P->end;
    bool have_format = false;
    elem *cur = NULL;
    P->line = 1;
    P->vertex_elem = P->face_elem = -1;
    if (end - p < 4 || memcmp(p, "ply", 3) || (p[3] != '\n' && p[3] != '\r'))
        ES_FAIL(P->ctx, ES_EFORMAT, "%s: header line 1: not a PLY file (first line is not "
                "'ply')", P->name);
    for (;;) {
        const char *eol = memchr(p, '\n', (size_t)(end - p)), *w, *q;
        size_t n;
        if (!eol)
            ES_FAIL(P->ctx, ES_EFORMAT, "%s: header line %" PRId64 ": file ends inside the "
                    "header (no end_header)", P->name, P->line);
        q = p;
        if (P->line == 1 || !word(&q, eol, &w, &n)) {
            /* "ply" itself, or a blank line */
        } else if (word_is(w, n, "comment") || word_is(w, n, "obj_info")) {
        } else if (word_is(w, n, "format")) {
            if (!word(&q, eol, &w, &n)) HFAIL("format line without a format");
            if (word_is(w, n, "ascii")) P->fmt = F_ASCII;
            else if (word_is(w, n, "binary_little_endian")) P->fmt = F_LE;
            else if (word_is(w, n, "binary_big_endian")) P->fmt = F_BE;
            else HFAIL("unknown format '%.*s'", (int)(n > 40 ? 40 : n), w);
            if (!word(&q, eol, &w, &n) || !word_is(w, n, "1.0"))
                HFAIL("format version must be 1.0");
            have_format = true;
        } else if (word_is(w, n, "element")) {
            const char *nm;
            size_t nn;
            int64_t count;
            if (P->nelems == MAX_ELEMS) HFAIL("more than %d elements", MAX_ELEMS);
            {
                elem *ne = es__realloc(P->ctx, P->elems, (size_t)(P->nelems + 1) * sizeof *ne);
                if (!ne) return ES_ENOMEM;
                P->elems = ne;
            }
            if (!word(&q, eol, &nm, &nn)) HFAIL("element without a name");
            if (!word(&q, eol, &w, &n) || es__parse_int64(w, w + n, &count) != w + n ||
                count < 0)
                HFAIL("element '%.*s' needs a count >= 0", (int)(nn > 40 ? 40 : nn), nm);
            cur = &P->elems[P->nelems];
            memset(cur, 0, sizeof *cur);
            snprintf(cur->name, sizeof cur->name, "%.*s", (int)(nn >= MAX_NAME ? MAX_NAME - 1 : nn),
                     nm);
            cur->count = count;
            if (!strcmp(cur->name, "vertex")) {
                if (P->vertex_elem >= 0) HFAIL("a second vertex element");
                P->vertex_elem = P->nelems;
                P->nverts_decl = count;
            } else if (!strcmp(cur->name, "face")) {
                if (P->face_elem >= 0) HFAIL("a second face element");
                P->face_elem = P->nelems;
            }
            P->nelems++;
        } else if (word_is(w, n, "property")) {
            prop pr = {0};
            if (!cur) HFAIL("property before any element");
            if (cur->nprops == MAX_PROPS) HFAIL("more than %d properties", MAX_PROPS);
            if (!word(&q, eol, &w, &n)) HFAIL("property without a type");
            if (word_is(w, n, "list")) {
                pr.is_list = true;
                if (!word(&q, eol, &w, &n) || !parse_type(w, n, &pr.count_type))
                    HFAIL("list property needs a count type");
                if (pr.count_type >= T_F32) HFAIL("list count type must be an integer type");
                if (!word(&q, eol, &w, &n)) HFAIL("list property without an item type");
            }
            if (!parse_type(w, n, &pr.type))
                HFAIL("unknown property type '%.*s'", (int)(n > 40 ? 40 : n), w);
            if (!word(&q, eol, &w, &n)) HFAIL("property without a name");
            if (P->nelems - 1 == P->vertex_elem && !pr.is_list) {
                if (word_is(w, n, "x")) pr.role = R_X;
                else if (word_is(w, n, "y")) pr.role = R_Y;
                else if (word_is(w, n, "z")) pr.role = R_Z;
            }
            if (P->nelems - 1 == P->face_elem &&
                (word_is(w, n, "vertex_indices") || word_is(w, n, "vertex_index"))) {
                if (!pr.is_list) HFAIL("face property '%.*s' must be a list", (int)n, w);
                if (pr.type >= T_F32) HFAIL("face vertex indices must have an integer type");
                pr.role = R_FACE;
            }
            for (int i = 0; pr.role != R_SKIP && i < cur->nprops; i++)
                if (cur->props[i].role == pr.role)
                    HFAIL("property '%.*s' declared twice", (int)n, w);
            cur->props[cur->nprops++] = pr;
        } else if (word_is(w, n, "end_header")) {
            p = eol + 1;
            P->line++;
            break;
        } else {
            HFAIL("unknown header keyword '%.*s'", (int)(n > 40 ? 40 : n), w);
        }
        p = eol + 1;
        P->line++;
    }
    if (!have_format) HFAIL("no format line before end_header");
    if (P->vertex_elem < 0) HFAIL("no vertex element");
    {
        int have[4] = {0};
        elem *v = &P->elems[P->vertex_elem];
        for (int i = 0; i < v->nprops; i++) have[v->props[i].role] = 1;
        if (!have[R_X] || !have[R_Y] || !have[R_Z])
            HFAIL("vertex element lacks scalar property '%s'",
                  !have[R_X] ? "x" : !have[R_Y] ? "y" : "z");
    }
    if (P->face_elem >= 0) {
        bool have = false;
        elem *f = &P->elems[P->face_elem];
        for (int i = 0; i < f->nprops; i++) have = have || f->props[i].role == R_FACE;
        if (!have) HFAIL("face element has no list 'vertex_indices' or 'vertex_index'");
    }
    P->p = p;
    return ES_OK;
}

/* ---------------------------------------------------------------- faces */

/* One corner of the face being read; fan-triangulates as corners arrive. */
typedef struct fan { int64_t n, c0, prev; } fan;

static inline es_status fan_add(plyp *P, fan *fn, int64_t v)
{
    if (fn->n == 0) fn->c0 = v;
    else if (fn->n >= 2) {
        es_status rc = es__mdbuild_face(&P->b, fn->c0, fn->prev, v);
        if (rc != ES_OK) return rc;
    }
    fn->prev = v;
    fn->n++;
    return ES_OK;
}

/* ---------------------------------------------------------------- binary */

static inline uint64_t load_bits(const unsigned char *p, int size, bool big)
{
    uint64_t v = 0;
    if (big) for (int i = 0; i < size; i++) v = (v << 8) | p[i];
    else for (int i = size - 1; i >= 0; i--) v = (v << 8) | p[i];
    return v;
}

static inline double load_double(const unsigned char *p, enum ptype t, bool big)
{
    uint64_t v = load_bits(p, type_size[t], big);
    switch (t) {
    case T_I8: return (double)(int8_t)v;
    case T_U8: return (double)(uint8_t)v;
    case T_I16: return (double)(int16_t)v;
    case T_U16: return (double)(uint16_t)v;
    case T_I32: return (double)(int32_t)v;
    case T_U32: return (double)(uint32_t)v;
    case T_F32: {
        uint32_t u = (uint32_t)v;
        float f;
        memcpy(&f, &u, 4);
        return f;
    }
    case T_F64: {
        double d;
        memcpy(&d, &v, 8);
        return d;
    }
    }
    return 0;
}

static inline int64_t load_int(const unsigned char *p, enum ptype t, bool big)
{
    uint64_t v = load_bits(p, type_size[t], big);
    switch (t) {
    case T_I8: return (int8_t)v;
    case T_I16: return (int16_t)v;
    case T_I32: return (int32_t)v;
    default: return (int64_t)v;   /* unsigned types; floats are refused in the header */
    }
}

static es_status truncated(plyp *P, const elem *e, int64_t i, size_t off)
{
    ES_FAIL(P->ctx, ES_EFORMAT, "%s: byte offset %zu: file truncated in element '%s' %" PRId64
            " of %" PRId64, P->name, off, e->name, i, e->count);
}

static es_status body_binary(plyp *P)
{
    const unsigned char *base = (const unsigned char *)P->buf;
    const unsigned char *p = (const unsigned char *)P->p, *end = (const unsigned char *)P->end;
    const bool big = P->fmt == F_BE;
    es_status rc;
    for (int ei = 0; ei < P->nelems; ei++) {
        const elem *e = &P->elems[ei];
        int64_t minsize = 0;
        if (e->nprops == 0) continue;   /* nothing to read, however many */
        for (int k = 0; k < e->nprops; k++)
            minsize += e->props[k].is_list ? type_size[e->props[k].count_type]
                                           : type_size[e->props[k].type];
        /* a header that claims more than the body holds fails here, before
         * any allocation sized by it */
        if (minsize > 0 && e->count > (end - p) / minsize)
            return truncated(P, e, (end - p) / minsize, (size_t)(end - base));
        if (ei == P->vertex_elem && (rc = es__mdbuild_reserve_verts(&P->b, e->count)) != ES_OK)
            return rc;
        if (ei == P->face_elem && (rc = es__mdbuild_reserve_faces(&P->b, e->count)) != ES_OK)
            return rc;
        for (int64_t i = 0; i < e->count; i++) {
            double xyz[3] = {0, 0, 0};
            const unsigned char *start = p;
            for (int k = 0; k < e->nprops; k++) {
                const prop *pr = &e->props[k];
                if (!pr->is_list) {
                    int sz = type_size[pr->type];
                    if (end - p < sz) return truncated(P, e, i, (size_t)(end - base));
                    if (pr->role >= R_X && pr->role <= R_Z)
                        xyz[pr->role - R_X] = load_double(p, pr->type, big);
                    p += sz;
                    continue;
                }
                int csz = type_size[pr->count_type], isz = type_size[pr->type];
                if (end - p < csz) return truncated(P, e, i, (size_t)(end - base));
                int64_t cnt = load_int(p, pr->count_type, big);
                size_t off = (size_t)(p - base);
                p += csz;
                if (cnt < 0)
                    ES_FAIL(P->ctx, ES_EFORMAT, "%s: byte offset %zu: element '%s' %" PRId64
                            ": negative list count %" PRId64, P->name, off, e->name, i, cnt);
                if (cnt > (end - p) / isz) return truncated(P, e, i, (size_t)(end - base));
                if (pr->role != R_FACE) {
                    p += cnt * isz;
                    continue;
                }
                if (cnt < 3)
                    ES_FAIL(P->ctx, ES_EFORMAT, "%s: byte offset %zu: face %" PRId64 " has %"
                            PRId64 " corners, need at least 3", P->name, off, i, cnt);
                if (cnt > 3 && P->npoly++ == 0) P->poly_elem = i;
                fan fn = {0, 0, 0};
                for (int64_t c = 0; c < cnt; c++, p += isz) {
                    int64_t v = load_int(p, pr->type, big);
                    if (v < 0 || v >= P->nverts_decl)
                        ES_FAIL(P->ctx, ES_EFORMAT, "%s: byte offset %zu: face %" PRId64
                                ": vertex index %" PRId64 " out of range (%" PRId64
                                " vertices)", P->name, (size_t)(p - base), i, v,
                                P->nverts_decl);
                    if ((rc = fan_add(P, &fn, v)) != ES_OK) return rc;
                }
            }
            if (ei == P->vertex_elem) {
                for (int k = 0; k < 3; k++)
                    if (!isfinite(xyz[k]))
                        ES_FAIL(P->ctx, ES_EFORMAT, "%s: byte offset %zu: vertex %" PRId64
                                " has a non-finite coordinate (NaN or inf)", P->name,
                                (size_t)(start - base), i);
                if ((rc = es__mdbuild_vertex(&P->b, xyz[0], xyz[1], xyz[2])) != ES_OK)
                    return rc;
            }
        }
    }
    return ES_OK;
}

/* ---------------------------------------------------------------- ascii */

/* Next token of the body, across lines; false at the end of the file. */
static bool next_token(plyp *P, const char **w)
{
    const char *p = P->p, *end = P->end;
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')) {
        if (*p == '\n') P->line++;
        p++;
    }
    P->p = p;
    *w = p;
    return p < end;
}

static es_status ascii_value(plyp *P, const elem *e, int64_t i, bool want_int, double *d,
                             int64_t *n)
{
    const char *w, *q;
    double dummy;
    if (!next_token(P, &w))
        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": file truncated in element '%s' %" PRId64
                " of %" PRId64, P->name, P->line, e->name, i, e->count);
    q = want_int ? es__parse_int64(w, P->end, n) : es__parse_double(w, P->end, d ? d : &dummy);
    if (!q || (q < P->end && *q != ' ' && *q != '\t' && *q != '\r' && *q != '\n')) {
        size_t k = 0;
        while (w + k < P->end && k < 40 && w[k] != ' ' && w[k] != '\t' && w[k] != '\r' &&
               w[k] != '\n')
            k++;
        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": bad %s '%.*s' in element '%s' %" PRId64,
                P->name, P->line, want_int ? "integer" : "number", (int)(k ? k : 1), w,
                e->name, i);
    }
    P->p = q;
    return ES_OK;
}

static es_status body_ascii(plyp *P)
{
    es_status rc;
    const char *w;
    for (int ei = 0; ei < P->nelems; ei++) {
        const elem *e = &P->elems[ei];
        if (e->nprops == 0) continue;
        /* every value takes at least two bytes (digit and separator) */
        if (e->nprops > 0 && e->count > (P->end - P->p) / (2 * e->nprops))
            ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": file truncated: element '%s' "
                    "declares %" PRId64 " items, more than the rest of the file holds",
                    P->name, P->line, e->name, e->count);
        if (ei == P->vertex_elem && (rc = es__mdbuild_reserve_verts(&P->b, e->count)) != ES_OK)
            return rc;
        if (ei == P->face_elem && (rc = es__mdbuild_reserve_faces(&P->b, e->count)) != ES_OK)
            return rc;
        for (int64_t i = 0; i < e->count; i++) {
            double xyz[3] = {0, 0, 0};
            for (int k = 0; k < e->nprops; k++) {
                const prop *pr = &e->props[k];
                int64_t cnt;
                if (!pr->is_list) {
                    double *dst = pr->role >= R_X && pr->role <= R_Z ? &xyz[pr->role - R_X]
                                                                     : NULL;
                    if ((rc = ascii_value(P, e, i, false, dst, NULL)) != ES_OK) return rc;
                    if (dst && !isfinite(*dst))
                        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": vertex %" PRId64
                                " has a non-finite coordinate (NaN or inf)", P->name, P->line,
                                i);
                    continue;
                }
                if ((rc = ascii_value(P, e, i, true, NULL, &cnt)) != ES_OK) return rc;
                if (cnt < 0)
                    ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": element '%s' %" PRId64
                            ": negative list count %" PRId64, P->name, P->line, e->name, i,
                            cnt);
                if (pr->role == R_FACE && cnt < 3)
                    ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": face %" PRId64 " has %"
                            PRId64 " corners, need at least 3", P->name, P->line, i, cnt);
                if (pr->role == R_FACE && cnt > 3 && P->npoly++ == 0) P->poly_elem = i;
                fan fn = {0, 0, 0};
                for (int64_t c = 0; c < cnt; c++) {
                    int64_t v = 0;
                    if (pr->type >= T_F32) {
                        rc = ascii_value(P, e, i, false, NULL, NULL);
                    } else {
                        rc = ascii_value(P, e, i, true, NULL, &v);
                    }
                    if (rc != ES_OK) return rc;
                    if (pr->role != R_FACE) continue;
                    if (v < 0 || v >= P->nverts_decl)
                        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": face %" PRId64
                                ": vertex index %" PRId64 " out of range (%" PRId64
                                " vertices)", P->name, P->line, i, v, P->nverts_decl);
                    if ((rc = fan_add(P, &fn, v)) != ES_OK) return rc;
                }
            }
            if (ei == P->vertex_elem) {
                if ((rc = es__mdbuild_vertex(&P->b, xyz[0], xyz[1], xyz[2])) != ES_OK)
                    return rc;
            }
        }
    }
    /* more values than the header declares (a face or vertex count that is
     * too small) would otherwise be dropped without a word */
    if (next_token(P, &w))
        ES_FAIL(P->ctx, ES_EFORMAT, "%s:%" PRId64 ": unexpected data after the last element "
                "(the header's counts are too small?)", P->name, P->line);
    return ES_OK;
}

es_status es__ply_parse(es_ctx *ctx, const char *name, const char *buf, size_t len,
                        es_meshdata *md)
{
    plyp P;
    es_status rc;
    memset(&P, 0, sizeof P);
    P.ctx = ctx;
    P.name = name;
    P.buf = P.p = buf;
    P.end = buf + len;
    es__mdbuild_init(&P.b, ctx, md);
    if ((rc = header(&P)) == ES_OK)
        rc = P.fmt == F_ASCII ? body_ascii(&P) : body_binary(&P);
    es__free(ctx, P.elems);
    if (rc != ES_OK) return rc;
    md->n_polygons_split = P.npoly;
    if (P.npoly)
        es__warn(ctx, "%s: %" PRId64 " polygon%s with more than 3 corners fan-triangulated "
                 "from the first corner (first is face %" PRId64 ")", name, P.npoly,
                 P.npoly == 1 ? "" : "s", P.poly_elem);
    es__mdbuild_finish(&P.b);
    return ES_OK;
}

/* ---------------------------------------------------------------- writer */

static void put_le(FILE *f, uint64_t v, int size)
{
    unsigned char b[8];
    for (int i = 0; i < size; i++) b[i] = (unsigned char)(v >> (8 * i));
    fwrite(b, 1, (size_t)size, f);
}

es_status es__ply_write(es_ctx *ctx, const char *path, FILE *f, bool binary,
                        int64_t nverts, int64_t nfaces, const int64_t *faces,
                        const double *xyz, const uint8_t *rgb)
{
    if (nverts > INT32_MAX)
        ES_FAIL(ctx, ES_ERANGE, "'%s': %" PRId64 " vertices exceed PLY's int indices", path,
                nverts);
    fprintf(f, "ply\nformat %s 1.0\ncomment edgespace %s\nelement vertex %" PRId64 "\n"
            "property double x\nproperty double y\nproperty double z\n",
            binary ? "binary_little_endian" : "ascii", es_version(), nverts);
    if (rgb) fputs("property uchar red\nproperty uchar green\nproperty uchar blue\n", f);
    fprintf(f, "element face %" PRId64 "\nproperty list uchar int vertex_indices\n"
            "end_header\n", nfaces);
    for (int64_t i = 0; i < nverts; i++) {
        if (binary) {
            for (int k = 0; k < 3; k++) {
                uint64_t u;
                memcpy(&u, &xyz[3 * i + k], 8);
                put_le(f, u, 8);
            }
            if (rgb) fwrite(rgb + 3 * i, 1, 3, f);
        } else {
            fprintf(f, "%.17g %.17g %.17g", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
            if (rgb) fprintf(f, " %u %u %u", rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
            fputc('\n', f);
        }
    }
    for (int64_t i = 0; i < nfaces; i++) {
        const int64_t *t = faces + 3 * i;
        if (binary) {
            fputc(3, f);
            for (int k = 0; k < 3; k++) put_le(f, (uint64_t)(uint32_t)t[k], 4);
        } else {
            fprintf(f, "3 %" PRId64 " %" PRId64 " %" PRId64 "\n", t[0], t[1], t[2]);
        }
    }
    return ES_OK;
}
