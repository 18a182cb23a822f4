/* lib/study/model_results.c — a model's result in the store
 * (/analysis/model/<name>, datasets-spec/analysis-results.md) and its
 * coefficients read back as points of edge-length space (coef:MODEL:COEF).
 * A coefficient is the combination sum_i w_i y_i of the rows with weights
 * w = X (X^T X)^-1 e_c, stored beside it, so that the embedding's prior gets
 * the same weights as every other point. */
#include "study/study_pkg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *type_name(es_ss_type t)
{
    return t == ES_SS_TYPE_III ? "III" : t == ES_SS_TYPE_II ? "II" : "I";
}

/* The transpose of a (rows x cols, ld rows) into a new buffer. */
static double *transpose(es_ctx *ctx, const double *a, int64_t rows, int64_t cols)
{
    double *t = es__alloc_array(ctx, rows * cols > 0 ? rows * cols : 1, sizeof *t);
    if (!t) return NULL;
    for (int64_t j = 0; j < cols; j++)
        for (int64_t i = 0; i < rows; i++) t[j + i * cols] = a[i + j * rows];
    return t;
}

es_status es__model_save(es_ctx *ctx, es_store *s, const es_study_model_opts *o,
                         const es_study_model_result *r)
{
    const es_model *m = r->model;
    const es_design *d = r->design;
    const int64_t T = m->nterms, n = m->n, p = m->p, q = m->ncoef, B = m->permutations;
    char params[1024], grp[300], path[700];
    es_status rc;
    double *ct = NULL, *lt = NULL;
    snprintf(params, sizeof params, "formula=%s; gpa=%s; where=%s; block=%s; ss=%s; "
             "permutation=%s; permutations=%lld; contrasts=%s; reference=%s; pairwise=%s; "
             "slopes=%s; at=%s; null=%s; edges=%s",
             o->formula, o->gpa ? o->gpa : "", o->where ? o->where : "", o->block ? o->block : "",
             type_name(m->ss_type), m->scheme == ES_PERM_RAW ? "raw" : "rrpp", (long long)B,
             d->contrasts == ES_CONTRASTS_SUM ? "sum" : "treatment",
             o->reference ? o->reference : "", o->pairwise ? o->pairwise : "",
             o->slopes ? o->slopes : "", o->at ? o->at : "",
             o->null_formula ? o->null_formula : "", o->edge_term ? o->edge_term : "");
    es_provenance prov = {o->command ? o->command : "es_study_model", r->rows, n, params};
    if ((rc = es_store_result_begin(ctx, s, "model", o->name, &prov)) != ES_OK) return rc;
    snprintf(grp, sizeof grp, "model/%s", o->name);
#define PUT(call) do { if ((rc = (call)) != ES_OK) goto done; } while (0)
#define P(ds) (snprintf(path, sizeof path, "%s/%s", grp, ds), path)
    int64_t *testable = es__alloc_array(ctx, T, sizeof *testable);
    if (!testable) return ES_ENOMEM;
    for (int64_t j = 0; j < T; j++) testable[j] = m->testable[j];
    rc = es_store_put_ints(ctx, s, P("testable"), testable, T);
    es__free(ctx, testable);
    if (rc != ES_OK) return rc;
    PUT(es_store_put_strings(ctx, s, P("terms"), (const char *const *)d->terms, T));
    PUT(es_store_put_ints(ctx, s, P("df"), m->df, T));
    PUT(es_store_put_vector(ctx, s, P("ss"), m->ss, T));
    PUT(es_store_put_vector(ctx, s, P("ms"), m->ms, T));
    PUT(es_store_put_vector(ctx, s, P("r2"), m->r2, T));
    PUT(es_store_put_vector(ctx, s, P("f"), m->f, T));
    PUT(es_store_put_vector(ctx, s, P("p"), m->pval, T));
    PUT(es_store_put_vector(ctx, s, P("z"), m->z, T));
    {
        const char **err = es__alloc_array(ctx, T > 0 ? T : 1, sizeof *err);
        if (!err) {
            rc = ES_ENOMEM;
            goto done;
        }
        for (int64_t j = 0; j < T; j++)
            err[j] = m->error[j] < 0 ? "Residual" : d->terms[m->error[j]];
        rc = es_store_put_strings(ctx, s, P("error_terms"), err, T);
        es__free(ctx, (void *)err);
        if (rc != ES_OK) goto done;
    }
    if (d->ndropped) {
        PUT(es_store_put_strings(ctx, s, P("dropped_terms"), (const char *const *)d->dropped,
                                 d->ndropped));
        PUT(es_store_put_strings(ctx, s, P("dropped_why"), (const char *const *)d->dropped_why,
                                 d->ndropped));
    }
    PUT(es_store_put_ints(ctx, s, P("rows"), r->rows, n));
    PUT(es_store_put_strings(ctx, s, P("coef_names"), (const char *const *)d->colnames, q));
    if (!(ct = transpose(ctx, m->coef, q, p))) {
        rc = ES_ENOMEM;
        goto done;
    }
    PUT(es_store_put_matrix(ctx, s, P("coefficients"), (es_mat){ct, p, q, p}));
    PUT(es_store_put_matrix(ctx, s, P("coef_weights"), (es_mat){m->coef_weights, n, q, n}));
    PUT(es_store_put_matrix(ctx, s, P("design"), (es_mat){d->x, n, q, n}));
    PUT(es_store_put_vector(ctx, s, P("mean"), m->mean, p));
    if (B > 0) PUT(es_store_put_matrix(ctx, s, P("f_perm"), (es_mat){m->fperm, B, T, B}));
    if (r->pairwise) {
        const es_model_pairwise *pw = r->pairwise;
        const int64_t L = pw->nlevels;
        if (!(lt = transpose(ctx, pw->lsmeans, L, p))) {
            rc = ES_ENOMEM;
            goto done;
        }
        PUT(es_store_put_strings(ctx, s, P("pairwise_levels"), (const char *const *)pw->levels, L));
        PUT(es_store_put_matrix(ctx, s, P("lsmeans"), (es_mat){lt, p, L, p}));
        PUT(es_store_put_matrix(ctx, s, P("lsmean_weights"), (es_mat){pw->weights, n, L, n}));
        PUT(es_store_put_matrix(ctx, s, P("pairwise_distances"), (es_mat){pw->dist, L, L, L}));
        PUT(es_store_put_matrix(ctx, s, P("pairwise_p"), (es_mat){pw->pval, L, L, L}));
        const double *extra[11] = {pw->z, pw->ucl, pw->vcor, pw->angle, pw->angle_ucl,
                                   pw->angle_z, pw->angle_p, pw->dlength, pw->dlength_ucl,
                                   pw->dlength_z, pw->dlength_p};
        static const char *const names[11] = {
            "pairwise_z", "pairwise_ucl", "pairwise_vcor", "pairwise_angle",
            "pairwise_angle_ucl", "pairwise_angle_z", "pairwise_angle_p", "pairwise_dlength",
            "pairwise_dlength_ucl", "pairwise_dlength_z", "pairwise_dlength_p"};
        for (int k = 0; k < 11; k++)
            if (extra[k])
                PUT(es_store_put_matrix(ctx, s, P(names[k]), (es_mat){(double *)extra[k], L, L, L}));
        PUT(es_store_put_vector(ctx, s, P("lsmean_at"), pw->at, pw->nvars));
        PUT(es_store_put_strings(ctx, s, P("lsmean_at_vars"), (const char *const *)d->vars,
                                 d->nvars));
        PUT(es_store_put_attr(ctx, s, grp, "pairwise", o->pairwise));
        PUT(es_store_put_attr(ctx, s, grp, "pairwise_slopes", o->slopes ? o->slopes : ""));
        PUT(es_store_put_attr_double(ctx, s, grp, "pairwise_confidence", pw->confidence));
    }
    if (r->edge_f) {
        const int lm = o->gpa != NULL;   /* per landmark in Procrustes space */
        const int64_t k = r->ntests;
        PUT(es_store_put_vector(ctx, s, P(lm ? "landmark_f" : "edge_f"), r->edge_f, k));
        PUT(es_store_put_vector(ctx, s, P(lm ? "landmark_p" : "edge_p"), r->edge_p, k));
        PUT(es_store_put_vector(ctx, s, P(lm ? "landmark_q" : "edge_q"), r->edge_q, k));
        PUT(es_store_put_attr(ctx, s, grp, "edge_term", o->edge_term));
        PUT(es_store_put_attr_int(ctx, s, grp, "edge_permutations",
                                  o->edge_permutations < 0 ? B : o->edge_permutations));
    }
    if (r->cac) {
        PUT(es_store_put_vector(ctx, s, P("cac"), r->cac, p));
        PUT(es_store_put_vector(ctx, s, P("cac_scores"), r->cac_scores, n));
    }
    PUT(es_store_put_attr(ctx, s, grp, "formula", o->formula));
    PUT(es_store_put_attr(ctx, s, grp, "space", o->gpa ? "procrustes" : "lengths"));
    PUT(es_store_put_attr(ctx, s, grp, "gpa", o->gpa ? o->gpa : ""));
    PUT(es_store_put_attr(ctx, s, grp, "where", o->where ? o->where : ""));
    PUT(es_store_put_attr(ctx, s, grp, "block", o->block ? o->block : ""));
    PUT(es_store_put_attr(ctx, s, grp, "ss_type", type_name(m->ss_type)));
    PUT(es_store_put_attr(ctx, s, grp, "permutation", m->scheme == ES_PERM_RAW ? "raw" : "rrpp"));
    PUT(es_store_put_attr(ctx, s, grp, "contrasts",
                          d->contrasts == ES_CONTRASTS_SUM ? "sum" : "treatment"));
    PUT(es_store_put_attr_int(ctx, s, grp, "permutations", B));
    PUT(es_store_put_attr_int(ctx, s, grp, "seed", (int64_t)m->seed));
    PUT(es_store_put_attr_int(ctx, s, grp, "n", n));
    PUT(es_store_put_attr_int(ctx, s, grp, "rank", m->rank));
    PUT(es_store_put_attr_int(ctx, s, grp, "df_resid", m->df_resid));
    PUT(es_store_put_attr_double(ctx, s, grp, "rss", m->rss));
    PUT(es_store_put_attr_double(ctx, s, grp, "tss", m->tss));
    if (r->comparison) {
        const es_model_comparison *c = r->comparison;
        char label[600];
        es__model_null_label(r->null_design, label, sizeof label);
        PUT(es_store_put_attr(ctx, s, grp, "null_model", label));
        const double row[7] = {(double)c->df, c->ss, c->ms, c->r2, c->f, c->z, c->pval};
        static const char *const keys[7] = {"null_df", "null_ss", "null_ms", "null_r2",
                                            "null_f", "null_z", "null_p"};
        for (int k = 0; k < 7; k++) PUT(es_store_put_attr_double(ctx, s, grp, keys[k], row[k]));
    }
#undef PUT
#undef P
done:
    es__free(ctx, ct);
    es__free(ctx, lt);
    return rc;
}

es_status es_study_model_coef(es_ctx *ctx, es_store *s, const char *model, const char *coef,
                              double *vec, double *weights)
{
    char path[700], space[64] = "";
    es_status rc;
    int64_t nn = 0, *rows = NULL, nr = 0, q = 0, c = -1;
    char **names = NULL;
    es_mat cm = {0}, wm = {0};
    if (!model || !*model || strchr(model, '/'))
        ES_FAIL(ctx, ES_EINVAL, "bad model name '%s'", model ? model : "");
    snprintf(path, sizeof path, "model/%s", model);
    if (!es_store_has(s, path)) {
        char hint[400];
        es_store_result_hint(ctx, s, "model", model, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "no model named '%s'%s", model, hint);
    }
    if ((rc = es_store_get_attr(ctx, s, path, "space", space, sizeof space)) != ES_OK) return rc;
    if (strcmp(space, "lengths"))
        ES_FAIL(ctx, ES_EINVAL, "model '%s' is in %s space; points are edge lengths", model,
                space);
    snprintf(path, sizeof path, "model/%s/coef_names", model);
    if ((rc = es_store_get_strings(ctx, s, path, &names, &q)) != ES_OK) return rc;
    for (int64_t k = 0; k < q && c < 0; k++)
        if (!strcmp(names[k], coef)) c = k;
    if (c < 0) {
        char list[512] = "";
        for (int64_t k = 0; k < q && strlen(list) < 400; k++) {
            strcat(list, k ? ", " : "");
            strncat(list, names[k], 100);
        }
        rc = es__fail(ctx, ES_ENOTFOUND, "model '%s' has no coefficient '%s' (it has: %s)",
                      model, coef, list);
        goto done;
    }
    snprintf(path, sizeof path, "model/%s/coefficients", model);
    if ((rc = es_store_get_matrix(ctx, s, path, &cm)) != ES_OK) goto done;
    snprintf(path, sizeof path, "model/%s/coef_weights", model);
    if ((rc = es_store_get_matrix(ctx, s, path, &wm)) != ES_OK) goto done;
    snprintf(path, sizeof path, "model/%s/rows", model);
    if ((rc = es_store_get_ints(ctx, s, path, &rows, &nr)) != ES_OK) goto done;
    nn = es_store_nrows(s);
    if (cm.rows != es_store_nedges(s) || cm.cols != q || wm.cols != q || wm.rows != nr) {
        rc = es__fail(ctx, ES_EFORMAT, "model '%s' is inconsistent with the store (%lld x %lld "
                      "coefficients, %lld edges)", model, (long long)cm.cols,
                      (long long)cm.rows, (long long)es_store_nedges(s));
        goto done;
    }
    if (isnan(ES_AT(cm, 0, c))) {
        rc = es__fail(ctx, ES_EINVAL, "coefficient '%s' of model '%s' is aliased (its column "
                      "is a combination of earlier ones)", coef, model);
        goto done;
    }
    memcpy(vec, cm.data + c * cm.ld, (size_t)cm.rows * sizeof *vec);
    for (int64_t i = 0; weights && i < nr; i++) {
        if (rows[i] < 0 || rows[i] >= nn) {
            rc = es__fail(ctx, ES_EFORMAT, "model '%s' names row %lld outside the store", model,
                          (long long)rows[i]);
            goto done;
        }
        weights[rows[i]] += ES_AT(wm, i, c);
    }
done:
    for (int64_t k = 0; names && k < q; k++) es_free(ctx, names[k]);
    es_free(ctx, names);
    es_free(ctx, cm.data);
    es_free(ctx, wm.data);
    es_free(ctx, rows);
    return rc;
}
