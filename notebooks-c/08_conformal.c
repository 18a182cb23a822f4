/* notebooks-c/08_conformal.c — The conformal morph of the core paper's
 * Section 5 (Fig. 11): a face mapped to the sphere.
 *
 * Question. Discrete conformal factors u (one per vertex; edge ab scaled by
 * e^((u_a + u_b) / 2)) take a closed genus-0 mesh to a mesh on the sphere.
 * Scaling them by k = 0, 1/4, 1/2, 3/4, 1 and embedding the lengths gives a
 * morph from the face to the sphere. Does the last frame land on the
 * sphere, and do the frames in between realize their lengths?
 *
 * Dataset. face-study s001_neutral (9,409 vertices; eye, mouth and neck
 * holes), closed off as the paper closes its face: a cone over each hole
 * (es_conformal_close). Without ../shared/data: the synthetic face family,
 * and the report says so. --small refines each frame less (30 iterations).
 *
 * Method. es_conformal_sphere (CETM's Newton flattening with one vertex at
 * infinity, inverse stereographic projection, Moebius centring, the factors
 * read back from the sphere's chordal lengths; lib/morph/conformal.c); each
 * frame by es_conformal_frame: the lengths under k u, embedded from the
 * dihedrals of the face and the sphere interpolated (the paper: "as
 * usual"), started from the previous frame, 60 refinement iterations.
 *
 * Expected finding. The k = 1 frame is the sphere (every vertex within 1 %
 * of the radius from the fitted centre); the middle frames realize their
 * lengths less well (the paper reports jitter near the end of its morph,
 * where regions turn from convex to concave).
 */
#include "notebook.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { NK = 5 };

typedef struct study {
    const char *what;
    int synthetic;
    es_mesh *open, *closed;
    double *xyz;             /* 3V' of the closed mesh */
    double *u, *sphere;      /* V', 3V' */
    es_conformal_info info;
    double k[NK];
    double *frames;          /* 3V' x NK */
    es_embed_report rep[NK];
    double off_sphere;       /* worst |distance to the fitted centre / radius - 1| at k = 1 */
} study;

/* ---- 1. data ------------------------------------------------------------------ */

static int load(notebook *nb, study *s)
{
    const char *set = "face-study", *dir = nb_dataset(nb, set);
    double *x = NULL;
    es_status rc;
    nb_step(nb, "load: a face, closed off");
    if (dir) {
        if (nb_read_mesh(nb, dir, "s001_neutral.obj", &s->open, &x)) return 1;
        s->what = "face-study s001_neutral";
    } else {
        es_synth_opts so;
        es_synth_set st;
        es_synth_opts_init(&so);
        so.n = 1;
        if ((rc = es_synth_generate(nb->ctx, ES_SYNTH_FACE, &so, &st)) != ES_OK)
            return nb_fail(nb, rc, "synthetic face");
        rc = es_mesh_new(nb->ctx, st.nverts, st.nfaces, st.faces, st.xyz, &s->open);
        es_synth_set_clear(nb->ctx, &st);
        if (rc != ES_OK) return nb_fail(nb, rc, "synthetic face");
        s->what = "a synthetic face (es_synth \"face\")";
        s->synthetic = 1;
        nb_p(nb, "> **Data: synthetic.** `%s` was not found under the data folder (or "
             "`--synthetic` was given): the face is the project's synthetic face.", set);
    }
    rc = es_conformal_close(nb->ctx, s->open, x, &s->closed);
    free(x);
    if (rc != ES_OK) return nb_fail(nb, rc, "closing the holes");
    {
        int64_t nv = es_mesh_nverts(s->closed);
        const int64_t *lo, *lv;
        int64_t holes = es_mesh_boundary_loops(s->open, &lo, &lv);
        if (!(s->xyz = malloc(sizeof(double) * (size_t)(3 * nv))))
            return nb_fail(nb, ES_ENOMEM, "positions");
        memcpy(s->xyz, es_mesh_xyz(s->closed), sizeof(double) * (size_t)(3 * nv));
        nb_p(nb, "**Data:** %s: %lld vertices, %lld holes closed by a cone each (%lld vertices, "
             "%lld faces closed).", s->what, (long long)es_mesh_nverts(s->open), (long long)holes,
             (long long)nv, (long long)es_mesh_nfaces(s->closed));
    }
    return 0;
}

/* ---- 2. the factors, the frames ------------------------------------------------ */

static int factors(notebook *nb, study *s)
{
    int64_t nv = es_mesh_nverts(s->closed), ne = es_mesh_nedges(s->closed);
    double *len = malloc(sizeof(double) * (size_t)ne);
    es_status rc;
    nb_step(nb, "factors: the face to the sphere");
    s->u = malloc(sizeof(double) * (size_t)nv);
    s->sphere = malloc(sizeof(double) * (size_t)(3 * nv));
    if (!len || !s->u || !s->sphere) {
        free(len);
        return nb_fail(nb, ES_ENOMEM, "factors");
    }
    rc = es_edge_lengths(nb->ctx, s->closed, s->xyz, len);
    if (rc == ES_OK) rc = es_conformal_sphere(nb->ctx, s->closed, len, -1, s->u, s->sphere, &s->info);
    free(len);
    if (rc != ES_OK) return nb_fail(nb, rc, "conformal factors");
    printf("%s:   flat in %d Newton steps, %lld broken faces, factor residual %.2g, u in [%.3g, "
           "%.3g]\n", nb->name, s->info.newton_iters, (long long)s->info.broken_faces,
           s->info.factor_residual, s->info.u_min, s->info.u_max);
    return 0;
}

/* Centre of the sphere through the points (least squares on |x|^2 = 2 c.x
 * + d, Gaussian elimination on the 4 x 4 normal equations). */
static void fit_centre(int64_t nv, const double *x, double *c)
{
    double A[4][5] = {{0}}, sol[4];
    for (int64_t v = 0; v < nv; v++) {
        const double *p = x + 3 * v;
        double row[4] = {2 * p[0], 2 * p[1], 2 * p[2], 1}, rhs = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        for (int r = 0; r < 4; r++) {
            for (int q = 0; q < 4; q++) A[r][q] += row[r] * row[q];
            A[r][4] += row[r] * rhs;
        }
    }
    for (int k = 0; k < 4; k++)
        for (int r = k + 1; r < 4; r++)
            for (int q = 4; q >= k; q--) A[r][q] -= A[r][k] / A[k][k] * A[k][q];
    for (int k = 3; k >= 0; k--) {
        sol[k] = A[k][4];
        for (int q = k + 1; q < 4; q++) sol[k] -= A[k][q] * sol[q];
        sol[k] /= A[k][k];
    }
    memcpy(c, sol, 3 * sizeof *c);
}

static int frames(notebook *nb, study *s)
{
    int64_t nv = es_mesh_nverts(s->closed);
    es_embedder *emb = NULL;
    es_embed_opts eo;
    es_status rc;
    nb_step(nb, "frames: k = 0, 1/4, 1/2, 3/4, 1, embedded");
    if (!(s->frames = malloc(sizeof(double) * (size_t)(3 * nv * NK))))
        return nb_fail(nb, ES_ENOMEM, "frames");
    if ((rc = es_embedder_new(nb->ctx, s->closed, &emb)) != ES_OK) return nb_fail(nb, rc, "embedder");
    es_embed_opts_init(&eo);
    eo.refine_max_iter = nb->small ? 30 : 60;
    for (int k = 0; k < NK; k++) {
        double *out = s->frames + 3 * nv * k;
        s->k[k] = k / (double)(NK - 1);
        rc = es_conformal_frame(nb->ctx, emb, s->xyz, s->sphere, s->u, s->k[k],
                                k ? out - 3 * nv : NULL, &eo, out, &s->rep[k]);
        if (rc != ES_OK) break;
        printf("%s:   k = %.2f: RMS ratio %.3g, max %.3g (%.1f s)\n", nb->name, s->k[k],
               s->rep[k].rms_ratio, s->rep[k].max_rel, s->rep[k].t_total);
        fflush(stdout);
    }
    es_embedder_free(emb);
    if (rc != ES_OK) return nb_fail(nb, rc, "frame");
    {
        const double *x = s->frames + 3 * nv * (NK - 1);
        double c[3];
        fit_centre(nv, x, c);
        s->off_sphere = 0;
        for (int64_t v = 0; v < nv; v++) {
            double d = sqrt(pow(x[3 * v] - c[0], 2) + pow(x[3 * v + 1] - c[1], 2) +
                            pow(x[3 * v + 2] - c[2], 2));
            s->off_sphere = fmax(s->off_sphere, fabs(d / s->info.radius - 1));
        }
    }
    return 0;
}

/* ---- 3. report ---------------------------------------------------------------- */

static int report(notebook *nb, study *s)
{
    int64_t nv = es_mesh_nverts(s->closed);
    es_render_mesh rm[NK];
    es_render_spec rs;
    static char labels[NK][32];
    es_status rc;
    FILE *f;
    nb_step(nb, "report: the morph, its quality");
    nb_h(nb, 2, "The factors");
    nb_p(nb, "The flattening took %d Newton steps (largest angle defect left %.2g rad%s); the "
         "sphere (radius %.4g at the face's length sum) was centred in %d Möbius steps. Its "
         "chordal lengths realize the factors to %.2g (the largest |u_a + u_b - 2 log(s/l)|); "
         "u ranges over [%.3f, %.3f], i.e. edges scaled by %.2f to %.2f.",
         s->info.newton_iters, s->info.angle_defect,
         s->info.broken_faces ? ", with faces the flat map breaks" : "", s->info.radius,
         s->info.mobius_iters, s->info.factor_residual, s->info.u_min, s->info.u_max,
         exp(s->info.u_min), exp(s->info.u_max));
    if (!(f = nb_csv_open(nb, "factors.csv", "vertex,u"))) return 1;
    for (int64_t v = 0; v < nv; v++) fprintf(f, "%lld,%.17g\n", (long long)v, s->u[v]);
    if (nb_csv_close(nb, f)) return 1;
    nb_h(nb, 2, "The morph (Fig. 11)");
    if (!(f = nb_csv_open(nb, "frames.csv", "k,rms_ratio,max_rel,closure,seconds"))) return 1;
    nb_table(nb, "k|RMS ratio|max relative error|closure energy|seconds");
    for (int k = 0; k < NK; k++) {
        fprintf(f, "%.4g,%.6g,%.6g,%.6g,%.3f\n", s->k[k], s->rep[k].rms_ratio, s->rep[k].max_rel,
                s->rep[k].closure_after, s->rep[k].t_total);
        nb_row(nb, "%.2f|%.3f %%|%.2f %%|%.3g|%.1f", s->k[k], 100 * s->rep[k].rms_ratio,
               100 * s->rep[k].max_rel, s->rep[k].closure_after, s->rep[k].t_total);
        snprintf(labels[k], sizeof labels[k], "k = %.2f", s->k[k]);
        es_render_mesh_from(&rm[k], s->closed, s->frames + 3 * nv * k);
        rm[k].label = labels[k];
        if (es_meshio_write(nb->ctx, nb_path(nb, "frame_%d.obj", k), ES_FORMAT_OBJ, s->closed,
                            s->frames + 3 * nv * k, NULL) != ES_OK)
            return nb_fail(nb, ES_EIO, "frame file");
    }
    if (nb_csv_close(nb, f)) return 1;
    es_render_spec_init(&rs);
    rs.nmeshes = NK;
    rs.meshes = rm;
    rs.width = 260;
    rs.height = 280;
    rs.fit_each = 1;   /* the sphere is smaller than the face at one length sum */
    rs.title = "Conformal factors k u, k = 0 .. 1, each frame embedded (Fig. 11)";
    /* the face seen from the front: the automatic view of the open face */
    if ((rc = es_render_auto_view(nb->ctx, es_mesh_nverts(s->open), s->frames,
                                  es_mesh_nfaces(s->open), es_mesh_faces(s->open), rs.view,
                                  rs.up)) != ES_OK)
        return nb_fail(nb, rc, "camera");
    rs.has_view = rs.has_up = 1;
    if ((rc = es_render(nb->ctx, &rs, nb_path(nb, "fig11.png"), NULL)) != ES_OK)
        return nb_fail(nb, rc, "render");
    nb_output(nb, "fig11.png");
    nb_image(nb, "fig11.png", "The closed-off face (k = 0) to the sphere (k = 1); meshes "
             "frame_K.obj, each panel scaled to fit");
    nb_p(nb, "At k = 1 the worst vertex is %.3g %% of the radius off the sphere fitted to the "
         "frame.", 100 * s->off_sphere);
    return 0;
}

int main(int argc, char **argv)
{
    notebook nb;
    study s;
    int rc = nb_open(&nb, "08_conformal", "The conformal morph: a face to the sphere (Fig. 11)",
                     argc, argv);
    if (rc) return rc;
    memset(&s, 0, sizeof s);
    nb_p(&nb, "**Question.** Discrete conformal factors take the closed-off face to the "
         "sphere; scaled by k = 0 .. 1 and embedded, do they morph the face onto the sphere, "
         "and do the frames realize their lengths?");
    nb_p(&nb, "**Expected.** The k = 1 frame on the sphere (within 1 %% of the radius); the "
         "middle frames less exact (the paper's jitter).");
    if (!load(&nb, &s) && !factors(&nb, &s) && !frames(&nb, &s) && !report(&nb, &s)) {
        nb_step(&nb, "self-check");
        nb_check(&nb, "k = 1: worst vertex off the sphere / radius", s.off_sphere, "<", 0.01);
        nb_check(&nb, "the sphere realizes the factors (max log error)", s.info.factor_residual,
                 "<", s.info.broken_faces ? 0.25 : 1e-6);
        nb_check(&nb, "k = 1: RMS ratio", s.rep[NK - 1].rms_ratio, "<", 1e-3);
        nb_check(&nb, "worst RMS ratio of the middle frames",
                 fmax(s.rep[1].rms_ratio, fmax(s.rep[2].rms_ratio, s.rep[3].rms_ratio)), "<",
                 0.05);
    }
    es_mesh_free(s.open);
    es_mesh_free(s.closed);
    free(s.xyz);
    free(s.u);
    free(s.sphere);
    free(s.frames);
    return nb_close(&nb);
}
