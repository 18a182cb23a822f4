/* tests/study/test_prior_faces.c — embedded meshes that look like the data
 * (the shape-faithful embedding issue), on a study with subjects held out:
 *   a. each held-out face given only as a file comes back near the real mesh
 *      (RMS vertex distance after a rigid fit, in % of its bbox diagonal),
 *      its edges realized to a small max error;
 *   b. the mean of each expression embeds near the Procrustes mean (GPA
 *      without scaling) of the same rows;
 *   c. mean +- 2 sd along PCs 1-3 embed near the same row weights applied to
 *      GPA-aligned vertices (the report's prior distance is exactly that);
 *   d. no more bending than those references, lengths realized;
 *   e. the mean neutral and mean happy faces come out in one frame.
 * With ../shared/data/face-study (argument "face-study"; the slow suite):
 * subjects s028-s030 held out, the bounds. Without it (and always,
 * in the numeric suite): the synthetic face family (datasets-spec/synthetic.md),
 * two subjects held out, the same measures with bounds measured on it.
 * Every number is printed; points whose lengths break the triangle
 * inequality (not realizable) are printed and not held to the bounds. */
#include "es_test.h"
#include "es_test_files.h"

#include <edgespace/edgespace.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct bounds {
    double a_dist, a_max_edge, b_dist, c_dist, bend, len_rms, rot_deg;
} bounds;

/* Positions of xyz rigidly fitted onto ref (both 3 x V): RMS distance over
 * ref's bbox diagonal, after scaling ref to xyz's edge-length sum when
 * scale_ref (a reference of another size: a Procrustes mean). */
static double fitted_distance(es_ctx *ctx, const es_mesh *m, const double *xyz,
                              const double *ref, int scale_ref)
{
    int64_t nv = es_mesh_nverts(m), ne = es_mesh_nedges(m);
    double *a = malloc(3 * (size_t)nv * sizeof *a), *b = malloc(3 * (size_t)nv * sizeof *b);
    double *l = malloc((size_t)ne * sizeof *l), s0 = 0, s1 = 0, rms = INFINITY;
    memcpy(a, xyz, 3 * (size_t)nv * sizeof *a);
    memcpy(b, ref, 3 * (size_t)nv * sizeof *b);
    if (scale_ref && es_edge_lengths(ctx, m, ref, l) == ES_OK) {
        for (int64_t e = 0; e < ne; e++) s0 += l[e];
        es_edge_lengths(ctx, m, xyz, l);
        for (int64_t e = 0; e < ne; e++) s1 += l[e];
        for (int64_t i = 0; i < 3 * nv; i++) b[i] *= s1 / s0;
    }
    if (es_embed_align(ctx, nv, a, b, NULL, &rms) != ES_OK) rms = INFINITY;
    double d = rms / es_bbox_diagonal(nv, b);
    free(a), free(b), free(l);
    return d;
}

/* Procrustes mean (GPA without scaling) of the store rows matching filter. */
static double *procrustes_mean(es_ctx *ctx, es_store *s, const char *filter)
{
    int64_t *rows = NULL, n = 0, nv = es_store_nverts(s);
    double *cfg = NULL, *x = malloc(3 * (size_t)nv * sizeof *x), *mean = NULL;
    if (es_store_select(ctx, s, filter, &rows, &n) != ES_OK || n < 2) goto done;
    cfg = malloc(3 * (size_t)nv * (size_t)n * sizeof *cfg);
    mean = malloc(3 * (size_t)nv * sizeof *mean);
    for (int64_t j = 0; j < n; j++) {
        es_store_read_positions(ctx, s, rows[j], x);
        es_procrustes_from_xyz(nv, x, cfg + 3 * nv * j);
    }
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.scale = 0;
    es_gpa_out out = {x, NULL, NULL, NULL, NULL, NULL};
    es_status rc = es_gpa_align(ctx, nv, 3, (es_mat){cfg, 3 * nv, n, 3 * nv}, &o, &out, NULL);
    if (rc == ES_OK || rc == ES_ENOCONV) es_procrustes_to_xyz(nv, x, mean);
    else free(mean), mean = NULL;
done:
    free(cfg), free(x);
    es_free(ctx, rows);
    return mean;
}

/* Embed a point through the study (what `edgespace embed` does), into xyz. */
static int embed_point(es_ctx *ctx, es_store *s, const char *point, double *xyz,
                       es_embed_report *rep)
{
    es_study_embed_opts o;
    es_study_embed_result res;
    es_study_embed_opts_init(&o);
    o.point = point;
    es_status rc = es_study_embed(ctx, s, &o, xyz, &res);
    ES_CHECK_MSG(rc == ES_OK, "embed %s: %s", point, es_ctx_errmsg(ctx));
    *rep = res.report;
    return rc == ES_OK;
}

/* The rotation angle (degrees) of the rigid fit of a onto b. */
static double rotation_deg(es_ctx *ctx, int64_t nv, const double *a, const double *b)
{
    double *ca = malloc(3 * (size_t)nv * sizeof *ca), *cb = malloc(3 * (size_t)nv * sizeof *cb);
    double r[9], ang = INFINITY;
    es_procrustes_from_xyz(nv, a, ca);
    es_procrustes_from_xyz(nv, b, cb);
    if (es_procrustes_opa(ctx, nv, 3, cb, ca, 0, 0, NULL, r, NULL, NULL) == ES_OK)
        ang = acos(fmax(-1, fmin(1, (r[0] + r[4] + r[8] - 1) / 2))) * 180 / M_PI;
    free(ca), free(cb);
    return ang;
}

/* One realizable target's shape and lengths against the common bounds. */
static void check_realized(const char *what, const es_embed_report *r, const bounds *b)
{
    ES_CHECK_MSG(r->rms_ratio <= b->len_rms, "%s: length RMS %.4g %% > %.4g %%", what,
                 100 * r->rms_ratio, 100 * b->len_rms);
    ES_CHECK_MSG(r->bend_ratio <= b->bend, "%s: bending ratio %.4f > %.3f", what, r->bend_ratio,
                 b->bend);
}

static void evaluate(es_ctx *ctx, const char *store, int64_t nheld, char **held,
                     const char *const *expressions, const bounds *b)
{
    es_store *s = NULL;
    es_mesh *m = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
    if (s) ES_CHECK_OK(ctx, es_store_mesh(ctx, s, &m));
    if (!m) {
        es_store_close(s);
        return;
    }
    int64_t nv = es_mesh_nverts(m);
    double *xyz = malloc(3 * (size_t)nv * sizeof *xyz), *truth = malloc(3 * (size_t)nv * sizeof *truth);
    double *mean_out[3] = {NULL, NULL, NULL};
    char point[4200];
    es_embed_report r;
    /* a. held-out faces from their lengths alone */
    for (int64_t i = 0; i < nheld; i++) {
        snprintf(point, sizeof point, "file:%s", held[i]);
        if (!embed_point(ctx, s, point, xyz, &r)) continue;
        ES_CHECK_OK(ctx, es_meshio_read_positions(ctx, m, held[i], truth));
        double d = fitted_distance(ctx, m, xyz, truth, 0);
        fprintf(stderr, "a %-40s %.4f %% bbox from the real mesh, max edge %.3f %%, length RMS "
                "%.4f %%, bending %.4f\n", strrchr(held[i], '/') + 1, 100 * d, 100 * r.max_rel,
                100 * r.rms_ratio, r.bend_ratio);
        ES_CHECK_MSG(d <= b->a_dist, "a: %s %.4f %% > %.3f %%", held[i], 100 * d, 100 * b->a_dist);
        ES_CHECK_MSG(r.max_rel <= b->a_max_edge, "a: %s max edge %.3f %% > %.3f %%", held[i],
                     100 * r.max_rel, 100 * b->a_max_edge);
        check_realized("a", &r, b);
    }
    /* b. expression means against their Procrustes means */
    for (int k = 0; k < 3; k++) {
        char filter[64];
        snprintf(filter, sizeof filter, "expression=%s", expressions[k]);
        snprintf(point, sizeof point, "mean[%s]", filter);
        double *pm = procrustes_mean(ctx, s, filter);
        mean_out[k] = malloc(3 * (size_t)nv * sizeof *xyz);
        if (!pm || !embed_point(ctx, s, point, mean_out[k], &r)) {
            ES_CHECK_MSG(pm != NULL, "no Procrustes mean of %s", filter);
            free(pm);
            continue;
        }
        double d = fitted_distance(ctx, m, mean_out[k], pm, 1);
        fprintf(stderr, "b %-40s %.4f %% bbox from the Procrustes mean, length RMS %.4f %%, max "
                "%.3f %%, bending %.4f\n", point, 100 * d, 100 * r.rms_ratio, 100 * r.max_rel,
                r.bend_ratio);
        ES_CHECK_MSG(d <= b->b_dist, "b: %s %.4f %% > %.3f %%", point, 100 * d, 100 * b->b_dist);
        check_realized("b", &r, b);
        free(pm);
    }
    /* e. one frame: the mean neutral and mean happy faces are not turned */
    double rot = rotation_deg(ctx, nv, mean_out[0], mean_out[1]);
    fprintf(stderr, "e mean %s vs mean %s: %.3f degrees apart\n", expressions[0], expressions[1],
            rot);
    ES_CHECK_MSG(rot <= b->rot_deg, "e: %.3f degrees apart", rot);
    /* c. mean +- 2 sd along PCs 1-3 against the same weights on GPA-aligned rows */
    es_pca_opts po;
    es_pca_opts_init(&po);
    po.ncomp = 10;
    es_study_pca_opts so;
    es_study_pca_opts_init(&so);
    so.name = "default";
    so.pca = po;
    so.command = "test";
    ES_CHECK_OK(ctx, es_study_pca(ctx, s, &so, NULL, NULL, NULL));
    for (int k = 1; k <= 3; k++)
        for (int sg = -1; sg <= 1; sg += 2) {
            snprintf(point, sizeof point, "mean %c 2*pc:%d", sg < 0 ? '-' : '+', k);
            if (!embed_point(ctx, s, point, xyz, &r)) continue;
            fprintf(stderr, "c %-40s %.4f %% bbox from the weighted GPA rows, length RMS %.4f %%, "
                    "max %.3f %%, bending %.4f%s\n", point, 100 * r.prior_rms, 100 * r.rms_ratio,
                    100 * r.max_rel, r.bend_ratio,
                    r.n_bad_faces ? " (not realizable: lengths break the triangle inequality)"
                                  : "");
            if (r.n_bad_faces) {
                /* no mesh has these lengths: the data's bending decides where they
                 * cannot be met (es_embed_opts.realize_bend), and the report says
                 * how far the lengths had to be moved to form triangles. The
                 * vertex blend itself misses such lengths by far more than the
                 * output does (its start RMS ratio is printed), so the distance
                 * from it is held to what was measured (0.36 % on face-study
                 * mean + 2 sd on PC 1), not to the realizable points' bound */
                fprintf(stderr, "  the vertex blend's own length RMS %.3f %%; %lld lengths moved "
                        "to form triangles, by at most %.3g %%\n", 100 * r.rms_ratio_linear,
                        (long long)r.n_projected, 100 * r.projection_max);
                ES_CHECK_MSG(r.bend_ratio <= b->bend, "c (not realizable): %s bending %.4f > %.3f",
                             point, r.bend_ratio, b->bend);
                ES_CHECK_MSG(r.n_projected > 0 && r.prior_rms <= 2 * b->c_dist,
                             "c (not realizable): %s %.4f %% from the vertex blend", point,
                             100 * r.prior_rms);
                continue;
            }
            ES_CHECK_MSG(r.prior_rms <= b->c_dist, "c: %s %.4f %% > %.3f %%", point,
                         100 * r.prior_rms, 100 * b->c_dist);
            check_realized("c", &r, b);
        }
    for (int k = 0; k < 3; k++) free(mean_out[k]);
    free(xyz), free(truth);
    es_mesh_free(m);
    es_store_abort(s);   /* the PCA was for this test only */
}

/* face-study without three subjects (s028-s030, or those named in the
 * environment variable EDGESPACE_HOLDOUT, e.g. "s001,s013,s022", for a
 * second measurement), as a manifest of absolute paths. */
static int face_study(es_ctx *ctx, const char *data, const char *dir, char **held, int64_t *nheld)
{
    const char *out_subjects[3] = {"s028", "s029", "s030"};
    const char *env = getenv("EDGESPACE_HOLDOUT");
    static char chosen[3][8];
    if (env && sscanf(env, "%4[^,],%4[^,],%4s", chosen[0], chosen[1], chosen[2]) == 3)
        for (int k = 0; k < 3; k++) out_subjects[k] = chosen[k];
    static const char *const expr[3] = {"neutral", "happy", "angry"};
    char man[4200], line[4600], store[4200];
    snprintf(man, sizeof man, "%s/manifest.csv", dir);
    snprintf(store, sizeof store, "%s/faces.h5", dir);
    FILE *f = fopen(man, "w");
    if (!f) return 0;
    fputs("file,subject,expression\n", f);
    *nheld = 0;
    for (int sub = 1; sub <= 30; sub++)
        for (int e = 0; e < 3; e++) {
            char id[16];
            int out = 0;
            snprintf(id, sizeof id, "s%03d", sub);
            for (int k = 0; k < 3; k++) out |= !strcmp(id, out_subjects[k]);
            snprintf(line, sizeof line, "%s/face-study/%s_%s.obj", data, id, expr[e]);
            if (out) held[(*nheld)++] = strdup(line);
            else fprintf(f, "%s,%s,%s\n", line, id, expr[e]);
        }
    fclose(f);
    es_ingest_opts io;
    es_ingest_opts_init(&io);
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, man, &io, NULL));
    return 1;
}

/* The synthetic face family: subjects 0 and 1 held out. */
static int synthetic(es_ctx *ctx, const char *dir, char **held, int64_t *nheld)
{
    es_synth_set set;
    es_synth_opts so;
    char path[4200], man[4200], store[4200];
    es_synth_opts_init(&so);
    so.n = 14;
    es_ctx_set_seed(ctx, 2026);
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_FACE, &so, &set));
    ES_CHECK_OK(ctx, es_synth_write(ctx, &set, dir));
    snprintf(man, sizeof man, "%s/kept.csv", dir);
    snprintf(store, sizeof store, "%s/faces.h5", dir);
    FILE *f = fopen(man, "w");
    if (!f) return 0;
    fputs("file,subject,expression\n", f);
    *nheld = 0;
    for (int64_t i = 0; i < set.nmembers; i++) {
        const char *subject = set.labels[i * set.nlabels], *expression = set.labels[i * set.nlabels + 1];
        snprintf(path, sizeof path, "%s/%s.obj", dir, set.names[i]);
        if (i < 6) held[(*nheld)++] = strdup(path);   /* the first two subjects */
        else fprintf(f, "%s,%s,%s\n", path, subject, expression);
    }
    fclose(f);
    es_synth_set_clear(ctx, &set);
    es_ingest_opts io;
    es_ingest_opts_init(&io);
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, man, &io, NULL));
    return 1;
}

int main(int argc, char **argv)
{
    static const char *const expressions[3] = {"neutral", "happy", "angry"};
    es_ctx *ctx = NULL;
    char *held[16], store[4200];
    int64_t nheld = 0;
    const int real = argc > 1 && !strcmp(argv[1], "face-study");
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    const char *dir = es_test_tmpdir(real ? "prior-face-study" : "prior-synthetic");
    snprintf(store, sizeof store, "%s/faces.h5", dir);
    if (real) {
        const char *data = es_test_shared_data();
        if (!data) ES_TEST_SKIP("../shared/data is not here: face-study checks skipped");
        /* the bounds */
        bounds b = {0.002, 0.005, 0.0012, 0.002, 1.1, 0.0005, 5};
        if (face_study(ctx, data, dir, held, &nheld))
            evaluate(ctx, store, nheld, held, expressions, &b);
    } else {
        /* measured on the synthetic family (dome faces of 780 vertices, 2 of
         * 14 subjects held out): a 0.083 %, b 0.132 %, bending of a and b
         * 1.016. Its +-2 sd points along PCs 1-3 carry the folds of the
         * coarse expression field in their lengths (the nearest-row start
         * shows the same folds), which the vertex blend does not have: c up
         * to 0.90 % and bending up to 1.51 there, held to these bounds as a
         * regression check only. */
        bounds b = {0.002, 0.005, 0.002, 0.011, 1.6, 0.0005, 5};
        if (synthetic(ctx, dir, held, &nheld)) evaluate(ctx, store, nheld, held, expressions, &b);
    }
    for (int64_t i = 0; i < nheld; i++) free(held[i]);
    es_ctx_free(ctx);
    ES_TEST_END();
}
