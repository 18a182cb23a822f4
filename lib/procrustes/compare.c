/* lib/procrustes/compare.c — comparing two shape spaces through their distance
 * matrices: Spearman/Mantel, nearest-neighbour agreement, largest rank
 * disagreements, group means and a permutation F test.
 *
 * Distances between points come from the Gram matrix of the centred
 * columns, accumulated over blocks of rows so no copy of the data is made
 * and the centring happens before the products (the uncentred Gram matrix
 * loses the small differences of similar shapes to cancellation).
 * The Mantel statistic is Spearman's rho over the upper triangle; under a
 * permutation of the specimens only the cross-product of centred ranks
 * changes, so each permutation costs one pass over n(n-1)/2 entries
 * (Legendre & Legendre 2012, sec. 10.5.1). Group statistics use the
 * identities of Anderson (2001, eqs. 1-3) for Euclidean distances:
 *   SS_T = (1/n) sum_{i<j} d_ij^2,  SS_W = sum_g (1/n_g) sum_{i<j in g} d_ij^2,
 *   ||m_a - m_b||^2 = B_ab/(n_a n_b) - B_aa/(2 n_a^2) - B_bb/(2 n_b^2),
 * B_ab the sum of d^2 over i in a, j in b; this is what geomorph's procD.lm
 * computes for a one-factor model, with labels permuted (Collyer et al. 2015).
 */
#include "core/core_private.h"
#include "edgespace/es_compare.h"
#include "procrustes/procrustes_pkg.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>

#define ROW_BLOCK 2048

es_status es_compare_distances(es_ctx *ctx, es_mat x, int normalize, es_mat dist)
{
    int64_t p = x.rows, n = x.cols;
    int ni, bi;
    es_status rc;
    if (n < 1 || p < 1) ES_FAIL(ctx, ES_EINVAL, "compare: empty point set");
    if (dist.rows != n || dist.cols != n || dist.ld < n)
        ES_FAIL(ctx, ES_EINVAL, "compare: distance matrix must be %lld x %lld", (long long)n,
                (long long)n);
    if ((rc = es__lapack_int(ctx, n, &ni)) != ES_OK) return rc;
    int64_t blk = p < ROW_BLOCK ? p : ROW_BLOCK;
    double *scale = es__alloc_array(ctx, n + p + n * n + blk * n, sizeof *scale);
    if (!scale) return ES_ENOMEM;
    double *mean = scale + n, *g = mean + p, *buf = g + n * n;
    for (int64_t j = 0; j < n; j++) {
        double s = 1.0;
        if (normalize) {
            s = 0;
            for (int64_t v = 0; v < p; v++) s += ES_AT(x, v, j);
            if (!(s != 0) || !isfinite(s)) {
                es__free(ctx, scale);
                ES_FAIL(ctx, ES_EINVAL, "compare: column %lld sums to %g and cannot be "
                        "normalized", (long long)j, s);
            }
        }
        scale[j] = 1.0 / s;
    }
    memset(mean, 0, (size_t)p * sizeof *mean);
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < p; v++) mean[v] += ES_AT(x, v, j) * scale[j] / (double)n;
    memset(g, 0, (size_t)(n * n) * sizeof *g);
    for (int64_t r0 = 0; r0 < p; r0 += blk) {
        int64_t nr = p - r0 < blk ? p - r0 : blk;
        for (int64_t j = 0; j < n; j++)
            for (int64_t v = 0; v < nr; v++)
                buf[v + j * nr] = ES_AT(x, r0 + v, j) * scale[j] - mean[r0 + v];
        bi = (int)nr;
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, ni, bi, 1.0, buf, bi, 1.0, g, ni);
    }
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i <= j; i++) {
            double d2 = g[i + i * n] + g[j + j * n] - 2 * g[i + j * n];
            double d = i == j ? 0.0 : sqrt(d2 > 0 ? d2 : 0.0);
            ES_AT(dist, i, j) = d;
            ES_AT(dist, j, i) = d;
        }
    es__free(ctx, scale);
    return ES_OK;
}

/* ---- ranks ---------------------------------------------------------------- */

typedef struct keyed { double v; int64_t i; } keyed;

static int cmp_keyed(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->v < y->v) return -1;
    if (x->v > y->v) return 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

/* Average ranks (1-based) of the upper triangle of d (n x n), pair order
 * (0,1), (0,2), (1,2), (0,3), ... (column by column). */
static es_status upper_ranks(es_ctx *ctx, int64_t n, const double *d, double *rank)
{
    int64_t m = n * (n - 1) / 2, t = 0;
    keyed *k = es__alloc_array(ctx, m, sizeof *k);
    if (!k) return ES_ENOMEM;
    for (int64_t j = 1; j < n; j++)
        for (int64_t i = 0; i < j; i++, t++) {
            double v = d[i + j * n];
            if (!isfinite(v)) {
                es__free(ctx, k);
                ES_FAIL(ctx, ES_EINVAL, "compare: distance (%lld, %lld) is not finite",
                        (long long)i, (long long)j);
            }
            k[t] = (keyed){v, t};
        }
    qsort(k, (size_t)m, sizeof *k, cmp_keyed);
    for (int64_t a = 0; a < m;) {
        int64_t b = a;
        while (b + 1 < m && k[b + 1].v == k[a].v) b++;
        double r = 0.5 * (double)(a + b) + 1.0;
        for (int64_t c = a; c <= b; c++) rank[k[c].i] = r;
        a = b + 1;
    }
    es__free(ctx, k);
    return ES_OK;
}

static es_status check_n(es_ctx *ctx, int64_t n)
{
    if (n < 3) ES_FAIL(ctx, ES_EINVAL, "compare: needs at least 3 specimens, got %lld",
                       (long long)n);
    if (n > 3037000499LL) ES_FAIL(ctx, ES_ERANGE, "compare: too many specimens");
    return ES_OK;
}

static void shuffle(es_rng *rng, int64_t *perm, int64_t n)
{
    for (int64_t j = n - 1; j > 0; j--) {
        int64_t i = (int64_t)es_rng_below(rng, (uint64_t)j + 1), t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
}

es_status es_compare_mantel(es_ctx *ctx, int64_t n, const double *d1, const double *d2,
                            int64_t permutations, double *rho, double *p)
{
    es_status rc;
    if ((rc = check_n(ctx, n)) != ES_OK) return rc;
    if (permutations < 0 || permutations > ES_MAX_PERMUTATIONS)
        ES_FAIL(ctx, ES_EINVAL, "compare: %lld permutations (0 to %d)", (long long)permutations,
                ES_MAX_PERMUTATIONS);
    int64_t m = n * (n - 1) / 2;
    double *r1 = es__alloc_array(ctx, 2 * m + n * n, sizeof *r1);
    int64_t *perm = es__alloc_array(ctx, n, sizeof *perm);
    if (!r1 || !perm) { es__free(ctx, r1); es__free(ctx, perm); return ES_ENOMEM; }
    double *r2 = r1 + m, *full2 = r2 + m;
    if ((rc = upper_ranks(ctx, n, d1, r1)) != ES_OK || (rc = upper_ranks(ctx, n, d2, r2)) != ES_OK)
        goto done;
    /* centre the ranks; both have mean (m+1)/2 */
    double mu = 0.5 * (double)(m + 1), s1 = 0, s2 = 0, c = 0;
    for (int64_t t = 0; t < m; t++) {
        r1[t] -= mu;
        r2[t] -= mu;
        s1 += r1[t] * r1[t];
        s2 += r2[t] * r2[t];
        c += r1[t] * r2[t];
    }
    if (!(s1 > 0) || !(s2 > 0)) {
        rc = es__fail(ctx, ES_EINVAL, "compare: all distances of a space are equal; rank "
                      "correlation undefined");
        goto done;
    }
    double denom = sqrt(s1 * s2), obs = c / denom;
    *rho = obs;
    if (p) *p = NAN;
    if (permutations > 0) {
        for (int64_t j = 1, t = 0; j < n; j++)
            for (int64_t i = 0; i < j; i++, t++) {
                full2[i + j * n] = r2[t];
                full2[j + i * n] = r2[t];
            }
        for (int64_t i = 0; i < n; i++) full2[i + i * n] = 0;
        es_rng rng;
        es_rng_init(&rng, es_ctx_seed(ctx) ^ 0x6d616e74656cULL);
        for (int64_t i = 0; i < n; i++) perm[i] = i;
        int64_t ge = 0;
        /* a relative tolerance keeps ties with the observed value counted */
        double thr = obs - 1e-12 * fabs(obs);
        for (int64_t q = 0; q < permutations; q++) {
            shuffle(&rng, perm, n);
            double cc = 0;
            for (int64_t j = 1, t = 0; j < n; j++) {
                const double *col = full2 + perm[j] * n;
                for (int64_t i = 0; i < j; i++, t++) cc += r1[t] * col[perm[i]];
            }
            if (cc / denom >= thr) ge++;
            if ((q & 255) == 0 && (rc = es__progress(ctx, "mantel", q, permutations))) goto done;
        }
        es__progress(ctx, "mantel", permutations, permutations);
        if (p) *p = (double)(1 + ge) / (double)(1 + permutations);
    }
done:
    es__free(ctx, r1);
    es__free(ctx, perm);
    return rc;
}

es_status es_compare_nn_agreement(es_ctx *ctx, int64_t n, const double *d1, const double *d2,
                                  int64_t *nn1, int64_t *nn2, double *agreement)
{
    es_status rc;
    if ((rc = check_n(ctx, n)) != ES_OK) return rc;
    int64_t same = 0;
    for (int64_t j = 0; j < n; j++) {
        int64_t b1 = -1, b2 = -1;
        for (int64_t i = 0; i < n; i++) {
            if (i == j) continue;
            if (b1 < 0 || d1[i + j * n] < d1[b1 + j * n]) b1 = i;
            if (b2 < 0 || d2[i + j * n] < d2[b2 + j * n]) b2 = i;
        }
        if (nn1) nn1[j] = b1;
        if (nn2) nn2[j] = b2;
        same += b1 == b2;
    }
    *agreement = (double)same / (double)n;
    return ES_OK;
}

typedef struct scored { double key, diff; int64_t t; } scored;

static int cmp_scored(const void *a, const void *b)
{
    const scored *x = a, *y = b;
    if (x->key > y->key) return -1;
    if (x->key < y->key) return 1;
    return x->t < y->t ? -1 : x->t > y->t;
}

es_status es_compare_disagreement(es_ctx *ctx, int64_t n, const double *d1, const double *d2,
                                  int64_t top, int64_t *pairs, double *diff)
{
    es_status rc;
    if ((rc = check_n(ctx, n)) != ES_OK) return rc;
    int64_t m = n * (n - 1) / 2;
    if (top < 0 || top > m)
        ES_FAIL(ctx, ES_EINVAL, "compare: %lld pairs requested of %lld", (long long)top,
                (long long)m);
    double *r = es__alloc_array(ctx, 2 * m, sizeof *r);
    scored *s = es__alloc_array(ctx, m, sizeof *s);
    if (!r || !s) { es__free(ctx, r); es__free(ctx, s); return ES_ENOMEM; }
    if ((rc = upper_ranks(ctx, n, d1, r)) != ES_OK || (rc = upper_ranks(ctx, n, d2, r + m)) != ES_OK)
        goto done;
    for (int64_t t = 0; t < m; t++) {
        double dd = (r[t] - r[m + t]) / (double)(m > 1 ? m - 1 : 1);
        s[t] = (scored){fabs(dd), dd, t};
    }
    qsort(s, (size_t)m, sizeof *s, cmp_scored);
    for (int64_t q = 0; q < top; q++) {
        /* pair index t -> (i, j), column by column: t = j(j-1)/2 + i */
        int64_t t = s[q].t, j = (int64_t)((1 + sqrt(1 + 8.0 * (double)t)) / 2);
        while (j * (j - 1) / 2 > t) j--;
        while ((j + 1) * j / 2 <= t) j++;
        pairs[2 * q] = t - j * (j - 1) / 2;
        pairs[2 * q + 1] = j;
        diff[q] = s[q].diff;
    }
done:
    es__free(ctx, r);
    es__free(ctx, s);
    return rc;
}

/* ---- groups ------------------------------------------------------------------ */

/* Block sums of d^2 by group (g x g, symmetric, B_aa counts each pair twice). */
static void block_sums(int64_t n, const double *d2, const int64_t *lab, int64_t g, double *b)
{
    memset(b, 0, (size_t)(g * g) * sizeof *b);
    for (int64_t j = 1; j < n; j++) {
        double *bj = b + lab[j] * g;
        for (int64_t i = 0; i < j; i++) bj[lab[i]] += d2[i + j * n];
    }
    for (int64_t a = 0; a < g; a++)
        for (int64_t c = 0; c <= a; c++) {
            double v = a == c ? 2 * b[a + a * g] : b[a + c * g] + b[c + a * g];
            b[a + c * g] = v;
            b[c + a * g] = v;
        }
}

static void group_stats(int64_t n, int64_t g, const double *b, const int64_t *cnt,
                        double sst, double *md2, double *ssw)
{
    double w = 0;
    for (int64_t a = 0; a < g; a++) w += b[a + a * g] / (2.0 * (double)cnt[a]);
    *ssw = w;
    (void)sst;
    (void)n;
    if (!md2) return;
    for (int64_t a = 0; a < g; a++)
        for (int64_t c = 0; c < g; c++) {
            double na = (double)cnt[a], nc = (double)cnt[c];
            double v = a == c ? 0.0 : b[a + c * g] / (na * nc) - b[a + a * g] / (2 * na * na) -
                                      b[c + c * g] / (2 * nc * nc);
            md2[a + c * g] = v > 0 ? v : 0.0;
        }
}

es_status es_compare_groups(es_ctx *ctx, int64_t n, const double *dist, const int64_t *group,
                            int64_t ngroups, int64_t permutations, double *mean_dist,
                            double *p_pair, es_group_stats *stats)
{
    es_status rc;
    int64_t g = ngroups;
    if ((rc = check_n(ctx, n)) != ES_OK) return rc;
    if (g < 2 || g > n) ES_FAIL(ctx, ES_EINVAL, "compare: %lld groups for %lld specimens",
                                (long long)g, (long long)n);
    if (permutations < 0 || permutations > ES_MAX_PERMUTATIONS)
        ES_FAIL(ctx, ES_EINVAL, "compare: %lld permutations (0 to %d)", (long long)permutations,
                ES_MAX_PERMUTATIONS);
    double *d2 = es__alloc_array(ctx, n * n + 4 * g * g, sizeof *d2);
    int64_t *lab = es__alloc_array(ctx, n + g, sizeof *lab);
    if (!d2 || !lab) { es__free(ctx, d2); es__free(ctx, lab); return ES_ENOMEM; }
    double *b = d2 + n * n, *md2 = b + g * g, *pm = md2 + g * g, *cntge = pm + g * g;
    int64_t *cnt = lab + n;
    memset(cnt, 0, (size_t)g * sizeof *cnt);
    for (int64_t i = 0; i < n; i++) {
        if (group[i] < 0 || group[i] >= g) {
            rc = es__fail(ctx, ES_EINVAL, "compare: specimen %lld has group %lld, not in [0, %lld)",
                          (long long)i, (long long)group[i], (long long)g);
            goto done;
        }
        lab[i] = group[i];
        cnt[group[i]]++;
    }
    for (int64_t a = 0; a < g; a++)
        if (cnt[a] == 0) {
            rc = es__fail(ctx, ES_EINVAL, "compare: group %lld is empty", (long long)a);
            goto done;
        }
    double sst = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) {
            double v = dist[i + j * n];
            if (!isfinite(v)) {
                rc = es__fail(ctx, ES_EINVAL, "compare: distance (%lld, %lld) is not finite",
                              (long long)i, (long long)j);
                goto done;
            }
            d2[i + j * n] = v * v;
            if (i < j) sst += v * v;
        }
    sst /= (double)n;
    double ssw;
    block_sums(n, d2, lab, g, b);
    group_stats(n, g, b, cnt, sst, md2, &ssw);
    double ssb = sst - ssw, f = n > g && ssw > 0 ? (ssb / (double)(g - 1)) / (ssw / (double)(n - g))
                                                 : NAN;
    memset(cntge, 0, (size_t)(g * g) * sizeof *cntge);
    int64_t fge = 0;
    if (permutations > 0) {
        es_rng rng;
        es_rng_init(&rng, es_ctx_seed(ctx) ^ 0x67726f757073ULL);
        for (int64_t q = 0; q < permutations; q++) {
            double w;
            shuffle(&rng, lab, n);
            block_sums(n, d2, lab, g, b);
            group_stats(n, g, b, cnt, sst, pm, &w);
            double fq = (sst - w) / (double)(g - 1) / (w / (double)(n - g));
            if (isfinite(f) && fq >= f - 1e-12 * fabs(f)) fge++;
            for (int64_t t = 0; t < g * g; t++)
                if (pm[t] >= md2[t] * (1 - 1e-12)) cntge[t] += 1;
            if ((q & 255) == 0 && (rc = es__progress(ctx, "group permutations", q, permutations)))
                goto done;
        }
        es__progress(ctx, "group permutations", permutations, permutations);
    }
    for (int64_t a = 0; a < g; a++)
        for (int64_t c = 0; c < g; c++) {
            if (mean_dist) mean_dist[a + c * g] = sqrt(md2[a + c * g]);
            if (p_pair)
                p_pair[a + c * g] = a == c ? 1.0 : permutations > 0
                    ? (1.0 + cntge[a + c * g]) / (1.0 + (double)permutations) : NAN;
        }
    if (stats) {
        stats->ss_total = sst;
        stats->ss_within = ssw;
        stats->ss_between = ssb;
        stats->r2 = sst > 0 ? ssb / sst : NAN;
        stats->f = f;
        stats->p = permutations > 0 && isfinite(f) ? (1.0 + (double)fge) / (1.0 + (double)permutations)
                                                   : NAN;
    }
done:
    es__free(ctx, d2);
    es__free(ctx, lab);
    return rc;
}

/* Kendall's Riemannian distance of every pair: each configuration centred
 * and scaled to unit centroid size once (a copy), then per pair the d x d
 * cross-product's singular values (es__procrustes_rho), O(k d^2) a pair. */
es_status es_compare_rho(es_ctx *ctx, es_mat aligned, int d, int allow_reflection, es_mat rho)
{
    const int64_t kd = aligned.rows, n = aligned.cols;
    if ((d != 2 && d != 3) || kd < d || kd % d)
        ES_FAIL(ctx, ES_EINVAL, "compare: %lld coordinates are not configurations in %d "
                "dimensions", (long long)kd, d);
    if (rho.rows != n || rho.cols != n || rho.ld < n)
        ES_FAIL(ctx, ES_EMISMATCH, "compare: rho is %lld x %lld for %lld configurations",
                (long long)rho.rows, (long long)rho.cols, (long long)n);
    const int64_t k = kd / d;
    double *z = es__alloc_array(ctx, kd * (n > 0 ? n : 1), sizeof *z);
    if (!z) return ES_ENOMEM;
    es_status rc = ES_OK;
    for (int64_t j = 0; j < n && rc == ES_OK; j++) {
        double *zj = z + j * kd, ss = 0;
        for (int64_t v = 0; v < kd; v++) zj[v] = ES_AT(aligned, v, j);
        for (int c = 0; c < d; c++) {
            double m = 0;
            for (int64_t p = 0; p < k; p++) m += zj[p + c * k] / (double)k;
            for (int64_t p = 0; p < k; p++) zj[p + c * k] -= m, ss += zj[p + c * k] * zj[p + c * k];
        }
        if (!(ss > 0) || !isfinite(ss))
            rc = es__fail(ctx, ES_EINVAL, "compare: configuration %lld has no size (all its "
                          "points coincide) or a non-finite coordinate", (long long)j);
        for (int64_t v = 0; v < kd; v++) zj[v] /= sqrt(ss);
    }
    for (int64_t j = 0; j < n && rc == ES_OK; j++) {
        ES_AT(rho, j, j) = 0;
        for (int64_t i = 0; i < j && rc == ES_OK; i++) {
            double a[9], r = 0;
            es__procrustes_cross(k, d, z + i * kd, z + j * kd, a);
            rc = es__procrustes_rho(ctx, d, a, 1, 1, allow_reflection, &r);
            ES_AT(rho, i, j) = ES_AT(rho, j, i) = r;
        }
        es__progress(ctx, "compare: rho", j + 1, n);
    }
    es__free(ctx, z);
    return rc;
}
