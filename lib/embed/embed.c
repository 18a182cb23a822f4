/* lib/embed/embed.c — edge lengths to vertex positions: the embedder object, the
 * sparse stages and the driver (the only file that includes cholmod.h).
 *
 * Stage 1 minimizes the vertex-figure closure energy (eq. 2-3) by
 * Levenberg-Marquardt on the 9 residuals per interior vertex; stage 2 solves
 * the frames G_u = G_v R_vu by least squares (the rows of G are three
 * independent right-hand sides of one connection Laplacian) and projects
 * each onto the nearest rotation; stage 3 solves x_u - x_v = G_v u_v over
 * both directed copies of every edge (a graph Laplacian, factorized once per
 * topology); stage 4 is Levenberg-Marquardt on the relative edge-length
 * residuals in position space (Gauss-Newton matrix plus the curvature of
 * the stretched edges' residuals), which closes what vertex closure leaves
 * open (holonomy around holes and handles, failure A of the oracle README;
 * edges between two boundary vertices, failure B). Every sparse matrix has
 * a pattern fixed by the topology: each is analysed once (CHOLMOD
 * supernodal/simplicial, AMD or METIS) at es_embedder_new and refactorized
 * numerically as values change. References: edge-length-interpolation
 * Section 2; Lipman et al. 2005 (frames); Marquardt 1963; Kabsch 1976.
 */
#include "embed/embed_pkg.h"
#include "edgespace/es_embed.h"
#include "edgespace/es_geom.h"

#include <cholmod.h>
#include <math.h>
#include <stdlib.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

struct es_embedder {
    es_ctx *ctx;
    const es_mesh *mesh;
    int64_t nv, ne, nf, maxk, nint;
    const int64_t *off, *sv, *se, *sf, *edges, *ef;
    const uint8_t *vb, *eb;
    int64_t *slot_corner;   /* 2E: corner of the slot's face at the slot's vertex */
    int64_t *edge_slot;     /* 2E: slot of e in the star of edges[2e], of edges[2e+1] */
    uint8_t *pinned;        /* V: lowest vertex of its component */
    double *vweight;        /* V: 1 for vertices in a face, else 0 */
    int64_t *rank, *nlow;   /* block-pattern bookkeeping (see pos3) */
    /* closure variables */
    int64_t nvar, *var, *amap_off, *amap, *adiag;
    cholmod_common cm;
    int cm_started;
    cholmod_sparse *H3, *H1, *HA;
    cholmod_factor *L3, *L1, *LA;
    cholmod_dense *X, *Y, *Ew, *B3, *B1, *BA;
    /* work, sized once */
    double *ang, *theta, *C, *G, *len, *alpha, *alpha_try, *alpha_keep, *xyz, *xyz_try, *xyz_best;
    double *init_copy;   /* init_xyz when the caller passes the output array itself */
    int64_t progress_total; /* progress steps of the solve running (0: none) */
    double *ltarget, *lpath, *res, *grad, *diag, *pcg, *jw, *fanwork, *fanr, *fanth, *fanal, *vclos, *verr;
    int have_vertex_results;
    int64_t nfactor;        /* numeric factorizations in the last solve */
};

void es_embed_opts_init(es_embed_opts *o)
{
    o->dihedral_mode = ES_EMBED_DIHEDRAL_AUTO;
    o->dihedral_max_iter = 30;
    o->dihedral_rtol = 1e-4;
    o->dihedral_tol = 1e-24;
    o->refine_max_iter = 12;
    o->refine_rtol = 1e-3;
    o->refine_tol = 1e-13;
    o->continuation_steps = 0;
    o->try_both = 0;
    o->align = 1;
    o->bad_face_rtol = 1e-12;
    o->realized_rtol = 1e-2;
    o->verbose = 0;
    o->blas_threads = 1;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CHOLMOD reports through cm->status; translate it here. */
static es_status cm_check(es_embedder *emb, const char *what)
{
    int st = emb->cm.status;
    if (st == CHOLMOD_OK || st == CHOLMOD_NOT_POSDEF || st == CHOLMOD_DSMALL) return ES_OK;
    if (st == CHOLMOD_OUT_OF_MEMORY || st == CHOLMOD_TOO_LARGE)
        ES_FAIL(emb->ctx, ES_ENOMEM, "embed: CHOLMOD out of memory in %s", what);
    ES_FAIL(emb->ctx, ES_ENUMERIC, "embed: CHOLMOD failed in %s (status %d)", what, st);
}

static int factorize(es_embedder *emb, cholmod_sparse *A, cholmod_factor *L);

/* ---- patterns --------------------------------------------------------- */

/* Upper-triangular block pattern of a V x V vertex adjacency (plus the
 * diagonal) with bs x bs blocks. Edges are sorted by (min, max), so walking
 * them in id order lists the lower neighbours of each max vertex in
 * increasing order: rank[e] is the position of min among them. */
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

static inline int64_t pos_off(const cholmod_sparse *A, int bs, const int64_t *rank, int64_t e,
                              int64_t b, int r, int c)
{
    return ((const int64_t *)A->p)[bs * b + c] + bs * rank[e] + r;
}

static inline int64_t pos_diag(const cholmod_sparse *A, int bs, const int64_t *nlow, int64_t v,
                               int r, int c)
{
    return ((const int64_t *)A->p)[bs * v + c] + bs * nlow[v] + r;
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
        if (!emb->HA) return cm_check(emb, "allocate") ? ES_ENOMEM : ES_ENOMEM;
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
        rc = cm_check(emb, "pattern");
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
        rc = cm_check(emb, "analyze");
        if (rc == ES_OK) rc = ES_ENUMERIC;
        goto fail;
    }
    if (emb->nvar > 0) {
        if ((rc = closure_pattern(emb)) != ES_OK) goto fail;
        emb->LA = cholmod_l_analyze(emb->HA, &emb->cm);
        if (!emb->LA) {
            rc = cm_check(emb, "analyze");
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
            if (!emb->pinned[a] && !emb->pinned[b]) x[pos_off(emb->H1, 1, emb->rank, e, b, 0, 0)] = -2.0;
            if (!emb->pinned[a]) x[pos_diag(emb->H1, 1, emb->nlow, a, 0, 0)] += 2.0;
            if (!emb->pinned[b]) x[pos_diag(emb->H1, 1, emb->nlow, b, 0, 0)] += 2.0;
        }
        for (int64_t v = 0; v < emb->nv; v++)
            if (emb->pinned[v] || emb->off[v + 1] == emb->off[v])
                x[pos_diag(emb->H1, 1, emb->nlow, v, 0, 0)] = 1.0;
        if (!factorize(emb, emb->H1, emb->L1) ||
            emb->cm.status != CHOLMOD_OK) {
            rc = cm_check(emb, "factorize (positions)");
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
                    emb->verr};
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

/* Factorize A (pattern of L) and solve A X = B into emb->X. Returns 1 if
 * A is not positive definite (nothing solved), 0 on success, -1 on a
 * CHOLMOD failure (message set). */
/* Numeric factorization. CHOLMOD 3's supernodal code opens OpenMP regions
 * with a thread count fixed at its compile time (4), ignoring
 * OMP_NUM_THREADS; on a machine with fewer free cores the extra threads
 * spin and wait, which doubled the CPU time of a factorization in
 * bench_embed. Dynamic adjustment lets the runtime size each region by the
 * load; the caller's setting is restored. */
static int factorize(es_embedder *emb, cholmod_sparse *A, cholmod_factor *L)
{
    int ok;
#ifdef _OPENMP
    int dyn = omp_get_dynamic();
    omp_set_dynamic(1);
#endif
    ok = cholmod_l_factorize(A, L, &emb->cm);
#ifdef _OPENMP
    omp_set_dynamic(dyn);
#endif
    return ok;
}

static int factor_solve(es_embedder *emb, cholmod_sparse *A, cholmod_factor *L,
                        cholmod_dense *B)
{
    emb->cm.status = CHOLMOD_OK;
    if (!factorize(emb, A, L)) return cm_check(emb, "factorize") ? -1 : 1;
    if (emb->cm.status == CHOLMOD_NOT_POSDEF) return 1;
    if (!cholmod_l_solve2(CHOLMOD_A, L, B, NULL, &emb->X, NULL, &emb->Y, &emb->Ew, &emb->cm))
        return cm_check(emb, "solve") ? -1 : 1;
    return 0;
}

/* y = A x for the symmetric matrix held in its upper triangle (CSC). */
static void sym_matvec(const cholmod_sparse *A, const double *x, double *y)
{
    const int64_t *cp = A->p, *ri = A->i;
    const double *ax = A->x;
    int64_t n = (int64_t)A->ncol;
    for (int64_t i = 0; i < n; i++) y[i] = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t p = cp[j]; p < cp[j + 1]; p++) {
            int64_t i = ri[p];
            y[i] += ax[p] * x[j];
            if (i != j) y[j] += ax[p] * x[i];
        }
}

static double dotn(const double *a, const double *b, int64_t n)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* Solve A d = b (A = emb->H3 with its damped diagonal in place) by
 * conjugate gradients preconditioned with the factor of an earlier A
 * (emb->L3): the Gauss-Newton matrix changes little between iterations,
 * so a lagged factor is a very good preconditioner and one solve costs a
 * small fraction of a factorization. Returns the iterations used, or -1
 * if the relative residual did not reach eta within max_it. */
static int lagged_pcg(es_embedder *emb, const cholmod_sparse *A, cholmod_factor *Lf,
                      cholmod_dense *B, const double *b, double *d, double eta, int max_it)
{
    int64_t n = (int64_t)A->ncol;
    double *r = emb->pcg, *z = r + n, *p = z + n, *q = p + n, rz = 0, bn;
    double *bx = B->x;
    size_t ncol = B->ncol;
    int ret = -1;
    bn = sqrt(dotn(b, b, n));
    for (int64_t i = 0; i < n; i++) {
        d[i] = 0;
        r[i] = b[i];
    }
    if (!(bn > 0)) return 0;
    B->ncol = 1;
    for (int it = 0; it < max_it; it++) {
        memcpy(bx, r, (size_t)n * sizeof *bx);
        if (!cholmod_l_solve2(CHOLMOD_A, Lf, B, NULL, &emb->X, NULL, &emb->Y, &emb->Ew, &emb->cm))
            break;
        memcpy(z, emb->X->x, (size_t)n * sizeof *z);
        if (it == 0) {
            memcpy(p, z, (size_t)n * sizeof *p);
            rz = dotn(r, z, n);
        } else {
            double rz_new = dotn(r, z, n), beta = rz_new / rz;
            rz = rz_new;
            for (int64_t i = 0; i < n; i++) p[i] = z[i] + beta * p[i];
        }
        sym_matvec(A, p, q);
        {
            double pq = dotn(p, q, n), a;
            if (!(pq > 0)) break;
            a = rz / pq;
            for (int64_t i = 0; i < n; i++) {
                d[i] += a * p[i];
                r[i] -= a * q[i];
            }
        }
        if (sqrt(dotn(r, r, n)) <= eta * bn) {
            ret = it + 1;
            break;
        }
    }
    B->ncol = ncol;
    return ret;
}

/* ---- stage 1: dihedrals ---------------------------------------------- */

static double closure_eval(es_embedder *emb, const double *alpha, int with_jac, double *vclos)
{
    double total = 0;
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t o = emb->off[v], k = emb->off[v + 1] - o;
        if (vclos) vclos[v] = 0;
        if (!k || emb->vb[v]) continue;
        for (int64_t j = 0; j < k; j++) emb->fanal[j] = alpha[emb->se[o + j]];
        double ev = es__fan_closure(k, emb->theta + o, emb->fanal, emb->res + 9 * v,
                                    with_jac ? emb->jw + 9 * o : NULL, emb->fanwork);
        if (vclos) vclos[v] = ev;
        total += ev;
    }
    return total;
}

/* *lambda_io carries the damping from one call to the next (start: 1e-3),
 * so that a run split into a trial and the rest follows the same path as
 * one run: restarting the damping sent the oracle's bumpy icosphere into
 * another closure minimum. */
static es_status stage_dihedrals(es_embedder *emb, const es_embed_opts *o, int max_iter,
                                 double *alpha, double *e_out, int64_t *iters, double *lambda_io)
{
    int64_t n = emb->nvar, it = 0;
    double *x = emb->HA ? emb->HA->x : NULL, *g = emb->grad, lambda = *lambda_io, e;
    int have_factor = 0;
    e = closure_eval(emb, alpha, 0, NULL);
    if (n == 0 || max_iter <= 0) {
        *e_out = e;
        return ES_OK;
    }
    while (it < max_iter && e > o->dihedral_tol * (double)(emb->nint + 1)) {
        double e_new = 0;
        int accepted = 0;
        closure_eval(emb, alpha, 1, NULL);
        memset(x, 0, emb->HA->nzmax * sizeof(double));
        for (int64_t a = 0; a < n; a++) g[a] = 0;
        for (int64_t v = 0; v < emb->nv; v++) {
            int64_t o0 = emb->off[v], k = emb->off[v + 1] - o0;
            const double *J = emb->jw + 9 * o0, *r = emb->res + 9 * v;
            const int64_t *m = emb->amap + emb->amap_off[v];
            if (!k || emb->vb[v]) continue;
            for (int64_t i = 0; i < k; i++) {
                double gi = 0;
                for (int q = 0; q < 9; q++) gi += J[9 * i + q] * r[q];
                g[emb->var[emb->se[o0 + i]]] += gi;
                for (int64_t j = i; j < k; j++) {
                    double h = 0;
                    for (int q = 0; q < 9; q++) h += J[9 * i + q] * J[9 * j + q];
                    x[m[i * k + j]] += h;
                }
            }
        }
        /* i == j pairs landed once on the diagonal, other pairs of one
         * vertex once in the upper triangle: x holds the upper part of J^T J.
         * Marquardt damping scales the diagonal; factorize, try, adapt. */
        {
            double *dg = emb->diag, mean = 0;
            for (int64_t a = 0; a < n; a++) {
                dg[a] = x[emb->adiag[a]];
                mean += dg[a];
            }
            mean /= (double)n;
            for (int tries = 0; tries < 12 && !accepted; tries++) {
                double *bx = emb->BA->x;
                int st;
                double *dx = emb->diag + n, *rhs = dx + n;
                int used = -1;
                for (int64_t a = 0; a < n; a++) {
                    x[emb->adiag[a]] = dg[a] + lambda * (dg[a] + 1e-9 * mean) + 1e-300;
                    rhs[a] = -g[a];
                }
                if (have_factor)
                    used = lagged_pcg(emb, emb->HA, emb->LA, emb->BA, rhs, dx,
                                      fmin(1e-2, fmax(1e-12, sqrt(e))), 12);
                if (used < 0) {
                    memcpy(bx, rhs, (size_t)n * sizeof *bx);
                    st = factor_solve(emb, emb->HA, emb->LA, emb->BA);
                    if (st < 0) return ES_ENUMERIC;
                    have_factor = st == 0;
                    emb->nfactor++;
                    if (st == 0) memcpy(dx, emb->X->x, (size_t)n * sizeof *dx);
                } else {
                    st = 0;
                }
                for (int64_t a = 0; a < n; a++) x[emb->adiag[a]] = dg[a];
                if (st == 0) {
                    for (int64_t ed = 0; ed < emb->ne; ed++)
                        emb->alpha_try[ed] =
                            emb->var[ed] >= 0 ? alpha[ed] + dx[emb->var[ed]] : alpha[ed];
                    e_new = closure_eval(emb, emb->alpha_try, 0, NULL);
                    if (isfinite(e_new) && e_new < e) {
                        accepted = 1;
                        memcpy(alpha, emb->alpha_try, (size_t)emb->ne * sizeof *alpha);
                        lambda = fmax(lambda / 3.0, 1e-12);
                        break;
                    }
                }
                lambda *= 8.0;
            }
        }
        it++;
        if (o->verbose)
            es__info(emb->ctx, "embed: dihedrals %lld E %.6g -> %.6g lambda %.3g", (long long)it,
                     e, e_new, lambda);
        if (!accepted) break;
        if (e - e_new < o->dihedral_rtol * e) {
            e = e_new;
            break;
        }
        e = e_new;
    }
    *iters += it;
    *e_out = e;
    *lambda_io = lambda;
    return ES_OK;
}

/* ---- stages 2-3: frames and positions -------------------------------- */

/* Frame with x along the spoke of slot i and z the normal of face f (one
 * of the two fan faces beside the spoke), in the vertex frame. */
static void slot_face_frame(const es_embedder *emb, int64_t v, int64_t i, int64_t f, double *A)
{
    int64_t o = emb->off[v], k = emb->off[v + 1] - o, j = i - o;
    if (emb->sf[i] == f) {
        memcpy(A, emb->C + 9 * i, 9 * sizeof(double));
    } else if (emb->vb[v] && j == k - 1) {
        memcpy(A, emb->C + 9 * i, 9 * sizeof(double));   /* C_{k-1}: z is face k-2's */
    } else {
        int64_t jp = (j + k - 1) % k;
        memcpy(A, emb->C + 9 * (o + jp), 9 * sizeof(double));
        es__mat3_right_z(A, emb->theta[o + jp]);
    }
}

static void compute_fan_frames(es_embedder *emb, const double *alpha)
{
    for (int64_t v = 0; v < emb->nv; v++) {
        int64_t o = emb->off[v], k = emb->off[v + 1] - o;
        if (!k) continue;
        for (int64_t j = 0; j < k; j++) emb->fanal[j] = alpha[emb->se[o + j]];
        es__fan_frames(k, emb->vb[v] ? k - 1 : k, emb->theta + o, emb->fanal, emb->C + 9 * o,
                       NULL);
    }
}

static es_status stage_frames(es_embedder *emb)
{
    double *x = emb->H3->x, *b = emb->B3->x;
    int64_t n3 = 3 * emb->nv;
    int st;
    memset(x, 0, emb->H3->nzmax * sizeof(double));
    memset(b, 0, (size_t)(3 * n3) * sizeof(double));
    for (int64_t e = 0; e < emb->ne; e++) {
        int64_t a = emb->edges[2 * e], c = emb->edges[2 * e + 1];
        int64_t f = emb->ef[2 * e] >= 0 ? emb->ef[2 * e] : emb->ef[2 * e + 1];
        double Aa[9], Ab[9], R[9];
        slot_face_frame(emb, a, emb->edge_slot[2 * e], f, Aa);
        slot_face_frame(emb, c, emb->edge_slot[2 * e + 1], f, Ab);
        /* the same physical frame seen from c has x reversed: Ab D, D = diag(-1,-1,1) */
        for (int r = 0; r < 3; r++) {
            Ab[3 * r] = -Ab[3 * r];
            Ab[3 * r + 1] = -Ab[3 * r + 1];
        }
        es__mat3_mul_bt(Aa, Ab, R);   /* G_c = G_a R */
        if (!emb->pinned[a] && !emb->pinned[c]) {
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++)
                    x[pos_off(emb->H3, 3, emb->rank, e, c, r, q)] = -R[3 * r + q];
        } else if (emb->pinned[a] && !emb->pinned[c]) {
            /* rhs_c += R^T h_a, h_a = e_col */
            for (int col = 0; col < 3; col++)
                for (int r = 0; r < 3; r++) b[3 * c + r + n3 * col] += R[3 * col + r];
        } else if (!emb->pinned[a] && emb->pinned[c]) {
            for (int col = 0; col < 3; col++)
                for (int r = 0; r < 3; r++) b[3 * a + r + n3 * col] += R[3 * r + col];
        }
        for (int r = 0; r < 3; r++) {
            if (!emb->pinned[a]) x[pos_diag(emb->H3, 3, emb->nlow, a, r, r)] += 1.0;
            if (!emb->pinned[c]) x[pos_diag(emb->H3, 3, emb->nlow, c, r, r)] += 1.0;
        }
    }
    for (int64_t v = 0; v < emb->nv; v++)
        if (emb->pinned[v] || emb->off[v + 1] == emb->off[v])
            for (int r = 0; r < 3; r++) {
                x[pos_diag(emb->H3, 3, emb->nlow, v, r, r)] = 1.0;
                b[3 * v + r + n3 * r] = 1.0;
            }
    st = factor_solve(emb, emb->H3, emb->L3, emb->B3);
    if (st < 0) return ES_ENUMERIC;
    if (st > 0) ES_FAIL(emb->ctx, ES_ENUMERIC, "embed: frame system is singular");
    {
        const double *s = emb->X->x;
        for (int64_t v = 0; v < emb->nv; v++) {
            double *G = emb->G + 9 * v;
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++) G[3 * r + q] = s[3 * v + q + n3 * r];
            es__mat3_nearest_rotation(G);
        }
    }
    return ES_OK;
}

static es_status stage_positions(es_embedder *emb, const double *len, double *xyz)
{
    double *b = emb->B1->x;
    int64_t nv = emb->nv;
    int st;
    memset(b, 0, (size_t)(3 * nv) * sizeof(double));
    for (int64_t v = 0; v < nv; v++)
        for (int64_t i = emb->off[v]; i < emb->off[v + 1]; i++) {
            int64_t u = emb->sv[i];
            const double *C = emb->C + 9 * i, *G = emb->G + 9 * v;
            double l = len[emb->se[i]], p[3] = {l * C[0], l * C[3], l * C[6]};
            for (int r = 0; r < 3; r++) {
                double g = G[3 * r] * p[0] + G[3 * r + 1] * p[1] + G[3 * r + 2] * p[2];
                if (!emb->pinned[u]) b[u + nv * r] += g;
                if (!emb->pinned[v]) b[v + nv * r] -= g;
            }
        }
    emb->cm.status = CHOLMOD_OK;
    if (!cholmod_l_solve2(CHOLMOD_A, emb->L1, emb->B1, NULL, &emb->X, NULL, &emb->Y, &emb->Ew,
                          &emb->cm))
        return cm_check(emb, "solve (positions)") ? ES_ENUMERIC : ES_ENUMERIC;
    (void)st;
    {
        const double *s = emb->X->x;
        for (int64_t v = 0; v < nv; v++)
            for (int r = 0; r < 3; r++) xyz[3 * v + r] = s[v + nv * r];
    }
    return ES_OK;
}

/* ---- stage 4: refinement in position space --------------------------- */

static double length_cost(const es_embedder *emb, const double *xyz, const double *L)
{
    double c = 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        const double *a = xyz + 3 * emb->edges[2 * e], *b = xyz + 3 * emb->edges[2 * e + 1];
        double d0 = b[0] - a[0], d1 = b[1] - a[1], d2 = b[2] - a[2];
        double r = (sqrt(d0 * d0 + d1 * d1 + d2 * d2) - L[e]) / L[e];
        c += r * r;
    }
    return c;
}

static es_status stage_refine(es_embedder *emb, const double *L, double *xyz, int max_iter,
                              double rtol, double tol, int verbose, int64_t *iters)
{
    double hist[4] = {0, 0, 0, 0}, c_prev = 0;
    const int pcg_max = 12, pcg_give_up = 2;
    int pcg_fail = 0;
    int64_t nv = emb->nv, n3 = 3 * nv, ne = emb->ne;
    double *x = emb->H3->x, *g = emb->grad, *dg = emb->diag, *step = emb->pcg + 4 * n3;
    double *hd = step + n3, lambda = 1e-4, c, ctol = tol * tol * (double)ne;
    int have_factor = 0;
    c = length_cost(emb, xyz, L);
    for (int it = 0; it < max_iter && c > ctol; it++) {
        double c_new = c, mean = 0, pred, rho = 0;
        int accepted = 0, st, used = -1;
        memset(x, 0, emb->H3->nzmax * sizeof(double));
        memset(g, 0, (size_t)n3 * sizeof(double));
        for (int64_t e = 0; e < ne; e++) {
            int64_t a = emb->edges[2 * e], b = emb->edges[2 * e + 1];
            const double *pa = xyz + 3 * a, *pb = xyz + 3 * b;
            double d[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]}, w[3];
            double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), r;
            if (!(dl > 0)) dl = 1e-300;
            r = (dl - L[e]) / L[e];
            for (int i = 0; i < 3; i++) w[i] = d[i] / (dl * L[e]);
            for (int i = 0; i < 3; i++) {
                g[3 * a + i] -= w[i] * r;
                g[3 * b + i] += w[i] * r;
            }
            /* Gauss-Newton w w^T plus the residual's own curvature
             * r (I - u u^T) / (|d| l), u = d / |d|, where that is positive
             * semi-definite: on stretched edges (r > 0). Gauss-Newton alone
             * sees no curvature across an edge, so on nearly flexible meshes
             * the flexes crawl (linear convergence at a non-zero residual);
             * the stretched-edge term gives them their true stiffness.
             * Compressed edges (r < 0) would make the matrix indefinite and
             * are left out, as in projected Newton methods (the full Hessian
             * stalled at its first iteration on the midpoints of real pairs). */
            {
                double sc = r > 0 ? r / (dl * L[e]) : 0, dd = dl * dl;
                for (int q = 0; q < 3; q++)
                    for (int p = 0; p < 3; p++) {
                        double h = w[p] * w[q] + sc * ((p == q) - d[p] * d[q] / dd);
                        x[pos_off(emb->H3, 3, emb->rank, e, b, p, q)] -= h;
                        if (p <= q) {
                            x[pos_diag(emb->H3, 3, emb->nlow, a, p, q)] += h;
                            x[pos_diag(emb->H3, 3, emb->nlow, b, p, q)] += h;
                        }
                    }
            }
        }
        for (int64_t i = 0; i < n3; i++) {
            dg[i] = x[pos_diag(emb->H3, 3, emb->nlow, i / 3, (int)(i % 3), (int)(i % 3))];
            mean += dg[i];
        }
        mean /= (double)n3;
        for (int tries = 0; tries < 20 && !accepted; tries++) {
            /* forcing term after Eisenstat and Walker (1996): loose while the
             * cost crawls, tight when it falls fast (quadratic phase) */
            double eta = fmin(0.1, fmax(1e-10, c_prev > 0 ? c / c_prev : 0.1));
            for (int64_t i = 0; i < n3; i++) {
                double v = emb->vweight[i / 3] == 0 ? mean : dg[i];
                x[pos_diag(emb->H3, 3, emb->nlow, i / 3, (int)(i % 3), (int)(i % 3))] =
                    (emb->vweight[i / 3] == 0 ? mean : dg[i]) + lambda * (v + 1e-8 * mean) +
                    1e-300;
                hd[i] = -g[i];
            }
            /* a lagged factor helps while the matrix drifts slowly; once it has
             * failed twice in a row (the damping has fallen so far that the
             * near-flexes dominate), every try would pay for a failed PCG run
             * and a factorization, so factorize directly from then on */
            used = -1;
            if (have_factor && pcg_fail < pcg_give_up) {
                used = lagged_pcg(emb, emb->H3, emb->L3, emb->B3, hd, step, eta, pcg_max);
                pcg_fail = used < 0 ? pcg_fail + 1 : 0;
            }
            if (used < 0) {
                memcpy(emb->B3->x, hd, (size_t)n3 * sizeof(double));
                emb->B3->ncol = 1;
                st = factor_solve(emb, emb->H3, emb->L3, emb->B3);
                emb->B3->ncol = 3;
                if (st < 0) return ES_ENUMERIC;
                have_factor = st == 0;
                emb->nfactor++;
                if (st == 0) memcpy(step, emb->X->x, (size_t)n3 * sizeof(double));
            } else {
                st = 0;
            }
            /* restore the undamped diagonal for the model and matvecs */
            for (int64_t i = 0; i < n3; i++)
                x[pos_diag(emb->H3, 3, emb->nlow, i / 3, (int)(i % 3), (int)(i % 3))] =
                    emb->vweight[i / 3] == 0 ? 0 : dg[i];
            if (st == 0) {
                double *xt = emb->xyz_try;
                for (int64_t i = 0; i < n3; i++) xt[i] = xyz[i] + step[i];
                c_new = length_cost(emb, xt, L);
                sym_matvec(emb->H3, step, hd);
                pred = -2.0 * dotn(g, step, n3) - dotn(step, hd, n3);
                rho = pred > 0 ? (c - c_new) / pred : -1;
                if (isfinite(c_new) && c_new < c && rho > 0) {
                    memcpy(xyz, xt, (size_t)n3 * sizeof *xyz);
                    accepted = 1;
                    /* Nielsen's gain-ratio rule (1999) let lambda creep up on
                     * these problems (rho stays small where the residual is
                     * not zero); Marquardt's fixed factors converge faster. */
                    lambda = fmax(lambda / (rho > 0.25 ? 5.0 : 2.0), 1e-12);
                    break;
                }
                /* the step overshot: try it shortened (1/2, 1/4, 1/8) before
                 * raising the damping, since a cost evaluation is far cheaper
                 * than the factorization a new damping needs. Taken only
                 * where the model still predicts the gain well (rho > 0.25),
                 * damping unchanged. On the midpoints of real pairs this
                 * saves most of the first iteration's rejected
                 * factorizations: 0-28 % less refinement time on nine
                 * meshes of 2K-54K vertices, RMS error equal or lower. */
                if (isfinite(pred) && pred > 0) {
                    double gs = dotn(g, step, n3), shs = dotn(step, hd, n3);
                    for (double t = 0.5; t > 0.1 && !accepted; t *= 0.5) {
                        double pt = -2.0 * t * gs - t * t * shs;
                        for (int64_t i = 0; i < n3; i++) xt[i] = xyz[i] + t * step[i];
                        c_new = length_cost(emb, xt, L);
                        rho = pt > 0 ? (c - c_new) / pt : -1;
                        if (isfinite(c_new) && c_new < c && rho > 0.25) {
                            memcpy(xyz, xt, (size_t)n3 * sizeof *xyz);
                            accepted = 1;
                        }
                    }
                    if (accepted) break;
                }
            }
            lambda *= 10.0;
        }
        (*iters)++;
        if (emb->progress_total) {   /* stages 1-3 were steps 1 and 2 */
            int64_t done = 3 + (int64_t)it, total = emb->progress_total;
            es__progress(emb->ctx, "embedding", done < total ? done : total - 1, total);
        }
        if (verbose)
            es__info(emb->ctx, "embed: refine %d cost %.6g -> %.6g lambda %.3g rho %.3g pcg %d",
                     it, c, c_new, lambda, rho, used);
        if (!accepted) break;
        /* relative stopping rule over a window of 3 iterations (oracle README,
         * failure D: an absolute rule stops too early or too late) */
        hist[it % 4] = c_new;
        c_prev = c;
        if (it >= 3 && hist[(it - 3) % 4] - c_new < 3.0 * rtol * c_new) {
            c = c_new;
            break;
        }
        c = c_new;
    }
    return ES_OK;
}

/* ---- driver ------------------------------------------------------------ */

static int all_finite(const double *x, int64_t n)
{
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(x[i])) return 0;
    return 1;
}

static void edge_lengths_of(const es_embedder *emb, const double *xyz, double *len)
{
    for (int64_t e = 0; e < emb->ne; e++) {
        const double *a = xyz + 3 * emb->edges[2 * e], *b = xyz + 3 * emb->edges[2 * e + 1];
        len[e] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                      (a[2] - b[2]) * (a[2] - b[2]));
    }
}

/* Signed bending angles (es_geom.h convention) of positions xyz. */
static void dihedrals_of(const es_embedder *emb, const double *xyz, double *alpha)
{
    const int64_t *F = es_mesh_faces(emb->mesh);
    for (int64_t e = 0; e < emb->ne; e++) {
        int64_t f = emb->ef[2 * e], g = emb->ef[2 * e + 1];
        double n[2][3], t[3], c[3], tl;
        alpha[e] = 0;
        if (f < 0 || g < 0) continue;
        for (int s = 0; s < 2; s++) {
            const int64_t *fc = F + 3 * (s ? g : f);
            const double *p0 = xyz + 3 * fc[0], *p1 = xyz + 3 * fc[1], *p2 = xyz + 3 * fc[2];
            double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
            double w[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
            n[s][0] = u[1] * w[2] - u[2] * w[1];
            n[s][1] = u[2] * w[0] - u[0] * w[2];
            n[s][2] = u[0] * w[1] - u[1] * w[0];
        }
        for (int i = 0; i < 3; i++)
            t[i] = xyz[3 * emb->edges[2 * e + 1] + i] - xyz[3 * emb->edges[2 * e] + i];
        tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        /* atan2 is scale-free in its two arguments: unnormalized normals are
         * fine as long as both arguments share the factor |n_f||n_g|. */
        c[0] = n[1][1] * n[0][2] - n[1][2] * n[0][1];
        c[1] = n[1][2] * n[0][0] - n[1][0] * n[0][2];
        c[2] = n[1][0] * n[0][1] - n[1][1] * n[0][0];
        if (tl > 0)
            alpha[e] = atan2((c[0] * t[0] + c[1] * t[1] + c[2] * t[2]) / tl,
                             n[1][0] * n[0][0] + n[1][1] * n[0][1] + n[1][2] * n[0][2]);
        if (!isfinite(alpha[e])) alpha[e] = 0;
    }
}

typedef struct path_result {
    double max_rel, rms;
    int64_t iters;
} path_result;

static void quick_metrics(const es_embedder *emb, const double *xyz, const double *L,
                          double *rms, double *mx)
{
    double ss = 0, sl = 0, m = 0;
    for (int64_t e = 0; e < emb->ne; e++) {
        const double *a = xyz + 3 * emb->edges[2 * e], *b = xyz + 3 * emb->edges[2 * e + 1];
        double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                        (a[2] - b[2]) * (a[2] - b[2])) - L[e];
        ss += d * d;
        sl += L[e];
        if (!(fabs(d) / L[e] <= m)) m = fabs(d) / L[e];
    }
    *rms = sqrt(ss / (double)emb->ne) / (sl / (double)emb->ne);
    *mx = m;
}

/* Continuation: stage 4 along l(s) = (1 - s) l_init + s l_target from the
 * initial mesh (scaled to the target's sum), which realizes l(0) exactly. */
static es_status run_continuation(es_embedder *emb, const es_embed_opts *o, const double *L,
                                  const double *init_xyz, double *xyz, int64_t *iters)
{
    int64_t n = o->continuation_steps, ne = emb->ne;
    double s0 = 0, s1 = 0, f;
    es_status rc;
    edge_lengths_of(emb, init_xyz, emb->lpath);
    for (int64_t e = 0; e < ne; e++) {
        s0 += emb->lpath[e];
        s1 += L[e];
    }
    f = s0 > 0 ? s1 / s0 : 1.0;
    for (int64_t i = 0; i < 3 * emb->nv; i++) xyz[i] = init_xyz[i] * f;
    for (int64_t e = 0; e < ne; e++) emb->lpath[e] *= f;
    for (int64_t step = 1; step <= n; step++) {
        double s = (double)step / (double)n;
        double *lp = emb->alpha_try;   /* scratch E */
        for (int64_t e = 0; e < ne; e++) lp[e] = (1 - s) * emb->lpath[e] + s * L[e];
        rc = stage_refine(emb, lp, xyz, step == n ? o->refine_max_iter : 4,
                          step == n ? o->refine_rtol : 1e-3, o->refine_tol, o->verbose, iters);
        if (rc != ES_OK) return rc;
        es__progress(emb->ctx, "embed: continuation", step, n);
    }
    return ES_OK;
}

/* Stages 2-3 from dihedrals alpha; falls back to the initial mesh (or the
 * origin) if the result is not finite. Adds to the report's stage times. */
static es_status linear_stages(es_embedder *emb, const double *alpha, const double *L,
                               double *xyz, es_embed_report *rep)
{
    es_status rc;
    double t1 = now_s();
    compute_fan_frames(emb, alpha);
    if ((rc = stage_frames(emb)) != ES_OK) return rc;
    rep->t_frames += now_s() - t1;
    t1 = now_s();
    if ((rc = stage_positions(emb, L, xyz)) != ES_OK) return rc;
    rep->t_positions += now_s() - t1;
    if (!all_finite(xyz, 3 * emb->nv))
        for (int64_t i = 0; i < 3 * emb->nv; i++) xyz[i] = 0;
    return ES_OK;
}

static es_status embed_solve(es_embedder *emb, const double *target, double scale,
                             const double *init_alpha, const double *init_xyz,
                             const es_embed_opts *opts, double *xyz, es_embed_report *report)
{
    es_ctx *ctx;
    es_embed_opts dflt;
    es_embed_report rep;
    const es_embed_opts *o = opts;
    int64_t nv, ne, n3;
    double sum = 0, f, t0 = now_s(), t1, *L, *alpha;
    const double *ref;
    es_status rc;
    int have_dihedral_result = 0;
    if (!emb) return ES_EINVAL;
    ctx = emb->ctx;
    nv = emb->nv;
    ne = emb->ne;
    n3 = 3 * nv;
    memset(&rep, 0, sizeof rep);
    rep.worst_edge = -1;
    if (!o) {
        es_embed_opts_init(&dflt);
        o = &dflt;
    }
    if (!target || !xyz) ES_FAIL(ctx, ES_EINVAL, "embed: NULL target or output");
    if (!init_alpha && !init_xyz)
        ES_FAIL(ctx, ES_EINVAL, "embed: need initial dihedrals or initial positions");
    if (!(isfinite(scale) && scale >= 0))
        ES_FAIL(ctx, ES_EINVAL, "embed: scale %g is not finite and >= 0", scale);
    for (int64_t e = 0; e < ne; e++) {
        if (!(isfinite(target[e]) && target[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "embed: target length of edge %lld (%lld-%lld) is %g, not "
                    "finite and positive", (long long)e, (long long)emb->edges[2 * e],
                    (long long)emb->edges[2 * e + 1], target[e]);
        sum += target[e];
    }
    if (!isfinite(sum)) ES_FAIL(ctx, ES_EINVAL, "embed: target lengths sum to %g", sum);
    if (init_alpha)
        for (int64_t e = 0; e < ne; e++)
            if (!emb->eb[e] && !isfinite(init_alpha[e]))
                ES_FAIL(ctx, ES_EINVAL, "embed: initial dihedral of edge %lld is not finite",
                        (long long)e);
    if (init_xyz)   /* all vertices: those in no face are copied to the output */
        for (int64_t i = 0; i < n3; i++)
            if (!isfinite(init_xyz[i]))
                ES_FAIL(ctx, ES_EINVAL, "embed: initial position of vertex %lld is not finite",
                        (long long)(i / 3));

    L = emb->ltarget;
    alpha = emb->alpha;
    f = scale > 0 ? scale / sum : 1.0;
    for (int64_t e = 0; e < ne; e++) L[e] = target[e] * f;
    rep.scale = scale > 0 ? scale : sum;
    rep.n_bad_faces = es__corner_angles(emb->mesh, L, o->bad_face_rtol, emb->ang);
    for (int64_t i = 0; i < emb->off[nv]; i++)
        emb->theta[i] = emb->slot_corner[i] >= 0 ? emb->ang[emb->slot_corner[i]] : 0.0;
    if (init_alpha) {
        for (int64_t e = 0; e < ne; e++) alpha[e] = emb->eb[e] ? 0.0 : init_alpha[e];
    } else {
        dihedrals_of(emb, init_xyz, alpha);
    }
    rep.closure_before = closure_eval(emb, alpha, 0, NULL);
    emb->have_vertex_results = 0;

    /* dihedral path: stages 1-4. Stage 1 repairs incoherent (noisy)
     * dihedrals but can pull interpolated ones into a wrong closure minimum
     * (oracle README, failure E). In auto mode one LM iteration decides:
     * stage 1 goes on only if that iteration removed 99 % of the closure
     * energy, else its dihedrals are dropped. On noisy dihedrals (0.001-0.1
     * rad, six real meshes) one iteration cuts the energy 300-20000x; on
     * interpolated ones (midpoints of six real pairs) 1.1-36x, and there a
     * finished stage 1 was always worse than none (failure E), and even the
     * one iteration gave no better result after the refinement (cactus
     * midpoints, 5K and 21K vertices: RMS ratio 0.0183 % / 0.0097 % with it,
     * 0.0170 % / 0.0093 % without). So the linear stages run once. */
    if (!(o->continuation_steps > 0 && init_xyz) || o->try_both) {
        double mx;
        int mode = o->dihedral_mode;
        if (emb->nvar == 0 || o->dihedral_max_iter <= 0) mode = ES_EMBED_DIHEDRAL_OFF;
        rep.closure_stage1 = rep.closure_before;
        /* one bar on a terminal: stage 1, stages 2-3, each refinement iteration */
        emb->progress_total = 3 + (o->refine_max_iter > 0 ? o->refine_max_iter : 0);
        es__progress(ctx, "embedding", 0, emb->progress_total);
        if (mode != ES_EMBED_DIHEDRAL_OFF) {
            double lambda1 = 1e-3;
            int first = mode == ES_EMBED_DIHEDRAL_AUTO ? 1 : o->dihedral_max_iter;
            memcpy(emb->alpha_keep, alpha, (size_t)ne * sizeof *alpha);
            t1 = now_s();
            if ((rc = stage_dihedrals(emb, o, first, alpha, &rep.closure_stage1,
                                      &rep.dihedral_iters, &lambda1)) != ES_OK)
                return rc;
            rep.used_stage1 = 1;
            if (mode == ES_EMBED_DIHEDRAL_AUTO) {
                if (!(rep.closure_stage1 < 0.01 * rep.closure_before)) {
                    memcpy(alpha, emb->alpha_keep, (size_t)ne * sizeof *alpha);
                    rep.used_stage1 = 0;
                } else if (first < o->dihedral_max_iter &&
                           (rc = stage_dihedrals(emb, o, o->dihedral_max_iter - first, alpha,
                                                 &rep.closure_stage1, &rep.dihedral_iters,
                                                 &lambda1)) != ES_OK) {
                    return rc;
                }
            }
            rep.t_dihedral = now_s() - t1;
        }
        es__progress(ctx, "embedding", 1, emb->progress_total);
        if ((rc = linear_stages(emb, alpha, L, xyz, &rep)) != ES_OK) return rc;
        es__progress(ctx, "embedding", 2, emb->progress_total);
        quick_metrics(emb, xyz, L, &rep.rms_ratio_linear, &mx);
        t1 = now_s();
        if (o->refine_max_iter > 0 &&
            (rc = stage_refine(emb, L, xyz, o->refine_max_iter, o->refine_rtol, o->refine_tol,
                               o->verbose, &rep.refine_iters)) != ES_OK)
            return rc;
        rep.t_refine = now_s() - t1;
        es__progress(ctx, "embedding", emb->progress_total, emb->progress_total);
        emb->progress_total = 0;
        have_dihedral_result = 1;
    }
    /* continuation path */
    if (o->continuation_steps > 0 && init_xyz) {
        double *cx = have_dihedral_result ? emb->xyz_best : xyz;
        int64_t it = 0;
        t1 = now_s();
        if ((rc = run_continuation(emb, o, L, init_xyz, cx, &it)) != ES_OK) return rc;
        rep.t_refine += now_s() - t1;
        rep.continuation_steps = o->continuation_steps;
        if (have_dihedral_result) {
            double r1, m1, r2, m2;
            quick_metrics(emb, xyz, L, &r1, &m1);
            quick_metrics(emb, cx, L, &r2, &m2);
            if (all_finite(cx, n3) && (m2 < m1 || !all_finite(xyz, n3))) {
                memcpy(xyz, cx, (size_t)n3 * sizeof *xyz);
                rep.used_continuation = 1;
                rep.refine_iters = it;
            }
        } else {
            rep.used_continuation = 1;
            rep.refine_iters = it;
        }
    }
    if (!all_finite(xyz, n3))
        for (int64_t i = 0; i < n3; i++) xyz[i] = init_xyz ? init_xyz[i] * f : 0.0;
    for (int64_t v = 0; v < nv; v++)
        if (emb->vweight[v] == 0) xyz[3 * v] = xyz[3 * v + 1] = xyz[3 * v + 2] = 0;

    /* alignment */
    ref = init_xyz ? init_xyz : es_mesh_xyz(emb->mesh);
    if (o->align && ref) {
        double r;
        if ((rc = es_kabsch_align_parts(ctx, nv, xyz, ref, emb->vweight,
                                        es_mesh_vertex_component(emb->mesh), &r)) != ES_OK)
            return rc;
        for (int64_t v = 0; v < nv; v++)
            if (emb->vweight[v] == 0)
                for (int i = 0; i < 3; i++) xyz[3 * v + i] = ref[3 * v + i];
    }

    /* report */
    if ((rc = es_embed_length_error(ctx, emb->mesh, xyz, L, 0, &rep.rms_ratio, &rep.max_rel,
                                    &rep.p99_rel)) != ES_OK)
        return rc;
    edge_lengths_of(emb, xyz, emb->lpath);
    for (int64_t v = 0; v < nv; v++) emb->verr[v] = 0;
    {
        double mx = -1;
        for (int64_t e = 0; e < ne; e++) {
            double r = fabs(emb->lpath[e] - L[e]) / L[e];
            emb->verr[emb->edges[2 * e]] += r;
            emb->verr[emb->edges[2 * e + 1]] += r;
            if (r > mx) {
                mx = r;
                rep.worst_edge = e;
            }
        }
    }
    for (int64_t v = 0; v < nv; v++) {
        int64_t k = emb->off[v + 1] - emb->off[v];
        if (k) emb->verr[v] /= (double)k;
    }
    dihedrals_of(emb, xyz, emb->alpha_try);
    rep.closure_after = closure_eval(emb, emb->alpha_try, 0, emb->vclos);
    emb->have_vertex_results = 1;
    rep.realized = rep.max_rel <= o->realized_rtol && rep.n_bad_faces == 0;
    rep.t_total = now_s() - t0;
    if (report) *report = rep;
    return ES_OK;
}

/* The BLAS work of an embedding is many small dense blocks (the supernodes
 * of a surface mesh's factor). Threaded OpenBLAS made whole midpoint
 * embeddings 25-33 % slower with 2 threads than with 1 on this project's
 * 2-core machine (9.4K, 13.6K and 54K vertices; OMP_NUM_THREADS=1 too), so
 * the solve runs with opts->blas_threads threads and restores the caller's
 * setting. OpenBLAS's setter is a weak symbol: with another BLAS the
 * setting is left alone. */
#if defined(__GNUC__)
extern void openblas_set_num_threads(int n) __attribute__((weak));
extern int openblas_get_num_threads(void) __attribute__((weak));
#define ES_HAVE_BLAS_THREADS 1
#endif

es_status es_embed_solve(es_ctx *ctx, es_embedder *emb, const double *target, double scale,
                         const double *init_alpha, const double *init_xyz,
                         const es_embed_opts *opts, double *xyz, es_embed_report *report)
{
    es_status rc;
    if (!emb) ES_FAIL(ctx, ES_EINVAL, "embed: no embedder");
    int want = opts ? opts->blas_threads : 1, had = 0;
    /* init_xyz may be the output array (a sequence aligned frame to frame):
     * the solve writes its output before it aligns it to init_xyz, so it
     * must read a copy then */
    if (init_xyz && xyz) {
        uintptr_t a = (uintptr_t)init_xyz, b = (uintptr_t)xyz;
        uintptr_t n = 3 * (uintptr_t)emb->nv * sizeof *xyz;
        if (a < b + n && b < a + n) {
            memcpy(emb->init_copy, init_xyz, (size_t)n);
            init_xyz = emb->init_copy;
        }
    }
#ifdef ES_HAVE_BLAS_THREADS
    if (want > 0 && openblas_set_num_threads && openblas_get_num_threads) {
        had = openblas_get_num_threads();
        if (had != want) openblas_set_num_threads(want);
        else had = 0;
    }
#endif
    rc = embed_solve(emb, target, scale, init_alpha, init_xyz, opts, xyz, report);
    if (emb->progress_total) {   /* failed part way: close the bar */
        es__progress(emb->ctx, "embedding", emb->progress_total, emb->progress_total);
        emb->progress_total = 0;
    }
#ifdef ES_HAVE_BLAS_THREADS
    if (had > 0) openblas_set_num_threads(had);
#endif
    (void)want;
    (void)had;
    /* the embedder works on its own context; the caller's gets the message */
    if (rc != ES_OK && ctx && ctx != emb->ctx) es__fail(ctx, rc, "%s", es_ctx_errmsg(emb->ctx));
    return rc;
}
