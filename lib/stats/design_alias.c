/* lib/stats/design_alias.c — terms a design cannot estimate. A term whose
 * columns are combinations of the intercept and the terms before it (a copy
 * of a factor under another name, a covariate that is the sum of others)
 * adds no rank: its sum of squares would be 0 on 0 df, its F NaN, and with
 * type III the term it copies would lose its own test. R's lm keeps such a
 * term and prints NA; a referee reads that as a bug. The design finds them
 * by the rank of its leading columns, from a pivoted QR (LAPACKE dgeqp3 on
 * unit-norm columns, rank at R's qr tolerance 1e-7), and names what each
 * duplicates from the basic least-squares solution of its columns on the
 * columns before it: the terms with a non-zero coefficient.
 */
#include "stats/stats_pkg.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define RANK_TOL 1e-7

/* Copy columns cols[0..k) of d->x, each scaled to unit norm, into a (N x k). */
static void gather(const es_design *d, const int64_t *cols, int64_t k, double *a)
{
    const int64_t n = d->n;
    for (int64_t c = 0; c < k; c++) {
        const double *x = d->x + cols[c] * n;
        double s = 0;
        for (int64_t i = 0; i < n; i++) s += x[i] * x[i];
        s = s > 0 ? 1.0 / sqrt(s) : 0.0;
        for (int64_t i = 0; i < n; i++) a[i + c * n] = x[i] * s;
    }
}

/* Pivoted QR of a (N x k) in place: rank, pivots jpvt (1-based), tau. */
static es_status pivoted_qr(es_ctx *ctx, int64_t n, int64_t k, double *a, lapack_int *jpvt,
                            double *tau, int64_t *rank)
{
    lapack_int ni, ki;
    es_status rc;
    *rank = 0;
    if (k == 0) return ES_OK;
    if ((rc = es__lapack_int(ctx, n, &ni)) != ES_OK || (rc = es__lapack_int(ctx, k, &ki)) != ES_OK)
        return rc;
    for (int64_t c = 0; c < k; c++) jpvt[c] = 0;
    lapack_int info = LAPACKE_dgeqp3(LAPACK_COL_MAJOR, ni, ki, a, ni, jpvt, tau);
    if (info != 0) ES_FAIL(ctx, ES_ENUMERIC, "model: LAPACKE_dgeqp3 failed (info %d)", (int)info);
    const int64_t m = n < k ? n : k;
    const double r11 = fabs(a[0]);
    for (int64_t c = 0; c < m; c++)
        if (r11 > 0 && fabs(a[c + c * n]) > RANK_TOL * r11) (*rank)++;
    return ES_OK;
}

/* The terms (flags, nterms) whose columns the basic solution of b on the
 * factored columns cols (a, jpvt, tau of rank k) uses. b is overwritten. */
static es_status used_terms(es_ctx *ctx, const es_design *d, const int64_t *cols, const double *a,
                            const lapack_int *jpvt, const double *tau, int64_t k, double *b,
                            int *used)
{
    const int64_t n = d->n;
    double nb = 0;
    for (int64_t i = 0; i < n; i++) nb += b[i] * b[i];
    nb = sqrt(nb);
    if (k == 0 || !(nb > 0)) return ES_OK;
    lapack_int info = LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)n, 1, (lapack_int)k,
                                     a, (lapack_int)n, tau, b, (lapack_int)n);
    if (info != 0) ES_FAIL(ctx, ES_ENUMERIC, "model: LAPACKE_dormqr failed (info %d)", (int)info);
    for (int64_t i = k - 1; i >= 0; i--) {   /* R11 z = (Q^T b)[0..k) */
        double s = b[i];
        for (int64_t j = i + 1; j < k; j++) s -= a[i + j * n] * b[j];
        b[i] = s / a[i + i * n];
    }
    for (int64_t i = 0; i < k; i++) {
        const int64_t t = d->assign[cols[jpvt[i] - 1]];
        if (t >= 0 && fabs(b[i]) > 1e-8 * nb) used[t] = 1;
    }
    return ES_OK;
}

/* Say which terms term j duplicates: "duplicates 'sex'", "is a combination
 * of 'a', 'b'", "is constant". */
static void describe(const es_design *d, int64_t j, const int *used, char *why, size_t len)
{
    int64_t nu = 0;
    for (int64_t t = 0; t < j; t++) nu += used[t];
    if (nu == 0) {
        snprintf(why, len, "is constant (a multiple of the intercept)");
        return;
    }
    size_t at = (size_t)snprintf(why, len, nu == 1 ? "duplicates " : "is a combination of ");
    int64_t k = 0;
    for (int64_t t = 0; t < j && at < len; t++)
        if (used[t])
            at += (size_t)snprintf(why + at, len - at, "%s'%s'", k++ ? ", " : "", d->terms[t]);
}

es_status es__design_first_aliased(es_ctx *ctx, const es_design *d, int64_t *term, char *why,
                                   size_t whylen)
{
    const int64_t n = d->n, q = d->ncols, T = d->nterms;
    *term = -1;
    double *a = es__alloc_array(ctx, n * q, sizeof *a);
    double *tau = es__alloc_array(ctx, q, sizeof *tau);
    double *b = es__alloc_array(ctx, n, sizeof *b);
    lapack_int *jpvt = es__alloc_array(ctx, q, sizeof *jpvt);
    int64_t *cols = es__alloc_array(ctx, q, sizeof *cols);
    int *used = es__calloc(ctx, (size_t)(T > 0 ? T : 1), sizeof *used);
    es_status rc = ES_OK;
    if (!a || !tau || !b || !jpvt || !cols || !used) {
        rc = ES_ENOMEM;
        goto done;
    }
    /* columns in term order: the intercept, then term 0, term 1, ... */
    int64_t k = 0, rank_before = 1;
    cols[k++] = 0;
    for (int64_t j = 0; j < T && *term < 0; j++) {
        const int64_t k0 = k;
        for (int64_t c = 0; c < q; c++)
            if (d->assign[c] == j) cols[k++] = c;
        int64_t rank = 0;
        gather(d, cols, k, a);
        if ((rc = pivoted_qr(ctx, n, k, a, jpvt, tau, &rank)) != ES_OK) goto done;
        if (rank > rank_before || k == k0) {
            rank_before = rank;
            continue;
        }
        /* term j adds nothing: what do its columns come from? */
        *term = j;
        int64_t kr = 0;
        gather(d, cols, k0, a);
        if ((rc = pivoted_qr(ctx, n, k0, a, jpvt, tau, &kr)) != ES_OK) goto done;
        for (int64_t c = k0; c < k; c++) {
            memcpy(b, d->x + cols[c] * n, (size_t)n * sizeof *b);
            if ((rc = used_terms(ctx, d, cols, a, jpvt, tau, kr, b, used)) != ES_OK) goto done;
        }
        describe(d, j, used, why, whylen);
    }
done:
    es__free(ctx, a);
    es__free(ctx, tau);
    es__free(ctx, b);
    es__free(ctx, jpvt);
    es__free(ctx, cols);
    es__free(ctx, used);
    return rc;
}
