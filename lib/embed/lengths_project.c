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

/* One Hildreth step on constraint i of face f: undo its last correction,
 * project onto its half-space again; returns how far its multiplier moved. */
static double hildreth(const int64_t *fe, int i, const double *L, double c, double *u, double *yi)
{
    int64_t ei = fe[i], ej = fe[(i + 1) % 3], ek = fe[(i + 2) % 3];
    double a[3] = {L[ei], -c * L[ej], -c * L[ek]};
    double aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    u[ei] += *yi * a[0], u[ej] += *yi * a[1], u[ek] += *yi * a[2];
    double viol = a[0] * u[ei] + a[1] * u[ej] + a[2] * u[ek];
    double ny = viol > 0 ? viol / aa : 0, moved = fabs(ny - *yi) * sqrt(aa);
    u[ei] -= ny * a[0], u[ej] -= ny * a[1], u[ek] -= ny * a[2];
    *yi = ny;
    return moved;
}

/* 1 if face f breaks a constraint at u (relative 1e-12). */
static int broken(const int64_t *fe, const double *L, double c, const double *u)
{
    double l[3] = {L[fe[0]] * u[fe[0]], L[fe[1]] * u[fe[1]], L[fe[2]] * u[fe[2]]};
    for (int i = 0; i < 3; i++)
        if (l[i] > c * (l[(i + 1) % 3] + l[(i + 2) % 3]) * (1 + 1e-12)) return 1;
    return 0;
}

int64_t es__lengths_project(es_embedder *emb, const double *L, double margin, double *out,
                            double *rms_change, double *max_change)
{
    const int64_t *FE = es_mesh_face_edges(emb->mesh), *EF = es_mesh_edge_faces(emb->mesh);
    int64_t nf = emb->nf, ne = emb->ne, changed = 0, nact = 0;
    /* work: u (E), the multipliers (3 F), the faces swept (F) and a mark per
     * face (F), in lpath and pcg (>= 21 V + 4 E doubles) */
    double *u = emb->lpath, *y = emb->pcg;
    int64_t *act = (int64_t *)(y + 3 * nf);
    uint8_t *in = (uint8_t *)(act + nf);
    double c = 1 - margin, ss = 0, mx = 0;
    if ((size_t)(3 * nf) * sizeof(double) + (size_t)nf * (sizeof(int64_t) + 1) >
        (size_t)(21 * emb->nv + 4 * ne) * sizeof(double))
        return -1;   /* cannot happen on a triangle mesh (F < 2V + 2) */
    for (int64_t e = 0; e < ne; e++) u[e] = 1;
    memset(y, 0, (size_t)(3 * nf) * sizeof *y);
    memset(in, 0, (size_t)nf);
    /* the sweeps run over the broken faces and their neighbours across an
     * edge (a face's constraints touch only its own edges); once they hold,
     * any other face they broke joins, and they run again */
    for (int round = 0; round < 100; round++) {
        int64_t added = 0;
        for (int64_t f = 0; f < nf; f++) {
            if (in[f] || !broken(FE + 3 * f, L, c, u)) continue;
            for (int k = 0; k < 3; k++)
                for (int s = 0; s < 2; s++) {
                    int64_t g = EF[2 * FE[3 * f + k] + s];
                    if (g >= 0 && !in[g]) in[g] = 1, act[nact++] = g, added++;
                }
            if (!in[f]) in[f] = 1, act[nact++] = f, added++;
        }
        if (!added) break;
        for (int sweep = 0; sweep < 5000; sweep++) {
            double moved = 0;
            for (int64_t j = 0; j < nact; j++)
                for (int i = 0; i < 3; i++) {
                    double m = hildreth(FE + 3 * act[j], i, L, c, u, y + 3 * act[j] + i);
                    if (m > moved) moved = m;
                }
            if (moved <= 1e-14) break;   /* the multipliers hold: the projection */
        }
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
