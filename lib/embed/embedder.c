/* lib/embed/embedder.c — the es_embedder object: what every solve of one
 * topology shares, made once by es_embedder_new and reused.
 *
 * Every sparse matrix of the embedding has a pattern fixed by the topology:
 * the 3 V x 3 V frame and refinement matrix H3 and the V x V position
 * Laplacian H1 (block patterns of the vertex adjacency), and the closure
 * Gauss-Newton matrix HA over the interior dihedrals (stage 1 of
 * edge-length-interpolation Section 2, eq. 2-3). Each is built and
 * analysed here once (CHOLMOD supernodal/simplicial, AMD or METIS), so a
 * solve only refactorizes numerically; the position Laplacian depends on
 * the topology alone and is factorized here too. The work buffers of all
 * four stages are allocated here once, so a solve allocates nothing.
 */
#include "embed/embed_pkg.h"

#include <stdlib.h>
#include <string.h>

/* Upper-triangular block pattern of a V x V vertex adjacency (plus the
 * diagonal) with bs x bs blocks, laid out as es__pos_off / es__pos_diag
 * read it. Edges are sorted by (min, max), so walking them in id order
 * lists the lower neighbours of each max vertex in increasing order:
 * rank[e] is the position of min among them. */
static cholmod_sparse *block_pattern(es_embedder *emb, int bs)
{
    int64_t nv = emb->nv, n = bs * nv, nz = 0;
    cholmod_sparse *A;
    int64_t *cp, *ri;
    for (int64_t v = 0; v < nv; v++)
        for (int c = 0; c < bs; c++) nz += bs * emb->nlow[v] + c + 1;
    A = cholmod_l_allocate_sparse((size_t)n, (size_t)n, (size_t)nz, 1, 1, 1, CHOLMOD_REAL,
                                  &emb->cm);
    if (!A) return NULL;
    cp = A->p;
    ri = A->i;
    cp[0] = 0;
    for (int64_t v = 0; v < nv; v++)
        for (int c = 0; c < bs; c++) cp[bs * v + c + 1] = cp[bs * v + c] + bs * emb->nlow[v] + c + 1;
    for (int64_t e = 0; e < emb->ne; e++) {
        int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1];
        for (int c = 0; c < bs; c++)
            for (int r = 0; r < bs; r++) ri[cp[bs * b + c] + bs * emb->rank[e] + r] = bs * a + r;
    }
    for (int64_t v = 0; v < nv; v++)
        for (int c = 0; c < bs; c++)
            for (int r = 0; r <= c; r++) ri[cp[bs * v + c] + bs * emb->nlow[v] + r] = bs * v + r;
    memset(A->x, 0, (size_t)nz * sizeof(double));
    return A;
}

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : x > y;
}

/* Pattern of J^T J for the closure residuals: variables (interior edges
 * with an interior end) a, b are coupled when both are spokes of one
 * interior vertex. amap gives, per interior vertex and ordered spoke pair,
 * the value slot. */
static es_status closure_pattern(es_embedder *emb)
{
    es_ctx *ctx = emb->ctx;
    int64_t npair = 0, n = emb->nvar, nz = 0, *keys, *cp, *ri;
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t k = emb->off[v + 1] - emb->off[v];
        if (!emb->vb[v] && k) npair += k * (k + 1) / 2;
    }
    keys = es__alloc_array(ctx, npair + n, sizeof *keys);
    emb->amap_off = es__alloc_array(ctx, emb->nv + 1, sizeof *emb->amap_off);
    if (!keys || !emb->amap_off) {
        es__free(ctx, keys);
        return ES_ENOMEM;
    }
    npair = 0;
    emb->amap_off[0] = 0;
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t k = emb->off[v + 1] - emb->off[v];
        emb->amap_off[v + 1] = emb->amap_off[v] + ((!emb->vb[v] && k) ? k * k : 0);
        if (emb->vb[v] || !k) continue;
        for (int64_t i = 0; i < k; i++)
            for (int64_t j = i; j < k; j++) {
                int64_t a = emb->var[emb->se[emb->off[v] + i]];
                int64_t b = emb->var[emb->se[emb->off[v] + j]];
                int64_t lo = a < b ? a : b, hi = a < b ? b : a;
                keys[npair++] = hi * n + lo;
            }
    }
    for (int64_t a = 0; a < n; a++) keys[npair++] = a * n + a;
    qsort(keys, (size_t)npair, sizeof *keys, cmp_i64);
    for (int64_t i = 0; i < npair; i++)
        if (i == 0 || keys[i] != keys[i - 1]) keys[nz++] = keys[i];
    emb->HA = cholmod_l_allocate_sparse((size_t)n, (size_t)n, (size_t)nz, 1, 1, 1, CHOLMOD_REAL,
                                        &emb->cm);
    emb->amap = es__alloc_array(ctx, emb->amap_off[emb->nv] + 1, sizeof *emb->amap);
    emb->adiag = es__alloc_array(ctx, n + 1, sizeof *emb->adiag);
    if (!emb->HA || !emb->amap || !emb->adiag) {
        es__free(ctx, keys);
        if (!emb->HA) (void)es__cm_check(emb, "allocate");   /* the message; the code stays */
        return ES_ENOMEM;
    }
    cp = emb->HA->p;
    ri = emb->HA->i;
    for (int64_t j = 0; j <= n; j++) cp[j] = 0;
    for (int64_t i = 0; i < nz; i++) {
        cp[keys[i] / n + 1]++;
        ri[i] = keys[i] % n;
    }
    for (int64_t j = 0; j < n; j++) cp[j + 1] += cp[j];
    es__free(ctx, keys);
    memset(emb->HA->x, 0, (size_t)nz * sizeof(double));
    for (int64_t a = 0; a < n; a++) emb->adiag[a] = cp[a + 1] - 1;   /* diag is last (sorted) */
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t k = emb->off[v + 1] - emb->off[v], *m = emb->amap + emb->amap_off[v];
        if (emb->vb[v] || !k) continue;
        for (int64_t i = 0; i < k; i++)
            for (int64_t j = 0; j < k; j++) {
                int64_t a = emb->var[emb->se[emb->off[v] + i]];
                int64_t b = emb->var[emb->se[emb->off[v] + j]];
                int64_t lo = a < b ? a : b, hi = a < b ? b : a;
                int64_t l = cp[hi], h = cp[hi + 1] - 1;
                while (l < h) {
                    int64_t mid = (l + h) / 2;
                    if (ri[mid] < lo) l = mid + 1;
                    else h = mid;
                }
                m[i * k + j] = l;
            }
    }
    return ES_OK;
}

/* ---- construction ----------------------------------------------------- */

static es_status alloc_work(es_embedder *emb)
{
    es_ctx *ctx = emb->ctx;
    int64_t nv = emb->nv, ne = emb->ne, ns = emb->off[nv];
#define ALLOC(p, n) if (!((p) = es__alloc_array(ctx, (n) + 1, sizeof *(p)))) return ES_ENOMEM
    ALLOC(emb->slot_corner, ns);
    ALLOC(emb->edge_slot, 2 * ne);
    ALLOC(emb->pinned, nv);
    ALLOC(emb->vweight, nv);
    ALLOC(emb->rank, ne);
    ALLOC(emb->nlow, nv);
    ALLOC(emb->var, ne);
    ALLOC(emb->ang, 3 * emb->nf);
    ALLOC(emb->theta, ns);
    ALLOC(emb->C, 9 * ns);
    ALLOC(emb->G, 9 * nv);
    ALLOC(emb->len, ne);
    ALLOC(emb->alpha, ne);
    ALLOC(emb->alpha_try, ne);
    ALLOC(emb->alpha_keep, ne);
    ALLOC(emb->xyz, 3 * nv);
    ALLOC(emb->xyz_try, 3 * nv);
    ALLOC(emb->xyz_best, 3 * nv);
    ALLOC(emb->init_copy, 3 * nv);
    ALLOC(emb->ltarget, ne);
    ALLOC(emb->lpath, ne);
    ALLOC(emb->res, 9 * nv + ne);
    ALLOC(emb->grad, 3 * nv + ne);
    ALLOC(emb->diag, 3 * (3 * nv + ne));
    ALLOC(emb->pcg, 18 * nv + 4 * ne);
    ALLOC(emb->jw, 9 * ns);
    ALLOC(emb->fanwork, 18 * (2 * emb->maxk + 2));
    ALLOC(emb->fanr, 9);
    ALLOC(emb->fanth, emb->maxk);
    ALLOC(emb->fanal, emb->maxk);
    ALLOC(emb->vclos, nv);
    ALLOC(emb->verr, nv);
#undef ALLOC
    return ES_OK;
}

es_status es_embedder_new(es_ctx *ctx, const es_mesh *mesh, es_embedder **out)
{
    es_embedder *emb;
    es_status rc;
    const int64_t *comp;
    int64_t *cnt = NULL;
    *out = NULL;
    if (!mesh) ES_FAIL(ctx, ES_EINVAL, "embed: NULL mesh");
    if (es_mesh_nfaces(mesh) <= 0) ES_FAIL(ctx, ES_EINVAL, "embed: mesh has no faces");
    emb = es__calloc(ctx, 1, sizeof *emb);
    if (!emb) return ES_ENOMEM;
    emb->ctx = ctx;
    emb->mesh = mesh;
    emb->nv = es_mesh_nverts(mesh);
    emb->ne = es_mesh_nedges(mesh);
    emb->nf = es_mesh_nfaces(mesh);
    emb->off = es_mesh_star_offsets(mesh);
    emb->sv = es_mesh_star_verts(mesh);
    emb->se = es_mesh_star_edges(mesh);
    emb->sf = es_mesh_star_faces(mesh);
    emb->edges = es_mesh_edges(mesh);
    emb->ef = es_mesh_edge_faces(mesh);
    emb->vb = es_mesh_vertex_on_boundary(mesh);
    emb->eb = es_mesh_edge_on_boundary(mesh);
    comp = es_mesh_vertex_component(mesh);
    for (int64_t v = 0; v < emb->nv; v++)
        if (emb->off[v + 1] - emb->off[v] > emb->maxk) emb->maxk = emb->off[v + 1] - emb->off[v];
    if ((rc = alloc_work(emb)) != ES_OK) goto fail;
    cholmod_l_start(&emb->cm);
    emb->cm_started = 1;
    emb->cm.print = 0;
    emb->cm.error_handler = NULL;
    /* Relaxed supernodal amalgamation 3x CHOLMOD's default (4, 16, 48 /
     * 0.8, 0.1, 0.05): a surface mesh's factor has small supernodes, and
     * merging them into larger dense blocks (a little more fill) lets the
     * BLAS run faster. Midpoints of real pairs, one thread, same results:
     * refinement 21-39 % and whole embeddings 16-30 % faster at 1.9K-54K
     * vertices; twice the default sizes gave about two thirds of that,
     * (16, 64, 192 / 0.2, 0.1) about the same, (32, 128, 256 / 0.3, 0.15)
     * less. */
    emb->cm.nrelax[0] = 12;
    emb->cm.nrelax[1] = 48;
    emb->cm.nrelax[2] = 128;
    emb->cm.zrelax[0] = 0.8;
    emb->cm.zrelax[1] = 0.15;
    emb->cm.zrelax[2] = 0.08;

    /* slots, pins, pattern bookkeeping */
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t k = emb->off[v + 1] - emb->off[v];
        emb->vweight[v] = k ? 1.0 : 0.0;
        if (k && !emb->vb[v]) emb->nint++;
        for (int64_t i = emb->off[v]; i < emb->off[v + 1]; i++) {
            int64_t e = emb->se[i];
            emb->slot_corner[i] = es__slot_corner(mesh, v, i);
            emb->edge_slot[2 * e + (emb->edges[2 * e] == v ? 0 : 1)] = i;
        }
    }
    cnt = es__calloc(ctx, (size_t)emb->nv + 1, sizeof *cnt);
    if (!cnt) {
        rc = ES_ENOMEM;
        goto fail;
    }
    for (int64_t e = 0; e < emb->ne; e++) emb->rank[e] = cnt[emb->edges[2 * e + 1]]++;
    for (int64_t v = 0; v < emb->nv; v++) emb->nlow[v] = cnt[v];
    es__free(ctx, cnt);
    {
        int64_t ncomp = 0;
        for (int64_t v = 0; v < emb->nv; v++)
            if (comp[v] + 1 > ncomp) ncomp = comp[v] + 1;
        cnt = es__calloc(ctx, (size_t)ncomp + 1, sizeof *cnt);
        if (!cnt) {
            rc = ES_ENOMEM;
            goto fail;
        }
        for (int64_t v = 0; v < emb->nv; v++)
            if (comp[v] >= 0 && !cnt[comp[v]]) {
                cnt[comp[v]] = 1;
                emb->pinned[v] = 1;
            }
        es__free(ctx, cnt);
        cnt = NULL;
    }
    emb->nvar = 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1];
        emb->var[e] = (!emb->eb[e] && (!emb->vb[a] || !emb->vb[b])) ? emb->nvar++ : -1;
    }

    /* patterns and symbolic analyses: once per topology */
    emb->H3 = block_pattern(emb, 3);
    emb->H1 = block_pattern(emb, 1);
    if (!emb->H3 || !emb->H1) {
        rc = es__cm_check(emb, "pattern");
        if (rc == ES_OK) rc = ES_ENOMEM;
        goto fail;
    }
    /* The position matrix H3 is factorized once per refinement iteration.
     * On larger meshes, with the supernodes above, CHOLMOD's nested
     * dissection (NESDIS) orders it better than AMD: 11-22 % faster
     * embeddings at 14K-54K vertices, for 0.1-0.35 s more analysis (once
     * per topology); below 10K vertices the analysis costs more than a
     * single embedding gains. H1 and HA keep the default ordering. */
    {
        int nmethods = emb->cm.nmethods, ordering = emb->cm.method[0].ordering;
        if (emb->nv >= 10000) {
            emb->cm.nmethods = 1;
            emb->cm.method[0].ordering = CHOLMOD_NESDIS;
        }
        emb->L3 = cholmod_l_analyze(emb->H3, &emb->cm);
        emb->cm.nmethods = nmethods;
        emb->cm.method[0].ordering = ordering;
    }
    emb->L1 = cholmod_l_analyze(emb->H1, &emb->cm);
    if (!emb->L3 || !emb->L1) {
        rc = es__cm_check(emb, "analyze");
        if (rc == ES_OK) rc = ES_ENUMERIC;
        goto fail;
    }
    if (emb->nvar > 0) {
        if ((rc = closure_pattern(emb)) != ES_OK) goto fail;
        emb->LA = cholmod_l_analyze(emb->HA, &emb->cm);
        if (!emb->LA) {
            rc = es__cm_check(emb, "analyze");
            if (rc == ES_OK) rc = ES_ENUMERIC;
            goto fail;
        }
        emb->BA = cholmod_l_allocate_dense((size_t)emb->nvar, 1, (size_t)emb->nvar, CHOLMOD_REAL,
                                           &emb->cm);
    }
    emb->B3 = cholmod_l_allocate_dense((size_t)(3 * emb->nv), 3, (size_t)(3 * emb->nv),
                                       CHOLMOD_REAL, &emb->cm);
    emb->B1 = cholmod_l_allocate_dense((size_t)emb->nv, 3, (size_t)emb->nv, CHOLMOD_REAL,
                                       &emb->cm);
    if (!emb->B3 || !emb->B1 || (emb->nvar > 0 && !emb->BA)) {
        rc = ES_ENOMEM;
        es__fail(ctx, rc, "embed: CHOLMOD out of memory");
        goto fail;
    }

    /* The position Laplacian (both directed copies of every edge, the
     * lowest vertex of each component pinned) depends on the topology
     * only: factorize it now, once. */
    {
        double *x = emb->H1->x;
        for (int64_t e = 0; e < emb->ne; e++) {
            int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1];
            if (!emb->pinned[a] && !emb->pinned[b]) x[es__pos_off(emb->H1, 1, emb->rank, e, b, 0, 0)] = -2.0;
            if (!emb->pinned[a]) x[es__pos_diag(emb->H1, 1, emb->nlow, a, 0, 0)] += 2.0;
            if (!emb->pinned[b]) x[es__pos_diag(emb->H1, 1, emb->nlow, b, 0, 0)] += 2.0;
        }
        for (int64_t v = 0; v < emb->nv; v++)
            if (emb->pinned[v] || emb->off[v + 1] == emb->off[v])
                x[es__pos_diag(emb->H1, 1, emb->nlow, v, 0, 0)] = 1.0;
        if (!es__factorize(emb, emb->H1, emb->L1) ||
            emb->cm.status != CHOLMOD_OK) {
            rc = es__cm_check(emb, "factorize (positions)");
            if (rc == ES_OK)
                rc = es__fail(ctx, ES_ENUMERIC, "embed: position Laplacian is singular");
            goto fail;
        }
    }
    *out = emb;
    return ES_OK;
fail:
    es__free(ctx, cnt);
    es_embedder_free(emb);
    return rc;
}

void es_embedder_free(es_embedder *emb)
{
    es_ctx *ctx;
    if (!emb) return;
    ctx = emb->ctx;
    if (emb->cm_started) {
        cholmod_l_free_sparse(&emb->H3, &emb->cm);
        cholmod_l_free_sparse(&emb->H1, &emb->cm);
        cholmod_l_free_sparse(&emb->HA, &emb->cm);
        cholmod_l_free_factor(&emb->L3, &emb->cm);
        cholmod_l_free_factor(&emb->L1, &emb->cm);
        cholmod_l_free_factor(&emb->LA, &emb->cm);
        cholmod_l_free_dense(&emb->X, &emb->cm);
        cholmod_l_free_dense(&emb->Y, &emb->cm);
        cholmod_l_free_dense(&emb->Ew, &emb->cm);
        cholmod_l_free_dense(&emb->B3, &emb->cm);
        cholmod_l_free_dense(&emb->B1, &emb->cm);
        cholmod_l_free_dense(&emb->BA, &emb->cm);
        cholmod_l_finish(&emb->cm);
    }
    void *bufs[] = {emb->slot_corner, emb->edge_slot, emb->pinned, emb->vweight, emb->rank,
                    emb->nlow, emb->var, emb->amap_off, emb->amap, emb->adiag, emb->ang,
                    emb->theta, emb->C, emb->G, emb->len, emb->alpha, emb->alpha_try, emb->alpha_keep, emb->xyz,
                    emb->xyz_try, emb->xyz_best, emb->init_copy, emb->ltarget, emb->lpath,
                    emb->res, emb->grad, emb->diag, emb->pcg,
                    emb->jw, emb->fanwork, emb->fanr, emb->fanth, emb->fanal, emb->vclos,
                    emb->verr, emb->flap, emb->omega, emb->prior_alpha, emb->vdev};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++) es__free(ctx, bufs[i]);
    es__free(ctx, emb);
}

const es_mesh *es_embedder_mesh(const es_embedder *emb) { return emb ? emb->mesh : NULL; }


const double *es_embedder_vertex_closure(const es_embedder *emb)
{
    return emb && emb->have_vertex_results ? emb->vclos : NULL;
}

const double *es_embedder_vertex_edge_error(const es_embedder *emb)
{
    return emb && emb->have_vertex_results ? emb->verr : NULL;
}

const double *es_embedder_vertex_deviation(const es_embedder *emb)
{
    return emb && emb->have_deviation ? emb->vdev : NULL;
}
