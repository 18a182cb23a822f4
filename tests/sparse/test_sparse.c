/* tests/sparse/test_sparse.c — lib/sparse's solver service (sparse_private.h)
 * on a matrix whose pattern the test writes itself, as the embedder does: a
 * g x g grid Laplacian with random positive weights and a positive
 * diagonal, in compressed-column form (upper and lower triangle). Checked
 * against LAPACK's dense Cholesky solve (dposv, an independent computation)
 * for every ordering (CHOLMOD's choice, natural, AMD, METIS, a given
 * permutation), simplicial and supernodal, with the values allocated at the
 * analysis or not, one and three right-hand sides; the symmetric product
 * against the dense one; the permutation of a given order comes back as
 * given; copies of a matrix and a factor solve alike; a zero pivot is
 * reported as a matrix that is not positive definite.
 */
#include "sparse/sparse_private.h"
#include "es_test.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>

#define G 9
#define N (G * G)

static double A[N * N];   /* the dense matrix, column-major */

static void make_dense(unsigned seed, double diag)
{
    srand(seed);
    memset(A, 0, sizeof A);
    for (int a = 0; a < N; a++) A[a + N * a] = diag;
    for (int y = 0; y < G; y++)
        for (int x = 0; x < G; x++)
            for (int dir = 0; dir < 2; dir++) {
                int x2 = x + (dir == 0), y2 = y + (dir == 1), a = y * G + x, b = y2 * G + x2;
                double w = 0.5 + (double)rand() / RAND_MAX;
                if (x2 >= G || y2 >= G) continue;
                A[a + N * a] += w, A[b + N * b] += w, A[a + N * b] -= w, A[b + N * a] -= w;
            }
}

/* The upper (or lower) triangle of A, its pattern from the nonzeros. */
static es__sparse_mat *sparse_from_dense(es__sparse *ws, int upper)
{
    int64_t nz = 0, *cp, *ri, p = 0;
    double *x;
    es__sparse_mat *S;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            if ((upper ? i <= j : i >= j) && A[i + N * j] != 0) nz++;
    S = es__sparse_mat_new(ws, N, nz, upper);
    if (!S) return NULL;
    cp = es__sparse_mat_colptr(S), ri = es__sparse_mat_rowind(S), x = es__sparse_mat_values(S);
    cp[0] = 0;
    for (int j = 0; j < N; j++) {
        for (int i = 0; i < N; i++)
            if ((upper ? i <= j : i >= j) && A[i + N * j] != 0) {
                ri[p] = i;
                x[p++] = A[i + N * j];
            }
        cp[j + 1] = p;
    }
    return S;
}

/* Largest relative difference of x (N x nrhs) from dposv's solution. */
static double diff_dposv(int nrhs, const double *b, const double *x)
{
    double *Ac = malloc(sizeof A), bc[3 * N], worst = 0, scale = 0;
    memcpy(Ac, A, sizeof A);
    memcpy(bc, b, (size_t)(nrhs * N) * sizeof *bc);
    if (LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', N, nrhs, Ac, N, bc, N) != 0) {
        free(Ac);
        return INFINITY;
    }
    for (int k = 0; k < nrhs * N; k++) {
        worst = fmax(worst, fabs(bc[k] - x[k]));
        scale = fmax(scale, fabs(bc[k]));
    }
    free(Ac);
    return worst / scale;
}

static void solve_and_check(es__sparse *ws, es__sparse_mat *S, es__sparse_factor *L,
                            es__sparse_dense *B, es__sparse_solution *sol, const char *what)
{
    double *b = es__sparse_dense_values(B), rhs[3 * N];
    for (int k = 0; k < 3 * N; k++) rhs[k] = b[k] = sin(0.7 * k) + 0.2;
    es__sparse_clear_status(ws);
    ES_CHECK(es__sparse_factorize(ws, S, L) == 1);
    ES_CHECK_MSG(es__sparse_status(ws, NULL) == ES__SPARSE_OK, "%s: factorize status", what);
    /* all three columns, then only the first */
    ES_CHECK(es__sparse_solve(ws, L, B, 3, sol) == 1);
    double d3 = diff_dposv(3, rhs, es__sparse_solution_values(sol));
    ES_CHECK_MSG(d3 < 1e-12, "%s: 3 right-hand sides differ from dposv by %g", what, d3);
    ES_CHECK(es__sparse_solve(ws, L, B, 1, sol) == 1);
    double d1 = diff_dposv(1, rhs, es__sparse_solution_values(sol));
    ES_CHECK_MSG(d1 < 1e-12, "%s: 1 right-hand side differs from dposv by %g", what, d1);
}

static void test_orderings(es_ctx *ctx)
{
    es__sparse *ws = NULL;
    const es__sparse_opts relaxed = {1, {12, 48, 128}, {0.8, 0.15, 0.08}, 1};
    es__sparse_solution sol = {0};
    int64_t given[N];
    make_dense(3, 0.05);
    for (int k = 0; k < N; k++) given[k] = N - 1 - k;   /* reversed */
    for (int with_opts = 0; with_opts < 2; with_opts++) {
        ES_CHECK_OK(ctx, es__sparse_new(ctx, with_opts ? &relaxed : NULL, &ws));
        es__sparse_dense *B = es__sparse_dense_new(ws, N, 3);
        ES_CHECK(B != NULL);
        for (int upper = 0; upper < 2; upper++)
            for (int ord = ES__SPARSE_ORDER_DEFAULT; ord <= ES__SPARSE_ORDER_GIVEN; ord++)
                for (int simp = 0; simp < 2; simp++) {
                    es__sparse_analysis an = {ord, ord == ES__SPARSE_ORDER_GIVEN ? given : NULL,
                                              1, simp, !simp};
                    es__sparse_mat *S = sparse_from_dense(ws, upper);
                    char what[96];
                    snprintf(what, sizeof what, "opts %d upper %d ordering %d simplicial %d",
                             with_opts, upper, ord, simp);
                    ES_CHECK(S != NULL);
                    es__sparse_factor *L = es__sparse_analyze(ws, S, &an);
                    ES_CHECK_MSG(L != NULL, "%s: analysis failed", what);
                    if (!L) {
                        es__sparse_mat_free(ws, &S);
                        continue;
                    }
                    {   /* the permutation is one; a given one comes back as it was */
                        const int64_t *p = es__sparse_factor_perm(L);
                        int seen[N] = {0}, ok = 1;
                        for (int k = 0; k < N; k++) {
                            if (p[k] < 0 || p[k] >= N || seen[p[k]]++) ok = 0;
                            if (ord == ES__SPARSE_ORDER_GIVEN && p[k] != given[k]) ok = 0;
                            if (ord == ES__SPARSE_ORDER_NATURAL && p[k] != k) ok = 0;
                        }
                        ES_CHECK_MSG(ok, "%s: permutation", what);
                    }
                    solve_and_check(ws, S, L, B, &sol, what);
                    es__sparse_factor_free(ws, &L);
                    es__sparse_mat_free(ws, &S);
                    ES_CHECK(L == NULL && S == NULL);
                }
        es__sparse_dense_free(ws, &B);
        es__sparse_solution_free(ws, &sol);
        es__sparse_free(ws);
    }
}

static void test_matvec_copies_and_indefinite(es_ctx *ctx)
{
    es__sparse *ws = NULL;
    es__sparse_solution sol = {0};
    const es__sparse_analysis an = {ES__SPARSE_ORDER_AMD, NULL, 1, 1, 0};
    double x[N], y[N], want[N];
    make_dense(5, 0.3);
    ES_CHECK_OK(ctx, es__sparse_new(ctx, NULL, &ws));
    es__sparse_mat *S = sparse_from_dense(ws, 1), *Sl = sparse_from_dense(ws, 0);
    ES_CHECK(S && Sl && es__sparse_mat_n(S) == N);
    /* the symmetric product from either triangle against the dense one */
    for (int i = 0; i < N; i++) x[i] = cos(1.3 * i);
    for (int i = 0; i < N; i++) {
        want[i] = 0;
        for (int j = 0; j < N; j++) want[i] += A[i + N * j] * x[j];
    }
    es__sparse_sym_matvec(S, x, y);
    for (int i = 0; i < N; i++) ES_CHECK_CLOSE(y[i], want[i], 1e-14, 1e-14);
    es__sparse_sym_matvec(Sl, x, y);
    for (int i = 0; i < N; i++) ES_CHECK_CLOSE(y[i], want[i], 1e-14, 1e-14);

    /* a copy of the matrix and of its symbolic factor solve as the originals */
    es__sparse_factor *L = es__sparse_analyze(ws, S, &an);
    es__sparse_mat *C = es__sparse_mat_copy(ws, S);
    es__sparse_factor *LC = L ? es__sparse_factor_copy(ws, L) : NULL;
    es__sparse_dense *B = es__sparse_dense_new(ws, N, 3);
    ES_CHECK(L && C && LC && B);
    ES_CHECK(es__sparse_mat_nzmax(C) == es__sparse_mat_nzmax(S));
    if (L && C && LC && B) {
        solve_and_check(ws, S, L, B, &sol, "original");
        solve_and_check(ws, C, LC, B, &sol, "copies");
        /* a zero first pivot (natural order): not positive definite, a
         * soft outcome. (A simplicial factor is CHOLMOD's LDL', which takes
         * an indefinite matrix with nonzero pivots without complaint; the
         * embedder's damping loops rely on this status only where it is
         * set.) */
        const es__sparse_analysis nat = {ES__SPARSE_ORDER_NATURAL, NULL, 0, 1, 0};
        es__sparse_factor *LN = es__sparse_analyze(ws, C, &nat);
        double *v = es__sparse_mat_values(C);
        ES_CHECK(LN != NULL);
        v[0] = 0;   /* (0, 0): column 0 holds only the diagonal in the upper triangle */
        es__sparse_clear_status(ws);
        ES_CHECK(LN && es__sparse_factorize(ws, C, LN) == 1);
        ES_CHECK(es__sparse_status(ws, NULL) == ES__SPARSE_NOT_POSDEF);
        es__sparse_factor_free(ws, &LN);
    }
    es__sparse_dense_free(ws, &B);
    es__sparse_factor_free(ws, &LC);
    es__sparse_factor_free(ws, &L);
    es__sparse_mat_free(ws, &C);
    es__sparse_mat_free(ws, &S);
    es__sparse_mat_free(ws, &Sl);
    es__sparse_solution_free(ws, &sol);
    es__sparse_free(ws);
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_orderings(ctx);
    test_matvec_copies_and_indefinite(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
