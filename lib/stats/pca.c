/* lib/stats/pca.c — exact principal component analysis of a streamed shape set,
 * projection onto a fitted PCA.
 *
 * Shapes are the N columns of X (E x N), read in blocks of rows through an
 * es_source. When N <= E (600 faces of 175,000 edges in Section 4 of Fisher
 * et al.) the eigenproblem lives in the N x N Gram matrix; the E x E
 * covariance is formed only when N > E. Both accumulate the data shifted by
 * its first row, Y = X - x_0 1^T, rather than the raw lengths: centring is
 * invariant to the shift, and the entries then have the size of the
 * variation, so double-centring loses no digits to cancellation (normalized
 * lengths differ from each other by a few percent only).
 *
 * The Gram matrix needs every pair of shapes, so it is built in tiles: an
 * outer tile of rows is held (256 MiB by default) while the later rows
 * stream past it in tiles of the same size; 600 x 175,000 takes about two
 * passes over the data, a third forms the components. Each entry
 * is a dot product over all E edges whatever the blocking.
 *
 * References: Jolliffe, Principal Component Analysis (2002), 3.5 (the Gram
 * or "dual" route); LAPACK dsyevr (Dhillon & Parlett's MRRR).
 */
#include "stats/stats_pkg.h"
#include "parallel/parallel_private.h"

#include <cblas.h>
#include <lapacke.h>
#include <float.h>
#include <math.h>
#include <string.h>

/* Bytes of one tile of rows of the Gram route (two are held) when the
 * source does not fix the block size. */
#define TILE_BYTES ((int64_t)256 << 20)

void es_pca_opts_init(es_pca_opts *o)
{
    memset(o, 0, sizeof *o);
    o->method = ES_PCA_AUTO;
    o->oversample = 10;
    o->power_iters = 4;
}

void es_pca_free(es_pca *p)
{
    if (!p) return;
    es_ctx *ctx = p->ctx;
    es__free(ctx, p->mean);
    es__free(ctx, p->components);
    es__free(ctx, p->eigenvalues);
    es__free(ctx, p->explained);
    es__free(ctx, p->scores);
    es__free(ctx, p);
}

es_status es__pca_alloc(es_ctx *ctx, int64_t E, int64_t N, int64_t K, es_pca **out)
{
    int64_t ek, nk;
    *out = NULL;
    if (!es__mul_i64(E, K, &ek) || !es__mul_i64(N, K, &nk))
        ES_FAIL(ctx, ES_ERANGE, "pca: %lld components of %lld edges overflow", (long long)K,
                (long long)E);
    es_pca *p = es__calloc(ctx, 1, sizeof *p);
    if (!p) return ES_ENOMEM;
    p->ctx = ctx;
    p->nedges = E;
    p->nrows = N;
    p->ncomp = K;
    p->mean = es__alloc_array(ctx, E, sizeof(double));
    p->components = es__alloc_array(ctx, ek > 0 ? ek : 1, sizeof(double));
    p->eigenvalues = es__alloc_array(ctx, K > 0 ? K : 1, sizeof(double));
    p->explained = es__alloc_array(ctx, K > 0 ? K : 1, sizeof(double));
    p->scores = es__alloc_array(ctx, nk > 0 ? nk : 1, sizeof(double));
    if (!p->mean || !p->components || !p->eigenvalues || !p->explained || !p->scores) {
        es_pca_free(p);
        return ES_ENOMEM;
    }
    *out = p;
    return ES_OK;
}

void es__pca_finish(es_pca *p)
{
    const int64_t E = p->nedges, N = p->nrows;
    for (int64_t k = 0; k < p->ncomp; k++) {
        double *u = p->components + k * E, big = 0;
        int64_t at = 0;
        for (int64_t e = 0; e < E; e++)
            if (fabs(u[e]) > big) big = fabs(u[e]), at = e;
        if (u[at] < 0) {
            for (int64_t e = 0; e < E; e++) u[e] = -u[e];
            if (p->scores)
                for (int64_t i = 0; i < N; i++) p->scores[i + k * N] = -p->scores[i + k * N];
        }
        p->explained[k] = p->total_variance > 0 ? p->eigenvalues[k] / p->total_variance : NAN;
    }
}

/* Top eigenpairs of the symmetric n x n matrix a (upper triangle used,
 * destroyed): w[0..m) descending, z (n x m) matching columns. want = 0
 * asks for all. */
static es_status sym_eigen(es_ctx *ctx, int64_t n, double *a, int64_t want, double *w,
                           double *z, int64_t *m_out)
{
    int ni, il, iu, m = 0;
    es_status rc = es__lapack_int(ctx, n, &ni);
    if (rc != ES_OK) return rc;
    int *isuppz = es__alloc_array(ctx, 2 * n, sizeof *isuppz);
    if (!isuppz) return ES_ENOMEM;
    char range = want > 0 && want < n ? 'I' : 'A';
    il = range == 'I' ? (int)(n - want + 1) : 1;
    iu = ni;
    lapack_int info = LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', range, 'U', ni, a, ni, 0.0, 0.0,
                                     il, iu, 0.0, &m, w, z, ni, isuppz);
    es__free(ctx, isuppz);
    if (info != 0)
        ES_FAIL(ctx, ES_ENUMERIC, "pca: LAPACKE_dsyevr failed (info %d) on a %lld x %lld "
                "matrix", (int)info, (long long)n, (long long)n);
    /* ascending -> descending */
    for (int64_t i = 0, j = m - 1; i < j; i++, j--) {
        double t = w[i];
        w[i] = w[j];
        w[j] = t;
        for (int64_t r = 0; r < n; r++) {
            t = z[r + i * n];
            z[r + i * n] = z[r + j * n];
            z[r + j * n] = t;
        }
    }
    *m_out = m;
    return ES_OK;
}

/* Number of eigenvalues above the numerical-zero threshold, capped by the
 * requested K (0: no cap) and by N - 1. */
static int64_t rank_of(const double *w, int64_t m, int64_t dim, int64_t N, int64_t K)
{
    double tol = w[0] > 0 ? (double)dim * DBL_EPSILON * w[0] : 0;
    int64_t r = 0;
    while (r < m && w[r] > tol) r++;
    if (r > N - 1) r = N - 1;
    if (K > 0 && r > K) r = K;
    return r;
}

es_status es__gram_decompose(es_ctx *ctx, double *G, int64_t N, int64_t E, int64_t K,
                             es__gram_fit *g)
{
    es_status rc;
    int64_t m;
    memset(g, 0, sizeof *g);
    g->N = N;
    double *rmean = es__alloc_array(ctx, N, sizeof *rmean);
    g->w = es__alloc_array(ctx, N, sizeof *g->w);
    /* eigenvectors take only K columns when K is given */
    g->V = es__alloc_array(ctx, N * (K > 0 ? K : N), sizeof *g->V);
    if (!rmean || !g->w || !g->V) {
        es__free(ctx, rmean);
        return ES_ENOMEM;
    }
    /* symmetrize, then double-centre: Gc = J G J with J = I - 11^T/N */
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = j + 1; i < N; i++) G[i + j * N] = G[j + i * N];
    double s = 0;
    for (int64_t i = 0; i < N; i++) {
        double r = 0;
        for (int64_t j = 0; j < N; j++) r += G[i + j * N];
        rmean[i] = r / (double)N;
        s += rmean[i];
    }
    s /= (double)N;
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = 0; i < N; i++) G[i + j * N] += s - rmean[i] - rmean[j];
    for (int64_t i = 0; i < N; i++) g->trace += G[i + i * N];
    es__free(ctx, rmean);
    if ((rc = sym_eigen(ctx, N, G, K, g->w, g->V, &m)) != ES_OK) return rc;
    g->r = m > 0 ? rank_of(g->w, m, N > E ? N : E, N, K) : 0;
    return ES_OK;
}

es_status es__gram_share(es_ctx *ctx, es__gram_fit *g)
{
    es_status rc;
    int64_t hdr[2] = {g->r, 0};
    double tr = g->trace;
    if (es__par_alone(ctx)) return ES_OK;
    if ((rc = es__par_bcast(ctx, hdr, sizeof hdr, 0)) != ES_OK ||
        (rc = es__par_bcast(ctx, &tr, sizeof tr, 0)) != ES_OK)
        return rc;
    g->r = hdr[0];
    g->trace = tr;
    if (es__par_rank(ctx) != 0) {
        es__free(ctx, g->w);
        es__free(ctx, g->V);
        g->w = es__alloc_array(ctx, g->r > 0 ? g->r : 1, sizeof *g->w);
        g->V = es__alloc_array(ctx, g->N * (g->r > 0 ? g->r : 1), sizeof *g->V);
    }
    if ((rc = es__par_agree(ctx, g->w && g->V ? ES_OK : ES_ENOMEM)) != ES_OK ||
        (rc = es__par_bcast(ctx, g->w, (size_t)g->r * sizeof *g->w, 0)) != ES_OK)
        return rc;
    return es__par_bcast(ctx, g->V, (size_t)(g->N * g->r) * sizeof *g->V, 0);
}

void es__gram_fill(const es__gram_fit *g, es_pca *p)
{
    const int64_t N = g->N;
    p->method = ES_PCA_GRAM;
    p->total_variance = g->trace / (double)(N - 1);
    for (int64_t k = 0; k < g->r; k++) {
        p->eigenvalues[k] = g->w[k] / (double)(N - 1);
        double sq = sqrt(g->w[k]);
        for (int64_t i = 0; i < N; i++) p->scores[i + k * N] = sq * g->V[i + k * N];
    }
}

void es__gram_fit_clear(es_ctx *ctx, es__gram_fit *g)
{
    es__free(ctx, g->w);
    es__free(ctx, g->V);
    memset(g, 0, sizeof *g);
}

es_status es__unit_columns(es_ctx *ctx, double *U, int64_t n, int64_t r, int64_t ldu,
                           bool sum_ranks)
{
    es_status rc;
    double *nrm = es__alloc_array(ctx, r > 0 ? r : 1, sizeof *nrm);
    if (!nrm) return ES_ENOMEM;
    for (int64_t k = 0; k < r; k++) {
        double acc = 0;
        for (int64_t e = 0; e < n; e++) acc += U[e + k * ldu] * U[e + k * ldu];
        nrm[k] = acc;
    }
    if (sum_ranks && (rc = es__par_sum(ctx, nrm, r)) != ES_OK) {
        es__free(ctx, nrm);
        return rc;
    }
    for (int64_t k = 0; k < r; k++) {
        double s = sqrt(nrm[k]);
        if (!(s > 0)) {
            es__free(ctx, nrm);
            ES_FAIL(ctx, ES_ENUMERIC, "pca: component %lld vanished", (long long)(k + 1));
        }
        for (int64_t e = 0; e < n; e++) U[e + k * ldu] /= s;
    }
    es__free(ctx, nrm);
    return ES_OK;
}

/* Read a block and subtract the vector c from every column. */
static es_status read_minus(es_ctx *ctx, const es_source *src, int64_t r0, int64_t n,
                            const double *c, double *buf)
{
    es_status rc = es__source_read(ctx, src, r0, n, buf);
    if (rc != ES_OK) return rc;
    const int64_t E = src->nedges;
    for (int64_t j = 0; j < n; j++)
        for (int64_t e = 0; e < E; e++) buf[e + j * E] -= c[e];
    return ES_OK;
}

/* ---- Gram route --------------------------------------------------------- */

static es_status fit_gram(es_ctx *ctx, const es_source *src, int64_t K, es_pca **out)
{
    const int64_t E = src->nedges, N = src->nrows;
    es_mat m;
    const int64_t *cols;
    if (!es__par_alone(ctx)) return es__pca_fit_gram_parallel(ctx, src, K, out);
    if (es__source_matrix_of(src, &m, &cols)) {
        /* in memory: read in place, edges at a time (pca_strip.c) */
        es__strip s = {m.data, m.ld, E, N, cols, 0, 0};
        for (int64_t j = 0; cols && j < N; j++)
            if (cols[j] < 0 || cols[j] >= m.cols)
                ES_FAIL(ctx, ES_ERANGE, "source: row %lld refers to column %lld of a %lld-column "
                        "matrix", (long long)j, (long long)cols[j], (long long)m.cols);
        return es__pca_fit_gram_strip(ctx, &s, E, K, out);
    }
    /* square tiles: thin ones (a few rows against thousands of edges) run
     * BLAS at a tenth of its speed */
    int64_t BO = src->block > 0 ? src->block : TILE_BYTES / (8 * E);
    if (BO < 1) BO = 1;
    if (BO > N) BO = N;
    const int64_t B = BO;
    es_status rc = ES_OK;
    int nn, ne;
    if ((rc = es__lapack_int(ctx, N, &nn)) != ES_OK || (rc = es__lapack_int(ctx, E, &ne)) != ES_OK)
        return rc;
    double *x0 = es__alloc_array(ctx, E, sizeof *x0);
    double *ysum = es__calloc(ctx, (size_t)E, sizeof *ysum);
    double *outer = es__alloc_array(ctx, E * BO, sizeof *outer);
    double *inner = es__alloc_array(ctx, E * B, sizeof *inner);
    /* N < 2^31 (LAPACK's int), so N * N does not overflow; eigenvectors take
     * only K columns when K is given */
    double *G = es__alloc_array(ctx, N * N, sizeof *G);
    es__gram_fit g;
    es_pca *p = NULL;
    memset(&g, 0, sizeof g);
    if (!x0 || !ysum || !outer || !inner || !G) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es__source_read(ctx, src, 0, 1, x0)) != ES_OK) goto done;

    /* G = Y^T Y in tiles: outer block I against itself and every later block */
    int64_t nread = 0, total_reads = 0;
    for (int64_t i0 = 0; i0 < N; i0 += BO) total_reads += N - i0;
    for (int64_t i0 = 0; i0 < N; i0 += BO) {
        int64_t bi = N - i0 < BO ? N - i0 : BO;
        if ((rc = read_minus(ctx, src, i0, bi, x0, outer)) != ES_OK) goto done;
        for (int64_t j = 0; j < bi; j++)
            for (int64_t e = 0; e < E; e++) ysum[e] += outer[e + j * E];
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, (int)bi, ne, 1.0, outer,
                    ne, 0.0, G + i0 + i0 * N, nn);
        nread += bi;
        for (int64_t j0 = i0 + bi; j0 < N; j0 += B) {
            int64_t bj = N - j0 < B ? N - j0 : B;
            if ((rc = read_minus(ctx, src, j0, bj, x0, inner)) != ES_OK) goto done;
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)bi, (int)bj, ne,
                        1.0, outer, ne, inner, ne, 0.0, G + i0 + j0 * N, nn);
            nread += bj;
            if ((rc = es__progress(ctx, "pca: Gram matrix", nread, total_reads))) goto done;
        }
        if ((rc = es__progress(ctx, "pca: Gram matrix", nread, total_reads))) goto done;
    }
    if ((rc = es__gram_decompose(ctx, G, N, E, K, &g)) != ES_OK ||
        (rc = es__pca_alloc(ctx, E, N, g.r, &p)) != ES_OK)
        goto done;
    es__gram_fill(&g, p);
    for (int64_t e = 0; e < E; e++) p->mean[e] = x0[e] + ysum[e] / (double)N;

    /* components: U = (X - mean 1^T) V diag(1/sqrt(mu)) */
    if (g.r > 0) {
        memset(p->components, 0, (size_t)(E * g.r) * sizeof(double));
        for (int64_t j0 = 0; j0 < N; j0 += BO) {
            int64_t bj = N - j0 < BO ? N - j0 : BO;
            if ((rc = read_minus(ctx, src, j0, bj, p->mean, outer)) != ES_OK) goto done;
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, ne, (int)g.r, (int)bj,
                        1.0, outer, ne, g.V + j0, nn, 1.0, p->components, ne);
            if ((rc = es__progress(ctx, "pca: components", j0 + bj, N))) goto done;
        }
        if ((rc = es__unit_columns(ctx, p->components, E, g.r, E, false)) != ES_OK) goto done;
    }
    es__pca_finish(p);
    *out = p;
    p = NULL;
done:
    es_pca_free(p);
    es__free(ctx, x0);
    es__free(ctx, ysum);
    es__free(ctx, outer);
    es__free(ctx, inner);
    es__free(ctx, G);
    es__gram_fit_clear(ctx, &g);
    return rc;
}

/* ---- covariance route ------------------------------------------------------ */

/* In a job, each rank reads its share of the rows (rounds in step, for a
 * collective reader); the partial covariances are summed on rank 0, which
 * decomposes; the scores of each rank's rows are gathered. */
static es_status fit_covariance(es_ctx *ctx, const es_source *src, int64_t K, es_pca **out)
{
    const int64_t E = src->nedges, N = src->nrows, B = es__source_block(src);
    const bool alone = es__par_alone(ctx), root = es__par_rank(ctx) == 0;
    es_status rc;
    int ne;
    if ((rc = es__lapack_int(ctx, E, &ne)) != ES_OK) return rc;
    int64_t ee, lo, hi, rounds;
    if (!es__mul_i64(E, E, &ee))
        ES_FAIL(ctx, ES_ERANGE, "pca: a %lld x %lld covariance overflows", (long long)E,
                (long long)E);
    es__source_share(ctx, src, B, &lo, &hi, &rounds);
    double *x0 = es__alloc_array(ctx, E, sizeof *x0);
    double *ysum = es__calloc(ctx, (size_t)E, sizeof *ysum);
    double *buf = es__alloc_array(ctx, E * B, sizeof *buf);
    double *C = es__calloc(ctx, (size_t)ee, sizeof *C);
    double *w = es__alloc_array(ctx, E, sizeof *w);
    double *Z = es__alloc_array(ctx, E * (K > 0 ? K : E), sizeof *Z);
    double *mine = NULL;
    es_pca *p = NULL;
    int64_t r = 0, hdr[1];
    double trace = 0;
    rc = x0 && ysum && buf && C && w && Z ? ES_OK : ES_ENOMEM;
    if (rc == ES_OK) rc = es__source_read(ctx, src, 0, 1, x0);
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) goto done;
    for (int64_t k = 0; k < rounds; k++) {
        int64_t r0, n;
        es__source_round(lo, hi, B, k, &r0, &n);
        if ((rc = es__par_agree(ctx, read_minus(ctx, src, r0, n, x0, buf))) != ES_OK) goto done;
        for (int64_t j = 0; j < n; j++)
            for (int64_t e = 0; e < E; e++) ysum[e] += buf[e + j * E];
        if (n > 0)
            cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, ne, (int)n, 1.0, buf, ne, 1.0,
                        C, ne);
        if ((rc = es__par_agree(ctx, es__progress(ctx, "pca: covariance", alone ? r0 + n : k + 1,
                                                  alone ? N : rounds))) != ES_OK)
            goto done;
    }
    if ((rc = es__par_sum_root(ctx, C, ee)) != ES_OK || (rc = es__par_sum(ctx, ysum, E)) != ES_OK)
        goto done;
    if (root) {
        /* Cc = Y^T Y - N ybar ybar^T, upper triangle */
        for (int64_t j = 0; j < E; j++) {
            double yj = ysum[j] / (double)N;
            for (int64_t i = 0; i <= j; i++)
                C[i + j * E] -= (double)N * (ysum[i] / (double)N) * yj;
            trace += C[j + j * E];
        }
        int64_t m;
        if ((rc = sym_eigen(ctx, E, C, K, w, Z, &m)) == ES_OK)
            r = m > 0 ? rank_of(w, m, N > E ? N : E, N, K) : 0;
    }
    hdr[0] = r;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK ||
        (rc = es__par_bcast(ctx, hdr, sizeof hdr, 0)) != ES_OK ||
        (rc = es__par_bcast(ctx, &trace, sizeof trace, 0)) != ES_OK ||
        (rc = es__par_bcast(ctx, w, (size_t)hdr[0] * sizeof *w, 0)) != ES_OK ||
        (rc = es__par_bcast(ctx, Z, (size_t)(E * hdr[0]) * sizeof *Z, 0)) != ES_OK)
        goto done;
    r = hdr[0];
    rc = es__pca_alloc(ctx, E, N, r, &p);
    if (rc == ES_OK && !alone &&
        !(mine = es__alloc_array(ctx, (hi - lo) * r > 0 ? (hi - lo) * r : 1, sizeof *mine)))
        rc = ES_ENOMEM;
    if ((rc = es__par_agree(ctx, rc)) != ES_OK) goto done;
    p->method = ES_PCA_COVARIANCE;
    p->total_variance = trace / (double)(N - 1);
    for (int64_t e = 0; e < E; e++) p->mean[e] = x0[e] + ysum[e] / (double)N;
    for (int64_t k = 0; k < r; k++) p->eigenvalues[k] = w[k] / (double)(N - 1);
    memcpy(p->components, Z, (size_t)(E * r) * sizeof(double));
    /* scores: S = (X - mean 1^T)^T U, one more pass (this rank's rows) */
    for (int64_t k = 0; k < rounds && r > 0; k++) {
        int64_t r0, n;
        es__source_round(lo, hi, B, k, &r0, &n);
        if ((rc = es__par_agree(ctx, read_minus(ctx, src, r0, n, p->mean, buf))) != ES_OK)
            goto done;
        if (n > 0)
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)n, (int)r, ne, 1.0, buf,
                        ne, p->components, ne, 0.0, alone ? p->scores + r0 : mine + (r0 - lo),
                        alone ? (int)N : (int)(hi - lo));
        if ((rc = es__par_agree(ctx, es__progress(ctx, "pca: scores", alone ? r0 + n : k + 1,
                                                  alone ? N : rounds))) != ES_OK)
            goto done;
    }
    if (!alone && r > 0 && (rc = es__gather_split(ctx, mine, N, r, p->scores)) != ES_OK) goto done;
    es__pca_finish(p);
    *out = p;
    p = NULL;
done:
    es_pca_free(p);
    es__free(ctx, x0);
    es__free(ctx, ysum);
    es__free(ctx, buf);
    es__free(ctx, C);
    es__free(ctx, w);
    es__free(ctx, Z);
    es__free(ctx, mine);
    return rc;
}

es_status es_pca_fit(es_ctx *ctx, const es_source *src, const es_pca_opts *opts, es_pca **out)
{
    es_pca_opts o;
    es_status rc;
    *out = NULL;
    if (opts) o = *opts;
    else es_pca_opts_init(&o);
    if ((rc = es__source_check(ctx, src, "pca")) != ES_OK) return rc;
    const int64_t E = src->nedges, N = src->nrows;
    if (N < 2) ES_FAIL(ctx, ES_EINVAL, "pca: need at least 2 rows, have %lld", (long long)N);
    int64_t kmax = N - 1 < E ? N - 1 : E;
    if (o.ncomp < 0 || o.ncomp > kmax)
        ES_FAIL(ctx, ES_EINVAL, "pca: %lld components asked, at most %lld possible with %lld "
                "rows and %lld edges", (long long)o.ncomp, (long long)kmax, (long long)N,
                (long long)E);
    switch (o.method) {
    case ES_PCA_AUTO:
        return N <= E ? fit_gram(ctx, src, o.ncomp, out) : fit_covariance(ctx, src, o.ncomp, out);
    case ES_PCA_GRAM:
        return fit_gram(ctx, src, o.ncomp, out);
    case ES_PCA_COVARIANCE:
        return fit_covariance(ctx, src, o.ncomp, out);
    case ES_PCA_RANDOMIZED: {
        if (o.ncomp < 1)
            ES_FAIL(ctx, ES_EINVAL, "pca: the randomized method needs a number of components");
        if (o.oversample < 0 || o.power_iters < 0 || o.power_iters > 1000)
            ES_FAIL(ctx, ES_EINVAL, "pca: oversampling must be >= 0 and power iterations "
                    "0 to 1000 (got %lld and %lld)", (long long)o.oversample,
                    (long long)o.power_iters);
        es_pca *p;
        if ((rc = es__pca_alloc(ctx, E, N, o.ncomp, &p)) != ES_OK) return rc;
        if ((rc = es__pca_fit_randomized(ctx, src, &o, p)) != ES_OK) {
            es_pca_free(p);
            return rc;
        }
        /* numerically zero components (rank < K, constant data) are dropped
         * as in the exact routes: their directions are arbitrary */
        p->ncomp = rank_of(p->eigenvalues, p->ncomp, N > E ? N : E, N, p->ncomp);
        es__pca_finish(p);
        *out = p;
        return ES_OK;
    }
    }
    ES_FAIL(ctx, ES_EINVAL, "pca: unknown method %d", (int)o.method);
}

es_status es_pca_from_arrays(es_ctx *ctx, int64_t E, int64_t K, const double *mean,
                             const double *components, const double *eigenvalues,
                             double total_variance, es_pca **out)
{
    es_pca *p;
    *out = NULL;
    if (E < 1 || K < 0 || !mean || (K > 0 && (!components || !eigenvalues)))
        ES_FAIL(ctx, ES_EINVAL, "pca: incomplete arrays (%lld edges, %lld components)",
                (long long)E, (long long)K);
    es_status rc = es__pca_alloc(ctx, E, 0, K, &p);
    if (rc != ES_OK) return rc;
    memcpy(p->mean, mean, (size_t)E * sizeof(double));
    if (K > 0) {
        memcpy(p->components, components, (size_t)(E * K) * sizeof(double));
        memcpy(p->eigenvalues, eigenvalues, (size_t)K * sizeof(double));
    }
    p->method = ES_PCA_GRAM;
    p->total_variance = total_variance;
    for (int64_t k = 0; k < K; k++)
        p->explained[k] = total_variance > 0 ? eigenvalues[k] / total_variance : NAN;
    *out = p;
    return ES_OK;
}

es_status es_pca_project(es_ctx *ctx, const es_pca *pca, es_mat X, double *scores,
                         double *residual)
{
    if (!pca || !scores) ES_FAIL(ctx, ES_EINVAL, "project: no PCA or no output");
    const int64_t E = pca->nedges, K = pca->ncomp;
    if (X.rows != E)
        ES_FAIL(ctx, ES_EMISMATCH, "project: vectors have %lld edges, the PCA %lld",
                (long long)X.rows, (long long)E);
    int ne;
    es_status rc = es__lapack_int(ctx, E, &ne);
    if (rc != ES_OK) return rc;
    double *xc = es__alloc_array(ctx, E, sizeof *xc);
    if (!xc) return ES_ENOMEM;
    for (int64_t j = 0; j < X.cols; j++) {
        for (int64_t e = 0; e < E; e++) {
            xc[e] = ES_AT(X, e, j) - pca->mean[e];
            if (!isfinite(xc[e])) {
                es__free(ctx, xc);
                ES_FAIL(ctx, ES_ENUMERIC, "project: vector %lld, edge %lld is not finite",
                        (long long)j, (long long)e);
            }
        }
        double *s = scores + j * K;
        if (K > 0) {
            cblas_dgemv(CblasColMajor, CblasTrans, ne, (int)K, 1.0, pca->components, ne, xc, 1,
                        0.0, s, 1);
            cblas_dgemv(CblasColMajor, CblasNoTrans, ne, (int)K, -1.0, pca->components, ne, s,
                        1, 1.0, xc, 1);
        }
        if (residual) residual[j] = cblas_dnrm2(ne, xc, 1);
    }
    es__free(ctx, xc);
    return ES_OK;
}
