/* tests/stats/test_point.c — the point syntax: parsing into linear combinations,
 * evaluation through a resolver, scale rules, and every syntax error with
 * the column it points at. */
#include "es_test.h"
#include "core/core_private.h"
#include "edgespace/es_point.h"
#include "edgespace/es_mesh.h"

enum { E = 4 };

/* A resolver without a store: rows a (scale 10), b (scale 20), mean (scale
 * 15, or 12 for mean[g=x]), pc:k = unit vector k with sd 0.5 k, diff:d.
 * Row weights over three rows: a = row 0, b = row 1, mean = all three,
 * pc:k = k (1, -1, 0), diff = row 1 - row 0, file = (0.2, 0.3, 0.5). */
static es_status resolve(es_ctx *ctx, void *ud, es_point_leaf kind, const char *arg,
                         int64_t index, double *v, double *scale, double *w)
{
    int *calls = ud;
    double dummy[3];
    (*calls)++;
    memset(v, 0, E * sizeof *v);
    if (!w) w = dummy;
    switch (kind) {
    case ES_POINT_MEAN:
        for (int e = 0; e < E; e++) v[e] = 0.25;
        *scale = 15;
        w[0] = w[1] = w[2] = 1.0 / 3;
        if (!strcmp(arg, "g=x,h=y-1")) v[0] = 0.4, v[1] = 0.1, *scale = 12;
        else if (*arg) ES_FAIL(ctx, ES_ENOTFOUND, "no rows match '%s'", arg);
        return ES_OK;
    case ES_POINT_ROW:
        if (!strcmp(arg, "a")) { v[0] = 0.1; v[1] = 0.2; v[2] = 0.3; v[3] = 0.4; *scale = 10; w[0] = 1; return ES_OK; }
        if (!strcmp(arg, "s-1.b_2")) { v[0] = 0.4; v[1] = 0.3; v[2] = 0.2; v[3] = 0.1; *scale = 20; w[1] = 1; return ES_OK; }
        ES_FAIL(ctx, ES_ENOTFOUND, "no such row");
    case ES_POINT_FILE:
        for (int e = 0; e < E; e++) v[e] = 0.25;
        *scale = 30;
        w[0] = 0.2, w[1] = 0.3, w[2] = 0.5;
        return ES_OK;
    case ES_POINT_PC:
        if (index > E) ES_FAIL(ctx, ES_ENOTFOUND, "only %d components", E);
        v[index - 1] = 1;
        *scale = 0.5 * (double)index;
        w[0] = (double)index, w[1] = -(double)index;
        return ES_OK;
    case ES_POINT_DIFF:
        v[0] = 0.01;
        v[1] = -0.01;
        w[0] = -1, w[1] = 1;
        return ES_OK;
    case ES_POINT_COEF:
        /* coef:m:age and coef:m:"expression=happy:age" */
        if (strcmp(arg, "m/age") && strcmp(arg, "m/expression=happy:age"))
            ES_FAIL(ctx, ES_ENOTFOUND, "no coefficient '%s'", arg);
        v[2] = 0.02;
        v[3] = -0.02;
        w[1] = 0.5, w[2] = -0.5;
        return ES_OK;
    }
    return ES_EINVAL;
}

static void eval_ok(es_ctx *ctx, const char *text, const double want[E], double scale,
                    double weight)
{
    es_point_expr *x = NULL;
    int calls = 0;
    double v[E];
    es_point_info info;
    ES_CHECK_OK(ctx, es_point_parse(ctx, text, &x));
    if (!x) return;
    ES_CHECK_OK(ctx, es_point_eval(ctx, x, E, resolve, &calls, NULL, v, &info));
    ES_CHECK(calls == es_point_expr_nterms(x));
    for (int e = 0; e < E; e++) ES_CHECK_CLOSE(v[e], want[e], 1e-14, 1e-15);
    if (isnan(scale)) ES_CHECK_MSG(isnan(info.scale), "%s: scale %g", text, info.scale);
    else ES_CHECK_CLOSE(info.scale, scale, 1e-14, 0);
    ES_CHECK_CLOSE(info.weight, weight, 1e-14, 1e-15);
    es_point_expr_free(x);
}

static void test_eval(es_ctx *ctx)
{
    const double a[E] = {0.1, 0.2, 0.3, 0.4}, b[E] = {0.4, 0.3, 0.2, 0.1};
    double w[E];
    eval_ok(ctx, "mean", (double[E]){0.25, 0.25, 0.25, 0.25}, 15, 1);
    /* a coefficient is a direction: it keeps the mean's scale and weight */
    eval_ok(ctx, "mean + 2*coef:m:age", (double[E]){0.25, 0.25, 0.29, 0.21}, 15, 1);
    eval_ok(ctx, "mean - coef:m:expression=happy:age", (double[E]){0.25, 0.25, 0.23, 0.27}, 15,
            1);
    eval_ok(ctx, "mean + 2*pc:1", (double[E]){1.25, 0.25, 0.25, 0.25}, 15, 1);
    eval_ok(ctx, "mean - 3 * pc:2 / 2", (double[E]){0.25, -1.25, 0.25, 0.25}, 15, 1);
    eval_ok(ctx, "mean[ g = x , h=y-1 ] + diff:smile",
            (double[E]){0.41, 0.09, 0.25, 0.25}, 12, 1);
    for (int e = 0; e < E; e++) w[e] = 0.5 * a[e] + 0.5 * b[e];
    eval_ok(ctx, "0.5*row:a + 0.5*row:s-1.b_2", w, 15, 1);
    eval_ok(ctx, "row:a*0.5 + (row:s-1.b_2)/2", w, 15, 1);
    for (int e = 0; e < E; e++) w[e] = -0.5 * a[e] + 1.5 * b[e];
    eval_ok(ctx, "lerp(row:a, row:s-1.b_2, 1.5)", w, -0.5 * 10 + 1.5 * 20, 1);
    for (int e = 0; e < E; e++) w[e] = 1.25 * a[e] - 0.25 * b[e];
    eval_ok(ctx, "lerp(row:a, row:\"s-1.b_2\", -(1/4))", w, 1.25 * 10 - 0.25 * 20, 1);
    for (int e = 0; e < E; e++) w[e] = a[e] - b[e];
    eval_ok(ctx, "row:a - row:s-1.b_2", w, NAN, 0);       /* a direction: no scale */
    for (int e = 0; e < E; e++) w[e] = -a[e];
    eval_ok(ctx, "-row:a * -1 * -1", w, 10, -1);
    eval_ok(ctx, "--row:a", a, 10, 1);
    eval_ok(ctx, "file:dir/x-1.obj", (double[E]){0.25, 0.25, 0.25, 0.25}, 30, 1);
    eval_ok(ctx, "(file:\"my dir/x.ply\" + row:a) / 2",
            (double[E]){0.175, 0.225, 0.275, 0.325}, 20, 1);
    eval_ok(ctx, "mean+pc:1-pc:2", (double[E]){0.75, -0.75, 0.25, 0.25}, 15, 1);
    eval_ok(ctx, "1e-1*row:a*10", a, 10, 1);

    /* the folded form */
    es_point_expr *x = NULL;
    ES_CHECK_OK(ctx, es_point_parse(ctx, "lerp(mean, row:a, 3) - 2*(pc:3 + diff:smile)", &x));
    if (x) {
        ES_CHECK(es_point_expr_nterms(x) == 4);
        double c;
        es_point_leaf k;
        const char *arg;
        int64_t idx;
        es_point_expr_term(x, 0, &c, &k, &arg, &idx);
        ES_CHECK(k == ES_POINT_MEAN && c == -2 && !strcmp(arg, ""));
        es_point_expr_term(x, 1, &c, &k, &arg, &idx);
        ES_CHECK(k == ES_POINT_ROW && c == 3 && !strcmp(arg, "a"));
        es_point_expr_term(x, 2, &c, &k, &arg, &idx);
        ES_CHECK(k == ES_POINT_PC && c == -2 && idx == 3);
        es_point_expr_term(x, 3, &c, &k, &arg, &idx);
        ES_CHECK(k == ES_POINT_DIFF && c == -2 && !strcmp(arg, "smile"));
        es_point_expr_free(x);
    }
    /* pc:NAME:K names its PCA as coef:MODEL:COEF names its model (issue
     * 29); digits then ':' are a name, digits alone K (pc:1-row:a is pc:1
     * minus row:a, as before) */
    x = NULL;
    ES_CHECK_OK(ctx, es_point_parse(ctx, "pc:faces:2 - 0.5*pc:\"my pca\":1 + pc:2019:3 + "
                                         "pc:1-row:a", &x));
    if (x) {
        static const struct { const char *arg; int64_t k; double c; } want[] = {
            {"faces", 2, 1}, {"my pca", 1, -0.5}, {"2019", 3, 1}, {"", 1, 1}};
        ES_CHECK(es_point_expr_nterms(x) == 5);
        for (int i = 0; i < 4; i++) {
            double c;
            es_point_leaf k;
            const char *arg;
            int64_t idx;
            es_point_expr_term(x, i, &c, &k, &arg, &idx);
            ES_CHECK_MSG(k == ES_POINT_PC && idx == want[i].k && c == want[i].c &&
                         !strcmp(arg, want[i].arg), "term %d: '%s' %lld %g", i, arg,
                         (long long)idx, c);
        }
        es_point_expr_free(x);
    }
    /* a value holding ',' reaches the store quoted (es_store_select's
     * col="v"), others as written */
    static const struct { const char *text, *filter; } filters[] = {
        {"mean[grp=\"a,b\"]", "grp=\"a,b\""},
        {"mean[ g = x , grp = \"a,b\" ]", "g=x,grp=\"a,b\""},
        {"mean[grp=\"a b\"]", "grp=a b"},
        {"mean[\"my col\"=\"x=y\"]", "my col=x=y"},
    };
    for (size_t i = 0; i < sizeof filters / sizeof filters[0]; i++) {
        es_point_expr *y = NULL;
        ES_CHECK_OK(ctx, es_point_parse(ctx, filters[i].text, &y));
        if (!y) continue;
        double c;
        es_point_leaf k;
        const char *arg = NULL;
        int64_t idx;
        es_point_expr_term(y, 0, &c, &k, &arg, &idx);
        ES_CHECK_MSG(es_point_expr_nterms(y) == 1 && k == ES_POINT_MEAN &&
                     !strcmp(arg, filters[i].filter), "%s: filter '%s'", filters[i].text, arg);
        es_point_expr_free(y);
    }
    /* a failing leaf names itself */
    int calls = 0;
    double v[E];
    ES_CHECK_OK(ctx, es_point_parse(ctx, "mean + row:zz", &x));
    if (x) {
        ES_CHECK_FAILS(ctx, es_point_eval(ctx, x, E, resolve, &calls, NULL, v, NULL), ES_ENOTFOUND,
                       "point: row:zz: no such row");
        es_point_expr_free(x);
    }
    ES_CHECK_OK(ctx, es_point_parse(ctx, "mean[q=1] + pc:9", &x));
    if (x) {
        ES_CHECK_FAILS(ctx, es_point_eval(ctx, x, E, resolve, &calls, NULL, v, NULL), ES_ENOTFOUND,
                       "point: mean[q=1]: no rows match 'q=1'");
        es_point_expr_free(x);
    }
}

/* Every syntax error: ES_EFORMAT and the column in the message. */
/* Numbers that are finite alone but not together: refused, never a point
 * of infinite lengths (1e300*1e300*mean was stored, and gpa failed later). */
static void test_overflow(es_ctx *ctx)
{
    static const struct { const char *text, *msg; } cases[] = {
        {"1e300*1e300*mean", "the coefficient of term 1 (mean) overflows"},
        {"mean + 1e300*1e300*row:a", "the coefficient of term 2 (row:a) overflows"},
        {"row:a/1e-320", "overflows"},
        {"1e308*row:a + 1e308*row:a", "weights (sum inf)"},
        {"mean + 1e308*pc:2 + 1e308*pc:2", "the length of edge 1 overflows"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        es_point_expr *x = NULL;
        es_status rc = es_point_parse(ctx, cases[i].text, &x);
        if (rc == ES_OK) {
            int calls = 0;
            double v[E];
            rc = es_point_eval(ctx, x, E, resolve, &calls, NULL, v, NULL);
        }
        ES_CHECK_MSG(rc == ES_ERANGE && strstr(es_ctx_errmsg(ctx), cases[i].msg),
                     "'%s': %d %s", cases[i].text, (int)rc, es_ctx_errmsg(ctx));
        es_point_expr_free(x);
    }
}

static void test_errors(es_ctx *ctx)
{
    static const struct { const char *text, *msg; } cases[] = {
        {"", "column 1: expected a point or a number, found the end of the expression"},
        {"   ", "column 4: expected a point or a number"},
        {"mean +", "column 7: expected a point or a number, found the end"},
        {"mean + # ", "column 8: expected a point or a number, found '#'"},
        {"(mean + row:a", "column 14: expected ')' to close the '(' at column 1"},
        {"mean)", "column 5: unexpected ')' after the end of the expression"},
        {"mean mean", "column 6: unexpected 'm' after the end"},
        {"meen + pc:1", "column 1: unknown name 'meen'"},
        {"mean[", "column 6: expected a column name, found the end"},
        {"mean[g]", "column 7: expected '=' after the column name, found ']'"},
        {"mean[g=]", "column 8: expected a value, found ']'"},
        {"mean[g=x", "column 9: expected ']' to close the '[' at column 5"},
        {"mean[g=x;h=y]", "column 9: expected ',' or ']', found ';'"},
        {"mean[g=\"x]", "column 8: unterminated quoted string (expected a value)"},
        {"mean[\"g,h\"=x]", "column 6: a column name cannot contain ',' or '='"},
        {"mean[g=x, \"g=h\"=x]", "column 11: a column name cannot contain ',' or '='"},
        {"row a", "column 4: expected ':' after 'row'"},
        {"row:", "column 5: expected a row id, found the end"},
        {"row:+a", "column 5: expected a row id, found '+'"},
        {"row:\"\"", "column 5: expected a row id, found an empty string"},
        {"file:face.stl", "column 6: expected a mesh file path ending in .obj, .ply or .off"},
        {"pc:0", "column 4: expected a component number >= 1"},
        {"mean + pc:x", "column 12: expected ':' and a component number after 'pc:x' "
                        "(pc:K or pc:NAME:K)"},
        {"mean + pc:faces:", "column 17: expected a component number >= 1 after 'pc:faces:'"},
        {"mean + pc:faces:0", "column 17: expected a component number >= 1 after 'pc:faces:'"},
        {"pc:faces:1x", "column 10: expected a component number >= 1 after 'pc:faces:'"},
        {"mean + pc:2b", "column 11: expected a component number >= 1"},
        {"diff:", "column 6: expected a difference name"},
        {"2pc:1 + mean", "column 2: expected an operator after the number"},
        {"mean + 2 pc:1", "column 10: a '*' is missing between the number and what follows"},
        {"mean + 2 (pc:1)", "column 10: a '*' is missing"},
        {"coef:m", "column 7: expected ':' and a coefficient after 'coef:m'"},
        {"coef:m:", "column 8: expected a coefficient name"},
        {"coef m:a", "column 5: expected ':' after 'coef'"},
        {"1e+ * mean", "column 1: malformed number"},
        {". * mean", "column 1: malformed number"},
        {"lerp row:a", "column 6: expected '(', found 'r'"},
        {"lerp(row:a row:b, 0.5)", "column 12: expected ',', found 'r'"},
        {"lerp(row:a, row:b, 0.5", "column 23: expected ')', found the end"},
        {"lerp(row:a, row:b, mean)", "column 20: the third argument of lerp must be a number"},
        {"lerp(0.5, row:b, 1)", "column 6: the first argument of lerp must be a point"},
        {"lerp(row:a, 2, 1)", "column 13: the second argument of lerp must be a point"},
        {"mean + 1", "column 6: cannot add a number and a point"},
        {"2 - mean", "column 3: cannot subtract a number and a point"},
        {"row:a * row:b", "column 7: cannot multiply two points"},
        {"mean / row:a", "column 8: cannot divide by a point"},
        {"mean / (1 - 1)", "column 6: division by zero"},
        {"2 * (3 + 4)", "column 1: the expression is a number, not a point"},
        {"1e999 * mean", "column 1: number out of range"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        es_point_expr *x = (es_point_expr *)1;
        ES_CHECK_FAILS(ctx, es_point_parse(ctx, cases[i].text, &x), ES_EFORMAT, cases[i].msg);
        ES_CHECK(x == NULL);
        ES_CHECK_MSG(!strncmp(es_ctx_errmsg(ctx), "point: column ", 14), "%s", cases[i].text);
    }
    /* nesting is bounded, not a stack overflow */
    char deep[2000];
    memset(deep, '(', 1000);
    strcpy(deep + 1000, "mean");
    es_point_expr *x = NULL;
    ES_CHECK_FAILS(ctx, es_point_parse(ctx, deep, &x), ES_EFORMAT, "nested too deeply");
    memset(deep, '-', 1000);
    ES_CHECK_FAILS(ctx, es_point_parse(ctx, deep, &x), ES_EFORMAT, "nested too deeply");
}

/* Row weights follow the combination: each leaf's weights times its
 * coefficient (and a component's standard deviation), so the weights of a
 * point are those of the same expression over the rows. */
static void test_row_weights(es_ctx *ctx)
{
    static const struct { const char *text; double w[3]; } cases[] = {
        {"row:a", {1, 0, 0}},
        {"lerp(row:a, row:s-1.b_2, 0.25)", {0.75, 0.25, 0}},
        {"mean + 2*pc:1", {1.0 / 3 + 1, 1.0 / 3 - 1, 1.0 / 3}},   /* 2 x sd 0.5 x (1, -1, 0) */
        {"mean - pc:2", {1.0 / 3 - 2, 1.0 / 3 + 2, 1.0 / 3}},      /* sd 1 x 2 (1, -1, 0) */
        {"row:a + 0.5*diff:d", {0.5, 0.5, 0}},
        {"0.5*file:x.obj + 0.5*mean", {0.1 + 1.0 / 6, 0.15 + 1.0 / 6, 0.25 + 1.0 / 6}},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        es_point_expr *x = NULL;
        int calls = 0;
        double v[E], w[3] = {9, 9, 9};
        ES_CHECK_OK(ctx, es_point_parse(ctx, cases[c].text, &x));
        if (!x) continue;
        ES_CHECK_OK(ctx, es_point_eval_rows(ctx, x, E, 3, resolve, &calls, NULL, v, w, NULL));
        for (int i = 0; i < 3; i++)
            ES_CHECK_MSG(fabs(w[i] - cases[c].w[i]) < 1e-14, "%s: w[%d] = %.17g, want %.17g",
                         cases[c].text, i, w[i], cases[c].w[i]);
        es_point_expr_free(x);
    }
}

/* Validity: on one triangle, interpolating two valid rows stays valid,
 * extrapolating far enough breaks the triangle inequality. */
static es_status resolve_tri(es_ctx *ctx, void *ud, es_point_leaf kind, const char *arg,
                             int64_t index, double *v, double *scale, double *w)
{
    (void)ud, (void)index, (void)w;
    if (kind != ES_POINT_ROW) ES_FAIL(ctx, ES_EINVAL, "rows only");
    const double eq[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3}, flat[3] = {0.25, 0.25, 0.5};
    memcpy(v, !strcmp(arg, "eq") ? eq : flat, sizeof eq);
    *scale = 3;
    return ES_OK;
}

static void test_validity(es_ctx *ctx)
{
    const int64_t faces[3] = {0, 1, 2};
    es_mesh *m = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, 3, 1, faces, NULL, &m));
    if (!m) return;
    const struct { const char *text; int valid; } cases[] = {
        {"lerp(row:eq, row:flat, 0.5)", 1}, {"lerp(row:eq, row:flat, 1.5)", 0},
        {"row:eq", 1}, {"2*row:flat - 3*row:eq", 0}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        es_point_expr *x = NULL;
        es_point_info info;
        double v[3];
        ES_CHECK_OK(ctx, es_point_parse(ctx, cases[i].text, &x));
        if (!x) continue;
        ES_CHECK_OK(ctx, es_point_eval(ctx, x, 3, resolve_tri, NULL, m, v, &info));
        ES_CHECK(info.checked == 1);
        ES_CHECK_MSG(info.validity.valid == cases[i].valid, "%s", cases[i].text);
        if (!cases[i].valid) ES_CHECK(info.validity.n_bad_faces + info.validity.n_nonpositive > 0);
        ES_CHECK_FAILS(ctx, es_point_eval(ctx, x, 4, resolve_tri, NULL, m, v, &info),
                       ES_EMISMATCH, "mesh has 3");
        es_point_expr_free(x);
    }
    es_mesh_free(m);
}

/* Failing the k-th allocation: parse and evaluate fail cleanly with
 * ES_ENOMEM until they succeed (leaks show in the ASan build). */
static int64_t fail_at, nalloc;
static void *t_malloc(void *ud, size_t n) { (void)ud; return ++nalloc == fail_at ? NULL : malloc(n); }
static void *t_realloc(void *ud, void *q, size_t n) { (void)ud; return ++nalloc == fail_at ? NULL : realloc(q, n); }
static void t_free(void *ud, void *q) { (void)ud; free(q); }

static void test_alloc_failures(es_ctx *ctx)
{
    es_allocator al = {t_malloc, t_realloc, t_free, NULL};
    es_ctx_set_allocator(ctx, &al);
    es_status rc = ES_ENOMEM;
    for (fail_at = 1; rc == ES_ENOMEM && fail_at < 500; fail_at++) {
        nalloc = 0;
        es_point_expr *x = NULL;
        int calls = 0;
        double v[E];
        rc = es_point_parse(ctx, "lerp(mean[g=x,h=y-1], row:a, 2) + 0.5*(pc:1 - diff:d) + "
                            "row:a + row:a + row:a + row:a + row:a + row:a + row:a + row:a", &x);
        if (rc == ES_OK) rc = es_point_eval(ctx, x, E, resolve, &calls, NULL, v, NULL);
        es_point_expr_free(x);
        ES_CHECK(rc == ES_OK || rc == ES_ENOMEM);
    }
    ES_CHECK(rc == ES_OK && fail_at > 10);
    es_ctx_set_allocator(ctx, NULL);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_eval(ctx);
    test_errors(ctx);
    test_overflow(ctx);
    test_validity(ctx);
    test_row_weights(ctx);
    test_alloc_failures(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
