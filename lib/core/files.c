/* lib/core/files.c — see files.h. */
#include "core/files.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

/* Grow b to at least `need` bytes (doubling); ES_ERANGE past SIZE_MAX/2. */
static es_status reserve(es_ctx *ctx, const char *path, char **b, size_t *cap, size_t need)
{
    size_t c = *cap ? *cap : 65536;
    char *nb;
    if (need <= *cap && *b) return ES_OK;
    while (c < need) {
        if (c > SIZE_MAX / 2) ES_FAIL(ctx, ES_ERANGE, "'%s' is too large", path);
        c *= 2;
    }
    if (!(nb = es__realloc(ctx, *b, c))) return ES_ENOMEM;
    *b = nb;
    *cap = c;
    return ES_OK;
}

static es_status check_text(es_ctx *ctx, const char *path, const char *b, size_t n)
{
    const char *z = memchr(b, '\0', n);
    if (!z) return ES_OK;
    int64_t line = 1;
    for (const char *p = b; p < z; p++) line += *p == '\n';
    ES_FAIL(ctx, ES_EFORMAT, "'%s' line %lld: NUL byte (not a text file?)", path,
            (long long)line);
}

es_status es__read_file_reuse(es_ctx *ctx, const char *path, unsigned flags, char **buf,
                              size_t *cap, size_t *len)
{
    struct stat st;
    size_t n = 0;
    es_status rc;
    int fd;
    *len = 0;
    if ((fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK)) < 0)
        ES_FAIL(ctx, errno == ENOENT && (flags & ES__READ_NOTFOUND) ? ES_ENOTFOUND : ES_EIO,
                "cannot open '%s': %s", path,
                strerror(errno));
    if (fstat(fd, &st) != 0 || S_ISDIR(st.st_mode) ||
        ((flags & ES__READ_REGULAR) && !S_ISREG(st.st_mode))) {
        int e = errno;
        close(fd);
        if (S_ISDIR(st.st_mode)) ES_FAIL(ctx, ES_EIO, "cannot read '%s': %s", path,
                                         strerror(EISDIR));
        if (!S_ISREG(st.st_mode)) ES_FAIL(ctx, ES_EIO, "'%s' is not a regular file", path);
        ES_FAIL(ctx, ES_EIO, "cannot read '%s': %s", path, strerror(e));
    }
    /* O_NONBLOCK only kept open() from waiting for a FIFO's writer */
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    /* regular files: one buffer of the right size; pipes and the like grow */
    if (S_ISREG(st.st_mode) && st.st_size > 0 && (uintmax_t)st.st_size < SIZE_MAX - 1)
        rc = reserve(ctx, path, buf, cap, (size_t)st.st_size + 2);
    else
        rc = reserve(ctx, path, buf, cap, 65536);
    for (; rc == ES_OK;) {
        if (n + 1 >= *cap && (rc = reserve(ctx, path, buf, cap, 2 * *cap)) != ES_OK) break;
        ssize_t got = read(fd, *buf + n, *cap - 1 - n);
        if (got == 0) break;
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            rc = es__fail(ctx, ES_EIO, "cannot read '%s': %s", path, strerror(errno));
            break;
        }
        n += (size_t)got;
    }
    close(fd);
    if (rc != ES_OK) return rc;
    (*buf)[n] = '\0';
    if ((flags & ES__READ_DROP_BOM) && n >= 3 && !memcmp(*buf, "\xEF\xBB\xBF", 3)) {
        memmove(*buf, *buf + 3, n - 2);
        n -= 3;
    }
    if ((flags & ES__READ_TEXT) && (rc = check_text(ctx, path, *buf, n)) != ES_OK) return rc;
    *len = n;
    return ES_OK;
}

es_status es__read_file(es_ctx *ctx, const char *path, unsigned flags, char **buf,
                        size_t *len)
{
    size_t cap = 0;
    es_status rc;
    *buf = NULL;
    if ((rc = es__read_file_reuse(ctx, path, flags, buf, &cap, len)) != ES_OK) {
        es__free(ctx, *buf);
        *buf = NULL;
    }
    return rc;
}

es_status es__mkdir_p(es_ctx *ctx, const char *dir)
{
    struct stat st;
    size_t n;
    char *path;
    if (!dir || !*dir) ES_FAIL(ctx, ES_EINVAL, "no directory name");
    if (stat(dir, &st) == 0) {
        if (S_ISDIR(st.st_mode)) return ES_OK;
        ES_FAIL(ctx, ES_EIO, "'%s' is not a directory", dir);
    }
    n = strlen(dir);
    if (!(path = es__strdup(ctx, dir))) return ES_ENOMEM;
    for (size_t i = 1; i <= n; i++) {
        if (path[i] != '/' && path[i] != '\0') continue;
        char keep = path[i];
        path[i] = '\0';
        if (mkdir(path, 0777) != 0 && errno != EEXIST) {
            es__fail(ctx, ES_EIO, "cannot create directory '%s': %s", path, strerror(errno));
            es__free(ctx, path);
            return ES_EIO;
        }
        path[i] = keep;
    }
    es__free(ctx, path);
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        ES_FAIL(ctx, ES_EIO, "'%s' is not a directory", dir);
    return ES_OK;
}

es_status es_make_dirs(es_ctx *ctx, const char *dir)
{
    return es__mkdir_p(ctx, dir);
}

const char *es__path_base(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

char *es__path_dir(es_ctx *ctx, const char *path)
{
    const char *slash = strrchr(path, '/');
    char *dir;
    if (!slash) return es__strdup(ctx, ".");
    if (slash == path) return es__strdup(ctx, "/");
    if ((dir = es__malloc(ctx, (size_t)(slash - path) + 1))) {
        memcpy(dir, path, (size_t)(slash - path));
        dir[slash - path] = '\0';
    }
    return dir;
}

void es__path_stem(const char *path, char *buf, size_t n)
{
    const char *base = es__path_base(path), *dot = strrchr(base, '.');
    size_t len = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (!n) return;
    if (len >= n) len = n - 1;
    memcpy(buf, base, len);
    buf[len] = '\0';
}

int es__path_writable_kind(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return 1;
    return S_ISREG(st.st_mode) ? 1 : 0;
}
