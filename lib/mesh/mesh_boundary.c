/* lib/mesh/mesh_boundary.c — boundary loops, connected components, Euler
 * characteristic and genus of a built mesh.
 *
 * On an oriented manifold every boundary vertex has exactly one outgoing
 * boundary half-edge, which is the first spoke of its fan (es_mesh.h), so
 * a loop is followed by jumping to star_verts[star_off[v]]. Components by
 * union-find over the edges (path halving, union by index so that the root
 * is the lowest vertex). Genus per component from chi = 2 - 2g - b.
 */
#include "mesh/mesh_pkg.h"

static int64_t uf_find(int64_t *p, int64_t x)
{
    while (p[x] != x) {
        p[x] = p[p[x]];
        x = p[x];
    }
    return x;
}

static es_status build_loops(es_ctx *ctx, es_mesh *m)
{
    int64_t nv = m->nv, nb = 0, nloops = 0;
    for (int64_t v = 0; v < nv; v++) nb += m->vert_bnd[v];
    uint8_t *seen = es__calloc(ctx, (size_t)(nv > 0 ? nv : 1), 1);
    m->loop_verts = es__alloc_array(ctx, nb > 0 ? nb : 1, sizeof *m->loop_verts);
    m->loop_off = es__alloc_array(ctx, nb + 1, sizeof *m->loop_off);
    if (!seen || !m->loop_verts || !m->loop_off) {
        es__free(ctx, seen);
        return ES_ENOMEM;
    }
    int64_t n = 0;
    m->loop_off[0] = 0;
    for (int64_t v0 = 0; v0 < nv; v0++) {
        if (!m->vert_bnd[v0] || seen[v0]) continue;
        for (int64_t v = v0; !seen[v]; v = m->star_verts[m->star_off[v]]) {
            seen[v] = 1;
            m->loop_verts[n++] = v;
        }
        m->loop_off[++nloops] = n;
    }
    es__free(ctx, seen);
    m->nloops = nloops;
    m->sum.n_boundary_verts = nb;
    m->sum.n_boundary_loops = nloops;
    return ES_OK;
}

static es_status build_components(es_ctx *ctx, es_mesh *m)
{
    int64_t nv = m->nv, ncomp = 0;
    es_status rc = ES_OK;
    int64_t *p = es__alloc_array(ctx, nv > 0 ? nv : 1, sizeof *p);
    m->comp = es__alloc_array(ctx, nv > 0 ? nv : 1, sizeof *m->comp);
    if (!p || !m->comp) { rc = ES_ENOMEM; goto done; }
    for (int64_t v = 0; v < nv; v++) p[v] = v;
    for (int64_t e = 0; e < m->ne; e++) {
        int64_t a = uf_find(p, m->edges[2 * e]), b = uf_find(p, m->edges[2 * e + 1]);
        if (a < b) p[b] = a;
        else if (b < a) p[a] = b;
    }
    /* roots are the lowest vertices, so ids come out ordered by them */
    for (int64_t v = 0; v < nv; v++) {
        if (m->star_off[v + 1] == m->star_off[v]) m->comp[v] = -1;
        else if (uf_find(p, v) == v) m->comp[v] = ncomp++;
        else m->comp[v] = m->comp[uf_find(p, v)];
    }
    m->sum.n_components = ncomp;
done:
    es__free(ctx, p);
    return rc;
}

static es_status compute_genus(es_ctx *ctx, es_mesh *m)
{
    int64_t nc = m->sum.n_components;
    int64_t *chi = es__calloc(ctx, (size_t)(nc > 0 ? nc : 1), 2 * sizeof *chi);
    if (!chi) return ES_ENOMEM;
    int64_t *loops = chi + nc;
    for (int64_t v = 0; v < m->nv; v++)
        if (m->comp[v] >= 0) chi[m->comp[v]]++;
    for (int64_t e = 0; e < m->ne; e++) chi[m->comp[m->edges[2 * e]]]--;
    for (int64_t f = 0; f < m->nf; f++) chi[m->comp[m->faces[3 * f]]]++;
    for (int64_t i = 0; i < m->nloops; i++) loops[m->comp[m->loop_verts[m->loop_off[i]]]]++;
    int64_t genus = 0, euler = 0;
    for (int64_t c = 0; c < nc; c++) {
        int64_t twog = 2 - chi[c] - loops[c];
        euler += chi[c];
        if (genus >= 0) genus = (twog < 0 || twog % 2) ? -1 : genus + twog / 2;
    }
    m->sum.euler = euler;
    m->sum.genus = genus;
    es__free(ctx, chi);
    return ES_OK;
}

es_status es__mesh_build_boundary(es_ctx *ctx, es_mesh *m)
{
    es_status rc;
    m->sum.nverts = m->nv;
    m->sum.nfaces = m->nf;
    m->sum.nedges = m->ne;
    m->sum.n_boundary_edges = 0;
    for (int64_t e = 0; e < m->ne; e++) m->sum.n_boundary_edges += m->edge_bnd[e];
    if ((rc = build_loops(ctx, m)) != ES_OK || (rc = build_components(ctx, m)) != ES_OK ||
        (rc = compute_genus(ctx, m)) != ES_OK)
        return rc;
    return ES_OK;
}
