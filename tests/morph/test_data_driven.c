/* tests/morph/test_data_driven.c — data-driven paths (es_data_path,
 * es_morph.h, Gao et al. 2017 Sec. 3.2) on point sets whose right answer
 * is known without the library:
 *  - the graph's shortest path against Floyd-Warshall on a K-nearest-
 *    neighbour graph the test builds itself by sorting distances (an
 *    independent computation), on a half circle and on two clusters that
 *    need one bridge (the shortest arc between them, found by a scan);
 *  - the paper's claim (Fig. 11b): on examples along a half circle the
 *    path stays near them (within 0.6 of the K-neighbour arc length, the
 *    straight line gets 8 units away), its length lies between the chord
 *    and 1.05 x the arc's length (pi), the ends are the end examples
 *    exactly, and the frames are affine combinations of the examples
 *    (reconstructed to 1e-10, weights summing to 1);
 *  - examples along a segment: the path is the segment (length within 1 %
 *    of the chord);
 *  - es_data_path_coords: 40 vectors of 500 entries (rank 6 plus tiny
 *    noise) keep their pairwise distances (against the direct sums, 1e-9
 *    relative) in at most 39 coordinates, one per component above 1e-12
 *    of the largest;
 *  - bad arguments named.
 */
#include "es_test.h"

#include <edgespace/edgespace.h>

#include <math.h>
#include <stdlib.h>

enum { DIM = 3 };

/* Examples along a half circle of radius r (x, y) with a small z wobble. */
static void half_circle(int64_t n, double r, double *x)
{
    for (int64_t j = 0; j < n; j++) {
        double a = M_PI * (double)j / (double)(n - 1);
        x[DIM * j] = r * cos(a), x[DIM * j + 1] = r * sin(a);
        x[DIM * j + 2] = 0.01 * r * sin(7.0 * (double)j);
    }
}

static double d3(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Floyd-Warshall on the symmetric K-nearest-neighbour graph plus the
 * shortest arc between its two parts when it has two (the test's sets
 * have at most two). Returns the src -> dst distance; *bridges the arcs added. */
static double oracle(int64_t n, const double *x, int64_t k, int64_t src, int64_t dst,
                     int64_t *bridges)
{
    double *g = malloc((size_t)(n * n) * sizeof *g);
    int64_t *part = malloc((size_t)n * sizeof *part);
    for (int64_t i = 0; i < n * n; i++) g[i] = INFINITY;
    for (int64_t i = 0; i < n; i++) {
        g[i * n + i] = 0;
        for (int64_t j = 0; j < n; j++) part[j] = j == i;
        for (int64_t r = 0; r < k; r++) {   /* selection: the r-th nearest */
            int64_t b = -1;
            for (int64_t j = 0; j < n; j++)
                if (!part[j] &&
                    (b < 0 || d3(x + DIM * i, x + DIM * j) < d3(x + DIM * i, x + DIM * b)))
                    b = j;
            part[b] = 1;
            g[i * n + b] = g[b * n + i] = d3(x + DIM * i, x + DIM * b);
        }
    }
    for (int64_t i = 0; i < n; i++) part[i] = !isinf(g[i]) || i == 0 ? 0 : -1;
    for (int changed = 1; changed;) {   /* the part of example 0 */
        changed = 0;
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = 0; part[i] == 0 && j < n; j++)
                if (part[j] && !isinf(g[i * n + j])) part[j] = 0, changed = 1;
    }
    *bridges = 0;
    int64_t bi = -1, bj = -1;
    for (int64_t i = 0; i < n; i++)
        for (int64_t j = 0; part[i] == 0 && j < n; j++)
            if (part[j] && (bi < 0 || d3(x + DIM * i, x + DIM * j) <
                                          d3(x + DIM * bi, x + DIM * bj)))
                bi = i, bj = j;
    if (bi >= 0) {
        g[bi * n + bj] = g[bj * n + bi] = d3(x + DIM * bi, x + DIM * bj);
        *bridges = 1;
    }
    for (int64_t m = 0; m < n; m++)
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = 0; j < n; j++)
                if (g[i * n + m] + g[m * n + j] < g[i * n + j]) g[i * n + j] = g[i * n + m] + g[m * n + j];
    double out = g[src * n + dst];
    free(g), free(part);
    return out;
}

static void test_half_circle(es_ctx *ctx)
{
    enum { N = 60, NF = 41 };
    double x[DIM * N], f[DIM * NF], w[N * NF];
    es_data_path_info info;
    int64_t bridges;
    half_circle(N, 10.0, x);
    ES_CHECK_OK(ctx, es_data_path(ctx, DIM, N, x, DIM, 0, N - 1, NULL, NF, f, w, &info));
    ES_CHECK_CLOSE(info.graph_length, oracle(N, x, 6, 0, N - 1, &bridges), 1e-12, 0);
    ES_CHECK(info.bridges == 0 && bridges == 0);
    ES_CHECK_MSG(info.converged && info.iterations > 0, "iterations %d", info.iterations);
    for (int k = 0; k < DIM; k++) {
        ES_CHECK(f[k] == x[k]);
        ES_CHECK(f[DIM * (NF - 1) + k] == x[DIM * (N - 1) + k]);
    }
    ES_CHECK_MSG(info.max_near < 0.6 && info.line_max_near * info.scale > 8.0,
                 "path %.3g straight line %.3g (scale %.3g)", info.max_near,
                 info.line_max_near, info.scale);
    ES_CHECK_MSG(info.length > 20 && info.length < 1.05 * M_PI * 10, "length %.4g",
                 info.length);
    /* the frames as combinations of the examples */
    double worst = 0, wsum = 0;
    for (int64_t s = 0; s < NF; s++) {
        double sum = 0, y[DIM] = {0, 0, 0};
        for (int64_t j = 0; j < N; j++) {
            sum += w[s * N + j];
            for (int k = 0; k < DIM; k++) y[k] += w[s * N + j] * x[DIM * j + k];
        }
        worst = fmax(worst, d3(y, f + DIM * s));
        wsum = fmax(wsum, fabs(sum - 1));
    }
    ES_CHECK_MSG(worst < 1e-10 && wsum < 1e-10, "reconstruction %.3g, weight sum %.3g", worst,
                 wsum);
    /* the frames are evenly spaced along the path */
    double dmin = INFINITY, dmax = 0;
    for (int64_t s = 1; s < NF; s++) {
        double dd = d3(f + DIM * (s - 1), f + DIM * s);
        dmin = fmin(dmin, dd), dmax = fmax(dmax, dd);
    }
    ES_CHECK_MSG(dmax < 1.05 * dmin, "frame spacing %.4g .. %.4g", dmin, dmax);
}

static void test_clusters(es_ctx *ctx)
{
    enum { N = 24, NF = 11 };
    double x[DIM * N], f[DIM * NF];
    es_data_path_info info;
    int64_t bridges;
    for (int64_t j = 0; j < N; j++) {   /* two clusters of 12, 50 apart */
        x[DIM * j] = (j < 12 ? 0 : 50) + 0.3 * (double)(j % 12) + 0.05 * sin((double)j);
        x[DIM * j + 1] = 0.2 * cos(3.0 * (double)j), x[DIM * j + 2] = 0.1 * sin(5.0 * (double)j);
    }
    ES_CHECK_OK(ctx, es_data_path(ctx, DIM, N, x, DIM, 2, 20, NULL, NF, f, NULL, &info));
    ES_CHECK_CLOSE(info.graph_length, oracle(N, x, 6, 2, 20, &bridges), 1e-12, 0);
    ES_CHECK_MSG(info.bridges == 1 && bridges == 1, "bridges %lld", (long long)info.bridges);
}

static void test_segment(es_ctx *ctx)
{
    enum { N = 30, NF = 9 };
    double x[DIM * N], f[DIM * NF];
    es_data_path_info info;
    for (int64_t j = 0; j < N; j++)
        x[DIM * j] = (double)j, x[DIM * j + 1] = 2.0 * (double)j, x[DIM * j + 2] = -(double)j;
    ES_CHECK_OK(ctx, es_data_path(ctx, DIM, N, x, DIM, 0, N - 1, NULL, NF, f, NULL, &info));
    double chord = d3(x, x + DIM * (N - 1));
    ES_CHECK_MSG(fabs(info.length - chord) < 0.01 * chord, "length %.6g chord %.6g",
                 info.length, chord);
    ES_CHECK(info.max_near < 0.51);
}

static void test_coords(es_ctx *ctx)
{
    enum { D = 500, N = 40 };
    double *x = malloc(sizeof(double) * D * N), *c = malloc(sizeof(double) * N * N), worst = 0;
    int64_t nc = -1;
    for (int64_t j = 0; j < N; j++)
        for (int64_t k = 0; k < D; k++) {
            double v = 0;
            for (int r = 1; r <= 6; r++) v += sin(0.37 * r * (double)j + 0.011 * (double)(k * r));
            x[j * D + k] = v + 1e-7 * cos(13.0 * (double)(j * D + k));
        }
    ES_CHECK_OK(ctx, es_data_path_coords(ctx, D, N, x, D, c, &nc));
    ES_CHECK_MSG(nc >= 6 && nc <= N - 1, "%lld coordinates", (long long)nc);
    for (int64_t i = 0; i < N; i++)
        for (int64_t j = 0; j < i; j++) {
            double dx = 0, dc = 0;
            for (int64_t k = 0; k < D; k++) dx += (x[i * D + k] - x[j * D + k]) * (x[i * D + k] - x[j * D + k]);
            for (int64_t k = 0; k < nc; k++) dc += (c[i * N + k] - c[j * N + k]) * (c[i * N + k] - c[j * N + k]);
            worst = fmax(worst, fabs(sqrt(dc) - sqrt(dx)) / sqrt(dx));
        }
    ES_CHECK_MSG(worst < 1e-9, "distances kept to %.3g", worst);
    free(x), free(c);
}

static void test_bad(es_ctx *ctx)
{
    double x[DIM * 4] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0}, f[DIM * 3];
    ES_CHECK_FAILS(ctx, es_data_path(ctx, DIM, 4, x, DIM, 1, 1, NULL, 3, f, NULL, NULL),
                   ES_EINVAL, "1 -> 1");
    ES_CHECK_FAILS(ctx, es_data_path(ctx, DIM, 4, x, DIM, 0, 4, NULL, 3, f, NULL, NULL),
                   ES_EINVAL, "0 -> 4");
    x[7] = NAN;
    ES_CHECK_FAILS(ctx, es_data_path(ctx, DIM, 4, x, DIM, 0, 3, NULL, 3, f, NULL, NULL),
                   ES_EINVAL, "example 2 coordinate 1");
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_half_circle(ctx);
    test_clusters(ctx);
    test_segment(ctx);
    test_coords(ctx);
    test_bad(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
