/* tests/parallel/test_parallel_gpa.c — generalized Procrustes analysis on the
 * ranks of an MPI job (es_gpa_align_ranks) gives the one-process result. Run
 * under `mpirun -n 2` and `-n 4` by the -Dmpi=enabled build
 * (tests/parallel/meson.build); alone in the default build, where
 * es_gpa_align_ranks is es_gpa_align.
 *
 * Every rank makes the same seeded configurations; the oracle is es_gpa_align
 * (the serial code, itself checked against R's shapes::procGPA in
 * tests/procrustes) on every configuration, run on each rank with a context
 * that is not joined to the job. The joined context aligns only this rank's
 * share. Compared to 1e-12 of their scale: the rank's aligned
 * configurations, the mean, scales, rotations, rho, sizes, centroids and the
 * report (iterations, power steps, GSS, rmsrho), for full GPA on the exact
 * Ten Berge route (n^2 k d small: rank 0 decomposes), full GPA on the
 * power-iteration route (n^2 k d > 2e8: each rank takes its dots), partial
 * GPA, and planar data;
 * 61 and 203 configurations do not split evenly. A configuration of zero
 * size on the last rank fails the fit on every rank with its message. */
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_parallel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void check(es_ctx *job, es_ctx *alone, int64_t k, int d, int64_t n, int scale,
                  const char *what)
{
    const int64_t kd = k * d;
    int64_t lo, hi;
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.scale = scale;
    es_parallel_share(job, n, &lo, &hi);
    double *x = es_test_configurations(k, d, n, 7 + (uint64_t)n);
    double *mine = malloc((size_t)(kd * (hi - lo) + 1) * 8);
    memcpy(mine, x + lo * kd, (size_t)(kd * (hi - lo)) * sizeof *x);
    /* one block per side: mean kd, size, rho, scale n, rot d*d*n, centroid d*n */
    int64_t len = kd + (3 + d * d + d) * n;
    double *a = calloc((size_t)len, 8), *b = calloc((size_t)len, 8);
    es_gpa_out oa = {a, a + kd, a + kd + n, a + kd + 2 * n, a + kd + 3 * n, a + kd + (3 + d * d) * n};
    es_gpa_out ob = {b, b + kd, b + kd + n, b + kd + 2 * n, b + kd + 3 * n, b + kd + (3 + d * d) * n};
    es_gpa_report ra, rb;
    ES_CHECK_OK(alone, es_gpa_align(alone, k, d, (es_mat){x, kd, n, kd}, &o, &oa, &ra));
    ES_CHECK_OK(job, es_gpa_align_ranks(job, k, d, n, (es_mat){mine, kd, hi - lo, kd}, &o, &ob,
                                        &rb));
    ES_CHECK_MSG(ra.iterations == rb.iterations && ra.converged && rb.converged,
                 "%s: %lld vs %lld iterations", what, (long long)ra.iterations,
                 (long long)rb.iterations);
    /* power steps (each a chain on the ranks): only on the power route */
    const int power = scale && (double)n * (double)n * (double)kd > 2e8;
    ES_CHECK_MSG(ra.power_steps == rb.power_steps && (power ? ra.power_steps >= ra.iterations
                                                            : ra.power_steps == 0),
                 "%s: %lld vs %lld power steps", what, (long long)ra.power_steps,
                 (long long)rb.power_steps);
    ES_CHECK_MSG(fabs(ra.gss - rb.gss) <= 1e-12 * ra.gss && fabs(ra.rmsrho - rb.rmsrho) <= 1e-12 *
                 ra.rmsrho && fabs(ra.total_ss - rb.total_ss) <= 1e-12 * ra.total_ss,
                 "%s: report differs (gss %.17g vs %.17g)", what, ra.gss, rb.gss);
    double dx = es_test_maxdiff(x + lo * kd, mine, kd * (hi - lo)), sx = es_test_maxabs(x, kd * n);
    ES_CHECK_MSG(dx <= 1e-12 * sx, "%s: aligned configurations differ by %g (scale %g)", what,
                 dx, sx);
    static const char *const names[] = {"mean", "size", "rho", "scale", "rotation", "centroid"};
    const int64_t off[] = {0, kd, kd + n, kd + 2 * n, kd + 3 * n, kd + (3 + d * d) * n, len};
    for (int q = 0; q < 6; q++) {
        double dq = es_test_maxdiff(a + off[q], b + off[q], off[q + 1] - off[q]);
        double sq = es_test_maxabs(a + off[q], off[q + 1] - off[q]);
        ES_CHECK_MSG(dq <= 1e-12 * sq, "%s: %s differs by %g (scale %g)", what, names[q], dq, sq);
    }
    free(x);
    free(mine);
    free(a);
    free(b);
}

int main(int argc, char **argv)
{
    ES_TEST_BEGIN();
    es_test_job run;
    es_test_job_begin(&run, &argc, &argv);
    es_ctx *job = run.job, *alone = run.alone;
    const int P = run.P, me = run.me;
    if (me == 0) printf("parallel gpa: %d rank(s)\n", P);

    check(job, alone, 40, 3, 61, 1, "full, exact scaling");
    check(job, alone, 40, 3, 61, 0, "partial");
    check(job, alone, 25, 2, 61, 1, "planar, full");
    check(job, alone, 1700, 3, 203, 1, "full, power-iteration scaling");   /* 203^2 5100 > 2e8 */

    /* a configuration of zero size in the last rank's share: every rank fails with its message */
    {
        const int64_t k = 10, kd = 30, n = 13;
        int64_t lo, hi;
        es_parallel_share(job, n, &lo, &hi);
        double *x = es_test_configurations(k, 3, n, 3);
        for (int64_t v = 0; v < kd; v++) x[(n - 1) * kd + v] = 1.0;
        ES_CHECK_FAILS(job, es_gpa_align_ranks(job, k, 3, n, (es_mat){x + lo * kd, kd, hi - lo, kd},
                                               NULL, NULL, NULL),
                       ES_EINVAL, "configuration 12 has zero centroid size");
        free(x);
    }
    int64_t msgs = 0, bytes = 0;
    es_parallel_traffic(job, &msgs, &bytes);
    ES_CHECK(P == 1 ? msgs == 0 : msgs > 0);
    if (me == 0) printf("rank 0 sent %lld messages, %lld bytes\n", (long long)msgs, (long long)bytes);
    return es_test_job_end(&run);
}
