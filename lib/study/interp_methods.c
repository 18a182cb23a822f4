/* lib/study/interp_methods.c — es_study_interp by the other papers'
 * methods (es_morph.h) between two stored rows, beside the project's own
 * (interp_walk.c), so that they share the store, the frame files, the
 * quality report and the stored results:
 *  - multiscale (Winkler et al.) and shape-space (Wuhrer et al.) put each
 *    frame together themselves from the rows' positions as ingested; the
 *    report is es_morph_report's (the embedder's scale), the stored result
 *    has no prior deviation;
 *  - conformal (edge-length-interpolation Sec. 5) takes one row to the
 *    sphere, its mesh closed off first when open, each frame embedded;
 *  - paper (edge-length-interpolation as published) embeds each frame of
 *    the rows' interpolated lengths from their averaged dihedrals by
 *    es_embed_paper_solve, aligned frame to frame;
 *  - data-driven (Gao et al.) finds a path through all rows (es_data_path)
 *    in their patch-based rotation-invariant coordinates and decodes each
 *    frame, as the paper does; data-driven-el finds it in the rows'
 *    edge-length PCA scores and embeds each frame as the point of its row
 *    weights, as interp_walk.c embeds lerp: near the prior of those
 *    weights, in the store's frame.
 * As the default walk does, every frame's lengths are checked before the
 * first file is written. */
#include "study/study_pkg.h"
#include "edgespace/es_io.h"
#include "edgespace/es_geom.h"
#include "meshio/meshio_private.h"

#include <math.h>
#include <stdio.h>

typedef struct mwalk {
    es_ctx *ctx;
    es_store *store;
    const es_study_interp_opts *o;
    const es_mesh *mesh;
    const char *name;
    int64_t ra, rb;
    es__file_set files;     /* the frames, renamed into place at the end */
    const es_mesh *file_mesh;   /* the frame files' topology, when not mesh's (an open
                                   store's meshes closed off for the conformal morph) */
    const double *file_xyz;
} mwalk;

static double step_t(const es_study_interp_opts *o, int64_t i)
{
    return o->steps == 1 ? o->t0
                         : o->t0 + (o->t1 - o->t0) * (double)i / (double)(o->steps - 1);
}

/* Frame i written, reported and (with a name) stored. emb: the embedder
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
    if ((rc = es__mesh_write_staged(w->ctx, fname, ES_FORMAT_AUTO,
                                    w->file_mesh ? w->file_mesh : w->mesh,
                                    w->file_mesh ? w->file_xyz : xyz, &w->files)) != ES_OK)
        return rc;
    if (o->frame) o->frame(o->userdata, i, o->steps, fname, heading, rep);
    if (!o->name) return ES_OK;
    es_provenance prov = {o->command ? o->command : "es_study_interp", rows, w->rb < 0 ? 1 : 2,
                          params};
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
        rc = o->method == ES_MORPH_MULTISCALE ? es_multiscale_new(ctx, w->mesh, &o->multiscale, &ms)
                                              : es_shape_space_new(ctx, w->mesh, xa, xb, NULL, &ss);
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double t = step_t(o, i), wt[2] = {1 - t, t}, t0 = es__seconds();
        char heading[96], params[1024];
        es_embed_report rep;
        if ((rc = geom_target(w, in, la, lb, t, len)) != ES_OK) break;
        rc = ms ? es_multiscale_interp(ctx, ms, 2, in, wt, xa, xyz, NULL)
                : es_shape_space_frame(ctx, ss, len, t, xyz);
        if (rc != ES_OK) break;
        memset(&rep, 0, sizeof rep);
        rep.t_total = es__seconds() - t0;
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

/* The published pipeline (es_embed_paper_solve) along t: each frame from
 * the lengths and shortest-arc averaged dihedrals of es_interp_targets,
 * aligned to the previous frame (the first to A). */
static es_status paper(mwalk *w, const double *xa, const double *xb)
{
    es_ctx *ctx = w->ctx;
    const es_study_interp_opts *o = w->o;
    int64_t nv = es_mesh_nverts(w->mesh), ne = es_mesh_nedges(w->mesh);
    const double *in[2] = {xa, xb};
    double *buf = es__alloc_array(ctx, 2 * ne + 6 * nv, sizeof *buf);
    double *len = buf, *alpha = len + ne, *xyz = alpha + ne, *prev = xyz + 3 * nv;
    es_embedder *emb = NULL;
    es_embed_paper_opts po;
    es_status rc = buf ? ES_OK : ES_ENOMEM;
    es_embed_paper_opts_init(&po);
    po.embed = o->embed;
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {   /* all frames checked first */
        double t = step_t(o, i), wt[2] = {1 - t, t};
        rc = es_interp_targets(ctx, w->mesh, 2, in, wt, len, NULL, NULL);
    }
    if (rc == ES_OK) rc = es_embedder_new(ctx, w->mesh, &emb);
    if (rc == ES_OK) memcpy(prev, xa, 3 * (size_t)nv * sizeof *prev);
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double t = step_t(o, i), wt[2] = {1 - t, t};
        char heading[96], params[1024];
        es_embed_report rep;
        if ((rc = es_interp_targets(ctx, w->mesh, 2, in, wt, len, alpha, NULL)) != ES_OK ||
            (rc = es_embed_paper_solve(ctx, emb, len, 0, alpha, prev, &po, xyz, &rep)) != ES_OK)
            break;
        snprintf(heading, sizeof heading, "t = %.4g (paper: %lld L-BFGS iterations, E %.3g)", t,
                 (long long)rep.dihedral_iters, rep.closure_stage1);
        snprintf(params, sizeof params, "method=paper; from=%s; to=%s; t=%.17g", o->from, o->to,
                 t);
        rc = emit(w, i, heading, len, xyz, &rep, emb, NULL, NULL, params);
        memcpy(prev, xyz, 3 * (size_t)nv * sizeof *prev);
        if (rc == ES_OK) rc = es__progress(ctx, "interp", i + 1, o->steps);
    }
    es_embedder_free(emb);
    es__free(ctx, buf);
    return rc;
}

/* The conformal morph (edge-length-interpolation Sec. 5) of row A, closed
 * off first when its mesh is open: frame k = t of lengths e^(k (u_a + u_b)
 * / 2) l_ab, embedded from the dihedrals of A and the sphere interpolated,
 * aligned frame to frame. The files have the closed mesh; the stored
 * results the store's vertices and edges of it. */
static es_status conformal(mwalk *w, const double *xa)
{
    es_ctx *ctx = w->ctx;
    const es_study_interp_opts *o = w->o;
    const int64_t *ed = es_mesh_edges(w->mesh);
    int64_t nv = es_mesh_nverts(w->mesh), ne = es_mesh_nedges(w->mesh), cv, ce;
    es_mesh *closed = NULL;
    es_embedder *emb = NULL;
    es_conformal_info info;
    double *buf = NULL, *len, *lk, *u, *sph, *xyz, *prev, *target;
    es_status rc = es_conformal_close(ctx, w->mesh, xa, &closed);
    if (rc != ES_OK) return rc;
    cv = es_mesh_nverts(closed), ce = es_mesh_nedges(closed);
    if (!(buf = es__alloc_array(ctx, 2 * ce + 10 * cv + ne, sizeof *buf))) {
        es_mesh_free(closed);
        return ES_ENOMEM;
    }
    len = buf, lk = len + ce, u = lk + ce, sph = u + cv, xyz = sph + 3 * cv, prev = xyz + 3 * cv;
    target = prev + 3 * cv;
    if ((rc = es_edge_lengths(ctx, closed, es_mesh_xyz(closed), len)) == ES_OK)
        rc = es_conformal_sphere(ctx, closed, len, -1, u, sph, &info);
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++)   /* all frames checked first */
        rc = es_conformal_lengths(ctx, closed, len, u, step_t(o, i), lk);
    if (rc == ES_OK) rc = es_embedder_new(ctx, closed, &emb);
    w->file_mesh = closed;
    w->file_xyz = xyz;
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double k = step_t(o, i);
        char heading[160], params[1024];
        es_embed_report rep;
        if ((rc = es_conformal_lengths(ctx, closed, len, u, k, lk)) != ES_OK ||
            (rc = es_conformal_frame(ctx, emb, es_mesh_xyz(closed), sph, u, k, i ? prev : NULL,
                                     &o->embed, xyz, &rep)) != ES_OK)
            break;
        for (int64_t e = 0; e < ne; e++) target[e] = lk[es_mesh_find_edge(closed, ed[2 * e],
                                                                          ed[2 * e + 1])];
        snprintf(heading, sizeof heading, "k = %.4g (conformal; %lld holes closed, factors in "
                 "[%.3g, %.3g])", k, (long long)(cv - nv), info.u_min, info.u_max);
        snprintf(params, sizeof params, "method=conformal; from=%s; k=%.17g", o->from, k);
        rc = emit(w, i, heading, target, xyz, &rep, NULL, es_embedder_vertex_closure(emb),
                  es_embedder_vertex_edge_error(emb), params);
        memcpy(prev, xyz, 3 * (size_t)cv * sizeof *prev);
        if (rc == ES_OK) rc = es__progress(ctx, "interp", i + 1, o->steps);
    }
    w->file_mesh = NULL;
    es_embedder_free(emb);
    es_mesh_free(closed);
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

/* Gao et al.'s path through all rows (es_data_path with opts->path, frames
 * evenly along it). data-driven (lri 1), as the paper: the path in the
 * rows' patch-based rotation-invariant coordinates (es_lri, base: row A),
 * each frame the coordinates' combination decoded and placed between A and
 * B by the interpolated rigid motion (es_lri_place); its report measures
 * the frame against the same combination of the rows' lengths.
 * data-driven-el (lri 0), the project's: the path in the rows' edge-length
 * PCA scores, each frame the point of its row weights embedded near its
 * prior like the default walk. */
static es_status data_driven(mwalk *w, int lri)
{
    es_ctx *ctx = w->ctx;
    const es_study_interp_opts *o = w->o;
    const char *name = es_morph_method_name(o->method);
    int64_t n = es_store_nrows(w->store), ne = es_mesh_nedges(w->mesh);
    int64_t nv = es_mesh_nverts(w->mesh), nc = 0, m = o->steps, dim = ne;
    double *l = es__alloc_array(ctx, ne * n + n + n * n + n * m * 2 + 2 * ne + 8 * nv + 2 * ne,
                                sizeof *l);
    double *sc = l + ne * n, *coords = sc + n, *frames = coords + n * n, *wts = frames + n * m;
    double *v = wts + n * m, *tl = v + ne, *xyz = tl + ne, *vc = xyz + 3 * nv, *ve = vc + nv;
    double scale;
    double *X = NULL, *feat = NULL, *fx = NULL, *y = NULL;
    es_data_path_info info;
    es_study_embedder *se = NULL;   /* the edge-length variant's embedding session */
    es_study_embed_result er;
    es_lri *L = NULL;
    es_status rc = l ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK && (o->t0 != 0 || o->t1 != 1))
        rc = es__fail(ctx, ES_EINVAL, "interp --method %s: the path runs from A to B (t0 0, t1 "
                      "1), not beyond", name);
    if (rc == ES_OK && m < 2)
        rc = es__fail(ctx, ES_EINVAL, "interp --method %s: give 2 or more steps", name);
    if (rc == ES_OK) rc = es_store_read_lengths(ctx, w->store, 0, n, (es_mat){l, ne, n, ne});
    if (rc == ES_OK) rc = es_store_read_scales(ctx, w->store, sc);
    if (rc == ES_OK && lri) {   /* every row's coordinates against row A */
        if (!(X = es__alloc_array(ctx, 3 * nv * n + 3 * nv, sizeof *X))) rc = ES_ENOMEM;
        y = X + 3 * nv * n;
        for (int64_t r = 0; rc == ES_OK && r < n; r++)
            rc = es_store_read_positions(ctx, w->store, r, X + 3 * nv * r);
        if (rc == ES_OK) rc = es_lri_new(ctx, w->mesh, X + 3 * nv * w->ra, NULL, &L);
        if (rc == ES_OK) {
            dim = es_lri_dim(L);
            if (!(feat = es__alloc_array(ctx, dim * (n + 1), sizeof *feat))) rc = ES_ENOMEM;
            fx = feat + dim * n;
        }
        for (int64_t r = 0; rc == ES_OK && r < n; r++) {
            rc = es_lri_encode(ctx, L, X + 3 * nv * r, feat + dim * r);
            if (rc == ES_OK) rc = es__progress(ctx, "interp: shape coordinates", r + 1, n);
        }
    }
    if (rc == ES_OK) rc = es_data_path_coords(ctx, dim, n, lri ? feat : l, dim, coords, &nc);
    if (rc == ES_OK && nc < 1)
        rc = es__fail(ctx, ES_EINVAL, "interp --method %s: the rows are all alike", name);
    if (rc == ES_OK)
        rc = es_data_path(ctx, nc, n, coords, n, w->ra, w->rb, &o->path, m, frames, wts, &info);
    for (int64_t i = 0; rc == ES_OK && i < m; i++)
        rc = dd_frame(w, n, l, sc, wts + i * n, i, v, &scale);
    if (rc == ES_OK && !lri) rc = es_study_embedder_open(ctx, w->store, 1, &se);
    for (int64_t i = 0; rc == ES_OK && i < m; i++) {
        const double *wi = wts + i * n;
        double s = (double)i / (double)(m - 1), t0 = es__seconds();
        es_embed_report rep;
        char heading[200], params[1024];
        dd_frame(w, n, l, sc, wi, i, v, &scale);
        if (lri) {
            for (int64_t k = 0; k < dim; k++) fx[k] = 0;
            for (int64_t r = 0; r < n; r++)
                for (int64_t k = 0; wi[r] != 0 && k < dim; k++) fx[k] += wi[r] * feat[dim * r + k];
            for (int64_t e = 0; e < ne; e++) tl[e] = v[e] * scale;
            memset(&rep, 0, sizeof rep);
            if ((rc = es_lri_decode(ctx, L, fx, y)) != ES_OK ||
                (rc = es_lri_place(ctx, nv, y, X + 3 * nv * w->ra, X + 3 * nv * w->rb, s,
                                   xyz)) != ES_OK)
                break;
            rep.t_total = es__seconds() - t0;
            if ((rc = es_morph_report(ctx, w->mesh, tl, xyz, o->embed.realized_rtol, &rep, vc,
                                      ve)) != ES_OK)
                break;
        } else {   /* each frame from the last one's correction (a warm start) */
            if ((rc = es_study_embedder_solve(ctx, se, v, scale, wi, &o->embed, i > 0 && !o->cold, 0,
                                              xyz, &er)) != ES_OK)
                break;
            rep = er.report;
        }
        snprintf(heading, sizeof heading, "s = %.4g along a path by %lld rows (%s; nearest row "
                 "at most %.3g neighbour arcs away, the straight line %.3g)", s,
                 (long long)info.hops, name, info.max_near, info.line_max_near);
        snprintf(params, sizeof params, "method=%s; from=%s; to=%s; s=%.17g; knn=%lld; "
                 "sigma=%.17g", name, o->from, o->to, s, (long long)o->path.knn, o->path.sigma);
        rc = lri ? emit(w, i, heading, tl, xyz, &rep, NULL, vc, ve, params)
                 : emit(w, i, heading, v, xyz, &rep, es_study_embedder_embedder(se), NULL, NULL,
                        params);
        if (rc == ES_OK) rc = es__progress(ctx, "interp", i + 1, m);
    }
    es_lri_free(L);
    es_study_embedder_free(se);
    es__free(ctx, X);
    es__free(ctx, feat);
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
    mwalk w = {ctx, store, o, mesh, name, -1, -1, {0}, NULL, NULL};
    double *xa = NULL, *xb = NULL;
    es_status rc;
    if (!es_morph_method_name(o->method))
        ES_FAIL(ctx, ES_EINVAL, "interp: unknown method %d", (int)o->method);
    if (o->weights)
        ES_FAIL(ctx, ES_EINVAL, "interp --method %s walks from A to B: --weights is the "
                "edge-length method's", es_morph_method_name(o->method));
    if ((rc = end_row(ctx, store, o, o->from, &w.ra)) != ES_OK ||
        (o->method != ES_MORPH_CONFORMAL && (rc = end_row(ctx, store, o, o->to, &w.rb)) != ES_OK))
        return rc;
    if (o->method == ES_MORPH_CONFORMAL && o->to)
        ES_FAIL(ctx, ES_EINVAL, "interp --method conformal maps one row to the sphere: give "
                "--from only (got --to %s)", o->to);
    if (o->method == ES_MORPH_DATA_DRIVEN || o->method == ES_MORPH_DATA_DRIVEN_EL) {
        rc = data_driven(&w, o->method == ES_MORPH_DATA_DRIVEN);
    } else {
        int64_t nv = es_mesh_nverts(mesh);
        if (!(xa = es__alloc_array(ctx, 6 * nv, sizeof *xa))) return ES_ENOMEM;
        xb = xa + 3 * nv;
        if ((rc = es_store_read_positions(ctx, store, w.ra, xa)) == ES_OK &&
            (w.rb < 0 || (rc = es_store_read_positions(ctx, store, w.rb, xb)) == ES_OK))
            rc = o->method == ES_MORPH_CONFORMAL ? conformal(&w, xa)
                 : o->method == ES_MORPH_PAPER   ? paper(&w, xa, xb)
                                                 : geometric(&w, xa, xb);
        es__free(ctx, xa);
    }
    return es__study_frames_done(ctx, store, o, rc, was_pending, &w.files);
}
