/* lib/include/edgespace/es_figure.h — lib/figure's figures of whole studies
 * and files: what a command, notebook or the Python package draws in one
 * call from stored results, a CSV table or mesh files (the plot and render
 * primitives are es_plot.h and es_render.h). Built only when libedgespace
 * has figures (es_config.h: ES_HAVE_FIGURES).
 *
 * Every message names the file it is about, and the line and column of a
 * table where one is to blame.
 */
#ifndef EDGESPACE_ES_FIGURE_H
#define EDGESPACE_ES_FIGURE_H

#include "es_core.h"
#include "es_compare.h"
#include "es_plot.h"
#include "es_render.h"
#include "es_store.h"
#include "es_study.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The comparison study's figures in dir (made if missing), format "png",
 * "pdf" or "svg" (NULL: svg) as the files' extension: heatmap_lengths,
 * heatmap_procrustes and, when the result has them, heatmap_rho (the
 * distance matrices, es_figure_compare_heatmap)
 * and pairs_scatter (distance pairs, coloured by group pair when group is
 * given). ids: n names (NULL: 1-based numbers); group_names: ngroups names
 * (NULL: numbers). */
ES_API es_status es_figure_compare_write(es_ctx *ctx, const es_compare_result *res,
                                         const char *const *ids, const int64_t *group,
                                         const char *const *group_names, const char *dir,
                                         const char *format);

/* One distance matrix of the study (which 0: edge lengths, 1: Procrustes,
 * 2: Riemannian rho at unit centroid size, ES_EINVAL if the result has none)
 * as a heat map at path (format by extension): rows and columns ordered by
 * group (group may be NULL), then by id, then by row; white lines between
 * groups and their names beside them; ids as row and column labels up to
 * 60 rows (group names only above that); the colour bar names the distance
 * and its units (between unit-sum length vectors when the study normalized
 * the lengths; data units of the GPA-aligned configurations). info (may be
 * NULL) receives es_plot_heatmap's plot area. */
ES_API es_status es_figure_compare_heatmap(es_ctx *ctx, const es_compare_result *res, int which,
                                           const char *const *ids, const int64_t *group,
                                           const char *const *group_names, const char *path,
                                           es_plot_info *info);

/* es_study_compare (es_study.h) and, with opts->out_dir, its figures (in
 * format, as es_figure_compare_write) beside its tables. */
ES_API es_status es_figure_compare(es_ctx *ctx, es_store *store, const es_study_compare_opts *opts,
                                   const char *format, es_compare_result **res);

/* ---- a figure of a CSV table (edgespace plot) -------------------------------
 *
 * The table is RFC 4180 CSV (quoted fields may hold commas, quotes and line
 * breaks; a stray quote or an unterminated quoted field is an error naming
 * the line). Its first record sets the number of columns: cells past it are
 * ignored, missing cells of shorter records are empty. The first record is
 * a header when not all its cells are numbers. Empty cells, "nan" and "na"
 * (any case) are missing values (NaN: skipped and counted by the plots);
 * other text where a number is wanted is an error naming the line and
 * column. Blank lines are skipped. */

typedef enum es_table_kind {
    ES_TABLE_SCATTER = 0,  /* points (x, y[0]) coloured by the category in `label` */
    ES_TABLE_LINES,        /* one curve per y column against x (legend: header names) */
    ES_TABLE_SCREE,        /* bars of y[0] (variances) in percent of the total, and cumulative */
    ES_TABLE_HISTOGRAM,    /* distribution of y[0] */
    ES_TABLE_HEATMAP       /* the whole table as a matrix; a non-numeric first column
                            * holds row labels, a header the column labels */
} es_table_kind;

/* Columns are named by their header name or by 1-based number (a name is
 * looked up first). */
typedef struct es_figure_table_spec {
    es_table_kind kind;        /* ES_TABLE_SCATTER */
    const char *x;             /* scatter and lines; NULL: column 1 for a scatter, the
                                * row number 1, 2, ... for lines */
    int64_t ny;                /* number of y columns; 0: the default column */
    const char *const *y;      /* ny columns (all are read and checked; lines draws
                                * each, the others use y[0]); default "2" for scatter
                                * and lines, "1" for scree and histogram */
    const char *label;         /* scatter: category column, or NULL */
    /* Size, font, title and axis labels; an axis label left NULL is the
     * header name of its column (scatter, lines, histogram x) or the plot's
     * default (es_plot.h). */
    es_plot_frame frame;
    int logy;                  /* lines: log10 y axis (0) */
    int64_t bins;              /* histogram bins; 0: Freedman-Diaconis (es_plot.h) */
    double total;              /* scree: total variance of the percentages; 0: the sum */
    es_colormap cmap;          /* heatmap colours (ES_CMAP_VIRIDIS) */
    int equal;                 /* scatter: equal scales on x and y (0) */
} es_figure_table_spec;

/* Defaults as marked above; the frame as es_plot.h's (640 x 480, 12 pt). */
ES_API void es_figure_table_spec_init(es_figure_table_spec *spec);

/* The kind named "scatter", "lines", "scree", "histogram" or "heatmap", or
 * -1 for any other name. */
ES_API int es_figure_table_kind_from_name(const char *name);

/* Draw the figure `spec` asks for from the table in csv_path to out_path
 * (format by extension as in es_plot.h). info: NULL, or filled by the plot
 * (es_plot_info).
 * Errors: ES_EIO (the table cannot be read, the figure not written),
 * ES_EFORMAT (malformed CSV, no data rows, text in a numeric column, a
 * heat map without numeric columns), ES_ENOTFOUND (no such column),
 * ES_EINVAL (a bad spec, or the plot's own checks), ES_ENOMEM. */
ES_API es_status es_figure_table(es_ctx *ctx, const es_figure_table_spec *spec,
                                 const char *csv_path, const char *out_path,
                                 es_plot_info *info);

/* ---- a stored PCA (edgespace plot-pca) ---------------------------------------- */

/* The PCA `pca_name` of store (NULL: the only one or "default"; see
 * es_study_pca_load) drawn to out_path: the scores on components pc_a and
 * pc_b (1-based; axes "PCk (x.x%)"), one colour per value of the label
 * column color_column (NULL: one colour; it also titles the legend) —
 * Fig. 9 of Fisher et al. — or, when scree is non-zero, the scree plot of
 * all its components against the total variance (pc_a, pc_b and
 * color_column unused). title: NULL for none.
 * Errors: those of es_study_pca_load; ES_EINVAL (a component outside
 * 1..K: "the PCA has K components"), ES_ENOTFOUND (no label column
 * color_column), those of es_plot_scatter / es_plot_scree. */
ES_API es_status es_figure_pca(es_ctx *ctx, es_store *store, const char *pca_name,
                               int64_t pc_a, int64_t pc_b, const char *color_column,
                               int scree, const char *title, const char *out_path);

/* ---- mesh files side by side (edgespace render) ------------------------------- */

/* Read n mesh files (OBJ, PLY, OFF: es_meshdata_read, ES_FORMAT_AUTO)
 * and draw them with es_render under spec (its meshes and nmeshes are
 * ignored: the files fill them) to out_path; rep: NULL or filled.
 *
 * labels: NULL, or n entries; a NULL entry (or labels NULL) is the file's
 * base name when n > 1 and no label for a single mesh.
 *
 * Scalars: nscalars is 0 (none), 1 (one file for every mesh) or n (one per
 * mesh). A scalar file holds one value per line in its first CSV column
 * (more columns are ignored); a first line that is not a number is a
 * header; empty lines and cells, "nan" and "na" are missing (drawn grey and
 * counted in rep->n_nan_scalars). The count decides what the values are
 * for: the mesh's vertices, else its faces, else its edges in es_mesh order
 * (es_mesh_edges of the file's topology, as the store and es_edge_lengths
 * number them).
 * Errors: those of es_meshdata_read and es_mesh_new (named by file);
 * ES_EIO (a scalar file cannot be read); ES_EFORMAT (malformed CSV, text
 * where a value belongs: "FILE:LINE: 'text' is not a number");
 * ES_EMISMATCH (a count that fits neither the vertices, edges nor faces);
 * ES_EINVAL (n < 1, nscalars not 0, 1 or n, NULL paths); those of
 * es_render. */
ES_API es_status es_figure_render_files(es_ctx *ctx, const es_render_spec *spec, int64_t n,
                                        const char *const *mesh_paths, int64_t nscalars,
                                        const char *const *scalar_paths,
                                        const char *const *labels, const char *out_path,
                                        es_render_report *rep);

/* One mesh file coloured by one scalar file, as es_figure_render_files
 * would draw it (spec: cmap, vmin/vmax, range_percentiles, scalar_column;
 * the rest ignored), written to out_path by its extension: .ply (binary,
 * vertex colours), .glb (COLOR_0) or .vtp (VTK XML PolyData for ParaView:
 * the values per point, per cell too for face values, and the colours as
 * UInt8 "colors"). Face and edge values colour each vertex by the mean of
 * the finite values around it, on the colour range of the values given (the
 * one es_figure_render_files' colour bar shows); NaN is ES_NAN_GREY. rep (may be NULL) gets
 * the colour range and the non-finite count. Errors: those of
 * es_figure_render_files; ES_EINVAL for another extension. */
ES_API es_status es_figure_color_file(es_ctx *ctx, const es_render_spec *spec,
                                      const char *mesh_path, const char *scalar_path,
                                      const char *out_path, es_render_report *rep);

/* ---- models and shape variation ---------------------------------------------- */

/* The per-edge tests of a model (es_study_model with opts.edge_term) drawn
 * on the mean mesh of its rows (the Procrustes mean of their positions, in
 * the store's frame): each edge with FDR q < 0.05 coloured by its F on a
 * log scale (colour bar "per-edge F (log)", range the 2nd to 98th
 * percentile of the coloured edges), the others grey (ES_NAN_GREY); faces
 * show the mean of their three edges (grey when one of them is). The number
 * of edges with q < 0.05 is in the title. ES_EINVAL when r has no per-edge tests. */
ES_API es_status es_figure_edge_tests(es_ctx *ctx, es_store *store,
                                      const es_study_model_result *r, const char *out_path);

#define ES_VARIATION_MAX_AXES 8

/* What es_figure_variation draws: one row per axis (a principal component,
 * or a model coefficient), each of four panels: mean - k sd, the mean,
 * mean + k sd, and the mean coloured by each vertex's displacement from
 * the minus to the plus shape. */
typedef struct es_figure_variation_opts {
    const char *pca_name;      /* the PCA of the components (NULL: the only one or "default") */
    int64_t npcs;              /* components to show (0: PC 1) */
    const int64_t *pcs;        /* npcs 1-based component numbers */
    const char *coef;          /* instead: "MODEL:COEF", a coefficient of a stored model in
                                  edge-length space; k is then in its units (for a factor
                                  level, k = 1 is the level's effect) */
    double k;                  /* how far (2) */
    es_embed_opts embed;       /* solver options (es_embed_opts_init) */
    int panel;                 /* panel width and height, pixels (360) */
    const char *title;         /* NULL: automatic */
} es_figure_variation_opts;
ES_API void es_figure_variation_opts_init(es_figure_variation_opts *opts);

typedef struct es_figure_variation_report {
    int64_t naxes;
    es_embed_report mean;                              /* the mean's embedding */
    es_embed_report minus[ES_VARIATION_MAX_AXES];      /* mean - k sd per axis */
    es_embed_report plus[ES_VARIATION_MAX_AXES];       /* mean + k sd per axis */
    double max_displacement[ES_VARIATION_MAX_AXES];    /* largest vertex displacement */
    es_render_report render;
} es_figure_variation_report;

/* Embed the mean and mean +- k sd along each axis (es_study_embed: near the
 * prior of each point's row weights, in the store's frame) and draw them in
 * one frame (one camera and one scale for all panels) with the
 * displacement heat map, to out_path (PNG/SVG/PDF by extension). The store
 * needs faces and, for components, a stored PCA. rep may be NULL. Errors:
 * those of es_study_embed (a point that leaves edge-length space: lower
 * k), es_render; ES_EINVAL for more than ES_VARIATION_MAX_AXES axes. */
ES_API es_status es_figure_variation(es_ctx *ctx, es_store *store,
                                     const es_figure_variation_opts *opts, const char *out_path,
                                     es_figure_variation_report *rep);

#ifdef __cplusplus
}
#endif
#endif
