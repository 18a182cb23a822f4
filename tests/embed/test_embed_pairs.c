/* tests/embed/test_embed_pairs.c — interpolation midpoints of real pairs from
 * ../shared/data (skipped when absent): the edge-length RMS ratio must be
 * <= 0.5% and the max relative error <= 10% (issue 4; the published method,
 * measured in the oracle README, misses both on all four pairs). Suite slow.
 */
#include "es_test.h"

#include <edgespace/edgespace.h>

static void pair(es_ctx *ctx, const char *data, const char *dir, const char *a, const char *b)
{
    char pa[8400], pb[8400];
    es_meshdata ma, mb;
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    snprintf(pa, sizeof pa, "%s/%s/%s.obj", data, dir, a);
    snprintf(pb, sizeof pb, "%s/%s/%s.obj", data, dir, b);
    ES_CHECK_OK(ctx, es_meshdata_read(ctx, pa, ES_FORMAT_OBJ, &ma));
    ES_CHECK_OK(ctx, es_meshdata_read(ctx, pb, ES_FORMAT_OBJ, &mb));
    ES_CHECK(ma.nverts == mb.nverts && ma.nfaces == mb.nfaces);
    ES_CHECK_OK(ctx, es_mesh_new(ctx, ma.nverts, ma.nfaces, ma.faces, ma.xyz, &mesh));
    if (mesh) ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        const double *in[2] = {ma.xyz, mb.xyz};
        double w[2] = {0.5, 0.5}, *out = malloc(3 * (size_t)ma.nverts * sizeof *out);
        es_embed_report r;
        es_interp_info info;
        ES_CHECK_OK(ctx, es_interp_embed(ctx, emb, 2, in, w, NULL, NULL, out, &r, &info));
        fprintf(stderr, "%s %s<->%s t=0.5: V %lld, rms %.3f%%, max %.2f%%, p99 %.3f%%, "
                "closure %.3g -> %.3g, stage 1 %s (%lld it), refine %lld it, %.2f s, "
                "%lld dihedrals wrapped\n", dir, a, b, (long long)ma.nverts, 100 * r.rms_ratio,
                100 * r.max_rel, 100 * r.p99_rel, r.closure_before, r.closure_after,
                r.used_stage1 ? "used" : "not used", (long long)r.dihedral_iters,
                (long long)r.refine_iters, r.t_total, (long long)info.n_wrapped);
        ES_CHECK_MSG(r.rms_ratio <= 0.005, "%s: rms ratio %g", dir, r.rms_ratio);
        ES_CHECK_MSG(r.max_rel <= 0.10, "%s: max relative error %g", dir, r.max_rel);
        for (int64_t i = 0; i < 3 * ma.nverts; i++) ES_CHECK(isfinite(out[i]));
        free(out);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    es_meshdata_clear(ctx, &ma);
    es_meshdata_clear(ctx, &mb);
}

int main(void)
{
    es_ctx *ctx;
    const char *data = es_test_shared_data();
    ES_TEST_BEGIN();
    if (!data) ES_TEST_SKIP("../shared/data absent");
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    pair(ctx, data, "sumner_cat_poses", "cat-01", "cat-02");
    pair(ctx, data, "goast_cactus", "cactus0", "cactus1");
    pair(ctx, data, "facecap_arkit", "anim_000", "anim_100");
    pair(ctx, data, "goast_spacetime_faces", "neutral", "smile");
    es_ctx_free(ctx);
    ES_TEST_END();
}
