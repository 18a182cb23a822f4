/* lib/store/store_beside.c — results beside the store (format version 3):
 * each result is its own small HDF5 file <store>.results/<kind>/<name>.h5,
 * holding the group /analysis/<kind>/<name> exactly as a store of version 1
 * or 2 holds it inside. Storing a result therefore costs what the result
 * holds, not a copy of the store (a 100 GB store took minutes and twice its
 * size on disk to publish a 1 KB point).
 *
 * Crash safety is the store's own scheme at the size of one result: a
 * result is built in memory (HDF5's core driver), written at commit to a
 * temporary sibling ".<name>.h5.tmp-<pid>-<n>" by plain write()s, fsynced,
 * and published by link() (a new name: refuses one that appeared
 * meanwhile) or rename() (--replace), then the folder is fsynced. Building
 * it in memory means HDF5 itself never fails a write (libhdf5 1.10.8
 * crashes at exit after a failed close, HDFFV-11052): a full disk or a file
 * size limit is one clean error of our own write(). A result costs its
 * size in memory once more, as it is already held by the caller.
 * A reader sees the old result or the new one; a writer killed at any
 * moment leaves the store and every published result as they were, plus a
 * stale temporary that the next writer of that name removes (its pid is
 * dead). Deletion is unlink(). Each result file carries the store's
 * store_id: a stale folder left by a deleted store of the same name is
 * never mistaken for this store's results.
 *
 * Result files come from the disk like the store itself, so they are
 * checked the same way (their root and /analysis groups here, the result's
 * groups and attributes by store_results.c) before HDF5 searches them.
 */
#include "store/store_pkg.h"
#include "core/files.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define SUFFIX ".h5"

void es__beside_new_id(char id[33])
{
    unsigned char b[16];
    int fd = open("/dev/urandom", O_RDONLY | O_CLOEXEC);
    ssize_t got = fd >= 0 ? read(fd, b, sizeof b) : -1;
    if (fd >= 0) close(fd);
    if (got != (ssize_t)sizeof b) {
        /* no random source: time, pid and an address, mixed (splitmix64) */
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        uint64_t x = (uint64_t)ts.tv_sec * 1000000007u ^ (uint64_t)ts.tv_nsec ^
                     ((uint64_t)getpid() << 32) ^ (uint64_t)(uintptr_t)id;
        for (int i = 0; i < 16; i++) {
            uint64_t z = (x += 0x9E3779B97F4A7C15ull);
            z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
            z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
            b[i] = (unsigned char)(z ^ (z >> 31));
        }
    }
    for (int i = 0; i < 16; i++) snprintf(id + 2 * i, 3, "%02x", b[i]);
}

/* <store>.results[/<kind>[/<name>.h5]] (kind, name NULL: shorter), beside
 * the store's file: through a symbolic link, beside its target, so every
 * link to one store sees one set of results. */
static char *side_path(es_store *s, const char *kind, const char *name)
{
    const char *base = es__store_target(s);
    size_t n = strlen(base) + 300;
    char *p = es__malloc(s->ctx, n);
    if (!p) return NULL;
    if (!kind) snprintf(p, n, "%s.results", base);
    else if (!name) snprintf(p, n, "%s.results/%s", base, kind);
    else snprintf(p, n, "%s.results/%s/%s" SUFFIX, base, kind, name);
    return p;
}

static es__beside *find(es_store *s, const char *kind, const char *name)
{
    for (int64_t i = 0; i < s->nside; i++)
        if (!strcmp(s->side[i].kind, kind) && !strcmp(s->side[i].name, name)) return &s->side[i];
    return NULL;
}

static es__beside *add(es_store *s, const char *kind, const char *name)
{
    if (s->nside == s->side_cap) {
        int64_t cap = s->side_cap ? 2 * s->side_cap : 8;
        es__beside *p = es__realloc(s->ctx, s->side, (size_t)cap * sizeof *p);
        if (!p) return NULL;
        s->side = p;
        s->side_cap = cap;
    }
    es__beside *b = &s->side[s->nside];
    memset(b, 0, sizeof *b);
    b->file = -1;
    snprintf(b->kind, sizeof b->kind, "%s", kind);
    snprintf(b->name, sizeof b->name, "%s", name);
    if (!(b->path = side_path(s, kind, name))) return NULL;
    s->nside++;
    return b;
}

/* Open a published result file read-only and check that it is this
 * store's: ES_OK with *f = -1 when it is absent or another store's. */
static es_status open_published(es_store *s, const char *path, es__h5_id *f)
{
    es_ctx *ctx = s->ctx;
    char id[40];
    es__h5_raw *raw = NULL;
    es_status rc = ES_OK;
    es__h5_id g = -1;
    *f = -1;
    if (access(path, F_OK) != 0) return ES_OK;
    /* a result file is read like a store: its superblock and the headers
     * HDF5 decodes on opening checked first (h5_headers.c) */
    if ((rc = es__h5_check_file(ctx, path)) != ES_OK) return rc;
    es__h5_id file = es__h5_file_open(path, false);
    /* (es__fail: the store has never named HDF5's reason here) */
    if (file < 0) return es__fail(ctx, ES_EFORMAT, "store: cannot read result file '%s'", path);
    /* the root's attributes and groups checked before HDF5 decodes them */
    if ((rc = es__h5_raw_open(ctx, file, path, &raw)) || (rc = es__h5_check_object(raw, file, "the root group")) ||
        (rc = es__h5_check_group(raw, file, "/")))
        goto done;
    if (es__h5_read_attr_text(ctx, raw, file, "store_id", id, sizeof id) != ES_OK ||
        strcmp(id, s->store_id))
        goto done; /* another store's (or not a result): not this store's result */
    if (es__h5_exists(file, "/analysis") > 0) {
        if ((rc = es__h5_check_named(raw, file, "/analysis"))) goto done;
        if ((g = es__h5_group_open(file, "/analysis")) < 0) {
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: '%s': /analysis is not a group", path);
            goto done;
        }
        if ((rc = es__h5_check_group(raw, g, "/analysis"))) goto done;
    }
    *f = file;
    file = -1;
done:
    es__h5_close(g);
    es__h5_raw_close(raw);
    es__h5_close(file);
    return rc;
}

static es_status make_dir(es_ctx *ctx, const char *dir)
{
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
        ES_FAIL(ctx, ES_EIO, "store: cannot create folder '%s': %s", dir, strerror(errno));
    return ES_OK;
}

/* The working file of a write of b: folders made, a stale working file of
 * a dead writer removed, the file created with the store's id. */
static es_status begin_write(es_store *s, es__beside *b)
{
    es_ctx *ctx = s->ctx;
    es_status rc = ES_OK;
    char *top, *dir;
    /* as a write into the store (store_publish.c): cancelled work stores
     * nothing, and values read before are stale from here on */
    if ((rc = es__cancelled(ctx, "a write"))) return rc;
    s->generation++;
    top = side_path(s, NULL, NULL);
    dir = side_path(s, b->kind, NULL);
    if (!top || !dir) rc = ES_ENOMEM;
    if (rc == ES_OK && !(rc = make_dir(ctx, top))) rc = make_dir(ctx, dir);
    es__free(ctx, top);
    es__free(ctx, dir);
    if (rc) return rc;
    es__store_clean_stale(b->path);
    es__store_clean_stale(es__store_target(s));   /* and the store's own, as a write would */
    if (!(b->tmp = es__store_temp_for(s, b->path))) return ES_ENOMEM;
    /* in memory until the commit writes its image (no backing store) */
    if ((b->file = es__h5_file_create_memory(b->tmp)) < 0) {
        /* (es__fail: the store has never named HDF5's reason here) */
        rc = es__fail(ctx, ES_EIO, "store: cannot create '%s'", b->tmp);
        es__free(ctx, b->tmp);
        b->tmp = NULL;
        return rc;
    }
    if ((rc = es__h5_write_attr_str(ctx, b->file, "store_id", s->store_id)) ||
        (rc = es__h5_write_attr_str(ctx, b->file, "creator", "edgespace " ES_VERSION_STRING)))
        return rc;
    b->pending = true;
    b->deleted = false;
    return ES_OK;
}

es_status es__beside_file(es_store *s, const char *kind, const char *name, bool create,
                          es__h5_id *f, const char **fpath)
{
    es_status rc;
    es__beside *b = find(s, kind, name);
    *f = -1;
    *fpath = s->path;
    if (!b) {
        es__h5_id pub;
        char *path = side_path(s, kind, name);
        if (!path) return ES_ENOMEM;
        rc = open_published(s, path, &pub);
        es__free(s->ctx, path);
        if (rc) return rc;
        if (pub < 0 && !create) return ES_OK;
        if (!(b = add(s, kind, name))) {
            es__h5_close(pub);
            return ES_ENOMEM;
        }
        b->file = pub;
        /* a file there that is not ours (a deleted store's) is replaced too */
        b->replaces = pub >= 0 || access(b->path, F_OK) == 0;
    }
    if (create && !b->tmp) {
        es__h5_close(b->file);
        b->file = -1;
        if ((rc = begin_write(s, b))) return rc;
    }
    if (b->deleted && !create) return ES_OK;
    *f = b->file;
    *fpath = b->tmp ? b->tmp : b->path;
    return ES_OK;
}

bool es__beside_writing(const es_store *s, const char *kind, const char *name)
{
    for (int64_t i = 0; i < s->nside; i++)
        if (!strcmp(s->side[i].kind, kind) && !strcmp(s->side[i].name, name))
            return s->side[i].tmp != NULL;
    return false;
}

es_status es__beside_delete(es_store *s, const char *kind, const char *name)
{
    es__beside *b = find(s, kind, name);
    es_status rc;
    if (!b) ES_FAIL(s->ctx, ES_ENOTFOUND, "store: no result %s/%s beside '%s'", kind, name, s->path);
    if ((rc = es__cancelled(s->ctx, "a write"))) return rc;
    s->generation++;
    es__h5_close(b->file);
    b->file = -1;
    es__free(s->ctx, b->tmp);
    b->tmp = NULL;
    b->deleted = b->pending = true;
    return ES_OK;
}

bool es__beside_pending(const es_store *s)
{
    for (int64_t i = 0; i < s->nside; i++)
        if (s->side[i].pending) return true;
    return false;
}

static es_status push_name(es_store *s, const char *v, size_t len, char ***names, int64_t *n,
                           int64_t *cap)
{
    for (int64_t i = 0; i < *n; i++)
        if (strlen((*names)[i]) == len && !strncmp((*names)[i], v, len)) return ES_OK;
    if (*n == *cap) {
        int64_t c = *cap ? 2 * *cap : 16;
        char **p = es__realloc(s->ctx, *names, (size_t)c * sizeof *p);
        if (!p) return ES_ENOMEM;
        *names = p;
        *cap = c;
    }
    if (!((*names)[*n] = es__malloc(s->ctx, len + 1))) return ES_ENOMEM;
    memcpy((*names)[*n], v, len);
    (*names)[*n][len] = '\0';
    (*n)++;
    return ES_OK;
}

/* Whether kind/name is a result of this store as seen through the handle. */
static es_status visible(es_store *s, const char *kind, const char *name, bool *yes)
{
    es__h5_id f;
    const char *fp;
    es_status rc = es__beside_file(s, kind, name, false, &f, &fp);
    *yes = rc == ES_OK && f >= 0;
    return rc;
}

es_status es__beside_names(es_store *s, const char *kind, char ***names, int64_t *n,
                           int64_t *cap)
{
    es_status rc = ES_OK;
    bool kinds = !kind || !*kind;
    char *dir = side_path(s, kinds ? NULL : kind, NULL);
    DIR *d;
    struct dirent *e;
    if (!dir) return ES_ENOMEM;
    d = opendir(dir);
    es__free(s->ctx, dir);
    while (d && rc == ES_OK && (e = readdir(d))) {
        size_t len = strlen(e->d_name), sl = strlen(SUFFIX);
        if (e->d_name[0] == '.' && (len < 2 || e->d_name[1] == '.' || len == 1)) continue;
        if (kinds) {
            /* a kind with at least one result of this store */
            char **sub = NULL;
            int64_t ns = 0, cs = 0;
            if (es__h5_bad_name(e->d_name) || strlen(e->d_name) > 120) continue;
            rc = es__beside_names(s, e->d_name, &sub, &ns, &cs);
            if (rc == ES_OK && ns > 0) rc = push_name(s, e->d_name, len, names, n, cap);
            for (int64_t i = 0; i < ns; i++) es__free(s->ctx, sub[i]);
            es__free(s->ctx, sub);
            continue;
        }
        if (len <= sl || strcmp(e->d_name + len - sl, SUFFIX) || len - sl > 120) continue;
        char name[128];
        bool yes;
        memcpy(name, e->d_name, len - sl);
        name[len - sl] = '\0';
        if (es__h5_bad_name(name)) continue;
        if ((rc = visible(s, kind, name, &yes)) == ES_OK && yes)
            rc = push_name(s, name, len - sl, names, n, cap);
    }
    if (d) closedir(d);
    /* this handle's writes not yet published */
    for (int64_t i = 0; i < s->nside && rc == ES_OK; i++) {
        const es__beside *b = &s->side[i];
        if (!b->tmp || b->deleted) continue;
        if (kinds) rc = push_name(s, b->kind, strlen(b->kind), names, n, cap);
        else if (!strcmp(b->kind, kind)) rc = push_name(s, b->name, strlen(b->name), names, n, cap);
    }
    return rc;
}

/* The in-memory file of b written to b->tmp (created, written, fsynced;
 * removed again on failure) and closed. */
static es_status write_image(es_ctx *ctx, es__beside *b)
{
    es_status rc = ES_OK;
    ssize_t size;
    size_t bytes = 0;
    char *img = NULL;
    int fd = -1;
    if ((rc = es__h5_file_image(ctx, b->file, b->path, &img, &bytes))) return rc;
    size = (ssize_t)bytes;
    es__h5_close(b->file);   /* in memory: nothing to fail */
    b->file = -1;
    if ((fd = open(b->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666)) < 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot create '%s': %s", b->tmp, strerror(errno));
        goto done;
    }
    for (ssize_t at = 0; at < size;) {
        ssize_t k = write(fd, img + at, (size_t)(size - at));
        if (k < 0 && errno == EINTR) continue;
        if (k < 0) {
            rc = es__fail(ctx, ES_EIO, "store: cannot write '%s': %s", b->tmp, strerror(errno));
            goto done;
        }
        at += k;
    }
    if (fsync(fd) != 0)
        rc = es__fail(ctx, ES_EIO, "store: cannot sync '%s': %s", b->tmp, strerror(errno));
done:
    if (fd >= 0 && close(fd) != 0 && rc == ES_OK)
        rc = es__fail(ctx, ES_EIO, "store: cannot write '%s': %s", b->tmp, strerror(errno));
    if (rc != ES_OK && fd >= 0) unlink(b->tmp);
    es__free(ctx, img);
    return rc;
}

/* Publish one pending write or deletion. */
static es_status publish_one(es_ctx *ctx, es_store *s, es__beside *b)
{
    es_status rc;
    char *dir = es__path_dir(ctx, b->path);
    if (!dir) return ES_ENOMEM;
    if (b->deleted) {
        if (unlink(b->path) != 0 && errno != ENOENT) {
            rc = es__fail(ctx, ES_EIO, "store: cannot delete '%s': %s", b->path, strerror(errno));
            goto done;
        }
        es__store_fsync(ctx, dir, true);
        rmdir(dir); /* the kind's last result takes its folder with it (if empty) */
        rc = ES_OK;
        goto done;
    }
    if ((rc = write_image(ctx, b))) goto done;
    if (!b->replaces || s->mode != ES_STORE_REPLACE) {
        /* a new name: link() refuses one that another writer published meanwhile */
        if (link(b->tmp, b->path) != 0) {
            if (errno == EEXIST && !b->replaces)
                rc = es__fail(ctx, ES_EEXIST, "store: result %s/%s was stored by another writer "
                              "meanwhile; nothing written", b->kind, b->name);
            else if (rename(b->tmp, b->path) != 0)
                rc = es__fail(ctx, ES_EIO, "store: cannot publish '%s': %s", b->path,
                              strerror(errno));
            if (rc) goto done;
        }
        unlink(b->tmp);
    } else if (rename(b->tmp, b->path) != 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot replace '%s': %s", b->path, strerror(errno));
        goto done;
    }
    es__store_fsync(ctx, dir, true);
done:
    es__free(ctx, dir);
    return rc;
}

es_status es__beside_publish(es_ctx *ctx, es_store *s)
{
    es_status rc = ES_OK;
    if (!es__beside_pending(s)) return ES_OK;
    if (s->broken)
        ES_FAIL(ctx, ES_EIO, "store: an earlier write to '%s' failed; nothing committed", s->path);
    if ((rc = es__cancelled(ctx, "a commit")) || (rc = es__cancelled(s->ctx, "a commit")))
        return rc;
    for (int64_t i = 0; i < s->nside && rc == ES_OK; i++)
        if (s->side[i].pending) rc = publish_one(ctx, s, &s->side[i]);
    if (rc != ES_OK) {
        s->broken = true;
        return rc;
    }
    /* forget what was published: later reads open the published files */
    es__beside_release(s);
    return ES_OK;
}

void es__beside_release(es_store *s)
{
    for (int64_t i = 0; i < s->nside; i++) {
        es__beside *b = &s->side[i];
        es__h5_close(b->file);
        if (b->tmp) unlink(b->tmp);
        es__free(s->ctx, b->tmp);
        es__free(s->ctx, b->path);
    }
    es__free(s->ctx, s->side);
    s->side = NULL;
    s->nside = s->side_cap = 0;
}

/* ---- upgrading a store of version 1 or 2 --------------------------------- */

/* Copy /analysis/<kind>/<name> of the store into its file beside it. */
static es_status move_out(es_store *s, const char *kind, const char *name)
{
    char full[300];
    es__h5_id f;
    const char *fp;
    es_status rc = es__beside_file(s, kind, name, true, &f, &fp);
    if (rc) return rc;
    snprintf(full, sizeof full, "/analysis/%s/%s", kind, name);
    if (es__h5_copy(s->file, full, f, full) < 0)
        rc = es__h5_fail(s->ctx, ES_EIO, "store: cannot copy %s to '%s'", full, fp);
    return rc;
}

static es_status upgrade_impl(es_ctx *ctx, es_store *s)
{
    char **kinds = NULL, **names = NULL;
    int64_t nk = 0, nn = 0;
    es_status rc;
    if (s->beside) return ES_OK;   /* version 3 already */
    es__beside_new_id(s->store_id);
    rc = es_store_list_results(ctx, s, NULL, &kinds, &nk);
    for (int64_t k = 0; rc == ES_OK && k < nk; k++) {
        if ((rc = es_store_list_results(ctx, s, kinds[k], &names, &nn))) break;
        for (int64_t i = 0; rc == ES_OK && i < nn; i++) rc = move_out(s, kinds[k], names[i]);
        for (int64_t i = 0; i < nn; i++) es__free(ctx, names[i]);
        es__free(ctx, names);
    }
    /* the store: results gone from it, version 3 with the files' id */
    if (rc == ES_OK) rc = es__store_begin_write(s);
    for (int64_t k = 0; rc == ES_OK && k < nk; k++) {
        char g[200];
        snprintf(g, sizeof g, "/analysis/%s", kinds[k]);
        if (es__h5_delete(s->file, g) < 0)
            rc = es__h5_fail(ctx, ES_EIO, "store: cannot remove %s", g);
    }
    if (rc == ES_OK &&
        !((rc = es__h5_write_attr_i64(ctx, s->file, "format_version", ES__FORMAT_VERSION_BESIDE)) ||
          (rc = es__h5_write_attr_str(ctx, s->file, "topology_kind",
                                      es_topology_kind_name(s->kind))) ||
          (rc = es__h5_write_attr_str(ctx, s->file, "store_id", s->store_id)))) {
        /* the results first: until the store carries their id they are not its */
        if ((rc = es__beside_publish(ctx, s)) == ES_OK) rc = es__store_publish(ctx, s);
    }
    for (int64_t k = 0; k < nk; k++) es__free(ctx, kinds[k]);
    es__free(ctx, kinds);
    if (rc == ES_OK) {
        s->beside = true;
        s->version = ES__FORMAT_VERSION_BESIDE;
    } else {
        s->broken = true;
    }
    return rc;
}

es_status es_store_upgrade(es_ctx *ctx, es_store *s)
{
    es_status rc;
    if (!s) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    if (s->mode == ES_STORE_READ) ES_FAIL(ctx, ES_EINVAL, "store: '%s' is open read-only", s->path);
    if (s->work || es__beside_pending(s))
        ES_FAIL(ctx, ES_EINVAL, "store: commit the writes to '%s' before upgrading it", s->path);
    ES__H5_QUIET(rc = upgrade_impl(ctx, s));
    return rc;
}

int es_store_format_version(const es_store *s)
{
    return s ? s->version : 0;
}
