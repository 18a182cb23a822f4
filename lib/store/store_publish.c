/* lib/store/store_publish.c — crash-safe writing: the working copy, its
 * publishing by atomic rename, and the checks that keep two writers from
 * losing each other's work.
 *
 * The store file itself is never written in place. A handle opened for
 * writing reads the original until its first write; then it copies the
 * file to a temporary sibling ".<name>.tmp-<pid>-<n>" and every write goes
 * to the copy. es_store_commit (also done by es_store_close) flushes and
 * closes the copy, fsyncs it, and rename()s it over the original, then
 * fsyncs the directory: a reader sees the old store or the new one, never
 * a mix, and a process killed at any moment leaves the original
 * byte-for-byte as it was plus, at worst, a stale temporary that the next
 * writer removes (its pid is dead). A new store is made the same way and
 * published with link(), which refuses to clobber a file that appeared
 * meanwhile. If the original changed under us (another writer committed
 * first), commit refuses rather than silently losing its work; the check
 * and the rename hold an advisory lock on the folder. This is the "write a
 * new file, then rename" scheme of editors and package managers (SQLite
 * keeps every fsync and rename in os_unix.c for the same reason); HDF5 1.10
 * has no transactional writes of its own. Results of a format-3 store are
 * not written here at all but beside it, a file each (store_beside.c):
 * storing one never copies the store.
 */
#include "store/store_pkg.h"
#include "store/store_private.h"
#include "core/files.h"

#include <limits.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Working copies are ".<base>.tmp-<pid>-<unique>" (the base shortened when
 * long: core/file_replace.c): the next writer removes those whose process
 * is gone. */
void es__store_clean_stale(const char *path) { es__temp_clean_stale(path, ES__TEMP_WORKING_COPY); }

/* The file the store's writes replace: the path given, or through a
 * symbolic link its target (a commit renames over the target and keeps the
 * link; it used to replace the link by a file and leave the target as it
 * was). */
const char *es__store_target(const es_store *s) { return s->target ? s->target : s->path; }
static const char *target_of(const es_store *s) { return es__store_target(s); }

/* A temporary sibling of path (the one naming scheme, core/): the working
 * copy of a store, a result file being written beside it. */
char *es__store_temp_for(es_store *s, const char *path)
{
    char unique[64];
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    /* what keeps two handles of one process apart */
    snprintf(unique, sizeof unique, "%lx%lx%u", (unsigned long)(uintptr_t)s,
             (unsigned long)ts.tv_nsec, s->tmp_counter++);
    return es__temp_sibling(s->ctx, path, ES__TEMP_WORKING_COPY, unique);
}

char *es__store_temp_name(es_store *s) { return es__store_temp_for(s, target_of(s)); }

static es_status copy_file(es_ctx *ctx, const char *src, const char *dst, struct stat *st)
{
    int in = -1, out = -1;
    es_status rc = ES_OK;
    char *buf = NULL;
    if ((in = open(src, O_RDONLY | O_CLOEXEC)) < 0 || fstat(in, st) < 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot read '%s': %s", src, strerror(errno));
        goto done;
    }
    if ((out = open(dst, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, st->st_mode & 07777)) < 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot create working copy '%s': %s", dst,
                      strerror(errno));
        goto done;
    }
    if (!(buf = es__malloc(ctx, 1 << 20))) { rc = ES_ENOMEM; goto done; }
    for (;;) {
        ssize_t r = read(in, buf, 1 << 20), w = 0;
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            rc = es__fail(ctx, ES_EIO, "store: cannot read '%s': %s", src, strerror(errno));
            goto done;
        }
        if (r == 0) break;
        while (w < r) {
            ssize_t k = write(out, buf + w, (size_t)(r - w));
            if (k < 0 && errno == EINTR) continue;
            if (k < 0) {
                rc = es__fail(ctx, ES_EIO, "store: cannot write '%s': %s", dst,
                              strerror(errno));
                goto done;
            }
            w += k;
        }
    }
done:
    es__free(ctx, buf);
    if (in >= 0) close(in);
    if (out >= 0 && close(out) < 0 && rc == ES_OK)
        rc = es__fail(ctx, ES_EIO, "store: cannot write '%s': %s", dst, strerror(errno));
    if (rc != ES_OK && out >= 0) unlink(dst);
    return rc;
}

static es_status fsync_path(es_ctx *ctx, const char *path, bool dir)
{
    int fd = open(path, (dir ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
    if (fd < 0 || (fsync(fd) < 0 && !dir)) {
        int e = errno;
        if (fd >= 0) close(fd);
        ES_FAIL(ctx, ES_EIO, "store: cannot sync '%s': %s", path, strerror(e));
    }
    close(fd);
    return ES_OK;
}

es_status es__store_fsync(es_ctx *ctx, const char *path, bool dir)
{
    return fsync_path(ctx, path, dir);
}

/* Another writer's commit replaces the file (a new inode) and an in-place
 * writer (h5py, h5repack) changes its size or mtime: either way the rows
 * this handle holds are no longer the file's. */
static bool same_identity(const struct stat *a, const struct stat *b)
{
    return a->st_ino == b->st_ino && a->st_dev == b->st_dev && a->st_size == b->st_size &&
           a->st_mtim.tv_sec == b->st_mtim.tv_sec && a->st_mtim.tv_nsec == b->st_mtim.tv_nsec;
}

/* First write on a handle opened for writing: switch to a working copy. */
es_status es__store_begin_write(es_store *s)
{
    es_ctx *ctx = s->ctx;
    es_status rc;
    if (s->mode == ES_STORE_READ)
        ES_FAIL(ctx, ES_EINVAL, "store: '%s' is open read-only", s->path);
    if (s->broken)
        ES_FAIL(ctx, ES_EIO, "store: an earlier write to '%s' failed; reopen the store",
                s->path);
    /* cancelled work stores nothing (es_ctx_cancel) */
    if ((rc = es__cancelled(ctx, "a write"))) return rc;
    /* whatever is about to be written: values read before are stale */
    s->generation++;
    if (s->work) return ES_OK;
    es__store_clean_stale(target_of(s));
    if (!(s->work = es__store_temp_name(s))) return ES_ENOMEM;
    if ((rc = copy_file(ctx, target_of(s), s->work, &s->orig))) goto fail;
    if (!same_identity(&s->orig, &s->opened)) {
        /* Rows, ids and columns in memory are those of the file we opened;
         * writing them onto another writer's newer store would corrupt it. */
        unlink(s->work);
        rc = es__fail(ctx, ES_EIO, "store: '%s' was changed by another writer since it was "
                      "opened; nothing written", s->path);
        goto fail;
    }
    es__h5_close(s->file);
    /* (es__fail: the store has never named HDF5's reason here) */
    if ((s->file = es__h5_file_open(s->work, true)) < 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot open working copy '%s'", s->work);
        unlink(s->work);
        s->file = es__h5_file_open_default(s->path);
        if (s->file < 0) s->broken = true;
        goto fail;
    }
    return ES_OK;
fail:
    es__free(ctx, s->work);
    s->work = NULL;
    return rc;
}

es_status es__store_publish(es_ctx *ctx, es_store *s)
{
    es_status rc = ES_OK;
    struct stat now, done;
    char *dir = NULL;
    if (!s->work) return es__beside_publish(ctx, s); /* the store itself unchanged */
    if (s->broken)
        ES_FAIL(ctx, ES_EIO, "store: an earlier write to '%s' failed; nothing committed",
                s->path);
    if ((rc = es__cancelled(ctx, "a commit")) || (rc = es__cancelled(s->ctx, "a commit")))
        return rc;
    /* flushed, then closed; a failed flush (a full disk) discards it safely */
    rc = es__h5_file_close(ctx, s->file, true, s->path);
    s->file = -1;
    if (rc != ES_OK) {
        rc = es__fail(ctx, rc, "store: %s", es_ctx_errmsg(ctx));
        goto fail;
    }
    if ((rc = fsync_path(ctx, s->work, false))) goto fail;
    /* the identity the published file will have (link and rename keep the
     * inode): taken now, a commit landing right after ours is not mistaken
     * for the file this handle's rows come from */
    if (stat(s->work, &done) != 0) memset(&done, 0, sizeof done);
    if (s->is_new) {
        /* link() refuses to replace a file that appeared meanwhile. */
        if (link(s->work, s->path) != 0) {
            if (errno == EEXIST) {
                rc = es__fail(ctx, ES_EEXIST, "store: '%s' was created by someone else "
                              "meanwhile; nothing written", s->path);
                goto fail;
            }
            if (access(s->path, F_OK) == 0 || rename(s->work, s->path) != 0) {
                rc = es__fail(ctx, ES_EIO, "store: cannot create '%s': %s", s->path,
                              strerror(errno));
                goto fail;
            }
        } else {
            unlink(s->work);
        }
    } else {
        /* The identity check and the rename are one step for every writer of
         * this folder (an advisory lock on the folder): otherwise another
         * commit landing between them would be replaced unseen. */
        int dfd = -1;
        if ((dir = es__path_dir(ctx, target_of(s))) &&
            (dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC)) >= 0)
            while (flock(dfd, LOCK_EX) != 0 && errno == EINTR) {
            }
        /* a folder that cannot be opened or locked (unreadable, some network
         * file systems) leaves the commit unlocked: the identity check alone */
        if (stat(target_of(s), &now) != 0 || !same_identity(&now, &s->orig)) {
            rc = es__fail(ctx, ES_EIO, "store: '%s' was changed by another writer since it "
                          "was opened; nothing written", s->path);
        } else if (rename(s->work, target_of(s)) != 0) {
            rc = es__fail(ctx, ES_EIO, "store: cannot replace '%s': %s", s->path,
                          strerror(errno));
        }
        if (dfd >= 0) close(dfd);   /* releases the lock */
        es__free(ctx, dir);
        dir = NULL;
        if (rc != ES_OK) goto fail;
    }
    s->opened = done;
    if ((dir = es__path_dir(ctx, target_of(s)))) {
        fsync_path(ctx, dir, true);
        es__free(ctx, dir);
    }
    es__free(ctx, s->work);
    s->work = NULL;
    s->is_new = false;
    if ((s->file = es__h5_file_open(s->path, false)) < 0)
        return es__fail(ctx, ES_EIO, "store: committed '%s' but cannot reopen it", s->path);
    /* results beside it after the store: one of them may name its new rows */
    return es__beside_publish(ctx, s);
fail:
    s->broken = true;
    return rc;
}

es_status es__store_publish_with(es_ctx *ctx, es_store *s, es__file_set *set)
{
    if (!s) {
        es__file_set_abort(ctx, set);
        ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    }
    es_status rc = es__file_set_move(s->ctx, &s->files, ctx, set);
    if (rc != ES_OK) {
        if (ctx != s->ctx) es__fail(ctx, rc, "%s", es_ctx_errmsg(s->ctx));
        es__file_set_abort(ctx, set);
    }
    return rc;
}

es_status es__store_files_done(es_ctx *ctx, es_store *s, es_status rc)
{
    if (s->files.n == 0) return rc;
    if (rc != ES_OK) {
        es__file_set_abort(s->ctx, &s->files);
        return rc;
    }
    /* renames in the files' own folders: they fail only when a folder
     * changed under us; the store is published by then, and says so */
    if ((rc = es__file_set_commit(s->ctx, &s->files)) != ES_OK) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(s->ctx));
        rc = es__fail(ctx, rc, "store: committed '%s', but %s", s->path, msg);
    }
    return rc;
}

es_status es_store_commit(es_ctx *ctx, es_store *store)
{
    es_status rc;
    if (!store) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    ES__H5_QUIET(rc = es__store_publish(ctx, store));
    return es__store_files_done(ctx, store, rc);
}
