/* tests/core/test_strmap.c — es__strmap against references that are correct
 * by inspection: a linear scan over (key, value) pairs for interleaved puts
 * and gets with many repeats, and a sorted array for 10^5 distinct random
 * keys; keys whose FNV-1a hashes share their low bits (found by brute
 * force), so that they probe the same slots at every table size; repeated
 * puts, the empty key, growth from the smallest table, and a failed
 * allocation during growth, which must leave the map as it was. */
#include "core/strmap.h"
#include "core/hash.h"
#include "es_test.h"
#include "es_test_alloc.h"

/* ---- the linear-scan reference --------------------------------------------- */

typedef struct ref_map {
    const char **keys;
    int64_t *vals, n;
} ref_map;

static int64_t ref_get(const ref_map *r, const char *key)
{
    for (int64_t i = 0; i < r->n; i++)
        if (!strcmp(r->keys[i], key)) return r->vals[i];
    return -1;
}

/* Insert unless present; the value stored before, or -1. */
static int64_t ref_put(ref_map *r, const char *key, int64_t val)
{
    int64_t prev = ref_get(r, key);
    if (prev >= 0) return prev;
    r->keys[r->n] = key;
    r->vals[r->n++] = val;
    return -1;
}

/* ---- keys ------------------------------------------------------------------ */

/* A random key of 0..maxlen bytes over the first nalpha letters of a
 * 39-letter alphabet (short keys over few letters repeat often). */
static void random_key(es_rng *rng, char *buf, int maxlen, int nalpha)
{
    static const char alpha[] = "abcdefghijklmnopqrstuvwxyz0123456789_-.";
    int len = (int)es_rng_below(rng, (uint64_t)maxlen + 1);
    for (int i = 0; i < len; i++) buf[i] = alpha[es_rng_below(rng, (uint64_t)nalpha)];
    buf[len] = '\0';
}

/* n distinct keys "k<base 36>" whose FNV-1a hashes agree in the low `bits`
 * bits with the first one found: every table of up to 2^bits slots puts
 * them all on one probe chain. keys: n x 16 bytes. */
static void colliding_keys(char (*keys)[16], int n, int bits)
{
    uint64_t mask = ((uint64_t)1 << bits) - 1, want = 0;
    int found = 0;
    for (uint64_t c = 0; found < n; c++) {
        char s[16];
        int len = 1;
        s[0] = 'k';
        for (uint64_t v = c; len == 1 || v; v /= 36)
            s[len++] = "0123456789abcdefghijklmnopqrstuvwxyz"[v % 36];
        s[len] = '\0';
        uint64_t h = es__fnv1a64_str(s) & mask;
        if (found == 0) want = h;
        if (h == want) memcpy(keys[found++], s, (size_t)len + 1);
    }
}

/* ---- tests ----------------------------------------------------------------- */

/* Interleaved puts and gets of keys drawn with many repeats (lengths 0-2
 * over 39 letters, or 3 over 10: about 2500 distinct keys, the empty one
 * among them), from the smallest table: every answer equals the linear
 * scan's, values and prev included. */
static void test_interleaved(es_ctx *ctx)
{
    enum { OPS = 100000 };
    static char pool[OPS][8];
    ref_map ref = {malloc(OPS * sizeof(char *)), malloc(OPS * sizeof(int64_t)), 0};
    es__strmap m;
    es_rng rng;
    int64_t bad = 0;
    es_rng_init(&rng, 7);
    ES_CHECK_OK(ctx, es__strmap_init(ctx, &m, 0));
    ES_CHECK(m.cap == 16 && m.n == 0);
    for (int i = 0; i < OPS && ref.keys && ref.vals; i++) {
        if (es_rng_below(&rng, 2)) random_key(&rng, pool[i], 2, 39);
        else random_key(&rng, pool[i], 3, 10);
        if (es_rng_below(&rng, 3) == 0) {
            /* a get, also of keys never put */
            bad += es__strmap_get(&m, pool[i]) != ref_get(&ref, pool[i]);
            continue;
        }
        int64_t prev = -2, want = ref_put(&ref, pool[i], i);
        ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, pool[i], i, &prev));
        bad += prev != want;
    }
    ES_CHECK_MSG(bad == 0, "%lld answers differ from the linear scan", (long long)bad);
    ES_CHECK(m.n == ref.n && ref.n > 1500 && es__strmap_get(&m, "") >= 0);
    /* every key the reference holds, with its first value; the table is at
     * most half full */
    for (int64_t i = 0; i < ref.n; i++) bad += es__strmap_get(&m, ref.keys[i]) != ref.vals[i];
    ES_CHECK(bad == 0 && 2 * m.n <= m.cap);
    es__strmap_clear(ctx, &m);
    ES_CHECK(m.cap == 0 && m.n == 0 && m.keys == NULL);
    ES_CHECK(es__strmap_get(&m, "a") == -1);
    free(ref.keys);
    free(ref.vals);
}

static int cmp_entry(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* 10^5 distinct random keys (up to 18 bytes; repeats dropped by sorting): all
 * found with their values, and 10^5 other strings not found. The sorted
 * array is the reference (bsearch). */
static void test_many(es_ctx *ctx)
{
    enum { N = 100000 };
    char (*buf)[24] = malloc(N * sizeof *buf);
    char **sorted = malloc(N * sizeof *sorted);
    es__strmap m;
    es_rng rng;
    int64_t n = 0, bad = 0;
    if (!buf || !sorted) { free(buf); free(sorted); ES_CHECK(0); return; }
    es_rng_init(&rng, 99);
    for (int i = 0; i < N; i++) {
        random_key(&rng, buf[i], 8, 39);
        size_t l = strlen(buf[i]);
        snprintf(buf[i] + l, sizeof buf[i] - l, "%llx",
                 (unsigned long long)(es_rng_next(&rng) >> 24));
        sorted[i] = buf[i];
    }
    qsort(sorted, N, sizeof *sorted, cmp_entry);
    for (int i = 0; i < N; i++)
        if (i == 0 || strcmp(sorted[i], sorted[n - 1])) sorted[n++] = sorted[i];
    ES_CHECK(n > N - 10);
    ES_CHECK_OK(ctx, es__strmap_init(ctx, &m, 0));
    for (int64_t i = 0; i < n; i++) {
        int64_t prev;
        ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, sorted[i], i, &prev));
        bad += prev != -1;
    }
    ES_CHECK(m.n == n && bad == 0);
    for (int64_t i = 0; i < n; i++) bad += es__strmap_get(&m, sorted[i]) != i;
    for (int i = 0; i < N; i++) {
        char probe[32];
        const char *key = probe;
        random_key(&rng, probe, 8, 39);
        strcat(probe, "#");   /* no stored key has a '#' */
        bad += es__strmap_get(&m, probe) != -1 ||
               bsearch(&key, sorted, (size_t)n, sizeof *sorted, cmp_entry) != NULL;
    }
    ES_CHECK_MSG(bad == 0, "%lld wrong answers", (long long)bad);
    es__strmap_clear(ctx, &m);
    free(sorted);
    free(buf);
}

/* Keys that collide in the low 12 bits share one probe chain in tables of
 * up to 4096 slots: puts and gets stay right along chains of 1500, through
 * every growth, with other keys interleaved. */
static void test_collisions(es_ctx *ctx)
{
    enum { NC = 1500 };
    static char keys[NC + 1][16];   /* the last is never put */
    char other[NC][16];
    ref_map ref = {malloc(2 * NC * sizeof(char *)), malloc(2 * NC * sizeof(int64_t)), 0};
    es__strmap m;
    int64_t bad = 0;
    colliding_keys(keys, NC + 1, 12);
    for (int i = 1; i <= NC; i++)
        ES_CHECK(((es__fnv1a64_str(keys[i]) ^ es__fnv1a64_str(keys[0])) & 0xfff) == 0);
    if (!ref.keys || !ref.vals) { ES_CHECK(0); free(ref.keys); free(ref.vals); return; }
    ES_CHECK_OK(ctx, es__strmap_init(ctx, &m, 1));
    for (int i = 0; i < NC; i++) {
        int64_t prev;
        snprintf(other[i], sizeof other[i], "o%d", i);
        ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, keys[i], 2 * i, &prev));
        bad += prev != ref_put(&ref, keys[i], 2 * i);
        ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, other[i], 2 * i + 1, &prev));
        bad += prev != ref_put(&ref, other[i], 2 * i + 1);
        /* an earlier colliding key, again: found, not inserted twice */
        int j = i / 2;
        ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, keys[j], -7, &prev));
        bad += prev != 2 * j;
        bad += es__strmap_get(&m, keys[i]) != 2 * i;
    }
    for (int64_t i = 0; i < ref.n; i++) bad += es__strmap_get(&m, ref.keys[i]) != ref.vals[i];
    /* a key on the chain that was never put: the probe walks it all */
    bad += es__strmap_get(&m, keys[NC]) != -1;
    ES_CHECK_MSG(bad == 0, "%lld wrong answers", (long long)bad);
    ES_CHECK(m.n == 2 * NC);
    es__strmap_clear(ctx, &m);
    free(ref.keys);
    free(ref.vals);
}

/* The value of a repeated put stays the first one; prev reports it; the
 * empty string is a key like any other; NULL is refused. */
static void test_edges(es_ctx *ctx)
{
    es__strmap m;
    int64_t prev = -2;
    ES_CHECK_OK(ctx, es__strmap_init(ctx, &m, 0));
    ES_CHECK(es__strmap_get(&m, "") == -1);
    ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, "", 5, &prev));
    ES_CHECK(prev == -1 && es__strmap_get(&m, "") == 5 && m.n == 1);
    ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, "", 6, &prev));
    ES_CHECK(prev == 5 && es__strmap_get(&m, "") == 5 && m.n == 1);
    ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, "x", 0, NULL));
    ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, "x", 9, &prev));
    ES_CHECK(prev == 0 && es__strmap_get(&m, "x") == 0);
    /* keys are compared by content, not by pointer */
    char copy[2] = "x";
    ES_CHECK(es__strmap_get(&m, copy) == 0);
    ES_CHECK(es__strmap_get(&m, NULL) == -1);
    ES_CHECK_FAILS(ctx, es__strmap_put(ctx, &m, NULL, 1, &prev), ES_EINVAL, "NULL key");
    ES_CHECK(prev == -1 && m.n == 2);
    es__strmap_clear(ctx, &m);
    es__strmap_clear(ctx, &m);   /* twice: harmless */
    es__strmap_clear(ctx, NULL);
}

/* A failed allocation while growing (either of the two arrays) returns
 * ES_ENOMEM and leaves the map as it was: same keys, values, size and
 * table, nothing leaked; the next put grows it. */
static void test_alloc_failure(void)
{
    es_ctx *ctx = NULL;
    failing_alloc fa = {0, 0, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    static char keys[40][8];
    es__strmap m;
    if (es_ctx_new(&ctx) != ES_OK) { ES_CHECK(0); return; }
    es_ctx_set_allocator(ctx, &a);
    ES_CHECK_FAILS(ctx, (fa.fail_at = 1, es__strmap_init(ctx, &m, 0)), ES_ENOMEM, NULL);
    ES_CHECK(fa.live == 0 && m.keys == NULL && m.cap == 0);
    fa.fail_at = 0;
    ES_CHECK_OK(ctx, es__strmap_init(ctx, &m, 0));
    for (int i = 0; i < 40; i++) snprintf(keys[i], sizeof keys[i], "key%d", i);
    int i = 0;
    /* 16 slots hold 8 keys; the 9th put grows */
    for (; 2 * (m.n + 1) <= m.cap; i++) ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, keys[i], i, NULL));
    ES_CHECK(i == 8);
    for (int fail = 1; fail <= 2; fail++) {
        es__strmap before = m;
        int64_t live = fa.live, prev = -2;
        fa.count = 0;
        fa.fail_at = fail;
        ES_CHECK_FAILS(ctx, es__strmap_put(ctx, &m, keys[i], i, &prev), ES_ENOMEM, NULL);
        ES_CHECK(prev == -1 && fa.live == live);
        ES_CHECK(m.cap == before.cap && m.n == before.n && m.keys == before.keys &&
                 m.vals == before.vals);
        for (int j = 0; j < i; j++) ES_CHECK(es__strmap_get(&m, keys[j]) == j);
        ES_CHECK(es__strmap_get(&m, keys[i]) == -1);
        /* a key already present needs no growth: found even now */
        fa.count = 0;
        ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, keys[3], 99, &prev));
        ES_CHECK(prev == 3 && fa.count == 0);
    }
    fa.fail_at = 0;
    ES_CHECK_OK(ctx, es__strmap_put(ctx, &m, keys[i], i, NULL));
    ES_CHECK(m.cap == 32 && m.n == 9);
    for (int j = 0; j <= i; j++) ES_CHECK(es__strmap_get(&m, keys[j]) == j);
    es__strmap_clear(ctx, &m);
    ES_CHECK(fa.live == 0);
    es_ctx_free(ctx);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_interleaved(ctx);
    test_many(ctx);
    test_collisions(ctx);
    test_edges(ctx);
    test_alloc_failure();
    es_ctx_free(ctx);
    ES_TEST_END();
}
