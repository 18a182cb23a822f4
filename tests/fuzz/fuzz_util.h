/* tests/fuzz/fuzz_util.h — what the fuzz targets of the file readers share:
 * the input as a file without touching the disk (a memfd, opened by the
 * readers as /proc/self/fd/N: a regular file), one context for the whole
 * run, and the contract of a failure: one line that names the input. */
#ifndef EDGESPACE_FUZZ_UTIL_H
#define EDGESPACE_FUZZ_UTIL_H

#define _GNU_SOURCE
#include "edgespace/edgespace.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static inline es_ctx *fuzz_ctx(void)
{
    static es_ctx *ctx;
    if (!ctx && es_ctx_new(&ctx) != ES_OK) abort();
    return ctx;
}

/* Slot k (0..3) of memory files: its contents replaced by data[0..size),
 * its path written to path. */
static inline void fuzz_file(int k, const void *data, size_t size, char *path, size_t n)
{
    static int fd[4] = {-1, -1, -1, -1};
    if (fd[k] < 0 && (fd[k] = memfd_create("edgespace-fuzz", 0)) < 0) abort();
    if (ftruncate(fd[k], 0) != 0 || (size && pwrite(fd[k], data, size, 0) != (ssize_t)size))
        abort();
    snprintf(path, n, "/proc/self/fd/%d", fd[k]);
}

/* A failure must leave one line that contains `needle`. */
static inline void fuzz_check_message(es_ctx *ctx, const char *needle)
{
    const char *m = es_ctx_errmsg(ctx);
    if (!m || !*m || strchr(m, '\n') || (needle && !strstr(m, needle))) __builtin_trap();
}

#endif
