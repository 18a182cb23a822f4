/* tools/bench/bench_pca.c — PCA of a synthetic shape set at the paper's FRGC
 * scale (600 shapes x 175,000 edges, Section 4 of Fisher et al.), against
 * numpy on the same matrix, algorithm for algorithm.
 *
 * Row i = (1 + basis * c_i + noise_i) / E: a rank-R variation with decaying
 * weights plus uniform noise, drawn from the seeded RNG. The matrix is made
 * once in memory and written to a temporary .npy; then, on that one matrix:
 *   exact, all components: es_pca_fit (Gram route) against numpy centring,
 *     G = A^T A, numpy.linalg.eigh(G), components A V / sqrt(w);
 *   exact, top 20: the same with 20 components;
 *   randomized top K: es_pca_fit (Halko et al. subspace iteration, p, q)
 *     against the same algorithm in numpy (Gaussian test matrix, q power
 *     iterations re-orthonormalized by QR, SVD of A^T Q).
 * Wall and CPU time of each (the median of --repeat runs: one run of a
 * second or two swings by 15 % on a shared 2-core machine), the ratio
 * numpy / ours, and the largest relative
 * difference of the top eigenvalues (numpy is the oracle). numpy runs under
 * /usr/bin/python3 (Debian's, with python3-numpy; the python3 first on PATH
 * may lack it); when it cannot run, the bench says so and why. Both sides
 * use the same OpenBLAS with the same thread count (OPENBLAS_NUM_THREADS, or
 * OpenBLAS's default: one per core) and the same worker spin: the short one
 * the edgespace command sets (tools/blas_spin.c), which numpy inherits;
 * both are printed. With OpenBLAS's default spin the workers burn CPU while
 * this side copies its chunks between the Gram matrix's products: top 20,
 * median of 5, 3.10 s CPU against numpy's 2.91; with the command's, 2.49
 * against 2.93.
 *
 *   bench_pca [--rows N] [--edges E] [--rank R] [--components K] [--repeat N]
 *             [--no-numpy]
 */

#include "edgespace/es_stats.h"

#include <cblas.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench_clock.h"
#include "blas_spin.h"

typedef struct gen {
    int64_t E, N, R;
    double *basis;   /* E x R */
    double *coef;    /* R x N */
    uint64_t seed;
    int64_t rows_read;
} gen;

static es_status gen_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n, es_mat out)
{
    gen *g = src->userdata;
    (void)ctx;
    /* noise: a splitmix64 hash of (seed, row, edge), cheap and the same on
     * every pass */
    for (int64_t j = 0; j < n; j++) {
        double *x = &ES_AT(out, 0, j);
        uint64_t base = g->seed + (uint64_t)(row0 + j) * (uint64_t)g->E;
        for (int64_t e = 0; e < g->E; e++) {
            uint64_t z = (base + (uint64_t)e) * 0x9e3779b97f4a7c15ull;
            z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
            z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
            z ^= z >> 31;
            x[e] = 1.0 + 0.01 * ((double)(z >> 11) * 0x1.0p-53 - 0.5);
        }
    }
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)g->E, (int)n, (int)g->R, 1.0,
                g->basis, (int)g->E, g->coef + row0 * g->R, (int)g->R, 1.0, out.data, (int)out.ld);
    for (int64_t j = 0; j < n; j++)
        for (int64_t e = 0; e < g->E; e++) ES_AT(out, e, j) /= (double)g->E;
    g->rows_read += n;
    return ES_OK;
}

static const char *loadavg(void)
{
    static char buf[64] = "?";
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (!fgets(buf, sizeof buf, f)) strcpy(buf, "?");
        fclose(f);
        buf[strcspn(buf, "\n")] = '\0';
    }
    return buf;
}

/* Stage timings from the progress callback: wall time from the previous
 * stage's end to this stage's last report. */
typedef struct stages {
    const char *what[8];
    double end[8];
    int n;
    double t0;
} stages;

static void on_progress(void *ud, const char *what, int64_t done, int64_t total)
{
    stages *st = ud;
    (void)done, (void)total;
    if (st->n == 0 || strcmp(st->what[st->n - 1], what)) {
        if (st->n == 8) return;
        st->what[st->n++] = what;
    }
    st->end[st->n - 1] = bench_wall_s();
}

static void print_stages(const stages *st)
{
    double prev = st->t0;
    printf("    stages:");
    for (int i = 0; i < st->n; i++) {
        printf(" %s %.2f s;", st->what[i], st->end[i] - prev);
        prev = st->end[i];
    }
    printf("\n");
}

#define PYTHON "/usr/bin/python3"

/* numpy's side, reading the matrix from argv[1]: the three timings and the
 * top eigenvalues of each, one line per method. */
static const char numpy_script[] =
    "import sys, time\n"
    "import numpy as np\n"
    "X = np.load(sys.argv[1]); K, p, q, seed, reps = (int(a) for a in sys.argv[2:7])\n"
    "E, N = X.shape\n"
    "def timed(name, f):\n"
    "    walls, cpus = [], []\n"
    "    for _ in range(reps):\n"
    "        t, c = time.perf_counter(), time.process_time()\n"
    "        w = f()\n"
    "        walls.append(time.perf_counter() - t); cpus.append(time.process_time() - c)\n"
    "    print(name, sorted(walls)[reps // 2], sorted(cpus)[reps // 2],\n"
    "          ' '.join(repr(float(v)) for v in w[:10]), flush=True)\n"
    "def gram(k):\n"
    "    A = X - X.mean(axis=1, keepdims=True)\n"
    "    w, V = np.linalg.eigh(A.T @ A)\n"
    "    w, V = w[::-1], V[:, ::-1]\n"
    "    r = min(int((w > max(E, N) * np.finfo(float).eps * w[0]).sum()), N - 1)\n"
    "    r = min(r, k) if k else r\n"
    "    U = A @ (V[:, :r] / np.sqrt(w[:r]))\n"
    "    return w[:r] / (N - 1)\n"
    "def randomized():\n"
    "    A = X - X.mean(axis=1, keepdims=True)\n"
    "    Y = A @ np.random.default_rng(seed).standard_normal((N, K + p))\n"
    "    for _ in range(q):\n"
    "        Q, _ = np.linalg.qr(Y)\n"
    "        Y = A @ (A.T @ Q)\n"
    "    Q, _ = np.linalg.qr(Y)\n"
    "    W, s, VT = np.linalg.svd(A.T @ Q, full_matrices=False)\n"
    "    U = Q @ VT[:K].T\n"
    "    return s[:K] ** 2 / (N - 1)\n"
    "timed('gram', lambda: gram(0))\n"
    "timed('top20', lambda: gram(20))\n"
    "timed('randomized', randomized)\n";

/* Why numpy cannot run, or NULL when it can. */
static const char *numpy_missing(void)
{
    if (access(PYTHON, X_OK) != 0) return PYTHON " is not installed";
    if (system(PYTHON " -c 'import numpy' >/dev/null 2>&1") != 0)
        return PYTHON " cannot import numpy (Debian package python3-numpy)";
    return NULL;
}

static int write_npy(const char *path, const double *X, int64_t E, int64_t N)
{
    FILE *f = fopen(path, "wb");
    char hdr[128];
    int hl = snprintf(hdr, sizeof hdr, "{'descr': '<f8', 'fortran_order': True, "
                      "'shape': (%lld, %lld), }", (long long)E, (long long)N);
    int pad = (64 - (10 + hl + 1) % 64) % 64, ok;
    unsigned short len = (unsigned short)(hl + pad + 1);
    if (!f) return -1;
    fwrite("\x93NUMPY\x01\x00", 1, 8, f);
    fputc(len & 0xff, f);
    fputc(len >> 8, f);
    fwrite(hdr, 1, (size_t)hl, f);
    for (int i = 0; i < pad; i++) fputc(' ', f);
    fputc('\n', f);
    ok = fwrite(X, sizeof(double), (size_t)(E * N), f) == (size_t)(E * N);
    return fclose(f) == 0 && ok ? 0 : -1;
}

typedef struct timing {
    double wall, cpu, eig[10];
    int neig;
} timing;

/* The fit `reps` times (at most 64): the last one's result, the median wall
 * and CPU time. */
static es_pca *fit(es_ctx *ctx, const es_source *src, const es_pca_opts *o, int reps, timing *t)
{
    es_pca *p = NULL;
    double wall[64], cpu[64];
    for (int r = 0; r < reps; r++) {
        es_pca_free(p);   /* the last run's, outside the clock */
        p = NULL;
        double w0 = bench_wall_s(), c0 = bench_process_cpu_s();
        if (es_pca_fit(ctx, src, o, &p) != ES_OK) {
            fprintf(stderr, "bench_pca: %s\n", es_ctx_errmsg(ctx));
            exit(1);
        }
        wall[r] = bench_wall_s() - w0;
        cpu[r] = bench_process_cpu_s() - c0;
    }
    t->wall = bench_median(wall, reps);
    t->cpu = bench_median(cpu, reps);
    t->neig = p->ncomp < 10 ? (int)p->ncomp : 10;
    for (int k = 0; k < t->neig; k++) t->eig[k] = p->eigenvalues[k];
    return p;
}

static void compare(const char *what, const timing *ours, const timing *np)
{
    double maxrel = 0;
    for (int k = 0; k < ours->neig && k < np->neig; k++) {
        double rel = fabs(ours->eig[k] - np->eig[k]) / fabs(np->eig[k]);
        if (rel > maxrel) maxrel = rel;
    }
    printf("  %-26s ours %7.2f s wall %7.2f s CPU | numpy %7.2f s wall %7.2f s CPU | "
           "numpy/ours wall %.2f, CPU %.2f | top eigenvalues differ by %.1e\n", what,
           ours->wall, ours->cpu, np->wall, np->cpu, np->wall / ours->wall, np->cpu / ours->cpu,
           maxrel);
}

int main(int argc, char **argv)
{
    int64_t N = 600, E = 175000, R = 20, K = 10;
    short_blas_spin(argv);
    int numpy = 1, reps = 1;
    static const struct option lo[] = {
        {"rows", required_argument, 0, 'n'}, {"edges", required_argument, 0, 'e'},
        {"rank", required_argument, 0, 'r'}, {"components", required_argument, 0, 'k'},
        {"repeat", required_argument, 0, 'R'}, {"no-numpy", no_argument, 0, 'x'},
        {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};
    int c;
    while ((c = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        switch (c) {
        case 'n': N = atoll(optarg); break;
        case 'e': E = atoll(optarg); break;
        case 'r': R = atoll(optarg); break;
        case 'k': K = atoll(optarg); break;
        case 'x': numpy = 0; break;
        case 'R':
            reps = atoi(optarg);
            if (reps < 1 || reps > 64) {
                fprintf(stderr, "bench_pca: --repeat %s: give 1 to 64 runs\n", optarg);
                return 2;
            }
            break;
        default:
            printf("usage: bench_pca [--rows N] [--edges E] [--rank R] [--components K] "
                   "[--repeat N] [--no-numpy]\n");
            return c == 'h' ? 0 : 2;
        }
    }
    es_ctx *ctx;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    gen g = {E, N, R, NULL, NULL, 12345, 0};
    g.basis = malloc((size_t)(E * R) * sizeof(double));
    g.coef = malloc((size_t)(R * N) * sizeof(double));
    es_rng rng;
    es_rng_init(&rng, 777);
    for (int64_t i = 0; i < E * R; i++) g.basis[i] = 0.02 * es_rng_normal(&rng);
    for (int64_t j = 0; j < N; j++)
        for (int64_t k = 0; k < R; k++) g.coef[k + j * R] = es_rng_normal(&rng) / (double)(k + 1);
    es_source src;
    memset(&src, 0, sizeof src);
    src.nedges = E;
    src.nrows = N;
    src.read = gen_read;
    src.userdata = &g;

    printf("bench_pca: %lld shapes x %lld edges (%.0f MiB as doubles), rank %lld + noise\n",
           (long long)N, (long long)E, (double)N * (double)E * 8 / 1048576.0, (long long)R);
    double *X = malloc((size_t)(E * N) * sizeof *X);
    if (!X) {
        fprintf(stderr, "bench_pca: cannot hold the %lld x %lld matrix\n", (long long)E,
                (long long)N);
        return 1;
    }
    gen_read(ctx, &src, 0, N, (es_mat){X, E, N, E});
    es_source mat = es_source_matrix((es_mat){X, E, N, E}, NULL, N);
    const char *threads = getenv("OPENBLAS_NUM_THREADS");
    const char *spin = getenv("OPENBLAS_THREAD_TIMEOUT");
    printf("  load average at start: %s; OpenBLAS threads: %s (%ld cores online), "
           "OPENBLAS_THREAD_TIMEOUT %s; times: the median of %d run%s\n", loadavg(),
           threads ? threads : "default", sysconf(_SC_NPROCESSORS_ONLN), spin ? spin : "unset",
           reps, reps == 1 ? "" : "s");

    es_pca_opts o;
    es_pca_opts_init(&o);
    timing t_exact, t_top, t_rnd, n_exact = {0}, n_top = {0}, n_rnd = {0};
    stages stg;
    memset(&stg, 0, sizeof stg);
    es_ctx_set_progress(ctx, on_progress, &stg);
    stg.t0 = bench_wall_s();
    es_pca *exact = fit(ctx, &mat, &o, 1, &t_exact);   /* one run's stages */
    es_ctx_set_progress(ctx, NULL, NULL);
    if (reps > 1) es_pca_free(fit(ctx, &mat, &o, reps, &t_exact));
    printf("  ours, exact (Gram route, %lld components): %.2f s wall, %.2f s CPU, peak RSS %.0f "
           "MiB\n", (long long)exact->ncomp, t_exact.wall, t_exact.cpu, bench_peak_rss_mib());
    print_stages(&stg);
    double cum = 0;
    for (int64_t k = 0; k < 3 && k < exact->ncomp; k++) cum += exact->explained[k];
    printf("    eigenvalues 1..3: %.6g %.6g %.6g; top 3 explain %.1f%% of the variance\n",
           exact->eigenvalues[0], exact->eigenvalues[1], exact->eigenvalues[2], 100 * cum);
    es_pca_opts ot = o;
    ot.ncomp = 20;
    es_pca_free(fit(ctx, &mat, &ot, reps, &t_top));
    o.method = ES_PCA_RANDOMIZED;
    o.ncomp = K;
    es_pca *rnd = fit(ctx, &mat, &o, reps, &t_rnd);
    double maxrel = 0;
    for (int64_t k = 0; k < K; k++) {
        double rel = fabs(rnd->eigenvalues[k] - exact->eigenvalues[k]) / exact->eigenvalues[k];
        if (rel > maxrel) maxrel = rel;
    }
    printf("  ours, randomized (top %lld, p=%lld, q=%lld): %.2f s wall, %.2f s CPU, max relative "
           "eigenvalue error against our exact fit %.2e\n", (long long)K, (long long)o.oversample,
           (long long)o.power_iters, t_rnd.wall, t_rnd.cpu, maxrel);

    const char *why = numpy ? numpy_missing() : "--no-numpy";
    char dir[] = "/tmp/bench_pca_XXXXXX", npy[64], py[64], cmd[512];
    if (!why && !mkdtemp(dir)) why = "cannot make a temporary folder";
    if (!why) {
        FILE *f;
        snprintf(npy, sizeof npy, "%s/X.npy", dir);
        snprintf(py, sizeof py, "%s/pca.py", dir);
        if (write_npy(npy, X, E, N) != 0 || !(f = fopen(py, "w")) ||
            fputs(numpy_script, f) < 0 || fclose(f) != 0)
            why = "cannot write the matrix and script to /tmp";
    }
    if (!why) {
        snprintf(cmd, sizeof cmd, PYTHON " %s %s %lld %lld %lld %llu %d", py, npy, (long long)K,
                 (long long)o.oversample, (long long)o.power_iters,
                 (unsigned long long)es_ctx_seed(ctx), reps);
        FILE *pp = popen(cmd, "r");
        char line[2048], name[32];
        int got = 0;
        while (pp && fgets(line, sizeof line, pp)) {
            timing t = {0};
            int off = 0;
            if (sscanf(line, "%31s %lf %lf%n", name, &t.wall, &t.cpu, &off) != 3) continue;
            for (char *q = line + off, *end; t.neig < 10; q = end) {
                t.eig[t.neig] = strtod(q, &end);
                if (end == q) break;
                t.neig++;
            }
            if (!strcmp(name, "gram")) n_exact = t, got++;
            else if (!strcmp(name, "top20")) n_top = t, got++;
            else if (!strcmp(name, "randomized")) n_rnd = t, got++;
        }
        if (!pp || pclose(pp) != 0 || got != 3) why = "the numpy script failed";
        remove(npy);
        remove(py);
        rmdir(dir);
    }
    if (why) {
        printf("  numpy comparison NOT run: %s\n", why);
    } else {
        printf("  on the same matrix, numpy under " PYTHON ":\n");
        compare("exact, all components:", &t_exact, &n_exact);
        compare("exact, top 20:", &t_top, &n_top);
        compare("randomized, top K:", &t_rnd, &n_rnd);
    }
    es_pca_free(exact);
    es_pca_free(rnd);
    free(X);
    free(g.basis);
    free(g.coef);
    es_ctx_free(ctx);
    return 0;
}
