/* lib/stats/pca_randomized.c — top-K PCA by randomized range finding.
 *
 * Halko, Martinsson & Tropp, "Finding structure with randomness", SIAM
 * Review 53(2), 2011: Algorithm 4.4 (randomized subspace iteration) then
 * Algorithm 5.1 (direct SVD of the small projected matrix). With
 * A = X - mean 1^T (E x N), l = K + p Gaussian test vectors Omega (N x l,
 * from the context's seed):
 *     Y = A Omega;  q times: Q = orth(Y), Y = A (A^T Q);  Q = orth(Y);
 *     B^T = A^T Q (N x l) = W S V^T;  components = Q V, scores = W S.
 * Every product with A is one streamed pass; A A^T Q is fused so that each
 * power iteration reads the data once, and the first pass finds the mean
 * on the way (centring is a rank-one correction). Passes in all: q + 2.
 * Memory O(E l + N l + block x E).
 *
 * Accuracy. Halko et al. (Section 10.4) bound the error by the optimal
 * sigma_{K+1} times a factor that decays like (sigma_{K+p+1}/sigma_K)^(2q+1)
 * times a modest constant; eigenvalues are never overestimated. Measured
 * (max relative error of the top 5 eigenvalues, 300 edges x 80 shapes,
 * p = 10; tests/stats/test_pca.c checks the same cases):
 *     spectrum                        q=0      q=1      q=2      q=4
 *     rank 5 + noise (clear gap)      2e-3     1e-9     1e-15    2e-15
 *     rank 40, sigma_k ~ 1/k          0.2      8e-4     5e-6     2e-10
 *     rank 40, flat (l6/l5 = 0.89)    0.3      6e-2     1e-2     4e-4
 * So the default q = 4 is exact to rounding when the data have a gap after
 * K + p, ~1e-10 on a decaying spectrum, and a few 1e-4 on a nearly flat
 * one, where asking for more oversampling or iterations helps.
 */
#include "stats/stats_pkg.h"
#include "parallel/parallel_private.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <string.h>

/* Orthonormalize the columns of Y (E x l) in place by Householder QR. */
static es_status orth(es_ctx *ctx, int64_t E, int64_t l, double *Y, double *tau)
{
    lapack_int info = LAPACKE_dgeqrf(LAPACK_COL_MAJOR, (int)E, (int)l, Y, (int)E, tau);
    if (info == 0) info = LAPACKE_dorgqr(LAPACK_COL_MAJOR, (int)E, (int)l, (int)l, Y, (int)E, tau);
    if (info != 0)
        ES_FAIL(ctx, ES_ENUMERIC, "pca: QR of the %lld x %lld sample failed (info %d)",
                (long long)E, (long long)l, (int)info);
    return ES_OK;
}

/* Q orthonormalized on rank 0 and sent to every rank (one decomposition,
 * the same bits everywhere). */
static es_status orth_shared(es_ctx *ctx, int64_t E, int64_t l, double *Q, double *tau)
{
    es_status rc = es__par_rank(ctx) == 0 ? orth(ctx, E, l, Q, tau) : ES_OK;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) return rc;
    return es__par_bcast(ctx, Q, (size_t)(E * l) * sizeof *Q, 0);
}

/* In an MPI job each rank reads its share of the rows in every pass (rounds
 * in step, for a collective reader): the products A Z are sums over rows,
 * summed over the ranks (E x l per pass), the rows of A^T Q are each rank's
 * own and are gathered before the SVD, which rank 0 does. */
es_status es__pca_fit_randomized(es_ctx *ctx, const es_source *src, const es_pca_opts *opts,
                                 es_pca *p)
{
    const int64_t E = src->nedges, N = src->nrows, B = es__source_block(src), K = opts->ncomp;
    /* K <= min(N, E) (checked by es_pca_fit): clamping the oversampling
     * first keeps K + p from overflowing for any p */
    int64_t l = K + (opts->oversample < N ? opts->oversample : N), lo, hi, rounds;
    if (l > N) l = N;
    if (l > E) l = E;
    int ne, nn;
    es_status rc;
    if ((rc = es__lapack_int(ctx, E, &ne)) != ES_OK || (rc = es__lapack_int(ctx, N, &nn)) != ES_OK)
        return rc;
    es__source_share(ctx, src, B, &lo, &hi, &rounds);
    const bool alone = es__par_alone(ctx);
    const int64_t np = hi - lo;
    double *buf = es__alloc_array(ctx, E * B, sizeof *buf);
    double *Q = es__alloc_array(ctx, E * l, sizeof *Q);
    double *Y = es__alloc_array(ctx, E * l, sizeof *Y);
    double *Z = es__alloc_array(ctx, N * l, sizeof *Z);   /* Omega, then A^T Q */
    double *tau = es__alloc_array(ctx, l, sizeof *tau);
    double *s = es__alloc_array(ctx, l, sizeof *s);
    double *W = es__alloc_array(ctx, N * l, sizeof *W);
    double *VT = es__alloc_array(ctx, l * l, sizeof *VT);
    double *super = es__alloc_array(ctx, l, sizeof *super);
    double *ysum = es__alloc_array(ctx, E + 1, sizeof *ysum);
    double *mine = alone ? NULL : es__alloc_array(ctx, np * l > 0 ? np * l : 1, sizeof *mine);
    rc = buf && Q && Y && Z && tau && s && W && VT && super && ysum && (alone || mine) ? ES_OK
                                                                                   : ES_ENOMEM;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) goto done;
    es_rng rng;
    es_rng_init(&rng, es_ctx_seed(ctx));
    for (int64_t i = 0; i < N * l; i++) Z[i] = es_rng_normal(&rng);

    /* First pass: Y = (X - x_0 1^T) Omega with the data shifted by its first
     * row, their sum and sum of squares; then centring by the mean costs
     * only a rank-one correction, so the mean needs no pass of its own. */
    double *x0 = p->mean;
    double ss = 0;
    if ((rc = es__par_agree(ctx, es__source_read(ctx, src, 0, 1, x0))) != ES_OK) goto done;
    memset(Y, 0, (size_t)(E * l) * sizeof *Y);
    memset(ysum, 0, (size_t)(E + 1) * sizeof *ysum);
    for (int64_t k = 0; k < rounds; k++) {
        int64_t r0, n;
        es__source_round(lo, hi, B, k, &r0, &n);
        if ((rc = es__par_agree(ctx, es__source_read(ctx, src, r0, n, buf))) != ES_OK) goto done;
        for (int64_t j = 0; j < n; j++)
            for (int64_t e = 0; e < E; e++) {
                double v = buf[e + j * E] -= x0[e];
                ysum[e] += v;
                ss += v * v;
            }
        if (n > 0)
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, ne, (int)l, (int)n, 1.0, buf,
                        ne, Z + r0, nn, 1.0, Y, ne);
    }
    ysum[E] = ss;
    if ((rc = es__par_sum(ctx, ysum, E + 1)) != ES_OK || (rc = es__par_sum(ctx, Y, E * l)) != ES_OK)
        goto done;
    ss = ysum[E];
    double ybar2 = 0;
    for (int64_t e = 0; e < E; e++) {
        ysum[e] /= (double)N;          /* mean - x_0 */
        ybar2 += ysum[e] * ysum[e];
        p->mean[e] = x0[e] + ysum[e];
    }
    p->total_variance = (ss - (double)N * ybar2) / (double)(N - 1);
    for (int64_t c = 0; c < l; c++) {
        double s1 = 0;
        for (int64_t i = 0; i < N; i++) s1 += Z[i + c * N];
        cblas_daxpy(ne, -s1, ysum, 1, Y + c * E, 1);
    }
    es__progress(ctx, "pca: randomized", 1, opts->power_iters + 2);

    /* q fused sweeps Y = A (A^T Q), then a last one that only forms Z = A^T Q */
    for (int64_t it = 0; it <= opts->power_iters; it++) {
        int last = it == opts->power_iters;
        double *t = Q;
        Q = Y;
        Y = t;
        if ((rc = orth_shared(ctx, E, l, Q, tau)) != ES_OK) goto done;
        if (!last) memset(Y, 0, (size_t)(E * l) * sizeof *Y);
        for (int64_t k = 0; k < rounds; k++) {
            int64_t r0, n;
            es__source_round(lo, hi, B, k, &r0, &n);
            if ((rc = es__par_agree(ctx, es__source_read(ctx, src, r0, n, buf))) != ES_OK)
                goto done;
            if (n == 0) continue;
            for (int64_t j = 0; j < n; j++)
                for (int64_t e = 0; e < E; e++) buf[e + j * E] -= p->mean[e];
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)n, (int)l, ne, 1.0, buf,
                        ne, Q, ne, 0.0, Z + r0, nn);
            if (!last)
                cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, ne, (int)l, (int)n, 1.0,
                            buf, ne, Z + r0, nn, 1.0, Y, ne);
        }
        if (!last && (rc = es__par_sum(ctx, Y, E * l)) != ES_OK) goto done;
        /* the ranks of a job stop together (a lone cancel would leave the
         * others waiting in the next sum) */
        if ((rc = es__par_agree(ctx, es__progress(ctx, "pca: randomized", it + 2,
                                                  opts->power_iters + 2))) != ES_OK)
            goto done;
    }
    if (!alone) {
        /* every rank's rows of Z = A^T Q, to every rank */
        for (int64_t c = 0; c < l; c++)
            memcpy(mine + c * np, Z + lo + c * N, (size_t)np * sizeof *mine);
        if ((rc = es__gather_split(ctx, mine, N, l, Z)) != ES_OK) goto done;
    }

    /* Z = A^T Q = W S V^T: components Q V, scores W S (on rank 0, sent) */
    rc = ES_OK;
    if (es__par_rank(ctx) == 0) {
        lapack_int info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'S', 'S', nn, (int)l, Z, nn, s, W, nn,
                                         VT, (int)l, super);
        if (info != 0)
            rc = es__fail(ctx, ES_ENUMERIC, "pca: LAPACKE_dgesvd of the %lld x %lld projection "
                          "failed (info %d)", (long long)N, (long long)l, (int)info);
    }
    if (rc == ES_OK && es__par_rank(ctx) == 0) {
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, ne, (int)K, (int)l, 1.0, Q, ne, VT,
                    (int)l, 0.0, p->components, ne);
        for (int64_t k = 0; k < K; k++) {
            p->eigenvalues[k] = s[k] * s[k] / (double)(N - 1);
            for (int64_t i = 0; i < N; i++) p->scores[i + k * N] = W[i + k * N] * s[k];
        }
    }
    if ((rc = es__par_agree(ctx, rc)) != ES_OK ||
        (rc = es__par_bcast(ctx, p->components, (size_t)(E * K) * sizeof(double), 0)) != ES_OK ||
        (rc = es__par_bcast(ctx, p->eigenvalues, (size_t)K * sizeof(double), 0)) != ES_OK ||
        (rc = es__par_bcast(ctx, p->scores, (size_t)(N * K) * sizeof(double), 0)) != ES_OK)
        goto done;
    p->method = ES_PCA_RANDOMIZED;
done:
    es__free(ctx, buf);
    es__free(ctx, Q);
    es__free(ctx, Y);
    es__free(ctx, Z);
    es__free(ctx, tau);
    es__free(ctx, s);
    es__free(ctx, W);
    es__free(ctx, VT);
    es__free(ctx, super);
    es__free(ctx, ysum);
    es__free(ctx, mine);
    return rc;
}
