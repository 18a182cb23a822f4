/* lib/mesh/mesh_pkg.h — the layout of es_mesh, shared by mesh.c,
 * mesh_stars.c and mesh_boundary.c. Never installed.
 *
 * All arrays are owned by the mesh and allocated through its context. The
 * build runs in stages (edges, stars, boundary/components), each in its own
 * file, so that every stage can be read and tested on its own.
 */
#ifndef EDGESPACE_MESH_PKG_H
#define EDGESPACE_MESH_PKG_H

#ifndef ES_MODULE_MESH
#error "mesh/mesh_pkg.h is private to lib/mesh/ (see lib/README.md)"
#endif

#include <stdatomic.h>
#include "mesh/mesh_private.h"

struct es_mesh {
    es_ctx *ctx;
    _Atomic int64_t refs; /* holders (es__mesh_ref); es_mesh_free drops one */
    int64_t nv, nf, ne;
    int64_t *faces;       /* 3 x F */
    double *xyz;          /* 3 x V or NULL */
    int64_t *edges;       /* 2 x E, (min, max), sorted */
    int64_t *edge_start;  /* V + 1: edges with min vertex v are [edge_start[v], edge_start[v+1]) */
    int64_t *face_edges;  /* 3 x F */
    int64_t *edge_faces;  /* 2 x E */
    uint8_t *vert_bnd;    /* V */
    uint8_t *edge_bnd;    /* E */
    int64_t *star_off;    /* V + 1 */
    int64_t *star_verts, *star_edges, *star_faces;
    int64_t nloops;
    int64_t *loop_off;    /* nloops + 1 */
    int64_t *loop_verts;
    int64_t *comp;        /* V, -1 for unreferenced vertices */
    es_mesh_summary sum;
};

/* Stage 2 (mesh_stars.c): vertex stars in CSR and the non-manifold-vertex
 * check. Needs faces, edges, face_edges, edge_faces and the boundary flags. */
es_status es__mesh_build_stars(es_ctx *ctx, es_mesh *m);

/* Stage 3 (mesh_boundary.c): boundary loops, components, Euler
 * characteristic and genus. Needs the stars. */
es_status es__mesh_build_boundary(es_ctx *ctx, es_mesh *m);

#endif
