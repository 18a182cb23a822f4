/* lib/store/store_pkg.h — store entry points shared inside the library and
 * with its tests, not public: creating a store from raw topology arrays
 * (es_store_create wraps it for an es_mesh). */
#ifndef EDGESPACE_STORE_PKG_H
#define EDGESPACE_STORE_PKG_H

#ifndef ES_MODULE_STORE
#error "store/store_pkg.h is private to lib/store/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "edgespace/es_store.h"

/* faces: 3 x nfaces, edges: 2 x nedges (as es_mesh_faces/es_mesh_edges),
 * fingerprint: 16 hex digits (es_mesh_fingerprint) or "". */
es_status es__store_create_raw(es_ctx *ctx, const char *path, int64_t nverts, int64_t nfaces,
                               const int64_t *faces, int64_t nedges, const int64_t *edges,
                               const char *fingerprint, es_store **out);

#endif
