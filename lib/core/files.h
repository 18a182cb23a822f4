/* lib/core/files.h — files and paths, written once for the library: whole
 * files into memory, directories made as needed, the parts of a path.
 * Library-private. Every message names the path and the system's reason. */
#ifndef EDGESPACE_CORE_FILES_H
#define EDGESPACE_CORE_FILES_H

#include "core/core_private.h"

enum {
    ES__READ_REGULAR = 1,   /* refuse anything but a regular file (a FIFO would block) */
    ES__READ_DROP_BOM = 2,  /* drop a leading UTF-8 byte order mark */
    ES__READ_TEXT = 4,      /* refuse a NUL byte, naming its line (a binary file) */
    ES__READ_NOTFOUND = 8   /* a missing file is ES_ENOTFOUND (else ES_EIO) */
};

/* Read the whole file at path into *buf, NUL-terminated; *len excludes
 * the NUL. *buf may hold a buffer of *cap bytes from an earlier call, which
 * is reused or grown (give *buf = NULL, *cap = 0 the first time); free it
 * with es__free. Failures: ES_EIO (cannot open or read, a directory, not a regular file with ES__READ_REGULAR),
 * ES_EFORMAT (NUL with ES__READ_TEXT), ES_ENOTFOUND (no such file, with
 * ES__READ_NOTFOUND), ES_ENOMEM, ES_ERANGE. */
es_status es__read_file_reuse(es_ctx *ctx, const char *path, unsigned flags, char **buf,
                              size_t *cap, size_t *len);
/* The same into a fresh buffer. */
es_status es__read_file(es_ctx *ctx, const char *path, unsigned flags, char **buf,
                        size_t *len);

/* mkdir -p: make dir and every missing parent; ES_EIO if a component
 * cannot be made or dir exists and is not a directory. */
es_status es__mkdir_p(es_ctx *ctx, const char *dir);

/* The last component of path (after the last '/'; path itself if none).
 * Borrowed from path. */
const char *es__path_base(const char *path);
/* The directory part of path ("." for a bare name, "/" for "/x"), allocated
 * through ctx (NULL and ES_ENOMEM recorded on failure). */
char *es__path_dir(es_ctx *ctx, const char *path);
/* The base name without its last extension ("a/b.obj" -> "b"; ".x" keeps
 * its dot), truncated to n - 1 bytes. */
void es__path_stem(const char *path, char *buf, size_t n);

/* 1 if path names a regular file or nothing (may be written over), 0 if
 * it names a device, FIFO, socket or directory: outputs refuse those. */
int es__path_writable_kind(const char *path);

#endif
