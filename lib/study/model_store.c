/* lib/study/model_store.c — linear models on a store (es_study_model): the
 * glue that reads the rows' labels and their response (normalized lengths,
 * or a GPA result's aligned coordinates), runs es_model.h, and keeps the
 * result under /analysis/model/<name>; and the coefficients read back for
 * the point syntax (coef:MODEL:COEF).
 *
 * The variable `size` is each row's own size when no label column has that
 * name (the scale, the sum of the raw edge lengths, in edge-length space;
 * the centroid size of the configuration in Procrustes space), so that
 * log(size) is the allometric covariate of geomorph's procD.lm(shape ~
 * log(Csize)).
 */
#include "study/study_pkg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void es_study_model_opts_init(es_study_model_opts *o)
{
    memset(o, 0, sizeof *o);
    o->ss_type = ES_SS_TYPE_I;
    o->scheme = ES_PERM_RRPP;
    o->permutations = 999;
    o->contrasts = ES_CONTRASTS_TREATMENT;
    o->edge_permutations = -1;
}

void es_study_model_free(es_study_model_result *r)
{
    if (!r) return;
    es_ctx *ctx = r->ctx;
    es_model_pairwise_free(r->pairwise);
    es_model_comparison_free(r->comparison);
    es_model_free(r->null_model);
    es_design_free(r->null_design);
    es_formula_free(r->null_formula);
    es_model_free(r->model);
    es_design_free(r->design);
    es_formula_free(r->formula);
    es__free(ctx, r->edge_f);
    es__free(ctx, r->edge_p);
    es__free(ctx, r->edge_q);
    es__free(ctx, r->cac);
    es__free(ctx, r->cac_scores);
    es__free(ctx, r->rows);
    es__free(ctx, (void *)r->ids);
    es__free(ctx, r);
}

/* The response: rows (store rows, model order) and a source over them. */
typedef struct response {
    es_mat aligned;        /* GPA: k*d x n_gpa (owned) */
    int64_t *cols;         /* GPA: the aligned column of each model row (owned) */
    double *size;          /* N sizes (owned) */
    int64_t dim;           /* GPA: coordinates per landmark; 0: edge lengths */
    es_source src;
} response;

static void response_clear(es_ctx *ctx, response *r)
{
    es_free(ctx, r->aligned.data);
    es__free(ctx, r->cols);
    es__free(ctx, r->size);
}

static es_status lengths_response(es_ctx *ctx, es_store *s, es_study_model_result *res,
                                  response *rp)
{
    es_status rc;
    if (es_store_nedges(s) < 1)
        ES_FAIL(ctx, ES_EINVAL, "model: store '%s' has no edges: model a GPA result instead "
                "(--gpa NAME)", es_store_path(s));
    const int64_t N = es_store_nrows(s), n = res->nrows;
    double *scales = es__alloc_array(ctx, N > 0 ? N : 1, sizeof *scales);
    rp->size = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *rp->size);
    if (!scales || !rp->size) {
        es__free(ctx, scales);
        return ES_ENOMEM;
    }
    if ((rc = es_store_read_scales(ctx, s, scales)) == ES_OK) {
        for (int64_t i = 0; i < n; i++) rp->size[i] = scales[res->rows[i]];
        rc = es_study_source(ctx, s, res->rows, n, &rp->src);
    }
    es__free(ctx, scales);
    return rc;
}

/* Procrustes space: the GPA result's rows that the filter keeps. */
static es_status gpa_response(es_ctx *ctx, es_store *s, const char *gpa, const int64_t *sel,
                              int64_t nsel, es_study_model_result *res, response *rp)
{
    char path[600];
    int64_t *grows = NULL, ng = 0, nsz = 0;
    double *size = NULL;
    es_status rc;
    if (strchr(gpa, '/')) ES_FAIL(ctx, ES_EINVAL, "model: bad GPA name '%s'", gpa);
    snprintf(path, sizeof path, "gpa/%s", gpa);
    if (!es_store_has(s, path)) {
        char hint[400];
        es_store_result_hint(ctx, s, "gpa", gpa, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "model: no GPA result '%s'%s (run edgespace gpa --name %s)",
                gpa, hint, gpa);
    }
    double dim = 0;
    snprintf(path, sizeof path, "gpa/%s", gpa);
    if ((rc = es_store_get_attr_double(ctx, s, path, "dim", &dim)) != ES_OK) return rc;
    rp->dim = (int64_t)dim;
    snprintf(path, sizeof path, "gpa/%s/aligned", gpa);
    if ((rc = es_store_get_matrix(ctx, s, path, &rp->aligned)) != ES_OK) return rc;
    if (rp->dim < 1 || rp->aligned.rows % rp->dim)
        ES_FAIL(ctx, ES_EFORMAT, "model: GPA result '%s' has %lld coordinates in %lld "
                "dimensions", gpa, (long long)rp->aligned.rows, (long long)rp->dim);
    snprintf(path, sizeof path, "gpa/%s/input_rows", gpa);
    if ((rc = es_store_get_ints(ctx, s, path, &grows, &ng)) != ES_OK) goto done;
    snprintf(path, sizeof path, "gpa/%s/size", gpa);
    if ((rc = es_store_get_vector(ctx, s, path, &size, &nsz)) != ES_OK) goto done;
    if (ng != rp->aligned.cols || nsz != ng) {
        rc = es__fail(ctx, ES_EFORMAT, "model: GPA result '%s' is inconsistent (%lld rows, "
                      "%lld configurations, %lld sizes)", gpa, (long long)ng,
                      (long long)rp->aligned.cols, (long long)nsz);
        goto done;
    }
    /* keep the GPA's order; a row the filter selects but the GPA lacks is
     * left out (and said) */
    res->rows = es__alloc_array(ctx, ng > 0 ? ng : 1, sizeof *res->rows);
    rp->cols = es__alloc_array(ctx, ng > 0 ? ng : 1, sizeof *rp->cols);
    rp->size = es__alloc_array(ctx, ng > 0 ? ng : 1, sizeof *rp->size);
    if (!res->rows || !rp->cols || !rp->size) {
        rc = ES_ENOMEM;
        goto done;
    }
    int64_t n = 0, isel = 0;
    for (int64_t j = 0; j < ng; j++) {
        int keep = !sel;
        for (int64_t k = 0; sel && k < nsel && !keep; k++) keep = sel[k] == grows[j];
        if (!keep) continue;
        res->rows[n] = grows[j];
        rp->cols[n] = j;
        rp->size[n] = size[j];
        n++;
    }
    for (int64_t k = 0; sel && k < nsel; k++) {
        int in = 0;
        for (int64_t j = 0; j < ng && !in; j++) in = grows[j] == sel[k];
        isel += !in;
    }
    if (isel) es__warn(ctx, "model: %lld of the selected rows are not in GPA result '%s' and "
                       "are left out", (long long)isel, gpa);
    res->nrows = n;
    rp->src = es_source_matrix(rp->aligned, rp->cols, n);
done:
    es_free(ctx, grows);
    es_free(ctx, size);
    return rc;
}

/* Columns for the formula's variables: label columns, or the size. */
static es_status columns(es_ctx *ctx, es_store *s, const es_study_model_result *res,
                         const es_formula *f, const response *rp, es_model_column *cols,
                         const char ***lab)
{
    const int64_t n = res->nrows, nv = es_formula_nvars(f);
    for (int64_t v = 0; v < nv; v++) {
        const char *name = es_formula_var(f, v, NULL);
        int64_t col = es_store_find_column(s, name);
        cols[v].name = name;
        cols[v].labels = NULL;
        cols[v].values = NULL;
        cols[v].reference = NULL;
        if (col < 0 && !strcmp(name, "size")) {
            cols[v].values = rp->size;
            continue;
        }
        if (col < 0) {
            char hint[400];
            es_store_column_hint(s, name, hint, sizeof hint);
            ES_FAIL(ctx, ES_ENOTFOUND, "model: no label column '%s' in '%s'%s", name,
                    es_store_path(s), hint);
        }
        if (!(lab[v] = es__alloc_array(ctx, n, sizeof **lab))) return ES_ENOMEM;
        for (int64_t i = 0; i < n; i++) lab[v][i] = es_store_label(s, res->rows[i], col);
        cols[v].labels = lab[v];
    }
    return ES_OK;
}

static es_status blocks_of(es_ctx *ctx, es_store *s, const es_study_model_result *res,
                           const char *block, int64_t **out)
{
    int64_t col = es_store_find_column(s, block), ng = 0;
    const char **lab = NULL, **names = NULL;
    if (col < 0) {
        char hint[400];
        es_store_column_hint(s, block, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "model: no label column '%s' for the blocks%s", block, hint);
    }
    if (!(lab = es__alloc_array(ctx, res->nrows, sizeof *lab))) return ES_ENOMEM;
    for (int64_t i = 0; i < res->nrows; i++) lab[i] = es_store_label(s, res->rows[i], col);
    es_status rc = es_groups_from_labels(ctx, lab, res->nrows, out, &names, &ng);
    es__free(ctx, (void *)lab);
    es_free(ctx, (void *)names);
    return rc;
}

/* A formula's name is a label column, or `size` (each row's scale, or the
 * GPA's centroid size) when no column has that name. */
static int known_column(void *ud, const char *name, char *why, size_t n)
{
    es_store *s = ud;
    char hint[400];
    if (es_store_find_column(s, name) >= 0 || !strcmp(name, "size")) return 1;
    es_store_column_hint(s, name, hint, sizeof hint);
    snprintf(why, n, "no label column '%s' in '%s'%s", name, es_store_path(s), hint);
    return 0;
}

/* The fit's companions: a null model to compare with, pairwise comparisons,
 * per-variable tests, the common allometric component. */
static es_status after_fit(es_ctx *ctx, es_store *store, const es_study_model_opts *o,
                           es_study_model_result *r, const response *rp, const es_model_opts *mo)
{
    es_status rc = ES_OK;
    const int64_t p = r->model->p, nv = r->design->nvars;
    if (o->null_formula) {
        const char **lab[64] = {NULL};
        es_model_column cols[64];
        if ((rc = es_formula_parse_checked(ctx, o->null_formula, known_column, store,
                                           &r->null_formula)) == ES_OK &&
            (rc = columns(ctx, store, r, r->null_formula, rp, cols, lab)) == ES_OK &&
            (rc = es_design_build(ctx, r->null_formula, r->nrows, cols,
                                  es_formula_nvars(r->null_formula), r->design->contrasts,
                                  &r->null_design)) == ES_OK) {
            es_model_opts no = *mo;
            no.error = NULL;
            no.permutations = 0;
            if ((rc = es_model_fit(ctx, r->null_design, &rp->src, &no, &r->null_model)) == ES_OK)
                rc = es_model_compare(ctx, r->null_model, r->model, &r->comparison);
        }
        for (int v = 0; v < 64; v++) es__free(ctx, (void *)lab[v]);
        if (rc != ES_OK) return rc;
    }
    if (o->pairwise) {
        es_model_pairwise_opts po;
        es_model_pairwise_opts_init(&po);
        double *at = es__alloc_array(ctx, nv > 0 ? nv : 1, sizeof *at);
        if (!at) return ES_ENOMEM;
        po.covariate = o->slopes;
        po.at = at;
        if ((rc = es__model_at(ctx, r->design, r->formula, o->at, at)) == ES_OK)
            rc = es_model_pairwise_fit(ctx, r->model, o->pairwise, &po, &r->pairwise);
        es__free(ctx, at);
        if (rc != ES_OK) return rc;
    } else if (o->slopes || o->at) {
        ES_FAIL(ctx, ES_EINVAL, "model: %s needs a pairwise factor", o->slopes ? "slopes" : "at");
    }
    if (o->edge_term) {
        const int64_t k = rp->dim ? p / rp->dim : p;
        int64_t *group = NULL;
        r->ntests = k;
        r->edge_f = es__alloc_array(ctx, k, sizeof *r->edge_f);
        r->edge_p = es__alloc_array(ctx, k, sizeof *r->edge_p);
        r->edge_q = es__alloc_array(ctx, k, sizeof *r->edge_q);
        if (rp->dim && (group = es__alloc_array(ctx, p, sizeof *group)))
            for (int64_t e = 0; e < p; e++) group[e] = e % k;   /* x1..xk, y1..yk, ... */
        if (!r->edge_f || !r->edge_p || !r->edge_q || (rp->dim && !group)) rc = ES_ENOMEM;
        else rc = es_model_group_tests(ctx, r->model, o->edge_term, o->edge_permutations,
                                       rp->dim ? k : 0, group, r->edge_f, r->edge_p, r->edge_q);
        es__free(ctx, group);
        if (rc != ES_OK) return rc;
    }
    if (es_model_find_term(r->model, "log(size)") >= 0) {
        r->cac = es__alloc_array(ctx, p, sizeof *r->cac);
        r->cac_scores = es__alloc_array(ctx, r->nrows, sizeof *r->cac_scores);
        if (!r->cac || !r->cac_scores) return ES_ENOMEM;
        rc = es_model_cac(ctx, r->model, "log(size)", r->cac, r->cac_scores);
    }
    return rc;
}

es_status es_study_model(es_ctx *ctx, es_store *store, const es_study_model_opts *opts,
                         es_study_model_result **out)
{
    es_study_model_opts o;
    response rp;
    memset(&rp, 0, sizeof rp);
    *out = NULL;
    if (opts) o = *opts;
    else es_study_model_opts_init(&o);
    if (!store || !o.formula) ES_FAIL(ctx, ES_EINVAL, "model: no store or no formula");
    if (o.name && (!*o.name || strchr(o.name, '/')))
        ES_FAIL(ctx, ES_EINVAL, "model: bad result name '%s' (no '/', not empty)", o.name);
    if (o.nerrors < 0 || (o.nerrors > 0 && !o.errors))
        ES_FAIL(ctx, ES_EINVAL, "model: bad error-term list");
    es_study_model_result *r = es__calloc(ctx, 1, sizeof *r);
    int64_t *sel = NULL, nsel = 0, *blocks = NULL, *error = NULL;
    const char **lab[64] = {NULL};
    char *refs = NULL;
    es_model_column cols[64];
    es_status rc;
    if (!r) return ES_ENOMEM;
    r->ctx = ctx;
    /* the columns are checked as the formula is read, before it is expanded */
    if ((rc = es_formula_parse_checked(ctx, o.formula, known_column, store, &r->formula)) != ES_OK)
        goto done;
    if ((o.where || !o.gpa) && (rc = es_store_select(ctx, store, o.where, &sel, &nsel)) != ES_OK)
        goto done;
    if (o.gpa) {
        rc = gpa_response(ctx, store, o.gpa, o.where ? sel : NULL, nsel, r, &rp);
    } else {
        r->rows = sel;
        r->nrows = nsel;
        sel = NULL;
        rc = lengths_response(ctx, store, r, &rp);
    }
    if (rc != ES_OK) goto done;
    if (r->nrows < 2) {
        rc = es__fail(ctx, ES_EINVAL, "model: %lld rows match '%s'", (long long)r->nrows,
                      o.where ? o.where : "");
        goto done;
    }
    if (!(r->ids = es__alloc_array(ctx, r->nrows, sizeof *r->ids))) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < r->nrows; i++) r->ids[i] = es_store_row_id(store, r->rows[i]);
    if ((rc = columns(ctx, store, r, r->formula, &rp, cols, lab)) != ES_OK ||
        (rc = es__model_references(ctx, r->formula, o.reference, r->nrows, cols, &refs)) != ES_OK ||
        (rc = es_design_build(ctx, r->formula, r->nrows, cols, es_formula_nvars(r->formula),
                              o.contrasts, &r->design)) != ES_OK)
        goto done;
    if (o.edge_term && es_design_dropped(r->design, o.edge_term)) {
        rc = es__fail(ctx, ES_EINVAL, "model: --edges %s: the term %s and was left out of the "
                      "model: test what it duplicates", o.edge_term,
                      es_design_dropped(r->design, o.edge_term));
        goto done;
    }
    if (!(error = es__alloc_array(ctx, r->design->nterms > 0 ? r->design->nterms : 1,
                                  sizeof *error))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es__model_errors(ctx, r->design, o.errors, o.nerrors, error)) != ES_OK) goto done;
    if (o.block && (rc = blocks_of(ctx, store, r, o.block, &blocks)) != ES_OK) goto done;
    /* a taken name is refused before the permutations run */
    if (o.name && (rc = es_store_result_check(ctx, store, "model", o.name)) != ES_OK) goto done;
    es_model_opts mo;
    es_model_opts_init(&mo);
    mo.ss_type = o.ss_type;
    mo.scheme = o.scheme;
    mo.permutations = o.permutations;
    mo.blocks = blocks;
    mo.error = error;
    if ((rc = es_model_fit(ctx, r->design, &rp.src, &mo, &r->model)) != ES_OK ||
        (rc = after_fit(ctx, store, &o, r, &rp, &mo)) != ES_OK)
        goto done;
    if (o.name && (rc = es__model_save(ctx, store, &o, r)) != ES_OK) goto done;
    *out = r;
    r = NULL;
done:
    for (int v = 0; v < 64; v++) es__free(ctx, (void *)lab[v]);
    es__free(ctx, refs);
    es__free(ctx, sel);
    es__free(ctx, blocks);
    es__free(ctx, error);
    response_clear(ctx, &rp);
    es_study_model_free(r);
    return rc;
}
