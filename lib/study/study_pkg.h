/* lib/study/study_pkg.h — what the files of lib/study share. */
#ifndef EDGESPACE_STUDY_PKG_H
#define EDGESPACE_STUDY_PKG_H

#ifndef ES_MODULE_STUDY
#error "study/study_pkg.h is private to lib/study/ (see lib/README.md)"
/* Store a model as model/<o->name> (model_results.c). */
es_status es__model_save(es_ctx *ctx, es_store *s, const es_study_model_opts *o,
                         const es_study_model_result *r);

#endif

#include "core/core_private.h"
#include "edgespace/es_study.h"

/* A CSV table being written: to standard output for path "-", else to a
 * part file that replaces path only once complete (es__replace_begin). An
 * HDF5 file at path (a store given by mistake) is refused. */
typedef struct es__table_out {
    es__file_replace w;
    FILE *f;
    const char *path;
} es__table_out;
es_status es__table_begin(es_ctx *ctx, const char *path, es__table_out *t);
/* Finish (rc ES_OK) or abandon (rc != ES_OK: the old file stays); returns
 * rc or the write error. */
es_status es__table_end(es_ctx *ctx, es__table_out *t, es_status rc);
/* ",<value>" with 17 significant digits (round trip). */
void es__table_number(FILE *f, double v);

/* Store a model as model/<o->name> (model_results.c). */
es_status es__model_save(es_ctx *ctx, es_store *s, const es_study_model_opts *o,
                         const es_study_model_result *r);

#endif
