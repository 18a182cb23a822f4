/* lib/stats/design.c — the model matrix of a formula over label columns, made
 * the way R's model.matrix makes it so that coefficients, type III sums of
 * squares and the oracle comparisons with R mean the same thing.
 *
 * A variable is numeric (its values, or their log) or categorical (levels
 * sorted in byte order, R's sort in the C locale). In each term a factor is
 * coded by its contrasts when the term's margin (the term without that
 * factor; the intercept for a main effect) is in the model, by one indicator
 * per level otherwise (R's rule, Chambers & Hastie 1992, sec. 2.4.1); the
 * columns of a term are the products of its variables' codes, the first
 * variable varying fastest. A term that adds no rank to the terms before it
 * is left out with a warning (design_alias.c); columns aliased within a term
 * (an empty cell of an interaction) are kept: the fit's QR finds them.
 */
#include "stats/stats_pkg.h"
#include "core/text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void es_design_free(es_design *d)
{
    if (!d) return;
    es_ctx *ctx = d->ctx;
    for (int64_t c = 0; d->colnames && c < d->ncols; c++) es__free(ctx, d->colnames[c]);
    for (int64_t j = 0; d->terms && j < d->nterms; j++) es__free(ctx, d->terms[j]);
    for (int64_t v = 0; d->vars && v < d->nvars; v++) {
        es__free(ctx, d->vars[v]);
        for (int64_t l = 0; d->levels && d->levels[v] && l < d->nlevels[v]; l++)
            es__free(ctx, d->levels[v][l]);
        if (d->levels) es__free(ctx, d->levels[v]);
    }
    for (int64_t k = 0; k < d->ndropped; k++) {
        es__free(ctx, d->dropped[k]);
        es__free(ctx, d->dropped_why[k]);
    }
    es__free(ctx, d->dropped);
    es__free(ctx, d->dropped_why);
    es__free(ctx, d->x);
    es__free(ctx, d->colnames);
    es__free(ctx, d->assign);
    es__free(ctx, d->terms);
    es__free(ctx, d->term_vars);
    es__free(ctx, d->vars);
    es__free(ctx, d->var_factor);
    es__free(ctx, d->nlevels);
    es__free(ctx, d->levels);
    es__free(ctx, d->codes);
    es__free(ctx, d->values);
    es__free(ctx, d->term_coding);
    es__free(ctx, d->col_level);
    es__free(ctx, d);
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Put level `ref` first (R's relevel): codes and levels renumbered. */
static es_status relevel(es_ctx *ctx, es_design *d, int64_t v, const char *ref)
{
    const int64_t n = d->n, L = d->nlevels[v];
    int64_t k = -1;
    for (int64_t l = 0; l < L && k < 0; l++)
        if (!strcmp(d->levels[v][l], ref)) k = l;
    if (k < 0) {
        char list[400] = "";
        for (int64_t l = 0; l < L && strlen(list) < 300; l++) {
            strcat(list, l ? ", " : "");
            strncat(list, d->levels[v][l], 60);
        }
        ES_FAIL(ctx, ES_EINVAL, "model: reference '%s' is not a level of '%s' (its levels: %s)",
                ref, d->vars[v], list);
    }
    char *first = d->levels[v][k];
    memmove(d->levels[v] + 1, d->levels[v], (size_t)k * sizeof *d->levels[v]);
    d->levels[v][0] = first;
    for (int64_t i = 0; i < n; i++) {
        int64_t *c = &d->codes[i + v * n];
        *c = *c == k ? 0 : *c < k ? *c + 1 : *c;
    }
    return ES_OK;
}

/* Levels of a categorical variable: sorted distinct labels, codes per row. */
static es_status make_factor(es_ctx *ctx, es_design *d, int64_t v, const char *const *lab)
{
    const int64_t n = d->n;
    const char **sorted = es__alloc_array(ctx, n, sizeof *sorted);
    if (!sorted) return ES_ENOMEM;
    for (int64_t i = 0; i < n; i++) {
        if (!lab[i]) {
            es__free(ctx, (void *)sorted);
            ES_FAIL(ctx, ES_EINVAL, "model: row %lld has no value of '%s'", (long long)i,
                    d->vars[v]);
        }
        sorted[i] = lab[i];
    }
    qsort(sorted, (size_t)n, sizeof *sorted, cmp_str);
    int64_t L = 0;
    for (int64_t i = 0; i < n; i++)
        if (i == 0 || strcmp(sorted[i], sorted[i - 1])) sorted[L++] = sorted[i];
    es_status rc = ES_OK;
    if (L < 2) {
        rc = es__fail(ctx, ES_EINVAL, "model: the factor '%s' has a single level '%s' in the "
                      "rows used; it cannot be a term", d->vars[v], n ? sorted[0] : "");
        goto done;
    }
    if (!(d->levels[v] = es__calloc(ctx, (size_t)L, sizeof **d->levels))) {
        rc = ES_ENOMEM;
        goto done;
    }
    d->nlevels[v] = L;
    for (int64_t l = 0; l < L; l++)
        if (!(d->levels[v][l] = es__strdup(ctx, sorted[l]))) {
            rc = ES_ENOMEM;
            goto done;
        }
    for (int64_t i = 0; i < n; i++) {
        const char *const *hit = bsearch(&lab[i], (const void *)d->levels[v], (size_t)L,
                                         sizeof(char *), cmp_str);
        d->codes[i + v * n] = hit - (const char *const *)d->levels[v];
    }
done:
    es__free(ctx, (void *)sorted);
    return rc;
}

/* Read variable v of the formula from its column. */
static es_status read_var(es_ctx *ctx, es_design *d, int64_t v, const es_model_column *col,
                          es_var_kind kind)
{
    const int64_t n = d->n;
    double *val = d->values + v * n;
    for (int64_t i = 0; i < n; i++) d->codes[i + v * n] = -1;
    int numeric = kind != ES_VAR_FACTOR;
    if (col->values) {
        for (int64_t i = 0; i < n; i++) val[i] = col->values[i];
    } else if (kind != ES_VAR_FACTOR) {
        for (int64_t i = 0; i < n && numeric; i++)
            if (!col->labels[i] || es__parse_finite(col->labels[i], &val[i]) != 0) {
                if (kind == ES_VAR_LOG)
                    ES_FAIL(ctx, ES_EINVAL, "model: log(%s): row %lld has '%s', not a number",
                            col->name, (long long)i, col->labels[i] ? col->labels[i] : "");
                numeric = 0;
            }
    }
    if (numeric && col->reference)
        ES_FAIL(ctx, ES_EINVAL, "model: a reference level '%s' is given for '%s', which is "
                "numeric (write factor(%s))", col->reference, col->name, col->name);
    if (numeric) {
        for (int64_t i = 0; i < n; i++) {
            if (!isfinite(val[i]))
                ES_FAIL(ctx, ES_EINVAL, "model: '%s' of row %lld is %g", col->name,
                        (long long)i, val[i]);
            if (kind == ES_VAR_LOG) {
                if (!(val[i] > 0))
                    ES_FAIL(ctx, ES_EINVAL, "model: log(%s): row %lld has %g, not positive",
                            col->name, (long long)i, val[i]);
                val[i] = log(val[i]);
            }
        }
        return ES_OK;
    }
    d->var_factor[v] = 1;
    if (col->labels) {
        es_status rc = make_factor(ctx, d, v, col->labels);
        return rc == ES_OK && col->reference ? relevel(ctx, d, v, col->reference) : rc;
    }
    /* factor() of a numeric column given as numbers: their text */
    char **txt = es__calloc(ctx, (size_t)n, sizeof *txt);
    es_status rc = txt ? ES_OK : ES_ENOMEM;
    for (int64_t i = 0; rc == ES_OK && i < n; i++) {
        char b[32];
        snprintf(b, sizeof b, "%.17g", col->values[i]);
        if (!(txt[i] = es__strdup(ctx, b))) rc = ES_ENOMEM;
    }
    if (rc == ES_OK) rc = make_factor(ctx, d, v, (const char *const *)txt);
    if (rc == ES_OK && col->reference) rc = relevel(ctx, d, v, col->reference);
    for (int64_t i = 0; txt && i < n; i++) es__free(ctx, txt[i]);
    es__free(ctx, txt);
    return rc;
}

/* The code matrix of variable v in a term: L x c (ld L) for a factor; what
 * its columns are named after (level index per column). */
typedef struct vcode {
    int64_t ncol;
    int factor, coding;     /* coding: 0 treatment, 1 sum, 2 indicators */
} vcode;

static double code_at(const es_design *d, int64_t v, const vcode *vc, int64_t i, int64_t k)
{
    if (!vc->factor) return d->values[i + v * d->n];
    int64_t l = d->codes[i + v * d->n], L = d->nlevels[v];
    switch (vc->coding) {
    case 0: return l == k + 1 ? 1.0 : 0.0;
    case 1: return l == k ? 1.0 : (l == L - 1 ? -1.0 : 0.0);
    default: return l == k ? 1.0 : 0.0;
    }
}

/* The level a code column names: treatment k -> level k+1, else level k. */
static int64_t code_level(const vcode *vc, int64_t k) { return vc->coding == 0 ? k + 1 : k; }

#define MAX_COLUMNS ES__DESIGN_MAX_COLUMNS

/* How design term j (formula term fj) codes each of its nv variables (vars,
 * vc) and how many columns that makes (*ncol, bounded). */
static es_status term_codes(es_ctx *ctx, es_design *d, const es_formula *f, int64_t fj,
                            int64_t j, const int *skip, vcode *vc, int64_t *vars,
                            int64_t *nv_out, int64_t *ncol_out)
{
    const uint64_t mask = es__formula_term_mask(f, fj);
    int64_t nv = 0, ncol = 1;
    for (int64_t v = 0; v < d->nvars; v++) {
        if (!(mask >> v & 1)) continue;
        vcode *c = &vc[nv];
        vars[nv] = v;
        c->factor = d->var_factor[v];
        if (c->factor) {
            uint64_t margin = mask & ~((uint64_t)1 << v);
            int present = margin == 0;
            for (int64_t t = 0; t < es_formula_nterms(f) && !present; t++)
                present = !skip[t] && es__formula_term_mask(f, t) == margin;
            c->coding = present ? (d->contrasts == ES_CONTRASTS_SUM ? 1 : 0) : 2;
            c->ncol = c->coding == 2 ? d->nlevels[v] : d->nlevels[v] - 1;
            d->term_coding[j + v * d->nterms] = c->coding;
        } else {
            c->coding = 0;
            c->ncol = 1;
        }
        if (!es__mul_i64(ncol, c->ncol, &ncol) || ncol > MAX_COLUMNS)
            ES_FAIL(ctx, ES_ERANGE, "model: the term '%s' has too many columns", d->terms[j]);
        nv++;
    }
    *nv_out = nv;
    *ncol_out = ncol;
    return ES_OK;
}

/* Column c of a term coded by vc over vars (N values): the product of its
 * variables' codes, the first variable varying fastest (mixed radix); k
 * gets each variable's code index. */
static void term_column(const es_design *d, const vcode *vc, const int64_t *vars, int64_t nv,
                        int64_t c, int64_t *k, double *col)
{
    int64_t rem = c;
    for (int64_t a = 0; a < nv; a++) {
        k[a] = rem % vc[a].ncol;
        rem /= vc[a].ncol;
    }
    for (int64_t i = 0; i < d->n; i++) {
        double x = 1;
        for (int64_t a = 0; a < nv; a++) x *= code_at(d, vars[a], &vc[a], i, k[a]);
        col[i] = x;
    }
}

es_status es__design_term_values(es_ctx *ctx, es_design *d, const es_formula *f, int64_t fj,
                                 const int *skip, double **buf, int64_t *cap, int64_t *ncol)
{
    vcode vc[64];
    int64_t vars[64], k[64], nv;
    es_status rc = term_codes(ctx, d, f, fj, fj, skip, vc, vars, &nv, ncol);
    if (rc != ES_OK) return rc;
    if (*ncol > *cap) {
        double *nb = es__realloc(ctx, *buf, (size_t)(d->n * *ncol) * sizeof *nb);
        if (!nb) return ES_ENOMEM;
        *buf = nb;
        *cap = *ncol;
    }
    for (int64_t c = 0; c < *ncol; c++) term_column(d, vc, vars, nv, c, k, *buf + c * d->n);
    return ES_OK;
}

/* Term j's columns from column q0 on (the arrays hold them all). */
static es_status fill_term_columns(es_ctx *ctx, es_design *d, const es_formula *f, int64_t j,
                                   const vcode *vc, const int64_t *vars, int64_t nv,
                                   int64_t ncol, int64_t q0)
{
    const int64_t n = d->n;
    for (int64_t c = 0; c < ncol; c++) {
        int64_t k[64];
        term_column(d, vc, vars, nv, c, k, d->x + (q0 + c) * n);
        size_t len = 1;
        for (int64_t a = 0; a < nv; a++) {
            len += strlen(d->vars[vars[a]]) + 2;
            if (vc[a].factor) len += strlen(d->levels[vars[a]][code_level(&vc[a], k[a])]) + 1;
        }
        char *s = es__malloc(ctx, len), *e;
        if (!s) return ES_ENOMEM;
        e = s;
        *e = '\0';
        for (int64_t a = 0; a < nv; a++) {
            if (a) *e++ = ':';
            if (vc[a].factor) {
                /* factor(x) names its levels as x=level */
                es_var_kind kind;
                const char *name = es_formula_var(f, vars[a], &kind);
                e = stpcpy(e, kind == ES_VAR_FACTOR ? name : d->vars[vars[a]]);
                *e++ = '=';
                e = stpcpy(e, d->levels[vars[a]][code_level(&vc[a], k[a])]);
            } else {
                e = stpcpy(e, d->vars[vars[a]]);
            }
        }
        *e = '\0';
        d->colnames[q0 + c] = s;
        d->assign[q0 + c] = j;
        int64_t *lev = d->col_level + (q0 + c) * d->nvars;
        for (int64_t v = 0; v < d->nvars; v++) lev[v] = -1;
        for (int64_t a = 0; a < nv; a++)
            if (vc[a].factor) lev[vars[a]] = code_level(&vc[a], k[a]);
        d->ncols = q0 + c + 1;
    }
    return ES_OK;
}

/* Every kept term's columns after the intercept: counted (and bounded)
 * first, so that the arrays are allocated once. */
static es_status build_columns(es_ctx *ctx, es_design *d, const es_formula *f, const int *skip)
{
    vcode vc[64];
    int64_t vars[64], nv, ncol, total = 1, nvars = d->nvars > 0 ? d->nvars : 1;
    const int64_t T = es_formula_nterms(f);
    es_status rc;
    for (int64_t fj = 0, j = 0; fj < T; fj++) {
        if (skip[fj]) continue;
        if ((rc = term_codes(ctx, d, f, fj, j, skip, vc, vars, &nv, &ncol)) != ES_OK) return rc;
        if ((total += ncol) > MAX_COLUMNS)
            ES_FAIL(ctx, ES_ERANGE, "model: the design has more than %d columns at the term "
                    "'%s'", MAX_COLUMNS, d->terms[j]);
        j++;
    }
    if (!(d->x = es__alloc_array(ctx, d->n * total, sizeof *d->x)) ||
        !(d->colnames = es__calloc(ctx, (size_t)total, sizeof *d->colnames)) ||
        !(d->assign = es__alloc_array(ctx, total, sizeof *d->assign)) ||
        !(d->col_level = es__alloc_array(ctx, total * nvars, sizeof *d->col_level)))
        return ES_ENOMEM;
    for (int64_t i = 0; i < d->n; i++) d->x[i] = 1.0;
    for (int64_t v = 0; v < d->nvars; v++) d->col_level[v] = -1;
    if (!(d->colnames[0] = es__strdup(ctx, "intercept"))) return ES_ENOMEM;
    d->assign[0] = -1;
    d->ncols = 1;
    for (int64_t fj = 0, j = 0; fj < T; fj++) {
        if (skip[fj]) continue;
        if ((rc = term_codes(ctx, d, f, fj, j, skip, vc, vars, &nv, &ncol)) != ES_OK ||
            (rc = fill_term_columns(ctx, d, f, j, vc, vars, nv, ncol, d->ncols)) != ES_OK)
            return rc;
        j++;
    }
    return ES_OK;
}

/* The design of f without the formula terms flagged in skip. */
static es_status build(es_ctx *ctx, const es_formula *f, int64_t n, const es_model_column *columns,
                       int64_t ncolumns, es_contrasts contrasts, const int *skip, es_design **out)
{
    *out = NULL;
    es_design *d = es__calloc(ctx, 1, sizeof *d);
    if (!d) return ES_ENOMEM;
    d->ctx = ctx;
    d->n = n;
    d->contrasts = contrasts;
    d->nvars = es_formula_nvars(f);
    for (int64_t t = 0; t < es_formula_nterms(f); t++) d->nterms += !skip[t];
    es_status rc = ES_OK;
    int64_t nv = d->nvars, nt = d->nterms;
    d->vars = es__calloc(ctx, (size_t)nv, sizeof *d->vars);
    d->var_factor = es__calloc(ctx, (size_t)nv, sizeof *d->var_factor);
    d->nlevels = es__calloc(ctx, (size_t)nv, sizeof *d->nlevels);
    d->levels = es__calloc(ctx, (size_t)nv, sizeof *d->levels);
    d->codes = es__alloc_array(ctx, n * nv, sizeof *d->codes);
    d->values = es__calloc(ctx, (size_t)(n * nv), sizeof *d->values);
    d->terms = es__calloc(ctx, (size_t)(nt > 0 ? nt : 1), sizeof *d->terms);
    d->term_vars = es__calloc(ctx, (size_t)(nt * nv > 0 ? nt * nv : 1), sizeof *d->term_vars);
    d->term_coding = es__alloc_array(ctx, nt * nv > 0 ? nt * nv : 1, sizeof *d->term_coding);
    if (!d->term_coding || !d->vars || !d->var_factor || !d->nlevels || !d->levels ||
        !d->codes || !d->values || !d->terms || !d->term_vars) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t v = 0; v < nv && rc == ES_OK; v++) {
        es_var_kind kind;
        const char *name = es_formula_var(f, v, &kind);
        const es_model_column *col = NULL;
        for (int64_t c = 0; c < ncolumns && !col; c++)
            if (columns[c].name && !strcmp(columns[c].name, name)) col = &columns[c];
        if (!(d->vars[v] = es__strdup(ctx, es__formula_var_label(f, v)))) {
            rc = ES_ENOMEM;
            break;
        }
        if (!col) rc = es__fail(ctx, ES_ENOTFOUND, "model: no label column '%s'", name);
        else if (!col->labels && !col->values)
            rc = es__fail(ctx, ES_EINVAL, "model: column '%s' has no values", name);
        else if (kind == ES_VAR_LOG && !col->values && !col->labels)
            rc = es__fail(ctx, ES_EINVAL, "model: log(%s) needs numbers", name);
        else rc = read_var(ctx, d, v, col, kind);
    }
    if (rc != ES_OK) goto done;
    for (int64_t fj = 0, j = 0; fj < es_formula_nterms(f); fj++) {
        if (skip[fj]) continue;
        if (!(d->terms[j] = es__strdup(ctx, es_formula_term(f, fj)))) {
            rc = ES_ENOMEM;
            goto done;
        }
        for (int64_t v = 0; v < nv; v++)
            d->term_vars[j + v * nt] = (int64_t)(es__formula_term_mask(f, fj) >> v & 1);
        j++;
    }
    for (int64_t k = 0; k < nt * nv; k++) d->term_coding[k] = -1;
    if ((rc = build_columns(ctx, d, f, skip)) != ES_OK) goto done;
    *out = d;
    d = NULL;
done:
    es_design_free(d);
    return rc;
}

/* Record formula term fj as dropped, and why, in d (taking why). */
static es_status note_dropped(es_ctx *ctx, es_design *d, const char *term, char *why)
{
    char **t = es__realloc(ctx, d->dropped, (size_t)(d->ndropped + 1) * sizeof *t);
    if (!t) return ES_ENOMEM;
    d->dropped = t;
    char **w = es__realloc(ctx, d->dropped_why, (size_t)(d->ndropped + 1) * sizeof *w);
    if (!w) return ES_ENOMEM;
    d->dropped_why = w;
    if (!(d->dropped[d->ndropped] = es__strdup(ctx, term))) return ES_ENOMEM;
    d->dropped_why[d->ndropped++] = why;
    return ES_OK;
}

es_status es_design_build(es_ctx *ctx, const es_formula *f, int64_t n,
                          const es_model_column *columns, int64_t ncolumns,
                          es_contrasts contrasts, es_design **out)
{
    *out = NULL;
    if (!f || n < 1 || (ncolumns > 0 && !columns))
        ES_FAIL(ctx, ES_EINVAL, "model: no formula or no rows");
    const int64_t T = es_formula_nterms(f);
    int *skip = es__calloc(ctx, (size_t)(T > 0 ? T : 1), sizeof *skip);
    char **why = es__calloc(ctx, (size_t)(T > 0 ? T : 1), sizeof *why);
    es_design *d = NULL;
    es_status rc = skip && why ? ES_OK : ES_ENOMEM;
    int any = 0;
    /* every term's design, the terms that add no rank found from it in one
     * pass, then the design without them (their absence can change how the
     * terms after them are coded) */
    if (rc == ES_OK && (rc = build(ctx, f, n, columns, ncolumns, contrasts, skip, &d)) == ES_OK &&
        (rc = es__design_find_aliased(ctx, d, f, skip, why)) == ES_OK)
        for (int64_t fj = 0; fj < T; fj++) any |= skip[fj];
    if (rc == ES_OK && any) {
        es_design_free(d);
        d = NULL;
        rc = build(ctx, f, n, columns, ncolumns, contrasts, skip, &d);
    }
    for (int64_t fj = 0; rc == ES_OK && fj < T; fj++)
        if (skip[fj]) {
            rc = note_dropped(ctx, d, es_formula_term(f, fj), why[fj]);
            if (rc == ES_OK) why[fj] = NULL;
        }
    if (rc == ES_OK && d->nterms == 0 && T > 0)
        rc = es__fail(ctx, ES_EINVAL, "model: every term of the formula was left out (%s %s)",
                      d->dropped[0], d->dropped_why[0]);
    if (rc == ES_OK) {
        *out = d;
        d = NULL;
    }
    for (int64_t fj = 0; why && fj < T; fj++) es__free(ctx, why[fj]);
    es__free(ctx, why);
    es__free(ctx, skip);
    es_design_free(d);
    return rc;
}

/* 1 when the term label `term` ("a:b") has variable label `var` among its parts. */
static int term_has_var(const char *term, const char *var)
{
    const size_t n = strlen(var);
    for (const char *s = term; s; s = strchr(s, ':') ? strchr(s, ':') + 1 : NULL)
        if (!strncmp(s, var, n) && (s[n] == ':' || s[n] == '\0')) return 1;
    return 0;
}

const char *es_design_dropped(const es_design *d, const char *name)
{
    if (!d || !name) return NULL;
    for (int64_t k = 0; k < d->ndropped; k++)
        if (!strcmp(d->dropped[k], name)) return d->dropped_why[k];
    /* a variable that only dropped terms held */
    for (int64_t t = 0; t < d->nterms; t++)
        if (term_has_var(d->terms[t], name)) return NULL;
    for (int64_t k = 0; k < d->ndropped; k++)
        if (term_has_var(d->dropped[k], name)) return d->dropped_why[k];
    return NULL;
}
