/* lib/mesh/mesh_stars.c — vertex stars (fans) in CSR, and the check that every
 * vertex's faces form a single fan (manifold vertex).
 *
 * For vertex v, face f with v at corner k holds the half-edge v->f[k+1]
 * and the half-edge f[k+2]->v. The fan order of es_mesh.h (face j is
 * (v, u_j, u_{j+1}) and holds v->u_j) steps from f to the face holding
 * v->f[k+2], i.e. across edge (f[k+2], v). Boundary vertices start at the
 * one corner whose spoke v->f[k+1] has no opposite half-edge; interior
 * vertices are rotated afterwards to start at the smallest neighbour. This
 * is the order the embedding's vertex-figure walk (paper Section 2.1, eq. 1)
 * and the oracle's fans.csv use. O(F) after the edges are built.
 */
#include "mesh/mesh_pkg.h"

/* The face across the edge of half-edge `he` (3f + k), or -1. */
static int64_t twin_face(const es_mesh *m, int64_t he)
{
    int64_t f = he / 3, k = he % 3;
    int64_t a = m->faces[he], b = m->faces[3 * f + (k + 1) % 3];
    int64_t e = m->face_edges[he];
    return m->edge_faces[2 * e + (a < b ? 1 : 0)];
}

static int64_t corner_of(const es_mesh *m, int64_t f, int64_t v)
{
    for (int k = 0; k < 3; k++)
        if (m->faces[3 * f + k] == v) return 3 * f + k;
    return -1;
}

static void rotate_left(int64_t *a, int64_t n, int64_t s, int64_t *tmp)
{
    for (int64_t i = 0; i < n; i++) tmp[i] = a[(i + s) % n];
    memcpy(a, tmp, (size_t)n * sizeof *a);
}

es_status es__mesh_build_stars(es_ctx *ctx, es_mesh *m)
{
    es_status rc = ES_OK;
    int64_t nv = m->nv, nf = m->nf, maxdeg = 0;
    int64_t *coff = es__alloc_array(ctx, nv + 1, sizeof *coff);
    int64_t *corners = es__alloc_array(ctx, 3 * nf > 0 ? 3 * nf : 1, sizeof *corners);
    int64_t *tmp = NULL;
    m->star_off = es__alloc_array(ctx, nv + 1, sizeof *m->star_off);
    if (!coff || !corners || !m->star_off) { rc = ES_ENOMEM; goto done; }

    /* corners of each vertex, CSR */
    memset(coff, 0, (size_t)(nv + 1) * sizeof *coff);
    for (int64_t c = 0; c < 3 * nf; c++) coff[m->faces[c] + 1]++;
    for (int64_t v = 0; v < nv; v++) coff[v + 1] += coff[v];
    m->star_off[0] = 0;
    for (int64_t v = 0; v < nv; v++) {
        int64_t deg = coff[v + 1] - coff[v];
        if (deg > maxdeg) maxdeg = deg;
        m->star_off[v + 1] = m->star_off[v] + deg + (deg > 0 && m->vert_bnd[v] ? 1 : 0);
    }
    {
        int64_t *cursor = es__alloc_array(ctx, nv > 0 ? nv : 1, sizeof *cursor);
        if (!cursor) { rc = ES_ENOMEM; goto done; }
        for (int64_t v = 0; v < nv; v++) cursor[v] = coff[v];
        for (int64_t c = 0; c < 3 * nf; c++) corners[cursor[m->faces[c]]++] = c;
        es__free(ctx, cursor);
    }

    int64_t ns = m->star_off[nv];
    m->star_verts = es__alloc_array(ctx, ns > 0 ? ns : 1, sizeof *m->star_verts);
    m->star_edges = es__alloc_array(ctx, ns > 0 ? ns : 1, sizeof *m->star_edges);
    m->star_faces = es__alloc_array(ctx, ns > 0 ? ns : 1, sizeof *m->star_faces);
    tmp = es__alloc_array(ctx, maxdeg + 2, sizeof *tmp);
    if (!m->star_verts || !m->star_edges || !m->star_faces || !tmp) {
        rc = ES_ENOMEM;
        goto done;
    }

    int64_t nunref = 0;
    for (int64_t v = 0; v < nv; v++) {
        int64_t deg = coff[v + 1] - coff[v], start = -1, nstart = 0;
        int64_t *sv = m->star_verts + m->star_off[v];
        int64_t *se = m->star_edges + m->star_off[v];
        int64_t *sf = m->star_faces + m->star_off[v];
        if (deg == 0) { nunref++; continue; }
        for (int64_t i = coff[v]; i < coff[v + 1]; i++)
            if (twin_face(m, corners[i]) < 0) {
                if (start < 0) start = corners[i];
                nstart++;
            }
        if (nstart > 1)
            goto nonmanifold;
        if (start < 0) start = corners[coff[v]];

        int64_t c = start, j = 0;
        for (;;) {
            int64_t f = c / 3, k = c % 3;
            int64_t cp = 3 * f + (k + 2) % 3; /* half-edge f[k+2] -> v */
            if (j >= deg) goto nonmanifold;
            sv[j] = m->faces[3 * f + (k + 1) % 3];
            se[j] = m->face_edges[c];
            sf[j] = f;
            j++;
            int64_t g = twin_face(m, cp);
            if (g < 0) {
                if (!m->vert_bnd[v] || nstart == 0) goto nonmanifold;
                sv[j] = m->faces[cp];
                se[j] = m->face_edges[cp];
                sf[j] = -1;
                break;
            }
            c = corner_of(m, g, v);
            if (c == start) break;
        }
        if (j != deg) goto nonmanifold;
        if (nstart == 0) {
            /* interior: start at the smallest neighbour (= smallest edge id) */
            int64_t s = 0;
            for (int64_t i = 1; i < deg; i++)
                if (sv[i] < sv[s]) s = i;
            if (s > 0) {
                rotate_left(sv, deg, s, tmp);
                rotate_left(se, deg, s, tmp);
                rotate_left(sf, deg, s, tmp);
            }
        }
        if ((v & 0xffff) == 0) es__progress(ctx, "mesh stars", v, nv);
        continue;
    nonmanifold:
        rc = es__fail(ctx, ES_ETOPOLOGY,
                      "mesh: vertex %lld is non-manifold: its %lld faces do not form a "
                      "single fan",
                      (long long)v, (long long)deg);
        goto done;
    }
    es__progress(ctx, "mesh stars", nv, nv);
    m->sum.n_unreferenced = nunref;
done:
    es__free(ctx, coff);
    es__free(ctx, corners);
    es__free(ctx, tmp);
    return rc;
}
