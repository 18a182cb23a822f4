/* tests/fuzz/fuzz_formula.c — libFuzzer target of the model formulas
 * (es_formula_parse_checked, then es_design_build on 8 rows). Columns are
 * the names of up to 3 characters starting with a letter, plus `size`:
 * those starting a-m are numbers (positive, so log() applies), the others
 * labels of 2 or 3 levels; any other name is an unknown column. A formula
 * that parses has 1 to ES_FORMULA_MAX_TERMS terms, each with a label and
 * variables it names; a design keeps them or names each it left out (no
 * rank added) with its reason; every refusal (parse or design) is one line
 * starting "formula: " or "model: ". The target's per-input time limit is two
 * seconds (tests/fuzz/meson.build): "~ v1*...*v18" used to expand for
 * minutes.
 * Seeds: tests/data/fuzz-formula. */
#include "fuzz_util.h"

#include "edgespace/es_model.h"

enum { N = 8 };

static int known(void *ud, const char *name, char *why, size_t n)
{
    size_t len = strlen(name);
    (void)ud;
    if (!strcmp(name, "size") ||
        (len >= 1 && len <= 3 && ((name[0] >= 'a' && name[0] <= 'z') ||
                                  (name[0] >= 'A' && name[0] <= 'Z'))))
        return 1;
    snprintf(why, n, "no label column '%.40s'", name);
    return 0;
}

static void check_refusal(es_ctx *ctx)
{
    const char *m = es_ctx_errmsg(ctx);
    if (!m || strchr(m, '\n') || (strncmp(m, "formula: ", 9) && strncmp(m, "model: ", 7)))
        __builtin_trap();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const labels[3][N] = {
        {"a", "b", "a", "b", "a", "b", "a", "b"},
        {"x", "y", "z", "x", "y", "z", "x", "y"},
        {"p", "p", "q", "q", "p", "q", "p", "q"}};
    static const double values[N] = {1, 2, 3, 5, 8, 13, 21, 34};
    es_ctx *ctx = fuzz_ctx();
    es_formula *f = NULL;
    es_design *d = NULL;
    es_model_column cols[64];
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    if (es_formula_parse_checked(ctx, text, known, NULL, &f) != ES_OK) {
        if (f) __builtin_trap();
        check_refusal(ctx);
        free(text);
        return 0;
    }
    int64_t nt = es_formula_nterms(f), nv = es_formula_nvars(f);
    if (!f || nt < 1 || nt > ES_FORMULA_MAX_TERMS || nv < 1 || nv > 64) __builtin_trap();
    for (int64_t j = 0; j < nt; j++)
        if (!es_formula_term(f, j) || !*es_formula_term(f, j)) __builtin_trap();
    for (int64_t v = 0; v < nv; v++) {
        const char *name = es_formula_var(f, v, NULL);
        if (!name || !known(NULL, name, NULL, 0)) __builtin_trap();
        cols[v].name = name;
        cols[v].labels = NULL;
        cols[v].values = NULL;
        if ((name[0] | 0x20) <= 'm') cols[v].values = values;
        else cols[v].labels = labels[(unsigned char)name[0] % 3];
        /* a baseline level for odd first letters (es_model_column grew the
         * field: left unset, the harness handed design.c a wild pointer);
         * a numeric column's is refused, factor(numeric)'s is no level */
        cols[v].reference = NULL;
        if (name[0] & 1) cols[v].reference = cols[v].labels ? cols[v].labels[1] : "a";
    }
    if (es_design_build(ctx, f, N, cols, nv, ES_CONTRASTS_TREATMENT, &d) == ES_OK) {
        /* terms that add no rank are left out, each named with its reason */
        if (!d || d->ncols < 1 || d->nterms < 1 || d->nterms + d->ndropped != nt)
            __builtin_trap();
        for (int64_t j = 0; j < d->ndropped; j++)
            if (!d->dropped[j] || !d->dropped_why[j] || !*d->dropped_why[j]) __builtin_trap();
    } else {
        if (d) __builtin_trap();
        check_refusal(ctx);
    }
    es_design_free(d);
    es_formula_free(f);
    free(text);
    return 0;
}
