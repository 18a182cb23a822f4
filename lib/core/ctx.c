/* lib/core/ctx.c — the library context: error messages, logging, progress,
 * allocator hooks, RNG seed, and the internal helpers every module uses.
 *
 * The context is the only state the library keeps; there is no global
 * mutable state (after GSL). Messages are formatted into a fixed buffer on
 * the context so that reporting an out-of-memory failure never allocates.
 */
#include "core/core_private.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <sys/resource.h>
#include <unistd.h>

#ifndef ES_VERSION_STRING
#define ES_VERSION_STRING "unknown"
#endif

#define ES_ERRMSG_SIZE 1024

struct es_ctx {
    char errmsg[ES_ERRMSG_SIZE];
    es_log_fn log_fn;
    void *log_ud;
    es_progress_fn progress_fn;
    void *progress_ud;
    uint64_t seed;
    es_allocator alloc;
    bool has_alloc;
    atomic_int cancel;     /* es_ctx_cancel: set from anywhere, read at progress reports */
    uint64_t memory_limit; /* bytes, 0: the machine's */
    void *parallel;              /* lib/parallel's state: the job this context joined */
    void (*parallel_free)(void *);
};

const char *es_version(void) { return ES_VERSION_STRING; }

const char *es_strerror(es_status code)
{
    switch (code) {
    case ES_OK: return "success";
    case ES_ENOMEM: return "out of memory";
    case ES_EINVAL: return "invalid argument or input";
    case ES_ERANGE: return "size or index out of range";
    case ES_EIO: return "input/output error";
    case ES_EFORMAT: return "malformed file or expression";
    case ES_ENUMERIC: return "numerical failure";
    case ES_ENOCONV: return "iteration did not converge";
    case ES_ENOTFOUND: return "not found";
    case ES_EEXIST: return "already exists";
    case ES_EMISMATCH: return "inputs do not correspond";
    case ES_ETOPOLOGY: return "not an oriented 2-manifold";
    case ES_ECANCELED: return "cancelled";
    }
    return "unknown status";
}

es_status es_ctx_new(es_ctx **out)
{
    es_ctx *ctx = calloc(1, sizeof *ctx);
    *out = NULL;
    if (!ctx) return ES_ENOMEM;
    ctx->seed = 0x5eed;
    *out = ctx;
    return ES_OK;
}

void es_ctx_free(es_ctx *ctx)
{
    if (ctx && ctx->parallel_free) ctx->parallel_free(ctx->parallel);
    free(ctx);
}

void *es__ctx_parallel(const es_ctx *ctx) { return ctx ? ctx->parallel : NULL; }

void es__ctx_set_parallel(es_ctx *ctx, void *state, void (*release)(void *))
{
    if (ctx->parallel_free) ctx->parallel_free(ctx->parallel);
    ctx->parallel = state;
    ctx->parallel_free = release;
}

const char *es_ctx_errmsg(const es_ctx *ctx) { return ctx ? ctx->errmsg : ""; }
void es_ctx_clear_error(es_ctx *ctx) { ctx->errmsg[0] = '\0'; }

void es__ctx_get_log(const es_ctx *ctx, es_log_fn *fn, void **userdata)
{
    *fn = ctx ? ctx->log_fn : NULL;
    *userdata = ctx ? ctx->log_ud : NULL;
}

void es_ctx_set_log(es_ctx *ctx, es_log_fn fn, void *userdata)
{
    ctx->log_fn = fn;
    ctx->log_ud = userdata;
}

void es_ctx_set_progress(es_ctx *ctx, es_progress_fn fn, void *userdata)
{
    ctx->progress_fn = fn;
    ctx->progress_ud = userdata;
}

void es_ctx_set_seed(es_ctx *ctx, uint64_t seed) { ctx->seed = seed; }
uint64_t es_ctx_seed(const es_ctx *ctx) { return ctx->seed; }

void es_ctx_set_allocator(es_ctx *ctx, const es_allocator *alloc)
{
    if (alloc && alloc->malloc_fn && alloc->realloc_fn && alloc->free_fn) {
        ctx->alloc = *alloc;
        ctx->has_alloc = true;
    } else {
        ctx->has_alloc = false;
    }
}

/* A message is one line of text: control characters that a file or a user
 * put into what it quotes (a column name holding a newline, a NUL-free
 * binary field) are written as escapes (\n, \t, \x01), never raw. */
static void one_line(char *dst, size_t n, const char *src)
{
    size_t at = 0;
    for (const unsigned char *p = (const unsigned char *)src; *p && at + 1 < n; p++) {
        char esc[5];
        size_t k;
        if (*p >= 0x20 && *p != 0x7f) {
            dst[at++] = (char)*p;
            continue;
        }
        if (*p == '\n') memcpy(esc, "\\n", 3);
        else if (*p == '\r') memcpy(esc, "\\r", 3);
        else if (*p == '\t') memcpy(esc, "\\t", 3);
        else snprintf(esc, sizeof esc, "\\x%02x", *p);
        k = strlen(esc);
        if (at + k + 1 > n) break;
        memcpy(dst + at, esc, k);
        at += k;
    }
    dst[at] = '\0';
}

es_status es__fail(es_ctx *ctx, es_status code, const char *fmt, ...)
{
    va_list ap;
    if (!ctx) return code;
    /* Format aside: callers may pass es_ctx_errmsg(ctx) itself as an argument
     * (wrapping an inner message), and vsnprintf's buffers must not overlap. */
    char buf[sizeof ctx->errmsg];
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    one_line(ctx->errmsg, sizeof ctx->errmsg, buf);
    return code;
}

static void log_message(es_ctx *ctx, es_log_level level, const char *fmt, va_list ap)
    ES__PRINTF(3, 0);
static void log_message(es_ctx *ctx, es_log_level level, const char *fmt, va_list ap)
{
    char buf[ES_ERRMSG_SIZE], line[ES_ERRMSG_SIZE];
    if (!ctx || !ctx->log_fn) return;
    vsnprintf(buf, sizeof buf, fmt, ap);
    one_line(line, sizeof line, buf);
    ctx->log_fn(ctx->log_ud, level, line);
}

void es__warn(es_ctx *ctx, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_message(ctx, ES_LOG_WARNING, fmt, ap);
    va_end(ap);
}

void es__info(es_ctx *ctx, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_message(ctx, ES_LOG_INFO, fmt, ap);
    va_end(ap);
}

es_status es__progress(es_ctx *ctx, const char *what, int64_t done, int64_t total)
{
    if (ctx && ctx->progress_fn) ctx->progress_fn(ctx->progress_ud, what, done, total);
    return es__cancelled(ctx, what);
}

es_status es__cancelled(es_ctx *ctx, const char *what)
{
    if (!ctx || !atomic_load(&ctx->cancel)) return ES_OK;
    ES_FAIL(ctx, ES_ECANCELED, "cancelled during %s; nothing stored", what);
}

void es_ctx_set_memory_limit(es_ctx *ctx, uint64_t bytes)
{
    if (ctx) ctx->memory_limit = bytes;
}

uint64_t es_ctx_memory_limit(const es_ctx *ctx)
{
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    uint64_t phys = pages > 0 && size > 0 ? (uint64_t)pages * (uint64_t)size : UINT64_MAX;
    struct rlimit rl;
    if (ctx && ctx->memory_limit) return ctx->memory_limit;
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
        (uint64_t)rl.rlim_cur < phys)
        phys = (uint64_t)rl.rlim_cur;
    return phys;
}

void es_ctx_cancel(es_ctx *ctx)
{
    if (ctx) atomic_store(&ctx->cancel, 1);
}

void es_ctx_cancel_clear(es_ctx *ctx)
{
    if (ctx) atomic_store(&ctx->cancel, 0);
}

int es_ctx_cancelled(const es_ctx *ctx)
{
    return ctx && atomic_load(&((es_ctx *)ctx)->cancel);
}

void *es__malloc(es_ctx *ctx, size_t size)
{
    void *p;
    if (size == 0) size = 1;
    p = ctx->has_alloc ? ctx->alloc.malloc_fn(ctx->alloc.userdata, size) : malloc(size);
    if (!p) es__fail(ctx, ES_ENOMEM, "out of memory (%zu bytes)", size);
    return p;
}

void *es__calloc(es_ctx *ctx, size_t n, size_t size)
{
    size_t bytes;
    void *p;
    if (!es__mul_size(n, size, &bytes)) {
        es__fail(ctx, ES_ENOMEM, "allocation size overflows (%zu x %zu bytes)", n, size);
        return NULL;
    }
    if (!ctx->has_alloc) {
        /* libc's calloc hands out fresh pages of a large block as the kernel
         * zeroed them, untouched: a memset here touched every page of every
         * large buffer (a fresh `embed` spent 10 % of its CPU zeroing, and
         * as much again in the page faults it took) */
        p = calloc(bytes ? bytes : 1, 1);
        if (!p) es__fail(ctx, ES_ENOMEM, "out of memory (%zu bytes)", bytes);
        if (p && bytes >= ((size_t)4 << 20)) es__advise_huge(p, bytes);
        return p;
    }
    p = es__malloc(ctx, bytes);
    if (p && bytes >= ((size_t)4 << 20)) es__advise_huge(p, bytes);
    if (p) memset(p, 0, bytes ? bytes : 1);
    return p;
}

void *es__realloc(es_ctx *ctx, void *ptr, size_t size)
{
    void *p;
    if (size == 0) size = 1;
    p = ctx->has_alloc ? ctx->alloc.realloc_fn(ctx->alloc.userdata, ptr, size)
                       : realloc(ptr, size);
    if (!p) es__fail(ctx, ES_ENOMEM, "out of memory (%zu bytes)", size);
    return p;
}

void es__free(es_ctx *ctx, void *ptr)
{
    if (!ptr) return;
    if (ctx && ctx->has_alloc) ctx->alloc.free_fn(ctx->alloc.userdata, ptr);
    else free(ptr);
}

void es_free(es_ctx *ctx, void *ptr) { es__free(ctx, ptr); }

void *es__alloc_array(es_ctx *ctx, int64_t n, size_t size)
{
    if (n < 0) {
        es__fail(ctx, ES_ERANGE, "negative element count %lld", (long long)n);
        return NULL;
    }
    return es__calloc(ctx, (size_t)n, size);
}

char *es__strdup(es_ctx *ctx, const char *s)
{
    size_t n = strlen(s) + 1;
    char *p = es__malloc(ctx, n);
    if (p) memcpy(p, s, n);
    return p;
}

es_status es__lapack_int(es_ctx *ctx, int64_t n, int *out)
{
    if (n < 0 || n > 2147483647) {
        ES_FAIL(ctx, ES_ERANGE, "dimension %lld exceeds LAPACK's 32-bit integers",
                (long long)n);
    }
    *out = (int)n;
    return ES_OK;
}

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void es_rng_init(es_rng *rng, uint64_t seed)
{
    for (int i = 0; i < 4; i++) rng->s[i] = splitmix64(&seed);
}

static inline uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

uint64_t es_rng_next(es_rng *rng)
{
    uint64_t *s = rng->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double es_rng_uniform(es_rng *rng) { return (double)(es_rng_next(rng) >> 11) * 0x1.0p-53; }

double es_rng_normal(es_rng *rng)
{
    double u1, u2;
    do u1 = es_rng_uniform(rng); while (u1 <= 0.0);
    u2 = es_rng_uniform(rng);
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586476925 * u2);
}

uint64_t es_rng_below(es_rng *rng, uint64_t n)
{
    uint64_t limit = UINT64_MAX - UINT64_MAX % n, x;
    do x = es_rng_next(rng); while (x >= limit);
    return x % n;
}
