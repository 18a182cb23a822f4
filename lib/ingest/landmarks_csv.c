/* lib/ingest/landmarks_csv.c — long CSV landmark tables and specimen label
 * tables.
 *
 * The long layout (one row per specimen and landmark) is the one of
 * ../shared/data/landmarks_rshapes, R's shapes data sets exported with
 * their *_specimens.csv labels, and of the procGPA oracle inputs. Both
 * tables are read by core/csv_table.h (libcsv, RFC 4180 quoting, the line
 * of every record for messages). Specimen ids are looked up through
 * core/strmap.h: a slot holds its own key, so a probe collision between ids
 * can never read another specimen's entry (the private map this replaced
 * stored table rows but compared against an array indexed by another
 * counter, and refused R's brains and dna tables with "listed twice").
 */
#include "ingest/ingest_pkg.h"
#include "core/csv_table.h"
#include "core/files.h"
#include "core/strmap.h"
#include "core/text.h"

#include <ctype.h>
#include <strings.h>

/* The column of record 0 whose name is `name` (case-insensitive, blanks
 * around it allowed), or -1. */
static int64_t find_header(const es__csv_table *t, const char *name)
{
    size_t n = strlen(name);
    for (int64_t c = 0; c < es__csv_nfields(t, 0); c++) {
        const char *f = es__csv_field(t, 0, c);
        while (isspace((unsigned char)*f)) f++;
        if (!strncasecmp(f, name, n)) {
            const char *r = f + n;
            while (isspace((unsigned char)*r)) r++;
            if (!*r) return c;
        }
    }
    return -1;
}

/* The columns of a long table and what they imply. */
typedef struct long_cols {
    int64_t spec, lmk, xyz[3];
    int64_t need;   /* the largest of them: a row needs need + 1 fields */
    int d;
} long_cols;

static es_status find_columns(es_ctx *ctx, const es__csv_table *t, const char *file,
                              long_cols *c)
{
    c->spec = find_header(t, "specimen");
    c->lmk = find_header(t, "landmark");
    c->xyz[0] = find_header(t, "x");
    c->xyz[1] = find_header(t, "y");
    c->xyz[2] = find_header(t, "z");
    if (c->spec < 0 || c->lmk < 0 || c->xyz[0] < 0 || c->xyz[1] < 0)
        ES_FAIL(ctx, ES_EFORMAT, "landmarks: %s:%lld: header must name columns specimen, "
                "landmark, x, y[, z]", file, (long long)t->line[0]);
    c->d = c->xyz[2] >= 0 ? 3 : 2;
    c->need = c->spec > c->lmk ? c->spec : c->lmk;
    for (int q = 0; q < c->d; q++) c->need = c->xyz[q] > c->need ? c->xyz[q] : c->need;
    return ES_OK;
}

/* First pass: check every row's field count and landmark number, find k
 * (the largest landmark number) and number the specimens in order of first
 * appearance (map: id -> specimen index; keys borrowed from t). */
static es_status scan_rows(es_ctx *ctx, const es__csv_table *t, const char *file,
                           const long_cols *c, es__strmap *map, int64_t *k)
{
    int64_t nrows = t->nrecords - 1;
    es_status rc;
    *k = 0;
    for (int64_t r = 1; r < t->nrecords; r++) {
        const char *lf = es__csv_field(t, r, c->lmk);
        int64_t lmk;
        if (es__csv_nfields(t, r) <= c->need)
            ES_FAIL(ctx, ES_EFORMAT, "landmarks: %s:%lld: %lld fields, expected %lld", file,
                    (long long)t->line[r], (long long)es__csv_nfields(t, r),
                    (long long)es__csv_nfields(t, 0));
        if (es__parse_int64_field(lf, &lmk) || lmk < 1)
            ES_FAIL(ctx, ES_EFORMAT, "landmarks: %s:%lld: landmark '%s' is not a positive "
                    "integer", file, (long long)t->line[r], lf);
        /* every specimen needs rows for landmarks 1..k: k <= the rows */
        if (lmk > nrows)
            ES_FAIL(ctx, ES_ERANGE, "landmarks: %s: %lld landmarks in %dD are too many "
                    "(largest landmark number) for %lld data rows (line %lld)", file,
                    (long long)lmk, c->d, (long long)nrows, (long long)t->line[r]);
        *k = lmk > *k ? lmk : *k;
        if ((rc = es__strmap_put(ctx, map, es__csv_field(t, r, c->spec), map->n, NULL)))
            return rc;
    }
    return ES_OK;
}

/* Second pass: the coordinates, each landmark once per specimen. */
static es_status fill_coords(es_ctx *ctx, const es__csv_table *t, const char *file,
                             const long_cols *c, const es__strmap *map, es__lm_builder *b)
{
    int64_t k = b->k;
    es_status rc = ES_OK;
    unsigned char *seen = es__calloc(ctx, (size_t)(b->n * k), 1);
    if (!seen) return ES_ENOMEM;
    for (int64_t r = 1; r < t->nrecords && rc == ES_OK; r++) {
        int64_t lmk, j = es__strmap_get(map, es__csv_field(t, r, c->spec));
        es__parse_int64_field(es__csv_field(t, r, c->lmk), &lmk);   /* checked by scan_rows */
        if (seen[j * k + lmk - 1]++) {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: landmark %lld of specimen '%s' "
                          "appears twice", file, (long long)t->line[r], (long long)lmk,
                          b->ids[j]);
            break;
        }
        for (int q = 0; q < c->d; q++) {
            const char *f = es__csv_field(t, r, c->xyz[q]);
            double v;
            if (es__parse_finite(f, &v)) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: %c coordinate '%s' is not a "
                              "number", file, (long long)t->line[r], "xyz"[q], f);
                break;
            }
            b->xyz[j * b->kd + lmk - 1 + q * k] = v;
        }
    }
    for (int64_t j = 0; j < b->n && rc == ES_OK; j++)
        for (int64_t v = 0; v < k; v++)
            if (!seen[j * k + v]) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: specimen '%s' lacks landmark %lld "
                              "(of %lld)", file, b->ids[j], (long long)v + 1, (long long)k);
                break;
            }
    es__free(ctx, seen);
    return rc;
}

es_status es_landmarks_read_csv(es_ctx *ctx, const char *path, const char *specimens_path,
                                es_landmarks **out)
{
    es__csv_table t;
    es__strmap map = {0};
    es__lm_builder b = {0};
    long_cols c = {0};
    int64_t k = 0, nspec;
    es_status rc;
    const char *file = es__path_base(path);
    *out = NULL;
    b.ctx = ctx;
    if ((rc = es__csv_read(ctx, "landmarks", path, 0, &t)) != ES_OK) return rc;
    if (t.nrecords < 2) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: no data rows", file);
        goto done;
    }
    if ((rc = find_columns(ctx, &t, file, &c)) || (rc = es__strmap_init(ctx, &map, 0)) ||
        (rc = scan_rows(ctx, &t, file, &c, &map, &k)))
        goto done;
    nspec = map.n;
    /* each specimen has a row per landmark, so more than the rows can fill
     * is incomplete anyway; where nspec * k would also dwarf the file, say so
     * now rather than allocate it to find which specimen lacks what */
    if (nspec > (t.nrecords - 1) / k && nspec / 4 > (t.nrecords + 1024) / k) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: %lld specimens of %lld landmarks need "
                      "more than its %lld data rows (a specimen lacks landmarks)", file,
                      (long long)nspec, (long long)k, (long long)(t.nrecords - 1));
        goto done;
    }
    b.limit = nspec;
    for (int64_t j = 0; j < nspec; j++)
        if ((rc = es__lm_builder_add(&b, k, c.d, file, 0)) != ES_OK) goto done;
    /* ids in order of first appearance: the map's values */
    for (int64_t i = 0; i < map.cap; i++)
        if (map.keys[i] && !(b.ids[map.vals[i]] = es__strdup(ctx, map.keys[i]))) {
            rc = ES_ENOMEM;
            goto done;
        }
    if ((rc = fill_coords(ctx, &t, file, &c, &map, &b))) goto done;
    rc = es__lm_builder_finish(&b, 0, out);
done:
    es__strmap_clear(ctx, &map);
    es__csv_table_clear(ctx, &t);
    es__lm_builder_clear(&b);
    if (rc == ES_OK && specimens_path &&
        (rc = es_landmarks_read_specimens(ctx, *out, specimens_path)) != ES_OK) {
        es_landmarks_free(*out);
        *out = NULL;
    }
    return rc;
}

es_status es_landmarks_read_specimens(es_ctx *ctx, es_landmarks *lm, const char *specimens_path)
{
    es__csv_table t;
    es__strmap map = {0};
    es_status rc;
    const char *file = es__path_base(specimens_path);
    char **names = NULL, **labels = NULL;
    int64_t nc = 0, nf, cid;
    if ((rc = es__csv_read(ctx, "landmarks", specimens_path, 0, &t)) != ES_OK) return rc;
    if (t.nrecords < 1) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: empty", file);
        goto fail;
    }
    nf = es__csv_nfields(&t, 0);
    if ((cid = find_header(&t, "specimen")) < 0) cid = 0;
    nc = nf - 1;
    names = es__calloc(ctx, (size_t)(nc > 0 ? nc : 1), sizeof *names);
    labels = es__calloc(ctx, (size_t)(lm->n * (nc > 0 ? nc : 1)), sizeof *labels);
    if (!names || !labels) { rc = ES_ENOMEM; goto fail; }
    for (int64_t c = 0, o = 0; c < nf; c++)
        if (c != cid && !(names[o++] = es__strdup(ctx, es__csv_field(&t, 0, c)))) {
            rc = ES_ENOMEM;
            goto fail;
        }
    /* the table's ids -> their record */
    if ((rc = es__strmap_init(ctx, &map, t.nrecords))) goto fail;
    for (int64_t r = 1; r < t.nrecords; r++) {
        const char *id = es__csv_field(&t, r, cid);
        int64_t prev;
        if (es__csv_nfields(&t, r) != nf) {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: %lld fields, the header has %lld",
                          file, (long long)t.line[r], (long long)es__csv_nfields(&t, r),
                          (long long)nf);
            goto fail;
        }
        if ((rc = es__strmap_put(ctx, &map, id, r, &prev))) goto fail;
        if (prev >= 0) {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: specimen '%s' listed twice "
                          "(first on line %lld)", file, (long long)t.line[r], id,
                          (long long)t.line[prev]);
            goto fail;
        }
    }
    for (int64_t j = 0; j < lm->n; j++) {
        int64_t r = es__strmap_get(&map, lm->ids[j]);
        if (r < 0) {
            rc = es__fail(ctx, ES_ENOTFOUND, "landmarks: %s: specimen '%s' has no row", file,
                          lm->ids[j]);
            goto fail;
        }
        for (int64_t c = 0, o = 0; c < nf; c++)
            if (c != cid && !(labels[j * nc + o++] = es__strdup(ctx, es__csv_field(&t, r, c)))) {
                rc = ES_ENOMEM;
                goto fail;
            }
    }
    es__free_strings(ctx, lm->colnames, lm->ncols);
    es__free_strings(ctx, lm->labels, lm->labels ? lm->n * lm->ncols : 0);
    lm->colnames = names;
    lm->labels = labels;
    lm->ncols = nc;
    es__strmap_clear(ctx, &map);
    es__csv_table_clear(ctx, &t);
    return ES_OK;
fail:
    es__free_strings(ctx, names, nc > 0 ? nc : 0);
    es__free_strings(ctx, labels, labels ? lm->n * (nc > 0 ? nc : 1) : 0);
    es__strmap_clear(ctx, &map);
    es__csv_table_clear(ctx, &t);
    return rc;
}
