/* tools/bench/bench_pca.c — PCA of a synthetic shape set at the paper's FRGC
 * scale (600 shapes x 175,000 edges, Section 4 of Fisher et al.), streamed
 * in blocks from a generator so that the data never sit in memory whole.
 *
 * Row i = (1 + basis * c_i + noise_i) / E: a rank-R variation with decaying
 * weights plus uniform noise, drawn from the seeded RNG per row so that
 * every pass sees the same matrix. Prints the time and peak RSS of the exact
 * fit (all components, Gram route) and of a randomized top-K fit, and the
 * randomized eigenvalues' relative error. If python3 with numpy is on the
 * PATH it also times numpy.linalg.svd on the same matrix (written to a
 * temporary .npy) and prints the ratio; otherwise it says it skipped that.
 *
 *   bench_pca [--rows N] [--edges E] [--rank R] [--components K] [--no-numpy]
 */

#include "edgespace/es_stats.h"

#include <cblas.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench_clock.h"

typedef struct gen {
    int64_t E, N, R;
    double *basis;   /* E x R */
    double *coef;    /* R x N */
    uint64_t seed;
    int64_t rows_read;
} gen;

static es_status gen_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n, es_mat out)
{
    gen *g = src->userdata;
    (void)ctx;
    /* noise: a splitmix64 hash of (seed, row, edge), cheap and the same on
     * every pass */
    for (int64_t j = 0; j < n; j++) {
        double *x = &ES_AT(out, 0, j);
        uint64_t base = g->seed + (uint64_t)(row0 + j) * (uint64_t)g->E;
        for (int64_t e = 0; e < g->E; e++) {
            uint64_t z = (base + (uint64_t)e) * 0x9e3779b97f4a7c15ull;
            z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
            z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
            z ^= z >> 31;
            x[e] = 1.0 + 0.01 * ((double)(z >> 11) * 0x1.0p-53 - 0.5);
        }
    }
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)g->E, (int)n, (int)g->R, 1.0,
                g->basis, (int)g->E, g->coef + row0 * g->R, (int)g->R, 1.0, out.data, (int)out.ld);
    for (int64_t j = 0; j < n; j++)
        for (int64_t e = 0; e < g->E; e++) ES_AT(out, e, j) /= (double)g->E;
    g->rows_read += n;
    return ES_OK;
}

static const char *loadavg(void)
{
    static char buf[64] = "?";
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (!fgets(buf, sizeof buf, f)) strcpy(buf, "?");
        fclose(f);
        buf[strcspn(buf, "\n")] = '\0';
    }
    return buf;
}

/* Stage timings from the progress callback: wall time from the previous
 * stage's end to this stage's last report. */
typedef struct stages {
    const char *what[8];
    double end[8];
    int n;
    double t0;
} stages;

static void on_progress(void *ud, const char *what, int64_t done, int64_t total)
{
    stages *st = ud;
    (void)done, (void)total;
    if (st->n == 0 || strcmp(st->what[st->n - 1], what)) {
        if (st->n == 8) return;
        st->what[st->n++] = what;
    }
    st->end[st->n - 1] = bench_wall_s();
}

static void print_stages(const stages *st)
{
    double prev = st->t0;
    printf("    stages:");
    for (int i = 0; i < st->n; i++) {
        printf(" %s %.2f s;", st->what[i], st->end[i] - prev);
        prev = st->end[i];
    }
    printf("\n");
}

static int have_numpy(void)
{
    return system("python3 -c 'import numpy' >/dev/null 2>&1") == 0;
}

int main(int argc, char **argv)
{
    int64_t N = 600, E = 175000, R = 20, K = 10;
    int numpy = 1;
    static const struct option lo[] = {
        {"rows", required_argument, 0, 'n'}, {"edges", required_argument, 0, 'e'},
        {"rank", required_argument, 0, 'r'}, {"components", required_argument, 0, 'k'},
        {"no-numpy", no_argument, 0, 'x'}, {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        switch (c) {
        case 'n': N = atoll(optarg); break;
        case 'e': E = atoll(optarg); break;
        case 'r': R = atoll(optarg); break;
        case 'k': K = atoll(optarg); break;
        case 'x': numpy = 0; break;
        default:
            printf("usage: bench_pca [--rows N] [--edges E] [--rank R] [--components K] "
                   "[--no-numpy]\n");
            return c == 'h' ? 0 : 2;
        }
    }
    es_ctx *ctx;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    gen g = {E, N, R, NULL, NULL, 12345, 0};
    g.basis = malloc((size_t)(E * R) * sizeof(double));
    g.coef = malloc((size_t)(R * N) * sizeof(double));
    es_rng rng;
    es_rng_init(&rng, 777);
    for (int64_t i = 0; i < E * R; i++) g.basis[i] = 0.02 * es_rng_normal(&rng);
    for (int64_t j = 0; j < N; j++)
        for (int64_t k = 0; k < R; k++) g.coef[k + j * R] = es_rng_normal(&rng) / (double)(k + 1);
    es_source src;
    memset(&src, 0, sizeof src);
    src.nedges = E;
    src.nrows = N;
    src.read = gen_read;
    src.userdata = &g;

    printf("bench_pca: %lld shapes x %lld edges (%.0f MiB as doubles), rank %lld + noise\n",
           (long long)N, (long long)E, (double)N * (double)E * 8 / 1048576.0, (long long)R);
    /* time to generate the data once (part of every pass below) */
    double *blk = malloc((size_t)E * 64 * sizeof(double));
    double t0 = bench_wall_s(), cg0 = bench_process_cpu_s();
    for (int64_t r0 = 0; r0 < N; r0 += 64) {
        int64_t n = N - r0 < 64 ? N - r0 : 64;
        gen_read(ctx, &src, r0, n, (es_mat){blk, E, n, E});
    }
    double tgen = bench_wall_s() - t0, cgen = bench_process_cpu_s() - cg0;
    printf("  load average at start: %s\n", loadavg());
    free(blk);
    printf("  generating one pass of the data:   %7.2f s wall, %.2f s CPU\n", tgen, cgen);

    es_pca_opts o;
    es_pca_opts_init(&o);
    es_pca *exact = NULL, *rnd = NULL;
    stages stg;
    memset(&stg, 0, sizeof stg);
    es_ctx_set_progress(ctx, on_progress, &stg);
    g.rows_read = 0;
    t0 = bench_wall_s();
    stg.t0 = t0;
    double c0 = bench_process_cpu_s();
    if (es_pca_fit(ctx, &src, &o, &exact) != ES_OK) {
        fprintf(stderr, "bench_pca: %s\n", es_ctx_errmsg(ctx));
        return 1;
    }
    double texact = bench_wall_s() - t0, cexact = bench_process_cpu_s() - c0;
    double rss_exact = bench_peak_rss_mib();
    printf("  exact PCA (Gram route, %lld components): %7.2f s wall, %.2f s CPU  (%.2f passes over "
           "the data, ~%.2f s CPU of them generating), peak RSS %.0f MiB\n",
           (long long)exact->ncomp, texact, cexact, (double)g.rows_read / (double)N,
           cgen * (double)g.rows_read / (double)N, rss_exact);
    print_stages(&stg);
    double cum = 0;
    for (int64_t k = 0; k < 3 && k < exact->ncomp; k++) cum += exact->explained[k];
    printf("    eigenvalues 1..3: %.6g %.6g %.6g; top 3 explain %.1f%% of the variance\n",
           exact->eigenvalues[0], exact->eigenvalues[1], exact->eigenvalues[2], 100 * cum);

    {
        es_pca *top = NULL;
        es_pca_opts ot = o;
        ot.ncomp = 20;
        g.rows_read = 0;
        t0 = bench_wall_s();
        c0 = bench_process_cpu_s();
        if (es_pca_fit(ctx, &src, &ot, &top) != ES_OK) {
            fprintf(stderr, "bench_pca: %s\n", es_ctx_errmsg(ctx));
            return 1;
        }
        printf("  exact PCA (Gram route, top 20):     %7.2f s wall, %.2f s CPU  (%.2f passes)\n",
               bench_wall_s() - t0, bench_process_cpu_s() - c0, (double)g.rows_read / (double)N);
        es_pca_free(top);
    }
    o.method = ES_PCA_RANDOMIZED;
    o.ncomp = K;
    g.rows_read = 0;
    t0 = bench_wall_s();
    c0 = bench_process_cpu_s();
    if (es_pca_fit(ctx, &src, &o, &rnd) != ES_OK) {
        fprintf(stderr, "bench_pca: %s\n", es_ctx_errmsg(ctx));
        return 1;
    }
    double trnd = bench_wall_s() - t0, crnd = bench_process_cpu_s() - c0;
    double maxrel = 0;
    for (int64_t k = 0; k < K; k++) {
        double rel = fabs(rnd->eigenvalues[k] - exact->eigenvalues[k]) / exact->eigenvalues[k];
        if (rel > maxrel) maxrel = rel;
    }
    printf("  randomized PCA (top %lld, p=%lld, q=%lld): %7.2f s wall, %.2f s CPU  (%.2f passes), "
           "max relative eigenvalue error %.2e\n", (long long)K, (long long)o.oversample,
           (long long)o.power_iters, trnd, crnd, (double)g.rows_read / (double)N, maxrel);

    if (numpy && have_numpy()) {
        char path[] = "/tmp/bench_pca_XXXXXX";
        int fd = mkstemp(path);
        if (fd >= 0) {
            close(fd);
            char npy[64];
            snprintf(npy, sizeof npy, "%s.npy", path);
            FILE *f = fopen(npy, "wb");
            char hdr[128];
            int hl = snprintf(hdr, sizeof hdr, "{'descr': '<f8', 'fortran_order': True, "
                              "'shape': (%lld, %lld), }", (long long)E, (long long)N);
            int total = 10 + hl + 1;
            int pad = (64 - total % 64) % 64;
            fwrite("\x93NUMPY\x01\x00", 1, 8, f);
            unsigned short len = (unsigned short)(hl + pad + 1);
            fputc(len & 0xff, f);
            fputc(len >> 8, f);
            fwrite(hdr, 1, (size_t)hl, f);
            for (int i = 0; i < pad; i++) fputc(' ', f);
            fputc('\n', f);
            double *b = malloc((size_t)E * 64 * sizeof(double));
            for (int64_t r0 = 0; r0 < N; r0 += 64) {
                int64_t n = N - r0 < 64 ? N - r0 : 64;
                gen_read(ctx, &src, r0, n, (es_mat){b, E, n, E});
                fwrite(b, sizeof(double), (size_t)(E * n), f);
            }
            free(b);
            fclose(f);
            char cmd[512];
            snprintf(cmd, sizeof cmd, "python3 -c \"import numpy as np, time; X = np.load('%s'); "
                     "t = time.time(); Xc = X - X.mean(axis=1, keepdims=True); "
                     "np.linalg.svd(Xc, full_matrices=False); print(time.time() - t)\"", npy);
            FILE *pp = popen(cmd, "r");
            double tnp = -1;
            if (pp && fscanf(pp, "%lf", &tnp) == 1)
                printf("  numpy.linalg.svd (centred, thin):   %7.2f s  -> ratio numpy / exact "
                       "%.2f\n", tnp, tnp / texact);
            else
                printf("  numpy.linalg.svd: failed to run\n");
            if (pp) pclose(pp);
            remove(npy);
            remove(path);
        }
    } else {
        printf("  numpy.linalg.svd: skipped (python3 with numpy not available)\n");
    }
    es_pca_free(exact);
    es_pca_free(rnd);
    free(g.basis);
    free(g.coef);
    es_ctx_free(ctx);
    return 0;
}
