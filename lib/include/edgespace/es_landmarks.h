/* lib/include/edgespace/es_landmarks.h — landmark data: TPS files and long
 * CSV tables.
 *
 * A landmark set is n specimens of k landmarks in d = 2 or 3 dimensions,
 * stored as es_procrustes.h expects: a k*d x n column-major matrix, one
 * specimen per column, x-block, y-block[, z-block]. Readers:
 *
 *  - TPS (F. James Rohlf's tpsDig format): per specimen "LM=k" (2D) or
 *    "LM3=k" (3D) followed by k coordinate lines, then optional "IMAGE=",
 *    "ID=", "SCALE=", "COMMENT=" lines. CURVES=/POINTS= blocks (outlines)
 *    are skipped with a warning; other unknown keys are skipped with one
 *    warning each. SCALE= multiplies the coordinates when apply_scale is set
 *    (what geomorph's readland.tps does); it is recorded either way.
 *  - Long CSV (../shared/data/landmarks_rshapes, the oracle inputs): a header
 *    naming columns specimen, landmark, x, y[, z] (any order, case-
 *    insensitive, other columns ignored), one row per landmark. Landmarks
 *    are numbered 1..k; every specimen must have each exactly once.
 *    Specimens keep the order of their first row.
 *  - Specimen labels (optional): a CSV whose first column (or the one named
 *    "specimen") holds specimen ids and whose other columns are labels
 *    (group, sex, ...). Every specimen of the landmark file must appear.
 *
 * CSV is read with libcsv (RFC 4180 quoting). Errors name the file and line:
 * "landmarks: skulls.tps:12: expected 2 coordinates, found 1".
 */
#ifndef EDGESPACE_ES_LANDMARKS_H
#define EDGESPACE_ES_LANDMARKS_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct es_landmarks {
    int64_t n;          /* specimens */
    int64_t k;          /* landmarks per specimen */
    int d;              /* 2 or 3 */
    double *xyz;        /* k*d x n, ld = k*d */
    char **ids;         /* n specimen ids */
    char **images;      /* n IMAGE= values (TPS; NULL entries where absent), or NULL */
    double *scale;      /* n SCALE= values (TPS; NaN where absent), or NULL */
    int64_t ncols;      /* label columns */
    char **colnames;    /* ncols names */
    char **labels;      /* n x ncols: labels[j * ncols + c] */
    es_ctx *ctx;        /* the allocator that owns all of the above */
} es_landmarks;

/* Read a TPS file. Caller owns *out (es_landmarks_free). ES_EIO if the file
 * cannot be read, ES_EFORMAT with file:line on malformed content,
 * ES_EMISMATCH when specimens differ in k or d, ES_ERANGE when the landmark
 * count is too large to hold (the message names the file). */
ES_API es_status es_landmarks_read_tps(es_ctx *ctx, const char *path, int apply_scale,
                                       es_landmarks **out);

/* Read a long CSV (specimen, landmark, x, y[, z]); specimens_path (or NULL)
 * gives labels. Errors as for TPS; ES_ENOTFOUND for a specimen without a
 * row in the specimens file. */
ES_API es_status es_landmarks_read_csv(es_ctx *ctx, const char *path,
                                       const char *specimens_path, es_landmarks **out);

/* Attach labels from a specimens CSV to a set read before (replaces any). */
ES_API es_status es_landmarks_read_specimens(es_ctx *ctx, es_landmarks *lm,
                                             const char *specimens_path);

/* Index of a label column by name, or -1. */
ES_API int64_t es_landmarks_find_column(const es_landmarks *lm, const char *name);

ES_API void es_landmarks_free(es_landmarks *lm);

/* "Truss" lengths: for each specimen, the lengths of nedges landmark pairs
 * (edges: 2 x nedges, 0-based landmark indices) into len (nedges x n,
 * column = specimen). ES_EINVAL on an index out of range or a pair with
 * equal ends. */
ES_API es_status es_landmarks_truss_lengths(es_ctx *ctx, const es_landmarks *lm,
                                            int64_t nedges, const int64_t *edges, es_mat len);

/* Read an edge list (2 numbers a line) or a triangulation (3 a line) of
 * 1-based landmark numbers; blank lines and '#' comments allowed, commas or
 * spaces separate. *idx (per x count, allocated with ctx: es_free) and
 * *count. per = 2 or 3. ES_EFORMAT with file:line. */
ES_API es_status es_landmarks_read_index_list(es_ctx *ctx, const char *path, int per,
                                              int64_t **idx, int64_t *count);

/* Create the store `path` from a landmark set and a triangulation of its
 * landmarks (ntri triangles, 3 x ntri 0-based indices; it must be an
 * oriented manifold, es_mesh_new's checks): the triangles' edges are the
 * store's edges, so every tool runs on the landmarks. With ntri = 0 or tri
 * NULL the store holds no faces and no edges (topology kind "none"):
 * positions, ids and labels only, for GPA; length operations on it fail.
 * 2D landmarks are stored with z = 0 in the store's 3 x V positions
 * (es_study_gpa analyses such rows in 2D). Labels become label columns;
 * TPS IMAGE= and SCALE= values are kept as columns "image" and "tps_scale"
 * when present. ES_EEXIST if path exists. All-or-nothing (es_store_commit). */
ES_API es_status es_landmarks_to_store(es_ctx *ctx, const es_landmarks *lm, int64_t ntri,
                                       const int64_t *tri, const char *path);

/* As es_landmarks_to_store, with an edge list of landmark pairs instead of
 * triangles (a "truss" store: 2 x nedges 0-based indices, any order and
 * orientation; made (min, max) and sorted, repeats dropped with a warning).
 * Each row's lengths are the pairs' distances divided by their sum, as for
 * meshes, so mean, pca, diff and point run on them; there are no faces.
 * nedges = 0 makes a landmarks-only store. ES_EINVAL on an index out of
 * range or a pair with equal ends. */
ES_API es_status es_landmarks_to_store_edges(es_ctx *ctx, const es_landmarks *lm,
                                             int64_t nedges, const int64_t *edges,
                                             const char *path);

#ifdef __cplusplus
}
#endif
#endif
