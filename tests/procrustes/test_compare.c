/* tests/procrustes/test_compare.c — distance-matrix comparison statistics on small
 * cases with known answers: distances (and scale normalization), Spearman
 * (hand-computed, with ties), the Mantel p-value against the exact
 * permutation distribution, nearest neighbours, rank disagreement, group
 * means and the F test against direct computation from coordinates. */
#include "core/core_private.h"
#include "es_test.h"
#include "edgespace/edgespace.h"

/* fontconfig (under cairo's text) keeps its caches until exit; not ours.
 * LeakSanitizer reads this hook in -Db_sanitize=address builds. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig\n"; }

static void test_distances(es_ctx *ctx)
{
    /* three points in 2D: (0,0), (3,4), (6,8); and scaled copies */
    double x[6] = {0, 0, 3, 4, 6, 8}, d[9];
    ES_CHECK_OK(ctx, es_compare_distances(ctx, (es_mat){x, 2, 3, 2}, 0, (es_mat){d, 3, 3, 3}));
    ES_CHECK_CLOSE(d[1], 5, 1e-14, 0);
    ES_CHECK_CLOSE(d[2], 10, 1e-14, 0);
    ES_CHECK_CLOSE(d[5], 5, 1e-14, 0);
    ES_CHECK(d[0] == 0 && d[3] == d[1]);
    /* normalized: (1,1) and (2,2) are the same point (0.5, 0.5) */
    double y[6] = {1, 1, 2, 2, 1, 3};
    ES_CHECK_OK(ctx, es_compare_distances(ctx, (es_mat){y, 2, 3, 2}, 1, (es_mat){d, 3, 3, 3}));
    ES_CHECK_CLOSE(d[1], 0, 0, 1e-15);
    ES_CHECK_CLOSE(d[2], sqrt(2 * 0.25 * 0.25), 1e-13, 0);
    ES_CHECK(y[2] == 2);   /* input untouched */
    /* accuracy for nearly equal large vectors (the Gram route centres first) */
    int64_t p = 5000;
    double *z = malloc((size_t)(3 * p) * sizeof *z);
    for (int64_t v = 0; v < p; v++) {
        z[v] = 1e6 + (double)v;
        z[p + v] = z[v] + (v == 7 ? 1e-3 : 0);
        z[2 * p + v] = z[v] + (v == 9 ? 2e-3 : 0);
    }
    ES_CHECK_OK(ctx, es_compare_distances(ctx, (es_mat){z, p, 3, p}, 0, (es_mat){d, 3, 3, 3}));
    ES_CHECK_CLOSE(d[1], 1e-3, 1e-6, 0);
    ES_CHECK_CLOSE(d[5], sqrt(5) * 1e-3, 1e-6, 0);
    z[0] = -z[0] - 2 * (double)(p - 1) * 1e6;   /* a column summing to ~0 cannot be normalized */
    (void)z;
    free(z);
    double w[4] = {1, -1, 2, 2};
    ES_CHECK_FAILS(ctx, es_compare_distances(ctx, (es_mat){w, 2, 2, 2}, 1, (es_mat){d, 2, 2, 2}),
                   ES_EINVAL, "column 0 sums to 0");
}

/* distance matrix from an upper triangle listed column by column */
static void from_upper(int64_t n, const double *u, double *d)
{
    memset(d, 0, (size_t)(n * n) * sizeof *d);
    for (int64_t j = 1, t = 0; j < n; j++)
        for (int64_t i = 0; i < j; i++, t++) d[i + j * n] = d[j + i * n] = u[t];
}

static double spearman_perm(int64_t n, const double *d1, const double *d2, const int64_t *perm)
{
    /* direct Spearman with average ranks, by brute force (n small) */
    int64_t m = n * (n - 1) / 2;
    double a[64], b[64], ra[64], rb[64];
    for (int64_t j = 1, t = 0; j < n; j++)
        for (int64_t i = 0; i < j; i++, t++) {
            a[t] = d1[i + j * n];
            b[t] = d2[perm[i] + perm[j] * n];
        }
    for (int64_t t = 0; t < m; t++) {
        double lo = 0, eq = 0, lo2 = 0, eq2 = 0;
        for (int64_t s = 0; s < m; s++) {
            lo += a[s] < a[t]; eq += a[s] == a[t];
            lo2 += b[s] < b[t]; eq2 += b[s] == b[t];
        }
        ra[t] = lo + (eq + 1) / 2;
        rb[t] = lo2 + (eq2 + 1) / 2;
    }
    double ma = 0, mb = 0, sab = 0, saa = 0, sbb = 0;
    for (int64_t t = 0; t < m; t++) { ma += ra[t] / (double)m; mb += rb[t] / (double)m; }
    for (int64_t t = 0; t < m; t++) {
        sab += (ra[t] - ma) * (rb[t] - mb);
        saa += (ra[t] - ma) * (ra[t] - ma);
        sbb += (rb[t] - mb) * (rb[t] - mb);
    }
    return sab / sqrt(saa * sbb);
}

static int next_perm(int64_t *a, int64_t n)
{
    int64_t i = n - 2;
    while (i >= 0 && a[i] >= a[i + 1]) i--;
    if (i < 0) return 0;
    int64_t j = n - 1;
    while (a[j] <= a[i]) j--;
    int64_t t = a[i]; a[i] = a[j]; a[j] = t;
    for (int64_t l = i + 1, r = n - 1; l < r; l++, r--) { t = a[l]; a[l] = a[r]; a[r] = t; }
    return 1;
}

static void test_mantel(es_ctx *ctx)
{
    double d1[9], d2[9], rho, p;
    /* hand-computed: ranks (1,2,3) vs (1,3,2): 1 - 6*2/(3*8) = 0.5 */
    from_upper(3, (double[]){1, 2, 3}, d1);
    from_upper(3, (double[]){1, 3, 2}, d2);
    ES_CHECK_OK(ctx, es_compare_mantel(ctx, 3, d1, d2, 0, &rho, &p));
    ES_CHECK_CLOSE(rho, 0.5, 1e-14, 0);
    ES_CHECK(isnan(p));
    /* ties: (1,2,3) vs (1,1,2) -> 1.5 / sqrt(2 * 1.5) */
    from_upper(3, (double[]){1, 1, 2}, d2);
    ES_CHECK_OK(ctx, es_compare_mantel(ctx, 3, d1, d2, 0, &rho, NULL));
    ES_CHECK_CLOSE(rho, 1.5 / sqrt(3.0), 1e-14, 0);

    /* n = 6: the permutation p-value converges to the exact one over all
     * 720 relabellings */
    es_rng rng;
    es_rng_init(&rng, 21);
    int64_t n = 6;
    double a[36], b[36], u1[15], u2[15];
    for (int t = 0; t < 15; t++) {
        u1[t] = es_rng_uniform(&rng);
        u2[t] = u1[t] + 1.5 * es_rng_uniform(&rng);
    }
    from_upper(n, u1, a);
    from_upper(n, u2, b);
    int64_t perm[6] = {0, 1, 2, 3, 4, 5};
    double obs = spearman_perm(n, a, b, perm);
    int64_t ge = 0, tot = 0;
    do {
        ge += spearman_perm(n, a, b, perm) >= obs - 1e-12;
        tot++;
    } while (next_perm(perm, n));
    double exact = (double)ge / (double)tot;
    ES_CHECK_OK(ctx, es_compare_mantel(ctx, n, a, b, 40000, &rho, &p));
    ES_CHECK_CLOSE(rho, obs, 1e-12, 0);
    ES_CHECK_MSG(fabs(p - exact) < 0.006, "Mantel p %g, exact %g", p, exact);
    ES_CHECK(exact > 0.002 && exact < 0.5);
    /* same seed, same p; a monotone transform keeps rho = 1 */
    double p2;
    ES_CHECK_OK(ctx, es_compare_mantel(ctx, n, a, b, 40000, &rho, &p2));
    ES_CHECK(p2 == p);
    for (int i = 0; i < 36; i++) b[i] = a[i] * a[i] * a[i];
    ES_CHECK_OK(ctx, es_compare_mantel(ctx, n, a, b, 999, &rho, &p));
    ES_CHECK_CLOSE(rho, 1.0, 1e-14, 0);
    ES_CHECK(p <= 5.0 / 1000);
    for (int i = 0; i < 36; i++) b[i] = 1.0 - (i % 7 == 0);
    ES_CHECK_FAILS(ctx, es_compare_mantel(ctx, 2, a, b, 9, &rho, &p), ES_EINVAL, "at least 3");
}

static void test_nn_disagreement(es_ctx *ctx)
{
    /* points on a line: 0, 1, 3, 7 and 0, 1, 2.5, 2.6 */
    double p1[4] = {0, 1, 3, 7}, p2[4] = {0, 1, 2.5, 2.6}, d1[16], d2[16], ag;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            d1[i + 4 * j] = fabs(p1[i] - p1[j]);
            d2[i + 4 * j] = fabs(p2[i] - p2[j]);
        }
    int64_t nn1[4], nn2[4];
    ES_CHECK_OK(ctx, es_compare_nn_agreement(ctx, 4, d1, d2, nn1, nn2, &ag));
    ES_CHECK(nn1[0] == 1 && nn1[1] == 0 && nn1[2] == 1 && nn1[3] == 2);
    ES_CHECK(nn2[0] == 1 && nn2[1] == 0 && nn2[2] == 3 && nn2[3] == 2);
    ES_CHECK_CLOSE(ag, 0.75, 0, 0);
    /* identical spaces but pair (2,3) made the farthest in space 1 */
    double e1[16];
    memcpy(e1, d2, sizeof e1);
    e1[2 + 4 * 3] = e1[3 + 4 * 2] = 100;
    int64_t pairs[4];
    double diff[2];
    ES_CHECK_OK(ctx, es_compare_disagreement(ctx, 4, e1, d2, 2, pairs, diff));
    ES_CHECK(pairs[0] == 2 && pairs[1] == 3);
    /* (2,3): rank 6 of 6 in space 1, rank 1 in space 2: (6 - 1) / 5 */
    ES_CHECK_CLOSE(diff[0], 1.0, 1e-14, 0);
    ES_CHECK(fabs(diff[1]) < diff[0]);
}

static void test_groups(es_ctx *ctx)
{
    es_rng rng;
    es_rng_init(&rng, 8);
    int64_t n = 20, g = 3, p = 4, lab[20];
    double x[80], d[400], md[9], pp[9];
    for (int64_t j = 0; j < n; j++) {
        lab[j] = j % 3;
        for (int64_t v = 0; v < p; v++)
            x[v + j * p] = es_rng_normal(&rng) + (lab[j] == 1 && v == 0 ? 6.0 : 0.0) +
                           (lab[j] == 2 && v == 1 ? 0.2 : 0.0);
    }
    ES_CHECK_OK(ctx, es_compare_distances(ctx, (es_mat){x, p, n, p}, 0, (es_mat){d, n, n, n}));
    es_group_stats st;
    ES_CHECK_OK(ctx, es_compare_groups(ctx, n, d, lab, g, 1999, md, pp, &st));
    /* direct computation from coordinates */
    double m[3][4] = {{0}}, gm[4] = {0}, cnt[3] = {0}, ssw = 0, sst = 0;
    for (int64_t j = 0; j < n; j++) {
        cnt[lab[j]]++;
        for (int64_t v = 0; v < p; v++) { m[lab[j]][v] += x[v + j * p]; gm[v] += x[v + j * p] / (double)n; }
    }
    for (int a = 0; a < 3; a++)
        for (int64_t v = 0; v < p; v++) m[a][v] /= cnt[a];
    for (int64_t j = 0; j < n; j++)
        for (int64_t v = 0; v < p; v++) {
            ssw += pow(x[v + j * p] - m[lab[j]][v], 2);
            sst += pow(x[v + j * p] - gm[v], 2);
        }
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++) {
            double dd = 0;
            for (int64_t v = 0; v < p; v++) dd += pow(m[a][v] - m[c][v], 2);
            ES_CHECK_CLOSE(md[a + 3 * c], sqrt(dd), 1e-10, 1e-12);
        }
    ES_CHECK_CLOSE(st.ss_total, sst, 1e-12, 0);
    ES_CHECK_CLOSE(st.ss_within, ssw, 1e-12, 0);
    double f = ((sst - ssw) / 2) / (ssw / 17);
    ES_CHECK_CLOSE(st.f, f, 1e-10, 0);
    ES_CHECK_CLOSE(st.r2, (sst - ssw) / sst, 1e-12, 0);
    /* group 1 is far from the others; groups 0 and 2 hardly differ */
    ES_CHECK(st.p <= 2.0 / 2000);
    ES_CHECK(pp[0 + 3 * 1] <= 2.0 / 2000 && pp[1 + 3 * 2] <= 2.0 / 2000);
    ES_CHECK_MSG(pp[0 + 3 * 2] > 0.05, "p(0,2) = %g", pp[0 + 3 * 2]);
    ES_CHECK(pp[0] == 1.0);
    lab[4] = 3;
    ES_CHECK_FAILS(ctx, es_compare_groups(ctx, n, d, lab, g, 9, md, pp, &st), ES_EINVAL,
                   "specimen 4 has group 3");
    lab[4] = 1;
    for (int64_t j = 0; j < n; j++) lab[j] = j % 2;
    ES_CHECK_FAILS(ctx, es_compare_groups(ctx, n, d, lab, 3, 9, md, pp, &st), ES_EINVAL,
                   "group 2 is empty");
}

static int64_t count_lines(const char *path)
{
    FILE *f = fopen(path, "r");
    int64_t n = 0;
    int c;
    if (!f) return -1;
    while ((c = fgetc(f)) != EOF) n += c == '\n';
    fclose(f);
    return n;
}

/* The whole study on landmark triangles: truss lengths of a complete graph
 * and GPA-aligned configurations of two groups, outputs written. */
static void test_study(es_ctx *ctx)
{
    es_rng rng;
    es_rng_init(&rng, 31);
    int64_t n = 12, k = 5, d = 2, kd = k * d, ne = k * (k - 1) / 2;
    es_landmarks lm = {0};
    double xyz[120], len[120], aligned[120];
    int64_t edges[20], group[12];
    for (int64_t j = 0, e = 0; j < k; j++)
        for (int64_t i = 0; i < j; i++, e++) { edges[2 * e] = i; edges[2 * e + 1] = j; }
    for (int64_t j = 0; j < n; j++) {
        group[j] = j < 6 ? 0 : 1;
        for (int64_t v = 0; v < kd; v++)
            xyz[v + j * kd] = (double)((v * 7) % 5) + 0.05 * es_rng_normal(&rng) +
                              (group[j] && v == 0 ? 0.8 : 0.0);
    }
    lm.n = n; lm.k = k; lm.d = (int)d; lm.xyz = xyz;
    ES_CHECK_OK(ctx, es_landmarks_truss_lengths(ctx, &lm, ne, edges, (es_mat){len, ne, n, ne}));
    ES_CHECK_CLOSE(len[0], hypot(xyz[0] - xyz[1], xyz[5] - xyz[6]), 1e-15, 0);
    int64_t bad[2] = {0, 5};
    ES_CHECK_FAILS(ctx, es_landmarks_truss_lengths(ctx, &lm, 1, bad, (es_mat){len, 1, n, 1}),
                   ES_EINVAL, "edge 1 joins landmarks 1 and 6");
    memcpy(aligned, xyz, sizeof aligned);
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, (int)d, (es_mat){aligned, kd, n, kd}, NULL, NULL, NULL));
    es_compare_opts o;
    es_compare_opts_init(&o);
    o.permutations = 499;
    o.top_pairs = 5;
    es_compare_result *r = NULL;
    ES_CHECK_OK(ctx, es_compare_study(ctx, (es_mat){len, ne, n, ne}, (es_mat){aligned, kd, n, kd},
                                      group, 2, &o, &r));
    if (!r) return;
    /* both spaces see the group difference */
    ES_CHECK(r->groups_len.p <= 0.02 && r->groups_proc.p <= 0.02);
    ES_CHECK(r->mantel_rho > 0.3 && r->mantel_p <= 0.01);
    ES_CHECK(r->ntop == 5 && r->nn_agreement >= 0 && r->nn_agreement <= 1);
    double rho2;
    ES_CHECK_OK(ctx, es_compare_mantel(ctx, n, r->d_len, r->d_proc, 0, &rho2, NULL));
    ES_CHECK(rho2 == r->mantel_rho);
    char dir[256];
    snprintf(dir, sizeof dir, "%s/test-compare-out/study", ES_BUILD_ROOT);
    const char *ids[12] = {"a", "b", "c", "d", "e", "f", "g,1", "h", "i", "j", "k", "l"};
    const char *gn[2] = {"one", "two"};
    ES_CHECK_OK(ctx, es_study_compare_write(ctx, r, ids, group, gn, dir));
#if ES_HAVE_FIGURES
    ES_CHECK_OK(ctx, es_figure_compare_write(ctx, r, ids, group, gn, dir, NULL));
#endif
    char path[512];
    static const struct { const char *f; int64_t lines; } files[] = {
        {"distances_lengths.csv", 13}, {"distances_procrustes.csv", 13}, {"pairs.csv", 67},
        {"nearest.csv", 13}, {"disagreement.csv", 6}, {"group_means.csv", 3},
        {"summary.csv", 11}, {"heatmap_lengths.svg", -1}, {"heatmap_procrustes.svg", -1},
        {"pairs_scatter.svg", -1}};
    for (size_t i = 0; i < sizeof files / sizeof files[0] - (ES_HAVE_FIGURES ? 0 : 3); i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i].f);
        int64_t l = count_lines(path);
        ES_CHECK_MSG(files[i].lines < 0 ? l > 0 : l == files[i].lines, "%s: %lld lines",
                     files[i].f, (long long)l);
    }
    es_compare_result_free(r);
    ES_CHECK_FAILS(ctx, es_compare_study(ctx, (es_mat){len, ne, n, ne},
                                         (es_mat){aligned, kd, n - 1, kd}, NULL, 0, &o, &r),
                   ES_EMISMATCH, "12 edge-length vectors but 11 configurations");
}

/* rho against R's shapes 1.2.7 (riemdist, Dryden's package):
 *   x <- rbind(c(0,0,0), c(1,0,0), c(0,1,0), c(0,0,1), c(1,1,1))
 *   y <- x + 3 * rbind(c(.1,0,0), c(0,.2,0), c(0,0,.1), c(.05,0,0), c(0,0,.3))
 *   m <- x; m[,1] <- -m[,1]                     # x mirrored
 *   p <- rbind(c(0,0), c(2,0), c(1,1.5), c(.3,2))
 *   q <- rbind(c(1,1), c(3,1.2), c(2.1,2), c(1,3.5))
 *   riemdist(x, y); riemdist(x, m); riemdist(x, m, reflect = TRUE); riemdist(p, q)
 * (python/tests/test_compare_units.py runs R live on a whole study). */
static void test_rho_against_r(es_ctx *ctx)
{
    static const double x[15] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 0, 1, 1};
    static const double dy[15] = {.1, 0, 0, .05, 0, 0, .2, 0, 0, 0, 0, 0, .1, 0, .3};
    double cfg[3 * 15], rho[9];
    for (int v = 0; v < 15; v++) {
        cfg[v] = x[v];
        cfg[15 + v] = x[v] + 3 * dy[v];
        cfg[30 + v] = v < 5 ? -x[v] : x[v];   /* mirrored in the first coordinate */
    }
    es_mat al = {cfg, 15, 3, 15}, r = {rho, 3, 3, 3};
    ES_CHECK_OK(ctx, es_compare_rho(ctx, al, 3, 0, r));
    ES_CHECK_CLOSE(rho[1 * 3 + 0], 0.290002254625452, 1e-12, 0);
    ES_CHECK_CLOSE(rho[2 * 3 + 0], 1.11024233511357, 1e-12, 0);
    ES_CHECK(rho[0] == 0 && rho[3 + 0] == rho[1]);
    ES_CHECK_OK(ctx, es_compare_rho(ctx, al, 3, 1, r));
    ES_CHECK(fabs(rho[2 * 3 + 0]) < 1e-6);   /* R: 2.1e-08 */
    static const double pq[16] = {0, 2, 1, .3, 0, 0, 1.5, 2, 1, 3, 2.1, 1, 1, 1.2, 2, 3.5};
    ES_CHECK_OK(ctx, es_compare_rho(ctx, (es_mat){(double *)pq, 8, 2, 8}, 2, 0,
                                    (es_mat){rho, 2, 2, 2}));
    ES_CHECK_CLOSE(rho[2], 0.305578949731456, 1e-12, 0);
    /* invariant to scale: the same pair, one of them 7 times larger */
    double big[16];
    for (int v = 0; v < 16; v++) big[v] = v < 8 ? pq[v] : 7 * pq[v];
    ES_CHECK_OK(ctx, es_compare_rho(ctx, (es_mat){big, 8, 2, 8}, 2, 0, (es_mat){rho, 2, 2, 2}));
    ES_CHECK_CLOSE(rho[2], 0.305578949731456, 1e-12, 0);
    ES_CHECK_FAILS(ctx, es_compare_rho(ctx, al, 4, 0, r), ES_EINVAL, "dimensions");
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_distances(ctx);
    test_mantel(ctx);
    test_nn_disagreement(ctx);
    test_groups(ctx);
    test_study(ctx);
    test_rho_against_r(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
