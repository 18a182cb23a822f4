/* lib/embed/stage_dihedrals.c — stage 1 of the embedding: dihedral angles
 * that close every interior vertex figure.
 *
 * The closure energy E = sum_v ||P_v - I||_F^2 (edge-length-interpolation
 * Section 2, eq. 2-3; the walk P_v is closure.c's) is minimized by
 * Levenberg-Marquardt (Marquardt 1963) on its 9 residuals per interior
 * vertex, with the sparse Gauss-Newton matrix J^T J (variables: interior
 * edges with an interior end, coupled when they are spokes of one vertex)
 * factorized by CHOLMOD, or solved by CG on the lagged factor when that
 * suffices (the paper uses L-BFGS here). Whether stage 1 runs at all is
 * the driver's decision (solve.c): it can pull interpolated dihedrals into
 * a wrong closure minimum.
 */
#include "embed/embed_pkg.h"

#include <math.h>
#include <string.h>

/* One pass over the interior vertices, each through closure.c's walk in
 * the embedder's buffers (no allocation per call: stage 1 calls this for
 * every trial step). */
double es__closure_eval(es_embedder *emb, const double *alpha, int with_jac, double *vclos)
{
    double total = 0;
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t o = emb->off[v], k = emb->off[v + 1] - o;
        if (vclos) vclos[v] = 0;
        if (!k || emb->vb[v]) continue;
        for (int64_t j = 0; j < k; j++) emb->fanal[j] = alpha[emb->se[o + j]];
        double ev = es__fan_closure(k, emb->theta + o, emb->fanal, emb->res + 9 * v,
                                    with_jac ? emb->jw + 9 * o : NULL, emb->fanwork);
        if (vclos) vclos[v] = ev;
        total += ev;
    }
    return total;
}

/* *lambda_io carries the damping from one call to the next (start: 1e-3),
 * so that a run split into a trial and the rest follows the same path as
 * one run: restarting the damping sent the oracle's bumpy icosphere into
 * another closure minimum. */
es_status es__stage_dihedrals(es_embedder *emb, const es_embed_opts *o, int max_iter,
                              double *alpha, double *e_out, int64_t *iters, double *lambda_io)
{
    es_status need = es__embedder_need(emb, ES__NEED_CLOSURE);
    if (need != ES_OK) return need;
    int64_t n = emb->nvar, it = 0;
    double *x = emb->HA ? es__sparse_mat_values(emb->HA) : NULL, *g = emb->grad;
    double lambda = *lambda_io, e;
    int have_factor = 0;
    e = es__closure_eval(emb, alpha, 0, NULL);
    if (n == 0 || max_iter <= 0) {
        *e_out = e;
        return ES_OK;
    }
    while (it < max_iter && e > o->dihedral_tol * (double)(emb->nint + 1)) {
        double e_new = 0;
        int accepted = 0;
        es__closure_eval(emb, alpha, 1, NULL);
        memset(x, 0, (size_t)es__sparse_mat_nzmax(emb->HA) * sizeof(double));
        for (int64_t a = 0; a < n; a++) g[a] = 0;
        for (int64_t v = 0; v < emb->nv; v++) {
            int64_t o0 = emb->off[v], k = emb->off[v + 1] - o0;
            const double *J = emb->jw + 9 * o0, *r = emb->res + 9 * v;
            const int64_t *m = emb->amap + emb->amap_off[v];
            if (!k || emb->vb[v]) continue;
            for (int64_t i = 0; i < k; i++) {
                double gi = 0;
                for (int q = 0; q < 9; q++) gi += J[9 * i + q] * r[q];
                g[emb->var[emb->se[o0 + i]]] += gi;
                for (int64_t j = i; j < k; j++) {
                    double h = 0;
                    for (int q = 0; q < 9; q++) h += J[9 * i + q] * J[9 * j + q];
                    x[m[i * k + j]] += h;
                }
            }
        }
        /* i == j pairs landed once on the diagonal, other pairs of one
         * vertex once in the upper triangle: x holds the upper part of J^T J.
         * Marquardt damping scales the diagonal; factorize, try, adapt. */
        {
            double *dg = emb->diag, mean = 0;
            for (int64_t a = 0; a < n; a++) {
                dg[a] = x[emb->adiag[a]];
                mean += dg[a];
            }
            mean /= (double)n;
            for (int tries = 0; tries < 12 && !accepted; tries++) {
                double *bx = es__sparse_dense_values(emb->BA);
                int st;
                double *dx = emb->diag + n, *rhs = dx + n;
                int used = -1;
                for (int64_t a = 0; a < n; a++) {
                    x[emb->adiag[a]] = dg[a] + lambda * (dg[a] + 1e-9 * mean) + 1e-300;
                    rhs[a] = -g[a];
                }
                if (have_factor)
                    used = es__lagged_pcg(emb, emb->HA, emb->LA, emb->BA, rhs, dx,
                                      fmin(1e-2, fmax(1e-12, sqrt(e))), 12);
                if (used < 0) {
                    memcpy(bx, rhs, (size_t)n * sizeof *bx);
                    st = es__factor_solve(emb, emb->HA, emb->LA, emb->BA, 1);
                    if (st < 0) return ES_ENUMERIC;
                    have_factor = st == 0;
                    emb->nfactor++;
                    if (st == 0)
                        memcpy(dx, es__sparse_solution_values(&emb->sol), (size_t)n * sizeof *dx);
                } else {
                    st = 0;
                }
                for (int64_t a = 0; a < n; a++) x[emb->adiag[a]] = dg[a];
                if (st == 0) {
                    for (int64_t ed = 0; ed < emb->ne; ed++)
                        emb->alpha_try[ed] =
                            emb->var[ed] >= 0 ? alpha[ed] + dx[emb->var[ed]] : alpha[ed];
                    e_new = es__closure_eval(emb, emb->alpha_try, 0, NULL);
                    if (isfinite(e_new) && e_new < e) {
                        accepted = 1;
                        memcpy(alpha, emb->alpha_try, (size_t)emb->ne * sizeof *alpha);
                        lambda = fmax(lambda / 3.0, 1e-12);
                        break;
                    }
                }
                lambda *= 8.0;
            }
        }
        it++;
        if (o->verbose)
            es__info(emb->ctx, "embed: dihedrals %lld E %.6g -> %.6g lambda %.3g", (long long)it,
                     e, e_new, lambda);
        if (!accepted) break;
        if (e - e_new < o->dihedral_rtol * e) {
            e = e_new;
            break;
        }
        e = e_new;
    }
    *iters += it;
    *e_out = e;
    *lambda_io = lambda;
    return ES_OK;
}
