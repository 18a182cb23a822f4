/* lib/figure/heatmap.c — the heat map of es_plot.h: a matrix as coloured
 * cells with row and column labels, groups of adjacent rows and columns
 * (separators and names), and a colour bar.
 *
 * Cells are vector rectangles so that a distance matrix stays sharp when a
 * PDF or SVG is zoomed (an image scaled up is smoothed by most SVG viewers,
 * whatever filter cairo asks for); above VECTOR_CELLS cells one image is
 * drawn instead, since a file with millions of rectangles opens slowly.
 */
#include "figure/figure_pkg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define VECTOR_CELLS (512 * 512)

void es_heatmap_spec_init(es_heatmap_spec *spec)
{
    memset(spec, 0, sizeof *spec);
    es__frame_init(&spec->frame);
    spec->cmap = ES_CMAP_VIRIDIS;
}

static double max_label_width(cairo_t *cr, const char *const *labels, int64_t n, double size)
{
    double w = 0;
    for (int64_t i = 0; labels && i < n; i++) w = fmax(w, es__text_width(cr, labels[i], size));
    return w;
}

/* Name of group g (the given one, or its 1-based number in buf). */
static const char *group_name(const es_heatmap_spec *spec, int64_t g, char *buf, size_t n)
{
    if (spec->group_names) return spec->group_names[g];
    snprintf(buf, n, "%lld", (long long)g + 1);
    return buf;
}

/* Widest group name among groups[0..n). */
static double max_group_width(cairo_t *cr, const es_heatmap_spec *spec, const int64_t *groups,
                              int64_t n, double size)
{
    char buf[32];
    double w = 0;
    for (int64_t i = 0; groups && i < n; i++)
        if (i == 0 || groups[i] != groups[i - 1])
            w = fmax(w, es__text_width(cr, group_name(spec, groups[i], buf, sizeof buf), size));
    return w;
}

static es_status check_groups(es_ctx *ctx, const int64_t *groups, int64_t n, const char *what)
{
    for (int64_t i = 0; groups && i < n; i++) {
        if (groups[i] < 0)
            ES_FAIL(ctx, ES_EINVAL, "heatmap: %s %lld has a negative group %lld", what,
                    (long long)i, (long long)groups[i]);
        for (int64_t j = 0; i > 0 && groups[i] != groups[i - 1] && j < i - 1; j++)
            if (groups[j] == groups[i])
                ES_FAIL(ctx, ES_EINVAL, "heatmap: the %ss of group %lld are not adjacent "
                        "(%s %lld and %lld); sort them by group first", what,
                        (long long)groups[i], what, (long long)j, (long long)i);
    }
    return ES_OK;
}

static void cell_rgb(const es_heatmap_spec *spec, double v, double vmin, double vmax,
                     double rgb[3])
{
    es_colormap_rgb(spec->cmap, isfinite(v) ? (v - vmin) / (vmax - vmin) : NAN, rgb);
}

/* The cells as rectangles, without antialiasing so that neighbours leave no
 * seam in a PNG; cell (i, j) covers [j, j+1] x [i, i+1] in user space. */
static void draw_cells_vector(cairo_t *cr, const es_heatmap_spec *spec, double vmin,
                              double vmax)
{
    const es_mat *m = &spec->values;
    cairo_save(cr);
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    for (int64_t i = 0; i < m->rows; i++)
        for (int64_t j = 0; j < m->cols; j++) {
            double rgb[3];
            cell_rgb(spec, ES_AT(*m, i, j), vmin, vmax, rgb);
            cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
            cairo_rectangle(cr, (double)j, (double)i, 1, 1);
            cairo_fill(cr);
        }
    cairo_restore(cr);
}

/* The cells as one image of a pixel per cell, scaled with nearest-neighbour
 * filtering (large matrices). */
static es_status draw_cells_image(es_ctx *ctx, cairo_t *cr, const es_heatmap_spec *spec,
                                  double vmin, double vmax)
{
    const es_mat *m = &spec->values;
    int rows = (int)m->rows, cols = (int)m->cols;
    cairo_surface_t *img = cairo_image_surface_create(CAIRO_FORMAT_RGB24, cols, rows);
    if (cairo_surface_status(img) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(img);
        ES_FAIL(ctx, ES_ENOMEM, "heatmap: cannot allocate a %d x %d image", cols, rows);
    }
    unsigned char *px = cairo_image_surface_get_data(img);
    int stride = cairo_image_surface_get_stride(img);
    for (int i = 0; i < rows; i++) {
        uint32_t *row = (uint32_t *)(void *)(px + (size_t)i * (size_t)stride);
        for (int j = 0; j < cols; j++) {
            double rgb[3];
            cell_rgb(spec, ES_AT(*m, i, j), vmin, vmax, rgb);
            row[j] = (uint32_t)lrint(rgb[0] * 255) << 16 | (uint32_t)lrint(rgb[1] * 255) << 8 |
                     (uint32_t)lrint(rgb[2] * 255);
        }
    }
    cairo_surface_mark_dirty(img);
    cairo_set_source_surface(cr, img, 0, 0);
    cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
    cairo_rectangle(cr, 0, 0, cols, rows);
    cairo_fill(cr);
    cairo_surface_destroy(img);
    return ES_OK;
}

/* White lines between runs of groups, across the whole matrix. */
static void draw_separators(cairo_t *cr, const es_plot_info *info, const int64_t *groups,
                            int64_t n, double step, int vertical)
{
    cairo_save(cr);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_set_line_width(cr, 1.5);
    for (int64_t i = 1; groups && i < n; i++) {
        if (groups[i] == groups[i - 1]) continue;
        double at = (vertical ? info->left : info->top) + (double)i * step;
        if (vertical) {
            cairo_move_to(cr, at, info->top);
            cairo_line_to(cr, at, info->bottom);
        } else {
            cairo_move_to(cr, info->left, at);
            cairo_line_to(cr, info->right, at);
        }
        cairo_stroke(cr);
    }
    cairo_restore(cr);
}

/* Each run's name beside it: rows (vertical 0) right-aligned at x = at with
 * a bracket spanning the run; columns centred above y = at where the name
 * fits the run's width. A name that would overlap the previous one is
 * left out. */
static void draw_group_names(cairo_t *cr, const es_heatmap_spec *spec, const es_plot_info *info,
                             const int64_t *groups, int64_t n, double step, int columns,
                             double at, double size)
{
    char buf[32];
    double last_end = -INFINITY;
    cairo_save(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    for (int64_t a = 0, b; groups && a < n; a = b) {
        for (b = a + 1; b < n && groups[b] == groups[a];) b++;
        const char *s = group_name(spec, groups[a], buf, sizeof buf);
        double lo = (double)a * step, hi = (double)b * step, mid = 0.5 * (lo + hi);
        if (columns) {
            double w = es__text_width(cr, s, size), x = info->left + mid;
            if (w > hi - lo || x - 0.5 * w < last_end) continue;
            es__text(cr, x, at, s, size, 0.5, 1, 0);
            last_end = x + 0.5 * w + 0.3 * size;
        } else {
            double y = info->top + mid;
            cairo_move_to(cr, at + 0.3 * size, info->top + lo + 1);
            cairo_line_to(cr, at + 0.3 * size, info->top + hi - 1);
            cairo_stroke(cr);
            if (y - 0.5 * size < last_end) continue;
            es__text(cr, at, y, s, size, 1, 0.5, 0);
            last_end = y + 0.6 * size;
        }
    }
    cairo_restore(cr);
}

es_status es_plot_heatmap(es_ctx *ctx, const es_heatmap_spec *spec, const char *path,
                          es_plot_info *info_out)
{
    es_status rc;
    es_plot_info info;
    es__canvas cv;
    const es_plot_frame *f = &spec->frame;
    const es_mat *m = &spec->values;
    double fs = f->font_size, vmin = spec->vmin, vmax = spec->vmax;

    memset(&info, 0, sizeof info);
    if (info_out) *info_out = info;
    if ((rc = es__frame_check(ctx, "heatmap", f)) != ES_OK) return rc;
    if (m->rows <= 0 || m->cols <= 0 || !m->data || m->ld < m->rows)
        ES_FAIL(ctx, ES_EINVAL, "heatmap: bad matrix %lld x %lld (ld %lld)",
                (long long)m->rows, (long long)m->cols, (long long)m->ld);
    if (m->rows > 16384 || m->cols > 16384)
        ES_FAIL(ctx, ES_ERANGE, "heatmap: matrix %lld x %lld is larger than 16384 x 16384",
                (long long)m->rows, (long long)m->cols);
    if ((rc = check_groups(ctx, spec->row_groups, m->rows, "row")) != ES_OK ||
        (rc = check_groups(ctx, spec->col_groups, m->cols, "column")) != ES_OK)
        return rc;
    int64_t rows = m->rows, cols = m->cols;
    if (vmin == vmax || !isfinite(vmin) || !isfinite(vmax)) {
        double lo = INFINITY, hi = -INFINITY;
        for (int64_t j = 0; j < cols; j++)
            for (int64_t i = 0; i < rows; i++) {
                double v = ES_AT(*m, i, j);
                if (isfinite(v)) lo = fmin(lo, v), hi = fmax(hi, v);
            }
        double pair[2] = {lo, hi};
        vmin = vmax = 0;
        es__color_range(spec->cmap, pair, lo <= hi ? 2 : 0, &vmin, &vmax);
    } else {
        es__color_range(spec->cmap, NULL, 0, &vmin, &vmax);
    }
    for (int64_t j = 0; j < cols; j++)
        for (int64_t i = 0; i < rows; i++) info.n_skipped += !isfinite(ES_AT(*m, i, j));

    if ((rc = es__canvas_open(ctx, path, f->width, f->height, &cv)) != ES_OK) return rc;
    cairo_t *cr = cv.cr;
    double lsize = 0.8 * fs;
    double rlw = spec->row_labels ? max_label_width(cr, spec->row_labels, rows, lsize) + 4 : 0;
    double clw = max_label_width(cr, spec->col_labels, cols, lsize);
    double rgw = spec->row_groups
                     ? max_group_width(cr, spec, spec->row_groups, rows, lsize) + 0.8 * lsize
                     : 0;
    double band = spec->col_groups ? 1.4 * lsize : 0;   /* column group names */
    double cbw = es__colorbar_width(cr, fs, vmin, vmax, spec->colorbar_label, fs, 0) + fs;
    es_plot_frame g = *f;
    g.height = f->height - (int)(spec->col_labels ? clw : 0) - (int)band;
    es__plot_area(&g, cbw, rlw + rgw, &info);
    info.top += band;
    info.bottom += band;
    info.xmin = 0;
    info.xmax = (double)cols;
    info.ymin = 0;
    info.ymax = (double)rows;
    double w = info.right - info.left, h = info.bottom - info.top;
    /* square cells unless the matrix is very elongated */
    if ((double)rows / (double)cols >= 0.25 && (double)rows / (double)cols <= 4) {
        double cell = fmin(w / (double)cols, h / (double)rows);
        w = cell * (double)cols;
        h = cell * (double)rows;
        info.right = info.left + w;
        info.bottom = info.top + h;
    }
    double cw = w / (double)cols, ch = h / (double)rows;

    cairo_save(cr);
    cairo_translate(cr, info.left, info.top);
    cairo_scale(cr, cw, ch);
    if (rows * cols <= VECTOR_CELLS) draw_cells_vector(cr, spec, vmin, vmax);
    else rc = draw_cells_image(ctx, cr, spec, vmin, vmax);
    cairo_restore(cr);
    if (rc != ES_OK) {
        es__canvas_discard(&cv);
        return rc;
    }
    draw_separators(cr, &info, spec->row_groups, rows, ch, 0);
    draw_separators(cr, &info, spec->col_groups, cols, cw, 1);

    /* labels: every k-th so that they never overlap */
    cairo_set_source_rgb(cr, 0, 0, 0);
    int64_t kr = (int64_t)ceil(1.1 * lsize / ch), kc = (int64_t)ceil(1.1 * lsize / cw);
    for (int64_t i = 0; spec->row_labels && i < rows; i += kr)
        es__text(cr, info.left - 4, info.top + ((double)i + 0.5) * ch, spec->row_labels[i],
                 lsize, 1, 0.5, 0);
    for (int64_t j = 0; spec->col_labels && j < cols; j += kc)
        es__text(cr, info.left + ((double)j + 0.5) * cw, info.bottom + 4, spec->col_labels[j],
                 lsize, 1, 0.5, -M_PI / 2);
    draw_group_names(cr, spec, &info, spec->row_groups, rows, ch, 0,
                     info.left - rlw - 0.8 * lsize, lsize);
    draw_group_names(cr, spec, &info, spec->col_groups, cols, cw, 1, info.top - 0.2 * lsize,
                     lsize);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, info.left, info.top, w, h);
    cairo_stroke(cr);
    es_plot_frame labels_only = *f;
    labels_only.height = f->height;
    es__draw_axes(cr, &labels_only, &info, NULL, NULL, 0);
    es__draw_colorbar(cr, info.right + fs, info.top, fs, h, spec->cmap, vmin, vmax,
                      spec->colorbar_label, fs, 0);
    rc = es__canvas_close(ctx, &cv);
    if (info_out) *info_out = info;
    return rc;
}
