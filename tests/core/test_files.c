/* tests/core/test_files.c — core/files.h: whole-file reads and their flags
 * (a FIFO refused at once with ES__READ_REGULAR, read to its end without;
 * the byte order mark; a NUL byte named by its line; a missing file as
 * ES_EIO or ES_ENOTFOUND), buffer reuse, mkdir -p, the parts of a path, and
 * replacing a file (es__replace_begin/end) where the path is a pipe, a
 * device or a directory. */
#include "core/files.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

static char dir[4096];

static const char *in_dir(const char *name, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", dir, name);
    return buf;
}

static void test_flags(es_ctx *ctx)
{
    char path[4200], *buf = NULL;
    size_t len = 7;
    in_dir("bom.txt", path, sizeof path);
    es_test_write_file(path, "\xef\xbb\xbfhi\n");
    ES_CHECK_OK(ctx, es__read_file(ctx, path, ES__READ_DROP_BOM, &buf, &len));
    ES_CHECK(buf && len == 3 && !strcmp(buf, "hi\n"));
    es__free(ctx, buf);
    ES_CHECK_OK(ctx, es__read_file(ctx, path, 0, &buf, &len));
    ES_CHECK(buf && len == 6 && !memcmp(buf, "\xef\xbb\xbfhi\n", 7));
    es__free(ctx, buf);
    /* a file that is only a BOM is empty */
    es_test_write_file(path, "\xef\xbb\xbf");
    ES_CHECK_OK(ctx, es__read_file(ctx, path, ES__READ_DROP_BOM, &buf, &len));
    ES_CHECK(buf && len == 0 && buf[0] == '\0');
    es__free(ctx, buf);

    /* a NUL byte: refused with its line under ES__READ_TEXT, data otherwise */
    in_dir("nul.txt", path, sizeof path);
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite("a\nb\r\nc\0d\n", 1, 9, f);
        fclose(f);
    }
    buf = (char *)1;
    ES_CHECK_FAILS(ctx, es__read_file(ctx, path, ES__READ_TEXT, &buf, &len), ES_EFORMAT,
                   "nul.txt' line 3: NUL byte");
    ES_CHECK(buf == NULL && len == 0);
    ES_CHECK_OK(ctx, es__read_file(ctx, path, 0, &buf, &len));
    ES_CHECK(buf && len == 9 && buf[6] == '\0' && buf[7] == 'd');
    es__free(ctx, buf);

    /* missing: ES_EIO, or ES_ENOTFOUND when the caller tells them apart */
    in_dir("missing.txt", path, sizeof path);
    ES_CHECK_FAILS(ctx, es__read_file(ctx, path, 0, &buf, &len), ES_EIO, "cannot open '");
    ES_CHECK(strstr(es_ctx_errmsg(ctx), "missing.txt': No such file"));
    ES_CHECK_FAILS(ctx, es__read_file(ctx, path, ES__READ_NOTFOUND, &buf, &len), ES_ENOTFOUND,
                   "missing.txt");
    /* a directory is never read */
    ES_CHECK_FAILS(ctx, es__read_file(ctx, dir, 0, &buf, &len), ES_EIO, "Is a directory");
    ES_CHECK_FAILS(ctx, es__read_file(ctx, dir, ES__READ_NOTFOUND, &buf, &len), ES_EIO, NULL);
}

/* A FIFO is refused at once with ES__READ_REGULAR (open never waits for a
 * writer) and is empty without a writer; a pipe is read to its end through
 * several buffers' worth of data. */
static void test_fifo(es_ctx *ctx)
{
    char path[4200], *buf = NULL;
    size_t len;
    int fds[2];
    alarm(20);   /* a read that blocks fails the test instead of hanging it */
    in_dir("fifo", path, sizeof path);
    if (mkfifo(path, 0600) == 0) {
        ES_CHECK_FAILS(ctx, es__read_file(ctx, path, ES__READ_REGULAR, &buf, &len), ES_EIO,
                       "fifo' is not a regular file");
        ES_CHECK(buf == NULL);
        ES_CHECK(es__path_writable_kind(path) == 0);
        ES_CHECK_OK(ctx, es__read_file(ctx, path, 0, &buf, &len));
        ES_CHECK(buf && len == 0);
        es__free(ctx, buf);
        remove(path);
    } else {
        ES_CHECK_MSG(0, "mkfifo: %s", strerror(errno));
    }
    /* a pipe with a writer, opened anew through /dev/fd (Linux) */
    if (pipe(fds) != 0) {
        ES_CHECK(0);
        return;
    }
    pid_t pid = fork();
    if (pid == 0) {
        FILE *w = fdopen(fds[1], "w");
        close(fds[0]);
        if (!w) _exit(1);
        for (int i = 0; i < 30000; i++) fprintf(w, "line %05d\n", i);
        _exit(fclose(w) == 0 ? 0 : 1);
    }
    close(fds[1]);
    if (pid > 0) {
        int status = 0;
        snprintf(path, sizeof path, "/dev/fd/%d", fds[0]);
        ES_CHECK_FAILS(ctx, es__read_file(ctx, path, ES__READ_REGULAR, &buf, &len), ES_EIO,
                       "is not a regular file");
        ES_CHECK_OK(ctx, es__read_file(ctx, path, ES__READ_TEXT, &buf, &len));
        waitpid(pid, &status, 0);
        ES_CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
        ES_CHECK_MSG(len == 30000 * 11, "read %zu bytes from the pipe", len);
        if (buf && len == 30000 * 11)
            ES_CHECK(!memcmp(buf, "line 00000\n", 11) && !strcmp(buf + len - 11, "line 29999\n"));
        es__free(ctx, buf);
    }
    close(fds[0]);
    alarm(0);
}

/* One buffer serves many files: grown when needed, kept otherwise. */
static void test_reuse(es_ctx *ctx)
{
    char small[4200], big[4200], *buf = NULL, *text = malloc(200001);
    size_t cap = 0, len = 0;
    if (!text) { ES_CHECK(0); return; }
    for (int i = 0; i < 200000; i++) text[i] = (char)('a' + i % 26);
    text[200000] = '\0';
    es_test_write_file(in_dir("small.txt", small, sizeof small), "tiny");
    es_test_write_file(in_dir("big.txt", big, sizeof big), text);
    ES_CHECK_OK(ctx, es__read_file_reuse(ctx, small, ES__READ_REGULAR, &buf, &cap, &len));
    ES_CHECK(buf && len == 4 && !strcmp(buf, "tiny") && cap >= 5);
    ES_CHECK_OK(ctx, es__read_file_reuse(ctx, big, ES__READ_REGULAR, &buf, &cap, &len));
    ES_CHECK(buf && len == 200000 && cap > 200000 && !strcmp(buf, text));
    char *kept = buf;
    size_t kept_cap = cap;
    ES_CHECK_OK(ctx, es__read_file_reuse(ctx, small, ES__READ_REGULAR, &buf, &cap, &len));
    ES_CHECK(buf == kept && cap == kept_cap && len == 4 && !strcmp(buf, "tiny"));
    /* a failure leaves the buffer to the caller, still freeable */
    ES_CHECK_FAILS(ctx, es__read_file_reuse(ctx, dir, 0, &buf, &cap, &len), ES_EIO, NULL);
    ES_CHECK(len == 0);
    es__free(ctx, buf);
    free(text);

    /* allocation failure: ES_ENOMEM, *buf NULL, nothing leaked */
    failing_alloc fa = {0, 1, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    es_ctx_set_allocator(ctx, &a);
    buf = (char *)1;
    ES_CHECK_FAILS(ctx, es__read_file(ctx, small, 0, &buf, &len), ES_ENOMEM, NULL);
    ES_CHECK(buf == NULL && fa.live == 0);
    es_ctx_set_allocator(ctx, NULL);
}

static void test_mkdir(es_ctx *ctx)
{
    char path[4200], file[4200];
    struct stat st;
    in_dir("a/b/c", path, sizeof path);
    ES_CHECK_OK(ctx, es__mkdir_p(ctx, path));
    ES_CHECK(stat(path, &st) == 0 && S_ISDIR(st.st_mode));
    ES_CHECK_OK(ctx, es__mkdir_p(ctx, path));            /* already there */
    in_dir("a/b/d/", path, sizeof path);                 /* a trailing slash */
    ES_CHECK_OK(ctx, es__mkdir_p(ctx, path));
    ES_CHECK(stat(path, &st) == 0 && S_ISDIR(st.st_mode));
    in_dir("a//e", path, sizeof path);                   /* a doubled slash */
    ES_CHECK_OK(ctx, es__mkdir_p(ctx, path));
    /* a file in the way, as the directory or as a parent */
    es_test_write_file(in_dir("a/f", file, sizeof file), "x");
    ES_CHECK_FAILS(ctx, es__mkdir_p(ctx, file), ES_EIO, "a/f' is not a directory");
    in_dir("a/f/g", path, sizeof path);
    ES_CHECK_FAILS(ctx, es__mkdir_p(ctx, path), ES_EIO, "cannot create directory '");
    ES_CHECK(strstr(es_ctx_errmsg(ctx), "a/f/g") || strstr(es_ctx_errmsg(ctx), "a/f'"));
    ES_CHECK_FAILS(ctx, es__mkdir_p(ctx, ""), ES_EINVAL, "no directory name");
    ES_CHECK_FAILS(ctx, es__mkdir_p(ctx, NULL), ES_EINVAL, NULL);
    ES_CHECK(es__path_writable_kind(file) == 1 && es__path_writable_kind(dir) == 0);
    in_dir("a/none", path, sizeof path);
    ES_CHECK(es__path_writable_kind(path) == 1);
    remove(file);
    static const char *const made[] = {"a/b/c", "a/b/d", "a/b", "a/e", "a"};
    for (size_t i = 0; i < sizeof made / sizeof *made; i++)
        ES_CHECK(rmdir(in_dir(made[i], path, sizeof path)) == 0);
}

static void test_paths(es_ctx *ctx)
{
    static const struct { const char *path, *base, *dir, *stem; } cases[] = {
        {"a/b/cat-01.obj", "cat-01.obj", "a/b", "cat-01"},
        {"x.tar.gz", "x.tar.gz", ".", "x.tar"},
        {".hidden", ".hidden", ".", ".hidden"},
        {"d/.hidden", ".hidden", "d", ".hidden"},
        {"/top.ply", "top.ply", "/", "top"},
        {"noext", "noext", ".", "noext"},
        {"dir.d/noext", "noext", "dir.d", "noext"},
        {"a/b/", "", "a/b", ""},
        {"", "", ".", ""},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char stem[64];
        char *d = es__path_dir(ctx, cases[i].path);
        es__path_stem(cases[i].path, stem, sizeof stem);
        ES_CHECK_MSG(!strcmp(es__path_base(cases[i].path), cases[i].base), "base of '%s'",
                     cases[i].path);
        ES_CHECK_MSG(d && !strcmp(d, cases[i].dir), "dir of '%s': %s", cases[i].path,
                     d ? d : "(null)");
        ES_CHECK_MSG(!strcmp(stem, cases[i].stem), "stem of '%s': %s", cases[i].path, stem);
        es__free(ctx, d);
    }
    /* the base name is borrowed from the path */
    const char *p = "x/y/z.obj";
    ES_CHECK(es__path_base(p) == p + 4);
    /* the stem is cut to the buffer, NUL included; n = 0 writes nothing */
    char s4[4] = "zzz", s0[1] = {'q'};
    es__path_stem("abcdef.obj", s4, sizeof s4);
    ES_CHECK(!strcmp(s4, "abc"));
    es__path_stem("abcdef.obj", s0, 0);
    ES_CHECK(s0[0] == 'q');
}

/* A file is replaced whole; a pipe or character device is written in place
 * and stays what it was (export to /dev/full used to put a CSV where the
 * device node was); a directory is refused. */
static void test_replace_targets(es_ctx *ctx)
{
    char path[4200], got[64];
    es__file_replace w;
    struct stat st;
    /* a FIFO: written in place, read back by the other end */
    in_dir("out.fifo", path, sizeof path);
    if (mkfifo(path, 0600) == 0) {
        int rd = open(path, O_RDONLY | O_NONBLOCK);
        ES_CHECK(rd >= 0);
        ES_CHECK_OK(ctx, es__replace_begin(ctx, path, &w));
        if (w.f) fputs("through the pipe\n", w.f);
        ES_CHECK_OK(ctx, es__replace_end(ctx, &w, ES_OK));
        ssize_t n = rd >= 0 ? read(rd, got, sizeof got - 1) : -1;
        ES_CHECK(n == 17 && !memcmp(got, "through the pipe\n", 17));
        ES_CHECK(stat(path, &st) == 0 && S_ISFIFO(st.st_mode));
        ES_CHECK(es_test_count_entries(dir, ".part") == 0);
        if (rd >= 0) close(rd);
        remove(path);
    }
    /* /dev/full: the device's error, and still a device */
    if (stat("/dev/full", &st) == 0 && S_ISCHR(st.st_mode)) {
        ES_CHECK_OK(ctx, es__replace_begin(ctx, "/dev/full", &w));
        if (w.f) for (int i = 0; i < 10000; i++) fputs("0123456789", w.f);
        ES_CHECK_FAILS(ctx, es__replace_end(ctx, &w, ES_OK), ES_EIO, "/dev/full");
        ES_CHECK(strstr(es_ctx_errmsg(ctx), strerror(ENOSPC)) != NULL);
        ES_CHECK(stat("/dev/full", &st) == 0 && S_ISCHR(st.st_mode));
    }
    /* a directory */
    ES_CHECK_FAILS(ctx, es__replace_begin(ctx, dir, &w), ES_EIO, strerror(EISDIR));
    ES_CHECK(w.f == NULL);
    /* a symlink to a FIFO is written through, in place */
    in_dir("out.fifo", path, sizeof path);
    if (mkfifo(path, 0600) == 0) {
        char link[4200];
        int rd = open(path, O_RDONLY | O_NONBLOCK);
        in_dir("to-fifo", link, sizeof link);
        ES_CHECK(symlink(path, link) == 0);
        ES_CHECK_OK(ctx, es__replace_begin(ctx, link, &w));
        if (w.f) fputs("x", w.f);
        ES_CHECK_OK(ctx, es__replace_end(ctx, &w, ES_OK));
        ES_CHECK(rd >= 0 && read(rd, got, 1) == 1 && got[0] == 'x');
        ES_CHECK(lstat(link, &st) == 0 && S_ISLNK(st.st_mode));
        if (rd >= 0) close(rd);
        remove(link);
        remove(path);
    }
}

/* A pid no process has: a child that has exited and been reaped. */
static pid_t dead_pid(void)
{
    pid_t pid = fork();
    if (pid == 0) _exit(0);
    waitpid(pid, NULL, 0);
    return pid;
}

static void touch(const char *path)
{
    FILE *f = fopen(path, "w");
    ES_CHECK(f != NULL);
    if (f) fclose(f);
}

/* Part files a killed writer left ("<name>.<pid>[.<n>].part") are removed by
 * the next write of that name when their process is gone, and kept when it
 * lives (issue 25: they piled up); a name too long for a part file beside
 * it (NAME_MAX) is written through a shortened one. */
static void test_stale_and_long_names(es_ctx *ctx)
{
    char path[4400], p[4600], live[4600], other[4600], name[300];
    es__file_replace w;
    pid_t gone = dead_pid();
    in_dir("model.h5", path, sizeof path);
    snprintf(p, sizeof p, "%s.%ld.part", path, (long)gone);
    touch(p);
    snprintf(p, sizeof p, "%s.%ld.3.part", path, (long)gone);
    touch(p);
    snprintf(live, sizeof live, "%s.%ld.part", path, (long)getppid());
    touch(live);
    snprintf(other, sizeof other, "%s/other.h5.%ld.part", dir, (long)gone);
    touch(other);
    ES_CHECK(es_test_count_entries(dir, ".part") == 4);
    ES_CHECK_OK(ctx, es__replace_begin(ctx, path, &w));
    if (w.f) fputs("new\n", w.f);
    ES_CHECK_OK(ctx, es__replace_end(ctx, &w, ES_OK));
    /* the live writer's and another file's are kept */
    ES_CHECK(es_test_count_entries(dir, ".part") == 2 && access(live, F_OK) == 0 &&
             access(other, F_OK) == 0);
    remove(live);
    remove(other);
    remove(path);
    /* 250 bytes: "<name>.<pid>.part" would pass NAME_MAX */
    memset(name, 'n', 250);
    memcpy(name + 246, ".csv", 5);
    snprintf(path, sizeof path, "%s/%.255s", dir, name);
    ES_CHECK_OK(ctx, es__replace_begin(ctx, path, &w));
    ES_CHECK(w.tmp && strlen(es__path_base(w.tmp)) <= 255 && strstr(w.tmp, "~"));
    if (w.f) fputs("long\n", w.f);
    ES_CHECK_OK(ctx, es__replace_end(ctx, &w, ES_OK));
    ES_CHECK(access(path, F_OK) == 0 && es_test_count_entries(dir, ".part") == 0);
    remove(path);
    /* two long names that share their first 120 bytes get two part names,
     * each within NAME_MAX; a short name is kept; the two kinds of sibling */
    {
        char want[300];
        memset(name, 'n', 250);
        name[250] = '\0';
        char *a = es__temp_sibling(ctx, name, ES__TEMP_PART, "");
        name[249] = 'm';
        char *b = es__temp_sibling(ctx, name, ES__TEMP_PART, "");
        ES_CHECK(a && b && strcmp(a, b) != 0 && strlen(a) <= 255 && strstr(a, "~"));
        ES_CHECK(a && !strncmp(a, name, 120) && a[120] == '~');
        es__free(ctx, a);
        es__free(ctx, b);
        a = es__temp_sibling(ctx, "d/short.h5", ES__TEMP_PART, ".2");
        snprintf(want, sizeof want, "d/short.h5.%ld.2.part", (long)getpid());
        ES_CHECK(a && !strcmp(a, want));
        es__free(ctx, a);
        a = es__temp_sibling(ctx, "d/short.h5", ES__TEMP_WORKING_COPY, "ab1");
        snprintf(want, sizeof want, "d/.short.h5.tmp-%ld-ab1", (long)getpid());
        ES_CHECK(a && !strcmp(a, want));
        es__free(ctx, a);
    }
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    snprintf(dir, sizeof dir, "%s", es_test_tmpdir("core-files"));
    test_flags(ctx);
    test_fifo(ctx);
    test_reuse(ctx);
    test_mkdir(ctx);
    test_paths(ctx);
    test_replace_targets(ctx);
    test_stale_and_long_names(ctx);
    static const char *const left[] = {"bom.txt", "nul.txt", "small.txt", "big.txt"};
    for (size_t i = 0; i < sizeof left / sizeof *left; i++) {
        char path[4200];
        remove(in_dir(left[i], path, sizeof path));
    }
    ES_CHECK(rmdir(dir) == 0);
    es_ctx_free(ctx);
    ES_TEST_END();
}
