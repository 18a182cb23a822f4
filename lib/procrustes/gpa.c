/* lib/procrustes/gpa.c — generalized Procrustes analysis, tangent coordinates, PCA.
 *
 * GPA as shapes::procGPA computes it (Dryden & Mardia 2016, sec. 7.3;
 * Gower 1975; Ten Berge 1977): centre every configuration, then repeat a
 * rotation sweep in which each configuration in turn is rotated onto the
 * mean of the others (Gauss-Seidel: the running sum is updated after each
 * rotation), and, for full GPA, a Ten Berge scaling step
 *     beta_i = sqrt(S / ||X_i||^2) * phi_i,
 * phi the leading eigenvector (taken positive) of the n x n matrix of
 * cosines <X_i, X_j> / (||X_i|| ||X_j||), S the total sum of squares of the
 * centred inputs, which the scaled set keeps. The fixed point is the one
 * procGPA converges to; its global orientation follows the inputs.
 *
 * Scaling to meshes (600 x 58,000 vertices): x is aligned in place, one
 * configuration at a time, with a k*d running sum that stays in cache; a
 * sweep reads each configuration twice and writes it once. Norms are
 * tracked, not recomputed (rotations keep them). phi comes from the n x n
 * Gram matrix when that is cheap, otherwise from power iteration warm-
 * started at the current scales (two passes per step; the cosine matrix of
 * a set of similar shapes has lambda_1 ~ n and lambda_2 << n, so a few steps
 * suffice).
 *
 * PCA of tangent coordinates: thin SVD of the centred data when small, else
 * the n x n Gram matrix (meshes: n << k*d) with loadings T V / sigma.
 */
#include "procrustes/procrustes_pkg.h"
#include "edgespace/es_procrustes.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>

/* Gram matrices up to this many multiply-adds are formed explicitly. */
#define GRAM_LIMIT 2e8

void es_gpa_opts_init(es_gpa_opts *opts)
{
    opts->scale = 1;
    opts->allow_reflection = 0;
    opts->tol = 1e-10;
    opts->max_iter = 1000;
}

typedef struct gpa_state {
    es_ctx *ctx;
    int64_t k, n, kd;
    int d;
    es_mat x;
    double *sum;     /* kd: sum of the (scaled) configurations */
    double *norm2;   /* n: ||b_i X_i||^2, the norms including pending scales */
    double *pend;    /* n: pending scale b_i not yet multiplied into column i */
    double *phi;     /* n: Ten Berge eigenvector */
    double *work;    /* max(n*n, kd) */
    double *z;       /* n */
    int64_t power_steps;
} gpa_state;

#define COL(st, j) ((st)->x.data + (int64_t)(j) * (st)->x.ld)

/* A = X^T (S - X) for one k x d configuration in a single pass (9 or 4
 * accumulators): the cross product with the mean of the others up to the
 * factor 1/(n-1), which the rotation ignores. (Two BLAS dgemm calls with
 * a 3 x 3 result were three times slower here: OpenBLAS is not tuned for
 * that shape.) */
static void cross_with_others(int64_t k, int d, const double *x, const double *s, double b,
                              double *a)
{
    if (d == 2) {
        double a00 = 0, a01 = 0, a10 = 0, a11 = 0;
        for (int64_t v = 0; v < k; v++) {
            double x0 = b * x[v], x1 = b * x[v + k];
            double o0 = s[v] - x0, o1 = s[v + k] - x1;
            a00 += x0 * o0; a01 += x0 * o1; a10 += x1 * o0; a11 += x1 * o1;
        }
        a[0] = a00; a[1] = a10; a[2] = a01; a[3] = a11;
        return;
    }
    double a00 = 0, a01 = 0, a02 = 0, a10 = 0, a11 = 0, a12 = 0, a20 = 0, a21 = 0, a22 = 0;
    for (int64_t v = 0; v < k; v++) {
        double x0 = b * x[v], x1 = b * x[v + k], x2 = b * x[v + 2 * k];
        double o0 = s[v] - x0, o1 = s[v + k] - x1, o2 = s[v + 2 * k] - x2;
        a00 += x0 * o0; a01 += x0 * o1; a02 += x0 * o2;
        a10 += x1 * o0; a11 += x1 * o1; a12 += x1 * o2;
        a20 += x2 * o0; a21 += x2 * o1; a22 += x2 * o2;
    }
    a[0] = a00; a[1] = a10; a[2] = a20;
    a[3] = a01; a[4] = a11; a[5] = a21;
    a[6] = a02; a[7] = a12; a[8] = a22;
}

/* One Gauss-Seidel rotation sweep; returns the largest ||R - I||_F. A
 * pending scale b_i is applied in the same pass, so the Ten Berge step
 * costs no pass of its own. */
static es_status rotation_sweep(gpa_state *st, int allow_reflection, double *rot_acc,
                                double *change)
{
    int64_t k = st->k;
    int d = st->d;
    double *s = st->sum, maxc = 0;
    for (int64_t i = 0; i < st->n; i++) {
        double *xi = COL(st, i), a[9], r[9], b = st->pend[i];
        es_status rc;
        cross_with_others(k, d, xi, s, b, a);
        if ((rc = es__procrustes_rotation(st->ctx, d, a, allow_reflection, r, NULL)) != ES_OK)
            return rc;
        double c = 0;
        for (int p = 0; p < d; p++)
            for (int q = 0; q < d; q++) {
                double e = r[p + q * d] - (p == q);
                c += e * e;
            }
        c = sqrt(c);
        if (c > maxc) maxc = c;
        /* X_i <- b X_i R and S += X_i(new) - b X_i(old), one pass */
        if (d == 2) {
            for (int64_t v = 0; v < k; v++) {
                double x0 = b * xi[v], x1 = b * xi[v + k];
                double y0 = x0 * r[0] + x1 * r[1], y1 = x0 * r[2] + x1 * r[3];
                s[v] += y0 - x0;
                s[v + k] += y1 - x1;
                xi[v] = y0;
                xi[v + k] = y1;
            }
        } else {
            for (int64_t v = 0; v < k; v++) {
                double x0 = b * xi[v], x1 = b * xi[v + k], x2 = b * xi[v + 2 * k];
                double y0 = x0 * r[0] + x1 * r[1] + x2 * r[2];
                double y1 = x0 * r[3] + x1 * r[4] + x2 * r[5];
                double y2 = x0 * r[6] + x1 * r[7] + x2 * r[8];
                s[v] += y0 - x0;
                s[v + k] += y1 - x1;
                s[v + 2 * k] += y2 - x2;
                xi[v] = y0;
                xi[v + k] = y1;
                xi[v + 2 * k] = y2;
            }
        }
        st->pend[i] = 1.0;
        /* cumulative rotation: aligned = x_centred * R_1 R_2 ... */
        double *ra = rot_acc + i * d * d, t[9];
        for (int p = 0; p < d; p++)
            for (int q = 0; q < d; q++) {
                double acc = 0;
                for (int l = 0; l < d; l++) acc += ra[p + l * d] * r[l + q * d];
                t[p + q * d] = acc;
            }
        memcpy(ra, t, (size_t)(d * d) * sizeof *t);
    }
    *change = maxc;
    return ES_OK;
}

/* Multiply pending scales into the data and recompute the sum exactly. */
static void flush_scales(gpa_state *st)
{
    memset(st->sum, 0, (size_t)st->kd * sizeof *st->sum);
    for (int64_t j = 0; j < st->n; j++) {
        double *xj = COL(st, j), b = st->pend[j];
        for (int64_t v = 0; v < st->kd; v++) {
            xj[v] *= b;
            st->sum[v] += xj[v];
        }
        st->pend[j] = 1.0;
    }
}

/* Leading eigenvector of the cosine matrix from the explicit Gram matrix. */
static es_status tenberge_exact(gpa_state *st)
{
    int64_t n = st->n;
    int ni, kdi, ldi, m;
    es_status rc;
    if ((rc = es__lapack_int(st->ctx, n, &ni)) != ES_OK ||
        (rc = es__lapack_int(st->ctx, st->kd, &kdi)) != ES_OK ||
        (rc = es__lapack_int(st->ctx, st->x.ld, &ldi)) != ES_OK)
        return rc;
    double *g = st->work, w[1];
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, ni, kdi, 1.0, st->x.data, ldi, 0.0, g,
                ni);
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i <= j; i++)
            g[i + j * n] /= sqrt(st->norm2[i] * st->norm2[j]);
    int *isuppz = es__alloc_array(st->ctx, 2, sizeof *isuppz);
    if (!isuppz) return ES_ENOMEM;
    lapack_int info = LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', 'I', 'U', ni, g, ni, 0, 0, ni, ni,
                                     0.0, &m, w, st->phi, ni, isuppz);
    es__free(st->ctx, isuppz);
    if (info != 0 || m != 1)
        ES_FAIL(st->ctx, ES_ENUMERIC, "gpa: eigen-decomposition for Ten Berge scaling failed "
                "(info %d)", (int)info);
    for (int64_t j = 0; j < n; j++) st->phi[j] = fabs(st->phi[j]);
    return ES_OK;
}

/* The same eigenvector by power iteration, warm-started at
 * phi_j = ||X_j|| / sqrt(total): the previous scaling made that the
 * eigenvector of the previous iterate, and for it y = sum_j phi_j X_j /
 * ||X_j|| is just S / sqrt(total), which the sweep has kept up to date, so
 * the first step costs one pass and later ones two. Stops when phi moves by
 * less than 0.1 tol / sqrt(n) (enough for scale changes below tol/10) or
 * 1e-15. On return work holds y for the returned phi, so the scaled sum is
 * sqrt(total) * y. */
static es_status tenberge_power(gpa_state *st, double total, double tol)
{
    int64_t n = st->n, kd = st->kd;
    double *y = st->work, *z = st->z, *phi = st->phi;
    double stop = fmax(1e-15, 0.1 * tol / sqrt((double)n));
    for (int64_t j = 0; j < n; j++) phi[j] = sqrt(st->norm2[j] / total);
    for (int64_t v = 0; v < kd; v++) y[v] = st->sum[v] / sqrt(total);
    for (int it = 0; it < 500; it++) {
        if (it > 0) {
            memset(y, 0, (size_t)kd * sizeof *y);
            for (int64_t j = 0; j < n; j++)
                cblas_daxpy((int)kd, phi[j] / sqrt(st->norm2[j]), COL(st, j), 1, y, 1);
        }
        st->power_steps++;
        double nz = 0, diff = 0;
        for (int64_t j = 0; j < n; j++) {
            z[j] = cblas_ddot((int)kd, COL(st, j), 1, y, 1) / sqrt(st->norm2[j]);
            nz += z[j] * z[j];
        }
        nz = sqrt(nz);
        if (!(nz > 0) || !isfinite(nz))
            ES_FAIL(st->ctx, ES_ENUMERIC, "gpa: Ten Berge power iteration broke down");
        for (int64_t j = 0; j < n; j++) diff = fmax(diff, fabs(fabs(z[j] / nz) - phi[j]));
        /* phi (the vector y was built from) is kept, not the update: y and
         * phi stay consistent; the update differs by less than diff */
        if (diff <= stop) return ES_OK;
        for (int64_t j = 0; j < n; j++) phi[j] = fabs(z[j] / nz);
    }
    ES_FAIL(st->ctx, ES_ENOCONV, "gpa: Ten Berge power iteration did not converge in 500 steps "
            "(the configurations are too dissimilar for the large-data path)");
}

/* Ten Berge scaling step: pending scales beta_i, keeping the total sum of
 * squares; the sum of the scaled set is set up for the next sweep. */
static es_status scaling_step(gpa_state *st, double total, double tol, double *scale_acc,
                              double *change, int exact)
{
    int64_t n = st->n, kd = st->kd;
    es_status rc;
    if (exact) {
        if ((rc = tenberge_exact(st)) != ES_OK) return rc;
    } else {
        if (kd > INT32_MAX) ES_FAIL(st->ctx, ES_ERANGE, "gpa: %lld coordinates per configuration "
                                    "exceed BLAS's int", (long long)kd);
        if ((rc = tenberge_power(st, total, tol)) != ES_OK) return rc;
    }
    double maxc = 0;
    for (int64_t j = 0; j < n; j++) {
        double b = sqrt(total / st->norm2[j]) * st->phi[j];
        if (!(b > 0) || !isfinite(b))
            ES_FAIL(st->ctx, ES_ENUMERIC, "gpa: Ten Berge scale of configuration %lld is %g "
                    "(it is orthogonal to all others)", (long long)j, b);
        st->pend[j] = b;
        st->norm2[j] *= b * b;
        scale_acc[j] *= b;
        maxc = fmax(maxc, fabs(b - 1.0));
    }
    if (exact) {
        flush_scales(st);
    } else {
        for (int64_t v = 0; v < kd; v++) st->sum[v] = sqrt(total) * st->work[v];
    }
    *change = maxc;
    return ES_OK;
}

es_status es_gpa_align(es_ctx *ctx, int64_t k, int d, es_mat x, const es_gpa_opts *opts,
                       es_gpa_out *out, es_gpa_report *report)
{
    es_gpa_opts o;
    es_gpa_report rep;
    gpa_state st;
    es_status rc = ES_OK;
    int64_t kd, n = x.cols, nn;
    double *rot_acc = NULL, *scale_acc = NULL, *buf = NULL;

    if (opts) o = *opts; else es_gpa_opts_init(&o);
    memset(&rep, 0, sizeof rep);
    if (report) *report = rep;
    if (d != 2 && d != 3) ES_FAIL(ctx, ES_EINVAL, "gpa: dimension %d is not 2 or 3", d);
    if (k < 1 || !es__mul_i64(k, d, &kd) || x.rows != kd || x.ld < kd)
        ES_FAIL(ctx, ES_EINVAL, "gpa: a %lld x %lld matrix (ld %lld) does not hold %lld x %d "
                "configurations", (long long)x.rows, (long long)x.cols, (long long)x.ld,
                (long long)k, d);
    if (n < 2) ES_FAIL(ctx, ES_EINVAL, "gpa: needs at least 2 configurations, got %lld",
                       (long long)n);
    if (!(o.tol >= 0) || o.max_iter < 1)
        ES_FAIL(ctx, ES_EINVAL, "gpa: tolerance %g / max_iter %lld invalid", o.tol,
                (long long)o.max_iter);
    if (!es__mul_i64(n, n, &nn)) ES_FAIL(ctx, ES_ERANGE, "gpa: %lld configurations", (long long)n);
    if (kd > INT32_MAX) ES_FAIL(ctx, ES_ERANGE, "gpa: %lld coordinates per configuration exceed "
                                "BLAS's int", (long long)kd);

    memset(&st, 0, sizeof st);
    st.ctx = ctx; st.k = k; st.d = d; st.n = n; st.kd = kd; st.x = x;
    /* one block: sum kd, work max(kd, n*n) (n*n only for the explicit Gram
     * matrix), norm2, pend, phi, z, scale n each, rot d*d*n */
    int exact = o.scale && (double)n * (double)n * (double)kd <= GRAM_LIMIT;
    int64_t nwork = exact && nn > kd ? nn : kd, total_len = kd + nwork + 5 * n + (int64_t)d * d * n;
    buf = es__alloc_array(ctx, total_len, sizeof *buf);
    if (!buf) return ES_ENOMEM;
    st.sum = buf;
    st.work = st.sum + kd;
    st.norm2 = st.work + nwork;
    st.pend = st.norm2 + n;
    st.phi = st.pend + n;
    st.z = st.phi + n;
    scale_acc = st.z + n;
    rot_acc = scale_acc + n;

    /* centre, record centroids and sizes, check for degenerate input */
    double total = 0;
    memset(st.sum, 0, (size_t)kd * sizeof *st.sum);
    for (int64_t j = 0; j < n; j++) {
        double *xj = COL(&st, j), c[3], ss = 0;
        for (int q = 0; q < d; q++) {
            double acc = 0;
            for (int64_t v = 0; v < k; v++) acc += xj[v + q * k];
            c[q] = acc / (double)k;
            for (int64_t v = 0; v < k; v++) {
                xj[v + q * k] -= c[q];
                ss += xj[v + q * k] * xj[v + q * k];
                st.sum[v + q * k] += xj[v + q * k];
            }
        }
        if (!isfinite(ss)) {
            rc = es__fail(ctx, ES_EINVAL, "gpa: configuration %lld has a non-finite coordinate",
                          (long long)j);
            goto done;
        }
        if (!(ss > 0)) {
            rc = es__fail(ctx, ES_EINVAL, "gpa: configuration %lld has zero centroid size (all "
                          "%lld points coincide)", (long long)j, (long long)k);
            goto done;
        }
        if (out && out->centroid) memcpy(out->centroid + j * d, c, (size_t)d * sizeof *c);
        if (out && out->size) out->size[j] = sqrt(ss);
        st.norm2[j] = ss;
        total += ss;
        scale_acc[j] = 1.0;
        st.pend[j] = 1.0;
        for (int q = 0; q < d * d; q++) rot_acc[j * d * d + q] = q % (d + 1) == 0;
    }
    rep.total_ss = total;

    for (rep.iterations = 1; rep.iterations <= o.max_iter; rep.iterations++) {
        if ((rc = rotation_sweep(&st, o.allow_reflection, rot_acc, &rep.rot_change)) != ES_OK)
            goto done;
        if (o.scale &&
            (rc = scaling_step(&st, total, o.tol, scale_acc, &rep.scale_change, exact)) != ES_OK)
            goto done;
        if ((rc = es__progress(ctx, "gpa", rep.iterations, o.max_iter))) goto done;
        if (rep.rot_change <= o.tol && rep.scale_change <= o.tol) {
            rep.converged = 1;
            break;
        }
    }
    if (rep.iterations > o.max_iter) rep.iterations = o.max_iter;
    es__progress(ctx, "gpa", o.max_iter, o.max_iter);
    flush_scales(&st);   /* also recomputes the sum without accumulated rounding */

    /* mean, GSS and rho */
    double *mean = st.work, msz = 0, gss = 0, sr = 0;
    for (int64_t v = 0; v < kd; v++) {
        mean[v] = st.sum[v] / (double)n;
        msz += mean[v] * mean[v];
    }
    msz = sqrt(msz);
    for (int64_t j = 0; j < n; j++) {
        const double *xj = COL(&st, j);
        double a[9], r = 0, nx = 0;
        for (int64_t v = 0; v < kd; v++) {
            gss += (xj[v] - mean[v]) * (xj[v] - mean[v]);
            nx += xj[v] * xj[v];
        }
        if (msz > 0) {
            es__procrustes_cross(k, d, xj, mean, a);
            if ((rc = es__procrustes_rho(ctx, d, a, sqrt(nx), msz, o.allow_reflection, &r)) !=
                ES_OK)
                goto done;
        } else {
            r = M_PI / 2;
        }
        sr += r * r;
        if (out && out->rho) out->rho[j] = r;
    }
    rep.gss = gss;
    rep.rmsrho = sqrt(sr / (double)n);
    if (out && out->mean) memcpy(out->mean, mean, (size_t)kd * sizeof *mean);
    if (out && out->scale) memcpy(out->scale, scale_acc, (size_t)n * sizeof *scale_acc);
    if (out && out->rot) memcpy(out->rot, rot_acc, (size_t)(d * d * n) * sizeof *rot_acc);
    if (!rep.converged)
        rc = es__fail(ctx, ES_ENOCONV, "gpa: not converged after %lld iterations (rotation change "
                      "%.3g, scale change %.3g, tolerance %.3g)", (long long)o.max_iter,
                      rep.rot_change, rep.scale_change, o.tol);
done:
    if (report) *report = rep;
    es__free(ctx, buf);
    return rc;
}

es_status es_gpa_tangent(es_ctx *ctx, int64_t k, int d, es_mat aligned, const double *mean,
                         es_tangent type, es_mat tan)
{
    int64_t kd = k * d, n = aligned.cols;
    if (aligned.rows != kd || tan.rows != kd || tan.cols != n || aligned.ld < kd || tan.ld < kd)
        ES_FAIL(ctx, ES_EINVAL, "gpa tangent: matrices are not %lld x %lld", (long long)kd,
                (long long)n);
    if (type == ES_TANGENT_RESIDUAL) {
        for (int64_t j = 0; j < n; j++)
            for (int64_t v = 0; v < kd; v++)
                ES_AT(tan, v, j) = ES_AT(aligned, v, j) - mean[v];
        return ES_OK;
    }
    if (type != ES_TANGENT_PARTIAL) ES_FAIL(ctx, ES_EINVAL, "gpa tangent: unknown type %d", type);
    double gm = 0;
    for (int64_t v = 0; v < kd; v++) gm += mean[v] * mean[v];
    gm = sqrt(gm);
    if (!(gm > 0)) ES_FAIL(ctx, ES_EINVAL, "gpa tangent: the mean has zero size");
    for (int64_t j = 0; j < n; j++) {
        double nz = 0, dot = 0;
        for (int64_t v = 0; v < kd; v++) {
            double a = ES_AT(aligned, v, j);
            nz += a * a;
            dot += a * mean[v];
        }
        nz = sqrt(nz);
        if (!(nz > 0))
            ES_FAIL(ctx, ES_EINVAL, "gpa tangent: configuration %lld has zero size", (long long)j);
        dot /= nz * gm;
        /* (I - gamma gamma^T) z, gamma = mean/|mean|, z = x/|x| */
        for (int64_t v = 0; v < kd; v++)
            ES_AT(tan, v, j) = ES_AT(aligned, v, j) / nz - dot * mean[v] / gm;
    }
    return ES_OK;
}

/* Sign of the largest-magnitude entry of l (p), the PC sign convention. */
static double max_sign(int64_t p, const double *l)
{
    double best = 0;
    for (int64_t v = 0; v < p; v++)
        if (fabs(l[v]) > fabs(best)) best = l[v];
    return best < 0 ? -1.0 : 1.0;
}

es_status es_gpa_pca(es_ctx *ctx, es_mat tan, int64_t npc, double *sdev, double *percent,
                     es_mat loadings, es_mat scores)
{
    int64_t p = tan.rows, n = tan.cols, r = p < n ? p : n;
    es_status rc = ES_OK;
    int pi, ni, ldt, ri;
    if (n < 2 || p < 1) ES_FAIL(ctx, ES_EINVAL, "gpa pca: needs at least 2 specimens");
    if (npc < 1 || npc > r)
        ES_FAIL(ctx, ES_EINVAL, "gpa pca: %lld components requested, at most %lld",
                (long long)npc, (long long)r);
    if (loadings.data && (loadings.rows != p || loadings.cols != npc || loadings.ld < p))
        ES_FAIL(ctx, ES_EINVAL, "gpa pca: loadings must be %lld x %lld", (long long)p,
                (long long)npc);
    if (scores.data && (scores.rows != n || scores.cols != npc || scores.ld < n))
        ES_FAIL(ctx, ES_EINVAL, "gpa pca: scores must be %lld x %lld", (long long)n,
                (long long)npc);
    if ((rc = es__lapack_int(ctx, p, &pi)) != ES_OK || (rc = es__lapack_int(ctx, n, &ni)) != ES_OK ||
        (rc = es__lapack_int(ctx, tan.ld, &ldt)) != ES_OK || (rc = es__lapack_int(ctx, r, &ri)) != ES_OK)
        return rc;

    /* row means (the mean specimen) and one loading column of scratch */
    double *m = es__alloc_array(ctx, 2 * p, sizeof *m), *work = NULL, total = 0;
    if (!m) return ES_ENOMEM;
    double *lc = m + p;
    for (int64_t v = 0; v < p; v++) {
        double acc = 0;
        for (int64_t j = 0; j < n; j++) acc += ES_AT(tan, v, j);
        m[v] = acc / (double)n;
    }
    if ((double)p * (double)n <= 4e6) {
        /* thin SVD of the centred copy: T_c = U S V^T, loadings U, scores V S */
        work = es__alloc_array(ctx, p * n + r + r * n + p * r, sizeof *work);
        if (!work) { rc = ES_ENOMEM; goto done; }
        double *a = work, *s = a + p * n, *vt = s + r, *u = vt + r * n;
        for (int64_t j = 0; j < n; j++)
            for (int64_t v = 0; v < p; v++) {
                a[v + j * p] = ES_AT(tan, v, j) - m[v];
                total += a[v + j * p] * a[v + j * p];
            }
        lapack_int info = LAPACKE_dgesdd(LAPACK_COL_MAJOR, 'S', pi, ni, a, pi, s, u, pi, vt, ri);
        if (info != 0) {
            rc = es__fail(ctx, ES_ENUMERIC, "gpa pca: SVD failed (info %d)", (int)info);
            goto done;
        }
        for (int64_t c = 0; c < npc; c++) {
            double sg = max_sign(p, u + c * p);
            if (sdev) sdev[c] = s[c] / sqrt((double)(n - 1));
            if (percent) percent[c] = total > 0 ? 100.0 * s[c] * s[c] / total : 0.0;
            if (loadings.data)
                for (int64_t v = 0; v < p; v++) ES_AT(loadings, v, c) = sg * u[v + c * p];
            if (scores.data)
                for (int64_t j = 0; j < n; j++) ES_AT(scores, j, c) = sg * vt[c + j * r] * s[c];
        }
        goto done;
    }
    /* Gram matrix of the centred data, H T^T T H (n x n): no copy of T */
    work = es__alloc_array(ctx, n * n + 2 * n, sizeof *work);
    if (!work) { rc = ES_ENOMEM; goto done; }
    double *g = work, *w = g + n * n, *rm = w + n, gm = 0;
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, ni, pi, 1.0, tan.data, ldt, 0.0, g, ni);
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < j; i++) g[j + i * n] = g[i + j * n];
    for (int64_t i = 0; i < n; i++) {
        double acc = 0;
        for (int64_t j = 0; j < n; j++) acc += g[i + j * n];
        rm[i] = acc / (double)n;
        gm += rm[i];
    }
    gm /= (double)n;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) g[i + j * n] += gm - rm[i] - rm[j];
    for (int64_t i = 0; i < n; i++) total += g[i + i * n];
    lapack_int info = LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'U', ni, g, ni, w);
    if (info != 0) {
        rc = es__fail(ctx, ES_ENUMERIC, "gpa pca: eigen-decomposition failed (info %d)", (int)info);
        goto done;
    }
    /* eigenvalues ascending: component c is column n-1-c; loadings T_c V / s */
    double lmax = fmax(w[n - 1], 0.0);
    for (int64_t c = 0; c < npc; c++) {
        double l = fmax(w[n - 1 - c], 0.0), s = sqrt(l), csum = 0;
        const double *vc = g + (n - 1 - c) * n;
        int null = !(l > 1e-13 * lmax * (double)n);
        double *lo = loadings.data ? &ES_AT(loadings, 0, c) : lc;
        if (null) {
            memset(lo, 0, (size_t)p * sizeof *lo);
        } else {
            for (int64_t j = 0; j < n; j++) csum += vc[j];
            cblas_dgemv(CblasColMajor, CblasNoTrans, pi, ni, 1.0 / s, tan.data, ldt, vc, 1, 0.0,
                        lo, 1);
            for (int64_t v = 0; v < p; v++) lo[v] -= m[v] * csum / s;
        }
        double sg = max_sign(p, lo);
        if (sg < 0)
            for (int64_t v = 0; v < p; v++) lo[v] = -lo[v];
        if (sdev) sdev[c] = null ? 0.0 : s / sqrt((double)(n - 1));
        if (percent) percent[c] = total > 0 && !null ? 100.0 * l / total : 0.0;
        if (scores.data)
            for (int64_t j = 0; j < n; j++) ES_AT(scores, j, c) = null ? 0.0 : sg * vc[j] * s;
    }
done:
    es__free(ctx, work);
    es__free(ctx, m);
    return rc;
}
