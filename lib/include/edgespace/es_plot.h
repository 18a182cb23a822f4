/* lib/include/edgespace/es_plot.h — figures for notebooks and reports:
 * scatter with a categorical legend, scree, line curves, heat map,
 * histogram; colour maps and the categorical palette shared with the mesh
 * renderer (es_render.h).
 *
 * Every plot is one call that takes a plain spec struct (fill it with the
 * matching _init function first, then set what you need) and an output path
 * whose extension picks the format: ".png" (raster, width x height pixels),
 * ".svg" or ".pdf" (vector, width x height points). Text uses cairo's toy
 * font API with the "sans-serif" face.
 *
 * Values that are not finite (NaN, inf) are skipped and counted in the
 * es_plot_info the call fills (if non-NULL), which also says where the
 * axes went, so a caller (or a test) can map data to device coordinates
 * with es_plot_info_to_device.
 *
 * Errors: ES_EINVAL for a bad spec (negative sizes, NULL data with n > 0,
 * an unknown file extension), ES_EIO when the file cannot be written,
 * ES_ENOMEM.
 */
#ifndef EDGESPACE_ES_PLOT_H
#define EDGESPACE_ES_PLOT_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- colour -------------------------------------------------------------- */

typedef enum es_colormap {
    ES_CMAP_VIRIDIS = 0, /* sequential, perceptually uniform (matplotlib viridis) */
    ES_CMAP_RDBU,        /* diverging: blue (low) - white (middle) - red (high),
                          * ColorBrewer RdBu reversed; for signed values */
    ES_CMAP_GREYS        /* sequential, black (low) to white (high) */
} es_colormap;

/* Colour of t in [0, 1] (clamped) under `map`, components in [0, 1].
 * A NaN t gives the neutral grey ES_NAN_GREY in all three components. */
#define ES_NAN_GREY 0.6
ES_API void es_colormap_rgb(es_colormap map, double t, double rgb[3]);

/* The map named "viridis", "rdbu" or "greys" (the names the commands and
 * the Python package take), or -1 for any other name. */
ES_API int es_colormap_from_name(const char *name);

/* Colour i (any i >= 0, cycling) of the categorical palette (Tableau 10:
 * distinct, colour-blind aware, readable on white). */
ES_API void es_palette_rgb(int64_t i, double rgb[3]);

/* Heckbert's "nice numbers" (Graphics Gems, 1990) loose labelling: a tick
 * step of 1, 2 or 5 x 10^k giving about `target` (>= 2) ticks, and the first
 * and last tick, multiples of the step, that enclose [lo, hi]. lo == hi is
 * widened around the value. Cannot fail; non-finite input gives 0, 1, 0.2. */
ES_API void es_plot_nice_ticks(double lo, double hi, int target, double *first,
                               double *last, double *step);

/* ---- common frame and results ------------------------------------------ */

typedef struct es_plot_frame {
    int width, height;        /* device size: pixels or points (640 x 480) */
    const char *title;        /* NULL: none */
    const char *xlabel, *ylabel;
    double font_size;         /* points (12) */
} es_plot_frame;

/* What a plot call did: the plot area in device coordinates (y downwards
 * from the top-left corner), the data range of the axes, and skipped
 * values. */
typedef struct es_plot_info {
    double left, top, right, bottom; /* plot area, device units */
    double xmin, xmax, ymin, ymax;   /* axis ranges, data units */
    int logy;                        /* y axis is log10 */
    int64_t n_skipped;               /* non-finite values left out */
} es_plot_info;

/* Device coordinates of data point (x, y) under `info`. */
ES_API void es_plot_info_to_device(const es_plot_info *info, double x, double y,
                                   double *px, double *py);

/* ---- scatter ----------------------------------------------------------- */

typedef struct es_scatter_spec {
    es_plot_frame frame;
    int64_t n;                  /* number of points */
    const double *x, *y;        /* n coordinates */
    /* n category names, one per point, or NULL (one unnamed group). Groups
     * are coloured by es_palette_rgb in order of first appearance, and
     * listed in that order in the legend. */
    const char *const *labels;
    const char *legend_title;   /* NULL: none */
    double marker_radius;       /* device units (4) */
    int equal_aspect;           /* same data units per device unit on x and y (0) */
} es_scatter_spec;

ES_API void es_scatter_spec_init(es_scatter_spec *spec);
ES_API es_status es_plot_scatter(es_ctx *ctx, const es_scatter_spec *spec,
                                 const char *path, es_plot_info *info);

/* ---- scree ------------------------------------------------------------- */

typedef struct es_scree_spec {
    es_plot_frame frame;        /* default labels: "component", "explained variance (%)" */
    int64_t n;                  /* components shown */
    const double *variance;     /* n variances (eigenvalues), >= 0 */
    /* Total variance the percentages are of; 0: the sum of the n shown
     * (give the full total when only the leading components are shown). */
    double total;
} es_scree_spec;

ES_API void es_scree_spec_init(es_scree_spec *spec);
/* Bars: percent of total per component; line with markers: cumulative
 * percent. Same axis, 0..100. */
ES_API es_status es_plot_scree(es_ctx *ctx, const es_scree_spec *spec, const char *path,
                               es_plot_info *info);

/* ---- line curves ------------------------------------------------------- */

typedef struct es_series {
    const char *name;           /* legend entry, NULL: not in the legend */
    int64_t n;
    const double *x, *y;        /* n points, drawn in order */
} es_series;

typedef struct es_lines_spec {
    es_plot_frame frame;
    int64_t nseries;
    const es_series *series;    /* coloured by es_palette_rgb(index) */
    int logy;                   /* log10 y axis; values <= 0 are skipped */
    int markers;                /* draw a dot at each point (0) */
    const int *points_only;     /* nseries flags or NULL: a series flagged 1 is drawn as
                                   dots without a line (a scatter among curves; its legend
                                   key a dot) */
} es_lines_spec;

ES_API void es_lines_spec_init(es_lines_spec *spec);
ES_API es_status es_plot_lines(es_ctx *ctx, const es_lines_spec *spec, const char *path,
                               es_plot_info *info);

/* ---- heat map ---------------------------------------------------------- */

typedef struct es_heatmap_spec {
    es_plot_frame frame;
    es_mat values;              /* rows x cols; row 0 drawn at the top */
    const char *const *row_labels; /* rows names or NULL */
    const char *const *col_labels; /* cols names or NULL */
    es_colormap cmap;           /* ES_CMAP_VIRIDIS */
    /* Colour range; vmin == vmax (the default 0, 0): the finite data range,
     * symmetric about 0 for ES_CMAP_RDBU. */
    double vmin, vmax;
    const char *colorbar_label; /* NULL: none; say the quantity and its units */
    /* Groups of adjacent rows and of adjacent columns, or NULL: row_groups[i]
     * is row i's index into group_names, the same along each run of adjacent
     * rows (sort the matrix by group first). A white line separates the runs
     * and each run's name stands beside it: left of the row labels, above
     * the columns (where it fits). */
    const int64_t *row_groups, *col_groups;
    const char *const *group_names; /* NULL: the 1-based group numbers */
} es_heatmap_spec;

ES_API void es_heatmap_spec_init(es_heatmap_spec *spec);
/* Cells are vector rectangles (sharp at any zoom in SVG and PDF) up to
 * 512 x 512 cells, one nearest-neighbour image above that. Cells with NaN
 * are drawn ES_NAN_GREY and counted in n_skipped. In the info, xmin..xmax
 * is 0..cols and ymin..ymax is 0..rows (row 0 on top). */
ES_API es_status es_plot_heatmap(es_ctx *ctx, const es_heatmap_spec *spec, const char *path,
                                 es_plot_info *info);

/* ---- histogram --------------------------------------------------------- */

typedef struct es_histogram_spec {
    es_plot_frame frame;        /* default ylabel "count" */
    int64_t n;
    const double *values;
    int64_t nbins;              /* 0: Freedman-Diaconis rule, clamped to 5..100 */
    double lo, hi;              /* bin range; lo == hi (default): data range */
} es_histogram_spec;

ES_API void es_histogram_spec_init(es_histogram_spec *spec);
ES_API es_status es_plot_histogram(es_ctx *ctx, const es_histogram_spec *spec,
                                   const char *path, es_plot_info *info);

#ifdef __cplusplus
}
#endif
#endif
