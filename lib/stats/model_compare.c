/* lib/stats/model_compare.c — two fitted models of the same rows compared,
 * as RRPP's anova(fit.null, fit.full) does: the residuals of the null model
 * are permuted and added back to its fitted values, both models are fitted
 * to each permuted response, and the F of the drop in residual SS is
 * compared with the observed one. The statistic is the one of an F test of
 * nested linear models (the extra sum of squares), here on the principal
 * coordinates of the response like every other test of es_model.h.
 */
#include "stats/stats_pkg.h"

#include <cblas.h>
#include <math.h>
#include <string.h>

void es_model_comparison_free(es_model_comparison *c)
{
    if (!c) return;
    es__free(c->ctx, c->fperm);
    es__free(c->ctx, c);
}

/* ||Y||^2 - ||Q^T Y||^2 for Y (N x r) and Q (N x k); work: k x r. */
static double resid_ss(int64_t n, int64_t r, const double *y, const double *q, int64_t k,
                       double *work)
{
    double t = cblas_ddot((int)(n * r), y, 1, y, 1);
    if (k < 1) return t;
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)k, (int)r, (int)n, 1.0, q, (int)n,
                y, (int)n, 0.0, work, (int)k);
    return t - cblas_ddot((int)(k * r), work, 1, work, 1);
}

/* Check that null and full model the same response and null's columns lie
 * in full's span. */
static es_status check_pair(es_ctx *ctx, const es_model *null, const es_model *full)
{
    if (null->n != full->n || null->p != full->p || null->priv->r != full->priv->r ||
        !(fabs(null->tss - full->tss) <= 1e-10 * full->tss))
        ES_FAIL(ctx, ES_EINVAL, "compare: the two models are not fitted to the same rows and "
                "response (%lld vs %lld rows, total SS %.17g vs %.17g)", (long long)null->n,
                (long long)full->n, null->tss, full->tss);
    const int64_t n = full->n, k0 = null->rank, k1 = full->rank;
    if (k1 <= k0)
        ES_FAIL(ctx, ES_EINVAL, "compare: the model has rank %lld, the null model %lld: nothing "
                "to test (the null model must be nested in the model)", (long long)k1,
                (long long)k0);
    double *c = es__alloc_array(ctx, k1 * k0, sizeof *c), *res = es__alloc_array(ctx, n, sizeof *res);
    es_status rc = c && res ? ES_OK : ES_ENOMEM;
    double worst = 0;
    if (rc == ES_OK) {
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)k1, (int)k0, (int)n, 1.0,
                    full->priv->qf, (int)n, null->priv->qf, (int)n, 0.0, c, (int)k1);
        for (int64_t j = 0; j < k0; j++) {
            memcpy(res, null->priv->qf + j * n, (size_t)n * sizeof *res);
            cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)k1, -1.0, full->priv->qf,
                        (int)n, c + j * k1, 1, 1.0, res, 1);
            worst = fmax(worst, cblas_dnrm2((int)n, res, 1));
        }
        if (worst > 1e-8)
            rc = es__fail(ctx, ES_EINVAL, "compare: the null model is not nested in the model "
                          "(its columns leave the model's span by %.3g)", worst);
    }
    es__free(ctx, c);
    es__free(ctx, res);
    return rc;
}

es_status es_model_compare(es_ctx *ctx, const es_model *null, const es_model *full,
                           es_model_comparison **out)
{
    *out = NULL;
    if (!null || !full) ES_FAIL(ctx, ES_EINVAL, "compare: two models are needed");
    es_status rc = check_pair(ctx, null, full);
    if (rc != ES_OK) return rc;
    const int64_t n = full->n, r = full->priv->r, k0 = null->rank, k1 = full->rank;
    const int64_t B = full->permutations;
    const double *z = full->priv->pca->scores;
    es_model_comparison *c = es__calloc(ctx, 1, sizeof *c);
    double *e0 = es__alloc_array(ctx, n * r, sizeof *e0), *f0 = es__alloc_array(ctx, n * r, sizeof *f0);
    double *y = es__alloc_array(ctx, n * r, sizeof *y), *work = es__alloc_array(ctx, k1 * r, sizeof *work);
    double *s = es__alloc_array(ctx, B + 1, sizeof *s);
    int64_t *perm = es__alloc_array(ctx, n, sizeof *perm);
    es__perm g;
    memset(&g, 0, sizeof g);
    if (c) c->ctx = ctx;
    if (!c || !e0 || !f0 || !y || !work || !s || !perm) {
        rc = ES_ENOMEM;
        goto done;
    }
    c->n = n;
    c->rank_null = k0;
    c->rank_full = k1;
    c->df = k1 - k0;
    c->df_resid_null = n - k0;
    c->df_resid_full = n - k1;
    c->permutations = B;
    c->rss_null = null->rss;
    c->rss_full = full->rss;
    c->tss = full->tss;
    c->ss = c->rss_null - c->rss_full;
    c->ms = c->ss / (double)c->df;
    c->r2 = c->ss / c->tss;
    c->f = c->ms / (c->rss_full / (double)c->df_resid_full);
    c->pval = c->z = NAN;
    if (!(c->fperm = es__alloc_array(ctx, B > 0 ? B : 1, sizeof *c->fperm))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if (B > 0) {
        /* E0 = Z - Q0 Q0^T Z, F0 = Z - E0 */
        if ((rc = es__model_residuals(ctx, full, null->priv->qf, k0, e0)) != ES_OK ||
            (rc = es__perm_init(ctx, &g, n, full->priv->blocks, full->seed)) != ES_OK)
            goto done;
        for (int64_t k = 0; k < n * r; k++) f0[k] = z[k] - e0[k];
        s[0] = c->f;
        for (int64_t b = 0; b < B; b++) {
            es__perm_next(&g, perm);
            for (int64_t col = 0; col < r; col++)
                for (int64_t i = 0; i < n; i++)
                    y[i + col * n] = f0[i + col * n] + e0[perm[i] + col * n];
            const double rss0 = resid_ss(n, r, y, null->priv->qf, k0, work);
            const double rss1 = resid_ss(n, r, y, full->priv->qf, k1, work);
            c->fperm[b] = ((rss0 - rss1) / (double)c->df) / (rss1 / (double)c->df_resid_full);
            s[b + 1] = c->fperm[b];
            if (b % 64 == 63 || b == B - 1) es__progress(ctx, "compare: permutations", b + 1, B);
        }
        if ((rc = es__perm_summary(ctx, s, B + 1, 0.95, &c->pval, &c->z, NULL)) != ES_OK)
            goto done;
    }
    *out = c;
    c = NULL;
done:
    es__perm_clear(ctx, &g);
    es_model_comparison_free(c);
    es__free(ctx, e0);
    es__free(ctx, f0);
    es__free(ctx, y);
    es__free(ctx, work);
    es__free(ctx, s);
    es__free(ctx, perm);
    return rc;
}
