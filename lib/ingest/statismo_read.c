/* lib/ingest/statismo_read.c — a statismo shape model read back
 * (datasets-spec/statismo.md): what edgespace, statismo or scalismo wrote,
 * so that its mean and modes can be embedded, projected or compared with a
 * study's own.
 *
 * The reading follows scalismo's StatismoIO.readStatismoPDM: the
 * representer's datasetType says a mesh (POLYGON_MESH: points and cells) or
 * a point set (POINT_SET: points only); /model/mean, /model/pcaBasis
 * (row-major 3V x K) and /model/pcaVariance are the model; format 0.8
 * stored the basis scaled by sqrt(variance), which is undone as scalismo
 * undoes it. HDF5 converts whatever numeric type the file holds (statismo:
 * float32) to double. String attributes are read by the store's own
 * decoder (es__h5_read_attr_text), which checks the heap libhdf5 trusts.
 * All of its HDF5 goes through lib/h5 (h5/h5_private.h). */
#include "core/core_private.h"
#include "edgespace/es_ingest.h"
#include "edgespace/es_store.h"
#include "h5/h5_private.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Dataset `name` of rank 1 or 2 (dims[1] = 1 for rank 1) as doubles (f64)
 * or int64, allocated into *out. */
static es_status read_numeric(es_ctx *ctx, es__h5_id file, const char *path, const char *name,
                              bool f64, int64_t dims[2], void **out)
{
    const size_t elem = f64 ? sizeof(double) : sizeof(int64_t);
    es__h5_id d = -1;
    es__h5_info in;
    uint64_t hd[2] = {0, 1};
    es_status rc = ES_OK;
    *out = NULL;
    es__h5_raw *raw = NULL;
    if (es__h5_exists(file, name) <= 0)
        ES_FAIL(ctx, ES_EFORMAT, "statismo: '%s' has no %s: not a statismo model", path, name);
    /* a model file is input from elsewhere: its header is checked before
     * libhdf5 decodes it, as a store's is (h5_headers.c) */
    if ((rc = es__h5_raw_open(ctx, file, path, &raw)) == ES_OK)
        rc = es__h5_check_named(raw, file, name);
    es__h5_raw_close(raw);
    if (rc != ES_OK) return rc;
    if ((d = es__h5_dataset_open(file, name)) < 0 || es__h5_dataset_info(d, &in) < 0 ||
        in.rank < 1 || in.rank > 2) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "statismo: '%s': %s is not a vector or matrix", path,
                         name);
        goto done;
    }
    hd[0] = in.dims[0];
    if (in.rank == 2) hd[1] = in.dims[1];
    if (hd[0] > INT32_MAX || hd[1] > INT32_MAX || hd[0] * hd[1] == 0) {
        rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': %s is %llu x %llu", path, name,
                      (unsigned long long)hd[0], (unsigned long long)hd[1]);
        goto done;
    }
    dims[0] = (int64_t)hd[0];
    dims[1] = (int64_t)hd[1];
    if ((rc = es__h5_check_chunks(ctx, d, path, name, elem)) != ES_OK) goto done;
    if (!(*out = es__alloc_array(ctx, dims[0] * dims[1], elem))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((f64 ? es__h5_dataset_read_f64(d, *out) : es__h5_dataset_read_i64(d, *out)) < 0)
        rc = es__h5_fail(ctx, ES_EFORMAT, "statismo: '%s': cannot read %s as numbers", path,
                         name);
done:
    es__h5_close(d);
    if (rc != ES_OK) {
        es__free(ctx, *out);
        *out = NULL;
    }
    return rc;
}

/* One number `name` (a dataset of exactly one element) into *i or *f;
 * ES_ENOTFOUND when absent or not one number. Its header is checked first,
 * and the element count, so a dataset of many numbers cannot overrun it. */
static es_status read_scalar(es_ctx *ctx, es__h5_id file, const char *path, const char *name,
                             int *i, double *f)
{
    es__h5_raw *raw = NULL;
    es__h5_id d = -1;
    es__h5_info in;
    es_status rc;
    if (es__h5_exists(file, name) <= 0) return ES_ENOTFOUND;
    if ((rc = es__h5_raw_open(ctx, file, path, &raw)) == ES_OK)
        rc = es__h5_check_named(raw, file, name);
    es__h5_raw_close(raw);
    if (rc != ES_OK) return rc;
    rc = ES_ENOTFOUND;
    if ((d = es__h5_dataset_open(file, name)) >= 0 && es__h5_dataset_info(d, &in) >= 0 &&
        in.npoints == 1 &&
        (i ? es__h5_dataset_read_int(d, i) : es__h5_dataset_read_f64(d, f)) >= 0)
        rc = ES_OK;
    es__h5_close(d);
    return rc;
}

/* The groups a statismo model's names are looked up in (the root,
 * /representer, /model, /version), each header and symbol table checked
 * before HDF5 searches or opens it, as a store's are (store_load.c): a model
 * file comes from elsewhere, and libhdf5 1.10 trusts what it says. */
static es_status check_groups(es_ctx *ctx, es__h5_id file, const char *path)
{
    static const char *const names[] = {"representer", "model", "version"};
    es__h5_raw *raw = NULL;
    es_status rc = es__h5_raw_open(ctx, file, path, &raw);
    if (rc == ES_OK) rc = es__h5_check_groups(raw, file, names, sizeof names / sizeof names[0]);
    es__h5_raw_close(raw);
    return rc;
}

/* The representer's datasetType (and name), read as scalismo does. */
static es_status read_kind(es_ctx *ctx, es__h5_id file, const char *path, es_statismo_data *m)
{
    es__h5_raw *raw = NULL;
    es__h5_id g = -1;
    char name[64] = "";
    es_status rc;
    if (es__h5_exists(file, "representer") <= 0 ||
        (g = es__h5_group_open(file, "representer")) < 0)
        ES_FAIL(ctx, ES_EFORMAT, "statismo: '%s' has no /representer: not a statismo model",
                path);
    if ((rc = es__h5_raw_open(ctx, g, path, &raw)) == ES_OK &&
        (rc = es__h5_check_object(raw, g, "/representer")) == ES_OK) {
        rc = es__h5_read_attr_text(ctx, raw, g, "datasetType", m->dataset_type,
                                   sizeof m->dataset_type);
        if (rc == ES_ENOTFOUND)
            rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': /representer has no datasetType "
                          "(a statismo 0.8 VTK representer is not read)", path);
        if (rc == ES_OK && es__h5_read_attr_text(ctx, raw, g, "name", name, sizeof name) != ES_OK)
            name[0] = '\0';
    }
    es__h5_raw_close(raw);
    es__h5_close(g);
    if (rc != ES_OK) return rc;
    if (strcmp(m->dataset_type, "POLYGON_MESH") && strcmp(m->dataset_type, "POINT_SET"))
        ES_FAIL(ctx, ES_EFORMAT, "statismo: '%s' is a %s model%s%s; edgespace reads POLYGON_MESH "
                "and POINT_SET models", path, m->dataset_type, *name ? " of " : "", name);
    return ES_OK;
}

static es_status read_impl(es_ctx *ctx, es__h5_id file, const char *path, es_statismo_data *m)
{
    int64_t dm[2], db[2], dv[2], dp[2], dc[2];
    double *basis = NULL, *pts = NULL;
    int64_t *cells = NULL;
    es_status rc;
    if ((rc = check_groups(ctx, file, path)) != ES_OK) return rc;
    if ((rc = read_kind(ctx, file, path, m)) != ES_OK) return rc;
    if ((rc = read_scalar(ctx, file, path, "version/majorVersion", &m->major, NULL)) == ES_OK)
        rc = read_scalar(ctx, file, path, "version/minorVersion", &m->minor, NULL);
    if (rc != ES_OK && rc != ES_ENOTFOUND) return rc;
    if (rc != ES_OK)
        ES_FAIL(ctx, ES_EFORMAT, "statismo: '%s' has no /version/majorVersion and minorVersion",
                path);
    if (!(m->major == 1 || (m->major == 0 && (m->minor == 8 || m->minor == 9))))
        ES_FAIL(ctx, ES_EFORMAT, "statismo: '%s' is format %d.%d; 0.8, 0.9 and 1.x are read",
                path, m->major, m->minor);
    if ((rc = read_numeric(ctx, file, path, "model/mean", true, dm, (void **)&m->mean)) != ES_OK ||
        (rc = read_numeric(ctx, file, path, "model/pcaBasis", true, db, (void **)&basis)) ||
        (rc = read_numeric(ctx, file, path, "model/pcaVariance", true, dv,
                           (void **)&m->variance)) != ES_OK ||
        (rc = read_numeric(ctx, file, path, "representer/points", true, dp,
                           (void **)&pts)) != ES_OK)
        goto done;
    m->nverts = dp[1];
    m->ncomp = db[1];
    if (dp[0] != 3 || dm[0] * dm[1] != 3 * m->nverts || db[0] != 3 * m->nverts ||
        dv[0] * dv[1] != m->ncomp) {
        rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': the sizes disagree (points %lld x %lld, "
                      "mean %lld, basis %lld x %lld, variance %lld; 3D models are read)", path,
                      (long long)dp[0], (long long)dp[1], (long long)(dm[0] * dm[1]),
                      (long long)db[0], (long long)db[1], (long long)(dv[0] * dv[1]));
        goto done;
    }
    if (!(m->basis = es__alloc_array(ctx, db[0] * db[1], sizeof(double))) ||
        !(m->points = es__alloc_array(ctx, 3 * m->nverts, sizeof(double)))) {
        rc = ES_ENOMEM;
        goto done;
    }
    /* row-major 3V x K -> column k = mode k; points 3 x V -> interleaved */
    for (int64_t r = 0; r < db[0]; r++)
        for (int64_t k = 0; k < m->ncomp; k++)
            m->basis[r + k * db[0]] = basis[r * m->ncomp + k];
    for (int64_t v = 0; v < m->nverts; v++)
        for (int c = 0; c < 3; c++) m->points[3 * v + c] = pts[c * m->nverts + v];
    for (int64_t k = 0; k < m->ncomp; k++) {
        double sd = sqrt(m->variance[k]);
        if (!(m->variance[k] >= 0) || !isfinite(m->variance[k])) {
            rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': variance of mode %lld is %g", path,
                          (long long)k + 1, m->variance[k]);
            goto done;
        }
        if (m->major == 0 && m->minor == 8)   /* stored U sqrt(variance): as scalismo undoes it */
            for (int64_t r = 0; r < db[0]; r++) m->basis[r + k * db[0]] *= sd > 1e-8 ? 1 / sd : 0;
    }
    rc = read_scalar(ctx, file, path, "model/noiseVariance", NULL, &m->noise_variance);
    if (rc != ES_OK && rc != ES_ENOTFOUND) goto done;
    if (rc != ES_OK) m->noise_variance = 0;   /* optional: absent means none */
    rc = ES_OK;
    if (!strcmp(m->dataset_type, "POLYGON_MESH")) {
        if ((rc = read_numeric(ctx, file, path, "representer/cells", false, dc,
                               (void **)&cells)) != ES_OK)
            goto done;
        if (dc[0] != 3) {
            rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': cells are %lld x %lld, not "
                          "triangles (3 x F)", path, (long long)dc[0], (long long)dc[1]);
            goto done;
        }
        m->nfaces = dc[1];
        if (!(m->faces = es__alloc_array(ctx, 3 * m->nfaces, sizeof(int64_t)))) {
            rc = ES_ENOMEM;
            goto done;
        }
        for (int64_t f = 0; f < m->nfaces; f++)
            for (int c = 0; c < 3; c++) {
                int64_t v = cells[c * m->nfaces + f];
                if (v < 0 || v >= m->nverts) {
                    rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': cell %lld names point %lld "
                                  "of %lld", path, (long long)f, (long long)v,
                                  (long long)m->nverts);
                    goto done;
                }
                m->faces[3 * f + c] = v;
            }
    }
    for (int64_t i = 0; i < 3 * m->nverts; i++)
        if (!isfinite(m->mean[i]) || !isfinite(m->points[i])) {
            rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': coordinate %lld is not finite", path,
                          (long long)i);
            goto done;
        }
    for (int64_t i = 0; i < db[0] * db[1]; i++)
        if (!isfinite(m->basis[i])) {
            rc = es__fail(ctx, ES_EFORMAT, "statismo: '%s': basis entry %lld is not finite", path,
                          (long long)i);
            goto done;
        }
done:
    es__free(ctx, basis);
    es__free(ctx, pts);
    es__free(ctx, cells);
    return rc;
}

es_status es_statismo_read(es_ctx *ctx, const char *path, es_statismo_data **out)
{
    es_statismo_data *m;
    es__h5_id file = -1;
    es_status rc;
    if (!path || !out) ES_FAIL(ctx, ES_EINVAL, "statismo: NULL argument");
    *out = NULL;
    if (!es_store_is_hdf5(path))
        ES_FAIL(ctx, ES_EFORMAT, "statismo: '%s' is not an HDF5 file (or cannot be read)", path);
    if ((rc = es__h5_check_file(ctx, path)) != ES_OK) return rc;
    if (!(m = es__calloc(ctx, 1, sizeof *m))) return ES_ENOMEM;
    m->ctx = ctx;
    es__h5_quiet q;
    es__h5_quiet_begin(&q);
    if ((file = es__h5_file_open(path, false)) < 0)
        rc = es__h5_fail(ctx, ES_EIO, "statismo: cannot open '%s'", path);
    else
        rc = read_impl(ctx, file, path, m);
    es__h5_close(file);
    es__h5_quiet_end(&q);
    if (rc != ES_OK) {
        es_statismo_data_free(m);
        return rc;
    }
    *out = m;
    return ES_OK;
}

void es_statismo_data_free(es_statismo_data *m)
{
    if (!m) return;
    es__free(m->ctx, m->faces);
    es__free(m->ctx, m->mean);
    es__free(m->ctx, m->points);
    es__free(m->ctx, m->basis);
    es__free(m->ctx, m->variance);
    es__free(m->ctx, m);
}
