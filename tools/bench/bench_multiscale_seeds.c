/* tools/bench/bench_multiscale_seeds.c — how much multi-scale interpolation
 * (Winkler et al. 2010, es_multiscale) depends on the random seed faces of
 * its patch hierarchy, and what the best of several hierarchies by the
 * method's own energy (es_multiscale_opts.tries) leaves of that spread.
 * For each real pair's midpoint: N single hierarchies (seeds 1 .. N) and N
 * best-of-T runs (seeds 1 + kT .. T + kT, disjoint blocks), each the RMS
 * ratio and max relative edge error against the midpoint's lengths, and
 * the energy; printed as min / median / max, with the rank correlation of
 * energy and RMS over the single seeds (does the energy pick well?).
 *
 *   bench_multiscale_seeds [N [T]]   (defaults 10 and 4; ../shared/data)
 */
#include <edgespace/edgespace.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

#ifndef ES_SHARED_DIR
#define ES_SHARED_DIR "../shared"
#endif

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void summary(const char *what, double *v, int n)
{
    double *c = malloc((size_t)n * sizeof *c);
    memcpy(c, v, (size_t)n * sizeof *c);
    qsort(c, (size_t)n, sizeof *c, cmp_d);
    printf("    %-28s %9.3g %% .. %9.3g %% .. %9.3g %%  (min, median, max)\n", what, 100 * c[0],
           100 * c[n / 2], 100 * c[n - 1]);
    free(c);
}

/* Spearman's rank correlation of a and b. */
static double spearman(const double *a, const double *b, int n)
{
    double ra[64], rb[64], s = 0;
    for (int i = 0; i < n; i++) {
        ra[i] = rb[i] = 0;
        for (int j = 0; j < n; j++) ra[i] += a[j] < a[i], rb[i] += b[j] < b[i];
    }
    for (int i = 0; i < n; i++) s += (ra[i] - rb[i]) * (ra[i] - rb[i]);
    return 1 - 6 * s / ((double)n * ((double)n * n - 1));
}

static int run(es_ctx *ctx, const char *name, const char *fa, const char *fb, int n, int tries)
{
    char pa[4096], pb[4096];
    es_meshdata a, b;
    es_mesh *m = NULL;
    double rms[64], mx[64], en[64], p99, w[2] = {0.5, 0.5}, *l, *out, t0, t_one = 0, t_best = 0;
    snprintf(pa, sizeof pa, "%s/data/%s", ES_SHARED_DIR, fa);
    snprintf(pb, sizeof pb, "%s/data/%s", ES_SHARED_DIR, fb);
    if (es_meshdata_read(ctx, pa, ES_FORMAT_AUTO, &a) != ES_OK) {
        printf("%s: skipped (%s)\n", name, es_ctx_errmsg(ctx));
        return 0;
    }
    if (es_meshdata_read(ctx, pb, ES_FORMAT_AUTO, &b) != ES_OK ||
        es_mesh_new(ctx, a.nverts, a.nfaces, a.faces, NULL, &m) != ES_OK)
        return 1;
    l = malloc((size_t)es_mesh_nedges(m) * sizeof *l);
    out = malloc(3 * (size_t)a.nverts * sizeof *out);
    const double *in[2] = {a.xyz, b.xyz};
    es_interp_targets(ctx, m, 2, in, w, l, NULL, NULL);
    printf("%s: %lld vertices, midpoint of %s -> %s\n", name, (long long)a.nverts, fa, fb);
    for (int pass = 0; pass < 2; pass++) {
        es_multiscale_opts o;
        es_multiscale_opts_init(&o);
        o.tries = pass ? tries : 1;
        for (int k = 0; k < n; k++) {
            es_multiscale *ms = NULL;
            es_multiscale_info info;
            es_ctx_set_seed(ctx, 1 + (uint64_t)k * (uint64_t)o.tries);
            t0 = bench_process_cpu_s();
            if (es_multiscale_new(ctx, m, &o, &ms) != ES_OK ||
                es_multiscale_interp(ctx, ms, 2, in, w, NULL, out, NULL) != ES_OK) {
                printf("  %s\n", es_ctx_errmsg(ctx));
                return 1;
            }
            *(pass ? &t_best : &t_one) += bench_process_cpu_s() - t0;
            es_multiscale_get_info(ms, &info);
            es_embed_length_error(ctx, m, out, l, 0, &rms[k], &mx[k], &p99);
            en[k] = info.energy;
            es_multiscale_free(ms);
        }
        printf("  %s (%.2f s CPU each, hierarchies included):\n",
               pass ? "best of the tries by energy" : "one hierarchy per seed",
               (pass ? t_best : t_one) / n);
        if (pass) printf("    (tries = %d, seeds in disjoint blocks)\n", tries);
        summary("RMS ratio", rms, n);
        summary("max relative edge error", mx, n);
        if (!pass) printf("    Spearman(energy, RMS ratio) over the seeds: %.2f\n",
                          spearman(en, rms, n));
    }
    es_mesh_free(m);
    es_meshdata_clear(ctx, &a);
    es_meshdata_clear(ctx, &b);
    free(l);
    free(out);
    return 0;
}

int main(int argc, char **argv)
{
    es_ctx *ctx;
    int n = argc > 1 ? atoi(argv[1]) : 10, tries = argc > 2 ? atoi(argv[2]) : 4, rc = 0;
    if (n < 3 || n > 64 || tries < 1 || tries > 64) {
        fprintf(stderr, "usage: bench_multiscale_seeds [N (3..64) [TRIES (1..64)]]\n");
        return 2;
    }
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    rc |= run(ctx, "cat", "sumner_cat_poses/cat-01.obj", "sumner_cat_poses/cat-02.obj", n, tries);
    rc |= run(ctx, "face-study", "face-study/s001_neutral.obj", "face-study/s001_happy.obj", n,
              tries);
    rc |= run(ctx, "cactus", "goast_cactus/cactus0.obj", "goast_cactus/cactus1.obj", n, tries);
    es_ctx_free(ctx);
    return rc;
}
