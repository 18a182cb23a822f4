/* lib/include/edgespace/es_embed.h — realize an edge-length vector as a mesh.
 *
 * Given a topology, target edge lengths and an initialization (dihedral
 * angles and/or vertex positions), compute vertex positions whose edge
 * lengths match the target as well as possible, plus a quality report.
 * Stages (Section 2 of edge-length-interpolation, with the changes below):
 *   1. dihedrals: Levenberg-Marquardt on the 9 closure residuals P_v - I of
 *      every interior vertex figure (eq. 1-2), sparse Cholesky (CHOLMOD);
 *   2. frames: sparse least squares on G_u = G_v R_vu, SVD-orthonormalized;
 *   3. positions: sparse least squares on x_u - x_v = G_v u_v;
 *   4. refinement: Levenberg-Marquardt on the relative edge-length residuals
 *      (|x_a - x_b| - l_e) / l_e in position space, with the Gauss-Newton
 *      matrix plus the curvature of the stretched edges' residuals (a
 *      projected Newton model: 5-6x lower RMS error than Gauss-Newton at
 *      equal iterations on the cat midpoint). Vertex closure does not
 *      fix the holonomy around holes and handles (oracle README, failure A)
 *      and leaves edges between two boundary vertices free (failure B);
 *      this stage closes both. Rigid motions (and, on open meshes, flexes)
 *      are held by the damping, so the result stays near the stage-3 mesh.
 * Optionally (continuation_steps > 0 with initial positions) stage 4 runs
 * along the path from the initial mesh's own lengths (which it realizes
 * exactly) to the target, warm-started step by step.
 * From positions (es_embed_prior_solve on open meshes: the prior's
 * realization, or a warm start) the solve is instead local-global
 * iterations on the triangles the target lengths make, with L-BFGS on a
 * factored V x V Laplacian (lib/embed/local_global.c), and stage 4 only
 * finishes where they did not meet the accuracy asked for (es_embed_opts:
 * solver, lg_*).
 *
 * Conventions are those of ../shared/oracle/embed (es_geom.h signs): the
 * angle alpha_e is the signed bending angle, alpha = 0 flat, < 0 convex;
 * boundary vertices carry no closure term and boundary edges no variable.
 * Frames: x along the spoke with the smallest edge id (a boundary vertex:
 * its first fan spoke), y in the plane of the triangle to its left; at the
 * lowest vertex of every component G = I and x = 0 (before alignment).
 *
 * An embedder is made once per topology: it holds the symbolic Cholesky
 * analyses (and the factor of the position Laplacian, which depends on the
 * topology only), and its work buffers, reused by every solve. It borrows
 * the mesh, which must outlive it. Not thread-safe: one per thread.
 */
#ifndef EDGESPACE_ES_EMBED_H
#define EDGESPACE_ES_EMBED_H

#include "es_core.h"
#include "es_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct es_embedder es_embedder;

typedef enum es_embed_dihedral_mode {
    ES_EMBED_DIHEDRAL_AUTO = 0, /* one stage-1 iteration decides: stage 1 goes on if it
                                   removed 99 % of the closure energy (incoherent, e.g.
                                   noisy, dihedrals), else its dihedrals are dropped */
    ES_EMBED_DIHEDRAL_ON,       /* always stage 1 (the paper) */
    ES_EMBED_DIHEDRAL_OFF       /* skip stage 1: stages 2-3 from the initial dihedrals */
} es_embed_dihedral_mode;

/* The solver of a solve that starts from positions (es_embed_prior_solve on
 * an open mesh, where the prior's realization is the start). */
typedef enum es_embed_solver {
    ES_EMBED_SOLVER_AUTO = 0,   /* local-global iterations (below) */
    ES_EMBED_SOLVER_LOCAL_GLOBAL,
    ES_EMBED_SOLVER_LM          /* Levenberg-Marquardt on the lengths with the bending
                                   prior (the solver before the local-global one: a
                                   3V x 3V factorization per iteration) */
} es_embed_solver;

typedef struct es_embed_opts {
    es_embed_dihedral_mode dihedral_mode;   /* default AUTO (see above) */
    int dihedral_max_iter;    /* stage 1 LM iterations; 0 skips stage 1 (default 30) */
    double dihedral_rtol;     /* stage 1 stops when E drops by less than this fraction
                                 per iteration, or E <= dihedral_tol * #interior verts
                                 (defaults 1e-4, 1e-24) */
    double dihedral_tol;
    int refine_max_iter;      /* stage 4 LM iterations per step; 0 skips (default 12;
                                 the notebooks use 60 where accuracy matters more
                                 than time) */
    double refine_rtol;       /* stage 4 stops when the cost dropped by less than this
                                 fraction per iteration over the last 3 iterations, or
                                 the RMS relative edge error is below refine_tol
                                 (defaults 1e-3, 1e-13) */
    double refine_tol;
    double refine_rms_tol;    /* stage 4 also stops as soon as the edge lengths meet both:
                                 RMS ratio <= refine_rms_tol and max relative error <=
                                 refine_max_tol (the report's rms_ratio and max_rel; a
                                 start that meets them is not refined at all). 0 in
                                 either: run to the other rules (defaults 0, 0) */
    double refine_max_tol;
    int continuation_steps;   /* > 0 and initial positions given: run stage 4 along the
                                 length path from the initial mesh in this many steps
                                 instead of stages 1-3 (default 0) */
    int try_both;             /* with initial positions and dihedrals: also run the
                                 continuation (or the dihedral path) and keep the better
                                 result by max relative edge error (default 0) */
    int align;                /* 1: rigidly align (Kabsch, proper rotation) the output to
                                 the initial positions, else to the mesh's reference
                                 positions if it has them (default 1); each connected
                                 component separately (lengths do not fix where the
                                 components lie relative to each other), and vertices in
                                 no face are put where the reference has them. Not
                                 aligned: those vertices are at the origin */
    double bad_face_rtol;     /* triangle-inequality tolerance of the report (1e-12) */
    double realized_rtol;     /* report.realized = max relative error <= this (1e-2) */
    int verbose;              /* 1: one note per iteration to the log callback (0) */
    /* es_embed_prior_solve only (measured on face-study; lib/embed/prior.c says how): */
    double prior_mu;          /* weight of the bending term relative to the length term at
                                 the first refinement iteration (default 2.5e-3: on
                                 face-study's PC +-2 sd points the largest that keeps the
                                 length RMS under 0.05 % and the smallest that keeps the
                                 bending under 1.1 x the prior's); 0: the prior only
                                 starts and frames the solve */
    double prior_decay;       /* mu factor per refinement iteration (default 0.8) ... */
    double prior_mu_floor;    /* ... down to this fraction of prior_mu, where it holds
                                 (default 0.07 = 0.8^12: 2.5e-3 to 1.7e-4 over the default
                                 12 iterations, then constant, however many follow): it
                                 never reaches 0 on an open mesh, whose flexes the lengths
                                 leave free and whose averaged noisy lengths only crumpling
                                 realizes exactly */
    double prior_sd_floor;    /* each edge's weight is divided by 1 + (sd_e / s0)^2, s0 =
                                 this x the median sd (the rows' disagreement; default 0.7;
                                 0: sd ignored) */
    double prior_start_max_rms; /* start from the prior's positions unless they are more
                                 than this RMS ratio off the lengths; then the closer of
                                 them and stages 2-3 on the prior's dihedrals (default
                                 0.04) */
    int prior_exact;          /* 1: the target is one real mesh's lengths (exactly
                                 realizable): after the run with the bending term, refine
                                 on (up to 3 x refine_max_iter) with the term held at 4e-4
                                 of prior_mu, so the lengths decide the last digits
                                 (default 0: averaged or extrapolated lengths, which only
                                 crumpling realizes exactly; es_study_embed sets it for a
                                 point that is one row or one mesh file) */
    int prior_bend_closed;    /* 1: the bending term on closed meshes too (default 0: a
                                 closed mesh is rigid for its lengths, which decide alone
                                 after the prior's start, as es_interp_embed does) */
    /* From positions (es_embed_prior_solve on open meshes): local-global
     * iterations on the triangles the target lengths make, with L-BFGS
     * (lib/embed/local_global.c), each a pass over the faces and one
     * back-substitution with a V x V factor (9.4K vertices: about 2.5 ms);
     * where they have not met the tolerances within lg_max_iter, the
     * Levenberg-Marquardt refinement (refine_max_iter, the prior's bending
     * term held at its last weight) finishes until it does: a Newton step
     * fixes the last length error with less bending than more local-global
     * iterations would. Measured on face-study in tools/bench/bench_walk.c
     * and tests/study/test_prior_faces.c. */
    es_embed_solver solver;   /* default AUTO (local-global, then the polish) */
    int lg_max_iter;          /* local-global iterations at most (default 40; exact
                                 targets, prior_exact, twice as many) */
    double lg_rms_tol;        /* the accuracy asked for: RMS ratio <= lg_rms_tol and max
                                 relative error <= lg_max_tol (defaults 5e-4, 1e-2; a
                                 third of each for an exact target) */
    double lg_max_tol;
    double lg_rtol;           /* local-global also stops when its energy falls by less
                                 than this fraction per iteration over five (1e-4) */
    int lg_history;           /* L-BFGS pairs kept (default 6) */
    int lg_polish;            /* where the local-global iterations did not meet the
                                 tolerances: Levenberg-Marquardt iterations at most
                                 (and at most refine_max_iter) toward them (default 4;
                                 0: local-global alone, es_embed_opts_fast) */
    int64_t polish_max_verts; /* meshes with this many vertices or more skip the polish
                                 (its 3V x 3V factorization then costs more than 25
                                 local-global iterations) and get lg_max_iter_large
                                 local-global iterations instead (default 50000; 0:
                                 the polish at every size) */
    int lg_max_iter_large;    /* those meshes' local-global iterations at most (70) */
    double realize_bend;      /* for such a target (no mesh has its lengths) the
                                 Levenberg-Marquardt finish always runs, with the prior's
                                 bending term held at realize_bend x prior_mu, so that the
                                 data's bending decides where the lengths cannot be met
                                 (default 3; 0: as for any target) */
    double realize_margin;    /* target lengths that break the triangle inequality on a
                                 face are replaced by the nearest lengths (relative least
                                 squares) whose every face has its longest edge at most
                                 1 - margin times the sum of the other two (default 0.01;
                                 < 0: embed them as they are); the report says how far */
    /* Interpolation's crease guard (lib/embed/crease_guard.c): es_interp_embed, and
     * es_embed_prior_solve on a closed mesh given the rows' span or spread (the
     * study's walk). Interpolated lengths realized without it fold across the
     * parts where the inputs differ most (the core paper's Fig. 4 cats: 4-13 %
     * of the edges bent past every input by 0.3 rad; with it 0.5-4.3 % at a
     * length RMS of 0.25-0.78 % instead of 0.06-0.20 %). */
    double crease_margin;     /* each interior edge may bend within the span of the blended
                                 inputs' (and the interpolated) bending angles widened by
                                 this many radians; the refinement pays crease_mu x the
                                 discrete-shells weight x the squared excess (default
                                 0.1) ... */
    double crease_mu;         /* ... (default 1e-3; more: fewer creases, more length error;
                                 0 or a margin < 0: no guard) */
    int blas_threads;         /* OpenBLAS threads during the solve, the caller's setting
                                 restored after; 0 leaves it alone (default 1: the
                                 factorizations' dense blocks are small, and 2 threads
                                 made embeddings 25-33 % slower on 2 cores) */
} es_embed_opts;

ES_API void es_embed_opts_init(es_embed_opts *opts);
/* The defaults for a slider or a walk that must answer at once: local-global
 * alone (no Levenberg-Marquardt finish), to an RMS ratio of 1e-3 and a max
 * relative error of 2e-2, at most 30 iterations. */
ES_API void es_embed_opts_fast(es_embed_opts *opts);

typedef struct es_embed_report {
    double closure_before;    /* E(alpha) (eq. 3) at the initial dihedrals */
    double closure_after;     /* E at the output mesh's dihedrals, target corner angles */
    double closure_stage1;    /* E after stage 1 */
    int64_t dihedral_iters;   /* stage 1 LM iterations (AUTO: 1 first, the rest only
                                 if that one removed 99 % of the closure energy) */
    int64_t refine_iters;     /* stage 4 LM iterations (all continuation steps) */
    int64_t lg_iters;         /* local-global iterations (solves from positions) */
    int64_t n_projected;      /* target lengths replaced to form triangles (realize_margin) */
    double projection_rms;    /* RMS and largest relative change of those lengths (0 if */
    double projection_max;    /* none): how far from the asked lengths the solve had to go */
    int64_t continuation_steps; /* steps used (0: dihedral path) */
    int used_continuation;    /* 1 if the returned result came from continuation */
    int used_stage1;          /* 1 if stage 1's dihedrals were kept (AUTO may drop them) */
    double t_dihedral, t_frames, t_positions, t_refine, t_total;   /* seconds */
    double t_local_global;    /* of t_refine, the local-global iterations' (with their
                                 factorization); the rest is the Levenberg-Marquardt finish */
    double rms_ratio_linear;  /* RMS ratio after stage 3, before refinement */
    double rms_ratio;         /* RMS(l_out - l_target) / mean(l_target) */
    double max_rel;           /* max_e |l_out - l_target| / l_target */
    double p99_rel;           /* 99th percentile of the same */
    int64_t worst_edge;       /* edge of max_rel */
    int64_t n_bad_faces;      /* target faces violating the triangle inequality */
    double scale;             /* sum of the output's target lengths */
    int realized;             /* 1 if max_rel <= opts.realized_rtol and no target face
                                 violates the triangle inequality */
    /* shape against the prior (es_embed_prior_solve; has_prior 0 otherwise) */
    int has_prior;
    double bend_out;          /* mean |bending angle| over interior edges, output */
    double bend_prior;        /* the same of the prior's realization */
    double bend_ratio;        /* bend_out / bend_prior: > 1 means creases the data lack */
    double prior_rms;         /* RMS vertex distance from the prior's realization (scaled
                                 to the output's size, rigidly aligned), as a fraction of
                                 its bounding-box diagonal */
    double prior_max;         /* the largest such distance */
} es_embed_report;

/* Make an embedder for `mesh` (borrowed; must outlive the embedder).
 * Fails with ES_EINVAL on a mesh without faces, ES_ENUMERIC if CHOLMOD
 * fails. */
ES_API es_status es_embedder_new(es_ctx *ctx, const es_mesh *mesh, es_embedder **out);
ES_API void es_embedder_free(es_embedder *emb);

/* The same with the fill-reducing vertex order of an earlier embedder of
 * this topology (es_embedder_ordering, V entries: a permutation of the
 * vertices; ES_EINVAL otherwise), so that it is not computed again: the
 * order is the costly part of an embedder's making on large meshes (METIS
 * from 10K vertices), and the study layer keeps it in its cache file.
 * order NULL: as es_embedder_new. */
ES_API es_status es_embedder_new_ordered(es_ctx *ctx, const es_mesh *mesh, const int64_t *order,
                                         es_embedder **out);
/* The embedder's vertex order (V entries), borrowed for its lifetime. */
ES_API const int64_t *es_embedder_ordering(const es_embedder *emb);

/* Embed target lengths. ctx receives the message of a failure (the
 * embedder's own context, from es_embedder_new, provides its memory).
 *   target     [in]  E edge lengths (any positive scale).
 *   scale      [in]  > 0: embed at sum of lengths = scale; 0: at the target's own sum.
 *   init_alpha [in]  E dihedral angles to start stage 1 from, or NULL.
 *   init_xyz   [in]  3 x V positions of a mesh with this topology, or NULL: its
 *                    dihedrals are the start when init_alpha is NULL, it is the
 *                    start of continuation, and the output is aligned to it.
 *                    At least one of init_alpha, init_xyz is required. It may
 *                    be the xyz array itself (the last frame of a sequence).
 *   opts       [in]  NULL for defaults.
 *   xyz        [out] 3 x V positions. Vertices in no face are put where the
 *                    alignment reference (init_xyz, else the mesh's positions)
 *                    has them, at the origin when there is none.
 *   report     [out] quality report, or NULL.
 * Errors: ES_EINVAL on a length that is not finite and positive (names the
 * edge), a non-finite initial angle or position, neither initialization;
 * ES_ENUMERIC if a factorization fails beyond repair. Targets whose faces
 * violate the triangle inequality are embedded as well as possible and
 * counted in the report (realized = 0); the output is always finite. */
ES_API es_status es_embed_solve(es_ctx *ctx, es_embedder *emb, const double *target,
                                double scale, const double *init_alpha, const double *init_xyz,
                                const es_embed_opts *opts, double *xyz,
                                es_embed_report *report);

/* Per-vertex results of the last solve (V entries each), borrowed until
 * the next solve or es_embedder_free; NULL before the first solve:
 * closure residual E_v at the output dihedrals and target corner angles
 * (0 at boundary vertices), and the mean relative edge-length error of the
 * edges around the vertex. */
ES_API const double *es_embedder_vertex_closure(const es_embedder *emb);
ES_API const double *es_embedder_vertex_edge_error(const es_embedder *emb);
/* After es_embed_prior_solve (NULL otherwise): each vertex's distance from
 * the prior's realization, as a fraction of its bounding-box diagonal (the
 * per-vertex values behind report.prior_rms, for a heat map). */
ES_API const double *es_embedder_vertex_deviation(const es_embedder *emb);
ES_API const es_mesh *es_embedder_mesh(const es_embedder *emb);

/* Closure energy E(alpha) = sum_v ||P_v - I||_F^2 (eq. 2-3) with corner
 * angles from `len` (E) and dihedrals `alpha` (E). Optional outputs (NULL
 * to skip): grad (E, dE/dalpha, 0 on boundary edges), vertex_energy (V). */
ES_API es_status es_embed_closure(es_ctx *ctx, const es_mesh *mesh, const double *len,
                                  const double *alpha, double *energy, double *grad,
                                  double *vertex_energy);

/* Edge-length error metrics of positions xyz against target lengths
 * (scaled to the same sum first when normalize is 1). */
ES_API es_status es_embed_length_error(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                                       const double *target, int normalize, double *rms_ratio,
                                       double *max_rel, double *p99_rel);

/* Rigidly align xyz (3 x V, in place) onto ref (3 x V) by the proper
 * rotation and translation of least squares (Kabsch 1976); vertices with
 * weight 0 (w NULL: all 1) do not count. *rms gets the RMS distance after. */
ES_API es_status es_embed_align(es_ctx *ctx, int64_t nverts, double *xyz, const double *ref,
                                const double *w, double *rms);

/* The same for each part separately: part[v] (0-based; < 0: vertex left
 * where it is) names the rigid piece vertex v belongs to, e.g. the
 * connected components of es_mesh_vertex_component, whose relative
 * placement edge lengths do not fix. part NULL: one piece. A part whose
 * weights sum to 0 is left where it is. */
ES_API es_status es_embed_align_parts(es_ctx *ctx, int64_t nverts, double *xyz,
                                      const double *ref, const double *w, const int64_t *part,
                                      double *rms);

/* ---- a prior from the data -------------------------------------------------
 * Where the lengths leave a surface free (every open mesh: faces with eye and
 * mouth holes and a neck boundary) the solve above bends it into shapes no
 * input has. Every point of a study is a combination of stored rows with
 * row weights w (es_point_eval_rows); the same weights applied to the rows
 * give a prior:
 *   xyz   = sum_i w_i X_i, X_i the rows' positions after GPA without scaling:
 *           the prior's own realization, which starts the solve and frames
 *           its output (one frame for every point of a store);
 *   alpha = c + sum_i w_i wrap(alpha_i - c), c the circular mean of the
 *           rows' dihedrals weighted by |w_i| (for two rows the shortest arc,
 *           as es_interp_targets);
 *   sd    = the |w_i|-weighted RMS of wrap(alpha_i - c): how much the rows
 *           that make the point disagree at each edge.
 * es_embed_prior_solve realizes target lengths near that prior: on an open
 * mesh it starts from xyz scaled to the target's length sum and refines
 *   F(x) = sum_e ((|x_a - x_b| - l_e) / l_e)^2
 *        + mu_k sum_e omega_e wrap(alpha_e(x) - alpha_e)^2,
 *   mu_k = prior_mu max(prior_decay^k, prior_mu_floor) at iteration k,
 *   omega_e = [3 l_e^2 / (A_f + A_g)] / mean(...) / (1 + (sd_e / s0)^2),
 * the discrete-shells bending weight (Grinspun et al. 2003) over interior
 * edges, the bending angle of es_geom.h. On a closed mesh (rigid for its
 * lengths) the term is off and the solve is the dihedral path from alpha
 * (what es_interp_embed does). The output is rigidly aligned to xyz.
 * Measured on face-study (81 rows, 3 subjects held out): held-out faces from
 * their lengths 0.13 % of the bbox diagonal from the real mesh (0.50 % from
 * the nearest row's start), means 0.11 % from the Procrustes mean (0.49 %),
 * bending ratio 1.00-1.05 (1.29-1.48), at the same cost per embedding. */
typedef struct es_embed_prior {
    const double *xyz;      /* 3 x V: the prior's realization (required); must not be
                               the output array */
    const double *alpha;    /* E: prior dihedrals (NULL: those of xyz) */
    const double *sd;       /* E: the rows' spread per edge (NULL: none) */
    const double *start;    /* 3 x V: on open meshes, refine from these positions instead
                               of xyz, e.g. a walk's previous frame (NULL: xyz); must
                               not be the output array */
    const double *span_lo;  /* E each, or NULL: per edge the least and the greatest
                               bending angle of the rows with a weight (not 0): the band */
    const double *span_hi;  /* of the crease guard on a closed mesh, as es_interp_embed
                               makes it from its inputs (crease_margin, crease_mu); NULL:
                               alpha +- 3 sd, or no guard without sd */
} es_embed_prior;

/* Embed target lengths (E; scale as es_embed_solve) near a prior. The
 * report adds the shape against the prior (has_prior = 1), and
 * es_embedder_vertex_deviation the per-vertex distances. Errors as
 * es_embed_solve, and ES_EINVAL without prior positions. */
ES_API es_status es_embed_prior_solve(es_ctx *ctx, es_embedder *emb, const double *target,
                                      double scale, const es_embed_prior *prior,
                                      const es_embed_opts *opts, double *xyz,
                                      es_embed_report *report);

/* The prior of row weights w (n rows): xyz (3 x V) from aligned[i] (3 x V
 * each, GPA-aligned without scaling), alpha and sd (E) from alpha_rows[i]
 * (E each, the rows' dihedrals). Any output may be NULL (then its inputs
 * may be too). Rows of weight 0 are not read. */
ES_API es_status es_embed_prior_from_rows(es_ctx *ctx, int64_t nverts, int64_t nedges,
                                          int64_t n, const double *const *aligned,
                                          const double *const *alpha_rows, const double *w,
                                          double *xyz, double *alpha, double *sd);

/* The same with each row's cosines and sines of its dihedrals given
 * (cos_rows[i], sin_rows[i]: E each). Without them the circular mean's
 * centre is made with a polynomial sine and cosine (1e-7), which costs
 * about as much as reading them (90 rows of 27,871 dihedrals: 10 ms). */
ES_API es_status es_embed_prior_from_rows_sc(es_ctx *ctx, int64_t nverts, int64_t nedges,
                                             int64_t n, const double *const *aligned,
                                             const double *const *alpha_rows,
                                             const double *const *cos_rows,
                                             const double *const *sin_rows, const double *w,
                                             double *xyz, double *alpha, double *sd);

/* Bytes an embedder of mesh and its solves need (an estimate from the
 * mesh's edges, measured against peak memory: embed_memory.c), and the
 * check es_embedder_new makes first: ES_ERANGE naming the need when it,
 * plus extra bytes the caller will hold meanwhile (extra_what names them,
 * " for 600 rows of the prior"), passes es_ctx_memory_limit. */
ES_API uint64_t es_embed_memory_estimate(const es_mesh *mesh);
ES_API es_status es_embed_check_memory(es_ctx *ctx, const es_mesh *mesh, uint64_t extra,
                                       const char *extra_what);

/* One-line and multi-line text of a report (for commands and notebooks):
 * writes at most n bytes with NUL, returns buf. */
ES_API const char *es_embed_report_format(const es_embed_report *rep, char *buf, size_t n);

/* ---- the published pipeline, for comparison (paper.c) ------------------------
 * edge-length-interpolation Section 2 as published: stage 1 minimizes the
 * closure energy E(alpha) (eq. 3) by L-BFGS from the initial dihedrals (the
 * paper: SciPy's fmin_l_bfgs_b from the inputs' averaged dihedrals; here
 * SciPy's default settings), stages 2-3 turn the minimizer into frames and
 * positions by least squares, and nothing follows: no refinement against
 * the lengths, no choice whether stage 1 helps (es_embed_solve's changes).
 * On open meshes stage 1 works on the interior vertices' closure, as on
 * closed ones. */
typedef struct es_embed_paper_opts {
    int history;            /* L-BFGS correction pairs, m (10) */
    int max_iter;           /* iterations, and evaluations of E (15000); 0: no stage 1 */
    double factr;           /* stop when E falls by <= factr x DBL_EPSILON x max(|E|, 1)
                               in an iteration (1e7) ... */
    double pgtol;           /* ... or when max |dE/dalpha| <= pgtol (1e-5) */
    es_embed_opts embed;    /* alignment and report settings of stages 2-3
                               (es_embed_opts_init); its stage-1, refinement, prior and
                               continuation fields are not used */
} es_embed_paper_opts;

ES_API void es_embed_paper_opts_init(es_embed_paper_opts *opts);

/* Embed target lengths (E; scale as es_embed_solve) by the published
 * pipeline from init_alpha (E, the averaged dihedrals), or from the
 * dihedrals of init_xyz when init_alpha is NULL; the output is aligned as
 * es_embed_solve aligns it (to init_xyz when given). The report is
 * es_embed_solve's for stages 2-3 with stage 1's figures put in:
 * closure_before (E at the start), closure_stage1 (E at the L-BFGS
 * minimizer: the "error" of the paper's Table 1), dihedral_iters (L-BFGS
 * iterations), t_dihedral, and t_total for the whole. Errors as
 * es_embed_solve, and ES_EINVAL for settings out of range. */
ES_API es_status es_embed_paper_solve(es_ctx *ctx, es_embedder *emb, const double *target,
                                      double scale, const double *init_alpha,
                                      const double *init_xyz,
                                      const es_embed_paper_opts *opts, double *xyz,
                                      es_embed_report *report);

#ifdef __cplusplus
}
#endif
#endif
