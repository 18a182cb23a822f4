/* lib/parallel/parallel_private.h — the collectives the other modules use
 * (library-private; es_parallel.h is the public side). Only lib/parallel
 * includes mpi.h: the numerical modules get sums, broadcasts and exchanges
 * of doubles; the communicator is offered as an opaque pointer for HDF5's
 * MPI-IO driver (es__par_comm; no caller yet: collective ingest is to come).
 *
 * Every function here is collective over ctx's job (all ranks call it, in
 * the same order) and a no-op, or a plain copy, on a context that is alone;
 * each returns ES_OK or ES_EIO (MPI failed: the message says so) on every
 * rank. Counts are elements; a message of more than 2^31 - 1 elements is
 * sent in pieces. */
#ifndef EDGESPACE_PARALLEL_PRIVATE_H
#define EDGESPACE_PARALLEL_PRIVATE_H

#if !defined(ES_BUILDING_LIBRARY) && !defined(ES_TESTING)
#error "parallel/parallel_private.h is private to libedgespace"
#endif

#include "core/core_private.h"
#include "edgespace/es_parallel.h"

#include <stdbool.h>
#include <stdint.h>

/* Rank and size of ctx's job (0 and 1 when alone). */
int es__par_rank(const es_ctx *ctx);
int es__par_size(const es_ctx *ctx);
static inline bool es__par_alone(const es_ctx *ctx) { return es__par_size(ctx) < 2; }

/* The contiguous share [*lo, *hi) of n items that rank p of size ranks
 * takes: the first n % size ranks take one more. */
void es__par_split(int64_t n, int size, int p, int64_t *lo, int64_t *hi);

/* The first failure of any rank (es_parallel_agree). */
es_status es__par_agree(es_ctx *ctx, es_status rc);

/* v[0..n) summed over the ranks, the same bits on every rank (reduced to
 * rank 0, then broadcast: MPI does not promise that an all-reduce gives
 * every rank the same rounding, and the ranks of a GPA must rotate by the
 * very same matrix). */
es_status es__par_sum(es_ctx *ctx, double *v, int64_t n);
es_status es__par_sum_i64(es_ctx *ctx, int64_t *v, int64_t n);
/* The sum on rank 0 only (others' v unchanged): a matrix that rank 0 alone
 * decomposes. */
es_status es__par_sum_root(es_ctx *ctx, double *v, int64_t n);
/* The largest of each v[i] over the ranks, on every rank. */
es_status es__par_max_i64(es_ctx *ctx, int64_t *v, int64_t n);

/* bytes of buf from rank root to every rank. */
es_status es__par_bcast(es_ctx *ctx, void *buf, size_t bytes, int root);

/* Rank q sends counts[q] doubles from mine; rank 0 receives them one rank
 * after another into all (sum of counts); counts is the same on every rank.
 * Rank 0's mine may be all itself (its part is then in place: it comes
 * first). es__par_allgather does the same into every rank's all. */
es_status es__par_gather(es_ctx *ctx, const double *mine, const int64_t *counts, double *all);
es_status es__par_allgather(es_ctx *ctx, const double *mine, const int64_t *counts,
                            double *all);

/* All-to-all exchange of doubles: this rank sends send_counts[q] doubles
 * from send + send_off[q] to rank q and receives recv_counts[q] from rank q
 * into recv + recv_off[q] (one entry per rank). */
es_status es__par_alltoall(es_ctx *ctx, const double *send, const int64_t *send_counts,
                           const int64_t *send_off, double *recv, const int64_t *recv_counts,
                           const int64_t *recv_off);

/* The communicator of ctx's job as an MPI_Comm * (for H5Pset_fapl_mpio), or
 * NULL when alone or without MPI. Borrowed. */
void *es__par_comm(const es_ctx *ctx);

/* Bytes this rank has sent in collectives so far and their count (the cost
 * model's "messages per rank", checked against measured runs). */
void es__par_traffic(const es_ctx *ctx, int64_t *messages, int64_t *bytes);

#endif
