/* lib/study/analysis.c — statistics and points on a shape store: the glue between
 * es_stats.h / es_point.h (which know nothing of storage) and es_store.h.
 *
 * Each es_study_* call selects rows with the store's label filter,
 * streams their lengths through an es_source, computes, and writes one
 * result group /analysis/<kind>/<name> with provenance (layouts in
 * es_study.h). Commands (tools/cmd/mean.c, ...) and notebooks call these,
 * so a result made from C is the same as one made from the command line.
 */
#include "study/study_pkg.h"
#include "edgespace/es_study.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_io.h"
#include "edgespace/es_procrustes.h"
#include "core/core_private.h"
#include "store/store_private.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PATH_MAX_LEN 512

/* ---- sources and files ------------------------------------------------------ */

static es_status store_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n,
                            es_mat out)
{
    es_store *store = src->userdata;
    if (src->rows) return es_store_read_lengths_rows(ctx, store, src->rows + row0, n, out);
    return es_store_read_lengths(ctx, store, row0, n, out);
}

es_status es_study_source(es_ctx *ctx, es_store *store, const int64_t *rows, int64_t nrows,
                          es_source *out)
{
    memset(out, 0, sizeof *out);
    if (!store) ES_FAIL(ctx, ES_EINVAL, "source: no store");
    if (rows && nrows < 0) ES_FAIL(ctx, ES_EINVAL, "source: %lld rows", (long long)nrows);
    out->nedges = es_store_nedges(store);
    out->nrows = rows ? nrows : es_store_nrows(store);
    out->read = store_read;
    out->userdata = store;
    out->rows = rows;
    return ES_OK;
}

/* A bad name, or one taken (not replaced without ES_STORE_REPLACE), is
 * refused before anything is computed. */
#define CHECK_NAME(ctx, store, kind, name) do { \
        es_status rc_; \
        if ((name) && (rc_ = es_store_result_check(ctx, store, kind, name)) != ES_OK) \
            return rc_; \
    } while (0)

/* Length statistics need edges: a landmarks-only store has none. */
#define NEED_EDGES(ctx, store) do { if (es_store_nedges(store) < 1) \
    ES_FAIL(ctx, ES_EINVAL, "analysis: store '%s' has no edges: it holds landmarks only; " \
            "give --edges or --triangles at ingest", es_store_path(store)); \
    } while (0)

/* ---- means -------------------------------------------------------------------- */

void es_study_group_result_free(es_group_result *r)
{
    if (!r) return;
    es_ctx *ctx = r->ctx;
    for (int64_t g = 0; r->names && g < r->ngroups; g++) es__free(ctx, r->names[g]);
    es__free(ctx, r->names);
    es__free(ctx, r->means);
    es__free(ctx, r->counts);
    es__free(ctx, r->scales);
    es__free(ctx, r->centroid_sizes);
    es__free(ctx, r);
}

/* Mean centroid size per group: of each row's positions as ingested (the
 * square root of the summed squared distances of the vertices from their
 * centroid, R's shapes::centroid.size), the size a geomorph or shapes user
 * reads beside the scale (the sum of edge lengths). */
static es_status group_centroid_sizes(es_ctx *ctx, es_store *store, const int64_t *rows,
                                      int64_t nrows, const int64_t *group, es_group_result *r)
{
    const int64_t V = es_store_nverts(store);
    double *xyz = es__alloc_array(ctx, 6 * (V > 0 ? V : 1), sizeof *xyz), *cfg = xyz + 3 * V;
    r->centroid_sizes = es__calloc(ctx, (size_t)r->ngroups, sizeof *r->centroid_sizes);
    if (!xyz || !r->centroid_sizes) {
        es__free(ctx, xyz);
        return ES_ENOMEM;
    }
    es_status rc = ES_OK;
    for (int64_t i = 0; i < nrows && rc == ES_OK; i++) {
        if ((rc = es_store_read_positions(ctx, store, rows[i], xyz)) != ES_OK) break;
        es_procrustes_from_xyz(V, xyz, cfg);
        r->centroid_sizes[group[i]] += es_procrustes_centroid_size(V, 3, cfg);
    }
    for (int64_t g = 0; g < r->ngroups; g++) r->centroid_sizes[g] /= (double)r->counts[g];
    es__free(ctx, xyz);
    return rc;
}

void es_study_mean_opts_init(es_study_mean_opts *o) { memset(o, 0, sizeof *o); }

es_status es_study_mean(es_ctx *ctx, es_store *store, const es_study_mean_opts *opts,
                        es_group_result **out)
{
    es_study_mean_opts o;
    if (opts) o = *opts;
    else es_study_mean_opts_init(&o);
    const char *name = o.name, *filter = o.where, *by = o.by, *command = o.command;
    es_status rc;
    int64_t *rows = NULL, nrows = 0, *group = NULL, ng = 0;
    const char **labels = NULL, **gnames = NULL;
    double *scales = NULL;
    es_group_result *r = NULL;
    if (out) *out = NULL;
    CHECK_NAME(ctx, store, "mean", name);
    NEED_EDGES(ctx, store);
    const int64_t E = es_store_nedges(store), col = by ? es_store_find_column(store, by) : -1;
    if (by && col < 0) {
        char hint[400];
        es_store_column_hint(store, by, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "mean: no label column '%s'%s", by, hint);
    }
    if ((rc = es_store_select(ctx, store, filter, &rows, &nrows)) != ES_OK) return rc;
    if (nrows == 0) {
        rc = es__fail(ctx, ES_EINVAL, "mean: no rows match '%s'", filter ? filter : "");
        goto done;
    }
    labels = es__alloc_array(ctx, nrows, sizeof *labels);
    scales = es__alloc_array(ctx, es_store_nrows(store), sizeof *scales);
    if (!labels || !scales) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < nrows; i++) labels[i] = by ? es_store_label(store, rows[i], col) : "all";
    if ((rc = es_groups_from_labels(ctx, labels, nrows, &group, &gnames, &ng)) != ES_OK ||
        (rc = es_store_read_scales(ctx, store, scales)) != ES_OK)
        goto done;
    r = es__calloc(ctx, 1, sizeof *r);
    if (!r) {
        rc = ES_ENOMEM;
        goto done;
    }
    r->ctx = ctx;
    r->nedges = E;
    r->ngroups = ng;
    r->names = es__calloc(ctx, (size_t)ng, sizeof *r->names);
    r->means = es__alloc_array(ctx, E * ng, sizeof *r->means);
    r->counts = es__alloc_array(ctx, ng, sizeof *r->counts);
    r->scales = es__calloc(ctx, (size_t)ng, sizeof *r->scales);
    if (!r->names || !r->means || !r->counts || !r->scales) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t g = 0; g < ng; g++)
        if (!(r->names[g] = es__strdup(ctx, gnames[g]))) {
            rc = ES_ENOMEM;
            goto done;
        }
    es_source src;
    if ((rc = es_study_source(ctx, store, rows, nrows, &src)) != ES_OK ||
        (rc = es_group_means(ctx, &src, group, ng, r->means, r->counts)) != ES_OK)
        goto done;
    for (int64_t i = 0; i < nrows; i++) r->scales[group[i]] += scales[rows[i]];
    for (int64_t g = 0; g < ng; g++) r->scales[g] /= (double)r->counts[g];
    if ((rc = group_centroid_sizes(ctx, store, rows, nrows, group, r)) != ES_OK) goto done;
    if (name) {
        char p[PATH_MAX_LEN], params[256];
        snprintf(params, sizeof params, "filter=%s; by=%s", filter ? filter : "", by ? by : "");
        es_provenance prov = {command ? command : "es_study_mean", rows, nrows, params};
        if ((rc = es_store_result_begin(ctx, store, "mean", name, &prov)) != ES_OK) goto done;
        if ((rc = es__result_path(ctx, p, PATH_MAX_LEN, "mean", name, "means")) != ES_OK ||
            (rc = es_store_put_matrix(ctx, store, p, (es_mat){r->means, E, ng, E})) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "mean", name, "counts")) != ES_OK ||
            (rc = es_store_put_ints(ctx, store, p, r->counts, ng)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "mean", name, "scales")) != ES_OK ||
            (rc = es_store_put_vector(ctx, store, p, r->scales, ng)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "mean", name, "centroid_sizes")) != ES_OK ||
            (rc = es_store_put_vector(ctx, store, p, r->centroid_sizes, ng)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "mean", name, "groups")) != ES_OK ||
            (rc = es_store_put_strings(ctx, store, p, (const char *const *)r->names, ng)) != ES_OK)
            goto done;
        snprintf(p, sizeof p, "mean/%s", name);
        if ((rc = es_store_put_attr(ctx, store, p, "filter", filter ? filter : "")) != ES_OK ||
            (rc = es_store_put_attr(ctx, store, p, "by", by ? by : "")) != ES_OK)
            goto done;
    }
    if (out) {
        *out = r;
        r = NULL;
    }
done:
    es_study_group_result_free(r);
    es__free(ctx, rows);
    es__free(ctx, (void *)labels);
    es__free(ctx, group);
    es__free(ctx, (void *)gnames);
    es__free(ctx, scales);
    return rc;
}

/* ---- PCA ------------------------------------------------------------------------ */

static const char *method_name(es_pca_method m)
{
    switch (m) {
    case ES_PCA_GRAM: return "gram";
    case ES_PCA_COVARIANCE: return "covariance";
    case ES_PCA_RANDOMIZED: return "randomized";
    case ES_PCA_AUTO: break;
    }
    return "auto";
}

static es_status save_pca(es_ctx *ctx, es_store *store, const char *name, const es_pca *p,
                          const int64_t *rows, const char *filter, const char *command)
{
    char path[PATH_MAX_LEN], params[512];
    const int64_t E = p->nedges, N = p->nrows, K = p->ncomp;
    snprintf(params, sizeof params, "filter=%s; ncomp=%lld; method=%s", filter ? filter : "",
             (long long)K, method_name(p->method));
    es_provenance prov = {command ? command : "es_study_pca", rows, N, params};
    es_status rc = es_store_result_begin(ctx, store, "pca", name, &prov);
    if (rc != ES_OK) return rc;
    /* scores as N x K on disk: row i = shape i, so the es_mat is K x N */
    double *st = es__alloc_array(ctx, N * (K > 0 ? K : 1), sizeof *st);
    if (!st) return ES_ENOMEM;
    for (int64_t i = 0; i < N; i++)
        for (int64_t k = 0; k < K; k++) st[k + i * K] = p->scores[i + k * N];
    if ((rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", name, "mean")) != ES_OK ||
        (rc = es_store_put_vector(ctx, store, path, p->mean, E)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", name, "components")) != ES_OK ||
        (rc = es_store_put_matrix(ctx, store, path, (es_mat){p->components, E, K, E})) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", name, "eigenvalues")) != ES_OK ||
        (rc = es_store_put_vector(ctx, store, path, p->eigenvalues, K)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", name, "explained")) != ES_OK ||
        (rc = es_store_put_vector(ctx, store, path, p->explained, K)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", name, "total_variance")) != ES_OK ||
        (rc = es_store_put_vector(ctx, store, path, &p->total_variance, 1)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", name, "scores")) != ES_OK ||
        (rc = es_store_put_matrix(ctx, store, path, (es_mat){st, K, N, K > 0 ? K : 1})) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", name, "rows")) != ES_OK ||
        (rc = es_store_put_ints(ctx, store, path, rows, N)) != ES_OK)
        goto done;
    snprintf(path, sizeof path, "pca/%s", name);
    if ((rc = es_store_put_attr(ctx, store, path, "method", method_name(p->method))) != ES_OK ||
        (rc = es_store_put_attr(ctx, store, path, "filter", filter ? filter : "")) != ES_OK ||
        (rc = es_store_put_attr_int(ctx, store, path, "ncomp", K)) != ES_OK)
        goto done;
done:
    es__free(ctx, st);
    return rc;
}

void es_study_pca_opts_init(es_study_pca_opts *o)
{
    memset(o, 0, sizeof *o);
    es_pca_opts_init(&o->pca);
}

es_status es_study_pca(es_ctx *ctx, es_store *store, const es_study_pca_opts *opts,
                       es_pca **out, int64_t **rows_out, int64_t *nrows_out)
{
    es_study_pca_opts o;
    if (opts) o = *opts;
    else es_study_pca_opts_init(&o);
    const char *name = o.name, *filter = o.where;
    int64_t *rows = NULL, nrows = 0;
    es_pca *p = NULL;
    es_source src;
    if (out) *out = NULL;
    if (rows_out) *rows_out = NULL;
    CHECK_NAME(ctx, store, "pca", name);
    NEED_EDGES(ctx, store);
    es_status rc = es_store_select(ctx, store, filter, &rows, &nrows);
    if (rc != ES_OK) return rc;
    if ((rc = es_study_source(ctx, store, rows, nrows, &src)) != ES_OK ||
        (rc = es_pca_fit(ctx, &src, &o.pca, &p)) != ES_OK)
        goto done;
    if (name && (rc = save_pca(ctx, store, name, p, rows, filter, o.command)) != ES_OK) goto done;
    if (out) {
        *out = p;
        p = NULL;
    }
    if (rows_out) {
        *rows_out = rows;
        rows = NULL;
    }
    if (nrows_out) *nrows_out = nrows;
done:
    es_pca_free(p);
    es__free(ctx, rows);
    return rc;
}

/* The PCA name to use: given, the only one, or "default". Writes into buf. */
static es_status pick_pca(es_ctx *ctx, es_store *store, const char *name, char *buf, size_t n)
{
    if (name) {
        snprintf(buf, n, "%s", name);
        return ES_OK;
    }
    char **names = NULL;
    int64_t count = 0;
    es_status rc = es_store_list_results(ctx, store, "pca", &names, &count);
    if (rc != ES_OK) return rc;
    int found = 0;
    if (count == 1) {
        snprintf(buf, n, "%s", names[0]);
        found = 1;
    }
    for (int64_t i = 0; i < count; i++) {
        if (!found && !strcmp(names[i], "default")) {
            snprintf(buf, n, "default");
            found = 1;
        }
        es_free(ctx, names[i]);
    }
    es_free(ctx, names);
    if (!found)
        ES_FAIL(ctx, ES_ENOTFOUND, "pca: %s; name one (--pca NAME)",
                count ? "several PCAs are stored and none is named 'default'"
                      : "the store holds no PCA (run edgespace pca first)");
    return ES_OK;
}

es_status es_study_pca_load(es_ctx *ctx, es_store *store, const char *name, es_pca **out,
                               int64_t **rows_out, int64_t *nrows_out)
{
    char nm[256], path[PATH_MAX_LEN];
    double *mean = NULL, *eig = NULL, *tv = NULL;
    int64_t E = 0, K = 0, ntv = 0, *rows = NULL, nrows = 0;
    es_mat comps = {0}, scores = {0};
    es_pca *p = NULL;
    *out = NULL;
    if (rows_out) *rows_out = NULL;
    es_status rc = pick_pca(ctx, store, name, nm, sizeof nm);
    if (rc != ES_OK) return rc;
    snprintf(path, sizeof path, "pca/%s", nm);
    if (!es_store_has(store, path)) {
        char hint[400];
        es_store_result_hint(ctx, store, "pca", nm, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "pca: no PCA named '%s'%s", nm, hint);
    }
    if ((rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", nm, "mean")) != ES_OK ||
        (rc = es_store_get_vector(ctx, store, path, &mean, &E)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", nm, "eigenvalues")) != ES_OK ||
        (rc = es_store_get_vector(ctx, store, path, &eig, &K)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", nm, "total_variance")) != ES_OK ||
        (rc = es_store_get_vector(ctx, store, path, &tv, &ntv)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", nm, "components")) != ES_OK ||
        (rc = es_store_get_matrix(ctx, store, path, &comps)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", nm, "scores")) != ES_OK ||
        (rc = es_store_get_matrix(ctx, store, path, &scores)) != ES_OK ||
        (rc = es__result_path(ctx, path, PATH_MAX_LEN, "pca", nm, "rows")) != ES_OK ||
        (rc = es_store_get_ints(ctx, store, path, &rows, &nrows)) != ES_OK)
        goto done;
    if (comps.rows != E || comps.cols != K || ntv != 1 || scores.rows != K ||
        scores.cols != nrows || E != es_store_nedges(store)) {
        rc = es__fail(ctx, ES_EFORMAT, "pca: '%s' is inconsistent (mean %lld, components "
                      "%lld x %lld, %lld eigenvalues, scores %lld x %lld, %lld rows)", nm,
                      (long long)E, (long long)comps.rows, (long long)comps.cols, (long long)K,
                      (long long)scores.rows, (long long)scores.cols, (long long)nrows);
        goto done;
    }
    if ((rc = es_pca_from_arrays(ctx, E, K, mean, comps.data, eig, tv[0], &p)) != ES_OK) goto done;
    es__free(ctx, p->scores);
    p->scores = es__alloc_array(ctx, nrows * (K > 0 ? K : 1), sizeof *p->scores);
    if (!p->scores) {
        rc = ES_ENOMEM;
        goto done;
    }
    p->nrows = nrows;
    for (int64_t i = 0; i < nrows; i++)
        for (int64_t k = 0; k < K; k++) p->scores[i + k * nrows] = ES_AT(scores, k, i);
    *out = p;
    p = NULL;
    if (rows_out) {
        *rows_out = rows;
        rows = NULL;
    }
    if (nrows_out) *nrows_out = nrows;
done:
    es_pca_free(p);
    es_free(ctx, mean);
    es_free(ctx, eig);
    es_free(ctx, tv);
    es_free(ctx, comps.data);
    es_free(ctx, scores.data);
    es_free(ctx, rows);
    return rc;
}

/* ---- differences ------------------------------------------------------------------ */

void es_study_diff_opts_init(es_study_diff_opts *o) { memset(o, 0, sizeof *o); }

es_status es_study_diff(es_ctx *ctx, es_store *store, const es_study_diff_opts *opts,
                        es_diff **out)
{
    if (out) *out = NULL;
    if (!opts) ES_FAIL(ctx, ES_EINVAL, "diff: a key column, a role column, 'from' and 'to' are needed");
    const char *name = opts->name, *filter = opts->where, *key = opts->key,
               *column = opts->column, *from = opts->from, *to = opts->to,
               *command = opts->command;
    CHECK_NAME(ctx, store, "diff", name);
    NEED_EDGES(ctx, store);
    if (!key || !column || !from || !to)
        ES_FAIL(ctx, ES_EINVAL, "diff: a key column, a role column, 'from' and 'to' are needed");
    if (!strcmp(from, to)) ES_FAIL(ctx, ES_EINVAL, "diff: 'from' and 'to' are both '%s'", from);
    const int64_t kc = es_store_find_column(store, key), rcol = es_store_find_column(store, column);
    char hint[400];
    if (kc < 0 || rcol < 0) {
        es_store_column_hint(store, kc < 0 ? key : column, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "diff: no label column '%s'%s", kc < 0 ? key : column, hint);
    }
    const int64_t N = es_store_nrows(store);
    int64_t *sel = NULL, nsel = 0;
    es_diff *d = NULL;
    es_status rc = es_store_select(ctx, store, filter, &sel, &nsel);
    if (rc != ES_OK) return rc;
    const char **keys = es__alloc_array(ctx, N > 0 ? N : 1, sizeof *keys);
    const char **ids = es__alloc_array(ctx, N > 0 ? N : 1, sizeof *ids);
    int *role = es__alloc_array(ctx, N > 0 ? N : 1, sizeof *role);
    if (!keys || !ids || !role) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < N; i++) {
        keys[i] = es_store_label(store, i, kc);
        ids[i] = es_store_row_id(store, i);
        role[i] = ES_DIFF_NONE;
    }
    int64_t nfrom = 0, nto = 0;
    for (int64_t j = 0; j < nsel; j++) {
        const char *v = es_store_label(store, sel[j], rcol);
        if (v && !strcmp(v, from)) role[sel[j]] = ES_DIFF_FROM, nfrom++;
        else if (v && !strcmp(v, to)) role[sel[j]] = ES_DIFF_TO, nto++;
    }
    if (!nfrom || !nto) {
        es_store_value_hint(store, rcol, !nfrom ? from : to, hint, sizeof hint);
        rc = es__fail(ctx, ES_ENOTFOUND, "diff: no rows with %s=%s%s", column,
                      !nfrom ? from : to, hint);
        goto done;
    }
    es_source src;
    if ((rc = es_study_source(ctx, store, NULL, 0, &src)) != ES_OK ||
        (rc = es_diff_paired(ctx, &src, keys, role, ids, &d)) != ES_OK)
        goto done;
    if (name) {
        char p[PATH_MAX_LEN], params[512];
        const int64_t E = d->nedges;
        snprintf(params, sizeof params, "filter=%s; key=%s; column=%s; from=%s; to=%s",
                 filter ? filter : "", key, column, from, to);
        int64_t *used = es__alloc_array(ctx, 2 * d->npairs, sizeof *used);
        if (!used) {
            rc = ES_ENOMEM;
            goto done;
        }
        memcpy(used, d->pair_from, (size_t)d->npairs * sizeof *used);
        memcpy(used + d->npairs, d->pair_to, (size_t)d->npairs * sizeof *used);
        es_provenance prov = {command ? command : "es_study_diff", used, 2 * d->npairs, params};
        rc = es_store_result_begin(ctx, store, "diff", name, &prov);
        es__free(ctx, used);
        if (rc != ES_OK) goto done;
        static const char *const vn[4] = {"mean", "sd", "se", "t"};
        const double *vv[4] = {d->mean, d->sd, d->se, d->t};
        for (int i = 0; i < 4; i++)
            if ((rc = es__result_path(ctx, p, PATH_MAX_LEN, "diff", name, vn[i])) != ES_OK ||
                (rc = es_store_put_vector(ctx, store, p, vv[i], E)) != ES_OK)
                goto done;
        if ((rc = es__result_path(ctx, p, PATH_MAX_LEN, "diff", name, "pair_from")) != ES_OK ||
            (rc = es_store_put_ints(ctx, store, p, d->pair_from, d->npairs)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "diff", name, "pair_to")) != ES_OK ||
            (rc = es_store_put_ints(ctx, store, p, d->pair_to, d->npairs)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "diff", name, "unpaired")) != ES_OK ||
            (rc = es_store_put_ints(ctx, store, p, d->unpaired, d->nunpaired)) != ES_OK)
            goto done;
        snprintf(p, sizeof p, "diff/%s", name);
        if ((rc = es_store_put_attr(ctx, store, p, "key", key)) != ES_OK ||
            (rc = es_store_put_attr(ctx, store, p, "column", column)) != ES_OK ||
            (rc = es_store_put_attr(ctx, store, p, "from", from)) != ES_OK ||
            (rc = es_store_put_attr(ctx, store, p, "to", to)) != ES_OK)
            goto done;
    }
    if (out) {
        *out = d;
        d = NULL;
    }
done:
    es_diff_free(d);
    es__free(ctx, sel);
    es__free(ctx, (void *)keys);
    es__free(ctx, (void *)ids);
    es__free(ctx, role);
    return rc;
}

/* ---- points ------------------------------------------------------------------------- */

void es_study_resolver_clear(es_ctx *ctx, es_study_resolver *r)
{
    if (!r) return;
    es_pca_free(r->pca);
    es_pca_free(r->all_rows);
    es__free(ctx, r->scales);
    es__free(ctx, r->pca_rows);
    r->pca = r->all_rows = NULL;
    r->scales = NULL;
    r->pca_rows = NULL;
}

static es_status load_scales(es_ctx *ctx, es_study_resolver *r)
{
    if (r->scales) return ES_OK;
    r->scales = es__alloc_array(ctx, es_store_nrows(r->store) > 0 ? es_store_nrows(r->store) : 1,
                                sizeof *r->scales);
    if (!r->scales) return ES_ENOMEM;
    es_status rc = es_store_read_scales(ctx, r->store, r->scales);
    if (rc != ES_OK) {
        es__free(ctx, r->scales);
        r->scales = NULL;
    }
    return rc;
}

/* Row weights of a mesh file: ridge regression on every row (es_pca_row_weights
 * on a PCA of all rows, fitted once per resolver). */
static es_status file_weights(es_ctx *ctx, es_study_resolver *r, const double *len, double *w)
{
    es_status rc;
    if (!r->all_rows) {
        es_source src;
        es_pca_opts o;
        es_pca_opts_init(&o);
        if ((rc = es_study_source(ctx, r->store, NULL, 0, &src)) != ES_OK ||
            (rc = es_pca_fit(ctx, &src, &o, &r->all_rows)) != ES_OK)
            return rc;
    }
    return es_pca_row_weights(ctx, r->all_rows, len, ES_RIDGE_REL, w);
}

/* Component `index` of the resolver's PCA (pc:K) or of the one named inline
 * (pc:NAME:K, arg NAME): the resolver's is loaded once and kept, another
 * one is loaded for this leaf alone (an expression rarely mixes PCAs). */
static es_status resolve_pc(es_ctx *ctx, es_study_resolver *r, const char *arg, int64_t index,
                            double *vec, double *scale, double *w)
{
    if (arg && *arg && !(r->pca_name && !strcmp(arg, r->pca_name))) {
        es_study_resolver other = {r->store, NULL, arg, NULL, NULL, NULL, NULL};
        es_status rc = resolve_pc(ctx, &other, NULL, index, vec, scale, w);
        es_study_resolver_clear(ctx, &other);
        return rc;
    }
    const int64_t E = es_store_nedges(r->store);
    es_status rc;
    int64_t n;
    if (!r->pca &&
        (rc = es_study_pca_load(ctx, r->store, r->pca_name, &r->pca, &r->pca_rows, &n)) != ES_OK)
        return rc;
    const es_pca *p = r->pca;
    if (index < 1 || index > p->ncomp)
        ES_FAIL(ctx, ES_ENOTFOUND, "the PCA has %lld components", (long long)p->ncomp);
    memcpy(vec, p->components + (index - 1) * E, (size_t)E * sizeof *vec);
    *scale = sqrt(p->eigenvalues[index - 1]);
    /* u_k = X_c v_k / s_k = sum_i z_ik x_i / ((N - 1) lambda_k): the scores
     * sum to 0, so the weights do too (a direction) */
    if (w && p->nrows > 1 && p->eigenvalues[index - 1] > 0)
        for (int64_t i = 0; i < p->nrows; i++)
            w[r->pca_rows[i]] += p->scores[i + (index - 1) * p->nrows] /
                                 ((double)(p->nrows - 1) * p->eigenvalues[index - 1]);
    return ES_OK;
}

static es_status resolve_diff(es_ctx *ctx, es_study_resolver *r, const char *arg, double *vec,
                              double *w)
{
    const int64_t E = es_store_nedges(r->store);
    char p[PATH_MAX_LEN];
    double *v = NULL;
    int64_t n = 0, *from = NULL, *to = NULL, nf = 0, nt = 0;
    es_status rc;
    if ((rc = es__result_name_check(ctx, NULL, arg)) != ES_OK) return rc;
    if ((rc = es__result_path(ctx, p, PATH_MAX_LEN, "diff", arg, "mean")) != ES_OK) return rc;
    if (!es_store_has(r->store, p)) {
        char hint[400];
        es_store_result_hint(ctx, r->store, "diff", arg, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "no difference named '%s'%s", arg, hint);
    }
    if ((rc = es_store_get_vector(ctx, r->store, p, &v, &n)) != ES_OK) return rc;
    if (n != E) {
        es_free(ctx, v);
        ES_FAIL(ctx, ES_EFORMAT, "difference '%s' has %lld values, the store %lld edges", arg,
                (long long)n, (long long)E);
    }
    memcpy(vec, v, (size_t)E * sizeof *vec);
    es_free(ctx, v);
    if (!w) return ES_OK;
    /* the mean over pairs of (to - from) */
    if ((rc = es__result_path(ctx, p, PATH_MAX_LEN, "diff", arg, "pair_from")) == ES_OK &&
        (rc = es_store_get_ints(ctx, r->store, p, &from, &nf)) == ES_OK &&
        (rc = es__result_path(ctx, p, PATH_MAX_LEN, "diff", arg, "pair_to")) == ES_OK &&
        (rc = es_store_get_ints(ctx, r->store, p, &to, &nt)) == ES_OK) {
        const int64_t N = es_store_nrows(r->store);
        if (nf != nt || nf < 1) rc = es__fail(ctx, ES_EFORMAT, "difference '%s' has %lld "
                                              "'from' and %lld 'to' rows", arg, (long long)nf,
                                              (long long)nt);
        for (int64_t k = 0; rc == ES_OK && k < nf; k++) {
            if (from[k] < 0 || from[k] >= N || to[k] < 0 || to[k] >= N) {
                rc = es__fail(ctx, ES_EFORMAT, "difference '%s' names a row outside the "
                              "store", arg);
                break;
            }
            w[to[k]] += 1.0 / (double)nf;
            w[from[k]] -= 1.0 / (double)nf;
        }
    }
    es_free(ctx, from);
    es_free(ctx, to);
    return rc;
}

es_status es_study_resolve(es_ctx *ctx, void *ud, es_point_leaf kind, const char *arg,
                           int64_t index, double *vec, double *scale, double *w)
{
    es_study_resolver *r = ud;
    es_store *st = r->store;
    const int64_t E = es_store_nedges(st);
    es_status rc;
    switch (kind) {
    case ES_POINT_MEAN: {
        int64_t *rows = NULL, n = 0;
        if ((rc = es_store_select(ctx, st, arg, &rows, &n)) != ES_OK) return rc;
        es_source src;
        if (n == 0) rc = es__fail(ctx, ES_ENOTFOUND, "no rows match '%s'", arg);
        else if ((rc = load_scales(ctx, r)) == ES_OK &&
                 (rc = es_study_source(ctx, st, rows, n, &src)) == ES_OK &&
                 (rc = es_mean(ctx, &src, vec)) == ES_OK) {
            double s = 0;
            for (int64_t i = 0; i < n; i++) s += r->scales[rows[i]];
            *scale = s / (double)n;
            for (int64_t i = 0; w && i < n; i++) w[rows[i]] += 1.0 / (double)n;
        }
        es__free(ctx, rows);
        return rc;
    }
    case ES_POINT_ROW: {
        int64_t row = es_store_find_row(st, arg);
        if (row < 0) {
            char hint[400];
            es_store_value_hint(st, -1, arg, hint, sizeof hint);
            ES_FAIL(ctx, ES_ENOTFOUND, "no row with id '%s'%s", arg, hint);
        }
        if ((rc = load_scales(ctx, r)) != ES_OK ||
            (rc = es_store_read_lengths(ctx, st, row, 1, (es_mat){vec, E, 1, E})) != ES_OK)
            return rc;
        *scale = r->scales[row];
        if (w) w[row] += 1;
        return ES_OK;
    }
    case ES_POINT_FILE:
        if (!r->mesh)
            ES_FAIL(ctx, ES_EINVAL, "store '%s' has no faces (a %s store), so mesh files "
                    "cannot be matched to it", es_store_path(r->store),
                    es_topology_kind_name(es_store_topology_kind(r->store)));
        if ((rc = es_meshio_lengths_from_file(ctx, r->mesh, arg, vec, scale)) != ES_OK) return rc;
        return w ? file_weights(ctx, r, vec, w) : ES_OK;
    case ES_POINT_PC:
        return resolve_pc(ctx, r, arg, index, vec, scale, w);
    case ES_POINT_DIFF:
        return resolve_diff(ctx, r, arg, vec, w);
    case ES_POINT_COEF: {
        /* "MODEL/COEF": a model name holds no '/' */
        const char *slash = strchr(arg, '/');
        char model[256];
        if (!slash || (size_t)(slash - arg) >= sizeof model)
            ES_FAIL(ctx, ES_EINVAL, "bad coefficient '%s'", arg);
        memcpy(model, arg, (size_t)(slash - arg));
        model[slash - arg] = '\0';
        *scale = NAN;
        return es_study_model_coef(ctx, st, model, slash + 1, vec, w);
    }
    }
    ES_FAIL(ctx, ES_EINVAL, "unknown leaf kind %d", (int)kind);
}

void es_study_point_opts_init(es_study_point_opts *o) { memset(o, 0, sizeof *o); }

es_status es_study_point(es_ctx *ctx, es_store *store, const es_study_point_opts *opts,
                         double **vec, double *weights, es_point_info *info)
{
    es_point_expr *x = NULL;
    es_mesh *mesh = NULL;
    es_point_info in;
    if (vec) *vec = NULL;
    if (!opts || !opts->expr) ES_FAIL(ctx, ES_EINVAL, "point: no expression");
    const char *name = opts->name, *expr = opts->expr, *command = opts->command;
    const double scale = opts->scale;
    es_study_resolver r = {store, NULL, opts->pca_name, NULL, NULL, NULL, NULL};
    CHECK_NAME(ctx, store, "point", name);
    NEED_EDGES(ctx, store);
    const int64_t E = es_store_nedges(store), N = es_store_nrows(store);
    /* the row weights are stored with a named point */
    const int want_w = weights || name;
    double *v = es__alloc_array(ctx, E + (want_w ? N : 0), sizeof *v);
    double *w = want_w ? v + E : NULL;
    if (!v) return ES_ENOMEM;
    es_status rc;
    if ((rc = es_point_parse(ctx, expr, &x)) != ES_OK ||
        (es_store_nfaces(store) > 0 && (rc = es_store_mesh(ctx, store, &mesh)) != ES_OK))
        goto done;
    /* A truss store has no faces: the point is not checked (in.checked = 0,
     * recorded as valid = "unchecked"). A store without edges fails in
     * es_point_eval's reads with the store's message. */
    r.mesh = mesh;
    if ((rc = es_point_eval_rows(ctx, x, E, w ? N : 0, es_study_resolve, &r, mesh, v, w,
                                 &in)) != ES_OK)
        goto done;
    if (scale > 0) in.scale = scale;
    if (name) {
        char p[PATH_MAX_LEN];
        es_provenance prov = {command ? command : "es_study_point", NULL, -1, expr};
        if ((rc = es_store_result_begin(ctx, store, "point", name, &prov)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "point", name, "lengths")) != ES_OK ||
            (rc = es_store_put_vector(ctx, store, p, v, E)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "point", name, "scale")) != ES_OK ||
            (rc = es_store_put_vector(ctx, store, p, &in.scale, 1)) != ES_OK ||
            (rc = es__result_path(ctx, p, PATH_MAX_LEN, "point", name, "row_weights")) != ES_OK ||
            (rc = es_store_put_vector(ctx, store, p, w, N)) != ES_OK)
            goto done;
        snprintf(p, sizeof p, "point/%s", name);
        /* valid is 1 or 0, or the text "unchecked (no faces)" on a truss */
        if ((rc = es_store_put_attr(ctx, store, p, "expression", expr)) != ES_OK ||
            (rc = es_store_put_attr_double(ctx, store, p, "weight", in.weight)) != ES_OK ||
            (rc = in.checked ? es_store_put_attr_int(ctx, store, p, "valid", in.validity.valid)
                             : es_store_put_attr(ctx, store, p, "valid",
                                                 "unchecked (no faces)")) != ES_OK ||
            (rc = es_store_put_attr_int(ctx, store, p, "n_bad_faces",
                                        in.validity.n_bad_faces)) != ES_OK ||
            (rc = es_store_put_attr_int(ctx, store, p, "n_nonpositive",
                                        in.validity.n_nonpositive)) != ES_OK ||
            (rc = es_store_put_attr_double(ctx, store, p, "worst_violation",
                                           in.validity.worst_violation)) != ES_OK ||
            (rc = es_store_put_attr_int(ctx, store, p, "worst_face",
                                        in.validity.worst_face)) != ES_OK)
            goto done;
    }
    if (info) *info = in;
    if (weights) memcpy(weights, w, (size_t)N * sizeof *weights);
    if (vec) {
        /* the caller owns the lengths: a block of its own, not the weights' */
        double *out = es__alloc_array(ctx, E, sizeof *out);
        if (!out) {
            rc = ES_ENOMEM;
            goto done;
        }
        memcpy(out, v, (size_t)E * sizeof *out);
        *vec = out;
    }
done:
    es_study_resolver_clear(ctx, &r);
    es_point_expr_free(x);
    es_mesh_free(mesh);
    es__free(ctx, v);
    return rc;
}
