/* tools/bench/bench_gpa.c — GPA throughput on mesh-sized data.
 *
 *   bench_gpa [n=600] [k=58000] [noscale]
 *
 * Builds n configurations of k vertices (a smooth base surface plus local
 * noise, each under a random similarity), then times es_gpa_align (full GPA
 * unless "noscale") and the tangent PCA of the result. Prints the figures and
 * the peak resident memory next to the size of the coordinates. The issue's
 * target: 600 x 58,000 in under 10 s with memory about that of the data.
 */
#include <edgespace/edgespace.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

/* xorshift-based uniform and normal numbers: the benchmark's own data. */
static uint64_t state = 0x9e3779b97f4a7c15ULL;
static double unif(void)
{
    state ^= state << 13; state ^= state >> 7; state ^= state << 17;
    return (double)(state >> 11) * (1.0 / 9007199254740992.0);
}
static double gauss(void)
{
    double u = unif(), v = unif();
    return sqrt(-2 * log(u + 1e-300)) * cos(2 * M_PI * v);
}

static void on_log(void *ud, es_log_level level, const char *msg)
{
    (void)ud; (void)level;
    printf("  [log] %s\n", msg);
}

int main(int argc, char **argv)
{
    int64_t n = argc > 1 ? atoll(argv[1]) : 600, k = argc > 2 ? atoll(argv[2]) : 58000;
    int scale = !(argc > 3 && !strcmp(argv[3], "noscale"));
    int64_t kd = 3 * k;
    double *x = malloc((size_t)(kd * n) * sizeof *x), *base = malloc((size_t)kd * sizeof *base);
    if (!x || !base) { fprintf(stderr, "bench_gpa: out of memory\n"); return 1; }
    for (int64_t v = 0; v < k; v++) {   /* points on a bumpy ellipsoid */
        double t = M_PI * unif(), p = 2 * M_PI * unif(), r = 1 + 0.1 * sin(5 * t) * cos(3 * p);
        base[v] = 2 * r * sin(t) * cos(p);
        base[v + k] = r * sin(t) * sin(p);
        base[v + 2 * k] = 0.7 * r * cos(t);
    }
    for (int64_t j = 0; j < n; j++) {
        double q[4], nq = 0, s = 0.8 + 0.4 * unif(), sh[3] = {gauss(), gauss(), gauss()};
        for (int i = 0; i < 4; i++) { q[i] = gauss(); nq += q[i] * q[i]; }
        nq = sqrt(nq);
        double w = q[0] / nq, a = q[1] / nq, b = q[2] / nq, c = q[3] / nq;
        double r[9] = {1 - 2 * (b * b + c * c), 2 * (a * b + w * c), 2 * (a * c - w * b),
                       2 * (a * b - w * c), 1 - 2 * (a * a + c * c), 2 * (b * c + w * a),
                       2 * (a * c + w * b), 2 * (b * c - w * a), 1 - 2 * (a * a + b * b)};
        double amp = 0.05 * gauss();   /* a per-shape global deformation plus noise */
        double *col = x + j * kd;
        for (int64_t v = 0; v < k; v++) {
            double p0 = base[v] * (1 + amp) + 0.01 * gauss(), p1 = base[v + k] + 0.01 * gauss();
            double p2 = base[v + 2 * k] * (1 - amp) + 0.01 * gauss();
            col[v] = s * (p0 * r[0] + p1 * r[1] + p2 * r[2]) + sh[0];
            col[v + k] = s * (p0 * r[3] + p1 * r[4] + p2 * r[5]) + sh[1];
            col[v + 2 * k] = s * (p0 * r[6] + p1 * r[7] + p2 * r[8]) + sh[2];
        }
    }
    free(base);
    double data_mib = (double)(kd * n) * 8 / 1048576.0, rss0 = bench_peak_rss_mib();

    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    es_ctx_set_log(ctx, on_log, NULL);
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.scale = scale;
    es_gpa_report rep;
    double *mean = malloc((size_t)kd * sizeof *mean), *rho = malloc((size_t)n * sizeof *rho);
    es_gpa_out out = {0};
    out.mean = mean;
    out.rho = rho;
    double t0 = bench_wall_s(), c0 = bench_process_cpu_s();
    es_status rc = es_gpa_align(ctx, k, 3, (es_mat){x, kd, n, kd}, &o, &out, &rep);
    double t1 = bench_wall_s(), c1 = bench_process_cpu_s();
    if (rc != ES_OK) { fprintf(stderr, "bench_gpa: %s\n", es_ctx_errmsg(ctx)); return 1; }
    double rss1 = bench_peak_rss_mib();
    /* tangent coordinates in place, then the first 10 PCs */
    double sd[10], pc[10];
    rc = es_gpa_tangent(ctx, k, 3, (es_mat){x, kd, n, kd}, mean, ES_TANGENT_RESIDUAL,
                        (es_mat){x, kd, n, kd});
    double t2 = bench_wall_s();
    if (rc == ES_OK)
        rc = es_gpa_pca(ctx, (es_mat){x, kd, n, kd}, 10, sd, pc, (es_mat){0}, (es_mat){0});
    double t3 = bench_wall_s();
    if (rc != ES_OK) { fprintf(stderr, "bench_gpa: %s\n", es_ctx_errmsg(ctx)); return 1; }
    printf("GPA %s, n = %lld configurations x k = %lld vertices (3D)\n",
           scale ? "full (scale)" : "partial (no scale)", (long long)n, (long long)k);
    printf("  align:      %.2f s wall, %.2f s CPU  (%lld iterations, rotation change %.2e, scale change %.2e, "
           "rmsrho %.4f)\n", t1 - t0, c1 - c0, (long long)rep.iterations, rep.rot_change,
           rep.scale_change, rep.rmsrho);
    printf("  per iteration: %.3f s wall (rotation sweep + Ten Berge step)\n",
           (t1 - t0) / (double)rep.iterations);
    printf("  tangent:    %.2f s\n", t2 - t1);
    printf("  PCA (10):   %.2f s  (PC1 %.1f%%, PC2 %.1f%%)\n", t3 - t2, pc[0], pc[1]);
    printf("  memory:     coordinates %.0f MiB, peak RSS %.0f MiB before GPA, %.0f MiB after "
           "(+%.1f MiB)\n", data_mib, rss0, rss1, rss1 - rss0);
    free(x); free(mean); free(rho);
    es_ctx_free(ctx);
    return 0;
}
