/* tests/parallel/test_parallel_pca.c — PCA on the ranks of an MPI job gives
 * the one-process result. Run under `mpirun -n 2` and `-n 4` by the
 * -Dmpi=enabled build (tests/parallel/meson.build); alone in the default
 * build, where it checks that a context is rank 0 of 1 and the same calls
 * work without MPI.
 *
 * Every rank makes the same seeded matrix; the oracle is es_pca_fit on a
 * context that is not joined to the job (one process, the serial code),
 * run on every rank. The joined context runs the Gram route (a matrix
 * source: each rank takes its strip of edges in place; a callback source:
 * rows read in shares and exchanged all-to-all), the covariance route and
 * the randomized route (rows shared, partial products summed): eigenvalues,
 * mean, components and scores agree to 1e-12 of their scale (sums are added
 * in another order); a linear model's permutations, shared over the ranks,
 * give the same p-values. A reader that fails on one rank fails the fit on every
 * rank with that rank's message. */
#include "core/core_private.h"   /* ES_FAIL: a reader sets its message */
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_parallel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct data {
    int64_t E, N;
    double *X;       /* E x N */
    int fail_rank;   /* the rank whose reads fail (-1: none) */
    int rank;
} data;

static void make(data *d, int64_t E, int64_t N)
{
    es_rng rng;
    d->E = E;
    d->N = N;
    d->X = malloc((size_t)(E * N) * sizeof *d->X);
    d->fail_rank = -1;
    es_rng_init(&rng, 2027);
    /* rank-5 variation about 1/E plus noise */
    double basis[5][512];
    for (int k = 0; k < 5; k++)
        for (int64_t e = 0; e < E && e < 512; e++) basis[k][e] = es_rng_normal(&rng);
    for (int64_t j = 0; j < N; j++)
        for (int64_t e = 0; e < E; e++) {
            double v = 1.0;
            for (int k = 0; k < 5; k++)
                v += 0.05 / (k + 1) * basis[k][e % 512] * sin(0.7 * (double)(j + 1) * (k + 1));
            d->X[e + j * E] = (v + 0.002 * es_rng_normal(&rng)) / (double)E;
        }
}

static es_status read_rows(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n, es_mat out)
{
    const data *d = src->userdata;
    if (d->rank == d->fail_rank && n > 0)
        ES_FAIL(ctx, ES_EIO, "reader: rank %d cannot read row %lld", d->rank, (long long)row0);
    for (int64_t j = 0; j < n; j++)
        memcpy(&ES_AT(out, 0, j), d->X + (row0 + j) * d->E, (size_t)d->E * sizeof(double));
    return ES_OK;
}

/* The fit on the job agrees with the fit alone. */
static void same_fit(const es_pca *a, const es_pca *b, const char *what)
{
    ES_CHECK_MSG(a->ncomp == b->ncomp && a->method == b->method, "%s: %lld vs %lld components",
                 what, (long long)a->ncomp, (long long)b->ncomp);
    if (a->ncomp != b->ncomp) return;
    const int64_t E = a->nedges, N = a->nrows, K = a->ncomp;
    double tol = 1e-12;
    ES_CHECK_MSG(fabs(a->total_variance - b->total_variance) <= tol * b->total_variance,
                 "%s: total variance %.17g vs %.17g", what, a->total_variance, b->total_variance);
    ES_CHECK_MSG(es_test_maxdiff(a->eigenvalues, b->eigenvalues, K) <= tol * es_test_maxabs(b->eigenvalues, K),
                 "%s: eigenvalues differ by %g", what, es_test_maxdiff(a->eigenvalues, b->eigenvalues, K));
    ES_CHECK_MSG(es_test_maxdiff(a->mean, b->mean, E) <= tol * es_test_maxabs(b->mean, E), "%s: mean", what);
    /* components and scores: the well-separated leading ones (the noise
     * floor's eigenvectors are not determined to 1e-12 by any order) */
    int64_t k_sep = K < 5 ? K : 5;
    ES_CHECK_MSG(es_test_maxdiff(a->components, b->components, E * k_sep) <= 1e-9,
                 "%s: components differ by %g", what,
                 es_test_maxdiff(a->components, b->components, E * k_sep));
    ES_CHECK_MSG(es_test_maxdiff(a->scores, b->scores, N * k_sep) <= 1e-12 * es_test_maxabs(b->scores, N * k_sep) + 1e-15,
                 "%s: scores differ by %g", what, es_test_maxdiff(a->scores, b->scores, N * k_sep));
}

static void check_route(es_ctx *job, es_ctx *alone, data *d, es_pca_method m, int64_t K,
                        int matrix, const char *what)
{
    es_source src = matrix ? es_source_matrix((es_mat){d->X, d->E, d->N, d->E}, NULL, d->N)
                           : (es_source){d->E, d->N, read_rows, d, 7, {0}, NULL};
    es_pca_opts o;
    es_pca *pj = NULL, *pa = NULL;
    es_pca_opts_init(&o);
    o.method = m;
    o.ncomp = K;
    ES_CHECK_OK(alone, es_pca_fit(alone, &src, &o, &pa));
    ES_CHECK_OK(job, es_pca_fit(job, &src, &o, &pj));
    if (pj && pa) same_fit(pj, pa, what);
    es_pca_free(pj);
    es_pca_free(pa);
}

int main(int argc, char **argv)
{
    ES_TEST_BEGIN();
    es_test_job run;
    es_test_job_begin(&run, &argc, &argv);
    es_ctx *job = run.job, *alone = run.alone;
    const int P = run.P, me = run.me;
    if (me == 0) printf("parallel pca: %d rank(s), MPI %s\n", P,
                        es_parallel_available() ? "built in" : "not built");
    es_ctx_set_seed(job, 99);
    es_ctx_set_seed(alone, 99);

    data d;
    make(&d, 300, 61);   /* N <= E: the Gram route; 61 rows do not split evenly */
    d.rank = me;
    check_route(job, alone, &d, ES_PCA_GRAM, 0, 1, "gram, matrix source, all components");
    check_route(job, alone, &d, ES_PCA_GRAM, 8, 1, "gram, matrix source, top 8");
    check_route(job, alone, &d, ES_PCA_GRAM, 8, 0, "gram, rows exchanged, top 8");
    check_route(job, alone, &d, ES_PCA_RANDOMIZED, 5, 0, "randomized, top 5");
    free(d.X);
    make(&d, 23, 61);    /* E < N: the covariance route */
    d.rank = me;
    check_route(job, alone, &d, ES_PCA_COVARIANCE, 0, 0, "covariance, all components");

    /* a linear model's permutations, shared over the ranks: F, SS of every
     * permutation and the p-values bit for bit those of one process */
    {
        const char *g[61];
        double x[61];
        for (int i = 0; i < 61; i++) {
            g[i] = i % 3 == 0 ? "a" : i % 3 == 1 ? "b" : "c";
            x[i] = sin(0.3 * i);
        }
        es_model_column cols[2] = {{"g", g, NULL, NULL}, {"x", NULL, x, NULL}};
        es_formula *fm = NULL;
        es_design *dsg = NULL;
        es_model *mj = NULL, *ma = NULL;
        es_model_opts mo;
        es_model_opts_init(&mo);
        mo.permutations = 199;
        mo.seed = 11;
        es_source src = {d.E, d.N, read_rows, &d, 7, {0}, NULL};
        ES_CHECK_OK(alone, es_formula_parse(alone, "~ g + x", &fm));
        ES_CHECK_OK(alone, es_design_build(alone, fm, 61, cols, 2, ES_CONTRASTS_TREATMENT, &dsg));
        ES_CHECK_OK(alone, es_model_fit(alone, dsg, &src, &mo, &ma));
        ES_CHECK_OK(job, es_model_fit(job, dsg, &src, &mo, &mj));
        if (ma && mj) {
            const int64_t n = ma->permutations * ma->nterms;
            ES_CHECK(mj->nterms == ma->nterms && mj->permutations == ma->permutations);
            for (int64_t t = 0; t < ma->nterms; t++)
                ES_CHECK_MSG(mj->pval[t] == ma->pval[t], "model term %lld: p %.17g vs %.17g",
                             (long long)t, mj->pval[t], ma->pval[t]);
            ES_CHECK_MSG(es_test_maxdiff(mj->ssperm, ma->ssperm, n) <= 1e-12 * es_test_maxabs(ma->ssperm, n),
                         "model: permutation SS differ by %g", es_test_maxdiff(mj->ssperm, ma->ssperm, n));
        }
        es_model_free(mj);
        es_model_free(ma);
        es_design_free(dsg);
        es_formula_free(fm);
    }

    /* a reader that fails on the last rank fails the fit everywhere, with its message */
    d.fail_rank = P - 1;
    {
        es_source src = {d.E, d.N, read_rows, &d, 7, {0}, NULL};
        es_pca_opts o;
        es_pca *p = NULL;
        es_pca_opts_init(&o);
        o.method = ES_PCA_COVARIANCE;
        ES_CHECK_FAILS(job, es_pca_fit(job, &src, &o, &p), ES_EIO, "cannot read row");
        ES_CHECK(p == NULL);
        char want[64];
        snprintf(want, sizeof want, "rank %d", P - 1);
        ES_CHECK_MSG(strstr(es_ctx_errmsg(job), want) != NULL, "%s", es_ctx_errmsg(job));
    }
    free(d.X);
    int64_t msgs = 0, bytes = 0;
    es_parallel_traffic(job, &msgs, &bytes);
    ES_CHECK(P == 1 ? msgs == 0 && bytes == 0 : msgs > 0 && bytes > 0);
    if (me == 0) printf("rank 0 sent %lld messages, %lld bytes\n", (long long)msgs, (long long)bytes);
    return es_test_job_end(&run);
}
