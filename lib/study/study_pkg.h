/* lib/study/study_pkg.h — what the files of lib/study share. */
#ifndef EDGESPACE_STUDY_PKG_H
#define EDGESPACE_STUDY_PKG_H

#ifndef ES_MODULE_STUDY
#error "study/study_pkg.h is private to lib/study/ (see lib/README.md)"
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

/* ---- embeddings and interpolation by the other papers' methods ------------ */

/* Store a mesh result as /analysis/embed/<name> (what es_study_store_embedding
 * stores, with the per-vertex values given: vdev may be NULL). */
es_status es__study_store_mesh_result(es_ctx *ctx, es_store *store, const char *name,
                                      const es_provenance *prov, const es_mesh *mesh,
                                      const double *vclos, const double *verr,
                                      const double *vdev, const double *target,
                                      const double *xyz, const es_embed_report *r,
                                      const char *init);

/* es_study_interp for opts->method other than edge-length, between two rows
 * (interp_methods.c); name: the result name (without the frame suffix). */
es_status es__study_interp_method(es_ctx *ctx, es_store *store, const es_study_interp_opts *o,
                                  const es_mesh *mesh, const char *name);

#endif
