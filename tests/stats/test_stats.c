/* tests/stats/test_stats.c — means (all rows, subsets, groups), group labels,
 * paired differences: pairing logic, duplicates, unpaired rows, standard
 * errors against a direct computation. */
#include "es_test.h"
#include "core/core_private.h"
#include "edgespace/es_stats.h"

static void test_means(es_ctx *ctx)
{
    enum { E = 5, N = 9 };
    double X[E * N];
    for (int j = 0; j < N; j++)
        for (int e = 0; e < E; e++) X[e + j * E] = 0.2 + 0.01 * (double)((j * 7 + e * 3) % 11);
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    double m[E], want[E] = {0};
    for (int j = 0; j < N; j++)
        for (int e = 0; e < E; e++) want[e] += X[e + j * E] / N;
    for (int64_t b = 1; b <= N; b += 3) {
        src.block = b;
        ES_CHECK_OK(ctx, es_mean(ctx, &src, m));
        for (int e = 0; e < E; e++) ES_CHECK_CLOSE(m[e], want[e], 1e-14, 0);
    }
    /* subset: rows 8, 2, 5 */
    const int64_t rows[3] = {8, 2, 5};
    es_source sub = es_source_matrix((es_mat){X, E, N, E}, rows, 3);
    ES_CHECK(sub.nrows == 3);
    ES_CHECK_OK(ctx, es_mean(ctx, &sub, m));
    for (int e = 0; e < E; e++)
        ES_CHECK_CLOSE(m[e], (X[e + 8 * E] + X[e + 2 * E] + X[e + 5 * E]) / 3, 1e-14, 0);
    const int64_t bad[1] = {9};
    es_source oob = es_source_matrix((es_mat){X, E, N, E}, bad, 1);
    ES_CHECK_FAILS(ctx, es_mean(ctx, &oob, m), ES_ERANGE, "column 9");
    es_source empty = es_source_matrix((es_mat){X, E, 0, E}, NULL, 0);
    ES_CHECK_FAILS(ctx, es_mean(ctx, &empty, m), ES_EINVAL, "no rows");

    /* groups from labels, one pass */
    const char *lab[N] = {"b", "a", "b", NULL, "c", "a", "b", "a", NULL};
    int64_t *g = NULL, ng = 0;
    const char **names = NULL;
    ES_CHECK_OK(ctx, es_groups_from_labels(ctx, lab, N, &g, &names, &ng));
    ES_CHECK(ng == 3);
    if (ng == 3) {
        ES_CHECK(!strcmp(names[0], "b") && !strcmp(names[1], "a") && !strcmp(names[2], "c"));
        ES_CHECK(g[0] == 0 && g[1] == 1 && g[3] == -1 && g[4] == 2 && g[8] == -1);
        double gm[E * 4];
        int64_t cnt[4];
        ES_CHECK_OK(ctx, es_group_means(ctx, &src, g, 4, gm, cnt));
        ES_CHECK(cnt[0] == 3 && cnt[1] == 3 && cnt[2] == 1 && cnt[3] == 0);
        for (int e = 0; e < E; e++) {
            ES_CHECK_CLOSE(gm[e + E], (X[e + E] + X[e + 5 * E] + X[e + 7 * E]) / 3, 1e-14, 0);
            ES_CHECK_CLOSE(gm[e + 2 * E], X[e + 4 * E], 1e-15, 0);
            ES_CHECK(isnan(gm[e + 3 * E]));
        }
        g[2] = 4;
        ES_CHECK_FAILS(ctx, es_group_means(ctx, &src, g, 4, gm, cnt), ES_ERANGE, "row 2");
    }
    es_free(ctx, g);
    es_free(ctx, (void *)names);
}

static void test_diff(es_ctx *ctx)
{
    /* subjects s1..s4 with neutral (from) and happy (to); s4 lacks happy,
     * s5 has only happy; one angry row takes no part */
    enum { E = 3, N = 9 };
    const char *ids[N] = {"s1n", "s1h", "s2h", "s2n", "s3n", "s3h", "s4n", "s5h", "s1a"};
    const char *keys[N] = {"s1", "s1", "s2", "s2", "s3", "s3", "s4", "s5", "s1"};
    int role[N] = {0, 1, 1, 0, 0, 1, 0, 1, -1};
    double X[E * N];
    const double d[3][E] = {{0.01, -0.02, 0.0}, {0.03, -0.01, 0.0}, {0.02, -0.03, 0.0}};
    for (int j = 0; j < N; j++)
        for (int e = 0; e < E; e++) X[e + j * E] = 0.3 + 0.001 * (double)(j + e);
    /* to = from + d[pair] */
    const int fr[3] = {0, 3, 4}, to[3] = {1, 2, 5};
    for (int p = 0; p < 3; p++)
        for (int e = 0; e < E; e++) X[e + to[p] * E] = X[e + fr[p] * E] + d[p][e];
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    es_diff *df = NULL;
    ES_CHECK_OK(ctx, es_diff_paired(ctx, &src, keys, role, ids, &df));
    if (df) {
        ES_CHECK(df->npairs == 3);
        for (int p = 0; p < 3 && df->npairs == 3; p++)
            ES_CHECK(df->pair_from[p] == fr[p] && df->pair_to[p] == to[p]);
        ES_CHECK(df->nunpaired == 2);
        if (df->nunpaired == 2) ES_CHECK(df->unpaired[0] == 6 && df->unpaired[1] == 7);
        for (int e = 0; e < E; e++) {
            double m = (d[0][e] + d[1][e] + d[2][e]) / 3, v = 0;
            for (int p = 0; p < 3; p++) v += (d[p][e] - m) * (d[p][e] - m);
            double sd = sqrt(v / 2), se = sd / sqrt(3.0);
            ES_CHECK_CLOSE(df->mean[e], m, 1e-9, 1e-15);
            ES_CHECK_CLOSE(df->sd[e], sd, 1e-9, 1e-13);
            ES_CHECK_CLOSE(df->se[e], se, 1e-9, 1e-13);
            if (e < 2) ES_CHECK_CLOSE(df->t[e], m / se, 1e-8, 0);
        }
        /* edge 2 does not change: the t statistic is defined as 0 there, or
         * NaN if rounding left a nonzero mean */
        ES_CHECK(df->t[2] == 0 || isnan(df->t[2]) || fabs(df->t[2]) < 1e6);
        es_diff_free(df);
        df = NULL;
    }
    /* a duplicate: a second neutral row for s2 */
    role[8] = 0;
    keys[8] = "s2";
    ES_CHECK_FAILS(ctx, es_diff_paired(ctx, &src, keys, role, ids, &df), ES_EINVAL,
                   "key 's2' has two 'from' rows ('s2n' and 's1a')");
    ES_CHECK(df == NULL);
    ES_CHECK_FAILS(ctx, es_diff_paired(ctx, &src, keys, role, NULL, &df), ES_EINVAL,
                   "('row 3' and 'row 8')");
    /* nobody paired */
    int only_from[N] = {0, -1, -1, 0, 0, -1, 0, -1, -1};
    ES_CHECK_FAILS(ctx, es_diff_paired(ctx, &src, keys, only_from, ids, &df), ES_EINVAL,
                   "no key has both");
    /* one pair: sd undefined */
    int one[N] = {0, 1, -1, -1, -1, -1, -1, -1, -1};
    ES_CHECK_OK(ctx, es_diff_paired(ctx, &src, keys, one, ids, &df));
    if (df) {
        ES_CHECK(df->npairs == 1 && df->nunpaired == 0);
        ES_CHECK(isnan(df->sd[0]) && isnan(df->t[0]));
        ES_CHECK_CLOSE(df->mean[1], d[0][1], 1e-9, 0);
        es_diff_free(df);
    }
}

/* Failing the k-th allocation: every k fails cleanly with ES_ENOMEM until
 * the call succeeds (leaks show in the ASan build). */
static int64_t fail_at, nalloc;
static void *t_malloc(void *ud, size_t n) { (void)ud; return ++nalloc == fail_at ? NULL : malloc(n); }
static void *t_realloc(void *ud, void *p, size_t n) { (void)ud; return ++nalloc == fail_at ? NULL : realloc(p, n); }
static void t_free(void *ud, void *p) { (void)ud; free(p); }

static void test_alloc_failures(es_ctx *ctx)
{
    enum { E = 6, N = 8 };
    double X[E * N];
    for (int i = 0; i < E * N; i++) X[i] = 0.1 + 0.001 * (double)((i * 37) % 17);
    const char *keys[N] = {"a", "a", "b", "b", "c", "c", "d", "e"};
    const int role[N] = {0, 1, 0, 1, 0, 1, 0, 1};
    es_source src = es_source_matrix((es_mat){X, E, N, E}, NULL, 0);
    es_allocator al = {t_malloc, t_realloc, t_free, NULL};
    es_ctx_set_allocator(ctx, &al);
    for (int what = 0; what < 3; what++) {
        es_status rc = ES_ENOMEM;
        for (fail_at = 1; rc == ES_ENOMEM && fail_at < 200; fail_at++) {
            nalloc = 0;
            if (what == 0) {
                es_diff *d = NULL;
                rc = es_diff_paired(ctx, &src, keys, role, NULL, &d);
                es_diff_free(d);
            } else {
                es_pca_opts o;
                es_pca_opts_init(&o);
                if (what == 2) o.method = ES_PCA_RANDOMIZED, o.ncomp = 2;
                es_pca *p = NULL;
                rc = es_pca_fit(ctx, &src, &o, &p);
                es_pca_free(p);
            }
            ES_CHECK(rc == ES_OK || rc == ES_ENOMEM);
        }
        ES_CHECK(rc == ES_OK);
    }
    es_ctx_set_allocator(ctx, NULL);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_means(ctx);
    test_diff(ctx);
    test_alloc_failures(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
