/* lib/parallel/parallel.c — the ranks of an MPI job and the few collectives
 * the library needs (parallel_private.h), behind one file so that mpi.h is
 * included nowhere else; without MPI (the default build) every context is
 * alone and each collective is a no-op or a copy.
 *
 * A context joined to a job holds a private duplicate of MPI_COMM_WORLD, so
 * the library's messages never match an application's. Sums are reduced to
 * rank 0 and broadcast rather than all-reduced: MPI lets an all-reduce round
 * differently on different ranks, and GPA's ranks must apply bit-identical
 * rotations to their parts of one configuration. Counts above INT_MAX
 * elements go in pieces (MPI's counts are int). Every rank counts what it
 * sends, for the cost model's "messages per rank" (datasets-spec/parallel.md).
 */
#include "parallel/parallel_private.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>

#if ES_HAVE_MPI
#include <mpi.h>
#endif

void es__par_split(int64_t n, int size, int p, int64_t *lo, int64_t *hi)
{
    int64_t q = n / size, r = n % size;
    *lo = (int64_t)p * q + (p < r ? p : r);
    *hi = *lo + q + (p < r);
}

int es_parallel_available(void) { return ES_HAVE_MPI; }

int es_parallel_launched(void)
{
    /* Open MPI's mpirun, PMIx launchers (srun, prterun), MPICH's Hydra */
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", NULL};
    for (int i = 0; vars[i]; i++)
        if (getenv(vars[i])) return 1;
    return 0;
}

#if ES_HAVE_MPI

typedef struct par {
    MPI_Comm comm;
    int rank, size;
    int64_t messages, bytes;
} par;

static int started_here;

static par *par_of(const es_ctx *ctx) { return es__ctx_parallel(ctx); }

int es__par_rank(const es_ctx *ctx) { par *p = par_of(ctx); return p ? p->rank : 0; }
int es__par_size(const es_ctx *ctx) { par *p = par_of(ctx); return p ? p->size : 1; }
void *es__par_comm(const es_ctx *ctx) { par *p = par_of(ctx); return p ? &p->comm : NULL; }

static es_status mpi_fail(es_ctx *ctx, int err, const char *what)
{
    char msg[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(err, msg, &len) != MPI_SUCCESS) snprintf(msg, sizeof msg, "error %d", err);
    ES_FAIL(ctx, ES_EIO, "parallel: %s failed: %s", what, msg);
}

es_status es_parallel_init(es_ctx *ctx, int *argc, char ***argv)
{
    int done = 0, provided, err;
    MPI_Initialized(&done);
    if (done) return ES_OK;
    if ((err = MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided)) != MPI_SUCCESS)
        return mpi_fail(ctx, err, "MPI_Init_thread");
    started_here = 1;
    return ES_OK;
}

void es_parallel_finalize(void)
{
    int done = 0, fin = 0;
    MPI_Initialized(&done);
    MPI_Finalized(&fin);
    if (started_here && done && !fin) MPI_Finalize();
    started_here = 0;
}

static void par_release(void *state)
{
    par *p = state;
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin) MPI_Comm_free(&p->comm);
    free(p);
}

es_status es_parallel_join(es_ctx *ctx)
{
    int done = 0, err;
    par *p;
    MPI_Initialized(&done);
    if (!done || par_of(ctx)) return ES_OK;
    if (!(p = calloc(1, sizeof *p))) ES_FAIL(ctx, ES_ENOMEM, "parallel: out of memory");
    /* errors come back as codes (the message is ours), never abort the job */
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    if ((err = MPI_Comm_dup(MPI_COMM_WORLD, &p->comm)) != MPI_SUCCESS) {
        free(p);
        return mpi_fail(ctx, err, "MPI_Comm_dup");
    }
    MPI_Comm_set_errhandler(p->comm, MPI_ERRORS_RETURN);
    MPI_Comm_rank(p->comm, &p->rank);
    MPI_Comm_size(p->comm, &p->size);
    es__ctx_set_parallel(ctx, p, par_release);
    return ES_OK;
}

void es__par_traffic(const es_ctx *ctx, int64_t *messages, int64_t *bytes)
{
    par *p = par_of(ctx);
    *messages = p ? p->messages : 0;
    *bytes = p ? p->bytes : 0;
}

static void count(par *p, int64_t messages, int64_t bytes)
{
    p->messages += messages;
    p->bytes += bytes;
}

es_status es_parallel_barrier(es_ctx *ctx)
{
    par *p = par_of(ctx);
    int err;
    if (!p || p->size < 2) return ES_OK;
    if ((err = MPI_Barrier(p->comm)) != MPI_SUCCESS) return mpi_fail(ctx, err, "MPI_Barrier");
    return ES_OK;
}

es_status es__par_agree(es_ctx *ctx, es_status rc)
{
    par *p = par_of(ctx);
    struct { int code; char msg[1024]; } m;
    int mine, first, err;
    if (!p || p->size < 2) return rc;
    mine = rc != ES_OK ? p->rank : p->size;
    if ((err = MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, p->comm)) != MPI_SUCCESS)
        return mpi_fail(ctx, err, "MPI_Allreduce");
    count(p, 1, sizeof mine);
    if (first == p->size) return ES_OK;
    memset(&m, 0, sizeof m);
    if (p->rank == first) {
        m.code = (int)rc;
        snprintf(m.msg, sizeof m.msg, "%s", es_ctx_errmsg(ctx));
    }
    if ((err = MPI_Bcast(&m, (int)sizeof m, MPI_BYTE, first, p->comm)) != MPI_SUCCESS)
        return mpi_fail(ctx, err, "MPI_Bcast");
    if (p->rank == first) count(p, p->size - 1, (int64_t)sizeof m);
    if (p->rank != first) es__fail(ctx, (es_status)m.code, "%s", m.msg);
    return (es_status)m.code;
}

es_status es_parallel_agree(es_ctx *ctx, es_status rc) { return es__par_agree(ctx, rc); }

/* Pieces of at most INT_MAX elements. */
#define PIECE ((int64_t)INT_MAX)

static es_status reduce_root(es_ctx *ctx, void *v, int64_t n, MPI_Datatype t, size_t elem,
                             MPI_Op op)
{
    par *p = par_of(ctx);
    for (int64_t o = 0; o < n; o += PIECE) {
        int k = (int)(n - o < PIECE ? n - o : PIECE), err;
        char *at = (char *)v + (size_t)o * elem;
        err = MPI_Reduce(p->rank == 0 ? MPI_IN_PLACE : at, p->rank == 0 ? at : NULL, k, t, op, 0,
                         p->comm);
        if (err != MPI_SUCCESS) return mpi_fail(ctx, err, "MPI_Reduce");
        if (p->rank != 0) count(p, 1, (int64_t)k * (int64_t)elem);
    }
    return ES_OK;
}

es_status es__par_bcast(es_ctx *ctx, void *buf, size_t bytes, int root)
{
    par *p = par_of(ctx);
    if (!p || p->size < 2) return ES_OK;
    for (size_t o = 0; o < bytes; o += (size_t)PIECE) {
        int k = (int)(bytes - o < (size_t)PIECE ? bytes - o : (size_t)PIECE), err;
        if ((err = MPI_Bcast((char *)buf + o, k, MPI_BYTE, root, p->comm)) != MPI_SUCCESS)
            return mpi_fail(ctx, err, "MPI_Bcast");
        if (p->rank == root) count(p, p->size - 1, (int64_t)k * (p->size - 1));
    }
    return ES_OK;
}

es_status es__par_sum_root(es_ctx *ctx, double *v, int64_t n)
{
    par *p = par_of(ctx);
    if (!p || p->size < 2) return ES_OK;
    return reduce_root(ctx, v, n, MPI_DOUBLE, sizeof *v, MPI_SUM);
}

es_status es__par_sum(es_ctx *ctx, double *v, int64_t n)
{
    es_status rc = es__par_sum_root(ctx, v, n);
    return rc ? rc : es__par_bcast(ctx, v, (size_t)n * sizeof *v, 0);
}

es_status es__par_sum_i64(es_ctx *ctx, int64_t *v, int64_t n)
{
    par *p = par_of(ctx);
    es_status rc;
    if (!p || p->size < 2) return ES_OK;
    if ((rc = reduce_root(ctx, v, n, MPI_INT64_T, sizeof *v, MPI_SUM))) return rc;
    return es__par_bcast(ctx, v, (size_t)n * sizeof *v, 0);
}

es_status es__par_max_i64(es_ctx *ctx, int64_t *v, int64_t n)
{
    par *p = par_of(ctx);
    es_status rc;
    if (!p || p->size < 2) return ES_OK;
    if ((rc = reduce_root(ctx, v, n, MPI_INT64_T, sizeof *v, MPI_MAX))) return rc;
    return es__par_bcast(ctx, v, (size_t)n * sizeof *v, 0);
}

/* int counts and displacements for the v-collectives; ES_ERANGE past INT_MAX. */
static es_status int_counts(es_ctx *ctx, int size, const int64_t *counts, const int64_t *off,
                            int *c, int *d)
{
    int64_t at = 0;
    for (int q = 0; q < size; q++) {
        int64_t o = off ? off[q] : at;
        if (counts[q] < 0 || counts[q] > INT_MAX || o < 0 || o > INT_MAX)
            ES_FAIL(ctx, ES_ERANGE, "parallel: a message of %lld doubles at %lld is beyond "
                    "MPI's int counts; use more ranks", (long long)counts[q], (long long)o);
        c[q] = (int)counts[q];
        d[q] = (int)o;
        at += counts[q];
    }
    return ES_OK;
}

static es_status gather_impl(es_ctx *ctx, const double *mine, const int64_t *counts,
                             double *all, int everyone)
{
    par *p = par_of(ctx);
    es_status rc;
    int *c, *d, err;
    if (!p || p->size < 2) {
        if (all != mine) memcpy(all, mine, (size_t)counts[0] * sizeof *all);
        return ES_OK;
    }
    if (!(c = es__alloc_array(ctx, 2 * p->size, sizeof *c))) return ES_ENOMEM;
    d = c + p->size;
    if ((rc = int_counts(ctx, p->size, counts, NULL, c, d)) == ES_OK) {
        err = everyone ? MPI_Allgatherv(mine, c[p->rank], MPI_DOUBLE, all, c, d, MPI_DOUBLE,
                                        p->comm)
                       : MPI_Gatherv(p->rank == 0 && mine == all ? MPI_IN_PLACE : mine,
                                     c[p->rank], MPI_DOUBLE, all, c, d, MPI_DOUBLE, 0,
                                     p->comm);
        if (err != MPI_SUCCESS) rc = mpi_fail(ctx, err, everyone ? "MPI_Allgatherv" : "MPI_Gatherv");
        else if (everyone) count(p, p->size - 1, (int64_t)c[p->rank] * 8 * (p->size - 1));
        else if (p->rank != 0) count(p, 1, (int64_t)c[p->rank] * 8);   /* rank 0's part stays */
    }
    es__free(ctx, c);
    return rc;
}

es_status es__par_gather(es_ctx *ctx, const double *mine, const int64_t *counts, double *all)
{
    return gather_impl(ctx, mine, counts, all, 0);
}

es_status es__par_allgather(es_ctx *ctx, const double *mine, const int64_t *counts,
                            double *all)
{
    return gather_impl(ctx, mine, counts, all, 1);
}

es_status es__par_alltoall(es_ctx *ctx, const double *send, const int64_t *send_counts,
                           const int64_t *send_off, double *recv, const int64_t *recv_counts,
                           const int64_t *recv_off)
{
    par *p = par_of(ctx);
    es_status rc;
    int *c, err;
    if (!p || p->size < 2) {
        memcpy(recv + recv_off[0], send + send_off[0], (size_t)send_counts[0] * sizeof *send);
        return ES_OK;
    }
    if (!(c = es__alloc_array(ctx, 4 * p->size, sizeof *c))) return ES_ENOMEM;
    if ((rc = int_counts(ctx, p->size, send_counts, send_off, c, c + p->size)) == ES_OK &&
        (rc = int_counts(ctx, p->size, recv_counts, recv_off, c + 2 * p->size,
                         c + 3 * p->size)) == ES_OK) {
        err = MPI_Alltoallv(send, c, c + p->size, MPI_DOUBLE, recv, c + 2 * p->size,
                            c + 3 * p->size, MPI_DOUBLE, p->comm);
        if (err != MPI_SUCCESS) rc = mpi_fail(ctx, err, "MPI_Alltoallv");
        for (int q = 0; q < p->size && rc == ES_OK; q++)
            if (q != p->rank && c[q] > 0) count(p, 1, (int64_t)c[q] * 8);
    }
    es__free(ctx, c);
    return rc;
}

#else /* one process: every context is alone */

int es__par_rank(const es_ctx *ctx) { (void)ctx; return 0; }
int es__par_size(const es_ctx *ctx) { (void)ctx; return 1; }
void *es__par_comm(const es_ctx *ctx) { (void)ctx; return NULL; }
es_status es_parallel_init(es_ctx *ctx, int *argc, char ***argv)
{
    (void)ctx, (void)argc, (void)argv;
    return ES_OK;
}
void es_parallel_finalize(void) {}
es_status es_parallel_join(es_ctx *ctx) { (void)ctx; return ES_OK; }
void es__par_traffic(const es_ctx *ctx, int64_t *messages, int64_t *bytes)
{
    (void)ctx;
    *messages = *bytes = 0;
}
es_status es_parallel_barrier(es_ctx *ctx) { (void)ctx; return ES_OK; }
es_status es__par_agree(es_ctx *ctx, es_status rc) { (void)ctx; return rc; }
es_status es_parallel_agree(es_ctx *ctx, es_status rc) { (void)ctx; return rc; }
es_status es__par_bcast(es_ctx *ctx, void *buf, size_t bytes, int root)
{
    (void)ctx, (void)buf, (void)bytes, (void)root;
    return ES_OK;
}
es_status es__par_sum_root(es_ctx *ctx, double *v, int64_t n)
{
    (void)ctx, (void)v, (void)n;
    return ES_OK;
}
es_status es__par_sum(es_ctx *ctx, double *v, int64_t n) { return es__par_sum_root(ctx, v, n); }
es_status es__par_sum_i64(es_ctx *ctx, int64_t *v, int64_t n)
{
    (void)ctx, (void)v, (void)n;
    return ES_OK;
}
es_status es__par_max_i64(es_ctx *ctx, int64_t *v, int64_t n)
{
    return es__par_sum_i64(ctx, v, n);
}
es_status es__par_gather(es_ctx *ctx, const double *mine, const int64_t *counts, double *all)
{
    (void)ctx;
    if (all != mine) memcpy(all, mine, (size_t)counts[0] * sizeof *all);
    return ES_OK;
}
es_status es__par_allgather(es_ctx *ctx, const double *mine, const int64_t *counts,
                            double *all)
{
    return es__par_gather(ctx, mine, counts, all);
}
es_status es__par_alltoall(es_ctx *ctx, const double *send, const int64_t *send_counts,
                           const int64_t *send_off, double *recv, const int64_t *recv_counts,
                           const int64_t *recv_off)
{
    (void)ctx, (void)recv_counts;
    memcpy(recv + recv_off[0], send + send_off[0], (size_t)send_counts[0] * sizeof *send);
    return ES_OK;
}

#endif

int es_parallel_rank(const es_ctx *ctx) { return es__par_rank(ctx); }
int es_parallel_nranks(const es_ctx *ctx) { return es__par_size(ctx); }

void es_parallel_share(const es_ctx *ctx, int64_t n, int64_t *lo, int64_t *hi)
{
    es__par_split(n, es__par_size(ctx), es__par_rank(ctx), lo, hi);
}

void es_parallel_traffic(const es_ctx *ctx, int64_t *messages, int64_t *bytes)
{
    es__par_traffic(ctx, messages, bytes);
}
