/* lib/embed/embedder.c — the es_embedder object: what every solve of one
 * topology shares, made once by es_embedder_new and reused.
 *
 * Every sparse matrix of the embedding has a pattern fixed by the topology:
 * the 3 V x 3 V frame and refinement matrix H3 and the V x V position
 * Laplacian H1 (block patterns of the vertex adjacency), and the closure
 * Gauss-Newton matrix HA over the interior dihedrals (stage 1 of
 * edge-length-interpolation Section 2, eq. 2-3). Each is built and
 * analysed here once (lib/sparse: CHOLMOD supernodal/simplicial, AMD or
 * METIS), so a
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
static es__sparse_mat *block_pattern(es_embedder *emb, int bs)
{
    int64_t nv = emb->nv, n = bs * nv, nz = 0;
    es__sparse_mat *A;
    int64_t *cp, *ri;
    for (int64_t v = 0; v < nv; v++)
        for (int c = 0; c < bs; c++) nz += bs * emb->nlow[v] + c + 1;
    A = es__sparse_mat_new(emb->sp, n, nz, 1);
    if (!A) return NULL;
    cp = es__sparse_mat_colptr(A);
    ri = es__sparse_mat_rowind(A);
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
    memset(es__sparse_mat_values(A), 0, (size_t)nz * sizeof(double));
    return A;
}

/* H3's pattern: lower-triangular in the vertex order emb->perm, which is
 * already fill-reducing and postordered, so the factorization takes it in
 * place (natural ordering). Column 3j + c (j = pinv[v]) holds rows 3j + c ..
 * 3j + 2 of v's diagonal block, then the three rows of each neighbour u
 * with pinv[u] > j in increasing pinv[u]. Fills emb->eslot, eswap, vslot.
 * (A vertex block's three columns stay together in every postorder of the
 * block-expanded elimination tree, so the vertex order loses nothing.) */
static es__sparse_mat *perm_block_pattern(es_embedder *emb)
{
    int64_t nv = emb->nv, nz = 0, *cp, *ri, *hi = NULL, *he = NULL;
    const int64_t *pinv = emb->pinv;
    es__sparse_mat *A;
    for (int64_t v = 0; v < nv; v++) {
        int64_t nhi = 0;
        for (int64_t i = emb->off[v]; i < emb->off[v + 1]; i++) nhi += pinv[emb->sv[i]] > pinv[v];
        nz += 6 + 9 * nhi;
    }
    A = es__sparse_mat_new(emb->sp, 3 * nv, nz, 0);
    hi = es__alloc_array(emb->ctx, emb->maxk + 1, sizeof *hi);
    he = es__alloc_array(emb->ctx, emb->maxk + 1, sizeof *he);
    if (!A || !hi || !he) {
        es__sparse_mat_free(emb->sp, &A);
        es__free(emb->ctx, hi);
        es__free(emb->ctx, he);
        return NULL;
    }
    es__advise_huge(es__sparse_mat_values(A), (size_t)nz * sizeof(double));
    cp = es__sparse_mat_colptr(A);
    ri = es__sparse_mat_rowind(A);
    cp[0] = 0;
    for (int64_t j = 0; j < nv; j++) {
        int64_t v = emb->perm[j], n = 0;
        /* v's later neighbours in the order, sorted (stars are short) */
        for (int64_t i = emb->off[v]; i < emb->off[v + 1]; i++) {
            int64_t u = emb->sv[i], k = n++;
            if (pinv[u] <= j) {
                n--;
                continue;
            }
            while (k > 0 && pinv[hi[k - 1]] > pinv[u]) {
                hi[k] = hi[k - 1];
                he[k] = he[k - 1];
                k--;
            }
            hi[k] = u;
            he[k] = emb->se[i];
        }
        for (int c = 0; c < 3; c++) {
            int64_t p = cp[3 * j + c];
            emb->vslot[3 * v + c] = p;
            for (int r = c; r < 3; r++) ri[p++] = 3 * j + r;
            for (int64_t k = 0; k < n; k++) {
                int64_t e = he[k];
                if (c == 0) emb->eswap[e] = emb->edges[2 * e] != v;
                emb->eslot[3 * e + c] = p;
                for (int r = 0; r < 3; r++) ri[p++] = 3 * pinv[hi[k]] + r;
            }
            cp[3 * j + c + 1] = p;
        }
    }
    es__free(emb->ctx, hi);
    es__free(emb->ctx, he);
    memset(es__sparse_mat_values(A), 0, (size_t)nz * sizeof(double));
    return A;
}

void es__h3_permute(const es_embedder *emb, const double *x, double *xp, int ncol)
{
    int64_t n3 = 3 * emb->nv;
    for (int c = 0; c < ncol; c++)
        for (int64_t v = 0; v < emb->nv; v++)
            for (int r = 0; r < 3; r++) xp[c * n3 + 3 * emb->pinv[v] + r] = x[c * n3 + 3 * v + r];
}

void es__h3_unpermute(const es_embedder *emb, const double *xp, double *x, int ncol)
{
    int64_t n3 = 3 * emb->nv;
    for (int c = 0; c < ncol; c++)
        for (int64_t v = 0; v < emb->nv; v++)
            for (int r = 0; r < 3; r++) x[c * n3 + 3 * v + r] = xp[c * n3 + 3 * emb->pinv[v] + r];
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
    emb->HA = es__sparse_mat_new(emb->sp, n, nz, 1);
    emb->amap = es__alloc_array(ctx, emb->amap_off[emb->nv] + 1, sizeof *emb->amap);
    emb->adiag = es__alloc_array(ctx, n + 1, sizeof *emb->adiag);
    if (!emb->HA || !emb->amap || !emb->adiag) {
        es__free(ctx, keys);
        if (!emb->HA) (void)es__solver_check(emb, "allocate");   /* the message; the code stays */
        return ES_ENOMEM;
    }
    cp = es__sparse_mat_colptr(emb->HA);
    ri = es__sparse_mat_rowind(emb->HA);
    for (int64_t j = 0; j <= n; j++) cp[j] = 0;
    for (int64_t i = 0; i < nz; i++) {
        cp[keys[i] / n + 1]++;
        ri[i] = keys[i] % n;
    }
    for (int64_t j = 0; j < n; j++) cp[j + 1] += cp[j];
    es__free(ctx, keys);
    memset(es__sparse_mat_values(emb->HA), 0, (size_t)nz * sizeof(double));
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

/* ---- symbolic analyses -------------------------------------------------- */

/* The fill-reducing order of the vertices is computed on the V x V vertex
 * graph (H1's pattern), not on the 3V x 3V position matrix: the same
 * factor (equal nnz(L) with AMD, 2.55e9 against 2.55e9 flops with nested
 * dissection at 54K vertices) for a third to a half of the analysis time.
 * From 10K vertices METIS orders it (on the face meshes 5-15 % fewer
 * flops per factorization than AMD, which orders smaller meshes in less
 * time than they would gain). The order includes CHOLMOD's postorder of
 * the vertex elimination tree; H3 is then built in that order and analysed
 * as it is (perm_block_pattern). A caller that kept the order of an
 * earlier embedder of the same topology (es_embedder_ordering) passes it
 * back, and the ordering is not computed again.
 *
 * This V x V factor (stage 3's frames, and the local-global matrix of
 * local_global.c, which solves with it every iteration) is simplicial:
 * a surface's vertex graph has small supernodes, too small for the BLAS
 * that a supernodal factor calls on them. Measured with the embedder's
 * orders and amalgamation on subdivided sfm_surrey faces and face-study,
 * one thread (factorization / solve with 3 right-hand sides, ms,
 * supernodal -> simplicial): 3.4K 4.7 / 0.33 -> 1.0 / 0.08; 9.4K
 * 18.8 / 1.31 -> 10.0 / 0.52; 13.6K 31 / 1.33 -> 6.9 / 0.46; 54K
 * 132 / 9.5 -> 57 / 5.0; 216K 456 / 50 -> 472 / 36. The 3V x 3V matrix of
 * the Levenberg-Marquardt stages (build_h3) stays supernodal: its 3 x 3
 * blocks make supernodes the BLAS is fast on (9.4K: 92 ms against 180). */
static es_status analyze_vertex_graph(es_embedder *emb, const int64_t *order)
{
    int64_t nv = emb->nv;
    es__sparse_analysis an = {nv >= 10000 ? ES__SPARSE_ORDER_METIS : ES__SPARSE_ORDER_AMD, NULL,
                              1, 1, 0};
    if (order) {   /* already postordered */
        an.ordering = ES__SPARSE_ORDER_GIVEN;
        an.perm = order;
    }
    emb->L1 = es__sparse_analyze(emb->sp, emb->H1, &an);
    if (!emb->L1) {
        es_status rc = es__solver_check(emb, "analyze");
        return rc != ES_OK ? rc : es__fail(emb->ctx, ES_ENOMEM, "embed: CHOLMOD out of memory "
                                                                "in analyze");
    }
    memcpy(emb->perm, es__sparse_factor_perm(emb->L1), (size_t)nv * sizeof *emb->perm);
    for (int64_t j = 0; j < nv; j++) emb->pinv[emb->perm[j]] = j;
    return ES_OK;
}

static es_status cm_fail(es_embedder *emb, const char *what)
{
    es_status rc = es__solver_check(emb, what);
    return rc != ES_OK ? rc : es__fail(emb->ctx, ES_ENOMEM, "embed: CHOLMOD out of memory in %s",
                                       what);
}

/* H3 (stages 2 and 4): its pattern in the vertex order, its analysis (as
 * it is: the order is the vertex graph's) and the factor's values
 * (allocated now with huge pages: their first touch was ~3x the cost of a
 * later factorization). */
static es_status build_h3(es_embedder *emb)
{
    const es__sparse_analysis an = {ES__SPARSE_ORDER_NATURAL, NULL, 0, 0, 1};
    if (!(emb->H3 = perm_block_pattern(emb))) return cm_fail(emb, "pattern");
    emb->L3 = es__sparse_analyze(emb->sp, emb->H3, &an);
    if (!emb->L3) return cm_fail(emb, "analyze");
    emb->B3 = es__sparse_dense_new(emb->sp, 3 * emb->nv, 3);
    return emb->B3 ? ES_OK : cm_fail(emb, "allocate");
}

/* HA (stage 1): the closure Gauss-Newton pattern and its analysis. */
static es_status build_closure(es_embedder *emb)
{
    const es__sparse_analysis an = {ES__SPARSE_ORDER_DEFAULT, NULL, 1, 0, 0};
    es_status rc;
    if (emb->nvar == 0) return ES_OK;
    if ((rc = closure_pattern(emb)) != ES_OK) return rc;
    emb->LA = es__sparse_analyze(emb->sp, emb->HA, &an);
    if (!emb->LA) return cm_fail(emb, "analyze");
    emb->BA = es__sparse_dense_new(emb->sp, emb->nvar, 1);
    return emb->BA ? ES_OK : cm_fail(emb, "allocate");
}

/* The position Laplacian of stage 3 (both directed copies of every edge,
 * the lowest vertex of each component pinned) depends on the topology
 * only: factorized once, on first use. */
static es_status factor_positions(es_embedder *emb)
{
    double *x = es__sparse_mat_values(emb->H1);
    const int64_t *cp = es__sparse_mat_colptr(emb->H1);
    memset(x, 0, (size_t)es__sparse_mat_nzmax(emb->H1) * sizeof(double));
    for (int64_t e = 0; e < emb->ne; e++) {
        int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1];
        if (!emb->pinned[a] && !emb->pinned[b]) x[es__pos_off(cp, 1, emb->rank, e, b, 0, 0)] = -2.0;
        if (!emb->pinned[a]) x[es__pos_diag(cp, 1, emb->nlow, a, 0, 0)] += 2.0;
        if (!emb->pinned[b]) x[es__pos_diag(cp, 1, emb->nlow, b, 0, 0)] += 2.0;
    }
    for (int64_t v = 0; v < emb->nv; v++)
        if (emb->pinned[v] || emb->off[v + 1] == emb->off[v])
            x[es__pos_diag(cp, 1, emb->nlow, v, 0, 0)] = 1.0;
    es__sparse_clear_status(emb->sp);
    if (!es__sparse_factorize(emb->sp, emb->H1, emb->L1) ||
        es__sparse_status(emb->sp, NULL) != ES__SPARSE_OK) {
        es_status rc = es__solver_check(emb, "factorize (positions)");
        return rc != ES_OK ? rc : es__fail(emb->ctx, ES_ENUMERIC, "embed: position Laplacian is singular");
    }
    emb->B1 = es__sparse_dense_new(emb->sp, emb->nv, 3);
    return emb->B1 ? ES_OK : cm_fail(emb, "allocate");
}

/* What a stage needs, made on its first use: a solve from a prior's
 * positions (local_global.c) needs none of the three, so an embedder that
 * serves only those is made in a fraction of the time. */
es_status es__embedder_need(es_embedder *emb, unsigned what)
{
    es_status rc;
    if ((what & ES__NEED_H3) && !emb->H3 && (rc = build_h3(emb)) != ES_OK) return rc;
    if ((what & ES__NEED_CLOSURE) && emb->nvar > 0 && !emb->HA &&
        (rc = build_closure(emb)) != ES_OK)
        return rc;
    if ((what & ES__NEED_POSITIONS) && !emb->B1 && (rc = factor_positions(emb)) != ES_OK)
        return rc;
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
    ALLOC(emb->pcg, 21 * nv + 4 * ne);
    ALLOC(emb->perm, nv);
    ALLOC(emb->pinv, nv);
    ALLOC(emb->eslot, 3 * ne);
    ALLOC(emb->eswap, ne);
    ALLOC(emb->vslot, 3 * nv);
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
    return es_embedder_new_ordered(ctx, mesh, NULL, out);
}

es_status es_embedder_new_ordered(es_ctx *ctx, const es_mesh *mesh, const int64_t *order,
                                  es_embedder **out)
{
    es_embedder *emb;
    es_status rc;
    const int64_t *comp;
    int64_t *cnt = NULL;
    *out = NULL;
    if (!mesh) ES_FAIL(ctx, ES_EINVAL, "embed: NULL mesh");
    if (es_mesh_nfaces(mesh) <= 0) ES_FAIL(ctx, ES_EINVAL, "embed: mesh has no faces");
    if ((rc = es_embed_check_memory(ctx, mesh, 0, NULL)) != ES_OK) return rc;
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
    {
        /* Relaxed supernodal amalgamation 3x CHOLMOD's default (4, 16, 48
         * / 0.8, 0.1, 0.05): a surface mesh's factor has small supernodes,
         * and merging them into larger dense blocks (a little more fill)
         * lets the BLAS run faster. Midpoints of real pairs, one thread,
         * same results: refinement 21-39 % and whole embeddings 16-30 %
         * faster at 1.9K-54K vertices; twice the default sizes gave about
         * two thirds of that, (16, 64, 192 / 0.2, 0.1) about the same, (32,
         * 128, 256 / 0.3, 0.15) less. The factorizations run with
         * CHOLMOD's OpenMP regions inactive (lib/sparse/sparse.c says
         * why). */
        const es__sparse_opts so = {1, {12, 48, 128}, {0.8, 0.15, 0.08}, 1};
        if ((rc = es__sparse_new(ctx, &so, &emb->sp)) != ES_OK) goto fail;
    }

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

    /* the order is checked before the analysis sees it: a permutation of the
     * vertices (a stale or foreign cache must not reach the analysis) */
    if (order) {
        if (!(cnt = es__calloc(ctx, (size_t)emb->nv + 1, sizeof *cnt))) {
            rc = ES_ENOMEM;
            goto fail;
        }
        for (int64_t j = 0; j < emb->nv; j++) {
            if (order[j] < 0 || order[j] >= emb->nv || cnt[order[j]]++) {
                rc = es__fail(ctx, ES_EINVAL, "embed: the vertex order given is not a "
                              "permutation of the %lld vertices", (long long)emb->nv);
                goto fail;
            }
        }
        es__free(ctx, cnt);
        cnt = NULL;
    }

    /* the vertex graph and its order: once per topology; the other
     * matrices are made on first use (es__embedder_need) */
    emb->H1 = block_pattern(emb, 1);
    if (!emb->H1) {
        rc = es__solver_check(emb, "pattern");
        if (rc == ES_OK) rc = ES_ENOMEM;
        goto fail;
    }
    if ((rc = analyze_vertex_graph(emb, order)) != ES_OK) goto fail;
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
    if (emb->sp) {
        es__sparse_mat_free(emb->sp, &emb->H3);
        es__sparse_mat_free(emb->sp, &emb->H1);
        es__sparse_mat_free(emb->sp, &emb->HA);
        es__sparse_factor_free(emb->sp, &emb->L3);
        es__sparse_factor_free(emb->sp, &emb->L1);
        es__sparse_factor_free(emb->sp, &emb->LA);
        es__sparse_solution_free(emb->sp, &emb->sol);
        es__sparse_dense_free(emb->sp, &emb->B3);
        es__sparse_dense_free(emb->sp, &emb->B1);
        es__sparse_dense_free(emb->sp, &emb->BA);
        es__sparse_mat_free(emb->sp, &emb->A1);
        es__sparse_factor_free(emb->sp, &emb->F1);
        es__sparse_dense_free(emb->sp, &emb->LB);
        es__sparse_solution_free(emb->sp, &emb->lg_sol);
        es__sparse_free(emb->sp);
    }
    void *bufs[] = {emb->slot_corner, emb->edge_slot, emb->pinned, emb->vweight, emb->rank,
                    emb->nlow, emb->var, emb->amap_off, emb->amap, emb->adiag, emb->ang,
                    emb->theta, emb->C, emb->G, emb->len, emb->alpha, emb->alpha_try, emb->alpha_keep, emb->xyz,
                    emb->xyz_try, emb->xyz_best, emb->init_copy, emb->ltarget, emb->lpath,
                    emb->res, emb->grad, emb->diag, emb->pcg,
                    emb->jw, emb->fanwork, emb->fanr, emb->fanth, emb->fanal, emb->vclos,
                    emb->verr, emb->flap, emb->omega, emb->prior_alpha, emb->vdev, emb->band_lo, emb->band_hi,
                    emb->perm, emb->pinv, emb->eslot, emb->eswap, emb->vslot,
                    emb->lg_w, emb->lg_wf, emb->lg_rest, emb->lg_work};
    for (size_t i = 0; i < sizeof bufs / sizeof bufs[0]; i++) es__free(ctx, bufs[i]);
    es__lbfgs_free(ctx, &emb->lg_hist);
    es__free(ctx, emb);
}

const es_mesh *es_embedder_mesh(const es_embedder *emb) { return emb ? emb->mesh : NULL; }

const int64_t *es_embedder_ordering(const es_embedder *emb) { return emb ? emb->perm : NULL; }


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
