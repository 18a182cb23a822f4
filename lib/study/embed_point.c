/* lib/study/embed_point.c — one point of a store's space embedded as a
 * mesh: the point resolved with its row weights, the prior those weights
 * give (or an explicit start: the nearest row, a named row, the circular
 * mean of rows' dihedrals, a given mesh), the solve, the mesh and residual
 * files, and the stored result with its provenance. */
#include "study/study_pkg.h"
#include "edgespace/es_io.h"
#include "meshio/meshio_private.h"
#include "store/store_private.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <unistd.h>

void es_study_embed_opts_init(es_study_embed_opts *o)
{
    memset(o, 0, sizeof *o);
    o->init = "prior";
    o->cache = 1;
    es_embed_opts_init(&o->embed);
}

/* The start: rows whose positions (and, for "mean", dihedrals) start the
 * solve, or a mesh file's positions. *init_row >= 0 names the row whose
 * positions start it; *sel and *nsel the rows of a "mean" start. */
static es_status choose_start(es_ctx *ctx, es_store *s, const es_mesh *mesh, const char *init,
                              const double *target, double *init_xyz, double *alpha,
                              int64_t *init_row, int64_t **sel, int64_t *nsel, char *desc,
                              size_t ndesc)
{
    es_status rc;
    *init_row = -1;
    if (!strcmp(init, "nearest")) {
        double d;
        if ((rc = es_study_nearest_row(ctx, s, target, NULL, 0, init_row, &d)) != ES_OK)
            return rc;
        snprintf(desc, ndesc, "nearest row %s (edge-length distance %.3g)",
                 es_store_row_id(s, *init_row), d);
    } else if (!strncmp(init, "row:", 4)) {
        if ((*init_row = es_store_find_row(s, init + 4)) < 0) {
            char hint[400];
            es_store_value_hint(s, -1, init + 4, hint, sizeof hint);
            ES_FAIL(ctx, ES_ENOTFOUND, "no row '%s' in the store%s", init + 4, hint);
        }
        snprintf(desc, ndesc, "row %s", init + 4);
    } else if (!strncmp(init, "mean", 4) && (init[4] == 0 || init[4] == ':' || init[4] == '[')) {
        /* mean[FILTER] as in the point syntax, or the older mean:FILTER */
        char filter[1024];
        size_t n = strlen(init);
        if (init[4] == '[' && init[n - 1] != ']')
            ES_FAIL(ctx, ES_EINVAL, "--init %s: expected mean[FILTER] with the closing ']'",
                    init);
        if (n >= sizeof filter) ES_FAIL(ctx, ES_EINVAL, "--init: the filter is too long");
        snprintf(filter, sizeof filter, "%.*s", init[4] == '[' ? (int)(n - 6) : (int)sizeof filter,
                 init[4] ? init + 5 : "");
        if ((rc = es_store_select(ctx, s, init[4] ? filter : NULL, sel, nsel)) != ES_OK)
            return rc;
        if (*nsel == 0) ES_FAIL(ctx, ES_ENOTFOUND, "--init %s selects no rows", init);
        if ((rc = es_study_mean_dihedrals(ctx, s, mesh, *sel, *nsel, alpha)) != ES_OK)
            return rc;
        *init_row = (*sel)[0];
        snprintf(desc, ndesc, "circular mean of dihedrals of %lld rows (%s)", (long long)*nsel,
                 init);
    } else if (!strncmp(init, "mesh:", 5)) {
        if ((rc = es_meshio_read_positions(ctx, mesh, init + 5, init_xyz)) != ES_OK) return rc;
        snprintf(desc, ndesc, "mesh %s", init + 5);
    } else {
        ES_FAIL(ctx, ES_EINVAL, "--init wants prior, nearest, row:ID, mean, mean[FILTER] or "
                "mesh:FILE (got '%s')", init);
    }
    if (*init_row >= 0) return es_store_read_positions(ctx, s, *init_row, init_xyz);
    return ES_OK;
}

/* Per vertex of the output, its vertex-figure closure energy, the mean
 * relative error of its edges and (with a prior) its distance from the
 * prior's realization as a fraction of the bounding-box diagonal; the
 * closure comes first because render --scalars colours by the first
 * column. */
static es_status write_residuals(es_ctx *ctx, const char *path, const es_embedder *emb,
                                 int64_t nv, es__file_set *set)
{
    const double *closure = es_embedder_vertex_closure(emb);
    const double *edge_error = es_embedder_vertex_edge_error(emb);
    const double *dev = es_embedder_vertex_deviation(emb);
    es__table_out t;
    es_status rc = es__table_begin(ctx, path, &t);
    if (rc != ES_OK) return rc;
    t.set = set;
    fputs(dev ? "closure,edge_error,deviation\n" : "closure,edge_error\n", t.f);
    for (int64_t v = 0; v < nv; v++) {
        fprintf(t.f, "%.17g,%.17g", closure[v], edge_error[v]);
        if (dev) fprintf(t.f, ",%.17g", dev[v]);
        fputc('\n', t.f);
    }
    return es__table_end(ctx, &t, ES_OK);
}

/* The published pipeline from dihedrals alpha (NULL: those of init_xyz),
 * aligned to init_xyz; the start's description says so. */
static es_status solve_paper(es_ctx *ctx, es_embedder *emb, const es_study_embed_opts *o,
                             const double *target, double scale, const double *alpha,
                             const double *init_xyz, double *xyz, es_study_embed_result *res)
{
    es_embed_paper_opts po;
    size_t n = strlen(res->init);
    es_embed_paper_opts_init(&po);
    po.embed = o->embed;
    snprintf(res->init + n, sizeof res->init - n, "; published pipeline (L-BFGS, stages 2-3)");
    return es_embed_paper_solve(ctx, emb, target, scale, alpha, init_xyz, &po, xyz,
                                &res->report);
}

es_status es_study_embed(es_ctx *ctx, es_store *s, const es_study_embed_opts *o, double *xyz_out,
                         es_study_embed_result *res)
{
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    es_study_embedder *se = NULL;
    double *target = NULL, *xyz = NULL, *init_xyz = NULL, *alpha = NULL, *sd = NULL, *w = NULL;
    double own;
    int64_t init_row = -1, *sel = NULL, nsel = 0, ne, nv, n = es_store_nrows(s);
    const int prior = !o || !o->init || !strcmp(o->init, "prior");
    es__file_set files = {0};   /* the mesh and residuals, renamed into place together */
    es_status rc;
    memset(res, 0, sizeof *res);
    if (!o || !o->point) ES_FAIL(ctx, ES_EINVAL, "embed: no point given");
    if (o->session && es_study_embedder_store(o->session) != s)
        ES_FAIL(ctx, ES_EINVAL, "embed: the session given is of another store");
    if (o->name && (rc = es_store_result_check(ctx, s, "embed", o->name)) != ES_OK) return rc;
    if ((rc = es_store_mesh(ctx, s, &mesh)) != ES_OK) return rc;
    ne = es_mesh_nedges(mesh);
    nv = es_mesh_nverts(mesh);
    target = es__alloc_array(ctx, ne, sizeof *target);
    xyz = xyz_out ? xyz_out : es__alloc_array(ctx, 3 * nv, sizeof *xyz);
    init_xyz = es__alloc_array(ctx, 3 * nv, sizeof *init_xyz);
    alpha = es__alloc_array(ctx, ne, sizeof *alpha);
    sd = es__alloc_array(ctx, ne, sizeof *sd);
    w = es__alloc_array(ctx, n > 0 ? n : 1, sizeof *w);
    if (!target || !xyz || !init_xyz || !alpha || !sd || !w) {
        rc = ES_ENOMEM;
        goto done;
    }
    /* the target: at the point's own scale unless opts->scale gives one */
    if ((rc = es_study_point_weights(ctx, s, o->point, o->pca_name, target, &own,
                                     prior ? w : NULL)) != ES_OK)
        goto done;
    res->scale = o->scale > 0 ? o->scale : own;
    if (prior) {
        /* the session: the embedder and the rows for priors, from the cache
         * beside the store when it is current (a fresh process skips their
         * making) */
        if (o->session) se = o->session;
        else if ((rc = es_study_embedder_open(ctx, s, o->cache, &se)) != ES_OK) goto done;
        if (o->paper) {
            /* the published pipeline from the prior's dihedrals, in its frame */
            snprintf(res->init, sizeof res->init, "prior's dihedrals and frame");
            if ((rc = es_study_prior(ctx, es_study_embedder_rows(se), w, init_xyz, alpha,
                                     sd)) != ES_OK ||
                (rc = solve_paper(ctx, es_study_embedder_embedder(se), o, target, res->scale,
                                  alpha, init_xyz, xyz, res)) != ES_OK)
                goto done;
        } else if ((rc = es_study_embedder_solve(ctx, se, target, res->scale, w, &o->embed,
                                                 o->session && o->warm,
                                                 es__study_point_is_one_mesh(ctx, o->point),
                                                 xyz, res)) != ES_OK)
            goto done;
        emb = es_study_embedder_embedder(se);
        /* provenance: the rows the prior drew on */
        for (int64_t i = 0; i < n; i++) nsel += w[i] != 0;
        if (nsel && !(sel = es__alloc_array(ctx, nsel, sizeof *sel))) {
            rc = ES_ENOMEM;
            goto done;
        }
        for (int64_t i = 0, j = 0; i < n; i++)
            if (w[i] != 0) sel[j++] = i;
    } else if ((rc = choose_start(ctx, s, mesh, o->init, target, init_xyz, alpha, &init_row,
                                  &sel, &nsel, res->init, sizeof res->init)) != ES_OK ||
               (rc = es_embedder_new(ctx, mesh, &emb)) != ES_OK ||
               (rc = o->paper ? solve_paper(ctx, emb, o, target, res->scale, sel ? alpha : NULL,
                                            init_xyz, xyz, res)
                              : es_embed_solve(ctx, emb, target, res->scale, sel ? alpha : NULL,
                                               init_xyz, &o->embed, xyz, &res->report)) != ES_OK) {
        goto done;
    }
    /* the files are staged beside their targets; with a stored result they
     * are renamed into place by the caller's commit of the store
     * (es__store_publish_with): a failed store write leaves no mesh behind,
     * and an old file as it was */
    if ((o->output && (rc = es__mesh_write_staged(ctx, o->output,
                                                  es_meshio_format_from_path(o->output), mesh,
                                                  xyz, &files)) != ES_OK) ||
        (o->residuals && (rc = write_residuals(ctx, o->residuals, emb, nv, &files)) != ES_OK))
        goto done;
    if (o->name) {
        /* the rows whose positions started the embedding (none for a mesh:
         * rows non-NULL with 0, as NULL would record every row) */
        char params[1024];
        es_provenance prov = {o->command ? o->command : "es_study_embed",
                              sel ? sel : &init_row, sel ? nsel : init_row >= 0 ? 1 : 0,
                              params};
        snprintf(params, sizeof params, "point=%s; scale=%.17g", o->point, res->scale);
        if ((rc = es_study_store_embedding(ctx, s, o->name, &prov, emb, target, xyz,
                                           &res->report, res->init)) != ES_OK)
            goto done;
        rc = es__store_publish_with(ctx, s, &files);
    } else {
        rc = es__file_set_commit(ctx, &files);   /* nothing stored: at once */
    }
done:
    es__file_set_abort(ctx, &files);   /* what is left of it: nothing once handed on */
    if (se) emb = NULL;   /* the session's */
    es_embedder_free(emb);
    if (se != o->session) es_study_embedder_free(se);
    es_mesh_free(mesh);
    es__free(ctx, sel);
    es__free(ctx, target);
    if (xyz != xyz_out) es__free(ctx, xyz);
    es__free(ctx, init_xyz);
    es__free(ctx, alpha);
    es__free(ctx, sd);
    es__free(ctx, w);
    return rc;
}
