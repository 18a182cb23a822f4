/* lib/study/prior.c — a store's rows made ready to serve as the embedding's
 * prior (es_embed.h): every row's positions aligned by GPA without scaling
 * into one frame, and every row's dihedrals.
 *
 * The frame: partial GPA (rotations and translations only, so each row
 * keeps its size and a weighted sum of rows has the size its weights
 * imply) of all rows, then one rigid motion taking the Procrustes mean onto
 * row 0, so that outputs come out where the store's first shape is (a face
 * upright as ingested) and the outputs of nearby points overlay directly.
 * Built once per command and shared by all its points: N x (3V + E)
 * doubles. */
#include "study/study_pkg.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_procrustes.h"

#include <math.h>
#include <sys/mman.h>

struct es_study_rows {
    es_ctx *ctx;
    int64_t n, nv, ne;
    double *aligned;        /* 3V x n: row i's positions in the frame */
    double *alpha;          /* E x n: row i's dihedrals */
    const double **pa, **pd;   /* column pointers for es_embed_prior_from_rows */
    void *map;              /* when aligned and alpha lie in a mapped cache file */
    size_t map_len;
};

void es_study_rows_free(es_study_rows *r)
{
    if (!r) return;
    if (r->map) {
        munmap(r->map, r->map_len);
    } else {
        es__free(r->ctx, r->aligned);
        es__free(r->ctx, r->alpha);
    }
    es__free(r->ctx, (void *)r->pa);
    es__free(r->ctx, (void *)r->pd);
    es__free(r->ctx, r);
}

/* GPA of the rows (configurations k x 3, column j = row j) in place, then
 * the one rigid motion that takes the Procrustes mean onto row 0 (orig0,
 * interleaved), applied to every row, back in the interleaved layout. */
static es_status align_rows(es_ctx *ctx, es_study_rows *r, const double *orig0)
{
    const int64_t k = r->nv, n = r->n;
    double *cfg = es__alloc_array(ctx, 3 * k * n, sizeof *cfg);
    double *mean = es__alloc_array(ctx, 3 * k, sizeof *mean);
    double *target = es__alloc_array(ctx, 3 * k, sizeof *target);
    double rot[9], c0[3] = {0, 0, 0};
    es_gpa_opts o;
    es_status rc = ES_OK;
    if (!cfg || !mean || !target) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t j = 0; j < n; j++)
        es_procrustes_from_xyz(k, r->aligned + 3 * k * j, cfg + 3 * k * j);
    es_gpa_opts_init(&o);
    o.scale = 0;
    es_gpa_out out = {mean, NULL, NULL, NULL, NULL, NULL};
    rc = es_gpa_align(ctx, k, 3, (es_mat){cfg, 3 * k, n, 3 * k}, &o, &out, NULL);
    if (rc != ES_OK && rc != ES_ENOCONV) goto done;
    /* (a GPA short of 1e-10 after its iterations is still a frame) */
    es_procrustes_from_xyz(k, orig0, target);
    for (int64_t i = 0; i < k; i++)
        for (int d = 0; d < 3; d++) c0[d] += orig0[3 * i + d] / (double)k;
    /* the GPA output is centred, so the motion is y R + c0 */
    if ((rc = es_procrustes_opa(ctx, k, 3, target, mean, 0, 0, NULL, rot, NULL, NULL)) != ES_OK)
        goto done;
    for (int64_t j = 0; j < n; j++) {
        const double *y = cfg + 3 * k * j;
        double *row = r->aligned + 3 * k * j;
        for (int64_t i = 0; i < k; i++)
            for (int c = 0; c < 3; c++)
                row[3 * i + c] = y[i] * rot[0 + 3 * c] + y[k + i] * rot[1 + 3 * c] +
                                 y[2 * k + i] * rot[2 + 3 * c] + c0[c];
    }
done:
    es__free(ctx, cfg);
    es__free(ctx, mean);
    es__free(ctx, target);
    return rc;
}

es_status es__study_rows_check_memory(es_ctx *ctx, const es_mesh *mesh, int64_t n)
{
    /* each row's aligned positions and dihedrals */
    char what[64];
    uint64_t per = 8 * (3 * (uint64_t)es_mesh_nverts(mesh) + (uint64_t)es_mesh_nedges(mesh));
    uint64_t bytes;
    if (__builtin_mul_overflow((uint64_t)n, per, &bytes)) bytes = UINT64_MAX;
    snprintf(what, sizeof what, " for the prior's %llu rows", (unsigned long long)n);
    return es_embed_check_memory(ctx, mesh, bytes, what);
}

/* The rows' struct and column pointers over arrays aligned and alpha,
 * owned by the rows from here on (freed, or unmapped when map is set). */
es_status es__study_rows_mapped(es_ctx *ctx, int64_t n, int64_t nv, int64_t ne, void *map,
                                size_t map_len, double *aligned, double *alpha,
                                es_study_rows **out)
{
    es_study_rows *r;
    *out = NULL;
    if (!(r = es__calloc(ctx, 1, sizeof *r))) {
        if (map) munmap(map, map_len);
        else es__free(ctx, aligned), es__free(ctx, alpha);
        return ES_ENOMEM;
    }
    r->ctx = ctx;
    r->n = n;
    r->nv = nv;
    r->ne = ne;
    r->aligned = aligned;
    r->alpha = alpha;
    r->map = map;
    r->map_len = map_len;
    r->pa = es__alloc_array(ctx, n, sizeof *r->pa);
    r->pd = es__alloc_array(ctx, n, sizeof *r->pd);
    if (!r->aligned || !r->alpha || !r->pa || !r->pd) {
        es_study_rows_free(r);
        return ES_ENOMEM;
    }
    for (int64_t j = 0; j < n; j++) {
        r->pa[j] = r->aligned + 3 * nv * j;
        r->pd[j] = r->alpha + ne * j;
    }
    *out = r;
    return ES_OK;
}

es_status es__study_rows_new(es_ctx *ctx, int64_t n, int64_t nv, int64_t ne, es_study_rows **out,
                             double **aligned, double **alpha)
{
    es_status rc = es__study_rows_mapped(ctx, n, nv, ne, NULL, 0,
                                         es__alloc_array(ctx, 3 * nv * n, sizeof **aligned),
                                         es__alloc_array(ctx, ne * n, sizeof **alpha), out);
    if (rc != ES_OK) return rc;
    *aligned = (*out)->aligned;
    *alpha = (*out)->alpha;
    return ES_OK;
}

void es__study_rows_arrays(const es_study_rows *r, const double **aligned, const double **alpha)
{
    *aligned = r->aligned;
    *alpha = r->alpha;
}

es_status es_study_rows_load(es_ctx *ctx, es_store *store, const es_mesh *mesh,
                             es_study_rows **out)
{
    es_study_rows *r = NULL;
    double *aligned, *alpha, *orig0 = NULL;
    es_status rc;
    *out = NULL;
    if (!mesh) ES_FAIL(ctx, ES_EINVAL, "prior: the store has no faces");
    if (es_store_nrows(store) < 1) ES_FAIL(ctx, ES_EINVAL, "prior: the store has no rows");
    if ((rc = es__study_rows_check_memory(ctx, mesh, es_store_nrows(store))) != ES_OK) return rc;
    if ((rc = es__study_rows_new(ctx, es_store_nrows(store), es_mesh_nverts(mesh),
                                 es_mesh_nedges(mesh), &r, &aligned, &alpha)) != ES_OK)
        return rc;
    if (!(orig0 = es__alloc_array(ctx, 3 * r->nv, sizeof *orig0))) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t j = 0; j < r->n && rc == ES_OK; j++) {
        double *x = aligned + 3 * r->nv * j;
        if ((rc = es_store_read_positions(ctx, store, j, x)) == ES_OK)
            rc = es_dihedral_angles(ctx, mesh, x, alpha + r->ne * j);
        if (rc == ES_OK) rc = es__progress(ctx, "prior: rows", j + 1, r->n);
    }
    if (rc == ES_OK) memcpy(orig0, r->aligned, (size_t)(3 * r->nv) * sizeof *orig0);
    if (rc == ES_OK && r->n > 1) rc = align_rows(ctx, r, orig0);
done:
    es__free(ctx, orig0);
    if (rc != ES_OK) {
        es_study_rows_free(r);
        return rc;
    }
    *out = r;
    return ES_OK;
}

es_status es_study_prior(es_ctx *ctx, const es_study_rows *r, const double *w, double *xyz,
                         double *alpha, double *sd)
{
    if (!r || !w) ES_FAIL(ctx, ES_EINVAL, "prior: no rows or weights");
    return es_embed_prior_from_rows(ctx, r->nv, r->ne, r->n, r->pa, r->pd, w, xyz, alpha, sd);
}

es_status es_study_prior_span(es_ctx *ctx, const es_study_rows *r, const double *w, double *lo,
                              double *hi)
{
    int any = 0;
    if (!r || !w || !lo || !hi) ES_FAIL(ctx, ES_EINVAL, "prior: no rows, weights or output");
    for (int64_t j = 0; j < r->n; j++) {
        if (w[j] == 0) continue;
        for (int64_t e = 0; e < r->ne; e++) {
            double a = r->pd[j][e];
            lo[e] = any ? fmin(lo[e], a) : a;
            hi[e] = any ? fmax(hi[e], a) : a;
        }
        any = 1;
    }
    if (!any) ES_FAIL(ctx, ES_EINVAL, "prior: every row's weight is 0");
    return ES_OK;
}
