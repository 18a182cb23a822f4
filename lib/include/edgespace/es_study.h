/* lib/include/edgespace/es_study.h — lib/study: analyses run on a shape store
 * (the only module where the numerical modules meet the store). The
 * statistics of es_stats.h and the points of es_point.h, with their results kept in
 * the store under /analysis/<kind>/<name> (datasets-spec/analysis-results.md):
 *
 *   mean/<name>:  means (G x E: row g = mean of group g), counts (G),
 *                 groups (G strings), scales (G: mean scale of the group);
 *                 attrs filter, by
 *   pca/<name>:   mean (E), components (K x E: row k = unit component k),
 *                 eigenvalues (K, divisor N-1), explained (K),
 *                 total_variance (1), scores (N x K), rows (N store rows);
 *                 attrs method, filter, ncomp
 *   diff/<name>:  mean, sd, se, t (E each), pair_from, pair_to (P store
 *                 rows), unpaired (store rows); attrs key, column, from, to
 *   point/<name>: lengths (E), scale (1); attrs expression, weight, valid,
 *                 n_bad_faces, n_nonpositive, worst_violation, worst_face
 * Every result carries the provenance of es_store_result_begin (command,
 * tool version, time, rows used). A name that is taken is refused with
 * ES_EEXIST before anything is computed, unless the store was opened with
 * ES_STORE_REPLACE, which replaces it (es_store_result_check).
 *
 * One style for every analysis: es_study_<x>(ctx, store, opts, outputs...)
 * with an options struct made by es_study_<x>_opts_init; opts->name NULL
 * stores nothing (the one switch), opts->command is provenance only (NULL:
 * "es_study_<x>"). No study call commits: the caller publishes what it
 * stored with es_store_commit (or es_store_close) and discards it with
 * es_store_rollback (or es_store_abort). The files es_study_embed and
 * es_study_interp write beside a stored result (meshes, residuals, frames)
 * ride on the store handle and are renamed into place by that commit, after
 * the store is published, or removed by the rollback: a failed store write
 * leaves no new file behind and an old one as it was. Without a name they
 * are renamed into place before the call returns.
 */
#ifndef EDGESPACE_ES_STUDY_H
#define EDGESPACE_ES_STUDY_H

#include "es_core.h"
#include "es_mesh.h"
#include "es_point.h"
#include "es_stats.h"
#include "es_store.h"
#include "es_embed.h"
#include "es_interp.h"
#include "es_procrustes.h"
#include "es_compare.h"
#include "es_model.h"
#include "es_morph.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A source over store rows: all rows (rows NULL) or rows[0..nrows). Borrows
 * store and rows. */
ES_API es_status es_study_source(es_ctx *ctx, es_store *store, const int64_t *rows,
                                 int64_t nrows, es_source *out);


/* ---- means --------------------------------------------------------------- */

typedef struct es_group_result {
    es_ctx *ctx;
    int64_t nedges, ngroups;
    char **names;       /* ngroups group names ("all" without a grouping column) */
    double *means;      /* E x ngroups, column g */
    int64_t *counts;    /* rows per group */
    double *scales;     /* mean scale per group (sum of raw edge lengths) */
    double *centroid_sizes; /* mean centroid size per group (shapes::centroid.size of the
                               positions as ingested) */
} es_group_result;
ES_API void es_study_group_result_free(es_group_result *r);

/* What es_study_mean does (es_study_mean_opts_init: every row, one group,
 * nothing stored). */
typedef struct es_study_mean_opts {
    const char *name;       /* store as mean/<name> (NULL: store nothing) */
    const char *where;      /* rows: "col=value,..." (NULL or "": all) */
    const char *by;         /* label column: one mean per value (NULL: one group "all") */
    const char *command;    /* provenance (NULL: "es_study_mean") */
} es_study_mean_opts;
ES_API void es_study_mean_opts_init(es_study_mean_opts *opts);

/* Means of the rows matching opts->where, one per value of label column
 * opts->by, stored as mean/<name> when opts->name is non-NULL (the store
 * open for writing; the caller commits). opts NULL: the defaults. out may
 * be NULL. */
ES_API es_status es_study_mean(es_ctx *ctx, es_store *store, const es_study_mean_opts *opts,
                               es_group_result **out);

/* ---- PCA ------------------------------------------------------------------ */

/* What es_study_pca does (es_study_pca_opts_init: every row, es_pca_opts_init's
 * fit, nothing stored). */
typedef struct es_study_pca_opts {
    const char *name;       /* store as pca/<name> (NULL: store nothing) */
    const char *where;      /* rows: "col=value,..." (NULL or "": all) */
    es_pca_opts pca;        /* the fit (es_pca_opts_init) */
    const char *command;    /* provenance (NULL: "es_study_pca") */
} es_study_pca_opts;
ES_API void es_study_pca_opts_init(es_study_pca_opts *opts);

/* Fit a PCA of the rows matching opts->where and store it as pca/<name>
 * when opts->name is non-NULL (the caller commits). opts NULL: the
 * defaults. *out (may be NULL) gets the fit, *rows (may be NULL) the store
 * rows used (es_free), in score order. */
ES_API es_status es_study_pca(es_ctx *ctx, es_store *store, const es_study_pca_opts *opts,
                              es_pca **out, int64_t **rows, int64_t *nrows);

/* Load pca/<name> (NULL: the only PCA in the store, else the one named
 * "default"). Scores are loaded too (nrows = rows fitted); *rows (may be
 * NULL) gets the store rows of the scores (es_free). */
ES_API es_status es_study_pca_load(es_ctx *ctx, es_store *store, const char *name,
                                      es_pca **out, int64_t **rows, int64_t *nrows);

/* ---- differences ------------------------------------------------------------ */

/* What es_study_diff does: key, column, from and to are required. */
typedef struct es_study_diff_opts {
    const char *name;       /* store as diff/<name> (NULL: store nothing) */
    const char *where;      /* rows: "col=value,..." (NULL or "": all) */
    const char *key;        /* label column that pairs the rows (the subject) */
    const char *column;     /* label column whose values from and to are compared */
    const char *from, *to;  /* the difference is to - from */
    const char *command;    /* provenance (NULL: "es_study_diff") */
} es_study_diff_opts;
ES_API void es_study_diff_opts_init(es_study_diff_opts *opts);

/* Rows matching opts->where whose label `column` equals `from` or `to` are
 * paired by label `key` (es_diff_paired's rules); stored as diff/<name>
 * when opts->name is non-NULL (the caller commits). Indices in the result
 * are store rows. out may be NULL. */
ES_API es_status es_study_diff(es_ctx *ctx, es_store *store, const es_study_diff_opts *opts,
                               es_diff **out);

/* ---- points ----------------------------------------------------------------- */

/* Resolver of point leaves on a store (es_point_resolve_fn with userdata =
 * an es_study_resolver). pca_name: the PCA of pc:K (NULL: as
 * es_study_pca_load). mesh: the store's topology, for file: leaves. Row
 * weights (es_point_eval_rows, nrows = es_store_nrows) are: 1/n on the rows
 * of a mean, 1 on a row, z_k / ((N - 1) lambda_k) on the PCA's rows for
 * pc:K (its standard deviation applied by the evaluator), +-1/P on the pairs
 * of a difference, and for a file ridge regression on every row
 * (es_pca_row_weights with ES_RIDGE_REL, on a PCA of all rows fitted once
 * per resolver). */
typedef struct es_study_resolver {
    es_store *store;
    const es_mesh *mesh;
    const char *pca_name;
    es_pca *pca;        /* loaded on first use; free with es_study_resolver_clear */
    double *scales;     /* all row scales, loaded on first use */
    int64_t *pca_rows;  /* the store rows of pca's scores */
    es_pca *all_rows;   /* a PCA of every row, for the weights of file: leaves */
} es_study_resolver;
ES_API es_status es_study_resolve(es_ctx *ctx, void *resolver, es_point_leaf kind,
                                  const char *arg, int64_t index, double *vec, double *scale,
                                  double *weights);
ES_API void es_study_resolver_clear(es_ctx *ctx, es_study_resolver *r);

/* What es_study_point does: expr is required. */
typedef struct es_study_point_opts {
    const char *name;       /* store as point/<name> (NULL: store nothing) */
    const char *expr;       /* the point (datasets-spec/point-syntax.md) */
    const char *pca_name;   /* the PCA of pc:K (NULL: as es_study_pca_load) */
    double scale;           /* > 0: overrides the scale rule of es_point.h (0) */
    const char *command;    /* provenance (NULL: "es_study_point") */
} es_study_point_opts;
ES_API void es_study_point_opts_init(es_study_point_opts *opts);

/* Evaluate opts->expr on the store (validity against the store's topology)
 * and, when opts->name is non-NULL, store it as point/<name> (its lengths,
 * scale and row weights; the caller commits). *vec (may be NULL) gets the
 * lengths (es_free); weights (may be NULL) the row weights (es_store_nrows
 * entries); info (may be NULL) the report. */
ES_API es_status es_study_point(es_ctx *ctx, es_store *store, const es_study_point_opts *opts,
                                double **vec, double *weights, es_point_info *info);

/* The E scale-normalized lengths of a point as a command line names it:
 * "row:ID", the name of a stored point (/analysis/point/NAME), or an
 * expression (datasets-spec/point-syntax.md; pca_name: the PCA of pc:K,
 * NULL for the only or the 'default' one), with its row weights (weights,
 * es_store_nrows entries, may be NULL; see es_study_resolver): a stored
 * point's own, or, for one stored without them, ridge regression on the
 * rows. *scale gets the point's own scale, else the mean scale of the
 * store's rows. A length that is not positive (extrapolated too far) is
 * ES_EINVAL naming the edge: no mesh realizes the point. */
ES_API es_status es_study_point_weights(es_ctx *ctx, es_store *store, const char *spec,
                                        const char *pca_name, double *lengths, double *scale,
                                        double *weights);

/* ---- tables -----------------------------------------------------------------
 * CSV files of results, with the labels a reader needs; every file is
 * replaced only once written whole, and path "-" writes to standard output. */

/* "edge,v0,v1,<names...>": one row per edge of the store's topology (its end
 * vertices), ncol value columns (column c = values + c * E). */
ES_API es_status es_study_write_edge_table(es_ctx *ctx, es_store *store, const char *path,
                                           int64_t ncol, const char *const *names,
                                           const double *values);
/* Per-edge tables of a mean result (one column per group), a paired
 * difference (mean, sd, se, t) and a point (length). */
ES_API es_status es_study_write_mean_table(es_ctx *ctx, es_store *store,
                                           const es_group_result *r, const char *path);
ES_API es_status es_study_write_diff_table(es_ctx *ctx, es_store *store, const es_diff *d,
                                           const char *path);
/* PREFIX_scores.csv (id, every label column, PC1..PCK of the fitted rows
 * `rows`), PREFIX_eigenvalues.csv (component, eigenvalue, explained,
 * cumulative) and PREFIX_components.csv (the edge table of the mean and
 * the components). */
ES_API es_status es_study_write_pca_tables(es_ctx *ctx, es_store *store, const es_pca *p,
                                           const int64_t *rows, const char *prefix);

/* Scores of inputs on a stored PCA: each input is a row id or a mesh file
 * of the store's topology (.obj, .ply, .off), then the rows matching
 * `where` (NULL: none). The result holds n names (borrowed from the inputs
 * or the store), scores (n x K, column k = PC k+1) and the residual norm of
 * each; es_study_projection_free releases it. */
typedef struct es_study_projection {
    es_ctx *ctx;
    int64_t n, ncomp;
    const char **names;
    double *scores;
    double *residuals;
} es_study_projection;
ES_API es_status es_study_project(es_ctx *ctx, es_store *store, const char *pca_name,
                                  int64_t ninputs, const char *const *inputs,
                                  const char *where, es_study_projection **out);
ES_API void es_study_projection_free(es_study_projection *p);
/* "name,PC1..PCK,residual". */
ES_API es_status es_study_write_projection_table(es_ctx *ctx, const es_study_projection *p,
                                                 const char *path);

/* Every stored result as a CSV table with labels (path "-": standard
 * output; a file is replaced only once written whole). result is
 * "KIND/NAME"; table NULL is the kind's default (the first listed):
 *   mean:    means (edge table, a column per group)
 *   pca:     scores (id, labels, PC1..), eigenvalues, components
 *   diff:    edges (mean, sd, se, t);  point: edges (length), weights
 *   gpa:     specimens (id, labels, centroid_size, rho, scale, PC1..),
 *            aligned (x1..xk, y1..yk[, z1..zk]), mean, pca, loadings
 *   compare: summary, distances_lengths, distances_procrustes, groups
 *   embed:   report (its attributes), vertices (positions and heat maps)
 *   model:   anova, coefficients, weights, pairwise, lsmeans, edges,
 *            scores (CAC), permutations (F of each permutation)
 * and every result: attributes (name, value: provenance and report).
 * Errors: ES_ENOTFOUND naming the result or listing the kind's tables. */
ES_API es_status es_study_export_result(es_ctx *ctx, es_store *store, const char *result,
                                        const char *table, const char *path);
/* The tables of a kind, ", "-separated, into buf (n bytes); returns buf. */
ES_API const char *es_study_result_tables(const char *kind, char *buf, size_t n);

/* ---- GPA and the comparison of the two spaces ----------------------------- */

/* What es_study_gpa does (es_study_gpa_opts_init: every row, es_gpa_opts_init's
 * alignment, min(10, n - 1) PCs, nothing stored). */
typedef struct es_study_gpa_opts {
    const char *name;       /* store as gpa/<name> (NULL: store nothing, the report
                               alone; the ranks other than 0 of an MPI job) */
    const int64_t *rows;    /* the store rows aligned, nrows of them (NULL with nrows -1,
                               the default: every row) */
    int64_t nrows;
    es_gpa_opts gpa;        /* the alignment (es_gpa_opts_init) */
    int64_t npc;            /* PCs of the tangent coordinates kept (<= 0: min(10, n - 1)) */
    const char *command;    /* provenance (NULL: "es_study_gpa") */
} es_study_gpa_opts;
ES_API void es_study_gpa_opts_init(es_study_gpa_opts *opts);

/* GPA of the positions of opts->rows of an open store, with the PCA of the
 * residual tangent coordinates, written to /analysis/gpa/<name> when
 * opts->name is non-NULL (a taken name: as above) with provenance (command;
 * params: scale, allow_reflection, tol, max_iter):
 *   aligned   n x k*d   row j: configuration of input row j (x-, y-, z-block)
 *   mean      k*d       Procrustes mean;  size, rho, scale: n each
 *   rotation  n x d*d   column-major d x d per row;  centroid: n x d
 *   pc_sdev, pc_percent (npc), pc_scores (n x npc), pc_loadings (npc x k*d)
 * and attributes dim, k, iterations, converged, rot_change, scale_change,
 * gss, rmsrho, total_ss. Planar data (z = 0 in every row, e.g. ingested 2D
 * landmarks) are analysed in 2D (dim 2), so that a 3D rotation cannot act
 * as a reflection. Memory: the positions of the rows (n x 3V doubles) once.
 * With a name the store must be open for writing; the caller commits
 * (es_store_commit / es_store_close). opts NULL: the defaults. report may
 * be NULL. On a context joined to an MPI job it is collective: every rank
 * reads and aligns its share of the rows (es_gpa_align_ranks; the others
 * may open the store read-only and pass name NULL), rank 0 gathers them,
 * takes the PCA and writes; each rank holds 3V x n/P doubles, rank 0 all n. */
ES_API es_status es_study_gpa(es_ctx *ctx, es_store *store, const es_study_gpa_opts *opts,
                              es_gpa_report *report);

/* What es_study_compare does: gpa_name is required. */
typedef struct es_study_compare_opts {
    const char *gpa_name;   /* the GPA result whose rows are compared */
    const char *by;         /* label column of the groups (NULL: no groups) */
    es_compare_opts compare;   /* the statistics (es_compare_opts_init) */
    const char *name;       /* store as compare/<name> (NULL: store nothing; the
                               `compare` command stores as its GPA's name) */
    const char *out_dir;    /* es_study_compare_write's tables go there (NULL: none) */
    const char *command;    /* provenance (NULL: "es_study_compare") */
} es_study_compare_opts;
ES_API void es_study_compare_opts_init(es_study_compare_opts *opts);

/* The study on a store: the rows of GPA result /analysis/gpa/<gpa_name>
 * (their aligned configurations) against their stored normalized edge
 * lengths, grouped by label column `by`. Writes, when opts->name is
 * non-NULL, /analysis/compare/<name> with provenance: datasets
 * d_lengths, d_procrustes (n x n), group_means_lengths/_procrustes and
 * p_lengths/_procrustes (g x g), group_names, attributes spearman_rho,
 * mantel_p, nn_agreement, by, gpa (permutations in @params). out_dir (or
 * NULL) gets es_study_compare_write's tables (es_figure_compare adds the
 * figures). The result carries the row ids, groups and group names. ES_ENOTFOUND if the GPA
 * result or the column is missing; ES_EINVAL for a store without edges. With
 * a name the store must be open for writing; the caller commits. res (may
 * be NULL) receives the result. */
ES_API es_status es_study_compare(es_ctx *ctx, es_store *store, const es_study_compare_opts *opts,
                                  es_compare_result **res);

/* Write the study to dir (created if missing): distances_lengths.csv and
 * distances_procrustes.csv (n x n with ids), pairs.csv (i, j, ids, both
 * distances, group pair), summary.csv (statistic, value), nearest.csv,
 * disagreement.csv, and with groups group_means.csv (space, group_a,
 * group_b, distance, p); each file is replaced only once complete. The
 * figures are es_figure_compare_write's (es_figure.h). ids: n names (NULL:
 * 1-based numbers);
 * group_names: ngroups names (NULL: numbers). ES_EIO names the file. */
ES_API es_status es_study_compare_write(es_ctx *ctx, const es_compare_result *res,
                                  const char *const *ids, const int64_t *group,
                                  const char *const *group_names, const char *dir);

/* ---- linear models ------------------------------------------------------------
 * es_model.h on a store: the response is the rows' normalized edge lengths
 * (edge-length space) or the aligned coordinates of a stored GPA result
 * (Procrustes space: its `aligned` configurations);
 * every variable of the formula is a label column, except `size` when no
 * label column has that name: each row's scale (sum of raw edge lengths)
 * in edge-length space, its centroid size in Procrustes space, so that
 * "~ log(size) + group" is the allometric model. Stored as
 * /analysis/model/<name> (datasets-spec/analysis-results.md). */
typedef struct es_study_model_opts {
    const char *formula;       /* "~ expression + subject" (required) */
    const char *gpa;           /* the GPA result whose coordinates are the response; NULL:
                                  normalized edge lengths */
    const char *where;         /* rows: "col=value,..." (with gpa: among the GPA's rows) */
    const char *block;         /* label column: permute only within its values (repeated
                                  measures: the subject), or NULL */
    es_ss_type ss_type;        /* ES_SS_TYPE_I */
    es_perm_scheme scheme;     /* ES_PERM_RRPP */
    int64_t permutations;      /* 999 */
    es_contrasts contrasts;    /* treatment */
    const char *pairwise;      /* a categorical variable: its LS means compared, or NULL */
    const char *slopes;        /* with pairwise: compare the levels' slopes on this numeric
                                  variable ("log(size)") instead of LS means */
    const char *at;            /* LS means at "NAME=VALUE,...": NAME a variable label
                                  ("log(size)") or the column a log() reads ("size", VALUE
                                  then on the column's scale); VALUE a number or "mean" (of
                                  what NAME names). Default: every numeric variable at its
                                  mean as the formula uses it (mean of log(size)) */
    const char *reference;     /* baseline levels "LEVEL" or "FACTOR=LEVEL", comma-separated
                                  (LEVEL alone: the one factor of the formula that has it) */
    const char *const *errors; /* nerrors "TERM=ERROR": TERM's F over ERROR's mean square
                                  (nested designs: "population=population:colony"); a term
                                  is its label or its variables joined by ':' in any order */
    int64_t nerrors;
    const char *null_formula;  /* compare the model with this nested one (RRPP's anova(null,
                                  full)), or NULL */
    const char *edge_term;     /* a term: per-variable tests with FDR: every edge in
                                  edge-length space, every landmark's displacement (its d
                                  coordinates together) in Procrustes space */
    int64_t edge_permutations; /* -1: permutations */
    const char *name;          /* store as model/<name> (NULL: store nothing) */
    const char *command;       /* provenance */
} es_study_model_opts;
ES_API void es_study_model_opts_init(es_study_model_opts *opts);

/* Everything a model on a store made; arrays owned (es_study_model_free). */
typedef struct es_study_model_result {
    es_ctx *ctx;
    es_formula *formula;
    es_design *design;
    es_model *model;
    es_model_pairwise *pairwise;   /* with opts->pairwise, else NULL */
    es_formula *null_formula;      /* with opts->null_formula, else NULL: */
    es_design *null_design;
    es_model *null_model;
    es_model_comparison *comparison;
    int64_t ntests;                /* with opts->edge_term: E edges or k landmarks */
    double *edge_f, *edge_p, *edge_q;   /* ntests each with opts->edge_term, else NULL */
    double *cac, *cac_scores;      /* p and N when log(size) is a term, else NULL */
    int64_t nrows;
    int64_t *rows;                 /* N store rows, in model order */
    const char **ids;              /* N row ids (borrowed from the store) */
} es_study_model_result;
ES_API void es_study_model_free(es_study_model_result *r);

/* Fit and test the model (es_model_fit), then what opts asks for after it,
 * and store it when opts->name is given (the store open for writing; the
 * caller commits). Terms the design leaves out as aliased are warned about
 * (the context's log) and listed in design->dropped. Errors: ES_ENOTFOUND
 * (a label column, the GPA result, an error term), ES_EINVAL (no rows, a
 * store without edges in edge-length space, pairwise or per-variable tests
 * of a dropped term, slopes or at without pairwise, a reference that is no
 * factor's level, a null model not nested in the model), those of
 * es_model.h. */
ES_API es_status es_study_model(es_ctx *ctx, es_store *store, const es_study_model_opts *opts,
                                es_study_model_result **out);

/* The analysis-of-variance table as CSV: term, df, ss, ms, r2, f, z, p,
 * error (the term whose MS divides, "Residual" by default), then the rows
 * Residual (df, ss, ms) and Total (df, ss); with a null model, a row "null
 * model: FORMULA" (df, ss, ms, r2, f, z, p of the comparison). */
ES_API es_status es_study_write_model_table(es_ctx *ctx, const es_study_model_result *r,
                                            const char *path);
/* The pairwise table as CSV, a row per pair of levels: level_a, level_b,
 * d, ucl, z, p (distances of LS means or of slopes), and for slopes r
 * (vector correlation), angle (degrees), angle_ucl, angle_z, angle_p,
 * dlength, dlength_ucl, dlength_z, dlength_p. ES_EINVAL without pairwise. */
ES_API es_status es_study_write_pairwise_table(es_ctx *ctx, const es_study_model_result *r,
                                               const char *path);
/* The fit as `edgespace model` shows it: the ANOVA table with Z (and each
 * term's error term), the terms left out and why, the comparison with the
 * null model, the pairwise table with the values its LS means are taken at,
 * the count of edges or landmarks with q < 0.05. *out: text, caller frees
 * with es_free. */
ES_API es_status es_study_model_summary(es_ctx *ctx, const es_study_model_result *r,
                                        char **out);

/* Coefficient `coef` (a design column name, e.g. "age" or "expression=happy")
 * of stored model `model` in edge-length space: its E values (vec) and its row
 * weights (weights, es_store_nrows entries, added to). What the point
 * syntax's coef:MODEL:COEF resolves to. */
ES_API es_status es_study_model_coef(es_ctx *ctx, es_store *store, const char *model,
                                     const char *coef, double *vec, double *weights);

/* ---- embeddings ------------------------------------------------------------- */

/* The stored row nearest to normalized lengths `target` (E) in Euclidean
 * edge-length distance: the default initialization. rows/nrows restrict the
 * search (NULL: all rows). */
ES_API es_status es_study_nearest_row(es_ctx *ctx, es_store *store, const double *target,
                                      const int64_t *rows, int64_t nrows, int64_t *row,
                                      double *dist);

/* Circular mean of the dihedrals of stored rows (E): the angle of the mean
 * unit vector per edge (oracle README, failure F). */
ES_API es_status es_study_mean_dihedrals(es_ctx *ctx, es_store *store, const es_mesh *mesh,
                                         const int64_t *rows, int64_t nrows, double *alpha);

/* Store an embedding as /analysis/embed/<name>: datasets positions (V x 3),
 * target_lengths (E, normalized), vertex_closure and vertex_edge_error
 * (V, for heat maps, from the embedder's last solve), vertex_deviation (V,
 * after a prior solve: distance from the prior's realization / bbox
 * diagonal), and the report as attributes (closure_before, closure_after,
 * rms_ratio, max_rel, p99_rel, n_bad_faces, realized, iterations, seconds
 * per stage, has_prior, bend_out, bend_prior, bend_ratio, prior_rms,
 * prior_max, init). Commit is the caller's. */
ES_API es_status es_study_store_embedding(es_ctx *ctx, es_store *store, const char *name,
                                       const es_provenance *prov, const es_embedder *emb,
                                       const double *target, const double *xyz,
                                       const es_embed_report *rep, const char *init);

/* The store's rows ready to serve as the embedding's prior (es_embed.h):
 * every row's positions aligned by GPA without scaling into the store's
 * frame (the Procrustes mean moved onto row 0, so outputs stand where the
 * first shape stands and outputs of nearby points overlay), and every row's
 * dihedrals. N x (3V + E) doubles; made once per command. */
typedef struct es_study_rows es_study_rows;
ES_API es_status es_study_rows_load(es_ctx *ctx, es_store *store, const es_mesh *mesh,
                                    es_study_rows **out);
ES_API void es_study_rows_free(es_study_rows *rows);
/* The prior of row weights w (es_store_nrows entries, as es_study_point_weights
 * gives them): realization xyz (3 x V, in the store's frame), dihedrals alpha
 * and their spread sd (E each). Any output may be NULL. */
ES_API es_status es_study_prior(es_ctx *ctx, const es_study_rows *rows, const double *w,
                                double *xyz, double *alpha, double *sd);
/* Per edge the least (lo) and the greatest (hi) bending angle of the rows
 * whose weight is not 0 (E each): the crease guard's band (es_embed_prior). */
ES_API es_status es_study_prior_span(es_ctx *ctx, const es_study_rows *rows, const double *w,
                                     double *lo, double *hi);

typedef struct es_study_embed_result {
    es_embed_report report;
    double scale;           /* the sum of lengths embedded at */
    char init[512];         /* what the embedding started from, in words */
} es_study_embed_result;

/* ---- an embedding session -----------------------------------------------------
 * What every embedding of a store's points shares, made once: the mesh, the
 * embedder and the rows made ready for priors. With use_cache, the
 * embedder's vertex order and the rows are kept in a file beside the store
 * (STORE.es-cache, datasets-spec/cache-format.md) and read back by the next
 * session while the store's rows are the same: a command in a fresh process
 * then skips the GPA of every row and the ordering (on face-study 0.6 s of
 * CPU). A stale or damaged cache is made again; one that cannot be written
 * (a read-only folder) only costs the time, and the log says so. The
 * session borrows the store (it must outlive the session) and remembers its
 * last output: a warm embedding starts from it instead of the prior's
 * realization (a walk's next frame, a slider's next position). The leaves
 * of its points read from stored results (means, pc:K, differences,
 * coefficients) are kept and reused until the store handle writes anything
 * (es_store_generation): a slider's "mean + t*pc:1" reads the store once.
 * Results written by another process after the handle opened are not seen,
 * as with any read through it. One thread at a time. */
typedef struct es_study_embedder es_study_embedder;
ES_API es_status es_study_embedder_open(es_ctx *ctx, es_store *store, int use_cache,
                                        es_study_embedder **out);
ES_API void es_study_embedder_free(es_study_embedder *se);
ES_API const es_mesh *es_study_embedder_mesh(const es_study_embedder *se);
ES_API es_embedder *es_study_embedder_embedder(es_study_embedder *se);
ES_API const es_study_rows *es_study_embedder_rows(const es_study_embedder *se);
ES_API es_store *es_study_embedder_store(const es_study_embedder *se);
/* Forget the last output: the next warm embedding starts from its prior. */
ES_API void es_study_embedder_forget(es_study_embedder *se);
/* Embed lengths (E, any scale; embedded at `scale`, > 0) with row weights w
 * (N) near their prior, as es_study_embed does by default; warm: from the
 * last output when there is one; exact: the lengths are one real mesh's
 * (es_embed_opts.prior_exact). xyz: 3 x V, in the store's frame. res->init
 * says what the solve started from. */
ES_API es_status es_study_embedder_solve(es_ctx *ctx, es_study_embedder *se,
                                         const double *lengths, double scale, const double *w, const es_embed_opts *eo,
                                         int warm, int exact, double *xyz,
                                         es_study_embed_result *res);
/* The same for a point expression (datasets-spec/point-syntax.md) at its own
 * scale (scale 0) or the one given; a point that is one row or one mesh file
 * is solved as exact. */
ES_API es_status es_study_embedder_point(es_ctx *ctx, es_study_embedder *se, const char *point,
                                         const char *pca_name, double scale,
                                         const es_embed_opts *eo, int warm, double *xyz,
                                         es_study_embed_result *res);

/* What es_study_embed does: embed one point of the store's space. */
typedef struct es_study_embed_opts {
    const char *point;      /* as es_study_point_weights reads it (required) */
    const char *pca_name;   /* the PCA of pc:K in the point (NULL: the only one) */
    const char *init;       /* NULL or "prior" (the default): the prior of the point's
                               row weights (es_study_prior, es_embed_prior_solve), the
                               output in the store's frame; explicit overrides, from
                               es_embed_solve without a prior: "nearest" (the stored row
                               nearest in edge-length distance), "row:ID",
                               "mean[:FILTER]" (circular mean of the rows' dihedrals) or
                               "mesh:FILE" (a mesh of this topology; the output is
                               aligned to it) */
    double scale;           /* > 0: embed at this sum of lengths (0: the point's) */
    const char *output;     /* mesh file to write (OBJ/PLY/OFF by extension), or NULL */
    const char *residuals;  /* CSV of per-vertex closure and edge error, or NULL */
    const char *name;       /* store as /analysis/embed/<name> (NULL: store nothing) */
    const char *command;    /* provenance of the stored result (NULL: "es_study_embed") */
    int cache;              /* 1 (the default): the session's cache beside the store
                               (es_study_embedder_open) */
    es_study_embedder *session;   /* an open session of this store to use (and leave
                               open) instead of making one: repeated calls then cost
                               only their solves (NULL: one for this call) */
    int warm;               /* with a session: start from its last output's correction
                               (es_study_embedder_solve; default 0: from the prior) */
    es_embed_opts embed;    /* solver options (es_embed_opts_init) */
    int paper;              /* 1: the published pipeline (es_embed_paper_solve, default
                               L-BFGS settings; embed's alignment and report settings)
                               from the same start's dihedrals: the prior's weighted
                               circular mean of the rows' (the paper: their average), or
                               the explicit start's (0) */
} es_study_embed_opts;
ES_API void es_study_embed_opts_init(es_study_embed_opts *opts);


/* Embed a point: resolve it, initialize, solve, write the mesh and the
 * residuals, store the result with its provenance. The store must be open
 * for writing when opts->name is given; the caller commits, and the mesh
 * and residual files appear with that commit (es_store_commit; removed by
 * es_store_rollback or es_store_abort). Without a name they are written at
 * once. xyz (3 x V, may be NULL) receives the positions. Nothing is stored
 * or written when a step fails. */
ES_API es_status es_study_embed(es_ctx *ctx, es_store *store, const es_study_embed_opts *opts,
                                double *xyz, es_study_embed_result *res);

/* Called for each frame es_study_interp has written: frame i of n, its
 * mesh file, a heading ("t = 0.5 (3 dihedrals wrapped)") and its report. */
typedef void (*es_study_frame_fn)(void *userdata, int64_t i, int64_t n, const char *path,
                                  const char *heading, const es_embed_report *report);

/* What es_study_interp does: a walk between two points, or one weighted
 * combination of rows. */
typedef struct es_study_interp_opts {
    const char *from, *to;  /* end points (t = 0 and 1) as es_study_point_weights reads
                               them; two rows ("row:A", "row:B") interpolate their
                               meshes (dihedrals averaged on the circle) */
    const char *weights;    /* instead: "w1*row:a + w2*row:b + ..." (two or more rows),
                               one frame */
    const char *pca_name;   /* the PCA of pc:K in from/to */
    double t0, t1;          /* range of t (0, 1) */
    int64_t steps;          /* frames from t0 to t1 inclusive (9) */
    const char *output;     /* mesh file; with several frames a printf pattern with one
                               integer conversion ("cat_%02d.obj"; %% is a literal %) */
    const char *name;       /* store the frames as /analysis/embed/<name>[_<i>] (NULL:
                               store nothing; the `interp` command names them
                               es_study_interp_default_name of the output) */
    const char *command;    /* provenance (NULL: "es_study_interp") */
    es_embed_opts embed;
    int cold;               /* 1: every frame from its own prior (as es_study_embed of
                               the same point); 0 (default): each frame from the last
                               one's output, which is nearer (a warm start) */
    es_morph_method method; /* ES_MORPH_EDGE_LENGTH (the default: the above); the other
                               papers' (es_morph.h) walk between two rows (from and to
                               "row:ID"): multiscale and shape-space put each frame
                               together themselves (positions in row A's frame);
                               data-driven follows a path through the store's rows
                               (es_data_path on their es_lri coordinates against row
                               A, frames evenly along it, t0 and t1 0 and 1) and
                               decodes each frame, placed between A and B by the
                               interpolated rigid motion; data-driven-el the same
                               path on the rows' edge-length PCA scores, each frame
                               embedded as the point of its row weights, like the
                               default; paper: the published pipeline
                               (es_embed_paper_solve) from the rows' averaged
                               dihedrals, aligned frame to frame; conformal: row
                               `from` alone (to NULL) mapped to the sphere, t the
                               factors' k (es_conformal_*; an open mesh is closed
                               off: the frame files have the closed mesh, the
                               stored results the store's vertices and edges) */
    es_study_frame_fn frame;   /* called after each frame (may be NULL) */
    void *userdata;
    es_multiscale_opts multiscale; /* method multiscale: its hierarchy (es_morph.h;
                                   its seeds from the context's) */
    es_data_path_opts path; /* methods data-driven and data-driven-el: the path's K,
                               sigma and the rest (es_data_path_opts_init) */
} es_study_interp_opts;
ES_API void es_study_interp_opts_init(es_study_interp_opts *opts);

/* Interpolate (or extrapolate: t or weights outside [0, 1]) and embed each
 * frame; frames are aligned frame to frame so the sequence does not jump.
 * Every frame is checked before the first is written: a walk that leaves
 * edge-length space (a length <= 0 at some t) is refused naming t and the
 * edge, and nothing is written. With opts->name the frames are stored (the
 * store open for writing); the caller commits, and the frame files appear
 * with that commit, all together (removed by es_store_rollback or
 * es_store_abort); without a name they appear, all together, before the
 * call returns. A walk that fails stores nothing and writes no frame. */
ES_API es_status es_study_interp(es_ctx *ctx, es_store *store, const es_study_interp_opts *opts);

/* The file of frame i: pattern with its one %d, %Nd or %0Nd conversion
 * expanded (%% is a literal %). 0, or -1 if the pattern is malformed or
 * the result does not fit in n bytes. */
ES_API int es_study_frame_path(const char *pattern, int64_t i, char *out, size_t n);
/* Where es_study_interp stores its frames, for messages: "NAME", or
 * "NAME_NN" for a sequence (NAME: opts->name, or when NULL
 * es_study_interp_default_name's). Returns buf. */
ES_API const char *es_study_interp_name(const es_study_interp_opts *opts, char *buf, size_t n);
/* The result name the `interp` command stores under when none is given:
 * the output's base name without its extension and without the frame
 * conversion ('cat_%02d.obj' -> 'cat'; "interp" when nothing is left).
 * Returns buf. */
ES_API const char *es_study_interp_default_name(const char *output, char *buf, size_t n);

/* ---- shape models for other tools ---------------------------------------- */

/* What es_study_export_statismo exports: a stored edge-length PCA
 * (pca_name; NULL and gpa_name NULL: the PCA es_study_pca_load picks) or
 * the Procrustes PCA of a stored GPA result (gpa_name). */
typedef struct es_study_statismo_opts {
    const char *pca_name, *gpa_name;   /* at most one */
    int64_t ncomp;          /* modes (0: every mode of a GPA; min(10, K) of a PCA,
                               each of which costs two embeddings) */
    double sd;              /* edge-length PCA: embed mean -/+ sd standard deviations
                               along each PC (default 1) */
    double noise_variance;  /* < 0 (default): 0 for an edge-length PCA, the PPCA
                               estimate of a GPA's (the variance the kept modes leave,
                               per remaining coordinate) */
    const char *command;    /* recorded in the model's builder parameters */
    es_embed_opts embed;    /* the embeddings' solver options */
} es_study_statismo_opts;
ES_API void es_study_statismo_opts_init(es_study_statismo_opts *opts);

typedef struct es_study_statismo_report {
    char source[256];       /* "pca/<name>" or "gpa/<name>" */
    int64_t ncomp, nverts, nfaces;
    double noise_variance;
    /* edge-length PCA only (0 otherwise): the worst embedding of the 2K + 1
     * points (RMS ratio, bending against the prior) and the largest
     * |X(+c) + X(-c) - 2 X(0)| / |X(+c) - X(-c)| over the PCs: how far the
     * meshes are from linear in the PC coefficient over -/+ c sd */
    double worst_rms_ratio, worst_bend_ratio, nonlinearity;
} es_study_statismo_report;

/* Write a statismo shape model (es_statismo_write) to path.
 * Edge-length PCA: the mean X(0) is the embedding of the PCA's mean (the
 * point mean[FILTER] of its rows) and X(+-c) of mean -/+ c sd along each PC
 * (mean[FILTER] + c*pc:K), each embedded near the prior of its row weights
 * in the store's frame as es_study_embed does; the linearization
 * d_k = (X(+c) - X(-c)) / 2c (mesh change per sd of PC k) gives the model
 * X(0) + D a, a ~ N(0, I), written with orthonormal modes: the principal
 * axes U of D with variances s^2 (D = U S W^T), sample coefficients
 * W^T (z_k / sd_k). GPA: the Procrustes mean, the tangent PCA's loadings
 * as modes and sdev^2 as variances (dim 3 only). Progress: "statismo:
 * embedding". ES_EINVAL for a store without triangles, both results given,
 * sd <= 0 or more modes than the result has; ES_ENOTFOUND for a missing
 * result; the embedding's errors (a point that leaves edge-length space
 * names its edge: give a smaller sd). report may be NULL. */
ES_API es_status es_study_export_statismo(es_ctx *ctx, es_store *store,
                                          const es_study_statismo_opts *opts, const char *path,
                                          es_study_statismo_report *report);

#ifdef __cplusplus
}
#endif
#endif
