/* lib/stats/model_pairwise.c — pairwise comparisons after a fitted model
 * (RRPP's pairwise and summary.pairwise): least-squares means of a
 * factor's levels, or their slopes on a covariate, compared by distance
 * (and for slopes by the angle between them and the difference of their
 * lengths), each with a permutation p-value, effect size and upper
 * confidence limit.
 *
 * Every compared vector is a combination of rows, v_l = c_l^T Y, so all of
 * them come from one product C^T Y* per permutation on the principal
 * coordinates (Y_c = Z U^T with U orthonormal keeps distances, lengths and
 * angles):
 *  - an LS mean's c = Qf Rf^-T g for the reference-grid row g (Searle, Speed
 *    & Milliken 1980; emmeans' grid: other factors' levels weighted
 *    equally, a nested factor's over those seen with the level, numeric
 *    variables at their mean or at a given value);
 *  - a level's slope is the within-level regression of the fitted values on
 *    the covariate (RRPP's getSlopes: fitted ~ group * x + 0), c = Qf Qf^T w
 *    with w_i = (x_i - mean_l x) / S_xx,l on the level's rows.
 * Y* = F0 + P E0: the null model's fitted values plus its permuted
 * residuals, so C^T Y* = C^T F0 + (P^T C)^T E0 (the observed data is the
 * identity permutation).
 */
#include "stats/stats_pkg.h"

#include <cblas.h>
#include <math.h>
#include <string.h>

void es_model_pairwise_opts_init(es_model_pairwise_opts *o)
{
    memset(o, 0, sizeof *o);
    o->confidence = 0.95;
}

void es_model_pairwise_free(es_model_pairwise *pw)
{
    if (!pw) return;
    es_ctx *ctx = pw->ctx;
    for (int64_t l = 0; pw->levels && l < pw->nlevels; l++) es__free(ctx, pw->levels[l]);
    es__free(ctx, pw->levels);
    double *own[] = {pw->at, pw->lsmeans, pw->weights, pw->dist, pw->pval, pw->z, pw->ucl,
                     pw->vcor, pw->angle, pw->angle_p, pw->angle_z, pw->angle_ucl, pw->dlength,
                     pw->dlength_p, pw->dlength_z, pw->dlength_ucl};
    for (size_t i = 0; i < sizeof own / sizeof *own; i++) es__free(ctx, own[i]);
    es__free(ctx, pw);
}

/* The code of column c's factor v (coding cd, flagged level k) at level l. */
static double code(int cd, int64_t k, int64_t l, int64_t L)
{
    if (cd == 1) return l == k ? 1.0 : (l == L - 1 ? -1.0 : 0.0);
    return l == k ? 1.0 : 0.0;
}

/* Whether factor u is nested in factor v: some term holds u and every term
 * that does holds v (~ pop/ind: ind within pop). A factor held only with a
 * covariate (~ w/pop) is not nested: its levels are the same everywhere. */
static int nested_in(const es_design *d, int64_t u, int64_t v)
{
    const int64_t T = d->nterms;
    int any = 0;
    for (int64_t t = 0; t < T; t++) {
        if (!d->term_vars[t + u * T]) continue;
        if (!d->term_vars[t + v * T]) return 0;
        any = 1;
    }
    return any && u != v && d->var_factor[u] && d->var_factor[v];
}

/* seen[u + l2 V] = 1 when level l2 of a factor u nested in v occurs in a
 * row of level l of v: the levels its grid averages over. */
static void nested_levels(const es_design *d, int64_t v, int64_t l, int64_t maxl,
                          unsigned char *seen)
{
    const int64_t V = d->nvars, n = d->n;
    memset(seen, 0, (size_t)(V * maxl));
    for (int64_t u = 0; u < V; u++)
        if (nested_in(d, u, v))
            for (int64_t i = 0; i < n; i++)
                if (d->codes[i + v * n] == l) seen[u + d->codes[i + u * n] * V] = 1;
}

/* Reference-grid row g (q) of level l of factor v, numeric variables at at[].
 * Another factor's levels are weighted equally; one nested in v only over
 * those that occur with level l (seen), as emmeans does for nesting: the
 * individuals of one population are not those of another, and a cell that
 * was never observed has no estimate to average. */
static void grid_row(const es_design *d, int64_t v, int64_t l, const double *at,
                     const unsigned char *seen, double *g)
{
    const int64_t V = d->nvars, T = d->nterms;
    for (int64_t c = 0; c < d->ncols; c++) {
        int64_t t = d->assign[c];
        double x = 1;
        for (int64_t u = 0; t >= 0 && u < V; u++) {
            if (!d->term_vars[t + u * T]) continue;
            if (!d->var_factor[u]) {
                x *= at[u];
                continue;
            }
            int cd = d->term_coding[t + u * T];
            int64_t k = d->col_level[u + c * V], L = d->nlevels[u];
            if (u == v) {
                x *= code(cd, k, l, L);
            } else {
                double s = 0, nl = 0;
                const int nested = nested_in(d, u, v);
                for (int64_t l2 = 0; l2 < L; l2++)
                    if (!nested || seen[u + l2 * V]) {
                        s += code(cd, k, l2, L);
                        nl++;
                    }
                x *= s / nl;
            }
        }
        g[c] = x;
    }
}

/* Row weights w = Qf Rf^-T g[kept] of a grid row (y: rank entries of work). */
static void grid_weights(const es_model *m, const double *g, double *y, double *w)
{
    const struct es_model_priv *pv = m->priv;
    for (int64_t a = 0; a < m->rank; a++) y[a] = g[pv->kept[a]];
    cblas_dtrsv(CblasColMajor, CblasUpper, CblasTrans, CblasNonUnit, (int)m->rank, pv->rf,
                (int)m->rank, y, 1);
    cblas_dgemv(CblasColMajor, CblasNoTrans, (int)m->n, (int)m->rank, 1.0, pv->qf, (int)m->n,
                y, 1, 0.0, w, 1);
}

/* Slope weights of level l: Qf Qf^T w, w the within-level regression on x. */
static es_status slope_weights(es_ctx *ctx, const es_model *m, int64_t v, int64_t l,
                               const double *x, double *y, double *w)
{
    const es_design *d = m->design;
    const int64_t n = m->n;
    double sx = 0, sxx = 0, cnt = 0;
    for (int64_t i = 0; i < n; i++)
        if (d->codes[i + v * n] == l) sx += x[i], cnt++;
    const double mx = cnt > 0 ? sx / cnt : 0;
    for (int64_t i = 0; i < n; i++) {
        w[i] = d->codes[i + v * n] == l ? x[i] - mx : 0.0;
        sxx += w[i] * w[i];
    }
    if (!(sxx > 0))
        ES_FAIL(ctx, ES_EINVAL, "pairwise: the covariate does not vary within level '%s'",
                d->levels[v][l]);
    for (int64_t i = 0; i < n; i++) w[i] /= sxx;
    cblas_dgemv(CblasColMajor, CblasTrans, (int)n, (int)m->rank, 1.0, m->priv->qf, (int)n, w, 1,
                0.0, y, 1);
    cblas_dgemv(CblasColMajor, CblasNoTrans, (int)n, (int)m->rank, 1.0, m->priv->qf, (int)n, y,
                1, 0.0, w, 1);
    return ES_OK;
}

/* The statistics of the rows of a (L x r, ld lda) for pair index k of
 * (a, b): into s[k] (distance), and for slopes s[np + k] (angle) and
 * s[2 np + k] (length difference); cos (np) gets the vector correlation. */
static void pair_stats(int64_t L, int64_t r, const double *a, int64_t lda, int slopes,
                       double *s, double *cosine)
{
    const int64_t np = L * (L - 1) / 2;
    int64_t k = 0;
    for (int64_t i = 0; i < L; i++)
        for (int64_t j = i + 1; j < L; j++, k++) {
            double dd = 0, ii = 0, jj = 0, ij = 0;
            for (int64_t c = 0; c < r; c++) {
                const double x = a[i + c * lda], y = a[j + c * lda];
                dd += (x - y) * (x - y);
                ii += x * x;
                jj += y * y;
                ij += x * y;
            }
            s[k] = sqrt(dd);
            if (!slopes) continue;
            double vc = ij / (sqrt(ii) * sqrt(jj));
            if (cosine) cosine[k] = vc;
            s[np + k] = acos(vc > 1 ? 1 : vc < -1 ? -1 : vc);
            s[2 * np + k] = fabs(sqrt(ii) - sqrt(jj));
        }
}

/* All statistics under every permutation: vals ((B + 1) x nstat), row b =
 * permutation b (0: observed). */
static es_status permute(es_ctx *ctx, const es_model *m, const int *use, es_model_pairwise *pw,
                         int64_t nstat, double *vals, double *cosine)
{
    const es_design *d = m->design;
    const int64_t n = m->n, r = m->priv->r, L = pw->nlevels, B = m->permutations;
    const double *z = m->priv->pca->scores;
    double *ur = NULL, *e = es__alloc_array(ctx, n * r, sizeof *e);
    double *cf = es__alloc_array(ctx, L * r, sizeof *cf);
    int64_t batch = (int64_t)(2 << 20) / (L * (n > r ? n : r));
    if (batch < 1) batch = 1;
    if (batch > 256) batch = 256;
    double *w = es__alloc_array(ctx, n * L * batch, sizeof *w);
    double *a = es__alloc_array(ctx, L * batch * r, sizeof *a);
    int64_t *perm = es__alloc_array(ctx, n, sizeof *perm), mr = 0;
    es__perm g;
    memset(&g, 0, sizeof g);
    es_status rc = ES_OK;
    if (!e || !cf || !w || !a || !perm) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es__model_basis(ctx, d, use, &ur, &mr)) != ES_OK ||
        (rc = es__model_residuals(ctx, m, ur, mr, e)) != ES_OK ||
        (rc = es__perm_init(ctx, &g, n, m->priv->blocks, m->seed)) != ES_OK)
        goto done;
    /* C^T F0 = C^T Z - C^T E0 */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)L, (int)r, (int)n, 1.0,
                pw->weights, (int)n, z, (int)n, 0.0, cf, (int)L);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)L, (int)r, (int)n, -1.0,
                pw->weights, (int)n, e, (int)n, 1.0, cf, (int)L);
    for (int64_t b0 = 0; b0 <= B; b0 += batch) {
        int64_t nb = B + 1 - b0 < batch ? B + 1 - b0 : batch;
        for (int64_t k = 0; k < nb; k++) {
            if (b0 + k == 0) for (int64_t i = 0; i < n; i++) perm[i] = i;
            else es__perm_next(&g, perm);
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
            pair_stats(L, r, ak, L * batch, pw->slopes, vals + (b0 + k) * nstat,
                       b0 + k == 0 ? cosine : NULL);
        }
        if ((rc = es__progress(ctx, "pairwise: permutations", b0 + nb - 1, B))) goto done;
    }
done:
    es__perm_clear(ctx, &g);
    es__free(ctx, ur);
    es__free(ctx, e);
    es__free(ctx, cf);
    es__free(ctx, w);
    es__free(ctx, a);
    es__free(ctx, perm);
    return rc;
}

/* Symmetric L x L matrices of statistic block s (np pairs) from vals: the
 * observed value, and p, Z, UCL over the B + 1 values. */
static es_status summarize(es_ctx *ctx, const es_model_pairwise *pw, const double *vals,
                           int64_t nstat, int64_t s, int64_t B, double *obs, double *p,
                           double *z, double *ucl)
{
    const int64_t L = pw->nlevels, np = L * (L - 1) / 2;
    double *col = es__alloc_array(ctx, B + 1, sizeof *col);
    if (!col) return ES_ENOMEM;
    es_status rc = ES_OK;
    for (int64_t x = 0; x < L * L; x++) obs[x] = 0, p[x] = 1, z[x] = ucl[x] = NAN;
    int64_t k = 0;
    for (int64_t i = 0; i < L && rc == ES_OK; i++)
        for (int64_t j = i + 1; j < L && rc == ES_OK; j++, k++) {
            for (int64_t b = 0; b <= B; b++) col[b] = vals[b * nstat + s * np + k];
            double pv = NAN, zv = NAN, uv = NAN;
            if (B > 0) rc = es__perm_summary(ctx, col, B + 1, pw->confidence, &pv, &zv, &uv);
            obs[i + j * L] = obs[j + i * L] = col[0];
            p[i + j * L] = p[j + i * L] = pv;
            z[i + j * L] = z[j + i * L] = zv;
            ucl[i + j * L] = ucl[j + i * L] = uv;
        }
    es__free(ctx, col);
    return rc;
}

/* Find variable `name` of d (its label), or -1. */
static int64_t find_var(const es_design *d, const char *name)
{
    for (int64_t u = 0; name && u < d->nvars; u++)
        if (!strcmp(d->vars[u], name)) return u;
    return -1;
}

/* Check the request and choose the null model's terms (use). */
static es_status check_request(es_ctx *ctx, const es_model *m, const char *var, int64_t v,
                               int64_t u, const char *cov, int *use)
{
    const es_design *d = m->design;
    const int64_t T = d->nterms;
    const char *why = es_design_dropped(d, var);
    if (why) ES_FAIL(ctx, ES_EINVAL, "pairwise: '%s' %s and was left out of the model: compare "
                     "the levels of what it duplicates", var, why);
    if (v < 0 || !d->var_factor[v])
        ES_FAIL(ctx, v < 0 ? ES_ENOTFOUND : ES_EINVAL, "pairwise: '%s' is not a %s of the model",
                var, v < 0 ? "variable" : "categorical variable");
    for (int64_t w = 0; w < d->nvars; w++)
        if (nested_in(d, v, w))
            ES_FAIL(ctx, ES_EINVAL, "pairwise: '%s' is nested in '%s' (every term holding it "
                    "holds '%s'): its levels are not the same things under each level of "
                    "'%s'; compare the levels of '%s'", var, d->vars[w], d->vars[w], d->vars[w],
                    d->vars[w]);
    if (!cov) {
        for (int64_t t = 0; t < T; t++) use[t] = !d->term_vars[t + v * T];
        return ES_OK;
    }
    if (u < 0 || d->var_factor[u])
        ES_FAIL(ctx, u < 0 ? ES_ENOTFOUND : ES_EINVAL, "pairwise: the covariate '%s' is not a "
                "numeric variable of the model", cov);
    int inter = 0;
    for (int64_t t = 0; t < T; t++) {
        const int both = d->term_vars[t + v * T] && d->term_vars[t + u * T];
        use[t] = !both;
        inter |= both;
    }
    if (!inter)
        ES_FAIL(ctx, ES_EINVAL, "pairwise: the model has no interaction of '%s' with '%s': its "
                "slopes are equal by construction (write ~ %s * %s)", cov, var, cov, var);
    return ES_OK;
}

es_status es_model_pairwise_fit(es_ctx *ctx, const es_model *m, const char *var,
                                const es_model_pairwise_opts *opts, es_model_pairwise **out)
{
    es_model_pairwise_opts o;
    *out = NULL;
    if (opts) o = *opts;
    else es_model_pairwise_opts_init(&o);
    if (!m || !var) ES_FAIL(ctx, ES_EINVAL, "pairwise: no model or no factor");
    if (!(o.confidence > 0 && o.confidence < 1))
        ES_FAIL(ctx, ES_EINVAL, "pairwise: confidence %g is not in (0, 1)", o.confidence);
    const es_design *d = m->design;
    const int64_t v = find_var(d, var), u = find_var(d, o.covariate);
    int *use = es__alloc_array(ctx, d->nterms > 0 ? d->nterms : 1, sizeof *use);
    if (!use) return ES_ENOMEM;
    es_status rc = check_request(ctx, m, var, v, u, o.covariate, use);
    if (rc != ES_OK) {
        es__free(ctx, use);
        return rc;
    }
    const int64_t n = m->n, p = m->p, r = m->priv->r, L = d->nlevels[v], B = m->permutations;
    const int64_t V = d->nvars, np = L * (L - 1) / 2, nstat = (o.covariate ? 3 : 1) * np;
    es_model_pairwise *pw = es__calloc(ctx, 1, sizeof *pw);
    double *g = es__alloc_array(ctx, d->ncols + n + m->rank, sizeof *g);
    double *cz = es__alloc_array(ctx, L * r, sizeof *cz);
    double *vals = es__alloc_array(ctx, (B + 1) * (nstat > 0 ? nstat : 1), sizeof *vals);
    double *cosine = es__alloc_array(ctx, np > 0 ? np : 1, sizeof *cosine);
    int64_t maxl = 1;
    for (int64_t w = 0; w < V; w++)
        if (d->nlevels[w] > maxl) maxl = d->nlevels[w];
    unsigned char *seen = es__alloc_array(ctx, V * maxl, 1);
    if (pw) pw->ctx = ctx;
    if (!pw || !g || !cz || !vals || !cosine || !seen) {
        rc = ES_ENOMEM;
        goto done;
    }
    pw->nlevels = L;
    pw->p = p;
    pw->n = n;
    pw->nvars = V;
    pw->slopes = o.covariate != NULL;
    pw->confidence = o.confidence;
    double **mats[] = {&pw->dist, &pw->pval, &pw->z, &pw->ucl, &pw->vcor, &pw->angle,
                       &pw->angle_p, &pw->angle_z, &pw->angle_ucl, &pw->dlength, &pw->dlength_p,
                       &pw->dlength_z, &pw->dlength_ucl};
    for (size_t k = 0; k < (pw->slopes ? 13u : 4u); k++)
        if (!(*mats[k] = es__alloc_array(ctx, L * L, sizeof **mats[k]))) rc = ES_ENOMEM;
    pw->levels = es__calloc(ctx, (size_t)L, sizeof *pw->levels);
    pw->at = es__alloc_array(ctx, V, sizeof *pw->at);
    pw->lsmeans = es__alloc_array(ctx, L * p, sizeof *pw->lsmeans);
    pw->weights = es__alloc_array(ctx, n * L, sizeof *pw->weights);
    if (rc != ES_OK || !pw->levels || !pw->at || !pw->lsmeans || !pw->weights) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t w = 0; w < V; w++) {
        double s = 0;
        for (int64_t i = 0; i < n; i++) s += d->values[i + w * n];
        pw->at[w] = d->var_factor[w] || w == u ? NAN
                    : o.at && !isnan(o.at[w]) ? o.at[w] : s / (double)n;
    }
    for (int64_t l = 0; l < L && rc == ES_OK; l++) {
        if (!(pw->levels[l] = es__strdup(ctx, d->levels[v][l]))) rc = ES_ENOMEM;
        else if (pw->slopes)
            rc = slope_weights(ctx, m, v, l, d->values + u * n, g, pw->weights + l * n);
        else {
            nested_levels(d, v, l, maxl, seen);
            grid_row(d, v, l, pw->at, seen, g);
            grid_weights(m, g, g + d->ncols, pw->weights + l * n);
        }
    }
    if (rc != ES_OK) goto done;
    /* the compared vectors in the response: C^T Z U^T (+ the mean for LS means) */
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)L, (int)r, (int)n, 1.0,
                pw->weights, (int)n, m->priv->pca->scores, (int)n, 0.0, cz, (int)L);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, (int)L, (int)p, (int)r, 1.0, cz,
                (int)L, m->priv->pca->components, (int)p, 0.0, pw->lsmeans, (int)L);
    for (int64_t e = 0; e < p && !pw->slopes; e++)
        for (int64_t l = 0; l < L; l++) pw->lsmeans[l + e * L] += m->mean[e];
    if (B > 0) {
        if ((rc = permute(ctx, m, use, pw, nstat, vals, cosine)) != ES_OK) goto done;
    } else {
        pair_stats(L, r, cz, L, pw->slopes, vals, cosine);
    }
    if ((rc = summarize(ctx, pw, vals, nstat, 0, B, pw->dist, pw->pval, pw->z, pw->ucl)) != ES_OK)
        goto done;
    if (pw->slopes) {
        if ((rc = summarize(ctx, pw, vals, nstat, 1, B, pw->angle, pw->angle_p, pw->angle_z,
                            pw->angle_ucl)) != ES_OK ||
            (rc = summarize(ctx, pw, vals, nstat, 2, B, pw->dlength, pw->dlength_p,
                            pw->dlength_z, pw->dlength_ucl)) != ES_OK)
            goto done;
        for (int64_t x = 0; x < L * L; x++) pw->vcor[x] = 1;
        for (int64_t i = 0, k = 0; i < L; i++)
            for (int64_t j = i + 1; j < L; j++, k++)
                pw->vcor[i + j * L] = pw->vcor[j + i * L] = cosine[k];
    }
    *out = pw;
    pw = NULL;
done:
    es_model_pairwise_free(pw);
    es__free(ctx, use);
    es__free(ctx, g);
    es__free(ctx, cz);
    es__free(ctx, vals);
    es__free(ctx, cosine);
    es__free(ctx, seen);
    return rc;
}
