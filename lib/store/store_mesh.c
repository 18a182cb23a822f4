/* lib/store/store_mesh.c — the store's topology as an es_mesh, both ways:
 * es_store_create takes the faces, edges and fingerprint of a mesh, and
 * es_store_mesh rebuilds the mesh (with row 0 as reference positions).
 * Kept apart from the HDF5 files so that they depend on raw arrays
 * only. */
#include "core/core_private.h"
#include "edgespace/es_mesh.h"
#include "mesh/mesh_private.h"
#include "core/hash.h"
#include "store/store_pkg.h"

es_status es_store_create(es_ctx *ctx, const char *path, const es_mesh *mesh, es_store **out)
{
    char fp[17];
    *out = NULL;
    if (!mesh) ES_FAIL(ctx, ES_EINVAL, "store: NULL mesh");
    es_mesh_fingerprint(mesh, fp);
    return es__store_create_raw(ctx, path, es_mesh_nverts(mesh), es_mesh_nfaces(mesh),
                                es_mesh_faces(mesh), es_mesh_nedges(mesh), es_mesh_edges(mesh),
                                fp, out);
}

const char *es_topology_kind_name(es_topology_kind kind)
{
    switch (kind) {
    case ES_TOPOLOGY_MESH: return "mesh";
    case ES_TOPOLOGY_TRUSS: return "truss";
    case ES_TOPOLOGY_NONE: return "none";
    }
    return "?";
}

es_status es_store_create_edges(es_ctx *ctx, const char *path, int64_t nverts, int64_t nedges,
                                const int64_t *edges, es_store **out)
{
    char fp[17];
    *out = NULL;
    if (nedges < 0 || (nedges > 0 && !edges))
        ES_FAIL(ctx, ES_EINVAL, "store: bad edge list (%lld edges)", (long long)nedges);
    if (nedges == 0) {
        es_faces_fingerprint(nverts, 0, NULL, fp);
    } else {
        const int64_t head[2] = {nverts, nedges};
        es__fingerprint_i64(head, 2, edges, 2 * nedges, fp);
    }
    return es__store_create_raw(ctx, path, nverts, 0, NULL, nedges, edges, fp, out);
}

es_status es_store_mesh(es_ctx *ctx, es_store *store, es_mesh **out)
{
    int64_t V = es_store_nverts(store), F = es_store_nfaces(store), n3;
    int64_t *faces = NULL;
    double *xyz = NULL;
    es_status rc;
    *out = NULL;
    if (!store) ES_FAIL(ctx, ES_EINVAL, "store: NULL store");
    if (es_store_topology_kind(store) == ES_TOPOLOGY_NONE)
        ES_FAIL(ctx, ES_EINVAL, "store: '%s' has no edges: it holds landmarks only; give "
                "--edges or --triangles at ingest", es_store_path(store));
    if (F == 0)
        ES_FAIL(ctx, ES_EINVAL, "store: '%s' is a truss store (%lld edges between landmarks, "
                "no faces): it has no mesh to embed or check; give --triangles at ingest for "
                "one", es_store_path(store), (long long)es_store_nedges(store));
    /* a command asks for the topology several times (the point's lengths,
     * the embedding, the report): built once, then shared (meshes are
     * immutable); a write since (a new generation or a first row) makes it
     * afresh. Only under the store's own context, which outlives the
     * store's reference. */
    if (store->mesh && (store->mesh_generation != store->generation ||
                        store->mesh_nrows != (store->nrows > 0))) {
        es_mesh_free(store->mesh);
        store->mesh = NULL;
    }
    if (store->mesh && ctx == store->ctx) {
        *out = es__mesh_ref(store->mesh);
        return ES_OK;
    }
    if (!es__mul_i64(F, 3, &n3) || !(faces = es__alloc_array(ctx, n3, sizeof *faces)))
        return ES_ENOMEM;
    if ((rc = es_store_read_faces(ctx, store, faces))) goto done;
    if (es_store_nrows(store) > 0) {
        if (!(xyz = es__alloc_array(ctx, 3 * V, sizeof *xyz))) { rc = ES_ENOMEM; goto done; }
        if ((rc = es_store_read_positions(ctx, store, 0, xyz))) goto done;
    }
    rc = es__mesh_new(ctx, V, F, faces, xyz, 0, out);   /* unused vertices: warned at ingest */
    if (rc == ES_OK && es_mesh_nedges(*out) != es_store_nedges(store)) {
        int64_t ne = es_mesh_nedges(*out);
        es_mesh_free(*out);
        *out = NULL;
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': its faces make %lld edges but it stores "
                      "%lld", es_store_path(store), (long long)ne,
                      (long long)es_store_nedges(store));
    }
    if (rc == ES_OK && ctx == store->ctx) {
        store->mesh = es__mesh_ref(*out);
        store->mesh_generation = store->generation;
        store->mesh_nrows = store->nrows > 0;
    }
done:
    es__free(ctx, faces);
    es__free(ctx, xyz);
    return rc;
}
