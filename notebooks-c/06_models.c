/* notebooks-c/06_models.c — Linear models on shape, in both spaces: a
 * repeated-measures face study and allometry on a landmark set.
 *
 * Question. With subject as a block (every subject seen in three
 * expressions), does expression explain shape in edge-length space and in
 * Procrustes space, and how much of the variation does each space give
 * it? On a landmark set with groups, does size (allometry) explain shape
 * beside the groups?
 *
 * Dataset. face-study (../shared/data: 30 subjects x neutral / happy /
 * angry, 9,409 vertices; without it the project's synthetic face family,
 * and the report says so); landmarks_rshapes/apes (167 great-ape skulls, 8
 * landmarks in 2D, 6 species-by-sex groups; skipped with a note when
 * ../shared/data is absent).
 *
 * Method. Faces: ingest -> GPA of the vertices (es_study_gpa) -> the model
 * "~ expression + subject" with permutations within subject
 * (es_study_model: residual randomization, type I sums of squares) on the
 * normalized edge lengths and on the GPA's aligned coordinates, pairwise
 * distances between the expressions' least-squares means, and per-edge
 * tests of expression (F, permutation p, FDR q) drawn on the mean face
 * (expression_edges.png, es_figure_edge_tests). Apes: a truss
 * store of all landmark pairs (es_landmarks_to_store_edges) -> GPA -> the
 * model "~ log(size) + group" in both spaces (size: the sum of the truss
 * lengths, or the centroid size), with its common allometric component;
 * then "~ log(size) * group" in Procrustes space with the groups' slopes
 * compared (distance, angle: UCL, Z, p) and its CAC checked against the
 * additive model's (the pooled within-group vector does not depend on the
 * interaction).
 *
 * Expected finding. Expression is significant in both spaces with the
 * subject blocked; on the apes, log(size) explains a significant share of
 * shape in Procrustes space (the classical allometry of great-ape skulls),
 * and the CAC scores of the two models agree to 1e-12.
 * Numbers agree with R's vegan::adonis2 (tests/tools/test_model_oracle.c).
 */
#include "notebook.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* One model's ANOVA table into the report (and a CSV beside it); the p of
 * term `want` (NaN when absent). */
static double report_model(notebook *nb, const char *space, const es_study_model_result *r,
                           const char *want, FILE *csv)
{
    const es_model *m = r->model;
    double p_want = NAN;
    nb_table(nb, "space|term|df|SS|R^2|F|Z|p");
    for (int64_t j = 0; j < m->nterms; j++) {
        const char *term = r->design->terms[j];
        char p[32];
        /* no p for a term constant within the blocks (the block itself) */
        if (isnan(m->pval[j])) snprintf(p, sizeof p, "not testable");
        else snprintf(p, sizeof p, "%.4f", m->pval[j]);
        nb_row(nb, "%s|%s|%lld|%.4g|%.4f|%.2f|%.2f|%s", space, term, (long long)m->df[j],
               m->ss[j], m->r2[j], m->f[j], m->z[j], p);
        fprintf(csv, "%s,%s,%lld,%.17g,%.17g,%.17g,%.17g\n", space, term, (long long)m->df[j],
                m->ss[j], m->r2[j], m->f[j], m->pval[j]);
        if (!strcmp(term, want)) p_want = m->pval[j];
    }
    nb_row(nb, "%s|Residual|%lld|%.4g| | | | ", space, (long long)m->df_resid, m->rss);
    return p_want;
}

static int fit_slopes(notebook *nb, es_store *st, const char *formula, const char *gpa,
                      const char *block, const char *pairwise, const char *slopes,
                      int64_t perms, const char *name, es_study_model_result **out)
{
    es_study_model_opts o;
    es_status rc;
    es_study_model_opts_init(&o);
    o.formula = formula;
    o.gpa = gpa;
    o.block = block;
    o.pairwise = pairwise;
    o.slopes = slopes;
    o.permutations = perms;
    o.name = name;
    o.command = "notebooks-c/06_models";
    if ((rc = es_study_model(nb->ctx, st, &o, out)) != ES_OK)
        return nb_fail(nb, rc, formula);
    return 0;
}

static int fit(notebook *nb, es_store *st, const char *formula, const char *gpa,
               const char *block, const char *pairwise, int64_t perms, const char *name,
               es_study_model_result **out)
{
    return fit_slopes(nb, st, formula, gpa, block, pairwise, NULL, perms, name, out);
}

/* Allometry by group: the groups' slopes compared, and the CAC of the
 * interaction model against the additive one's (the pooled within-group
 * vector does not depend on the interaction). Returns the largest
 * difference of the CAC scores relative to their largest magnitude. */
static double slopes_by_group(notebook *nb, es_store *st, const es_study_model_result *add,
                              int64_t perms, FILE *csv)
{
    es_study_model_result *ri = NULL;
    double worst = NAN;
    if (fit_slopes(nb, st, "~ log(size) * group", "gpa", NULL, "group", "log(size)", perms,
                   "apes_slopes", &ri))
        return worst;
    nb_h(nb, 3, "Allometric slopes by group (Procrustes space, ~ log(size) * group)");
    report_model(nb, "Procrustes (slopes)", ri, "", csv);
    const es_model_pairwise *pw = ri->pairwise;
    nb_table(nb, "groups|slope distance|UCL 95%|Z|p|angle (deg)|Z|p");
    for (int64_t a = 0; pw && a < pw->nlevels; a++)
        for (int64_t b = a + 1; b < pw->nlevels; b++) {
            const int64_t x = a + b * pw->nlevels;
            nb_row(nb, "%s - %s|%.4g|%.4g|%.2f|%.3f|%.1f|%.2f|%.3f", pw->levels[a],
                   pw->levels[b], pw->dist[x], pw->ucl[x], pw->z[x], pw->pval[x],
                   pw->angle[x] * 57.29577951308232, pw->angle_z[x], pw->angle_p[x]);
        }
    double scale = 0;
    worst = 0;
    for (int64_t i = 0; i < ri->nrows && add->cac_scores && ri->cac_scores; i++) {
        scale = fmax(scale, fabs(add->cac_scores[i]));
        worst = fmax(worst, fabs(add->cac_scores[i] - ri->cac_scores[i]));
    }
    worst = scale > 0 ? worst / scale : NAN;
    nb_p(nb, "The common allometric component (the pooled within-group regression on log size) "
         "of this model gives the same scores as the additive model's: largest difference "
         "%.2g of their largest magnitude.", worst);
    es_study_model_free(ri);
    return worst;
}

static int gpa_of(notebook *nb, es_store *st)
{
    es_study_gpa_opts go;
    es_gpa_report rep;
    es_status rc;
    int64_t n = es_store_nrows(st), *rows = malloc((size_t)(n > 0 ? n : 1) * sizeof *rows);
    if (!rows) return nb_fail(nb, ES_ENOMEM, "GPA");
    for (int64_t i = 0; i < n; i++) rows[i] = i;   /* every row */
    es_study_gpa_opts_init(&go);
    go.name = "gpa";
    go.rows = rows;
    go.nrows = n;
    go.command = "notebooks-c/06_models";
    rc = es_study_gpa(nb->ctx, st, &go, &rep);
    free(rows);
    if (rc != ES_OK) return nb_fail(nb, rc, "GPA");
    nb_p(nb, "GPA: %lld iterations, RMS rho %.4g.", (long long)rep.iterations, rep.rmsrho);
    return 0;
}

/* ---- the face study ------------------------------------------------------------ */

/* Where on the face expression acts: per-edge tests of ~ expression +
 * subject (F, permutation p, FDR q) drawn on the mean face
 * (es_figure_edge_tests); *nsig: edges with q < 0.05. */
static int edge_figure(notebook *nb, es_store *st, int64_t perms, int64_t *nsig)
{
    es_study_model_opts o;
    es_study_model_result *r = NULL;
    es_status rc;
    es_study_model_opts_init(&o);
    o.formula = "~ expression + subject";
    o.block = "subject";
    o.permutations = perms;
    o.edge_term = "expression";
    o.command = "notebooks-c/06_models";
    nb_step(nb, "faces: per-edge tests and their figure");
    if ((rc = es_study_model(nb->ctx, st, &o, &r)) != ES_OK)
        return nb_fail(nb, rc, "per-edge tests");
    *nsig = 0;
    for (int64_t e = 0; e < r->ntests; e++) *nsig += r->edge_q[e] < 0.05;
    rc = es_figure_edge_tests(nb->ctx, st, r, nb_path(nb, "expression_edges.png"));
    es_study_model_free(r);
    if (rc != ES_OK) return nb_fail(nb, rc, "per-edge figure");
    nb_image(nb, "expression_edges.png", "Per-edge F of expression (subject as block) on the "
             "mean face: edges with FDR q < 0.05 coloured on a log scale, the others grey");
    nb_p(nb, "%lld of the edges change with expression at FDR q < 0.05 (%lld permutations "
         "within subject).", (long long)*nsig, (long long)perms);
    return 0;
}

static int faces(notebook *nb, int64_t perms, FILE *csv, double *p_len, double *p_proc,
                 double *r2_len, double *r2_proc, int64_t *n_edges_sig)
{
    char store_path[4400], dir[4400];
    const char *manifest, *source = nb_dataset(nb, "face-study");
    es_ingest_report ir;
    es_store *st = NULL;
    es_study_model_result *rl = NULL, *rp = NULL;
    es_status rc;
    int bad = 0;
    nb_step(nb, "faces: ingest");
    nb_h(nb, 2, "Faces: expression with subject as block");
    if (source) {
        snprintf(dir, sizeof dir, "%s/manifest.csv", source);
        manifest = dir;
        nb_p(nb, "**Data:** `face-study` from `%s` (every subject: neutral, happy, angry).",
             source);
    } else {
        es_synth_opts so;
        es_synth_set set;
        es_synth_opts_init(&so);
        so.n = nb->small ? 8 : 20;
        snprintf(dir, sizeof dir, "%s", nb_path(nb, "synthetic-faces"));
        if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_FACE, &so, &set)) != ES_OK)
            return nb_fail(nb, rc, "generating synthetic faces");
        rc = es_synth_write(nb->ctx, &set, dir);
        es_synth_set_clear(nb->ctx, &set);
        if (rc != ES_OK) return nb_fail(nb, rc, "writing synthetic faces");
        snprintf(dir, sizeof dir, "%s", nb_path(nb, "synthetic-faces/manifest.csv"));
        manifest = dir;
        nb_p(nb, "> **Data: synthetic.** `../shared/data/face-study` was not found, so this "
             "run uses the project's synthetic face family (%lld subjects x 3 expressions; "
             "`datasets-spec/synthetic.md`). The numbers describe that family.",
             (long long)so.n);
    }
    nb_input(nb, "faces manifest", "%s", manifest);
    snprintf(store_path, sizeof store_path, "%s", nb_path(nb, "faces.h5"));
    unlink(store_path);
    if ((rc = es_ingest_manifest(nb->ctx, store_path, manifest, NULL, &ir)) != ES_OK)
        return nb_fail(nb, rc, "ingest");
    if ((rc = es_store_open(nb->ctx, store_path, ES_STORE_WRITE, &st)) != ES_OK)
        return nb_fail(nb, rc, "opening the store");
    nb_step(nb, "faces: GPA and the model in both spaces");
    bad = gpa_of(nb, st) ||
          fit(nb, st, "~ expression + subject", NULL, "subject", "expression", perms,
              "faces_lengths", &rl) ||
          fit(nb, st, "~ expression + subject", "gpa", "subject", NULL, perms,
              "faces_procrustes", &rp);
    if (!bad) {
        nb_p(nb, "%lld meshes; permutations within subject: %lld (residual randomization). "
             "The subject term is constant within its blocks, so it gets no p-value.",
             (long long)rl->nrows, (long long)perms);
        *p_len = report_model(nb, "edge lengths", rl, "expression", csv);
        *p_proc = report_model(nb, "Procrustes", rp, "expression", csv);
        *r2_len = rl->model->r2[0];
        *r2_proc = rp->model->r2[0];
        nb_p(nb, "Expression explains %.1f %% of the edge-length variation and %.1f %% of the "
             "Procrustes variation; subject (identity) most of the rest.",
             100 * *r2_len, 100 * *r2_proc);
        if (rl->pairwise) {
            const es_model_pairwise *pw = rl->pairwise;
            nb_table(nb, "expressions|distance of LS means (edge lengths)|p");
            for (int64_t a = 0; a < pw->nlevels; a++)
                for (int64_t b = a + 1; b < pw->nlevels; b++)
                    nb_row(nb, "%s - %s|%.4g|%.4f", pw->levels[a], pw->levels[b],
                           pw->dist[a + b * pw->nlevels], pw->pval[a + b * pw->nlevels]);
        }
        if (!bad) bad = edge_figure(nb, st, perms, n_edges_sig);
        if (!bad && (rc = es_store_commit(nb->ctx, st)) != ES_OK) bad = nb_fail(nb, rc, "commit");
    }
    es_study_model_free(rl);
    es_study_model_free(rp);
    es_store_close(st);
    return bad;
}

/* ---- allometry on the apes ------------------------------------------------------ */

static int apes(notebook *nb, int64_t perms, FILE *csv, double *p_size_proc, double *p_size_len,
                double *cac_diff)
{
    char lpath[4400], spath[4400], store_path[4400];
    const char *data = nb_dataset(nb, "landmarks_rshapes");
    es_landmarks *lm = NULL;
    es_store *st = NULL;
    es_study_model_result *rl = NULL, *rp = NULL;
    int64_t *edges = NULL, ne = 0;
    es_status rc;
    int bad = 0;
    nb_step(nb, "apes: allometry in both spaces");
    nb_h(nb, 2, "Allometry: great-ape skulls");
    if (!data) {
        nb_p(nb, "> `../shared/data/landmarks_rshapes` was not found: this part is skipped.");
        return 0;
    }
    snprintf(lpath, sizeof lpath, "%s/apes_landmarks.csv", data);
    snprintf(spath, sizeof spath, "%s/apes_specimens.csv", data);
    nb_input(nb, "landmarks", "%s", lpath);
    if ((rc = es_landmarks_read_csv(nb->ctx, lpath, spath, &lm)) != ES_OK)
        return nb_fail(nb, rc, "reading the apes");
    /* the truss: every pair of landmarks */
    edges = calloc((size_t)(lm->k * (lm->k - 1)), sizeof *edges);
    for (int64_t a = 0; edges && a < lm->k; a++)
        for (int64_t b = a + 1; b < lm->k; b++, ne++) edges[2 * ne] = a, edges[2 * ne + 1] = b;
    snprintf(store_path, sizeof store_path, "%s", nb_path(nb, "apes.h5"));
    unlink(store_path);
    if (!edges) {
        bad = nb_fail(nb, ES_ENOMEM, "the truss");
    } else if ((rc = es_landmarks_to_store_edges(nb->ctx, lm, ne, edges, store_path)) != ES_OK ||
               (rc = es_store_open(nb->ctx, store_path, ES_STORE_WRITE, &st)) != ES_OK) {
        bad = nb_fail(nb, rc, "the apes' store");
    } else {
        bad = gpa_of(nb, st) ||
              fit(nb, st, "~ log(size) + group", NULL, NULL, NULL, perms, "apes_lengths", &rl) ||
              fit(nb, st, "~ log(size) + group", "gpa", NULL, NULL, perms, "apes_procrustes",
                  &rp);
    }
    if (!bad) {
        nb_p(nb, "%lld skulls, %lld landmarks in %dD; the truss: all %lld landmark pairs, "
             "scaled to sum 1. `size` is the sum of a skull's truss lengths in edge-length "
             "space and its centroid size in Procrustes space.", (long long)lm->n,
             (long long)lm->k, lm->d, (long long)ne);
        *p_size_len = report_model(nb, "edge lengths", rl, "log(size)", csv);
        *p_size_proc = report_model(nb, "Procrustes", rp, "log(size)", csv);
        if (rp->cac)
            nb_p(nb, "The common allometric component is stored with the Procrustes model "
                 "(`model/apes_procrustes`, datasets `cac` and `cac_scores`).");
        *cac_diff = slopes_by_group(nb, st, rp, perms, csv);
        if ((rc = es_store_commit(nb->ctx, st)) != ES_OK) bad = nb_fail(nb, rc, "commit");
    }
    es_study_model_free(rl);
    es_study_model_free(rp);
    es_store_close(st);
    es_landmarks_free(lm);
    free(edges);
    return bad;
}

int main(int argc, char **argv)
{
    notebook nb;
    double p_len = NAN, p_proc = NAN, r2_len = NAN, r2_proc = NAN;
    double p_size_proc = NAN, p_size_len = NAN, cac_diff = NAN;
    int64_t n_edges_sig = -1;
    int rc = nb_open(&nb, "06_models", "Linear models on shape: blocked designs and allometry, "
                     "in both spaces", argc, argv);
    if (rc) return rc;
    const int64_t perms = nb.small ? 199 : 999;
    nb_p(&nb, "**Question.** With subject as a block, does expression explain face shape in "
         "edge-length and in Procrustes space? Does size explain great-ape skull shape beside "
         "species and sex?");
    nb_p(&nb, "**Expected.** Expression is significant in both spaces; log(size) is "
         "significant for the apes in Procrustes space.");
    FILE *csv = nb_csv_open(&nb, "anova.csv", "space,term,df,ss,r2,f,p");   /* + Z in the report */
    if (!csv) return nb_close(&nb);
    int bad = faces(&nb, perms, csv, &p_len, &p_proc, &r2_len, &r2_proc, &n_edges_sig);
    if (!bad) bad = apes(&nb, perms, csv, &p_size_proc, &p_size_len, &cac_diff);
    nb_csv_close(&nb, csv);
    if (!bad) {
        nb_step(&nb, "self-check");
        nb_check(&nb, "faces: expression p in edge-length space", p_len, "<=", 0.05);
        nb_check(&nb, "faces: expression p in Procrustes space", p_proc, "<=", 0.05);
        nb_check(&nb, "faces: expression R^2 in edge-length space", r2_len, ">", 0.0);
        nb_check(&nb, "faces: expression R^2 in Procrustes space", r2_proc, ">", 0.0);
        nb_check(&nb, "faces: edges with FDR q < 0.05 for expression (figure drawn)",
                 (double)n_edges_sig, ">", 0.0);
        if (!isnan(p_size_proc))
            nb_check(&nb, "apes: log(size) p in Procrustes space", p_size_proc, "<=", 0.05);
        if (!isnan(p_size_proc))
            nb_check(&nb, "apes: CAC scores of ~ log(size) * group vs + group (relative)",
                     cac_diff, "<=", 1e-12);
        if (!isnan(p_size_len))
            nb_p(&nb, "Apes, log(size) in edge-length space: p = %.4f.", p_size_len);
    }
    return nb_close(&nb);
}
