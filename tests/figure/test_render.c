/* tests/figure/test_render.c — the mesh renderer (es_render.h): silhouettes of a
 * sphere and a square against their analytic areas, visibility of two
 * overlapping quads in either face order, back-face handling, scalar maps
 * with NaN values, colour-bar ends, the automatic view of a face-like
 * surface and its invariance under rotation, several panels with labels,
 * valid PNG and SVG output, errors; mesh files coloured by per-vertex,
 * per-face and per-edge scalars from CSV files (es_figure_render_files)
 * drawn exactly as the same arrays given to es_render. Figures are left in
 * build/test-out/render/ to be looked at. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"
#include "mesh_gen.h"
#include "test_images.h"

#include <edgespace/es_figure.h>
#include <edgespace/es_io.h>
#include <edgespace/es_render.h>
#include <sys/wait.h>

static es_render_mesh as_item(const tm_mesh *m, const char *label)
{
    es_render_mesh r;
    memset(&r, 0, sizeof r);
    r.nverts = m->nv;
    r.nfaces = m->nf;
    r.xyz = m->xyz;
    r.faces = m->faces;
    r.label = label;
    return r;
}

/* Pixels of the image that differ from white by more than 8/255 in some
 * channel. */
static int64_t count_foreground(const tp_image *im, int x0, int y0, int x1, int y1)
{
    int64_t n = 0;
    double rgb[3], white[3] = {1, 1, 1};
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            tp_rgb(im, x, y, rgb);
            n += tp_dist(rgb, white) > 8 / 255.0;
        }
    return n;
}

static void test_sphere_silhouette(es_ctx *ctx)
{
    tm_mesh s = tm_sphere(1.5, 96, 192);
    es_render_mesh it = as_item(&s, NULL);
    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.meshes = &it;
    spec.nmeshes = 1;
    spec.width = spec.height = 400;
    spec.projection = ES_PROJ_ORTHOGRAPHIC;
    es_render_report rep;
    const char *png = tp_path("render", "sphere_ortho.png");
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
    ES_CHECK(rep.width == 400 && rep.height == 400);
    ES_CHECK(rep.n_nan_scalars == 0 && rep.n_faces_drawn > s.nf / 3);
    /* the polygonal sphere is slightly smaller than the round one: area of
     * the inscribed 192-gon / circle = sin(2pi/192)/(2pi/192) */
    double r_px = 1.5 / rep.units_per_pixel;
    double want = M_PI * r_px * r_px * sin(2 * M_PI / 192) / (2 * M_PI / 192);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        int64_t got = count_foreground(&im, 0, 0, im.w, im.h);
        ES_CHECK_CLOSE((double)got, want, 0.015, 0);
        /* the sphere spans `fill` of the panel */
        ES_CHECK_CLOSE(2 * r_px, 0.9 * 400, 0.02, 0);
        /* lit from the camera: brightest in the middle, darker at the rim */
        double c[3], rim[3];
        tp_rgb(&im, 200, 200, c);
        tp_rgb(&im, 200 + (int)(0.97 * r_px), 200, rim);
        ES_CHECK(c[0] > rim[0] + 0.2);
        tp_free(&im);
    }
    /* perspective: the same sphere is framed to the same fill */
    spec.projection = ES_PROJ_PERSPECTIVE;
    png = tp_path("render", "sphere_persp.png");
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        int64_t got = count_foreground(&im, 0, 0, im.w, im.h);
        double r = 0.9 * 200;
        ES_CHECK_CLOSE((double)got, M_PI * r * r, 0.03, 0);
        tp_free(&im);
    }
    tm_free(&s);
}

/* A square of side 2 in the plane z = 0 facing +z. */
static tm_mesh make_square(void)
{
    tm_mesh m;
    m.nv = 4;
    m.nf = 2;
    m.xyz = malloc(12 * sizeof *m.xyz);
    m.faces = malloc(6 * sizeof *m.faces);
    const double p[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const int64_t f[6] = {0, 1, 2, 0, 2, 3};
    memcpy(m.xyz, p, sizeof p);
    memcpy(m.faces, f, sizeof f);
    return m;
}

static void test_square(es_ctx *ctx)
{
    tm_mesh sq = make_square();
    es_render_mesh it = as_item(&sq, NULL);
    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.meshes = &it;
    spec.nmeshes = 1;
    spec.width = 300;
    spec.height = 200;
    spec.projection = ES_PROJ_ORTHOGRAPHIC;
    spec.fill = 0.8;
    es_render_report rep;
    const char *png = tp_path("render", "square.png");
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
    /* the automatic view looks at the front (+z side): along -z, y up */
    ES_CHECK_CLOSE(rep.view[2], -1, 0, 1e-9);
    ES_CHECK(rep.n_backfaces == 0);
    tp_image im;
    double front[3] = {0, 0, 0};
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        double side = 2 / rep.units_per_pixel;
        ES_CHECK_CLOSE(side, 0.8 * 200, 1e-9, 0);
        int64_t got = count_foreground(&im, 0, 0, im.w, im.h);
        ES_CHECK_CLOSE((double)got, side * side, 0.01, 0);
        /* facing the headlight: full diffuse plus highlight, clamped */
        tp_rgb(&im, 150, 100, front);
        for (int k = 0; k < 3; k++)
            ES_CHECK_CLOSE(front[k], fmin(1, spec.base_rgb[k] + 0.12), 0, 2.5 / 255);
        tp_free(&im);
    }
    /* the mesh's own colour (es_render_mesh.rgb) instead of the spec's */
    {
        static const double blue[3] = {0.25, 0.4, 0.7};
        double own[3];
        it.rgb = blue;
        ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
        ES_CHECK(tp_load(png, &im) == 0);
        if (im.s) {
            tp_rgb(&im, 150, 100, own);
            for (int k = 0; k < 3; k++) ES_CHECK_CLOSE(own[k], blue[k] + 0.12, 0, 2.5 / 255);
            tp_free(&im);
        }
        it.rgb = NULL;
    }
    /* from behind: drawn darker, or culled */
    spec.has_view = 1;
    spec.view[0] = 0, spec.view[1] = 0, spec.view[2] = 1;
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
    ES_CHECK(rep.n_backfaces == 2);
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        double back[3];
        tp_rgb(&im, 150, 100, back);
        ES_CHECK(back[0] < 0.7 * front[0] && back[0] > 0.2);
        tp_free(&im);
    }
    spec.backface = ES_BACKFACE_CULL;
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        ES_CHECK(count_foreground(&im, 0, 0, im.w, im.h) == 0);
        tp_free(&im);
    }
    tm_free(&sq);
}

/* Two quads overlapping in the middle of the picture: A at z = 0 coloured
 * by the low end of the map, B at z = 0.5 (nearer the camera, which looks
 * along -z) by the high end. The overlap shows B whatever the face order. */
static void test_overlap(es_ctx *ctx)
{
    const double p[24] = {-1, -1, 0, 0.5, -1, 0, 0.5, 1, 0, -1, 1, 0,
                          -0.5, -1, 0.5, 1, -1, 0.5, 1, 1, 0.5, -0.5, 1, 0.5};
    const int64_t fa[12] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
    const int64_t fb[12] = {4, 5, 6, 4, 6, 7, 0, 1, 2, 0, 2, 3};
    const double va[4] = {0, 0, 1, 1}, vb[4] = {1, 1, 0, 0};
    double lowc[3], highc[3];
    es_colormap_rgb(ES_CMAP_VIRIDIS, 0, lowc);
    es_colormap_rgb(ES_CMAP_VIRIDIS, 1, highc);
    for (int order = 0; order < 2; order++) {
        es_render_mesh it;
        memset(&it, 0, sizeof it);
        it.nverts = 8;
        it.nfaces = 4;
        it.xyz = p;
        it.faces = order ? fb : fa;
        it.scalar_kind = ES_SCALARS_FACE;
        it.scalars = order ? vb : va;
        for (int proj = 0; proj < 2; proj++) {
            es_render_spec spec;
            es_render_spec_init(&spec);
            spec.meshes = &it;
            spec.nmeshes = 1;
            spec.width = spec.height = 200;
            spec.colorbar = 0;
            spec.projection = proj ? ES_PROJ_ORTHOGRAPHIC : ES_PROJ_PERSPECTIVE;
            spec.has_view = spec.has_up = 1;
            spec.view[2] = -1;
            spec.up[1] = 1;
            es_render_report rep;
            const char *png = tp_path("render", order ? "overlap_b.png" : "overlap_a.png");
            ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
            tp_image im;
            ES_CHECK(tp_load(png, &im) == 0);
            if (!im.s) continue;
            double mid[3], left[3], right[3];
            tp_rgb(&im, 100, 100, mid);    /* overlap: B */
            tp_rgb(&im, 40, 100, left);    /* A only */
            tp_rgb(&im, 160, 100, right);  /* B only */
            ES_CHECK_MSG(tp_dist(mid, highc) < tp_dist(mid, lowc), "order %d proj %d", order,
                         proj);
            ES_CHECK(tp_dist(mid, right) < 0.03);
            ES_CHECK(tp_dist(left, lowc) < tp_dist(left, highc));
            tp_free(&im);
        }
    }
}

static void test_scalars(es_ctx *ctx)
{
    tm_mesh s = tm_sphere(1, 48, 96);
    double *vs = malloc((size_t)s.nv * sizeof *vs);
    for (int64_t v = 0; v < s.nv; v++) vs[v] = s.xyz[3 * v + 1]; /* height */
    /* NaN on the vertices near (0, 0, 1) — the front after the auto view */
    int64_t nnan = 0;
    for (int64_t v = 0; v < s.nv; v++) {
        const double *p = s.xyz + 3 * v;
        if (p[0] * p[0] + p[1] * p[1] < 0.04 && fabs(p[2]) > 0.5) vs[v] = NAN, nnan++;
    }
    es_render_mesh it = as_item(&s, "height");
    it.scalar_kind = ES_SCALARS_VERTEX;
    it.scalars = vs;
    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.meshes = &it;
    spec.nmeshes = 1;
    spec.width = spec.height = 300;
    spec.colorbar_label = "y";
    spec.title = "vertex scalars";
    spec.has_view = spec.has_up = 1;
    spec.view[2] = -1;
    spec.up[1] = 1;
    es_render_report rep;
    const char *png = tp_path("render", "sphere_vertex_scalars.png");
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
    ES_CHECK(rep.n_nan_scalars == nnan && nnan > 0);
    ES_CHECK_CLOSE(rep.vmin, -1, 0, 1e-12);
    ES_CHECK_CLOSE(rep.vmax, 1, 0, 1e-12);
    ES_CHECK(rep.width > 300 && rep.height > 300 && rep.colorbar[3] > 100);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        ES_CHECK(im.w == rep.width && im.h == rep.height);
        /* colour bar: top row is the map at 1, bottom row at 0 */
        double got[3], want[3];
        int cx = (int)(rep.colorbar[0] + 0.5 * rep.colorbar[2]);
        tp_rgb(&im, cx, (int)rep.colorbar[1], got);
        es_colormap_rgb(spec.cmap, 1, want);
        ES_CHECK(tp_dist(got, want) < 1.5 / 255);
        tp_rgb(&im, cx, (int)(rep.colorbar[1] + rep.colorbar[3] - 1), got);
        es_colormap_rgb(spec.cmap, 0, want);
        ES_CHECK(tp_dist(got, want) < 1.5 / 255);
        /* the NaN spot in the middle is grey (r = g = b), the top is
         * yellowish (high end), the bottom purple (low end) */
        int pcx = (int)(rep.panel_x0 + 150), pcy = (int)(rep.panel_y0 + 150);
        tp_rgb(&im, pcx, pcy, got);
        ES_CHECK(fabs(got[0] - got[1]) < 0.02 && fabs(got[1] - got[2]) < 0.02);
        double top[3], bottom[3];
        tp_rgb(&im, pcx, pcy - 120, top);
        tp_rgb(&im, pcx, pcy + 120, bottom);
        ES_CHECK(top[1] > top[2] && bottom[2] > bottom[1]);
        tp_free(&im);
    }
    /* no NaN scalars: none counted */
    for (int64_t v = 0; v < s.nv; v++) vs[v] = s.xyz[3 * v + 1];
    spec.cmap = ES_CMAP_RDBU;
    ES_CHECK_OK(ctx, es_render(ctx, &spec, tp_path("render", "sphere_rdbu.png"), &rep));
    ES_CHECK(rep.n_nan_scalars == 0);

    /* per-edge scalars: each edge's mean height; edges listed (max, min) in
     * reverse order to show the list may come in any order */
    int64_t ne = 0, *edges = malloc(6 * (size_t)s.nf * sizeof *edges);
    for (int64_t f = 0; f < s.nf; f++)
        for (int k = 0; k < 3; k++) {
            int64_t a = s.faces[3 * f + k], b = s.faces[3 * f + (k + 1) % 3];
            if (a < b) continue; /* each interior edge once, from one of its faces */
            edges[2 * ne] = a;
            edges[2 * ne + 1] = b;
            ne++;
        }
    double *es_ = malloc((size_t)ne * sizeof *es_);
    for (int64_t e = 0; e < ne; e++)
        es_[e] = 0.5 * (s.xyz[3 * edges[2 * e] + 1] + s.xyz[3 * edges[2 * e + 1] + 1]);
    es_[0] = NAN;
    it.scalar_kind = ES_SCALARS_EDGE;
    it.scalars = es_;
    it.edges = edges;
    it.nedges = ne;
    it.label = "edge scalars";
    spec.cmap = ES_CMAP_VIRIDIS;
    ES_CHECK_OK(ctx, es_render(ctx, &spec, tp_path("render", "sphere_edge_scalars.png"), &rep));
    ES_CHECK(rep.n_nan_scalars == 1);
    ES_CHECK(rep.vmax < 1 && rep.vmin > -1);
    it.nedges = ne - 1; /* an edge missing from the list */
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, tp_path("render", "x.png"), NULL), ES_ENOTFOUND,
                   "not in the edge list");
    free(es_);
    free(edges);
    free(vs);
    tm_free(&s);
}

/* Rotate points by the rotation R (row-major 3 x 3). */
static void rotate(const double R[9], const double *in, double *out, int64_t n)
{
    for (int64_t v = 0; v < n; v++)
        for (int i = 0; i < 3; i++)
            out[3 * v + i] = R[3 * i] * in[3 * v] + R[3 * i + 1] * in[3 * v + 1] +
                             R[3 * i + 2] * in[3 * v + 2];
}

static void test_auto_view(es_ctx *ctx)
{
    tm_mesh f = tm_face(96, 64);
    double view[3], up[3];
    ES_CHECK_OK(ctx, es_render_auto_view(ctx, f.nv, f.xyz, f.nf, f.faces, view, up));
    /* from the front (within 3 degrees: the features tilt the axes a
     * little in the symmetry plane), chin down, forehead up */
    ES_CHECK(view[2] < -cos(3 * M_PI / 180) && fabs(view[0]) < 1e-9);
    ES_CHECK(up[1] > cos(3 * M_PI / 180) && fabs(up[0]) < 1e-9);
    double v0[3], u0[3];
    memcpy(v0, view, sizeof v0);
    memcpy(u0, up, sizeof u0);
    /* without faces the sign of the view falls back to the axis rule */
    ES_CHECK_OK(ctx, es_render_auto_view(ctx, f.nv, f.xyz, 0, NULL, view, up));
    ES_CHECK_CLOSE(fabs(view[2]), fabs(v0[2]), 0, 1e-12);

    /* a tilted copy (still within 11 degrees of y-up): view and up rotate with it */
    double a = 0.12, b = 0.5;
    const double Rx[9] = {1, 0, 0, 0, cos(a), -sin(a), 0, sin(a), cos(a)};
    const double Ry[9] = {cos(b), 0, sin(b), 0, 1, 0, -sin(b), 0, cos(b)};
    double R[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            R[3 * i + j] = 0;
            for (int k = 0; k < 3; k++) R[3 * i + j] += Ry[3 * i + k] * Rx[3 * k + j];
        }
    double *xr = malloc(3 * (size_t)f.nv * sizeof *xr), vr[3], ur[3];
    rotate(R, f.xyz, xr, f.nv);
    rotate(R, v0, vr, 1);
    rotate(R, u0, ur, 1);
    ES_CHECK_OK(ctx, es_render_auto_view(ctx, f.nv, xr, f.nf, f.faces, view, up));
    for (int k = 0; k < 3; k++) {
        ES_CHECK_CLOSE(view[k], vr[k], 0, 1e-6);
        ES_CHECK_CLOSE(up[k], ur[k], 0, 1e-6);
    }

    /* the face from the front, a three-quarter view and in perspective,
     * side by side with a torus and a bumpy disc: to look at */
    tm_mesh t = tm_torus(1, 0.35, 96, 48), d = tm_bumpy_disc(96, 32);
    es_render_mesh items[4] = {as_item(&f, "face (auto view)"), as_item(&t, "torus"),
                               as_item(&d, "bumpy disc"), as_item(&f, "face, tilted")};
    items[3].xyz = xr;
    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.meshes = items;
    spec.nmeshes = 4;
    spec.width = spec.height = 320;
    spec.title = "synthetic meshes, automatic views";
    spec.fit_each = 1;
    es_render_report rep;
    const char *png = tp_path("render", "row.png");
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, &rep));
    ES_CHECK(rep.width == 4 * 320 && rep.height > 320);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        /* every panel has something in it, and the gaps between them are empty */
        for (int i = 0; i < 4; i++) {
            int64_t c = count_foreground(&im, 320 * i, (int)rep.panel_y0, 320 * (i + 1),
                                         (int)rep.panel_y0 + 320);
            ES_CHECK_MSG(c > 0.2 * 320 * 320, "panel %d: %lld pixels", i, (long long)c);
        }
        /* the tilted copy is seen the same way: the same picture up to
         * rasterization (mean channel difference) */
        double diff = 0, p0[3], p3[3];
        for (int y = 0; y < 320; y++)
            for (int x = 0; x < 320; x++) {
                tp_rgb(&im, x, (int)rep.panel_y0 + y, p0);
                tp_rgb(&im, 3 * 320 + x, (int)rep.panel_y0 + y, p3);
                diff += fabs(p0[0] - p3[0]) + fabs(p0[1] - p3[1]) + fabs(p0[2] - p3[2]);
            }
        diff /= 3 * 320 * 320;
        ES_CHECK_MSG(diff < 0.005, "mean difference %g", diff);
        tp_free(&im);
    }
    /* the same four in a 2 x 2 grid: panel 3 is at column 1, row 1 */
    spec.ncols = 2;
    const char *grid = tp_path("render", "grid.png");
    es_render_report rg;
    ES_CHECK_OK(ctx, es_render(ctx, &spec, grid, &rg));
    ES_CHECK(rg.ncols == 2 && rg.width == 2 * 320 && rg.height == (int)(rg.panel_y0 + 2 * rg.row_pitch));
    ES_CHECK(tp_load(grid, &im) == 0);
    if (im.s) {
        for (int i = 0; i < 4; i++) {
            int x0 = (int)rg.panel_x0 + 320 * (i % 2), y0 = (int)(rg.panel_y0 + rg.row_pitch * (i / 2));
            int64_t c = count_foreground(&im, x0, y0, x0 + 320, y0 + 320);
            ES_CHECK_MSG(c > 0.2 * 320 * 320, "grid panel %d: %lld pixels", i, (long long)c);
        }
        tp_free(&im);
    }
    spec.ncols = 0;
    const char *svg = tp_path("render", "row.svg");
    ES_CHECK_OK(ctx, es_render(ctx, &spec, svg, &rep));
    ES_CHECK(tp_file_has(svg, "<?xml", "<svg") && tp_file_size(svg) > 20000);
    /* a vector figure holds each panel at supersample x its pixels (3 x 320),
     * drawn at the panel's size */
    {
        size_t nsvg = 0;
        char *text = es_test_slurp(svg, &nsvg);
        ES_CHECK(spec.supersample == 3 && text && strstr(text, "width=\"960\"") &&
                 strstr(text, "matrix(0.333333,0,0,0.333333,320,"));
        free(text);
    }

    /* a three-quarter view of the face, explicit */
    es_render_mesh one = as_item(&f, "face, 3/4 view");
    spec.meshes = &one;
    spec.nmeshes = 1;
    spec.title = NULL;
    spec.has_view = spec.has_up = 1;
    spec.view[0] = 0.6, spec.view[1] = -0.2, spec.view[2] = -1;
    spec.up[0] = 0, spec.up[1] = 1, spec.up[2] = 0;
    ES_CHECK_OK(ctx, es_render(ctx, &spec, tp_path("render", "face_34.png"), &rep));
    free(xr);
    tm_free(&t);
    tm_free(&d);
    tm_free(&f);
}

static void test_errors(es_ctx *ctx)
{
    tm_mesh sq = make_square();
    es_render_mesh it = as_item(&sq, NULL);
    es_render_spec spec;
    es_render_spec_init(&spec);
    const char *png = tp_path("render", "err.png");
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, png, NULL), ES_EINVAL, "no meshes");
    spec.meshes = &it;
    spec.nmeshes = 1;
    sq.faces[4] = 9;
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, png, NULL), ES_EINVAL, "face 1");
    sq.faces[4] = 2;
    spec.has_view = 1; /* zero vector */
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, png, NULL), ES_EINVAL, "view direction");
    spec.view[1] = 1;
    spec.has_up = 1;
    spec.up[1] = 2;
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, png, NULL), ES_EINVAL, "parallel");
    spec.has_up = 0; /* automatic up parallel to the view: a coordinate axis instead */
    ES_CHECK_OK(ctx, es_render(ctx, &spec, png, NULL));
    it.scalar_kind = ES_SCALARS_VERTEX;
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, png, NULL), ES_EINVAL, "no scalars");
    it.scalar_kind = ES_SCALARS_NONE;
    sq.xyz[5] = NAN;
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, png, NULL), ES_EINVAL, "vertex 1");
    sq.xyz[5] = 0;
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, "/nonexistent-dir/r.png", NULL), ES_EIO,
                   "nonexistent");
    spec.supersample = 9;
    ES_CHECK_FAILS(ctx, es_render(ctx, &spec, png, NULL), ES_EINVAL, "supersample");
    tm_free(&sq);
}

/* A real face from ../shared/data/face-study (randomly rotated per file):
 * the automatic view must show it upright from the front. Checked on the
 * geometry: the nose tip (the vertex nearest the camera) lies on the
 * vertical midline of the silhouette, and below the middle of a head that
 * includes the neck is not expected, so only "between 20% and 80% of the
 * height" is asked; the eyes (boundary loops) lie above the nose tip. */
static void test_shared_faces(es_ctx *ctx)
{
    const char *data = es_test_shared_data();
    char path[8192];
    if (!data) {
        fprintf(stderr, "SKIP (section): ../shared/data absent, no real face rendered\n");
        return;
    }
    static const char *const names[3] = {"s001_neutral", "s001_happy", "s001_angry"};
    es_meshdata md[3];
    es_render_mesh items[3];
    memset(md, 0, sizeof md);
    memset(items, 0, sizeof items);
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/face-study/%s.obj", data, names[i]);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md[i]));
        if (!md[i].xyz) return;
        items[i].nverts = md[i].nverts;
        items[i].nfaces = md[i].nfaces;
        items[i].xyz = md[i].xyz;
        items[i].faces = md[i].faces;
        items[i].label = names[i];

        double view[3], up[3], right[3];
        ES_CHECK_OK(ctx, es_render_auto_view(ctx, md[i].nverts, md[i].xyz, md[i].nfaces,
                                             md[i].faces, view, up));
        right[0] = view[1] * up[2] - view[2] * up[1];
        right[1] = view[2] * up[0] - view[0] * up[2];
        right[2] = view[0] * up[1] - view[1] * up[0];
        double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY,
               dmin = INFINITY, nx = 0, ny = 0;
        for (int64_t v = 0; v < md[i].nverts; v++) {
            const double *p = md[i].xyz + 3 * v;
            double x = p[0] * right[0] + p[1] * right[1] + p[2] * right[2];
            double y = p[0] * up[0] + p[1] * up[1] + p[2] * up[2];
            double d = p[0] * view[0] + p[1] * view[1] + p[2] * view[2];
            xlo = fmin(xlo, x), xhi = fmax(xhi, x), ylo = fmin(ylo, y), yhi = fmax(yhi, y);
            if (d < dmin) dmin = d, nx = x, ny = y;
        }
        double fx = (nx - xlo) / (xhi - xlo), fy = (ny - ylo) / (yhi - ylo);
        ES_CHECK_MSG(fabs(fx - 0.5) < 0.1, "%s: nose tip at %.2f of the width", names[i], fx);
        ES_CHECK_MSG(fy > 0.2 && fy < 0.8, "%s: nose tip at %.2f of the height", names[i], fy);
        /* the eye holes sit above the nose tip: the mean height of the
         * boundary vertices of the mesh's upper half beats the nose's */
        es_mesh *m = NULL;
        ES_CHECK_OK(ctx, es_mesh_new(ctx, md[i].nverts, md[i].nfaces, md[i].faces, NULL, &m));
        if (m) {
            const int64_t *lo_, *lv;
            int64_t nl = es_mesh_boundary_loops(m, &lo_, &lv);
            int eyes_above = 0;
            for (int64_t l = 0; l < nl; l++) {
                double sy = 0, sx = 0;
                int64_t cnt = lo_[l + 1] - lo_[l];
                for (int64_t k = lo_[l]; k < lo_[l + 1]; k++) {
                    const double *p = md[i].xyz + 3 * lv[k];
                    sy += p[0] * up[0] + p[1] * up[1] + p[2] * up[2];
                    sx += p[0] * right[0] + p[1] * right[1] + p[2] * right[2];
                }
                sx /= (double)cnt, sy /= (double)cnt;
                /* small loops off the midline: the eyes */
                if (cnt < 200 && fabs((sx - xlo) / (xhi - xlo) - 0.5) > 0.08) eyes_above += sy > ny;
            }
            ES_CHECK_MSG(eyes_above == 2, "%s: %d eye loops above the nose", names[i], eyes_above);
            es_mesh_free(m);
        }
    }
    /* per-edge scalars through es_render_mesh_from: the log ratio of the
     * happy and neutral edge lengths, drawn on the happy face */
    es_mesh *topo = NULL;
    ES_CHECK_OK(ctx, es_mesh_new(ctx, md[0].nverts, md[0].nfaces, md[0].faces, md[0].xyz, &topo));
    if (topo) {
        es_render_mesh e;
        es_render_mesh_from(&e, topo, md[1].xyz);
        ES_CHECK(e.xyz == md[1].xyz && e.nedges == es_mesh_nedges(topo) && e.faces);
        double *lr = malloc((size_t)e.nedges * sizeof *lr);
        for (int64_t k = 0; k < e.nedges; k++) {
            double la = 0, lb = 0;
            for (int c = 0; c < 3; c++) {
                double d0 = md[0].xyz[3 * e.edges[2 * k] + c] - md[0].xyz[3 * e.edges[2 * k + 1] + c];
                double d1 = md[1].xyz[3 * e.edges[2 * k] + c] - md[1].xyz[3 * e.edges[2 * k + 1] + c];
                la += d0 * d0, lb += d1 * d1;
            }
            lr[k] = 0.5 * log(lb / la);
        }
        e.scalar_kind = ES_SCALARS_EDGE;
        e.scalars = lr;
        e.label = "log(happy / neutral) per edge";
        es_render_spec sp;
        es_render_spec_init(&sp);
        sp.meshes = &e;
        sp.nmeshes = 1;
        sp.cmap = ES_CMAP_RDBU;
        sp.vmin = -0.3, sp.vmax = 0.3;
        es_render_report r2;
        ES_CHECK_OK(ctx, es_render(ctx, &sp, tp_path("render", "face_study_edge_ratio.png"), &r2));
        ES_CHECK(r2.vmin == -0.3 && r2.vmax == 0.3);
        free(lr);
        es_mesh_free(topo);
    }

    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.meshes = items;
    spec.nmeshes = 3;
    spec.title = "face-study s001 (automatic views)";
    es_render_report rep;
    ES_CHECK_OK(ctx, es_render(ctx, &spec, tp_path("render", "face_study_s001.png"), &rep));
    ES_CHECK(rep.n_faces_drawn > md[0].nfaces / 2);
    for (int i = 0; i < 3; i++) es_meshdata_clear(ctx, &md[i]);
}

/* ---- es_figure_render_files: mesh files and scalar CSV files ------------ */

static int same_file(const char *a, const char *b)
{
    size_t na = 0, nb = 0;
    char *x = es_test_slurp(a, &na), *y = es_test_slurp(b, &nb);
    int same = x && y && na == nb && !memcmp(x, y, na);
    free(x);
    free(y);
    return same;
}

static void write_obj(const char *path, const tm_mesh *m)
{
    FILE *f = fopen(path, "w");
    ES_CHECK(f != NULL);
    if (!f) return;
    for (int64_t v = 0; v < m->nv; v++)
        fprintf(f, "v %.17g %.17g %.17g\n", m->xyz[3 * v], m->xyz[3 * v + 1], m->xyz[3 * v + 2]);
    for (int64_t k = 0; k < m->nf; k++)
        fprintf(f, "f %lld %lld %lld\n", (long long)m->faces[3 * k] + 1,
                (long long)m->faces[3 * k + 1] + 1, (long long)m->faces[3 * k + 2] + 1);
    fclose(f);
}

/* values[0..n) one per line, NaN as `missing` (a blank line, "nan", ...),
 * after an optional header line. */
static void write_values(const char *path, const char *header, const double *v, int64_t n,
                         const char *missing)
{
    FILE *f = fopen(path, "w");
    ES_CHECK(f != NULL);
    if (!f) return;
    if (header) fprintf(f, "%s\n", header);
    for (int64_t i = 0; i < n; i++)
        if (isnan(v[i])) fprintf(f, "%s\n", missing);
        else fprintf(f, "%.17g,ignored\n", v[i]);
    fclose(f);
}

/* The file route and es_render on the same arrays give the same picture
 * byte for byte: vertex values with a header and blank-line and "nan"
 * missing values, face values, edge values in es_mesh order. */
static void test_render_files(es_ctx *ctx)
{
    tm_mesh s = tm_sphere(1, 16, 32);
    es_mesh *mesh = NULL;
    char obj[4200], csv[4200], a[4200], b[4200];
    snprintf(obj, sizeof obj, "%s", tp_path("render", "files_sphere.obj"));
    snprintf(csv, sizeof csv, "%s", tp_path("render", "files_scalars.csv"));
    write_obj(obj, &s);
    ES_CHECK_OK(ctx, es_mesh_new(ctx, s.nv, s.nf, s.faces, NULL, &mesh));
    if (!mesh) return;
    int64_t ne = es_mesh_nedges(mesh);
    const int64_t *edges = es_mesh_edges(mesh);
    ES_CHECK(ne != s.nv && ne != s.nf && s.nv != s.nf);
    double *val = malloc((size_t)(ne + s.nv + s.nf) * sizeof *val);
    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.width = spec.height = 120;
    spec.has_view = spec.has_up = 1;
    spec.view[2] = -1;
    spec.up[1] = 1;
    es_render_report rep, rep2;
    const char *const paths[1] = {obj}, *const scal[1] = {csv};
    static const char *const what[3] = {"vertex", "face", "edge"};
    static const es_scalar_kind kinds[3] = {ES_SCALARS_VERTEX, ES_SCALARS_FACE, ES_SCALARS_EDGE};
    int64_t counts[3] = {s.nv, s.nf, ne};
    for (int k = 0; k < 3; k++) {
        int64_t n = counts[k];
        for (int64_t i = 0; i < n; i++) {
            const int64_t *c = k == 0 ? &i : k == 1 ? s.faces + 3 * i : edges + 2 * i;
            int nc = k == 0 ? 1 : k == 1 ? 3 : 2;
            val[i] = 0;
            for (int j = 0; j < nc; j++) val[i] += s.xyz[3 * c[j] + 1] / nc; /* height */
        }
        val[3] = NAN;
        if (k == 0) val[7] = NAN;
        write_values(csv, k == 0 ? "height" : NULL, val, n, "");
        if (k == 0) { /* one "nan" in place of a blank line */
            write_values(csv, "height", val, 7, "");
            FILE *f = fopen(csv, "a");
            if (f) {
                fprintf(f, "nan\n");
                for (int64_t i = 8; i < n; i++) fprintf(f, "%.17g\n", val[i]);
                fclose(f);
            }
        }
        snprintf(a, sizeof a, "%s", tp_path("render", k == 0 ? "files_vertex.png" :
                                                       k == 1 ? "files_face.png" : "files_edge.png"));
        snprintf(b, sizeof b, "%s", tp_path("render", "files_direct.png"));
        ES_CHECK_OK(ctx, es_figure_render_files(ctx, &spec, 1, paths, 1, scal, NULL, a, &rep));
        ES_CHECK_MSG(rep.n_nan_scalars == (k == 0 ? 2 : 1), "%s: %lld missing", what[k],
                     (long long)rep.n_nan_scalars);
        ES_CHECK(rep.vmin > -1.01 && rep.vmax < 1.01 && rep.vmax - rep.vmin > 1.5);
        es_render_mesh it = as_item(&s, NULL);
        it.scalar_kind = kinds[k];
        it.scalars = val;
        it.nedges = ne;
        it.edges = edges;
        es_render_spec sp = spec;
        sp.meshes = &it;
        sp.nmeshes = 1;
        if (k == 0) sp.colorbar_label = "height";   /* the file's header labels its bar */
        ES_CHECK_OK(ctx, es_render(ctx, &sp, b, &rep2));
        ES_CHECK_MSG(same_file(a, b), "%s scalars from a file differ from es_render's", what[k]);
        ES_CHECK(rep2.n_nan_scalars == rep.n_nan_scalars && rep2.vmin == rep.vmin);
        tp_image im;
        ES_CHECK(tp_load(a, &im) == 0);
        if (im.s) { /* top of the sphere near the map's high end, bottom near its low end */
            double top[3], bottom[3], hi[3], lo[3];
            int cx = (int)(rep.panel_x0 + 60), cy = (int)(rep.panel_y0 + 60);
            tp_rgb(&im, cx, cy - 45, top);
            tp_rgb(&im, cx, cy + 45, bottom);
            es_colormap_rgb(spec.cmap, 1, hi);
            es_colormap_rgb(spec.cmap, 0, lo);
            ES_CHECK_MSG(tp_dist(top, hi) < tp_dist(top, lo) &&
                         tp_dist(bottom, lo) < tp_dist(bottom, hi), "%s colours", what[k]);
            tp_free(&im);
        }
    }

    /* one file for two meshes: file names under the panels by default */
    const char *const two[2] = {obj, obj}, *const lab[2] = {"first", NULL};
    ES_CHECK_OK(ctx, es_figure_render_files(ctx, &spec, 2, two, 1, scal, lab,
                                            tp_path("render", "files_two.png"), &rep));
    ES_CHECK(rep.ncols == 2 && rep.width >= 2 * 120 && rep.n_nan_scalars == 2);
    ES_CHECK_OK(ctx, es_figure_render_files(ctx, &spec, 2, two, 0, NULL, NULL,
                                            tp_path("render", "files_two_plain.png"), &rep));
    ES_CHECK(rep.n_nan_scalars == 0);

    /* errors name the file, and the line */
    char wbuf[8600];
    const char *want = wbuf, *png = tp_path("render", "files_err.png");
    es_test_write_file(csv, "1\n2\n3\n");
    snprintf(wbuf, sizeof wbuf, "'%s' has 3 values; '%s' has %lld vertices, %lld edges, %lld faces",
             csv, obj, (long long)s.nv, (long long)ne, (long long)s.nf);
    ES_CHECK_FAILS(ctx, es_figure_render_files(ctx, &spec, 1, paths, 1, scal, NULL, png, NULL),
                   ES_EMISMATCH, want);
    es_test_write_file(csv, "v\n1\n\nx\n");
    snprintf(wbuf, sizeof wbuf, "%s:4: 'x' is not a number", csv);
    ES_CHECK_FAILS(ctx, es_figure_render_files(ctx, &spec, 1, paths, 1, scal, NULL, png, NULL),
                   ES_EFORMAT, want);
    es_test_write_file(csv, "1\n\"2\n");
    snprintf(wbuf, sizeof wbuf, "scalars '%s' line 3: unterminated quoted field (opened on line 2)",
             csv);
    ES_CHECK_FAILS(ctx, es_figure_render_files(ctx, &spec, 1, paths, 1, scal, NULL, png, NULL),
                   ES_EFORMAT, want);
    const char *const gone[1] = {"/nonexistent-dir/s.csv"};
    ES_CHECK_FAILS(ctx, es_figure_render_files(ctx, &spec, 1, paths, 1, gone, NULL, png, NULL),
                   ES_EIO, "cannot open '/nonexistent-dir/s.csv'");
    const char *const three[3] = {obj, obj, obj};
    ES_CHECK_FAILS(ctx, es_figure_render_files(ctx, &spec, 3, three, 2, two, NULL, png, NULL),
                   ES_EINVAL, "2 scalar files for 3 meshes");
    const char *const nomesh[1] = {"/nonexistent-dir/m.obj"};
    ES_CHECK_FAILS(ctx, es_figure_render_files(ctx, &spec, 1, nomesh, 0, NULL, NULL, png, NULL),
                   ES_EIO, "/nonexistent-dir/m.obj");

    /* allocation failures, on two squares with edge scalars: every allocation
     * of a successful call failed in turn gives ES_ENOMEM (or, where a
     * reader only shrinks a buffer, success) and leaves nothing allocated */
    tm_mesh sq = make_square();
    static const double ev[5] = {1, 2, 3, 4, NAN};
    snprintf(obj, sizeof obj, "%s", tp_path("render", "files_square.obj"));
    write_obj(obj, &sq);
    write_values(csv, "e", ev, 5, "");
    spec.width = spec.height = 32;
    failing_alloc fa = {0, 0, 0};
    es_allocator al = {fa_malloc, fa_realloc, fa_free, &fa};
    es_ctx_set_allocator(ctx, &al);
    ES_CHECK_OK(ctx, es_figure_render_files(ctx, &spec, 2, two, 1, scal, NULL, png, &rep));
    es_ctx_set_allocator(ctx, NULL);
    ES_CHECK(rep.n_nan_scalars == 2 && fa.live == 0);
    int64_t total = fa.count, nomem = 0;
    for (int64_t k = 1; k <= total; k++) {
        failing_alloc fk = {0, k, 0};
        es_allocator ak = {fa_malloc, fa_realloc, fa_free, &fk};
        es_ctx_set_allocator(ctx, &ak);
        es_status rc = es_figure_render_files(ctx, &spec, 2, two, 1, scal, NULL, png, NULL);
        es_ctx_set_allocator(ctx, NULL);
        nomem += rc == ES_ENOMEM;
        ES_CHECK_MSG(rc == ES_OK || rc == ES_ENOMEM, "k %lld: rc %d", (long long)k, rc);
        ES_CHECK_MSG(fk.live == 0, "k %lld: %lld blocks left", (long long)k, (long long)fk.live);
    }
    ES_CHECK_MSG(total > 20 && nomem > total / 2, "%lld of %lld failed allocations reported",
                 (long long)nomem, (long long)total);
    {   /* every failed figure took its part file with it */
        char dir[4200];
        snprintf(dir, sizeof dir, "%s", png);
        *strrchr(dir, '/') = 0;
        ES_CHECK_MSG(es_test_count_entries(dir, ".part") == 0, "a part file stayed in %s", dir);
    }
    tm_free(&sq);
    free(val);
    es_mesh_free(mesh);
    tm_free(&s);
}

/* The edgespace render command on a sphere written as OBJ. */
static int run(const char *cmd)
{
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void test_cli(void)
{
    const char *exe = getenv("EDGESPACE");
    char cmd[16384];
    if (!exe) {
        fprintf(stderr, "SKIP (section): EDGESPACE not set, command not tested\n");
        return;
    }
    tm_mesh s = tm_sphere(1, 16, 32);
    const char *obj = tp_path("render", "cli_sphere.obj"), *csv = tp_path("render", "cli.csv");
    const char *png = tp_path("render", "cli_sphere.png"), *bad = tp_path("render", "bad.csv");
    FILE *f = fopen(obj, "w"), *g = fopen(csv, "w"), *h = fopen(bad, "w");
    ES_CHECK(f && g && h);
    if (!f || !g || !h) return;
    for (int64_t v = 0; v < s.nv; v++)
        fprintf(f, "v %.17g %.17g %.17g\n", s.xyz[3 * v], s.xyz[3 * v + 1], s.xyz[3 * v + 2]);
    for (int64_t k = 0; k < s.nf; k++)
        fprintf(f, "f %lld %lld %lld\n", (long long)s.faces[3 * k] + 1,
                (long long)s.faces[3 * k + 1] + 1, (long long)s.faces[3 * k + 2] + 1);
    fprintf(g, "height\n");
    for (int64_t v = 0; v < s.nv; v++)
        if (v == 3) fprintf(g, "nan\n");
        else fprintf(g, "%.6g\n", s.xyz[3 * v + 1]);
    fprintf(h, "1\n2\n3\n");
    fclose(f);
    fclose(g);
    fclose(h);
    remove(png);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --scalars '%s' --cmap rdbu "
             "--view 0,0,-1 --up 0,1,0 --width 200 --height 200 --title sphere >/dev/null 2>&1",
             exe, obj, png, csv);
    ES_CHECK(run(cmd) == 0);
    tp_image im;
    ES_CHECK(tp_load(png, &im) == 0);
    if (im.s) {
        ES_CHECK(im.w > 200 && im.h > 200); /* colour bar and title */
        tp_free(&im);
    }
    snprintf(cmd, sizeof cmd, "'%s' render '%s' '%s' -o '%s' --ortho --same-view >/dev/null",
             exe, obj, obj, tp_path("render", "cli_two.svg"));
    ES_CHECK(run(cmd) == 0);
    ES_CHECK(tp_file_has(tp_path("render", "cli_two.svg"), "<?xml", "<svg"));
    snprintf(cmd, sizeof cmd, "'%s' render --help >/dev/null", exe);
    ES_CHECK(run(cmd) == 0);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' >/dev/null 2>&1", exe, obj); /* no -o */
    ES_CHECK(run(cmd) == 2);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o x.png --view 1,2 >/dev/null 2>&1", exe, obj);
    ES_CHECK(run(cmd) == 2);
    snprintf(cmd, sizeof cmd, "'%s' render '%s' -o '%s' --scalars '%s' 2>/dev/null", exe, obj,
             png, bad); /* 3 values fit nothing */
    ES_CHECK(run(cmd) == 1);
    snprintf(cmd, sizeof cmd, "'%s' render /nonexistent.obj -o '%s' 2>/dev/null", exe, png);
    ES_CHECK(run(cmd) == 1);
    tm_free(&s);
}


/* Fail the k-th allocation of a two-panel render with per-edge scalars for
 * k = 1, 2, ... until it succeeds: ES_ENOMEM each time, no leak (ASan). */
static void test_alloc_failures(es_ctx *ctx)
{
    tm_mesh sq = make_square();
    const int64_t edges[10] = {0, 1, 1, 2, 2, 0, 2, 3, 3, 0};
    const double ev[5] = {1, 2, 3, 4, NAN};
    es_render_mesh it[2] = {as_item(&sq, "a"), as_item(&sq, "b")};
    it[1].scalar_kind = ES_SCALARS_EDGE;
    it[1].scalars = ev;
    it[1].edges = edges;
    it[1].nedges = 5;
    es_render_spec spec;
    es_render_spec_init(&spec);
    spec.meshes = it;
    spec.nmeshes = 2;
    spec.width = spec.height = 64;
    const char *png = tp_path("render", "alloc.png");
    es_status rc = ES_ENOMEM;
    int k;
    for (k = 1; k < 40 && rc == ES_ENOMEM; k++) {
        failing_alloc fa = {0, k, 0};
        es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
        es_ctx_set_allocator(ctx, &a);
        rc = es_render(ctx, &spec, png, NULL);
        es_ctx_set_allocator(ctx, NULL);
        ES_CHECK(rc == ES_OK || rc == ES_ENOMEM);
    }
    ES_CHECK_MSG(rc == ES_OK && k > 5, "rc %d after %d tries", rc, k);
    tm_free(&sq);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    test_sphere_silhouette(ctx);
    test_square(ctx);
    test_overlap(ctx);
    test_scalars(ctx);
    test_auto_view(ctx);
    test_errors(ctx);
    test_alloc_failures(ctx);
    test_shared_faces(ctx);
    test_render_files(ctx);
    test_cli();
    es_ctx_free(ctx);
    ES_TEST_END();
}
