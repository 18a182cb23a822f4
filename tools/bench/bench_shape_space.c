/* tools/bench/bench_shape_space.c — the candidate sets of Wuhrer et al.'s
 * averaging algorithm (es_shape_space) on the real pairs: how many
 * candidates the paper's rule makes at the midpoint (the slots' weights,
 * exact), what the cap stores, the time and peak memory per frame, and how
 * the cap changes the result: the midpoint with cap 32 (the default) and
 * 256 against cap = unbounded where the paper's count allows it (RMS vertex
 * distance over the bounding-box diagonal), and the RMS ratio / max
 * relative edge error of each against the midpoint's lengths.
 *
 *   bench_shape_space        (data from ../shared/data)
 */
#include <edgespace/edgespace.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

#ifndef ES_SHARED_DIR
#define ES_SHARED_DIR "../shared"
#endif

/* the paper's own rule stays within memory below this many candidates */
#define UNCAPPED_MAX 2e7

static double rms_dist(int64_t nv, const double *a, const double *b)
{
    double s = 0;
    for (int64_t i = 0; i < 3 * nv; i++) s += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(s / (double)nv) / es_bbox_diagonal(nv, b);
}

static void run(es_ctx *ctx, const char *name, const char *fa, const char *fb)
{
    char pa[4096], pb[4096];
    es_meshdata a, b;
    es_mesh *m = NULL;
    int64_t caps[3] = {32, 256, INT64_MAX / 4};
    double *out[3] = {NULL, NULL, NULL}, *l;
    snprintf(pa, sizeof pa, "%s/data/%s", ES_SHARED_DIR, fa);
    snprintf(pb, sizeof pb, "%s/data/%s", ES_SHARED_DIR, fb);
    if (es_meshdata_read(ctx, pa, ES_FORMAT_AUTO, &a) != ES_OK ||
        es_meshdata_read(ctx, pb, ES_FORMAT_AUTO, &b) != ES_OK ||
        es_mesh_new(ctx, a.nverts, a.nfaces, a.faces, NULL, &m) != ES_OK) {
        printf("%-12s skipped: %s\n", name, es_ctx_errmsg(ctx));
        return;
    }
    l = malloc((size_t)es_mesh_nedges(m) * sizeof *l);
    printf("%-12s %6lld vertices, %s -> %s, t = 0.5:\n", name, (long long)a.nverts, fa, fb);
    for (int k = 0; k < 3; k++) {
        es_shape_space_opts o;
        es_shape_space *ss = NULL;
        es_shape_space_info info;
        double t0 = bench_wall_s(), c0 = bench_process_cpu_s(), rms, mx, p99;
        es_shape_space_opts_init(&o);
        o.cap = caps[k];
        if (k == 2 && !(out[0] && out[0][0] == out[0][0])) break;
        if (es_shape_space_new(ctx, m, a.xyz, b.xyz, &o, &ss) != ES_OK) break;
        if (k == 2) {   /* the paper's count from the capped run decides */
            es_shape_space_info i0;
            es_shape_space *s0 = NULL;
            es_shape_space_opts o0;
            es_shape_space_opts_init(&o0);
            es_shape_space_new(ctx, m, a.xyz, b.xyz, &o0, &s0);
            es_shape_space_frame(ctx, s0, NULL, 0.5, out[0]);
            es_shape_space_get_info(s0, &i0);
            es_shape_space_free(s0);
            if (i0.paper_candidates > UNCAPPED_MAX) {
                printf("  unbounded: not run (%.3g candidates)\n", i0.paper_candidates);
                es_shape_space_free(ss);
                break;
            }
        }
        out[k] = malloc(3 * (size_t)a.nverts * sizeof *out[k]);
        if (es_shape_space_frame(ctx, ss, NULL, 0.5, out[k]) != ES_OK) {
            printf("  %s\n", es_ctx_errmsg(ctx));
            es_shape_space_free(ss);
            break;
        }
        es_shape_space_get_info(ss, &info);
        for (int64_t e = 0; e < es_mesh_nedges(m); e++) {
            const int64_t *ed = es_mesh_edges(m);
            double la = 0, lb = 0;
            for (int c = 0; c < 3; c++) {
                la += pow(a.xyz[3 * ed[2 * e] + c] - a.xyz[3 * ed[2 * e + 1] + c], 2);
                lb += pow(b.xyz[3 * ed[2 * e] + c] - b.xyz[3 * ed[2 * e + 1] + c], 2);
            }
            l[e] = 0.5 * (sqrt(la) + sqrt(lb));
        }
        es_embed_length_error(ctx, m, out[k], l, 0, &rms, &mx, &p99);
        printf("  cap %-9s paper's candidates %9.3g (most at a vertex %9.3g), stored %9lld "
               "(at most %lld a vertex); %.2f s wall, %.2f s CPU, peak RSS %.0f MiB; RMS ratio "
               "%.3g %%, max %.3g %%", k == 2 ? "unbounded" : (k ? "256" : "32"),
               info.paper_candidates, info.paper_max, (long long)info.candidates,
               (long long)info.max_candidates, bench_wall_s() - t0, bench_process_cpu_s() - c0,
               bench_peak_rss_mib(), 100 * rms, 100 * mx);
        if (k) printf("; %.3g x diag from cap 32", rms_dist(a.nverts, out[k], out[0]));
        printf("\n");
        es_shape_space_free(ss);
    }
    for (int k = 0; k < 3; k++) free(out[k]);
    free(l);
    es_mesh_free(m);
    es_meshdata_clear(ctx, &a);
    es_meshdata_clear(ctx, &b);
}

int main(void)
{
    es_ctx *ctx;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    run(ctx, "facecap", "facecap_arkit/neutral.obj", "facecap_arkit/bs_jawOpen.obj");
    run(ctx, "sfm_surrey", "sfm_surrey_face_3448/mean_neutral.obj",
        "sfm_surrey_face_3448/expr_happiness.obj");
    run(ctx, "finger", "goast_finger/finger0.obj", "goast_finger/finger1.obj");
    run(ctx, "cactus", "goast_cactus/cactus0.obj", "goast_cactus/cactus1.obj");
    run(ctx, "spacetime", "goast_spacetime_faces/neutral.obj", "goast_spacetime_faces/smile.obj");
    run(ctx, "cat", "sumner_cat_poses/cat-01.obj", "sumner_cat_poses/cat-02.obj");
    run(ctx, "face-study", "face-study/s001_neutral.obj", "face-study/s001_happy.obj");
    es_ctx_free(ctx);
    return 0;
}
