/* lib/include/edgespace/es_core.h — context, status codes, matrix views.
 *
 * The contract every public header of libedgespace follows, written once here
 * (after cholmod.h and sqlite.h.in):
 *
 *  - Public functions are es_<family>_<verb>: the family is the module's
 *    name (es_store_, es_meshio_, es_parallel_) or a type or word the module
 *    owns (es_mesh_, es_pca_, es_ctx_, es_rng_), never another module's, and
 *    the function is declared in that module's header, so the name says
 *    where to look (tests/layout/check_layout.py lists the families).
 *    Macros and enum values are ES_*.
 *  - Every fallible function takes an es_ctx * first and returns es_status.
 *    ES_OK is 0. On failure the message is on the context
 *    (es_ctx_errmsg), owned by it and overwritten by the next failure.
 *  - Constructors write their result through an out parameter; the caller owns
 *    it and releases it with the matching _free/_close, which accept NULL.
 *  - The library never prints and never exits. Warnings go to the log
 *    callback, long loops report through the progress callback; both are
 *    optional and silent by default.
 *  - Values are double; counts and indices are int64_t. Dense matrices are
 *    column-major with an explicit leading dimension (es_mat).
 *  - One context per thread; nothing in the library is global and mutable.
 */
#ifndef EDGESPACE_ES_CORE_H
#define EDGESPACE_ES_CORE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(ES_BUILDING_LIBRARY) && defined(__GNUC__)
#define ES_API __attribute__((visibility("default")))
#else
#define ES_API
#endif

typedef enum es_status {
    ES_OK = 0,       /* success */
    ES_ENOMEM,       /* an allocation failed */
    ES_EINVAL,       /* an argument or input value is invalid */
    ES_ERANGE,       /* a size or index is out of range or overflows */
    ES_EIO,          /* a file could not be opened, read or written */
    ES_EFORMAT,      /* a file or expression is malformed */
    ES_ENUMERIC,     /* a numerical routine failed (LAPACK info != 0, NaN) */
    ES_ENOCONV,      /* an iteration did not converge within its limits */
    ES_ENOTFOUND,    /* a named row, group, point or column does not exist */
    ES_EEXIST,       /* the thing to create exists already */
    ES_EMISMATCH,    /* inputs disagree (topology, vertex count, dimension) */
    ES_ETOPOLOGY,    /* a face list is not an oriented 2-manifold */
    ES_ECANCELED     /* the work was cancelled (es_ctx_cancel); nothing was stored */
} es_status;

typedef enum es_log_level {
    ES_LOG_WARNING = 1,
    ES_LOG_INFO = 2
} es_log_level;

typedef struct es_ctx es_ctx;

/* A non-owning view of a column-major matrix: element (i, j) is
 * data[i + j*ld], ld >= rows. */
typedef struct es_mat {
    double *data;
    int64_t rows, cols, ld;
} es_mat;
#define ES_AT(m, i, j) ((m).data[(i) + (int64_t)(j) * (m).ld])

/* The most permutations any permutation test takes (models, per-edge tests,
 * Mantel and group tests): 10^8, one cap for all of them. */
#define ES_MAX_PERMUTATIONS 100000000

/* Version string of the library, e.g. "0.1.0". Static. */
ES_API const char *es_version(void);

/* Static one-line description of a status code. */
ES_API const char *es_strerror(es_status code);

/* Seconds on the monotonic clock the library times its stages and reports
 * with (an arbitrary origin: only differences mean anything), for callers
 * that time the library's work beside its reports. */
ES_API double es_clock_seconds(void);

/* Create a context: error message buffer, log and progress hooks, allocator,
 * RNG seed (default 0x5eed). Returns ES_ENOMEM if it cannot be allocated. */
ES_API es_status es_ctx_new(es_ctx **out);
ES_API void es_ctx_free(es_ctx *ctx);

/* The message of the last failure ("" if none). Owned by ctx; valid until
 * the next failing call on ctx. */
ES_API const char *es_ctx_errmsg(const es_ctx *ctx);
ES_API void es_ctx_clear_error(es_ctx *ctx);

typedef void (*es_log_fn)(void *userdata, es_log_level level, const char *msg);
/* Receive warnings and notes (NULL: discard them, the default). */
ES_API void es_ctx_set_log(es_ctx *ctx, es_log_fn fn, void *userdata);

/* Progress of long work: `what` names the stage, done of total units.
 * Called at most a few hundred times per stage; done == total at the end. */
typedef void (*es_progress_fn)(void *userdata, const char *what, int64_t done,
                               int64_t total);
ES_API void es_ctx_set_progress(es_ctx *ctx, es_progress_fn fn, void *userdata);

/* Ask the work running on ctx to stop: safe from the progress or log
 * callback, another thread or a signal handler (an atomic flag). Long work
 * checks it at each progress report and returns ES_ECANCELED; a store write
 * or commit refuses while it is set, so cancelled work stores nothing. The
 * request stays until es_ctx_cancel_clear (every call made meanwhile stops
 * at its first check). */
ES_API void es_ctx_cancel(es_ctx *ctx);
ES_API void es_ctx_cancel_clear(es_ctx *ctx);
ES_API int es_ctx_cancelled(const es_ctx *ctx);

/* The memory work on ctx may plan to use, in bytes: what refuses a job
 * whose estimated need is larger before it allocates it (an embedding of
 * 5 million vertices grew past 14 GB and was killed by the kernel). 0 (the
 * default) means the machine's physical memory, or less under a process
 * limit (RLIMIT_AS); es_ctx_memory_limit returns the limit in force. */
ES_API void es_ctx_set_memory_limit(es_ctx *ctx, uint64_t bytes);
ES_API uint64_t es_ctx_memory_limit(const es_ctx *ctx);

/* Seed for everything random the library does (randomized PCA, permutation
 * tests, synthetic data). Same seed, same results. */
ES_API void es_ctx_set_seed(es_ctx *ctx, uint64_t seed);
ES_API uint64_t es_ctx_seed(const es_ctx *ctx);

/* Allocator hooks (all three or none; NULL restores malloc/realloc/free).
 * Used by tests to fail the k-th allocation. */
typedef struct es_allocator {
    void *(*malloc_fn)(void *userdata, size_t size);
    void *(*realloc_fn)(void *userdata, void *ptr, size_t size);
    void (*free_fn)(void *userdata, void *ptr);
    void *userdata;
} es_allocator;
ES_API void es_ctx_set_allocator(es_ctx *ctx, const es_allocator *alloc);

/* Free memory that the library allocated through ctx's allocator and handed
 * to the caller (documented per function). NULL: no-op. */
ES_API void es_free(es_ctx *ctx, void *ptr);

/* The library's deterministic random numbers (xoshiro256**, Blackman &
 * Vigna 2018, seeded by splitmix64): what randomized PCA, permutation tests
 * and synthetic data use, from es_ctx_seed. Same seed, same numbers, on
 * every machine. */
typedef struct es_rng { uint64_t s[4]; } es_rng;
ES_API void es_rng_init(es_rng *rng, uint64_t seed);
ES_API uint64_t es_rng_next(es_rng *rng);
ES_API double es_rng_uniform(es_rng *rng);   /* [0, 1) with 53 random bits */
ES_API double es_rng_normal(es_rng *rng);    /* standard normal, Box-Muller */
/* Uniform integer in [0, n), n > 0, without modulo bias. */
ES_API uint64_t es_rng_below(es_rng *rng, uint64_t n);

/* mkdir -p: make directory dir and every missing parent (ES_EIO naming the
 * component that cannot be made, or dir if it is not a directory). */
ES_API es_status es_make_dirs(es_ctx *ctx, const char *dir);

/* One CSV field of free text (ids, labels, names) to f, quoted the RFC 4180
 * way when it holds a comma, quote or line break; "" for NULL. A field a
 * spreadsheet would run as a formula (starting with = + - @, a tab or a
 * carriage return, and not a number) is quoted with a leading apostrophe
 * ("'=cmd|..."), as OWASP advises against CSV injection. Every CSV the
 * library and the command write goes through it. */
ES_API void es_csv_write_field(FILE *f, const char *s);

#ifdef __cplusplus
}
#endif
#endif
