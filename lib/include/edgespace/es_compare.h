/* lib/include/edgespace/es_compare.h — comparing two shape spaces on one set
 * of shapes: scale-normalized edge-length space and Procrustes space (the
 * paper's Section 4, Figs. 7-8).
 *
 * Everything works on n x n distance matrices (column-major, symmetric,
 * zero diagonal), so any two spaces can be compared. Helpers build them
 * from points: the columns of a p x n matrix (edge-length vectors, E x N;
 * GPA-aligned configurations, k*d x N). Statistics:
 *  - Spearman rank correlation of the n(n-1)/2 pairwise distances with a
 *    Mantel permutation test (Mantel 1967; vegan::mantel's one-sided
 *    p = (1 + #{r_perm >= r}) / (1 + permutations), specimens permuted);
 *  - nearest-neighbour agreement (fraction of specimens whose nearest other
 *    specimen is the same in both spaces);
 *  - the pairs on which the spaces disagree most: largest |rank1 - rank2|
 *    of the pair's distance, ranks scaled to [0, 1];
 *  - between-group distances of group means and a one-factor test in the
 *    spirit of geomorph's procD.lm (Goodall's F on sums of squared
 *    distances, Anderson 2001), all computed from the distance matrix
 *    (Euclidean: ||m_a - m_b||^2 from within- and between-block sums of
 *    D^2), with permutation p-values from shuffled group labels.
 * Permutations use the context's seed: same seed, same p-values.
 */
#ifndef EDGESPACE_ES_COMPARE_H
#define EDGESPACE_ES_COMPARE_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Euclidean distances between the columns of x (p x n) into dist (n x n,
 * ld >= n), through the Gram matrix (one BLAS pass over x; no copy).
 * normalize = 1 divides each column by its sum first (scale-normalized
 * edge lengths, eq. 12 of the paper) without modifying x. ES_EINVAL on a
 * column with zero or non-finite sum when normalizing. */
ES_API es_status es_compare_distances(es_ctx *ctx, es_mat x, int normalize, es_mat dist);

/* Kendall's Riemannian shape distance rho (radians, in [0, pi/2]; the
 * distance of configurations centred and scaled to unit centroid size,
 * as R's shapes::riemdist) between every pair of columns of aligned (k*d x
 * n, each column a k x d configuration: x-block, y-block[, z-block]) into
 * rho (n x n, ld >= n). allow_reflection: reflections count as the same
 * shape (riemdist(reflect = TRUE)). Invariant to the columns' placement,
 * rotation and scale, so any alignment gives the same rho. ES_EINVAL for d
 * not 2 or 3, rows not a multiple of d, or a configuration of zero size. */
ES_API es_status es_compare_rho(es_ctx *ctx, es_mat aligned, int d, int allow_reflection,
                                es_mat rho);

/* Spearman correlation of the upper triangles of d1 and d2 (n x n each,
 * ld = n) with a Mantel permutation test. permutations = 0 skips the test
 * (*p = NaN). Ties get average ranks. */
ES_API es_status es_compare_mantel(es_ctx *ctx, int64_t n, const double *d1, const double *d2,
                                   int64_t permutations, double *rho, double *p);

/* Nearest neighbour (other than itself) of every specimen in each space
 * (nn1, nn2: n each, may be NULL) and the fraction that agree. */
ES_API es_status es_compare_nn_agreement(es_ctx *ctx, int64_t n, const double *d1,
                                         const double *d2, int64_t *nn1, int64_t *nn2,
                                         double *agreement);

/* The `top` pairs with the largest |r1 - r2|, r = rank of the pair's
 * distance scaled to [0, 1] (0 nearest). pairs: 2 x top (i < j), diff: top
 * values r1 - r2 (positive: farther in space 1). top <= n(n-1)/2. */
ES_API es_status es_compare_disagreement(es_ctx *ctx, int64_t n, const double *d1,
                                         const double *d2, int64_t top, int64_t *pairs,
                                         double *diff);

/* One-factor group test on a Euclidean distance matrix. */
typedef struct es_group_stats {
    double ss_total;    /* sum of squared distances to the grand mean */
    double ss_between;  /* sum_g n_g ||m_g - m||^2 */
    double ss_within;
    double r2;          /* ss_between / ss_total */
    double f;           /* (ss_between / (g-1)) / (ss_within / (n-g)) */
    double p;           /* permutation p-value of f (NaN if permutations = 0) */
} es_group_stats;

/* group: n labels in [0, ngroups), every group non-empty, ngroups >= 2.
 * [out] mean_dist (ngroups x ngroups, may be NULL): distances between group
 *       means; p_pair (same, may be NULL): permutation p-values of each
 *       distance (diagonal 1); stats (may be NULL). */
ES_API es_status es_compare_groups(es_ctx *ctx, int64_t n, const double *dist,
                                   const int64_t *group, int64_t ngroups, int64_t permutations,
                                   double *mean_dist, double *p_pair, es_group_stats *stats);

/* ---- the whole study ---------------------------------------------------- */

typedef struct es_compare_opts {
    int64_t permutations;  /* Mantel and group tests (default 999; 0: no tests) */
    int64_t top_pairs;     /* disagreeing pairs to report (default 20, capped at n(n-1)/2) */
    int normalize_lengths; /* divide each length column by its sum (default 1) */
} es_compare_opts;

ES_API void es_compare_opts_init(es_compare_opts *opts);

/* Everything es_compare_study computes; arrays owned by the result. Space 1
 * is edge-length space ("len"), space 2 Procrustes space ("proc"). */
typedef struct es_compare_result {
    int64_t n;
    double *d_len, *d_proc;        /* n x n distance matrices */
    double mantel_rho, mantel_p;   /* Spearman of the two, Mantel p */
    double nn_agreement;
    int64_t *nn_len, *nn_proc;     /* n nearest neighbours */
    int64_t ntop;
    int64_t *top_pairs;            /* 2 x ntop */
    double *top_diff;              /* ntop: scaled rank in len - rank in proc */
    int64_t ngroups;               /* 0 when no groups were given */
    double *mean_len, *mean_proc;  /* ngroups x ngroups distances of group means */
    double *p_len, *p_proc;        /* their permutation p-values */
    es_group_stats groups_len, groups_proc;
    int normalized_lengths;        /* d_len is between unit-sum length vectors (opts) */
    /* n x n Riemannian distances rho (es_compare_rho) when the study knows
     * the configurations' dimension (es_study_compare), else NULL */
    double *d_rho;
    /* Filled by the study on a store (es_study_compare), NULL otherwise: the
     * row ids (n), each row's group (n) and the group names (ngroups). */
    char **ids;
    int64_t *group;
    char **group_names;
    es_ctx *ctx;
} es_compare_result;

/* The comparison study on n shapes: lengths (E x n edge lengths, raw or
 * normalized) and aligned (k*d x n, e.g. es_gpa_align output: Procrustes
 * distances are Euclidean distances of aligned configurations). group (n
 * labels in [0, ngroups)) may be NULL with ngroups = 0. Caller owns *out
 * (es_compare_result_free). */
ES_API es_status es_compare_study(es_ctx *ctx, es_mat lengths, es_mat aligned,
                                  const int64_t *group, int64_t ngroups,
                                  const es_compare_opts *opts, es_compare_result **out);
ES_API void es_compare_result_free(es_compare_result *res);

/* "a|b" with the two names in byte order: the label of a pair of groups in
 * the study's tables and figures. es_free the result (NULL: out of memory). */
ES_API char *es_compare_pair_label(es_ctx *ctx, const char *a, const char *b);



#ifdef __cplusplus
}
#endif
#endif
