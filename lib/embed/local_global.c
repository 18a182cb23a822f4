/* lib/embed/local_global.c — edge lengths to positions by local-global
 * iterations on the triangles the lengths define, accelerated by L-BFGS
 * with the factored global matrix as its initial inverse Hessian.
 *
 * Every face's three target lengths make a triangle in the plane. The
 * energy
 *   E(x) = sum_f min_{R_f} sum_{k=0..2} w_e |d_fk(x) - R_f r_fk|^2,
 * d_fk the face's k-th edge vector, r_fk the same edge of the planar
 * triangle, R_f a 3 x 2 matrix with orthonormal columns, is zero exactly
 * when every face is congruent to its triangle, i.e. every edge has its
 * length (the as-rigid-as-possible energy with flat rest triangles: Liu et
 * al. 2008, "A local/global approach to mesh parameterization"; projective
 * dynamics, Bouaziz et al. 2014). Local step: each R_f in closed form (the
 * polar factor of a 3 x 2 covariance). Global step: one solve with
 *   A = sum_f sum_k w_e (delta_a - delta_b)(delta_a - delta_b)^T,
 * a weighted graph Laplacian whose weights w_e = 1 / lbar_e^2 (relative
 * residuals) come from the mesh's own reference lengths: A depends on the
 * topology alone and is factorized once per embedder, so an iteration costs
 * a pass over the faces and a back-substitution with three right-hand
 * sides (9.4K vertices: about 1 ms each). x -> A^-1 b(x) is the gradient
 * step x - A^-1 grad E / 2, so L-BFGS with A^-1 as its initial inverse
 * Hessian starts with the plain local-global step and then bends its
 * steps with the curvature it has seen (Liu, Bouaziz & Kavan 2017); an
 * Armijo line search on E keeps every step downhill.
 *
 * Why this solver, measured on face-study (9.4K vertices, 87 rows, points
 * near their priors; tools/bench/bench_walk.c):
 *  - Levenberg-Marquardt on the lengths (stage_refine.c) factorizes a 3V x
 *    3V matrix per iteration: 12 iterations, 0.7-0.8 s CPU per point; 48
 *    and 3 s for a held-out face. A factor cached from another point
 *    preconditions it badly: the soft directions (flexes) are set by each
 *    point's residuals, and 40 CG steps per Newton step did not converge.
 *  - Local-global iterations leave the flexes where the start puts them
 *    (the prior's realization: the data's own bending) and fix the
 *    lengths: 40 iterations, 0.1 s, came 0.05 % of the bbox diagonal from
 *    held-out real faces (Levenberg-Marquardt: 0.07-0.09 %), bending 0.95-
 *    0.99 x the Levenberg-Marquardt result's. L-BFGS gave the same
 *    iterates as Anderson acceleration (m = 5) without its 30-50 % rejected
 *    steps.
 *  - For lengths no mesh has exactly (means, PC extremes), more exact
 *    lengths cost more bending, whatever the solver: the iterates move along
 *    that curve, so the accuracy stop (rms_tol, max_tol) is what keeps the
 *    surface smooth.
 */
#include "embed/embed_pkg.h"

#include <math.h>
#include <string.h>

/* doubles a face in emb->lg_rest (rest_triangles) */
#define REST 12

/* ---- the matrix: its pattern once per embedder, its values per solve ---- */

static es_status prepare(es_embedder *emb, int history)
{
    int64_t nv = emb->nv, ne = emb->ne;
    es_status rc;
    if (emb->lg_hist.m != history || emb->lg_hist.n != 3 * nv) {
        es__lbfgs_free(emb->ctx, &emb->lg_hist);
        if ((rc = es__lbfgs_init(emb->ctx, &emb->lg_hist, 3 * nv, history)) != ES_OK) return rc;
    }
    if (emb->F1) return ES_OK;
    if ((!emb->lg_w && !(emb->lg_w = es__alloc_array(emb->ctx, ne + 1, sizeof(double)))) ||
        (!emb->lg_wf && !(emb->lg_wf = es__alloc_array(emb->ctx, ne + 1, sizeof(double)))) ||
        (!emb->lg_rest && !(emb->lg_rest = es__alloc_array(emb->ctx, REST * emb->nf + 1, sizeof(double)))) ||
        (!emb->lg_work && !(emb->lg_work = es__alloc_array(emb->ctx, 6 * 3 * nv + 1, sizeof(double)))))
        return ES_ENOMEM;
    if (!emb->A1) emb->A1 = es__sparse_mat_copy(emb->sp, emb->H1);
    if (!emb->LB) emb->LB = es__sparse_dense_new(emb->sp, nv, 3);
    if (emb->A1 && emb->LB) emb->F1 = es__sparse_factor_copy(emb->sp, emb->L1);
    if (!emb->A1 || !emb->LB || !emb->F1) {
        rc = es__solver_check(emb, "allocate (local-global)");
        return rc != ES_OK ? rc : es__fail(emb->ctx, ES_ENOMEM, "embed: CHOLMOD out of memory");
    }
    return ES_OK;
}

/* x, cp: A1's values and column pointers */
static void add_off(const es_embedder *emb, double *x, const int64_t *cp, int64_t e, double w)
{
    x[es__pos_off(cp, 1, emb->rank, e, emb->edges[2 * e + 1], 0, 0)] += w;
}

static void add_diag(const es_embedder *emb, double *x, const int64_t *cp, int64_t v, double w)
{
    x[es__pos_diag(cp, 1, emb->nlow, v, 0, 0)] += w;
}

/* The weights and A for lengths L (relative residuals: 1 / l^2 at mean
 * length 1) and A's numeric factorization (9.4K vertices: about 9 ms, a few
 * iterations' worth; weights from the target rather than from a fixed
 * reference keep the solve of a point independent of what the embedder
 * solved before). A warm solve (reuse > 0) keeps the last factor while no
 * weight moved more than `reuse` from those it was made with: the factor
 * is only L-BFGS's initial inverse Hessian (apply_inverse), the energy and
 * its gradient use A as assembled now, so a slightly stale factor costs at
 * most a few more iterations, and a walk's frames skip a factorization
 * each (face-study: 14 % of a fast frame's CPU). */
static int factor_still_fits(const es_embedder *emb, double reuse)
{
    /* all but 1 % of the weights within `reuse`, and none doubled or
     * halved: a walk along face-study's PC 1 in 20 frames moves the median
     * weight 0.5 % a frame but a few short edges' by 12-35 %, and a test of
     * every weight refactored every frame */
    int64_t off = 0, allowed = emb->ne / 100;
    if (!(reuse > 0) || !emb->lg_have_factor) return 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        double d = fabs(emb->lg_w[e] - emb->lg_wf[e]);
        if (d > reuse * emb->lg_wf[e] && (++off > allowed || d > emb->lg_wf[e] ||
                                          2 * emb->lg_w[e] < emb->lg_wf[e]))
            return 0;
    }
    return 1;
}

static es_status assemble(es_embedder *emb, const double *L, double reuse)
{
    int64_t nv = emb->nv, ne = emb->ne;
    const int64_t *EF = es_mesh_edge_faces(emb->mesh);
    double lmean = 0, dmean = 0, *x = es__sparse_mat_values(emb->A1);
    const int64_t *cp = es__sparse_mat_colptr(emb->A1);
    memset(x, 0, (size_t)es__sparse_mat_nzmax(emb->A1) * sizeof(double));
    for (int64_t e = 0; e < ne; e++) lmean += L[e];
    lmean /= (double)(ne > 0 ? ne : 1);
    for (int64_t e = 0; e < ne; e++) {
        int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1];
        double l = L[e] / lmean, w;
        emb->lg_w[e] = 1.0 / (l * l);
        /* one term per face beside the edge */
        w = emb->lg_w[e] * (double)((EF[2 * e] >= 0) + (EF[2 * e + 1] >= 0));
        add_off(emb, x, cp, e, -w);
        add_diag(emb, x, cp, a, w);
        add_diag(emb, x, cp, b, w);
        dmean += 2 * w;
    }
    dmean /= (double)(nv > 0 ? nv : 1);
    /* translations leave E unchanged: a proximal term eps |x - x_k|^2
     * (eps 1e-9 of the mean diagonal) makes A definite without moving any
     * fixed point; vertices in no face keep their positions */
    emb->lg_eps = 1e-9 * dmean;
    for (int64_t v = 0; v < nv; v++)
        add_diag(emb, x, cp, v, emb->off[v + 1] == emb->off[v] ? 1.0 : emb->lg_eps);
    if (factor_still_fits(emb, reuse)) return ES_OK;
    emb->lg_have_factor = 0;
    es__sparse_clear_status(emb->sp);
    if (!es__sparse_factorize(emb->sp, emb->A1, emb->F1) ||
        es__sparse_status(emb->sp, NULL) != ES__SPARSE_OK) {
        es_status rc = es__solver_check(emb, "factorize (local-global)");
        return rc != ES_OK ? rc : es__fail(emb->ctx, ES_ENUMERIC,
                                           "embed: the local-global matrix is singular");
    }
    memcpy(emb->lg_wf, emb->lg_w, (size_t)ne * sizeof *emb->lg_wf);
    emb->lg_have_factor = 1;
    return ES_OK;
}

/* ---- one point's part ---------------------------------------------------- */

/* Each face's triangle of lengths L as the 2D vectors of its edges k = 0,
 * 1, 2 (edge k joins corners k and k + 1), from corner 0's angle by
 * Kahan's formula (emb->ang, es__corner_angles), each times its edge's
 * weight, then the three weights and their inverses: REST doubles a face,
 * read in order by the local step (the weights gathered by edge cost a
 * cache miss each; the inverses spare it three divisions a face). A face
 * whose lengths break the triangle inequality is flattened to a segment. */
static void rest_triangles(es_embedder *emb, const double *L)
{
    const int64_t *FE = es_mesh_face_edges(emb->mesh);
    for (int64_t f = 0; f < emb->nf; f++) {
        double l0 = L[FE[3 * f]], l2 = L[FE[3 * f + 2]], th = emb->ang[3 * f];
        double t2x = l2 * cos(th), t2y = l2 * sin(th);
        double *r = emb->lg_rest + REST * f, w[3];
        for (int k = 0; k < 3; k++) w[k] = emb->lg_w[FE[3 * f + k]];
        r[0] = w[0] * l0, r[1] = 0;                 /* corner 1 - corner 0 */
        r[2] = w[1] * (t2x - l0), r[3] = w[1] * t2y;   /* corner 2 - corner 1 */
        r[4] = -w[2] * t2x, r[5] = -w[2] * t2y;      /* corner 0 - corner 2 */
        r[6] = w[0], r[7] = w[1], r[8] = w[2];
        r[9] = 1.0 / w[0], r[10] = 1.0 / w[1], r[11] = 1.0 / w[2];
    }
}

/* R = S (S^T S)^(-1/2) for a 3 x 2 S (row-major): the 3 x 2 matrix with
 * orthonormal columns nearest to S. The square root of the 2 x 2 SPD
 * M = S^T S is (M + s I) / q, s = sqrt(det M), q = sqrt(tr M + 2 s), and
 * det(M + s I) = s q^2, so M^(-1/2) = adj(M + s I) / (s q): one division
 * (the local step's hottest loop; it had six). A face crushed to a segment
 * or a point gets any orthonormal pair whose first column follows S's
 * longer column. */
static void polar32(const double *S, double *R)
{
    double a11 = S[0] * S[0] + S[2] * S[2] + S[4] * S[4];
    double a12 = S[0] * S[1] + S[2] * S[3] + S[4] * S[5];
    double a22 = S[1] * S[1] + S[3] * S[3] + S[5] * S[5];
    double det = a11 * a22 - a12 * a12, tr = a11 + a22;
    if (tr > 0 && det > 1e-24 * tr * tr) {
        double s = sqrt(det), q = sqrt(tr + 2 * s), inv = 1.0 / (s * q);
        double i11 = (a22 + s) * inv, i12 = -a12 * inv, i22 = (a11 + s) * inv;
        for (int i = 0; i < 3; i++) {
            R[2 * i] = S[2 * i] * i11 + S[2 * i + 1] * i12;
            R[2 * i + 1] = S[2 * i] * i12 + S[2 * i + 1] * i22;
        }
        return;
    }
    int col = a11 >= a22 ? 0 : 1;
    double nc = sqrt(col ? a22 : a11), u[3], c[3] = {0, 0, 0}, dd = 0, nn = 0;
    for (int i = 0; i < 3; i++) u[i] = nc > 0 ? S[2 * i + col] / nc : (i == 0);
    c[fabs(u[0]) < 0.9 ? 0 : 1] = 1;
    for (int i = 0; i < 3; i++) dd += c[i] * u[i];
    for (int i = 0; i < 3; i++) {
        c[i] -= dd * u[i];
        nn += c[i] * c[i];
    }
    nn = sqrt(nn);
    for (int i = 0; i < 3; i++) {
        R[2 * i + col] = u[i];
        R[2 * i + 1 - col] = c[i] / nn;
    }
}

/* The local step at xyz: every face's R_f; returns E(xyz) and writes the
 * global step's right-hand side b (V x 3, column-major), proximal part
 * included. The sums are made per vertex in xyz's interleaved layout (a
 * face touches three vertices' 3 adjacent doubles, not nine scattered
 * ones) in acc (3 V), then moved into b. With w_k r_k stored (rest_
 * triangles), the residual is d_k - (R w_k r_k) / w_k. */
static double local_step(const es_embedder *emb, const double *xyz, double *b, double *acc)
{
    const int64_t *F = es_mesh_faces(emb->mesh);
    int64_t nv = emb->nv;
    double E = 0;
    memset(acc, 0, (size_t)(3 * nv) * sizeof *acc);
    for (int64_t f = 0; f < emb->nf; f++) {
        const int64_t *fv = F + 3 * f;
        const double *r = emb->lg_rest + REST * f, *w = r + 6, *wi = r + 9;
        const double *p0 = xyz + 3 * fv[0], *p1 = xyz + 3 * fv[1], *p2 = xyz + 3 * fv[2];
        double d[3][3], S[6], R[6];
        for (int i = 0; i < 3; i++) {
            d[0][i] = p1[i] - p0[i];
            d[1][i] = p2[i] - p1[i];
            d[2][i] = p0[i] - p2[i];
        }
        /* S = sum_k w_k d_k r_k^T: the weights are in r */
        for (int i = 0; i < 3; i++) {
            S[2 * i] = d[0][i] * r[0] + d[1][i] * r[2] + d[2][i] * r[4];
            S[2 * i + 1] = d[0][i] * r[1] + d[1][i] * r[3] + d[2][i] * r[5];
        }
        polar32(S, R);
        double *a0 = acc + 3 * fv[0], *a1 = acc + 3 * fv[1], *a2 = acc + 3 * fv[2];
        for (int k = 0; k < 3; k++) {
            double *to = k == 0 ? a1 : k == 1 ? a2 : a0, *from = k == 0 ? a0 : k == 1 ? a1 : a2;
            double iw = wi[k], e = 0;
            for (int i = 0; i < 3; i++) {
                double ri = R[2 * i] * r[2 * k] + R[2 * i + 1] * r[2 * k + 1];   /* w_k R r_k */
                double dv = d[k][i] - ri * iw;
                e += dv * dv;
                to[i] += ri;
                from[i] -= ri;
            }
            E += w[k] * e;
        }
    }
    for (int64_t v = 0; v < nv; v++) {
        double c = emb->off[v + 1] == emb->off[v] ? 1.0 : emb->lg_eps;
        for (int k = 0; k < 3; k++) b[v + nv * k] = acc[3 * v + k] + c * xyz[3 * v + k];
    }
    return E;
}

/* g = (grad E) / 2 = A x - b (the proximal parts cancel), xyz layout;
 * t: 2 V of work. */
static void half_gradient(const es_embedder *emb, const double *xyz, const double *b, double *g,
                          double *t)
{
    int64_t nv = emb->nv;
    for (int k = 0; k < 3; k++) {
        for (int64_t v = 0; v < nv; v++) t[v] = xyz[3 * v + k];
        es__sparse_sym_matvec(emb->A1, t, t + nv);
        for (int64_t v = 0; v < nv; v++) g[3 * v + k] = t[nv + v] - b[v + nv * k];
    }
}

/* d = A^-1 q (xyz layout; d may be q). */
static es_status apply_inverse(es_embedder *emb, const double *q, double *d)
{
    int64_t nv = emb->nv;
    double *b = es__sparse_dense_values(emb->LB);
    for (int64_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) b[v + nv * k] = q[3 * v + k];
    es__sparse_clear_status(emb->sp);
    if (!es__sparse_solve(emb->sp, emb->F1, emb->LB, 3, &emb->lg_sol)) {
        es_status rc = es__solver_check(emb, "solve (local-global)");
        return rc != ES_OK ? rc : ES_ENUMERIC;
    }
    const double *s = es__sparse_solution_values(&emb->lg_sol);
    for (int64_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) d[3 * v + k] = s[v + nv * k];
    return ES_OK;
}

es_status es__lg_solve(es_embedder *emb, const double *L, double *xyz, const es__lg_opts *o,
                       es__lg_result *res)
{
    int64_t n3 = 3 * emb->nv;
    const int accuracy = o->rms_tol > 0 && o->max_tol > 0;
    double *g, *gn, *d, *xt, *b, *tmp, *acc, E, hist[5];
    es_status rc;
    memset(res, 0, sizeof *res);
    if ((rc = prepare(emb, o->history > 0 ? o->history : 6)) != ES_OK ||
        (rc = assemble(emb, L, o->factor_reuse)) != ES_OK)
        return rc;
    g = emb->lg_work, gn = g + n3, d = gn + n3, xt = d + n3, tmp = xt + n3, acc = tmp + n3;
    b = es__sparse_dense_values(emb->LB);
    es__lbfgs_reset(&emb->lg_hist);
    es__corner_angles(emb->mesh, L, 0, emb->ang);
    rest_triangles(emb, L);
    E = local_step(emb, xyz, b, acc);
    half_gradient(emb, xyz, b, g, tmp);
    for (int it = 0;; it++) {
        double rms, mx;
        es__length_fit(emb, xyz, L, &rms, &mx);
        res->energy = E, res->rms = rms, res->max = mx;
        if (o->verbose)
            es__info(emb->ctx, "embed: local-global %d energy %.6g rms %.4g %% max %.4g %%", it,
                     E, 100 * rms, 100 * mx);
        if (accuracy && rms <= o->rms_tol && mx <= o->max_tol) {
            res->met = 1;
            break;
        }
        if (it >= o->max_iter || !(E > 0)) break;
        /* the relative stopping rule over a window of five iterations */
        if (it >= 5 && hist[it % 5] - E < 5.0 * o->rtol * E) break;
        hist[it % 5] = E;
        if (emb->progress_total)
            es__progress(emb->ctx, "embedding", it < emb->progress_total ? it : emb->progress_total - 1,
                         emb->progress_total);
        /* the quasi-Newton direction: x+ = x - t d */
        memcpy(d, g, (size_t)n3 * sizeof *d);
        es__lbfgs_first(&emb->lg_hist, d);
        if ((rc = apply_inverse(emb, d, d)) != ES_OK) return rc;
        es__lbfgs_second(&emb->lg_hist, d);
        double slope = -2.0 * es__dot(g, d, n3), t = 1, Et = E;
        if (!(slope < 0)) {   /* not downhill: forget the pairs, take the plain step */
            es__lbfgs_reset(&emb->lg_hist);
            if ((rc = apply_inverse(emb, g, d)) != ES_OK) return rc;
            slope = -2.0 * es__dot(g, d, n3);
            if (!(slope < 0)) break;
        }
        int ok = 0;
        for (int ls = 0; ls < 12 && !ok; ls++, t *= 0.5) {
            for (int64_t i = 0; i < n3; i++) xt[i] = xyz[i] - t * d[i];
            Et = local_step(emb, xt, b, acc);
            ok = Et <= E + 1e-4 * t * slope;
        }
        if (!ok) {   /* b is xt's: make it xyz's again for the caller's reuse */
            local_step(emb, xyz, b, acc);
            break;
        }
        half_gradient(emb, xt, b, gn, tmp);
        es__lbfgs_push(&emb->lg_hist, xyz, xt, g, gn);
        memcpy(xyz, xt, (size_t)n3 * sizeof *xyz);
        memcpy(g, gn, (size_t)n3 * sizeof *g);
        E = Et;
        res->iters++;
    }
    return ES_OK;
}
