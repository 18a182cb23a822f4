/* notebooks-c/02_barbells.c — Barbells: what does global alignment miss?
 * (the paper's Section 4, Figs. 7-8)
 *
 * Question. Generalized Procrustes analysis (GPA) aligns whole shapes under
 * rotation, translation and scale, so a shape with far-apart parts is
 * judged mostly by how its parts sit, not by what they look like.
 * Scale-normalized edge lengths (eq. 12) compare the parts themselves. Do
 * the two distances disagree the way the paper says, and how much do they
 * agree on a real labelled set?
 *
 * Dataset. (a) The synthetic barbells of es_synth "barbell": sphere-like
 * and cube-like ends joined by bars of several lengths (datasets-spec/
 * synthetic.md). (b) face-study (../shared/data/face-study, labelled by
 * expression); without ../shared/data the synthetic face family instead.
 *
 * Method. Raw edge lengths (es_edge_lengths) and full GPA of the vertices
 * (es_gpa_align); es_compare_study computes both n x n distance matrices
 * (lengths scaled to sum 1; Procrustes = Euclidean distance of aligned
 * configurations), their Mantel correlation, nearest-neighbour agreement
 * and, with groups, a permutation test of group differences in each space.
 *
 * Expected finding. Procrustes: the two long barbells are much closer than
 * the two short ones (normalizing scale shrinks the long ones, and the ends
 * count for little); edge lengths: the two distances are comparable. On the
 * faces both spaces separate the expressions and broadly agree.
 */
#include "notebook.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct shapes {
    int64_t n, V, F, E;
    es_mesh *mesh;
    double *len;         /* E x n raw edge lengths */
    double *cfg;         /* 3V x n configurations, GPA-aligned after align() */
    char **ids;          /* n (borrowed or owned, see own_ids) */
    char **group_name;   /* ngroups */
    int64_t *group, ngroups;
    es_compare_result *cmp;
} shapes;

static void shapes_clear(shapes *s)
{
    es_mesh_free(s->mesh);
    free(s->len);
    free(s->cfg);
    if (s->ids)
        for (int64_t i = 0; i < s->n; i++) free(s->ids[i]);
    free(s->ids);
    if (s->group_name)
        for (int64_t g = 0; g < s->ngroups; g++) free(s->group_name[g]);
    free(s->group_name);
    free(s->group);
    es_compare_result_free(s->cmp);
    memset(s, 0, sizeof *s);
}

/* Fill topology, lengths and configurations from n position arrays. */
static int from_positions(notebook *nb, shapes *s, int64_t n, int64_t V, int64_t F,
                          const int64_t *faces, const double *const *xyz)
{
    es_status rc;
    if ((rc = es_mesh_new(nb->ctx, V, F, faces, xyz[0], &s->mesh)) != ES_OK)
        return nb_fail(nb, rc, "topology");
    s->n = n;
    s->V = V;
    s->F = F;
    s->E = es_mesh_nedges(s->mesh);
    s->len = malloc(sizeof(double) * (size_t)(s->E * n));
    s->cfg = malloc(sizeof(double) * (size_t)(3 * V * n));
    if (!s->len || !s->cfg) return nb_fail(nb, ES_ENOMEM, "shape arrays");
    for (int64_t i = 0; i < n; i++) {
        if ((rc = es_edge_lengths(nb->ctx, s->mesh, xyz[i], s->len + i * s->E)) != ES_OK)
            return nb_fail(nb, rc, "edge lengths");
        es_procrustes_from_xyz(V, xyz[i], s->cfg + i * 3 * V);
    }
    return 0;
}

/* Groups from labels, in order of first appearance. */
static int set_groups(notebook *nb, shapes *s, char **labels)
{
    s->group = malloc(sizeof(int64_t) * (size_t)s->n);
    s->group_name = calloc((size_t)s->n, sizeof(char *));
    if (!s->group || !s->group_name) return nb_fail(nb, ES_ENOMEM, "groups");
    for (int64_t i = 0; i < s->n; i++) {
        int64_t g = 0;
        while (g < s->ngroups && strcmp(s->group_name[g], labels[i])) g++;
        if (g == s->ngroups && !(s->group_name[s->ngroups++] = strdup(labels[i])))
            return nb_fail(nb, ES_ENOMEM, "groups");
        s->group[i] = g;
    }
    return 0;
}

static int align_and_compare(notebook *nb, shapes *s, int64_t permutations)
{
    es_gpa_opts go;
    es_gpa_report gr;
    es_compare_opts co;
    es_status rc;
    es_gpa_opts_init(&go);
    rc = es_gpa_align(nb->ctx, s->V, 3, (es_mat){s->cfg, 3 * s->V, s->n, 3 * s->V}, &go, NULL,
                      &gr);
    if (rc != ES_OK) return nb_fail(nb, rc, "GPA");
    es_compare_opts_init(&co);
    co.permutations = permutations;
    co.top_pairs = 5;
    rc = es_compare_study(nb->ctx, (es_mat){s->len, s->E, s->n, s->E},
                          (es_mat){s->cfg, 3 * s->V, s->n, 3 * s->V}, s->group,
                          s->group ? s->ngroups : 0, &co, &s->cmp);
    if (rc != ES_OK) return nb_fail(nb, rc, "comparison study");
    nb_p(nb, "Full GPA of %lld shapes converged in %lld iterations (RMS rho %.3g). Procrustes "
         "distances here are Euclidean distances between the aligned configurations in the "
         "data's units: full GPA keeps the inputs' total size (as R's procGPA does), so they "
         "are not the unit-size Procrustes distance of the textbooks.",
         (long long)s->n, (long long)gr.iterations, gr.rmsrho);
    return 0;
}

static int heatmaps(notebook *nb, const shapes *s, const char *stem, const char *what)
{
    es_heatmap_spec hs;
    es_status rc;
    char file[64], title[128];
    const double *d[2] = {s->cmp->d_len, s->cmp->d_proc};
    const char *space[2] = {"lengths", "procrustes"};
    const char *nice[2] = {"scaled edge-length distance", "Procrustes distance"};
    const char *unit[2] = {"distance (lengths scaled to sum 1)", "distance (data units)"};
    /* shapes ordered by group (stable), so that a group shows as a block */
    int64_t *order = malloc((size_t)s->n * sizeof *order), m = 0;
    const char *labels[12];
    double *sorted = malloc((size_t)(s->n * s->n) * sizeof *sorted);
    if (!order || !sorted) {
        free(order), free(sorted);
        return nb_fail(nb, ES_ENOMEM, "heat map");
    }
    for (int64_t g = 0; g < (s->group ? s->ngroups : 1); g++)
        for (int64_t i = 0; i < s->n; i++)
            if (!s->group || s->group[i] == g) order[m++] = i;
    for (int64_t i = m; i < s->n; i++) order[i] = i;   /* no group: as they come */
    for (int k = 0; k < 2; k++) {
        es_heatmap_spec_init(&hs);
        snprintf(file, sizeof file, "%s_%s.png", stem, space[k]);
        snprintf(title, sizeof title, "%s: %s%s", what, nice[k],
                 s->group ? " (ordered by group)" : "");
        hs.frame.title = title;
        hs.frame.width = 560;
        hs.frame.height = 520;
        for (int64_t j = 0; j < s->n; j++)
            for (int64_t i = 0; i < s->n; i++)
                sorted[i + j * s->n] = d[k][order[i] + order[j] * s->n];
        hs.values = (es_mat){sorted, s->n, s->n, s->n};
        if (s->n <= 12) {
            for (int64_t i = 0; i < s->n; i++) labels[i] = s->ids[order[i]];
            hs.row_labels = labels;
            hs.col_labels = labels;
        }
        hs.colorbar_label = unit[k];
        if ((rc = es_plot_heatmap(nb->ctx, &hs, nb_path(nb, "%s", file), NULL)) != ES_OK) {
            free(order), free(sorted);
            return nb_fail(nb, rc, "heat map");
        }
    }
    free(order), free(sorted);
    return 0;
}

/* ---- (a) barbells ------------------------------------------------------------ */

static int barbells(notebook *nb, double *ratio_proc, double *ratio_len)
{
    es_synth_opts so;
    es_synth_set set;
    shapes s;
    es_status rc;
    const double **xyz = NULL;
    int64_t nlen;
    int err = 1;
    FILE *f;

    memset(&s, 0, sizeof s);
    nb_step(nb, "barbells: synthesize, edge lengths, GPA, both distance matrices");
    nb_h(nb, 2, "(a) Synthetic barbells (Figs. 7-8)");
    es_synth_opts_init(&so);
    so.n = nlen = nb->small ? 4 : 6;
    so.resolution = nb->small ? 6 : 8;
    if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_BARBELL, &so, &set)) != ES_OK)
        return nb_fail(nb, rc, "barbells");
    nb_input(nb, "barbells", "es_synth barbell, %lld bar lengths, resolution %lld",
             (long long)so.n, (long long)so.resolution);
    xyz = malloc(sizeof(double *) * (size_t)set.nmembers);
    s.ids = calloc((size_t)set.nmembers, sizeof(char *));
    if (!xyz || !s.ids) {
        nb_fail(nb, ES_ENOMEM, "barbells");
        goto done;
    }
    for (int64_t i = 0; i < set.nmembers; i++) {
        xyz[i] = set.xyz + 3 * set.nverts * i;
        if (!(s.ids[i] = strdup(set.names[i] + strlen("barbell_")))) goto done;
    }
    if (from_positions(nb, &s, set.nmembers, set.nverts, set.nfaces, set.faces, xyz)) goto done;
    if (align_and_compare(nb, &s, 0)) goto done;
    nb_p(nb, "%lld barbells (%lld vertices, %lld edges each): sphere-like and cube-like ends, "
         "bars of %lld lengths from %g to %g (the bulbs have radius 1).",
         (long long)s.n, (long long)s.V, (long long)s.E, (long long)nlen,
         atof(set.labels[3 * 0 + 2]), atof(set.labels[3 * (nlen - 1) + 2]));
    if (!(f = nb_csv_open(nb, "barbells_pairs.csv",
                          "bar_length,d_procrustes,d_lengths,d_procrustes_rel,d_lengths_rel")))
        goto done;
    {
        double *x = malloc(sizeof(double) * (size_t)nlen * 3);
        double *yp = x + nlen, *yl = x + 2 * nlen;
        es_series ser[2];
        es_lines_spec ls;
        if (!x) goto done;
        nb_table(nb, "bar length|Procrustes distance sphere-cube|edge-length distance "
                     "sphere-cube|Procrustes, relative to shortest|edge length, relative");
        for (int64_t l = 0; l < nlen; l++) {
            int64_t a = l, b = nlen + l;
            x[l] = atof(set.labels[3 * a + 2]);
            yp[l] = s.cmp->d_proc[a + b * s.n];
            yl[l] = s.cmp->d_len[a + b * s.n];
        }
        for (int64_t l = 0; l < nlen; l++) {
            fprintf(f, "%g,%.8g,%.8g,%.6g,%.6g\n", x[l], yp[l], yl[l], yp[l] / yp[0],
                    yl[l] / yl[0]);
            nb_row(nb, "%g|%.4g|%.4g|%.3f|%.3f", x[l], yp[l], yl[l], yp[l] / yp[0],
                   yl[l] / yl[0]);
        }
        *ratio_proc = yp[nlen - 1] / yp[0];
        *ratio_len = yl[nlen - 1] / yl[0];
        for (int64_t l = nlen - 1; l >= 0; l--) {   /* relative to the shortest bar */
            yp[l] /= yp[0];
            yl[l] /= yl[0];
        }
        ser[0] = (es_series){"Procrustes (GPA)", nlen, x, yp};
        ser[1] = (es_series){"scaled edge lengths", nlen, x, yl};
        es_lines_spec_init(&ls);
        ls.frame.title = "Sphere-end vs cube-end barbell: distance as the bar grows";
        ls.frame.xlabel = "bar length (bulb radius 1)";
        ls.frame.ylabel = "distance / distance at the shortest bar";
        ls.nseries = 2;
        ls.series = ser;
        ls.markers = 1;
        rc = es_plot_lines(nb->ctx, &ls, nb_path(nb, "barbells_distance.png"), NULL);
        free(x);
        if (nb_csv_close(nb, f)) goto done;
        if (rc != ES_OK) {
            nb_fail(nb, rc, "line plot");
            goto done;
        }
    }
    nb_image(nb, "barbells_distance.png", "Distance between the sphere-end and the cube-end "
             "barbell with the same bar, relative to the shortest bar (data: "
             "barbells_pairs.csv)");
    nb_p(nb, "From the shortest to the longest bar the Procrustes distance between the two "
         "ends' barbells falls to %.2f of its value, the scaled edge-length distance changes "
         "to %.2f: after global alignment the long barbells look alike because their ends are "
         "small and far from the centre, while the edge lengths still see the ends.",
         *ratio_proc, *ratio_len);
    if (heatmaps(nb, &s, "barbells", "barbells")) goto done;
    nb_image(nb, "barbells_lengths.png", "All pairwise scaled edge-length distances");
    nb_image(nb, "barbells_procrustes.png", "All pairwise Procrustes distances");
    {
        /* the aligned barbells, shortest and longest bar of each end */
        es_render_mesh rm[4];
        es_render_spec rs;
        int64_t pick[4] = {0, nlen, nlen - 1, 2 * nlen - 1};
        char plabel[4][64];
        double *pos = malloc(sizeof(double) * (size_t)(3 * s.V * 4));
        if (!pos) goto done;
        es_render_spec_init(&rs);
        for (int i = 0; i < 4; i++) {
            es_procrustes_to_xyz(s.V, s.cfg + pick[i] * 3 * s.V, pos + i * 3 * s.V);
            snprintf(plabel[i], sizeof plabel[i], "%s ends, bar %g",
                     pick[i] < nlen ? "sphere" : "cube", atof(set.labels[3 * pick[i] + 2]));
            memset(&rm[i], 0, sizeof rm[i]);
            rm[i] = (es_render_mesh){.nverts = s.V, .nfaces = s.F, .xyz = pos + i * 3 * s.V,
                                     .faces = set.faces, .label = plabel[i]};
        }
        rs.nmeshes = 4;
        rs.meshes = rm;
        rs.width = rs.height = 300;
        rs.same_view = 1;
        rs.title = "Barbells after full GPA (common scale)";
        rc = es_render(nb->ctx, &rs, nb_path(nb, "barbells_aligned.png"), NULL);
        free(pos);
        if (rc != ES_OK) {
            nb_fail(nb, rc, "render");
            goto done;
        }
        nb_image(nb, "barbells_aligned.png", "The shortest and longest barbells of each end "
                 "after GPA: scaling shrinks the long ones, so their ends nearly coincide");
    }
    err = 0;
done:
    free(xyz);
    shapes_clear(&s);
    es_synth_set_clear(nb->ctx, &set);
    return err;
}

/* ---- (b) a real labelled set -------------------------------------------------- */

static int load_faces(notebook *nb, shapes *s, const char **what)
{
    const char *dir = nb_dataset(nb, "face-study");
    int64_t nsub = nb->small ? 6 : 30, n = 0;
    es_status rc;
    char **labels = NULL;
    double **xyz = NULL;
    int err = 1;

    if (dir) {
        char path[4352];
        es_manifest *m = NULL;
        es_meshdata md0, md;
        int64_t cexp = -1, csub = -1, nseen = 0;
        const char *seen[64];
        snprintf(path, sizeof path, "%s/manifest.csv", dir);
        if ((rc = es_manifest_read(nb->ctx, path, &m)) != ES_OK)
            return nb_fail(nb, rc, "face-study manifest");
        for (int64_t c = 0; c < m->ncols; c++) {
            if (!strcmp(m->colnames[c], "expression")) cexp = c;
            if (!strcmp(m->colnames[c], "subject")) csub = c;
        }
        xyz = calloc((size_t)m->nrows, sizeof(double *));
        labels = calloc((size_t)m->nrows, sizeof(char *));
        s->ids = calloc((size_t)m->nrows, sizeof(char *));
        memset(&md0, 0, sizeof md0);
        if (cexp < 0 || csub < 0 || !xyz || !labels || !s->ids) {
            nb_fail(nb, cexp < 0 || csub < 0 ? ES_ENOTFOUND : ES_ENOMEM, "face-study labels");
            es_manifest_free(nb->ctx, m);
            goto done;
        }
        for (int64_t r = 0; r < m->nrows; r++) {
            const char *sub = m->cells[r * m->ncols + csub];
            int64_t k = 0;
            while (k < nseen && strcmp(seen[k], sub)) k++;
            if (k == nseen) {
                if (nseen >= nsub) continue;
                seen[nseen++] = sub;
            }
            snprintf(path, sizeof path, "%s/%s", m->dir, m->cells[r * m->ncols + m->file_col]);
            if ((rc = es_meshdata_read(nb->ctx, path, ES_FORMAT_AUTO, &md)) != ES_OK) {
                nb_fail(nb, rc, "reading a face");
                break;
            }
            xyz[n] = md.xyz;
            md.xyz = NULL;
            if (n == 0) md0 = md;
            else es_meshdata_clear(nb->ctx, &md);
            labels[n] = strdup(m->cells[r * m->ncols + cexp]);
            s->ids[n] = strdup(m->ids[r]);
            n++;
        }
        es_manifest_free(nb->ctx, m);
        if (!nb->failed)
            from_positions(nb, s, n, md0.nverts, md0.nfaces, md0.faces,
                           (const double *const *)xyz);
        es_meshdata_clear(nb->ctx, &md0);
        *what = "face-study";
        nb_p(nb, "**Data:** `face-study`, the first %lld subjects x {neutral, happy, angry}.",
             (long long)nseen);
    } else {
        es_synth_opts so;
        es_synth_set set;
        es_synth_opts_init(&so);
        so.n = nb->small ? 6 : 20;
        if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_FACE, &so, &set)) != ES_OK)
            return nb_fail(nb, rc, "synthetic faces");
        n = set.nmembers;
        xyz = calloc((size_t)n, sizeof(double *));
        labels = calloc((size_t)n, sizeof(char *));
        s->ids = calloc((size_t)n, sizeof(char *));
        if (xyz && labels && s->ids) {
            for (int64_t i = 0; i < n; i++) {
                xyz[i] = set.xyz + 3 * set.nverts * i;
                labels[i] = strdup(set.labels[i * set.nlabels + 1]);   /* expression */
                s->ids[i] = strdup(set.names[i]);
            }
            from_positions(nb, s, n, set.nverts, set.nfaces, set.faces,
                           (const double *const *)xyz);
        } else {
            nb_fail(nb, ES_ENOMEM, "synthetic faces");
        }
        free(xyz);
        xyz = NULL;
        es_synth_set_clear(nb->ctx, &set);
        *what = "synthetic faces";
        nb_input(nb, "labelled set", "synthetic face family, %lld subjects", (long long)so.n);
        nb_p(nb, "> **Data: synthetic.** `../shared/data/face-study` was not found (or "
             "`--synthetic` was given), so the labelled set is the project's synthetic face "
             "family (%lld subjects x {neutral, happy, angry}).", (long long)so.n);
    }
    if (nb->failed) goto done;
    for (int64_t i = 0; i < n; i++)
        if (!labels[i] || !s->ids[i]) {
            nb_fail(nb, ES_ENOMEM, "labels");
            goto done;
        }
    err = set_groups(nb, s, labels);
done:
    if (xyz && dir)
        for (int64_t i = 0; i < n; i++) es_free(nb->ctx, xyz[i]);
    free(xyz);
    if (labels)
        for (int64_t i = 0; i < n; i++) free(labels[i]);
    free(labels);
    return err;
}

static int labelled(notebook *nb, double *p_len)
{
    shapes s;
    const char *what = "";
    es_scatter_spec sp;
    const char **pair_label = NULL;
    double *x = NULL, *y = NULL;
    int64_t np = 0;
    es_status rc;
    int err = 1;
    FILE *f = NULL;

    memset(&s, 0, sizeof s);
    nb_step(nb, "labelled set: faces by expression in both spaces");
    nb_h(nb, 2, "(b) A labelled set: faces by expression");
    if (load_faces(nb, &s, &what) || align_and_compare(nb, &s, nb->small ? 199 : 999))
        goto done;
    {
        const es_compare_result *c = s.cmp;
        nb_p(nb, "%lld %s (%lld vertices, %lld edges). The two spaces' pairwise distances "
             "have Spearman correlation %.3f (Mantel p = %.3g); %.0f%% of the faces have the "
             "same nearest neighbour in both.", (long long)s.n, what, (long long)s.V,
             (long long)s.E, c->mantel_rho, c->mantel_p, 100 * c->nn_agreement);
        nb_table(nb, "space|R^2 of expression|F|permutation p");
        nb_row(nb, "scaled edge lengths|%.3f|%.2f|%.3g", c->groups_len.r2, c->groups_len.f,
               c->groups_len.p);
        nb_row(nb, "Procrustes|%.3f|%.2f|%.3g", c->groups_proc.r2, c->groups_proc.f,
               c->groups_proc.p);
        nb_p(nb, "R^2: the share of the squared distances that lies between the expression "
             "means (a one-factor test on the distance matrix, permutations of the labels).");
        /* the verdict on the expected finding, from the numbers above */
        nb_p(nb, "**Finding.** %s; the two spaces %s (Spearman %.2f between their distances, "
             "%.0f%% shared nearest neighbours).",
             c->groups_len.p < 0.05 && c->groups_proc.p < 0.05
                 ? "Both spaces separate the expressions (p < 0.05)"
                 : c->groups_len.p < 0.05 ? "Only the edge-length space separates the expressions "
                                            "(p < 0.05); the Procrustes space does not"
                 : c->groups_proc.p < 0.05 ? "Only the Procrustes space separates the "
                                             "expressions (p < 0.05)"
                                           : "Neither space separates the expressions at p < 0.05",
             c->mantel_rho >= 0.5 ? "broadly agree" : "agree only weakly", c->mantel_rho,
             100 * c->nn_agreement);
        *p_len = c->groups_len.p;
        nb_table(nb, "groups|edge-length distance of means|p|Procrustes distance of means|p");
        for (int64_t a = 0; a < s.ngroups; a++)
            for (int64_t b = a + 1; b < s.ngroups; b++) {
                int64_t ab = a + b * s.ngroups;
                nb_row(nb, "%s - %s|%.4g|%.3g|%.4g|%.3g", s.group_name[a], s.group_name[b],
                       c->mean_len[ab], c->p_len[ab], c->mean_proc[ab], c->p_proc[ab]);
            }
    }
    /* pairwise distances, one space against the other, coloured by the pair's groups */
    np = s.n * (s.n - 1) / 2;
    x = malloc(sizeof(double) * (size_t)np);
    y = malloc(sizeof(double) * (size_t)np);
    pair_label = malloc(sizeof(char *) * (size_t)np);
    if (!x || !y || !pair_label) {
        nb_fail(nb, ES_ENOMEM, "pairs");
        goto done;
    }
    if (!(f = nb_csv_open(nb, "faces_pairs.csv", "id_a,id_b,group_a,group_b,d_procrustes,"
                                                 "d_lengths")))
        goto done;
    {
        int64_t k = 0;
        for (int64_t j = 0; j < s.n; j++)
            for (int64_t i = 0; i < j; i++, k++) {
                x[k] = s.cmp->d_proc[i + j * s.n];
                y[k] = s.cmp->d_len[i + j * s.n];
                pair_label[k] = s.group[i] == s.group[j] ? "same expression"
                                                         : "different expressions";
                fprintf(f, "%s,%s,%s,%s,%.8g,%.8g\n", s.ids[i], s.ids[j],
                        s.group_name[s.group[i]], s.group_name[s.group[j]], x[k], y[k]);
            }
    }
    if (nb_csv_close(nb, f)) goto done;
    es_scatter_spec_init(&sp);
    sp.frame.title = "Pairs of faces: Procrustes vs edge-length distance";
    sp.frame.xlabel = "Procrustes distance (GPA)";
    sp.frame.ylabel = "scaled edge-length distance";
    sp.n = np;
    sp.x = x;
    sp.y = y;
    sp.labels = pair_label;
    sp.marker_radius = 2.5;
    if ((rc = es_plot_scatter(nb->ctx, &sp, nb_path(nb, "faces_pairs.png"), NULL)) != ES_OK) {
        nb_fail(nb, rc, "scatter");
        goto done;
    }
    nb_image(nb, "faces_pairs.png", "Every pair of faces, distance in one space against the "
             "other (data: faces_pairs.csv)");
    if (heatmaps(nb, &s, "faces", "faces")) goto done;
    nb_image(nb, "faces_lengths.png", "Scaled edge-length distances between all faces "
             "(ordered by expression)");
    nb_image(nb, "faces_procrustes.png", "Procrustes distances between all faces (ordered by "
             "expression)");
    err = 0;
done:
    free(x);
    free(y);
    free(pair_label);
    shapes_clear(&s);
    return err;
}

int main(int argc, char **argv)
{
    notebook nb;
    double ratio_proc = NAN, ratio_len = NAN, p_len = NAN;
    int rc = nb_open(&nb, "02_barbells", "Barbells: Procrustes vs edge-length distances",
                     argc, argv);
    if (rc) return rc;
    nb_p(&nb, "**Question.** Global alignment (GPA) cannot align all parts of a shape at "
         "once; scale-normalized edge lengths compare the parts themselves. Where do the "
         "two distances disagree (the paper's barbells, Figs. 7-8), and how far do they agree "
         "on real faces labelled by expression?");
    nb_p(&nb, "**Expected.** In Procrustes space the two long barbells are much closer than "
         "the two short ones; in edge-length space the two distances are comparable. On the "
         "faces both spaces separate the expressions and broadly agree.");
    if (!barbells(&nb, &ratio_proc, &ratio_len)) labelled(&nb, &p_len);
    nb_step(&nb, "self-check");
    /* The paper's finding, as two bounds: in Procrustes space the long pair
     * is clearly closer than the short pair, and the edge-length distances
     * stay more comparable (a smaller log-ratio). */
    nb_check(&nb, "Procrustes distance, longest/shortest bar", ratio_proc, "<", 0.75);
    nb_check(&nb, "abs log ratio, edge lengths minus Procrustes",
             fabs(log(ratio_len)) - fabs(log(ratio_proc)), "<", 0);
    nb_check(&nb, "expression groups differ in edge-length space (permutation p)", p_len, "<",
             0.05);
    return nb_close(&nb);
}
