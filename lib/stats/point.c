/* lib/stats/point.c — the point syntax: a recursive-descent parser that folds
 * every expression into a linear combination of leaves, and its evaluation
 * through a resolver callback.
 *
 * Grammar (datasets-spec/point-syntax.md):
 *     sum     := product (('+' | '-') product)*
 *     product := unary (('*' | '/') unary)*
 *     unary   := ('-' | '+') unary | primary
 *     primary := NUMBER | '(' sum ')' | 'lerp' '(' sum ',' sum ',' sum ')'
 *              | 'mean' ['[' NAME '=' VALUE (',' NAME '=' VALUE)* ']']
 *              | 'row:' ID | 'file:' PATH | 'pc:' [NAME ':'] INTEGER | 'diff:' NAME
 *              | 'coef:' NAME ':' COEF
 * Numbers are constants, so each sub-expression is either a number or a
 * linear form sum c_i leaf_i; the parser checks the types as it goes (a
 * number cannot be added to a point, two points cannot be multiplied) and
 * reports the column of the offending token. Parsing is the only place
 * where expressions are inspected; the evaluator just sums.
 */
#include "edgespace/es_point.h"
#include "core/core_private.h"
#include "core/scan.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct term {
    double coef;
    es_point_leaf kind;
    char *arg;
    int64_t index;
} term;

struct es_point_expr {
    es_ctx *ctx;
    int64_t n, cap;
    term *t;
};

/* A parsed sub-expression: a number (is_num) or a linear form held as a
 * range [t0, t1) of the expression's term array. */
typedef struct form {
    int is_num;
    double num;
    int64_t t0, t1;
} form;

typedef struct parser {
    es_ctx *ctx;
    es__scan sc;   /* the text and the cursor; whitespace ' ', '\t', '\n', '\r' */
    es_point_expr *x;
    int depth;
} parser;

#define MAX_DEPTH 200

#define perr(p, ...) es__scan_fail(&(p)->sc, __VA_ARGS__)

static void skip_ws(parser *p) { es__scan_skip_space(&p->sc); }

static int is_id_char(char c)
{
    return isalnum((unsigned char)c) || c == '-' || c == '_' || c == '.';
}

/* What the next token looks like, for messages. */
static const char *describe(parser *p, char *buf, size_t n)
{
    return es__scan_describe(&p->sc, buf, n);
}

static es_status add_term(parser *p, double coef, es_point_leaf kind, const char *arg,
                          size_t arglen, int64_t index, form *f)
{
    es_point_expr *x = p->x;
    if (x->n == x->cap) {
        int64_t cap = x->cap ? 2 * x->cap : 8;
        term *t = es__realloc(p->ctx, x->t, (size_t)cap * sizeof *t);
        if (!t) return ES_ENOMEM;
        x->t = t;
        x->cap = cap;
    }
    char *a = es__malloc(p->ctx, arglen + 1);
    if (!a) return ES_ENOMEM;
    memcpy(a, arg, arglen);
    a[arglen] = '\0';
    x->t[x->n] = (term){coef, kind, a, index};
    f->is_num = 0;
    f->t0 = x->n;
    f->t1 = ++x->n;
    return ES_OK;
}

static void scale_form(parser *p, form *f, double c)
{
    if (f->is_num) f->num *= c;
    else
        for (int64_t i = f->t0; i < f->t1; i++) p->x->t[i].coef *= c;
}

/* A word: a quoted string "..." (any characters but '"') or a run of
 * characters accepted by `ok`. Sets *w, *len; the quotes are not part of
 * the word. */
static es_status word(parser *p, int (*ok)(char), const char *what, const char **w,
                      size_t *len)
{
    size_t at = p->sc.pos;
    char b[8];
    switch (es__scan_word(&p->sc, ok, w, len)) {
    case ES__SCAN_OK: return ES_OK;
    case ES__SCAN_UNTERMINATED: return perr(p, at, "unterminated quoted string (expected %s)", what);
    case ES__SCAN_EMPTY: return perr(p, at, "expected %s, found an empty string", what);
    default: return perr(p, at, "expected %s, found %s", what, describe(p, b, sizeof b));
    }
}

/* A coefficient's name: "age", "expression=happy", "a=x:b=y". */
static int coef_char(char c)
{
    return is_id_char(c) || c == '=' || c == ':';
}

static int path_char(char c)
{
    return c && c != ' ' && c != '\t' && c != '\n' && c != ',' && c != ')';
}

static int has_mesh_ext(const char *w, size_t n)
{
    static const char *const ext[] = {".obj", ".ply", ".off", ".OBJ", ".PLY", ".OFF"};
    for (size_t i = 0; i < sizeof ext / sizeof *ext; i++)
        if (n > 4 && !memcmp(w + n - 4, ext[i], 4)) return 1;
    return 0;
}

static es_status parse_sum(parser *p, form *f);

static es_status expect(parser *p, char c)
{
    skip_ws(p);
    if (p->sc.s[p->sc.pos] != c) {
        char b[8];
        return perr(p, p->sc.pos, "expected '%c', found %s", c, describe(p, b, sizeof b));
    }
    p->sc.pos++;
    return ES_OK;
}

/* A number (its value exactly strtod's: core/text.h), of fewer than 64
 * bytes. */
static es_status parse_number(parser *p, form *f)
{
    size_t at = p->sc.pos, len = 0;
    switch (es__scan_number(&p->sc, 64, &f->num, &len)) {
    case ES__SCAN_OK: break;
    case ES__SCAN_TOO_LONG: return perr(p, at, "number too long");
    default: return perr(p, at, "malformed number");
    }
    f->is_num = 1;
    if (!isfinite(f->num)) return perr(p, at, "number out of range");
    char c = es__scan_peek(&p->sc);
    if (isalpha((unsigned char)c) || c == '_')
        return perr(p, p->sc.pos, "expected an operator after the number, found '%c' (write "
                    "2*pc:1)", c);
    return ES_OK;
}

/* mean or mean[col=value,...]: the filter is stored as "col=value,col=value",
 * in es_store_select's syntax. */
static es_status parse_mean(parser *p, form *f)
{
    size_t save = p->sc.pos;
    skip_ws(p);
    if (p->sc.s[p->sc.pos] != '[') {
        p->sc.pos = save;
        return add_term(p, 1.0, ES_POINT_MEAN, "", 0, 0, f);
    }
    size_t open = p->sc.pos++;
    char *filt = NULL;
    size_t flen = 0;
    es_status rc = ES_OK;
    for (;;) {
        const char *w = NULL, *v = NULL; /* set by word(); initialized for -O3 */
        size_t wl = 0, vl = 0;
        skip_ws(p);
        size_t wat = p->sc.pos;
        if ((rc = word(p, is_id_char, "a column name", &w, &wl)) != ES_OK) break;
        /* es_store_select splits terms at ',' and the name from the value at
         * the first '=', so a quoted name cannot hold them */
        if (memchr(w, ',', wl) || memchr(w, '=', wl)) {
            rc = perr(p, wat, "a column name cannot contain ',' or '='");
            break;
        }
        skip_ws(p);
        if (p->sc.s[p->sc.pos] != '=') {
            char b[8];
            rc = perr(p, p->sc.pos, "expected '=' after the column name, found %s",
                      describe(p, b, sizeof b));
            break;
        }
        p->sc.pos++;
        skip_ws(p);
        if ((rc = word(p, is_id_char, "a value", &v, &vl)) != ES_OK) break;
        /* a value holding ',' is passed quoted (es_store_select's col="v") */
        int q = memchr(v, ',', vl) != NULL;
        char *nf = es__realloc(p->ctx, filt, flen + wl + vl + 5);
        if (!nf) {
            rc = ES_ENOMEM;
            break;
        }
        filt = nf;
        if (flen) filt[flen++] = ',';
        memcpy(filt + flen, w, wl);
        flen += wl;
        filt[flen++] = '=';
        if (q) filt[flen++] = '"';
        memcpy(filt + flen, v, vl);
        flen += vl;
        if (q) filt[flen++] = '"';
        filt[flen] = '\0';
        skip_ws(p);
        if (p->sc.s[p->sc.pos] == ',') {
            p->sc.pos++;
            continue;
        }
        if (p->sc.s[p->sc.pos] == ']') {
            p->sc.pos++;
            break;
        }
        char b[8];
        rc = !p->sc.s[p->sc.pos] ? perr(p, p->sc.pos, "expected ']' to close the '[' at column %zu",
                                  open + 1)
                           : perr(p, p->sc.pos, "expected ',' or ']', found %s",
                                  describe(p, b, sizeof b));
        break;
    }
    if (rc == ES_OK) rc = add_term(p, 1.0, ES_POINT_MEAN, filt, flen, 0, f);
    es__free(p->ctx, filt);
    return rc;
}

static es_status parse_lerp(parser *p, form *f, size_t at)
{
    form a, b, t;
    es_status rc;
    size_t pa, pb, pt;
    if ((rc = expect(p, '(')) != ES_OK) return rc;
    skip_ws(p);
    pa = p->sc.pos;
    if ((rc = parse_sum(p, &a)) != ES_OK || (rc = expect(p, ',')) != ES_OK) return rc;
    skip_ws(p);
    pb = p->sc.pos;
    if ((rc = parse_sum(p, &b)) != ES_OK || (rc = expect(p, ',')) != ES_OK) return rc;
    skip_ws(p);
    pt = p->sc.pos;
    if ((rc = parse_sum(p, &t)) != ES_OK || (rc = expect(p, ')')) != ES_OK) return rc;
    if (a.is_num) return perr(p, pa, "the first argument of lerp must be a point");
    if (b.is_num) return perr(p, pb, "the second argument of lerp must be a point");
    if (!t.is_num) return perr(p, pt, "the third argument of lerp must be a number");
    (void)at;
    /* terms of a precede those of b precede those of t (none) */
    scale_form(p, &a, 1.0 - t.num);
    scale_form(p, &b, t.num);
    f->is_num = 0;
    f->t0 = a.t0;
    f->t1 = b.t1;
    return ES_OK;
}

static es_status parse_primary(parser *p, form *f)
{
    skip_ws(p);
    size_t at = p->sc.pos;
    char c = p->sc.s[at];
    if (isdigit((unsigned char)c) || c == '.') return parse_number(p, f);
    if (c == '(') {
        p->sc.pos++;
        es_status rc = parse_sum(p, f);
        if (rc != ES_OK) return rc;
        return es__scan_expect_close(&p->sc, '(', ')', at);
    }
    if (!isalpha((unsigned char)c)) {
        char b[8];
        return perr(p, at, "expected a point or a number, found %s", describe(p, b, sizeof b));
    }
    size_t n = es__scan_span(&p->sc, es__scan_ident_char);
    const char *name = p->sc.s + at;
#define IS(lit) (n == sizeof(lit) - 1 && !memcmp(name, lit, n))
    if (IS("mean")) return parse_mean(p, f);
    if (IS("lerp")) return parse_lerp(p, f, at);
    if (IS("coef")) {
        /* coef:MODEL:COEF, stored as "MODEL/COEF" (a model name has no '/') */
        const char *mw = NULL, *cw = NULL;
        size_t ml = 0, cl = 0;
        es_status rc;
        if (p->sc.s[p->sc.pos] != ':') return perr(p, p->sc.pos, "expected ':' after 'coef'");
        p->sc.pos++;
        if ((rc = word(p, is_id_char, "a model name", &mw, &ml)) != ES_OK) return rc;
        if (memchr(mw, '/', ml)) return perr(p, at + 5, "a model name cannot contain '/'");
        if (p->sc.s[p->sc.pos] != ':')
            return perr(p, p->sc.pos, "expected ':' and a coefficient after 'coef:%.*s' "
                        "(coef:MODEL:COEF)", (int)ml, mw);
        p->sc.pos++;
        if ((rc = word(p, coef_char, "a coefficient name", &cw, &cl)) != ES_OK) return rc;
        char *a = es__malloc(p->ctx, ml + cl + 2);
        if (!a) return ES_ENOMEM;
        memcpy(a, mw, ml);
        a[ml] = '/';
        memcpy(a + ml + 1, cw, cl);
        rc = add_term(p, 1.0, ES_POINT_COEF, a, ml + cl + 1, 0, f);
        es__free(p->ctx, a);
        return rc;
    }
    if (IS("row") || IS("file") || IS("pc") || IS("diff")) {
        if (p->sc.s[p->sc.pos] != ':')
            return perr(p, p->sc.pos, "expected ':' after '%.*s'", (int)n, name);
        p->sc.pos++;
        const char *w = NULL;
        size_t wl = 0, wat = p->sc.pos;
        es_status rc;
        if (IS("row")) {
            if ((rc = word(p, is_id_char, "a row id", &w, &wl)) != ES_OK)
                return rc;
            return add_term(p, 1.0, ES_POINT_ROW, w, wl, 0, f);
        }
        if (IS("diff")) {
            if ((rc = word(p, is_id_char, "a difference name", &w, &wl)) != ES_OK)
                return rc;
            return add_term(p, 1.0, ES_POINT_DIFF, w, wl, 0, f);
        }
        if (IS("file")) {
            if ((rc = word(p, path_char, "a mesh file path", &w, &wl)) != ES_OK) return rc;
            if (!has_mesh_ext(w, wl))
                return perr(p, wat, "expected a mesh file path ending in .obj, .ply or .off, "
                            "found '%.*s'", (int)wl, w);
            return add_term(p, 1.0, ES_POINT_FILE, w, wl, 0, f);
        }
        /* pc:K (the PCA of --pca) or pc:NAME:K (the PCA named inline, as
         * coef:MODEL:COEF names its model). Digits not followed by ':' are
         * K, so pc:1-row:a stays pc:1 minus row:a. */
        size_t j = p->sc.pos;
        while (isdigit((unsigned char)p->sc.s[j])) j++;
        if (j == p->sc.pos || p->sc.s[j] == ':') {
            if ((rc = word(p, is_id_char, "a PCA name or a component number", &w, &wl)) != ES_OK)
                return rc;
            if (p->sc.s[p->sc.pos] != ':')
                return perr(p, p->sc.pos, "expected ':' and a component number after 'pc:%.*s' "
                            "(pc:K or pc:NAME:K)", (int)wl, w);
            wat = ++p->sc.pos;
        }
        int64_t k = 0;
        j = p->sc.pos;
        while (isdigit((unsigned char)p->sc.s[j]) && k < 1000000000) k = 10 * k + (p->sc.s[j++] - '0');
        if (j == p->sc.pos || k < 1 || isalnum((unsigned char)p->sc.s[j]) || p->sc.s[j] == '_' ||
            p->sc.s[j] == '.')
            return perr(p, wat, "expected a component number >= 1 after 'pc:%.*s%s'",
                        (int)wl, w ? w : "", w ? ":" : "");
        p->sc.pos = j;
        return add_term(p, 1.0, ES_POINT_PC, w ? w : "", wl, k, f);
    }
#undef IS
    return perr(p, at, "unknown name '%.*s' (expected mean, row:, file:, pc:, diff:, coef: "
                "or lerp)", (int)n, name);
}

static es_status parse_unary(parser *p, form *f)
{
    skip_ws(p);
    char c = p->sc.s[p->sc.pos];
    if (c == '-' || c == '+') {
        if (++p->depth > MAX_DEPTH) return perr(p, p->sc.pos, "expression nested too deeply");
        p->sc.pos++;
        es_status rc = parse_unary(p, f);
        p->depth--;
        if (rc == ES_OK && c == '-') scale_form(p, f, -1.0);
        return rc;
    }
    if (++p->depth > MAX_DEPTH) return perr(p, p->sc.pos, "expression nested too deeply");
    es_status rc = parse_primary(p, f);
    p->depth--;
    return rc;
}

/* A number followed by something that starts a point or a number: the
 * multiplication sign was left out ("2 pc:1"). */
static es_status missing_star(parser *p, const form *f)
{
    char c = p->sc.s[p->sc.pos];
    if (f->is_num && (isalpha((unsigned char)c) || isdigit((unsigned char)c) || c == '(' ||
                      c == '.'))
        return perr(p, p->sc.pos, "a '*' is missing between the number and what follows "
                    "(write 2*pc:1, not 2 pc:1)");
    return ES_OK;
}

static es_status parse_product(parser *p, form *f)
{
    es_status rc = parse_unary(p, f);
    while (rc == ES_OK) {
        skip_ws(p);
        if ((rc = missing_star(p, f)) != ES_OK) break;
        char op = p->sc.s[p->sc.pos];
        if (op != '*' && op != '/') break;
        size_t at = p->sc.pos++;
        form g;
        skip_ws(p);
        size_t gat = p->sc.pos;
        if ((rc = parse_unary(p, &g)) != ES_OK) break;
        if (op == '/') {
            if (!g.is_num) return perr(p, gat, "cannot divide by a point");
            if (g.num == 0) return perr(p, at, "division by zero");
            scale_form(p, f, 1.0 / g.num);
        } else if (f->is_num && g.is_num) {
            f->num *= g.num;
        } else if (f->is_num) {
            double c = f->num;
            *f = g;
            scale_form(p, f, c);
        } else if (g.is_num) {
            scale_form(p, f, g.num);
        } else {
            return perr(p, at, "cannot multiply two points");
        }
    }
    return rc;
}

static es_status parse_sum(parser *p, form *f)
{
    es_status rc = parse_product(p, f);
    while (rc == ES_OK) {
        skip_ws(p);
        char op = p->sc.s[p->sc.pos];
        if (op != '+' && op != '-') break;
        size_t at = p->sc.pos++;
        form g;
        if ((rc = parse_product(p, &g)) != ES_OK) break;
        if (f->is_num != g.is_num)
            return perr(p, at, "cannot %s a number and a point", op == '+' ? "add" : "subtract");
        if (f->is_num) {
            f->num = op == '+' ? f->num + g.num : f->num - g.num;
        } else {
            if (op == '-') scale_form(p, &g, -1.0);
            f->t1 = g.t1;   /* g's terms follow f's */
        }
    }
    return rc;
}

void es_point_expr_free(es_point_expr *x)
{
    if (!x) return;
    for (int64_t i = 0; i < x->n; i++) es__free(x->ctx, x->t[i].arg);
    es__free(x->ctx, x->t);
    es__free(x->ctx, x);
}

static const char *leaf_prefix(es_point_leaf k)
{
    switch (k) {
    case ES_POINT_MEAN: return "mean";
    case ES_POINT_ROW: return "row:";
    case ES_POINT_FILE: return "file:";
    case ES_POINT_PC: return "pc:";
    case ES_POINT_DIFF: return "diff:";
    case ES_POINT_COEF: return "coef:";
    }
    return "?";
}

es_status es_point_parse(es_ctx *ctx, const char *text, es_point_expr **out)
{
    *out = NULL;
    if (!text) ES_FAIL(ctx, ES_EINVAL, "point: no expression");
    es_point_expr *x = es__calloc(ctx, 1, sizeof *x);
    if (!x) return ES_ENOMEM;
    x->ctx = ctx;
    parser p = {ctx, {0}, x, 0};
    form f;
    es__scan_init(&p.sc, ctx, text, "point", "the end of the expression", ES__SCAN_SPACE_BLANKS);
    es_status rc = parse_sum(&p, &f);
    if (rc == ES_OK) {
        skip_ws(&p);
        if (text[p.sc.pos]) {
            char b[8];
            rc = perr(&p, p.sc.pos, "unexpected %s after the end of the expression",
                      describe(&p, b, sizeof b));
        } else if (f.is_num) {
            rc = perr(&p, 0, "the expression is a number, not a point");
        }
    }
    /* 1e300*1e300*mean: each number is finite, their product is not */
    for (int64_t i = 0; rc == ES_OK && i < x->n; i++)
        if (!isfinite(x->t[i].coef))
            rc = es__fail(ctx, ES_ERANGE, "point: the coefficient of term %lld (%s%s) "
                          "overflows", (long long)i + 1, leaf_prefix(x->t[i].kind),
                          x->t[i].arg ? x->t[i].arg : "");
    if (rc != ES_OK) {
        es_point_expr_free(x);
        return rc;
    }
    *out = x;
    return ES_OK;
}

int64_t es_point_expr_nterms(const es_point_expr *x) { return x ? x->n : 0; }

void es_point_expr_term(const es_point_expr *x, int64_t i, double *coef, es_point_leaf *kind,
                        const char **arg, int64_t *index)
{
    const term *t = &x->t[i];
    if (coef) *coef = t->coef;
    if (kind) *kind = t->kind;
    if (arg) *arg = t->arg;
    if (index) *index = t->index;
}


es_status es_point_eval(es_ctx *ctx, const es_point_expr *x, int64_t E,
                        es_point_resolve_fn resolve, void *ud, const es_mesh *mesh, double *vec,
                        es_point_info *info)
{
    return es_point_eval_rows(ctx, x, E, 0, resolve, ud, mesh, vec, NULL, info);
}

es_status es_point_eval_rows(es_ctx *ctx, const es_point_expr *x, int64_t E, int64_t nrows,
                             es_point_resolve_fn resolve, void *ud, const es_mesh *mesh,
                             double *vec, double *weights, es_point_info *info)
{
    if (!x || !resolve || !vec || E < 1)
        ES_FAIL(ctx, ES_EINVAL, "point: nothing to evaluate");
    if (weights && nrows < 1) ES_FAIL(ctx, ES_EINVAL, "point: row weights of %lld rows",
                                      (long long)nrows);
    if (!weights) nrows = 0;
    if (mesh && es_mesh_nedges(mesh) != E)
        ES_FAIL(ctx, ES_EMISMATCH, "point: %lld edges, the mesh has %lld", (long long)E,
                (long long)es_mesh_nedges(mesh));
    double *leaf = es__alloc_array(ctx, E + nrows, sizeof *leaf);
    double *lw = weights ? leaf + E : NULL;   /* the leaf's row weights */
    if (!leaf) return ES_ENOMEM;
    if (weights) memset(weights, 0, (size_t)nrows * sizeof *weights);
    es_point_info in;
    memset(&in, 0, sizeof in);
    in.scale = NAN;
    double wscale = 0;
    memset(vec, 0, (size_t)E * sizeof *vec);
    for (int64_t i = 0; i < x->n; i++) {
        const term *t = &x->t[i];
        double s = NAN;
        if (lw) memset(lw, 0, (size_t)nrows * sizeof *lw);
        es_status rc = resolve(ctx, ud, t->kind, t->arg, t->index, leaf, &s, lw);
        if (rc != ES_OK) {
            char msg[1024];
            snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
            es__free(ctx, leaf);
            if (t->kind == ES_POINT_PC)
                ES_FAIL(ctx, rc, "point: pc:%s%s%lld: %s", t->arg, *t->arg ? ":" : "",
                        (long long)t->index, msg);
            if (t->kind == ES_POINT_MEAN)
                ES_FAIL(ctx, rc, "point: mean%s%s%s: %s", *t->arg ? "[" : "", t->arg,
                        *t->arg ? "]" : "", msg);
            if (t->kind == ES_POINT_COEF) {
                const char *slash = strchr(t->arg, '/');
                ES_FAIL(ctx, rc, "point: coef:%.*s:%s: %s", (int)(slash - t->arg), t->arg,
                        slash + 1, msg);
            }
            ES_FAIL(ctx, rc, "point: %s%s: %s", leaf_prefix(t->kind), t->arg, msg);
        }
        double c = t->coef;
        if (t->kind == ES_POINT_PC) {
            if (!(s >= 0) || !isfinite(s)) {
                es__free(ctx, leaf);
                ES_FAIL(ctx, ES_ENUMERIC, "point: pc:%s%s%lld: standard deviation is %g",
                        t->arg, *t->arg ? ":" : "", (long long)t->index, s);
            }
            c *= s;
            in.ndirections++;
        } else if (t->kind == ES_POINT_DIFF || t->kind == ES_POINT_COEF) {
            in.ndirections++;
        } else {
            if (!(s > 0) || !isfinite(s)) {
                es__free(ctx, leaf);
                ES_FAIL(ctx, ES_EINVAL, "point: %s%s: scale is %g, not positive",
                        leaf_prefix(t->kind), t->arg, s);
            }
            in.weight += t->coef;
            wscale += t->coef * s;
            in.nshapes++;
        }
        for (int64_t e = 0; e < E; e++) vec[e] += c * leaf[e];
        for (int64_t r = 0; r < nrows; r++) weights[r] += c * lw[r];
    }
    es__free(ctx, leaf);
    for (int64_t e = 0; e < E; e++) in.length_sum += vec[e];
    if (in.weight != 0) in.scale = wscale / in.weight;
    /* finite terms can still sum past the largest double: such a point is
     * refused here, not stored for a later step to trip over */
    for (int64_t e = 0; e < E; e++)
        if (!isfinite(vec[e]))
            ES_FAIL(ctx, ES_ERANGE, "point: the length of edge %lld overflows (%g): the "
                    "coefficients are too large", (long long)e, vec[e]);
    for (int64_t r = 0; r < nrows; r++)
        if (!isfinite(weights[r]))
            ES_FAIL(ctx, ES_ERANGE, "point: the weight of row %lld overflows (%g): the "
                    "coefficients are too large", (long long)r, weights[r]);
    if (!isfinite(in.weight) || (in.weight != 0 && !isfinite(in.scale)))
        ES_FAIL(ctx, ES_ERANGE, "point: the shapes' weights (sum %g) or scale (%g) overflow: "
                "the coefficients are too large", in.weight, in.scale);
    if (fabs(in.weight - 1.0) > 1e-12)
        es__warn(ctx, "point: the shapes' weights sum to %g, not 1: the lengths sum to %g",
                 in.weight, in.length_sum);
    if (mesh) {
        es_status rc = es_lengths_check(ctx, mesh, vec, 0.0, &in.validity);
        if (rc != ES_OK) return rc;
        in.checked = 1;
    }
    if (info) *info = in;
    return ES_OK;
}
