/* tests/store/test_store_beside.c — results beside the store (format 3,
 * datasets-spec/store-format.md "Results beside the store"): storing a
 * result leaves the store file byte for byte and inode for inode as it was
 * (no copy), the result is read back, listed, replaced only when asked and
 * deleted; a writer SIGKILLed before or during its commits leaves the store
 * unchanged and every visible result whole, and its stale working file is
 * removed by the next writer; a results folder left by a deleted store of
 * the same name is not taken for the new store's; a damaged result file is
 * refused with a message; and a store of format 2 (earlier releases) is
 * still read and written, its results inside it as before, until it is
 * upgraded when asked (es_store_upgrade), after which its results are
 * beside it and storing one copies nothing. */
#include "crafted.h"

#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

enum { NV = 200, NROWS = 40 };

/* A truss store of NROWS rows over NV landmarks (about 200 KB of lengths
 * and positions): big enough that a copy would show. */
static void make_store(es_ctx *ctx, const char *path)
{
    static int64_t edges[2 * (NV - 1)];
    static double xyz[3 * NV * NROWS], len[(NV - 1) * NROWS], scale[NROWS];
    static char idbuf[NROWS][16];
    const char *ids[NROWS];
    es_store *s = NULL;
    for (int e = 0; e < NV - 1; e++) edges[2 * e] = e, edges[2 * e + 1] = e + 1;
    for (int i = 0; i < NROWS; i++) {
        double sum = 0;
        for (int v = 0; v < NV; v++)
            for (int k = 0; k < 3; k++) xyz[3 * NV * i + 3 * v + k] = v * (k == 0) + 0.01 * i * k;
        for (int e = 0; e < NV - 1; e++) {
            const double *a = xyz + 3 * NV * i + 3 * e, *b = a + 3;
            double d2 = 0;
            for (int k = 0; k < 3; k++) d2 += (a[k] - b[k]) * (a[k] - b[k]);
            sum += len[(NV - 1) * i + e] = sqrt(d2);
        }
        for (int e = 0; e < NV - 1; e++) len[(NV - 1) * i + e] /= sum;
        scale[i] = sum;
        snprintf(idbuf[i], sizeof idbuf[i], "row%02d", i);
        ids[i] = idbuf[i];
    }
    es_store_rows r = {NROWS, ids, NULL, NULL, len, scale, xyz, 0, NULL, NULL};
    ES_CHECK_OK(ctx, es_store_create_edges(ctx, path, NV, NV - 1, edges, &s));
    ES_CHECK_OK(ctx, es_store_append(ctx, s, &r));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    es_store_close(s);
}

/* Store result kind/name: a vector of n values v0, v0 + 1, ... */
static es_status put_result(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            int n, double v0)
{
    char path[300];
    double v[64];
    es_provenance prov = {"test_store_beside", NULL, -1, "n=..."};
    es_status rc = es_store_result_begin(ctx, s, kind, name, &prov);
    for (int i = 0; i < n && i < 64; i++) v[i] = v0 + i;
    snprintf(path, sizeof path, "%s/%s/v", kind, name);
    if (rc == ES_OK) rc = es_store_put_vector(ctx, s, path, v, n);
    return rc;
}

/* The vector of kind/name is whole: n values from v0 (v0 out when NULL). */
static int result_whole(es_ctx *ctx, es_store *s, const char *kind, const char *name, int n)
{
    char path[300];
    double *v = NULL;
    int64_t got = 0;
    int ok;
    snprintf(path, sizeof path, "%s/%s/v", kind, name);
    if (es_store_get_vector(ctx, s, path, &v, &got) != ES_OK) return 0;
    ok = got == n;
    for (int64_t i = 1; ok && i < got; i++) ok = v[i] == v[0] + (double)i;
    es_free(ctx, v);
    return ok;
}

static int same_file(const struct stat *a, const struct stat *b)
{
    return a->st_ino == b->st_ino && a->st_size == b->st_size &&
           a->st_mtim.tv_sec == b->st_mtim.tv_sec && a->st_mtim.tv_nsec == b->st_mtim.tv_nsec;
}

static void test_no_copy(es_ctx *ctx, const char *path)
{
    struct stat before, after;
    size_t n0 = 0, n1 = 0;
    char *bytes0, *bytes1, side[1200];
    es_store *s = NULL;
    char **names = NULL;
    int64_t n = 0;
    ES_CHECK(stat(path, &before) == 0);
    bytes0 = es_test_slurp(path, &n0);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    ES_CHECK_OK(ctx, put_result(ctx, s, "point", "p1", 10, 1.0));
    ES_CHECK_OK(ctx, put_result(ctx, s, "mean", "m1", 5, 7.0));
    /* this handle reads its own writes before the commit; others do not */
    ES_CHECK(result_whole(ctx, s, "point", "p1", 10));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    ES_CHECK(result_whole(ctx, s, "point", "p1", 10));
    es_store_close(s);
    s = NULL;
    ES_CHECK(stat(path, &after) == 0);
    bytes1 = es_test_slurp(path, &n1);
    /* the store file was not copied, renamed or written */
    ES_CHECK(same_file(&before, &after));
    ES_CHECK(bytes0 && bytes1 && n0 == n1 && !memcmp(bytes0, bytes1, n0));
    free(bytes0);
    free(bytes1);
    snprintf(side, sizeof side, "%s.results/point/p1.h5", path);
    ES_CHECK(access(side, F_OK) == 0);

    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    if (!s) return;
    ES_CHECK(es_store_has(s, "point/p1") && es_store_has(s, "point/p1/v") &&
             !es_store_has(s, "point/p2"));
    ES_CHECK(result_whole(ctx, s, "mean", "m1", 5));
    {
        char buf[64];
        ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "point/p1", "command", buf, sizeof buf));
        ES_CHECK(!strcmp(buf, "test_store_beside"));
    }
    ES_CHECK_OK(ctx, es_store_list_results(ctx, s, NULL, &names, &n));
    ES_CHECK(n == 2 && !strcmp(names[0], "mean") && !strcmp(names[1], "point"));
    for (int64_t i = 0; i < n; i++) es_free(ctx, names[i]);
    es_free(ctx, names);
    ES_CHECK_FAILS(ctx, put_result(ctx, s, "point", "p3", 3, 0), ES_EINVAL, "read-only");
    es_store_close(s);
    s = NULL;

    /* replaced only when asked; deleted */
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    ES_CHECK_FAILS(ctx, put_result(ctx, s, "point", "p1", 3, 0), ES_EEXIST, "exists already");
    es_store_close(s);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_REPLACE, &s));
    ES_CHECK_OK(ctx, put_result(ctx, s, "point", "p1", 3, 100.0));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    ES_CHECK(result_whole(ctx, s, "point", "p1", 3));
    ES_CHECK_OK(ctx, es_store_delete_result(ctx, s, "mean", "m1"));
    ES_CHECK(!es_store_has(s, "mean/m1"));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    es_store_close(s);
    snprintf(side, sizeof side, "%s.results/mean/m1.h5", path);
    ES_CHECK(access(side, F_OK) != 0);
    ES_CHECK(stat(path, &after) == 0 && same_file(&before, &after));
}

/* A writer killed before its commit, and one killed while it commits
 * result after result: the store is unchanged, every visible result whole,
 * and the next writer removes the dead one's working file. */
static void test_killed_writer(es_ctx *ctx, const char *path)
{
    struct stat before, after;
    char kdir[1200];
    es_store *s = NULL;
    ES_CHECK(stat(path, &before) == 0);
    snprintf(kdir, sizeof kdir, "%s.results/k", path);
    pid_t pid = fork();
    if (pid == 0) {
        es_ctx *c = NULL;
        es_store *w = NULL;
        if (es_ctx_new(&c) != ES_OK || es_store_open(c, path, ES_STORE_WRITE, &w) != ES_OK ||
            put_result(c, w, "k", "dead", 20, 0) != ES_OK)
            _exit(3);
        raise(SIGKILL);   /* written, never committed */
        _exit(4);
    }
    int st = 0;
    waitpid(pid, &st, 0);
    ES_CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    /* built in memory until its commit: nothing on disk */
    ES_CHECK(es_test_count_entries(kdir, ".tmp-") == 0);
    ES_CHECK(stat(path, &after) == 0 && same_file(&before, &after));
    /* a working file a dead writer left (killed while writing it) */
    {
        char stale[1400];
        pid_t gone = fork();
        if (gone == 0) _exit(0);
        waitpid(gone, NULL, 0);
        mkdir(kdir, 0777);
        snprintf(stale, sizeof stale, "%s/.dead.h5.tmp-%ld-0", kdir, (long)gone);
        es_test_write_file(stale, "half a result");
    }
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    ES_CHECK(s && !es_store_has(s, "k/dead"));
    ES_CHECK_OK(ctx, put_result(ctx, s, "k", "dead", 4, 0));
    ES_CHECK(es_test_count_entries(kdir, ".tmp-") == 0);   /* the dead one's removed */
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    ES_CHECK(es_test_count_entries(kdir, ".tmp-") == 0);
    es_store_close(s);
    s = NULL;

    /* killed at a moment of its commits */
    for (int trial = 0; trial < 3; trial++) {
        int fds[2];
        ES_CHECK(pipe(fds) == 0);
        pid = fork();
        if (pid == 0) {
            es_ctx *c = NULL;
            es_store *w = NULL;
            char name[32];
            close(fds[0]);
            if (es_ctx_new(&c) != ES_OK || es_store_open(c, path, ES_STORE_REPLACE, &w) != ES_OK)
                _exit(3);
            for (int i = 0;; i++) {
                snprintf(name, sizeof name, "r%d", i % 50);
                if (put_result(c, w, "k", name, 1 + i % 60, (double)i) != ES_OK ||
                    es_store_commit(c, w) != ES_OK)
                    _exit(5);
                if (i == 5 && write(fds[1], "x", 1) != 1) _exit(6);
            }
        }
        close(fds[1]);
        char x;
        ES_CHECK(read(fds[0], &x, 1) == 1);
        close(fds[0]);
        usleep(20000 * (useconds_t)(trial + 1));
        kill(pid, SIGKILL);
        waitpid(pid, &st, 0);
        ES_CHECK_MSG(WIFSIGNALED(st), "the writer ended by itself: status %d", st);
        ES_CHECK(stat(path, &after) == 0 && same_file(&before, &after));
        ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
        if (!s) continue;
        char **names = NULL;
        int64_t n = 0;
        ES_CHECK_OK(ctx, es_store_list_results(ctx, s, "k", &names, &n));
        ES_CHECK(n >= 6);
        for (int64_t i = 0; i < n; i++) {
            char p[300];
            double *v = NULL;
            int64_t m = 0;
            snprintf(p, sizeof p, "k/%s/v", names[i]);
            ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, p, &v, &m));
            int whole = m >= 1;
            for (int64_t j = 1; whole && j < m; j++) whole = v[j] == v[0] + (double)j;
            ES_CHECK_MSG(whole, "result k/%s is not whole", names[i]);
            es_free(ctx, v);
            es_free(ctx, names[i]);
        }
        es_free(ctx, names);
        es_store_close(s);
        s = NULL;
    }
}

/* A results folder that outlived its store is not the next store's. */
static void test_stale_folder(es_ctx *ctx, const char *dir)
{
    char path[700];
    es_store *s = NULL;
    char **names = NULL;
    int64_t n = -1;
    snprintf(path, sizeof path, "%s/again.h5", dir);
    make_store(ctx, path);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    ES_CHECK_OK(ctx, put_result(ctx, s, "mean", "old", 4, 0));
    es_store_close(s);
    ES_CHECK(unlink(path) == 0);   /* the store deleted, its results folder left */
    make_store(ctx, path);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK(!es_store_has(s, "mean/old"));
    ES_CHECK_OK(ctx, es_store_list_results(ctx, s, NULL, &names, &n));
    ES_CHECK(n == 0);
    es_free(ctx, names);
    ES_CHECK_OK(ctx, put_result(ctx, s, "mean", "old", 2, 9));   /* replaces the stale file */
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    ES_CHECK(result_whole(ctx, s, "mean", "old", 2));
    es_store_close(s);
}

/* A result file with changed bytes: refused with a message naming it, or
 * read, never a crash; a file that is not HDF5 at all is named. */
static void test_damaged(es_ctx *ctx, const char *path)
{
    char side[1200];
    es_store *s = NULL;
    size_t n = 0;
    snprintf(side, sizeof side, "%s.results/point/p1.h5", path);
    char *orig = es_test_slurp(side, &n);
    ES_CHECK(orig && n > 100);
    if (!orig) return;
    uint64_t state = 12345;
    for (int t = 0; t < 60; t++) {
        char *b = malloc(n);
        if (!b) break;
        memcpy(b, orig, n);
        for (int q = 0; q < 3; q++) {
            state = state * 6364136223846793005u + 1442695040888963407u;
            b[(state >> 17) % n] = (char)(state >> 9);
        }
        FILE *f = fopen(side, "wb");
        ES_CHECK(f && fwrite(b, 1, n, f) == n);
        if (f) fclose(f);
        free(b);
        if (es_store_open(ctx, path, ES_STORE_READ, &s) == ES_OK) {
            double *v = NULL;
            int64_t m = 0;
            es_status rc = es_store_get_vector(ctx, s, "point/p1/v", &v, &m);
            ES_CHECK_MSG(rc == ES_OK || rc == ES_ENOTFOUND || strstr(es_ctx_errmsg(ctx), "store: "),
                         "trial %d: %s", t, es_ctx_errmsg(ctx));
            es_free(ctx, v);
            es_store_close(s);
            s = NULL;
        }
    }
    es_test_write_file(side, "not hdf5\n");
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    if (s) {
        double *v = NULL;
        int64_t m = 0;
        ES_CHECK_FAILS(ctx, es_store_get_vector(ctx, s, "point/p1/v", &v, &m), ES_EFORMAT,
                       "p1.h5");
        es_store_close(s);
    }
    FILE *f = fopen(side, "wb");
    ES_CHECK(f && fwrite(orig, 1, n, f) == n);
    if (f) fclose(f);
    free(orig);
}

/* A store as earlier releases wrote it (format 2): read, and its results
 * still go inside it (published by the working copy, as before). */
static void test_format1(es_ctx *ctx, const char *dir)
{
    char path[700], side[800];
    es_store *s = NULL;
    struct stat before, after;
    snprintf(path, sizeof path, "%s/old.h5", dir);
    ES_CHECK(crafted_base(path) == 0);   /* format 2, a result mean/m inside */
    ES_CHECK(stat(path, &before) == 0);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK(es_store_has(s, "mean/m/means"));
    ES_CHECK_OK(ctx, put_result(ctx, s, "point", "q", 6, 2));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    es_store_close(s);
    s = NULL;
    snprintf(side, sizeof side, "%s.results", path);
    ES_CHECK(access(side, F_OK) != 0);
    ES_CHECK(stat(path, &after) == 0 && after.st_ino != before.st_ino);   /* copied, renamed */
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    ES_CHECK(s && result_whole(ctx, s, "point", "q", 6) && es_store_has(s, "mean/m"));
    ES_CHECK(es_store_format_version(s) == 2);
    ES_CHECK_FAILS(ctx, es_store_upgrade(ctx, s), ES_EINVAL, "read-only");
    es_store_close(s);
    s = NULL;

    /* upgraded when asked: the results move beside it, read as before */
    char side_q[900];
    snprintf(side_q, sizeof side_q, "%s.results/point/q.h5", path);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    ES_CHECK_OK(ctx, es_store_upgrade(ctx, s));
    ES_CHECK(es_store_format_version(s) == 3);
    es_store_close(s);
    s = NULL;
    ES_CHECK(access(side_q, F_OK) == 0);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK(es_store_format_version(s) == 3);
    ES_CHECK(result_whole(ctx, s, "point", "q", 6));
    {
        es_mat m = {0};
        char by[16];
        ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, "mean/m/means", &m));
        ES_CHECK(m.cols == 2 && m.rows == 6);
        es_free(ctx, m.data);
        ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "mean/m", "by", by, sizeof by));
        ES_CHECK(!strcmp(by, "grp"));
    }
    ES_CHECK_OK(ctx, es_store_upgrade(ctx, s));   /* version 3 already: nothing to do */
    ES_CHECK(stat(path, &before) == 0);
    ES_CHECK_OK(ctx, put_result(ctx, s, "point", "r", 3, 0));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    ES_CHECK(stat(path, &after) == 0 && same_file(&before, &after));   /* no copy any more */
    es_store_close(s);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    const char *dir = es_test_tmpdir("store_beside");
    char path[700];
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    snprintf(path, sizeof path, "%s/s.h5", dir);
    make_store(ctx, path);
    test_no_copy(ctx, path);
    test_killed_writer(ctx, path);
    test_damaged(ctx, path);
    test_stale_folder(ctx, dir);
    test_format1(ctx, dir);
    es_ctx_free(ctx);
    ES_TEST_END();
}
