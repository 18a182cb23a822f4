/* tools/bench/bench_store_result.c — what storing a small result costs in a
 * large store (issue 27: "storing a small result in a 1 GB store < 50 ms
 * with no extra GB of disk").
 *
 * Makes a truss store of about --mb megabytes (rows of E = 28,000 lengths and
 * their landmarks, appended in blocks; not timed), then stores --results
 * results of one E-vector each (a `point --name`: begin, put, commit) and
 * prints the time per result (median and worst), the store file's identity
 * before and after (a copy would change it), and the disk space the folder
 * lost (statvfs: other writers on that file system count too), next to the
 * results' own size. --legacy turns the store into format 2 first (as
 * earlier releases wrote it: results inside, every commit copies the
 * store; needs /usr/bin/python3 with h5py), for the comparison.
 *
 *   bench_store_result [--mb 1024] [--results 20] [--dir DIR] [--legacy]
 */
#include "edgespace/edgespace.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "bench_clock.h"

#define E 28000
#define NV (E + 1)
#define BLOCK 16

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double free_mb(const char *dir)
{
    struct statvfs v;
    return statvfs(dir, &v) == 0 ? (double)v.f_bavail * (double)v.f_frsize / 1048576.0 : NAN;
}

int main(int argc, char **argv)
{
    double mb = 1024;
    int nres = 20, legacy = 0;
    const char *dir = "/tmp";
    static const struct option lo[] = {{"mb", required_argument, 0, 'm'},
        {"results", required_argument, 0, 'r'}, {"dir", required_argument, 0, 'd'},
        {"legacy", no_argument, 0, 'l'}, {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        if (c == 'm') mb = atof(optarg);
        else if (c == 'r') nres = atoi(optarg);
        else if (c == 'd') dir = optarg;
        else if (c == 'l') legacy = 1;
        else {
            printf("usage: bench_store_result [--mb MB] [--results N] [--dir DIR] [--legacy]\n");
            return c == 'h' ? 0 : 2;
        }
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/bench_store_result-%ld.h5", dir, (long)getpid());
    es_ctx *ctx = NULL;
    es_store *s = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    /* rows: E lengths + NV x 3 positions = about 0.86 MB each */
    const int64_t rows = (int64_t)(mb * 1048576.0 / (8.0 * (E + 3.0 * NV))) + 1;
    int64_t *edges = malloc(sizeof *edges * 2 * E);
    double *xyz = malloc(sizeof *xyz * 3 * NV * BLOCK), *len = malloc(sizeof *len * E * BLOCK);
    double scale[BLOCK], *times = malloc(sizeof *times * (size_t)(nres > 0 ? nres : 1));
    char idbuf[BLOCK][32];
    const char *ids[BLOCK];
    for (int64_t e = 0; e < E; e++) edges[2 * e] = e, edges[2 * e + 1] = e + 1;
    if (es_store_create_edges(ctx, path, NV, E, edges, &s) != ES_OK) goto fail;
    for (int64_t r0 = 0; r0 < rows; r0 += BLOCK) {
        int n = rows - r0 < BLOCK ? (int)(rows - r0) : BLOCK;
        for (int j = 0; j < n; j++) {
            for (int64_t v = 0; v < NV; v++) {
                xyz[3 * NV * j + 3 * v] = (double)v;
                xyz[3 * NV * j + 3 * v + 1] = 0.001 * (double)((r0 + j + v) % 7);
                xyz[3 * NV * j + 3 * v + 2] = 0;
            }
            double sum = 0;
            for (int64_t e = 0; e < E; e++) {
                const double *a = xyz + 3 * NV * j + 3 * e, *b = a + 3;
                sum += len[E * j + e] = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]));
            }
            for (int64_t e = 0; e < E; e++) len[E * j + e] /= sum;
            scale[j] = sum;
            snprintf(idbuf[j], sizeof idbuf[j], "r%07lld", (long long)(r0 + j));
            ids[j] = idbuf[j];
        }
        es_store_rows rr = {n, ids, NULL, NULL, len, scale, xyz, 0, NULL, NULL};
        if (es_store_append(ctx, s, &rr) != ES_OK) goto fail;
    }
    if (es_store_commit(ctx, s) != ES_OK) goto fail;
    es_store_close(s);
    s = NULL;
    if (legacy) {
        /* format 2 (a truss store as an earlier release wrote it: results inside) */
        char cmd[8300];
        snprintf(cmd, sizeof cmd, "/usr/bin/python3 -c \"import h5py; f=h5py.File('%s','r+'); "
                 "f.attrs['format_version']=2; del f.attrs['store_id']; f.close()\"",
                 path);
        if (system(cmd) != 0) fprintf(stderr, "bench_store_result: cannot make it format 2 (h5py)\n");
    }
    struct stat st0, st1;
    stat(path, &st0);
    printf("bench_store_result: store of %lld rows x %d edges, %.0f MB, format %s\n",
           (long long)rows, E, (double)st0.st_size / 1048576.0, legacy ? "2 (results inside)" : "3");
    double free0 = free_mb(dir), bytes = 0;
    for (int i = 0; i < nres; i++) {
        char name[32], p[64];
        es_provenance prov = {"bench_store_result", NULL, -1, NULL};
        snprintf(name, sizeof name, "p%d", i);
        snprintf(p, sizeof p, "point/%s/lengths", name);
        double t = bench_wall_s();
        if (es_store_open(ctx, path, ES_STORE_WRITE, &s) != ES_OK ||
            es_store_result_begin(ctx, s, "point", name, &prov) != ES_OK ||
            es_store_put_vector(ctx, s, p, len, E) != ES_OK || es_store_commit(ctx, s) != ES_OK)
            goto fail;
        es_store_close(s);
        s = NULL;
        times[i] = bench_wall_s() - t;
        bytes += 8.0 * E;
    }
    stat(path, &st1);
    qsort(times, (size_t)nres, sizeof *times, cmp);
    printf("  %d results of %.0f KB: median %.1f ms, worst %.1f ms per stored result "
           "(open, begin, put, commit, close)\n", nres, 8.0 * E / 1024, 1e3 * times[nres / 2],
           1e3 * times[nres - 1]);
    printf("  store file %s; disk used by the writes %.1f MB (the results hold %.1f MB)\n",
           st0.st_ino == st1.st_ino && st0.st_mtime == st1.st_mtime ? "untouched (same inode, mtime)"
                                                                     : "replaced (copied)",
           free0 - free_mb(dir), bytes / 1048576.0);
    {
        char cmd[8300];
        snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s.results'", path, path);
        if (system(cmd) != 0) fprintf(stderr, "bench_store_result: cannot remove %s\n", path);
    }
    es_ctx_free(ctx);
    return 0;
fail:
    fprintf(stderr, "bench_store_result: %s\n", es_ctx_errmsg(ctx));
    es_store_abort(s);
    unlink(path);
    es_ctx_free(ctx);
    return 1;
}
