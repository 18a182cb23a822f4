/* lib/store/store_ranks.c — the rows of a store written by the ranks of an
 * MPI job with collective parallel-HDF5 writes (store_private.h).
 *
 * Rank 0 holds the store's handle and its working copy; it closes its HDF5
 * file, every rank opens the copy with the MPI-IO driver and writes its rows
 * of /shapes/lengths, /shapes/scales and /shapes/positions with one
 * collective write per dataset and call (es__h5_file_open_ranks,
 * es__h5_write_rows_ranks: lib/h5/h5_ranks.c); then every rank closes it
 * and rank 0 reopens its handle. The datasets are the ones es_store_create
 * makes (chunked, unlimited rows, no filters): Debian 12's HDF5 1.10.8
 * writes chunked datasets collectively, and would filtered ones since
 * 1.10.2, but the store has no filters, so nothing of its format changes.
 * Rank 0 made room for the rows before (es__store_reserve_values) and
 * allocated their chunks (es__h5_allocate_rows says why), so no rank
 * changes a dataset's extent or allocates: the ranks only overwrite. Only
 * the working copy is written: the store is published, or not, by rank 0's
 * commit, as ever.
 */
#include "store/store_pkg.h"
#include "store/store_private.h"
#include "parallel/parallel_private.h"

#include <stdlib.h>
#include <string.h>

struct es__store_ranks {
    es__h5_id file;
};

/* A build without MPI or with a serial HDF5: the ranks never get here (a
 * context is alone). */
static es_status no_mpi(es_ctx *ctx)
{
    ES_FAIL(ctx, ES_EINVAL, "store: writing on the ranks of an MPI job needs a build with "
            "-Dmpi=enabled (parallel HDF5)");
}

static es_status ranks_open(es_ctx *ctx, es_store *s, es__store_ranks *h)
{
    int64_t len = 0;
    char *path = NULL;
    es_status rc = ES_OK;
    h->file = -1;
    if (es__par_rank(ctx) == 0) {
        if (!s || !s->work)
            rc = es__fail(ctx, ES_EINVAL, "store: no working copy to write on the ranks");
        else if (es__h5_file_flush_close(s->file) < 0)
            rc = es__h5_fail(ctx, ES_EIO, "store: cannot write '%s'", s->path);
        if (s && s->work) s->file = -1;
        if (rc == ES_OK) len = (int64_t)strlen(s->work) + 1;
    }
    /* the working copy's name, from rank 0 */
    if ((rc = es__par_agree(ctx, rc)) || (rc = es__par_bcast(ctx, &len, sizeof len, 0)))
        return rc;
    if (!(path = es__malloc(ctx, (size_t)len))) rc = ES_ENOMEM;
    else if (es__par_rank(ctx) == 0) memcpy(path, s->work, (size_t)len);
    if ((rc = es__par_agree(ctx, rc)) == ES_OK &&
        (rc = es__par_bcast(ctx, path, (size_t)len, 0)) == ES_OK) {
        if ((h->file = es__h5_file_open_ranks(ctx, path)) < 0)
            rc = es__h5_fail(ctx, ES_EIO, "store: cannot open '%s' on the ranks of the job "
                             "(MPI-IO)", path);
        rc = es__par_agree(ctx, rc);
    }
    es__free(ctx, path);
    return rc;
}

es_status es__store_ranks_open(es_ctx *ctx, es_store *s, es__store_ranks **out)
{
    es__store_ranks *h;
    es_status rc;
    *out = NULL;
    if (!es__h5_parallel()) return no_mpi(ctx);
    h = es__malloc(ctx, sizeof *h);
    if ((rc = es__par_agree(ctx, h ? ES_OK : ES_ENOMEM))) {
        es__free(ctx, h);
        return rc;
    }
    ES__H5_QUIET(rc = ranks_open(ctx, s, h));
    if (rc != ES_OK) {
        if (h->file >= 0) ES__H5_QUIET(es__h5_close(h->file));
        if (s) s->broken = true;
        es__free(ctx, h);
        return rc;
    }
    *out = h;
    return ES_OK;
}

es_status es__store_ranks_write(es_ctx *ctx, es__store_ranks *h, int64_t row0, int64_t n,
                                const double *lengths, const double *scales, const double *xyz)
{
    es_status rc = ES_OK;
    es__h5_quiet q;
    int has_lengths;
    if (!es__h5_parallel()) return no_mpi(ctx);
    /* every rank writes every dataset (collective), whatever its n, and
     * none goes on to the next after a failure on any (it would wait) */
    es__h5_quiet_begin(&q);
    has_lengths = es__h5_exists(h->file, "/shapes/lengths");
    if (has_lengths > 0)
        rc = es__par_agree(ctx, es__h5_write_rows_ranks(ctx, h->file, "/shapes/lengths", row0, n,
                                                        lengths));
    if (has_lengths > 0 && rc == ES_OK)
        rc = es__par_agree(ctx, es__h5_write_rows_ranks(ctx, h->file, "/shapes/scales", row0, n,
                                                        scales));
    if (rc == ES_OK)
        rc = es__par_agree(ctx, es__h5_write_rows_ranks(ctx, h->file, "/shapes/positions", row0,
                                                        n, xyz));
    es__h5_quiet_end(&q);
    return rc;
}

es_status es__store_ranks_close(es_ctx *ctx, es_store *s, es__store_ranks *h)
{
    es_status rc = ES_OK;
    es__h5_quiet q;
    if (!es__h5_parallel()) return ES_OK;
    es__h5_quiet_begin(&q);
    if (h && h->file >= 0 && es__h5_close(h->file) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot close the working copy on the ranks");
    if (es__par_rank(ctx) == 0 && s && s->work && s->file < 0) {
        s->file = es__h5_file_open(s->work, true);
        /* (es__fail: the store has never named HDF5's reason here) */
        if (s->file < 0 && rc == ES_OK)
            rc = es__fail(ctx, ES_EIO, "store: cannot reopen working copy '%s'", s->work);
    }
    es__h5_quiet_end(&q);
    es__free(ctx, h);
    rc = es__par_agree(ctx, rc);
    if (rc != ES_OK && s) s->broken = true;
    return rc;
}
