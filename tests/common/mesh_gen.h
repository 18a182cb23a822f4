/* tests/common/mesh_gen.h — small synthetic meshes for the render tests: a UV
 * sphere, a torus, a bumpy disc, a face-like height field, quads. Faces are
 * oriented so that their normals point along a reference direction
 * (outwards, or +z for height fields). Caller frees xyz and faces. */
#ifndef EDGESPACE_TESTS_MESH_GEN_H
#define EDGESPACE_TESTS_MESH_GEN_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef struct tm_mesh {
    int64_t nv, nf;
    double *xyz;
    int64_t *faces;
} tm_mesh;

typedef void (*tm_grid_fn)(double u, double v, const void *ud, double p[3], double ref[3]);

/* A (nu+1) x (nv+1) grid over [0,1]^2 mapped by fn; wrap_u / wrap_v join
 * the seams (no duplicate vertices). Every face is flipped if needed so its
 * normal agrees with the reference direction fn gives at its first corner. */
tm_mesh tm_grid(int nu, int nvv, int wrap_u, int wrap_v, tm_grid_fn fn,
                              const void *ud);

void tm_free(tm_mesh *m);

/* A closed UV sphere of radius r: latitude rings plus two pole vertices. */
tm_mesh tm_sphere(double r, int nlat, int nlon);

void tm_torus_fn(double u, double v, const void *ud, double p[3], double ref[3]);

tm_mesh tm_torus(double R, double r, int nu, int nv);

/* A disc of radius 1 in the xy plane (polar grid; the centre row is nu
 * coincident vertices, so the first ring of triangles has degenerate
 * members but no hole) with bumps in z; faces look to +z. */
void tm_disc_fn(double u, double v, const void *ud, double p[3], double ref[3]);

tm_mesh tm_bumpy_disc(int nu, int nv);

/* A face-like height field (y up, looking to +z): an ellipsoidal cap 1.4
 * tall and 1 wide with a nose, brow ridge, eye sockets, cheeks, lips and
 * chin. Built on a polar grid of the ellipse. */
double tm_gauss(double x, double y, double cx, double cy, double sx, double sy);

void tm_face_fn(double u, double v, const void *ud, double p[3], double ref[3]);

tm_mesh tm_face(int nu, int nv);

#endif
