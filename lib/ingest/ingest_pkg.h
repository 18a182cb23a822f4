/* lib/ingest/ingest_pkg.h — what the landmark readers share (landmarks.c):
 * the growable specimen array both the TPS and the long-CSV reader fill,
 * reading a landmark text file, freeing a string array. Package header: only lib/ingest includes it. */
#ifndef EDGESPACE_INGEST_PKG_H
#define EDGESPACE_INGEST_PKG_H

#ifndef ES_MODULE_INGEST
#error "ingest/ingest_pkg.h is private to lib/ingest/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "edgespace/es_landmarks.h"

/* Specimens while reading: k landmarks in d dimensions each, kd = k * d
 * doubles per specimen (column-major x-block, y-block[, z-block]). ids,
 * images and scale have one entry per specimen (NULL, NULL, NaN when
 * added). Start from {0} with ctx set. */
typedef struct es__lm_builder {
    es_ctx *ctx;
    int64_t limit;   /* most specimens the input can hold (0: no bound): room
                      * is never made for more than the file has lines for */
    int64_t n, cap, k, kd;
    int d;
    double *xyz;
    char **ids, **images;
    double *scale;
} es__lm_builder;

/* Append a specimen of k landmarks in d dimensions, zeroed. The first one
 * fixes k and d; a later one that differs is ES_EMISMATCH naming file and
 * line. line is 0 for CSV, where k is the largest landmark number rather
 * than an LM= count (the ES_ERANGE message says which). */
es_status es__lm_builder_add(es__lm_builder *b, int64_t k, int d, const char *file,
                             int64_t line);
/* Free everything the builder holds and reset it. */
void es__lm_builder_clear(es__lm_builder *b);
/* Hand the arrays to a new es_landmarks (images and scales only with
 * with_tps_fields); the builder is reset either way. */
es_status es__lm_builder_finish(es__lm_builder *b, int with_tps_fields, es_landmarks **out);

/* A landmark text file (TPS, index list) into *buf (es__free): a regular
 * file without NUL bytes, its UTF-8 byte order mark dropped; messages start
 * "landmarks: ". */
es_status es__lm_read_text(es_ctx *ctx, const char *path, char **buf, size_t *len);

/* Free s[0..n) and s (NULL: nothing). */
void es__free_strings(es_ctx *ctx, char **s, int64_t n);

#endif
