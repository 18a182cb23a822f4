/* lib/mesh/mesh_private.h — what lib/mesh offers the modules above it
 * beyond its public headers (es_mesh.h, es_geom.h). Library-private. */
#ifndef EDGESPACE_MESH_PRIVATE_H
#define EDGESPACE_MESH_PRIVATE_H

#include "core/core_private.h"
#include "edgespace/es_mesh.h"

/* es_mesh_new; warn_unreferenced 0 leaves the warning about vertices in no
 * face to a caller that can name the file (or has warned once already). */
es_status es__mesh_new(es_ctx *ctx, int64_t nverts, int64_t nfaces, const int64_t *faces,
                       const double *xyz, int warn_unreferenced, es_mesh **out);

/* One more holder of m (immutable once made): es_mesh_free then frees it
 * only when the last holder lets go. Returns m. The store hands its
 * topology out this way (es_store_mesh), so that the commands that ask for
 * it more than once build it once. */
es_mesh *es__mesh_ref(es_mesh *m);

#endif
