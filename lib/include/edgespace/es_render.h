/* lib/include/edgespace/es_render.h — pictures of triangle meshes.
 *
 * es_render draws one or several meshes side by side in a row (or a grid
 * of `ncols` columns), each with
 * an optional label under it, an optional title above and, when scalars are
 * given, one colour bar for all of them on the right. The output format
 * follows the file extension as in es_plot.h (.png, .svg, .pdf).
 *
 * How: a z-buffer rasterizer (in render.c) draws each panel into an image
 * at `supersample` times the resolution, with per-pixel Lambert shading
 * under a headlight (light from the camera) from interpolated vertex
 * normals, and box-filters it down; cairo then places the panels, labels
 * and colour bar. A z-buffer rather than the painter's algorithm because it
 * is exact for interpenetrating and cyclically overlapping triangles,
 * shades per pixel and is O(pixels + triangles) without a sort; the price
 * is that in SVG/PDF output the mesh panels are embedded images (text and
 * colour bar stay vector), kept at `supersample` times the panel's pixels
 * so that they stay sharp when zoomed or printed (PNG: box-filtered down).
 *
 * Camera: by default each mesh is seen along its smallest principal axis
 * (PCA of its vertices), centred on its centroid, from the side its faces
 * point to (es_render_auto_view gives the rule). Every panel uses the same
 * scale (data units per pixel) so that sizes compare across panels, unless
 * fit_each asks for each mesh to fill its own panel.
 * Explicit `view` (the direction the camera looks along) and `up` vectors
 * override the choice for all panels.
 *
 * Scalars: per vertex (interpolated across faces, then mapped), per edge
 * (each face shows the mean of its three edges) or per face. NaN or inf
 * scalars are drawn in the neutral grey ES_NAN_GREY (shaded like the rest),
 * counted in the report and keyed "n/a" under the colour bar. Without scalars a mesh is drawn in `base_rgb`.
 */
#ifndef EDGESPACE_ES_RENDER_H
#define EDGESPACE_ES_RENDER_H

#include "es_core.h"
#include "es_mesh.h"
#include "es_plot.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum es_projection {
    ES_PROJ_PERSPECTIVE = 0,   /* vertical field of view fov_deg */
    ES_PROJ_ORTHOGRAPHIC
} es_projection;

typedef enum es_backface {
    ES_BACKFACE_DARKER = 0,    /* drawn, lit from their own side, in a darker tone */
    ES_BACKFACE_CULL           /* not drawn (what is behind them shows) */
} es_backface;

typedef enum es_scalar_kind {
    ES_SCALARS_NONE = 0,
    ES_SCALARS_VERTEX,         /* nverts values */
    ES_SCALARS_EDGE,           /* nedges values, edge i = column i of `edges` */
    ES_SCALARS_FACE            /* nfaces values */
} es_scalar_kind;

/* One mesh to draw. All arrays borrowed for the duration of the call. */
typedef struct es_render_mesh {
    int64_t nverts, nfaces;
    const double *xyz;         /* 3 x nverts positions */
    const int64_t *faces;      /* 3 x nfaces, 0-based, counter-clockwise = front */
    const char *label;         /* drawn under the panel, or NULL */
    es_scalar_kind scalar_kind;
    const double *scalars;
    /* For ES_SCALARS_EDGE: the edge list (2 x nedges vertex pairs, in any
     * order, e.g. es_mesh_edges()); every face edge must be in it. */
    int64_t nedges;
    const int64_t *edges;
    const double *rgb;         /* this mesh's surface colour without scalars (3 values in
                                  [0, 1]), or NULL: the spec's base_rgb (inputs and
                                  interpolated frames told apart in one picture) */
} es_render_mesh;

typedef struct es_render_spec {
    int64_t nmeshes;
    const es_render_mesh *meshes;
    int64_t ncols;             /* panels per row, wrapping into a grid (0: one row) */
    int width, height;         /* of each panel, device units (480 x 480) */
    es_projection projection;  /* ES_PROJ_PERSPECTIVE */
    /* Perspective strength (25): the eye sits where the mesh's bounding
     * sphere just fills this field of view; the picture is then scaled to
     * `fill` the panel, so a smaller angle means a flatter, more distant
     * look, not a smaller mesh. */
    double fov_deg;
    int has_view, has_up;      /* use view / up below instead of the automatic ones */
    int same_view;             /* 1: every panel uses the automatic view of mesh 0
                                * (sequences, shapes in one frame); 0: each its own */
    double view[3];            /* direction the camera looks along (not normalized) */
    double up[3];              /* screen up; made orthogonal to view */
    double fill;               /* fraction of the panel the largest mesh spans (0.9) */
    int fit_each;              /* 1: every mesh spans `fill` of its own panel;
                                * 0 (default): one scale for all panels */
    es_backface backface;      /* ES_BACKFACE_DARKER */
    es_colormap cmap;          /* for scalars (ES_CMAP_VIRIDIS) */
    /* Colour range; vmin == vmax (default): the finite range over all
     * meshes, symmetric about 0 for ES_CMAP_RDBU. */
    double vmin, vmax;
    int colorbar;              /* draw a colour bar when there are scalars (1) */
    const char *colorbar_label;
    /* The scalars are log10 of a quantity: the colour bar's ticks sit at 1,
     * 2 and 5 times powers of ten of the quantity, labelled with it (0). */
    int colorbar_log10;
    const char *nan_label;     /* key of the grey of non-finite scalars (NULL: "n/a") */
    const char *title;         /* above the row, or NULL */
    double base_rgb[3];        /* surface colour without scalars (light grey-beige) */
    double background_rgb[3];  /* (1, 1, 1) */
    double font_size;          /* (12) */
    int supersample;           /* 1..4 samples per pixel per axis (3) */
    /* Without vmin/vmax: the colour range from the lo-th to the hi-th
     * percentile of the finite scalars (linear interpolation between order
     * statistics, numpy's default), so that a few large values (a mesh's
     * worst residuals) do not leave the rest one colour; values beyond are
     * drawn in the end colours. {0, 0} (default): {0, 100}, the full range. */
    double range_percentiles[2];
    /* es_figure_render_files: the CSV column of the scalar files, a header
     * name or a 1-based number (NULL: the first); its header labels the
     * colour bar when colorbar_label is NULL. */
    const char *scalar_column;
} es_render_spec;

typedef struct es_render_report {
    int width, height;         /* the whole picture, device units */
    int64_t n_nan_scalars;     /* non-finite scalars drawn grey, all meshes */
    int64_t n_faces_drawn;     /* faces that covered at least one sample */
    int64_t n_backfaces;       /* faces seen from behind (drawn darker or culled) */
    double vmin, vmax;         /* colour range used */
    double units_per_pixel;    /* scale shared by the panels (orthographic: exact;
                                * perspective: at the depth of the bounding box
                                * centre); with fit_each, the coarsest panel's */
    double view[3], up[3];     /* camera of the first panel, unit vectors */
    int ncols;                 /* panels per row used */
    double panel_x0;           /* left edge of panel 0; panel i starts at
                                * panel_x0 + (i % ncols) * width */
    double panel_y0;           /* top edge of panel 0; panel i at
                                * panel_y0 + (i / ncols) * row_pitch */
    double row_pitch;          /* panel height plus the label line */
    double colorbar[4];        /* x, y, w, h of the colour bar's colour area, or zeros */
} es_render_report;

ES_API void es_render_spec_init(es_render_spec *spec);

/* Fill `item` (all fields reset) from a mesh's topology: faces and the
 * edge list (so per-edge scalars in es_mesh edge order work), with
 * positions xyz (3 x V), or the mesh's reference positions when xyz is
 * NULL. Borrowed pointers: valid as long as mesh and xyz. Then set label,
 * scalar_kind and scalars as needed. */
ES_API void es_render_mesh_from(es_render_mesh *item, const es_mesh *mesh, const double *xyz);

/* Draw spec->meshes to `path`. report: NULL or filled.
 * Errors: ES_EINVAL (no meshes, NULL arrays, a face index out of range, a
 * scalar kind without scalars, zero view/up vectors or view parallel to
 * up, an unknown extension), ES_ENOTFOUND (an edge of a face missing from
 * `edges`), ES_EIO, ES_ENOMEM. */
ES_API es_status es_render(es_ctx *ctx, const es_render_spec *spec, const char *path,
                           es_render_report *report);

/* The automatic camera of a mesh (faces may be NULL, nfaces 0):
 *  - view: the eigenvector of the smallest eigenvalue of the vertex
 *    covariance, signed so that the area-weighted sum of face normals
 *    points back to the camera (the faces look at the camera); if that sum
 *    is nearly orthogonal to it (a closed surface), signed so that the
 *    camera sits on the positive side of the axis's largest component.
 *  - up: if one of the two other axes is within about 11 degrees of the
 *    coordinate y axis (|cos| > 0.98: the mesh is stored y-up), that axis,
 *    pointing along +y. Otherwise the largest-variance axis, signed so that
 *    the skewness of the vertices along it is negative (the longer tail
 *    points down: a neck under a head, legs under a body); when the
 *    skewness is below 0.05 in magnitude, with its largest-magnitude
 *    component positive. Randomly rotated data can still come out upside
 *    down or sideways: give `up` (or the view of one reference mesh to all
 *    panels) when it matters.
 * Fails with ES_EINVAL on fewer than 3 vertices or non-finite positions. */
ES_API es_status es_render_auto_view(es_ctx *ctx, int64_t nverts, const double *xyz,
                                     int64_t nfaces, const int64_t *faces, double view[3],
                                     double up[3]);

#ifdef __cplusplus
}
#endif
#endif
