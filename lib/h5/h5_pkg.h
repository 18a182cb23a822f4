/* lib/h5/h5_pkg.h — what the files of lib/h5 share and nothing outside it
 * may see: HDF5's own header, the library's property lists and types, and
 * the raw reader's byte access for the format checker. The module's own
 * tests may include it after defining ES_MODULE_H5. */
#ifndef EDGESPACE_H5_PKG_H
#define EDGESPACE_H5_PKG_H

#ifndef ES_MODULE_H5
#error "h5/h5_pkg.h is private to lib/h5/ (see lib/README.md)"
#endif

#include "h5/h5_private.h"

#include <hdf5.h>

_Static_assert(sizeof(hid_t) == sizeof(es__h5_id), "es__h5_id holds an HDF5 hid_t");

/* Close what a failed call left open without clearing HDF5's error stack
 * (every HDF5 call clears it), so that the caller's es__h5_fail still
 * names HDF5's reason. */
#define ES__H5_KEEP_ERROR(stmt)                                \
    do {                                                       \
        hid_t es__h5_err_ = H5Eget_current_stack();            \
        stmt;                                                  \
        if (es__h5_err_ >= 0) H5Eset_current_stack(es__h5_err_); \
    } while (0)

/* Close n ids (negative ones skipped) within ES__H5_KEEP_ERROR: after a
 * failed call, the caller's es__h5_fail still names HDF5's reason. */
void es__h5_close_kept(const hid_t *ids, int n);

/* A variable-length UTF-8 string type (close it), or negative. */
hid_t es__h5_str_type(void);
/* File access: HDF5 1.8-readable format, file locking where supported. */
hid_t es__h5_file_access(void);
/* Open a dataset with a 16 MiB chunk cache (for whole reads: HDF5's
 * reason for a failed open is not kept). */
hid_t es__h5_open_ds(hid_t loc, const char *name);
/* Open a dataset without a chunk cache (for appends and block reads, which
 * move whole chunks). */
hid_t es__h5_open_ds_nocache(hid_t loc, const char *name);

/* Raw access for the structure checks (h5_groups.c, h5_headers.c): n bytes
 * at a file address, bounded by the file; little-endian numbers; the sizes
 * of addresses and lengths. */
es_status es__h5_raw_read(es__h5_raw *raw, uint64_t addr, uint64_t n, void *buf,
                          const char *what);
uint64_t es__h5_le(const uint8_t *p, unsigned n);
unsigned es__h5_raw_addr_size(const es__h5_raw *raw);
unsigned es__h5_raw_length_size(const es__h5_raw *raw);
es_ctx *es__h5_raw_ctx(const es__h5_raw *raw);
const char *es__h5_raw_path(const es__h5_raw *raw);
/* Each message of an object header (its type, flags and bytes): return 0
 * to go on, 1 to stop (ES_OK), -1 if it is malformed (ES_EFORMAT).
 * ES_ENOTFOUND when no call stopped. */
typedef int (*es__h5_msg_fn)(void *ud, unsigned type, unsigned flags, const uint8_t *msg,
                             uint64_t n);
es_status es__h5_raw_messages(es__h5_raw *raw, uint64_t oaddr, es__h5_msg_fn fn, void *ud);
/* The object header address of an open object (group, dataset, file: its
 * root group). */
es_status es__h5_object_addr(es_ctx *ctx, hid_t obj, uint64_t *addr);

#endif
