/* lib/figure/plot.c — the figures of es_plot.h: scatter with a categorical legend,
 * scree, line curves, heat map and histogram, drawn with cairo through the
 * canvas of plot_canvas.c.
 *
 * Every figure follows the same steps: check the spec, find the data range,
 * choose nice ticks (Heckbert 1990) that enclose it, lay out the plot area
 * leaving room for a legend or colour bar on the right, draw, and close the
 * canvas (which writes the file). Axis ranges are the loose nice ranges, so
 * the first and last tick sit on the frame.
 *
 * Reference for the histogram bin width: D. Freedman and P. Diaconis, "On
 * the histogram as a density estimator: L2 theory", Z. Wahrscheinlichkeits-
 * theorie verw. Gebiete 57 (1981) 453-476.
 */
#include "figure/figure_pkg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void es__frame_init(es_plot_frame *f)
{
    memset(f, 0, sizeof *f);
    f->width = 640;
    f->height = 480;
    f->font_size = 12;
}

es_status es__frame_check(es_ctx *ctx, const char *what, const es_plot_frame *f)
{
    if (!(f->font_size > 0 && f->font_size < 200))
        ES_FAIL(ctx, ES_EINVAL, "%s: font size %g is outside (0, 200)", what, f->font_size);
    return ES_OK;
}

static void info_clear(es_plot_info *info)
{
    memset(info, 0, sizeof *info);
}

/* ---- scatter --------------------------------------------------------------- */

void es_scatter_spec_init(es_scatter_spec *spec)
{
    memset(spec, 0, sizeof *spec);
    es__frame_init(&spec->frame);
    spec->marker_radius = 4;
}

/* Group index of each point by first appearance of its label; names[g] is
 * borrowed from labels. Returns the number of groups. */
static int64_t group_points(const char *const *labels, int64_t n, int64_t *group,
                            const char **names)
{
    int64_t ng = 0;
    for (int64_t i = 0; i < n; i++) {
        const char *s = labels && labels[i] ? labels[i] : "";
        int64_t g = 0;
        while (g < ng && strcmp(names[g], s) != 0) g++;
        if (g == ng) names[ng++] = s;
        group[i] = g;
    }
    return ng;
}

/* Widen [*lo, *hi] so that units per device unit match `want`. */
static void widen_to(double *lo, double *hi, double units_per_px, double px)
{
    double need = units_per_px * px, have = *hi - *lo;
    if (need > have) {
        *lo -= 0.5 * (need - have);
        *hi += 0.5 * (need - have);
    }
}

es_status es_plot_scatter(es_ctx *ctx, const es_scatter_spec *spec, const char *path,
                          es_plot_info *info_out)
{
    es_status rc;
    es_plot_info info;
    es__canvas cv;
    int64_t *group = NULL, ng = 0;
    const char **names = NULL;
    const es_plot_frame *f = &spec->frame;
    double fs = f->font_size;

    info_clear(&info);
    if ((rc = es__frame_check(ctx, "scatter", f)) != ES_OK) return rc;
    if (spec->n < 0 || (spec->n > 0 && (!spec->x || !spec->y)))
        ES_FAIL(ctx, ES_EINVAL, "scatter: %lld points but no coordinates", (long long)spec->n);
    if (!(spec->marker_radius > 0))
        ES_FAIL(ctx, ES_EINVAL, "scatter: marker radius %g must be positive",
                spec->marker_radius);
    int64_t n = spec->n;
    group = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *group);
    names = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *names);
    if (!group || !names) {
        rc = ES_ENOMEM;
        goto done;
    }
    ng = group_points(spec->labels, n, group, names);

    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int64_t i = 0; i < n; i++) {
        if (!isfinite(spec->x[i]) || !isfinite(spec->y[i])) {
            info.n_skipped++;
            continue;
        }
        x0 = fmin(x0, spec->x[i]);
        x1 = fmax(x1, spec->x[i]);
        y0 = fmin(y0, spec->y[i]);
        y1 = fmax(y1, spec->y[i]);
    }
    if (x0 > x1) x0 = x1 = y0 = y1 = 0;
    /* pad by 4% so markers do not sit on the frame */
    double px_ = 0.04 * (x1 - x0), py_ = 0.04 * (y1 - y0);
    x0 -= px_, x1 += px_, y0 -= py_, y1 += py_;

    if ((rc = es__canvas_open(ctx, path, f->width, f->height, &cv)) != ES_OK) goto done;
    bool legend = spec->labels && ng > 0;
    double lw = legend ? es__legend_width(cv.cr, spec->legend_title, names, ng, fs) + fs : 0;
    es__plot_area(f, lw, 0, &info);
    if (spec->equal_aspect) {
        double w = info.right - info.left, h = info.bottom - info.top;
        double u = fmax((x1 - x0) / w, (y1 - y0) / h);
        widen_to(&x0, &x1, u, w);
        widen_to(&y0, &y1, u, h);
    }
    es__ticks xt, yt;
    es__ticks_nice(x0, x1, 6, 0, &xt);
    es__ticks_nice(y0, y1, 6, 0, &yt);
    info.xmin = xt.lo;
    info.xmax = xt.hi;
    info.ymin = yt.lo;
    info.ymax = yt.hi;
    if (spec->equal_aspect) {
        /* the nice ranges differ in scale; re-widen them to one scale */
        double w = info.right - info.left, h = info.bottom - info.top;
        double u = fmax((info.xmax - info.xmin) / w, (info.ymax - info.ymin) / h);
        widen_to(&info.xmin, &info.xmax, u, w);
        widen_to(&info.ymin, &info.ymax, u, h);
    }
    es__draw_axes(cv.cr, f, &info, &xt, &yt, 1);

    cairo_t *cr = cv.cr;
    cairo_save(cr);
    cairo_rectangle(cr, info.left, info.top, info.right - info.left, info.bottom - info.top);
    cairo_clip(cr);
    cairo_set_line_width(cr, 0.75);
    for (int64_t i = 0; i < n; i++) {
        double px, py, rgb[3];
        if (!isfinite(spec->x[i]) || !isfinite(spec->y[i])) continue;
        es_plot_info_to_device(&info, spec->x[i], spec->y[i], &px, &py);
        es_palette_rgb(group[i], rgb);
        cairo_new_sub_path(cr);
        cairo_arc(cr, px, py, spec->marker_radius, 0, 2 * M_PI);
        cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
        cairo_fill_preserve(cr);
        cairo_set_source_rgb(cr, 0.6 * rgb[0], 0.6 * rgb[1], 0.6 * rgb[2]);
        cairo_stroke(cr);
    }
    cairo_restore(cr);
    if (legend)
        es__draw_legend(cr, info.right + fs, info.top, spec->legend_title, names, ng, 0, NULL, fs);
    rc = es__canvas_close(ctx, &cv);
done:
    es__free(ctx, group);
    es__free(ctx, names);
    if (info_out) *info_out = info;
    return rc;
}

/* ---- scree ----------------------------------------------------------------- */

void es_scree_spec_init(es_scree_spec *spec)
{
    memset(spec, 0, sizeof *spec);
    es__frame_init(&spec->frame);
    spec->frame.xlabel = "component";
    spec->frame.ylabel = "explained variance (%)";
}

es_status es_plot_scree(es_ctx *ctx, const es_scree_spec *spec, const char *path,
                        es_plot_info *info_out)
{
    es_status rc;
    es_plot_info info;
    es__canvas cv;
    const es_plot_frame *f = &spec->frame;
    double fs = f->font_size, total = spec->total, sum = 0;

    info_clear(&info);
    if (info_out) *info_out = info;
    if ((rc = es__frame_check(ctx, "scree", f)) != ES_OK) return rc;
    if (spec->n <= 0 || !spec->variance)
        ES_FAIL(ctx, ES_EINVAL, "scree: need at least one variance (n = %lld)",
                (long long)spec->n);
    for (int64_t i = 0; i < spec->n; i++) {
        if (!isfinite(spec->variance[i]) || spec->variance[i] < 0)
            ES_FAIL(ctx, ES_EINVAL, "scree: variance %lld is %g (must be finite, >= 0)",
                    (long long)i + 1, spec->variance[i]);
        sum += spec->variance[i];
    }
    if (total == 0) total = sum;
    if (!(total > 0) || total < sum * (1 - 1e-12))
        ES_FAIL(ctx, ES_EINVAL, "scree: total variance %g is below the sum shown %g",
                spec->total, sum);

    if ((rc = es__canvas_open(ctx, path, f->width, f->height, &cv)) != ES_OK) return rc;
    cairo_t *cr = cv.cr;
    static const char *const names[] = {"per component", "cumulative"};
    double lw = es__legend_width(cr, NULL, names, 2, fs) + fs;
    es__plot_area(f, lw, 0, &info);
    es__ticks xt, yt;
    es__ticks_nice(1, (double)spec->n, 10, 1, &xt);
    /* only ticks on components */
    int k = 0;
    for (int i = 0; i < xt.n; i++)
        if (xt.v[i] >= 1 && xt.v[i] <= (double)spec->n) xt.v[k++] = xt.v[i];
    xt.n = k;
    xt.decimals = 0;
    es__ticks_nice(0, 100, 6, 0, &yt);
    info.xmin = 0.4;
    info.xmax = (double)spec->n + 0.6;
    info.ymin = 0;
    info.ymax = 100;
    es__draw_axes(cr, f, &info, &xt, &yt, 1);

    double rgb[3], cum = 0, px, py, qx, qy;
    es_palette_rgb(0, rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    for (int64_t i = 0; i < spec->n; i++) {
        double pct = 100 * spec->variance[i] / total;
        es_plot_info_to_device(&info, (double)i + 1 - 0.35, pct, &px, &py);
        es_plot_info_to_device(&info, (double)i + 1 + 0.35, 0, &qx, &qy);
        cairo_rectangle(cr, px, py, qx - px, qy - py);
    }
    cairo_fill(cr);
    es_palette_rgb(1, rgb);
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_set_line_width(cr, 2);
    for (int64_t i = 0; i < spec->n; i++) {
        cum += 100 * spec->variance[i] / total;
        es_plot_info_to_device(&info, (double)i + 1, fmin(cum, 100), &px, &py);
        cairo_line_to(cr, px, py);
    }
    cairo_stroke(cr);
    cum = 0;
    for (int64_t i = 0; i < spec->n; i++) {
        cum += 100 * spec->variance[i] / total;
        es_plot_info_to_device(&info, (double)i + 1, fmin(cum, 100), &px, &py);
        cairo_new_sub_path(cr);
        cairo_arc(cr, px, py, 3, 0, 2 * M_PI);
    }
    cairo_fill(cr);
    static const int styles[2] = {2, 1};
    es__draw_legend(cr, info.right + fs, info.top, NULL, names, 2, 1, styles, fs);
    rc = es__canvas_close(ctx, &cv);
    if (info_out) *info_out = info;
    return rc;
}

/* ---- lines ----------------------------------------------------------------- */

void es_lines_spec_init(es_lines_spec *spec)
{
    memset(spec, 0, sizeof *spec);
    es__frame_init(&spec->frame);
}

es_status es_plot_lines(es_ctx *ctx, const es_lines_spec *spec, const char *path,
                        es_plot_info *info_out)
{
    es_status rc;
    es_plot_info info;
    es__canvas cv;
    const es_plot_frame *f = &spec->frame;
    double fs = f->font_size;
    const char **names = NULL;
    int *styles = NULL;

    info_clear(&info);
    if (info_out) *info_out = info;
    if ((rc = es__frame_check(ctx, "lines", f)) != ES_OK) return rc;
    if (spec->nseries < 0 || (spec->nseries > 0 && !spec->series))
        ES_FAIL(ctx, ES_EINVAL, "lines: %lld series but no array", (long long)spec->nseries);
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    bool any_name = false;
    for (int64_t s = 0; s < spec->nseries; s++) {
        const es_series *se = &spec->series[s];
        if (se->n < 0 || (se->n > 0 && (!se->x || !se->y)))
            ES_FAIL(ctx, ES_EINVAL, "lines: series %lld has %lld points but no data",
                    (long long)s, (long long)se->n);
        any_name |= se->name != NULL;
        for (int64_t i = 0; i < se->n; i++) {
            if (!isfinite(se->x[i]) || !isfinite(se->y[i]) || (spec->logy && se->y[i] <= 0)) {
                info.n_skipped++;
                continue;
            }
            x0 = fmin(x0, se->x[i]);
            x1 = fmax(x1, se->x[i]);
            y0 = fmin(y0, se->y[i]);
            y1 = fmax(y1, se->y[i]);
        }
    }
    if (x0 > x1) {
        x0 = 0, x1 = 1;
        y0 = spec->logy ? 1 : 0, y1 = spec->logy ? 10 : 1;
    }
    names = es__alloc_array(ctx, spec->nseries > 0 ? spec->nseries : 1, sizeof *names);
    styles = es__alloc_array(ctx, spec->nseries > 0 ? spec->nseries : 1, sizeof *styles);
    if (!names || !styles) {
        es__free(ctx, names);
        es__free(ctx, styles);
        return ES_ENOMEM;
    }
    for (int64_t s = 0; s < spec->nseries; s++) {
        names[s] = spec->series[s].name;
        /* legend keys: a dot for a scatter, a line segment for a curve */
        styles[s] = !(spec->points_only && spec->points_only[s]);
    }

    if ((rc = es__canvas_open(ctx, path, f->width, f->height, &cv)) != ES_OK) goto done;
    cairo_t *cr = cv.cr;
    double lw = any_name ? es__legend_width(cr, NULL, names, spec->nseries, fs) + fs : 0;
    es__plot_area(f, lw, 0, &info);
    es__ticks xt, yt;
    es__ticks_nice(x0, x1, 6, 0, &xt);
    info.xmin = xt.lo;
    info.xmax = xt.hi;
    if (spec->logy) {
        es__ticks_log(y0, y1, &yt);
        info.logy = 1;
        info.ymin = pow(10, yt.lo);
        info.ymax = pow(10, yt.hi);
    } else {
        double pad = 0.03 * (y1 - y0);
        es__ticks_nice(y0 - pad, y1 + pad, 6, 0, &yt);
        info.ymin = yt.lo;
        info.ymax = yt.hi;
    }
    es__draw_axes(cr, f, &info, &xt, &yt, 1);
    cairo_save(cr);
    cairo_rectangle(cr, info.left, info.top, info.right - info.left, info.bottom - info.top);
    cairo_clip(cr);
    cairo_set_line_width(cr, 2);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (int64_t s = 0; s < spec->nseries; s++) {
        const es_series *se = &spec->series[s];
        double rgb[3], px, py;
        es_palette_rgb(s, rgb);
        cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
        int dots = spec->points_only && spec->points_only[s];
        cairo_new_path(cr);
        int64_t run = 0;   /* segments in the path being built */
        for (int64_t i = 0; !dots && i < se->n; i++) {
            if (!isfinite(se->x[i]) || !isfinite(se->y[i]) || (spec->logy && se->y[i] <= 0)) {
                cairo_stroke(cr); /* a gap, not a jump across missing values */
                run = 0;
                continue;
            }
            es_plot_info_to_device(&info, se->x[i], se->y[i], &px, &py);
            cairo_line_to(cr, px, py);
            /* cairo strokes one path as one polygon whose self-crossings it
             * resolves pairwise: 40,000 zig-zag points took seconds, growing
             * with the square. Stroked in runs of 256 segments, with a dot
             * of the line's width where two runs meet (what the round join
             * would have drawn), it is linear. */
            if (++run == 256) {
                cairo_stroke(cr);
                cairo_arc(cr, px, py, 1, 0, 2 * M_PI);
                cairo_fill(cr);
                cairo_move_to(cr, px, py);
                run = 1;
            }
        }
        cairo_stroke(cr);
        if (spec->markers || dots) {
            for (int64_t i = 0; i < se->n; i++) {
                if (!isfinite(se->x[i]) || !isfinite(se->y[i]) || (spec->logy && se->y[i] <= 0))
                    continue;
                es_plot_info_to_device(&info, se->x[i], se->y[i], &px, &py);
                cairo_new_sub_path(cr);
                cairo_arc(cr, px, py, 3, 0, 2 * M_PI);
            }
            cairo_fill(cr);
        }
    }
    cairo_restore(cr);
    if (any_name) es__draw_legend(cr, info.right + fs, info.top, NULL, names, spec->nseries, 1,
                                  styles, fs);
    rc = es__canvas_close(ctx, &cv);
done:
    es__free(ctx, names);
    es__free(ctx, styles);
    if (info_out) *info_out = info;
    return rc;
}

/* ---- histogram ------------------------------------------------------------- */

void es_histogram_spec_init(es_histogram_spec *spec)
{
    memset(spec, 0, sizeof *spec);
    es__frame_init(&spec->frame);
    spec->frame.ylabel = "count";
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

es_status es_plot_histogram(es_ctx *ctx, const es_histogram_spec *spec, const char *path,
                            es_plot_info *info_out)
{
    es_status rc = ES_OK;
    es_plot_info info;
    es__canvas cv;
    const es_plot_frame *f = &spec->frame;
    double *sorted = NULL;
    int64_t *count = NULL, nf = 0, nbins = spec->nbins;

    info_clear(&info);
    if (info_out) *info_out = info;
    if ((rc = es__frame_check(ctx, "histogram", f)) != ES_OK) return rc;
    if (spec->n < 0 || (spec->n > 0 && !spec->values))
        ES_FAIL(ctx, ES_EINVAL, "histogram: %lld values but no data", (long long)spec->n);
    if (nbins < 0 || nbins > 10000)
        ES_FAIL(ctx, ES_EINVAL, "histogram: %lld bins is outside 0..10000", (long long)nbins);
    sorted = es__alloc_array(ctx, spec->n > 0 ? spec->n : 1, sizeof *sorted);
    if (!sorted) return ES_ENOMEM;
    for (int64_t i = 0; i < spec->n; i++)
        if (isfinite(spec->values[i])) sorted[nf++] = spec->values[i];
    info.n_skipped = spec->n - nf;
    qsort(sorted, (size_t)nf, sizeof *sorted, cmp_double);
    double lo = spec->lo, hi = spec->hi;
    if (lo == hi) {
        lo = nf ? sorted[0] : 0;
        hi = nf ? sorted[nf - 1] : 1;
    }
    if (lo > hi) {
        double s = lo;
        lo = hi, hi = s;
    }
    if (lo == hi) lo -= 0.5, hi += 0.5;
    if (nbins == 0) {
        double iqr = nf >= 4 ? sorted[(3 * nf) / 4] - sorted[nf / 4] : 0;
        if (iqr > 0) nbins = (int64_t)ceil((hi - lo) / (2 * iqr * pow((double)nf, -1.0 / 3)));
        else nbins = (int64_t)ceil(log2((double)(nf > 1 ? nf : 1))) + 1; /* Sturges */
        nbins = nbins < 5 ? 5 : nbins > 100 ? 100 : nbins;
    }
    count = es__calloc(ctx, (size_t)nbins, sizeof *count);
    if (!count) {
        rc = ES_ENOMEM;
        goto done;
    }
    int64_t cmax = 0;
    for (int64_t i = 0; i < nf; i++) {
        double v = sorted[i];
        if (v < lo || v > hi) continue;
        int64_t b = (int64_t)floor((v - lo) / (hi - lo) * (double)nbins);
        if (b >= nbins) b = nbins - 1; /* hi itself goes in the last bin */
        if (++count[b] > cmax) cmax = count[b];
    }

    if ((rc = es__canvas_open(ctx, path, f->width, f->height, &cv)) != ES_OK) goto done;
    cairo_t *cr = cv.cr;
    es__plot_area(f, 0, 0, &info);
    es__ticks xt, yt;
    es__ticks_nice(lo, hi, 6, 0, &xt);
    es__ticks_nice(0, cmax > 0 ? (double)cmax * 1.05 : 1, 6, 1, &yt);
    info.xmin = xt.lo;
    info.xmax = xt.hi;
    info.ymin = 0;
    info.ymax = yt.hi;
    es__draw_axes(cr, f, &info, &xt, &yt, 1);
    double rgb[3], px, py, qx, qy, bw = (hi - lo) / (double)nbins;
    es_palette_rgb(0, rgb);
    for (int64_t b = 0; b < nbins; b++) {
        if (!count[b]) continue;
        es_plot_info_to_device(&info, lo + (double)b * bw, (double)count[b], &px, &py);
        es_plot_info_to_device(&info, lo + (double)(b + 1) * bw, 0, &qx, &qy);
        cairo_rectangle(cr, px, py, qx - px, qy - py);
        cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
        cairo_fill_preserve(cr);
        cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_set_line_width(cr, 0.75);
        cairo_stroke(cr);
    }
    rc = es__canvas_close(ctx, &cv);
done:
    es__free(ctx, sorted);
    es__free(ctx, count);
    if (info_out) *info_out = info;
    return rc;
}
