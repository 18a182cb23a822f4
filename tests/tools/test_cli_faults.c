/* tests/tools/test_cli_faults.c — the commands that store results, under
 * faults, as a user would meet them:
 *   - a result name that is taken is refused (the store unchanged) unless
 *     --replace is given, for mean, pca, diff and point (gpa, embed and
 *     interp in their own tests);
 *   - a --csv table that cannot be written leaves the store unchanged (the
 *     tables are written before the commit);
 *   - writes that fail part way, injected with RLIMIT_FSIZE (every write past
 *     the limit fails with EFBIG), and a full disk (a small tmpfs, where the
 *     machine allows mounting one; skipped with a message otherwise): the
 *     command fails with a clear message and the store is byte-for-byte as
 *     it was, with no working copy left;
 *   - SIGKILL while pca, gpa, mean, point and embed store their results,
 *     at moments spread over a run and the moment its working copy appears:
 *     the store is unchanged or complete, never between;
 *   - export to a device (/dev/full) fails with the device's error and
 *     leaves the node a device; a directory is refused;
 *   - a misspelt label column, value or row id names the closest ones. */
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "es_test_run.h"

#include <errno.h>
#include <sys/mount.h>
#include <sys/resource.h>

enum { NMESH = 12, NU = 40, NV = 40 };

static const char *dir;
static char store[4200], o[4300], e[4300];

static void put_bytes(const char *path, const char *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    ES_CHECK(f && fwrite(b, 1, n, f) == n);
    if (f) fclose(f);
}

/* The store at path as bytes b, without the results beside it of kind (NULL:
 * of every kind): each result is a file beside the store (format 3). */
static void reset_store(const char *path, const char *b, size_t n, const char *kind)
{
    char cmd[9000];
    put_bytes(path, b, n);
    snprintf(cmd, sizeof cmd, "rm -rf '%s.results%s%s'", path, kind ? "/" : "", kind ? kind : "");
    ES_CHECK(system(cmd) == 0);
}

/* Start `edgespace args...` (argv[0] added), writes limited to fsize bytes
 * (0: no limit). */
static pid_t spawn(const char *const *args, rlim_t fsize)
{
    const char *argv[32];
    int n = 0;
    argv[n++] = es_test_edgespace();
    for (; args[n - 1] && n < 31; n++) argv[n] = args[n - 1];
    argv[n] = NULL;
    return es_test_spawn_limited(argv, o, e, (unsigned long long)fsize);
}

static int run(const char *const *args, rlim_t fsize, char *err, size_t n)
{
    int st = es_test_wait(spawn(args, fsize));
    es_test_read_small(e, err, n);
    return st;
}

/* The store is byte-for-byte base, and no working copy is left. */
static int unchanged(const char *path, const char *base, size_t n)
{
    return es_test_same_bytes(path, base, n) && es_test_count_entries(dir, ".tmp-") == 0;
}

/* pca, mean, diff and point: a taken name, then --replace; a table that
 * cannot be written. */
static void test_replace_and_tables(const char *base, size_t nbase)
{
    char err[4096], csv[4400];
    snprintf(csv, sizeof csv, "%s/no/such/dir/t", dir);
    const char *cmds[4][16] = {
        {"pca", store, "--name", "p"},
        {"mean", store, "--by", "grp", "--name", "m"},
        {"diff", store, "--pair-by", "subject", "--column", "grp", "--from", "a", "--to", "b",
         "--name", "d"},
        {"point", store, "mean + 0.5*pc:1", "--name", "q"},
    };
    for (int c = 0; c < 4; c++) {
        const char **args = cmds[c];
        int n = 0;
        while (args[n]) n++;
        /* the first run stores the result */
        reset_store(store, base, nbase, NULL);
        if (c == 3) {
            const char *pa[] = {"pca", store, "--name", "p", NULL};
            ES_CHECK(run(pa, 0, err, sizeof err) == 0);
        }
        char *before = NULL;
        size_t nb = 0;
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 0, "%s: %s", cmds[c][0], err);
        before = es_test_slurp(store, &nb);
        /* again: refused, naming the result and --replace; nothing written */
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 1 && strstr(err, "exists already") &&
                     strstr(err, "--replace"), "%s again: %s", cmds[c][0], err);
        ES_CHECK_MSG(before && unchanged(store, before, nb), "%s again changed the store",
                     cmds[c][0]);
        /* a table that cannot be written: exit 1 and the store unchanged
         * (it was: the result committed first, then the failure) */
        args[n] = "--replace";
        args[n + 1] = "--csv";
        args[n + 2] = csv;
        args[n + 3] = NULL;
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 1 && strstr(err, "no/such/dir"),
                     "%s --csv: %s", cmds[c][0], err);
        ES_CHECK_MSG(before && unchanged(store, before, nb), "%s with an unwritable table "
                     "changed the store", cmds[c][0]);
        /* --replace replaces */
        args[n + 1] = NULL;
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 0, "%s --replace: %s", cmds[c][0], err);
        free(before);
    }
    reset_store(store, base, nbase, NULL);
}

/* A file size limit (RLIMIT_FSIZE, no privileges needed): a result is a
 * file of its own beside the store (format 3), so storing one needs room
 * for the result, never for a copy of the store. Under a limit below the
 * result's size the command says why in one line; above it (half the
 * store, just under the store) it stores the result; either way the store
 * stays byte for byte as it was and no working file is left. (A result is
 * built in memory and written by the library's own write(): HDF5 never
 * fails a write, which libhdf5 1.10.8 survives badly, HDFFV-11052.) */
static void test_failed_writes(const char *base, size_t nbase)
{
    char err[4096], res[64];
    const char *cmds[][8] = {
        {"pca", store, "--name", "w1", NULL},
        {"mean", store, "--by", "grp", "--name", "w2", NULL},
        {"point", store, "mean", "--name", "w3", NULL},
        {"gpa", store, "--name", "w4", NULL},
    };
    static const char *const res_of[] = {"pca/w1", "mean/w2", "point/w3", "gpa/w4"};
    /* (not below 4096: the limit applies to the captured stderr too) */
    const rlim_t limits[] = {4096, (rlim_t)nbase / 2, (rlim_t)nbase - 1};
    int refused = 0;
    for (size_t c = 0; c < sizeof cmds / sizeof cmds[0]; c++)
        for (size_t l = 0; l < sizeof limits / sizeof limits[0]; l++) {
            es_ctx *ctx = NULL;
            es_store *s = NULL;
            reset_store(store, base, nbase, NULL);
            int st = run(cmds[c], limits[l], err, sizeof err);
            ES_CHECK_MSG((st == 1 && l == 0 && strstr(err, "File too large") &&
                          strchr(err, '\n') == strrchr(err, '\n')) || st == 0,
                         "%s at %llu bytes: exit %d %s", cmds[c][0],
                         (unsigned long long)limits[l], st, err);
            refused += st == 1;
            ES_CHECK_MSG(unchanged(store, base, nbase), "%s at %llu bytes changed the store or "
                         "left a working copy", cmds[c][0], (unsigned long long)limits[l]);
            snprintf(res, sizeof res, "%s", res_of[c]);
            ES_CHECK(es_ctx_new(&ctx) == ES_OK && es_store_open(ctx, store, ES_STORE_READ, &s) == ES_OK);
            ES_CHECK_MSG(s && es_store_has(s, res) == (st == 0), "%s at %llu bytes: exit %d but "
                         "the result is %s", cmds[c][0], (unsigned long long)limits[l], st,
                         s && es_store_has(s, res) ? "there" : "missing");
            es_store_close(s);
            es_ctx_free(ctx);
        }
    ES_CHECK_MSG(refused >= 3, "only %d commands were refused at 4096 bytes", refused);
    reset_store(store, base, nbase, NULL);
}

/* A full disk: a tmpfs of twice the store and a little, where the machine
 * lets us mount one (root, and a kernel that allows it in this namespace).
 * The working copy fits but the result does not (HDF5's own writes fail),
 * then the copy itself does not fit, then a new store does not. */
static void test_full_disk(const char *base, size_t nbase, const char *manifest)
{
    char small[4300], s2[4400], filler[4400], s3[4400], err[4096], opts[64];
    snprintf(small, sizeof small, "%s/small", dir);
    mkdir(small, 0755);
    snprintf(opts, sizeof opts, "size=%zu", 2 * nbase + 65536);
    if (mount("tmpfs", small, "tmpfs", 0, opts) != 0) {
        fprintf(stderr, "SKIP (full disk part): cannot mount a tmpfs here (%s)\n",
                strerror(errno));
        return;
    }
    snprintf(s2, sizeof s2, "%s/s.h5", small);
    snprintf(filler, sizeof filler, "%s/filler", small);
    snprintf(s3, sizeof s3, "%s/new.h5", small);
    put_bytes(s2, base, nbase);
    for (int round = 0; round < 2; round++) {
        /* round 0: less room than a copy of the store, enough for the
         * result (stored: results need no copy); round 1: a filler leaves
         * no room at all (refused in one line) */
        const char *args[] = {"pca", s2, "--name", round ? "full" : "fits", NULL};
        char rdir[4500];
        if (round == 1) {
            char *fill = calloc(1, nbase + 65536);
            FILE *f = fill ? fopen(filler, "wb") : NULL;
            if (f) {
                size_t w = fwrite(fill, 1, nbase + 65536, f);
                (void)w;   /* short: the disk is full, as wanted */
                fclose(f);
            }
            free(fill);
        } else {
            char *fill = calloc(1, nbase);
            if (fill) put_bytes(filler, fill, nbase / 4);
            free(fill);
        }
        int st = run(args, 0, err, sizeof err);
        if (round == 0)
            ES_CHECK_MSG(st == 0, "pca with room for its result but not a copy: %d %s", st, err);
        else
            ES_CHECK_MSG(st == 1 && strstr(err, "No space left on device") &&
                         strchr(err, '\n') == strrchr(err, '\n'),
                         "pca on a full disk: %d %s", st, err);
        ES_CHECK(es_test_same_bytes(s2, base, nbase));
        snprintf(rdir, sizeof rdir, "%s.results/pca", s2);
        ES_CHECK(es_test_count_entries(small, ".tmp-") == 0 &&
                 es_test_count_entries(rdir, ".tmp-") == 0);
        remove(filler);
    }
    {
        /* the ingest below needs a full disk again */
        char *fill = calloc(1, nbase + 65536);
        FILE *f = fill ? fopen(filler, "wb") : NULL;
        if (f) {
            size_t w = fwrite(fill, 1, nbase + 65536, f);
            (void)w;
            fclose(f);
        }
        free(fill);
    }
    {
        /* an ingest that does not fit: no store appears */
        const char *args[] = {"ingest", s3, "--manifest", manifest, "-q", NULL};
        int st = run(args, 0, err, sizeof err);
        ES_CHECK_MSG(st == 1 && strstr(err, "No space left on device") && access(s3, F_OK) != 0,
                     "ingest on a full disk: %d %s", st, err);
        ES_CHECK(es_test_count_entries(small, ".tmp-") == 0);
    }
    remove(filler);
    remove(s2);
    ES_CHECK(umount(small) == 0);
}

/* SIGKILL while a command stores its result: the store unchanged (results
 * are files beside it, format 3), the result absent or complete. The
 * working file of a result exists only while its commit writes it, so the
 * kills aimed at it ("the moment it appears") land there now and then. */
static void test_kills(es_ctx *ctx, const char *base, size_t nbase)
{
    const char *cmds[][8] = {
        {"pca", store, "--name", "k", NULL},
        {"gpa", store, "--name", "k", NULL},
        {"mean", store, "--by", "grp", "--name", "k", NULL},
        {"point", store, "mean + pc:1", "--name", "k", NULL},
        {"embed", store, "--point", "row:m03", "-o", NULL, "--name", "k"},
    };
    static const char *const kinds[] = {"pca", "gpa", "mean", "point", "embed"};
    char mesh[4400], res[64];
    snprintf(mesh, sizeof mesh, "%s/e.obj", dir);
    cmds[4][5] = mesh;
    int unch = 0, done = 0, in_copy = 0;
    char rdir[4500];
    for (int c = 0; c < 5; c++) {
        const char *args[10];
        int n = 0;
        for (; n < 8 && cmds[c][n]; n++) args[n] = cmds[c][n];
        args[n] = NULL;
        snprintf(res, sizeof res, "%s/k", kinds[c]);
        snprintf(rdir, sizeof rdir, "%s.results/%s", store, kinds[c]);
        /* a point needs a PCA: part of the base for this command */
        reset_store(store, base, nbase, NULL);
        if (c == 3) {
            char err[4096];
            const char *pa[] = {"pca", store, NULL};
            ES_CHECK(run(pa, 0, err, sizeof err) == 0);
        }
        size_t nb0;
        char *b0 = es_test_slurp(store, &nb0);
        double T = es_test_now();
        ES_CHECK(es_test_wait(spawn(args, 0)) == 0);
        T = es_test_now() - T;
        static const double at[] = {0.1, 0.3, 0.5, 0.7, 0.85, 0.95, 1.0, -1, -2, -3};
        for (size_t k = 0; k < sizeof at / sizeof at[0] && b0; k++) {
            reset_store(store, b0, nb0, kinds[c]);
            pid_t pid = spawn(args, 0);
            char mine[64];
            snprintf(mine, sizeof mine, ".tmp-%ld-", (long)pid);
            if (at[k] >= 0) {
                es_test_sleep(at[k] * T);
            } else {
                /* the moment its working copy appears, then a little later */
                double t0 = es_test_now();
                while (es_test_count_entries(rdir, mine) == 0 && es_test_now() - t0 < 2 * T + 5)
                    es_test_sleep(0.0002);
                if (at[k] < -1) es_test_sleep(at[k] == -2 ? 0.002 : 0.02);
            }
            kill(pid, SIGKILL);
            int st = es_test_wait(pid);
            if (st == 128 + SIGKILL && es_test_count_entries(rdir, mine) > 0) in_copy++;
            es_store *s = NULL;
            ES_CHECK_MSG(es_store_open(ctx, store, ES_STORE_READ, &s) == ES_OK,
                         "%s killed at %g: the store does not open: %s", kinds[c], at[k],
                         es_ctx_errmsg(ctx));
            if (!s) continue;
            ES_CHECK_MSG(es_test_same_bytes(store, b0, nb0), "%s killed at %g: the store's bytes "
                         "changed", kinds[c], at[k]);
            if (es_store_has(s, res)) {
                char **keys = NULL;
                int64_t nkeys = 0;
                done++;
                /* complete: its provenance and datasets all there */
                ES_CHECK_MSG(es_store_list_attrs(ctx, s, res, &keys, &nkeys) ==
                                 ES_OK && nkeys >= 4, "%s: a partial result", kinds[c]);
                for (int64_t i = 0; i < nkeys; i++) es_free(ctx, keys[i]);
                es_free(ctx, keys);
            } else {
                unch++;
            }
            es_store_close(s);
        }
        /* the next writer removes the dead processes' working files */
        {
            char published[4600];
            snprintf(published, sizeof published, "%s/k.h5", rdir);
            put_bytes(store, b0, nb0);
            unlink(published);
        }
        ES_CHECK(es_test_wait(spawn(args, 0)) == 0);
        ES_CHECK_MSG(es_test_count_entries(dir, ".tmp-") == 0 &&
                     es_test_count_entries(rdir, ".tmp-") == 0, "%s: stale working files left",
                     kinds[c]);
        free(b0);
    }
    fprintf(stderr, "kills: %d left the store unchanged (%d with a working copy in progress), "
            "%d came after the commit\n", unch, in_copy, done);
    ES_CHECK(unch >= 10);
    reset_store(store, base, nbase, NULL);
}

/* export to a device node and to a directory */
static void test_devices(void)
{
    char err[4096];
    struct stat st;
    if (stat("/dev/full", &st) == 0 && S_ISCHR(st.st_mode)) {
        const char *args[] = {"export", store, "--lengths", "/dev/full", NULL};
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 1 && strstr(err, "/dev/full") &&
                     strstr(err, "No space left on device"), "export to /dev/full: %s", err);
        ES_CHECK(stat("/dev/full", &st) == 0 && S_ISCHR(st.st_mode));
    }
    if (stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode)) {
        const char *args[] = {"export", store, "--lengths", "/dev/null", NULL};
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 0, "export to /dev/null: %s", err);
        ES_CHECK(stat("/dev/null", &st) == 0 && S_ISCHR(st.st_mode));
    }
    {
        const char *args[] = {"export", store, "--lengths", dir, NULL};
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 1 && strstr(err, "Is a directory"),
                     "export to a directory: %s", err);
    }
}

/* A misspelt label column, value or row id names the closest ones. */
static void test_misspelt(void)
{
    char err[4096];
    static const struct { const char *args[12], *want; } cases[] = {
        {{"mean", NULL, "--by", "gpr", "--no-store"}, "no label column 'gpr' (did you mean 'grp'?)"},
        {{"mean", NULL, "--where", "subjcet=s1", "--no-store"},
         "no label column 'subjcet' in"},
        {{"mean", NULL, "--where", "grp=aa", "--no-store"}, "no row has grp='aa' (did you mean "
         "'a' or 'b'?)"},
        {{"diff", NULL, "--pair-by", "subject", "--column", "grp", "--from", "a", "--to", "c"},
         "no rows with grp=c (did you mean 'a' or 'b'?)"},
        {{"diff", NULL, "--pair-by", "subjects", "--column", "grp", "--from", "a", "--to", "b"},
         "no label column 'subjects' (did you mean 'subject'?)"},
        {{"point", NULL, "row:m3"}, "no row with id 'm3' (did you mean 'm03'"},
        {{"embed", NULL, "--point", "row:m03", "--init", "row:mo3", "--no-store", "-o", "x.obj"},
         "no row 'mo3' in the store (did you mean 'm03'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *args[14];
        int n = 0;
        for (; n < 12 && (n < 2 || cases[i].args[n]); n++)
            args[n] = n == 1 ? store : cases[i].args[n];
        args[n] = NULL;
        int st = run(args, 0, err, sizeof err);
        ES_CHECK_MSG(st == 1 && strstr(err, cases[i].want), "%s: %d %s", cases[i].args[0], st,
                     err);
    }
}

int main(void)
{
    es_ctx *ctx = NULL;
    char manifest[4300], p[4300], err[4096];
    FILE *f;
    ES_TEST_BEGIN();
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE is not set");
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    dir = es_test_tmpdir("cli-faults");
    snprintf(store, sizeof store, "%s/s.h5", dir);
    snprintf(o, sizeof o, "%s/.out", dir);
    snprintf(e, sizeof e, "%s/.err", dir);
    snprintf(manifest, sizeof manifest, "%s/m.csv", dir);
    for (int k = 0; k < NMESH; k++) {
        snprintf(p, sizeof p, "%s/m%02d.obj", dir, k);
        ES_CHECK(es_test_write_torus(p, NU, NV, k) == 0);
    }
    if (!(f = fopen(manifest, "w"))) return 1;
    fputs("file,grp,subject\n", f);
    for (int k = 0; k < NMESH; k++) fprintf(f, "m%02d.obj,%s,s%d\n", k, k % 2 ? "b" : "a", k / 2);
    fclose(f);
    {
        const char *args[] = {"ingest", store, "--manifest", manifest, "-q", NULL};
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 0, "ingest: %s", err);
    }
    size_t nbase;
    char *base = es_test_slurp(store, &nbase);
    ES_CHECK(base != NULL);
    if (!base) ES_TEST_END();

    test_replace_and_tables(base, nbase);
    test_failed_writes(base, nbase);
    test_full_disk(base, nbase, manifest);
    test_kills(ctx, base, nbase);
    test_devices();
    test_misspelt();
    free(base);
    es_ctx_free(ctx);
    ES_TEST_END();
}
