/* lib/figure/figure_pkg.h — what the files of lib/figure share: an output
 * canvas (a cairo surface chosen by the file extension), text, axes with
 * nice ticks, legends and colour bars (plot.c, plot_canvas.c, render.c: the
 * only files that draw), and the reading of numbers from CSV cells
 * (table_figure.c, render_files.c). Only lib/figure includes cairo.h.
 * Never installed.
 */
#ifndef EDGESPACE_FIGURE_PKG_H
#define EDGESPACE_FIGURE_PKG_H

#ifndef ES_MODULE_FIGURE
#error "figure/figure_pkg.h is private to lib/figure/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "edgespace/es_io.h"
#include "edgespace/es_plot.h"
#include "edgespace/es_render.h"

#include <cairo.h>

typedef enum es__canvas_kind { ES__CANVAS_PNG, ES__CANVAS_SVG, ES__CANVAS_PDF } es__canvas_kind;

typedef struct es__canvas {
    cairo_surface_t *surface;
    cairo_t *cr;
    es__canvas_kind kind;
    const char *path;           /* borrowed from the caller */
    int width, height;
    es__file_replace out;       /* the part file that replaces path when complete */
    es_ctx *ctx;                /* whose allocator made out.tmp */
} es__canvas;

/* Open a canvas for `path` (format from its extension), size width x height,
 * painted white, font "sans-serif". The figure is written to a part file
 * beside path that replaces it only when complete (es__replace_begin), so a
 * failed figure leaves the old file. On failure nothing is left open. */
es_status es__canvas_open(es_ctx *ctx, const char *path, int width, int height,
                          es__canvas *cv);
/* Write the file (PNG) or finish it (SVG, PDF), then release everything.
 * Reports drawing or writing errors as ES_EIO naming the path. */
es_status es__canvas_close(es_ctx *ctx, es__canvas *cv);
/* Release without reporting (on an error path; the part file is removed).
 * NULL members: no-op. */
void es__canvas_discard(es__canvas *cv);

/* A plot frame's defaults (640 x 480, font 12, no title or labels), and its
 * check (font size in (0, 200)) naming the plot `what` (plot.c). */
void es__frame_init(es_plot_frame *f);
es_status es__frame_check(es_ctx *ctx, const char *what, const es_plot_frame *f);

/* Text anchored at (x, y): ha 0 left, 0.5 centre, 1 right; va 0 top,
 * 0.5 middle, 1 bottom (of the font's ascent..descent box); rotated by
 * `angle` radians about the anchor. */
void es__text(cairo_t *cr, double x, double y, const char *s, double size, double ha,
              double va, double angle);
double es__text_width(cairo_t *cr, const char *s, double size);

/* Ticks of one axis. */
#define ES__MAX_TICKS 64
typedef struct es__ticks {
    int n;
    double v[ES__MAX_TICKS];
    double lo, hi;              /* axis range (the nice range, or given) */
    int decimals;               /* digits after the point for labels; -1: %g */
} es__ticks;

/* Nice ticks enclosing [lo, hi] (Heckbert); integer_only: step >= 1. */
void es__ticks_nice(double lo, double hi, int target, int integer_only, es__ticks *t);
/* Decades enclosing [lo, hi] (both > 0) for a log10 axis; values in v are
 * the exponents and lo/hi are log10 of the range. */
void es__ticks_log(double lo, double hi, es__ticks *t);
void es__tick_label(const es__ticks *t, double v, int logy, char *buf, size_t n);

/* Plot area for a frame whose plot has extra room `right_extra` on the
 * right (legend, colour bar). Fills info->left/top/right/bottom. */
void es__plot_area(const es_plot_frame *f, double right_extra, double left_extra,
                   es_plot_info *info);
/* Frame box, grid, ticks, tick labels, axis labels and title. */
void es__draw_axes(cairo_t *cr, const es_plot_frame *f, const es_plot_info *info,
                   const es__ticks *xt, const es__ticks *yt, int grid);

/* Legend of n entries (NULL names skipped) with palette colours, top-left
 * corner at (x, y). Key styles: 0 filled circle, 1 line segment, 2 square;
 * styles[i] per entry, or `style` for all when styles is NULL. */
void es__draw_legend(cairo_t *cr, double x, double y, const char *title,
                     const char *const *names, int64_t n, int style, const int *styles,
                     double size);
double es__legend_width(cairo_t *cr, const char *title, const char *const *names,
                        int64_t n, double size);

/* Vertical colour bar, vmax at the top; the top device row has exactly the
 * map's colour at 1, the bottom row at 0. Ticks and label on the right.
 * logscale: the values are log10 of the quantity; ticks at 1, 2, 5 x 10^k of
 * the quantity, labelled with it. */
void es__draw_colorbar(cairo_t *cr, double x, double y, double w, double h,
                       es_colormap cmap, double vmin, double vmax, const char *label,
                       double size, int logscale);
/* Width taken by a colour bar of bar width w (bar, ticks, label). */
double es__colorbar_width(cairo_t *cr, double w, double vmin, double vmax,
                          const char *label, double size, int logscale);

/* Resolve a colour range: vmin == vmax means the finite range of data
 * (symmetric about 0 for diverging maps); a degenerate range is widened. */
void es__color_range(es_colormap cmap, const double *v, int64_t n, double *vmin,
                     double *vmax);

/* The colour range of a render spec's scalars into rep->vmin, vmax (given,
 * percentiles, or the finite range; es__color_range), and the non-finite
 * count into rep->n_nan_scalars (render.c; es_render and the coloured mesh
 * files share it). */
es_status es__render_range(es_ctx *ctx, const es_render_spec *spec, es_render_report *rep);

/* A scalar file's column `want` (NULL: the first; render_files.c): *n values,
 * one per line after an optional header (its text into head[hn]), NaN for
 * blanks; and what they colour on a mesh read from mesh_path: its vertices,
 * faces or (through a topology made into *mesh_out) edges, set in it. */
es_status es__read_scalars(es_ctx *ctx, const char *path, const char *want, double **out,
                           int64_t *n, char *head, size_t hn);
es_status es__match_scalars(es_ctx *ctx, const char *mesh_path, const es_meshdata *md,
                            const char *sf, int64_t n, es_mesh **mesh_out,
                            es_render_mesh *it);

/* A CSV cell as a number for the figures: blanks around it are ignored; an
 * empty cell, "nan" or "na" (any case) is a missing value, NaN; anything
 * strtod reads whole is its value. 0 for a number or a missing value, -1
 * for text (*v is then 0). */
int es__figure_cell_number(const char *s, double *v);

#endif
