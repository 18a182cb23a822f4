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

#ifdef __cplusplus
}
#endif
#endif
