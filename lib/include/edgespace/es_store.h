/* lib/include/edgespace/es_store.h — the HDF5 shape store.
 *
 * One file holds one topology, N shapes (rows) in correspondence, their
 * scale-normalized edge lengths (N x E; row i is shape i, which is the same
 * memory as an E x N column-major es_mat with ld = E), scales, vertex
 * positions (N x V x 3) and string labels, plus analysis results under
 * /analysis with provenance. datasets-spec/store-format.md is the exact
 * layout. Rows are named by unique ids.
 *
 * A store handle is not thread-safe; use one per thread.
 */
#ifndef EDGESPACE_ES_STORE_H
#define EDGESPACE_ES_STORE_H

#include "es_core.h"
#include "es_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct es_store es_store;

typedef enum es_store_mode {
    ES_STORE_READ = 0,
    ES_STORE_WRITE = 1   /* read and write an existing store */
} es_store_mode;

/* Open an existing store; checks the format version. */
ES_API es_status es_store_open(es_ctx *ctx, const char *path, es_store_mode mode,
                               es_store **out);
ES_API void es_store_close(es_store *store);

ES_API int64_t es_store_nrows(const es_store *store);
ES_API int64_t es_store_nedges(const es_store *store);
ES_API int64_t es_store_nverts(const es_store *store);
ES_API int64_t es_store_nfaces(const es_store *store);
ES_API const char *es_store_path(const es_store *store);

/* The stored topology (reference positions: those of row 0, or none for an
 * empty store). Caller owns *out. */
ES_API es_status es_store_mesh(es_ctx *ctx, es_store *store, es_mesh **out);

/* Normalized lengths of rows [row0, row0 + n) into out (E x n, column j =
 * row row0 + j). Reads only those rows. */
ES_API es_status es_store_read_lengths(es_ctx *ctx, es_store *store, int64_t row0, int64_t n,
                                       es_mat out);
/* Lengths of an arbitrary list of rows (E x nrows). */
ES_API es_status es_store_read_lengths_rows(es_ctx *ctx, es_store *store, const int64_t *rows,
                                            int64_t nrows, es_mat out);
/* Scales (sum of raw edge lengths) of all N rows. */
ES_API es_status es_store_read_scales(es_ctx *ctx, es_store *store, double *scales /* N */);
/* Vertex positions of one row, as ingested (3 x V). */
ES_API es_status es_store_read_positions(es_ctx *ctx, es_store *store, int64_t row,
                                         double *xyz);

/* Row ids and labels. Borrowed strings, valid until the store is closed. */
ES_API const char *es_store_row_id(const es_store *store, int64_t row);
ES_API int64_t es_store_find_row(const es_store *store, const char *id); /* -1 if absent */
ES_API int64_t es_store_ncolumns(const es_store *store);
ES_API const char *es_store_column_name(const es_store *store, int64_t col);
ES_API int64_t es_store_find_column(const es_store *store, const char *name);
ES_API const char *es_store_label(const es_store *store, int64_t row, int64_t col);

/* Rows matching a filter "col=value[,col=value...]" (all must hold; NULL or
 * "" selects every row), in row order. *rows is allocated with the ctx
 * allocator (es_free). Unknown columns fail with ES_ENOTFOUND. */
ES_API es_status es_store_select(es_ctx *ctx, const es_store *store, const char *filter,
                                 int64_t **rows, int64_t *nrows);

/* ---- analysis results -------------------------------------------------
 * Results live under /analysis/<kind>/<name>/ (kind: pca, mean, diff,
 * point, gpa, compare, embed, ...). Writing a result that exists replaces
 * it. Each result group carries provenance attributes (command, tool
 * version, UTC time, rows used) set by es_store_result_begin. */
typedef struct es_provenance {
    const char *command;     /* the command line or API call that made it */
    const int64_t *rows;     /* rows used (NULL with nrows = -1: all rows) */
    int64_t nrows;
    const char *params;      /* free-form "key=value; ..." parameters, or NULL */
} es_provenance;

/* Create (or replace) /analysis/<kind>/<name> with its provenance. */
ES_API es_status es_store_result_begin(es_ctx *ctx, es_store *store, const char *kind,
                                       const char *name, const es_provenance *prov);
/* Datasets inside a result group: `path` is "<kind>/<name>/<dataset>". */
ES_API es_status es_store_put_matrix(es_ctx *ctx, es_store *store, const char *path,
                                     es_mat m);      /* stored as cols x rows (row = column of m) */
ES_API es_status es_store_put_vector(es_ctx *ctx, es_store *store, const char *path,
                                     const double *v, int64_t n);
ES_API es_status es_store_put_ints(es_ctx *ctx, es_store *store, const char *path,
                                   const int64_t *v, int64_t n);
ES_API es_status es_store_put_strings(es_ctx *ctx, es_store *store, const char *path,
                                      const char *const *s, int64_t n);
ES_API es_status es_store_put_attr(es_ctx *ctx, es_store *store, const char *path,
                                   const char *key, const char *value);
/* Read back: *m->data / *v allocated with the ctx allocator (es_free). */
ES_API es_status es_store_get_matrix(es_ctx *ctx, es_store *store, const char *path,
                                     es_mat *m);
ES_API es_status es_store_get_vector(es_ctx *ctx, es_store *store, const char *path,
                                     double **v, int64_t *n);
ES_API es_status es_store_get_ints(es_ctx *ctx, es_store *store, const char *path,
                                   int64_t **v, int64_t *n);
/* Attribute value copied into buf (truncated to n bytes with NUL). */
ES_API es_status es_store_get_attr(es_ctx *ctx, es_store *store, const char *path,
                                   const char *key, char *buf, size_t n);
/* 1 if the result or dataset exists, else 0. */
ES_API int es_store_has(es_store *store, const char *path);
/* Names of the results of one kind (es_free each and the array). */
ES_API es_status es_store_list_results(es_ctx *ctx, es_store *store, const char *kind,
                                       char ***names, int64_t *n);

#ifdef __cplusplus
}
#endif
#endif
