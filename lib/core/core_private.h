/* lib/core/core_private.h — what every module of the library shares and
 * users never see (library-private: lib/README.md explains the three header
 * tiers).
 *
 * ES_FAIL records a message on the context and returns the code; es__alloc
 * and friends go through the context's allocator and record ES_ENOMEM
 * themselves; checked size arithmetic; a small deterministic RNG
 * (xoshiro256**, Blackman & Vigna 2018) seeded from the context. Never
 * installed.
 */
#ifndef EDGESPACE_CORE_PRIVATE_H
#define EDGESPACE_CORE_PRIVATE_H

#if !defined(ES_BUILDING_LIBRARY) && !defined(ES_TESTING)
#error "core/core_private.h is private to libedgespace: include <edgespace/edgespace.h>"
#endif

#include "edgespace/es_core.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#if defined(__GNUC__)
#define ES__PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define ES__PRINTF(a, b)
#endif

/* Format the context's message and return code. */
es_status es__fail(es_ctx *ctx, es_status code, const char *fmt, ...) ES__PRINTF(3, 4);
#define ES_FAIL(ctx, code, ...) return es__fail((ctx), (code), __VA_ARGS__)

/* Warnings and notes to the log callback (no-op without one). */
void es__warn(es_ctx *ctx, const char *fmt, ...) ES__PRINTF(2, 3);
void es__info(es_ctx *ctx, const char *fmt, ...) ES__PRINTF(2, 3);

/* The context's log callback, so that a caller can put another in its place
 * for a while (ingest collects its threads' warnings to replay them in
 * input order) and restore it. */
void es__ctx_get_log(const es_ctx *ctx, es_log_fn *fn, void **userdata);

/* The state lib/parallel keeps for a context joined to an MPI job (NULL
 * when it is alone); release frees it with the context. */
void *es__ctx_parallel(const es_ctx *ctx);
void es__ctx_set_parallel(es_ctx *ctx, void *state, void (*release)(void *));

/* Progress callback (no-op without one), then the cancel check: ES_ECANCELED
 * (recorded, naming `what`) once es_ctx_cancel was called, else ES_OK. A
 * loop stops on it and returns it; loops of no work worth stopping may
 * ignore it, since every store write refuses while the request stands. */
es_status es__progress(es_ctx *ctx, const char *what, int64_t done, int64_t total);
/* The cancel check alone (ES_OK, or ES_ECANCELED recorded). */
es_status es__cancelled(es_ctx *ctx, const char *what);

/* Allocation through the context; on failure they record ES_ENOMEM with a
 * message and return NULL. es__calloc checks n * size for overflow. */
void *es__malloc(es_ctx *ctx, size_t size);
void *es__calloc(es_ctx *ctx, size_t n, size_t size);
void *es__realloc(es_ctx *ctx, void *ptr, size_t size);
void es__free(es_ctx *ctx, void *ptr);
/* n elements of `size` bytes, n an int64 count (negative counts fail). */
void *es__alloc_array(es_ctx *ctx, int64_t n, size_t size);
/* The operating system (os.c). Seconds on the monotonic clock, for
 * timing stages and reports. */
double es__seconds(void);
/* Processors online (at least 1). */
int64_t es__cpu_count(void);
/* Ask the kernel to back the 2 MiB-aligned interior of [p, p + bytes) with
 * transparent huge pages (Linux madvise MADV_HUGEPAGE; elsewhere, or for
 * memory that is not anonymous, nothing happens). Call before the first
 * touch. es__calloc does it for blocks of 4 MiB and more: on this
 * project's virtual machines a 4 KiB page fault costs ~16 us, so first
 * touching 100 MB took 0.41 s of CPU, and 0.02 s with huge pages. */
void es__advise_huge(void *p, size_t bytes);

/* Replace a file only when its new content is complete (file_replace.c):
 * begin opens a part file beside path (through a symlink, beside its target;
 * with the old file's mode); write to w.f; end closes it and renames it over
 * the file if rc is ES_OK and the writes succeeded, else removes it. end
 * returns rc or the write error. A FIFO or character device at path (a pipe,
 * /dev/null, /dev/full) is written in place, never replaced by a file; a
 * directory, block device or socket is refused (ES_EIO). */
typedef struct es__file_replace {
    FILE *f;
    char *tmp;          /* the part file (NULL when written in place) */
    char *target;       /* the symlink's resolution, or NULL */
    const char *path;   /* as given (for messages) */
} es__file_replace;
es_status es__replace_begin(es_ctx *ctx, const char *path, es__file_replace *w);
es_status es__replace_end(es_ctx *ctx, es__file_replace *w, es_status rc);
/* Files that appear together or not at all (the frames of a walk): each
 * written file's end is staged (closed, its part kept) instead of renamed;
 * commit renames them all into place, abort removes the parts. A failed
 * write (rc) is not staged and its part is removed. */
typedef struct es__file_set {
    es__file_replace *w;
    int64_t n, cap;
} es__file_set;
es_status es__replace_end_staged(es_ctx *ctx, es__file_replace *w, es_status rc,
                                 es__file_set *set);
es_status es__file_set_commit(es_ctx *ctx, es__file_set *set);
void es__file_set_abort(es_ctx *ctx, es__file_set *set);
void es__file_set_clear(es_ctx *ctx, es__file_set *set);
/* Append from's staged files to into: into's memory is ctx's, from's
 * from_ctx's (two contexts may have two allocators); from is left empty.
 * ES_ENOMEM leaves both as they were. */
es_status es__file_set_move(es_ctx *ctx, es__file_set *into, es_ctx *from_ctx,
                            es__file_set *from);
/* Temporary siblings, named in one place (file_replace.c): a part file
 * (es__replace_begin's) or a working copy (the store's, published by its
 * commit). es__temp_sibling: the name beside path for this process, with
 * unique ("" or what keeps two of one process apart) in it; path's base is
 * shortened when the name would pass NAME_MAX (255): its first 120 bytes
 * (at a UTF-8 boundary), '~' and 16 hex digits of its FNV-1a hash, as a
 * store or output named with 230 bytes could not be written. NULL:
 * ES_ENOMEM. es__temp_clean_stale removes path's siblings of that kind
 * whose process is gone (a killed writer's). */
typedef enum { ES__TEMP_PART, ES__TEMP_WORKING_COPY } es__temp_kind;
char *es__temp_sibling(es_ctx *ctx, const char *path, es__temp_kind kind, const char *unique);
void es__temp_clean_stale(const char *path, es__temp_kind kind);
char *es__strdup(es_ctx *ctx, const char *s);

/* The k-th smallest (0-based) of a[0..n-1], k < n, NaN-free; reorders a
 * (order_stat.c). */
double es__kth_smallest(double *a, int64_t n, int64_t k);

/* Checked products; false on overflow. */
static inline bool es__mul_size(size_t a, size_t b, size_t *out)
{
    return !__builtin_mul_overflow(a, b, out);
}
static inline bool es__mul_i64(int64_t a, int64_t b, int64_t *out)
{
    return !__builtin_mul_overflow(a, b, out);
}

/* LAPACK's integers are 32-bit on Debian: refuse rather than truncate. */
es_status es__lapack_int(es_ctx *ctx, int64_t n, int *out);

#endif
