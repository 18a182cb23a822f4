/* tools/bench/bench_walk.c — the embedding at interactive speed, measured as
 * a user meets it: a store of faces (face-study; with levels > 0 each face
 * subdivided that many times, which keeps them in correspondence), then
 *   - the one-time work per command: the embedder (symbolic analyses) and
 *     the rows made ready for priors (GPA, dihedrals);
 *   - the midpoint of two faces near its prior (lerp(row:a, row:b, 0.5)), a
 *     cold and a warm embedding (the embedder reused), with its accuracy;
 *   - a walk of F frames along PC 1 (mean + t * pc:1, t from -1.5 to 1.5), each
 *     frame near its prior: frames per
 *     second, CPU and wall.
 *
 *   bench_walk [levels [frames [rows]]]   (defaults 0, 20, 30; data from
 *                                          ../shared/data/face-study)
 *   EDGESPACE_VERBOSE=1 prints the refinement's iterations;
 *   EDGESPACE_BENCH_TOL=RMS,MAX (fractions) sets the accuracy stop;
 *   EDGESPACE_BENCH_WARM=1 starts each walk frame from the previous one.
 */
#include <edgespace/edgespace.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_clock.h"

#ifndef ES_SHARED_DIR
#define ES_SHARED_DIR "../shared"
#endif

static void log_fn(void *ud, es_log_level lv, const char *msg)
{
    (void)ud, (void)lv;
    fprintf(stderr, "  %s\n", msg);
}

static int fail(es_ctx *ctx, const char *what)
{
    fprintf(stderr, "bench_walk: %s: %s\n", what, es_ctx_errmsg(ctx));
    return 1;
}

/* A store of the first nrows face-study meshes, subdivided `levels` times. */
static int make_store(es_ctx *ctx, const char *path, int levels, int64_t nrows)
{
    static const char *const ex[3] = {"neutral", "happy", "angry"};
    es_store *s = NULL;
    es_mesh *mesh = NULL;
    char file[4096], id[64];
    int64_t n = 0;
    for (int64_t i = 0; i < nrows; i++) {
        es_meshdata md;
        int64_t nv, nf, *faces, nv2, *f2;
        double *xyz, *x2, *len = NULL, scale;
        snprintf(file, sizeof file, "%s/data/face-study/s%03lld_%s.obj", ES_SHARED_DIR,
                 (long long)(i / 3 + 1), ex[i % 3]);
        if (es_meshdata_read(ctx, file, ES_FORMAT_OBJ, &md) != ES_OK) return fail(ctx, file);
        nv = md.nverts, nf = md.nfaces;
        faces = md.faces, xyz = md.xyz;
        int64_t *fown = NULL;
        double *xown = NULL;
        for (int l = 0; l < levels; l++) {
            if (es_mesh_subdivide(ctx, nv, nf, faces, 1, xyz, &nv2, &f2, &x2) != ES_OK)
                return fail(ctx, "subdivide");
            es_free(ctx, fown), es_free(ctx, xown);
            faces = fown = f2, xyz = xown = x2, nv = nv2, nf *= 4;
        }
        if (!mesh && (es_mesh_new(ctx, nv, nf, faces, xyz, &mesh) != ES_OK ||
                      es_store_create(ctx, path, mesh, &s) != ES_OK))
            return fail(ctx, "store");
        len = malloc(sizeof(double) * (size_t)es_mesh_nedges(mesh));
        es_edge_lengths(ctx, mesh, xyz, len);
        es_lengths_normalize(ctx, es_mesh_nedges(mesh), len, len, &scale);
        snprintf(id, sizeof id, "s%03lld_%s", (long long)(i / 3 + 1), ex[i % 3]);
        const char *ids[1] = {id}, *cols[1] = {"expression"}, *labels[1] = {ex[i % 3]};
        es_store_rows r = {1, ids, NULL, NULL, len, &scale, xyz, 1, cols, labels};
        if (es_store_append(ctx, s, &r) != ES_OK) return fail(ctx, "append");
        free(len);
        es_free(ctx, fown), es_free(ctx, xown);
        es_meshdata_clear(ctx, &md);
        n++;
    }
    es_mesh_free(mesh);
    if (es_store_commit(ctx, s) != ES_OK) return fail(ctx, "commit");
    es_store_close(s);
    return n > 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
    int levels = argc > 1 ? atoi(argv[1]) : 0;
    int frames = argc > 2 ? atoi(argv[2]) : 20;
    int64_t nrows = argc > 3 ? atoll(argv[3]) : 30;
    char path[256];
    es_ctx *ctx;
    es_store *s = NULL;
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    es_study_rows *rows = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    if (getenv("EDGESPACE_VERBOSE")) es_ctx_set_log(ctx, log_fn, NULL);
    snprintf(path, sizeof path, "/tmp/bench_walk_%d_%ld.h5", levels, (long)getpid());
    if (make_store(ctx, path, levels, nrows)) return 1;
    if (es_store_open(ctx, path, ES_STORE_WRITE, &s) != ES_OK || es_store_mesh(ctx, s, &mesh) != ES_OK)
        return fail(ctx, "open");
    const int64_t nv = es_mesh_nverts(mesh), ne = es_mesh_nedges(mesh), n = es_store_nrows(s);
    double *len = malloc(sizeof(double) * (size_t)ne), *w = malloc(sizeof(double) * (size_t)n);
    double *prior = malloc(sizeof(double) * (size_t)(3 * nv + 2 * ne));
    double *out = malloc(sizeof(double) * (size_t)(3 * nv)), scale;
    es_embed_prior pr = {prior, prior + 3 * nv, prior + 3 * nv + ne, NULL, NULL, NULL};
    es_embed_report r;
    es_embed_opts eo;
    es_embed_opts_init(&eo);
    eo.verbose = getenv("EDGESPACE_VERBOSE") != NULL;
    if (getenv("EDGESPACE_BENCH_TOL") &&   /* the accuracy stop, as fractions */
        sscanf(getenv("EDGESPACE_BENCH_TOL"), "%lf,%lf", &eo.refine_rms_tol,
               &eo.refine_max_tol) == 2)
        printf("# refinement stops at rms <= %.3g %%, max <= %.3g %%\n", 100 * eo.refine_rms_tol,
               100 * eo.refine_max_tol);
    printf("# face-study x %lld rows, %d subdivisions: %lld vertices, %lld edges\n",
           (long long)n, levels, (long long)nv, (long long)ne);
    double w0 = bench_wall_s(), c0 = bench_process_cpu_s();
    if (es_embedder_new(ctx, mesh, &emb) != ES_OK) return fail(ctx, "embedder");
    printf("setup: embedder (symbolic analyses)   wall %6.3f s  cpu %6.3f s\n",
           bench_wall_s() - w0, bench_process_cpu_s() - c0);
    w0 = bench_wall_s(), c0 = bench_process_cpu_s();
    if (es_study_rows_load(ctx, s, mesh, &rows) != ES_OK) return fail(ctx, "rows");
    printf("setup: rows for priors (GPA, dihedrals) wall %6.3f s  cpu %6.3f s\n",
           bench_wall_s() - w0, bench_process_cpu_s() - c0);
    /* the midpoint of the first two rows, cold then warm */
    for (int pass = 0; pass < 2; pass++) {
        if (es_study_point_weights(ctx, s, "lerp(row:s001_neutral, row:s001_happy, 0.5)", NULL,
                                   len, &scale, w) != ES_OK ||
            es_study_prior(ctx, rows, w, prior, prior + 3 * nv, prior + 3 * nv + ne) != ES_OK)
            return fail(ctx, "point");
        w0 = bench_wall_s(), c0 = bench_process_cpu_s();
        if (es_embed_prior_solve(ctx, emb, len, scale, &pr, &eo, out, &r) != ES_OK)
            return fail(ctx, "embed");
        printf("midpoint (%s)  wall %6.3f s  cpu %6.3f s  refine %lld it  rms %.4f %%  max %.3f %%"
               "  bending %.3f\n", pass ? "warm" : "cold", bench_wall_s() - w0,
               bench_process_cpu_s() - c0, (long long)r.refine_iters, 100 * r.rms_ratio,
               100 * r.max_rel, r.bend_ratio);
    }
    /* a walk along PC 1 */
    es_study_pca_opts po;
    es_study_pca_opts_init(&po);
    po.name = "walk";
    po.pca.ncomp = 5;
    po.command = "bench";
    if (es_study_pca(ctx, s, &po, NULL, NULL, NULL) != ES_OK)
        return fail(ctx, "pca");
    double tw = 0, tc = 0, worst_rms = 0, worst_max = 0;
    double *prev = malloc(sizeof(double) * (size_t)(3 * nv));
    int warm = getenv("EDGESPACE_BENCH_WARM") != NULL;
    int64_t iters = 0;
    for (int f = 0; f < frames; f++) {
        char expr[64];
        double t = frames > 1 ? -1.5 + 3.0 * f / (frames - 1) : 0;
        snprintf(expr, sizeof expr, "mean + %.6f*pc:1", t);
        if (es_study_point_weights(ctx, s, expr, "walk", len, &scale, w) != ES_OK)
            return fail(ctx, expr);
        w0 = bench_wall_s(), c0 = bench_process_cpu_s();
        /* warm (EDGESPACE_BENCH_WARM): from the previous frame's positions */
        pr.start = warm && f > 0 ? prev : NULL;
        if (es_study_prior(ctx, rows, w, prior, prior + 3 * nv, prior + 3 * nv + ne) != ES_OK ||
            es_embed_prior_solve(ctx, emb, len, scale, &pr, &eo, out, &r) != ES_OK)
            return fail(ctx, "walk frame");
        memcpy(prev, out, sizeof(double) * (size_t)(3 * nv));
        tw += bench_wall_s() - w0, tc += bench_process_cpu_s() - c0;
        iters += r.refine_iters;
        if (!r.n_bad_faces) worst_rms = fmax(worst_rms, r.rms_ratio), worst_max = fmax(worst_max, r.max_rel);
    }
    printf("walk along PC 1: %d frames  wall %6.3f s  cpu %6.3f s  %.1f frames/s (wall)  "
           "%.1f it/frame  worst realizable rms %.4f %%  max %.3f %%%s\n", frames, tw, tc,
           frames / tw, (double)iters / frames, 100 * worst_rms, 100 * worst_max,
           warm ? "  (warm: each frame from the last)" : "");
    es_study_rows_free(rows);
    es_embedder_free(emb);
    es_mesh_free(mesh);
    es_store_abort(s);
    remove(path);
    free(len), free(w), free(prior), free(out), free(prev);
    es_ctx_free(ctx);
    return 0;
}
