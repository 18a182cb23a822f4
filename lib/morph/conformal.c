/* lib/morph/conformal.c — the conformal morph of edge-length-interpolation
 * Section 5 (Fig. 11): discrete conformal factors u that take a closed
 * genus-0 mesh to a discretely conformally equivalent mesh on the sphere
 * (l~_ij = e^((u_i + u_j) / 2) l_ij, the paper's eq. 13 after Springborn,
 * Schröder and Pinkall 2008, "CETM"), and frames k u embedded.
 *
 * The paper cites [27, 4] for the factors and gives no steps; these are:
 *  1. one vertex v_inf is sent to infinity: the rest of the mesh is a disk
 *     whose boundary is v_inf's link;
 *  2. the disk is flattened by CETM: its convex energy minimized by Newton
 *     (the Hessian is the cotangent Laplacian, CETM Sec. 3), target angle
 *     sum 2 pi at the interior vertices, the boundary factors held at
 *     w_j = -2 log(l_inf,j / mean): inversion about v_inf written on lengths,
 *     the one condition under which the edges to v_inf stay conformally
 *     equivalent after step 4 (their chordal length there is sqrt(2 rho_j),
 *     which is e^((u_inf + u_j) / 2) l_inf,j for one u_inf iff
 *     e^(w_j / 2) l_inf,j is the same for every neighbour j);
 *     the line search uses only the energy's gradient: along a Newton
 *     direction d the slope -F(u + t d) . d is increasing (convexity), so a
 *     step where it is <= 0, or small, lowers the energy;
 *  3. the flat metric is laid out in the plane across edges, breadth first;
 *     faces the flat metric breaks (an obtuse triangle where the scale
 *     changes fast: CETM's extension gives them angles 0, 0, pi) are
 *     walked around, and the sphere misses the factors on their long
 *     sides (counted and measured in the info; refused beyond 0.25);
 *  4. inverse stereographic projection onto the unit sphere, v_inf at the
 *     pole: |s(p) - s(q)| = |p - q| sqrt(rho_p rho_q), rho = 2 / (1 + |p|^2),
 *     so every factor changes by log rho and the lengths stay discretely
 *     conformal;
 *  5. Moebius-centred: the area-weighted centroid c of the vertices is
 *     moved toward the centre by the sphere's Moebius maps, until |c| <
 *     1e-10 (or 300 steps; the test asks 1e-6); such maps scale chordal
 *     distances by
 *     sqrt(|phi'(x)| |phi'(y)|), so conformal equivalence holds throughout;
 *     and mirrored if need be so that its faces' normals point outward;
 *  6. scaled so that the edge lengths keep the input's sum (the morph
 *     changes shape, not size), and u read back from the sphere's chordal
 *     lengths s by least squares on u_a + u_b = 2 log(s_e / l_e): E
 *     equations for V unknowns, consistent up to rounding (the residual is
 *     reported), their matrix the signless Laplacian, definite because a
 *     triangle mesh's graph has odd cycles.
 */
#include "morph/morph_pkg.h"
#include "edgespace/es_geom.h"

#include <math.h>
#include <stdlib.h>

typedef struct cf {
    es_ctx *ctx;
    const es_mesh *m;
    int64_t nv, ne, nf, inf, nint;
    const double *len;
    const int64_t *F, *fe, *ed;
    int64_t *idx;           /* V: unknown index of an interior vertex, -1 boundary, -2 v_inf */
    double *w;              /* V: flattening factors */
    double *lam;            /* E: lengths under w */
    double *ang;            /* 3F: corner angles of disk faces */
    double *res;            /* nint: angle sum - 2 pi */
    double *dir, *w0;       /* nint, V */
    int64_t nz, *ti, *tj;   /* Hessian triplets */
    double *tv;
    int64_t *slot;          /* 3F: triplet of each face's opposite edge (-1: none) */
    int64_t *dslot;         /* nint: diagonal triplet */
} cf;

/* The three angles of a triangle with sides a (opposite corner 0), b, c
 * (CETM's extension: a side longer than the other two together makes its
 * opposite angle pi and the others 0). */
static void tri_angles(double a, double b, double c, double *t)
{
    if (a >= b + c) t[0] = M_PI, t[1] = t[2] = 0;
    else if (b >= a + c) t[1] = M_PI, t[0] = t[2] = 0;
    else if (c >= a + b) t[2] = M_PI, t[0] = t[1] = 0;
    else {
        t[0] = acos(fmax(-1, fmin(1, (b * b + c * c - a * a) / (2 * b * c))));
        t[1] = acos(fmax(-1, fmin(1, (a * a + c * c - b * b) / (2 * a * c))));
        t[2] = M_PI - t[0] - t[1];
    }
}

static int disk_face(const cf *c, int64_t f)
{
    const int64_t *t = c->F + 3 * f;
    return t[0] != c->inf && t[1] != c->inf && t[2] != c->inf;
}

/* Lengths under w, corner angles and the interior angle-sum residuals.
 * Returns max |residual|. */
static double residuals(cf *c, const double *w)
{
    double mx = 0;
    for (int64_t e = 0; e < c->ne; e++)
        c->lam[e] = c->len[e] * exp(0.5 * (w[c->ed[2 * e]] + w[c->ed[2 * e + 1]]));
    for (int64_t i = 0; i < c->nint; i++) c->res[i] = -2 * M_PI;
    for (int64_t f = 0; f < c->nf; f++) {
        if (!disk_face(c, f)) continue;
        /* corner k faces edge k+1 (es_mesh.h: edge k joins corners k, k+1) */
        const int64_t *fe = c->fe + 3 * f;
        tri_angles(c->lam[fe[1]], c->lam[fe[2]], c->lam[fe[0]], c->ang + 3 * f);
        for (int k = 0; k < 3; k++) {
            int64_t i = c->idx[c->F[3 * f + k]];
            if (i >= 0) c->res[i] += c->ang[3 * f + k];
        }
    }
    for (int64_t i = 0; i < c->nint; i++) mx = fmax(mx, fabs(c->res[i]));
    return mx;
}

static double cot_of(double t)
{
    return t <= 0 || t >= M_PI ? 0 : cos(t) / sin(t);   /* degenerate: no weight (CETM) */
}

/* The Hessian triplets: one per interior vertex (diagonal) and per edge
 * between two interior vertices, in a fixed order. */
static es_status hessian_pattern(cf *c)
{
    int64_t nz = c->nint;
    for (int64_t e = 0; e < c->ne; e++)
        if (c->idx[c->ed[2 * e]] >= 0 && c->idx[c->ed[2 * e + 1]] >= 0) nz++;
    c->ti = es__alloc_array(c->ctx, 2 * nz, sizeof *c->ti);
    c->tv = es__alloc_array(c->ctx, nz, sizeof *c->tv);
    c->slot = es__alloc_array(c->ctx, c->ne, sizeof *c->slot);
    if (!c->ti || !c->tv || !c->slot) return ES_ENOMEM;
    c->tj = c->ti + nz;
    for (int64_t i = 0; i < c->nint; i++) c->ti[i] = c->tj[i] = i;
    nz = c->nint;
    for (int64_t e = 0; e < c->ne; e++) {
        int64_t a = c->idx[c->ed[2 * e]], b = c->idx[c->ed[2 * e + 1]];
        c->slot[e] = -1;
        if (a >= 0 && b >= 0) c->ti[nz] = a, c->tj[nz] = b, c->slot[e] = nz++;
    }
    c->nz = nz;
    return ES_OK;
}

/* Values of the cotangent Laplacian at the current angles: edge weight
 * (cot alpha + cot beta) / 2 over the disk faces beside it. */
static void hessian_values(cf *c)
{
    for (int64_t k = 0; k < c->nz; k++) c->tv[k] = 0;
    for (int64_t f = 0; f < c->nf; f++) {
        if (!disk_face(c, f)) continue;
        for (int k = 0; k < 3; k++) {
            int64_t e = c->fe[3 * f + (k + 1) % 3];   /* opposite corner k */
            int64_t a = c->idx[c->ed[2 * e]], b = c->idx[c->ed[2 * e + 1]];
            double h = 0.5 * cot_of(c->ang[3 * f + k]);
            if (a >= 0) c->tv[a] += h;
            if (b >= 0) c->tv[b] += h;
            if (c->slot[e] >= 0) c->tv[c->slot[e]] -= h;
        }
    }
    /* a hair of diagonal against semi-definiteness from degenerate faces */
    for (int64_t i = 0; i < c->nint; i++) c->tv[i] = c->tv[i] * (1 + 1e-12) + 1e-14;
}

/* Slope of the energy along dir at step t from w0: -F(w0 + t dir) . dir. */
static double slope(cf *c, double t)
{
    double s = 0;
    for (int64_t v = 0; v < c->nv; v++) {
        int64_t i = c->idx[v];
        c->w[v] = c->w0[v] + (i >= 0 ? t * c->dir[i] : 0);
    }
    residuals(c, c->w);
    for (int64_t i = 0; i < c->nint; i++) s -= c->res[i] * c->dir[i];
    return s;
}

/* Newton on the flattening; leaves c->w and c->lam at the solution. */
static es_status flatten(cf *c, es__spd *spd, int *iters, double *defect)
{
    int64_t id = -1;
    es_status rc = hessian_pattern(c);
    double r = residuals(c, c->w);
    int it;
    for (it = 0; rc == ES_OK && it < 100 && r > 1e-11; it++) {
        double s0, t = 1, s1;
        hessian_values(c);
        rc = id < 0 ? es__spd_add(spd, c->nint, c->nz, c->ti, c->tj, c->tv,
                                   "conformal flattening", &id)
                    : es__spd_refactor(spd, id, c->tv);
        if (rc != ES_OK) break;
        for (int64_t i = 0; i < c->nint; i++) c->dir[i] = c->res[i];
        if ((rc = es__spd_solve(spd, id, 1, c->dir, c->nint)) != ES_OK) break;
        memcpy(c->w0, c->w, (size_t)c->nv * sizeof *c->w);
        s0 = 0;
        for (int64_t i = 0; i < c->nint; i++) s0 -= c->res[i] * c->dir[i];
        if (!(s0 < 0)) break;   /* no descent left at rounding level */
        s1 = slope(c, 1);
        if (!(s1 <= 0.1 * -s0)) {
            /* past the minimum along dir: bisect the increasing slope */
            double lo = 0, hi = 1;
            for (int k = 0; k < 40; k++) {
                t = 0.5 * (lo + hi);
                s1 = slope(c, t);
                if (!isfinite(s1) || s1 > 0.1 * -s0) hi = t;
                else if (s1 < 0.1 * s0) lo = t;
                else break;
            }
        }
        r = residuals(c, c->w);
        es__progress(c->ctx, "conformal: flattening", it + 1, 100);
    }
    es__progress(c->ctx, "conformal: flattening", 1, 1);
    *iters = it;
    *defect = r;
    if (rc == ES_OK && !(r <= 1e-8))
        rc = es__fail(c->ctx, ES_ENOCONV, "conformal: the flattening stopped at an angle "
                      "defect of %.3g rad after %d Newton steps", r, it);
    return rc;
}

static int broken(const cf *c, int64_t f)
{
    return c->ang[3 * f] == M_PI || c->ang[3 * f + 1] == M_PI || c->ang[3 * f + 2] == M_PI;
}

static int64_t first_broken(const cf *c)
{
    for (int64_t f = 0; f < c->nf; f++)
        if (disk_face(c, f) && broken(c, f)) return f;
    return -1;
}

/* Place the third vertex of face g, reached across its edge e, to the left
 * of e's direction in g (g counter-clockwise), unless it is placed. */
static void place_across(const cf *c, double *p, uint8_t *placed, int64_t g, int64_t e)
{
    int kk = 0;
    while (c->fe[3 * g + kk] != e) kk++;
    int64_t a = c->F[3 * g + kk], b = c->F[3 * g + (kk + 1) % 3], xv = c->F[3 * g + (kk + 2) % 3];
    if (placed[xv]) return;
    double lbx = c->lam[c->fe[3 * g + (kk + 1) % 3]], lxa = c->lam[c->fe[3 * g + (kk + 2) % 3]];
    double ux = p[2 * b] - p[2 * a], uy = p[2 * b + 1] - p[2 * a + 1];
    double d = sqrt(ux * ux + uy * uy), s = (lxa * lxa - lbx * lbx + d * d) / (2 * d);
    double h = sqrt(fmax(lxa * lxa - s * s, 0));
    ux /= d, uy /= d;
    p[2 * xv] = p[2 * a] + s * ux - h * uy;
    p[2 * xv + 1] = p[2 * a + 1] + s * uy + h * ux;
    placed[xv] = 1;
}

/* Place the disk in the plane (p: 2 per vertex) from lengths c->lam, face
 * after face breadth first across edges. A face the flat metric breaks
 * (CETM's extension gives it the angles 0, 0, pi) cannot be laid out as
 * it is: the walk goes around such faces and enters one only when no
 * other face is left to reach, so every other face keeps its lengths (the
 * broken faces' long sides come out short). */
static es_status layout(cf *c, double *p)
{
    const int64_t *ef = es_mesh_edge_faces(c->m);
    int64_t *queue = es__alloc_array(c->ctx, c->nf, sizeof *queue), qh = 0, qt = 0, f0 = -1;
    uint8_t *seen = es__calloc(c->ctx, (size_t)c->nf + (size_t)c->nv, 1), *placed;
    if (!queue || !seen) {
        es__free(c->ctx, queue);
        es__free(c->ctx, seen);
        return ES_ENOMEM;
    }
    placed = seen + c->nf;
    for (int64_t f = 0; f < c->nf && f0 < 0; f++)
        if (disk_face(c, f) && !broken(c, f)) f0 = f;
    for (int64_t f = 0; f < c->nf && f0 < 0; f++)
        if (disk_face(c, f)) f0 = f;
    {
        const int64_t *t = c->F + 3 * f0, *fe = c->fe + 3 * f0;
        double l01 = c->lam[fe[0]], l12 = c->lam[fe[1]], l20 = c->lam[fe[2]];
        double x = (l20 * l20 - l12 * l12 + l01 * l01) / (2 * l01);
        p[2 * t[0]] = 0, p[2 * t[0] + 1] = 0;
        p[2 * t[1]] = l01, p[2 * t[1] + 1] = 0;
        p[2 * t[2]] = x, p[2 * t[2] + 1] = sqrt(fmax(l20 * l20 - x * x, 0));
        placed[t[0]] = placed[t[1]] = placed[t[2]] = 1;
    }
    seen[f0] = 1;
    queue[qt++] = f0;
    for (;;) {
        int64_t entered = 0;
        while (qh < qt) {   /* across unbroken faces */
            int64_t f = queue[qh++];
            for (int k = 0; k < 3; k++) {
                int64_t e = c->fe[3 * f + k], g = ef[2 * e] == f ? ef[2 * e + 1] : ef[2 * e];
                if (g < 0 || seen[g] || !disk_face(c, g) || broken(c, g)) continue;
                seen[g] = 1;
                queue[qt++] = g;
                place_across(c, p, placed, g, e);
            }
        }
        /* a broken face beside the laid-out part that reaches a new vertex */
        for (int64_t g = 0; g < c->nf && !entered; g++) {
            if (seen[g] || !disk_face(c, g)) continue;
            for (int k = 0; k < 3 && !entered; k++) {
                int64_t e = c->fe[3 * g + k], f = ef[2 * e] == g ? ef[2 * e + 1] : ef[2 * e];
                if (f < 0 || !seen[f]) continue;
                seen[g] = 1;
                queue[qt++] = g;
                place_across(c, p, placed, g, e);
                entered = 1;
            }
        }
        if (!entered) break;
    }
    es__free(c->ctx, queue);
    es__free(c->ctx, seen);
    return ES_OK;
}

/* Vertex areas (a third of each incident triangle's) of positions x. */
static void vertex_areas(const cf *c, const double *x, double *a)
{
    for (int64_t v = 0; v < c->nv; v++) a[v] = 0;
    for (int64_t f = 0; f < c->nf; f++) {
        const int64_t *t = c->F + 3 * f;
        double u[3], w[3], n[3];
        es__v3_sub(x + 3 * t[1], x + 3 * t[0], u);
        es__v3_sub(x + 3 * t[2], x + 3 * t[0], w);
        es__v3_cross(u, w, n);
        for (int k = 0; k < 3; k++) a[t[k]] += sqrt(es__v3_dot(n, n)) / 6;
    }
}

/* Area-weighted centroid of points x on the unit sphere; returns |g|. */
static double centroid(const cf *c, const double *x, double *a, double *g)
{
    double sa = 0;
    vertex_areas(c, x, a);
    g[0] = g[1] = g[2] = 0;
    for (int64_t v = 0; v < c->nv; v++) {
        for (int k = 0; k < 3; k++) g[k] += a[v] * x[3 * v + k];
        sa += a[v];
    }
    for (int k = 0; k < 3; k++) g[k] /= sa;
    return sqrt(es__v3_dot(g, g));
}

/* Moebius-centre points x on the unit sphere: phi_b with b = beta g, g the
 * centroid, phi_b(x) = ((1 - |b|^2)(x - b) - |x - b|^2 b) / |x - b|^2 on
 * |x| = 1 (b to the centre, the sphere onto itself). A step with beta = 1
 * removes only part of g (measured: 1/3, then ~1 % per step near the
 * end), so beta grows while the centroid shrinks and falls back when it
 * does not. Returns the steps taken; *off gets the final |centroid|. */
static int centre(const cf *c, double *x, double *y, double *a, double *off)
{
    double g[3], beta = 1;
    int it, taken = 0;
    *off = centroid(c, x, a, g);
    for (it = 0; it < 300 && *off > 1e-10; it++) {
        double b[3], bb, gn[3], o2;
        for (int k = 0; k < 3; k++) b[k] = beta * g[k];
        bb = es__v3_dot(b, b);
        if (bb >= 0.81) {   /* stay well inside the ball */
            beta *= 0.25;
            continue;
        }
        for (int64_t v = 0; v < c->nv; v++) {
            const double *p = x + 3 * v;
            double d[3], dd, *q = y + 3 * v;
            es__v3_sub(p, b, d);
            dd = es__v3_dot(d, d);
            for (int k = 0; k < 3; k++) q[k] = ((1 - bb) * d[k] - dd * b[k]) / dd;
            es__v3_normalize(q);   /* on the sphere up to rounding; keep it there */
        }
        o2 = centroid(c, y, a, gn);
        if (o2 < *off) {
            memcpy(x, y, 3 * (size_t)c->nv * sizeof *x);
            memcpy(g, gn, sizeof g);
            *off = o2;
            taken++;
            beta = fmin(2 * beta, 64);
        } else {
            beta = fmax(0.25 * beta, 1e-3);
        }
    }
    return taken;
}

/* u from the sphere's chordal lengths by least squares (step 6). */
static es_status factors_from(cf *c, es__spd *spd, const double *x, double *u, double *resid)
{
    int64_t nz = c->nv + c->ne, id;
    int64_t *ti = es__alloc_array(c->ctx, 2 * nz, sizeof *ti);
    double *tv = es__alloc_array(c->ctx, nz + c->ne, sizeof *tv), *b = tv + nz;
    es_status rc = ti && tv ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK) {
        int64_t *tj = ti + nz;
        for (int64_t v = 0; v < c->nv; v++) ti[v] = tj[v] = v, tv[v] = 0, u[v] = 0;
        for (int64_t e = 0; e < c->ne; e++) {
            int64_t p = c->ed[2 * e], q = c->ed[2 * e + 1];
            double d[3];
            es__v3_sub(x + 3 * p, x + 3 * q, d);
            b[e] = 2 * log(sqrt(es__v3_dot(d, d)) / c->len[e]);
            ti[c->nv + e] = p, tj[c->nv + e] = q, tv[c->nv + e] = 1;
            tv[p] += 1, tv[q] += 1;
            u[p] += b[e], u[q] += b[e];
        }
        rc = es__spd_add(spd, c->nv, nz, ti, tj, tv, "conformal factors", &id);
        if (rc == ES_OK) rc = es__spd_solve(spd, id, 1, u, c->nv);
        *resid = 0;
        for (int64_t e = 0; rc == ES_OK && e < c->ne; e++)
            *resid = fmax(*resid, fabs(u[c->ed[2 * e]] + u[c->ed[2 * e + 1]] - b[e]));
    }
    es__free(c->ctx, ti);
    es__free(c->ctx, tv);
    return rc;
}

static es_status check_sphere_topology(es_ctx *ctx, const es_mesh *m)
{
    es_mesh_summary s;
    es_mesh_summarize(m, &s);
    if (s.n_boundary_edges || s.n_components != 1 || s.euler != 2 || s.n_unreferenced)
        ES_FAIL(ctx, ES_EINVAL, "conformal: the mesh must be closed, genus 0 and in one piece "
                "(has %lld boundary loops, %lld components, Euler characteristic %lld, %lld "
                "vertices in no face; es_conformal_close closes holes)",
                (long long)s.n_boundary_loops, (long long)s.n_components, (long long)s.euler,
                (long long)s.n_unreferenced);
    return ES_OK;
}

es_status es_conformal_sphere(es_ctx *ctx, const es_mesh *mesh, const double *len,
                              int64_t infinity, double *u, double *sphere,
                              es_conformal_info *info)
{
    cf c;
    es__spd *spd = NULL;
    double *buf = NULL, *x, *p, *area, mean = 0, off = 0, sum_l = 0, sum_s = 0, resid = 0;
    es_conformal_info inf;
    es_status rc;
    memset(&c, 0, sizeof c);
    memset(&inf, 0, sizeof inf);
    if (!mesh || !len || !u) ES_FAIL(ctx, ES_EINVAL, "conformal: NULL argument");
    if ((rc = check_sphere_topology(ctx, mesh)) != ES_OK) return rc;
    c.ctx = ctx, c.m = mesh, c.len = len;
    c.nv = es_mesh_nverts(mesh), c.ne = es_mesh_nedges(mesh), c.nf = es_mesh_nfaces(mesh);
    c.F = es_mesh_faces(mesh), c.fe = es_mesh_face_edges(mesh), c.ed = es_mesh_edges(mesh);
    for (int64_t e = 0; e < c.ne; e++)
        if (!(isfinite(len[e]) && len[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "conformal: edge %lld has length %g (must be finite and "
                    "positive)", (long long)e, len[e]);
    {
        const int64_t *off_s = es_mesh_star_offsets(mesh);
        if (infinity < 0)   /* the vertex of largest degree: a closed hole's apex */
            for (int64_t v = 0, best = -1; v < c.nv; v++)
                if (off_s[v + 1] - off_s[v] > best) best = off_s[v + 1] - off_s[v], infinity = v;
        if (infinity >= c.nv)
            ES_FAIL(ctx, ES_EINVAL, "conformal: vertex %lld sent to infinity is not in the "
                    "mesh", (long long)infinity);
        c.inf = infinity;
    }
    buf = es__alloc_array(ctx, 14 * c.nv + c.ne + 3 * c.nf, sizeof *buf);
    c.idx = es__alloc_array(ctx, c.nv, sizeof *c.idx);
    if (!buf || !c.idx) {
        rc = ES_ENOMEM;
        goto done;
    }
    c.w = buf, c.lam = c.w + c.nv, c.ang = c.lam + c.ne, c.res = c.ang + 3 * c.nf;
    c.dir = c.res + c.nv, c.w0 = c.dir + c.nv, p = c.w0 + c.nv, x = p + 2 * c.nv;
    area = x + 3 * c.nv;
    /* roles: v_inf, its link (boundary of the disk), the rest (unknowns) */
    {
        const int64_t *so = es_mesh_star_offsets(mesh), *sv = es_mesh_star_verts(mesh);
        int64_t deg = so[c.inf + 1] - so[c.inf];
        for (int64_t v = 0; v < c.nv; v++) c.idx[v] = 0, c.w[v] = 0;
        c.idx[c.inf] = -2;
        for (int64_t k = so[c.inf]; k < so[c.inf + 1]; k++) {
            c.idx[sv[k]] = -1;
            mean += len[es_mesh_find_edge(mesh, c.inf, sv[k])] / (double)deg;
        }
        for (int64_t k = so[c.inf]; k < so[c.inf + 1]; k++)
            c.w[sv[k]] = -2 * log(len[es_mesh_find_edge(mesh, c.inf, sv[k])] / mean);
        for (int64_t v = 0; v < c.nv; v++)
            if (c.idx[v] == 0) c.idx[v] = c.nint++;
    }
    if ((rc = es__spd_new(ctx, &spd)) != ES_OK) goto done;
    if (c.nint > 0 && (rc = flatten(&c, spd, &inf.newton_iters, &inf.angle_defect)) != ES_OK)
        goto done;
    if (c.nint == 0) residuals(&c, c.w);
    if ((rc = layout(&c, p)) != ES_OK) goto done;
    /* centred, unit RMS radius, then onto the sphere; v_inf at the pole */
    {
        double cx = 0, cy = 0, rr = 0, n = (double)(c.nv - 1);
        for (int64_t v = 0; v < c.nv; v++)
            if (v != c.inf) cx += p[2 * v] / n, cy += p[2 * v + 1] / n;
        for (int64_t v = 0; v < c.nv; v++)
            if (v != c.inf) {
                p[2 * v] -= cx, p[2 * v + 1] -= cy;
                rr += (p[2 * v] * p[2 * v] + p[2 * v + 1] * p[2 * v + 1]) / n;
            }
        rr = sqrt(rr);
        for (int64_t v = 0; v < c.nv; v++) {
            double px = p[2 * v] / rr, py = p[2 * v + 1] / rr, q = px * px + py * py;
            if (v == c.inf) {
                x[3 * v] = x[3 * v + 1] = 0, x[3 * v + 2] = 1;
                continue;
            }
            x[3 * v] = 2 * px / (1 + q), x[3 * v + 1] = 2 * py / (1 + q);
            x[3 * v + 2] = (q - 1) / (1 + q);
        }
    }
    inf.mobius_iters = centre(&c, x, area + c.nv, area, &off);
    inf.centre_offset = off;
    /* the projection reverses orientation (the plane's counter-clockwise
     * faces, seen from outside the sphere, turn clockwise): mirrored so that
     * the faces' normals point outward, as a mesh's usually do (a reflection
     * keeps every length). Inside out, the sphere's dihedrals interpolated
     * with the face's crumpled every middle frame of the morph. */
    {
        double vol = 0;
        for (int64_t f = 0; f < c.nf; f++) {
            const double *p0 = x + 3 * c.F[3 * f], *p1 = x + 3 * c.F[3 * f + 1];
            const double *p2 = x + 3 * c.F[3 * f + 2];
            double cr[3];
            es__v3_cross(p1, p2, cr);
            vol += es__v3_dot(p0, cr) / 6;
        }
        if (vol < 0)
            for (int64_t v = 0; v < c.nv; v++) x[3 * v] = -x[3 * v];
    }
    /* the input's length sum */
    for (int64_t e = 0; e < c.ne; e++) {
        double d[3];
        es__v3_sub(x + 3 * c.ed[2 * e], x + 3 * c.ed[2 * e + 1], d);
        sum_s += sqrt(es__v3_dot(d, d));
        sum_l += len[e];
    }
    inf.radius = sum_l / sum_s;
    for (int64_t i = 0; i < 3 * c.nv; i++) x[i] *= inf.radius;
    if ((rc = factors_from(&c, spd, x, u, &resid)) != ES_OK) goto done;
    inf.factor_residual = resid;
    inf.infinity = c.inf;
    inf.u_min = INFINITY, inf.u_max = -INFINITY;
    for (int64_t v = 0; v < c.nv; v++)
        inf.u_min = fmin(inf.u_min, u[v]), inf.u_max = fmax(inf.u_max, u[v]);
    /* Faces the flat map breaks make the sphere miss the factors on their
     * long sides (facecap's two obtuse lip triangles: 0.0037 in log);
     * CETM's way out, intrinsic edge flips, would make eq. 13 fail on the
     * flipped edges instead. Long protrusions shrink exponentially under a
     * conformal map to the sphere (goast_finger: u down to -29, its tip's
     * vertices 1e-13 radii apart): there the chordal lengths keep no
     * digits and realize no factors. Refused rather than returned: a miss
     * above 1e-6 without broken faces, or above 0.25 with them (Spacetime
     * Faces: one broken face, 0.14 on its long side, and the k = 1 frame
     * still within 0.52 % of the radius everywhere). */
    for (int64_t f = 0; f < c.nf; f++) inf.broken_faces += disk_face(&c, f) && broken(&c, f);
    if (!(resid <= (inf.broken_faces ? 0.25 : 1e-6))) {
        rc = inf.broken_faces
                 ? es__fail(ctx, ES_ENUMERIC, "conformal: the flat map breaks %lld triangles "
                            "(the first the mesh's face %lld) and the sphere misses the factors "
                            "by %.3g (log scale) there; remesh the obtuse triangles",
                            (long long)inf.broken_faces, (long long)first_broken(&c), resid)
                 : es__fail(ctx, ES_ENUMERIC, "conformal: the sphere's lengths miss the factors "
                            "by %.3g (log scale): the map shrinks part of the mesh beyond double "
                            "precision (u down to %.3g: a long protrusion); a rounder shape "
                            "maps", resid, inf.u_min);
        goto done;
    }
    if (sphere) memcpy(sphere, x, 3 * (size_t)c.nv * sizeof *x);
    if (info) *info = inf;
done:
    es__spd_free(spd);
    es__free(ctx, buf);
    es__free(ctx, c.idx);
    es__free(ctx, c.ti);
    es__free(ctx, c.tv);
    es__free(ctx, c.slot);
    return rc;
}

es_status es_conformal_lengths(es_ctx *ctx, const es_mesh *mesh, const double *len,
                               const double *u, double k, double *out)
{
    const int64_t *ed;
    if (!mesh || !len || !u || !out) ES_FAIL(ctx, ES_EINVAL, "conformal: NULL argument");
    if (!isfinite(k)) ES_FAIL(ctx, ES_EINVAL, "conformal: k is not finite");
    ed = es_mesh_edges(mesh);
    for (int64_t e = 0; e < es_mesh_nedges(mesh); e++) {
        out[e] = len[e] * exp(0.5 * k * (u[ed[2 * e]] + u[ed[2 * e + 1]]));
        if (!(isfinite(out[e]) && out[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "conformal: at k = %g edge %lld gets length %g", k,
                    (long long)e, out[e]);
    }
    return ES_OK;
}

es_status es_conformal_frame(es_ctx *ctx, es_embedder *emb, const double *xyz,
                             const double *sphere, const double *u, double k,
                             const double *start, const es_embed_opts *opts, double *out,
                             es_embed_report *report)
{
    const es_mesh *m = emb ? es_embedder_mesh(emb) : NULL;
    int64_t ne;
    double *len, *lk, *alpha, w[2] = {1 - k, k};
    const double *in[2] = {xyz, sphere};
    es_status rc;
    if (!m || !xyz || !sphere || !u || !out) ES_FAIL(ctx, ES_EINVAL, "conformal: NULL argument");
    ne = es_mesh_nedges(m);
    if (!(len = es__alloc_array(ctx, 3 * ne, sizeof *len))) return ES_ENOMEM;
    lk = len + ne, alpha = lk + ne;
    /* lengths from the factors; the dihedrals of the two ends interpolated
     * along the shortest arc (the paper: "as usual") */
    if ((rc = es_edge_lengths(ctx, m, xyz, len)) == ES_OK &&
        (rc = es_conformal_lengths(ctx, m, len, u, k, lk)) == ES_OK &&
        (rc = es_interp_targets(ctx, m, 2, in, w, NULL, alpha, NULL)) == ES_OK)
        rc = es_embed_solve(ctx, emb, lk, 0, alpha, start ? start : xyz, opts, out, report);
    es__free(ctx, len);
    return rc;
}
