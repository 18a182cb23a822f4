/* tests/mesh/test_mesh.c — topology: edges, face/edge maps, fans, boundary
 * loops, components, Euler characteristic and genus, fingerprints, every
 * rejection with its message; with ../shared present, fans against the
 * embedding oracle and every real mesh of ../shared/data.
 *
 */
#include "edgespace/edgespace.h"
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"

#include <dirent.h>

/* ---- meshes from files, through the io module's reader ---- */

typedef struct obj { int64_t nv, nf; double *xyz; int64_t *faces; es_meshdata md; } obj;

static es_ctx *io_ctx;

static void obj_free(obj *o)
{
    es_meshdata_clear(io_ctx, &o->md);
    memset(o, 0, sizeof *o);
}

static int obj_read(const char *path, obj *o)
{
    memset(o, 0, sizeof *o);
    if (es_meshdata_read(io_ctx, path, ES_FORMAT_OBJ, &o->md) != ES_OK) {
        fprintf(stderr, "%s\n", es_ctx_errmsg(io_ctx));
        return -1;
    }
    o->nv = o->md.nverts;
    o->nf = o->md.nfaces;
    o->xyz = o->md.xyz;
    o->faces = o->md.faces;
    return 0;
}

/* ---- generic invariants every built mesh must satisfy ---- */

static void check_invariants(const es_mesh *m)
{
    int64_t nv = es_mesh_nverts(m), nf = es_mesh_nfaces(m), ne = es_mesh_nedges(m);
    const int64_t *F = es_mesh_faces(m), *E = es_mesh_edges(m);
    const int64_t *FE = es_mesh_face_edges(m), *EF = es_mesh_edge_faces(m);
    const int64_t *so = es_mesh_star_offsets(m), *sv = es_mesh_star_verts(m);
    const int64_t *se = es_mesh_star_edges(m), *sf = es_mesh_star_faces(m);
    const uint8_t *vb = es_mesh_vertex_on_boundary(m), *eb = es_mesh_edge_on_boundary(m);
    int bad = 0;

    for (int64_t e = 0; e < ne; e++) {
        bad += E[2 * e] >= E[2 * e + 1];
        if (e > 0)
            bad += !(E[2 * e - 2] < E[2 * e] ||
                     (E[2 * e - 2] == E[2 * e] && E[2 * e - 1] < E[2 * e + 1]));
        bad += es_mesh_find_edge(m, E[2 * e], E[2 * e + 1]) != e;
        bad += es_mesh_find_edge(m, E[2 * e + 1], E[2 * e]) != e;
        bad += eb[e] != (EF[2 * e] < 0 || EF[2 * e + 1] < 0);
        bad += EF[2 * e] < 0 && EF[2 * e + 1] < 0;
        for (int r = 0; r < 2; r++) {
            int64_t f = EF[2 * e + r], from = E[2 * e + r], to = E[2 * e + 1 - r];
            if (f < 0) continue;
            int found = 0;
            for (int k = 0; k < 3; k++)
                found += F[3 * f + k] == from && F[3 * f + (k + 1) % 3] == to &&
                         FE[3 * f + k] == e;
            bad += found != 1;
        }
    }
    ES_CHECK_MSG(bad == 0, "%d edge invariant violations", bad);

    bad = 0;
    int64_t *seen = calloc((size_t)(3 * nf + 1), sizeof *seen);
    for (int64_t v = 0; v < nv; v++) {
        int64_t k = so[v + 1] - so[v], nfan = vb[v] ? k - 1 : k;
        for (int64_t j = 0; j < k; j++) {
            bad += se[so[v] + j] != es_mesh_find_edge(m, v, sv[so[v] + j]);
            if (j >= nfan) { bad += sf[so[v] + j] != -1; continue; }
            int64_t f = sf[so[v] + j], u0 = sv[so[v] + j], u1 = sv[so[v] + (j + 1) % k];
            int ok = 0;
            for (int c = 0; c < 3; c++)
                if (F[3 * f + c] == v && F[3 * f + (c + 1) % 3] == u0 &&
                    F[3 * f + (c + 2) % 3] == u1) {
                    ok = 1;
                    seen[3 * f + c]++;
                }
            bad += !ok;
        }
        if (k > 0 && !vb[v]) /* interior fans start at the smallest neighbour */
            for (int64_t j = 1; j < k; j++) bad += sv[so[v] + j] < sv[so[v]];
        if (k > 0 && vb[v]) {
            bad += !eb[se[so[v]]] || !eb[se[so[v] + k - 1]];
            for (int64_t j = 1; j + 1 < k; j++) bad += eb[se[so[v] + j]];
        }
    }
    for (int64_t c = 0; c < 3 * nf; c++) bad += seen[c] != 1; /* every corner once */
    free(seen);
    ES_CHECK_MSG(bad == 0, "%d star invariant violations", bad);

    /* boundary loops follow the boundary half-edges */
    const int64_t *lo, *lv;
    int64_t nl = es_mesh_boundary_loops(m, &lo, &lv), nbv = 0;
    bad = 0;
    for (int64_t i = 0; i < nl; i++) {
        int64_t n = lo[i + 1] - lo[i];
        nbv += n;
        for (int64_t j = 0; j < n; j++) {
            int64_t a = lv[lo[i] + j], b = lv[lo[i] + (j + 1) % n];
            int64_t e = es_mesh_find_edge(m, a, b);
            bad += e < 0 || !eb[e] || EF[2 * e + (a < b ? 0 : 1)] < 0;
        }
    }
    es_mesh_summary s;
    es_mesh_summarize(m, &s);
    ES_CHECK_MSG(bad == 0, "%d loop violations", bad);
    ES_CHECK(nbv == s.n_boundary_verts);
    ES_CHECK(s.n_boundary_loops == nl);
    ES_CHECK(s.nverts == nv && s.nedges == ne && s.nfaces == nf);
    ES_CHECK(s.euler == nv - s.n_unreferenced - ne + nf);
}

/* Geometric CCW test: consecutive spokes turn positively about the outward
 * direction `dir(v)` (given per vertex by the caller). */
static int ccw_violations(const es_mesh *m, const double *xyz, const double *dirs)
{
    const int64_t *so = es_mesh_star_offsets(m), *sv = es_mesh_star_verts(m);
    const uint8_t *vb = es_mesh_vertex_on_boundary(m);
    int bad = 0;
    for (int64_t v = 0; v < es_mesh_nverts(m); v++) {
        int64_t k = so[v + 1] - so[v], nfan = vb[v] ? k - 1 : k;
        for (int64_t j = 0; j < nfan; j++) {
            const double *p = xyz + 3 * v, *a = xyz + 3 * sv[so[v] + j];
            const double *b = xyz + 3 * sv[so[v] + (j + 1) % k], *d = dirs + 3 * v;
            double x[3] = {a[0] - p[0], a[1] - p[1], a[2] - p[2]};
            double y[3] = {b[0] - p[0], b[1] - p[1], b[2] - p[2]};
            double c[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                           x[0] * y[1] - x[1] * y[0]};
            bad += c[0] * d[0] + c[1] * d[1] + c[2] * d[2] <= 0;
        }
    }
    return bad;
}

static es_mesh *build(es_ctx *ctx, int64_t nv, int64_t nf, const int64_t *f, const double *x)
{
    es_mesh *m = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, nv, nf, f, x, &m));
    if (m) check_invariants(m);
    return m;
}

static void check_summary(const es_mesh *m, int64_t loops, int64_t comps, int64_t euler,
                          int64_t genus)
{
    es_mesh_summary s;
    es_mesh_summarize(m, &s);
    ES_CHECK_MSG(s.n_boundary_loops == loops, "loops %lld want %lld",
                 (long long)s.n_boundary_loops, (long long)loops);
    ES_CHECK_MSG(s.n_components == comps, "components %lld want %lld",
                 (long long)s.n_components, (long long)comps);
    ES_CHECK_MSG(s.euler == euler, "euler %lld want %lld", (long long)s.euler,
                 (long long)euler);
    ES_CHECK_MSG(s.genus == genus, "genus %lld want %lld", (long long)s.genus,
                 (long long)genus);
}

/* outward directions = position - centroid (convex closed shapes) */
static double *radial_dirs(int64_t nv, const double *xyz)
{
    double c[3] = {0, 0, 0}, *d = malloc((size_t)nv * 3 * sizeof *d);
    for (int64_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) c[k] += xyz[3 * v + k] / (double)nv;
    for (int64_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) d[3 * v + k] = xyz[3 * v + k] - c[k];
    return d;
}

/* ---- small closed and open meshes ---- */

static const double tet_xyz[] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
static const int64_t tet_faces[] = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};

static const double cube_xyz[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                  0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
static const int64_t cube_faces[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                     1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};

static void test_closed(es_ctx *ctx)
{
    es_mesh *m = build(ctx, 4, 4, tet_faces, tet_xyz);
    if (m) {
        ES_CHECK(es_mesh_nedges(m) == 6);
        check_summary(m, 0, 1, 2, 0);
        double *d = radial_dirs(4, tet_xyz);
        ES_CHECK(ccw_violations(m, tet_xyz, d) == 0);
        free(d);
        for (int64_t v = 0; v < 4; v++)
            ES_CHECK(es_mesh_star_offsets(m)[v + 1] - es_mesh_star_offsets(m)[v] == 3);
        ES_CHECK(es_mesh_xyz(m) != NULL && es_mesh_xyz(m)[3] == 1.0);
        ES_CHECK(es_mesh_find_edge(m, 0, 0) == -1 && es_mesh_find_edge(m, 0, 9) == -1);
    }
    es_mesh_free(m);

    m = build(ctx, 8, 12, cube_faces, cube_xyz);
    if (m) {
        ES_CHECK(es_mesh_nedges(m) == 18);
        check_summary(m, 0, 1, 2, 0);
        double *d = radial_dirs(8, cube_xyz);
        ES_CHECK(ccw_violations(m, cube_xyz, d) == 0);
        free(d);
        ES_CHECK(es_mesh_find_edge(m, 0, 6) == -1); /* no space diagonal */
        ES_CHECK(es_mesh_find_edge(m, 0, 2) >= 0);  /* face diagonal */
    }
    es_mesh_free(m);
}

/* Disc: centre 0 plus rings of n vertices at radii 1..r, flat in z = 0,
 * faces counter-clockwise seen from +z. */
static int64_t disc(int64_t n, int64_t rings, double **xyz, int64_t **faces)
{
    int64_t nv = 1 + n * rings, nf = n + 2 * n * (rings - 1), f = 0;
    *xyz = calloc((size_t)nv * 3, sizeof **xyz);
    *faces = malloc((size_t)nf * 3 * sizeof **faces);
    for (int64_t r = 0; r < rings; r++)
        for (int64_t i = 0; i < n; i++) {
            double t = 2 * M_PI * ((double)i + 0.5 * (double)r) / (double)n;
            (*xyz)[3 * (1 + r * n + i)] = (double)(r + 1) * cos(t);
            (*xyz)[3 * (1 + r * n + i) + 1] = (double)(r + 1) * sin(t);
        }
    for (int64_t i = 0; i < n; i++) {
        int64_t *t = *faces + 3 * f++;
        t[0] = 0; t[1] = 1 + i; t[2] = 1 + (i + 1) % n;
    }
    for (int64_t r = 1; r < rings; r++)
        for (int64_t i = 0; i < n; i++) {
            int64_t a = 1 + (r - 1) * n + i, b = 1 + (r - 1) * n + (i + 1) % n;
            int64_t c = 1 + r * n + i, d = 1 + r * n + (i + 1) % n;
            int64_t *t = *faces + 3 * f++;
            t[0] = a; t[1] = c; t[2] = d;
            t = *faces + 3 * f++;
            t[0] = a; t[1] = d; t[2] = b;
        }
    return nf;
}

static void test_disc(es_ctx *ctx)
{
    double *xyz;
    int64_t *faces, n = 12, rings = 3;
    int64_t nf = disc(n, rings, &xyz, &faces), nv = 1 + n * rings;
    es_mesh *m = build(ctx, nv, nf, faces, xyz);
    if (m) {
        check_summary(m, 1, 1, 1, 0);
        es_mesh_summary s;
        es_mesh_summarize(m, &s);
        ES_CHECK(s.n_boundary_verts == n && s.n_boundary_edges == n);
        double *up = calloc((size_t)nv * 3, sizeof *up);
        for (int64_t v = 0; v < nv; v++) up[3 * v + 2] = 1;
        ES_CHECK(ccw_violations(m, xyz, up) == 0);
        free(up);
        /* the outer boundary runs counter-clockwise seen from +z */
        const int64_t *lo, *lv;
        es_mesh_boundary_loops(m, &lo, &lv);
        double area = 0;
        for (int64_t j = 0; j < n; j++) {
            const double *a = xyz + 3 * lv[j], *b = xyz + 3 * lv[(j + 1) % n];
            area += a[0] * b[1] - a[1] * b[0];
        }
        ES_CHECK(area > 0);
        /* a boundary vertex's fan: k neighbours, k-1 faces, starts at the
         * boundary spoke whose face follows counter-clockwise */
        int64_t v = 1 + (rings - 1) * n;
        const int64_t *so = es_mesh_star_offsets(m), *sf = es_mesh_star_faces(m);
        ES_CHECK(es_mesh_vertex_on_boundary(m)[v] && !es_mesh_vertex_on_boundary(m)[0]);
        ES_CHECK(sf[so[v + 1] - 1] == -1 && sf[so[v]] >= 0);
        ES_CHECK(es_mesh_star_verts(m)[so[v]] == v + 1);
    }
    es_mesh_free(m);
    free(xyz);
    free(faces);
}

/* Torus grid n x k, wrapped both ways. */
static int64_t torus(int64_t n, int64_t k, double **xyz, int64_t **faces)
{
    int64_t f = 0;
    *xyz = malloc((size_t)(n * k) * 3 * sizeof **xyz);
    *faces = malloc((size_t)(2 * n * k) * 3 * sizeof **faces);
    for (int64_t i = 0; i < n; i++)
        for (int64_t j = 0; j < k; j++) {
            double u = 2 * M_PI * (double)i / (double)n, w = 2 * M_PI * (double)j / (double)k;
            double *p = *xyz + 3 * (i * k + j);
            p[0] = (3 + cos(w)) * cos(u);
            p[1] = (3 + cos(w)) * sin(u);
            p[2] = sin(w);
            int64_t a = i * k + j, b = ((i + 1) % n) * k + j, c = ((i + 1) % n) * k + (j + 1) % k;
            int64_t d = i * k + (j + 1) % k;
            int64_t *t = *faces + 3 * f++;
            t[0] = a; t[1] = b; t[2] = c;
            t = *faces + 3 * f++;
            t[0] = a; t[1] = c; t[2] = d;
        }
    return f;
}

static void test_torus_and_components(es_ctx *ctx)
{
    double *xyz;
    int64_t *faces;
    int64_t nf = torus(12, 8, &xyz, &faces);
    es_mesh *m = build(ctx, 96, nf, faces, xyz);
    if (m) {
        check_summary(m, 0, 1, 0, 1);
        /* outward normal of the torus at a vertex: away from the tube core */
        double *d = malloc(96 * 3 * sizeof *d);
        for (int64_t v = 0; v < 96; v++) {
            double *p = xyz + 3 * v, r = hypot(p[0], p[1]);
            d[3 * v] = p[0] - 3 * p[0] / r;
            d[3 * v + 1] = p[1] - 3 * p[1] / r;
            d[3 * v + 2] = p[2];
        }
        ES_CHECK(ccw_violations(m, xyz, d) == 0);
        free(d);
    }
    es_mesh_free(m);
    free(xyz);
    free(faces);

    /* two tetrahedra (the second listed first) plus a disc */
    int64_t two[24];
    for (int i = 0; i < 12; i++) two[i] = tet_faces[i] + 4;
    for (int i = 0; i < 12; i++) two[12 + i] = tet_faces[i];
    m = build(ctx, 8, 8, two, NULL);
    if (m) {
        check_summary(m, 0, 2, 4, 0);
        const int64_t *comp = es_mesh_vertex_component(m);
        ES_CHECK(comp[0] == 0 && comp[3] == 0 && comp[4] == 1 && comp[7] == 1);
        ES_CHECK(es_mesh_xyz(m) == NULL);
    }
    es_mesh_free(m);

    /* a tetrahedron and an open disc: genus sums, loops count */
    double *dx;
    int64_t *df;
    int64_t dnf = disc(6, 2, &dx, &df), dnv = 13;
    int64_t *mix = malloc((size_t)(4 + dnf) * 3 * sizeof *mix);
    for (int64_t i = 0; i < 3 * dnf; i++) mix[i] = df[i];
    for (int i = 0; i < 12; i++) mix[3 * dnf + i] = tet_faces[i] + dnv;
    m = build(ctx, dnv + 4, dnf + 4, mix, NULL);
    if (m) check_summary(m, 1, 2, 3, 0);
    es_mesh_free(m);
    free(mix);
    free(dx);
    free(df);
}

/* ---- rejections, each with its message ---- */

typedef struct log_capture { int n; char last[512]; } log_capture;
static void capture(void *ud, es_log_level level, const char *msg)
{
    log_capture *c = ud;
    (void)level;
    c->n++;
    snprintf(c->last, sizeof c->last, "%s", msg);
}

static void test_rejections(es_ctx *ctx)
{
    es_mesh *m = (es_mesh *)1;
    int64_t range[] = {0, 1, 2, 0, 2, 7};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 4, 2, range, NULL, &m), ES_ETOPOLOGY,
                   "face 1: vertex index 7 out of range");
    ES_CHECK(m == NULL);
    double bad_xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    int64_t tri[] = {0, 1, 2};
    bad_xyz[3 * 2 + 1] = NAN;   /* the reference embeddings align to */
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 4, 1, tri, bad_xyz, &m), ES_EINVAL,
                   "vertex 2 has a non-finite coordinate");
    int64_t neg[] = {0, -1, 2};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 4, 1, neg, NULL, &m), ES_ETOPOLOGY,
                   "face 0: vertex index -1");
    int64_t rep[] = {0, 1, 2, 3, 1, 3};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 4, 2, rep, NULL, &m), ES_ETOPOLOGY,
                   "face 1 (3, 1, 3) repeats a vertex");
    int64_t dup[] = {0, 1, 2, 1, 3, 2, 2, 0, 1};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 4, 3, dup, NULL, &m), ES_ETOPOLOGY,
                   "faces 0 and 2 are duplicates");
    int64_t flipdup[] = {0, 1, 2, 0, 2, 1};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 3, 2, flipdup, NULL, &m), ES_ETOPOLOGY,
                   "duplicates");
    int64_t three[] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 5, 3, three, NULL, &m), ES_ETOPOLOGY,
                   "edge (0, 1) is shared by 3 faces (0, 1, 2)");
    int64_t orient[] = {0, 1, 2, 0, 1, 3};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 4, 2, orient, NULL, &m), ES_ETOPOLOGY,
                   "faces 0 and 1 both traverse edge 0->1: inconsistent orientation");
    /* orientation flip deep inside a closed mesh */
    int64_t cube_bad[36];
    memcpy(cube_bad, cube_faces, sizeof cube_bad);
    cube_bad[3 * 7 + 1] = cube_faces[3 * 7 + 2];
    cube_bad[3 * 7 + 2] = cube_faces[3 * 7 + 1];
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 8, 12, cube_bad, NULL, &m), ES_ETOPOLOGY,
                   "inconsistent orientation");
    /* bowtie: two tetrahedra sharing vertex 0 (closed fans) */
    int64_t bow[24];
    for (int i = 0; i < 12; i++) bow[i] = tet_faces[i];
    for (int i = 0; i < 12; i++) bow[12 + i] = tet_faces[i] == 0 ? 0 : tet_faces[i] + 3;
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 7, 8, bow, NULL, &m), ES_ETOPOLOGY,
                   "vertex 0 is non-manifold");
    /* two triangles touching at vertex 2 (open fans) */
    int64_t touch[] = {0, 1, 2, 2, 3, 4};
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 5, 2, touch, NULL, &m), ES_ETOPOLOGY,
                   "vertex 2 is non-manifold");
    /* a closed and an open fan at vertex 0 */
    int64_t mixed[12 + 3];
    for (int i = 0; i < 12; i++) mixed[i] = tet_faces[i];
    mixed[12] = 0; mixed[13] = 4; mixed[14] = 5;
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, 6, 5, mixed, NULL, &m), ES_ETOPOLOGY,
                   "vertex 0 is non-manifold");
    ES_CHECK_FAILS(ctx, es_mesh_new(ctx, -1, 0, NULL, NULL, &m), ES_EINVAL, "negative");

    /* unreferenced vertices are allowed, with a warning */
    log_capture cap = {0, ""};
    es_ctx_set_log(ctx, capture, &cap);
    m = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, 6, 4, tet_faces, NULL, &m));
    ES_CHECK(cap.n == 1 && strstr(cap.last, "2 of 6 vertices are in no face (first: 4)"));
    if (m) {
        es_mesh_summary s;
        es_mesh_summarize(m, &s);
        ES_CHECK(s.n_unreferenced == 2 && s.euler == 2 && s.genus == 0);
        ES_CHECK(es_mesh_vertex_component(m)[5] == -1);
        ES_CHECK(es_mesh_star_offsets(m)[6] == es_mesh_star_offsets(m)[4]);
        check_invariants(m);
    }
    es_mesh_free(m);
    es_ctx_set_log(ctx, NULL, NULL);

    /* empty mesh */
    m = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, 0, 0, NULL, NULL, &m));
    if (m) ES_CHECK(es_mesh_nedges(m) == 0);
    es_mesh_free(m);
    es_mesh_free(NULL);
}

/* ---- fingerprint ---- */

static void test_fingerprint(es_ctx *ctx)
{
    char a[17], b[17];
    int64_t one[] = {0, 1, 2};
    /* FNV-1a 64 of the little-endian bytes of (4; 0, 1, 2), computed
     * independently (Python) */
    es_faces_fingerprint(4, 1, one, a);
    ES_CHECK(strcmp(a, "e616bd27c47b6fa2") == 0);
    es_faces_fingerprint(0, 0, NULL, a);
    ES_CHECK(strcmp(a, "a8c7f832281a39c5") == 0);
    es_mesh *m = build(ctx, 8, 12, cube_faces, cube_xyz);
    if (m) {
        es_mesh_fingerprint(m, a);
        es_faces_fingerprint(8, 12, cube_faces, b);
        ES_CHECK(strcmp(a, b) == 0 && strlen(a) == 16);
        es_faces_fingerprint(9, 12, cube_faces, b);
        ES_CHECK(strcmp(a, b) != 0);
    }
    es_mesh_free(m);
}

/* ---- allocation failure sweep ---- */


static void test_alloc_failures(es_ctx *ctx)
{
    double *xyz;
    int64_t *faces, nf = disc(6, 2, &xyz, &faces);
    int ok = 0;
    for (int64_t k = 1; k < 200 && !ok; k++) {
        failing_alloc fa = {0, k, 0};
        es_allocator al = {fa_malloc, fa_realloc, fa_free, &fa};
        es_mesh *m = NULL;
        es_ctx_set_allocator(ctx, &al);
        es_status rc = es_mesh_new(ctx, 13, nf, faces, xyz, &m);
        if (rc == ES_OK) ok = 1;
        else ES_CHECK_MSG(rc == ES_ENOMEM && m == NULL, "k=%lld rc=%d", (long long)k, rc);
        es_mesh_free(m);
        ES_CHECK_MSG(fa.live == 0, "k=%lld: %lld blocks leaked", (long long)k,
                     (long long)fa.live);
        es_ctx_set_allocator(ctx, NULL);
    }
    ES_CHECK(ok);
    free(xyz);
    free(faces);
}

/* ---- large mesh (sizes of the benchmarks; no timing asserted) ---- */

static void test_large(es_ctx *ctx)
{
    double *xyz;
    int64_t *faces, n = 300, k = 195;
    int64_t nf = torus(n, k, &xyz, &faces);
    es_mesh *m = build(ctx, n * k, nf, faces, xyz);
    if (m) {
        ES_CHECK(es_mesh_nedges(m) == 3 * n * k);
        check_summary(m, 0, 1, 0, 1);
    }
    es_mesh_free(m);
    free(xyz);
    free(faces);
}

/* ---- ../shared: oracle fans and the real meshes ---- */

static void test_oracle_fans(es_ctx *ctx)
{
    char buf[8192];
    const char *names[] = {"bumpy_ico2", "hemi2", "tube_small"};
    const int64_t loops[] = {0, 1, 0};
    const char *dir = es_test_shared_path("oracle/embed", buf, sizeof buf);
    if (!dir) {
        fprintf(stderr, "skipping oracle fans: ../shared/oracle/embed absent\n");
        return;
    }
    for (int i = 0; i < 3; i++) {
        char path[8400];
        obj o;
        snprintf(path, sizeof path, "%s/%s/mesh.obj", dir, names[i]);
        if (obj_read(path, &o) != 0) {
            ES_CHECK_MSG(0, "cannot read %s", path);
            continue;
        }
        es_mesh *m = build(ctx, o.nv, o.nf, o.faces, o.xyz);
        snprintf(path, sizeof path, "%s/%s/fans.csv", dir, names[i]);
        FILE *fp = fopen(path, "r");
        if (m && fp) {
            char line[8192];
            int64_t rows = 0, bad = 0;
            const int64_t *so = es_mesh_star_offsets(m), *sv = es_mesh_star_verts(m);
            check_summary(m, loops[i], 1, 2 - loops[i], 0);
            if (!fgets(line, sizeof line, fp)) line[0] = '\0';
            while (fgets(line, sizeof line, fp)) {
                char *p = line, *end;
                long long v = strtoll(p, &end, 10), bnd = strtoll(end + 1, &end, 10);
                int64_t j = 0;
                p = end + 1;
                rows++;
                if (v < 0 || v >= o.nv) { bad++; continue; }
                bad += bnd != es_mesh_vertex_on_boundary(m)[v];
                for (;;) {
                    long long u = strtoll(p, &end, 10);
                    if (end == p) break;
                    bad += so[v] + j >= so[v + 1] || sv[so[v] + j] != u;
                    j++;
                    p = end;
                }
                bad += j != so[v + 1] - so[v];
            }
            ES_CHECK_MSG(rows == o.nv && bad == 0, "%s: %lld rows, %lld mismatches",
                         names[i], (long long)rows, (long long)bad);
        } else {
            ES_CHECK_MSG(fp != NULL, "cannot read %s", path);
        }
        if (fp) fclose(fp);
        es_mesh_free(m);
        obj_free(&o);
    }
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void test_real_meshes(es_ctx *ctx)
{
    /* boundary loop counts from data/SOURCES.md */
    static const struct { const char *dir; int64_t loops; } sets[] = {
        {"face-study", 4}, {"goast_spacetime_faces", 2}, {"facecap_arkit", 4},
        {"sfm_surrey_face_3448", 2}, {"sumner_cat_poses", 0}, {"goast_cactus", 0},
        {"goast_finger", 0}};
    const char *data = es_test_shared_data();
    if (!data) {
        fprintf(stderr, "skipping real meshes: ../shared/data absent\n");
        return;
    }
    for (size_t s = 0; s < sizeof sets / sizeof sets[0]; s++) {
        char path[8400], first_fp[17] = "";
        snprintf(path, sizeof path, "%s/%s", data, sets[s].dir);
        DIR *d = opendir(path);
        if (!d) {
            fprintf(stderr, "skipping %s: absent\n", sets[s].dir);
            continue;
        }
        char *names[512];
        int n = 0;
        struct dirent *de;
        while ((de = readdir(d)) && n < 512) {
            size_t len = strlen(de->d_name);
            if (len > 4 && strcmp(de->d_name + len - 4, ".obj") == 0)
                names[n++] = strdup(de->d_name);
        }
        closedir(d);
        qsort(names, (size_t)n, sizeof *names, cmp_str);
        int64_t nbad = 0;
        for (int i = 0; i < n; i++) {
            obj o;
            char fp[17];
            snprintf(path, sizeof path, "%s/%s/%s", data, sets[s].dir, names[i]);
            if (obj_read(path, &o) != 0) {
                ES_CHECK_MSG(0, "cannot read %s", path);
                free(names[i]);
                continue;
            }
            es_faces_fingerprint(o.nv, o.nf, o.faces, fp);
            {
                es_mesh *m = NULL;
                ES_CHECK_OK(ctx, es_mesh_new(ctx, o.nv, o.nf, o.faces, o.xyz, &m));
                if (m && i == 0) check_invariants(m);
                if (m) {
                    es_mesh_summary sm;
                    es_mesh_summarize(m, &sm);
                    ES_CHECK_MSG(sm.n_boundary_loops == sets[s].loops &&
                                 sm.n_components == 1 && sm.genus == 0,
                                 "%s: %lld loops, %lld components, genus %lld", path,
                                 (long long)sm.n_boundary_loops,
                                 (long long)sm.n_components, (long long)sm.genus);
                }
                es_mesh_free(m);
            }
            if (i == 0) memcpy(first_fp, fp, sizeof fp);
            else nbad += strcmp(fp, first_fp) != 0;
            obj_free(&o);
            free(names[i]);
        }
        ES_CHECK_MSG(n > 0 && nbad == 0, "%s: %d meshes, %lld with another face list",
                     sets[s].dir, n, (long long)nbad);
    }
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK || es_ctx_new(&io_ctx) != ES_OK) return 1;
    test_closed(ctx);
    test_disc(ctx);
    test_torus_and_components(ctx);
    test_rejections(ctx);
    test_fingerprint(ctx);
    test_alloc_failures(ctx);
    test_large(ctx);
    test_oracle_fans(ctx);
    test_real_meshes(ctx);
    es_ctx_free(ctx);
    es_ctx_free(io_ctx);
    ES_TEST_END();
}
