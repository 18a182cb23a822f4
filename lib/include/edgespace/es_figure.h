/* lib/include/edgespace/es_figure.h — lib/figure's figures of whole studies:
 * what a command or notebook draws from stored results in one call (the
 * plot and render primitives are es_plot.h and es_render.h). Built only
 * when libedgespace has figures (es_config.h: ES_HAVE_FIGURES).
 */
#ifndef EDGESPACE_ES_FIGURE_H
#define EDGESPACE_ES_FIGURE_H

#include "es_core.h"
#include "es_compare.h"
#include "es_store.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The comparison study's figures in dir (made if missing): heatmap_lengths.svg,
 * heatmap_procrustes.svg (the two distance matrices) and pairs_scatter.svg
 * (distance pairs, coloured by group pair when group is given). ids: n names
 * (NULL: 1-based numbers); group_names: ngroups names (NULL: numbers). */
ES_API es_status es_figure_compare_write(es_ctx *ctx, const es_compare_result *res,
                                         const char *const *ids, const int64_t *group,
                                         const char *const *group_names, const char *dir);

/* es_study_compare (es_study.h) and, with out_dir, its figures beside its
 * tables. */
ES_API es_status es_figure_compare(es_ctx *ctx, es_store *store, const char *gpa_name,
                                   const char *by, const es_compare_opts *opts,
                                   const char *name, const char *out_dir, const char *command,
                                   es_compare_result **res);

#ifdef __cplusplus
}
#endif
#endif
