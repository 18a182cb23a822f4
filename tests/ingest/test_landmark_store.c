/* tests/ingest/test_landmark_store.c — landmark stores without faces
 * (datasets-spec/store-format.md, topology_kind):
 *  - "none": positions, ids and labels only; E = F = 0; every length
 *    operation fails with the "has no edges" message; GPA runs;
 *  - "truss": an edge list, no faces; stored lengths equal the pair
 *    distances divided by their sum (each row sums to 1), the edge list is
 *    canonical, PCA runs, es_store_mesh refuses;
 *  - a triangulation still makes a version 1 mesh store (no topology_kind);
 *  - the on-disk layout (HDF5 read directly) and the format checks: version
 *    2 without or with an unknown topology_kind, or version 3, is refused;
 * on synthetic 2D landmarks and, when ../shared is present, on the apes set
 * of landmarks_rshapes. */
#include "core/core_private.h"
#include "es_test.h"
#include "edgespace/edgespace.h"

#include <hdf5.h>   /* the on-disk layout is checked from outside the library */
#include <math.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#define NOEDGES "has no edges: it holds landmarks only; give --edges or --triangles"

static char dir[512];

static const char *tmp(const char *name)
{
    static char buf[4][700];
    static int i;
    i = (i + 1) % 4;
    snprintf(buf[i], sizeof buf[i], "%s/%s", dir, name);
    return buf[i];
}

/* n specimens of a k-gon with deterministic perturbations, 2D. */
static void write_synth(const char *lm, const char *spec, int n, int k)
{
    FILE *f = fopen(lm, "w"), *g = fopen(spec, "w");
    fputs("specimen,landmark,x,y\n", f);
    fputs("specimen,group\n", g);
    for (int j = 0; j < n; j++) {
        fprintf(g, "s%d,%s\n", j, j % 2 ? "b" : "a");
        for (int v = 0; v < k; v++) {
            double t = 2 * M_PI * v / k, r = 1 + 0.1 * sin(3.0 * j + 1.7 * v) + 0.05 * (j % 2);
            fprintf(f, "s%d,%d,%.17g,%.17g\n", j, v + 1, 10 + r * cos(t) * (1 + 0.01 * j),
                    -3 + r * sin(t));
        }
    }
    fclose(f);
    fclose(g);
}

static void check_none(es_ctx *ctx, const es_landmarks *lm, const char *path)
{
    es_store *s = NULL;
    es_mesh *m = NULL;
    double buf[64], *xyz = malloc((size_t)(3 * lm->k) * sizeof *xyz);
    unlink(path);
    ES_CHECK_OK(ctx, es_landmarks_to_store(ctx, lm, 0, NULL, path));
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    if (!s || !xyz) return;
    ES_CHECK(es_store_topology_kind(s) == ES_TOPOLOGY_NONE);
    ES_CHECK(!strcmp(es_topology_kind_name(es_store_topology_kind(s)), "none"));
    ES_CHECK(es_store_nedges(s) == 0 && es_store_nfaces(s) == 0);
    ES_CHECK(es_store_nverts(s) == lm->k && es_store_nrows(s) == lm->n);
    /* positions: 3 x V per row, z = 0 for 2D, exactly the landmarks */
    int64_t kd = lm->k * lm->d;
    double worst = 0;
    for (int64_t j = 0; j < lm->n; j++) {
        ES_CHECK(!strcmp(es_store_row_id(s, j), lm->ids[j]));
        ES_CHECK_OK(ctx, es_store_read_positions(ctx, s, j, xyz));
        for (int64_t v = 0; v < lm->k; v++)
            for (int q = 0; q < 3; q++) {
                double want = q < lm->d ? lm->xyz[kd * j + v + q * lm->k] : 0.0;
                worst = fmax(worst, fabs(xyz[3 * v + q] - want));
            }
    }
    ES_CHECK(worst == 0);
    int64_t gc = es_store_find_column(s, "group"), lc = es_landmarks_find_column(lm, "group");
    ES_CHECK(gc >= 0 && lc >= 0);
    for (int64_t j = 0; gc >= 0 && lc >= 0 && j < lm->n; j++)
        ES_CHECK(!strcmp(es_store_label(s, j, gc), lm->labels[j * lm->ncols + lc]));
    /* every length operation refuses with the message */
    ES_CHECK_FAILS(ctx, es_store_read_lengths(ctx, s, 0, 1, (es_mat){buf, 0, 1, 1}), ES_EINVAL,
                   NOEDGES);
    int64_t r0 = 0;
    ES_CHECK_FAILS(ctx, es_store_read_lengths_rows(ctx, s, &r0, 1, (es_mat){buf, 0, 1, 1}),
                   ES_EINVAL, NOEDGES);
    double *sc = malloc((size_t)lm->n * sizeof *sc);
    ES_CHECK_FAILS(ctx, es_store_read_scales(ctx, s, sc), ES_EINVAL, NOEDGES);
    free(sc);
    ES_CHECK_FAILS(ctx, es_store_mesh(ctx, s, &m), ES_EINVAL, NOEDGES);
    ES_CHECK(m == NULL);
    ES_CHECK_FAILS(ctx, es_study_pca(ctx, s, NULL, NULL, NULL, NULL), ES_EINVAL, NOEDGES);
    ES_CHECK_FAILS(ctx, es_study_mean(ctx, s, NULL, NULL), ES_EINVAL, NOEDGES);
    es_store_close(s);
    /* GPA runs on it and its result survives the commit */
    es_study_gpa_opts o;
    es_gpa_report rep;
    es_study_gpa_opts_init(&o);
    o.name = "g";
    o.command = "test";
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    ES_CHECK_OK(ctx, es_study_gpa(ctx, s, &o, &rep));
    ES_CHECK(rep.converged && rep.rmsrho > 0 && isfinite(rep.gss));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    es_store_close(s);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    char dim[16] = "";
    ES_CHECK(s && es_store_has(s, "gpa/g"));
    ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "gpa/g", "dim", dim, sizeof dim));
    ES_CHECK_MSG(atoi(dim) == lm->d, "dim %s", dim);
    ES_CHECK(es_store_topology_kind(s) == ES_TOPOLOGY_NONE);
    es_store_close(s);
    free(xyz);
}

/* Edges given unsorted, reversed and once twice: the store keeps each pair
 * once as (min, max) in order. */
static void check_truss(es_ctx *ctx, const es_landmarks *lm, const char *path)
{
    const int64_t k = lm->k;
    int64_t in[2 * 64], ne = 0;
    for (int64_t v = k - 1; v >= 0; v--) {      /* the polygon, reversed */
        in[2 * ne] = (v + 1) % k;
        in[2 * ne + 1] = v;
        ne++;
    }
    in[2 * ne] = 0, in[2 * ne + 1] = 2, ne++;  /* a diagonal */
    in[2 * ne] = 2, in[2 * ne + 1] = 0, ne++;  /* repeated, reversed */
    const int64_t E = k + 1;
    es_store *s = NULL;
    es_mesh *m = NULL;
    unlink(path);
    ES_CHECK_OK(ctx, es_landmarks_to_store_edges(ctx, lm, ne, in, path));
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK(es_store_topology_kind(s) == ES_TOPOLOGY_TRUSS);
    ES_CHECK(es_store_nfaces(s) == 0 && es_store_nedges(s) == E && es_store_nrows(s) == lm->n);
    int64_t *ed = malloc((size_t)(2 * E) * sizeof *ed);
    double *len = malloc((size_t)(E * lm->n) * sizeof *len);
    double *sc = malloc((size_t)lm->n * sizeof *sc);
    double *raw = malloc((size_t)(E * lm->n) * sizeof *raw);
    ES_CHECK_OK(ctx, es_store_read_edges(ctx, s, ed));
    for (int64_t e = 0; e < E; e++) {
        ES_CHECK(ed[2 * e] < ed[2 * e + 1]);
        if (e > 0)
            ES_CHECK(ed[2 * e - 2] < ed[2 * e] ||
                     (ed[2 * e - 2] == ed[2 * e] && ed[2 * e - 1] < ed[2 * e + 1]));
    }
    ES_CHECK(ed[0] == 0 && ed[1] == 1 && ed[2] == 0 && ed[3] == 2);
    ES_CHECK_OK(ctx, es_store_read_lengths(ctx, s, 0, lm->n, (es_mat){len, E, lm->n, E}));
    ES_CHECK_OK(ctx, es_store_read_scales(ctx, s, sc));
    ES_CHECK_OK(ctx, es_landmarks_truss_lengths(ctx, lm, E, ed, (es_mat){raw, E, lm->n, E}));
    for (int64_t j = 0; j < lm->n; j++) {
        double sum = 0, rawsum = 0;
        for (int64_t e = 0; e < E; e++) rawsum += raw[e + j * E];
        for (int64_t e = 0; e < E; e++) {
            sum += len[e + j * E];
            /* direct: the Euclidean distance of the pair in the landmark file */
            int64_t a = ed[2 * e], b = ed[2 * e + 1];
            double d2 = 0;
            for (int q = 0; q < lm->d; q++) {
                double dd = lm->xyz[j * k * lm->d + a + q * k] - lm->xyz[j * k * lm->d + b + q * k];
                d2 += dd * dd;
            }
            ES_CHECK_CLOSE(len[e + j * E], sqrt(d2) / rawsum, 1e-14, 0);
        }
        ES_CHECK_CLOSE(sum, 1.0, 1e-14, 0);
        ES_CHECK_CLOSE(sc[j], rawsum, 1e-14, 0);
    }
    ES_CHECK_FAILS(ctx, es_store_mesh(ctx, s, &m), ES_EINVAL, "truss store");
    ES_CHECK(m == NULL);
    /* PCA on the truss lengths: orthonormal components, scores reproduce the data */
    es_pca *p = NULL;
    int64_t *rows = NULL, nr = 0;
    es_study_pca_opts spo;
    es_study_pca_opts_init(&spo);
    spo.name = "p";
    spo.command = "test";
    ES_CHECK_OK(ctx, es_study_pca(ctx, s, &spo, &p, &rows, &nr));
    if (p) {
        ES_CHECK(p->nedges == E && nr == lm->n && p->ncomp >= 1);
        double worst = 0;
        for (int64_t a = 0; a < p->ncomp; a++)
            for (int64_t b = 0; b < p->ncomp; b++) {
                double dot = 0;
                for (int64_t e = 0; e < E; e++)
                    dot += p->components[e + a * E] * p->components[e + b * E];
                worst = fmax(worst, fabs(dot - (a == b)));
            }
        ES_CHECK_MSG(worst < 1e-10, "components not orthonormal: %g", worst);
        double msum = 0;
        for (int64_t e = 0; e < E; e++) msum += p->mean[e];
        ES_CHECK_CLOSE(msum, 1.0, 1e-13, 0);
    }
    es_pca_free(p);
    es_free(ctx, rows);
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    es_store_close(s);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    ES_CHECK(s && es_store_has(s, "pca/p") && es_store_topology_kind(s) == ES_TOPOLOGY_TRUSS);
    es_store_close(s);
    free(ed);
    free(len);
    free(sc);
    free(raw);
}

static void check_errors(es_ctx *ctx, const es_landmarks *lm)
{
    struct stat st;
    int64_t bad1[2] = {0, lm->k}, bad2[2] = {1, 1};
    const char *p = tmp("bad.h5");
    unlink(p);
    ES_CHECK_FAILS(ctx, es_landmarks_to_store_edges(ctx, lm, 1, bad1, p), ES_EINVAL, "edge 1");
    ES_CHECK_FAILS(ctx, es_landmarks_to_store_edges(ctx, lm, 1, bad2, p), ES_EINVAL, "edge 1");
    ES_CHECK(stat(p, &st) != 0);   /* all-or-nothing: no store appeared */
    /* the raw constructor wants canonical, sorted, unique pairs */
    es_store *s = NULL;
    int64_t unsorted[4] = {1, 2, 0, 1}, rev[2] = {2, 1};
    ES_CHECK_FAILS(ctx, es_store_create_edges(ctx, p, 3, 2, unsorted, &s), ES_EINVAL,
                   "sorted order");
    ES_CHECK_FAILS(ctx, es_store_create_edges(ctx, p, 3, 1, rev, &s), ES_EINVAL, "(min, max)");
    ES_CHECK(s == NULL && stat(p, &st) != 0);
    /* an existing store is not replaced */
    ES_CHECK_OK(ctx, es_landmarks_to_store(ctx, lm, 0, NULL, p));
    ES_CHECK_FAILS(ctx, es_landmarks_to_store(ctx, lm, 0, NULL, p), ES_EEXIST, "exists");
    unlink(p);
}

/* A triangulation still gives a mesh store that reads as before. */
static void check_mesh(es_ctx *ctx, const es_landmarks *lm, const char *path)
{
    int64_t tri[3 * 64], nt = 0;
    for (int64_t v = 1; v + 1 < lm->k; v++) {     /* fan, counter-clockwise */
        tri[3 * nt] = 0, tri[3 * nt + 1] = v, tri[3 * nt + 2] = v + 1;
        nt++;
    }
    es_store *s = NULL;
    es_mesh *m = NULL;
    unlink(path);
    ES_CHECK_OK(ctx, es_landmarks_to_store(ctx, lm, nt, tri, path));
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    if (!s) return;
    ES_CHECK(es_store_topology_kind(s) == ES_TOPOLOGY_MESH && es_store_nfaces(s) == nt);
    ES_CHECK_OK(ctx, es_store_mesh(ctx, s, &m));
    ES_CHECK(m && es_mesh_nedges(m) == es_store_nedges(s));
    es_mesh_free(m);
    es_store_close(s);
}

static int64_t attr_i64(hid_t f, const char *name)
{
    int64_t v = -1;
    hid_t a = H5Aopen(f, name, H5P_DEFAULT);
    if (a >= 0) H5Aread(a, H5T_NATIVE_INT64, &v), H5Aclose(a);
    return v;
}

/* Value of a variable-length string attribute of the root, or "" if absent. */
static void attr_str(hid_t f, const char *name, char *buf, size_t n)
{
    char *v = NULL;
    hid_t a = -1, t = H5Tcopy(H5T_C_S1);
    buf[0] = 0;
    /* UTF-8 as stored: HDF5 1.10 has no conversion to ASCII strings */
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    H5E_BEGIN_TRY { a = H5Aopen(f, name, H5P_DEFAULT); } H5E_END_TRY
    if (a >= 0 && H5Aread(a, t, &v) >= 0 && v) {
        snprintf(buf, n, "%s", v);
        H5free_memory(v);
    }
    if (a >= 0) H5Aclose(a);
    H5Tclose(t);
}

static void set_attr_str(hid_t f, const char *name, const char *val)
{
    hid_t t = H5Tcopy(H5T_C_S1), sp = H5Screate(H5S_SCALAR), a;
    H5Tset_size(t, H5T_VARIABLE);
    H5E_BEGIN_TRY { H5Adelete(f, name); } H5E_END_TRY
    a = H5Acreate2(f, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, t, &val);
    H5Aclose(a), H5Sclose(sp), H5Tclose(t);
}

static int64_t ds_rows(hid_t f, const char *name, hsize_t *d1)
{
    hsize_t d[3] = {0, 0, 0};
    int64_t r = -1;
    hid_t ds, sp;
    H5E_BEGIN_TRY { ds = H5Dopen2(f, name, H5P_DEFAULT); } H5E_END_TRY
    if (ds < 0) return -1;
    sp = H5Dget_space(ds);
    if (H5Sget_simple_extent_dims(sp, d, NULL) >= 1) r = (int64_t)d[0];
    if (d1) *d1 = d[1];
    H5Sclose(sp), H5Dclose(ds);
    return r;
}

static void check_layout(es_ctx *ctx, const char *tag)
{
    char p[3][700], kind[32];
    const char *kinds[3] = {"none", "truss", "mesh"};
    hsize_t d1 = 0;
    for (int i = 0; i < 3; i++) {
        snprintf(p[i], sizeof p[i], "%s/%s-%s.h5", dir, tag, kinds[i]);
        hid_t f = H5Fopen(p[i], H5F_ACC_RDONLY, H5P_DEFAULT);
        ES_CHECK(f >= 0);
        if (f < 0) continue;
        attr_str(f, "topology_kind", kind, sizeof kind);
        ES_CHECK_MSG(attr_i64(f, "format_version") == 3, "%s", kinds[i]);
        ES_CHECK_MSG(!strcmp(kind, kinds[i]), "%s: kind '%s'", kinds[i], kind);
        if (i < 2) ES_CHECK(ds_rows(f, "/topology/faces", &d1) == 0 && d1 == 3);
        ES_CHECK((ds_rows(f, "/topology/edges", &d1) == 0) == (i == 0) && d1 == 2);
        ES_CHECK((ds_rows(f, "/shapes/lengths", NULL) < 0) == (i == 0));
        ES_CHECK((ds_rows(f, "/shapes/scales", NULL) < 0) == (i == 0));
        ES_CHECK(ds_rows(f, "/shapes/positions", NULL) > 0);
        H5Fclose(f);
    }
    /* tampered copies of the truss store: the format checks refuse them */
    static const char *const bad[3] = {"blob", NULL, "version4"};
    for (int i = 0; i < 3; i++) {
        char q[760], cmd[1600];
        es_store *s = NULL;
        snprintf(q, sizeof q, "%s/%s-tampered.h5", dir, tag);
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", p[1], q);
        ES_CHECK(system(cmd) == 0);
        hid_t f = H5Fopen(q, H5F_ACC_RDWR, H5P_DEFAULT);
        if (f < 0) { ES_CHECK(f >= 0); continue; }
        if (i == 0) set_attr_str(f, "topology_kind", bad[i]);
        if (i == 1) H5Adelete(f, "topology_kind");
        if (i == 2) {
            int64_t v = 4;
            hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
            H5Awrite(a, H5T_NATIVE_INT64, &v);
            H5Aclose(a);
        }
        H5Fclose(f);
        ES_CHECK_FAILS(ctx, es_store_open(ctx, q, ES_STORE_READ, &s), ES_EFORMAT,
                       i == 0 ? "topology_kind 'blob'" : i == 1 ? "topology_kind" : "version 4");
        ES_CHECK(s == NULL);
        unlink(q);
    }
    /* a mesh store relabelled "truss" contradicts its faces */
    {
        char q[760], cmd[1600];
        es_store *s = NULL;
        snprintf(q, sizeof q, "%s/%s-tampered.h5", dir, tag);
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", p[2], q);
        ES_CHECK(system(cmd) == 0);
        hid_t f = H5Fopen(q, H5F_ACC_RDWR, H5P_DEFAULT);
        int64_t v = 2;
        hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
        H5Awrite(a, H5T_NATIVE_INT64, &v);
        H5Aclose(a);
        set_attr_str(f, "topology_kind", "truss");
        H5Fclose(f);
        ES_CHECK_FAILS(ctx, es_store_open(ctx, q, ES_STORE_READ, &s), ES_EFORMAT,
                       "topology kind 'truss' with");
        unlink(q);
    }
}

static void run_set(es_ctx *ctx, const char *lmcsv, const char *spec, const char *tag)
{
    es_landmarks *lm = NULL;
    char a[64], b[64], c[64];
    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, lmcsv, spec, &lm));
    if (!lm) return;
    snprintf(a, sizeof a, "%s-none.h5", tag);
    snprintf(b, sizeof b, "%s-truss.h5", tag);
    snprintf(c, sizeof c, "%s-mesh.h5", tag);
    check_none(ctx, lm, tmp(a));
    check_truss(ctx, lm, tmp(b));
    check_mesh(ctx, lm, tmp(c));
    check_errors(ctx, lm);
    check_layout(ctx, tag);
    es_landmarks_free(lm);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    snprintf(dir, sizeof dir, "%s/test-landmark-store", ES_BUILD_ROOT);
    mkdir(dir, 0777);
    const char *lm = tmp("synth.csv"), *spec = tmp("synth-spec.csv");
    write_synth(lm, spec, 7, 6);
    run_set(ctx, lm, spec, "synth");
    const char *data = es_test_shared_data();
    if (data) {
        char l2[4200], s2[4200];
        snprintf(l2, sizeof l2, "%s/landmarks_rshapes/apes_landmarks.csv", data);
        snprintf(s2, sizeof s2, "%s/landmarks_rshapes/apes_specimens.csv", data);
        if (access(l2, R_OK) == 0 && access(s2, R_OK) == 0) run_set(ctx, l2, s2, "apes");
        else fprintf(stderr, "note: apes landmarks absent, synthetic data only\n");
    } else {
        fprintf(stderr, "note: ../shared absent, synthetic data only\n");
    }
    es_ctx_free(ctx);
    ES_TEST_END();
}
