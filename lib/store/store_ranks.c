/* lib/store/store_ranks.c — the rows of a store written by the ranks of an
 * MPI job with collective parallel-HDF5 writes (store_private.h).
 *
 * Rank 0 holds the store's handle and its working copy; it closes its HDF5
 * file, every rank opens the copy with the MPI-IO driver (H5Pset_fapl_mpio
 * on the job's communicator) and writes its rows of /shapes/lengths,
 * /shapes/scales and /shapes/positions with one collective H5Dwrite per
 * dataset and call (H5Pset_dxpl_mpio, H5FD_MPIO_COLLECTIVE: a rank with no
 * rows takes part with an empty selection); then every rank closes it and
 * rank 0 reopens its handle. The datasets are the ones es_store_create
 * makes (chunked, unlimited rows, no filters): Debian 12's HDF5 1.10.8
 * writes chunked datasets collectively, and would filtered ones since
 * 1.10.2, but the store has no filters, so nothing of its format changes.
 * Rank 0 made room for the rows before (es__store_reserve_values) and
 * allocated their chunks (es__h5_allocate_rows says why), so no rank
 * changes a dataset's extent or allocates: the ranks only overwrite. Only the working copy is written: the store
 * is published, or not, by rank 0's commit, as ever.
 */
#include "store/store_pkg.h"
#include "store/store_private.h"
#include "parallel/parallel_private.h"

#include <stdlib.h>
#include <string.h>

#if ES_HAVE_MPI && defined(H5_HAVE_PARALLEL)

struct es__store_ranks {
    hid_t file;
};

static es_status ranks_open(es_ctx *ctx, es_store *s, es__store_ranks *h)
{
    int64_t len = 0;
    char *path = NULL;
    hid_t fapl = -1;
    es_status rc = ES_OK;
    h->file = -1;
    if (es__par_rank(ctx) == 0) {
        if (!s || !s->work)
            rc = es__fail(ctx, ES_EINVAL, "store: no working copy to write on the ranks");
        else if (H5Fflush(s->file, H5F_SCOPE_GLOBAL) < 0 || H5Fclose(s->file) < 0)
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
        fapl = es__h5_file_access();
        if (fapl < 0 || H5Pset_fapl_mpio(fapl, *(MPI_Comm *)es__par_comm(ctx), MPI_INFO_NULL) < 0 ||
            (h->file = H5Fopen(path, H5F_ACC_RDWR, fapl)) < 0)
            rc = es__h5_fail(ctx, ES_EIO, "store: cannot open '%s' on the ranks of the job "
                             "(MPI-IO)", path);
        es__h5_close(fapl);
        rc = es__par_agree(ctx, rc);
    }
    es__free(ctx, path);
    return rc;
}

/* Rows [row0, row0 + n) of a rows dataset from buf, collectively. */
static es_status write_rows(es_ctx *ctx, hid_t file, const char *name, int64_t row0, int64_t n,
                            const double *buf)
{
    hsize_t dims[3], start[3] = {(hsize_t)row0, 0, 0}, count[3];
    hid_t ds = -1, fsp = -1, msp = -1, dxpl = -1;
    static const double none = 0;
    es_status rc = ES_OK;
    int rank;
    if ((ds = es__h5_open_ds_nocache(file, name)) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        (rank = H5Sget_simple_extent_dims(fsp, dims, NULL)) < 1 || rank > 3) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot open dataset '%s'", name);
        goto done;
    }
    count[0] = (hsize_t)n;
    for (int k = 1; k < rank; k++) count[k] = dims[k];
    if ((hsize_t)(row0 + n) > dims[0]) {
        rc = es__fail(ctx, ES_ERANGE, "store: rows %lld..%lld are beyond the %llu of '%s'",
                      (long long)row0, (long long)(row0 + n - 1), (unsigned long long)dims[0],
                      name);
        goto done;
    }
    if ((n > 0 ? H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, count, NULL)
               : H5Sselect_none(fsp)) < 0 ||
        (msp = H5Screate_simple(rank, count, NULL)) < 0 ||
        (n == 0 && H5Sselect_none(msp) < 0) ||
        (dxpl = H5Pcreate(H5P_DATASET_XFER)) < 0 ||
        H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) < 0 ||
        H5Dwrite(ds, H5T_NATIVE_DOUBLE, msp, fsp, dxpl, n > 0 ? buf : &none) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot write rows %lld..%lld of '%s' on the ranks",
                         (long long)row0, (long long)(row0 + n - 1), name);
done:
    es__h5_close(dxpl);
    es__h5_close(msp);
    es__h5_close(fsp);
    es__h5_close(ds);
    return rc;
}

es_status es__store_ranks_open(es_ctx *ctx, es_store *s, es__store_ranks **out)
{
    es__store_ranks *h = es__malloc(ctx, sizeof *h);
    es_status rc;
    *out = NULL;
    if ((rc = es__par_agree(ctx, h ? ES_OK : ES_ENOMEM))) {
        es__free(ctx, h);
        return rc;
    }
    H5E_BEGIN_TRY { rc = ranks_open(ctx, s, h); } H5E_END_TRY
    if (rc != ES_OK) {
        if (h->file >= 0) H5Fclose(h->file);
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
    htri_t has_lengths;
    /* every rank writes every dataset (collective), whatever its n, and
     * none goes on to the next after a failure on any (it would wait) */
    H5E_BEGIN_TRY {
        has_lengths = H5Lexists(h->file, "/shapes/lengths", H5P_DEFAULT);
        if (has_lengths > 0)
            rc = es__par_agree(ctx, write_rows(ctx, h->file, "/shapes/lengths", row0, n, lengths));
        if (has_lengths > 0 && rc == ES_OK)
            rc = es__par_agree(ctx, write_rows(ctx, h->file, "/shapes/scales", row0, n, scales));
        if (rc == ES_OK)
            rc = es__par_agree(ctx, write_rows(ctx, h->file, "/shapes/positions", row0, n, xyz));
    } H5E_END_TRY
    return rc;
}

es_status es__store_ranks_close(es_ctx *ctx, es_store *s, es__store_ranks *h)
{
    es_status rc = ES_OK;
    H5E_BEGIN_TRY {
        if (h && h->file >= 0 && H5Fclose(h->file) < 0)
            rc = es__h5_fail(ctx, ES_EIO, "store: cannot close the working copy on the ranks");
        if (es__par_rank(ctx) == 0 && s && s->work && s->file < 0) {
            hid_t fapl = es__h5_file_access();
            s->file = H5Fopen(s->work, H5F_ACC_RDWR, fapl);
            es__h5_close(fapl);
            if (s->file < 0 && rc == ES_OK)
                rc = es__h5_fail(ctx, ES_EIO, "store: cannot reopen working copy '%s'", s->work);
        }
    } H5E_END_TRY
    es__free(ctx, h);
    rc = es__par_agree(ctx, rc);
    if (rc != ES_OK && s) s->broken = true;
    return rc;
}

#else /* no MPI or a serial HDF5: the ranks never get here (a context is alone) */

static es_status no_mpi(es_ctx *ctx)
{
    ES_FAIL(ctx, ES_EINVAL, "store: writing on the ranks of an MPI job needs a build with "
            "-Dmpi=enabled (parallel HDF5)");
}

es_status es__store_ranks_open(es_ctx *ctx, es_store *s, es__store_ranks **out)
{
    (void)s;
    *out = NULL;
    return no_mpi(ctx);
}

es_status es__store_ranks_write(es_ctx *ctx, es__store_ranks *h, int64_t row0, int64_t n,
                                const double *lengths, const double *scales, const double *xyz)
{
    (void)h, (void)row0, (void)n, (void)lengths, (void)scales, (void)xyz;
    return no_mpi(ctx);
}

es_status es__store_ranks_close(es_ctx *ctx, es_store *s, es__store_ranks *h)
{
    (void)ctx, (void)s, (void)h;
    return ES_OK;
}

#endif
