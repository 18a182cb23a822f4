/* lib/stats/pca_strip.c — the Gram route on data held in memory, edges at a
 * time: a matrix source's own columns (es_source_matrix), or the strip of
 * edges one rank of an MPI job holds for every row (pca_parallel.c).
 *
 * G = Y^T Y (Y = X - x_0 1^T, shifted by the first row as in pca.c) is a sum
 * over edges, so it is accumulated over chunks of edges of all N rows: each
 * chunk is copied once, shifted, into a buffer of about 8 MB that is
 * reused (no tile of the whole data is copied, no fresh memory is touched
 * per pass) and added by one dsyrk whose inner dimension, the chunk's
 * edges, keeps it compute-bound. The components (X - mean 1^T) V are one
 * product with the data in place (chunk copies only for a selection of
 * columns). The data are read twice in all; numpy's Gram route on the same
 * matrix reads them for the mean, copies them to centre them and reads the
 * copy twice (tools/bench/bench_pca.c).
 */
#include "stats/stats_pkg.h"
#include "parallel/parallel_private.h"

#include <cblas.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

/* The chunk buffer: about this many bytes, and at least MIN_CHUNK edges so
 * that dsyrk's update of G (N^2 reads and writes a chunk) stays small
 * against its N^2 x chunk multiply-adds. */
#define CHUNK_BYTES ((int64_t)8 << 20)
#define MIN_CHUNK 256

static int64_t chunk_edges(const es__strip *s)
{
    int64_t c = CHUNK_BYTES / (8 * (s->nrows > 0 ? s->nrows : 1));
    if (c < MIN_CHUNK) c = MIN_CHUNK;
    if (c > s->nedges) c = s->nedges;
    return c < 1 ? 1 : c;
}

static const double *column(const es__strip *s, int64_t j)
{
    return s->data + (s->cols ? s->cols[j] : j) * s->ld;
}

/* Y[e, j] = X[e0 + e, col j] - shift[e0 + e] for e < c, into y (c x N), and
 * (ysum not NULL) ysum[e0 + e] += sum_j Y[e, j]: one vectorized pass. */
static void copy_chunk(const es__strip *s, int64_t e0, int64_t c, const double *shift,
                       double *y, double *ysum)
{
    const double *sh = shift + e0;
    for (int64_t j = 0; j < s->nrows; j++) {
        const double *x = column(s, j) + e0;
        double *yj = y + j * c;
        if (ysum) {
            double *ys = ysum + e0;
            for (int64_t e = 0; e < c; e++) {
                double v = x[e] - sh[e];
                yj[e] = v;
                ys[e] += v;
            }
        } else {
            for (int64_t e = 0; e < c; e++) yj[e] = x[e] - sh[e];
        }
    }
}

/* A value that is not finite makes its edge's sum not finite: only then
 * are the chunk's values searched, to name the row and edge as a source
 * read would. */
static es_status check_chunk(es_ctx *ctx, const es__strip *s, int64_t e0, int64_t c,
                             const double *ysum)
{
    for (int64_t e = 0; e < c; e++) {
        if (isfinite(ysum[e0 + e])) continue;
        for (int64_t j = 0; j < s->nrows; j++) {
            double v = column(s, j)[e0 + e];
            if (!isfinite(v))
                ES_FAIL(ctx, ES_ENUMERIC, "source: row %lld, edge %lld: length is %g",
                        (long long)(s->row0 + j), (long long)(s->edge0 + e0 + e), v);
        }
        ES_FAIL(ctx, ES_ENUMERIC, "pca: the lengths of edge %lld overflow",
                (long long)(s->edge0 + e0 + e));
    }
    return ES_OK;
}

es_status es__strip_gram(es_ctx *ctx, const es__strip *s, const double *shift, double *G,
                         double *ysum)
{
    const int64_t N = s->nrows, c = chunk_edges(s);
    int nn;
    es_status rc = es__lapack_int(ctx, N, &nn);
    if (rc != ES_OK) return rc;
    double *y = es__alloc_array(ctx, c * N, sizeof *y);
    if (!y) return ES_ENOMEM;
    for (int64_t e0 = 0; e0 < s->nedges && rc == ES_OK; e0 += c) {
        int64_t k = s->nedges - e0 < c ? s->nedges - e0 : c;
        copy_chunk(s, e0, k, shift, y, ysum);
        if ((rc = check_chunk(ctx, s, e0, k, ysum)) != ES_OK) break;
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, nn, (int)k, 1.0, y, (int)k, 1.0, G,
                    nn);
        rc = es__progress(ctx, "pca: Gram matrix", e0 + k, s->nedges);   /* agreed after */
    }
    es__free(ctx, y);
    return rc;
}

es_status es__strip_project(es_ctx *ctx, const es__strip *s, const double *centre,
                            const double *V, int64_t r, double *U, int64_t ldu)
{
    const int64_t N = s->nrows, c = chunk_edges(s);
    int nn, ldx;
    es_status rc = es__lapack_int(ctx, N, &nn);
    if (rc != ES_OK || r < 1 || s->nedges < 1) return rc;
    if (!s->cols && es__lapack_int(ctx, s->ld, &ldx) == ES_OK && s->nedges <= INT32_MAX) {
        /* the columns are the data's own: U = X V - centre (1^T V), one
         * product read in place. V's columns are orthogonal to 1 (centred
         * eigenvectors), so the correction is tiny, and X V loses about
         * eps / (the lengths' relative variation) to cancellation: 1e-14 for
         * variation of 1 %, against a copy of the whole data saved */
        double *csum = es__alloc_array(ctx, r, sizeof *csum);
        if (!csum) return ES_ENOMEM;
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)s->nedges, (int)r, nn, 1.0,
                    s->data, ldx, V, nn, 0.0, U, (int)ldu);
        for (int64_t k = 0; k < r; k++) {
            double acc = 0;
            for (int64_t j = 0; j < N; j++) acc += V[j + k * N];
            csum[k] = acc;
        }
        for (int64_t k = 0; k < r; k++)
            for (int64_t e = 0; e < s->nedges; e++) U[e + k * ldu] -= centre[e] * csum[k];
        es__free(ctx, csum);
        es__progress(ctx, "pca: components", s->nedges, s->nedges);
        return ES_OK;
    }
    double *y = es__alloc_array(ctx, c * N, sizeof *y);
    if (!y) return ES_ENOMEM;
    for (int64_t e0 = 0; e0 < s->nedges && rc == ES_OK; e0 += c) {
        int64_t k = s->nedges - e0 < c ? s->nedges - e0 : c;
        copy_chunk(s, e0, k, centre, y, NULL);
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)k, (int)r, nn, 1.0, y,
                    (int)k, V, nn, 0.0, U + e0, (int)ldu);
        rc = es__progress(ctx, "pca: components", e0 + k, s->nedges);   /* agreed after */
    }
    es__free(ctx, y);
    return rc;
}

es_status es__pca_fit_gram_strip(es_ctx *ctx, const es__strip *s, int64_t E_total, int64_t K,
                                 es_pca **out)
{
    const int64_t E = s->nedges, N = s->nrows;
    const bool alone = es__par_alone(ctx);
    es__gram_fit g;
    es_pca *p = NULL;
    es_status rc = ES_OK;
    double *x0 = es__alloc_array(ctx, E > 0 ? E : 1, sizeof *x0);
    double *ysum = es__calloc(ctx, (size_t)(E > 0 ? E : 1), sizeof *ysum);
    double *G = es__calloc(ctx, (size_t)N, (size_t)N * sizeof *G);
    double *mine = NULL;
    memset(&g, 0, sizeof g);
    *out = NULL;
    if (!x0 || !ysum || !G) rc = ES_ENOMEM;
    /* shifted by row 0 on this rank's edges, G summed on rank 0 */
    if (rc == ES_OK) {
        memcpy(x0, column(s, 0), (size_t)E * sizeof *x0);
        rc = es__strip_gram(ctx, s, x0, G, ysum);
    }
    if ((rc = es__par_agree(ctx, rc)) != ES_OK || (rc = es__par_sum_root(ctx, G, N * N)) != ES_OK)
        goto done;
    if (es__par_rank(ctx) == 0) rc = es__gram_decompose(ctx, G, N, E_total, K, &g);
    else g.N = N;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK || (rc = es__gram_share(ctx, &g)) != ES_OK)
        goto done;
    es__free(ctx, G);
    G = NULL;
    rc = es__pca_alloc(ctx, E_total, N, g.r, &p);
    if (rc == ES_OK && !alone && !(mine = es__alloc_array(ctx, E * g.r > 0 ? E * g.r : 1,
                                                         sizeof *mine)))
        rc = ES_ENOMEM;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) goto done;
    es__gram_fill(&g, p);
    /* this rank's components, unit length over all edges, then everyone's */
    for (int64_t e = 0; e < E; e++) x0[e] += ysum[e] / (double)N;   /* the mean */
    rc = es__strip_project(ctx, s, x0, g.V, g.r, alone ? p->components : mine, alone ? E_total : E);
    if ((rc = es__par_agree(ctx, rc)) != ES_OK ||
        (rc = es__unit_columns(ctx, alone ? p->components : mine, E, g.r, alone ? E_total : E,
                               !alone)) != ES_OK)
        goto done;
    if (alone) {
        memcpy(p->mean, x0, (size_t)E * sizeof *x0);
    } else {
        if ((rc = es__gather_split(ctx, mine, E_total, g.r, p->components)) != ES_OK ||
            (rc = es__gather_split(ctx, x0, E_total, 1, p->mean)) != ES_OK)
            goto done;
    }
    es__pca_finish(p);
    *out = p;
    p = NULL;
done:
    es_pca_free(p);
    es__gram_fit_clear(ctx, &g);
    es__free(ctx, x0);
    es__free(ctx, ysum);
    es__free(ctx, G);
    es__free(ctx, mine);
    return rc;
}
