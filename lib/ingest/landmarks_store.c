/* lib/ingest/landmarks_store.c — a landmark set into a store, with one of three
 * topologies (datasets-spec/store-format.md, topology_kind):
 *  - a triangulation of the landmarks: a mesh store, so that every tool runs;
 *  - an edge list ("truss"): the lengths of the landmark pairs, normalized per
 *    row as for meshes, so that edge-length statistics run (no faces);
 *  - nothing: configurations, ids and labels only, for GPA and export.
 * Positions are 3 x V per row as for meshes: 2D landmarks get z = 0 (GPA
 * analyses such rows in 2D). TPS image names and scales become label columns.
 */
#include "core/core_private.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_landmarks.h"
#include "edgespace/es_mesh.h"
#include "edgespace/es_store.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int cmp_pair(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    return x[0] != y[0] ? (x[0] > y[0]) - (x[0] < y[0]) : (x[1] > y[1]) - (x[1] < y[1]);
}

/* ntri > 0: mesh store over tri; else nedges > 0: truss store over edges
 * (any order and orientation: made canonical here); else landmarks only. */
static es_status to_store(es_ctx *ctx, const es_landmarks *lm, int64_t ntri, const int64_t *tri,
                          int64_t nedges, const int64_t *edges_in, const char *path)
{
    es_status rc;
    es_mesh *mesh = NULL;
    es_store *s = NULL;
    double *xyz = NULL, *len = NULL, *sc = NULL;
    int64_t *edges = NULL;
    const char **colnames = NULL, **labels = NULL;
    char *scale_txt = NULL;
    if (!lm || !path) ES_FAIL(ctx, ES_EINVAL, "landmarks: NULL argument");
    if (ntri < 0 || (ntri > 0 && !tri) || nedges < 0 || (nedges > 0 && !edges_in))
        ES_FAIL(ctx, ES_EINVAL, "landmarks: bad topology (%lld triangles, %lld edges)",
                (long long)ntri, (long long)nedges);
    int64_t k = lm->k, n = lm->n, kd = k * lm->d, e = 0;
    xyz = es__alloc_array(ctx, 3 * k * n, sizeof *xyz);
    if (!xyz) return ES_ENOMEM;
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < k; v++)
            for (int q = 0; q < 3; q++)
                xyz[3 * k * j + 3 * v + q] = q < lm->d ? lm->xyz[kd * j + v + q * k] : 0.0;
    if (ntri > 0) {
        if ((rc = es_mesh_new(ctx, k, ntri, tri, xyz, &mesh)) != ES_OK) goto done;
        e = es_mesh_nedges(mesh);
    } else if (nedges > 0) {
        /* canonical (min, max), sorted, each pair once: the mesh convention */
        if (!(edges = es__alloc_array(ctx, 2 * nedges, sizeof *edges))) { rc = ES_ENOMEM; goto done; }
        for (int64_t i = 0; i < nedges; i++) {
            int64_t a = edges_in[2 * i], b = edges_in[2 * i + 1];
            if (a < 0 || b < 0 || a >= k || b >= k || a == b) {
                rc = es__fail(ctx, ES_EINVAL, "landmarks: edge %lld joins landmarks %lld and "
                              "%lld (of %lld)", (long long)i + 1, (long long)a + 1,
                              (long long)b + 1, (long long)k);
                goto done;
            }
            edges[2 * i] = a < b ? a : b;
            edges[2 * i + 1] = a < b ? b : a;
        }
        qsort(edges, (size_t)nedges, 2 * sizeof *edges, cmp_pair);
        for (int64_t i = 0; i < nedges; i++) {
            if (e > 0 && edges[2 * i] == edges[2 * e - 2] && edges[2 * i + 1] == edges[2 * e - 1])
                continue;
            edges[2 * e] = edges[2 * i];
            edges[2 * e + 1] = edges[2 * i + 1];
            e++;
        }
        if (e < nedges)
            es__warn(ctx, "landmarks: %lld repeated edges dropped (%lld distinct)",
                     (long long)(nedges - e), (long long)e);
    }
    if (e > 0) {
        len = es__alloc_array(ctx, e * n, sizeof *len);
        sc = es__alloc_array(ctx, n, sizeof *sc);
        if (!len || !sc) { rc = ES_ENOMEM; goto done; }
        if (!mesh && (rc = es_landmarks_truss_lengths(ctx, lm, e, edges,
                                                      (es_mat){len, e, n, e})) != ES_OK)
            goto done;
    }
    for (int64_t j = 0; e > 0 && j < n; j++) {
        if ((mesh && (rc = es_edge_lengths(ctx, mesh, xyz + 3 * k * j, len + e * j)) != ES_OK) ||
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
    if ((rc = mesh ? es_store_create(ctx, path, mesh, &s)
                   : es_store_create_edges(ctx, path, k, e, edges, &s)) != ES_OK)
        goto done;
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
    es__free(ctx, edges);
    es__free(ctx, len);
    es__free(ctx, sc);
    es__free(ctx, colnames);
    es__free(ctx, labels);
    es__free(ctx, scale_txt);
    return rc;
}

es_status es_landmarks_to_store(es_ctx *ctx, const es_landmarks *lm, int64_t ntri,
                                const int64_t *tri, const char *path)
{
    return to_store(ctx, lm, tri ? ntri : 0, tri, 0, NULL, path);
}

es_status es_landmarks_to_store_edges(es_ctx *ctx, const es_landmarks *lm, int64_t nedges,
                                      const int64_t *edges, const char *path)
{
    if (nedges > 0 && !edges) ES_FAIL(ctx, ES_EINVAL, "landmarks: NULL edge list");
    return to_store(ctx, lm, 0, NULL, edges ? nedges : 0, edges, path);
}
