/* tests/stats/test_pca.c — PCA against a direct SVD of the centred matrix
 * (LAPACKE_dgesvd), orthonormality, block-size independence,
 * reproducibility, the randomized route's accuracy, projection. */
#include "es_test.h"
#include "core/core_private.h"
#include "edgespace/es_stats.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_io.h"
#include "edgespace/es_mesh.h"

#include <cblas.h>
#include <lapacke.h>

/* Normalized-length-like data: 1/E (1 + low-rank variation with decaying
 * spectrum + noise), E x N. */
static double *make_data(int64_t E, int64_t N, int64_t rank, double noise, uint64_t seed)
{
    es_rng rng;
    es_rng_init(&rng, seed);
    double *X = malloc((size_t)(E * N) * sizeof *X);
    double *basis = malloc((size_t)(E * rank) * sizeof *basis);
    for (int64_t i = 0; i < E * rank; i++) basis[i] = es_rng_normal(&rng);
    for (int64_t j = 0; j < N; j++) {
        for (int64_t e = 0; e < E; e++) X[e + j * E] = 1.0 + noise * es_rng_normal(&rng);
        for (int64_t k = 0; k < rank; k++) {
            double c = 0.05 * es_rng_normal(&rng) / (double)(k + 1);
            for (int64_t e = 0; e < E; e++) X[e + j * E] += c * basis[e + k * E];
        }
        for (int64_t e = 0; e < E; e++) X[e + j * E] /= (double)E;
    }
    free(basis);
    return X;
}

/* Reference: SVD of the centred matrix. ev (min(E,N)), U (E x min), S (N x min) scores. */
typedef struct ref { int64_t m; double *ev, *U, *S, *mean; } ref;

static ref reference(const double *X, int64_t E, int64_t N)
{
    ref r;
    int64_t m = E < N ? E : N;
    r.m = m;
    r.mean = calloc((size_t)E, sizeof(double));
    double *A = malloc((size_t)(E * N) * sizeof *A);
    for (int64_t j = 0; j < N; j++)
        for (int64_t e = 0; e < E; e++) r.mean[e] += X[e + j * E] / (double)N;
    for (int64_t j = 0; j < N; j++)
        for (int64_t e = 0; e < E; e++) A[e + j * E] = X[e + j * E] - r.mean[e];
    double *s = malloc((size_t)m * sizeof *s), *VT = malloc((size_t)(m * N) * sizeof *VT);
    double *sup = malloc((size_t)m * sizeof *sup);
    r.U = malloc((size_t)(E * m) * sizeof *r.U);
    r.S = malloc((size_t)(N * m) * sizeof *r.S);
    r.ev = malloc((size_t)m * sizeof *r.ev);
    int info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'S', 'S', (int)E, (int)N, A, (int)E, s, r.U,
                              (int)E, VT, (int)m, sup);
    if (info != 0) { fprintf(stderr, "dgesvd failed\n"); exit(1); }
    for (int64_t k = 0; k < m; k++) {
        r.ev[k] = s[k] * s[k] / (double)(N - 1);
        for (int64_t i = 0; i < N; i++) r.S[i + k * N] = VT[k + i * m] * s[k];
    }
    free(A); free(s); free(VT); free(sup);
    return r;
}

static void ref_free(ref *r) { free(r->ev); free(r->U); free(r->S); free(r->mean); }

/* Compare a fit with the reference on its first K components. */
static void check_against(const es_pca *p, const ref *r, int64_t K, double tol_ev, double tol_vec)
{
    const int64_t E = p->nedges, N = p->nrows;
    ES_CHECK(p->ncomp >= K);
    for (int64_t e = 0; e < E; e++) ES_CHECK_CLOSE(p->mean[e], r->mean[e], 1e-13, 0);
    for (int64_t k = 0; k < K; k++) {
        ES_CHECK_CLOSE(p->eigenvalues[k], r->ev[k], tol_ev, 0);
        double dot = cblas_ddot((int)E, p->components + k * E, 1, r->U + k * E, 1);
        double sg = dot < 0 ? -1 : 1;
        ES_CHECK_CLOSE(fabs(dot), 1.0, tol_vec, 0);
        double scale = sqrt(r->ev[0] * (double)(N - 1));
        for (int64_t i = 0; i < N; i++)
            ES_CHECK_CLOSE(p->scores[i + k * N], sg * r->S[i + k * N], 0, tol_vec * scale);
    }
}

static void check_orthonormal(const es_pca *p, double tol)
{
    const int64_t E = p->nedges, K = p->ncomp;
    for (int64_t a = 0; a < K; a++) {
        /* deterministic sign: largest-magnitude entry positive */
        double big = 0, val = 0;
        for (int64_t e = 0; e < E; e++)
            if (fabs(p->components[e + a * E]) > big) big = fabs(val = p->components[e + a * E]);
        ES_CHECK(val > 0);
        for (int64_t b = a; b < K; b++) {
            double d = cblas_ddot((int)E, p->components + a * E, 1, p->components + b * E, 1);
            ES_CHECK_CLOSE(d, a == b ? 1.0 : 0.0, 0, tol);
        }
        if (a + 1 < K) ES_CHECK(p->eigenvalues[a] >= p->eigenvalues[a + 1]);
    }
}

static void test_exact(es_ctx *ctx, int64_t E, int64_t N, es_pca_method method)
{
    double *X = make_data(E, N, 6, 0.002, 42 + (uint64_t)N);
    ref r = reference(X, E, N);
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    es_pca_opts o;
    es_pca_opts_init(&o);
    o.method = method;
    es_pca *p[4] = {NULL, NULL, NULL, NULL};
    const int64_t blocks[4] = {0, 1, 7, N};
    for (int b = 0; b < 4; b++) {
        src.block = blocks[b];
        ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p[b]));
    }
    if (!p[0] || !p[1] || !p[2] || !p[3]) goto out;
    int64_t rank = (E < N - 1 ? E : N - 1);
    ES_CHECK(p[0]->ncomp == rank);
    ES_CHECK(p[0]->method == (N <= E ? ES_PCA_GRAM : ES_PCA_COVARIANCE) || method != ES_PCA_AUTO);
    check_against(p[0], &r, p[0]->ncomp, 1e-10, 1e-9);
    check_orthonormal(p[0], 1e-12 * (double)(N + E));
    double sum = 0;
    for (int64_t k = 0; k < p[0]->ncomp; k++) sum += p[0]->explained[k];
    ES_CHECK_CLOSE(sum, 1.0, 1e-10, 0);
    /* block sizes 1, 7 and all rows give the same result */
    for (int b = 1; b < 4; b++) {
        ES_CHECK(p[b]->ncomp == p[0]->ncomp);
        for (int64_t k = 0; k < p[0]->ncomp && k < p[b]->ncomp; k++) {
            ES_CHECK_CLOSE(p[b]->eigenvalues[k], p[0]->eigenvalues[k], 1e-12,
                           1e-13 * p[0]->eigenvalues[0]);
            for (int64_t e = 0; e < E; e++)
                ES_CHECK_CLOSE(p[b]->components[e + k * E], p[0]->components[e + k * E], 0,
                               1e-9);
        }
        for (int64_t e = 0; e < E; e++) ES_CHECK(p[b]->mean[e] == p[0]->mean[e]);
    }
    /* reproducible: the same call twice gives bit-identical output */
    es_pca *again = NULL;
    src.block = 0;
    ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &again));
    if (again) {
        ES_CHECK(!memcmp(again->components, p[0]->components,
                         (size_t)(E * p[0]->ncomp) * sizeof(double)));
        ES_CHECK(!memcmp(again->scores, p[0]->scores, (size_t)(N * p[0]->ncomp) * sizeof(double)));
        es_pca_free(again);
    }
    /* projection of the fitted rows reproduces their scores; with all
     * components the residual is zero */
    double *sc = malloc((size_t)(p[0]->ncomp * N) * sizeof *sc), *res = malloc((size_t)N * sizeof *res);
    ES_CHECK_OK(ctx, es_pca_project(ctx, p[0], (es_mat){X, E, N, E}, sc, res));
    double scale = sqrt(r.ev[0] * (double)(N - 1));
    for (int64_t i = 0; i < N; i++) {
        for (int64_t k = 0; k < p[0]->ncomp; k++)
            ES_CHECK_CLOSE(sc[k + i * p[0]->ncomp], p[0]->scores[i + k * N], 0, 1e-10 * scale);
        if (p[0]->ncomp == E || p[0]->ncomp == N - 1) ES_CHECK_CLOSE(res[i], 0, 0, 1e-10 * scale);
    }
    free(sc);
    free(res);
out:
    for (int b = 0; b < 4; b++) es_pca_free(p[b]);
    ref_free(&r);
    free(X);
}

/* Top K only: requested count, projection residual equals the norm of the
 * remaining components. */
static void test_topk(es_ctx *ctx)
{
    const int64_t E = 50, N = 20, K = 3;
    double *X = make_data(E, N, 8, 0.001, 7);
    ref r = reference(X, E, N);
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    es_pca_opts o;
    es_pca_opts_init(&o);
    o.ncomp = K;
    es_pca *p = NULL;
    ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p));
    if (p) {
        ES_CHECK(p->ncomp == K);
        check_against(p, &r, K, 1e-10, 1e-9);
        double tot = 0;
        for (int64_t k = 0; k < r.m; k++) tot += r.ev[k];
        ES_CHECK_CLOSE(p->total_variance, tot, 1e-10, 0);
        double s[3], res;
        ES_CHECK_OK(ctx, es_pca_project(ctx, p, (es_mat){X + 4 * E, E, 1, E}, s, &res));
        double rest = 0;
        for (int64_t k = K; k < r.m; k++) rest += r.S[4 + k * N] * r.S[4 + k * N];
        ES_CHECK_CLOSE(res, sqrt(rest), 1e-8, 0);
        es_pca_free(p);
    }
    /* errors */
    o.ncomp = N;
    ES_CHECK_FAILS(ctx, es_pca_fit(ctx, &src, &o, &p), ES_EINVAL, "at most 19");
    es_source one = es_source_matrix((es_mat){X, E, 1, E}, NULL, 0);
    ES_CHECK_FAILS(ctx, es_pca_fit(ctx, &one, NULL, &p), ES_EINVAL, "at least 2 rows");
    X[3 + 5 * E] = NAN;
    ES_CHECK_FAILS(ctx, es_pca_fit(ctx, &src, NULL, &p), ES_ENUMERIC, "row 5, edge 3");
    ref_free(&r);
    free(X);
}

/* Randomized top K against exact: a spectrum with a gap after K gives
 * near-exact results; a subset of rows through the source's row list. */
static void test_randomized(es_ctx *ctx)
{
    const int64_t E = 300, N = 80, K = 5;
    double *X = make_data(E, N, K, 1e-4, 99);
    ref r = reference(X, E, N);
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    src.block = 13;
    es_pca_opts o;
    es_pca_opts_init(&o);
    o.ncomp = K;
    o.method = ES_PCA_RANDOMIZED;
    es_pca *p = NULL, *q = NULL;
    ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p));
    ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &q));
    if (p && q) {
        ES_CHECK(p->method == ES_PCA_RANDOMIZED);
        check_against(p, &r, K, 1e-10, 1e-9);
        check_orthonormal(p, 1e-12 * (double)E);
        ES_CHECK(!memcmp(p->components, q->components, (size_t)(E * K) * sizeof(double)));
    }
    es_pca_free(p);
    es_pca_free(q);
    p = NULL;
    /* no gap: a decaying spectrum of rank 40 and a flat one. The error
     * falls with every power iteration, eigenvalues are never overestimated,
     * and the defaults meet the documented bounds (1e-8, 1e-3). */
    for (int flat = 0; flat < 2; flat++) {
        free(X);
        ref_free(&r);
        X = make_data(E, N, 40, 2e-3, 5);
        if (flat) {   /* equalize: rebuild with equal weights */
            es_rng g;
            es_rng_init(&g, 5);
            double *Bs = malloc((size_t)(E * 40) * sizeof *Bs);
            for (int64_t i = 0; i < E * 40; i++) Bs[i] = es_rng_normal(&g);
            for (int64_t j = 0; j < N; j++) {
                for (int64_t e = 0; e < E; e++) X[e + j * E] = 1 + 2e-3 * es_rng_normal(&g);
                for (int64_t k = 0; k < 40; k++) {
                    double c = 0.05 * es_rng_normal(&g);
                    for (int64_t e = 0; e < E; e++) X[e + j * E] += c * Bs[e + k * E];
                }
                for (int64_t e = 0; e < E; e++) X[e + j * E] /= (double)E;
            }
            free(Bs);
        }
        r = reference(X, E, N);
        src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
        double prev = INFINITY;
        for (int64_t it = 0; it <= 4; it++) {
            o.power_iters = it;
            ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p));
            if (!p) continue;
            double worst = 0;
            for (int64_t k = 0; k < K; k++) {
                double rel = fabs(p->eigenvalues[k] - r.ev[k]) / r.ev[k];
                if (rel > worst) worst = rel;
                ES_CHECK(p->eigenvalues[k] <= r.ev[k] * (1 + 1e-12));
            }
            ES_CHECK_MSG(worst < prev * 1.5 || worst < 1e-13, "q=%lld: %g after %g", (long long)it,
                         worst, prev);
            if (it == 4) ES_CHECK_MSG(worst < (flat ? 1e-3 : 1e-8), "q=4: %g", worst);
            prev = worst;
            es_pca_free(p);
            p = NULL;
        }
    }
    ref_free(&r);
    free(X);
}

/* Options from a command line: an oversampling of 2^63 - 1 is clamped
 * before it is added to K (it overflowed, undefined behaviour that UBSan
 * reports), and a power iteration count that would never end is refused. */
static void test_extreme_options(es_ctx *ctx)
{
    enum { E = 30, N = 12 };
    double X[E * N];
    es_rng g;
    es_pca_opts o;
    es_pca *p = NULL;
    es_rng_init(&g, 7);
    for (int i = 0; i < E * N; i++) X[i] = es_rng_normal(&g);
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    es_pca_opts_init(&o);
    o.method = ES_PCA_RANDOMIZED;
    o.ncomp = 3;
    o.oversample = INT64_MAX;
    ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p));
    ES_CHECK(p && p->ncomp == 3);
    es_pca_free(p);
    p = NULL;
    o.oversample = 10;
    o.power_iters = 1001;
    ES_CHECK_FAILS(ctx, es_pca_fit(ctx, &src, &o, &p), ES_EINVAL, "0 to 1000");
    ES_CHECK(p == NULL);
    o.power_iters = INT64_MAX;
    ES_CHECK_FAILS(ctx, es_pca_fit(ctx, &src, &o, &p), ES_EINVAL, "power iterations");
}

/* Rank-deficient data: every route, the randomized one included, returns
 * only the components above max(N, E) eps (largest), so rank-1 data asked
 * for 3 gives 1 and constant data gives none (the randomized route used to
 * return its null directions with eigenvalues ~1e-34 or 0). */
static void test_rank(es_ctx *ctx)
{
    const int64_t E = 12, N = 40;
    double X[12 * 40];
    static const es_pca_method methods[] = {ES_PCA_AUTO, ES_PCA_GRAM, ES_PCA_COVARIANCE,
                                            ES_PCA_RANDOMIZED};
    for (int constant = 0; constant < 2; constant++) {
        for (int64_t j = 0; j < N; j++)
            for (int64_t e = 0; e < E; e++)
                X[e + j * E] = 1.0 / (double)E +
                               (constant ? 0 : 1e-3 * (double)(j % 5) * sin((double)e));
        es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
        for (size_t m = 0; m < sizeof methods / sizeof methods[0]; m++) {
            es_pca_opts o;
            es_pca_opts_init(&o);
            o.method = methods[m];
            o.ncomp = 3;
            es_pca *p = NULL;
            ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p));
            if (!p) continue;
            ES_CHECK_MSG(p->ncomp == (constant ? 0 : 1), "method %d, constant %d: %lld "
                         "components", (int)methods[m], constant, (long long)p->ncomp);
            for (int64_t k = 0; k < p->ncomp; k++)
                ES_CHECK_MSG(p->eigenvalues[k] > 0, "method %d: eigenvalue %lld is %g",
                             (int)methods[m], (long long)k, p->eigenvalues[k]);
            if (!constant && p->ncomp > 0) ES_CHECK_CLOSE(p->explained[0], 1.0, 1e-12, 0);
            es_pca_free(p);
        }
    }
}

/* ../shared/data/face-study: 30 subjects x {neutral, happy, angry}. The
 * qualitative finding of Fig. 9: the happy group's mean PC-1 score differs
 * from the neutral group's by more than 3 standard errors. Also pairs
 * happy with neutral by subject (30 pairs, none unpaired). */
static void test_face_study(es_ctx *ctx)
{
    const char *data = es_test_shared_data();
    char path[4096], line[512];
    if (!data) {
        fprintf(stderr, "face-study: ../shared/data absent, section skipped\n");
        return;
    }
    int len = snprintf(path, sizeof path, "%s/face-study/manifest.csv", data);
    FILE *f = len > 0 && (size_t)len < sizeof path ? fopen(path, "r") : NULL;
    if (!f) {
        fprintf(stderr, "face-study: %s absent, section skipped\n", path);
        return;
    }
    enum { MAXN = 200 };
    char *subj[MAXN], *expr[MAXN], *file[MAXN];
    int64_t N = 0;
    if (!fgets(line, sizeof line, f)) N = -1;   /* header */
    while (N >= 0 && N < MAXN && fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        char *a = strtok(line, ","), *b = strtok(NULL, ","), *c = strtok(NULL, ",");
        if (!a || !b || !c) continue;
        file[N] = strdup(a), subj[N] = strdup(b), expr[N] = strdup(c);
        N++;
    }
    fclose(f);
    ES_CHECK(N == 90);
    if (N < 4) return;
    es_mesh *mesh = NULL;
    double *X = NULL, scale;
    int64_t E = 0;
    for (int64_t i = 0; i < N; i++) {
        es_meshdata md;
        len = snprintf(path, sizeof path, "%s/face-study/%s", data, file[i]);
        ES_CHECK(len > 0 && (size_t)len < sizeof path);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md));
        if (!md.xyz) goto out;
        if (!mesh) {
            ES_CHECK_OK(ctx, es_mesh_new(ctx, md.nverts, md.nfaces, md.faces, NULL, &mesh));
            if (!mesh) { es_meshdata_clear(ctx, &md); goto out; }
            E = es_mesh_nedges(mesh);
            X = malloc((size_t)(E * N) * sizeof *X);
        }
        ES_CHECK(md.nverts == es_mesh_nverts(mesh));
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, md.xyz, X + i * E));
        ES_CHECK_OK(ctx, es_lengths_normalize(ctx, E, X + i * E, X + i * E, &scale));
        es_meshdata_clear(ctx, &md);
    }
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    es_pca_opts o;
    es_pca_opts_init(&o);
    o.ncomp = 5;
    es_pca *p = NULL;
    ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p));
    if (p) {
        double sum[2] = {0, 0}, ss[2] = {0, 0};
        int64_t n[2] = {0, 0};
        for (int64_t i = 0; i < N; i++) {
            int g = !strcmp(expr[i], "happy") ? 1 : !strcmp(expr[i], "neutral") ? 0 : -1;
            if (g < 0) continue;
            sum[g] += p->scores[i];
            ss[g] += p->scores[i] * p->scores[i];
            n[g]++;
        }
        ES_CHECK(n[0] == 30 && n[1] == 30);
        double m0 = sum[0] / (double)n[0], m1 = sum[1] / (double)n[1];
        double v0 = (ss[0] - (double)n[0] * m0 * m0) / (double)(n[0] - 1);
        double v1 = (ss[1] - (double)n[1] * m1 * m1) / (double)(n[1] - 1);
        double se = sqrt(v0 / (double)n[0] + v1 / (double)n[1]);
        ES_CHECK_MSG(fabs(m1 - m0) > 3 * se, "PC-1: happy %g, neutral %g, se %g", m1, m0, se);
        fprintf(stderr, "face-study: E = %lld, PC-1..3 explain %.1f%%, %.1f%%, %.1f%%; PC-1 mean "
                "score happy - neutral = %.3g (%.1f standard errors)\n", (long long)E,
                100 * p->explained[0], 100 * p->explained[1], 100 * p->explained[2], m1 - m0,
                fabs(m1 - m0) / se);
        es_pca_free(p);
    }
    int role[MAXN];
    for (int64_t i = 0; i < N; i++)
        role[i] = !strcmp(expr[i], "neutral") ? ES_DIFF_FROM
                  : !strcmp(expr[i], "happy") ? ES_DIFF_TO : ES_DIFF_NONE;
    es_diff *d = NULL;
    ES_CHECK_OK(ctx, es_diff_paired(ctx, &src, (const char *const *)subj, role,
                                    (const char *const *)file, &d));
    if (d) {
        ES_CHECK(d->npairs == 30 && d->nunpaired == 0);
        double sum = 0, tmax = 0;
        for (int64_t e = 0; e < E; e++) {
            sum += d->mean[e];
            if (fabs(d->t[e]) > tmax) tmax = fabs(d->t[e]);
        }
        ES_CHECK_CLOSE(sum, 0, 0, 1e-12);   /* normalized lengths: differences sum to 0 */
        ES_CHECK(tmax > 10);                /* the smile acts strongly somewhere */
        es_diff_free(d);
    }
out:
    es_mesh_free(mesh);
    free(X);
    for (int64_t i = 0; i < N; i++) free(file[i]), free(subj[i]), free(expr[i]);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_exact(ctx, 40, 12, ES_PCA_AUTO);         /* Gram route */
    test_exact(ctx, 15, 60, ES_PCA_AUTO);         /* covariance route */
    test_exact(ctx, 40, 12, ES_PCA_COVARIANCE);   /* both routes agree with the SVD */
    test_exact(ctx, 15, 30, ES_PCA_GRAM);
    test_topk(ctx);
    test_randomized(ctx);
    test_rank(ctx);
    test_extreme_options(ctx);
    test_face_study(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
