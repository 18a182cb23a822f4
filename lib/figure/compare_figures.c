/* lib/figure/compare_figures.c — the comparison study's figures: the two
 * distance heat maps (rows ordered by group, labelled with ids or group
 * names, the colour bar in the distance's units) and the scatter of
 * distance pairs coloured by group pair; and the study on a store with its
 * tables and figures in one call.
 */
#include "figure/figure_pkg.h"
#include "core/files.h"
#include "edgespace/es_figure.h"
#include "edgespace/es_study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* A row of the heat maps, sorted by group, then by id, then by row number
 * (the key carries all three, so the order is total and qsort stable). */
typedef struct order_key {
    int64_t row, group;
    const char *id;
} order_key;

static int cmp_order(const void *pa, const void *pb)
{
    const order_key *a = pa, *b = pb;
    if (a->group != b->group) return a->group < b->group ? -1 : 1;
    int c = a->id && b->id ? strcmp(a->id, b->id) : 0;
    if (c) return c;
    return (a->row > b->row) - (a->row < b->row);
}

es_status es_figure_compare_heatmap(es_ctx *ctx, const es_compare_result *r, int which,
                                    const char *const *ids, const int64_t *group,
                                    const char *const *gnames, const char *path,
                                    es_plot_info *info)
{
    if (!r || which < 0 || which > 2 || !path)
        ES_FAIL(ctx, ES_EINVAL, "compare heatmap: no result, no path or a matrix %d "
                "that is not 0 (edge lengths), 1 (Procrustes) or 2 (rho)", which);
    if (which == 2 && !r->d_rho)
        ES_FAIL(ctx, ES_EINVAL, "compare heatmap: the result has no rho distances");
    const int64_t n = r->n;
    const double *d = which == 2 ? r->d_rho : which ? r->d_proc : r->d_len;
    order_key *key = es__alloc_array(ctx, n, sizeof *key);
    double *sorted = es__alloc_array(ctx, n * n, sizeof *sorted);
    int64_t *sgroup = es__alloc_array(ctx, n, sizeof *sgroup);
    const char **sids = es__alloc_array(ctx, n, sizeof *sids);
    es_status rc = key && sorted && sgroup && sids ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK) {
        for (int64_t i = 0; i < n; i++)
            key[i] = (order_key){i, group ? group[i] : 0, ids ? ids[i] : NULL};
        qsort(key, (size_t)n, sizeof *key, cmp_order);
        for (int64_t j = 0; j < n; j++) {
            sgroup[j] = key[j].group;
            sids[j] = key[j].id;
            for (int64_t i = 0; i < n; i++) sorted[i + j * n] = d[key[i].row + key[j].row * n];
        }
        es_heatmap_spec h;
        es_heatmap_spec_init(&h);
        h.frame.width = 720;
        h.frame.height = 660;   /* square cells beside the colour bar */
        h.frame.title = which == 2 ? "Riemannian shape distances ρ (unit centroid size)"
                        : which ? "Procrustes distances (GPA-aligned)"
                                : "edge-length distances (scale-normalized)";
        h.values = (es_mat){sorted, n, n, n};
        /* ids while they can be read (two per line of text at most); the
         * group names carry a larger matrix */
        h.row_labels = h.col_labels = ids && n <= 60 ? sids : NULL;
        h.row_groups = h.col_groups = group ? sgroup : NULL;
        h.group_names = gnames;
        h.colorbar_label = which == 2 ? "ρ (radians, as shapes::riemdist)"
                           : which ? "Procrustes distance (data units, GPA-aligned)"
                           : r->normalized_lengths
                               ? "distance between unit-sum length vectors"
                               : "edge-length distance (data units)";
        rc = es_plot_heatmap(ctx, &h, path, info);
    }
    es__free(ctx, key);
    es__free(ctx, sorted);
    es__free(ctx, sgroup);
    es__free(ctx, sids);
    return rc;
}

/* "png", "pdf" or "svg" (NULL: svg). */
static es_status check_format(es_ctx *ctx, const char *format)
{
    static const char *const known[] = {"png", "pdf", "svg"};
    for (size_t i = 0; i < sizeof known / sizeof *known; i++)
        if (!strcmp(format, known[i])) return ES_OK;
    ES_FAIL(ctx, ES_EINVAL, "compare: unknown figure format '%s' (png, pdf, svg)", format);
}

es_status es_figure_compare_write(es_ctx *ctx, const es_compare_result *r,
                                  const char *const *ids, const int64_t *group,
                                  const char *const *gnames, const char *dir,
                                  const char *format)
{
    char path[4096];
    es_status rc;
    int64_t n = r->n, m = n * (n - 1) / 2;
    if (!format) format = "svg";
    if ((rc = check_format(ctx, format)) != ES_OK) return rc;
    if ((rc = es__mkdir_p(ctx, dir)) != ES_OK)
        return es__fail(ctx, rc, "compare: %s", es_ctx_errmsg(ctx));
    const char *files[3] = {"heatmap_lengths", "heatmap_procrustes", "heatmap_rho"};
    for (int s = 0; s < (r->d_rho ? 3 : 2); s++) {
        snprintf(path, sizeof path, "%s/%s.%s", dir, files[s], format);
        if ((rc = es_figure_compare_heatmap(ctx, r, s, ids, group, gnames, path, NULL)) != ES_OK)
            return rc;
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
        snprintf(path, sizeof path, "%s/pairs_scatter.%s", dir, format);
        rc = es_plot_scatter(ctx, &sc, path, NULL);
    }
    if (lab)
        for (int64_t t = 0; t < m; t++) es__free(ctx, lab[t]);
    es__free(ctx, lab);
    es__free(ctx, x);
    return rc;
}


es_status es_figure_compare(es_ctx *ctx, es_store *store, const es_study_compare_opts *opts,
                            const char *format, es_compare_result **res)
{
    es_compare_result *r = NULL;
    const char *out_dir = opts ? opts->out_dir : NULL;
    es_status rc = es_study_compare(ctx, store, opts, &r);
    if (rc == ES_OK && out_dir)
        rc = es_figure_compare_write(ctx, r, (const char *const *)r->ids, r->group,
                                     (const char *const *)r->group_names, out_dir, format);
    if (rc == ES_OK && res) {
        *res = r;
        r = NULL;
    }
    es_compare_result_free(r);
    return rc;
}
