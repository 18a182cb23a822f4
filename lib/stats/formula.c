/* lib/stats/formula.c — model formulas ("~ log(size) + species * sex"): a
 * recursive-descent parser into a set of terms, each term a set of
 * variables held as a bit mask.
 *
 * Grammar (datasets-spec/analysis-results.md, "model/<name>"):
 *     formula := ['~'] sum
 *     sum     := product ('+' product)*
 *     product := in (('*' | '/') in)*        a*b = a + b + a:b; a/b = a + a:b,
 *                                            and (a+b)/c = a + b + a:b:c: the
 *                                            left side's variables all join
 *                                            each right term (R's nesting)
 *     in      := inter ('%in%' inter)*       b %in% a = b:a: each left term
 *                                            joins all the right's variables
 *     inter   := atom (':' atom)*            a:b = every union of a term of
 *                                            a with a term of b
 *     atom    := '(' sum ')' | NAME | factor '(' NAME ')' | log '(' NAME ')'
 * '*' and '/' share a precedence and group left to right (a/b*c is
 * (a/b)*c), '%in%' binds tighter and ':' tighter still, as in R.
 * NAME is letters, digits, '_' and '.', or any text in double quotes. The
 * terms are then ordered by degree, written order within a degree, as R's
 * terms() orders them, so that sequential sums of squares follow R's.
 *
 * Products expand exponentially (a*b*...*r, 18 names, is 262,143 terms,
 * which took minutes to expand term by term): each expansion is bounded
 * before it is made (ES_FORMULA_MAX_TERMS), and a caller that knows the
 * columns has each name checked as it is read (es_formula_parse_checked),
 * so a misspelt or missing column is said before anything is expanded.
 */
#include "stats/stats_pkg.h"
#include "core/scan.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VARS 64

typedef struct fvar {
    char *name;        /* the label column */
    char *label;       /* "x", "factor(x)", "log(x)" */
    es_var_kind kind;
} fvar;

struct es_formula {
    es_ctx *ctx;
    int64_t nvars;
    fvar vars[MAX_VARS];
    int64_t nterms;
    uint64_t *terms;   /* masks, model order */
    char **labels;     /* nterms */
};

/* A set of terms under construction. */
typedef struct tset {
    uint64_t *m;
    int64_t n, cap;
} tset;

typedef struct fparser {
    es_ctx *ctx;
    es__scan sc;   /* the text and the cursor; whitespace by isspace() */
    es_formula *f;
    int depth;
    es_formula_column_fn known;   /* or NULL: names are not checked */
    void *known_ud;
} fparser;

#define ferr(p, ...) es__scan_fail(&(p)->sc, __VA_ARGS__)

static void ws(fparser *p) { es__scan_skip_space(&p->sc); }

static const char *what(fparser *p, char *buf, size_t n)
{
    return es__scan_describe(&p->sc, buf, n);
}

static es_status tset_add(es_ctx *ctx, tset *t, uint64_t m)
{
    for (int64_t i = 0; i < t->n; i++)
        if (t->m[i] == m) return ES_OK;
    if (t->n == t->cap) {
        int64_t cap = t->cap ? 2 * t->cap : 8;
        uint64_t *nm = es__realloc(ctx, t->m, (size_t)cap * sizeof *nm);
        if (!nm) return ES_ENOMEM;
        t->m = nm;
        t->cap = cap;
    }
    t->m[t->n++] = m;
    return ES_OK;
}

static void tset_clear(es_ctx *ctx, tset *t)
{
    es__free(ctx, t->m);
    memset(t, 0, sizeof *t);
}

static int name_char(char c)
{
    return isalnum((unsigned char)c) || c == '_' || c == '.';
}

/* A column name at the cursor: a run of name characters or a quoted string. */
static es_status read_name(fparser *p, const char **w, size_t *len)
{
    size_t at = p->sc.pos;
    char b[8];
    switch (es__scan_word(&p->sc, name_char, w, len)) {
    case ES__SCAN_OK: return ES_OK;
    case ES__SCAN_UNTERMINATED: return ferr(p, at, "unterminated quoted column name");
    case ES__SCAN_EMPTY: return ferr(p, at, "empty column name");
    default: return ferr(p, at, "expected a column name, found %s", what(p, b, sizeof b));
    }
}

/* The index of variable (name, kind), added if new. */
static es_status var_index(fparser *p, size_t at, const char *w, size_t len, es_var_kind kind,
                           int64_t *idx)
{
    es_formula *f = p->f;
    for (int64_t v = 0; v < f->nvars; v++)
        if (f->vars[v].kind == kind && strlen(f->vars[v].name) == len &&
            !memcmp(f->vars[v].name, w, len)) {
            *idx = v;
            return ES_OK;
        }
    if (f->nvars == MAX_VARS) return ferr(p, at, "more than %d variables", MAX_VARS);
    fvar *v = &f->vars[f->nvars];
    v->name = es__malloc(p->ctx, len + 1);
    v->label = es__malloc(p->ctx, len + 9);
    if (!v->name || !v->label) {
        es__free(p->ctx, v->name);
        es__free(p->ctx, v->label);
        v->name = v->label = NULL;
        return ES_ENOMEM;
    }
    memcpy(v->name, w, len);
    v->name[len] = '\0';
    v->kind = kind;
    snprintf(v->label, len + 9, "%s%s%s", kind == ES_VAR_FACTOR ? "factor(" :
             kind == ES_VAR_LOG ? "log(" : "", v->name, kind == ES_VAR_AUTO ? "" : ")");
    *idx = f->nvars++;
    return ES_OK;
}

/* The caller's check of a column name (es_formula_parse_checked). */
static es_status check_column(fparser *p, size_t at, const char *w, size_t len)
{
    char name[512], why[512] = "";
    if (!p->known) return ES_OK;
    if (len >= sizeof name) return ferr(p, at, "a column name of %zu bytes (at most %zu)", len,
                                        sizeof name - 1);
    memcpy(name, w, len);
    name[len] = '\0';
    if (p->known(p->known_ud, name, why, sizeof why)) return ES_OK;
    return es__scan_fail_code(&p->sc, ES_ENOTFOUND, at, "%s", *why ? why : "no such label column");
}

/* Expanding a product or interaction of a and b terms makes (at most) the
 * given count: refused, naming where, when it passes the bound. */
static es_status check_expansion(fparser *p, size_t at, int64_t a, int64_t b, int with_mains)
{
    int64_t n = a * b + (with_mains ? a + b : 0);   /* a, b <= the bound: no overflow */
    if (n <= ES_FORMULA_MAX_TERMS) return ES_OK;
    return ferr(p, at, "the formula expands to more than %d terms (%lld here): write the "
                "interactions wanted, or group main effects with ( )", ES_FORMULA_MAX_TERMS,
                (long long)n);
}

/* An operator at column at (op) must have a term after it: say so, naming
 * both places, rather than "expected a column name" alone. */
static es_status operand_follows(fparser *p, size_t at, const char *op)
{
    ws(p);
    char c = p->sc.s[p->sc.pos];
    if (c == '(' || c == '"' || name_char(c)) return ES_OK;
    char b[8];
    return ferr(p, p->sc.pos, "expected a term after the '%s' at column %zu, found %s", op, at + 1,
                what(p, b, sizeof b));
}

static es_status parse_sum(fparser *p, tset *out);

static es_status parse_atom(fparser *p, tset *out)
{
    ws(p);
    size_t at = p->sc.pos;
    es_status rc;
    if (++p->depth > 100) return ferr(p, at, "formula nested too deeply");
    if (p->sc.s[at] == '(') {
        p->sc.pos++;
        if ((rc = parse_sum(p, out)) != ES_OK ||
            (rc = es__scan_expect_close(&p->sc, '(', ')', at)) != ES_OK)
            return rc;
        p->depth--;
        return ES_OK;
    }
    if (p->sc.s[at] && strchr("+*/:%", p->sc.s[at]))
        return ferr(p, at, "'%.*s' has no term before it",
                    strncmp(p->sc.s + at, "%in%", 4) ? 1 : 4, p->sc.s + at);
    const char *w = NULL;
    size_t len = 0;
    if ((rc = read_name(p, &w, &len)) != ES_OK) return rc;
    es_var_kind kind = ES_VAR_AUTO;
    size_t after = p->sc.pos;
    ws(p);
    if (p->sc.s[p->sc.pos] == '(' && p->sc.s[at] != '"') {
        if (len == 6 && !memcmp(w, "factor", 6)) kind = ES_VAR_FACTOR;
        else if (len == 3 && !memcmp(w, "log", 3)) kind = ES_VAR_LOG;
        else
            return ferr(p, at, "unknown function '%.*s' (factor() and log() are known)",
                        (int)len, w);
        p->sc.pos++;
        ws(p);
        at = p->sc.pos;
        if ((rc = read_name(p, &w, &len)) != ES_OK) return rc;
        ws(p);
        if (p->sc.s[p->sc.pos] != ')') {
            char b[8];
            return ferr(p, p->sc.pos, "expected ')' after the column name, found %s",
                        what(p, b, sizeof b));
        }
        p->sc.pos++;
    } else {
        p->sc.pos = after;
    }
    int64_t v = 0;
    if ((rc = check_column(p, at, w, len)) != ES_OK ||
        (rc = var_index(p, at, w, len, kind, &v)) != ES_OK)
        return rc;
    p->depth--;
    return tset_add(p->ctx, out, (uint64_t)1 << v);
}

/* out = every union of a term of a with a term of b */
static es_status cross(es_ctx *ctx, const tset *a, const tset *b, tset *out)
{
    es_status rc = ES_OK;
    for (int64_t i = 0; i < a->n && rc == ES_OK; i++)
        for (int64_t j = 0; j < b->n && rc == ES_OK; j++) rc = tset_add(ctx, out, a->m[i] | b->m[j]);
    return rc;
}

/* The union of the variables of every term of t: R's nesting operators
 * treat a whole side as one term (terms.formula's NestTerms, InTerms). */
static uint64_t all_vars(const tset *t)
{
    uint64_t u = 0;
    for (int64_t i = 0; i < t->n; i++) u |= t->m[i];
    return u;
}

/* out = a/b (R: a + every term of b joined with all of a's variables) or,
 * nest_in set, a %in% b (every term of a joined with all of b's). */
static es_status nest(es_ctx *ctx, const tset *a, const tset *b, int nest_in, tset *out)
{
    es_status rc = ES_OK;
    if (nest_in) {
        uint64_t u = all_vars(b);
        for (int64_t i = 0; i < a->n && rc == ES_OK; i++) rc = tset_add(ctx, out, a->m[i] | u);
        return rc;
    }
    uint64_t u = all_vars(a);
    for (int64_t i = 0; i < a->n && rc == ES_OK; i++) rc = tset_add(ctx, out, a->m[i]);
    for (int64_t j = 0; j < b->n && rc == ES_OK; j++) rc = tset_add(ctx, out, u | b->m[j]);
    return rc;
}

/* Replace *out by *with (which is left empty). */
static void tset_take(es_ctx *ctx, tset *out, tset *with)
{
    tset_clear(ctx, out);
    *out = *with;
    memset(with, 0, sizeof *with);
}

static es_status parse_inter(fparser *p, tset *out)
{
    es_status rc = parse_atom(p, out);
    while (rc == ES_OK) {
        ws(p);
        if (p->sc.s[p->sc.pos] != ':') break;
        size_t at = p->sc.pos++;
        tset b = {0}, c = {0};
        if ((rc = operand_follows(p, at, ":")) == ES_OK &&
            (rc = parse_atom(p, &b)) == ES_OK &&
            (rc = check_expansion(p, at, out->n, b.n, 0)) == ES_OK &&
            (rc = cross(p->ctx, out, &b, &c)) == ES_OK)
            tset_take(p->ctx, out, &c);
        tset_clear(p->ctx, &b);
        tset_clear(p->ctx, &c);
    }
    return rc;
}

/* Whether "%in%" is at p->sc.pos; any other %...% is refused by name. */
static es_status at_in_operator(fparser *p, int *yes)
{
    const char *s = p->sc.s + p->sc.pos;
    *yes = 0;
    if (*s != '%') return ES_OK;
    if (!strncmp(s, "%in%", 4)) {
        *yes = 1;
        return ES_OK;
    }
    const char *end = strchr(s + 1, '%');
    int len = end && end - s < 40 ? (int)(end - s) + 1 : 1;
    return ferr(p, p->sc.pos, "unknown operator '%.*s' (the operators are '+', '*', ':', '/' and "
                "'%%in%%')", len, s);
}

/* b %in% a binds tighter than * and /, looser than ':' (R's precedence). */
static es_status parse_in(fparser *p, tset *out)
{
    es_status rc = parse_inter(p, out);
    while (rc == ES_OK) {
        ws(p);
        int in = 0;
        if ((rc = at_in_operator(p, &in)) != ES_OK || !in) break;
        size_t at = p->sc.pos;
        p->sc.pos += 4;
        tset b = {0}, c = {0};
        if ((rc = operand_follows(p, at, "%in%")) == ES_OK &&
            (rc = parse_inter(p, &b)) == ES_OK &&
            (rc = nest(p->ctx, out, &b, 1, &c)) == ES_OK)
            tset_take(p->ctx, out, &c);
        tset_clear(p->ctx, &b);
        tset_clear(p->ctx, &c);
    }
    return rc;
}

/* a*b and a/b: one precedence, left to right, as in R (a/b*c = (a/b)*c). */
static es_status parse_product(fparser *p, tset *out)
{
    es_status rc = parse_in(p, out);
    while (rc == ES_OK) {
        ws(p);
        char op = p->sc.s[p->sc.pos];
        if (op != '*' && op != '/') break;
        size_t at = p->sc.pos++;
        tset b = {0}, c = {0};
        if ((rc = operand_follows(p, at, op == '*' ? "*" : "/")) != ES_OK ||
            (rc = parse_in(p, &b)) != ES_OK) {
            /* reported */
        } else if (op == '/') {
            if ((rc = check_expansion(p, at, out->n + b.n, 1, 0)) == ES_OK)
                rc = nest(p->ctx, out, &b, 0, &c);
        } else if ((rc = check_expansion(p, at, out->n, b.n, 1)) == ES_OK) {
            for (int64_t i = 0; rc == ES_OK && i < out->n; i++) rc = tset_add(p->ctx, &c, out->m[i]);
            for (int64_t i = 0; rc == ES_OK && i < b.n; i++) rc = tset_add(p->ctx, &c, b.m[i]);
            if (rc == ES_OK) rc = cross(p->ctx, out, &b, &c);
        }
        if (rc == ES_OK) tset_take(p->ctx, out, &c);
        tset_clear(p->ctx, &b);
        tset_clear(p->ctx, &c);
    }
    return rc;
}

static es_status parse_sum(fparser *p, tset *out)
{
    es_status rc = parse_product(p, out);
    while (rc == ES_OK) {
        ws(p);
        char c = p->sc.s[p->sc.pos];
        if (c == '-')
            return ferr(p, p->sc.pos, "removing terms with '-' is not supported; list the terms "
                        "to keep");
        if (c != '+') break;
        size_t at = p->sc.pos++;
        tset b = {0};
        if ((rc = operand_follows(p, at, "+")) == ES_OK &&
            (rc = parse_product(p, &b)) == ES_OK &&
            (rc = check_expansion(p, at, out->n + b.n, 1, 0)) == ES_OK)
            for (int64_t i = 0; rc == ES_OK && i < b.n; i++) rc = tset_add(p->ctx, out, b.m[i]);
        tset_clear(p->ctx, &b);
    }
    return rc;
}

void es_formula_free(es_formula *f)
{
    if (!f) return;
    for (int64_t v = 0; v < f->nvars; v++) {
        es__free(f->ctx, f->vars[v].name);
        es__free(f->ctx, f->vars[v].label);
    }
    for (int64_t j = 0; f->labels && j < f->nterms; j++) es__free(f->ctx, f->labels[j]);
    es__free(f->ctx, f->labels);
    es__free(f->ctx, f->terms);
    es__free(f->ctx, f);
}

/* Order by degree (stable) and make the labels. */
static es_status finish(es_ctx *ctx, es_formula *f, const tset *t)
{
    f->terms = es__alloc_array(ctx, t->n, sizeof *f->terms);
    f->labels = es__calloc(ctx, (size_t)t->n, sizeof *f->labels);
    if (!f->terms || !f->labels) return ES_ENOMEM;
    f->nterms = 0;
    for (int deg = 1; deg <= MAX_VARS; deg++)
        for (int64_t i = 0; i < t->n; i++)
            if (__builtin_popcountll(t->m[i]) == deg) f->terms[f->nterms++] = t->m[i];
    for (int64_t j = 0; j < f->nterms; j++) {
        size_t len = 1;
        for (int64_t v = 0; v < f->nvars; v++)
            if (f->terms[j] >> v & 1) len += strlen(f->vars[v].label) + 1;
        char *s = es__malloc(ctx, len);
        if (!s) return ES_ENOMEM;
        s[0] = '\0';
        for (int64_t v = 0; v < f->nvars; v++)
            if (f->terms[j] >> v & 1) {
                if (*s) strcat(s, ":");
                strcat(s, f->vars[v].label);
            }
        f->labels[j] = s;
    }
    return ES_OK;
}

es_status es_formula_parse(es_ctx *ctx, const char *text, es_formula **out)
{
    return es_formula_parse_checked(ctx, text, NULL, NULL, out);
}

es_status es_formula_parse_checked(es_ctx *ctx, const char *text, es_formula_column_fn known,
                                   void *userdata, es_formula **out)
{
    *out = NULL;
    if (!text) ES_FAIL(ctx, ES_EINVAL, "formula: no formula");
    es_formula *f = es__calloc(ctx, 1, sizeof *f);
    if (!f) return ES_ENOMEM;
    f->ctx = ctx;
    fparser p = {ctx, {0}, f, 0, known, userdata};
    tset t = {0};
    es_status rc;
    es__scan_init(&p.sc, ctx, text, "formula", "the end of the formula", ES__SCAN_SPACE_C);
    ws(&p);
    const char *tilde = strchr(text, '~');
    if (tilde && tilde != text + p.sc.pos) {
        rc = ferr(&p, p.sc.pos, "the response is the store's shapes: write the formula as "
                  "'~ terms', without a left-hand side");
        goto done;
    }
    if (text[p.sc.pos] == '~') p.sc.pos++;
    ws(&p);
    if (!text[p.sc.pos]) {
        rc = ferr(&p, p.sc.pos, "the formula has no terms (write e.g. '~ group')");
        goto done;
    }
    if ((rc = parse_sum(&p, &t)) != ES_OK) goto done;
    ws(&p);
    if (text[p.sc.pos]) {
        char b[8];
        rc = ferr(&p, p.sc.pos, "unexpected %s (terms are joined by '+', '*', ':', '/' or "
                  "'%%in%%')",
                  what(&p, b, sizeof b));
        goto done;
    }
    if ((rc = finish(ctx, f, &t)) != ES_OK) goto done;
    *out = f;
    f = NULL;
done:
    tset_clear(ctx, &t);
    es_formula_free(f);
    return rc;
}

int64_t es_formula_nvars(const es_formula *f) { return f ? f->nvars : 0; }

const char *es_formula_var(const es_formula *f, int64_t v, es_var_kind *kind)
{
    if (!f || v < 0 || v >= f->nvars) return NULL;
    if (kind) *kind = f->vars[v].kind;
    return f->vars[v].name;
}

int64_t es_formula_nterms(const es_formula *f) { return f ? f->nterms : 0; }

const char *es_formula_term(const es_formula *f, int64_t j)
{
    return f && j >= 0 && j < f->nterms ? f->labels[j] : NULL;
}

const char *es__formula_var_label(const es_formula *f, int64_t v) { return f->vars[v].label; }
uint64_t es__formula_term_mask(const es_formula *f, int64_t j) { return f->terms[j]; }
