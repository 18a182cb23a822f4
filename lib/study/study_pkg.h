/* lib/study/study_pkg.h — what the files of lib/study share. */
#ifndef EDGESPACE_STUDY_PKG_H
#define EDGESPACE_STUDY_PKG_H

#ifndef ES_MODULE_STUDY
#error "study/study_pkg.h is private to lib/study/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "edgespace/es_study.h"

/* A CSV table being written: to standard output for path "-", else to a
 * part file that replaces path only once complete (es__replace_begin). An
 * HDF5 file at path (a store given by mistake) is refused. */
typedef struct es__table_out {
    es__file_replace w;
    FILE *f;
    const char *path;
    es__file_set *set;   /* non-NULL: the file is staged there, not renamed at end */
} es__table_out;
es_status es__table_begin(es_ctx *ctx, const char *path, es__table_out *t);
/* Finish (rc ES_OK) or abandon (rc != ES_OK: the old file stays); returns
 * rc or the write error. */
es_status es__table_end(es_ctx *ctx, es__table_out *t, es_status rc);
/* ",<value>" with 17 significant digits (round trip). */
void es__table_number(FILE *f, double v);

/* "id,<every label column>,<names...>": one line per store row rows[i]
 * (n of them) with values[i + k n] in column k. */
es_status es__write_row_table(es_ctx *ctx, es_store *st, const char *path, int64_t n,
                              const int64_t *rows, int64_t ncol, const char *const *names,
                              const double *values);
/* n names "<prefix>1" .. "<prefix>n" (es__free_names). */
es_status es__numbered_names(es_ctx *ctx, const char *prefix, int64_t n, char ***names);
void es__free_names(es_ctx *ctx, char **names, int64_t n);

/* Reading a result's parts: "<kind>/<name>/<ds>" into buf; the dataset
 * read by type; a stored matrix (dataset [a][b], es_mat b x a) transposed
 * to a x b column-major (row i = dataset row i). */
es_status es__result_path(es_ctx *ctx, char *buf, size_t n, const char *kind, const char *name,
                          const char *ds);
es_status es__result_vector(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            const char *ds, double **v, int64_t *n);
es_status es__result_matrix(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            const char *ds, es_mat *m);
es_status es__result_ints(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                          const char *ds, int64_t **v, int64_t *n);
es_status es__result_strings(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                             const char *ds, char ***v, int64_t *n);
double *es__transpose_mat(es_ctx *ctx, es_mat m);

/* The tables of GPA and model results (export_tables.c): (ctx, store, kind,
 * name, path). */
#define ES__TABLE(fn) es_status fn(es_ctx *ctx, es_store *s, const char *kind, \
                                   const char *name, const char *path)
ES__TABLE(es__t_gpa_specimens);
ES__TABLE(es__t_gpa_aligned);
ES__TABLE(es__t_gpa_mean);
ES__TABLE(es__t_gpa_pca);
ES__TABLE(es__t_gpa_loadings);
ES__TABLE(es__t_model_anova);
ES__TABLE(es__t_model_coefficients);
ES__TABLE(es__t_model_weights);
ES__TABLE(es__t_model_pairwise);
ES__TABLE(es__t_model_lsmeans);
ES__TABLE(es__t_model_edges);
ES__TABLE(es__t_model_scores);
ES__TABLE(es__t_model_permutations);
#undef ES__TABLE

/* A model's requests as written (model_requests.c): --reference
 * "LEVEL|FACTOR=LEVEL,..." onto the columns (cols[v].reference points into
 * *held, a copy of spec that the caller frees after es_design_build);
 * --at "NAME=VALUE|mean,..." into at (nvars, NaN: the mean); --error
 * "TERM=ERROR" items into error (nterms, -1: the residual). */
es_status es__model_references(es_ctx *ctx, const es_formula *f, const char *spec, int64_t n,
                               es_model_column *cols, char **held);
es_status es__model_at(es_ctx *ctx, const es_design *d, const es_formula *f, const char *spec,
                       double *at);
es_status es__model_errors(es_ctx *ctx, const es_design *d, const char *const *spec,
                           int64_t count, int64_t *error);

/* "~ a + b" of a design's terms ("~ 1" without any) into buf. */
void es__model_null_label(const es_design *d, char *buf, size_t len);

/* Store a model as model/<o->name> (model_results.c). */
es_status es__model_save(es_ctx *ctx, es_store *s, const es_study_model_opts *o,
                         const es_study_model_result *r);
/* ---- embeddings: the rows for priors and their cache (prior.c, embed_cache.c) */

/* An es_study_rows of n rows with its arrays (3V x n aligned positions, E x n
 * dihedrals) for the caller to fill. */
/* The rows of a prior (n of them) and the embedder of mesh that uses them
 * against the context's memory limit (es_embed_check_memory), before
 * either is allocated. */
es_status es__study_rows_check_memory(es_ctx *ctx, const es_mesh *mesh, int64_t n);
es_status es__study_rows_new(es_ctx *ctx, int64_t n, int64_t nv, int64_t ne, es_study_rows **out,
                             double **aligned, double **alpha);
/* The rows over arrays they own from here on: aligned and alpha freed with
 * them, or, when map is set (map_len bytes from mmap: a cache file read in
 * place), lying in map, which they unmap. */
es_status es__study_rows_mapped(es_ctx *ctx, int64_t n, int64_t nv, int64_t ne, void *map,
                                size_t map_len, double *aligned, double *alpha,
                                es_study_rows **out);
void es__study_rows_arrays(const es_study_rows *r, const double **aligned, const double **alpha);
/* The cache's key for the store as it is now (reads the positions of rows
 * without a content hash). */
es_status es__study_cache_key(es_ctx *ctx, es_store *s, uint64_t *key);
/* The cached vertex order and rows for this key, or both NULL (no cache, or a
 * stale or damaged one: the log says which). Fails only without memory. */
es_status es__study_cache_load(es_ctx *ctx, es_store *s, uint64_t key, int64_t **order,
                               es_study_rows **rows);
/* Keep them for the next command; a failure is only logged. */
void es__study_cache_save(es_ctx *ctx, es_store *s, uint64_t key, const int64_t *order,
                          const es_study_rows *rows);

/* 1 if a point expression is one mesh's lengths (a row or a file with
 * coefficient 1): exactly realizable (embed_session.c). */
int es__study_point_is_one_mesh(es_ctx *ctx, const char *spec);

/* es_study_point_weights with an expression's leaves from `resolve` (NULL:
 * es_study_point's own, read afresh) on the store's topology mesh. */
es_status es__study_point_weights_via(es_ctx *ctx, es_store *store, const char *spec,
                                      const char *pca_name, es_point_resolve_fn resolve,
                                      void *ud, const es_mesh *mesh, double *lengths,
                                      double *scale, double *w);

/* A point's leaves kept for an embedding session (embed_leaves.c): the
 * leaves read from stored results (means, components, differences,
 * coefficients) resolved once and then copied, while the store's
 * generation is the one they were read at. Files and rows are read each
 * time (a file can change; a row is one read). */
typedef struct es__leaf_cache es__leaf_cache;
es_status es__leaf_cache_new(es_ctx *ctx, es_store *store, const es_mesh *mesh,
                            es__leaf_cache **out);
void es__leaf_cache_free(es__leaf_cache *c);
/* Point the cache at the PCA that pc:K leaves name (NULL: the default one)
 * and drop what the store's writes since have made stale; call before each
 * evaluation. */
es_status es__leaf_cache_ready(es__leaf_cache *c, const char *pca_name);
/* The es_point_resolve_fn; userdata: the cache. */
es_status es__leaf_cache_resolve(es_ctx *ctx, void *ud, es_point_leaf kind, const char *arg,
                                 int64_t index, double *vec, double *scale, double *w);

/* ---- embeddings and interpolation by the other papers' methods ------------ */

/* Store a mesh result as /analysis/embed/<name> (what es_study_store_embedding
 * stores, with the per-vertex values given: vdev may be NULL). */
es_status es__study_store_mesh_result(es_ctx *ctx, es_store *store, const char *name,
                                      const es_provenance *prov, const es_mesh *mesh,
                                      const double *vclos, const double *verr,
                                      const double *vdev, const double *target,
                                      const double *xyz, const es_embed_report *r,
                                      const char *init);

/* Frame i's file (the output pattern's, or the output itself for one
 * frame) and its result name (NAME_<i> in a sequence, else NAME), for
 * every interpolation method (interp_walk.c). */
void es__study_frame_names(const es_study_interp_opts *o, const char *name, int64_t i,
                           char *fname, size_t nf, char *rname, size_t nr);

/* The end of a walk (every interpolation method): with rc ES_OK, the
 * store committed (with a command), then the staged frame files renamed
 * into place; otherwise the files discarded and, unless writes were
 * pending before the walk (was_pending), what it stored rolled back (the
 * message of rc kept). */
es_status es__study_frames_done(es_ctx *ctx, es_store *store, const es_study_interp_opts *o,
                                es_status rc, int was_pending, es__file_set *files);

/* es_study_interp for opts->method other than edge-length, between two rows
 * (interp_methods.c); name: the result name (without the frame suffix). */
es_status es__study_interp_method(es_ctx *ctx, es_store *store, const es_study_interp_opts *o,
                                  const es_mesh *mesh, const char *name, int was_pending);

#endif
