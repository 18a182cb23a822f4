/* tests/study/test_statismo.c — statismo shape models from a store
 * (es_study_export_statismo, es_statismo_write), read back with the HDF5 C
 * API from outside the library.
 *
 * On synthetic faces: the file has statismo 0.9's layout (version scalars,
 * float32 matrices of the sizes datasets-spec/statismo.md gives, int32
 * cells equal to the store's faces), orthonormal modes; a GPA's model is
 * its mean, loadings and sdev^2 in single precision; a PCA's mean is the
 * embedding es_study_embed makes of the PCA's mean. Errors: both results,
 * a missing one, too many modes, sd <= 0, a store as the output (refused,
 * left as it was), invalid models; a failed write leaves an earlier model
 * byte for byte and no part file. python/tests/test_statismo.py checks the
 * rest of the format with h5py. */
#include "es_test.h"
#include "es_test_files.h"
#include "edgespace/edgespace.h"

#include <hdf5.h>   /* the file is read from outside the library */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A whole dataset as float (or int32 with is_int), its dims in d[0..1]
 * (rank 1: d[1] = 0, scalar: both 0). NULL if absent. */
static void *read_ds(const char *path, const char *name, int is_int, hsize_t d[2], int *rank,
                     hid_t *ftype_class)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), ds = -1, sp = -1, t = -1;
    void *buf = NULL;
    d[0] = d[1] = 0;
    *rank = -1;
    if (f < 0) return NULL;
    H5E_BEGIN_TRY { ds = H5Dopen2(f, name, H5P_DEFAULT); } H5E_END_TRY
    if (ds >= 0) {
        sp = H5Dget_space(ds);
        t = H5Dget_type(ds);
        *rank = H5Sget_simple_extent_ndims(sp);
        H5Sget_simple_extent_dims(sp, d, NULL);
        *ftype_class = H5Tget_class(t) == H5T_FLOAT ? (H5Tget_size(t) == 4 ? 32 : 64)
                                                    : (H5Tget_size(t) == 4 ? -32 : -64);
        size_t n = (size_t)(*rank > 0 ? d[0] : 1) * (size_t)(*rank > 1 ? d[1] : 1);
        buf = malloc(n * 4);
        H5Dread(ds, is_int ? H5T_NATIVE_INT32 : H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                buf);
        H5Tclose(t);
        H5Sclose(sp);
        H5Dclose(ds);
    }
    H5Fclose(f);
    return buf;
}

static es_status make_store(es_ctx *ctx, const char *dir, char *path, size_t n)
{
    es_synth_opts o;
    es_synth_set set;
    char sub[4200], man[4300];
    es_status rc;
    es_synth_opts_init(&o);
    o.n = 5;
    snprintf(sub, sizeof sub, "%s/faces", dir);
    snprintf(man, sizeof man, "%s/manifest.csv", sub);
    snprintf(path, n, "%s/faces.h5", dir);
    if ((rc = es_synth_generate(ctx, ES_SYNTH_FACE, &o, &set)) != ES_OK) return rc;
    rc = es_synth_write(ctx, &set, sub);
    es_synth_set_clear(ctx, &set);
    return rc ? rc : es_ingest_manifest(ctx, path, man, NULL, NULL);
}

static void check_layout(const char *path, int64_t V, int64_t F, int64_t K, const int64_t *faces)
{
    hsize_t d[2];
    int rank;
    hid_t cls = 0;
    int32_t *maj = read_ds(path, "version/majorVersion", 1, d, &rank, &cls);
    int32_t *min = read_ds(path, "version/minorVersion", 1, d, &rank, &cls);
    ES_CHECK(maj && min && maj[0] == 0 && min[0] == 9 && rank == 0 && cls == -32);
    free(maj), free(min);
    float *U = read_ds(path, "model/pcaBasis", 0, d, &rank, &cls);
    ES_CHECK(U && rank == 2 && d[0] == (hsize_t)(3 * V) && d[1] == (hsize_t)K && cls == 32);
    /* orthonormal columns (float32: to 1e-5) */
    for (int64_t a = 0; U && a < K; a++)
        for (int64_t b = 0; b <= a; b++) {
            double dot = 0;
            for (int64_t i = 0; i < 3 * V; i++) dot += (double)U[i * K + a] * U[i * K + b];
            ES_CHECK_CLOSE(dot, a == b ? 1.0 : 0.0, 0, 1e-5);
        }
    free(U);
    int32_t *cells = read_ds(path, "representer/cells", 1, d, &rank, &cls);
    ES_CHECK(cells && d[0] == 3 && d[1] == (hsize_t)F && cls == -32);
    for (int64_t f = 0; cells && f < F; f++)
        for (int c = 0; c < 3; c++) ES_CHECK(cells[c * F + f] == faces[3 * f + c]);
    free(cells);
    float *var = read_ds(path, "model/pcaVariance", 0, d, &rank, &cls);
    ES_CHECK(var && rank == 1 && d[0] == (hsize_t)K && cls == 32);
    for (int64_t k = 1; var && k < K; k++) ES_CHECK(var[k] <= var[k - 1] && var[k] >= 0);
    free(var);
    float *nv = read_ds(path, "model/noiseVariance", 0, d, &rank, &cls);
    ES_CHECK(nv && rank == 0 && nv[0] >= 0);
    free(nv);
}

int main(void)
{
    es_ctx *ctx = NULL;
    es_store *s = NULL;
    char path[4400], model[4400], gmodel[4400];
    const char *dir = es_test_tmpdir("statismo");
    es_study_statismo_opts o;
    es_study_statismo_report r;
    es_pca_opts po;
    int64_t V, F, *faces;
    ES_TEST_BEGIN();
    ES_CHECK_OK(ctx, es_ctx_new(&ctx));
    ES_CHECK_OK(ctx, make_store(ctx, dir, path, sizeof path));
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) ES_TEST_END();
    es_pca_opts_init(&po);
    po.ncomp = 4;
    es_study_pca_opts so;
    es_study_pca_opts_init(&so);
    so.name = "p";
    so.pca = po;
    so.command = "test";
    ES_CHECK_OK(ctx, es_study_pca(ctx, s, &so, NULL, NULL, NULL));
    es_study_gpa_opts go;
    es_study_gpa_opts_init(&go);
    go.name = "g";
    go.command = "test";
    ES_CHECK_OK(ctx, es_study_gpa(ctx, s, &go, NULL));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    V = es_store_nverts(s);
    F = es_store_nfaces(s);
    faces = malloc(sizeof *faces * (size_t)(3 * F));
    ES_CHECK_OK(ctx, es_store_read_faces(ctx, s, faces));
    snprintf(model, sizeof model, "%s/p.h5", dir);
    snprintf(gmodel, sizeof gmodel, "%s/g.h5", dir);

    /* an edge-length PCA: its mean is es_study_embed's embedding of it */
    es_study_statismo_opts_init(&o);
    o.pca_name = "p";
    o.ncomp = 2;
    ES_CHECK_OK(ctx, es_study_export_statismo(ctx, s, &o, model, &r));
    ES_CHECK(r.ncomp == 2 && r.nverts == V && r.nfaces == F && !strcmp(r.source, "pca/p"));
    ES_CHECK(r.worst_rms_ratio > 0 && r.worst_rms_ratio < 1e-3 && r.noise_variance == 0);
    check_layout(model, V, F, 2, faces);
    {
        es_study_embed_opts eo;
        es_study_embed_result er;
        double *xyz = malloc(sizeof *xyz * (size_t)(3 * V));
        hsize_t d[2];
        int rank;
        hid_t cls;
        float *mean = read_ds(model, "model/mean", 0, d, &rank, &cls);
        es_study_embed_opts_init(&eo);
        eo.point = "mean";
        eo.pca_name = "p";
        ES_CHECK_OK(ctx, es_study_embed(ctx, s, &eo, xyz, &er));
        ES_CHECK(mean && d[0] == (hsize_t)(3 * V));
        for (int64_t i = 0; mean && i < 3 * V; i++) ES_CHECK(mean[i] == (float)xyz[i]);
        free(mean);
        free(xyz);
    }

    /* a Procrustes PCA: the GPA's numbers in single precision */
    es_study_statismo_opts_init(&o);
    o.gpa_name = "g";
    ES_CHECK_OK(ctx, es_study_export_statismo(ctx, s, &o, gmodel, &r));
    {
        double *sdev = NULL, *gmean = NULL, *xyz = malloc(sizeof *xyz * (size_t)(3 * V));
        int64_t ns = 0, nm = 0;
        es_mat load = {0};
        hsize_t d[2];
        int rank;
        hid_t cls;
        ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, "gpa/g/pc_sdev", &sdev, &ns));
        ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, "gpa/g/mean", &gmean, &nm));
        ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, "gpa/g/pc_loadings", &load));
        ES_CHECK(r.ncomp == ns && ns > 2 && r.noise_variance > 0);
        check_layout(gmodel, V, F, ns, faces);
        float *var = read_ds(gmodel, "model/pcaVariance", 0, d, &rank, &cls);
        float *U = read_ds(gmodel, "model/pcaBasis", 0, d, &rank, &cls);
        float *mean = read_ds(gmodel, "model/mean", 0, d, &rank, &cls);
        for (int64_t k = 0; var && k < ns; k++) ES_CHECK(var[k] == (float)(sdev[k] * sdev[k]));
        es_procrustes_to_xyz(V, gmean, xyz);
        for (int64_t i = 0; mean && i < 3 * V; i++) ES_CHECK(mean[i] == (float)xyz[i]);
        es_procrustes_to_xyz(V, load.data + load.ld, xyz);   /* mode 2 */
        for (int64_t i = 0; U && i < 3 * V; i++) ES_CHECK(U[i * ns + 1] == (float)xyz[i]);
        free(var), free(U), free(mean), free(xyz);
        es_free(ctx, sdev);
        es_free(ctx, gmean);
        es_free(ctx, load.data);
    }

    /* errors */
    {
        size_t n0 = 0, n1 = 0;
        char *before = es_test_slurp(model, &n0), *store_before = es_test_slurp(path, &n1);
        es_study_statismo_opts_init(&o);
        o.pca_name = "p";
        o.gpa_name = "g";
        ES_CHECK_FAILS(ctx, es_study_export_statismo(ctx, s, &o, model, NULL), ES_EINVAL,
                       "not both");
        o.pca_name = NULL;
        o.gpa_name = "nope";
        ES_CHECK_FAILS(ctx, es_study_export_statismo(ctx, s, &o, model, NULL), ES_ENOTFOUND,
                       "no GPA result 'nope'");
        o.gpa_name = NULL;
        o.pca_name = "p";
        o.ncomp = 5;
        ES_CHECK_FAILS(ctx, es_study_export_statismo(ctx, s, &o, model, NULL), ES_EINVAL,
                       "5 modes asked, the PCA has 4");
        o.ncomp = 1;
        o.sd = 0;
        ES_CHECK_FAILS(ctx, es_study_export_statismo(ctx, s, &o, model, NULL), ES_EINVAL,
                       "> 0 sd");
        o.sd = 1;
        ES_CHECK_FAILS(ctx, es_study_export_statismo(ctx, s, &o, path, NULL), ES_EEXIST,
                       "refusing to overwrite the store");
        ES_CHECK(es_test_same_bytes(path, store_before, n1));
        {   /* any other HDF5 file that is not a model: refused at the write */
            char copy[4400];
            FILE *c;
            snprintf(copy, sizeof copy, "%s/other.h5", dir);
            if ((c = fopen(copy, "wb"))) {
                fwrite(store_before, 1, n1, c);
                fclose(c);
            }
            ES_CHECK_FAILS(ctx, es_study_export_statismo(ctx, s, &o, copy, NULL), ES_EEXIST,
                           "not a statismo model");
            ES_CHECK(es_test_same_bytes(copy, store_before, n1));
        }
        /* invalid models: nothing written, the earlier file intact */
        double mean[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, basis[9] = {1}, var1[1] = {1};
        int64_t tri[3] = {0, 1, 3};
        es_statismo_model m = {3, 1, tri, mean, 1, basis, var1, 0, 0, NULL, NULL, 0, 0,
                               NULL, NULL, NULL, NULL};
        ES_CHECK_FAILS(ctx, es_statismo_write(ctx, model, &m), ES_EINVAL, "face 0 names vertex 3");
        tri[2] = 2;
        var1[0] = -1;
        ES_CHECK_FAILS(ctx, es_statismo_write(ctx, model, &m), ES_EINVAL, "variance of mode 1");
        var1[0] = 1;
        m.ncomp = 0;
        ES_CHECK_FAILS(ctx, es_statismo_write(ctx, model, &m), ES_EINVAL, "at least one mode");
        ES_CHECK(es_test_same_bytes(model, before, n0));
        ES_CHECK(es_test_count_entries(dir, ".part") == 0);
        m.ncomp = 1;   /* and a valid one replaces it */
        ES_CHECK_OK(ctx, es_statismo_write(ctx, model, &m));
        check_layout(model, 3, 1, 1, tri);
        {   /* read back (es_statismo_read) as written; a name scalismo cannot open refused */
            es_statismo_data *d = NULL;
            char bad[4400];
            ES_CHECK_OK(ctx, es_statismo_read(ctx, model, &d));
            ES_CHECK(d && d->nverts == 3 && d->nfaces == 1 && d->ncomp == 1 &&
                     !strcmp(d->dataset_type, "POLYGON_MESH") && d->minor == 9);
            for (int i = 0; d && i < 9; i++)
                ES_CHECK(d->mean[i] == mean[i] && d->points[i] == mean[i] &&
                         d->basis[i] == basis[i]);
            for (int i = 0; d && i < 3; i++) ES_CHECK(d->faces[i] == tri[i]);
            es_statismo_data_free(d);
            snprintf(bad, sizeof bad, "%s/m.hdf5", dir);
            ES_CHECK_FAILS(ctx, es_statismo_write(ctx, bad, &m), ES_EINVAL, "name it '");
            ES_CHECK(access(bad, F_OK) != 0);
            ES_CHECK_FAILS(ctx, es_statismo_read(ctx, path, &d), ES_EFORMAT, "representer");
        }
        free(before);
        free(store_before);
    }
    free(faces);
    es_store_close(s);
    es_ctx_free(ctx);
    ES_TEST_END();
}
