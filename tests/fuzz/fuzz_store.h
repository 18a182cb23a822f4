/* tests/fuzz/fuzz_store.h — what the store fuzz targets share: the base
 * store of the crafted-store suite (tests/store/crafted.c), made once per
 * run in a fresh folder and kept as bytes, and the check of a store that
 * opened or was refused: every read works or fails with one clean line. */
#ifndef EDGESPACE_FUZZ_STORE_H
#define EDGESPACE_FUZZ_STORE_H

#include "fuzz_util.h"
#include "crafted.h"

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
