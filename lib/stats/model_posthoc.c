/* lib/stats/model_posthoc.c — what follows a fitted model: pairwise
 * comparisons of least-squares means (RRPP's pairwise), per-variable
 * (per-edge) tests with the FDR, and the common allometric component.
 *
 * All three reuse the fit's principal coordinates Z and components U
 * (Y_c = Z U^T) and its permutations:
 *  - an LS mean is a combination of rows, c^T Y, with c = Qf Rf^-T g for
 *    the reference-grid row g (Searle, Speed & Milliken 1980; emmeans'
 *    grid: other factors' levels weighted equally, numeric variables at
 *    their mean), so the distance of two is ||(c_a - c_b)^T Z||; under
 *    the null model (without the factor) its residuals are permuted as in
 *    the fit and the full model's LS means recomputed;
 *  - the univariate F of every variable e needs the columns of [D Qf]^T P E
 *    in the response's space: (W^T E) U^T, one more product per batch;
 *  - the CAC is the unit coefficient vector of log size (Mitteroecker,
 *    Gunz, Bernhard, Schaefer & Bookstein 2004).
 */
#include "stats/stats_pkg.h"

#include <cblas.h>
#include <math.h>
#include <string.h>

#define TIE_EPS 1.4901161193847656e-08

void es_model_pairwise_free(es_model_pairwise *pw)
{
    if (!pw) return;
    for (int64_t l = 0; pw->levels && l < pw->nlevels; l++) es__free(pw->ctx, pw->levels[l]);
    es__free(pw->ctx, pw->levels);
    es__free(pw->ctx, pw->lsmeans);
    es__free(pw->ctx, pw->weights);
    es__free(pw->ctx, pw->dist);
    es__free(pw->ctx, pw->pval);
    es__free(pw->ctx, pw);
}

/* The code of column c's factor v (coding cd, flagged level k) at level l. */
static double code(int cd, int64_t k, int64_t l, int64_t L)
{
    if (cd == 1) return l == k ? 1.0 : (l == L - 1 ? -1.0 : 0.0);
    return l == k ? 1.0 : 0.0;
}

/* Reference-grid row g (q) of level l of factor v. */
static void grid_row(const es_design *d, int64_t v, int64_t l, double *g)
{
    const int64_t n = d->n, V = d->nvars, T = d->nterms;
    for (int64_t c = 0; c < d->ncols; c++) {
        int64_t t = d->assign[c];
        double x = 1;
        for (int64_t u = 0; t >= 0 && u < V; u++) {
            if (!d->term_vars[t + u * T]) continue;
            if (!d->var_factor[u]) {
                double s = 0;
                for (int64_t i = 0; i < n; i++) s += d->values[i + u * n];
                x *= s / (double)n;
                continue;
            }
            int cd = d->term_coding[t + u * T];
            int64_t k = d->col_level[u + c * V], L = d->nlevels[u];
            if (u == v) {
                x *= code(cd, k, l, L);
            } else {
                double s = 0;
                for (int64_t l2 = 0; l2 < L; l2++) s += code(cd, k, l2, L);
                x *= s / (double)L;
            }
        }
        g[c] = x;
    }
}

/* Row weights c = Qf Rf^-T g[kept] of a grid row. */
static void grid_weights(const es_model *m, const double *g, double *y, double *w)
{
    const struct es_model_priv *pv = m->priv;
    for (int64_t a = 0; a < m->rank; a++) y[a] = g[pv->kept[a]];
    cblas_dtrsv(CblasColMajor, CblasUpper, CblasTrans, CblasNonUnit, (int)m->rank, pv->rf,
                (int)m->rank, y, 1);
    cblas_dgemv(CblasColMajor, CblasNoTrans, (int)m->n, (int)m->rank, 1.0, pv->qf, (int)m->n,
                y, 1, 0.0, w, 1);
}

/* Distances between the rows of a (L x r, ld lda). */
static void row_dists(int64_t L, int64_t r, const double *a, int64_t lda, double *dist)
{
    for (int64_t i = 0; i < L; i++)
        for (int64_t j = 0; j < L; j++) {
            double s = 0;
            for (int64_t k = 0; k < r; k++) {
                double t = a[i + k * lda] - a[j + k * lda];
                s += t * t;
            }
            dist[i + j * L] = sqrt(s);
        }
}

static es_status pairwise_permute(es_ctx *ctx, const es_model *m, int64_t v,
                                  es_model_pairwise *pw, int64_t *count)
{
    const es_design *d = m->design;
    const int64_t n = m->n, r = m->priv->r, L = pw->nlevels, B = m->permutations;
    const double *z = m->priv->pca->scores;
    int *use = es__alloc_array(ctx, d->nterms, sizeof *use);
    double *ur = NULL, *e = es__alloc_array(ctx, n * r, sizeof *e);
    double *cf = es__alloc_array(ctx, L * r, sizeof *cf);
    int64_t batch = (int64_t)(2 << 20) / (L * (n > r ? n : r));
    if (batch < 1) batch = 1;
    if (batch > 256) batch = 256;
    double *w = es__alloc_array(ctx, n * L * batch, sizeof *w);
    double *a = es__alloc_array(ctx, L * batch * r, sizeof *a);
    double *dist = es__alloc_array(ctx, L * L, sizeof *dist);
    int64_t *perm = es__alloc_array(ctx, n, sizeof *perm), mr = 0;
    es__perm g;
    memset(&g, 0, sizeof g);
    es_status rc = ES_OK;
    if (!use || !e || !cf || !w || !a || !dist || !perm) {
        rc = ES_ENOMEM;
        goto done;
    }
    /* the null model: every term without the factor */
    for (int64_t t = 0; t < d->nterms; t++) use[t] = !d->term_vars[t + v * d->nterms];
    if ((rc = es__model_basis(ctx, d, use, &ur, &mr)) != ES_OK ||
        (rc = es__model_residuals(ctx, m, ur, mr, e)) != ES_OK ||
        (rc = es__perm_init(ctx, &g, n, m->priv->blocks, m->seed)) != ES_OK)
        goto done;
    /* C^T F_r = C^T Z - C^T E */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)L, (int)r, (int)n, 1.0,
                pw->weights, (int)n, z, (int)n, 0.0, cf, (int)L);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)L, (int)r, (int)n, -1.0,
                pw->weights, (int)n, e, (int)n, 1.0, cf, (int)L);
    for (int64_t b0 = 0; b0 < B; b0 += batch) {
        int64_t nb = B - b0 < batch ? B - b0 : batch;
        for (int64_t k = 0; k < nb; k++) {
            es__perm_next(&g, perm);
            for (int64_t l = 0; l < L; l++) {
                const double *src = pw->weights + l * n;
                double *dst = w + (k * L + l) * n;
                for (int64_t i = 0; i < n; i++) dst[perm[i]] = src[i];
            }
        }
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)(L * nb), (int)r, (int)n,
                    1.0, w, (int)n, e, (int)n, 0.0, a, (int)(L * batch));
        for (int64_t k = 0; k < nb; k++) {
            double *ak = a + k * L;
            for (int64_t col = 0; col < r; col++)
                for (int64_t l = 0; l < L; l++) ak[l + col * L * batch] += cf[l + col * L];
            row_dists(L, r, ak, L * batch, dist);
            for (int64_t x = 0; x < L * L; x++)
                if (dist[x] >= pw->dist[x] - TIE_EPS * fmax(1.0, pw->dist[x])) count[x]++;
        }
        if ((rc = es__progress(ctx, "pairwise: permutations", b0 + nb, B))) goto done;
    }
done:
    es__perm_clear(ctx, &g);
    es__free(ctx, use);
    es__free(ctx, ur);
    es__free(ctx, e);
    es__free(ctx, cf);
    es__free(ctx, w);
    es__free(ctx, a);
    es__free(ctx, dist);
    es__free(ctx, perm);
    return rc;
}

es_status es_model_pairwise_fit(es_ctx *ctx, const es_model *m, const char *var,
                                es_model_pairwise **out)
{
    *out = NULL;
    if (!m || !var) ES_FAIL(ctx, ES_EINVAL, "pairwise: no model or no factor");
    const es_design *d = m->design;
    int64_t v = -1;
    for (int64_t u = 0; u < d->nvars && v < 0; u++)
        if (!strcmp(d->vars[u], var)) v = u;
    if (v < 0 || !d->var_factor[v])
        ES_FAIL(ctx, v < 0 ? ES_ENOTFOUND : ES_EINVAL, "pairwise: '%s' is not a %s of the model",
                var, v < 0 ? "variable" : "categorical variable");
    const int64_t n = m->n, p = m->p, r = m->priv->r, L = d->nlevels[v];
    es_model_pairwise *pw = es__calloc(ctx, 1, sizeof *pw);
    if (!pw) return ES_ENOMEM;
    pw->ctx = ctx;
    pw->nlevels = L;
    pw->p = p;
    pw->n = n;
    double *g = es__alloc_array(ctx, d->ncols + m->rank, sizeof *g);
    double *cz = es__alloc_array(ctx, L * r, sizeof *cz);
    int64_t *count = es__calloc(ctx, (size_t)(L * L), sizeof *count);
    pw->levels = es__calloc(ctx, (size_t)L, sizeof *pw->levels);
    pw->lsmeans = es__alloc_array(ctx, L * p, sizeof *pw->lsmeans);
    pw->weights = es__alloc_array(ctx, n * L, sizeof *pw->weights);
    pw->dist = es__alloc_array(ctx, L * L, sizeof *pw->dist);
    pw->pval = es__alloc_array(ctx, L * L, sizeof *pw->pval);
    es_status rc = ES_OK;
    if (!g || !cz || !count || !pw->levels || !pw->lsmeans || !pw->weights || !pw->dist ||
        !pw->pval) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t l = 0; l < L; l++) {
        if (!(pw->levels[l] = es__strdup(ctx, d->levels[v][l]))) {
            rc = ES_ENOMEM;
            goto done;
        }
        grid_row(d, v, l, g);
        grid_weights(m, g, g + d->ncols, pw->weights + l * n);
    }
    /* LS means: C^T Z (L x r), distances, and in the response: C^T Z U^T + mean */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)L, (int)r, (int)n, 1.0,
                pw->weights, (int)n, m->priv->pca->scores, (int)n, 0.0, cz, (int)L);
    row_dists(L, r, cz, L, pw->dist);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, (int)L, (int)p, (int)r, 1.0, cz,
                (int)L, m->priv->pca->components, (int)p, 0.0, pw->lsmeans, (int)L);
    for (int64_t e = 0; e < p; e++)
        for (int64_t l = 0; l < L; l++) pw->lsmeans[l + e * L] += m->mean[e];
    for (int64_t x = 0; x < L * L; x++) pw->pval[x] = NAN;
    if (m->permutations > 0) {
        if ((rc = pairwise_permute(ctx, m, v, pw, count)) != ES_OK) goto done;
        for (int64_t x = 0; x < L * L; x++)
            pw->pval[x] = (double)(count[x] + 1) / (double)(m->permutations + 1);
    }
    for (int64_t l = 0; l < L; l++) pw->pval[l + l * L] = 1.0;
    *out = pw;
    pw = NULL;
done:
    es_model_pairwise_free(pw);
    es__free(ctx, g);
    es__free(ctx, cz);
    es__free(ctx, count);
    return rc;
}

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

es_status es_model_variable_tests(es_ctx *ctx, const es_model *m, const char *term,
                                  int64_t permutations, double *f, double *pval, double *qval)
{
    if (!m || !f || !pval || !qval) ES_FAIL(ctx, ES_EINVAL, "edge tests: bad arguments");
    const int64_t j = es_model_find_term(m, term);
    if (j < 0) ES_FAIL(ctx, ES_ENOTFOUND, "edge tests: the model has no term '%s'",
                       term ? term : "");
    if (permutations > ES_MAX_PERMUTATIONS)
        ES_FAIL(ctx, ES_EINVAL, "edge tests: %lld permutations (0 to %d)",
                (long long)permutations, ES_MAX_PERMUTATIONS);
    const int64_t B = permutations < 0 ? m->permutations : permutations;
    const int64_t n = m->n, p = m->p, r = m->priv->r, rk = m->rank;
    const double *z = m->priv->pca->scores, *u = m->priv->pca->components;
    double *ub = NULL, *e = NULL, *w = NULL, *a = NULL, *big = NULL, *ss = NULL, *fs = NULL;
    double *ee = NULL, *rss0 = NULL;
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
    perm = es__alloc_array(ctx, n, sizeof *perm);
    count = es__calloc(ctx, (size_t)p, sizeof *count);
    if (!e || !w || !a || !big || !ss || !fs || !ee || !rss0 || !perm || !count) {
        rc = ES_ENOMEM;
        goto done;
    }
    const double *dd = ub + mr * n;
    const double dfr = (double)m->df_resid;
    for (int64_t x = 0; x < p; x++) f[x] = pval[x] = qval[x] = NAN;
    /* observed: SS_e = ||D^T Z u_e||^2, RSS_e = ||(I - Qf Qf^T) Z u_e||^2 */
    if (df > 0) {
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)df, (int)r, (int)n, 1.0, dd,
                    (int)n, z, (int)n, 0.0, a, (int)df);
        colsq_product(df, r, a, df, u, p, big, nbig, ss);
    }
    if ((rc = es__model_residuals(ctx, m, m->priv->qf, rk, e)) != ES_OK) goto done;
    colsq_product(n, r, e, n, u, p, big, nbig, rss0);
    for (int64_t x = 0; x < p; x++)
        if (df > 0 && rss0[x] > 0) f[x] = (ss[x] / (double)df) / (rss0[x] / dfr);
    if (B > 0 && df > 0) {
        /* the permuted residuals: E of the reduced model (RRPP) or Z (raw) */
        if (m->scheme == ES_PERM_RAW) memcpy(e, z, (size_t)(n * r) * sizeof *e);
        else if ((rc = es__model_residuals(ctx, m, ub, mr, e)) != ES_OK) goto done;
        colsq_product(n, r, e, n, u, p, big, nbig, ee);   /* ||E u_e||^2 */
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
                for (int64_t x = 0; x < p; x++) {
                    if (!isfinite(f[x])) continue;
                    double fx = (ss[x] / (double)df) / ((ee[x] - fs[x]) / dfr);
                    if (fx >= f[x] - TIE_EPS * fmax(1.0, f[x])) count[x]++;
                }
            }
            if ((rc = es__progress(ctx, "edge tests: permutations", b0 + nb, B))) goto done;
        }
        for (int64_t x = 0; x < p; x++)
            if (isfinite(f[x])) pval[x] = (double)(count[x] + 1) / (double)(B + 1);
        rc = es_fdr_bh(ctx, p, pval, qval);
    }
done:
    es__perm_clear(ctx, &g);
    es__free(ctx, ub);
    es__free(ctx, e);
    es__free(ctx, w);
    es__free(ctx, a);
    es__free(ctx, big);
    es__free(ctx, ss);
    es__free(ctx, fs);
    es__free(ctx, ee);
    es__free(ctx, rss0);
    es__free(ctx, perm);
    es__free(ctx, count);
    return rc;
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
    const int64_t p = m->p, q = m->ncoef, r = m->priv->r, n = m->n;
    double nrm = 0;
    for (int64_t e = 0; e < p; e++) nrm += m->coef[c + e * q] * m->coef[c + e * q];
    nrm = sqrt(nrm);
    if (!(nrm > 0) || !isfinite(nrm))
        ES_FAIL(ctx, ES_ENUMERIC, "cac: the coefficient of '%s' is %s", term,
                isfinite(nrm) ? "zero" : "aliased");
    for (int64_t e = 0; e < p; e++) cac[e] = m->coef[c + e * q] / nrm;
    if (!scores) return ES_OK;
    /* scores = Z (U^T cac) */
    double *t = es__alloc_array(ctx, r, sizeof *t);
    if (!t) return ES_ENOMEM;
    cblas_dgemv(CblasColMajor, CblasTrans, (int)p, (int)r, 1.0, m->priv->pca->components,
                (int)p, cac, 1, 0.0, t, 1);
    cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)r, 1.0, m->priv->pca->scores, (int)n,
                t, 1, 0.0, scores, 1);
    es__free(ctx, t);
    return ES_OK;
}
