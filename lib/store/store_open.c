/* lib/store/store_open.c — the store handle: open and create, load and
 * check what the file holds, close (committing) or abort, and the handle's
 * getters (datasets-spec/store-format.md).
 *
 * One HDF5 file: a format version at the root, the topology, per-shape rows
 * (normalized lengths N x E, scales, positions N x V x 3, ids, source paths,
 * content hashes), string label columns, and analysis results with their
 * provenance. Opening (es__store_load, store_load.c) checks every dataset
 * against the others and reads the row metadata into the handle once, so
 * the getters never touch the file and a store that does not fit its format
 * is refused at open rather than half-way through a study.
 * Every public entry point runs with HDF5's error printing off
 * (ES__H5_QUIET).
 */
#include "store/store_pkg.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static void release(es_store *s, bool keep_work)
{
    if (!s) return;
    es_ctx *ctx = s->ctx;
    if (s->file >= 0) es__h5_file_close(ctx, s->file, !(s->work && !keep_work), s->path);
    s->file = -1;
    if (s->work && !keep_work) unlink(s->work);
    es__file_set_abort(ctx, &s->files);   /* never committed: they never appear */
    es__beside_release(s);
    es__store_free_rows(s);
    es_mesh_free(s->mesh);
    es__free(ctx, s->work);
    es__free(ctx, s->path);
    es__free(ctx, s->target);
    es__free(ctx, s);
}

/* Through a symbolic link writes replace its target (resolved now: the
 * link is what the user named, the file what changes). */
static es_status resolve_link(es_store *s)
{
    struct stat st;
    char *real;
    if (lstat(s->path, &st) != 0 || !S_ISLNK(st.st_mode)) return ES_OK;
    if (!(real = realpath(s->path, NULL)))
        ES_FAIL(s->ctx, errno == ENOENT ? ES_ENOTFOUND : ES_EIO, "store: '%s' is a symbolic "
                "link to a missing file", s->path);
    s->target = es__strdup(s->ctx, real);
    free(real);
    return s->target ? ES_OK : ES_ENOMEM;
}

static es_status open_impl(es_ctx *ctx, const char *path, es_store_mode mode, es_store **out)
{
    es_store *s;
    es_status rc;
    int is;
    *out = NULL;
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "store: empty path");
    if (mode != ES_STORE_READ && mode != ES_STORE_WRITE && mode != ES_STORE_REPLACE)
        ES_FAIL(ctx, ES_EINVAL, "store: bad open mode %d", (int)mode);
    if (access(path, F_OK) != 0)
        ES_FAIL(ctx, errno == ENOENT ? ES_ENOTFOUND : ES_EIO, "store: cannot open '%s': %s",
                path, strerror(errno));
    if ((is = es__h5_is_hdf5(path)) <= 0) {
        if (is < 0) return es__h5_fail(ctx, ES_EIO, "store: cannot read '%s'", path);
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' is not an HDF5 file", path);
    }
    /* what HDF5 decodes while opening (the root group's header) */
    if ((rc = es__h5_check_file(ctx, path)) != ES_OK) return rc;
    if (!(s = es__calloc(ctx, 1, sizeof *s))) return ES_ENOMEM;
    s->ctx = ctx;
    s->file = -1;
    s->mode = mode;
    if (!(s->path = es__strdup(ctx, path))) { rc = ES_ENOMEM; goto fail; }
    if (mode != ES_STORE_READ && (rc = resolve_link(s))) goto fail;
    /* Before opening: if another writer replaces the file in between, the
     * first write sees a different identity and refuses (never stale rows). */
    if (stat(path, &s->opened) != 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot open '%s': %s", path, strerror(errno));
        goto fail;
    }
    /* (es__fail: the store has never named HDF5's reason here) */
    if ((s->file = es__h5_file_open(path, false)) < 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot open '%s'", path);
        goto fail;
    }
    if ((rc = es__store_load(s))) goto fail;
    *out = s;
    return ES_OK;
fail:
    release(s, false);
    return rc;
}

es_status es_store_open(es_ctx *ctx, const char *path, es_store_mode mode, es_store **out)
{
    es_status rc;
    es__h5_init();
    ES__H5_QUIET(rc = open_impl(ctx, path, mode, out));
    return rc;
}

/* /topology/<name>: n rows of `width` vertex indices, fixed size (the
 * topology never changes after creation, so it is neither chunked nor
 * extendable). */
static es_status write_topology(es_ctx *ctx, es__h5_id g, const char *name, int64_t n,
                                int width, const int64_t *data)
{
    const uint64_t d[2] = {(uint64_t)n, (uint64_t)width};
    if (es__h5_put_i64(g, name, 2, d, data, false) < 0)
        return es__h5_fail(ctx, ES_EIO, "store: cannot write /topology/%s", name);
    return ES_OK;
}

static es_status create_impl(es_ctx *ctx, const char *path, int64_t nverts, int64_t nfaces,
                             const int64_t *faces, int64_t nedges, const int64_t *edges,
                             const char *fingerprint, es_store **out)
{
    es_store *s;
    es_status rc = ES_OK;
    es__h5_id g = -1;
    char when[32];
    time_t now = time(NULL);
    struct tm tmv;
    *out = NULL;
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "store: empty path");
    if (nverts < 1 || nfaces < 0 || nedges < 0 || (nfaces > 0 && (!faces || nedges < 1)) ||
        (nedges > 0 && !edges))
        ES_FAIL(ctx, ES_EINVAL, "store: bad topology (%lld vertices, %lld faces, %lld "
                "edges)", (long long)nverts, (long long)nfaces, (long long)nedges);
    for (int64_t e = 0; nfaces == 0 && e < nedges; e++) {
        const int64_t *p = edges + 2 * e;
        if (p[0] < 0 || p[0] >= p[1] || p[1] >= nverts ||
            (e > 0 && (p[-2] > p[0] || (p[-2] == p[0] && p[-1] >= p[1]))))
            ES_FAIL(ctx, ES_EINVAL, "store: edge %lld (%lld, %lld) is not a (min, max) pair of "
                    "vertices below %lld in sorted order without repeats", (long long)e,
                    (long long)p[0], (long long)p[1], (long long)nverts);
    }
    if (access(path, F_OK) == 0)
        ES_FAIL(ctx, ES_EEXIST, "store: '%s' exists already", path);
    {
        struct stat st;
        if (lstat(path, &st) == 0)
            ES_FAIL(ctx, ES_EEXIST, "store: '%s' is a symbolic link to a missing file; "
                    "name the file itself", path);
    }
    if (!(s = es__calloc(ctx, 1, sizeof *s))) return ES_ENOMEM;
    s->ctx = ctx;
    s->file = -1;
    s->mode = ES_STORE_WRITE;
    s->is_new = true;
    s->nverts = nverts;
    s->nfaces = nfaces;
    s->nedges = nedges;
    s->kind = nfaces > 0 ? ES_TOPOLOGY_MESH : nedges > 0 ? ES_TOPOLOGY_TRUSS : ES_TOPOLOGY_NONE;
    snprintf(s->fingerprint, sizeof s->fingerprint, "%.16s", fingerprint ? fingerprint : "");
    if (!(s->path = es__strdup(ctx, path)) || !(s->work = es__store_temp_name(s))) {
        rc = ES_ENOMEM;
        goto fail;
    }
    es__store_clean_stale(path);
    if ((s->file = es__h5_file_create(s->work, false)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create '%s'", s->work);
        goto fail;
    }
    gmtime_r(&now, &tmv);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    /* format 3: results beside the store (store_beside.c), tied to it by its id */
    s->beside = true;
    s->version = ES__FORMAT_VERSION_BESIDE;
    es__beside_new_id(s->store_id);
    if ((rc = es__h5_write_attr_i64(ctx, s->file, "format_version", ES__FORMAT_VERSION_BESIDE)) ||
        (rc = es__h5_write_attr_str(ctx, s->file, "creator", "edgespace " ES_VERSION_STRING)) ||
        (rc = es__h5_write_attr_str(ctx, s->file, "created", when)) ||
        (rc = es__h5_write_attr_str(ctx, s->file, "topology_kind",
                                    es_topology_kind_name(s->kind))) ||
        (rc = es__h5_write_attr_str(ctx, s->file, "store_id", s->store_id)))
        goto fail;
    if ((g = es__h5_group_create(s->file, "/topology", false)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create /topology");
        goto fail;
    }
    if ((rc = es__h5_write_attr_i64(ctx, g, "nverts", nverts)) ||
        (rc = es__h5_write_attr_str(ctx, g, "fingerprint", s->fingerprint)))
        goto fail;
    if ((rc = write_topology(ctx, g, "faces", nfaces, 3, faces)) ||
        (rc = write_topology(ctx, g, "edges", nedges, 2, edges)))
        goto fail;
    es__h5_close(g);
    g = -1;
    if ((g = es__h5_group_create(s->file, "/shapes", false)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create /shapes");
        goto fail;
    }
    /* HDF5 chunks cannot be 0 wide: a store without edges has no lengths
     * (and no scales, which are sums of raw edge lengths). */
    if ((nedges > 0 &&
         ((rc = es__h5_create_rows(ctx, g, "lengths", ES__H5_F64, 2, (uint64_t)nedges, 0, 8)) ||
          (rc = es__h5_create_rows(ctx, g, "scales", ES__H5_F64, 1, 0, 0, 8)))) ||
        (rc = es__h5_create_rows(ctx, g, "positions", ES__H5_F64, 3, (uint64_t)nverts, 3, 8)) ||
        (rc = es__h5_create_rows(ctx, g, "ids", ES__H5_STR, 1, 0, 0, 16)) ||
        (rc = es__h5_create_rows(ctx, g, "source_paths", ES__H5_STR, 1, 0, 0, 16)) ||
        (rc = es__h5_create_rows(ctx, g, "content_hash", ES__H5_STR, 1, 0, 0, 16)))
        goto fail;
    es__h5_close(g);
    if ((g = es__h5_group_create(s->file, "/labels", false)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create /labels");
        goto fail;
    }
    if ((rc = es__h5_write_attr_strs(ctx, g, "columns", NULL, 0))) goto fail;
    es__h5_close(g);
    if ((g = es__h5_group_create(s->file, "/analysis", false)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot create /analysis");
        goto fail;
    }
    es__h5_close(g);
    g = -1;
    if ((rc = es__store_reserve_rows(s, 1))) goto fail;
    *out = s;
    return ES_OK;
fail:
    es__h5_close(g);
    release(s, false);
    return rc;
}

es_status es__store_create_raw(es_ctx *ctx, const char *path, int64_t nverts, int64_t nfaces,
                               const int64_t *faces, int64_t nedges, const int64_t *edges,
                               const char *fingerprint, es_store **out)
{
    es_status rc;
    es__h5_init();
    ES__H5_QUIET(rc = create_impl(ctx, path, nverts, nfaces, faces, nedges, edges, fingerprint,
                                  out));
    return rc;
}

void es_store_abort(es_store *store)
{
    if (!store) return;
    ES__H5_QUIET(release(store, false));
}

/* Back to the published store: the working copy is thrown away (as abort
 * does) and the handle reopens and reloads the file, as open does. */
static es_status rollback_impl(es_ctx *ctx, es_store *s)
{
    es_status rc;
    if (!s->work) {
        /* only results beside the store written (format 3): they are
         * dropped unpublished, the store itself was never touched */
        if (es__beside_pending(s)) {
            es__beside_release(s);
            s->broken = false;
        }
        return ES_OK;
    }
    if (s->is_new)
        ES_FAIL(ctx, ES_EINVAL, "store: '%s' was never committed; abort it instead of rolling "
                "back", s->path);
    es__h5_file_close(ctx, s->file, false, s->work);
    s->file = -1;
    unlink(s->work);
    es__free(s->ctx, s->work);
    s->work = NULL;
    s->broken = false;
    es__store_free_rows(s);
    if (stat(s->path, &s->opened) != 0) {
        s->broken = true;
        ES_FAIL(ctx, ES_EIO, "store: cannot reopen '%s': %s", s->path, strerror(errno));
    }
    if ((s->file = es__h5_file_open(s->path, false)) < 0) {
        s->broken = true;
        return es__fail(ctx, ES_EIO, "store: cannot reopen '%s'", s->path);
    }
    if ((rc = es__store_load(s)) != ES_OK) {
        s->broken = true;
        if (ctx != s->ctx) es__fail(ctx, rc, "%s", es_ctx_errmsg(s->ctx));
    }
    return rc;
}

es_status es_store_rollback(es_ctx *ctx, es_store *store)
{
    es_status rc;
    if (!store) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    es__file_set_abort(store->ctx, &store->files);   /* they went with the writes */
    ES__H5_QUIET(rc = rollback_impl(ctx, store));
    store->generation++;   /* what was read from the discarded writes is stale */
    return rc;
}

int es_store_pending(const es_store *store)
{
    return store && (store->work || es__beside_pending(store));
}

es_status es_store_close(es_store *store)
{
    if (!store) return ES_OK;
    es__h5_quiet q;
    es__h5_quiet_begin(&q);
    const bool pending = store->work || es__beside_pending(store);
    es_status rc = pending && store->broken ? ES_EIO : ES_OK;
    if (pending && !store->broken) {
        rc = es__store_publish(store->ctx, store);
        if (rc != ES_OK)
            es__warn(store->ctx, "%s", es_ctx_errmsg(store->ctx));
    }
    /* the files riding on the handle appear with a published store only */
    es_status frc = es__store_files_done(store->ctx, store, rc);
    if (frc != ES_OK && rc == ES_OK) {
        es__warn(store->ctx, "%s", es_ctx_errmsg(store->ctx));
        rc = frc;
    }
    release(store, false);
    es__h5_quiet_end(&q);
    return rc;
}

uint64_t es_store_generation(const es_store *s) { return s ? s->generation : 0; }
int64_t es_store_nrows(const es_store *s) { return s ? s->nrows : 0; }
int64_t es_store_nedges(const es_store *s) { return s ? s->nedges : 0; }
int64_t es_store_nverts(const es_store *s) { return s ? s->nverts : 0; }
int64_t es_store_nfaces(const es_store *s) { return s ? s->nfaces : 0; }
es_topology_kind es_store_topology_kind(const es_store *s)
{
    return s ? s->kind : ES_TOPOLOGY_MESH;
}
const char *es_store_path(const es_store *s) { return s ? s->path : NULL; }
const char *es_store_fingerprint(const es_store *s) { return s ? s->fingerprint : NULL; }

es_status es_store_set_replace(es_ctx *ctx, es_store *s, int replace)
{
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL handle");
    if (s->mode == ES_STORE_READ)
        ES_FAIL(ctx, ES_EINVAL, "store: '%s' is open for reading: results cannot be replaced",
                s->path);
    s->mode = replace ? ES_STORE_REPLACE : ES_STORE_WRITE;
    return ES_OK;
}

int es_store_is_hdf5(const char *path)
{
    int is = 0;
    if (!path || access(path, F_OK) != 0) return 0;
    ES__H5_QUIET(is = es__h5_is_hdf5(path));
    return is > 0;
}
