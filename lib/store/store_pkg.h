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

/* Format versions (datasets-spec/store-format.md): 1, meshes; 2 adds the
 * root attribute topology_kind ("mesh", "truss", "none"); 3 (written since
 * 0.2) has topology_kind and a store_id, and keeps its results beside the
 * store, one file each (store_beside.c), so that storing one never copies
 * the store. All three are read; 1 and 2 keep their results inside until
 * upgraded (es_store_upgrade). */
#define ES__FORMAT_VERSION 1
#define ES__FORMAT_VERSION_KIND 2
#define ES__FORMAT_VERSION_BESIDE 3

/* Label column names are at most this many bytes (checked at open and
 * append); coordinates at most ES__MAX_COORD in magnitude over an extent of
 * at least ES__MIN_EXTENT (store_rows.c). */
#define ES__MAX_COLUMN_NAME 500
#define ES__MAX_COORD 1e30
#define ES__MIN_EXTENT 1e-30

/* faces: 3 x nfaces, edges: 2 x nedges (as es_mesh_faces/es_mesh_edges),
 * fingerprint: 16 hex digits (es_mesh_fingerprint) or "". */
es_status es__store_create_raw(es_ctx *ctx, const char *path, int64_t nverts, int64_t nfaces,
                               const int64_t *faces, int64_t nedges, const int64_t *edges,
                               const char *fingerprint, es_store **out);

/* A result beside the store: <store>.results/<kind>/<name>.h5, holding the
 * group /analysis/<kind>/<name> as a store would. */
typedef struct es__beside {
    char kind[128], name[128];
    char *path;            /* the published file */
    char *tmp;             /* the working file of a write through this handle, or NULL */
    hid_t file;            /* the working file (read-write) or the published one (read-only) */
    bool pending;          /* written or deleted through this handle: published at commit */
    bool deleted;          /* delete at commit */
    bool replaces;         /* a published file was there when the write began */
} es__beside;

struct es_store {
    es_ctx *ctx;
    char *path;            /* the store as named by the user */
    char *target;          /* path's target when path is a symbolic link, or NULL */
    char *work;            /* working copy (writes) or NULL */
    hid_t file;
    es_store_mode mode;
    bool is_new;           /* created by es_store_create, not yet published */
    bool broken;           /* a write failed half-way: never commit */
    struct stat orig;      /* identity of the original when it was copied */
    struct stat opened;    /* identity of the file the in-memory rows came from */
    unsigned tmp_counter;
    uint64_t generation;   /* es_store_generation: bumped by every write */
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
    int version;           /* format_version: 1, 2 or 3 */
    bool beside;           /* format 3: results live beside the store */
    char store_id[33];     /* format 3: the id its results carry */
    es__beside *side;      /* results beside the store this handle opened or wrote */
    int64_t nside, side_cap;
    es_mesh *mesh;         /* es_store_mesh's last answer (one reference), made with
                            * ctx, while generation and nrows are mesh_generation and
                            * mesh_nrows: its faces and row 0 cannot have changed */
    uint64_t mesh_generation;
    int64_t mesh_nrows;
    es__file_set files;    /* staged files that appear with the next commit
                            * (es__store_publish_with; memory of ctx above) */
};

/* ---- HDF5 helpers (store_h5.c); callers run inside H5E_BEGIN_TRY ---- */

/* Record fmt plus the innermost message of HDF5's error stack and return
 * code. Call right after the failing HDF5 call, before any other. */
es_status es__h5_fail(es_ctx *ctx, es_status code, const char *fmt, ...) ES__PRINTF(3, 4);
/* Before the first HDF5 call of an entry point that opens or creates a
 * file: keeps HDF5's exit handler from printing (store_h5.c). */
void es__h5_init(void);
/* Close any HDF5 identifier by its type; negative ids are ignored. */
void es__h5_close(hid_t id);
/* A variable-length UTF-8 string type (close it), or negative. */
hid_t es__h5_str_type(void);
/* File access: HDF5 1.8-readable format, file locking where supported. */
hid_t es__h5_file_access(void);
/* Close a file this process opened, the one way every HDF5 writer closes
 * (the store, statismo files): keep (flushed, then closed; a failed flush
 * makes it a discarded file and returns ES_EIO naming path) or discard
 * (closed into a memory file, so that a full disk cannot crash libhdf5
 * 1.10.8 at exit). Negative ids are ignored. */
es_status es__h5_file_close(es_ctx *ctx, hid_t file, bool keep, const char *path);
/* Open a dataset with a 16 MiB chunk cache, or without any (for appends
 * and block reads, which move whole chunks). */
hid_t es__h5_open_ds(hid_t loc, const char *name);
hid_t es__h5_open_ds_nocache(hid_t loc, const char *name);
/* An empty, row-extendable chunked dataset of rank 1..3 with rows of
 * d1 (x d2) elements of elem_bytes each. */
es_status es__h5_create_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t ftype, int rank,
                             hsize_t d1, hsize_t d2, size_t elem_bytes);
/* Append n rows from buf (memory type mtype, the dataset's row shape);
 * buf NULL: make room for them only (HDF5's fill value until written). */
es_status es__h5_append_rows(es_ctx *ctx, hid_t loc, const char *name, hid_t mtype,
                             int64_t n, const void *buf);
/* Allocate every chunk of rows [row0, row0 + n) of a rows dataset not
 * allocated yet, by writing one 0 into each (the rest is HDF5's fill value
 * 0 too). Parallel HDF5 1.10.8 allocates all chunks of a dataset at a
 * parallel write only when it has none; in one that has some, each rank
 * allocated the new ones at addresses of its own and wrote over other
 * objects (/topology/edges). So rank 0 allocates them before the ranks
 * write (store_ranks.c), which then only overwrite. */
es_status es__h5_allocate_rows(es_ctx *ctx, hid_t loc, const char *name, int64_t row0,
                               int64_t n);
/* Write (replacing) a scalar int64, a scalar float64, a string, or a 1-D
 * string attribute. */
es_status es__h5_write_attr_i64(es_ctx *ctx, hid_t obj, const char *key, int64_t v);
es_status es__h5_write_attr_f64(es_ctx *ctx, hid_t obj, const char *key, double v);
es_status es__h5_write_attr_str(es_ctx *ctx, hid_t obj, const char *key, const char *v);
es_status es__h5_write_attr_strs(es_ctx *ctx, hid_t obj, const char *key,
                                 const char *const *v, int64_t n);
/* One integer attribute (a scalar or 1-element integer); objname names obj
 * in the message. */
es_status es__h5_read_attr_i64(es_ctx *ctx, hid_t obj, const char *objname, const char *key,
                               int64_t *v);

/* ---- strings read without trusting the file (store_vlen.c) ----
 * libhdf5 1.10 trusts the global heap that holds variable-length strings
 * (a changed byte crashed it); these decode the strings themselves and
 * check every size against the heap and the file. A raw reader is opened on
 * any object of the file (after a flush, so that it sees this handle's own
 * writes) and keeps the heap collections it parsed until closed; path
 * names the store in messages (borrowed). */
typedef struct es__h5_raw es__h5_raw;
es_status es__h5_raw_open(es_ctx *ctx, hid_t obj, const char *path, es__h5_raw **out);
/* A raw reader of a file HDF5 has not opened: fd (the caller's, closed by
 * the caller after es__h5_raw_close), the superblock's base address and
 * sizes of addresses and lengths. */
es_status es__h5_raw_open_fd(es_ctx *ctx, int fd, const char *path, uint64_t base, unsigned sa,
                             unsigned ss, es__h5_raw **out);
void es__h5_raw_close(es__h5_raw *raw);
/* A whole 1-D string dataset (variable or fixed length) of exactly n rows
 * into out[0..n) (allocated through ctx; the caller frees what is non-NULL,
 * also on failure). */
/* Bytes of one variable-length string descriptor on disk (16 with 8-byte
 * addresses), and the file's size in bytes. */
unsigned es__h5_raw_vlen_size(const es__h5_raw *raw);
uint64_t es__h5_raw_file_size(const es__h5_raw *raw);
es_status es__h5_read_strings(es_ctx *ctx, es__h5_raw *raw, hid_t loc, const char *name,
                              int64_t n, char **out);
/* Every string of a string attribute (a null dataspace: none). *out has *n
 * strings, each and the array allocated through ctx. */
es_status es__h5_read_attr_strings(es_ctx *ctx, es__h5_raw *raw, hid_t obj, const char *key,
                                   char ***out, int64_t *n);
/* Raw access for the structure checks (store_groups.c): n bytes at a file
 * address, bounded by the file; little-endian numbers; the sizes of
 * addresses and lengths. */
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
/* Check the symbol table of an old-style group (its v1 B-tree, symbol
 * nodes and local heap; store_groups.c) before HDF5 looks anything up in
 * it: libhdf5 1.10 follows a local heap free list that loops until memory
 * runs out (24 GB for three changed bytes) and B-tree children without
 * bound. A group with links in its header (new style) has nothing to check. */
es_status es__h5_check_group(es__h5_raw *raw, hid_t group, const char *name);
/* The root group's header and symbol table, then each of the n groups
 * named under it that exists (header first, then its symbol table), before
 * HDF5 searches, opens or decodes any of them; an absent one is left for
 * the caller to name. For a store (store_load.c) and a statismo model
 * (statismo_read.c). */
es_status es__h5_check_groups(es__h5_raw *raw, hid_t file, const char *const *names, size_t n);
/* Check every message of an object header before HDF5 decodes any of it
 * (store_headers.c): the header at oaddr, of the open object obj, or of
 * the object `name` under loc (found without decoding its header); name
 * names it in messages. libhdf5 1.10 decodes what a header says with few
 * checks (a layout message's version byte changed made H5Dopen divide by
 * zero); a store object is opened only once its header passed. */
es_status es__h5_check_header(es__h5_raw *raw, uint64_t oaddr, const char *name);
es_status es__h5_check_object(es__h5_raw *raw, hid_t obj, const char *name);
es_status es__h5_check_named(es__h5_raw *raw, hid_t loc, const char *name);
/* Before HDF5 opens path at all: its superblock (versions 0 to 2) and the
 * headers HDF5 decodes while opening (the root group's, a version 2
 * superblock's extension), read raw (libhdf5 1.10 allocates what the root
 * header's chunks claim, 2 GB and more, before it refuses them). */
es_status es__h5_check_file(es_ctx *ctx, const char *path);
/* A string attribute, or one integer or real as text, into buf[n],
 * truncated; ES_ENOTFOUND if absent. */
es_status es__h5_read_attr_text(es_ctx *ctx, es__h5_raw *raw, hid_t obj, const char *key,
                                char *buf, size_t n);
/* A chunked dataset's chunks within its fixed dimensions, and its first
 * stored chunk of the size they make when nothing compresses it (elem:
 * bytes an element on disk); ES_OK for other layouts. Checked before HDF5
 * reads it: libhdf5 1.10 reads a chunk at the size its layout claims. */
es_status es__h5_check_chunks(es_ctx *ctx, hid_t ds, const char *path, const char *name,
                               uint64_t elem);
/* Bytes of dataset ds (rank 1..3, elem bytes an element) that the file
 * holds: its storage, or for a compressed (filtered) one the uncompressed
 * size of its allocated chunks. A count larger than this is refused before
 * anything of its size is allocated. */
uint64_t es__h5_covered_bytes(hid_t ds, int rank, uint64_t elem);
/* A name HDF5 cannot take as one link: NULL, empty, ".", ".." or with '/'. */
bool es__h5_bad_name(const char *name);

/* ---- the working copy and its publishing (store_publish.c) ---- */

/* Remove ".<base>.tmp-<pid>-<n>" siblings of path whose process is gone. */
void es__store_clean_stale(const char *path);
/* A fresh temporary sibling name for s->path (NULL: ES_ENOMEM recorded). */
/* The file a store's writes replace: its path, or a symbolic link's target;
 * its results folder (format 3) sits beside that file. */
const char *es__store_target(const es_store *s);
char *es__store_temp_name(es_store *s);
/* Before any write: refuse read-only or broken handles, and on the first
 * write switch the handle to a working copy of the file it opened. */
es_status es__store_begin_write(es_store *s);
/* Flush, fsync and publish the working copy over s->path (link() for a new
 * store), then reopen it read-only; ES_OK at once if nothing was written.
 * A failure marks the handle broken. */
es_status es__store_publish(es_ctx *ctx, es_store *s);
/* After a commit whose status is rc: the files riding on the handle
 * (s->files) renamed into place when rc is ES_OK, else discarded; returns
 * rc or the rename's error (in ctx). */
es_status es__store_files_done(es_ctx *ctx, es_store *s, es_status rc);

/* A fresh temporary sibling name for any path (the working file of a
 * result beside the store). */
char *es__store_temp_for(es_store *s, const char *path);
/* fsync a file, or a folder (errors ignored for folders). */
es_status es__store_fsync(es_ctx *ctx, const char *path, bool dir);

/* ---- results beside the store (store_beside.c): format 3 ---- */

/* A new store id: 32 hex digits from the system's random source. */
void es__beside_new_id(char id[33]);
/* The file that holds result kind/name for this handle: *f the working
 * file of a write through it, or the published file (read-only), or -1 when
 * neither exists (or the published one belongs to another store);
 * *fpath names it in messages. create: start a write (a working file
 * beside the published one, which it replaces at commit). */
es_status es__beside_file(es_store *s, const char *kind, const char *name, bool create,
                          hid_t *f, const char **fpath);
/* Whether this handle is writing result kind/name beside the store. */
bool es__beside_writing(const es_store *s, const char *kind, const char *name);
/* Delete kind/name at commit (it must exist). */
es_status es__beside_delete(es_store *s, const char *kind, const char *name);
/* Names of kind's results beside the store (kind NULL or "": the kinds),
 * as seen through this handle, appended to *names (unsorted). */
es_status es__beside_names(es_store *s, const char *kind, char ***names, int64_t *n,
                           int64_t *cap);
/* Whether a commit has anything beside the store to publish. */
bool es__beside_pending(const es_store *s);
/* Publish every pending write (written aside, fsynced, renamed or linked)
 * and deletion; a failure marks the handle broken. */
es_status es__beside_publish(es_ctx *ctx, es_store *s);
/* Close every file, remove the working files of writes not published. */
void es__beside_release(es_store *s);

/* ---- result paths (store_results.c; store_catalog.c lists and deletes) ---- */

/* Split "a/b/c" into at most 8 checked link names: their count, or -1 with
 * *rc set. */
int es__result_split(es_ctx *ctx, const char *path, char parts[8][128], es_status *rc);
/* "/analysis/<rel>" into buf. */
void es__result_full_path(char *buf, size_t n, const char *rel);
/* Whether every component of full exists in file (named fpath in
 * messages), each group below /analysis checked before HDF5 searches it. */
es_status es__result_find_link(es_ctx *ctx, hid_t file, const char *fpath, const char *full,
                               bool *exists);
/* The attribute messages of obj checked before HDF5 decodes any. */
es_status es__result_check_attrs(es_ctx *ctx, const char *fpath, hid_t obj, const char *full);
enum { ES__RESULT_READ, ES__RESULT_WRITE_BEGUN, ES__RESULT_CREATE };
/* The file that holds result path rel ("kind/name[/...]"): beside the store
 * (format 3) or the store itself; see store_results.c. */
es_status es__result_locate(es_ctx *ctx, es_store *s, const char *rel, int how, hid_t *f,
                            const char **fpath);
/* es__result_locate, then whether /analysis/<path> (into full[n]) exists there. */
es_status es__result_find(es_ctx *ctx, es_store *s, const char *path, int how, char *full,
                          size_t n, hid_t *f, const char **fpath, bool *exists);

/* ---- in-memory row metadata (store_rows.c) ---- */

/* Free ids, sources, hashes, labels, column names and the id map. */
void es__store_free_rows(es_store *s);
/* Check what the file holds and load the row metadata (store_load.c). */
es_status es__store_load(es_store *s);
/* Grow the per-row arrays to hold `need` rows; new slots are NULL. */
es_status es__store_reserve_rows(es_store *s, int64_t need);
/* Map each of the s->nrows loaded ids to its row; ES_EFORMAT on a repeat. */
es_status es__store_index_ids(es_store *s);

#endif
