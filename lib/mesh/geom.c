/* lib/mesh/geom.c — geometry on a fixed topology: edge lengths, scale
 * normalization, corner angles, signed bending (dihedral) angles, and the
 * validity check of a length vector.
 *
 * Corner angles use Kahan's formula for the angles of a needle-like
 * triangle (W. Kahan, "Miscalculating Area and Angles of a Needle-like
 * Triangle", 2014, Section 3): accurate to a few ulps for every valid
 * triangle, where the law of cosines loses half the digits near 0 and pi.
 * Dihedrals use atan2 of the cross and dot products of the normals, which
 * keeps full accuracy near 0 and +-pi where acos would not (oracle README,
 * "lessons"). Sign convention of es_geom.h, shared with the oracle:
 * alpha_e = atan2((n_g x n_f) . t, n_g . n_f). Scale normalization is the
 * paper's eq. 12 (sum of lengths = 1).
 */
#include "edgespace/es_geom.h"
#include "mesh/mesh_pkg.h"
#include "core/vec3.h"

#include <math.h>

static es_status check_args(es_ctx *ctx, const char *fn, const es_mesh *mesh,
                            const void *in, const void *out)
{
    if (!mesh || !in || !out)
        ES_FAIL(ctx, ES_EINVAL, "%s: NULL %s", fn, !mesh ? "mesh" : !in ? "input" : "output");
    return ES_OK;
}

es_status es_edge_lengths(es_ctx *ctx, const es_mesh *mesh, const double *xyz, double *len)
{
    es_status rc = check_args(ctx, "es_edge_lengths", mesh, xyz, len);
    if (rc != ES_OK) return rc;
    for (int64_t e = 0; e < mesh->ne; e++) {
        const double *a = xyz + 3 * mesh->edges[2 * e], *b = xyz + 3 * mesh->edges[2 * e + 1];
        double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
        len[e] = sqrt(dx * dx + dy * dy + dz * dz);
    }
    return ES_OK;
}

es_status es_lengths_normalize(es_ctx *ctx, int64_t nedges, const double *len, double *out,
                               double *scale)
{
    double s = 0;
    if (nedges < 0 || (nedges > 0 && (!len || !out)))
        ES_FAIL(ctx, ES_EINVAL, "es_lengths_normalize: bad arguments (%lld edges)",
                (long long)nedges);
    for (int64_t e = 0; e < nedges; e++) s += len[e];
    if (!(isfinite(s) && s > 0))
        ES_FAIL(ctx, ES_EINVAL,
                "es_lengths_normalize: sum of %lld lengths is %g, not finite and positive",
                (long long)nedges, s);
    for (int64_t e = 0; e < nedges; e++) out[e] = len[e] / s;
    if (scale) *scale = s;
    return ES_OK;
}

/* Angle opposite side c of the triangle with sides a, b, c (Kahan 2014):
 * with a >= b, mu = c - (a - b) if b >= c, else b - (a - c), and
 * C = 2 atan(sqrt(((a - b) + c) mu / ((a + (b + c)) ((a - c) + b)))).
 * The parentheses matter. A violated triangle inequality makes the
 * argument negative: clamp to 0 (c too short) or pi (c too long). Both
 * factors vanish only when b = 0 and c = a: the angle at an end of a
 * zero-length side is undetermined, reported as -1 and settled by the
 * caller. NaN passes through. */
static double kahan_angle(double a, double b, double c)
{
    if (a < b) { double t = a; a = b; b = t; }
    double mu = b >= c ? c - (a - b) : b - (a - c);
    double num = ((a - b) + c) * mu, den = (a + (b + c)) * ((a - c) + b);
    if (isnan(num) || isnan(den)) return NAN;
    if (num <= 0 && den <= 0) return -1;
    if (num <= 0) return 0;
    if (den <= 0) return M_PI;
    return 2 * atan(sqrt(num / den));
}

es_status es_corner_angles(es_ctx *ctx, const es_mesh *mesh, const double *len, double *angles)
{
    es_status rc = check_args(ctx, "es_corner_angles", mesh, len, angles);
    if (rc != ES_OK) return rc;
    for (int64_t f = 0; f < mesh->nf; f++) {
        const int64_t *fe = mesh->face_edges + 3 * f;
        double *t = angles + 3 * f;
        /* side k joins corners k and k+1, so corner k faces side k+1 */
        double l0 = len[fe[0]], l1 = len[fe[1]], l2 = len[fe[2]];
        t[0] = kahan_angle(l0, l2, l1);
        t[1] = kahan_angle(l0, l1, l2);
        t[2] = kahan_angle(l1, l2, l0);
        if (t[0] < 0 || t[1] < 0 || t[2] < 0) {
            /* zero-length sides: share what is left of pi equally among the
             * undetermined corners (the limit of a shrinking side) */
            double rest = M_PI;
            int n = 0;
            for (int k = 0; k < 3; k++) {
                if (t[k] < 0) n++;
                else rest -= t[k];
            }
            for (int k = 0; k < 3; k++)
                if (t[k] < 0) t[k] = rest > 0 ? rest / n : 0;
        }
    }
    return ES_OK;
}

static void face_normal(const es_mesh *m, const double *xyz, int64_t f, double *n)
{
    const double *p = xyz + 3 * m->faces[3 * f], *q = xyz + 3 * m->faces[3 * f + 1];
    const double *r = xyz + 3 * m->faces[3 * f + 2];
    double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    double v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    es__v3_cross(u, v, n);
    double s = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (s > 0) { n[0] /= s; n[1] /= s; n[2] /= s; }
}

double es_bbox_diagonal(int64_t nverts, const double *xyz)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (nverts <= 0 || !xyz) return 0.0;
    for (int64_t v = 0; v < nverts; v++)
        for (int i = 0; i < 3; i++) {
            double c = xyz[3 * v + i];
            if (!isfinite(c)) return NAN;
            lo[i] = fmin(lo[i], c);
            hi[i] = fmax(hi[i], c);
        }
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

es_status es_dihedral_angles(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                             double *alpha)
{
    es_status rc = check_args(ctx, "es_dihedral_angles", mesh, xyz, alpha);
    if (rc != ES_OK) return rc;
    double *nrm = es__alloc_array(ctx, mesh->nf > 0 ? 3 * mesh->nf : 1, sizeof *nrm);
    if (!nrm) return ES_ENOMEM;
    for (int64_t f = 0; f < mesh->nf; f++) face_normal(mesh, xyz, f, nrm + 3 * f);
    for (int64_t e = 0; e < mesh->ne; e++) {
        int64_t f = mesh->edge_faces[2 * e], g = mesh->edge_faces[2 * e + 1];
        if (f < 0 || g < 0) {
            alpha[e] = 0;
            continue;
        }
        const double *a = xyz + 3 * mesh->edges[2 * e], *b = xyz + 3 * mesh->edges[2 * e + 1];
        double t[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, c[3];
        double tn = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        const double *nf = nrm + 3 * f, *ng = nrm + 3 * g;
        es__v3_cross(ng, nf, c);
        double y = tn > 0 ? (c[0] * t[0] + c[1] * t[1] + c[2] * t[2]) / tn : 0;
        double x = ng[0] * nf[0] + ng[1] * nf[1] + ng[2] * nf[2];
        alpha[e] = atan2(y, x);
        /* atan2 returns -pi for (y = -0, x < 0); the range is (-pi, pi] */
        if (alpha[e] == -M_PI) alpha[e] = M_PI;
    }
    es__free(ctx, nrm);
    return ES_OK;
}

es_status es_lengths_check(es_ctx *ctx, const es_mesh *mesh, const double *len, double rtol,
                           es_validity *out)
{
    if (!mesh || !len || !out)
        ES_FAIL(ctx, ES_EINVAL, "es_lengths_check: NULL %s",
                !mesh ? "mesh" : !len ? "lengths" : "output");
    if (!(rtol >= 0) || !isfinite(rtol))
        ES_FAIL(ctx, ES_EINVAL, "es_lengths_check: rtol %g is not finite and >= 0", rtol);
    es_validity v = {0, 0, 0, -1, -INFINITY, 0};
    for (int64_t e = 0; e < mesh->ne; e++) {
        if (!isfinite(len[e])) v.n_nonfinite++;
        else if (len[e] <= 0) v.n_nonpositive++;
    }
    for (int64_t f = 0; f < mesh->nf; f++) {
        const int64_t *fe = mesh->face_edges + 3 * f;
        double l[3] = {len[fe[0]], len[fe[1]], len[fe[2]]};
        if (!isfinite(l[0]) || !isfinite(l[1]) || !isfinite(l[2])) continue;
        int i = l[0] >= l[1] ? (l[0] >= l[2] ? 0 : 2) : (l[1] >= l[2] ? 1 : 2);
        double rest = l[(i + 1) % 3] + l[(i + 2) % 3], sum = l[i] + rest;
        if (l[i] > rest + rtol * sum) v.n_bad_faces++;
        double viol = sum > 0 ? (l[i] - rest) / sum : 0;
        if (viol > v.worst_violation) {
            v.worst_violation = viol;
            v.worst_face = f;
        }
    }
    if (v.worst_face < 0) v.worst_violation = 0;
    v.valid = v.n_nonfinite == 0 && v.n_nonpositive == 0 && v.n_bad_faces == 0;
    *out = v;
    return ES_OK;
}
