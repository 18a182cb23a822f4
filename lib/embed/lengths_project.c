/* lib/embed/lengths_project.c — the lengths nearest to a target whose every
 * face is a triangle.
 *
 * A point of edge-length space (a mean plus 2 sd along a PC, an
 * extrapolation) can break the triangle inequality on a few faces: no mesh
 * has those lengths, and a solver that chases them crumples the surface
 * around the faces (mean + 2 sd on PC 2 of a face study: 11 faces, bending
 * 1.21 x the vertex blend's). The embedding is asked for the nearest
 * lengths that form triangles instead, in the relative least-squares sense
 * of the rest of the solve:
 *   min sum_e (l'_e / l_e - 1)^2  subject to, for every face and each of
 *   its edges i (j, k the other two): l'_i <= (1 - margin) (l'_j + l'_k).
 * In u_e = l'_e / l_e every constraint is a half-space a^T u <= 0, and the
 * projection onto their intersection is Hildreth's method (Dykstra's
 * alternating projections for half-spaces; Hildreth 1957): each sweep undoes
 * a constraint's last correction, projects onto its half-space again and
 * keeps the multiplier. It converges to the exact projection; a face's
 * constraints touch only its own three edges, so the changes stay next to
 * the broken faces.
 */
#include "embed/embed_pkg.h"

#include <math.h>
#include <string.h>

int64_t es__lengths_project(es_embedder *emb, const double *L, double margin, double *out,
                            double *rms_change, double *max_change)
{
    const int64_t *FE = es_mesh_face_edges(emb->mesh);
    int64_t nf = emb->nf, ne = emb->ne, changed = 0;
    double *u = emb->lpath, *y = emb->pcg;   /* E and 3 F of work (pcg holds >= 21 V + 4 E) */
    double c = 1 - margin, ss = 0, mx = 0;
    int64_t need = 3 * nf;
    if (need > 21 * emb->nv + 4 * ne) return -1;   /* cannot happen on a triangle mesh */
    for (int64_t e = 0; e < ne; e++) u[e] = 1;
    memset(y, 0, (size_t)need * sizeof *y);
    for (int sweep = 0; sweep < 2000; sweep++) {
        double moved = 0;
        for (int64_t f = 0; f < nf; f++) {
            const int64_t *fe = FE + 3 * f;
            for (int i = 0; i < 3; i++) {
                int64_t ei = fe[i], ej = fe[(i + 1) % 3], ek = fe[(i + 2) % 3];
                double a[3] = {L[ei], -c * L[ej], -c * L[ek]}, *yi = y + 3 * f + i;
                double aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
                /* undo the last correction, project again */
                u[ei] += *yi * a[0], u[ej] += *yi * a[1], u[ek] += *yi * a[2];
                double viol = a[0] * u[ei] + a[1] * u[ej] + a[2] * u[ek], ny;
                ny = viol > 0 ? viol / aa : 0;
                u[ei] -= ny * a[0], u[ej] -= ny * a[1], u[ek] -= ny * a[2];
                if (fabs(ny - *yi) * sqrt(aa) > moved) moved = fabs(ny - *yi) * sqrt(aa);
                *yi = ny;
            }
        }
        if (moved <= 1e-14) break;   /* the multipliers hold: the projection */
    }
    for (int64_t e = 0; e < ne; e++) {
        double r = u[e] - 1;
        out[e] = L[e] * u[e];
        if (r != 0) {
            changed++;
            ss += r * r;
            if (fabs(r) > mx) mx = fabs(r);
        }
    }
    *rms_change = ne > 0 ? sqrt(ss / (double)ne) : 0;
    *max_change = mx;
    return changed;
}
