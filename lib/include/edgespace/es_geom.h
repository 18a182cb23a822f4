/* lib/include/edgespace/es_geom.h — geometry on a fixed topology: edge
 * lengths, scale normalization, corner angles, dihedral angles, validity.
 *
 * Sign convention of dihedrals (shared with ../shared/oracle/embed and the
 * embedding): for edge e = (a, b), a < b, let f be the face holding the
 * half-edge a->b and g the face holding b->a, n_f and n_g their unit
 * normals and t the unit vector a->b. The signed bending angle is
 *     alpha_e = atan2((n_g x n_f) . t, n_g . n_f),
 * which equals delta - pi for the interior dihedral angle delta:
 * alpha = 0 on a flat edge, alpha < 0 on a convex edge, in (-pi, pi].
 * Boundary edges have alpha = 0 by definition.
 */
#ifndef EDGESPACE_ES_GEOM_H
#define EDGESPACE_ES_GEOM_H

#include "es_core.h"
#include "es_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Lengths of all E edges of `mesh` at positions xyz (3 x V). */
ES_API es_status es_edge_lengths(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                                 double *len /* E */);

/* out = len / sum(len), *scale = sum(len) (Section 4, eq. 12). out may
 * alias len. Fails (ES_EINVAL) if the sum is not finite and positive. */
ES_API es_status es_lengths_normalize(es_ctx *ctx, int64_t nedges, const double *len,
                                      double *out, double *scale);

/* Corner angles of every face from edge lengths: angles[3f + k] is the
 * angle at corner k (vertex faces[3f+k]). Kahan's stable formula; a
 * triangle violating the triangle inequality gets its angles clamped to
 * (0 or pi) and counts in the return of es_lengths_check, not here. */
ES_API es_status es_corner_angles(es_ctx *ctx, const es_mesh *mesh, const double *len,
                                  double *angles /* 3 x F */);

/* Length of the diagonal of the axis-aligned bounding box of nverts points
 * (3 x nverts): the scale geometric tolerances are relative to ("vertex RMS
 * <= 1e-9 x diagonal"). 0 for no points; not finite if a coordinate is not. */
ES_API double es_bbox_diagonal(int64_t nverts, const double *xyz);

/* Signed bending angles (convention above) of all edges at positions xyz. */
ES_API es_status es_dihedral_angles(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                                    double *alpha /* E */);

typedef struct es_validity {
    int64_t n_nonfinite;      /* NaN or infinite lengths */
    int64_t n_nonpositive;    /* lengths <= 0 */
    int64_t n_bad_faces;      /* faces violating the triangle inequality */
    int64_t worst_face;       /* face with the largest violation, or -1 */
    double worst_violation;   /* max over faces of (l_i - l_j - l_k)/(l_i+l_j+l_k)
                                 for the longest side l_i; <= 0 when valid */
    int valid;                /* 1 when all counts above are zero */
} es_validity;

/* Check a length vector: finite, positive, and on every face
 * l_i <= l_j + l_k + rtol * (l_i + l_j + l_k). Never fails on bad lengths
 * (that is what it reports); fails only on bad arguments. */
ES_API es_status es_lengths_check(es_ctx *ctx, const es_mesh *mesh, const double *len,
                                  double rtol, es_validity *out);

#ifdef __cplusplus
}
#endif
#endif
