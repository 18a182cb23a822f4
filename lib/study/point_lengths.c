/* lib/study/point_lengths.c — a point as a command line names it (a row, a
 * stored point, an expression) turned into lengths and a scale: what embed,
 * interp and every other consumer of a point share. */
#include "core/core_private.h"
#include "edgespace/es_study.h"
#include "study/study_pkg.h"

#include <math.h>
#include <stdio.h>

/* The mean scale of the store's rows: the scale of a point without one. */
static es_status mean_row_scale(es_ctx *ctx, es_store *store, double *scale)
{
    int64_t n = es_store_nrows(store);
    double *scales = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *scales);
    es_status rc;
    if (!scales) return ES_ENOMEM;
    *scale = 0;
    if ((rc = es_store_read_scales(ctx, store, scales)) == ES_OK)
        for (int64_t i = 0; i < n; i++) *scale += scales[i] / (double)n;
    es__free(ctx, scales);
    return rc;
}

static es_status row_point(es_ctx *ctx, es_store *store, const char *id, double *lengths,
                           double *scale, double *w)
{
    int64_t r = es_store_find_row(store, id), ne = es_store_nedges(store);
    double *scales;
    es_status rc;
    if (r < 0) {
        char hint[400];
        es_store_value_hint(store, -1, id, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "no row '%s' in the store%s", id, hint);
    }
    if (!(scales = es__alloc_array(ctx, es_store_nrows(store), sizeof *scales)))
        return ES_ENOMEM;
    if ((rc = es_store_read_lengths(ctx, store, r, 1, (es_mat){lengths, ne, 1, ne})) == ES_OK &&
        (rc = es_store_read_scales(ctx, store, scales)) == ES_OK)
        *scale = scales[r];
    es__free(ctx, scales);
    if (w) w[r] = 1;
    return rc;
}

/* A stored point's row weights, or (stored before points kept them) ridge
 * regression on the rows. */
static es_status stored_weights(es_ctx *ctx, es_store *store, const char *name,
                                const double *lengths, double *w)
{
    char path[512];
    double *v = NULL;
    int64_t n = 0, N = es_store_nrows(store);
    es_status rc;
    snprintf(path, sizeof path, "point/%s/row_weights", name);
    if (!es_store_has(store, path)) {
        es_study_resolver r = {store, NULL, NULL, NULL, NULL, NULL, NULL};
        es_source src;
        es_pca_opts o;
        es_pca_opts_init(&o);
        if ((rc = es_study_source(ctx, store, NULL, 0, &src)) == ES_OK &&
            (rc = es_pca_fit(ctx, &src, &o, &r.all_rows)) == ES_OK)
            rc = es_pca_row_weights(ctx, r.all_rows, lengths, ES_RIDGE_REL, w);
        es_study_resolver_clear(ctx, &r);
        return rc;
    }
    if ((rc = es_store_get_vector(ctx, store, path, &v, &n)) != ES_OK) return rc;
    if (n != N) rc = es__fail(ctx, ES_EMISMATCH, "point '%s' has weights for %lld rows, the "
                              "store has %lld (rows were added since it was stored)", name,
                              (long long)n, (long long)N);
    else memcpy(w, v, (size_t)N * sizeof *w);
    es__free(ctx, v);
    return rc;
}

static es_status stored_point(es_ctx *ctx, es_store *store, const char *name, double *lengths,
                              double *scale, double *w)
{
    char path[512];
    double *v = NULL;
    int64_t n = 0, ne = es_store_nedges(store);
    es_status rc;
    snprintf(path, sizeof path, "point/%s/lengths", name);
    if ((rc = es_store_get_vector(ctx, store, path, &v, &n)) != ES_OK) return rc;
    if (n != ne) {
        es__free(ctx, v);
        ES_FAIL(ctx, ES_EMISMATCH, "point '%s' has %lld lengths, the store's topology %lld "
                "edges", name, (long long)n, (long long)ne);
    }
    memcpy(lengths, v, (size_t)ne * sizeof *lengths);
    es__free(ctx, v);
    v = NULL;
    snprintf(path, sizeof path, "point/%s/scale", name);
    if (es_store_has(store, path) && (rc = es_store_get_vector(ctx, store, path, &v, &n)) == ES_OK &&
        n >= 1 && v[0] > 0)
        *scale = v[0];
    es__free(ctx, v);
    if (rc == ES_OK && w) rc = stored_weights(ctx, store, name, lengths, w);
    return rc;
}

es_status es_study_point_weights(es_ctx *ctx, es_store *store, const char *spec,
                                 const char *pca_name, double *lengths, double *scale,
                                 double *w)
{
    return es__study_point_weights_via(ctx, store, spec, pca_name, NULL, NULL, NULL, lengths,
                                       scale, w);
}

/* An expression's lengths with its leaves from `resolve` (es_study_resolve
 * behind a cache, say) on the store's topology `mesh`. */
static es_status resolved_point(es_ctx *ctx, es_store *store, const char *spec,
                                es_point_resolve_fn resolve, void *ud, const es_mesh *mesh,
                                double *lengths, double *scale, double *w)
{
    es_point_expr *x = NULL;
    es_point_info info;
    es_status rc;
    if ((rc = es_point_parse(ctx, spec, &x)) != ES_OK) return rc;
    rc = es_point_eval_rows(ctx, x, es_store_nedges(store), w ? es_store_nrows(store) : 0,
                            resolve, ud, mesh, lengths, w, &info);
    es_point_expr_free(x);
    if (rc == ES_OK && isfinite(info.scale) && info.scale > 0) *scale = info.scale;
    return rc;
}

es_status es__study_point_weights_via(es_ctx *ctx, es_store *store, const char *spec,
                                      const char *pca_name, es_point_resolve_fn resolve,
                                      void *ud, const es_mesh *mesh, double *lengths,
                                      double *scale, double *w)
{
    char path[512];
    int64_t ne = es_store_nedges(store);
    es_status rc;
    *scale = 0;
    if (!spec || !*spec) ES_FAIL(ctx, ES_EINVAL, "no point given");
    if (w) memset(w, 0, (size_t)es_store_nrows(store) * sizeof *w);
    snprintf(path, sizeof path, "point/%s/lengths", spec);
    if (!strncmp(spec, "row:", 4)) {
        rc = row_point(ctx, store, spec + 4, lengths, scale, w);
    } else if (es_store_has(store, path)) {
        rc = stored_point(ctx, store, spec, lengths, scale, w);
    } else if (resolve) {
        rc = resolved_point(ctx, store, spec, resolve, ud, mesh, lengths, scale, w);
    } else {   /* an expression (es_point.h syntax) */
        es_point_info info;
        double *v = NULL;
        es_study_point_opts po;
        es_study_point_opts_init(&po);
        po.expr = spec;
        po.pca_name = pca_name;
        po.command = "edgespace";
        if ((rc = es_study_point(ctx, store, &po, &v, w, &info)) == ES_OK) {
            memcpy(lengths, v, (size_t)ne * sizeof *lengths);
            if (isfinite(info.scale) && info.scale > 0) *scale = info.scale;
        }
        es_free(ctx, v);
    }
    if (rc == ES_OK && *scale == 0) rc = mean_row_scale(ctx, store, scale);
    if (rc != ES_OK) return rc;
    /* beyond the positive orthant (extrapolation) no mesh realizes the point */
    for (int64_t e = 0; e < ne; e++)
        if (!(lengths[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "the point has length %g at edge %lld: it is outside "
                    "edge-length space (not realizable)", lengths[e], (long long)e);
    return ES_OK;
}
