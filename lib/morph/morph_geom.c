/* lib/morph/morph_geom.c — the small pieces of geometry the methods of
 * lib/morph share: placing a triangle's third vertex from its lengths and
 * its plane (Winkler et al.'s leaves, Wuhrer et al.'s tree walk), rotating
 * about an axis (a dihedral), a triangle's normal.
 */
#include "morph/morph_pkg.h"

#include <math.h>

double es__v3_normalize(double *v)
{
    double n = sqrt(es__v3_dot(v, v));
    if (n > 0) v[0] /= n, v[1] /= n, v[2] /= n;
    return n;
}

double es__tri_normal(const double *a, const double *b, const double *c, double *n)
{
    double u[3], w[3];
    es__v3_sub(b, a, u);
    es__v3_sub(c, a, w);
    es__v3_cross(u, w, n);
    return es__v3_normalize(n);
}

void es__rotate_axis(const double *v, const double *u, double a, double *out)
{
    /* Rodrigues: v cos a + (u x v) sin a + u (u . v)(1 - cos a) */
    double c = cos(a), s = sin(a), uv = es__v3_dot(u, v), x[3];
    es__v3_cross(u, v, x);
    for (int i = 0; i < 3; i++) out[i] = v[i] * c + x[i] * s + u[i] * uv * (1 - c);
}

void es__apex(const double *p, const double *q, const double *n, double l_pq, double l_pr,
              double l_qr, double *r)
{
    double u[3], m[3], x, y2, y;
    es__v3_sub(q, p, u);
    es__v3_normalize(u);
    es__v3_cross(n, u, m);   /* in the plane, to the left of p -> q about n */
    es__v3_normalize(m);
    /* foot of the apex on pq, measured from p (law of cosines) */
    x = (l_pr * l_pr - l_qr * l_qr + l_pq * l_pq) / (2 * l_pq);
    y2 = l_pr * l_pr - x * x;
    y = y2 > 0 ? sqrt(y2) : 0;
    for (int i = 0; i < 3; i++) r[i] = 0.5 * (p[i] + q[i]) + (x - 0.5 * l_pq) * u[i] + y * m[i];
}
