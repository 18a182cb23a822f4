/* lib/include/edgespace/es_analysis.h — the statistics of es_stats.h and
 * the points of es_point.h run on a shape store, with their results kept in
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
 * tool version, time, rows used) and is replaced when written again.
 */
#ifndef EDGESPACE_ES_ANALYSIS_H
#define EDGESPACE_ES_ANALYSIS_H

#include "es_core.h"
#include "es_mesh.h"
#include "es_point.h"
#include "es_stats.h"
#include "es_store.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A source over store rows: all rows (rows NULL) or rows[0..nrows). Borrows
 * store and rows. */
ES_API es_status es_source_store(es_ctx *ctx, es_store *store, const int64_t *rows,
                                 int64_t nrows, es_source *out);

/* Normalized edge lengths (E) and scale of a mesh file whose face list is
 * that of `mesh` (ES_EMISMATCH otherwise, naming the file). */
ES_API es_status es_lengths_from_file(es_ctx *ctx, const es_mesh *mesh, const char *path,
                                      double *len, double *scale);

/* ---- means --------------------------------------------------------------- */

typedef struct es_group_result {
    es_ctx *ctx;
    int64_t nedges, ngroups;
    char **names;       /* ngroups group names ("all" without a grouping column) */
    double *means;      /* E x ngroups, column g */
    int64_t *counts;    /* rows per group */
    double *scales;     /* mean scale per group */
} es_group_result;
ES_API void es_group_result_free(es_group_result *r);

/* Means of the rows matching `filter` (NULL/"": all), one per value of
 * label column `by` (NULL: one group "all"), stored as mean/<name> when name
 * is non-NULL. out may be NULL. */
ES_API es_status es_analysis_mean(es_ctx *ctx, es_store *store, const char *name,
                                  const char *filter, const char *by, const char *command,
                                  es_group_result **out);

/* ---- PCA ------------------------------------------------------------------ */

/* Fit a PCA of the rows matching `filter` and store it as pca/<name>.
 * *out (may be NULL) gets the fit, *rows (may be NULL) the store rows
 * used (es_free), in score order. */
ES_API es_status es_analysis_pca(es_ctx *ctx, es_store *store, const char *name,
                                 const char *filter, const es_pca_opts *opts,
                                 const char *command, es_pca **out, int64_t **rows,
                                 int64_t *nrows);

/* Load pca/<name> (NULL: the only PCA in the store, else the one named
 * "default"). Scores are loaded too (nrows = rows fitted); *rows (may be
 * NULL) gets the store rows of the scores (es_free). */
ES_API es_status es_analysis_pca_load(es_ctx *ctx, es_store *store, const char *name,
                                      es_pca **out, int64_t **rows, int64_t *nrows);

/* ---- differences ------------------------------------------------------------ */

/* Rows matching `filter` whose label `column` equals `from` or `to` are
 * paired by label `key` (es_diff_paired's rules); stored as diff/<name>.
 * Indices in the result are store rows. out may be NULL. */
ES_API es_status es_analysis_diff(es_ctx *ctx, es_store *store, const char *name,
                                  const char *filter, const char *key, const char *column,
                                  const char *from, const char *to, const char *command,
                                  es_diff **out);

/* ---- points ----------------------------------------------------------------- */

/* Resolver of point leaves on a store (es_point_resolve_fn with userdata =
 * an es_analysis_resolver). pca_name: the PCA of pc:K (NULL: as
 * es_analysis_pca_load). mesh: the store's topology, for file: leaves. */
typedef struct es_analysis_resolver {
    es_store *store;
    const es_mesh *mesh;
    const char *pca_name;
    es_pca *pca;        /* loaded on first use; free with es_analysis_resolver_clear */
    double *scales;     /* all row scales, loaded on first use */
} es_analysis_resolver;
ES_API es_status es_analysis_resolve(es_ctx *ctx, void *resolver, es_point_leaf kind,
                                  const char *arg, int64_t index, double *vec, double *scale);
ES_API void es_analysis_resolver_clear(es_ctx *ctx, es_analysis_resolver *r);

/* Evaluate `expr` on the store (validity against the store's topology) and,
 * when name is non-NULL, store it as point/<name>. scale > 0 overrides the
 * scale rule of es_point.h. *vec (may be NULL) gets the lengths (es_free);
 * info (may be NULL) the report. */
ES_API es_status es_analysis_point(es_ctx *ctx, es_store *store, const char *name,
                                   const char *expr, const char *pca_name, double scale,
                                   const char *command, double **vec, es_point_info *info);

#ifdef __cplusplus
}
#endif
#endif
