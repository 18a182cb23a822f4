/* lib/procrustes/procrustes.c — ordinary Procrustes analysis and shape distances.
 *
 * The rotation fitting one configuration X onto another T maximises
 * tr(R^T X^T T); with X^T T = U S V^T it is R = U V^T (Kabsch 1976;
 * Gower & Dijksterhuis 2004, ch. 4). When reflections are excluded and
 * det(U V^T) = -1 the singular vector of the smallest singular value is
 * flipped, which is shapes::procGPA's choice (fort.ROTATION) and the
 * optimum over SO(d) (Umeyama 1991, eq. 39). The scale of the
 * similarity fit is tr(R^T X^T T) / ||X||^2 (Dryden & Mardia 2016,
 * result 7.1). The Riemannian distance between two shapes is
 * acos of the same signed singular-value sum for unit-size centred
 * configurations (Dryden & Mardia, eq. 3.5; shapes::riemdist).
 */
#include "procrustes/procrustes_pkg.h"
#include "edgespace/es_procrustes.h"

#include <lapacke.h>
#include <math.h>

static double det3(const double *m, int d)
{
    if (d == 2) return m[0] * m[3] - m[1] * m[2];
    return m[0] * (m[4] * m[8] - m[7] * m[5]) - m[3] * (m[1] * m[8] - m[7] * m[2]) +
           m[6] * (m[1] * m[5] - m[4] * m[2]);
}

es_status es__procrustes_rotation(es_ctx *ctx, int d, const double *a, int allow_reflection,
                                  double *r, double *trace)
{
    double m[9], u[9], vt[9], s[3], superb[3];
    for (int i = 0; i < d * d; i++) {
        if (!isfinite(a[i])) ES_FAIL(ctx, ES_ENUMERIC, "procrustes: cross product is not finite");
        m[i] = a[i];
    }
    lapack_int info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'A', 'A', d, d, m, d, s, u, d, vt, d,
                                     superb);
    if (info != 0)
        ES_FAIL(ctx, ES_ENUMERIC, "procrustes: SVD of the %dx%d cross product failed (info %d)",
                d, d, (int)info);
    double flip = 1.0;
    if (!allow_reflection && det3(u, d) * det3(vt, d) < 0) flip = -1.0;
    /* R = U diag(1, .., flip) V^T */
    for (int j = 0; j < d; j++)
        for (int i = 0; i < d; i++) {
            double acc = 0;
            for (int l = 0; l < d; l++)
                acc += u[i + l * d] * (l == d - 1 ? flip : 1.0) * vt[l + j * d];
            r[i + j * d] = acc;
        }
    if (trace) {
        double t = 0;
        for (int l = 0; l < d; l++) t += (l == d - 1 ? flip : 1.0) * s[l];
        *trace = t;
    }
    return ES_OK;
}

void es__procrustes_cross(int64_t k, int d, const double *x, const double *y, double *a)
{
    for (int i = 0; i < d; i++)
        for (int j = 0; j < d; j++) {
            const double *xi = x + (int64_t)i * k, *yj = y + (int64_t)j * k;
            double acc = 0;
            for (int64_t p = 0; p < k; p++) acc += xi[p] * yj[p];
            a[i + j * d] = acc;
        }
}

void es__procrustes_apply(int64_t k, int d, double *x, const double *r)
{
    double *c0 = x, *c1 = x + k, *c2 = d == 3 ? x + 2 * k : NULL;
    if (d == 2) {
        for (int64_t p = 0; p < k; p++) {
            double a = c0[p], b = c1[p];
            c0[p] = a * r[0] + b * r[1];
            c1[p] = a * r[2] + b * r[3];
        }
        return;
    }
    for (int64_t p = 0; p < k; p++) {
        double a = c0[p], b = c1[p], c = c2[p];
        c0[p] = a * r[0] + b * r[1] + c * r[2];
        c1[p] = a * r[3] + b * r[4] + c * r[5];
        c2[p] = a * r[6] + b * r[7] + c * r[8];
    }
}

es_status es__procrustes_rho(es_ctx *ctx, int d, const double *a, double sx, double sy,
                             int allow_reflection, double *rho)
{
    double r[9], t, an[9];
    es_status rc;
    for (int i = 0; i < d * d; i++) an[i] = a[i] / (sx * sy);
    if ((rc = es__procrustes_rotation(ctx, d, an, allow_reflection, r, &t)) != ES_OK) return rc;
    /* rounding can push the cosine past 1 for identical shapes */
    *rho = acos(t >= 1.0 ? 1.0 : t <= -1.0 ? -1.0 : t);
    return ES_OK;
}

static es_status check_dims(es_ctx *ctx, int64_t k, int d)
{
    if (d != 2 && d != 3) ES_FAIL(ctx, ES_EINVAL, "procrustes: dimension %d is not 2 or 3", d);
    if (k < 1) ES_FAIL(ctx, ES_EINVAL, "procrustes: %lld points", (long long)k);
    return ES_OK;
}

static void centroid_of(int64_t k, int d, const double *x, double *c)
{
    for (int j = 0; j < d; j++) {
        double acc = 0;
        for (int64_t p = 0; p < k; p++) acc += x[p + j * k];
        c[j] = acc / (double)k;
    }
}

es_status es_procrustes_center(es_ctx *ctx, int64_t k, int d, double *x, double *cs)
{
    es_status rc;
    double c[3], ss = 0;
    if ((rc = check_dims(ctx, k, d)) != ES_OK) return rc;
    centroid_of(k, d, x, c);
    for (int j = 0; j < d; j++)
        for (int64_t p = 0; p < k; p++) {
            x[p + j * k] -= c[j];
            ss += x[p + j * k] * x[p + j * k];
        }
    if (cs) *cs = sqrt(ss);
    return ES_OK;
}

double es_procrustes_centroid_size(int64_t k, int d, const double *x)
{
    double c[3], ss = 0;
    if ((d != 2 && d != 3) || k < 1) return NAN;
    centroid_of(k, d, x, c);
    for (int j = 0; j < d; j++)
        for (int64_t p = 0; p < k; p++) {
            double v = x[p + j * k] - c[j];
            ss += v * v;
        }
    return sqrt(ss);
}

/* Centred copies of two configurations in one allocation. */
static es_status centred_pair(es_ctx *ctx, int64_t k, int d, const double *x, const double *y,
                              double **buf, double *sx, double *sy)
{
    int64_t kd = k * d;
    double *b = es__alloc_array(ctx, 2 * kd, sizeof *b);
    if (!b) return ES_ENOMEM;
    memcpy(b, x, (size_t)kd * sizeof *b);
    memcpy(b + kd, y, (size_t)kd * sizeof *b);
    es_procrustes_center(ctx, k, d, b, sx);
    es_procrustes_center(ctx, k, d, b + kd, sy);
    *buf = b;
    return ES_OK;
}

es_status es_procrustes_opa(es_ctx *ctx, int64_t k, int d, const double *target,
                            const double *x, int scale, int allow_reflection,
                            double *fitted, double *rot, double *s, double *oss)
{
    es_status rc;
    double *b = NULL, st, sx, a[9], r[9], tr;
    if ((rc = check_dims(ctx, k, d)) != ES_OK) return rc;
    if ((rc = centred_pair(ctx, k, d, target, x, &b, &st, &sx)) != ES_OK) return rc;
    double *tc = b, *xc = b + k * d;
    if (!(sx > 0) || !(st > 0)) {
        es__free(ctx, b);
        ES_FAIL(ctx, ES_EINVAL, "procrustes: the %s has zero centroid size (all %lld points "
                "coincide)", sx > 0 ? "target" : "configuration", (long long)k);
    }
    es__procrustes_cross(k, d, xc, tc, a);
    if ((rc = es__procrustes_rotation(ctx, d, a, allow_reflection, r, &tr)) != ES_OK) {
        es__free(ctx, b);
        return rc;
    }
    double beta = scale ? tr / (sx * sx) : 1.0;
    es__procrustes_apply(k, d, xc, r);
    double res = 0;
    for (int64_t i = 0; i < k * d; i++) {
        xc[i] *= beta;
        double e = tc[i] - xc[i];
        res += e * e;
    }
    if (fitted) memcpy(fitted, xc, (size_t)(k * d) * sizeof *fitted);
    if (rot) memcpy(rot, r, (size_t)(d * d) * sizeof *rot);
    if (s) *s = beta;
    if (oss) *oss = res;
    es__free(ctx, b);
    return ES_OK;
}

es_status es_procrustes_distance(es_ctx *ctx, int64_t k, int d, const double *x,
                                 const double *y, int allow_reflection, double *rho,
                                 double *full, double *partial)
{
    es_status rc;
    double *b = NULL, sx, sy, a[9], r;
    if ((rc = check_dims(ctx, k, d)) != ES_OK) return rc;
    if ((rc = centred_pair(ctx, k, d, x, y, &b, &sx, &sy)) != ES_OK) return rc;
    if (!(sx > 0) || !(sy > 0)) {
        es__free(ctx, b);
        ES_FAIL(ctx, ES_EINVAL, "procrustes: a configuration has zero centroid size (all %lld "
                "points coincide)", (long long)k);
    }
    es__procrustes_cross(k, d, b, b + k * d, a);
    rc = es__procrustes_rho(ctx, d, a, sx, sy, allow_reflection, &r);
    es__free(ctx, b);
    if (rc != ES_OK) return rc;
    if (rho) *rho = r;
    if (full) *full = sin(r);
    if (partial) *partial = 2.0 * sin(r / 2.0);
    return ES_OK;
}

void es_procrustes_from_xyz(int64_t k, const double *xyz, double *config)
{
    for (int64_t v = 0; v < k; v++)
        for (int q = 0; q < 3; q++) config[v + q * k] = xyz[3 * v + q];
}

void es_procrustes_to_xyz(int64_t k, const double *config, double *xyz)
{
    for (int64_t v = 0; v < k; v++)
        for (int q = 0; q < 3; q++) xyz[3 * v + q] = config[v + q * k];
}
