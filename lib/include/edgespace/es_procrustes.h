/* lib/include/edgespace/es_procrustes.h — Procrustes analysis: ordinary
 * Procrustes (OPA), generalized Procrustes (GPA), Procrustes distances,
 * tangent coordinates and their PCA.
 *
 * Conventions follow R's shapes::procGPA (Dryden & Mardia 2016, ch. 7),
 * so results can be checked against the tools morphometricians trust:
 *
 *  - A configuration is k points in d = 2 or 3 dimensions, stored k x d
 *    column-major: x_1..x_k, y_1..y_k[, z_1..z_k] (procGPA's vectorisation:
 *    x-block, y-block, z-block). A set of n configurations is an es_mat of
 *    k*d rows and n columns, one configuration per column.
 *  - Configurations are centred. Rotations are proper (det +1) unless
 *    reflection is allowed; they come from the SVD of the d x d cross
 *    product, the last singular vector flipped when exactly one of U, V has
 *    negative determinant.
 *  - Full GPA (scale = 1) alternates rotation sweeps (each configuration in
 *    turn rotated onto the mean of the others) with Ten Berge (1977)
 *    scaling; the scaled configurations keep the total sum of squares of the
 *    centred inputs (they are not unit size). Partial GPA (scale = 0) only
 *    rotates. The Procrustes mean is the plain mean of the aligned set.
 *  - rho is the Riemannian shape distance between unit-size centred
 *    configurations; full and partial Procrustes distances are sin(rho) and
 *    2 sin(rho / 2) (Dryden & Mardia, eqs. 3.5-3.6).
 *  - Tangent coordinates are either procGPA's default "residual" ones
 *    (aligned - mean) or the orthogonal projection of the unit-size aligned
 *    configurations onto the tangent space at the unit-size mean ("partial
 *    Procrustes" tangent coordinates, Kent 1994). PCA sdev uses divisor
 *    n - 1. Each PC is signed so that its largest-magnitude loading is
 *    positive (procGPA's signs are arbitrary).
 *
 * The orientation of a GPA result is arbitrary (it follows the inputs; no
 * normalization is applied); compare results with other software after one
 * global rotation aligning the means, and PCs up to sign.
 */
#ifndef EDGESPACE_ES_PROCRUSTES_H
#define EDGESPACE_ES_PROCRUSTES_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- single configurations --------------------------------------------- */

/* Centre a k x d configuration in place; *cs (may be NULL) receives its
 * centroid size sqrt(sum of squared centred coordinates). */
ES_API es_status es_procrustes_center(es_ctx *ctx, int64_t k, int d, double *x, double *cs);

/* Centroid size of a k x d configuration (centred internally, x unchanged).
 * Cannot fail for k >= 1, d in {2, 3}; returns NaN otherwise. */
ES_API double es_procrustes_centroid_size(int64_t k, int d, const double *x);

/* Ordinary Procrustes analysis: fit x (k x d) onto target (k x d).
 * [in]  target, x        configurations (any position)
 * [in]  scale            1: also fit a scale factor; 0: rigid only
 * [in]  allow_reflection 1: orthogonal R with det -1 allowed
 * [out] fitted (k x d)   s * (x - centroid(x)) * R, centred at the origin;
 *                        may alias x
 * [out] rot (d x d, col-major), s, oss: rotation, scale (1 when scale = 0)
 *                        and the residual sum of squares against the centred
 *                        target; each may be NULL.
 * ES_EINVAL on d not in {2, 3}, k < 1 or a configuration of zero size (all
 * points coincide), ES_ENUMERIC on a failed SVD. */
ES_API es_status es_procrustes_opa(es_ctx *ctx, int64_t k, int d, const double *target,
                                   const double *x, int scale, int allow_reflection,
                                   double *fitted, double *rot, double *s, double *oss);

/* Shape distances between two configurations (k x d each): Riemannian rho
 * in [0, pi/2], full Procrustes sin(rho), partial Procrustes 2 sin(rho/2).
 * Any output may be NULL. ES_EINVAL on zero-size configurations. */
ES_API es_status es_procrustes_distance(es_ctx *ctx, int64_t k, int d, const double *x,
                                        const double *y, int allow_reflection, double *rho,
                                        double *full, double *partial);

/* Layout conversion between meshes/stores (3 x k, xyz interleaved) and
 * configurations (k x 3 column-major). Cannot fail. */
ES_API void es_procrustes_from_xyz(int64_t k, const double *xyz, double *config);
ES_API void es_procrustes_to_xyz(int64_t k, const double *config, double *xyz);

/* ---- generalized Procrustes analysis ------------------------------------ */

typedef struct es_gpa_opts {
    int scale;             /* 1 (default): full GPA with Ten Berge scaling; 0: partial */
    int allow_reflection;  /* 0 (default): proper rotations only */
    double tol;            /* stop when, in one iteration, every rotation moved by less
                            * than tol (Frobenius norm of R - I) and every scale factor
                            * changed by less than tol (relative). Default 1e-10. */
    int64_t max_iter;      /* default 1000; ES_ENOCONV beyond it */
} es_gpa_opts;

ES_API void es_gpa_opts_init(es_gpa_opts *opts);

/* What the iteration did; always filled, also on ES_ENOCONV. */
typedef struct es_gpa_report {
    int64_t iterations;    /* rotation sweeps (each followed by a scaling step if scale) */
    double rot_change;     /* largest ||R - I||_F of the last sweep */
    double scale_change;   /* largest |beta - 1| of the last scaling step (0 if partial) */
    int converged;         /* 1 if both fell below tol */
    double total_ss;       /* sum of squares of the centred inputs (kept by full GPA) */
    double gss;            /* sum over configurations of ||aligned - mean||^2 */
    double rmsrho;         /* sqrt(mean rho^2) */
    int64_t power_steps;   /* Ten Berge power-iteration steps, all scaling steps together
                              (0 on the explicit-Gram route and for partial GPA): on the
                              ranks each is a broadcast chain (datasets-spec/parallel.md) */
} es_gpa_report;

/* Optional per-configuration outputs of es_gpa_align (each may be NULL). */
typedef struct es_gpa_out {
    double *mean;       /* k*d: Procrustes mean (plain mean of the aligned set) */
    double *size;       /* n: centroid size of each input */
    double *rho;        /* n: Riemannian distance of each configuration to the mean */
    double *scale;      /* n: scale factor applied (1 for partial GPA) */
    double *rot;        /* d*d x n: rotation applied, column-major d x d per configuration */
    double *centroid;   /* d x n: centroid of each input */
} es_gpa_out;

/* GPA in place. x is k*d x n (ld >= k*d), one configuration per column;
 * on return column j is scale[j] * (x_j - centroid_j) * rot_j. Needs n >= 2
 * and no zero-size configuration (ES_EINVAL names it). Extra memory is
 * O(k*d + n^2), never a copy of x. ES_ENOCONV after max_iter iterations
 * (x then holds the last iterate and the report says how far it got). */
ES_API es_status es_gpa_align(es_ctx *ctx, int64_t k, int d, es_mat x,
                              const es_gpa_opts *opts, es_gpa_out *out,
                              es_gpa_report *report);

/* es_gpa_align on the ranks of ctx's job (es_parallel.h; collective: every
 * rank calls it with the same k, d, n and options): n configurations in
 * all, of which x (k*d x m, ld = k*d) holds this rank's contiguous share
 * (es_parallel_share(ctx, n, ...): m = hi - lo), aligned in place. out's arrays
 * are for all n and every rank receives all of them; the report is the
 * same on every rank. The sweep is sequential (Gauss-Seidel), so the ranks
 * take their shares in turn and hand the running sum on: the result is
 * one process's to rounding (the same additions in the same order).
 * Memory: each rank its share, rank 0 on the exact Ten Berge route (n^2 k d
 * <= 2e8) every configuration. On a context that is alone it is
 * es_gpa_align. */
ES_API es_status es_gpa_align_ranks(es_ctx *ctx, int64_t k, int d, int64_t n, es_mat x,
                                    const es_gpa_opts *opts, es_gpa_out *out,
                                    es_gpa_report *report);

typedef enum es_tangent {
    ES_TANGENT_RESIDUAL = 0, /* aligned - mean (procGPA's default "residual") */
    ES_TANGENT_PARTIAL = 1   /* orthogonal projection at the unit-size mean */
} es_tangent;

/* Tangent coordinates of an aligned set (k*d x n) at its mean (k*d), into
 * tan (k*d x n; may alias aligned). ES_EINVAL on a zero-size mean with
 * ES_TANGENT_PARTIAL. */
ES_API es_status es_gpa_tangent(es_ctx *ctx, int64_t k, int d, es_mat aligned,
                                const double *mean, es_tangent type, es_mat tan);

/* PCA of tangent coordinates tan (p x n, p = k*d, columns are specimens;
 * the mean of the columns is removed first, which is a no-op for residual
 * coordinates). npc <= min(p, n) components:
 * [out] sdev (npc), percent (npc; of the total variance, 0 if none),
 *       loadings (p x npc, or data NULL), scores (n x npc, or data NULL).
 * Uses the SVD of the centred data when it is small and the n x n Gram
 * matrix when p is large (meshes), so memory stays O(n^2 + p * npc). */
ES_API es_status es_gpa_pca(es_ctx *ctx, es_mat tan, int64_t npc, double *sdev,
                            double *percent, es_mat loadings, es_mat scores);

#ifdef __cplusplus
}
#endif
#endif
