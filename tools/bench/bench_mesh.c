/* tools/bench/bench_mesh.c — timings of topology and geometry on synthetic
 * meshes up to the benchmark sizes (~58k vertices, ~175k edges): es_mesh_new,
 * es_edge_lengths, es_corner_angles, es_dihedral_angles, es_mesh_subdivide.
 * Prints a table of process CPU times (single-threaded code; CPU time is
 * steadier than wall time on a shared machine); never pass/fail.
 * Usage: bench_mesh [repeats]
 */
#include <edgespace/edgespace.h>

#include <stdio.h>
#include <stdlib.h>

#include "bench_clock.h"

static int fail(es_ctx *ctx, const char *what)
{
    fprintf(stderr, "bench_mesh: %s: %s\n", what, es_ctx_errmsg(ctx));
    return 1;
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? atoi(argv[1]) : 5;
    es_ctx *ctx = NULL;
    if (reps < 1) reps = 1;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    printf("%-12s %4s %8s %8s %8s | %9s %9s %9s %9s %9s  (CPU ms, best of %d)\n", "family", "sub",
           "V", "E", "F", "mesh_new", "lengths", "corners", "dihedral", "subdiv", reps);
    const es_synth_family fams[] = {ES_SYNTH_FACE, ES_SYNTH_BARBELL};
    for (int fi = 0; fi < 2; fi++)
        for (int sub = 0; sub <= 3; sub++) {
            es_synth_set s;
            es_synth_opts o;
            es_synth_opts_init(&o);
            o.n = 1;
            if (fams[fi] == ES_SYNTH_BARBELL) o.n = 2;
            if (es_synth_generate(ctx, fams[fi], &o, &s) != ES_OK) return fail(ctx, "synth");
            if (es_synth_subdivide(ctx, &s, sub) != ES_OK) return fail(ctx, "subdivide");
            double t[5] = {1e300, 1e300, 1e300, 1e300, 1e300};
            es_mesh *m = NULL;
            double *len = NULL, *ang = NULL, *al = NULL;
            for (int r = 0; r < reps; r++) {
                double t0 = bench_process_cpu_s();
                es_mesh_free(m);
                m = NULL;
                if (es_mesh_new(ctx, s.nverts, s.nfaces, s.faces, NULL, &m) != ES_OK)
                    return fail(ctx, "mesh_new");
                double t1 = bench_process_cpu_s();
                int64_t ne = es_mesh_nedges(m);
                if (!len) {
                    len = malloc((size_t)ne * sizeof *len);
                    al = malloc((size_t)ne * sizeof *al);
                    ang = malloc((size_t)s.nfaces * 3 * sizeof *ang);
                }
                double t2 = bench_process_cpu_s();
                es_edge_lengths(ctx, m, s.xyz, len);
                double t3 = bench_process_cpu_s();
                es_corner_angles(ctx, m, len, ang);
                double t4 = bench_process_cpu_s();
                if (es_dihedral_angles(ctx, m, s.xyz, al) != ES_OK) return fail(ctx, "dihedral");
                double t5 = bench_process_cpu_s();
                int64_t nv2, *f2;
                double *x2;
                if (es_mesh_subdivide(ctx, s.nverts, s.nfaces, s.faces, 1, s.xyz, &nv2, &f2,
                                      &x2) != ES_OK)
                    return fail(ctx, "subdivide");
                double t6 = bench_process_cpu_s();
                es_free(ctx, f2);
                es_free(ctx, x2);
                double d[5] = {t1 - t0, t3 - t2, t4 - t3, t5 - t4, t6 - t5};
                for (int k = 0; k < 5; k++)
                    if (d[k] < t[k]) t[k] = d[k];
            }
            printf("%-12s %4d %8lld %8lld %8lld | %9.3f %9.3f %9.3f %9.3f %9.3f\n",
                   es_synth_family_name(fams[fi]), sub, (long long)s.nverts,
                   (long long)es_mesh_nedges(m), (long long)s.nfaces, 1e3 * t[0], 1e3 * t[1],
                   1e3 * t[2], 1e3 * t[3], 1e3 * t[4]);
            es_mesh_free(m);
            free(len);
            free(ang);
            free(al);
            es_synth_set_clear(ctx, &s);
        }
    es_ctx_free(ctx);
    return 0;
}
