/* lib/figure/plot_canvas.c — the drawing layer under es_plot.h and es_render.h:
 * cairo surfaces chosen by file extension (PNG through an image surface and
 * cairo_surface_write_to_png, SVG and PDF through cairo's vector surfaces),
 * colour maps, the categorical palette, nice ticks, axes, legends and
 * colour bars.
 *
 * References: P. Heckbert, "Nice numbers for graph labels", Graphics Gems
 * (1990) 61-63 (loose labelling). Viridis: van der Walt & Smith, matplotlib
 * (2015), sampled at 11 points and interpolated linearly in sRGB. RdBu:
 * ColorBrewer (Brewer 2002), 11 classes, reversed so that low is blue.
 * Tableau 10 (Stone, Tableau 2016) for categories.
 */
#include "figure/figure_pkg.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* ---- colour -------------------------------------------------------------- */

static const unsigned viridis11[11] = {
    0x440154, 0x482475, 0x414487, 0x355f8d, 0x2a788e, 0x21918c,
    0x22a884, 0x44bf70, 0x7ad151, 0xbddf26, 0xfde725};
static const unsigned rdbu11_rev[11] = {
    0x053061, 0x2166ac, 0x4393c3, 0x92c5de, 0xd1e5f0, 0xf7f7f7,
    0xfddbc7, 0xf4a582, 0xd6604d, 0xb2182b, 0x67001f};
static const unsigned tableau10[10] = {
    0x4e79a7, 0xf28e2b, 0xe15759, 0x76b7b2, 0x59a14f,
    0xedc948, 0xb07aa1, 0xff9da7, 0x9c755f, 0xbab0ac};

static void hex_rgb(unsigned h, double rgb[3])
{
    rgb[0] = ((h >> 16) & 0xff) / 255.0;
    rgb[1] = ((h >> 8) & 0xff) / 255.0;
    rgb[2] = (h & 0xff) / 255.0;
}

static void table_rgb(const unsigned *tab, int n, double t, double rgb[3])
{
    double s = t * (n - 1), a[3], b[3];
    int i = (int)floor(s);
    if (i >= n - 1) i = n - 2;
    if (i < 0) i = 0;
    double f = s - i;
    hex_rgb(tab[i], a);
    hex_rgb(tab[i + 1], b);
    for (int k = 0; k < 3; k++) rgb[k] = a[k] + f * (b[k] - a[k]);
}

void es_colormap_rgb(es_colormap map, double t, double rgb[3])
{
    if (isnan(t)) {
        rgb[0] = rgb[1] = rgb[2] = ES_NAN_GREY;
        return;
    }
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    switch (map) {
    case ES_CMAP_RDBU: table_rgb(rdbu11_rev, 11, t, rgb); return;
    case ES_CMAP_GREYS: rgb[0] = rgb[1] = rgb[2] = t; return;
    case ES_CMAP_VIRIDIS:
    default: table_rgb(viridis11, 11, t, rgb); return;
    }
}

int es_colormap_from_name(const char *name)
{
    static const char *const names[] = {"viridis", "rdbu", "greys"};
    static const es_colormap maps[] = {ES_CMAP_VIRIDIS, ES_CMAP_RDBU, ES_CMAP_GREYS};
    for (int k = 0; name && k < 3; k++)
        if (!strcmp(name, names[k])) return (int)maps[k];
    return -1;
}

void es_palette_rgb(int64_t i, double rgb[3])
{
    if (i < 0) i = -i;
    hex_rgb(tableau10[i % 10], rgb);
}

void es__color_range(es_colormap cmap, const double *v, int64_t n, double *vmin,
                     double *vmax)
{
    if (*vmin == *vmax || !isfinite(*vmin) || !isfinite(*vmax)) {
        double lo = INFINITY, hi = -INFINITY;
        for (int64_t i = 0; i < n; i++) {
            if (!isfinite(v[i])) continue;
            if (v[i] < lo) lo = v[i];
            if (v[i] > hi) hi = v[i];
        }
        if (lo > hi) lo = hi = 0;
        if (cmap == ES_CMAP_RDBU) {
            double m = fmax(fabs(lo), fabs(hi));
            lo = -m;
            hi = m;
        }
        *vmin = lo;
        *vmax = hi;
    }
    if (*vmin > *vmax) {
        double s = *vmin;
        *vmin = *vmax;
        *vmax = s;
    }
    if (*vmin == *vmax) {
        double d = *vmin != 0 ? 0.5 * fabs(*vmin) : 0.5;
        *vmin -= d;
        *vmax += d;
    }
}

/* ---- nice numbers ---------------------------------------------------------- */

/* Heckbert's nicenum: a 1, 2, 5 x 10^k number near x (rounded or not less). */
static double nicenum(double x, int round_it)
{
    double e = floor(log10(x)), f = x / pow(10, e), nf;
    if (round_it) nf = f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10;
    else nf = f <= 1 ? 1 : f <= 2 ? 2 : f <= 5 ? 5 : 10;
    return nf * pow(10, e);
}

void es_plot_nice_ticks(double lo, double hi, int target, double *first, double *last,
                        double *step)
{
    if (!isfinite(lo) || !isfinite(hi)) {
        *first = 0;
        *last = 1;
        *step = 0.2;
        return;
    }
    if (lo > hi) {
        double s = lo;
        lo = hi;
        hi = s;
    }
    if (lo == hi) {
        double d = lo != 0 ? 0.1 * fabs(lo) : 1;
        lo -= d;
        hi += d;
    }
    if (target < 2) target = 2;
    /* the step from the data's own range: rounding the range up to a nice
     * number first (Heckbert) can leave a third of the axis empty */
    double d = nicenum((hi - lo) / (target - 1), 1);
    *first = floor(lo / d) * d;
    *last = ceil(hi / d) * d;
    /* floor/ceil of a quotient can land one step short by rounding */
    if (*first > lo) *first -= d;
    if (*last < hi) *last += d;
    *step = d;
}

void es__ticks_nice(double lo, double hi, int target, int integer_only, es__ticks *t)
{
    double first, last, step;
    es_plot_nice_ticks(lo, hi, target, &first, &last, &step);
    if (integer_only && step < 1) {
        step = 1;
        first = floor(first);
        last = ceil(last);
    }
    t->lo = first;
    t->hi = last;
    t->n = 0;
    for (int i = 0; t->n < ES__MAX_TICKS; i++) {
        double v = first + i * step;
        if (v > last + 0.5 * step) break;
        t->v[t->n++] = fabs(v) < 1e-12 * step ? 0 : v;
    }
    double m = fmax(fabs(first), fabs(last));
    if (m >= 1e6 || (m > 0 && step < 1e-4)) t->decimals = -1;
    else t->decimals = (int)fmax(-floor(log10(step) + 1e-9), 0);
}

void es__ticks_log(double lo, double hi, es__ticks *t)
{
    double a = floor(log10(lo) + 1e-9), b = ceil(log10(hi) - 1e-9);
    if (b <= a) b = a + 1;
    int every = (int)ceil((b - a) / 10);
    t->lo = a;
    t->hi = b;
    t->n = 0;
    for (double e = a; e <= b + 0.5 && t->n < ES__MAX_TICKS; e += every) t->v[t->n++] = e;
    t->decimals = -1;
}

void es__tick_label(const es__ticks *t, double v, int logy, char *buf, size_t n)
{
    if (logy) snprintf(buf, n, "1e%d", (int)lrint(v));
    else if (t->decimals < 0) snprintf(buf, n, "%.3g", v);
    else snprintf(buf, n, "%.*f", t->decimals, v);
}

/* ---- canvas ---------------------------------------------------------------- */

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcasecmp(s + a - b, suffix) == 0;
}

/* cairo's stream output into the part file. */
static cairo_status_t write_part(void *closure, const unsigned char *data, unsigned int n)
{
    FILE *f = closure;
    return fwrite(data, 1, n, f) == n ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

es_status es__canvas_open(es_ctx *ctx, const char *path, int width, int height,
                          es__canvas *cv)
{
    memset(cv, 0, sizeof *cv);
    if (!path || !*path) ES_FAIL(ctx, ES_EINVAL, "plot: no output path");
    if (width < 16 || height < 16 || width > 16384 || height > 16384)
        ES_FAIL(ctx, ES_EINVAL, "plot: '%s': size %d x %d is outside 16..16384", path,
                width, height);
    cv->path = path;
    cv->ctx = ctx;
    cv->width = width;
    cv->height = height;
    if (ends_with(path, ".png")) cv->kind = ES__CANVAS_PNG;
    else if (ends_with(path, ".svg")) cv->kind = ES__CANVAS_SVG;
    else if (ends_with(path, ".pdf")) cv->kind = ES__CANVAS_PDF;
    else ES_FAIL(ctx, ES_EINVAL, "plot: '%s': unknown output format (use .png, .svg or .pdf)",
                 path);
    es_status rc = es__replace_begin(ctx, path, &cv->out);
    if (rc != ES_OK) return es__fail(ctx, rc, "plot: %s", es_ctx_errmsg(ctx));
    if (cv->kind == ES__CANVAS_PNG)
        cv->surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height);
    else if (cv->kind == ES__CANVAS_SVG)
        cv->surface = cairo_svg_surface_create_for_stream(write_part, cv->out.f, width, height);
    else
        cv->surface = cairo_pdf_surface_create_for_stream(write_part, cv->out.f, width, height);
    cairo_status_t st = cairo_surface_status(cv->surface);
    if (st != CAIRO_STATUS_SUCCESS) {
        es__canvas_discard(cv);
        if (st == CAIRO_STATUS_NO_MEMORY) ES_FAIL(ctx, ES_ENOMEM, "plot: '%s': out of memory", path);
        ES_FAIL(ctx, ES_EIO, "plot: cannot create '%s': %s", path,
                cairo_status_to_string(st));
    }
    cv->cr = cairo_create(cv->surface);
    if (cairo_status(cv->cr) != CAIRO_STATUS_SUCCESS) {
        es__canvas_discard(cv);
        ES_FAIL(ctx, ES_ENOMEM, "plot: '%s': cannot create a drawing context", path);
    }
    cairo_set_source_rgb(cv->cr, 1, 1, 1);
    cairo_paint(cv->cr);
    cairo_select_font_face(cv->cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                           CAIRO_FONT_WEIGHT_NORMAL);
    return ES_OK;
}

/* Release the drawing objects (the stream surfaces write their last bytes
 * when destroyed, so this comes before the part file is closed). */
static void release(es__canvas *cv)
{
    if (cv->cr) cairo_destroy(cv->cr);
    if (cv->surface) cairo_surface_destroy(cv->surface);
    cv->cr = NULL;
    cv->surface = NULL;
}

void es__canvas_discard(es__canvas *cv)
{
    release(cv);
    if (cv->out.f) es__replace_end(cv->ctx, &cv->out, ES_EIO);   /* the old file stays */
}

es_status es__canvas_close(es_ctx *ctx, es__canvas *cv)
{
    cairo_status_t st = cairo_status(cv->cr);
    if (st == CAIRO_STATUS_SUCCESS) {
        cairo_surface_flush(cv->surface);
        if (cv->kind == ES__CANVAS_PNG)
            st = cairo_surface_write_to_png_stream(cv->surface, write_part, cv->out.f);
        else {
            cairo_surface_finish(cv->surface);
            st = cairo_surface_status(cv->surface);
        }
    }
    release(cv);
    es_status rc = st == CAIRO_STATUS_SUCCESS ? ES_OK
                 : st == CAIRO_STATUS_NO_MEMORY
                     ? es__fail(ctx, ES_ENOMEM, "plot: '%s': out of memory", cv->path)
                     : es__fail(ctx, ES_EIO, "plot: cannot write '%s': %s", cv->path,
                                cairo_status_to_string(st));
    /* publish the part file only when the whole figure is in it */
    if ((rc = es__replace_end(ctx, &cv->out, rc)) != ES_OK && st == CAIRO_STATUS_SUCCESS)
        return es__fail(ctx, rc, "plot: %s", es_ctx_errmsg(ctx));
    return rc;
}

/* ---- text ------------------------------------------------------------------ */

void es__text(cairo_t *cr, double x, double y, const char *s, double size, double ha,
              double va, double angle)
{
    cairo_text_extents_t te;
    cairo_font_extents_t fe;
    if (!s || !*s) return;
    cairo_save(cr);
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, s, &te);
    cairo_font_extents(cr, &fe);
    cairo_translate(cr, x, y);
    cairo_rotate(cr, angle);
    double h = fe.ascent + fe.descent;
    cairo_move_to(cr, -ha * te.x_advance, -va * h + fe.ascent);
    cairo_show_text(cr, s);
    cairo_restore(cr);
}

double es__text_width(cairo_t *cr, const char *s, double size)
{
    cairo_text_extents_t te;
    if (!s || !*s) return 0;
    cairo_save(cr);
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, s, &te);
    cairo_restore(cr);
    return te.x_advance;
}

/* ---- axes ------------------------------------------------------------------ */

void es__plot_area(const es_plot_frame *f, double right_extra, double left_extra,
                   es_plot_info *info)
{
    double fs = f->font_size;
    info->left = 3.2 * fs + 2.0 * fs * (f->ylabel && *f->ylabel) + left_extra + 6;
    info->right = f->width - 1.5 * fs - right_extra;
    info->top = (f->title && *f->title) ? 2.6 * fs : 1.2 * fs;
    info->bottom = f->height - 2.2 * fs - 1.8 * fs * (f->xlabel && *f->xlabel);
    if (info->right < info->left + 8) info->right = info->left + 8;
    if (info->bottom < info->top + 8) info->bottom = info->top + 8;
}

void es__draw_axes(cairo_t *cr, const es_plot_frame *f, const es_plot_info *info,
                   const es__ticks *xt, const es__ticks *yt, int grid)
{
    double fs = f->font_size, px, py;
    char buf[64];
    cairo_save(cr);
    cairo_set_line_width(cr, 1);
    for (int i = 0; xt && i < xt->n; i++) {
        es_plot_info_to_device(info, xt->v[i], info->ymin, &px, &py);
        px = floor(px) + 0.5;
        if (grid) {
            cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
            cairo_move_to(cr, px, info->top);
            cairo_line_to(cr, px, info->bottom);
            cairo_stroke(cr);
        }
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, px, info->bottom);
        cairo_line_to(cr, px, info->bottom + 4);
        cairo_stroke(cr);
        es__tick_label(xt, xt->v[i], 0, buf, sizeof buf);
        es__text(cr, px, info->bottom + 6, buf, 0.85 * fs, 0.5, 0, 0);
    }
    for (int i = 0; yt && i < yt->n; i++) {
        double yv = info->logy ? pow(10, yt->v[i]) : yt->v[i];
        es_plot_info_to_device(info, info->xmin, yv, &px, &py);
        py = floor(py) + 0.5;
        if (grid) {
            cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
            cairo_move_to(cr, info->left, py);
            cairo_line_to(cr, info->right, py);
            cairo_stroke(cr);
        }
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, info->left - 4, py);
        cairo_line_to(cr, info->left, py);
        cairo_stroke(cr);
        es__tick_label(yt, yt->v[i], info->logy, buf, sizeof buf);
        es__text(cr, info->left - 6, py, buf, 0.85 * fs, 1, 0.5, 0);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, floor(info->left) + 0.5, floor(info->top) + 0.5,
                    floor(info->right) - floor(info->left),
                    floor(info->bottom) - floor(info->top));
    cairo_stroke(cr);
    double cx = 0.5 * (info->left + info->right), cy = 0.5 * (info->top + info->bottom);
    if (f->xlabel) es__text(cr, cx, f->height - 0.5 * fs, f->xlabel, fs, 0.5, 1, 0);
    if (f->ylabel) es__text(cr, 0.5 * fs, cy, f->ylabel, fs, 0.5, 0, -M_PI / 2);
    if (f->title) es__text(cr, 0.5 * f->width, 0.6 * fs, f->title, 1.15 * fs, 0.5, 0, 0);
    cairo_restore(cr);
}

void es_plot_info_to_device(const es_plot_info *info, double x, double y, double *px,
                            double *py)
{
    double yv = info->logy ? log10(y) : y;
    double y0 = info->logy ? log10(info->ymin) : info->ymin;
    double y1 = info->logy ? log10(info->ymax) : info->ymax;
    *px = info->left + (x - info->xmin) / (info->xmax - info->xmin) * (info->right - info->left);
    *py = info->bottom - (yv - y0) / (y1 - y0) * (info->bottom - info->top);
}

/* ---- legend ---------------------------------------------------------------- */

double es__legend_width(cairo_t *cr, const char *title, const char *const *names,
                        int64_t n, double size)
{
    double w = es__text_width(cr, title, size);
    for (int64_t i = 0; i < n; i++)
        if (names[i]) w = fmax(w, 2.2 * size + es__text_width(cr, names[i], 0.9 * size));
    return w + 0.8 * size;
}

void es__draw_legend(cairo_t *cr, double x, double y, const char *title,
                     const char *const *names, int64_t n, int style, const int *styles,
                     double size)
{
    double rgb[3], line = 1.4 * size;
    cairo_save(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    if (title && *title) {
        es__text(cr, x, y, title, size, 0, 0, 0);
        y += line;
    }
    for (int64_t i = 0; i < n; i++) {
        if (!names[i]) continue;
        es_palette_rgb(i, rgb);
        cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
        double cy = y + 0.5 * line;
        int st = styles ? styles[i] : style;
        if (st == 0) {
            cairo_arc(cr, x + 0.6 * size, cy, 0.35 * size, 0, 2 * M_PI);
            cairo_fill(cr);
        } else if (st == 2) {
            cairo_rectangle(cr, x + 0.2 * size, cy - 0.4 * size, 1.2 * size, 0.8 * size);
            cairo_fill(cr);
        } else {
            cairo_set_line_width(cr, 2);
            cairo_move_to(cr, x, cy);
            cairo_line_to(cr, x + 1.6 * size, cy);
            cairo_stroke(cr);
        }
        cairo_set_source_rgb(cr, 0, 0, 0);
        es__text(cr, x + 2.2 * size, cy, names[i], 0.9 * size, 0, 0.5, 0);
        y += line;
    }
    cairo_restore(cr);
}

/* ---- colour bar ------------------------------------------------------------ */

/* The colour bar's ticks and their labels. logscale: the values are log10 of
 * the quantity, and the ticks sit at 1, 2 and 5 times powers of ten of it
 * (every integer multiple when that gives fewer than 3), labelled with the
 * quantity itself. */
static void colorbar_ticks(double vmin, double vmax, int logscale, es__ticks *t,
                           char labels[][32])
{
    if (logscale) {
        static const double steps[2][9] = {{1, 2, 5}, {1, 2, 3, 4, 5, 6, 7, 8, 9}};
        static const int nsteps[2] = {3, 9};
        for (int pass = 0; pass < 2; pass++) {
            t->n = 0;
            for (double k = floor(vmin); k <= ceil(vmax) && t->n < ES__MAX_TICKS; k++)
                for (int i = 0; i < nsteps[pass] && t->n < ES__MAX_TICKS; i++) {
                    double v = k + log10(steps[pass][i]);
                    if (v < vmin - 1e-9 || v > vmax + 1e-9) continue;
                    snprintf(labels[t->n], 32, "%g", steps[pass][i] * pow(10, k));
                    t->v[t->n++] = v;
                }
            if (t->n >= 3) break;
        }
        return;
    }
    es__ticks_nice(vmin, vmax, 5, 0, t);
    for (int i = 0; i < t->n; i++) es__tick_label(t, t->v[i], 0, labels[i], 32);
}

double es__colorbar_width(cairo_t *cr, double w, double vmin, double vmax,
                          const char *label, double size, int logscale)
{
    es__ticks t;
    char labels[ES__MAX_TICKS][32];
    double tw = 0;
    colorbar_ticks(vmin, vmax, logscale, &t, labels);
    for (int i = 0; i < t.n; i++) tw = fmax(tw, es__text_width(cr, labels[i], 0.85 * size));
    return w + 6 + tw + (label && *label ? 1.8 * size : 0) + 4;
}

void es__draw_colorbar(cairo_t *cr, double x, double y, double w, double h,
                       es_colormap cmap, double vmin, double vmax, const char *label,
                       double size, int logscale)
{
    double rgb[3];
    char labels[ES__MAX_TICKS][32];
    int rows = (int)lrint(h);
    if (rows < 2) rows = 2;
    x = round(x);
    y = round(y);
    w = round(w);
    cairo_save(cr);
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    for (int i = 0; i < rows; i++) {
        es_colormap_rgb(cmap, 1.0 - (double)i / (rows - 1), rgb);
        cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
        /* bands overlap by a fraction so no seam shows in vector output */
        cairo_rectangle(cr, x, y + i, w, i + 1 < rows ? 1.25 : 1);
        cairo_fill(cr);
    }
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, x - 0.5, y - 0.5, w + 1, rows + 1);
    cairo_stroke(cr);
    es__ticks t;
    colorbar_ticks(vmin, vmax, logscale, &t, labels);
    for (int i = 0; i < t.n; i++) {
        if (t.v[i] < vmin - 1e-9 * (vmax - vmin) || t.v[i] > vmax + 1e-9 * (vmax - vmin))
            continue;
        double py = y + (rows - 1) * (vmax - t.v[i]) / (vmax - vmin) + 0.5;
        cairo_move_to(cr, x + w, py);
        cairo_line_to(cr, x + w + 4, py);
        cairo_stroke(cr);
        es__text(cr, x + w + 6, py, labels[i], 0.85 * size, 0, 0.5, 0);
    }
    if (label && *label) {
        double tw = es__colorbar_width(cr, w, vmin, vmax, NULL, size, logscale);
        es__text(cr, x + tw + 0.2 * size, y + 0.5 * h, label, size, 0.5, 0, -M_PI / 2);
    }
    cairo_restore(cr);
}
