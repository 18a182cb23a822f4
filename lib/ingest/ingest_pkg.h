/* lib/ingest/ingest_pkg.h — what the files of lib/ingest share: for the
 * landmark readers (landmarks.c) the growable specimen array both the TPS
 * and the long-CSV reader fill, reading a landmark text file, freeing a
 * string array; for mesh ingest the inputs, the block being read, and the
 * reading both the one-process and the ranks' ingest use. Package header:
 * only lib/ingest includes it. */
#ifndef EDGESPACE_INGEST_PKG_H
#define EDGESPACE_INGEST_PKG_H

#ifndef ES_MODULE_INGEST
#error "ingest/ingest_pkg.h is private to lib/ingest/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "core/strmap.h"
#include "edgespace/es_ingest.h"
#include "edgespace/es_landmarks.h"
#include "edgespace/es_mesh.h"
#include "edgespace/es_store.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>

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

/* ---- mesh ingest (ingest.c one process, ingest_ranks.c the ranks of an MPI
 * job; ingest_read.c the reading both share) ------------------------------ */

/* One input: where to read it, its id and (manifest) label row. */
typedef struct ingest_input {
    const char *id;
    const char *path;           /* path to open */
    const char *const *labels;  /* ncols values or NULL */
} ingest_input;

/* What reading produces: the current block's values, one slot per input
 * of the block (slot = input - first input of the block), and per input
 * (all n, a few bytes each) the content hash and whether it is skipped. */
typedef struct ingest_batch {
    int64_t cap, V, E;
    double *xyz, *len, *scale;   /* 3V x cap, E x cap, cap */
    char (*hash)[25];            /* content hash per input */
    uint8_t *skip;               /* 1: already in the store, same content */
} ingest_batch;

typedef struct ingest_ref {
    es_mesh *mesh;
    const int64_t *faces;
    int64_t V, F;
    char what[600];       /* "the store 's.h5'" or "the first input 'a.obj'" */
} ingest_ref;

typedef struct ingest_note { int64_t index, seq; char *msg; } ingest_note;

typedef struct ingest_job {
    const ingest_input *in;
    int64_t n;                  /* end of the current block */
    int64_t slot0;              /* its first input: slot 0 of the ingest_batch */
    const ingest_ref *r;
    const es_store *st;
    const es_ingest_opts *o;
    ingest_batch *b;
    atomic_llong next, done;
    pthread_mutex_t mu;
    int64_t err_index;          /* lowest failing input, all inputs' count if none */
    es_status err_rc;
    char err_msg[1200];
    ingest_note *notes;                /* warnings (malloc'd, main ctx not touched) */
    int64_t nnotes, capnotes;
    int64_t bytes_read;
    int64_t ntotal;             /* inputs in all (progress) */
} ingest_job;

/* An ingest under way: the store as opened (NULL for a new one), the
 * reference topology (the store's, or the first input's), the block of
 * values being read and the job that reads it. */
typedef struct ingest_session {
    const char *path;      /* the store's path */
    es_store *st;
    ingest_ref r;
    int64_t *faces;        /* r.faces' memory */
    ingest_batch b;
    ingest_job j;
    bool mu_init;
    int64_t first;         /* 1: a new store's first input is read already, into slot 0 */
} ingest_session;

/* Start: open the store at store_path if it exists (in mode: ES_STORE_WRITE,
 * or ES_STORE_READ on the ranks that do not write) and take its topology,
 * else read the first input for it (its values into slot 0); a batch of
 * blocks of about 64 MB (or opts->block_rows) for the nshare inputs this
 * process reads, hashes and skip flags for all n. *s is zeroed first;
 * es__ingest_end frees what it holds but the store. */
es_status es__ingest_begin(es_ctx *ctx, ingest_session *s, const char *store_path,
                           es_store_mode mode, const ingest_input *in, int64_t n,
                           int64_t nshare, const es_ingest_opts *o);
void es__ingest_end(es_ctx *ctx, ingest_session *s);

/* A growing text of warnings (lines), to be said by another rank. */
typedef struct ingest_text { char *p; size_t n, cap; } ingest_text;

/* Read and check inputs [b0, b1) into the batch (slot = input - b0), on
 * threads; the block's warnings in input order, said on ctx, or appended to
 * *keep when it is not NULL. The lowest failing input's error. */
es_status es__ingest_read_block(es_ctx *ctx, ingest_session *s, int64_t b0, int64_t b1,
                                ingest_text *keep);

/* The values of the inputs of [b0, b1) that are not skipped moved to the
 * front of the batch, in input order; their count. */
int64_t es__ingest_compact(ingest_batch *b, int64_t b0, int64_t b1);

/* Whether input in, whose content hashes to hash, is in the store st
 * already: *skip 1 if with the same content; ES_EEXIST (naming the file and
 * the id) if with other content; *skip 0 if its id is new. */
es_status es__ingest_known(es_ctx *ctx, const es_store *st, const ingest_input *in,
                           const char *hash, int *skip);

/* The whole file at path into *buf (grown, reused across files): a regular
 * file, ES_ENOTFOUND if missing. */
es_status es__ingest_slurp(es_ctx *ctx, const char *path, char **buf, size_t *cap, size_t *len);

/* The rows kept so far, in input order (pointer arrays for all n inputs:
 * the ids and labels are the inputs', the hashes the batch's, the real
 * source paths made here), and the content hashes seen: the store's rows
 * (as it was opened) and the inputs kept. */
typedef struct ingest_kept {
    int64_t n;
    const char **ids, **hashes, **labels;   /* labels: ncols per row */
    char **sources;
    es__strmap seen_store, seen_new;
} ingest_kept;

es_status es__ingest_kept_init(es_ctx *ctx, ingest_kept *k, const es_store *st, int64_t n,
                               int64_t ncols);
void es__ingest_kept_clear(es_ctx *ctx, ingest_kept *k);

/* Inputs [b0, b1) of b: the skipped counted in rep, a warning for each that
 * repeats the content of a row of st or of an input kept before, the rest
 * added to k; values: their slots moved to the front of the batch too. */
es_status es__ingest_keep(es_ctx *ctx, const es_store *st, const ingest_input *in, int64_t b0,
                          int64_t b1, int64_t ncols, ingest_batch *b, bool values,
                          ingest_kept *k, es_ingest_report *rep);

/* The inputs ingested on the ranks of ctx's job (ingest_ranks.c): the same
 * store as es__ingest_serial makes (the ingest of ingest.c). */
es_status es__ingest_ranks(es_ctx *ctx, const char *store_path, int64_t n,
                           const ingest_input *in, int64_t ncols, const char *const *colnames,
                           const es_ingest_opts *o, es_ingest_report *rep);

#endif
