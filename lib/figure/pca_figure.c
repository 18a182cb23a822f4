/* lib/figure/pca_figure.c — the figures of a stored PCA (es_figure_pca,
 * behind `edgespace plot-pca`): the scores on two components coloured by a
 * label column, as in Fig. 9 of Fisher et al., or the scree plot. The
 * store gives the PCA and the labels of the rows it was fitted on; the
 * plots are es_plot.h's.
 */
#include "figure/figure_pkg.h"
#include "edgespace/es_figure.h"
#include "edgespace/es_study.h"

#include <stdio.h>

static es_status draw_scores(es_ctx *ctx, es_store *store, const es_pca *p, const int64_t *rows,
                             int64_t nrows, int64_t a, int64_t b, const char *color,
                             const char *title, const char *out)
{
    char xl[64], yl[64];
    const char **labels = NULL;
    es_status rc;
    if (a < 1 || b < 1 || a > p->ncomp || b > p->ncomp)
        ES_FAIL(ctx, ES_EINVAL, "the PCA has %lld components", (long long)p->ncomp);
    int64_t col = color ? es_store_find_column(store, color) : -1;
    if (color && col < 0) {
        char hint[400];
        es_store_column_hint(store, color, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "no label column '%s'%s", color, hint);
    }
    if (col >= 0) {
        if (!(labels = es__alloc_array(ctx, nrows, sizeof *labels))) return ES_ENOMEM;
        for (int64_t i = 0; i < nrows; i++) labels[i] = es_store_label(store, rows[i], col);
    }
    es_scatter_spec sp;
    es_scatter_spec_init(&sp);
    snprintf(xl, sizeof xl, "PC%lld (%.1f%%)", (long long)a, 100 * p->explained[a - 1]);
    snprintf(yl, sizeof yl, "PC%lld (%.1f%%)", (long long)b, 100 * p->explained[b - 1]);
    sp.frame.xlabel = xl;
    sp.frame.ylabel = yl;
    sp.frame.title = title;
    sp.n = nrows;
    sp.x = p->scores + (a - 1) * nrows;
    sp.y = p->scores + (b - 1) * nrows;
    sp.labels = labels;
    sp.legend_title = color;
    rc = es_plot_scatter(ctx, &sp, out, NULL);
    es__free(ctx, labels);
    return rc;
}

es_status es_figure_pca(es_ctx *ctx, es_store *store, const char *pca_name, int64_t pc_a,
                        int64_t pc_b, const char *color_column, int scree, const char *title,
                        const char *out_path)
{
    es_pca *p = NULL;
    int64_t *rows = NULL, nrows = 0;
    es_status rc;
    if (!store || !out_path) ES_FAIL(ctx, ES_EINVAL, "figure pca: NULL store or output path");
    if ((rc = es_study_pca_load(ctx, store, pca_name, &p, &rows, &nrows)) != ES_OK) return rc;
    if (scree) {
        es_scree_spec sp;
        es_scree_spec_init(&sp);
        sp.n = p->ncomp;
        sp.variance = p->eigenvalues;
        sp.total = p->total_variance;
        sp.frame.title = title;
        rc = es_plot_scree(ctx, &sp, out_path, NULL);
    } else {
        rc = draw_scores(ctx, store, p, rows, nrows, pc_a, pc_b, color_column, title, out_path);
    }
    es__free(ctx, rows);
    es_pca_free(p);
    return rc;
}
