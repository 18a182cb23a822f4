/* notebooks-c/11_other_papers.c — The other three papers' main claims on
 * the project's data: Winkler et al.'s large rotations and extrapolation,
 * Wuhrer et al.'s exact morph of a triangulated polygon, Gao et al.'s path
 * that stays near the examples.
 *
 * Questions. (1) Winkler et al. 2010 (Figs. 1, 10; Sec. 3.5): does
 * multi-scale interpolation follow a rotation past 180 degrees, and does it
 * extrapolate to t = 2? (2) Wuhrer et al. 2010 (Theorem 1): on a
 * triangulated polygon (a mesh whose dual graph is a tree) is every frame
 * of the shape-space morph isometric to the inputs' interpolated lengths,
 * extrapolated ones too? (3) Gao et al. 2017 (Sec. 3.2, Figs. 8, 11): does
 * the data-driven path stay near the examples, where the straight line
 * between its ends leaves them?
 *
 * Datasets. (1) The project's elliptic tube bent by s x 180 degrees and
 * twisted by s x 270 degrees (es_synth "tube-twist"), members s = 0, 0.5,
 * 1, 1.5, 2: inputs s = 0 and 1, the other members the targets. (2) The
 * project's strip (es_synth "strip": y = a sin x, a = 1 -> -1; the paper's
 * Fig. 6 pair). (3) facecap_arkit's 67 frames of a recorded performance
 * (1,919 vertices; --small every other one), from its first to its last
 * frame; without ../shared/data the twisted tube's members s = 0 .. 1 (the
 * report says so).
 *
 * Method. (1) es_multiscale_interp (best of 4 hierarchies) at t = 0 .. 2,
 * against vertex interpolation and the project's embedding (es_interp_embed)
 * of the same weights, each aligned to the family's member at s = t and
 * measured by the RMS vertex distance over the bounding-box diagonal.
 * (2) es_shape_space_frame at t = -0.25 .. 1.25, the largest relative edge
 * error against (1 - t) l_A + t l_B. (3) Every frame in Gao et al.'s
 * coordinates (es_lri, base: the first frame), their principal components
 * (es_data_path_coords), es_data_path between the ends, drawn over the
 * first two components, and five frames of the path decoded and placed.
 *
 * Expected finding. (1) Multi-scale and the embedding land much nearer the
 * members than vertex interpolation, at t = 2 too; (2) errors at rounding
 * level (Theorem 1), vertex interpolation's far from it; (3) the path's
 * frames stay nearer the examples than the straight line's.
 */
#include "notebook.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double BLUE[3] = {0.38, 0.56, 0.86}, RED[3] = {0.86, 0.45, 0.40};

typedef struct study {
    /* (1) Winkler */
    double w_d[3][5];        /* multiscale, ours, vertex lerp: distance to member at t */
    double w_rms[3][5];      /* their RMS ratio against the interpolated lengths */
    /* (2) Wuhrer */
    double s_max[7], s_lin[7];
    /* (3) Gao */
    int gao_synthetic;
    int64_t g_n, g_hops;
    double g_max, g_line_max, g_mean, g_line_mean;
} study;

/* The rendered rows: nrow x ncol meshes of one topology, row colours. */
static int grid(notebook *nb, const es_mesh *m, const double *const *x, int nrow, int ncol,
                const char *const *labels, const double *const *rgb, const char *file,
                const char *title, const double *view)
{
    int64_t n = (int64_t)nrow * ncol;
    es_render_mesh *rm = calloc((size_t)n, sizeof *rm);
    es_render_spec rs;
    es_status rc;
    if (!rm) return nb_fail(nb, ES_ENOMEM, "render");
    for (int64_t i = 0; i < n; i++) {
        es_render_mesh_from(&rm[i], m, x[i]);
        rm[i].label = labels[i];
        rm[i].rgb = rgb[i / ncol];
    }
    es_render_spec_init(&rs);
    rs.nmeshes = n;
    rs.meshes = rm;
    rs.ncols = ncol;
    rs.width = 220;
    rs.height = 200;
    rs.same_view = 1;
    rs.title = title;
    if (view) {   /* view[0..2] the direction looked along, view[3..5] up */
        rs.has_view = rs.has_up = 1;
        memcpy(rs.view, view, sizeof rs.view);
        memcpy(rs.up, view + 3, sizeof rs.up);
    }
    rc = es_render(nb->ctx, &rs, nb_path(nb, "%s", file), NULL);
    free(rm);
    if (rc != ES_OK) return nb_fail(nb, rc, "render");
    nb_output(nb, file);
    return 0;
}

/* ---- 1. Winkler et al.: rotation and extrapolation --------------------------- */

static int winkler(notebook *nb, study *s)
{
    es_synth_opts so;
    es_synth_set set;
    es_mesh *m = NULL;
    es_multiscale *ms = NULL;
    es_embedder *emb = NULL;
    es_status rc;
    static char labels[15][40];
    const char *lab[15];
    const double *rows[15], *col[3] = {NULL, BLUE, RED};
    double *out = NULL;
    int64_t nv = 0, ne = 0;
    nb_step(nb, "Winkler et al.: the twisted tube, t = 0 .. 2");
    es_synth_opts_init(&so);
    so.n = 5;
    so.span = 2;   /* members at s = 0, 0.5, 1, 1.5, 2 */
    if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_TUBE_TWIST, &so, &set)) != ES_OK)
        return nb_fail(nb, rc, "twisted tube");
    nv = set.nverts;
    rc = es_mesh_new(nb->ctx, nv, set.nfaces, set.faces, NULL, &m);
    if (rc == ES_OK) ne = es_mesh_nedges(m);
    if (rc == ES_OK && !(out = malloc(sizeof(double) * (size_t)(3 * nv * 15 + ne)))) rc = ES_ENOMEM;
    if (rc == ES_OK) rc = es_multiscale_new(nb->ctx, m, NULL, &ms);
    if (rc == ES_OK) rc = es_embedder_new(nb->ctx, m, &emb);
    const double *in[2] = {set.xyz, set.xyz + 6 * nv};   /* s = 0 and s = 1 */
    for (int k = 0; rc == ES_OK && k < 5; k++) {
        double t = 0.5 * k, w[2] = {1 - t, t}, *len = out + 3 * nv * 15, p99, mx;
        const double *member = set.xyz + 3 * nv * k;
        double *o[3] = {out + 3 * nv * k, out + 3 * nv * (5 + k), out + 3 * nv * (10 + k)};
        es_embed_report r;
        if ((rc = es_interp_targets(nb->ctx, m, 2, in, w, len, NULL, NULL)) != ES_OK ||
            (rc = es_multiscale_interp(nb->ctx, ms, 2, in, w, member, o[0], NULL)) != ES_OK ||
            (rc = es_interp_embed(nb->ctx, emb, 2, in, w, k ? o[1] - 3 * nv : in[0], NULL, o[1],
                                  &r, NULL)) != ES_OK)
            break;
        for (int64_t i = 0; i < 3 * nv; i++) o[2][i] = (1 - t) * in[0][i] + t * in[1][i];
        for (int j = 0; j < 3 && rc == ES_OK; j++) {
            double fit;
            if ((rc = es_embed_length_error(nb->ctx, m, o[j], len, 0, &s->w_rms[j][k], &mx,
                                            &p99)) == ES_OK &&
                (rc = es_embed_align(nb->ctx, nv, o[j], member, NULL, &fit)) == ES_OK)
                s->w_d[j][k] = fit / es_bbox_diagonal(nv, member);
            snprintf(labels[5 * j + k], sizeof labels[0], "t = %.1f: %.1f %%", t,
                     100 * s->w_d[j][k]);
            lab[5 * j + k] = labels[5 * j + k];
            rows[5 * j + k] = o[j];
        }
        printf("%s:   t = %.1f: distance to the member, multiscale %.3g, ours %.3g, vertex lerp "
               "%.3g\n", nb->name, t, s->w_d[0][k], s->w_d[1][k], s->w_d[2][k]);
    }
    if (rc == ES_OK) {
        FILE *f = nb_csv_open(nb, "winkler.csv", "t,multiscale_distance,ours_distance,"
                                                "lerp_distance,multiscale_rms_ratio,"
                                                "ours_rms_ratio,lerp_rms_ratio");
        if (!f) rc = ES_EIO;
        for (int k = 0; f && k < 5; k++)
            fprintf(f, "%.2f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", 0.5 * k, s->w_d[0][k],
                    s->w_d[1][k], s->w_d[2][k], s->w_rms[0][k], s->w_rms[1][k], s->w_rms[2][k]);
        if (f && nb_csv_close(nb, f)) rc = ES_EIO;
    }
    if (rc == ES_OK) {
        static const double grey[3] = {0.80, 0.76, 0.70};
        col[0] = grey;
        nb_h(nb, 2, "Winkler et al.: a rotation past 180 degrees, extrapolated to t = 2");
        if (grid(nb, m, rows, 3, 5, lab, col, "winkler.png", "Inputs t = 0 and 1; multi-scale "
                 "(grey), the project's embedding (blue), vertex lerp (red)", NULL))
            rc = ES_EIO;
        else
            nb_image(nb, "winkler.png", "The elliptic tube bent 180 and twisted 270 degrees "
                     "(t = 1) from straight (t = 0), interpolated and extrapolated; labels: the "
                     "RMS distance to the family's member at s = t over its diagonal "
                     "(winkler.csv)");
    }
    es_multiscale_free(ms);
    es_embedder_free(emb);
    es_mesh_free(m);
    es_synth_set_clear(nb->ctx, &set);
    free(out);
    return rc == ES_OK ? 0 : (nb->failed ? 1 : nb_fail(nb, rc, "Winkler"));
}

/* ---- 2. Wuhrer et al.: the triangulated polygon ------------------------------- */

static int wuhrer(notebook *nb, study *s)
{
    es_synth_opts so;
    es_synth_set set;
    es_mesh *m = NULL;
    es_shape_space *ss = NULL;
    es_status rc;
    static char labels[14][40];
    const char *lab[14];
    const double *rows[14], *col[2] = {BLUE, RED};
    double *out = NULL, *la = NULL;
    int64_t nv, ne;
    nb_step(nb, "Wuhrer et al.: a triangulated polygon, t = -0.25 .. 1.25");
    es_synth_opts_init(&so);
    so.n = 2;
    if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_STRIP, &so, &set)) != ES_OK)
        return nb_fail(nb, rc, "strip");
    nv = set.nverts;
    rc = es_mesh_new(nb->ctx, nv, set.nfaces, set.faces, NULL, &m);
    ne = m ? es_mesh_nedges(m) : 0;
    out = malloc(sizeof(double) * (size_t)(3 * nv * 14));
    la = malloc(sizeof(double) * (size_t)(3 * ne));
    if (rc == ES_OK && (!out || !la)) rc = ES_ENOMEM;
    if (rc == ES_OK) rc = es_shape_space_new(nb->ctx, m, set.xyz, set.xyz + 3 * nv, NULL, &ss);
    if (rc == ES_OK) rc = es_edge_lengths(nb->ctx, m, set.xyz, la);
    if (rc == ES_OK) rc = es_edge_lengths(nb->ctx, m, set.xyz + 3 * nv, la + ne);
    for (int k = 0; rc == ES_OK && k < 7; k++) {
        double t = -0.25 + 0.25 * k, *lt = la + 2 * ne, rms, p99;
        double *o = out + 3 * nv * k, *lin = out + 3 * nv * (7 + k);
        for (int64_t e = 0; e < ne; e++) lt[e] = (1 - t) * la[e] + t * la[ne + e];
        if ((rc = es_shape_space_frame(nb->ctx, ss, lt, t, o)) != ES_OK) break;
        for (int64_t i = 0; i < 3 * nv; i++) lin[i] = (1 - t) * set.xyz[i] + t * set.xyz[3 * nv + i];
        if ((rc = es_embed_length_error(nb->ctx, m, o, lt, 0, &rms, &s->s_max[k], &p99)) != ES_OK ||
            (rc = es_embed_length_error(nb->ctx, m, lin, lt, 0, &rms, &s->s_lin[k], &p99)) != ES_OK)
            break;
        snprintf(labels[k], sizeof labels[0], "t = %.2f: %.1e", t, s->s_max[k]);
        snprintf(labels[7 + k], sizeof labels[0], "t = %.2f: %.0f %%", t, 100 * s->s_lin[k]);
        lab[k] = labels[k], lab[7 + k] = labels[7 + k];
        rows[k] = o, rows[7 + k] = lin;
    }
    if (rc == ES_OK) {
        FILE *f = nb_csv_open(nb, "wuhrer.csv", "t,shape_space_max_rel,vertex_lerp_max_rel");
        if (!f) rc = ES_EIO;
        for (int k = 0; f && k < 7; k++)
            fprintf(f, "%.2f,%.6g,%.6g\n", -0.25 + 0.25 * k, s->s_max[k], s->s_lin[k]);
        if (f && nb_csv_close(nb, f)) rc = ES_EIO;
    }
    if (rc == ES_OK) {
        nb_h(nb, 2, "Wuhrer et al.: exact on a triangulated polygon (Theorem 1)");
        static const double along_z[6] = {0, -0.4, -1, 0, 1, 0};   /* the curve, a little from above */
        if (grid(nb, m, rows, 2, 7, lab, col, "wuhrer.png", "The strip y = a sin x, a = 1 (t = 0) "
                 "-> -1 (t = 1): shape space (blue), vertex lerp (red)", along_z))
            rc = ES_EIO;
        else
            nb_image(nb, "wuhrer.png", "Labels: the largest relative edge error against the "
                     "interpolated lengths (wuhrer.csv)");
    }
    es_shape_space_free(ss);
    es_mesh_free(m);
    es_synth_set_clear(nb->ctx, &set);
    free(out);
    free(la);
    return rc == ES_OK ? 0 : (nb->failed ? 1 : nb_fail(nb, rc, "Wuhrer"));
}

/* ---- 3. Gao et al.: the path near the examples ------------------------------- */

/* The examples: facecap's performance, else the twisted tube's members. */
static int gao_examples(notebook *nb, study *s, es_mesh **m, double ***x)
{
    const char *dir = nb_dataset(nb, "facecap_arkit");
    char d[4400];
    if (dir) {
        int step = nb->small ? 10 : 5;
        snprintf(d, sizeof d, "%s", dir);
        s->g_n = 330 / step + 1;
        if (!(*x = calloc((size_t)s->g_n, sizeof **x))) return nb_fail(nb, ES_ENOMEM, "examples");
        for (int64_t i = 0; i < s->g_n; i++) {
            char file[32];
            snprintf(file, sizeof file, "anim_%03lld.obj", (long long)(i * step));
            if (nb_read_mesh(nb, d, file, m, &(*x)[i])) return 1;
        }
        return 0;
    }
    {
        es_synth_opts so;
        es_synth_set set;
        es_status rc;
        es_synth_opts_init(&so);
        so.n = s->g_n = nb->small ? 7 : 13;
        s->gao_synthetic = 1;
        if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_TUBE_TWIST, &so, &set)) != ES_OK)
            return nb_fail(nb, rc, "examples");
        rc = es_mesh_new(nb->ctx, set.nverts, set.nfaces, set.faces, NULL, m);
        if (rc == ES_OK && !(*x = calloc((size_t)s->g_n, sizeof **x))) rc = ES_ENOMEM;
        for (int64_t i = 0; rc == ES_OK && i < s->g_n; i++) {
            size_t b = sizeof(double) * (size_t)(3 * set.nverts);
            if (!((*x)[i] = malloc(b))) rc = ES_ENOMEM;
            else memcpy((*x)[i], set.xyz + 3 * set.nverts * i, b);
        }
        es_synth_set_clear(nb->ctx, &set);
        return rc == ES_OK ? 0 : nb_fail(nb, rc, "examples");
    }
}

static int gao(notebook *nb, study *s)
{
    es_mesh *m = NULL;
    double **x = NULL, *feat = NULL, *coords = NULL, *frames = NULL, *line = NULL, *y = NULL;
    es_lri *lri = NULL;
    es_data_path_info info;
    int64_t n, dim = 0, nc = 0, nf = 41, nv;
    es_status rc = ES_OK;
    nb_step(nb, "Gao et al.: a path through the examples");
    if (gao_examples(nb, s, &m, &x)) goto done;
    n = s->g_n;
    nv = es_mesh_nverts(m);
    if ((rc = es_lri_new(nb->ctx, m, x[0], NULL, &lri)) != ES_OK) goto done;
    dim = es_lri_dim(lri);
    feat = malloc(sizeof(double) * (size_t)(dim * (n + 1)));
    coords = malloc(sizeof(double) * (size_t)(n * n));
    frames = malloc(sizeof(double) * (size_t)(n * nf));
    line = malloc(sizeof(double) * (size_t)(2 * n));
    y = malloc(sizeof(double) * (size_t)(3 * nv * 6));
    if (!feat || !coords || !frames || !line || !y) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; rc == ES_OK && i < n; i++) rc = es_lri_encode(nb->ctx, lri, x[i], feat + dim * i);
    if (rc == ES_OK) rc = es_data_path_coords(nb->ctx, dim, n, feat, dim, coords, &nc);
    if (rc == ES_OK && nc < 2) {
        fprintf(stderr, "%s: the examples span fewer than two components\n", nb->name);
        rc = ES_EINVAL;
    }
    if (rc == ES_OK) rc = es_data_path(nb->ctx, nc, n, coords, n, 0, n - 1, NULL, nf, frames,
                                       NULL, &info);
    if (rc != ES_OK) goto done;
    s->g_hops = info.hops;
    s->g_max = info.max_near, s->g_line_max = info.line_max_near;
    s->g_mean = info.mean_near, s->g_line_mean = info.line_mean_near;
    printf("%s:   %lld examples, %lld coordinates each; path by %lld examples; nearest example "
           "along the path at most %.3g (mean %.3g), along the straight line %.3g (%.3g)\n",
           nb->name, (long long)n, (long long)dim, (long long)info.hops, info.max_near,
           info.mean_near, info.line_max_near, info.line_mean_near);
    /* the plot: examples, path and line on the first two components */
    {
        double *ex = malloc(sizeof(double) * (size_t)(2 * n)), *px = malloc(sizeof(double) * (size_t)(2 * nf));
        es_series ser[3];
        static const int dots[3] = {1, 0, 0};
        es_lines_spec ls;
        FILE *f = nb_csv_open(nb, "gao_path.csv", "kind,index,pc1,pc2");
        if (!ex || !px || !f) rc = ES_ENOMEM;
        for (int64_t i = 0; rc == ES_OK && i < n; i++) {
            ex[i] = coords[i * n], ex[n + i] = coords[i * n + 1];
            fprintf(f, "example,%lld,%.9g,%.9g\n", (long long)i, ex[i], ex[n + i]);
        }
        for (int64_t i = 0; rc == ES_OK && i < nf; i++) {
            px[i] = frames[i * nc], px[nf + i] = frames[i * nc + 1];
            fprintf(f, "path,%lld,%.9g,%.9g\n", (long long)i, px[i], px[nf + i]);
        }
        line[0] = ex[0], line[1] = ex[n - 1], line[2] = ex[n], line[3] = ex[2 * n - 1];
        if (f && nb_csv_close(nb, f)) rc = ES_EIO;
        ser[0] = (es_series){"examples", n, ex, ex + n};
        ser[1] = (es_series){"data-driven path", nf, px, px + nf};
        ser[2] = (es_series){"straight line", 2, line, line + 2};
        es_lines_spec_init(&ls);
        ls.frame.title = "The path over the examples' first two principal components";
        ls.frame.xlabel = "PC 1 (Gao et al.'s coordinates)";
        ls.frame.ylabel = "PC 2";
        ls.frame.width = 760;
        ls.nseries = 3;
        ls.series = ser;
        ls.points_only = dots;
        if (rc == ES_OK) rc = es_plot_lines(nb->ctx, &ls, nb_path(nb, "gao_path.png"), NULL);
        free(ex);
        free(px);
        if (rc != ES_OK) goto done;
        nb_output(nb, "gao_path.png");
    }
    /* five frames along the path decoded, placed between the ends */
    {
        double *fx = feat + dim * n, *wts = malloc(sizeof(double) * (size_t)(n * nf));
        static char labels[6][32];
        const char *lab[6];
        const double *rows[6], *col[1] = {NULL};
        static const double grey[3] = {0.80, 0.76, 0.70};
        col[0] = grey;
        if (!wts) {
            rc = ES_ENOMEM;
            goto done;
        }
        rc = es_data_path(nb->ctx, nc, n, coords, n, 0, n - 1, NULL, nf, frames, wts, NULL);
        for (int j = 0; rc == ES_OK && j < 5; j++) {
            int64_t fi = j * (nf - 1) / 4;
            for (int64_t k = 0; k < dim; k++) fx[k] = 0;
            for (int64_t r = 0; r < n; r++)
                for (int64_t k = 0; wts[fi * n + r] != 0 && k < dim; k++)
                    fx[k] += wts[fi * n + r] * feat[dim * r + k];
            if ((rc = es_lri_decode(nb->ctx, lri, fx, y + 3 * nv * 5)) == ES_OK)
                rc = es_lri_place(nb->ctx, nv, y + 3 * nv * 5, x[0], x[n - 1],
                                  (double)j / 4, y + 3 * nv * j);
            snprintf(labels[j], sizeof labels[j], "s = %.2f", (double)j / 4);
            lab[j] = labels[j];
            rows[j] = y + 3 * nv * j;
        }
        free(wts);
        if (rc != ES_OK) goto done;
        nb_h(nb, 2, "Gao et al.: the path stays near the examples");
        nb_image(nb, "gao_path.png", "%lld examples (%s) in Gao et al.'s rotation-invariant "
                 "coordinates, their first two principal components; the data-driven path from "
                 "the first to the last and the straight line between them (gao_path.csv)",
                 (long long)n, s->gao_synthetic ? "the twisted tube's members"
                                                : "facecap's recorded performance");
        /* facecap faces +y, its chin toward +z: seen from the front */
        static const double front[6] = {0, -1, 0, 0, 0, -1};
        if (grid(nb, m, rows, 1, 5, lab, col, "gao_frames.png", "Frames along the data-driven "
                 "path, decoded from the coordinates", s->gao_synthetic ? NULL : front))
            goto done;
        nb_image(nb, "gao_frames.png", "Five frames evenly along the path");
        nb_p(nb, "The path passes %lld examples; a frame is at most %.3g (mean %.3g) neighbour "
             "distances from its nearest example, against %.3g (%.3g) along the straight line.",
             (long long)s->g_hops, s->g_max, s->g_mean, s->g_line_max, s->g_line_mean);
    }
done:
    es_lri_free(lri);
    for (int64_t i = 0; x && i < s->g_n; i++) free(x[i]);
    free(x);
    free(feat);
    free(coords);
    free(frames);
    free(line);
    free(y);
    es_mesh_free(m);
    if (rc != ES_OK && !nb->failed) return nb_fail(nb, rc, "Gao");
    return nb->failed;
}

int main(int argc, char **argv)
{
    notebook nb;
    study s;
    int rc = nb_open(&nb, "11_other_papers", "The other papers' main claims on our data", argc,
                     argv);
    if (rc) return rc;
    memset(&s, 0, sizeof s);
    nb_p(&nb, "**Questions.** Winkler et al.: large rotations and extrapolation; Wuhrer et al.: "
         "exactness on a triangulated polygon; Gao et al.: a path that stays near the examples.");
    if (!winkler(&nb, &s) && !wuhrer(&nb, &s) && !gao(&nb, &s)) {
        double worst = 0;
        for (int k = 0; k < 7; k++) worst = fmax(worst, s.s_max[k]);
        nb_step(&nb, "self-check");
        nb_check(&nb, "Winkler: multi-scale at t = 2, distance to the member / vertex lerp's",
                 s.w_d[0][4] / s.w_d[2][4], "<", 0.5);
        nb_check(&nb, "Winkler: multi-scale at t = 0.5, distance to the member / vertex lerp's",
                 s.w_d[0][1] / s.w_d[2][1], "<", 0.6);
        nb_check(&nb, "Wuhrer: worst relative edge error of a frame (Theorem 1)", worst, "<",
                 1e-12);
        nb_check(&nb, "Wuhrer: vertex lerp's worst edge at t = 0.5", s.s_lin[3], ">", 0.05);
        nb_check(&nb, "Gao: the path's farthest frame from an example / the straight line's",
                 s.g_max / s.g_line_max, "<", 1);
    }
    return nb_close(&nb);
}
