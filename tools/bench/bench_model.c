/* tools/bench/bench_model.c — a 3-term linear model with permutation tests
 * (es_model_fit, RRPP) at the scale: 600 shapes x 28,000 edges,
 * 9,999 permutations. The shapes come from a seeded generator through an
 * es_source (never whole in memory): row i = (1 + effect(a_i) + slope x_i
 * + noise_i) / E with a three-level factor a, a two-level factor b without
 * an effect, and a numeric x, so a and x are found and b is not. Prints the
 * wall and CPU time and the peak RSS of the fit alone and with the
 * permutations, and the ANOVA table.
 *
 *   bench_model [--rows N] [--edges E] [--permutations B] [--scheme rrpp|raw]
 */
#include "edgespace/es_model.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

typedef struct gen {
    int64_t E;
    const char *const *a;
    const double *x;
    uint64_t seed;
} gen;

static double u01(uint64_t *s)
{
    /* splitmix64: each row has its own stream, so every pass reads the same matrix */
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (double)((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
}

static es_status gen_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n, es_mat out)
{
    const gen *g = src->userdata;
    (void)ctx;
    for (int64_t j = 0; j < n; j++) {
        const int64_t i = row0 + j;
        const int lev = g->a[i][0] - 'p';
        uint64_t s = g->seed + 7919u * (uint64_t)i;
        for (int64_t e = 0; e < g->E; e++) {
            /* the factor moves the first tenth of the edges, x the second */
            double v = 1 + 0.02 * (u01(&s) - 0.5);
            if (e < g->E / 10) v += 0.002 * lev;
            else if (e < g->E / 5) v += 0.001 * g->x[i];
            out.data[e + j * out.ld] = v / (double)g->E;
        }
    }
    return ES_OK;
}

int main(int argc, char **argv)
{
    int64_t N = 600, E = 28000, B = 9999;
    es_perm_scheme scheme = ES_PERM_RRPP;
    static const struct option lo[] = {
        {"rows", required_argument, NULL, 'n'}, {"edges", required_argument, NULL, 'e'},
        {"permutations", required_argument, NULL, 'p'}, {"scheme", required_argument, NULL, 's'},
        {NULL, 0, NULL, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "n:e:p:s:", lo, NULL)) != -1) {
        switch (c) {
        case 'n': N = atoll(optarg); break;
        case 'e': E = atoll(optarg); break;
        case 'p': B = atoll(optarg); break;
        case 's': scheme = strcmp(optarg, "raw") ? ES_PERM_RRPP : ES_PERM_RAW; break;
        default:
            fprintf(stderr, "usage: bench_model [--rows N] [--edges E] [--permutations B] "
                            "[--scheme rrpp|raw]\n");
            return 2;
        }
    }
    if (N < 12 || E < 10 || B < 0) {
        fprintf(stderr, "bench_model: need N >= 12, E >= 10, B >= 0\n");
        return 2;
    }
    static const char *const levels[3] = {"p", "q", "r"}, *const sexes[2] = {"f", "m"};
    const char **a = malloc((size_t)N * sizeof *a), **b = malloc((size_t)N * sizeof *b);
    double *x = malloc((size_t)N * sizeof *x);
    es_ctx *ctx = NULL;
    if (!a || !b || !x || es_ctx_new(&ctx) != ES_OK) return 1;
    uint64_t s = 42;
    for (int64_t i = 0; i < N; i++) {
        a[i] = levels[i % 3];
        b[i] = sexes[(i / 3) % 2];
        x[i] = u01(&s) * 2 - 1;
    }
    gen g = {E, a, x, 12345};
    es_source src = {.nedges = E, .nrows = N, .read = gen_read, .userdata = &g};
    es_model_column cols[3] = {{"a", a, NULL, NULL}, {"b", b, NULL, NULL}, {"x", NULL, x, NULL}};
    es_formula *f = NULL;
    es_design *d = NULL;
    es_model *m0 = NULL, *m = NULL;
    es_model_opts o;
    es_model_opts_init(&o);
    o.scheme = scheme;
    o.permutations = 0;
    printf("bench_model: %lld rows x %lld edges, ~ a + b + x, %lld permutations (%s)\n",
           (long long)N, (long long)E, (long long)B, scheme == ES_PERM_RAW ? "raw" : "rrpp");
    double w0 = bench_wall_s(), c0 = bench_process_cpu_s();
    es_status rc = es_formula_parse(ctx, "~ a + b + x", &f);
    if (rc == ES_OK) rc = es_design_build(ctx, f, N, cols, 3, ES_CONTRASTS_TREATMENT, &d);
    if (rc == ES_OK) rc = es_model_fit(ctx, d, &src, &o, &m0);
    double w1 = bench_wall_s(), c1 = bench_process_cpu_s();
    if (rc == ES_OK) {
        printf("fit without permutations: wall %.2f s, CPU %.2f s, peak RSS %.0f MiB\n", w1 - w0,
               c1 - c0, bench_peak_rss_mib());
        o.permutations = B;
        rc = es_model_fit(ctx, d, &src, &o, &m);
    }
    double w2 = bench_wall_s(), c2 = bench_process_cpu_s();
    if (rc != ES_OK) {
        fprintf(stderr, "bench_model: %s\n", es_ctx_errmsg(ctx));
        return 1;
    }
    printf("fit with %lld permutations: wall %.2f s, CPU %.2f s, peak RSS %.0f MiB "
           "(permutations alone: wall %.2f s, CPU %.2f s)\n", (long long)B, w2 - w1, c2 - c1,
           bench_peak_rss_mib(), (w2 - w1) - (w1 - w0), (c2 - c1) - (c1 - c0));
    printf("%-6s %5s %14s %8s %10s %8s\n", "term", "df", "SS", "R2", "F", "p");
    for (int64_t j = 0; j < m->nterms; j++)
        printf("%-6s %5lld %14.6g %8.4f %10.4g %8.4g\n", d->terms[j], (long long)m->df[j],
               m->ss[j], m->r2[j], m->f[j], m->pval[j]);
    printf("%-6s %5lld %14.6g\n", "resid", (long long)m->df_resid, m->rss);
    es_model_free(m0);
    es_model_free(m);
    es_design_free(d);
    es_formula_free(f);
    es_ctx_free(ctx);
    free(a);
    free(b);
    free(x);
    return 0;
}
