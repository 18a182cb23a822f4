/* lib/study/statismo_export.c — a stored PCA as a statismo shape model
 * (es_statismo_write; datasets-spec/statismo.md), so that statismo and
 * scalismo users can load what a study found.
 *
 * A statismo model is linear in vertex positions; an edge-length PCA is
 * linear in edge lengths, so its modes are linearized: the mean of the
 * PCA's rows and mean -/+ c sd along each PC are embedded as meshes near
 * the prior of their row weights (what es_study_embed does, all in the
 * store's frame), and the mesh displacement per sd of PC k is the central
 * difference d_k = (X(+c) - X(-c)) / 2c. The model x = X(0) + D a, a ~ N(0,
 * I) has covariance D D^T; statismo wants orthonormal modes, so its basis
 * and variances are the principal axes of D (a PCA of the 2K vectors +-d_k:
 * U and s^2 with D = U S W^T), and sample coefficients rotate with them
 * (b = W^T a). A GPA result's Procrustes PCA is already linear in
 * positions: its mean, tangent loadings and sdev^2 are the model as they
 * are. */
#include "study/study_pkg.h"
#include "edgespace/es_ingest.h"

#include <math.h>
#include <stdio.h>
#include <sys/stat.h>

void es_study_statismo_opts_init(es_study_statismo_opts *o)
{
    memset(o, 0, sizeof *o);
    o->sd = 1;
    o->noise_variance = -1;
    es_embed_opts_init(&o->embed);
}

/* "mean[...]" for the rows a PCA was fitted on (its stored filter), each
 * value quoted so that any label survives the point syntax. */
static es_status mean_spec(es_ctx *ctx, const char *filter, char *out, size_t n)
{
    size_t k = 0;
    int inq = 0, val = 0;
    if (!filter || !*filter) return snprintf(out, n, "mean") < (int)n ? ES_OK : ES_ERANGE;
    k = (size_t)snprintf(out, n, "mean[");
    for (const char *c = filter;; c++) {
        int end = !*c || (*c == ',' && !inq);
        if (val && (end || (!inq && *c == '"'))) {
            if (*c == '"') {    /* already quoted: copy through */
                val = 0;
                inq = 1;
            } else {
                if (k + 1 < n) out[k++] = '"';
                val = 0;
            }
        }
        if (!*c) break;
        if (*c == '"') inq = !inq;
        if (k + 2 >= n) ES_FAIL(ctx, ES_ERANGE, "statismo: PCA filter too long");
        out[k++] = *c;
        if (*c == '=' && !inq && c[1] != '"') {
            out[k++] = '"';
            val = 1;
        }
    }
    if (k + 2 >= n) ES_FAIL(ctx, ES_ERANGE, "statismo: PCA filter too long");
    out[k++] = ']';
    out[k] = 0;
    return ES_OK;
}

/* The modes of an edge-length PCA, linearized (see the top of the file):
 * mean (3V), basis (3V x K), variance (K), scores (K x N). */
static es_status edge_length_model(es_ctx *ctx, es_store *s, const es_study_statismo_opts *o,
                                   es_statismo_model *m, double **bufs,
                                   es_study_statismo_report *r)
{
    es_pca *p = NULL, *q = NULL;
    es_mesh *mesh = NULL;
    es_study_embedder *se = NULL;
    es_study_embed_result er;
    char path[600], filter[512] = "", mspec[1200], spec[1300];
    int64_t *prow = NULL, nprow = 0, K, V3 = 3 * es_store_nverts(s);
    double *D = NULL, *xp = NULL;
    const char *name = o->pca_name;
    char **names = NULL;
    int64_t nnames = 0;
    es_status rc;
    /* the PCA es_study_pca_load picks without a name: the only one, else
     * "default"; its filter says which rows its mean is of */
    if (!name && (rc = es_store_list_results(ctx, s, "pca", &names, &nnames)) != ES_OK)
        return rc;
    name = name ? name : nnames == 1 ? names[0] : "default";
    snprintf(r->source, sizeof r->source, "pca/%s", name);
    if ((rc = es_study_pca_load(ctx, s, name, &p, &prow, &nprow)) != ES_OK) goto done;
    snprintf(path, sizeof path, "pca/%s", name);
    if ((rc = es_store_get_attr(ctx, s, path, "filter", filter, sizeof filter)) != ES_OK)
        goto done;
    K = o->ncomp > 0 ? o->ncomp : p->ncomp < 10 ? p->ncomp : 10;
    if (K > p->ncomp) {
        rc = es__fail(ctx, ES_EINVAL, "statismo: %lld modes asked, the PCA has %lld",
                      (long long)K, (long long)p->ncomp);
        goto done;
    }
    if ((rc = mean_spec(ctx, filter, mspec, sizeof mspec)) != ES_OK ||
        (rc = es_store_mesh(ctx, s, &mesh)) != ES_OK ||
        (rc = es_study_embedder_open(ctx, s, 1, &se)) != ES_OK)
        goto done;
    bufs[0] = es__alloc_array(ctx, V3, sizeof(double));           /* mean */
    D = es__alloc_array(ctx, V3 * 2 * K, sizeof *D);               /* +-d_k */
    xp = es__alloc_array(ctx, V3, sizeof *xp);
    if (!bufs[0] || !D || !xp) {
        rc = ES_ENOMEM;
        goto done;
    }
    r->worst_rms_ratio = r->worst_bend_ratio = r->nonlinearity = 0;
    for (int64_t j = 0; j <= 2 * K && rc == ES_OK; j++) {
        int64_t k = (j - 1) / 2;
        double c = j == 0 ? 0 : (j % 2 ? -o->sd : o->sd);
        double *out = j == 0 ? bufs[0] : j % 2 ? D + V3 * k : xp;
        if ((rc = es__progress(ctx, "statismo: embedding", j, 2 * K + 1))) break;
        if (j == 0) snprintf(spec, sizeof spec, "%s", mspec);
        else snprintf(spec, sizeof spec, "%s + %.17g*pc:%lld", mspec, c, (long long)k + 1);
        /* each point from its own prior, as es_study_embed starts it: a model
         * file is a function of the store, not of the order its points were
         * embedded in (warm starts left mean -/+ c sd 1e-4 asymmetric) */
        if ((rc = es_study_embedder_point(ctx, se, spec, name, 0, &o->embed, 0, out, &er)) != ES_OK)
            break;
        r->worst_rms_ratio = fmax(r->worst_rms_ratio, er.report.rms_ratio);
        r->worst_bend_ratio = fmax(r->worst_bend_ratio, er.report.bend_ratio);
        if (j > 0 && j % 2 == 0) {
            /* d_k = (X(+c) - X(-c)) / 2c; how far from linear: the second
             * difference against the first */
            double *dk = D + V3 * k, *nk = D + V3 * (K + k), num = 0, den = 0;
            for (int64_t i = 0; i < V3; i++) {
                double a = xp[i] - bufs[0][i], b = dk[i] - bufs[0][i];
                num += (a + b) * (a + b);
                den += (a - b) * (a - b);
                dk[i] = (xp[i] - dk[i]) / (2 * o->sd);
                nk[i] = -dk[i];
            }
            r->nonlinearity = fmax(r->nonlinearity, den > 0 ? sqrt(num / den) : 0);
        }
    }
    es__progress(ctx, "statismo: embedding", 2 * K + 1, 2 * K + 1);
    if (rc != ES_OK) goto done;
    {
        /* principal axes of D: a PCA of the 2K vectors +-d_k (mean 0), whose
         * covariance is 2 D D^T / (2K - 1) */
        es_source src = es_source_matrix((es_mat){D, V3, 2 * K, V3}, NULL, 2 * K);
        es_pca_opts po;
        es_pca_opts_init(&po);
        po.ncomp = K;
        po.method = ES_PCA_GRAM;
        if ((rc = es_pca_fit(ctx, &src, &po, &q)) != ES_OK) goto done;
    }
    m->ncomp = q->ncomp;
    bufs[1] = es__alloc_array(ctx, V3 * q->ncomp, sizeof(double));
    bufs[2] = es__alloc_array(ctx, q->ncomp, sizeof(double));
    bufs[3] = es__alloc_array(ctx, q->ncomp * (nprow > 0 ? nprow : 1), sizeof(double));
    if (!bufs[1] || !bufs[2] || !bufs[3]) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t a = 0; a < q->ncomp; a++) {
        /* W[k][a] = (u_a . d_k) / s_a: the rotation from PC coefficients to
         * the mode's; the mode is signed so that its largest W is positive
         * (mode a then reads as the PC it mostly is) */
        double s2 = q->eigenvalues[a] * (double)(2 * K - 1) / 2, sa = sqrt(s2), big = 0;
        for (int64_t k = 0; k < K; k++)
            if (fabs(q->scores[k + a * 2 * K]) > fabs(big)) big = q->scores[k + a * 2 * K];
        double sign = big < 0 ? -1 : 1;
        bufs[2][a] = s2;
        for (int64_t i = 0; i < V3; i++) bufs[1][i + a * V3] = sign * q->components[i + a * V3];
        for (int64_t i = 0; i < nprow; i++) {
            double b = 0;
            for (int64_t k = 0; k < K; k++)
                b += sign * q->scores[k + a * 2 * K] / sa * p->scores[i + k * p->nrows] /
                     sqrt(p->eigenvalues[k]);
            bufs[3][a + i * q->ncomp] = b;
        }
    }
    m->mean = bufs[0];
    m->basis = bufs[1];
    m->variance = bufs[2];
    m->scores = bufs[3];
    m->nscores = nprow;
    m->noise_variance = o->noise_variance >= 0 ? o->noise_variance : 0;
done:
    es_pca_free(p);
    es_pca_free(q);
    es_study_embedder_free(se);
    es_mesh_free(mesh);
    es__free(ctx, prow);
    es__free(ctx, D);
    es__free(ctx, xp);
    for (int64_t i = 0; i < nnames; i++) es_free(ctx, names[i]);
    es_free(ctx, names);
    return rc;
}

/* A GPA result's Procrustes PCA: the mean and the tangent loadings in
 * vertex-interleaved order, sdev^2, scores in sd units, and the PPCA noise
 * (Tipping & Bishop 1999): the variance the kept modes leave, per
 * remaining dimension. */
static es_status procrustes_model(es_ctx *ctx, es_store *s, const es_study_statismo_opts *o,
                                  es_statismo_model *m, double **bufs)
{
    char path[600], buf[64];
    es_mat load = {0}, sc = {0};
    double *mean = NULL, *sdev = NULL, *pct = NULL, total;
    int64_t nm = 0, ns = 0, np = 0, K, V = es_store_nverts(s), V3 = 3 * V;
    es_status rc;
#define GP(ds) (snprintf(path, sizeof path, "gpa/%s/%s", o->gpa_name, ds), path)
    if (!es_store_has(s, GP("pc_loadings")))
        ES_FAIL(ctx, ES_ENOTFOUND, "statismo: no GPA result '%s' with pc_loadings in '%s'",
                o->gpa_name, es_store_path(s));
    snprintf(path, sizeof path, "gpa/%s", o->gpa_name);
    if ((rc = es_store_get_attr(ctx, s, path, "dim", buf, sizeof buf)) != ES_OK) return rc;
    if (strcmp(buf, "3") != 0)
        ES_FAIL(ctx, ES_EINVAL, "statismo: GPA '%s' is %sD; a mesh model needs 3D", o->gpa_name,
                buf);
    if ((rc = es_store_get_vector(ctx, s, GP("mean"), &mean, &nm)) != ES_OK ||
        (rc = es_store_get_vector(ctx, s, GP("pc_sdev"), &sdev, &ns)) != ES_OK ||
        (rc = es_store_get_vector(ctx, s, GP("pc_percent"), &pct, &np)) != ES_OK ||
        (rc = es_store_get_matrix(ctx, s, GP("pc_loadings"), &load)) != ES_OK ||
        (rc = es_store_get_matrix(ctx, s, GP("pc_scores"), &sc)) != ES_OK)
        goto done;
#undef GP
    if (nm != V3 || load.rows != V3 || load.cols != ns || sc.rows != ns) {
        rc = es__fail(ctx, ES_EMISMATCH, "statismo: GPA '%s' does not match the store's %lld "
                      "vertices", o->gpa_name, (long long)V);
        goto done;
    }
    K = o->ncomp > 0 ? o->ncomp : ns;
    if (K > ns || K < 1 || !(sdev[0] > 0) || !(pct[0] > 0)) {
        rc = es__fail(ctx, ES_EINVAL, "statismo: %lld modes asked, GPA '%s' has %lld",
                      (long long)K, o->gpa_name, (long long)ns);
        goto done;
    }
    bufs[0] = es__alloc_array(ctx, V3, sizeof(double));
    bufs[1] = es__alloc_array(ctx, V3 * K, sizeof(double));
    bufs[2] = es__alloc_array(ctx, K, sizeof(double));
    bufs[3] = es__alloc_array(ctx, K * (sc.cols > 0 ? sc.cols : 1), sizeof(double));
    if (!bufs[0] || !bufs[1] || !bufs[2] || !bufs[3]) {
        rc = ES_ENOMEM;
        goto done;
    }
    es_procrustes_to_xyz(V, mean, bufs[0]);
    total = sdev[0] * sdev[0] * 100 / pct[0];   /* pc_percent is of the total variance */
    m->noise_variance = total;
    for (int64_t k = 0; k < K; k++) {
        es_procrustes_to_xyz(V, load.data + k * load.ld, bufs[1] + k * V3);
        bufs[2][k] = sdev[k] * sdev[k];
        m->noise_variance -= bufs[2][k];
        for (int64_t j = 0; j < sc.cols; j++)
            bufs[3][k + j * K] = sc.data[k + j * sc.ld] / sdev[k];
    }
    m->noise_variance = o->noise_variance >= 0 ? o->noise_variance
                        : fmax(0, m->noise_variance) / (double)(V3 - K);
    m->mean = bufs[0];
    m->basis = bufs[1];
    m->variance = bufs[2];
    m->scores = bufs[3];
    m->ncomp = K;
    m->nscores = sc.cols;
done:
    es_free(ctx, mean);
    es_free(ctx, sdev);
    es_free(ctx, pct);
    es_free(ctx, load.data);
    es_free(ctx, sc.data);
    return rc;
}

es_status es_study_export_statismo(es_ctx *ctx, es_store *s, const es_study_statismo_opts *o,
                                   const char *path, es_study_statismo_report *r)
{
    es_statismo_model m;
    es_study_statismo_report own;
    double *bufs[4] = {NULL, NULL, NULL, NULL};
    int64_t *faces = NULL;
    char sdbuf[64];
    const char *keys[5] = {"method", "source", "store", "sd_step", "command"};
    const char *vals[5];
    es_status rc;
    if (!r) r = &own;
    memset(r, 0, sizeof *r);
    memset(&m, 0, sizeof m);
    if (!o || (o->pca_name && o->gpa_name))
        ES_FAIL(ctx, ES_EINVAL, "statismo: give a PCA or a GPA result, not both");
    if ((rc = es_statismo_check_name(ctx, path)) != ES_OK) return rc;   /* before any work */
    if (!o->gpa_name && (es_store_topology_kind(s) != ES_TOPOLOGY_MESH || es_store_nfaces(s) < 1))
        ES_FAIL(ctx, ES_EINVAL, "statismo: store '%s' has no triangles: an edge-length PCA is "
                "exported through embedded meshes; a landmark GPA (--gpa) is exported as a point "
                "set", es_store_path(s));
    {
        /* the store itself as the output: refused before the embeddings
         * (es_statismo_write refuses any HDF5 file that is not a model) */
        struct stat a, b;
        if (path && stat(path, &a) == 0 && stat(es_store_path(s), &b) == 0 &&
            a.st_dev == b.st_dev && a.st_ino == b.st_ino)
            ES_FAIL(ctx, ES_EEXIST, "statismo: refusing to overwrite the store '%s' with a "
                    "model", path);
    }
    if (o->gpa_name ? 0 : !(o->sd > 0 && isfinite(o->sd)))
        ES_FAIL(ctx, ES_EINVAL, "statismo: the step along each PC must be > 0 sd (got %g)",
                o->sd);
    m.nverts = es_store_nverts(s);
    /* a mesh model over the store's triangles; without them a point set */
    m.nfaces = es_store_topology_kind(s) == ES_TOPOLOGY_MESH ? es_store_nfaces(s) : 0;
    if (m.nfaces > 0) {
        if (!(faces = es__alloc_array(ctx, 3 * m.nfaces, sizeof *faces))) return ES_ENOMEM;
        if ((rc = es_store_read_faces(ctx, s, faces)) != ES_OK) goto done;
        m.faces = faces;
    }
    if (o->gpa_name) snprintf(r->source, sizeof r->source, "gpa/%s", o->gpa_name);
    rc = o->gpa_name ? procrustes_model(ctx, s, o, &m, bufs)
                     : edge_length_model(ctx, s, o, &m, bufs, r);
    if (rc != ES_OK) goto done;
    snprintf(sdbuf, sizeof sdbuf, "%.17g", o->gpa_name ? 0.0 : o->sd);
    vals[0] = o->gpa_name ? "Procrustes PCA (GPA tangent modes)"
                          : "edge-length PCA, linearized by embedding mean +- sd_step sd";
    vals[1] = r->source;
    vals[2] = es_store_path(s);
    vals[3] = sdbuf;
    vals[4] = o->command ? o->command : "es_study_export_statismo";
    m.builder = "edgespace export --statismo";
    m.nparams = 5;
    m.param_keys = keys;
    m.param_values = vals;
    rc = es_statismo_write(ctx, path, &m);
    r->ncomp = m.ncomp;
    r->nverts = m.nverts;
    r->nfaces = m.nfaces;
    r->noise_variance = m.noise_variance;
done:
    for (int i = 0; i < 4; i++) es__free(ctx, bufs[i]);
    es__free(ctx, faces);
    return rc;
}
