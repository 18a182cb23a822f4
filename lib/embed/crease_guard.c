/* lib/embed/crease_guard.c — the crease guard of interpolated embeddings: a
 * one-sided bending term (es__bend_prior with a band) that holds each
 * interior edge's bending angle inside a band of angles the blended inputs
 * allow, and costs nothing inside it.
 *
 * Why. Interpolated lengths are no mesh's lengths (a weighted mean of the
 * lengths of poses whose parts rotate and stretch differently), and the
 * refinement realizes them to a fraction of a percent by wrinkling: on the
 * bilinear cats of the core paper's Fig. 4 (notebooks-c/07_paper_poses,
 * 7,207 vertices) 3.9-12.5 % of the interior edges came out bent past every
 * input by over 0.3 rad, in folds over the shoulders and the hind legs
 * (where the stretching and the crouching cat differ most), from a stages
 * 2-3 mesh with 0.1-1.8 % such edges but 3-12 % RMS length error. The folds
 * are not forced by the lengths' intrinsic curvature: moving every vertex's
 * angle defect into the span of the inputs' costs only 0.09-0.27 % RMS of
 * the lengths, and those lengths fold the same. They are the refinement's
 * way from a start 10 % off, locally, to the lengths.
 *
 * Measured on those cats (worst of Fig. 4's 8 frames, length RMS ratio /
 * share of edges bent past every input by 0.3 rad; then Fig. 5's 6 frames),
 * refinement 40 iterations, margin 0.1 rad:
 *   no guard                 0.20 % / 12.5 %     0.12 % / 7.0 %
 *   guard mu 1e-4            0.41 % /  7.6 %     0.26 % / 2.5 %
 *   guard mu 1e-3 (default)  0.78 % /  4.3 %     0.52 % / 1.2 %
 *   guard mu 3e-3            1.26 % /  3.2 %     0.88 % / 0.7 %
 *   guard mu 1e-2            2.24 % /  2.2 %
 *   guard mu 0.1             3.85 % /  1.1 %
 * (margin 0: 0.88 % / 4.0 % and 0.49 % / 0.7 % at mu 1e-3), and the
 * alternatives tried, none better on both: a two-sided pull toward the
 * interpolated dihedrals (the open-mesh prior's term, constant or decaying
 * from 1 to 1e-4, from the frame or from stages 2-3) 0.45-4.8 % / 2.3-5.9
 * %; the vertex blend of the aligned inputs as the start (9-22 % off the
 * lengths; Levenberg-Marquardt or local-global) 0.9-3.7 % / 2.0-4.1 %; the
 * pull first, then the guard 0.81-2.1 % / 1.7-4.0 %; continuation from the
 * heaviest input with the guard 1.46 % / 5.9 %; the published pipeline (no
 * refinement; frames 0-2) 3.8-14 % / 10-17 %; a band of alpha +- 3 sd (the rows' spread)
 * instead of the inputs' span 0.78 % / 5.1 %. Nothing found meets both 0.5
 * % RMS and 0.5 % creases on Fig. 4. The default keeps the frames within 1
 * % RMS of their lengths (the notebooks' bound) and cuts the creases about
 * threefold; a caller that wants fewer creases raises crease_mu along the
 * curve above. Inside the band the term is zero, so frames that bend as
 * their inputs do (an input itself, the faces, the cactus) come out as
 * without it.
 */
#include "embed/embed_pkg.h"
#include "edgespace/es_geom.h"

#include <math.h>

/* The guard over the band [lo, hi] in emb->band_lo / band_hi, weighted by
 * the discrete-shells weights of the target lengths len. */
static void guard_from_band(es_embedder *emb, const double *len, const es_embed_opts *o,
                            es__bend_prior *guard)
{
    es__bend_weights(emb, len, NULL, 0, emb->omega);
    *guard = (es__bend_prior){.alpha = emb->band_lo, .hi = emb->band_hi, .omega = emb->omega,
                              .flap = emb->flap};
    es__bend_schedule(guard, o->crease_mu, 1, o->crease_mu, o);
}

/* The band: [min(lo, alpha) - margin, max(hi, alpha) + margin] (the
 * interpolated angle too: an extrapolation may leave the inputs' span). */
static void band(es_embedder *emb, const double *alpha, const double *lo, const double *hi,
                 double margin)
{
    for (int64_t e = 0; e < emb->ne; e++) {
        double l = fmin(lo[e], alpha[e]) - margin, h = fmax(hi[e], alpha[e]) + margin;
        emb->band_lo[e] = l;
        emb->band_hi[e] = h;
    }
}

es_status es__crease_guard_inputs(es_embedder *emb, int64_t nin, const double *const *xyz,
                                  const double *w, const double *alpha, const double *len,
                                  const es_embed_opts *o, es__bend_prior *guard)
{
    const double margin = o->crease_margin;
    int64_t ne = emb->ne;
    double *lo, *hi, *a = emb->alpha_try;
    es_status rc;
    if ((rc = es__bend_work(emb)) != ES_OK) return rc;
    lo = emb->band_lo;
    hi = emb->band_hi;
    for (int64_t e = 0; e < ne; e++) lo[e] = hi[e] = alpha[e];
    for (int64_t k = 0; k < nin; k++) {
        if (w[k] == 0) continue;
        if ((rc = es_dihedral_angles(emb->ctx, emb->mesh, xyz[k], a)) != ES_OK) return rc;
        for (int64_t e = 0; e < ne; e++) {
            lo[e] = fmin(lo[e], a[e]);
            hi[e] = fmax(hi[e], a[e]);
        }
    }
    band(emb, alpha, lo, hi, margin);
    guard_from_band(emb, len, o, guard);
    return ES_OK;
}

es_status es__crease_guard_prior(es_embedder *emb, const double *alpha, const double *span_lo,
                                 const double *span_hi, const double *sd, const double *len,
                                 const es_embed_opts *o, es__bend_prior *guard)
{
    const double margin = o->crease_margin;
    es_status rc;
    if ((rc = es__bend_work(emb)) != ES_OK) return rc;
    if (span_lo && span_hi) {
        band(emb, alpha, span_lo, span_hi, margin);
    } else {
        /* 3 sd covers the span of two rows at weights from 0.1 to 0.9 (sd =
         * |a1 - a2| sqrt(t (1 - t)), the farther row max(t, 1 - t) |a1 - a2|
         * from the mean); measured on the cats it is a looser guard than the
         * span (Fig. 4 worst 5.1 % creases against 4.3 %) */
        for (int64_t e = 0; e < emb->ne; e++) {
            double h = 3 * sd[e] + margin;
            emb->band_lo[e] = alpha[e] - h;
            emb->band_hi[e] = alpha[e] + h;
        }
    }
    guard_from_band(emb, len, o, guard);
    return ES_OK;
}
