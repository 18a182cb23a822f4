/* tests/ingest/test_landmarks_r.c — every landmark array of R's shapes
 * package (brains, dna.dat, the great apes, ...), exported by R
 * (tests/ingest/export_rshapes.R) as long CSV + specimens CSV with ids
 * "brains_001" ..., rows and specimens shuffled, and read back. brains and
 * dna are the tables the old specimens map refused ("listed twice") though
 * no id repeats. The oracle is R: the array's dimensions, its sum and sum of
 * squares, and its first and last elements, computed by R on the array
 * itself, not on the file. Skipped with a message when Rscript or the shapes
 * package (Debian r-cran-shapes, installed by tools/setup.sh) is missing. */
#include "es_test.h"
#include "es_test_files.h"
#include "edgespace/edgespace.h"

#include <dirent.h>
#include <math.h>
#include <stdlib.h>

static int64_t find_id(const es_landmarks *lm, const char *id)
{
    for (int64_t j = 0; j < lm->n; j++)
        if (!strcmp(lm->ids[j], id)) return j;
    return -1;
}

/* One exported array against R's figures for it. */
static void check_table(es_ctx *ctx, const char *dir, const char *base)
{
    char lpath[4400], spath[4400], opath[4400], first[340], last[340];
    double n, k, d, sum, sumsq, x0, x1;
    snprintf(lpath, sizeof lpath, "%s/%s_landmarks.csv", dir, base);
    snprintf(spath, sizeof spath, "%s/%s_specimens.csv", dir, base);
    snprintf(opath, sizeof opath, "%s/%s_oracle.csv", dir, base);
    FILE *f = fopen(opath, "r");
    int got = f ? fscanf(f, "%*[^\n]\n%lf,%lf,%lf,%lf,%lf,%lf,%lf", &n, &k, &d, &sum, &sumsq,
                         &x0, &x1) : 0;
    if (f) fclose(f);
    ES_CHECK_MSG(got == 7, "%s: R's oracle line", base);
    if (got != 7) return;
    es_landmarks *lm = NULL;
    es_status rc = es_landmarks_read_csv(ctx, lpath, spath, &lm);
    ES_CHECK_MSG(rc == ES_OK, "%s: %s", base, es_ctx_errmsg(ctx));
    if (rc != ES_OK) return;
    ES_CHECK_MSG(lm->n == (int64_t)n && lm->k == (int64_t)k && lm->d == (int)d,
                 "%s: %lld x %lld x %d, R says %g x %g x %g", base, (long long)lm->n,
                 (long long)lm->k, lm->d, n, k, d);
    double s = 0, s2 = 0;
    int64_t len = lm->n * lm->k * lm->d;
    for (int64_t i = 0; i < len; i++) s += lm->xyz[i], s2 += lm->xyz[i] * lm->xyz[i];
    /* summation order differs from R's: agree to rounding */
    ES_CHECK_MSG(fabs(s - sum) <= 1e-12 * (sumsq > 0 ? sqrt(sumsq * (double)len) : 1) &&
                 fabs(s2 - sumsq) <= 1e-12 * sumsq,
                 "%s: sum %.17g / %.17g, sum of squares %.17g / %.17g", base, s, sum, s2, sumsq);
    /* x[1, 1, 1] is landmark 1, x of specimen 1; x[k, d, n] the last
     * coordinate of the last landmark of specimen n */
    snprintf(first, sizeof first, "%s_001", base);
    snprintf(last, sizeof last, "%s_%03lld", base, (long long)lm->n);
    int64_t j0 = find_id(lm, first), j1 = find_id(lm, last), kd = lm->k * lm->d;
    ES_CHECK_MSG(j0 >= 0 && j1 >= 0, "%s: ids %s and %s", base, first, last);
    if (j0 >= 0 && j1 >= 0)
        ES_CHECK_MSG(lm->xyz[j0 * kd] == x0 && lm->xyz[j1 * kd + kd - 1] == x1,
                     "%s: first %.17g / %.17g, last %.17g / %.17g", base, lm->xyz[j0 * kd],
                     x0, lm->xyz[j1 * kd + kd - 1], x1);
    es_landmarks_free(lm);
}

int main(void)
{
    es_ctx *ctx = NULL;
    char cmd[9000];
    ES_TEST_BEGIN();
    if (system("Rscript -e 'suppressMessages(library(shapes))' >/dev/null 2>&1") != 0) {
        ES_TEST_SKIP("Rscript with the shapes package (r-cran-shapes) absent");
    }
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    const char *dir = es_test_tmpdir("landmarks_r");
    snprintf(cmd, sizeof cmd, "Rscript %s/tests/ingest/export_rshapes.R '%s'", ES_SOURCE_ROOT,
             dir);
    ES_CHECK_MSG(system(cmd) == 0, "%s failed", cmd);
    DIR *d = opendir(dir);
    struct dirent *e;
    int tables = 0, brains = 0, dna = 0;
    while (d && (e = readdir(d))) {
        const char *suffix = "_oracle.csv";
        size_t len = strlen(e->d_name), ls = strlen(suffix);
        char base[300];
        if (len <= ls || len - ls >= sizeof base || strcmp(e->d_name + len - ls, suffix)) continue;
        snprintf(base, sizeof base, "%.*s", (int)(len - ls), e->d_name);
        check_table(ctx, dir, base);
        brains += !strcmp(base, "brains");
        dna += !strcmp(base, "dna_dat");
        tables++;
    }
    if (d) closedir(d);
    ES_CHECK_MSG(tables >= 10 && brains && dna, "%d tables exported by R (brains %d, dna %d)",
                 tables, brains, dna);
    fprintf(stderr, "%d landmark arrays of R's shapes package read\n", tables);
    es_ctx_free(ctx);
    ES_TEST_END();
}
