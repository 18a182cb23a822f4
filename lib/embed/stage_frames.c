/* lib/embed/stage_frames.c — stages 2 and 3 of the embedding: vertex
 * frames from the dihedrals, then positions from the frames.
 *
 * Stage 2 (edge-length-interpolation Section 2; frames as in Lipman et al.
 * 2005) solves G_u = G_v R_vu over all edges by least squares: the rows of
 * G are three independent right-hand sides of one connection Laplacian
 * (H3, refactorized per solve), and each G_v is then projected onto the
 * nearest rotation. Stage 3 solves x_u - x_v = G_v u_v over both directed
 * copies of every edge, a graph Laplacian (H1) that depends on the
 * topology only and was factorized by es_embedder_new. The lowest vertex
 * of every component is pinned (G = I, x = 0), which makes both systems
 * definite.
 */
#include "embed/embed_pkg.h"

#include <string.h>

/* Frame with x along the spoke of slot i and z the normal of face f (one
 * of the two fan faces beside the spoke), in the vertex frame. */
static void slot_face_frame(const es_embedder *emb, int64_t v, int64_t i, int64_t f, double *A)
{
    int64_t o = emb->off[v], k = emb->off[v + 1] - o, j = i - o;
    if (emb->sf[i] == f) {
        memcpy(A, emb->C + 9 * i, 9 * sizeof(double));
    } else if (emb->vb[v] && j == k - 1) {
        memcpy(A, emb->C + 9 * i, 9 * sizeof(double));   /* C_{k-1}: z is face k-2's */
    } else {
        int64_t jp = (j + k - 1) % k;
        memcpy(A, emb->C + 9 * (o + jp), 9 * sizeof(double));
        es__mat3_right_z(A, emb->theta[o + jp]);
    }
}

/* Every vertex's walk (closure.c) with its corner angles and alpha: the
 * frames C_j of its spokes in its own frame, which the edges then relate. */
static void compute_fan_frames(es_embedder *emb, const double *alpha)
{
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t o = emb->off[v], k = emb->off[v + 1] - o;
        if (!k) continue;
        for (int64_t j = 0; j < k; j++) emb->fanal[j] = alpha[emb->se[o + j]];
        es__fan_frames(k, emb->vb[v] ? k - 1 : k, emb->theta + o, emb->fanal, emb->C + 9 * o,
                       NULL);
    }
}

es_status es__stage_frames(es_embedder *emb, const double *alpha)
{
    es_status need = es__embedder_need(emb, ES__NEED_H3);
    if (need != ES_OK) return need;
    double *x = es__sparse_mat_values(emb->H3), *b = emb->pcg;   /* 3 right-hand sides in vertex order */
    int64_t n3 = 3 * emb->nv;
    int st;
    compute_fan_frames(emb, alpha);
    memset(x, 0, (size_t)es__sparse_mat_nzmax(emb->H3) * sizeof(double));
    memset(b, 0, (size_t)(3 * n3) * sizeof(double));
    for (int64_t e = 0; e < emb->ne; e++) {
        int64_t a = emb->edges[2 * e], c = emb->edges[2 * e + 1];
        int64_t f = emb->ef[2 * e] >= 0 ? emb->ef[2 * e] : emb->ef[2 * e + 1];
        double Aa[9], Ab[9], R[9];
        slot_face_frame(emb, a, emb->edge_slot[2 * e], f, Aa);
        slot_face_frame(emb, c, emb->edge_slot[2 * e + 1], f, Ab);
        /* the same physical frame seen from c has x reversed: Ab D, D = diag(-1,-1,1) */
        for (int r = 0; r < 3; r++) {
            Ab[3 * r] = -Ab[3 * r];
            Ab[3 * r + 1] = -Ab[3 * r + 1];
        }
        es__mat3_mul_bt(Aa, Ab, R);   /* G_c = G_a R */
        if (!emb->pinned[a] && !emb->pinned[c]) {
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++)
                    x[es__h3_off(emb, e, r, q)] = -R[3 * r + q];
        } else if (emb->pinned[a] && !emb->pinned[c]) {
            /* rhs_c += R^T h_a, h_a = e_col */
            for (int col = 0; col < 3; col++)
                for (int r = 0; r < 3; r++) b[3 * c + r + n3 * col] += R[3 * col + r];
        } else if (!emb->pinned[a] && emb->pinned[c]) {
            for (int col = 0; col < 3; col++)
                for (int r = 0; r < 3; r++) b[3 * a + r + n3 * col] += R[3 * r + col];
        }
        for (int r = 0; r < 3; r++) {
            if (!emb->pinned[a]) x[es__h3_diag(emb, a, r, r)] += 1.0;
            if (!emb->pinned[c]) x[es__h3_diag(emb, c, r, r)] += 1.0;
        }
    }
    for (int64_t v = 0; v < emb->nv; v++)
        if (emb->pinned[v] || emb->off[v + 1] == emb->off[v])
            for (int r = 0; r < 3; r++) {
                x[es__h3_diag(emb, v, r, r)] = 1.0;
                b[3 * v + r + n3 * r] = 1.0;
            }
    es__h3_permute(emb, b, es__sparse_dense_values(emb->B3), 3);
    st = es__factor_solve(emb, emb->H3, emb->L3, emb->B3, 3);
    if (st < 0) return ES_ENUMERIC;
    if (st > 0) ES_FAIL(emb->ctx, ES_ENUMERIC, "embed: frame system is singular");
    {
        const double *s = es__sparse_solution_values(&emb->sol);
        for (int64_t v = 0; v < emb->nv; v++) {
            double *G = emb->G + 9 * v;
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++) G[3 * r + q] = s[3 * emb->pinv[v] + q + n3 * r];
            es__mat3_nearest_rotation(G);
        }
    }
    return ES_OK;
}

es_status es__stage_positions(es_embedder *emb, const double *len, double *xyz)
{
    es_status need = es__embedder_need(emb, ES__NEED_POSITIONS);
    if (need != ES_OK) return need;
    double *b = es__sparse_dense_values(emb->B1);
    int64_t nv = emb->nv;
    memset(b, 0, (size_t)(3 * nv) * sizeof(double));
    for (int64_t v = 0; v < nv; v++)
        for (int64_t i = emb->off[v]; i < emb->off[v + 1]; i++) {
            int64_t u = emb->sv[i];
            const double *C = emb->C + 9 * i, *G = emb->G + 9 * v;
            double l = len[emb->se[i]], p[3] = {l * C[0], l * C[3], l * C[6]};
            for (int r = 0; r < 3; r++) {
                double g = G[3 * r] * p[0] + G[3 * r + 1] * p[1] + G[3 * r + 2] * p[2];
                if (!emb->pinned[u]) b[u + nv * r] += g;
                if (!emb->pinned[v]) b[v + nv * r] -= g;
            }
        }
    es__sparse_clear_status(emb->sp);
    if (!es__sparse_solve(emb->sp, emb->L1, emb->B1, 3, &emb->sol)) {
        (void)es__solver_check(emb, "solve (positions)");   /* the message; the code stays */
        return ES_ENUMERIC;
    }
    {
        const double *s = es__sparse_solution_values(&emb->sol);
        for (int64_t v = 0; v < nv; v++)
            for (int r = 0; r < 3; r++) xyz[3 * v + r] = s[v + nv * r];
    }
    return ES_OK;
}
