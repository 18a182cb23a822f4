/* lib/figure/compare_figures.c — the comparison study's figures: the two
 * distance heat maps and the scatter of distance pairs coloured by group
 * pair; and the study on a store with its tables and figures in one call.
 */
#include "figure/figure_pkg.h"
#include "core/files.h"
#include "edgespace/es_figure.h"
#include "edgespace/es_study.h"

#include <stdio.h>
#include <stdlib.h>

typedef struct names {
    const char *const *s;
    char buf[32];
} names;

/* Name i: the given one, or its 1-based number. */
static const char *name_of(names *nm, int64_t i)
{
    if (nm->s) return nm->s[i];
    snprintf(nm->buf, sizeof nm->buf, "%lld", (long long)i + 1);
    return nm->buf;
}

es_status es_figure_compare_write(es_ctx *ctx, const es_compare_result *r,
                                  const char *const *ids, const int64_t *group,
                                  const char *const *gnames, const char *dir)
{
    char path[4096];
    es_status rc;
    int64_t n = r->n, m = n * (n - 1) / 2;
    if ((rc = es__mkdir_p(ctx, dir)) != ES_OK)
        return es__fail(ctx, rc, "compare: %s", es_ctx_errmsg(ctx));
    const char *files[2] = {"heatmap_lengths.svg", "heatmap_procrustes.svg"};
    const char *titles[2] = {"edge-length distances (scale-normalized)",
                             "Procrustes distances (GPA-aligned)"};
    double *mats[2] = {r->d_len, r->d_proc};
    for (int s = 0; s < 2; s++) {
        es_heatmap_spec h;
        es_heatmap_spec_init(&h);
        h.frame.title = titles[s];
        h.values = (es_mat){mats[s], n, n, n};
        h.row_labels = n <= 60 ? ids : NULL;
        h.col_labels = n <= 60 ? ids : NULL;
        h.colorbar_label = "distance";
        snprintf(path, sizeof path, "%s/%s", dir, files[s]);
        if ((rc = es_plot_heatmap(ctx, &h, path, NULL)) != ES_OK) return rc;
    }
    double *x = es__alloc_array(ctx, 2 * m, sizeof *x);
    char **lab = group ? es__calloc(ctx, (size_t)m, sizeof *lab) : NULL;
    if (!x || (group && !lab)) {
        es__free(ctx, x);
        es__free(ctx, lab);
        return ES_ENOMEM;
    }
    double *y = x + m;
    names g1 = {gnames, {0}}, g2 = {gnames, {0}};
    rc = ES_OK;
    for (int64_t j = 1, t = 0; j < n; j++)
        for (int64_t i = 0; i < j; i++, t++) {
            x[t] = r->d_len[i + j * n];
            y[t] = r->d_proc[i + j * n];
            if (group && rc == ES_OK) {
                char a[32], b[32];
                snprintf(a, sizeof a, "%s", name_of(&g1, group[i]));
                snprintf(b, sizeof b, "%s", name_of(&g2, group[j]));
                if (!(lab[t] = es_compare_pair_label(ctx, gnames ? gnames[group[i]] : a,
                                          gnames ? gnames[group[j]] : b)))
                    rc = ES_ENOMEM;
            }
        }
    if (rc == ES_OK) {
        es_scatter_spec sc;
        es_scatter_spec_init(&sc);
        sc.frame.title = "pairs of shapes in both spaces";
        sc.frame.xlabel = "edge-length distance";
        sc.frame.ylabel = "Procrustes distance";
        sc.n = m;
        sc.x = x;
        sc.y = y;
        sc.labels = (const char *const *)lab;
        sc.legend_title = group ? "group pair" : NULL;
        sc.marker_radius = m > 2000 ? 2 : 4;
        snprintf(path, sizeof path, "%s/pairs_scatter.svg", dir);
        rc = es_plot_scatter(ctx, &sc, path, NULL);
    }
    if (lab)
        for (int64_t t = 0; t < m; t++) es__free(ctx, lab[t]);
    es__free(ctx, lab);
    es__free(ctx, x);
    return rc;
}


es_status es_figure_compare(es_ctx *ctx, es_store *store, const char *gpa_name, const char *by,
                            const es_compare_opts *opts, const char *name, const char *out_dir,
                            const char *command, es_compare_result **res)
{
    es_compare_result *r = NULL;
    es_status rc = es_study_compare(ctx, store, gpa_name, by, opts, name, out_dir, command, &r);
    if (rc == ES_OK && out_dir)
        rc = es_figure_compare_write(ctx, r, (const char *const *)r->ids, r->group,
                                     (const char *const *)r->group_names, out_dir);
    if (rc == ES_OK && res) {
        *res = r;
        r = NULL;
    }
    es_compare_result_free(r);
    return rc;
}
