/* lib/ingest/landmarks.c — what the landmark readers share, and what works
 * on a landmark set once read: the specimen builder that the TPS reader
 * (landmarks_tps.c) and the long-CSV reader (landmarks_csv.c) fill,
 * freeing a set, label columns by name, truss lengths between landmark
 * pairs, and the edge and triangle lists (1-based landmark numbers) that
 * ingest-landmarks takes beside a set.
 */
#include "ingest/ingest_pkg.h"
#include "core/files.h"
#include "core/text.h"

#include <math.h>

void es__free_strings(es_ctx *ctx, char **s, int64_t n)
{
    if (!s) return;
    for (int64_t i = 0; i < n; i++) es__free(ctx, s[i]);
    es__free(ctx, s);
}

es_status es__lm_read_text(es_ctx *ctx, const char *path, char **buf, size_t *len)
{
    /* A UTF-8 byte order mark (Excel's "CSV UTF-8", Windows editors) is not
     * data: dropped, as the manifest and mesh readers do. */
    /* A NUL byte is refused naming its line: the line-by-line readers would
     * stop at it and silently drop the rest of the file. */
    es_status rc = es__read_file(ctx, path, ES__READ_REGULAR | ES__READ_DROP_BOM | ES__READ_TEXT,
                                 buf, len);
    return rc == ES_OK ? ES_OK : es__fail(ctx, rc, "landmarks: %s", es_ctx_errmsg(ctx));
}

void es_landmarks_free(es_landmarks *lm)
{
    if (!lm) return;
    es_ctx *ctx = lm->ctx;
    es__free(ctx, lm->xyz);
    es__free_strings(ctx, lm->ids, lm->n);
    es__free_strings(ctx, lm->images, lm->images ? lm->n : 0);
    es__free(ctx, lm->scale);
    es__free_strings(ctx, lm->colnames, lm->ncols);
    es__free_strings(ctx, lm->labels, lm->labels ? lm->n * lm->ncols : 0);
    es__free(ctx, lm);
}

int64_t es_landmarks_find_column(const es_landmarks *lm, const char *name)
{
    for (int64_t c = 0; lm && c < lm->ncols; c++)
        if (!strcmp(lm->colnames[c], name)) return c;
    return -1;
}

/* ---- the specimen builder --------------------------------------------------- */

/* Specimens the builder first makes room for; it doubles from there. */
enum { FIRST_CAP = 16 };

es_status es__lm_builder_add(es__lm_builder *b, int64_t k, int d, const char *file,
                             int64_t line)
{
    if (b->n == 0) {
        /* k comes from the file: check that the first FIRST_CAP specimens'
         * bytes fit int64, so that a huge count is named here rather than
         * wrapping into a tiny allocation */
        if (!es__mul_i64(k, d, &b->kd) ||
            b->kd > INT64_MAX / (FIRST_CAP * (int64_t)sizeof(double)))
            ES_FAIL(b->ctx, ES_ERANGE, "landmarks: %s: %lld landmarks in %dD are too many%s",
                    file, (long long)k, d,
                    line > 0 ? " (LM= count)" : " (largest landmark number)");
        b->k = k;
        b->d = d;
    } else if (k != b->k || d != b->d) {
        ES_FAIL(b->ctx, ES_EMISMATCH, "landmarks: %s:%lld: specimen %lld has %lld landmarks in "
                "%dD, the first had %lld in %dD", file, (long long)line, (long long)b->n + 1,
                (long long)k, d, (long long)b->k, b->d);
    }
    if (b->n == b->cap) {
        int64_t nc = b->cap ? 2 * b->cap : FIRST_CAP, bytes;
        if (b->limit > 0 && nc > b->limit) nc = b->limit > b->n ? b->limit : b->n + 1;
        if (!es__mul_i64(nc, b->kd, &bytes) || !es__mul_i64(bytes, (int64_t)sizeof(double), &bytes))
            ES_FAIL(b->ctx, ES_ERANGE, "landmarks: %s: %lld specimens of %lld landmarks in %dD "
                    "are too many", file, (long long)nc, (long long)b->k, b->d);
        double *x = es__realloc(b->ctx, b->xyz, (size_t)bytes);
        if (!x) return ES_ENOMEM;
        b->xyz = x;
        char **ids = es__realloc(b->ctx, b->ids, (size_t)nc * sizeof *ids);
        if (!ids) return ES_ENOMEM;
        b->ids = ids;
        char **im = es__realloc(b->ctx, b->images, (size_t)nc * sizeof *im);
        if (!im) return ES_ENOMEM;
        b->images = im;
        double *sc = es__realloc(b->ctx, b->scale, (size_t)nc * sizeof *sc);
        if (!sc) return ES_ENOMEM;
        b->scale = sc;
        b->cap = nc;
    }
    b->ids[b->n] = NULL;
    b->images[b->n] = NULL;
    b->scale[b->n] = NAN;
    memset(b->xyz + b->n * b->kd, 0, (size_t)b->kd * sizeof(double));
    b->n++;
    return ES_OK;
}

void es__lm_builder_clear(es__lm_builder *b)
{
    es__free(b->ctx, b->xyz);
    es__free_strings(b->ctx, b->ids, b->n);
    es__free_strings(b->ctx, b->images, b->n);
    es__free(b->ctx, b->scale);
    memset(b, 0, sizeof *b);
}

es_status es__lm_builder_finish(es__lm_builder *b, int with_tps_fields, es_landmarks **out)
{
    es_landmarks *lm = es__calloc(b->ctx, 1, sizeof *lm);
    if (!lm) { es__lm_builder_clear(b); return ES_ENOMEM; }
    lm->ctx = b->ctx;
    lm->n = b->n;
    lm->k = b->k;
    lm->d = b->d;
    lm->xyz = b->xyz;
    lm->ids = b->ids;
    if (with_tps_fields) {
        lm->images = b->images;
        lm->scale = b->scale;
    } else {
        es__free_strings(b->ctx, b->images, b->n);
        es__free(b->ctx, b->scale);
    }
    memset(b, 0, sizeof *b);
    *out = lm;
    return ES_OK;
}

/* ---- truss lengths and index lists ----------------------------------------- */

es_status es_landmarks_truss_lengths(es_ctx *ctx, const es_landmarks *lm, int64_t nedges,
                                     const int64_t *edges, es_mat len)
{
    if (len.rows != nedges || len.cols != lm->n || len.ld < nedges)
        ES_FAIL(ctx, ES_EINVAL, "landmarks: lengths matrix must be %lld x %lld",
                (long long)nedges, (long long)lm->n);
    for (int64_t e = 0; e < nedges; e++) {
        int64_t a = edges[2 * e], b = edges[2 * e + 1];
        if (a < 0 || b < 0 || a >= lm->k || b >= lm->k || a == b)
            ES_FAIL(ctx, ES_EINVAL, "landmarks: edge %lld joins landmarks %lld and %lld (of "
                    "%lld)", (long long)e + 1, (long long)a + 1, (long long)b + 1,
                    (long long)lm->k);
    }
    int64_t kd = lm->k * lm->d;
    for (int64_t j = 0; j < lm->n; j++) {
        const double *c = lm->xyz + j * kd;
        for (int64_t e = 0; e < nedges; e++) {
            int64_t a = edges[2 * e], b = edges[2 * e + 1];
            double s = 0;
            for (int q = 0; q < lm->d; q++) {
                double dd = c[a + q * lm->k] - c[b + q * lm->k];
                s += dd * dd;
            }
            ES_AT(len, e, j) = sqrt(s);
        }
    }
    return ES_OK;
}

/* Separators between the numbers of an index-list line. */
#define INDEX_SEPS " \t,\r"

es_status es_landmarks_read_index_list(es_ctx *ctx, const char *path, int per, int64_t **idx,
                                       int64_t *count)
{
    char *buf = NULL;
    size_t len;
    es_status rc;
    const char *file = es__path_base(path);
    *idx = NULL;
    *count = 0;
    if (per != 2 && per != 3) ES_FAIL(ctx, ES_EINVAL, "landmarks: %d indices per line", per);
    if ((rc = es__lm_read_text(ctx, path, &buf, &len)) != ES_OK) return rc;
    int64_t cap = 64, n = 0, line = 0;
    int64_t *out = es__alloc_array(ctx, cap * per, sizeof *out);
    if (!out) { es__free(ctx, buf); return ES_ENOMEM; }
    char *cur = buf;
    while (cur && *cur) {
        char *nl = strchr(cur, '\n');
        if (nl) *nl = 0;
        char *s = cur, *hash = strchr(s, '#');
        cur = nl ? nl + 1 : NULL;
        line++;
        if (hash) *hash = 0;
        int64_t v[4];
        int got = 0;
        const char *p = s;
        for (;;) {
            p += strspn(p, INDEX_SEPS);
            if (!*p) break;
            const char *e = p + strcspn(p, INDEX_SEPS);
            int64_t x;
            if (es__parse_int64(p, e, &x) != e || got == per) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: expected %d landmark numbers",
                              file, (long long)line, per);
                goto fail;
            }
            if (x < 1) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: landmark number %lld < 1",
                              file, (long long)line, (long long)x);
                goto fail;
            }
            v[got++] = x - 1;
            p = e;
        }
        if (got == 0) continue;
        if (got != per) {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: expected %d landmark numbers, "
                          "found %d", file, (long long)line, per, got);
            goto fail;
        }
        if (n == cap) {
            int64_t *no = es__realloc(ctx, out, (size_t)(2 * cap * per) * sizeof *no);
            if (!no) { rc = ES_ENOMEM; goto fail; }
            out = no;
            cap *= 2;
        }
        for (int q = 0; q < per; q++) out[n * per + q] = v[q];
        n++;
    }
    if (n == 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: no entries", file);
        goto fail;
    }
    es__free(ctx, buf);
    *idx = out;
    *count = n;
    return ES_OK;
fail:
    es__free(ctx, buf);
    es__free(ctx, out);
    return rc;
}
