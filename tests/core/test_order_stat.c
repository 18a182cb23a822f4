/* tests/core/test_order_stat.c — es__kth_smallest against qsort (the
 * oracle): every k of small arrays, sampled k of large ones, with many
 * repeats, sorted and reversed inputs, one element, all equal, and +inf. */
#include "core/core_private.h"
#include "es_test.h"

#include <math.h>
#include <stdlib.h>

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static unsigned long long state = 88172645463325252ULL;
static double next(int levels)   /* xorshift: values with repeats when levels > 0 */
{
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return levels > 0 ? (double)(state % (unsigned)levels) : (double)(state >> 11) * 0x1p-53;
}

static int check(const double *src, int64_t n, int64_t k)
{
    double *a = malloc((size_t)n * sizeof *a), *s = malloc((size_t)n * sizeof *s);
    memcpy(a, src, (size_t)n * sizeof *a);
    memcpy(s, src, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, cmp);
    double got = es__kth_smallest(a, n, k);
    qsort(a, (size_t)n, sizeof *a, cmp);   /* a permutation of the input */
    int ok = got == s[k] && memcmp(a, s, (size_t)n * sizeof *a) == 0;
    free(a), free(s);
    return ok;
}

int main(void)
{
    ES_TEST_BEGIN();
    double v[2000];
    for (int trial = 0; trial < 200; trial++) {
        int64_t n = 1 + trial % 37;
        int levels = trial % 3 == 0 ? 0 : trial % 3 == 1 ? 3 : 50;
        for (int64_t i = 0; i < n; i++) v[i] = next(levels);
        for (int64_t k = 0; k < n; k++) ES_CHECK(check(v, n, k));
    }
    for (int shape = 0; shape < 5; shape++) {
        int64_t n = 2000;
        for (int64_t i = 0; i < n; i++)
            v[i] = shape == 0 ? next(0) : shape == 1 ? (double)i : shape == 2 ? (double)(n - i) :
                   shape == 3 ? 1.0 : (i % 97 == 0 ? INFINITY : next(7));
        for (int64_t k = 0; k < n; k += 97) ES_CHECK(check(v, n, k));
        ES_CHECK(check(v, n, n - 1));
        ES_CHECK(check(v, n, n / 2));
    }
    ES_TEST_END();
}
