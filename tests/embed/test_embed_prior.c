/* tests/embed/test_embed_prior.c — embedding near a prior from the data
 * (es_embed.h): the dihedral gradient against central differences and
 * es_dihedral_angles' sign, row weights of a point in the rows' span
 * (es_pca_row_weights, checked against the known combination), the prior of
 * a row (its own mesh comes back), a blend of two open height fields
 * (realized, in the prior's frame, near the blend, no more bending than the
 * blend, closer to it than the solve without a prior), the polish and the
 * mesh size from which local-global iterations replace it, a closed mesh (the
 * same result as es_interp_embed), and bad arguments.
 */
#define ES_MODULE_EMBED   /* the module's own test: its package header too */
#include "embed/embed_pkg.h"
#include "es_test.h"
#include "mesh_gen.h"

#include <edgespace/edgespace.h>

static double aligned_rms(es_ctx *ctx, int64_t nv, const double *a, const double *b)
{
    double *c = malloc(3 * (size_t)nv * sizeof *c), rms = INFINITY;
    memcpy(c, a, 3 * (size_t)nv * sizeof *c);
    if (es_embed_align(ctx, nv, c, b, NULL, &rms) != ES_OK) rms = INFINITY;
    free(c);
    return rms;
}

static double plain_rms(int64_t nv, const double *a, const double *b)
{
    double s = 0;
    for (int64_t i = 0; i < 3 * nv; i++) s += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(s / (double)nv);
}

static void test_gradient(es_ctx *ctx)
{
    double worst = 0;
    srand(3);
    for (int trial = 0; trial < 200; trial++) {
        double p[12], g[12], al, h = 1e-6;
        for (int i = 0; i < 12; i++) p[i] = (double)rand() / RAND_MAX * 2 - 1;
        if (es__dihedral_grad(p, p + 3, p + 6, p + 9, &al, g)) continue;
        for (int i = 0; i < 12; i++) {
            double q[12], a1, a2, gg[12], fd;
            memcpy(q, p, sizeof q);
            q[i] += h;
            es__dihedral_grad(q, q + 3, q + 6, q + 9, &a1, gg);
            q[i] -= 2 * h;
            es__dihedral_grad(q, q + 3, q + 6, q + 9, &a2, gg);
            fd = remainder(a1 - a2, 2 * M_PI) / (2 * h);
            if (fabs(fd - g[i]) / (1 + fabs(g[i])) > worst) worst = fabs(fd - g[i]) / (1 + fabs(g[i]));
        }
    }
    ES_CHECK_MSG(worst < 1e-6, "dihedral gradient vs central differences: %g", worst);
    {   /* the angle is es_dihedral_angles' (f holds 0->1, g holds 1->0) */
        es_mesh *m = NULL;
        int64_t F[6] = {0, 1, 2, 1, 0, 3};
        double x[12] = {0, 0, 0, 1, 0, 0, 0.5, 1, 0.2, 0.4, -1, 0.3}, al[5], a, g[12];
        ES_CHECK_OK(ctx, es_mesh_new(ctx, 4, 2, F, x, &m));
        if (m) {
            ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, x, al));
            es__dihedral_grad(x, x + 3, x + 6, x + 9, &a, g);
            for (int64_t e = 0; e < es_mesh_nedges(m); e++)
                if (es_mesh_edges(m)[2 * e] == 0 && es_mesh_edges(m)[2 * e + 1] == 1)
                    ES_CHECK_CLOSE(a, al[e], 1e-12, 1e-14);
        }
        es_mesh_free(m);
    }
}

/* Rows of a known combination: the weights come back exactly (no ridge). */
static void test_row_weights(es_ctx *ctx)
{
    enum { E = 50, N = 4 };
    double rows[E * N], x[E], w[N];
    es_pca *p = NULL;
    es_pca_opts o;
    srand(5);
    for (int i = 0; i < E * N; i++) rows[i] = 1 + 0.1 * (double)rand() / RAND_MAX;
    for (int e = 0; e < E; e++) x[e] = 0.2 * rows[e] + 0.5 * rows[e + E] + 0.3 * rows[e + 2 * E];
    es_source src = es_source_matrix((es_mat){rows, E, N, E}, NULL, 0);
    es_pca_opts_init(&o);
    ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, &o, &p));
    if (!p) return;
    ES_CHECK_OK(ctx, es_pca_row_weights(ctx, p, x, 0, w));
    ES_CHECK_CLOSE(w[0], 0.2, 1e-9, 1e-10);
    ES_CHECK_CLOSE(w[1], 0.5, 1e-9, 1e-10);
    ES_CHECK_CLOSE(w[2], 0.3, 1e-9, 1e-10);
    ES_CHECK_CLOSE(w[3], 0.0, 1e-9, 1e-10);
    /* a ridge shrinks toward the mean (1/N each) and keeps the sum at 1 */
    ES_CHECK_OK(ctx, es_pca_row_weights(ctx, p, x, 10, w));
    ES_CHECK_CLOSE(w[0] + w[1] + w[2] + w[3], 1.0, 1e-12, 1e-12);
    ES_CHECK(fabs(w[1] - 0.25) < 0.25);
    ES_CHECK_OK(ctx, es_pca_row_weights(ctx, p, NULL, 0, w));
    for (int i = 0; i < N; i++) ES_CHECK_CLOSE(w[i], 0.25, 0, 1e-15);
    ES_CHECK_FAILS(ctx, es_pca_row_weights(ctx, p, x, -1, w), ES_EINVAL, "ridge");
    es_pca_free(p);
}

/* second shape of a height field: a bulge and a shear */
static void deform(int64_t nv, const double *a, double *b, double amount)
{
    for (int64_t v = 0; v < nv; v++) {
        const double *p = a + 3 * v;
        double *q = b + 3 * v;
        q[0] = p[0] + 0.05 * amount * p[1];
        q[1] = p[1];
        q[2] = p[2] + amount * 0.15 * exp(-4 * (p[0] * p[0] + (p[1] + 0.3) * (p[1] + 0.3)));
    }
}

/* an open height field over [-1, 1]^2 with two bumps */
static void hf_fn(double u, double v, const void *ud, double p[3], double ref[3])
{
    double x = 2 * u - 1, y = 2 * v - 1;
    (void)ud;
    p[0] = x;
    p[1] = y;
    p[2] = 0.3 * exp(-3 * (x * x + y * y)) + 0.1 * exp(-8 * ((x - 0.4) * (x - 0.4) + y * y));
    ref[0] = ref[1] = 0;
    ref[2] = 1;
}

static void test_open(es_ctx *ctx)
{
    tm_mesh f = tm_grid(24, 24, 0, 0, hf_fn, NULL);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    int64_t nv = f.nv, ne;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, f.nv, f.nf, f.faces, f.xyz, &mesh));
    if (mesh) ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        double *b = malloc(3 * (size_t)nv * sizeof *b), *prior = malloc(3 * (size_t)nv * sizeof *prior);
        double *out = malloc(3 * (size_t)nv * sizeof *out), diag = es_bbox_diagonal(nv, f.xyz);
        double *len, *al[2], *pal, *psd, w[2] = {0.5, 0.5}, w1[2] = {1, 0};
        const double *xs[2];
        es_embed_report r;
        ne = es_mesh_nedges(mesh);
        len = malloc((size_t)ne * sizeof *len);
        pal = malloc((size_t)ne * sizeof *pal);
        psd = malloc((size_t)ne * sizeof *psd);
        al[0] = malloc((size_t)ne * sizeof *al[0]);
        al[1] = malloc((size_t)ne * sizeof *al[1]);
        deform(nv, f.xyz, b, 1.0);
        xs[0] = f.xyz;
        xs[1] = b;
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, f.xyz, al[0]));
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, b, al[1]));
        /* a row: its own mesh comes back, in its own frame */
        es_embed_prior pr = {prior, pal, psd, NULL, NULL, NULL};
        ES_CHECK_OK(ctx, es_embed_prior_from_rows(ctx, nv, ne, 2, xs, (const double *const *)al,
                                                  w1, prior, pal, psd));
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, f.xyz, len));
        ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, NULL, out, &r));
        ES_CHECK_MSG(plain_rms(nv, out, f.xyz) <= 1e-9 * diag, "row: %g x diag",
                     plain_rms(nv, out, f.xyz) / diag);
        /* the midpoint: realized, near the vertex blend, in the blend's frame */
        ES_CHECK_OK(ctx, es_embed_prior_from_rows(ctx, nv, ne, 2, xs, (const double *const *)al,
                                                  w, prior, pal, psd));
        ES_CHECK_OK(ctx, es_interp_targets(ctx, mesh, 2, xs, w, len, NULL, NULL));
        ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, NULL, out, &r));
        fprintf(stderr, "open midpoint: rms ratio %.3g, max %.3g, %.3g x diag from the blend "
                "(%.3g after alignment)\n", r.rms_ratio, r.max_rel, plain_rms(nv, out, prior) / diag,
                aligned_rms(ctx, nv, out, prior) / diag);
        ES_CHECK(r.rms_ratio <= 5e-4 && r.max_rel <= 5e-3);
        fprintf(stderr, "open midpoint: bend ratio %.4f, %.3g x diag from the scaled blend "
                "(max %.3g)\n", r.bend_ratio, r.prior_rms, r.prior_max);
        ES_CHECK(r.has_prior && r.bend_ratio > 0.9 && r.bend_ratio < 1.1);
        ES_CHECK(r.prior_rms <= r.prior_max && r.prior_rms <= 1e-2);
        {   /* a warm start (pr.start: a walk's previous frame) from this result:
             * with the accuracy stop at what it already meets, no iteration and
             * the same mesh (up to the start's rescaling to the target's length
             * sum, which its residual length errors move by 1e-4, and the
             * alignment to the prior: 1.05e-6 x diag measured); NULL starts
             * from the prior, and the solve is the same as before */
            double *prev = malloc(3 * (size_t)nv * sizeof *prev), *out2 = malloc(3 * (size_t)nv * sizeof *out2);
            es_embed_opts o;
            es_embed_report r2;
            memcpy(prev, out, 3 * (size_t)nv * sizeof *prev);
            es_embed_opts_init(&o);
            o.lg_rms_tol = 1.01 * r.rms_ratio;
            o.lg_max_tol = 1.01 * r.max_rel;
            pr.start = prev;
            ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, &o, out2, &r2));
            ES_CHECK_MSG(r2.refine_iters == 0 && r2.lg_iters == 0 &&
                             plain_rms(nv, out2, prev) <= 1e-5 * diag,
                         "warm start: %lld + %lld iterations, %g x diag from the start",
                         (long long)r2.lg_iters, (long long)r2.refine_iters,
                         plain_rms(nv, out2, prev) / diag);
            ES_CHECK_FAILS(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, &o, prev, &r2),
                           ES_EINVAL, "start positions are the output");
            prev[5] = NAN;
            ES_CHECK_FAILS(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, &o, out2, &r2),
                           ES_EINVAL, "start position of vertex 1");
            pr.start = NULL;
            ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, NULL, out2, &r2));
            ES_CHECK(plain_rms(nv, out2, out) == 0 && r2.refine_iters == r.refine_iters &&
                     r2.lg_iters == r.lg_iters);
            free(prev), free(out2);
        }
        {   /* the per-vertex deviations are the report's */
            const double *dev = es_embedder_vertex_deviation(emb);
            double ss = 0, mx = 0;
            ES_CHECK(dev != NULL);
            for (int64_t v = 0; dev && v < nv; v++) ss += dev[v] * dev[v], mx = fmax(mx, dev[v]);
            ES_CHECK_CLOSE(sqrt(ss / (double)nv), r.prior_rms, 1e-12, 0);
            ES_CHECK_CLOSE(mx, r.prior_max, 1e-12, 0);
        }
        {   /* without the prior (from the first row's dihedrals) the flexes are
             * free: farther from the blend than with it */
            double *plain = malloc(3 * (size_t)nv * sizeof *plain);
            es_embed_report r0;
            ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, NULL, f.xyz, NULL, plain, &r0));
            double d0 = aligned_rms(ctx, nv, plain, prior), d1 = aligned_rms(ctx, nv, out, prior);
            fprintf(stderr, "open midpoint: %.3g x diag from the blend with the prior, %.3g "
                    "without\n", d1 / diag, d0 / diag);
            ES_CHECK_MSG(d1 < d0, "the prior did not bring the output nearer the blend: %g vs %g",
                         d1, d0);
            ES_CHECK(!r0.has_prior && es_embedder_vertex_deviation(emb) == NULL);
            free(plain);
        }
        {   /* the polish and the size from which more local-global iterations
             * take its place (polish_max_verts): tolerances that 5 local-global
             * iterations do not meet */
            double *out2 = malloc(3 * (size_t)nv * sizeof *out2);
            es_embed_opts o;
            es_embed_report rp, rl, r0;
            es_embed_opts_init(&o);
            o.lg_max_iter = 5;
            o.lg_max_iter_large = 12;
            o.lg_rms_tol = 1e-9;
            o.lg_max_tol = 1e-8;
            ES_CHECK(o.polish_max_verts > nv);   /* the default: this mesh is polished */
            ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, &o, out2, &rp));
            o.polish_max_verts = nv;             /* as large as the limit */
            ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, &o, out2, &rl));
            o.polish_max_verts = 0;              /* no limit */
            ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, &o, out2, &r0));
            ES_CHECK_MSG(rp.lg_iters == 5 && rp.refine_iters > 0 && rl.refine_iters == 0 &&
                             rl.lg_iters > 5 && rl.lg_iters <= 12 && r0.lg_iters == 5 &&
                             r0.refine_iters == rp.refine_iters,
                         "polished %lld + %lld, at the limit %lld + %lld, no limit %lld + %lld",
                         (long long)rp.lg_iters, (long long)rp.refine_iters,
                         (long long)rl.lg_iters, (long long)rl.refine_iters,
                         (long long)r0.lg_iters, (long long)r0.refine_iters);
            free(out2);
        }
        ES_CHECK(plain_rms(nv, out, prior) <= 1e-2 * diag);
        ES_CHECK(plain_rms(nv, out, prior) <= aligned_rms(ctx, nv, out, prior) * (1 + 1e-6));
        for (int64_t i = 0; i < 3 * nv; i++) ES_CHECK(isfinite(out[i]));
        free(b), free(prior), free(out), free(len), free(al[0]), free(al[1]), free(pal), free(psd);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    tm_free(&f);
}

static void test_closed(es_ctx *ctx)
{
    tm_mesh s = tm_sphere(1.0, 14, 24);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    int64_t nv = s.nv, ne;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, s.nv, s.nf, s.faces, s.xyz, &mesh));
    if (mesh) ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        double *b = malloc(3 * (size_t)nv * sizeof *b), *prior = malloc(3 * (size_t)nv * sizeof *prior);
        double *out = malloc(3 * (size_t)nv * sizeof *out), *ref = malloc(3 * (size_t)nv * sizeof *ref);
        double *len, *al[2], *pal, w[2] = {0.6, 0.4}, diag = es_bbox_diagonal(nv, s.xyz);
        const double *xs[2];
        ne = es_mesh_nedges(mesh);
        len = malloc((size_t)ne * sizeof *len);
        pal = malloc((size_t)ne * sizeof *pal);
        al[0] = malloc((size_t)ne * sizeof *al[0]);
        al[1] = malloc((size_t)ne * sizeof *al[1]);
        for (int64_t v = 0; v < nv; v++) {   /* an ellipsoid with a dent */
            const double *p = s.xyz + 3 * v;
            b[3 * v] = 1.3 * p[0];
            b[3 * v + 1] = 0.8 * p[1];
            b[3 * v + 2] = p[2] * (1 - 0.2 * exp(-5 * (p[0] * p[0] + p[1] * p[1])));
        }
        xs[0] = s.xyz;
        xs[1] = b;
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, s.xyz, al[0]));
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, b, al[1]));
        es_embed_prior pr = {prior, pal, NULL, NULL, NULL, NULL};
        ES_CHECK_OK(ctx, es_embed_prior_from_rows(ctx, nv, ne, 2, xs, (const double *const *)al,
                                                  w, prior, pal, NULL));
        ES_CHECK_OK(ctx, es_interp_targets(ctx, mesh, 2, xs, w, len, NULL, NULL));
        ES_CHECK_OK(ctx, es_interp_embed(ctx, emb, 2, xs, w, NULL, NULL, ref, NULL, NULL));
        ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, emb, len, 0, &pr, NULL, out, NULL));
        ES_CHECK_MSG(aligned_rms(ctx, nv, out, ref) <= 1e-9 * diag,
                     "closed: %g x diag from es_interp_embed", aligned_rms(ctx, nv, out, ref) / diag);
        free(b), free(prior), free(out), free(ref), free(len), free(al[0]), free(al[1]), free(pal);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    tm_free(&s);
}

static void test_bad_arguments(es_ctx *ctx)
{
    tm_mesh s = tm_sphere(1.0, 6, 8);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, s.nv, s.nf, s.faces, s.xyz, &mesh));
    if (mesh) ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        int64_t ne = es_mesh_nedges(mesh), nv = s.nv;
        double *len = malloc((size_t)ne * sizeof *len), *out = malloc(3 * (size_t)nv * sizeof *out);
        double *bad = malloc(3 * (size_t)nv * sizeof *bad), w[1] = {NAN};
        const double *xs[1] = {s.xyz};
        es_embed_prior none = {NULL, NULL, NULL, NULL, NULL, NULL}, self = {out, NULL, NULL, NULL, NULL, NULL},
                       nan = {bad, NULL, NULL, NULL, NULL, NULL};
        es_edge_lengths(ctx, mesh, s.xyz, len);
        memcpy(bad, s.xyz, 3 * (size_t)nv * sizeof *bad);
        bad[7] = NAN;
        ES_CHECK_FAILS(ctx, es_embed_prior_solve(ctx, emb, len, 0, NULL, NULL, out, NULL),
                       ES_EINVAL, "prior's positions are required");
        ES_CHECK_FAILS(ctx, es_embed_prior_solve(ctx, emb, len, 0, &none, NULL, out, NULL),
                       ES_EINVAL, "prior's positions are required");
        ES_CHECK_FAILS(ctx, es_embed_prior_solve(ctx, emb, len, 0, &self, NULL, out, NULL),
                       ES_EINVAL, "output array");
        ES_CHECK_FAILS(ctx, es_embed_prior_solve(ctx, emb, len, 0, &nan, NULL, out, NULL),
                       ES_EINVAL, "vertex 2 is not finite");
        ES_CHECK_FAILS(ctx, es_embed_prior_from_rows(ctx, nv, ne, 1, xs, NULL, w, out, NULL, NULL),
                       ES_EINVAL, "not finite");
        free(len), free(out), free(bad);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    tm_free(&s);
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_gradient(ctx);
    test_row_weights(ctx);
    test_open(ctx);
    test_closed(ctx);
    test_bad_arguments(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
