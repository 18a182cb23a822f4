/* notebooks-c/03_poses.c — Poses: interpolating between two poses in
 * edge-length space (the paper's Figs. 4 and 12).
 *
 * Question. Linear interpolation of vertex positions between two poses
 * shrinks and shears the parts that rotate. Interpolating the edge lengths
 * instead and embedding each intermediate vector should keep the parts
 * rigid. How close do the embedded frames come to their interpolated
 * lengths along the way (the Fig. 12 curves), and how does that compare
 * with plain vertex interpolation?
 *
 * Dataset. sumner_cat_poses (../shared/data/sumner_cat_poses; 7,207
 * vertices, closed, genus 0): the animal poses cat-01 and cat-02 (the pair
 * the embedding issue measures). If that set is absent but goast_cactus is
 * there: the original cactus and, among the first poses, the one farthest
 * from it in edge-length space. Without ../shared/data: the
 * project's closed bent tube (es_synth "tube-closed"), straight to bent by
 * 180 degrees.
 *
 * Method. l(t): the weighted mean of the two poses' scaled lengths at the
 * weighted mean scale (es_interp_targets; the poses share a scale, so this
 * is (1 - t) l_A + t l_B); each frame embedded by es_interp_embed from the
 * interpolated dihedral angles of the two poses (the paper's
 * initialization, along the shortest arc), aligned to the previous frame. Along t: RMS(l_out - l(t)) / mean l(t) and the largest
 * relative edge error, for the embedded frames and for the vertex
 * interpolation (1 - t) x_A + t x_B (B rigidly aligned to A first).
 *
 * Expected finding. The embedded frames follow l(t) closely (the paper,
 * Fig. 12: RMS ratio about 0.75%, worst edge 15% on the arm); vertex
 * interpolation is
 * exact at the ends but loses length in the middle where parts rotate.
 */
#include "notebook.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct study {
    int64_t V, F, E;
    es_mesh *mesh;
    double *xa, *xb;          /* 3V: the two poses (B rigidly aligned to A) */
    char id_a[128], id_b[128];
    int up_axis;              /* stored up axis: 1 = +y (the cat), 2 = +z (the cactus), 0 = auto */
    int64_t nt;               /* frames, including both ends */
    double *t;                /* nt */
    double *frames;           /* 3V x nt embedded frames */
    double *rms_emb, *max_emb, *rms_lin, *max_lin;   /* nt each */
    double secs;
    int64_t n_wrapped;        /* edges whose dihedral crosses +-pi between the poses */
} study;

/* ---- 1. data ------------------------------------------------------------------ */

static int read_pose(notebook *nb, const char *path, study *s, double **xyz)
{
    es_meshdata md;
    es_status rc = es_meshdata_read(nb->ctx, path, ES_FORMAT_AUTO, &md);
    if (rc != ES_OK) return nb_fail(nb, rc, "reading a pose");
    if (!s->mesh) {
        s->V = md.nverts;
        s->F = md.nfaces;
        rc = es_mesh_new(nb->ctx, s->V, s->F, md.faces, md.xyz, &s->mesh);
    } else if (md.nverts != s->V) {
        rc = ES_EMISMATCH;
    }
    if (rc == ES_OK && !(*xyz = malloc(sizeof(double) * (size_t)(3 * s->V)))) rc = ES_ENOMEM;
    if (rc == ES_OK) memcpy(*xyz, md.xyz, sizeof(double) * (size_t)(3 * s->V));
    es_meshdata_clear(nb->ctx, &md);
    return rc == ES_OK ? 0 : nb_fail(nb, rc, path);
}

static int load(notebook *nb, study *s)
{
    const char *dir;
    es_status rc;
    nb_step(nb, "load: two poses");
    const char *dataset = "sumner_cat_poses";
    dir = nb_dataset(nb, dataset);
    if (!dir) dir = nb_dataset(nb, dataset = "goast_cactus");
    if (dir) {
        /* the cat: its first two poses; the cactus: the farthest of its
         * first eight from the original */
        int is_cat = strcmp(dataset, "sumner_cat_poses") == 0;
        char path[4352];
        es_manifest *m = NULL;
        int64_t nmax, best = -1;
        double bestd = -1, *la = NULL, *lb = NULL, sa, sb;
        snprintf(path, sizeof path, "%s/metadata.csv", dir);
        if ((rc = es_manifest_read(nb->ctx, path, &m)) != ES_OK)
            return nb_fail(nb, rc, path);
        nmax = m->nrows < 8 ? m->nrows : 8;
        if (is_cat && nmax > 2) nmax = 2;
        snprintf(path, sizeof path, "%s/%s", m->dir, m->cells[m->file_col]);
        if (read_pose(nb, path, s, &s->xa)) goto fail;
        s->E = es_mesh_nedges(s->mesh);
        la = malloc(sizeof(double) * (size_t)s->E);
        lb = malloc(sizeof(double) * (size_t)s->E);
        if (!la || !lb) goto fail;
        es_edge_lengths(nb->ctx, s->mesh, s->xa, la);
        es_lengths_normalize(nb->ctx, s->E, la, la, &sa);
        /* B: the pose farthest from A in scaled edge-length distance */
        for (int64_t i = 1; i < nmax; i++) {
            double *x = NULL, d = 0;
            snprintf(path, sizeof path, "%s/%s", m->dir, m->cells[i * m->ncols + m->file_col]);
            if (read_pose(nb, path, s, &x)) goto fail;
            es_edge_lengths(nb->ctx, s->mesh, x, lb);
            es_lengths_normalize(nb->ctx, s->E, lb, lb, &sb);
            for (int64_t e = 0; e < s->E; e++) d += (la[e] - lb[e]) * (la[e] - lb[e]);
            if (d > bestd) {
                bestd = d;
                best = i;
                free(s->xb);
                s->xb = x;
            } else {
                free(x);
            }
        }
        snprintf(s->id_a, sizeof s->id_a, "%s", m->ids[0]);
        snprintf(s->id_b, sizeof s->id_b, "%s", m->ids[best]);
        if (is_cat)
            nb_p(nb, "**Data:** `sumner_cat_poses` from `%s` (Sumner & Popovic): A = `%s`, "
                 "B = `%s`; scaled edge-length distance %.3g.", dir, s->id_a, s->id_b,
                 sqrt(bestd));
        else
            nb_p(nb, "**Data:** `goast_cactus` from `%s`: A = `%s` (the original), B = `%s`, "
                 "the farthest of the first %lld poses from A in scaled edge-length distance "
                 "(%.3g).", dir, s->id_a, s->id_b, (long long)nmax, sqrt(bestd));
        nb_input(nb, "dataset", "%s", dataset);
        s->up_axis = is_cat ? 1 : 2;
        free(la);
        free(lb);
        es_manifest_free(nb->ctx, m);
        return 0;
    fail:
        free(la);
        free(lb);
        es_manifest_free(nb->ctx, m);
        return nb->failed ? 1 : nb_fail(nb, ES_ENOMEM, "poses");
    } else {
        es_synth_opts so;
        es_synth_set set;
        es_synth_opts_init(&so);
        so.n = 2;
        if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_TUBE_CLOSED, &so, &set)) != ES_OK)
            return nb_fail(nb, rc, "synthetic tubes");
        s->V = set.nverts;
        s->F = set.nfaces;
        rc = es_mesh_new(nb->ctx, s->V, s->F, set.faces, set.xyz, &s->mesh);
        s->xa = malloc(sizeof(double) * (size_t)(3 * s->V));
        s->xb = malloc(sizeof(double) * (size_t)(3 * s->V));
        if (rc == ES_OK && (!s->xa || !s->xb)) rc = ES_ENOMEM;
        if (rc == ES_OK) {
            memcpy(s->xa, set.xyz, sizeof(double) * (size_t)(3 * s->V));
            memcpy(s->xb, set.xyz + 3 * s->V, sizeof(double) * (size_t)(3 * s->V));
            snprintf(s->id_a, sizeof s->id_a, "%s", set.names[0]);
            snprintf(s->id_b, sizeof s->id_b, "%s", set.names[1]);
        }
        es_synth_set_clear(nb->ctx, &set);
        if (rc != ES_OK) return nb_fail(nb, rc, "synthetic tubes");
        s->E = es_mesh_nedges(s->mesh);
        nb_input(nb, "dataset", "es_synth tube-closed, 0 and 180 degrees");
        nb_p(nb, "> **Data: synthetic.** Neither `sumner_cat_poses` nor `goast_cactus` was "
             "found under the data folder (or `--synthetic` was given), so the two poses are "
             "the project's closed bent tube (`es_synth` \"tube-closed\"), straight (A) and "
             "bent by 180 degrees (B).");
    }
    return 0;
}

/* ---- 2. interpolation ------------------------------------------------------------ */

static int interpolate(notebook *nb, study *s)
{
    const int64_t E = s->E, V3 = 3 * s->V;
    const double *in[2] = {s->xa, s->xb};
    double *lt = malloc(sizeof(double) * (size_t)E);
    double *lin = malloc(sizeof(double) * (size_t)V3), rms, p99;
    es_embedder *emb = NULL;
    es_interp_info info;
    es_status rc = ES_ENOMEM;
    int64_t wrapped = 0;
    double t0 = nb_now();

    nb_step(nb, "interpolate: lengths along t, each frame embedded");
    s->nt = nb->small ? 3 : 11;
    s->t = malloc(sizeof(double) * (size_t)s->nt);
    s->frames = malloc(sizeof(double) * (size_t)(V3 * s->nt));
    s->rms_emb = malloc(sizeof(double) * (size_t)(4 * s->nt));
    if (!lt || !lin || !s->t || !s->frames || !s->rms_emb) goto done;
    s->max_emb = s->rms_emb + s->nt;
    s->rms_lin = s->rms_emb + 2 * s->nt;
    s->max_lin = s->rms_emb + 3 * s->nt;
    if ((rc = es_embed_align(nb->ctx, s->V, s->xb, s->xa, NULL, &rms)) != ES_OK ||
        (rc = es_embedder_new(nb->ctx, s->mesh, &emb)) != ES_OK)
        goto done;
    for (int64_t k = 0; k < s->nt; k++) {
        double t = (double)k / (double)(s->nt - 1), w[2] = {1 - t, t};
        es_embed_report r;
        s->t[k] = t;
        /* the target l(t), for the vertex-interpolation baseline */
        if ((rc = es_interp_targets(nb->ctx, s->mesh, 2, in, w, lt, NULL, &info)) != ES_OK)
            goto done;
        for (int64_t i = 0; i < V3; i++) lin[i] = (1 - t) * s->xa[i] + t * s->xb[i];
        if ((rc = es_embed_length_error(nb->ctx, s->mesh, lin, lt, 0, &s->rms_lin[k],
                                        &s->max_lin[k], &p99)) != ES_OK)
            goto done;
        /* the frame: embedded from the (shortest-arc) interpolated dihedrals,
         * aligned to the previous frame */
        rc = es_interp_embed(nb->ctx, emb, 2, in, w, k ? s->frames + V3 * (k - 1) : s->xa, NULL,
                             s->frames + V3 * k, &r, &info);
        if (rc != ES_OK) goto done;
        if (info.n_wrapped > wrapped) wrapped = info.n_wrapped;
        s->rms_emb[k] = r.rms_ratio;
        s->max_emb[k] = r.max_rel;
        printf("%s:   t = %.2f: embedded rms %.3g max %.3g; vertex lerp rms %.3g max %.3g "
               "(%.1f s)\n", nb->name, t, r.rms_ratio, r.max_rel, s->rms_lin[k], s->max_lin[k],
               r.t_total);
        fflush(stdout);
        if ((rc = es_meshio_write(nb->ctx, nb_path(nb, "frame_%02lld.obj", (long long)k),
                                  ES_FORMAT_OBJ, s->mesh, s->frames + V3 * k, NULL)) != ES_OK)
            goto done;
        nb_output(nb, nb_path(nb, "frame_%02lld.obj", (long long)k) + strlen(nb->outdir) + 1);
    }
    s->secs = nb_now() - t0;
    s->n_wrapped = wrapped;
    rc = ES_OK;
done:
    es_embedder_free(emb);
    free(lt);
    free(lin);
    if (rc != ES_OK) return nb_fail(nb, rc, "interpolation");
    return 0;
}

/* ---- 3. report ------------------------------------------------------------------- */

static int report(notebook *nb, study *s)
{
    es_series ser[2];
    es_lines_spec ls;
    es_render_mesh rm[11];
    es_render_spec rs;
    es_status rc;
    FILE *f;
    int64_t kmax = 0, kmax_lin = 0, nshow = 0;

    nb_step(nb, "report: error curves and frames");
    nb_h(nb, 2, "Interpolation from %s to %s", s->id_a, s->id_b);
    nb_p(nb, "%lld vertices, %lld edges; %lld frames at t = 0, %.3g, ..., 1, embedded in "
         "%.1f s in all (%lld edges' dihedrals cross +-pi between the poses and are "
         "interpolated along the shortest arc).", (long long)s->V, (long long)s->E,
         (long long)s->nt, s->t[1], s->secs, (long long)s->n_wrapped);
    if (!(f = nb_csv_open(nb, "errors.csv", "t,embedded_rms_ratio,embedded_max_rel,"
                                            "vertex_lerp_rms_ratio,vertex_lerp_max_rel")))
        return 1;
    nb_table(nb, "t|embedded: RMS ratio|embedded: max rel|vertex lerp: RMS ratio|"
                 "vertex lerp: max rel");
    for (int64_t k = 0; k < s->nt; k++) {
        fprintf(f, "%.6g,%.6g,%.6g,%.6g,%.6g\n", s->t[k], s->rms_emb[k], s->max_emb[k],
                s->rms_lin[k], s->max_lin[k]);
        nb_row(nb, "%.2f|%.2e|%.2e|%.2e|%.2e", s->t[k], s->rms_emb[k], s->max_emb[k],
               s->rms_lin[k], s->max_lin[k]);
        if (s->max_emb[k] > s->max_emb[kmax]) kmax = k;
        if (s->max_lin[k] > s->max_lin[kmax_lin]) kmax_lin = k;
    }
    if (nb_csv_close(nb, f)) return 1;

    for (int panel = 0; panel < 2; panel++) {
        const char *file = panel ? "max_rel.png" : "rms_ratio.png";
        es_lines_spec_init(&ls);
        /* interior frames only: the ends are the inputs themselves (errors at
         * rounding level, which would only stretch the log axis) */
        ser[0] = (es_series){"edge lengths, embedded", s->nt - 2, s->t + 1,
                             (panel ? s->max_emb : s->rms_emb) + 1};
        ser[1] = (es_series){"vertex lerp", s->nt - 2, s->t + 1,
                             (panel ? s->max_lin : s->rms_lin) + 1};
        ls.frame.title = panel ? "Largest relative edge error along t (Fig. 12, right)"
                               : "RMS edge error / mean length along t (Fig. 12, left)";
        ls.frame.xlabel = "t";
        ls.frame.width = 720;   /* room for the legend beside the curves */
        ls.frame.ylabel = panel ? "max |l - l(t)| / l(t)" : "RMS(l - l(t)) / mean l(t)";
        ls.nseries = 2;
        ls.series = ser;
        ls.logy = 1;
        ls.markers = 1;
        if ((rc = es_plot_lines(nb->ctx, &ls, nb_path(nb, "%s", file), NULL)) != ES_OK)
            return nb_fail(nb, rc, "line plot");
    }
    nb_image(nb, "rms_ratio.png", "RMS edge-length error relative to the mean interpolated "
             "length, along t, interior frames: the embedded edge-length interpolation against "
             "vertex interpolation (log scale; data: errors.csv, which has the ends too)");
    nb_image(nb, "max_rel.png", "Largest relative edge-length error along t");
    nb_p(nb, "The embedded frames' worst edge is %.2f%% off its interpolated length (at "
         "t = %.2f); vertex interpolation's worst edge is %.1f%% off (at t = %.2f).",
         100 * s->max_emb[kmax], s->t[kmax], 100 * s->max_lin[kmax_lin], s->t[kmax_lin]);

    for (int64_t k = 0; k < s->nt && nshow < 11; k += (s->nt > 6 ? 2 : 1)) {
        static char labels[11][32];
        snprintf(labels[nshow], sizeof labels[0], "t = %.2f", s->t[k]);
        memset(&rm[nshow], 0, sizeof rm[nshow]);
        rm[nshow].nverts = s->V;
        rm[nshow].nfaces = s->F;
        rm[nshow].xyz = s->frames + 3 * s->V * k;
        rm[nshow].faces = es_mesh_faces(s->mesh);
        rm[nshow].label = labels[nshow];
        nshow++;
    }
    es_render_spec_init(&rs);
    rs.nmeshes = nshow;
    rs.meshes = rm;
    rs.width = 260;
    rs.height = 320;
    /* one camera for all frames: the automatic view of the last (most bent)
     * frame, whose principal axes are well defined (a straight tube's are
     * not); the cat is stored y-up, the cactus z-up */
    if ((rc = es_render_auto_view(nb->ctx, s->V, s->frames + 3 * s->V * (s->nt - 1), s->F,
                                  es_mesh_faces(s->mesh), rs.view, rs.up)) != ES_OK)
        return nb_fail(nb, rc, "camera");
    rs.has_view = rs.has_up = 1;
    if (s->up_axis) {
        rs.up[0] = rs.up[1] = rs.up[2] = 0;
        rs.up[s->up_axis] = 1;
    }
    rs.title = "Embedded frames of the edge-length interpolation";
    if ((rc = es_render(nb->ctx, &rs, nb_path(nb, "frames.png"), NULL)) != ES_OK)
        return nb_fail(nb, rc, "render");
    nb_image(nb, "frames.png", "Embedded frames (meshes: frame_NN.obj)");
    return 0;
}

int main(int argc, char **argv)
{
    notebook nb;
    study s;
    int rc = nb_open(&nb, "03_poses", "Poses: edge-length interpolation between two poses",
                     argc, argv);
    if (rc) return rc;
    memset(&s, 0, sizeof s);
    nb_p(&nb, "**Question.** Interpolating edge lengths between two poses and embedding each "
         "frame should keep the parts rigid. How close do the frames come to their "
         "interpolated lengths along t (Fig. 12), compared with vertex interpolation?");
    nb_p(&nb, "**Expected.** The embedded frames stay within the paper's Fig. 12 levels "
         "(RMS ratio below 0.75%%, worst edge below 15%%); vertex interpolation is exact at "
         "the ends but loses length in the middle, where parts rotate.");
    if (!load(&nb, &s) && !interpolate(&nb, &s) && !report(&nb, &s)) {
        double worst_rms = 0, worst_max = 0, lin_mid = s.max_lin[s.nt / 2];
        for (int64_t k = 0; k < s.nt; k++) {
            if (s.rms_emb[k] > worst_rms) worst_rms = s.rms_emb[k];
            if (s.max_emb[k] > worst_max) worst_max = s.max_emb[k];
        }
        nb_step(&nb, "self-check");
        /* The paper's Fig. 12 bounds for its own method (arm): RMS ratio
         * peaks at 0.75%, the worst edge at 15%. */
        nb_check(&nb, "worst RMS ratio along t", worst_rms, "<", 7.5e-3);
        nb_check(&nb, "worst max relative edge error along t", worst_max, "<", 0.15);
        nb_check(&nb, "vertex lerp worst edge at t = 0.5 / embedded worst edge", lin_mid / worst_max,
                 ">", 1);
    }
    es_mesh_free(s.mesh);
    free(s.xa);
    free(s.xb);
    free(s.t);
    free(s.frames);
    free(s.rms_emb);
    return nb_close(&nb);
}
