/* lib/morph/multiscale.c — multi-scale geometry interpolation (Winkler,
 * Drieseberg, Alexa and Hormann 2010): a mesh from per-edge lengths and
 * dihedrals, put together bottom up over the patch hierarchy of
 * multiscale_tree.c. See es_morph.h for the steps and the choices made.
 *
 * Leaves glue their faces one by one along their walk (Sec. 3.3): the
 * first face of a piece lies in the xy plane, every further face is placed
 * by its lengths across the edge it is reached over, its plane turned from
 * the plane of the face it is reached from by the target dihedral. With
 * es_geom.h's convention (edge a < b, f holding a -> b, g holding b -> a,
 * t the unit vector a -> b) alpha = atan2((n_g x n_f) . t, n_g . n_f),
 * i.e. n_g is n_f turned about t by -alpha.
 * Inner patches register their children (multiscale_register.c), then
 * blend them (Sec. 3.2, eq. 3): v_a - v_b = s_ab (R_k (x_a - x_b)) / |.|
 * for every occurrence of edge ab in a child k, solved by least squares
 * with the matrix factorized once per topology.
 */
#include "morph/morph_pkg.h"
#include "edgespace/es_geom.h"

#include <math.h>

void es_multiscale_opts_init(es_multiscale_opts *o)
{
    o->patches = 6;
    o->leaf_faces = 0;
    o->passes = 4;
    o->tries = 4;
}

void es_multiscale_free(es_multiscale *ms)
{
    if (!ms) return;
    for (int i = 0; ms->alt && i < ms->opts.tries - 1; i++) es_multiscale_free(ms->alt[i]);

    es__free(ms->ctx, ms->alt);
    es__free(ms->ctx, ms->scratch);
    es__ms_free_nodes(ms);
    es__spd_free(ms->spd);
    es__free(ms->ctx, ms->work);
    es__free(ms->ctx, ms->iwork);
    es__free(ms->ctx, ms);
}

/* One hierarchy from seed `seed`. */
static es_status new_one(es_ctx *ctx, const es_mesh *mesh, const es_multiscale_opts *opts,
                         uint64_t seed, es_multiscale **out);

es_status es_multiscale_new(es_ctx *ctx, const es_mesh *mesh, const es_multiscale_opts *opts,
                            es_multiscale **out)
{
    es_multiscale_opts o;
    es_multiscale *ms = NULL;
    uint64_t seed = es_ctx_seed(ctx);
    es_status rc;
    *out = NULL;
    if (opts) o = *opts;
    else es_multiscale_opts_init(&o);
    if (o.tries < 1 || o.tries > 64)
        ES_FAIL(ctx, ES_EINVAL, "multiscale: tries must be 1 .. 64 (got %d)", o.tries);
    if ((rc = new_one(ctx, mesh, &o, seed, &ms)) != ES_OK) return rc;
    ms->scratch = es__alloc_array(ctx, 3 * es_mesh_nverts(mesh) + es_mesh_nedges(mesh),
                                  sizeof *ms->scratch);
    if (!ms->scratch) rc = ES_ENOMEM;
    if (rc == ES_OK && o.tries > 1 && !(ms->alt = es__calloc(ctx, (size_t)o.tries - 1,
                                                              sizeof *ms->alt)))
        rc = ES_ENOMEM;
    for (int i = 1; rc == ES_OK && i < o.tries; i++) {
        if ((rc = es__progress(ctx, "multiscale: hierarchies", i, o.tries)) == ES_OK)
            rc = new_one(ctx, mesh, &o, seed + (uint64_t)i, &ms->alt[i - 1]);
    }
    if (rc != ES_OK) {
        es_multiscale_free(ms);
        return rc;
    }
    ms->info.tries = o.tries;
    *out = ms;
    return ES_OK;
}

static es_status new_one(es_ctx *ctx, const es_mesh *mesh, const es_multiscale_opts *opts,
                         uint64_t seed, es_multiscale **out)
{
    es_multiscale *ms;
    es_status rc;
    int64_t m;
    *out = NULL;
    if (!mesh || es_mesh_nfaces(mesh) < 1) ES_FAIL(ctx, ES_EINVAL, "multiscale: mesh without faces");
    if (!(ms = es__calloc(ctx, 1, sizeof *ms))) return ES_ENOMEM;
    ms->ctx = ctx;
    ms->mesh = mesh;
    ms->opts = *opts;
    ms->seed = seed;
    if (ms->opts.patches < 2 || ms->opts.patches > 64 || ms->opts.passes < 0 ||
        ms->opts.leaf_faces < 0) {
        int64_t patches = ms->opts.patches;
        es__free(ctx, ms);
        ES_FAIL(ctx, ES_EINVAL, "multiscale: patches must be 2 .. 64 (got %lld), passes and "
                "leaf_faces >= 0", (long long)patches);
    }
    /* a leaf has at least m faces, so that every split has m seeds */
    if (ms->opts.leaf_faces < ms->opts.patches) ms->opts.leaf_faces = ms->opts.patches;
    if ((rc = es__spd_new(ctx, &ms->spd)) != ES_OK || (rc = es__ms_build(ms)) != ES_OK) {
        es_multiscale_free(ms);
        return rc;
    }
    m = ms->maxm > 1 ? ms->maxm : 1;
    ms->work = es__alloc_array(ctx, es__ms_register_work(m) + 12 * m + 3 * ms->maxnv,
                               sizeof *ms->work);
    ms->iwork = es__alloc_array(ctx, m * m + 2 * m + ms->maxnv, sizeof *ms->iwork);
    if (!ms->work || !ms->iwork) {
        es_multiscale_free(ms);
        return ES_ENOMEM;
    }
    *out = ms;
    return ES_OK;
}

void es_multiscale_get_info(const es_multiscale *ms, es_multiscale_info *info)
{
    if (ms && info) *info = ms->info;
}

/* Local index of mesh vertex v in node n (binary search in its sorted
 * vertices). */
static int64_t local(const ms_node *n, int64_t v)
{
    int64_t lo = 0, hi = n->nv - 1;
    while (lo < hi) {
        int64_t mid = (lo + hi) / 2;
        if (n->verts[mid] < v) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* Glue leaf n's faces along its walk. */
static void glue_leaf(es_multiscale *ms, ms_node *n, const double *len, const double *alpha,
                      int64_t *placed)
{
    const int64_t *F = es_mesh_faces(ms->mesh), *fe = es_mesh_face_edges(ms->mesh);
    const int64_t *edges = es_mesh_edges(ms->mesh), *ef = es_mesh_edge_faces(ms->mesh);
    double *x = n->x;
    for (int64_t i = 0; i < n->nv; i++) placed[i] = 0;
    for (int64_t s = 0; s < n->nf; s++) {
        int64_t f = n->walk[3 * s], e = n->walk[3 * s + 1], g = n->walk[3 * s + 2];
        int64_t lv[3];
        for (int k = 0; k < 3; k++) lv[k] = local(n, F[3 * f + k]);
        if (e < 0) {
            /* a piece starts: the face in the xy plane; a vertex it shares
             * with a piece placed before keeps its place (translated to it) */
            double p[9] = {0}, nz[3] = {0, 0, 1}, shift[3] = {0, 0, 0};
            p[3] = len[fe[3 * f]];
            es__apex(p, p + 3, nz, len[fe[3 * f]], len[fe[3 * f + 2]], len[fe[3 * f + 1]], p + 6);
            for (int k = 0; k < 3; k++)
                if (placed[lv[k]]) {
                    es__v3_sub(x + 3 * lv[k], p + 3 * k, shift);
                    break;
                }
            for (int k = 0; k < 3; k++)
                if (!placed[lv[k]]) {
                    for (int c = 0; c < 3; c++) x[3 * lv[k] + c] = p[3 * k + c] + shift[c];
                    placed[lv[k]] = 1;
                }
            continue;
        }
        {
            int64_t a = edges[2 * e], b = edges[2 * e + 1], la = local(n, a), lb = local(n, b);
            int64_t c = -1, kc = 0;
            double ng[3], nf[3], t[3];
            const double *pg0 = x + 3 * local(n, F[3 * g]), *pg1 = x + 3 * local(n, F[3 * g + 1]);
            const double *pg2 = x + 3 * local(n, F[3 * g + 2]);
            for (int k = 0; k < 3; k++)
                if (F[3 * f + k] != a && F[3 * f + k] != b) c = lv[k], kc = k;
            if (placed[c]) continue;
            es__tri_normal(pg0, pg1, pg2, ng);
            es__v3_sub(x + 3 * lb, x + 3 * la, t);
            es__v3_normalize(t);
            /* the new face's lengths: to a and to b */
            double l_ab = len[e], l_ac = 0, l_bc = 0;
            for (int k = 0; k < 3; k++) {
                int64_t ek = fe[3 * f + k], u = edges[2 * ek], w = edges[2 * ek + 1];
                if ((u == a && w == F[3 * f + kc]) || (w == a && u == F[3 * f + kc])) l_ac = len[ek];
                if ((u == b && w == F[3 * f + kc]) || (w == b && u == F[3 * f + kc])) l_bc = len[ek];
            }
            if (ef[2 * e] == f) {
                /* f holds a -> b: f = (a, b, c) about n_f = n_g turned by +alpha */
                es__rotate_axis(ng, t, alpha[e], nf);
                es__apex(x + 3 * la, x + 3 * lb, nf, l_ab, l_ac, l_bc, x + 3 * c);
            } else {
                /* f holds b -> a: f = (b, a, c) about n_f = n_g turned by -alpha */
                es__rotate_axis(ng, t, -alpha[e], nf);
                es__apex(x + 3 * lb, x + 3 * la, nf, l_ab, l_bc, l_ac, x + 3 * c);
            }
            placed[c] = 1;
        }
    }
}

/* Register and blend inner node n's children into its positions. */
static es_status blend_inner(es_multiscale *ms, ms_node *n, const double *len, double *t_reg,
                             double *t_blend)
{
    int64_t m = n->nchild;
    double *r = ms->work + es__ms_register_work(ms->maxm), *t = r + 9 * m, *b = t + 3 * m;
    double t0 = es__seconds(), t1;
    es_status rc = es__ms_register(ms, n, r, t, ms->work, ms->iwork);
    if (rc != ES_OK) return rc;
    t1 = es__seconds();
    *t_reg += t1 - t0;
    for (int64_t i = 0; i < 3 * n->nv; i++) b[i] = 0;
    /* right-hand side M^T e of eq. 3: each occurrence's direction, rotated
     * into the first child's frame, at the target length */
    for (int64_t j = 0; j < n->ne; j++) {
        int64_t pa = n->eloc[2 * j], pb = n->eloc[2 * j + 1];
        double s = len[n->edges[j]];
        for (int64_t o = n->eocc_off[j]; o < n->eocc_off[j + 1]; o++) {
            int64_t k = n->eocc[3 * o];
            const double *xc = ms->node[n->child[k]].x, *rk = r + 9 * k;
            double d[3], u[3];
            es__v3_sub(xc + 3 * n->eocc[3 * o + 1], xc + 3 * n->eocc[3 * o + 2], d);
            for (int c = 0; c < 3; c++) u[c] = rk[3 * c] * d[0] + rk[3 * c + 1] * d[1] + rk[3 * c + 2] * d[2];
            if (es__v3_normalize(u) == 0) continue;
            for (int c = 0; c < 3; c++) {
                if (!n->pin[pa]) b[pa + n->nv * c] += s * u[c];
                if (!n->pin[pb]) b[pb + n->nv * c] -= s * u[c];
            }
        }
    }
    if ((rc = es__spd_solve(ms->spd, n->spd, 3, b, n->nv)) != ES_OK) return rc;
    for (int64_t i = 0; i < n->nv; i++)
        for (int c = 0; c < 3; c++) n->x[3 * i + c] = b[i + n->nv * c];
    *t_blend += es__seconds() - t1;
    return ES_OK;
}

/* One hierarchy's solve (arguments checked by the caller). */
static es_status solve_one(es_multiscale *ms, const double *len, const double *alpha,
                           double *xyz)
{
    int64_t nv = es_mesh_nverts(ms->mesh);
    double t_leaf = 0, t_reg = 0, t_blend = 0, t0;
    es_status rc = ES_OK;
    /* children come after their parents: bottom up is backwards */
    for (int64_t i = ms->nnode - 1; i >= 0 && rc == ES_OK; i--) {
        ms_node *n = &ms->node[i];
        if (!n->nchild) {
            t0 = es__seconds();
            glue_leaf(ms, n, len, alpha, ms->iwork + ms->maxm * ms->maxm + 2 * ms->maxm);
            t_leaf += es__seconds() - t0;
        } else {
            rc = blend_inner(ms, n, len, &t_reg, &t_blend);
        }
    }
    if (rc != ES_OK) return rc;
    for (int64_t i = 0; i < 3 * nv; i++) xyz[i] = 0;
    for (int64_t i = 0; i < ms->node[0].nv; i++)
        for (int c = 0; c < 3; c++) xyz[3 * ms->node[0].verts[i] + c] = ms->node[0].x[3 * i + c];
    ms->info.t_leaves = t_leaf;
    ms->info.t_register = t_reg;
    ms->info.t_blend = t_blend;
    return ES_OK;
}

/* The method's own energy of positions x against its targets: the mean
 * squared relative length error over all edges plus the mean squared
 * dihedral error (wrapped to (-pi, pi]) over the interior ones. work: E. */
static double energy(const es_multiscale *ms, const double *len, const double *alpha,
                     const double *x, double *work)
{
    const es_mesh *m = ms->mesh;
    const int64_t *ed = es_mesh_edges(m);
    const uint8_t *eb = es_mesh_edge_on_boundary(m);
    int64_t ne = es_mesh_nedges(m), nin = 0;
    double el = 0, ea = 0;
    for (int64_t e = 0; e < ne; e++) {
        double d[3];
        es__v3_sub(x + 3 * ed[2 * e], x + 3 * ed[2 * e + 1], d);
        el += pow((sqrt(es__v3_dot(d, d)) - len[e]) / len[e], 2);
    }
    if (es_dihedral_angles(ms->ctx, m, x, work) != ES_OK) return INFINITY;
    for (int64_t e = 0; e < ne; e++)
        if (!eb[e]) ea += pow(remainder(work[e] - alpha[e], 2 * M_PI), 2), nin++;
    return el / (double)ne + (nin ? ea / (double)nin : 0);
}

es_status es_multiscale_solve(es_ctx *ctx, es_multiscale *ms, const double *len,
                              const double *alpha, double *xyz)
{
    const es_mesh *mesh;
    const uint8_t *eb;
    int64_t ne, nv;
    es_status rc;
    if (!ms || !len || !alpha || !xyz) ES_FAIL(ctx, ES_EINVAL, "multiscale: NULL argument");
    mesh = ms->mesh;
    ne = es_mesh_nedges(mesh);
    nv = es_mesh_nverts(mesh);
    eb = es_mesh_edge_on_boundary(mesh);
    for (int64_t e = 0; e < ne; e++) {
        if (!(len[e] > 0) || !isfinite(len[e]))
            ES_FAIL(ctx, ES_EINVAL, "multiscale: edge %lld has length %g (must be finite and "
                    "positive)", (long long)e, len[e]);
        if (!eb[e] && !isfinite(alpha[e]))
            ES_FAIL(ctx, ES_EINVAL, "multiscale: edge %lld has a dihedral that is not finite",
                    (long long)e);
    }
    if ((rc = solve_one(ms, len, alpha, xyz)) != ES_OK) return rc;
    ms->info.chosen = 0;
    if (ms->opts.tries > 1) {
        /* the other hierarchies: the result of least energy is kept */
        double *x = ms->scratch, *work = x + 3 * nv, best = energy(ms, len, alpha, xyz, work);
        double tl = ms->info.t_leaves, tr = ms->info.t_register, tb = ms->info.t_blend;
        ms->info.energy_max = best;
        for (int i = 0; i < ms->opts.tries - 1; i++) {
            es_multiscale *a = ms->alt[i];
            double en;
            if ((rc = solve_one(a, len, alpha, x)) != ES_OK) return rc;
            tl += a->info.t_leaves, tr += a->info.t_register, tb += a->info.t_blend;
            en = energy(ms, len, alpha, x, work);
            ms->info.energy_max = fmax(ms->info.energy_max, en);
            if (en < best) {
                best = en;
                ms->info.chosen = i + 1;
                memcpy(xyz, x, 3 * (size_t)nv * sizeof *x);
            }
        }
        ms->info.energy = best;
        ms->info.t_leaves = tl, ms->info.t_register = tr, ms->info.t_blend = tb;
    } else {
        ms->info.energy = ms->info.energy_max = energy(ms, len, alpha, xyz, ms->scratch + 3 * nv);
    }
    return ES_OK;
}

es_status es_multiscale_interp(es_ctx *ctx, es_multiscale *ms, int64_t nin,
                               const double *const *xyz, const double *w, const double *align_to,
                               double *out, es_interp_info *info)
{
    const es_mesh *mesh = ms ? ms->mesh : NULL;
    int64_t ne, nv;
    double *len = NULL, *alpha = NULL, rms;
    es_interp_info inf;
    es_status rc;
    if (!ms || !out) ES_FAIL(ctx, ES_EINVAL, "multiscale: NULL argument");
    ne = es_mesh_nedges(mesh);
    nv = es_mesh_nverts(mesh);
    len = es__alloc_array(ctx, ne, sizeof *len);
    alpha = es__alloc_array(ctx, ne, sizeof *alpha);
    if (!len || !alpha) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es_interp_targets(ctx, mesh, nin, xyz, w, len, alpha, &inf)) != ES_OK ||
        (rc = es_multiscale_solve(ctx, ms, len, alpha, out)) != ES_OK)
        goto done;
    rc = es_embed_align_parts(ctx, nv, out, align_to ? align_to : xyz[inf.reference], NULL,
                              es_mesh_vertex_component(mesh), &rms);
    if (rc == ES_OK && info) *info = inf;
done:
    es__free(ctx, len);
    es__free(ctx, alpha);
    return rc;
}
