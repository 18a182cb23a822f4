/* tests/parallel/parallel_counts.c — what each route of the library costs a
 * rank on small data, counted as it runs, for check_cost_model.py (which
 * runs this under mpirun at P = 1, 2, 4 and compares every count with
 * tools/bench/cost_model.py's formulas for the same sizes).
 *
 * Usage: parallel_counts DIR. Every rank writes DIR/rank-<r>.txt, one line
 * per route: `route=NAME P=.. rank=..` and the sizes the model takes, then
 * what was counted: read (bytes this rank read: counted in the row source's
 * callback for PCA; for ingest the library's own count of mesh-file bytes,
 * es_ingest_report.bytes_read_rank, whose files' sizes the line lists), and
 * messages and sent (what this rank sent in the library's collectives,
 * es_parallel_traffic, before and after the call). Routes: PCA's Gram
 * route on rows exchanged all-to-all, the randomized route, GPA on the exact
 * and the power-iteration Ten Berge routes and partial GPA (es_gpa_align_ranks;
 * each rank is handed its share, so GPA reads nothing here), and ingest of
 * tori into a new store and appended to it (three inputs already in it).
 * Results are checked elsewhere (tests/parallel/test_parallel_*.c): here
 * only that every call succeeds. */
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_meshes.h"
#include "es_test_parallel.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static FILE *out;
static int P, me;

/* A seeded E x N matrix of lengths, rows read through a counting callback. */
typedef struct rows {
    int64_t E, N;
    double *X;
    int64_t bytes;   /* read so far by this rank */
} rows;

static es_status read_rows(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n, es_mat o)
{
    rows *d = src->userdata;
    (void)ctx;
    for (int64_t j = 0; j < n; j++)
        memcpy(&ES_AT(o, 0, j), d->X + (row0 + j) * d->E, (size_t)d->E * sizeof(double));
    d->bytes += 8 * d->E * n;
    return ES_OK;
}

/* What the job's context sent since *m, *b (updated to now). */
static void traffic_since(es_ctx *job, int64_t *m, int64_t *b)
{
    int64_t m1, b1;
    es_parallel_traffic(job, &m1, &b1);
    *m = m1 - *m;
    *b = b1 - *b;
}

static void pca_route(es_ctx *job, rows *d, es_pca_method method, int64_t K, int64_t block,
                      const char *name)
{
    es_source src = {d->E, d->N, read_rows, d, block, {0}, NULL};
    es_pca_opts o;
    es_pca *p = NULL;
    int64_t m = 0, b = 0;
    es_pca_opts_init(&o);
    o.method = method;
    o.ncomp = K;
    d->bytes = 0;
    es_parallel_traffic(job, &m, &b);
    ES_CHECK_OK(job, es_pca_fit(job, &src, &o, &p));
    traffic_since(job, &m, &b);
    /* the Gram route sends the components it found (K, or fewer for a
     * rank-deficient matrix); the randomized one the K asked for */
    fprintf(out, "route=%s P=%d rank=%d N=%lld E=%lld K=%lld block=%lld oversample=%lld "
            "power=%lld read=%lld messages=%lld sent=%lld\n", name, P, me, (long long)d->N,
            (long long)d->E, (long long)(method == ES_PCA_GRAM && p ? p->ncomp : K),
            (long long)block, (long long)o.oversample, (long long)o.power_iters,
            (long long)d->bytes, (long long)m, (long long)b);
    es_pca_free(p);
}

static void gpa_route(es_ctx *job, int64_t k, int d, int64_t n, int scale, const char *name)
{
    const int64_t kd = k * d;
    int64_t lo, hi, m = 0, b = 0;
    es_gpa_opts o;
    es_gpa_report rep;
    es_parallel_share(job, n, &lo, &hi);
    double *x = es_test_configurations(k, d, n, 11 + (uint64_t)n);
    double *mine = malloc((size_t)(kd * (hi - lo) + 1) * 8);
    double *res = calloc((size_t)(kd + (3 + d * d + d) * n), sizeof *res);
    /* every output, as `edgespace gpa` asks for them (lib/study/gpa_store.c) */
    es_gpa_out go = {res, res + kd, res + kd + n, res + kd + 2 * n, res + kd + 3 * n,
                     res + kd + (3 + d * d) * n};
    memcpy(mine, x + lo * kd, (size_t)(kd * (hi - lo)) * sizeof *x);
    es_gpa_opts_init(&o);
    o.scale = scale;
    memset(&rep, 0, sizeof rep);
    es_parallel_traffic(job, &m, &b);
    ES_CHECK_OK(job, es_gpa_align_ranks(job, k, d, n, (es_mat){mine, kd, hi - lo, kd}, &o, &go,
                                        &rep));
    traffic_since(job, &m, &b);
    fprintf(out, "route=%s P=%d rank=%d n=%lld k=%lld d=%d scale=%d iterations=%lld "
            "power_steps=%lld messages=%lld sent=%lld\n", name, P, me, (long long)n, (long long)k,
            d, scale, (long long)rep.iterations, (long long)rep.power_steps, (long long)m,
            (long long)b);
    free(x);
    free(mine);
    free(res);
}

/* The store's working copy, looked for in its directory when rank 0
 * reports "writing store" (before the commit renames it): the bytes of its
 * path with the NUL, which rank 0 broadcasts. Its name holds the pid and the
 * clock (lib/store/store_publish.c), so the model takes its length from here. */
typedef struct work_copy {
    const char *dir, *base;
    int64_t bytes;
} work_copy;

static void find_work_copy(void *ud, const char *what, int64_t done, int64_t total)
{
    work_copy *w = ud;
    char prefix[300];
    (void)total;
    if (strcmp(what, "writing store") != 0 || done != 0) return;
    snprintf(prefix, sizeof prefix, ".%s.tmp-", w->base);
    DIR *d = opendir(w->dir);
    for (struct dirent *e; d && (e = readdir(d));)
        if (!strncmp(e->d_name, prefix, strlen(prefix)))
            w->bytes = (int64_t)(strlen(w->dir) + 1 + strlen(e->d_name) + 1);
    if (d) closedir(d);
}

/* Ingest files[0 .. n) into DIR/store.h5; known[i]: the store has input i already. */
static void ingest_route(es_ctx *job, const char *dir, char **files, const int *known, int64_t n,
                         int64_t block, const char *name)
{
    es_ingest_opts o;
    es_ingest_report rep;
    int64_t m = 0, b = 0;
    char store[4096];
    work_copy w = {dir, "store.h5", 0};
    snprintf(store, sizeof store, "%s/%s", dir, w.base);
    es_ctx_set_progress(job, find_work_copy, &w);
    es_ingest_opts_init(&o);
    o.block_rows = block;
    o.threads = 1;
    memset(&rep, 0, sizeof rep);
    es_parallel_traffic(job, &m, &b);
    ES_CHECK_OK(job, es_ingest_files(job, store, n, (const char *const *)files, &o, &rep));
    traffic_since(job, &m, &b);
    es_ctx_set_progress(job, NULL, NULL);
    es_store *st = NULL;
    int64_t V = 0, E = 0, F = 0;
    ES_CHECK_OK(job, es_store_open(job, store, ES_STORE_READ, &st));
    if (st) {
        V = es_store_nverts(st);
        E = es_store_nedges(st);
        F = es_store_nfaces(st);
        es_store_close(st);
    }
    fprintf(out, "route=%s P=%d rank=%d N=%lld V=%lld E=%lld F=%lld block=%lld created=%d "
            "store=%s work_path=%lld sizes=", name, P, me, (long long)n, (long long)V, (long long)E,
            (long long)F, (long long)block, rep.created, store, (long long)w.bytes);
    for (int64_t i = 0; i < n; i++) {
        struct stat sb;
        ES_CHECK(stat(files[i], &sb) == 0);
        fprintf(out, "%s%lld", i ? "," : "", (long long)sb.st_size);
    }
    fprintf(out, " known=");
    for (int64_t i = 0; i < n; i++) fprintf(out, "%s%d", i ? "," : "", known[i]);
    fprintf(out, " read=%lld messages=%lld sent=%lld\n", (long long)rep.bytes_read_rank,
            (long long)m, (long long)b);
}

int main(int argc, char **argv)
{
    ES_TEST_BEGIN();
    es_test_job run;
    es_test_job_begin(&run, &argc, &argv);
    P = run.P;
    me = run.me;
    if (argc < 2) ES_TEST_SKIP("give the directory for the counts");
    const char *dir = argv[1];
    char path[4096];
    snprintf(path, sizeof path, "%s/rank-%d.txt", dir, me);
    if (!(out = fopen(path, "w"))) {
        fprintf(stderr, "cannot write %s\n", path);
        return 1;
    }
    es_ctx_set_seed(run.job, 5);

    /* PCA: 61 rows (they do not split evenly) of 300 edges, 7 rows a round */
    rows d = {300, 61, malloc(300 * 61 * sizeof(double)), 0};
    {
        es_rng rng;
        es_rng_init(&rng, 2027);
        for (int64_t j = 0; j < d.N; j++)
            for (int64_t e = 0; e < d.E; e++)
                d.X[e + j * d.E] = 1.0 + 0.05 * sin(0.7 * (double)(j + 1) * (double)(e % 5 + 1)) +
                                   0.002 * es_rng_normal(&rng);
    }
    pca_route(run.job, &d, ES_PCA_GRAM, 8, 7, "pca_gram");
    pca_route(run.job, &d, ES_PCA_RANDOMIZED, 5, 7, "pca_randomized");
    free(d.X);

    /* GPA: 61^2 x 120 <= 2e8 (exact: rank 0 decomposes), 203^2 x 5100 > 2e8 (power) */
    gpa_route(run.job, 40, 3, 61, 1, "gpa_exact");
    gpa_route(run.job, 1700, 3, 203, 1, "gpa_power");
    gpa_route(run.job, 25, 2, 61, 0, "gpa_partial");

    /* ingest: 11 tori into a new store (2 rows a round), then 8 new and 3
     * it has (read again for their hash, skipped) appended, 3 a round */
    char *files[11], *more[11];
    int none[11] = {0}, known[11] = {0};
    for (int i = 0; i < 11; i++) {
        files[i] = malloc(4096);
        more[i] = malloc(4096);
        snprintf(files[i], 4096, "%s/t%d.obj", dir, i);
        if (i % 4 == 1) {   /* t1, t5, t9 again */
            snprintf(more[i], 4096, "%s/t%d.obj", dir, i);
            known[i] = 1;
        } else {
            snprintf(more[i], 4096, "%s/u%d.obj", dir, i);
        }
        if (me == 0) {
            ES_CHECK(es_test_write_torus(files[i], 14, 8, i) == 0);
            if (!known[i]) ES_CHECK(es_test_write_torus(more[i], 14, 8, 20 + i) == 0);
        }
    }
    ES_CHECK_OK(run.job, es_parallel_barrier(run.job));   /* the files are there for every rank */
    ingest_route(run.job, dir, files, none, 11, 2, "ingest_new");
    ingest_route(run.job, dir, more, known, 11, 3, "ingest_append");
    for (int i = 0; i < 11; i++) {
        free(files[i]);
        free(more[i]);
    }
    ES_CHECK(fclose(out) == 0);
    return es_test_job_end(&run);
}
