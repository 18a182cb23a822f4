/* lib/embed/embed_report.c — the text of an embedding's quality report,
 * for commands and notebooks (es_embed.h). */
#include "core/core_private.h"
#include "edgespace/es_embed.h"

#include <stdio.h>

const char *es_embed_report_format(const es_embed_report *r, char *buf, size_t n)
{
    if (!buf || !n) return buf;
    snprintf(buf, n,
             "edge lengths: RMS ratio %.3g%%, max %.3g%% (edge %lld), p99 %.3g%%%s\n"
             "closure energy: %.4g (initial) -> %.4g (stage 1%s) -> %.4g (output)\n"
             "iterations: stage 1 %lld, refinement %lld%s; target faces violating the "
             "triangle inequality: %lld\n"
             "time: dihedrals %.3f s, frames %.3f s, positions %.3f s, refinement %.3f s, "
             "total %.3f s\n",
             100 * r->rms_ratio, 100 * r->max_rel, (long long)r->worst_edge, 100 * r->p99_rel,
             r->realized ? "" : "  [NOT REALIZED: best effort]", r->closure_before,
             r->closure_stage1, r->used_stage1 ? "" : ", not used", r->closure_after,
             (long long)r->dihedral_iters, (long long)r->refine_iters,
             r->used_continuation ? " (continuation)" : "", (long long)r->n_bad_faces,
             r->t_dihedral, r->t_frames, r->t_positions, r->t_refine, r->t_total);
    return buf;
}
