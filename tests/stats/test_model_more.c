/* tests/stats/test_model_more.c — what es_model.h adds after the ANOVA
 * table, each against an independent computation written here in the
 * response's own space (least squares by the normal equations, no principal
 * coordinates, no Gram-Schmidt) or against values R printed:
 *  - es_effect_size and es_quantile against R (RRPP 2.0's effect.size
 *    written with R's optimise, quantile(type = 7));
 *  - aliased terms: a copy of a factor under other labels, a sum of two
 *    covariates and a constant left out and named; type III after the copy
 *    is gone keeps the factor's test; a type III term held by an
 *    interaction and an exact fit refused; --reference puts a level first;
 *  - the CAC: the same under ~ w + A and ~ w * A, and the pooled
 *    within-group regression computed naively;
 *  - error terms: F = MS_j / MS_e and each permutation's the same ratio;
 *  - per-landmark (grouped) tests: F of a group from the naive SS and RSS;
 *  - two models compared: F of the extra sum of squares, and its
 *    permutations against the naive refit of the permuted null model;
 *  - pairwise slopes: each level's slope of the fitted values, their
 *    distances, angles and length differences; LS means at a given value;
 *  - an allocation-failure sweep over all of them.
 */
#include "es_test.h"
#include "es_test_alloc.h"
#include "core/core_private.h"
#include "edgespace/es_model.h"

enum { N = 30, P = 6 };

/* Fitted values of y (n x p) on x (n x k) by the normal equations. */
static void fit(int n, int k, const double *x, int p, const double *y, double *out)
{
    double a[64 * 64] = {0}, b[64 * 16] = {0};
    for (int i = 0; i < k; i++)
        for (int j = 0; j < k; j++)
            for (int r = 0; r < n; r++) a[i + j * k] += x[r + i * n] * x[r + j * n];
    for (int i = 0; i < k; i++)
        for (int c = 0; c < p; c++)
            for (int r = 0; r < n; r++) b[i + c * k] += x[r + i * n] * y[r + c * n];
    for (int j = 0; j < k; j++) {   /* Gauss-Jordan, a is SPD */
        double d = a[j + j * k];
        for (int c = 0; c < k; c++) a[j + c * k] /= d;
        for (int c = 0; c < p; c++) b[j + c * k] /= d;
        for (int i = 0; i < k; i++) {
            if (i == j) continue;
            double f = a[i + j * k];
            for (int c = 0; c < k; c++) a[i + c * k] -= f * a[j + c * k];
            for (int c = 0; c < p; c++) b[i + c * k] -= f * b[j + c * k];
        }
    }
    for (int r = 0; r < n; r++)
        for (int c = 0; c < p; c++) {
            double s = 0;
            for (int i = 0; i < k; i++) s += x[r + i * n] * b[i + c * k];
            out[r + c * n] = s;
        }
}

/* Residual sum of squares of y on the columns x (n x k), per variable (rss
 * p entries) and in total (returned). */
static double rss_of(int n, int k, const double *x, int p, const double *y, double *rss)
{
    double f[N * 16], t = 0;
    fit(n, k, x, p, y, f);
    for (int c = 0; c < p; c++) {
        double s = 0;
        for (int r = 0; r < n; r++) s += (y[r + c * n] - f[r + c * n]) * (y[r + c * n] - f[r + c * n]);
        if (rss) rss[c] = s;
        t += s;
    }
    return t;
}

/* The data: group A (3 levels, unequal), covariate w with a slope per
 * level, B (2 levels) nested in A, response Y (N x P, column-major). */
typedef struct data {
    const char *a[N], *b[N], *acopy[N], *ab[N], *coarse[N];
    double w[N], w2[N], ws[N], y[N * P], yt[N * P];
    char wl[N][32], w2l[N][32], wsl[N][32];
} data;

static void make(data *d)
{
    static const char *al[3] = {"a1", "a2", "a3"}, *cl[3] = {"x", "y", "z"};
    static const char *ab[6] = {"a1b1", "a1b2", "a2b1", "a2b2", "a3b1", "a3b2"};
    es_rng rng;
    es_rng_init(&rng, 9);
    for (int i = 0; i < N; i++) {
        int g = i < 12 ? 0 : i < 21 ? 1 : 2, h = i % 2;
        d->a[i] = al[g];
        d->acopy[i] = cl[2 - g];
        d->b[i] = h ? "b2" : "b1";
        d->ab[i] = ab[2 * g + h];
        d->coarse[i] = g == 0 ? "c1" : "c2";
        d->w[i] = 1 + 0.1 * i + 0.3 * es_rng_normal(&rng);
        d->w2[i] = 0.5 + es_rng_normal(&rng);
        d->ws[i] = d->w[i] + d->w2[i];
        snprintf(d->wl[i], 32, "%.17g", d->w[i]);
        snprintf(d->w2l[i], 32, "%.17g", d->w2[i]);
        snprintf(d->wsl[i], 32, "%.17g", d->ws[i]);
        for (int e = 0; e < P; e++)
            d->y[i + e * N] = 0.3 * g * (e % 3) + (0.2 + 0.15 * g * (e == 1)) * d->w[i] * (e + 1) +
                              0.1 * h * (e == 4) + 0.05 * d->w2[i] + 0.2 * es_rng_normal(&rng);
    }
    for (int i = 0; i < N; i++)
        for (int e = 0; e < P; e++) d->yt[e + i * P] = d->y[i + e * N];
}

static es_design *design(es_ctx *ctx, const char *formula, const es_model_column *cols, int nc)
{
    es_formula *f = NULL;
    es_design *d = NULL;
    ES_CHECK_OK(ctx, es_formula_parse(ctx, formula, &f));
    if (f) ES_CHECK_OK(ctx, es_design_build(ctx, f, N, cols, nc, ES_CONTRASTS_TREATMENT, &d));
    es_formula_free(f);
    return d;
}

static es_model *fitm(es_ctx *ctx, const es_design *d, const data *x, int64_t B,
                      const int64_t *error, es_ss_type type)
{
    es_source src = es_source_matrix((es_mat){(double *)x->yt, P, N, P}, NULL, 0);
    es_model_opts o;
    es_model_opts_init(&o);
    o.permutations = B;
    o.error = error;
    o.ss_type = type;
    o.seed = 5;
    es_model *m = NULL;
    if (d) ES_CHECK_OK(ctx, es_model_fit(ctx, d, &src, &o, &m));
    return m;
}

static void test_effect_size(es_ctx *ctx)
{
    /* R: zscore(x) with RRPP 2.0.2's box.cox and optimise; quantile(x, 0.95) */
    const double x1[10] = {5.5, 1.2, 0.8, 2.3, 1.9, 0.4, 1.1, 3.2, 0.9, 1.5};
    const double x2[9] = {-0.3, 0.5, -1.2, 0.8, 0.1, -0.6, 1.9, -2.2, 0.05};
    double x3[41], z = 0, q = 0;
    x3[0] = 2;
    for (int i = 1; i <= 40; i++) x3[i] = i / 7.0;
    ES_CHECK_OK(ctx, es_effect_size(ctx, x1, 10, &z));
    ES_CHECK_CLOSE(z, 2.0389874737745846, 1e-10, 0);
    ES_CHECK_OK(ctx, es_quantile(ctx, x1, 10, 0.95, &q));
    ES_CHECK_CLOSE(q, 4.4649999999999981, 1e-14, 0);
    ES_CHECK_OK(ctx, es_effect_size(ctx, x2, 9, &z));   /* shifted: values <= 0 */
    ES_CHECK_CLOSE(z, 0.045669261646623813, 1e-9, 0);
    ES_CHECK_OK(ctx, es_quantile(ctx, x2, 9, 0.95, &q));
    ES_CHECK_CLOSE(q, 1.4599999999999995, 1e-14, 0);
    ES_CHECK_OK(ctx, es_effect_size(ctx, x3, 41, &z));
    ES_CHECK_CLOSE(z, -0.46300597097779533, 1e-10, 0);
    ES_CHECK_OK(ctx, es_quantile(ctx, x3, 41, 0.95, &q));
    ES_CHECK_CLOSE(q, 5.4285714285714288, 1e-14, 0);
    const double same[4] = {2, 2, 2, 2}, withnan[3] = {1, NAN, 2};
    ES_CHECK_OK(ctx, es_effect_size(ctx, same, 4, &z));
    ES_CHECK(z == 0);
    ES_CHECK_OK(ctx, es_effect_size(ctx, withnan, 3, &z));
    ES_CHECK(isnan(z));
    ES_CHECK_FAILS(ctx, es_quantile(ctx, x1, 10, 1.5, &q), ES_EINVAL, "probability 1.5");
}

static void test_aliased(es_ctx *ctx, const data *x)
{
    es_model_column cols[5] = {{"A", x->a, NULL, NULL}, {"Acopy", x->acopy, NULL, NULL},
                               {"w", (const char **)NULL, x->w, NULL},
                               {"w2", NULL, x->w2, NULL}, {"ws", NULL, x->ws, NULL}};
    es_design *d = design(ctx, "~ A + Acopy", cols, 5);
    if (d) {
        ES_CHECK(d->nterms == 1 && d->ndropped == 1 && !strcmp(d->dropped[0], "Acopy") &&
                 !strcmp(d->dropped_why[0], "duplicates 'A'"));
        ES_CHECK(!strcmp(es_design_dropped(d, "Acopy"), "duplicates 'A'"));
        /* type III: A keeps its test once the copy is gone */
        es_model *m = fitm(ctx, d, x, 19, NULL, ES_SS_TYPE_III);
        if (m) {
            ES_CHECK(m->nterms == 1 && m->df[0] == 2 && !isnan(m->pval[0]) && !isnan(m->z[0]));
            ES_CHECK_FAILS(ctx, es_model_pairwise_fit(ctx, m, "Acopy", NULL, &(es_model_pairwise *){NULL}),
                           ES_EINVAL, "'Acopy' duplicates 'A'");
            double f[P], p[P], q[P];
            ES_CHECK_FAILS(ctx, es_model_variable_tests(ctx, m, "Acopy", 9, f, p, q), ES_EINVAL,
                           "duplicates 'A'");
        }
        es_model_free(m);
    }
    es_design_free(d);
    d = design(ctx, "~ w + w2 + ws", cols, 5);
    if (d) ES_CHECK(d->ndropped == 1 && !strcmp(d->dropped_why[0], "is a combination of 'w', 'w2'"));
    es_design_free(d);
    double one[N];
    for (int i = 0; i < N; i++) one[i] = 3;
    es_model_column c1[2] = {{"A", x->a, NULL, NULL}, {"k", NULL, one, NULL}};
    d = design(ctx, "~ A + k", c1, 2);
    if (d) ES_CHECK(d->ndropped == 1 && strstr(d->dropped_why[0], "constant"));
    es_design_free(d);
    /* C merges two levels of A: after A (type III) it adds nothing */
    es_model_column cc[2] = {{"A", x->a, NULL, NULL}, {"C", x->coarse, NULL, NULL}};
    d = design(ctx, "~ C + A", cc, 2);
    if (d) {
        es_source src = es_source_matrix((es_mat){(double *)x->yt, P, N, P}, NULL, 0);
        es_model_opts o;
        es_model_opts_init(&o);
        o.ss_type = ES_SS_TYPE_III;
        es_model *m = NULL;
        ES_CHECK_FAILS(ctx, es_model_fit(ctx, d, &src, &o, &m), ES_EINVAL,
                       "type III sums of squares the term 'C' adds nothing");
        /* an error term that is the term itself */
        int64_t err[2] = {0, -1};
        o.ss_type = ES_SS_TYPE_I;
        o.error = err;
        ES_CHECK_FAILS(ctx, es_model_fit(ctx, d, &src, &o, &m), ES_EINVAL, "the term itself");
    }
    es_design_free(d);
    /* a reference level first; an unknown one listed */
    es_model_column cr[1] = {{"A", x->a, NULL, "a3"}};
    d = design(ctx, "~ A", cr, 1);
    if (d) ES_CHECK(!strcmp(d->levels[0][0], "a3") && !strcmp(d->colnames[1], "A=a1") &&
                    d->x[0 + 1 * N] == 1 && d->x[N - 1 + 1 * N] == 0);
    es_design_free(d);
    cr[0].reference = "a9";
    es_formula *f = NULL;
    es_design *bad = NULL;
    ES_CHECK_OK(ctx, es_formula_parse(ctx, "~ A", &f));
    ES_CHECK_FAILS(ctx, es_design_build(ctx, f, N, cr, 1, 0, &bad), ES_EINVAL,
                   "'a9' is not a level of 'A' (its levels: a1, a2, a3)");
    es_formula_free(f);
}

static void test_cac(es_ctx *ctx, const data *x)
{
    es_model_column cols[2] = {{"A", x->a, NULL, NULL}, {"w", NULL, x->w, NULL}};
    es_design *d1 = design(ctx, "~ w + A", cols, 2), *d2 = design(ctx, "~ w * A", cols, 2);
    es_model *m1 = fitm(ctx, d1, x, 0, NULL, ES_SS_TYPE_I), *m2 = fitm(ctx, d2, x, 0, NULL,
                                                                        ES_SS_TYPE_I);
    double c1[P], c2[P], s1[N], s2[N];
    if (m1 && m2) {
        ES_CHECK_OK(ctx, es_model_cac(ctx, m1, "w", c1, s1));
        ES_CHECK_OK(ctx, es_model_cac(ctx, m2, "w", c2, s2));
        double sc = 0;
        for (int i = 0; i < N; i++) sc = fmax(sc, fabs(s1[i]));
        for (int i = 0; i < N; i++) ES_CHECK_CLOSE(s2[i], s1[i], 0, 1e-12 * sc);
        /* naive: the slope of y on w after the group means, as a unit vector */
        double xa[N * 4], r[N], b[P] = {0}, nb = 0;
        for (int i = 0; i < N; i++) {
            xa[i] = 1;
            xa[i + N] = !strcmp(x->a[i], "a2");
            xa[i + 2 * N] = !strcmp(x->a[i], "a3");
        }
        fit(N, 3, xa, 1, x->w, r);
        for (int i = 0; i < N; i++) r[i] = x->w[i] - r[i];
        for (int e = 0; e < P; e++) {
            for (int i = 0; i < N; i++) b[e] += r[i] * x->y[i + e * N];
            nb += b[e] * b[e];
        }
        for (int e = 0; e < P; e++) ES_CHECK_CLOSE(c2[e], b[e] / sqrt(nb), 0, 1e-12);
        /* the interaction model's own coefficient of w (a1's slope) is not it */
        double dot = 0, nc = 0;
        for (int e = 0; e < P; e++) {
            dot += m2->coef[1 + e * m2->ncoef] * c2[e];
            nc += m2->coef[1 + e * m2->ncoef] * m2->coef[1 + e * m2->ncoef];
        }
        ES_CHECK_MSG(dot / sqrt(nc) < 0.9999, "cosine %g", dot / sqrt(nc));
    }
    es_model_free(m1);
    es_model_free(m2);
    es_design_free(d1);
    es_design_free(d2);
}

static void test_error_groups_compare(es_ctx *ctx, const data *x)
{
    es_model_column cols[3] = {{"A", x->a, NULL, NULL}, {"B", x->b, NULL, NULL},
                               {"w", NULL, x->w, NULL}};
    es_design *d = design(ctx, "~ A + A:B", cols, 3);
    int64_t err[2] = {1, -1};
    es_model *m = fitm(ctx, d, x, 49, err, ES_SS_TYPE_I), *m0 = fitm(ctx, d, x, 49, NULL,
                                                                     ES_SS_TYPE_I);
    if (m && m0) {
        ES_CHECK(m->error[0] == 1 && m->error[1] == -1);
        ES_CHECK_CLOSE(m->f[0], m->ms[0] / m->ms[1], 1e-14, 0);
        ES_CHECK_CLOSE(m->f[1], m0->f[1], 1e-14, 0);
        for (int b = 0; b < 49; b++)
            ES_CHECK_CLOSE(m->fperm[b], (m->ssperm[b] / 2) / (m->ssperm[b + 49] / 3), 1e-12, 0);
        /* the error term's permuted SS is its own RRPP stream, the same as without it */
        for (int b = 0; b < 49; b++) ES_CHECK_CLOSE(m->ssperm[b + 49], m0->ssperm[b + 49], 1e-12, 0);
        /* grouped tests: variables {0,1,2} and {3,4,5} */
        int64_t grp[P] = {0, 0, 0, 1, 1, 1};
        double f[2], p[2], q[2], rr[P], rf[P];
        double xr[N * 3], xf[N * 6];
        ES_CHECK_OK(ctx, es_model_group_tests(ctx, m0, "A", 19, 2, grp, f, p, q));
        for (int c = 0; c < 6; c++)
            for (int i = 0; i < N; i++) xf[i + c * N] = d->x[i + c * N];
        memcpy(xr, d->x, sizeof(double) * N);
        rss_of(N, 1, xr, P, x->y, rr);
        rss_of(N, 6, xf, P, x->y, rf);
        /* A's SS = RSS(1) - RSS(1 + A); RSS of the full model */
        double xa[N * 3];
        memcpy(xa, d->x, sizeof(double) * N * 3);
        double ra[P];
        rss_of(N, 3, xa, P, x->y, ra);
        for (int g = 0; g < 2; g++) {
            double ss = 0, e = 0;
            for (int k = 3 * g; k < 3 * g + 3; k++) ss += rr[k] - ra[k], e += rf[k];
            ES_CHECK_CLOSE(f[g], (ss / 2) / (e / (N - 6)), 1e-10, 0);
            ES_CHECK(p[g] > 0 && p[g] <= 1 && q[g] >= p[g]);
        }
        ES_CHECK_FAILS(ctx, es_model_group_tests(ctx, m0, "A", 9, 2, (int64_t[P]){0, 0, 0, 1, 1, 2},
                                                 f, p, q), ES_EINVAL, "group 2");
    }
    /* two models: ~ w against ~ w * A */
    es_design *d0 = design(ctx, "~ w", cols, 3), *d1 = design(ctx, "~ w * A", cols, 3);
    es_model *n0 = fitm(ctx, d0, x, 0, NULL, ES_SS_TYPE_I), *n1 = fitm(ctx, d1, x, 29, NULL,
                                                                       ES_SS_TYPE_I);
    es_model_comparison *c = NULL;
    if (n0 && n1) {
        ES_CHECK_OK(ctx, es_model_compare(ctx, n0, n1, &c));
        double x0[N * 2], x1[N * 6];
        memcpy(x0, d0->x, sizeof x0);
        memcpy(x1, d1->x, sizeof x1);
        const double r0 = rss_of(N, 2, x0, P, x->y, NULL), r1 = rss_of(N, 6, x1, P, x->y, NULL);
        if (c) {
            ES_CHECK(c->df == 4 && c->df_resid_full == N - 6);
            ES_CHECK_CLOSE(c->ss, r0 - r1, 1e-10, 0);
            ES_CHECK_CLOSE(c->f, ((r0 - r1) / 4) / (r1 / (N - 6)), 1e-10, 0);
            /* permutation 1 against the naive refit of the permuted null model */
            int64_t perm[N];
            ES_CHECK_OK(ctx, es_model_permutations(ctx, N, NULL, n1->seed, 1, perm));
            double f0[N * P], ys[N * P];
            fit(N, 2, x0, P, x->y, f0);
            for (int i = 0; i < N; i++)
                for (int e = 0; e < P; e++)
                    ys[i + e * N] = f0[i + e * N] + x->y[perm[i] + e * N] - f0[perm[i] + e * N];
            const double s0 = rss_of(N, 2, x0, P, ys, NULL), s1 = rss_of(N, 6, x1, P, ys, NULL);
            ES_CHECK_CLOSE(c->fperm[0], ((s0 - s1) / 4) / (s1 / (N - 6)), 1e-9, 0);
            ES_CHECK(c->pval > 0 && c->pval <= 1 && isfinite(c->z));
        }
        es_model_comparison_free(c);
        c = NULL;
        ES_CHECK_FAILS(ctx, es_model_compare(ctx, n1, n0, &c), ES_EINVAL, "nested");
    }
    es_model_free(n0);
    es_model_free(n1);
    es_design_free(d0);
    es_design_free(d1);
    es_model_free(m);
    es_model_free(m0);
    es_design_free(d);
}

static void test_slopes(es_ctx *ctx, const data *x)
{
    es_model_column cols[2] = {{"A", x->a, NULL, NULL}, {"w", NULL, x->w, NULL}};
    es_design *d = design(ctx, "~ w * A", cols, 2), *da = design(ctx, "~ w + A", cols, 2);
    es_model *m = fitm(ctx, d, x, 29, NULL, ES_SS_TYPE_I), *ma = fitm(ctx, da, x, 9, NULL,
                                                                      ES_SS_TYPE_I);
    es_model_pairwise *pw = NULL;
    es_model_pairwise_opts o;
    es_model_pairwise_opts_init(&o);
    o.covariate = "w";
    if (m) {
        ES_CHECK_OK(ctx, es_model_pairwise_fit(ctx, m, "A", &o, &pw));
        /* naive: per level, the slope of the fitted values (here: of y, the
         * model being saturated in w * A) on w */
        double s[3][P] = {{0}}, len[3] = {0};
        for (int g = 0; g < 3; g++) {
            const char *lv = g == 0 ? "a1" : g == 1 ? "a2" : "a3";
            double mw = 0, cnt = 0, sxx = 0;
            for (int i = 0; i < N; i++)
                if (!strcmp(x->a[i], lv)) mw += x->w[i], cnt++;
            mw /= cnt;
            for (int i = 0; i < N; i++)
                if (!strcmp(x->a[i], lv)) sxx += (x->w[i] - mw) * (x->w[i] - mw);
            for (int e = 0; e < P; e++) {
                for (int i = 0; i < N; i++)
                    if (!strcmp(x->a[i], lv)) s[g][e] += (x->w[i] - mw) * x->y[i + e * N] / sxx;
                len[g] += s[g][e] * s[g][e];
            }
            len[g] = sqrt(len[g]);
        }
        for (int a = 0; pw && a < 3; a++)
            for (int b = a + 1; b < 3; b++) {
                double dd = 0, dot = 0;
                for (int e = 0; e < P; e++) {
                    dd += (s[a][e] - s[b][e]) * (s[a][e] - s[b][e]);
                    dot += s[a][e] * s[b][e];
                }
                ES_CHECK_CLOSE(pw->dist[a + 3 * b], sqrt(dd), 1e-10, 0);
                ES_CHECK_CLOSE(pw->vcor[a + 3 * b], dot / (len[a] * len[b]), 1e-10, 0);
                ES_CHECK_CLOSE(pw->angle[a + 3 * b], acos(dot / (len[a] * len[b])), 1e-9, 0);
                ES_CHECK_CLOSE(pw->dlength[a + 3 * b], fabs(len[a] - len[b]), 1e-9, 1e-14);
                ES_CHECK(pw->pval[a + 3 * b] > 0 && isfinite(pw->z[a + 3 * b]) &&
                         pw->ucl[a + 3 * b] > 0);
            }
        for (int e = 0; pw && e < P; e++) ES_CHECK_CLOSE(pw->lsmeans[1 + 3 * e], s[1][e], 1e-10, 1e-14);
        es_model_pairwise_free(pw);
        pw = NULL;
        /* LS means at w = 2: intercepts + 2 slopes, a1 - a2 from the coefficients */
        double at[2] = {2.0, NAN};   /* the design's variables: w, A */
        es_model_pairwise_opts_init(&o);
        o.at = at;
        ES_CHECK_OK(ctx, es_model_pairwise_fit(ctx, m, "A", &o, &pw));
        if (pw) {
            const int64_t q = m->ncoef;   /* intercept, w, A=a2, A=a3, w:A=a2, w:A=a3 */
            double dd = 0;
            for (int e = 0; e < P; e++) {
                double diff = m->coef[2 + e * q] + 2.0 * m->coef[4 + e * q];
                dd += diff * diff;
            }
            ES_CHECK_CLOSE(pw->dist[0 + 3 * 1], sqrt(dd), 1e-10, 0);
            ES_CHECK(pw->at[0] == 2.0 && isnan(pw->at[1]));
        }
        es_model_pairwise_free(pw);
        pw = NULL;
    }
    o.covariate = "w";
    o.at = NULL;
    if (ma) ES_CHECK_FAILS(ctx, es_model_pairwise_fit(ctx, ma, "A", &o, &pw), ES_EINVAL,
                           "equal by construction");
    o.covariate = "A";
    if (m) ES_CHECK_FAILS(ctx, es_model_pairwise_fit(ctx, m, "A", &o, &pw), ES_EINVAL,
                          "not a numeric variable");
    es_model_free(m);
    es_model_free(ma);
    es_design_free(d);
    es_design_free(da);
}

static void test_alloc_sweep(const data *x)
{
    es_model_column cols[2] = {{"A", x->a, NULL, NULL}, {"w", NULL, x->w, NULL}};
    es_status rc = ES_ENOMEM;
    int k;
    for (k = 1; k < 4000 && rc == ES_ENOMEM; k++) {
        es_ctx *ctx = NULL;
        es_ctx_new(&ctx);
        failing_alloc fa = {0, k, 0};
        es_allocator al = {fa_malloc, fa_realloc, fa_free, &fa};
        es_ctx_set_allocator(ctx, &al);
        es_formula *f = NULL, *f0 = NULL;
        es_design *d = NULL, *d0 = NULL;
        es_model *m = NULL, *m0 = NULL;
        es_model_pairwise *pw = NULL;
        es_model_comparison *c = NULL;
        es_model_pairwise_opts po;
        es_model_pairwise_opts_init(&po);
        po.covariate = "w";
        es_model_opts o;
        es_model_opts_init(&o);
        o.permutations = 5;
        int64_t grp[P] = {0, 1, 2, 0, 1, 2};
        double gf[3], gp[3], gq[3], cac[P], sc[N];
        es_source src = es_source_matrix((es_mat){(double *)x->yt, P, N, P}, NULL, 0);
        rc = es_formula_parse(ctx, "~ w * A + A", &f);
        if (rc == ES_OK) rc = es_formula_parse(ctx, "~ w + A", &f0);
        if (rc == ES_OK) rc = es_design_build(ctx, f, N, cols, 2, 0, &d);
        if (rc == ES_OK) rc = es_design_build(ctx, f0, N, cols, 2, 0, &d0);
        if (rc == ES_OK) rc = es_model_fit(ctx, d, &src, &o, &m);
        if (rc == ES_OK) rc = es_model_fit(ctx, d0, &src, &o, &m0);
        if (rc == ES_OK) rc = es_model_pairwise_fit(ctx, m, "A", &po, &pw);
        if (rc == ES_OK) rc = es_model_compare(ctx, m0, m, &c);
        if (rc == ES_OK) rc = es_model_group_tests(ctx, m, "A", 5, 3, grp, gf, gp, gq);
        if (rc == ES_OK) rc = es_model_cac(ctx, m, "w", cac, sc);
        ES_CHECK(rc == ES_OK || rc == ES_ENOMEM);
        es_model_comparison_free(c);
        es_model_pairwise_free(pw);
        es_model_free(m);
        es_model_free(m0);
        es_design_free(d);
        es_design_free(d0);
        es_formula_free(f);
        es_formula_free(f0);
        es_ctx_set_allocator(ctx, NULL);
        ES_CHECK_MSG(fa.live == 0, "allocation %d: %lld blocks leaked", k, (long long)fa.live);
        es_ctx_free(ctx);
    }
    ES_CHECK(rc == ES_OK && k > 10);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    static data x;
    make(&x);
    test_effect_size(ctx);
    test_aliased(ctx, &x);
    test_cac(ctx, &x);
    test_error_groups_compare(ctx, &x);
    test_slopes(ctx, &x);
    test_alloc_sweep(&x);
    es_ctx_free(ctx);
    ES_TEST_END();
}
