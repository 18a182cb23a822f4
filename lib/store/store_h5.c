/* lib/store/store_h5.c — the store's thin layer over the HDF5 C API, so the
 * other files of lib/store speak in datasets of rows and attributes rather
 * than dataspaces and property lists.
 *
 * Errors: every caller runs inside H5E_BEGIN_TRY (HDF5 prints nothing), and
 * es__h5_fail appends the innermost message of HDF5's error stack
 * (H5Ewalk2) to ours. Storage: the on-disk types are little-endian
 * (H5T_IEEE_F64LE, H5T_STD_I64LE), strings variable-length UTF-8, and row
 * datasets chunked with an unlimited first dimension so that appending a
 * shape appends a row (datasets-spec/store-format.md).
 */
#include "store/store_pkg.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define CACHE_BYTES (16u << 20)

static herr_t walk_cb(unsigned n, const H5E_error2_t *err, void *data)
{
    char *buf = data;
    if (n == 0 && err->desc) snprintf(buf, 200, "%s", err->desc);
    return 0;
}

/* HDF5's stack runs from the failing API call down to the cause; the
 * innermost entry (n == 0) names the cause ("file signature not found"). */
es_status es__h5_fail(es_ctx *ctx, es_status code, const char *fmt, ...)
{
    char msg[600], inner[200] = "";
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk_cb, inner);
    if (*inner) return es__fail(ctx, code, "%s (HDF5: %s)", msg, inner);
    return es__fail(ctx, code, "%s", msg);
}

void es__h5_close(hid_t id)
{
    if (id < 0) return;
    switch (H5Iget_type(id)) {
    case H5I_FILE: H5Fclose(id); break;
    case H5I_GROUP: H5Gclose(id); break;
    case H5I_DATASET: H5Dclose(id); break;
    case H5I_DATASPACE: H5Sclose(id); break;
    case H5I_DATATYPE: H5Tclose(id); break;
    case H5I_ATTR: H5Aclose(id); break;
    case H5I_GENPROP_LST: H5Pclose(id); break;
    default: break;
    }
}

hid_t es__h5_str_type(void)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0) return t;
    if (H5Tset_size(t, H5T_VARIABLE) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

static hid_t dataset_access(void)
{
    hid_t dapl = H5Pcreate(H5P_DATASET_ACCESS);
    if (dapl >= 0) H5Pset_chunk_cache(dapl, 521, CACHE_BYTES, 1.0);
    return dapl;
}

hid_t es__h5_open_ds(hid_t loc, const char *name)
{
    hid_t dapl = dataset_access(), ds = H5Dopen2(loc, name, dapl);
    es__h5_close(dapl);
    return ds;
}

/* For appends: no chunk cache, so whole chunks go straight from the
 * caller's buffer to the file instead of through a copy per chunk. */
hid_t es__h5_open_ds_nocache(hid_t loc, const char *name)
{
    hid_t dapl = H5Pcreate(H5P_DATASET_ACCESS), ds;
    if (dapl >= 0) H5Pset_chunk_cache(dapl, 0, 0, 1.0);
    ds = H5Dopen2(loc, name, dapl);
    es__h5_close(dapl);
    return ds;
}

/* Rows per chunk so that a chunk is about 1 MiB (at least 1, at most 64):
 * big enough for sequential reads, small enough for the 16 MiB cache. */
static hsize_t chunk_rows(size_t row_bytes)
{
    size_t r = row_bytes ? ((size_t)1 << 20) / row_bytes : 64;
    return r < 1 ? 1 : r > 64 ? 64 : r;
}

es_status es__h5_create_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t ftype, int rank,
                             hsize_t d1, hsize_t d2, size_t elem_bytes)
{
    hsize_t dims[3] = {0, d1, d2}, maxd[3] = {H5S_UNLIMITED, d1, d2}, chunk[3];
    size_t row = elem_bytes * (rank > 1 ? d1 : 1) * (rank > 2 ? d2 : 1);
    hid_t sp = -1, dcpl = -1, ds = -1;
    es_status rc = ES_OK;
    chunk[0] = rank == 1 ? 256 : chunk_rows(row);
    chunk[1] = d1;
    chunk[2] = d2;
    if ((sp = H5Screate_simple(rank, dims, maxd)) < 0 ||
        (dcpl = H5Pcreate(H5P_DATASET_CREATE)) < 0 || H5Pset_chunk(dcpl, rank, chunk) < 0 ||
        (ds = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT)) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create dataset '%s'", name);
    es__h5_close(ds);
    es__h5_close(dcpl);
    es__h5_close(sp);
    return rc;
}

es_status es__h5_append_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t mtype,
                             int64_t n, const void *buf)
{
    hsize_t dims[3], start[3] = {0, 0, 0}, count[3];
    hid_t ds = -1, fsp = -1, msp = -1;
    es_status rc = ES_OK;
    int rank;
    if (n == 0) return ES_OK;
    if ((ds = es__h5_open_ds_nocache(loc, name)) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        (rank = H5Sget_simple_extent_dims(fsp, dims, NULL)) < 1 || rank > 3) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot open dataset '%s'", name);
        goto done;
    }
    es__h5_close(fsp);
    fsp = -1;
    start[0] = dims[0];
    count[0] = (hsize_t)n;
    for (int k = 1; k < rank; k++) count[k] = dims[k];
    dims[0] += (hsize_t)n;
    if (H5Dset_extent(ds, dims) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
        (msp = H5Screate_simple(rank, count, NULL)) < 0 ||
        H5Dwrite(ds, mtype, msp, fsp, H5P_DEFAULT, buf) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot append to dataset '%s'", name);
done:
    es__h5_close(msp);
    es__h5_close(fsp);
    es__h5_close(ds);
    return rc;
}

es_status es__h5_write_attr_i64(es_ctx *ctx, hid_t obj, const char *key, int64_t v)
{
    hid_t sp = -1, a = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((sp = H5Screate(H5S_SCALAR)) < 0 ||
        (a = H5Acreate2(obj, key, H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, H5T_NATIVE_INT64, &v) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    return rc;
}

es_status es__h5_write_attr_f64(es_ctx *ctx, hid_t obj, const char *key, double v)
{
    hid_t sp = -1, a = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((sp = H5Screate(H5S_SCALAR)) < 0 ||
        (a = H5Acreate2(obj, key, H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, H5T_NATIVE_DOUBLE, &v) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    return rc;
}

es_status es__h5_write_attr_str(es_ctx *ctx, hid_t obj, const char *key, const char *v)
{
    hid_t sp = -1, a = -1, t = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((t = es__h5_str_type()) < 0 || (sp = H5Screate(H5S_SCALAR)) < 0 ||
        (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, t, &v) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    es__h5_close(t);
    return rc;
}

es_status es__h5_write_attr_strs(es_ctx *ctx, hid_t obj, const char *key,
                                 const char *const *v, int64_t n)
{
    hsize_t d = (hsize_t)n;
    hid_t sp = -1, a = -1, t = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((t = es__h5_str_type()) < 0 || (sp = n ? H5Screate_simple(1, &d, NULL)
                                        : H5Screate(H5S_NULL)) < 0 ||
        (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (n && H5Awrite(a, t, v) < 0))
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    es__h5_close(t);
    return rc;
}

es_status es__h5_read_attr_i64(es_ctx *ctx, hid_t obj, const char *objname, const char *key,
                               int64_t *v)
{
    hid_t a = H5Aopen(obj, key, H5P_DEFAULT);
    es_status rc = ES_OK;
    if (a < 0) return es__h5_fail(ctx, ES_EFORMAT, "store: %s has no attribute '%s'", objname, key);
    if (H5Aread(a, H5T_NATIVE_INT64, v) < 0)
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s' of %s", key, objname);
    H5Aclose(a);
    return rc;
}

/* Any string attribute (variable or fixed length) into buf, truncated. */
es_status es__h5_read_attr_text(es_ctx *ctx, hid_t obj, const char *key, char *buf, size_t n)
{
    hid_t a = -1, t = -1, mt = -1, sp = -1;
    es_status rc = ES_OK;
    if (n) buf[0] = '\0';
    if ((a = H5Aopen(obj, key, H5P_DEFAULT)) < 0 || (t = H5Aget_type(a)) < 0 ||
        (sp = H5Aget_space(a)) < 0) {
        rc = es__h5_fail(ctx, ES_ENOTFOUND, "store: no attribute '%s'", key);
        goto done;
    }
    if (H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) > 0) {
        char *s = NULL;
        if ((mt = es__h5_str_type()) < 0 || H5Sget_simple_extent_npoints(sp) != 1 ||
            H5Aread(a, mt, &s) < 0) {
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        if (n) snprintf(buf, n, "%s", s ? s : "");
        H5free_memory(s);
    } else if (H5Tget_class(t) == H5T_STRING) {
        size_t len = H5Tget_size(t);
        char *tmp = es__malloc(ctx, len + 1);
        if (!tmp) { rc = ES_ENOMEM; goto done; }
        if ((mt = H5Tcopy(t)) < 0 || H5Aread(a, mt, tmp) < 0) {
            es__free(ctx, tmp);
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        tmp[len] = '\0';
        if (n) snprintf(buf, n, "%s", tmp);
        es__free(ctx, tmp);
    } else if (H5Tget_class(t) == H5T_INTEGER && H5Sget_simple_extent_npoints(sp) == 1) {
        long long v;
        if (H5Aread(a, H5T_NATIVE_LLONG, &v) < 0) {
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        if (n) snprintf(buf, n, "%lld", v);
    } else if (H5Tget_class(t) == H5T_FLOAT && H5Sget_simple_extent_npoints(sp) == 1) {
        double v;
        if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0) {
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        if (n) snprintf(buf, n, "%.17g", v);
    } else {
        rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' is not a string or scalar", key);
    }
done:
    es__h5_close(mt);
    es__h5_close(sp);
    es__h5_close(t);
    es__h5_close(a);
    return rc;
}

/* A whole 1-D string dataset into n freshly allocated C strings. */
es_status es__h5_read_strings(es_ctx *ctx, hid_t loc, const char *name, int64_t n, char **out)
{
    hid_t ds = -1, sp = -1, t = -1;
    hsize_t d = 0;
    char **raw = NULL;
    es_status rc = ES_OK;
    if ((ds = es__h5_open_ds(loc, name)) < 0 || (sp = H5Dget_space(ds)) < 0 ||
        H5Sget_simple_extent_ndims(sp) != 1) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot open string dataset '%s'", name);
        goto done;
    }
    H5Sget_simple_extent_dims(sp, &d, NULL);
    if ((int64_t)d != n) {
        rc = es__fail(ctx, ES_EFORMAT, "store: dataset '%s' has %llu rows, expected %lld",
                      name, (unsigned long long)d, (long long)n);
        goto done;
    }
    if (n == 0) goto done;
    if (!(raw = es__alloc_array(ctx, n, sizeof *raw))) { rc = ES_ENOMEM; goto done; }
    if ((t = es__h5_str_type()) < 0 || H5Dread(ds, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw) < 0) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read dataset '%s'", name);
        es__free(ctx, raw);
        raw = NULL;
        goto done;
    }
    for (int64_t i = 0; i < n; i++) {
        out[i] = es__strdup(ctx, raw[i] ? raw[i] : "");
        if (!out[i]) { rc = ES_ENOMEM; break; }
    }
    H5Dvlen_reclaim(t, sp, H5P_DEFAULT, raw);
done:
    es__free(ctx, raw);
    es__h5_close(t);
    es__h5_close(sp);
    es__h5_close(ds);
    return rc;
}

int64_t es__h5_dataset_rows(hid_t loc, const char *name, int rank_want, hsize_t *dims)
{
    hid_t ds = H5Dopen2(loc, name, H5P_DEFAULT), sp = -1;
    int64_t r = -1;
    if (ds >= 0 && (sp = H5Dget_space(ds)) >= 0 &&
        H5Sget_simple_extent_ndims(sp) == rank_want &&
        H5Sget_simple_extent_dims(sp, dims, NULL) >= 0)
        r = (int64_t)dims[0];
    es__h5_close(sp);
    es__h5_close(ds);
    return r;
}

hid_t es__h5_file_access(void)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    /* Readable by HDF5 1.8 and later (h5py, rhdf5, MATLAB all are). */
    if (fapl >= 0) H5Pset_libver_bounds(fapl, H5F_LIBVER_EARLIEST, H5F_LIBVER_V18);
#if H5_VERSION_GE(1, 10, 7)
    /* Keep HDF5's flock, but do not fail on file systems without it. */
    if (fapl >= 0) H5Pset_file_locking(fapl, 1, 1);
#endif
    return fapl;
}

bool es__h5_bad_name(const char *name)
{
    return !name || !*name || strchr(name, '/') || !strcmp(name, ".") || !strcmp(name, "..");
}

int es_file_is_hdf5(const char *path)
{
    htri_t is = 0;
    if (!path || access(path, F_OK) != 0) return 0;
    H5E_BEGIN_TRY { is = H5Fis_hdf5(path); } H5E_END_TRY
    return is > 0;
}
