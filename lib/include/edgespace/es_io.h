/* lib/include/edgespace/es_io.h — reading and writing mesh files.
 *
 * Readers: OBJ (v and f lines; f a, a/b, a//c, a/b/c; negative indices;
 * vt, vn, g, o, s, usemtl, mtllib and comments ignored), PLY (ascii,
 * binary_little_endian, binary_big_endian; any extra element properties;
 * any list count and index types), OFF. Polygons with more than three
 * corners are fan-triangulated from their first corner (the same in every
 * file that shares the face list), with a warning through the log callback.
 * Every error names the file and the line (text) or byte offset (binary)
 * and says what was wrong.
 *
 * Readers return plain arrays (es_meshdata) so that a set of files can be
 * checked for correspondence before any topology is built.
 */
#ifndef EDGESPACE_ES_IO_H
#define EDGESPACE_ES_IO_H

#include "es_core.h"
#include "es_mesh.h"

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum es_mesh_format {
    ES_FORMAT_AUTO = 0, /* from the file name's extension */
    ES_FORMAT_OBJ,
    ES_FORMAT_PLY,      /* writer: binary little endian */
    ES_FORMAT_PLY_ASCII,
    ES_FORMAT_OFF,
    ES_FORMAT_STL,      /* written only: binary, float32, facet normals */
    ES_FORMAT_GLB       /* written only: glTF 2.0 binary, float32 positions, uint32
                         * indices, vertex colours as COLOR_0 */
} es_mesh_format;

typedef struct es_meshdata {
    int64_t nverts;
    int64_t nfaces;
    double *xyz;        /* 3 x nverts, owned (free with es_meshdata_clear) */
    int64_t *faces;     /* 3 x nfaces, 0-based, owned */
    int64_t n_polygons_split; /* input polygons with > 3 corners */
} es_meshdata;

/* Read a mesh file. On failure *out is left empty (all zero/NULL). */
ES_API es_status es_meshdata_read(es_ctx *ctx, const char *path, es_mesh_format format,
                                  es_meshdata *out);
/* Parse a file's contents from memory; `name` is used in messages. */
ES_API es_status es_meshdata_parse(es_ctx *ctx, const char *name, const char *buf,
                                   size_t len, es_mesh_format format, es_meshdata *out);
ES_API void es_meshdata_clear(es_ctx *ctx, es_meshdata *md);

/* Read a file and build its topology (positions kept as reference xyz).
 * Errors: those of es_meshdata_read, then those of es_mesh_new (e.g.
 * ES_ETOPOLOGY) with the file name put in front of the message. */
ES_API es_status es_meshio_read(es_ctx *ctx, const char *path, es_mesh **out);

/* The positions (3 x V) of a mesh file whose face list is that of `mesh`
 * (a new shape of a study's topology); ES_EMISMATCH naming the file when
 * it is not, and the errors of es_meshdata_read. */
ES_API es_status es_meshio_read_positions(es_ctx *ctx, const es_mesh *mesh, const char *path,
                                          double *xyz);

/* Write positions xyz (3 x V) with mesh's faces. Format from the extension
 * when ES_FORMAT_AUTO (.obj, .ply = binary little endian, .off, .stl, .glb).
 * xyz: NULL writes the mesh's reference positions (ES_EINVAL if it has none).
 * vertex_rgb: NULL or 3 x V bytes of per-vertex colour (PLY and GLB).
 * OBJ, PLY and OFF coordinates are written exactly (%.17g, or binary
 * doubles); reading the file back gives the same arrays. STL and GLB hold
 * float32 for viewers and printers and are not read back. ES_EIO names the path and the reason.
 * The file is written beside the target (PATH.PID.part) and renamed over
 * it when complete: a failed write leaves an existing file as it was; the
 * old file's permissions are kept and a symlink is written through. */
ES_API es_status es_meshio_write(es_ctx *ctx, const char *path, es_mesh_format format,
                                 const es_mesh *mesh, const double *xyz,
                                 const uint8_t *vertex_rgb);

/* Format guessed from a path's extension (ES_FORMAT_AUTO if unknown). */
ES_API es_mesh_format es_meshio_format_from_path(const char *path);


/* Normalized edge lengths (E) and scale of a mesh file whose face list is
 * that of `mesh` (ES_EMISMATCH otherwise, naming the file). */
ES_API es_status es_meshio_lengths_from_file(es_ctx *ctx, const es_mesh *mesh, const char *path,
                                             double *len, double *scale);

#ifdef __cplusplus
}
#endif
#endif
