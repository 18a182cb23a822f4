/* lib/procrustes/procrustes_pkg.h — helpers shared by procrustes.c, gpa.c and
 * compare.c; never installed. */
#ifndef EDGESPACE_PROCRUSTES_PKG_H
#define EDGESPACE_PROCRUSTES_PKG_H

#ifndef ES_MODULE_PROCRUSTES
#error "procrustes/procrustes_pkg.h is private to lib/procrustes/ (see lib/README.md)"
#endif

#include "core/core_private.h"

/* The orthogonal R (d x d, col-major) maximising tr(R^T A) for A = X^T T
 * (d x d, col-major), so that X R is the best fit of X to T. Without
 * reflection the last singular vector is flipped when det(U V^T) < 0.
 * *trace (may be NULL) receives tr(R^T A) = the signed sum of singular
 * values. ES_ENUMERIC if the SVD fails or A is not finite. */
es_status es__procrustes_rotation(es_ctx *ctx, int d, const double *a, int allow_reflection,
                                  double *r, double *trace);

/* A = X^T Y for k x d configurations (d x d, col-major). */
void es__procrustes_cross(int64_t k, int d, const double *x, const double *y, double *a);

/* y = x R in place (k x d times d x d). */
void es__procrustes_apply(int64_t k, int d, double *x, const double *r);

/* Riemannian distance from the cross product of two centred configurations
 * of sizes sx, sy (> 0). */
es_status es__procrustes_rho(es_ctx *ctx, int d, const double *a, double sx, double sy,
                             int allow_reflection, double *rho);

#endif
