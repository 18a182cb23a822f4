/* lib/embed/embed_pkg.h — what the files of lib/embed share: the es_embedder
 * object (its sparse matrices, factors and work buffers, on lib/sparse's
 * solver service), the linear solves (linsolve.c), the four stages
 * (stage_*.c) that solve.c drives, and the vertex-figure and rotation
 * helpers (closure.c, align.c). Never installed.
 *
 * 3 x 3 matrices here are row-major double[9] (m[3*i + j]); they never
 * leave these files.
 */
#ifndef EDGESPACE_EMBED_PKG_H
#define EDGESPACE_EMBED_PKG_H

#ifndef ES_MODULE_EMBED
#error "embed/embed_pkg.h is private to lib/embed/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "edgespace/es_embed.h"
#include "edgespace/es_mesh.h"
#include "sparse/sparse_private.h"

/* ---- limited-memory BFGS (lbfgs.c) -------------------------------------- */

/* The two-loop recursion of L-BFGS (Nocedal 1980) with a caller's initial
 * inverse Hessian: the m latest pairs s = x+ - x, y = g+ - g. */
#define ES__LBFGS_MAX 16
typedef struct es__lbfgs {
    int64_t n;
    int m, count, head;
    double *mem, *s, *y, rho[ES__LBFGS_MAX], alpha[ES__LBFGS_MAX];
} es__lbfgs;
es_status es__lbfgs_init(es_ctx *ctx, es__lbfgs *lb, int64_t n, int m);
void es__lbfgs_free(es_ctx *ctx, es__lbfgs *lb);
void es__lbfgs_reset(es__lbfgs *lb);
/* First loop: q = g reduced by the pairs, in place. */
void es__lbfgs_first(es__lbfgs *lb, double *q);
/* Second loop: d = H0 q (given) corrected by the pairs, in place. */
void es__lbfgs_second(es__lbfgs *lb, double *d);
/* Keep the pair (x+ - x, g+ - g) if its curvature is positive. */
void es__lbfgs_push(es__lbfgs *lb, const double *x0, const double *x1, const double *g0,
                    const double *g1);

/* ---- the embedder (embedder.c) ------------------------------------------ */

/* Everything here is sized and, for the sparse matrices, patterned and
 * analysed once per topology by es_embedder_new; a solve only writes
 * values. */
struct es_embedder {
    es_ctx *ctx;
    const es_mesh *mesh;
    int64_t nv, ne, nf, maxk, nint;
    const int64_t *off, *sv, *se, *sf, *edges, *ef;
    const uint8_t *vb, *eb;
    int64_t *slot_corner;   /* 2E: corner of the slot's face at the slot's vertex */
    int64_t *edge_slot;     /* 2E: slot of e in the star of edges[2e], of edges[2e+1] */
    uint8_t *pinned;        /* V: lowest vertex of its component */
    double *vweight;        /* V: 1 for vertices in a face, else 0 */
    int64_t *rank, *nlow;   /* H1's pattern bookkeeping (see es__pos_off) */
    /* H3 is stored lower-triangular in the fill-reducing vertex order, so
     * that the factorization takes it as it is (no permuted transpose per
     * factorization, which cost ~7 % of each and a fresh allocation):
     * perm[j] is the vertex in block position j, pinv its inverse; the
     * slots of H3's entries are es__h3_off / es__h3_diag (embedder.c). */
    int64_t *perm, *pinv;   /* V each */
    int64_t *eslot;         /* 3E: slot of (row block 0, column c) of edge e's block */
    uint8_t *eswap;         /* E: 1 if edge e's first vertex is its block's row vertex */
    int64_t *vslot;         /* 3V: slot of the diagonal entry of column c of v's block */
    int cg_lag_ok;          /* stage 4 tries CG on a factor at most this many iterations
                               old (stage_refine.c) */
    /* closure variables */
    int64_t nvar, *var, *amap_off, *amap, *adiag;
    es__sparse *sp;         /* the solver workspace of all of them */
    es__sparse_mat *H3, *H1, *HA;
    es__sparse_factor *L3, *L1, *LA;
    es__sparse_dense *B3, *B1, *BA;
    es__sparse_solution sol;   /* of the solves with L3, L1, LA */
    /* work, sized once */
    double *ang, *theta, *C, *G, *len, *alpha, *alpha_try, *alpha_keep, *xyz, *xyz_try, *xyz_best;
    double *init_copy;   /* init_xyz when the caller passes the output array itself */
    int64_t progress_total; /* progress steps of the solve running (0: none) */
    double *ltarget, *lpath, *res, *grad, *diag, *pcg, *jw, *fanwork, *fanr, *fanth, *fanal, *vclos, *verr;
    int have_vertex_results;
    /* the bending prior (bending.c, prior.c), made on the first prior solve */
    int64_t *flap;          /* 6E: c, d, edges ac, bc, ad, bd of each interior edge's faces */
    double *omega, *prior_alpha, *vdev;   /* E, E, V (vdev: distance from the prior) */
    double *band_lo, *band_hi;   /* E, E: the crease guard's band (crease_guard.c) */
    int have_deviation;
    int64_t nfactor;        /* numeric factorizations in the last solve */
    /* the local-global solve (local_global.c), made on its first use: the
     * weighted Laplacian A1 in H1's pattern and its factor F1 (H1's order),
     * the edge weights, the rest triangles of the current target, and work */
    es__sparse_mat *A1;
    es__sparse_factor *F1;
    es__sparse_dense *LB;
    es__sparse_solution lg_sol;
    double *lg_w, *lg_rest, *lg_work, lg_eps;
    double *lg_wf;         /* the weights F1 was factored with */
    int lg_have_factor;    /* F1 holds a numeric factor of A1 with lg_wf */
    es__lbfgs lg_hist;
};

/* What es__embedder_need makes on first use (embedder.c). */
#define ES__NEED_H3 1u          /* H3, its analysis and B3: stages 2 and 4 */
#define ES__NEED_CLOSURE 2u     /* HA, its analysis and BA: stage 1 */
#define ES__NEED_POSITIONS 4u   /* the position Laplacian's factor and B1: stage 3 */
es_status es__embedder_need(es_embedder *emb, unsigned what);

/* Slot in H3->x of H[3a + p, 3b + q], (a, b) = edge e's vertices (a < b),
 * and of H[3v + r, 3v + c] (either triangle). */
static inline int64_t es__h3_off(const es_embedder *emb, int64_t e, int p, int q)
{
    return emb->eswap[e] ? emb->eslot[3 * e + q] + p : emb->eslot[3 * e + p] + q;
}

static inline int64_t es__h3_diag(const es_embedder *emb, int64_t v, int r, int c)
{
    return r < c ? emb->vslot[3 * v + r] + (c - r) : emb->vslot[3 * v + c] + (r - c);
}

/* x (3V, vertex order) to xp (H3's order) and back; ncol columns of
 * leading dimension 3V. */
void es__h3_permute(const es_embedder *emb, const double *x, double *xp, int ncol);
void es__h3_unpermute(const es_embedder *emb, const double *xp, double *x, int ncol);

/* Value slots of the upper-triangular pattern of the V x V vertex
 * adjacency H1 (bs = 1) that embedder.c builds, cp its column pointers:
 * entry (r, c) of the block of edge e = (a, b), a < b, in column block b,
 * and entry (r, c) of the diagonal block of v. Edges are sorted by (min,
 * max), so rank[e] is the position of a among b's lower neighbours and
 * nlow[v] their count. */
static inline int64_t es__pos_off(const int64_t *cp, int bs, const int64_t *rank, int64_t e,
                                  int64_t b, int r, int c)
{
    return cp[bs * b + c] + bs * rank[e] + r;
}

static inline int64_t es__pos_diag(const int64_t *cp, int bs, const int64_t *nlow, int64_t v,
                                   int r, int c)
{
    return cp[bs * v + c] + bs * nlow[v] + r;
}

/* ---- linear solves (linsolve.c) ---------------------------------------- */

/* Translate the status of emb->sp: ES_OK for success and the soft
 * statuses (not positive definite, tiny diagonal), else the code with a
 * message naming `what`. */
es_status es__solver_check(es_embedder *emb, const char *what);

/* Factorize A and solve A X = B (its first ncol columns) into emb->sol.
 * Returns 1 if A is not positive definite (nothing solved), 0 on success,
 * -1 on a solver failure (message set). */
int es__factor_solve(es_embedder *emb, es__sparse_mat *A, es__sparse_factor *L,
                     es__sparse_dense *B, int64_t ncol);

/* a . b over n entries. */
double es__dot(const double *a, const double *b, int64_t n);

/* Solve A d = b by conjugate gradients preconditioned with the factor Lf
 * of an earlier A (B: a dense of A's size for the preconditioner's
 * right-hand side). Returns the iterations used, or -1 if the relative
 * residual did not reach eta within max_it. */
int es__lagged_pcg(es_embedder *emb, const es__sparse_mat *A, es__sparse_factor *Lf,
                   es__sparse_dense *B, const double *b, double *d, double eta, int max_it);

/* ---- the stages (stage_*.c), driven by solve.c ------------------------- */

/* Closure energy (eq. 3) of dihedrals alpha with the corner angles in
 * emb->theta; residuals to emb->res, with_jac: Jacobian blocks to emb->jw;
 * vclos (V, may be NULL): each vertex's energy. */
double es__closure_eval(es_embedder *emb, const double *alpha, int with_jac, double *vclos);

/* Stage 1: up to max_iter Levenberg-Marquardt iterations on the closure
 * residuals, alpha in place. *e_out: the final energy; *iters grows by the
 * iterations run; *lambda_io carries the damping between calls. */
es_status es__stage_dihedrals(es_embedder *emb, const es_embed_opts *o, int max_iter,
                              double *alpha, double *e_out, int64_t *iters, double *lambda_io);

/* Stage 2: the walk's frames from dihedrals alpha (emb->C), then the
 * vertex frames (emb->G) by least squares, each projected onto the nearest
 * rotation. */
es_status es__stage_frames(es_embedder *emb, const double *alpha);

/* Stage 3: positions xyz (3 x V) from the frames and edge lengths len. */
es_status es__stage_positions(es_embedder *emb, const double *len, double *xyz);

/* The bending prior's term of stage 4 (bending.c):
 *   mu * sum_e omega_e wrap(alpha_e(x) - alpha_prior_e)^2
 * over interior edges, wrap to (-pi, pi]. Its Gauss-Newton matrix couples
 * the four vertices a, b, c, d of the edge's two faces; (c, d) is no mesh
 * edge, so its block is left out and the (c, c) and (d, d) blocks are
 * doubled instead: g g^T + u u^T with u = (0, 0, g_c, -g_d) is positive
 * semi-definite, bounds g g^T from above, and fits the vertex-adjacency
 * pattern the embedder analysed once. */
typedef struct es__bend_prior {
    const double *alpha;   /* E: prior dihedrals (compared modulo 2 pi); with hi, the
                              lower ends of a band */
    const double *hi;      /* NULL, or E: the band's upper ends. Then the term is one-
                              sided, mu sum_e omega_e dist(alpha_e(x), [alpha_e, hi_e])^2
                              (no wrap): zero inside the band, so it only holds
                              bending the band does not allow (the crease guard of
                              es_interp_embed) */
    const double *omega;   /* E: per-edge weights >= 0 (0: not in the term) */
    const int64_t *flap;   /* 6E (embedder's flap) */
    /* The weight schedule, set once by es__bend_schedule and stepped only
     * by the functions below it (bending.c): */
    double mu;             /* weight of the term now */
    double decay;          /* mu factor per LM iteration (1: constant) ... */
    double mu_min;         /* ... down to this weight, where it holds */
    double mu_exact;       /* held while an exactly realizable target finishes */
    double mu_realize;     /* held in the polish of a target no mesh has */
} es__bend_prior;

/* The schedule of bp's weight, in one place: first, times decay per
 * iteration of a refinement, down to last; the two held weights from the
 * options (4e-4 x and realize_bend x prior_mu: solve.c says why). */
void es__bend_schedule(es__bend_prior *bp, double first, double decay, double last,
                       const es_embed_opts *o);
/* Whether bp's weight still decays (a refinement then re-evaluates its
 * cost every iteration). */
int es__bend_annealing(const es__bend_prior *bp);
/* One decay step of bp's weight; returns es__bend_annealing afterwards. */
int es__bend_anneal(es__bend_prior *bp);
/* A copy of bp whose weight is held at mu. */
es__bend_prior es__bend_held(const es__bend_prior *bp, double mu);

/* Signed bending angle (es_geom.h convention) of edge (a, b), c the third
 * vertex of the face holding a->b and d that of the face holding b->a, and
 * its gradient g (12: d/da, d/db, d/dc, d/dd). Returns 0, or -1 on a
 * degenerate flap (g zero). */
int es__dihedral_grad(const double *pa, const double *pb, const double *pc, const double *pd,
                      double *alpha, double *g);
/* The term's value at xyz. */
double es__bend_cost(const es_embedder *emb, const es__bend_prior *bp, const double *xyz);
/* Add the term's half-gradient to g and its Gauss-Newton blocks to emb->H3. */
void es__bend_assemble(es_embedder *emb, const double *xyz, const es__bend_prior *bp, double *g);
/* emb->flap, made once per embedder. */
es_status es__bend_flaps(es_embedder *emb);
/* The term's work, made on its first use in an embedder: the flaps, and
 * emb->omega, prior_alpha, band_lo and band_hi. */
es_status es__bend_work(es_embedder *emb);

/* The crease guard (crease_guard.c): a band term of weight o->crease_mu
 * over the band of each interior edge, widened by o->crease_margin on both
 * sides, in
 * emb->band_lo / band_hi, with emb->omega from the target lengths len.
 * From the inputs: the span of the bending angles of the inputs with a
 * weight (not 0) and of the interpolated angles alpha. From a prior: the
 * rows' span (span_lo, span_hi) and alpha, or without it alpha +- 3 sd
 * (the rows' spread). */
es_status es__crease_guard_inputs(es_embedder *emb, int64_t nin, const double *const *xyz,
                                  const double *w, const double *alpha, const double *len,
                                  const es_embed_opts *o, es__bend_prior *guard);
es_status es__crease_guard_prior(es_embedder *emb, const double *alpha, const double *span_lo,
                                 const double *span_hi, const double *sd, const double *len,
                                 const es_embed_opts *o, es__bend_prior *guard);
/* omega (E): the discrete-shells weight 3 l_e^2 / (A_f + A_g) from lengths L
 * normalized to mean 1, divided by 1 + (sd_e / s0)^2 when sd is given, s0 =
 * sd_floor x the median sd over interior edges. */
void es__bend_weights(const es_embedder *emb, const double *L, const double *sd,
                      double sd_floor, double *omega);

/* When stage 4 stops (es_embed_opts): after max_iter iterations; when the
 * cost fell by less than rtol per iteration over 3 (once the bending
 * weight holds); when the RMS relative edge error is below tol; and when
 * the edge lengths meet the accuracy asked for, RMS ratio <= rms_tol and
 * max relative error <= max_tol (both > 0; 0 turns that rule off). */
typedef struct es__refine_opts {
    int max_iter;
    double rtol, tol, rms_tol, max_tol;
    int verbose;
} es__refine_opts;

/* The refinement's rules from the embedding options. */
es__refine_opts es__refine_opts_from(const es_embed_opts *o);

/* Stage 4: Levenberg-Marquardt on the relative edge-length residuals
 * against L (plus the bending prior's term when bp is given), xyz in place;
 * *iters grows by the iterations run. */
es_status es__stage_refine(es_embedder *emb, const double *L, double *xyz, es__bend_prior *bp,
                           const es__refine_opts *ro, int64_t *iters);

/* ---- the local-global solve (local_global.c) ---------------------------- */

/* When it stops: the edge lengths meet both tolerances (0: that rule off),
 * the energy falls by less than rtol of itself per iteration over the last
 * five, or after max_iter iterations. */
typedef struct es__lg_opts {
    int max_iter, history;
    double rms_tol, max_tol, rtol;
    int verbose;
    /* > 0: keep the factor of an earlier solve while no edge's weight moved
     * more than this fraction from the weights it was made with (a warm
     * start: the next frame of a walk or slider); 0: factor every solve */
    double factor_reuse;
} es__lg_opts;

typedef struct es__lg_result {
    int64_t iters;
    int met;               /* 1: stopped because the tolerances were met */
    double energy, rms, max;
} es__lg_result;

/* Positions xyz (3 x V, in place: the start) whose every face is as near
 * congruent to the triangle of its target lengths L (E) as local-global
 * iterations get in the rules of o. */
es_status es__lg_solve(es_embedder *emb, const double *L, double *xyz, const es__lg_opts *o,
                       es__lg_result *res);

/* RMS ratio and max relative error of positions against lengths L, as
 * es_embed_length_error measures them (normalize 0) without its
 * allocation and percentile (solve.c). */
void es__length_fit(const es_embedder *emb, const double *xyz, const double *L, double *rms,
                    double *mx);

/* ---- lengths that form triangles (lengths_project.c) -------------------- */

/* The lengths nearest to L (E; relative least squares) whose every face
 * satisfies the triangle inequality with margin: the longest edge at most
 * (1 - margin) times the sum of the other two. Writes them to out (may be
 * L); returns the number of lengths changed, and the RMS and largest
 * relative change. */
int64_t es__lengths_project(es_embedder *emb, const double *L, double margin, double *out,
                            double *rms_change, double *max_change);

/* What a prior solve asks of the driver (solve.c) beyond es_embed_solve. */
typedef struct es__solve_ext {
    const double *start_xyz;  /* refine from these positions (scaled to the target's
                                 sum) instead of stages 1-3 */
    int start_auto;           /* with init_alpha: also stages 2-3 from it when the
                                 positions are more than start_max_rms off the
                                 lengths, and keep the closer start */
    double start_max_rms;
    const double *align_ref;  /* align the output to this (3 x V) */
    int warm;                 /* start_xyz is an earlier solve's output corrected (a walk,
                                 a slider): the solver may keep that solve's factor */
    es__bend_prior *bp;       /* NULL: lengths only */
} es__solve_ext;

/* es_embed_solve (its stages from init_alpha, or init_xyz, as there) with
 * the bending term bp in the refinement (NULL: lengths only). */
es_status es__embed_solve_bend(es_ctx *ctx, es_embedder *emb, const double *target, double scale,
                               const double *init_alpha, const double *init_xyz,
                               const double *align_ref, es__bend_prior *bp,
                               const es_embed_opts *opts, double *xyz, es_embed_report *report);

/* es_embed_solve with the extensions; start_xyz and align_ref must not
 * alias xyz. */
es_status es__embed_solve_ext(es_ctx *ctx, es_embedder *emb, const double *target,
                              double scale, const double *init_alpha, const es__solve_ext *ext,
                              const es_embed_opts *opts, double *xyz, es_embed_report *report);

/* Whether the Levenberg-Marquardt polish may run after the local-global
 * iterations: asked for, and the mesh below polish_max_verts. */
int es__polish_allowed(const es_embedder *emb, const es_embed_opts *o);

/* Whether `start`, scaled to the target's sum at `scale` as the solve
 * scales it, is more than max_rms (RMS ratio) off the target's lengths:
 * then a solve from positions with start_auto tries stages 2-3 from the
 * dihedrals too (positions_start). Uses emb->ltarget, lpath and xyz_try. */
int es__start_beyond(es_embedder *emb, const double *target, double scale, const double *start,
                     double max_rms);

/* ---- vertex figures (closure.c) ----------------------------------------- */

/* Corner angles of all faces from lengths (3 x F, angle at corner k of
 * face f in ang[3f + k]) by Kahan's needle-stable formula ("Miscalculating
 * area and angles of a needle-like triangle", 2014, sec. 12). A face that
 * violates the triangle inequality by more than rtol * perimeter counts in
 * the return value; its angles are clamped to 0 / pi. */
int64_t es__corner_angles(const es_mesh *mesh, const double *len, double rtol, double *ang);

/* Index into the 3 x F corner array of the corner of v in star slot i
 * (the slot's face), or -1 for the open slot of a boundary vertex. */
int64_t es__slot_corner(const es_mesh *mesh, int64_t v, int64_t slot);

/* Walk of one vertex figure. k spokes, theta[j] the corner angle of fan face
 * j, alpha[j] the dihedral of spoke j (alpha[0] unused at a boundary vertex),
 * nface = k (interior) or k - 1 (boundary). C (9 k): C_j, the frame with x
 * along spoke j and z the normal of face j (face j-1 for the last spoke of a
 * boundary vertex), in the vertex frame C_0 = I. Returns P = C_k (interior)
 * in P (may be NULL). */
void es__fan_frames(int64_t k, int64_t nface, const double *theta, const double *alpha,
                    double *C, double *P);

/* Closure residual r = vec(P - I) (9, row-major) of an interior vertex,
 * and when J != NULL its derivatives, J[9 j + m] = d r_m / d alpha_j.
 * work: 18 (2k + 1) doubles. Returns ||r||^2. */
double es__fan_closure(int64_t k, const double *theta, const double *alpha, double *r,
                       double *J, double *work);

/* m = m Z(t) (eq. 6's rotation about z). */
void es__mat3_right_z(double *m, double t);

/* ---- rotations (align.c) ------------------------------------------------ */

static inline void es__mat3_identity(double *m)
{
    for (int i = 0; i < 9; i++) m[i] = (i % 4 == 0) ? 1.0 : 0.0;
}

/* out = a b (3 x 3 row-major); out may not alias. */
void es__mat3_mul(const double *a, const double *b, double *out);
/* out = a b^T. */
void es__mat3_mul_bt(const double *a, const double *b, double *out);
/* Nearest proper rotation to m (in place); returns 0, or -1 if m is
 * degenerate (then m is set to I). */
int es__mat3_nearest_rotation(double *m);

#endif
