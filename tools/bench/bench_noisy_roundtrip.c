/* tools/bench/bench_noisy_roundtrip.c — how far noisy starting dihedrals
 * leave an embedding from the mesh whose exact lengths it is given, on real
 * meshes from ../shared/data, and how tightly those lengths fix the mesh.
 *
 * Part 1: each mesh's own lengths from its own dihedrals plus Gaussian
 * noise (0.005 and 0.05 rad, three seeds), default options: edge-length RMS
 * ratio and max relative error, vertex RMS distance to the mesh after a
 * rigid alignment (x bounding-box diagonal), stage-1 and refinement
 * iterations, wall time.
 * With "long", each 0.05 rad case is solved again with 200 stage-1 and
 * 200 refinement iterations and no early stop: an end point whose error
 * stays where it was is a local minimum of the length error (a dent or
 * bulge whose flat-region dihedrals the noise flipped), not a stage that
 * ran out of iterations.
 * Part 2 (closed meshes): start from the mesh itself moved by position
 * noise of s x diagonal (stage 1 off, refinement to machine precision):
 * where the refinement ends, how well it realizes the lengths and how far
 * it is from the mesh. An end point that realizes the lengths to ~1e-13
 * away from the mesh is another realization of the same lengths: the
 * lengths do not fix the mesh more tightly than that distance.
 *
 *   bench_noisy_roundtrip [long]     (data from ../shared/data)
 */
#include <edgespace/edgespace.h>



#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

#ifndef ES_SHARED_DIR
#define ES_SHARED_DIR "../shared"
#endif

static int long_runs;   /* "long" on the command line */

static void print_row(const char *file, int64_t nv, double sigma, uint64_t seed, const char *tag,
                      const es_embed_report *r, double vrms_diag, double wall)
{
    printf("%-34s %6lld  noise %5.3f rad seed %llu%-5s %9.2e %9.2e  %9.2e  %3lld %3lld  %6.2f\n",
           file, (long long)nv, sigma, (unsigned long long)seed, tag, r->rms_ratio, r->max_rel,
           vrms_diag, (long long)r->dihedral_iters, (long long)r->refine_iters, wall);
    fflush(stdout);
}

static void run(es_ctx *ctx, const char *file, int closed)
{
    char path[4096];
    es_meshdata md;
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    snprintf(path, sizeof path, "%s/data/%s", ES_SHARED_DIR, file);
    if (es_meshdata_read(ctx, path, ES_FORMAT_OBJ, &md)) {
        fprintf(stderr, "bench_noisy_roundtrip: %s\n", es_ctx_errmsg(ctx));
        return;
    }
    if (es_mesh_new(ctx, md.nverts, md.nfaces, md.faces, md.xyz, &mesh) ||
        es_embedder_new(ctx, mesh, &emb)) {
        fprintf(stderr, "bench_noisy_roundtrip: %s\n", es_ctx_errmsg(ctx));
        goto done;
    }
    {
        int64_t nv = md.nverts, ne = es_mesh_nedges(mesh);
        double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
        double *out = malloc(3 * (size_t)nv * sizeof *out), *x0 = malloc(3 * (size_t)nv * sizeof *x0);
        double diag = es_bbox_diagonal(nv, md.xyz), rms;
        es_embed_report r;
        es_edge_lengths(ctx, mesh, md.xyz, len);
        for (int level = 0; level < 2; level++)
            for (uint64_t seed = 1; seed <= 3; seed++) {
                double sigma = level ? 0.05 : 0.005, w0;
                es_rng rng;
                es_rng_init(&rng, seed);
                es_dihedral_angles(ctx, mesh, md.xyz, al);
                for (int64_t e = 0; e < ne; e++) al[e] += sigma * es_rng_normal(&rng);
                w0 = bench_wall_s();
                if (es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r)) goto fail;
                w0 = bench_wall_s() - w0;
                es_embed_align(ctx, nv, out, md.xyz, NULL, &rms);
                print_row(file, nv, sigma, seed, "", &r, rms / diag, w0);
                if (long_runs && level) {
                    es_embed_opts o;
                    es_embed_opts_init(&o);
                    o.dihedral_max_iter = 200;
                    o.dihedral_rtol = 1e-14;
                    o.refine_max_iter = 200;
                    o.refine_rtol = 1e-12;
                    o.refine_tol = 0;
                    w0 = bench_wall_s();
                    if (es_embed_solve(ctx, emb, len, 0, al, NULL, &o, out, &r)) goto fail;
                    w0 = bench_wall_s() - w0;
                    es_embed_align(ctx, nv, out, md.xyz, NULL, &rms);
                    print_row(file, nv, sigma, seed, " long", &r, rms / diag, w0);
                }
            }
        if (closed) {
            const double moves[3] = {1e-6, 2e-6, 1e-5};
            es_embed_opts o;
            es_embed_opts_init(&o);
            o.dihedral_mode = ES_EMBED_DIHEDRAL_OFF;
            o.refine_max_iter = 200;
            o.refine_rtol = 1e-15;
            o.refine_tol = 0;
            for (int m = 0; m < 3; m++) {
                es_rng rng;
                es_rng_init(&rng, 99);
                for (int64_t i = 0; i < 3 * nv; i++)
                    x0[i] = md.xyz[i] + moves[m] * diag * es_rng_normal(&rng);
                if (es_embed_solve(ctx, emb, len, 0, NULL, x0, &o, out, &r)) goto fail;
                es_embed_align(ctx, nv, out, md.xyz, NULL, &rms);
                printf("%-34s %6lld  moved %.0e x diag               %9.2e %9.2e  %9.2e  %3s "
                       "%3lld\n",
                       file, (long long)nv, moves[m], r.rms_ratio, r.max_rel, rms / diag, "-",
                       (long long)r.refine_iters);
                fflush(stdout);
            }
        }
        free(len), free(al), free(out), free(x0);
        goto done;
    }
fail:
    fprintf(stderr, "bench_noisy_roundtrip: %s\n", es_ctx_errmsg(ctx));
done:
    es_embedder_free(emb);
    es_mesh_free(mesh);
    es_meshdata_clear(ctx, &md);
}

int main(int argc, char **argv)
{
    es_ctx *ctx;
    long_runs = argc > 1 && strcmp(argv[1], "long") == 0;
    if (es_ctx_new(&ctx)) return 1;
    printf("# %-32s %6s  %-31s %9s %9s  %9s  %3s %3s  %6s\n", "mesh", "V", "start", "rms",
           "max", "vrms/diag", "s1", "ref", "wall");
    run(ctx, "goast_finger/finger0.obj", 1);
    run(ctx, "goast_cactus/cactus0.obj", 1);
    run(ctx, "sumner_cat_poses/cat-01.obj", 1);
    run(ctx, "facecap_arkit/neutral.obj", 0);
    run(ctx, "goast_spacetime_faces/disgust.obj", 0);
    run(ctx, "face-study/s001_neutral.obj", 0);
    es_ctx_free(ctx);
    return 0;
}
