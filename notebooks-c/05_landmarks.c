/* notebooks-c/05_landmarks.c — Landmarks: group differences in Procrustes
 * space and in the edge lengths of a triangulation.
 *
 * Question. On a classical landmark set with known groups, do GPA and a
 * group test find the groups, and does the same test on the scaled edge
 * lengths of a triangulation of the landmarks (a "truss") reach the same
 * verdict?
 *
 * Dataset. landmarks_rshapes/apes (../shared/data: 167 great-ape skulls, 8
 * landmarks in 2D, 6 groups by species and sex; R package shapes, Dryden).
 * Without ../shared/data: 12 vertices of each mesh of the project's
 * synthetic face family (3D, groups = expression), and the report says so.
 *
 * Method. es_landmarks_read_csv -> full GPA (es_gpa_align) -> tangent
 * coordinates and their PCA (es_gpa_tangent, es_gpa_pca) -> Procrustes
 * distances (es_compare_distances) -> one-factor permutation test
 * (es_compare_groups). Triangulation: Delaunay triangulation of the
 * Procrustes mean (projected on its best-fitting plane for 3D data; the
 * empty-circumcircle test over all triples, fine for a dozen landmarks) ->
 * truss lengths (es_landmarks_truss_lengths) scaled to sum 1 -> PCA
 * (es_pca_fit), the same group test, and the Mantel correlation of the two
 * spaces' distances (es_compare_mantel).
 *
 * Expected finding. Both spaces separate the groups (p < 0.05); their
 * distances agree strongly, since a triangulation of a few landmarks in 2D
 * is rigid and determines the configuration.
 */
#include "notebook.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct study {
    es_landmarks *lm;
    const char *what;
    int64_t n, k;
    int d;
    int64_t *group, ngroups;
    const char **gname;        /* ngroups, borrowed */
    const char **glabel;       /* n, borrowed */
    double *aligned, *mean;    /* k*d x n, k*d */
    double *d_proc, *d_len;    /* n x n */
    int64_t ntri, nedges;
    int64_t tri[3 * 64], edges[2 * 192];
    double *len;               /* nedges x n, scaled to sum 1 */
    es_group_stats g_proc, g_len;
    double mantel_rho, mantel_p;
} study;

/* ---- 1. data ------------------------------------------------------------------ */

static int load(notebook *nb, study *s)
{
    const char *dir;
    es_status rc;
    int64_t col;
    nb_step(nb, "load: landmark configurations and groups");
    dir = nb_dataset(nb, "landmarks_rshapes");
    if (dir) {
        char lp[4352], sp[4352];
        snprintf(lp, sizeof lp, "%s/apes_landmarks.csv", dir);
        snprintf(sp, sizeof sp, "%s/apes_specimens.csv", dir);
        if ((rc = es_landmarks_read_csv(nb->ctx, lp, sp, &s->lm)) != ES_OK)
            return nb_fail(nb, rc, "reading the apes");
        s->what = "apes";
        nb_p(nb, "**Data:** `landmarks_rshapes/apes` from `%s`: great-ape skulls, %lld "
             "landmarks in %dD, groups by species and sex (R package shapes: gor = gorilla, "
             "pan = chimpanzee, pongo = orang-utan; f = female, m = male).", dir,
             (long long)s->lm->k, s->lm->d);
    } else {
        es_synth_opts so;
        es_synth_set set;
        FILE *f;
        char lp[4352];
        const int64_t K = 12;
        es_synth_opts_init(&so);
        so.n = 20;   /* cheap; fewer subjects leave Procrustes space short of power */
        if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_FACE, &so, &set)) != ES_OK)
            return nb_fail(nb, rc, "synthetic faces");
        /* landmarks: K vertices spread over the rings of the face (the
         * family's vertices run from the centre outwards), written as the
         * long CSV every landmark reader takes */
        snprintf(lp, sizeof lp, "%s", nb_path(nb, "synthetic_landmarks.csv"));
        f = nb_csv_open(nb, "synthetic_landmarks.csv", "specimen,landmark,x,y,z");
        if (f) {
            for (int64_t i = 0; i < set.nmembers; i++)
                for (int64_t j = 0; j < K; j++) {
                    int64_t v = (int64_t)(((double)j + 0.5) * (double)set.nverts / (double)K);
                    const double *x = set.xyz + 3 * (set.nverts * i + v);
                    fprintf(f, "%s,%lld,%.10g,%.10g,%.10g\n", set.names[i], (long long)j + 1,
                            x[0], x[1], x[2]);
                }
        }
        if (nb_csv_close(nb, f) == 0) {
            FILE *g = nb_csv_open(nb, "synthetic_specimens.csv", "specimen,group");
            for (int64_t i = 0; g && i < set.nmembers; i++)
                fprintf(g, "%s,%s\n", set.names[i], set.labels[i * set.nlabels + 1]);
            nb_csv_close(nb, g);
        }
        es_synth_set_clear(nb->ctx, &set);
        if (nb->failed) return 1;
        if ((rc = es_landmarks_read_csv(nb->ctx, lp, nb_path(nb, "synthetic_specimens.csv"),
                                        &s->lm)) != ES_OK)
            return nb_fail(nb, rc, "reading the synthetic landmarks");
        s->what = "synthetic face landmarks";
        nb_input(nb, "dataset", "12 vertices of es_synth face, %lld subjects", (long long)so.n);
        nb_p(nb, "> **Data: synthetic.** `../shared/data/landmarks_rshapes` was not found (or "
             "`--synthetic` was given), so the landmarks are 12 vertices of each mesh of the "
             "project's synthetic face family (%lld subjects x {neutral, happy, angry}; 3D), "
             "grouped by expression.",
             (long long)so.n);
    }
    s->n = s->lm->n;
    s->k = s->lm->k;
    s->d = s->lm->d;
    col = es_landmarks_find_column(s->lm, "group");
    if (col < 0) return nb_fail(nb, ES_ENOTFOUND, "a 'group' column");
    s->glabel = malloc(sizeof(char *) * (size_t)s->n);
    if (!s->glabel) return nb_fail(nb, ES_ENOMEM, "groups");
    for (int64_t i = 0; i < s->n; i++)
        s->glabel[i] = s->lm->labels[i * s->lm->ncols + col];
    if ((rc = es_groups_from_labels(nb->ctx, s->glabel, s->n, &s->group, &s->gname,
                                    &s->ngroups)) != ES_OK)
        return nb_fail(nb, rc, "groups");
    nb_p(nb, "%lld specimens, %lld landmarks in %dD, %lld groups.", (long long)s->n,
         (long long)s->k, s->d, (long long)s->ngroups);
    return 0;
}

/* ---- 2. Procrustes space ----------------------------------------------------------- */

static int scatter(notebook *nb, const study *s, const double *x, const double *y,
                   const char *file, const char *title, const char *xl, const char *yl)
{
    es_scatter_spec sp;
    es_status rc;
    es_scatter_spec_init(&sp);
    sp.frame.title = title;
    sp.frame.xlabel = xl;
    sp.frame.ylabel = yl;
    sp.n = s->n;
    sp.x = x;
    sp.y = y;
    sp.labels = s->glabel;
    sp.legend_title = "group";
    sp.marker_radius = 3;
    if ((rc = es_plot_scatter(nb->ctx, &sp, nb_path(nb, "%s", file), NULL)) != ES_OK)
        return nb_fail(nb, rc, "scatter");
    return 0;
}

static int procrustes(notebook *nb, study *s, int64_t perms)
{
    const int64_t p = s->k * s->d, n = s->n;
    es_gpa_opts go;
    es_gpa_out out;
    es_gpa_report gr;
    es_status rc;
    double *tan = NULL, sdev[4], pct[4], *scores = NULL;
    char xl[64], yl[64];
    int err = 1;

    nb_step(nb, "procrustes: GPA, tangent PCA, group test");
    nb_h(nb, 2, "Procrustes space");
    s->aligned = malloc(sizeof(double) * (size_t)(p * n));
    s->mean = malloc(sizeof(double) * (size_t)p);
    s->d_proc = malloc(sizeof(double) * (size_t)(n * n));
    tan = malloc(sizeof(double) * (size_t)(p * n));
    scores = malloc(sizeof(double) * (size_t)(n * 4));
    if (!s->aligned || !s->mean || !s->d_proc || !tan || !scores) {
        nb_fail(nb, ES_ENOMEM, "GPA");
        goto done;
    }
    memcpy(s->aligned, s->lm->xyz, sizeof(double) * (size_t)(p * n));
    es_gpa_opts_init(&go);
    memset(&out, 0, sizeof out);
    out.mean = s->mean;
    if ((rc = es_gpa_align(nb->ctx, s->k, s->d, (es_mat){s->aligned, p, n, p}, &go, &out,
                           &gr)) != ES_OK ||
        (rc = es_gpa_tangent(nb->ctx, s->k, s->d, (es_mat){s->aligned, p, n, p}, s->mean,
                             ES_TANGENT_PARTIAL, (es_mat){tan, p, n, p})) != ES_OK ||
        (rc = es_gpa_pca(nb->ctx, (es_mat){tan, p, n, p}, 2, sdev, pct, (es_mat){NULL, 0, 0, 0},
                         (es_mat){scores, n, 2, n})) != ES_OK ||
        (rc = es_compare_distances(nb->ctx, (es_mat){s->aligned, p, n, p}, 0,
                                   (es_mat){s->d_proc, n, n, n})) != ES_OK ||
        (rc = es_compare_groups(nb->ctx, n, s->d_proc, s->group, s->ngroups, perms, NULL, NULL,
                                &s->g_proc)) != ES_OK) {
        nb_fail(nb, rc, "Procrustes analysis");
        goto done;
    }
    snprintf(xl, sizeof xl, "tangent PC 1 (%.1f%%)", pct[0]);
    snprintf(yl, sizeof yl, "tangent PC 2 (%.1f%%)", pct[1]);
    if (scatter(nb, s, scores, scores + n, "procrustes_pcs.png", "Procrustes tangent PCA", xl,
                yl))
        goto done;
    {
        FILE *f = nb_csv_open(nb, "procrustes_scores.csv", "specimen,group,pc1,pc2");
        for (int64_t i = 0; f && i < n; i++)
            fprintf(f, "%s,%s,%.8g,%.8g\n", s->lm->ids[i], s->glabel[i], scores[i],
                    scores[i + n]);
        if (nb_csv_close(nb, f)) goto done;
    }
    nb_p(nb, "Full GPA converged in %lld iterations (RMS rho %.4f). The first two tangent PCs "
         "explain %.1f%% and %.1f%% of the shape variance.", (long long)gr.iterations,
         gr.rmsrho, pct[0], pct[1]);
    nb_image(nb, "procrustes_pcs.png", "Tangent-space PCA scores by group "
             "(data: procrustes_scores.csv)");
    err = 0;
done:
    free(tan);
    free(scores);
    return err;
}

/* ---- 3. the triangulation and its edge lengths ------------------------------------ */

/* Delaunay triangulation of q (2 x k) by the empty-circumcircle test over all
 * triples: O(k^4), meant for a few dozen landmarks. Triangles come out
 * counter-clockwise. */
static int64_t delaunay(int64_t k, const double *q, int64_t *tri, int64_t maxtri)
{
    int64_t nt = 0;
    for (int64_t a = 0; a < k; a++)
        for (int64_t b = a + 1; b < k; b++)
            for (int64_t c = b + 1; c < k; c++) {
                double ax = q[2 * a], ay = q[2 * a + 1], bx = q[2 * b], by = q[2 * b + 1];
                double cx = q[2 * c], cy = q[2 * c + 1];
                double orient = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
                int empty = 1;
                if (fabs(orient) < 1e-12) continue;
                for (int64_t m = 0; m < k && empty; m++) {
                    double dx, dy, ex, ey, fx, fy, det;
                    if (m == a || m == b || m == c) continue;
                    dx = ax - q[2 * m]; dy = ay - q[2 * m + 1];
                    ex = bx - q[2 * m]; ey = by - q[2 * m + 1];
                    fx = cx - q[2 * m]; fy = cy - q[2 * m + 1];
                    det = (dx * dx + dy * dy) * (ex * fy - ey * fx) -
                          (ex * ex + ey * ey) * (dx * fy - dy * fx) +
                          (fx * fx + fy * fy) * (dx * ey - dy * ex);
                    if ((orient > 0 ? det : -det) > 0) empty = 0;
                }
                if (empty && nt < maxtri) {
                    tri[3 * nt] = a;
                    tri[3 * nt + 1] = orient > 0 ? b : c;
                    tri[3 * nt + 2] = orient > 0 ? c : b;
                    nt++;
                }
            }
    return nt;
}

static int triangulate(notebook *nb, study *s)
{
    double q[2 * 64], r[3] = {0, 0, 0}, view[3], up[3], xyz[3 * 64];
    es_status rc;
    if (s->k > 64) return nb_fail(nb, ES_ERANGE, "more than 64 landmarks");
    /* the mean in 2D: as it is, or on its best-fitting plane (3D) */
    for (int64_t j = 0; j < s->k; j++)
        for (int c = 0; c < 3; c++) xyz[3 * j + c] = c < s->d ? s->mean[j + c * s->k] : 0;
    if (s->d == 3) {
        if ((rc = es_render_auto_view(nb->ctx, s->k, xyz, 0, NULL, view, up)) != ES_OK)
            return nb_fail(nb, rc, "mean plane");
        r[0] = up[1] * view[2] - up[2] * view[1];
        r[1] = up[2] * view[0] - up[0] * view[2];
        r[2] = up[0] * view[1] - up[1] * view[0];
    }
    for (int64_t j = 0; j < s->k; j++) {
        const double *x = xyz + 3 * j;
        q[2 * j] = s->d == 3 ? r[0] * x[0] + r[1] * x[1] + r[2] * x[2] : x[0];
        q[2 * j + 1] = s->d == 3 ? up[0] * x[0] + up[1] * x[1] + up[2] * x[2] : x[1];
    }
    s->ntri = delaunay(s->k, q, s->tri, 64);
    s->nedges = 0;
    for (int64_t t = 0; t < s->ntri; t++)
        for (int c = 0; c < 3; c++) {
            int64_t a = s->tri[3 * t + c], b = s->tri[3 * t + (c + 1) % 3], e;
            if (a > b) { int64_t tmp = a; a = b; b = tmp; }
            for (e = 0; e < s->nedges; e++)
                if (s->edges[2 * e] == a && s->edges[2 * e + 1] == b) break;
            if (e == s->nedges && s->nedges < 192) {
                s->edges[2 * e] = a;
                s->edges[2 * e + 1] = b;
                s->nedges++;
            }
        }
    return 0;
}

static int edge_lengths(notebook *nb, study *s, int64_t perms)
{
    const int64_t n = s->n;
    int64_t E;
    es_pca *pca = NULL;
    es_pca_opts po;
    es_source src;
    es_status rc;
    char xl[64], yl[64];
    FILE *f;

    nb_step(nb, "edge lengths: Delaunay triangulation of the mean, truss lengths, group test");
    nb_h(nb, 2, "Edge lengths of a triangulation");
    if (triangulate(nb, s)) return 1;
    E = s->nedges;
    s->len = malloc(sizeof(double) * (size_t)(E * n));
    s->d_len = malloc(sizeof(double) * (size_t)(n * n));
    if (!s->len || !s->d_len) return nb_fail(nb, ES_ENOMEM, "lengths");
    if ((rc = es_landmarks_truss_lengths(nb->ctx, s->lm, E, s->edges,
                                         (es_mat){s->len, E, n, E})) != ES_OK)
        return nb_fail(nb, rc, "truss lengths");
    for (int64_t i = 0; i < n; i++) {
        double sc;
        if ((rc = es_lengths_normalize(nb->ctx, E, s->len + i * E, s->len + i * E, &sc)) !=
            ES_OK)
            return nb_fail(nb, rc, "scaling lengths");
    }
    src = es_source_matrix((es_mat){s->len, E, n, E}, NULL, n);
    es_pca_opts_init(&po);
    po.ncomp = 2;
    if ((rc = es_pca_fit(nb->ctx, &src, &po, &pca)) != ES_OK ||
        (rc = es_compare_distances(nb->ctx, (es_mat){s->len, E, n, E}, 0,
                                   (es_mat){s->d_len, n, n, n})) != ES_OK ||
        (rc = es_compare_groups(nb->ctx, n, s->d_len, s->group, s->ngroups, perms, NULL, NULL,
                                &s->g_len)) != ES_OK ||
        (rc = es_compare_mantel(nb->ctx, n, s->d_proc, s->d_len, perms, &s->mantel_rho,
                                &s->mantel_p)) != ES_OK) {
        es_pca_free(pca);
        return nb_fail(nb, rc, "edge-length analysis");
    }
    snprintf(xl, sizeof xl, "edge-length PC 1 (%.1f%%)", 100 * pca->explained[0]);
    snprintf(yl, sizeof yl, "edge-length PC 2 (%.1f%%)", 100 * pca->explained[1]);
    rc = scatter(nb, s, pca->scores, pca->scores + n, "lengths_pcs.png",
                 "PCA of scaled triangulation edge lengths", xl, yl);
    if (!rc && (f = nb_csv_open(nb, "lengths_scores.csv", "specimen,group,pc1,pc2"))) {
        for (int64_t i = 0; i < n; i++)
            fprintf(f, "%s,%s,%.8g,%.8g\n", s->lm->ids[i], s->glabel[i], pca->scores[i],
                    pca->scores[i + n]);
        nb_csv_close(nb, f);
    }
    es_pca_free(pca);
    if (rc || nb->failed) return 1;
    if ((f = nb_csv_open(nb, "triangulation.csv", "triangle,a,b,c"))) {
        for (int64_t t = 0; t < s->ntri; t++)
            fprintf(f, "%lld,%lld,%lld,%lld\n", (long long)t, (long long)s->tri[3 * t] + 1,
                    (long long)s->tri[3 * t + 1] + 1, (long long)s->tri[3 * t + 2] + 1);
        if (nb_csv_close(nb, f)) return 1;
    }
    nb_p(nb, "The Delaunay triangulation of the Procrustes mean has %lld triangles and %lld "
         "edges (triangulation.csv, 1-based landmarks). Each specimen becomes the vector of "
         "its %lld edge lengths scaled to sum 1.", (long long)s->ntri, (long long)E,
         (long long)E);
    nb_image(nb, "lengths_pcs.png", "PCA of the scaled edge lengths by group "
             "(data: lengths_scores.csv)");
    return 0;
}

/* ---- 4. the verdicts side by side --------------------------------------------------- */

static void verdicts(notebook *nb, const study *s, int64_t perms)
{
    nb_step(nb, "report: group tests in both spaces");
    nb_h(nb, 2, "Group differences in both spaces");
    nb_table(nb, "space|R^2 of group|F|permutation p");
    nb_row(nb, "Procrustes (GPA)|%.3f|%.2f|%.3g", s->g_proc.r2, s->g_proc.f, s->g_proc.p);
    nb_row(nb, "scaled triangulation edge lengths|%.3f|%.2f|%.3g", s->g_len.r2, s->g_len.f,
           s->g_len.p);
    nb_p(nb, "(%lld permutations of the group labels.) The two spaces' pairwise distances "
         "have Spearman correlation %.3f (Mantel p = %.3g).", (long long)perms, s->mantel_rho,
         s->mantel_p);
}

int main(int argc, char **argv)
{
    notebook nb;
    study s;
    int64_t perms;
    int rc = nb_open(&nb, "05_landmarks", "Landmarks: group tests in Procrustes and "
                     "edge-length space", argc, argv);
    if (rc) return rc;
    memset(&s, 0, sizeof s);
    perms = nb.small ? 199 : 999;
    nb_p(&nb, "**Question.** Do GPA and a permutation test find the groups of a landmark set, "
         "and do the scaled edge lengths of a triangulation of the landmarks agree?");
    nb_p(&nb, "**Expected.** Both spaces find the groups (p < 0.05) and their distances "
         "agree closely: a triangulation of a few landmarks in 2D is rigid and determines the "
         "configuration (in 3D a planar triangulation has fewer edges than the 3k - 6 degrees "
         "of freedom and does not).");
    if (!load(&nb, &s) && !procrustes(&nb, &s, perms) && !edge_lengths(&nb, &s, perms)) {
        verdicts(&nb, &s, perms);
        nb_step(&nb, "self-check");
        nb_check(&nb, "groups differ in Procrustes space (permutation p)", s.g_proc.p, "<", 0.05);
        nb_check(&nb, "groups differ in edge-length space (permutation p)", s.g_len.p, "<", 0.05);
        nb_check(&nb, "Mantel correlation of the two spaces", s.mantel_rho, ">", 0.5);
    }
    es_free(nb.ctx, s.group);
    es_free(nb.ctx, s.gname);
    free(s.glabel);
    free(s.aligned);
    free(s.mean);
    free(s.d_proc);
    free(s.d_len);
    free(s.len);
    es_landmarks_free(s.lm);
    return nb_close(&nb);
}
