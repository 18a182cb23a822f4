/* lib/study/interp_walk.c — interpolation and extrapolation of a store's
 * shapes, each frame embedded, written and (optionally) stored:
 *  - between two rows, or a weighted combination of rows, the rows' meshes
 *    are interpolated (es_interp_targets: lengths, and dihedrals averaged on
 *    the circle as the start);
 *  - between any two points (stored points, means, expressions), frame t
 *    embeds (1 - t) A + t B at the scale (1 - t) s_A + t s_B (lerp in
 *    datasets-spec/point-syntax.md), started from the previous frame (the
 *    first from the nearest row; a frame at a row end from that row's
 *    dihedrals, so it is the row again).
 * Frames are aligned frame to frame, so the sequence does not jump. Every
 * frame is checked before the first is written: a walk that leaves
 * edge-length space is refused and leaves nothing behind. */
#include "study/study_pkg.h"
#include "edgespace/es_io.h"
#include "core/files.h"

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
    char name[256];
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
    if (o->steps > 1) {
        es_study_frame_path(o->output, i, fname, sizeof fname);
        snprintf(rname, sizeof rname, "%s_%02lld", wk->name, (long long)i);
    } else {
        snprintf(fname, sizeof fname, "%s", o->output);
        snprintf(rname, sizeof rname, "%s", wk->name);
    }
    if ((rc = es_mesh_write(wk->ctx, fname, ES_FORMAT_AUTO, wk->mesh, xyz, NULL)) != ES_OK)
        return rc;
    if (o->frame) o->frame(o->userdata, i, o->steps, fname, heading, rep);
    if (!o->command) return ES_OK;
    return es_study_store_embedding(wk->ctx, wk->store, rname, prov, wk->emb, target, xyz, rep,
                                    init);
}

const char *es_study_interp_name(const es_study_interp_opts *o, char *buf, size_t n)
{
    char name[256];
    if (o->name) snprintf(name, sizeof name, "%s", o->name);
    else default_name(o->output, name, sizeof name);
    snprintf(buf, n, "%s%s", name, !o->weights && o->steps > 1 ? "_NN" : "");
    return buf;
}

/* ---- between rows ---------------------------------------------------------- */

/* The rows and weights of frame i: (1 - t, t) between --from and --to, or
 * the --weights expression's coefficients. */
typedef struct row_inputs {
    int64_t n;
    int64_t *rows;
    double *w;
    double **xyz;
} row_inputs;

static void row_inputs_clear(es_ctx *ctx, row_inputs *in)
{
    for (int64_t k = 0; in->xyz && k < in->n; k++) es__free(ctx, in->xyz[k]);
    es__free(ctx, in->xyz);
    es__free(ctx, in->rows);
    es__free(ctx, in->w);
    memset(in, 0, sizeof *in);
}

/* The rows of "w1*row:a + w2*row:b ..." (the point syntax: every term a
 * row), or of --from row:A --to row:B. */
static es_status parse_rows(es_ctx *ctx, es_store *s, const es_study_interp_opts *o,
                            row_inputs *in)
{
    es_point_expr *expr = NULL;
    es_status rc = ES_OK;
    int64_t n;
    memset(in, 0, sizeof *in);
    if (o->weights) {
        if ((rc = es_point_parse(ctx, o->weights, &expr)) != ES_OK)
            return es__fail(ctx, rc, "--weights: %s", es_ctx_errmsg(ctx));
        n = es_point_expr_nterms(expr);
    } else {
        n = 2;
    }
    in->rows = es__alloc_array(ctx, n, sizeof *in->rows);
    in->w = es__alloc_array(ctx, n, sizeof *in->w);
    in->xyz = es__calloc(ctx, (size_t)n, sizeof *in->xyz);
    if (!in->rows || !in->w || !in->xyz) {
        es_point_expr_free(expr);
        return ES_ENOMEM;
    }
    in->n = n;
    for (int64_t k = 0; k < n && rc == ES_OK; k++) {
        const char *id;
        if (expr) {
            es_point_leaf kind;
            int64_t index;
            es_point_expr_term(expr, k, &in->w[k], &kind, &id, &index);
            if (kind != ES_POINT_ROW)
                rc = es__fail(ctx, ES_EINVAL, "--weights wants 'w1*row:a + w2*row:b ...' "
                              "(rows only)");
        } else {
            id = (k ? o->to : o->from) + 4;
        }
        if (rc == ES_OK && (in->rows[k] = es_store_find_row(s, id)) < 0) {
            char hint[400];
            es_store_value_hint(s, -1, id, hint, sizeof hint);
            rc = es__fail(ctx, ES_ENOTFOUND, "no row '%s' in the store%s", id, hint);
        }
    }
    if (rc == ES_OK && n < 2)
        rc = es__fail(ctx, ES_EINVAL, "--weights wants two or more rows");
    es_point_expr_free(expr);
    return rc;
}

static es_status interp_rows(walk *wk, double *res)
{
    es_ctx *ctx = wk->ctx;
    const es_study_interp_opts *o = wk->o;
    int64_t nv = es_mesh_nverts(wk->mesh), ne = es_mesh_nedges(wk->mesh);
    double *len = es__alloc_array(ctx, ne, sizeof *len);
    double *alpha = es__alloc_array(ctx, ne, sizeof *alpha);
    row_inputs in;
    es_status rc = parse_rows(ctx, wk->store, o, &in);
    for (int64_t k = 0; rc == ES_OK && k < in.n; k++)
        if (!(in.xyz[k] = es__alloc_array(ctx, 3 * nv, sizeof *in.xyz[k])))
            rc = ES_ENOMEM;
        else
            rc = es_store_read_positions(ctx, wk->store, in.rows[k], in.xyz[k]);
    if (rc == ES_OK && (!len || !alpha)) rc = ES_ENOMEM;
    const double *const *xyz = (const double *const *)in.xyz;
    /* every frame's targets first: a refused frame leaves nothing behind */
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double t = frame_t(o, i), w[2] = {1 - t, t};
        if ((rc = es_interp_targets(ctx, wk->mesh, in.n, xyz, o->weights ? in.w : w, len,
                                    NULL, NULL)) != ES_OK && !o->weights)
            rc = es__fail(ctx, rc, "at t = %.4g: %s", t, es_ctx_errmsg(ctx));
    }
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double t = frame_t(o, i), w[2] = {1 - t, t};
        const double *wi = o->weights ? in.w : w;
        char params[1024], heading[128];
        es_embed_report rep;
        es_interp_info info;
        es_provenance prov = {o->command, in.rows, in.n, params};
        int off = 0;
        /* frames align to the previous frame, the first to the reference input */
        if ((rc = es_interp_targets(ctx, wk->mesh, in.n, xyz, wi, len, alpha, &info)) != ES_OK ||
            (rc = es_embed_solve(ctx, wk->emb, len, 0, alpha, i ? res : xyz[info.reference],
                                 &o->embed, res, &rep)) != ES_OK)
            break;
        for (int64_t k = 0; k < in.n && off < (int)sizeof params - 40; k++)
            off += snprintf(params + off, sizeof params - (size_t)off, "%sw[%s]=%.6g",
                            k ? "; " : "", es_store_row_id(wk->store, in.rows[k]), wi[k]);
        if (o->weights)
            snprintf(heading, sizeof heading, "weights (%lld dihedrals wrapped)",
                     (long long)info.n_wrapped);
        else
            snprintf(heading, sizeof heading, "t = %.4g (%lld dihedrals wrapped)", t,
                     (long long)info.n_wrapped);
        rc = emit_frame(wk, i, heading, len, res, &rep, &prov,
                        "circular mean of the inputs' dihedrals");
    }
    row_inputs_clear(ctx, &in);
    es__free(ctx, len);
    es__free(ctx, alpha);
    return rc;
}

/* ---- between points ---------------------------------------------------------- */

/* Frame t of a walk from a (scale sa) to b (scale sb): v = (1 - t) a + t b
 * at the scale (1 - t) sa + t sb. Past the positive orthant (extrapolated
 * too far) it says so, naming t and the edge. */
static es_status lerp_frame(es_ctx *ctx, const double *a, const double *b, double sa,
                            double sb, int64_t ne, double t, double *v, double *scale)
{
    *scale = (1 - t) * sa + t * sb;
    for (int64_t e = 0; e < ne; e++) {
        v[e] = (1 - t) * a[e] + t * b[e];
        if (!(v[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "at t = %.4g the length of edge %lld is %g: outside "
                    "edge-length space (extrapolated too far)", t, (long long)e, v[e]);
    }
    if (!(*scale > 0)) ES_FAIL(ctx, ES_EINVAL, "at t = %.4g the scale is %g", t, *scale);
    return ES_OK;
}

/* The dihedrals of a row end point ("row:ID"; NULL for another kind): a
 * frame at that end starts from them, so it is the row itself again. */
static es_status row_end_dihedrals(es_ctx *ctx, es_store *s, const es_mesh *mesh,
                                   const char *spec, double *xyz, double **alpha)
{
    int64_t row;
    es_status rc;
    *alpha = NULL;
    if (strncmp(spec, "row:", 4) || (row = es_store_find_row(s, spec + 4)) < 0) return ES_OK;
    if (!(*alpha = es__alloc_array(ctx, es_mesh_nedges(mesh), sizeof **alpha))) return ES_ENOMEM;
    if ((rc = es_store_read_positions(ctx, s, row, xyz)) != ES_OK ||
        (rc = es_dihedral_angles(ctx, mesh, xyz, *alpha)) != ES_OK) {
        es__free(ctx, *alpha);
        *alpha = NULL;
    }
    return rc;
}

static es_status interp_points(walk *wk, double *res)
{
    es_ctx *ctx = wk->ctx;
    es_store *s = wk->store;
    const es_study_interp_opts *o = wk->o;
    int64_t ne = es_mesh_nedges(wk->mesh), nv = es_mesh_nverts(wk->mesh);
    char initd[320], params[1024];
    double *a = es__alloc_array(ctx, ne, sizeof *a), *b = es__alloc_array(ctx, ne, sizeof *b);
    double *v = es__alloc_array(ctx, ne, sizeof *v);
    double *start = es__alloc_array(ctx, 3 * nv, sizeof *start);
    double sa, sb, scale, *end_alpha[2] = {NULL, NULL};
    int64_t row = -1;   /* the first frame's nearest row: the only row used */
    es_status rc = ES_OK;
    if (!a || !b || !v || !start) rc = ES_ENOMEM;
    if (rc == ES_OK) rc = es_study_point_lengths(ctx, s, o->from, o->pca_name, a, &sa);
    if (rc == ES_OK) rc = es_study_point_lengths(ctx, s, o->to, o->pca_name, b, &sb);
    if (rc == ES_OK) rc = row_end_dihedrals(ctx, s, wk->mesh, o->from, start, &end_alpha[0]);
    if (rc == ES_OK) rc = row_end_dihedrals(ctx, s, wk->mesh, o->to, start, &end_alpha[1]);
    /* every frame is checked before the first is written */
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++)
        rc = lerp_frame(ctx, a, b, sa, sb, ne, frame_t(o, i), v, &scale);
    for (int64_t i = 0; rc == ES_OK && i < o->steps; i++) {
        double t = frame_t(o, i);
        es_embed_report rep;
        lerp_frame(ctx, a, b, sa, sb, ne, t, v, &scale);
        if (i == 0) {
            double d;
            if ((rc = es_study_nearest_row(ctx, s, v, NULL, 0, &row, &d)) != ES_OK ||
                (rc = es_store_read_positions(ctx, s, row, start)) != ES_OK)
                break;
            snprintf(initd, sizeof initd, "first frame: nearest row %s; then the previous frame",
                     es_store_row_id(s, row));
        }
        /* from the second frame on, the previous frame (res itself) is both
         * the start and the alignment reference; a frame at a row end starts
         * from that row's dihedrals */
        const double *at_end = t == 0 ? end_alpha[0] : t == 1 ? end_alpha[1] : NULL;
        char heading[64], endd[320];
        es_provenance prov = {o->command, &row, 1, params};
        if ((rc = es_embed_solve(ctx, wk->emb, v, scale, at_end, i ? res : start, &o->embed,
                                 res, &rep)) != ES_OK)
            break;
        snprintf(params, sizeof params, "from=%s; to=%s; t=%.17g", o->from, o->to, t);
        snprintf(heading, sizeof heading, "t = %.4g", t);
        if (at_end) snprintf(endd, sizeof endd, "the dihedrals of %s", t == 0 ? o->from : o->to);
        rc = emit_frame(wk, i, heading, v, res, &rep, &prov, at_end ? endd : initd);
    }
    es__free(ctx, a);
    es__free(ctx, b);
    es__free(ctx, v);
    es__free(ctx, start);
    es__free(ctx, end_alpha[0]);
    es__free(ctx, end_alpha[1]);
    return rc;
}

/* ---- the walk ------------------------------------------------------------------ */

es_status es_study_interp(es_ctx *ctx, es_store *store, const es_study_interp_opts *o)
{
    walk wk = {ctx, store, o, NULL, NULL, {0}};
    es_mesh *mesh = NULL;
    double *res = NULL;
    char probe[4096];
    es_status rc;
    if (!o || !o->output) ES_FAIL(ctx, ES_EINVAL, "interp: no output given");
    if (o->weights ? (o->from || o->to) : (!o->from || !o->to))
        ES_FAIL(ctx, ES_EINVAL, "interp: give from and to, or weights");
    if (o->steps < 1) ES_FAIL(ctx, ES_EINVAL, "interp: steps must be >= 1");
    if (!o->weights && o->steps > 1 && es_study_frame_path(o->output, 0, probe, sizeof probe))
        ES_FAIL(ctx, ES_EINVAL, "with several frames, the output must be a pattern with one "
                "integer conversion, like 'out_%%02d.obj'");
    if (o->name) snprintf(wk.name, sizeof wk.name, "%s", o->name);
    else default_name(o->output, wk.name, sizeof wk.name);
    /* every frame's result name is free (or replaced) before a frame is written */
    for (int64_t i = 0; o->command && i < (o->weights ? 1 : o->steps); i++) {
        char rn[300];
        if (!o->weights && o->steps > 1) snprintf(rn, sizeof rn, "%s_%02lld", wk.name, (long long)i);
        else snprintf(rn, sizeof rn, "%s", wk.name);
        if ((rc = es_store_result_check(ctx, store, "embed", rn)) != ES_OK) return rc;
    }
    if ((rc = es_store_mesh(ctx, store, &mesh)) != ES_OK) return rc;
    wk.mesh = mesh;
    if (!(res = es__alloc_array(ctx, 3 * es_mesh_nverts(mesh), sizeof *res))) rc = ES_ENOMEM;
    if (rc == ES_OK) rc = es_embedder_new(ctx, mesh, &wk.emb);
    if (rc == ES_OK) {
        int rows = o->weights || (!strncmp(o->from, "row:", 4) && !strncmp(o->to, "row:", 4));
        es_study_interp_opts one;
        if (o->weights) {   /* one frame */
            one = *o;
            one.steps = 1;
            wk.o = &one;
        }
        rc = rows ? interp_rows(&wk, res) : interp_points(&wk, res);
        wk.o = o;
    }
    if (rc == ES_OK && o->command) rc = es_store_commit(ctx, store);
    es_embedder_free(wk.emb);
    es_mesh_free(mesh);
    es__free(ctx, res);
    return rc;
}
