/* tools/bench/bench_points.c — embedding at interactive speed, measured as a
 * user meets it (issue 23): a store of one data set's meshes (optionally
 * subdivided `levels` times, which keeps them in correspondence), then
 *   - the session's making: without the cache, writing it, reading it;
 *   - the points a study looks at (the mean, mean -/+ 2 sd on PCs 1-3, an
 *     interpolation of two rows, a held-out mesh file when the data set has
 *     one), each embedded cold near its prior on a warm session with the
 *     default solver (local-global, Levenberg-Marquardt finish where needed)
 *     and with the previous one (--solver lm), side by side: CPU and wall,
 *     iterations, RMS and max edge error, bending against the prior,
 *     distance from the prior's realization, and for the held-out mesh the
 *     distance from the real one;
 *   - a walk of F frames along PC 1 (mean + t pc:1, t from -1.5 to 1.5):
 *     warm (each frame from the last one's correction) and cold, frames per
 *     CPU-second, the largest distance of a warm frame from its cold twin;
 *   - the same with the slider's accuracy (es_embed_opts_fast).
 * CPU is the process's (clock_gettime CLOCK_PROCESS_CPUTIME_ID); run it
 * with nothing else on the machine for the wall times to mean anything.
 *
 *   bench_points [dataset [levels [frames [few]]]]
 *     dataset: face-study (default), sfm_surrey_face_3448, facecap_arkit, ...
 *     (a folder of ../shared/data with OBJ files in correspondence)
 *     frames 0: no walks; "few": the mean and mean + 2 sd on PC 2 only, without
 *     the previous solver (the scaling table's rows: 216K vertices take minutes
 *     a point with it), each with its stages' times
 */
#define _XOPEN_SOURCE 700   /* nftw */
#include <edgespace/edgespace.h>

#include <dirent.h>
#include <ftw.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_clock.h"

#ifndef ES_SHARED_DIR
#define ES_SHARED_DIR "../shared"
#endif

static int fail(es_ctx *ctx, const char *what)
{
    fprintf(stderr, "bench_points: %s: %s\n", what, es_ctx_errmsg(ctx));
    exit(1);
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The OBJ files of a data set's folder, sorted; the last one is held out. */
static int64_t list_meshes(const char *dir, char ***out)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int64_t n = 0, cap = 64;
    char **v = malloc((size_t)cap * sizeof *v);
    if (!d) return 0;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l < 5 || strcmp(e->d_name + l - 4, ".obj")) continue;
        if (n == cap) v = realloc(v, (size_t)(cap *= 2) * sizeof *v);
        v[n++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(v, (size_t)n, sizeof *v, cmp_str);
    *out = v;
    return n;
}

/* Positions and faces of one file, subdivided `levels` times. */
static void read_mesh(es_ctx *ctx, const char *path, int levels, int64_t *nv, int64_t *nf,
                      int64_t **faces, double **xyz)
{
    es_meshdata md;
    if (es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md) != ES_OK) fail(ctx, path);
    *nv = md.nverts, *nf = md.nfaces;
    *faces = malloc(sizeof(int64_t) * (size_t)(3 * md.nfaces));
    *xyz = malloc(sizeof(double) * (size_t)(3 * md.nverts));
    memcpy(*faces, md.faces, sizeof(int64_t) * (size_t)(3 * md.nfaces));
    memcpy(*xyz, md.xyz, sizeof(double) * (size_t)(3 * md.nverts));
    es_meshdata_clear(ctx, &md);
    for (int l = 0; l < levels; l++) {
        int64_t nv2, *f2;
        double *x2;
        if (es_mesh_subdivide(ctx, *nv, *nf, *faces, 1, *xyz, &nv2, &f2, &x2) != ES_OK)
            fail(ctx, "subdivide");
        free(*faces), free(*xyz);
        *nf *= 4, *nv = nv2;
        *faces = malloc(sizeof(int64_t) * (size_t)(3 * *nf));
        *xyz = malloc(sizeof(double) * (size_t)(3 * nv2));
        memcpy(*faces, f2, sizeof(int64_t) * (size_t)(3 * *nf));
        memcpy(*xyz, x2, sizeof(double) * (size_t)(3 * nv2));
        es_free(ctx, f2), es_free(ctx, x2);
    }
}

typedef struct result {
    double cpu, wall;
    es_study_embed_result r;
} result;

static result embed(es_ctx *ctx, es_study_embedder *se, const char *pt, const es_embed_opts *o,
                    int warm, double *out)
{
    result x;
    double w0 = bench_wall_s(), c0 = bench_process_cpu_s();
    if (es_study_embedder_point(ctx, se, pt, "bench", 0, o, warm, out, &x.r) != ES_OK) fail(ctx, pt);
    x.cpu = bench_process_cpu_s() - c0;
    x.wall = bench_wall_s() - w0;
    return x;
}

static int remove_one(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

static double rms_between(int64_t nv, const double *a, const double *b)
{
    double s = 0;
    for (int64_t i = 0; i < 3 * nv; i++) s += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(s / (double)nv) / es_bbox_diagonal(nv, b);
}

static void row(const char *pt, const char *solver, const result *x, double truth)
{
    const es_embed_report *r = &x->r.report;
    printf("  %-34s %-5s cpu %7.3f s  wall %7.3f s  it %3lld+%-2lld  rms %.4f %%  max %6.3f %%  "
           "bend %.3f  prior %.3f %%", pt, solver, x->cpu, x->wall, (long long)r->lg_iters,
           (long long)r->refine_iters, 100 * r->rms_ratio, 100 * r->max_rel, r->bend_ratio,
           100 * r->prior_rms);
    if (truth >= 0) printf("  real %.4f %%", 100 * truth);
    if (r->n_bad_faces) printf("  (not realizable: %lld faces)", (long long)r->n_bad_faces);
    printf("\n    stages: refinement %.3f s (local-global %.3f s of it), total %.3f s\n",
           r->t_refine, r->t_local_global, r->t_total);
}

int main(int argc, char **argv)
{
    const char *set = argc > 1 ? argv[1] : "face-study";
    int levels = argc > 2 ? atoi(argv[2]) : 0, frames = argc > 3 ? atoi(argv[3]) : 20;
    int few = argc > 4 && !strcmp(argv[4], "few");
    char dir[4096], path[4300], store[256], held[4300];
    char **names = NULL;
    es_ctx *ctx;
    es_store *s = NULL;
    es_mesh *mesh = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    snprintf(dir, sizeof dir, "%s/data/%s", ES_SHARED_DIR, set);
    int64_t nfiles = list_meshes(dir, &names);
    if (nfiles < 4) {
        fprintf(stderr, "bench_points: %s holds %lld meshes (4 or more needed)\n", dir,
                (long long)nfiles);
        return 1;
    }
    snprintf(store, sizeof store, "/tmp/bench_points_%ld.h5", (long)getpid());
    snprintf(held, sizeof held, "%s/%s", dir, names[nfiles - 1]);
    /* the store: every file but the last (held out) */
    double w0 = bench_wall_s(), c0 = bench_process_cpu_s();
    for (int64_t i = 0; i + 1 < nfiles; i++) {
        int64_t nv, nf, *faces;
        double *xyz, scale;
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        read_mesh(ctx, path, levels, &nv, &nf, &faces, &xyz);
        if (!mesh && (es_mesh_new(ctx, nv, nf, faces, xyz, &mesh) != ES_OK ||
                      es_store_create(ctx, store, mesh, &s) != ES_OK))
            fail(ctx, "store");
        int64_t ne = es_mesh_nedges(mesh);
        double *len = malloc(sizeof(double) * (size_t)ne);
        es_edge_lengths(ctx, mesh, xyz, len);
        es_lengths_normalize(ctx, ne, len, len, &scale);
        char id[256];
        es_id_from_path(names[i], id, sizeof id);
        const char *ids[1] = {id};
        es_store_rows r = {1, ids, NULL, NULL, len, &scale, xyz, 0, NULL, NULL};
        if (es_store_append(ctx, s, &r) != ES_OK) fail(ctx, "append");
        free(len), free(faces), free(xyz);
    }
    es_study_pca_opts po;
    es_study_pca_opts_init(&po);
    po.name = "bench";
    po.pca.ncomp = 5;
    po.command = "bench";
    if (es_study_pca(ctx, s, &po, NULL, NULL, NULL) != ES_OK ||
        es_store_commit(ctx, s) != ES_OK)
        fail(ctx, "pca");
    int64_t nv = es_store_nverts(s);
    printf("# %s x %lld rows, %d subdivisions: %lld vertices, %lld edges (store made in %.1f s)\n",
           set, (long long)es_store_nrows(s), levels, (long long)nv, (long long)es_store_nedges(s),
           bench_wall_s() - w0);

    /* the session: without the cache, making it, reading it */
    es_study_embedder *se = NULL;
    for (int pass = 0; pass < 3; pass++) {
        es_study_embedder_free(se);
        se = NULL;
        w0 = bench_wall_s(), c0 = bench_process_cpu_s();
        if (es_study_embedder_open(ctx, s, pass > 0, &se) != ES_OK) fail(ctx, "session");
        printf("session %-28s cpu %7.3f s  wall %7.3f s\n",
               pass == 0 ? "(no cache)" : pass == 1 ? "(making the cache)" : "(reading the cache)",
               bench_process_cpu_s() - c0, bench_wall_s() - w0);
    }

    /* points, cold on a warm session, both solvers */
    const char *pts[] = {"mean", "mean - 2*pc:1", "mean + 2*pc:1", "mean - 2*pc:2",
                         "mean + 2*pc:2", "mean - 2*pc:3", "mean + 2*pc:3", NULL, NULL};
    char lerp[1200], file[4400];
    snprintf(lerp, sizeof lerp, "lerp(row:%s, row:%s, 0.5)", es_store_row_id(s, 0),
             es_store_row_id(s, 1));
    pts[7] = lerp;
    if (few) pts[1] = "mean + 2*pc:2", pts[2] = NULL;
    double *out = malloc(sizeof(double) * (size_t)(3 * nv)), *truth = NULL;
    if (levels == 0 && !few) {
        snprintf(file, sizeof file, "file:%s", held);
        pts[8] = file;
        truth = malloc(sizeof(double) * (size_t)(3 * nv));
        if (es_meshio_read_positions(ctx, mesh, held, truth) != ES_OK) fail(ctx, held);
    }
    es_embed_opts dflt, lm, fast;
    es_embed_opts_init(&dflt);
    es_embed_opts_init(&lm);
    lm.solver = ES_EMBED_SOLVER_LM;
    es_embed_opts_fast(&fast);
    double tot[3] = {0, 0, 0};
    int npts = 0;
    printf("points (each from its prior, on a warm session):\n");
    for (int k = 0; k < 9 && pts[k]; k++, npts++) {
        const es_embed_opts *os[3] = {&dflt, &lm, &fast};
        const char *nm[3] = {"new", "lm", "fast"};
        for (int q = 0; q < 3; q++) {
            if (few && q == 1) continue;
            result x = embed(ctx, se, pts[k], os[q], 0, out);
            double d = -1;
            if (truth && pts[k] == file) {
                double *c = malloc(sizeof(double) * (size_t)(3 * nv)), r2, s0 = 0, s1 = 0;
                int64_t ne = es_store_nedges(s);
                double *l = malloc(sizeof(double) * (size_t)ne);
                es_edge_lengths(ctx, mesh, truth, l);
                for (int64_t e = 0; e < ne; e++) s0 += l[e];
                es_edge_lengths(ctx, mesh, out, l);
                for (int64_t e = 0; e < ne; e++) s1 += l[e];
                for (int64_t i = 0; i < 3 * nv; i++) c[i] = truth[i] * s1 / s0;
                es_embed_align(ctx, nv, out, c, NULL, &r2);
                d = r2 / es_bbox_diagonal(nv, c);
                free(c), free(l);
            }
            row(pts[k], nm[q], &x, d);
            tot[q] += x.cpu;
        }
    }
    if (few) printf("mean CPU per point: new %.3f s, fast %.3f s\n", tot[0] / npts, tot[2] / npts);
    else printf("mean CPU per point: new %.3f s, lm %.3f s (ratio %.2f), fast %.3f s\n",
                tot[0] / npts, tot[1] / npts, tot[1] / tot[0], tot[2] / npts);

    /* walks along PC 1 */
    double *cold = malloc(sizeof(double) * (size_t)(3 * nv) * (size_t)frames);
    for (int mode = 0; mode < 5 && frames > 0; mode++) {
        /* 0 cold, 1 warm, 2 lm cold, 3 fast cold, 4 fast warm */
        const es_embed_opts *o = mode == 2 ? &lm : mode >= 3 ? &fast : &dflt;
        int warm = mode == 1 || mode == 4;
        double cpu = 0, wall = 0, far = 0;
        int64_t it = 0, pit = 0;
        es_study_embedder_forget(se);
        for (int f = 0; f < frames; f++) {
            char pt[64];
            snprintf(pt, sizeof pt, "mean + %.6f*pc:1",
                     frames > 1 ? -1.5 + 3.0 * f / (frames - 1) : 0.0);
            result x = embed(ctx, se, pt, o, warm, out);
            cpu += x.cpu, wall += x.wall;
            it += x.r.report.lg_iters, pit += x.r.report.refine_iters;
            if (mode == 0) memcpy(cold + 3 * nv * f, out, sizeof(double) * (size_t)(3 * nv));
            else if (mode != 2) far = fmax(far, rms_between(nv, out, cold + 3 * nv * f));
        }
        static const char *const what[5] = {"cold", "warm", "lm (previous solver)", "fast, cold",
                                            "fast, warm"};
        printf("walk along PC 1, %d frames, %-22s cpu %7.3f s  wall %7.3f s  %5.1f frames per "
               "CPU-second  %.1f+%.1f it/frame", frames, what[mode], cpu, wall, frames / cpu,
               (double)it / frames, (double)pit / frames);
        if (mode != 0 && mode != 2) printf("  at most %.4f %% of the diagonal from cold", 100 * far);
        printf("\n");
        fflush(stdout);
    }
    es_study_embedder_free(se);
    es_mesh_free(mesh);
    es_store_close(s);
    remove(store);
    snprintf(path, sizeof path, "%s.es-cache", store);
    remove(path);
    snprintf(path, sizeof path, "%s.results", store);   /* format 3: results beside */
    nftw(path, remove_one, 16, FTW_DEPTH | FTW_PHYS);
    for (int64_t i = 0; i < nfiles; i++) free(names[i]);
    free(names), free(out), free(truth), free(cold);
    es_ctx_free(ctx);
    return 0;
}
