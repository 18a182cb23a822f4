/* tools/bench/bench_parse.c — OBJ parsing throughput: es_meshdata_parse
 * against a plain strtod/strtol line parser over the same bytes, plus
 * es_meshdata_read (file reading included) and peak RSS.
 *
 *   bench_parse [FILE.obj | DIR] ...   (default: ../shared/data/face-study,
 *                                       or a generated 30 MB OBJ without it)
 *
 * Files are loaded once; each pass parses all of them and the best of
 * several passes is reported, so the figures are parse speed, not disk.
 */
#include "edgespace/edgespace.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench_clock.h"

typedef struct file { char *path, *buf; size_t len; } file;

static int add_file(file **fs, int *n, const char *path)
{
    FILE *f = fopen(path, "rb");
    long len;
    if (!f) return -1;
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    rewind(f);
    *fs = realloc(*fs, (size_t)(*n + 1) * sizeof **fs);
    file *x = &(*fs)[(*n)++];
    x->path = strdup(path);
    x->buf = malloc((size_t)len + 1);
    x->len = fread(x->buf, 1, (size_t)len, f);
    x->buf[x->len] = '\0';
    fclose(f);
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void add_path(file **fs, int *n, const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return;
    if (!S_ISDIR(st.st_mode)) {
        add_file(fs, n, path);
        return;
    }
    DIR *d = opendir(path);
    struct dirent *e;
    char *names[4096];
    int k = 0;
    while (d && (e = readdir(d)) && k < 4096) {
        const char *dot = strrchr(e->d_name, '.');
        if (dot && !strcmp(dot, ".obj")) names[k++] = strdup(e->d_name);
    }
    if (d) closedir(d);
    qsort(names, (size_t)k, sizeof *names, cmp_str);
    for (int i = 0; i < k; i++) {
        char p[8192];
        snprintf(p, sizeof p, "%s/%s", path, names[i]);
        add_file(fs, n, p);
        free(names[i]);
    }
}

/* A grid surface with face-study-like coordinates ("%.6f"). */
static void generate(file **fs, int *n)
{
    const int m = 580;   /* 336,400 vertices, 669,918 triangles, ~30 MB */
    size_t cap = (size_t)m * m * 80, len = 0;
    char *b = malloc(cap);
    srand(1);
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++)
            len += (size_t)snprintf(b + len, cap - len, "v %.6f %.6f %.6f\n", i * 0.05 - 14.5,
                                    j * 0.05 - 14.5, 3 * sin(i * 0.1) * cos(j * 0.07) +
                                    (rand() / (double)RAND_MAX - 0.5) * 0.01);
    for (int i = 0; i + 1 < m; i++)
        for (int j = 0; j + 1 < m; j++) {
            int a = i * m + j + 1, c = a + m;
            len += (size_t)snprintf(b + len, cap - len, "f %d %d %d\nf %d %d %d\n", a, c, a + 1,
                                    a + 1, c, c + 1);
        }
    *fs = realloc(*fs, (size_t)(*n + 1) * sizeof **fs);
    (*fs)[*n].path = strdup("generated.obj");
    (*fs)[*n].buf = b;
    (*fs)[*n].len = len;
    (*n)++;
}

/* The straightforward reader: one line at a time, strtod and strtol. */
static void naive_parse(const char *buf, size_t len, es_meshdata *md)
{
    int64_t vcap = 4096, fcap = 8192;
    const char *p = buf, *end = buf + len;
    memset(md, 0, sizeof *md);
    md->xyz = malloc((size_t)vcap * 3 * sizeof(double));
    md->faces = malloc((size_t)fcap * 3 * sizeof(int64_t));
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        char *q = (char *)p + 2;
        if (!nl) nl = end;
        if (p[0] == 'v' && p[1] == ' ') {
            if (md->nverts == vcap)
                md->xyz = realloc(md->xyz, (size_t)(vcap *= 2) * 3 * sizeof(double));
            for (int k = 0; k < 3; k++) md->xyz[3 * md->nverts + k] = strtod(q, &q);
            md->nverts++;
        } else if (p[0] == 'f' && p[1] == ' ') {
            if (md->nfaces == fcap)
                md->faces = realloc(md->faces, (size_t)(fcap *= 2) * 3 * sizeof(int64_t));
            for (int k = 0; k < 3; k++) md->faces[3 * md->nfaces + k] = strtol(q, &q, 10) - 1;
            md->nfaces++;
        }
        p = nl + 1;
    }
}

int main(int argc, char **argv)
{
    file *fs = NULL;
    int n = 0, passes = 5;
    size_t total = 0;
    es_ctx *ctx;
    double best_fast = 1e30, best_naive = 1e30, best_read = 1e30, best_fast_wall = 1e30;
    int64_t verts = 0, mismatches = 0;

    for (int i = 1; i < argc; i++) add_path(&fs, &n, argv[i]);
    if (argc == 1) add_path(&fs, &n, ES_SOURCE_ROOT "/../shared/data/face-study");
    if (n == 0) {
        fprintf(stderr, "bench_parse: no OBJ files found; using a generated mesh\n");
        generate(&fs, &n);
    }
    for (int i = 0; i < n; i++) total += fs[i].len;
    if (es_ctx_new(&ctx) != ES_OK) return 1;

    for (int pass = 0; pass < passes; pass++) {
        double w0 = bench_wall_s(), t0 = bench_process_cpu_s();
        for (int i = 0; i < n; i++) {
            es_meshdata md;
            if (es_meshdata_parse(ctx, fs[i].path, fs[i].buf, fs[i].len, ES_FORMAT_OBJ, &md)) {
                fprintf(stderr, "bench_parse: %s\n", es_ctx_errmsg(ctx));
                return 1;
            }
            if (pass == 0) verts += md.nverts;
            es_meshdata_clear(ctx, &md);
        }
        double t1 = bench_process_cpu_s();
        if (bench_wall_s() - w0 < best_fast_wall) best_fast_wall = bench_wall_s() - w0;
        for (int i = 0; i < n; i++) {
            es_meshdata md;
            naive_parse(fs[i].buf, fs[i].len, &md);
            free(md.xyz);
            free(md.faces);
        }
        double t2 = bench_process_cpu_s();
        if (fs[0].path[0] != 'g' || strcmp(fs[0].path, "generated.obj")) {
            for (int i = 0; i < n; i++) {
                es_meshdata md;
                if (es_meshdata_read(ctx, fs[i].path, ES_FORMAT_OBJ, &md)) return 1;
                es_meshdata_clear(ctx, &md);
            }
        }
        double t3 = bench_process_cpu_s();
        if (t1 - t0 < best_fast) best_fast = t1 - t0;
        if (t2 - t1 < best_naive) best_naive = t2 - t1;
        if (t3 - t2 < best_read) best_read = t3 - t2;
    }
    /* the two readers agree bit for bit */
    for (int i = 0; i < n; i++) {
        es_meshdata a, b;
        es_meshdata_parse(ctx, fs[i].path, fs[i].buf, fs[i].len, ES_FORMAT_OBJ, &a);
        naive_parse(fs[i].buf, fs[i].len, &b);
        if (a.nverts != b.nverts || a.nfaces != b.nfaces ||
            memcmp(a.xyz, b.xyz, (size_t)a.nverts * 24) ||
            memcmp(a.faces, b.faces, (size_t)a.nfaces * 24))
            mismatches++;
        es_meshdata_clear(ctx, &a);
        free(b.xyz);
        free(b.faces);
    }

    /* the other formats, on the first mesh written by es_meshio_write */
    static const struct { const char *ext; es_mesh_format fmt; } other[] = {
        {"ply", ES_FORMAT_PLY}, {"ply", ES_FORMAT_PLY_ASCII}, {"off", ES_FORMAT_OFF},
        {"obj", ES_FORMAT_OBJ}};
    double other_mbs[4] = {0}, other_ms[4] = {0};
    {
        es_meshdata md;
        es_mesh *mesh = NULL;
        if (es_meshdata_parse(ctx, fs[0].path, fs[0].buf, fs[0].len, ES_FORMAT_OBJ, &md) ||
            es_mesh_new(ctx, md.nverts, md.nfaces, md.faces, md.xyz, &mesh)) {
            fprintf(stderr, "bench_parse: %s\n", es_ctx_errmsg(ctx));
            return 1;
        }
        for (int k = 0; k < 4; k++) {
            char tmp[64];
            file *x = NULL;
            int nx = 0, reps = 20;
            snprintf(tmp, sizeof tmp, "/tmp/bench_parse_%d.%s", (int)getpid(), other[k].ext);
            if (es_meshio_write(ctx, tmp, other[k].fmt, mesh, md.xyz, NULL) ||
                add_file(&x, &nx, tmp))
                return 1;
            remove(tmp);
            double best = 1e30;
            for (int pass = 0; pass < passes; pass++) {
                double t0 = bench_process_cpu_s();
                for (int r = 0; r < reps; r++) {
                    es_meshdata m2;
                    if (es_meshdata_parse(ctx, tmp, x->buf, x->len, ES_FORMAT_AUTO, &m2))
                        return 1;
                    es_meshdata_clear(ctx, &m2);
                }
                if (bench_process_cpu_s() - t0 < best) best = bench_process_cpu_s() - t0;
            }
            other_mbs[k] = reps * (double)x->len / 1e6 / best;
            other_ms[k] = reps / best;
            free(x->path);
            free(x->buf);
            free(x);
        }
        es_mesh_free(mesh);
        es_meshdata_clear(ctx, &md);
    }

    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double mb = (double)total / 1e6;
    printf("input: %d OBJ file%s, %.1f MB, %lld vertices (best of %d passes, in memory, "
           "CPU time of one thread)\n", n, n == 1 ? "" : "s", mb, (long long)verts, passes);
    printf("es_meshdata_parse : %8.1f MB/s  %8.1f meshes/s  (%.3f s)\n", mb / best_fast,
           n / best_fast, best_fast);
    printf("naive strtod parse: %8.1f MB/s  %8.1f meshes/s  (%.3f s)\n", mb / best_naive,
           n / best_naive, best_naive);
    printf("speed-up          : %8.2fx\n", best_naive / best_fast);
    printf("es_meshdata_parse : %8.1f MB/s  wall clock\n", mb / best_fast_wall);
    if (best_read > 1e-9 && strcmp(fs[0].path, "generated.obj"))
        printf("es_meshdata_read  : %8.1f MB/s  %8.1f meshes/s  (file reading included)\n",
               mb / best_read, n / best_read);
    printf("results identical : %s\n", mismatches ? "NO" : "yes");
    for (int k = 0; k < 4; k++)
        printf("%-18s: %8.1f MB/s  %8.1f meshes/s  (first mesh as written by "
               "es_meshio_write)\n", k == 0 ? "PLY binary LE" : k == 1 ? "PLY ascii" :
               k == 2 ? "OFF" : "OBJ (%.17g)", other_mbs[k], other_ms[k]);
    printf("peak RSS          : %.1f MB (inputs held in memory: %.1f MB)\n",
           (double)ru.ru_maxrss / 1024.0, mb);
    es_ctx_free(ctx);
    for (int i = 0; i < n; i++) {
        free(fs[i].path);
        free(fs[i].buf);
    }
    free(fs);
    return mismatches ? 1 : 0;
}
