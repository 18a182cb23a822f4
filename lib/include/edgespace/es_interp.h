/* lib/include/edgespace/es_interp.h — interpolation in edge-length space.
 *
 * K input shapes with one topology (positions 3 x V each) and weights w_k
 * (any real numbers; weights outside [0, 1] extrapolate) give the target
 *   l = (sum_k w_k l_k / s_k) * (sum_k w_k s_k),  s_k = sum of l_k,
 * i.e. the weighted mean of the scale-normalized lengths at the weighted
 * mean scale (eq. 12 of edge-length-interpolation), and the initial
 * dihedrals by a circular (shortest-arc) weighted mean,
 *   alpha = alpha_r + sum_k w_k wrap(alpha_k - alpha_r),
 * r the input of largest weight, wrap to (-pi, pi]: a literal average sends
 * edges whose dihedral crosses +-pi between inputs to about 0 (oracle
 * README, failure F). The target is embedded by es_embed_solve from those
 * dihedrals and aligned to input r (sequences: to the previous frame).
 */
#ifndef EDGESPACE_ES_INTERP_H
#define EDGESPACE_ES_INTERP_H

#include "es_core.h"
#include "es_mesh.h"
#include "es_embed.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct es_interp_info {
    int64_t reference;      /* input r (largest weight) */
    int64_t n_wrapped;      /* edges whose dihedrals differ by more than pi between
                               input r and some other input (shortest arc taken) */
    double scale;           /* sum of target lengths */
} es_interp_info;

/* Target lengths (E) and initial dihedrals (E) for weights w (nin) of
 * inputs xyz[k] (3 x V each). Either output may be NULL. Fails with
 * ES_EINVAL on nin < 1, non-finite weights or positions, weights summing to
 * 0, an input with a zero-length edge, and a target length <= 0 (weights
 * that extrapolate too far: no mesh realizes it; the message names the
 * edge). */
ES_API es_status es_interp_targets(es_ctx *ctx, const es_mesh *mesh, int64_t nin,
                                   const double *const *xyz, const double *w, double *len,
                                   double *alpha, es_interp_info *info);

/* Interpolate and embed: out (3 x V). align_to: positions to align the
 * output to (NULL: input r). report/info may be NULL. */
ES_API es_status es_interp_embed(es_ctx *ctx, es_embedder *emb, int64_t nin, const double *const *xyz,
                                 const double *w, const double *align_to,
                                 const es_embed_opts *opts, double *out,
                                 es_embed_report *report, es_interp_info *info);

/* A sequence from a (t = t0) to b (t = t1) in nsteps frames (nsteps >= 1;
 * nsteps = 1 gives t0 only), weights (1 - t, t); t may leave [0, 1]. Frame i
 * is out + 3 V i, aligned to frame i - 1 (frame 0 to a) so that the
 * sequence does not jump. reports: nsteps entries or NULL. */
ES_API es_status es_interp_sequence(es_ctx *ctx, es_embedder *emb, const double *a, const double *b,
                                    double t0, double t1, int64_t nsteps,
                                    const es_embed_opts *opts, double *out,
                                    es_embed_report *reports);

#ifdef __cplusplus
}
#endif
#endif
