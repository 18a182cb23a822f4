/* lib/embed/bending.c — the bending prior's term of the refinement: signed
 * bending angles and their gradients, the term's value, its Gauss-Newton
 * blocks in the position system's pattern, and the per-edge weights.
 *
 * Where edge lengths leave a surface free (every open mesh: a disc with b
 * boundary vertices has b - 3 flexes), the lengths alone let it crumple; the
 * term pulls each interior edge's bending angle toward a prior from the
 * data (es_embed.h, prior.c) with the discrete-shells weight 3 l_e^2 /
 * (A_f + A_g) (Grinspun et al. 2003, "Discrete shells"), as the NRIC/GOAST
 * bending energy does.
 *
 * Dihedral gradient (Wardetzky et al. 2007, "Discrete quadratic curvature
 * energies"; Tamstorf & Grinspun 2013) in es_geom.h's convention, alpha =
 * atan2((n_g x n_f) . t, n_g . n_f), f holding a->b with third vertex c, g
 * holding b->a with third vertex d: with e = b - a, n_f = e x (c - a),
 * n_g = (a - b) x (d - b),
 *   d alpha / dc = |e| n_f / |n_f|^2,   d alpha / dd = |e| n_g / |n_g|^2,
 *   s_c = (c - a) . e / |e|^2,          s_d = (d - a) . e / |e|^2,
 *   d alpha / da = -(1 - s_c) d/dc - (1 - s_d) d/dd,
 *   d alpha / db = -s_c d/dc - s_d d/dd
 * (the a, b parts follow from invariance under translations and
 * rotations; tests/embed/test_embed_prior.c checks all of it against
 * central differences).
 */
#include "embed/embed_pkg.h"
#include "core/vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The bending angle of the flap (a, b; c, d), with the normals and the edge
 * vector for the gradient. */
static double flap_alpha(const double *pa, const double *pb, const double *pc, const double *pd,
                         double *nf, double *ng, double *e, double *el)
{
    double ac[3], bd[3], ba[3], c[3];
    for (int i = 0; i < 3; i++) {
        e[i] = pb[i] - pa[i];
        ac[i] = pc[i] - pa[i];
        ba[i] = pa[i] - pb[i];
        bd[i] = pd[i] - pb[i];
    }
    es__v3_cross(e, ac, nf);
    es__v3_cross(ba, bd, ng);
    *el = sqrt(es__v3_dot(e, e));
    es__v3_cross(ng, nf, c);
    if (!(*el > 0)) return 0;
    return atan2(es__v3_dot(c, e) / *el, es__v3_dot(ng, nf));
}

int es__dihedral_grad(const double *pa, const double *pb, const double *pc, const double *pd,
                      double *alpha, double *g)
{
    double nf[3], ng[3], e[3], el, nf2, ng2, sc, sd, ee;
    *alpha = flap_alpha(pa, pb, pc, pd, nf, ng, e, &el);
    nf2 = es__v3_dot(nf, nf);
    ng2 = es__v3_dot(ng, ng);
    ee = el * el;
    if (!(el > 0 && nf2 > 1e-30 * ee * ee && ng2 > 1e-30 * ee * ee)) {
        memset(g, 0, 12 * sizeof *g);
        return -1;
    }
    double ac[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
    double ad[3] = {pd[0] - pa[0], pd[1] - pa[1], pd[2] - pa[2]};
    sc = es__v3_dot(ac, e) / ee;
    sd = es__v3_dot(ad, e) / ee;
    for (int i = 0; i < 3; i++) {
        double gc = el * nf[i] / nf2, gd = el * ng[i] / ng2;
        g[6 + i] = gc;
        g[9 + i] = gd;
        g[i] = -(1 - sc) * gc - (1 - sd) * gd;
        g[3 + i] = -sc * gc - sd * gd;
    }
    return 0;
}

/* The term's residual of edge e at bending angle al: the wrapped distance
 * from the prior's angle, or with a band the distance outside it. */
static double bend_residual(const es__bend_prior *bp, int64_t e, double al)
{
    if (bp->hi) return al < bp->alpha[e] ? al - bp->alpha[e] : al > bp->hi[e] ? al - bp->hi[e] : 0;
    return remainder(al - bp->alpha[e], 2.0 * M_PI);
}

double es__bend_cost(const es_embedder *emb, const es__bend_prior *bp, const double *xyz)
{
    double c = 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        const int64_t *fl = bp->flap + 6 * e;
        double nf[3], ng[3], t[3], el, al, r;
        if (fl[0] < 0 || !(bp->omega[e] > 0)) continue;
        al = flap_alpha(xyz + 3 * emb->edges[2 * e], xyz + 3 * emb->edges[2 * e + 1],
                        xyz + 3 * fl[0], xyz + 3 * fl[1], nf, ng, t, &el);
        r = bend_residual(bp, e, al);
        c += bp->omega[e] * r * r;
    }
    return bp->mu * c;
}

void es__bend_assemble(es_embedder *emb, const double *xyz, const es__bend_prior *bp, double *g)
{
    double *x = es__sparse_mat_values(emb->H3);
    for (int64_t e = 0; e < emb->ne; e++) {
        const int64_t *fl = bp->flap + 6 * e;
        int64_t q[4], qe[4][4];
        double al, gq[12], w = bp->mu * bp->omega[e], r;
        if (fl[0] < 0 || !(w > 0)) continue;
        q[0] = emb->edges[2 * e];
        q[1] = emb->edges[2 * e + 1];
        q[2] = fl[0];
        q[3] = fl[1];
        if (es__dihedral_grad(xyz + 3 * q[0], xyz + 3 * q[1], xyz + 3 * q[2], xyz + 3 * q[3],
                              &al, gq) != 0)
            continue;
        r = bend_residual(bp, e, al);
        /* inside a band: no gradient and no curvature (the one-sided term is
         * flat there) */
        if (bp->hi && r == 0) continue;
        for (int p = 0; p < 4; p++)
            for (int i = 0; i < 3; i++) g[3 * q[p] + i] += w * r * gq[3 * p + i];
        /* the mesh edges between the flap's vertices (c-d is none) */
        qe[0][1] = e;
        qe[0][2] = fl[2];
        qe[1][2] = fl[3];
        qe[0][3] = fl[4];
        qe[1][3] = fl[5];
        for (int p = 0; p < 4; p++) {
            double fac = p >= 2 ? 2.0 : 1.0;   /* the doubled (c, c) and (d, d) blocks */
            for (int i = 0; i < 3; i++)
                for (int j = i; j < 3; j++)
                    x[es__h3_diag(emb, q[p], i, j)] +=
                        fac * w * gq[3 * p + i] * gq[3 * p + j];
            for (int s = p + 1; s < 4; s++) {
                if (p == 2 && s == 3) continue;
                int64_t ee = qe[p][s], lo = q[p] < q[s] ? p : s, hi = q[p] < q[s] ? s : p;
                if (ee < 0) continue;
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++)
                        x[es__h3_off(emb, ee, i, j)] += w * gq[3 * lo + i] * gq[3 * hi + j];
            }
        }
    }
}

/* Third vertex of face f that is neither a nor b, and the face's edges
 * joining a and b to it. */
static void third(const int64_t *F, const int64_t *FE, int64_t f, int64_t a, int64_t b,
                  int64_t *c, int64_t *eac, int64_t *ebc)
{
    const int64_t *v = F + 3 * f, *fe = FE + 3 * f;
    *c = -1;
    for (int k = 0; k < 3; k++)
        if (v[k] != a && v[k] != b) *c = v[k];
    *eac = *ebc = -1;
    for (int k = 0; k < 3; k++) {
        int64_t p = v[k], q = v[(k + 1) % 3];
        if ((p == a && q == *c) || (p == *c && q == a)) *eac = fe[k];
        if ((p == b && q == *c) || (p == *c && q == b)) *ebc = fe[k];
    }
}

es_status es__bend_flaps(es_embedder *emb)
{
    const es_mesh *mesh = emb->mesh;
    const int64_t *EF = es_mesh_edge_faces(mesh), *F = es_mesh_faces(mesh);
    const int64_t *FE = es_mesh_face_edges(mesh);
    int64_t *fl;
    if (emb->flap) return ES_OK;
    if (!(fl = es__alloc_array(emb->ctx, 6 * emb->ne + 1, sizeof *fl))) return ES_ENOMEM;
    for (int64_t e = 0; e < emb->ne; e++) {
        int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1], f = EF[2 * e], g = EF[2 * e + 1];
        int64_t *o = fl + 6 * e;
        for (int k = 0; k < 6; k++) o[k] = -1;
        if (f < 0 || g < 0) continue;
        /* f holds a->b (es_mesh.h: row 0 holds min->max), as the gradient wants */
        third(F, FE, f, a, b, &o[0], &o[2], &o[3]);
        third(F, FE, g, a, b, &o[1], &o[4], &o[5]);
        if (o[0] < 0 || o[1] < 0 || o[0] == o[1]) o[0] = -1;
    }
    emb->flap = fl;
    return ES_OK;
}

es_status es__bend_work(es_embedder *emb)
{
    es_status rc;
    if ((rc = es__bend_flaps(emb)) != ES_OK) return rc;
    double **bufs[] = {&emb->omega, &emb->prior_alpha, &emb->band_lo, &emb->band_hi};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++)
        if (!*bufs[i] && !(*bufs[i] = es__alloc_array(emb->ctx, emb->ne + 1, sizeof(double))))
            return ES_ENOMEM;
    return ES_OK;
}

/* Area of a triangle from its edge lengths (Heron in Kahan's ordering). */
static double tri_area(double a, double b, double c)
{
    double t;
    if (a < b) t = a, a = b, b = t;
    if (b < c) t = b, b = c, c = t;
    if (a < b) t = a, a = b, b = t;
    t = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    return t > 0 ? 0.25 * sqrt(t) : 0;
}

void es__bend_weights(const es_embedder *emb, const double *L, const double *sd,
                      double sd_floor, double *omega)
{
    const int64_t *EF = es_mesh_edge_faces(emb->mesh), *FE = es_mesh_face_edges(emb->mesh);
    int64_t n = 0;
    double sum = 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        double area = 0;
        omega[e] = 0;
        if (emb->flap[6 * e] < 0) continue;
        for (int s = 0; s < 2; s++) {
            const int64_t *fe = FE + 3 * EF[2 * e + s];
            area += tri_area(L[fe[0]], L[fe[1]], L[fe[2]]);
        }
        if (area > 0) {
            omega[e] = 3 * L[e] * L[e] / area;
            sum += omega[e];
            n++;
        }
    }
    if (n > 0 && sum > 0)
        for (int64_t e = 0; e < emb->ne; e++) omega[e] *= (double)n / sum;
    if (!sd || !(sd_floor > 0)) return;
    /* a Gaussian prior per dihedral whose variance grows with the rows'
     * disagreement there: folded lip and eyelid edges, where the rows differ
     * by up to 1.5 rad, must not hold the surface (research13: held-out faces'
     * max edge error 2-4 % without this, 0.48 % with it) */
    double *t = es__alloc_array(emb->ctx, emb->ne + 1, sizeof *t), s0;
    if (!t) return;   /* the unweighted term still works */
    n = 0;
    for (int64_t e = 0; e < emb->ne; e++)
        if (emb->flap[6 * e] >= 0) t[n++] = sd[e];
    if (n > 0) {
        s0 = sd_floor * es__kth_smallest(t, n, n / 2);
        if (s0 > 0)
            for (int64_t e = 0; e < emb->ne; e++) omega[e] /= 1 + (sd[e] / s0) * (sd[e] / s0);
    }
    es__free(emb->ctx, t);
}

/* ---- the weight schedule ------------------------------------------------------ */

void es__bend_schedule(es__bend_prior *bp, double first, double decay, double last,
                       const es_embed_opts *o)
{
    bp->mu = first;
    bp->decay = decay;
    bp->mu_min = last;
    bp->mu_exact = 4e-4 * o->prior_mu;
    bp->mu_realize = o->realize_bend * o->prior_mu;
}

int es__bend_annealing(const es__bend_prior *bp)
{
    return bp->decay > 0 && bp->decay < 1 && bp->mu > bp->mu_min;
}

int es__bend_anneal(es__bend_prior *bp)
{
    bp->mu = fmax(bp->mu * bp->decay, bp->mu_min);
    return bp->mu > bp->mu_min;
}

es__bend_prior es__bend_held(const es__bend_prior *bp, double mu)
{
    es__bend_prior h = *bp;
    h.mu = h.mu_min = mu;
    h.decay = 1;
    return h;
}
