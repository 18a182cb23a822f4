/* tests/parallel/test_parallel_ingest.c — `mpirun -n P edgespace ingest`
 * (the -Dmpi=enabled build) makes the store one process makes, at P = 2
 * and 4, and keeps its all-or-nothing promise.
 *
 * The oracle is the one-process ingest of the same manifest (es_ingest_manifest
 * on a context that is not joined to a job; tests/ingest checks it against
 * independently computed lengths). The stores are compared dataset for
 * dataset: ids, source paths, content hashes, every label column, faces,
 * lengths, scales and positions, bit for bit (each row is measured by the
 * same code, only on another rank); the store_id and creation time of two
 * stores always differ. Cases: a new store (P = 4 in blocks of 2 rows, so
 * the ranks write in several collective rounds, and 11 rows do not split
 * evenly); rows appended to a store with a new label column, three inputs
 * already in it (skipped: the rows after them move up); 24 meshes of 10,000
 * vertices appended in rounds of one row a rank (new chunks in a store that
 * has some: what parallel HDF5 got wrong when the ranks allocated them); a
 * warning on the last rank, said once by rank 0; a corrupt mesh file
 * in the last rank's share (every rank fails with its file and line; the
 * store is byte for byte as it was, and a new store is not made); and a
 * rank killed with SIGKILL while the ranks read and write (mpirun ends the
 * job; the store is as it was or, had the commit come first, complete).
 *
 * Usage: test_parallel_ingest MPIRUN (meson passes the mpirun it found). */
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "es_test_run.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *mpirun, *dir;

/* `mpirun -n P edgespace ingest STORE --manifest M [extra]`: its exit status, stderr into err. */
static int run_ingest(int P, const char *store, const char *manifest, const char *extra,
                      char *err, size_t n)
{
    char cmd[4096], errfile[900];
    snprintf(errfile, sizeof errfile, "%s/mpi.err", dir);
    snprintf(cmd, sizeof cmd, "'%s' -n %d --oversubscribe --allow-run-as-root '%s' ingest '%s' "
             "--manifest '%s' %s >'%s/mpi.out' 2>'%s'", mpirun, P, es_test_edgespace(), store,
             manifest, extra, dir, errfile);
    int st = system(cmd);
    es_test_read_small(errfile, err, n);
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128;
}

static int same_str(const char *a, const char *b) { return a && b && !strcmp(a, b); }

/* The stores at a and b hold the same rows, labels, topology and values. */
static void same_store(es_ctx *ctx, const char *a, const char *b)
{
    es_store *sa = NULL, *sb = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, a, ES_STORE_READ, &sa));
    ES_CHECK_OK(ctx, es_store_open(ctx, b, ES_STORE_READ, &sb));
    if (!sa || !sb) goto done;
    const int64_t N = es_store_nrows(sa), E = es_store_nedges(sa), V = es_store_nverts(sa);
    const int64_t F = es_store_nfaces(sa), C = es_store_ncolumns(sa);
    ES_CHECK_MSG(N == es_store_nrows(sb) && E == es_store_nedges(sb) && V == es_store_nverts(sb) &&
                 F == es_store_nfaces(sb) && C == es_store_ncolumns(sb), "%s vs %s: %lld vs %lld "
                 "rows, %lld vs %lld columns", a, b, (long long)N, (long long)es_store_nrows(sb),
                 (long long)C, (long long)es_store_ncolumns(sb));
    if (N != es_store_nrows(sb) || E != es_store_nedges(sb) || V != es_store_nverts(sb) ||
        F != es_store_nfaces(sb) || C != es_store_ncolumns(sb))
        goto done;
    for (int64_t i = 0; i < N; i++) {
        ES_CHECK_MSG(same_str(es_store_row_id(sa, i), es_store_row_id(sb, i)) &&
                     same_str(es_store_source_path(sa, i), es_store_source_path(sb, i)) &&
                     same_str(es_store_content_hash(sa, i), es_store_content_hash(sb, i)),
                     "%s vs %s: row %lld is '%s' vs '%s'", a, b, (long long)i,
                     es_store_row_id(sa, i), es_store_row_id(sb, i));
        for (int64_t c = 0; c < C; c++)
            ES_CHECK_MSG(same_str(es_store_column_name(sa, c), es_store_column_name(sb, c)) &&
                         same_str(es_store_label(sa, i, c), es_store_label(sb, i, c)),
                         "%s vs %s: row %lld column %lld differs", a, b, (long long)i,
                         (long long)c);
    }
    double *la = malloc((size_t)(E * N + N + 6 * V) * sizeof *la);
    double *lb = malloc((size_t)(E * N + N + 6 * V) * sizeof *lb);
    int64_t *fa = malloc((size_t)(6 * F + 1) * sizeof *fa);
    ES_CHECK_OK(ctx, es_store_read_lengths(ctx, sa, 0, N, (es_mat){la, E, N, E}));
    ES_CHECK_OK(ctx, es_store_read_lengths(ctx, sb, 0, N, (es_mat){lb, E, N, E}));
    ES_CHECK_MSG(!memcmp(la, lb, (size_t)(E * N) * sizeof *la), "%s vs %s: lengths differ", a, b);
    ES_CHECK_OK(ctx, es_store_read_scales(ctx, sa, la));
    ES_CHECK_OK(ctx, es_store_read_scales(ctx, sb, lb));
    ES_CHECK_MSG(!memcmp(la, lb, (size_t)N * sizeof *la), "%s vs %s: scales differ", a, b);
    for (int64_t i = 0; i < N; i++) {
        ES_CHECK_OK(ctx, es_store_read_positions(ctx, sa, i, la));
        ES_CHECK_OK(ctx, es_store_read_positions(ctx, sb, i, lb));
        ES_CHECK_MSG(!memcmp(la, lb, (size_t)(3 * V) * sizeof *la), "%s vs %s: positions of row "
                     "%lld differ", a, b, (long long)i);
    }
    ES_CHECK_OK(ctx, es_store_read_faces(ctx, sa, fa));
    ES_CHECK_OK(ctx, es_store_read_faces(ctx, sb, fa + 3 * F));
    ES_CHECK_MSG(!memcmp(fa, fa + 3 * F, (size_t)(3 * F) * sizeof *fa), "%s vs %s: faces", a, b);
    free(la);
    free(lb);
    free(fa);
done:
    es_store_close(sa);
    es_store_close(sb);
}

static void copy_file(const char *from, const char *to)
{
    size_t n = 0;
    char *buf = es_test_slurp(from, &n);
    FILE *f = fopen(to, "wb");
    ES_CHECK(buf && f && fwrite(buf, 1, n, f) == n);
    if (f) fclose(f);
    free(buf);
}

/* A manifest of tori: name%d.obj for k in [k0, k1), ids idpfx%d, a label. */
static void write_manifest(const char *path, const char *name, int k0, int k1, const char *idpfx,
                           int nu, int nv, const char *col)
{
    char p[900];
    FILE *f = fopen(path, "w");
    ES_CHECK(f != NULL);
    if (!f) return;
    fprintf(f, "file,id,%s\n", col);
    for (int k = k0; k < k1; k++) {
        snprintf(p, sizeof p, "%s/%s%d.obj", dir, name, k);
        if (access(p, F_OK) != 0) ES_CHECK(es_test_write_torus(p, nu, nv, k) == 0);
        fprintf(f, "%s%d.obj,%s%d,%c\n", name, k, idpfx, k, "abc"[k % 3]);
    }
    fclose(f);
}

/* The ranks of an mpirun (its children running edgespace); up to n. */
static int ranks_of(pid_t mpirun_pid, pid_t *out, int n)
{
    DIR *d = opendir("/proc");
    struct dirent *e;
    int k = 0;
    while (d && (e = readdir(d)) && k < n) {
        char path[300], buf[512], comm[64];
        int pid, ppid;
        snprintf(path, sizeof path, "/proc/%s/stat", e->d_name);
        FILE *f = fopen(path, "r");
        if (!f) continue;
        if (fgets(buf, sizeof buf, f) && sscanf(buf, "%d (%63[^)]) %*c %d", &pid, comm, &ppid) == 3 &&
            ppid == mpirun_pid && !strcmp(comm, "edgespace"))
            out[k++] = pid;
        fclose(f);
    }
    if (d) closedir(d);
    return k;
}

int main(int argc, char **argv)
{
    ES_TEST_BEGIN();
    if (argc < 2) ES_TEST_SKIP("give the mpirun to use");
    mpirun = argv[1];
    es_ctx *ctx = NULL;
    char m[900], m2[900], m3[900], err[65536], s0[900], sp[900], a0[900], ap[900];
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    dir = es_test_tmpdir("parallel-ingest");

    /* a new store: one process, then the ranks */
    snprintf(m, sizeof m, "%s/m.csv", dir);
    write_manifest(m, "t", 0, 11, "t", 14, 8, "grp");
    snprintf(s0, sizeof s0, "%s/serial.h5", dir);
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, s0, m, NULL, NULL));
    /* append: three inputs the store has (skipped), eight new, a new label column */
    snprintf(m2, sizeof m2, "%s/m2.csv", dir);
    write_manifest(m2, "u", 0, 8, "u", 14, 8, "side");
    {
        size_t n = 0;
        char *text = es_test_slurp(m2, &n), *body = text ? strchr(text, '\n') : NULL;
        FILE *f = fopen(m2, "w");
        ES_CHECK(body && f);
        if (f && body) {
            fprintf(f, "file,id,side\nt1.obj,t1,b\nt4.obj,t4,b\n%st9.obj,t9,a\n", body + 1);
            fclose(f);
        }
        free(text);
    }
    snprintf(a0, sizeof a0, "%s/append_serial.h5", dir);
    copy_file(s0, a0);
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, a0, m2, NULL, NULL));
    for (int P = 2; P <= 4; P += 2) {
        snprintf(sp, sizeof sp, "%s/np%d.h5", dir, P);
        ES_CHECK_MSG(run_ingest(P, sp, m, P == 4 ? "--block-rows 2" : "", err, sizeof err) == 0,
                     "mpirun -n %d ingest: %s", P, err);
        same_store(ctx, s0, sp);
        snprintf(ap, sizeof ap, "%s/append_np%d.h5", dir, P);
        copy_file(s0, ap);
        ES_CHECK_MSG(run_ingest(P, ap, m2, "--block-rows 3", err, sizeof err) == 0,
                     "mpirun -n %d ingest (append): %s", P, err);
        size_t no = 0;
        char out[900], *text;
        snprintf(out, sizeof out, "%s/mpi.out", dir);
        text = es_test_slurp(out, &no);
        ES_CHECK_MSG(text && strstr(text, "8 added, 3 skipped"), "append at P = %d: %s", P,
                     text ? text : "(no output)");
        free(text);
        same_store(ctx, a0, ap);
    }

    /* a warning on the last rank (a mesh with two vertices in one place) is said by rank 0 */
    {
        enum { NU = 14, NV = 8 };
        double xyz[3 * NU * NV];
        int64_t faces[6 * NU * NV];
        char z[900], mz[900], sz[900];
        es_test_torus(NU, NV, 5, xyz, faces);
        memcpy(xyz + 3, xyz, 3 * sizeof *xyz);
        snprintf(z, sizeof z, "%s/z.obj", dir);
        ES_CHECK(es_test_write_obj(z, NU * NV, xyz, 2 * NU * NV, faces) == 0);
        snprintf(mz, sizeof mz, "%s/mz.csv", dir);
        es_test_write_file(mz, "file\nt0.obj\nt1.obj\nt2.obj\nz.obj\n");
        snprintf(sz, sizeof sz, "%s/warned.h5", dir);
        ES_CHECK_MSG(run_ingest(2, sz, mz, "", err, sizeof err) == 0, "mpirun -n 2 ingest: %s",
                     err);
        char *w = strstr(err, "z.obj': 1 edge of length 0");
        ES_CHECK_MSG(w && !strstr(w + 1, "z.obj': 1 edge of length 0"), "the last rank's "
                     "warning is not said once: %s", err);
    }

    /* a corrupt mesh in the last rank's share: every rank fails, the store is unchanged */
    snprintf(m3, sizeof m3, "%s/m3.csv", dir);
    write_manifest(m3, "v", 0, 9, "v", 14, 8, "grp");
    {
        char bad[900];
        snprintf(bad, sizeof bad, "%s/v8.obj", dir);
        FILE *f = fopen(bad, "a");
        ES_CHECK(f != NULL);
        if (f) {
            fprintf(f, "v 1.0 nonsense 2.0\n");
            fclose(f);
        }
    }
    for (int P = 2; P <= 4; P += 2) {
        size_t nbase = 0;
        snprintf(sp, sizeof sp, "%s/np%d.h5", dir, P);
        char *base = es_test_slurp(sp, &nbase);
        ES_CHECK_MSG(run_ingest(P, sp, m3, "--block-rows 2", err, sizeof err) != 0 &&
                     strstr(err, "v8.obj:") && strstr(err, "nonsense"),
                     "mpirun -n %d ingest of a corrupt mesh: %s", P, err);
        char *first = strstr(err, "v8.obj:");
        ES_CHECK_MSG(first && !strstr(first + 1, "v8.obj:"), "the error is not said once: %s",
                     err);
        ES_CHECK_MSG(base && es_test_same_bytes(sp, base, nbase), "np%d.h5 changed", P);
        ES_CHECK_MSG(es_test_count_entries(dir, ".tmp-") == 0, "a working copy was left");
        free(base);
        snprintf(sp, sizeof sp, "%s/new_np%d.h5", dir, P);
        ES_CHECK(run_ingest(P, sp, m3, "", err, sizeof err) != 0 && access(sp, F_OK) != 0);
    }

    /* a rank killed while the ranks read and write: the store as it was, or complete */
    {
        char mk[900], target[900], cmd[4096];
        snprintf(mk, sizeof mk, "%s/mk0.csv", dir);
        write_manifest(mk, "big", 0, 2, "big", 100, 100, "grp");
        snprintf(target, sizeof target, "%s/big.h5", dir);
        ES_CHECK_OK(ctx, es_ingest_manifest(ctx, target, mk, NULL, NULL));
        snprintf(mk, sizeof mk, "%s/mk.csv", dir);
        write_manifest(mk, "big", 2, 26, "big", 100, 100, "grp");
        /* first a whole run: 10,000-vertex rows fill new chunks of a store
         * that has some (rank 0 allocates them before the ranks write) */
        {
            char bs[900], bp[900];
            snprintf(bs, sizeof bs, "%s/big_serial.h5", dir);
            snprintf(bp, sizeof bp, "%s/big_np4.h5", dir);
            copy_file(target, bs);
            copy_file(target, bp);
            ES_CHECK_OK(ctx, es_ingest_manifest(ctx, bs, mk, NULL, NULL));
            ES_CHECK_MSG(run_ingest(4, bp, mk, "--block-rows 1", err, sizeof err) == 0,
                         "mpirun -n 4 ingest of 10,000-vertex meshes: %s", err);
            same_store(ctx, bs, bp);
        }
        size_t nbase = 0;
        char *base = es_test_slurp(target, &nbase);
        int killed = 0, during_write = 0;
        static const double after[] = {0.1, 0.3, 0.6, 1.0};
        for (size_t t = 0; t < sizeof after / sizeof after[0]; t++) {
            snprintf(cmd, sizeof cmd, "exec '%s' -n 4 --oversubscribe --allow-run-as-root '%s' "
                     "ingest '%s' --manifest '%s' --block-rows 1 >'%s/kill.out' 2>&1", mpirun,
                     es_test_edgespace(), target, mk, dir);
            pid_t pid = fork();
            if (pid == 0) {
                execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
                _exit(127);
            }
            pid_t r[4];
            int nr = 0;
            double t0 = es_test_now();
            while ((nr = ranks_of(pid, r, 4)) < 4 && es_test_now() - t0 < 20) es_test_sleep(0.01);
            es_test_sleep(after[t]);
            if (nr == 4 && kill(r[3], SIGKILL) == 0) killed++;
            int st = es_test_wait(pid);
            int64_t rows = -1;
            es_store *s = NULL;
            if (es_store_open(ctx, target, ES_STORE_READ, &s) == ES_OK) {
                rows = es_store_nrows(s);
                es_store_close(s);
            }
            ES_CHECK_MSG(rows == 2 || rows == 26, "killed after %.2f s: %lld rows", after[t],
                         (long long)rows);
            if (rows == 2)
                ES_CHECK_MSG(base && es_test_same_bytes(target, base, nbase), "killed after "
                             "%.2f s (exit %d): the store changed", after[t], st);
            if (es_test_count_entries(dir, ".tmp-") > 0) during_write++;
            if (rows != 2 && base) {   /* the commit came first: back for the next kill */
                FILE *f = fopen(target, "wb");
                ES_CHECK(f && fwrite(base, 1, nbase, f) == nbase);
                if (f) fclose(f);
            }
        }
        ES_CHECK_MSG(killed > 0, "no rank was killed");
        fprintf(stderr, "%d kills of a rank left the store unchanged or complete (%d while rank "
                "0's working copy was being written)\n", killed, during_write);
        free(base);
    }
    es_ctx_free(ctx);
    ES_TEST_END();
}
