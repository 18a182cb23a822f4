/* lib/figure/render.c — pictures of triangle meshes (es_render.h): automatic
 * camera from the principal axes of the vertices, a z-buffer rasterizer
 * with supersampling, Lambert shading under a headlight, scalar colour
 * maps, several panels in a row with labels and one colour bar.
 *
 * Why a z-buffer and not the painter's algorithm: sorting triangles by
 * depth fails for interpenetrating or cyclically overlapping triangles
 * (the folded poses and embedded meshes this toolkit produces can have
 * both), and drawing thousands of antialiased cairo polygons leaves
 * hairline seams between neighbours (conflation artefacts). Rasterizing
 * ourselves gives exact visibility, per-pixel shading and perspective-
 * correct interpolation of normals and scalars; supersampling (box filter)
 * gives smooth silhouettes. Cairo composes the result with vector text.
 *
 * References: barycentric rasterization with edge functions, J. Pineda,
 * "A parallel algorithm for polygon rasterization", SIGGRAPH 1988;
 * perspective-correct interpolation, P. Heckbert and H. Moreton,
 * "Interpolation for polygon texture mapping and shading" (1991);
 * Phong-interpolated normals with a Lambert term, B. T. Phong, CACM 18
 * (1975) 311-317.
 */
#include "figure/figure_pkg.h"
#include "edgespace/es_render.h"
#include "core/vec3.h"

#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void es_render_spec_init(es_render_spec *spec)
{
    memset(spec, 0, sizeof *spec);
    spec->width = 480;
    spec->height = 480;
    spec->projection = ES_PROJ_PERSPECTIVE;
    spec->fov_deg = 25;
    spec->fill = 0.9;
    spec->backface = ES_BACKFACE_DARKER;
    spec->cmap = ES_CMAP_VIRIDIS;
    spec->colorbar = 1;
    spec->base_rgb[0] = 0.80;
    spec->base_rgb[1] = 0.76;
    spec->base_rgb[2] = 0.70;
    spec->background_rgb[0] = spec->background_rgb[1] = spec->background_rgb[2] = 1;
    spec->font_size = 12;
    spec->supersample = 3;
}

void es_render_mesh_from(es_render_mesh *item, const es_mesh *mesh, const double *xyz)
{
    memset(item, 0, sizeof *item);
    item->nverts = es_mesh_nverts(mesh);
    item->nfaces = es_mesh_nfaces(mesh);
    item->faces = es_mesh_faces(mesh);
    item->xyz = xyz ? xyz : es_mesh_xyz(mesh);
    item->nedges = es_mesh_nedges(mesh);
    item->edges = es_mesh_edges(mesh);
}

/* ---- small vector helpers ---------------------------------------------- */


static bool normalize3(double *a)
{
    double n = es__v3_norm(a);
    if (!(n > 1e-300) || !isfinite(n)) return false;
    a[0] /= n, a[1] /= n, a[2] /= n;
    return true;
}

/* Index of the largest-magnitude component. */
static int argmax_abs3(const double *a)
{
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(a[i]) > fabs(a[k])) k = i;
    return k;
}

/* ---- automatic view ------------------------------------------------------ */

es_status es_render_auto_view(es_ctx *ctx, int64_t nverts, const double *xyz,
                              int64_t nfaces, const int64_t *faces, double view[3],
                              double up[3])
{
    if (nverts < 3 || !xyz)
        ES_FAIL(ctx, ES_EINVAL, "render: need at least 3 vertices for a view (have %lld)",
                (long long)nverts);
    double c[3] = {0, 0, 0}, cov[9] = {0}, w[3];
    for (int64_t v = 0; v < nverts; v++)
        for (int k = 0; k < 3; k++) {
            if (!isfinite(xyz[3 * v + k]))
                ES_FAIL(ctx, ES_EINVAL, "render: vertex %lld has a non-finite coordinate",
                        (long long)v);
            c[k] += xyz[3 * v + k];
        }
    for (int k = 0; k < 3; k++) c[k] /= (double)nverts;
    for (int64_t v = 0; v < nverts; v++) {
        double d[3] = {xyz[3 * v] - c[0], xyz[3 * v + 1] - c[1], xyz[3 * v + 2] - c[2]};
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) cov[i + 3 * j] += d[i] * d[j];
    }
    /* eigenvalues ascending; columns of cov become the eigenvectors */
    if (LAPACKE_dsyev(LAPACK_COL_MAJOR, 'V', 'U', 3, cov, 3, w) != 0)
        ES_FAIL(ctx, ES_ENUMERIC, "render: eigen-decomposition of the vertex covariance failed");
    double *e0 = cov, *e1 = cov + 3, *e2 = cov + 6;

    /* area-weighted normal sum: which side the faces look to */
    double nsum[3] = {0, 0, 0}, asum = 0;
    for (int64_t f = 0; faces && f < nfaces; f++) {
        const int64_t *t = faces + 3 * f;
        if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= nverts || t[1] >= nverts ||
            t[2] >= nverts)
            continue;
        const double *a = xyz + 3 * t[0], *b = xyz + 3 * t[1], *d = xyz + 3 * t[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double s[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]}, n[3];
        es__v3_cross(u, s, n);
        for (int k = 0; k < 3; k++) nsum[k] += n[k];
        asum += es__v3_norm(n);
    }
    double side = es__v3_dot(nsum, e0);
    double sgn;
    if (asum > 0 && fabs(side) > 1e-3 * asum) sgn = side > 0 ? -1 : 1;
    else sgn = e0[argmax_abs3(e0)] > 0 ? -1 : 1; /* camera on the positive side */
    for (int k = 0; k < 3; k++) view[k] = sgn * e0[k];

    /* up: the data's own +y when it is close to the picture plane (stored
     * y-up), else the longest axis with its longer tail pointing down */
    const double *pick;
    double s2, c1 = fabs(e1[1]), c2 = fabs(e2[1]);
    if (fmax(c1, c2) > 0.98) {
        pick = c2 >= c1 ? e2 : e1;
        s2 = pick[1] > 0 ? 1 : -1;
    } else {
        double m2 = 0, m3 = 0;
        pick = e2;
        for (int64_t v = 0; v < nverts; v++) {
            double t = (xyz[3 * v] - c[0]) * pick[0] + (xyz[3 * v + 1] - c[1]) * pick[1] +
                       (xyz[3 * v + 2] - c[2]) * pick[2];
            m2 += t * t;
            m3 += t * t * t;
        }
        double skew = m2 > 0 ? (m3 / (double)nverts) / pow(m2 / (double)nverts, 1.5) : 0;
        if (fabs(skew) > 0.05) s2 = skew < 0 ? 1 : -1;
        else s2 = pick[argmax_abs3(pick)] > 0 ? 1 : -1;
    }
    for (int k = 0; k < 3; k++) up[k] = s2 * pick[k];
    return ES_OK;
}

/* ---- checks and scalars -------------------------------------------------- */

typedef struct edge_key { int64_t a, b, id; } edge_key;

static int cmp_edge_key(const void *p, const void *q)
{
    const edge_key *x = p, *y = q;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    return (x->b > y->b) - (x->b < y->b);
}

static es_status check_mesh(es_ctx *ctx, int64_t i, const es_render_mesh *m)
{
    if (m->nverts < 1 || m->nfaces < 0 || !m->xyz || (m->nfaces > 0 && !m->faces))
        ES_FAIL(ctx, ES_EINVAL, "render: mesh %lld: %lld vertices, %lld faces, missing arrays",
                (long long)i, (long long)m->nverts, (long long)m->nfaces);
    for (int64_t k = 0; k < 3 * m->nverts; k++)
        if (!isfinite(m->xyz[k]))
            ES_FAIL(ctx, ES_EINVAL, "render: mesh %lld: vertex %lld has a non-finite coordinate",
                    (long long)i, (long long)(k / 3));
    for (int64_t k = 0; k < 3 * m->nfaces; k++)
        if (m->faces[k] < 0 || m->faces[k] >= m->nverts)
            ES_FAIL(ctx, ES_EINVAL, "render: mesh %lld: face %lld has vertex index %lld "
                    "outside 0..%lld", (long long)i, (long long)(k / 3),
                    (long long)m->faces[k], (long long)m->nverts - 1);
    if (m->scalar_kind != ES_SCALARS_NONE && !m->scalars)
        ES_FAIL(ctx, ES_EINVAL, "render: mesh %lld: scalar kind set but no scalars", (long long)i);
    if (m->scalar_kind == ES_SCALARS_EDGE) {
        if (m->nedges < 1 || !m->edges)
            ES_FAIL(ctx, ES_EINVAL, "render: mesh %lld: per-edge scalars need the edge list",
                    (long long)i);
        for (int64_t k = 0; k < 2 * m->nedges; k++)
            if (m->edges[k] < 0 || m->edges[k] >= m->nverts)
                ES_FAIL(ctx, ES_EINVAL, "render: mesh %lld: edge %lld has vertex index %lld "
                        "outside 0..%lld", (long long)i, (long long)(k / 2),
                        (long long)m->edges[k], (long long)m->nverts - 1);
    }
    if (m->scalar_kind < ES_SCALARS_NONE || m->scalar_kind > ES_SCALARS_FACE)
        ES_FAIL(ctx, ES_EINVAL, "render: mesh %lld: unknown scalar kind %d", (long long)i,
                (int)m->scalar_kind);
    return ES_OK;
}

static int64_t nscalars(const es_render_mesh *m)
{
    switch (m->scalar_kind) {
    case ES_SCALARS_VERTEX: return m->nverts;
    case ES_SCALARS_EDGE: return m->nedges;
    case ES_SCALARS_FACE: return m->nfaces;
    default: return 0;
    }
}

/* Per-face values for edge scalars: the mean of the face's three edges
 * (NaN if one is not finite). */
static es_status edge_to_face(es_ctx *ctx, int64_t i, const es_render_mesh *m, double *fv)
{
    edge_key *keys = es__alloc_array(ctx, m->nedges, sizeof *keys);
    if (!keys) return ES_ENOMEM;
    for (int64_t e = 0; e < m->nedges; e++) {
        int64_t a = m->edges[2 * e], b = m->edges[2 * e + 1];
        keys[e] = (edge_key){a < b ? a : b, a < b ? b : a, e};
    }
    qsort(keys, (size_t)m->nedges, sizeof *keys, cmp_edge_key);
    for (int64_t f = 0; f < m->nfaces; f++) {
        double s = 0;
        for (int k = 0; k < 3; k++) {
            int64_t a = m->faces[3 * f + k], b = m->faces[3 * f + (k + 1) % 3];
            edge_key q = {a < b ? a : b, a < b ? b : a, 0};
            const edge_key *hit = bsearch(&q, keys, (size_t)m->nedges, sizeof *keys,
                                          cmp_edge_key);
            if (!hit) {
                es__free(ctx, keys);
                ES_FAIL(ctx, ES_ENOTFOUND, "render: mesh %lld: edge (%lld, %lld) of face %lld "
                        "is not in the edge list", (long long)i, (long long)a, (long long)b,
                        (long long)f);
            }
            s += m->scalars[hit->id];
        }
        fv[f] = isfinite(s) ? s / 3 : NAN;
    }
    es__free(ctx, keys);
    return ES_OK;
}

/* ---- camera -------------------------------------------------------------- */

typedef struct camera {
    double r[3], u[3], f[3];   /* right, up, forward (look direction) */
    double c[3];               /* centre of the mesh's bounding box */
    double dist;               /* eye = c - dist * f (perspective) */
    double scale;              /* pixels per unit (ortho) or focal length in pixels */
    double ox, oy;             /* screen offset that centres the projected box */
    int persp;
} camera;

static es_status make_basis(es_ctx *ctx, const es_render_spec *spec, const es_render_mesh *m,
                            camera *cam)
{
    double view[3], up[3];
    es_status rc;
    if (!spec->has_view || !spec->has_up) {
        if ((rc = es_render_auto_view(ctx, m->nverts, m->xyz, m->nfaces, m->faces, view, up)) !=
            ES_OK)
            return rc;
    }
    if (spec->has_view) memcpy(view, spec->view, sizeof view);
    if (spec->has_up) memcpy(up, spec->up, sizeof up);
    if (!normalize3(view)) ES_FAIL(ctx, ES_EINVAL, "render: the view direction is zero");
    double d = es__v3_dot(up, view);
    for (int k = 0; k < 3; k++) up[k] -= d * view[k];
    if (!normalize3(up)) {
        if (spec->has_up) ES_FAIL(ctx, ES_EINVAL, "render: the up vector is zero or parallel to the view");
        /* automatic up parallel to an explicit view: take a coordinate axis */
        static const double axes[2][3] = {{0, 1, 0}, {0, 0, 1}};
        for (int a = 0; a < 2; a++) {
            memcpy(up, axes[a], sizeof up);
            d = es__v3_dot(up, view);
            for (int k = 0; k < 3; k++) up[k] -= d * view[k];
            if (normalize3(up)) break;
        }
    }
    memcpy(cam->f, view, sizeof view);
    memcpy(cam->u, up, sizeof up);
    es__v3_cross(cam->f, cam->u, cam->r);
    return ES_OK;
}

/* Camera coordinates (x right, y up, z depth along f from the eye). */
static void to_camera(const camera *cam, const double *p, double *q)
{
    double d[3] = {p[0] - cam->c[0], p[1] - cam->c[1], p[2] - cam->c[2]};
    q[0] = es__v3_dot(d, cam->r);
    q[1] = es__v3_dot(d, cam->u);
    q[2] = es__v3_dot(d, cam->f) + cam->dist;
}

/* Place the camera: centre on the bounding box in camera axes, and for
 * perspective back off so the bounding sphere fits the field of view. Then
 * return the scale that makes the mesh span `fill` of a W x H panel. */
static double frame_mesh(const es_render_spec *spec, const es_render_mesh *m, camera *cam,
                         double W, double H)
{
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX}, q[3];
    memset(cam->c, 0, sizeof cam->c);
    cam->dist = 0;
    for (int64_t v = 0; v < m->nverts; v++) {
        to_camera(cam, m->xyz + 3 * v, q);
        for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], q[k]), hi[k] = fmax(hi[k], q[k]);
    }
    double mid[3];
    for (int k = 0; k < 3; k++) mid[k] = 0.5 * (lo[k] + hi[k]);
    for (int k = 0; k < 3; k++)
        cam->c[k] = mid[0] * cam->r[k] + mid[1] * cam->u[k] + mid[2] * cam->f[k];
    double R = 0.5 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                          (hi[2] - lo[2]) * (hi[2] - lo[2]));
    if (!(R > 0)) R = 1;
    cam->persp = spec->projection == ES_PROJ_PERSPECTIVE;
    cam->ox = cam->oy = 0;
    if (!cam->persp) {
        double sx = hi[0] - lo[0], sy = hi[1] - lo[1];
        double s = fmin(sx > 0 ? W / sx : DBL_MAX, sy > 0 ? H / sy : DBL_MAX);
        return s < DBL_MAX ? spec->fill * s : spec->fill * fmin(W, H) / (2 * R);
    }
    cam->dist = R / sin(0.5 * spec->fov_deg * M_PI / 180);
    double xlo = DBL_MAX, xhi = -DBL_MAX, ylo = DBL_MAX, yhi = -DBL_MAX;
    for (int64_t v = 0; v < m->nverts; v++) {
        to_camera(cam, m->xyz + 3 * v, q);
        xlo = fmin(xlo, q[0] / q[2]), xhi = fmax(xhi, q[0] / q[2]);
        ylo = fmin(ylo, q[1] / q[2]), yhi = fmax(yhi, q[1] / q[2]);
    }
    cam->ox = 0.5 * (xlo + xhi); /* in units of the focal length, scaled later */
    cam->oy = 0.5 * (ylo + yhi);
    double sx = xhi - xlo, sy = yhi - ylo;
    double s = fmin(sx > 0 ? W / sx : DBL_MAX, sy > 0 ? H / sy : DBL_MAX);
    return s < DBL_MAX ? spec->fill * s : spec->fill * fmin(W, H) / 2;
}

/* Screen position (pixels, y down) of camera point q in a W x H image, and
 * the depth key (smaller is nearer) and perspective weight 1/z. */
static void project(const camera *cam, const double *q, double W, double H, double *sx,
                    double *sy, double *key, double *wgt)
{
    if (cam->persp) {
        double iz = 1.0 / q[2];
        *sx = 0.5 * W + cam->scale * (q[0] * iz - cam->ox);
        *sy = 0.5 * H - cam->scale * (q[1] * iz - cam->oy);
        *key = -iz;
        *wgt = iz;
    } else {
        *sx = 0.5 * W + cam->scale * q[0];
        *sy = 0.5 * H - cam->scale * q[1];
        *key = q[2];
        *wgt = 1;
    }
}

/* ---- rasterizer ---------------------------------------------------------- */

typedef struct raster {
    int w, h;                  /* supersampled size */
    uint32_t *rgb;             /* w x h, 0x00RRGGBB: 8 bits are plenty before averaging */
    float *depth;              /* w x h, +inf: empty */
} raster;

typedef struct shade_in {
    es_ctx *ctx;
    const es_render_spec *spec;
    const es_render_mesh *m;
    const double *vnormal;     /* 3 x V, unit */
    const double *face_value;  /* per face or NULL */
    double vmin, vmax;
    int64_t drawn, back;
} shade_in;

static uint32_t pack_rgb(const double c[3])
{
    uint32_t p = 0;
    for (int k = 0; k < 3; k++) {
        double v = c[k] < 0 ? 0 : c[k] > 1 ? 1 : c[k];
        p |= (uint32_t)(v * 255 + 0.5) << (16 - 8 * k);
    }
    return p;
}

static uint32_t shade(const shade_in *in, const double n_in[3], double value, int back,
                      const double light[3])
{
    const es_render_spec *spec = in->spec;
    double n[3] = {n_in[0], n_in[1], n_in[2]}, base[3];
    if (!normalize3(n)) n[0] = light[0], n[1] = light[1], n[2] = light[2];
    if (back) n[0] = -n[0], n[1] = -n[1], n[2] = -n[2];
    double lam = fmax(0, es__v3_dot(n, light));
    if (in->m->scalar_kind == ES_SCALARS_NONE)
        memcpy(base, in->m->rgb ? in->m->rgb : spec->base_rgb, sizeof base);
    else es_colormap_rgb(spec->cmap, isfinite(value) ? (value - in->vmin) / (in->vmax - in->vmin)
                                                     : NAN, base);
    /* a small Blinn-Phong highlight (exponent 40) under the headlight */
    double l2 = lam * lam, l4 = l2 * l2, l8 = l4 * l4, l32 = l8 * l8 * l8 * l8;
    double k = 0.25 + 0.75 * lam, spec_term = 0.12 * l32 * l8;
    if (back) k *= 0.55, spec_term = 0;
    double c[3];
    for (int j = 0; j < 3; j++) c[j] = base[j] * k + spec_term;
    return pack_rgb(c);
}

static void raster_mesh(raster *R, const camera *cam, shade_in *in, const double *q,
                        const double *sx, const double *sy, const double *key,
                        const double *wgt)
{
    const es_render_mesh *m = in->m;
    double light[3] = {-cam->f[0], -cam->f[1], -cam->f[2]};
    for (int64_t f = 0; f < m->nfaces; f++) {
        const int64_t *t = m->faces + 3 * f;
        int64_t a = t[0], b = t[1], c = t[2];
        if (cam->persp && (q[3 * a + 2] <= 0 || q[3 * b + 2] <= 0 || q[3 * c + 2] <= 0))
            continue; /* behind the eye */
        double area = (sx[b] - sx[a]) * (sy[c] - sy[a]) - (sx[c] - sx[a]) * (sy[b] - sy[a]);
        if (area == 0 || !isfinite(area)) continue;
        /* screen y points down, so a counter-clockwise (front) face has area < 0 */
        int back = area > 0;
        if (back) {
            in->back++;
            if (in->spec->backface == ES_BACKFACE_CULL) continue;
        }
        int x0 = (int)fmax(0, floor(fmin(sx[a], fmin(sx[b], sx[c])))),
            x1 = (int)fmin(R->w - 1, ceil(fmax(sx[a], fmax(sx[b], sx[c])))),
            y0 = (int)fmax(0, floor(fmin(sy[a], fmin(sy[b], sy[c])))),
            y1 = (int)fmin(R->h - 1, ceil(fmax(sy[a], fmax(sy[b], sy[c]))));
        bool any = false;
        double fval = in->face_value ? in->face_value[f] : NAN;
        for (int y = y0; y <= y1; y++) {
            double py = y + 0.5;
            for (int x = x0; x <= x1; x++) {
                double px = x + 0.5;
                /* barycentric weights from edge functions */
                double l0 = ((sx[b] - px) * (sy[c] - py) - (sx[c] - px) * (sy[b] - py)) / area;
                double l1 = ((sx[c] - px) * (sy[a] - py) - (sx[a] - px) * (sy[c] - py)) / area;
                double l2 = 1 - l0 - l1;
                if (l0 < 0 || l1 < 0 || l2 < 0) continue;
                double z = l0 * key[a] + l1 * key[b] + l2 * key[c];
                size_t idx = (size_t)y * (size_t)R->w + (size_t)x;
                if (!(z < R->depth[idx])) continue;
                R->depth[idx] = (float)z;
                any = true;
                /* perspective-correct attribute weights */
                double w0 = l0 * wgt[a], w1 = l1 * wgt[b], w2 = l2 * wgt[c], ws = w0 + w1 + w2;
                w0 /= ws, w1 /= ws, w2 /= ws;
                double n[3];
                for (int k = 0; k < 3; k++)
                    n[k] = w0 * in->vnormal[3 * a + k] + w1 * in->vnormal[3 * b + k] +
                           w2 * in->vnormal[3 * c + k];
                double val = fval;
                if (m->scalar_kind == ES_SCALARS_VERTEX)
                    val = w0 * m->scalars[a] + w1 * m->scalars[b] + w2 * m->scalars[c];
                R->rgb[idx] = shade(in, n, val, back, light);
            }
        }
        if (any) in->drawn++;
        if ((f & 0x3fff) == 0x3fff) es__progress(in->ctx, "render", f, m->nfaces);
    }
}

/* Area-weighted vertex normals (the cross products are twice the areas). */
static void vertex_normals(const es_render_mesh *m, double *vn)
{
    memset(vn, 0, 3 * (size_t)m->nverts * sizeof *vn);
    for (int64_t f = 0; f < m->nfaces; f++) {
        const int64_t *t = m->faces + 3 * f;
        const double *a = m->xyz + 3 * t[0], *b = m->xyz + 3 * t[1], *c = m->xyz + 3 * t[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double s[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, n[3];
        es__v3_cross(u, s, n);
        for (int k = 0; k < 3; k++)
            for (int j = 0; j < 3; j++) vn[3 * t[k] + j] += n[j];
    }
    for (int64_t v = 0; v < m->nverts; v++) normalize3(vn + 3 * v);
}

/* Average ss x ss samples into an opaque ARGB32 image of W x H (ss 1: the
 * samples themselves). */
static void downsample(const raster *R, int ss, unsigned char *data, int stride, int W, int H)
{
    double inv = 1.0 / (ss * ss);
    for (int y = 0; y < H; y++) {
        uint32_t *row = (uint32_t *)(void *)(data + (size_t)y * (size_t)stride);
        for (int x = 0; x < W; x++) {
            double acc[3] = {0, 0, 0};
            for (int j = 0; j < ss; j++)
                for (int i = 0; i < ss; i++) {
                    uint32_t p = R->rgb[(size_t)(y * ss + j) * (size_t)R->w + (size_t)(x * ss + i)];
                    acc[0] += (p >> 16) & 0xff, acc[1] += (p >> 8) & 0xff, acc[2] += p & 0xff;
                }
            uint32_t px = 0xffu << 24;
            for (int k = 0; k < 3; k++) px |= (uint32_t)(acc[k] * inv + 0.5) << (16 - 8 * k);
            row[x] = px;
        }
    }
}

static es_status check_spec(es_ctx *ctx, const es_render_spec *spec)
{
    if (spec->nmeshes < 1 || !spec->meshes)
        ES_FAIL(ctx, ES_EINVAL, "render: no meshes to draw");
    if (spec->nmeshes > 64)
        ES_FAIL(ctx, ES_ERANGE, "render: %lld meshes in a row (at most 64)",
                (long long)spec->nmeshes);
    if (spec->width < 16 || spec->height < 16 || spec->width > 8192 || spec->height > 8192)
        ES_FAIL(ctx, ES_EINVAL, "render: panel size %d x %d is outside 16..8192", spec->width,
                spec->height);
    if (spec->supersample < 1 || spec->supersample > 4)
        ES_FAIL(ctx, ES_EINVAL, "render: supersample %d is outside 1..4", spec->supersample);
    if (!(spec->fill > 0 && spec->fill <= 1))
        ES_FAIL(ctx, ES_EINVAL, "render: fill %g is outside (0, 1]", spec->fill);
    {
        const double *p = spec->range_percentiles;
        if (!(p[0] >= 0 && p[1] <= 100 && (p[1] == 0 ? p[0] == 0 : p[0] < p[1])))
            ES_FAIL(ctx, ES_EINVAL, "render: percentiles %g, %g: want 0 <= LO < HI <= 100", p[0],
                    p[1]);
    }
    if (spec->projection == ES_PROJ_PERSPECTIVE && !(spec->fov_deg >= 1 && spec->fov_deg <= 150))
        ES_FAIL(ctx, ES_EINVAL, "render: field of view %g is outside 1..150 degrees",
                spec->fov_deg);
    if (!(spec->font_size > 0 && spec->font_size < 200))
        ES_FAIL(ctx, ES_EINVAL, "render: font size %g is outside (0, 200)", spec->font_size);
    return ES_OK;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The range_percentiles of every finite scalar of every mesh into *lo, *hi. */
static es_status percentile_range(es_ctx *ctx, const es_render_spec *spec, double *lo,
                                  double *hi)
{
    int64_t n = 0, k = 0;
    for (int64_t i = 0; i < spec->nmeshes; i++) n += nscalars(&spec->meshes[i]);
    double *v = es__alloc_array(ctx, n, sizeof *v);
    if (!v) return ES_ENOMEM;
    for (int64_t i = 0; i < spec->nmeshes; i++)
        for (int64_t j = 0; j < nscalars(&spec->meshes[i]); j++)
            if (isfinite(spec->meshes[i].scalars[j])) v[k++] = spec->meshes[i].scalars[j];
    qsort(v, (size_t)k, sizeof *v, cmp_double);
    for (int e = 0; e < 2 && k > 0; e++) {
        double p = e == 1 && spec->range_percentiles[1] <= 0 ? 100 : spec->range_percentiles[e];
        double at = p / 100 * (double)(k - 1), f = floor(at);
        int64_t i0 = (int64_t)f, i1 = i0 + 1 < k ? i0 + 1 : i0;
        *(e ? hi : lo) = v[i0] + (at - f) * (v[i1] - v[i0]);
    }
    es__free(ctx, v);
    return ES_OK;
}

es_status es__render_range(es_ctx *ctx, const es_render_spec *spec, es_render_report *rep)
{
    double lo = INFINITY, hi = -INFINITY;
    es_status rc;
    rep->n_nan_scalars = 0;
    for (int64_t i = 0; i < spec->nmeshes; i++) {
        const es_render_mesh *m = &spec->meshes[i];
        for (int64_t k = 0; k < nscalars(m); k++) {
            double v = m->scalars[k];
            if (!isfinite(v)) rep->n_nan_scalars++;
            else lo = fmin(lo, v), hi = fmax(hi, v);
        }
    }
    rep->vmin = spec->vmin;
    rep->vmax = spec->vmax;
    if ((rep->vmin == rep->vmax || !isfinite(rep->vmin) || !isfinite(rep->vmax)) && lo < hi &&
        (spec->range_percentiles[0] > 0 || (spec->range_percentiles[1] > 0 &&
                                           spec->range_percentiles[1] < 100)) &&
        (rc = percentile_range(ctx, spec, &lo, &hi)) != ES_OK)
        return rc;
    if (rep->vmin == rep->vmax || !isfinite(rep->vmin) || !isfinite(rep->vmax)) {
        double pair[2] = {lo, hi};
        rep->vmin = rep->vmax = 0;
        es__color_range(spec->cmap, pair, lo <= hi ? 2 : 0, &rep->vmin, &rep->vmax);
    } else {
        es__color_range(spec->cmap, NULL, 0, &rep->vmin, &rep->vmax);
    }
    return ES_OK;
}

es_status es_render(es_ctx *ctx, const es_render_spec *spec, const char *path,
                    es_render_report *rep_out)
{
    es_status rc;
    es_render_report rep;
    es__canvas cv = {0};
    camera *cams = NULL;
    raster R = {0};
    double *q = NULL, *sx = NULL, *sy = NULL, *key = NULL, *wgt = NULL, *vn = NULL, *fv = NULL;
    cairo_surface_t *panel = NULL;

    memset(&rep, 0, sizeof rep);
    if (rep_out) *rep_out = rep;
    if ((rc = check_spec(ctx, spec)) != ES_OK) return rc;
    int64_t n = spec->nmeshes, maxv = 0, maxf = 0;
    bool any_scalars = false;
    for (int64_t i = 0; i < n; i++) {
        const es_render_mesh *m = &spec->meshes[i];
        if ((rc = check_mesh(ctx, i, m)) != ES_OK) return rc;
        maxv = m->nverts > maxv ? m->nverts : maxv;
        maxf = m->nfaces > maxf ? m->nfaces : maxf;
        any_scalars |= m->scalar_kind != ES_SCALARS_NONE;
    }
    if ((rc = es__render_range(ctx, spec, &rep)) != ES_OK) return rc;

    /* cameras, and one scale for all panels: the coarsest that fits them all */
    int ss = spec->supersample, W = spec->width, H = spec->height;
    cams = es__alloc_array(ctx, n, sizeof *cams);
    if (!cams) return ES_ENOMEM;
    double upp = 0;
    for (int64_t i = 0; i < n; i++) {
        const es_render_mesh *vm = spec->same_view ? &spec->meshes[0] : &spec->meshes[i];
        if ((rc = make_basis(ctx, spec, vm, &cams[i])) != ES_OK) goto done;
        double s = frame_mesh(spec, &spec->meshes[i], &cams[i], (double)W * ss, (double)H * ss);
        double u = cams[i].persp ? cams[i].dist / s : 1 / s;
        upp = fmax(upp, u);
        if (spec->fit_each) cams[i].scale = s;
    }
    if (!spec->fit_each)
        for (int64_t i = 0; i < n; i++)
            cams[i].scale = cams[i].persp ? cams[i].dist / upp : 1 / upp;
    rep.units_per_pixel = upp * ss;
    memcpy(rep.view, cams[0].f, sizeof rep.view);
    memcpy(rep.up, cams[0].u, sizeof rep.up);

    /* layout of the whole picture */
    double fs = spec->font_size;
    bool labels = false;
    for (int64_t i = 0; i < n; i++) labels |= spec->meshes[i].label && *spec->meshes[i].label;
    bool cbar = any_scalars && spec->colorbar;
    int title_h = spec->title && *spec->title ? (int)ceil(2.4 * fs) : 0;
    int label_h = labels ? (int)ceil(2.0 * fs) : 0;
    int cb_w = 0;
    if (cbar) {
        cairo_surface_t *tmp = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1);
        cairo_t *tcr = cairo_create(tmp);
        cairo_select_font_face(tcr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                               CAIRO_FONT_WEIGHT_NORMAL);
        cb_w = (int)ceil(2 * fs + es__colorbar_width(tcr, fs, rep.vmin, rep.vmax,
                                                     spec->colorbar_label, fs,
                                                     spec->colorbar_log10));
        cairo_destroy(tcr);
        cairo_surface_destroy(tmp);
    }
    int64_t ncols = spec->ncols > 0 && spec->ncols < n ? spec->ncols : n;
    int64_t nrows = (n + ncols - 1) / ncols, pitch = H + label_h;
    if ((int64_t)W * ncols + cb_w > 16384 || title_h + pitch * nrows > 16384) {
        rc = es__fail(ctx, ES_ERANGE, "render: %lld panels of %d x %d in %lld columns make "
                      "a picture over 16384 pixels", (long long)n, W, H, (long long)ncols);
        goto done;
    }
    rep.width = (int)(W * ncols) + cb_w;
    rep.height = (int)(title_h + pitch * nrows);
    rep.ncols = (int)ncols;
    rep.row_pitch = (double)pitch;
    rep.panel_x0 = 0;
    rep.panel_y0 = title_h;

    /* work arrays, reused for every panel */
    size_t npx;
    if (!es__mul_size((size_t)W * (size_t)ss, (size_t)H * (size_t)ss, &npx)) {
        rc = es__fail(ctx, ES_ERANGE, "render: image size overflows");
        goto done;
    }
    R.w = W * ss;
    R.h = H * ss;
    /* not zeroed: every panel clears them (npx * 4 bytes cannot overflow:
     * npx <= 8192^2 * 16) */
    R.rgb = es__malloc(ctx, npx * sizeof *R.rgb);
    R.depth = es__malloc(ctx, npx * sizeof *R.depth);
    q = es__alloc_array(ctx, 3 * maxv, sizeof *q);
    sx = es__alloc_array(ctx, maxv, sizeof *sx);
    sy = es__alloc_array(ctx, maxv, sizeof *sy);
    key = es__alloc_array(ctx, maxv, sizeof *key);
    wgt = es__alloc_array(ctx, maxv, sizeof *wgt);
    vn = es__alloc_array(ctx, 3 * maxv, sizeof *vn);
    fv = es__alloc_array(ctx, maxf > 0 ? maxf : 1, sizeof *fv);
    if (!R.rgb || !R.depth || !q || !sx || !sy || !key || !wgt || !vn || !fv) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es__canvas_open(ctx, path, rep.width, rep.height, &cv)) != ES_OK) goto done;
    /* a PNG gets each panel at its size, the samples averaged; SVG and PDF
     * get the samples themselves (ss x the panel's pixels, drawn at the
     * panel's size), so that a vector figure zoomed or printed shows the
     * mesh ss times finer than the screen's pixels (at 480 px a panel was
     * visibly blurred in a PDF at 300 dpi), while its text stays vector */
    const int pd = cv.kind == ES__CANVAS_PNG ? 1 : ss;
    panel = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, W * pd, H * pd);
    if (cairo_surface_status(panel) != CAIRO_STATUS_SUCCESS) {
        rc = es__fail(ctx, ES_ENOMEM, "render: cannot allocate a %d x %d image", W * pd, H * pd);
        goto done;
    }
    cairo_t *cr = cv.cr;
    cairo_set_source_rgb(cr, spec->background_rgb[0], spec->background_rgb[1],
                         spec->background_rgb[2]);
    cairo_paint(cr);

    for (int64_t i = 0; i < n; i++) {
        const es_render_mesh *m = &spec->meshes[i];
        const camera *cam = &cams[i];
        es__progress(ctx, "render", i, n);
        uint32_t bg = pack_rgb(spec->background_rgb);
        for (size_t p = 0; p < npx; p++) {
            R.depth[p] = INFINITY;
            R.rgb[p] = bg;
        }
        for (int64_t v = 0; v < m->nverts; v++) {
            to_camera(cam, m->xyz + 3 * v, q + 3 * v);
            project(cam, q + 3 * v, R.w, R.h, sx + v, sy + v, key + v, wgt + v);
        }
        vertex_normals(m, vn);
        shade_in in = {ctx, spec, m, vn, NULL, rep.vmin, rep.vmax, 0, 0};
        if (m->scalar_kind == ES_SCALARS_FACE) in.face_value = m->scalars;
        if (m->scalar_kind == ES_SCALARS_EDGE) {
            if ((rc = edge_to_face(ctx, i, m, fv)) != ES_OK) goto done;
            in.face_value = fv;
        }
        raster_mesh(&R, cam, &in, q, sx, sy, key, wgt);
        rep.n_faces_drawn += in.drawn;
        rep.n_backfaces += in.back;
        cairo_surface_flush(panel);
        downsample(&R, ss / pd, cairo_image_surface_get_data(panel),
                   cairo_image_surface_get_stride(panel), W * pd, H * pd);
        cairo_surface_mark_dirty(panel);
        double px0 = (double)(W * (i % ncols)), py0 = (double)(title_h + pitch * (i / ncols));
        cairo_save(cr);
        cairo_translate(cr, px0, py0);
        cairo_scale(cr, 1.0 / pd, 1.0 / pd);
        cairo_set_source_surface(cr, panel, 0, 0);
        cairo_paint(cr);
        cairo_restore(cr);
        if (cv.kind != ES__CANVAS_PNG) {
            /* vector surfaces may keep a reference to the image: give the
             * next panel a fresh one */
            cairo_surface_destroy(panel);
            panel = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, W * pd, H * pd);
            if (cairo_surface_status(panel) != CAIRO_STATUS_SUCCESS) {
                rc = es__fail(ctx, ES_ENOMEM, "render: cannot allocate a %d x %d image",
                              W * pd, H * pd);
                goto done;
            }
        }
        if (m->label && *m->label) {
            cairo_set_source_rgb(cr, 0, 0, 0);
            es__text(cr, px0 + 0.5 * W, py0 + H + 0.4 * fs, m->label, fs, 0.5, 0, 0);
        }
    }
    es__progress(ctx, "render", n, n);
    if (title_h) {
        cairo_set_source_rgb(cr, 0, 0, 0);
        es__text(cr, 0.5 * (double)(W * ncols), 0.6 * fs, spec->title, 1.15 * fs, 0.5, 0, 0);
    }
    if (cbar) {
        /* beside the first row, or centred on all rows */
        double span = (double)(pitch * (nrows - 1) + H);
        double x = round((double)(W * ncols) + fs), y = round(title_h + 0.1 * span),
               w = round(fs), h = round(0.8 * span);
        es__draw_colorbar(cr, x, y, w, h, spec->cmap, rep.vmin, rep.vmax, spec->colorbar_label,
                          fs, spec->colorbar_log10);
        rep.colorbar[0] = x, rep.colorbar[1] = y, rep.colorbar[2] = w, rep.colorbar[3] = h;
        if (rep.n_nan_scalars > 0) {
            /* a key for the grey of missing values, under the bar */
            double ky = y + h + 0.6 * fs;
            cairo_set_source_rgb(cr, ES_NAN_GREY, ES_NAN_GREY, ES_NAN_GREY);
            cairo_rectangle(cr, x, ky, w, w);
            cairo_fill(cr);
            cairo_set_source_rgb(cr, 0, 0, 0);
            es__text(cr, x + w + 6, ky + 0.5 * w, spec->nan_label ? spec->nan_label : "n/a",
                     0.85 * fs, 0, 0.5, 0);
        }
    }
    rc = es__canvas_close(ctx, &cv);
done:
    es__canvas_discard(&cv);
    if (panel) cairo_surface_destroy(panel);
    es__free(ctx, cams);
    es__free(ctx, R.rgb);
    es__free(ctx, R.depth);
    es__free(ctx, q);
    es__free(ctx, sx);
    es__free(ctx, sy);
    es__free(ctx, key);
    es__free(ctx, wgt);
    es__free(ctx, vn);
    es__free(ctx, fv);
    if (rep_out) *rep_out = rep;
    return rc;
}
