/* tests/embed/test_embed_shape.c — the pieces of the local-global solve
 * (lib/embed/local_global.c, lbfgs.c, lengths_project.c) and the embedder
 * made from a kept vertex order:
 *  - L-BFGS's two loops with an identity H0 on a convex quadratic reach its
 *    minimizer (solved independently with LAPACK's dposv) in at most n + 1
 *    exact-line-search steps, as the theory says for quadratics;
 *  - local-global on a closed sphere's own lengths from a perturbed start
 *    comes back to the sphere up to a rigid motion (<= 1e-6 x diag: a
 *    closed convex surface is rigid for its lengths), with the energy
 *    falling every iteration (read from the verbose log); on an open wavy
 *    sheet (which its lengths leave free to flex) it meets the tolerances;
 *    started at the answer it takes no iteration;
 *  - the triangle projection: every face of the result satisfies the
 *    inequality with its margin; a target that already does is returned
 *    unchanged; one broken face alone is projected as the closed form of
 *    the projection onto one half-space (an independent computation) says;
 *    with many broken faces the result satisfies the KKT conditions of the
 *    least-squares problem: the change is a non-negative combination of
 *    the tight constraints' normals (multipliers by LAPACK's dgels);
 *  - es_embedder_new_ordered with an embedder's own order solves bit for
 *    bit as that embedder; an order that is not a permutation is refused.
 */
#define ES_MODULE_EMBED   /* the module's own test: its package header too */
#include "embed/embed_pkg.h"
#include "es_test.h"
#include "mesh_gen.h"

#include <edgespace/edgespace.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void wavy_fn(double u, double v, const void *ud, double p[3], double ref[3])
{
    (void)ud;
    p[0] = 2 * u;
    p[1] = 1.5 * v;
    p[2] = 0.25 * sin(5 * u) * cos(4 * v) + 0.2 * u * v;
    ref[0] = ref[1] = 0, ref[2] = 1;
}

/* L-BFGS on f(x) = x^T Q x / 2 - c^T x with exact line searches. */
static void check_lbfgs(es_ctx *ctx)
{
    enum { N = 12 };
    double Q[N * N], c[N], xs[N], x[N], g[N], gn[N], d[N], xn[N];
    es__lbfgs lb;
    srand(7);
    for (int i = 0; i < N; i++) {
        c[i] = rand() / (double)RAND_MAX - 0.5;
        for (int j = 0; j <= i; j++) {
            double a = rand() / (double)RAND_MAX - 0.5;
            Q[i * N + j] = Q[j * N + i] = a;
        }
    }
    for (int i = 0; i < N; i++) Q[i * N + i] += N;   /* diagonally dominant: SPD */
    {
        double A[N * N];
        memcpy(A, Q, sizeof A);
        memcpy(xs, c, sizeof xs);
        ES_CHECK(LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', N, 1, A, N, xs, N) == 0);
    }
    ES_CHECK_OK(ctx, es__lbfgs_init(ctx, &lb, N, N));
    memset(x, 0, sizeof x);
    for (int i = 0; i < N; i++) g[i] = -c[i];
    int it;
    for (it = 0; it <= N; it++) {
        double gq = 0, dQd = 0, t;
        if (sqrt(es__dot(g, g, N)) < 1e-12) break;
        memcpy(d, g, sizeof d);
        es__lbfgs_first(&lb, d);   /* H0 = I */
        es__lbfgs_second(&lb, d);
        for (int i = 0; i < N; i++) {
            double qd = 0;
            for (int j = 0; j < N; j++) qd += Q[i * N + j] * d[j];
            dQd += d[i] * qd;
            gq += g[i] * d[i];
        }
        t = gq / dQd;   /* exact line search along -d */
        for (int i = 0; i < N; i++) xn[i] = x[i] - t * d[i];
        for (int i = 0; i < N; i++) {
            double s = -c[i];
            for (int j = 0; j < N; j++) s += Q[i * N + j] * xn[j];
            gn[i] = s;
        }
        es__lbfgs_push(&lb, x, xn, g, gn);
        memcpy(x, xn, sizeof x);
        memcpy(g, gn, sizeof g);
    }
    double err = 0;
    for (int i = 0; i < N; i++) err = fmax(err, fabs(x[i] - xs[i]));
    fprintf(stderr, "lbfgs: %d steps, max |x - x*| %.3g\n", it, err);
    ES_CHECK_MSG(err < 1e-9 && it <= N + 1, "L-BFGS: %d steps, error %g", it, err);
    es__lbfgs_free(ctx, &lb);
}

static int64_t energies_n;
static double energies[400];

static void log_energy(void *ud, es_log_level lv, const char *msg)
{
    double e;
    int it;
    (void)ud, (void)lv;
    if (sscanf(msg, "embed: local-global %d energy %lf", &it, &e) == 2 && energies_n < 400)
        energies[energies_n++] = e;
}

static double rigid_rms(es_ctx *ctx, int64_t nv, const double *x, const double *ref)
{
    double *a = malloc(3 * (size_t)nv * sizeof *a), r = INFINITY;
    memcpy(a, x, 3 * (size_t)nv * sizeof *a);
    ES_CHECK_OK(ctx, es_embed_align(ctx, nv, a, ref, NULL, &r));
    free(a);
    return r;
}

/* Local-global from a perturbed start on mesh g's own lengths; returns the
 * RMS distance from g after a rigid fit, as a fraction of its diagonal. */
static double recover(es_ctx *ctx, es_embedder *emb, const es_mesh *mesh, const tm_mesh *g,
                      double tol, es__lg_result *res)
{
    int64_t nv = g->nv, ne = es_mesh_nedges(mesh);
    double *L = malloc((size_t)ne * sizeof *L), *x = malloc(3 * (size_t)nv * sizeof *x);
    double diag = es_bbox_diagonal(nv, g->xyz), d;
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, g->xyz, L));
    srand(3);   /* a smooth perturbation of 3 % of the diagonal and a little noise */
    for (int64_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++)
            x[3 * v + k] = g->xyz[3 * v + k] + 0.03 * diag * sin(2.0 * g->xyz[3 * v] + k) +
                           1e-3 * diag * (rand() / (double)RAND_MAX - 0.5);
    es__lg_opts o = {600, 6, tol, 10 * tol, 0, 1, 0};
    energies_n = 0;
    es_ctx_set_log(ctx, log_energy, NULL);
    ES_CHECK_OK(ctx, es__lg_solve(emb, L, x, &o, res));
    es_ctx_set_log(ctx, NULL, NULL);
    d = rigid_rms(ctx, nv, x, g->xyz) / diag;
    int mono = energies_n > 2;
    for (int64_t i = 1; i < energies_n; i++) mono &= energies[i] <= energies[i - 1];
    ES_CHECK_MSG(mono, "local-global: the energy rose (%lld values)", (long long)energies_n);
    /* from the answer: nothing to do */
    memcpy(x, g->xyz, 3 * (size_t)nv * sizeof *x);
    o.rms_tol = 1e-9, o.max_tol = 1e-8, o.verbose = 0;
    es__lg_result r0;
    ES_CHECK_OK(ctx, es__lg_solve(emb, L, x, &o, &r0));
    ES_CHECK(r0.met && r0.iters == 0 && memcmp(x, g->xyz, 3 * (size_t)nv * sizeof *x) == 0);
    free(L), free(x);
    return d;
}

static void check_local_global(es_ctx *ctx)
{
    tm_mesh shapes[2] = {tm_sphere(1.0, 14, 20), tm_grid(24, 18, 0, 0, wavy_fn, NULL)};
    for (int k = 0; k < 2; k++) {
        tm_mesh *g = &shapes[k];
        es_mesh *mesh = NULL;
        es_embedder *emb = NULL, *emb2 = NULL;
        es__lg_result res;
        ES_CHECK_OK(ctx, es_mesh_new(ctx, g->nv, g->nf, g->faces, g->xyz, &mesh));
        ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
        if (!emb) continue;
        /* the sphere to 1e-10, the sheet (slow in its flexes) to 2e-5 */
        double d = recover(ctx, emb, mesh, g, k ? 2e-5 : 1e-10, &res);
        fprintf(stderr, "local-global (%s): %lld iterations, rms %.3g max %.3g, %.3g x diag from "
                "the mesh\n", k ? "open sheet" : "sphere", (long long)res.iters, res.rms, res.max, d);
        ES_CHECK_MSG(res.met, "local-global: tolerances not met (rms %g, max %g)", res.rms, res.max);
        if (k == 0) ES_CHECK_MSG(d <= 1e-6, "local-global: %g x diag from the sphere", d);

        /* the same embedder made from its own order solves bit for bit alike */
        ES_CHECK_OK(ctx, es_embedder_new_ordered(ctx, mesh, es_embedder_ordering(emb), &emb2));
        if (emb2) {
            int64_t nv = g->nv, ne = es_mesh_nedges(mesh);
            double *L = malloc((size_t)ne * sizeof *L), *x = malloc(3 * (size_t)nv * sizeof *x),
                   *x2 = malloc(3 * (size_t)nv * sizeof *x2);
            es__lg_opts o = {20, 6, 0, 0, 0, 0, 0};
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, g->xyz, L));
            for (int64_t i = 0; i < 3 * nv; i++) x[i] = x2[i] = g->xyz[i] * (1 + 0.01 * sin((double)i));
            ES_CHECK_OK(ctx, es__lg_solve(emb, L, x, &o, &res));
            ES_CHECK_OK(ctx, es__lg_solve(emb2, L, x2, &o, &res));
            ES_CHECK(memcmp(x, x2, 3 * (size_t)nv * sizeof *x) == 0);

            /* a warm solve keeps the factor of the last one while the weights
             * are within factor_reuse of its own: the lengths of the mesh
             * stretched 1 % more along x (weights at most ~2 % off) reach the
             * tolerance as a solve with a fresh factor does, in about as many
             * iterations; stretched 40 % more (weights far beyond 10 %) they
             * are factored again, bit for bit as a fresh embedder solves them.
             * Oracle: the fresh-factor solve of the same realizable lengths. */
            es__lg_opts warm = {2000, 6, 1e-9, 1e-8, 0, 0, 0.1}, cold = warm;
            double *y = malloc(3 * (size_t)nv * sizeof *y);
            cold.factor_reuse = 0;
            for (int step = 0; step < 2; step++) {
                double f = step ? 1.41 : 1.01;
                es__lg_result rw, rc2;
                for (int64_t i = 0; i < 3 * nv; i++) y[i] = g->xyz[i] * (i % 3 == 0 ? f : 1.0);
                ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, y, L));
                for (int64_t i = 0; i < 3 * nv; i++) x2[i] = x[i];
                ES_CHECK_OK(ctx, es__lg_solve(emb, L, x, &warm, &rw));
                ES_CHECK_OK(ctx, es__lg_solve(emb2, L, x2, &cold, &rc2));
                fprintf(stderr, "local-global, stretched x %.2f: kept factor %lld iterations (rms "
                        "%.3g), fresh factor %lld (rms %.3g)\n", f, (long long)rw.iters, rw.rms,
                        (long long)rc2.iters, rc2.rms);
                ES_CHECK_MSG(rw.met == rc2.met && rw.iters <= 2 * rc2.iters + 10,
                             "kept factor: met %d in %lld iterations; fresh: met %d in %lld",
                             rw.met, (long long)rw.iters, rc2.met, (long long)rc2.iters);
                if (step == 1) ES_CHECK(memcmp(x, x2, 3 * (size_t)nv * sizeof *x) == 0);
            }
            free(y);
            free(L), free(x), free(x2);
        }
        int64_t *bad = malloc((size_t)g->nv * sizeof *bad);
        for (int64_t v = 0; v < g->nv; v++) bad[v] = v;
        bad[1] = 0;
        es_embedder *emb3 = NULL;
        ES_CHECK_FAILS(ctx, es_embedder_new_ordered(ctx, mesh, bad, &emb3), ES_EINVAL,
                       "not a permutation");
        ES_CHECK(emb3 == NULL);
        free(bad);
        es_embedder_free(emb2);
        es_embedder_free(emb);
        es_mesh_free(mesh);
        tm_free(g);
    }
}

/* 1 if every face of lengths l has its longest edge <= (1 - m) (other two). */
static int all_triangles(const es_mesh *mesh, const double *l, double m)
{
    const int64_t *FE = es_mesh_face_edges(mesh);
    for (int64_t f = 0; f < es_mesh_nfaces(mesh); f++) {
        double a = l[FE[3 * f]], b = l[FE[3 * f + 1]], c = l[FE[3 * f + 2]], mx = fmax(a, fmax(b, c));
        if (mx > (1 - m) * (a + b + c - mx) * (1 + 1e-12)) return 0;
    }
    return 1;
}

static void check_projection(es_ctx *ctx)
{
    tm_mesh g = tm_grid(10, 8, 0, 0, wavy_fn, NULL);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, g.nv, g.nf, g.faces, g.xyz, &mesh));
    ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (!emb) return;
    int64_t ne = es_mesh_nedges(mesh);
    const int64_t *FE = es_mesh_face_edges(mesh);
    const double m = 0.01;
    double *L = malloc((size_t)ne * sizeof *L), *P = malloc((size_t)ne * sizeof *P);
    double rms, mx;
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, g.xyz, L));
    /* a target that forms triangles comes back as it is */
    ES_CHECK(es__lengths_project(emb, L, m, P, &rms, &mx) == 0 && rms == 0 && mx == 0);
    ES_CHECK(memcmp(P, L, (size_t)ne * sizeof *L) == 0);
    /* one face broken: the half-space's projection in u = l'/l, a the
     * constraint's normal: u = 1 - (a.1 / |a|^2) a */
    int64_t f = -1, e0 = 0, e1 = 0, e2 = 0;
    const uint8_t *eb = es_mesh_edge_on_boundary(mesh);
    for (int64_t h = 0; h < es_mesh_nfaces(mesh) && f < 0; h++)
        for (int k = 0; k < 3 && f < 0; k++)
            if (eb[FE[3 * h + k]])   /* a boundary edge: in this face only */
                f = h, e0 = FE[3 * h + k], e1 = FE[3 * h + (k + 1) % 3], e2 = FE[3 * h + (k + 2) % 3];
    L[e0] = 1.3 * (L[e1] + L[e2]);
    double a[3] = {L[e0], -(1 - m) * L[e1], -(1 - m) * L[e2]};
    double viol = a[0] + a[1] + a[2], aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    int64_t n = es__lengths_project(emb, L, m, P, &rms, &mx);
    ES_CHECK(n == 3 && all_triangles(mesh, P, m));
    double want[3] = {L[e0] * (1 - viol / aa * a[0]), L[e1] * (1 - viol / aa * a[1]),
                      L[e2] * (1 - viol / aa * a[2])};
    ES_CHECK_CLOSE(P[e0], want[0], 1e-12, 0);
    ES_CHECK_CLOSE(P[e1], want[1], 1e-12, 0);
    ES_CHECK_CLOSE(P[e2], want[2], 1e-12, 0);
    /* many broken faces, some sharing edges: feasible, and no random
     * feasible point nearby is nearer */
    srand(11);
    for (int64_t e = 0; e < ne; e++)
        if (rand() % 6 == 0) L[e] *= 1.6 + 0.6 * rand() / (double)RAND_MAX;
    n = es__lengths_project(emb, L, m, P, &rms, &mx);
    fprintf(stderr, "projection: %lld lengths changed, rms %.3g max %.3g\n", (long long)n, rms, mx);
    ES_CHECK(n > 0 && all_triangles(mesh, P, m));
    /* KKT: u - 1 = -sum_i y_i a_i over the tight constraints, y >= 0 */
    {
        int64_t nf = es_mesh_nfaces(mesh), nact = 0;
        double *A = calloc((size_t)(ne * 3 * nf), sizeof *A), *r = malloc((size_t)ne * sizeof *r);
        for (int64_t h = 0; h < nf; h++)
            for (int i = 0; i < 3; i++) {
                int64_t ei = FE[3 * h + i], ej = FE[3 * h + (i + 1) % 3], ek = FE[3 * h + (i + 2) % 3];
                double lhs = P[ei], rhs = (1 - m) * (P[ej] + P[ek]);
                if (fabs(lhs - rhs) > 1e-10 * rhs) continue;   /* not tight */
                A[nact * ne + ei] += L[ei];
                A[nact * ne + ej] -= (1 - m) * L[ej];
                A[nact * ne + ek] -= (1 - m) * L[ek];
                nact++;
            }
        for (int64_t e = 0; e < ne; e++) r[e] = 1 - P[e] / L[e];
        double *b = malloc((size_t)ne * sizeof *b);
        memcpy(b, r, (size_t)ne * sizeof *b);
        ES_CHECK(LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', (lapack_int)ne, (lapack_int)nact, 1, A,
                               (lapack_int)ne, b, (lapack_int)ne) == 0);
        double ymin = INFINITY, res2 = 0, rn = 0;
        for (int64_t i = 0; i < nact; i++) ymin = fmin(ymin, b[i]);
        for (int64_t e = nact; e < ne; e++) res2 += b[e] * b[e];   /* dgels: residual rows */
        for (int64_t e = 0; e < ne; e++) rn += r[e] * r[e];
        fprintf(stderr, "projection: %lld tight constraints, min multiplier %.3g, KKT residual %.3g "
                "of %.3g\n", (long long)nact, ymin, sqrt(res2), sqrt(rn));
        ES_CHECK(nact > 0 && ymin >= -1e-9 && sqrt(res2) <= 1e-9 * sqrt(rn));
        free(A), free(r), free(b);
    }
    free(L), free(P);
    es_embedder_free(emb);
    es_mesh_free(mesh);
    tm_free(&g);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    check_lbfgs(ctx);
    check_local_global(ctx);
    check_projection(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
