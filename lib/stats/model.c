/* lib/stats/model.c — linear models on shape and their permutation tests
 * (es_model.h): the method of geomorph's procD.lm and RRPP's lm.rrpp
 * (Collyer, Sekora & Adams 2015), on the principal coordinates of the rows.
 *
 * Every statistic is a sum of squares of a projection of the centred
 * response, so it depends on the response only through the Gram matrix of
 * its rows: the principal coordinates Z (N x r, the PCA scores, Z Z^T =
 * Y_c Y_c^T) give the same numbers as the p-column response, however large
 * p is (Anderson 2001; Gower 1966). For term j with reduced-model basis Ur
 * and D the orthonormal complement that the term adds (N x df),
 *     SS_j = ||D^T Y*||^2,  RSS = ||(I - Qf Qf^T) Y*||^2,
 *     F = (SS_j / df) / (RSS / (N - rank)),  R^2 = SS_j / TSS,
 * with Y* = Z observed, and under permutation pi of the residuals E of the
 * reduced model (RRPP) Y* = F_r + P E: since F_r lies in span(Ur), which D
 * is orthogonal to and Qf contains, SS_j = ||D^T P E||^2 and RSS = ||E||^2 -
 * ||Qf^T P E||^2. Both come from one product [D Qf]^T P E per
 * permutation, done for a batch of permutations at once (one dgemm).
 * Permuting rows (vegan's adonis2) is the same with E = Z. RRPP's RSS is
 * that of the full model fitted to the permuted data (RRPP's SS.iter).
 */
#include "stats/stats_pkg.h"
#include "parallel/parallel_private.h"

#include <cblas.h>
#include <float.h>
#include <math.h>
#include <string.h>

#define BASIS_TOL 1e-7
/* vegan's and RRPP's tie rule: F* >= F - eps counts */
#define TIE_EPS 1.4901161193847656e-08

void es_model_opts_init(es_model_opts *o)
{
    memset(o, 0, sizeof *o);
    o->ss_type = ES_SS_TYPE_I;
    o->scheme = ES_PERM_RRPP;
    o->permutations = 999;
}

int es__basis_add(int64_t n, double *q, int64_t *m, const double *x, double *r)
{
    double *v = q + *m * n, nx = cblas_dnrm2((int)n, x, 1);
    memcpy(v, x, (size_t)n * sizeof *v);
    if (r) memset(r, 0, (size_t)(*m + 1) * sizeof *r);
    for (int pass = 0; pass < 2 && *m > 0; pass++)
        for (int64_t k = 0; k < *m; k++) {
            double c = cblas_ddot((int)n, q + k * n, 1, v, 1);
            cblas_daxpy((int)n, -c, q + k * n, 1, v, 1);
            if (r) r[k] += c;
        }
    double nv = cblas_dnrm2((int)n, v, 1);
    if (!(nx > 0) || !(nv > BASIS_TOL * nx)) return 0;
    cblas_dscal((int)n, 1.0 / nv, v, 1);
    if (r) r[*m] = nv;
    (*m)++;
    return 1;
}

es_status es__model_basis(es_ctx *ctx, const es_design *d, const int *use, double **q,
                          int64_t *m)
{
    const int64_t n = d->n;
    *m = 0;
    if (!(*q = es__alloc_array(ctx, n * d->ncols, sizeof **q))) return ES_ENOMEM;
    for (int64_t c = 0; c < d->ncols; c++)
        if (d->assign[c] < 0 || use[d->assign[c]]) es__basis_add(n, *q, m, d->x + c * n, NULL);
    return ES_OK;
}

es_status es__model_residuals(es_ctx *ctx, const es_model *m, const double *q, int64_t mq,
                              double *e)
{
    const int64_t n = m->n, r = m->priv->r;
    const double *z = m->priv->pca->scores;
    memcpy(e, z, (size_t)(n * r) * sizeof *e);
    if (mq < 1) return ES_OK;
    double *c = es__alloc_array(ctx, mq * r, sizeof *c);
    if (!c) return ES_ENOMEM;
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)mq, (int)r, (int)n, 1.0, q,
                (int)n, z, (int)n, 0.0, c, (int)mq);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)n, (int)r, (int)mq, -1.0, q,
                (int)n, c, (int)mq, 1.0, e, (int)n);
    es__free(ctx, c);
    return ES_OK;
}

void es_model_free(es_model *m)
{
    if (!m) return;
    es_ctx *ctx = m->ctx;
    double *own[] = {m->ss, m->ms, m->r2, m->f, m->pval, m->z, m->fperm, m->ssperm, m->coef,
                     m->coef_weights, m->mean};
    for (size_t i = 0; i < sizeof own / sizeof *own; i++) es__free(ctx, own[i]);
    es__free(ctx, m->df);
    es__free(ctx, m->error);
    es__free(ctx, m->testable);
    if (m->priv) {
        es_pca_free(m->priv->pca);
        es__free(ctx, m->priv->qf);
        es__free(ctx, m->priv->rf);
        es__free(ctx, m->priv->kept);
        es__free(ctx, m->priv->blocks);
        es__free(ctx, m->priv);
    }
    es__free(ctx, m);
}

int64_t es_model_find_term(const es_model *m, const char *term)
{
    for (int64_t j = 0; m && term && j < m->nterms; j++)
        if (!strcmp(m->design->terms[j], term)) return j;
    return -1;
}

/* Which terms the reduced model of term j holds (full = reduced + j). */
static void reduced_terms(const es_design *d, es_ss_type type, int64_t j, int *use)
{
    const int64_t T = d->nterms, V = d->nvars;
    for (int64_t t = 0; t < T; t++) {
        if (type == ES_SS_TYPE_I) use[t] = t < j;
        else if (type == ES_SS_TYPE_III) use[t] = t != j;
        else {  /* II: the terms that do not contain term j */
            int contains = 1;
            for (int64_t v = 0; v < V; v++)
                if (d->term_vars[j + v * T] && !d->term_vars[t + v * T]) contains = 0;
            use[t] = !contains;
        }
    }
}

es_status es__model_term_basis(es_ctx *ctx, const es_model *m, int64_t j, double **q,
                               int64_t *mr, int64_t *df)
{
    const es_design *d = m->design;
    int *use = es__alloc_array(ctx, d->nterms, sizeof *use);
    *q = NULL;
    if (!use) return ES_ENOMEM;
    reduced_terms(d, m->ss_type, j, use);
    es_status rc = es__model_basis(ctx, d, use, q, mr);
    es__free(ctx, use);
    if (rc != ES_OK) return rc;
    /* D: what term j's columns add to the reduced basis */
    int64_t mf = *mr;
    for (int64_t c = 0; c < d->ncols; c++)
        if (d->assign[c] == j) es__basis_add(d->n, *q, &mf, d->x + c * d->n, NULL);
    *df = mf - *mr;
    return ES_OK;
}

/* The full design's QR: X[:, kept] = Qf Rf. */
static es_status full_qr(es_ctx *ctx, es_model *m)
{
    const es_design *d = m->design;
    const int64_t n = d->n, q = d->ncols;
    struct es_model_priv *pv = m->priv;
    double *r = es__alloc_array(ctx, q + 1, sizeof *r);
    pv->qf = es__alloc_array(ctx, n * q, sizeof *pv->qf);
    pv->rf = es__calloc(ctx, (size_t)(q * q), sizeof *pv->rf);
    pv->kept = es__alloc_array(ctx, q, sizeof *pv->kept);
    if (!r || !pv->qf || !pv->rf || !pv->kept) {
        es__free(ctx, r);
        return ES_ENOMEM;
    }
    int64_t rank = 0;
    for (int64_t c = 0; c < q; c++) {
        int64_t before = rank;
        if (es__basis_add(n, pv->qf, &rank, d->x + c * n, r)) {
            pv->kept[before] = c;
            for (int64_t k = 0; k <= before; k++) pv->rf[k + before * q] = r[k];
        }
    }
    es__free(ctx, r);
    /* pack Rf to rank x rank, ld rank */
    for (int64_t j = 0; j < rank; j++)
        for (int64_t i = 0; i < rank; i++) pv->rf[i + j * rank] = pv->rf[i + j * q];
    m->rank = rank;
    return ES_OK;
}

/* Coefficients (q x p) and their row weights (N x q) from the full QR:
 * B = Rf^-1 Qf^T Y; with Y = 1 mean^T + Z U^T, the intercept row adds the
 * mean. A coefficient's weights are Qf Rf^-T e_c. */
static es_status coefficients(es_ctx *ctx, es_model *m)
{
    const struct es_model_priv *pv = m->priv;
    const int64_t n = m->n, p = m->p, q = m->ncoef, rk = m->rank, r = pv->r;
    const es_pca *pca = pv->pca;
    double *qz = es__alloc_array(ctx, rk * (r > 0 ? r : 1), sizeof *qz);
    double *bk = es__alloc_array(ctx, rk * p, sizeof *bk);
    m->coef = es__alloc_array(ctx, q * p, sizeof *m->coef);
    m->coef_weights = es__calloc(ctx, (size_t)(n * q), sizeof *m->coef_weights);
    m->mean = es__alloc_array(ctx, p, sizeof *m->mean);
    es_status rc = ES_OK;
    if (!qz || !bk || !m->coef || !m->coef_weights || !m->mean) {
        rc = ES_ENOMEM;
        goto done;
    }
    memcpy(m->mean, pca->mean, (size_t)p * sizeof *m->mean);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)rk, (int)r, (int)n, 1.0, pv->qf,
                (int)n, pca->scores, (int)n, 0.0, qz, (int)rk);
    /* Rf^-1 (Qf^T Z), then times U^T: rk x p */
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasNoTrans, CblasNonUnit, (int)rk,
                (int)r, 1.0, pv->rf, (int)rk, qz, (int)rk);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, (int)rk, (int)p, (int)r, 1.0, qz,
                (int)rk, pca->components, (int)p, 0.0, bk, (int)rk);
    for (int64_t k = 0; k < q * p; k++) m->coef[k] = NAN;
    for (int64_t a = 0; a < rk; a++) {
        int64_t c = pv->kept[a];
        for (int64_t e = 0; e < p; e++)
            m->coef[c + e * q] = bk[a + e * rk] + (c == 0 ? pca->mean[e] : 0.0);
        /* weights: solve Rf^T y = e_a, w = Qf y */
        double *y = qz;   /* reuse: rk entries */
        memset(y, 0, (size_t)rk * sizeof *y);
        y[a] = 1;
        cblas_dtrsv(CblasColMajor, CblasUpper, CblasTrans, CblasNonUnit, (int)rk, pv->rf,
                    (int)rk, y, 1);
        cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)rk, 1.0, pv->qf, (int)n, y, 1,
                    0.0, m->coef_weights + c * n, 1);
    }
done:
    es__free(ctx, qz);
    es__free(ctx, bk);
    return rc;
}

/* 1 when every column of D is constant within each block: permuting within
 * blocks then leaves the term's SS as observed, and its test is void. */
static es_status constant_in_blocks(es_ctx *ctx, const es_model *m, const double *dd,
                                    int64_t df, int *constant)
{
    const int64_t n = m->n;
    *constant = 0;
    if (!m->priv->blocks) return ES_OK;
    es__perm g;
    es_status rc = es__perm_init(ctx, &g, n, m->priv->blocks, 0);
    if (rc != ES_OK) return rc;
    double scale = 0;
    for (int64_t k = 0; k < n * df; k++) scale = fmax(scale, fabs(dd[k]));
    int same = 1;
    for (int64_t c = 0; c < df && same; c++)
        for (int64_t b = 0; b < g.nblocks && same; b++) {
            const double first = dd[g.rows[g.start[b]] + c * n];
            for (int64_t k = g.start[b] + 1; k < g.start[b + 1] && same; k++)
                same = fabs(dd[g.rows[k] + c * n] - first) <= 1e-9 * scale;
        }
    es__perm_clear(ctx, &g);
    *constant = same;
    return ES_OK;
}

/* Permutations for term j: F of each into m->fperm, the count into pval.
 * On the ranks of an MPI job each rank evaluates a contiguous share of the
 * B permutations; every rank draws all of them from the one seeded stream
 * (drawing is O(n), evaluating O(n r df)), so permutation b is the same
 * whatever P, and the shares, zero elsewhere, are summed: the same bits as
 * one process, p-values identical. */
static es_status permute_term(es_ctx *ctx, es_model *m, int64_t j, const double *dd, int64_t df,
                              const double *e)
{
    const struct es_model_priv *pv = m->priv;
    const int64_t n = m->n, r = pv->r, rk = m->rank, mc = df + rk, B = m->permutations;
    const double ee = cblas_ddot((int)(n * r), e, 1, e, 1);
    int64_t batch = (int64_t)(4 << 20) / (mc * (n > r ? n : r));
    if (batch < 1) batch = 1;
    if (batch > 256) batch = 256;
    if (batch > B) batch = B;
    double *w = es__alloc_array(ctx, n * mc * batch, sizeof *w);
    double *a = es__alloc_array(ctx, mc * batch * r, sizeof *a);
    int64_t *perm = es__alloc_array(ctx, n, sizeof *perm);
    es__perm g;
    es_status rc = es__perm_init(ctx, &g, n, pv->blocks, m->seed);
    if (rc == ES_OK && (!w || !a || !perm)) rc = ES_ENOMEM;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) goto done;   /* no rank left in a sum */
    int64_t count = 0, lo, hi;
    const double fobs = m->f[j];
    es__par_split(B, es__par_size(ctx), es__par_rank(ctx), &lo, &hi);
    if (!es__par_alone(ctx))
        for (int64_t b = 0; b < B; b++) m->fperm[b + j * B] = m->ssperm[b + j * B] = 0.0;
    for (int64_t b = 0; b < lo; b++) es__perm_next(&g, perm);   /* the other ranks' */
    for (int64_t b0 = lo; b0 < hi; b0 += batch) {
        int64_t nb = hi - b0 < batch ? hi - b0 : batch;
        /* W[perm[i], :] = [D Qf][i, :] for each permutation of the batch */
        for (int64_t k = 0; k < nb; k++) {
            es__perm_next(&g, perm);
            double *wk = w + k * mc * n;
            for (int64_t c = 0; c < mc; c++) {
                const double *src = c < df ? dd + c * n : pv->qf + (c - df) * n;
                double *dst = wk + c * n;
                for (int64_t i = 0; i < n; i++) dst[perm[i]] = src[i];
            }
        }
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)(mc * nb), (int)r, (int)n,
                    1.0, w, (int)n, e, (int)n, 0.0, a, (int)(mc * batch));
        for (int64_t k = 0; k < nb; k++) {
            double ss = 0, fs = 0;
            for (int64_t col = 0; col < r; col++) {
                const double *ak = a + k * mc + col * mc * batch;
                for (int64_t c = 0; c < df; c++) ss += ak[c] * ak[c];
                for (int64_t c = df; c < mc; c++) fs += ak[c] * ak[c];
            }
            double rss = ee - fs;
            double f = (ss / (double)df) / (rss / (double)m->df_resid);
            m->fperm[(b0 + k) + j * B] = f;
            m->ssperm[(b0 + k) + j * B] = ss;
            if (f >= fobs - TIE_EPS * fmax(1.0, fabs(fobs))) count++;
        }
        if ((rc = es__progress(ctx, "model: permutations", j * B + b0 + nb, m->nterms * B)))
            goto done;
    }
    if (!es__par_alone(ctx) &&
        ((rc = es__par_sum(ctx, m->fperm + j * B, B)) != ES_OK ||
         (rc = es__par_sum(ctx, m->ssperm + j * B, B)) != ES_OK ||
         (rc = es__par_sum_i64(ctx, &count, 1)) != ES_OK))
        goto done;
    m->pval[j] = (double)(count + 1) / (double)(B + 1);
done:
    es__perm_clear(ctx, &g);
    es__free(ctx, w);
    es__free(ctx, a);
    es__free(ctx, perm);
    return rc;
}

/* Observed statistics of every term, then its permutations. */
static es_status test_terms(es_ctx *ctx, es_model *m)
{
    const es_design *d = m->design;
    const int64_t n = m->n, r = m->priv->r, T = m->nterms;
    const double *z = m->priv->pca->scores;
    double *e = es__alloc_array(ctx, n * r, sizeof *e);
    double *dz = es__alloc_array(ctx, d->ncols * r, sizeof *dz);
    double *ur = NULL;
    es_status rc = ES_OK;
    if (!e || !dz) {
        rc = ES_ENOMEM;
        goto done;
    }
    /* the residual of the full model, directly (no cancellation) */
    if ((rc = es__model_residuals(ctx, m, m->priv->qf, m->rank, e)) != ES_OK) goto done;
    m->rss = cblas_ddot((int)(n * r), e, 1, e, 1);
    if (!(m->rss > 1e-20 * m->tss)) {
        rc = es__fail(ctx, ES_EINVAL, "model: the design fits the %lld rows exactly (residual "
                      "sum of squares %.3g of %.3g): F is undefined; use fewer terms",
                      (long long)n, m->rss, m->tss);
        goto done;
    }
    for (int64_t j = 0; j < T && rc == ES_OK; j++) {
        int64_t mr = 0, df = 0;
        if ((rc = es__model_term_basis(ctx, m, j, &ur, &mr, &df)) != ES_OK) break;
        const double *dd = ur + mr * n;
        m->df[j] = df;
        if (df == 0) {
            rc = es__fail(ctx, ES_EINVAL, "model: under type %s sums of squares the term '%s' "
                          "adds nothing once %s in (its columns are combinations of theirs): "
                          "its test would have 0 df; use type I, or leave out what holds it",
                          m->ss_type == ES_SS_TYPE_III ? "III" : m->ss_type == ES_SS_TYPE_II ?
                          "II" : "I", d->terms[j], m->ss_type == ES_SS_TYPE_I ?
                          "the terms before it are" : "the other terms are");
            break;
        }
        int constant = 0;
        if ((rc = constant_in_blocks(ctx, m, dd, df, &constant)) != ES_OK) break;
        m->testable[j] = df > 0 && !constant;
        double ss = 0;
        if (df > 0) {
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)df, (int)r, (int)n, 1.0,
                        dd, (int)n, z, (int)n, 0.0, dz, (int)df);
            ss = cblas_ddot((int)(df * r), dz, 1, dz, 1);
        }
        m->ss[j] = ss;
        m->ms[j] = df > 0 ? ss / (double)df : NAN;
        m->r2[j] = ss / m->tss;
        m->f[j] = df > 0 && m->rss > 0 ? m->ms[j] / (m->rss / (double)m->df_resid) : NAN;
        m->pval[j] = NAN;
        if (m->permutations > 0 && m->testable[j] && isfinite(m->f[j])) {
            if (m->scheme == ES_PERM_RAW) memcpy(e, z, (size_t)(n * r) * sizeof *e);
            else if ((rc = es__model_residuals(ctx, m, ur, mr, e)) != ES_OK) break;
            rc = permute_term(ctx, m, j, dd, df, e);
        } else {
            /* constant within blocks: every permutation leaves SS as observed */
            for (int64_t b = 0; b < m->permutations; b++) {
                m->fperm[b + j * m->permutations] = NAN;
                m->ssperm[b + j * m->permutations] = df > 0 ? ss : NAN;
            }
        }
        es__free(ctx, ur);
        ur = NULL;
    }
done:
    es__free(ctx, e);
    es__free(ctx, dz);
    es__free(ctx, ur);
    return rc;
}

/* Terms with an error term other than the residual: F = MS_j / MS_e, in the
 * observed data and in each permutation (both terms' SS from the same row
 * permutation, each under its own reduced model: RRPP's anova(error =));
 * then every tested term's p-value and effect size from its F's. */
static es_status finish_terms(es_ctx *ctx, es_model *m)
{
    const int64_t T = m->nterms, B = m->permutations;
    double *s = es__alloc_array(ctx, B + 1, sizeof *s);
    if (!s) return ES_ENOMEM;
    es_status rc = ES_OK;
    for (int64_t j = 0; j < T && rc == ES_OK; j++) {
        const int64_t e = m->error[j];
        if (e >= 0) {
            m->f[j] = m->ms[j] / m->ms[e];
            for (int64_t b = 0; b < B; b++)
                m->fperm[b + j * B] = (m->ssperm[b + j * B] / (double)m->df[j]) /
                                      (m->ssperm[b + e * B] / (double)m->df[e]);
        }
        m->z[j] = NAN;
        if (B < 1 || isnan(m->pval[j])) continue;
        s[0] = m->f[j];
        memcpy(s + 1, m->fperm + j * B, (size_t)B * sizeof *s);
        rc = es__perm_summary(ctx, s, B + 1, 0.95, &m->pval[j], &m->z[j], NULL);
    }
    es__free(ctx, s);
    return rc;
}

es_status es_model_fit(es_ctx *ctx, const es_design *d, const es_source *src,
                       const es_model_opts *opts, es_model **out)
{
    es_model_opts o;
    *out = NULL;
    if (opts) o = *opts;
    else es_model_opts_init(&o);
    if (!d || !src) ES_FAIL(ctx, ES_EINVAL, "model: no design or no data");
    if (src->nrows != d->n)
        ES_FAIL(ctx, ES_EINVAL, "model: %lld rows of data, %lld of design", (long long)src->nrows,
                (long long)d->n);
    if (o.permutations < 0 || o.permutations > ES_MAX_PERMUTATIONS)
        ES_FAIL(ctx, ES_EINVAL, "model: %lld permutations (0 to %d)", (long long)o.permutations,
                ES_MAX_PERMUTATIONS);
    if (o.ss_type < ES_SS_TYPE_I || o.ss_type > ES_SS_TYPE_III)
        ES_FAIL(ctx, ES_EINVAL, "model: unknown sums-of-squares type %d", (int)o.ss_type);
    const int64_t n = d->n, T = d->nterms, B = o.permutations;
    es_model *m = es__calloc(ctx, 1, sizeof *m);
    if (!m) return ES_ENOMEM;
    m->ctx = ctx;
    m->design = d;
    m->n = n;
    m->p = src->nedges;
    m->nterms = T;
    m->ss_type = o.ss_type;
    m->scheme = o.scheme;
    m->permutations = B;
    m->seed = o.seed ? o.seed : es_ctx_seed(ctx);
    m->ncoef = d->ncols;
    es_status rc = ES_OK;
    if (!(m->priv = es__calloc(ctx, 1, sizeof *m->priv))) {
        rc = ES_ENOMEM;
        goto done;
    }
    m->df = es__calloc(ctx, (size_t)(T > 0 ? T : 1), sizeof *m->df);
    m->testable = es__calloc(ctx, (size_t)(T > 0 ? T : 1), sizeof *m->testable);
    m->ss = es__alloc_array(ctx, T > 0 ? T : 1, sizeof(double));
    m->ms = es__alloc_array(ctx, T > 0 ? T : 1, sizeof(double));
    m->r2 = es__alloc_array(ctx, T > 0 ? T : 1, sizeof(double));
    m->f = es__alloc_array(ctx, T > 0 ? T : 1, sizeof(double));
    m->pval = es__alloc_array(ctx, T > 0 ? T : 1, sizeof(double));
    m->z = es__alloc_array(ctx, T > 0 ? T : 1, sizeof(double));
    m->error = es__alloc_array(ctx, T > 0 ? T : 1, sizeof *m->error);
    m->fperm = es__alloc_array(ctx, (B > 0 ? B : 1) * (T > 0 ? T : 1), sizeof(double));
    m->ssperm = es__alloc_array(ctx, (B > 0 ? B : 1) * (T > 0 ? T : 1), sizeof(double));
    if (!m->df || !m->testable || !m->ss || !m->ms || !m->r2 || !m->f || !m->pval || !m->z ||
        !m->error || !m->fperm || !m->ssperm) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t j = 0; j < T; j++) {
        m->error[j] = o.error ? o.error[j] : -1;
        if (m->error[j] < -1 || m->error[j] >= T || m->error[j] == j) {
            rc = es__fail(ctx, ES_EINVAL, "model: the error term of '%s' is %s", d->terms[j],
                          m->error[j] == j ? "the term itself" : "not a term of the model");
            goto done;
        }
    }
    if (o.blocks) {
        if (!(m->priv->blocks = es__alloc_array(ctx, n, sizeof *m->priv->blocks))) {
            rc = ES_ENOMEM;
            goto done;
        }
        for (int64_t i = 0; i < n; i++) {
            if (o.blocks[i] < 0) {
                rc = es__fail(ctx, ES_EINVAL, "model: row %lld has block %lld (< 0)",
                              (long long)i, (long long)o.blocks[i]);
                goto done;
            }
            m->priv->blocks[i] = o.blocks[i];
        }
    }
    if ((rc = full_qr(ctx, m)) != ES_OK) goto done;
    m->df_resid = n - m->rank;
    if (m->df_resid < 1) {
        rc = es__fail(ctx, ES_EINVAL, "model: %lld rows and a design of rank %lld leave no "
                      "residual degrees of freedom", (long long)n, (long long)m->rank);
        goto done;
    }
    es_pca_opts po;
    es_pca_opts_init(&po);
    if ((rc = es_pca_fit(ctx, src, &po, &m->priv->pca)) != ES_OK) goto done;
    m->priv->r = m->priv->pca->ncomp;
    if (m->priv->r < 1) {
        rc = es__fail(ctx, ES_EINVAL, "model: all %lld rows are equal: nothing to explain",
                      (long long)n);
        goto done;
    }
    m->priv->zz = cblas_ddot((int)(n * m->priv->r), m->priv->pca->scores, 1,
                             m->priv->pca->scores, 1);
    m->tss = m->priv->zz;
    if ((rc = test_terms(ctx, m)) != ES_OK || (rc = finish_terms(ctx, m)) != ES_OK ||
        (rc = coefficients(ctx, m)) != ES_OK)
        goto done;
    *out = m;
    m = NULL;
done:
    es_model_free(m);
    return rc;
}
