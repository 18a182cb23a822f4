/* lib/morph/data_driven.c — data-driven shape interpolation (Gao, Chen,
 * Lai and Xia 2017, Sec. 3.2): a path through a collection of examples,
 * started by Dijkstra on their K-nearest-neighbour graph and smoothed by
 * the iterated quadratic energy of eq. 2, which keeps it near the examples
 * while shortening and evening it. See es_morph.h for the choices made
 * where the paper is silent (the unit of its parameters above all).
 *
 * Sizes: the pairwise distances of the examples come from one Gram matrix
 * (n x n, BLAS), the graph is dense-scanned (n is a store's row count, a
 * few thousand at most); each iteration finds the k~ nearest examples of
 * every sample by a scan (samples x n x dim) and solves one dense SPD
 * system of the inner samples with dim right-hand sides.
 */
#include "morph/morph_pkg.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>

void es_data_path_opts_init(es_data_path_opts *o)
{
    o->knn = 6, o->near = 6, o->samples = 200;
    o->sigma = 1, o->gamma = 0.01, o->lambda = 100, o->delta = 1e-4, o->eps = 1e-3;
    o->max_iter = 200;
}

static double dist(int64_t dim, const double *a, const double *b)
{
    double s = 0;
    for (int64_t k = 0; k < dim; k++) s += (a[k] - b[k]) * (a[k] - b[k]);
    return sqrt(s);
}

/* The examples' mean mu (dim, zeroed by the caller) and the centred
 * examples c (dim x n, packed). */
static void centre(int64_t dim, int64_t n, const double *x, int64_t ldx, double *mu, double *c)
{
    for (int64_t j = 0; j < n; j++)
        for (int64_t k = 0; k < dim; k++) mu[k] += x[j * ldx + k] / (double)n;
    for (int64_t j = 0; j < n; j++)
        for (int64_t k = 0; k < dim; k++) c[j * dim + k] = x[j * ldx + k] - mu[k];
}

/* Pairwise distances d (n x n) from the Gram matrix of the centred
 * coordinates (centring keeps the cancellation small). */
static es_status pair_dist(es_ctx *ctx, int64_t dim, int64_t n, const double *x, int64_t ldx,
                           double *d)
{
    double *c = es__alloc_array(ctx, dim * n, sizeof *c), *mu = es__calloc(ctx, (size_t)dim, 8);
    if (!c || !mu) {
        es__free(ctx, c), es__free(ctx, mu);
        return ES_ENOMEM;
    }
    centre(dim, n, x, ldx, mu, c);
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, (int)n, (int)dim, 1.0, c, (int)dim, 0.0,
                d, (int)n);
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < j; i++) {
            double s = d[i * n + i] + d[j * n + j] - 2 * d[j * n + i];
            d[j * n + i] = s > 0 ? sqrt(s) : 0;
        }
    for (int64_t j = 0; j < n; j++) {
        d[j * n + j] = 0;
        for (int64_t i = j + 1; i < n; i++) d[j * n + i] = d[i * n + j];
    }
    es__free(ctx, c), es__free(ctx, mu);
    return ES_OK;
}

/* The connected K-nearest-neighbour graph as a symmetric adjacency (0: no
 * arc), and Dijkstra's path from src to dst into route (hops returned). */
static es_status graph_path(es_ctx *ctx, int64_t n, const double *d, const es_data_path_opts *o,
                            int64_t src, int64_t dst, int64_t *route, es_data_path_info *info)
{
    unsigned char *adj = es__calloc(ctx, (size_t)(n * n), 1);
    int64_t *used = es__alloc_array(ctx, n, sizeof *used), *prev = es__alloc_array(ctx, n, 8);
    double *best = es__alloc_array(ctx, n, sizeof *best), sum = 0;
    int64_t narc = 0, k = o->knn < n - 1 ? o->knn : n - 1;
    if (!adj || !used || !prev || !best) {
        es__free(ctx, adj), es__free(ctx, used), es__free(ctx, prev), es__free(ctx, best);
        return ES_ENOMEM;
    }
    for (int64_t i = 0; i < n; i++) {
        for (int64_t j = 0; j < n; j++) used[j] = j == i;
        for (int64_t r = 0; r < k; r++) {
            int64_t b = -1;
            for (int64_t j = 0; j < n; j++)
                if (!used[j] && (b < 0 || d[i * n + j] < d[i * n + b])) b = j;
            used[b] = 1, sum += d[i * n + b];
            if (!adj[i * n + b]) narc++;
            adj[i * n + b] = adj[b * n + i] = 1;
        }
    }
    info->scale = sum / (double)(n * k);
    info->arcs = narc, info->bridges = 0;
    /* connect: grow the part of example 0, bridging by its shortest arc out */
    for (;;) {
        int64_t nin = 0, bi = -1, bj = -1;
        for (int64_t j = 0; j < n; j++) used[j] = j == 0;
        for (int64_t changed = 1; changed;) {
            changed = 0;
            for (int64_t i = 0; i < n; i++)
                for (int64_t j = 0; used[i] && j < n; j++)
                    if (!used[j] && adj[i * n + j]) used[j] = 1, changed = 1;
        }
        for (int64_t i = 0; i < n; i++) nin += used[i] != 0;
        if (nin == n) break;
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = 0; used[i] && j < n; j++)
                if (!used[j] && (bi < 0 || d[i * n + j] < d[bi * n + bj])) bi = i, bj = j;
        adj[bi * n + bj] = adj[bj * n + bi] = 1;
        info->arcs++, info->bridges++;
    }
    /* Dijkstra, dense: n is small */
    for (int64_t j = 0; j < n; j++) best[j] = INFINITY, used[j] = 0, prev[j] = -1;
    best[src] = 0;
    for (;;) {
        int64_t u = -1;
        for (int64_t j = 0; j < n; j++)
            if (!used[j] && (u < 0 || best[j] < best[u])) u = j;
        if (u < 0 || u == dst) break;
        used[u] = 1;
        for (int64_t j = 0; j < n; j++)
            if (adj[u * n + j] && best[u] + d[u * n + j] < best[j])
                best[j] = best[u] + d[u * n + j], prev[j] = u;
    }
    info->graph_length = best[dst];
    info->hops = 0;
    for (int64_t v = dst; v >= 0; v = prev[v]) route[info->hops++] = v;
    for (int64_t a = 0, b = info->hops - 1; a < b; a++, b--) {
        int64_t t = route[a];
        route[a] = route[b], route[b] = t;
    }
    es__free(ctx, adj), es__free(ctx, used), es__free(ctx, prev), es__free(ctx, best);
    return ES_OK;
}

/* Resample the polyline p (dim x np) to m points evenly spaced by length
 * (the ends exactly); returns its length. */
static double resample(int64_t dim, int64_t np, const double *p, int64_t m, double *out)
{
    double total = 0, acc = 0;
    int64_t seg = 0;
    for (int64_t i = 1; i < np; i++) total += dist(dim, p + (i - 1) * dim, p + i * dim);
    for (int64_t s = 0; s < m; s++) {
        double want = total * (double)s / (double)(m - 1), len, f;
        while (seg < np - 2 && acc + (len = dist(dim, p + seg * dim, p + (seg + 1) * dim)) < want)
            acc += len, seg++;
        len = np > 1 ? dist(dim, p + seg * dim, p + (seg + 1) * dim) : 0;
        f = len > 0 ? (want - acc) / len : 0;
        f = f < 0 ? 0 : f > 1 ? 1 : f;
        if (s == m - 1) f = 1;
        for (int64_t k = 0; k < dim; k++)
            out[s * dim + k] = (1 - f) * p[seg * dim + k] + f * p[(seg + 1) * dim + k];
    }
    return total;
}

/* Distance from each of m points q to its nearest example: mean and max. */
static void near_stats(int64_t dim, int64_t n, const double *x, int64_t ldx, int64_t m,
                       const double *q, double scale, double *mean, double *max)
{
    *mean = 0, *max = 0;
    for (int64_t s = 0; s < m; s++) {
        double b = INFINITY;
        for (int64_t j = 0; j < n; j++) {
            double dj = dist(dim, q + s * dim, x + j * ldx);
            b = dj < b ? dj : b;
        }
        *mean += b / scale / (double)m;
        *max = b / scale > *max ? b / scale : *max;
    }
}

/* One iteration of eq. 2 on path p (dim x m) into q; a: (m-2)^2, rhs:
 * (m-2) x dim, nb/nd: near scratch. Returns the LAPACK info. */
static int smooth_step(int64_t dim, int64_t n, const double *x, int64_t ldx, int64_t m,
                       const double *p, double *q, const es_data_path_opts *o, double scale,
                       double *a, double *rhs, int64_t *nb, double *nd)
{
    int64_t mi = m - 2, kn = o->near < n ? o->near : n;
    double sigma = o->sigma * scale, lap[3];
    for (int64_t i = 0; i < mi * mi; i++) a[i] = 0;
    for (int64_t i = 0; i < mi * dim; i++) rhs[i] = 0;
    for (int64_t s = 1; s <= m - 2; s++) {
        int64_t r = s - 1;
        for (int64_t t = 0; t < kn; t++) nd[t] = INFINITY, nb[t] = -1;
        for (int64_t j = 0; j < n; j++) {   /* insertion into the k~ nearest */
            double dj = dist(dim, p + s * dim, x + j * ldx);
            for (int64_t t = kn - 1; t >= 0 && dj < nd[t]; t--) {
                if (t + 1 < kn) nd[t + 1] = nd[t], nb[t + 1] = nb[t];
                nd[t] = dj, nb[t] = j;
            }
        }
        for (int64_t t = 0; t < kn; t++) {
            double w = exp(-nd[t] / sigma);
            a[r * mi + r] += w;
            for (int64_t k = 0; k < dim; k++) rhs[k * mi + r] += w * x[nb[t] * ldx + k];
        }
        a[r * mi + r] += o->delta;
        for (int64_t k = 0; k < dim; k++) rhs[k * mi + r] += o->delta * p[s * dim + k];
    }
    /* gamma sum |p_s - p_{s-1}|^2 and lambda |L p|^2 as (samples, weights)
     * rows; a row's terms on the held ends move to the right-hand side */
    for (int64_t s = 1; s <= m - 1 + (m - 2); s++) {
        int64_t idx[3], cnt;
        double wt;
        if (s <= m - 1) {   /* segment s-1 .. s */
            idx[0] = s, idx[1] = s - 1, lap[0] = 1, lap[1] = -1, cnt = 2, wt = o->gamma;
        } else {            /* Laplacian row of inner sample c */
            int64_t c = s - (m - 1);
            double d0 = dist(dim, p + (c - 1) * dim, p + c * dim);
            double d1 = dist(dim, p + c * dim, p + (c + 1) * dim), sd = d0 + d1;
            idx[0] = c - 1, idx[1] = c, idx[2] = c + 1, cnt = 3, wt = o->lambda;
            lap[0] = sd > 0 ? -d0 / sd : -0.5, lap[1] = 1, lap[2] = sd > 0 ? -d1 / sd : -0.5;
        }
        for (int64_t u = 0; u < cnt; u++) {
            int64_t ru = idx[u] - 1;
            if (ru < 0 || ru >= mi) continue;
            for (int64_t v = 0; v < cnt; v++) {
                int64_t rv = idx[v] - 1;
                if (rv >= 0 && rv < mi)
                    a[rv * mi + ru] += wt * lap[u] * lap[v];
                else
                    for (int64_t k = 0; k < dim; k++)
                        rhs[k * mi + ru] -= wt * lap[u] * lap[v] * p[idx[v] * dim + k];
            }
        }
    }
    int info = LAPACKE_dposv(LAPACK_COL_MAJOR, 'U', (lapack_int)mi, (lapack_int)dim, a,
                             (lapack_int)mi, rhs, (lapack_int)mi);
    for (int64_t k = 0; k < dim; k++) q[k] = p[k], q[(m - 1) * dim + k] = p[(m - 1) * dim + k];
    for (int64_t s = 1; s <= m - 2; s++)
        for (int64_t k = 0; k < dim; k++) q[s * dim + k] = rhs[k * mi + s - 1];
    return info;
}

/* Frames as affine combinations of the examples: w = 1/n + pinv(X - mean)
 * (f - mean), the least-norm solution (it sums to 1 since the centred
 * examples annihilate the ones vector). */
static es_status frame_weights(es_ctx *ctx, int64_t dim, int64_t n, const double *x,
                               int64_t ldx, int64_t nf, const double *f, double *w)
{
    int64_t ldb = dim > n ? dim : n;
    double *c = es__alloc_array(ctx, dim * n, 8), *b = es__alloc_array(ctx, ldb * nf, 8);
    double *mu = es__calloc(ctx, (size_t)dim, 8), *sv = es__alloc_array(ctx, ldb, 8);
    lapack_int rank;
    int info = -1;
    if (c && b && mu && sv) {
        centre(dim, n, x, ldx, mu, c);
        for (int64_t s = 0; s < nf; s++)
            for (int64_t k = 0; k < ldb; k++) b[s * ldb + k] = k < dim ? f[s * dim + k] - mu[k] : 0;
        info = LAPACKE_dgelsd(LAPACK_COL_MAJOR, (lapack_int)dim, (lapack_int)n, (lapack_int)nf,
                              c, (lapack_int)dim, b, (lapack_int)ldb, sv, 1e-12, &rank);
        for (int64_t s = 0; info == 0 && s < nf; s++)
            for (int64_t j = 0; j < n; j++) w[s * n + j] = 1.0 / (double)n + b[s * ldb + j];
    }
    es__free(ctx, c), es__free(ctx, b), es__free(ctx, mu), es__free(ctx, sv);
    if (!c || !b || !mu || !sv) return ES_ENOMEM;
    if (info != 0) ES_FAIL(ctx, ES_ENUMERIC, "data-driven path: least squares failed (%d)", info);
    return ES_OK;
}

es_status es_data_path(es_ctx *ctx, int64_t dim, int64_t n, const double *x, int64_t ldx,
                       int64_t src, int64_t dst, const es_data_path_opts *opts, int64_t nframes,
                       double *frames, double *weights, es_data_path_info *info)
{
    es_data_path_opts o;
    es_data_path_info inf = {0};
    es_status rc = ES_OK;
    if (opts) o = *opts; else es_data_path_opts_init(&o);
    if (!x || !frames || dim < 1 || ldx < dim || n < 2 || nframes < 2)
        ES_FAIL(ctx, ES_EINVAL, "data-driven path: %lld examples of dimension %lld (ld %lld) "
                "and %lld frames (needs 2 examples and 2 frames)", (long long)n, (long long)dim,
                (long long)ldx, (long long)nframes);
    if (src < 0 || src >= n || dst < 0 || dst >= n || src == dst)
        ES_FAIL(ctx, ES_EINVAL, "data-driven path: examples %lld -> %lld of %lld (two "
                "different ones needed)", (long long)src, (long long)dst, (long long)n);
    if (o.knn < 1 || o.near < 1 || o.samples < 3 || !(o.sigma > 0) || !(o.gamma >= 0) ||
        !(o.lambda >= 0) || !(o.delta > 0) || !(o.eps > 0) || o.max_iter < 0)
        ES_FAIL(ctx, ES_EINVAL, "data-driven path: options out of range (knn, near >= 1, "
                "samples >= 3, sigma, delta, eps > 0, gamma, lambda >= 0)");
    for (int64_t j = 0; j < n; j++)
        for (int64_t k = 0; k < dim; k++)
            if (!isfinite(x[j * ldx + k]))
                ES_FAIL(ctx, ES_EINVAL, "data-driven path: example %lld coordinate %lld is not "
                        "finite", (long long)j, (long long)k);
    int64_t m = o.samples, mi = m - 2;
    double *d = es__alloc_array(ctx, n * n, 8), *poly = es__alloc_array(ctx, n * dim, 8);
    double *p = es__alloc_array(ctx, m * dim, 8), *q = es__alloc_array(ctx, m * dim, 8);
    double *a = es__alloc_array(ctx, mi * mi, 8), *rhs = es__alloc_array(ctx, mi * dim, 8);
    double *nd = es__alloc_array(ctx, o.near, 8), *line = es__alloc_array(ctx, nframes * dim, 8);
    int64_t *route = es__alloc_array(ctx, n, 8), *nb = es__alloc_array(ctx, o.near, 8);
    if (!d || !poly || !p || !q || !a || !rhs || !nd || !line || !route || !nb) rc = ES_ENOMEM;
    if (rc == ES_OK) rc = pair_dist(ctx, dim, n, x, ldx, d);
    if (rc == ES_OK) rc = graph_path(ctx, n, d, &o, src, dst, route, &inf);
    if (rc == ES_OK) {
        for (int64_t h = 0; h < inf.hops; h++)
            for (int64_t k = 0; k < dim; k++) poly[h * dim + k] = x[route[h] * ldx + k];
        resample(dim, inf.hops, poly, m, p);
        if (!(inf.scale > 0)) inf.scale = 1;   /* all examples equal: any unit */
    }
    for (int it = 0; rc == ES_OK && it < o.max_iter && !inf.converged; it++) {
        double move = 0;
        int li = smooth_step(dim, n, x, ldx, m, p, q, &o, inf.scale, a, rhs, nb, nd);
        if (li != 0) {
            rc = es__fail(ctx, ES_ENUMERIC, "data-driven path: the system of iteration %d is "
                          "not positive definite (%d)", it + 1, li);
            break;
        }
        for (int64_t s = 0; s < m; s++) move += dist(dim, p + s * dim, q + s * dim) / (double)m;
        double *t = p;
        p = q, q = t;
        inf.iterations = it + 1;
        inf.converged = move < o.eps * inf.scale;
        rc = es__progress(ctx, "data-driven path", it + 1, o.max_iter);
    }
    if (rc == ES_OK) {
        inf.length = resample(dim, m, p, nframes, frames);
        for (int64_t k = 0; k < dim; k++) {   /* the ends are the examples, exactly */
            frames[k] = x[src * ldx + k];
            frames[(nframes - 1) * dim + k] = x[dst * ldx + k];
        }
        for (int64_t s = 0; s < nframes; s++) {
            double f = (double)s / (double)(nframes - 1);
            for (int64_t k = 0; k < dim; k++)
                line[s * dim + k] = (1 - f) * x[src * ldx + k] + f * x[dst * ldx + k];
        }
        near_stats(dim, n, x, ldx, nframes, frames, inf.scale, &inf.mean_near, &inf.max_near);
        near_stats(dim, n, x, ldx, nframes, line, inf.scale, &inf.line_mean_near,
                   &inf.line_max_near);
        if (weights) rc = frame_weights(ctx, dim, n, x, ldx, nframes, frames, weights);
    }
    void *fr[] = {d, poly, p, q, a, rhs, nd, line, route, nb};
    for (size_t i = 0; i < sizeof fr / sizeof fr[0]; i++) es__free(ctx, fr[i]);
    if (info) *info = inf;
    return rc;
}

es_status es_data_path_coords(es_ctx *ctx, int64_t dim, int64_t n, const double *x, int64_t ldx,
                              double *coords, int64_t *ncoord)
{
    if (!x || !coords || !ncoord || dim < 1 || n < 1 || ldx < dim)
        ES_FAIL(ctx, ES_EINVAL, "data-driven coordinates: %lld vectors of dimension %lld "
                "(ld %lld)", (long long)n, (long long)dim, (long long)ldx);
    double *c = es__alloc_array(ctx, dim * n, sizeof *c), *mu = es__calloc(ctx, (size_t)dim, 8);
    double *g = es__alloc_array(ctx, n * n, sizeof *g), *ev = es__alloc_array(ctx, n, 8);
    int info = -1;
    if (c && mu && g && ev) {
        centre(dim, n, x, ldx, mu, c);
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, (int)n, (int)dim, 1.0, c, (int)dim,
                    0.0, g, (int)n);
        info = LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'U', (lapack_int)n, g, (lapack_int)n, ev);
    }
    if (info == 0) {   /* eigenvalues ascending: component r is column n-1-r */
        int64_t r = 0;
        double top = ev[n - 1] > 0 ? ev[n - 1] : 0;
        for (; r < n && ev[n - 1 - r] > 1e-12 * top && top > 0; r++) {
            const double *v = g + (n - 1 - r) * n;
            double sq = sqrt(ev[n - 1 - r]);
            int64_t big = 0;   /* a sign fixed by the largest entry, for reproducible output */
            for (int64_t j = 1; j < n; j++) big = fabs(v[j]) > fabs(v[big]) ? j : big;
            for (int64_t j = 0; j < n; j++)
                coords[j * n + r] = (v[big] < 0 ? -v[j] : v[j]) * sq;
        }
        for (int64_t j = 0; j < n; j++)
            for (int64_t k = r; k < n; k++) coords[j * n + k] = 0;
        *ncoord = r;
    }
    es__free(ctx, c), es__free(ctx, mu), es__free(ctx, g), es__free(ctx, ev);
    if (!c || !mu || !g || !ev) return ES_ENOMEM;
    if (info != 0) ES_FAIL(ctx, ES_ENUMERIC, "data-driven coordinates: eigensolver failed (%d)",
                           info);
    return ES_OK;
}
