/* lib/h5/h5_ranks.c — a file written by the ranks of an MPI job: opened
 * on every rank with HDF5's MPI-IO driver (H5Pset_fapl_mpio on the job's
 * communicator, es__par_comm) and rows written with one collective
 * H5Dwrite per dataset and call (H5Pset_dxpl_mpio, H5FD_MPIO_COLLECTIVE: a
 * rank with no rows takes part with an empty selection). The store's rows
 * on the ranks (lib/store/store_ranks.c) are built on these; MPI's types
 * stay here and in lib/parallel. */
#include "h5/h5_pkg.h"
#include "parallel/parallel_private.h"

#if ES_HAVE_MPI && defined(H5_HAVE_PARALLEL)

bool es__h5_parallel(void) { return true; }

es__h5_id es__h5_file_open_ranks(es_ctx *ctx, const char *path)
{
    hid_t fapl = es__h5_file_access(), f = -1;
    if (fapl >= 0 &&
        H5Pset_fapl_mpio(fapl, *(MPI_Comm *)es__par_comm(ctx), MPI_INFO_NULL) >= 0)
        f = H5Fopen(path, H5F_ACC_RDWR, fapl);
    ES__H5_KEEP_ERROR(es__h5_close(fapl));
    return f;
}

es_status es__h5_write_rows_ranks(es_ctx *ctx, es__h5_id file, const char *name, int64_t row0,
                                  int64_t n, const double *buf)
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

#else /* no MPI or a serial HDF5: the store refuses before it gets here */

bool es__h5_parallel(void) { return false; }

es__h5_id es__h5_file_open_ranks(es_ctx *ctx, const char *path)
{
    (void)ctx, (void)path;
    return -1;
}

es_status es__h5_write_rows_ranks(es_ctx *ctx, es__h5_id file, const char *name, int64_t row0,
                                  int64_t n, const double *buf)
{
    (void)file, (void)name, (void)row0, (void)n, (void)buf;
    ES_FAIL(ctx, ES_EINVAL, "h5: this build's HDF5 does not write in parallel");
}

#endif
