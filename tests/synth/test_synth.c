/* tests/synth/test_synth.c — synthetic families and subdivision: members share
 * one valid face list with the expected topology, faces point outward,
 * seeded runs are identical, the barbells reproduce the paper's Fig. 7
 * finding in Procrustes space, the bent tubes bend by theta, the twisted
 * tube twists by 270 degrees, the strip is a triangulated polygon, subdivision
 * gives V + E vertices and 4F faces whose sides are half their parents',
 * and the files written (and the `edgespace synth` command) are right.
 */
#include "edgespace/edgespace.h"
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"

#include <lapacke.h>
#include <unistd.h>

static es_mesh *topology(es_ctx *ctx, const es_synth_set *s)
{
    es_mesh *m = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, s->nverts, s->nfaces, s->faces, s->xyz, &m));
    return m;
}

/* Signed volume (divergence theorem): positive when faces point outward. */
static double volume(const es_synth_set *s, int64_t i)
{
    const double *x = s->xyz + 3 * s->nverts * i;
    double vol = 0;
    for (int64_t f = 0; f < s->nfaces; f++) {
        const double *a = x + 3 * s->faces[3 * f], *b = x + 3 * s->faces[3 * f + 1];
        const double *c = x + 3 * s->faces[3 * f + 2];
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
    }
    return vol;
}

/* Every member: finite positions, lengths valid, no sliver below min_deg. */
static void check_members(es_ctx *ctx, const es_synth_set *s, const es_mesh *m, double min_deg)
{
    int64_t ne = es_mesh_nedges(m);
    double *len = malloc((size_t)ne * sizeof *len);
    double *ang = malloc((size_t)s->nfaces * 3 * sizeof *ang);
    for (int64_t i = 0; i < s->nmembers; i++) {
        es_validity v;
        double amin = M_PI;
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, s->xyz + 3 * s->nverts * i, len));
        ES_CHECK_OK(ctx, es_lengths_check(ctx, m, len, 0, &v));
        ES_CHECK_MSG(v.valid, "%s: invalid lengths", s->names[i]);
        ES_CHECK_OK(ctx, es_corner_angles(ctx, m, len, ang));
        for (int64_t c = 0; c < 3 * s->nfaces; c++) amin = fmin(amin, ang[c]);
        ES_CHECK_MSG(amin * 180 / M_PI > min_deg, "%s: smallest angle %g deg", s->names[i],
                     amin * 180 / M_PI);
        for (int64_t j = 0; j < s->nmembers; j++)
            if (j != i) ES_CHECK(strcmp(s->names[i], s->names[j]) != 0);
    }
    free(len);
    free(ang);
}

static void check_topology(const es_mesh *m, int64_t loops, int64_t genus)
{
    es_mesh_summary sm;
    es_mesh_summarize(m, &sm);
    ES_CHECK_MSG(sm.n_boundary_loops == loops && sm.genus == genus && sm.n_components == 1 &&
                 sm.n_unreferenced == 0,
                 "loops %lld genus %lld components %lld unreferenced %lld",
                 (long long)sm.n_boundary_loops, (long long)sm.genus,
                 (long long)sm.n_components, (long long)sm.n_unreferenced);
}

/* ---- Procrustes distance (ordinary, full): centre, unit centroid size,
 * best rotation by the SVD of B^T A (Kabsch) ---- */

static void centre_scale(int64_t n, const double *in, double *out)
{
    double c[3] = {0, 0, 0}, ss = 0;
    for (int64_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++) c[k] += in[3 * v + k] / (double)n;
    for (int64_t v = 0; v < n; v++)
        for (int k = 0; k < 3; k++) {
            out[3 * v + k] = in[3 * v + k] - c[k];
            ss += out[3 * v + k] * out[3 * v + k];
        }
    for (int64_t i = 0; i < 3 * n; i++) out[i] /= sqrt(ss);
}

static double procrustes(int64_t n, const double *a0, const double *b0)
{
    double *a = malloc((size_t)n * 3 * sizeof *a), *b = malloc((size_t)n * 3 * sizeof *b);
    double M[9] = {0}, S[3], U[9], VT[9], sup[2];
    centre_scale(n, a0, a);
    centre_scale(n, b0, b);
    for (int64_t v = 0; v < n; v++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) M[i + 3 * j] += a[3 * v + i] * b[3 * v + j];
    LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'A', 'A', 3, 3, M, 3, S, U, 3, VT, 3, sup);
    double detU = U[0] * (U[4] * U[8] - U[7] * U[5]) - U[3] * (U[1] * U[8] - U[7] * U[2]) +
                  U[6] * (U[1] * U[5] - U[4] * U[2]);
    double detV = VT[0] * (VT[4] * VT[8] - VT[7] * VT[5]) -
                  VT[3] * (VT[1] * VT[8] - VT[7] * VT[2]) +
                  VT[6] * (VT[1] * VT[5] - VT[4] * VT[2]);
    double tr = S[0] + S[1] + (detU * detV < 0 ? -S[2] : S[2]);
    free(a);
    free(b);
    return sqrt(fmax(0.0, 2 - 2 * tr));
}

static double els_distance(es_ctx *ctx, const es_mesh *m, const double *a, const double *b)
{
    int64_t ne = es_mesh_nedges(m);
    double *la = malloc((size_t)ne * sizeof *la), *lb = malloc((size_t)ne * sizeof *lb), d = 0;
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, a, la));
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, b, lb));
    ES_CHECK_OK(ctx, es_lengths_normalize(ctx, ne, la, la, NULL));
    ES_CHECK_OK(ctx, es_lengths_normalize(ctx, ne, lb, lb, NULL));
    for (int64_t e = 0; e < ne; e++) d += (la[e] - lb[e]) * (la[e] - lb[e]);
    free(la);
    free(lb);
    return sqrt(d);
}

static void test_barbell(es_ctx *ctx)
{
    es_synth_set s;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_BARBELL, NULL, &s));
    if (!s.xyz) return;
    ES_CHECK(s.nmembers == 4 && s.nlabels == 3 && !strcmp(s.label_names[0], "end"));
    ES_CHECK(!strcmp(s.names[0], "barbell_sphere_short") &&
             !strcmp(s.names[3], "barbell_cube_long"));
    es_mesh *m = topology(ctx, &s);
    if (m) {
        check_topology(m, 0, 0);
        check_members(ctx, &s, m, 5);
        for (int64_t i = 0; i < 4; i++) ES_CHECK_MSG(volume(&s, i) > 0, "%s", s.names[i]);
        /* the cube-like end holds more volume than the sphere-like one */
        ES_CHECK(volume(&s, 2) > volume(&s, 0) && volume(&s, 3) > volume(&s, 1));
        int64_t V = s.nverts;
        const double *ss = s.xyz, *sl = s.xyz + 3 * V, *cs = s.xyz + 6 * V, *cl = s.xyz + 9 * V;
        double p_short = procrustes(V, ss, cs), p_long = procrustes(V, sl, cl);
        double e_short = els_distance(ctx, m, ss, cs), e_long = els_distance(ctx, m, sl, cl);
        /* Fig. 7: in Procrustes space the long barbells are clearly closer
         * to each other than the short ones; scaled edge lengths make the
         * two distances more comparable */
        ES_CHECK_MSG(p_long < 0.8 * p_short, "Procrustes: long %g, short %g", p_long, p_short);
        ES_CHECK_MSG(e_long / e_short > p_long / p_short,
                     "edge lengths: long/short %g, Procrustes %g", e_long / e_short,
                     p_long / p_short);
        /* the distance is a distance: invariant to a rigid motion */
        double *moved = malloc((size_t)V * 3 * sizeof *moved);
        for (int64_t v = 0; v < V; v++) {
            moved[3 * v] = -cs[3 * v + 1] + 5;
            moved[3 * v + 1] = cs[3 * v];
            moved[3 * v + 2] = cs[3 * v + 2] - 1;
        }
        ES_CHECK_CLOSE(procrustes(V, ss, moved), p_short, 1e-10, 1e-12);
        ES_CHECK(procrustes(V, cs, moved) < 1e-6);
        free(moved);
    }
    es_mesh_free(m);
    es_synth_set_clear(ctx, &s);

    es_synth_opts o;
    es_synth_opts_init(&o);
    o.n = 3;
    o.resolution = 4;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_BARBELL, &o, &s));
    ES_CHECK(s.nmembers == 6 && s.nverts == 2 + 12 * 18);
    if (s.names) ES_CHECK(!strcmp(s.names[1], "barbell_sphere_L1"));
    es_synth_set_clear(ctx, &s);
}

static void test_tubes(es_ctx *ctx)
{
    for (int closed = 0; closed < 2; closed++) {
        es_synth_set s;
        ES_CHECK_OK(ctx, es_synth_generate(ctx, closed ? ES_SYNTH_TUBE_CLOSED : ES_SYNTH_TUBE,
                                           NULL, &s));
        if (!s.xyz) continue;
        ES_CHECK(s.nmembers == 7 && !strcmp(s.labels[6], "180"));
        es_mesh *m = topology(ctx, &s);
        if (m) {
            check_topology(m, closed ? 0 : 2, 0);
            check_members(ctx, &s, m, 5);
            if (closed)
                for (int64_t i = 0; i < s.nmembers; i++) ES_CHECK(volume(&s, i) > 0);
            /* bending keeps the axis length: the axis points (centroids of
             * the tube rings) lie on an arc of radius len/theta; at theta =
             * pi the far end ring's centre is at (0, 2 len / pi, 0) */
            int64_t nseg = 16, first = closed ? 1 + 4 * nseg : 0, nring = 33;
            const double *x = s.xyz + 3 * s.nverts * 6;
            double c[3] = {0, 0, 0}, c0[3] = {0, 0, 0};
            for (int64_t j = 0; j < nseg; j++)
                for (int k = 0; k < 3; k++) {
                    c[k] += x[3 * (first + (nring - 1) * nseg + j) + k] / (double)nseg;
                    c0[k] += x[3 * (first + j) + k] / (double)nseg;
                }
            ES_CHECK_CLOSE(c[0], 0.0, 0, 1e-12);
            ES_CHECK_CLOSE(c[1], 16 / M_PI, 1e-12, 0);
            ES_CHECK_CLOSE(c0[0], 0.0, 0, 1e-12);
            ES_CHECK_CLOSE(c0[1], 0.0, 0, 1e-12);
            /* dihedrals: zero along the straight tube's axis direction,
             * the straight member has no bending between rings */
            int64_t ne = es_mesh_nedges(m);
            double *al = malloc((size_t)ne * sizeof *al), *al6 = malloc((size_t)ne * sizeof *al);
            ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, s.xyz, al));
            ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, x, al6));
            double sum0 = 0, sum6 = 0;
            for (int64_t e = 0; e < ne; e++) {
                sum0 += fabs(al[e]);
                sum6 += fabs(al6[e]);
            }
            ES_CHECK(sum6 > sum0);
            free(al);
            free(al6);
        }
        es_mesh_free(m);
        es_synth_set_clear(ctx, &s);
        /* the coarsest resolution still makes valid tubes (it made 2 faces
         * on each side of a ring edge: 2 segments around) */
        es_synth_opts o;
        es_synth_opts_init(&o);
        o.resolution = 1;
        ES_CHECK_OK(ctx, es_synth_generate(ctx, closed ? ES_SYNTH_TUBE_CLOSED : ES_SYNTH_TUBE, &o,
                                           &s));
        if (!s.xyz) continue;
        m = topology(ctx, &s);
        ES_CHECK_MSG(m != NULL, "tube at resolution 1: %s", es_ctx_errmsg(ctx));
        if (m) check_topology(m, closed ? 0 : 2, 0);
        es_mesh_free(m);
        es_synth_set_clear(ctx, &s);
    }
}

/* The families made for the other papers' claims: the bent and twisted
 * elliptic tube (its far ring turned by 270 degrees about the end tangent,
 * span 2 continuing the same family) and the triangulated polygon strip
 * (a tree as dual graph, the two members mirror images of each other). */
static void test_twist_strip(es_ctx *ctx)
{
    es_synth_set s, t;
    es_synth_opts o;
    es_mesh *m;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE_TWIST, NULL, &s));
    if (s.xyz) {
        const int64_t nseg = 16, nring = 33;
        const double *x = s.xyz + 3 * s.nverts * 6, *v0 = x + 3 * (nring - 1) * nseg;
        double c[3] = {0, 0, 0};
        ES_CHECK(s.nmembers == 7 && s.nlabels == 2 && !strcmp(s.label_names[1], "twist_deg"));
        ES_CHECK(!strcmp(s.labels[12], "180") && !strcmp(s.labels[13], "270"));
        ES_CHECK(!strcmp(es_synth_family_name(ES_SYNTH_TUBE_TWIST), "tube-twist"));
        m = topology(ctx, &s);
        if (m) {
            check_topology(m, 2, 0);
            check_members(ctx, &s, m, 5);
        }
        es_mesh_free(m);
        /* bent by pi: the end ring's centre at (0, 16/pi, 0), its tangent -x,
         * the bend normal -y; the major axis (vertex 0 of the ring, at +y
         * untwisted) turned by 270 degrees about the tangent lies along -z */
        for (int64_t j = 0; j < nseg; j++)
            for (int k = 0; k < 3; k++) c[k] += v0[3 * j + k] / (double)nseg;
        ES_CHECK_CLOSE(c[1], 16 / M_PI, 1e-12, 0);
        ES_CHECK_CLOSE(v0[0] - c[0], 0.0, 0, 1e-12);
        ES_CHECK_CLOSE(v0[1] - c[1], 0.0, 0, 1e-12);
        ES_CHECK_CLOSE(v0[2] - c[2], -1.0, 0, 1e-12);
        es_synth_opts_init(&o);
        o.n = 3;
        o.span = 2;
        ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE_TWIST, &o, &t));
        if (t.xyz) {
            ES_CHECK(!strcmp(t.labels[4], "360") && !strcmp(t.labels[5], "540"));
            ES_CHECK(memcmp(t.xyz + 3 * t.nverts, x, 3 * (size_t)s.nverts * sizeof *x) == 0);
        }
        es_synth_set_clear(ctx, &t);
    }
    es_synth_set_clear(ctx, &s);
    es_synth_opts_init(&o);
    o.span = 0;
    ES_CHECK_FAILS(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE, &o, &s), ES_EINVAL, "span");

    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_STRIP, NULL, &s));
    if (s.xyz) {
        ES_CHECK(s.nmembers == 2 && !strcmp(s.labels[0], "1") && !strcmp(s.labels[1], "-1"));
        m = topology(ctx, &s);
        if (m) {
            const int64_t *ef = es_mesh_edge_faces(m);
            int64_t ne = es_mesh_nedges(m), interior = 0;
            double *la = malloc((size_t)ne * sizeof *la), *lb = malloc((size_t)ne * sizeof *lb);
            check_topology(m, 1, 0);
            check_members(ctx, &s, m, 5);
            for (int64_t e = 0; e < ne; e++) interior += ef[2 * e] >= 0 && ef[2 * e + 1] >= 0;
            ES_CHECK(interior == s.nfaces - 1);   /* a connected dual graph with F - 1 arcs: a tree */
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, s.xyz, la));
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, s.xyz + 3 * s.nverts, lb));
            for (int64_t e = 0; e < ne; e++) ES_CHECK_CLOSE(la[e], lb[e], 1e-14, 0);
            free(la), free(lb);
        }
        es_mesh_free(m);
    }
    es_synth_set_clear(ctx, &s);
}

static void test_face(es_ctx *ctx)
{
    es_synth_set s, t;
    es_synth_opts o;
    es_synth_opts_init(&o);
    o.n = 4;
    es_ctx_set_seed(ctx, 11);
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_FACE, &o, &s));
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_FACE, &o, &t));
    if (!s.xyz || !t.xyz) return;
    ES_CHECK(s.nmembers == 12 && s.nlabels == 2);
    ES_CHECK(!strcmp(s.label_names[0], "subject") && !strcmp(s.label_names[1], "expression"));
    ES_CHECK(!strcmp(s.labels[2 * 4], "s02") && !strcmp(s.labels[2 * 4 + 1], "happy"));
    /* seeded runs are identical, bit for bit; another seed differs */
    ES_CHECK(s.nverts == t.nverts && s.nfaces == t.nfaces);
    ES_CHECK(memcmp(s.faces, t.faces, (size_t)(3 * s.nfaces) * sizeof *s.faces) == 0);
    ES_CHECK(memcmp(s.xyz, t.xyz, (size_t)(3 * s.nverts * s.nmembers) * sizeof *s.xyz) == 0);
    es_synth_set_clear(ctx, &t);
    es_ctx_set_seed(ctx, 12);
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_FACE, &o, &t));
    if (t.xyz) {
        ES_CHECK(memcmp(s.faces, t.faces, (size_t)(3 * s.nfaces) * sizeof *s.faces) == 0);
        ES_CHECK(memcmp(s.xyz, t.xyz, (size_t)(3 * s.nverts) * sizeof *s.xyz) != 0);
    }
    es_synth_set_clear(ctx, &t);

    es_mesh *m = topology(ctx, &s);
    if (m) {
        check_topology(m, 4, 0);     /* rim, two eyes, mouth: like face-study */
        check_members(ctx, &s, m, 5);
        /* the expression is the structure: within a subject, happy and
         * angry differ from neutral more than noise does, and the
         * neutral->happy change of edge lengths correlates across subjects */
        int64_t ne = es_mesh_nedges(m), V = s.nverts;
        double *l0 = malloc((size_t)ne * 4 * sizeof *l0), *d[2];
        d[0] = l0 + 2 * ne;
        d[1] = l0 + 3 * ne;
        for (int sj = 0; sj < 2; sj++) {
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, s.xyz + 3 * V * (3 * sj), l0));
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, s.xyz + 3 * V * (3 * sj + 1), l0 + ne));
            for (int64_t e = 0; e < ne; e++) d[sj][e] = l0[ne + e] / l0[e] - 1;
        }
        double num = 0, n0 = 0, n1 = 0;
        for (int64_t e = 0; e < ne; e++) {
            num += d[0][e] * d[1][e];
            n0 += d[0][e] * d[0][e];
            n1 += d[1][e] * d[1][e];
        }
        ES_CHECK_MSG(num / sqrt(n0 * n1) > 0.5, "happy change correlation %g",
                     num / sqrt(n0 * n1));
        free(l0);
    }
    es_mesh_free(m);
    es_synth_set_clear(ctx, &s);
    es_ctx_set_seed(ctx, 0x5eed);
}

/* ---- subdivision ---- */

static void check_subdivision(es_ctx *ctx, int64_t nv, int64_t nf, const int64_t *faces,
                              int64_t nshapes, const double *xyz)
{
    es_mesh *m = NULL, *m2 = NULL;
    int64_t nv2, *f2;
    double *x2;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, nv, nf, faces, NULL, &m));
    ES_CHECK_OK(ctx, es_mesh_subdivide(ctx, nv, nf, faces, nshapes, xyz, &nv2, &f2, &x2));
    if (!m || !f2) {
        es_mesh_free(m);
        return;
    }
    int64_t ne = es_mesh_nedges(m);
    ES_CHECK(nv2 == nv + ne);
    ES_CHECK_OK(ctx, es_mesh_new(ctx, nv2, 4 * nf, f2, NULL, &m2));
    if (m2) {
        es_mesh_summary a, b;
        es_mesh_summarize(m, &a);
        es_mesh_summarize(m2, &b);
        ES_CHECK(b.euler == a.euler && b.genus == a.genus &&
                 b.n_boundary_loops == a.n_boundary_loops && b.nedges == 2 * ne + 3 * nf);
        const int64_t *E = es_mesh_edges(m), *FE2 = es_mesh_face_edges(m2);
        int64_t ne2 = es_mesh_nedges(m2);
        double *l = malloc((size_t)ne * sizeof *l), *l2 = malloc((size_t)ne2 * sizeof *l2);
        for (int64_t sh = 0; sh < nshapes; sh++) {
            const double *x = xyz + 3 * nv * sh, *y = x2 + 3 * nv2 * sh;
            int bad = 0;
            for (int64_t e = 0; e < ne; e++) /* vertex V + e is edge e's midpoint */
                for (int k = 0; k < 3; k++)
                    bad += y[3 * (nv + e) + k] != 0.5 * (x[3 * E[2 * e] + k] + x[3 * E[2 * e + 1] + k]);
            for (int64_t v = 0; v < 3 * nv; v++) bad += y[v] != x[v];
            ES_CHECK_MSG(bad == 0, "%d misplaced vertices", bad);
            /* every child face has half its parent's sides */
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, x, l));
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m2, y, l2));
            const int64_t *FE = es_mesh_face_edges(m);
            for (int64_t f = 0; f < nf; f++) {
                double p[3] = {l[FE[3 * f]], l[FE[3 * f + 1]], l[FE[3 * f + 2]]};
                /* children 0..2 keep the parent's side order; the middle one
                 * has sides (ab-bc) = ca/2, (bc-ca) = ab/2, (ca-ab) = bc/2 */
                for (int c = 0; c < 3; c++)
                    for (int k = 0; k < 3; k++) {
                        double want = p[k] / 2;
                        ES_CHECK_CLOSE(l2[FE2[3 * (4 * f + c) + k]] * 1, want, 1e-13,
                                       1e-15);
                    }
                ES_CHECK_CLOSE(l2[FE2[3 * (4 * f + 3)]], p[2] / 2, 1e-13, 1e-15);
                ES_CHECK_CLOSE(l2[FE2[3 * (4 * f + 3) + 1]], p[0] / 2, 1e-13, 1e-15);
                ES_CHECK_CLOSE(l2[FE2[3 * (4 * f + 3) + 2]], p[1] / 2, 1e-13, 1e-15);
            }
        }
        free(l);
        free(l2);
    }
    es_mesh_free(m);
    es_mesh_free(m2);
    es_free(ctx, f2);
    es_free(ctx, x2);
}

static void test_subdivide(es_ctx *ctx)
{
    /* flat input: a hexagon fan in z = 0 */
    int64_t hexf[18];
    double hexx[21] = {0, 0, 0};
    for (int i = 0; i < 6; i++) {
        hexx[3 * (i + 1)] = cos(M_PI * i / 3);
        hexx[3 * (i + 1) + 1] = sin(M_PI * i / 3);
        hexx[3 * (i + 1) + 2] = 0;
        hexf[3 * i] = 0;
        hexf[3 * i + 1] = 1 + i;
        hexf[3 * i + 2] = 1 + (i + 1) % 6;
    }
    check_subdivision(ctx, 7, 6, hexf, 1, hexx);
    /* after subdivision every edge of the flat regular hexagon is 1/2 */
    int64_t nv2, *f2;
    double *x2;
    es_mesh *m2 = NULL;
    ES_CHECK_OK(ctx, es_mesh_subdivide(ctx, 7, 6, hexf, 1, hexx, &nv2, &f2, &x2));
    if (f2) {
        ES_CHECK_OK(ctx, es_mesh_new(ctx, nv2, 24, f2, NULL, &m2));
        if (m2) {
            double l[64];
            ES_CHECK(es_mesh_nedges(m2) == 2 * 12 + 18 && es_mesh_nedges(m2) <= 64);
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m2, x2, l));
            for (int64_t e = 0; e < es_mesh_nedges(m2); e++) ES_CHECK_CLOSE(l[e], 0.5, 1e-14, 0);
        }
        es_mesh_free(m2);
        es_free(ctx, f2);
        es_free(ctx, x2);
    }

    /* curved closed input, several shapes at once: the barbells */
    es_synth_set s;
    es_synth_opts o;
    es_synth_opts_init(&o);
    o.resolution = 2;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_BARBELL, &o, &s));
    if (s.xyz) {
        check_subdivision(ctx, s.nverts, s.nfaces, s.faces, s.nmembers, s.xyz);
        int64_t v0 = s.nverts, f0 = s.nfaces;
        ES_CHECK_OK(ctx, es_synth_subdivide(ctx, &s, 2));
        ES_CHECK(s.nfaces == 16 * f0 && s.nverts == v0 + (3 * f0 / 2) + (3 * 4 * f0 / 2));
        es_mesh *m = topology(ctx, &s);
        if (m) check_topology(m, 0, 0);
        es_mesh_free(m);
    }
    es_synth_set_clear(ctx, &s);

    /* no positions: faces only; and a non-manifold input is refused */
    ES_CHECK_OK(ctx, es_mesh_subdivide(ctx, 7, 6, hexf, 0, NULL, &nv2, &f2, &x2));
    ES_CHECK(nv2 == 19 && x2 == NULL && f2 != NULL);
    es_free(ctx, f2);
    int64_t bad[] = {0, 1, 2, 0, 1, 3};
    ES_CHECK_FAILS(ctx, es_mesh_subdivide(ctx, 4, 2, bad, 0, NULL, &nv2, &f2, &x2),
                   ES_ETOPOLOGY, "inconsistent orientation");
    ES_CHECK(f2 == NULL);
    ES_CHECK_FAILS(ctx, es_mesh_subdivide(ctx, 7, 6, hexf, 2, NULL, &nv2, &f2, &x2), ES_EINVAL,
                   "NULL");
}

/* ---- options, names, files, command ---- */

static void test_files(es_ctx *ctx)
{
    es_synth_family fam;
    es_synth_set s;
    es_synth_opts o;
    ES_CHECK_OK(ctx, es_synth_family_from_name(ctx, "tube-closed", &fam));
    ES_CHECK(fam == ES_SYNTH_TUBE_CLOSED && !strcmp(es_synth_family_name(fam), "tube-closed"));
    ES_CHECK_OK(ctx, es_synth_family_from_name(ctx, "barbells", &fam));
    ES_CHECK(fam == ES_SYNTH_BARBELL);
    ES_CHECK_FAILS(ctx, es_synth_family_from_name(ctx, "barbellss", &fam), ES_ENOTFOUND,
                   "unknown family");
    ES_CHECK_FAILS(ctx, es_synth_family_from_name(ctx, "bagel", &fam), ES_ENOTFOUND,
                   "unknown family 'bagel' (known: barbell");
    ES_CHECK(es_synth_family_name((es_synth_family)99) == NULL);
    es_synth_opts_init(&o);
    o.resolution = 65;
    ES_CHECK_FAILS(ctx, es_synth_generate(ctx, ES_SYNTH_FACE, &o, &s), ES_EINVAL, "resolution");
    ES_CHECK(s.xyz == NULL && s.nmembers == 0);
    es_synth_opts_init(&o);
    o.n = 1;
    ES_CHECK_FAILS(ctx, es_synth_generate(ctx, ES_SYNTH_BARBELL, &o, &s), ES_EINVAL, "n >= 2");

    char dir[] = "/tmp/es_synth_test_XXXXXX", path[256], line[256];
    if (!mkdtemp(dir)) {
        ES_CHECK_MSG(0, "mkdtemp failed");
        return;
    }
    o.n = 2;
    o.resolution = 2;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_FACE, &o, &s));
    snprintf(path, sizeof path, "%s/out", dir);
    ES_CHECK_OK(ctx, es_synth_write(ctx, &s, path));
    snprintf(path, sizeof path, "%s/out/manifest.csv", dir);
    FILE *fp = fopen(path, "r");
    int rows = 0;
    if (fp) {
        ES_CHECK(fgets(line, sizeof line, fp) && !strcmp(line, "file,subject,expression\n"));
        while (fgets(line, sizeof line, fp)) rows++;
        fclose(fp);
    }
    ES_CHECK(rows == 6);
    /* the OBJ round-trips exactly (%.17g) */
    snprintf(path, sizeof path, "%s/out/face_s02_angry.obj", dir);
    fp = fopen(path, "r");
    int64_t nv = 0, nf = 0, bad = 0;
    const double *x = s.xyz + 3 * s.nverts * 5;
    if (fp) {
        while (fgets(line, sizeof line, fp)) {
            double a, b, c;
            long long i, j, k;
            if (sscanf(line, "v %lf %lf %lf", &a, &b, &c) == 3 && nv < s.nverts) {
                bad += a != x[3 * nv] || b != x[3 * nv + 1] || c != x[3 * nv + 2];
                nv++;
            } else if (sscanf(line, "f %lld %lld %lld", &i, &j, &k) == 3 && nf < s.nfaces) {
                bad += i - 1 != s.faces[3 * nf] || j - 1 != s.faces[3 * nf + 1] ||
                       k - 1 != s.faces[3 * nf + 2];
                nf++;
            }
        }
        fclose(fp);
    }
    ES_CHECK_MSG(nv == s.nverts && nf == s.nfaces && bad == 0, "%lld v, %lld f, %lld bad",
                 (long long)nv, (long long)nf, (long long)bad);
    /* every file written has the set's face list (same fingerprint) */
    char want_fp[17], got_fp[17];
    es_faces_fingerprint(s.nverts, s.nfaces, s.faces, want_fp);
    for (int64_t i = 0; i < s.nmembers; i++) {
        es_meshdata md;
        snprintf(path, sizeof path, "%s/out/%s.obj", dir, s.names[i]);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_OBJ, &md));
        es_faces_fingerprint(md.nverts, md.nfaces, md.faces, got_fp);
        ES_CHECK_MSG(md.faces && !strcmp(got_fp, want_fp), "%s: fingerprint %s, want %s", path,
                     got_fp, want_fp);
        es_meshdata_clear(ctx, &md);
    }
    snprintf(path, sizeof path, "%s/new/deeper", dir);    /* parents are created */
    ES_CHECK_OK(ctx, es_synth_write(ctx, &s, path));
    snprintf(path, sizeof path, "%s/out/manifest.csv/below", dir); /* under a file */
    ES_CHECK_FAILS(ctx, es_synth_write(ctx, &s, path), ES_EIO, "cannot create directory");
    es_synth_set_clear(ctx, &s);

    /* the command */
    const char *exe = getenv("EDGESPACE");
    if (exe) {
        char cmd[1024];
        snprintf(cmd, sizeof cmd, "'%s' synth tube -o '%s/cli' --n 3 -r 2 --seed 5 >/dev/null",
                 exe, dir);
        ES_CHECK(system(cmd) == 0);
        snprintf(path, sizeof path, "%s/cli/tube_002.obj", dir);
        ES_CHECK(access(path, R_OK) == 0);
        /* a folder with a manifest is left alone without --replace (issue 25:
         * it was overwritten silently) */
        snprintf(path, sizeof path, "%s/cli/manifest.csv", dir);
        FILE *mf = fopen(path, "w");
        if (mf) fputs("file,mine\n", mf);
        if (mf) fclose(mf);
        snprintf(cmd, sizeof cmd, "'%s' synth tube -o '%s/cli' --n 3 -r 2 2>/dev/null", exe,
                 dir);
        int st0 = system(cmd);
        char head[32] = "";
        mf = fopen(path, "r");
        if (mf && !fgets(head, sizeof head, mf)) head[0] = '\0';
        if (mf) fclose(mf);
        ES_CHECK(WIFEXITED(st0) && WEXITSTATUS(st0) == 1 && !strcmp(head, "file,mine\n"));
        snprintf(cmd, sizeof cmd, "'%s' synth tube -o '%s/cli' --n 3 -r 2 --replace >/dev/null",
                 exe, dir);
        ES_CHECK(system(cmd) == 0);
        snprintf(cmd, sizeof cmd, "'%s' synth bagel -o '%s/cli' 2>/dev/null", exe, dir);
        int st = system(cmd);
        ES_CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2);
        snprintf(cmd, sizeof cmd, "'%s' synth --help >/dev/null", exe);
        ES_CHECK(system(cmd) == 0);
        snprintf(cmd, sizeof cmd, "'%s' synth face 2>/dev/null", exe);
        st = system(cmd);
        ES_CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 2);
        snprintf(cmd, sizeof cmd, "rm -rf '%s/cli'", dir);
        ES_CHECK(system(cmd) == 0);
    } else {
        fprintf(stderr, "skipping command checks: EDGESPACE not set\n");
    }
    snprintf(path, sizeof path, "rm -rf '%s'", dir);
    ES_CHECK(system(path) == 0);
}

/* ---- allocation failures: fail the k-th allocation until success ---- */


static void test_alloc_failures(es_ctx *ctx)
{
    for (int what = 0; what < 3; what++) {
        int ok = 0;
        for (int64_t k = 1; k < 2000 && !ok; k++) {
            failing_alloc fa = {0, k, 0};
            es_allocator al = {fa_malloc, fa_realloc, fa_free, &fa};
            es_synth_opts o;
            es_synth_set s;
            es_status rc;
            es_synth_opts_init(&o);
            o.n = 2;
            o.resolution = 1;
            es_ctx_set_allocator(ctx, &al);
            if (what < 2) {
                rc = es_synth_generate(ctx, what ? ES_SYNTH_BARBELL : ES_SYNTH_FACE, &o, &s);
                if (rc == ES_OK) rc = es_synth_subdivide(ctx, &s, 1);
                es_synth_set_clear(ctx, &s);
            } else {
                int64_t f[] = {0, 1, 2, 0, 2, 3}, nv, *fo = NULL;
                double x[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, *xo = NULL;
                rc = es_mesh_subdivide(ctx, 4, 2, f, 1, x, &nv, &fo, &xo);
                es_free(ctx, fo);
                es_free(ctx, xo);
            }
            if (rc == ES_OK) ok = 1;
            else ES_CHECK_MSG(rc == ES_ENOMEM, "case %d, k=%lld: rc %d", what, (long long)k, rc);
            ES_CHECK_MSG(fa.live == 0, "case %d, k=%lld: %lld blocks leaked", what,
                         (long long)k, (long long)fa.live);
            es_ctx_set_allocator(ctx, NULL);
        }
        ES_CHECK_MSG(ok, "case %d never succeeded", what);
    }
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_barbell(ctx);
    test_tubes(ctx);
    test_twist_strip(ctx);
    test_face(ctx);
    test_subdivide(ctx);
    test_files(ctx);
    test_alloc_failures(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
