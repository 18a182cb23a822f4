/* tests/common/es_test.h — a minimal test harness (after GSL's gsl_test): checks
 * print only on failure, a test program exits 1 if any check failed, 77 to
 * be counted as skipped (meson's convention), 0 otherwise.
 *
 *   int main(void) { ES_TEST_BEGIN(); ...; ES_CHECK(x > 0); ES_TEST_END(); }
 */
#ifndef EDGESPACE_TESTS_ES_TEST_H
#define EDGESPACE_TESTS_ES_TEST_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Failed checks so far (tests/common/es_test.c). */
extern int es_test_failures;

#define ES_TEST_BEGIN() (es_test_failures = 0)
#define ES_TEST_END() return es_test_failures ? 1 : 0
#define ES_TEST_SKIP(...) do { fprintf(stderr, "SKIP: " __VA_ARGS__); \
    fputc('\n', stderr); exit(77); } while (0)

#define ES_CHECK(cond) do { if (!(cond)) { es_test_failures++; \
    fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); } } while (0)

#define ES_CHECK_MSG(cond, ...) do { if (!(cond)) { es_test_failures++; \
    fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
    fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); } } while (0)

/* |got - want| <= atol + rtol * |want|, and both finite. */
#define ES_CHECK_CLOSE(got, want, rtol, atol) do { \
    double es_g_ = (got), es_w_ = (want); \
    if (!(isfinite(es_g_) && isfinite(es_w_) && \
          fabs(es_g_ - es_w_) <= (atol) + (rtol) * fabs(es_w_))) { es_test_failures++; \
        fprintf(stderr, "%s:%d: %s = %.17g, want %s = %.17g (rtol %g, atol %g)\n", \
                __FILE__, __LINE__, #got, es_g_, #want, es_w_, (double)(rtol), \
                (double)(atol)); } } while (0)

/* A library call that must succeed; prints the context's message if not. */
#define ES_CHECK_OK(ctx, call) do { es_status es_rc_ = (call); if (es_rc_ != ES_OK) { \
    es_test_failures++; fprintf(stderr, "%s:%d: %s failed (%s): %s\n", __FILE__, \
    __LINE__, #call, es_strerror(es_rc_), es_ctx_errmsg(ctx)); } } while (0)

/* 1 if `needle` is NULL or occurs in `s`. */
int es_test_contains(const char *s, const char *needle);

/* A library call that must fail with `code` and a message containing
 * `needle` (NULL: any message). */
#define ES_CHECK_FAILS(ctx, call, code, needle) do { es_status es_rc_ = (call); \
    const char *es_m_ = es_ctx_errmsg(ctx); \
    if (es_rc_ != (code) || !es_test_contains(es_m_, (needle))) { \
        es_test_failures++; fprintf(stderr, "%s:%d: %s returned %d (%s), want %d " \
        "with message containing \"%s\"\n", __FILE__, __LINE__, #call, (int)es_rc_, \
        es_m_, (int)(code), (needle) ? (const char *)(needle) : ""); } } while (0)

/* Directory of ../shared/data beside the source tree, or NULL if absent
 * (ES_SHARED_DIR is set by tests/meson.build; the environment variable
 * EDGESPACE_SHARED overrides it). */
const char *es_test_shared_data(void);

/* Path of ../shared/<sub> or NULL if absent. */
const char *es_test_shared_path(const char *sub, char *buf, size_t n);

/* max_i |a[i] - b[i]| and max_i |a[i]| over n values (0 for n = 0): the
 * scale a result is compared to. */
double es_test_maxdiff(const double *a, const double *b, int64_t n);
double es_test_maxabs(const double *a, int64_t n);

#endif
