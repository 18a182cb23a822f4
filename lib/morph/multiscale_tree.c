/* lib/morph/multiscale_tree.c — the patch hierarchy of multi-scale geometry
 * interpolation (Winkler et al. 2010, Sec. 3.3), built once per topology.
 *
 * The whole mesh is the root; a patch is split into m parts by growing
 * regions breadth first over the dual graph from m random seed faces at
 * once (faces the seeds do not reach, in another piece of the patch, start
 * parts of their own); each part is then grown by the faces across its
 * border edges, so neighbouring children overlap along their border and
 * share at least the four vertices of two faces, enough to register them.
 * Splitting stops at leaf_faces faces (Sec. 3.3: "less than m triangles"),
 * or where a split would not make smaller patches. Every inner patch gets
 * the occurrences of its vertices and edges in its children and its
 * blending matrix M^T M (eq. 2), which does not depend on t and is
 * factorized here (Sec. 3.2: "we can factorize it in a pre-processing
 * step"), with one vertex of each connected piece held in place.
 */
#include "morph/morph_pkg.h"

#include <math.h>
#include <stdlib.h>

/* What building needs beyond the nodes: scratch arrays indexed by mesh
 * face, vertex and edge, reset after each use. */
typedef struct builder {
    es_multiscale *ms;
    int64_t nv, nf, ne;
    const int64_t *faces, *fe, *ef;
    int64_t *in_node;     /* F: node stamp (+1) of the patch being split */
    int64_t *part;        /* F: part of each face of that patch */
    int64_t *stamp;       /* F: stamp of the child being grown */
    int64_t *queue;       /* F */
    int64_t *vloc;        /* V: local vertex of the patch at hand, -1 */
    int64_t *eloc;        /* E: local edge of the patch at hand, -1 */
    int64_t stamp_next;
    es_rng rng;
} builder;

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : x > y;
}

/* A new node holding `faces` (taken over), at `level`; its index. */
static es_status add_node(es_multiscale *ms, int64_t *faces, int64_t nf, int64_t level,
                          int64_t *idx)
{
    if (ms->nnode == ms->cap) {
        int64_t cap = ms->cap ? 2 * ms->cap : 64;
        ms_node *nn = es__realloc(ms->ctx, ms->node, (size_t)cap * sizeof *nn);
        if (!nn) {
            es__free(ms->ctx, faces);
            return ES_ENOMEM;
        }
        ms->node = nn;
        ms->cap = cap;
    }
    memset(&ms->node[ms->nnode], 0, sizeof(ms_node));
    ms->node[ms->nnode].faces = faces;
    ms->node[ms->nnode].nf = nf;
    ms->node[ms->nnode].level = level;
    ms->node[ms->nnode].spd = -1;
    *idx = ms->nnode++;
    return ES_OK;
}

/* The vertices and edges of node n's faces, sorted, with local endpoints. */
static es_status node_elements(builder *b, ms_node *n)
{
    es_ctx *ctx = b->ms->ctx;
    const int64_t *edges = es_mesh_edges(b->ms->mesh);
    int64_t nv = 0, ne = 0;
    n->verts = es__alloc_array(ctx, 3 * n->nf, sizeof *n->verts);
    n->edges = es__alloc_array(ctx, 3 * n->nf, sizeof *n->edges);
    if (!n->verts || !n->edges) return ES_ENOMEM;
    for (int64_t i = 0; i < n->nf; i++)
        for (int k = 0; k < 3; k++) {
            int64_t v = b->faces[3 * n->faces[i] + k], e = b->fe[3 * n->faces[i] + k];
            if (b->vloc[v] < 0) b->vloc[v] = 0, n->verts[nv++] = v;
            if (b->eloc[e] < 0) b->eloc[e] = 0, n->edges[ne++] = e;
        }
    qsort(n->verts, (size_t)nv, sizeof *n->verts, cmp_i64);
    qsort(n->edges, (size_t)ne, sizeof *n->edges, cmp_i64);
    n->nv = nv;
    n->ne = ne;
    for (int64_t i = 0; i < nv; i++) b->vloc[n->verts[i]] = i;
    n->eloc = es__alloc_array(ctx, 2 * ne, sizeof *n->eloc);
    n->x = es__alloc_array(ctx, 3 * nv, sizeof *n->x);
    if (!n->eloc || !n->x) return ES_ENOMEM;
    for (int64_t j = 0; j < ne; j++) {
        n->eloc[2 * j] = b->vloc[edges[2 * n->edges[j]]];
        n->eloc[2 * j + 1] = b->vloc[edges[2 * n->edges[j] + 1]];
    }
    for (int64_t i = 0; i < nv; i++) b->vloc[n->verts[i]] = -1;
    for (int64_t j = 0; j < ne; j++) b->eloc[n->edges[j]] = -1;
    return ES_OK;
}

/* The neighbour of face f across its k-th edge, or -1 (boundary). */
static int64_t across(const builder *b, int64_t f, int k)
{
    int64_t e = b->fe[3 * f + k];
    int64_t g = b->ef[2 * e] == f ? b->ef[2 * e + 1] : b->ef[2 * e];
    return g;
}

/* Breadth-first from the faces already queued (qh .. qt), within the patch
 * stamped `tag`, giving each reached face the part of the face it came
 * from. Returns the new queue tail. */
static int64_t grow(builder *b, int64_t tag, int64_t qh, int64_t qt)
{
    while (qh < qt) {
        int64_t f = b->queue[qh++];
        for (int k = 0; k < 3; k++) {
            int64_t g = across(b, f, k);
            if (g >= 0 && b->in_node[g] == tag && b->part[g] < 0) {
                b->part[g] = b->part[f];
                b->queue[qt++] = g;
            }
        }
    }
    return qt;
}

/* The leaf's gluing walk: breadth first over its faces, one piece after
 * the other. */
static es_status leaf_walk(builder *b, ms_node *n, int64_t tag)
{
    int64_t qt = 0, qh = 0, w = 0;
    if (!(n->walk = es__alloc_array(b->ms->ctx, 3 * n->nf, sizeof *n->walk))) return ES_ENOMEM;
    for (int64_t i = 0; i < n->nf; i++) b->part[n->faces[i]] = -1;
    for (int64_t i = 0; i < n->nf; i++) {
        int64_t f0 = n->faces[i];
        if (b->part[f0] >= 0) continue;
        b->part[f0] = 0;
        b->queue[qt++] = f0;
        n->walk[3 * w] = f0, n->walk[3 * w + 1] = -1, n->walk[3 * w + 2] = -1, w++;
        while (qh < qt) {
            int64_t f = b->queue[qh++];
            for (int k = 0; k < 3; k++) {
                int64_t g = across(b, f, k);
                if (g < 0 || b->in_node[g] != tag || b->part[g] >= 0) continue;
                b->part[g] = 0;
                b->queue[qt++] = g;
                n->walk[3 * w] = g, n->walk[3 * w + 1] = b->fe[3 * f + k];
                n->walk[3 * w + 2] = f, w++;
            }
        }
    }
    return ES_OK;
}

/* Split node ni into children (pushed as new nodes), or make it a leaf. */
static es_status split(builder *b, int64_t ni)
{
    es_multiscale *ms = b->ms;
    es_ctx *ctx = ms->ctx;
    int64_t m = ms->opts.patches, nf = ms->node[ni].nf, tag = ni + 1, nparts = 0, qt = 0;
    int64_t *fs = ms->node[ni].faces, *counts = NULL, **cf = NULL, level = ms->node[ni].level;
    int leaf = nf <= ms->opts.leaf_faces;
    es_status rc = ES_OK;
    for (int64_t i = 0; i < nf; i++) b->in_node[fs[i]] = tag, b->part[fs[i]] = -1;
    if (!leaf) {
        /* m distinct random seeds (a partial Fisher-Yates shuffle of a copy) */
        int64_t *pick = es__alloc_array(ctx, nf, sizeof *pick);
        if (!pick) return ES_ENOMEM;
        memcpy(pick, fs, (size_t)nf * sizeof *pick);
        for (int64_t k = 0; k < m; k++) {
            int64_t j = k + (int64_t)es_rng_below(&b->rng, (uint64_t)(nf - k)), f = pick[j];
            pick[j] = pick[k], pick[k] = f;
            b->part[f] = nparts++;
            b->queue[qt++] = f;
        }
        es__free(ctx, pick);
        qt = grow(b, tag, 0, qt);
        for (int64_t i = 0; i < nf; i++)
            if (b->part[fs[i]] < 0) {   /* a piece no seed reached */
                int64_t q0 = qt;
                b->part[fs[i]] = nparts++;
                b->queue[qt++] = fs[i];
                qt = grow(b, tag, q0, qt);
            }
        counts = es__calloc(ctx, (size_t)nparts, sizeof *counts);
        cf = es__calloc(ctx, (size_t)nparts, sizeof *cf);
        if (!counts || !cf) {
            rc = ES_ENOMEM;
            goto done;
        }
        /* each part and the faces across its border edges */
        for (int64_t k = 0; k < nparts && rc == ES_OK; k++) {
            int64_t s = ++b->stamp_next, c = 0;
            if (!(cf[k] = es__alloc_array(ctx, nf, sizeof **cf))) {
                rc = ES_ENOMEM;
                break;
            }
            for (int64_t i = 0; i < nf; i++) {
                int64_t f = fs[i];
                if (b->part[f] != k) continue;
                if (b->stamp[f] != s) b->stamp[f] = s, cf[k][c++] = f;
                for (int q = 0; q < 3; q++) {
                    int64_t g = across(b, f, q);
                    if (g >= 0 && b->in_node[g] == tag && b->stamp[g] != s)
                        b->stamp[g] = s, cf[k][c++] = g;
                }
            }
            counts[k] = c;
            if (c >= nf) leaf = 1;   /* no smaller patch: stop here */
        }
        if (nparts < 2) leaf = 1;
    }
    if (rc == ES_OK && leaf) {
        rc = leaf_walk(b, &ms->node[ni], tag);
    } else if (rc == ES_OK) {
        int64_t *child = es__alloc_array(ctx, nparts, sizeof *child);
        if (!child) rc = ES_ENOMEM;
        for (int64_t k = 0; k < nparts && rc == ES_OK; k++) {
            qsort(cf[k], (size_t)counts[k], sizeof **cf, cmp_i64);
            rc = add_node(ms, cf[k], counts[k], level + 1, &child[k]);
            cf[k] = NULL;
        }
        if (rc == ES_OK) {
            ms->node[ni].child = child;
            ms->node[ni].nchild = nparts;
        } else {
            es__free(ctx, child);
        }
    }
done:
    for (int64_t i = 0; i < nf; i++) b->in_node[fs[i]] = 0;
    for (int64_t k = 0; cf && k < nparts; k++) es__free(ctx, cf[k]);
    es__free(ctx, cf);
    es__free(ctx, counts);
    return rc;
}

/* Occurrences of an inner node's vertices and edges in its children, and
 * its blending matrix. */
static es_status inner_tables(builder *b, int64_t ni)
{
    es_multiscale *ms = b->ms;
    es_ctx *ctx = ms->ctx;
    ms_node *n = &ms->node[ni];
    int64_t nv = n->nv, ne = n->ne, nocc = 0, neocc = 0, nz = 0, *ti = NULL, *tj = NULL;
    int64_t *root = NULL;
    double *tv = NULL;
    es_status rc = ES_OK;
    for (int64_t k = 0; k < n->nchild; k++) {
        nocc += ms->node[n->child[k]].nv;
        neocc += ms->node[n->child[k]].ne;
    }
    n->occ_off = es__calloc(ctx, (size_t)nv + 1, sizeof *n->occ_off);
    n->occ = es__alloc_array(ctx, 2 * nocc, sizeof *n->occ);
    n->eocc_off = es__calloc(ctx, (size_t)ne + 1, sizeof *n->eocc_off);
    n->eocc = es__alloc_array(ctx, 3 * neocc, sizeof *n->eocc);
    n->pin = es__calloc(ctx, (size_t)nv, sizeof *n->pin);
    root = es__alloc_array(ctx, nv, sizeof *root);
    if (!n->occ_off || !n->occ || !n->eocc_off || !n->eocc || !n->pin || !root) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < nv; i++) b->vloc[n->verts[i]] = i;
    for (int64_t j = 0; j < ne; j++) b->eloc[n->edges[j]] = j;
    /* counts, then fill (CSR) */
    for (int64_t k = 0; k < n->nchild; k++) {
        const ms_node *c = &ms->node[n->child[k]];
        for (int64_t i = 0; i < c->nv; i++) n->occ_off[b->vloc[c->verts[i]] + 1]++;
        for (int64_t j = 0; j < c->ne; j++) n->eocc_off[b->eloc[c->edges[j]] + 1]++;
    }
    for (int64_t i = 0; i < nv; i++) n->occ_off[i + 1] += n->occ_off[i];
    for (int64_t j = 0; j < ne; j++) n->eocc_off[j + 1] += n->eocc_off[j];
    {
        int64_t *fill = es__alloc_array(ctx, nv + ne, sizeof *fill);
        if (!fill) {
            rc = ES_ENOMEM;
            goto done;
        }
        memcpy(fill, n->occ_off, (size_t)nv * sizeof *fill);
        memcpy(fill + nv, n->eocc_off, (size_t)ne * sizeof *fill);
        for (int64_t k = 0; k < n->nchild; k++) {
            const ms_node *c = &ms->node[n->child[k]];
            for (int64_t i = 0; i < c->nv; i++) {
                int64_t p = fill[b->vloc[c->verts[i]]]++;
                n->occ[2 * p] = k, n->occ[2 * p + 1] = i;
            }
            for (int64_t j = 0; j < c->ne; j++) {
                int64_t p = fill[nv + b->eloc[c->edges[j]]]++;
                n->eocc[3 * p] = k, n->eocc[3 * p + 1] = c->eloc[2 * j];
                n->eocc[3 * p + 2] = c->eloc[2 * j + 1];
            }
        }
        es__free(ctx, fill);
    }
    for (int64_t i = 0; i < nv; i++) b->vloc[n->verts[i]] = -1;
    for (int64_t j = 0; j < ne; j++) b->eloc[n->edges[j]] = -1;
    /* one held vertex per connected piece (union-find over the edges) */
    for (int64_t i = 0; i < nv; i++) root[i] = i;
    for (int64_t j = 0; j < ne; j++) {
        int64_t a = n->eloc[2 * j], c = n->eloc[2 * j + 1];
        while (root[a] != a) a = root[a] = root[root[a]];
        while (root[c] != c) c = root[c] = root[root[c]];
        if (a != c) root[a > c ? a : c] = a < c ? a : c;
    }
    for (int64_t i = 0; i < nv; i++) {
        int64_t a = i;
        while (root[a] != a) a = root[a];
        if (a == i) n->pin[i] = 1;
    }
    /* M^T M: each edge (a, b) counted once per child holding it */
    ti = es__alloc_array(ctx, 3 * ne + nv, sizeof *ti);
    tj = es__alloc_array(ctx, 3 * ne + nv, sizeof *tj);
    tv = es__alloc_array(ctx, 3 * ne + nv, sizeof *tv);
    if (!ti || !tj || !tv) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t j = 0; j < ne; j++) {
        int64_t a = n->eloc[2 * j], c = n->eloc[2 * j + 1];
        double w = (double)(n->eocc_off[j + 1] - n->eocc_off[j]);
        if (!n->pin[a]) ti[nz] = a, tj[nz] = a, tv[nz++] = w;
        if (!n->pin[c]) ti[nz] = c, tj[nz] = c, tv[nz++] = w;
        if (!n->pin[a] && !n->pin[c]) ti[nz] = a, tj[nz] = c, tv[nz++] = -w;
    }
    for (int64_t i = 0; i < nv; i++)
        if (n->pin[i]) ti[nz] = i, tj[nz] = i, tv[nz++] = 1.0;
    rc = es__spd_add(ms->spd, nv, nz, ti, tj, tv, "multiscale: blending matrix", &n->spd);
done:
    es__free(ctx, root);
    es__free(ctx, ti);
    es__free(ctx, tj);
    es__free(ctx, tv);
    return rc;
}

void es__ms_free_nodes(es_multiscale *ms)
{
    for (int64_t i = 0; i < ms->nnode; i++) {
        ms_node *n = &ms->node[i];
        void *p[] = {n->faces, n->verts, n->edges, n->eloc, n->child, n->walk, n->occ_off,
                     n->occ, n->eocc_off, n->eocc, n->pin, n->x};
        for (size_t k = 0; k < sizeof p / sizeof p[0]; k++) es__free(ms->ctx, p[k]);
    }
    es__free(ms->ctx, ms->node);
    ms->node = NULL;
    ms->nnode = ms->cap = 0;
}

es_status es__ms_build(es_multiscale *ms)
{
    es_ctx *ctx = ms->ctx;
    builder b;
    int64_t *all;
    double t0 = es__seconds(), t1;
    es_status rc = ES_OK;
    memset(&b, 0, sizeof b);
    b.ms = ms;
    b.nv = es_mesh_nverts(ms->mesh);
    b.nf = es_mesh_nfaces(ms->mesh);
    b.ne = es_mesh_nedges(ms->mesh);
    b.faces = es_mesh_faces(ms->mesh);
    b.fe = es_mesh_face_edges(ms->mesh);
    b.ef = es_mesh_edge_faces(ms->mesh);
    es_rng_init(&b.rng, ms->seed);
    b.in_node = es__calloc(ctx, (size_t)b.nf, sizeof *b.in_node);
    b.part = es__alloc_array(ctx, b.nf, sizeof *b.part);
    b.stamp = es__calloc(ctx, (size_t)b.nf, sizeof *b.stamp);
    b.queue = es__alloc_array(ctx, b.nf, sizeof *b.queue);
    b.vloc = es__alloc_array(ctx, b.nv, sizeof *b.vloc);
    b.eloc = es__alloc_array(ctx, b.ne, sizeof *b.eloc);
    all = es__alloc_array(ctx, b.nf, sizeof *all);
    if (!b.in_node || !b.part || !b.stamp || !b.queue || !b.vloc || !b.eloc || !all) {
        es__free(ctx, all);
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t v = 0; v < b.nv; v++) b.vloc[v] = -1;
    for (int64_t e = 0; e < b.ne; e++) b.eloc[e] = -1;
    for (int64_t f = 0; f < b.nf; f++) all[f] = f;
    {
        int64_t root;
        rc = add_node(ms, all, b.nf, 0, &root);
    }
    /* nodes are appended as they are made, so one pass in index order
     * splits every patch after its parent */
    for (int64_t i = 0; rc == ES_OK && i < ms->nnode; i++) {
        if ((rc = node_elements(&b, &ms->node[i])) == ES_OK) rc = split(&b, i);
        if (i % 64 == 0) es__progress(ctx, "multiscale: patches", i + 1, ms->nnode);
    }
    t1 = es__seconds();
    for (int64_t i = 0; rc == ES_OK && i < ms->nnode; i++) {
        ms_node *n = &ms->node[i];
        if (n->level + 1 > ms->info.levels) ms->info.levels = n->level + 1;
        if (n->nchild > ms->maxm) ms->maxm = n->nchild;
        if (n->nv > ms->maxnv) ms->maxnv = n->nv;
        if (!n->nchild) {
            ms->info.leaves++;
            if (n->nf > ms->info.max_leaf) ms->info.max_leaf = n->nf;
            continue;
        }
        rc = inner_tables(&b, i);
        if (i % 64 == 0) es__progress(ctx, "multiscale: factorizations", i + 1, ms->nnode);
    }
    ms->info.nodes = ms->nnode;
    ms->info.t_split = t1 - t0;
    ms->info.t_factor = es__seconds() - t1;
done:
    es__free(ctx, b.in_node);
    es__free(ctx, b.part);
    es__free(ctx, b.stamp);
    es__free(ctx, b.queue);
    es__free(ctx, b.vloc);
    es__free(ctx, b.eloc);
    return rc;
}
