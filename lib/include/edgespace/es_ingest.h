/* lib/include/edgespace/es_ingest.h — manifests, ingest and export: meshes
 * in correspondence (plus their labels) into an HDF5 store, and back out;
 * statismo shape models written and read (at the end).
 *
 * A manifest (datasets-spec/manifest-format.md) is a CSV file read with
 * libcsv: a header row with a `file` column (mesh paths relative to the
 * manifest's directory), an optional `id` column, and any label columns.
 * Quoted fields (with commas, quotes and newlines), UTF-8, CRLF line ends and
 * a leading byte-order mark are accepted; every error names the manifest and
 * the line.
 *
 * Ingest is all-or-nothing, in bounded memory: inputs are read and
 * validated a block at a time (readable mesh, same vertex count and face
 * list as the store or as the first input, a valid oriented 2-manifold,
 * finite positive scale, unique ids), each block's rows are appended to the
 * store's working copy, and only after the last block is the store replaced
 * atomically (see es_store.h). A failure or a kill at any moment leaves the
 * store exactly as it was. Memory holds one block (es_ingest_opts.block_rows)
 * plus a few dozen bytes per input, whatever the number of inputs.
 *
 * Duplicates: an input whose id is in the store already and whose content
 * hash equals the stored row's is skipped (re-ingesting a manifest is a
 * no-op that leaves the file untouched); the same id with different content
 * fails with ES_EEXIST. Identical content under a new id is ingested, with a
 * warning naming the row it duplicates.
 */
#ifndef EDGESPACE_ES_INGEST_H
#define EDGESPACE_ES_INGEST_H

#include "es_core.h"
#include "es_io.h"
#include "es_store.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A parsed manifest: plain arrays, owned, freed by es_manifest_free. */
typedef struct es_manifest {
    char *path;        /* as given */
    char *dir;         /* directory that `file` paths are relative to */
    int64_t ncols;
    char **colnames;   /* ncols header names, in file order */
    int64_t nrows;
    char **cells;      /* nrows x ncols, row-major: cells[r * ncols + c] */
    int64_t *lines;    /* line (1-based) where each row starts */
    int64_t file_col;  /* column index of `file` */
    int64_t id_col;    /* column index of `id`, or -1 */
    char **ids;        /* nrows row ids: the id column, else file name
                          without its extension */
} es_manifest;

/* Read and check a manifest: header present and unique non-empty names,
 * a `file` column, every row with as many fields as the header, non-empty
 * file (and id) cells, valid UTF-8, unique ids. ES_EIO if unreadable,
 * ES_EFORMAT ("manifest 'm.csv' line 7: ...") otherwise. */
ES_API es_status es_manifest_read(es_ctx *ctx, const char *path, es_manifest **out);
/* The same from memory; `name` is used in messages, `dir` for paths. */
ES_API es_status es_manifest_parse(es_ctx *ctx, const char *name, const char *dir,
                                   const char *buf, size_t len, es_manifest **out);
ES_API void es_manifest_free(es_ctx *ctx, es_manifest *m);

/* Row id of a mesh path: its file name without the last extension
 * ("a/b/cat-01.obj" -> "cat-01"). Writes at most n bytes with NUL. */
ES_API void es_id_from_path(const char *path, char *buf, size_t n);

/* Content hash of a byte buffer: "fnv1a64:" + 16 lowercase hex digits of
 * the 64-bit FNV-1a hash (25 bytes with NUL). */
ES_API void es_content_hash(const void *buf, size_t len, char out[25]);

typedef struct es_ingest_opts {
    int create;              /* create the store if it does not exist (1) */
    es_mesh_format format;   /* ES_FORMAT_AUTO: from each file's extension */
    int threads;             /* files read and parsed at once; 0 (default): one
                                per online CPU, at most 16. Extra threads use
                                contexts of their own, so their temporary
                                buffers come from malloc, not ctx's allocator;
                                1 keeps every allocation on ctx. Results do not
                                depend on it. */
    int64_t block_rows;      /* inputs read and checked before their rows are
                                written to the store's working copy (the memory
                                ingest holds); 0 (default): about 64 MB of
                                positions and lengths, and at least one per
                                thread. Results do not depend on it. */
} es_ingest_opts;

ES_API void es_ingest_opts_init(es_ingest_opts *opts);

typedef struct es_ingest_report {
    int64_t rows_added;      /* rows appended */
    int64_t rows_skipped;    /* inputs already in the store (same id and content) */
    int64_t rows_total;      /* rows in the store afterwards */
    int64_t bytes_read;      /* bytes of mesh files read and parsed (by all ranks) */
    int created;             /* 1 if the store was created */
    int64_t bytes_read_rank; /* of bytes_read, those this rank read (all of them on one
                                process; datasets-spec/parallel.md: what each rank reads) */
} es_ingest_report;

/* Ingest the meshes of a manifest (labels from its columns) into the store
 * at store_path. opts NULL: defaults. report may be NULL. On a context
 * joined to an MPI job (es_parallel.h) this and es_ingest_files are
 * collective: each rank reads its share of the meshes and the values are
 * written with collective parallel-HDF5 writes; the store is the one a
 * single process makes, the report and status the same on every rank
 * (datasets-spec/parallel.md). */
ES_API es_status es_ingest_manifest(es_ctx *ctx, const char *store_path,
                                    const char *manifest_path, const es_ingest_opts *opts,
                                    es_ingest_report *report);
/* Ingest a list of mesh files (ids from file names, no labels). */
ES_API es_status es_ingest_files(es_ctx *ctx, const char *store_path, int64_t nfiles,
                                 const char *const *files, const es_ingest_opts *opts,
                                 es_ingest_report *report);

/* ---- export ------------------------------------------------------------ */


/* Write rows of a store as CSV: header "id,scale,<a>-<b>,..." (one column
 * per edge, named by its 0-based vertex pair), then one line per row with
 * the normalized lengths (%.17g, so values read back exactly). rows NULL
 * with nrows = -1: every row. raw != 0 writes scale x length instead. */
ES_API es_status es_export_lengths_csv(es_ctx *ctx, es_store *store, const int64_t *rows,
                                       int64_t nrows, int raw, const char *path);
/* Write each row's stored positions as a mesh file DIR/<id>.<ext> (ext from
 * format: obj, ply or off; ES_FORMAT_AUTO means OBJ). The directory is
 * created, with any missing parents, if absent. */
ES_API es_status es_export_meshes(es_ctx *ctx, es_store *store, const int64_t *rows,
                                  int64_t nrows, const char *dir, es_mesh_format format);

/* ---- statismo shape models --------------------------------------------
 * A linear shape model mean + sum_k b_k sqrt(variance_k) basis_k (b ~
 * N(0, I)) over one triangle mesh, written in the statismo 0.9 HDF5 layout
 * that statismo (StatisticalModel IO) and scalismo (StatismoIO) load:
 * datasets-spec/statismo.md is the exact layout. Coordinates are
 * vertex-interleaved (x0 y0 z0 x1 ...), as statismo's sample vectors are;
 * they are stored in single precision, as statismo keeps them.
 * es_study_export_statismo builds one from a stored PCA or GPA. */
typedef struct es_statismo_model {
    int64_t nverts, nfaces;
    const int64_t *faces;      /* 3 x F, 0-based (the representer's cells) */
    const double *mean;        /* 3 x V: the mean shape, also the representer's
                                  reference mesh */
    int64_t ncomp;             /* K >= 1 modes */
    const double *basis;       /* 3V x K, column k = mode k (orthonormal columns) */
    const double *variance;    /* K: variance along each mode */
    double noise_variance;     /* the PPCA noise variance (>= 0) */
    int64_t nscores;           /* samples with coefficients (0: none) */
    const double *scores;      /* K x nscores: sample j's coefficients, in units of
                                  each mode's standard deviation */
    const char *builder;       /* modelinfo builder name (NULL: "edgespace") */
    int64_t ndata, nparams;    /* key/value strings of the builder's dataInfo
                                  and parameters groups */
    const char *const *data_keys, *const *data_values;
    const char *const *param_keys, *const *param_values;
} es_statismo_model;

/* Write m to path (replaced only once complete). ES_EINVAL on a model
 * without vertices, faces or modes, a face index out of range, non-finite
 * values or negative variances; ES_ERANGE beyond 2^31 vertices; ES_EEXIST
 * if path is an HDF5 file that is not a statismo model (a store, say). */
ES_API es_status es_statismo_write(es_ctx *ctx, const char *path, const es_statismo_model *m);
/* ES_OK if path ends in ".h5", the only name scalismo opens a model by
 * (StatisticalModelIOUtils); else ES_EINVAL naming the file to write
 * instead ("model.hdf5" -> "model.h5"). es_statismo_write checks it. */
ES_API es_status es_statismo_check_name(es_ctx *ctx, const char *path);

/* A statismo model read back (es_statismo_read; owned, es_statismo_data_free):
 * what edgespace, statismo or scalismo wrote, read as scalismo's
 * StatismoIO.readStatismoPDM reads it. */
typedef struct es_statismo_data {
    es_ctx *ctx;
    char dataset_type[32];     /* "POLYGON_MESH" or "POINT_SET" */
    int major, minor;          /* the format version (0.8, 0.9 or 1.x) */
    int64_t nverts, nfaces;    /* nfaces 0 for a point set */
    int64_t *faces;            /* 3 x F (NULL for a point set) */
    double *points;            /* 3 x V: the representer's reference points */
    double *mean;              /* 3 x V: the model's mean, vertex-interleaved */
    int64_t ncomp;
    double *basis;             /* 3V x K, column k = mode k (unit; 0.8's scaled basis
                                  divided by sqrt(variance) as scalismo does) */
    double *variance;          /* K */
    double noise_variance;
} es_statismo_data;

/* Read a statismo 3D shape model. ES_EFORMAT naming what is missing or
 * inconsistent (no representer, an IMAGE or VOLUME_MESH model, sizes that
 * disagree, a cell out of range, a non-finite value); ES_EIO if unreadable. */
ES_API es_status es_statismo_read(es_ctx *ctx, const char *path, es_statismo_data **out);
ES_API void es_statismo_data_free(es_statismo_data *m);

#ifdef __cplusplus
}
#endif
#endif
