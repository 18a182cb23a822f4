/* lib/study/embed_store.c — the embedding next to a store: initialization from
 * stored shapes (nearest row in edge-length distance, circular mean of
 * rows' dihedrals), and embeddings stored with their
 * quality report and per-vertex residuals under /analysis/embed/<name>.
 */
#include "study/study_pkg.h"
#include "edgespace/es_study.h"
#include "edgespace/es_geom.h"

#include <math.h>
#include <stdio.h>

es_status es_study_nearest_row(es_ctx *ctx, es_store *store, const double *target,
                               const int64_t *rows, int64_t nrows, int64_t *row, double *dist)
{
    int64_t ne = es_store_nedges(store), n = rows ? nrows : es_store_nrows(store), best = -1;
    double *l, bd = INFINITY;
    es_status rc = ES_OK;
    if (n <= 0) ES_FAIL(ctx, ES_ENOTFOUND, "embed: the store has no rows to start from");
    l = es__alloc_array(ctx, ne, sizeof *l);
    if (!l) return ES_ENOMEM;
    for (int64_t i = 0; i < n; i++) {
        int64_t r = rows ? rows[i] : i;
        double d = 0;
        if ((rc = es_store_read_lengths(ctx, store, r, 1, (es_mat){l, ne, 1, ne})) != ES_OK)
            break;
        for (int64_t e = 0; e < ne; e++) d += (l[e] - target[e]) * (l[e] - target[e]);
        if (d < bd) {
            bd = d;
            best = r;
        }
    }
    es__free(ctx, l);
    if (rc != ES_OK) return rc;
    *row = best;
    if (dist) *dist = sqrt(bd);
    return ES_OK;
}

es_status es_study_mean_dihedrals(es_ctx *ctx, es_store *store, const es_mesh *mesh,
                                  const int64_t *rows, int64_t nrows, double *alpha)
{
    int64_t ne = es_mesh_nedges(mesh), nv = es_mesh_nverts(mesh);
    double *xyz, *a, *c, *s;
    es_status rc = ES_OK;
    if (nrows < 1) ES_FAIL(ctx, ES_EINVAL, "embed: no rows to average dihedrals over");
    xyz = es__alloc_array(ctx, 3 * nv, sizeof *xyz);
    a = es__alloc_array(ctx, ne, sizeof *a);
    c = es__calloc(ctx, (size_t)ne, sizeof *c);
    s = es__calloc(ctx, (size_t)ne, sizeof *s);
    if (!xyz || !a || !c || !s) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < nrows; i++) {
        if ((rc = es_store_read_positions(ctx, store, rows[i], xyz)) != ES_OK ||
            (rc = es_dihedral_angles(ctx, mesh, xyz, a)) != ES_OK)
            goto done;
        for (int64_t e = 0; e < ne; e++) {
            c[e] += cos(a[e]);
            s[e] += sin(a[e]);
        }
    }
    for (int64_t e = 0; e < ne; e++) alpha[e] = (c[e] == 0 && s[e] == 0) ? 0 : atan2(s[e], c[e]);
done:
    es__free(ctx, xyz);
    es__free(ctx, a);
    es__free(ctx, c);
    es__free(ctx, s);
    return rc;
}

es_status es_study_store_embedding(es_ctx *ctx, es_store *store, const char *name,
                                const es_provenance *prov, const es_embedder *emb,
                                const double *target, const double *xyz,
                                const es_embed_report *r, const char *init)
{
    if (!es_embedder_vertex_closure(emb))
        ES_FAIL(ctx, ES_EINVAL, "embed: store result: the embedder has not solved yet");
    return es__study_store_mesh_result(ctx, store, name, prov, es_embedder_mesh(emb),
                                       es_embedder_vertex_closure(emb),
                                       es_embedder_vertex_edge_error(emb),
                                       es_embedder_vertex_deviation(emb), target, xyz, r, init);
}

es_status es__study_store_mesh_result(es_ctx *ctx, es_store *store, const char *name,
                                      const es_provenance *prov, const es_mesh *mesh,
                                      const double *vclos, const double *verr,
                                      const double *vdev, const double *target,
                                      const double *xyz, const es_embed_report *r,
                                      const char *init)
{
    int64_t nv = es_mesh_nverts(mesh), ne = es_mesh_nedges(mesh);
    char path[512];
    double *tn = NULL, sum = 0;
    es_status rc;
    struct { const char *key; double v; } attrs[] = {
        {"closure_before", r->closure_before}, {"closure_stage1", r->closure_stage1},
        {"closure_after", r->closure_after}, {"rms_ratio", r->rms_ratio},
        {"rms_ratio_linear", r->rms_ratio_linear}, {"max_rel", r->max_rel},
        {"p99_rel", r->p99_rel}, {"worst_edge", (double)r->worst_edge},
        {"n_bad_faces", (double)r->n_bad_faces}, {"realized", r->realized},
        {"used_stage1", r->used_stage1}, {"used_continuation", r->used_continuation},
        {"dihedral_iters", (double)r->dihedral_iters}, {"refine_iters", (double)r->refine_iters},
        {"t_dihedral", r->t_dihedral}, {"t_frames", r->t_frames},
        {"t_positions", r->t_positions}, {"t_refine", r->t_refine}, {"t_total", r->t_total},
        {"scale", r->scale}, {"has_prior", r->has_prior}, {"bend_out", r->bend_out},
        {"bend_prior", r->bend_prior}, {"bend_ratio", r->bend_ratio},
        {"prior_rms", r->prior_rms}, {"prior_max", r->prior_max}};
    if ((rc = es_store_result_begin(ctx, store, "embed", name, prov)) != ES_OK) return rc;
#define P(ds) (snprintf(path, sizeof path, "embed/%s/%s", name, ds) < (int)sizeof path ? path : "")
    if ((rc = es_store_put_matrix(ctx, store, P("positions"), (es_mat){(double *)xyz, 3, nv, 3})) !=
            ES_OK ||
        (rc = es_store_put_vector(ctx, store, P("vertex_closure"), vclos, nv)) != ES_OK ||
        (rc = es_store_put_vector(ctx, store, P("vertex_edge_error"), verr, nv)) != ES_OK ||
        (vdev && (rc = es_store_put_vector(ctx, store, P("vertex_deviation"), vdev, nv)) !=
                     ES_OK))
        return rc;
    tn = es__alloc_array(ctx, ne, sizeof *tn);
    if (!tn) return ES_ENOMEM;
    for (int64_t e = 0; e < ne; e++) sum += target[e];
    for (int64_t e = 0; e < ne; e++) tn[e] = target[e] / sum;
    rc = es_store_put_vector(ctx, store, P("target_lengths"), tn, ne);
    es__free(ctx, tn);
    if (rc != ES_OK) return rc;
    snprintf(path, sizeof path, "embed/%s", name);
    for (size_t i = 0; i < sizeof attrs / sizeof attrs[0]; i++)
        if ((rc = es_store_put_attr_double(ctx, store, path, attrs[i].key, attrs[i].v)) != ES_OK)
            return rc;
    if (init && (rc = es_store_put_attr(ctx, store, path, "init", init)) != ES_OK) return rc;
#undef P
    return ES_OK;
}
