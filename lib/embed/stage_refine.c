/* lib/embed/stage_refine.c — stage 4 of the embedding: Levenberg-Marquardt
 * (Marquardt 1963) on the relative edge-length residuals (|x_a - x_b| -
 * l_e) / l_e in position space.
 *
 * Vertex closure (stages 1-3, edge-length-interpolation Section 2) leaves
 * open the holonomy around holes and handles (failure A of the oracle
 * README) and the edges between two boundary vertices (failure B); this
 * stage closes both. Its matrix is the Gauss-Newton matrix plus the
 * curvature of the stretched edges' residuals, in H3's pattern, solved by
 * CG on a lagged factor while that converges and by refactorization
 * otherwise. Rigid motions (and, on open meshes, flexes) are held by the
 * damping, so the result stays near the stage-3 mesh; with a prior, the
 * bending term (bending.c) holds the flexes near the data's dihedrals.
 */
#include "embed/embed_pkg.h"

#include <math.h>
#include <string.h>

/* The cost stage 4 minimizes: sum_e r_e^2 of the relative residuals. */
static double length_cost(const es_embedder *emb, const double *xyz, const double *L)
{
    double c = 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        const double *a = xyz + 3 * emb->edges[2 * e], *b = xyz + 3 * emb->edges[2 * e + 1];
        double d0 = b[0] - a[0], d1 = b[1] - a[1], d2 = b[2] - a[2];
        double r = (sqrt(d0 * d0 + d1 * d1 + d2 * d2) - L[e]) / L[e];
        c += r * r;
    }
    return c;
}

/* The cost with the bending prior's term when bp is active. */
static double refine_cost(const es_embedder *emb, const double *xyz, const double *L,
                          const es__bend_prior *bp)
{
    double c = length_cost(emb, xyz, L);
    if (bp) c += es__bend_cost(emb, bp, xyz);
    return c;
}

es_status es__stage_refine(es_embedder *emb, const double *L, double *xyz,
                           es__bend_prior *bp, int max_iter, double rtol, double tol,
                           int verbose, int64_t *iters)
{
    double hist[4] = {0, 0, 0, 0}, c_prev = 0;
    const int pcg_max = 12, pcg_give_up = 2;
    int pcg_fail = 0;
    int64_t nv = emb->nv, n3 = 3 * nv, ne = emb->ne;
    double *x = emb->H3->x, *g = emb->grad, *dg = emb->diag, *step = emb->pcg + 4 * n3;
    double *hd = step + n3, lambda = 1e-4, c, ctol = tol * tol * (double)ne;
    int have_factor = 0, it_hold = 0;
    /* mu decays within the run (bp->decay < 1) down to bp->mu_min: while it
     * does, the cost changes from one iteration to the next, so it is
     * evaluated afresh and the relative stopping rule waits */
    int annealing = bp && bp->decay > 0 && bp->decay < 1 && bp->mu > bp->mu_min;
    if (bp && !(bp->mu > 0)) bp = NULL;
    c = refine_cost(emb, xyz, L, bp);
    for (int it = 0; it < max_iter && c > ctol; it++) {
        double c_new = c, mean = 0, pred, rho = 0;
        int accepted = 0, st, used = -1;
        if (bp && annealing && it > 0) {
            bp->mu = fmax(bp->mu * bp->decay, bp->mu_min);
            annealing = bp->mu > bp->mu_min;
            c = refine_cost(emb, xyz, L, bp);
            c_prev = 0;
            if (!annealing) it_hold = it;   /* the stopping rule counts from here */
        }
        memset(x, 0, emb->H3->nzmax * sizeof(double));
        memset(g, 0, (size_t)n3 * sizeof(double));
        for (int64_t e = 0; e < ne; e++) {
            int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1];
            const double *pa = xyz + 3 * a, *pb = xyz + 3 * b;
            double d[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]}, w[3];
            double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), r;
            if (!(dl > 0)) dl = 1e-300;
            r = (dl - L[e]) / L[e];
            for (int i = 0; i < 3; i++) w[i] = d[i] / (dl * L[e]);
            for (int i = 0; i < 3; i++) {
                g[3 * a + i] -= w[i] * r;
                g[3 * b + i] += w[i] * r;
            }
            /* Gauss-Newton w w^T plus the residual's own curvature
             * r (I - u u^T) / (|d| l), u = d / |d|, where that is positive
             * semi-definite: on stretched edges (r > 0). Gauss-Newton alone
             * sees no curvature across an edge, so on nearly flexible meshes
             * the flexes crawl (linear convergence at a non-zero residual);
             * the stretched-edge term gives them their true stiffness.
             * Compressed edges (r < 0) would make the matrix indefinite and
             * are left out, as in projected Newton methods (the full Hessian
             * stalled at its first iteration on the midpoints of real pairs). */
            {
                double sc = r > 0 ? r / (dl * L[e]) : 0, dd = dl * dl;
                for (int q = 0; q < 3; q++)
                    for (int p = 0; p < 3; p++) {
                        double h = w[p] * w[q] + sc * ((p == q) - d[p] * d[q] / dd);
                        x[es__pos_off(emb->H3, 3, emb->rank, e, b, p, q)] -= h;
                        if (p <= q) {
                            x[es__pos_diag(emb->H3, 3, emb->nlow, a, p, q)] += h;
                            x[es__pos_diag(emb->H3, 3, emb->nlow, b, p, q)] += h;
                        }
                    }
            }
        }
        if (bp) es__bend_assemble(emb, xyz, bp, g);
        for (int64_t i = 0; i < n3; i++) {
            dg[i] = x[es__pos_diag(emb->H3, 3, emb->nlow, i / 3, (int)(i % 3), (int)(i % 3))];
            mean += dg[i];
        }
        mean /= (double)n3;
        for (int tries = 0; tries < 20 && !accepted; tries++) {
            /* forcing term after Eisenstat and Walker (1996): loose while the
             * cost crawls, tight when it falls fast (quadratic phase) */
            double eta = fmin(0.1, fmax(1e-10, c_prev > 0 ? c / c_prev : 0.1));
            for (int64_t i = 0; i < n3; i++) {
                double v = emb->vweight[i / 3] == 0 ? mean : dg[i];
                x[es__pos_diag(emb->H3, 3, emb->nlow, i / 3, (int)(i % 3), (int)(i % 3))] =
                    v + lambda * (v + 1e-8 * mean) + 1e-300;
                hd[i] = -g[i];
            }
            /* a lagged factor helps while the matrix drifts slowly; once it has
             * failed twice in a row (the damping has fallen so far that the
             * near-flexes dominate), every try would pay for a failed PCG run
             * and a factorization, so factorize directly from then on */
            used = -1;
            if (have_factor && pcg_fail < pcg_give_up) {
                used = es__lagged_pcg(emb, emb->H3, emb->L3, emb->B3, hd, step, eta, pcg_max);
                pcg_fail = used < 0 ? pcg_fail + 1 : 0;
            }
            if (used < 0) {
                memcpy(emb->B3->x, hd, (size_t)n3 * sizeof(double));
                emb->B3->ncol = 1;
                st = es__factor_solve(emb, emb->H3, emb->L3, emb->B3);
                emb->B3->ncol = 3;
                if (st < 0) return ES_ENUMERIC;
                have_factor = st == 0;
                emb->nfactor++;
                if (st == 0) memcpy(step, emb->X->x, (size_t)n3 * sizeof(double));
            } else {
                st = 0;
            }
            /* restore the undamped diagonal for the model and matvecs */
            for (int64_t i = 0; i < n3; i++)
                x[es__pos_diag(emb->H3, 3, emb->nlow, i / 3, (int)(i % 3), (int)(i % 3))] =
                    emb->vweight[i / 3] == 0 ? 0 : dg[i];
            if (st == 0) {
                double *xt = emb->xyz_try;
                for (int64_t i = 0; i < n3; i++) xt[i] = xyz[i] + step[i];
                c_new = refine_cost(emb, xt, L, bp);
                es__sym_matvec(emb->H3, step, hd);
                pred = -2.0 * es__dot(g, step, n3) - es__dot(step, hd, n3);
                rho = pred > 0 ? (c - c_new) / pred : -1;
                if (isfinite(c_new) && c_new < c && rho > 0) {
                    memcpy(xyz, xt, (size_t)n3 * sizeof *xyz);
                    accepted = 1;
                    /* Nielsen's gain-ratio rule (1999) let lambda creep up on
                     * these problems (rho stays small where the residual is
                     * not zero); Marquardt's fixed factors converge faster. */
                    lambda = fmax(lambda / (rho > 0.25 ? 5.0 : 2.0), 1e-12);
                    break;
                }
                /* the step overshot: try it shortened (1/2, 1/4, 1/8) before
                 * raising the damping, since a cost evaluation is far cheaper
                 * than the factorization a new damping needs. Taken only
                 * where the model still predicts the gain well (rho > 0.25),
                 * damping unchanged. On the midpoints of real pairs this
                 * saves most of the first iteration's rejected
                 * factorizations: 0-28 % less refinement time on nine
                 * meshes of 2K-54K vertices, RMS error equal or lower. */
                if (isfinite(pred) && pred > 0) {
                    double gs = es__dot(g, step, n3), shs = es__dot(step, hd, n3);
                    for (double t = 0.5; t > 0.1 && !accepted; t *= 0.5) {
                        double pt = -2.0 * t * gs - t * t * shs;
                        for (int64_t i = 0; i < n3; i++) xt[i] = xyz[i] + t * step[i];
                        c_new = refine_cost(emb, xt, L, bp);
                        rho = pt > 0 ? (c - c_new) / pt : -1;
                        if (isfinite(c_new) && c_new < c && rho > 0.25) {
                            memcpy(xyz, xt, (size_t)n3 * sizeof *xyz);
                            accepted = 1;
                        }
                    }
                    if (accepted) break;
                }
            }
            lambda *= 10.0;
        }
        (*iters)++;
        if (emb->progress_total) {   /* stages 1-3 were steps 1 and 2 */
            int64_t done = 3 + (int64_t)it, total = emb->progress_total;
            es__progress(emb->ctx, "embedding", done < total ? done : total - 1, total);
        }
        if (verbose)
            es__info(emb->ctx, "embed: refine %d cost %.6g -> %.6g lambda %.3g rho %.3g pcg %d",
                     it, c, c_new, lambda, rho, used);
        if (!accepted) break;
        /* relative stopping rule over a window of 3 iterations (oracle README,
         * failure D: an absolute rule stops too early or too late) */
        hist[it % 4] = c_new;
        c_prev = c;
        if (it >= it_hold + 3 && !annealing &&
            hist[(it - 3) % 4] - c_new < 3.0 * rtol * c_new) {
            c = c_new;
            break;
        }
        c = c_new;
    }
    return ES_OK;
}
