/* lib/embed/align.c — rotations: 3 x 3 products, the nearest proper
 * rotation to a matrix (its polar factor), and rigid alignment of a mesh
 * onto a reference (Kabsch 1976), each connected part on its own.
 *
 * Stage 2 of the embedding (edge-length-interpolation Section 2; frames
 * as in Lipman et al. 2005) projects every least-squares vertex frame onto
 * the nearest rotation, and the driver aligns the output to the initial
 * or reference positions, whose placement edge lengths do not fix.
 */
#include "embed/embed_pkg.h"
#include "embed/embed_private.h"

#include <lapacke.h>
#include <math.h>
#include <string.h>

void es__mat3_mul(const double *a, const double *b, double *out)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

void es__mat3_mul_bt(const double *a, const double *b, double *out)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1] +
                             a[3 * i + 2] * b[3 * j + 2];
}

static double det3(const double *m)
{
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}

/* Polar factor by SVD with the last singular vector flipped when needed
 * (the proper rotation nearest in Frobenius norm). */
static int nearest_rotation_svd(double *m)
{
    double a[9], s[3], u[9], vt[9], sup[2], r[9];
    for (int i = 0; i < 9; i++) a[i] = m[i];   /* row-major m = column-major m^T */
    if (LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'A', 'A', 3, 3, a, 3, s, u, 3, vt, 3, sup) != 0 ||
        !(s[0] > 0)) {
        es__mat3_identity(m);
        return -1;
    }
    /* column-major: m^T = U S V^T, so m = V S U^T; rotation V U^T (col-major r^T). */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            /* r = (U V^T)^T in col-major = V U^T: r[i][j] = sum_k vt[k][i] u[j][k] */
            r[3 * i + j] = 0;
            for (int k = 0; k < 3; k++) r[3 * i + j] += vt[k + 3 * i] * u[j + 3 * k];
        }
    if (det3(r) < 0) {
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                r[3 * i + j] = 0;
                for (int k = 0; k < 3; k++)
                    r[3 * i + j] += (k == 2 ? -1.0 : 1.0) * vt[k + 3 * i] * u[j + 3 * k];
            }
    }
    for (int i = 0; i < 9; i++) m[i] = r[i];
    return 0;
}

int es__mat3_nearest_rotation(double *m)
{
    /* Newton's iteration for the polar factor with Higham's scaling; it keeps
     * det > 0, so it returns the nearest proper rotation when det(m) > 0. */
    double x[9], inv_t[9];
    double d = det3(m);
    for (int i = 0; i < 9; i++)
        if (!isfinite(m[i])) {
            es__mat3_identity(m);
            return -1;
        }
    if (!(d > 1e-12 * pow(fabs(m[0]) + fabs(m[4]) + fabs(m[8]) + 1e-300, 3)))
        return nearest_rotation_svd(m);
    for (int i = 0; i < 9; i++) x[i] = m[i];
    for (int it = 0; it < 30; it++) {
        double dt = det3(x), nx = 0, ni = 0, g, diff = 0;
        /* inverse transpose = cofactor matrix / det */
        inv_t[0] = (x[4] * x[8] - x[5] * x[7]) / dt;
        inv_t[1] = -(x[3] * x[8] - x[5] * x[6]) / dt;
        inv_t[2] = (x[3] * x[7] - x[4] * x[6]) / dt;
        inv_t[3] = -(x[1] * x[8] - x[2] * x[7]) / dt;
        inv_t[4] = (x[0] * x[8] - x[2] * x[6]) / dt;
        inv_t[5] = -(x[0] * x[7] - x[1] * x[6]) / dt;
        inv_t[6] = (x[1] * x[5] - x[2] * x[4]) / dt;
        inv_t[7] = -(x[0] * x[5] - x[2] * x[3]) / dt;
        inv_t[8] = (x[0] * x[4] - x[1] * x[3]) / dt;
        for (int i = 0; i < 9; i++) {
            nx += x[i] * x[i];
            ni += inv_t[i] * inv_t[i];
        }
        g = it < 6 ? sqrt(sqrt(ni / nx)) : 1.0;
        for (int i = 0; i < 9; i++) {
            double y = 0.5 * (g * x[i] + inv_t[i] / g);
            diff += (y - x[i]) * (y - x[i]);
            x[i] = y;
        }
        if (diff < 1e-30) break;
    }
    for (int i = 0; i < 9; i++) m[i] = x[i];
    return 0;
}

es_status es_embed_align(es_ctx *ctx, int64_t nverts, double *xyz, const double *ref,
                         const double *w, double *rms)
{
    return es_embed_align_parts(ctx, nverts, xyz, ref, w, NULL, rms);
}

/* One pass gathers every part's weighted centroids and cross-covariance,
 * one 3 x 3 SVD per part gives its rotation, one pass moves the vertices:
 * O(V + parts), so a mesh split into many pieces (seams cut open) costs no
 * more than one piece. */
es_status es_embed_align_parts(es_ctx *ctx, int64_t nverts, double *xyz, const double *ref,
                               const double *w, const int64_t *part, double *rms)
{
    int64_t np = 1;
    double *acc, ss = 0;   /* per part: sum w, centroid of xyz (3), of ref (3), h (9), r (9) */
    enum { SW = 0, CA = 1, CB = 4, H = 7, R = 16, STRIDE = 25 };
    if (nverts <= 0 || !xyz || !ref) ES_FAIL(ctx, ES_EINVAL, "kabsch: empty input");
    if (part)
        for (int64_t v = 0; v < nverts; v++)
            if (part[v] + 1 > np) np = part[v] + 1;
    acc = es__calloc(ctx, (size_t)np * STRIDE, sizeof *acc);
    if (!acc) return ES_ENOMEM;
    for (int64_t v = 0; v < nverts; v++) {
        double wv = w ? w[v] : 1.0, *a;
        if (part && part[v] < 0) continue;
        a = acc + STRIDE * (part ? part[v] : 0);
        a[SW] += wv;
        for (int i = 0; i < 3; i++) {
            a[CA + i] += wv * xyz[3 * v + i];
            a[CB + i] += wv * ref[3 * v + i];
        }
    }
    if (!part && !(acc[SW] > 0)) {
        es__free(ctx, acc);
        ES_FAIL(ctx, ES_EINVAL, "kabsch: weights sum to %g", acc[SW]);
    }
    for (int64_t p = 0; p < np; p++)
        for (int i = 0; i < 6; i++)
            if (acc[STRIDE * p + SW] > 0) acc[STRIDE * p + CA + i] /= acc[STRIDE * p + SW];
    /* h = sum w (ref - cb)(xyz - ca)^T; the rotation R maximizing tr(R^T h)
     * is the polar factor of h (Kabsch 1976). */
    for (int64_t v = 0; v < nverts; v++) {
        double wv = w ? w[v] : 1.0, *a;
        if (part && part[v] < 0) continue;
        a = acc + STRIDE * (part ? part[v] : 0);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                a[H + 3 * i + j] += wv * (ref[3 * v + i] - a[CB + i]) * (xyz[3 * v + j] - a[CA + j]);
    }
    for (int64_t p = 0; p < np; p++) {
        double *a = acc + STRIDE * p;
        for (int i = 0; i < 9; i++) a[R + i] = a[H + i];
        /* a part with no weight keeps its place (identity, no shift) */
        if (!(a[SW] > 0) || nearest_rotation_svd(a + R) != 0) es__mat3_identity(a + R);
        if (!(a[SW] > 0))
            for (int i = 0; i < 3; i++) a[CA + i] = a[CB + i] = 0;
    }
    for (int64_t v = 0; v < nverts; v++) {
        double p[3], q[3];
        const double *a, *r;
        if (part && part[v] < 0) continue;
        a = acc + STRIDE * (part ? part[v] : 0);
        r = a + R;
        for (int i = 0; i < 3; i++) p[i] = xyz[3 * v + i] - a[CA + i];
        for (int i = 0; i < 3; i++) {
            q[i] = r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2] + a[CB + i];
            xyz[3 * v + i] = q[i];
            if (!w || w[v] > 0) ss += (q[i] - ref[3 * v + i]) * (q[i] - ref[3 * v + i]);
        }
    }
    es__free(ctx, acc);
    if (rms) *rms = sqrt(ss / (double)nverts);
    return ES_OK;
}

/* For the modules above (embed_private.h): the same polar factor. */
int es__rotation_nearest(double m[9]) { return es__mat3_nearest_rotation(m); }
