/* lib/synth/synth_pkg.h — what synth.c and synth_shapes.c share: allocation
 * of a set and its labels, and the generators. Never installed. */
#ifndef EDGESPACE_SYNTH_PKG_H
#define EDGESPACE_SYNTH_PKG_H

#ifndef ES_MODULE_SYNTH
#error "synth/synth_pkg.h is private to lib/synth/ (see lib/README.md)"
#endif

#include "edgespace/es_synth.h"
#include "core/core_private.h"

/* Allocate the arrays of a set of nmembers x (nverts, nfaces) with nlabels
 * label columns; strings start NULL. */
es_status es__synth_alloc(es_ctx *ctx, es_synth_set *s, int64_t nverts, int64_t nfaces,
                          int64_t nmembers, int64_t nlabels);
/* Set a string slot (a name, label name or label) from a format. */
es_status es__synth_str(es_ctx *ctx, char **slot, const char *fmt, ...) ES__PRINTF(3, 4);

/* Generators (synth_shapes.c); opts are already defaulted and checked. */
es_status es__synth_barbell(es_ctx *ctx, const es_synth_opts *o, es_synth_set *s);
/* kind: 0 open tube, 1 closed (capped), 2 open elliptic tube bent and twisted */
es_status es__synth_tube(es_ctx *ctx, const es_synth_opts *o, int kind, es_synth_set *s);
es_status es__synth_strip(es_ctx *ctx, const es_synth_opts *o, es_synth_set *s);
es_status es__synth_face(es_ctx *ctx, const es_synth_opts *o, es_synth_set *s);

#endif
