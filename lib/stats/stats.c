/* lib/stats/stats.c — data sources, means and paired differences in edge-length
 * space.
 *
 * All statistics stream their data through an es_source (es_stats.h) one
 * block of rows at a time, so memory stays O(block x E) whatever N is. The
 * paired difference is Section 4 of Fisher et al. ("we take the difference
 * of the edge length vectors of these two expressions ... then average the
 * difference across all paired examples"); we add the per-edge standard
 * error and one-sample t statistic so that a heat map can show where the
 * expression acts and how reliably. Welford's update (Welford 1962) keeps
 * the variance accurate when the differences are small against the lengths.
 */
#include "stats/stats_pkg.h"
#include "core/strmap.h"
#include "parallel/parallel_private.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define BLOCK_BYTES ((int64_t)128 << 20)

/* ---- sources ------------------------------------------------------------ */

static es_status matrix_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n,
                             es_mat out)
{
    for (int64_t j = 0; j < n; j++) {
        int64_t c = src->rows ? src->rows[row0 + j] : row0 + j;
        if (c < 0 || c >= src->mat.cols)
            ES_FAIL(ctx, ES_ERANGE, "source: row %lld refers to column %lld of a %lld-column "
                    "matrix", (long long)(row0 + j), (long long)c, (long long)src->mat.cols);
        memcpy(&ES_AT(out, 0, j), &ES_AT(src->mat, 0, c), (size_t)src->nedges * sizeof(double));
    }
    return ES_OK;
}

es_source es_source_matrix(es_mat X, const int64_t *rows, int64_t nrows)
{
    es_source s;
    memset(&s, 0, sizeof s);
    s.nedges = X.rows;
    s.nrows = rows ? nrows : X.cols;
    s.read = matrix_read;
    s.mat = X;
    s.rows = rows;
    return s;
}

bool es__source_matrix_of(const es_source *src, es_mat *m, const int64_t **rows)
{
    if (!src || src->read != matrix_read) return false;
    *m = src->mat;
    *rows = src->rows;
    return true;
}

void es__source_share(es_ctx *ctx, const es_source *src, int64_t block, int64_t *lo,
                      int64_t *hi, int64_t *rounds)
{
    const int P = es__par_size(ctx);
    int64_t most = src->nrows / P + (src->nrows % P != 0);
    es__par_split(src->nrows, P, es__par_rank(ctx), lo, hi);
    if (block < 1) block = 1;
    *rounds = (most + block - 1) / block;
}

es_status es__source_check(es_ctx *ctx, const es_source *src, const char *what)
{
    if (!src || !src->read)
        ES_FAIL(ctx, ES_EINVAL, "%s: no data source or no reader", what);
    if (src->nedges < 1 || src->nrows < 0)
        ES_FAIL(ctx, ES_EINVAL, "%s: source has %lld edges and %lld rows", what,
                (long long)src->nedges, (long long)src->nrows);
    int64_t total;
    if (!es__mul_i64(src->nedges, src->nrows, &total))
        ES_FAIL(ctx, ES_ERANGE, "%s: %lld x %lld values overflow", what,
                (long long)src->nedges, (long long)src->nrows);
    return ES_OK;
}

int64_t es__source_block(const es_source *src)
{
    int64_t b = src->block > 0 ? src->block : BLOCK_BYTES / (8 * src->nedges);
    if (b > src->nrows) b = src->nrows;
    return b < 1 ? 1 : b;
}

es_status es__source_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n,
                          double *buf)
{
    es_mat out = {buf, src->nedges, n, src->nedges};
    es_status rc = src->read(ctx, src, row0, n, out);
    if (rc != ES_OK) return rc;
    for (int64_t j = 0; j < n; j++)
        for (int64_t e = 0; e < src->nedges; e++)
            if (!isfinite(buf[e + j * src->nedges]))
                ES_FAIL(ctx, ES_ENUMERIC, "source: row %lld, edge %lld: length is %g",
                        (long long)(row0 + j), (long long)e, buf[e + j * src->nedges]);
    return ES_OK;
}

/* ---- means ---------------------------------------------------------------- */

es_status es_group_means(es_ctx *ctx, const es_source *src, const int64_t *group,
                         int64_t ngroups, double *means, int64_t *counts)
{
    es_status rc = es__source_check(ctx, src, "mean");
    if (rc != ES_OK) return rc;
    if (ngroups < 1 || !means || !counts)
        ES_FAIL(ctx, ES_EINVAL, "mean: need at least one group and output arrays");
    const int64_t E = src->nedges, N = src->nrows, B = es__source_block(src);
    for (int64_t i = 0; i < N; i++)
        if (group && (group[i] < -1 || group[i] >= ngroups))
            ES_FAIL(ctx, ES_ERANGE, "mean: row %lld has group %lld, not in [-1, %lld)",
                    (long long)i, (long long)group[i], (long long)ngroups);
    double *buf = es__alloc_array(ctx, E * B, sizeof *buf);
    if (!buf) return ES_ENOMEM;
    memset(means, 0, (size_t)(E * ngroups) * sizeof *means);
    memset(counts, 0, (size_t)ngroups * sizeof *counts);
    for (int64_t r0 = 0; r0 < N; r0 += B) {
        int64_t n = N - r0 < B ? N - r0 : B;
        if ((rc = es__source_read(ctx, src, r0, n, buf)) != ES_OK) goto done;
        for (int64_t j = 0; j < n; j++) {
            int64_t g = group ? group[r0 + j] : 0;
            if (g < 0) continue;
            double *m = means + g * E;
            const double *x = buf + j * E;
            for (int64_t e = 0; e < E; e++) m[e] += x[e];
            counts[g]++;
        }
        if ((rc = es__progress(ctx, "mean", r0 + n, N))) goto done;
    }
    for (int64_t g = 0; g < ngroups; g++)
        for (int64_t e = 0; e < E; e++)
            means[e + g * E] = counts[g] ? means[e + g * E] / (double)counts[g] : NAN;
done:
    es__free(ctx, buf);
    return rc;
}

es_status es_mean(es_ctx *ctx, const es_source *src, double *mean)
{
    int64_t count = 0;
    es_status rc = es__source_check(ctx, src, "mean");
    if (rc != ES_OK) return rc;
    if (src->nrows < 1) ES_FAIL(ctx, ES_EINVAL, "mean: no rows to average");
    return es_group_means(ctx, src, NULL, 1, mean, &count);
}

/* ---- string keys ----------------------------------------------------------
 * Group labels and pairing keys numbered 0, 1, ... in order of first
 * appearance: core's string map holds key -> number, keys[] the names. */

typedef struct keyset {
    es__strmap map;
    const char **keys;  /* borrowed, in order of first appearance */
} keyset;

static es_status keyset_init(es_ctx *ctx, keyset *s, int64_t maxn)
{
    s->keys = es__alloc_array(ctx, maxn > 0 ? maxn : 1, sizeof *s->keys);
    if (!s->keys) {
        memset(&s->map, 0, sizeof s->map);
        return ES_ENOMEM;
    }
    return es__strmap_init(ctx, &s->map, maxn);
}

static void keyset_clear(es_ctx *ctx, keyset *s)
{
    es__strmap_clear(ctx, &s->map);
    es__free(ctx, (void *)s->keys);
    s->keys = NULL;
}

/* The number of key, numbering it if new (at most keyset_init's maxn keys,
 * so the map never grows and cannot fail). */
static int64_t keyset_index(es_ctx *ctx, keyset *s, const char *key)
{
    int64_t n = s->map.n, prev;
    es__strmap_put(ctx, &s->map, key, n, &prev);
    if (prev >= 0) return prev;
    s->keys[n] = key;
    return n;
}

es_status es_groups_from_labels(es_ctx *ctx, const char *const *labels, int64_t n,
                                int64_t **group, const char ***names, int64_t *ngroups)
{
    keyset s;
    es_status rc;
    *group = NULL;
    *names = NULL;
    *ngroups = 0;
    if (n < 0 || (n > 0 && !labels)) ES_FAIL(ctx, ES_EINVAL, "groups: no labels");
    int64_t *g = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *g);
    if (!g) return ES_ENOMEM;
    if ((rc = keyset_init(ctx, &s, n)) != ES_OK) {
        keyset_clear(ctx, &s);
        es__free(ctx, g);
        return rc;
    }
    for (int64_t i = 0; i < n; i++) g[i] = labels[i] ? keyset_index(ctx, &s, labels[i]) : -1;
    *group = g;
    *names = s.keys;
    *ngroups = s.map.n;
    es__strmap_clear(ctx, &s.map);
    return ES_OK;
}

/* ---- paired differences --------------------------------------------------- */

void es_diff_free(es_diff *d)
{
    if (!d) return;
    es_ctx *ctx = d->ctx;
    es__free(ctx, d->mean);
    es__free(ctx, d->sd);
    es__free(ctx, d->se);
    es__free(ctx, d->t);
    es__free(ctx, d->pair_from);
    es__free(ctx, d->pair_to);
    es__free(ctx, d->unpaired);
    es__free(ctx, d);
}

static const char *row_name(const char *const *ids, int64_t i, char *buf, size_t n)
{
    if (ids && ids[i]) return ids[i];
    snprintf(buf, n, "row %lld", (long long)i);
    return buf;
}

/* Pair the rows: per key one FROM and one TO slot. */
static es_status make_pairs(es_ctx *ctx, int64_t N, const char *const *keys, const int *role,
                            const char *const *ids, es_diff *d)
{
    keyset m;
    es_status rc = keyset_init(ctx, &m, N);
    int64_t *from = es__alloc_array(ctx, N > 0 ? N : 1, sizeof *from);
    int64_t *to = es__alloc_array(ctx, N > 0 ? N : 1, sizeof *to);
    if (rc != ES_OK || !from || !to) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < N; i++) from[i] = to[i] = -1;
    for (int64_t i = 0; i < N; i++) {
        if (role[i] == ES_DIFF_NONE || !keys[i]) continue;
        if (role[i] != ES_DIFF_FROM && role[i] != ES_DIFF_TO) {
            rc = es__fail(ctx, ES_EINVAL, "diff: row %lld has role %d", (long long)i, role[i]);
            goto done;
        }
        int64_t k = keyset_index(ctx, &m, keys[i]);
        int64_t *slot = role[i] == ES_DIFF_FROM ? &from[k] : &to[k];
        if (*slot >= 0) {
            char b1[32], b2[32];
            rc = es__fail(ctx, ES_EINVAL, "diff: key '%s' has two '%s' rows ('%s' and '%s'); "
                          "each key may pair one 'from' with one 'to' row", keys[i],
                          role[i] == ES_DIFF_FROM ? "from" : "to",
                          row_name(ids, *slot, b1, sizeof b1), row_name(ids, i, b2, sizeof b2));
            goto done;
        }
        *slot = i;
    }
    int64_t P = 0, U = 0;
    for (int64_t k = 0; k < m.map.n; k++) {
        if (from[k] >= 0 && to[k] >= 0) P++;
        else U++;
    }
    if (P == 0) {
        rc = es__fail(ctx, ES_EINVAL, "diff: no key has both a 'from' and a 'to' row "
                      "(%lld unpaired rows)", (long long)U);
        goto done;
    }
    d->pair_from = es__alloc_array(ctx, P, sizeof *d->pair_from);
    d->pair_to = es__alloc_array(ctx, P, sizeof *d->pair_to);
    d->unpaired = es__alloc_array(ctx, U > 0 ? U : 1, sizeof *d->unpaired);
    if (!d->pair_from || !d->pair_to || !d->unpaired) {
        rc = ES_ENOMEM;
        goto done;
    }
    P = U = 0;
    for (int64_t k = 0; k < m.map.n; k++) {
        if (from[k] >= 0 && to[k] >= 0) {
            d->pair_from[P] = from[k];
            d->pair_to[P++] = to[k];
        } else {
            d->unpaired[U++] = from[k] >= 0 ? from[k] : to[k];
        }
    }
    /* insertion sort: unpaired rows ascending */
    for (int64_t i = 1; i < U; i++) {
        int64_t v = d->unpaired[i], j = i;
        for (; j > 0 && d->unpaired[j - 1] > v; j--) d->unpaired[j] = d->unpaired[j - 1];
        d->unpaired[j] = v;
    }
    d->npairs = P;
    d->nunpaired = U;
done:
    keyset_clear(ctx, &m);
    es__free(ctx, from);
    es__free(ctx, to);
    return rc;
}

es_status es_diff_paired(es_ctx *ctx, const es_source *src, const char *const *keys,
                         const int *role, const char *const *ids, es_diff **out)
{
    es_status rc;
    double *buf = NULL;
    *out = NULL;
    if ((rc = es__source_check(ctx, src, "diff")) != ES_OK) return rc;
    if (!keys || !role) ES_FAIL(ctx, ES_EINVAL, "diff: keys and roles are required");
    const int64_t E = src->nedges;
    es_diff *d = es__calloc(ctx, 1, sizeof *d);
    if (!d) return ES_ENOMEM;
    d->ctx = ctx;
    d->nedges = E;
    if ((rc = make_pairs(ctx, src->nrows, keys, role, ids, d)) != ES_OK) goto fail;
    d->mean = es__alloc_array(ctx, E, sizeof(double));
    d->sd = es__alloc_array(ctx, E, sizeof(double));
    d->se = es__alloc_array(ctx, E, sizeof(double));
    d->t = es__alloc_array(ctx, E, sizeof(double));
    buf = es__alloc_array(ctx, 2 * E, sizeof(double));
    if (!d->mean || !d->sd || !d->se || !d->t || !buf) {
        rc = ES_ENOMEM;
        goto fail;
    }
    /* Welford: mean in d->mean, sum of squared deviations in d->sd */
    memset(d->mean, 0, (size_t)E * sizeof(double));
    memset(d->sd, 0, (size_t)E * sizeof(double));
    const int64_t P = d->npairs;
    for (int64_t p = 0; p < P; p++) {
        if ((rc = es__source_read(ctx, src, d->pair_from[p], 1, buf)) != ES_OK ||
            (rc = es__source_read(ctx, src, d->pair_to[p], 1, buf + E)) != ES_OK)
            goto fail;
        for (int64_t e = 0; e < E; e++) {
            double x = buf[E + e] - buf[e], delta = x - d->mean[e];
            d->mean[e] += delta / (double)(p + 1);
            d->sd[e] += delta * (x - d->mean[e]);
        }
        if ((rc = es__progress(ctx, "diff", p + 1, P))) goto fail;
    }
    for (int64_t e = 0; e < E; e++) {
        d->sd[e] = P > 1 ? sqrt(d->sd[e] / (double)(P - 1)) : NAN;
        d->se[e] = d->sd[e] / sqrt((double)P);
        if (d->se[e] > 0) d->t[e] = d->mean[e] / d->se[e];
        else d->t[e] = (d->se[e] == 0 && d->mean[e] == 0) ? 0.0 : NAN;
    }
    es__free(ctx, buf);
    *out = d;
    return ES_OK;
fail:
    es__free(ctx, buf);
    es_diff_free(d);
    return rc;
}
