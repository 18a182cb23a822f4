/* lib/study/model_requests.c — a model's requests as the user writes them
 * (names of levels, variables, columns and terms) turned into what
 * es_model.h takes: the baseline level of each factor (--reference), the
 * values of the LS means' covariates (--at) and the error term of each F
 * (--error). Each names what it could not match and what there is.
 */
#include "study/study_pkg.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Copy item [s, s + len) of a comma list into buf; split at the last '='
 * outside parentheses into name and value (value NULL without '='). */
static es_status split_item(es_ctx *ctx, const char *what, const char *s, size_t len, char *buf,
                            size_t cap, const char **name, const char **value)
{
    if (len == 0 || len >= cap) ES_FAIL(ctx, ES_EINVAL, "model: %s: empty or too long item", what);
    memcpy(buf, s, len);
    buf[len] = '\0';
    char *eq = strrchr(buf, '=');
    *name = buf;
    *value = NULL;
    if (eq) {
        *eq = '\0';
        *value = eq + 1;
    }
    return ES_OK;
}

/* 1 when the rows have label `level` in column values lab (n). */
static int has_level(const char *const *lab, int64_t n, const char *level)
{
    for (int64_t i = 0; lab && i < n; i++)
        if (lab[i] && !strcmp(lab[i], level)) return 1;
    return 0;
}

es_status es__model_references(es_ctx *ctx, const es_formula *f, const char *spec, int64_t n,
                               es_model_column *cols, char **held)
{
    const int64_t nv = es_formula_nvars(f);
    /* the columns point into *held, a copy of spec cut at its commas */
    char *copy = *held = spec ? es__strdup(ctx, spec) : NULL;
    if (spec && !copy) return ES_ENOMEM;
    for (char *s = copy; s && *s;) {
        const size_t len = strcspn(s, ",");
        const int last = s[len] == '\0';
        s[len] = '\0';
        char *eq = strrchr(s, '=');
        const char *name = eq ? s : NULL, *level = eq ? eq + 1 : s;
        if (eq) *eq = '\0';
        if (!*level) ES_FAIL(ctx, ES_EINVAL, "model: --reference: an empty level");
        int64_t hit = -1, nhit = 0;
        for (int64_t v = 0; v < nv; v++) {
            es_var_kind kind;
            const char *col = es_formula_var(f, v, &kind);
            if (kind == ES_VAR_LOG) continue;
            char label[300];
            snprintf(label, sizeof label, "factor(%s)", col);
            if (name ? strcmp(name, col) && strcmp(name, label)
                     : !has_level(cols[v].labels, n, level))
                continue;
            if (hit < 0 || strcmp(col, es_formula_var(f, hit, NULL))) nhit++;
            hit = v;
        }
        if (hit < 0 && name)
            ES_FAIL(ctx, ES_EINVAL, "model: --reference %s=%s: '%s' is not a factor of the "
                    "formula", name, level, name);
        if (hit < 0)
            ES_FAIL(ctx, ES_EINVAL, "model: --reference %s: no factor of the formula has the "
                    "level '%s'", level, level);
        if (nhit > 1)
            ES_FAIL(ctx, ES_EINVAL, "model: --reference %s: several factors of the formula have "
                    "that level; write FACTOR=%s", level, level);
        /* every variable reading that column as labels gets the reference */
        for (int64_t v = 0; v < nv; v++)
            if (!strcmp(es_formula_var(f, v, NULL), es_formula_var(f, hit, NULL)) &&
                !cols[v].values)
                cols[v].reference = level;
        s = last ? s + len : s + len + 1;
    }
    return ES_OK;
}

es_status es__model_at(es_ctx *ctx, const es_design *d, const es_formula *f, const char *spec,
                       double *at)
{
    const int64_t n = d->n;
    char buf[400];
    for (int64_t v = 0; v < d->nvars; v++) at[v] = NAN;
    for (const char *s = spec; s && *s;) {
        const size_t len = strcspn(s, ",");
        const char *name = NULL, *value = NULL;
        es_status rc = split_item(ctx, "--at", s, len, buf, sizeof buf, &name, &value);
        if (rc != ES_OK) return rc;
        if (!value) ES_FAIL(ctx, ES_EINVAL, "model: --at %s: write NAME=VALUE or NAME=mean", name);
        int64_t hit = -1;
        int raw = 0;   /* NAME is the column a log() reads: VALUE on its scale */
        for (int64_t v = 0; v < d->nvars && hit < 0; v++) {
            es_var_kind kind;
            const char *col = es_formula_var(f, v, &kind);
            if (!strcmp(name, d->vars[v])) hit = v;
            else if (kind == ES_VAR_LOG && !strcmp(name, col)) hit = v, raw = 1;
        }
        if (hit < 0 || d->var_factor[hit])
            ES_FAIL(ctx, ES_EINVAL, "model: --at %s: '%s' is not a numeric variable of the model",
                    buf, name);
        double x;
        char *end;
        if (!strcmp(value, "mean")) {
            double sum = 0;
            for (int64_t i = 0; i < n; i++) sum += raw ? exp(d->values[i + hit * n])
                                                       : d->values[i + hit * n];
            x = sum / (double)n;
        } else {
            x = strtod(value, &end);
            if (end == value || *end || !isfinite(x))
                ES_FAIL(ctx, ES_EINVAL, "model: --at %s=%s: not a number or 'mean'", name, value);
        }
        if (raw && !(x > 0))
            ES_FAIL(ctx, ES_EINVAL, "model: --at %s=%s: log of a value <= 0", name, value);
        at[hit] = raw ? log(x) : x;
        s += len + (s[len] == ',');
    }
    return ES_OK;
}

/* The design term a name means: its label, or the same variables joined
 * by ':' in another order ("ind:pop" for "pop:ind", which is how R labels
 * ind %in% pop when pop comes first); -1 if none. */
static int64_t find_term(const es_design *d, const char *name)
{
    const int64_t T = d->nterms, V = d->nvars;
    for (int64_t t = 0; t < T; t++)
        if (!strcmp(d->terms[t], name)) return t;
    int64_t nvars = 0;
    char held[64] = {0};   /* held[v]: the name lists variable v (formulas have <= 64) */
    for (const char *s = name; V <= 64;) {
        size_t len = strcspn(s, ":");
        int64_t v = 0;
        while (v < V && (strlen(d->vars[v]) != len || strncmp(d->vars[v], s, len))) v++;
        if (v == V) return -1;
        nvars += !held[v];
        held[v] = 1;
        if (!s[len]) break;
        s += len + 1;
    }
    for (int64_t t = 0; t < T; t++) {
        int64_t same = 0, size = 0;
        for (int64_t v = 0; v < V; v++) {
            size += d->term_vars[t + v * T] != 0;
            same += d->term_vars[t + v * T] && held[v];
        }
        if (size == nvars && same == nvars) return t;
    }
    return -1;
}

es_status es__model_errors(es_ctx *ctx, const es_design *d, const char *const *spec,
                           int64_t count, int64_t *error)
{
    const int64_t T = d->nterms;
    char buf[400];
    for (int64_t j = 0; j < T; j++) error[j] = -1;
    for (int64_t k = 0; k < count; k++) {
        const char *term = NULL, *err = NULL;
        es_status rc = split_item(ctx, "--error", spec[k], strlen(spec[k]), buf, sizeof buf,
                                  &term, &err);
        if (rc != ES_OK) return rc;
        if (!err) ES_FAIL(ctx, ES_EINVAL, "model: --error %s: write TERM=ERROR_TERM", term);
        const int64_t j = find_term(d, term), e = find_term(d, err);
        const char *bad = j < 0 ? term : (e < 0 && strcmp(err, "Residual")) ? err : NULL;
        if (bad) {
            const char *why = es_design_dropped(d, bad);
            if (why) ES_FAIL(ctx, ES_EINVAL, "model: --error %s=%s: '%s' %s and was left out",
                             term, err, bad, why);
            char list[400] = "";
            for (int64_t t = 0; t < T && strlen(list) < 300; t++) {
                strcat(list, t ? ", " : "");
                strncat(list, d->terms[t], 60);
            }
            ES_FAIL(ctx, ES_ENOTFOUND, "model: --error %s=%s: the model has no term '%s' (its "
                    "terms: %s, and Residual)", term, err, bad, list);
        }
        error[j] = e;
    }
    return ES_OK;
}
