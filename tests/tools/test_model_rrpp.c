/* tests/tools/test_model_rrpp.c — what `edgespace model` adds to SS/F/p
 * (those are vegan's: test_model_oracle.c), against
 *  - an independent reference written for this test
 *    (tools/oracle/rrpp_reference.R: R's model.matrix, qr, optimise and
 *    quantile on the response itself, the Collyer-Adams residual
 *    permutation), always, where R is installed;
 *  - RRPP itself (tools/oracle/rrpp.R: lm.rrpp, anova, pairwise, summary),
 *    where it is installed ($ES_RRPP_LIB, tools/oracle/install_rrpp.sh
 *    builds it from its source with Debian's R packages);
 * both with the very permutations the fit used (es_model_permutations,
 * written as CSV), so p-values must be equal and Z, UCL equal to rounding.
 * On landmarks_rshapes in Procrustes space (GPA, then the aligned
 * coordinates):
 *  - apes, species and sex read from the group (gorf: gor, f) and sexcopy,
 *    sex under other labels: ~ log(size) * species with the slopes of the
 *    species compared (distances, vector-correlation angles, length
 *    differences: value, UCL, Z, p), the CAC scores (and the same scores
 *    from ~ log(size) + species to 1e-12, with its LS means at log of mean
 *    size, and a comparison with ~ log(size)); ~ species / sex with sex
 *    nested in species as the error term of species; per-landmark tests;
 *    ~ sex + sexcopy: the copy left out by name, type III keeps sex's
 *    test, pairwise and per-landmark requests on the copy refused;
 *  - rats: ~ time + factor(rat_no), the rat as block (permutations within
 *    rats), Z of time and the comparison with ~ factor(rat_no);
 *  - with the argument face-study (slow suite): ~ expression + subject in
 *    edge-length space blocked by subject, --reference neutral, LS means
 *    of the expressions, and the CAC scores of ~ log(size) + expression
 *    and ~ log(size) * expression.
 * At the end it prints the table quantity / ours / oracle / max
 * difference. Skips without ../shared or Rscript. */
#include "core/core_private.h"
#include "core/csv_table.h"
#include "es_test.h"
#include "es_test_models.h"
#include "es_test_run.h"
#include "edgespace/edgespace.h"

#include <math.h>
#include <sys/stat.h>

#define B 199
#define SEED "11"

static char dir[512];
static es_ctx *ctx;
static int have_rrpp;

/* The largest difference seen per data set, oracle and quantity. */
typedef struct seen {
    char set[24], oracle[12], quantity[24];   /* set: the case (data set_model) */
    double diff, ours, theirs;
} seen;
static seen table[128];
static int nseen;

static void note(const char *set, const char *oracle, const char *q, double ours, double theirs,
                 double diff)
{
    int k = 0;
    while (k < nseen && (strcmp(table[k].set, set) || strcmp(table[k].oracle, oracle) ||
                         strcmp(table[k].quantity, q)))
        k++;
    if (k == nseen && nseen < 128) {
        snprintf(table[k].set, sizeof table[k].set, "%s", set);
        snprintf(table[k].oracle, sizeof table[k].oracle, "%s", oracle);
        snprintf(table[k].quantity, sizeof table[k].quantity, "%s", q);
        table[k].diff = -1;
        nseen++;
    }
    if (k < nseen && diff > table[k].diff) {
        table[k].diff = diff;
        table[k].ours = ours;
        table[k].theirs = theirs;
    }
}

static int64_t column(const es__csv_table *t, const char *name)
{
    for (int64_t c = 0; c < es__csv_nfields(t, 0); c++)
        if (!strcmp(es__csv_field(t, 0, c), name)) return c;
    return -1;
}

static double num(const es__csv_table *t, int64_t r, int64_t c)
{
    const char *s = es__csv_field(t, r, c);
    return (!*s || !strcmp(s, "NA") || !strcmp(s, "nan")) ? NAN : strtod(s, NULL);
}

/* The record of ours whose key fields (k1[, k2], either order) match. */
static int64_t match(const es__csv_table *t, const char *k1, const char *k2, const char *v1,
                     const char *v2)
{
    const int64_t c1 = column(t, k1), c2 = k2 ? column(t, k2) : -1;
    for (int64_t r = 1; c1 >= 0 && r < t->nrecords; r++) {
        const char *a = es__csv_field(t, r, c1), *b = c2 >= 0 ? es__csv_field(t, r, c2) : NULL;
        if (!k2 && !strcmp(a, v1)) return r;
        if (k2 && ((!strcmp(a, v1) && !strcmp(b, v2)) || (!strcmp(a, v2) && !strcmp(b, v1))))
            return r;
    }
    return -1;
}

/* Compare columns cols (relative tolerance rtol[k] of the largest |value|
 * of that column in the oracle, so near-zero entries are not over-read). */
static void compare(const char *set, const char *oracle, const char *ours, const char *theirs,
                    const char *k1, const char *k2, const char *const *cols, const double *rtol,
                    int ncols)
{
    es__csv_table a = {0}, b = {0};
    ES_CHECK_OK(ctx, es__csv_read(ctx, "ours", ours, 0, &a));
    ES_CHECK_OK(ctx, es__csv_read(ctx, oracle, theirs, 0, &b));
    ES_CHECK_MSG(b.nrecords > 1, "%s: %s wrote no rows (%s)", set, oracle, theirs);
    for (int k = 0; k < ncols; k++) {
        const int64_t ca = column(&a, cols[k]), cb = column(&b, cols[k]);
        ES_CHECK_MSG(ca >= 0 && cb >= 0, "%s: no column %s", set, cols[k]);
        if (ca < 0 || cb < 0) continue;
        double scale = 0;
        for (int64_t r = 1; r < b.nrecords; r++) scale = fmax(scale, fabs(num(&b, r, cb)));
        const int64_t b1 = column(&b, k1), b2 = k2 ? column(&b, k2) : -1;
        for (int64_t r = 1; r < b.nrecords; r++) {
            const int64_t ra = match(&a, k1, k2, es__csv_field(&b, r, b1),
                                     b2 >= 0 ? es__csv_field(&b, r, b2) : NULL);
            ES_CHECK_MSG(ra > 0, "%s: %s has no row %s", set, ours, es__csv_field(&b, r, b1));
            if (ra < 0) continue;
            const double x = num(&a, ra, ca), y = num(&b, r, cb), d = fabs(x - y);
            /* a term constant within blocks has no test here (the oracles permute it anyway) */
            if (isnan(x) && (!strcmp(cols[k], "p") || !strcmp(cols[k], "z")) &&
                isnan(num(&a, ra, column(&a, "p"))) && strcmp(oracle, "+ vs *"))
                continue;
            char q[48];
            snprintf(q, sizeof q, "%s", cols[k]);
            note(set, oracle, q, x, y, isnan(x) && isnan(y) ? 0 : d);
            ES_CHECK_MSG(d <= rtol[k] * fmax(scale, 1e-300) || (isnan(x) && isnan(y)),
                         "%s %s row %lld %s: ours %.17g, %s %.17g", set, ours, (long long)r,
                         cols[k], x, oracle, y);
        }
    }
    es__csv_table_clear(ctx, &a);
    es__csv_table_clear(ctx, &b);
}

static void write_perms(const char *spec, const char *block, const char *path)
{
    ES_CHECK_MSG(es_test_write_permutations(ctx, spec, block, strtoull(SEED, NULL, 10), B, path),
                 "permutations of %s: %s", spec, es_ctx_errmsg(ctx));
}

/* Run an oracle script into DIR/<what>.<oracle>/; args end with NULL. */
static int oracle(const char *script, const char *what, const char *response, int skip,
                  const char *spec, const char *formula, const char *perms, const char *const *kv)
{
    char cmd[8192], out[700];
    snprintf(out, sizeof out, "%s/%s.%s", dir, what, strstr(script, "reference") ? "ref" : "rrpp");
    mkdir(out, 0777);
    int n = snprintf(cmd, sizeof cmd, "Rscript '%s/tools/oracle/%s' '%s' %d '%s' '%s' '%s' '%s'",
                     ES_SOURCE_ROOT, script, response, skip, spec, formula, perms, out);
    for (int k = 0; kv && kv[k]; k++) n += snprintf(cmd + n, sizeof cmd - (size_t)n, " '%s'", kv[k]);
    snprintf(cmd + n, sizeof cmd - (size_t)n, " > '%s/log.txt' 2>&1", out);
    int rc = system(cmd);
    ES_CHECK_MSG(rc == 0, "%s: %s failed (%s/log.txt)", what, script, out);
    return rc == 0;
}

static const char *const anova_cols[] = {"df", "ss", "ms", "r2", "f", "z", "p"};
static const double anova_ref_tol[] = {0, 1e-10, 1e-10, 1e-10, 1e-10, 1e-8, 1e-12};
/* RRPP rounds the design to 12 digits and works on its own QR */
static const double anova_rrpp_tol[] = {0, 1e-7, 1e-7, 1e-7, 1e-7, 1e-6, 1e-12};
static const char *const pair_cols[] = {"d", "ucl", "z", "p", "r", "angle", "angle_ucl",
                                        "angle_z", "angle_p", "dlength", "dlength_ucl",
                                        "dlength_z", "dlength_p"};
static const double pair_tol[] = {1e-10, 1e-10, 1e-8, 1e-12, 1e-10, 1e-10, 1e-10,
                                  1e-8, 1e-12, 1e-9, 1e-9, 1e-7, 1e-12};

/* One case: ours (CLI args after the formula), the reference, and RRPP. */
static void run_case(const char *what, const char *store, const char *formula,
                     const char *response, int skip, const char *spec, const char *perms,
                     const char *const *ours_args, const char *const *kv, int pairwise, int slopes)
{
    static es_test_out r;
    char anova[700], pw[700], path[800];
    snprintf(anova, sizeof anova, "%s/%s.csv", dir, what);
    snprintf(pw, sizeof pw, "%s/%s.pairwise.csv", dir, what);
    const char *args[40] = {"model", store, formula, "--permutations", "199", "--seed", SEED, "-n", what,
                            "--replace", "-o", anova};
    int n = 12;
    for (int k = 0; ours_args && ours_args[k]; k++) args[n++] = ours_args[k];
    args[n] = NULL;
    es_test_run(&r, dir, args);
    ES_CHECK_MSG(r.status == 0, "%s: %s%s", what, r.out, r.err);
    ES_CHECK_MSG(!strstr(r.out, "nan") && !strstr(r.out, " 0 of "), "%s: %s", what, r.out);
    const char *scripts[2] = {"rrpp_reference.R", "rrpp.R"};
    for (int s = 0; s < 1 + have_rrpp; s++) {
        const char *o = s ? "RRPP" : "reference";
        if (!oracle(scripts[s], what, response, skip, spec, formula, perms, kv)) continue;
        snprintf(path, sizeof path, "%s/%s.%s/anova.csv", dir, what, s ? "rrpp" : "ref");
        compare(what, o, anova, path, "term", NULL, anova_cols, s ? anova_rrpp_tol : anova_ref_tol,
                7);
        if (pairwise) {
            snprintf(path, sizeof path, "%s/%s.%s/pairwise.csv", dir, what, s ? "rrpp" : "ref");
            compare(what, o, pw, path, "level_a", "level_b", pair_cols, pair_tol, slopes ? 13 : 4);
        }
    }
}

/* The CAC scores of stored model `name` into DIR/<name>.scores.csv. */
static void cac_scores(const char *store, const char *name, char *path, size_t len)
{
    static es_test_out r;
    char res[100];
    snprintf(path, len, "%s/%s.scores.csv", dir, name);
    snprintf(res, sizeof res, "model/%s", name);
    ES_RUN(&r, dir, "export", store, "--result", res, "--table", "scores", "--output", path);
    ES_CHECK_MSG(r.status == 0, "%s", r.err);
}

/* A landmark set ingested, aligned and exported; the apes with species and
 * sex read from the group and sexcopy, sex under other labels. */
static int landmarks(const char *set, char *store, char *aligned, char *spec, size_t n)
{
    char sp[600], derived[700];
    snprintf(sp, sizeof sp, "%s/data/landmarks_rshapes/%s_specimens.csv", ES_SHARED_DIR, set);
    snprintf(derived, sizeof derived, "%s/%s.derived.csv", dir, set);
    if (!strcmp(set, "apes")) {
        /* gorf -> species gor, sex f, sexcopy female */
        es__csv_table t = {0};
        ES_CHECK_OK(ctx, es__csv_read(ctx, "apes", sp, 0, &t));
        FILE *f = fopen(derived, "w");
        if (f) fputs("specimen,group,species,sex,sexcopy\n", f);
        for (int64_t i = 1; f && i < t.nrecords; i++) {
            const char *g = es__csv_field(&t, i, 1);
            const size_t L = strlen(g);
            fprintf(f, "%s,%s,%.*s,%c,%s\n", es__csv_field(&t, i, 0), g, (int)(L - 1), g,
                    g[L - 1], g[L - 1] == 'f' ? "female" : "male");
        }
        if (f) fclose(f);
        es__csv_table_clear(ctx, &t);
    }
    return es_test_landmark_gpa(dir, set, strcmp(set, "apes") ? NULL : derived, store, aligned,
                                spec, n);
}

static void apes(void)
{
    static es_test_out r;
    char store[600], aligned[600], spec[600], perms[700], s1[700], s2[700], path[700];
    if (!landmarks("apes", store, aligned, spec, sizeof store)) {
        ES_CHECK_MSG(0, "apes: ingest or GPA failed");
        return;
    }
    snprintf(perms, sizeof perms, "%s/apes.perms.csv", dir);
    write_perms(spec, NULL, perms);
    /* allometry by species: slopes compared, the CAC */
    const char *a1[] = {"--gpa", "g", "--pairwise", "species", "--slopes", "log(size)", NULL};
    const char *k1[] = {"pairwise=species", "slopes=log(size)", "cac=log(size)", NULL};
    run_case("apes_slopes", store, "~ log(size) * species", aligned, 4, spec, perms, a1,
             k1, 1, 1);
    static const char *const sc[] = {"cac_score"};
    static const double sct[] = {1e-10};
    cac_scores(store, "apes_slopes", s1, sizeof s1);
    snprintf(path, sizeof path, "%s/apes_slopes.ref/cac.csv", dir);
    /* the reference's column is "score" */
    {
        char fixed[900];
        snprintf(fixed, sizeof fixed, "sed -i '1s/score/cac_score/' '%s'", path);
        ES_CHECK(system(fixed) == 0);
    }
    compare("apes_slopes", "reference", s1, path, "id", NULL, sc, sct, 1);
    /* ~ log(size) + species: the same CAC to 1e-12; LS means at log of mean
     * size (RRPP's), compared with ~ log(size) */
    const char *a2[] = {"--gpa", "g", "--pairwise", "species", "--at", "size=mean", "--null",
                        "~ log(size)", "--edges", "species", NULL};
    const char *k2[] = {"pairwise=species", "at=data", "null=~ log(size)", "edges=species",
                        "dim=2", NULL};
    run_case("apes_additive", store, "~ log(size) + species", aligned, 4, spec, perms, a2,
             k2, 1, 0);
    cac_scores(store, "apes_additive", s2, sizeof s2);
    {
        es__csv_table x = {0}, y = {0};
        ES_CHECK_OK(ctx, es__csv_read(ctx, "s1", s1, 0, &x));
        ES_CHECK_OK(ctx, es__csv_read(ctx, "s2", s2, 0, &y));
        const int64_t cx = column(&x, "cac_score"), cy = column(&y, "cac_score");
        double worst = 0, scale = 0;
        ES_CHECK(x.nrecords == y.nrecords && x.nrecords == 168 && cx > 0 && cy > 0);
        for (int64_t i = 1; i < x.nrecords && i < y.nrecords; i++) {
            worst = fmax(worst, fabs(num(&x, i, cx) - num(&y, i, cy)));
            scale = fmax(scale, fabs(num(&x, i, cx)));
        }
        note("apes_cac", "+ vs *", "cac_score", scale, scale, worst);
        ES_CHECK_MSG(worst <= 1e-12 * scale, "apes: CAC under + and * differ by %g (scale %g)",
                     worst, scale);
        es__csv_table_clear(ctx, &x);
        es__csv_table_clear(ctx, &y);
    }
    static const char *const cmp_cols[] = {"df", "ss", "r2", "f", "z", "p"};
    static const double cmp_tol[] = {0, 1e-10, 1e-10, 1e-10, 1e-8, 1e-12};
    static const double cmp_rrpp[] = {0, 1e-7, 1e-7, 1e-7, 1e-6, 1e-12};
    for (int s = 0; s < 1 + have_rrpp; s++) {
        /* our comparison row is "null model: ~ log(size)" of the ANOVA CSV */
        char ours[700], cmd[1600];
        snprintf(ours, sizeof ours, "%s/apes_additive.null.csv", dir);
        snprintf(cmd, sizeof cmd, "(echo term,df,ss,ms,r2,f,z,p,error; grep '^null model' "
                 "'%s/apes_additive.csv' | sed 's/^null model: ~ log(size)/x/') > '%s'", dir,
                 ours);
        ES_CHECK(system(cmd) == 0);
        snprintf(path, sizeof path, "%s/apes_additive.%s/comparison.csv", dir, s ? "rrpp" : "ref");
        snprintf(cmd, sizeof cmd, "sed -i '1s/^/term,/; 2,$s/^/x,/' '%s'", path);
        ES_CHECK(system(cmd) == 0);
        compare("apes_null", s ? "RRPP" : "reference", ours, path, "term", NULL, cmp_cols,
                s ? cmp_rrpp : cmp_tol, 6);
    }
    static const char *const lm_cols[] = {"f", "p"};
    static const double lm_tol[] = {1e-10, 1e-12};
    ES_RUN(&r, dir, "export", store, "--result", "model/apes_additive", "--table", "edges",
           "--output", s1);
    ES_CHECK_MSG(r.status == 0, "%s", r.err);
    snprintf(path, sizeof path, "%s/apes_additive.ref/landmarks.csv", dir);
    compare("apes_landmark", "reference", s1, path, "landmark", NULL, lm_cols, lm_tol, 2);

    /* sex nested in species: species tested over species:sex */
    const char *a3[] = {"--gpa", "g", "--error", "species=species:sex", NULL};
    const char *k3[] = {"error=species=species:sex", NULL};
    run_case("apes_nested", store, "~ species + species:sex", aligned, 4, spec, perms, a3,
             k3, 0, 0);

    /* a copy of sex: left out by name; type III keeps sex; requests refused */
    ES_RUN(&r, dir, "model", store, "~ sex + sexcopy", "--gpa", "g", "--type", "III",
           "--no-store", "--permutations", "99", "--pairwise", "sex");
    ES_CHECK_MSG(r.status == 0 && strstr(r.err, "term 'sexcopy' duplicates 'sex'") &&
                 strstr(r.out, "left out: sexcopy duplicates 'sex'") && !strstr(r.out, "nan") &&
                 !strstr(r.out, "(block)") && strstr(r.out, "\nsex "), "%s%s", r.out, r.err);
    {
        /* the distance of the sexes is the one of ~ sex, not 0 */
        const char *d = strstr(r.out, "\n  f ");
        double dist = d ? strtod(d + 20, NULL) : 0;
        ES_CHECK_MSG(d && dist > 1, "%s", r.out);
    }
    ES_RUN(&r, dir, "model", store, "~ sex + sexcopy", "--gpa", "g", "--no-store", "--permutations", "9",
           "--pairwise", "sexcopy");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "'sexcopy' duplicates 'sex'"), "%s", r.err);
    ES_RUN(&r, dir, "model", store, "~ sex + sexcopy", "--gpa", "g", "--no-store", "--permutations", "9",
           "--edges", "sexcopy");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "duplicates 'sex'"), "%s", r.err);
    ES_RUN(&r, dir, "model", store, "~ species", "--gpa", "g", "--no-store", "--permutations", "0",
           "--edges", "species");
    ES_CHECK_MSG(r.status == 0 && !strstr(r.out, "0 of") && strstr(r.out, "no p or q values"),
                 "%s", r.out);
}

static void rats(void)
{
    char store[600], aligned[600], spec[600], perms[700];
    if (!landmarks("rats", store, aligned, spec, sizeof store)) {
        ES_CHECK_MSG(0, "rats: ingest or GPA failed");
        return;
    }
    snprintf(perms, sizeof perms, "%s/rats.perms.csv", dir);
    write_perms(spec, "rat_no", perms);
    const char *a[] = {"--gpa", "g", "--block", "rat_no", "--type", "II", NULL};
    const char *k[] = {"type=II", NULL};
    run_case("rats", store, "~ time + factor(rat_no)", aligned, 2, spec, perms, a, k, 0,
             0);
}

static void faces(void)
{
    static es_test_out r;
    char man[600], store[600], lengths[600], spec[600], perms[700], s1[700], s2[700], path[4000];
    snprintf(man, sizeof man, "%s/data/face-study/manifest.csv", ES_SHARED_DIR);
    snprintf(store, sizeof store, "%s/face.h5", dir);
    snprintf(lengths, sizeof lengths, "%s/face.lengths.csv", dir);
    snprintf(spec, sizeof spec, "%s/face.rows.csv", dir);
    unlink(store);
    ES_RUN(&r, dir, "ingest", store, "--manifest", man, "-q");
    ES_CHECK(r.status == 0);
    ES_RUN(&r, dir, "export", store, "--lengths", lengths);
    ES_CHECK(r.status == 0);
    /* the rows' labels (a row table of a stored model) and their scale, the
     * size of edge-length space (the lengths table's second column) */
    ES_RUN(&r, dir, "model", store, "~ log(size) + expression", "--permutations", "0", "-n", "face_cac_plus",
           "--replace");
    ES_CHECK(r.status == 0);
    cac_scores(store, "face_cac_plus", s2, sizeof s2);
    snprintf(path, sizeof path, "cut -d, -f2 '%s' > '%s.scale' && paste -d, '%s' '%s.scale' > "
             "'%s'", lengths, spec, s2, spec, spec);
    ES_CHECK(system(path) == 0);
    snprintf(perms, sizeof perms, "%s/face.perms.csv", dir);
    write_perms(spec, "subject", perms);
    const char *a1[] = {"--block", "subject", "--reference", "neutral", "--pairwise",
                        "expression", NULL};
    const char *k1[] = {"reference=expression=neutral", "pairwise=expression", NULL};
    run_case("face", store, "~ expression + subject", lengths, 1, spec, perms, a1,
             k1, 1, 0);
    /* the CAC under + and * */
    const char *a2[] = {NULL};
    const char *k2[] = {"cac=log(size)", NULL};
    write_perms(spec, NULL, perms);
    run_case("face_cac_star", store, "~ log(size) * expression", lengths, 1, spec,
             perms, a2, k2, 0, 0);
    cac_scores(store, "face_cac_star", s1, sizeof s1);
    es__csv_table x = {0}, y = {0};
    ES_CHECK_OK(ctx, es__csv_read(ctx, "s1", s1, 0, &x));
    ES_CHECK_OK(ctx, es__csv_read(ctx, "s2", s2, 0, &y));
    const int64_t cx = column(&x, "cac_score"), cy = column(&y, "cac_score");
    double worst = 0, scale = 0;
    for (int64_t i = 1; i < x.nrecords && i < y.nrecords; i++) {
        worst = fmax(worst, fabs(num(&x, i, cx) - num(&y, i, cy)));
        scale = fmax(scale, fabs(num(&x, i, cx)));
    }
    note("face_cac", "+ vs *", "cac_score", scale, scale, worst);
    ES_CHECK_MSG(x.nrecords == 91 && worst <= 1e-12 * scale, "face: CAC differs by %g", worst);
    es__csv_table_clear(ctx, &x);
    es__csv_table_clear(ctx, &y);
    snprintf(path, sizeof path, "sed -i '1s/score/cac_score/' '%s/face_cac_star.ref/cac.csv'", dir);
    ES_CHECK(system(path) == 0);
    static const char *const sc[] = {"cac_score"};
    static const double sct[] = {1e-9};
    snprintf(path, sizeof path, "%s/face_cac_star.ref/cac.csv", dir);
    compare("face_cac_star", "reference", s1, path, "id", NULL, sc, sct, 1);
}

int main(int argc, char **argv)
{
    ES_TEST_BEGIN();
    char probe[600];
    struct stat st;
    snprintf(probe, sizeof probe, "%s/data/landmarks_rshapes", ES_SHARED_DIR);
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE not set");
    if (stat(probe, &st)) ES_TEST_SKIP("no %s", probe);
    if (system("Rscript -e 'invisible(0)' >/dev/null 2>&1")) ES_TEST_SKIP("no Rscript");
    have_rrpp = system("Rscript -e 'lib <- Sys.getenv(\"ES_RRPP_LIB\"); if (nzchar(lib)) "
                       ".libPaths(c(lib, .libPaths())); suppressMessages(library(RRPP))' "
                       ">/dev/null 2>&1") == 0;
    fprintf(stderr, "RRPP %s\n", have_rrpp ? "found: compared too" : "not installed: the "
            "reference only (tools/oracle/install_rrpp.sh)");
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    snprintf(dir, sizeof dir, "%s/test-model-rrpp", ES_BUILD_ROOT);
    mkdir(dir, 0777);
    if (argc > 1 && !strcmp(argv[1], "face-study")) {
        faces();
    } else {
        apes();
        rats();
    }
    fprintf(stderr, "%-15s %-10s %-12s %22s %22s %10s\n", "case", "oracle", "quantity",
            "ours", "oracle", "max diff");
    for (int k = 0; k < nseen; k++)
        fprintf(stderr, "%-15s %-10s %-12s %22.15g %22.15g %10.2g\n", table[k].set,
                table[k].oracle, table[k].quantity, table[k].ours, table[k].theirs,
                table[k].diff);
    es_ctx_free(ctx);
    ES_TEST_END();
}
