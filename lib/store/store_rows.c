/* lib/store/store_rows.c — the shapes of a store, one row each: the
 * in-memory row metadata (ids, source paths, content hashes, labels) and
 * the id map, reading lengths, scales, positions and the topology,
 * appending rows (with new label columns), and selecting rows by label.
 *
 * Lengths are N x E on disk, the same memory as the library's E x N
 * column-major shape sets, so a block of rows reads straight into an es_mat
 * column per shape. Appends are all-or-nothing for the caller: everything
 * is validated before the first write, and a failure after it marks the
 * handle broken so the half-written working copy is never published.
 */
#include "store/store_pkg.h"
#include "store/store_private.h"
#include "core/scan.h"
#include "core/suggest.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void es__store_free_rows(es_store *s)
{
    es_ctx *ctx = s->ctx;
    for (int64_t i = 0; i < s->nrows; i++) {
        if (s->ids) es__free(ctx, s->ids[i]);
        if (s->sources) es__free(ctx, s->sources[i]);
        if (s->hashes) es__free(ctx, s->hashes[i]);
    }
    for (int64_t c = 0; c < s->ncols; c++) {
        for (int64_t i = 0; s->labels && s->labels[c] && i < s->nrows; i++)
            es__free(ctx, s->labels[c][i]);
        if (s->labels) es__free(ctx, s->labels[c]);
        if (s->colnames) es__free(ctx, s->colnames[c]);
    }
    es__free(ctx, s->ids);
    es__free(ctx, s->sources);
    es__free(ctx, s->hashes);
    es__free(ctx, s->labels);
    es__free(ctx, s->colnames);
    es__strmap_clear(ctx, &s->id_rows);
    s->ids = s->sources = s->hashes = s->colnames = NULL;
    s->labels = NULL;
    s->nrows = s->ncols = s->cap = 0;
}

/* Doubling keeps a long run of small appends linear; only the pointer
 * arrays move, never the strings (the id map's keys). */
es_status es__store_reserve_rows(es_store *s, int64_t need)
{
    es_ctx *ctx = s->ctx;
    int64_t cap = s->cap ? s->cap : 16;
    if (need <= s->cap) return ES_OK;
    while (cap < need) cap *= 2;
    char ***arrs[3] = {&s->ids, &s->sources, &s->hashes};
    size_t bytes;
    if (!es__mul_size((size_t)cap, sizeof(char *), &bytes))
        ES_FAIL(ctx, ES_ENOMEM, "store: too many rows (%lld)", (long long)need);
    for (int k = 0; k < 3; k++) {
        char **p = es__realloc(ctx, *arrs[k], bytes);
        if (!p) return ES_ENOMEM;
        memset(p + s->cap, 0, (size_t)(cap - s->cap) * sizeof *p);
        *arrs[k] = p;
    }
    for (int64_t c = 0; c < s->ncols; c++) {
        char **p = es__realloc(ctx, s->labels[c], bytes);
        if (!p) return ES_ENOMEM;
        memset(p + s->cap, 0, (size_t)(cap - s->cap) * sizeof *p);
        s->labels[c] = p;
    }
    s->cap = cap;
    return ES_OK;
}

es_status es__store_index_ids(es_store *s)
{
    es_status rc;
    es__strmap_clear(s->ctx, &s->id_rows);
    if ((rc = es__strmap_init(s->ctx, &s->id_rows, s->nrows))) return rc;
    for (int64_t i = 0; i < s->nrows; i++) {
        int64_t prev;
        if ((rc = es__strmap_put(s->ctx, &s->id_rows, s->ids[i], i, &prev))) return rc;
        if (prev >= 0)
            ES_FAIL(s->ctx, ES_EFORMAT, "store: '%s': /shapes/ids repeats '%s' (rows %lld and "
                    "%lld)", s->path, s->ids[i], (long long)prev, (long long)i);
    }
    return ES_OK;
}

const char *es_store_row_id(const es_store *s, int64_t row)
{
    return s && row >= 0 && row < s->nrows ? s->ids[row] : NULL;
}
const char *es_store_source_path(const es_store *s, int64_t row)
{
    return s && row >= 0 && row < s->nrows ? s->sources[row] : NULL;
}
const char *es_store_content_hash(const es_store *s, int64_t row)
{
    return s && row >= 0 && row < s->nrows ? s->hashes[row] : NULL;
}

int64_t es_store_find_row(const es_store *s, const char *id)
{
    return s && id ? es__strmap_get(&s->id_rows, id) : -1;
}

int64_t es_store_ncolumns(const es_store *s) { return s ? s->ncols : 0; }
const char *es_store_column_name(const es_store *s, int64_t col)
{
    return s && col >= 0 && col < s->ncols ? s->colnames[col] : NULL;
}
int64_t es_store_find_column(const es_store *s, const char *name)
{
    if (!s || !name) return -1;
    for (int64_t c = 0; c < s->ncols; c++)
        if (!strcmp(s->colnames[c], name)) return c;
    return -1;
}
const char *es_store_label(const es_store *s, int64_t row, int64_t col)
{
    if (!s || row < 0 || row >= s->nrows || col < 0 || col >= s->ncols) return NULL;
    return s->labels[col][row];
}

/* Read rows [row0, row0+n) of a 2-D dataset (row length m) into memory
 * laid out as n rows of stride ld >= m. */
static es_status read_block(es_ctx *ctx, es_store *s, const char *name, int64_t row0, int64_t n,
                            int64_t m, double *buf, int64_t ld)
{
    if (n == 0) return ES_OK;
    if (es__h5_read_rows_f64(s->file, name, row0, n, m, buf, ld) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot read rows %lld..%lld of %s in '%s'",
                           (long long)row0, (long long)(row0 + n - 1), name, s->path);
    return ES_OK;
}

static es_status no_edges(es_ctx *ctx, const es_store *s)
{
    ES_FAIL(ctx, ES_EINVAL, "store: '%s' has no edges: it holds landmarks only; give --edges "
            "or --triangles at ingest", s->path);
}

static es_status check_out(es_ctx *ctx, es_store *s, int64_t n, es_mat out)
{
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    if (s->nedges == 0) return no_edges(ctx, s);
    if (n < 0 || !out.data || out.rows != s->nedges || out.cols != n || out.ld < out.rows)
        ES_FAIL(ctx, ES_EINVAL, "store: output matrix is %lld x %lld (ld %lld), need "
                "%lld x %lld", (long long)out.rows, (long long)out.cols, (long long)out.ld,
                (long long)s->nedges, (long long)n);
    return ES_OK;
}

static es_status read_lengths_impl(es_ctx *ctx, es_store *s, int64_t row0, int64_t n,
                                   es_mat out)
{
    es_status rc = check_out(ctx, s, n, out);
    if (rc) return rc;
    if (row0 < 0 || row0 > s->nrows || n > s->nrows - row0)
        ES_FAIL(ctx, ES_ERANGE, "store: rows %lld..%lld are out of range (store has %lld "
                "rows)", (long long)row0, (long long)(row0 + n - 1), (long long)s->nrows);
    return read_block(ctx, s, "/shapes/lengths", row0, n, s->nedges, out.data, out.ld);
}

es_status es_store_read_lengths(es_ctx *ctx, es_store *s, int64_t row0, int64_t n, es_mat out)
{
    es_status rc;
    ES__H5_QUIET(rc = read_lengths_impl(ctx, s, row0, n, out));
    return rc;
}

static es_status read_lengths_rows_impl(es_ctx *ctx, es_store *s, const int64_t *rows,
                                        int64_t nrows, es_mat out)
{
    es_status rc = check_out(ctx, s, nrows, out);
    if (rc) return rc;
    for (int64_t j = 0; j < nrows; j++)
        if (rows[j] < 0 || rows[j] >= s->nrows)
            ES_FAIL(ctx, ES_ERANGE, "store: row %lld is out of range (store has %lld rows)",
                    (long long)rows[j], (long long)s->nrows);
    /* Runs of consecutive rows are read as one block. */
    for (int64_t j = 0; j < nrows;) {
        int64_t k = j + 1;
        while (k < nrows && rows[k] == rows[k - 1] + 1) k++;
        if ((rc = read_block(ctx, s, "/shapes/lengths", rows[j], k - j, s->nedges,
                             out.data + j * out.ld, out.ld)))
            return rc;
        j = k;
    }
    return ES_OK;
}

es_status es_store_read_lengths_rows(es_ctx *ctx, es_store *s, const int64_t *rows,
                                     int64_t nrows, es_mat out)
{
    es_status rc;
    ES__H5_QUIET(rc = read_lengths_rows_impl(ctx, s, rows, nrows, out));
    return rc;
}

/* A whole dataset as doubles (f) or integers (i). */
static es_status read_1d(es_ctx *ctx, es_store *s, const char *name, double *f, int64_t *i)
{
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    if ((f ? es__h5_read_f64(s->file, name, f) : es__h5_read_i64(s->file, name, i)) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot read %s of '%s'", name, s->path);
    return ES_OK;
}

es_status es_store_read_scales(es_ctx *ctx, es_store *s, double *scales)
{
    es_status rc = ES_OK;
    if (s && s->nedges == 0) return no_edges(ctx, s);
    if (s && s->nrows == 0) return ES_OK;
    ES__H5_QUIET(rc = read_1d(ctx, s, "/shapes/scales", scales, NULL));
    return rc;
}

es_status es_store_read_faces(es_ctx *ctx, es_store *s, int64_t *faces)
{
    es_status rc;
    if (s && s->nfaces == 0) return ES_OK;
    ES__H5_QUIET(rc = read_1d(ctx, s, "/topology/faces", NULL, faces));
    return rc;
}

es_status es_store_read_edges(es_ctx *ctx, es_store *s, int64_t *edges)
{
    es_status rc;
    if (s && s->nedges == 0) return ES_OK;
    ES__H5_QUIET(rc = read_1d(ctx, s, "/topology/edges", NULL, edges));
    return rc;
}

static es_status read_positions_impl(es_ctx *ctx, es_store *s, int64_t row, double *xyz)
{
    if (row < 0 || row >= s->nrows)
        ES_FAIL(ctx, ES_ERANGE, "store: row %lld is out of range (store has %lld rows)",
                (long long)row, (long long)s->nrows);
    if (es__h5_read_row3_f64(s->file, "/shapes/positions", row, s->nverts, 3, xyz) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot read positions of row %lld in '%s'",
                           (long long)row, s->path);
    return ES_OK;
}

es_status es_store_read_positions(es_ctx *ctx, es_store *s, int64_t row, double *xyz)
{
    es_status rc;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = read_positions_impl(ctx, s, row, xyz));
    return rc;
}

/* Row i's values: a positive scale, finite lengths and positions, every
 * label given. */
static es_status check_values(es_ctx *ctx, const es_store *s, const es_store_rows *r, int64_t i)
{
    const char *id = r->ids[i];
    if (s->nedges > 0 && (!(r->scales[i] > 0) || !isfinite(r->scales[i])))
        ES_FAIL(ctx, ES_EINVAL, "store: row '%s' has scale %g (must be finite, > 0)", id,
                r->scales[i]);
    for (int64_t e = 0; e < s->nedges; e++)
        if (!isfinite(r->lengths[e + i * s->nedges]))
            ES_FAIL(ctx, ES_EINVAL, "store: row '%s' has a non-finite length at edge %lld", id,
                    (long long)e);
    double lo = HUGE_VAL, hi = -HUGE_VAL, big = 0;
    for (int64_t v = 0; v < 3 * s->nverts; v++) {
        double x = r->xyz[v + i * 3 * s->nverts];
        if (!isfinite(x))
            ES_FAIL(ctx, ES_EINVAL, "store: row '%s' has a non-finite position at vertex %lld",
                    id, (long long)(v / 3));
        lo = fmin(lo, x);
        hi = fmax(hi, x);
        big = fmax(big, fabs(x));
    }
    /* the geometry squares and cubes lengths (dihedrals, areas): 1e77 or
     * 1e-100 left double's range and embedded with 17-56 % error and NaN
     * bending; 1e-30 to 1e30 keeps every product inside it */
    if (s->nverts > 1 && (big > ES__MAX_COORD || hi - lo < ES__MIN_EXTENT))
        ES_FAIL(ctx, ES_ERANGE, "store: row '%s' has coordinates up to %.3g over an extent of "
                "%.3g, outside what edgespace computes with (extent at least %g, coordinates "
                "at most %g); rescale it", id, big, hi - lo, ES__MIN_EXTENT, ES__MAX_COORD);
    for (int64_t c = 0; c < r->ncols; c++)
        if (!r->labels[i * r->ncols + c])
            ES_FAIL(ctx, ES_EINVAL, "store: row '%s' lacks a value for column '%s'", id,
                    r->colnames[c]);
    return ES_OK;
}

/* Everything checked before the first write, so that a refused batch
 * leaves the store untouched. Ids are looked up in the store's map and in
 * a map of the batch's own (keys borrowed from r->ids): linear in the rows,
 * where comparing each new id with every stored and new one took over a
 * minute for 10^5 rows. */
/* written: the values are in the store already (es__store_append_written) */
static es_status validate_rows(es_ctx *ctx, const es_store *s, const es_store_rows *r,
                               bool written)
{
    const bool lens = s->nedges > 0;   /* a store without edges ignores lengths/scales */
    es__strmap batch;
    es_status rc = ES_OK;
    if (r->n < 0 || (r->n > 0 && (!r->ids || (!written && ((lens && (!r->lengths ||
                                                                      !r->scales)) || !r->xyz)))) ||
        r->ncols < 0 || (r->ncols > 0 && (!r->colnames || (r->n > 0 && !r->labels))))
        ES_FAIL(ctx, ES_EINVAL, "store: incomplete rows to append");
    /* the column list is one attribute (64 KiB at most in HDF5's compact
     * storage): 20,000 columns failed inside HDF5 after 8.6 s */
    if (r->ncols > ES_STORE_MAX_COLUMNS)
        ES_FAIL(ctx, ES_ERANGE, "store: %lld label columns; a store holds at most %d",
                (long long)r->ncols, ES_STORE_MAX_COLUMNS);
    {
        int64_t total = s->ncols;
        for (int64_t c = 0; c < r->ncols; c++)
            total += r->colnames[c] && es_store_find_column(s, r->colnames[c]) < 0;
        if (total > ES_STORE_MAX_COLUMNS)
            ES_FAIL(ctx, ES_ERANGE, "store: %lld label columns with those of '%s'; a store holds "
                    "at most %d", (long long)total, s->path, ES_STORE_MAX_COLUMNS);
    }
    for (int64_t c = 0; c < r->ncols; c++) {
        if (r->colnames[c] && strlen(r->colnames[c]) > ES__MAX_COLUMN_NAME)
            ES_FAIL(ctx, ES_EINVAL, "store: label column name of %zu bytes (at most %d): "
                    "'%.40s...'", strlen(r->colnames[c]), ES__MAX_COLUMN_NAME, r->colnames[c]);
        if (es__h5_bad_name(r->colnames[c]))
            ES_FAIL(ctx, ES_EINVAL, "store: bad label column name '%s' (empty, '.', '..' or "
                    "containing '/')", r->colnames[c] ? r->colnames[c] : "(null)");
        for (int64_t d = 0; d < c; d++)
            if (!strcmp(r->colnames[c], r->colnames[d]))
                ES_FAIL(ctx, ES_EINVAL, "store: label column '%s' given twice",
                        r->colnames[c]);
    }
    if ((rc = es__strmap_init(ctx, &batch, r->n))) return rc;
    for (int64_t i = 0; i < r->n && rc == ES_OK; i++) {
        const char *id = r->ids[i];
        int64_t first = -1;
        if (!id || !*id)
            rc = es__fail(ctx, ES_EINVAL, "store: row %lld has an empty id", (long long)i);
        else if (es_store_find_row(s, id) >= 0)
            rc = es__fail(ctx, ES_EEXIST, "store: id '%s' exists already in '%s'", id, s->path);
        else if ((rc = es__strmap_put(ctx, &batch, id, i, &first)) == ES_OK && first >= 0)
            rc = es__fail(ctx, ES_EEXIST, "store: id '%s' is given twice", id);
        else if (rc == ES_OK && !written)
            rc = check_values(ctx, s, r, i);
    }
    es__strmap_clear(ctx, &batch);
    return rc;
}

/* Add label columns the store does not have yet ("" in existing rows). */
static es_status add_columns(es_ctx *ctx, es_store *s, const es_store_rows *r, es__h5_id g)
{
    es_status rc;
    for (int64_t c = 0; c < r->ncols; c++) {
        const char *name = r->colnames[c];
        char **vals, ***labels, **names;
        if (es_store_find_column(s, name) >= 0) continue;
        if (!(names = es__realloc(ctx, s->colnames, (size_t)(s->ncols + 1) * sizeof *names)))
            return ES_ENOMEM;
        s->colnames = names;
        if (!(labels = es__realloc(ctx, s->labels, (size_t)(s->ncols + 1) * sizeof *labels)))
            return ES_ENOMEM;
        s->labels = labels;
        if (!(vals = es__alloc_array(ctx, s->cap ? s->cap : 1, sizeof *vals))) return ES_ENOMEM;
        s->labels[s->ncols] = vals;
        if (!(s->colnames[s->ncols] = es__strdup(ctx, name))) return ES_ENOMEM;
        s->ncols++;
        for (int64_t i = 0; i < s->nrows; i++)
            if (!(vals[i] = es__strdup(ctx, ""))) return ES_ENOMEM;
        if ((rc = es__h5_create_rows(ctx, g, name, ES__H5_STR, 1, 0, 0, 16))) return rc;
        if (s->nrows > 0 &&
            (rc = es__h5_append_strs(ctx, g, name, s->nrows, (const char *const *)vals)))
            return rc;
    }
    return es__h5_write_attr_strs(ctx, g, "columns", (const char *const *)s->colnames, s->ncols);
}

static es_status append_impl(es_ctx *ctx, es_store *s, const es_store_rows *r, bool written)
{
    es_status rc;
    es__h5_id g = -1;
    const char **tmp = NULL;
    int64_t n = r->n, n0 = s->nrows;
    if ((rc = validate_rows(ctx, s, r, written))) return rc;
    if (n == 0 && r->ncols == 0) return ES_OK;
    if ((rc = es__store_begin_write(s))) return rc;
    if ((rc = es__store_reserve_rows(s, n0 + n))) return rc;
    /* From here a failure leaves the working copy half-written: mark it. */
    if ((g = es__h5_group_open(s->file, "/labels")) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot open /labels");
        goto done;
    }
    if ((rc = add_columns(ctx, s, r, g))) goto done;
    if ((rc = es__store_reserve_rows(s, n0 + n))) goto done;
    if (n == 0) goto done;
    if (!written && ((s->nedges > 0 &&
         ((rc = es__h5_append_f64(ctx, s->file, "/shapes/lengths", n, r->lengths)) ||
          (rc = es__h5_append_f64(ctx, s->file, "/shapes/scales", n, r->scales)))) ||
        (rc = es__h5_append_f64(ctx, s->file, "/shapes/positions", n, r->xyz))))
        goto done;
    if (!(tmp = es__alloc_array(ctx, n, sizeof *tmp))) { rc = ES_ENOMEM; goto done; }
    for (int64_t i = 0; i < n; i++)
        tmp[i] = r->source_paths && r->source_paths[i] ? r->source_paths[i] : "";
    if ((rc = es__h5_append_strs(ctx, s->file, "/shapes/ids", n,
                                 (const char *const *)r->ids)) ||
        (rc = es__h5_append_strs(ctx, s->file, "/shapes/source_paths", n, tmp)))
        goto done;
    for (int64_t i = 0; i < n; i++)
        tmp[i] = r->content_hashes && r->content_hashes[i] ? r->content_hashes[i] : "";
    if ((rc = es__h5_append_strs(ctx, s->file, "/shapes/content_hash", n, tmp))) goto done;
    for (int64_t c = 0; c < s->ncols; c++) {
        int64_t rc_col = -1;
        for (int64_t k = 0; k < r->ncols; k++)
            if (!strcmp(r->colnames[k], s->colnames[c])) rc_col = k;
        for (int64_t i = 0; i < n; i++)
            tmp[i] = rc_col >= 0 ? r->labels[i * r->ncols + rc_col] : "";
        if ((rc = es__h5_append_strs(ctx, g, s->colnames[c], n, tmp))) goto done;
        for (int64_t i = 0; i < n; i++)
            if (!(s->labels[c][n0 + i] = es__strdup(ctx, tmp[i]))) { rc = ES_ENOMEM; goto done; }
    }
    for (int64_t i = 0; i < n; i++) {
        const char *src = r->source_paths && r->source_paths[i] ? r->source_paths[i] : "";
        const char *h = r->content_hashes && r->content_hashes[i] ? r->content_hashes[i] : "";
        if (!(s->ids[n0 + i] = es__strdup(ctx, r->ids[i])) ||
            !(s->sources[n0 + i] = es__strdup(ctx, src)) ||
            !(s->hashes[n0 + i] = es__strdup(ctx, h))) {
            rc = ES_ENOMEM;
            break;
        }
        if ((rc = es__strmap_put(ctx, &s->id_rows, s->ids[n0 + i], n0 + i, NULL))) break;
        s->nrows++;
    }
done:
    if (rc != ES_OK) {
        /* Keep the in-memory strings of unfinished rows from leaking. */
        for (int64_t i = s->nrows; i < s->cap; i++) {
            for (int64_t c = 0; c < s->ncols; c++) {
                es__free(ctx, s->labels[c][i]);
                s->labels[c][i] = NULL;
            }
            es__free(ctx, s->ids[i]);
            es__free(ctx, s->sources[i]);
            es__free(ctx, s->hashes[i]);
            s->ids[i] = s->sources[i] = s->hashes[i] = NULL;
        }
        s->broken = true;
    }
    es__free(ctx, tmp);
    es__h5_close(g);
    return rc;
}

es_status es_store_append(es_ctx *ctx, es_store *store, const es_store_rows *rows)
{
    es_status rc;
    if (!store || !rows) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument to es_store_append");
    ES__H5_QUIET(rc = append_impl(ctx, store, rows, false));
    return rc;
}

es_status es__store_append_written(es_ctx *ctx, es_store *s, const es_store_rows *r)
{
    es_status rc;
    ES__H5_QUIET(rc = append_impl(ctx, s, r, true));
    return rc;
}

es_status es__store_reserve_values(es_ctx *ctx, es_store *s, int64_t n)
{
    es_status rc;
    if ((rc = es__store_begin_write(s))) return rc;
    es__h5_quiet q;
    es__h5_quiet_begin(&q);
    if ((s->nedges > 0 &&
         ((rc = es__h5_append_room(ctx, s->file, "/shapes/lengths", n)) ||
          (rc = es__h5_append_room(ctx, s->file, "/shapes/scales", n)))) ||
        (rc = es__h5_append_room(ctx, s->file, "/shapes/positions", n)) ||
        (s->nedges > 0 &&
         ((rc = es__h5_allocate_rows(ctx, s->file, "/shapes/lengths", s->nrows, n)) ||
          (rc = es__h5_allocate_rows(ctx, s->file, "/shapes/scales", s->nrows, n)))) ||
        (rc = es__h5_allocate_rows(ctx, s->file, "/shapes/positions", s->nrows, n)))
        s->broken = true;
    es__h5_quiet_end(&q);
    return rc;
}

void es_store_column_hint(const es_store *s, const char *name, char *buf, size_t n)
{
    es__suggest sg;
    es__suggest_init(&sg, name);
    for (int64_t c = 0; s && c < s->ncols; c++) es__suggest_add(&sg, s->colnames[c]);
    es__suggest_format(&sg, "columns", buf, n);
}

void es_store_value_hint(const es_store *s, int64_t col, const char *value, char *buf, size_t n)
{
    es__suggest sg;
    es__suggest_init(&sg, value);
    if (s && col < s->ncols && col >= -1)
        for (int64_t i = 0; i < s->nrows; i++)
            es__suggest_add(&sg, col < 0 ? s->ids[i] : s->labels[col][i]);
    es__suggest_format(&sg, col < 0 ? "ids" : "values", buf, n);
}

/* es_free's each name and the array. */
static void free_names(es_ctx *ctx, char **names, int64_t n)
{
    for (int64_t i = 0; i < n; i++) es_free(ctx, names[i]);
    es_free(ctx, names);
}

void es_store_result_hint(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                          char *buf, size_t n)
{
    char **names = NULL, what[160], saved[1024];
    int64_t count = 0;
    if (!n) return;
    buf[0] = '\0';
    if (!s || !kind) return;
    snprintf(saved, sizeof saved, "%s", es_ctx_errmsg(ctx));   /* listing may fail: keep it */
    if (es_store_list_results(ctx, s, kind, &names, &count) == ES_OK && count > 0) {
        es__suggest sg;
        es__suggest_init(&sg, name ? name : "");
        for (int64_t i = 0; i < count; i++) es__suggest_add(&sg, names[i]);
        snprintf(what, sizeof what, "%s results", kind);
        es__suggest_format(&sg, what, buf, n);
    } else if (es_store_list_results(ctx, s, NULL, &names, &count) == ES_OK && count > 0) {
        size_t at = (size_t)snprintf(buf, n, " (no %s results; the store has:", kind);
        for (int64_t i = 0; i < count && at < n; i++)
            at += (size_t)snprintf(buf + at, n - at, "%s %s", i ? "," : "", names[i]);
        if (at < n) snprintf(buf + at, n - at, ")");
    } else {
        snprintf(buf, n, " (the store holds no results)");
    }
    if (names) free_names(ctx, names, count);
    es__fail(ctx, ES_OK, "%s", saved);
}

/* The row filter's names stop at ',' or '=', its unquoted values at ','. */
static int filter_name_char(char c) { return c != ',' && c != '='; }
static int filter_value_char(char c) { return c != ','; }

es_status es_store_select(es_ctx *ctx, const es_store *s, const char *filter, int64_t **rows,
                          int64_t *nrows)
{
    int64_t *out, n = 0, nterms = 0;
    int64_t cols[32];
    const char *vals[32];
    size_t vlen[32];
    *rows = NULL;
    *nrows = 0;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    /* terms column=value separated by ','; blanks are part of names and
     * values, so the scanner skips none */
    es__scan sc;
    es__scan_init(&sc, ctx, filter ? filter : "", "store", "the end of the filter",
                  ES__SCAN_SPACE_NONE);
    while (!es__scan_at_end(&sc)) {
        const char *p = sc.s + sc.pos, *eq = NULL, *w = NULL;
        char name[ES__MAX_COLUMN_NAME + 1];
        size_t wl = 0;
        bool quoted = false;
        es__scan_span(&sc, filter_name_char);
        if (es__scan_peek(&sc) == '=') {
            eq = sc.s + sc.pos++;
            /* col="value" may hold ',' (labels with commas); "" is a value */
            es__scan_result q = es__scan_quoted(&sc, &w, &wl);
            quoted = q != ES__SCAN_NONE;
            if (q == ES__SCAN_UNTERMINATED ||
                (quoted && !es__scan_at_end(&sc) && es__scan_peek(&sc) != ','))
                ES_FAIL(ctx, ES_EFORMAT, "store: bad quoted value in filter '%s'", filter);
            if (!quoted) es__scan_span(&sc, filter_value_char);
        }
        const char *end = sc.s + sc.pos;
        if (!eq || eq == p)
            ES_FAIL(ctx, ES_EFORMAT, "store: bad filter term '%.*s' (want column=value)",
                    (int)(end - p), p);
        if (nterms == 32) ES_FAIL(ctx, ES_ERANGE, "store: more than 32 filter terms");
        /* (a longer name was cut short and matched another column) */
        if ((size_t)(eq - p) >= sizeof name)
            ES_FAIL(ctx, ES_ENOTFOUND, "store: no label column '%.40s...' in '%s' (a name of "
                    "%zu bytes; columns have at most %d)", p, s->path, (size_t)(eq - p),
                    ES__MAX_COLUMN_NAME);
        snprintf(name, sizeof name, "%.*s", (int)(eq - p), p);
        if ((cols[nterms] = es_store_find_column(s, name)) < 0) {
            char hint[400];
            if (!strcmp(name, "id")) cols[nterms] = -2;
            else {
                es_store_column_hint(s, name, hint, sizeof hint);
                ES_FAIL(ctx, ES_ENOTFOUND, "store: no label column '%s' in '%s'%s", name,
                        s->path, hint);
            }
        }
        vals[nterms] = eq + 1 + quoted;
        vlen[nterms] = (size_t)(end - eq - 1) - 2 * (size_t)quoted;
        nterms++;
        es__scan_accept(&sc, ',');
    }
    if (!(out = es__alloc_array(ctx, s->nrows ? s->nrows : 1, sizeof *out))) return ES_ENOMEM;
    for (int64_t i = 0; i < s->nrows; i++) {
        bool ok = true;
        for (int64_t k = 0; k < nterms && ok; k++) {
            const char *v = cols[k] == -2 ? s->ids[i] : s->labels[cols[k]][i];
            ok = strlen(v) == vlen[k] && !memcmp(v, vals[k], vlen[k]);
        }
        if (ok) out[n++] = i;
    }
    /* nothing selected: a value no row has is most likely misspelt */
    for (int64_t k = 0; n == 0 && k < nterms; k++) {
        bool any = false;
        for (int64_t i = 0; i < s->nrows && !any; i++) {
            const char *v = cols[k] == -2 ? s->ids[i] : s->labels[cols[k]][i];
            any = strlen(v) == vlen[k] && !memcmp(v, vals[k], vlen[k]);
        }
        if (!any && s->nrows > 0) {
            char value[256], hint[400];
            const int64_t col = cols[k] == -2 ? -1 : cols[k];
            snprintf(value, sizeof value, "%.*s", (int)vlen[k], vals[k]);
            es_store_value_hint(s, col, value, hint, sizeof hint);
            es__warn(ctx, "store: no row has %s='%s'%s", col < 0 ? "id" : s->colnames[col],
                     value, hint);
        }
    }
    *rows = out;
    *nrows = n;
    return ES_OK;
}
