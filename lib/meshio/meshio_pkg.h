/* lib/meshio/meshio_pkg.h — what the mesh readers and writers share.
 *
 * mesh_io.c dispatches by format and owns the pieces every format needs: a
 * growable vertex/face builder, the exact fast decimal parser, integer
 * parsing and file reading. mesh_io_obj.c, mesh_io_ply.c and mesh_io_off.c
 * hold one format each. Never installed.
 */
#ifndef EDGESPACE_MESHIO_PKG_H
#define EDGESPACE_MESHIO_PKG_H

#ifndef ES_MODULE_MESHIO
#error "meshio/meshio_pkg.h is private to lib/meshio/ (see lib/README.md)"
#endif

#include "core/text.h"
#include "core/files.h"
#include "meshio/meshio_private.h"

/* Growable arrays behind an es_meshdata; capacities in vertices/faces. */
typedef struct es__mdbuild {
    es_ctx *ctx;
    es_meshdata *md;
    int64_t vcap, fcap;
} es__mdbuild;

void es__mdbuild_init(es__mdbuild *b, es_ctx *ctx, es_meshdata *md);
/* Make room for `more` further vertices / faces (ES_ENOMEM, ES_ERANGE). */
es_status es__mdbuild_reserve_verts(es__mdbuild *b, int64_t more);
es_status es__mdbuild_reserve_faces(es__mdbuild *b, int64_t more);
/* Give back slack capacity at the end of a successful parse. */
void es__mdbuild_finish(es__mdbuild *b);

static inline es_status es__mdbuild_vertex(es__mdbuild *b, double x, double y, double z)
{
    es_meshdata *md = b->md;
    if (md->nverts == b->vcap) {
        es_status rc = es__mdbuild_reserve_verts(b, 1);
        if (rc != ES_OK) return rc;
    }
    double *p = md->xyz + 3 * md->nverts++;
    p[0] = x;
    p[1] = y;
    p[2] = z;
    return ES_OK;
}

static inline es_status es__mdbuild_face(es__mdbuild *b, int64_t a, int64_t c1, int64_t c2)
{
    es_meshdata *md = b->md;
    if (md->nfaces == b->fcap) {
        es_status rc = es__mdbuild_reserve_faces(b, 1);
        if (rc != ES_OK) return rc;
    }
    int64_t *p = md->faces + 3 * md->nfaces++;
    p[0] = a;
    p[1] = c1;
    p[2] = c2;
    return ES_OK;
}

/* The format parsers: md is empty on entry and on failure the caller
 * clears it. */
es_status es__obj_parse(es_ctx *ctx, const char *name, const char *buf, size_t len,
                        es_meshdata *md);
es_status es__ply_parse(es_ctx *ctx, const char *name, const char *buf, size_t len,
                        es_meshdata *md);
es_status es__off_parse(es_ctx *ctx, const char *name, const char *buf, size_t len,
                        es_meshdata *md);

/* Writers over raw arrays (es_meshio_write gives them a mesh's faces).
 * faces 3 x nfaces 0-based, xyz 3 x nverts, rgb NULL or 3 x nverts. */
es_status es__obj_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts,
                        int64_t nfaces, const int64_t *faces, const double *xyz);
es_status es__ply_write(es_ctx *ctx, const char *path, FILE *f, bool binary,
                        int64_t nverts, int64_t nfaces, const int64_t *faces,
                        const double *xyz, const uint8_t *rgb);
es_status es__off_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts,
                        int64_t nfaces, const int64_t *faces, const double *xyz);
/* Write-only formats (mesh_io_stl_glb.c): binary STL with facet normals,
 * glTF 2.0 binary with optional per-vertex colours. */
es_status es__stl_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts, int64_t nfaces,
                        const int64_t *faces, const double *xyz);
es_status es__glb_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts, int64_t nfaces,
                        const int64_t *faces, const double *xyz, const uint8_t *rgb);

#endif
