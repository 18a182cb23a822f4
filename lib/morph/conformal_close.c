/* lib/morph/conformal_close.c — an open mesh closed off for the conformal
 * morph, as the paper closes its face ("with the back of the head closed
 * off", edge-length-interpolation Fig. 11): every boundary loop gets one
 * new vertex and a fan of triangles from it to the loop's edges, oriented
 * like the faces beside them. The apex stands over the loop's centroid,
 * along the fan's outward normal (Newell's normal of the loop), as high as
 * the loop's farthest vertex is from the centroid: a cone. A flat fan from
 * the centroid of a non-convex loop (a mouth) has triangles close to
 * degenerate, which the conformal flattening then makes degenerate
 * (measured on the synthetic face: a mouth triangle 1 % from the triangle
 * inequality broke it and the sphere's lengths missed the factors by
 * 40 %; an apex raised by half the mean radius still broke one); with the
 * apex that high no fan corner exceeds about 135 degrees. A face with eye
 * and mouth holes and a neck rim (a sphere with holes) becomes a closed
 * genus-0 mesh; its own vertices keep their indices, the loops' apexes
 * follow them in loop order.
 */
#include "morph/morph_pkg.h"

#include <math.h>

es_status es_conformal_close(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                             es_mesh **closed)
{
    const int64_t *lo, *lv, *F, *ef;
    int64_t nv, nf, nl, nb, *faces = NULL;
    double *x = NULL;
    es_status rc;
    *closed = NULL;
    if (!mesh) ES_FAIL(ctx, ES_EINVAL, "conformal close: NULL mesh");
    if (!xyz) xyz = es_mesh_xyz(mesh);
    if (!xyz) ES_FAIL(ctx, ES_EINVAL, "conformal close: the mesh has no positions");
    nv = es_mesh_nverts(mesh);
    nf = es_mesh_nfaces(mesh);
    F = es_mesh_faces(mesh);
    ef = es_mesh_edge_faces(mesh);
    nl = es_mesh_boundary_loops(mesh, &lo, &lv);
    nb = nl ? lo[nl] : 0;
    faces = es__alloc_array(ctx, 3 * (nf + nb), sizeof *faces);
    x = es__alloc_array(ctx, 3 * (nv + nl), sizeof *x);
    if (!faces || !x) {
        rc = ES_ENOMEM;
        goto done;
    }
    memcpy(faces, F, 3 * (size_t)nf * sizeof *faces);
    memcpy(x, xyz, 3 * (size_t)nv * sizeof *x);
    for (int64_t i = 0; i < nl; i++) {
        int64_t n = lo[i + 1] - lo[i], apex = nv + i;
        double nrm[3] = {0, 0, 0}, r = 0, *g = x + 3 * apex;
        for (int c = 0; c < 3; c++) g[c] = 0;
        for (int64_t k = lo[i]; k < lo[i + 1]; k++)
            for (int c = 0; c < 3; c++) g[c] += xyz[3 * lv[k] + c] / (double)n;
        for (int64_t k = 0; k < n; k++) {
            const double *p = xyz + 3 * lv[lo[i] + k], *q = xyz + 3 * lv[lo[i] + (k + 1) % n];
            double d[3], cr[3];
            es__v3_sub(p, g, d);
            r = fmax(r, sqrt(es__v3_dot(d, d)));
            /* Newell's normal of the loop walked backwards, as the fan walks it */
            es__v3_cross(q, p, cr);
            for (int c = 0; c < 3; c++) nrm[c] += cr[c];
        }
        if (es__v3_normalize(nrm) > 0)
            for (int c = 0; c < 3; c++) g[c] += r * nrm[c];
        for (int64_t k = 0; k < n; k++) {
            int64_t a = lv[lo[i] + k], b = lv[lo[i] + (k + 1) % n], e = es_mesh_find_edge(mesh, a, b);
            /* the face beside edge (a, b) holds a -> b or b -> a; the new one
             * takes the other direction */
            int a_to_b = e >= 0 && (a < b ? ef[2 * e] >= 0 : ef[2 * e + 1] >= 0);
            int64_t *t = faces + 3 * (nf + lo[i] + k);
            t[0] = a_to_b ? b : a, t[1] = a_to_b ? a : b, t[2] = apex;
        }
    }
    rc = es_mesh_new(ctx, nv + nl, nf + nb, faces, x, closed);
done:
    es__free(ctx, faces);
    es__free(ctx, x);
    return rc;
}
