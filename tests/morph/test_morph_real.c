/* tests/morph/test_morph_real.c — the other papers' methods on a real pair
 * of ../shared/data (skipped when absent): goast_cactus cactus0 -> cactus1
 * (5,261 vertices, closed) and its 19 poses as the data-driven examples.
 *  - multi-scale: the ends come back up to a rigid motion (1e-9 of the
 *    diagonal), the midpoint realizes its interpolated lengths to RMS
 *    ratio < 0.5 % (es_morph_report, the embedder's scale; bench_morph
 *    measured 0.11 %, the edge-length embedding 0.017 %) and lies nearer
 *    the two ends' aligned average than either end does;
 *  - data-driven: es_data_path through the 19 poses' normalized lengths
 *    (PCA scores with every component) ends exactly at the two poses, and
 *    each frame's row weights reproduce its coordinates' lengths (the
 *    frame's lengths, summed from the rows, stay positive and sum to 1).
 *  - shape-space: the midpoint with the default cap on stored candidates
 *    (the paper's rule would make 5.6e8 here): at most 32 slots a vertex,
 *    the ends exact, RMS ratio below 6 % (measured 3.4 %);
 *  - data-driven in Gao et al.'s own coordinates (es_lri): every pose
 *    encoded against cactus0 and decoded back to 1e-9 of the diagonal, and
 *    the coordinates' path ends at the two poses.
 */
#include "es_test.h"
#include "es_test_files.h"

#include <edgespace/edgespace.h>

enum { NPOSE = 19 };

static double aligned_rms(es_ctx *ctx, int64_t nv, const double *a, const double *b)
{
    double *c = malloc(3 * (size_t)nv * sizeof *c), rms = INFINITY;
    memcpy(c, a, 3 * (size_t)nv * sizeof *c);
    if (es_embed_align(ctx, nv, c, b, NULL, &rms) != ES_OK) rms = INFINITY;
    free(c);
    return rms / es_bbox_diagonal(nv, b);
}

int main(void)
{
    es_ctx *ctx;
    es_meshdata md[NPOSE];
    es_mesh *m = NULL;
    es_multiscale *ms = NULL;
    char p[4200];
    const char *data;
    ES_TEST_BEGIN();
    if (!(data = es_test_shared_data())) ES_TEST_SKIP("../shared/data absent");
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    memset(md, 0, sizeof md);
    for (int k = 0; k < NPOSE; k++) {
        snprintf(p, sizeof p, "%s/goast_cactus/cactus%d.obj", data, k);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, p, ES_FORMAT_OBJ, &md[k]));
    }
    ES_CHECK_OK(ctx, es_mesh_new(ctx, md[0].nverts, md[0].nfaces, md[0].faces, NULL, &m));
    ES_CHECK_OK(ctx, es_multiscale_new(ctx, m, NULL, &ms));
    if (ms) {
        int64_t nv = md[0].nverts, ne = es_mesh_nedges(m);
        const double *in[2] = {md[0].xyz, md[1].xyz};
        double *out = malloc(3 * (size_t)nv * sizeof *out), *l = malloc((size_t)ne * sizeof *l);
        double *avg = malloc(3 * (size_t)nv * sizeof *avg), rms, mx;
        for (int k = 0; k < 2; k++) {
            double w[2] = {k == 0, k == 1};
            ES_CHECK_OK(ctx, es_multiscale_interp(ctx, ms, 2, in, w, NULL, out, NULL));
            ES_CHECK_MSG(aligned_rms(ctx, nv, out, in[k]) < 1e-9, "end %d: %g", k,
                         aligned_rms(ctx, nv, out, in[k]));
        }
        double w[2] = {0.5, 0.5};
        ES_CHECK_OK(ctx, es_multiscale_interp(ctx, ms, 2, in, w, NULL, out, NULL));
        ES_CHECK_OK(ctx, es_interp_targets(ctx, m, 2, in, w, l, NULL, NULL));
        es_embed_report rep;
        memset(&rep, 0, sizeof rep);
        ES_CHECK_OK(ctx, es_morph_report(ctx, m, l, out, 0.01, &rep, NULL, NULL));
        rms = rep.rms_ratio, mx = rep.max_rel;
        memcpy(avg, in[1], 3 * (size_t)nv * sizeof *avg);
        double fit;
        ES_CHECK_OK(ctx, es_embed_align(ctx, nv, avg, in[0], NULL, &fit));
        for (int64_t i = 0; i < 3 * nv; i++) avg[i] = 0.5 * (avg[i] + in[0][i]);
        double d = aligned_rms(ctx, nv, out, avg), d0 = aligned_rms(ctx, nv, in[0], avg);
        double d1 = aligned_rms(ctx, nv, in[1], avg);
        fprintf(stderr, "cactus0 -> cactus1, t = 0.5: multiscale RMS %.3g%%, max %.3g%%; %.3g%% "
                "of diag from the aligned average (ends %.3g%%, %.3g%%)\n", 100 * rms, 100 * mx,
                100 * d, 100 * d0, 100 * d1);
        ES_CHECK_MSG(rms < 0.005, "multiscale midpoint RMS ratio %g", rms);
        ES_CHECK_MSG(d < d0 && d < d1, "midpoint %g from the average, ends %g %g", d, d0, d1);
        free(out), free(l), free(avg);
    }
    /* data-driven through the 19 poses */
    if (m) {
        int64_t ne = es_mesh_nedges(m), nc = 0;
        enum { NF = 7 };
        double *len = malloc((size_t)(ne * NPOSE) * sizeof *len), sc;
        double *c = malloc(sizeof(double) * NPOSE * NPOSE), f[NPOSE * NF], wts[NPOSE * NF];
        es_data_path_info info;
        for (int k = 0; k < NPOSE; k++) {
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, md[k].xyz, len + k * ne));
            ES_CHECK_OK(ctx, es_lengths_normalize(ctx, ne, len + k * ne, len + k * ne, &sc));
        }
        ES_CHECK_OK(ctx, es_data_path_coords(ctx, ne, NPOSE, len, ne, c, &nc));
        ES_CHECK_OK(ctx, es_data_path(ctx, nc, NPOSE, c, NPOSE, 0, 1, NULL, NF, f, wts, &info));
        fprintf(stderr, "cactus data-driven: %lld coordinates, %lld hops, %d iterations, "
                "nearest pose at most %.3g arcs away (straight line %.3g)\n", (long long)nc,
                (long long)info.hops, info.iterations, info.max_near, info.line_max_near);
        for (int64_t k = 0; k < nc; k++) {
            ES_CHECK(f[k] == c[k]);
            ES_CHECK(f[(NF - 1) * nc + k] == c[NPOSE + k]);
        }
        for (int s = 0; s < NF; s++) {
            double sum = 0, lo = INFINITY;
            for (int64_t e = 0; e < ne; e++) {
                double v = 0;
                for (int r = 0; r < NPOSE; r++) v += wts[s * NPOSE + r] * len[r * ne + e];
                sum += v, lo = v < lo ? v : lo;
            }
            ES_CHECK_MSG(fabs(sum - 1) < 1e-9 && lo > 0, "frame %d: lengths sum %.12g, min %g",
                         s, sum, lo);
        }
        free(len), free(c);
    }
    /* shape-space with the default cap */
    if (m) {
        int64_t nv = md[0].nverts;
        es_shape_space *ss = NULL;
        es_shape_space_info info;
        double *out = malloc(3 * (size_t)nv * sizeof *out), *l = malloc((size_t)es_mesh_nedges(m) * 8);
        const double *in[2] = {md[0].xyz, md[1].xyz};
        double w[2] = {0.5, 0.5};
        es_embed_report rep;
        ES_CHECK_OK(ctx, es_shape_space_new(ctx, m, in[0], in[1], NULL, &ss));
        if (ss) {
            ES_CHECK_OK(ctx, es_shape_space_frame(ctx, ss, NULL, 0, out));
            ES_CHECK(aligned_rms(ctx, nv, out, in[0]) < 1e-9);
            ES_CHECK_OK(ctx, es_shape_space_frame(ctx, ss, NULL, 0.5, out));
            es_shape_space_get_info(ss, &info);
            for (int64_t e = 0; e < es_mesh_nedges(m); e++) l[e] = 0;
            ES_CHECK_OK(ctx, es_interp_targets(ctx, m, 2, in, w, l, NULL, NULL));
            memset(&rep, 0, sizeof rep);
            ES_CHECK_OK(ctx, es_morph_report(ctx, m, l, out, 0.01, &rep, NULL, NULL));
            fprintf(stderr, "cactus0 -> cactus1, t = 0.5: shape space RMS %.3g%%, max %.3g%%; "
                    "the paper's rule %.3g candidates, %lld stored (%lld a vertex at most)\n",
                    100 * rep.rms_ratio, 100 * rep.max_rel, info.paper_candidates,
                    (long long)info.candidates, (long long)info.max_candidates);
            ES_CHECK(info.max_candidates <= 32 && info.paper_candidates > 1e6);
            ES_CHECK_MSG(rep.rms_ratio < 0.06, "shape space midpoint RMS %g", rep.rms_ratio);
        }
        es_shape_space_free(ss);
        free(out), free(l);
    }
    /* Gao et al.'s coordinates: every pose back from its own, the path's ends */
    if (m) {
        int64_t nv = md[0].nverts, dim, nc = 0;
        es_lri *L = NULL;
        ES_CHECK_OK(ctx, es_lri_new(ctx, m, md[0].xyz, NULL, &L));
        if (L) {
            double *feat, *y = malloc(3 * (size_t)nv * sizeof *y), worst = 0;
            double *c = malloc(sizeof(double) * NPOSE * NPOSE), f[NPOSE * 3];
            dim = es_lri_dim(L);
            feat = malloc((size_t)(dim * NPOSE) * sizeof *feat);
            for (int k = 0; k < NPOSE; k++) {
                ES_CHECK_OK(ctx, es_lri_encode(ctx, L, md[k].xyz, feat + dim * k));
                ES_CHECK_OK(ctx, es_lri_decode(ctx, L, feat + dim * k, y));
                worst = fmax(worst, aligned_rms(ctx, nv, y, md[k].xyz));
            }
            ES_CHECK_OK(ctx, es_data_path_coords(ctx, dim, NPOSE, feat, dim, c, &nc));
            ES_CHECK_OK(ctx, es_data_path(ctx, nc, NPOSE, c, NPOSE, 0, 1, NULL, 3, f, NULL, NULL));
            fprintf(stderr, "cactus in Gao et al.'s coordinates: %lld patches, %lld numbers a "
                    "pose; worst pose back from its coordinates %.2g x diag\n",
                    (long long)es_lri_npatches(L), (long long)dim, worst);
            ES_CHECK_MSG(worst < 1e-9, "LRI round trip %g", worst);
            for (int64_t k = 0; k < nc; k++)
                ES_CHECK(f[k] == c[k] && f[2 * nc + k] == c[NPOSE + k]);
            free(feat), free(y), free(c);
        }
        es_lri_free(L);
    }
    es_multiscale_free(ms);
    es_mesh_free(m);
    for (int k = 0; k < NPOSE; k++) es_meshdata_clear(ctx, &md[k]);
    es_ctx_free(ctx);
    ES_TEST_END();
}
