/* lib/morph/multiscale_register.c — simultaneous registration of a patch's
 * children (Winkler et al. 2010, Sec. 3.1, after Williams and Bennamoun
 * 2000, "Simultaneous registration of multiple point sets using
 * orthonormal matrices").
 *
 * Child k maps its points x by y = R_k x + t_k; every vertex the parent
 * holds in two children k, l gives the residual (R_k x + t_k) - (R_l x' +
 * t_l). With W = [R_1 .. R_m | t_1 .. t_m] (3 x 4m) and d = e_k (x; 1) -
 * e_l (x'; 1) the cost is tr(W Q W^T), Q = sum d d^T, a constant of the
 * children's positions. The translations are optimal in closed form (t_1 =
 * 0 fixes the global one), which leaves tr(R A R^T) with the Schur
 * complement A = Q_rr - Q_rt Q_tt^-1 Q_tr (3m x 3m). For one child with the
 * others fixed, tr(R_k A_kk R_k^T) = tr(A_kk) is constant, so the best R_k
 * minimizes <R_k, B_k> with B_k = sum_{j != k} R_j A_jk: the polar factor
 * of -B_k (a proper rotation: Sec. 3.1's reflections fixed by Arun et al.'s
 * last-column flip). Each pass updates every child in the order of placement
 * from the fixed first child.
 */
#include "morph/morph_pkg.h"

#include <lapacke.h>
#include <math.h>

int64_t es__ms_register_work(int64_t m)
{
    return 16 * m * m + 9 * m * m + 3 * m * m + m * m + 1;
}

/* B_k (3 x 3, row-major) = sum over j != k, used[j], of R_j A_jk. */
static void gather(int64_t m, const double *A, const double *r, const int64_t *used,
                   int64_t k, double *B)
{
    int64_t n = 3 * m;
    for (int i = 0; i < 9; i++) B[i] = 0;
    for (int64_t j = 0; j < m; j++) {
        if (j == k || !used[j]) continue;
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) {
                double s = 0;
                for (int q = 0; q < 3; q++) s += r[9 * j + 3 * a + q] * A[(3 * j + q) + n * (3 * k + c)];
                B[3 * a + c] += s;
            }
    }
}

/* Target of child k's copy of parent vertex p: the mean of the placed
 * copies in the other used children; its own copy in *xs. Returns the
 * number of copies averaged (0: none). */
static int64_t target(const es_multiscale *ms, const ms_node *n, int64_t p, int64_t k,
                      const int64_t *used, const double *r, const double *t, const double **xs,
                      double *tg)
{
    int64_t cnt = 0;
    *xs = NULL;
    tg[0] = tg[1] = tg[2] = 0;
    for (int64_t a = n->occ_off[p]; a < n->occ_off[p + 1]; a++) {
        int64_t j = n->occ[2 * a];
        const double *xj = ms->node[n->child[j]].x + 3 * n->occ[2 * a + 1];
        if (j == k) {
            *xs = xj;
        } else if (used[j]) {
            for (int c = 0; c < 3; c++)
                tg[c] += r[9 * j + 3 * c] * xj[0] + r[9 * j + 3 * c + 1] * xj[1] +
                         r[9 * j + 3 * c + 2] * xj[2] + t[3 * j + c];
            cnt++;
        }
    }
    if (!*xs) return 0;
    for (int c = 0; cnt && c < 3; c++) tg[c] /= (double)cnt;
    return cnt;
}

/* Child k's rotation and translation by Kabsch (1976) onto the placed
 * children (used), at the vertices it shares with them. */
static void place(const es_multiscale *ms, const ms_node *n, int64_t k, const int64_t *used,
                  double *r, double *t)
{
    double cs[3] = {0, 0, 0}, ct[3] = {0, 0, 0}, H[9] = {0}, tg[3], w = 0;
    const double *xs;
    for (int64_t p = 0; p < n->nv; p++)
        if (target(ms, n, p, k, used, r, t, &xs, tg)) {
            for (int c = 0; c < 3; c++) cs[c] += xs[c], ct[c] += tg[c];
            w += 1;
        }
    if (!(w > 0)) return;
    for (int c = 0; c < 3; c++) cs[c] /= w, ct[c] /= w;
    for (int64_t p = 0; p < n->nv; p++)
        if (target(ms, n, p, k, used, r, t, &xs, tg))
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) H[3 * i + j] += (tg[i] - ct[i]) * (xs[j] - cs[j]);
    /* R maximizing tr(R^T H) is H's polar factor; fewer than three
     * independent points leave it as good as the points allow */
    if (es__rotation_nearest(H) != 0) return;
    for (int i = 0; i < 9; i++) r[9 * k + i] = H[i];
    for (int c = 0; c < 3; c++)
        t[3 * k + c] = ct[c] - (H[3 * c] * cs[0] + H[3 * c + 1] * cs[1] + H[3 * c + 2] * cs[2]);
}

es_status es__ms_register(es_multiscale *ms, const ms_node *n, double *r, double *t,
                          double *work, int64_t *iwork)
{
    const int64_t m = n->nchild, n4 = 4 * m, n3 = 3 * m, nt = m - 1;
    double *Q = work, *A = Q + n4 * n4, *Z = A + n3 * n3, *T = Z + nt * n3;
    int64_t *order = iwork, *used = order + m, *adj = used + m;
    for (int64_t i = 0; i < n4 * n4; i++) Q[i] = 0;
    for (int64_t i = 0; i < m * m; i++) adj[i] = 0;
    /* Q = sum over corresponding pairs of d d^T */
    for (int64_t p = 0; p < n->nv; p++)
        for (int64_t a = n->occ_off[p]; a < n->occ_off[p + 1]; a++)
            for (int64_t b = a + 1; b < n->occ_off[p + 1]; b++) {
                int64_t k = n->occ[2 * a], l = n->occ[2 * b], idx[8];
                const double *xk = ms->node[n->child[k]].x + 3 * n->occ[2 * a + 1];
                const double *xl = ms->node[n->child[l]].x + 3 * n->occ[2 * b + 1];
                double d[8];
                for (int c = 0; c < 3; c++) {
                    idx[c] = 3 * k + c, d[c] = xk[c];
                    idx[4 + c] = 3 * l + c, d[4 + c] = -xl[c];
                }
                idx[3] = n3 + k, d[3] = 1;
                idx[7] = n3 + l, d[7] = -1;
                for (int u = 0; u < 8; u++)
                    for (int v = 0; v < 8; v++) Q[idx[u] + n4 * idx[v]] += d[u] * d[v];
                adj[k * m + l]++, adj[l * m + k]++;
            }
    /* A = Q_rr - Q_rt' Q_t't'^-1 Q_t'r, translations of children 1 .. m-1 */
    for (int64_t i = 0; i < n3; i++)
        for (int64_t j = 0; j < n3; j++) A[i + n3 * j] = Q[i + n4 * j];
    if (nt > 0) {
        double tr = 0;
        int info;
        for (int64_t i = 0; i < nt; i++)
            for (int64_t j = 0; j < n3; j++) Z[i + nt * j] = Q[(n3 + 1 + i) + n4 * j];
        for (int64_t i = 0; i < nt; i++) {
            for (int64_t j = 0; j < nt; j++) T[i + nt * j] = Q[(n3 + 1 + i) + n4 * (n3 + 1 + j)];
            tr += T[i + nt * i];
        }
        /* children that share no vertex with the rest leave Q_tt singular:
         * a ridge of 1e-12 of the mean diagonal keeps their translation at 0 */
        for (int64_t i = 0; i < nt; i++) T[i + nt * i] += 1e-12 * (tr / (double)nt + 1);
        info = LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', (int)nt, (int)n3, T, (int)nt, Z, (int)nt);
        if (info != 0)
            ES_FAIL(ms->ctx, ES_ENUMERIC, "multiscale: registration of %lld patches failed "
                    "(LAPACK info %d)", (long long)m, info);
        for (int64_t i = 0; i < n3; i++)
            for (int64_t j = 0; j < n3; j++) {
                double s = 0;
                for (int64_t q = 0; q < nt; q++) s += Q[i + n4 * (n3 + 1 + q)] * Z[q + nt * j];
                A[i + n3 * j] -= s;
            }
    }
    /* order of placement: from child 0, always the child sharing the most
     * vertices with those placed (a child held by one corner or one edge
     * would turn freely about it) */
    for (int64_t k = 0; k < m; k++) used[k] = 0;
    order[0] = 0;
    used[0] = 1;
    for (int64_t s = 1; s < m; s++) {
        int64_t best = -1, bw = -1;
        for (int64_t k = 0; k < m; k++) {
            int64_t w = 0;
            if (used[k]) continue;
            for (int64_t l = 0; l < m; l++)
                if (used[l]) w += adj[k * m + l];
            if (w > bw) bw = w, best = k;
        }
        order[s] = best;
        used[best] = 1;
    }
    /* first placement: each child by Kabsch onto the children placed
     * before it (their shared vertices), in that order */
    for (int64_t k = 0; k < m; k++) {
        for (int i = 0; i < 9; i++) r[9 * k + i] = i % 4 == 0;
        for (int c = 0; c < 3; c++) t[3 * k + c] = 0;
        used[k] = 0;
    }
    used[0] = 1;
    for (int64_t s = 1; s < m; s++) {
        int64_t k = order[s];
        place(ms, n, k, used, r, t);
        used[k] = 1;
    }
    /* then `passes` passes of Williams and Bennamoun's update over all */
    for (int pass = 0; pass < ms->opts.passes; pass++)
        for (int64_t s = 1; s < m; s++) {
            int64_t k = order[s];
            double B[9], sum = 0;
            gather(m, A, r, used, k, B);
            for (int i = 0; i < 9; i++) B[i] = -B[i], sum += fabs(B[i]);
            if (sum > 0 && es__rotation_nearest(B) == 0)
                for (int i = 0; i < 9; i++) r[9 * k + i] = B[i];
        }
    /* translations: T = -R Z^T, t_0 = 0 */
    for (int c = 0; c < 3; c++) t[c] = 0;
    for (int64_t k = 1; k < m; k++)
        for (int a = 0; a < 3; a++) {
            double s = 0;
            for (int64_t j = 0; j < m; j++)
                for (int q = 0; q < 3; q++) s += r[9 * j + 3 * a + q] * Z[(k - 1) + nt * (3 * j + q)];
            t[3 * k + a] = -s;
        }
    return ES_OK;
}
