/* tests/common/mesh_gen.c — see mesh_gen.h. */
#include "mesh_gen.h"

tm_mesh tm_grid(int nu, int nvv, int wrap_u, int wrap_v, tm_grid_fn fn,
                              const void *ud)
{
    tm_mesh m;
    int cu = wrap_u ? nu : nu + 1, cv = wrap_v ? nvv : nvv + 1;
    m.nv = (int64_t)cu * cv;
    m.nf = 2 * (int64_t)nu * nvv;
    m.xyz = malloc(3 * (size_t)m.nv * sizeof *m.xyz);
    m.faces = malloc(3 * (size_t)m.nf * sizeof *m.faces);
    double *refs = malloc(3 * (size_t)m.nv * sizeof *refs);
    for (int j = 0; j < cv; j++)
        for (int i = 0; i < cu; i++)
            fn((double)i / nu, (double)j / nvv, ud, m.xyz + 3 * (j * cu + i),
               refs + 3 * (j * cu + i));
    int64_t f = 0;
    for (int j = 0; j < nvv; j++)
        for (int i = 0; i < nu; i++) {
            int64_t a = j * cu + i, b = j * cu + (i + 1) % cu, c = ((j + 1) % cv) * cu + i,
                    d = ((j + 1) % cv) * cu + (i + 1) % cu;
            int64_t t[2][3] = {{a, b, d}, {a, d, c}};
            for (int k = 0; k < 2; k++, f++) {
                const double *p0 = m.xyz + 3 * t[k][0], *p1 = m.xyz + 3 * t[k][1],
                             *p2 = m.xyz + 3 * t[k][2];
                double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
                double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
                double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                               e1[0] * e2[1] - e1[1] * e2[0]};
                const double *r = refs + 3 * t[k][0];
                int flip = n[0] * r[0] + n[1] * r[1] + n[2] * r[2] < 0;
                m.faces[3 * f] = t[k][0];
                m.faces[3 * f + 1] = t[k][flip ? 2 : 1];
                m.faces[3 * f + 2] = t[k][flip ? 1 : 2];
            }
        }
    free(refs);
    return m;
}

void tm_free(tm_mesh *m)
{
    free(m->xyz);
    free(m->faces);
    m->xyz = NULL;
    m->faces = NULL;
}

tm_mesh tm_sphere(double r, int nlat, int nlon)
{
    tm_mesh m;
    m.nv = (int64_t)(nlat - 1) * nlon + 2;
    m.nf = 2 * (int64_t)nlon * (nlat - 1);
    m.xyz = malloc(3 * (size_t)m.nv * sizeof *m.xyz);
    m.faces = malloc(3 * (size_t)m.nf * sizeof *m.faces);
    int64_t N = m.nv - 2, S = m.nv - 1, f = 0;
    for (int i = 1; i < nlat; i++)
        for (int j = 0; j < nlon; j++) {
            double th = M_PI * i / nlat, ph = 2 * M_PI * j / nlon;
            double *p = m.xyz + 3 * ((i - 1) * nlon + j);
            p[0] = r * sin(th) * cos(ph);
            p[1] = r * cos(th);
            p[2] = r * sin(th) * sin(ph);
        }
    m.xyz[3 * N] = 0, m.xyz[3 * N + 1] = r, m.xyz[3 * N + 2] = 0;
    m.xyz[3 * S] = 0, m.xyz[3 * S + 1] = -r, m.xyz[3 * S + 2] = 0;
#define TM_RING(i, j) ((int64_t)((i) - 1) * nlon + ((j) % nlon))
    for (int j = 0; j < nlon; j++) {
        int64_t t[3] = {N, TM_RING(1, j + 1), TM_RING(1, j)};
        for (int k = 0; k < 3; k++) m.faces[3 * f + k] = t[k];
        f++;
        int64_t s[3] = {S, TM_RING(nlat - 1, j), TM_RING(nlat - 1, j + 1)};
        for (int k = 0; k < 3; k++) m.faces[3 * f + k] = s[k];
        f++;
    }
    for (int i = 1; i < nlat - 1; i++)
        for (int j = 0; j < nlon; j++) {
            int64_t a = TM_RING(i, j), b = TM_RING(i, j + 1), c = TM_RING(i + 1, j),
                    d = TM_RING(i + 1, j + 1);
            int64_t t[6] = {a, b, d, a, d, c};
            for (int k = 0; k < 6; k++) m.faces[3 * f + k] = t[k];
            f += 2;
        }
#undef TM_RING
    /* orient outwards: the centroid of each face points away from 0 */
    for (int64_t g = 0; g < m.nf; g++) {
        int64_t *t = m.faces + 3 * g;
        const double *p0 = m.xyz + 3 * t[0], *p1 = m.xyz + 3 * t[1], *p2 = m.xyz + 3 * t[2];
        double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        double c[3] = {p0[0] + p1[0] + p2[0], p0[1] + p1[1] + p2[1], p0[2] + p1[2] + p2[2]};
        if (n[0] * c[0] + n[1] * c[1] + n[2] * c[2] < 0) {
            int64_t s = t[1];
            t[1] = t[2];
            t[2] = s;
        }
    }
    return m;
}

void tm_torus_fn(double u, double v, const void *ud, double p[3], double ref[3])
{
    const double *rr = ud; /* R, r */
    double a = 2 * M_PI * u, b = 2 * M_PI * v;
    p[0] = (rr[0] + rr[1] * cos(b)) * cos(a);
    p[1] = rr[1] * sin(b);
    p[2] = (rr[0] + rr[1] * cos(b)) * sin(a);
    ref[0] = cos(b) * cos(a);
    ref[1] = sin(b);
    ref[2] = cos(b) * sin(a);
}

tm_mesh tm_torus(double R, double r, int nu, int nv)
{
    double rr[2] = {R, r};
    return tm_grid(nu, nv, 1, 1, tm_torus_fn, rr);
}

void tm_disc_fn(double u, double v, const void *ud, double p[3], double ref[3])
{
    (void)ud;
    double rad = v, a = 2 * M_PI * u;
    p[0] = rad * cos(a);
    p[1] = rad * sin(a);
    p[2] = 0.08 * sin(5 * a) * rad + 0.15 * exp(-8 * rad * rad);
    ref[0] = ref[1] = 0;
    ref[2] = 1;
}

tm_mesh tm_bumpy_disc(int nu, int nv)
{
    return tm_grid(nu, nv, 1, 0, tm_disc_fn, NULL);
}

double tm_gauss(double x, double y, double cx, double cy, double sx, double sy)
{
    double dx = (x - cx) / sx, dy = (y - cy) / sy;
    return exp(-0.5 * (dx * dx + dy * dy));
}

void tm_face_fn(double u, double v, const void *ud, double p[3], double ref[3])
{
    (void)ud;
    double rad = v, a = 2 * M_PI * u;
    double x = 0.5 * rad * cos(a), y = 0.7 * rad * sin(a);
    double e = 1 - (x / 0.52) * (x / 0.52) - (y / 0.75) * (y / 0.75);
    double z = 0.45 * sqrt(fmax(e, 0));
    z += 0.20 * tm_gauss(x, y, 0, 0.0, 0.05, 0.16) * (0.8 - 0.2 * tanh(10 * (y - 0.1))); /* nose */
    z += 0.10 * tm_gauss(x, y, 0, -0.12, 0.07, 0.05);                      /* nose tip */
    z -= 0.09 * tm_gauss(x, y, -0.17, 0.15, 0.08, 0.05);                   /* eye sockets */
    z -= 0.09 * tm_gauss(x, y, 0.17, 0.15, 0.08, 0.05);
    z += 0.05 * tm_gauss(x, y, -0.17, 0.15, 0.035, 0.025);                 /* eyeballs */
    z += 0.05 * tm_gauss(x, y, 0.17, 0.15, 0.035, 0.025);
    z += 0.05 * tm_gauss(x, y, 0, 0.27, 0.28, 0.04);                       /* brow */
    z += 0.04 * tm_gauss(x, y, -0.22, -0.12, 0.08, 0.08);                  /* cheeks */
    z += 0.04 * tm_gauss(x, y, 0.22, -0.12, 0.08, 0.08);
    z += 0.035 * tm_gauss(x, y, 0, -0.30, 0.12, 0.025);                    /* lips */
    z -= 0.03 * tm_gauss(x, y, 0, -0.335, 0.12, 0.018);                    /* mouth line */
    z += 0.03 * tm_gauss(x, y, 0, -0.52, 0.10, 0.06);                      /* chin */
    p[0] = x;
    p[1] = y;
    p[2] = z;
    ref[0] = ref[1] = 0;
    ref[2] = 1;
}

tm_mesh tm_face(int nu, int nv)
{
    return tm_grid(nu, nv, 1, 0, tm_face_fn, NULL);
}
