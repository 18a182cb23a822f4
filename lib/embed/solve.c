/* lib/embed/solve.c — edge lengths to vertex positions: es_embed_solve,
 * which checks the input and drives the four stages.
 *
 * Stage 1 (stage_dihedrals.c) repairs the initial dihedrals' closure,
 * stages 2-3 (stage_frames.c) turn dihedrals into frames and positions,
 * stage 4 (stage_refine.c) refines the positions against the lengths
 * (edge-length-interpolation Section 2, with the changes of es_embed.h;
 * Lipman et al. 2005 for the frames, Marquardt 1963 for stages 1 and 4).
 * Alternatively stage 4 runs alone along a path of lengths from the initial
 * mesh (continuation). The result is rigidly aligned to the initial or
 * reference positions per component (Kabsch 1976, align.c) and measured
 * for the report.
 */
#include "embed/embed_pkg.h"
#include "edgespace/es_geom.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

void es_embed_opts_init(es_embed_opts *o)
{
    o->dihedral_mode = ES_EMBED_DIHEDRAL_AUTO;
    o->dihedral_max_iter = 30;
    o->dihedral_rtol = 1e-4;
    o->dihedral_tol = 1e-24;
    o->refine_max_iter = 12;
    o->refine_rtol = 1e-3;
    o->refine_tol = 1e-13;
    o->refine_rms_tol = 0;
    o->refine_max_tol = 0;
    o->continuation_steps = 0;
    o->try_both = 0;
    o->align = 1;
    o->bad_face_rtol = 1e-12;
    o->realized_rtol = 1e-2;
    o->verbose = 0;
    o->blas_threads = 1;
    /* measured on face-study when the prior solve was built (prior.c) */
    o->prior_mu = 2.5e-3;
    o->prior_decay = 0.8;
    o->prior_mu_floor = 0.07;   /* 0.8^12: where 12 iterations end */
    o->prior_sd_floor = 0.7;
    o->prior_start_max_rms = 0.04;
    o->prior_exact = 0;
    o->prior_bend_closed = 0;
    /* the local-global solve: measured on face-study (local_global.c) */
    o->solver = ES_EMBED_SOLVER_AUTO;
    /* 40, then the Levenberg-Marquardt polish: measured against 100
     * iterations and no polish (tools/bench/bench_points, quiet machine),
     * 100 was 13 % faster on face-study's points (0.34 s against 0.40 s a
     * point: most met the accuracy stop in 47-91 iterations) but bent them
     * more (mean 1.077 x the prior's against 1.065, mean + 2 sd on PC 2
     * 1.112 against 1.082), and on sfm_surrey subdivided to 13.6K and 54K
     * vertices mean + 2 sd on PC 2 bent 1.385 and 1.673 against 1.329 and
     * 1.626 in as much time: the polish fixes the last length error with
     * less bending than more local-global iterations */
    o->lg_max_iter = 40;
    o->lg_history = 6;
    o->lg_rms_tol = 5e-4;
    o->lg_max_tol = 1e-2;
    o->lg_rtol = 1e-4;
    o->lg_polish = 4;
    /* sfm_surrey subdivided, quiet machine (tools/bench/bench_points): at
     * 54K vertices one polish iteration costs about 25 local-global ones
     * and at 216K about 35, and more local-global iterations then do at
     * least as well: 216K mean 57 iterations, 6.5 s, max 0.97 %, bending
     * 1.14 x the prior's, against 40 + 2 polish iterations, 11.9 s, max
     * 0.93 %, bending 1.18; mean + 2 sd on PC 2 (not realizable) 7.0 s,
     * max 3.1 %, bending 1.71 against 12.1 s, 2.7 %, 1.89; at 54K 1.5 s,
     * max 2.5 %, bending 1.56 against 3.2 s, 2.1 %, 1.63. At 13.6K the
     * polish still bent less (1.33 against 1.41) for 0.5 s more */
    o->polish_max_verts = 50000;
    o->lg_max_iter_large = 70;
    o->realize_bend = 3;
    o->realize_margin = 0.01;
    o->crease_margin = 0.1;
    o->crease_mu = 1e-3;   /* measured: crease_guard.c */
}

void es_embed_opts_fast(es_embed_opts *o)
{
    es_embed_opts_init(o);
    o->lg_polish = 0;
    o->lg_max_iter = 30;
    o->lg_rms_tol = 1e-3;
    o->lg_max_tol = 2e-2;
}

static int all_finite(const double *x, int64_t n)
{
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(x[i])) return 0;
    return 1;
}

static void edge_lengths_of(const es_embedder *emb, const double *xyz, double *len)
{
    for (int64_t e = 0; e < emb->ne; e++) {
        const double *a = xyz + 3 * emb->edges[2 * e], *b = xyz + 3 * emb->edges[2 * e + 1];
        len[e] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                      (a[2] - b[2]) * (a[2] - b[2]));
    }
}

void es__length_fit(const es_embedder *emb, const double *xyz, const double *L, double *rms,
                    double *mx)
{
    double ss = 0, sl = 0, m = 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        const double *a = xyz + 3 * emb->edges[2 * e], *b = xyz + 3 * emb->edges[2 * e + 1];
        double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                        (a[2] - b[2]) * (a[2] - b[2])) - L[e];
        ss += d * d;
        sl += L[e];
        if (!(fabs(d) / L[e] <= m)) m = fabs(d) / L[e];
    }
    *rms = sqrt(ss / (double)emb->ne) / (sl / (double)emb->ne);
    *mx = m;
}

/* Continuation: stage 4 along l(s) = (1 - s) l_init + s l_target from the
 * initial mesh (scaled to the target's sum), which realizes l(0) exactly. */
static es_status run_continuation(es_embedder *emb, const es_embed_opts *o, const double *L,
                                  const double *init_xyz, es__bend_prior *bp, double *xyz,
                                  int64_t *iters)
{
    int64_t n = o->continuation_steps, ne = emb->ne;
    double s0 = 0, s1 = 0, f;
    es_status rc;
    edge_lengths_of(emb, init_xyz, emb->lpath);
    for (int64_t e = 0; e < ne; e++) {
        s0 += emb->lpath[e];
        s1 += L[e];
    }
    f = s0 > 0 ? s1 / s0 : 1.0;
    for (int64_t i = 0; i < 3 * emb->nv; i++) xyz[i] = init_xyz[i] * f;
    for (int64_t e = 0; e < ne; e++) emb->lpath[e] *= f;
    for (int64_t step = 1; step <= n; step++) {
        double s = (double)step / (double)n;
        double *lp = emb->alpha_try;   /* scratch E */
        for (int64_t e = 0; e < ne; e++) lp[e] = (1 - s) * emb->lpath[e] + s * L[e];
        es__refine_opts ro = es__refine_opts_from(o);
        if (step < n) {   /* the path's inner steps: a few iterations each */
            ro.max_iter = 4;
            ro.rtol = 1e-3;
            ro.rms_tol = ro.max_tol = 0;
        }
        rc = es__stage_refine(emb, lp, xyz, bp, &ro, iters);
        if (rc != ES_OK) return rc;
        es__progress(emb->ctx, "embed: continuation", step, n);
    }
    return ES_OK;
}

/* Stages 2-3 from dihedrals alpha; a result that is not finite becomes the
 * origin, from which the refinement starts. Adds to the report's stage
 * times. */
static es_status linear_stages(es_embedder *emb, const double *alpha, const double *L,
                               double *xyz, es_embed_report *rep)
{
    es_status rc;
    double t1 = es__seconds();
    if ((rc = es__stage_frames(emb, alpha)) != ES_OK) return rc;
    rep->t_frames += es__seconds() - t1;
    t1 = es__seconds();
    if ((rc = es__stage_positions(emb, L, xyz)) != ES_OK) return rc;
    rep->t_positions += es__seconds() - t1;
    if (!all_finite(xyz, 3 * emb->nv))
        for (int64_t i = 0; i < 3 * emb->nv; i++) xyz[i] = 0;
    return ES_OK;
}

/* xyz = start scaled so that its lengths sum to `sum`; returns the RMS
 * ratio of its lengths against L. */
static double scaled_start(const es_embedder *emb, const double *start, const double *L,
                           double sum, double *xyz)
{
    double s0 = 0, rms, mx;
    edge_lengths_of(emb, start, emb->lpath);
    for (int64_t e = 0; e < emb->ne; e++) s0 += emb->lpath[e];
    for (int64_t i = 0; i < 3 * emb->nv; i++) xyz[i] = start[i] * (s0 > 0 ? sum / s0 : 1.0);
    es__length_fit(emb, xyz, L, &rms, &mx);
    return rms;
}

/* Stage 4 from positions: xyz = start scaled to the target's sum, or, when
 * ext->start_auto and those positions are more than start_max_rms off the
 * lengths (a vertex blend of rows whose parts rotate far apart, e.g. two
 * poses of a cat: 6-8 %; a blend of faces: 0.7-2.2 %), the stages 2-3 mesh
 * of alpha if that is closer. */
static es_status positions_start(es_embedder *emb, const es__solve_ext *ext, const double *alpha,
                                 const double *L, double *xyz, es_embed_report *rep)
{
    int64_t n3 = 3 * emb->nv;
    es_status rc;
    rep->rms_ratio_linear = scaled_start(emb, ext->start_xyz, L, rep->scale, xyz);
    if (ext->start_auto && alpha && rep->rms_ratio_linear > ext->start_max_rms) {
        double r2, m2, *lx = emb->xyz_best;
        if ((rc = linear_stages(emb, alpha, L, lx, rep)) != ES_OK) return rc;
        es__length_fit(emb, lx, L, &r2, &m2);
        if (all_finite(lx, n3) && r2 < rep->rms_ratio_linear) {
            memcpy(xyz, lx, (size_t)n3 * sizeof *xyz);
            rep->rms_ratio_linear = r2;
        }
    }
    return ES_OK;
}

int es__start_beyond(es_embedder *emb, const double *target, double scale, const double *start,
                     double max_rms)
{
    double sum = 0, f;
    for (int64_t e = 0; e < emb->ne; e++) sum += target[e];
    if (!(sum > 0 && isfinite(sum))) return 1;   /* the solve refuses it; let it */
    f = scale > 0 ? scale / sum : 1.0;
    for (int64_t e = 0; e < emb->ne; e++) emb->ltarget[e] = target[e] * f;
    /* as embed_solve forms L and the scale, and positions_start decides */
    return scaled_start(emb, start, emb->ltarget, scale > 0 ? scale : sum, emb->xyz_try) > max_rms;
}

/* Stage 4 (Levenberg-Marquardt on the lengths, with the bending prior) from
 * the start's positions: the solver before the local-global one, kept for
 * ES_EMBED_SOLVER_LM and as the polish. */
static es_status refine_from_start(es_embedder *emb, const es_embed_opts *o, es__bend_prior *bp,
                                   const double *L, double *xyz, es_embed_report *rep)
{
    es_status rc;
    es__refine_opts ro = es__refine_opts_from(o);
    /* an exactly realizable target (below) asks for the real mesh back,
     * not for an accuracy: its refinement runs to the cost's own rules
     * (stopped at the accuracy, held-out synthetic faces came back 0.05-
     * 0.13 % of the bbox diagonal from the real ones instead of
     * 0.04-0.06 %) */
    if (bp && o->prior_exact) ro.rms_tol = ro.max_tol = 0;
    if (o->refine_max_iter > 0 &&
        (rc = es__stage_refine(emb, L, xyz, bp, &ro, &rep->refine_iters)) != ES_OK)
        return rc;
    /* an exactly realizable target: the lengths finish, from the prior's
     * shape, until the cost stops falling (up to 3 x the iterations),
     * with the bending term held at 4e-4 of its first weight so that
     * the flexes the lengths leave free do not drift (held-out real
     * faces: max edge error 0.48 % -> 0.16 %, distance to the real mesh
     * at worst 0.205 % -> 0.194 % of the bbox diagonal; with no term at
     * all 0.178 % on faces that were at 0.11 %) */
    if (bp && o->prior_exact && o->refine_max_iter > 0) {
        es__bend_prior hold = es__bend_held(bp, bp->mu_exact);
        /* the lengths decide: no accuracy stop short of where they stop falling */
        ro.max_iter = 3 * o->refine_max_iter;
        ro.rms_tol = ro.max_tol = 0;
        if ((rc = es__stage_refine(emb, L, xyz, &hold, &ro, &rep->refine_iters)) != ES_OK)
            return rc;
    }
    return ES_OK;
}

/* Whether the mesh is large enough that local-global iterations take the
 * polish's place (polish_max_verts, measured above). */
static int polish_too_costly(const es_embedder *emb, const es_embed_opts *o)
{
    return o->polish_max_verts > 0 && emb->nv >= o->polish_max_verts;
}

/* Whether the Levenberg-Marquardt polish may run: asked for, and the mesh
 * below that size. */
int es__polish_allowed(const es_embedder *emb, const es_embed_opts *o)
{
    return o->lg_polish > 0 && o->refine_max_iter > 0 && !polish_too_costly(emb, o);
}

/* The local-global iterations of one solve, at most (exact targets: twice);
 * a polished solve on a mesh too large for the polish gets
 * lg_max_iter_large instead. */
static int shape_iters(const es_embedder *emb, const es_embed_opts *o)
{
    int n = o->lg_polish > 0 && polish_too_costly(emb, o) && o->lg_max_iter_large > o->lg_max_iter
                ? o->lg_max_iter_large
                : o->lg_max_iter;
    return o->prior_exact ? 2 * n : n;
}

/* From the start's positions: the local-global solve (local_global.c) on
 * the nearest lengths that form triangles when the target's do not
 * (lengths_project.c), and where it has not met the tolerances within its
 * iterations, Levenberg-Marquardt with the prior's bending term held at
 * its last weight (stage_refine.c) until it does. Local-global iterations
 * are cheap and fix most of the length error; a Newton step then fixes the
 * rest with less bending than further local-global iterations would
 * (face-study mean + 2 sd on PC 2 at RMS 0.05 %: bending 1.087 x the
 * prior's against 1.107). An exactly realizable target (one real mesh's
 * lengths) is solved to a third of the tolerances. The report measures the
 * output against the asked lengths and says how far the projection went. */
static es_status shape_from_start(es_embedder *emb, const es_embed_opts *o, es__bend_prior *bp,
                                  const double *L, int warm, double *xyz, es_embed_report *rep)
{
    const double *Lr = L;
    es__lg_result res;
    /* a warm start keeps the last factor while the weights are within 10 %
     * of its own (local_global.c: assemble) */
    es__lg_opts lo = {shape_iters(emb, o), o->lg_history, o->lg_rms_tol, o->lg_max_tol, o->lg_rtol,
                      o->verbose, warm ? 0.1 : 0};
    es_status rc;
    if (rep->n_bad_faces > 0 && o->realize_margin >= 0) {
        rep->n_projected = es__lengths_project(emb, L, o->realize_margin, emb->len,
                                               &rep->projection_rms, &rep->projection_max);
        Lr = emb->len;
    }
    if (o->prior_exact) lo.rms_tol /= 3, lo.max_tol /= 3;
    double t0 = es__seconds();
    rc = es__lg_solve(emb, Lr, xyz, &lo, &res);
    rep->t_local_global = es__seconds() - t0;
    if (rc != ES_OK) return rc;
    rep->lg_iters = res.iters;
    /* a target no mesh has: the finish always runs, with the prior's term at
     * realize_bend x its first weight, so that the data's bending decides
     * where the lengths cannot be met (face-study mean + 2 sd on PC 1, 81
     * rows: bending 1.22 x the prior's with the last weight, 1.07 with 3 x
     * the first, length RMS 0.04 % -> 0.13 %) */
    int inconsistent = rep->n_bad_faces > 0 && o->realize_bend > 0 && bp;
    if ((!res.met || inconsistent) && es__polish_allowed(emb, o)) {
        es__refine_opts ro = es__refine_opts_from(o);
        es__bend_prior hold;
        /* a few iterations: chasing the last edges' error for longer crumpled
         * the rest (sfm_surrey subdivided to 54K: mean + 2 sd on PC 2 went
         * from bending 1.31 x the prior's to 1.69 in 12 iterations to move
         * its worst edge from 7 % to 1.01 %) */
        ro.max_iter = o->lg_polish < o->refine_max_iter ? o->lg_polish : o->refine_max_iter;
        ro.rms_tol = lo.rms_tol, ro.max_tol = lo.max_tol;
        if (bp) hold = es__bend_held(bp, inconsistent ? bp->mu_realize : bp->mu_min);
        if ((rc = es__stage_refine(emb, Lr, xyz, bp ? &hold : NULL, &ro, &rep->refine_iters)) != ES_OK)
            return rc;
    }
    return ES_OK;
}

/* The inputs refused with a message naming the edge or vertex; *sum the
 * target lengths' sum. */
static es_status check_inputs(es_embedder *emb, const double *target, double scale,
                              const double *init_alpha, const double *init_xyz, double *sum)
{
    *sum = 0;
    if (!(isfinite(scale) && scale >= 0))
        ES_FAIL(emb->ctx, ES_EINVAL, "embed: scale %g is not finite and >= 0", scale);
    for (int64_t e = 0; e < emb->ne; e++) {
        if (!(isfinite(target[e]) && target[e] > 0))
            ES_FAIL(emb->ctx, ES_EINVAL, "embed: target length of edge %lld (%lld-%lld) is %g, not "
                    "finite and positive", (long long)e, (long long)emb->edges[2 * e],
                    (long long)emb->edges[2 * e + 1], target[e]);
        *sum += target[e];
    }
    if (!isfinite(*sum)) ES_FAIL(emb->ctx, ES_EINVAL, "embed: target lengths sum to %g", *sum);
    if (init_alpha)
        for (int64_t e = 0; e < emb->ne; e++)
            if (!emb->eb[e] && !isfinite(init_alpha[e]))
                ES_FAIL(emb->ctx, ES_EINVAL, "embed: initial dihedral of edge %lld is not finite",
                        (long long)e);
    if (init_xyz)   /* all vertices: those in no face are copied to the output */
        for (int64_t i = 0; i < 3 * emb->nv; i++)
            if (!isfinite(init_xyz[i]))
                ES_FAIL(emb->ctx, ES_EINVAL, "embed: initial position of vertex %lld is not finite",
                        (long long)(i / 3));
    return ES_OK;
}

/* The path from given positions (a prior's realization): the start, then
 * local-global iterations (or Levenberg-Marquardt with ES_EMBED_SOLVER_LM).
 * alpha: the dihedrals for positions_start's stages 2-3 fallback, or NULL. */
static es_status solve_from_positions(es_embedder *emb, const es_embed_opts *o, es__bend_prior *bp,
                                      const es__solve_ext *ext, const double *alpha,
                                      const double *L, double *xyz, es_embed_report *rep)
{
    es_status rc;
    double t1;
    int lg = o->solver != ES_EMBED_SOLVER_LM;
    emb->progress_total = 1 + (lg ? shape_iters(emb, o) : o->refine_max_iter > 0 ? o->refine_max_iter : 0);
    es__progress(emb->ctx, "embedding", 0, emb->progress_total);
    if ((rc = positions_start(emb, ext, alpha, L, xyz, rep)) != ES_OK)
        return rc;
    es__progress(emb->ctx, "embedding", 1, emb->progress_total);
    t1 = es__seconds();
    rc = lg ? shape_from_start(emb, o, bp, L, ext && ext->warm, xyz, rep)
            : refine_from_start(emb, o, bp, L, xyz, rep);
    if (rc != ES_OK) return rc;
    rep->t_refine = es__seconds() - t1;
    es__progress(emb->ctx, "embedding", emb->progress_total, emb->progress_total);
    emb->progress_total = 0;
    return ES_OK;
}

/* The dihedral path (edge-length-interpolation Section 2): stages 1-4.
 * Stage 1 repairs incoherent (noisy) dihedrals but can pull interpolated
 * ones into a wrong closure minimum (oracle README, failure E). In auto
 * mode one LM iteration decides: stage 1 goes on only if that iteration
 * removed 99 % of the closure energy, else its dihedrals are dropped. On
 * noisy dihedrals (0.001-0.1 rad, six real meshes) one iteration cuts the
 * energy 300-20000x; on interpolated ones (midpoints of six real pairs)
 * 1.1-36x, and there a finished stage 1 was always worse than none
 * (failure E), and even the one iteration gave no better result after the
 * refinement (cactus midpoints, 5K and 21K vertices: RMS ratio 0.0183 % /
 * 0.0097 % with it, 0.0170 % / 0.0093 % without). So the linear stages run
 * once. */
static es_status solve_dihedral_path(es_embedder *emb, const es_embed_opts *o,
                                     es__bend_prior *bp, double *alpha, const double *L,
                                     double *xyz, es_embed_report *rep)
{
    es_status rc;
    double t1;
    double mx;
    int mode = o->dihedral_mode;
    if (emb->nvar == 0 || o->dihedral_max_iter <= 0) mode = ES_EMBED_DIHEDRAL_OFF;
    rep->closure_stage1 = rep->closure_before;
    /* one bar on a terminal: stage 1, stages 2-3, each refinement iteration */
    emb->progress_total = 3 + (o->refine_max_iter > 0 ? o->refine_max_iter : 0);
    es__progress(emb->ctx, "embedding", 0, emb->progress_total);
    if (mode != ES_EMBED_DIHEDRAL_OFF) {
        double lambda1 = 1e-3;
        int first = mode == ES_EMBED_DIHEDRAL_AUTO ? 1 : o->dihedral_max_iter;
        memcpy(emb->alpha_keep, alpha, (size_t)emb->ne * sizeof *alpha);
        t1 = es__seconds();
        if ((rc = es__stage_dihedrals(emb, o, first, alpha, &rep->closure_stage1,
                                  &rep->dihedral_iters, &lambda1)) != ES_OK)
            return rc;
        rep->used_stage1 = 1;
        if (mode == ES_EMBED_DIHEDRAL_AUTO) {
            if (!(rep->closure_stage1 < 0.01 * rep->closure_before)) {
                memcpy(alpha, emb->alpha_keep, (size_t)emb->ne * sizeof *alpha);
                rep->used_stage1 = 0;
            } else if (first < o->dihedral_max_iter &&
                       (rc = es__stage_dihedrals(emb, o, o->dihedral_max_iter - first, alpha,
                                             &rep->closure_stage1, &rep->dihedral_iters,
                                             &lambda1)) != ES_OK) {
                return rc;
            }
        }
        rep->t_dihedral = es__seconds() - t1;
    }
    es__progress(emb->ctx, "embedding", 1, emb->progress_total);
    if ((rc = linear_stages(emb, alpha, L, xyz, rep)) != ES_OK) return rc;
    es__progress(emb->ctx, "embedding", 2, emb->progress_total);
    es__length_fit(emb, xyz, L, &rep->rms_ratio_linear, &mx);
    t1 = es__seconds();
    es__refine_opts ro = es__refine_opts_from(o);
    if (o->refine_max_iter > 0 &&
        (rc = es__stage_refine(emb, L, xyz, bp, &ro, &rep->refine_iters)) != ES_OK)
        return rc;
    rep->t_refine = es__seconds() - t1;
    es__progress(emb->ctx, "embedding", emb->progress_total, emb->progress_total);
    emb->progress_total = 0;
    return ES_OK;
}

/* The continuation path (run_continuation) from init_xyz; after the
 * dihedral path it replaces that result only where its worst edge is
 * better. */
static es_status solve_continuation(es_embedder *emb, const es_embed_opts *o, es__bend_prior *bp,
                                    const double *L, const double *init_xyz,
                                    int have_dihedral_result, double *xyz, es_embed_report *rep)
{
    es_status rc;
    double t1;
    double *cx = have_dihedral_result ? emb->xyz_best : xyz;
    int64_t it = 0;
    t1 = es__seconds();
    if ((rc = run_continuation(emb, o, L, init_xyz, bp, cx, &it)) != ES_OK) return rc;
    rep->t_refine += es__seconds() - t1;
    rep->continuation_steps = o->continuation_steps;
    if (have_dihedral_result) {
        double r1, m1, r2, m2;
        es__length_fit(emb, xyz, L, &r1, &m1);
        es__length_fit(emb, cx, L, &r2, &m2);
        if (all_finite(cx, 3 * emb->nv) && (m2 < m1 || !all_finite(xyz, 3 * emb->nv))) {
            memcpy(xyz, cx, (size_t)(3 * emb->nv) * sizeof *xyz);
            rep->used_continuation = 1;
            rep->refine_iters = it;
        }
    } else {
        rep->used_continuation = 1;
        rep->refine_iters = it;
    }
    return ES_OK;
}

/* The report's measures of the output: length errors, each vertex's mean
 * relative error and closure energy, the worst edge, realized. */
static es_status report_output(es_embedder *emb, const es_embed_opts *o, const double *L,
                               const double *xyz, es_embed_report *rep)
{
    es_status rc;
    if ((rc = es_embed_length_error(emb->ctx, emb->mesh, xyz, L, 0, &rep->rms_ratio, &rep->max_rel,
                                    &rep->p99_rel)) != ES_OK)
        return rc;
    edge_lengths_of(emb, xyz, emb->lpath);
    for (int64_t v = 0; v < emb->nv; v++) emb->verr[v] = 0;
    {
        double mx = -1;
        for (int64_t e = 0; e < emb->ne; e++) {
            double r = fabs(emb->lpath[e] - L[e]) / L[e];
            emb->verr[emb->edges[2 * e]] += r;
            emb->verr[emb->edges[2 * e + 1]] += r;
            if (r > mx) {
                mx = r;
                rep->worst_edge = e;
            }
        }
    }
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t k = emb->off[v + 1] - emb->off[v];
        if (k) emb->verr[v] /= (double)k;
    }
    if ((rc = es_dihedral_angles(emb->ctx, emb->mesh, xyz, emb->alpha_try)) != ES_OK) return rc;
    rep->closure_after = es__closure_eval(emb, emb->alpha_try, 0, emb->vclos);
    emb->have_vertex_results = 1;
    rep->realized = rep->max_rel <= o->realized_rtol && rep->n_bad_faces == 0;
    return ES_OK;
}

static es_status embed_solve(es_embedder *emb, const double *target, double scale,
                             const double *init_alpha, const double *init_xyz,
                             const es__solve_ext *ext, const es_embed_opts *opts, double *xyz,
                             es_embed_report *report)
{
    es_ctx *ctx;
    es_embed_opts dflt;
    es_embed_report rep;
    const es_embed_opts *o = opts;
    int64_t nv, ne, n3;
    double sum = 0, f, t0 = es__seconds(), *L, *alpha;
    const double *ref;
    es_status rc;
    int have_dihedral_result = 0;
    if (!emb) return ES_EINVAL;
    ctx = emb->ctx;
    nv = emb->nv;
    ne = emb->ne;
    n3 = 3 * nv;
    memset(&rep, 0, sizeof rep);
    rep.worst_edge = -1;
    if (!o) {
        es_embed_opts_init(&dflt);
        o = &dflt;
    }
    if (!target || !xyz) ES_FAIL(ctx, ES_EINVAL, "embed: NULL target or output");
    const double *start = ext && ext->start_xyz ? ext->start_xyz : NULL;
    es__bend_prior *bp = ext ? ext->bp : NULL;
    if (!init_alpha && !init_xyz && !start)
        ES_FAIL(ctx, ES_EINVAL, "embed: need initial dihedrals or initial positions");
    if ((rc = check_inputs(emb, target, scale, init_alpha, init_xyz, &sum)) != ES_OK) return rc;

    L = emb->ltarget;
    alpha = emb->alpha;
    f = scale > 0 ? scale / sum : 1.0;
    for (int64_t e = 0; e < ne; e++) L[e] = target[e] * f;
    rep.scale = scale > 0 ? scale : sum;
    rep.n_bad_faces = es__corner_angles(emb->mesh, L, o->bad_face_rtol, emb->ang);
    for (int64_t i = 0; i < emb->off[nv]; i++)
        emb->theta[i] = emb->slot_corner[i] >= 0 ? emb->ang[emb->slot_corner[i]] : 0.0;
    if (init_alpha) {
        for (int64_t e = 0; e < ne; e++) alpha[e] = emb->eb[e] ? 0.0 : init_alpha[e];
    } else {
        if ((rc = es_dihedral_angles(ctx, emb->mesh, init_xyz ? init_xyz : start, alpha)) != ES_OK)
            return rc;
    }
    rep.closure_before = es__closure_eval(emb, alpha, 0, NULL);
    emb->have_vertex_results = 0;
    emb->have_deviation = 0;   /* a prior solve measures it afterwards */

    /* one path to a first mesh, then alignment and the report */
    if (start) {
        if ((rc = solve_from_positions(emb, o, bp, ext, init_alpha ? alpha : NULL, L, xyz,
                                       &rep)) != ES_OK)
            return rc;
    } else if (!(o->continuation_steps > 0 && init_xyz) || o->try_both) {
        if ((rc = solve_dihedral_path(emb, o, bp, alpha, L, xyz, &rep)) != ES_OK) return rc;
        have_dihedral_result = 1;
    }
    if (o->continuation_steps > 0 && init_xyz && !start &&
        (rc = solve_continuation(emb, o, bp, L, init_xyz, have_dihedral_result, xyz, &rep)) !=
            ES_OK)
        return rc;
    if (!all_finite(xyz, n3))
        for (int64_t i = 0; i < n3; i++) xyz[i] = init_xyz ? init_xyz[i] * f : 0.0;
    for (int64_t v = 0; v < nv; v++)
        if (emb->vweight[v] == 0) xyz[3 * v] = xyz[3 * v + 1] = xyz[3 * v + 2] = 0;

    /* alignment */
    ref = ext && ext->align_ref ? ext->align_ref : init_xyz ? init_xyz : es_mesh_xyz(emb->mesh);
    if (o->align && ref) {
        double r;
        if ((rc = es_embed_align_parts(ctx, nv, xyz, ref, emb->vweight,
                                       es_mesh_vertex_component(emb->mesh), &r)) != ES_OK)
            return rc;
        for (int64_t v = 0; v < nv; v++)
            if (emb->vweight[v] == 0)
                for (int i = 0; i < 3; i++) xyz[3 * v + i] = ref[3 * v + i];
    }

    if ((rc = report_output(emb, o, L, xyz, &rep)) != ES_OK) return rc;
    rep.t_total = es__seconds() - t0;
    if (report) *report = rep;
    return ES_OK;
}

/* The BLAS work of an embedding is many small dense blocks (the supernodes
 * of a surface mesh's factor). Threaded OpenBLAS made whole midpoint
 * embeddings 25-33 % slower with 2 threads than with 1 on this project's
 * 2-core machine (9.4K, 13.6K and 54K vertices; OMP_NUM_THREADS=1 too), so
 * the solve runs with opts->blas_threads threads and restores the caller's
 * setting. OpenBLAS's setter is a weak symbol: with another BLAS the
 * setting is left alone. */
#if defined(__GNUC__)
extern void openblas_set_num_threads(int n) __attribute__((weak));
extern int openblas_get_num_threads(void) __attribute__((weak));
#define ES_HAVE_BLAS_THREADS 1
#endif

/* Both entry points: the BLAS threads, the aliasing of init_xyz with the
 * output, the progress bar and the caller's context. */
static es_status solve_wrapped(es_ctx *ctx, es_embedder *emb, const double *target,
                               double scale, const double *init_alpha, const double *init_xyz,
                               const es__solve_ext *ext, const es_embed_opts *opts, double *xyz,
                               es_embed_report *report)
{
    es_status rc;
    if (!emb) ES_FAIL(ctx, ES_EINVAL, "embed: no embedder");
    int want = opts ? opts->blas_threads : 1, had = 0;
    /* init_xyz may be the output array (a sequence aligned frame to frame):
     * the solve writes its output before it aligns it to init_xyz, so it
     * must read a copy then */
    if (init_xyz && xyz) {
        uintptr_t a = (uintptr_t)init_xyz, b = (uintptr_t)xyz;
        uintptr_t n = 3 * (uintptr_t)emb->nv * sizeof *xyz;
        if (a < b + n && b < a + n) {
            memcpy(emb->init_copy, init_xyz, (size_t)n);
            init_xyz = emb->init_copy;
        }
    }
#ifdef ES_HAVE_BLAS_THREADS
    if (want > 0 && openblas_set_num_threads && openblas_get_num_threads) {
        had = openblas_get_num_threads();
        if (had != want) openblas_set_num_threads(want);
        else had = 0;
    }
#endif
    rc = embed_solve(emb, target, scale, init_alpha, init_xyz, ext, opts, xyz, report);
    if (emb->progress_total) {   /* failed part way: close the bar */
        es__progress(emb->ctx, "embedding", emb->progress_total, emb->progress_total);
        emb->progress_total = 0;
    }
#ifdef ES_HAVE_BLAS_THREADS
    if (had > 0) openblas_set_num_threads(had);
#endif
    (void)want;
    (void)had;
    /* the embedder works on its own context; the caller's gets the message */
    if (rc != ES_OK && ctx && ctx != emb->ctx) es__fail(ctx, rc, "%s", es_ctx_errmsg(emb->ctx));
    return rc;
}

es_status es_embed_solve(es_ctx *ctx, es_embedder *emb, const double *target, double scale,
                         const double *init_alpha, const double *init_xyz,
                         const es_embed_opts *opts, double *xyz, es_embed_report *report)
{
    return solve_wrapped(ctx, emb, target, scale, init_alpha, init_xyz, NULL, opts, xyz, report);
}

es_status es__embed_solve_ext(es_ctx *ctx, es_embedder *emb, const double *target,
                              double scale, const double *init_alpha, const es__solve_ext *ext,
                              const es_embed_opts *opts, double *xyz, es_embed_report *report)
{
    return solve_wrapped(ctx, emb, target, scale, init_alpha, NULL, ext, opts, xyz, report);
}

es_status es__embed_solve_bend(es_ctx *ctx, es_embedder *emb, const double *target, double scale,
                               const double *init_alpha, const double *init_xyz,
                               const double *align_ref, es__bend_prior *bp,
                               const es_embed_opts *opts, double *xyz, es_embed_report *report)
{
    es__solve_ext ext;
    memset(&ext, 0, sizeof ext);
    ext.bp = bp;
    ext.align_ref = align_ref;
    return solve_wrapped(ctx, emb, target, scale, init_alpha, init_xyz, &ext, opts, xyz, report);
}
