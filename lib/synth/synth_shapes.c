/* lib/synth/synth_shapes.c — the shapes of the synthetic families (es_synth.h,
 * datasets-spec/synthetic.md): barbells, bent tubes, face-like domes.
 *
 * Barbells and tubes are ring meshes: rings of `nseg` vertices along an
 * axis, optionally closed by a pole vertex at either end, with the ring
 * angle increasing counter-clockwise about the axis so that faces point
 * outward. Barbell ends are superellipsoids (Barr 1981): exponent 2 is a
 * sphere, 8 a rounded cube, which is the paper's Fig. 7 set-up (two end
 * shapes x two bar lengths). The face-like dome is a disc of hexagonal
 * rings (ring r has 6r vertices) lifted to a dome, with vertices inside
 * three elliptic holes removed.
 */
#include "synth/synth_pkg.h"
#include "edgespace/es_mesh.h"

#include <math.h>

/* ---- ring meshes ---- */

/* Faces of rings 0..nr-1 of nseg vertices; pole0/pole1 add a vertex before
 * ring 0 / after the last ring. Returns the number of faces written. */
static int64_t ring_faces(int64_t nr, int64_t nseg, int pole0, int pole1, int64_t *F)
{
    int64_t base = pole0 ? 1 : 0, f = 0, last = base + nr * nseg;
    if (pole0)
        for (int64_t j = 0; j < nseg; j++) {
            int64_t *t = F + 3 * f++;
            t[0] = 0; t[1] = base + (j + 1) % nseg; t[2] = base + j;
        }
    for (int64_t r = 0; r + 1 < nr; r++)
        for (int64_t j = 0; j < nseg; j++) {
            int64_t a0 = base + r * nseg + j, a1 = base + r * nseg + (j + 1) % nseg;
            int64_t b0 = a0 + nseg, b1 = a1 + nseg;
            int64_t *t = F + 3 * f++;
            t[0] = a0; t[1] = a1; t[2] = b1;
            t = F + 3 * f++;
            t[0] = a0; t[1] = b1; t[2] = b0;
        }
    if (pole1)
        for (int64_t j = 0; j < nseg; j++) {
            int64_t a0 = base + (nr - 1) * nseg + j, a1 = base + (nr - 1) * nseg + (j + 1) % nseg;
            int64_t *t = F + 3 * f++;
            t[0] = a0; t[1] = a1; t[2] = last;
        }
    return f;
}

static double sgnpow(double x, double e) { return x < 0 ? -pow(-x, e) : pow(x, e); }

static void add_noise(es_rng *rng, double *xyz, int64_t nv, double sd)
{
    if (sd <= 0) return;
    for (int64_t i = 0; i < 3 * nv; i++) xyz[i] += sd * es_rng_normal(rng);
}

/* ---- barbells ---- */

/* Angles phi_0 = 0 .. phi_{n-1} at equal arc length around the
 * superellipse (sgnpow(cos phi, eps), sgnpow(sin phi, eps)). */
static void superellipse_angles(double eps, int64_t n, double *phi)
{
    enum { NS = 8192 };
    double prev[2] = {1, 0}, total = 0, acc = 0;
    for (int pass = 0; pass < 2; pass++) {
        int64_t j = 1;
        acc = 0;
        prev[0] = 1;
        prev[1] = 0;
        phi[0] = 0;
        for (int i = 1; i <= NS; i++) {
            double t = 2 * M_PI * i / NS;
            double p[2] = {sgnpow(cos(t), eps), sgnpow(sin(t), eps)};
            double d = hypot(p[0] - prev[0], p[1] - prev[1]);
            if (pass == 1)
                while (j < n && acc + d >= total * (double)j / (double)n) {
                    double w = d > 0 ? (total * (double)j / (double)n - acc) / d : 1;
                    phi[j++] = 2 * M_PI * ((double)(i - 1) + w) / NS;
                }
            acc += d;
            prev[0] = p[0];
            prev[1] = p[1];
        }
        total = acc;
        for (; pass == 1 && j < n; j++) phi[j] = 2 * M_PI * (double)j / (double)n;
    }
}

/* One barbell: superellipsoid ends of radius R and exponent p, bar of
 * radius rb and length L along x, centred at the origin. Ring order: left
 * pole, left bulb (nb rings, the last is the neck), bar (nbar rings), right
 * bulb (neck first), right pole. */
static void barbell_xyz(double p, double L, int64_t nseg, int64_t nb, int64_t nbar,
                        double *xyz)
{
    const double R = 1.0, rb = 0.35, eps = 2.0 / p;
    double thn = M_PI - asin(pow(rb / R, 1.0 / eps));       /* radial(thn) = rb */
    double c = L / 2 + R * pow(-cos(thn), eps);            /* bulb centre |x| */
    int64_t v = 0;
    /* rings at equal arc length along the bulb's profile, so that the flat
     * sides of the cube-like end are sampled as densely as its corners */
    enum { NS = 4096 };
    double arc[NS + 1], thk[128]; /* nb <= 96 (resolution <= 64) */
    arc[0] = 0;
    for (int i = 1; i <= NS; i++) {
        double t0 = thn * (i - 1) / NS, t1 = thn * i / NS;
        double dx = R * (sgnpow(cos(t1), eps) - sgnpow(cos(t0), eps));
        double dr = R * (pow(fabs(sin(t1)), eps) - pow(fabs(sin(t0)), eps));
        arc[i] = arc[i - 1] + sqrt(dx * dx + dr * dr);
    }
    for (int64_t k = 1, i = 1; k <= nb; k++) {
        double target = arc[NS] * (double)k / (double)nb;
        while (i < NS && arc[i] < target) i++;
        double w = arc[i] > arc[i - 1] ? (target - arc[i - 1]) / (arc[i] - arc[i - 1]) : 1;
        thk[k] = thn * ((double)(i - 1) + w) / NS;
    }
    thk[nb] = thn;
    double phi[96 * 2]; /* nseg <= 192 (resolution <= 64) */
    superellipse_angles(eps, nseg, phi);
    xyz[v++] = -(c + R); xyz[v++] = 0; xyz[v++] = 0;
    for (int side = 0; side < 2; side++) {
        for (int64_t kk = 1; kk <= nb; kk++) {
            int64_t k = side == 0 ? kk : nb + 1 - kk;
            double th = thk[k];
            double xl = R * sgnpow(cos(th), eps), rad = R * pow(fabs(sin(th)), eps);
            double x = side == 0 ? -c - xl : c + xl;
            for (int64_t j = 0; j < nseg; j++) {
                double ph = phi[j];
                xyz[v++] = x;
                xyz[v++] = rad * sgnpow(cos(ph), eps);
                xyz[v++] = rad * sgnpow(sin(ph), eps);
            }
        }
        if (side == 0)
            for (int64_t r = 1; r <= nbar; r++) {
                double x = -L / 2 + L * (double)r / (double)(nbar + 1);
                for (int64_t j = 0; j < nseg; j++) {
                    double ph = 2 * M_PI * (double)j / (double)nseg;
                    xyz[v++] = x;
                    xyz[v++] = rb * cos(ph);
                    xyz[v++] = rb * sin(ph);
                }
            }
    }
    xyz[v++] = c + R; xyz[v++] = 0; xyz[v++] = 0;
}

es_status es__synth_barbell(es_ctx *ctx, const es_synth_opts *o, es_synth_set *s)
{
    static const char *const ends[] = {"sphere", "cube"};
    static const double expo[] = {2.0, 8.0};
    const double Lshort = 1.0, Llong = 6.0;
    int64_t res = o->resolution ? o->resolution : 8, nlen = o->n ? o->n : 2;
    int64_t nseg = 3 * res, nb = (3 * res) / 2, nbar = (3 * res) / 2;
    int64_t nr = 2 * nb + nbar, nv = 2 + nr * nseg, nf = 2 * nseg * nr;
    es_status rc = es__synth_alloc(ctx, s, nv, nf, 2 * nlen, 3);
    if (rc != ES_OK) return rc;
    ring_faces(nr, nseg, 1, 1, s->faces);
    if ((rc = es__synth_str(ctx, &s->label_names[0], "end")) != ES_OK ||
        (rc = es__synth_str(ctx, &s->label_names[1], "bar")) != ES_OK ||
        (rc = es__synth_str(ctx, &s->label_names[2], "bar_length")) != ES_OK)
        return rc;
    es_rng rng;
    es_rng_init(&rng, es_ctx_seed(ctx));
    double noise = o->noise < 0 ? 0 : o->noise;
    for (int e = 0; e < 2; e++)
        for (int64_t l = 0; l < nlen; l++) {
            int64_t i = e * nlen + l;
            double L = Lshort + (Llong - Lshort) * (double)l / (double)(nlen - 1);
            char bar[32];
            if (nlen == 2) snprintf(bar, sizeof bar, "%s", l ? "long" : "short");
            else snprintf(bar, sizeof bar, "L%lld", (long long)l);
            barbell_xyz(expo[e], L, nseg, nb, nbar, s->xyz + 3 * nv * i);
            add_noise(&rng, s->xyz + 3 * nv * i, nv, noise * (L + 4));
            if ((rc = es__synth_str(ctx, &s->names[i], "barbell_%s_%s", ends[e], bar)) ||
                (rc = es__synth_str(ctx, &s->labels[3 * i], "%s", ends[e])) ||
                (rc = es__synth_str(ctx, &s->labels[3 * i + 1], "%s", bar)) ||
                (rc = es__synth_str(ctx, &s->labels[3 * i + 2], "%.6g", L)))
                return rc;
        }
    return ES_OK;
}

/* ---- bent tubes ---- */

/* Point (s, y, z) of the straight tube along x, bent so that the axis
 * segment [0, len] follows a circular arc of angle theta in the xy-plane;
 * beyond the ends the axis continues straight along the end tangents. */
static void bend(double theta, double len, double s, double y, double z, double *out)
{
    if (theta == 0) {
        out[0] = s; out[1] = y; out[2] = z;
        return;
    }
    double rho = len / theta, sa = s < 0 ? 0 : s > len ? len : s, ph = sa / rho;
    double T[2] = {cos(ph), sin(ph)}, N[2] = {-sin(ph), cos(ph)};
    out[0] = rho * sin(ph) + (s - sa) * T[0] + y * N[0];
    out[1] = rho * (1 - cos(ph)) + (s - sa) * T[1] + y * N[1];
    out[2] = z;
}

/* Point (s, y, z) of the straight tube along x with its cross-section
 * turned by angle phi * s / len about the axis (the twist grows linearly
 * along [0, len]), then bent. */
static void twist_bend(double theta, double phi, double len, double s, double y, double z,
                       double *out)
{
    double a = phi * (s < 0 ? 0 : s > len ? 1 : s / len), c = cos(a), sn = sin(a);
    bend(theta, len, s, c * y - sn * z, sn * y + c * z, out);
}

es_status es__synth_tube(es_ctx *ctx, const es_synth_opts *o, int kind, es_synth_set *s)
{
    const double r = 1.0, len = 8.0;
    const int closed = kind == 1, twisted = kind == 2;
    /* the twisted tube's cross-section is an ellipse (half-axes 1 and 0.5),
     * so that its twist shows: a circle would turn into itself */
    const double ry = r, rz = twisted ? 0.5 * r : r, phi_max = twisted ? 1.5 * M_PI : 0;
    int64_t res = o->resolution ? o->resolution : 8, n = o->n ? o->n : 7;
    /* at least 3 segments around: 2 would put two faces on each side of a ring edge */
    int64_t nseg = res < 2 ? 3 : 2 * res, nring = 4 * res + 1, ncap = closed ? (res + 1) / 2 : 0;
    int64_t nr = nring + 2 * ncap, nv = nr * nseg + (closed ? 2 : 0);
    int64_t nf = 2 * nseg * (nr - 1) + (closed ? 2 * nseg : 0);
    es_status rc = es__synth_alloc(ctx, s, nv, nf, n, twisted ? 2 : 1);
    if (rc != ES_OK) return rc;
    ring_faces(nr, nseg, closed, closed, s->faces);
    if ((rc = es__synth_str(ctx, &s->label_names[0], "theta_deg")) != ES_OK ||
        (twisted && (rc = es__synth_str(ctx, &s->label_names[1], "twist_deg")) != ES_OK))
        return rc;
    es_rng rng;
    es_rng_init(&rng, es_ctx_seed(ctx));
    double noise = o->noise < 0 ? 0 : o->noise;
    for (int64_t i = 0; i < n; i++) {
        double frac = n > 1 ? o->span * (double)i / (double)(n - 1) : 0;
        double theta = M_PI * frac, phi = phi_max * frac;
        double *x = s->xyz + 3 * nv * i;
        int64_t v = 0;
        if (closed) bend(theta, len, -r, 0, 0, x + 3 * v++);
        for (int64_t k = 0; k < nr; k++) {
            double sk, rad;
            if (k < ncap) {            /* left cap, from the pole outward */
                double g = M_PI / 2 * (double)(k + 1) / (double)(ncap + 1);
                sk = -r * cos(g);
                rad = r * sin(g);
            } else if (k >= ncap + nring) {
                double g = M_PI / 2 * (double)(nr - k) / (double)(ncap + 1);
                sk = len + r * cos(g);
                rad = r * sin(g);
            } else {
                sk = len * (double)(k - ncap) / (double)(nring - 1);
                rad = r;
            }
            for (int64_t j = 0; j < nseg; j++) {
                double ph = 2 * M_PI * (double)j / (double)nseg;
                twist_bend(theta, phi, len, sk, rad / r * ry * cos(ph), rad / r * rz * sin(ph),
                           x + 3 * v++);
            }
        }
        if (closed) bend(theta, len, len + r, 0, 0, x + 3 * v++);
        add_noise(&rng, x, nv, noise * len);
        if ((rc = es__synth_str(ctx, &s->names[i], "%s_%03lld",
                                closed ? "tubec" : twisted ? "tubetw" : "tube", (long long)i)) ||
            (rc = es__synth_str(ctx, &s->labels[(twisted ? 2 : 1) * i], "%.6g",
                                theta * 180 / M_PI)) ||
            (twisted && (rc = es__synth_str(ctx, &s->labels[2 * i + 1], "%.6g",
                                            phi * 180 / M_PI))))
            return rc;
    }
    return ES_OK;
}

/* ---- a triangulated 3D polygon ---- */

es_status es__synth_strip(es_ctx *ctx, const es_synth_opts *o, es_synth_set *s)
{
    /* Wuhrer et al.'s Fig. 6: the curve y = a sin x, x in [0, 2 pi], given
     * thickness 2 along z: two rows of vertices zipped into triangles, so
     * the dual graph is a path; a = 1 - 2 s from 1 to -1. Thicker than the
     * curve's spread in y, so that the best rigid alignment of a = 1 to
     * a = -1 is the identity and not the turn about x that flips z (which
     * makes every pair of face normals antipodal, where SLERP has no path) */
    const double h = 2.0;
    int64_t res = o->resolution ? o->resolution : 8, n = o->n ? o->n : 2, nseg = 4 * res;
    int64_t nv = 2 * (nseg + 1), nf = 2 * nseg;
    es_status rc = es__synth_alloc(ctx, s, nv, nf, n, 1);
    if (rc != ES_OK) return rc;
    for (int64_t j = 0; j < nseg; j++) {
        int64_t a0 = 2 * j, a1 = a0 + 1, b0 = a0 + 2, b1 = a0 + 3, *t = s->faces + 6 * j;
        /* alternate the diagonal, as a polygon triangulation may */
        if (j % 2 == 0) {
            t[0] = a0; t[1] = b0; t[2] = b1;
            t[3] = a0; t[4] = b1; t[5] = a1;
        } else {
            t[0] = a0; t[1] = b0; t[2] = a1;
            t[3] = a1; t[4] = b0; t[5] = b1;
        }
    }
    if ((rc = es__synth_str(ctx, &s->label_names[0], "amplitude")) != ES_OK) return rc;
    es_rng rng;
    es_rng_init(&rng, es_ctx_seed(ctx));
    double noise = o->noise < 0 ? 0 : o->noise;
    for (int64_t i = 0; i < n; i++) {
        double frac = n > 1 ? o->span * (double)i / (double)(n - 1) : 0, amp = 1 - 2 * frac;
        double *x = s->xyz + 3 * nv * i;
        for (int64_t j = 0; j <= nseg; j++) {
            double u = 2 * M_PI * (double)j / (double)nseg;
            for (int k = 0; k < 2; k++) {
                x[3 * (2 * j + k)] = u;
                x[3 * (2 * j + k) + 1] = amp * sin(u);
                x[3 * (2 * j + k) + 2] = k * h;
            }
        }
        add_noise(&rng, x, nv, noise * 2 * M_PI);
        if ((rc = es__synth_str(ctx, &s->names[i], "strip_%03lld", (long long)i)) ||
            (rc = es__synth_str(ctx, &s->labels[i], "%.6g", amp)))
            return rc;
    }
    return ES_OK;
}

/* ---- face-like domes ---- */

typedef struct ellipse { double cu, cv, au, av; } ellipse;
static const ellipse holes[3] = {
    {-0.38, 0.25, 0.16, 0.08}, {0.38, 0.25, 0.16, 0.08}, {0.0, -0.45, 0.28, 0.06}};

static int in_hole(double u, double v)
{
    for (int h = 0; h < 3; h++) {
        double a = (u - holes[h].cu) / holes[h].au, b = (v - holes[h].cv) / holes[h].av;
        if (a * a + b * b < 1) return 1;
    }
    return 0;
}

static double gauss2(double u, double v, double cu, double cv, double su, double sv)
{
    double a = (u - cu) / su, b = (v - cv) / sv;
    return exp(-0.5 * (a * a + b * b));
}

/* Hexagonal disc of R rings: vertex (u, v) list and CCW faces; ring r has
 * 6r vertices at radius r/R, neighbouring rings are zipped by angle. */
static void hex_disc(int64_t R, double *uv, int64_t *F, int64_t *nf_out)
{
    int64_t v = 0, f = 0;
    uv[v++] = 0;
    uv[v++] = 0;
    for (int64_t r = 1; r <= R; r++)
        for (int64_t i = 0; i < 6 * r; i++) {
            double t = 2 * M_PI * (double)i / (double)(6 * r);
            uv[v++] = (double)r / (double)R * cos(t);
            uv[v++] = (double)r / (double)R * sin(t);
        }
    for (int64_t r = 0; r < R; r++) {
        int64_t ni = r ? 6 * r : 1, no = 6 * (r + 1);
        int64_t bi = r ? 1 + 3 * r * (r - 1) : 0, bo = 1 + 3 * r * (r + 1);
        int64_t i = 0, j = 0;
        while (i < (r ? ni : 0) || j < no) {
            /* angles of the next inner and outer vertices (unwrapped) */
            double ai = r ? (double)(i + 1) / (double)ni : 2.0;
            double ao = (double)(j + 1) / (double)no;
            int64_t *t = F + 3 * f++;
            t[0] = bi + (r ? i % ni : 0);
            t[1] = bo + j % no;
            if (j < no && (ao <= ai || i >= (r ? ni : 0))) {
                t[2] = bo + (j + 1) % no;
                j++;
            } else {
                t[1] = bo + j % no;
                t[2] = bi + (i + 1) % ni;
                i++;
            }
        }
    }
    *nf_out = f;
}

/* Random rotation: axis uniform on the sphere, angle up to amax. */
static void random_rotation(es_rng *rng, double amax, double Q[9])
{
    double ax[3], n = 0, a = amax * es_rng_uniform(rng);
    do {
        n = 0;
        for (int k = 0; k < 3; k++) {
            ax[k] = es_rng_normal(rng);
            n += ax[k] * ax[k];
        }
    } while (n < 1e-12);
    n = sqrt(n);
    for (int k = 0; k < 3; k++) ax[k] /= n;
    double c = cos(a), s = sin(a), C = 1 - c;
    /* Rodrigues, column-major */
    Q[0] = c + ax[0] * ax[0] * C;          Q[3] = ax[0] * ax[1] * C - ax[2] * s;
    Q[6] = ax[0] * ax[2] * C + ax[1] * s;  Q[1] = ax[1] * ax[0] * C + ax[2] * s;
    Q[4] = c + ax[1] * ax[1] * C;          Q[7] = ax[1] * ax[2] * C - ax[0] * s;
    Q[2] = ax[2] * ax[0] * C - ax[1] * s;  Q[5] = ax[2] * ax[1] * C + ax[0] * s;
    Q[8] = c + ax[2] * ax[2] * C;
}

/* Expression fields: displacement (du, dv, dz) at (u, v) at intensity 1. */
static void expression(int e, double u, double v, double d[3])
{
    d[0] = d[1] = d[2] = 0;
    if (e == 1) { /* happy: mouth corners up and out, cheeks raised */
        for (int sd = -1; sd <= 1; sd += 2) {
            double w = gauss2(u, v, 0.28 * sd, -0.45, 0.12, 0.12);
            double c = gauss2(u, v, 0.40 * sd, -0.10, 0.18, 0.15);
            d[0] += 0.06 * sd * w;
            d[1] += 0.08 * w + 0.03 * c;
            d[2] += 0.02 * w + 0.05 * c;
        }
    } else if (e == 2) { /* angry: brows down and in, lips pressed, corners down */
        for (int sd = -1; sd <= 1; sd += 2) {
            double b = gauss2(u, v, 0.32 * sd, 0.42, 0.15, 0.08);
            double m = gauss2(u, v, 0.28 * sd, -0.45, 0.10, 0.10);
            d[0] += -0.04 * sd * b;
            d[1] += -0.06 * b - 0.05 * m;
            d[2] += 0.02 * b;
        }
        double l = gauss2(u, v, 0.0, -0.45, 0.30, 0.12);
        d[1] += (v > -0.45 ? -0.03 : 0.03) * l;
    }
}

es_status es__synth_face(es_ctx *ctx, const es_synth_opts *o, es_synth_set *s)
{
    static const char *const expr[] = {"neutral", "happy", "angry"};
    int64_t R = o->resolution ? 2 * o->resolution : 16, nsub = o->n ? o->n : 10;
    int64_t nv0 = 1 + 3 * R * (R + 1), nf0 = 6 * R * R, nf = 0, nv = 0;
    double noise = o->noise < 0 ? 1e-4 : o->noise;
    es_status rc = ES_OK;
    double *uv = es__alloc_array(ctx, 2 * nv0, sizeof *uv);
    int64_t *F0 = es__alloc_array(ctx, 3 * nf0, sizeof *F0);
    int64_t *map = es__alloc_array(ctx, nv0, sizeof *map);
    es_mesh *check = NULL;
    if (!uv || !F0 || !map) { rc = ES_ENOMEM; goto done; }
    hex_disc(R, uv, F0, &nf0);

    /* drop faces touching a hole vertex, then unreferenced vertices */
    for (int64_t v = 0; v < nv0; v++) map[v] = -1;
    for (int64_t f = 0; f < nf0; f++) {
        const int64_t *t = F0 + 3 * f;
        if (in_hole(uv[2 * t[0]], uv[2 * t[0] + 1]) || in_hole(uv[2 * t[1]], uv[2 * t[1] + 1]) ||
            in_hole(uv[2 * t[2]], uv[2 * t[2] + 1]))
            continue;
        for (int k = 0; k < 3; k++) map[t[k]] = 0;
        memmove(F0 + 3 * nf, t, 3 * sizeof *t);
        nf++;
    }
    for (int64_t v = 0; v < nv0; v++)
        if (map[v] == 0) {
            map[v] = nv;
            uv[2 * nv] = uv[2 * v];
            uv[2 * nv + 1] = uv[2 * v + 1];
            nv++;
        }
    for (int64_t i = 0; i < 3 * nf; i++) F0[i] = map[F0[i]];
    /* the holes must leave an oriented manifold: check once here */
    if ((rc = es_mesh_new(ctx, nv, nf, F0, NULL, &check)) != ES_OK) goto done;

    if ((rc = es__synth_alloc(ctx, s, nv, nf, 3 * nsub, 2)) != ES_OK) goto done;
    memcpy(s->faces, F0, (size_t)(3 * nf) * sizeof *F0);
    if ((rc = es__synth_str(ctx, &s->label_names[0], "subject")) ||
        (rc = es__synth_str(ctx, &s->label_names[1], "expression")))
        goto done;

    es_rng rng;
    es_rng_init(&rng, es_ctx_seed(ctx));
    enum { NB = 6 };
    for (int64_t sj = 0; sj < nsub; sj++) {
        double bc[NB][2], ba[NB], bs[NB], Q[9], sh[3], inten[3];
        double sw = 1 + 0.05 * es_rng_normal(&rng), sv = 1 + 0.05 * es_rng_normal(&rng);
        double scale = 1 + 0.05 * es_rng_normal(&rng);
        for (int b = 0; b < NB; b++) {
            double rr = 0.8 * sqrt(es_rng_uniform(&rng)), t = 2 * M_PI * es_rng_uniform(&rng);
            bc[b][0] = rr * cos(t);
            bc[b][1] = rr * sin(t);
            ba[b] = 0.04 * es_rng_normal(&rng);
            bs[b] = 0.15 + 0.2 * es_rng_uniform(&rng);
        }
        inten[0] = 0;
        inten[1] = 0.6 + 0.4 * es_rng_uniform(&rng);
        inten[2] = 0.6 + 0.4 * es_rng_uniform(&rng);
        for (int e = 0; e < 3; e++) {
            int64_t i = 3 * sj + e;
            double *x = s->xyz + 3 * nv * i;
            random_rotation(&rng, 0.3, Q);
            for (int k = 0; k < 3; k++) sh[k] = 0.5 * es_rng_normal(&rng);
            for (int64_t v = 0; v < nv; v++) {
                double u = uv[2 * v], w = uv[2 * v + 1], d[3], p[3];
                double z = 0.55 * sqrt(fmax(0.0, 1 - 0.75 * (u * u + w * w)));
                z += 0.25 * gauss2(u, w, 0, 0.02, 0.09, 0.18);      /* nose */
                z += 0.06 * gauss2(u, w, -0.38, 0.42, 0.15, 0.06);  /* brows */
                z += 0.06 * gauss2(u, w, 0.38, 0.42, 0.15, 0.06);
                z += 0.04 * gauss2(u, w, 0, -0.68, 0.2, 0.1);       /* chin */
                for (int b = 0; b < NB; b++) z += ba[b] * gauss2(u, w, bc[b][0], bc[b][1], bs[b], bs[b]);
                expression(e, u, w, d);
                p[0] = scale * sw * (u + inten[e] * d[0]);
                p[1] = scale * sv * 1.2 * (w + inten[e] * d[1]);
                p[2] = scale * (z + inten[e] * d[2]);
                for (int k = 0; k < 3; k++)
                    x[3 * v + k] = Q[k] * p[0] + Q[3 + k] * p[1] + Q[6 + k] * p[2] + sh[k];
            }
            add_noise(&rng, x, nv, noise * 2);
            if ((rc = es__synth_str(ctx, &s->names[i], "face_s%02lld_%s", (long long)sj + 1,
                                    expr[e])) ||
                (rc = es__synth_str(ctx, &s->labels[2 * i], "s%02lld", (long long)sj + 1)) ||
                (rc = es__synth_str(ctx, &s->labels[2 * i + 1], "%s", expr[e])))
                goto done;
        }
    }
done:
    es_mesh_free(check);
    es__free(ctx, uv);
    es__free(ctx, F0);
    es__free(ctx, map);
    return rc;
}
