/* lib/store/store_pkg.h — what the files of lib/store share and nothing
 * outside it may see: the handle (struct es_store), the working copy and
 * its publishing (store_publish.c), the in-memory row metadata (store_rows.c), and creating a store from raw
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
#include "h5/h5_private.h"

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
    es__h5_id file;        /* the working file (read-write) or the published one
                            * (read-only) */
    bool pending;          /* written or deleted through this handle: published at commit */
    bool deleted;          /* delete at commit */
    bool replaces;         /* a published file was there when the write began */
} es__beside;

struct es_store {
    es_ctx *ctx;
    char *path;            /* the store as named by the user */
    char *target;          /* path's target when path is a symbolic link, or NULL */
    char *work;            /* working copy (writes) or NULL */
    es__h5_id file;
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
                          es__h5_id *f, const char **fpath);
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
es_status es__result_find_link(es_ctx *ctx, es__h5_id file, const char *fpath, const char *full,
                               bool *exists);
/* The attribute messages of obj checked before HDF5 decodes any. */
es_status es__result_check_attrs(es_ctx *ctx, const char *fpath, es__h5_id obj, const char *full);
enum { ES__RESULT_READ, ES__RESULT_WRITE_BEGUN, ES__RESULT_CREATE };
/* The file that holds result path rel ("kind/name[/...]"): beside the store
 * (format 3) or the store itself; see store_results.c. */
es_status es__result_locate(es_ctx *ctx, es_store *s, const char *rel, int how, es__h5_id *f,
                            const char **fpath);
/* es__result_locate, then whether /analysis/<path> (into full[n]) exists there. */
es_status es__result_find(es_ctx *ctx, es_store *s, const char *path, int how, char *full,
                          size_t n, es__h5_id *f, const char **fpath, bool *exists);

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
