/* tests/tools/test_model_oracle.c — edgespace model against R's vegan
 * adonis2 (tools/oracle/adonis2.R: PERMANOVA on Euclidean distances, whose
 * sums of squares are the multivariate linear model's) on the real data of
 * ../shared, with row permutations (--permute raw, adonis2's scheme):
 *  - landmarks_rshapes in Procrustes space (edgespace gpa, the aligned
 *    coordinates exported with `export --result gpa/g --table aligned`):
 *    rats, time + rat (18 rats x 8 ages) with the rat as block (adonis2's
 *    strata); schizophrenia and sand, allometry log(centroid size) + group,
 *    sequential (type I = by "terms") and marginal (type II and III = by
 *    "margin" in a main-effects model);
 *  - with the argument face-study (slow suite: R reads 90 x 27,871 lengths
 *    for minutes): expression + subject blocked by subject in edge-length
 *    space (`export --lengths`) and in Procrustes space.
 * adonis2 is handed the very permutations of our fit (es_model_permutations
 * as its permutation matrix). Degrees of freedom equal; SS, R^2 and F within
 * 1e-10 relative; the p-values equal. Skips without ../shared or without
 * Rscript and vegan. */
#include "core/core_private.h"
#include "core/csv_table.h"
#include "es_test.h"
#include "es_test_models.h"
#include "es_test_run.h"
#include "edgespace/edgespace.h"

#include <math.h>
#include <sys/stat.h>

static char dir[512];
static es_ctx *ctx;
static double maxrel;   /* the largest relative difference of SS, R^2, F seen */
static int same_p;      /* p-values compared (all must be equal) */

static double rel(double a, double b)
{
    double d = fabs(a - b) / fmax(fabs(b), 1e-300);
    if (d > maxrel) maxrel = d;
    return d;
}

/* The record of `term` in a table (term, df, ss, ...), or -1. */
static int64_t find_term(const es__csv_table *t, const char *term)
{
    for (int64_t r = 1; r < t->nrecords; r++)
        if (!strcmp(es__csv_field(t, r, 0), term)) return r;
    return -1;
}

static double num(const es__csv_table *t, int64_t r, int64_t c)
{
    const char *s = es__csv_field(t, r, c);
    return (!*s || !strcmp(s, "NA") || !strcmp(s, "nan")) ? NAN : strtod(s, NULL);
}

/* ours: term,df,ss,ms,r2,f,z,p,error; R's: term,df,ss,r2,f,p. */
static void compare(const char *what, const char *ours, const char *theirs, int64_t B)
{
    es__csv_table a = {0}, b = {0};
    ES_CHECK_OK(ctx, es__csv_read(ctx, "ours", ours, 0, &a));
    ES_CHECK_OK(ctx, es__csv_read(ctx, "adonis2", theirs, 0, &b));
    ES_CHECK_MSG(b.nrecords >= 3, "%s: adonis2 wrote no table", what);
    for (int64_t rb = 1; rb < b.nrecords; rb++) {
        const char *term = es__csv_field(&b, rb, 0);
        int64_t ra = find_term(&a, term);
        ES_CHECK_MSG(ra > 0, "%s: no term '%s' in ours", what, term);
        if (ra < 0) continue;
        ES_CHECK_MSG(num(&a, ra, 1) == num(&b, rb, 1), "%s %s: df", what, term);
        ES_CHECK_MSG(rel(num(&a, ra, 2), num(&b, rb, 2)) <= 1e-10, "%s %s: SS", what, term);
        ES_CHECK_MSG(rel(num(&a, ra, 4), num(&b, rb, 3)) <= 1e-10, "%s %s: R2", what, term);
        double fa = num(&a, ra, 5), fb = num(&b, rb, 4), pa = num(&a, ra, 7), pb = num(&b, rb, 5);
        if (isnan(fb)) continue;   /* Residual, Total */
        ES_CHECK_MSG(rel(fa, fb) <= 1e-10, "%s %s: F %.17g vs %.17g", what, term, fa, fb);
        if (isnan(pa)) continue;   /* the block: not testable by permutations within it */
        /* the same permutations: the same count */
        ES_CHECK_MSG(fabs(pa - pb) <= 1e-12, "%s %s: p %.6f vs adonis2 %.6f with the same %lld "
                     "permutations", what, term, pa, pb, (long long)B);
        same_p++;
        fprintf(stderr, "%s %s: F %.10g (adonis2 %.10g), p %.4f (adonis2 %.4f)\n", what, term, fa,
                fb, pa, pb);
    }
    es__csv_table_clear(ctx, &a);
    es__csv_table_clear(ctx, &b);
}

/* One model both ways. type: I, II or III (adonis2 by terms, margin). */
static void run_case(const char *what, const char *store, const char *formula, const char *gpa,
                     const char *block, const char *type, const char *response, int skip,
                     const char *design, int64_t B)
{
    static es_test_out r;
    char ours[700], theirs[700], perms[32], pfile[700], cmd[4096];
    snprintf(ours, sizeof ours, "%s/%s.ours.csv", dir, what);
    snprintf(theirs, sizeof theirs, "%s/%s.adonis2.csv", dir, what);
    snprintf(perms, sizeof perms, "%lld", (long long)B);
    const char *args[32] = {"model", store, formula, "--permute", "raw", "--permutations", perms, "--type",
                            type, "--no-store", "--seed", "11", "-o", ours};
    int n = 14;
    if (gpa) args[n++] = "--gpa", args[n++] = gpa;
    if (block) args[n++] = "--block", args[n++] = block;
    args[n] = NULL;
    es_test_run(&r, dir, args);
    ES_CHECK_MSG(r.status == 0, "%s: %s", what, r.err);
    /* adonis2 gets the permutations of our fit (seed 11) as its matrix */
    snprintf(pfile, sizeof pfile, "%s/%s.perms.csv", dir, what);
    ES_CHECK_MSG(es_test_write_permutations(ctx, design, block, 11, B, pfile), "%s: %s", what,
                 es_ctx_errmsg(ctx));
    snprintf(cmd, sizeof cmd, "Rscript '%s/tools/oracle/adonis2.R' '%s' %d '%s' '%s' %s %s '%s' 11 "
             "'%s'", ES_SOURCE_ROOT, response, skip, design, formula,
             strcmp(type, "I") ? "margin" : "terms", block ? block : "-", pfile, theirs);
    ES_CHECK_MSG(system(cmd) == 0, "%s: %s failed", what, cmd);
    compare(what, ours, theirs, B);
}

static int landmarks(const char *set, char *store, char *aligned, char *spec, size_t n)
{
    return es_test_landmark_gpa(dir, set, NULL, store, aligned, spec, n);
}

int main(int argc, char **argv)
{
    ES_TEST_BEGIN();
    char probe[600];
    struct stat st;
    snprintf(probe, sizeof probe, "%s/data/landmarks_rshapes", ES_SHARED_DIR);
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE not set");
    if (stat(probe, &st)) ES_TEST_SKIP("no %s", probe);
    if (system("Rscript -e 'suppressMessages(library(vegan))' >/dev/null 2>&1"))
        ES_TEST_SKIP("no Rscript with vegan (r-cran-vegan)");
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    snprintf(dir, sizeof dir, "%s/test-model-oracle", ES_BUILD_ROOT);
    mkdir(dir, 0777);
    char store[600], aligned[600], spec[600];
    if (argc > 1 && !strcmp(argv[1], "face-study")) {
        static es_test_out r;
        char man[600], lengths[600];
        snprintf(man, sizeof man, "%s/data/face-study/manifest.csv", ES_SHARED_DIR);
        snprintf(store, sizeof store, "%s/face.h5", dir);
        snprintf(lengths, sizeof lengths, "%s/face.lengths.csv", dir);
        snprintf(aligned, sizeof aligned, "%s/face.aligned.csv", dir);
        snprintf(spec, sizeof spec, "%s/face.specimens.csv", dir);
        unlink(store);
        ES_RUN(&r, dir, "ingest", store, "--manifest", man, "-q");
        ES_CHECK(r.status == 0);
        ES_RUN(&r, dir, "gpa", store, "--name", "g");
        ES_CHECK(r.status == 0);
        ES_RUN(&r, dir, "export", store, "--lengths", lengths);
        ES_CHECK(r.status == 0);
        ES_RUN(&r, dir, "export", store, "--result", "gpa/g", "--output", spec);
        ES_CHECK(r.status == 0);
        ES_RUN(&r, dir, "export", store, "--result", "gpa/g", "--table", "aligned", "--output",
               aligned);
        ES_CHECK(r.status == 0);
        run_case("face_lengths", store, "~ expression + subject", NULL, "subject", "I", lengths,
                 1, spec, 999);
        run_case("face_procrustes", store, "~ expression + subject", "g", "subject", "I",
                 aligned, 3, spec, 999);
    } else {
        ES_CHECK(landmarks("rats", store, aligned, spec, sizeof store));
        run_case("rats", store, "~ time + factor(rat_no)", "g", "rat_no", "I", aligned, 2, spec,
                 999);
        ES_CHECK(landmarks("schizophrenia", store, aligned, spec, sizeof store));
        run_case("schizophrenia_I", store, "~ log(size) + group", "g", NULL, "I", aligned, 1,
                 spec, 4999);
        run_case("schizophrenia_II", store, "~ log(size) + group", "g", NULL, "II", aligned, 1,
                 spec, 4999);
        ES_CHECK(landmarks("sand", store, aligned, spec, sizeof store));
        run_case("sand_I", store, "~ log(size) + group", "g", NULL, "I", aligned, 1, spec, 4999);
        run_case("sand_III", store, "~ log(size) + group", "g", NULL, "III", aligned, 1, spec,
                 4999);
    }
    fprintf(stderr, "largest relative difference of SS, R2, F from adonis2: %.3g; %d p-values "
            "equal with the same permutations\n", maxrel, same_p);
    es_ctx_free(ctx);
    ES_TEST_END();
}
