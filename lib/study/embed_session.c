/* lib/study/embed_session.c — an embedding session on a store: what every
 * embedding of the store's points shares, made once (the mesh, the embedder
 * from its kept vertex order, the rows made ready for priors, from the cache
 * beside the store when it is current), and the last output, from which a
 * warm embedding starts (a walk's next frame, a slider's next position).
 *
 * A point is embedded near the prior of its row weights (es_embed.h): the
 * solve starts from the prior's realization, or warm from that realization
 * plus the correction the last solve made to its own (x_last - prior_last):
 * a walk's next frame or a slider's next position then starts where the
 * last one ended, moved with the prior. Carrying the correction rather than
 * the last output itself keeps the result anchored to this point's prior,
 * so it depends little on which point came before (starting from the last
 * output as it is, a walk's middle frame came 0.5 % of the diagonal from the
 * same point embedded alone on facecap, and mean +- c sd of a statismo
 * export lost their symmetry). A last output that bends more than 1.1 x its
 * prior (the folds of an extrapolated point) is no start: carried along a
 * walk of the synthetic faces from mean - 2 sd on PC 1 (bending 1.48), it
 * kept every later frame folded (1.45-1.49, where each frame alone bends
 * 1.00-1.21); that frame starts from its prior instead. */
#include "embed/embed_private.h"
#include "study/study_pkg.h"

#include <math.h>
#include <stdio.h>

struct es_study_embedder {
    es_ctx *ctx;
    es_store *store;
    es_mesh *mesh;
    es_embedder *emb;
    es_study_rows *rows;
    int64_t nv, ne, n;
    double *target, *w, *prior, *last;   /* E, N, 3V + 4E, 3V */
    double *correction, *start;          /* 3V each: x_last - prior_last, the warm start */
    int last_ok;                         /* the last output bent <= 1.1 x its prior */
    int have_last;
    es__leaf_cache *leaves;              /* the points' leaves, kept (embed_leaves.c) */
};

void es_study_embedder_free(es_study_embedder *se)
{
    if (!se) return;
    es__leaf_cache_free(se->leaves);
    es_embedder_free(se->emb);
    es_study_rows_free(se->rows);
    es_mesh_free(se->mesh);
    es__free(se->ctx, se->target);
    es__free(se->ctx, se->w);
    es__free(se->ctx, se->prior);
    es__free(se->ctx, se->last);
    es__free(se->ctx, se->correction);
    es__free(se->ctx, se->start);
    es__free(se->ctx, se);
}

es_status es_study_embedder_open(es_ctx *ctx, es_store *store, int use_cache,
                                 es_study_embedder **out)
{
    es_study_embedder *se;
    int64_t *order = NULL;
    uint64_t key = 0;
    es_status rc;
    *out = NULL;
    if (!store) ES_FAIL(ctx, ES_EINVAL, "embed: no store");
    if (es_store_nrows(store) < 1) ES_FAIL(ctx, ES_EINVAL, "embed: the store has no rows");
    if (!(se = es__calloc(ctx, 1, sizeof *se))) return ES_ENOMEM;
    se->ctx = ctx;
    se->store = store;
    if ((rc = es_store_mesh(ctx, store, &se->mesh)) != ES_OK) goto fail;
    se->nv = es_mesh_nverts(se->mesh);
    se->ne = es_mesh_nedges(se->mesh);
    se->n = es_store_nrows(store);
    if ((rc = es__study_rows_check_memory(ctx, se->mesh, se->n)) != ES_OK) goto fail;
    se->target = es__alloc_array(ctx, se->ne, sizeof *se->target);
    se->w = es__alloc_array(ctx, se->n, sizeof *se->w);
    se->prior = es__alloc_array(ctx, 3 * se->nv + 4 * se->ne, sizeof *se->prior);
    se->last = es__alloc_array(ctx, 3 * se->nv, sizeof *se->last);
    se->correction = es__alloc_array(ctx, 3 * se->nv, sizeof *se->correction);
    se->start = es__alloc_array(ctx, 3 * se->nv, sizeof *se->start);
    if (!se->target || !se->w || !se->prior || !se->last || !se->correction || !se->start) {
        rc = ES_ENOMEM;
        goto fail;
    }
    if (use_cache) {
        if ((rc = es__study_cache_key(ctx, store, &key)) != ES_OK ||
            (rc = es__study_cache_load(ctx, store, key, &order, &se->rows)) != ES_OK)
            goto fail;
    }
    if ((rc = es_embedder_new_ordered(ctx, se->mesh, order, &se->emb)) != ES_OK ||
        (rc = es__leaf_cache_new(ctx, store, se->mesh, &se->leaves)) != ES_OK)
        goto fail;
    if (!se->rows) {
        if ((rc = es_study_rows_load(ctx, store, se->mesh, &se->rows)) != ES_OK) goto fail;
        if (use_cache) es__study_cache_save(ctx, store, key, es_embedder_ordering(se->emb), se->rows);
    }
    es__free(ctx, order);
    *out = se;
    return ES_OK;
fail:
    es__free(ctx, order);
    es_study_embedder_free(se);
    return rc;
}

const es_mesh *es_study_embedder_mesh(const es_study_embedder *se) { return se ? se->mesh : NULL; }
es_embedder *es_study_embedder_embedder(es_study_embedder *se) { return se ? se->emb : NULL; }
const es_study_rows *es_study_embedder_rows(const es_study_embedder *se)
{
    return se ? se->rows : NULL;
}

es_store *es_study_embedder_store(const es_study_embedder *se) { return se ? se->store : NULL; }

void es_study_embedder_forget(es_study_embedder *se)
{
    if (se) se->have_last = 0;
}

es_status es_study_embedder_solve(es_ctx *ctx, es_study_embedder *se, const double *lengths,
                                  double scale, const double *w, const es_embed_opts *eo, int warm, int exact,
                                  double *xyz, es_study_embed_result *res)
{
    int64_t used = 0, top = 0;
    es_embed_opts o;
    es_status rc;
    if (!se) ES_FAIL(ctx, ES_EINVAL, "embed: no session");
    double *alpha = se->prior + 3 * se->nv, *sd = alpha + se->ne, *lo = sd + se->ne,
           *hi = lo + se->ne;
    if (es_store_nrows(se->store) != se->n)
        ES_FAIL(ctx, ES_EMISMATCH, "embed: the store has %lld rows, the session was made for "
                "%lld: rows were added since; open a new session", (long long)es_store_nrows(se->store),
                (long long)se->n);
    if (eo) o = *eo;
    else es_embed_opts_init(&o);
    o.prior_exact = exact;
    memset(res, 0, sizeof *res);
    res->scale = scale;
    int64_t n3 = 3 * se->nv;
    if ((rc = es_study_prior(ctx, se->rows, w, se->prior, NULL, NULL)) != ES_OK) return rc;
    warm = warm && se->have_last && se->last_ok;
    if (warm)   /* (the solve scales the start to the target's sum) */
        for (int64_t i = 0; i < n3; i++) se->start[i] = se->prior[i] + se->correction[i];
    /* the circular means of the rows' dihedrals and their spread (twice the
     * work of the positions' blend), and the span of the rows' dihedrals
     * (the crease guard's band on closed meshes), only where the solve reads
     * them: not for local-global iterations alone (a slider, a walk,
     * --fast) from a start near the lengths */
    int dihedrals = es__prior_solve_reads_dihedrals(se->emb, lengths, scale, se->prior,
                                                    warm ? se->start : NULL, &o);
    int span = dihedrals && es__prior_solve_reads_span(se->emb, &o);
    if ((dihedrals && (rc = es_study_prior(ctx, se->rows, w, NULL, alpha, sd)) != ES_OK) ||
        (span && (rc = es_study_prior_span(ctx, se->rows, w, lo, hi)) != ES_OK))
        return rc;
    es_embed_prior pr = {se->prior, dihedrals ? alpha : NULL, dihedrals ? sd : NULL,
                         warm ? se->start : NULL, span ? lo : NULL, span ? hi : NULL};
    if ((rc = es_embed_prior_solve(ctx, se->emb, lengths, scale, &pr, &o, xyz, &res->report)) !=
        ES_OK)
        return rc;
    memcpy(se->last, xyz, (size_t)n3 * sizeof *xyz);
    for (int64_t i = 0; i < n3; i++) se->correction[i] = xyz[i] - se->prior[i];
    se->have_last = 1;
    se->last_ok = !(res->report.bend_ratio > 1.1);
    for (int64_t i = 0; i < se->n; i++) {
        used += w[i] != 0;
        if (fabs(w[i]) > fabs(w[top])) top = i;
    }
    snprintf(res->init, sizeof res->init, "prior of %lld row%s (weight %.3g on %s), store frame%s",
             (long long)used, used == 1 ? "" : "s", w[top], es_store_row_id(se->store, top),
             pr.start ? ", started with the last output's correction" : "");
    return ES_OK;
}

int es__study_point_is_one_mesh(es_ctx *ctx, const char *spec)
{
    es_point_expr *x = NULL;
    double coef = 0;
    es_point_leaf kind = ES_POINT_MEAN;
    int one = 0;
    if (!strncmp(spec, "row:", 4) || !strncmp(spec, "file:", 5)) {
        if (es_point_parse(ctx, spec, &x) == ES_OK && es_point_expr_nterms(x) == 1) {
            es_point_expr_term(x, 0, &coef, &kind, NULL, NULL);
            one = coef == 1 && (kind == ES_POINT_ROW || kind == ES_POINT_FILE);
        }
        es_point_expr_free(x);
        es_ctx_clear_error(ctx);
    }
    return one;
}

es_status es_study_embedder_point(es_ctx *ctx, es_study_embedder *se, const char *point,
                                  const char *pca_name,
                                  double scale, const es_embed_opts *eo, int warm, double *xyz,
                                  es_study_embed_result *res)
{
    double own;
    es_status rc;
    if (!se) ES_FAIL(ctx, ES_EINVAL, "embed: no session");
    if (!point) ES_FAIL(ctx, ES_EINVAL, "embed: no point given");
    if ((rc = es__leaf_cache_ready(se->leaves, pca_name)) != ES_OK ||
        (rc = es__study_point_weights_via(ctx, se->store, point, pca_name, es__leaf_cache_resolve,
                                          se->leaves, se->mesh, se->target, &own, se->w)) != ES_OK)
        return rc;
    return es_study_embedder_solve(ctx, se, se->target, scale > 0 ? scale : own, se->w, eo, warm,
                                   es__study_point_is_one_mesh(ctx, point), xyz, res);
}
