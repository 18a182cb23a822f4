/* lib/stats/model_posthoc.c — what follows a fitted model (pairwise
 * comparisons are model_pairwise.c): per-variable (per-edge) and
 * per-landmark tests with the FDR, and the common allometric component.
 *
 * Both reuse the fit's principal coordinates Z and components U
 * (Y_c = Z U^T) and its permutations:
 *  - the F of every variable e needs the columns of [D Qf]^T P E in the
 *    response's space: (W^T E) U^T, one more product per batch; a group of
 *    variables (a landmark's coordinates) sums their SS and RSS;
 *  - the CAC is the pooled within-group regression vector of log size
 *    (Mitteroecker, Gunz, Bernhard, Schaefer & Bookstein 2004).
 */
#include "stats/stats_pkg.h"

#include <cblas.h>
#include <math.h>
#include <string.h>

#define TIE_EPS 1.4901161193847656e-08

/* ---- per-variable tests ------------------------------------------------------- */

/* Column sums of squares of rows [r0, r1) of a (nr x p, ld lda): out[e]. */
static void colsq(const double *a, int64_t lda, int64_t r0, int64_t r1, int64_t p, double *out)
{
    for (int64_t e = 0; e < p; e++) {
        double s = 0;
        for (int64_t i = r0; i < r1; i++) s += a[i + e * lda] * a[i + e * lda];
        out[e] = s;
    }
}

/* out[e] = ||A u_e||^2 for the rows u_e of U (p x r): column sums of
 * squares of A U^T (rows x p), formed in blocks of columns in work. */
static void colsq_product(int64_t rows, int64_t r, const double *a, int64_t lda, const double *u,
                          int64_t p, double *work, int64_t nwork, double *out)
{
    int64_t pb = nwork / rows;
    if (pb > p) pb = p;
    for (int64_t e0 = 0; e0 < p; e0 += pb) {
        int64_t nb = p - e0 < pb ? p - e0 : pb;
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, (int)rows, (int)nb, (int)r, 1.0, a,
                    (int)lda, u + e0, (int)p, 0.0, work, (int)rows);
        colsq(work, rows, 0, rows, nb, out + e0);
    }
}

/* out[g] = sum of in[e] over the variables e of group g. */
static void group_sum(int64_t p, const int64_t *group, const double *in, int64_t ng, double *out)
{
    if (!group) {
        memcpy(out, in, (size_t)p * sizeof *out);
        return;
    }
    for (int64_t g = 0; g < ng; g++) out[g] = 0;
    for (int64_t e = 0; e < p; e++) out[group[e]] += in[e];
}

es_status es_model_group_tests(es_ctx *ctx, const es_model *m, const char *term,
                               int64_t permutations, int64_t ng, const int64_t *group, double *f,
                               double *pval, double *qval)
{
    if (!m || !f || !pval || !qval) ES_FAIL(ctx, ES_EINVAL, "variable tests: bad arguments");
    const int64_t j = es_model_find_term(m, term);
    const char *why = es_design_dropped(m->design, term);
    if (j < 0 && why)
        ES_FAIL(ctx, ES_EINVAL, "variable tests: the term '%s' %s and was left out of the "
                "model", term, why);
    if (j < 0) ES_FAIL(ctx, ES_ENOTFOUND, "variable tests: the model has no term '%s'",
                       term ? term : "");
    if (permutations > ES_MAX_PERMUTATIONS)
        ES_FAIL(ctx, ES_EINVAL, "variable tests: %lld permutations (0 to %d)",
                (long long)permutations, ES_MAX_PERMUTATIONS);
    const int64_t B = permutations < 0 ? m->permutations : permutations;
    const int64_t n = m->n, p = m->p, r = m->priv->r, rk = m->rank;
    if (group) {
        if (ng < 1) ES_FAIL(ctx, ES_EINVAL, "variable tests: %lld groups", (long long)ng);
        for (int64_t e = 0; e < p; e++)
            if (group[e] < 0 || group[e] >= ng)
                ES_FAIL(ctx, ES_EINVAL, "variable tests: variable %lld is in group %lld, not in "
                        "[0, %lld)", (long long)e, (long long)group[e], (long long)ng);
    } else {
        ng = p;
    }
    const double *z = m->priv->pca->scores, *u = m->priv->pca->components;
    double *ub = NULL, *e = NULL, *w = NULL, *a = NULL, *big = NULL, *ss = NULL, *fs = NULL;
    double *ee = NULL, *rss0 = NULL, *gss = NULL, *gfs = NULL, *gee = NULL;
    int64_t *perm = NULL, *count = NULL, mr = 0, df = 0;
    es__perm g;
    memset(&g, 0, sizeof g);
    es_status rc = es__model_term_basis(ctx, m, j, &ub, &mr, &df);
    if (rc != ES_OK) return rc;
    const int64_t mc = df + rk;
    int64_t batch = (int64_t)(4 << 20) / (mc * (p > n ? p : n));
    if (batch < 1) batch = 1;
    if (batch > 64) batch = 64;
    if (B > 0 && batch > B) batch = B;
    e = es__alloc_array(ctx, n * r, sizeof *e);
    w = es__alloc_array(ctx, n * mc * batch, sizeof *w);
    a = es__alloc_array(ctx, mc * batch * r, sizeof *a);
    const int64_t nbig = mc * batch * p > 64 * n ? mc * batch * p : 64 * n;
    big = es__alloc_array(ctx, nbig, sizeof *big);
    ss = es__alloc_array(ctx, p, sizeof *ss);
    fs = es__alloc_array(ctx, p, sizeof *fs);
    ee = es__alloc_array(ctx, p, sizeof *ee);
    rss0 = es__alloc_array(ctx, p, sizeof *rss0);
    gss = es__alloc_array(ctx, ng, sizeof *gss);
    gfs = es__alloc_array(ctx, ng, sizeof *gfs);
    gee = es__alloc_array(ctx, ng, sizeof *gee);
    perm = es__alloc_array(ctx, n, sizeof *perm);
    count = es__calloc(ctx, (size_t)ng, sizeof *count);
    if (!e || !w || !a || !big || !ss || !fs || !ee || !rss0 || !gss || !gfs || !gee || !perm ||
        !count) {
        rc = ES_ENOMEM;
        goto done;
    }
    const double *dd = ub + mr * n;
    const double dfr = (double)m->df_resid;
    for (int64_t x = 0; x < ng; x++) f[x] = pval[x] = qval[x] = NAN;
    /* observed: SS_e = ||D^T Z u_e||^2, RSS_e = ||(I - Qf Qf^T) Z u_e||^2 */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)df, (int)r, (int)n, 1.0, dd,
                (int)n, z, (int)n, 0.0, a, (int)df);
    colsq_product(df, r, a, df, u, p, big, nbig, ss);
    if ((rc = es__model_residuals(ctx, m, m->priv->qf, rk, e)) != ES_OK) goto done;
    colsq_product(n, r, e, n, u, p, big, nbig, rss0);
    group_sum(p, group, ss, ng, gss);
    group_sum(p, group, rss0, ng, gee);
    for (int64_t x = 0; x < ng; x++)
        if (gee[x] > 0) f[x] = (gss[x] / (double)df) / (gee[x] / dfr);
    if (B > 0) {
        /* the permuted residuals: E of the reduced model (RRPP) or Z (raw) */
        if (m->scheme == ES_PERM_RAW) memcpy(e, z, (size_t)(n * r) * sizeof *e);
        else if ((rc = es__model_residuals(ctx, m, ub, mr, e)) != ES_OK) goto done;
        colsq_product(n, r, e, n, u, p, big, nbig, ee);   /* ||E u_e||^2 */
        group_sum(p, group, ee, ng, gee);
        if ((rc = es__perm_init(ctx, &g, n, m->priv->blocks, m->seed)) != ES_OK) goto done;
        for (int64_t b0 = 0; b0 < B; b0 += batch) {
            int64_t nb = B - b0 < batch ? B - b0 : batch;
            for (int64_t k = 0; k < nb; k++) {
                es__perm_next(&g, perm);
                for (int64_t c = 0; c < mc; c++) {
                    const double *src = c < df ? dd + c * n : m->priv->qf + (c - df) * n;
                    double *dst = w + (k * mc + c) * n;
                    for (int64_t i = 0; i < n; i++) dst[perm[i]] = src[i];
                }
            }
            const int64_t rows = mc * nb;
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)rows, (int)r, (int)n, 1.0,
                        w, (int)n, e, (int)n, 0.0, a, (int)rows);
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, (int)rows, (int)p, (int)r, 1.0,
                        a, (int)rows, u, (int)p, 0.0, big, (int)rows);
            for (int64_t k = 0; k < nb; k++) {
                colsq(big, rows, k * mc, k * mc + df, p, ss);
                colsq(big, rows, k * mc + df, (k + 1) * mc, p, fs);
                group_sum(p, group, ss, ng, gss);
                group_sum(p, group, fs, ng, gfs);
                for (int64_t x = 0; x < ng; x++) {
                    if (!isfinite(f[x])) continue;
                    double fx = (gss[x] / (double)df) / ((gee[x] - gfs[x]) / dfr);
                    if (fx >= f[x] - TIE_EPS * fmax(1.0, f[x])) count[x]++;
                }
            }
            if ((rc = es__progress(ctx, "variable tests: permutations", b0 + nb, B)))
                goto done;
        }
        for (int64_t x = 0; x < ng; x++)
            if (isfinite(f[x])) pval[x] = (double)(count[x] + 1) / (double)(B + 1);
        rc = es_fdr_bh(ctx, ng, pval, qval);
    }
done:
    es__perm_clear(ctx, &g);
    double *own[] = {ub, e, w, a, big, ss, fs, ee, rss0, gss, gfs, gee};
    for (size_t k = 0; k < sizeof own / sizeof *own; k++) es__free(ctx, own[k]);
    es__free(ctx, perm);
    es__free(ctx, count);
    return rc;
}

es_status es_model_variable_tests(es_ctx *ctx, const es_model *m, const char *term,
                                  int64_t permutations, double *f, double *pval, double *qval)
{
    return es_model_group_tests(ctx, m, term, permutations, 0, NULL, f, pval, qval);
}

es_status es_model_cac(es_ctx *ctx, const es_model *m, const char *term, double *cac,
                       double *scores)
{
    if (!m || !cac) ES_FAIL(ctx, ES_EINVAL, "cac: bad arguments");
    const int64_t j = es_model_find_term(m, term);
    if (j < 0) ES_FAIL(ctx, ES_ENOTFOUND, "cac: the model has no term '%s'", term ? term : "");
    const es_design *d = m->design;
    int64_t c = -1, ncol = 0;
    for (int64_t k = 0; k < d->ncols; k++)
        if (d->assign[k] == j) c = k, ncol++;
    if (ncol != 1)
        ES_FAIL(ctx, ES_EINVAL, "cac: '%s' is not one numeric column (log size)", term);
    for (int64_t v = 0; v < d->nvars; v++)
        if (d->col_level[v + c * d->nvars] >= 0)
            ES_FAIL(ctx, ES_EINVAL, "cac: '%s' is not one numeric column (log size)", term);
    /* size residualized on the intercept and every term without its variable */
    const int64_t p = m->p, r = m->priv->r, n = m->n, T = d->nterms;
    int64_t u = -1;
    for (int64_t v = 0; v < d->nvars; v++)
        if (d->term_vars[j + v * T]) u = v;
    int *use = es__alloc_array(ctx, T, sizeof *use);
    double *q0 = NULL, *x = es__alloc_array(ctx, n, sizeof *x), *a = es__alloc_array(ctx, r, sizeof *a);
    int64_t m0 = 0;
    es_status rc = use && x && a ? ES_OK : ES_ENOMEM;
    for (int64_t t = 0; rc == ES_OK && t < T; t++) use[t] = !d->term_vars[t + u * T];
    if (rc == ES_OK) rc = es__model_basis(ctx, d, use, &q0, &m0);
    if (rc != ES_OK) goto done;
    memcpy(x, d->x + c * n, (size_t)n * sizeof *x);
    for (int64_t k = 0; k < m0; k++)
        cblas_daxpy((int)n, -cblas_ddot((int)n, q0 + k * n, 1, x, 1), q0 + k * n, 1, x, 1);
    /* its regression vector is U (Z^T x) / ||x||^2: the direction of a = Z^T x */
    cblas_dgemv(CblasColMajor, CblasTrans, (int)n, (int)r, 1.0, m->priv->pca->scores, (int)n,
                x, 1, 0.0, a, 1);
    const double nrm = cblas_dnrm2((int)r, a, 1);
    if (!(nrm > 0) || !isfinite(nrm)) {
        rc = es__fail(ctx, ES_ENUMERIC, "cac: the within-group regression on '%s' is %s", term,
                      isfinite(nrm) ? "zero" : "not finite");
        goto done;
    }
    cblas_dscal((int)r, 1.0 / nrm, a, 1);
    cblas_dgemv(CblasColMajor, CblasNoTrans, (int)p, (int)r, 1.0, m->priv->pca->components,
                (int)p, a, 1, 0.0, cac, 1);
    if (scores)
        cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)r, 1.0, m->priv->pca->scores,
                    (int)n, a, 1, 0.0, scores, 1);
done:
    es__free(ctx, use);
    es__free(ctx, q0);
    es__free(ctx, x);
    es__free(ctx, a);
    return rc;
}
