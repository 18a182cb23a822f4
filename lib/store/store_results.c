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
 * checked (its header by store_headers.c, a group's symbol table by
 * store_groups.c) before HDF5 looks the next name up in it or opens it: a
 * result's groups and datasets come from the file like everything else.
 * ES_OK with *exists, or the check's refusal. */
es_status es__result_find_link(es_ctx *ctx, hid_t file, const char *fpath, const char *full,
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
        if (H5Lexists(file, buf, H5P_DEFAULT) <= 0) break;
        if (++depth >= 2) {   /* /analysis itself was checked at open */
            if ((raw || (rc = es__h5_raw_open(ctx, file, fpath, &raw)) == ES_OK) &&
                (rc = es__h5_check_named(raw, file, buf)) == ES_OK && save) {
                hid_t g = H5Gopen2(file, buf, H5P_DEFAULT);
                if (g >= 0) {
                    rc = es__h5_check_group(raw, g, buf);
                    H5Gclose(g);
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
es_status es__result_locate(es_ctx *ctx, es_store *s, const char *rel, int how, hid_t *f,
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
        hid_t g;
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
    hid_t f;
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
    H5E_BEGIN_TRY { rc = check_free(ctx, s, kind, name, &exists); } H5E_END_TRY
    return rc;
}

static es_status result_begin_impl(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                   const es_provenance *prov)
{
    char full[600], when[32];
    hid_t g = -1, lcpl = -1;
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
    hid_t f;
    const char *fp;
    if ((rc = es__result_locate(ctx, s, full + 10, ES__RESULT_CREATE, &f, &fp))) return rc;
    /* beside the store: whether this handle's working file has it already
     * (begun twice); inside it, check_free looked in the very same bytes
     * (and a working copy is not searched raw: that flushes it) */
    if (s->beside && (rc = es__result_find_link(ctx, f, fp, full, &exists))) return rc;
    if (exists && H5Ldelete(f, full, H5P_DEFAULT) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot replace %s", full);
        goto fail;
    }
    if ((lcpl = H5Pcreate(H5P_LINK_CREATE)) < 0 || H5Pset_create_intermediate_group(lcpl, 1) < 0 ||
        (g = H5Gcreate2(f, full, lcpl, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
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
        hsize_t d = (hsize_t)nr;
        hid_t sp = -1, ds = -1;
        if (!rows) {
            if (!(all = es__alloc_array(ctx, nr ? nr : 1, sizeof *all))) {
                rc = ES_ENOMEM;
                goto fail;
            }
            for (int64_t i = 0; i < nr; i++) all[i] = i;
            rows = all;
        }
        if ((sp = H5Screate_simple(1, &d, NULL)) < 0 ||
            (ds = H5Dcreate2(g, "input_rows", H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                             H5P_DEFAULT)) < 0 ||
            (nr > 0 && H5Dwrite(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) < 0))
            rc = es__h5_fail(ctx, ES_EIO, "store: cannot write %s/input_rows", full);
        es__h5_close(ds);
        es__h5_close(sp);
        if (rc) goto fail;
    }
    es__free(ctx, all);
    es__h5_close(g);
    es__h5_close(lcpl);
    return ES_OK;
fail:
    es__free(ctx, all);
    es__h5_close(g);
    es__h5_close(lcpl);
    s->broken = true;
    return rc;
}

es_status es_store_result_begin(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                const es_provenance *prov)
{
    es_status rc;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    H5E_BEGIN_TRY { rc = result_begin_impl(ctx, s, kind, name, prov); } H5E_END_TRY
    return rc;
}

/* Prepare a put: the path must be kind/name/dataset inside a begun result;
 * an existing dataset of that name is removed. */
static es_status put_prepare(es_ctx *ctx, es_store *s, const char *path, char *full, size_t n,
                             hid_t *f)
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
    if (e && H5Ldelete(*f, full, H5P_DEFAULT) < 0) {
        s->broken = true;
        return es__h5_fail(ctx, ES_EIO, "store: cannot replace %s", full);
    }
    return ES_OK;
}

static es_status put_impl(es_ctx *ctx, es_store *s, const char *path, int rank,
                          const hsize_t *dims, hid_t ftype, hid_t mtype, const void *buf)
{
    char full[700];
    hid_t sp = -1, ds = -1, lcpl = -1, f = -1;
    es_status rc = put_prepare(ctx, s, path, full, sizeof full, &f);
    hsize_t total = 1;
    if (rc) return rc;
    for (int k = 0; k < rank; k++) total *= dims[k];
    if ((lcpl = H5Pcreate(H5P_LINK_CREATE)) < 0 || H5Pset_create_intermediate_group(lcpl, 1) < 0 ||
        (sp = H5Screate_simple(rank, dims, NULL)) < 0 ||
        (ds = H5Dcreate2(f, full, ftype, sp, lcpl, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (total > 0 && H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write %s", full);
        s->broken = true;
    }
    es__h5_close(ds);
    es__h5_close(sp);
    es__h5_close(lcpl);
    return rc;
}

es_status es_store_put_matrix(es_ctx *ctx, es_store *s, const char *path, es_mat m)
{
    es_status rc;
    hsize_t dims[2] = {(hsize_t)m.cols, (hsize_t)m.rows};
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
    H5E_BEGIN_TRY {
        rc = put_impl(ctx, s, path, 2, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, src);
    } H5E_END_TRY
    es__free(ctx, packed);
    return rc;
}

es_status es_store_put_vector(es_ctx *ctx, es_store *s, const char *path, const double *v,
                              int64_t n)
{
    es_status rc;
    hsize_t d = (hsize_t)n;
    if (!s || n < 0 || (n > 0 && !v)) ES_FAIL(ctx, ES_EINVAL, "store: bad vector argument");
    H5E_BEGIN_TRY { rc = put_impl(ctx, s, path, 1, &d, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, v); }
    H5E_END_TRY
    return rc;
}

es_status es_store_put_ints(es_ctx *ctx, es_store *s, const char *path, const int64_t *v,
                            int64_t n)
{
    es_status rc;
    hsize_t d = (hsize_t)n;
    if (!s || n < 0 || (n > 0 && !v)) ES_FAIL(ctx, ES_EINVAL, "store: bad vector argument");
    H5E_BEGIN_TRY { rc = put_impl(ctx, s, path, 1, &d, H5T_STD_I64LE, H5T_NATIVE_INT64, v); }
    H5E_END_TRY
    return rc;
}

es_status es_store_put_strings(es_ctx *ctx, es_store *s, const char *path,
                               const char *const *str, int64_t n)
{
    es_status rc;
    hsize_t d = (hsize_t)n;
    hid_t t;
    if (!s || n < 0 || (n > 0 && !str)) ES_FAIL(ctx, ES_EINVAL, "store: bad strings argument");
    for (int64_t i = 0; i < n; i++)
        if (!str[i])
            ES_FAIL(ctx, ES_EINVAL, "store: string %lld of %s is NULL", (long long)i, path);
    H5E_BEGIN_TRY {
        t = es__h5_str_type();
        rc = t < 0 ? es__h5_fail(ctx, ES_EIO, "store: string type") :
                     put_impl(ctx, s, path, 1, &d, t, t, str);
        es__h5_close(t);
    } H5E_END_TRY
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
                          size_t n, hid_t *f, const char **fpath, bool *exists)
{
    es_status rc = es__result_locate(ctx, s, path, how, f, fpath);
    if (rc) return rc;
    es__result_full_path(full, n, path);
    return es__result_find_link(ctx, *f, *fpath, full, exists);
}

/* The header of obj, every attribute message, checked (store_headers.c)
 * before HDF5 decodes any of them. */
es_status es__result_check_attrs(es_ctx *ctx, const char *fpath, hid_t obj, const char *full)
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
    hid_t obj;
    bool e;
    int np = es__result_split(ctx, path, parts, &rc);
    if (np < 0) return rc;
    if (np < 2 || !key || !*key || (v->type == 0 && !v->s))
        ES_FAIL(ctx, ES_EINVAL, "store: bad attribute '%s' on '%s'", key ? key : "", path);
    hid_t f;
    const char *fp;
    if ((rc = es__result_find(ctx, s, path, ES__RESULT_WRITE_BEGUN, full, sizeof full, &f, &fp, &e))) return rc;
    if (!e) ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object %s", full);
    if ((obj = H5Oopen(f, full, H5P_DEFAULT)) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot open %s", full);
    rc = es__result_check_attrs(ctx, fp, obj, full);
    if (rc == ES_OK)
        rc = v->type == 1 ? es__h5_write_attr_f64(ctx, obj, key, v->d)
             : v->type == 2 ? es__h5_write_attr_i64(ctx, obj, key, v->i)
                            : es__h5_write_attr_str(ctx, obj, key, v->s);
    H5Oclose(obj);
    if (rc) s->broken = true;
    return rc;
}

es_status es_store_put_attr(es_ctx *ctx, es_store *s, const char *path, const char *key,
                            const char *value)
{
    es_status rc;
    attr_value v = {0, value, 0, 0};
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    H5E_BEGIN_TRY { rc = put_attr_impl(ctx, s, path, key, &v); } H5E_END_TRY
    return rc;
}

es_status es_store_put_attr_double(es_ctx *ctx, es_store *s, const char *path, const char *key,
                                   double value)
{
    es_status rc;
    attr_value v = {1, NULL, value, 0};
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    H5E_BEGIN_TRY { rc = put_attr_impl(ctx, s, path, key, &v); } H5E_END_TRY
    return rc;
}

es_status es_store_put_attr_int(es_ctx *ctx, es_store *s, const char *path, const char *key,
                                int64_t value)
{
    es_status rc;
    attr_value v = {2, NULL, 0, value};
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    H5E_BEGIN_TRY { rc = put_attr_impl(ctx, s, path, key, &v); } H5E_END_TRY
    return rc;
}

/* Open /analysis/<path> as a dataset of the given rank; dims out. */
static es_status get_open(es_ctx *ctx, es_store *s, const char *path, int rank, hsize_t *dims,
                          hid_t *ds)
{
    char parts[8][128], full[700];
    es_status rc;
    hid_t sp;
    bool e;
    hid_t f;
    const char *fp;
    (void)parts;
    if ((rc = es__result_find(ctx, s, path, ES__RESULT_READ, full, sizeof full, &f, &fp, &e))) return rc;
    if (!e) ES_FAIL(ctx, ES_ENOTFOUND, "store: no dataset %s", full);
    if ((*ds = H5Dopen2(f, full, H5P_DEFAULT)) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: %s is not a dataset", full);
    sp = H5Dget_space(*ds);
    if (sp < 0 || H5Sget_simple_extent_ndims(sp) != rank) {
        es__h5_close(sp);
        H5Dclose(*ds);
        *ds = -1;
        ES_FAIL(ctx, ES_EFORMAT, "store: %s is not of rank %d", full, rank);
    }
    H5Sget_simple_extent_dims(sp, dims, NULL);
    H5Sclose(sp);
    return ES_OK;
}

static es_status get_impl(es_ctx *ctx, es_store *s, const char *path, int rank, hid_t mtype,
                          size_t elem, void **data, int64_t *d0, int64_t *d1)
{
    hsize_t dims[2] = {0, 1};
    hid_t ds = -1, t = -1;
    int64_t total;
    uint64_t need;
    es_status rc = get_open(ctx, s, path, rank, dims, &ds);
    *data = NULL;
    if (rc) return rc;
    /* a number dataset whose storage holds all of it: a crafted dataspace
     * must not size an allocation the file cannot fill */
    if ((t = H5Dget_type(ds)) < 0 ||
        (H5Tget_class(t) != H5T_FLOAT && H5Tget_class(t) != H5T_INTEGER)) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': /analysis/%s is not numbers", s->path, path);
        goto done;
    }
    if ((rc = es__h5_check_chunks(ctx, ds, s->path, path, H5Tget_size(t)))) goto done;
    if (!es__mul_i64((int64_t)dims[0], (int64_t)dims[1], &total) || total < 0 ||
        __builtin_mul_overflow((uint64_t)total, (uint64_t)H5Tget_size(t), &need) ||
        es__h5_covered_bytes(ds, rank, H5Tget_size(t)) < need) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: /analysis/%s claims more values "
                      "than the file holds", s->path, path);
        goto done;
    }
    if (!(*data = es__alloc_array(ctx, total ? total : 1, elem))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if (total > 0 && H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, *data) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot read %s", path);
        es__free(ctx, *data);
        *data = NULL;
        goto done;
    }
    *d0 = (int64_t)dims[0];
    if (d1) *d1 = (int64_t)dims[1];
done:
    es__h5_close(t);
    H5Dclose(ds);
    return rc;
}

es_status es_store_get_matrix(es_ctx *ctx, es_store *s, const char *path, es_mat *m)
{
    es_status rc;
    void *data = NULL;
    int64_t cols = 0, rows = 0;
    if (!s || !m) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    H5E_BEGIN_TRY {
        rc = get_impl(ctx, s, path, 2, H5T_NATIVE_DOUBLE, sizeof(double), &data, &cols, &rows);
    } H5E_END_TRY
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
    H5E_BEGIN_TRY {
        rc = get_impl(ctx, s, path, 1, H5T_NATIVE_DOUBLE, sizeof(double), &data, n, NULL);
    } H5E_END_TRY
    *v = data;
    return rc;
}

es_status es_store_get_ints(es_ctx *ctx, es_store *s, const char *path, int64_t **v,
                            int64_t *n)
{
    es_status rc;
    void *data = NULL;
    if (!s || !v || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    H5E_BEGIN_TRY {
        rc = get_impl(ctx, s, path, 1, H5T_NATIVE_INT64, sizeof(int64_t), &data, n, NULL);
    } H5E_END_TRY
    *v = data;
    return rc;
}

static es_status get_strings_impl(es_ctx *ctx, es_store *s, const char *path, char ***out,
                                  int64_t *n)
{
    char full[700];
    hsize_t dims[2] = {0, 1};
    hid_t ds = -1, t = -1;
    es__h5_raw *raw = NULL;
    char **v = NULL;
    int64_t count;
    uint64_t disk, need;
    es_status rc = get_open(ctx, s, path, 1, dims, &ds);
    if (rc) return rc;
    es__result_full_path(full, sizeof full, path);
    count = (int64_t)dims[0];
    if ((t = H5Dget_type(ds)) < 0 || H5Tget_class(t) != H5T_STRING) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': %s is not strings", s->path, full);
        goto done;
    }
    if ((rc = es__h5_raw_open(ctx, ds, s->path, &raw))) goto done;
    /* the strings' descriptors (or fixed-length strings) must be in the
     * file before an array of their count is allocated */
    disk = H5Tis_variable_str(t) > 0 ? es__h5_raw_vlen_size(raw) : H5Tget_size(t);
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
    hid_t file = H5Iget_file_id(ds);   /* the store, or the result's file beside it */
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
    es__h5_close(t);
    H5Dclose(ds);
    return rc;
}

es_status es_store_get_strings(es_ctx *ctx, es_store *s, const char *path, char ***v,
                               int64_t *n)
{
    es_status rc;
    if (!s || !v || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    *v = NULL;
    *n = 0;
    H5E_BEGIN_TRY { rc = get_strings_impl(ctx, s, path, v, n); } H5E_END_TRY
    return rc;
}

static es_status get_attr_impl(es_ctx *ctx, es_store *s, const char *path, const char *key,
                               char *buf, size_t n)
{
    char parts[8][128], full[700];
    es_status rc;
    hid_t obj;
    bool e;
    hid_t f;
    const char *fp;
    (void)parts;
    if ((rc = es__result_find(ctx, s, path, ES__RESULT_READ, full, sizeof full, &f, &fp, &e))) return rc;
    if (!e) ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object %s", full);
    if ((obj = H5Oopen(f, full, H5P_DEFAULT)) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot open %s", full);
    /* HDF5 decodes every attribute of the object to find one: checked first */
    if ((rc = es__result_check_attrs(ctx, fp, obj, full))) {
        H5Oclose(obj);
        return rc;
    }
    if (H5Aexists(obj, key) <= 0) {
        H5Oclose(obj);
        ES_FAIL(ctx, ES_ENOTFOUND, "store: %s has no attribute '%s'", full, key);
    }
    {
        es__h5_raw *raw = NULL;
        if ((rc = es__h5_raw_open(ctx, obj, fp, &raw)) == ES_OK)
            rc = es__h5_read_attr_text(ctx, raw, obj, key, buf, n);
        es__h5_raw_close(raw);
    }
    H5Oclose(obj);
    return rc;
}

es_status es_store_get_attr(es_ctx *ctx, es_store *s, const char *path, const char *key,
                            char *buf, size_t n)
{
    es_status rc;
    if (!s || !key || !buf) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    H5E_BEGIN_TRY { rc = get_attr_impl(ctx, s, path, key, buf, n); } H5E_END_TRY
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
