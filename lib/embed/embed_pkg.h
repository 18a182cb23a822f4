/* lib/embed/embed_pkg.h — pieces of the embedding shared by embed.c,
 * embed_walk.c and interp.c: corner angles, vertex-figure walks, closure
 * residuals and their derivatives, small rotation helpers. Never installed.
 *
 * 3 x 3 matrices here are row-major double[9] (m[3*i + j]); they never
 * leave these files.
 */
#ifndef EDGESPACE_EMBED_PKG_H
#define EDGESPACE_EMBED_PKG_H

#ifndef ES_MODULE_EMBED
#error "embed/embed_pkg.h is private to lib/embed/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "edgespace/es_mesh.h"

/* Corner angles of all faces from lengths (3 x F, angle at corner k of
 * face f in ang[3f + k]) by Kahan's needle-stable formula ("Miscalculating
 * area and angles of a needle-like triangle", 2014, sec. 12). A face that
 * violates the triangle inequality by more than rtol * perimeter counts in
 * the return value; its angles are clamped to 0 / pi. */
int64_t es__corner_angles(const es_mesh *mesh, const double *len, double rtol, double *ang);

/* Index into the 3 x F corner array of the corner of v in star slot i
 * (the slot's face), or -1 for the open slot of a boundary vertex. */
int64_t es__slot_corner(const es_mesh *mesh, int64_t v, int64_t slot);

/* Walk of one vertex figure. k spokes, theta[j] the corner angle of fan face
 * j, alpha[j] the dihedral of spoke j (alpha[0] unused at a boundary vertex),
 * nface = k (interior) or k - 1 (boundary). C (9 k): C_j, the frame with x
 * along spoke j and z the normal of face j (face j-1 for the last spoke of a
 * boundary vertex), in the vertex frame C_0 = I. Returns P = C_k (interior)
 * in P (may be NULL). */
void es__fan_frames(int64_t k, int64_t nface, const double *theta, const double *alpha,
                    double *C, double *P);

/* Closure residual r = vec(P - I) (9, row-major) of an interior vertex,
 * and when J != NULL its derivatives, J[9 j + m] = d r_m / d alpha_j.
 * work: 18 (2k + 1) doubles. Returns ||r||^2. */
double es__fan_closure(int64_t k, const double *theta, const double *alpha, double *r,
                       double *J, double *work);

/* out = a b (3 x 3 row-major); out may not alias. */
void es__mat3_mul(const double *a, const double *b, double *out);
/* out = a b^T. */
void es__mat3_mul_bt(const double *a, const double *b, double *out);
/* m = m Z(t) (eq. 6's rotation about z). */
void es__mat3_right_z(double *m, double t);
/* Nearest proper rotation to m (in place); returns 0, or -1 if m is
 * degenerate (then m is set to I). */
int es__mat3_nearest_rotation(double *m);

#endif
