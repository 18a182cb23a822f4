/* tests/fuzz/fuzz_point.c — libFuzzer target of the point syntax
 * (es_point_parse, then es_point_eval_rows with a resolver of known leaves
 * on a 3-edge space of 4 rows). An expression that evaluates gives finite
 * lengths, weights and scale (overflowing coefficients are refused); every
 * refusal is one line starting "point: ". Seeds: tests/data/fuzz-point. */
#include "fuzz_util.h"
#include "core/core_private.h"

#include <math.h>

enum { E = 3, R = 4 };

/* Every leaf resolves: rows and means to fixed lengths, pc:K to a
 * direction with standard deviation K, files and diffs to directions;
 * a leaf whose argument starts with '!' fails, as a missing row would. */
static es_status resolve(es_ctx *ctx, void *ud, es_point_leaf kind, const char *arg,
                         int64_t index, double *vec, double *scale, double *w)
{
    (void)ud;
    if (arg && arg[0] == '!') return es__fail(ctx, ES_ENOTFOUND, "no such leaf");
    for (int e = 0; e < E; e++) vec[e] = (e + 1 + (arg ? (double)strlen(arg) : 0)) / 10.0;
    *scale = kind == ES_POINT_PC ? (double)(index % 7) : 2.0;
    for (int r = 0; w && r < R; r++) w[r] = kind == ES_POINT_ROW ? (r == 0) : 0.25;
    return ES_OK;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    es_ctx *ctx = fuzz_ctx();
    es_point_expr *x = NULL;
    es_point_info info;
    double vec[E], w[R];
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    if (es_point_parse(ctx, text, &x) == ES_OK) {
        if (!x || es_point_expr_nterms(x) < 1) __builtin_trap();
        if (es_point_eval_rows(ctx, x, E, R, resolve, NULL, NULL, vec, w, &info) == ES_OK) {
            for (int e = 0; e < E; e++)
                if (!isfinite(vec[e])) __builtin_trap();
            for (int r = 0; r < R; r++)
                if (!isfinite(w[r])) __builtin_trap();
            if (info.nshapes > 0 && info.weight != 0 && !isfinite(info.scale)) __builtin_trap();
        } else {
            fuzz_check_message(ctx, "point: ");
        }
        es_point_expr_free(x);
    } else {
        if (x) __builtin_trap();
        fuzz_check_message(ctx, "point: ");
    }
    free(text);
    return 0;
}
