/* lib/core/vec3.h — 3-vectors as double[3], written once for every module
 * (mesh geometry, bending, the morphs, the renderer). Library-private.
 * The cross product reads both inputs before it writes, so out may be a or
 * b; each operation is the one expression the copies it replaced computed,
 * term for term, so results are unchanged to the bit. */
#ifndef EDGESPACE_CORE_VEC3_H
#define EDGESPACE_CORE_VEC3_H

#include <math.h>

static inline void es__v3_sub(const double *a, const double *b, double *out)
{
    out[0] = a[0] - b[0], out[1] = a[1] - b[1], out[2] = a[2] - b[2];
}

static inline void es__v3_cross(const double *a, const double *b, double *out)
{
    double c0 = a[1] * b[2] - a[2] * b[1], c1 = a[2] * b[0] - a[0] * b[2];
    double c2 = a[0] * b[1] - a[1] * b[0];
    out[0] = c0, out[1] = c1, out[2] = c2;
}

static inline double es__v3_dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double es__v3_norm(const double *a) { return sqrt(es__v3_dot(a, a)); }

#endif
