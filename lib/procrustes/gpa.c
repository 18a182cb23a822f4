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
 * On the ranks of an MPI job (es_gpa_align_ranks) each rank holds a
 * contiguous share of the configurations. The sweep is Gauss-Seidel, so
 * configuration i+1 is rotated onto a sum that already holds i's rotation:
 * the work is sequential, and splitting it Jacobi-style would change the
 * iterates and the result. Every pass that carries a running value from one
 * configuration to the next (the sum, a sum of squares, the largest change)
 * is a chain (below): the ranks take their shares in turn, each handing the
 * running values on to all, so every rank adds the same numbers in the same
 * order as one process and holds the very same bits; the result is the
 * one-process result, bit for bit up to BLAS's own threading. What the
 * ranks gain is memory (n/P configurations each) and reading; the per-
 * configuration dots of the power iteration run side by side.
 *
 * PCA of tangent coordinates: thin SVD of the centred data when small, else
 * the n x n Gram matrix (meshes: n << k*d) with loadings T V / sigma.
 */
#include "procrustes/procrustes_pkg.h"
#include "parallel/parallel_private.h"
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
    int ranks, rank;   /* 1 and 0: every configuration is here */
    int64_t lo, hi;    /* this rank's configurations [lo, hi) of 0 .. n-1 */
    es_mat x;          /* configurations lo .. hi-1 */
    double *sum;     /* kd + 1: sum of the (scaled) configurations, then a running max */
    double *norm2;   /* n: ||b_i X_i||^2, the norms including pending scales */
    double *pend;    /* n: pending scale b_i not yet multiplied into column i */
    double *phi;     /* n: Ten Berge eigenvector */
    double *work;    /* max(n*n, kd) */
    double *z;       /* n */
    double *all;     /* rank 0 of several, exact scaling: every configuration (kd x n) */
    int64_t power_steps;
} gpa_state;

#define COL(st, j) ((st)->x.data + ((int64_t)(j) - (st)->lo) * (st)->x.ld)

/* One step of a chain: configuration j (this rank's) with the running values acc. */
typedef es_status (*gpa_step)(gpa_state *st, int64_t j, double *acc, void *ud);

/* step for j = 0 .. n-1 in order, carrying acc[0 .. m) from one to the
 * next: alone a plain loop; on the ranks each rank runs its share in turn
 * and broadcasts acc, so that the next rank continues from the very bits
 * the previous one left (P broadcasts of m doubles). A failure is agreed
 * on by all ranks after the pass: the lowest failing rank's first failure,
 * which is the failure one process meets first. */
static es_status chain(gpa_state *st, double *acc, int64_t m, gpa_step step, void *ud)
{
    es_status rc = ES_OK, brc;
    for (int q = 0; q < st->ranks; q++) {
        if (q == st->rank)
            for (int64_t j = st->lo; j < st->hi && rc == ES_OK; j++) rc = step(st, j, acc, ud);
        if (st->ranks > 1 && (brc = es__par_bcast(st->ctx, acc, (size_t)m * sizeof *acc, q)))
            return brc;
    }
    return st->ranks > 1 ? es__par_agree(st->ctx, rc) : rc;
}

/* v holds per values for each of the n configurations, this rank's
 * entries filled: afterwards every rank holds all of them. */
static es_status gather_shares(gpa_state *st, double *v, int64_t per)
{
    int64_t *counts, lo, hi;
    double *mine;
    es_status rc;
    if (st->ranks < 2) return ES_OK;
    counts = es__alloc_array(st->ctx, st->ranks, sizeof *counts);
    mine = es__alloc_array(st->ctx, (st->hi - st->lo) * per + 1, sizeof *mine);
    rc = counts && mine ? ES_OK : ES_ENOMEM;
    if ((rc = es__par_agree(st->ctx, rc)) == ES_OK) {
        for (int q = 0; q < st->ranks; q++) {
            es__par_split(st->n, st->ranks, q, &lo, &hi);
            counts[q] = (hi - lo) * per;
        }
        memcpy(mine, v + st->lo * per, (size_t)((st->hi - st->lo) * per) * sizeof *mine);
        rc = es__par_allgather(st->ctx, mine, counts, v);
    }
    es__free(st->ctx, counts);
    es__free(st->ctx, mine);
    return rc;
}

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

typedef struct sweep_args { int allow_reflection; double *rot_acc; } sweep_args;

/* Configuration i of a Gauss-Seidel rotation sweep: rotated onto the sum
 * of the others, the sum s = acc[0 .. kd) updated at once, the largest
 * ||R - I||_F so far in acc[kd]. A pending scale b_i is applied in the same
 * pass, so the Ten Berge step costs no pass of its own. */
static es_status sweep_one(gpa_state *st, int64_t i, double *s, void *ud)
{
    const sweep_args *sa = ud;
    int64_t k = st->k;
    int d = st->d;
    double *xi = COL(st, i), a[9], r[9], b = st->pend[i];
    es_status rc;
    cross_with_others(k, d, xi, s, b, a);
    if ((rc = es__procrustes_rotation(st->ctx, d, a, sa->allow_reflection, r, NULL)) != ES_OK)
        return rc;
    double c = 0;
    for (int p = 0; p < d; p++)
        for (int q = 0; q < d; q++) {
            double e = r[p + q * d] - (p == q);
            c += e * e;
        }
    c = sqrt(c);
    if (c > s[st->kd]) s[st->kd] = c;
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
    double *ra = sa->rot_acc + i * d * d, t[9];
    for (int p = 0; p < d; p++)
        for (int q = 0; q < d; q++) {
            double acc = 0;
            for (int l = 0; l < d; l++) acc += ra[p + l * d] * r[l + q * d];
            t[p + q * d] = acc;
        }
    memcpy(ra, t, (size_t)(d * d) * sizeof *t);
    return ES_OK;
}

/* One Gauss-Seidel rotation sweep; returns the largest ||R - I||_F. */
static es_status rotation_sweep(gpa_state *st, int allow_reflection, double *rot_acc,
                                double *change)
{
    sweep_args sa = {allow_reflection, rot_acc};
    es_status rc;
    st->sum[st->kd] = 0;
    rc = chain(st, st->sum, st->kd + 1, sweep_one, &sa);
    *change = st->sum[st->kd];
    return rc;
}

static es_status flush_one(gpa_state *st, int64_t j, double *sum, void *ud)
{
    double *xj = COL(st, j), b = st->pend[j];
    (void)ud;
    for (int64_t v = 0; v < st->kd; v++) {
        xj[v] *= b;
        sum[v] += xj[v];
    }
    return ES_OK;
}

/* Multiply pending scales into the data and recompute the sum exactly. */
static es_status flush_scales(gpa_state *st)
{
    es_status rc;
    memset(st->sum, 0, (size_t)st->kd * sizeof *st->sum);
    rc = chain(st, st->sum, st->kd, flush_one, NULL);
    for (int64_t j = 0; j < st->n; j++) st->pend[j] = 1.0;
    return rc;
}

/* Leading eigenvector of the cosine matrix from the explicit Gram matrix;
 * on the ranks rank 0 gathers the configurations (n^2 k d is small on
 * this route), decomposes and broadcasts phi. */
static es_status tenberge_exact(gpa_state *st)
{
    int64_t n = st->n;
    const double *xall = st->x.data;
    int64_t ldx = st->x.ld;
    int ni, kdi, ldi, m;
    es_status rc = ES_OK;
    if (st->ranks > 1) {
        int64_t *counts = es__alloc_array(st->ctx, st->ranks, sizeof *counts), lo, hi;
        if ((rc = es__par_agree(st->ctx, counts ? ES_OK : ES_ENOMEM)) != ES_OK) {
            es__free(st->ctx, counts);
            return rc;
        }
        for (int q = 0; q < st->ranks; q++) {
            es__par_split(n, st->ranks, q, &lo, &hi);
            counts[q] = (hi - lo) * st->kd;
        }
        rc = es__par_gather(st->ctx, st->x.data, counts, st->all);
        es__free(st->ctx, counts);
        if (rc) return rc;
        xall = st->all;
        ldx = st->kd;
    }
    if (st->rank == 0) {
        if ((rc = es__lapack_int(st->ctx, n, &ni)) != ES_OK ||
            (rc = es__lapack_int(st->ctx, st->kd, &kdi)) != ES_OK ||
            (rc = es__lapack_int(st->ctx, ldx, &ldi)) != ES_OK)
            goto agree;
        double *g = st->work, w[1];
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, ni, kdi, 1.0, xall, ldi, 0.0, g, ni);
        for (int64_t j = 0; j < n; j++)
            for (int64_t i = 0; i <= j; i++)
                g[i + j * n] /= sqrt(st->norm2[i] * st->norm2[j]);
        int *isuppz = es__alloc_array(st->ctx, 2, sizeof *isuppz);
        if (!isuppz) { rc = ES_ENOMEM; goto agree; }
        lapack_int info = LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', 'I', 'U', ni, g, ni, 0, 0, ni,
                                         ni, 0.0, &m, w, st->phi, ni, isuppz);
        es__free(st->ctx, isuppz);
        if (info != 0 || m != 1)
            rc = es__fail(st->ctx, ES_ENUMERIC, "gpa: eigen-decomposition for Ten Berge "
                          "scaling failed (info %d)", (int)info);
        for (int64_t j = 0; j < n; j++) st->phi[j] = fabs(st->phi[j]);
    }
agree:
    if (st->ranks < 2) return rc;
    if ((rc = es__par_agree(st->ctx, rc)) != ES_OK) return rc;
    return es__par_bcast(st->ctx, st->phi, (size_t)n * sizeof *st->phi, 0);
}

static es_status power_axpy(gpa_state *st, int64_t j, double *y, void *ud)
{
    (void)ud;
    cblas_daxpy((int)st->kd, st->phi[j] / sqrt(st->norm2[j]), COL(st, j), 1, y, 1);
    return ES_OK;
}

/* The same eigenvector by power iteration, warm-started at
 * phi_j = ||X_j|| / sqrt(total): the previous scaling made that the
 * eigenvector of the previous iterate, and for it y = sum_j phi_j X_j /
 * ||X_j|| is just S / sqrt(total), which the sweep has kept up to date, so
 * the first step costs one pass and later ones two. Stops when phi moves by
 * less than 0.1 tol / sqrt(n) (enough for scale changes below tol/10) or
 * 1e-15. On return work holds y for the returned phi, so the scaled sum is
 * sqrt(total) * y. On the ranks y is a chain and each rank takes the dots
 * of its own configurations. */
static es_status tenberge_power(gpa_state *st, double total, double tol)
{
    int64_t n = st->n, kd = st->kd;
    double *y = st->work, *z = st->z, *phi = st->phi;
    double stop = fmax(1e-15, 0.1 * tol / sqrt((double)n));
    es_status rc;
    for (int64_t j = 0; j < n; j++) phi[j] = sqrt(st->norm2[j] / total);
    for (int64_t v = 0; v < kd; v++) y[v] = st->sum[v] / sqrt(total);
    for (int it = 0; it < 500; it++) {
        if (it > 0) {
            memset(y, 0, (size_t)kd * sizeof *y);
            if ((rc = chain(st, y, kd, power_axpy, NULL)) != ES_OK) return rc;
        }
        st->power_steps++;
        double nz = 0, diff = 0;
        for (int64_t j = st->lo; j < st->hi; j++)
            z[j] = cblas_ddot((int)kd, COL(st, j), 1, y, 1) / sqrt(st->norm2[j]);
        if ((rc = gather_shares(st, z, 1)) != ES_OK) return rc;
        for (int64_t j = 0; j < n; j++) nz += z[j] * z[j];
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
 * squares; the sum of the scaled set is set up for the next sweep. Every
 * rank computes every beta (phi is the same on all). */
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
        if ((rc = flush_scales(st)) != ES_OK) return rc;
    } else {
        for (int64_t v = 0; v < kd; v++) st->sum[v] = sqrt(total) * st->work[v];
    }
    *change = maxc;
    return ES_OK;
}

typedef struct centre_args { es_gpa_out *out; } centre_args;

/* Configuration j centred: its centroid and size recorded, its sum of
 * squares added to acc[kd] (the total) and its coordinates to the sum. */
static es_status centre_one(gpa_state *st, int64_t j, double *acc, void *ud)
{
    es_gpa_out *out = ((centre_args *)ud)->out;
    int64_t k = st->k;
    int d = st->d;
    double *xj = COL(st, j), c[3], ss = 0;
    for (int q = 0; q < d; q++) {
        double s = 0;
        for (int64_t v = 0; v < k; v++) s += xj[v + q * k];
        c[q] = s / (double)k;
        for (int64_t v = 0; v < k; v++) {
            xj[v + q * k] -= c[q];
            ss += xj[v + q * k] * xj[v + q * k];
            acc[v + q * k] += xj[v + q * k];
        }
    }
    if (!isfinite(ss))
        ES_FAIL(st->ctx, ES_EINVAL, "gpa: configuration %lld has a non-finite coordinate",
                (long long)j);
    if (!(ss > 0))
        ES_FAIL(st->ctx, ES_EINVAL, "gpa: configuration %lld has zero centroid size (all %lld "
                "points coincide)", (long long)j, (long long)k);
    if (out && out->centroid) memcpy(out->centroid + j * d, c, (size_t)d * sizeof *c);
    if (out && out->size) out->size[j] = sqrt(ss);
    st->norm2[j] = ss;
    acc[st->kd] += ss;
    return ES_OK;
}

typedef struct fit_args { const double *mean; double msz; int allow_reflection; double *rho; } fit_args;

/* Configuration j's part of GSS (acc[0]) and of the sum of rho^2 (acc[1]). */
static es_status fit_one(gpa_state *st, int64_t j, double *acc, void *ud)
{
    const fit_args *fa = ud;
    const double *xj = COL(st, j), *mean = fa->mean;
    double a[9], r = 0, nx = 0;
    es_status rc;
    for (int64_t v = 0; v < st->kd; v++) {
        acc[0] += (xj[v] - mean[v]) * (xj[v] - mean[v]);
        nx += xj[v] * xj[v];
    }
    if (fa->msz > 0) {
        es__procrustes_cross(st->k, st->d, xj, mean, a);
        if ((rc = es__procrustes_rho(st->ctx, st->d, a, sqrt(nx), fa->msz, fa->allow_reflection,
                                     &r)) != ES_OK)
            return rc;
    } else {
        r = M_PI / 2;
    }
    acc[1] += r * r;
    if (fa->rho) fa->rho[j] = r;
    return ES_OK;
}

/* The work of es_gpa_align and es_gpa_align_ranks: n configurations in all,
 * x holding [lo, hi) of them; ranks 1: all here, no messages. */
static es_status gpa_run(es_ctx *ctx, int64_t k, int d, int64_t n, int ranks, es_mat x,
                         const es_gpa_opts *opts, es_gpa_out *out, es_gpa_report *report)
{
    es_gpa_opts o;
    es_gpa_report rep;
    gpa_state st;
    es_status rc = ES_OK;
    int64_t kd, nn;
    double *rot_acc = NULL, *scale_acc = NULL, *buf = NULL;

    if (opts) o = *opts; else es_gpa_opts_init(&o);
    memset(&rep, 0, sizeof rep);
    if (report) *report = rep;
    memset(&st, 0, sizeof st);
    st.ranks = ranks;
    st.rank = ranks > 1 ? es__par_rank(ctx) : 0;
    st.lo = 0;
    st.hi = n;
    if (ranks > 1) es__par_split(n, ranks, st.rank, &st.lo, &st.hi);
    if (d != 2 && d != 3) ES_FAIL(ctx, ES_EINVAL, "gpa: dimension %d is not 2 or 3", d);
    if (k < 1 || !es__mul_i64(k, d, &kd) || x.rows != kd || x.ld < kd ||
        x.cols != st.hi - st.lo || (ranks > 1 && x.ld != kd))
        ES_FAIL(ctx, ES_EINVAL, "gpa: a %lld x %lld matrix (ld %lld) does not hold %lld "
                "configurations of %lld x %d%s", (long long)x.rows, (long long)x.cols,
                (long long)x.ld, (long long)(st.hi - st.lo), (long long)k, d,
                ranks > 1 ? " (this rank's share, ld = k d)" : "");
    if (n < 2) ES_FAIL(ctx, ES_EINVAL, "gpa: needs at least 2 configurations, got %lld",
                       (long long)n);
    if (!(o.tol >= 0) || o.max_iter < 1)
        ES_FAIL(ctx, ES_EINVAL, "gpa: tolerance %g / max_iter %lld invalid", o.tol,
                (long long)o.max_iter);
    if (!es__mul_i64(n, n, &nn)) ES_FAIL(ctx, ES_ERANGE, "gpa: %lld configurations", (long long)n);
    if (kd > INT32_MAX) ES_FAIL(ctx, ES_ERANGE, "gpa: %lld coordinates per configuration exceed "
                                "BLAS's int", (long long)kd);

    st.ctx = ctx; st.k = k; st.d = d; st.n = n; st.kd = kd; st.x = x;
    /* one block: sum kd + 1, work max(kd, n*n) (n*n only for the explicit
     * Gram matrix), norm2, pend, phi, z, scale n each, rot d*d*n; rank 0 of
     * several on the exact route also every configuration */
    int exact = o.scale && (double)n * (double)n * (double)kd <= GRAM_LIMIT;
    int64_t nwork = exact && nn > kd ? nn : kd;
    int64_t nall = exact && ranks > 1 && st.rank == 0 ? n * kd : 0;
    int64_t total_len = kd + 1 + nwork + 5 * n + (int64_t)d * d * n + nall;
    buf = es__alloc_array(ctx, total_len, sizeof *buf);
    if (ranks > 1) rc = es__par_agree(ctx, buf ? ES_OK : ES_ENOMEM);
    if (!buf || rc) { rc = rc ? rc : ES_ENOMEM; goto done; }
    st.sum = buf;
    st.work = st.sum + kd + 1;
    st.norm2 = st.work + nwork;
    st.pend = st.norm2 + n;
    st.phi = st.pend + n;
    st.z = st.phi + n;
    scale_acc = st.z + n;
    rot_acc = scale_acc + n;
    st.all = nall ? rot_acc + (int64_t)d * d * n : NULL;

    /* centre, record centroids and sizes, check for degenerate input */
    for (int64_t j = 0; j < n; j++) {
        scale_acc[j] = 1.0;
        st.pend[j] = 1.0;
        for (int q = 0; q < d * d; q++) rot_acc[j * d * d + q] = q % (d + 1) == 0;
    }
    memset(st.sum, 0, (size_t)(kd + 1) * sizeof *st.sum);
    centre_args ca = {out};
    if ((rc = chain(&st, st.sum, kd + 1, centre_one, &ca)) != ES_OK ||
        (rc = gather_shares(&st, st.norm2, 1)) != ES_OK ||
        (out && out->size && (rc = gather_shares(&st, out->size, 1)) != ES_OK) ||
        (out && out->centroid && (rc = gather_shares(&st, out->centroid, d)) != ES_OK))
        goto done;
    double total = st.sum[kd];
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
    /* also recomputes the sum without accumulated rounding */
    if ((rc = flush_scales(&st)) != ES_OK) goto done;

    /* mean, GSS and rho */
    double *mean = st.work, msz = 0, acc[2] = {0, 0};
    for (int64_t v = 0; v < kd; v++) {
        mean[v] = st.sum[v] / (double)n;
        msz += mean[v] * mean[v];
    }
    fit_args fa = {mean, sqrt(msz), o.allow_reflection, out ? out->rho : NULL};
    if ((rc = chain(&st, acc, 2, fit_one, &fa)) != ES_OK ||
        (out && out->rho && (rc = gather_shares(&st, out->rho, 1)) != ES_OK) ||
        (rc = gather_shares(&st, rot_acc, (int64_t)d * d)) != ES_OK)
        goto done;
    rep.gss = acc[0];
    rep.rmsrho = sqrt(acc[1] / (double)n);
    if (out && out->mean) memcpy(out->mean, mean, (size_t)kd * sizeof *mean);
    if (out && out->scale) memcpy(out->scale, scale_acc, (size_t)n * sizeof *scale_acc);
    if (out && out->rot) memcpy(out->rot, rot_acc, (size_t)(d * d * n) * sizeof *rot_acc);
    if (!rep.converged)
        rc = es__fail(ctx, ES_ENOCONV, "gpa: not converged after %lld iterations (rotation change "
                      "%.3g, scale change %.3g, tolerance %.3g)", (long long)o.max_iter,
                      rep.rot_change, rep.scale_change, o.tol);
done:
    rep.power_steps = st.power_steps;
    if (report) *report = rep;
    es__free(ctx, buf);
    return rc;
}

es_status es_gpa_align(es_ctx *ctx, int64_t k, int d, es_mat x, const es_gpa_opts *opts,
                       es_gpa_out *out, es_gpa_report *report)
{
    return gpa_run(ctx, k, d, x.cols, 1, x, opts, out, report);
}

es_status es_gpa_align_ranks(es_ctx *ctx, int64_t k, int d, int64_t n, es_mat x,
                             const es_gpa_opts *opts, es_gpa_out *out, es_gpa_report *report)
{
    return gpa_run(ctx, k, d, n, es__par_size(ctx), x, opts, out, report);
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
