/* lib/study/interp_methods.c — es_study_interp by the other papers'
 * methods (es_morph.h) between two stored rows, beside the project's own
 * (interp_walk.c), so that they share the store, the frame files, the
 * quality report and the stored results:
 *  - multiscale (Winkler et al.) and shape-space (Wuhrer et al.) put each
 *    frame together themselves from the rows' positions as ingested; the
 *    report is es_morph_report's (the embedder's scale), the stored result
 *    has no prior deviation;
 *  - data-driven (Gao et al.) finds a path through all rows (es_data_path
 *    on their edge-length PCA scores with every component) and embeds each
 *    frame as the point of its row weights, as interp_walk.c embeds lerp:
 *    near the prior of those weights, in the store's frame.
 * As the default walk does, every frame's lengths are checked before the
 * first file is written. */
#include "study/study_pkg.h"
#include "edgespace/es_io.h"
#include "edgespace/es_geom.h"
#include "meshio/meshio_private.h"

#include <math.h>
#include <stdio.h>
#include <time.h>

typedef struct mwalk {
    es_ctx *ctx;
    es_store *store;
    const es_study_interp_opts *o;
    const es_mesh *mesh;
    const char *name;
    int64_t ra, rb;
    es__file_set files;     /* the frames, renamed into place at the end */
} mwalk;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double step_t(const es_study_interp_opts *o, int64_t i)
{
    return o->steps == 1 ? o->t0
                         : o->t0 + (o->t1 - o->t0) * (double)i / (double)(o->steps - 1);
}

/* Frame i written, reported and (with a command) stored. emb: the embedder
 * that made it (data-driven), or NULL with the per-vertex values vc, ve. */
static es_status emit(mwalk *w, int64_t i, const char *heading, const double *target,
                      const double *xyz, const es_embed_report *rep, const es_embedder *emb,
                      const double *vc, const double *ve, const char *params)
{
    const es_study_interp_opts *o = w->o;
    char fname[4096], rname[300], init[96];
    int64_t rows[2] = {w->ra, w->rb};
    es_status rc;
    es__study_frame_names(o, w->name, i, fname, sizeof fname, rname, sizeof rname);
    if ((rc = es__mesh_write_staged(w->ctx, fname, ES_FORMAT_AUTO, w->mesh, xyz, &w->files)) !=
        ES_OK)
        return rc;
    if (o->frame) o->frame(o->userdata, i, o->steps, fname, heading, rep);
    if (!o->command) return ES_OK;
    es_provenance prov = {o->command, rows, 2, params};
    snprintf(init, sizeof init, "%s", es_morph_method_name(o->method));
    if (emb)
        return es_study_store_embedding(w->ctx, w->store, rname, &prov, emb, target, xyz, rep,
                                        init);
    return es__study_store_mesh_result(w->ctx, w->store, rname, &prov, w->mesh, vc, ve, NULL,
                                       target, xyz, rep, init);
}

/* Target lengths of frame t: multiscale interpolates as es_interp_targets
 * (normalized lengths at the mean scale); shape-space linearly (Sec. 4).
 * ES_EINVAL names t and the edge past the positive orthant. */
static es_status geom_target(mwalk *w, const double *const *in, const double *la,
                             const double *lb, double t, double *len)
{
    int64_t ne = es_mesh_nedges(w->mesh);
    double wt[2] = {1 - t, t};
    if (w->o->method == ES_MORPH_MULTISCALE)
        return es_interp_targets(w->ctx, w->mesh, 2, in, wt, len, NULL, NULL);
    for (int64_t e = 0; e < ne; e++) {
        len[e] = (1 - t) * la[e] + t * lb[e];
        if (!(len[e] > 0))
            ES_FAIL(w->ctx, ES_EINVAL, "at t = %.4g the length of edge %lld is %g: outside "
                    "edge-length space (extrapolated too far)", t, (long long)e, len[e]);
    }
    return ES_OK;
}

static es_status geometric(mwalk *w, const double *xa, const double *xb)
{
    es_ctx *ctx = w->ctx;
    const es_study_interp_opts *o = w->o;
    int64_t nv = es_mesh_nverts(w->mesh), ne = es_mesh_nedges(w->mesh);
    const double *in[2] = {xa, xb};
    double *buf = es__alloc_array(ctx, 3 * ne + 5 * nv, sizeof *buf);
    double *la = buf, *lb = la + ne, *len = lb + ne, *xyz = len + ne, *vc = xyz + 3 * nv;
    double *ve = vc + nv;
    es_multiscale *ms = NULL;
    es_shape_space *ss = NULL;
    es_status rc = buf ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK) rc = es_edge_lengths(ctx, w->mesh, xa, la);
    if (rc == ES_OK) rc = es_edge_lengths(ctx, w->mesh, xb, lb);
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++)
        rc = geom_target(w, in, la, lb, step_t(o, i), len);
    if (rc == ES_OK)
        rc = o->method == ES_MORPH_MULTISCALE ? es_multiscale_new(ctx, w->mesh, NULL, &ms)
                                              : es_shape_space_new(ctx, w->mesh, xa, xb, &ss);
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double t = step_t(o, i), wt[2] = {1 - t, t}, t0 = now_s();
        char heading[96], params[1024];
        es_embed_report rep;
        if ((rc = geom_target(w, in, la, lb, t, len)) != ES_OK) break;
        rc = ms ? es_multiscale_interp(ctx, ms, 2, in, wt, xa, xyz, NULL)
                : es_shape_space_frame(ctx, ss, len, t, xyz);
        if (rc != ES_OK) break;
        memset(&rep, 0, sizeof rep);
        rep.t_total = now_s() - t0;
        if ((rc = es_morph_report(ctx, w->mesh, len, xyz, o->embed.realized_rtol, &rep, vc,
                                  ve)) != ES_OK)
            break;
        snprintf(heading, sizeof heading, "t = %.4g (%s)", t, es_morph_method_name(o->method));
        snprintf(params, sizeof params, "method=%s; from=%s; to=%s; t=%.17g",
                 es_morph_method_name(o->method), o->from, o->to, t);
        rc = emit(w, i, heading, len, xyz, &rep, NULL, vc, ve, params);
        if (rc == ES_OK) rc = es__progress(ctx, "interp", i + 1, o->steps);
    }
    es_multiscale_free(ms);
    es_shape_space_free(ss);
    es__free(ctx, buf);
    return rc;
}

/* Frame i of the path: lengths (normalized) and scale of weights w. */
static es_status dd_frame(mwalk *w, int64_t n, const double *l, const double *sc,
                          const double *wt, int64_t i, double *v, double *scale)
{
    int64_t ne = es_mesh_nedges(w->mesh);
    *scale = 0;
    for (int64_t e = 0; e < ne; e++) v[e] = 0;
    for (int64_t r = 0; r < n; r++) {
        *scale += wt[r] * sc[r];
        for (int64_t e = 0; wt[r] != 0 && e < ne; e++) v[e] += wt[r] * l[r * ne + e];
    }
    for (int64_t e = 0; e < ne; e++)
        if (!(v[e] > 0))
            ES_FAIL(w->ctx, ES_EINVAL, "data-driven frame %lld: the length of edge %lld is %g",
                    (long long)i, (long long)e, v[e]);
    if (!(*scale > 0))
        ES_FAIL(w->ctx, ES_EINVAL, "data-driven frame %lld: the scale is %g", (long long)i, *scale);
    return ES_OK;
}

static es_status data_driven(mwalk *w)
{
    es_ctx *ctx = w->ctx;
    const es_study_interp_opts *o = w->o;
    int64_t n = es_store_nrows(w->store), ne = es_mesh_nedges(w->mesh);
    int64_t nv = es_mesh_nverts(w->mesh), nc = 0, m = o->steps;
    double *l = es__alloc_array(ctx, ne * n + n + n * n + n * m * 2 + ne + 3 * nv * 2 + 2 * ne,
                                sizeof *l);
    double *sc = l + ne * n, *coords = sc + n, *frames = coords + n * n, *wts = frames + n * m;
    double *v = wts + n * m, *xyz = v + ne, *prior = xyz + 3 * nv, *alpha = prior + 3 * nv;
    double *sd = alpha + ne, scale;
    es_data_path_info info;
    es_study_rows *rows = NULL;
    es_embedder *emb = NULL;
    es_status rc = l ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK && (o->t0 != 0 || o->t1 != 1))
        rc = es__fail(ctx, ES_EINVAL, "interp --method data-driven: the path runs from A to B "
                      "(t0 0, t1 1), not beyond");
    if (rc == ES_OK && m < 2)
        rc = es__fail(ctx, ES_EINVAL, "interp --method data-driven: give 2 or more steps");
    if (rc == ES_OK) rc = es_store_read_lengths(ctx, w->store, 0, n, (es_mat){l, ne, n, ne});
    if (rc == ES_OK) rc = es_store_read_scales(ctx, w->store, sc);
    if (rc == ES_OK) rc = es_data_path_coords(ctx, ne, n, l, ne, coords, &nc);
    if (rc == ES_OK && nc < 1)
        rc = es__fail(ctx, ES_EINVAL, "interp --method data-driven: the rows are all alike");
    if (rc == ES_OK)
        rc = es_data_path(ctx, nc, n, coords, n, w->ra, w->rb, NULL, m, frames, wts, &info);
    for (int64_t i = 0; rc == ES_OK && i < m; i++)
        rc = dd_frame(w, n, l, sc, wts + i * n, i, v, &scale);
    if (rc == ES_OK) rc = es_study_rows_load(ctx, w->store, w->mesh, &rows);
    if (rc == ES_OK) rc = es_embedder_new(ctx, w->mesh, &emb);
    for (int64_t i = 0; rc == ES_OK && i < m; i++) {
        const double *wi = wts + i * n;
        es_embed_prior pr = {prior, alpha, sd, NULL};
        es_embed_report rep;
        char heading[160], params[1024];
        dd_frame(w, n, l, sc, wi, i, v, &scale);
        if ((rc = es_study_prior(ctx, rows, wi, prior, alpha, sd)) != ES_OK ||
            (rc = es_embed_prior_solve(ctx, emb, v, scale, &pr, &o->embed, xyz, &rep)) != ES_OK)
            break;
        snprintf(heading, sizeof heading, "s = %.4g along a path by %lld rows (data-driven; "
                 "nearest row at most %.3g neighbour arcs away, the straight line %.3g)",
                 (double)i / (double)(m - 1), (long long)info.hops, info.max_near,
                 info.line_max_near);
        snprintf(params, sizeof params, "method=data-driven; from=%s; to=%s; s=%.17g", o->from,
                 o->to, (double)i / (double)(m - 1));
        rc = emit(w, i, heading, v, xyz, &rep, emb, NULL, NULL, params);
    }
    es_embedder_free(emb);
    es_study_rows_free(rows);
    es__free(ctx, l);
    return rc;
}

/* A row end: "row:ID". */
static es_status end_row(es_ctx *ctx, es_store *s, const es_study_interp_opts *o,
                         const char *spec, int64_t *row)
{
    if (!spec || strncmp(spec, "row:", 4) != 0)
        ES_FAIL(ctx, ES_EINVAL, "interp --method %s walks between two rows: give --from and "
                "--to as row:ID (got '%s')", es_morph_method_name(o->method), spec ? spec : "");
    if ((*row = es_store_find_row(s, spec + 4)) < 0)
        ES_FAIL(ctx, ES_ENOTFOUND, "interp: no row '%s' in %s", spec + 4, es_store_path(s));
    return ES_OK;
}

es_status es__study_interp_method(es_ctx *ctx, es_store *store, const es_study_interp_opts *o,
                                  const es_mesh *mesh, const char *name, int was_pending)
{
    mwalk w = {ctx, store, o, mesh, name, -1, -1, {0}};
    double *xa = NULL, *xb = NULL;
    es_status rc;
    if (!es_morph_method_name(o->method))
        ES_FAIL(ctx, ES_EINVAL, "interp: unknown method %d", (int)o->method);
    if (o->weights)
        ES_FAIL(ctx, ES_EINVAL, "interp --method %s walks from A to B: --weights is the "
                "edge-length method's", es_morph_method_name(o->method));
    if ((rc = end_row(ctx, store, o, o->from, &w.ra)) != ES_OK ||
        (rc = end_row(ctx, store, o, o->to, &w.rb)) != ES_OK)
        return rc;
    if (o->method == ES_MORPH_DATA_DRIVEN) rc = data_driven(&w);
    else {
        int64_t nv = es_mesh_nverts(mesh);
        if (!(xa = es__alloc_array(ctx, 6 * nv, sizeof *xa))) return ES_ENOMEM;
        xb = xa + 3 * nv;
        if ((rc = es_store_read_positions(ctx, store, w.ra, xa)) == ES_OK &&
            (rc = es_store_read_positions(ctx, store, w.rb, xb)) == ES_OK)
            rc = geometric(&w, xa, xb);
        es__free(ctx, xa);
    }
    return es__study_frames_done(ctx, store, o, rc, was_pending, &w.files);
}
