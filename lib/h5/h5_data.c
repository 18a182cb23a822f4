/* lib/h5/h5_data.c — datasets and links: row datasets created, appended to
 * and read in blocks, fixed datasets written and read whole, what a
 * dataset is and how much of it the file holds, and the links, groups and
 * objects of a file.
 *
 * Storage: the on-disk types are little-endian (H5T_IEEE_F64LE,
 * H5T_STD_I64LE), strings variable-length UTF-8, and row datasets chunked
 * with an unlimited first dimension so that appending a shape appends a
 * row (datasets-spec/store-format.md). A function that returns an int or
 * an id keeps HDF5's error stack for its caller's es__h5_fail.
 */
#include "h5/h5_pkg.h"

#include <stdlib.h>
#include <string.h>

#define CACHE_BYTES (16u << 20)

hid_t es__h5_str_type(void)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0) return t;
    if (H5Tset_size(t, H5T_VARIABLE) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

static hid_t dataset_access(void)
{
    hid_t dapl = H5Pcreate(H5P_DATASET_ACCESS);
    if (dapl >= 0) H5Pset_chunk_cache(dapl, 521, CACHE_BYTES, 1.0);
    return dapl;
}

/* With a 16 MiB chunk cache, for whole reads. */
hid_t es__h5_open_ds(hid_t loc, const char *name)
{
    hid_t dapl = dataset_access(), ds = H5Dopen2(loc, name, dapl);
    es__h5_close(dapl);
    return ds;
}

/* For appends: no chunk cache, so whole chunks go straight from the
 * caller's buffer to the file instead of through a copy per chunk. */
hid_t es__h5_open_ds_nocache(hid_t loc, const char *name)
{
    hid_t dapl = H5Pcreate(H5P_DATASET_ACCESS), ds;
    if (dapl >= 0) H5Pset_chunk_cache(dapl, 0, 0, 1.0);
    ds = H5Dopen2(loc, name, dapl);
    es__h5_close(dapl);
    return ds;
}

/* Rows per chunk so that a chunk is about 1 MiB (at least 1, at most 64):
 * big enough for sequential reads, small enough for the 16 MiB cache. */
static hsize_t chunk_rows(size_t row_bytes)
{
    size_t r = row_bytes ? ((size_t)1 << 20) / row_bytes : 64;
    return r < 1 ? 1 : r > 64 ? 64 : r;
}

/* The file and memory types of an element type (the string type: close it). */
static hid_t file_type(es__h5_type t)
{
    switch (t) {
    case ES__H5_F64: return H5T_IEEE_F64LE;
    case ES__H5_I64: return H5T_STD_I64LE;
    case ES__H5_F32: return H5T_IEEE_F32LE;
    case ES__H5_I32: return H5T_STD_I32LE;
    default: return es__h5_str_type();
    }
}

static hid_t mem_type(es__h5_type t)
{
    switch (t) {
    case ES__H5_F64: return H5T_NATIVE_DOUBLE;
    case ES__H5_I64: return H5T_NATIVE_INT64;
    case ES__H5_F32: return H5T_NATIVE_FLOAT;
    case ES__H5_I32: return H5T_NATIVE_INT32;
    default: return es__h5_str_type();
    }
}

es_status es__h5_create_rows(es_ctx *ctx, es__h5_id loc, const char *name, es__h5_type type,
                             int rank, uint64_t d1, uint64_t d2, size_t elem_bytes)
{
    hsize_t dims[3] = {0, d1, d2}, maxd[3] = {H5S_UNLIMITED, d1, d2}, chunk[3];
    size_t row = elem_bytes * (rank > 1 ? d1 : 1) * (rank > 2 ? d2 : 1);
    hid_t sp = -1, dcpl = -1, ds = -1, ftype = file_type(type);
    es_status rc = ES_OK;
    chunk[0] = rank == 1 ? 256 : chunk_rows(row);
    chunk[1] = d1;
    chunk[2] = d2;
    if ((sp = H5Screate_simple(rank, dims, maxd)) < 0 ||
        (dcpl = H5Pcreate(H5P_DATASET_CREATE)) < 0 || H5Pset_chunk(dcpl, rank, chunk) < 0 ||
        (ds = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT)) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create dataset '%s'", name);
    es__h5_close(ds);
    es__h5_close(dcpl);
    es__h5_close(sp);
    if (type == ES__H5_STR) es__h5_close(ftype);
    return rc;
}

/* Append n rows from buf (memory type mtype, the dataset's row shape);
 * buf NULL: make room for them only (HDF5's fill value until written). */
static es_status append_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t mtype, int64_t n,
                             const void *buf)
{
    hsize_t dims[3], start[3] = {0, 0, 0}, count[3];
    hid_t ds = -1, fsp = -1, msp = -1;
    es_status rc = ES_OK;
    int rank;
    if (n == 0) return ES_OK;
    if ((ds = es__h5_open_ds_nocache(loc, name)) < 0 || (fsp = H5Dget_space(ds)) < 0 ||
        (rank = H5Sget_simple_extent_dims(fsp, dims, NULL)) < 1 || rank > 3) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot open dataset '%s'", name);
        goto done;
    }
    es__h5_close(fsp);
    fsp = -1;
    start[0] = dims[0];
    count[0] = (hsize_t)n;
    for (int k = 1; k < rank; k++) count[k] = dims[k];
    dims[0] += (hsize_t)n;
    if (H5Dset_extent(ds, dims) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot append to dataset '%s'", name);
        goto done;
    }
    if (!buf) goto done;   /* room only: the ranks write the rows (store_ranks.c) */
    if ((fsp = H5Dget_space(ds)) < 0 ||
        H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
        (msp = H5Screate_simple(rank, count, NULL)) < 0 ||
        H5Dwrite(ds, mtype, msp, fsp, H5P_DEFAULT, buf) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot append to dataset '%s'", name);
done:
    es__h5_close(msp);
    es__h5_close(fsp);
    es__h5_close(ds);
    return rc;
}

es_status es__h5_append_f64(es_ctx *ctx, es__h5_id loc, const char *name, int64_t n,
                            const double *v)
{
    return append_rows(ctx, loc, name, H5T_NATIVE_DOUBLE, n, v);
}

es_status es__h5_append_room(es_ctx *ctx, es__h5_id loc, const char *name, int64_t n)
{
    return append_rows(ctx, loc, name, H5T_NATIVE_DOUBLE, n, NULL);
}

es_status es__h5_append_strs(es_ctx *ctx, es__h5_id loc, const char *name, int64_t n,
                             const char *const *v)
{
    hid_t t = es__h5_str_type();
    es_status rc;
    /* (the store made its type before opening /labels: a failure there is
     * its "cannot open /labels") */
    if (t < 0) return es__h5_fail(ctx, ES_EIO, "store: cannot append to dataset '%s'", name);
    rc = append_rows(ctx, loc, name, t, n, v);
    es__h5_close(t);
    return rc;
}

es_status es__h5_allocate_rows(es_ctx *ctx, hid_t loc, const char *name, int64_t row0,
                               int64_t n)
{
    hsize_t cd[3] = {1, 1, 1}, start[3] = {0, 0, 0}, stride[3] = {1, 1, 1}, count[3] = {1, 1, 1};
    hid_t ds = -1, dcpl = -1, fsp = -1, msp = -1;
    double *zeros = NULL;
    es_status rc = ES_OK;
    int rank;
    if (n <= 0) return ES_OK;
    if ((ds = es__h5_open_ds_nocache(loc, name)) < 0 || (dcpl = H5Dget_create_plist(ds)) < 0 ||
        (fsp = H5Dget_space(ds)) < 0 || (rank = H5Sget_simple_extent_ndims(fsp)) < 1 ||
        rank > 3 || H5Pget_chunk(dcpl, rank, cd) != rank || cd[0] < 1) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot open dataset '%s'", name);
        goto done;
    }
    /* the chunk holding row0 has rows before it (allocated) unless row0 starts one */
    start[0] = ((hsize_t)row0 + cd[0] - 1) / cd[0] * cd[0];
    if (start[0] >= (hsize_t)(row0 + n)) goto done;
    stride[0] = cd[0];
    count[0] = ((hsize_t)(row0 + n) - start[0] + cd[0] - 1) / cd[0];
    if (!(zeros = es__alloc_array(ctx, (int64_t)count[0], sizeof *zeros))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if (H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, stride, count, NULL) < 0 ||
        (msp = H5Screate_simple(1, count, NULL)) < 0 ||
        H5Dwrite(ds, H5T_NATIVE_DOUBLE, msp, fsp, H5P_DEFAULT, zeros) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot make room in dataset '%s'", name);
done:
    es__free(ctx, zeros);
    es__h5_close(msp);
    es__h5_close(fsp);
    es__h5_close(dcpl);
    es__h5_close(ds);
    return rc;
}
uint64_t es__h5_covered_bytes(hid_t ds, int rank, uint64_t elem)
{
    hid_t dcpl = H5Dget_create_plist(ds), sp = H5Dget_space(ds);
    hsize_t cd[3] = {1, 1, 1}, nchunks = 0;
    uint64_t have = H5Dget_storage_size(ds), per = elem;
    /* (1.10.8's H5Dget_num_chunks refuses H5S_ALL: the dataset's space) */
    if (dcpl >= 0 && H5Pget_nfilters(dcpl) > 0 && H5Pget_layout(dcpl) == H5D_CHUNKED &&
        rank >= 1 && rank <= 3 && H5Pget_chunk(dcpl, rank, cd) == rank && sp >= 0 &&
        H5Dget_num_chunks(ds, sp, &nchunks) >= 0) {
        for (int k = 0; k < rank; k++)
            if (__builtin_mul_overflow(per, (uint64_t)cd[k], &per)) per = UINT64_MAX;
        if (__builtin_mul_overflow(per, (uint64_t)nchunks, &have)) have = UINT64_MAX;
    }
    es__h5_close(sp);
    es__h5_close(dcpl);
    return have;
}

es_status es__h5_check_chunks(es_ctx *ctx, hid_t ds, const char *path, const char *name,
                               uint64_t elem)
{
    hid_t dcpl = H5Dget_create_plist(ds), sp = H5Dget_space(ds);
    hsize_t cd[8], dims[8], maxd[8], n = 0, off[8], size = 0;
    haddr_t addr;
    unsigned mask;
    uint64_t nominal = elem;
    es_status rc = ES_OK;
    int rank;
    if (dcpl < 0 || sp < 0 || (rank = H5Sget_simple_extent_dims(sp, dims, maxd)) < 0 ||
        rank > 8) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: '%s': cannot read the layout of %s", path, name);
        goto done;
    }
    if (H5Pget_layout(dcpl) != H5D_CHUNKED) goto done;
    /* chunks within the fixed dimensions (HDF5 makes them so; a changed byte
     * of the layout message made a 6 KB chunk of positions claim 12 MB, and
     * libhdf5 1.10 read it past its buffer), and a stored chunk of the size
     * they make when nothing compresses it */
    if (H5Pget_chunk(dcpl, rank, cd) != rank) goto bad;
    for (int k = 0; k < rank; k++)
        if (cd[k] < 1 || (maxd[k] != H5S_UNLIMITED && cd[k] > maxd[k]) ||
            __builtin_mul_overflow(nominal, (uint64_t)cd[k], &nominal))
            goto bad;
    if (nominal > ((uint64_t)1 << 32)) goto bad;
    if (H5Pget_nfilters(dcpl) == 0 && H5Dget_num_chunks(ds, sp, &n) >= 0 && n > 0 &&
        (H5Dget_chunk_info(ds, sp, 0, off, &mask, &addr, &size) < 0 || size != nominal))
        goto bad;
    goto done;
bad:
    rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: the chunks of %s do not fit it", path,
                  name);
done:
    es__h5_close(sp);
    es__h5_close(dcpl);
    return rc;
}

bool es__h5_bad_name(const char *name)
{
    return !name || !*name || strchr(name, '/') || !strcmp(name, ".") || !strcmp(name, "..");
}

/* ---- fixed datasets written and read whole ---- */

static int put(hid_t loc, const char *name, es__h5_type type, int rank, const uint64_t *dims,
               const void *v, bool parents)
{
    hsize_t d[32], total = 1;
    hid_t ftype = file_type(type), mtype = mem_type(type), sp = -1, ds = -1, lcpl = -1;
    int r = 0;
    for (int k = 0; k < rank && k < 32; k++) total *= (d[k] = (hsize_t)dims[k]);
    if (ftype < 0 || mtype < 0 || rank > 32 ||
        (parents && ((lcpl = H5Pcreate(H5P_LINK_CREATE)) < 0 ||
                     H5Pset_create_intermediate_group(lcpl, 1) < 0)) ||
        (sp = rank ? H5Screate_simple(rank, d, NULL) : H5Screate(H5S_SCALAR)) < 0 ||
        (ds = H5Dcreate2(loc, name, ftype, sp, parents ? lcpl : H5P_DEFAULT, H5P_DEFAULT,
                         H5P_DEFAULT)) < 0 ||
        (total > 0 && H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0))
        r = -1;
    /* (string types were made here; the others are HDF5's predefined ones) */
    es__h5_close_kept((const hid_t[]){ds, sp, lcpl, type == ES__H5_STR ? ftype : -1,
                                      type == ES__H5_STR ? mtype : -1}, 5);
    return r;
}

int es__h5_put_f64(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const double *v, bool parents)
{
    return put(loc, name, ES__H5_F64, rank, dims, v, parents);
}

int es__h5_put_i64(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const int64_t *v, bool parents)
{
    return put(loc, name, ES__H5_I64, rank, dims, v, parents);
}

int es__h5_put_f32(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const float *v)
{
    return put(loc, name, ES__H5_F32, rank, dims, v, false);
}

int es__h5_put_i32(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const int32_t *v)
{
    return put(loc, name, ES__H5_I32, rank, dims, v, false);
}

int es__h5_put_strs(es__h5_id loc, const char *name, int64_t n, const char *const *v,
                    bool parents)
{
    uint64_t d = (uint64_t)n;
    return put(loc, name, ES__H5_STR, 1, &d, v, parents);
}

es__h5_id es__h5_dataset_open(es__h5_id loc, const char *name)
{
    return H5Dopen2(loc, name, H5P_DEFAULT);
}

int es__h5_dataset_info(es__h5_id ds, es__h5_info *info)
{
    hid_t sp = H5Dget_space(ds), t = H5Dget_type(ds);
    hsize_t d[32];
    int r = -1;
    memset(info, 0, sizeof *info);
    if (sp >= 0 && t >= 0 && (info->rank = H5Sget_simple_extent_dims(sp, d, NULL)) >= 0) {
        H5T_class_t c = H5Tget_class(t);
        for (int k = 0; k < info->rank; k++) info->dims[k] = d[k];
        info->npoints = H5Sget_simple_extent_type(sp) == H5S_NULL
                            ? 0 : (int64_t)H5Sget_simple_extent_npoints(sp);
        info->cls = c == H5T_INTEGER ? ES__H5_CLASS_INTEGER : c == H5T_FLOAT ? ES__H5_CLASS_FLOAT
                    : c == H5T_STRING ? ES__H5_CLASS_STRING : ES__H5_CLASS_OTHER;
        info->size = H5Tget_size(t);
        info->vlen = c == H5T_STRING && H5Tis_variable_str(t) > 0;
        r = 0;
    }
    if (r < 0) info->rank = -1;
    es__h5_close_kept((const hid_t[]){t, sp}, 2);
    return r;
}

int es__h5_dataset_read_f64(es__h5_id ds, double *out)
{
    return H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0 ? -1 : 0;
}

int es__h5_dataset_read_i64(es__h5_id ds, int64_t *out)
{
    return H5Dread(ds, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0 ? -1 : 0;
}

int es__h5_dataset_read_int(es__h5_id ds, int *out)
{
    return H5Dread(ds, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0 ? -1 : 0;
}

static int read_whole(hid_t loc, const char *name, hid_t mtype, void *out)
{
    hid_t ds = es__h5_open_ds(loc, name);
    int r = ds < 0 || H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0 ? -1 : 0;
    ES__H5_KEEP_ERROR(es__h5_close(ds));
    return r;
}

int es__h5_read_f64(es__h5_id loc, const char *name, double *out)
{
    return read_whole(loc, name, H5T_NATIVE_DOUBLE, out);
}

int es__h5_read_i64(es__h5_id loc, const char *name, int64_t *out)
{
    return read_whole(loc, name, H5T_NATIVE_INT64, out);
}

/* The cnt block at start of open dataset ds (closed here) into the
 * leading cnt block of memory of dims mdims, as doubles. */
static int read_block(hid_t ds, int rank, const hsize_t *start, const hsize_t *cnt,
                      const hsize_t *mdims, double *out)
{
    static const hsize_t zero[3] = {0, 0, 0};
    hid_t fsp = -1, msp = -1;
    int r = 0;
    if (ds < 0) return -1;
    if ((fsp = H5Dget_space(ds)) < 0 ||
        H5Sselect_hyperslab(fsp, H5S_SELECT_SET, start, NULL, cnt, NULL) < 0 ||
        (msp = H5Screate_simple(rank, mdims, NULL)) < 0 ||
        H5Sselect_hyperslab(msp, H5S_SELECT_SET, zero, NULL, cnt, NULL) < 0 ||
        H5Dread(ds, H5T_NATIVE_DOUBLE, msp, fsp, H5P_DEFAULT, out) < 0)
        r = -1;
    es__h5_close_kept((const hid_t[]){msp, fsp, ds}, 3);
    return r;
}

/* Blocks of rows move whole chunks: no chunk cache. */
int es__h5_read_rows_f64(es__h5_id loc, const char *name, int64_t row0, int64_t n, int64_t m,
                         double *out, int64_t ld)
{
    const hsize_t start[2] = {(hsize_t)row0, 0}, cnt[2] = {(hsize_t)n, (hsize_t)m};
    const hsize_t mdims[2] = {(hsize_t)n, (hsize_t)ld};
    return read_block(es__h5_open_ds_nocache(loc, name), 2, start, cnt, mdims, out);
}

int es__h5_read_row3_f64(es__h5_id loc, const char *name, int64_t row, int64_t d1, int64_t d2,
                         double *out)
{
    const hsize_t start[3] = {(hsize_t)row, 0, 0}, cnt[3] = {1, (hsize_t)d1, (hsize_t)d2};
    return read_block(es__h5_open_ds(loc, name), 3, start, cnt, cnt, out);
}

/* ---- links, groups and objects ---- */

int es__h5_exists(es__h5_id loc, const char *name)
{
    return H5Lexists(loc, name, H5P_DEFAULT);
}

int es__h5_delete(es__h5_id loc, const char *name)
{
    return H5Ldelete(loc, name, H5P_DEFAULT) < 0 ? -1 : 0;
}

es__h5_id es__h5_group_create(es__h5_id loc, const char *name, bool parents)
{
    hid_t lcpl = -1, g = -1;
    if (!parents) return H5Gcreate2(loc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if ((lcpl = H5Pcreate(H5P_LINK_CREATE)) >= 0 && H5Pset_create_intermediate_group(lcpl, 1) >= 0)
        g = H5Gcreate2(loc, name, lcpl, H5P_DEFAULT, H5P_DEFAULT);
    ES__H5_KEEP_ERROR(es__h5_close(lcpl));
    return g;
}

es__h5_id es__h5_group_open(es__h5_id loc, const char *name)
{
    return H5Gopen2(loc, name, H5P_DEFAULT);
}

es__h5_id es__h5_object_open(es__h5_id loc, const char *name)
{
    return H5Oopen(loc, name, H5P_DEFAULT);
}

int64_t es__h5_group_size(es__h5_id g)
{
    H5G_info_t info;
    return H5Gget_info(g, &info) < 0 ? -1 : (int64_t)info.nlinks;
}

int es__h5_copy(es__h5_id src, const char *name, es__h5_id dst, const char *dname)
{
    hid_t lcpl = -1;
    int r = 0;
    if ((lcpl = H5Pcreate(H5P_LINK_CREATE)) < 0 || H5Pset_create_intermediate_group(lcpl, 1) < 0 ||
        H5Ocopy(src, name, dst, dname, H5P_DEFAULT, lcpl) < 0)
        r = -1;
    ES__H5_KEEP_ERROR(es__h5_close(lcpl));
    return r;
}

typedef struct lister { es__h5_name_fn fn; void *ud; } lister;

static herr_t link_cb(hid_t g, const char *name, const H5L_info_t *info, void *data)
{
    const lister *l = data;
    (void)g;
    (void)info;
    return l->fn(l->ud, name) < 0 ? -1 : 0;
}

static herr_t attr_cb(hid_t loc, const char *name, const H5A_info_t *info, void *data)
{
    const lister *l = data;
    (void)loc;
    (void)info;
    return l->fn(l->ud, name) < 0 ? -1 : 0;
}

int es__h5_list(es__h5_id g, bool attrs, es__h5_name_fn fn, void *ud)
{
    lister l = {fn, ud};
    herr_t r = attrs ? H5Aiterate2(g, H5_INDEX_NAME, H5_ITER_INC, NULL, attr_cb, &l)
                     : H5Literate(g, H5_INDEX_NAME, H5_ITER_INC, NULL, link_cb, &l);
    return r < 0 ? -1 : 0;
}
