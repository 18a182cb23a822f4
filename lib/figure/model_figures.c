/* lib/figure/model_figures.c — figures of models and of shape variation:
 * the per-edge tests of a model as a heat map on the mean mesh
 * (es_figure_edge_tests: each significant edge's F, log scale), and mean +- k sd along principal components or
 * along a model coefficient, embedded near the data and drawn in one frame
 * beside the per-vertex displacement (es_figure_variation).
 *
 * The mean mesh is the Procrustes mean of the rows' positions (the prior of
 * uniform row weights, es_study_prior), which looks like the data by
 * construction. The variation's shapes are embedded by es_study_embed with
 * its defaults, near the prior of each point's row weights and in the
 * store's frame, so the minus, mean and plus shapes stand in one place and
 * share one camera; the displacement is measured after a rigid alignment
 * of plus onto minus (Kabsch), so it shows shape change, not placement.
 */
#include "figure/figure_pkg.h"
#include "edgespace/es_figure.h"
#include "edgespace/es_study.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The Procrustes mean of rows (uniform weights over them) in the store's
 * frame; the mesh too. */
static es_status mean_mesh(es_ctx *ctx, es_store *store, const int64_t *rows, int64_t n,
                           es_mesh **mesh, double **xyz)
{
    es_study_rows *sr = NULL;
    const int64_t N = es_store_nrows(store);
    double *w = es__calloc(ctx, (size_t)(N > 0 ? N : 1), sizeof *w);
    es_status rc = w ? ES_OK : ES_ENOMEM;
    *xyz = NULL;
    if (rc == ES_OK) rc = es_store_mesh(ctx, store, mesh);
    if (rc == ES_OK && !(*xyz = es__alloc_array(ctx, 3 * es_mesh_nverts(*mesh), sizeof **xyz)))
        rc = ES_ENOMEM;
    for (int64_t i = 0; rc == ES_OK && i < n; i++) w[rows ? rows[i] : i] += 1.0 / (double)n;
    if (rc == ES_OK) rc = es_study_rows_load(ctx, store, *mesh, &sr);
    if (rc == ES_OK) rc = es_study_prior(ctx, sr, w, *xyz, NULL, NULL);
    es_study_rows_free(sr);
    es__free(ctx, w);
    return rc;
}

es_status es_figure_edge_tests(es_ctx *ctx, es_store *store, const es_study_model_result *r,
                               const char *out_path)
{
    if (!r || !r->edge_q || !out_path)
        ES_FAIL(ctx, ES_EINVAL, "edge figure: the model has no per-edge tests (--edges TERM)");
    const int64_t E = es_store_nedges(store);
    if (r->model->p != E)
        ES_FAIL(ctx, ES_EINVAL, "edge figure: the model is not per edge");
    es_mesh *mesh = NULL;
    double *xyz = NULL, *v = es__alloc_array(ctx, E, sizeof *v);
    es_status rc = v ? mean_mesh(ctx, store, r->rows, r->nrows, &mesh, &xyz) : ES_ENOMEM;
    int64_t nsig = 0;
    if (rc == ES_OK) {
        /* The F of each edge, not its q: with most edges significant, q sits
         * at its floor 1/(B+1) almost everywhere and shows nothing, while F
         * still ranks the edges. Log scale since F spans decades; the edges
         * not significant (q >= 0.05, or untested) are NaN, drawn grey. */
        for (int64_t e = 0; e < E; e++) {
            bool sig = r->edge_q[e] < 0.05 && r->edge_f[e] > 0;
            v[e] = sig ? log10(r->edge_f[e]) : NAN;
            nsig += sig;
        }
        char title[256];
        es_render_mesh m;
        es_render_spec spec;
        es_render_mesh_from(&m, mesh, xyz);
        m.scalar_kind = ES_SCALARS_EDGE;
        m.scalars = v;
        es_render_spec_init(&spec);
        spec.nmeshes = 1;
        spec.meshes = &m;
        spec.cmap = ES_CMAP_VIRIDIS;
        /* a few extreme edges do not set the range of all (render --percentiles) */
        spec.range_percentiles[0] = 2;
        spec.range_percentiles[1] = 98;
        spec.colorbar_log10 = 1;
        snprintf(title, sizeof title, "%lld of %lld edges with FDR q < 0.05",
                 (long long)nsig, (long long)E);
        spec.nan_label = "q \u2265 0.05";
        spec.title = title;
        spec.colorbar_label = "per-edge F (log)";
        rc = es_render(ctx, &spec, out_path, NULL);
    }
    es_mesh_free(mesh);
    es__free(ctx, xyz);
    es__free(ctx, v);
    return rc;
}

/* ---- shape variation ------------------------------------------------------------ */

void es_figure_variation_opts_init(es_figure_variation_opts *o)
{
    memset(o, 0, sizeof *o);
    o->k = 2;
    o->panel = 360;
    es_embed_opts_init(&o->embed);
}

/* One point near its prior in the session (es_study_embed's default),
 * warm from the last: mean, then - and + along each axis. */
static es_status embed_point(es_ctx *ctx, es_study_embedder *se, const es_figure_variation_opts *o,
                             const char *point, double *xyz, es_embed_report *rep, int64_t *done,
                             int64_t total)
{
    es_study_embed_result res;
    es_status rc = es_study_embedder_point(ctx, se, point, o->pca_name, 0, &o->embed, 1, xyz, &res);
    if (rc != ES_OK) return es__fail(ctx, rc, "variation: %s: %s", point, es_ctx_errmsg(ctx));
    if (rep) *rep = res.report;
    es__progress(ctx, "variation: embedding", ++*done, total);
    return ES_OK;
}

/* Per-vertex distance of b from a after b is rigidly aligned onto a. */
static es_status displacement(es_ctx *ctx, int64_t nv, const double *a, const double *b,
                              double *d, double *dmax)
{
    double *ca = es__alloc_array(ctx, 6 * nv, sizeof *ca), *cb = ca ? ca + 3 * nv : NULL;
    if (!ca) return ES_ENOMEM;
    es_procrustes_from_xyz(nv, a, ca);
    es_procrustes_from_xyz(nv, b, cb);
    es_status rc = es_procrustes_opa(ctx, nv, 3, ca, cb, 0, 0, cb, NULL, NULL, NULL);
    if (rc == ES_OK) {
        /* opa centres its output: centre a too */
        double c[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++) {
            for (int64_t v = 0; v < nv; v++) c[k] += ca[v + k * nv] / (double)nv;
            for (int64_t v = 0; v < nv; v++) ca[v + k * nv] -= c[k];
        }
        *dmax = 0;
        for (int64_t v = 0; v < nv; v++) {
            double s = 0;
            for (int k = 0; k < 3; k++) s += pow(cb[v + k * nv] - ca[v + k * nv], 2);
            d[v] = sqrt(s);
            if (d[v] > *dmax) *dmax = d[v];
        }
    }
    es__free(ctx, ca);
    return rc;
}

es_status es_figure_variation(es_ctx *ctx, es_store *store, const es_figure_variation_opts *opts,
                              const char *out_path, es_figure_variation_report *rep)
{
    es_figure_variation_opts o;
    if (opts) o = *opts;
    else es_figure_variation_opts_init(&o);
    const int64_t one = 1, *pcs = o.npcs > 0 ? o.pcs : &one;
    const int64_t naxes = o.coef ? 1 : (o.npcs > 0 ? o.npcs : 1);
    if (!store || !out_path) ES_FAIL(ctx, ES_EINVAL, "variation: no store or no output");
    if (naxes > ES_VARIATION_MAX_AXES)
        ES_FAIL(ctx, ES_EINVAL, "variation: at most %d components", ES_VARIATION_MAX_AXES);
    if (!(o.k > 0) || !isfinite(o.k))
        ES_FAIL(ctx, ES_EINVAL, "variation: k = %g is not a positive number", o.k);
    if (o.coef && !strchr(o.coef, ':'))
        ES_FAIL(ctx, ES_EINVAL, "variation: name the coefficient as MODEL:COEF, not '%s'", o.coef);
    es_figure_variation_report r;
    memset(&r, 0, sizeof r);
    r.naxes = naxes;
    es_mesh *mesh = NULL;
    es_study_embedder *se = NULL;
    int64_t done = 0, total = 1 + 2 * naxes;
    es_status rc = es_study_embedder_open(ctx, store, 1, &se);
    if (rc == ES_OK) rc = es_store_mesh(ctx, store, &mesh);
    if (rc != ES_OK) {
        es_study_embedder_free(se);
        return rc;
    }
    const int64_t nv = es_mesh_nverts(mesh), npanel = 4 * naxes;
    double *xyz = es__alloc_array(ctx, 3 * nv * (1 + 2 * naxes), sizeof *xyz);
    double *disp = es__alloc_array(ctx, nv * naxes, sizeof *disp);
    es_render_mesh *items = es__calloc(ctx, (size_t)npanel, sizeof *items);
    char (*labels)[160] = es__alloc_array(ctx, npanel, sizeof *labels);
    if (!xyz || !disp || !items || !labels) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = embed_point(ctx, se, &o, "mean", xyz, &r.mean, &done, total)) != ES_OK) goto done;
    for (int64_t a = 0; a < naxes && rc == ES_OK; a++) {
        char lo[512], hi[512], what[128];
        if (o.coef) {
            snprintf(lo, sizeof lo, "mean - %.17g*coef:%s", o.k, o.coef);
            snprintf(hi, sizeof hi, "mean + %.17g*coef:%s", o.k, o.coef);
            snprintf(what, sizeof what, "%s", o.coef);
        } else {
            if (pcs[a] < 1) {
                rc = es__fail(ctx, ES_EINVAL, "variation: component %lld", (long long)pcs[a]);
                break;
            }
            snprintf(lo, sizeof lo, "mean - %.17g*pc:%lld", o.k, (long long)pcs[a]);
            snprintf(hi, sizeof hi, "mean + %.17g*pc:%lld", o.k, (long long)pcs[a]);
            snprintf(what, sizeof what, "PC%lld", (long long)pcs[a]);
        }
        double *xm = xyz + 3 * nv * (1 + 2 * a), *xp = xm + 3 * nv;
        if ((rc = embed_point(ctx, se, &o, lo, xm, &r.minus[a], &done, total)) != ES_OK ||
            (rc = embed_point(ctx, se, &o, hi, xp, &r.plus[a], &done, total)) != ES_OK ||
            (rc = displacement(ctx, nv, xm, xp, disp + a * nv, &r.max_displacement[a])) != ES_OK)
            break;
        const char *unit = o.coef ? "" : " sd";
        snprintf(labels[4 * a], 160, "%s \u2212%g%s", what, o.k, unit);   /* minus sign */
        snprintf(labels[4 * a + 1], 160, "mean");
        snprintf(labels[4 * a + 2], 160, "%s +%g%s", what, o.k, unit);
        snprintf(labels[4 * a + 3], 160, "%s: displacement \u2212 to +", what);
        const double *pos[4] = {xm, xyz, xp, xyz};
        for (int k = 0; k < 4; k++) {
            es_render_mesh_from(&items[4 * a + k], mesh, pos[k]);
            items[4 * a + k].label = labels[4 * a + k];
        }
        items[4 * a + 3].scalar_kind = ES_SCALARS_VERTEX;
        items[4 * a + 3].scalars = disp + a * nv;
    }
    if (rc != ES_OK) goto done;
    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.nmeshes = npanel;
    spec.meshes = items;
    spec.ncols = 4;
    spec.same_view = 1;
    spec.width = spec.height = o.panel > 0 ? o.panel : 360;
    spec.vmin = 0;
    for (int64_t a = 0; a < naxes; a++)
        if (r.max_displacement[a] > spec.vmax) spec.vmax = r.max_displacement[a];
    if (!(spec.vmax > 0)) spec.vmax = 1;
    spec.colorbar_label = "displacement (data units)";
    char title[256];
    if (o.title) spec.title = o.title;
    else {
        snprintf(title, sizeof title, "shape variation: mean \u00b1 %g %s, embedded near the data",
                 o.k, o.coef ? "\u00d7 coefficient" : "sd");
        spec.title = title;
    }
    rc = es_render(ctx, &spec, out_path, &r.render);
done:
    if (rep) *rep = r;
    es_study_embedder_free(se);
    es_mesh_free(mesh);
    es__free(ctx, xyz);
    es__free(ctx, disp);
    es__free(ctx, items);
    es__free(ctx, labels);
    return rc;
}
