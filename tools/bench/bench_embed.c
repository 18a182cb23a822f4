/* tools/bench/bench_embed.c — time per embedding against vertex count (2K to
 * 60K vertices; larger meshes by midpoint subdivision of real ones, which
 * keeps them in correspondence) with the edge-length error and closure
 * energy beside each time. Three cases per mesh: the midpoint t = 0.5 of a
 * real pair (es_interp_embed: the hard, inconsistent case), the same
 * midpoint through the published method's stages only (stage 1 always, no
 * refinement; a comparison in the same run), the same midpoint near the
 * prior of the two shapes (es_embed_prior_solve, what `edgespace embed`
 * and `interp` do; its CPU time over es_interp_embed's is printed), and the
 * round trip of one shape's own lengths and dihedrals (consistent input).
 * Wall and process CPU time are printed: on a shared machine the wall time
 * includes waiting for a core.
 *
 *   bench_embed [max_vertices]      (default 60000; data from ../shared/data)
 *   bench_embed sweep               time and error of the face-study midpoint
 *                                   and the 54K face against the number of
 *                                   refinement iterations (the trade-off
 *                                   behind --refine-iters)
 *   EDGESPACE_BENCH_TOL=RMS,MAX (fractions): the accuracy stop for the
 *   midpoint and the prior cases.
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

/* One result line; exact round trips have errors near 1e-12, printed %g. */
static void print_row(const char *dir, const char *what, int64_t nv, double wall, double cpu,
                      double setup, const es_embed_report *r, int exact)
{
    printf("%-22s %-19s %7lld  %6.2f %6.2f  %6.2f %6.2f %6.2f %6.2f  ", dir, what, (long long)nv,
           wall, cpu, r->t_dihedral, r->t_frames + r->t_positions, r->t_refine, setup);
    if (exact)
        printf("%8.2g%% %7.2g%%", 100 * r->rms_ratio, 100 * r->max_rel);
    else
        printf("%8.4f%% %7.3f%%", 100 * r->rms_ratio, 100 * r->max_rel);
    printf("  %9.3g %9.3g  %s\n", r->closure_before, r->closure_after,
           r->used_stage1 ? "stage1" : "-");
}

static int sweep_mode;

/* The midpoint at 0, 1, 2, ... refinement iterations (sweep mode). */
static void sweep(es_ctx *ctx, es_embedder *emb, int64_t nv, const double *const *in, double *out,
                  const char *dir, double setup)
{
    static const int iters[] = {0, 1, 2, 3, 4, 6, 8, 12, 20, 40};
    double w[2] = {0.5, 0.5};
    for (size_t i = 0; i < sizeof iters / sizeof iters[0]; i++) {
        es_embed_opts o;
        es_embed_report r;
        char what[32];
        double w0 = bench_wall_s(), c0 = bench_process_cpu_s();
        es_embed_opts_init(&o);
        o.refine_max_iter = iters[i];
        if (es_interp_embed(ctx, emb, 2, in, w, NULL, &o, out, &r, NULL)) return;
        snprintf(what, sizeof what, "refine %d", iters[i]);
        print_row(dir, what, nv, bench_wall_s() - w0, bench_process_cpu_s() - c0, setup, &r, 0);
        fflush(stdout);
    }
}

static void run(es_ctx *ctx, const char *dir, const char *a, const char *b, int levels,
                int64_t vmax)
{
    char pa[4096], pb[4096];
    es_meshdata ma, mb;
    int64_t nv, nf, *faces;
    double *xyz;
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    snprintf(pa, sizeof pa, "%s/data/%s/%s.obj", ES_SHARED_DIR, dir, a);
    snprintf(pb, sizeof pb, "%s/data/%s/%s.obj", ES_SHARED_DIR, dir, b);
    if (es_meshdata_read(ctx, pa, ES_FORMAT_OBJ, &ma) || es_meshdata_read(ctx, pb, ES_FORMAT_OBJ, &mb)) {
        fprintf(stderr, "bench_embed: %s\n", es_ctx_errmsg(ctx));
        return;
    }
    nv = ma.nverts;
    nf = ma.nfaces;
    faces = malloc(3 * (size_t)nf * sizeof *faces);
    memcpy(faces, ma.faces, 3 * (size_t)nf * sizeof *faces);
    xyz = malloc(6 * (size_t)nv * sizeof *xyz);
    memcpy(xyz, ma.xyz, 3 * (size_t)nv * sizeof *xyz);
    memcpy(xyz + 3 * nv, mb.xyz, 3 * (size_t)nv * sizeof *xyz);
    for (int l = 0; l < levels; l++) {
        int64_t nv2, *f2;
        double *x2;
        if (es_mesh_subdivide(ctx, nv, nf, faces, 2, xyz, &nv2, &f2, &x2)) {
            fprintf(stderr, "bench_embed: %s\n", es_ctx_errmsg(ctx));
            return;
        }
        free(faces);
        free(xyz);
        faces = malloc(12 * (size_t)nf * sizeof *faces);
        memcpy(faces, f2, 12 * (size_t)nf * sizeof *faces);
        xyz = malloc(6 * (size_t)nv2 * sizeof *xyz);
        memcpy(xyz, x2, 6 * (size_t)nv2 * sizeof *xyz);
        es_free(ctx, f2);
        es_free(ctx, x2);
        nv = nv2;
        nf *= 4;
    }
    if (nv > vmax) goto done;
    if (es_mesh_new(ctx, nv, nf, faces, xyz, &mesh)) goto fail;
    {
        double w0 = bench_wall_s(), c0, tw_new;
        if (es_embedder_new(ctx, mesh, &emb)) goto fail;
        tw_new = bench_wall_s() - w0;
        const double *in[2] = {xyz, xyz + 3 * nv};
        double w[2] = {0.5, 0.5}, *out = malloc(3 * (size_t)nv * sizeof *out);
        int64_t ne = es_mesh_nedges(mesh);
        double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
        es_embed_report r;
        es_embed_opts paper;
        if (sweep_mode) {
            sweep(ctx, emb, nv, in, out, dir, tw_new);
            free(out), free(len), free(al);
            goto done;
        }
        /* midpoint */
        es_embed_opts mo;
        es_embed_opts_init(&mo);
        if (getenv("EDGESPACE_BENCH_TOL"))   /* the accuracy stop, as fractions */
            (void)sscanf(getenv("EDGESPACE_BENCH_TOL"), "%lf,%lf", &mo.refine_rms_tol,
                         &mo.refine_max_tol);
        w0 = bench_wall_s();
        c0 = bench_process_cpu_s();
        if (es_interp_embed(ctx, emb, 2, in, w, NULL, &mo, out, &r, NULL)) goto fail;
        print_row(dir, "midpoint t=0.5", nv, bench_wall_s() - w0, bench_process_cpu_s() - c0,
                  tw_new, &r, 0);
        double cpu_interp = bench_process_cpu_s() - c0;
        /* the same midpoint near the prior of the two shapes (b aligned onto
         * a, their dihedrals): the study's path */
        {
            double *bb = malloc(3 * (size_t)nv * sizeof *bb), rms;
            double *prior = malloc((3 * (size_t)nv + 2 * (size_t)ne) * sizeof *prior);
            double *a2 = malloc(2 * (size_t)ne * sizeof *a2);
            memcpy(bb, xyz + 3 * nv, 3 * (size_t)nv * sizeof *bb);
            es_embed_align(ctx, nv, bb, xyz, NULL, &rms);
            es_dihedral_angles(ctx, mesh, xyz, a2);
            es_dihedral_angles(ctx, mesh, bb, a2 + ne);
            const double *rows[2] = {xyz, bb}, *alr[2] = {a2, a2 + ne};
            es_embed_prior pr = {prior, prior + 3 * nv, prior + 3 * nv + ne, NULL, NULL, NULL};
            es_embed_prior_from_rows(ctx, nv, ne, 2, rows, alr, w, prior, prior + 3 * nv,
                                     prior + 3 * nv + ne);
            es_interp_targets(ctx, mesh, 2, in, w, len, NULL, NULL);
            w0 = bench_wall_s();
            c0 = bench_process_cpu_s();
            if (es_embed_prior_solve(ctx, emb, len, 0, &pr, &mo, out, &r)) goto fail;
            double cpu_prior = bench_process_cpu_s() - c0;
            print_row(dir, "prior t=0.5", nv, bench_wall_s() - w0, cpu_prior, tw_new, &r, 0);
            printf("%-22s %-19s %7lld  prior / interp CPU %.2f; bending %.3f x the prior's, "
                   "%.3g %% bbox from it\n", dir, "  ratio", (long long)nv, cpu_prior / cpu_interp,
                   r.bend_ratio, 100 * r.prior_rms);
            free(bb), free(prior), free(a2);
        }
        /* the published method's stages on the same midpoint, in the same
         * run: stage 1 always (LM here, not the paper's L-BFGS), no refinement */
        es_embed_opts_init(&paper);
        paper.dihedral_mode = ES_EMBED_DIHEDRAL_ON;
        paper.refine_max_iter = 0;
        w0 = bench_wall_s();
        c0 = bench_process_cpu_s();
        if (es_interp_embed(ctx, emb, 2, in, w, NULL, &paper, out, &r, NULL)) goto fail;
        print_row(dir, "paper stages t=0.5", nv, bench_wall_s() - w0, bench_process_cpu_s() - c0,
                  tw_new, &r, 0);
        /* round trip of shape a */
        es_edge_lengths(ctx, mesh, xyz, len);
        es_dihedral_angles(ctx, mesh, xyz, al);
        w0 = bench_wall_s();
        c0 = bench_process_cpu_s();
        if (es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r)) goto fail;
        print_row(dir, "round trip (exact)", nv, bench_wall_s() - w0, bench_process_cpu_s() - c0,
                  tw_new, &r, 1);
        fflush(stdout);
        free(out), free(len), free(al);
    }
    goto done;
fail:
    fprintf(stderr, "bench_embed: %s\n", es_ctx_errmsg(ctx));
done:
    es_embedder_free(emb);
    es_mesh_free(mesh);
    free(faces);
    free(xyz);
    es_meshdata_clear(ctx, &ma);
    es_meshdata_clear(ctx, &mb);
}

int main(int argc, char **argv)
{
    es_ctx *ctx;
    int64_t vmax = argc > 1 ? atoll(argv[1]) : 60000;
    sweep_mode = argc > 1 && strcmp(argv[1], "sweep") == 0;
    if (sweep_mode) vmax = 60000;
    if (es_ctx_new(&ctx)) return 1;
    printf("# %-20s %-19s %7s  %6s %6s  %6s %6s %6s %6s  %9s %8s  %9s %9s\n", "mesh", "case", "V",
           "wall", "cpu", "dih", "lin", "refine", "setup", "rms", "max", "E before", "E after");
    printf("# times in s; dih/lin/refine: wall per stage; setup: embedder_new (analysis)\n");
    if (sweep_mode) {
        run(ctx, "face-study", "s001_neutral", "s001_happy", 0, vmax);
        run(ctx, "sfm_surrey_face_3448", "mean_neutral", "expr_happiness", 2, vmax);
        es_ctx_free(ctx);
        return 0;
    }
    run(ctx, "facecap_arkit", "anim_000", "anim_100", 0, vmax);
    run(ctx, "sfm_surrey_face_3448", "mean_neutral", "expr_happiness", 0, vmax);
    run(ctx, "goast_cactus", "cactus0", "cactus1", 0, vmax);
    run(ctx, "sumner_cat_poses", "cat-01", "cat-02", 0, vmax);
    run(ctx, "face-study", "s001_neutral", "s001_happy", 0, vmax);
    run(ctx, "sfm_surrey_face_3448", "mean_neutral", "expr_happiness", 1, vmax);
    run(ctx, "goast_cactus", "cactus0", "cactus1", 1, vmax);
    run(ctx, "facecap_arkit", "anim_000", "anim_100", 3, vmax);
    run(ctx, "sfm_surrey_face_3448", "mean_neutral", "expr_happiness", 2, vmax);
    es_ctx_free(ctx);
    return 0;
}
