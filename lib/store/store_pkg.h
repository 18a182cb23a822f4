/* lib/store/store_pkg.h — what the files of lib/store share and nothing
 * outside it may see: the handle (struct es_store), the HDF5 helpers
 * (store_h5.c), the working copy and its publishing (store_publish.c), the
 * in-memory row metadata (store_rows.c), and creating a store from raw
 * topology arrays (es_store_create wraps it for an es_mesh). The module's
 * own tests may include it after defining ES_MODULE_STORE. */
#ifndef EDGESPACE_STORE_PKG_H
#define EDGESPACE_STORE_PKG_H

#ifndef ES_MODULE_STORE
#error "store/store_pkg.h is private to lib/store/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "core/strmap.h"
#include "edgespace/es_store.h"

#include <hdf5.h>

#include <stdbool.h>
#include <stdint.h>
#include <sys/stat.h>

/* faces: 3 x nfaces, edges: 2 x nedges (as es_mesh_faces/es_mesh_edges),
 * fingerprint: 16 hex digits (es_mesh_fingerprint) or "". */
es_status es__store_create_raw(es_ctx *ctx, const char *path, int64_t nverts, int64_t nfaces,
                               const int64_t *faces, int64_t nedges, const int64_t *edges,
                               const char *fingerprint, es_store **out);

struct es_store {
    es_ctx *ctx;
    char *path;            /* the store as named by the user */
    char *work;            /* working copy (writes) or NULL */
    hid_t file;
    es_store_mode mode;
    bool is_new;           /* created by es_store_create, not yet published */
    bool broken;           /* a write failed half-way: never commit */
    struct stat orig;      /* identity of the original when it was copied */
    struct stat opened;    /* identity of the file the in-memory rows came from */
    unsigned tmp_counter;
    int64_t nrows, nverts, nfaces, nedges;
    es_topology_kind kind;
    char fingerprint[17];
    char **ids, **sources, **hashes; /* nrows each */
    int64_t cap;
    es__strmap id_rows;    /* ids[i] -> i; its keys are the strings ids[i] point
                            * to, which stay put when ids itself is regrown */
    int64_t ncols;
    char **colnames;
    char ***labels;        /* labels[col][row] */
};

/* ---- HDF5 helpers (store_h5.c); callers run inside H5E_BEGIN_TRY ---- */

/* Record fmt plus the innermost message of HDF5's error stack and return
 * code. Call right after the failing HDF5 call, before any other. */
es_status es__h5_fail(es_ctx *ctx, es_status code, const char *fmt, ...) ES__PRINTF(3, 4);
/* Close any HDF5 identifier by its type; negative ids are ignored. */
void es__h5_close(hid_t id);
/* A variable-length UTF-8 string type (close it), or negative. */
hid_t es__h5_str_type(void);
/* File access: HDF5 1.8-readable format, file locking where supported. */
hid_t es__h5_file_access(void);
/* Open a dataset with a 16 MiB chunk cache, or without any (for appends
 * and block reads, which move whole chunks). */
hid_t es__h5_open_ds(hid_t loc, const char *name);
hid_t es__h5_open_ds_nocache(hid_t loc, const char *name);
/* An empty, row-extendable chunked dataset of rank 1..3 with rows of
 * d1 (x d2) elements of elem_bytes each. */
es_status es__h5_create_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t ftype, int rank,
                             hsize_t d1, hsize_t d2, size_t elem_bytes);
/* Append n rows from buf (memory type mtype, the dataset's row shape). */
es_status es__h5_append_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t mtype,
                             int64_t n, const void *buf);
/* Write (replacing) a scalar int64, a scalar float64, a string, or a 1-D
 * string attribute. */
es_status es__h5_write_attr_i64(es_ctx *ctx, hid_t obj, const char *key, int64_t v);
es_status es__h5_write_attr_f64(es_ctx *ctx, hid_t obj, const char *key, double v);
es_status es__h5_write_attr_str(es_ctx *ctx, hid_t obj, const char *key, const char *v);
es_status es__h5_write_attr_strs(es_ctx *ctx, hid_t obj, const char *key,
                                 const char *const *v, int64_t n);
/* A scalar integer attribute; objname names obj in the message. */
es_status es__h5_read_attr_i64(es_ctx *ctx, hid_t obj, const char *objname, const char *key,
                               int64_t *v);
/* Any string or scalar numeric attribute as text into buf[n], truncated;
 * ES_ENOTFOUND if absent. */
es_status es__h5_read_attr_text(es_ctx *ctx, hid_t obj, const char *key, char *buf, size_t n);
/* A whole 1-D string dataset of exactly n rows into n strings allocated
 * through ctx (out[i] owned by the caller, also on failure). */
es_status es__h5_read_strings(es_ctx *ctx, hid_t loc, const char *name, int64_t n,
                              char **out);
/* Rows of a dataset of rank rank_want (its dims in dims), or -1. */
int64_t es__h5_dataset_rows(hid_t loc, const char *name, int rank_want, hsize_t *dims);
/* A name HDF5 cannot take as one link: NULL, empty, ".", ".." or with '/'. */
bool es__h5_bad_name(const char *name);

/* ---- the working copy and its publishing (store_publish.c) ---- */

/* Remove ".<base>.tmp-<pid>-<n>" siblings of path whose process is gone. */
void es__store_clean_stale(const char *path);
/* A fresh temporary sibling name for s->path (NULL: ES_ENOMEM recorded). */
char *es__store_temp_name(es_store *s);
/* Before any write: refuse read-only or broken handles, and on the first
 * write switch the handle to a working copy of the file it opened. */
es_status es__store_begin_write(es_store *s);
/* Flush, fsync and publish the working copy over s->path (link() for a new
 * store), then reopen it read-only; ES_OK at once if nothing was written.
 * A failure marks the handle broken. */
es_status es__store_publish(es_ctx *ctx, es_store *s);

/* ---- in-memory row metadata (store_rows.c) ---- */

/* Free ids, sources, hashes, labels, column names and the id map. */
void es__store_free_rows(es_store *s);
/* Grow the per-row arrays to hold `need` rows; new slots are NULL. */
es_status es__store_reserve_rows(es_store *s, int64_t need);
/* Map each of the s->nrows loaded ids to its row (the first of repeats). */
es_status es__store_index_ids(es_store *s);

#endif
