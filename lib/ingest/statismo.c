/* lib/ingest/statismo.c — a shape model written as a statismo file (format
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
 * renamed over it only when complete. All of its HDF5 goes through lib/h5
 * (h5/h5_private.h). */
#include "core/core_private.h"
#include "edgespace/es_ingest.h"
#include "edgespace/es_store.h"
#include "h5/h5_private.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The statismo version of the layout below (/version). */
enum { STATISMO_MAJOR = 0, STATISMO_MINOR = 9 };

/* Strings are fixed-length and NUL-terminated (statismo's HDF5Utils). */
static es_status put_str_attr(es_ctx *ctx, es__h5_id obj, const char *key, const char *v)
{
    if (es__h5_put_attr_cstr(obj, key, v) < 0)
        return es__h5_fail(ctx, ES_EIO, "statismo: cannot write attribute '%s'", key);
    return ES_OK;
}

static es_status put_str(es_ctx *ctx, es__h5_id loc, const char *name, const char *v)
{
    if (es__h5_put_cstr(loc, name, v) < 0)
        return es__h5_fail(ctx, ES_EIO, "statismo: cannot write '%s'", name);
    return ES_OK;
}

/* A float32 (f) or int32 (i) dataset of rank 0 (dims NULL), 1 or 2,
 * row-major. */
static es_status put_data(es_ctx *ctx, es__h5_id loc, const char *name, int rank,
                          const uint64_t *dims, const float *f, const int32_t *i)
{
    if ((f ? es__h5_put_f32(loc, name, rank, dims, f)
           : es__h5_put_i32(loc, name, rank, dims, i)) < 0)
        return es__h5_fail(ctx, ES_EIO, "statismo: cannot write '%s'", name);
    return ES_OK;
}

/* rows x cols doubles, element (i, j) at src[i * rs + j * cs], as a
 * row-major float32 matrix (statismo's MatrixType); cols 0: a vector of
 * rows elements (VectorType). */
static es_status put_matrix(es_ctx *ctx, es__h5_id loc, const char *name, int64_t rows,
                            int64_t cols, const double *src, int64_t rs, int64_t cs)
{
    const uint64_t dims[2] = {(uint64_t)rows, (uint64_t)cols};
    int64_t nc = cols > 0 ? cols : 1;
    float *buf = es__alloc_array(ctx, rows * nc, sizeof *buf);
    es_status rc;
    if (!buf) return ES_ENOMEM;
    for (int64_t i = 0; i < rows; i++)
        for (int64_t j = 0; j < nc; j++) buf[i * nc + j] = (float)src[i * rs + j * cs];
    rc = put_data(ctx, loc, name, cols > 0 ? 2 : 1, dims, buf, NULL);
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
static es_status put_representer(es_ctx *ctx, es__h5_id root, const es_statismo_model *m)
{
    es__h5_id g = es__h5_group_create(root, "representer", false), sub;
    const uint64_t dims[2] = {3, (uint64_t)m->nfaces};
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
    if ((rc = put_data(ctx, g, "cells", 2, dims, NULL, cells)))
        goto done;
    /* statismo's mesh representers write (and may look for) these two */
    for (int i = 0; i < 2 && rc == ES_OK; i++) {
        const char *name = i ? "cellData" : "pointData";
        if ((sub = es__h5_group_create(g, name, false)) < 0)
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
static es_status put_modelinfo(es_ctx *ctx, es__h5_id root, const es_statismo_model *m)
{
    es__h5_id info = -1, b = -1, d = -1, p = -1;
    char when[64];
    time_t now = time(NULL);
    struct tm tmv;
    const double zero = 0;
    es_status rc = ES_OK;
    /* statismo writes asctime(localtime()); UTC here so files do not
     * depend on the machine's zone */
    strftime(when, sizeof when, "%a %b %d %H:%M:%S %Y\n", gmtime_r(&now, &tmv));
    if ((info = es__h5_group_create(root, "modelinfo", false)) < 0 ||
        (b = es__h5_group_create(info, "modelBuilder-0", false)) < 0 ||
        (d = es__h5_group_create(b, "dataInfo", false)) < 0 ||
        (p = es__h5_group_create(b, "parameters", false)) < 0) {
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

static es_status put_model(es_ctx *ctx, es__h5_id root, const es_statismo_model *m)
{
    es__h5_id g = es__h5_group_create(root, "model", false);
    float noise = (float)m->noise_variance;
    es_status rc;
    if (g < 0) return es__h5_fail(ctx, ES_EIO, "statismo: cannot create /model");
    /* basis: 3V x K row-major, column k = mode k (vertex-interleaved) */
    if (!(rc = put_matrix(ctx, g, "mean", 3 * m->nverts, 0, m->mean, 1, 0)) &&
        !(rc = put_matrix(ctx, g, "pcaBasis", 3 * m->nverts, m->ncomp, m->basis, 1,
                          3 * m->nverts)) &&
        !(rc = put_matrix(ctx, g, "pcaVariance", m->ncomp, 0, m->variance, 1, 0)))
        rc = put_data(ctx, g, "noiseVariance", 0, NULL, &noise, NULL);
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
    es__h5_id f = -1;
    int is_model = 0;
    if (!es_store_is_hdf5(path)) return ES_OK;
    if ((f = es__h5_file_open_default(path)) >= 0 && es__h5_exists(f, "model") > 0 &&
        es__h5_exists(f, "representer") > 0)
        is_model = es__h5_exists(f, "model/pcaBasis");
    es__h5_close(f);
    if (is_model <= 0)
        ES_FAIL(ctx, ES_EEXIST, "statismo: refusing to overwrite '%s': an HDF5 file that is "
                "not a statismo model", path);
    return ES_OK;
}

es_status es_statismo_write(es_ctx *ctx, const char *path, const es_statismo_model *m)
{
    es__file_replace w;
    es__h5_id file = -1, ver = -1;
    const int32_t major = STATISMO_MAJOR, minor = STATISMO_MINOR;
    es_status rc;
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "statismo: no output file");
    if ((rc = es_statismo_check_name(ctx, path)) != ES_OK || (rc = check_model(ctx, m)) != ES_OK)
        return rc;
    ES__H5_QUIET(rc = check_target(ctx, path));
    if (rc != ES_OK) return rc;
    /* the part file stays empty on the FILE side; HDF5 writes it by name */
    if ((rc = es__replace_begin(ctx, path, &w)) != ES_OK) return rc;
    es__h5_quiet q;
    es__h5_quiet_begin(&q);
    if ((file = es__h5_file_create(w.tmp, true)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot create '%s'", path);
    } else if ((ver = es__h5_group_create(file, "version", false)) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot create /version");
    } else if (!(rc = put_data(ctx, ver, "majorVersion", 0, NULL, NULL, &major)) &&
               !(rc = put_data(ctx, ver, "minorVersion", 0, NULL, NULL, &minor)) &&
               !(rc = put_representer(ctx, file, m)) && !(rc = put_model(ctx, file, m))) {
        rc = put_modelinfo(ctx, file, m);
    }
    es__h5_close(ver);
    /* the full-disk-safe close of lib/h5: a failed write or flush never
     * reaches libhdf5's crash at exit */
    if (es__h5_file_close(ctx, file, rc == ES_OK, path) != ES_OK && rc == ES_OK)
        rc = es__fail(ctx, ES_EIO, "statismo: %s", es_ctx_errmsg(ctx));
    es__h5_quiet_end(&q);
    return es__replace_end(ctx, &w, rc);
}
