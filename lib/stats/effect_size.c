/* lib/stats/effect_size.c — what a permutation distribution says beyond its
 * p-value: RRPP's effect size Z and upper confidence limit, so that tables
 * read like lm.rrpp's and pairwise's.
 *
 * effect.size (RRPP 2.0, shared.support.code.r; Collyer & Adams 2018,
 * Adams & Collyer 2016): the observed statistic and its permutation values
 * are Box-Cox transformed with the lambda that maximizes the profile
 * log-likelihood of the permutation values alone (MASS::boxcox's, with the
 * Jacobian folded in by dividing by their geometric mean), found by R's
 * optimise on [-5, 5] (Brent's fmin, tolerance eps^0.25, below written as
 * R's Brent_fmin in src/library/stats/src/optimize.c so the same lambda is
 * found), then standardized with the divisor n. Sums use long double as R's
 * sum and mean do, and mean makes R's second pass.
 */
#include "stats/stats_pkg.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TIE_EPS 1.4901161193847656e-08
#define LAMBDA_EPS 0.001

/* R's mean(x): long double sum, then a correction pass. */
static double r_mean(const double *x, int64_t n)
{
    long double s = 0;
    for (int64_t i = 0; i < n; i++) s += x[i];
    s /= (long double)n;
    if (isfinite((double)s)) {
        long double t = 0;
        for (int64_t i = 0; i < n; i++) t += x[i] - s;
        s += t / (long double)n;
    }
    return (double)s;
}

typedef struct boxcox {
    int64_t n;
    const double *logy;   /* log(y / geometric mean), n */
    const double *yy;     /* y / geometric mean, n */
    double *t;            /* work, n */
} boxcox;

/* Minus the profile log-likelihood of lambda (optimise minimizes -f). */
static double neg_loglik(double la, const boxcox *b)
{
    for (int64_t i = 0; i < b->n; i++) {
        const double lg = b->logy[i];
        b->t[i] = fabs(la) > LAMBDA_EPS
                      ? (pow(b->yy[i], la) - 1) / la
                      : lg * (1 + (la * lg) / 2 * (1 + (la * lg) / 3 * (1 + (la * lg) / 4)));
    }
    const double m = r_mean(b->t, b->n);
    long double ss = 0;
    for (int64_t i = 0; i < b->n; i++) ss += (b->t[i] - m) * (b->t[i] - m);
    return -(-(double)b->n / 2 * log((double)ss));
}

/* R's Brent_fmin (optimize.c), step for step. */
static double brent_fmin(double ax, double bx, const boxcox *bc, double tol)
{
    const double c = (3. - sqrt(5.)) * .5;
    double a = ax, b = bx, d = 0., e = 0., p, q, r, u, v, w, x, t2, fu, fv, fw, fx, xm, tol1, tol3;
    const double eps = sqrt(DBL_EPSILON);
    v = a + c * (b - a);
    w = v;
    x = v;
    fx = neg_loglik(x, bc);
    fv = fx;
    fw = fx;
    tol3 = tol / 3.;
    for (;;) {
        xm = (a + b) * .5;
        tol1 = eps * fabs(x) + tol3;
        t2 = tol1 * 2.;
        if (fabs(x - xm) <= t2 - (b - a) * .5) break;
        p = 0.;
        q = 0.;
        r = 0.;
        if (fabs(e) > tol1) {   /* fit a parabola */
            r = (x - w) * (fx - fv);
            q = (x - v) * (fx - fw);
            p = (x - v) * q - (x - w) * r;
            q = (q - r) * 2.;
            if (q > 0.) p = -p;
            else q = -q;
            r = e;
            e = d;
        }
        if (fabs(p) >= fabs(q * .5 * r) || p <= q * (a - x) || p >= q * (b - x)) {
            e = x < xm ? b - x : a - x;   /* a golden-section step */
            d = c * e;
        } else {                          /* a parabolic-interpolation step */
            d = p / q;
            u = x + d;
            if (u - a < t2 || b - u < t2) {
                d = tol1;
                if (x >= xm) d = -d;
            }
        }
        if (fabs(d) >= tol1) u = x + d;
        else if (d > 0.) u = x + tol1;
        else u = x - tol1;
        fu = neg_loglik(u, bc);
        if (fu <= fx) {
            if (u < x) b = x;
            else a = x;
            v = w;
            w = x;
            x = u;
            fv = fw;
            fw = fx;
            fx = fu;
        } else {
            if (u < x) a = u;
            else b = u;
            if (fu <= fw || w == x) {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if (fu <= fv || v == x || v == w) {
                v = u;
                fv = fu;
            }
        }
    }
    return x;
}

es_status es_effect_size(es_ctx *ctx, const double *x, int64_t n, double *z)
{
    if (!x || !z || n < 1) ES_FAIL(ctx, ES_EINVAL, "effect size: no values");
    *z = NAN;
    double lo = x[0];
    int same = 1;
    for (int64_t i = 0; i < n; i++) {
        if (isnan(x[i])) return ES_OK;
        if (x[i] != x[0]) same = 0;
        if (x[i] < lo) lo = x[i];
    }
    if (same || n < 3) {
        *z = 0;
        return ES_OK;
    }
    double *y = es__alloc_array(ctx, 4 * n, sizeof *y);
    if (!y) return ES_ENOMEM;
    double *yy = y + n, *logy = y + 2 * n, *t = y + 3 * n;
    const double shift = lo <= 0 ? -lo + 0.0001 : 0;
    for (int64_t i = 0; i < n; i++) y[i] = x[i] + shift;
    /* lambda from the permutation values y[1..n) */
    const int64_t m = n - 1;
    for (int64_t i = 0; i < m; i++) logy[i] = log(y[i + 1]);
    const double gm = exp(r_mean(logy, m));
    for (int64_t i = 0; i < m; i++) {
        yy[i] = y[i + 1] / gm;
        logy[i] = log(yy[i]);
    }
    boxcox bc = {m, logy, yy, t};
    double la = brent_fmin(-5.0, 5.0, &bc, pow(DBL_EPSILON, 0.25));
    if (fabs(la) < LAMBDA_EPS) la = 0;
    for (int64_t i = 0; i < n; i++) t[i] = la == 0 ? log(y[i]) : (pow(y[i], la) - 1) / la;
    const double mt = r_mean(t, n);
    long double s2 = 0;
    for (int64_t i = 0; i < n; i++) {
        t[i] -= mt;
        s2 += (long double)t[i] * t[i];
    }
    const double sd = sqrt((double)(s2 / (long double)n));
    *z = (t[0] - r_mean(t, n)) / sd;
    es__free(ctx, y);
    return ES_OK;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

es_status es_quantile(es_ctx *ctx, const double *x, int64_t n, double prob, double *q)
{
    if (!x || !q || n < 0 || !(prob >= 0 && prob <= 1))
        ES_FAIL(ctx, ES_EINVAL, "quantile: bad arguments (probability %g)", prob);
    *q = NAN;
    double *s = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *s);
    if (!s) return ES_ENOMEM;
    int64_t k = 0;
    for (int64_t i = 0; i < n; i++)
        if (!isnan(x[i])) s[k++] = x[i];
    if (k > 0) {
        qsort(s, (size_t)k, sizeof *s, cmp_double);
        /* R's 1-based index = 1 + (n - 1) p; (1 - h) x[lo] + h x[hi] */
        const double index = 1 + (double)(k - 1) * prob, flo = floor(index);
        const int64_t lo = (int64_t)flo - 1, hi = (int64_t)ceil(index) - 1;
        const double h = index - flo;
        *q = index > flo && s[hi] != s[lo] ? (1 - h) * s[lo] + h * s[hi] : s[lo];
    }
    es__free(ctx, s);
    return ES_OK;
}

es_status es__perm_summary(es_ctx *ctx, const double *s, int64_t n, double confidence,
                           double *p, double *z, double *ucl)
{
    es_status rc = ES_OK;
    if (p) {
        int64_t count = 0;
        for (int64_t b = 0; b < n; b++)
            if (s[b] >= s[0] - TIE_EPS * fmax(1.0, fabs(s[0]))) count++;
        *p = isnan(s[0]) ? NAN : (double)count / (double)n;
    }
    if (z && (rc = es_effect_size(ctx, s, n, z)) != ES_OK) return rc;
    if (ucl) rc = es_quantile(ctx, s, n, confidence, ucl);
    return rc;
}
