/* lib/core/file_replace.c — write a file so that it replaces the old one only
 * when the new content is complete: a failed or killed write leaves a file
 * that was there before as it was (core/core_private.h). */
#include "core/core_private.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The part file is made beside the file that path names (through a
 * symlink: beside its target, which is what gets replaced), with the mode
 * of a file already there. A pipe or character device is written in place
 * (export to /dev/full as root used to replace the device node by a CSV
 * file); a directory or block device is refused. Names are tried with a counter: a part file left
 * by a killed process of the same pid must not block every later write. */
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
    if (!(w->tmp = es__malloc(ctx, strlen(t) + 48))) {
        free(w->target);
        w->target = NULL;
        return ES_ENOMEM;
    }
    for (unsigned n = 0;; n++) {
        sprintf(w->tmp, n ? "%s.%ld.%u.part" : "%s.%ld.part", t, (long)getpid(), n);
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

es_status es__replace_end(es_ctx *ctx, es__file_replace *w, es_status rc)
{
    if (!w->f) return rc;
    if (rc == ES_OK && ferror(w->f))
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", w->path, strerror(errno));
    if (fclose(w->f) != 0 && rc == ES_OK)
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", w->path, strerror(errno));
    if (rc == ES_OK && w->tmp && rename(w->tmp, w->target ? w->target : w->path) != 0)
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", w->path, strerror(errno));
    if (rc != ES_OK && w->tmp) remove(w->tmp);
    es__free(ctx, w->tmp);
    free(w->target);
    memset(w, 0, sizeof *w);
    return rc;
}
