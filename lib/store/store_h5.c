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
#define _GNU_SOURCE   /* memfd_create, fallocate */
#include "store/store_pkg.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <sys/mman.h>
#include <stdarg.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define CACHE_BYTES (16u << 20)

/* HDF5's description of the cause. */
static herr_t walk_cb(unsigned n, const H5E_error2_t *err, void *data)
{
    char *buf = data;
    const char *en;
    if (n != 0 || !err->desc) return 0;
    /* the file drivers' "file write failed: time = ..., filename = ...,
     * file descriptor = 5, errno = 28, error message = ..." says, to a
     * user, what failed and the system's reason */
    if ((en = strstr(err->desc, "errno = ")) && strchr(err->desc, ':')) {
        int e = atoi(en + 8);
        snprintf(buf, 200, "%.*s: %s", (int)(strchr(err->desc, ':') - err->desc), err->desc,
                 strerror(e));
    } else {
        snprintf(buf, 200, "%s", err->desc);   /* es__fail keeps it on one line */
    }
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

/* At exit HDF5 closes what is left open; after some failures inside
 * libhdf5 1.10 (an H5Dopen of a corrupt dataset leaks its datatype) that
 * fails, and it prints "HDF5: infinite loop closing library" and a list of
 * its interfaces to stderr unless error printing is off. The library never
 * prints: this runs before HDF5's own exit handler (atexit order is the
 * reverse of registration, and H5open registered HDF5's first) and turns
 * the printing off for that last step only. */
static void quiet_exit(void)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static void init_once(void)
{
    if (H5open() >= 0) atexit(quiet_exit);
}

void es__h5_init(void)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, init_once);
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
    if (H5Dset_extent(ds, dims) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot append to dataset '%s'", name);
        goto done;
    }
    if (!buf) goto done;   /* room only: the ranks write the rows (store_ranks.c) */
    if ((fsp = H5Dget_space(ds)) < 0 ||
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

es_status es__h5_allocate_rows(es_ctx *ctx, hid_t loc, const char *name, int64_t row0,
                               int64_t n)
{
    hsize_t cd[3] = {1, 1, 1}, start[3] = {0, 0, 0}, stride[3] = {1, 1, 1}, count[3] = {1, 1, 1};
    hid_t ds = -1, dcpl = -1, fsp = -1, msp = -1;
    double *zeros = NULL;
    es_status rc = ES_OK;
    int rank;
    if (n <= 0) return ES_OK;
    if ((ds = es__h5_open_ds_nocache(loc, name)) < 0 || (dcpl = H5Dget_create_plist(ds)) < 0 ||
        (fsp = H5Dget_space(ds)) < 0 || (rank = H5Sget_simple_extent_ndims(fsp)) < 1 ||
        rank > 3 || H5Pget_chunk(dcpl, rank, cd) != rank || cd[0] < 1) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot open dataset '%s'", name);
        goto done;
    }
    /* the chunk holding row0 has rows before it (allocated) unless row0 starts one */
    start[0] = ((hsize_t)row0 + cd[0] - 1) / cd[0] * cd[0];
    if (start[0] >= (hsize_t)(row0 + n)) goto done;
    stride[0] = cd[0];
    count[0] = ((hsize_t)(row0 + n) - start[0] + cd[0] - 1) / cd[0];
    if (!(zeros = es__alloc_array(ctx, (int64_t)count[0], sizeof *zeros))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if (H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, stride, count, NULL) < 0 ||
        (msp = H5Screate_simple(1, count, NULL)) < 0 ||
        H5Dwrite(ds, H5T_NATIVE_DOUBLE, msp, fsp, H5P_DEFAULT, zeros) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot make room in dataset '%s'", name);
done:
    es__free(ctx, zeros);
    es__h5_close(msp);
    es__h5_close(fsp);
    es__h5_close(dcpl);
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
    hid_t a = H5Aopen(obj, key, H5P_DEFAULT), t = -1, sp = -1;
    es_status rc = ES_OK;
    if (a < 0) return es__h5_fail(ctx, ES_EFORMAT, "store: %s has no attribute '%s'", objname, key);
    /* one integer: H5Aread writes every element, so a crafted array would
     * overrun v */
    if ((t = H5Aget_type(a)) < 0 || (sp = H5Aget_space(a)) < 0 ||
        H5Tget_class(t) != H5T_INTEGER || H5Sget_simple_extent_type(sp) == H5S_NULL ||
        H5Sget_simple_extent_npoints(sp) != 1)
        rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' of %s is not one integer", key,
                      objname);
    else if (H5Aread(a, H5T_NATIVE_INT64, v) < 0)
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s' of %s", key, objname);
    es__h5_close(sp);
    es__h5_close(t);
    H5Aclose(a);
    return rc;
}

/* A string attribute through the store's own decoder (store_vlen.c); one
 * integer or real as text. */
es_status es__h5_read_attr_text(es_ctx *ctx, es__h5_raw *raw, hid_t obj, const char *key,
                                char *buf, size_t n)
{
    hid_t a = -1, t = -1, sp = -1;
    es_status rc = ES_OK;
    H5T_class_t cls;
    if (n) buf[0] = '\0';
    if ((a = H5Aopen(obj, key, H5P_DEFAULT)) < 0 || (t = H5Aget_type(a)) < 0 ||
        (sp = H5Aget_space(a)) < 0) {
        rc = es__h5_fail(ctx, ES_ENOTFOUND, "store: no attribute '%s'", key);
        goto done;
    }
    cls = H5Tget_class(t);
    if (cls == H5T_STRING) {
        char **s = NULL;
        int64_t ns = 0;
        if ((rc = es__h5_read_attr_strings(ctx, raw, obj, key, &s, &ns))) goto done;
        if (ns != 1)
            rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' holds %lld strings, not one",
                          key, (long long)ns);
        else if (n)
            snprintf(buf, n, "%s", s[0]);
        for (int64_t i = 0; i < ns; i++) es__free(ctx, s[i]);
        es__free(ctx, s);
    } else if ((cls == H5T_INTEGER || cls == H5T_FLOAT) &&
               H5Sget_simple_extent_type(sp) != H5S_NULL &&
               H5Sget_simple_extent_npoints(sp) == 1) {
        long long iv;
        double dv;
        if (H5Aread(a, cls == H5T_INTEGER ? H5T_NATIVE_LLONG : H5T_NATIVE_DOUBLE,
                    cls == H5T_INTEGER ? (void *)&iv : (void *)&dv) < 0) {
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        if (n && cls == H5T_INTEGER) snprintf(buf, n, "%lld", iv);
        else if (n) snprintf(buf, n, "%.17g", dv);
    } else {
        rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' is not a string or scalar", key);
    }
done:
    es__h5_close(sp);
    es__h5_close(t);
    es__h5_close(a);
    return rc;
}

uint64_t es__h5_covered_bytes(hid_t ds, int rank, uint64_t elem)
{
    hid_t dcpl = H5Dget_create_plist(ds), sp = H5Dget_space(ds);
    hsize_t cd[3] = {1, 1, 1}, nchunks = 0;
    uint64_t have = H5Dget_storage_size(ds), per = elem;
    /* (1.10.8's H5Dget_num_chunks refuses H5S_ALL: the dataset's space) */
    if (dcpl >= 0 && H5Pget_nfilters(dcpl) > 0 && H5Pget_layout(dcpl) == H5D_CHUNKED &&
        rank >= 1 && rank <= 3 && H5Pget_chunk(dcpl, rank, cd) == rank && sp >= 0 &&
        H5Dget_num_chunks(ds, sp, &nchunks) >= 0) {
        for (int k = 0; k < rank; k++)
            if (__builtin_mul_overflow(per, (uint64_t)cd[k], &per)) per = UINT64_MAX;
        if (__builtin_mul_overflow(per, (uint64_t)nchunks, &have)) have = UINT64_MAX;
    }
    es__h5_close(sp);
    es__h5_close(dcpl);
    return have;
}

es_status es__h5_check_chunks(es_ctx *ctx, hid_t ds, const char *path, const char *name,
                               uint64_t elem)
{
    hid_t dcpl = H5Dget_create_plist(ds), sp = H5Dget_space(ds);
    hsize_t cd[8], dims[8], maxd[8], n = 0, off[8], size = 0;
    haddr_t addr;
    unsigned mask;
    uint64_t nominal = elem;
    es_status rc = ES_OK;
    int rank;
    if (dcpl < 0 || sp < 0 || (rank = H5Sget_simple_extent_dims(sp, dims, maxd)) < 0 ||
        rank > 8) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: '%s': cannot read the layout of %s", path, name);
        goto done;
    }
    if (H5Pget_layout(dcpl) != H5D_CHUNKED) goto done;
    /* chunks within the fixed dimensions (HDF5 makes them so; a changed byte
     * of the layout message made a 6 KB chunk of positions claim 12 MB, and
     * libhdf5 1.10 read it past its buffer), and a stored chunk of the size
     * they make when nothing compresses it */
    if (H5Pget_chunk(dcpl, rank, cd) != rank) goto bad;
    for (int k = 0; k < rank; k++)
        if (cd[k] < 1 || (maxd[k] != H5S_UNLIMITED && cd[k] > maxd[k]) ||
            __builtin_mul_overflow(nominal, (uint64_t)cd[k], &nominal))
            goto bad;
    if (nominal > ((uint64_t)1 << 32)) goto bad;
    if (H5Pget_nfilters(dcpl) == 0 && H5Dget_num_chunks(ds, sp, &n) >= 0 && n > 0 &&
        (H5Dget_chunk_info(ds, sp, 0, off, &mask, &addr, &size) < 0 || size != nominal))
        goto bad;
    goto done;
bad:
    rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: the chunks of %s do not fit it", path,
                  name);
done:
    es__h5_close(sp);
    es__h5_close(dcpl);
    return rc;
}

/* A file thrown away (an aborted or failed write) is closed into a memory
 * file. Closing flushes HDF5's caches, and when that write fails too (the
 * disk is full: the very failure being handled) libhdf5 1.10.8 frees the
 * file but keeps its identifier, then crashes at exit closing it again
 * (HDFFV-11052, fixed in 1.10.10). What the flush writes into the memory
 * file is deleted with it. A file size limit (RLIMIT_FSIZE) applies to
 * memory files too, so only that fault still reaches the bug. */
static void close_discarded(hid_t file)
{
#if defined(__linux__) && defined(MFD_CLOEXEC)
    void *h = NULL;
    int sink = memfd_create("edgespace-discarded", MFD_CLOEXEC);
    if (sink >= 0 && H5Fget_vfd_handle(file, H5P_DEFAULT, &h) >= 0 && h)
        dup2(sink, *(int *)h);
    if (sink >= 0) close(sink);
#endif
    H5Fclose(file);
}

/* A flush that fails leaves libhdf5 1.10.8's metadata cache unable to
 * flush again ("slist already enabled?"), so the file can then be neither
 * kept nor discarded: its close fails and the crash above follows at exit
 * (`export --statismo` onto a nearly full disk printed its error, then
 * segfaulted). So the flush must not meet a full disk: the blocks of the
 * whole file, and a margin for what the flush appends, are reserved first
 * (fallocate, keeping the size), and a disk without them is found here,
 * where the file can still be discarded. 0, or the errno that refused. */
static int reserve_space(hid_t file)
{
#if defined(__linux__) && defined(FALLOC_FL_KEEP_SIZE)
    hid_t fapl = H5Fget_access_plist(file);
    int sec2 = fapl >= 0 && H5Pget_driver(fapl) == H5FD_SEC2;
    hsize_t size = 0;
    void *h = NULL;
    es__h5_close(fapl);
    if (!sec2 || H5Fget_filesize(file, &size) < 0 ||
        H5Fget_vfd_handle(file, H5P_DEFAULT, &h) < 0 || !h)
        return 0;
    if (fallocate(*(int *)h, FALLOC_FL_KEEP_SIZE, 0, (off_t)size + (4 << 10)) != 0 &&
        (errno == ENOSPC || errno == EDQUOT || errno == EFBIG))
        return errno;
#else
    (void)file;
#endif
    return 0;   /* reserved, or a file system without fallocate: best effort */
}

es_status es__h5_file_close(es_ctx *ctx, hid_t file, bool keep, const char *path)
{
    int e;
    if (file < 0) return ES_OK;
    if (!keep) {
        close_discarded(file);
        return ES_OK;
    }
    if ((e = reserve_space(file)) != 0) {
        close_discarded(file);
        ES_FAIL(ctx, ES_EIO, "cannot write '%s': %s", path, strerror(e));
    }
    if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) {
        es_status rc = es__h5_fail(ctx, ES_EIO, "cannot write '%s'", path);
        close_discarded(file);
        return rc;
    }
    if (H5Fclose(file) < 0) return es__h5_fail(ctx, ES_EIO, "cannot write '%s'", path);
    return ES_OK;
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

int es_store_is_hdf5(const char *path)
{
    htri_t is = 0;
    if (!path || access(path, F_OK) != 0) return 0;
    H5E_BEGIN_TRY { is = H5Fis_hdf5(path); } H5E_END_TRY
    return is > 0;
}
