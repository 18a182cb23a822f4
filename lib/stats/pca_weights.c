/* lib/stats/pca_weights.c — a point of edge-length space as a combination of
 * the rows a PCA was fitted on. The embedding applies the same weights to
 * the rows' dihedrals and positions (its prior), so every point needs them:
 * a mean, a component, a difference have them exactly; a new mesh gets them
 * by ridge regression, done here in the PCA's basis (X_c = U S V^T, so the
 * ridge solution V (S^2 + r I)^-1 S U^T (x - mean) is a sum over
 * components of the scores z_k = s_k v_k). */
#include "stats/stats_pkg.h"

#include <math.h>

es_status es_pca_row_weights(es_ctx *ctx, const es_pca *p, const double *x, double ridge_rel,
                             double *w)
{
    const int64_t N = p ? p->nrows : 0, E = p ? p->nedges : 0, K = p ? p->ncomp : 0;
    if (!p || N < 1 || !p->scores) ES_FAIL(ctx, ES_EINVAL, "row weights: no fitted PCA");
    if (!(ridge_rel >= 0) || !isfinite(ridge_rel))
        ES_FAIL(ctx, ES_EINVAL, "row weights: ridge %g is not a non-negative number", ridge_rel);
    for (int64_t i = 0; i < N; i++) w[i] = 1.0 / (double)N;
    if (!x || N < 2) return ES_OK;
    const double ridge = ridge_rel * (double)(N - 1) * p->total_variance / (double)N;
    for (int64_t k = 0; k < K; k++) {
        const double *u = p->components + k * E;
        double proj = 0, den = (double)(N - 1) * p->eigenvalues[k] + ridge;
        for (int64_t e = 0; e < E; e++) proj += u[e] * (x[e] - p->mean[e]);
        if (!(den > 0)) continue;   /* a component of no variance carries no weight */
        for (int64_t i = 0; i < N; i++) w[i] += p->scores[i + k * N] * proj / den;
    }
    return ES_OK;
}
