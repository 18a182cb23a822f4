/* lib/morph/morph_report.c — the methods' names, and the quality of a mesh
 * made by any of them on the embedder's scale (es_embed_report), so that
 * the papers' methods and the project's compare on the same numbers: the
 * edge-length errors against the target, the target faces that break the
 * triangle inequality, the closure energy (edge-length-interpolation eq. 3)
 * of the output's dihedrals with the target's corner angles, and the
 * per-vertex values a stored embedding keeps.
 */
#include "morph/morph_pkg.h"
#include "edgespace/es_geom.h"

#include <math.h>

static const char *const names[] = {"edge-length", "multiscale", "shape-space", "data-driven",
                                    "paper",       "conformal",  "data-driven-el"};

const char *es_morph_method_name(es_morph_method m)
{
    return (int)m >= 0 && (size_t)m < sizeof names / sizeof names[0] ? names[m] : NULL;
}

es_status es_morph_method_from_name(es_ctx *ctx, const char *name, es_morph_method *out)
{
    char known[256] = "";
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        if (name && strcmp(name, names[i]) == 0) {
            *out = (es_morph_method)i;
            return ES_OK;
        }
        snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", i ? ", " : "",
                 names[i]);
    }
    ES_FAIL(ctx, ES_ENOTFOUND, "unknown interpolation method '%s' (known: %s)",
            name ? name : "", known);
}

es_status es_morph_report(es_ctx *ctx, const es_mesh *mesh, const double *target,
                          const double *xyz, double realized_rtol, es_embed_report *rep,
                          double *vclos, double *verr)
{
    int64_t ne, nv;
    const int64_t *ed;
    double *alpha = NULL, *vc = NULL, sum = 0, worst = -1;
    es_validity val;
    es_status rc;
    double t_total;
    if (!mesh || !target || !xyz || !rep) ES_FAIL(ctx, ES_EINVAL, "report: NULL argument");
    ne = es_mesh_nedges(mesh);
    nv = es_mesh_nverts(mesh);
    ed = es_mesh_edges(mesh);
    t_total = rep->t_total;
    memset(rep, 0, sizeof *rep);
    rep->t_total = t_total;
    rep->worst_edge = -1;
    for (int64_t e = 0; e < ne; e++) {
        double d[3], l, rel;
        if (!(target[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "report: target length of edge %lld is %g", (long long)e,
                    target[e]);
        es__v3_sub(xyz + 3 * ed[2 * e], xyz + 3 * ed[2 * e + 1], d);
        l = sqrt(es__v3_dot(d, d));
        rel = fabs(l - target[e]) / target[e];
        if (!(rel <= worst)) worst = rel, rep->worst_edge = e;
        sum += target[e];
    }
    rep->scale = sum;
    if ((rc = es_embed_length_error(ctx, mesh, xyz, target, 0, &rep->rms_ratio, &rep->max_rel,
                                    &rep->p99_rel)) != ES_OK ||
        (rc = es_lengths_check(ctx, mesh, target, 1e-12, &val)) != ES_OK)
        return rc;
    rep->n_bad_faces = val.n_bad_faces;
    rep->rms_ratio_linear = rep->rms_ratio;
    rep->realized = rep->max_rel <= realized_rtol && val.n_bad_faces == 0;
    alpha = es__alloc_array(ctx, ne, sizeof *alpha);
    vc = vclos ? vclos : es__alloc_array(ctx, nv, sizeof *vc);
    if (!alpha || !vc) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es_dihedral_angles(ctx, mesh, xyz, alpha)) != ES_OK ||
        (rc = es_embed_closure(ctx, mesh, target, alpha, &rep->closure_after, NULL, vc)) != ES_OK)
        goto done;
    rep->closure_before = rep->closure_stage1 = rep->closure_after;
    if (verr) {
        /* the mean relative error of the edges at each vertex */
        int64_t *deg = es__calloc(ctx, (size_t)nv, sizeof *deg);
        if (!deg) {
            rc = ES_ENOMEM;
            goto done;
        }
        for (int64_t v = 0; v < nv; v++) verr[v] = 0;
        for (int64_t e = 0; e < ne; e++) {
            double d[3], r;
            es__v3_sub(xyz + 3 * ed[2 * e], xyz + 3 * ed[2 * e + 1], d);
            r = fabs(sqrt(es__v3_dot(d, d)) - target[e]) / target[e];
            verr[ed[2 * e]] += r, verr[ed[2 * e + 1]] += r;
            deg[ed[2 * e]]++, deg[ed[2 * e + 1]]++;
        }
        for (int64_t v = 0; v < nv; v++)
            if (deg[v]) verr[v] /= (double)deg[v];
        es__free(ctx, deg);
    }
done:
    es__free(ctx, alpha);
    if (vc != vclos) es__free(ctx, vc);
    return rc;
}
