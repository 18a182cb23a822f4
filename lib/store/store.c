/* lib/store/store.c — the HDF5 shape store (datasets-spec/store-format.md).
 *
 * One HDF5 file: a format version at the root, the topology, per-shape rows
 * (normalized lengths N x E, scales, positions N x V x 3, ids, source paths,
 * content hashes), string label columns, and analysis results with their
 * provenance. This is the only file of the library that includes hdf5.h;
 * every HDF5 call runs with HDF5's own error printing off
 * (H5E_BEGIN_TRY/H5E_END_TRY around each public entry point), and the
 * innermost message of HDF5's error stack (H5Ewalk2) is appended to ours.
 *
 * Crash safety. The store file itself is never written in place. A handle
 * opened for writing reads the original until its first write; then it
 * copies the file to a temporary sibling ".<name>.tmp-<pid>-<n>" and every
 * write goes to the copy. es_store_commit (also done by es_store_close)
 * flushes and closes the copy, fsyncs it, and rename()s it over the
 * original, then fsyncs the directory: a reader sees the old store or the
 * new one, never a mix, and a process killed at any moment leaves the
 * original byte-for-byte as it was plus, at worst, a stale temporary that
 * the next writer removes (its pid is dead). A new store is made the same
 * way and published with link(), which refuses to clobber a file that
 * appeared meanwhile. If the original changed under us (another writer
 * committed first), commit refuses rather than silently losing its work.
 * This is the approach of SQLite's rollback-free "write a new file, then
 * rename" mode used by editors and package managers; HDF5 1.10 has no
 * transactional writes of its own.
 */
#include "core/core_private.h"
#include "store/store_pkg.h"

#include <hdf5.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <stdint.h>
#include <time.h>
#include <unistd.h>

/* Version 1: meshes only. Version 2 adds the root attribute topology_kind
 * ("mesh", "truss", "none"): faces may be empty (truss: an edge list of
 * landmark pairs), and so may edges (none: landmark configurations only, no
 * /shapes/lengths or /shapes/scales). Mesh stores are still written as
 * version 1, byte-compatible with earlier releases; both versions are read. */
#define FORMAT_VERSION 1
#define FORMAT_VERSION_KIND 2
#define CACHE_BYTES (16u << 20)

struct es_store {
    es_ctx *ctx;
    char *path;            /* the store as named by the user */
    char *work;            /* working copy (writes) or NULL */
    hid_t file;
    es_store_mode mode;
    bool is_new;           /* created by es_store_create, not yet published */
    bool broken;           /* a write failed half-way: never commit */
    struct stat orig;      /* identity of the original when it was copied */
    struct stat opened;    /* identity of the file the in-memory rows came from */
    unsigned tmp_counter;
    int64_t nrows, nverts, nfaces, nedges;
    es_topology_kind kind;
    char fingerprint[17];
    char **ids, **sources, **hashes; /* nrows each */
    int64_t cap;
    int64_t ncols;
    char **colnames;
    char ***labels;        /* labels[col][row] */
};

/* ---- errors ------------------------------------------------------------ */

static herr_t walk_cb(unsigned n, const H5E_error2_t *err, void *data)
{
    char *buf = data;
    if (n == 0 && err->desc) snprintf(buf, 200, "%s", err->desc);
    return 0;
}

/* Our message plus the innermost HDF5 message, if the stack has one. Call
 * right after the failing HDF5 call, before any other. */
static es_status h5fail(es_ctx *ctx, es_status code, const char *fmt, ...) ES__PRINTF(3, 4);
static es_status h5fail(es_ctx *ctx, es_status code, const char *fmt, ...)
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


static void close_id(hid_t id)
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

/* ---- small HDF5 helpers ------------------------------------------------ */

static hid_t str_type(void)
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

static hid_t open_ds(hid_t loc, const char *name)
{
    hid_t dapl = dataset_access(), ds = H5Dopen2(loc, name, dapl);
    close_id(dapl);
    return ds;
}

/* For appends: no chunk cache, so whole chunks go straight from the
 * caller's buffer to the file instead of through a copy per chunk. */
static hid_t open_ds_nocache(hid_t loc, const char *name)
{
    hid_t dapl = H5Pcreate(H5P_DATASET_ACCESS), ds;
    if (dapl >= 0) H5Pset_chunk_cache(dapl, 0, 0, 1.0);
    ds = H5Dopen2(loc, name, dapl);
    close_id(dapl);
    return ds;
}

/* Rows per chunk so that a chunk is about 1 MiB (at least 1, at most 64). */
static hsize_t chunk_rows(size_t row_bytes)
{
    size_t r = row_bytes ? ((size_t)1 << 20) / row_bytes : 64;
    return r < 1 ? 1 : r > 64 ? 64 : r;
}

/* An empty, row-extendable dataset of rank 1..3 with the given row shape. */
static es_status create_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t ftype, int rank,
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
        rc = h5fail(ctx, ES_EIO, "store: cannot create dataset '%s'", name);
    close_id(ds);
    close_id(dcpl);
    close_id(sp);
    return rc;
}

/* Append n rows from buf (memory type mtype, row shape of the dataset). */
static es_status append_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t mtype,
                             int64_t n, const void *buf)
{
    hsize_t dims[3], start[3] = {0, 0, 0}, count[3];
    hid_t ds = -1, fsp = -1, msp = -1;
    es_status rc = ES_OK;
    int rank;
    if (n == 0) return ES_OK;
    if ((ds = open_ds_nocache(loc, name)) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        (rank = H5Sget_simple_extent_dims(fsp, dims, NULL)) < 1 || rank > 3) {
        rc = h5fail(ctx, ES_EFORMAT, "store: cannot open dataset '%s'", name);
        goto done;
    }
    close_id(fsp);
    fsp = -1;
    start[0] = dims[0];
    count[0] = (hsize_t)n;
    for (int k = 1; k < rank; k++) count[k] = dims[k];
    dims[0] += (hsize_t)n;
    if (H5Dset_extent(ds, dims) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
        (msp = H5Screate_simple(rank, count, NULL)) < 0 ||
        H5Dwrite(ds, mtype, msp, fsp, H5P_DEFAULT, buf) < 0)
        rc = h5fail(ctx, ES_EIO, "store: cannot append to dataset '%s'", name);
done:
    close_id(msp);
    close_id(fsp);
    close_id(ds);
    return rc;
}

static es_status write_attr_i64(es_ctx *ctx, hid_t obj, const char *key, int64_t v)
{
    hid_t sp = -1, a = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((sp = H5Screate(H5S_SCALAR)) < 0 ||
        (a = H5Acreate2(obj, key, H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, H5T_NATIVE_INT64, &v) < 0)
        rc = h5fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    close_id(a);
    close_id(sp);
    return rc;
}

static es_status write_attr_str(es_ctx *ctx, hid_t obj, const char *key, const char *v)
{
    hid_t sp = -1, a = -1, t = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((t = str_type()) < 0 || (sp = H5Screate(H5S_SCALAR)) < 0 ||
        (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, t, &v) < 0)
        rc = h5fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    close_id(a);
    close_id(sp);
    close_id(t);
    return rc;
}

static es_status write_attr_strs(es_ctx *ctx, hid_t obj, const char *key,
                                 const char *const *v, int64_t n)
{
    hsize_t d = (hsize_t)n;
    hid_t sp = -1, a = -1, t = -1;
    es_status rc = ES_OK;
    if (H5Aexists(obj, key) > 0) H5Adelete(obj, key);
    if ((t = str_type()) < 0 || (sp = n ? H5Screate_simple(1, &d, NULL)
                                        : H5Screate(H5S_NULL)) < 0 ||
        (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (n && H5Awrite(a, t, v) < 0))
        rc = h5fail(ctx, ES_EIO, "store: cannot write attribute '%s'", key);
    close_id(a);
    close_id(sp);
    close_id(t);
    return rc;
}

static es_status read_attr_i64(es_ctx *ctx, hid_t obj, const char *objname, const char *key,
                               int64_t *v)
{
    hid_t a = H5Aopen(obj, key, H5P_DEFAULT);
    es_status rc = ES_OK;
    if (a < 0) return h5fail(ctx, ES_EFORMAT, "store: %s has no attribute '%s'", objname, key);
    if (H5Aread(a, H5T_NATIVE_INT64, v) < 0)
        rc = h5fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s' of %s", key, objname);
    H5Aclose(a);
    return rc;
}

/* Any string attribute (variable or fixed length) into buf, truncated. */
static es_status read_attr_text(es_ctx *ctx, hid_t obj, const char *key, char *buf, size_t n)
{
    hid_t a = -1, t = -1, mt = -1, sp = -1;
    es_status rc = ES_OK;
    if (n) buf[0] = '\0';
    if ((a = H5Aopen(obj, key, H5P_DEFAULT)) < 0 || (t = H5Aget_type(a)) < 0 ||
        (sp = H5Aget_space(a)) < 0) {
        rc = h5fail(ctx, ES_ENOTFOUND, "store: no attribute '%s'", key);
        goto done;
    }
    if (H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) > 0) {
        char *s = NULL;
        if ((mt = str_type()) < 0 || H5Sget_simple_extent_npoints(sp) != 1 ||
            H5Aread(a, mt, &s) < 0) {
            rc = h5fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
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
            rc = h5fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        tmp[len] = '\0';
        if (n) snprintf(buf, n, "%s", tmp);
        es__free(ctx, tmp);
    } else if (H5Tget_class(t) == H5T_INTEGER && H5Sget_simple_extent_npoints(sp) == 1) {
        long long v;
        if (H5Aread(a, H5T_NATIVE_LLONG, &v) < 0) {
            rc = h5fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        if (n) snprintf(buf, n, "%lld", v);
    } else if (H5Tget_class(t) == H5T_FLOAT && H5Sget_simple_extent_npoints(sp) == 1) {
        double v;
        if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0) {
            rc = h5fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
            goto done;
        }
        if (n) snprintf(buf, n, "%.17g", v);
    } else {
        rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' is not a string or scalar", key);
    }
done:
    close_id(mt);
    close_id(sp);
    close_id(t);
    close_id(a);
    return rc;
}

/* A whole 1-D string dataset into n freshly allocated C strings. */
static es_status read_strings(es_ctx *ctx, hid_t loc, const char *name, int64_t n, char **out)
{
    hid_t ds = -1, sp = -1, t = -1;
    hsize_t d = 0;
    char **raw = NULL;
    es_status rc = ES_OK;
    if ((ds = open_ds(loc, name)) < 0 || (sp = H5Dget_space(ds)) < 0 ||
        H5Sget_simple_extent_ndims(sp) != 1) {
        rc = h5fail(ctx, ES_EFORMAT, "store: cannot open string dataset '%s'", name);
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
    if ((t = str_type()) < 0 || H5Dread(ds, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw) < 0) {
        rc = h5fail(ctx, ES_EFORMAT, "store: cannot read dataset '%s'", name);
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
    close_id(t);
    close_id(sp);
    close_id(ds);
    return rc;
}

static int64_t dataset_rows(hid_t loc, const char *name, int rank_want, hsize_t *dims)
{
    hid_t ds = H5Dopen2(loc, name, H5P_DEFAULT), sp = -1;
    int64_t r = -1;
    if (ds >= 0 && (sp = H5Dget_space(ds)) >= 0 &&
        H5Sget_simple_extent_ndims(sp) == rank_want &&
        H5Sget_simple_extent_dims(sp, dims, NULL) >= 0)
        r = (int64_t)dims[0];
    close_id(sp);
    close_id(ds);
    return r;
}

/* ---- files: copies, temporaries, commit ----------------------------------- */

static char *path_dir(es_ctx *ctx, const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return es__strdup(ctx, ".");
    size_t n = slash == path ? 1 : (size_t)(slash - path);
    char *d = es__malloc(ctx, n + 1);
    if (d) {
        memcpy(d, path, n);
        d[n] = '\0';
    }
    return d;
}

static const char *path_base(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* Remove ".<base>.tmp-<pid>-<n>" siblings whose process is gone. */
static void clean_stale(const char *path)
{
    char dirbuf[4096], prefix[512];
    const char *base = path_base(path);
    size_t dn = (size_t)(base - path);
    DIR *d;
    struct dirent *e;
    if (dn >= sizeof dirbuf) return;
    if (dn == 0) snprintf(dirbuf, sizeof dirbuf, ".");
    else {
        memcpy(dirbuf, path, dn);
        dirbuf[dn] = '\0';
    }
    snprintf(prefix, sizeof prefix, ".%s.tmp-", base);
    if (!(d = opendir(dirbuf))) return;
    while ((e = readdir(d))) {
        size_t pn = strlen(prefix);
        char *end, full[4608];
        long pid;
        if (strncmp(e->d_name, prefix, pn)) continue;
        pid = strtol(e->d_name + pn, &end, 10);
        if (end == e->d_name + pn || *end != '-' || pid <= 0) continue;
        if (pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
        snprintf(full, sizeof full, "%s/%s", dirbuf, e->d_name);
        unlink(full);
    }
    closedir(d);
}

static char *temp_name(es_store *s)
{
    const char *base = path_base(s->path);
    size_t dn = (size_t)(base - s->path), n = strlen(s->path) + 64;
    char *t = es__malloc(s->ctx, n);
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    /* pid first (stale copies are recognized by it), then enough to keep
     * two handles of one process apart. */
    if (t) snprintf(t, n, "%.*s.%s.tmp-%ld-%lx%lx%u", (int)dn, s->path, base, (long)getpid(),
                    (unsigned long)(uintptr_t)s, (unsigned long)ts.tv_nsec, s->tmp_counter++);
    return t;
}

static es_status copy_file(es_ctx *ctx, const char *src, const char *dst, struct stat *st)
{
    int in = -1, out = -1;
    es_status rc = ES_OK;
    char *buf = NULL;
    if ((in = open(src, O_RDONLY | O_CLOEXEC)) < 0 || fstat(in, st) < 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot read '%s': %s", src, strerror(errno));
        goto done;
    }
    if ((out = open(dst, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, st->st_mode & 07777)) < 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot create working copy '%s': %s", dst,
                      strerror(errno));
        goto done;
    }
    if (!(buf = es__malloc(ctx, 1 << 20))) { rc = ES_ENOMEM; goto done; }
    for (;;) {
        ssize_t r = read(in, buf, 1 << 20), w = 0;
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            rc = es__fail(ctx, ES_EIO, "store: cannot read '%s': %s", src, strerror(errno));
            goto done;
        }
        if (r == 0) break;
        while (w < r) {
            ssize_t k = write(out, buf + w, (size_t)(r - w));
            if (k < 0 && errno == EINTR) continue;
            if (k < 0) {
                rc = es__fail(ctx, ES_EIO, "store: cannot write '%s': %s", dst,
                              strerror(errno));
                goto done;
            }
            w += k;
        }
    }
done:
    es__free(ctx, buf);
    if (in >= 0) close(in);
    if (out >= 0 && close(out) < 0 && rc == ES_OK)
        rc = es__fail(ctx, ES_EIO, "store: cannot write '%s': %s", dst, strerror(errno));
    if (rc != ES_OK && out >= 0) unlink(dst);
    return rc;
}

static es_status fsync_path(es_ctx *ctx, const char *path, bool dir)
{
    int fd = open(path, (dir ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
    if (fd < 0 || (fsync(fd) < 0 && !dir)) {
        int e = errno;
        if (fd >= 0) close(fd);
        ES_FAIL(ctx, ES_EIO, "store: cannot sync '%s': %s", path, strerror(e));
    }
    close(fd);
    return ES_OK;
}

static hid_t file_access(void)
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

static es_status begin_write(es_store *s);

/* ---- loading the row metadata -------------------------------------------- */

static void free_rowmeta(es_store *s)
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
    s->ids = s->sources = s->hashes = s->colnames = NULL;
    s->labels = NULL;
    s->nrows = s->ncols = s->cap = 0;
}

/* Grow the per-row arrays to hold `need` rows. New slots are NULL. */
static es_status reserve_rows(es_store *s, int64_t need)
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

static es_status load_columns(es_store *s)
{
    es_ctx *ctx = s->ctx;
    hid_t g = -1, a = -1, sp = -1, t = -1;
    hssize_t n = 0;
    char **raw = NULL;
    es_status rc = ES_OK;
    if ((g = H5Gopen2(s->file, "/labels", H5P_DEFAULT)) < 0 ||
        (a = H5Aopen(g, "columns", H5P_DEFAULT)) < 0 || (sp = H5Aget_space(a)) < 0) {
        rc = h5fail(ctx, ES_EFORMAT, "store: '%s': /labels lacks its 'columns' attribute",
                    s->path);
        goto done;
    }
    n = H5Sget_simple_extent_type(sp) == H5S_NULL ? 0 : H5Sget_simple_extent_npoints(sp);
    if (n > 0) {
        if (!(raw = es__alloc_array(ctx, n, sizeof *raw)) ||
            !(s->colnames = es__alloc_array(ctx, n, sizeof *s->colnames)) ||
            !(s->labels = es__alloc_array(ctx, n, sizeof *s->labels))) {
            rc = ES_ENOMEM;
            goto done;
        }
        if ((t = str_type()) < 0 || H5Aread(a, t, raw) < 0) {
            rc = h5fail(ctx, ES_EFORMAT, "store: cannot read /labels columns");
            goto done;
        }
        s->ncols = n;
        for (hssize_t c = 0; c < n && rc == ES_OK; c++)
            if (!(s->colnames[c] = es__strdup(ctx, raw[c] ? raw[c] : ""))) rc = ES_ENOMEM;
        H5Dvlen_reclaim(t, sp, H5P_DEFAULT, raw);
        for (hssize_t c = 0; c < n && rc == ES_OK; c++) {
            if (!(s->labels[c] = es__alloc_array(ctx, s->cap ? s->cap : 1, sizeof(char *))))
                rc = ES_ENOMEM;
            else
                rc = read_strings(ctx, g, s->colnames[c], s->nrows, s->labels[c]);
        }
    }
done:
    es__free(ctx, raw);
    close_id(t);
    close_id(sp);
    close_id(a);
    close_id(g);
    return rc;
}

/* Check the format version and the shapes of every dataset; load ids,
 * source paths, hashes and labels. */
static es_status load(es_store *s)
{
    es_ctx *ctx = s->ctx;
    int64_t version = 0, n;
    hsize_t dims[3];
    es_status rc;
    hid_t g;
    char fp[64];
    if ((rc = read_attr_i64(ctx, s->file, "the root group", "format_version", &version)))
        return es__fail(ctx, ES_EFORMAT, "store: '%s' is not an edgespace store (%s)",
                        s->path, es_ctx_errmsg(ctx));
    if (version != FORMAT_VERSION && version != FORMAT_VERSION_KIND)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' has format version %lld; this edgespace reads "
                "versions %d and %d", s->path, (long long)version, FORMAT_VERSION,
                FORMAT_VERSION_KIND);
    s->kind = ES_TOPOLOGY_MESH;
    if (version == FORMAT_VERSION_KIND) {
        char kind[16];
        if (read_attr_text(ctx, s->file, "topology_kind", kind, sizeof kind))
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s' has format version 2 but no topology_kind "
                    "attribute", s->path);
        if (!strcmp(kind, "mesh")) s->kind = ES_TOPOLOGY_MESH;
        else if (!strcmp(kind, "truss")) s->kind = ES_TOPOLOGY_TRUSS;
        else if (!strcmp(kind, "none")) s->kind = ES_TOPOLOGY_NONE;
        else
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s' has topology_kind '%s' (want mesh, truss or "
                    "none)", s->path, kind);
    }
    if ((g = H5Gopen2(s->file, "/topology", H5P_DEFAULT)) < 0)
        return h5fail(ctx, ES_EFORMAT, "store: '%s' has no /topology", s->path);
    rc = read_attr_i64(ctx, g, "/topology", "nverts", &s->nverts);
    if (!rc) rc = read_attr_text(ctx, g, "fingerprint", fp, sizeof fp);
    H5Gclose(g);
    if (rc) return rc;
    snprintf(s->fingerprint, sizeof s->fingerprint, "%.16s", fp);
    if ((s->nfaces = dataset_rows(s->file, "/topology/faces", 2, dims)) < 0 || dims[1] != 3)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /topology/faces is not F x 3", s->path);
    if ((s->nedges = dataset_rows(s->file, "/topology/edges", 2, dims)) < 0 || dims[1] != 2)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /topology/edges is not E x 2", s->path);
    if ((s->kind == ES_TOPOLOGY_MESH) != (s->nfaces > 0) ||
        (s->kind == ES_TOPOLOGY_NONE) != (s->nedges == 0))
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': topology kind '%s' with %lld faces and %lld "
                "edges", s->path, es_topology_kind_name(s->kind), (long long)s->nfaces,
                (long long)s->nedges);
    if (s->kind == ES_TOPOLOGY_NONE) {
        n = dataset_rows(s->file, "/shapes/positions", 3, dims);
        if (n < 0 || (int64_t)dims[1] != s->nverts || dims[2] != 3)
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /shapes/positions is not N x %lld x 3",
                    s->path, (long long)s->nverts);
    } else if ((n = dataset_rows(s->file, "/shapes/lengths", 2, dims)) < 0 ||
               (int64_t)dims[1] != s->nedges) {
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /shapes/lengths is not N x %lld", s->path,
                (long long)s->nedges);
    }
    if (dataset_rows(s->file, "/shapes/positions", 3, dims) != n ||
        (int64_t)dims[1] != s->nverts || dims[2] != 3)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /shapes/positions is not %lld x %lld x 3",
                s->path, (long long)n, (long long)s->nverts);
    if (s->kind != ES_TOPOLOGY_NONE && dataset_rows(s->file, "/shapes/scales", 1, dims) != n)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /shapes/scales does not have %lld rows",
                s->path, (long long)n);
    s->nrows = 0;
    if ((rc = reserve_rows(s, n > 0 ? n : 1))) return rc;
    s->nrows = n;
    if ((rc = read_strings(ctx, s->file, "/shapes/ids", n, s->ids)) ||
        (rc = read_strings(ctx, s->file, "/shapes/source_paths", n, s->sources)) ||
        (rc = read_strings(ctx, s->file, "/shapes/content_hash", n, s->hashes)))
        return rc;
    return load_columns(s);
}

/* ---- open, create, close, commit -------------------------------------- */

static void release(es_store *s, bool keep_work)
{
    if (!s) return;
    es_ctx *ctx = s->ctx;
    if (s->file >= 0) H5Fclose(s->file);
    s->file = -1;
    if (s->work && !keep_work) unlink(s->work);
    free_rowmeta(s);
    es__free(ctx, s->work);
    es__free(ctx, s->path);
    es__free(ctx, s);
}

int es_file_is_hdf5(const char *path)
{
    htri_t is = 0;
    if (!path || access(path, F_OK) != 0) return 0;
    H5E_BEGIN_TRY { is = H5Fis_hdf5(path); } H5E_END_TRY
    return is > 0;
}

static es_status open_impl(es_ctx *ctx, const char *path, es_store_mode mode, es_store **out)
{
    es_store *s;
    es_status rc;
    htri_t is;
    hid_t fapl;
    *out = NULL;
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "store: empty path");
    if (mode != ES_STORE_READ && mode != ES_STORE_WRITE)
        ES_FAIL(ctx, ES_EINVAL, "store: bad open mode %d", (int)mode);
    if (access(path, F_OK) != 0)
        ES_FAIL(ctx, errno == ENOENT ? ES_ENOTFOUND : ES_EIO, "store: cannot open '%s': %s",
                path, strerror(errno));
    if ((is = H5Fis_hdf5(path)) <= 0) {
        if (is < 0) return h5fail(ctx, ES_EIO, "store: cannot read '%s'", path);
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' is not an HDF5 file", path);
    }
    if (!(s = es__calloc(ctx, 1, sizeof *s))) return ES_ENOMEM;
    s->ctx = ctx;
    s->file = -1;
    s->mode = mode;
    if (!(s->path = es__strdup(ctx, path))) { rc = ES_ENOMEM; goto fail; }
    /* Before opening: if another writer replaces the file in between, the
     * first write sees a different identity and refuses (never stale rows). */
    if (stat(path, &s->opened) != 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot open '%s': %s", path, strerror(errno));
        goto fail;
    }
    fapl = file_access();
    s->file = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    close_id(fapl);
    if (s->file < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot open '%s'", path);
        goto fail;
    }
    if ((rc = load(s))) goto fail;
    *out = s;
    return ES_OK;
fail:
    release(s, false);
    return rc;
}

es_status es_store_open(es_ctx *ctx, const char *path, es_store_mode mode, es_store **out)
{
    es_status rc;
    H5E_BEGIN_TRY { rc = open_impl(ctx, path, mode, out); } H5E_END_TRY
    return rc;
}

static es_status create_impl(es_ctx *ctx, const char *path, int64_t nverts, int64_t nfaces,
                             const int64_t *faces, int64_t nedges, const int64_t *edges,
                             const char *fingerprint, es_store **out)
{
    es_store *s;
    es_status rc = ES_OK;
    hid_t fapl = -1, g = -1, sp = -1, ds = -1, t = -1;
    hsize_t d[2];
    char when[32];
    time_t now = time(NULL);
    struct tm tmv;
    *out = NULL;
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "store: empty path");
    if (nverts < 1 || nfaces < 0 || nedges < 0 || (nfaces > 0 && (!faces || nedges < 1)) ||
        (nedges > 0 && !edges))
        ES_FAIL(ctx, ES_EINVAL, "store: bad topology (%lld vertices, %lld faces, %lld "
                "edges)", (long long)nverts, (long long)nfaces, (long long)nedges);
    for (int64_t e = 0; nfaces == 0 && e < nedges; e++) {
        const int64_t *p = edges + 2 * e;
        if (p[0] < 0 || p[0] >= p[1] || p[1] >= nverts ||
            (e > 0 && (p[-2] > p[0] || (p[-2] == p[0] && p[-1] >= p[1]))))
            ES_FAIL(ctx, ES_EINVAL, "store: edge %lld (%lld, %lld) is not a (min, max) pair of "
                    "vertices below %lld in sorted order without repeats", (long long)e,
                    (long long)p[0], (long long)p[1], (long long)nverts);
    }
    if (access(path, F_OK) == 0)
        ES_FAIL(ctx, ES_EEXIST, "store: '%s' exists already", path);
    if (!(s = es__calloc(ctx, 1, sizeof *s))) return ES_ENOMEM;
    s->ctx = ctx;
    s->file = -1;
    s->mode = ES_STORE_WRITE;
    s->is_new = true;
    s->nverts = nverts;
    s->nfaces = nfaces;
    s->nedges = nedges;
    s->kind = nfaces > 0 ? ES_TOPOLOGY_MESH : nedges > 0 ? ES_TOPOLOGY_TRUSS : ES_TOPOLOGY_NONE;
    snprintf(s->fingerprint, sizeof s->fingerprint, "%.16s", fingerprint ? fingerprint : "");
    if (!(s->path = es__strdup(ctx, path)) || !(s->work = temp_name(s))) {
        rc = ES_ENOMEM;
        goto fail;
    }
    clean_stale(path);
    fapl = file_access();
    s->file = H5Fcreate(s->work, H5F_ACC_EXCL, H5P_DEFAULT, fapl);
    if (s->file < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot create '%s'", s->work);
        goto fail;
    }
    gmtime_r(&now, &tmv);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    if ((rc = write_attr_i64(ctx, s->file, "format_version",
                             s->kind == ES_TOPOLOGY_MESH ? FORMAT_VERSION
                                                         : FORMAT_VERSION_KIND)) ||
        (rc = write_attr_str(ctx, s->file, "creator", "edgespace " ES_VERSION_STRING)) ||
        (rc = write_attr_str(ctx, s->file, "created", when)) ||
        (s->kind != ES_TOPOLOGY_MESH &&
         (rc = write_attr_str(ctx, s->file, "topology_kind", es_topology_kind_name(s->kind)))))
        goto fail;
    if ((g = H5Gcreate2(s->file, "/topology", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot create /topology");
        goto fail;
    }
    if ((rc = write_attr_i64(ctx, g, "nverts", nverts)) ||
        (rc = write_attr_str(ctx, g, "fingerprint", s->fingerprint)))
        goto fail;
    d[0] = (hsize_t)nfaces;
    d[1] = 3;
    if ((sp = H5Screate_simple(2, d, NULL)) < 0 ||
        (ds = H5Dcreate2(g, "faces", H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                         H5P_DEFAULT)) < 0 ||
        (nfaces > 0 && H5Dwrite(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, faces) < 0)) {
        rc = h5fail(ctx, ES_EIO, "store: cannot write /topology/faces");
        goto fail;
    }
    close_id(ds);
    close_id(sp);
    ds = sp = -1;
    d[0] = (hsize_t)nedges;
    d[1] = 2;
    if ((sp = H5Screate_simple(2, d, NULL)) < 0 ||
        (ds = H5Dcreate2(g, "edges", H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                         H5P_DEFAULT)) < 0 ||
        (nedges > 0 && H5Dwrite(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, edges) < 0)) {
        rc = h5fail(ctx, ES_EIO, "store: cannot write /topology/edges");
        goto fail;
    }
    close_id(g);
    g = -1;
    if ((g = H5Gcreate2(s->file, "/shapes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (t = str_type()) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot create /shapes");
        goto fail;
    }
    /* HDF5 chunks cannot be 0 wide: a store without edges has no lengths
     * (and no scales, which are sums of raw edge lengths). */
    if ((nedges > 0 &&
         ((rc = create_rows(ctx, g, "lengths", H5T_IEEE_F64LE, 2, (hsize_t)nedges, 0, 8)) ||
          (rc = create_rows(ctx, g, "scales", H5T_IEEE_F64LE, 1, 0, 0, 8)))) ||
        (rc = create_rows(ctx, g, "positions", H5T_IEEE_F64LE, 3, (hsize_t)nverts, 3, 8)) ||
        (rc = create_rows(ctx, g, "ids", t, 1, 0, 0, 16)) ||
        (rc = create_rows(ctx, g, "source_paths", t, 1, 0, 0, 16)) ||
        (rc = create_rows(ctx, g, "content_hash", t, 1, 0, 0, 16)))
        goto fail;
    close_id(g);
    if ((g = H5Gcreate2(s->file, "/labels", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot create /labels");
        goto fail;
    }
    if ((rc = write_attr_strs(ctx, g, "columns", NULL, 0))) goto fail;
    close_id(g);
    if ((g = H5Gcreate2(s->file, "/analysis", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot create /analysis");
        goto fail;
    }
    close_id(g);
    g = -1;
    if ((rc = reserve_rows(s, 1))) goto fail;
    close_id(t);
    close_id(ds);
    close_id(sp);
    close_id(fapl);
    *out = s;
    return ES_OK;
fail:
    close_id(t);
    close_id(g);
    close_id(ds);
    close_id(sp);
    close_id(fapl);
    release(s, false);
    return rc;
}

es_status es__store_create_raw(es_ctx *ctx, const char *path, int64_t nverts, int64_t nfaces,
                               const int64_t *faces, int64_t nedges, const int64_t *edges,
                               const char *fingerprint, es_store **out)
{
    es_status rc;
    H5E_BEGIN_TRY {
        rc = create_impl(ctx, path, nverts, nfaces, faces, nedges, edges, fingerprint, out);
    } H5E_END_TRY
    return rc;
}

/* First write on a handle opened for writing: switch to a working copy. */
static es_status begin_write(es_store *s)
{
    es_ctx *ctx = s->ctx;
    es_status rc;
    hid_t fapl;
    if (s->mode != ES_STORE_WRITE)
        ES_FAIL(ctx, ES_EINVAL, "store: '%s' is open read-only", s->path);
    if (s->broken)
        ES_FAIL(ctx, ES_EIO, "store: an earlier write to '%s' failed; reopen the store",
                s->path);
    if (s->work) return ES_OK;
    clean_stale(s->path);
    if (!(s->work = temp_name(s))) return ES_ENOMEM;
    if ((rc = copy_file(ctx, s->path, s->work, &s->orig))) goto fail;
    if (s->orig.st_ino != s->opened.st_ino || s->orig.st_dev != s->opened.st_dev ||
        s->orig.st_size != s->opened.st_size ||
        s->orig.st_mtim.tv_sec != s->opened.st_mtim.tv_sec ||
        s->orig.st_mtim.tv_nsec != s->opened.st_mtim.tv_nsec) {
        /* Rows, ids and columns in memory are those of the file we opened;
         * writing them onto another writer's newer store would corrupt it. */
        unlink(s->work);
        rc = es__fail(ctx, ES_EIO, "store: '%s' was changed by another writer since it was "
                      "opened; nothing written", s->path);
        goto fail;
    }
    H5Fclose(s->file);
    fapl = file_access();
    s->file = H5Fopen(s->work, H5F_ACC_RDWR, fapl);
    close_id(fapl);
    if (s->file < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot open working copy '%s'", s->work);
        unlink(s->work);
        s->file = H5Fopen(s->path, H5F_ACC_RDONLY, H5P_DEFAULT);
        if (s->file < 0) s->broken = true;
        goto fail;
    }
    return ES_OK;
fail:
    es__free(ctx, s->work);
    s->work = NULL;
    return rc;
}

static es_status commit_impl(es_ctx *ctx, es_store *s)
{
    es_status rc = ES_OK;
    struct stat now, done;
    char *dir = NULL;
    hid_t fapl;
    if (!s->work) return ES_OK; /* nothing written */
    if (s->broken)
        ES_FAIL(ctx, ES_EIO, "store: an earlier write to '%s' failed; nothing committed",
                s->path);
    if (H5Fflush(s->file, H5F_SCOPE_GLOBAL) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot flush '%s'", s->work);
        goto fail;
    }
    if (H5Fclose(s->file) < 0) {
        s->file = -1;
        rc = h5fail(ctx, ES_EIO, "store: cannot close '%s'", s->work);
        goto fail;
    }
    s->file = -1;
    if ((rc = fsync_path(ctx, s->work, false))) goto fail;
    /* the identity the published file will have (link and rename keep the
     * inode): taken now, a commit landing right after ours is not mistaken
     * for the file this handle's rows come from */
    if (stat(s->work, &done) != 0) memset(&done, 0, sizeof done);
    if (s->is_new) {
        /* link() refuses to replace a file that appeared meanwhile. */
        if (link(s->work, s->path) != 0) {
            if (errno == EEXIST) {
                rc = es__fail(ctx, ES_EEXIST, "store: '%s' was created by someone else "
                              "meanwhile; nothing written", s->path);
                goto fail;
            }
            if (access(s->path, F_OK) == 0 || rename(s->work, s->path) != 0) {
                rc = es__fail(ctx, ES_EIO, "store: cannot create '%s': %s", s->path,
                              strerror(errno));
                goto fail;
            }
        } else {
            unlink(s->work);
        }
    } else {
        /* The identity check and the rename are one step for every writer of
         * this folder (an advisory lock on the folder): otherwise another
         * commit landing between them would be replaced unseen. */
        int dfd = -1;
        if ((dir = path_dir(ctx, s->path)) &&
            (dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC)) >= 0)
            while (flock(dfd, LOCK_EX) != 0 && errno == EINTR) {
            }
        /* a folder that cannot be opened or locked (unreadable, some network
         * file systems) leaves the commit unlocked: the identity check alone */
        if (stat(s->path, &now) != 0 || now.st_ino != s->orig.st_ino ||
            now.st_dev != s->orig.st_dev || now.st_size != s->orig.st_size ||
            now.st_mtim.tv_sec != s->orig.st_mtim.tv_sec ||
            now.st_mtim.tv_nsec != s->orig.st_mtim.tv_nsec) {
            rc = es__fail(ctx, ES_EIO, "store: '%s' was changed by another writer since it "
                          "was opened; nothing written", s->path);
        } else if (rename(s->work, s->path) != 0) {
            rc = es__fail(ctx, ES_EIO, "store: cannot replace '%s': %s", s->path,
                          strerror(errno));
        }
        if (dfd >= 0) close(dfd);   /* releases the lock */
        es__free(ctx, dir);
        dir = NULL;
        if (rc != ES_OK) goto fail;
    }
    s->opened = done;
    if ((dir = path_dir(ctx, s->path))) {
        fsync_path(ctx, dir, true);
        es__free(ctx, dir);
    }
    es__free(ctx, s->work);
    s->work = NULL;
    s->is_new = false;
    fapl = file_access();
    s->file = H5Fopen(s->path, H5F_ACC_RDONLY, fapl);
    close_id(fapl);
    if (s->file < 0)
        return h5fail(ctx, ES_EIO, "store: committed '%s' but cannot reopen it", s->path);
    return ES_OK;
fail:
    s->broken = true;
    return rc;
}

es_status es_store_commit(es_ctx *ctx, es_store *store)
{
    es_status rc;
    if (!store) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    H5E_BEGIN_TRY { rc = commit_impl(ctx, store); } H5E_END_TRY
    return rc;
}

void es_store_abort(es_store *store)
{
    if (!store) return;
    H5E_BEGIN_TRY { release(store, false); } H5E_END_TRY
}

void es_store_close(es_store *store)
{
    if (!store) return;
    H5E_BEGIN_TRY {
        if (store->work && !store->broken) {
            es_status rc = commit_impl(store->ctx, store);
            if (rc != ES_OK)
                es__warn(store->ctx, "%s", es_ctx_errmsg(store->ctx));
        }
        release(store, false);
    } H5E_END_TRY
}

/* ---- getters ------------------------------------------------------------ */

int64_t es_store_nrows(const es_store *s) { return s ? s->nrows : 0; }
int64_t es_store_nedges(const es_store *s) { return s ? s->nedges : 0; }
int64_t es_store_nverts(const es_store *s) { return s ? s->nverts : 0; }
int64_t es_store_nfaces(const es_store *s) { return s ? s->nfaces : 0; }
es_topology_kind es_store_topology_kind(const es_store *s)
{
    return s ? s->kind : ES_TOPOLOGY_MESH;
}
const char *es_store_path(const es_store *s) { return s ? s->path : NULL; }
const char *es_store_fingerprint(const es_store *s) { return s ? s->fingerprint : NULL; }

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
    if (!s || !id) return -1;
    for (int64_t i = 0; i < s->nrows; i++)
        if (!strcmp(s->ids[i], id)) return i;
    return -1;
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

/* ---- reading rows ------------------------------------------------------- */

/* Read rows [row0, row0+n) of a 2-D dataset (row length m) into memory
 * laid out as n rows of stride ld >= m. */
static es_status read_block(es_ctx *ctx, es_store *s, const char *name, int64_t row0, int64_t n,
                            int64_t m, double *buf, int64_t ld)
{
    hsize_t fstart[2] = {(hsize_t)row0, 0}, cnt[2] = {(hsize_t)n, (hsize_t)m};
    hsize_t mdims[2] = {(hsize_t)n, (hsize_t)ld}, mstart[2] = {0, 0};
    hid_t ds = -1, fsp = -1, msp = -1;
    es_status rc = ES_OK;
    if (n == 0) return ES_OK;
    if ((ds = open_ds_nocache(s->file, name)) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        H5Sselect_hyperslab(fsp, H5S_SELECT_SET, fstart, NULL, cnt, NULL) < 0 ||
        (msp = H5Screate_simple(2, mdims, NULL)) < 0 ||
        H5Sselect_hyperslab(msp, H5S_SELECT_SET, mstart, NULL, cnt, NULL) < 0 ||
        H5Dread(ds, H5T_NATIVE_DOUBLE, msp, fsp, H5P_DEFAULT, buf) < 0)
        rc = h5fail(ctx, ES_EIO, "store: cannot read rows %lld..%lld of %s in '%s'",
                    (long long)row0, (long long)(row0 + n - 1), name, s->path);
    close_id(msp);
    close_id(fsp);
    close_id(ds);
    return rc;
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
    H5E_BEGIN_TRY { rc = read_lengths_impl(ctx, s, row0, n, out); } H5E_END_TRY
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
    H5E_BEGIN_TRY { rc = read_lengths_rows_impl(ctx, s, rows, nrows, out); } H5E_END_TRY
    return rc;
}

static es_status read_1d(es_ctx *ctx, es_store *s, const char *name, hid_t mtype, void *buf)
{
    hid_t ds;
    es_status rc = ES_OK;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    if ((ds = open_ds(s->file, name)) < 0 ||
        H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
        rc = h5fail(ctx, ES_EIO, "store: cannot read %s of '%s'", name, s->path);
    close_id(ds);
    return rc;
}

es_status es_store_read_scales(es_ctx *ctx, es_store *s, double *scales)
{
    es_status rc = ES_OK;
    if (s && s->nedges == 0) return no_edges(ctx, s);
    if (s && s->nrows == 0) return ES_OK;
    H5E_BEGIN_TRY { rc = read_1d(ctx, s, "/shapes/scales", H5T_NATIVE_DOUBLE, scales); }
    H5E_END_TRY
    return rc;
}

es_status es_store_read_faces(es_ctx *ctx, es_store *s, int64_t *faces)
{
    es_status rc;
    if (s && s->nfaces == 0) return ES_OK;
    H5E_BEGIN_TRY { rc = read_1d(ctx, s, "/topology/faces", H5T_NATIVE_INT64, faces); }
    H5E_END_TRY
    return rc;
}

es_status es_store_read_edges(es_ctx *ctx, es_store *s, int64_t *edges)
{
    es_status rc;
    if (s && s->nedges == 0) return ES_OK;
    H5E_BEGIN_TRY { rc = read_1d(ctx, s, "/topology/edges", H5T_NATIVE_INT64, edges); }
    H5E_END_TRY
    return rc;
}

static es_status read_positions_impl(es_ctx *ctx, es_store *s, int64_t row, double *xyz)
{
    hsize_t start[3] = {(hsize_t)row, 0, 0}, cnt[3] = {1, (hsize_t)s->nverts, 3};
    hid_t ds = -1, fsp = -1, msp = -1;
    es_status rc = ES_OK;
    if (row < 0 || row >= s->nrows)
        ES_FAIL(ctx, ES_ERANGE, "store: row %lld is out of range (store has %lld rows)",
                (long long)row, (long long)s->nrows);
    if ((ds = open_ds(s->file, "/shapes/positions")) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, cnt, NULL) < 0 ||
        (msp = H5Screate_simple(3, cnt, NULL)) < 0 ||
        H5Dread(ds, H5T_NATIVE_DOUBLE, msp, fsp, H5P_DEFAULT, xyz) < 0)
        rc = h5fail(ctx, ES_EIO, "store: cannot read positions of row %lld in '%s'",
                    (long long)row, s->path);
    close_id(msp);
    close_id(fsp);
    close_id(ds);
    return rc;
}

es_status es_store_read_positions(es_ctx *ctx, es_store *s, int64_t row, double *xyz)
{
    es_status rc;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    H5E_BEGIN_TRY { rc = read_positions_impl(ctx, s, row, xyz); } H5E_END_TRY
    return rc;
}

/* ---- appending rows ----------------------------------------------------- */

static bool bad_name(const char *name)
{
    return !name || !*name || strchr(name, '/') || !strcmp(name, ".") || !strcmp(name, "..");
}

static es_status validate_rows(es_ctx *ctx, const es_store *s, const es_store_rows *r)
{
    const bool lens = s->nedges > 0;   /* a store without edges ignores lengths/scales */
    if (r->n < 0 || (r->n > 0 && (!r->ids || (lens && (!r->lengths || !r->scales)) || !r->xyz)) ||
        r->ncols < 0 || (r->ncols > 0 && (!r->colnames || (r->n > 0 && !r->labels))))
        ES_FAIL(ctx, ES_EINVAL, "store: incomplete rows to append");
    for (int64_t c = 0; c < r->ncols; c++) {
        if (bad_name(r->colnames[c]))
            ES_FAIL(ctx, ES_EINVAL, "store: bad label column name '%s' (empty, '.', '..' or "
                    "containing '/')", r->colnames[c] ? r->colnames[c] : "(null)");
        for (int64_t d = 0; d < c; d++)
            if (!strcmp(r->colnames[c], r->colnames[d]))
                ES_FAIL(ctx, ES_EINVAL, "store: label column '%s' given twice",
                        r->colnames[c]);
    }
    for (int64_t i = 0; i < r->n; i++) {
        const char *id = r->ids[i];
        if (!id || !*id) ES_FAIL(ctx, ES_EINVAL, "store: row %lld has an empty id", (long long)i);
        if (es_store_find_row(s, id) >= 0)
            ES_FAIL(ctx, ES_EEXIST, "store: id '%s' exists already in '%s'", id, s->path);
        for (int64_t k = 0; k < i; k++)
            if (!strcmp(r->ids[k], id))
                ES_FAIL(ctx, ES_EEXIST, "store: id '%s' is given twice", id);
        if (lens && (!(r->scales[i] > 0) || !isfinite(r->scales[i])))
            ES_FAIL(ctx, ES_EINVAL, "store: row '%s' has scale %g (must be finite, > 0)", id,
                    r->scales[i]);
        for (int64_t e = 0; e < s->nedges; e++)
            if (!isfinite(r->lengths[e + i * s->nedges]))
                ES_FAIL(ctx, ES_EINVAL, "store: row '%s' has a non-finite length at edge "
                        "%lld", id, (long long)e);
        for (int64_t c = 0; c < r->ncols; c++)
            if (!r->labels[i * r->ncols + c])
                ES_FAIL(ctx, ES_EINVAL, "store: row '%s' lacks a value for column '%s'", id,
                        r->colnames[c]);
    }
    return ES_OK;
}

/* Add label columns the store does not have yet ("" in existing rows). */
static es_status add_columns(es_ctx *ctx, es_store *s, const es_store_rows *r, hid_t g,
                             hid_t t)
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
        if ((rc = create_rows(ctx, g, name, t, 1, 0, 0, 16))) return rc;
        if (s->nrows > 0 && (rc = append_rows(ctx, g, name, t, s->nrows, vals))) return rc;
    }
    return write_attr_strs(ctx, g, "columns", (const char *const *)s->colnames, s->ncols);
}

static es_status append_impl(es_ctx *ctx, es_store *s, const es_store_rows *r)
{
    es_status rc;
    hid_t t = -1, g = -1;
    const char **tmp = NULL;
    int64_t n = r->n, n0 = s->nrows;
    if ((rc = validate_rows(ctx, s, r))) return rc;
    if (n == 0 && r->ncols == 0) return ES_OK;
    if ((rc = begin_write(s))) return rc;
    if ((rc = reserve_rows(s, n0 + n))) return rc;
    /* From here a failure leaves the working copy half-written: mark it. */
    if ((t = str_type()) < 0 || (g = H5Gopen2(s->file, "/labels", H5P_DEFAULT)) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot open /labels");
        goto done;
    }
    if ((rc = add_columns(ctx, s, r, g, t))) goto done;
    if ((rc = reserve_rows(s, n0 + n))) goto done;
    if (n == 0) goto done;
    if ((s->nedges > 0 &&
         ((rc = append_rows(ctx, s->file, "/shapes/lengths", H5T_NATIVE_DOUBLE, n, r->lengths)) ||
          (rc = append_rows(ctx, s->file, "/shapes/scales", H5T_NATIVE_DOUBLE, n, r->scales)))) ||
        (rc = append_rows(ctx, s->file, "/shapes/positions", H5T_NATIVE_DOUBLE, n, r->xyz)))
        goto done;
    if (!(tmp = es__alloc_array(ctx, n, sizeof *tmp))) { rc = ES_ENOMEM; goto done; }
    for (int64_t i = 0; i < n; i++) tmp[i] = r->source_paths && r->source_paths[i] ? r->source_paths[i] : "";
    if ((rc = append_rows(ctx, s->file, "/shapes/ids", t, n, r->ids)) ||
        (rc = append_rows(ctx, s->file, "/shapes/source_paths", t, n, tmp)))
        goto done;
    for (int64_t i = 0; i < n; i++) tmp[i] = r->content_hashes && r->content_hashes[i] ? r->content_hashes[i] : "";
    if ((rc = append_rows(ctx, s->file, "/shapes/content_hash", t, n, tmp))) goto done;
    for (int64_t c = 0; c < s->ncols; c++) {
        int64_t rc_col = -1;
        for (int64_t k = 0; k < r->ncols; k++)
            if (!strcmp(r->colnames[k], s->colnames[c])) rc_col = k;
        for (int64_t i = 0; i < n; i++)
            tmp[i] = rc_col >= 0 ? r->labels[i * r->ncols + rc_col] : "";
        if ((rc = append_rows(ctx, g, s->colnames[c], t, n, tmp))) goto done;
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
    close_id(g);
    close_id(t);
    return rc;
}

es_status es_store_append(es_ctx *ctx, es_store *store, const es_store_rows *rows)
{
    es_status rc;
    if (!store || !rows) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument to es_store_append");
    H5E_BEGIN_TRY { rc = append_impl(ctx, store, rows); } H5E_END_TRY
    return rc;
}

/* ---- selecting rows ----------------------------------------------------- */

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
    for (const char *p = filter; p && *p;) {
        const char *comma = strchr(p, ','), *end = comma ? comma : p + strlen(p);
        const char *eq = memchr(p, '=', (size_t)(end - p));
        char name[256];
        bool quoted = false;
        if (eq && eq[1] == '"') {
            /* col="value" may hold ',' (labels with commas) */
            const char *close = strchr(eq + 2, '"');
            if (!close || (close[1] && close[1] != ','))
                ES_FAIL(ctx, ES_EFORMAT, "store: bad quoted value in filter '%s'", filter);
            quoted = true;
            end = close + 1;
            comma = *end == ',' ? end : NULL;
        }
        if (!eq || eq == p)
            ES_FAIL(ctx, ES_EFORMAT, "store: bad filter term '%.*s' (want column=value)",
                    (int)(end - p), p);
        if (nterms == 32) ES_FAIL(ctx, ES_ERANGE, "store: more than 32 filter terms");
        snprintf(name, sizeof name, "%.*s", (int)(eq - p), p);
        if ((cols[nterms] = es_store_find_column(s, name)) < 0) {
            if (!strcmp(name, "id")) cols[nterms] = -2;
            else
                ES_FAIL(ctx, ES_ENOTFOUND, "store: no label column '%s' in '%s'", name,
                        s->path);
        }
        vals[nterms] = eq + 1 + quoted;
        vlen[nterms] = (size_t)(end - eq - 1) - 2 * (size_t)quoted;
        nterms++;
        p = comma ? comma + 1 : end;
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
    *rows = out;
    *nrows = n;
    return ES_OK;
}

/* ---- analysis results --------------------------------------------------- */

/* Split "a/b/c" into validated components; returns how many (max 8). */
static int split_path(es_ctx *ctx, const char *path, char parts[8][128], es_status *rc)
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

static bool link_exists(hid_t file, const char *full)
{
    char buf[1200];
    size_t n = strlen(full);
    if (n >= sizeof buf) return false;
    memcpy(buf, full, n + 1);
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char save = *p;
            *p = '\0';
            if (H5Lexists(file, buf, H5P_DEFAULT) <= 0) return false;
            if (!save) return true;
            *p = save;
        }
    }
}

static void full_path(char *buf, size_t n, const char *rel)
{
    snprintf(buf, n, "/analysis/%s", rel);
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
    if (bad_name(kind) || bad_name(name) || strlen(kind) > 120 || strlen(name) > 120)
        ES_FAIL(ctx, ES_EINVAL, "store: bad result kind/name '%s/%s'", kind ? kind : "",
                name ? name : "");
    if (!prov || !prov->command) ES_FAIL(ctx, ES_EINVAL, "store: a result needs provenance");
    if (prov->rows)
        for (int64_t i = 0; i < prov->nrows; i++)
            if (prov->rows[i] < 0 || prov->rows[i] >= s->nrows)
                ES_FAIL(ctx, ES_ERANGE, "store: provenance row %lld is out of range",
                        (long long)prov->rows[i]);
    if ((rc = begin_write(s))) return rc;
    snprintf(full, sizeof full, "/analysis/%s/%s", kind, name);
    if (link_exists(s->file, full) && H5Ldelete(s->file, full, H5P_DEFAULT) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot replace %s", full);
        goto fail;
    }
    if ((lcpl = H5Pcreate(H5P_LINK_CREATE)) < 0 || H5Pset_create_intermediate_group(lcpl, 1) < 0 ||
        (g = H5Gcreate2(s->file, full, lcpl, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot create %s", full);
        goto fail;
    }
    gmtime_r(&now, &tmv);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    if ((rc = write_attr_str(ctx, g, "command", prov->command)) ||
        (rc = write_attr_str(ctx, g, "tool_version", "edgespace " ES_VERSION_STRING)) ||
        (rc = write_attr_str(ctx, g, "time", when)) ||
        (rc = write_attr_str(ctx, g, "params", prov->params ? prov->params : "")) ||
        (rc = write_attr_i64(ctx, g, "store_nrows", s->nrows)))
        goto fail;
    {
        /* input_rows is a dataset, not an attribute: it can exceed 64 KiB. */
        int64_t nr = prov->rows ? prov->nrows : s->nrows;
        const int64_t *rows = prov->rows;
        hsize_t d = (hsize_t)nr;
        hid_t sp = -1, ds = -1;
        if (!rows) {
            if (!(all = es__alloc_array(ctx, nr ? nr : 1, sizeof *all))) { rc = ES_ENOMEM; goto fail; }
            for (int64_t i = 0; i < nr; i++) all[i] = i;
            rows = all;
        }
        if ((sp = H5Screate_simple(1, &d, NULL)) < 0 ||
            (ds = H5Dcreate2(g, "input_rows", H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                             H5P_DEFAULT)) < 0 ||
            (nr > 0 && H5Dwrite(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows) < 0))
            rc = h5fail(ctx, ES_EIO, "store: cannot write %s/input_rows", full);
        close_id(ds);
        close_id(sp);
        if (rc) goto fail;
    }
    es__free(ctx, all);
    close_id(g);
    close_id(lcpl);
    return ES_OK;
fail:
    es__free(ctx, all);
    close_id(g);
    close_id(lcpl);
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
static es_status put_prepare(es_ctx *ctx, es_store *s, const char *path, char *full, size_t n)
{
    char parts[8][128], group[600];
    es_status rc;
    int np = split_path(ctx, path, parts, &rc);
    if (np < 0) return rc;
    if (np < 3) ES_FAIL(ctx, ES_EINVAL, "store: '%s' is not kind/name/dataset", path);
    if ((rc = begin_write(s))) return rc;
    snprintf(group, sizeof group, "/analysis/%s/%s", parts[0], parts[1]);
    if (!link_exists(s->file, group))
        ES_FAIL(ctx, ES_ENOTFOUND, "store: result %s/%s was not begun "
                "(es_store_result_begin)", parts[0], parts[1]);
    full_path(full, n, path);
    if (link_exists(s->file, full) && H5Ldelete(s->file, full, H5P_DEFAULT) < 0) {
        s->broken = true;
        return h5fail(ctx, ES_EIO, "store: cannot replace %s", full);
    }
    return ES_OK;
}

static es_status put_impl(es_ctx *ctx, es_store *s, const char *path, int rank,
                          const hsize_t *dims, hid_t ftype, hid_t mtype, const void *buf)
{
    char full[700];
    hid_t sp = -1, ds = -1, lcpl = -1;
    es_status rc = put_prepare(ctx, s, path, full, sizeof full);
    hsize_t total = 1;
    if (rc) return rc;
    for (int k = 0; k < rank; k++) total *= dims[k];
    if ((lcpl = H5Pcreate(H5P_LINK_CREATE)) < 0 || H5Pset_create_intermediate_group(lcpl, 1) < 0 ||
        (sp = H5Screate_simple(rank, dims, NULL)) < 0 ||
        (ds = H5Dcreate2(s->file, full, ftype, sp, lcpl, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (total > 0 && H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)) {
        rc = h5fail(ctx, ES_EIO, "store: cannot write %s", full);
        s->broken = true;
    }
    close_id(ds);
    close_id(sp);
    close_id(lcpl);
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
        if (!str[i]) ES_FAIL(ctx, ES_EINVAL, "store: string %lld of %s is NULL", (long long)i, path);
    H5E_BEGIN_TRY {
        t = str_type();
        rc = t < 0 ? h5fail(ctx, ES_EIO, "store: string type") :
                     put_impl(ctx, s, path, 1, &d, t, t, str);
        close_id(t);
    } H5E_END_TRY
    return rc;
}

static es_status put_attr_impl(es_ctx *ctx, es_store *s, const char *path, const char *key,
                               const char *value)
{
    char parts[8][128], full[700];
    es_status rc;
    hid_t obj;
    int np = split_path(ctx, path, parts, &rc);
    if (np < 0) return rc;
    if (np < 2 || !key || !*key || !value)
        ES_FAIL(ctx, ES_EINVAL, "store: bad attribute '%s' on '%s'", key ? key : "", path);
    if ((rc = begin_write(s))) return rc;
    full_path(full, sizeof full, path);
    if (!link_exists(s->file, full))
        ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object %s", full);
    if ((obj = H5Oopen(s->file, full, H5P_DEFAULT)) < 0)
        return h5fail(ctx, ES_EIO, "store: cannot open %s", full);
    rc = write_attr_str(ctx, obj, key, value);
    H5Oclose(obj);
    if (rc) s->broken = true;
    return rc;
}

es_status es_store_put_attr(es_ctx *ctx, es_store *s, const char *path, const char *key,
                            const char *value)
{
    es_status rc;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    H5E_BEGIN_TRY { rc = put_attr_impl(ctx, s, path, key, value); } H5E_END_TRY
    return rc;
}

/* Open /analysis/<path> as a dataset of the given rank; dims out. */
static es_status get_open(es_ctx *ctx, es_store *s, const char *path, int rank, hsize_t *dims,
                          hid_t *ds)
{
    char parts[8][128], full[700];
    es_status rc;
    hid_t sp;
    if (split_path(ctx, path, parts, &rc) < 0) return rc;
    full_path(full, sizeof full, path);
    if (!link_exists(s->file, full)) ES_FAIL(ctx, ES_ENOTFOUND, "store: no dataset %s", full);
    if ((*ds = H5Dopen2(s->file, full, H5P_DEFAULT)) < 0)
        return h5fail(ctx, ES_EFORMAT, "store: %s is not a dataset", full);
    sp = H5Dget_space(*ds);
    if (sp < 0 || H5Sget_simple_extent_ndims(sp) != rank) {
        close_id(sp);
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
    hid_t ds = -1;
    int64_t total;
    es_status rc = get_open(ctx, s, path, rank, dims, &ds);
    *data = NULL;
    if (rc) return rc;
    if (!es__mul_i64((int64_t)dims[0], (int64_t)dims[1], &total)) {
        H5Dclose(ds);
        ES_FAIL(ctx, ES_ERANGE, "store: %s is too large", path);
    }
    if (!(*data = es__alloc_array(ctx, total ? total : 1, elem))) {
        H5Dclose(ds);
        return ES_ENOMEM;
    }
    if (total > 0 && H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, *data) < 0) {
        rc = h5fail(ctx, ES_EIO, "store: cannot read %s", path);
        es__free(ctx, *data);
        *data = NULL;
    }
    H5Dclose(ds);
    *d0 = (int64_t)dims[0];
    if (d1) *d1 = (int64_t)dims[1];
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

static es_status get_attr_impl(es_ctx *ctx, es_store *s, const char *path, const char *key,
                               char *buf, size_t n)
{
    char parts[8][128], full[700];
    es_status rc;
    hid_t obj;
    if (split_path(ctx, path, parts, &rc) < 0) return rc;
    full_path(full, sizeof full, path);
    if (!link_exists(s->file, full)) ES_FAIL(ctx, ES_ENOTFOUND, "store: no result object %s", full);
    if ((obj = H5Oopen(s->file, full, H5P_DEFAULT)) < 0)
        return h5fail(ctx, ES_EIO, "store: cannot open %s", full);
    if (H5Aexists(obj, key) <= 0) {
        H5Oclose(obj);
        ES_FAIL(ctx, ES_ENOTFOUND, "store: %s has no attribute '%s'", full, key);
    }
    rc = read_attr_text(ctx, obj, key, buf, n);
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

int es_store_has(es_store *s, const char *path)
{
    char full[700];
    int r = 0;
    if (!s || !path || !*path) return 0;
    full_path(full, sizeof full, path);
    H5E_BEGIN_TRY { r = link_exists(s->file, full) ? 1 : 0; } H5E_END_TRY
    return r;
}

typedef struct name_list { es_ctx *ctx; char **names; int64_t n, cap; es_status rc; } name_list;

static herr_t list_cb(hid_t g, const char *name, const H5L_info_t *info, void *data)
{
    name_list *l = data;
    (void)g;
    (void)info;
    if (l->n == l->cap) {
        int64_t cap = l->cap ? 2 * l->cap : 16;
        char **p = es__realloc(l->ctx, l->names, (size_t)cap * sizeof *p);
        if (!p) { l->rc = ES_ENOMEM; return -1; }
        l->names = p;
        l->cap = cap;
    }
    if (!(l->names[l->n] = es__strdup(l->ctx, name))) { l->rc = ES_ENOMEM; return -1; }
    l->n++;
    return 0;
}

static es_status list_impl(es_ctx *ctx, es_store *s, const char *kind, char ***names,
                           int64_t *n)
{
    char full[600];
    name_list l = {ctx, NULL, 0, 0, ES_OK};
    hid_t g;
    if (kind && *kind && bad_name(kind))
        ES_FAIL(ctx, ES_EINVAL, "store: bad result kind '%s'", kind);
    snprintf(full, sizeof full, "/analysis%s%s", kind && *kind ? "/" : "", kind ? kind : "");
    if (!link_exists(s->file, full)) return ES_OK;
    if ((g = H5Gopen2(s->file, full, H5P_DEFAULT)) < 0)
        return h5fail(ctx, ES_EFORMAT, "store: %s is not a group", full);
    if (H5Literate(g, H5_INDEX_NAME, H5_ITER_INC, NULL, list_cb, &l) < 0) {
        es_status rc = l.rc ? l.rc : h5fail(ctx, ES_EIO, "store: cannot list %s", full);
        H5Gclose(g);
        for (int64_t i = 0; i < l.n; i++) es__free(ctx, l.names[i]);
        es__free(ctx, l.names);
        return rc;
    }
    H5Gclose(g);
    *names = l.names;
    *n = l.n;
    return ES_OK;
}

es_status es_store_list_results(es_ctx *ctx, es_store *s, const char *kind, char ***names,
                                int64_t *n)
{
    es_status rc;
    if (!s || !names || !n) ES_FAIL(ctx, ES_EINVAL, "store: NULL argument");
    *names = NULL;
    *n = 0;
    H5E_BEGIN_TRY { rc = list_impl(ctx, s, kind, names, n); } H5E_END_TRY
    return rc;
}
