/* lib/store/store_results.c — analysis results in a store: each result is
 * a group /analysis/<kind>/<name> begun with its provenance (command, tool
 * version, time, parameters, the rows it used) and filled with datasets
 * (matrices, vectors, integers, strings) and string attributes, read back
 * by path, tested for, listed and deleted.
 *
 * Paths are at most 8 components, each checked like an HDF5 link name, so
 * a result path from a command line can neither climb out of /analysis nor
 * make HDF5 parse "." or "..". A matrix is stored as a cols x rows dataset,
 * the bytes of its column-major memory unchanged (as /shapes/lengths is
 * N x E); h5py and numpy read its transpose. Writes go through the working
 * copy (store_publish.c); a failed write marks the handle broken.
 */
#include "store/store_pkg.h"
#include "store/store_private.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Split "a/b/c" into validated components; returns how many (max 8). */
int es__result_split(es_ctx *ctx, const char *path, char parts[8][128], es_status *rc)
{
    int n = 0;
    *rc = ES_OK;
    for (const char *p = path; p;) {
        const char *slash = strchr(p, '/');
        size_t len = slash ? (size_t)(slash - p) : strlen(p);
        if (n == 8 || len == 0 || len >= 128 || (len == 1 && p[0] == '.') ||
            (len == 2 && p[0] == '.' && p[1] == '.')) {
            *rc = es__fail(ctx, ES_EINVAL, "store: bad result path '%s'", path ? path : "");
            return -1;
        }
        memcpy(parts[n], p, len);
        parts[n][len] = '\0';
        n++;
        p = slash ? slash + 1 : NULL;
    }
    return n;
}

/* Whether every component of full exists in file (the store's, or a
 * result file beside it: fpath names it). Each object below /analysis is
 * checked (its header by h5_headers.c, a group's symbol table by
 * h5_groups.c) before HDF5 looks the next name up in it or opens it: a
 * result's groups and datasets come from the file like everything else.
 * ES_OK with *exists, or the check's refusal. */
es_status es__result_find_link(es_ctx *ctx, es__h5_id file, const char *fpath, const char *full,
                               bool *exists)
{
    char buf[1200];
    size_t n = strlen(full);
    int depth = 0;
    es__h5_raw *raw = NULL;
    es_status rc = ES_OK;
    *exists = false;
    if (n >= sizeof buf) return ES_OK;
    memcpy(buf, full, n + 1);
    for (char *p = buf + 1; rc == ES_OK; p++) {
        if (*p != '/' && *p != '\0') continue;
        char save = *p;
        *p = '\0';
        if (es__h5_exists(file, buf) <= 0) break;
        if (++depth >= 2) {   /* /analysis itself was checked at open */
            if ((raw || (rc = es__h5_raw_open(ctx, file, fpath, &raw)) == ES_OK) &&
                (rc = es__h5_check_named(raw, file, buf)) == ES_OK && save) {
                es__h5_id g = es__h5_group_open(file, buf);
                if (g >= 0) {
                    rc = es__h5_check_group(raw, g, buf);
                    es__h5_close(g);
                }
            }
            if (rc != ES_OK) break;
        }
        if (!save) {
            *exists = true;
            break;
        }
        *p = save;
    }
    es__h5_raw_close(raw);
    return rc;
}

void es__result_full_path(char *buf, size_t n, const char *rel)
{
    snprintf(buf, n, "/analysis/%s", rel);
}


/* The file that holds result path rel ("kind/name[/...]"), *f, named *fpath
 * in messages: for a store of format 3 the result's own file beside it
 * (store_beside.c), else (and for a result a format-3 store holds inside)
 * the store. ES__RESULT_READ: as this handle sees it; ES__RESULT_WRITE_BEGUN: to write into a
 * result begun through this handle; ES__RESULT_CREATE: to begin one. Writes into the
 * store itself switch it to its working copy (store_publish.c). */
es_status es__result_locate(es_ctx *ctx, es_store *s, const char *rel, int how, es__h5_id *f,
                        const char **fpath)
{
    char parts[8][128];
    es_status rc;
    int np = es__result_split(ctx, rel, parts, &rc);
    if (np < 0) return rc;
    *f = s->file;
    *fpath = s->path;
    if (s->beside && np >= 2) {
        if (how != ES__RESULT_READ && s->mode == ES_STORE_READ)
            ES_FAIL(ctx, ES_EINVAL, "store: '%s' is open read-only", s->path);
        if (how != ES__RESULT_READ && s->broken)
            ES_FAIL(ctx, ES_EIO, "store: an earlier write to '%s' failed; reopen the store",
                    s->path);
        es__h5_id g;
        const char *gp;
        if ((rc = es__beside_file(s, parts[0], parts[1], how == ES__RESULT_CREATE, &g, &gp))) return rc;
        if (how == ES__RESULT_WRITE_BEGUN && !es__beside_writing(s, parts[0], parts[1]))
            ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object /analysis/%s/%s: it was not "
                    "begun (es_store_result_begin)", parts[0], parts[1]);
        if (g >= 0 || how != ES__RESULT_READ) {
            *f = g;
            *fpath = gp;
        }
        return ES_OK;
    }
    if (how != ES__RESULT_READ && (rc = es__store_begin_write(s))) return rc;
    *f = s->file;
    return ES_OK;
}

/* The name must be free unless the handle replaces results. */
static es_status check_free(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            bool *exists)
{
    char full[600];
    es_status rc;
    if ((rc = es__result_name_check(ctx, kind, name)) != ES_OK) return rc;
    snprintf(full, sizeof full, "/analysis/%s/%s", kind, name);
    es__h5_id f;
    const char *fp;
    if ((rc = es__result_locate(ctx, s, full + 10, ES__RESULT_READ, &f, &fp)) ||
        (rc = es__result_find_link(ctx, f, fp, full, exists)))
        return rc;
    if (*exists && s->mode != ES_STORE_REPLACE)
        ES_FAIL(ctx, ES_EEXIST, "store: result %s/%s exists already in '%s' (give another name, "
                "or replace it: --replace, replace=True in Python)", kind, name, s->path);
    return ES_OK;
}

es_status es_store_result_check(es_ctx *ctx, es_store *s, const char *kind, const char *name)
{
    es_status rc;
    bool exists;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = check_free(ctx, s, kind, name, &exists));
    return rc;
}

static es_status result_begin_impl(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                   const es_provenance *prov)
{
    char full[600], when[32];
    es__h5_id g = -1;
    es_status rc;
    time_t now = time(NULL);
    struct tm tmv;
    int64_t *all = NULL;
    bool exists;
    if ((rc = check_free(ctx, s, kind, name, &exists))) return rc;
    if (!prov || !prov->command) ES_FAIL(ctx, ES_EINVAL, "store: a result needs provenance");
    if (prov->rows)
        for (int64_t i = 0; i < prov->nrows; i++)
            if (prov->rows[i] < 0 || prov->rows[i] >= s->nrows)
                ES_FAIL(ctx, ES_ERANGE, "store: provenance row %lld is out of range",
                        (long long)prov->rows[i]);
    snprintf(full, sizeof full, "/analysis/%s/%s", kind, name);
    es__h5_id f;
    const char *fp;
    if ((rc = es__result_locate(ctx, s, full + 10, ES__RESULT_CREATE, &f, &fp))) return rc;
    /* beside the store: whether this handle's working file has it already
     * (begun twice); inside it, check_free looked in the very same bytes
     * (and a working copy is not searched raw: that flushes it) */
    if (s->beside && (rc = es__result_find_link(ctx, f, fp, full, &exists))) return rc;
    if (exists && es__h5_delete(f, full) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot replace %s", full);
        goto fail;
    }
    if ((g = es__h5_group_create(f, full, true)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create %s", full);
        goto fail;
    }
    gmtime_r(&now, &tmv);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    if ((rc = es__h5_write_attr_str(ctx, g, "command", prov->command)) ||
        (rc = es__h5_write_attr_str(ctx, g, "tool_version", "edgespace " ES_VERSION_STRING)) ||
        (rc = es__h5_write_attr_str(ctx, g, "time", when)) ||
        (rc = es__h5_write_attr_str(ctx, g, "params", prov->params ? prov->params : "")) ||
        (rc = es__h5_write_attr_i64(ctx, g, "store_nrows", s->nrows)))
        goto fail;
    {
        /* input_rows is a dataset, not an attribute: it can exceed 64 KiB. */
        int64_t nr = prov->rows ? prov->nrows : s->nrows;
        const int64_t *rows = prov->rows;
        const uint64_t d = (uint64_t)nr;
        if (!rows) {
            if (!(all = es__alloc_array(ctx, nr ? nr : 1, sizeof *all))) {
                rc = ES_ENOMEM;
                goto fail;
            }
            for (int64_t i = 0; i < nr; i++) all[i] = i;
            rows = all;
        }
        if (es__h5_put_i64(g, "input_rows", 1, &d, rows, false) < 0) {
            rc = es__h5_fail(ctx, ES_EIO, "store: cannot write %s/input_rows", full);
            goto fail;
        }
    }
    es__free(ctx, all);
    es__h5_close(g);
    return ES_OK;
fail:
    es__free(ctx, all);
    es__h5_close(g);
    s->broken = true;
    return rc;
}

es_status es_store_result_begin(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                const es_provenance *prov)
{
    es_status rc;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = result_begin_impl(ctx, s, kind, name, prov));
    return rc;
}

/* Prepare a put: the path must be kind/name/dataset inside a begun result;
 * an existing dataset of that name is removed. */
static es_status put_prepare(es_ctx *ctx, es_store *s, const char *path, char *full, size_t n,
                             es__h5_id *f)
{
    char parts[8][128], group[600];
    es_status rc;
    bool e;
    const char *fp;
    int np = es__result_split(ctx, path, parts, &rc);
    if (np < 0) return rc;
    if (np < 3) ES_FAIL(ctx, ES_EINVAL, "store: '%s' is not kind/name/dataset", path);
    if ((rc = es__result_locate(ctx, s, path, ES__RESULT_WRITE_BEGUN, f, &fp))) return rc;
    snprintf(group, sizeof group, "/analysis/%s/%s", parts[0], parts[1]);
    if ((rc = es__result_find_link(ctx, *f, fp, group, &e))) return rc;
    if (!e)
        ES_FAIL(ctx, ES_ENOTFOUND, "store: result %s/%s was not begun "
                "(es_store_result_begin)", parts[0], parts[1]);
    es__result_full_path(full, n, path);
    if ((rc = es__result_find_link(ctx, *f, fp, full, &e))) return rc;
    if (e && es__h5_delete(*f, full) < 0) {
        s->broken = true;
        return es__h5_fail(ctx, ES_EIO, "store: cannot replace %s", full);
    }
    return ES_OK;
}

/* Doubles f, integers i or strings str, as type says; rank 1 or 2. */
static es_status put_impl(es_ctx *ctx, es_store *s, const char *path, int rank,
                          const uint64_t *dims, es__h5_type type, const double *f,
                          const int64_t *i, const char *const *str)
{
    char full[700];
    es__h5_id file = -1;
    es_status rc = put_prepare(ctx, s, path, full, sizeof full, &file);
    int r;
    if (rc) return rc;
    r = type == ES__H5_F64 ? es__h5_put_f64(file, full, rank, dims, f, true)
        : type == ES__H5_I64 ? es__h5_put_i64(file, full, rank, dims, i, true)
            : es__h5_put_strs(file, full, (int64_t)dims[0], str, true);
    if (r < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write %s", full);
        s->broken = true;
    }
    return rc;
}

es_status es_store_put_matrix(es_ctx *ctx, es_store *s, const char *path, es_mat m)
{
    es_status rc;
    const uint64_t dims[2] = {(uint64_t)m.cols, (uint64_t)m.rows};
    double *packed = NULL;
    const double *src = m.data;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    if (m.rows < 0 || m.cols < 0 || m.ld < m.rows || (!m.data && m.rows * m.cols > 0))
        ES_FAIL(ctx, ES_EINVAL, "store: bad matrix for %s", path ? path : "");
    if (m.ld != m.rows && m.rows > 0 && m.cols > 0) {
        int64_t total;
        if (!es__mul_i64(m.rows, m.cols, &total))
            ES_FAIL(ctx, ES_ERANGE, "store: matrix too large");
        if (!(packed = es__alloc_array(ctx, total, sizeof *packed))) return ES_ENOMEM;
        for (int64_t j = 0; j < m.cols; j++)
            memcpy(packed + j * m.rows, m.data + j * m.ld, (size_t)m.rows * sizeof *packed);
        src = packed;
    }
    ES__H5_QUIET(rc = put_impl(ctx, s, path, 2, dims, ES__H5_F64, src, NULL, NULL));
    es__free(ctx, packed);
    return rc;
}

es_status es_store_put_vector(es_ctx *ctx, es_store *s, const char *path, const double *v,
                              int64_t n)
{
    es_status rc;
    const uint64_t d = (uint64_t)n;
    if (!s || n < 0 || (n > 0 && !v)) ES_FAIL(ctx, ES_EINVAL, "store: bad vector argument");
    ES__H5_QUIET(rc = put_impl(ctx, s, path, 1, &d, ES__H5_F64, v, NULL, NULL));
    return rc;
}

es_status es_store_put_ints(es_ctx *ctx, es_store *s, const char *path, const int64_t *v,
                            int64_t n)
{
    es_status rc;
    const uint64_t d = (uint64_t)n;
    if (!s || n < 0 || (n > 0 && !v)) ES_FAIL(ctx, ES_EINVAL, "store: bad vector argument");
    ES__H5_QUIET(rc = put_impl(ctx, s, path, 1, &d, ES__H5_I64, NULL, v, NULL));
    return rc;
}

es_status es_store_put_strings(es_ctx *ctx, es_store *s, const char *path,
                               const char *const *str, int64_t n)
{
    es_status rc;
    const uint64_t d = (uint64_t)n;
    if (!s || n < 0 || (n > 0 && !str)) ES_FAIL(ctx, ES_EINVAL, "store: bad strings argument");
    for (int64_t i = 0; i < n; i++)
        if (!str[i])
            ES_FAIL(ctx, ES_EINVAL, "store: string %lld of %s is NULL", (long long)i, path);
    ES__H5_QUIET(rc = put_impl(ctx, s, path, 1, &d, ES__H5_STR, NULL, NULL, str));
    return rc;
}

/* What an attribute holds: text, or a number stored as one (float64 or
 * int64) so that readers (h5py, R) get numbers. */
typedef struct attr_value {
    int type;           /* 0 string, 1 float64, 2 int64 */
    const char *s;
    double d;
    int64_t i;
} attr_value;

es_status es__result_find(es_ctx *ctx, es_store *s, const char *path, int how, char *full,
                          size_t n, es__h5_id *f, const char **fpath, bool *exists)
{
    es_status rc = es__result_locate(ctx, s, path, how, f, fpath);
    if (rc) return rc;
    es__result_full_path(full, n, path);
    return es__result_find_link(ctx, *f, *fpath, full, exists);
}

/* The header of obj, every attribute message, checked (h5_headers.c)
 * before HDF5 decodes any of them. */
es_status es__result_check_attrs(es_ctx *ctx, const char *fpath, es__h5_id obj,
                                 const char *full)
{
    es__h5_raw *raw = NULL;
    es_status rc = es__h5_raw_open(ctx, obj, fpath, &raw);
    if (rc == ES_OK) rc = es__h5_check_object(raw, obj, full);
    es__h5_raw_close(raw);
    return rc;
}

static es_status put_attr_impl(es_ctx *ctx, es_store *s, const char *path, const char *key,
                               const attr_value *v)
{
    char parts[8][128], full[700];
    es_status rc;
    es__h5_id obj;
    bool e;
    int np = es__result_split(ctx, path, parts, &rc);
    if (np < 0) return rc;
    if (np < 2 || !key || !*key || (v->type == 0 && !v->s))
        ES_FAIL(ctx, ES_EINVAL, "store: bad attribute '%s' on '%s'", key ? key : "", path);
    es__h5_id f;
    const char *fp;
    if ((rc = es__result_find(ctx, s, path, ES__RESULT_WRITE_BEGUN, full, sizeof full, &f, &fp, &e))) return rc;
    if (!e) ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object %s", full);
    if ((obj = es__h5_object_open(f, full)) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot open %s", full);
    rc = es__result_check_attrs(ctx, fp, obj, full);
    if (rc == ES_OK)
        rc = v->type == 1 ? es__h5_write_attr_f64(ctx, obj, key, v->d)
             : v->type == 2 ? es__h5_write_attr_i64(ctx, obj, key, v->i)
                            : es__h5_write_attr_str(ctx, obj, key, v->s);
    es__h5_close(obj);
    if (rc) s->broken = true;
    return rc;
}

es_status es_store_put_attr(es_ctx *ctx, es_store *s, const char *path, const char *key,
                            const char *value)
{
    es_status rc;
    attr_value v = {0, value, 0, 0};
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = put_attr_impl(ctx, s, path, key, &v));
    return rc;
}

es_status es_store_put_attr_double(es_ctx *ctx, es_store *s, const char *path, const char *key,
                                   double value)
{
    es_status rc;
    attr_value v = {1, NULL, value, 0};
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = put_attr_impl(ctx, s, path, key, &v));
    return rc;
}

es_status es_store_put_attr_int(es_ctx *ctx, es_store *s, const char *path, const char *key,
                                int64_t value)
{
    es_status rc;
    attr_value v = {2, NULL, 0, value};
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = put_attr_impl(ctx, s, path, key, &v));
    return rc;
}

/* Open /analysis/<path> as a dataset of the given rank; dims out. */
static es_status get_open(es_ctx *ctx, es_store *s, const char *path, int rank,
                          es__h5_info *info, es__h5_id *ds)
{
    char parts[8][128], full[700];
    es_status rc;
    bool e;
    es__h5_id f;
    const char *fp;
    (void)parts;
    if ((rc = es__result_find(ctx, s, path, ES__RESULT_READ, full, sizeof full, &f, &fp, &e))) return rc;
    if (!e) ES_FAIL(ctx, ES_ENOTFOUND, "store: no dataset %s", full);
    if ((*ds = es__h5_dataset_open(f, full)) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: %s is not a dataset", full);
    if (es__h5_dataset_info(*ds, info) < 0 || info->rank != rank) {
        es__h5_close(*ds);
        *ds = -1;
        ES_FAIL(ctx, ES_EFORMAT, "store: %s is not of rank %d", full, rank);
    }
    if (rank == 1) info->dims[1] = 1;
    return ES_OK;
}

/* Doubles (f64) or integers into *data. */
static es_status get_impl(es_ctx *ctx, es_store *s, const char *path, int rank, bool f64,
                          void **data, int64_t *d0, int64_t *d1)
{
    es__h5_info in;
    const uint64_t *dims = in.dims;
    es__h5_id ds = -1;
    int64_t total;
    uint64_t need;
    es_status rc = get_open(ctx, s, path, rank, &in, &ds);
    *data = NULL;
    if (rc) return rc;
    /* a number dataset whose storage holds all of it: a crafted dataspace
     * must not size an allocation the file cannot fill */
    if (in.cls != ES__H5_CLASS_FLOAT && in.cls != ES__H5_CLASS_INTEGER) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': /analysis/%s is not numbers", s->path, path);
        goto done;
    }
    if ((rc = es__h5_check_chunks(ctx, ds, s->path, path, in.size))) goto done;
    if (!es__mul_i64((int64_t)dims[0], (int64_t)dims[1], &total) || total < 0 ||
        __builtin_mul_overflow((uint64_t)total, in.size, &need) ||
        es__h5_covered_bytes(ds, rank, in.size) < need) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: /analysis/%s claims more values "
                      "than the file holds", s->path, path);
        goto done;
    }
    if (!(*data = es__alloc_array(ctx, total ? total : 1,
                                  f64 ? sizeof(double) : sizeof(int64_t)))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if (total > 0 && (f64 ? es__h5_dataset_read_f64(ds, *data)
                          : es__h5_dataset_read_i64(ds, *data)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot read %s", path);
        es__free(ctx, *data);
        *data = NULL;
        goto done;
    }
    *d0 = (int64_t)dims[0];
    if (d1) *d1 = (int64_t)dims[1];
done:
    es__h5_close(ds);
    return rc;
}

es_status es_store_get_matrix(es_ctx *ctx, es_store *s, const char *path, es_mat *m)
{
    es_status rc;
    void *data = NULL;
    int64_t cols = 0, rows = 0;
    if (!s || !m) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    ES__H5_QUIET(rc = get_impl(ctx, s, path, 2, true, &data, &cols, &rows));
    if (rc) return rc;
    m->data = data;
    m->rows = rows;
    m->cols = cols;
    m->ld = rows > 0 ? rows : 1;
    return ES_OK;
}

es_status es_store_get_vector(es_ctx *ctx, es_store *s, const char *path, double **v,
                              int64_t *n)
{
    es_status rc;
    void *data = NULL;
    if (!s || !v || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    ES__H5_QUIET(rc = get_impl(ctx, s, path, 1, true, &data, n, NULL));
    *v = data;
    return rc;
}

es_status es_store_get_ints(es_ctx *ctx, es_store *s, const char *path, int64_t **v,
                            int64_t *n)
{
    es_status rc;
    void *data = NULL;
    if (!s || !v || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    ES__H5_QUIET(rc = get_impl(ctx, s, path, 1, false, &data, n, NULL));
    *v = data;
    return rc;
}

static es_status get_strings_impl(es_ctx *ctx, es_store *s, const char *path, char ***out,
                                  int64_t *n)
{
    char full[700];
    es__h5_info in;
    es__h5_id ds = -1;
    es__h5_raw *raw = NULL;
    char **v = NULL;
    int64_t count;
    uint64_t disk, need;
    es_status rc = get_open(ctx, s, path, 1, &in, &ds);
    if (rc) return rc;
    es__result_full_path(full, sizeof full, path);
    count = (int64_t)in.dims[0];
    if (in.cls != ES__H5_CLASS_STRING) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': %s is not strings", s->path, full);
        goto done;
    }
    if ((rc = es__h5_raw_open(ctx, ds, s->path, &raw))) goto done;
    /* the strings' descriptors (or fixed-length strings) must be in the
     * file before an array of their count is allocated */
    disk = in.vlen ? es__h5_raw_vlen_size(raw) : in.size;
    if ((rc = es__h5_check_chunks(ctx, ds, s->path, path, disk))) goto done;
    if (count < 0 || __builtin_mul_overflow((uint64_t)count, disk, &need) ||
        es__h5_covered_bytes(ds, 1, disk) < need) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: %s claims more strings than the "
                      "file holds", s->path, full);
        goto done;
    }
    if (!(v = es__calloc(ctx, (size_t)(count > 0 ? count : 1), sizeof *v))) {
        rc = ES_ENOMEM;
        goto done;
    }
    es__h5_id file = es__h5_file_of(ds);   /* the store, or the result's file beside it */
    rc = es__h5_read_strings(ctx, raw, file, full, count, v);
    es__h5_close(file);
    if (rc != ES_OK) {
        for (int64_t i = 0; i < count; i++) es__free(ctx, v[i]);
        es__free(ctx, v);
        goto done;
    }
    *out = v;
    *n = count;
done:
    es__h5_raw_close(raw);
    es__h5_close(ds);
    return rc;
}

es_status es_store_get_strings(es_ctx *ctx, es_store *s, const char *path, char ***v,
                               int64_t *n)
{
    es_status rc;
    if (!s || !v || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    *v = NULL;
    *n = 0;
    ES__H5_QUIET(rc = get_strings_impl(ctx, s, path, v, n));
    return rc;
}

static es_status get_attr_impl(es_ctx *ctx, es_store *s, const char *path, const char *key,
                               char *buf, size_t n)
{
    char parts[8][128], full[700];
    es_status rc;
    es__h5_id obj;
    bool e;
    es__h5_id f;
    const char *fp;
    (void)parts;
    if ((rc = es__result_find(ctx, s, path, ES__RESULT_READ, full, sizeof full, &f, &fp, &e))) return rc;
    if (!e) ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object %s", full);
    if ((obj = es__h5_object_open(f, full)) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot open %s", full);
    /* HDF5 decodes every attribute of the object to find one: checked first */
    if ((rc = es__result_check_attrs(ctx, fp, obj, full))) {
        es__h5_close(obj);
        return rc;
    }
    if (es__h5_attr_exists(obj, key) <= 0) {
        es__h5_close(obj);
        ES_FAIL(ctx, ES_ENOTFOUND, "store: %s has no attribute '%s'", full, key);
    }
    {
        es__h5_raw *raw = NULL;
        if ((rc = es__h5_raw_open(ctx, obj, fp, &raw)) == ES_OK)
            rc = es__h5_read_attr_text(ctx, raw, obj, key, buf, n);
        es__h5_raw_close(raw);
    }
    es__h5_close(obj);
    return rc;
}

es_status es_store_get_attr(es_ctx *ctx, es_store *s, const char *path, const char *key,
                            char *buf, size_t n)
{
    es_status rc;
    if (!s || !key || !buf) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    ES__H5_QUIET(rc = get_attr_impl(ctx, s, path, key, buf, n));
    return rc;
}

es_status es_store_get_attr_double(es_ctx *ctx, es_store *s, const char *path,
                                   const char *key, double *value)
{
    char buf[128], *end = NULL;
    es_status rc = es_store_get_attr(ctx, s, path, key, buf, sizeof buf);
    if (rc != ES_OK) return rc;
    /* a number, or (stores written before numeric attributes) its text */
    double v = strtod(buf, &end);
    if (end == buf || *end)
        ES_FAIL(ctx, ES_EFORMAT, "store: attribute '%s' of %s is '%s', not a number", key, path,
                buf);
    *value = v;
    return ES_OK;
}
