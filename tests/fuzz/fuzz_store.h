/* tests/fuzz/fuzz_store.h — what the store fuzz targets share: the base
 * store of the crafted-store suite (tests/store/crafted.c), made once per
 * run in a fresh folder and kept as bytes, and the check of a store that
 * opened or was refused: every read works or fails with one clean line. */
#ifndef EDGESPACE_FUZZ_STORE_H
#define EDGESPACE_FUZZ_STORE_H

#include "fuzz_util.h"
#include "crafted.h"

#include <hdf5.h>
#include <sys/stat.h>

static inline const unsigned char *fuzz_base_store(size_t *n)
{
    static unsigned char *bytes;
    static size_t len;
    if (!bytes) {
        char dir[] = "/tmp/edgespace-fuzz-XXXXXX", path[64];
        FILE *f;
        if (!mkdtemp(dir)) abort();
        snprintf(path, sizeof path, "%s/base.h5", dir);
        if (crafted_base(path) != 0 || !(f = fopen(path, "rb"))) abort();
        fseek(f, 0, SEEK_END);
        len = (size_t)ftell(f);
        rewind(f);
        if (!(bytes = malloc(len)) || fread(bytes, 1, len, f) != len) abort();
        fclose(f);
        remove(path);
        rmdir(dir);
    }
    *n = len;
    return bytes;
}

/* The base store's object headers (address and bytes of each, found by
 * HDF5 itself: every group and dataset reachable from the root), for the
 * target that aims its changes at them. */
typedef struct fuzz_header { size_t addr, len; } fuzz_header;
static fuzz_header fuzz_headers[256];

static herr_t fuzz_header_cb(hid_t obj, const char *name, const H5O_info_t *info, void *ud)
{
    size_t *n = ud;
    (void)obj;
    (void)name;
    if (*n < 256 && info->hdr.space.total > 0) {
        fuzz_headers[*n].addr = (size_t)info->addr;
        fuzz_headers[*n].len = (size_t)info->hdr.space.total;
        ++*n;
    }
    return 0;
}

static inline const fuzz_header *fuzz_base_headers(size_t *n)
{
    static size_t count;
    static int done;
    if (!done) {
        size_t nbase;
        const unsigned char *base = fuzz_base_store(&nbase);
        char dir[] = "/tmp/edgespace-fuzz-XXXXXX", path[64];
        FILE *f;
        hid_t file;
        done = 1;
        if (!mkdtemp(dir)) abort();
        snprintf(path, sizeof path, "%s/base.h5", dir);
        if (!(f = fopen(path, "wb")) || fwrite(base, 1, nbase, f) != nbase || fclose(f)) abort();
        if ((file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT)) < 0 ||
            H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_NATIVE, fuzz_header_cb, &count,
                      H5O_INFO_BASIC | H5O_INFO_HDR) < 0)
            abort();
        H5Fclose(file);
        remove(path);
        rmdir(dir);
    }
    *n = count;
    return fuzz_headers;
}

/* The input as a store file at a real path: HDF5 1.10 resolves the path it
 * opens (realpath), so a memory file's /proc/self/fd/N name cannot be
 * opened (every input was refused at H5Fopen before the store's code ran).
 * In /dev/shm where there is one (memory), else in /tmp. */
static char fuzz_store_path[96];

static inline void fuzz_store_remove(void)
{
    remove(fuzz_store_path);
}

static inline const char *fuzz_store_file(const void *data, size_t size)
{
    char *path = fuzz_store_path;
    FILE *f;
    if (!path[0]) {
        struct stat st;
        snprintf(path, sizeof fuzz_store_path, "%s/edgespace-fuzz-%ld.h5",
                 stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode) ? "/dev/shm" : "/tmp",
                 (long)getpid());
        atexit(fuzz_store_remove);
    }
    if (!(f = fopen(path, "wb")) || (size && fwrite(data, 1, size, f) != size) || fclose(f))
        abort();
    return path;
}

/* Open the store at path and read all of it; refusals and failed reads
 * must each leave one clean line. */
static inline void fuzz_open_and_read(const char *path)
{
    es_ctx *ctx = fuzz_ctx();
    es_store *s = NULL;
    if (es_store_open(ctx, path, ES_STORE_READ, &s) == ES_OK) {
        if (!s || crafted_read_all(ctx, s) != 0) __builtin_trap();
        es_store_close(s);
    } else {
        if (s || !crafted_message_ok(es_ctx_errmsg(ctx))) __builtin_trap();
    }
}

#endif
