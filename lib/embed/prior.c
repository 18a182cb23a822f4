/* lib/embed/prior.c — embedding near a prior from the data (es_embed.h):
 * the prior of row weights, the solve that starts from its realization
 * and keeps the free directions near its dihedrals, and the shape of the
 * output measured against it.
 *
 * Why each choice, measured on face-study with three subjects held out
 * (when the prior solve was built, commit e097105, by a program not kept;
 * the test prior_face_study (tests/study/test_prior_faces.c) checks
 * the held-out bounds): starting from the prior's positions rather
 * than stages 2-3 on its dihedrals (means 0.11 % of the bbox diagonal from
 * the Procrustes mean against 0.22 %); keeping the bending term on (never
 * annealed to 0) on open meshes, whose averaged noisy lengths are realized
 * exactly only by crumpling; weighting each edge down where the rows
 * disagree (max edge error of held-out faces 0.48 % against 2-4 %); no term
 * on closed meshes, where the lengths fix the shape (cat and cactus
 * midpoints come out as es_interp_embed's).
 */
#include "embed/embed_pkg.h"
#include "embed/embed_private.h"
#include "edgespace/es_geom.h"

#include <math.h>
#include <string.h>

/* cos and sin of x in [-pi, pi] to about 1e-7, for the circular mean's
 * sums only: that mean is the centre the dihedrals are averaged around
 * (add_deviations below), so it picks each dihedral's branch and an error of
 * 1e-7 in it moves the prior's dihedrals by less than 1e-7 x |1 - sum w|
 * (nothing when the weights sum to 1, as a point's do). Taylor series of
 * x / 2 to degree 11 (|x / 2| <= pi / 2: remainder below 6e-9), then the
 * double-angle formulas (dihedrals lie in [-pi, pi]; beyond, the centre
 * degrades, as the wrapping below does); several times faster than libm's,
 * and it keeps the prior free of a cache of every row's cosines and sines
 * (2 E doubles a row: 40 MB on face-study, zeroed and filled by a fresh
 * command's first prior). */
static void add_sincos_approx(int64_t n, double a, const double *restrict x,
                              double *restrict cs, double *restrict sn)
{
    /* straight-line code: vectorized where OpenMP's simd is known (-O2
     * alone does not) */
#pragma omp simd
    for (int64_t e = 0; e < n; e++) {
        double h = 0.5 * x[e], h2 = h * h;
        double sh = h * (1 + h2 * (-1.0 / 6 + h2 * (1.0 / 120 + h2 * (-1.0 / 5040 + h2 *
                    (1.0 / 362880 + h2 * (-1.0 / 39916800))))));
        double ch = 1 + h2 * (-0.5 + h2 * (1.0 / 24 + h2 * (-1.0 / 720 + h2 * (1.0 / 40320 +
                    h2 * (-1.0 / 3628800 + h2 * (1.0 / 479001600))))));
        cs[e] += a * (ch * ch - sh * sh);
        sn[e] += a * (2 * sh * ch);
    }
}

/* acc += w d and, with var, var += |w| d^2 for d = x - c wrapped to
 * [-pi, pi) (x, c in [-pi, pi]: one correction does; remainder() cost as
 * much as the rest of the loop), written as selects so that the loop
 * vectorizes (the prior of a slider position reads every row: this loop
 * was a fifth of a warm fast step's CPU). */
/* GCC if-converts the wrap only where comparisons may not trap (no
 * floating-point exception is ever read in this library) */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize("no-trapping-math")
#endif
static void add_deviations(int64_t n, double w, const double *restrict x,
                           const double *restrict c, double *restrict acc,
                           double *restrict var)
{
    const double a = fabs(w);
    if (var) {
#pragma omp simd
        for (int64_t e = 0; e < n; e++) {
            double d = x[e] - c[e];
            d = d >= M_PI ? d - 2.0 * M_PI : d < -M_PI ? d + 2.0 * M_PI : d;
            acc[e] += w * d;
            var[e] += a * d * d;
        }
    } else {
#pragma omp simd
        for (int64_t e = 0; e < n; e++) {
            double d = x[e] - c[e];
            d = d >= M_PI ? d - 2.0 * M_PI : d < -M_PI ? d + 2.0 * M_PI : d;
            acc[e] += w * d;
        }
    }
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif

es_status es_embed_prior_from_rows_sc(es_ctx *ctx, int64_t nverts, int64_t nedges, int64_t n,
                                      const double *const *aligned,
                                      const double *const *alpha_rows,
                                      const double *const *cos_rows,
                                      const double *const *sin_rows, const double *w,
                                      double *xyz, double *alpha, double *sd)
{
    if (n < 1 || !w) ES_FAIL(ctx, ES_EINVAL, "prior: need at least one row and its weight");
    for (int64_t k = 0; k < n; k++)
        if (!isfinite(w[k])) ES_FAIL(ctx, ES_EINVAL, "prior: weight of row %lld is not finite",
                                     (long long)k);
    if (xyz) {
        memset(xyz, 0, (size_t)(3 * nverts) * sizeof *xyz);
        for (int64_t k = 0; k < n; k++)
            if (w[k] != 0)
                for (int64_t i = 0; i < 3 * nverts; i++) xyz[i] += w[k] * aligned[k][i];
    }
    if (!alpha && !sd) return ES_OK;
    int64_t big = 0;
    double wa = 0;
    for (int64_t k = 0; k < n; k++) {
        wa += fabs(w[k]);
        if (fabs(w[k]) > fabs(w[big])) big = k;
    }
    /* row by row (each row's arrays read once, in order) into per-edge sums;
     * xyz's buffer is not needed here, alpha and sd hold the sums */
    double *cs = alpha ? alpha : sd, *sn = alpha && sd ? sd : NULL;
    double *tmp = NULL;
    if (!sn && !(sn = tmp = es__alloc_array(ctx, nedges, sizeof *sn))) return ES_ENOMEM;
    memset(cs, 0, (size_t)nedges * sizeof *cs);
    memset(sn, 0, (size_t)nedges * sizeof *sn);
    for (int64_t k = 0; k < n; k++) {
        double a = fabs(w[k]);
        if (a == 0) continue;
        if (cos_rows && sin_rows) {
            for (int64_t e = 0; e < nedges; e++) {
                cs[e] += a * cos_rows[k][e];
                sn[e] += a * sin_rows[k][e];
            }
        } else {
            add_sincos_approx(nedges, a, alpha_rows[k], cs, sn);
        }
    }
    /* the circular mean; rows that cancel out fall back to the heaviest */
    for (int64_t e = 0; e < nedges; e++)
        cs[e] = cs[e] * cs[e] + sn[e] * sn[e] > 1e-24 ? atan2(sn[e], cs[e]) : alpha_rows[big][e];
    double *c = cs, *acc = sn;   /* c: the mean; acc: sum w d, then sd */
    double *var = NULL;
    if (sd && !(var = es__alloc_array(ctx, nedges, sizeof *var))) {
        es__free(ctx, tmp);
        return ES_ENOMEM;
    }
    memset(acc, 0, (size_t)nedges * sizeof *acc);
    if (var) memset(var, 0, (size_t)nedges * sizeof *var);
    for (int64_t k = 0; k < n; k++) {
        if (w[k] == 0) continue;
        add_deviations(nedges, w[k], alpha_rows[k], c, acc, var);
    }
    for (int64_t e = 0; e < nedges; e++) {
        double mean = c[e] + acc[e];
        if (sd) sd[e] = wa > 0 ? sqrt(var[e] / wa) : 0;
        if (alpha) alpha[e] = mean;
    }
    es__free(ctx, var);
    es__free(ctx, tmp);
    return ES_OK;
}

es_status es_embed_prior_from_rows(es_ctx *ctx, int64_t nverts, int64_t nedges, int64_t n,
                                   const double *const *aligned, const double *const *alpha_rows,
                                   const double *w, double *xyz, double *alpha, double *sd)
{
    return es_embed_prior_from_rows_sc(ctx, nverts, nedges, n, aligned, alpha_rows, NULL, NULL,
                                       w, xyz, alpha, sd);
}

/* Work of the prior, made on the first prior solve of an embedder. */
static es_status prior_work(es_embedder *emb)
{
    es_status rc;
    if ((rc = es__bend_work(emb)) != ES_OK) return rc;
    if (!emb->vdev && !(emb->vdev = es__alloc_array(emb->ctx, emb->nv + 1, sizeof(double))))
        return ES_ENOMEM;
    return ES_OK;
}

static double mean_abs_interior(const es_embedder *emb, const double *alpha)
{
    int64_t n = 0;
    double s = 0;
    for (int64_t e = 0; e < emb->ne; e++)
        if (!emb->eb[e]) {
            s += fabs(alpha[e]);
            n++;
        }
    return n ? s / (double)n : 0;
}

/* The output's shape against the prior: bending of each, and the vertex
 * distances after scaling the prior to the output's size and a rigid
 * alignment, as fractions of the scaled prior's bounding-box diagonal. */
static es_status shape_quality(es_ctx *ctx, es_embedder *emb, const double *xyz,
                               const double *prior_xyz, es_embed_report *rep)
{
    const es_mesh *mesh = emb->mesh;
    int64_t nv = emb->nv, ne = emb->ne;
    double *a = emb->alpha_try, *p = emb->xyz_try, *ps = emb->xyz_best;
    double s0 = 0, s1 = 0, ss = 0, mx = 0, rms, diag;
    es_status rc;
    if ((rc = es_dihedral_angles(ctx, mesh, xyz, a)) != ES_OK) return rc;
    rep->bend_out = mean_abs_interior(emb, a);
    if ((rc = es_dihedral_angles(ctx, mesh, prior_xyz, a)) != ES_OK) return rc;
    rep->bend_prior = mean_abs_interior(emb, a);
    rep->bend_ratio = rep->bend_prior > 0 ? rep->bend_out / rep->bend_prior : NAN;
    if ((rc = es_edge_lengths(ctx, mesh, xyz, emb->lpath)) != ES_OK) return rc;
    for (int64_t e = 0; e < ne; e++) s1 += emb->lpath[e];
    if ((rc = es_edge_lengths(ctx, mesh, prior_xyz, emb->lpath)) != ES_OK) return rc;
    for (int64_t e = 0; e < ne; e++) s0 += emb->lpath[e];
    for (int64_t i = 0; i < 3 * nv; i++) {
        p[i] = xyz[i];
        ps[i] = prior_xyz[i] * (s0 > 0 ? s1 / s0 : 1.0);
    }
    if ((rc = es_embed_align(ctx, nv, p, ps, emb->vweight, &rms)) != ES_OK) return rc;
    diag = es_bbox_diagonal(nv, ps);
    for (int64_t v = 0; v < nv; v++) {
        double d = 0;
        for (int i = 0; i < 3; i++) d += (p[3 * v + i] - ps[3 * v + i]) * (p[3 * v + i] - ps[3 * v + i]);
        d = diag > 0 ? sqrt(d) / diag : 0;
        emb->vdev[v] = d;
        ss += d * d;
        if (d > mx) mx = d;
    }
    rep->prior_rms = sqrt(ss / (double)(nv > 0 ? nv : 1));
    rep->prior_max = mx;
    rep->has_prior = 1;
    emb->have_deviation = 1;
    return ES_OK;
}

/* Whether es_embed_prior_solve below uses the bending term (open meshes,
 * or closed ones when asked); without it a closed mesh takes the dihedral
 * path from the prior's dihedrals. */
static int bends(const es_embedder *emb, const es_embed_opts *o)
{
    int open = es_mesh_boundary_loops(emb->mesh, NULL, NULL) > 0;
    return o->prior_mu > 0 && (open || o->prior_bend_closed);
}

int es__prior_solve_reads_dihedrals(es_embedder *emb, const double *target, double scale,
                                    const double *prior_xyz, const double *start,
                                    const es_embed_opts *opts)
{
    es_embed_opts dflt;
    if (!emb || !target || !prior_xyz) return 1;
    if (!opts) {
        es_embed_opts_init(&dflt);
        opts = &dflt;
    }
    if (!bends(emb, opts) || opts->solver == ES_EMBED_SOLVER_LM || es__polish_allowed(emb, opts))
        return 1;
    return es__start_beyond(emb, target, scale, start ? start : prior_xyz,
                            opts->prior_start_max_rms);
}

int es__prior_solve_reads_span(const es_embedder *emb, const es_embed_opts *opts)
{
    es_embed_opts dflt;
    if (!emb) return 1;
    if (!opts) {
        es_embed_opts_init(&dflt);
        opts = &dflt;
    }
    return !bends(emb, opts) && opts->crease_mu > 0 && opts->crease_margin >= 0;
}

es_status es_embed_prior_solve(es_ctx *ctx, es_embedder *emb, const double *target, double scale,
                               const es_embed_prior *prior, const es_embed_opts *opts, double *xyz,
                               es_embed_report *report)
{
    es_embed_opts dflt;
    es_embed_report rep;
    es__bend_prior bp;
    es__solve_ext ext;
    double sum = 0, f;
    int bend;
    es_status rc;
    if (!emb) ES_FAIL(ctx, ES_EINVAL, "embed: no embedder");
    if (!prior || !prior->xyz) ES_FAIL(ctx, ES_EINVAL, "embed: the prior's positions are required");
    if (prior->xyz == xyz) ES_FAIL(ctx, ES_EINVAL, "embed: the prior's positions are the output array");
    if (prior->start == xyz) ES_FAIL(ctx, ES_EINVAL, "embed: the start positions are the output array");
    if (!target) ES_FAIL(ctx, ES_EINVAL, "embed: NULL target");
    if (!opts) {
        es_embed_opts_init(&dflt);
        opts = &dflt;
    }
    emb->have_deviation = 0;
    if ((rc = prior_work(emb)) != ES_OK) return es__fail(ctx, rc, "%s", es_ctx_errmsg(emb->ctx));
    for (int64_t i = 0; i < 3 * emb->nv; i++)
        if (!isfinite(prior->xyz[i]))
            ES_FAIL(ctx, ES_EINVAL, "embed: the prior's position of vertex %lld is not finite",
                    (long long)(i / 3));
    for (int64_t i = 0; prior->start && i < 3 * emb->nv; i++)
        if (!isfinite(prior->start[i]))
            ES_FAIL(ctx, ES_EINVAL, "embed: the start position of vertex %lld is not finite",
                    (long long)(i / 3));
    if (prior->alpha) {
        for (int64_t e = 0; e < emb->ne; e++) {
            if (!isfinite(prior->alpha[e]))
                ES_FAIL(ctx, ES_EINVAL, "embed: the prior's dihedral of edge %lld is not finite",
                        (long long)e);
            emb->prior_alpha[e] = prior->alpha[e];
        }
    } else if ((rc = es_dihedral_angles(ctx, emb->mesh, prior->xyz, emb->prior_alpha)) != ES_OK) {
        return rc;
    }
    /* the edge weights from the target lengths at the embedding's scale */
    for (int64_t e = 0; e < emb->ne; e++) sum += target[e];
    f = scale > 0 && sum > 0 ? scale / sum : 1.0;
    for (int64_t e = 0; e < emb->ne; e++) emb->ltarget[e] = target[e] * f;
    es__bend_weights(emb, emb->ltarget, prior->sd, opts->prior_sd_floor, emb->omega);
    bend = bends(emb, opts);
    bp = (es__bend_prior){.alpha = emb->prior_alpha, .omega = emb->omega, .flap = emb->flap};
    es__bend_schedule(&bp, opts->prior_mu, opts->prior_decay, opts->prior_mu * opts->prior_mu_floor,
                      opts);
    memset(&ext, 0, sizeof ext);
    ext.bp = bend ? &bp : NULL;
    /* a closed mesh without the term: interpolation, whose refinement
     * carries the crease guard as es_interp_embed's does (crease_guard.c),
     * its band from the rows' span */
    if (!bend && ((prior->span_lo && prior->span_hi) || prior->sd) && opts->crease_mu > 0 &&
        opts->crease_margin >= 0) {
        if ((rc = es__crease_guard_prior(emb, emb->prior_alpha, prior->span_lo, prior->span_hi,
                                         prior->sd, emb->ltarget, opts, &bp)) != ES_OK)
            return es__fail(ctx, rc, "%s", es_ctx_errmsg(emb->ctx));
        ext.bp = &bp;
    }
    /* a closed mesh without the term: the dihedral path from the prior's
     * dihedrals, which is what interpolation does */
    ext.start_xyz = bend ? (prior->start ? prior->start : prior->xyz) : NULL;
    ext.warm = bend && prior->start;
    ext.start_auto = 1;
    ext.start_max_rms = opts->prior_start_max_rms;
    ext.align_ref = prior->xyz;
    if ((rc = es__embed_solve_ext(ctx, emb, target, scale, emb->prior_alpha, &ext, opts, xyz,
                                  &rep)) != ES_OK)
        return rc;
    if ((rc = shape_quality(emb->ctx, emb, xyz, prior->xyz, &rep)) != ES_OK)
        return es__fail(ctx, rc, "%s", es_ctx_errmsg(emb->ctx));
    if (report) *report = rep;
    return ES_OK;
}
