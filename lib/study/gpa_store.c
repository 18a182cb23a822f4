/* lib/study/gpa_store.c — GPA of the vertex positions held in a store, results
 * written back under /analysis/gpa/<name>.
 *
 * The store keeps positions as 3 x V per row (xyz interleaved); GPA wants
 * k x d column-major configurations (es_procrustes.h), so each row is read
 * into a small buffer and transposed into its column of one k*d x n matrix:
 * the only large allocation, the size of the coordinates. Planar rows
 * (z = 0 everywhere, as ingested 2D landmarks are) are analysed in 2D.
 *
 * On the ranks of an MPI job each rank reads and aligns its contiguous
 * share of the rows (es_gpa_align_ranks); the aligned shares are gathered
 * on rank 0, which alone takes the PCA of the tangent coordinates (its
 * n x n Gram matrix needs every pair of rows) and writes the result.
 */
#include "core/core_private.h"
#include "parallel/parallel_private.h"
#include "edgespace/es_study.h"

#include <math.h>
#include <stdio.h>

/* Owned buffers; rho, scale (in size) and pct (in sdev) are views. */
typedef struct gpa_bufs {
    double *x, *row, *mean, *size, *rot, *cen, *sdev, *scores, *load;
    double *rho, *scale, *pct;
} gpa_bufs;

static void free_bufs(es_ctx *ctx, gpa_bufs *b)
{
    double *own[] = {b->x, b->row, b->mean, b->size, b->rot, b->cen, b->sdev, b->scores, b->load};
    for (size_t i = 0; i < sizeof own / sizeof own[0]; i++) es__free(ctx, own[i]);
}

void es_study_gpa_opts_init(es_study_gpa_opts *o)
{
    memset(o, 0, sizeof *o);
    o->nrows = -1;
    es_gpa_opts_init(&o->gpa);
}

es_status es_study_gpa(es_ctx *ctx, es_store *store, const es_study_gpa_opts *opts,
                       es_gpa_report *report)
{
    es_study_gpa_opts so;
    if (opts) so = *opts;
    else es_study_gpa_opts_init(&so);
    const char *name = so.name, *command = so.command;
    const int64_t *rows = so.rows, nrows = so.nrows;
    int64_t npc = so.npc;
    es_gpa_opts o = so.gpa;
    es_gpa_report rep;
    es_status rc = ES_OK;
    gpa_bufs b;
    int64_t n = nrows < 0 ? es_store_nrows(store) : nrows, k = es_store_nverts(store);
    int64_t lo, hi;
    const int ranks = es__par_size(ctx), writer = es__par_rank(ctx) == 0;
    memset(&b, 0, sizeof b);
    memset(&rep, 0, sizeof rep);
    if (writer && name && (!*name || strchr(name, '/')))
        rc = es__fail(ctx, ES_EINVAL, "gpa: result name '%s' is empty or has '/'", name);
    else if (writer && name) rc = es_store_result_check(ctx, store, "gpa", name);
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) return rc;
    if (n < 2) ES_FAIL(ctx, ES_EINVAL, "gpa: needs at least 2 rows, got %lld", (long long)n);
    if (k < 1) ES_FAIL(ctx, ES_EINVAL, "gpa: the store has no vertices");
    es__par_split(n, ranks, es__par_rank(ctx), &lo, &hi);

    /* positions -> 3D configurations (this rank's rows; rank 0's buffer
     * holds all n, its own first, for the gathering), and whether every z
     * is 0 (in every rank's rows) */
    int64_t kd3 = 3 * k;
    b.x = es__alloc_array(ctx, kd3 * (writer ? n : hi - lo), sizeof *b.x);
    b.row = es__alloc_array(ctx, kd3, sizeof *b.row);
    int64_t nonplanar = 0;
    rc = b.x && b.row ? ES_OK : ES_ENOMEM;
    for (int64_t j = lo; j < hi && rc == ES_OK; j++) {
        int64_t r = rows ? rows[j] : j;
        double *xj = b.x + (j - lo) * kd3;
        if (r < 0 || r >= es_store_nrows(store)) {
            rc = es__fail(ctx, ES_ERANGE, "gpa: row %lld out of range", (long long)r);
            break;
        }
        if ((rc = es_store_read_positions(ctx, store, r, b.row)) != ES_OK) break;
        es_procrustes_from_xyz(k, b.row, xj);
        for (int64_t v = 0; v < k && !nonplanar; v++) nonplanar = xj[2 * k + v] != 0.0;
        rc = es__progress(ctx, "reading positions", j - lo + 1, hi - lo);
    }
    if ((rc = es__par_agree(ctx, rc)) != ES_OK ||
        (rc = es__par_max_i64(ctx, &nonplanar, 1)) != ES_OK)
        goto done;
    int d = nonplanar ? 3 : 2;
    int64_t kd = k * d;
    if (!nonplanar)   /* drop the z-block: configuration j moves to j * 2k */
        for (int64_t j = 0; j < hi - lo; j++)
            memmove(b.x + j * kd, b.x + j * kd3, (size_t)kd * sizeof *b.x);
    es__free(ctx, b.row);
    b.row = NULL;

    b.mean = es__alloc_array(ctx, kd, sizeof *b.mean);
    b.size = es__alloc_array(ctx, 3 * n, sizeof *b.size);
    b.rot = es__alloc_array(ctx, (int64_t)d * d * n, sizeof *b.rot);
    b.cen = es__alloc_array(ctx, (int64_t)d * n, sizeof *b.cen);
    rc = b.mean && b.size && b.rot && b.cen ? ES_OK : ES_ENOMEM;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) goto done;
    b.rho = b.size + n;
    b.scale = b.rho + n;
    es_gpa_out out = {b.mean, b.size, b.rho, b.scale, b.rot, b.cen};
    es_mat xm = {b.x, kd, n, kd};
    rc = es_gpa_align_ranks(ctx, k, d, n, (es_mat){b.x, kd, hi - lo, kd}, &o, &out, &rep);
    if (rc != ES_OK && rc != ES_ENOCONV) goto done;
    if (rc == ES_ENOCONV) {
        es__warn(ctx, "%s", es_ctx_errmsg(ctx));
        rc = ES_OK;
    }
    if (ranks > 1) {   /* the aligned shares onto rank 0, its own in place */
        int64_t *counts = es__alloc_array(ctx, ranks, sizeof *counts), a, e;
        if ((rc = es__par_agree(ctx, counts ? ES_OK : ES_ENOMEM)) == ES_OK) {
            for (int q = 0; q < ranks; q++) {
                es__par_split(n, ranks, q, &a, &e);
                counts[q] = (e - a) * kd;
            }
            rc = es__par_gather(ctx, b.x, counts, b.x);
        }
        es__free(ctx, counts);
        if (rc != ES_OK || !writer) goto done;   /* the rest is rank 0's */
    }

    /* PCA of residual tangent coordinates; the tangent matrix is a second
     * copy only when it is small, otherwise the Gram route reads x itself
     * after subtracting the mean in place and adding it back */
    int64_t maxpc = n - 1 < kd ? n - 1 : kd;
    if (npc <= 0 || npc > maxpc) npc = maxpc < 10 ? maxpc : 10;
    b.sdev = es__alloc_array(ctx, 2 * npc, sizeof *b.sdev);
    b.scores = es__alloc_array(ctx, 2 * n * npc, sizeof *b.scores);
    b.load = es__alloc_array(ctx, kd * npc, sizeof *b.load);
    if (!b.sdev || !b.scores || !b.load) { rc = ES_ENOMEM; goto done; }
    b.pct = b.sdev + npc;
    if ((rc = es_gpa_tangent(ctx, k, d, xm, b.mean, ES_TANGENT_RESIDUAL, xm)) != ES_OK) goto done;
    rc = es_gpa_pca(ctx, xm, npc, b.sdev, b.pct, (es_mat){b.load, kd, npc, kd},
                    (es_mat){b.scores, n, npc, n});
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < kd; v++) b.x[j * kd + v] += b.mean[v];
    if (rc != ES_OK) goto done;
    double *sct = b.scores + n * npc;   /* npc x n: stored as n x npc */
    for (int64_t j = 0; j < n; j++)
        for (int64_t c = 0; c < npc; c++) sct[c + j * npc] = b.scores[j + c * n];

    if (!name) goto done;   /* nothing stored: the report alone */

    /* write the result */
    char params[256], path[1024], grp[512];
    snprintf(params, sizeof params, "scale=%d; allow_reflection=%d; tol=%g; max_iter=%lld",
             o.scale, o.allow_reflection, o.tol, (long long)o.max_iter);
    es_provenance prov = {command ? command : "es_study_gpa", rows, rows ? n : -1, params};
    if ((rc = es_store_result_begin(ctx, store, "gpa", name, &prov)) != ES_OK) goto done;
    snprintf(grp, sizeof grp, "gpa/%s", name);
#define PUT(call) do { if ((rc = (call)) != ES_OK) goto done; } while (0)
#define P(ds) (snprintf(path, sizeof path, "%s/%s", grp, ds), path)
    PUT(es_store_put_matrix(ctx, store, P("aligned"), xm));
    PUT(es_store_put_vector(ctx, store, P("mean"), b.mean, kd));
    PUT(es_store_put_vector(ctx, store, P("size"), b.size, n));
    PUT(es_store_put_vector(ctx, store, P("rho"), b.rho, n));
    PUT(es_store_put_vector(ctx, store, P("scale"), b.scale, n));
    PUT(es_store_put_matrix(ctx, store, P("rotation"), (es_mat){b.rot, (int64_t)d * d, n, (int64_t)d * d}));
    PUT(es_store_put_matrix(ctx, store, P("centroid"), (es_mat){b.cen, d, n, d}));
    PUT(es_store_put_vector(ctx, store, P("pc_sdev"), b.sdev, npc));
    PUT(es_store_put_vector(ctx, store, P("pc_percent"), b.pct, npc));
    PUT(es_store_put_matrix(ctx, store, P("pc_scores"), (es_mat){sct, npc, n, npc}));
    PUT(es_store_put_matrix(ctx, store, P("pc_loadings"), (es_mat){b.load, kd, npc, kd}));
    PUT(es_store_put_attr_int(ctx, store, grp, "dim", d));
    PUT(es_store_put_attr_int(ctx, store, grp, "k", k));
    PUT(es_store_put_attr_int(ctx, store, grp, "iterations", rep.iterations));
    PUT(es_store_put_attr_int(ctx, store, grp, "converged", rep.converged));
    PUT(es_store_put_attr_double(ctx, store, grp, "rot_change", rep.rot_change));
    PUT(es_store_put_attr_double(ctx, store, grp, "scale_change", rep.scale_change));
    PUT(es_store_put_attr_double(ctx, store, grp, "gss", rep.gss));
    PUT(es_store_put_attr_double(ctx, store, grp, "rmsrho", rep.rmsrho));
    PUT(es_store_put_attr_double(ctx, store, grp, "total_ss", rep.total_ss));
    PUT(es_store_put_attr(ctx, store, grp, "layout", "aligned rows: x-block, y-block[, z-block]"));
#undef PUT
#undef P
done:
    if (report) *report = rep;
    free_bufs(ctx, &b);
    return rc;
}
