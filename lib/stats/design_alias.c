/* lib/stats/design_alias.c — terms a design cannot estimate. A term whose
 * columns are combinations of the intercept and the terms before it (a copy
 * of a factor under another name, a covariate that is the sum of others)
 * adds no rank: its sum of squares would be 0 on 0 df, its F NaN, and with
 * type III the term it copies would lose its own test. R's lm keeps such a
 * term and prints NA; a referee reads that as a bug. The design finds them
 * by the rank of its leading columns, grown a column at a time (the model's
 * Gram-Schmidt basis, R's qr tolerance 1e-7), and names what each
 * duplicates from the basic least-squares solution of its columns on the
 * columns before it (a pivoted QR, LAPACKE dgeqp3 on unit-norm columns):
 * the terms with a non-zero coefficient.
 */
#include "stats/stats_pkg.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define RANK_TOL 1e-7

/* Columns x (N x k) each scaled to unit norm into a. */
static void gather(int64_t n, const double *x, int64_t k, double *a)
{
    for (int64_t c = 0; c < k; c++) {
        const double *xc = x + c * n;
        double s = 0;
        for (int64_t i = 0; i < n; i++) s += xc[i] * xc[i];
        s = s > 0 ? 1.0 / sqrt(s) : 0.0;
        for (int64_t i = 0; i < n; i++) a[i + c * n] = xc[i] * s;
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

/* The terms (flags used, by formula term) whose columns the basic solution
 * of b on the factored columns (a, jpvt, tau of rank k; term_of gives each
 * column's formula term, -1 the intercept) uses. b is overwritten. */
static es_status used_terms(es_ctx *ctx, int64_t n, const int64_t *term_of, const double *a,
                            const lapack_int *jpvt, const double *tau, int64_t k, double *b,
                            int *used)
{
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
        const int64_t t = term_of[jpvt[i] - 1];
        if (t >= 0 && fabs(b[i]) > 1e-8 * nb) used[t] = 1;
    }
    return ES_OK;
}

/* Say which terms (formula terms before fj, flagged in used) term fj
 * duplicates: "duplicates 'sex'", "is a combination of 'a', 'b'", "is
 * constant". */
static void describe(const es_formula *f, int64_t fj, const int *used, char *why, size_t len)
{
    int64_t nu = 0;
    for (int64_t t = 0; t < fj; t++) nu += used[t];
    if (nu == 0) {
        snprintf(why, len, "is constant (a multiple of the intercept)");
        return;
    }
    size_t at = (size_t)snprintf(why, len, nu == 1 ? "duplicates " : "is a combination of ");
    int64_t k = 0;
    for (int64_t t = 0; t < fj && at < len; t++)
        if (used[t])
            at += (size_t)snprintf(why + at, len - at, "%s'%s'", k++ ? ", " : "",
                                   es_formula_term(f, t));
}

/* Room for need kept columns (N values and a term each; *cap now). */
static es_status grow(es_ctx *ctx, int64_t n, double **x, int64_t **term_of, int64_t *cap,
                      int64_t need)
{
    if (need <= *cap) return ES_OK;
    int64_t c = *cap * 2 > need ? *cap * 2 : need;
    double *nx = es__realloc(ctx, *x, (size_t)(n * c) * sizeof *nx);
    if (!nx) return ES_ENOMEM;
    *x = nx;
    int64_t *nt = es__realloc(ctx, *term_of, (size_t)c * sizeof *nt);
    if (!nt) return ES_ENOMEM;
    *term_of = nt;
    *cap = c;
    return ES_OK;
}

/* Term fj adds nothing to the kept columns x (N x k, their terms term_of):
 * why (allocated) says what its columns (tc, N x ncol) come from, from
 * the basic least-squares solution of each on the columns before. */
static es_status explain(es_ctx *ctx, const es_formula *f, int64_t n, const double *x,
                         const int64_t *term_of, int64_t k, int64_t fj, const double *tc,
                         int64_t ncol, char **why)
{
    const int64_t T = es_formula_nterms(f);
    double *a = es__alloc_array(ctx, n * k, sizeof *a);
    double *tau = es__alloc_array(ctx, k, sizeof *tau);
    double *b = es__alloc_array(ctx, n, sizeof *b);
    lapack_int *jpvt = es__alloc_array(ctx, k, sizeof *jpvt);
    int *used = es__calloc(ctx, (size_t)T, sizeof *used);
    char msg[400];
    int64_t kr = 0;
    es_status rc = a && tau && b && jpvt && used ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK) {
        gather(n, x, k, a);
        rc = pivoted_qr(ctx, n, k, a, jpvt, tau, &kr);
    }
    for (int64_t c = 0; rc == ES_OK && c < ncol; c++) {
        memcpy(b, tc + c * n, (size_t)n * sizeof *b);
        rc = used_terms(ctx, n, term_of, a, jpvt, tau, kr, b, used);
    }
    if (rc == ES_OK) {
        describe(f, fj, used, msg, sizeof msg);
        es__warn(ctx, "model: term '%s' %s (its columns are combinations of theirs): left out",
                 es_formula_term(f, fj), msg);
        if (!(*why = es__strdup(ctx, msg))) rc = ES_ENOMEM;
    }
    es__free(ctx, a);
    es__free(ctx, tau);
    es__free(ctx, b);
    es__free(ctx, jpvt);
    es__free(ctx, used);
    return rc;
}

/* One pass in term order (a term's codes depend only on the kept terms
 * before it: its margins are of lower degree, and terms are ordered by
 * degree, so this is what leaving out the first such term, rebuilding and
 * looking again would find). The rank of the columns so far grows a column
 * at a time in an orthonormal basis (es__basis_add, the model's own rank
 * rule): a pivoted QR of all leading columns for every term, and the
 * design rebuilt after each term left out, took over a minute for "~ v1*...
 * *v7*d*e*f" on 8 rows (found by fuzz_formula). */
es_status es__design_find_aliased(es_ctx *ctx, es_design *d, const es_formula *f, int *skip,
                                  char **why)
{
    const int64_t n = d->n, T = es_formula_nterms(f);
    const int64_t cap = n < ES__DESIGN_MAX_COLUMNS ? n : ES__DESIGN_MAX_COLUMNS;
    int64_t k = 1, xcap = 64, tcap = 0, ncol = 0, m = 0;
    double *x = es__alloc_array(ctx, n * xcap, sizeof *x), *tc = NULL;
    int64_t *term_of = es__alloc_array(ctx, xcap, sizeof *term_of);
    /* room for min(n, max columns) directions and the slot es__basis_add works in */
    double *basis = es__alloc_array(ctx, n * (cap + 1), sizeof *basis);
    es_status rc = x && term_of && basis ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK) {
        for (int64_t i = 0; i < n; i++) x[i] = 1.0;   /* the intercept */
        term_of[0] = -1;
        es__basis_add(n, basis, &m, x, NULL);
    }
    for (int64_t fj = 0; rc == ES_OK && fj < T; fj++) {
        int added = 0;
        if ((rc = es__design_term_values(ctx, d, f, fj, skip, &tc, &tcap, &ncol)) != ES_OK) break;
        if (k + ncol > ES__DESIGN_MAX_COLUMNS) {
            rc = es__fail(ctx, ES_ERANGE, "model: the design has more than %d columns at the "
                          "term '%s'", ES__DESIGN_MAX_COLUMNS, es_formula_term(f, fj));
            break;
        }
        for (int64_t c = 0; c < ncol && m < cap; c++)
            added |= es__basis_add(n, basis, &m, tc + c * n, NULL);
        if (!added && ncol > 0) {
            skip[fj] = 1;
            rc = explain(ctx, f, n, x, term_of, k, fj, tc, ncol, &why[fj]);
            continue;
        }
        if ((rc = grow(ctx, n, &x, &term_of, &xcap, k + ncol)) != ES_OK) break;
        memcpy(x + k * n, tc, (size_t)(n * ncol) * sizeof *x);
        for (int64_t c = 0; c < ncol; c++) term_of[k + c] = fj;
        k += ncol;
    }
    es__free(ctx, x);
    es__free(ctx, tc);
    es__free(ctx, term_of);
    es__free(ctx, basis);
    return rc;
}
