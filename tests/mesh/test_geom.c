/* tests/mesh/test_geom.c — edge lengths, normalization, corner angles (Kahan),
 * signed dihedrals, length validity. Checked by property (rigid-motion
 * invariance, flat -> 0, convex -> negative, angle sums, accuracy on needle
 * triangles against closed forms) and, when ../shared is present, against
 * ../shared/oracle/embed/<mesh>/{corners,edges}.csv to ~1e-12.
 */
#include "edgespace/edgespace.h"
#include "core/core_private.h"
#include "es_test.h"

/* Icosahedron-like convex closed mesh: an octahedron. */
static const double oct_xyz[] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
static const int64_t oct_faces[] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
                                    2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};

static void rotate(const double *in, double *out, int64_t nv, double ax, double ay, double az,
                   const double *shift)
{
    double cx = cos(ax), sx = sin(ax), cy = cos(ay), sy = sin(ay), cz = cos(az), sz = sin(az);
    double R[9] = {cy * cz, cy * sz, -sy,                      /* column 0 */
                   sx * sy * cz - cx * sz, sx * sy * sz + cx * cz, sx * cy,
                   cx * sy * cz + sx * sz, cx * sy * sz - sx * cz, cx * cy};
    for (int64_t v = 0; v < nv; v++)
        for (int i = 0; i < 3; i++)
            out[3 * v + i] = R[i] * in[3 * v] + R[3 + i] * in[3 * v + 1] +
                             R[6 + i] * in[3 * v + 2] + shift[i];
}

static void test_octahedron(es_ctx *ctx)
{
    es_mesh *m = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, 6, 8, oct_faces, oct_xyz, &m));
    if (!m) return;
    int64_t ne = es_mesh_nedges(m);
    double len[12], len2[12], ang[24], ang2[24], al[12], al2[12], xyz2[18], nl[12], s;
    ES_CHECK(ne == 12);
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, oct_xyz, len));
    for (int e = 0; e < 12; e++) ES_CHECK_CLOSE(len[e], sqrt(2.0), 1e-15, 0);
    ES_CHECK_OK(ctx, es_corner_angles(ctx, m, len, ang));
    for (int i = 0; i < 24; i++) ES_CHECK_CLOSE(ang[i], M_PI / 3, 1e-15, 0);
    ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, oct_xyz, al));
    /* interior dihedral of the octahedron is acos(-1/3); alpha = delta - pi < 0 */
    for (int e = 0; e < 12; e++) ES_CHECK_CLOSE(al[e], acos(-1.0 / 3) - M_PI, 1e-14, 0);

    /* invariance under a rigid motion (and lengths scale with a dilation) */
    double sh[3] = {3, -2, 7};
    rotate(oct_xyz, xyz2, 6, 0.3, -1.1, 2.5, sh);
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, xyz2, len2));
    ES_CHECK_OK(ctx, es_corner_angles(ctx, m, len2, ang2));
    ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, xyz2, al2));
    for (int e = 0; e < 12; e++) ES_CHECK_CLOSE(len2[e], len[e], 1e-14, 0);
    for (int e = 0; e < 12; e++) ES_CHECK_CLOSE(al2[e], al[e], 0, 1e-13);
    for (int i = 0; i < 24; i++) ES_CHECK_CLOSE(ang2[i], ang[i], 0, 1e-14);

    /* a mirror image flips the sign of every dihedral */
    for (int v = 0; v < 6; v++) {
        xyz2[3 * v] = -oct_xyz[3 * v];
        xyz2[3 * v + 1] = oct_xyz[3 * v + 1];
        xyz2[3 * v + 2] = oct_xyz[3 * v + 2];
    }
    ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, xyz2, al2));
    for (int e = 0; e < 12; e++) ES_CHECK_CLOSE(al2[e], -al[e], 0, 1e-14);

    /* normalization keeps the scale and may alias */
    ES_CHECK_OK(ctx, es_lengths_normalize(ctx, 12, len, nl, &s));
    ES_CHECK_CLOSE(s, 12 * sqrt(2.0), 1e-15, 0);
    double sum = 0;
    for (int e = 0; e < 12; e++) sum += nl[e];
    ES_CHECK_CLOSE(sum, 1.0, 1e-15, 0);
    memcpy(len2, len, sizeof len);
    ES_CHECK_OK(ctx, es_lengths_normalize(ctx, 12, len2, len2, NULL));
    for (int e = 0; e < 12; e++) ES_CHECK(len2[e] == nl[e]);
    len2[3] = NAN;
    ES_CHECK_FAILS(ctx, es_lengths_normalize(ctx, 12, len2, nl, &s), ES_EINVAL,
                   "not finite and positive");
    double zeros[3] = {0, 0, 0};
    ES_CHECK_FAILS(ctx, es_lengths_normalize(ctx, 3, zeros, nl, &s), ES_EINVAL, "sum");

    /* validity: a valid vector, then NaN, negative and a broken face */
    es_validity v;
    ES_CHECK_OK(ctx, es_lengths_check(ctx, m, len, 0, &v));
    ES_CHECK(v.valid && v.n_bad_faces == 0 && v.worst_violation <= 0 && v.worst_face >= 0);
    memcpy(len2, len, sizeof len);
    len2[0] = NAN;
    len2[1] = -1;
    len2[2] = 0;
    ES_CHECK_OK(ctx, es_lengths_check(ctx, m, len2, 1e-12, &v));
    ES_CHECK(!v.valid && v.n_nonfinite == 1 && v.n_nonpositive == 2);
    memcpy(len2, len, sizeof len);
    len2[5] = 10;                 /* longer than the two others of its faces */
    ES_CHECK_OK(ctx, es_lengths_check(ctx, m, len2, 1e-12, &v));
    ES_CHECK(!v.valid && v.n_nonfinite == 0 && v.n_nonpositive == 0);
    ES_CHECK(v.n_bad_faces == 2 && v.worst_face >= 0);
    const int64_t *FE = es_mesh_face_edges(m);
    ES_CHECK(FE[3 * v.worst_face] == 5 || FE[3 * v.worst_face + 1] == 5 ||
             FE[3 * v.worst_face + 2] == 5);
    ES_CHECK_CLOSE(v.worst_violation, (10 - 2 * sqrt(2.0)) / (10 + 2 * sqrt(2.0)), 1e-14, 0);
    /* the tolerance admits slightly broken faces */
    memcpy(len2, len, sizeof len);
    len2[5] = 2 * sqrt(2.0) * (1 + 1e-10);
    ES_CHECK_OK(ctx, es_lengths_check(ctx, m, len2, 1e-9, &v));
    ES_CHECK(v.valid && v.worst_violation > 0);
    ES_CHECK_OK(ctx, es_lengths_check(ctx, m, len2, 0, &v));
    ES_CHECK(!v.valid && v.n_bad_faces == 2);
    ES_CHECK_FAILS(ctx, es_lengths_check(ctx, m, len, -1, &v), ES_EINVAL, "rtol");
    ES_CHECK_FAILS(ctx, es_edge_lengths(ctx, m, NULL, len), ES_EINVAL, "NULL");
    es_mesh_free(m);
}

/* A flat disc with random in-plane jitter: every alpha is 0, corner
 * angles around an interior vertex sum to 2 pi and equal the angles
 * measured in the plane. Faces point up (+z): raising the centre makes a
 * convex cone (alpha < 0 on the fold), sinking it a concave one. */
static void test_flat_and_curved(es_ctx *ctx)
{
    enum { N = 10, R = 4 };
    int64_t nv = 1 + N * R, nf = N + 2 * N * (R - 1), f = 0;
    double *xyz = calloc((size_t)nv * 3, sizeof *xyz);
    int64_t *faces = malloc((size_t)nf * 3 * sizeof *faces);
    es_rng rng;
    es_rng_init(&rng, 7);
    for (int r = 0; r < R; r++)
        for (int i = 0; i < N; i++) {
            double t = 2 * M_PI * i / N + 0.04 * es_rng_normal(&rng);
            double rad = (r + 1) * (1 + 0.03 * es_rng_normal(&rng));
            xyz[3 * (1 + r * N + i)] = rad * cos(t);
            xyz[3 * (1 + r * N + i) + 1] = rad * sin(t);
        }
    for (int i = 0; i < N; i++) {
        faces[3 * f] = 0; faces[3 * f + 1] = 1 + i; faces[3 * f + 2] = 1 + (i + 1) % N;
        f++;
    }
    for (int r = 1; r < R; r++)
        for (int i = 0; i < N; i++) {
            int64_t a = 1 + (r - 1) * N + i, b = 1 + (r - 1) * N + (i + 1) % N;
            int64_t c = 1 + r * N + i, d = 1 + r * N + (i + 1) % N;
            faces[3 * f] = a; faces[3 * f + 1] = c; faces[3 * f + 2] = d; f++;
            faces[3 * f] = a; faces[3 * f + 1] = d; faces[3 * f + 2] = b; f++;
        }
    es_mesh *m = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, nv, nf, faces, xyz, &m));
    if (m) {
        int64_t ne = es_mesh_nedges(m);
        double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
        double *ang = malloc((size_t)nf * 3 * sizeof *ang), *vs = calloc((size_t)nv, sizeof *vs);
        const uint8_t *vb = es_mesh_vertex_on_boundary(m);
        ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, xyz, al));
        for (int64_t e = 0; e < ne; e++) ES_CHECK_CLOSE(al[e], 0.0, 0, 1e-15);
        ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, xyz, len));
        ES_CHECK_OK(ctx, es_corner_angles(ctx, m, len, ang));
        for (int64_t c = 0; c < 3 * nf; c++) vs[faces[c]] += ang[c];
        for (int64_t v = 0; v < nv; v++)
            if (!vb[v]) ES_CHECK_CLOSE(vs[v], 2 * M_PI, 0, 1e-13);
        /* corner angles agree with angles measured in space */
        for (int64_t c = 0; c < 3 * nf; c++) {
            int64_t ff = c / 3, k = c % 3;
            const double *p = xyz + 3 * faces[c], *q = xyz + 3 * faces[3 * ff + (k + 1) % 3];
            const double *r = xyz + 3 * faces[3 * ff + (k + 2) % 3];
            double u[2] = {q[0] - p[0], q[1] - p[1]}, w[2] = {r[0] - p[0], r[1] - p[1]};
            ES_CHECK_CLOSE(ang[c], atan2(u[0] * w[1] - u[1] * w[0], u[0] * w[0] + u[1] * w[1]),
                           0, 1e-13);
        }
        const int64_t *E = es_mesh_edges(m);
        for (int sign = -1; sign <= 1; sign += 2) {
            /* a cone: the centre raised (sign -1) or sunk (sign +1); its
             * spokes are convex (alpha < 0) when raised, its base (the
             * first ring) folds the other way, the rest stays flat */
            xyz[2] = -sign * 0.3;
            ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, xyz, al));
            int bad = 0;
            for (int64_t e = 0; e < ne; e++) {
                int spoke = E[2 * e] == 0, base = E[2 * e] > 0 && E[2 * e + 1] <= N;
                bad += spoke  ? !(sign * al[e] > 0)
                       : base ? !(sign * al[e] < 0)
                              : !(fabs(al[e]) < 1e-15);
            }
            ES_CHECK_MSG(bad == 0, "sign %d: %d edges with the wrong sign", sign, bad);
        }
        xyz[2] = 0;
        free(len);
        free(al);
        free(ang);
        free(vs);
    }
    es_mesh_free(m);
    free(xyz);
    free(faces);
}

/* Cube split into 12 triangles: alpha = -pi/2 on the 12 cube edges, 0 on
 * the 6 face diagonals. */
static void test_cube(es_ctx *ctx)
{
    static const double x[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                               0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const int64_t f[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    es_mesh *m = NULL;
    double len[18], al[18];
    ES_CHECK_OK(ctx, es_mesh_new(ctx, 8, 12, f, x, &m));
    if (!m) return;
    ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, x, len));
    ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, x, al));
    int ndiag = 0;
    for (int e = 0; e < 18; e++) {
        if (len[e] > 1.2) {
            ndiag++;
            ES_CHECK_CLOSE(len[e], sqrt(2.0), 1e-15, 0);
            ES_CHECK_CLOSE(al[e], 0.0, 0, 1e-15);
        } else {
            ES_CHECK_CLOSE(len[e], 1.0, 1e-15, 0);
            ES_CHECK_CLOSE(al[e], -M_PI / 2, 1e-15, 0);
        }
    }
    ES_CHECK(ndiag == 6);
    es_mesh_free(m);
}

/* One triangle with given side lengths through a 3-vertex mesh. */
static void angles_of(es_ctx *ctx, const es_mesh *tri, double l01, double l12, double l20,
                      double out[3])
{
    /* edges of the single face (0,1,2) sorted: (0,1), (0,2), (1,2) */
    double len[3] = {l01, l20, l12};
    ES_CHECK_OK(ctx, es_corner_angles(ctx, tri, len, out));
}

static void test_needles(es_ctx *ctx)
{
    int64_t face[3] = {0, 1, 2};
    es_mesh *tri = NULL;
    double a[3];
    ES_CHECK_OK(ctx, es_mesh_new(ctx, 3, 1, face, NULL, &tri));
    if (!tri) return;
    ES_CHECK(es_mesh_find_edge(tri, 0, 2) == 1 && es_mesh_find_edge(tri, 1, 2) == 2);

    /* 3-4-5: right angle at vertex 2 (opposite the side 0-1 of length 5) */
    angles_of(ctx, tri, 5, 3, 4, a);
    ES_CHECK_CLOSE(a[2], M_PI / 2, 1e-15, 0);
    ES_CHECK_CLOSE(a[0], atan2(3, 4), 1e-15, 0);
    ES_CHECK_CLOSE(a[1], atan2(4, 3), 1e-15, 0);

    /* isosceles needles with apex theta at vertex 0: Kahan keeps full
     * relative accuracy where the law of cosines returns 0 or loses half */
    for (double th = 1e-3; th > 1e-15; th /= 31) {
        double c = 2 * sin(th / 2), want = 2 * asin(c / 2); /* exact for this c */
        angles_of(ctx, tri, 1, c, 1, a);
        ES_CHECK_CLOSE(a[0], want, 1e-14, 0);
        ES_CHECK_CLOSE(a[1], (M_PI - want) / 2, 1e-15, 0);
        ES_CHECK_CLOSE(a[0] + a[1] + a[2], M_PI, 1e-15, 0);
    }
    /* flat caps: base 2, legs s = 1 + d, apex angle near pi. The reference
     * uses s - 1 = d and s + 1, both exact, so it is as accurate as atan. */
    for (double d = 1e-2; d > 1e-15; d /= 17) {
        double s = 1 + d, base = atan(sqrt((s - 1) * (s + 1)));
        angles_of(ctx, tri, 2, s, s, a); /* apex at vertex 2 */
        ES_CHECK_CLOSE(a[0], base, 1e-14, 0);
        ES_CHECK_CLOSE(a[1], base, 1e-14, 0);
        ES_CHECK_CLOSE(a[2], M_PI - 2 * base, 1e-15, 0);
        ES_CHECK_CLOSE(a[0] + a[1] + a[2], M_PI, 1e-15, 0);
    }
    /* degenerate and violating triangles: finite, clamped, sum pi */
    angles_of(ctx, tri, 1, 1, 2, a); /* collinear, vertex 1 between 0 and 2 */
    ES_CHECK(a[0] == 0 && a[2] == 0 && a[1] == M_PI);
    angles_of(ctx, tri, 1, 1, 3, a); /* violates: side 2-0 too long */
    ES_CHECK(a[0] == 0 && a[2] == 0 && a[1] == M_PI);
    angles_of(ctx, tri, 1, 0, 1, a); /* zero side */
    ES_CHECK(isfinite(a[0] + a[1] + a[2]));
    ES_CHECK_CLOSE(a[0] + a[1] + a[2], M_PI, 1e-15, 0);
    es_validity v;
    double bad[3] = {1, 3, 1};
    ES_CHECK_OK(ctx, es_lengths_check(ctx, tri, bad, 0, &v));
    ES_CHECK(v.n_bad_faces == 1 && v.worst_face == 0);
    ES_CHECK_CLOSE(v.worst_violation, 0.2, 1e-15, 0);
    es_mesh_free(tri);
}

/* ---- oracle ---- */

static void test_oracle(es_ctx *ctx)
{
    char buf[8192];
    const char *names[] = {"bumpy_ico2", "hemi2", "tube_small"};
    const char *dir = es_test_shared_path("oracle/embed", buf, sizeof buf);
    if (!dir) {
        fprintf(stderr, "skipping oracle comparison: ../shared/oracle/embed absent\n");
        return;
    }
    for (int i = 0; i < 3; i++) {
        char path[8400], line[1024];
        es_meshdata md;
        snprintf(path, sizeof path, "%s/%s/mesh.obj", dir, names[i]);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_OBJ, &md));
        if (!md.faces) continue;
        int64_t nv = md.nverts, nf = md.nfaces, *faces = md.faces;
        double *xyz = calloc((size_t)nv * 3, sizeof *xyz);
        snprintf(path, sizeof path, "%s/%s/vertices.csv", dir, names[i]);
        FILE *fp = fopen(path, "r");
        int64_t rows = 0;
        if (fp && fgets(line, sizeof line, fp))
            while (fgets(line, sizeof line, fp)) {
                long long v;
                double x, y, z;
                if (sscanf(line, "%lld,%lf,%lf,%lf", &v, &x, &y, &z) == 4 && v >= 0 && v < nv) {
                    xyz[3 * v] = x; xyz[3 * v + 1] = y; xyz[3 * v + 2] = z;
                    rows++;
                }
            }
        if (fp) fclose(fp);
        ES_CHECK(rows == nv);
        es_mesh *m = NULL;
        ES_CHECK_OK(ctx, es_mesh_new(ctx, nv, nf, faces, xyz, &m));
        if (m) {
            int64_t ne = es_mesh_nedges(m), nbad = 0, ecount = 0, ccount = 0;
            double *len = malloc((size_t)ne * sizeof *len), *al = malloc((size_t)ne * sizeof *al);
            double *nl = malloc((size_t)ne * sizeof *nl), *ang = malloc((size_t)nf * 3 * sizeof *ang);
            double maxda = 0, maxdl = 0, maxdc = 0, scale;
            const int64_t *E = es_mesh_edges(m);
            ES_CHECK_OK(ctx, es_edge_lengths(ctx, m, xyz, len));
            ES_CHECK_OK(ctx, es_lengths_normalize(ctx, ne, len, nl, &scale));
            ES_CHECK_OK(ctx, es_dihedral_angles(ctx, m, xyz, al));
            ES_CHECK_OK(ctx, es_corner_angles(ctx, m, len, ang));
            snprintf(path, sizeof path, "%s/%s/edges.csv", dir, names[i]);
            fp = fopen(path, "r");
            if (fp && fgets(line, sizeof line, fp))
                while (fgets(line, sizeof line, fp)) {
                    long long e, a, b;
                    double l, at;
                    if (sscanf(line, "%lld,%lld,%lld,%lf,%lf", &e, &a, &b, &l, &at) != 5 ||
                        e < 0 || e >= ne) { nbad++; continue; }
                    nbad += E[2 * e] != a || E[2 * e + 1] != b;
                    maxdl = fmax(maxdl, fabs(nl[e] - l) / l);
                    maxda = fmax(maxda, fabs(al[e] - at));
                    ecount++;
                }
            if (fp) fclose(fp);
            snprintf(path, sizeof path, "%s/%s/corners.csv", dir, names[i]);
            fp = fopen(path, "r");
            if (fp && fgets(line, sizeof line, fp))
                while (fgets(line, sizeof line, fp)) {
                    long long f, k, v;
                    double a;
                    if (sscanf(line, "%lld,%lld,%lld,%lf", &f, &k, &v, &a) != 4 || f < 0 ||
                        f >= nf || k < 0 || k > 2) { nbad++; continue; }
                    nbad += faces[3 * f + k] != v;
                    maxdc = fmax(maxdc, fabs(ang[3 * f + k] - a));
                    ccount++;
                }
            if (fp) fclose(fp);
            ES_CHECK_MSG(ecount == ne && ccount == 3 * nf && nbad == 0,
                         "%s: %lld edges, %lld corners, %lld bad rows", names[i],
                         (long long)ecount, (long long)ccount, (long long)nbad);
            ES_CHECK_MSG(maxdl < 1e-12 && maxda < 1e-12 && maxdc < 1e-12,
                         "%s: max |dl|/l %g, |d alpha| %g, |d corner| %g", names[i], maxdl,
                         maxda, maxdc);
            free(len); free(al); free(nl); free(ang);
        }
        es_mesh_free(m);
        free(xyz);
        es_meshdata_clear(ctx, &md);
    }
}

static void *null_malloc(void *ud, size_t n) { (void)ud; (void)n; return NULL; }
static void *null_realloc(void *ud, void *p, size_t n) { (void)ud; (void)p; (void)n; return NULL; }
static void plain_free(void *ud, void *p) { (void)ud; free(p); }

/* The only allocation of the module (face normals) fails cleanly. */
/* The bounding-box diagonal: a box 1 x 2 x 2 has diagonal 3 wherever it
 * lies; no points give 0, a non-finite coordinate NaN. */
static void test_bbox_diagonal(void)
{
    double box[12] = {5, -1, 2, 6, -1, 2, 5, 1, 4, 5.5, 0, 3};
    double bad[6] = {0, 0, 0, 1, NAN, 1};
    ES_CHECK_CLOSE(es_bbox_diagonal(4, box), 3.0, 1e-15, 0);
    ES_CHECK_CLOSE(es_bbox_diagonal(1, box), 0.0, 0, 0);
    ES_CHECK(es_bbox_diagonal(0, box) == 0.0);
    ES_CHECK(isnan(es_bbox_diagonal(2, bad)));
}

static void test_alloc_failure(es_ctx *ctx)
{
    es_mesh *m = NULL;
    double al[12];
    ES_CHECK_OK(ctx, es_mesh_new(ctx, 6, 8, oct_faces, oct_xyz, &m));
    if (!m) return;
    es_allocator a = {null_malloc, null_realloc, plain_free, NULL};
    es_ctx_set_allocator(ctx, &a);
    ES_CHECK_FAILS(ctx, es_dihedral_angles(ctx, m, oct_xyz, al), ES_ENOMEM, "out of memory");
    es_ctx_set_allocator(ctx, NULL);
    es_mesh_free(m);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_octahedron(ctx);
    test_flat_and_curved(ctx);
    test_cube(ctx);
    test_needles(ctx);
    test_oracle(ctx);
    test_bbox_diagonal();
    test_alloc_failure(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
