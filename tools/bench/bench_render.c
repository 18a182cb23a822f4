/* tools/bench/bench_render.c — time es_render and the plots: a synthetic
 * face-like height field at several triangle counts, panel sizes and
 * supersampling factors, a real face-study mesh when ../shared/data is
 * there, and a 2000-point scatter to PNG and SVG. Prints figures; never a
 * test. Output files go to the current directory's bench-out/. */
#include <edgespace/edgespace.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bench_clock.h"

#include "mesh_gen.h"   /* tests/common: the synthetic face grid */

/* Best of `reps` CPU times of one render. */
static double time_render(es_ctx *ctx, const es_render_spec *spec, const char *out, int reps)
{
    double best = 1e30;
    for (int r = 0; r < reps; r++) {
        double t0 = bench_process_cpu_s();
        if (es_render(ctx, spec, out, NULL) != ES_OK) {
            fprintf(stderr, "bench_render: %s\n", es_ctx_errmsg(ctx));
            exit(1);
        }
        double t = bench_process_cpu_s() - t0;
        if (t < best) best = t;
    }
    return best;
}

int main(void)
{
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    mkdir("bench-out", 0777);
    printf("%-34s %9s %7s %3s %10s %12s\n", "mesh", "faces", "panel", "ss", "cpu ms", "Msamples/s");
    static const int grids[3][2] = {{64, 32}, {192, 96}, {512, 256}};
    for (int g = 0; g < 3; g++) {
        tm_mesh f = tm_face(grids[g][0], grids[g][1]);
        es_render_mesh it;
        memset(&it, 0, sizeof it);
        it.nverts = f.nv, it.nfaces = f.nf, it.xyz = f.xyz, it.faces = f.faces;
        static const int sizes[2] = {480, 1024};
        for (int s = 0; s < 2; s++)
            for (int ss = 1; ss <= 3; ss += 2) {
                es_render_spec spec;
                es_render_spec_init(&spec);
                spec.meshes = &it, spec.nmeshes = 1;
                spec.width = spec.height = sizes[s];
                spec.supersample = ss;
                double t = time_render(ctx, &spec, "bench-out/face.png", 3);
                char name[64];
                snprintf(name, sizeof name, "synthetic face %dx%d", grids[g][0], grids[g][1]);
                printf("%-34s %9lld %7d %3d %10.1f %12.2f\n", name, (long long)f.nf, sizes[s],
                       ss, 1e3 * t, 1e-6 * sizes[s] * sizes[s] * ss * ss / t);
            }
        tm_free(&f);
    }
#ifdef ES_SHARED_DIR
    char path[4096];
    snprintf(path, sizeof path, "%s/data/face-study/s001_neutral.obj", ES_SHARED_DIR);
    es_meshdata md;
    memset(&md, 0, sizeof md);
    if (es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md) == ES_OK) {
        es_render_mesh it;
        memset(&it, 0, sizeof it);
        it.nverts = md.nverts, it.nfaces = md.nfaces, it.xyz = md.xyz, it.faces = md.faces;
        es_render_spec spec;
        es_render_spec_init(&spec);
        spec.meshes = &it, spec.nmeshes = 1;
        double t = time_render(ctx, &spec, "bench-out/s001.png", 3);
        printf("%-34s %9lld %7d %3d %10.1f %12.2f\n", "face-study s001_neutral (PNG)",
               (long long)md.nfaces, spec.width, spec.supersample, 1e3 * t,
               1e-6 * spec.width * spec.height * 9 / t);
        t = time_render(ctx, &spec, "bench-out/s001.svg", 3);
        printf("%-34s %9lld %7d %3d %10.1f %12.2f\n", "face-study s001_neutral (SVG)",
               (long long)md.nfaces, spec.width, spec.supersample, 1e3 * t,
               1e-6 * spec.width * spec.height * 9 / t);
        es_meshdata_clear(ctx, &md);
    }
#endif
    enum { N = 2000 };
    static double x[N], y[N];
    static const char *lab[N];
    static const char *const groups[5] = {"a", "b", "c", "d", "e"};
    for (int i = 0; i < N; i++) {
        x[i] = (double)(i % 97) + 0.01 * i;
        y[i] = (double)((i * 37) % 101);
        lab[i] = groups[i % 5];
    }
    es_scatter_spec sc;
    es_scatter_spec_init(&sc);
    sc.n = N, sc.x = x, sc.y = y, sc.labels = lab;
    static const char *const outs[2] = {"bench-out/scatter.png", "bench-out/scatter.svg"};
    for (int k = 0; k < 2; k++) {
        double best = 1e30;
        for (int r = 0; r < 3; r++) {
            double t0 = bench_process_cpu_s();
            if (es_plot_scatter(ctx, &sc, outs[k], NULL) != ES_OK) return 1;
            double t = bench_process_cpu_s() - t0;
            best = t < best ? t : best;
        }
        printf("scatter %d points -> %-14s %10.1f cpu ms\n", N, k ? "SVG" : "PNG", 1e3 * best);
    }
    es_ctx_free(ctx);
    return 0;
}
