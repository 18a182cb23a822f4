/* tests/figure/test_plot.c — the figures of es_plot.h: nice ticks, colour maps,
 * valid PNG/SVG/PDF output of every plot kind, scatter points and heat-map
 * cells where the returned es_plot_info says they are, error paths; the
 * figures of a CSV table (es_figure_table, es_figure.h) read back from PNG,
 * and its messages naming file, line and column. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"
#include "test_images.h"

#include <edgespace/es_figure.h>
#include <edgespace/es_plot.h>
#include <sys/wait.h>
#include <time.h>

static void test_nice_ticks(void)
{
    static const double cases[][2] = {{0, 1}, {-3.7, 12.1}, {0.0012, 0.0047}, {1e5, 3.3e6},
                                      {-1, -1}, {5, 5}, {0.1, 0.9}, {-250, 10}};
    double first, last, step;
    es_plot_nice_ticks(0, 1, 6, &first, &last, &step);
    ES_CHECK_CLOSE(first, 0, 0, 1e-15);
    ES_CHECK_CLOSE(last, 1, 0, 1e-15);
    ES_CHECK_CLOSE(step, 0.2, 1e-12, 0);
    es_plot_nice_ticks(-3.7, 12.1, 6, &first, &last, &step);
    ES_CHECK_CLOSE(first, -5, 0, 1e-12);
    ES_CHECK_CLOSE(last, 15, 0, 1e-12);
    ES_CHECK_CLOSE(step, 5, 0, 1e-12);
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double lo = cases[c][0], hi = cases[c][1];
        es_plot_nice_ticks(lo, hi, 5, &first, &last, &step);
        ES_CHECK_MSG(first <= lo && last >= hi && first < last, "[%g, %g] -> [%g, %g]", lo, hi,
                     first, last);
        /* step is 1, 2 or 5 times a power of ten */
        double m = step / pow(10, floor(log10(step)));
        ES_CHECK_MSG(fabs(m - 1) < 1e-9 || fabs(m - 2) < 1e-9 || fabs(m - 5) < 1e-9,
                     "step %g", step);
        double k = (last - first) / step;
        ES_CHECK_MSG(fabs(k - round(k)) < 1e-6 && k >= 1 && k <= 12, "%g steps", k);
        /* the ticks are multiples of the step */
        ES_CHECK(fabs(first / step - round(first / step)) < 1e-6);
    }
    /* the axis hugs the data: -0.11..0.1 was drawn -0.2..0.1 (a third empty) */
    es_plot_nice_ticks(-0.11, 0.1, 6, &first, &last, &step);
    ES_CHECK_MSG(first <= -0.11 && last >= 0.1 && last - first <= 1.25 * 0.21,
                 "[-0.11, 0.1] -> [%g, %g]", first, last);
    es_plot_nice_ticks(NAN, 1, 5, &first, &last, &step);
    ES_CHECK(isfinite(first) && isfinite(last) && step > 0);
}

static void test_colors(void)
{
    double rgb[3], want[3];
    es_colormap_rgb(ES_CMAP_VIRIDIS, 0, rgb);
    want[0] = 0x44 / 255.0, want[1] = 0x01 / 255.0, want[2] = 0x54 / 255.0;
    ES_CHECK(tp_dist(rgb, want) < 1e-12);
    es_colormap_rgb(ES_CMAP_VIRIDIS, 1, rgb);
    want[0] = 0xfd / 255.0, want[1] = 0xe7 / 255.0, want[2] = 0x25 / 255.0;
    ES_CHECK(tp_dist(rgb, want) < 1e-12);
    es_colormap_rgb(ES_CMAP_VIRIDIS, 7, rgb); /* clamped */
    ES_CHECK(tp_dist(rgb, want) < 1e-12);
    /* the diverging map is blue below, near-white in the middle, red above */
    es_colormap_rgb(ES_CMAP_RDBU, 0, rgb);
    ES_CHECK(rgb[2] > rgb[0] + 0.2);
    es_colormap_rgb(ES_CMAP_RDBU, 1, rgb);
    ES_CHECK(rgb[0] > rgb[2] + 0.2);
    es_colormap_rgb(ES_CMAP_RDBU, 0.5, rgb);
    ES_CHECK(rgb[0] > 0.9 && rgb[1] > 0.9 && rgb[2] > 0.9);
    es_colormap_rgb(ES_CMAP_VIRIDIS, NAN, rgb);
    ES_CHECK(rgb[0] == ES_NAN_GREY && rgb[1] == ES_NAN_GREY && rgb[2] == ES_NAN_GREY);
    /* viridis lightness increases monotonically */
    double prev = -1;
    for (int i = 0; i <= 100; i++) {
        es_colormap_rgb(ES_CMAP_VIRIDIS, i / 100.0, rgb);
        double lum = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
        ES_CHECK(lum >= prev - 1e-9);
        prev = lum;
        ES_CHECK(isfinite(rgb[0]) && isfinite(rgb[1]) && isfinite(rgb[2]));
    }
    /* the first palette colours are pairwise distinct */
    for (int i = 0; i < 10; i++)
        for (int j = 0; j < i; j++) {
            double a[3], b[3];
            es_palette_rgb(i, a);
            es_palette_rgb(j, b);
            ES_CHECK(tp_dist(a, b) > 0.1);
        }
}

/* 3 clusters of points with labels; check every point's centre pixel. */
static void test_scatter(es_ctx *ctx)
{
    enum { N = 30 };
    double x[N], y[N];
    const char *labels[N];
    static const char *const groups[3] = {"neutral", "happy", "angry"};
    es_rng rng;
    es_rng_init(&rng, 42);
    for (int i = 0; i < N; i++) {
        int g = i % 3;
        x[i] = 10 * g + 3 * es_rng_normal(&rng);
        y[i] = -5 * g + 2 * es_rng_normal(&rng);
        labels[i] = groups[g];
    }
    es_scatter_spec s;
    es_scatter_spec_init(&s);
    s.n = N;
    s.x = x;
    s.y = y;
    s.labels = labels;
    s.legend_title = "expression";
    s.frame.title = "PC1 vs PC2";
    s.frame.xlabel = "PC1";
    s.frame.ylabel = "PC2";
    s.marker_radius = 4;
    es_plot_info info;
    const char *png = tp_path("plot", "scatter.png");
    ES_CHECK_OK(ctx, es_plot_scatter(ctx, &s, png, &info));
    ES_CHECK(info.n_skipped == 0);
    ES_CHECK(info.left > 0 && info.right < s.frame.width && info.top > 0 &&
             info.bottom < s.frame.height);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        ES_CHECK(im.w == 640 && im.h == 480);
        int ok = 0;
        for (int i = 0; i < N; i++) {
            double px, py, rgb[3], want[3];
            es_plot_info_to_device(&info, x[i], y[i], &px, &py);
            ES_CHECK(px > info.left && px < info.right && py > info.top && py < info.bottom);
            /* a later point may cover this one: check the point drawn last there */
            int top = i;
            for (int j = i + 1; j < N; j++) {
                double qx, qy;
                es_plot_info_to_device(&info, x[j], y[j], &qx, &qy);
                if (hypot(qx - px, qy - py) < 2 * s.marker_radius + 1) top = j;
            }
            es_palette_rgb(top % 3, want);
            tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
            ok += tp_dist(rgb, want) < 0.08;
        }
        ES_CHECK_MSG(ok == N, "%d of %d points found at their pixel", ok, N);
        /* the background far from everything stays white */
        double rgb[3], white[3] = {1, 1, 1};
        tp_rgb(&im, 2, im.h - 2, rgb);
        ES_CHECK(tp_dist(rgb, white) < 1e-9);
        tp_free(&im);
    }
    const char *svg = tp_path("plot", "scatter.svg");
    ES_CHECK_OK(ctx, es_plot_scatter(ctx, &s, svg, NULL));
    ES_CHECK(tp_file_has(svg, "<?xml", "<svg"));
    ES_CHECK(tp_file_size(svg) > 5000);
    const char *pdf = tp_path("plot", "scatter.pdf");
    ES_CHECK_OK(ctx, es_plot_scatter(ctx, &s, pdf, NULL));
    ES_CHECK(tp_file_has(pdf, "%PDF", NULL));

    /* NaN points are skipped and counted; equal aspect keeps one scale */
    x[3] = NAN;
    s.equal_aspect = 1;
    ES_CHECK_OK(ctx, es_plot_scatter(ctx, &s, tp_path("plot", "scatter_equal.png"), &info));
    ES_CHECK(info.n_skipped == 1);
    ES_CHECK_CLOSE((info.xmax - info.xmin) / (info.right - info.left),
                   (info.ymax - info.ymin) / (info.bottom - info.top), 1e-9, 0);

    ES_CHECK_FAILS(ctx, es_plot_scatter(ctx, &s, tp_path("plot", "scatter.bmp"), NULL),
                   ES_EINVAL, "unknown output format");
    ES_CHECK_FAILS(ctx, es_plot_scatter(ctx, &s, "/nonexistent-dir/x.png", NULL), ES_EIO,
                   "/nonexistent-dir/x.png");
    ES_CHECK_FAILS(ctx, es_plot_scatter(ctx, &s, "/nonexistent-dir/x.svg", NULL), ES_EIO,
                   "/nonexistent-dir/x.svg");
    s.x = NULL;
    ES_CHECK_FAILS(ctx, es_plot_scatter(ctx, &s, png, NULL), ES_EINVAL, "coordinates");
}

static void test_scree(es_ctx *ctx)
{
    double var[8] = {5, 2.5, 1.2, 0.6, 0.3, 0.2, 0.1, 0.1};
    es_scree_spec s;
    es_scree_spec_init(&s);
    s.n = 8;
    s.variance = var;
    s.total = 11;
    s.frame.title = "scree";
    es_plot_info info;
    const char *png = tp_path("plot", "scree.png");
    ES_CHECK_OK(ctx, es_plot_scree(ctx, &s, png, &info));
    ES_CHECK(info.ymin == 0 && info.ymax == 100);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        /* inside the first bar, a bit below its top: bar colour */
        double px, py, rgb[3], want[3];
        es_plot_info_to_device(&info, 1, 100 * 5 / 11.0 - 5, &px, &py);
        tp_rgb(&im, (int)px + 4, (int)py, rgb);
        es_palette_rgb(0, want);
        ES_CHECK(tp_dist(rgb, want) < 0.05);
        /* above the bar is not bar colour */
        es_plot_info_to_device(&info, 1, 100 * 5 / 11.0 + 5, &px, &py);
        tp_rgb(&im, (int)px + 4, (int)py, rgb);
        ES_CHECK(tp_dist(rgb, want) > 0.2);
        tp_free(&im);
    }
    const char *svg = tp_path("plot", "scree.svg");
    ES_CHECK_OK(ctx, es_plot_scree(ctx, &s, svg, NULL));
    ES_CHECK(tp_file_has(svg, "<?xml", "<svg") && tp_file_size(svg) > 2000);
    s.total = 3; /* less than the sum */
    ES_CHECK_FAILS(ctx, es_plot_scree(ctx, &s, png, NULL), ES_EINVAL, "total");
    var[2] = -1;
    s.total = 0;
    ES_CHECK_FAILS(ctx, es_plot_scree(ctx, &s, png, NULL), ES_EINVAL, "variance 3");
}

static void test_lines(es_ctx *ctx)
{
    enum { N = 41 };
    double t[N], rms[N], mx[N];
    for (int i = 0; i < N; i++) {
        t[i] = i / (double)(N - 1);
        rms[i] = 1e-3 * (0.05 + sin(M_PI * t[i]));
        mx[i] = 4e-3 * (0.05 + sin(M_PI * t[i]));
    }
    es_series se[2] = {{"RMS relative error", N, t, rms}, {"max relative error", N, t, mx}};
    es_lines_spec s;
    es_lines_spec_init(&s);
    s.nseries = 2;
    s.series = se;
    s.frame.xlabel = "t";
    s.frame.ylabel = "relative edge-length error";
    s.frame.title = "interpolation error";
    es_plot_info info;
    const char *png = tp_path("plot", "lines.png");
    ES_CHECK_OK(ctx, es_plot_lines(ctx, &s, png, &info));
    ES_CHECK(info.xmin <= 0 && info.xmax >= 1 && info.ymax >= 4.2e-3 && info.ymin <= 5e-5);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        double px, py, rgb[3], want[3];
        es_plot_info_to_device(&info, t[N / 2], mx[N / 2], &px, &py);
        es_palette_rgb(1, want);
        tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
        ES_CHECK(tp_dist(rgb, want) < 0.15);
        tp_free(&im);
    }
    s.logy = 1;
    s.markers = 1;
    rms[0] = 0; /* not on a log axis */
    ES_CHECK_OK(ctx, es_plot_lines(ctx, &s, tp_path("plot", "lines_log.svg"), &info));
    ES_CHECK(info.n_skipped == 1 && info.logy);
    ES_CHECK(info.ymin <= 5e-5 && info.ymax >= 4.2e-3);
    ES_CHECK_OK(ctx, es_plot_lines(ctx, &s, tp_path("plot", "lines_log.png"), NULL));
    /* a series of dots only (points_only): its points drawn, nothing between
     * them; the curve beside it still a line */
    {
        static const int dots[2] = {1, 0};
        double xd[2] = {0.2, 0.8}, yd[2] = {2e-3, 2e-3};
        es_series sd[2] = {{"examples", 2, xd, yd}, {"path", N, t, mx}};
        s.logy = 0;
        s.markers = 0;
        s.series = sd;
        s.points_only = dots;
        png = tp_path("plot", "lines_dots.png");
        ES_CHECK_OK(ctx, es_plot_lines(ctx, &s, png, &info));
        ES_CHECK(tp_load(png, &im) == 0);
        if (im.s) {
            double px, py, rgb[3], want[3];
            es_palette_rgb(0, want);
            es_plot_info_to_device(&info, xd[0], yd[0], &px, &py);
            tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
            ES_CHECK_MSG(tp_dist(rgb, want) < 0.15, "no dot at the first example");
            es_plot_info_to_device(&info, 0.5, yd[0], &px, &py);   /* between the dots */
            tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
            ES_CHECK_MSG(tp_dist(rgb, want) > 0.3, "a line between the dots");
            es_palette_rgb(1, want);
            es_plot_info_to_device(&info, t[N / 2], mx[N / 2], &px, &py);
            tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
            ES_CHECK(tp_dist(rgb, want) < 0.15);
            tp_free(&im);
        }
    }
}

/* Long curves: time linear in the points (one cairo path for a whole zig-zag
 * curve took 6 s at 40,000 points and grew with the square), and no gap
 * where the runs it is now stroked in meet: every point of a slow ramp
 * across them is drawn in the curve's colour. */
static void test_long_lines(es_ctx *ctx)
{
    enum { N = 20000 };
    double *x = malloc(N * sizeof *x), *y = malloc(N * sizeof *y), t0, t1;
    struct timespec a, b;
    if (!x || !y) { free(x); free(y); return; }
    for (int i = 0; i < N; i++) {
        x[i] = i;
        y[i] = (i * 2654435761u % 1000) / 1000.0;   /* a zig-zag over the whole plot */
    }
    es_series se = {NULL, N, x, y};
    es_lines_spec s;
    es_lines_spec_init(&s);
    s.nseries = 1;
    s.series = &se;
    clock_gettime(CLOCK_MONOTONIC, &a);
    ES_CHECK_OK(ctx, es_plot_lines(ctx, &s, tp_path("plot", "lines_long.png"), NULL));
    se.n = N / 4;
    clock_gettime(CLOCK_MONOTONIC, &b);
    t1 = (double)(b.tv_sec - a.tv_sec) + 1e-9 * (double)(b.tv_nsec - a.tv_nsec);
    ES_CHECK_OK(ctx, es_plot_lines(ctx, &s, tp_path("plot", "lines_quarter.png"), NULL));
    clock_gettime(CLOCK_MONOTONIC, &a);
    t0 = (double)(a.tv_sec - b.tv_sec) + 1e-9 * (double)(a.tv_nsec - b.tv_nsec);
    ES_CHECK_MSG(t1 < 9 * t0 + 0.5, "%d points in %.2f s, %d in %.2f s", N, t1, N / 4, t0);
    /* a ramp of 2000 points: the runs meet at points 255, 510, ... */
    es_plot_info info;
    se.n = 2000;
    for (int i = 0; i < 2000; i++) y[i] = i / 2000.0;
    const char *png = tp_path("plot", "lines_ramp.png");
    ES_CHECK_OK(ctx, es_plot_lines(ctx, &s, png, &info));
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        double want[3], rgb[3], px, py;
        int off = 0;
        es_palette_rgb(0, want);
        for (int i = 200; i < 1800; i += 5) {
            es_plot_info_to_device(&info, x[i], y[i], &px, &py);
            tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
            off += tp_dist(rgb, want) > 0.25;
        }
        ES_CHECK_MSG(off == 0, "%d points of the ramp are not drawn", off);
        tp_free(&im);
    }
    free(x);
    free(y);
}

static void test_heatmap(es_ctx *ctx)
{
    enum { R = 6, C = 6 };
    double d[R * C];
    const char *names[R] = {"s001", "s002", "s003", "s004", "s005", "s006"};
    for (int j = 0; j < C; j++)
        for (int i = 0; i < R; i++) d[i + j * R] = fabs((double)i - j) + 0.1 * (i + j);
    d[1 + 4 * R] = NAN;
    es_heatmap_spec s;
    es_heatmap_spec_init(&s);
    s.values = (es_mat){d, R, C, R};
    s.row_labels = names;
    s.col_labels = names;
    s.frame.title = "distance matrix";
    s.colorbar_label = "distance";
    es_plot_info info;
    const char *png = tp_path("plot", "heatmap.png");
    ES_CHECK_OK(ctx, es_plot_heatmap(ctx, &s, png, &info));
    ES_CHECK(info.n_skipped == 1);
    double lo = 0, hi = 5 + 0.5;
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        int ok = 0;
        for (int j = 0; j < C; j++)
            for (int i = 0; i < R; i++) {
                double px, py, rgb[3], want[3], v = d[i + j * R];
                es_plot_info_to_device(&info, j + 0.5, R - i - 0.5, &px, &py);
                es_colormap_rgb(ES_CMAP_VIRIDIS, isnan(v) ? NAN : (v - lo) / (hi - lo), want);
                tp_rgb(&im, (int)px, (int)py, rgb);
                ok += tp_dist(rgb, want) < 0.02;
            }
        ES_CHECK_MSG(ok == R * C, "%d of %d cells have their colour", ok, R * C);
        tp_free(&im);
    }
    const char *svg = tp_path("plot", "heatmap.svg");
    ES_CHECK_OK(ctx, es_plot_heatmap(ctx, &s, svg, NULL));
    ES_CHECK(tp_file_has(svg, "<?xml", "<svg") && tp_file_size(svg) > 2000);
    /* a signed matrix with the diverging map: symmetric range */
    for (int k = 0; k < R * C; k++) d[k] = isnan(d[k]) ? 0 : d[k] - 1;
    s.cmap = ES_CMAP_RDBU;
    s.row_labels = s.col_labels = NULL;
    ES_CHECK_OK(ctx, es_plot_heatmap(ctx, &s, tp_path("plot", "heatmap_rdbu.png"), NULL));
    s.values.ld = 2;
    ES_CHECK_FAILS(ctx, es_plot_heatmap(ctx, &s, png, NULL), ES_EINVAL, "matrix");
}

/* The study's distance heat map puts rows and columns in group order: six
 * rows of two interleaved groups, distinct distances, and every cell's
 * pixel checked against the distance of the rows the order says (group,
 * then id): an independent permutation in the test, not the library's. */
static void test_compare_heatmap_order(es_ctx *ctx)
{
    enum { N = 6 };
    double d[N * N];
    const int64_t group[N] = {1, 0, 1, 0, 1, 0};
    const char *ids[N] = {"f", "e", "d", "c", "b", "a"};
    const char *gnames[2] = {"angry", "happy"};
    const int order[N] = {5, 3, 1, 4, 2, 0};   /* group 0 by id a, c, e; group 1 b, d, f */
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            d[i + j * N] = i == j ? 0 : (group[i] != group[j]) + 0.05 * (i + j);
    es_compare_result r;
    memset(&r, 0, sizeof r);
    r.n = N;
    r.d_len = r.d_proc = d;
    r.normalized_lengths = 1;
    es_plot_info info;
    const char *png = tp_path("plot", "compare_heatmap.png");
    ES_CHECK_OK(ctx, es_figure_compare_heatmap(ctx, &r, 0, ids, group, gnames, png, &info));
    double hi = 0;
    for (int k = 0; k < N * N; k++) hi = fmax(hi, d[k]);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        int ok = 0, block_low = 0;
        for (int b = 0; b < N; b++)
            for (int a = 0; a < N; a++) {
                double px, py, rgb[3], want[3], v = d[order[a] + order[b] * N];
                es_plot_info_to_device(&info, b + 0.5, N - a - 0.5, &px, &py);
                es_colormap_rgb(ES_CMAP_VIRIDIS, v / hi, want);
                tp_rgb(&im, (int)px, (int)py, rgb);
                ok += tp_dist(rgb, want) < 0.02;
                block_low += (a < 3) == (b < 3) && v < 1;
            }
        ES_CHECK_MSG(ok == N * N, "%d of %d cells have the colour of the grouped order", ok,
                     N * N);
        ES_CHECK(block_low == 2 * 9);   /* within-group blocks on the diagonal */
        tp_free(&im);
    }
    /* the same matrix without groups: by id alone (a..f is rows 5..0) */
    ES_CHECK_OK(ctx, es_figure_compare_heatmap(ctx, &r, 1, ids, NULL, NULL, png, &info));
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        double px, py, rgb[3], want[3];
        es_plot_info_to_device(&info, 1.5, N - 0.5, &px, &py);   /* row a, column b */
        es_colormap_rgb(ES_CMAP_VIRIDIS, d[5 + 4 * N] / hi, want);
        tp_rgb(&im, (int)px, (int)py, rgb);
        ES_CHECK(tp_dist(rgb, want) < 0.02);
        tp_free(&im);
    }
    /* a heat map's groups must be adjacent runs */
    es_heatmap_spec s;
    es_heatmap_spec_init(&s);
    s.values = (es_mat){d, N, N, N};
    s.row_groups = group;
    ES_CHECK_FAILS(ctx, es_plot_heatmap(ctx, &s, png, NULL), ES_EINVAL, "not adjacent");
}

static void test_histogram(es_ctx *ctx)
{
    enum { N = 500 };
    double v[N];
    es_rng rng;
    es_rng_init(&rng, 7);
    for (int i = 0; i < N; i++) v[i] = es_rng_normal(&rng);
    v[10] = NAN;
    es_histogram_spec s;
    es_histogram_spec_init(&s);
    s.n = N;
    s.values = v;
    s.frame.xlabel = "value";
    s.frame.title = "histogram";
    es_plot_info info;
    const char *png = tp_path("plot", "histogram.png");
    ES_CHECK_OK(ctx, es_plot_histogram(ctx, &s, png, &info));
    ES_CHECK(info.n_skipped == 1);
    ES_CHECK(info.ymax >= 40 && info.ymax <= 200); /* peak of ~N/bins * ... */
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        /* near 0 the bars are tall: the bar colour at a low count there */
        double px, py, rgb[3], want[3];
        es_plot_info_to_device(&info, 0, 5, &px, &py);
        es_palette_rgb(0, want);
        int found = 0;
        for (int dx = -3; dx <= 3; dx++) {
            tp_rgb(&im, (int)px + dx, (int)py, rgb);
            found |= tp_dist(rgb, want) < 0.05;
        }
        ES_CHECK(found);
        tp_free(&im);
    }
    const char *svg = tp_path("plot", "histogram.svg");
    ES_CHECK_OK(ctx, es_plot_histogram(ctx, &s, svg, NULL));
    ES_CHECK(tp_file_has(svg, "<?xml", "<svg") && tp_file_size(svg) > 2000);
    s.nbins = -1;
    ES_CHECK_FAILS(ctx, es_plot_histogram(ctx, &s, png, NULL), ES_EINVAL, "bins");
}


/* Fail the k-th allocation of a scatter and a histogram for k = 1, 2, ...
 * until the call succeeds (ASan reports any leak). */
static void test_alloc_failures(es_ctx *ctx)
{
    double x[4] = {0, 1, 2, 3}, y[4] = {1, 0, 1, 0};
    const char *lab[4] = {"a", "b", "a", "b"};
    es_scatter_spec s;
    es_scatter_spec_init(&s);
    s.n = 4, s.x = x, s.y = y, s.labels = lab;
    es_histogram_spec h;
    es_histogram_spec_init(&h);
    h.n = 4, h.values = x;
    const char *png = tp_path("plot", "alloc.png");
    for (int which = 0; which < 2; which++) {
        es_status rc = ES_ENOMEM;
        int k;
        for (k = 1; k < 20 && rc == ES_ENOMEM; k++) {
            failing_alloc fa = {0, k, 0};
            es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
            es_ctx_set_allocator(ctx, &a);
            rc = which == 0 ? es_plot_scatter(ctx, &s, png, NULL)
                            : es_plot_histogram(ctx, &h, png, NULL);
            es_ctx_set_allocator(ctx, NULL);
            ES_CHECK(rc == ES_OK || rc == ES_ENOMEM);
        }
        ES_CHECK_MSG(rc == ES_OK && k > 2, "plot %d: rc %d after %d tries", which, rc, k);
    }
}

/* ---- es_figure_table: figures of a CSV table ------------------------------ */

enum { TN = 12 };

/* Row i of the test table: x = i, y = 2 (i % 3) + i / 10, var = 10 / (i + 1);
 * row 5 has no PC2 (an empty cell), and a blank line follows row 6. */
static double tx(int i) { return i; }
static double ty(int i) { return 2 * (i % 3) + 0.1 * i; }
static double tvar(int i) { return 10.0 / (i + 1); }
static const char *tgroup(int i) { return i % 3 == 0 ? "neutral" : i % 3 == 1 ? "happy" : "angry"; }

static void write_table(const char *path)
{
    FILE *f = fopen(path, "w");
    ES_CHECK(f != NULL);
    if (!f) return;
    fputs("subject,expression,PC1,PC2,var\n", f);
    for (int i = 0; i < TN; i++) {
        if (i == 5) fprintf(f, "s%03d,%s,%g,,%.17g\n", i, tgroup(i), tx(i), tvar(i));
        else fprintf(f, "s%03d,%s,%g,%.17g,%.17g\n", i, tgroup(i), tx(i), ty(i), tvar(i));
        if (i == 6) fputs("\n", f);
    }
    fclose(f);
}

/* Scatter coloured by category: every point's centre pixel has its group's
 * palette colour (groups in order of first appearance); the missing PC2 is
 * skipped; columns by number draw the same picture as by name. */
static void test_table_scatter(es_ctx *ctx, const char *csv)
{
    char png[4200], png2[4200];
    snprintf(png, sizeof png, "%s", tp_path("plot", "table_scatter.png"));
    snprintf(png2, sizeof png2, "%s", tp_path("plot", "table_scatter_bynumber.png"));
    static const char *const ycol[1] = {"PC2"};
    es_figure_table_spec s;
    es_figure_table_spec_init(&s);
    ES_CHECK(s.kind == ES_TABLE_SCATTER && s.frame.width == 640 && s.frame.height == 480);
    s.x = "PC1";
    s.ny = 1;
    s.y = ycol;
    s.label = "expression";
    es_plot_info info;
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, png, &info));
    ES_CHECK(info.n_skipped == 1);
    ES_CHECK(info.xmin <= 0 && info.xmax >= TN - 1 && info.ymin <= ty(0) && info.ymax >= ty(11));
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        ES_CHECK(im.w == 640 && im.h == 480);
        int ok = 0;
        for (int i = 0; i < TN; i++) {
            if (i == 5) continue;
            double px, py, rgb[3], want[3];
            es_plot_info_to_device(&info, tx(i), ty(i), &px, &py);
            es_palette_rgb(i % 3, want); /* neutral, happy, angry: first seen in that order */
            tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
            ok += tp_dist(rgb, want) < 0.08;
        }
        ES_CHECK_MSG(ok == TN - 1, "%d of %d table points found at their pixel", ok, TN - 1);
        tp_free(&im);
    }
    static const char *const ynum[1] = {"4"};
    s.x = "3";
    s.y = ynum;
    s.label = "2";
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, png2, NULL));
    size_t n1 = 0, n2 = 0;
    char *a = es_test_slurp(png, &n1), *b = es_test_slurp(png2, &n2);
    ES_CHECK_MSG(a && b && n1 == n2 && !memcmp(a, b, n1), "columns by number differ from names");
    free(a);
    free(b);
    const char *svg = tp_path("plot", "table_scatter.svg");
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, svg, NULL));
    ES_CHECK(tp_file_has(svg, "<?xml", "<svg"));
}

/* Lines against PC1 (one series per y column), scree of var, histogram of var. */
static void test_table_lines_scree_hist(es_ctx *ctx, const char *csv)
{
    static const char *const ycols[2] = {"PC2", "var"};
    es_figure_table_spec s;
    es_plot_info info;
    tp_image im;
    double px, py, rgb[3], want[3];
    es_figure_table_spec_init(&s);
    s.kind = ES_TABLE_LINES;
    s.x = "PC1";
    s.ny = 2;
    s.y = ycols;
    const char *png = tp_path("plot", "table_lines.png");
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, png, &info));
    ES_CHECK(info.n_skipped == 1 && !info.logy);
    ES_CHECK(info.ymax >= tvar(0) && info.xmax >= TN - 1);
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        /* the second series' marker at x = 0, far above the first's */
        es_plot_info_to_device(&info, tx(0), tvar(0), &px, &py);
        es_palette_rgb(1, want);
        tp_rgb(&im, (int)floor(px) + 1, (int)floor(py), rgb);
        ES_CHECK_MSG(tp_dist(rgb, want) < 0.15, "lines: %g %g %g", rgb[0], rgb[1], rgb[2]);
        tp_free(&im);
    }
    s.logy = 1;
    s.x = NULL; /* row numbers 1..n */
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, tp_path("plot", "table_lines_log.png"), &info));
    ES_CHECK(info.logy && info.xmin <= 1 && info.xmax >= TN && info.xmax < TN + 3);

    es_figure_table_spec_init(&s);
    s.kind = ES_TABLE_SCREE;
    s.ny = 1;
    s.y = ycols + 1;
    png = tp_path("plot", "table_scree.png");
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, png, &info));
    ES_CHECK(info.ymin == 0 && info.ymax == 100);
    double sum = 0;
    for (int i = 0; i < TN; i++) sum += tvar(i);
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        /* inside the first bar, below its top (10 / sum of the total) */
        es_plot_info_to_device(&info, 1, 100 * tvar(0) / sum - 3, &px, &py);
        tp_rgb(&im, (int)px + 3, (int)py, rgb);
        es_palette_rgb(0, want);
        ES_CHECK(tp_dist(rgb, want) < 0.05);
        tp_free(&im);
    }

    s.kind = ES_TABLE_HISTOGRAM;
    s.bins = 4; /* [0.83, 10] in 4: 10 values in the first bin */
    png = tp_path("plot", "table_histogram.png");
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, png, &info));
    ES_CHECK(info.n_skipped == 0 && info.ymax >= 10);
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        es_plot_info_to_device(&info, 1.5, 5, &px, &py);
        tp_rgb(&im, (int)px, (int)py, rgb);
        es_palette_rgb(0, want);
        ES_CHECK(tp_dist(rgb, want) < 0.05);
        tp_free(&im);
    }
}

/* Heat map with row and column names; a table without a header draws its
 * first two columns as x and y by default. */
static void test_table_heatmap_defaults(es_ctx *ctx)
{
    char dist[4200], nohead[4200];
    snprintf(dist, sizeof dist, "%s", tp_path("plot", "table_dist.csv"));
    snprintf(nohead, sizeof nohead, "%s", tp_path("plot", "table_nohead.csv"));
    es_test_write_file(dist, ",a,b,c\na,0,1,2\nb,1,0,1.5\nc,2,\"1.5\",0\n");
    es_test_write_file(nohead, "1,2\n2,4\n3,9\n");
    static const double d[3][3] = {{0, 1, 2}, {1, 0, 1.5}, {2, 1.5, 0}};
    es_figure_table_spec s;
    es_plot_info info;
    tp_image im;
    es_figure_table_spec_init(&s);
    s.kind = ES_TABLE_HEATMAP;
    const char *png = tp_path("plot", "table_heatmap.png");
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, dist, png, &info));
    ES_CHECK(info.xmin == 0 && info.xmax == 3 && info.ymin == 0 && info.ymax == 3);
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        int ok = 0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double px, py, rgb[3], want[3];
                es_plot_info_to_device(&info, j + 0.5, 3 - i - 0.5, &px, &py);
                es_colormap_rgb(ES_CMAP_VIRIDIS, d[i][j] / 2, want);
                tp_rgb(&im, (int)px, (int)py, rgb);
                ok += tp_dist(rgb, want) < 0.02;
            }
        ES_CHECK_MSG(ok == 9, "%d of 9 table cells have their colour", ok);
        tp_free(&im);
    }
    es_figure_table_spec_init(&s);
    png = tp_path("plot", "table_nohead.png");
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, nohead, png, &info));
    ES_CHECK(info.xmin <= 1 && info.xmax >= 3 && info.ymin <= 2 && info.ymax >= 9);
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        double px, py, rgb[3], want[3];
        es_plot_info_to_device(&info, 2, 4, &px, &py);
        es_palette_rgb(0, want);
        tp_rgb(&im, (int)floor(px), (int)floor(py), rgb);
        ES_CHECK(tp_dist(rgb, want) < 0.08);
        tp_free(&im);
    }
    ES_CHECK(es_figure_table_kind_from_name("heatmap") == ES_TABLE_HEATMAP);
    ES_CHECK(es_figure_table_kind_from_name("scree") == ES_TABLE_SCREE);
    ES_CHECK(es_figure_table_kind_from_name("pie") == -1);
    ES_CHECK(es_colormap_from_name("rdbu") == ES_CMAP_RDBU);
    ES_CHECK(es_colormap_from_name("greys") == ES_CMAP_GREYS);
    ES_CHECK(es_colormap_from_name("jet") == -1 && es_colormap_from_name(NULL) == -1);
}

/* Bad columns, text in numbers, malformed CSV: messages name the file and
 * the line (of the file, past blank lines) and column. */
static void test_table_errors(es_ctx *ctx, const char *csv)
{
    char p[4200], wbuf[4400];
    const char *out = tp_path("plot", "table_error.png"), *want = wbuf;
    static const char *const nope[1] = {"nope"}, *const expr[1] = {"expression"};
    es_figure_table_spec s;
    es_figure_table_spec_init(&s);
    s.ny = 1;
    s.y = nope;
    snprintf(wbuf, sizeof wbuf, "'%s' has no column 'nope'", csv);
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, csv, out, NULL), ES_ENOTFOUND, want);
    s.y = expr;
    snprintf(wbuf, sizeof wbuf, "%s: line 2, column 2: 'neutral' is not a number", csv);
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, csv, out, NULL), ES_EFORMAT, want);
    static const char *const pc2[1] = {"PC2"};
    s.x = "PC1";
    s.y = pc2;
    s.label = "6";   /* one past the last column */
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, csv, out, NULL), ES_ENOTFOUND, "no column '6'");
    s.label = NULL;
    s.x = NULL;
    s.y = NULL;
    s.ny = 0;

    snprintf(p, sizeof p, "%s", tp_path("plot", "table_text.csv"));
    es_test_write_file(p, "a,b\n1,2\n\n3,x\n");
    snprintf(wbuf, sizeof wbuf, "%s: line 4, column 2: 'x' is not a number", p);
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, p, out, NULL), ES_EFORMAT, want);
    es_test_write_file(p, "a,b\n1,2\n3,4\"x\n");
    snprintf(wbuf, sizeof wbuf, "table '%s' line 3: malformed CSV", p);
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, p, out, NULL), ES_EFORMAT, want);
    es_test_write_file(p, "a,b\n1,2\n3,\"4\n5,6\n");
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, p, out, NULL), ES_EFORMAT,
                   "unterminated quoted field (opened on line 3)");
    es_test_write_file(p, "a,b\n");
    snprintf(wbuf, sizeof wbuf, "'%s' has no data rows", p);
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, p, out, NULL), ES_EFORMAT, want);
    es_test_write_file(p, "names\nx\ny\n");
    s.kind = ES_TABLE_HEATMAP;
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, p, out, NULL), ES_EFORMAT, "no numeric columns");
    s.kind = ES_TABLE_SCATTER;
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, "/nonexistent-dir/t.csv", out, NULL), ES_EIO,
                   "cannot open '/nonexistent-dir/t.csv'");
    s.ny = 1; /* y NULL */
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, csv, out, NULL), ES_EINVAL, "y columns");
    s.ny = 0;
    s.kind = (es_table_kind)9;
    ES_CHECK_FAILS(ctx, es_figure_table(ctx, &s, csv, out, NULL), ES_EINVAL, "unknown kind");
}

/* Fail each allocation of a labelled table scatter in turn: ES_ENOMEM,
 * nothing left allocated; the call without failures succeeds. */
static void test_table_alloc_failures(es_ctx *ctx, const char *csv)
{
    static const char *const ycol[1] = {"PC2"};
    es_figure_table_spec s;
    es_figure_table_spec_init(&s);
    s.x = "PC1", s.ny = 1, s.y = ycol, s.label = "expression";
    const char *png = tp_path("plot", "table_alloc.png");
    failing_alloc fa = {0, 0, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    es_ctx_set_allocator(ctx, &a);
    ES_CHECK_OK(ctx, es_figure_table(ctx, &s, csv, png, NULL));
    es_ctx_set_allocator(ctx, NULL);
    int64_t total = fa.count, nomem = 0;
    for (int64_t k = 1; k <= total; k++) {
        failing_alloc fk = {0, k, 0};
        es_allocator ak = {fa_malloc, fa_realloc, fa_free, &fk};
        es_ctx_set_allocator(ctx, &ak);
        es_status rc = es_figure_table(ctx, &s, csv, png, NULL);
        es_ctx_set_allocator(ctx, NULL);
        nomem += rc == ES_ENOMEM;
        ES_CHECK_MSG(rc == ES_ENOMEM, "k %lld: rc %d", (long long)k, rc);
        ES_CHECK_MSG(fk.live == 0, "k %lld: %lld blocks left", (long long)k, (long long)fk.live);
    }
    ES_CHECK_MSG(total > 20 && nomem == total, "%lld of %lld failed allocations reported",
                 (long long)nomem, (long long)total);
}

static void test_table(es_ctx *ctx)
{
    char csv[4200];
    snprintf(csv, sizeof csv, "%s", tp_path("plot", "table.csv"));
    write_table(csv);
    test_table_scatter(ctx, csv);
    test_table_lines_scree_hist(ctx, csv);
    test_table_heatmap_defaults(ctx);
    test_table_errors(ctx, csv);
    test_table_alloc_failures(ctx, csv);
}

static int run(const char *cmd)
{
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* edgespace plot on small CSV tables: every kind writes a valid file; bad
 * columns, kinds and numbers are refused with the documented exit codes. */
static void test_cli(void)
{
    const char *exe = getenv("EDGESPACE");
    char cmd[16384];
    if (!exe) {
        fprintf(stderr, "SKIP (section): EDGESPACE not set, command not tested\n");
        return;
    }
    char pts[4096], dist[4096]; /* tp_path's buffers are reused */
    snprintf(pts, sizeof pts, "%s", tp_path("plot", "cli_points.csv"));
    snprintf(dist, sizeof dist, "%s", tp_path("plot", "cli_dist.csv"));
    FILE *f = fopen(pts, "w"), *g = fopen(dist, "w");
    ES_CHECK(f && g);
    if (!f || !g) return;
    fputs("subject,expression,PC1,PC2,var\n", f);
    for (int i = 0; i < 12; i++)
        fprintf(f, "s%03d,%s,%g,%g,%g\n", i / 3, i % 3 == 0 ? "neutral" : i % 3 == 1 ? "happy" : "angry",
                (double)(i % 3) + 0.1 * i, (double)(i % 2) - 0.05 * i, 10.0 / (i + 1));
    fputs(",a,b,c\na,0,1,2\nb,1,0,1.5\nc,2,1.5,0\n", g);
    fclose(f);
    fclose(g);
    static const char *const jobs[][2] = {
        {"scatter", "--x PC1 --y PC2 --label expression --title 'PC1 vs PC2'"},
        {"lines", "--x PC1 --y PC2,var --logy"},
        {"scree", "--y var"},
        {"histogram", "--y var --bins 5"},
    };
    for (int k = 0; k < 4; k++) {
        for (int fmt = 0; fmt < 2; fmt++) {
            char name[64];
            snprintf(name, sizeof name, "cli_%s.%s", jobs[k][0], fmt ? "svg" : "png");
            const char *out = tp_path("plot", name);
            remove(out);
            snprintf(cmd, sizeof cmd, "'%s' plot %s '%s' -o '%s' %s", exe, jobs[k][0], pts, out,
                     jobs[k][1]);
            ES_CHECK_MSG(run(cmd) == 0, "%s", cmd);
            ES_CHECK_MSG(fmt ? tp_file_has(out, "<?xml", "<svg") : tp_file_has(out, "\x89PNG", NULL),
                         "%s", out);
        }
    }
    const char *hm = tp_path("plot", "cli_heatmap.png");
    snprintf(cmd, sizeof cmd, "'%s' plot heatmap '%s' -o '%s' --cmap rdbu", exe, dist, hm);
    ES_CHECK(run(cmd) == 0);
    ES_CHECK(tp_file_has(hm, "\x89PNG", NULL));
    snprintf(cmd, sizeof cmd, "'%s' plot scatter '%s' -o x.png --x PC1 --y nope 2>/dev/null", exe, pts);
    ES_CHECK(run(cmd) == 1);
    snprintf(cmd, sizeof cmd, "'%s' plot scatter '%s' -o x.png --x PC1 --y expression 2>/dev/null",
             exe, pts);
    ES_CHECK(run(cmd) == 1);
    snprintf(cmd, sizeof cmd, "'%s' plot pie '%s' -o x.png 2>/dev/null", exe, pts);
    ES_CHECK(run(cmd) == 2);
    snprintf(cmd, sizeof cmd, "'%s' plot scatter '%s' 2>/dev/null", exe, pts);
    ES_CHECK(run(cmd) == 2);
    snprintf(cmd, sizeof cmd, "'%s' plot --help >/dev/null", exe);
    ES_CHECK(run(cmd) == 0);
}

/* A figure replaces a file only once complete: written over an old file it
 * replaces it, a figure that fails leaves it, and no part file stays
 * behind in either case. */
static void test_replaced_whole(es_ctx *ctx)
{
    const char *path = tp_path("replace", "fig.svg");
    double x[3] = {0, 1, 2}, y[3] = {1, 0, 2};
    es_scatter_spec sp;
    es_test_write_file(path, "old");
    es_scatter_spec_init(&sp);
    sp.n = 3, sp.x = x, sp.y = y;
    ES_CHECK_OK(ctx, es_plot_scatter(ctx, &sp, path, NULL));
    size_t n = 0;
    char *text = es_test_slurp(path, &n);
    ES_CHECK_MSG(text && n > 100 && strstr(text, "<svg"), "the figure did not replace the file");
    free(text);
    es_test_write_file(path, "old");
    sp.frame.width = 5;   /* refused: too small */
    ES_CHECK_FAILS(ctx, es_plot_scatter(ctx, &sp, path, NULL), ES_EINVAL, "size");
    text = es_test_slurp(path, &n);
    ES_CHECK_MSG(text && n == 3 && !memcmp(text, "old", 3), "a failed figure changed the file");
    free(text);
    char dir[4200];
    snprintf(dir, sizeof dir, "%s", path);
    *strrchr(dir, '/') = 0;
    ES_CHECK_MSG(es_test_count_entries(dir, ".part") == 0, "a part file stayed in %s", dir);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    test_nice_ticks();
    test_colors();
    test_scatter(ctx);
    test_scree(ctx);
    test_lines(ctx);
    test_long_lines(ctx);
    test_heatmap(ctx);
    test_compare_heatmap_order(ctx);
    test_histogram(ctx);
    test_alloc_failures(ctx);
    test_table(ctx);
    test_cli();
    test_replaced_whole(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
