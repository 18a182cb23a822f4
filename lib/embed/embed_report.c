/* lib/embed/embed_report.c — how well an embedding realizes its target:
 * the edge-length error measures (es_embed_length_error, also for callers
 * that embed by other means) and the text of an embedding's quality
 * report, for commands and notebooks (es_embed.h).
 */
#include "core/core_private.h"
#include "edgespace/es_embed.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

es_status es_embed_length_error(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                                 const double *target, int normalize, double *rms_ratio,
                                 double *max_rel, double *p99_rel)
{
    int64_t ne = es_mesh_nedges(mesh);
    const int64_t *ed = es_mesh_edges(mesh);
    double *rel, *len, sl = 0, st = 0, f = 1, ss = 0, mx = 0;
    if (ne <= 0) ES_FAIL(ctx, ES_EINVAL, "embed: mesh has no edges");
    rel = es__alloc_array(ctx, ne, sizeof *rel);
    len = es__alloc_array(ctx, ne, sizeof *len);
    if (!rel || !len) {
        es__free(ctx, rel);
        es__free(ctx, len);
        return ES_ENOMEM;
    }
    for (int64_t e = 0; e < ne; e++) {
        const double *a = xyz + 3 * ed[2 * e], *b = xyz + 3 * ed[2 * e + 1];
        len[e] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                      (a[2] - b[2]) * (a[2] - b[2]));
        sl += len[e];
        st += target[e];
    }
    if (normalize && sl > 0) f = st / sl;
    for (int64_t e = 0; e < ne; e++) {
        double d = len[e] * f - target[e];
        ss += d * d;
        rel[e] = fabs(d) / target[e];
        if (rel[e] != rel[e]) rel[e] = INFINITY;   /* NaN: counted as the worst */
        if (!(rel[e] <= mx)) mx = rel[e];
    }
    if (rms_ratio) *rms_ratio = sqrt(ss / (double)ne) / (st / (double)ne);
    if (max_rel) *max_rel = mx;
    if (p99_rel) {
        *p99_rel = es__kth_smallest(rel, ne, (int64_t)floor(0.99 * (double)(ne - 1)));
    }
    es__free(ctx, rel);
    es__free(ctx, len);
    return ES_OK;
}


const char *es_embed_report_format(const es_embed_report *r, char *buf, size_t n)
{
    char verdict[160] = "", shape[256] = "";
    int k;
    if (!buf || !n) return buf;
    /* not realized: either the target cannot be realized (a face breaks the
     * triangle inequality) or the best compromise stays above the bar */
    if (!r->realized && r->n_bad_faces > 0)
        snprintf(verdict, sizeof verdict, "  [NOT REALIZABLE: %lld target faces violate the "
                 "triangle inequality]", (long long)r->n_bad_faces);
    else if (!r->realized)
        snprintf(verdict, sizeof verdict, "  [NOT REALIZED: best compromise]");
    if (r->has_prior)
        snprintf(shape, sizeof shape, "shape: bending %.3f x the prior's; %.3g %% of the bbox "
                 "diagonal from the prior's realization (max %.3g %%)\n", r->bend_ratio,
                 100 * r->prior_rms, 100 * r->prior_max);
    k = snprintf(buf, n,
                 "edge lengths: RMS ratio %.3g%%, max %.3g%% (edge %lld), p99 %.3g%%%s\n"
                 "%s"
                 "closure energy: %.4g (initial) -> %.4g (stage 1%s) -> %.4g (output)\n"
                 "iterations: stage 1 %lld, refinement %lld%s; target faces violating the "
                 "triangle inequality: %lld\n"
                 "time: dihedrals %.3f s, frames %.3f s, positions %.3f s, refinement %.3f s, "
                 "total %.3f s\n",
                 100 * r->rms_ratio, 100 * r->max_rel, (long long)r->worst_edge,
                 100 * r->p99_rel, verdict, shape, r->closure_before, r->closure_stage1,
                 r->used_stage1 ? "" : ", not used", r->closure_after,
                 (long long)r->dihedral_iters, (long long)r->refine_iters,
                 r->used_continuation ? " (continuation)" : "", (long long)r->n_bad_faces,
                 r->t_dihedral, r->t_frames, r->t_positions, r->t_refine, r->t_total);
    (void)k;
    return buf;
}
