/* lib/stats/pca_parallel.c — the Gram route on the ranks of an MPI job.
 *
 * The Gram matrix needs every pair of rows, but it is a sum over edges:
 * G = sum over ranks q of Y_q^T Y_q, Y_q the strip of edges rank q holds for
 * all N rows. So each rank reads its share of the rows (contiguous, through
 * the source: for a store, collective parallel-HDF5 reads), and one
 * all-to-all exchange per round of rows turns rows into strips: rank q
 * receives, from every rank, that rank's rows restricted to q's edges,
 * already in place in its strip (column-major, a row's edges contiguous).
 * Then everything is local (pca_strip.c) but three collectives: the partial
 * Gram matrices summed on rank 0, which decomposes and broadcasts the
 * eigenpairs, and the components' and mean's strips gathered.
 *
 * Per rank: reads N E / P values, sends about N E / P x (P - 1) / P, holds
 * its strip (N E / P), G (N^2) and the components (E K) gathered at the
 * end; datasets-spec/parallel.md has the whole cost model. A matrix source
 * (in memory on every rank) needs no exchange: each rank takes its edges
 * from the matrix itself.
 */
#include "stats/stats_pkg.h"
#include "parallel/parallel_private.h"

#include <string.h>

/* Rows read per round: about 64 MB of lengths (or src->block). */
#define ROUND_BYTES ((int64_t)64 << 20)

es_status es__gather_split(es_ctx *ctx, const double *mine, int64_t total, int64_t r,
                           double *out)
{
    const int P = es__par_size(ctx);
    int64_t *counts = es__alloc_array(ctx, 2 * P, sizeof *counts), *lo = counts ? counts + P : NULL;
    double *all = es__alloc_array(ctx, total * r > 0 ? total * r : 1, sizeof *all);
    es_status rc = counts && all ? ES_OK : ES_ENOMEM;
    if ((rc = es__par_agree(ctx, rc)) == ES_OK) {
        for (int q = 0; q < P; q++) {
            int64_t a, b;
            es__par_split(total, P, q, &a, &b);
            lo[q] = a;
            counts[q] = (b - a) * r;
        }
        rc = es__par_allgather(ctx, mine, counts, all);
    }
    if (rc == ES_OK) {
        /* rank q's block (n_q x r) holds rows lo[q] .. of each column */
        int64_t at = 0;
        for (int q = 0; q < P; q++) {
            const int64_t nq = r > 0 ? counts[q] / r : 0;
            for (int64_t k = 0; k < r; k++, at += nq)
                memcpy(out + lo[q] + k * total, all + at, (size_t)nq * sizeof *out);
        }
    }
    es__free(ctx, counts);
    es__free(ctx, all);
    return rc;
}

/* This rank's strip (edges [e_lo, e_hi) of all N rows, ld e_hi - e_lo) from
 * the rows every rank reads. */
static es_status load_strip(es_ctx *ctx, const es_source *src, double *strip)
{
    const int P = es__par_size(ctx), me = es__par_rank(ctx);
    const int64_t E = src->nedges;
    int64_t B = src->block > 0 ? src->block : ROUND_BYTES / (8 * E), lo, hi, rounds;
    if (B < 1) B = 1;
    es__source_share(ctx, src, B, &lo, &hi, &rounds);
    int64_t *t = es__alloc_array(ctx, 8 * P, sizeof *t);
    double *buf = es__alloc_array(ctx, E * B, sizeof *buf);
    double *send = es__alloc_array(ctx, E * B, sizeof *send);
    es_status rc = t && buf && send ? ES_OK : ES_ENOMEM;
    int64_t *elo = t, *ehi = t + P, *rlo = t + 2 * P, *rhi = t + 3 * P;
    int64_t *sc = t + 4 * P, *so = t + 5 * P, *rcnt = t + 6 * P, *ro = t + 7 * P;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) goto done;
    for (int q = 0; q < P; q++) {
        es__par_split(E, P, q, &elo[q], &ehi[q]);
        es__par_split(src->nrows, P, q, &rlo[q], &rhi[q]);
    }
    const int64_t Ep = ehi[me] - elo[me];
    for (int64_t k = 0; k < rounds && rc == ES_OK; k++) {
        int64_t r0, n;
        es__source_round(lo, hi, B, k, &r0, &n);
        rc = es__par_agree(ctx, es__source_read(ctx, src, r0, n, buf));
        if (rc != ES_OK) break;
        /* to rank q: my n rows on q's edges; from rank q: its rows of this
         * round on my edges, straight into their columns of the strip */
        int64_t at = 0;
        for (int q = 0; q < P; q++) {
            const int64_t eq = ehi[q] - elo[q];
            int64_t q0, nq;
            es__source_round(rlo[q], rhi[q], B, k, &q0, &nq);
            so[q] = at;
            sc[q] = eq * n;
            for (int64_t j = 0; j < n; j++)
                memcpy(send + at + j * eq, buf + j * E + elo[q], (size_t)eq * sizeof *send);
            at += eq * n;
            rcnt[q] = Ep * nq;
            ro[q] = q0 * Ep;
        }
        rc = es__par_alltoall(ctx, send, sc, so, strip, rcnt, ro);
        es__progress(ctx, "pca: reading rows", k + 1, rounds);
    }
done:
    es__free(ctx, t);
    es__free(ctx, buf);
    es__free(ctx, send);
    return rc;
}

es_status es__pca_fit_gram_parallel(es_ctx *ctx, const es_source *src, int64_t K, es_pca **out)
{
    const int P = es__par_size(ctx), me = es__par_rank(ctx);
    const int64_t E = src->nedges, N = src->nrows;
    int64_t e_lo, e_hi;
    es_mat m;
    const int64_t *cols;
    es_status rc;
    es__par_split(E, P, me, &e_lo, &e_hi);
    if (es__source_matrix_of(src, &m, &cols)) {
        /* every rank holds the matrix: its edges are rows of it */
        es__strip s = {m.data + e_lo, m.ld, e_hi - e_lo, N, cols, 0, e_lo};
        for (int64_t j = 0; cols && j < N; j++)
            if (cols[j] < 0 || cols[j] >= m.cols)
                ES_FAIL(ctx, ES_ERANGE, "source: row %lld refers to column %lld of a %lld-column "
                        "matrix", (long long)j, (long long)cols[j], (long long)m.cols);
        return es__pca_fit_gram_strip(ctx, &s, E, K, out);
    }
    int64_t ep = e_hi - e_lo, total;
    double *strip = NULL;
    if (!es__mul_i64(ep > 0 ? ep : 1, N, &total)) rc = es__fail(ctx, ES_ERANGE, "pca: strip too large");
    else rc = (strip = es__alloc_array(ctx, total, sizeof *strip)) ? ES_OK : ES_ENOMEM;
    if ((rc = es__par_agree(ctx, rc)) == ES_OK && (rc = load_strip(ctx, src, strip)) == ES_OK) {
        es__strip s = {strip, ep > 0 ? ep : 1, ep, N, NULL, 0, e_lo};
        rc = es__pca_fit_gram_strip(ctx, &s, E, K, out);
    }
    es__free(ctx, strip);
    return rc;
}
