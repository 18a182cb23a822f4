/* lib/morph/shape_space.c — morphing triangular meshes in shape space
 * (Wuhrer, Bose, Shu, O'Rourke and Brunton 2010): edge lengths
 * interpolated linearly, face normals by SLERP, the mesh rebuilt by walking
 * a minimum spanning tree of the dual graph with the averaging algorithm
 * (Sec. 6). See es_morph.h for the choices made where the paper is silent.
 *
 * The walk is fixed per pair of poses and made once: the spanning forest
 * by Kruskal's algorithm over the interior edges sorted by the change of
 * their dihedral (ties by edge id), then a depth-first preorder of its
 * faces from each component's root face. A frame only places faces along
 * that order. Candidates live in one pool per object, each vertex's in a
 * chain in the order they were made, so "the latest candidate of v0" and
 * "all candidates of v1" are a pointer and a walk.
 */
#include "morph/morph_pkg.h"
#include "edgespace/es_geom.h"

#include <math.h>
#include <stdlib.h>

struct es_shape_space {
    es_ctx *ctx;
    const es_mesh *mesh;
    int64_t nv, ne, nf;
    int64_t cap;            /* stored candidates per vertex (opts.cap) */
    double *xa, *xb;        /* 3V each, B aligned to A */
    double *na, *nb;        /* 3F unit normals */
    double *la, *lb;        /* E lengths */
    int64_t *walk;          /* 3 per step: face, edge crossed (-1: a root), face from */
    int64_t nwalk;
    int64_t *root_edge;     /* per root step: the component's first edge, first vertex */
    int64_t ntree, ninterior;
    /* candidate pool of a frame: slots with a position and a weight (how
     * many of the paper's candidates the slot stands for), each vertex's in
     * a chain from oldest to newest; freed slots on a free list */
    double *cpos;           /* 3 per slot */
    double *cw;             /* per slot */
    int64_t *cnext;         /* next slot of the same vertex (or of the free list), -1 */
    int64_t nslot, ccap, cfree;
    int64_t *head, *tail, *count, *stamp;   /* V each: chain, stored slots, last update */
    double *vsum, *vw;      /* 3V, V: weighted sum and weight of all a vertex's candidates */
    double *nt;             /* 3F normals at t */
    int64_t last_stored, last_max;
    double last_paper, last_paper_max;
};

void es_shape_space_opts_init(es_shape_space_opts *o)
{
    o->cap = 32;
}

void es_shape_space_free(es_shape_space *ss)
{
    if (!ss) return;
    void *p[] = {ss->xa, ss->xb, ss->na, ss->nb, ss->la, ss->lb, ss->walk, ss->root_edge,
                 ss->cpos, ss->cw, ss->cnext, ss->head, ss->tail, ss->count, ss->stamp,
                 ss->vsum, ss->vw, ss->nt};
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) es__free(ss->ctx, p[i]);
    es__free(ss->ctx, ss);
}

void es_shape_space_get_info(const es_shape_space *ss, es_shape_space_info *info)
{
    if (!ss || !info) return;
    info->dual_arcs = ss->ninterior;
    info->tree_arcs = ss->ntree;
    info->candidates = ss->last_stored;
    info->max_candidates = ss->last_max;
    info->paper_candidates = ss->last_paper;
    info->paper_max = ss->last_paper_max;
}

typedef struct arc { double w; int64_t e; } arc;

static int cmp_arc(const void *a, const void *b)
{
    const arc *x = a, *y = b;
    if (x->w != y->w) return x->w < y->w ? -1 : 1;
    return x->e < y->e ? -1 : x->e > y->e;
}

static int64_t find(int64_t *p, int64_t a)
{
    while (p[a] != a) a = p[a] = p[p[a]];
    return a;
}

/* The spanning forest and its depth-first walk. */
static es_status build_walk(es_shape_space *ss)
{
    es_ctx *ctx = ss->ctx;
    const es_mesh *m = ss->mesh;
    const int64_t *ef = es_mesh_edge_faces(m), *fe = es_mesh_face_edges(m);
    const int64_t *off = es_mesh_star_offsets(m), *se = es_mesh_star_edges(m);
    int64_t nf = ss->nf, ne = ss->ne, na = 0, *uf = NULL, *tree = NULL, *stack = NULL;
    uint8_t *intree = NULL, *seen = NULL;
    arc *arcs = NULL;
    double *aa = NULL, *ab = NULL;
    es_status rc = ES_OK;
    arcs = es__alloc_array(ctx, ne, sizeof *arcs);
    aa = es__alloc_array(ctx, ne, sizeof *aa);
    ab = es__alloc_array(ctx, ne, sizeof *ab);
    uf = es__alloc_array(ctx, nf, sizeof *uf);
    intree = es__calloc(ctx, (size_t)ne, sizeof *intree);
    seen = es__calloc(ctx, (size_t)nf, sizeof *seen);
    stack = es__alloc_array(ctx, 2 * nf + 2, sizeof *stack);
    ss->walk = es__alloc_array(ctx, 3 * nf, sizeof *ss->walk);
    ss->root_edge = es__alloc_array(ctx, 2 * nf, sizeof *ss->root_edge);
    if (!arcs || !aa || !ab || !uf || !intree || !seen || !stack || !ss->walk || !ss->root_edge) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es_dihedral_angles(ctx, m, ss->xa, aa)) != ES_OK ||
        (rc = es_dihedral_angles(ctx, m, ss->xb, ab)) != ES_OK)
        goto done;
    for (int64_t e = 0; e < ne; e++)
        if (ef[2 * e] >= 0 && ef[2 * e + 1] >= 0)
            arcs[na++] = (arc){fabs(remainder(ab[e] - aa[e], 2 * M_PI)), e};
    ss->ninterior = na;
    qsort(arcs, (size_t)na, sizeof *arcs, cmp_arc);
    for (int64_t f = 0; f < nf; f++) uf[f] = f;
    for (int64_t i = 0; i < na; i++) {
        int64_t e = arcs[i].e, a = find(uf, ef[2 * e]), b = find(uf, ef[2 * e + 1]);
        if (a == b) continue;
        uf[a] = b;
        intree[e] = 1;
        ss->ntree++;
    }
    /* depth first from each component's root face: the face of its first
     * (lowest) vertex's first edge; a component walked leaves no face of it
     * unseen, so later vertices of it are skipped */
    tree = stack;
    for (int64_t v = 0; v < ss->nv; v++) {
        int64_t e0, f0, sp = 0;
        if (off[v + 1] == off[v]) continue;   /* in no face */
        e0 = se[off[v]];
        f0 = ef[2 * e0] >= 0 ? ef[2 * e0] : ef[2 * e0 + 1];
        if (seen[f0]) continue;
        ss->root_edge[2 * ss->nwalk] = e0;
        ss->root_edge[2 * ss->nwalk + 1] = v;
        seen[f0] = 1;
        ss->walk[3 * ss->nwalk] = f0, ss->walk[3 * ss->nwalk + 1] = -1;
        ss->walk[3 * ss->nwalk + 2] = -1, ss->nwalk++;
        tree[sp++] = f0;
        tree[sp++] = 0;   /* next edge slot of f0 to try */
        while (sp > 0) {
            int64_t f = tree[sp - 2], k = tree[sp - 1];
            if (k == 3) {
                sp -= 2;
                continue;
            }
            tree[sp - 1]++;
            int64_t e = fe[3 * f + k], g = ef[2 * e] == f ? ef[2 * e + 1] : ef[2 * e];
            if (g < 0 || !intree[e] || seen[g]) continue;
            seen[g] = 1;
            ss->walk[3 * ss->nwalk] = g, ss->walk[3 * ss->nwalk + 1] = e;
            ss->walk[3 * ss->nwalk + 2] = f, ss->nwalk++;
            tree[sp++] = g;
            tree[sp++] = 0;
        }
    }
done:
    es__free(ctx, arcs);
    es__free(ctx, aa);
    es__free(ctx, ab);
    es__free(ctx, uf);
    es__free(ctx, intree);
    es__free(ctx, seen);
    es__free(ctx, stack);
    return rc;
}

es_status es_shape_space_new(es_ctx *ctx, const es_mesh *mesh, const double *xa,
                             const double *xb, const es_shape_space_opts *opts,
                             es_shape_space **out)
{
    es_shape_space *ss;
    es_shape_space_opts dflt;
    const int64_t *F;
    es_status rc = ES_OK;
    double rms;
    *out = NULL;
    if (!opts) {
        es_shape_space_opts_init(&dflt);
        opts = &dflt;
    }
    if (!mesh || !xa || !xb) ES_FAIL(ctx, ES_EINVAL, "shape space: NULL argument");
    if (es_mesh_nfaces(mesh) < 1) ES_FAIL(ctx, ES_EINVAL, "shape space: mesh without faces");
    if (opts->cap < 2)
        ES_FAIL(ctx, ES_EINVAL, "shape space: cap must be >= 2 (got %lld)", (long long)opts->cap);
    if (!(ss = es__calloc(ctx, 1, sizeof *ss))) return ES_ENOMEM;
    ss->ctx = ctx;
    ss->cap = opts->cap;
    ss->mesh = mesh;
    ss->nv = es_mesh_nverts(mesh);
    ss->ne = es_mesh_nedges(mesh);
    ss->nf = es_mesh_nfaces(mesh);
    F = es_mesh_faces(mesh);
#define ALLOC(p, n) if (!((p) = es__alloc_array(ctx, (n) + 1, sizeof *(p)))) rc = ES_ENOMEM
    ALLOC(ss->xa, 3 * ss->nv);
    ALLOC(ss->xb, 3 * ss->nv);
    ALLOC(ss->na, 3 * ss->nf);
    ALLOC(ss->nb, 3 * ss->nf);
    ALLOC(ss->nt, 3 * ss->nf);
    ALLOC(ss->la, ss->ne);
    ALLOC(ss->lb, ss->ne);
    ALLOC(ss->head, ss->nv);
    ALLOC(ss->tail, ss->nv);
    ALLOC(ss->count, ss->nv);
    ALLOC(ss->stamp, ss->nv);
    ALLOC(ss->vsum, 3 * ss->nv);
    ALLOC(ss->vw, ss->nv);
#undef ALLOC
    if (rc != ES_OK) goto fail;
    for (int64_t i = 0; i < 3 * ss->nv; i++)
        if (!isfinite(xa[i]) || !isfinite(xb[i])) {
            rc = es__fail(ctx, ES_EINVAL, "shape space: vertex %lld is not finite",
                          (long long)(i / 3));
            goto fail;
        }
    memcpy(ss->xa, xa, 3 * (size_t)ss->nv * sizeof *xa);
    memcpy(ss->xb, xb, 3 * (size_t)ss->nv * sizeof *xb);
    /* the best rigid alignment of B to A before anything (Sec. 3, 5) */
    if ((rc = es_embed_align_parts(ctx, ss->nv, ss->xb, ss->xa, NULL,
                                   es_mesh_vertex_component(mesh), &rms)) != ES_OK ||
        (rc = es_edge_lengths(ctx, mesh, ss->xa, ss->la)) != ES_OK ||
        (rc = es_edge_lengths(ctx, mesh, ss->xb, ss->lb)) != ES_OK)
        goto fail;
    for (int64_t f = 0; f < ss->nf; f++) {
        const int64_t *t = F + 3 * f;
        if (es__tri_normal(ss->xa + 3 * t[0], ss->xa + 3 * t[1], ss->xa + 3 * t[2], ss->na + 3 * f) == 0 ||
            es__tri_normal(ss->xb + 3 * t[0], ss->xb + 3 * t[1], ss->xb + 3 * t[2], ss->nb + 3 * f) == 0) {
            rc = es__fail(ctx, ES_EINVAL, "shape space: face %lld is degenerate (no normal) in "
                          "one of the poses", (long long)f);
            goto fail;
        }
    }
    if ((rc = build_walk(ss)) != ES_OK) goto fail;
    *out = ss;
    return ES_OK;
fail:
    es_shape_space_free(ss);
    return rc;
}

/* SLERP of unit vectors u -> v at t; ref: a direction perpendicular-ish to u
 * to turn about when u and v are antipodal. */
static void slerp(const double *u, const double *v, double t, const double *ref, double *out)
{
    double k[3], c = es__v3_dot(u, v), s;
    es__v3_cross(u, v, k);
    s = es__v3_normalize(k);
    if (s < 1e-12) {
        if (c > 0) {
            out[0] = u[0], out[1] = u[1], out[2] = u[2];
            return;
        }
        es__v3_cross(u, ref, k);
        if (es__v3_normalize(k) == 0) {
            double e[3] = {fabs(u[0]) < 0.9, fabs(u[0]) >= 0.9, 0};
            es__v3_cross(u, e, k);
            es__v3_normalize(k);
        }
    }
    es__rotate_axis(u, k, t * atan2(s, c), out);
}

/* A new candidate for vertex v at p, standing for w of the paper's. The
 * vertex's totals take it whole; past `cap` stored slots the vertex's two
 * oldest slots merge into their weighted mean (the newest, which the next
 * face takes as "the latest candidate", stay exact). */
static es_status add_candidate(es_shape_space *ss, int64_t v, const double *p, double w,
                               int64_t clock)
{
    int64_t i;
    if (ss->cfree >= 0) {
        i = ss->cfree;
        ss->cfree = ss->cnext[i];
    } else {
        if (ss->nslot == ss->ccap) {
            int64_t cap = ss->ccap ? 2 * ss->ccap : 4 * ss->nv + 16;
            double *np = es__realloc(ss->ctx, ss->cpos, 3 * (size_t)cap * sizeof *np);
            if (!np) return ES_ENOMEM;
            ss->cpos = np;
            if (!(np = es__realloc(ss->ctx, ss->cw, (size_t)cap * sizeof *np))) return ES_ENOMEM;
            ss->cw = np;
            int64_t *nn = es__realloc(ss->ctx, ss->cnext, (size_t)cap * sizeof *nn);
            if (!nn) return ES_ENOMEM;
            ss->cnext = nn;
            ss->ccap = cap;
        }
        i = ss->nslot++;
    }
    for (int c = 0; c < 3; c++) ss->cpos[3 * i + c] = p[c], ss->vsum[3 * v + c] += w * p[c];
    ss->cw[i] = w;
    ss->vw[v] += w;
    ss->last_paper += w;
    ss->cnext[i] = -1;
    if (ss->head[v] < 0) ss->head[v] = i;
    else ss->cnext[ss->tail[v]] = i;
    ss->tail[v] = i;
    ss->count[v]++;
    ss->stamp[v] = clock;
    if (ss->count[v] > ss->cap) {
        int64_t h = ss->head[v], n = ss->cnext[h];
        double wh = ss->cw[h], wn = ss->cw[n];
        for (int c = 0; c < 3; c++)
            ss->cpos[3 * h + c] = (wh * ss->cpos[3 * h + c] + wn * ss->cpos[3 * n + c]) / (wh + wn);
        ss->cw[h] = wh + wn;
        ss->cnext[h] = ss->cnext[n];
        ss->cnext[n] = ss->cfree;
        ss->cfree = n;
        ss->count[v]--;
    }
    return ES_OK;
}

/* The lengths of face f's sides to its third vertex c from a and from b. */
static void side_lengths(const es_shape_space *ss, const double *len, int64_t f, int64_t a,
                         int64_t b, int64_t c, double *l_ac, double *l_bc)
{
    const int64_t *fe = es_mesh_face_edges(ss->mesh), *ed = es_mesh_edges(ss->mesh);
    for (int k = 0; k < 3; k++) {
        int64_t e = fe[3 * f + k], u = ed[2 * e], w = ed[2 * e + 1];
        if ((u == a && w == c) || (u == c && w == a)) *l_ac = len[e];
        if ((u == b && w == c) || (u == c && w == b)) *l_bc = len[e];
    }
}

static int64_t third(const int64_t *F, int64_t f, int64_t a, int64_t b)
{
    for (int k = 0; k < 3; k++)
        if (F[3 * f + k] != a && F[3 * f + k] != b) return F[3 * f + k];
    return -1;
}

es_status es_shape_space_frame(es_ctx *ctx, es_shape_space *ss, const double *len, double t,
                               double *xyz)
{
    const es_mesh *m;
    const int64_t *F, *ed, *ef;
    double *lt = NULL;
    int64_t clock = 0, nroot = 0;
    es_status rc = ES_OK;
    if (!ss || !xyz) ES_FAIL(ctx, ES_EINVAL, "shape space: NULL argument");
    if (!isfinite(t)) ES_FAIL(ctx, ES_EINVAL, "shape space: t is not finite");
    m = ss->mesh;
    F = es_mesh_faces(m);
    ed = es_mesh_edges(m);
    ef = es_mesh_edge_faces(m);
    if (!len) {
        if (!(lt = es__alloc_array(ctx, ss->ne, sizeof *lt))) return ES_ENOMEM;
        for (int64_t e = 0; e < ss->ne; e++) lt[e] = (1 - t) * ss->la[e] + t * ss->lb[e];
        len = lt;
    }
    for (int64_t e = 0; e < ss->ne; e++)
        if (!(len[e] > 0) || !isfinite(len[e])) {
            rc = es__fail(ctx, ES_EINVAL, "shape space: at t = %.4g edge %lld has length %g "
                          "(outside edge-length space)", t, (long long)e, len[e]);
            goto done;
        }
    for (int64_t f = 0; f < ss->nf; f++) {
        double ref[3];
        es__v3_sub(ss->xa + 3 * F[3 * f + 1], ss->xa + 3 * F[3 * f], ref);
        slerp(ss->na + 3 * f, ss->nb + 3 * f, t, ref, ss->nt + 3 * f);
    }
    ss->nslot = 0;
    ss->cfree = -1;
    ss->last_max = ss->last_stored = 0;
    ss->last_paper = ss->last_paper_max = 0;
    for (int64_t v = 0; v < ss->nv; v++) {
        ss->head[v] = ss->tail[v] = -1, ss->count[v] = ss->stamp[v] = 0;
        ss->vsum[3 * v] = ss->vsum[3 * v + 1] = ss->vsum[3 * v + 2] = ss->vw[v] = 0;
    }
    for (int64_t s = 0; s < ss->nwalk && rc == ES_OK; s++) {
        int64_t f = ss->walk[3 * s], e = ss->walk[3 * s + 1];
        if (e < 0) {
            /* a root: the first vertex v where A and B interpolate linearly,
             * its first edge (v, u) by SLERP, the face's third vertex from
             * its lengths and normal */
            int64_t e0 = ss->root_edge[2 * nroot], v = ss->root_edge[2 * nroot + 1];
            int64_t u = ed[2 * e0] == v ? ed[2 * e0 + 1] : ed[2 * e0], w = third(F, f, v, u);
            double pv[3], pu[3], pw[3], da[3], db[3], d[3], l_vw = 0, l_uw = 0;
            nroot++;
            es__v3_sub(ss->xa + 3 * u, ss->xa + 3 * v, da);
            es__v3_sub(ss->xb + 3 * u, ss->xb + 3 * v, db);
            es__v3_normalize(da);
            es__v3_normalize(db);
            slerp(da, db, t, ss->nt + 3 * f, d);
            for (int c = 0; c < 3; c++) {
                pv[c] = (1 - t) * ss->xa[3 * v + c] + t * ss->xb[3 * v + c];
                pu[c] = pv[c] + len[e0] * d[c];
            }
            side_lengths(ss, len, f, v, u, w, &l_vw, &l_uw);
            /* (v, u, w) counter-clockwise when f holds v -> u */
            if ((ed[2 * e0] == v) == (ef[2 * e0] == f))
                es__apex(pv, pu, ss->nt + 3 * f, len[e0], l_vw, l_uw, pw);
            else
                es__apex(pu, pv, ss->nt + 3 * f, len[e0], l_uw, l_vw, pw);
            if ((rc = add_candidate(ss, v, pv, 1, ++clock)) != ES_OK ||
                (rc = add_candidate(ss, u, pu, 1, ++clock)) != ES_OK ||
                (rc = add_candidate(ss, w, pw, 1, ++clock)) != ES_OK)
                goto done;
            continue;
        }
        {
            int64_t a = ed[2 * e], b = ed[2 * e + 1], c = third(F, f, a, b);
            int64_t v0 = ss->stamp[a] >= ss->stamp[b] ? a : b, v1 = v0 == a ? b : a;
            int64_t nc = ss->count[v1];
            double l_ac = 0, l_bc = 0, p0[3];
            const double *n = ss->nt + 3 * f;
            side_lengths(ss, len, f, a, b, c, &l_ac, &l_bc);
            memcpy(p0, ss->cpos + 3 * ss->tail[v0], sizeof p0);
            /* d2 candidates for c: the latest of v0 with each of v1's (a slot
             * standing for w of them gives one standing for w) */
            for (int64_t i = ss->head[v1], k = 0; k < nc; i = ss->cnext[i], k++) {
                double p1[3], pc[3], wi = ss->cw[i];
                const double *pa = v0 == a ? p0 : p1, *pb = v0 == a ? p1 : p0;
                memcpy(p1, ss->cpos + 3 * i, sizeof p1);
                if (ef[2 * e] == f) es__apex(pa, pb, n, len[e], l_ac, l_bc, pc);
                else es__apex(pb, pa, n, len[e], l_bc, l_ac, pc);
                if ((rc = add_candidate(ss, c, pc, wi, ++clock)) != ES_OK) goto done;
            }
        }
    }
    /* every vertex at the mean of all its candidates */
    for (int64_t v = 0; v < ss->nv; v++) {
        for (int c = 0; c < 3; c++) xyz[3 * v + c] = ss->vw[v] > 0 ? ss->vsum[3 * v + c] / ss->vw[v] : 0;
        if (ss->count[v] > ss->last_max) ss->last_max = ss->count[v];
        if (ss->vw[v] > ss->last_paper_max) ss->last_paper_max = ss->vw[v];
        ss->last_stored += ss->count[v];
    }
done:
    es__free(ctx, lt);
    return rc;
}
