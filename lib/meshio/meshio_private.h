/* lib/meshio/meshio_private.h — what lib/meshio offers the modules above it
 * beyond es_io.h. Library-private. */
#ifndef EDGESPACE_MESHIO_PRIVATE_H
#define EDGESPACE_MESHIO_PRIVATE_H

#include "core/core_private.h"
#include "edgespace/es_io.h"

/* Write a face list and positions to path in `format` (AUTO: from the
 * extension), replacing a file there only once complete. The testable core
 * of es_meshio_write. */
es_status es__meshdata_write(es_ctx *ctx, const char *path, es_mesh_format format,
                             int64_t nverts, int64_t nfaces, const int64_t *faces,
                             const double *xyz, const uint8_t *rgb);
/* es_meshio_write whose file is staged in set (core_private.h): it appears
 * with the set's other files at es__file_set_commit, or not at all. */
es_status es__mesh_write_staged(es_ctx *ctx, const char *path, es_mesh_format format,
                                const es_mesh *mesh, const double *xyz, es__file_set *set);

#endif
