/* tests/sparse/test_spd.c — the sparse SPD systems lib/sparse offers the
 * modules above it (sparse_private.h): solutions of random sparse SPD
 * matrices (a grid Laplacian with a positive diagonal and random weights,
 * off-diagonal entries given in either triangle and some split into
 * repeated triplets) checked against LAPACK's dense Cholesky solve (dposv,
 * an independent computation) for several right-hand sides with a leading
 * dimension above n; a numeric refactorization with new values on the same
 * triplets against dposv again; many matrices in one set; an indefinite
 * matrix refused with ES_ENUMERIC naming it; an index out of range refused.
 */
#include "sparse/sparse_private.h"
#include "es_test.h"

#include <edgespace/edgespace.h>
#include <lapacke.h>

typedef struct trip { int64_t *i, *j; double *v; int64_t nz; } trip;

/* A g x g grid Laplacian with random positive edge weights plus d on the
 * diagonal; every third off-diagonal entry is given as two halves, every
 * other one in the lower triangle. Dense copy in A (n x n). */
static trip grid(int g, double d, unsigned seed, double *A)
{
    int64_t n = (int64_t)g * g, cap = 8 * n;
    trip t = {malloc(cap * sizeof(int64_t)), malloc(cap * sizeof(int64_t)),
              malloc(cap * sizeof(double)), 0};
    srand(seed);
    memset(A, 0, (size_t)(n * n) * sizeof *A);
    for (int64_t a = 0; a < n; a++) {
        t.i[t.nz] = a, t.j[t.nz] = a, t.v[t.nz++] = d;
        A[a + n * a] += d;
    }
    for (int y = 0; y < g; y++)
        for (int x = 0; x < g; x++)
            for (int dir = 0; dir < 2; dir++) {
                int x2 = x + (dir == 0), y2 = y + (dir == 1);
                int64_t a = (int64_t)y * g + x, b = (int64_t)y2 * g + x2;
                double w = 0.5 + (double)rand() / RAND_MAX;
                if (x2 >= g || y2 >= g) continue;
                A[a + n * a] += w, A[b + n * b] += w, A[a + n * b] -= w, A[b + n * a] -= w;
                t.i[t.nz] = a, t.j[t.nz] = a, t.v[t.nz++] = w;
                t.i[t.nz] = b, t.j[t.nz] = b, t.v[t.nz++] = w;
                if ((a + b) % 3 == 0) {
                    t.i[t.nz] = a, t.j[t.nz] = b, t.v[t.nz++] = -0.25 * w;
                    t.i[t.nz] = b, t.j[t.nz] = a, t.v[t.nz++] = -0.75 * w;
                } else if (a % 2) {
                    t.i[t.nz] = b, t.j[t.nz] = a, t.v[t.nz++] = -w;
                } else {
                    t.i[t.nz] = a, t.j[t.nz] = b, t.v[t.nz++] = -w;
                }
            }
    return t;
}

static double max_diff_dense(int64_t n, const double *A, int nrhs, const double *b, int64_t ldb,
                             const double *x)
{
    double *Ac = malloc((size_t)(n * n) * sizeof *Ac), *bc = malloc((size_t)(n * nrhs) * sizeof *bc);
    double worst = 0, scale = 0;
    memcpy(Ac, A, (size_t)(n * n) * sizeof *Ac);
    for (int c = 0; c < nrhs; c++) memcpy(bc + c * n, b + c * ldb, (size_t)n * sizeof *bc);
    if (LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', (int)n, nrhs, Ac, (int)n, bc, (int)n) != 0) {
        worst = INFINITY;
    } else {
        for (int c = 0; c < nrhs; c++)
            for (int64_t r = 0; r < n; r++) {
                worst = fmax(worst, fabs(bc[r + c * n] - x[r + c * ldb]));
                scale = fmax(scale, fabs(bc[r + c * n]));
            }
        worst /= scale;
    }
    free(Ac), free(bc);
    return worst;
}

static void test_solve(es_ctx *ctx)
{
    const int g = 12, nrhs = 3;
    const int64_t n = (int64_t)g * g, ldb = n + 5;
    double *A = malloc((size_t)(n * n) * sizeof *A), *b = malloc((size_t)(ldb * nrhs) * sizeof *b);
    double *x = malloc((size_t)(ldb * nrhs) * sizeof *x);
    trip t = grid(g, 0.1, 7, A);
    es__spd *s = NULL;
    int64_t id = -1, id2 = -1;
    ES_CHECK_OK(ctx, es__spd_new(ctx, &s));
    ES_CHECK_OK(ctx, es__spd_add(s, n, t.nz, t.i, t.j, t.v, "grid", &id));
    ES_CHECK(id == 0 && es__spd_count(s) == 1 && es__spd_size(s, 0) == n);
    for (int64_t k = 0; k < ldb * nrhs; k++) b[k] = sin(0.37 * (double)k) + 0.1;
    memcpy(x, b, (size_t)(ldb * nrhs) * sizeof *x);
    ES_CHECK_OK(ctx, es__spd_solve(s, id, nrhs, x, ldb));
    double d = max_diff_dense(n, A, nrhs, b, ldb, x);
    ES_CHECK_MSG(d < 1e-10, "solve differs from dposv by %g (relative)", d);
    /* the padding rows of each column are left alone */
    for (int c = 0; c < nrhs; c++)
        for (int64_t r = n; r < ldb; r++) ES_CHECK(x[r + c * ldb] == b[r + c * ldb]);

    /* new values on the same triplets: a heavier diagonal, doubled weights */
    for (int64_t k = 0; k < t.nz; k++) t.v[k] *= 2;
    for (int64_t a = 0; a < n; a++) t.v[a] = 3.0;   /* the first n triplets are the diagonal */
    for (int64_t k = 0; k < n * n; k++) A[k] *= 2;
    for (int64_t a = 0; a < n; a++) A[a + n * a] += 3.0 - 0.2;
    ES_CHECK_OK(ctx, es__spd_refactor(s, id, t.v));
    memcpy(x, b, (size_t)(ldb * nrhs) * sizeof *x);
    ES_CHECK_OK(ctx, es__spd_solve(s, id, nrhs, x, ldb));
    d = max_diff_dense(n, A, nrhs, b, ldb, x);
    ES_CHECK_MSG(d < 1e-10, "refactorized solve differs from dposv by %g", d);

    /* a second matrix in the same set, the first still answers */
    {
        double *A2 = malloc(36 * 36 * sizeof *A2), b2[36], x2[36];
        trip t2 = grid(6, 1.0, 11, A2);
        ES_CHECK_OK(ctx, es__spd_add(s, 36, t2.nz, t2.i, t2.j, t2.v, "small grid", &id2));
        ES_CHECK(id2 == 1 && es__spd_count(s) == 2 && es__spd_size(s, 1) == 36);
        for (int k = 0; k < 36; k++) b2[k] = x2[k] = cos((double)k);
        ES_CHECK_OK(ctx, es__spd_solve(s, id2, 1, x2, 36));
        ES_CHECK(max_diff_dense(36, A2, 1, b2, 36, x2) < 1e-10);
        free(A2), free(t2.i), free(t2.j), free(t2.v);
        memcpy(x, b, (size_t)(ldb * nrhs) * sizeof *x);
        ES_CHECK_OK(ctx, es__spd_solve(s, id, nrhs, x, ldb));
        ES_CHECK(max_diff_dense(n, A, nrhs, b, ldb, x) < 1e-10);
    }

    /* refused: indefinite, an index out of range, no such matrix */
    {
        int64_t ii[3] = {0, 1, 0}, jj[3] = {0, 1, 1};
        double vv[3] = {1, 1, 2};   /* [[1, 2], [2, 1]]: eigenvalues 3, -1 */
        int64_t bad[3] = {0, 1, 2}, id3 = -1;
        ES_CHECK_FAILS(ctx, es__spd_add(s, 2, 3, ii, jj, vv, "indefinite test", &id3),
                       ES_ENUMERIC, "indefinite test");
        ES_CHECK_FAILS(ctx, es__spd_add(s, 2, 3, bad, jj, vv, "range test", &id3), ES_EINVAL,
                       "outside 2 x 2");
        ES_CHECK(es__spd_count(s) == 2);
        ES_CHECK_FAILS(ctx, es__spd_solve(s, 5, 1, x, ldb), ES_EINVAL, "no matrix 5");
    }
    es__spd_free(s);
    free(A), free(b), free(x), free(t.i), free(t.j), free(t.v);
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_solve(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
