/* lib/embed/paper.c — the published pipeline of edge-length-interpolation
 * Section 2, as published, beside the project's embedding for comparison
 * (es_embed_paper_solve, es_embed.h):
 *  - stage 1: the closure energy E(alpha) (eq. 3) minimized over the
 *    dihedrals by L-BFGS from the caller's initial dihedrals (the paper:
 *    SciPy's fmin_l_bfgs_b from the inputs' averaged dihedrals). SciPy's
 *    defaults are the settings (the paper names none): m = 10 correction
 *    pairs, stop when the energy falls by less than factr = 1e7 machine
 *    epsilons relative to max(|E|, 1) in an iteration, or when the largest
 *    |dE/dalpha| is below pgtol = 1e-5, or after 15000 iterations or
 *    evaluations; a line search for the strong Wolfe conditions with
 *    c1 = 1e-3 and c2 = 0.9 (those of L-BFGS-B's dcsrch), here by
 *    bracketing and zooming with safeguarded cubic steps (Nocedal and
 *    Wright 2006, Alg. 3.5-3.6), the first step 1 / |g| as L-BFGS-B takes it;
 *  - stages 2-3: frames by least squares on G_v M_vu = G_u with one frame
 *    fixed, orthonormalized by SVD, then positions by least squares: the
 *    embedder's own stages 2-3, which are the paper's (Lipman et al. 2005),
 *    run through es_embed_solve with its stage 1 and refinement switched
 *    off.
 * Nothing else: no refinement of the positions against the lengths (the
 * published pipeline has none), no decision whether stage 1 helps. Only
 * the embedder's public API is used, so its internals may change freely.
 */
#include "core/core_private.h"
#include "edgespace/es_embed.h"
#include "edgespace/es_geom.h"

#include <float.h>
#include <math.h>

void es_embed_paper_opts_init(es_embed_paper_opts *o)
{
    o->history = 10;
    o->max_iter = 15000;
    o->factr = 1e7;
    o->pgtol = 1e-5;
    es_embed_opts_init(&o->embed);
}

/* ---- L-BFGS on the closure energy ---------------------------------------------- */

typedef struct lbfgs {
    es_ctx *ctx;
    const es_mesh *mesh;
    const double *len;        /* target lengths */
    int64_t n;                /* variables: every edge's dihedral (boundary ones have
                                 gradient 0 and never move) */
    int64_t nfev, max_fev;
    double *x, *g, *d, *xt, *gt;   /* iterate, its gradient, direction, trial point */
} lbfgs;

static double dot(const double *a, const double *b, int64_t n)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* E and its gradient at x + a d, into xt and gt; *dphi = gt . d. */
static es_status trial(lbfgs *L, double a, double *f, double *dphi)
{
    es_status rc;
    for (int64_t i = 0; i < L->n; i++) L->xt[i] = L->x[i] + a * L->d[i];
    rc = es_embed_closure(L->ctx, L->mesh, L->len, L->xt, f, L->gt, NULL);
    L->nfev++;
    *dphi = dot(L->gt, L->d, L->n);
    return rc;
}

/* Minimizer of the cubic through (a, fa, da) and (b, fb, db), kept inside
 * the middle 80 % of [a, b] (else the midpoint). */
static double cubic_step(double a, double fa, double da, double b, double fb, double db)
{
    double lo = fmin(a, b), hi = fmax(a, b), w = hi - lo, t;
    double d1 = da + db - 3 * (fa - fb) / (a - b), r = d1 * d1 - da * db;
    if (r >= 0) {
        double d2 = (b > a ? 1 : -1) * sqrt(r);
        t = b - (b - a) * (db + d2 - d1) / (db - da + 2 * d2);
        if (isfinite(t) && t > lo + 0.1 * w && t < hi - 0.1 * w) return t;
    }
    return 0.5 * (a + b);
}

/* A step a along d meeting the strong Wolfe conditions (c1 = 1e-3, c2 =
 * 0.9); on return xt, gt, *fa hold the accepted point. 1 if found, 0 if the
 * search gave up (then the caller stops, as L-BFGS-B does). */
static int line_search(lbfgs *L, double f0, double d0, double a1, double *fa, double *step,
                       es_status *rc)
{
    const double c1 = 1e-3, c2 = 0.9;
    double a_lo = 0, f_lo = f0, d_lo = d0, a_hi = 0, f_hi = 0, d_hi = 0, a = a1, f, df;
    int bracketed = 0;
    for (int i = 0; i < 20; i++) {
        if ((*rc = trial(L, a, &f, &df)) != ES_OK) return 0;
        if (!isfinite(f)) {
            a_hi = a, f_hi = INFINITY, d_hi = 0, bracketed = 1;
            break;
        }
        if (f > f0 + c1 * a * d0 || (i > 0 && f >= f_lo)) {
            a_hi = a, f_hi = f, d_hi = df, bracketed = 1;
            break;
        }
        if (fabs(df) <= -c2 * d0) goto accept;
        if (df >= 0) {
            a_hi = a_lo, f_hi = f_lo, d_hi = d_lo;
            a_lo = a, f_lo = f, d_lo = df, bracketed = 1;
            break;
        }
        a_lo = a, f_lo = f, d_lo = df;
        a *= 4;
    }
    if (!bracketed) goto fallback;
    for (int i = 0; i < 30; i++) {   /* zoom */
        a = isfinite(f_hi) ? cubic_step(a_lo, f_lo, d_lo, a_hi, f_hi, d_hi)
                           : 0.5 * (a_lo + a_hi);
        if ((*rc = trial(L, a, &f, &df)) != ES_OK) return 0;
        if (!isfinite(f) || f > f0 + c1 * a * d0 || f >= f_lo) {
            a_hi = a, f_hi = f, d_hi = df;
        } else {
            if (fabs(df) <= -c2 * d0) goto accept;
            if (df * (a_hi - a_lo) >= 0) a_hi = a_lo, f_hi = f_lo, d_hi = d_lo;
            a_lo = a, f_lo = f, d_lo = df;
        }
        if (fabs(a_hi - a_lo) <= 1e-14 * fmax(a_lo, a_hi)) break;
    }
fallback:
    /* no Wolfe point: the best decrease seen, if any */
    if (a_lo > 0 && f_lo < f0) {
        if ((*rc = trial(L, a_lo, &f, &df)) != ES_OK) return 0;
        a = a_lo;
        goto accept;
    }
    return 0;
accept:
    *fa = f;
    *step = a;
    return 1;
}

/* Minimize E from L->x (in place). *f0 gets E at the start, *f1 at the end,
 * *iters the iterations. */
static es_status run_lbfgs(lbfgs *L, const es_embed_paper_opts *o, double *f0, double *f1,
                           int64_t *iters)
{
    int64_t n = L->n, m = o->history, k = 0, kept = 0, head = 0;
    double *s = es__alloc_array(L->ctx, 2 * m * n + 2 * m, sizeof *s);
    double *y = s + m * n, *rho = y + m * n, *alf = rho + m, f;
    es_status rc = ES_OK;
    if (!s) return ES_ENOMEM;
    if ((rc = es_embed_closure(L->ctx, L->mesh, L->len, L->x, &f, L->g, NULL)) != ES_OK)
        goto done;
    L->nfev = 1;
    *f0 = f;
    while (k < o->max_iter && L->nfev < L->max_fev) {
        double gmax = 0, fnew, step, d0, a1;
        for (int64_t i = 0; i < n; i++) gmax = fmax(gmax, fabs(L->g[i]));
        if (gmax <= o->pgtol) break;
        /* two-loop recursion (Nocedal 1980) */
        for (int64_t i = 0; i < n; i++) L->d[i] = -L->g[i];
        for (int64_t j = 0; j < kept; j++) {
            int64_t c = (head - 1 - j + m) % m;
            alf[c] = rho[c] * dot(s + c * n, L->d, n);
            for (int64_t i = 0; i < n; i++) L->d[i] -= alf[c] * y[c * n + i];
        }
        if (kept) {
            int64_t c = (head - 1 + m) % m;
            double gam = 1.0 / (rho[c] * dot(y + c * n, y + c * n, n));
            for (int64_t i = 0; i < n; i++) L->d[i] *= gam;
        }
        for (int64_t j = kept - 1; j >= 0; j--) {
            int64_t c = (head - 1 - j + m) % m;
            double b = rho[c] * dot(y + c * n, L->d, n);
            for (int64_t i = 0; i < n; i++) L->d[i] += (alf[c] - b) * s[c * n + i];
        }
        d0 = dot(L->g, L->d, n);
        if (!(d0 < 0)) {   /* not a descent direction: forget the curvature pairs */
            kept = 0;
            for (int64_t i = 0; i < n; i++) L->d[i] = -L->g[i];
            d0 = dot(L->g, L->d, n);
        }
        a1 = kept ? 1.0 : 1.0 / sqrt(dot(L->d, L->d, n));
        if (!line_search(L, f, d0, a1, &fnew, &step, &rc)) break;
        /* the new pair s = xt - x, y = gt - g */
        {
            double *sc = s + head * n, *yc = y + head * n, sy;
            for (int64_t i = 0; i < n; i++) {
                sc[i] = L->xt[i] - L->x[i];
                yc[i] = L->gt[i] - L->g[i];
            }
            sy = dot(sc, yc, n);
            if (sy > DBL_EPSILON * dot(yc, yc, n)) {
                rho[head] = 1.0 / sy;
                head = (head + 1) % m;
                if (kept < m) kept++;
            }
        }
        memcpy(L->x, L->xt, (size_t)n * sizeof *L->x);
        memcpy(L->g, L->gt, (size_t)n * sizeof *L->g);
        k++;
        es__progress(L->ctx, "embed --paper: stage 1 (L-BFGS)", k, o->max_iter);
        {
            double fold = f;
            f = fnew;
            if ((fold - f) / fmax(fmax(fabs(fold), fabs(f)), 1.0) <= o->factr * DBL_EPSILON)
                break;
        }
    }
    if (rc == ES_OK) es__progress(L->ctx, "embed --paper: stage 1 (L-BFGS)", 1, 1);
    *f1 = f;
    *iters = k;
done:
    es__free(L->ctx, s);
    return rc;
}

/* ---- the pipeline --------------------------------------------------------------- */

es_status es_embed_paper_solve(es_ctx *ctx, es_embedder *emb, const double *target,
                               double scale, const double *init_alpha, const double *init_xyz,
                               const es_embed_paper_opts *opts, double *xyz,
                               es_embed_report *report)
{
    es_embed_paper_opts dflt;
    es_embed_opts eo;
    es_embed_report rep;
    const es_mesh *mesh = emb ? es_embedder_mesh(emb) : NULL;
    lbfgs L;
    double f0 = 0, f1 = 0, t0 = es__seconds(), t_stage1, sum = 0, fs;
    int64_t ne, iters = 0;
    es_status rc;
    if (!opts) {
        es_embed_paper_opts_init(&dflt);
        opts = &dflt;
    }
    if (!emb || !target || !xyz) ES_FAIL(ctx, ES_EINVAL, "embed --paper: NULL argument");
    if (!init_alpha && !init_xyz)
        ES_FAIL(ctx, ES_EINVAL, "embed --paper: need initial dihedrals or initial positions");
    if (opts->history < 1 || opts->history > 1000 || opts->max_iter < 0 ||
        !(opts->factr >= 0) || !(opts->pgtol >= 0))
        ES_FAIL(ctx, ES_EINVAL, "embed --paper: L-BFGS settings out of range (history 1 .. "
                "1000, max_iter, factr and pgtol >= 0)");
    if (!(isfinite(scale) && scale >= 0))
        ES_FAIL(ctx, ES_EINVAL, "embed --paper: scale %g is not finite and >= 0", scale);
    ne = es_mesh_nedges(mesh);
    for (int64_t e = 0; e < ne; e++) {
        if (!(isfinite(target[e]) && target[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "embed --paper: target length of edge %lld is %g, not "
                    "finite and positive", (long long)e, target[e]);
        sum += target[e];
    }
    memset(&L, 0, sizeof L);
    L.ctx = ctx;
    L.mesh = mesh;
    L.n = ne;
    L.max_fev = opts->max_iter > 0 ? opts->max_iter : 1;
    L.x = es__alloc_array(ctx, 6 * ne, sizeof *L.x);
    if (!L.x) return ES_ENOMEM;
    L.g = L.x + ne, L.d = L.g + ne, L.xt = L.d + ne, L.gt = L.xt + ne;
    /* the closure energy is scale-free; the lengths at the embedding's scale */
    fs = scale > 0 ? scale / sum : 1.0;
    L.len = L.gt + ne;
    for (int64_t e = 0; e < ne; e++) L.gt[ne + e] = target[e] * fs;
    if (init_alpha) {
        const uint8_t *eb = es_mesh_edge_on_boundary(mesh);
        for (int64_t e = 0; e < ne; e++) {
            if (!eb[e] && !isfinite(init_alpha[e])) {
                es__free(ctx, L.x);
                ES_FAIL(ctx, ES_EINVAL, "embed --paper: initial dihedral of edge %lld is not "
                        "finite", (long long)e);
            }
            L.x[e] = eb[e] ? 0.0 : init_alpha[e];
        }
    } else if ((rc = es_dihedral_angles(ctx, mesh, init_xyz, L.x)) != ES_OK) {
        es__free(ctx, L.x);
        return rc;
    }
    rc = opts->max_iter > 0 ? run_lbfgs(&L, opts, &f0, &f1, &iters)
                            : es_embed_closure(ctx, mesh, L.len, L.x, &f0, NULL, NULL);
    if (opts->max_iter <= 0) f1 = f0;
    t_stage1 = es__seconds() - t0;
    /* stages 2-3 from the minimizer, nothing after them */
    eo = opts->embed;
    eo.dihedral_mode = ES_EMBED_DIHEDRAL_OFF;
    eo.refine_max_iter = 0;
    eo.continuation_steps = 0;
    eo.try_both = 0;
    eo.refine_rms_tol = eo.refine_max_tol = 0;
    if (rc == ES_OK)
        rc = es_embed_solve(ctx, emb, L.gt + ne, scale > 0 ? scale : sum, L.x, init_xyz, &eo,
                            xyz, &rep);
    es__free(ctx, L.x);
    if (rc != ES_OK) return rc;
    rep.closure_before = f0;
    rep.closure_stage1 = f1;
    rep.dihedral_iters = iters;
    rep.used_stage1 = 1;
    rep.t_dihedral = t_stage1;
    rep.t_total = es__seconds() - t0;
    if (report) *report = rep;
    return ES_OK;
}
