/* lib/store/store_private.h — what lib/store offers the modules above it
 * beyond es_store.h: rows written by the ranks of an MPI job (ingest on
 * the ranks, lib/ingest/ingest_ranks.c). Library-private.
 *
 * The rows' values go in first, the rest after: rank 0, which holds the
 * store's handle (its working copy), makes room for the rows
 * (es__store_reserve_values), all ranks open the working copy together
 * with HDF5's MPI-IO driver and write their rows' lengths, scales and
 * positions with collective writes (es__store_ranks_open, _write, _close;
 * store_ranks.c), and rank 0 then appends the rows' ids, sources, hashes
 * and labels (es__store_append_written) and commits as ever: the store is
 * the one es_store_append makes, and the working copy is published, or
 * not, all at once. */
#ifndef EDGESPACE_STORE_PRIVATE_H
#define EDGESPACE_STORE_PRIVATE_H

#if !defined(ES_BUILDING_LIBRARY) && !defined(ES_TESTING)
#error "store/store_private.h is private to libedgespace"
#endif

#include "core/core_private.h"
#include "edgespace/es_store.h"

/* n more rows in the working copy's lengths, scales and positions (their
 * values unwritten, HDF5's fill value 0, until es__store_ranks_write), none
 * yet in its ids: the store is incomplete until es__store_append_written,
 * and a failure marks the handle broken (never committed). */
es_status es__store_reserve_values(es_ctx *ctx, es_store *s, int64_t n);

/* es_store_append for the r->n rows whose values (the last r->n reserved)
 * are written: ids, source paths, content hashes and labels, checked as
 * es_store_append checks them; r->lengths, scales and xyz are not read. */
es_status es__store_append_written(es_ctx *ctx, es_store *s, const es_store_rows *r);

/* The working copy open on every rank of ctx's job (collective): rank 0
 * passes its handle (whose HDF5 file it closes meanwhile), the others
 * NULL. ES_EINVAL in a build without MPI and parallel HDF5. */
typedef struct es__store_ranks es__store_ranks;
es_status es__store_ranks_open(es_ctx *ctx, es_store *s, es__store_ranks **out);

/* Collective: this rank's n rows (n may be 0) from store row row0 on:
 * lengths E x n, scales n, positions 3V x n, as es_store_rows holds them. */
es_status es__store_ranks_write(es_ctx *ctx, es__store_ranks *h, int64_t row0, int64_t n,
                                const double *lengths, const double *scales, const double *xyz);

/* Collective: closed on every rank (h freed; NULL is nothing), rank 0's
 * handle on its working copy again. The status agreed by all. */
es_status es__store_ranks_close(es_ctx *ctx, es_store *s, es__store_ranks *h);

/* Files that appear with the next commit, not before (a study's meshes
 * and frames beside the results it stored): set's staged files
 * (es__replace_end_staged) move onto the handle, set is left empty.
 * es_store_commit (and es_store_close) renames them into place once the
 * store itself is published, and removes them when the commit fails;
 * es_store_rollback and es_store_abort remove them. So a store write that
 * fails leaves no new file behind and an old file as it was. On ES_ENOMEM
 * set's files are removed. */
es_status es__store_publish_with(es_ctx *ctx, es_store *s, es__file_set *set);

/* ES_OK if kind (NULL: not checked) and name may name a result: not empty,
 * ".", "..", no '/' or control character, at most 120 bytes
 * (store_names.c); else ES_EINVAL saying which rule it breaks. The one rule
 * for every writer and reader of results. */
es_status es__result_name_check(es_ctx *ctx, const char *kind, const char *name);

#endif
