/* lib/landmarks_store.c — a landmark set with a triangulation of its
 * landmarks into a store, so that the store's GPA and edge-length tools run
 * on landmark data ("truss" lengths over the triangulation's edges).
 * 2D landmarks get z = 0; TPS image names and scales become label columns.
 */
#include "es_internal.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_landmarks.h"
#include "edgespace/es_mesh.h"
#include "edgespace/es_store.h"

#include <math.h>
#include <stdio.h>

es_status es_landmarks_to_store(es_ctx *ctx, const es_landmarks *lm, int64_t ntri,
                                const int64_t *tri, const char *path)
{
    es_status rc;
    es_mesh *mesh = NULL;
    es_store *s = NULL;
    double *xyz = NULL, *len = NULL, *sc = NULL;
    const char **colnames = NULL, **labels = NULL;
    char *scale_txt = NULL;
    if (!tri || ntri < 1)
        ES_FAIL(ctx, ES_EINVAL, "landmarks: the store format needs faces; give a triangulation "
                "of the %lld landmarks (e.g. --triangles) to store them", (long long)lm->k);
    int64_t k = lm->k, n = lm->n, kd = k * lm->d;
    xyz = es__alloc_array(ctx, 3 * k * n, sizeof *xyz);
    if (!xyz) return ES_ENOMEM;
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < k; v++)
            for (int q = 0; q < 3; q++)
                xyz[3 * k * j + 3 * v + q] = q < lm->d ? lm->xyz[kd * j + v + q * k] : 0.0;
    if ((rc = es_mesh_new(ctx, k, ntri, tri, xyz, &mesh)) != ES_OK) goto done;
    int64_t e = es_mesh_nedges(mesh);
    len = es__alloc_array(ctx, e * n, sizeof *len);
    sc = es__alloc_array(ctx, n, sizeof *sc);
    if (!len || !sc) { rc = ES_ENOMEM; goto done; }
    for (int64_t j = 0; j < n; j++) {
        if ((rc = es_edge_lengths(ctx, mesh, xyz + 3 * k * j, len + e * j)) != ES_OK ||
            (rc = es_lengths_normalize(ctx, e, len + e * j, len + e * j, sc + j)) != ES_OK) {
            char msg[512];
            snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
            es__fail(ctx, rc, "landmarks: specimen '%s': %s", lm->ids[j], msg);
            goto done;
        }
    }
    /* label columns: the set's, then image / tps_scale when any is present */
    int has_img = 0, has_sc = 0;
    for (int64_t j = 0; j < n; j++) {
        has_img |= lm->images && lm->images[j] != NULL;
        has_sc |= lm->scale && isfinite(lm->scale[j]);
    }
    int64_t nc = lm->ncols + has_img + has_sc;
    if (nc > 0) {
        colnames = es__alloc_array(ctx, nc, sizeof *colnames);
        labels = es__alloc_array(ctx, n * nc, sizeof *labels);
        scale_txt = es__alloc_array(ctx, n * 32, 1);
        if (!colnames || !labels || !scale_txt) { rc = ES_ENOMEM; goto done; }
        for (int64_t c = 0; c < lm->ncols; c++) colnames[c] = lm->colnames[c];
        if (has_img) colnames[lm->ncols] = "image";
        if (has_sc) colnames[lm->ncols + has_img] = "tps_scale";
        for (int64_t j = 0; j < n; j++) {
            for (int64_t c = 0; c < lm->ncols; c++) labels[j * nc + c] = lm->labels[j * lm->ncols + c];
            if (has_img) labels[j * nc + lm->ncols] = lm->images[j] ? lm->images[j] : "";
            if (has_sc) {
                char *t = scale_txt + 32 * j;
                if (isfinite(lm->scale[j])) snprintf(t, 32, "%.17g", lm->scale[j]);
                else t[0] = 0;
                labels[j * nc + lm->ncols + has_img] = t;
            }
        }
    }
    if ((rc = es_store_create(ctx, path, mesh, &s)) != ES_OK) goto done;
    es_store_rows rows = {0};
    rows.n = n;
    rows.ids = (const char *const *)lm->ids;
    rows.lengths = len;
    rows.scales = sc;
    rows.xyz = xyz;
    rows.ncols = nc;
    rows.colnames = colnames;
    rows.labels = labels;
    if ((rc = es_store_append(ctx, s, &rows)) != ES_OK) goto done;
    rc = es_store_commit(ctx, s);
done:
    if (s) {
        if (rc == ES_OK) es_store_close(s);
        else es_store_abort(s);
    }
    es_mesh_free(mesh);
    es__free(ctx, xyz);
    es__free(ctx, len);
    es__free(ctx, sc);
    es__free(ctx, colnames);
    es__free(ctx, labels);
    es__free(ctx, scale_txt);
    return rc;
}
