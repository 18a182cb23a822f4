/* lib/embed/lbfgs.c — the two-loop recursion of limited-memory BFGS
 * (Nocedal 1980; Nocedal & Wright, "Numerical Optimization", Alg. 7.4)
 * around an initial inverse Hessian the caller applies between the two
 * loops. The local-global solve uses its factored Laplacian there, which
 * makes the plain local-global step the first L-BFGS step (Liu, Bouaziz &
 * Kavan 2017, "Quasi-Newton methods for real-time simulation of
 * hyperelastic materials").
 */
#include "embed/embed_pkg.h"

#include <math.h>
#include <string.h>

es_status es__lbfgs_init(es_ctx *ctx, es__lbfgs *lb, int64_t n, int m)
{
    memset(lb, 0, sizeof *lb);
    if (m < 1) m = 1;
    if (m > ES__LBFGS_MAX) m = ES__LBFGS_MAX;
    lb->n = n;
    lb->m = m;
    lb->mem = es__alloc_array(ctx, (size_t)(2 * m) * (size_t)n + 1, sizeof(double));
    if (!lb->mem) return ES_ENOMEM;
    lb->s = lb->mem;
    lb->y = lb->mem + (size_t)m * (size_t)n;
    return ES_OK;
}

void es__lbfgs_free(es_ctx *ctx, es__lbfgs *lb)
{
    es__free(ctx, lb->mem);
    memset(lb, 0, sizeof *lb);
}

void es__lbfgs_reset(es__lbfgs *lb)
{
    lb->count = lb->head = 0;
}

/* the pairs from the newest (j = 0) to the oldest */
static int slot(const es__lbfgs *lb, int j)
{
    return (lb->head - 1 - j + 2 * lb->m) % lb->m;
}

void es__lbfgs_first(es__lbfgs *lb, double *q)
{
    int64_t n = lb->n;
    for (int j = 0; j < lb->count; j++) {
        int k = slot(lb, j);
        const double *s = lb->s + (size_t)k * (size_t)n, *y = lb->y + (size_t)k * (size_t)n;
        double a = lb->rho[k] * es__dot(s, q, n);
        lb->alpha[k] = a;
        for (int64_t i = 0; i < n; i++) q[i] -= a * y[i];
    }
}

void es__lbfgs_second(es__lbfgs *lb, double *d)
{
    int64_t n = lb->n;
    for (int j = lb->count - 1; j >= 0; j--) {
        int k = slot(lb, j);
        const double *s = lb->s + (size_t)k * (size_t)n, *y = lb->y + (size_t)k * (size_t)n;
        double b = lb->alpha[k] - lb->rho[k] * es__dot(y, d, n);
        for (int64_t i = 0; i < n; i++) d[i] += b * s[i];
    }
}

void es__lbfgs_push(es__lbfgs *lb, const double *x0, const double *x1, const double *g0,
                    const double *g1)
{
    int64_t n = lb->n;
    double *s = lb->s + (size_t)lb->head * (size_t)n, *y = lb->y + (size_t)lb->head * (size_t)n;
    double sy = 0, yy = 0, ss = 0;
    for (int64_t i = 0; i < n; i++) {
        s[i] = x1[i] - x0[i];
        y[i] = g1[i] - g0[i];
        sy += s[i] * y[i];
        yy += y[i] * y[i];
        ss += s[i] * s[i];
    }
    /* a pair without positive curvature would make the update indefinite */
    if (!(sy > 1e-10 * sqrt(ss * yy))) return;
    lb->rho[lb->head] = 1.0 / sy;
    lb->head = (lb->head + 1) % lb->m;
    if (lb->count < lb->m) lb->count++;
}
