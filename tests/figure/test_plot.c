/* tests/figure/test_plot.c — the figures of es_plot.h: nice ticks, colour maps,
 * valid PNG/SVG/PDF output of every plot kind, scatter points and heat-map
 * cells where the returned es_plot_info says they are, error paths. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "test_images.h"

#include <edgespace/es_plot.h>
#include <sys/wait.h>

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
    test_heatmap(ctx);
    test_histogram(ctx);
    test_alloc_failures(ctx);
    test_cli();
    es_ctx_free(ctx);
    ES_TEST_END();
}
