/* tests/embed/test_embed.c — the embedding library (es_embed.h, es_interp.h) on
 * the oracle's reference values (../shared/oracle/embed, skipped when
 * absent) and on meshes made here: closure energy, gradient and per-vertex
 * energies at given dihedrals, the frames-and-positions stages from exact
 * dihedrals, round trips on closed (sphere, torus: genus 1) and open (disc)
 * meshes, a mesh of several pieces, interpolation and extrapolation,
 * garbage in, failure messages on the caller's context.
 */
#include "es_test.h"
#include "mesh_gen.h"
#define ES_MODULE_EMBED   /* the module's own test: its package header too */
#include "embed/embed_pkg.h"

#include <edgespace/edgespace.h>

/* ---- helpers ------------------------------------------------------------ */

/* RMS vertex distance of a onto b after a proper rigid alignment. */
static double aligned_rms(es_ctx *ctx, int64_t nv, const double *a, const double *b)
{
    double *c = malloc(3 * (size_t)nv * sizeof *c), rms = INFINITY;
    memcpy(c, a, 3 * (size_t)nv * sizeof *c);
    if (es_embed_align(ctx, nv, c, b, NULL, &rms) != ES_OK) rms = INFINITY;
    free(c);
    return rms;
}

static int all_finite(const double *x, int64_t n)
{
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(x[i])) return 0;
    return 1;
}

/* Read a CSV of numbers (header skipped) into rows x cols, "nan" allowed. */
static double *read_csv(const char *path, int64_t *rows, int cols)
{
    FILE *f = fopen(path, "r");
    char line[8192];
    int64_t cap = 256, n = 0;
    double *v;
    if (!f) return NULL;
    v = malloc((size_t)cap * cols * sizeof *v);
    if (!fgets(line, sizeof line, f)) {
        fclose(f);
        free(v);
        return NULL;
    }
    while (fgets(line, sizeof line, f)) {
        char *s = line;
        if (n == cap) {
            cap *= 2;
            v = realloc(v, (size_t)cap * cols * sizeof *v);
        }
        for (int c = 0; c < cols; c++) {
            v[n * cols + c] = strtod(s, &s);
            while (*s && *s != ',' && *s != '\n') s++;
            if (*s == ',') s++;
        }
        n++;
    }
    fclose(f);
    *rows = n;
    return v;
}

/* ---- oracle ------------------------------------------------------------- */

static void oracle_case(es_ctx *ctx, const char *dir)
{
    char p[8600];
    es_meshdata md;
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    int64_t nrow, nvr, ncr, nver, ntr;
    double *edges, *verts, *corners, *venergy, *etrue;
    snprintf(p, sizeof p, "%s/mesh.obj", dir);
    ES_CHECK_OK(ctx, es_meshdata_read(ctx, p, ES_FORMAT_OBJ, &md));
    snprintf(p, sizeof p, "%s/vertices.csv", dir);
    verts = read_csv(p, &nvr, 4);
    snprintf(p, sizeof p, "%s/edges.csv", dir);
    edges = read_csv(p, &nrow, 9);
    snprintf(p, sizeof p, "%s/corners.csv", dir);
    corners = read_csv(p, &ncr, 4);
    snprintf(p, sizeof p, "%s/vertex_energy.csv", dir);
    venergy = read_csv(p, &nver, 3);
    snprintf(p, sizeof p, "%s/embed_true.csv", dir);
    etrue = read_csv(p, &ntr, 4);
    ES_CHECK(verts && edges && corners && venergy && etrue);
    if (!(verts && edges && corners && venergy && etrue)) return;
    ES_CHECK(nvr == md.nverts && ntr == md.nverts);
    for (int64_t v = 0; v < md.nverts; v++)
        for (int i = 0; i < 3; i++) md.xyz[3 * v + i] = verts[4 * v + 1 + i];
    ES_CHECK_OK(ctx, es_mesh_new(ctx, md.nverts, md.nfaces, md.faces, md.xyz, &mesh));
    if (!mesh) return;
    int64_t ne = es_mesh_nedges(mesh), nv = md.nverts, nf = md.nfaces;
    const int64_t *ed = es_mesh_edges(mesh);
    const uint8_t *eb = es_mesh_edge_on_boundary(mesh), *vb = es_mesh_vertex_on_boundary(mesh);
    double *len = malloc((size_t)ne * sizeof *len), *at = malloc((size_t)ne * sizeof *at);
    double *a0 = malloc((size_t)ne * sizeof *a0), *g = malloc((size_t)ne * sizeof *g);
    double *ve = malloc((size_t)nv * sizeof *ve), *ang = malloc(3 * (size_t)nf * sizeof *ang);
    double *out = malloc(3 * (size_t)nv * sizeof *out), e0 = 0, etr = 1, esum = 0, gmax = 0;
    ES_CHECK(nrow == ne);
    for (int64_t e = 0; e < ne && e < nrow; e++) {
        ES_CHECK(ed[2 * e] == (int64_t)edges[9 * e + 1] && ed[2 * e + 1] == (int64_t)edges[9 * e + 2]);
        len[e] = edges[9 * e + 3];
        at[e] = eb[e] ? 0 : edges[9 * e + 4];
        a0[e] = eb[e] ? 0 : edges[9 * e + 5];
    }
    /* corner angles: Kahan here, law of cosines there */
    es__corner_angles(mesh, len, 0.0, ang);
    for (int64_t i = 0; i < ncr && i < 3 * nf; i++) {
        int64_t f = (int64_t)corners[4 * i], c = (int64_t)corners[4 * i + 1];
        ES_CHECK_CLOSE(ang[3 * f + c], corners[4 * i + 3], 0, 1e-12);
    }
    /* energy, gradient, per-vertex energies at alpha0; E(alpha_true) ~ 0 */
    ES_CHECK_OK(ctx, es_embed_closure(ctx, mesh, len, a0, &e0, g, ve));
    ES_CHECK_OK(ctx, es_embed_closure(ctx, mesh, len, at, &etr, NULL, NULL));
    ES_CHECK(etr < 1e-24);
    for (int64_t e = 0; e < ne; e++) {
        if (eb[e]) {
            ES_CHECK(g[e] == 0);
            continue;
        }
        gmax = fmax(gmax, fabs(edges[9 * e + 6]));
        ES_CHECK_CLOSE(g[e], edges[9 * e + 6], 1e-11, 1e-12);
    }
    ES_CHECK(gmax > 0);
    for (int64_t i = 0; i < nver; i++) {
        int64_t v = (int64_t)venergy[3 * i];
        ES_CHECK(!vb[v]);
        ES_CHECK_CLOSE(ve[v], venergy[3 * i + 2], 1e-11, 1e-14);
        esum += venergy[3 * i + 2];
    }
    ES_CHECK_CLOSE(e0, esum, 1e-12, 0);

    /* stages 2-3 from the true dihedrals, oracle frame conventions */
    ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        es_embed_opts o;
        es_embed_report r;
        double md_ = 0, diag = es_bbox_diagonal(nv, etrue ? md.xyz : md.xyz);
        es_embed_opts_init(&o);
        o.dihedral_mode = ES_EMBED_DIHEDRAL_OFF;
        o.refine_max_iter = 0;
        o.align = 0;
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, at, NULL, &o, out, &r));
        for (int64_t v = 0; v < nv; v++)
            for (int i = 0; i < 3; i++) md_ = fmax(md_, fabs(out[3 * v + i] - etrue[4 * v + 1 + i]));
        ES_CHECK_MSG(md_ <= 1e-12 * diag, "%s: stages 2-3 differ by %g (diag %g)", dir, md_, diag);
        ES_CHECK(r.rms_ratio < 1e-12 && r.max_rel < 1e-11);
        /* the whole pipeline from alpha0 realizes the lengths */
        es_embed_opts_init(&o);
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, a0, NULL, &o, out, &r));
        ES_CHECK_MSG(r.rms_ratio < 1e-8 && r.max_rel < 1e-7, "%s: from alpha0 rms %g max %g", dir,
                     r.rms_ratio, r.max_rel);
        ES_CHECK(r.closure_before > 1 && r.closure_after < 1e-12);
        ES_CHECK(es_embedder_vertex_closure(emb) != NULL);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    es_meshdata_clear(ctx, &md);
    free(len), free(at), free(a0), free(g), free(ve), free(ang), free(out);
    free(edges), free(verts), free(corners), free(venergy), free(etrue);
}

static void test_oracle(es_ctx *ctx)
{
    char buf[8192], p[8400];
    const char *dir = es_test_shared_path("oracle/embed", buf, sizeof buf);
    const char *names[] = {"bumpy_ico2", "hemi2", "tube_small"};
    if (!dir) {
        fprintf(stderr, "note: ../shared/oracle/embed absent, oracle checks skipped\n");
        return;
    }
    for (int i = 0; i < 3; i++) {
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        oracle_case(ctx, p);
    }
}

/* ---- round trips on meshes made here ------------------------------------ */

/* A bumpy icosphere (closed, genus 0): the icosahedron subdivided `levels`
 * times, radius modulated so that the surface is not a sphere. */
static tm_mesh icosphere(int levels)
{
    static const double X = 0.525731112119133606, Z = 0.850650808352039932;
    static const double v0[12][3] = {{-X, 0, Z}, {X, 0, Z}, {-X, 0, -Z}, {X, 0, -Z},
                                     {0, Z, X},  {0, Z, -X}, {0, -Z, X}, {0, -Z, -X},
                                     {Z, X, 0},  {-Z, X, 0}, {Z, -X, 0}, {-Z, -X, 0}};
    static const int f0[20][3] = {{0, 4, 1},  {0, 9, 4},  {9, 5, 4},  {4, 5, 8},  {4, 8, 1},
                                  {8, 10, 1}, {8, 3, 10}, {5, 3, 8},  {5, 2, 3},  {2, 7, 3},
                                  {7, 10, 3}, {7, 6, 10}, {7, 11, 6}, {11, 0, 6}, {0, 1, 6},
                                  {6, 1, 10}, {9, 0, 11}, {9, 11, 2}, {9, 2, 5},  {7, 2, 11}};
    tm_mesh m;
    int64_t nf = 20, nv = 12, cap = 12;
    for (int l = 0; l < levels; l++) cap = cap + 30 * (int64_t)(1 << (2 * l)) * 1;
    cap = 10 * (int64_t)(1 << (2 * levels)) + 2;
    m.xyz = malloc(3 * (size_t)cap * sizeof *m.xyz);
    m.faces = malloc(3 * 20 * (size_t)(1 << (2 * levels)) * sizeof *m.faces);
    memcpy(m.xyz, v0, sizeof v0);
    for (int f = 0; f < 20; f++)
        for (int k = 0; k < 3; k++) m.faces[3 * f + k] = f0[f][k];
    for (int l = 0; l < levels; l++) {
        /* midpoint of each edge, found by a linear scan of a small table */
        int64_t *ea = malloc(3 * (size_t)nf * sizeof *ea), *eb = malloc(3 * (size_t)nf * sizeof *eb);
        int64_t *em = malloc(3 * (size_t)nf * sizeof *em), ne = 0;
        int64_t *nfc = malloc(12 * (size_t)nf * sizeof *nfc);
        for (int64_t f = 0; f < nf; f++) {
            int64_t mid[3];
            for (int k = 0; k < 3; k++) {
                int64_t a = m.faces[3 * f + k], b = m.faces[3 * f + (k + 1) % 3], i;
                if (a > b) { int64_t t = a; a = b; b = t; }
                for (i = 0; i < ne; i++)
                    if (ea[i] == a && eb[i] == b) break;
                if (i == ne) {
                    double *p = m.xyz + 3 * nv, n = 0;
                    for (int c = 0; c < 3; c++) p[c] = 0.5 * (m.xyz[3 * a + c] + m.xyz[3 * b + c]);
                    n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                    for (int c = 0; c < 3; c++) p[c] /= n;
                    ea[ne] = a, eb[ne] = b, em[ne++] = nv++;
                }
                mid[k] = em[i];
            }
            int64_t c0 = m.faces[3 * f], c1 = m.faces[3 * f + 1], c2 = m.faces[3 * f + 2];
            int64_t t[12] = {c0, mid[0], mid[2], c1, mid[1], mid[0], c2, mid[2], mid[1],
                             mid[0], mid[1], mid[2]};
            memcpy(nfc + 12 * f, t, sizeof t);
        }
        memcpy(m.faces, nfc, 12 * (size_t)nf * sizeof *nfc);
        nf *= 4;
        free(ea), free(eb), free(em), free(nfc);
    }
    for (int64_t v = 0; v < nv; v++) {
        double *p = m.xyz + 3 * v, r = 1 + 0.15 * sin(3 * p[0]) * cos(2 * p[1]) + 0.1 * p[2] * p[2];
        for (int c = 0; c < 3; c++) p[c] *= r;
    }
    m.nv = nv;
    m.nf = nf;
    return m;
}

static void roundtrip(es_ctx *ctx, const char *name, tm_mesh tm, int closed)
{
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    es_rng rng;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, tm.nv, tm.nf, tm.faces, tm.xyz, &mesh));
    if (!mesh) return;
    ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (!emb) {
        es_mesh_free(mesh);
        return;
    }
    int64_t ne = es_mesh_nedges(mesh), nv = tm.nv;
    double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
    double *out = malloc(3 * (size_t)nv * sizeof *out), diag = es_bbox_diagonal(nv, tm.xyz), rms;
    es_embed_report r;
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, tm.xyz, len));
    ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, tm.xyz, al));
    /* exact lengths, own dihedrals */
    ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r));
    rms = aligned_rms(ctx, nv, out, tm.xyz);
    ES_CHECK_MSG(rms <= 1e-9 * diag, "%s: exact round trip vertex rms %g x diag", name, rms / diag);
    /* the output is aligned to the mesh's reference positions already */
    {
        double d = 0;
        for (int64_t i = 0; i < 3 * nv; i++) d += (out[i] - tm.xyz[i]) * (out[i] - tm.xyz[i]);
        ES_CHECK_MSG(sqrt(d / (double)nv) <= 1e-9 * diag, "%s: output not aligned", name);
    }
    /* dihedrals with noise: at 0.005 rad a closed mesh comes back; at 0.05 rad the
     * lengths are realized but near-flat vertices may come back popped through
     * (a mirror image of their star: the same lengths, so not an error of the
     * solver); the distance is printed */
    for (int level = 0; level < 2; level++) {
        double sigma = level ? 0.05 : 0.005;
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, tm.xyz, al));
        es_rng_init(&rng, 7);
        for (int64_t e = 0; e < ne; e++) al[e] += sigma * es_rng_normal(&rng);
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r));
        rms = aligned_rms(ctx, nv, out, tm.xyz);
        fprintf(stderr, "%s: dihedral noise %g rad: rms ratio %.3g max %.3g, vertex rms %.3g x "
                "diag, closure %.3g -> %.3g\n", name, sigma, r.rms_ratio, r.max_rel, rms / diag,
                r.closure_before, r.closure_after);
        if (closed && !level)
            ES_CHECK_MSG(rms <= 1e-6 * diag, "%s: noisy round trip vertex rms %g x diag", name,
                         rms / diag);
        ES_CHECK_MSG(r.rms_ratio <= 1e-6, "%s: noisy round trip rms ratio %g (max %g)", name,
                     r.rms_ratio, r.max_rel);
        ES_CHECK(r.closure_before > r.closure_after);
        ES_CHECK(all_finite(out, 3 * nv));
        /* incoherent dihedrals: auto mode keeps stage 1, also when it may
         * take only the one iteration that decides */
        ES_CHECK_MSG(r.used_stage1 && r.dihedral_iters > 1, "%s: stage 1 dropped on noise", name);
        {
            es_embed_opts one;
            es_embed_opts_init(&one);
            one.dihedral_max_iter = 1;
            ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, &one, out, &r));
            ES_CHECK_MSG(r.used_stage1 && r.dihedral_iters == 1, "%s: max 1 iteration: used %d, "
                         "%lld iterations", name, r.used_stage1, (long long)r.dihedral_iters);
        }
    }
    /* scale: embedding at scale s gives edge lengths summing to s */
    ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 3.5, NULL, tm.xyz, NULL, out, &r));
    {
        double s = 0;
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, out, len));
        for (int64_t e = 0; e < ne; e++) s += len[e];
        ES_CHECK_CLOSE(s, 3.5, 1e-9, 0);
        ES_CHECK_CLOSE(r.scale, 3.5, 1e-15, 0);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    free(len), free(al), free(out);
}

/* Keep the faces of m with every corner in zlo < z < zhi (an open band with
 * two holes when cut from a sphere), drop the vertices left unused. */
static tm_mesh band(tm_mesh m, double zlo, double zhi)
{
    tm_mesh b;
    int64_t *map = malloc((size_t)m.nv * sizeof *map);
    b.xyz = malloc(3 * (size_t)m.nv * sizeof *b.xyz);
    b.faces = malloc(3 * (size_t)m.nf * sizeof *b.faces);
    b.nv = b.nf = 0;
    for (int64_t v = 0; v < m.nv; v++) map[v] = -1;
    for (int64_t f = 0; f < m.nf; f++) {
        int keep = 1;
        for (int k = 0; k < 3; k++) {
            double z = m.xyz[3 * m.faces[3 * f + k] + 2];
            if (!(z > zlo && z < zhi)) keep = 0;
        }
        if (!keep) continue;
        for (int k = 0; k < 3; k++) {
            int64_t v = m.faces[3 * f + k];
            if (map[v] < 0) {
                memcpy(b.xyz + 3 * b.nv, m.xyz + 3 * v, 3 * sizeof *b.xyz);
                map[v] = b.nv++;
            }
            b.faces[3 * b.nf + k] = map[v];
        }
        b.nf++;
    }
    free(map);
    return b;
}

static void test_roundtrips(es_ctx *ctx)
{
    tm_mesh s = icosphere(3), t = tm_torus(1.0, 0.35, 24, 12), d = band(s, -0.7, 0.8);
    roundtrip(ctx, "icosphere", s, 1);
    roundtrip(ctx, "torus", t, 1);
    roundtrip(ctx, "open band", d, 0);
    tm_free(&s), tm_free(&t), tm_free(&d);
}

/* Pieces in one mesh: a bumpy sphere, a torus moved away and turned, and a
 * vertex in no face. Lengths fix each piece but not where the pieces lie
 * relative to each other, so the output is aligned piece by piece: the
 * exact round trip must come back in place without any further alignment,
 * and the unused vertex where the reference has it. */
static void test_components(es_ctx *ctx)
{
    tm_mesh a = icosphere(2), b = tm_torus(1.0, 0.35, 16, 8);
    int64_t nv = a.nv + b.nv + 1, nf = a.nf + b.nf;
    double *xyz = malloc(3 * (size_t)nv * sizeof *xyz), c = cos(0.7), s = sin(0.7);
    int64_t *faces = malloc(3 * (size_t)nf * sizeof *faces);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    memcpy(xyz, a.xyz, 3 * (size_t)a.nv * sizeof *xyz);
    for (int64_t v = 0; v < b.nv; v++) {
        const double *p = b.xyz + 3 * v;
        double *q = xyz + 3 * (a.nv + v);
        q[0] = c * p[0] - s * p[2] + 4.0;
        q[1] = p[1] - 1.0;
        q[2] = s * p[0] + c * p[2] + 0.5;
    }
    xyz[3 * (nv - 1)] = 7, xyz[3 * (nv - 1) + 1] = -8, xyz[3 * (nv - 1) + 2] = 9;
    memcpy(faces, a.faces, 3 * (size_t)a.nf * sizeof *faces);
    for (int64_t i = 0; i < 3 * b.nf; i++) faces[3 * a.nf + i] = b.faces[i] + a.nv;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, nv, nf, faces, xyz, &mesh));
    if (mesh) ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        int64_t ne = es_mesh_nedges(mesh);
        double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
        double *out = malloc(3 * (size_t)nv * sizeof *out), d = 0;
        double diag = es_bbox_diagonal(nv - 1, xyz);
        es_embed_report r;
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, xyz, len));
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, xyz, al));
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r));
        for (int64_t i = 0; i < 3 * nv; i++) d += (out[i] - xyz[i]) * (out[i] - xyz[i]);
        ES_CHECK_MSG(sqrt(d / (double)nv) <= 1e-9 * diag, "two pieces: %g x diag off",
                     sqrt(d / (double)nv) / diag);
        ES_CHECK(out[3 * (nv - 1)] == 7 && out[3 * (nv - 1) + 1] == -8 &&
                 out[3 * (nv - 1) + 2] == 9);
        /* the vertex in no face takes its place from the initial positions:
         * a NaN there is refused, not copied to the output */
        memcpy(out, xyz, 3 * (size_t)nv * sizeof *out);
        out[3 * (nv - 1) + 2] = NAN;
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, 0, al, out, NULL, out, &r), ES_EINVAL,
                       "initial position of vertex");
        free(len), free(al), free(out);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    free(xyz), free(faces);
    tm_free(&a), tm_free(&b);
}

/* The level-2 icosphere with an embedder, its own lengths and dihedrals. */
typedef struct {
    tm_mesh s;
    es_mesh *mesh;
    es_embedder *emb;
    int64_t ne;
    double *len, *al, *out;   /* E, E, 3V */
} sphere_case;

static int sphere_open(es_ctx *ctx, sphere_case *c)
{
    memset(c, 0, sizeof *c);
    c->s = icosphere(2);
    ES_CHECK_OK(ctx, es_mesh_new(ctx, c->s.nv, c->s.nf, c->s.faces, c->s.xyz, &c->mesh));
    if (c->mesh) ES_CHECK_OK(ctx, es_embedder_new(ctx, c->mesh, &c->emb));
    if (!c->emb) return 0;
    c->ne = es_mesh_nedges(c->mesh);
    c->len = malloc((size_t)c->ne * sizeof *c->len);
    c->al = malloc((size_t)c->ne * sizeof *c->al);
    c->out = malloc(3 * (size_t)c->s.nv * sizeof *c->out);
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, c->mesh, c->s.xyz, c->len));
    ES_CHECK_OK(ctx, es_dihedral_angles(ctx, c->mesh, c->s.xyz, c->al));
    return 1;
}

static void sphere_close(sphere_case *c)
{
    free(c->len), free(c->al), free(c->out);
    es_embedder_free(c->emb);
    es_mesh_free(c->mesh);
    tm_free(&c->s);
}

/* The alignment reference may be the output array itself, as when a
 * sequence aligns each frame to the last: the result is the same as with a
 * separate copy (the solve must not align the output to itself). */
static void test_align_in_place(es_ctx *ctx)
{
    sphere_case c;
    if (sphere_open(ctx, &c)) {
        int64_t n3 = 3 * c.s.nv;
        double *moved = malloc((size_t)n3 * sizeof *moved);
        double co = cos(1.1), sn = sin(1.1), d = 0, diag = es_bbox_diagonal(c.s.nv, c.s.xyz);
        es_embed_report r;
        /* the reference turned and shifted: an output aligned to it is it */
        for (int64_t v = 0; v < c.s.nv; v++) {
            const double *p = c.s.xyz + 3 * v;
            moved[3 * v] = co * p[0] - sn * p[1] + 3;
            moved[3 * v + 1] = sn * p[0] + co * p[1] - 2;
            moved[3 * v + 2] = p[2] + 1;
        }
        memcpy(c.out, moved, (size_t)n3 * sizeof *c.out);
        ES_CHECK_OK(ctx, es_embed_solve(ctx, c.emb, c.len, 0, c.al, c.out, NULL, c.out, &r));
        for (int64_t i = 0; i < n3; i++) d += (c.out[i] - moved[i]) * (c.out[i] - moved[i]);
        ES_CHECK_MSG(sqrt(d / (double)c.s.nv) <= 1e-9 * diag,
                     "in place: %g x diag off the reference", sqrt(d / (double)c.s.nv) / diag);
        free(moved);
    }
    sphere_close(&c);
}

/* Progress: one "embedding" bar per solve, from 0 to its total, never
 * backwards, ending at the total (which clears a terminal's bar) also when
 * the refinement stops early. */
typedef struct {
    int64_t calls, first, last, total, backwards;
} progress_log;

static void on_progress(void *ud, const char *what, int64_t done, int64_t total)
{
    progress_log *p = ud;
    if (strcmp(what, "embedding")) return;
    if (p->calls++ == 0) p->first = done;
    if (done < p->last) p->backwards++;
    p->last = done;
    p->total = total;
}

static void test_progress(es_ctx *ctx)
{
    sphere_case c;
    if (sphere_open(ctx, &c)) {
        progress_log p = {0, 0, 0, 0, 0};
        es_embed_report r;
        for (int64_t e = 0; e < c.ne; e++) c.len[e] *= 1 + 0.05 * sin((double)e);
        es_ctx_set_progress(ctx, on_progress, &p);
        ES_CHECK_OK(ctx, es_embed_solve(ctx, c.emb, c.len, 0, c.al, NULL, NULL, c.out, &r));
        es_ctx_set_progress(ctx, NULL, NULL);
        ES_CHECK_MSG(p.calls >= 4 && p.first == 0 && p.backwards == 0 && p.last == p.total &&
                     p.total == 3 + 12, "progress: %lld calls, %lld -> %lld of %lld, %lld back",
                     (long long)p.calls, (long long)p.first, (long long)p.last,
                     (long long)p.total, (long long)p.backwards);
    }
    sphere_close(&c);
}

/* es_embed_align_parts: two parts moved by different rigid motions come
 * back each onto its reference; a vertex of part -1 stays where it is. */
static void test_kabsch_parts(es_ctx *ctx)
{
    double ref[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5, 6, 5, 5, 5, 7, 6};
    double x[18], rms, c = cos(1.1), s = sin(1.1);
    int64_t part[6] = {0, 0, 0, 1, 1, -1};
    for (int v = 0; v < 6; v++) {
        const double *p = ref + 3 * v;
        if (v < 3) {   /* part 0: turned about z, shifted */
            x[3 * v] = c * p[0] - s * p[1] + 2, x[3 * v + 1] = s * p[0] + c * p[1] - 1;
            x[3 * v + 2] = p[2] + 3;
        } else {       /* part 1 and the free vertex: turned about x */
            x[3 * v] = p[0] - 9, x[3 * v + 1] = c * p[1] - s * p[2];
            x[3 * v + 2] = s * p[1] + c * p[2];
        }
    }
    {
        double keep[3] = {x[15], x[16], x[17]};
        part[5] = 1;   /* first: the free vertex as part of part 1 (3 points fix it) */
        ES_CHECK_OK(ctx, es_embed_align_parts(ctx, 6, x, ref, NULL, part, &rms));
        ES_CHECK(rms < 1e-14);
        for (int i = 0; i < 18; i++) ES_CHECK_CLOSE(x[i], ref[i], 0, 1e-14);
        /* again from the moved positions with vertex 5 in no part */
        x[15] = keep[0], x[16] = keep[1], x[17] = keep[2];
        part[5] = -1;
        for (int v = 0; v < 5; v++)
            for (int i = 0; i < 3; i++) x[3 * v + i] += 0.5;
        ES_CHECK_OK(ctx, es_embed_align_parts(ctx, 6, x, ref, NULL, part, NULL));
        for (int i = 0; i < 15; i++) ES_CHECK_CLOSE(x[i], ref[i], 0, 1e-14);
        ES_CHECK(x[15] == keep[0] && x[16] == keep[1] && x[17] == keep[2]);
    }
    ES_CHECK_FAILS(ctx, es_embed_align_parts(ctx, 0, x, ref, NULL, part, NULL), ES_EINVAL,
                   "empty");
}

/* The solve runs with opts.blas_threads OpenBLAS threads and gives the
 * caller's setting back (weak symbols: skipped with another BLAS). */
#if defined(__GNUC__)
extern void openblas_set_num_threads(int n) __attribute__((weak));
extern int openblas_get_num_threads(void) __attribute__((weak));
#endif
static void test_blas_threads(es_ctx *ctx)
{
#if defined(__GNUC__)
    tm_mesh s = icosphere(1);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    if (!openblas_set_num_threads || !openblas_get_num_threads) {
        tm_free(&s);
        return;
    }
    ES_CHECK_OK(ctx, es_mesh_new(ctx, s.nv, s.nf, s.faces, s.xyz, &mesh));
    if (mesh) ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        int64_t ne = es_mesh_nedges(mesh);
        double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
        double *out = malloc(3 * (size_t)s.nv * sizeof *out);
        int before = openblas_get_num_threads();
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, s.xyz, len));
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, s.xyz, al));
        int set;
        openblas_set_num_threads(2);
        set = openblas_get_num_threads();   /* 1 where OpenBLAS caps it on one core */
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, NULL));
        ES_CHECK(openblas_get_num_threads() == set);
        openblas_set_num_threads(before);
        free(len), free(al), free(out);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    tm_free(&s);
#else
    (void)ctx;
#endif
}

/* ---- interpolation ------------------------------------------------------ */

/* Bend a torus-like tube: rotate points about the y axis by an angle that
 * grows with x, a near-isometric deformation. */
static void bend(int64_t nv, const double *x, double k, double *y)
{
    for (int64_t v = 0; v < nv; v++) {
        double a = k * x[3 * v], c = cos(a), s = sin(a);
        y[3 * v] = c * x[3 * v] + s * x[3 * v + 2];
        y[3 * v + 1] = x[3 * v + 1];
        y[3 * v + 2] = -s * x[3 * v] + c * x[3 * v + 2];
    }
}

static void test_interp(es_ctx *ctx)
{
    tm_mesh t = tm_torus(1.0, 0.35, 32, 12);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    double *b = malloc(3 * (size_t)t.nv * sizeof *b), *out = malloc(9 * (size_t)t.nv * sizeof *out);
    const double *in[2] = {t.xyz, b};
    es_embed_report r, rs[3];
    es_interp_info info;
    bend(t.nv, t.xyz, 0.6, b);
    for (int64_t i = 0; i < 3 * t.nv; i++) b[i] *= 1.3;   /* and scale */
    ES_CHECK_OK(ctx, es_mesh_new(ctx, t.nv, t.nf, t.faces, t.xyz, &mesh));
    ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        int64_t ne = es_mesh_nedges(mesh);
        double w[2] = {0.5, 0.5}, *len = malloc((size_t)ne * sizeof *len), s = 0;
        double *la = malloc((size_t)ne * sizeof *la), *lb = malloc((size_t)ne * sizeof *lb);
        double sa = 0, sb = 0;
        ES_CHECK_OK(ctx, es_interp_embed(ctx, emb, 2, in, w, NULL, NULL, out, &r, &info));
        ES_CHECK_MSG(r.rms_ratio <= 0.005 && r.max_rel <= 0.1, "torus midpoint rms %g max %g",
                     r.rms_ratio, r.max_rel);
        /* the target is the mean of normalized lengths at the mean scale */
        ES_CHECK_OK(ctx, es_interp_targets(ctx, mesh, 2, in, w, len, NULL, &info));
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, t.xyz, la));
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, b, lb));
        for (int64_t e = 0; e < ne; e++) {
            sa += la[e];
            sb += lb[e];
            s += len[e];
        }
        ES_CHECK_CLOSE(s, 0.5 * (sa + sb), 1e-12, 0);
        ES_CHECK_CLOSE(len[5], (0.5 * la[5] / sa + 0.5 * lb[5] / sb) * 0.5 * (sa + sb), 1e-12, 0);
        /* the accuracy stop (refine_rms_tol, refine_max_tol): tolerances the
         * linear stages already meet stop the refinement before its first
         * iteration; tolerances between the start and the full run's result
         * are met, in fewer iterations, as the lengths of the output
         * measured here (not the report) confirm */
        {
            es_embed_opts o;
            es_embed_report ra;
            double *lo = malloc((size_t)ne * sizeof *lo), mx = 0, ss = 0, sl = 0;
            es_embed_opts_init(&o);
            ES_CHECK(o.refine_rms_tol == 0 && o.refine_max_tol == 0);
            o.refine_rms_tol = o.refine_max_tol = 1;
            ES_CHECK_OK(ctx, es_interp_embed(ctx, emb, 2, in, w, NULL, &o, out, &ra, NULL));
            ES_CHECK_MSG(ra.refine_iters == 0, "loose tolerances: %lld iterations",
                         (long long)ra.refine_iters);
            ES_CHECK(r.refine_iters >= 3 && ra.rms_ratio > 2 * r.rms_ratio);
            o.refine_rms_tol = 0.5 * (ra.rms_ratio + r.rms_ratio);
            o.refine_max_tol = 0.5 * (ra.max_rel + r.max_rel);
            ES_CHECK_OK(ctx, es_interp_embed(ctx, emb, 2, in, w, NULL, &o, out, &ra, NULL));
            ES_CHECK_OK(ctx, es_interp_targets(ctx, mesh, 2, in, w, len, NULL, NULL));
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, out, lo));
            for (int64_t e = 0; e < ne; e++) {
                double d = lo[e] - len[e];
                mx = fmax(mx, fabs(d) / len[e]);
                ss += d * d;
                sl += len[e];
            }
            ss = sqrt(ss / (double)ne) / (sl / (double)ne);
            fprintf(stderr, "torus midpoint: full %lld it rms %g max %g; stopped at rms <= %g, "
                    "max <= %g: %lld it rms %g max %g (measured %g %g)\n",
                    (long long)r.refine_iters, r.rms_ratio, r.max_rel, o.refine_rms_tol,
                    o.refine_max_tol, (long long)ra.refine_iters, ra.rms_ratio, ra.max_rel, ss, mx);
            ES_CHECK(ss <= o.refine_rms_tol * (1 + 1e-9) && mx <= o.refine_max_tol * (1 + 1e-9));
            ES_CHECK(ra.refine_iters >= 1 && ra.refine_iters < r.refine_iters);
            free(lo);
        }
        /* endpoints come back; extrapolation stays finite */
        ES_CHECK_OK(ctx, es_interp_sequence(ctx, emb, t.xyz, b, 0.0, 1.2, 3, NULL, out, rs));
        ES_CHECK(aligned_rms(ctx, t.nv, out, t.xyz) <= 1e-8 * es_bbox_diagonal(t.nv, t.xyz));
        ES_CHECK(rs[0].max_rel < 1e-8);
        ES_CHECK(all_finite(out, 9 * t.nv));
        fprintf(stderr, "torus sequence t = 0, 0.6, 1.2: rms %g %g %g max %g %g %g\n",
                rs[0].rms_ratio, rs[1].rms_ratio, rs[2].rms_ratio, rs[0].max_rel, rs[1].max_rel,
                rs[2].max_rel);
        ES_CHECK_MSG(rs[1].rms_ratio <= 0.005 && rs[1].max_rel <= 0.1, "t = 0.6: rms %g max %g",
                     rs[1].rms_ratio, rs[1].max_rel);
        ES_CHECK(rs[2].realized == (rs[2].max_rel <= 1e-3));
        /* bad weights */
        w[0] = 1.0, w[1] = -1.0;
        ES_CHECK_FAILS(ctx, es_interp_targets(ctx, mesh, 2, in, w, len, NULL, NULL), ES_EINVAL,
                       "sum");
        w[1] = NAN;
        ES_CHECK_FAILS(ctx, es_interp_targets(ctx, mesh, 2, in, w, len, NULL, NULL), ES_EINVAL,
                       "weight");
        free(len), free(la), free(lb);
    }
    es_embedder_free(emb);
    es_mesh_free(mesh);
    tm_free(&t);
    free(b), free(out);
}

/* ---- garbage in ---------------------------------------------------------- */

static void test_garbage(es_ctx *ctx)
{
    tm_mesh s = icosphere(2);
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, s.nv, s.nf, s.faces, s.xyz, &mesh));
    ES_CHECK_OK(ctx, es_embedder_new(ctx, mesh, &emb));
    if (emb) {
        int64_t ne = es_mesh_nedges(mesh);
        double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
        double *out = malloc(3 * (size_t)s.nv * sizeof *out), keep;
        es_embed_report r;
        es_rng rng;
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, s.xyz, len));
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, mesh, s.xyz, al));
        keep = len[3];
        len[3] = NAN;
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r), ES_EINVAL,
                       "edge 3");
        len[3] = -1;
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r), ES_EINVAL,
                       "edge 3");
        len[3] = 0;
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r), ES_EINVAL,
                       "positive");
        len[3] = keep;
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, 0, NULL, NULL, NULL, out, &r), ES_EINVAL,
                       "initial");
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, -1, al, NULL, NULL, out, &r), ES_EINVAL,
                       "scale");
        keep = al[2];
        al[2] = INFINITY;
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r), ES_EINVAL,
                       "dihedral");
        al[2] = keep;
        /* every initial position must be finite, also at a vertex in no face
         * (the output takes it from there) */
        memcpy(out, s.xyz, 3 * (size_t)s.nv * sizeof *out);
        out[3 * 5 + 1] = NAN;
        ES_CHECK_FAILS(ctx, es_embed_solve(ctx, emb, len, 0, NULL, out, NULL, out, &r), ES_EINVAL,
                       "vertex 5");
        /* impossible triangles and random lengths: flagged best effort, finite */
        len[3] *= 5;
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r));
        ES_CHECK(r.n_bad_faces >= 1 && !r.realized && all_finite(out, 3 * s.nv));
        es_rng_init(&rng, 3);
        for (int64_t e = 0; e < ne; e++) len[e] = 0.01 + es_rng_uniform(&rng);
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r));
        ES_CHECK(!r.realized && all_finite(out, 3 * s.nv) && isfinite(r.rms_ratio));
        for (int64_t v = 0; v < s.nv; v++) {
            ES_CHECK(isfinite(es_embedder_vertex_closure(emb)[v]));
            ES_CHECK(isfinite(es_embedder_vertex_edge_error(emb)[v]));
        }
        /* all-zero dihedrals: the mirror-symmetric stationary point (failure C) is
         * not a trap for the position refinement */
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, mesh, s.xyz, len));
        for (int64_t e = 0; e < ne; e++) al[e] = 0;
        ES_CHECK_OK(ctx, es_embed_solve(ctx, emb, len, 0, al, NULL, NULL, out, &r));
        ES_CHECK(all_finite(out, 3 * s.nv));
        free(len), free(al), free(out);
    }
    es_embedder_free(emb);
    ES_CHECK_FAILS(ctx, es_embedder_new(ctx, NULL, &emb), ES_EINVAL, "mesh");
    ES_CHECK(emb == NULL);
    es_embedder_free(NULL);
    es_mesh_free(mesh);
    tm_free(&s);
}

/* An embedder works on the context it was made with; es_embed_solve may be
 * called with another (one context per thread), and a failure's message
 * must reach the caller's context, also for a NULL embedder. A success
 * leaves the caller's context alone. */
static void test_caller_ctx(es_ctx *ctx)
{
    sphere_case c;
    es_ctx *other = NULL;
    es_embed_report r;
    double keep;
    ES_CHECK(es_ctx_new(&other) == ES_OK);
    if (!other) return;
    if (sphere_open(ctx, &c)) {
        keep = c.len[7];
        c.len[7] = -2;
        ES_CHECK_FAILS(other, es_embed_solve(other, c.emb, c.len, 0, c.al, NULL, NULL, c.out, &r),
                       ES_EINVAL, "target length of edge 7");
        c.len[7] = keep;
        ES_CHECK_FAILS(other, es_embed_solve(other, c.emb, c.len, 0, NULL, NULL, NULL, c.out, &r),
                       ES_EINVAL, "need initial dihedrals or initial positions");
        ES_CHECK_FAILS(other, es_embed_solve(other, c.emb, c.len, NAN, c.al, NULL, NULL, c.out, &r),
                       ES_EINVAL, "scale nan");
        ES_CHECK_FAILS(other, es_embed_solve(other, c.emb, NULL, 0, c.al, NULL, NULL, c.out, &r),
                       ES_EINVAL, "NULL target or output");
        /* the messages came from the embedder's context, which still has
         * the last one; a success does not overwrite the caller's */
        ES_CHECK(es_test_contains(es_ctx_errmsg(ctx), "NULL target or output"));
        ES_CHECK_OK(other, es_embed_solve(other, c.emb, c.len, 0, c.al, NULL, NULL, c.out, &r));
        ES_CHECK(r.realized && r.max_rel < 1e-8);
        ES_CHECK(es_test_contains(es_ctx_errmsg(other), "NULL target or output"));
        /* no context given: the failure is still reported by its code */
        ES_CHECK(es_embed_solve(NULL, c.emb, NULL, 0, c.al, NULL, NULL, c.out, &r) == ES_EINVAL);
        ES_CHECK_FAILS(other, es_embed_solve(other, NULL, c.len, 0, c.al, NULL, NULL, c.out, &r),
                       ES_EINVAL, "no embedder");
    }
    sphere_close(&c);
    es_ctx_free(other);
}

static void log_stderr(void *ud, es_log_level level, const char *msg)
{
    (void)ud, (void)level;
    fprintf(stderr, "%s\n", msg);
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    if (getenv("ES_TEST_VERBOSE")) es_ctx_set_log(ctx, log_stderr, NULL);
    test_oracle(ctx);
    test_roundtrips(ctx);
    test_components(ctx);
    test_kabsch_parts(ctx);
    test_align_in_place(ctx);
    test_progress(ctx);
    test_blas_threads(ctx);
    test_interp(ctx);
    test_garbage(ctx);
    test_caller_ctx(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
