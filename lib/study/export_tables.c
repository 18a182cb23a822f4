/* lib/study/export_tables.c — the tables of GPA and model results
 * (es_study_export_result; the registry and the other kinds are in
 * export_results.c). GPA coordinates are named x1..xk, y1..yk[, z1..zk],
 * procGPA's vectorisation; a model in Procrustes space names its variables
 * the same way, one in edge-length space is an edge table.
 */
#include "study/study_pkg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* "x1".."xk", "y1".., "z1".. for a k x d configuration (p = k d), or
 * "v1".."vp" when k and d are not known. */
static es_status coord_names(es_ctx *ctx, int64_t p, int64_t k, int64_t d, char ***names)
{
    if (k < 1 || d < 2 || d > 3 || k * d != p) return es__numbered_names(ctx, "v", p, names);
    es_status rc = es__numbered_names(ctx, "x", p, names);
    if (rc != ES_OK) return rc;
    for (int64_t c = 0; c < d; c++)
        for (int64_t v = 0; v < k; v++)
            snprintf((*names)[v + c * k], 24, "%c%lld", "xyz"[c], (long long)(v + 1));
    return ES_OK;
}

/* k and d of GPA result `gpa` (0 when it is not there). */
static void gpa_shape(es_ctx *ctx, es_store *s, const char *gpa, int64_t *k, int64_t *d)
{
    char grp[300];
    double kv = 0, dv = 0;
    *k = *d = 0;
    snprintf(grp, sizeof grp, "gpa/%s", gpa);
    if (!*gpa || !es_store_has(s, grp)) return;
    if (es_store_get_attr_double(ctx, s, grp, "k", &kv) == ES_OK &&
        es_store_get_attr_double(ctx, s, grp, "dim", &dv) == ES_OK) {
        *k = (int64_t)kv;
        *d = (int64_t)dv;
    }
    es_ctx_clear_error(ctx);
}

/* "<first>,<names...>": one line per entry i of `labels` (or its number). */
static es_status variable_table(es_ctx *ctx, const char *path, const char *first, int64_t p,
                                const char *const *labels, int64_t ncol,
                                const char *const *names, const double *values, int64_t ld)
{
    es__table_out t;
    es_status rc = es__table_begin(ctx, path, &t);
    if (rc != ES_OK) return rc;
    fputs(first, t.f);
    for (int64_t c = 0; c < ncol; c++) {
        fputc(',', t.f);
        es_csv_write_field(t.f, names[c]);
    }
    fputc('\n', t.f);
    for (int64_t i = 0; i < p; i++) {
        if (labels) es_csv_write_field(t.f, labels[i]);
        else fprintf(t.f, "%lld", (long long)(i + 1));
        for (int64_t c = 0; c < ncol; c++) es__table_number(t.f, values[i + c * ld]);
        fputc('\n', t.f);
    }
    return es__table_end(ctx, &t, ES_OK);
}

/* ---- GPA --------------------------------------------------------------------------- */

es_status es__t_gpa_specimens(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                              const char *path)
{
    static const char *const ds[3] = {"size", "rho", "scale"};
    double *v[3] = {NULL, NULL, NULL}, *all = NULL;
    int64_t *rows = NULL, n = 0, nv = 0, ncol = 0;
    es_mat sc = {0};
    char **names = NULL;
    es_status rc = es__result_ints(ctx, s, kind, name, "input_rows", &rows, &n);
    for (int k = 0; k < 3 && rc == ES_OK; k++) {
        rc = es__result_vector(ctx, s, kind, name, ds[k], &v[k], &nv);
        if (rc == ES_OK && nv != n)
            rc = es__fail(ctx, ES_EFORMAT, "export: gpa/%s/%s has %lld values for %lld rows",
                          name, ds[k], (long long)nv, (long long)n);
    }
    if (rc == ES_OK) rc = es__result_matrix(ctx, s, kind, name, "pc_scores", &sc);
    if (rc == ES_OK && sc.cols != n)
        rc = es__fail(ctx, ES_EFORMAT, "export: gpa/%s/pc_scores is inconsistent", name);
    if (rc != ES_OK) goto done;
    ncol = 3 + sc.rows;
    if (!(all = es__alloc_array(ctx, n * ncol, sizeof *all))) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int k = 0; k < 3; k++) memcpy(all + k * n, v[k], (size_t)n * sizeof *all);
    for (int64_t c = 0; c < sc.rows; c++)
        for (int64_t i = 0; i < n; i++) all[i + (3 + c) * n] = ES_AT(sc, c, i);
    if ((rc = es__numbered_names(ctx, "PC", ncol, &names)) != ES_OK) goto done;
    for (int64_t c = 0; c < sc.rows; c++) snprintf(names[3 + c], 24, "PC%lld", (long long)(c + 1));
    snprintf(names[0], 24, "centroid_size");
    snprintf(names[1], 24, "rho");
    snprintf(names[2], 24, "scale");
    rc = es__write_row_table(ctx, s, path, n, rows, ncol, (const char *const *)names, all);
done:
    es__free_names(ctx, names, ncol);
    for (int k = 0; k < 3; k++) es_free(ctx, v[k]);
    es_free(ctx, rows);
    es_free(ctx, sc.data);
    es__free(ctx, all);
    return rc;
}

es_status es__t_gpa_aligned(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            const char *path)
{
    es_mat al = {0};
    int64_t *rows = NULL, n = 0, k, d;
    double *t = NULL;
    char **names = NULL;
    es_status rc;
    gpa_shape(ctx, s, name, &k, &d);
    if ((rc = es__result_matrix(ctx, s, kind, name, "aligned", &al)) != ES_OK ||
        (rc = es__result_ints(ctx, s, kind, name, "input_rows", &rows, &n)) != ES_OK)
        goto done;
    if (al.cols != n) {
        rc = es__fail(ctx, ES_EFORMAT, "export: gpa/%s/aligned is inconsistent", name);
        goto done;
    }
    if (!(t = es__transpose_mat(ctx, al))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = coord_names(ctx, al.rows, k, d, &names)) == ES_OK)
        rc = es__write_row_table(ctx, s, path, n, rows, al.rows, (const char *const *)names, t);
    es__free_names(ctx, names, al.rows);
done:
    es_free(ctx, al.data);
    es_free(ctx, rows);
    es__free(ctx, t);
    return rc;
}

es_status es__t_gpa_mean(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                         const char *path)
{
    double *m = NULL;
    int64_t p = 0, k, d;
    static const char *const xyz[3] = {"x", "y", "z"};
    gpa_shape(ctx, s, name, &k, &d);
    es_status rc = es__result_vector(ctx, s, kind, name, "mean", &m, &p);
    if (rc == ES_OK && (k < 1 || k * d != p))
        rc = es__fail(ctx, ES_EFORMAT, "export: gpa/%s has no k and dim for its %lld values",
                      name, (long long)p);
    if (rc == ES_OK) rc = variable_table(ctx, path, "landmark", k, NULL, d, xyz, m, k);
    es_free(ctx, m);
    return rc;
}

es_status es__t_gpa_pca(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                        const char *path)
{
    double *v[2] = {NULL, NULL}, *all = NULL;
    int64_t n0 = 0, n1 = 0;
    static const char *const cols[2] = {"sdev", "percent"};
    es_status rc;
    if ((rc = es__result_vector(ctx, s, kind, name, "pc_sdev", &v[0], &n0)) == ES_OK &&
        (rc = es__result_vector(ctx, s, kind, name, "pc_percent", &v[1], &n1)) == ES_OK) {
        if (n0 != n1) rc = es__fail(ctx, ES_EFORMAT, "export: gpa/%s/pc_* disagree", name);
        else if (!(all = es__alloc_array(ctx, 2 * n0 > 0 ? 2 * n0 : 1, sizeof *all))) rc = ES_ENOMEM;
        if (rc == ES_OK) {
            memcpy(all, v[0], (size_t)n0 * sizeof *all);
            memcpy(all + n0, v[1], (size_t)n0 * sizeof *all);
            rc = variable_table(ctx, path, "component", n0, NULL, 2, cols, all, n0);
        }
    }
    es_free(ctx, v[0]);
    es_free(ctx, v[1]);
    es__free(ctx, all);
    return rc;
}

es_status es__t_gpa_loadings(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                             const char *path)
{
    es_mat l = {0};
    int64_t k, d;
    char **coords = NULL, **pcs = NULL;
    gpa_shape(ctx, s, name, &k, &d);
    es_status rc = es__result_matrix(ctx, s, kind, name, "pc_loadings", &l);
    if (rc == ES_OK && (rc = coord_names(ctx, l.rows, k, d, &coords)) == ES_OK &&
        (rc = es__numbered_names(ctx, "PC", l.cols, &pcs)) == ES_OK)
        rc = variable_table(ctx, path, "coordinate", l.rows, (const char *const *)coords, l.cols,
                            (const char *const *)pcs, l.data, l.ld);
    es__free_names(ctx, coords, l.rows);
    es__free_names(ctx, pcs, l.cols);
    es_free(ctx, l.data);
    return rc;
}

/* ---- models ------------------------------------------------------------------------ */

/* A matrix of p-vectors (dataset [ncol][p]) as an edge table in edge-length
 * space or a coordinate table in Procrustes space. */
static es_status model_vectors(es_ctx *ctx, es_store *s, const char *name, const char *ds,
                               int64_t ncol, const char *const *cols, const char *path)
{
    char grp[300], space[32] = "", gpa[256] = "";
    es_mat m = {0};
    int64_t k, d;
    char **coords = NULL;
    snprintf(grp, sizeof grp, "model/%s", name);
    es_status rc = es__result_matrix(ctx, s, "model", name, ds, &m);
    if (rc == ES_OK) rc = es_store_get_attr(ctx, s, grp, "space", space, sizeof space);
    if (rc == ES_OK) rc = es_store_get_attr(ctx, s, grp, "gpa", gpa, sizeof gpa);
    if (rc == ES_OK && m.cols != ncol)
        rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/%s has %lld columns, not %lld", name,
                      ds, (long long)m.cols, (long long)ncol);
    if (rc == ES_OK && !strcmp(space, "lengths")) {
        rc = m.rows == es_store_nedges(s)
                 ? es_study_write_edge_table(ctx, s, path, ncol, cols, m.data)
                 : es__fail(ctx, ES_EFORMAT, "export: model/%s/%s is not per edge", name, ds);
    } else if (rc == ES_OK) {
        gpa_shape(ctx, s, gpa, &k, &d);
        if ((rc = coord_names(ctx, m.rows, k, d, &coords)) == ES_OK)
            rc = variable_table(ctx, path, "coordinate", m.rows, (const char *const *)coords,
                                ncol, cols, m.data, m.ld);
        es__free_names(ctx, coords, m.rows);
    }
    es_free(ctx, m.data);
    return rc;
}

static es_status with_strings(es_ctx *ctx, es_store *s, const char *name, const char *names_ds,
                              const char *ds, const char *path)
{
    char **names = NULL;
    int64_t n = 0;
    es_status rc = es__result_strings(ctx, s, "model", name, names_ds, &names, &n);
    if (rc == ES_OK) rc = model_vectors(ctx, s, name, ds, n, (const char *const *)names, path);
    for (int64_t i = 0; i < n; i++) es_free(ctx, names[i]);
    es_free(ctx, names);
    return rc;
}

es_status es__t_model_coefficients(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                   const char *path)
{
    (void)kind;
    return with_strings(ctx, s, name, "coef_names", "coefficients", path);
}

es_status es__t_model_lsmeans(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                              const char *path)
{
    char p[700];
    es_status rc = es__result_path(ctx, p, sizeof p, kind, name, "lsmeans");
    if (rc == ES_OK && !es_store_has(s, p))
        ES_FAIL(ctx, ES_ENOTFOUND, "export: model/%s has no pairwise comparison (fit it with "
                "--pairwise FACTOR)", name);
    return rc != ES_OK ? rc : with_strings(ctx, s, name, "pairwise_levels", "lsmeans", path);
}

es_status es__t_model_weights(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                              const char *path)
{
    char **names = NULL;
    int64_t q = 0, *rows = NULL, n = 0;
    es_mat w = {0};
    es_status rc = es__result_strings(ctx, s, kind, name, "coef_names", &names, &q);
    if (rc == ES_OK) rc = es__result_ints(ctx, s, kind, name, "rows", &rows, &n);
    if (rc == ES_OK) rc = es__result_matrix(ctx, s, kind, name, "coef_weights", &w);
    if (rc == ES_OK && (w.rows != n || w.cols != q))
        rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/coef_weights is inconsistent", name);
    if (rc == ES_OK)
        rc = es__write_row_table(ctx, s, path, n, rows, q, (const char *const *)names, w.data);
    for (int64_t i = 0; i < q; i++) es_free(ctx, names[i]);
    es_free(ctx, names);
    es_free(ctx, rows);
    es_free(ctx, w.data);
    return rc;
}

/* Per-landmark tests (Procrustes space): landmark, f, p, q. */
static es_status landmark_table(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                const char *path)
{
    static const char *const ds[3] = {"landmark_f", "landmark_p", "landmark_q"};
    double *v[3] = {NULL};
    int64_t n[3] = {0};
    es__table_out t;
    es_status rc = ES_OK;
    for (int k = 0; k < 3 && rc == ES_OK; k++)
        if ((rc = es__result_vector(ctx, s, kind, name, ds[k], &v[k], &n[k])) == ES_OK &&
            n[k] != n[0])
            rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/%s is inconsistent", name, ds[k]);
    if (rc == ES_OK && (rc = es__table_begin(ctx, path, &t)) == ES_OK) {
        fputs("landmark,f,p,q\n", t.f);
        for (int64_t i = 0; i < n[0]; i++) {
            fprintf(t.f, "%lld", (long long)(i + 1));
            for (int k = 0; k < 3; k++) es__table_number(t.f, v[k][i]);
            fputc('\n', t.f);
        }
        rc = es__table_end(ctx, &t, ES_OK);
    }
    for (int k = 0; k < 3; k++) es_free(ctx, v[k]);
    return rc;
}

es_status es__t_model_edges(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            const char *path)
{
    static const char *const ds[3] = {"edge_f", "edge_p", "edge_q"}, *const cols[3] = {"f", "p",
                                                                                          "q"};
    const int64_t E = es_store_nedges(s);
    double *all = NULL, *v = NULL;
    int64_t n = 0;
    char p[700];
    es_status rc = es__result_path(ctx, p, sizeof p, kind, name, "landmark_f");
    if (rc == ES_OK && es_store_has(s, p)) return landmark_table(ctx, s, kind, name, path);
    all = es__alloc_array(ctx, 3 * E > 0 ? 3 * E : 1, sizeof *all);
    rc = all ? es__result_path(ctx, p, sizeof p, kind, name, "edge_f") : ES_ENOMEM;
    if (rc == ES_OK && !es_store_has(s, p))
        rc = es__fail(ctx, ES_ENOTFOUND, "export: model/%s has no per-edge or per-landmark "
                      "tests (fit it with --edges TERM)", name);
    for (int k = 0; k < 3 && rc == ES_OK; k++) {
        if ((rc = es__result_vector(ctx, s, kind, name, ds[k], &v, &n)) != ES_OK) break;
        if (n != E) rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/%s is not per edge", name,
                                  ds[k]);
        else memcpy(all + k * E, v, (size_t)E * sizeof *all);
        es_free(ctx, v);
    }
    if (rc == ES_OK) rc = es_study_write_edge_table(ctx, s, path, 3, cols, all);
    es__free(ctx, all);
    return rc;
}

es_status es__t_model_scores(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                             const char *path)
{
    static const char *const cols[1] = {"cac_score"};
    int64_t *rows = NULL, n = 0, nv = 0;
    double *v = NULL;
    char p[700];
    es_status rc = es__result_path(ctx, p, sizeof p, kind, name, "cac_scores");
    if (rc == ES_OK && !es_store_has(s, p))
        ES_FAIL(ctx, ES_ENOTFOUND, "export: model/%s has no log(size) term, so no common "
                "allometric component", name);
    if (rc == ES_OK) rc = es__result_ints(ctx, s, kind, name, "rows", &rows, &n);
    if (rc == ES_OK) rc = es_store_get_vector(ctx, s, p, &v, &nv);
    if (rc == ES_OK && nv != n)
        rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/cac_scores is inconsistent", name);
    if (rc == ES_OK) rc = es__write_row_table(ctx, s, path, n, rows, 1, cols, v);
    es_free(ctx, rows);
    es_free(ctx, v);
    return rc;
}

es_status es__t_model_permutations(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                   const char *path)
{
    char **terms = NULL;
    int64_t nt = 0;
    es_mat f = {0};
    es_status rc = es__result_strings(ctx, s, kind, name, "terms", &terms, &nt);
    char p[700];
    if (rc == ES_OK && (rc = es__result_path(ctx, p, sizeof p, kind, name, "f_perm")) == ES_OK &&
        !es_store_has(s, p))
        rc = es__fail(ctx, ES_ENOTFOUND, "export: model/%s was fitted without permutations",
                      name);
    if (rc == ES_OK) rc = es_store_get_matrix(ctx, s, p, &f);
    if (rc == ES_OK && f.cols != nt)
        rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/f_perm is inconsistent", name);
    if (rc == ES_OK)
        rc = variable_table(ctx, path, "permutation", f.rows, NULL, nt,
                            (const char *const *)terms, f.data, f.ld);
    for (int64_t i = 0; i < nt; i++) es_free(ctx, terms[i]);
    es_free(ctx, terms);
    es_free(ctx, f.data);
    return rc;
}
