/* lib/study/interp_walk.c — interpolation and extrapolation of a store's
 * shapes, each frame embedded, written and (optionally) stored.
 *
 * Between any two points A and B (rows, stored points, means,
 * expressions), frame t is the point lerp(A, B, t) of
 * datasets-spec/point-syntax.md: lengths (1 - t) A + t B at the scale
 * (1 - t) s_A + t s_B, row weights (1 - t) w_A + t w_B. It is embedded
 * exactly as es_study_embed embeds that point: near the prior of its row
 * weights (es_study_prior, es_embed_prior_solve), in the store's frame, so
 * frames overlay without jumps and embed of lerp(A, B, t) gives this
 * walk's frame t. Between two rows the prior's dihedrals are the circular
 * interpolation of the rows' (the shortest arc, as es_interp_targets). A
 * weighted combination of rows is one such point. Every frame is checked
 * before the first is written: a walk that leaves edge-length space is
 * refused and leaves nothing behind. The frame files appear all together
 * once the walk is complete (and stored), or none of them: each is staged
 * beside its name and renamed into place at the end (a full disk used to
 * leave new and old frames mixed). */
#include "study/study_pkg.h"
#include "edgespace/es_io.h"
#include "core/files.h"
#include "meshio/meshio_private.h"
#include "store/store_private.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>

void es_study_interp_opts_init(es_study_interp_opts *o)
{
    memset(o, 0, sizeof *o);
    o->t0 = 0;
    o->t1 = 1;
    o->steps = 9;
    es_embed_opts_init(&o->embed);
    es_multiscale_opts_init(&o->multiscale);
    es_data_path_opts_init(&o->path);
}

/* t of frame i of `steps` from t0 to t1 inclusive. */
static double frame_t(const es_study_interp_opts *o, int64_t i)
{
    return o->steps == 1 ? o->t0
                         : o->t0 + (o->t1 - o->t0) * (double)i / (double)(o->steps - 1);
}

int es_study_frame_path(const char *pat, int64_t i, char *out, size_t n)
{
    size_t k = 0;
    int seen = 0;
    for (const char *p = pat; *p; p++) {
        char num[32];
        int zero = 0, width = 0, w;
        if (*p != '%' || p[1] == '%') {
            if (k + 1 >= n) return -1;
            out[k++] = *p;
            p += *p == '%';
            continue;
        }
        if (seen++) return -1;
        p++;
        if (*p == '0') zero = 1, p++;
        while (isdigit((unsigned char)*p)) width = width * 10 + (*p++ - '0');
        if (*p != 'd' || width > 20) return -1;
        w = zero ? snprintf(num, sizeof num, "%0*lld", width, (long long)i)
                 : snprintf(num, sizeof num, "%*lld", width, (long long)i);
        if (k + (size_t)w >= n) return -1;
        memcpy(out + k, num, (size_t)w);
        k += (size_t)w;
    }
    out[k] = 0;
    return seen == 1 ? 0 : -1;
}

/* The default result name: the output's base name without its extension
 * and without the frame conversion ('cat_%02d.obj' -> 'cat'). */
static void default_name(const char *path, char *buf, size_t n)
{
    char *q;
    es__path_stem(path, buf, n);
    q = strchr(buf, '%');   /* the conversion, skipping literal %% */
    while (q && q[1] == '%') q = strchr(q + 2, '%');
    if (q) {
        *q = 0;
        while (q > buf && (q[-1] == '_' || q[-1] == '-')) *--q = 0;
    }
    if (!*buf) snprintf(buf, n, "interp");
}

/* What every frame of a walk shares. */
typedef struct walk {
    es_ctx *ctx;
    es_store *store;
    const es_study_interp_opts *o;
    const es_mesh *mesh;
    es_embedder *emb;
    es_study_embedder *se;   /* the embedder and the rows for priors (cached) */
    char name[256];
    es__file_set files;     /* the frames, renamed into place at the end */
} walk;

/* Frame i: its mesh file (the pattern expanded), the caller's callback,
 * and, when storing, the result NAME (NAME_<i> in a sequence) with its
 * provenance and what it started from. */
static es_status emit_frame(walk *wk, int64_t i, const char *heading, const double *target,
                            const double *xyz, const es_embed_report *rep,
                            const es_provenance *prov, const char *init)
{
    const es_study_interp_opts *o = wk->o;
    char fname[4096], rname[300];
    es_status rc;
    es__study_frame_names(o, wk->name, i, fname, sizeof fname, rname, sizeof rname);
    if ((rc = es__mesh_write_staged(wk->ctx, fname, ES_FORMAT_AUTO, wk->mesh, xyz,
                                    &wk->files)) != ES_OK)
        return rc;
    if (o->frame) o->frame(o->userdata, i, o->steps, fname, heading, rep);
    if (!o->name) return ES_OK;
    return es_study_store_embedding(wk->ctx, wk->store, rname, prov, wk->emb, target, xyz, rep,
                                    init);
}

es_status es__study_frames_done(es_ctx *ctx, es_store *store, const es_study_interp_opts *o,
                                es_status rc, int was_pending, es__file_set *files)
{
    if (rc != ES_OK) {
        char msg[1024];
        es__file_set_abort(ctx, files);
        /* frames already stored in the working copy go with the files */
        snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
        if (o->name && !was_pending && es_store_pending(store) &&
            es_store_rollback(ctx, store) != ES_OK)
            es__warn(ctx, "%s", es_ctx_errmsg(ctx));
        es__fail(ctx, rc, "%s", msg);
        return rc;
    }
    /* stored frames: the files appear with the caller's commit of the store */
    if (o->name) return es__store_publish_with(ctx, store, files);
    return es__file_set_commit(ctx, files);
}

const char *es_study_interp_default_name(const char *output, char *buf, size_t n)
{
    default_name(output ? output : "", buf, n);
    return buf;
}

const char *es_study_interp_name(const es_study_interp_opts *o, char *buf, size_t n)
{
    char name[256];
    if (o->name) snprintf(name, sizeof name, "%s", o->name);
    else default_name(o->output, name, sizeof name);
    snprintf(buf, n, "%s%s", name, !o->weights && o->steps > 1 ? "_NN" : "");
    return buf;
}

void es__study_frame_names(const es_study_interp_opts *o, const char *name, int64_t i,
                           char *fname, size_t nf, char *rname, size_t nr)
{
    if (o->steps > 1) {
        es_study_frame_path(o->output, i, fname, nf);
        snprintf(rname, nr, "%s_%02lld", name, (long long)i);
    } else {
        snprintf(fname, nf, "%s", o->output);
        snprintf(rname, nr, "%s", name);
    }
}

/* ---- the walk ------------------------------------------------------------------ */

/* Frame t of a walk from a to b: lengths, scale and row weights of
 * lerp(a, b, t). Past the positive orthant (extrapolated too far) it says
 * so, naming t and the edge. */
static es_status lerp_frame(es_ctx *ctx, int64_t ne, int64_t nr, const double *a,
                            const double *b, double sa, double sb, const double *wa,
                            const double *wb, double t, double *v, double *scale, double *w)
{
    *scale = (1 - t) * sa + t * sb;
    for (int64_t e = 0; e < ne; e++) {
        v[e] = (1 - t) * a[e] + t * b[e];
        if (!(v[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "at t = %.4g the length of edge %lld is %g: outside "
                    "edge-length space (extrapolated too far)", t, (long long)e, v[e]);
    }
    if (!(*scale > 0)) ES_FAIL(ctx, ES_EINVAL, "at t = %.4g the scale is %g", t, *scale);
    for (int64_t i = 0; w && i < nr; i++) w[i] = (1 - t) * wa[i] + t * wb[i];
    return ES_OK;
}

/* The rows the prior of weights w draws on (provenance): a new array. */
static es_status used_rows(es_ctx *ctx, int64_t n, const double *w, int64_t **rows,
                           int64_t *nrows)
{
    int64_t k = 0;
    for (int64_t i = 0; i < n; i++) k += w[i] != 0;
    *nrows = k;
    if (!(*rows = es__alloc_array(ctx, k > 0 ? k : 1, sizeof **rows))) return ES_ENOMEM;
    for (int64_t i = 0, j = 0; i < n; i++)
        if (w[i] != 0) (*rows)[j++] = i;
    return ES_OK;
}

/* Embed frame i (lengths v at scale, weights w) near its prior, from the
 * last frame (warm) unless o->cold, and emit it. */
static es_status embed_frame(walk *wk, int64_t i, double t, const double *v, double scale,
                             const double *w, double *res)
{
    es_ctx *ctx = wk->ctx;
    const es_study_interp_opts *o = wk->o;
    int64_t n = es_store_nrows(wk->store), *rows = NULL, nrows = 0;
    char params[1024], heading[64], init[64];
    es_study_embed_result er;
    const es_embed_report *rep = &er.report;
    es_status rc;
    if ((rc = es_study_embedder_solve(ctx, wk->se, v, scale, w, &o->embed, i > 0 && !o->cold, 0, res,
                                      &er)) != ES_OK ||
        (rc = used_rows(ctx, n, w, &rows, &nrows)) != ES_OK) {
        es__free(ctx, rows);
        return rc;
    }
    es_provenance prov = {o->command ? o->command : "es_study_interp", rows, nrows, params};
    if (o->weights) {
        snprintf(params, sizeof params, "weights=%s", o->weights);
        snprintf(heading, sizeof heading, "weights");
    } else {
        snprintf(params, sizeof params, "from=%s; to=%s; t=%.17g", o->from, o->to, t);
        snprintf(heading, sizeof heading, "t = %.4g", t);
    }
    snprintf(init, sizeof init, "prior of %lld rows, store frame", (long long)nrows);
    rc = emit_frame(wk, i, heading, v, res, rep, &prov, init);
    es__progress(ctx, "interp: frames", i + 1, o->steps);
    es__free(ctx, rows);
    return rc;
}

static es_status walk_frames(walk *wk, double *res)
{
    es_ctx *ctx = wk->ctx;
    es_store *s = wk->store;
    const es_study_interp_opts *o = wk->o;
    int64_t ne = es_mesh_nedges(wk->mesh), nr = es_store_nrows(s);
    const char *from = o->weights ? o->weights : o->from, *to = o->weights ? o->weights : o->to;
    double *a = es__alloc_array(ctx, 3 * ne + 3 * nr, sizeof *a);
    double sa, sb, scale, *b = a + ne, *v = b + ne, *wa = v + ne;
    double *wb = wa + nr, *w = wb + nr;
    es_status rc = ES_OK;
    if (!a) return ES_ENOMEM;
    if ((rc = es_study_point_weights(ctx, s, from, o->pca_name, a, &sa, wa)) != ES_OK ||
        (rc = es_study_point_weights(ctx, s, to, o->pca_name, b, &sb, wb)) != ES_OK)
        goto done;
    /* every frame is checked before the first is written */
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++)
        rc = lerp_frame(ctx, ne, nr, a, b, sa, sb, wa, wb, frame_t(o, i), v, &scale, NULL);
    if (rc == ES_OK && (rc = es_study_embedder_open(ctx, s, 1, &wk->se)) != ES_OK) goto done;
    wk->emb = es_study_embedder_embedder(wk->se);
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double t = frame_t(o, i);
        /* the embedder reports its progress; a cancel stops the walk here */
        if ((rc = es__cancelled(ctx, "interp"))) break;
        lerp_frame(ctx, ne, nr, a, b, sa, sb, wa, wb, t, v, &scale, w);
        rc = embed_frame(wk, i, t, v, scale, w, res);
    }
done:
    es__free(ctx, a);
    return rc;
}

es_status es_study_interp(es_ctx *ctx, es_store *store, const es_study_interp_opts *o)
{
    walk wk = {ctx, store, o, NULL, NULL, NULL, {0}, {0}};
    const int was_pending = es_store_pending(store);
    es_study_interp_opts one;
    es_mesh *mesh = NULL;
    double *res = NULL;
    char probe[4096];
    es_status rc;
    if (!o || !o->output) ES_FAIL(ctx, ES_EINVAL, "interp: no output given");
    if (o->weights ? (o->from || o->to)
                   : (!o->from || (!o->to && o->method != ES_MORPH_CONFORMAL)))
        ES_FAIL(ctx, ES_EINVAL, "interp: give from and to, or weights");
    if (o->steps < 1) ES_FAIL(ctx, ES_EINVAL, "interp: steps must be >= 1");
    if (!o->weights && o->steps > 1 && es_study_frame_path(o->output, 0, probe, sizeof probe))
        ES_FAIL(ctx, ES_EINVAL, "with several frames, the output must be a pattern with one "
                "integer conversion, like 'out_%%02d.obj'");
    /* the frames' result names (nothing is stored without one) */
    snprintf(wk.name, sizeof wk.name, "%s", o->name ? o->name : "");
    /* every frame's result name is free (or replaced) before a frame is written */
    for (int64_t i = 0; o->name && i < (o->weights ? 1 : o->steps); i++) {
        char rn[300];
        if (!o->weights && o->steps > 1) snprintf(rn, sizeof rn, "%s_%02lld", wk.name, (long long)i);
        else snprintf(rn, sizeof rn, "%s", wk.name);
        if ((rc = es_store_result_check(ctx, store, "embed", rn)) != ES_OK) return rc;
    }
    if (o->weights) {   /* one point, one frame */
        one = *o;
        one.steps = 1;
        wk.o = &one;
    }
    if ((rc = es_store_mesh(ctx, store, &mesh)) != ES_OK) return rc;
    if (o->method != ES_MORPH_EDGE_LENGTH) {   /* the other papers' (interp_methods.c) */
        rc = es__study_interp_method(ctx, store, o, mesh, wk.name, was_pending);
        es_mesh_free(mesh);
        return rc;
    }
    wk.mesh = mesh;
    if (!(res = es__alloc_array(ctx, 3 * es_mesh_nverts(mesh), sizeof *res))) rc = ES_ENOMEM;
    if (rc == ES_OK) rc = walk_frames(&wk, res);
    rc = es__study_frames_done(ctx, store, o, rc, was_pending, &wk.files);
    es_study_embedder_free(wk.se);
    es_mesh_free(mesh);
    es__free(ctx, res);
    return rc;
}
