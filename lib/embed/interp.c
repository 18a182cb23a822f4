/* lib/embed/interp.c — interpolation and extrapolation of shapes in edge-length
 * space (edge-length-interpolation Sections 3-4): weighted means of
 * scale-normalized lengths, circular means of dihedrals for the start of
 * the embedding, sequences aligned frame to frame. See es_interp.h.
 */
#include "embed/embed_pkg.h"
#include "edgespace/es_interp.h"
#include "edgespace/es_geom.h"

#include <math.h>

es_status es_interp_targets(es_ctx *ctx, const es_mesh *mesh, int64_t nin,
                            const double *const *xyz, const double *w, double *len,
                            double *alpha, es_interp_info *info)
{
    int64_t ne, nv, r = 0;
    double wsum = 0, scale = 0, *lk = NULL, *ak = NULL, *ar = NULL;
    es_interp_info inf = {0, 0, 0};
    es_status rc = ES_OK;
    if (!mesh || !xyz || !w) ES_FAIL(ctx, ES_EINVAL, "interp: NULL argument");
    if (nin < 1) ES_FAIL(ctx, ES_EINVAL, "interp: need at least one input (got %lld)",
                         (long long)nin);
    ne = es_mesh_nedges(mesh);
    nv = es_mesh_nverts(mesh);
    for (int64_t k = 0; k < nin; k++) {
        if (!isfinite(w[k])) ES_FAIL(ctx, ES_EINVAL, "interp: weight %lld is not finite",
                                     (long long)k);
        if (!xyz[k]) ES_FAIL(ctx, ES_EINVAL, "interp: input %lld is NULL", (long long)k);
        wsum += w[k];
        if (fabs(w[k]) > fabs(w[r]) || (fabs(w[k]) == fabs(w[r]) && w[k] > w[r])) r = k;
    }
    if (!(fabs(wsum) > 1e-12))
        ES_FAIL(ctx, ES_EINVAL, "interp: weights sum to %g; they must sum to a non-zero "
                "value (normally 1)", wsum);
    inf.reference = r;
    lk = es__alloc_array(ctx, ne, sizeof *lk);
    ak = es__alloc_array(ctx, ne, sizeof *ak);
    ar = es__alloc_array(ctx, ne, sizeof *ar);
    if (!lk || !ak || !ar) {
        rc = ES_ENOMEM;
        goto done;
    }
    if (len)
        for (int64_t e = 0; e < ne; e++) len[e] = 0;
    if (alpha && (rc = es_dihedral_angles(ctx, mesh, xyz[r], ar)) != ES_OK) goto done;
    if (alpha)
        for (int64_t e = 0; e < ne; e++) alpha[e] = ar[e];
    for (int64_t k = 0; k < nin; k++) {
        double s = 0;
        for (int64_t i = 0; i < 3 * nv; i++)
            if (!isfinite(xyz[k][i])) {
                rc = es__fail(ctx, ES_EINVAL, "interp: input %lld: vertex %lld is not finite",
                              (long long)k, (long long)(i / 3));
                goto done;
            }
        if ((rc = es_edge_lengths(ctx, mesh, xyz[k], lk)) != ES_OK) goto done;
        for (int64_t e = 0; e < ne; e++) {
            if (!(lk[e] > 0)) {
                rc = es__fail(ctx, ES_EINVAL, "interp: input %lld: edge %lld has length 0",
                              (long long)k, (long long)e);
                goto done;
            }
            s += lk[e];
        }
        scale += w[k] * s;
        if (len)
            for (int64_t e = 0; e < ne; e++) len[e] += w[k] * lk[e] / s;
        if (alpha && k != r) {
            if ((rc = es_dihedral_angles(ctx, mesh, xyz[k], ak)) != ES_OK) goto done;
            for (int64_t e = 0; e < ne; e++) {
                double d = ak[e] - ar[e];
                if (fabs(d) > M_PI) inf.n_wrapped++;
                alpha[e] += w[k] * remainder(d, 2.0 * M_PI);
            }
        }
    }
    if (alpha)
        for (int64_t e = 0; e < ne; e++) alpha[e] = remainder(alpha[e], 2.0 * M_PI);
    scale /= wsum;
    if (!(scale > 0)) {
        rc = es__fail(ctx, ES_EINVAL, "interp: the weighted scale is %g (not positive)", scale);
        goto done;
    }
    if (len)
        for (int64_t e = 0; e < ne; e++) {
            len[e] /= wsum;
            /* past the positive orthant (extrapolated too far) no mesh
             * realizes the target: refuse rather than invent a length */
            if (!(len[e] > 0)) {
                rc = es__fail(ctx, ES_EINVAL, "interp: edge %lld has length %g at these "
                              "weights: outside edge-length space (extrapolated too far)",
                              (long long)e, len[e] * scale);
                goto done;
            }
            len[e] *= scale;
        }
    inf.scale = scale;
    if (info) *info = inf;
done:
    es__free(ctx, lk);
    es__free(ctx, ak);
    es__free(ctx, ar);
    return rc;
}

/* The refinement carries the crease guard (crease_guard.c): interpolated
 * lengths are no mesh's, and realized without it they fold across the
 * parts where the inputs differ most (notebook 07's Fig. 4 cats: 4-13 % of
 * the edges bent past every input). */
es_status es_interp_embed(es_ctx *ctx, es_embedder *emb, int64_t nin, const double *const *xyz,
                          const double *w, const double *align_to, const es_embed_opts *opts,
                          double *out, es_embed_report *report, es_interp_info *info)
{
    const es_mesh *mesh = es_embedder_mesh(emb);
    int64_t ne = es_mesh_nedges(mesh);
    double *len, *alpha;
    es_embed_opts dflt;
    es_interp_info inf;
    es_status rc;
    if (!opts) {
        es_embed_opts_init(&dflt);
        opts = &dflt;
    }
    len = es__alloc_array(ctx, ne, sizeof *len);
    alpha = es__alloc_array(ctx, ne, sizeof *alpha);
    if (!len || !alpha) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es_interp_targets(ctx, mesh, nin, xyz, w, len, alpha, &inf)) != ES_OK) goto done;
    const double *ref = align_to ? align_to : xyz[inf.reference];
    if (opts->crease_mu > 0 && opts->crease_margin >= 0) {
        es__bend_prior guard;
        if ((rc = es__crease_guard_inputs(emb, nin, xyz, w, alpha, len, opts, &guard)) != ES_OK) {
            rc = es__fail(ctx, rc, "%s", es_ctx_errmsg(emb->ctx));
            goto done;
        }
        rc = es__embed_solve_bend(ctx, emb, len, 0, alpha, ref, NULL, &guard, opts, out, report);
    } else {
        rc = es_embed_solve(ctx, emb, len, 0, alpha, ref, opts, out, report);
    }
    if (rc == ES_OK && info) *info = inf;
done:
    es__free(ctx, len);
    es__free(ctx, alpha);
    return rc;
}

es_status es_interp_sequence(es_ctx *ctx, es_embedder *emb, const double *a, const double *b,
                             double t0, double t1, int64_t nsteps, const es_embed_opts *opts,
                             double *out, es_embed_report *reports)
{
    int64_t nv = es_mesh_nverts(es_embedder_mesh(emb));
    const double *in[2] = {a, b};
    if (nsteps < 1) ES_FAIL(ctx, ES_EINVAL, "interp: need at least one step");
    for (int64_t i = 0; i < nsteps; i++) {
        double t = nsteps == 1 ? t0 : t0 + (t1 - t0) * (double)i / (double)(nsteps - 1);
        double w[2] = {1.0 - t, t};
        es_status rc = es_interp_embed(ctx, emb, 2, in, w, i ? out + 3 * nv * (i - 1) : a, opts,
                                       out + 3 * nv * i, reports ? reports + i : NULL, NULL);
        if (rc != ES_OK) return rc;
        es__progress(ctx, "interp: sequence", i + 1, nsteps);
    }
    return ES_OK;
}
