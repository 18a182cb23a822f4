/* lib/procrustes/compare_study.c — the GPA-vs-edge-length comparison study as
 * one call on arrays (its tables: lib/study/compare_tables.c; its figures:
 * lib/figure/compare_figures.c).
 *
 * The study of the paper's Section 4 (Figs. 7-8): the same shapes measured
 * in scale-normalized edge-length space and in Procrustes space (Euclidean
 * distances of GPA-aligned configurations). It runs the statistics of
 * compare.c on both distance matrices and writes what a morphometrician
 * reads: the matrices, every pair with both distances and its group pair,
 * the disagreeing pairs, nearest neighbours, group-mean distances with
 * permutation p-values.
 */
#include "core/core_private.h"
#include "edgespace/es_compare.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

void es_compare_opts_init(es_compare_opts *opts)
{
    opts->permutations = 999;
    opts->top_pairs = 20;
    opts->normalize_lengths = 1;
}

void es_compare_result_free(es_compare_result *res)
{
    if (!res) return;
    es_ctx *ctx = res->ctx;
    es__free(ctx, res->d_len);
    es__free(ctx, res->d_rho);
    es__free(ctx, res->nn_len);
    es__free(ctx, res->top_pairs);
    es__free(ctx, res->top_diff);
    es__free(ctx, res->mean_len);
    for (int64_t i = 0; res->ids && i < res->n; i++) es__free(ctx, res->ids[i]);
    for (int64_t g = 0; res->group_names && g < res->ngroups; g++) es__free(ctx, res->group_names[g]);
    es__free(ctx, res->ids);
    es__free(ctx, res->group);
    es__free(ctx, res->group_names);
    es__free(ctx, res);
}

es_status es_compare_study(es_ctx *ctx, es_mat lengths, es_mat aligned, const int64_t *group,
                           int64_t ngroups, const es_compare_opts *opts, es_compare_result **out)
{
    es_compare_opts o;
    es_status rc;
    int64_t n = lengths.cols;
    *out = NULL;
    if (opts) o = *opts; else es_compare_opts_init(&o);
    if (aligned.cols != n)
        ES_FAIL(ctx, ES_EMISMATCH, "compare: %lld edge-length vectors but %lld configurations",
                (long long)n, (long long)aligned.cols);
    if (n < 3) ES_FAIL(ctx, ES_EINVAL, "compare: needs at least 3 shapes, got %lld", (long long)n);
    if ((group == NULL) != (ngroups == 0))
        ES_FAIL(ctx, ES_EINVAL, "compare: group labels and group count must come together");
    es_compare_result *r = es__calloc(ctx, 1, sizeof *r);
    if (!r) return ES_ENOMEM;
    r->ctx = ctx;
    r->n = n;
    r->normalized_lengths = o.normalize_lengths != 0;
    int64_t m = n * (n - 1) / 2;
    r->ntop = o.top_pairs < m ? (o.top_pairs > 0 ? o.top_pairs : 0) : m;
    r->d_len = es__alloc_array(ctx, 2 * n * n, sizeof *r->d_len);
    r->nn_len = es__alloc_array(ctx, 2 * n, sizeof *r->nn_len);
    r->top_pairs = es__alloc_array(ctx, 2 * (r->ntop > 0 ? r->ntop : 1), sizeof *r->top_pairs);
    r->top_diff = es__alloc_array(ctx, r->ntop > 0 ? r->ntop : 1, sizeof *r->top_diff);
    if (!r->d_len || !r->nn_len || !r->top_pairs || !r->top_diff) { rc = ES_ENOMEM; goto fail; }
    r->d_proc = r->d_len + n * n;
    r->nn_proc = r->nn_len + n;
    es__progress(ctx, "compare", 0, 4);
    if ((rc = es_compare_distances(ctx, lengths, o.normalize_lengths,
                                   (es_mat){r->d_len, n, n, n})) != ES_OK ||
        (rc = es_compare_distances(ctx, aligned, 0, (es_mat){r->d_proc, n, n, n})) != ES_OK)
        goto fail;
    es__progress(ctx, "compare", 1, 4);
    if ((rc = es_compare_mantel(ctx, n, r->d_len, r->d_proc, o.permutations, &r->mantel_rho,
                                &r->mantel_p)) != ES_OK ||
        (rc = es_compare_nn_agreement(ctx, n, r->d_len, r->d_proc, r->nn_len, r->nn_proc,
                                      &r->nn_agreement)) != ES_OK ||
        (rc = es_compare_disagreement(ctx, n, r->d_len, r->d_proc, r->ntop, r->top_pairs,
                                      r->top_diff)) != ES_OK)
        goto fail;
    es__progress(ctx, "compare", 2, 4);
    if (ngroups > 0) {
        int64_t gg = ngroups * ngroups;
        r->ngroups = ngroups;
        r->mean_len = es__alloc_array(ctx, 4 * gg, sizeof *r->mean_len);
        if (!r->mean_len) { rc = ES_ENOMEM; goto fail; }
        r->mean_proc = r->mean_len + gg;
        r->p_len = r->mean_proc + gg;
        r->p_proc = r->p_len + gg;
        if ((rc = es_compare_groups(ctx, n, r->d_len, group, ngroups, o.permutations,
                                    r->mean_len, r->p_len, &r->groups_len)) != ES_OK ||
            (rc = es_compare_groups(ctx, n, r->d_proc, group, ngroups, o.permutations,
                                    r->mean_proc, r->p_proc, &r->groups_proc)) != ES_OK)
            goto fail;
    }
    es__progress(ctx, "compare", 4, 4);
    *out = r;
    return ES_OK;
fail:
    es_compare_result_free(r);
    return rc;
}

/* "a|b" with the names in order, for the scatter's legend. */
char *es_compare_pair_label(es_ctx *ctx, const char *a, const char *b)
{
    if (strcmp(a, b) > 0) { const char *t = a; a = b; b = t; }
    size_t la = strlen(a), lb = strlen(b);
    char *s = es__malloc(ctx, la + lb + 2);
    if (!s) return NULL;
    memcpy(s, a, la);
    s[la] = '|';
    memcpy(s + la + 1, b, lb + 1);
    return s;
}
