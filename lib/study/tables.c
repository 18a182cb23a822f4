/* lib/study/tables.c — results as CSV tables with the labels a reader needs:
 * per-edge tables (edge, end vertices, values), PCA scores with every label
 * column, eigenvalues, projections. Commands and notebooks write the same
 * files through these. */
#include "study/study_pkg.h"

#include <errno.h>
#include <stdio.h>

es_status es__table_begin(es_ctx *ctx, const char *path, es__table_out *t)
{
    es_status rc;
    memset(t, 0, sizeof *t);
    t->path = path;
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "no output file given");
    if (!strcmp(path, "-")) {
        t->f = stdout;
        return ES_OK;
    }
    /* an HDF5 file here is most likely the store given as the CSV by mistake */
    if (es_store_is_hdf5(path))
        ES_FAIL(ctx, ES_EIO, "'%s' is an HDF5 file (a store?); not overwriting it with CSV",
                path);
    if ((rc = es__replace_begin(ctx, path, &t->w)) != ES_OK) return rc;
    t->f = t->w.f;
    return ES_OK;
}

es_status es__table_end(es_ctx *ctx, es__table_out *t, es_status rc)
{
    if (!t->f) return rc;
    if (t->f == stdout) {
        if (rc == ES_OK && (ferror(stdout) || fflush(stdout) != 0))
            rc = es__fail(ctx, ES_EIO, "error writing to standard output: %s", strerror(errno));
        t->f = NULL;
        return rc;
    }
    t->f = NULL;
    return t->set ? es__replace_end_staged(ctx, &t->w, rc, t->set)
                  : es__replace_end(ctx, &t->w, rc);
}

void es__table_number(FILE *f, double v)
{
    fprintf(f, ",%.17g", v);
}

es_status es_study_write_edge_table(es_ctx *ctx, es_store *store, const char *path,
                                    int64_t ncol, const char *const *names,
                                    const double *values)
{
    /* the stored edge list, not es_store_mesh: truss stores have no faces */
    const int64_t E = es_store_nedges(store);
    int64_t *edges = es__alloc_array(ctx, 2 * E > 0 ? 2 * E : 1, sizeof *edges);
    es__table_out t;
    es_status rc;
    if (!edges) return ES_ENOMEM;
    if ((rc = es_store_read_edges(ctx, store, edges)) != ES_OK ||
        (rc = es__table_begin(ctx, path, &t)) != ES_OK) {
        es__free(ctx, edges);
        return rc;
    }
    fputs("edge,v0,v1", t.f);
    for (int64_t c = 0; c < ncol; c++) {
        fputc(',', t.f);
        es_csv_write_field(t.f, names[c]);
    }
    fputc('\n', t.f);
    for (int64_t e = 0; e < E; e++) {
        fprintf(t.f, "%lld,%lld,%lld", (long long)e, (long long)edges[2 * e],
                (long long)edges[2 * e + 1]);
        for (int64_t c = 0; c < ncol; c++) es__table_number(t.f, values[e + c * E]);
        fputc('\n', t.f);
    }
    es__free(ctx, edges);
    return es__table_end(ctx, &t, ES_OK);
}

es_status es_study_write_mean_table(es_ctx *ctx, es_store *store, const es_group_result *r,
                                    const char *path)
{
    return es_study_write_edge_table(ctx, store, path, r->ngroups, (const char *const *)r->names,
                                     r->means);
}

es_status es_study_write_diff_table(es_ctx *ctx, es_store *store, const es_diff *d,
                                    const char *path)
{
    static const char *const names[4] = {"mean", "sd", "se", "t"};
    const int64_t E = d->nedges;
    double *vals = es__alloc_array(ctx, 4 * E, sizeof *vals);
    es_status rc;
    if (!vals) return ES_ENOMEM;
    memcpy(vals, d->mean, (size_t)E * sizeof *vals);
    memcpy(vals + E, d->sd, (size_t)E * sizeof *vals);
    memcpy(vals + 2 * E, d->se, (size_t)E * sizeof *vals);
    memcpy(vals + 3 * E, d->t, (size_t)E * sizeof *vals);
    rc = es_study_write_edge_table(ctx, store, path, 4, names, vals);
    es__free(ctx, vals);
    return rc;
}

es_status es__write_row_table(es_ctx *ctx, es_store *st, const char *path, int64_t n,
                              const int64_t *rows, int64_t ncol, const char *const *names,
                              const double *values)
{
    const int64_t ncols = es_store_ncolumns(st), N = es_store_nrows(st);
    for (int64_t i = 0; i < n; i++)
        if (rows[i] < 0 || rows[i] >= N)
            ES_FAIL(ctx, ES_EFORMAT, "table: row %lld is not in the store", (long long)rows[i]);
    es__table_out t;
    es_status rc = es__table_begin(ctx, path, &t);
    if (rc != ES_OK) return rc;
    fputs("id", t.f);
    for (int64_t c = 0; c < ncols; c++) {
        fputc(',', t.f);
        es_csv_write_field(t.f, es_store_column_name(st, c));
    }
    for (int64_t k = 0; k < ncol; k++) {
        fputc(',', t.f);
        es_csv_write_field(t.f, names[k]);
    }
    fputc('\n', t.f);
    for (int64_t i = 0; i < n; i++) {
        es_csv_write_field(t.f, es_store_row_id(st, rows[i]));
        for (int64_t c = 0; c < ncols; c++) {
            fputc(',', t.f);
            es_csv_write_field(t.f, es_store_label(st, rows[i], c));
        }
        for (int64_t k = 0; k < ncol; k++) es__table_number(t.f, values[i + k * n]);
        fputc('\n', t.f);
    }
    return es__table_end(ctx, &t, ES_OK);
}

es_status es__numbered_names(es_ctx *ctx, const char *prefix, int64_t n, char ***names)
{
    size_t len = strlen(prefix) + 24;
    *names = es__calloc(ctx, (size_t)(n > 0 ? n : 1), sizeof **names);
    if (!*names) return ES_ENOMEM;
    for (int64_t k = 0; k < n; k++) {
        if (!((*names)[k] = es__malloc(ctx, len))) {
            es__free_names(ctx, *names, n);
            *names = NULL;
            return ES_ENOMEM;
        }
        snprintf((*names)[k], len, "%s%lld", prefix, (long long)(k + 1));
    }
    return ES_OK;
}

void es__free_names(es_ctx *ctx, char **names, int64_t n)
{
    for (int64_t k = 0; names && k < n; k++) es__free(ctx, names[k]);
    es__free(ctx, names);
}

static es_status write_scores(es_ctx *ctx, es_store *st, const es_pca *p, const int64_t *rows,
                              const char *path)
{
    char **names = NULL;
    es_status rc = es__numbered_names(ctx, "PC", p->ncomp, &names);
    if (rc != ES_OK) return rc;
    rc = es__write_row_table(ctx, st, path, p->nrows, rows, p->ncomp,
                             (const char *const *)names, p->scores);
    es__free_names(ctx, names, p->ncomp);
    return rc;
}

static es_status write_eigenvalues(es_ctx *ctx, const es_pca *p, const char *path)
{
    es__table_out t;
    double cum = 0;
    es_status rc = es__table_begin(ctx, path, &t);
    if (rc != ES_OK) return rc;
    fputs("component,eigenvalue,explained,cumulative\n", t.f);
    for (int64_t k = 0; k < p->ncomp; k++) {
        cum += p->explained[k];
        fprintf(t.f, "%lld", (long long)(k + 1));
        es__table_number(t.f, p->eigenvalues[k]);
        es__table_number(t.f, p->explained[k]);
        es__table_number(t.f, cum);
        fputc('\n', t.f);
    }
    return es__table_end(ctx, &t, ES_OK);
}

/* The mean and the components per edge. */
static es_status write_components(es_ctx *ctx, es_store *st, const es_pca *p, const char *path)
{
    const int64_t E = p->nedges, K = p->ncomp;
    double *vals = es__alloc_array(ctx, E * (K + 1), sizeof *vals);
    char (*label)[24] = es__alloc_array(ctx, K + 1, sizeof *label);
    const char **names = es__alloc_array(ctx, K + 1, sizeof *names);
    es_status rc = ES_ENOMEM;
    if (vals && label && names) {
        memcpy(vals, p->mean, (size_t)E * sizeof *vals);
        memcpy(vals + E, p->components, (size_t)(E * K) * sizeof *vals);
        names[0] = "mean";
        for (int64_t k = 0; k < K; k++) {
            snprintf(label[k + 1], sizeof label[k + 1], "PC%lld", (long long)(k + 1));
            names[k + 1] = label[k + 1];
        }
        rc = es_study_write_edge_table(ctx, st, path, K + 1, names, vals);
    }
    es__free(ctx, vals);
    es__free(ctx, label);
    es__free(ctx, (void *)names);
    return rc;
}

es_status es_study_write_pca_tables(es_ctx *ctx, es_store *store, const es_pca *p,
                                    const int64_t *rows, const char *prefix)
{
    size_t n = strlen(prefix) + 32;
    char *path = es__malloc(ctx, n);
    es_status rc;
    if (!path) return ES_ENOMEM;
    snprintf(path, n, "%s_scores.csv", prefix);
    if ((rc = write_scores(ctx, store, p, rows, path)) == ES_OK) {
        snprintf(path, n, "%s_eigenvalues.csv", prefix);
        if ((rc = write_eigenvalues(ctx, p, path)) == ES_OK) {
            snprintf(path, n, "%s_components.csv", prefix);
            rc = write_components(ctx, store, p, path);
        }
    }
    es__free(ctx, path);
    return rc;
}

es_status es_study_write_projection_table(es_ctx *ctx, const es_study_projection *p,
                                          const char *path)
{
    es__table_out t;
    es_status rc = es__table_begin(ctx, path, &t);
    if (rc != ES_OK) return rc;
    fputs("name", t.f);
    for (int64_t k = 0; k < p->ncomp; k++) fprintf(t.f, ",PC%lld", (long long)(k + 1));
    fputs(",residual\n", t.f);
    for (int64_t i = 0; i < p->n; i++) {
        es_csv_write_field(t.f, p->names[i]);
        for (int64_t k = 0; k < p->ncomp; k++) es__table_number(t.f, p->scores[i + k * p->n]);
        es__table_number(t.f, p->residuals[i]);
        fputc('\n', t.f);
    }
    return es__table_end(ctx, &t, ES_OK);
}
