/* lib/ingest/landmarks.c — landmark readers: tpsDig TPS files and long CSV tables.
 *
 * TPS is the format of F. J. Rohlf's tpsDig/tpsUtil (Rohlf 2015, "The tps
 * series of software", Hystrix 26:9-12), which most morphometric data are
 * exchanged in; the keys and their meaning follow geomorph's readland.tps
 * (SCALE multiplies, CURVES/POINTS blocks are outlines, not landmarks). The
 * long CSV layout is the one of ../shared/data/landmarks_rshapes and of the
 * procGPA oracle inputs. CSV goes through libcsv (RFC 4180 quoting), fed one
 * line at a time so that every record knows its line number for messages.
 */
#include "core/core_private.h"
#include "edgespace/es_landmarks.h"

#include <csv.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <strings.h>

/* ---- small helpers ------------------------------------------------------ */

static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* Whole file into memory, NUL-terminated. */
static es_status slurp(es_ctx *ctx, const char *path, char **buf, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) ES_FAIL(ctx, ES_EIO, "landmarks: cannot open '%s': %s", path, strerror(errno));
    size_t cap = 1 << 16, n = 0;
    char *b = es__malloc(ctx, cap);
    if (!b) { fclose(f); return ES_ENOMEM; }
    for (;;) {
        if (n + 1 >= cap) {
            char *nb = es__realloc(ctx, b, cap * 2);
            if (!nb) { es__free(ctx, b); fclose(f); return ES_ENOMEM; }
            b = nb;
            cap *= 2;
        }
        size_t got = fread(b + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0) break;
    }
    int err = ferror(f);
    fclose(f);
    if (err) {
        es__free(ctx, b);
        ES_FAIL(ctx, ES_EIO, "landmarks: error reading '%s'", path);
    }
    b[n] = 0;
    /* A UTF-8 byte order mark (Excel's "CSV UTF-8", Windows editors) is not
     * data: drop it, as the manifest and mesh readers do. */
    if (n >= 3 && !memcmp(b, "\xEF\xBB\xBF", 3)) {
        memmove(b, b + 3, n - 2);
        n -= 3;
    }
    *buf = b;
    *len = n;
    return ES_OK;
}

/* Parse a whole string as a finite double. */
static int parse_num(const char *s, double *out)
{
    char *end;
    while (isspace((unsigned char)*s)) s++;
    if (!*s) return -1;
    errno = 0;
    double v = strtod(s, &end);
    while (isspace((unsigned char)*end)) end++;
    if (*end || errno == ERANGE || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

static int parse_int(const char *s, int64_t *out)
{
    char *end;
    while (isspace((unsigned char)*s)) s++;
    if (!*s) return -1;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    while (isspace((unsigned char)*end)) end++;
    if (*end || errno == ERANGE) return -1;
    *out = v;
    return 0;
}

static void free_strings(es_ctx *ctx, char **s, int64_t n)
{
    if (!s) return;
    for (int64_t i = 0; i < n; i++) es__free(ctx, s[i]);
    es__free(ctx, s);
}

void es_landmarks_free(es_landmarks *lm)
{
    if (!lm) return;
    es_ctx *ctx = lm->ctx;
    es__free(ctx, lm->xyz);
    free_strings(ctx, lm->ids, lm->n);
    free_strings(ctx, lm->images, lm->images ? lm->n : 0);
    es__free(ctx, lm->scale);
    free_strings(ctx, lm->colnames, lm->ncols);
    free_strings(ctx, lm->labels, lm->labels ? lm->n * lm->ncols : 0);
    es__free(ctx, lm);
}

int64_t es_landmarks_find_column(const es_landmarks *lm, const char *name)
{
    for (int64_t c = 0; lm && c < lm->ncols; c++)
        if (!strcmp(lm->colnames[c], name)) return c;
    return -1;
}

/* Growable array of specimens while reading. */
typedef struct builder {
    es_ctx *ctx;
    int64_t n, cap, k, kd;
    int d;
    double *xyz;
    char **ids, **images;
    double *scale;
} builder;

/* Specimens the builder first makes room for; it doubles from there. */
enum { FIRST_CAP = 16 };

/* line is 0 for CSV, where k is the largest landmark number, not an LM= line. */
static es_status builder_add(builder *b, int64_t k, int d, const char *file, int64_t line)
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

static void builder_clear(builder *b)
{
    es__free(b->ctx, b->xyz);
    free_strings(b->ctx, b->ids, b->n);
    free_strings(b->ctx, b->images, b->n);
    es__free(b->ctx, b->scale);
    memset(b, 0, sizeof *b);
}

static es_status builder_finish(builder *b, int with_tps_fields, es_landmarks **out)
{
    es_landmarks *lm = es__calloc(b->ctx, 1, sizeof *lm);
    if (!lm) { builder_clear(b); return ES_ENOMEM; }
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
        free_strings(b->ctx, b->images, b->n);
        es__free(b->ctx, b->scale);
    }
    memset(b, 0, sizeof *b);
    *out = lm;
    return ES_OK;
}

/* ---- TPS ---------------------------------------------------------------- */

/* "KEY=value" (case-insensitive key); returns the value or NULL. */
static const char *tps_key(const char *line, const char *key)
{
    size_t n = strlen(key);
    if (strncasecmp(line, key, n) || line[n] != '=') return NULL;
    const char *v = line + n + 1;
    while (*v == ' ' || *v == '\t') v++;
    return v;
}

es_status es_landmarks_read_tps(es_ctx *ctx, const char *path, int apply_scale,
                                es_landmarks **out)
{
    char *buf = NULL;
    size_t len;
    es_status rc;
    builder b = {0};
    const char *file = base_name(path);
    *out = NULL;
    b.ctx = ctx;
    if ((rc = slurp(ctx, path, &buf, &len)) != ES_OK) return rc;

    int64_t line = 0, pending = 0;   /* coordinate lines still expected */
    int64_t skip = 0;                /* POINTS= lines of a curve still to skip */
    int d = 2, warned_curves = 0;
    char *cur = buf;
    while (cur && *cur) {
        char *nl = strchr(cur, '\n');
        if (nl) *nl = 0;
        char *s = cur;
        cur = nl ? nl + 1 : NULL;
        line++;
        size_t l = strlen(s);
        while (l && (s[l - 1] == '\r' || isspace((unsigned char)s[l - 1]))) s[--l] = 0;
        while (isspace((unsigned char)*s)) s++;
        if (!*s) continue;
        if (skip > 0) { skip--; continue; }
        if (pending > 0) {
            double v[3];
            int got = 0;
            char *p = s, *e;
            while (*p && got < 4) {
                while (*p == ' ' || *p == '\t' || *p == ',') p++;
                if (!*p) break;
                errno = 0;
                double x = strtod(p, &e);
                if (e == p || !isfinite(x)) {
                    rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: expected %d coordinates, "
                                  "found '%s'", file, (long long)line, d, s);
                    goto fail;
                }
                if (got < 3) v[got] = x;
                got++;
                p = e;
            }
            if (got != d) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: expected %d coordinates, "
                              "found %d", file, (long long)line, d, got);
                goto fail;
            }
            int64_t lmk = b.k - pending;
            double *col = b.xyz + (b.n - 1) * b.kd;
            for (int q = 0; q < d; q++) col[lmk + q * b.k] = v[q];
            pending--;
            continue;
        }
        const char *val;
        int64_t iv;
        if ((val = tps_key(s, "LM")) || (val = tps_key(s, "LM3"))) {
            int dim = tps_key(s, "LM3") ? 3 : 2;
            if (parse_int(val, &iv) || iv < 1) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: bad landmark count '%s'",
                              file, (long long)line, val);
                goto fail;
            }
            d = dim;
            if ((rc = builder_add(&b, iv, d, file, line)) != ES_OK) goto fail;
            pending = iv;
        } else if ((val = tps_key(s, "ID"))) {
            if (b.n == 0) goto before_lm;
            es__free(ctx, b.ids[b.n - 1]);
            if (!(b.ids[b.n - 1] = es__strdup(ctx, val))) { rc = ES_ENOMEM; goto fail; }
        } else if ((val = tps_key(s, "IMAGE"))) {
            if (b.n == 0) goto before_lm;
            es__free(ctx, b.images[b.n - 1]);
            if (!(b.images[b.n - 1] = es__strdup(ctx, val))) { rc = ES_ENOMEM; goto fail; }
        } else if ((val = tps_key(s, "SCALE"))) {
            double sc;
            if (b.n == 0) goto before_lm;
            if (parse_num(val, &sc) || !(sc > 0)) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: bad SCALE '%s'", file,
                              (long long)line, val);
                goto fail;
            }
            b.scale[b.n - 1] = sc;
        } else if ((val = tps_key(s, "CURVES"))) {
            if (!warned_curves++)
                es__warn(ctx, "landmarks: %s:%lld: CURVES (outlines) are ignored", file,
                         (long long)line);
        } else if ((val = tps_key(s, "POINTS"))) {
            if (parse_int(val, &iv) || iv < 0) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: bad POINTS count '%s'", file,
                              (long long)line, val);
                goto fail;
            }
            skip = iv;
        } else if (tps_key(s, "COMMENT") || tps_key(s, "VARIABLES")) {
            /* free text, ignored */
        } else if (strchr(s, '=')) {
            es__warn(ctx, "landmarks: %s:%lld: unknown key '%s' ignored", file, (long long)line, s);
        } else {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: unexpected line '%s' (coordinates "
                          "must follow an LM= line)", file, (long long)line, s);
            goto fail;
        }
        continue;
    before_lm:
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: '%s' before the first LM= line", file,
                      (long long)line, s);
        goto fail;
    }
    if (pending > 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: end of file with %lld of %lld "
                      "coordinate lines of specimen %lld missing", file, (long long)line,
                      (long long)pending, (long long)b.k, (long long)b.n);
        goto fail;
    }
    if (skip > 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: end of file inside a POINTS= block",
                      file, (long long)line);
        goto fail;
    }
    if (b.n == 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: no LM= or LM3= specimen", file);
        goto fail;
    }
    for (int64_t j = 0; j < b.n; j++) {
        if (apply_scale && isfinite(b.scale[j]))
            for (int64_t v = 0; v < b.kd; v++) b.xyz[j * b.kd + v] *= b.scale[j];
        if (!b.ids[j]) {
            char name[32];
            snprintf(name, sizeof name, "%lld", (long long)j + 1);
            if (!(b.ids[j] = es__strdup(ctx, name))) { rc = ES_ENOMEM; goto fail; }
        }
    }
    es__free(ctx, buf);
    return builder_finish(&b, 1, out);
fail:
    es__free(ctx, buf);
    builder_clear(&b);
    return rc;
}

/* ---- CSV through libcsv ---------------------------------------------------- */

typedef struct csv_row {
    int64_t line, nf;
    char **f;
} csv_row;

typedef struct csv_table {
    es_ctx *ctx;
    csv_row *rows;
    int64_t nrows, cap;
    char **fields;   /* fields of the record being read */
    int64_t nf, fcap;
    int64_t line;    /* line being fed */
    int oom;
} csv_table;

static void on_field(void *s, size_t len, void *data)
{
    csv_table *t = data;
    if (t->oom) return;
    if (t->nf == t->fcap) {
        int64_t nc = t->fcap ? 2 * t->fcap : 8;
        char **nf = es__realloc(t->ctx, t->fields, (size_t)nc * sizeof *nf);
        if (!nf) { t->oom = 1; return; }
        t->fields = nf;
        t->fcap = nc;
    }
    char *c = es__malloc(t->ctx, len + 1);
    if (!c) { t->oom = 1; return; }
    if (len) memcpy(c, s, len);
    c[len] = 0;
    t->fields[t->nf++] = c;
}

static void on_record(int c, void *data)
{
    csv_table *t = data;
    (void)c;
    if (t->oom) return;
    if (t->nrows == t->cap) {
        int64_t nc = t->cap ? 2 * t->cap : 64;
        csv_row *nr = es__realloc(t->ctx, t->rows, (size_t)nc * sizeof *nr);
        if (!nr) { t->oom = 1; return; }
        t->rows = nr;
        t->cap = nc;
    }
    char **f = es__alloc_array(t->ctx, t->nf ? t->nf : 1, sizeof *f);
    if (!f) { t->oom = 1; return; }
    if (t->nf) memcpy(f, t->fields, (size_t)t->nf * sizeof *f);
    t->rows[t->nrows++] = (csv_row){t->line, t->nf, f};
    t->nf = 0;
}

static void table_free(csv_table *t)
{
    for (int64_t r = 0; r < t->nrows; r++) free_strings(t->ctx, t->rows[r].f, t->rows[r].nf);
    es__free(t->ctx, t->rows);
    free_strings(t->ctx, t->fields, t->nf);
    memset(t, 0, sizeof *t);
}

static es_status read_table(es_ctx *ctx, const char *path, csv_table *t)
{
    char *buf = NULL;
    size_t len;
    es_status rc;
    struct csv_parser p;
    memset(t, 0, sizeof *t);
    t->ctx = ctx;
    if ((rc = slurp(ctx, path, &buf, &len)) != ES_OK) return rc;
    if (csv_init(&p, CSV_APPEND_NULL) != 0) {
        es__free(ctx, buf);
        ES_FAIL(ctx, ES_ENOMEM, "landmarks: cannot initialise the CSV parser");
    }
    char *cur = buf, *end = buf + len;
    while (cur < end) {
        char *nl = memchr(cur, '\n', (size_t)(end - cur));
        size_t n = nl ? (size_t)(nl - cur) + 1 : (size_t)(end - cur);
        t->line++;
        if (csv_parse(&p, cur, n, on_field, on_record, t) != n) {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: %s", base_name(path),
                          (long long)t->line, csv_strerror(csv_error(&p)));
            goto done;
        }
        cur += n;
    }
    csv_fini(&p, on_field, on_record, t);
    if (t->oom) rc = es__fail(ctx, ES_ENOMEM, "landmarks: out of memory reading '%s'", path);
done:
    csv_free(&p);
    es__free(ctx, buf);
    if (rc != ES_OK) table_free(t);
    return rc;
}

static int64_t find_header(const csv_row *h, const char *name)
{
    for (int64_t c = 0; c < h->nf; c++) {
        const char *f = h->f[c];
        while (isspace((unsigned char)*f)) f++;
        size_t n = strlen(name);
        if (!strncasecmp(f, name, n)) {
            const char *r = f + n;
            while (isspace((unsigned char)*r)) r++;
            if (!*r) return c;
        }
    }
    return -1;
}

/* Hash map from specimen id to index (open addressing, FNV-1a). */
typedef struct id_map { int64_t cap, *slot; } id_map;

static uint64_t fnv(const char *s)
{
    uint64_t h = 1469598103934665603ULL;
    for (; *s; s++) h = (h ^ (unsigned char)*s) * 1099511628211ULL;
    return h;
}

static int64_t map_find(const id_map *m, char **ids, const char *id, int64_t *slot)
{
    uint64_t h = fnv(id) & (uint64_t)(m->cap - 1);
    while (m->slot[h] >= 0) {
        if (!strcmp(ids[m->slot[h]], id)) { if (slot) *slot = (int64_t)h; return m->slot[h]; }
        h = (h + 1) & (uint64_t)(m->cap - 1);
    }
    if (slot) *slot = (int64_t)h;
    return -1;
}

es_status es_landmarks_read_csv(es_ctx *ctx, const char *path, const char *specimens_path,
                                es_landmarks **out)
{
    csv_table t;
    es_status rc;
    builder b = {0};
    id_map map = {0, NULL};
    unsigned char *seen = NULL;
    const char *file = base_name(path);
    *out = NULL;
    b.ctx = ctx;
    if ((rc = read_table(ctx, path, &t)) != ES_OK) return rc;
    if (t.nrows < 2) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: no data rows", file);
        goto fail;
    }
    const csv_row *h = &t.rows[0];
    int64_t cs = find_header(h, "specimen"), cl = find_header(h, "landmark");
    int64_t cx[3] = {find_header(h, "x"), find_header(h, "y"), find_header(h, "z")};
    if (cs < 0 || cl < 0 || cx[0] < 0 || cx[1] < 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: header must name columns specimen, "
                      "landmark, x, y[, z]", file, (long long)h->line);
        goto fail;
    }
    int d = cx[2] >= 0 ? 3 : 2;
    int64_t need = cs > cl ? cs : cl;
    for (int q = 0; q < d; q++) need = cx[q] > need ? cx[q] : need;

    /* first pass: k and the specimens in order of appearance */
    int64_t k = 0, nspec = 0;
    map.cap = 64;
    while (map.cap < 2 * t.nrows) map.cap *= 2;
    map.slot = es__alloc_array(ctx, map.cap, sizeof *map.slot);
    char **order = es__alloc_array(ctx, t.nrows, sizeof *order);
    if (!map.slot || !order) { es__free(ctx, order); rc = ES_ENOMEM; goto fail; }
    for (int64_t i = 0; i < map.cap; i++) map.slot[i] = -1;
    for (int64_t r = 1; r < t.nrows; r++) {
        const csv_row *row = &t.rows[r];
        int64_t lmk, slot;
        if (row->nf == 1 && !row->f[0][0]) continue;
        if (row->nf <= need) {
            es__free(ctx, order);
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: %lld fields, expected %lld", file,
                          (long long)row->line, (long long)row->nf, (long long)h->nf);
            goto fail;
        }
        if (parse_int(row->f[cl], &lmk) || lmk < 1) {
            es__free(ctx, order);
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: landmark '%s' is not a positive "
                          "integer", file, (long long)row->line, row->f[cl]);
            goto fail;
        }
        if (lmk > t.nrows - 1) {
            /* every specimen needs rows for landmarks 1..k: k <= the rows */
            es__free(ctx, order);
            rc = es__fail(ctx, ES_ERANGE, "landmarks: %s: %lld landmarks in %dD are too many "
                          "(largest landmark number) for %lld data rows (line %lld)",
                          file, (long long)lmk, d, (long long)(t.nrows - 1),
                          (long long)row->line);
            goto fail;
        }
        k = lmk > k ? lmk : k;
        if (map_find(&map, order, row->f[cs], &slot) < 0) {
            map.slot[slot] = nspec;
            order[nspec++] = row->f[cs];
        }
    }
    es__free(ctx, order);
    if (nspec == 0) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: no data rows", file);
        goto fail;
    }
    /* each specimen has a row per landmark, so more than the rows can fill
     * is incomplete anyway; where nspec * k would also dwarf the file, say so
     * now rather than allocate it to find which specimen lacks what */
    if (nspec > (t.nrows - 1) / k && nspec / 4 > (t.nrows + 1024) / k) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: %lld specimens of %lld landmarks need "
                      "more than its %lld data rows (a specimen lacks landmarks)", file,
                      (long long)nspec, (long long)k, (long long)(t.nrows - 1));
        goto fail;
    }
    for (int64_t j = 0; j < nspec; j++)
        if ((rc = builder_add(&b, k, d, file, 0)) != ES_OK) goto fail;
    /* ids in order of first appearance, then the map again over b.ids */
    for (int64_t i = 0; i < map.cap; i++) map.slot[i] = -1;
    int64_t nid = 0;
    for (int64_t r = 1; r < t.nrows; r++) {
        const csv_row *row = &t.rows[r];
        int64_t slot;
        if (row->nf == 1 && !row->f[0][0]) continue;
        if (nid < nspec && map_find(&map, b.ids, row->f[cs], &slot) < 0) {
            if (!(b.ids[nid] = es__strdup(ctx, row->f[cs]))) { rc = ES_ENOMEM; goto fail; }
            map.slot[slot] = nid++;
        }
    }
    /* second pass: coordinates; each landmark once per specimen */
    seen = es__calloc(ctx, (size_t)(nspec * k), 1);
    if (!seen) { rc = ES_ENOMEM; goto fail; }
    for (int64_t r = 1; r < t.nrows; r++) {
        const csv_row *row = &t.rows[r];
        int64_t lmk;
        if (row->nf == 1 && !row->f[0][0]) continue;
        parse_int(row->f[cl], &lmk);
        int64_t j = map_find(&map, b.ids, row->f[cs], NULL);
        if (seen[j * k + lmk - 1]++) {
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: landmark %lld of specimen '%s' "
                          "appears twice", file, (long long)row->line, (long long)lmk, b.ids[j]);
            goto fail;
        }
        for (int q = 0; q < d; q++) {
            double v;
            if (parse_num(row->f[cx[q]], &v)) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: %c coordinate '%s' is not a "
                              "number", file, (long long)row->line, "xyz"[q], row->f[cx[q]]);
                goto fail;
            }
            b.xyz[j * b.kd + lmk - 1 + q * k] = v;
        }
    }
    for (int64_t j = 0; j < nspec; j++)
        for (int64_t v = 0; v < k; v++)
            if (!seen[j * k + v]) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: specimen '%s' lacks landmark %lld "
                              "(of %lld)", file, b.ids[j], (long long)v + 1, (long long)k);
                goto fail;
            }
    es__free(ctx, seen);
    seen = NULL;
    es__free(ctx, map.slot);
    map.slot = NULL;
    table_free(&t);
    if ((rc = builder_finish(&b, 0, out)) != ES_OK) return rc;
    if (specimens_path && (rc = es_landmarks_read_specimens(ctx, *out, specimens_path)) != ES_OK) {
        es_landmarks_free(*out);
        *out = NULL;
    }
    return rc;
fail:
    es__free(ctx, seen);
    es__free(ctx, map.slot);
    table_free(&t);
    builder_clear(&b);
    return rc;
}

es_status es_landmarks_read_specimens(es_ctx *ctx, es_landmarks *lm, const char *specimens_path)
{
    csv_table t;
    es_status rc;
    const char *file = base_name(specimens_path);
    char **names = NULL, **labels = NULL;
    int64_t nc = 0;
    if ((rc = read_table(ctx, specimens_path, &t)) != ES_OK) return rc;
    if (t.nrows < 1) {
        rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s: empty", file);
        goto fail;
    }
    const csv_row *h = &t.rows[0];
    int64_t cid = find_header(h, "specimen");
    if (cid < 0) cid = 0;
    nc = h->nf - 1;
    names = es__calloc(ctx, (size_t)(nc > 0 ? nc : 1), sizeof *names);
    labels = es__calloc(ctx, (size_t)(lm->n * (nc > 0 ? nc : 1)), sizeof *labels);
    if (!names || !labels) { rc = ES_ENOMEM; goto fail; }
    for (int64_t c = 0, o = 0; c < h->nf; c++) {
        if (c == cid) continue;
        if (!(names[o++] = es__strdup(ctx, h->f[c]))) { rc = ES_ENOMEM; goto fail; }
    }
    /* ids of the landmark set -> row of the specimens table (linear scan
     * over a map built on the table's id column) */
    id_map map = {64, NULL};
    char **tid = es__alloc_array(ctx, t.nrows, sizeof *tid);
    while (map.cap < 2 * t.nrows) map.cap *= 2;
    map.slot = es__alloc_array(ctx, map.cap, sizeof *map.slot);
    if (!tid || !map.slot) {
        es__free(ctx, tid);
        es__free(ctx, map.slot);
        rc = ES_ENOMEM;
        goto fail;
    }
    for (int64_t i = 0; i < map.cap; i++) map.slot[i] = -1;
    int64_t nt = 0;
    for (int64_t r = 1; r < t.nrows; r++) {
        const csv_row *row = &t.rows[r];
        int64_t slot;
        if (row->nf == 1 && !row->f[0][0]) continue;
        if (row->nf != h->nf) {
            es__free(ctx, tid);
            es__free(ctx, map.slot);
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: %lld fields, the header has %lld",
                          file, (long long)row->line, (long long)row->nf, (long long)h->nf);
            goto fail;
        }
        tid[nt] = row->f[cid];
        if (map_find(&map, tid, row->f[cid], &slot) >= 0) {
            es__free(ctx, tid);
            es__free(ctx, map.slot);
            rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: specimen '%s' listed twice", file,
                          (long long)row->line, row->f[cid]);
            goto fail;
        }
        map.slot[slot] = r;   /* table row */
        nt++;
    }
    for (int64_t j = 0; j < lm->n && rc == ES_OK; j++) {
        int64_t r = -1;
        uint64_t hh = fnv(lm->ids[j]) & (uint64_t)(map.cap - 1);
        while (map.slot[hh] >= 0) {
            if (!strcmp(t.rows[map.slot[hh]].f[cid], lm->ids[j])) { r = map.slot[hh]; break; }
            hh = (hh + 1) & (uint64_t)(map.cap - 1);
        }
        if (r < 0) {
            rc = es__fail(ctx, ES_ENOTFOUND, "landmarks: %s: specimen '%s' has no row", file,
                          lm->ids[j]);
            break;
        }
        for (int64_t c = 0, o = 0; c < h->nf; c++) {
            if (c == cid) continue;
            if (!(labels[j * nc + o++] = es__strdup(ctx, t.rows[r].f[c]))) { rc = ES_ENOMEM; break; }
        }
    }
    es__free(ctx, tid);
    es__free(ctx, map.slot);
    if (rc != ES_OK) goto fail;
    free_strings(ctx, lm->colnames, lm->ncols);
    free_strings(ctx, lm->labels, lm->labels ? lm->n * lm->ncols : 0);
    lm->colnames = names;
    lm->labels = labels;
    lm->ncols = nc;
    table_free(&t);
    return ES_OK;
fail:
    free_strings(ctx, names, nc > 0 ? nc : 0);
    free_strings(ctx, labels, labels ? lm->n * (nc > 0 ? nc : 1) : 0);
    table_free(&t);
    return rc;
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

es_status es_landmarks_read_index_list(es_ctx *ctx, const char *path, int per, int64_t **idx,
                                       int64_t *count)
{
    char *buf = NULL;
    size_t len;
    es_status rc;
    const char *file = base_name(path);
    *idx = NULL;
    *count = 0;
    if (per != 2 && per != 3) ES_FAIL(ctx, ES_EINVAL, "landmarks: %d indices per line", per);
    if ((rc = slurp(ctx, path, &buf, &len)) != ES_OK) return rc;
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
        char *p = s, *e;
        for (;;) {
            while (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r') p++;
            if (!*p) break;
            errno = 0;
            long long x = strtoll(p, &e, 10);
            if (e == p || errno || (*e && *e != ' ' && *e != '\t' && *e != ',' && *e != '\r') ||
                got == per) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: expected %d landmark numbers",
                              file, (long long)line, per);
                goto fail;
            }
            if (x < 1) {
                rc = es__fail(ctx, ES_EFORMAT, "landmarks: %s:%lld: landmark number %lld < 1",
                              file, (long long)line, x);
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
