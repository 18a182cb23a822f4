/* lib/include/edgespace/es_stats.h — statistics in edge-length space:
 * means (all rows, a subset, per group), PCA (exact by the Gram or the
 * covariance route, or randomized top-K), projection onto a fitted PCA, and
 * paired difference vectors ("happy minus neutral" per subject, averaged).
 *
 * Everything reads its data through an es_source: N shapes (rows) of E
 * normalized edge lengths, delivered in blocks of consecutive rows by a
 * callback, so that the statistics never depend on where the data live (an
 * HDF5 store, a matrix in memory, a generator) and never need all N x E
 * values in memory at once. Section 4 of Fisher et al., "Edge-length
 * interpolation", is the method: PCA of scale-normalized length vectors,
 * projection on the top components, mean "expression minus neutral".
 *
 * Conventions: covariance eigenvalues use the divisor N - 1 (the unbiased
 * sample covariance); a component is a unit vector of length E whose
 * largest-magnitude entry is positive (the first one on ties); the score of
 * row i on component k is u_k . (x_i - mean).
 */
#ifndef EDGESPACE_ES_STATS_H
#define EDGESPACE_ES_STATS_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- data sources ------------------------------------------------------ */

typedef struct es_source es_source;

/* Fill `out` (E x n, column j = source row row0 + j, out.ld >= E) with the
 * normalized lengths of source rows [row0, row0 + n). Set a message on ctx
 * and return non-zero on failure; the statistics pass that status on. */
typedef es_status (*es_block_fn)(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n,
                                 es_mat out);

struct es_source {
    int64_t nedges;     /* E */
    int64_t nrows;      /* N */
    es_block_fn read;   /* the reader */
    void *userdata;     /* for the reader */
    int64_t block;      /* rows per read; 0 chooses (128 MiB per block, 256 MiB
                           per tile in the Gram route) */
    /* Used by es_source_matrix's reader; free for other readers. */
    es_mat mat;
    const int64_t *rows;
};

/* A source over an in-memory E x M matrix: all its columns (rows == NULL,
 * N = M), or the columns listed in rows[0..nrows) in that order. Borrows X
 * and rows; both must outlive the source. */
ES_API es_source es_source_matrix(es_mat X, const int64_t *rows, int64_t nrows);

/* ---- means --------------------------------------------------------------- */

/* mean (E) of all rows of src. Fails (ES_EINVAL) on an empty source. */
ES_API es_status es_mean(es_ctx *ctx, const es_source *src, double *mean);

/* Per-group means in one pass: group[i] in [0, ngroups) is the group of
 * source row i, or -1 to leave it out. means is E x ngroups (column g, ld E),
 * counts[g] the rows in group g; an empty group's column is NaN. */
ES_API es_status es_group_means(es_ctx *ctx, const es_source *src, const int64_t *group,
                                int64_t ngroups, double *means, int64_t *counts);

/* Group indices from string labels: the distinct values of labels[0..n) in
 * order of first appearance become groups 0, 1, ...; NULL labels get -1.
 * *group (n) and *names (*ngroups borrowed pointers into labels) are
 * allocated with the ctx allocator: es_free both. */
ES_API es_status es_groups_from_labels(es_ctx *ctx, const char *const *labels, int64_t n,
                                       int64_t **group, const char ***names,
                                       int64_t *ngroups);

/* ---- PCA ------------------------------------------------------------------ */

typedef enum es_pca_method {
    ES_PCA_AUTO = 0,     /* Gram when N <= E, else covariance */
    ES_PCA_GRAM,         /* N x N Gram matrix: memory O(N^2 + block x E + K x E) */
    ES_PCA_COVARIANCE,   /* E x E covariance: memory O(E^2) */
    ES_PCA_RANDOMIZED    /* top K by randomized range finding (Halko et al. 2011) */
} es_pca_method;

typedef struct es_pca_opts {
    int64_t ncomp;        /* K; 0: all (the numerical rank, at most min(N-1, E)).
                             ES_PCA_RANDOMIZED needs K > 0. */
    es_pca_method method;
    int64_t oversample;   /* randomized: extra sample vectors p (default 10) */
    int64_t power_iters;  /* randomized: subspace iterations q (default 4, at most 1000) */
} es_pca_opts;

/* Defaults: ncomp 0, AUTO, oversample 10, power_iters 4. */
ES_API void es_pca_opts_init(es_pca_opts *opts);

/* A fitted PCA. Plain arrays owned by the object (free with es_pca_free). */
typedef struct es_pca {
    es_ctx *ctx;             /* the allocating context (must outlive the object) */
    int64_t nedges;          /* E */
    int64_t nrows;           /* N rows it was fitted on */
    int64_t ncomp;           /* K components kept */
    es_pca_method method;    /* the route taken (never AUTO) */
    double total_variance;   /* trace of the sample covariance, divisor N - 1 */
    double *mean;            /* E */
    double *components;      /* E x K, column k = unit component k, ld E */
    double *eigenvalues;     /* K, descending, divisor N - 1 */
    double *explained;       /* K, eigenvalue / total_variance */
    double *scores;          /* N x K, ld N: scores[i + k N] = u_k . (x_i - mean) */
} es_pca;

/* Fit a PCA of all rows of src (opts NULL: defaults).
 *
 * Gram route (N <= E): G = Y^T Y for Y = X - x_0 1^T is accumulated in
 * square tiles of rows (two tiles held, 256 MiB each by default; about
 * N / (2 x tile rows) + 1 passes over the data)
 * (shifted by the first row, which keeps the entries at the scale of the
 * variation instead of that of the lengths), double-centring gives the
 * Gram matrix of the centred data, LAPACKE_dsyevr its eigenpairs (mu_k, v_k);
 * eigenvalues are mu_k / (N - 1), scores sqrt(mu_k) v_k, and a second pass
 * forms the components (X - mean 1^T) v_k / sqrt(mu_k). Covariance route
 * (N > E): one pass accumulates the E x E covariance the same way, a second
 * the scores. Randomized route (Halko, Martinsson & Tropp 2011, q + 2
 * passes): eigenvalues are never overestimated; with the defaults p = 10,
 * q = 4 the top eigenvalues are exact to rounding when the spectrum has a
 * gap after K + p, within ~1e-10 relative on a decaying spectrum and a few
 * 1e-4 on a nearly flat one (table in lib/stats/pca_randomized.c, checked by
 * tests/stats/test_pca.c).
 *
 * Components whose eigenvalue is below max(N, E) * eps * (largest) are
 * numerically zero and are not returned, so ncomp may be less than asked.
 * Errors: ES_EINVAL (N < 2, E < 1, K > min(N-1, E)), ES_ENOMEM, ES_ENUMERIC
 * (LAPACK failure or non-finite data), ES_ERANGE (sizes beyond LAPACK's
 * 32-bit integers), or the reader's status. */
ES_API es_status es_pca_fit(es_ctx *ctx, const es_source *src, const es_pca_opts *opts,
                            es_pca **out);
ES_API void es_pca_free(es_pca *pca);

/* Wrap arrays read back from a store into an es_pca (copies them; no
 * scores: nrows 0). The explained ratios are eigenvalues / total_variance
 * (NaN unless total_variance > 0). */
ES_API es_status es_pca_from_arrays(es_ctx *ctx, int64_t nedges, int64_t ncomp,
                                    const double *mean, const double *components,
                                    const double *eigenvalues, double total_variance,
                                    es_pca **out);

/* Scores of new vectors: for each column x of X (E x n), scores (K x n, ld
 * K) = U^T (x - mean) and residual[j] = |(x - mean) - U scores| (the part
 * the K components do not explain). residual may be NULL. */
ES_API es_status es_pca_project(es_ctx *ctx, const es_pca *pca, es_mat X, double *scores,
                                double *residual);

/* Row weights w (N, the rows the PCA was fitted on) that reproduce x from
 * those rows: w = 1/N + sum_k z_k (u_k . (x - mean)) / ((N - 1) lambda_k +
 * ridge), z_k the scores of component k. With every component kept and
 * ridge 0 this is the least-squares combination sum_i w_i x_i = x for x in
 * the rows' affine span (minimum norm, sum w = 1); ridge > 0 shrinks the
 * weights of components with little variance (ridge regression on the
 * rows, Hoerl & Kennard 1970), which keeps a point outside the span (a new
 * mesh) from getting wild weights. ridge_rel sets ridge = ridge_rel x
 * (N - 1) x total_variance / N, a fraction of the mean eigenvalue's
 * weight; ES_RIDGE_REL is the default the study uses. x NULL: the mean
 * (w = 1/N). */
#define ES_RIDGE_REL 1e-3
ES_API es_status es_pca_row_weights(es_ctx *ctx, const es_pca *pca, const double *x,
                                    double ridge_rel, double *w);

/* ---- paired differences -------------------------------------------------- */

/* Roles of rows in a paired difference. */
enum { ES_DIFF_NONE = -1, ES_DIFF_FROM = 0, ES_DIFF_TO = 1 };

/* The mean of (to - from) over pairs of rows sharing a key. */
typedef struct es_diff {
    es_ctx *ctx;
    int64_t nedges;     /* E */
    int64_t npairs;     /* P */
    double *mean;       /* E: mean over pairs of x_to - x_from */
    double *sd;         /* E: sample sd of the differences (divisor P - 1; NaN if P < 2) */
    double *se;         /* E: sd / sqrt(P) */
    double *t;          /* E: mean / se (one-sample t, P - 1 degrees of freedom);
                           0 where mean and se are 0, NaN where only se is 0 */
    int64_t *pair_from; /* P source rows, in order of first appearance of the key */
    int64_t *pair_to;   /* P */
    int64_t nunpaired;  /* rows with role FROM or TO whose key has no partner */
    int64_t *unpaired;  /* nunpaired source rows, ascending */
} es_diff;

/* Pair rows by key and average to - from.
 *  keys[i]: the pairing key of source row i (e.g. the subject), NULL to skip.
 *  role[i]: ES_DIFF_FROM, ES_DIFF_TO or ES_DIFF_NONE.
 *  ids: row names for messages (NULL: "row i").
 * Rule for duplicates: a key may hold at most one FROM and one TO row; a
 * second one fails with ES_EINVAL naming the key and both rows (averaging
 * them silently would weight that subject twice). Rows whose key lacks a
 * partner are listed in `unpaired`, not an error. No pair at all is
 * ES_EINVAL. */
ES_API es_status es_diff_paired(es_ctx *ctx, const es_source *src, const char *const *keys,
                                const int *role, const char *const *ids, es_diff **out);
ES_API void es_diff_free(es_diff *diff);

#ifdef __cplusplus
}
#endif
#endif
