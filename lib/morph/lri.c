/* lib/morph/lri.c — the shape representation of Gao, Chen, Lai and Xia
 * 2017 (Sec. 3.1, eq. 1): patch-based linear rotation-invariant
 * coordinates after Baran, Vlasic, Grinspun and Popovic 2009, with the
 * mean position and mean rotation removed, and their reconstruction.
 *
 * Encoding a mesh against the base mesh (positions v~, face normals n~):
 *  - per face f the deformation gradient D_f = [v2 - v1, v3 - v1, n_f]
 *    [v~2 - v~1, v~3 - v~1, n~_f]^-1 split by the polar decomposition
 *    D_f = R_f S_f (the rotation is the nearest one, S = R^T D made
 *    symmetric): S_f's six entries;
 *  - the faces in patches (below); G_i the mean rotation of patch i's
 *    faces (their sum's nearest rotation); per pair of adjacent patches
 *    log(G_i^T G_j), per face log(G_p(f)^T R_f) (axis times angle).
 * The coordinates x = [S_f, log(G_i^T G_j), log(G_p(f)^T R_f)] hold no
 * rotation or position of the whole: a rigid motion of the mesh leaves
 * them as they are (to rounding). The paper weights the parts equally.
 * Decoding (the paper: "two linear systems, the first to reconstruct the
 * rigid rotation of each face and the second to recover the coordinate of
 * shape vertices"):
 *  1. patch rotations: least squares on G_i C_ij = G_j over adjacent
 *     pairs, C_ij = exp of the coordinate, the first patch of every
 *     connected part held at I (a sparse SPD system of 3 unknowns per
 *     patch, three right-hand sides), each G then its nearest rotation;
 *  2. R_f = G_p(f) exp(log(G^T R_f)), D_f = R_f S_f;
 *  3. positions: least squares on v_b - v_a = D_f (v~_b - v~_a) over the
 *     three sides of every face (deformation-transfer style; its matrix, a
 *     graph Laplacian with one vertex per connected part held, depends on
 *     the topology only and is factorized once).
 * Patches: the paper uses [WPP07]'s partition into 2000 patches (Sec.
 * 3.1); here a deterministic farthest-point partition of the dual graph:
 * seed faces chosen one by one as the face farthest (in dual-graph hops)
 * from those chosen, face 0 first, every face in the patch of its nearest
 * seed (ties to the earlier seed).
 */
#include "morph/morph_pkg.h"

#include <math.h>
#include <stdlib.h>

struct es_lri {
    es_ctx *ctx;
    const es_mesh *mesh;
    int64_t nv, nf, np, na;     /* vertices, faces, patches, adjacent patch pairs */
    int64_t *patch;             /* F: patch of each face */
    int64_t *pair;              /* 2 na: adjacent patches (i < j) */
    int64_t *pin_patch;         /* np: 1 for the patch held at I in its part */
    double *binv;               /* 9 F: [v~2 - v~1, v~3 - v~1, n~] ^-1, row-major */
    double *bedge;              /* 9 F: the base face's three sides (v~b - v~a) */
    es__spd *spd;
    int64_t id_rot, id_pos;     /* the two matrices in spd */
    int64_t *pin_vert;          /* V: 1 for the vertex held in its part */
    double *work;               /* 9 F + 9 np + 3 max(np, V) */
};

void es_lri_opts_init(es_lri_opts *o)
{
    o->patches = 0;
}

int64_t es_lri_dim(const es_lri *l) { return l ? 9 * l->nf + 3 * l->na : 0; }
int64_t es_lri_npatches(const es_lri *l) { return l ? l->np : 0; }

void es_lri_free(es_lri *l)
{
    if (!l) return;
    es__spd_free(l->spd);
    void *p[] = {l->patch, l->pair, l->pin_patch, l->binv, l->bedge, l->pin_vert, l->work};
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) es__free(l->ctx, p[i]);
    es__free(l->ctx, l);
}

/* ---- 3 x 3 helpers (row-major) ---------------------------------------------- */

static void mat_mul(const double *a, const double *b, double *c)
{
    double t[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            t[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
    memcpy(c, t, sizeof t);
}

static void mat_tmul(const double *a, const double *b, double *c)   /* a^T b */
{
    double t[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            t[3 * i + j] = a[i] * b[j] + a[3 + i] * b[3 + j] + a[6 + i] * b[6 + j];
    memcpy(c, t, sizeof t);
}

static int mat_inv(const double *m, double *r)
{
    double d = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
               m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (!(fabs(d) > 0)) return -1;
    r[0] = (m[4] * m[8] - m[5] * m[7]) / d, r[1] = (m[2] * m[7] - m[1] * m[8]) / d;
    r[2] = (m[1] * m[5] - m[2] * m[4]) / d, r[3] = (m[5] * m[6] - m[3] * m[8]) / d;
    r[4] = (m[0] * m[8] - m[2] * m[6]) / d, r[5] = (m[2] * m[3] - m[0] * m[5]) / d;
    r[6] = (m[3] * m[7] - m[4] * m[6]) / d, r[7] = (m[1] * m[6] - m[0] * m[7]) / d;
    r[8] = (m[0] * m[4] - m[1] * m[3]) / d;
    return 0;
}

/* Axis times angle of rotation r (angle in [0, pi]). */
static void rot_log(const double *r, double *w)
{
    double c = fmax(-1, fmin(1, 0.5 * (r[0] + r[4] + r[8] - 1))), th = acos(c);
    double v[3] = {r[7] - r[5], r[2] - r[6], r[3] - r[1]}, s = sin(th);
    if (th < 1e-8) {   /* near I: w = vee(R - R^T) / 2 */
        for (int k = 0; k < 3; k++) w[k] = 0.5 * v[k];
    } else if (M_PI - th > 1e-6) {
        for (int k = 0; k < 3; k++) w[k] = th / (2 * s) * v[k];
    } else {           /* near pi: the axis from R + I's largest column */
        double b[9];
        int k = 0;
        for (int i = 0; i < 9; i++) b[i] = r[i] + (i % 4 == 0);
        for (int i = 1; i < 3; i++)
            if (b[4 * i] > b[4 * k]) k = i;
        double n = sqrt(b[0 + k] * b[0 + k] + b[3 + k] * b[3 + k] + b[6 + k] * b[6 + k]);
        for (int i = 0; i < 3; i++) w[i] = th * b[3 * i + k] / n;
        if (v[0] * w[0] + v[1] * w[1] + v[2] * w[2] < 0)
            for (int i = 0; i < 3; i++) w[i] = -w[i];
    }
}

/* Rodrigues: the rotation by |w| about w. */
static void rot_exp(const double *w, double *r)
{
    double th = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), a, b;
    if (th < 1e-12) a = 1 - th * th / 6, b = 0.5 - th * th / 24;
    else a = sin(th) / th, b = (1 - cos(th)) / (th * th);
    double K[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0}, K2[9];
    mat_mul(K, K, K2);
    for (int i = 0; i < 9; i++) r[i] = (i % 4 == 0) + a * K[i] + b * K2[i];
}

/* [p1 - p0, p2 - p0, unit normal] of face f at positions x, row-major
 * with the three as columns. 0 if degenerate. */
static int face_frame(const int64_t *t, const double *x, double *m)
{
    double u[3], v[3], n[3];
    es__v3_sub(x + 3 * t[1], x + 3 * t[0], u);
    es__v3_sub(x + 3 * t[2], x + 3 * t[0], v);
    es__v3_cross(u, v, n);
    if (es__v3_normalize(n) == 0) return 0;
    for (int i = 0; i < 3; i++) m[3 * i] = u[i], m[3 * i + 1] = v[i], m[3 * i + 2] = n[i];
    return 1;
}

/* ---- the patches ------------------------------------------------------------- */

/* Farthest-point partition of the dual graph into np patches. */
static es_status partition(es_lri *l)
{
    const int64_t *fe = es_mesh_face_edges(l->mesh), *ef = es_mesh_edge_faces(l->mesh);
    int64_t nf = l->nf, *dist = es__alloc_array(l->ctx, 2 * nf, sizeof *dist), *q, seed = 0;
    if (!dist) return ES_ENOMEM;
    q = dist + nf;
    for (int64_t f = 0; f < nf; f++) dist[f] = INT64_MAX, l->patch[f] = -1;
    for (int64_t p = 0; p < l->np; p++) {
        int64_t qh = 0, qt = 0;
        /* BFS from the new seed, only where it is nearer than the seeds before */
        dist[seed] = 0, l->patch[seed] = p, q[qt++] = seed;
        while (qh < qt) {
            int64_t f = q[qh++];
            for (int k = 0; k < 3; k++) {
                int64_t e = fe[3 * f + k], g = ef[2 * e] == f ? ef[2 * e + 1] : ef[2 * e];
                if (g < 0 || dist[g] <= dist[f] + 1) continue;
                dist[g] = dist[f] + 1, l->patch[g] = p, q[qt++] = g;
            }
        }
        /* the next seed: the farthest face (unreached parts first) */
        for (int64_t f = 0, best = -1; f < nf; f++)
            if (dist[f] > best) best = dist[f], seed = f;
        if (dist[seed] == 0) {   /* fewer faces than patches */
            l->np = p + 1;
            break;
        }
    }
    es__free(l->ctx, dist);
    return ES_OK;
}

static int cmp_pair(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    return x[0] != y[0] ? (x[0] < y[0] ? -1 : 1) : (x[1] < y[1] ? -1 : x[1] > y[1]);
}

/* Adjacent patch pairs, sorted and unique; the patch held in each part. */
static es_status patch_graph(es_lri *l)
{
    const int64_t *ef = es_mesh_edge_faces(l->mesh);
    int64_t ne = es_mesh_nedges(l->mesh), n = 0, *stack;
    if (!(l->pair = es__alloc_array(l->ctx, 2 * ne + 2, sizeof *l->pair))) return ES_ENOMEM;
    for (int64_t e = 0; e < ne; e++) {
        int64_t f = ef[2 * e], g = ef[2 * e + 1];
        if (f < 0 || g < 0 || l->patch[f] == l->patch[g]) continue;
        l->pair[2 * n] = l->patch[f] < l->patch[g] ? l->patch[f] : l->patch[g];
        l->pair[2 * n + 1] = l->patch[f] < l->patch[g] ? l->patch[g] : l->patch[f];
        n++;
    }
    qsort(l->pair, (size_t)n, 2 * sizeof *l->pair, cmp_pair);
    l->na = 0;
    for (int64_t i = 0; i < n; i++)
        if (!l->na || cmp_pair(l->pair + 2 * i, l->pair + 2 * (l->na - 1))) {
            l->pair[2 * l->na] = l->pair[2 * i], l->pair[2 * l->na + 1] = l->pair[2 * i + 1];
            l->na++;
        }
    /* parts of the patch graph: union-find, the lowest patch of each held */
    if (!(l->pin_patch = es__calloc(l->ctx, (size_t)l->np, sizeof *l->pin_patch)) ||
        !(stack = es__alloc_array(l->ctx, l->np, sizeof *stack)))
        return ES_ENOMEM;
    for (int64_t p = 0; p < l->np; p++) stack[p] = p;
    for (int64_t i = 0; i < l->na; i++) {
        int64_t a = l->pair[2 * i], b = l->pair[2 * i + 1];
        while (stack[a] != a) a = stack[a];
        while (stack[b] != b) b = stack[b];
        if (a != b) stack[a > b ? a : b] = a < b ? a : b;
    }
    for (int64_t p = 0; p < l->np; p++) l->pin_patch[p] = stack[p] == p;
    es__free(l->ctx, stack);
    return ES_OK;
}

/* ---- the two matrices ------------------------------------------------------- */

/* Positions: the graph Laplacian of the faces' sides (an edge counted once
 * per face beside it), the lowest vertex of every component held. */
static es_status position_matrix(es_lri *l)
{
    const int64_t *ed = es_mesh_edges(l->mesh), *ef = es_mesh_edge_faces(l->mesh);
    const int64_t *comp = es_mesh_vertex_component(l->mesh);
    int64_t ne = es_mesh_nedges(l->mesh), nz = l->nv + ne, *ti, k = 0;
    double *tv;
    es_status rc;
    ti = es__alloc_array(l->ctx, 2 * nz, sizeof *ti);
    tv = es__alloc_array(l->ctx, nz, sizeof *tv);
    l->pin_vert = es__calloc(l->ctx, (size_t)l->nv, sizeof *l->pin_vert);
    if (!ti || !tv || !l->pin_vert) {
        es__free(l->ctx, ti), es__free(l->ctx, tv);
        return ES_ENOMEM;
    }
    {
        int64_t *seen = ti;   /* first vertex of each component, before ti is used */
        for (int64_t v = 0; v < l->nv; v++) seen[v] = -1;
        for (int64_t v = 0; v < l->nv; v++)
            if (comp[v] < 0) l->pin_vert[v] = 1;   /* in no face: stays at the origin */
            else if (seen[comp[v]] < 0) l->pin_vert[v] = 1, seen[comp[v]] = v;
    }
    for (int64_t v = 0; v < l->nv; v++) ti[v] = ti[nz + v] = v, tv[v] = l->pin_vert[v];
    k = l->nv;
    for (int64_t e = 0; e < ne; e++) {
        int64_t a = ed[2 * e], b = ed[2 * e + 1];
        double w = (ef[2 * e] >= 0) + (ef[2 * e + 1] >= 0);
        if (!l->pin_vert[a]) tv[a] += w;
        if (!l->pin_vert[b]) tv[b] += w;
        ti[k] = a, ti[nz + k] = b, tv[k] = l->pin_vert[a] || l->pin_vert[b] ? 0 : -w;
        k++;
    }
    rc = es__spd_add(l->spd, l->nv, nz, ti, ti + nz, tv, "LRI positions", &l->id_pos);
    es__free(l->ctx, ti);
    es__free(l->ctx, tv);
    return rc;
}

es_status es_lri_new(es_ctx *ctx, const es_mesh *mesh, const double *base,
                     const es_lri_opts *opts, es_lri **out)
{
    es_lri *l;
    es_lri_opts dflt;
    const int64_t *F;
    es_status rc = ES_OK;
    *out = NULL;
    if (!opts) {
        es_lri_opts_init(&dflt);
        opts = &dflt;
    }
    if (!mesh || !base) ES_FAIL(ctx, ES_EINVAL, "LRI: NULL argument");
    if (es_mesh_nfaces(mesh) < 1) ES_FAIL(ctx, ES_EINVAL, "LRI: mesh without faces");
    if (opts->patches < 0) ES_FAIL(ctx, ES_EINVAL, "LRI: patches must be >= 0");
    if (!(l = es__calloc(ctx, 1, sizeof *l))) return ES_ENOMEM;
    l->ctx = ctx, l->mesh = mesh, l->nv = es_mesh_nverts(mesh), l->nf = es_mesh_nfaces(mesh);
    /* the paper's 2000 patches on SCAPE's 25K faces: about 12 faces each */
    l->np = opts->patches ? opts->patches : l->nf / 12 < 1 ? 1 : l->nf / 12 > 2000 ? 2000 : l->nf / 12;
    if (l->np > l->nf) l->np = l->nf;
    F = es_mesh_faces(mesh);
    l->patch = es__alloc_array(ctx, l->nf, sizeof *l->patch);
    l->binv = es__alloc_array(ctx, 9 * l->nf, sizeof *l->binv);
    l->bedge = es__alloc_array(ctx, 9 * l->nf, sizeof *l->bedge);
    if (!l->patch || !l->binv || !l->bedge) rc = ES_ENOMEM;
    for (int64_t f = 0; rc == ES_OK && f < l->nf; f++) {
        double m[9];
        const int64_t *t = F + 3 * f;
        if (!face_frame(t, base, m) || mat_inv(m, l->binv + 9 * f))
            rc = es__fail(ctx, ES_EINVAL, "LRI: face %lld of the base mesh is degenerate",
                          (long long)f);
        for (int k = 0; rc == ES_OK && k < 3; k++)
            es__v3_sub(base + 3 * t[(k + 1) % 3], base + 3 * t[k], l->bedge + 9 * f + 3 * k);
    }
    if (rc == ES_OK) rc = partition(l);
    if (rc == ES_OK) rc = patch_graph(l);
    if (rc == ES_OK) rc = es__spd_new(ctx, &l->spd);
    if (rc == ES_OK) rc = position_matrix(l);
    if (rc == ES_OK) {
        int64_t big = l->np > l->nv ? l->np : l->nv;
        if (!(l->work = es__alloc_array(ctx, 9 * l->nf + 9 * l->np + 9 * big, sizeof *l->work)))
            rc = ES_ENOMEM;
    }
    l->id_rot = -1;
    if (rc != ES_OK) {
        es_lri_free(l);
        return rc;
    }
    *out = l;
    return ES_OK;
}

/* ---- encoding ---------------------------------------------------------------- */

es_status es_lri_encode(es_ctx *ctx, es_lri *l, const double *xyz, double *x)
{
    const int64_t *F;
    double *R, *G;
    if (!l || !xyz || !x) ES_FAIL(ctx, ES_EINVAL, "LRI: NULL argument");
    F = es_mesh_faces(l->mesh);
    R = l->work, G = R + 9 * l->nf;
    for (int64_t p = 0; p < 9 * l->np; p++) G[p] = 0;
    for (int64_t f = 0; f < l->nf; f++) {
        double m[9], D[9], *r = R + 9 * f, S[9];
        if (!face_frame(F + 3 * f, xyz, m))
            ES_FAIL(ctx, ES_EINVAL, "LRI: face %lld is degenerate", (long long)f);
        mat_mul(m, l->binv + 9 * f, D);
        memcpy(r, D, sizeof D);
        es__rotation_nearest(r);
        mat_tmul(r, D, S);   /* S = R^T D, symmetrized */
        x[9 * f] = S[0], x[9 * f + 1] = 0.5 * (S[1] + S[3]), x[9 * f + 2] = 0.5 * (S[2] + S[6]);
        x[9 * f + 3] = S[4], x[9 * f + 4] = 0.5 * (S[5] + S[7]), x[9 * f + 5] = S[8];
        for (int i = 0; i < 9; i++) G[9 * l->patch[f] + i] += r[i];
    }
    for (int64_t p = 0; p < l->np; p++) es__rotation_nearest(G + 9 * p);
    for (int64_t f = 0; f < l->nf; f++) {
        double rel[9];
        mat_tmul(G + 9 * l->patch[f], R + 9 * f, rel);
        rot_log(rel, x + 9 * f + 6);
    }
    for (int64_t i = 0; i < l->na; i++) {
        double c[9];
        mat_tmul(G + 9 * l->pair[2 * i], G + 9 * l->pair[2 * i + 1], c);
        rot_log(c, x + 9 * l->nf + 3 * i);
    }
    return ES_OK;
}

/* ---- decoding ---------------------------------------------------------------- */

/* Patch rotations G (9 np) from the connection maps of x: least squares on
 * G_i C_ij = G_j, each row of the G's a right-hand side. In unknowns
 * g = G^T (columns = rows of G), an equation is C^T g_i - g_j = 0:
 * normal blocks (i,i) += I, (j,j) += I, (i,j) -= C, (j,i) -= C^T. */
static es_status patch_rotations(es_lri *l, const double *x, double *G)
{
    int64_t n = 3 * l->np, nz = 3 * l->np + 9 * l->na, k = 0;
    int64_t *ti = es__alloc_array(l->ctx, 2 * nz, sizeof *ti);
    double *tv = es__alloc_array(l->ctx, nz, sizeof *tv), *b = l->work + 9 * l->nf;
    es_status rc = ti && tv ? ES_OK : ES_ENOMEM;
    if (rc != ES_OK) goto done;
    for (int64_t i = 0; i < n; i++) ti[k] = ti[nz + k] = i, tv[k] = 0, k++;
    for (int64_t i = 0; i < 3 * n; i++) b[i] = 0;   /* n x 3: column r = row r of the G's */
    for (int64_t i = 0; i < l->na; i++) {
        int64_t p = l->pair[2 * i], q = l->pair[2 * i + 1];
        double C[9];
        rot_exp(x + 9 * l->nf + 3 * i, C);
        for (int a = 0; a < 3; a++) {
            if (!l->pin_patch[p]) tv[3 * p + a] += 1;
            if (!l->pin_patch[q]) tv[3 * q + a] += 1;
            for (int c = 0; c < 3; c++) {
                /* (i,j) block, entry (a, c): -C[a][c] */
                ti[k] = 3 * p + a, ti[nz + k] = 3 * q + c;
                tv[k++] = l->pin_patch[p] || l->pin_patch[q] ? 0 : -C[3 * a + c];
                /* a held patch is I: its terms move to the right-hand side */
                for (int r = 0; r < 3; r++) {
                    if (l->pin_patch[p] && !l->pin_patch[q])
                        b[3 * q + c + n * r] += C[3 * a + c] * (a == r);   /* C^T e_r */
                    if (l->pin_patch[q] && !l->pin_patch[p])
                        b[3 * p + a + n * r] += C[3 * a + c] * (c == r);   /* C e_r */
                }
            }
        }
    }
    for (int64_t p = 0; p < l->np; p++)
        if (l->pin_patch[p])
            for (int a = 0; a < 3; a++) tv[3 * p + a] = 1, b[3 * p + a + n * a] = 1;
    rc = l->id_rot < 0 ? es__spd_add(l->spd, n, nz, ti, ti + nz, tv, "LRI rotations", &l->id_rot)
                       : es__spd_refactor(l->spd, l->id_rot, tv);
    if (rc == ES_OK) rc = es__spd_solve(l->spd, l->id_rot, 3, b, n);
    for (int64_t p = 0; rc == ES_OK && p < l->np; p++) {
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) G[9 * p + 3 * r + c] = b[3 * p + c + n * r];
        es__rotation_nearest(G + 9 * p);
    }
done:
    es__free(l->ctx, ti);
    es__free(l->ctx, tv);
    return rc;
}

es_status es_lri_decode(es_ctx *ctx, es_lri *l, const double *x, double *xyz)
{
    const int64_t *F;
    double *D, *G, *b;
    es_status rc;
    if (!l || !x || !xyz) ES_FAIL(ctx, ES_EINVAL, "LRI: NULL argument");
    for (int64_t i = 0; i < es_lri_dim(l); i++)
        if (!isfinite(x[i])) ES_FAIL(ctx, ES_EINVAL, "LRI: coordinate %lld is not finite", (long long)i);
    F = es_mesh_faces(l->mesh);
    D = l->work, G = D + 9 * l->nf, b = G + 9 * l->np;
    {
        double *Gs = es__alloc_array(ctx, 9 * l->np, sizeof *Gs);
        if (!Gs) return ES_ENOMEM;
        rc = patch_rotations(l, x, Gs);
        if (rc == ES_OK) memcpy(G, Gs, 9 * (size_t)l->np * sizeof *Gs);
        es__free(ctx, Gs);
        if (rc != ES_OK) return rc;
    }
    for (int64_t f = 0; f < l->nf; f++) {
        const double *s = x + 9 * f;
        double S[9] = {s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5]}, rel[9], R[9];
        rot_exp(s + 6, rel);
        mat_mul(G + 9 * l->patch[f], rel, R);
        mat_mul(R, S, D + 9 * f);
    }
    /* positions: sum over face sides of D_f (v~_b - v~_a), into b (V x 3) */
    for (int64_t i = 0; i < 3 * l->nv; i++) b[i] = 0;
    for (int64_t f = 0; f < l->nf; f++)
        for (int k = 0; k < 3; k++) {
            int64_t va = F[3 * f + k], vb = F[3 * f + (k + 1) % 3];
            const double *d = l->bedge + 9 * f + 3 * k, *m = D + 9 * f;
            for (int c = 0; c < 3; c++) {
                double t = m[3 * c] * d[0] + m[3 * c + 1] * d[1] + m[3 * c + 2] * d[2];
                if (!l->pin_vert[vb]) b[vb + l->nv * c] += t;
                if (!l->pin_vert[va]) b[va + l->nv * c] -= t;
            }
        }
    if ((rc = es__spd_solve(l->spd, l->id_pos, 3, b, l->nv)) != ES_OK) return rc;
    for (int64_t v = 0; v < l->nv; v++)
        for (int c = 0; c < 3; c++) xyz[3 * v + c] = b[v + l->nv * c];
    return ES_OK;
}

/* ---- the whole's rigid motion (Sec. 3.2.3) ------------------------------------ */

/* Proper rotation r and translation t taking y onto x by least squares
 * (Kabsch: the nearest rotation to the cross-covariance). */
static void rigid_fit(int64_t nv, const double *y, const double *x, double *r, double *t)
{
    double cy[3] = {0, 0, 0}, cx[3] = {0, 0, 0};
    for (int64_t v = 0; v < nv; v++)
        for (int c = 0; c < 3; c++) cy[c] += y[3 * v + c] / (double)nv, cx[c] += x[3 * v + c] / (double)nv;
    for (int i = 0; i < 9; i++) r[i] = 0;
    for (int64_t v = 0; v < nv; v++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) r[3 * i + j] += (x[3 * v + i] - cx[i]) * (y[3 * v + j] - cy[j]);
    es__rotation_nearest(r);
    for (int i = 0; i < 3; i++) t[i] = cx[i] - (r[3 * i] * cy[0] + r[3 * i + 1] * cy[1] + r[3 * i + 2] * cy[2]);
}

/* Unit quaternion (w, x, y, z) of rotation r (Shepperd's method). */
static void rot_quat(const double *r, double *q)
{
    double tr = r[0] + r[4] + r[8];
    if (tr > 0) {
        double s = 2 * sqrt(tr + 1);
        q[0] = s / 4, q[1] = (r[7] - r[5]) / s, q[2] = (r[2] - r[6]) / s, q[3] = (r[3] - r[1]) / s;
    } else if (r[0] > r[4] && r[0] > r[8]) {
        double s = 2 * sqrt(1 + r[0] - r[4] - r[8]);
        q[0] = (r[7] - r[5]) / s, q[1] = s / 4, q[2] = (r[1] + r[3]) / s, q[3] = (r[2] + r[6]) / s;
    } else if (r[4] > r[8]) {
        double s = 2 * sqrt(1 + r[4] - r[0] - r[8]);
        q[0] = (r[2] - r[6]) / s, q[1] = (r[1] + r[3]) / s, q[2] = s / 4, q[3] = (r[5] + r[7]) / s;
    } else {
        double s = 2 * sqrt(1 + r[8] - r[0] - r[4]);
        q[0] = (r[3] - r[1]) / s, q[1] = (r[2] + r[6]) / s, q[2] = (r[5] + r[7]) / s, q[3] = s / 4;
    }
}

static void quat_rot(const double *q, double *r)
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    r[0] = 1 - 2 * (y * y + z * z), r[1] = 2 * (x * y - w * z), r[2] = 2 * (x * z + w * y);
    r[3] = 2 * (x * y + w * z), r[4] = 1 - 2 * (x * x + z * z), r[5] = 2 * (y * z - w * x);
    r[6] = 2 * (x * z - w * y), r[7] = 2 * (y * z + w * x), r[8] = 1 - 2 * (x * x + y * y);
}

es_status es_lri_place(es_ctx *ctx, int64_t nv, const double *y, const double *xs,
                       const double *xt, double s, double *out)
{
    double rs[9], ts[3], rt[9], tt[3], qs[4], qt[4], q[4], r[9], t[3], d = 0, th, a, b, n = 0;
    if (!y || !xs || !xt || !out || nv < 1) ES_FAIL(ctx, ES_EINVAL, "LRI place: NULL argument");
    if (!isfinite(s)) ES_FAIL(ctx, ES_EINVAL, "LRI place: s is not finite");
    rigid_fit(nv, y, xs, rs, ts);
    rigid_fit(nv, y, xt, rt, tt);
    rot_quat(rs, qs);
    rot_quat(rt, qt);
    for (int k = 0; k < 4; k++) d += qs[k] * qt[k];
    if (d < 0) {   /* the shorter way round */
        for (int k = 0; k < 4; k++) qt[k] = -qt[k];
        d = -d;
    }
    d = fmin(d, 1);
    th = acos(d);
    if (th < 1e-9) a = 1 - s, b = s;
    else a = sin((1 - s) * th) / sin(th), b = sin(s * th) / sin(th);
    for (int k = 0; k < 4; k++) q[k] = a * qs[k] + b * qt[k], n += q[k] * q[k];
    for (int k = 0; k < 4; k++) q[k] /= sqrt(n);
    quat_rot(q, r);
    for (int c = 0; c < 3; c++) t[c] = (1 - s) * ts[c] + s * tt[c];
    for (int64_t v = 0; v < nv; v++) {
        double p[3] = {y[3 * v], y[3 * v + 1], y[3 * v + 2]};
        for (int i = 0; i < 3; i++)
            out[3 * v + i] = r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2] + t[i];
    }
    return ES_OK;
}
