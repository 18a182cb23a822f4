/* lib/core/file_replace.c — write a file so that it replaces the old one only
 * when the new content is complete: a failed or killed write leaves a file
 * that was there before as it was (core/core_private.h). Also the one naming
 * scheme of temporary siblings (part files here, the store's working copies)
 * with its two rules: a name too long for the folder is shortened with a
 * hash, and what a dead process left is removed by the next writer. */
#include "core/core_private.h"
#include "core/files.h"
#include "core/hash.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef NAME_MAX
#define NAME_MAX 255
#endif

static void short_base(const char *base, size_t extra, char *out, size_t n)
{
    size_t len = strlen(base), keep;
    if (len + extra <= NAME_MAX) {
        snprintf(out, n, "%s", base);
        return;
    }
    /* 120 bytes, cut before a UTF-8 continuation byte, then ~hash */
    keep = len < 120 ? len : 120;
    while (keep > 0 && ((unsigned char)base[keep] & 0xc0) == 0x80) keep--;
    snprintf(out, n, "%.*s~%016llx", (int)keep, base,
             (unsigned long long)es__fnv1a64_str(base));
}

/* kill(pid, 0) failing with ESRCH is the only proof that the writer is
 * gone: EPERM means alive under another user, so its file is kept. */
static void remove_stale(const char *path, const char *prefix, const char *suffix)
{
    char dirbuf[4096];
    const char *base = es__path_base(path);
    size_t dn = (size_t)(base - path), pn = strlen(prefix), sn = strlen(suffix);
    DIR *d;
    struct dirent *e;
    if (dn >= sizeof dirbuf) return;
    if (dn == 0) snprintf(dirbuf, sizeof dirbuf, ".");
    else {
        memcpy(dirbuf, path, dn);
        dirbuf[dn] = '\0';
    }
    if (!(d = opendir(dirbuf))) return;
    while ((e = readdir(d))) {
        size_t en = strlen(e->d_name);
        char *end, full[4608];
        long pid;
        if (en < pn + sn || strncmp(e->d_name, prefix, pn) ||
            strcmp(e->d_name + en - sn, suffix))
            continue;
        pid = strtol(e->d_name + pn, &end, 10);
        if (end == e->d_name + pn || (*end != '-' && *end != '.') || pid <= 0) continue;
        if (pid == (long)getpid() || kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
        snprintf(full, sizeof full, "%s/%s", dirbuf, e->d_name);
        unlink(full);
    }
    closedir(d);
}

/* The one naming scheme of temporary siblings. A part file (one writer's
 * file, renamed over its target): "<base>.<pid><unique>.part", the base
 * shortened for 24 bytes of suffix; a working copy (a store's, or a result
 * file's beside it, published by the store's commit): ".<base>.tmp-<pid>-
 * <unique>", hidden, the base shortened for 56 bytes. The pid first in
 * both, so that the next writer removes what a dead process left. */
static void temp_affixes(const char *path, es__temp_kind kind, char *lead, size_t n,
                         const char **tail)
{
    char sb[NAME_MAX + 1];
    short_base(es__path_base(path), kind == ES__TEMP_PART ? 24 : 56, sb, sizeof sb);
    snprintf(lead, n, kind == ES__TEMP_PART ? "%s." : ".%s.tmp-", sb);
    *tail = kind == ES__TEMP_PART ? ".part" : "";
}

char *es__temp_sibling(es_ctx *ctx, const char *path, es__temp_kind kind, const char *unique)
{
    char lead[NAME_MAX + 16];
    const char *tail;
    size_t dn = (size_t)(es__path_base(path) - path), n;
    char *t;
    temp_affixes(path, kind, lead, sizeof lead, &tail);
    n = dn + strlen(lead) + strlen(unique) + 48;
    if ((t = es__malloc(ctx, n)))
        snprintf(t, n, "%.*s%s%ld%s%s%s", (int)dn, path, lead, (long)getpid(),
                 kind == ES__TEMP_PART ? "" : "-", unique, tail);
    return t;
}

void es__temp_clean_stale(const char *path, es__temp_kind kind)
{
    char lead[NAME_MAX + 16];
    const char *tail;
    temp_affixes(path, kind, lead, sizeof lead, &tail);
    remove_stale(path, lead, tail);
}

/* The part file is made beside the file that path names (through a
 * symlink: beside its target, which is what gets replaced), with the mode
 * of a file already there: "<base>.<pid>[.<n>].part", the base shortened
 * when it is long. A pipe or character device is written in place (export
 * to /dev/full as root used to replace the device node by a CSV file); a
 * directory or block device is refused. Names are tried with a counter: a
 * part file left by a killed process of the same pid must not block every
 * later write; those of dead processes are removed. */
es_status es__replace_begin(es_ctx *ctx, const char *path, es__file_replace *w)
{
    struct stat st;
    int have = 0;
    const char *t;
    memset(w, 0, sizeof *w);
    w->path = path;
    if (lstat(path, &st) == 0 && S_ISLNK(st.st_mode)) w->target = realpath(path, NULL);
    t = w->target ? w->target : path;
    if (stat(t, &st) == 0) have = 1;
    if (have && (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode))) {
        /* a stream, not a file: renaming a part file over it would put a
         * regular file where a device node or pipe was */
        free(w->target);
        w->target = NULL;
        if (!(w->f = fopen(path, "wb")))
            ES_FAIL(ctx, ES_EIO, "cannot write '%s': %s", path, strerror(errno));
        return ES_OK;
    }
    if (have && !S_ISREG(st.st_mode)) {
        free(w->target);
        w->target = NULL;
        ES_FAIL(ctx, ES_EIO, "cannot write '%s': %s", path,
                S_ISDIR(st.st_mode) ? strerror(EISDIR) : "not a regular file, pipe or "
                "character device");
    }
    es__temp_clean_stale(t, ES__TEMP_PART);
    for (unsigned n = 0;; n++) {
        char unique[16] = "";
        if (n) snprintf(unique, sizeof unique, ".%u", n);
        es__free(ctx, w->tmp);
        if (!(w->tmp = es__temp_sibling(ctx, t, ES__TEMP_PART, unique))) {
            free(w->target);
            memset(w, 0, sizeof *w);
            return ES_ENOMEM;
        }
        if ((w->f = fopen(w->tmp, "wbx"))) break;
        if (errno != EEXIST || n == 99) {
            es_status rc = es__fail(ctx, ES_EIO, "cannot create '%s': %s", w->tmp,
                                    strerror(errno));
            es__free(ctx, w->tmp);
            free(w->target);
            memset(w, 0, sizeof *w);
            return rc;
        }
    }
    if (have && S_ISREG(st.st_mode)) fchmod(fileno(w->f), st.st_mode & 07777);
    return ES_OK;
}

/* Close the part file; rc and the close's errors decide. */
static es_status close_part(es_ctx *ctx, es__file_replace *w, es_status rc)
{
    if (rc == ES_OK && ferror(w->f))
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", w->path, strerror(errno));
    if (fclose(w->f) != 0 && rc == ES_OK)
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", w->path, strerror(errno));
    w->f = NULL;
    return rc;
}

static void replace_clear(es_ctx *ctx, es__file_replace *w)
{
    es__free(ctx, w->tmp);
    free(w->target);
    memset(w, 0, sizeof *w);
}

es_status es__replace_end(es_ctx *ctx, es__file_replace *w, es_status rc)
{
    if (!w->f) return rc;
    rc = close_part(ctx, w, rc);
    if (rc == ES_OK && w->tmp && rename(w->tmp, w->target ? w->target : w->path) != 0)
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", w->path, strerror(errno));
    if (rc != ES_OK && w->tmp) remove(w->tmp);
    replace_clear(ctx, w);
    return rc;
}

/* ---- a set of files that appear together -------------------------------------- */

es_status es__replace_end_staged(es_ctx *ctx, es__file_replace *w, es_status rc,
                                 es__file_set *set)
{
    es__file_replace *nw;
    if (!w->f) return rc;
    if (!w->tmp || rc != ES_OK) return es__replace_end(ctx, w, rc);   /* a stream, or failed */
    if ((rc = close_part(ctx, w, rc)) != ES_OK) {
        remove(w->tmp);
        replace_clear(ctx, w);
        return rc;
    }
    if (set->n == set->cap) {
        int64_t cap = set->cap ? 2 * set->cap : 8;
        if (!(nw = es__realloc(ctx, set->w, (size_t)cap * sizeof *nw))) {
            remove(w->tmp);
            replace_clear(ctx, w);
            return ES_ENOMEM;
        }
        set->w = nw;
        set->cap = cap;
    }
    /* its own copy of the path: the caller's buffer is reused */
    if (!(set->w[set->n].path = es__strdup(ctx, w->path))) {
        remove(w->tmp);
        replace_clear(ctx, w);
        return ES_ENOMEM;
    }
    set->w[set->n].tmp = w->tmp;
    set->w[set->n].target = w->target;
    set->w[set->n].f = NULL;
    set->n++;
    memset(w, 0, sizeof *w);
    return ES_OK;
}

es_status es__file_set_commit(es_ctx *ctx, es__file_set *set)
{
    es_status rc = ES_OK;
    int64_t k;
    /* renames in one folder do not need space; they fail only when the
     * folder changed under us, and then the rest stay parts (removed) */
    for (k = 0; k < set->n; k++) {
        es__file_replace *w = &set->w[k];
        if (rename(w->tmp, w->target ? w->target : w->path) != 0) {
            rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s (%lld of %lld files written)",
                          w->path, strerror(errno), (long long)k, (long long)set->n);
            break;
        }
    }
    for (; k < set->n; k++) remove(set->w[k].tmp);
    es__file_set_clear(ctx, set);
    return rc;
}

void es__file_set_abort(es_ctx *ctx, es__file_set *set)
{
    for (int64_t k = 0; k < set->n; k++) remove(set->w[k].tmp);
    es__file_set_clear(ctx, set);
}

es_status es__file_set_move(es_ctx *ctx, es__file_set *into, es_ctx *from_ctx,
                            es__file_set *from)
{
    const int64_t n0 = into->n;
    if (from->n == 0) return ES_OK;
    if (n0 + from->n > into->cap) {
        es__file_replace *nw = es__realloc(ctx, into->w, (size_t)(n0 + from->n) * sizeof *nw);
        if (!nw) return ES_ENOMEM;
        into->w = nw;
        into->cap = n0 + from->n;
    }
    /* the names copied into ctx's memory first: a failure undoes only them */
    for (int64_t k = 0; k < from->n; k++) {
        es__file_replace *d = &into->w[n0 + k];
        *d = from->w[k];
        d->tmp = es__strdup(ctx, from->w[k].tmp);
        d->path = d->tmp ? es__strdup(ctx, from->w[k].path) : NULL;
        if (!d->tmp || !d->path) {
            for (int64_t j = 0; j <= k; j++) {
                es__free(ctx, into->w[n0 + j].tmp);
                es__free(ctx, (char *)into->w[n0 + j].path);
            }
            return ES_ENOMEM;
        }
    }
    into->n = n0 + from->n;
    /* the targets (malloc'd by realpath) move as they are */
    for (int64_t k = 0; k < from->n; k++) from->w[k].target = NULL;
    es__file_set_clear(from_ctx, from);
    return ES_OK;
}

void es__file_set_clear(es_ctx *ctx, es__file_set *set)
{
    for (int64_t k = 0; k < set->n; k++) {
        es__free(ctx, set->w[k].tmp);
        es__free(ctx, (char *)set->w[k].path);
        free(set->w[k].target);
    }
    es__free(ctx, set->w);
    memset(set, 0, sizeof *set);
}
