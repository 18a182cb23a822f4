/* lib/embed/stage_refine.c — stage 4 of the embedding: Levenberg-Marquardt
 * (Marquardt 1963) on the relative edge-length residuals (|x_a - x_b| -
 * l_e) / l_e in position space.
 *
 * Vertex closure (stages 1-3, edge-length-interpolation Section 2) leaves
 * open the holonomy around holes and handles (failure A of the oracle
 * README) and the edges between two boundary vertices (failure B); this
 * stage closes both. Its matrix is the Gauss-Newton matrix plus the
 * curvature of the stretched edges' residuals, in H3's pattern, solved by
 * a numeric factorization, or by CG on the factor of an earlier matrix
 * at the lags where that has converged. Rigid motions (and, on
 * open meshes, flexes) are held by the damping, so the result stays near
 * the stage-3 mesh; with a prior, the bending term (bending.c) holds the
 * flexes near the data's dihedrals. It stops as soon as the lengths meet
 * the accuracy asked for (es__refine_opts).
 */
#include "embed/embed_pkg.h"

#include <math.h>
#include <string.h>

es__refine_opts es__refine_opts_from(const es_embed_opts *o)
{
    es__refine_opts r = {o->refine_max_iter, o->refine_rtol, o->refine_tol, o->refine_rms_tol,
                         o->refine_max_tol, o->verbose};
    return r;
}

/* The cost stage 4 minimizes, sum_e r_e^2 of the relative residuals (plus
 * the bending term when bp is active), and the report's measures of the
 * same positions: the RMS ratio and the max relative error. */
typedef struct fit {
    double cost, rms, max;
} fit;

static fit evaluate(const es_embedder *emb, const double *xyz, const double *L,
                    const es__bend_prior *bp)
{
    double c = 0, ss = 0, sl = 0, mx = 0;
    fit f;
    for (int64_t e = 0; e < emb->ne; e++) {
        const double *a = xyz + 3 * emb->edges[2 * e], *b = xyz + 3 * emb->edges[2 * e + 1];
        double d0 = b[0] - a[0], d1 = b[1] - a[1], d2 = b[2] - a[2];
        double d = sqrt(d0 * d0 + d1 * d1 + d2 * d2) - L[e], r = d / L[e];
        c += r * r;
        ss += d * d;
        sl += L[e];
        if (!(fabs(r) <= mx)) mx = fabs(r);
    }
    f.cost = bp ? c + es__bend_cost(emb, bp, xyz) : c;
    f.rms = sqrt(ss / (double)emb->ne) / (sl / (double)emb->ne);
    f.max = mx;
    return f;
}

/* H3 (undamped) and the half-gradient g of the cost at xyz. */
static void assemble(es_embedder *emb, const double *L, const double *xyz,
                     const es__bend_prior *bp, double *g)
{
    double *x = es__sparse_mat_values(emb->H3);
    memset(x, 0, (size_t)es__sparse_mat_nzmax(emb->H3) * sizeof(double));
    memset(g, 0, (size_t)(3 * emb->nv) * sizeof(double));
    for (int64_t e = 0; e < emb->ne; e++) {
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
        double sc = r > 0 ? r / (dl * L[e]) : 0, dd = dl * dl;
        for (int q = 0; q < 3; q++)
            for (int p = 0; p < 3; p++) {
                double h = w[p] * w[q] + sc * ((p == q) - d[p] * d[q] / dd);
                x[es__h3_off(emb, e, p, q)] -= h;
                if (p <= q) {
                    x[es__h3_diag(emb, a, p, q)] += h;
                    x[es__h3_diag(emb, b, p, q)] += h;
                }
            }
    }
    if (bp) es__bend_assemble(emb, xyz, bp, g);
}

/* How many CG steps on the factor of a matrix `lag` iterations old may
 * take, 0 for none. Near the solution the lagged factor needed 6-11 steps
 * where it converged at all, and on the faces it converged one iteration
 * after a factorization and failed after two, so trying every iteration
 * wasted a CG run on every other one: CG is tried only at lags where it
 * has converged before in this refinement. The rule sees only the
 * iterates, never the clock, so a solve gives the same mesh on every run
 * and whatever the embedder solved before. */
static int cg_budget(const es_embedder *emb, int lag)
{
    return lag <= emb->cg_lag_ok ? 12 : 0;
}

/* Whether a CG run on a factor `lag` iterations old converged: the lags
 * allowed next grow by one on success, shrink below a failure. */
static void cg_outcome(es_embedder *emb, int lag, int steps)
{
    if (steps >= 0) {
        if (lag >= emb->cg_lag_ok) emb->cg_lag_ok = lag + 1;
    } else {
        emb->cg_lag_ok = lag - 1 > 0 ? lag - 1 : 0;
    }
}

/* Factorize the damped H3 and solve H3 stepp = bp (H3's order) in place of
 * the right-hand side. Returns 0, 1 if not positive definite, -1 on a
 * solver failure. */
static int factor_step(es_embedder *emb, const double *bp, double *stepp)
{
    int64_t n3 = 3 * emb->nv;
    int st;
    memcpy(es__sparse_dense_values(emb->B3), bp, (size_t)n3 * sizeof(double));
    st = es__factor_solve(emb, emb->H3, emb->L3, emb->B3, 1);
    emb->nfactor++;
    if (st == 0) memcpy(stepp, es__sparse_solution_values(&emb->sol), (size_t)n3 * sizeof(double));
    return st;
}

/* Write the damped (or, lambda < 0, the undamped) diagonal into H3. */
static void set_diagonal(es_embedder *emb, const double *dg, double mean, double lambda)
{
    double *x = es__sparse_mat_values(emb->H3);
    for (int64_t i = 0; i < 3 * emb->nv; i++) {
        int64_t v = i / 3, k = i % 3;
        double d = emb->vweight[v] == 0 ? mean : dg[i];
        x[es__h3_diag(emb, v, (int)k, (int)k)] =
            lambda < 0 ? (emb->vweight[v] == 0 ? 0 : dg[i]) : d + lambda * (d + 1e-8 * mean) + 1e-300;
    }
}

es_status es__stage_refine(es_embedder *emb, const double *L, double *xyz, es__bend_prior *bp,
                           const es__refine_opts *ro, int64_t *iters)
{
    es_status need = es__embedder_need(emb, ES__NEED_H3);
    if (need != ES_OK) return need;
    double hist[4] = {0, 0, 0, 0}, c_prev = 0;
    int64_t nv = emb->nv, n3 = 3 * nv, ne = emb->ne;
    double *x = es__sparse_mat_values(emb->H3), *g = emb->grad, *dg = emb->diag;
    double *step = emb->pcg + 4 * n3, *hp = step + n3, *stepp = hp + n3;
    double lambda = 1e-4, ctol = ro->tol * ro->tol * (double)ne;
    int it_hold = 0, lag = -1;   /* lag: iterations since the last factorization (-1: none) */
    const int accuracy = ro->rms_tol > 0 && ro->max_tol > 0;
    fit cur;
    /* mu decays within the run (bp->decay < 1) down to bp->mu_min: while it
     * does, the cost changes from one iteration to the next, so it is
     * evaluated afresh and the relative stopping rule waits */
    int annealing = bp && es__bend_annealing(bp);
    if (bp && !(bp->mu > 0)) bp = NULL;
    emb->cg_lag_ok = 1;   /* learnt afresh in every refinement */
    cur = evaluate(emb, xyz, L, bp);
    for (int it = 0; it < ro->max_iter && cur.cost > ctol; it++) {
        double mean = 0, pred, rho = 0;
        fit nxt = cur;
        int accepted = 0, st, used = -1;
        if (accuracy && cur.rms <= ro->rms_tol && cur.max <= ro->max_tol) break;
        if (bp && annealing && it > 0) {
            annealing = es__bend_anneal(bp);
            cur = evaluate(emb, xyz, L, bp);
            c_prev = 0;
            if (!annealing) it_hold = it;   /* the stopping rule counts from here */
        }
        assemble(emb, L, xyz, bp, g);
        for (int64_t i = 0; i < n3; i++) {
            dg[i] = x[es__h3_diag(emb, i / 3, (int)(i % 3), (int)(i % 3))];
            mean += dg[i];
        }
        mean /= (double)n3;
        if (lag >= 0) lag++;
        for (int tries = 0; tries < 20 && !accepted; tries++) {
            /* forcing term after Eisenstat and Walker (1996): loose while the
             * cost crawls, tight when it falls fast (quadratic phase) */
            double eta = fmin(0.1, fmax(1e-10, c_prev > 0 ? cur.cost / c_prev : 0.1));
            int budget = lag >= 0 ? cg_budget(emb, lag) : 0;
            set_diagonal(emb, dg, mean, lambda);
            for (int64_t v = 0; v < nv; v++)
                for (int r = 0; r < 3; r++) hp[3 * emb->pinv[v] + r] = -g[3 * v + r];
            used = -1;
            if (budget > 0) {
                used = es__lagged_pcg(emb, emb->H3, emb->L3, emb->B3, hp, stepp, eta, budget);
                cg_outcome(emb, lag, used);
            }
            if (used < 0) {
                st = factor_step(emb, hp, stepp);
                if (st < 0) return ES_ENUMERIC;
                lag = st == 0 ? 0 : -1;
            } else {
                st = 0;
            }
            /* restore the undamped diagonal for the model and matvecs */
            set_diagonal(emb, dg, mean, -1);
            if (st == 0) {
                double *xt = emb->xyz_try;
                es__h3_unpermute(emb, stepp, step, 1);
                for (int64_t i = 0; i < n3; i++) xt[i] = xyz[i] + step[i];
                nxt = evaluate(emb, xt, L, bp);
                es__sparse_sym_matvec(emb->H3, stepp, hp);
                double gs = es__dot(g, step, n3), shs = es__dot(stepp, hp, n3);
                pred = -2.0 * gs - shs;
                rho = pred > 0 ? (cur.cost - nxt.cost) / pred : -1;
                if (isfinite(nxt.cost) && nxt.cost < cur.cost && rho > 0) {
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
                    for (double t = 0.5; t > 0.1 && !accepted; t *= 0.5) {
                        double pt = -2.0 * t * gs - t * t * shs;
                        for (int64_t i = 0; i < n3; i++) xt[i] = xyz[i] + t * step[i];
                        nxt = evaluate(emb, xt, L, bp);
                        rho = pt > 0 ? (cur.cost - nxt.cost) / pt : -1;
                        if (isfinite(nxt.cost) && nxt.cost < cur.cost && rho > 0.25) {
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
        if (ro->verbose)
            es__info(emb->ctx, "embed: refine %d cost %.6g -> %.6g lambda %.3g rho %.3g pcg %d "
                     "rms %.4g %% max %.4g %%", it, cur.cost, nxt.cost, lambda, rho, used,
                     100 * nxt.rms, 100 * nxt.max);
        if (!accepted) break;
        /* relative stopping rule over a window of 3 iterations (oracle README,
         * failure D: an absolute rule stops too early or too late) */
        hist[it % 4] = nxt.cost;
        c_prev = cur.cost;
        cur = nxt;
        if (it >= it_hold + 3 && !annealing && hist[(it - 3) % 4] - nxt.cost < 3.0 * ro->rtol * nxt.cost)
            break;
    }
    return ES_OK;
}
