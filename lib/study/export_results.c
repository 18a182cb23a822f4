/* lib/study/export_results.c — every stored result as a CSV table with the
 * labels a reader needs (es_study_export_result): the row tables carry each
 * row's id and every label column, the edge tables each edge's end
 * vertices. A result kind has a default table and others
 * (es_study_result_tables); "attributes" (name, value) works on every
 * result, whatever its kind, so nothing stored is out of reach of a
 * spreadsheet or R. The GPA and model tables are in export_tables.c.
 */
#include "study/study_pkg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

es_status es__result_path(es_ctx *ctx, char *buf, size_t n, const char *kind, const char *name,
                          const char *ds)
{
    int len = snprintf(buf, n, "%s/%s/%s", kind, name, ds);
    if (len < 0 || (size_t)len >= n) ES_FAIL(ctx, ES_ERANGE, "result name '%s' is too long", name);
    return ES_OK;
}

es_status es__result_vector(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            const char *ds, double **v, int64_t *n)
{
    char p[700];
    es_status rc = es__result_path(ctx, p, sizeof p, kind, name, ds);
    return rc != ES_OK ? rc : es_store_get_vector(ctx, s, p, v, n);
}

es_status es__result_matrix(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            const char *ds, es_mat *m)
{
    char p[700];
    es_status rc = es__result_path(ctx, p, sizeof p, kind, name, ds);
    return rc != ES_OK ? rc : es_store_get_matrix(ctx, s, p, m);
}

es_status es__result_ints(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                          const char *ds, int64_t **v, int64_t *n)
{
    char p[700];
    es_status rc = es__result_path(ctx, p, sizeof p, kind, name, ds);
    return rc != ES_OK ? rc : es_store_get_ints(ctx, s, p, v, n);
}

es_status es__result_strings(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                             const char *ds, char ***v, int64_t *n)
{
    char p[700];
    es_status rc = es__result_path(ctx, p, sizeof p, kind, name, ds);
    return rc != ES_OK ? rc : es_store_get_strings(ctx, s, p, v, n);
}

/* The transpose of a stored matrix (dataset [a][b] read as es_mat b x a):
 * the a x b column-major array, row i = dataset row i. */
double *es__transpose_mat(es_ctx *ctx, es_mat m)
{
    double *t = es__alloc_array(ctx, m.rows * m.cols > 0 ? m.rows * m.cols : 1, sizeof *t);
    if (!t) return NULL;
    for (int64_t j = 0; j < m.cols; j++)
        for (int64_t i = 0; i < m.rows; i++) t[j + i * m.cols] = ES_AT(m, i, j);
    return t;
}

/* ---- any result: its attributes -------------------------------------------------- */

static es_status t_attributes(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                              const char *path)
{
    char grp[300], val[4096];
    char **keys = NULL;
    int64_t n = 0;
    es__table_out t;
    snprintf(grp, sizeof grp, "%s/%s", kind, name);
    es_status rc = es_store_list_attrs(ctx, s, grp, &keys, &n);
    if (rc != ES_OK) return rc;
    if ((rc = es__table_begin(ctx, path, &t)) == ES_OK) {
        fputs("attribute,value\n", t.f);
        for (int64_t i = 0; i < n && rc == ES_OK; i++) {
            if ((rc = es_store_get_attr(ctx, s, grp, keys[i], val, sizeof val)) != ES_OK) break;
            es_csv_write_field(t.f, keys[i]);
            fputc(',', t.f);
            es_csv_write_field(t.f, val);
            fputc('\n', t.f);
        }
        rc = es__table_end(ctx, &t, rc);
    }
    for (int64_t i = 0; i < n; i++) es_free(ctx, keys[i]);
    es_free(ctx, keys);
    return rc;
}

/* ---- mean, pca, diff, point ------------------------------------------------------- */

static es_status t_mean(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                        const char *path)
{
    es_mat m = {0};
    char **groups = NULL;
    int64_t ng = 0;
    es_status rc;
    if ((rc = es__result_matrix(ctx, s, kind, name, "means", &m)) == ES_OK &&
        (rc = es__result_strings(ctx, s, kind, name, "groups", &groups, &ng)) == ES_OK) {
        if (m.rows != es_store_nedges(s) || m.cols != ng)
            rc = es__fail(ctx, ES_EFORMAT, "export: mean/%s is inconsistent", name);
        else
            rc = es_study_write_edge_table(ctx, s, path, ng, (const char *const *)groups, m.data);
    }
    for (int64_t g = 0; g < ng; g++) es_free(ctx, groups[g]);
    es_free(ctx, groups);
    es_free(ctx, m.data);
    return rc;
}

static es_status t_pca_scores(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                              const char *path)
{
    es_mat sc = {0};
    int64_t *rows = NULL, n = 0;
    double *v = NULL;
    char **names = NULL;
    es_status rc;
    if ((rc = es__result_matrix(ctx, s, kind, name, "scores", &sc)) != ES_OK ||
        (rc = es__result_ints(ctx, s, kind, name, "rows", &rows, &n)) != ES_OK)
        goto done;
    if (sc.cols != n) {
        rc = es__fail(ctx, ES_EFORMAT, "export: pca/%s has %lld scores for %lld rows", name,
                      (long long)sc.cols, (long long)n);
        goto done;
    }
    if (!(v = es__transpose_mat(ctx, sc))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es__numbered_names(ctx, "PC", sc.rows, &names)) == ES_OK)
        rc = es__write_row_table(ctx, s, path, n, rows, sc.rows, (const char *const *)names, v);
    es__free_names(ctx, names, sc.rows);
done:
    es_free(ctx, sc.data);
    es_free(ctx, rows);
    es__free(ctx, v);
    return rc;
}

static es_status t_pca_eigenvalues(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                   const char *path)
{
    double *ev = NULL, *ex = NULL, cum = 0;
    int64_t k = 0, k2 = 0;
    es__table_out t;
    es_status rc;
    if ((rc = es__result_vector(ctx, s, kind, name, "eigenvalues", &ev, &k)) == ES_OK &&
        (rc = es__result_vector(ctx, s, kind, name, "explained", &ex, &k2)) == ES_OK &&
        (rc = es__table_begin(ctx, path, &t)) == ES_OK) {
        fputs("component,eigenvalue,explained,cumulative\n", t.f);
        for (int64_t c = 0; c < k && c < k2; c++) {
            cum += ex[c];
            fprintf(t.f, "%lld", (long long)(c + 1));
            es__table_number(t.f, ev[c]);
            es__table_number(t.f, ex[c]);
            es__table_number(t.f, cum);
            fputc('\n', t.f);
        }
        rc = es__table_end(ctx, &t, ES_OK);
    }
    es_free(ctx, ev);
    es_free(ctx, ex);
    return rc;
}

/* An edge table of named vectors of length E (each a dataset of the result). */
static es_status edge_vectors(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                              int64_t nv, const char *const *ds, const char *const *cols,
                              const char *path)
{
    const int64_t E = es_store_nedges(s);
    double *all = es__alloc_array(ctx, E * nv > 0 ? E * nv : 1, sizeof *all), *v = NULL;
    int64_t n = 0;
    es_status rc = all ? ES_OK : ES_ENOMEM;
    for (int64_t k = 0; k < nv && rc == ES_OK; k++) {
        if ((rc = es__result_vector(ctx, s, kind, name, ds[k], &v, &n)) != ES_OK) break;
        if (n != E) rc = es__fail(ctx, ES_EFORMAT, "export: %s/%s/%s has %lld values, the "
                                  "store %lld edges", kind, name, ds[k], (long long)n,
                                  (long long)E);
        else memcpy(all + k * E, v, (size_t)E * sizeof *all);
        es_free(ctx, v);
    }
    if (rc == ES_OK) rc = es_study_write_edge_table(ctx, s, path, nv, cols, all);
    es__free(ctx, all);
    return rc;
}

static es_status t_pca_components(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                  const char *path)
{
    es_mat c = {0};
    double *mean = NULL, *all = NULL;
    int64_t E = es_store_nedges(s), n = 0;
    char **names = NULL;
    es_status rc;
    if ((rc = es__result_vector(ctx, s, kind, name, "mean", &mean, &n)) != ES_OK ||
        (rc = es__result_matrix(ctx, s, kind, name, "components", &c)) != ES_OK)
        goto done;
    if (n != E || c.rows != E) {
        rc = es__fail(ctx, ES_EFORMAT, "export: pca/%s is inconsistent", name);
        goto done;
    }
    if (!(all = es__alloc_array(ctx, E * (c.cols + 1), sizeof *all)) ||
        (rc = es__numbered_names(ctx, "PC", c.cols + 1, &names)) != ES_OK) {
        rc = all ? rc : ES_ENOMEM;
        goto done;
    }
    es__free(ctx, names[0]);
    if (!(names[0] = es__strdup(ctx, "mean"))) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t k = 1; k <= c.cols; k++) snprintf(names[k], 24, "PC%lld", (long long)k);
    memcpy(all, mean, (size_t)E * sizeof *all);
    memcpy(all + E, c.data, (size_t)(E * c.cols) * sizeof *all);
    rc = es_study_write_edge_table(ctx, s, path, c.cols + 1, (const char *const *)names, all);
done:
    es__free_names(ctx, names, c.cols + 1);
    es_free(ctx, mean);
    es_free(ctx, c.data);
    es__free(ctx, all);
    return rc;
}

static es_status t_diff(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                        const char *path)
{
    static const char *const ds[4] = {"mean", "sd", "se", "t"};
    return edge_vectors(ctx, s, kind, name, 4, ds, ds, path);
}

static es_status t_point(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                         const char *path)
{
    static const char *const ds[1] = {"lengths"}, *const cols[1] = {"length"};
    return edge_vectors(ctx, s, kind, name, 1, ds, cols, path);
}

/* The row weights of a point: one line per store row. */
static es_status t_point_weights(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                 const char *path)
{
    double *w = NULL;
    int64_t n = 0, *rows = NULL;
    static const char *const cols[1] = {"weight"};
    es_status rc = es__result_vector(ctx, s, kind, name, "row_weights", &w, &n);
    if (rc != ES_OK) return rc;
    if (n != es_store_nrows(s)) rc = es__fail(ctx, ES_EFORMAT, "export: point/%s has %lld "
                                              "weights for %lld rows", name, (long long)n,
                                              (long long)es_store_nrows(s));
    else if (!(rows = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *rows))) rc = ES_ENOMEM;
    for (int64_t i = 0; rc == ES_OK && i < n; i++) rows[i] = i;
    if (rc == ES_OK) rc = es__write_row_table(ctx, s, path, n, rows, 1, cols, w);
    es__free(ctx, rows);
    es_free(ctx, w);
    return rc;
}

/* ---- compare, embed --------------------------------------------------------------- */

static es_status t_compare_summary(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                   const char *path)
{
    static const char *const keys[3] = {"spearman_rho", "mantel_p", "nn_agreement"};
    char grp[300];
    double v[3];
    es__table_out t;
    es_status rc = ES_OK;
    snprintf(grp, sizeof grp, "%s/%s", kind, name);
    for (int i = 0; i < 3 && rc == ES_OK; i++)
        rc = es_store_get_attr_double(ctx, s, grp, keys[i], &v[i]);
    if (rc != ES_OK || (rc = es__table_begin(ctx, path, &t)) != ES_OK) return rc;
    fputs("statistic,value\n", t.f);
    for (int i = 0; i < 3; i++) {
        fputs(keys[i], t.f);
        es__table_number(t.f, v[i]);
        fputc('\n', t.f);
    }
    return es__table_end(ctx, &t, ES_OK);
}

/* An n x n matrix of a result with the row ids as first column and header. */
static es_status id_matrix(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                           const char *ds, const char *path)
{
    es_mat m = {0};
    int64_t *rows = NULL, n = 0;
    es__table_out t;
    es_status rc;
    if ((rc = es__result_matrix(ctx, s, kind, name, ds, &m)) != ES_OK ||
        (rc = es__result_ints(ctx, s, kind, name, "input_rows", &rows, &n)) != ES_OK)
        goto done;
    if (m.rows != n || m.cols != n) {
        rc = es__fail(ctx, ES_EFORMAT, "export: %s/%s/%s is not %lld x %lld", kind, name, ds,
                      (long long)n, (long long)n);
        goto done;
    }
    for (int64_t i = 0; i < n; i++)
        if (rows[i] < 0 || rows[i] >= es_store_nrows(s)) {
            rc = es__fail(ctx, ES_EFORMAT, "export: %s/%s names a row outside the store", kind,
                          name);
            goto done;
        }
    if ((rc = es__table_begin(ctx, path, &t)) != ES_OK) goto done;
    fputs("id", t.f);
    for (int64_t j = 0; j < n; j++) {
        fputc(',', t.f);
        es_csv_write_field(t.f, es_store_row_id(s, rows[j]));
    }
    fputc('\n', t.f);
    for (int64_t i = 0; i < n; i++) {
        es_csv_write_field(t.f, es_store_row_id(s, rows[i]));
        for (int64_t j = 0; j < n; j++) es__table_number(t.f, ES_AT(m, j, i));
        fputc('\n', t.f);
    }
    rc = es__table_end(ctx, &t, ES_OK);
done:
    es_free(ctx, m.data);
    es_free(ctx, rows);
    return rc;
}

static es_status t_compare_lengths(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                   const char *path)
{
    return id_matrix(ctx, s, kind, name, "d_lengths", path);
}

static es_status t_compare_procrustes(es_ctx *ctx, es_store *s, const char *kind,
                                      const char *name, const char *path)
{
    return id_matrix(ctx, s, kind, name, "d_procrustes", path);
}

static es_status t_compare_groups(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                  const char *path)
{
    static const char *const ds[4] = {"group_means_lengths", "p_lengths",
                                      "group_means_procrustes", "p_procrustes"};
    es_mat m[4] = {{0}};
    char **g = NULL;
    int64_t ng = 0;
    es__table_out t;
    es_status rc = es__result_strings(ctx, s, kind, name, "group_names", &g, &ng);
    for (int k = 0; k < 4 && rc == ES_OK; k++) {
        rc = es__result_matrix(ctx, s, kind, name, ds[k], &m[k]);
        if (rc == ES_OK && (m[k].rows != ng || m[k].cols != ng))
            rc = es__fail(ctx, ES_EFORMAT, "export: %s/%s/%s is not %lld x %lld", kind, name,
                          ds[k], (long long)ng, (long long)ng);
    }
    if (rc == ES_OK && (rc = es__table_begin(ctx, path, &t)) == ES_OK) {
        fputs("group_a,group_b,distance_lengths,p_lengths,distance_procrustes,p_procrustes\n", t.f);
        for (int64_t a = 0; a < ng; a++)
            for (int64_t b = a + 1; b < ng; b++) {
                es_csv_write_field(t.f, g[a]);
                fputc(',', t.f);
                es_csv_write_field(t.f, g[b]);
                for (int k = 0; k < 4; k++) es__table_number(t.f, ES_AT(m[k], a, b));
                fputc('\n', t.f);
            }
        rc = es__table_end(ctx, &t, ES_OK);
    }
    for (int k = 0; k < 4; k++) es_free(ctx, m[k].data);
    for (int64_t a = 0; a < ng; a++) es_free(ctx, g[a]);
    es_free(ctx, g);
    return rc;
}

static es_status t_embed_vertices(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                                  const char *path)
{
    static const char *const ds[3] = {"vertex_closure", "vertex_edge_error",
                                      "vertex_deviation"};
    es_mat pos = {0};
    double *v[3] = {NULL, NULL, NULL};
    int64_t n[3] = {0, 0, 0}, have = 0;
    es__table_out t;
    es_status rc = es__result_matrix(ctx, s, kind, name, "positions", &pos);
    char p[700];
    for (int k = 0; k < 3 && rc == ES_OK; k++) {
        if ((rc = es__result_path(ctx, p, sizeof p, kind, name, ds[k])) != ES_OK) break;
        if (k == 2 && !es_store_has(s, p)) break;   /* no prior, no deviation */
        if ((rc = es_store_get_vector(ctx, s, p, &v[k], &n[k])) == ES_OK && n[k] != pos.cols)
            rc = es__fail(ctx, ES_EFORMAT, "export: %s has %lld values for %lld vertices", p,
                          (long long)n[k], (long long)pos.cols);
        have = k + 1;
    }
    if (rc == ES_OK && pos.rows != 3)
        rc = es__fail(ctx, ES_EFORMAT, "export: embed/%s/positions is not V x 3", name);
    if (rc == ES_OK && (rc = es__table_begin(ctx, path, &t)) == ES_OK) {
        fputs("vertex,x,y,z,closure,edge_error", t.f);
        fputs(have == 3 ? ",deviation\n" : "\n", t.f);
        for (int64_t i = 0; i < pos.cols; i++) {
            fprintf(t.f, "%lld", (long long)i);
            for (int c = 0; c < 3; c++) es__table_number(t.f, ES_AT(pos, c, i));
            for (int k = 0; k < have; k++) es__table_number(t.f, v[k][i]);
            fputc('\n', t.f);
        }
        rc = es__table_end(ctx, &t, ES_OK);
    }
    es_free(ctx, pos.data);
    for (int k = 0; k < 3; k++) es_free(ctx, v[k]);
    return rc;
}

/* ---- the registry ------------------------------------------------------------------ */

typedef es_status (*table_fn)(es_ctx *, es_store *, const char *, const char *, const char *);

typedef struct table_def {
    const char *kind, *table;
    table_fn fn;
} table_def;

/* The first table of a kind is its default. */
static const table_def tables[] = {
    {"mean", "means", t_mean},
    {"pca", "scores", t_pca_scores},
    {"pca", "eigenvalues", t_pca_eigenvalues},
    {"pca", "components", t_pca_components},
    {"diff", "edges", t_diff},
    {"point", "edges", t_point},
    {"point", "weights", t_point_weights},
    {"gpa", "specimens", es__t_gpa_specimens},
    {"gpa", "aligned", es__t_gpa_aligned},
    {"gpa", "mean", es__t_gpa_mean},
    {"gpa", "pca", es__t_gpa_pca},
    {"gpa", "loadings", es__t_gpa_loadings},
    {"compare", "summary", t_compare_summary},
    {"compare", "distances_lengths", t_compare_lengths},
    {"compare", "distances_procrustes", t_compare_procrustes},
    {"compare", "groups", t_compare_groups},
    {"embed", "report", t_attributes},
    {"embed", "vertices", t_embed_vertices},
    {"model", "anova", es__t_model_anova},
    {"model", "coefficients", es__t_model_coefficients},
    {"model", "weights", es__t_model_weights},
    {"model", "pairwise", es__t_model_pairwise},
    {"model", "lsmeans", es__t_model_lsmeans},
    {"model", "edges", es__t_model_edges},
    {"model", "scores", es__t_model_scores},
    {"model", "permutations", es__t_model_permutations},
};

const char *es_study_result_tables(const char *kind, char *buf, size_t n)
{
    size_t len = 0;
    if (!buf || !n) return buf;
    buf[0] = '\0';
    for (size_t i = 0; kind && i < sizeof tables / sizeof *tables; i++)
        if (!strcmp(tables[i].kind, kind) && len < n)
            len += (size_t)snprintf(buf + len, n - len, "%s, ", tables[i].table);
    if (len < n) snprintf(buf + len, n - len, "attributes");
    return buf;
}

es_status es_study_export_result(es_ctx *ctx, es_store *store, const char *result,
                                 const char *table, const char *path)
{
    char kind[128], name[256];
    const char *slash = result ? strchr(result, '/') : NULL;
    if (!store || !result || !path) ES_FAIL(ctx, ES_EINVAL, "export: bad arguments");
    if (!slash || slash == result || !slash[1] || strchr(slash + 1, '/') ||
        (size_t)(slash - result) >= sizeof kind || strlen(slash + 1) >= sizeof name)
        ES_FAIL(ctx, ES_EINVAL, "export: name a result as KIND/NAME (e.g. gpa/all), not '%s'",
                result);
    memcpy(kind, result, (size_t)(slash - result));
    kind[slash - result] = '\0';
    snprintf(name, sizeof name, "%s", slash + 1);
    if (!es_store_has(store, result)) {
        char hint[400];
        es_store_result_hint(ctx, store, kind, name, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "export: the store has no result %s%s", result, hint);
    }
    if (table && !strcmp(table, "attributes")) return t_attributes(ctx, store, kind, name, path);
    for (size_t i = 0; i < sizeof tables / sizeof *tables; i++)
        if (!strcmp(tables[i].kind, kind) && (!table || !strcmp(tables[i].table, table)))
            return tables[i].fn(ctx, store, kind, name, path);
    if (!table) return t_attributes(ctx, store, kind, name, path);
    char list[512];
    ES_FAIL(ctx, ES_ENOTFOUND, "export: %s results have no table '%s' (tables: %s)", kind, table,
            es_study_result_tables(kind, list, sizeof list));
}
