/* tests/procrustes/test_procrustes.c — OPA, GPA, distances, tangent PCA.
 *
 * Properties checked always: recovery of a known similarity by OPA,
 * invariance of GPA to random rotations, translations, scalings and a
 * relabelled order of specimens, reflection handling, degenerate input, the
 * stationarity conditions of the GPA fixed point (each configuration's
 * rotation onto the mean is the identity; Ten Berge: <X_j, mean>/||X_j||^2
 * is the same for all j) on a set large enough for the power-iteration path.
 * With ../shared present: agreement with R shapes::procGPA
 * (../shared/oracle/gpa, README there) to 1e-8 after one global rotation
 * aligning the means and per-PC signs.
 */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "edgespace/edgespace.h"

#include <math.h>
#include <stdarg.h>

/* ---- helpers ----------------------------------------------------------- */

static void random_rotation(es_rng *rng, int d, double *r)
{
    if (d == 2) {
        double t = 2 * M_PI * es_rng_uniform(rng);
        r[0] = cos(t); r[1] = sin(t); r[2] = -sin(t); r[3] = cos(t);
        return;
    }
    double q[4], nq = 0;
    for (int i = 0; i < 4; i++) { q[i] = es_rng_normal(rng); nq += q[i] * q[i]; }
    nq = sqrt(nq);
    double w = q[0] / nq, x = q[1] / nq, y = q[2] / nq, z = q[3] / nq;
    double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),
                   2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x),
                   2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
    memcpy(r, m, sizeof m);
}

/* y = s * x * R + t (k x d) */
static void similarity(int64_t k, int d, const double *x, const double *r, double s,
                       const double *t, double *y)
{
    for (int q = 0; q < d; q++)
        for (int64_t v = 0; v < k; v++) {
            double acc = 0;
            for (int l = 0; l < d; l++) acc += x[v + l * k] * r[l + q * d];
            y[v + q * k] = s * acc + t[q];
        }
}

static double max_abs_diff(int64_t n, const double *a, const double *b)
{
    double m = 0;
    for (int64_t i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

static double max_abs(int64_t n, const double *a)
{
    double m = 0;
    for (int64_t i = 0; i < n; i++) m = fmax(m, fabs(a[i]));
    return m;
}

/* Rotate every configuration of set (kd x n) by the rotation fitting `from`
 * onto `to` (both k x d, centred): the global normalization. */
static void align_globally(es_ctx *ctx, int64_t k, int d, int64_t n, double *set,
                           const double *from, const double *to)
{
    double r[9];
    ES_CHECK_OK(ctx, es_procrustes_opa(ctx, k, d, to, from, 0, 0, NULL, r, NULL, NULL));
    for (int64_t j = 0; j < n; j++) {
        double *c = set + j * k * d, tmp[3];
        for (int64_t v = 0; v < k; v++) {
            for (int q = 0; q < d; q++) {
                tmp[q] = 0;
                for (int l = 0; l < d; l++) tmp[q] += c[v + l * k] * r[l + q * d];
            }
            for (int q = 0; q < d; q++) c[v + q * k] = tmp[q];
        }
    }
}

/* Random landmark set: a base shape plus noise, random similarity each. */
static double *make_set(es_rng *rng, int64_t k, int d, int64_t n, double noise)
{
    double *base = malloc((size_t)(k * d) * sizeof *base);
    double *x = malloc((size_t)(k * d * n) * sizeof *x);
    for (int64_t i = 0; i < k * d; i++) base[i] = es_rng_normal(rng);
    for (int64_t j = 0; j < n; j++) {
        double r[9], t[3], *c = x + j * k * d, tmp[3 * 64];
        for (int64_t i = 0; i < k * d; i++) tmp[i] = base[i] + noise * es_rng_normal(rng);
        random_rotation(rng, d, r);
        for (int q = 0; q < d; q++) t[q] = 10 * es_rng_normal(rng);
        similarity(k, d, tmp, r, 0.5 + es_rng_uniform(rng), t, c);
    }
    free(base);
    return x;
}

/* ---- OPA and distances ------------------------------------------------- */

static void test_opa(es_ctx *ctx)
{
    es_rng rng;
    es_rng_init(&rng, 11);
    for (int d = 2; d <= 3; d++) {
        int64_t k = 9;
        double x[27], y[27], fit[27], r[9], rr[9], t[3] = {1, -2, 3}, s, oss;
        for (int i = 0; i < k * d; i++) x[i] = es_rng_normal(&rng);
        random_rotation(&rng, d, r);
        similarity(k, d, x, r, 2.5, t, y);
        /* fitting y onto x undoes the similarity: R^T and 1/2.5 */
        ES_CHECK_OK(ctx, es_procrustes_opa(ctx, k, d, x, y, 1, 0, fit, rr, &s, &oss));
        ES_CHECK_CLOSE(s, 1 / 2.5, 1e-12, 0);
        ES_CHECK(oss < 1e-20);
        for (int p = 0; p < d; p++)
            for (int q = 0; q < d; q++) ES_CHECK_CLOSE(rr[p + q * d], r[q + p * d], 0, 1e-12);
        double rho, full, partial;
        ES_CHECK_OK(ctx, es_procrustes_distance(ctx, k, d, x, y, 0, &rho, &full, &partial));
        ES_CHECK(rho < 1e-7);
        /* rigid fit keeps the scale and leaves the size difference as residual */
        ES_CHECK_OK(ctx, es_procrustes_opa(ctx, k, d, x, y, 0, 0, fit, NULL, &s, &oss));
        ES_CHECK(s == 1.0);
        double cx = es_procrustes_centroid_size(k, d, x);
        ES_CHECK_CLOSE(es_procrustes_centroid_size(k, d, fit), 2.5 * cx, 1e-12, 0);
        ES_CHECK_CLOSE(oss, (2.5 - 1) * (2.5 - 1) * cx * cx, 1e-10, 0);
        /* distances of two different shapes: the identities between them */
        for (int i = 0; i < k * d; i++) y[i] = x[i] + 0.3 * es_rng_normal(&rng);
        ES_CHECK_OK(ctx, es_procrustes_distance(ctx, k, d, x, y, 0, &rho, &full, &partial));
        ES_CHECK(rho > 0.01 && rho < M_PI / 2);
        ES_CHECK_CLOSE(full, sin(rho), 1e-14, 0);
        ES_CHECK_CLOSE(partial, 2 * sin(rho / 2), 1e-14, 0);
        /* the full Procrustes distance is the residual of the scaled OPA of
         * unit-size configurations (Dryden & Mardia, eq. 3.5) */
        double xu[27], yu[27];
        memcpy(xu, x, sizeof xu); memcpy(yu, y, sizeof yu);
        double sx, sy;
        es_procrustes_center(ctx, k, d, xu, &sx);
        es_procrustes_center(ctx, k, d, yu, &sy);
        for (int i = 0; i < k * d; i++) { xu[i] /= sx; yu[i] /= sy; }
        ES_CHECK_OK(ctx, es_procrustes_opa(ctx, k, d, xu, yu, 1, 0, NULL, NULL, NULL, &oss));
        ES_CHECK_CLOSE(sqrt(oss), full, 1e-10, 0);
    }
    /* bad input */
    double z[6] = {1, 1, 1, 2, 2, 2}, w[6] = {0, 1, 2, 0, 1, 3};
    ES_CHECK_FAILS(ctx, es_procrustes_opa(ctx, 3, 2, w, z, 1, 0, NULL, NULL, NULL, NULL),
                   ES_EINVAL, "zero centroid size");
    ES_CHECK_FAILS(ctx, es_procrustes_distance(ctx, 3, 4, w, z, 0, NULL, NULL, NULL), ES_EINVAL,
                   "dimension 4");
}

/* A mirrored specimen: zero distance only when reflection is allowed. */
static void test_reflection(es_ctx *ctx)
{
    es_rng rng;
    es_rng_init(&rng, 5);
    for (int d = 2; d <= 3; d++) {
        int64_t k = 8, n = 6, kd = k * d;
        double *x = make_set(&rng, k, d, n, 0.05);
        double mir[24];
        memcpy(mir, x, (size_t)kd * sizeof *mir);
        for (int64_t v = 0; v < k; v++) mir[v] = -mir[v];   /* x -> -x: a reflection */
        double rho;
        ES_CHECK_OK(ctx, es_procrustes_distance(ctx, k, d, x, mir, 1, &rho, NULL, NULL));
        ES_CHECK(rho < 1e-7);
        ES_CHECK_OK(ctx, es_procrustes_distance(ctx, k, d, x, mir, 0, &rho, NULL, NULL));
        ES_CHECK(rho > 0.1);
        double r[9];
        ES_CHECK_OK(ctx, es_procrustes_opa(ctx, k, d, x, mir, 0, 1, NULL, r, NULL, NULL));
        double det = d == 2 ? r[0] * r[3] - r[1] * r[2]
                            : r[0] * (r[4] * r[8] - r[7] * r[5]) - r[3] * (r[1] * r[8] -
                              r[7] * r[2]) + r[6] * (r[1] * r[5] - r[4] * r[2]);
        ES_CHECK_CLOSE(det, -1.0, 0, 1e-12);
        ES_CHECK_OK(ctx, es_procrustes_opa(ctx, k, d, x, mir, 0, 0, NULL, r, NULL, NULL));
        det = d == 2 ? r[0] * r[3] - r[1] * r[2]
                     : r[0] * (r[4] * r[8] - r[7] * r[5]) - r[3] * (r[1] * r[8] - r[7] * r[2]) +
                       r[6] * (r[1] * r[5] - r[4] * r[2]);
        ES_CHECK_CLOSE(det, 1.0, 0, 1e-12);

        /* GPA on the set with specimen 0 replaced by its mirror image */
        double *y = malloc((size_t)(kd * n) * sizeof *y), *y2 = malloc((size_t)(kd * n) * sizeof *y);
        memcpy(y, x, (size_t)(kd * n) * sizeof *y);
        memcpy(y, mir, (size_t)kd * sizeof *y);
        memcpy(y2, y, (size_t)(kd * n) * sizeof *y);
        double rho0[6], rho1[6], rho2[6];
        es_gpa_opts o;
        es_gpa_opts_init(&o);
        o.tol = 1e-12;
        es_gpa_out out = {0};
        out.rho = rho0;
        ES_CHECK_OK(ctx, es_gpa_align(ctx, k, d, (es_mat){x, kd, n, kd}, &o, &out, NULL));
        o.allow_reflection = 1;
        out.rho = rho1;
        ES_CHECK_OK(ctx, es_gpa_align(ctx, k, d, (es_mat){y, kd, n, kd}, &o, &out, NULL));
        o.allow_reflection = 0;
        out.rho = rho2;
        ES_CHECK_OK(ctx, es_gpa_align(ctx, k, d, (es_mat){y2, kd, n, kd}, &o, &out, NULL));
        for (int j = 0; j < n; j++) ES_CHECK_CLOSE(rho1[j], rho0[j], 1e-7, 1e-9);
        ES_CHECK_MSG(rho2[0] > 5 * rho0[0] + 0.05, "mirrored specimen rho %g vs %g", rho2[0],
                     rho0[0]);
        free(x); free(y); free(y2);
    }
}

/* ---- GPA invariance ---------------------------------------------------- */

static void test_invariance(es_ctx *ctx, int d, int scale)
{
    es_rng rng;
    es_rng_init(&rng, 100 + d + 10 * scale);
    int64_t k = 12, n = 15, kd = k * d;
    double *x = make_set(&rng, k, d, n, 0.1);
    double *y = malloc((size_t)(kd * n) * sizeof *y);
    int64_t perm[15];
    double fac[15];
    for (int64_t j = 0; j < n; j++) perm[j] = j;
    for (int64_t j = n - 1; j > 0; j--) {
        int64_t i = (int64_t)es_rng_below(&rng, (uint64_t)j + 1), t = perm[i];
        perm[i] = perm[j]; perm[j] = t;
    }
    /* y_j = similarity of x_perm[j]; scaling only for full GPA */
    for (int64_t j = 0; j < n; j++) {
        double r[9], t[3];
        random_rotation(&rng, d, r);
        for (int q = 0; q < d; q++) t[q] = 100 * es_rng_normal(&rng);
        fac[j] = scale ? 0.2 + 3 * es_rng_uniform(&rng) : 1.0;
        similarity(k, d, x + perm[j] * kd, r, fac[j], t, y + j * kd);
    }
    double *mx = malloc((size_t)kd * sizeof *mx), *my = malloc((size_t)kd * sizeof *my);
    double rx[15], ry[15], sx[15], sy[15];
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.scale = scale;
    o.tol = 1e-13;
    es_gpa_report rep;
    es_gpa_out ox = {mx, sx, rx, NULL, NULL, NULL}, oy = {my, sy, ry, NULL, NULL, NULL};
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, d, (es_mat){x, kd, n, kd}, &o, &ox, &rep));
    ES_CHECK(rep.converged && rep.iterations > 1);
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, d, (es_mat){y, kd, n, kd}, &o, &oy, &rep));
    for (int64_t j = 0; j < n; j++) {
        ES_CHECK_CLOSE(ry[j], rx[perm[j]], 1e-8, 1e-12);
        ES_CHECK_CLOSE(sy[j], fac[j] * sx[perm[j]], 1e-12, 0);
    }
    /* the aligned sets agree after one global rotation (and, for full GPA,
     * one global scale: the kept total sum of squares differs) */
    double gx = 0, gy = 0;
    for (int64_t i = 0; i < kd; i++) { gx += mx[i] * mx[i]; gy += my[i] * my[i]; }
    double g = sqrt(gx / gy);
    for (int64_t i = 0; i < kd * n; i++) y[i] *= g;
    for (int64_t i = 0; i < kd; i++) my[i] *= g;
    align_globally(ctx, k, d, n, y, my, mx);
    double scale_ref = max_abs(kd * n, x), worst = 0;
    for (int64_t j = 0; j < n; j++)
        worst = fmax(worst, max_abs_diff(kd, y + j * kd, x + perm[j] * kd));
    ES_CHECK_MSG(worst <= 1e-8 * scale_ref, "d=%d scale=%d: aligned sets differ by %g", d, scale,
                 worst);
    if (!scale) ES_CHECK_CLOSE(g, 1.0, 1e-12, 0);
    free(x); free(y); free(mx); free(my);
}

/* Stationarity of the fixed point: rotation onto the mean is I, and the
 * Ten Berge condition <X_j, mean>/||X_j||^2 = const. Large enough that the
 * scaling step runs by power iteration rather than the explicit Gram matrix. */
static void test_fixed_point(es_ctx *ctx)
{
    es_rng rng;
    es_rng_init(&rng, 77);
    int64_t k = 4000, n = 120, d = 3, kd = k * d;
    double *base = malloc((size_t)kd * sizeof *base), *x = malloc((size_t)(kd * n) * sizeof *x);
    double *mean = malloc((size_t)kd * sizeof *mean), total_in = 0;
    double *tmp = malloc((size_t)kd * sizeof *tmp);
    for (int64_t i = 0; i < kd; i++) base[i] = es_rng_normal(&rng);
    for (int64_t j = 0; j < n; j++) {
        double r[9], t[3] = {1, 2, 3};
        for (int64_t i = 0; i < kd; i++) tmp[i] = base[i] + 0.05 * es_rng_normal(&rng);
        random_rotation(&rng, 3, r);
        similarity(k, 3, tmp, r, 0.5 + es_rng_uniform(&rng), t, x + j * kd);
        total_in += pow(es_procrustes_centroid_size(k, 3, x + j * kd), 2);
    }
    free(tmp);
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.tol = 1e-11;
    es_gpa_report rep;
    es_gpa_out out = {0};
    out.mean = mean;
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, (int)d, (es_mat){x, kd, n, kd}, &o, &out, &rep));
    ES_CHECK_CLOSE(rep.total_ss, total_in, 1e-12, 0);
    double tot = 0, c0 = 0, cmin = INFINITY, cmax = -INFINITY, asym = 0;
    for (int64_t j = 0; j < n; j++) {
        double *c = x + j * kd, nn = 0, dot = 0, a[9];
        for (int64_t i = 0; i < kd; i++) { nn += c[i] * c[i]; dot += c[i] * mean[i]; }
        tot += nn;
        double ratio = dot / nn;
        cmin = fmin(cmin, ratio); cmax = fmax(cmax, ratio);
        c0 = ratio;
        /* X_j^T mean must be symmetric (rotation onto the mean = I) */
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++) {
                double acc = 0;
                for (int64_t v = 0; v < k; v++) acc += c[v + p * k] * mean[v + q * k];
                a[p + 3 * q] = acc;
            }
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < p; q++)
                asym = fmax(asym, fabs(a[p + 3 * q] - a[q + 3 * p]) / (a[0] + a[4] + a[8]));
    }
    ES_CHECK_CLOSE(tot, total_in, 1e-11, 0);
    ES_CHECK_MSG((cmax - cmin) <= 1e-9 * fabs(c0), "Ten Berge condition spread %g", cmax - cmin);
    ES_CHECK_MSG(asym <= 1e-10, "rotation condition asymmetry %g", asym);
    free(base); free(x); free(mean);
}

static void test_degenerate(es_ctx *ctx)
{
    int64_t k = 5, n = 4, d = 2, kd = k * d;
    double x[40];
    es_rng rng;
    es_rng_init(&rng, 3);
    for (int i = 0; i < kd; i++) x[i] = es_rng_normal(&rng);
    for (int j = 1; j < n; j++) memcpy(x + j * kd, x, (size_t)kd * sizeof *x);
    /* all-identical shapes: converges at once, zero distances and variance */
    double rho[4], sd[2], pc[2], mean[10];
    es_gpa_report rep;
    es_gpa_out out = {0};
    out.rho = rho;
    out.mean = mean;
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, (int)d, (es_mat){x, kd, n, kd}, NULL, &out, &rep));
    ES_CHECK(rep.converged && rep.iterations <= 2);
    ES_CHECK(rep.gss < 1e-20 && rep.rmsrho < 1e-7);
    for (int j = 0; j < n; j++) ES_CHECK(rho[j] < 1e-7);
    double tan[40];
    ES_CHECK_OK(ctx, es_gpa_tangent(ctx, k, (int)d, (es_mat){x, kd, n, kd}, mean,
                                    ES_TANGENT_RESIDUAL, (es_mat){tan, kd, n, kd}));
    ES_CHECK_OK(ctx, es_gpa_pca(ctx, (es_mat){tan, kd, n, kd}, 2, sd, pc, (es_mat){0},
                                (es_mat){0}));
    ES_CHECK(sd[0] < 1e-12);
    /* coincident points: a clear error naming the configuration */
    for (int i = 0; i < kd; i++) x[2 * kd + i] = 7.0;
    ES_CHECK_FAILS(ctx, es_gpa_align(ctx, k, (int)d, (es_mat){x, kd, n, kd}, NULL, NULL, NULL),
                   ES_EINVAL, "configuration 2 has zero centroid size");
    x[2 * kd] = NAN;
    ES_CHECK_FAILS(ctx, es_gpa_align(ctx, k, (int)d, (es_mat){x, kd, n, kd}, NULL, NULL, NULL),
                   ES_EINVAL, "non-finite");
    ES_CHECK_FAILS(ctx, es_gpa_align(ctx, k, (int)d, (es_mat){x, kd, 1, kd}, NULL, NULL, NULL),
                   ES_EINVAL, "at least 2");
    ES_CHECK_FAILS(ctx, es_gpa_align(ctx, k, 3, (es_mat){x, kd, n, kd}, NULL, NULL, NULL),
                   ES_EINVAL, "does not hold");
    /* an iteration limit too small reports non-convergence with its state */
    es_rng_init(&rng, 4);
    double *y = make_set(&rng, 6, 3, 10, 0.3);
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.max_iter = 1;
    o.tol = 1e-15;
    ES_CHECK_FAILS(ctx, es_gpa_align(ctx, 6, 3, (es_mat){y, 18, 10, 18}, &o, NULL, &rep),
                   ES_ENOCONV, "not converged");
    ES_CHECK(rep.iterations == 1 && !rep.converged && rep.rot_change > 0);
    free(y);
}

/* PCA: both paths (SVD, Gram) agree, loadings orthonormal, scores = T^T L. */
static void test_pca(es_ctx *ctx)
{
    es_rng rng;
    es_rng_init(&rng, 9);
    int64_t p = 5000, n = 900;   /* p*n > 4e6: Gram path */
    double *t = malloc((size_t)(p * n) * sizeof *t);
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < p; v++)
            t[v + j * p] = (v % 7 == 0 ? 3.0 : 1.0) * es_rng_normal(&rng) * (v < 40 ? 5 : 0.1) + 2;
    int64_t npc = 4;
    double sd[4], pc[4], sd2[4], pc2[4];
    double *l = malloc((size_t)(p * npc) * sizeof *l), *s = malloc((size_t)(n * npc) * sizeof *s);
    double *l2 = malloc((size_t)(200 * npc) * sizeof *l), *s2 = malloc((size_t)(n * npc) * sizeof *s);
    double *m = calloc((size_t)p, sizeof *m);
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < p; v++) m[v] += t[v + j * p] / (double)n;
    ES_CHECK_OK(ctx, es_gpa_pca(ctx, (es_mat){t, p, n, p}, npc, sd, pc, (es_mat){l, p, npc, p},
                                (es_mat){s, n, npc, n}));
    /* the first 200 rows alone, through the SVD path (200*900 < 4e6): with
     * the variance concentrated in rows < 40 both see the same top PCs up
     * to the (tiny) contribution of the other rows; check each path's own
     * invariants instead of equality. */
    ES_CHECK_OK(ctx, es_gpa_pca(ctx, (es_mat){t, 200, n, p}, npc, sd2, pc2,
                                (es_mat){l2, 200, npc, 200}, (es_mat){s2, n, npc, n}));
    for (int64_t a = 0; a < npc; a++) {
        for (int64_t b = 0; b <= a; b++) {
            double g = 0, g2 = 0;
            for (int64_t v = 0; v < p; v++) g += l[v + a * p] * l[v + b * p];
            for (int64_t v = 0; v < 200; v++) g2 += l2[v + a * 200] * l2[v + b * 200];
            ES_CHECK_CLOSE(g, a == b ? 1.0 : 0.0, 0, 1e-10);
            ES_CHECK_CLOSE(g2, a == b ? 1.0 : 0.0, 0, 1e-10);
        }
        if (a > 0) ES_CHECK(sd[a] <= sd[a - 1] && sd2[a] <= sd2[a - 1]);
        /* score variance = sdev^2 */
        double ss = 0, ss2 = 0;
        for (int64_t j = 0; j < n; j++) { ss += s[j + a * n] * s[j + a * n]; ss2 += s2[j + a * n] * s2[j + a * n]; }
        ES_CHECK_CLOSE(sqrt(ss / (double)(n - 1)), sd[a], 1e-10, 0);
        ES_CHECK_CLOSE(sqrt(ss2 / (double)(n - 1)), sd2[a], 1e-10, 0);
        /* scores are the centred data projected on the loadings */
        for (int64_t j = 0; j < n; j += 97) {
            double acc = 0;
            for (int64_t v = 0; v < p; v++) acc += (t[v + j * p] - m[v]) * l[v + a * p];
            ES_CHECK_CLOSE(acc, s[j + a * n], 1e-9, 1e-9 * sd[0]);
        }
        ES_CHECK(pc[a] > 0 && pc[a] < 100);
    }
    free(t); free(l); free(s); free(l2); free(s2); free(m);
}

/* Partial (orthogonal projection) tangent coordinates after full GPA: they
 * are orthogonal to the mean and their length is the full Procrustes
 * distance sin(rho) (Dryden & Mardia, sec. 4.4). */
static void test_tangent(es_ctx *ctx)
{
    es_rng rng;
    es_rng_init(&rng, 17);
    int64_t k = 10, n = 12, d = 3, kd = k * d;
    double *x = make_set(&rng, k, (int)d, n, 0.15), mean[30], rho[12], *t = malloc(sizeof(double) * 360);
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.tol = 1e-13;
    es_gpa_out out = {0};
    out.mean = mean;
    out.rho = rho;
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, (int)d, (es_mat){x, kd, n, kd}, &o, &out, NULL));
    ES_CHECK_OK(ctx, es_gpa_tangent(ctx, k, (int)d, (es_mat){x, kd, n, kd}, mean,
                                    ES_TANGENT_PARTIAL, (es_mat){t, kd, n, kd}));
    double gm = 0;
    for (int64_t v = 0; v < kd; v++) gm += mean[v] * mean[v];
    gm = sqrt(gm);
    for (int64_t j = 0; j < n; j++) {
        double dot = 0, nn = 0;
        for (int64_t v = 0; v < kd; v++) {
            dot += t[v + j * kd] * mean[v] / gm;
            nn += t[v + j * kd] * t[v + j * kd];
        }
        ES_CHECK_CLOSE(dot, 0.0, 0, 1e-13);
        ES_CHECK_CLOSE(sqrt(nn), sin(rho[j]), 1e-9, 1e-13);
    }
    double zero[30] = {0};
    ES_CHECK_FAILS(ctx, es_gpa_tangent(ctx, k, (int)d, (es_mat){x, kd, n, kd}, zero,
                                       ES_TANGENT_PARTIAL, (es_mat){t, kd, n, kd}),
                   ES_EINVAL, "zero size");
    free(x);
    free(t);
}

/* ---- allocation failures ------------------------------------------------ */


/* Fail the k-th allocation for k = 1, 2, ... until a call succeeds: each
 * failure must be ES_ENOMEM (leaks show under -Db_sanitize=address). */
static void test_alloc_sweep(void)
{
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return;
    failing_alloc fa = {0, 0, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    es_ctx_set_allocator(ctx, &a);
    es_rng rng;
    es_rng_init(&rng, 2);
    double *x0 = make_set(&rng, 6, 3, 5, 0.1), x[90], mean[18], tan[90], sd[3], l[54], sc[15];
    es_status rc = ES_ENOMEM;
    int64_t k;
    for (k = 1; k < 200 && rc == ES_ENOMEM; k++) {
        fa.count = 0;
        fa.fail_at = k;
        memcpy(x, x0, sizeof x);
        es_gpa_out out = {0};
        out.mean = mean;
        rc = es_gpa_align(ctx, 6, 3, (es_mat){x, 18, 5, 18}, NULL, &out, NULL);
        if (rc == ES_OK)
            rc = es_gpa_tangent(ctx, 6, 3, (es_mat){x, 18, 5, 18}, mean, ES_TANGENT_PARTIAL,
                                (es_mat){tan, 18, 5, 18});
        if (rc == ES_OK)
            rc = es_gpa_pca(ctx, (es_mat){tan, 18, 5, 18}, 3, sd, NULL, (es_mat){l, 18, 3, 18},
                            (es_mat){sc, 5, 3, 5});
        if (rc == ES_OK)
            rc = es_procrustes_opa(ctx, 6, 3, x0, x0 + 18, 1, 0, NULL, NULL, NULL, NULL);
        ES_CHECK(rc == ES_OK || rc == ES_ENOMEM);
    }
    ES_CHECK(rc == ES_OK && k > 3);
    free(x0);
    es_ctx_free(ctx);
}

/* ---- oracle: shapes::procGPA ------------------------------------------- */

/* snprintf into a path buffer; vsnprintf keeps -Wformat-truncation quiet
 * and the length is checked instead. */
static void pathf(char *buf, size_t n, const char *fmt, ...) ES__PRINTF(3, 4);
static void pathf(char *buf, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int len = vsnprintf(buf, n, fmt, ap);
    va_end(ap);
    if (len < 0 || (size_t)len >= n) buf[0] = 0;
}

/* Read a numeric CSV with a header; returns rows x cols (row-major) or NULL. */
static double *read_csv(const char *path, int64_t *rows, int64_t *cols)
{
    FILE *f = fopen(path, "r");
    if (!f) return NULL;
    char line[8192];
    int64_t nr = 0, nc = 0, cap = 1024;
    double *v = malloc((size_t)cap * sizeof *v);
    if (!fgets(line, sizeof line, f)) { fclose(f); free(v); return NULL; }
    for (char *c = line; *c; c++) nc += *c == ',';
    nc++;
    while (fgets(line, sizeof line, f)) {
        char *s = line, *e;
        for (int64_t c = 0; c < nc; c++) {
            if ((nr + 1) * nc > cap) { cap *= 2; v = realloc(v, (size_t)cap * sizeof *v); }
            if (*s == '"' || (*s >= 'a' && *s <= 'z')) {   /* a text field: "x", "y" */
                v[nr * nc + c] = NAN;
                while (*s && *s != ',') s++;
            } else {
                v[nr * nc + c] = strtod(s, &e);
                s = e;
            }
            if (*s == ',') s++;
        }
        nr++;
    }
    fclose(f);
    *rows = nr;
    *cols = nc;
    return v;
}

/* Largest relative asymmetry of X_j^T mean over the set: zero at a GPA fixed
 * point (each configuration's optimal rotation onto the mean is I). */
static double stationarity(int64_t k, int d, int64_t n, const double *x)
{
    int64_t kd = k * d;
    double *m = calloc((size_t)kd, sizeof *m), worst = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < kd; v++) m[v] += x[j * kd + v] / (double)n;
    for (int64_t j = 0; j < n; j++) {
        double a[9], tr = 0;
        for (int p = 0; p < d; p++)
            for (int q = 0; q < d; q++) {
                double acc = 0;
                for (int64_t v = 0; v < k; v++) acc += x[j * kd + v + p * k] * m[v + q * k];
                a[p + q * d] = acc;
            }
        for (int p = 0; p < d; p++) tr += a[p + p * d];
        for (int p = 0; p < d; p++)
            for (int q = 0; q < p; q++)
                worst = fmax(worst, fabs(a[p + q * d] - a[q + p * d]) / tr);
    }
    free(m);
    return worst;
}

static void oracle_case(es_ctx *ctx, const char *dir, const char *name, int scale)
{
    char path[4096], tag[128];
    int64_t r, c, r2, c2;
    snprintf(tag, sizeof tag, "%s_%s_tol1e-12", name, scale ? "scale" : "noscale");
    pathf(path, sizeof path, "%s/%s_input.csv", dir, name);
    double *in = read_csv(path, &r, &c);
    ES_CHECK_MSG(in != NULL, "cannot read %s", path);
    if (!in) return;
    int d = (int)c - 2;
    int64_t k = 0, n = 0;
    for (int64_t i = 0; i < r; i++) {
        k = in[i * c + 1] > k ? (int64_t)in[i * c + 1] : k;
        n = in[i * c] > n ? (int64_t)in[i * c] : n;
    }
    int64_t kd = k * d;
    double *x = calloc((size_t)(kd * n), sizeof *x), *orot = calloc((size_t)(kd * n), sizeof *x);
    for (int64_t i = 0; i < r; i++) {
        int64_t j = (int64_t)in[i * c] - 1, v = (int64_t)in[i * c + 1] - 1;
        for (int q = 0; q < d; q++) x[j * kd + v + q * k] = in[i * c + 2 + q];
    }
    pathf(path, sizeof path, "%s/%s_rotated.csv", dir, tag);
    double *rot = read_csv(path, &r2, &c2);
    ES_CHECK(rot && r2 == r);
    for (int64_t i = 0; rot && i < r2; i++) {
        int64_t j = (int64_t)rot[i * c2] - 1, v = (int64_t)rot[i * c2 + 1] - 1;
        for (int q = 0; q < d; q++) orot[j * kd + v + q * k] = rot[i * c2 + 2 + q];
    }
    double *mean = malloc((size_t)kd * sizeof *mean), *omean = malloc((size_t)kd * sizeof *mean);
    pathf(path, sizeof path, "%s/%s_mshape.csv", dir, tag);
    double *ms = read_csv(path, &r2, &c2);
    ES_CHECK(ms && r2 == k);
    for (int64_t v = 0; ms && v < k; v++)
        for (int q = 0; q < d; q++) omean[v + q * k] = ms[v * c2 + 1 + q];

    double *rho = malloc((size_t)n * sizeof *rho), *size = malloc((size_t)n * sizeof *size);
    es_gpa_opts o;
    es_gpa_opts_init(&o);
    o.scale = scale;
    o.tol = 1e-13;
    es_gpa_report rep;
    es_gpa_out out = {0};
    out.mean = mean; out.rho = rho; out.size = size;
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, d, (es_mat){x, kd, n, kd}, &o, &out, &rep));

    /* The README asks for 1e-8. Some tol1e-12 runs of procGPA stopped short
     * of the fixed point (scale=FALSE above all): measure how far, and allow
     * that much where it exceeds 1e-8. Ours must be stationary to 1e-10. */
    double st_ours = stationarity(k, d, n, x), st_oracle = stationarity(k, d, n, orot);
    double tol = fmax(1e-8, 3 * st_oracle);
    ES_CHECK_MSG(st_ours <= 1e-10, "%s: our GPA is not stationary (%g)", tag, st_ours);
    if (tol > 1e-8)
        fprintf(stderr, "note: %s: procGPA output is %.2g from stationarity (ours %.2g): "
                "comparing to %.2g\n", tag, st_oracle, st_ours, tol);

    /* one global rotation aligning our mean with procGPA's */
    align_globally(ctx, k, d, n, x, mean, omean);
    align_globally(ctx, k, d, 1, mean, mean, omean);
    double ref = max_abs(kd * n, orot);
    double dr = max_abs_diff(kd * n, x, orot), dm = max_abs_diff(kd, mean, omean);
    ES_CHECK_MSG(dr <= tol * ref, "%s: rotated differ by %g (scale %g)", tag, dr, ref);
    ES_CHECK_MSG(dm <= tol * ref, "%s: mshape differs by %g", tag, dm);

    /* specimens: rho, size, rotated_size, scores */
    pathf(path, sizeof path, "%s/%s_specimens.csv", dir, tag);
    double *sp = read_csv(path, &r2, &c2);
    ES_CHECK(sp && r2 == n);
    int64_t npc = (c2 - 4) / 2;
    for (int64_t j = 0; sp && j < n; j++) {
        ES_CHECK_CLOSE(rho[j], sp[j * c2 + 1], tol, 1e-10);
        ES_CHECK_CLOSE(size[j], sp[j * c2 + 2], 1e-12, 0);
        ES_CHECK_CLOSE(es_procrustes_centroid_size(k, d, x + j * kd), sp[j * c2 + 3], tol, 0);
    }
    /* PCA of residual tangent coordinates */
    double *tan = malloc((size_t)(kd * n) * sizeof *tan);
    double *sd = malloc((size_t)npc * sizeof *sd), *pc = malloc((size_t)npc * sizeof *pc);
    double *sc = malloc((size_t)(n * npc) * sizeof *sc);
    ES_CHECK_OK(ctx, es_gpa_tangent(ctx, k, d, (es_mat){x, kd, n, kd}, mean, ES_TANGENT_RESIDUAL,
                                    (es_mat){tan, kd, n, kd}));
    ES_CHECK_OK(ctx, es_gpa_pca(ctx, (es_mat){tan, kd, n, kd}, npc, sd, pc, (es_mat){0},
                                (es_mat){sc, n, npc, n}));
    pathf(path, sizeof path, "%s/%s_pca.csv", dir, tag);
    int64_t r3, c3;
    double *pca = read_csv(path, &r3, &c3);
    ES_CHECK(pca && r3 >= npc);
    for (int64_t a = 0; pca && a < npc; a++) {
        ES_CHECK_CLOSE(sd[a], pca[a * c3 + 1], tol, tol * pca[1]);
        ES_CHECK_CLOSE(pc[a], pca[a * c3 + 2], tol, tol);
        /* scores up to the PC's sign; tiny trailing PCs are ill-determined */
        if (pca[a * c3 + 1] < 1e-6 * pca[1]) continue;
        double sgn = 0, worst = 0;
        for (int64_t j = 0; j < n; j++) sgn += sc[j + a * n] * sp[j * c2 + 4 + a];
        sgn = sgn < 0 ? -1 : 1;
        for (int64_t j = 0; j < n; j++)
            worst = fmax(worst, fabs(sgn * sc[j + a * n] - sp[j * c2 + 4 + a]));
        /* scores are in coordinate units: same normalization as rotated */
        ES_CHECK_MSG(worst <= tol * ref, "%s: PC%lld scores differ by %g", tag,
                     (long long)a + 1, worst);
    }
    /* summary: rmsrho, GSS, kept total sum of squares */
    pathf(path, sizeof path, "%s/%s_summary.csv", dir, tag);
    double *su = read_csv(path, &r2, &c2);
    if (su && r2 == 1 && c2 == 11) {
        ES_CHECK_CLOSE(rep.rmsrho, su[6], tol, 0);
        ES_CHECK_CLOSE(rep.gss, su[7], tol, 0);
        ES_CHECK_CLOSE(rep.total_ss, su[9], 1e-12, 0);
    } else {
        ES_CHECK_MSG(0, "cannot read %s", path);
    }
    free(in); free(x); free(orot); free(rot); free(mean); free(omean); free(ms); free(rho);
    free(size); free(sp); free(tan); free(sd); free(pc); free(sc); free(pca); free(su);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_opa(ctx);
    test_reflection(ctx);
    for (int d = 2; d <= 3; d++)
        for (int s = 0; s <= 1; s++) test_invariance(ctx, d, s);
    test_fixed_point(ctx);
    test_degenerate(ctx);
    test_pca(ctx);
    test_tangent(ctx);
    test_alloc_sweep();

    char buf[4096];
    const char *data = es_test_shared_data(), *dir = NULL;
    struct stat stt;
    if (data) {
        pathf(buf, sizeof buf, "%s/../oracle/gpa", data);
        if (stat(buf, &stt) == 0) dir = buf;
    }
    if (!dir) {
        fprintf(stderr, "note: ../shared/oracle/gpa absent, oracle comparisons skipped\n");
    } else {
        static const char *names[] = {"gorf", "gorm", "macf", "macm", "macaques", "protein"};
        for (int i = 0; i < 6; i++)
            for (int s = 0; s <= 1; s++) oracle_case(ctx, dir, names[i], s);
    }
    es_ctx_free(ctx);
    ES_TEST_END();
}
