/* lib/include/edgespace/es_parallel.h — one analysis across the processes of
 * an MPI job (mpirun -n P), with parallel HDF5.
 *
 * A library built with -Dmpi=enabled (Open MPI and Debian's openmpi build of
 * HDF5) runs PCA (Gram, covariance and randomized routes: es_pca_fit, and
 * `mpirun -n P edgespace pca`), the permutations of a linear model
 * (es_model_fit), GPA (es_gpa_align_ranks) and mesh ingest
 * (es_ingest_manifest, es_ingest_files: collective parallel-HDF5 writes)
 * on P processes ("ranks"); datasets-spec/parallel.md says what runs where. Every rank runs the same program: a
 * context joined to the job (es_parallel_join) makes those calls
 * collective, so every rank must make them, in the same order and with the
 * same arguments; each returns the same status on every rank, with the
 * message of the lowest rank that failed. Results are the same as on one
 * process (to rounding: sums are added in another order; permutation
 * p-values are identical for the same seed), and stores and results are
 * written by rank 0 alone, never twice.
 * datasets-spec/parallel.md states how the work and the data are divided and
 * what each rank reads, computes and sends.
 *
 * A library built without MPI has the same calls: es_parallel_available()
 * is 0, es_parallel_init does nothing and every context is alone (rank 0
 * of 1), so callers need no #ifdef.
 */
#ifndef EDGESPACE_ES_PARALLEL_H
#define EDGESPACE_ES_PARALLEL_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 if the library was built with MPI, else 0. */
ES_API int es_parallel_available(void);

/* 1 if this process was started by an MPI launcher (mpirun, mpiexec: the
 * environment says so), else 0. A program run without one stays serial and
 * never initializes MPI (which can take a second and print warnings). */
ES_API int es_parallel_launched(void);

/* Initialize MPI (MPI_Init_thread, funneled: only the thread that calls the
 * library's collectives talks to MPI) unless it already is; a no-op
 * without MPI. argc/argv may be NULL. ES_EIO if MPI cannot start. */
ES_API es_status es_parallel_init(es_ctx *ctx, int *argc, char ***argv);

/* Finalize MPI if es_parallel_init started it (call once, at the end, after
 * every context joined to the job is freed). */
ES_API void es_parallel_finalize(void);

/* Join ctx to the job: its collective calls run on all ranks of
 * MPI_COMM_WORLD (a private duplicate of it). A no-op without MPI, or
 * before es_parallel_init. Call it on every rank. */
ES_API es_status es_parallel_join(es_ctx *ctx);

/* This rank (0 .. P-1) and the number of ranks P of ctx's job: 0 and 1 for a
 * context not joined to one. */
ES_API int es_parallel_rank(const es_ctx *ctx);
ES_API int es_parallel_nranks(const es_ctx *ctx);

/* The contiguous share [*lo, *hi) of n items (rows, configurations) that
 * this rank takes: the first n % P ranks take one more; 0 and n alone. */
ES_API void es_parallel_share(const es_ctx *ctx, int64_t n, int64_t *lo, int64_t *hi);

/* Wait for every rank of ctx's job (MPI_Barrier); ES_OK at once alone. */
ES_API es_status es_parallel_barrier(es_ctx *ctx);

/* What this rank has sent through the library's collectives since ctx
 * joined its job: messages and bytes (0 and 0 alone): the measured side of
 * the cost model in datasets-spec/parallel.md. */
ES_API void es_parallel_traffic(const es_ctx *ctx, int64_t *messages, int64_t *bytes);

/* The first failure of any rank, agreed on by all: every rank passes its
 * own status; all return ES_OK if every rank had ES_OK, else the status of
 * the lowest failing rank, whose message is copied onto every rank's ctx.
 * Alone: rc. */
ES_API es_status es_parallel_agree(es_ctx *ctx, es_status rc);

#ifdef __cplusplus
}
#endif
#endif
