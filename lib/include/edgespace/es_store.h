/* lib/include/edgespace/es_store.h — the HDF5 shape store.
 *
 * One file holds one topology, N shapes (rows) in correspondence, their
 * scale-normalized edge lengths (N x E; row i is shape i, which is the same
 * memory as an E x N column-major es_mat with ld = E), scales, vertex
 * positions (N x V x 3) and string labels, plus analysis results under
 * /analysis with provenance. datasets-spec/store-format.md is the exact
 * layout. Rows are named by unique ids. Landmark stores may have no faces
 * (an edge list, "truss") or no topology at all: es_topology_kind below.
 *
 * A store handle is not thread-safe; use one per thread.
 *
 * Writes are all-or-nothing. The store file is never modified in place: a
 * handle opened with ES_STORE_WRITE (or made by es_store_create) writes to a
 * private working copy beside the store (".<name>.tmp-<pid>-<n>", made at
 * the first write), and es_store_commit (also run by es_store_close)
 * replaces the store with it by an atomic rename() after fsync. A process
 * that fails or is killed before the commit leaves the store byte-for-byte
 * as it was; its stale working copy is removed by the next writer. The
 * first write refuses (ES_EIO) if another writer replaced the store since
 * this handle opened it, and a commit if it was replaced since the copy.
 */
#ifndef EDGESPACE_ES_STORE_H
#define EDGESPACE_ES_STORE_H

#include "es_core.h"
#include "es_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct es_store es_store;

/* What the store's topology is (format version 2, root attribute
 * topology_kind; version 1 stores are meshes):
 *  - MESH:  triangle faces and the edges they make (es_mesh.h);
 *  - TRUSS: an edge list of vertex (landmark) pairs and no faces: lengths
 *           and length statistics work, es_store_mesh does not;
 *  - NONE:  no faces and no edges (landmark configurations only): positions,
 *           ids and labels; E = 0, and every length operation
 *           (es_store_read_lengths, _rows, _scales, PCA, ...) fails with
 *           ES_EINVAL "store has no edges: it holds landmarks only". */
typedef enum es_topology_kind {
    ES_TOPOLOGY_MESH = 0,
    ES_TOPOLOGY_TRUSS = 1,
    ES_TOPOLOGY_NONE = 2
} es_topology_kind;

/* "mesh", "truss" or "none" (static string; "?" for other values). */
ES_API const char *es_topology_kind_name(es_topology_kind kind);

typedef enum es_store_mode {
    ES_STORE_READ = 0,
    ES_STORE_WRITE = 1,  /* read and write an existing store; a result is never
                            written over one of the same name (ES_EEXIST) */
    ES_STORE_REPLACE = 2 /* ES_STORE_WRITE, and results written through this
                            handle replace those of the same name (--replace) */
} es_store_mode;

/* Open an existing store. Everything the file says is checked once, here,
 * before any of it is used: the format version, every dataset's type,
 * shape and row count against the others and against the bytes the file
 * holds, the topology's indices (faces within the vertices, edges sorted,
 * unique and those of the faces), the scales, unique non-empty ids, the
 * label columns, and every string against HDF5's heap (strings are decoded
 * by the store itself, not by libhdf5, whose heap reader crashes on a
 * corrupt file). Fails with ES_ENOTFOUND if the file does not exist,
 * ES_EFORMAT naming the dataset and what disagrees if it is not a store (or
 * of another format version, or corrupt). */
ES_API es_status es_store_open(es_ctx *ctx, const char *path, es_store_mode mode,
                               es_store **out);
/* Switch a write handle between ES_STORE_WRITE (replace 0) and
 * ES_STORE_REPLACE (1) for the results written from now on (Python's
 * replace= on one call). ES_EINVAL on a read handle. */
ES_API es_status es_store_set_replace(es_ctx *ctx, es_store *store, int replace);
/* Create a new, empty store (N = 0) for `mesh`'s topology, open for
 * writing. Nothing appears at `path` until es_store_commit/es_store_close.
 * Fails with ES_EEXIST if `path` exists. */
ES_API es_status es_store_create(es_ctx *ctx, const char *path, const es_mesh *mesh,
                                 es_store **out);
/* Create a new, empty store without faces, open for writing: a "truss"
 * store over nedges vertex pairs (edges: 2 x nedges, each (min, max) with
 * min < max < nverts, sorted lexicographically, no repeats; ES_EINVAL
 * otherwise), or, with nedges = 0 (edges may be NULL), a store of vertex
 * positions only (ES_TOPOLOGY_NONE). Its fingerprint is FNV-1a 64 over
 * (nverts, nedges, the 2E indices) for a truss, over nverts alone for none.
 * Written as format version 2; otherwise as es_store_create. */
ES_API es_status es_store_create_edges(es_ctx *ctx, const char *path, int64_t nverts,
                                       int64_t nedges, const int64_t *edges, es_store **out);
/* Publish what was written so far (atomic rename over the store; no-op if
 * nothing was written). The handle stays usable; later writes start a new
 * working copy. On failure nothing is published and the handle refuses
 * further writes. */
ES_API es_status es_store_commit(es_ctx *ctx, es_store *store);
/* Commit pending writes and close; the handle is freed either way. Returns
 * the commit's status: ES_OK (also when there was nothing to commit), the
 * commit's failure (its message in the store's ctx and, for callers that
 * ignore the status, a warning through the log callback; the store is then
 * as it was before the writes), or ES_EIO for pending writes of a handle an
 * earlier failure broke (dropped; the ctx's message is still that
 * failure's). NULL: ES_OK. */
ES_API es_status es_store_close(es_store *store);
/* Close, discarding every uncommitted write. NULL: no-op. */
ES_API void es_store_abort(es_store *store);
/* Discard every uncommitted write and go on with the store as it is
 * published (reloaded, as es_store_open loads it); also clears a failed
 * write's refusal of further writes. ES_EINVAL for a new store never
 * committed (abort it). */
ES_API es_status es_store_rollback(es_ctx *ctx, es_store *store);
/* 1 if the handle holds uncommitted writes, else 0. */
ES_API int es_store_pending(const es_store *store);

/* A number that changes whenever this handle starts a write (rows,
 * results, attributes, deletions) or rolls writes back: a cache of values read through the
 * handle is current while the number it was made at is. Other handles' and
 * other processes' writes are not counted (a handle reads the file it
 * opened). */
ES_API uint64_t es_store_generation(const es_store *store);
ES_API int64_t es_store_nrows(const es_store *store);
ES_API int64_t es_store_nedges(const es_store *store);
ES_API int64_t es_store_nverts(const es_store *store);
ES_API int64_t es_store_nfaces(const es_store *store);   /* 0 unless a mesh store */
ES_API es_topology_kind es_store_topology_kind(const es_store *store);
ES_API const char *es_store_path(const es_store *store);
/* 1 if path names an existing HDF5 file (a store, say), else 0: outputs
 * that would overwrite one refuse with this. */
ES_API int es_store_is_hdf5(const char *path);
/* Topology fingerprint (es_mesh_fingerprint of the stored faces), 16 hex
 * digits. Borrowed, valid until close. */
ES_API const char *es_store_fingerprint(const es_store *store);

/* The stored face list (3 x F, 0-based) and edge list (2 x E, (min, max),
 * sorted), as es_mesh defines them. Nothing is read when F (or E) is 0. */
ES_API es_status es_store_read_faces(es_ctx *ctx, es_store *store, int64_t *faces);
ES_API es_status es_store_read_edges(es_ctx *ctx, es_store *store, int64_t *edges);

/* Rows to append: n shapes in the store's topology. */
typedef struct es_store_rows {
    int64_t n;
    const char *const *ids;            /* n unique, non-empty ids */
    const char *const *source_paths;   /* n, or NULL (stored as "") */
    const char *const *content_hashes; /* n, or NULL (stored as "") */
    const double *lengths;             /* E x n normalized lengths (column = row);
                                          ignored (may be NULL) when E = 0 */
    const double *scales;              /* n, finite and > 0; ignored when E = 0 */
    const double *xyz;                 /* 3V x n positions as ingested */
    int64_t ncols;                     /* label columns given */
    const char *const *colnames;       /* ncols names (no '/', not '.' or '..') */
    const char *const *labels;         /* n x ncols: value of column c of row i is
                                          labels[i * ncols + c] */
} es_store_rows;

/* Append rows (to the working copy; see es_store_commit). Label columns
 * new to the store are added with "" in the existing rows; store columns
 * not given get "" in the new rows. Fails with ES_EEXIST on an id that is
 * in the store or given twice, ES_EINVAL on a non-finite length or a bad
 * scale, ES_ERANGE on coordinates outside 1e-30..1e30 (extent, magnitude)
 * or more than ES_STORE_MAX_COLUMNS label columns (names of at most 500
 * bytes); nothing is written then. */
#define ES_STORE_MAX_COLUMNS 2000
ES_API es_status es_store_append(es_ctx *ctx, es_store *store, const es_store_rows *rows);

/* The stored topology (reference positions: those of row 0, or none for an
 * empty store). Caller owns *out. A truss or landmarks-only store has no
 * faces and so no mesh: ES_EINVAL says so (length statistics do not need
 * it; read the edges with es_store_read_edges). */
ES_API es_status es_store_mesh(es_ctx *ctx, es_store *store, es_mesh **out);

/* Normalized lengths of rows [row0, row0 + n) into out (E x n, column j =
 * row row0 + j). Reads only those rows. */
ES_API es_status es_store_read_lengths(es_ctx *ctx, es_store *store, int64_t row0, int64_t n,
                                       es_mat out);
/* Lengths of an arbitrary list of rows (E x nrows). */
ES_API es_status es_store_read_lengths_rows(es_ctx *ctx, es_store *store, const int64_t *rows,
                                            int64_t nrows, es_mat out);
/* Scales (sum of raw edge lengths) of all N rows. A store without edges
 * has none: ES_EINVAL. */
ES_API es_status es_store_read_scales(es_ctx *ctx, es_store *store, double *scales /* N */);
/* Vertex positions of one row, as ingested (3 x V; 2D landmarks have
 * z = 0). */
ES_API es_status es_store_read_positions(es_ctx *ctx, es_store *store, int64_t row,
                                         double *xyz);

/* Row ids and labels. Borrowed strings, valid until the store is closed. */
ES_API const char *es_store_row_id(const es_store *store, int64_t row);
ES_API int64_t es_store_find_row(const es_store *store, const char *id); /* -1 if absent */
/* Source path and content hash ("fnv1a64:<16 hex>") recorded at ingest. */
ES_API const char *es_store_source_path(const es_store *store, int64_t row);
ES_API const char *es_store_content_hash(const es_store *store, int64_t row);
ES_API int64_t es_store_ncolumns(const es_store *store);
ES_API const char *es_store_column_name(const es_store *store, int64_t col);
ES_API int64_t es_store_find_column(const es_store *store, const char *name);
ES_API const char *es_store_label(const es_store *store, int64_t row, int64_t col);

/* For the message about a name the store does not have: the label columns
 * closest to `name` by edit distance, as " (did you mean 'group'?)", or the
 * first few columns when none is close (" (columns: file, id, ...)"); for
 * es_store_value_hint, the values of column col (col -1: the row ids). ""
 * when there is nothing to offer. Writes at most n bytes to buf. */
ES_API void es_store_column_hint(const es_store *store, const char *name, char *buf, size_t n);
ES_API void es_store_value_hint(const es_store *store, int64_t col, const char *value, char *buf,
                                size_t n);
/* The same for a result /analysis/<kind>/<name> the store does not have:
 * the closest names of that kind (" (did you mean 'faces'?)"), else those
 * there are (" (pca results: a, b)"), else the kinds present (" (no pca
 * results; the store has: gpa, model)") or " (the store holds no results)".
 * Leaves ctx's error message as it was. */
ES_API void es_store_result_hint(es_ctx *ctx, es_store *store, const char *kind, const char *name,
                                 char *buf, size_t n);

/* Rows matching a filter "col=value[,col=value...]" (all must hold; NULL or
 * "" selects every row; the column "id" means the row id unless a label
 * column has that name), in row order. A value that holds ',' is written
 * quoted, col="a,b" (any characters but '"'); ES_EFORMAT on a quote that
 * is not closed or not followed by ',' or the end. *rows is allocated with the ctx
 * allocator (es_free). Unknown columns fail with ES_ENOTFOUND naming the
 * closest ones; a value that no row has selects nothing, with a warning
 * (log callback) that names the closest values. */
ES_API es_status es_store_select(es_ctx *ctx, const es_store *store, const char *filter,
                                 int64_t **rows, int64_t *nrows);

/* ---- analysis results -------------------------------------------------
 * Results live under /analysis/<kind>/<name>/ (kind: pca, mean, diff,
 * point, gpa, compare, embed, ...). Writing a result that exists is refused
 * (ES_EEXIST naming it) unless the handle was opened with ES_STORE_REPLACE,
 * which replaces it: never silently. Each result group carries provenance attributes (command, tool
 * version, UTC time, rows used) set by es_store_result_begin: attributes
 * command, tool_version, time, params, store_nrows, and the dataset
 * input_rows (int64 row indices). Writes go to the working copy and become
 * visible, all together, at es_store_commit/es_store_close. */
typedef struct es_provenance {
    const char *command;     /* the command line or API call that made it */
    const int64_t *rows;     /* rows used (NULL with nrows = -1: all rows) */
    int64_t nrows;
    const char *params;      /* free-form "key=value; ..." parameters, or NULL */
} es_provenance;

/* ES_OK if /analysis/<kind>/<name> may be written through this handle (the
 * name is free, or the handle replaces results), else ES_EEXIST naming it;
 * ES_EINVAL for a bad kind or name. The analyses of es_study.h call it
 * before they compute, so that a long one is not run only to be refused. */
ES_API es_status es_store_result_check(es_ctx *ctx, es_store *store, const char *kind,
                                       const char *name);
/* Create /analysis/<kind>/<name> with its provenance (replacing one of that
 * name only with ES_STORE_REPLACE; es_store_result_check's rule). */
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
/* Numeric attributes, stored as numbers (scalar float64 / int64), so that
 * h5py, R and the CSV tables read numbers. */
ES_API es_status es_store_put_attr_double(es_ctx *ctx, es_store *store, const char *path,
                                          const char *key, double value);
ES_API es_status es_store_put_attr_int(es_ctx *ctx, es_store *store, const char *path,
                                       const char *key, int64_t value);
/* Read back: *m->data / *v allocated with the ctx allocator (es_free). */
ES_API es_status es_store_get_matrix(es_ctx *ctx, es_store *store, const char *path,
                                     es_mat *m);
ES_API es_status es_store_get_vector(es_ctx *ctx, es_store *store, const char *path,
                                     double **v, int64_t *n);
ES_API es_status es_store_get_ints(es_ctx *ctx, es_store *store, const char *path,
                                   int64_t **v, int64_t *n);
/* A 1-D string dataset: *v gets n strings (es_free each and the array). */
ES_API es_status es_store_get_strings(es_ctx *ctx, es_store *store, const char *path,
                                      char ***v, int64_t *n);
/* Attribute value copied into buf (truncated to n bytes with NUL); a
 * numeric attribute as text (%.17g, or the integer). */
ES_API es_status es_store_get_attr(es_ctx *ctx, es_store *store, const char *path,
                                   const char *key, char *buf, size_t n);
/* A numeric attribute, or one stored as the text of a number (results
 * written before numeric attributes existed); ES_EFORMAT otherwise. */
ES_API es_status es_store_get_attr_double(es_ctx *ctx, es_store *store, const char *path,
                                          const char *key, double *value);
/* 1 if the result or dataset exists, else 0. */
ES_API int es_store_has(es_store *store, const char *path);
/* Names of the results of one kind, in name order; kind NULL or "": the
 * kinds present. *names is NULL when there are none. es_free each name and
 * the array. */
ES_API es_status es_store_list_results(es_ctx *ctx, es_store *store, const char *kind,
                                       char ***names, int64_t *n);
/* Names of the attributes of a result or dataset ("kind/name[/dataset]"),
 * in name order; *keys NULL when there are none. es_free each and the
 * array. */
ES_API es_status es_store_list_attrs(es_ctx *ctx, es_store *store, const char *path,
                                     char ***keys, int64_t *n);
/* Delete result kind/name; like every write it becomes visible at
 * es_store_commit/es_store_close, and a failure leaves the store as it
 * was. Beside a store of version 3 its file is removed; inside one of
 * version 1 or 2 the group is unlinked in the working copy, and HDF5 does
 * not give the bytes back until the file is repacked (h5repack).
 * ES_ENOTFOUND if there is no such result. */
ES_API es_status es_store_delete_result(es_ctx *ctx, es_store *store, const char *kind,
                                        const char *name);

/* The store's format version (datasets-spec/store-format.md): 3 for every
 * store written since 0.2, whose results are files beside it
 * (<store>.results/<kind>/<name>.h5, published without copying the store);
 * 1 or 2 for a store of an earlier release, whose results stay inside it
 * (each commit copies the store) until it is upgraded. */
ES_API int es_store_format_version(const es_store *store);
/* Upgrade a store of version 1 or 2, opened for writing with nothing
 * uncommitted, to version 3: its results are moved to files beside it and
 * the store is published once more (one copy); ES_OK at once for version 3.
 * The result files are published before the store, so a failure or crash
 * part way leaves the old store as it was (the new files are not yet its). */
ES_API es_status es_store_upgrade(es_ctx *ctx, es_store *store);

#ifdef __cplusplus
}
#endif
#endif
