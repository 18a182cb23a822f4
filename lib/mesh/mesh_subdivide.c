/* lib/mesh/mesh_subdivide.c — 1-to-4 midpoint subdivision of a triangle
 * mesh and of shapes on it (es_mesh.h). A topology operation, so it lives
 * with the mesh; the synthetic families (lib/synth) and the scaling
 * benchmarks subdivide through it. */
#include "mesh/mesh_pkg.h"
#include "core/core_private.h"

#include <stdint.h>
#include <string.h>

es_status es_mesh_subdivide(es_ctx *ctx, int64_t nverts, int64_t nfaces, const int64_t *faces,
                            int64_t nshapes, const double *xyz, int64_t *nverts_out,
                            int64_t **faces_out, double **xyz_out)
{
    es_mesh *m = NULL;
    es_status rc;
    int64_t *nf = NULL, nv2, nx;
    double *nx_xyz = NULL;
    *faces_out = NULL;
    *xyz_out = NULL;
    *nverts_out = 0;
    if (nshapes < 0 || (nshapes > 0 && !xyz))
        ES_FAIL(ctx, ES_EINVAL, "subdivide: %lld shapes with %s positions",
                (long long)nshapes, xyz ? "given" : "NULL");
    if ((rc = es_mesh_new(ctx, nverts, nfaces, faces, NULL, &m)) != ES_OK) return rc;
    int64_t ne = es_mesh_nedges(m);
    const int64_t *E = es_mesh_edges(m), *FE = es_mesh_face_edges(m);
    nv2 = nverts + ne;
    if (!es__mul_i64(nv2, 3, &nx) || !es__mul_i64(nx, nshapes, &nx) || nfaces > INT64_MAX / 12) {
        rc = es__fail(ctx, ES_ERANGE, "subdivide: output size overflows");
        goto fail;
    }
    nf = es__alloc_array(ctx, 12 * nfaces > 0 ? 12 * nfaces : 1, sizeof *nf);
    if (!nf) { rc = ES_ENOMEM; goto fail; }
    for (int64_t f = 0; f < nfaces; f++) {
        const int64_t *t = faces + 3 * f;
        int64_t ab = nverts + FE[3 * f], bc = nverts + FE[3 * f + 1];
        int64_t ca = nverts + FE[3 * f + 2];
        int64_t q[12] = {t[0], ab, ca, ab, t[1], bc, ca, bc, t[2], ab, bc, ca};
        memcpy(nf + 12 * f, q, sizeof q);
    }
    if (nshapes > 0) {
        nx_xyz = es__alloc_array(ctx, nx, sizeof *nx_xyz);
        if (!nx_xyz) { rc = ES_ENOMEM; goto fail; }
        for (int64_t s = 0; s < nshapes; s++) {
            const double *in = xyz + 3 * nverts * s;
            double *o = nx_xyz + 3 * nv2 * s;
            memcpy(o, in, (size_t)(3 * nverts) * sizeof *o);
            for (int64_t e = 0; e < ne; e++)
                for (int k = 0; k < 3; k++)
                    o[3 * (nverts + e) + k] =
                        0.5 * (in[3 * E[2 * e] + k] + in[3 * E[2 * e + 1] + k]);
        }
    }
    es_mesh_free(m);
    *nverts_out = nv2;
    *faces_out = nf;
    *xyz_out = nx_xyz;
    return ES_OK;
fail:
    es_mesh_free(m);
    es__free(ctx, nf);
    es__free(ctx, nx_xyz);
    return rc;
}
