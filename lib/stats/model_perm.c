/* lib/stats/model_perm.c — the permutations of the model tests and the
 * false discovery rate of many tests.
 *
 * Permutations are drawn one at a time from the library's seeded RNG
 * (es_rng), Fisher-Yates within each block, so that the fit, the pairwise
 * comparisons and the per-edge tests can replay the same sequence term by
 * term without holding it, and a test can hand the very same permutations
 * to R (es_model_permutations). Blocks restrict the exchanges to rows of
 * one subject: the repeated-measures design of RRPP's `block` and vegan's
 * `strata`.
 */
#include "stats/stats_pkg.h"

#include <math.h>
#include <stdlib.h>

void es__perm_clear(es_ctx *ctx, es__perm *g)
{
    es__free(ctx, g->rows);
    es__free(ctx, g->start);
    es__free(ctx, g->buf);
    g->rows = g->start = g->buf = NULL;
}

typedef struct brow { int64_t block, row; } brow;

static int cmp_brow(const void *a, const void *b)
{
    const brow *x = a, *y = b;
    if (x->block != y->block) return x->block < y->block ? -1 : 1;
    return (x->row > y->row) - (x->row < y->row);
}

es_status es__perm_init(es_ctx *ctx, es__perm *g, int64_t n, const int64_t *blocks,
                        uint64_t seed)
{
    memset(g, 0, sizeof *g);
    if (n < 1) ES_FAIL(ctx, ES_EINVAL, "permutations: %lld rows", (long long)n);
    g->n = n;
    es_rng_init(&g->rng, seed);
    g->rows = es__alloc_array(ctx, n, sizeof *g->rows);
    g->start = es__alloc_array(ctx, n + 1, sizeof *g->start);
    g->buf = es__alloc_array(ctx, n, sizeof *g->buf);
    brow *br = es__alloc_array(ctx, n, sizeof *br);
    es_status rc = ES_OK;
    if (!g->rows || !g->start || !g->buf || !br) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < n; i++) {
        if (blocks && blocks[i] < 0) {
            rc = es__fail(ctx, ES_EINVAL, "permutations: row %lld has block %lld (< 0)",
                          (long long)i, (long long)blocks[i]);
            goto done;
        }
        br[i] = (brow){blocks ? blocks[i] : 0, i};
    }
    qsort(br, (size_t)n, sizeof *br, cmp_brow);
    for (int64_t i = 0; i < n; i++) {
        g->rows[i] = br[i].row;
        if (i == 0 || br[i].block != br[i - 1].block) g->start[g->nblocks++] = i;
    }
    g->start[g->nblocks] = n;
done:
    es__free(ctx, br);
    if (rc != ES_OK) es__perm_clear(ctx, g);
    return rc;
}

void es__perm_next(es__perm *g, int64_t *perm)
{
    for (int64_t b = 0; b < g->nblocks; b++) {
        const int64_t s = g->start[b], len = g->start[b + 1] - s;
        int64_t *v = g->buf + s;
        memcpy(v, g->rows + s, (size_t)len * sizeof *v);
        for (int64_t k = len - 1; k > 0; k--) {
            int64_t j = (int64_t)es_rng_below(&g->rng, (uint64_t)k + 1);
            int64_t t = v[k];
            v[k] = v[j];
            v[j] = t;
        }
        for (int64_t k = 0; k < len; k++) perm[g->rows[s + k]] = v[k];
    }
}

es_status es_model_permutations(es_ctx *ctx, int64_t n, const int64_t *blocks, uint64_t seed,
                                int64_t count, int64_t *out)
{
    es__perm g;
    if (count < 0 || (count > 0 && !out))
        ES_FAIL(ctx, ES_EINVAL, "permutations: %lld asked", (long long)count);
    es_status rc = es__perm_init(ctx, &g, n, blocks, seed);
    if (rc != ES_OK) return rc;
    for (int64_t b = 0; b < count; b++) es__perm_next(&g, out + b * n);
    es__perm_clear(ctx, &g);
    return ES_OK;
}

typedef struct pidx { double p; int64_t i; } pidx;

static int cmp_pidx(const void *a, const void *b)
{
    const pidx *x = a, *y = b;
    if (x->p != y->p) return x->p < y->p ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

es_status es_fdr_bh(es_ctx *ctx, int64_t n, const double *p, double *q)
{
    if (n < 0 || (n > 0 && (!p || !q))) ES_FAIL(ctx, ES_EINVAL, "fdr: bad arguments");
    pidx *s = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *s);
    if (!s) return ES_ENOMEM;
    int64_t m = 0;
    for (int64_t i = 0; i < n; i++) {
        if (isnan(p[i])) continue;
        if (p[i] < 0 || p[i] > 1) {
            es__free(ctx, s);
            ES_FAIL(ctx, ES_EINVAL, "fdr: p-value %lld is %g, not in [0, 1]", (long long)i, p[i]);
        }
        s[m++] = (pidx){p[i], i};
    }
    qsort(s, (size_t)m, sizeof *s, cmp_pidx);
    /* q_(k) = min over j >= k of m p_(j) / j, capped at 1 */
    double run = 1.0;
    for (int64_t k = m - 1; k >= 0; k--) {
        double v = (double)m * s[k].p / (double)(k + 1);
        if (v < run) run = v;
        s[k].p = run;
    }
    for (int64_t i = 0; i < n; i++) q[i] = NAN;
    for (int64_t k = 0; k < m; k++) q[s[k].i] = s[k].p;
    es__free(ctx, s);
    return ES_OK;
}
