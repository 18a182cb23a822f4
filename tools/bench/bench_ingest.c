/* tools/bench/bench_ingest.c — how fast is ingest? Meshes per second, MB/s
 * of mesh files parsed, peak memory, and where the time goes.
 *
 *   bench_ingest [MANIFEST] [--repeat N] [--threads T] [--dir DIR]
 *
 * MANIFEST defaults to ../shared/data/face-study/manifest.csv (90 meshes,
 * 9,409 vertices, 27,871 edges each). Each repeat runs one whole ingest
 * (es_ingest_manifest into a new store) in a child process, so that its wall
 * time, CPU time and peak RSS (wait4) are its own. Then one pass times the
 * phases separately through the public API, in CPU time of the thread:
 * read + hash, parse, edge lengths, store write + commit (fsync waits are
 * not CPU time). Timings are figures, never pass/fail.
 */
#include <edgespace/edgespace.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_clock.h"

#ifndef ES_SHARED_DIR
#define ES_SHARED_DIR "../shared"
#endif

static double tv(struct timeval t) { return (double)t.tv_sec + 1e-6 * (double)t.tv_usec; }

static void die(es_ctx *ctx, es_status rc, const char *what)
{
    fprintf(stderr, "bench_ingest: %s: %s\n", what, ctx ? es_ctx_errmsg(ctx) : es_strerror(rc));
    exit(1);
}

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    struct stat st;
    char *buf;
    if (!f || fstat(fileno(f), &st) != 0) {
        perror(path);
        exit(1);
    }
    buf = malloc((size_t)st.st_size + 1);
    *n = fread(buf, 1, (size_t)st.st_size, f);
    fclose(f);
    return buf;
}

int main(int argc, char **argv)
{
    const char *manifest = ES_SHARED_DIR "/data/face-study/manifest.csv", *dir = NULL;
    char store[4300], tmpl[4200];
    int repeat = 5, threads = 0;
    es_ctx *ctx;
    es_manifest *m = NULL;
    es_status rc;
    double total_bytes = 0, *wall, *cpu, maxrss = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--dir") && i + 1 < argc) dir = argv[++i];
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc) threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--help")) {
            puts("usage: bench_ingest [MANIFEST] [--repeat N] [--threads T] [--dir DIR]");
            return 0;
        } else manifest = argv[i];
    }
    if (repeat < 1) repeat = 1;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    if (!dir) {
        snprintf(tmpl, sizeof tmpl, "%s/bench-ingest-XXXXXX",
                 getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
        if (!mkdtemp(tmpl)) {
            perror("mkdtemp");
            return 1;
        }
        dir = tmpl;
    }
    snprintf(store, sizeof store, "%s/bench.h5", dir);
    if ((rc = es_manifest_read(ctx, manifest, &m))) die(ctx, rc, "manifest");
    for (int64_t r = 0; r < m->nrows; r++) {
        char p[8400];
        struct stat st;
        snprintf(p, sizeof p, "%s/%s", m->dir, m->cells[r * m->ncols + m->file_col]);
        if (stat(p, &st) == 0) total_bytes += (double)st.st_size;
    }
    printf("manifest   %s\nmeshes     %lld, %.1f MB of mesh files\n", manifest,
           (long long)m->nrows, total_bytes / 1e6);

    /* ---- whole ingests, each in its own process ---- */
    wall = calloc((size_t)repeat, sizeof *wall);
    cpu = calloc((size_t)repeat, sizeof *cpu);
    for (int k = 0; k < repeat; k++) {
        struct rusage ru;
        int status;
        double t0;
        pid_t pid;
        unlink(store);
        t0 = bench_wall_s();
        if ((pid = fork()) == 0) {
            es_ingest_report rep;
            es_ingest_opts o;
            es_ctx *c2;
            es_ingest_opts_init(&o);
            o.threads = threads;
            if (es_ctx_new(&c2) != ES_OK) _exit(1);
            if ((rc = es_ingest_manifest(c2, store, manifest, &o, &rep))) die(c2, rc, "ingest");
            _exit(rep.rows_added == m->nrows ? 0 : 1);
        }
        if (wait4(pid, &status, 0, &ru) < 0 || !WIFEXITED(status) || WEXITSTATUS(status)) {
            fprintf(stderr, "bench_ingest: ingest failed\n");
            return 1;
        }
        wall[k] = bench_wall_s() - t0;
        cpu[k] = tv(ru.ru_utime) + tv(ru.ru_stime);
        if ((double)ru.ru_maxrss > maxrss) maxrss = (double)ru.ru_maxrss;
    }
    bench_sort(wall, repeat);
    bench_sort(cpu, repeat);
    {
        struct stat st;
        stat(store, &st);
        printf("store      %.1f MB\n", (double)st.st_size / 1e6);
    }
    printf("ingest     threads %d (0: one per CPU, here %ld); best %.3f s, median %.3f s wall "
           "(%d runs); CPU (user+sys) best %.3f s\n", threads, sysconf(_SC_NPROCESSORS_ONLN),
           wall[0], wall[repeat / 2], repeat, cpu[0]);
    printf("rate       %.1f meshes/s, %.1f MB/s of mesh files (best wall)\n",
           (double)m->nrows / wall[0], total_bytes / 1e6 / wall[0]);
    printf("rate/CPU   %.1f meshes/s, %.1f MB/s per CPU second\n", (double)m->nrows / cpu[0],
           total_bytes / 1e6 / cpu[0]);
    printf("peak RSS   %.1f MB (one ingest process)\n", maxrss / 1024.0);

    /* ---- phases, one pass ---- */
    {
        double t_read = 0, t_parse = 0, t_len = 0, t_write = 0, t;
        int64_t N = m->nrows, E = 0, V = 0;
        double *len = NULL, *xyz = NULL, *scale = calloc((size_t)N, sizeof *scale);
        es_mesh *mesh = NULL;
        es_store *s = NULL;
        for (int64_t r = 0; r < N; r++) {
            char p[8400], hash[25];
            size_t n;
            char *buf;
            es_meshdata md;
            snprintf(p, sizeof p, "%s/%s", m->dir, m->cells[r * m->ncols + m->file_col]);
            t = bench_thread_cpu_s();
            buf = slurp(p, &n);
            es_content_hash(buf, n, hash);
            t_read += bench_thread_cpu_s() - t;
            t = bench_thread_cpu_s();
            if ((rc = es_meshdata_parse(ctx, p, buf, n, ES_FORMAT_AUTO, &md))) die(ctx, rc, p);
            t_parse += bench_thread_cpu_s() - t;
            free(buf);
            t = bench_thread_cpu_s();
            if (!mesh) {
                if ((rc = es_mesh_new(ctx, md.nverts, md.nfaces, md.faces, NULL, &mesh)))
                    die(ctx, rc, "mesh");
                E = es_mesh_nedges(mesh);
                V = md.nverts;
                len = malloc((size_t)(E * N) * sizeof *len);
                xyz = malloc((size_t)(3 * V * N) * sizeof *xyz);
            }
            if ((rc = es_edge_lengths(ctx, mesh, md.xyz, len + r * E)) ||
                (rc = es_lengths_normalize(ctx, E, len + r * E, len + r * E, &scale[r])))
                die(ctx, rc, "lengths");
            memcpy(xyz + r * 3 * V, md.xyz, (size_t)(3 * V) * sizeof *xyz);
            t_len += bench_thread_cpu_s() - t;
            es_meshdata_clear(ctx, &md);
        }
        {
            const char **ids = calloc((size_t)N, sizeof *ids);
            es_store_rows rows = {N, NULL, NULL, NULL, len, scale, xyz, 0, NULL, NULL};
            for (int64_t r = 0; r < N; r++) ids[r] = m->ids[r];
            rows.ids = ids;
            unlink(store);
            t = bench_thread_cpu_s();
            if ((rc = es_store_create(ctx, store, mesh, &s)) ||
                (rc = es_store_append(ctx, s, &rows)) || (rc = es_store_commit(ctx, s)))
                die(ctx, rc, "store");
            es_store_close(s);
            t_write = bench_thread_cpu_s() - t;
            free(ids);
        }
        printf("phases CPU read+hash %.3f s, parse %.3f s (%.1f MB/s), lengths %.3f s, "
               "store write+commit %.3f s\n", t_read, t_parse, total_bytes / 1e6 / t_parse,
               t_len, t_write);
        {
            /* reading back: all rows in one block, and row by row */
            es_mat out = {len, E, N, E};
            t = bench_thread_cpu_s();
            if (es_store_open(ctx, store, ES_STORE_READ, &s)) die(ctx, ES_EIO, "open");
            printf("read CPU   open %.3f s; ", bench_thread_cpu_s() - t);
            t = bench_thread_cpu_s();
            if (es_store_read_lengths(ctx, s, 0, N, out)) die(ctx, ES_EIO, "read back");
            printf("all %lld rows of lengths in one block: %.3f s", (long long)N, bench_thread_cpu_s() - t);
            t = bench_thread_cpu_s();
            for (int64_t r = 0; r < N; r++) {
                es_mat one = {len + r * E, E, 1, E};
                if (es_store_read_lengths(ctx, s, r, 1, one)) die(ctx, ES_EIO, "read row");
            }
            printf("; row by row: %.3f s\n", bench_thread_cpu_s() - t);
            es_store_close(s);
        }
        es_mesh_free(mesh);
        free(len);
        free(xyz);
        free(scale);
    }
    unlink(store);
    if (dir == tmpl) rmdir(tmpl);
    es_manifest_free(ctx, m);
    es_ctx_free(ctx);
    free(wall);
    free(cpu);
    return 0;
}
