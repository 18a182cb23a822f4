/* tests/tools/test_embed_cli.c — the embed and interp commands (interp
 * --method too): --help, exit statuses (0 ok, 1 failure, 2 usage), what
 * they print, write and store. */
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "es_test_run.h"

#include <edgespace/edgespace.h>

/* The frames dir/<stem>_<i>.obj (i zero-padded to `width` digits) of a
 * sequence do not jump: each is already where the best rigid motion onto
 * the one before would put it. */
static void check_frames_do_not_jump(const char *dir, const char *stem, int width, int nframes)
{
    es_ctx *ctx = NULL;
    es_meshdata prev = {0}, cur = {0};
    char name[64], p[4400];
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    for (int i = 0; ctx && i < nframes; i++) {
        double raw = 0, fitted;
        snprintf(name, sizeof name, "%s_%0*d.obj", stem, width, i);
        snprintf(p, sizeof p, "%s/%s", dir, name);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, p, ES_FORMAT_OBJ, &cur));
        if (i > 0 && cur.nverts == prev.nverts) {
            for (int64_t k = 0; k < 3 * cur.nverts; k++)
                raw += (cur.xyz[k] - prev.xyz[k]) * (cur.xyz[k] - prev.xyz[k]);
            raw = sqrt(raw / (double)cur.nverts);
            ES_CHECK_OK(ctx, es_embed_align(ctx, cur.nverts, cur.xyz, prev.xyz, NULL, &fitted));
            ES_CHECK_MSG(raw <= fitted * (1 + 1e-6) + 1e-9, "%s: %g from the frame before, %g "
                         "after a rigid fit", name, raw, fitted);
        }
        es_meshdata_clear(ctx, &prev);
        prev = cur;
        memset(&cur, 0, sizeof cur);
    }
    if (ctx) es_meshdata_clear(ctx, &prev);
    es_ctx_free(ctx);
}

/* interp --method: the other papers' methods walk between two rows, write
 * every frame, print reports and store them like the default (the ends
 * reproduce the rows: RMS ratio < 1e-8, "init" names the method); an
 * unknown method is a usage error listing the known ones, and a method
 * that walks between rows refuses a mean. */
static void check_methods(const char *dir, const char *store)
{
    static es_test_out r;
    static const char *const methods[] = {"multiscale", "shape-space", "data-driven", "paper",
                                          "data-driven-el"};
    char pat[4400], p[4400], name[64], buf[256];
    for (int m = 0; m < 5; m++) {
        snprintf(pat, sizeof pat, "%s/m%d_%%02d.obj", dir, m);
        snprintf(name, sizeof name, "m%d", m);
        ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "--steps",
               "3", "--method", methods[m], "-o", pat, "--name", name);
        ES_CHECK_MSG(r.status == 0 && strstr(r.out, methods[m]) && strstr(r.out, "RMS ratio") &&
                         strstr(r.out, "stored: /analysis/embed/"),
                     "interp --method %s: %d %s %s", methods[m], r.status, r.out, r.err);
        for (int i = 0; i < 3; i++) {
            snprintf(p, sizeof p, "%s/m%d_%02d.obj", dir, m, i);
            ES_CHECK_MSG(access(p, F_OK) == 0, "missing %s", p);
        }
        es_ctx *ctx = NULL;
        es_store *s = NULL;
        ES_CHECK(es_ctx_new(&ctx) == ES_OK);
        if (ctx) ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
        for (int i = 0; s && i < 3; i += 2) {
            char path[96];
            snprintf(path, sizeof path, "embed/m%d_%02d", m, i);
            ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, path, "rms_ratio", buf, sizeof buf));
            ES_CHECK_MSG(atof(buf) < 1e-8, "%s %s: end frame RMS ratio %s", methods[m], path, buf);
            ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, path, "init", buf, sizeof buf));
            ES_CHECK_MSG(strcmp(buf, methods[m]) == 0, "%s: init '%s'", path, buf);
        }
        es_store_close(s);
        es_ctx_free(ctx);
    }
    /* --seed and --tries: the same seed gives the same frames, byte for byte;
     * another seed with one hierarchy other frames */
    {
        char f[3][4400];
        for (int k = 0; k < 3; k++) {
            snprintf(f[k], sizeof f[k], "%s/seed%d.obj", dir, k);
            ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-2",
                   "--steps", "1", "--t0", "0.5", "--method", "multiscale", "--seed",
                   k == 2 ? "8" : "7", "--tries", "1", "-o", f[k], "--no-store");
            ES_CHECK_MSG(r.status == 0, "--seed: %d %s", r.status, r.err);
        }
        size_t n0 = 0, n1 = 0, n2 = 0;
        char *b0 = es_test_slurp(f[0], &n0), *b1 = es_test_slurp(f[1], &n1);
        char *b2 = es_test_slurp(f[2], &n2);
        ES_CHECK(b0 && b1 && b2 && n0 == n1 && memcmp(b0, b1, n0) == 0);
        ES_CHECK(b0 && b2 && (n0 != n2 || memcmp(b0, b2, n0) != 0));
        free(b0), free(b1), free(b2);
        ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-2", "--method",
               "multiscale", "--tries", "0", "-o", f[0]);
        ES_CHECK_MSG(r.status == 2 && strstr(r.err, "--tries"), "%d %s", r.status, r.err);
        /* data-driven's K and sigma: taken (recorded in the stored parameters), bad
         * values refused */
        snprintf(pat, sizeof pat, "%s/dd_%%d.obj", dir);
        ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-2", "--method",
               "data-driven", "--knn", "1", "--sigma", "0.5", "--steps", "3", "-o", pat,
               "--name", "ddk");
        ES_CHECK_MSG(r.status == 0, "--knn 1 --sigma 0.5: %d %s", r.status, r.err);
        {
            es_ctx *c2 = NULL;
            es_store *st = NULL;
            ES_CHECK(es_ctx_new(&c2) == ES_OK);
            if (c2) ES_CHECK_OK(c2, es_store_open(c2, store, ES_STORE_READ, &st));
            if (st) {
                char par[1024];
                ES_CHECK_OK(c2, es_store_get_attr(c2, st, "embed/ddk_01", "params", par,
                                                  sizeof par));
                ES_CHECK_MSG(strstr(par, "knn=1;") && strstr(par, "sigma=0.5"), "%s", par);
            }
            es_store_close(st);
            es_ctx_free(c2);
        }
        ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-2", "--method",
               "data-driven", "--sigma", "0", "-o", pat);
        ES_CHECK_MSG(r.status == 2 && strstr(r.err, "--sigma"), "%d %s", r.status, r.err);
    }
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "--method",
           "sideways", "-o", pat);
    ES_CHECK_MSG(r.status == 2 && strstr(r.err, "known: edge-length"), "%d %s", r.status, r.err);
    ES_RUN(&r, dir, "interp", store, "--from", "mean", "--to", "row:mesh-1", "--method",
           "multiscale", "-o", pat, "--no-store");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "row:ID"), "%d %s", r.status, r.err);
}

/* embed --paper / --method paper: the published pipeline runs its stage 1
 * (L-BFGS) on an open mesh (two boundary loops) as on a closed one (the old
 * --paper started from the prior's positions and ran 0 dihedral iterations
 * there), says so, and is stored like any embedding. interp --method
 * conformal on the same open tubes. */
static void check_paper_conformal(const char *dir)
{
    static es_test_out r;
    char tubes[4200], store[4400], man[4400], out[4400];
    es_ctx *ctx = NULL;
    es_synth_opts so;
    es_synth_set set;
    snprintf(tubes, sizeof tubes, "%s/tubes", dir);
    snprintf(store, sizeof store, "%s/tubes.h5", dir);
    snprintf(man, sizeof man, "%s/manifest.csv", tubes);
    snprintf(out, sizeof out, "%s/paper.obj", dir);
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    es_synth_opts_init(&so);
    so.n = 3;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE, &so, &set));
    ES_CHECK_OK(ctx, es_synth_write(ctx, &set, tubes));
    ES_RUN(&r, dir, "ingest", "-q", store, "--manifest", man);
    ES_CHECK_MSG(r.status == 0, "ingest tubes: %s", r.err);
    for (int k = 0; k < 2; k++) {
        char point[512], *it;
        snprintf(point, sizeof point, "0.5*row:%s + 0.5*row:%s", set.names[0], set.names[2]);
        if (k)
            ES_RUN(&r, dir, "embed", store, "--point", point, "-o", out, "--method", "paper",
                   "--name", "p1");
        else
            ES_RUN(&r, dir, "embed", store, "--point", point, "-o", out, "--paper");
        it = strstr(r.out, "stage 1 ");
        ES_CHECK_MSG(r.status == 0 && strstr(r.out, "published pipeline") && it &&
                         atol(it + 8) > 0 && strstr(r.out, "refinement 0"),
                     "embed --paper on an open mesh: %d %s %s", r.status, r.out, r.err);
    }
    ES_RUN(&r, dir, "embed", store, "--point", "mean", "-o", out, "--method", "fast");
    ES_CHECK_MSG(r.status == 2 && strstr(r.err, "default or paper"), "%d %s", r.status, r.err);
    /* interp --method conformal: one row to the sphere; the open tube closed
     * off (two apexes more in the files), the last frame realizes the
     * factors, results stored on the store's vertices */
    {
        char pat[4400], row[300], p[4400], buf[64];
        es_meshdata md = {0};
        es_store *s = NULL;
        snprintf(pat, sizeof pat, "%s/conf_%%d.obj", dir);
        snprintf(row, sizeof row, "row:%s", set.names[1]);
        ES_RUN(&r, dir, "interp", store, "--from", row, "--method", "conformal", "--steps", "3",
               "-o", pat, "--name", "conf");
        ES_CHECK_MSG(r.status == 0 && strstr(r.out, "k = 0.5 (conformal; 2 holes closed"),
                     "interp --method conformal: %d %s %s", r.status, r.out, r.err);
        snprintf(p, sizeof p, "%s/conf_2.obj", dir);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, p, ES_FORMAT_OBJ, &md));
        ES_CHECK(md.nverts == set.nverts + 2);
        es_meshdata_clear(ctx, &md);
        ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
        if (s) {
            ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "embed/conf_02", "rms_ratio", buf,
                                               sizeof buf));
            ES_CHECK_MSG(atof(buf) < 1e-8, "conformal k = 1: RMS ratio %s", buf);
            ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "embed/conf_02", "init", buf, sizeof buf));
            ES_CHECK_MSG(!strcmp(buf, "conformal"), "init %s", buf);
        }
        es_store_close(s);
        ES_RUN(&r, dir, "interp", store, "--from", row, "--to", row, "--method", "conformal",
               "-o", pat, "--no-store");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "--from only"), "%d %s", r.status, r.err);
    }
    es_synth_set_clear(ctx, &set);
    es_ctx_free(ctx);
}

int main(void)
{
    static es_test_out r;
    char store[4200], p[4400], pat[4400], out[4400];
    const char *dir;
    ES_TEST_BEGIN();
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE is not set");
    dir = es_test_tmpdir("cli-embed");
    snprintf(store, sizeof store, "%s/s.h5", dir);
    for (int k = 0; k < 3; k++) {
        snprintf(p, sizeof p, "%s/mesh-%d.obj", dir, k);
        ES_CHECK(es_test_write_torus(p, 16, 8, k) == 0);
    }
    const char *verbs[2] = {"embed", "interp"};
    for (int k = 0; k < 2; k++) {
        ES_RUN(&r, dir, verbs[k], "--help");
        ES_CHECK(r.status == 0 && strstr(r.out, "usage: edgespace ") && strstr(r.out, verbs[k]));
        ES_RUN(&r, dir, verbs[k], "--bogus");
        ES_CHECK(r.status == 2);
        ES_RUN(&r, dir, verbs[k]);
        ES_CHECK(r.status == 2);
    }
    snprintf(p, sizeof p, "%s/mesh-0.obj", dir);
    snprintf(pat, sizeof pat, "%s/mesh-1.obj", dir);
    snprintf(out, sizeof out, "%s/mesh-2.obj", dir);
    ES_RUN(&r, dir, "ingest", "-q", store, p, pat, out);
    ES_CHECK_MSG(r.status == 0, "ingest: %s", r.err);

    /* interp: a sequence of 3 frames; the pattern expands; reports stored */
    snprintf(pat, sizeof pat, "%s/seq_%%02d.obj", dir);
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "--steps", "3",
           "-o", pat);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "t = 0.5") && strstr(r.out, "RMS ratio"),
                 "interp: %d %s %s", r.status, r.out, r.err);
    for (int i = 0; i < 3; i++) {
        snprintf(p, sizeof p, "%s/seq_%02d.obj", dir, i);
        ES_CHECK_MSG(access(p, F_OK) == 0, "missing %s", p);
    }
    check_frames_do_not_jump(dir, "seq", 2, 3);
    /* between points that are not both rows: frames exist, do not jump,
     * are stored; too far an extrapolation is refused naming t */
    {
        snprintf(pat, sizeof pat, "%s/walk_%%d.obj", dir);
        ES_RUN(&r, dir, "interp", store, "--from", "mean", "--to", "row:mesh-2", "--steps", "3",
               "-o", pat, "--name", "walk");
        ES_CHECK_MSG(r.status == 0 && strstr(r.out, "t = 0.5") && strstr(r.out, "walk_NN"),
                     "interp between points: %d %s %s", r.status, r.out, r.err);
        check_frames_do_not_jump(dir, "walk", 1, 3);
        /* the frame at the row end is that row's prior alone (recorded) and
         * is that row again */
        {
            es_ctx *c2 = NULL;
            es_mesh *m2 = NULL;
            es_store *st = NULL;
            int64_t nw = 0;
            char w2[4300], init[256] = "";
            snprintf(p, sizeof p, "%s/mesh-2.obj", dir);
            snprintf(w2, sizeof w2, "%s/walk_2.obj", dir);
            double *xw = es_test_obj_positions(w2, &nw), worst = 0;
            ES_CHECK(es_ctx_new(&c2) == ES_OK);
            if (c2) ES_CHECK_OK(c2, es_meshio_read(c2, p, &m2));
            if (m2 && xw && nw == es_mesh_nverts(m2)) {
                int64_t ne = es_mesh_nedges(m2);
                double *l0 = malloc((size_t)ne * sizeof *l0), *l1 = malloc((size_t)ne * sizeof *l1);
                ES_CHECK_OK(c2, es_edge_lengths(c2, m2, es_mesh_xyz(m2), l0));
                ES_CHECK_OK(c2, es_edge_lengths(c2, m2, xw, l1));
                for (int64_t e = 0; e < ne; e++) worst = fmax(worst, fabs(l1[e] / l0[e] - 1));
                free(l0), free(l1);
            }
            ES_CHECK_MSG(m2 && xw && worst < 1e-9, "walk end at row mesh-2: edges %g off", worst);
            if (c2) ES_CHECK_OK(c2, es_store_open(c2, store, ES_STORE_READ, &st));
            if (st)
                ES_CHECK_OK(c2, es_store_get_attr(c2, st, "embed/walk_02", "init", init,
                                                  sizeof init));
            ES_CHECK_MSG(strstr(init, "prior of 1 rows"), "walk_02 init: '%s'", init);
            es_store_close(st);
            free(xw);
            es_mesh_free(m2);
            es_ctx_free(c2);
        }
        ES_RUN(&r, dir, "info", store);
        ES_CHECK_MSG(strstr(r.out, "walk_02"), "walk not stored: %s", r.out);
        snprintf(p, sizeof p, "%s/far_0.obj", dir);
        snprintf(pat, sizeof pat, "%s/far_%%d.obj", dir);
        ES_RUN(&r, dir, "interp", store, "--from", "mean", "--to", "row:mesh-2", "--steps", "2",
               "--t1", "400", "-o", pat, "--no-store");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "at t = 400"), "far extrapolation: %d %s",
                     r.status, r.err);
        /* refused before any frame is written */
        ES_CHECK_MSG(access(p, F_OK) != 0, "a refused walk left %s", p);
        ES_RUN(&r, dir, "interp", store, "--from", "mean[nothing=1]", "--to", "row:mesh-2",
               "-o", pat, "--no-store");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "nothing"), "bad point: %d %s", r.status,
                     r.err);
    }
    /* pc:K with several PCAs stored: --pca names the one meant */
    ES_RUN(&r, dir, "pca", store, "--name", "one", "-k", "2");
    ES_CHECK_MSG(r.status == 0, "pca one: %s", r.err);
    ES_RUN(&r, dir, "pca", store, "--name", "two", "-k", "1");
    ES_CHECK_MSG(r.status == 0, "pca two: %s", r.err);
    snprintf(out, sizeof out, "%s/pc.obj", dir);
    ES_RUN(&r, dir, "embed", store, "--point", "mean + 0.5*pc:1", "-o", out, "--no-store");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "--pca NAME"), "pc:K, two PCAs: %d %s", r.status,
                 r.err);
    ES_RUN(&r, dir, "embed", store, "--point", "mean + 0.5*pc:1", "--pca", "one", "-o", out,
           "--no-store");
    ES_CHECK_MSG(r.status == 0, "embed --pca one: %s", r.err);
    /* a memory limit below the estimated need: refused in one line naming it,
     * before anything is embedded; a size that is not one: a usage error */
    remove(out);
    ES_RUN(&r, dir, "embed", store, "--point", "mean", "-o", out, "--no-store", "--max-memory",
           "100K");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "needs about") &&
                 strstr(r.err, "more than the memory limit of 0.102 MB") &&
                 access(out, F_OK) != 0, "--max-memory 100K: %d %s", r.status, r.err);
    ES_RUN(&r, dir, "embed", store, "--point", "mean", "-o", out, "--no-store", "--max-memory",
           "lots");
    ES_CHECK_MSG(r.status == 2, "--max-memory lots: %d %s", r.status, r.err);
    snprintf(pat, sizeof pat, "%s/pcwalk_%%d.obj", dir);
    ES_RUN(&r, dir, "interp", store, "--from", "mean", "--to", "mean + pc:1", "--pca", "two",
           "--steps", "2", "-o", pat, "--no-store");
    ES_CHECK_MSG(r.status == 0, "interp --pca two: %s", r.err);
    /* %% in the pattern is a literal percent sign */
    snprintf(pat, sizeof pat, "%s/pct_%%d%%%%.obj", dir);
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "--steps", "2",
           "--refine-iters", "0", "--no-store", "-o", pat);
    snprintf(p, sizeof p, "%s/pct_1%%.obj", dir);
    ES_CHECK_MSG(r.status == 0 && access(p, F_OK) == 0, "%%%% pattern: %d %s", r.status, r.err);
    snprintf(pat, sizeof pat, "%s/two_%%d_%%d.obj", dir);
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "--steps", "2",
           "-o", pat);
    ES_CHECK(r.status == 2 && strstr(r.err, "pattern"));
    snprintf(pat, sizeof pat, "%s/seq_%%02d.obj", dir);
#if ES_HAVE_FIGURES
    /* render: a view direction of 0,0,0 is a usage error */
    snprintf(p, sizeof p, "%s/seq_00.obj", dir);
    snprintf(out, sizeof out, "%s/seq_00.png", dir);
    ES_RUN(&r, dir, "render", p, "--view", "0,0,0", "-o", out);
    ES_CHECK_MSG(r.status == 2 && strstr(r.err, "direction"), "render --view 0,0,0: %d %s",
                 r.status, r.err);
    ES_RUN(&r, dir, "render", p, "--view", "0,0,-1", "--width", "64", "--height", "64", "-o", out);
    ES_CHECK_MSG(r.status == 0 && access(out, F_OK) == 0, "render: %d %s", r.status, r.err);
#endif
    ES_RUN(&r, dir, "info", store);
    ES_CHECK_MSG(strstr(r.out, "seq_00") && strstr(r.out, "seq_02"), "info: %s", r.out);
    /* weights, extrapolation */
    snprintf(out, sizeof out, "%s/w.ply", dir);
    ES_RUN(&r, dir, "interp", store, "--weights", "0.5*row:mesh-0 + 0.7*row:mesh-1 - 0.2*row:mesh-2",
           "-o", out, "--no-store");
    ES_CHECK_MSG(r.status == 0 && access(out, F_OK) == 0, "weights: %s", r.err);
    ES_RUN(&r, dir, "interp", store, "--weights", "0.5*row:mesh-0 +* row:mesh-1", "-o", out);
    ES_CHECK(r.status == 2);
    /* a walk between rows that extrapolates out of edge-length space is
     * refused naming t and the edge, as between points (rows used to clamp
     * the lengths), and writes no frame */
    {
        char far[4300], first[4300];
        snprintf(far, sizeof far, "%s/far_%%02d.obj", dir);
        snprintf(first, sizeof first, "%s/far_00.obj", dir);
        ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "--t1",
               "1e6", "--steps", "3", "-o", far, "--no-store");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "outside edge-length space") &&
                     strstr(r.err, "t = ") && access(first, F_OK) != 0,
                     "rows far out: %d %s", r.status, r.err);
        ES_RUN(&r, dir, "interp", store, "--weights", "-1e6*row:mesh-0 + 1000001*row:mesh-1",
               "-o", out, "--no-store");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "outside edge-length space"),
                     "weights far out: %d %s", r.status, r.err);
    }
    /* the walk's results exist: refused before a frame is written */
    {
        char again[4300], first[4300];
        snprintf(again, sizeof again, "%s/again_%%02d.obj", dir);
        snprintf(first, sizeof first, "%s/again_00.obj", dir);
        ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "-o", again,
               "--name", "seq", "--steps", "3");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "result embed/seq_00 exists already") &&
                     access(first, F_OK) != 0, "interp again: %d %s", r.status, r.err);
    }
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:nope", "-o", pat,
           "--replace");
    ES_CHECK(r.status == 1 && strstr(r.err, "nope"));
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-1", "-o", out);
    ES_CHECK(r.status == 2 && strstr(r.err, "pattern"));

    check_methods(dir, store);
    check_paper_conformal(dir);

    /* embed a stored row from the nearest other start, and from a given row */
    snprintf(out, sizeof out, "%s/e.obj", dir);
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--init", "row:mesh-0");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "init: row mesh-0") &&
                 strstr(r.out, "stored: /analysis/embed/e"), "embed: %d %s %s", r.status, r.out,
                 r.err);
    /* embed/e exists: refused before solving, and no mesh is left behind */
    {
        char e2[4300];
        snprintf(e2, sizeof e2, "%s/e2.obj", dir);
        ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", e2, "--name", "e");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "result embed/e exists already") &&
                     access(e2, F_OK) != 0, "embed again: %d %s", r.status, r.err);
    }
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--init", "mean",
           "--replace");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "circular mean"), "embed mean: %s", r.err);
    /* from a given mesh: it is the alignment reference too, so a mesh moved
     * rigidly brings the output along; a mesh of another topology is refused */
    {
        char moved[4300], other[4300];
        int64_t nv = 0;
        double *x;
        snprintf(p, sizeof p, "%s/mesh-2.obj", dir);
        snprintf(moved, sizeof moved, "%s/moved.obj", dir);
        x = es_test_obj_positions(p, &nv);
        if (x) {
            int64_t V = 16 * 8, F = 2 * V;
            double *xt = malloc(3 * (size_t)V * sizeof *xt);
            int64_t *faces = malloc(3 * (size_t)F * sizeof *faces);
            es_test_torus(16, 8, 2, xt, faces);
            for (int64_t i = 0; i < 3 * nv; i++) x[i] += i % 3 == 0 ? 10.0 : 0.0;
            ES_CHECK(nv == V && es_test_write_obj(moved, V, x, F, faces) == 0);
            snprintf(pat, sizeof pat, "mesh:%s", moved);
            ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--init", pat,
                   "--no-store");
            ES_CHECK_MSG(r.status == 0 && strstr(r.out, "init: mesh "), "embed mesh: %d %s",
                         r.status, r.err);
            int64_t nout = 0;
            double *y = es_test_obj_positions(out, &nout), d = 0;
            for (int64_t i = 0; y && nout == nv && i < 3 * nv; i++)
                d = fmax(d, fabs(y[i] - x[i]));
            ES_CHECK_MSG(y && nout == nv && d < 1e-6, "embed from a moved mesh: %g off it", d);
            free(y), free(x), free(xt), free(faces);
        }
        snprintf(other, sizeof other, "%s/tri.obj", dir);
        es_test_write_file(other, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        snprintf(pat, sizeof pat, "mesh:%s", other);
        ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--init", pat,
               "--replace");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "do not match the store's topology"),
                     "embed from another topology: %d %s", r.status, r.err);
        snprintf(pat, sizeof pat, "%s/seq_%%02d.obj", dir);
    }
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--replace");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "prior of 1 row (weight 1 on mesh-2)") &&
                 strstr(r.out, "shape: bending"), "embed with the prior: %s", r.out);
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--init", "nearest",
           "--replace");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "nearest row mesh-2") &&
                 !strstr(r.out, "shape: bending"), "embed nearest: %s", r.out);
    /* per-vertex residuals as CSV, drawn by render --scalars */
    {
        char res[4300], png[4300];
        size_t n = 0;
        snprintf(res, sizeof res, "%s/res.csv", dir);
        snprintf(png, sizeof png, "%s/res.png", dir);
        ES_RUN(&r, dir, "embed", store, "--point", "0.5*row:mesh-0 + 0.5*row:mesh-1", "-o", out,
               "--residuals", res, "--no-store");
        ES_CHECK_MSG(r.status == 0 && strstr(r.out, "per-vertex residuals"), "--residuals: %s",
                     r.err);
        char *text = es_test_slurp(res, &n), *line = text ? strchr(text, '\n') : NULL;
        int rows = 0, bad = 0;
        ES_CHECK(text && !strncmp(text, "closure,edge_error,deviation\n", 29));
        while (line && line[1]) {
            char *end;
            double a = strtod(line + 1, &end), b = end && *end == ',' ? strtod(end + 1, &end) : -1;
            double c = end && *end == ',' ? strtod(end + 1, &end) : -1;
            bad += !(a >= 0 && b >= 0 && c >= 0 && isfinite(a) && isfinite(b) && isfinite(c));
            rows++;
            line = strchr(line + 1, '\n');
        }
        ES_CHECK_MSG(rows == 16 * 8 && bad == 0, "residual CSV: %d rows, %d bad", rows, bad);
        free(text);
#if ES_HAVE_FIGURES
        ES_RUN(&r, dir, "render", out, "--scalars", res, "--width", "64", "--height", "64", "-o",
               png);
        ES_CHECK_MSG(r.status == 0 && access(png, F_OK) == 0, "render --scalars: %s", r.err);
#endif
    }
    {
        es_ctx *ctx;
        es_store *s = NULL;
        double *v = NULL;
        int64_t n = 0;
        char buf[64];
        es_ctx_new(&ctx);
        ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
        if (s) {
            ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, "embed/e/vertex_closure", &v, &n));
            ES_CHECK(n == es_store_nverts(s));
            ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "embed/e", "rms_ratio", buf, sizeof buf));
            ES_CHECK(atof(buf) < 1e-6);
            es_free(ctx, v);
        }
        es_store_close(s);
        es_ctx_free(ctx);
    }
    /* --refine-iters bounds the refinement; 0 leaves the linear stages' result */
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--init", "row:mesh-0",
           "--refine-iters", "0", "--no-store");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "refinement 0"), "refine-iters 0: %s %s", r.out,
                 r.err);
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--refine-iters", "many");
    ES_CHECK(r.status == 2 && strstr(r.err, "--refine-iters"));
    snprintf(p, sizeof p, "%s/r_%%02d.obj", dir);
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-2", "--steps", "2",
           "--refine-iters", "2", "--no-store", "-o", p);
    ES_CHECK_MSG(r.status == 0 && !strstr(r.out, "refinement 3") && strstr(r.out, "RMS ratio"),
                 "interp --refine-iters: %s %s", r.out, r.err);
    ES_RUN(&r, dir, "interp", store, "--from", "row:mesh-0", "--to", "row:mesh-2",
           "--refine-iters", "-1", "-o", p);
    ES_CHECK(r.status == 2);
    ES_RUN(&r, dir, "embed", store, "--point", "nothing", "-o", out);
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "edgespace embed: "), "%s", r.err);
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--init", "sideways");
    ES_CHECK(r.status != 0);
    ES_RUN(&r, dir, "embed", store, "--point", "row:mesh-2", "-o", out, "--scale", "-1");
    ES_CHECK(r.status == 2);
    ES_TEST_END();
}
