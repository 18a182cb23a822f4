/* lib/h5/h5_private.h — the one adapter between libedgespace and HDF5
 * (libhdf5): what lib/store and the statismo files of lib/ingest call
 * instead of the HDF5 C API, which only lib/h5 includes. Library-private.
 *
 * Objects: an es__h5_id is an open HDF5 object (file, group, dataset,
 * attribute), HDF5's own identifier; negative is none (or a failure).
 * Close each with es__h5_close.
 *
 * Errors: the functions that return an id or an int fail with a negative
 * value and leave HDF5's reason on its error stack for the caller's
 * es__h5_fail, which adds it to the caller's message; those that return
 * es_status record their message themselves. Every entry point of the
 * library that calls these runs them inside ES__H5_QUIET (HDF5 prints
 * nothing) after es__h5_init.
 *
 * Formats: on disk, reals are little-endian IEEE, integers little-endian
 * two's complement, strings variable-length UTF-8 unless said otherwise;
 * row datasets are chunked with an unlimited first dimension
 * (datasets-spec/store-format.md). Messages name the store ("store: ...")
 * as they always have: the store is what users see.
 *
 * The format checker (h5_headers.c, h5_groups.c, h5_vlen.c): libhdf5 1.10
 * trusts what a file says, so every object header, group symbol table and
 * variable-length string is checked here, read raw, before libhdf5
 * decodes it. */
#ifndef EDGESPACE_H5_PRIVATE_H
#define EDGESPACE_H5_PRIVATE_H

#if !defined(ES_BUILDING_LIBRARY) && !defined(ES_TESTING)
#error "h5/h5_private.h is private to libedgespace"
#endif

#include "core/core_private.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* An open HDF5 object: HDF5's hid_t, which is int64_t since 1.10 (checked
 * where it is used, lib/h5/h5_pkg.h). */
typedef int64_t es__h5_id;

/* ---- errors and quiet sections (h5_file.c) ---- */

/* Record fmt plus the innermost message of HDF5's error stack and return
 * code. Call right after the failing call, before any other. */
es_status es__h5_fail(es_ctx *ctx, es_status code, const char *fmt, ...) ES__PRINTF(3, 4);
/* Before the first HDF5 call of an entry point that opens or creates a
 * file: keeps HDF5's exit handler from printing. */
void es__h5_init(void);
/* HDF5's error printing off for one statement (H5E_BEGIN_TRY/H5E_END_TRY):
 * the library never prints. */
typedef struct es__h5_quiet {
    unsigned is_v2;
    void (*func)(void);
    void *data;
} es__h5_quiet;
void es__h5_quiet_begin(es__h5_quiet *q);
void es__h5_quiet_end(const es__h5_quiet *q);
#define ES__H5_QUIET(stmt)                   \
    do {                                     \
        es__h5_quiet es__h5_q_;              \
        es__h5_quiet_begin(&es__h5_q_);      \
        stmt;                                \
        es__h5_quiet_end(&es__h5_q_);        \
    } while (0)
/* Close any object by its kind; negative ids are ignored (0). Negative if
 * HDF5 failed to close it. */
int es__h5_close(es__h5_id id);

/* ---- files (h5_file.c) ---- */

/* 1 if path is an HDF5 file, 0 if not, negative if it cannot be read. */
int es__h5_is_hdf5(const char *path);
/* Open read-only or read-write with the library's file access (HDF5 1.8
 * readable format, file locking where the file system has it). */
es__h5_id es__h5_file_open(const char *path, bool write);
/* Open read-only with HDF5's default file access. */
es__h5_id es__h5_file_open_default(const char *path);
/* Create path (refused if it exists, unless truncate) with the library's
 * file access. */
es__h5_id es__h5_file_create(const char *path, bool truncate);
/* Create a file that lives in memory until its image is taken
 * (es__h5_file_image); path only names it (refused if it exists). */
es__h5_id es__h5_file_create_memory(const char *path);
/* A file of es__h5_file_create_memory flushed and its bytes copied into
 * *img (allocated through ctx, *size bytes); ES_EIO names path. */
es_status es__h5_file_image(es_ctx *ctx, es__h5_id file, const char *path, char **img,
                            size_t *size);
/* Close a file this process opened, the one way every HDF5 writer closes
 * (the store, statismo files): keep (flushed, then closed; a failed flush
 * makes it a discarded file and returns ES_EIO naming path) or discard
 * (closed into a memory file, so that a full disk cannot crash libhdf5
 * 1.10.8 at exit). Negative ids are ignored. */
es_status es__h5_file_close(es_ctx *ctx, es__h5_id file, bool keep, const char *path);
/* Flush everything and close (negative on failure, the file closed or not). */
int es__h5_file_flush_close(es__h5_id file);
/* The file an object is in (close it). */
es__h5_id es__h5_file_of(es__h5_id obj);

/* ---- the ranks of an MPI job (h5_ranks.c) ---- */

/* Whether this build's HDF5 writes in parallel (MPI-IO). */
bool es__h5_parallel(void);
/* Open path read-write on every rank of ctx's job with the MPI-IO driver
 * (collective); negative on failure. */
es__h5_id es__h5_file_open_ranks(es_ctx *ctx, const char *path);
/* Collective: this rank's n rows (n may be 0) of rows dataset name from
 * row0 on, written from buf with one collective write. */
es_status es__h5_write_rows_ranks(es_ctx *ctx, es__h5_id file, const char *name, int64_t row0,
                                  int64_t n, const double *buf);

/* ---- links, groups and objects (h5_data.c) ---- */

/* 1 if a link name exists under loc, 0 if not, negative on failure. */
int es__h5_exists(es__h5_id loc, const char *name);
/* Remove link name (negative on failure). */
int es__h5_delete(es__h5_id loc, const char *name);
/* Create a group (parents: with missing groups on the way), open one, or
 * open any object by name. */
es__h5_id es__h5_group_create(es__h5_id loc, const char *name, bool parents);
es__h5_id es__h5_group_open(es__h5_id loc, const char *name);
es__h5_id es__h5_object_open(es__h5_id loc, const char *name);
/* The number of links in group g, negative on failure. */
int64_t es__h5_group_size(es__h5_id g);
/* Copy object name of src to dname of dst, making missing groups. */
int es__h5_copy(es__h5_id src, const char *name, es__h5_id dst, const char *dname);
/* Each link name of group g (attrs false) or attribute name of object g
 * (attrs true), in name order: fn returns 0 to go on, negative to stop
 * (the listing then fails). */
typedef int (*es__h5_name_fn)(void *ud, const char *name);
int es__h5_list(es__h5_id g, bool attrs, es__h5_name_fn fn, void *ud);

/* ---- datasets (h5_data.c) ---- */

/* Element types: on disk as the header says, in memory double, int64_t,
 * float, int32_t or char * (ES__H5_STR: variable-length strings). */
typedef enum es__h5_type { ES__H5_F64, ES__H5_I64, ES__H5_F32, ES__H5_I32, ES__H5_STR } es__h5_type;

/* An empty, row-extendable chunked dataset of rank 1..3 with rows of
 * d1 (x d2) elements of elem_bytes each. */
es_status es__h5_create_rows(es_ctx *ctx, es__h5_id loc, const char *name, es__h5_type type,
                             int rank, uint64_t d1, uint64_t d2, size_t elem_bytes);
/* Append n rows (the dataset's row shape) of doubles or strings. */
es_status es__h5_append_f64(es_ctx *ctx, es__h5_id loc, const char *name, int64_t n,
                            const double *v);
es_status es__h5_append_strs(es_ctx *ctx, es__h5_id loc, const char *name, int64_t n,
                             const char *const *v);
/* Make room for n more rows, unwritten (HDF5's fill value 0 until the
 * ranks write them, es__h5_write_rows_ranks). */
es_status es__h5_append_room(es_ctx *ctx, es__h5_id loc, const char *name, int64_t n);
/* Allocate every chunk of rows [row0, row0 + n) of a rows dataset not
 * allocated yet, by writing one 0 into each (the rest is HDF5's fill value
 * 0 too). Parallel HDF5 1.10.8 allocates all chunks of a dataset at a
 * parallel write only when it has none; in one that has some, each rank
 * allocated the new ones at addresses of its own and wrote over other
 * objects (/topology/edges). So rank 0 allocates them before the ranks
 * write (store_ranks.c), which then only overwrite. */
es_status es__h5_allocate_rows(es_ctx *ctx, es__h5_id loc, const char *name, int64_t row0,
                               int64_t n);
/* A new dataset of fixed shape (rank 0: a scalar, dims unused) written
 * whole from v (row-major); parents: make missing groups on the way.
 * Negative on failure. */
int es__h5_put_f64(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const double *v, bool parents);
int es__h5_put_i64(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const int64_t *v, bool parents);
int es__h5_put_f32(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const float *v);
int es__h5_put_i32(es__h5_id loc, const char *name, int rank, const uint64_t *dims,
                   const int32_t *v);
int es__h5_put_strs(es__h5_id loc, const char *name, int64_t n, const char *const *v,
                    bool parents);
/* A scalar fixed-length NUL-terminated string (statismo's kind). */
int es__h5_put_cstr(es__h5_id loc, const char *name, const char *v);

/* What a dataset is. */
typedef enum es__h5_class {
    ES__H5_CLASS_OTHER, ES__H5_CLASS_INTEGER, ES__H5_CLASS_FLOAT, ES__H5_CLASS_STRING
} es__h5_class;
typedef struct es__h5_info {
    int rank;              /* of its dataspace */
    uint64_t dims[32];     /* H5S_MAX_RANK */
    int64_t npoints;       /* elements */
    es__h5_class cls;
    uint64_t size;         /* bytes of an element on disk (H5Tget_size) */
    bool vlen;             /* a variable-length string */
} es__h5_info;
/* Open a dataset (negative on failure). */
es__h5_id es__h5_dataset_open(es__h5_id loc, const char *name);
/* Its space and type (negative when HDF5 cannot say). */
int es__h5_dataset_info(es__h5_id ds, es__h5_info *info);
/* The whole of an open dataset, converted to double, int64_t or int. */
int es__h5_dataset_read_f64(es__h5_id ds, double *out);
int es__h5_dataset_read_i64(es__h5_id ds, int64_t *out);
int es__h5_dataset_read_int(es__h5_id ds, int *out);
/* The whole of dataset name (opened with a 16 MiB chunk cache; HDF5's
 * reason for a failed open is not kept). */
int es__h5_read_f64(es__h5_id loc, const char *name, double *out);
int es__h5_read_i64(es__h5_id loc, const char *name, int64_t *out);
/* Rows [row0, row0+n) of a 2-D dataset (rows of m) into memory laid out
 * as n rows of stride ld >= m; one row of a 3-D dataset (d1 x d2). */
int es__h5_read_rows_f64(es__h5_id loc, const char *name, int64_t row0, int64_t n, int64_t m,
                         double *out, int64_t ld);
int es__h5_read_row3_f64(es__h5_id loc, const char *name, int64_t row, int64_t d1, int64_t d2,
                         double *out);
/* A chunked dataset's chunks within its fixed dimensions, and its first
 * stored chunk of the size they make when nothing compresses it (elem:
 * bytes an element on disk); ES_OK for other layouts. Checked before HDF5
 * reads it: libhdf5 1.10 reads a chunk at the size its layout claims. */
es_status es__h5_check_chunks(es_ctx *ctx, es__h5_id ds, const char *path, const char *name,
                              uint64_t elem);
/* Bytes of dataset ds (rank 1..3, elem bytes an element) that the file
 * holds: its storage, or for a compressed (filtered) one the uncompressed
 * size of its allocated chunks. A count larger than this is refused before
 * anything of its size is allocated. */
uint64_t es__h5_covered_bytes(es__h5_id ds, int rank, uint64_t elem);
/* A name HDF5 cannot take as one link: NULL, empty, ".", ".." or with '/'. */
bool es__h5_bad_name(const char *name);

/* ---- attributes (h5_attr.c) ---- */

/* 1 if obj has attribute key, 0 if not, negative on failure. */
int es__h5_attr_exists(es__h5_id obj, const char *key);
/* Write (replacing) a scalar int64, a scalar float64, a string, or a 1-D
 * string attribute. */
es_status es__h5_write_attr_i64(es_ctx *ctx, es__h5_id obj, const char *key, int64_t v);
es_status es__h5_write_attr_f64(es_ctx *ctx, es__h5_id obj, const char *key, double v);
es_status es__h5_write_attr_str(es_ctx *ctx, es__h5_id obj, const char *key, const char *v);
es_status es__h5_write_attr_strs(es_ctx *ctx, es__h5_id obj, const char *key,
                                 const char *const *v, int64_t n);
/* A new scalar fixed-length NUL-terminated string attribute (statismo's
 * kind); negative on failure. */
int es__h5_put_attr_cstr(es__h5_id obj, const char *key, const char *v);
/* One integer attribute (a scalar or 1-element integer); objname names obj
 * in the message. */
es_status es__h5_read_attr_i64(es_ctx *ctx, es__h5_id obj, const char *objname,
                               const char *key, int64_t *v);

/* ---- strings read without trusting the file (h5_vlen.c) ----
 * libhdf5 1.10 trusts the global heap that holds variable-length strings
 * (a changed byte crashed it); these decode the strings themselves and
 * check every size against the heap and the file. A raw reader is opened on
 * any object of the file (after a flush, so that it sees this handle's own
 * writes) and keeps the heap collections it parsed until closed; path
 * names the file in messages (borrowed). */
typedef struct es__h5_raw es__h5_raw;
es_status es__h5_raw_open(es_ctx *ctx, es__h5_id obj, const char *path, es__h5_raw **out);
/* A raw reader of a file HDF5 has not opened: fd (the caller's, closed by
 * the caller after es__h5_raw_close), the superblock's base address and
 * sizes of addresses and lengths. */
es_status es__h5_raw_open_fd(es_ctx *ctx, int fd, const char *path, uint64_t base, unsigned sa,
                             unsigned ss, es__h5_raw **out);
void es__h5_raw_close(es__h5_raw *raw);
/* Bytes of one variable-length string descriptor on disk (16 with 8-byte
 * addresses), and the file's size in bytes. */
unsigned es__h5_raw_vlen_size(const es__h5_raw *raw);
uint64_t es__h5_raw_file_size(const es__h5_raw *raw);
/* A whole 1-D string dataset (variable or fixed length) of exactly n rows
 * into out[0..n) (allocated through ctx; the caller frees what is non-NULL,
 * also on failure). */
es_status es__h5_read_strings(es_ctx *ctx, es__h5_raw *raw, es__h5_id loc, const char *name,
                              int64_t n, char **out);
/* Every string of a string attribute (a null dataspace: none). *out has *n
 * strings, each and the array allocated through ctx. */
es_status es__h5_read_attr_strings(es_ctx *ctx, es__h5_raw *raw, es__h5_id obj, const char *key,
                                   char ***out, int64_t *n);
/* A string attribute, or one integer or real as text, into buf[n],
 * truncated; ES_ENOTFOUND if absent (h5_attr.c). */
es_status es__h5_read_attr_text(es_ctx *ctx, es__h5_raw *raw, es__h5_id obj, const char *key,
                                char *buf, size_t n);

/* ---- the format checker (h5_headers.c, h5_groups.c) ---- */

/* Check the symbol table of an old-style group (its v1 B-tree, symbol
 * nodes and local heap) before HDF5 looks anything up in it: libhdf5 1.10
 * follows a local heap free list that loops until memory runs out (24 GB
 * for three changed bytes) and B-tree children without bound. A group with
 * links in its header (new style) has nothing to check. */
es_status es__h5_check_group(es__h5_raw *raw, es__h5_id group, const char *name);
/* The root group's header and symbol table, then each of the n groups
 * named under it that exists (header first, then its symbol table), before
 * HDF5 searches, opens or decodes any of them; an absent one is left for
 * the caller to name. For a store (store_load.c) and a statismo model
 * (statismo_read.c). */
es_status es__h5_check_groups(es__h5_raw *raw, es__h5_id file, const char *const *names,
                              size_t n);
/* Check every message of an object header before HDF5 decodes any of it:
 * the header at oaddr, of the open object obj, or of the object `name`
 * under loc (found without decoding its header); name names it in
 * messages. libhdf5 1.10 decodes what a header says with few checks (a
 * layout message's version byte changed made H5Dopen divide by zero); an
 * object is opened only once its header passed. */
es_status es__h5_check_header(es__h5_raw *raw, uint64_t oaddr, const char *name);
es_status es__h5_check_object(es__h5_raw *raw, es__h5_id obj, const char *name);
es_status es__h5_check_named(es__h5_raw *raw, es__h5_id loc, const char *name);
/* Before HDF5 opens path at all: its superblock (versions 0 to 2) and the
 * headers HDF5 decodes while opening (the root group's, a version 2
 * superblock's extension), read raw (libhdf5 1.10 allocates what the root
 * header's chunks claim, 2 GB and more, before it refuses them). */
es_status es__h5_check_file(es_ctx *ctx, const char *path);

#endif
