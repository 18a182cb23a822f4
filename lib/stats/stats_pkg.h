/* lib/stats/stats_pkg.h — helpers shared by stats.c, pca.c and
 * pca_randomized.c: block sizes and checked reads from an es_source. */
#ifndef EDGESPACE_STATS_PKG_H
#define EDGESPACE_STATS_PKG_H

#ifndef ES_MODULE_STATS
#error "stats/stats_pkg.h is private to lib/stats/ (see lib/README.md)"
#endif

#include "edgespace/es_stats.h"
#include "core/core_private.h"

/* Check the source's shape and reader. `what` names the caller. */
es_status es__source_check(es_ctx *ctx, const es_source *src, const char *what);

/* Rows per block: src->block if set, else about 128 MiB of doubles; never
 * more than N, at least 1. */
int64_t es__source_block(const es_source *src);

/* Read rows [row0, row0+n) into buf (E x n, ld E) and check that every
 * value is finite (ES_ENUMERIC naming the row and edge otherwise). */
es_status es__source_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n,
                          double *buf);

/* Fit helpers of the randomized route (pca_randomized.c). */
es_status es__pca_fit_randomized(es_ctx *ctx, const es_source *src, const es_pca_opts *opts,
                                 es_pca *pca);
/* Allocate an es_pca with E, N, K set and all arrays allocated. */
es_status es__pca_alloc(es_ctx *ctx, int64_t nedges, int64_t nrows, int64_t ncomp,
                        es_pca **out);
/* Flip components so the largest-magnitude entry is positive (scores too),
 * fill explained ratios. */
void es__pca_finish(es_pca *pca);

#endif
