/* tests/morph/test_multiscale.c — multi-scale geometry interpolation
 * (es_morph.h, Winkler et al. 2010) on the project's own meshes:
 *  - the paper's "clearly reproduces T_0 and T_1" (Sec. 3): a mesh's own
 *    lengths and dihedrals give it back up to a rigid motion (open and
 *    closed tubes, a mesh of two pieces, several patch counts), so the
 *    gluing follows es_dihedral_angles' sign and the blending is exact;
 *  - the hierarchy: levels, leaves no larger than leaf_faces unless a split
 *    could not make smaller patches, the same output for the same seed;
 *  - the midpoint of the tube bent 0 -> 180 degrees against the family's
 *    own 90 degree member (an independent shape: the bend is what the
 *    synthetic family does between its ends) and against vertex
 *    interpolation, whose middle shrinks;
 *  - the large rotation and extrapolation of Winkler et al. (Figs. 1, 6,
 *    Sec. 3.5): the elliptic tube bent 180 and twisted 270 degrees, t = 0.5
 *    and t = 2 against the family's own members there (bent 90 / 360,
 *    twisted 135 / 540 degrees): under half of vertex interpolation's
 *    distance (measured 6.1 % / 21 % of the diagonal against 13 % / 67 %;
 *    the project's edge-length embedding, printed beside them, lands 6.0 %
 *    / 24.5 % away: the members are not what interpolating lengths and
 *    dihedrals gives, so neither method is held to them more tightly);
 *  - the tries: the best of 4 hierarchies is the single-seed result of
 *    least energy (recomputed here from its definition), bit for bit;
 *  - bad arguments named.
 */
#include "es_test.h"

#include <edgespace/edgespace.h>

static double aligned_rms(es_ctx *ctx, const es_mesh *m, const double *a, const double *b)
{
    int64_t nv = es_mesh_nverts(m);
    double *c = malloc(3 * (size_t)nv * sizeof *c), rms = INFINITY;
    memcpy(c, a, 3 * (size_t)nv * sizeof *c);
    if (es_embed_align_parts(ctx, nv, c, b, NULL, es_mesh_vertex_component(m), &rms) != ES_OK)
        rms = INFINITY;
    free(c);
    return rms / es_bbox_diagonal(nv, b);
}

/* Solve from x's own lengths and dihedrals: x comes back. */
static void check_reproduces(es_ctx *ctx, const es_mesh *m, const double *x, int64_t patches,
                             const char *what)
{
    int64_t ne = es_mesh_nedges(m), nv = es_mesh_nverts(m);
    double *l = malloc((size_t)ne * sizeof *l), *a = malloc((size_t)ne * sizeof *a);
    double *out = malloc(3 * (size_t)nv * sizeof *out);
    es_multiscale_opts o;
    es_multiscale *ms = NULL;
    es_multiscale_opts_init(&o);
    o.patches = patches;
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, x, l));
    ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, x, a));
    ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, &o, &ms));
    if (ms) {
        es_multiscale_info info;
        ES_CHECK_OK(ctx, es_multiscale_solve(ctx, ms, l, a, out));
        double d = aligned_rms(ctx, m, out, x);
        es_multiscale_get_info(ms, &info);
        fprintf(stderr, "%s, m = %lld: %lld levels, %lld patches (%lld leaves, largest %lld "
                "faces); own lengths and dihedrals -> %.2g x diag\n", what, (long long)patches,
                (long long)info.levels, (long long)info.nodes, (long long)info.leaves,
                (long long)info.max_leaf, d);
        ES_CHECK_MSG(d < 1e-9, "%s: reproduction %g x diag", what, d);
        ES_CHECK(info.levels >= 2 && info.leaves >= 2 && info.nodes > info.leaves);
    }
    es_multiscale_free(ms);
    free(l), free(a), free(out);
}

static void test_reproduction(es_ctx *ctx)
{
    es_synth_opts so;
    es_synth_set set;
    es_mesh *m = NULL;
    es_synth_opts_init(&so);
    so.n = 3;
    for (int closed = 0; closed < 2; closed++) {
        ES_CHECK_OK(ctx, es_synth_generate(ctx, closed ? ES_SYNTH_TUBE_CLOSED : ES_SYNTH_TUBE,
                                           &so, &set));
        ES_CHECK_OK(ctx, es_mesh_new(ctx, set.nverts, set.nfaces, set.faces, NULL, &m));
        if (m) {
            /* the bent member (90 degrees): no face lies in a plane with its
             * neighbours, so every dihedral counts */
            const double *x = set.xyz + 3 * set.nverts;
            check_reproduces(ctx, m, x, 6, closed ? "closed tube" : "open tube");
            check_reproduces(ctx, m, x, 3, closed ? "closed tube" : "open tube");
        }
        es_mesh_free(m);
        m = NULL;
        es_synth_set_clear(ctx, &set);
    }
    /* two pieces: the tube and a copy moved away, each reproduced */
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE, &so, &set));
    {
        int64_t nv = set.nverts, nf = set.nfaces;
        int64_t *F = malloc(6 * (size_t)nf * sizeof *F);
        double *x = malloc(6 * (size_t)nv * sizeof *x);
        for (int64_t i = 0; i < 3 * nf; i++) F[i] = set.faces[i], F[3 * nf + i] = set.faces[i] + nv;
        for (int64_t i = 0; i < 3 * nv; i++) {
            x[i] = set.xyz[3 * nv + i];
            x[3 * nv + i] = set.xyz[6 * nv + i] + (i % 3 == 2 ? 30.0 : 0.0);
        }
        ES_CHECK_OK(ctx, es_mesh_new(ctx, 2 * nv, 2 * nf, F, NULL, &m));
        if (m) check_reproduces(ctx, m, x, 6, "two tubes");
        es_mesh_free(m);
        free(F), free(x);
    }
    es_synth_set_clear(ctx, &set);
}

static void test_midpoint(es_ctx *ctx)
{
    es_synth_opts so;
    es_synth_set set;
    es_mesh *m = NULL;
    es_multiscale *ms = NULL, *ms2 = NULL;
    es_synth_opts_init(&so);
    so.n = 3;   /* 0, 90, 180 degrees */
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE_CLOSED, &so, &set));
    ES_CHECK_OK(ctx, es_mesh_new(ctx, set.nverts, set.nfaces, set.faces, NULL, &m));
    ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, NULL, &ms));
    ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, NULL, &ms2));
    if (ms && ms2) {
        int64_t nv = set.nverts, ne = es_mesh_nedges(m);
        const double *in[2] = {set.xyz, set.xyz + 6 * nv}, *mid = set.xyz + 3 * nv;
        double w[2] = {0.5, 0.5}, *out = malloc(3 * (size_t)nv * sizeof *out);
        double *out2 = malloc(3 * (size_t)nv * sizeof *out2), *lin = malloc(3 * (size_t)nv * sizeof *lin);
        double *l = malloc((size_t)ne * sizeof *l), rms, mx, p99, rms_lin, mx_lin, d, d_lin;
        es_interp_info info;
        ES_CHECK_OK(ctx, es_multiscale_interp(ctx, ms, 2, in, w, NULL, out, &info));
        ES_CHECK_OK(ctx, es_multiscale_interp(ctx, ms2, 2, in, w, NULL, out2, NULL));
        ES_CHECK(memcmp(out, out2, 3 * (size_t)nv * sizeof *out) == 0);   /* same seed */
        ES_CHECK_OK(ctx, es_interp_targets(ctx, m, 2, in, w, l, NULL, NULL));
        ES_CHECK_OK(ctx, es_embed_length_error(ctx, m, out, l, 0, &rms, &mx, &p99));
        for (int64_t i = 0; i < 3 * nv; i++) lin[i] = 0.5 * (in[0][i] + in[1][i]);
        ES_CHECK_OK(ctx, es_embed_length_error(ctx, m, lin, l, 0, &rms_lin, &mx_lin, &p99));
        d = aligned_rms(ctx, m, out, mid);
        d_lin = aligned_rms(ctx, m, lin, mid);
        fprintf(stderr, "closed tube 0 -> 180 deg, t = 0.5: multiscale rms %.3g%%, max %.3g%%, "
                "%.3g%% of diag from the 90 degree member; vertex lerp rms %.3g%%, max %.3g%%, "
                "%.3g%% of diag\n", 100 * rms, 100 * mx, 100 * d, 100 * rms_lin, 100 * mx_lin,
                100 * d_lin);
        ES_CHECK_MSG(rms < 0.01 && mx < 0.1, "multiscale midpoint rms %g max %g", rms, mx);
        ES_CHECK_MSG(d < 0.01 && d < 0.2 * d_lin, "multiscale %g, lerp %g x diag from the 90 "
                     "degree tube", d, d_lin);
        ES_CHECK(mx < mx_lin);
        free(out), free(out2), free(lin), free(l);
    }
    es_multiscale_free(ms);
    es_multiscale_free(ms2);
    es_mesh_free(m);
    es_synth_set_clear(ctx, &set);
}

/* The tries (es_multiscale_opts.tries): a hierarchy per seed s, s + 1, ...;
 * the best of 4 is the single-seed result of least energy, bit for bit,
 * and its energy is the least of the four (each measured alone); single
 * seeds give different results; the energy is recomputed here from its
 * definition (mean squared relative length error + mean squared dihedral
 * error) on the chosen output. */
static void test_tries(es_ctx *ctx)
{
    es_synth_opts so;
    es_synth_set set;
    es_mesh *m = NULL;
    es_synth_opts_init(&so);
    so.n = 2;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE_TWIST, &so, &set));
    ES_CHECK_OK(ctx, es_mesh_new(ctx, set.nverts, set.nfaces, set.faces, NULL, &m));
    if (m) {
        int64_t nv = set.nverts, ne = es_mesh_nedges(m);
        const double *in[2] = {set.xyz, set.xyz + 3 * nv};
        const uint8_t *eb = es_mesh_edge_on_boundary(m);
        double w[2] = {0.5, 0.5}, en[4], best = INFINITY, *outs = malloc(12 * (size_t)nv * sizeof *outs);
        double *out = malloc(3 * (size_t)nv * sizeof *out), *l = malloc((size_t)ne * sizeof *l);
        double *a = malloc((size_t)ne * sizeof *a), *ao = malloc((size_t)ne * sizeof *ao);
        double *lo = malloc((size_t)ne * sizeof *lo);
        uint64_t seed = es_ctx_seed(ctx);
        int ibest = -1, differ = 0;
        es_multiscale_opts o;
        es_multiscale_info info;
        es_multiscale *ms = NULL;
        es_multiscale_opts_init(&o);
        ES_CHECK(o.tries == 4);
        ES_CHECK_OK(ctx, es_interp_targets(ctx, m, 2, in, w, l, a, NULL));
        o.tries = 1;
        for (int k = 0; k < 4; k++) {
            es_ctx_set_seed(ctx, seed + (uint64_t)k);
            ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, &o, &ms));
            if (!ms) continue;
            ES_CHECK_OK(ctx, es_multiscale_solve(ctx, ms, l, a, outs + 3 * nv * k));
            es_multiscale_get_info(ms, &info);
            en[k] = info.energy;
            if (en[k] < best) best = en[k], ibest = k;
            if (k && memcmp(outs, outs + 3 * nv * k, 3 * (size_t)nv * sizeof *outs)) differ++;
            es_multiscale_free(ms);
            ms = NULL;
        }
        es_ctx_set_seed(ctx, seed);
        o.tries = 4;
        ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, &o, &ms));
        if (ms && ibest >= 0) {
            double el = 0, ea = 0;
            int64_t nin = 0;
            ES_CHECK_OK(ctx, es_multiscale_solve(ctx, ms, l, a, out));
            es_multiscale_get_info(ms, &info);
            fprintf(stderr, "twisted tube midpoint, energy per seed: %.3g %.3g %.3g %.3g; best of "
                    "4: seed + %d, %.3g (worst %.3g)\n", en[0], en[1], en[2], en[3],
                    info.chosen, info.energy, info.energy_max);
            ES_CHECK(info.tries == 4 && info.chosen == ibest && info.energy == best);
            ES_CHECK(memcmp(out, outs + 3 * nv * ibest, 3 * (size_t)nv * sizeof *out) == 0);
            ES_CHECK(differ == 3);
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, out, lo));
            ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, out, ao));
            for (int64_t e = 0; e < ne; e++) {
                el += pow((lo[e] - l[e]) / l[e], 2) / (double)ne;
                if (!eb[e]) ea += pow(remainder(ao[e] - a[e], 2 * M_PI), 2), nin++;
            }
            ES_CHECK_CLOSE(info.energy, el + ea / (double)nin, 1e-9, 0);
        }
        o.tries = 0;
        es_multiscale_free(ms);
        ms = NULL;
        ES_CHECK_FAILS(ctx, es_multiscale_new(ctx, m, &o, &ms), ES_EINVAL, "tries");
        free(outs), free(out), free(l), free(a), free(ao), free(lo);
    }
    es_mesh_free(m);
    es_synth_set_clear(ctx, &set);
}

static void test_errors(es_ctx *ctx)
{
    es_synth_opts so;
    es_synth_set set;
    es_mesh *m = NULL;
    es_multiscale *ms = NULL;
    es_multiscale_opts o;
    es_synth_opts_init(&so);
    so.n = 2;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE, &so, &set));
    ES_CHECK_OK(ctx, es_mesh_new(ctx, set.nverts, set.nfaces, set.faces, NULL, &m));
    es_multiscale_opts_init(&o);
    o.patches = 1;
    ES_CHECK_FAILS(ctx, es_multiscale_new(ctx, m, &o, &ms), ES_EINVAL, "patches");
    ES_CHECK(ms == NULL);
    ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, NULL, &ms));
    if (ms) {
        int64_t ne = es_mesh_nedges(m);
        double *l = calloc((size_t)ne, sizeof *l), *a = calloc((size_t)ne, sizeof *a);
        double *out = malloc(3 * (size_t)set.nverts * sizeof *out);
        for (int64_t e = 0; e < ne; e++) l[e] = 1;
        l[17] = -1;
        ES_CHECK_FAILS(ctx, es_multiscale_solve(ctx, ms, l, a, out), ES_EINVAL, "edge 17");
        l[17] = 1;
        a[5] = NAN;
        if (es_mesh_edge_on_boundary(m)[5] == 0)
            ES_CHECK_FAILS(ctx, es_multiscale_solve(ctx, ms, l, a, out), ES_EINVAL, "edge 5");
        free(l), free(a), free(out);
    }
    es_multiscale_free(ms);
    es_mesh_free(m);
    es_synth_set_clear(ctx, &set);
}

/* Winkler et al.'s large rotation and extrapolation (Figs. 1, 6; Sec. 3.5)
 * on the elliptic tube bent 180 and twisted 270 degrees: members s = 0,
 * 0.5, 1, 1.5, 2 of the family (span 2); the pair s = 0 -> 1 at t = 0.5
 * and t = 2 against the family's own s = 0.5 and s = 2 members (bent 360,
 * twisted 540 degrees), beside vertex interpolation. */
static void test_twist(es_ctx *ctx)
{
    es_synth_opts so;
    es_synth_set set;
    es_mesh *m = NULL;
    es_multiscale *ms = NULL;
    es_synth_opts_init(&so);
    so.n = 5;
    so.span = 2;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE_TWIST, &so, &set));
    ES_CHECK_OK(ctx, es_mesh_new(ctx, set.nverts, set.nfaces, set.faces, NULL, &m));
    ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, NULL, &ms));
    if (ms) {
        int64_t nv = set.nverts;
        const double *in[2] = {set.xyz, set.xyz + 6 * nv};
        double *out = malloc(3 * (size_t)nv * sizeof *out), *lin = malloc(3 * (size_t)nv * sizeof *lin);
        const double ts[2] = {0.5, 2.0};
        const int64_t member[2] = {1, 4};
        es_embedder *emb = NULL;
        ES_CHECK_OK(ctx, es_embedder_new(ctx, m, &emb));
        for (int k = 0; emb && k < 2; k++) {
            double w[2] = {1 - ts[k], ts[k]}, d, d_lin, d_el;
            const double *want = set.xyz + 3 * nv * member[k];
            ES_CHECK_OK(ctx, es_multiscale_interp(ctx, ms, 2, in, w, NULL, out, NULL));
            d = aligned_rms(ctx, m, out, want);
            for (int64_t i = 0; i < 3 * nv; i++) lin[i] = w[0] * in[0][i] + w[1] * in[1][i];
            d_lin = aligned_rms(ctx, m, lin, want);
            ES_CHECK_OK(ctx, es_interp_embed(ctx, emb, 2, in, w, NULL, NULL, lin, NULL, NULL));
            d_el = aligned_rms(ctx, m, lin, want);
            fprintf(stderr, "twisted tube s = 0 -> 1, t = %g: multiscale %.3g%% of diag from "
                    "the s = %g member, edge-length embedding %.3g%%, vertex lerp %.3g%%\n",
                    ts[k], 100 * d, ts[k], 100 * d_el, 100 * d_lin);
            ES_CHECK_MSG(d < 0.5 * d_lin, "t = %g: multiscale %g, lerp %g x diag", ts[k], d,
                         d_lin);
        }
        es_embedder_free(emb);
        free(out), free(lin);
    }
    es_multiscale_free(ms);
    es_mesh_free(m);
    es_synth_set_clear(ctx, &set);
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_reproduction(ctx);
    test_midpoint(ctx);
    test_twist(ctx);
    test_tries(ctx);
    test_errors(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
