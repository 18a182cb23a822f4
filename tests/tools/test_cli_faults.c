/* tests/tools/test_cli_faults.c — the commands that store results, under
 * faults, as a user would meet them:
 *   - a result name that is taken is refused (the store unchanged) unless
 *     --replace is given, for mean, pca, diff and point (gpa, embed and
 *     interp in their own tests);
 *   - an --output table that cannot be written leaves the store unchanged (the
 *     tables are written before the commit);
 *   - writes that fail part way, injected with RLIMIT_FSIZE (every write past
 *     the limit fails with EFBIG), and a full disk (a small tmpfs, where the
 *     machine allows mounting one; skipped with a message otherwise): the
 *     command fails with a clear message and the store is byte-for-byte as
 *     it was, with no working copy left; `export --statismo` onto a tmpfs
 *     with 4 KiB to 512 KiB free writes the model or fails in one line,
 *     never crashing at exit, never leaving a part file; `interp` writes
 *     all its frames or none;
 *   - SIGKILL while pca, gpa, mean, point and embed store their results,
 *     at moments spread over a run and the moment its working copy appears:
 *     the store is unchanged or complete, never between;
 *   - export to a device (/dev/full) fails with the device's error and
 *     leaves the node a device; a directory is refused;
 *   - a misspelt label column, value or row id names the closest ones;
 *   - the stored command line replays as exactly the arguments given. */
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "es_test_run.h"

#include <errno.h>
#include <sys/mount.h>
#include <sys/statvfs.h>
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
/* stderr of a failed command: its progress lines (work of a second or
 * more logs "... of N (P %, T s)" lines without a terminal) and then one
 * error line naming want. */
static int one_error_line(const char *err, const char *want)
{
    const char *last = err, *p = err, *nl;
    int errors = 0;
    for (; *p; p = nl + 1) {
        if (!(nl = strchr(p, '\n'))) return 0;   /* every line ends */
        const char *pct = strstr(p, " %, ");
        if (!pct || pct > nl || nl[-1] != ')') {
            errors++;
            last = p;
        }
    }
    return errors == 1 && strstr(last, want) && strstr(last, want) < strchr(last, '\n');
}

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
        args[n + 1] = "--output";
        args[n + 2] = csv;
        args[n + 3] = NULL;
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 1 && strstr(err, "no/such/dir"),
                     "%s --output: %s", cmds[c][0], err);
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
            ES_CHECK_MSG((st == 1 && l == 0 && one_error_line(err, "File too large")) || st == 0,
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
            ES_CHECK_MSG(st == 1 && one_error_line(err, "No space left on device"),
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

/* `export --statismo` onto a nearly full disk (issue 25): it printed a
 * clean error, then segfaulted at exit for 8 of 13 free sizes between 4 and
 * 224 KiB (libhdf5 1.10.8 after a failed flush). Every writer shares the
 * store's full-disk-safe close now: each size exits 0 with the model or 1
 * with one line, leaves no part file, and an old model stays as it was. */
static void test_full_disk_statismo(const char *base, size_t nbase)
{
    static const int free_kib[] = {4, 8, 16, 32, 48, 64, 80, 96, 112, 128, 160, 192, 224,
                                   512};
    char small[4300], model[4400], filler[4400], err[4096], opts[64], src[4300];
    int ok = 0, refused = 0;
    snprintf(src, sizeof src, "%s/statismo-src.h5", dir);
    put_bytes(src, base, nbase);
    {
        const char *args[] = {"pca", src, "--name", "p", "--components", "3", NULL};
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 0, "pca: %s", err);
    }
    snprintf(small, sizeof small, "%s/small-statismo", dir);
    snprintf(model, sizeof model, "%s/model.h5", small);
    snprintf(filler, sizeof filler, "%s/filler", small);
    mkdir(small, 0755);
    snprintf(opts, sizeof opts, "size=%d", 2 << 20);
    if (mount("tmpfs", small, "tmpfs", 0, opts) != 0) {
        fprintf(stderr, "SKIP (full-disk statismo part): cannot mount a tmpfs here (%s)\n",
                strerror(errno));
        remove(src);
        return;
    }
    for (size_t k = 0; k < sizeof free_kib / sizeof free_kib[0]; k++) {
        const char *args[] = {"export", src, "--statismo", model, "--pca", "p", NULL};
        struct statvfs sv;
        int st;
        remove(model);
        remove(filler);
        if (statvfs(small, &sv) == 0) {
            unsigned long long avail = (unsigned long long)sv.f_bavail * sv.f_frsize;
            unsigned long long keep = (unsigned long long)free_kib[k] << 10;
            FILE *f = fopen(filler, "wb");
            if (f && avail > keep) {
                static char zero[1 << 16];
                for (unsigned long long left = avail - keep; left > 0;) {
                    size_t w = left < sizeof zero ? (size_t)left : sizeof zero;
                    if (fwrite(zero, 1, w, f) != w) break;
                    left -= w;
                }
            }
            if (f) fclose(f);
        }
        st = run(args, 0, err, sizeof err);
        ES_CHECK_MSG(st == 0 || (st == 1 && one_error_line(err, "No space left on device")),
                     "export --statismo with %d KiB free: exit %d %s", free_kib[k], st, err);
        ES_CHECK_MSG(st != 1 || access(model, F_OK) != 0, "a failed export left %s", model);
        ES_CHECK_MSG(es_test_count_entries(small, ".part") == 0,
                     "a part file stayed (%d KiB free)", free_kib[k]);
        ok += st == 0;
        refused += st == 1;
    }
    printf("export --statismo on a nearly full disk: %d written, %d refused cleanly\n", ok,
           refused);
    ES_CHECK(ok > 0 && refused > 0);
    remove(model);
    remove(filler);
    remove(src);
    ES_CHECK(umount(small) == 0);
}

/* The frames of a walk appear together or not at all (issue 25: on a full
 * disk `interp` left new and old frames mixed): with room for two of nine
 * frames the old frames stay byte for byte and no part file is left; with
 * room for all, all nine are new. */
static void test_full_disk_frames(const char *base, size_t nbase)
{
    char small[4300], src[4300], pat[4400], ref[4400], f0[4400], filler[4400], err[4096];
    char opts[64];
    struct stat st;
    snprintf(src, sizeof src, "%s/frames-src.h5", dir);
    put_bytes(src, base, nbase);
    snprintf(ref, sizeof ref, "%s/ref_%%02d.obj", dir);
    {
        const char *args[] = {"interp", src, "--from", "row:m00", "--to", "row:m01", "--steps", "9",
                              "-o", ref, "--no-store", NULL};
        ES_CHECK_MSG(run(args, 0, err, sizeof err) == 0, "interp: %s", err);
    }
    snprintf(f0, sizeof f0, "%s/ref_00.obj", dir);
    if (stat(f0, &st) != 0) {
        ES_CHECK(0);
        return;
    }
    snprintf(small, sizeof small, "%s/small-frames", dir);
    mkdir(small, 0755);
    snprintf(opts, sizeof opts, "size=%lld", (long long)(12 * st.st_size + (1 << 20)));
    if (mount("tmpfs", small, "tmpfs", 0, opts) != 0) {
        fprintf(stderr, "SKIP (full-disk frames part): cannot mount a tmpfs here (%s)\n",
                strerror(errno));
    } else {
        char frame[4500];
        struct statvfs sv;
        snprintf(pat, sizeof pat, "%s/f_%%02d.obj", small);
        snprintf(filler, sizeof filler, "%s/filler", small);
        for (int i = 0; i < 9; i++) {
            snprintf(frame, sizeof frame, "%s/f_%02d.obj", small, i);
            es_test_write_file(frame, "old\n");
        }
        /* room for two frames and a half */
        if (statvfs(small, &sv) == 0) {
            long long keep = 5 * (long long)st.st_size / 2;
            long long fill = (long long)sv.f_bavail * (long long)sv.f_frsize - keep;
            FILE *f = fopen(filler, "wb");
            static char zero[1 << 16];
            for (; f && fill > 0; fill -= (long long)sizeof zero)
                if (fwrite(zero, 1, fill < (long long)sizeof zero ? (size_t)fill : sizeof zero,
                           f) == 0)
                    break;
            if (f) fclose(f);
        }
        const char *args[] = {"interp", src, "--from", "row:m00", "--to", "row:m01", "--steps", "9",
                              "-o", pat, "--no-store", NULL};
        int rc = run(args, 0, err, sizeof err);
        ES_CHECK_MSG(rc == 1 && strstr(err, "No space left on device"), "interp on a full "
                     "disk: exit %d %s", rc, err);
        for (int i = 0; i < 9; i++) {
            snprintf(frame, sizeof frame, "%s/f_%02d.obj", small, i);
            ES_CHECK_MSG(es_test_same_bytes(frame, "old\n", 4), "frame %d was replaced by a "
                         "walk that failed", i);
        }
        ES_CHECK(es_test_count_entries(small, ".part") == 0);
        /* with room: every frame new, as the walk outside wrote it */
        remove(filler);
        rc = run(args, 0, err, sizeof err);
        ES_CHECK_MSG(rc == 0, "interp with room: %s", err);
        for (int i = 0; i < 9; i++) {
            char want[4500];
            size_t nw = 0;
            snprintf(frame, sizeof frame, "%s/f_%02d.obj", small, i);
            snprintf(want, sizeof want, "%s/ref_%02d.obj", dir, i);
            char *w = es_test_slurp(want, &nw);
            ES_CHECK_MSG(w && es_test_same_bytes(frame, w, nw), "frame %d differs", i);
            free(w);
            remove(frame);
        }
        ES_CHECK(umount(small) == 0);
    }
    for (int i = 0; i < 9; i++) {
        snprintf(f0, sizeof f0, "%s/ref_%02d.obj", dir, i);
        remove(f0);
    }
    remove(src);
}

/* The stored command line replays as the command that ran (issue 25: a
 * name "a'; touch PWNED; echo '" was stored so that replaying it ran
 * touch): a shell reads back exactly the arguments given. */
static void test_provenance_quoting(es_ctx *ctx, const char *base, size_t nbase)
{
    static const char *const name = "a'; touch PWNED; echo '";
    const char *args[] = {"mean", store, "--by", "grp", "-n", name, NULL};
    char err[4096], cmd[8192], sh[8400], line[4096], pwned[4300];
    es_store *s = NULL;
    int k = 0, ok = 1, used[6] = {0};
    put_bytes(store, base, nbase);
    ES_CHECK_MSG(run(args, 0, err, sizeof err) == 0, "mean -n: %s", err);
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
    snprintf(sh, sizeof sh, "mean/%s", name);
    ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, sh, "command", cmd, sizeof cmd));
    es_store_close(s);
    ES_CHECK(!strncmp(cmd, "edgespace ", 10));
    /* the shell splits the stored line: printf shows each argument */
    snprintf(sh, sizeof sh, "cd '%s' && printf '%%s\\n' %s", dir, cmd + 10);
    FILE *p = popen(sh, "r");
    ES_CHECK(p != NULL);
    while (p && fgets(line, sizeof line, p)) {
        /* (getopt moves the store after the options) */
        int hit = 0;
        line[strcspn(line, "\n")] = '\0';
        for (int a = 0; a < 6 && !hit; a++)
            if (!used[a] && !strcmp(line, args[a])) used[a] = hit = 1;
        ok &= hit;
        k++;
    }
    if (p) pclose(p);
    ES_CHECK_MSG(ok && k == 6, "the stored command '%s' read back as %d other arguments", cmd,
                 k);
    snprintf(pwned, sizeof pwned, "%s/PWNED", dir);
    ES_CHECK(access(pwned, F_OK) != 0);
    put_bytes(store, base, nbase);
}

/* Inputs refused in one line before any work (issue 25): meshes scaled by
 * 1e77 or 1e-100 (ingested, they embedded with 17-56 % error and NaN
 * bending), a manifest of 20,000 label columns (an internal HDF5 error after
 * 8.6 s); and `-o -` of mean, point and model is the CSV alone on stdout
 * (the summary goes to stderr). */
static void test_hostile_inputs(const char *base, size_t nbase)
{
    static const char *const scales[2] = {"1e77", "1e-100"};
    char err[4096], obj[4400], man[4400], st[4400];
    snprintf(st, sizeof st, "%s/hostile.h5", dir);
    for (int k = 0; k < 2; k++) {
        double sc = strtod(scales[k], NULL);
        FILE *f;
        snprintf(obj, sizeof obj, "%s/scaled.obj", dir);
        if (!(f = fopen(obj, "w"))) continue;
        fprintf(f, "v 0 0 0\nv %.17g 0 0\nv 0 %.17g 0\nv 0 0 %.17g\n", sc, sc, sc);
        fputs("f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", f);
        fclose(f);
        const char *args[] = {"ingest", st, obj, "-q", NULL};
        int rc = run(args, 0, err, sizeof err);
        ES_CHECK_MSG(rc == 1 && strstr(err, "rescale it") && access(st, F_OK) != 0,
                     "a mesh scaled by %s: exit %d %s", scales[k], rc, err);
        remove(obj);
    }
    {
        FILE *f;
        snprintf(man, sizeof man, "%s/wide.csv", dir);
        if ((f = fopen(man, "w"))) {
            fputs("file", f);
            for (int c = 0; c < 20000; c++) fprintf(f, ",c%d", c);
            for (int k = 0; k < 2; k++) {
                fprintf(f, "\nm%02d.obj", k);
                for (int c = 0; c < 20000; c++) fputs(",v", f);
            }
            fputc('\n', f);
            fclose(f);
        }
        const char *args[] = {"ingest", st, "--manifest", man, "-q", NULL};
        int rc = run(args, 0, err, sizeof err);
        ES_CHECK_MSG(rc == 1 && strstr(err, "20001 label columns; a store holds at most 2000") &&
                     access(st, F_OK) != 0, "20,000 columns: exit %d %s", rc, err);
        remove(man);
    }
    /* -o -: stdout is the CSV, from its header on */
    put_bytes(store, base, nbase);
    static const char *const heads[3] = {"edge,v0,v1,a,b\n", "edge,v0,v1,length\n",
                                         "term,df,ss,ms,r2,f,z,p,error\n"};
    const char *const cmds[3][10] = {
        {"mean", store, "--by", "grp", "--no-store", "-o", "-", NULL},
        {"point", store, "mean", "--output", "-", NULL},
        {"model", store, "~ grp", "--permutations", "9", "--no-store", "-o", "-", NULL}};
    for (int c = 0; c < 3; c++) {
        char out[256] = "";
        int rc = run(cmds[c], 0, err, sizeof err);
        es_test_read_small(o, out, sizeof out);
        ES_CHECK_MSG(rc == 0 && !strncmp(out, heads[c], strlen(heads[c])),
                     "%s -o -: exit %d, stdout starts '%.60s'", cmds[c][0], rc, out);
    }
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
    test_full_disk_statismo(base, nbase);
    test_full_disk_frames(base, nbase);
    test_provenance_quoting(ctx, base, nbase);
    test_hostile_inputs(base, nbase);
    test_kills(ctx, base, nbase);
    test_devices();
    test_misspelt();
    free(base);
    es_ctx_free(ctx);
    ES_TEST_END();
}
