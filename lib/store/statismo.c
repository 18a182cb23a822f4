/* lib/store/statismo.c — a shape model written as a statismo file (format
 * 0.9, datasets-spec/statismo.md), the HDF5 layout that statismo's
 * StatisticalModel IO and scalismo's StatismoIO read.
 *
 * The types follow what those readers accept rather than the store's own
 * conventions: statismo keeps models in single precision and scalismo's
 * reader (jhdf) casts the data it gets to Java float and int arrays, so
 * every matrix is 32-bit float (cells 32-bit signed int), matrices are
 * row-major as statismo's Eigen types are, strings are fixed-length and
 * NUL-terminated as statismo's HDF5Utils writes them, and the version and
 * noise variance are scalars. The file is written beside its name and
 * renamed over it only when complete. */
#include "store/store_pkg.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The statismo version of the layout below (/version). */
enum { STATISMO_MAJOR = 0, STATISMO_MINOR = 9 };

/* A fixed-length C string type of strlen(s) + 1 bytes (close it). */
static hid_t fixed_str(const char *s)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t >= 0 && H5Tset_size(t, strlen(s) + 1) < 0) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

static es_status put_str_attr(es_ctx *ctx, hid_t obj, const char *key, const char *v)
{
    hid_t t = fixed_str(v), sp = H5Screate(H5S_SCALAR), a = -1;
    es_status rc = ES_OK;
    if (t < 0 || sp < 0 || (a = H5Acreate2(obj, key, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Awrite(a, t, v) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot write attribute '%s'", key);
    es__h5_close(a);
    es__h5_close(sp);
    es__h5_close(t);
    return rc;
}

static es_status put_str(es_ctx *ctx, hid_t loc, const char *name, const char *v)
{
    hid_t t = fixed_str(v), sp = H5Screate(H5S_SCALAR), d = -1;
    es_status rc = ES_OK;
    if (t < 0 || sp < 0 ||
        (d = H5Dcreate2(loc, name, t, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot write '%s'", name);
    es__h5_close(d);
    es__h5_close(sp);
    es__h5_close(t);
    return rc;
}

/* A dataset of rank 0 (dims NULL), 1 or 2 in file type ftype from buf
 * (memory type mtype, row-major). */
static es_status put_data(es_ctx *ctx, hid_t loc, const char *name, hid_t ftype, hid_t mtype,
                          int rank, const hsize_t *dims, const void *buf)
{
    hid_t sp = rank ? H5Screate_simple(rank, dims, NULL) : H5Screate(H5S_SCALAR), d = -1;
    es_status rc = ES_OK;
    if (sp < 0 ||
        (d = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot write '%s'", name);
    es__h5_close(d);
    es__h5_close(sp);
    return rc;
}

/* rows x cols doubles, element (i, j) at src[i * rs + j * cs], as a
 * row-major float32 matrix (statismo's MatrixType); cols 0: a vector of
 * rows elements (VectorType). */
static es_status put_matrix(es_ctx *ctx, hid_t loc, const char *name, int64_t rows,
                            int64_t cols, const double *src, int64_t rs, int64_t cs)
{
    hsize_t dims[2] = {(hsize_t)rows, (hsize_t)cols};
    int64_t nc = cols > 0 ? cols : 1;
    float *buf = es__alloc_array(ctx, rows * nc, sizeof *buf);
    es_status rc;
    if (!buf) return ES_ENOMEM;
    for (int64_t i = 0; i < rows; i++)
        for (int64_t j = 0; j < nc; j++) buf[i * nc + j] = (float)src[i * rs + j * cs];
    rc = put_data(ctx, loc, name, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, cols > 0 ? 2 : 1, dims, buf);
    es__free(ctx, buf);
    return rc;
}

static es_status check_model(es_ctx *ctx, const es_statismo_model *m)
{
    int64_t v3, n;
    if (!m || m->nverts < 1 || m->nfaces < 0 || m->ncomp < 1 || (m->nfaces && !m->faces) ||
        !m->mean || !m->basis || !m->variance)
        ES_FAIL(ctx, ES_EINVAL, "statismo: a model needs points, a mean and at least one mode");
    if (m->nverts > INT32_MAX)
        ES_FAIL(ctx, ES_ERANGE, "statismo: %lld vertices do not fit the format's 32-bit cells",
                (long long)m->nverts);
    if (!es__mul_i64(3, m->nverts, &v3) || !es__mul_i64(v3, m->ncomp, &n))
        ES_FAIL(ctx, ES_ERANGE, "statismo: model too large");
    for (int64_t i = 0; i < 3 * m->nfaces; i++)
        if (m->faces[i] < 0 || m->faces[i] >= m->nverts)
            ES_FAIL(ctx, ES_EINVAL, "statismo: face %lld names vertex %lld of %lld",
                    (long long)(i / 3), (long long)m->faces[i], (long long)m->nverts);
    for (int64_t i = 0; i < v3; i++)
        if (!isfinite(m->mean[i]) || fabs(m->mean[i]) > FLT_MAX)
            ES_FAIL(ctx, ES_EINVAL, "statismo: mean coordinate %lld is not a finite float",
                    (long long)i);
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(m->basis[i]))
            ES_FAIL(ctx, ES_EINVAL, "statismo: basis entry %lld is not finite", (long long)i);
    for (int64_t k = 0; k < m->ncomp; k++)
        if (!(m->variance[k] >= 0) || m->variance[k] > FLT_MAX)
            ES_FAIL(ctx, ES_EINVAL, "statismo: variance of mode %lld is %g", (long long)k + 1,
                    m->variance[k]);
    if (!(m->noise_variance >= 0) || m->noise_variance > FLT_MAX)
        ES_FAIL(ctx, ES_EINVAL, "statismo: noise variance %g", m->noise_variance);
    if (m->nscores < 0 || (m->nscores > 0 && !m->scores))
        ES_FAIL(ctx, ES_EINVAL, "statismo: %lld scores without their array",
                (long long)m->nscores);
    return ES_OK;
}

/* /representer: the mean as the reference mesh (points 3 x V, cells 3 x F),
 * or without faces as a point set (statismo's itkPointSetRepresenter:
 * datasetType POINT_SET and no cells, what scalismo's readStatismoPDM reads
 * as an UnstructuredPointsDomain). */
static es_status put_representer(es_ctx *ctx, hid_t root, const es_statismo_model *m)
{
    hid_t g = H5Gcreate2(root, "representer", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), sub;
    hsize_t dims[2] = {3, (hsize_t)m->nfaces};
    int32_t *cells = NULL;
    es_status rc;
    if (g < 0) return es__h5_fail(ctx, ES_EIO, "statismo: cannot create /representer");
    const int mesh = m->nfaces > 0;
    if ((rc = put_str_attr(ctx, g, "name",
                           mesh ? "itkStandardMeshRepresenter" : "itkPointSetRepresenter")) ||
        (rc = put_str_attr(ctx, g, "version", "1.0")) ||
        (rc = put_str_attr(ctx, g, "datasetType", mesh ? "POLYGON_MESH" : "POINT_SET")) ||
        (rc = put_matrix(ctx, g, "points", 3, m->nverts, m->mean, 1, 3)) || !mesh)
        goto done;
    if (!(cells = es__alloc_array(ctx, 3 * m->nfaces, sizeof *cells))) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t f = 0; f < m->nfaces; f++)
        for (int c = 0; c < 3; c++) cells[c * m->nfaces + f] = (int32_t)m->faces[3 * f + c];
    if ((rc = put_data(ctx, g, "cells", H5T_STD_I32LE, H5T_NATIVE_INT32, 2, dims, cells)))
        goto done;
    /* statismo's mesh representers write (and may look for) these two */
    for (int i = 0; i < 2 && rc == ES_OK; i++) {
        const char *name = i ? "cellData" : "pointData";
        if ((sub = H5Gcreate2(g, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0)
            rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot create /representer/%s", name);
        es__h5_close(sub);
    }
done:
    es__free(ctx, cells);
    es__h5_close(g);
    return rc;
}

/* /modelinfo: build time, scores (K x n, statismo's dummy 1 x 1 zero
 * without them) and one modelBuilder group with data info and parameters. */
static es_status put_modelinfo(es_ctx *ctx, hid_t root, const es_statismo_model *m)
{
    hid_t info = -1, b = -1, d = -1, p = -1;
    char when[64];
    time_t now = time(NULL);
    struct tm tmv;
    const double zero = 0;
    es_status rc = ES_OK;
    /* statismo writes asctime(localtime()); UTC here so files do not
     * depend on the machine's zone */
    strftime(when, sizeof when, "%a %b %d %H:%M:%S %Y\n", gmtime_r(&now, &tmv));
    if ((info = H5Gcreate2(root, "modelinfo", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (b = H5Gcreate2(info, "modelBuilder-0", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (d = H5Gcreate2(b, "dataInfo", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
        (p = H5Gcreate2(b, "parameters", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot create /modelinfo");
        goto done;
    }
    if ((rc = put_str(ctx, info, "build-time", when)) ||
        (rc = m->nscores > 0
                  ? put_matrix(ctx, info, "scores", m->ncomp, m->nscores, m->scores, 1,
                               m->ncomp)
                  : put_matrix(ctx, info, "scores", 1, 1, &zero, 1, 1)) ||
        (rc = put_str(ctx, b, "builderName", m->builder ? m->builder : "edgespace")) ||
        (rc = put_str(ctx, b, "buildTime", when)))
        goto done;
    for (int64_t i = 0; i < m->ndata && rc == ES_OK; i++)
        rc = put_str(ctx, d, m->data_keys[i], m->data_values[i]);
    for (int64_t i = 0; i < m->nparams && rc == ES_OK; i++)
        rc = put_str(ctx, p, m->param_keys[i], m->param_values[i]);
done:
    es__h5_close(p);
    es__h5_close(d);
    es__h5_close(b);
    es__h5_close(info);
    return rc;
}

static es_status put_model(es_ctx *ctx, hid_t root, const es_statismo_model *m)
{
    hid_t g = H5Gcreate2(root, "model", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    float noise = (float)m->noise_variance;
    es_status rc;
    if (g < 0) return es__h5_fail(ctx, ES_EIO, "statismo: cannot create /model");
    /* basis: 3V x K row-major, column k = mode k (vertex-interleaved) */
    if (!(rc = put_matrix(ctx, g, "mean", 3 * m->nverts, 0, m->mean, 1, 0)) &&
        !(rc = put_matrix(ctx, g, "pcaBasis", 3 * m->nverts, m->ncomp, m->basis, 1,
                          3 * m->nverts)) &&
        !(rc = put_matrix(ctx, g, "pcaVariance", m->ncomp, 0, m->variance, 1, 0)))
        rc = put_data(ctx, g, "noiseVariance", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, 0, NULL,
                      &noise);
    es__h5_close(g);
    return rc;
}

/* scalismo opens a model only by a name ending in .h5 (or .h5.json, its
 * JSON form): a model it cannot open is refused here, with the name to use. */
es_status es_statismo_check_name(es_ctx *ctx, const char *path)
{
    size_t n = path ? strlen(path) : 0;
    const char *base, *dot;
    if (!n) ES_FAIL(ctx, ES_EINVAL, "statismo: no output file");
    base = strrchr(path, '/');
    if (n > 3 && !strcmp(path + n - 3, ".h5")) return ES_OK;
    base = base ? base + 1 : path;
    dot = strrchr(base, '.');
    ES_FAIL(ctx, ES_EINVAL, "statismo: '%s': scalismo reads statismo models only from files "
            "named *.h5; name it '%.*s.h5'", path, (int)(dot && dot > base ? dot - path : (long)n),
            path);
}

/* An existing file may be replaced only if it is a statismo model: a typo
 * must not overwrite a store or another HDF5 file. */
static es_status check_target(es_ctx *ctx, const char *path)
{
    hid_t f = -1;
    htri_t is_model = 0;
    if (!es_store_is_hdf5(path)) return ES_OK;
    if ((f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT)) >= 0 &&
        H5Lexists(f, "model", H5P_DEFAULT) > 0 && H5Lexists(f, "representer", H5P_DEFAULT) > 0)
        is_model = H5Lexists(f, "model/pcaBasis", H5P_DEFAULT);
    es__h5_close(f);
    if (is_model <= 0)
        ES_FAIL(ctx, ES_EEXIST, "statismo: refusing to overwrite '%s': an HDF5 file that is "
                "not a statismo model", path);
    return ES_OK;
}

es_status es_statismo_write(es_ctx *ctx, const char *path, const es_statismo_model *m)
{
    es__file_replace w;
    hid_t file = -1, fapl = -1, ver = -1;
    const int32_t major = STATISMO_MAJOR, minor = STATISMO_MINOR;
    es_status rc;
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "statismo: no output file");
    if ((rc = es_statismo_check_name(ctx, path)) != ES_OK || (rc = check_model(ctx, m)) != ES_OK)
        return rc;
    H5E_BEGIN_TRY {
        rc = check_target(ctx, path);
    } H5E_END_TRY
    if (rc != ES_OK) return rc;
    /* the part file stays empty on the FILE side; HDF5 writes it by name */
    if ((rc = es__replace_begin(ctx, path, &w)) != ES_OK) return rc;
    H5E_BEGIN_TRY {
        if ((fapl = es__h5_file_access()) < 0 ||
            (file = H5Fcreate(w.tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl)) < 0) {
            rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot create '%s'", path);
        } else if ((ver = H5Gcreate2(file, "version", H5P_DEFAULT, H5P_DEFAULT,
                                     H5P_DEFAULT)) < 0) {
            rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot create /version");
        } else if (!(rc = put_data(ctx, ver, "majorVersion", H5T_STD_I32LE, H5T_NATIVE_INT32, 0,
                                   NULL, &major)) &&
                   !(rc = put_data(ctx, ver, "minorVersion", H5T_STD_I32LE, H5T_NATIVE_INT32,
                                   0, NULL, &minor)) &&
                   !(rc = put_representer(ctx, file, m)) && !(rc = put_model(ctx, file, m))) {
            rc = put_modelinfo(ctx, file, m);
        }
        es__h5_close(ver);
        /* the store's full-disk-safe close: a failed write or flush never
         * reaches libhdf5's crash at exit */
        if (es__h5_file_close(ctx, file, rc == ES_OK, path) != ES_OK && rc == ES_OK)
            rc = es__fail(ctx, ES_EIO, "statismo: %s", es_ctx_errmsg(ctx));
        es__h5_close(fapl);
    } H5E_END_TRY
    return es__replace_end(ctx, &w, rc);
}
