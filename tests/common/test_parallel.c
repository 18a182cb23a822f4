/* tests/common/test_parallel.c — es_test_parallel.h. */
#include "es_test_parallel.h"
#include "es_test.h"

#include <math.h>
#include <stdlib.h>

void es_test_job_begin(es_test_job *t, int *argc, char ***argv)
{
    t->job = t->alone = NULL;
    ES_CHECK(es_ctx_new(&t->job) == ES_OK && es_ctx_new(&t->alone) == ES_OK);
    ES_CHECK_OK(t->job, es_parallel_init(t->job, argc, argv));
    ES_CHECK_OK(t->job, es_parallel_join(t->job));
    t->P = es_parallel_nranks(t->job);
    t->me = es_parallel_rank(t->job);
    ES_CHECK(t->P >= 1 && t->me >= 0 && t->me < t->P);
    ES_CHECK(es_parallel_rank(t->alone) == 0 && es_parallel_nranks(t->alone) == 1);
    if (!es_parallel_available()) ES_CHECK(t->P == 1);
}

int es_test_job_end(es_test_job *t)
{
    es_ctx_free(t->job);
    es_ctx_free(t->alone);
    t->job = t->alone = NULL;
    int failed = es_test_failures;
    es_parallel_finalize();
    return failed ? 1 : 0;
}

double *es_test_configurations(int64_t k, int d, int64_t n, uint64_t seed)
{
    es_rng rng;
    int64_t kd = k * d;
    double *x = malloc((size_t)(kd * n) * sizeof *x), *t = malloc((size_t)kd * sizeof *t);
    es_rng_init(&rng, seed);
    for (int64_t v = 0; v < kd; v++) t[v] = es_rng_normal(&rng);
    for (int64_t j = 0; j < n; j++) {
        double a = es_rng_normal(&rng), s = 1.0 + 0.2 * es_rng_uniform(&rng);
        double c = cos(a), sn = sin(a), sh[3];
        for (int q = 0; q < d; q++) sh[q] = es_rng_normal(&rng);
        for (int64_t v = 0; v < k; v++) {
            double p[3];
            for (int q = 0; q < d; q++) p[q] = t[v + q * k] + 0.05 * es_rng_normal(&rng);
            double r0 = c * p[0] - sn * p[1], r1 = sn * p[0] + c * p[1];
            x[j * kd + v] = s * r0 + sh[0];
            x[j * kd + v + k] = s * r1 + sh[1];
            if (d == 3) x[j * kd + v + 2 * k] = s * p[2] + sh[2];
        }
    }
    free(t);
    return x;
}
