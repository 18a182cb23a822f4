/* lib/include/edgespace/es_point.h — points of edge-length space written as
 * expressions: "mean[expression=neutral] + diff:smile", "mean + 2*pc:1",
 * "lerp(row:s001_neutral, row:s002_neutral, 1.5)".
 *
 * datasets-spec/point-syntax.md is the reference of the syntax. Numbers
 * fold at parse time, so every valid expression is a linear combination
 * sum_i c_i * leaf_i of leaves:
 *   mean, mean[col=value,...]   mean of all rows / of the rows matching all
 *                               filters                          (a shape)
 *   row:ID                      one stored row by id              (a shape)
 *   file:PATH.obj               a mesh file (.obj, .ply, .off)    (a shape)
 *   pc:K                        principal component K >= 1, in units of
 *                               its standard deviation       (a direction)
 *   diff:NAME                   a stored mean difference     (a direction)
 *   coef:MODEL:COEF             a coefficient of a stored linear model
 *                               (es_study_model; COEF a design column such
 *                               as age or expression=happy)  (a direction)
 * The expression is parsed once (es_point_parse), then evaluated through a
 * resolver callback that looks the leaves up (es_point_eval), so that the
 * syntax is independent of the store.
 *
 * Scale. Shapes carry a scale (sum of raw edge lengths; for mean[...] the
 * mean scale of the rows that define it); directions carry none. The scale
 * to embed a point at is sum_i c_i s_i / sum_i c_i over the shape leaves:
 * the same affine weights that combine the shapes combine their scales
 * (mean + 2*pc:1 has the mean's scale; lerp(a, b, t) has (1-t) s_a + t s_b).
 * When the shape weights sum to 0 (a pure direction such as
 * "diff:smile - diff:frown") there is no scale (NaN). Shape weights that do
 * not sum to 1 give lengths that do not sum to 1; es_point_eval warns.
 */
#ifndef EDGESPACE_ES_POINT_H
#define EDGESPACE_ES_POINT_H

#include "es_core.h"
#include "es_geom.h"
#include "es_mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum es_point_leaf {
    ES_POINT_MEAN = 0,  /* arg: the filter "col=value,..." ("" for all rows;
                           a value holding ',' is quoted, as es_store_select reads) */
    ES_POINT_ROW,       /* arg: the row id */
    ES_POINT_FILE,      /* arg: the path */
    ES_POINT_PC,        /* index: K (1-based), arg the PCA named inline (pc:NAME:K) or "" */
    ES_POINT_DIFF,      /* arg: the difference's name */
    ES_POINT_COEF       /* arg: "MODEL/COEF", the model's name and the coefficient's */
} es_point_leaf;

typedef struct es_point_expr es_point_expr;

/* Parse `text`. Syntax errors are ES_EFORMAT with a message that names the
 * 1-based column: "point: column 12: expected ')'". Caller owns *out. */
ES_API es_status es_point_parse(es_ctx *ctx, const char *text, es_point_expr **out);
ES_API void es_point_expr_free(es_point_expr *expr);

/* The linear combination: number of terms, and term i (coefficient, kind,
 * argument string borrowed from expr, component index for ES_POINT_PC). */
ES_API int64_t es_point_expr_nterms(const es_point_expr *expr);
ES_API void es_point_expr_term(const es_point_expr *expr, int64_t i, double *coef,
                               es_point_leaf *kind, const char **arg, int64_t *index);

/* Looks up one leaf. Write the E values of the leaf into vec:
 *  shapes (MEAN, ROW, FILE): scale-normalized lengths, and *scale = the
 *    shape's scale (mean scale of the rows for MEAN);
 *  PC: the unit component K, and *scale = its standard deviation
 *    (sqrt of the eigenvalue), by which the evaluator multiplies it;
 *  DIFF, COEF: the difference or coefficient vector; *scale is ignored.
 * weights: NULL, or the nrows entries given to es_point_eval_rows, zero on
 *    entry: the leaf as a combination of the stored rows it comes from,
 *    vec ~ sum_i weights[i] row_i (normalized lengths), exactly for means,
 *    rows, components, differences and coefficients, by ridge regression
 *    for a file. A
 *    shape's weights sum to 1, a direction's to 0. Evaluating them costs
 *    nothing extra for most leaves, so the embedding can apply the same
 *    weights to the rows' dihedrals and positions (its prior).
 * Return ES_OK or a status with a message on ctx (e.g. ES_ENOTFOUND). */
typedef es_status (*es_point_resolve_fn)(es_ctx *ctx, void *userdata, es_point_leaf kind,
                                         const char *arg, int64_t index, double *vec,
                                         double *scale, double *weights);

typedef struct es_point_info {
    double weight;        /* sum of the coefficients of the shape leaves */
    double scale;         /* scale to embed at (see above); NaN without shapes */
    double length_sum;    /* sum of the point's lengths (== weight for normalized inputs) */
    int64_t nshapes;      /* shape leaves */
    int64_t ndirections;  /* direction leaves */
    int checked;          /* 1 when a mesh was given and `validity` is filled */
    es_validity validity; /* es_lengths_check of the point (positive lengths,
                             triangle inequality per face, rtol 0) */
} es_point_info;

/* Evaluate expr: vec (nedges) = sum_i c_i leaf_i. info may be NULL. With a
 * mesh (its E must equal nedges) info->validity reports where the point
 * leaves the realizable region; an invalid point is not an error. A failing
 * resolver's status is returned with its message prefixed by the leaf
 * ("point: row:s009: ..."). */
ES_API es_status es_point_eval(es_ctx *ctx, const es_point_expr *expr, int64_t nedges,
                               es_point_resolve_fn resolve, void *userdata,
                               const es_mesh *mesh, double *vec, es_point_info *info);

/* The same, carrying the leaves' row weights through the combination:
 * weights (nrows) = sum_i c_i weights(leaf_i), with each pc:K's standard
 * deviation applied as to its vector. nrows 0 and weights NULL: as
 * es_point_eval. */
ES_API es_status es_point_eval_rows(es_ctx *ctx, const es_point_expr *expr, int64_t nedges,
                                    int64_t nrows, es_point_resolve_fn resolve,
                                    void *userdata, const es_mesh *mesh, double *vec,
                                    double *weights, es_point_info *info);

#ifdef __cplusplus
}
#endif
#endif
