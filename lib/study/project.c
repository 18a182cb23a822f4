/* lib/study/project.c — scores of rows and of new meshes on a stored PCA,
 * with the residual: how a new face places among the study's. */
#include "core/core_private.h"
#include "edgespace/es_io.h"
#include "edgespace/es_study.h"

void es_study_projection_free(es_study_projection *p)
{
    if (!p) return;
    es__free(p->ctx, (void *)p->names);
    es__free(p->ctx, p->scores);
    es__free(p->ctx, p->residuals);
    es__free(p->ctx, p);
}

/* The normalized lengths of input `in`: a mesh file (its extension says
 * so) of the store's topology, or a row id. */
static es_status input_lengths(es_ctx *ctx, es_store *st, es_mesh **mesh, const char *in,
                               double *x)
{
    int64_t E = es_store_nedges(st), row;
    double scale;
    es_status rc;
    if (es_meshio_format_from_path(in) != ES_FORMAT_AUTO) {
        /* rows of a truss store project without a mesh; files need its faces */
        if (!*mesh && (rc = es_store_mesh(ctx, st, mesh)) != ES_OK) return rc;
        return es_meshio_lengths_from_file(ctx, *mesh, in, x, &scale);
    }
    if ((row = es_store_find_row(st, in)) < 0)
        ES_FAIL(ctx, ES_ENOTFOUND, "'%s' is neither a mesh file (.obj, .ply, .off) nor a row "
                "id of the store", in);
    return es_store_read_lengths(ctx, st, row, 1, (es_mat){x, E, 1, E});
}

es_status es_study_project(es_ctx *ctx, es_store *store, const char *pca_name,
                           int64_t ninputs, const char *const *inputs, const char *where,
                           es_study_projection **out)
{
    es_pca *p = NULL;
    es_mesh *mesh = NULL;
    int64_t *rows = NULL, nrows = 0;
    double *x = NULL;
    es_study_projection *r = NULL;
    es_status rc;
    *out = NULL;
    if ((rc = es_study_pca_load(ctx, store, pca_name, &p, NULL, NULL)) != ES_OK ||
        (where && (rc = es_store_select(ctx, store, where, &rows, &nrows)) != ES_OK))
        goto done;
    const int64_t E = p->nedges, K = p->ncomp, n = ninputs + nrows;
    if (!(r = es__calloc(ctx, 1, sizeof *r)) ||
        !(r->names = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *r->names)) ||
        !(r->scores = es__alloc_array(ctx, (n > 0 ? n : 1) * (K > 0 ? K : 1), sizeof *r->scores)) ||
        !(r->residuals = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *r->residuals)) ||
        !(x = es__alloc_array(ctx, E, sizeof *x))) {
        rc = ES_ENOMEM;
        goto done;
    }
    r->ctx = ctx;
    r->n = n;
    r->ncomp = K;
    double *score = es__alloc_array(ctx, K > 0 ? K : 1, sizeof *score);
    if (!score) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < n && rc == ES_OK; i++) {
        if (i < ninputs) {
            r->names[i] = inputs[i];
            rc = input_lengths(ctx, store, &mesh, inputs[i], x);
        } else {
            int64_t row = rows[i - ninputs];
            r->names[i] = es_store_row_id(store, row);
            rc = es_store_read_lengths(ctx, store, row, 1, (es_mat){x, E, 1, E});
        }
        if (rc == ES_OK) rc = es_pca_project(ctx, p, (es_mat){x, E, 1, E}, score,
                                             &r->residuals[i]);
        for (int64_t k = 0; rc == ES_OK && k < K; k++) r->scores[i + k * n] = score[k];
    }
    es__free(ctx, score);
done:
    if (rc == ES_OK) {
        *out = r;
        r = NULL;
    }
    es_study_projection_free(r);
    es__free(ctx, x);
    es__free(ctx, rows);
    es_mesh_free(mesh);
    es_pca_free(p);
    return rc;
}
