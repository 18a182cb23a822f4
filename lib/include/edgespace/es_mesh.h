/* lib/include/edgespace/es_mesh.h — topology of a triangle mesh.
 *
 * An es_mesh is built from a face list (and optionally reference vertex
 * positions) and is immutable afterwards. It must be an oriented 2-manifold,
 * possibly with boundary, any number of components and any genus.
 *
 * Conventions (datasets-spec/store-format.md repeats them):
 *  - Faces are 3 x F, column f = (a, b, c) counter-clockwise, 0-based.
 *  - Edges are the unique undirected edges, stored 2 x E as (min, max) and
 *    sorted lexicographically by (min vertex, max vertex). Edge id = column.
 *  - face_edges (3 x F): entry k of face f is the edge joining corner k and
 *    corner k+1 (mod 3), i.e. edge (f[k], f[k+1]).
 *  - edge_faces (2 x E): row 0 is the face holding the half-edge min->max,
 *    row 1 the face holding max->min; -1 where there is none (boundary).
 *  - Vertex stars (fans), stored CSR: for vertex v, neighbours
 *    u_0..u_{k-1} counter-clockwise with respect to the face orientation, so
 *    face j of the fan is (v, u_j, u_{j+1}) and holds the half-edge v->u_j.
 *    An interior vertex has k neighbours and k faces (face k-1 is
 *    (v, u_{k-1}, u_0)) and its fan starts at the spoke with the smallest
 *    edge id (which is the smallest neighbour index). A boundary vertex has k
 *    neighbours and k-1 faces; its fan starts at the boundary spoke whose
 *    face lies counter-clockwise after it, and ends at the other boundary
 *    spoke. This is the order the embedding's vertex-figure walk needs.
 */
#ifndef EDGESPACE_ES_MESH_H
#define EDGESPACE_ES_MESH_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct es_mesh es_mesh;

/* Build the topology of `nfaces` triangles over `nverts` vertices.
 * faces: 3 x nfaces, 0-based. xyz: 3 x nverts reference positions or NULL
 * (copied). Fails with ES_ETOPOLOGY, naming the face/edge/vertex, on:
 * an index out of range, a repeated index in a face, an edge shared by 3+
 * faces, a duplicated face, a non-manifold vertex (its faces form more than
 * one fan), inconsistent orientation of two faces sharing an edge.
 * Unreferenced vertices are allowed and warned about (log callback).
 * Fails with ES_EINVAL, naming the vertex, on a non-finite position. */
ES_API es_status es_mesh_new(es_ctx *ctx, int64_t nverts, int64_t nfaces,
                             const int64_t *faces, const double *xyz, es_mesh **out);
ES_API void es_mesh_free(es_mesh *mesh);

ES_API int64_t es_mesh_nverts(const es_mesh *mesh);
ES_API int64_t es_mesh_nfaces(const es_mesh *mesh);
ES_API int64_t es_mesh_nedges(const es_mesh *mesh);

/* Borrowed arrays, valid as long as the mesh. */
ES_API const int64_t *es_mesh_faces(const es_mesh *mesh);      /* 3 x F */
ES_API const int64_t *es_mesh_edges(const es_mesh *mesh);      /* 2 x E */
ES_API const int64_t *es_mesh_face_edges(const es_mesh *mesh); /* 3 x F */
ES_API const int64_t *es_mesh_edge_faces(const es_mesh *mesh); /* 2 x E */
/* Reference positions (3 x V) or NULL if none were given. */
ES_API const double *es_mesh_xyz(const es_mesh *mesh);

/* Edge id of {a, b}, or -1 if they are not joined. O(log degree). */
ES_API int64_t es_mesh_find_edge(const es_mesh *mesh, int64_t a, int64_t b);

/* Vertex stars, CSR: the star of v occupies [offsets[v], offsets[v+1]) of
 * the neighbour and spoke-edge arrays, and the same range minus one slot
 * (boundary) of the face array: star_faces[offsets[v] + j] is face j of
 * the fan (undefined in the last slot of a boundary vertex, set to -1).
 * offsets has V+1 entries. Isolated vertices have empty stars. */
ES_API const int64_t *es_mesh_star_offsets(const es_mesh *mesh);
ES_API const int64_t *es_mesh_star_verts(const es_mesh *mesh);
ES_API const int64_t *es_mesh_star_edges(const es_mesh *mesh);
ES_API const int64_t *es_mesh_star_faces(const es_mesh *mesh);

/* Per-vertex and per-edge boundary flags (1 on the boundary, else 0). */
ES_API const uint8_t *es_mesh_vertex_on_boundary(const es_mesh *mesh);
ES_API const uint8_t *es_mesh_edge_on_boundary(const es_mesh *mesh);

typedef struct es_mesh_summary {
    int64_t nverts, nfaces, nedges;
    int64_t n_boundary_edges, n_boundary_verts, n_boundary_loops;
    int64_t n_components;       /* connected components of referenced vertices */
    int64_t n_unreferenced;     /* vertices in no face */
    int64_t euler;              /* V - E + F over referenced vertices */
    int64_t genus;              /* per component sum; -1 if not well defined */
} es_mesh_summary;
ES_API void es_mesh_summarize(const es_mesh *mesh, es_mesh_summary *out);

/* Boundary loops, CSR: loop i is the vertex sequence
 * loop_verts[loop_offsets[i] .. loop_offsets[i+1]), in the order that
 * follows the boundary half-edges. Borrowed. */
ES_API int64_t es_mesh_boundary_loops(const es_mesh *mesh, const int64_t **loop_offsets,
                                      const int64_t **loop_verts);

/* Component id (0-based, by lowest vertex) of every vertex; -1 for
 * unreferenced vertices. Borrowed. */
ES_API const int64_t *es_mesh_vertex_component(const es_mesh *mesh);

/* Fingerprint of (nverts, face list): a 64-bit FNV-1a hash over the
 * little-endian int64 values, as 16 lowercase hex digits plus NUL.
 * Meshes are in correspondence iff vertex count and faces are equal. */
ES_API void es_mesh_fingerprint(const es_mesh *mesh, char out[17]);
/* Same hash from a raw face list, without building a mesh. */
ES_API void es_faces_fingerprint(int64_t nverts, int64_t nfaces, const int64_t *faces,
                                 char out[17]);

/* 1-to-4 midpoint subdivision. The input must be an oriented manifold
 * (es_mesh_new's checks, ES_ETOPOLOGY otherwise). Output vertices: the V
 * old ones, then one per edge in edge-id order (edges sorted by (min, max),
 * es_mesh.h): vertex V + e is the midpoint of edge e. Face f = (a, b, c)
 * becomes faces 4f .. 4f+3: (a, m_ab, m_ca), (m_ab, b, m_bc),
 * (m_ca, m_bc, c), (m_ab, m_bc, m_ca).
 * xyz: 3 x nverts x nshapes (nshapes >= 0; NULL when 0); *xyz_out gets
 * 3 x (V + E) x nshapes (NULL when nshapes is 0). *faces_out: 3 x 4F.
 * Outputs are allocated through ctx; release them with es_free. */
ES_API es_status es_mesh_subdivide(es_ctx *ctx, int64_t nverts, int64_t nfaces,
                                   const int64_t *faces, int64_t nshapes, const double *xyz,
                                   int64_t *nverts_out, int64_t **faces_out,
                                   double **xyz_out);

#ifdef __cplusplus
}
#endif
#endif
