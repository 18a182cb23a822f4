/* lib/h5/h5_file.c — HDF5 itself and its files: errors (es__h5_fail adds
 * the innermost message of HDF5's error stack, H5Ewalk2, to ours), quiet
 * sections, closing any object, and files opened, created (on disk or in
 * memory) and closed, the one full-disk-safe close of every file written
 * included.
 */
#define _GNU_SOURCE   /* memfd_create, fallocate */
#include "h5/h5_pkg.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <sys/mman.h>
#include <stdarg.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

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

/* H5E_BEGIN_TRY and H5E_END_TRY as two calls: the handler saved, printing
 * off, the handler put back. */
void es__h5_quiet_begin(es__h5_quiet *q)
{
    H5E_auto2_t f2 = NULL;
    H5E_auto1_t f1 = NULL;
    q->is_v2 = 0;
    q->data = NULL;
    (void)H5Eauto_is_v2(H5E_DEFAULT, &q->is_v2);
    if (q->is_v2) {
        (void)H5Eget_auto2(H5E_DEFAULT, &f2, &q->data);
        (void)H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
        q->func = (void (*)(void))f2;
    } else {
        (void)H5Eget_auto1(&f1, &q->data);
        (void)H5Eset_auto1(NULL, NULL);
        q->func = (void (*)(void))f1;
    }
}

void es__h5_quiet_end(const es__h5_quiet *q)
{
    if (q->is_v2) (void)H5Eset_auto2(H5E_DEFAULT, (H5E_auto2_t)q->func, q->data);
    else (void)H5Eset_auto1((H5E_auto1_t)q->func, q->data);
}

int es__h5_close(es__h5_id id)
{
    if (id < 0) return 0;
    switch (H5Iget_type(id)) {
    case H5I_FILE: return H5Fclose(id) < 0 ? -1 : 0;
    case H5I_GROUP: return H5Gclose(id) < 0 ? -1 : 0;
    case H5I_DATASET: return H5Dclose(id) < 0 ? -1 : 0;
    case H5I_DATASPACE: return H5Sclose(id) < 0 ? -1 : 0;
    case H5I_DATATYPE: return H5Tclose(id) < 0 ? -1 : 0;
    case H5I_ATTR: return H5Aclose(id) < 0 ? -1 : 0;
    case H5I_GENPROP_LST: return H5Pclose(id) < 0 ? -1 : 0;
    default: return 0;
    }
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

void es__h5_close_kept(const hid_t *ids, int n)
{
    ES__H5_KEEP_ERROR({
        for (int k = 0; k < n; k++) es__h5_close(ids[k]);
    });
}

int es__h5_is_hdf5(const char *path)
{
    return H5Fis_hdf5(path);
}

es__h5_id es__h5_file_open(const char *path, bool write)
{
    hid_t fapl = es__h5_file_access();
    hid_t f = H5Fopen(path, write ? H5F_ACC_RDWR : H5F_ACC_RDONLY, fapl);
    ES__H5_KEEP_ERROR(es__h5_close(fapl));
    return f;
}

es__h5_id es__h5_file_open_default(const char *path)
{
    return H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
}

es__h5_id es__h5_file_create(const char *path, bool truncate)
{
    hid_t fapl = es__h5_file_access(), f = -1;
    if (fapl >= 0) f = H5Fcreate(path, truncate ? H5F_ACC_TRUNC : H5F_ACC_EXCL, H5P_DEFAULT, fapl);
    ES__H5_KEEP_ERROR(es__h5_close(fapl));
    return f;
}

/* In memory, growing by 64 KiB, without a backing file: the caller writes
 * its image (store_beside.c). */
es__h5_id es__h5_file_create_memory(const char *path)
{
    hid_t fapl = es__h5_file_access(), f = -1;
    if (fapl >= 0 && H5Pset_fapl_core(fapl, (size_t)1 << 16, 0) >= 0)
        f = H5Fcreate(path, H5F_ACC_EXCL, H5P_DEFAULT, fapl);
    ES__H5_KEEP_ERROR(es__h5_close(fapl));
    return f;
}

es_status es__h5_file_image(es_ctx *ctx, es__h5_id file, const char *path, char **img,
                            size_t *size)
{
    ssize_t n;
    *img = NULL;
    *size = 0;
    if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0 || (n = H5Fget_file_image(file, NULL, 0)) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot build result file '%s'", path);
    if (!(*img = es__malloc(ctx, n > 0 ? (size_t)n : 1))) return ES_ENOMEM;
    if (H5Fget_file_image(file, *img, (size_t)n) != n) {
        es__free(ctx, *img);
        *img = NULL;
        return es__h5_fail(ctx, ES_EIO, "store: cannot build result file '%s'", path);
    }
    *size = (size_t)n;
    return ES_OK;
}

int es__h5_file_flush_close(es__h5_id file)
{
    if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) return -1;
    return H5Fclose(file) < 0 ? -1 : 0;
}

es__h5_id es__h5_file_of(es__h5_id obj)
{
    return H5Iget_file_id(obj);
}
