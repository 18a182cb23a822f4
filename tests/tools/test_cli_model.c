/* tests/tools/test_cli_model.c — edgespace model, export --result,
 * variation and results, run as a user would on synthetic faces (6 subjects x neutral,
 * happy, angry, with noise): help and usage errors (exit 2), failures
 * (exit 1) with their messages, a blocked two-factor model whose ANOVA CSV
 * is checked against the balanced design's closed form computed here from
 * the lengths `export --lengths` wrote (type I expression and subject SS,
 * the residual, F), the same table read back with `export --result`, the
 * tables of a GPA result with the rows' labels, the per-edge figure, and
 * the shape-variation figure along a PC and along a coefficient, a nested
 * formula's labels and error term and a malformed one's column, and
 * `results` listing and deleting (all or nothing). */
#include "core/core_private.h"
#include "core/csv_table.h"
#include "core/files.h"
#include "es_test.h"
#include "es_test_run.h"
#include "edgespace/edgespace.h"

#include <math.h>
#include <sys/stat.h>
#include <time.h>

enum { S = 6, X = 3, N = S * X };

#if ES_HAVE_FIGURES
static int is_png(const char *path)
{
    unsigned char b[8] = {0};
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(b, 1, 8, f) : 0;
    if (f) fclose(f);
    return n == 8 && b[0] == 0x89 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G';
}
#endif

/* Field c of the record whose first field is `key` (NAN when absent). */
static double csv_value(const es__csv_table *t, const char *key, int64_t c)
{
    for (int64_t r = 0; r < t->nrecords; r++)
        if (!strcmp(es__csv_field(t, r, 0), key)) return strtod(es__csv_field(t, r, c), NULL);
    return NAN;
}

/* The closed form of the balanced subject x expression design: type I SS
 * of expression, of subject after it, and the residual, from the lengths
 * table (id "face_sNN_<expression>", scale, then the edges). */
static int closed_form(const es__csv_table *t, double ss[3])
{
    static const char *const ex[X] = {"neutral", "happy", "angry"};
    const int64_t E = es__csv_nfields(t, 0) - 2;
    double *y = calloc((size_t)(N * E), sizeof *y), *m = calloc((size_t)E, sizeof *m);
    int *sub = calloc(N, sizeof *sub), *exp = calloc(N, sizeof *exp), ok = t->nrecords == N + 1;
    for (int64_t i = 0; ok && i < N; i++) {
        const char *id = es__csv_field(t, i + 1, 0);
        sub[i] = atoi(id + 6) - 1;
        exp[i] = -1;
        for (int k = 0; k < X; k++)
            if (strstr(id, ex[k])) exp[i] = k;
        ok = sub[i] >= 0 && sub[i] < S && exp[i] >= 0;
        for (int64_t e = 0; e < E; e++) {
            y[i + e * N] = strtod(es__csv_field(t, i + 1, e + 2), NULL);
            m[e] += y[i + e * N] / N;
        }
    }
    ss[0] = ss[1] = ss[2] = 0;
    for (int64_t e = 0; ok && e < E; e++) {
        double me[X] = {0}, ms[S] = {0};
        for (int64_t i = 0; i < N; i++) {
            me[exp[i]] += y[i + e * N] / S;
            ms[sub[i]] += y[i + e * N] / X;
        }
        for (int k = 0; k < X; k++) ss[0] += S * (me[k] - m[e]) * (me[k] - m[e]);
        for (int s = 0; s < S; s++) ss[1] += X * (ms[s] - m[e]) * (ms[s] - m[e]);
        for (int64_t i = 0; i < N; i++) {
            double r = y[i + e * N] - me[exp[i]] - ms[sub[i]] + m[e];
            ss[2] += r * r;
        }
    }
    free(y);
    free(m);
    free(sub);
    free(exp);
    return ok;
}

int main(void)
{
    ES_TEST_BEGIN();
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE not set");
    static es_test_out r, r2;
    char dir[512], faces[600], store[600], manifest[700], anova[600], lengths[600], fig[600],
        var[600], pairwise_csv[600];
    snprintf(dir, sizeof dir, "%s/test-cli-model", ES_BUILD_ROOT);
    mkdir(dir, 0777);
    snprintf(faces, sizeof faces, "%s/faces", dir);
    snprintf(store, sizeof store, "%s/faces.h5", dir);
    snprintf(manifest, sizeof manifest, "%s/manifest.csv", faces);
    snprintf(anova, sizeof anova, "%s/anova.csv", dir);
    snprintf(pairwise_csv, sizeof pairwise_csv, "%s/anova.pairwise.csv", dir);
    snprintf(lengths, sizeof lengths, "%s/lengths.csv", dir);
    snprintf(fig, sizeof fig, "%s/edges.png", dir);
    snprintf(var, sizeof var, "%s/variation.png", dir);
    unlink(store);

    /* help and usage errors */
    static const char *verbs[] = {"model", "variation"};
    for (int i = 0; i < (ES_HAVE_FIGURES ? 2 : 1); i++) {
        ES_RUN(&r, dir, verbs[i], "--help");
        ES_CHECK(r.status == 0 && strstr(r.out, "usage: edgespace"));
    }
    ES_RUN(&r, dir, "model", store);
    ES_CHECK(r.status == 2 && strstr(r.err, "give a STORE and a FORMULA"));
    ES_RUN(&r, dir, "model", store, "~ a", "--type", "IV");
    ES_CHECK(r.status == 2 && strstr(r.err, "--type is I, II or III, not 'IV'"));
    ES_RUN(&r, dir, "model", store, "~ a", "--figure", fig);
    ES_CHECK(r.status == 2 && strstr(r.err, "--figure needs --edges TERM"));
    ES_RUN(&r, dir, "export", store, "--result", "model/m");
    ES_CHECK(r.status == 2 && strstr(r.err, "--result needs --output PATH"));
    ES_RUN(&r, dir, "export", store, "--table", "anova", "--output", "-");
    ES_CHECK(r.status == 2 && strstr(r.err, "go with --result"));

    /* the faces, their lengths, and failures on the store */
    ES_RUN(&r, dir, "synth", "face", "--count", "6", "--noise", "0.002", "-o", faces, "--replace");
    ES_CHECK(r.status == 0);
    ES_RUN(&r, dir, "ingest", store, "--manifest", manifest, "-q");
    ES_CHECK(r.status == 0);
    /* export takes --where like every command (--select is the same) */
    ES_RUN(&r, dir, "export", store, "--lengths", lengths, "--where", "expression=happy");
    ES_CHECK_MSG(r.status == 0, "%s", r.err);
    {
        es__csv_table th = {0};
        es_ctx *c2 = NULL;
        if (es_ctx_new(&c2) != ES_OK) return 1;
        ES_CHECK_OK(c2, es__csv_read(c2, "lengths", lengths, 0, &th));
        ES_CHECK(th.nrecords == 1 + S && !strcmp(es__csv_field(&th, 1, 0), "face_s01_happy"));
        es__csv_table_clear(c2, &th);
        es_ctx_free(c2);
    }
    ES_RUN(&r, dir, "export", store, "--lengths", lengths);
    ES_CHECK(r.status == 0);
    ES_RUN(&r, dir, "model", store, "~ expresion");
    /* a misspelt column names the closest */
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "no label column 'expresion'") &&
                 strstr(r.err, "did you mean") && strstr(r.err, "expression"), "%s", r.err);
    /* an 18-way product (262,143 terms) is refused at its first unknown
     * column, and a product of known columns is bounded before it expands
     * (a*b*a*b... is the 3 terms of a*b): at once, not after minutes (issue
     * 25) */
    {
        char big[200], known[400];
        size_t k = (size_t)snprintf(big, sizeof big, "~ v1"), k2;
        struct timespec t0, t1;
        for (int v = 2; v <= 18; v++) k += (size_t)snprintf(big + k, sizeof big - k, "*v%d", v);
        k2 = (size_t)snprintf(known, sizeof known, "~ expression");
        for (int v = 2; v <= 18; v++)
            k2 += (size_t)snprintf(known + k2, sizeof known - k2, "*%s",
                                   v % 2 ? "expression" : "subject");
        clock_gettime(CLOCK_MONOTONIC, &t0);
        ES_RUN(&r, dir, "model", store, big);
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "formula: column 3: no label column 'v1'"),
                     "%s", r.err);
        /* (expression x subject with one face each leaves no residual) */
        ES_RUN(&r, dir, "model", store, known, "--permutations", "9", "--no-store");
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "no residual degrees of freedom"), "%s",
                     r.err);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double sec = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        ES_CHECK_MSG(sec < 5, "two bounded formulas took %.1f s", sec);
    }
    /* one cap for every permutation count (issue 25: --edge-permutations and
     * compare -p took 2^40) */
    ES_RUN(&r, dir, "model", store, "~ expression", "--edge-permutations", "1099511627776");
    ES_CHECK_MSG(r.status == 2 && strstr(r.err, "from 0 to 100000000"), "%s", r.err);
    ES_RUN(&r, dir, "model", store, "~ expression", "--permutations", "100000001");
    ES_CHECK_MSG(r.status == 2 && strstr(r.err, "from 0 to 100000000"), "%s", r.err);
    ES_RUN(&r, dir, "model", store, "~ expression", "--block", "subjct");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "'subjct'") && strstr(r.err, "did you mean") &&
                 strstr(r.err, "subject"), "%s", r.err);
    ES_RUN(&r, dir, "export", store, "--result", "model/m", "--output", "-");
    ES_CHECK(r.status == 1 && strstr(r.err, "the store has no result model/m"));

    /* subject as term and block: the ANOVA against the closed form */
    ES_RUN(&r, dir, "model", store, "~ expression + subject", "--block", "subject", "--permutations", "99",
           "--pairwise", "expression", "--edges", "expression", "-n", "m", "-o", anova,
           ES_HAVE_FIGURES ? "--figure" : "--seed", ES_HAVE_FIGURES ? fig : "7");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "(block)") &&
                 strstr(r.out, "stored as /analysis/model/m") && strstr(r.out, "pairwise table: ") &&
                 strstr(r.out, "edges with FDR q < 0.05"), "%s%s", r.out, r.err);
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    es__csv_table ta = {0}, tl = {0};
    double ss[3];
    ES_CHECK_OK(ctx, es__csv_read(ctx, "anova", anova, 0, &ta));
    ES_CHECK_OK(ctx, es__csv_read(ctx, "lengths", lengths, 0, &tl));
    ES_CHECK(closed_form(&tl, ss));
    ES_CHECK_CLOSE(csv_value(&ta, "expression", 2), ss[0], 1e-9, 0);
    ES_CHECK_CLOSE(csv_value(&ta, "subject", 2), ss[1], 1e-9, 0);
    ES_CHECK_CLOSE(csv_value(&ta, "Residual", 2), ss[2], 1e-9, 0);
    const double df_res = N - 1 - (X - 1) - (S - 1);
    ES_CHECK(csv_value(&ta, "Residual", 1) == df_res);
    ES_CHECK_CLOSE(csv_value(&ta, "expression", 5), (ss[0] / (X - 1)) / (ss[2] / df_res), 1e-9,
                   0);
    /* p of 99 permutations: at its floor 1/100 for this strong an effect */
    ES_CHECK_CLOSE(csv_value(&ta, "expression", 7), 0.01, 1e-12, 0);
    ES_CHECK(isnan(csv_value(&ta, "subject", 7)) && isnan(csv_value(&ta, "subject", 6)));
    /* the effect size of so strong an effect is far out in its distribution */
    ES_CHECK_MSG(csv_value(&ta, "expression", 6) > 2, "Z %g", csv_value(&ta, "expression", 6));
    es__csv_table_clear(ctx, &ta);
    es__csv_table_clear(ctx, &tl);

    /* the stored table reads back the same; the other tables, the errors */
    char *want = NULL;
    size_t wn = 0;
    ES_CHECK_OK(ctx, es__read_file(ctx, anova, ES__READ_TEXT, &want, &wn));
    ES_RUN(&r, dir, "export", store, "--result", "model/m", "--output", "-");
    ES_CHECK_MSG(r.status == 0 && want && !strcmp(r.out, want), "%s%s", r.out, r.err);
    es__free(ctx, want);
    ES_RUN(&r, dir, "export", store, "--result", "model/m", "--table", "pairwise", "--output", "-");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "level_a,level_b,d,ucl,z,p\n") &&
                 strstr(r.out, "happy,neutral,"), "%s%s", r.out, r.err);
    /* ... and equals the pairwise table -o wrote beside the ANOVA table */
    ES_CHECK_OK(ctx, es__read_file(ctx, pairwise_csv, ES__READ_TEXT, &want, &wn));
    ES_CHECK_MSG(want && !strcmp(r.out, want), "%s", r.out);
    es__free(ctx, want);
    ES_RUN(&r, dir, "export", store, "--result", "model/m", "--table", "attributes", "--output", "-");
    ES_CHECK(r.status == 0 && strstr(r.out, "formula,~ expression + subject\n") &&
             strstr(r.out, "block,subject\n"));
    ES_RUN(&r, dir, "export", store, "--result", "model/m", "--table", "nope", "--output", "-");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "(tables: anova, coefficients,"), "%s", r.err);
    ES_RUN(&r, dir, "info", store);
    ES_CHECK(r.status == 0 && strstr(r.out, "model"));

    /* a GPA result's tables carry the rows' ids and labels */
    ES_RUN(&r, dir, "gpa", store, "--name", "g");
    ES_CHECK(r.status == 0);
    ES_RUN(&r, dir, "export", store, "--result", "gpa/g", "--output", "-");
    ES_CHECK_MSG(r.status == 0 && !strncmp(r.out, "id,file,subject,expression,centroid_size", 40)
                 && strstr(r.out, "\nface_s01_neutral,face_s01_neutral.obj,s01,neutral,"),
                 "%s%s", r.out, r.err);
    ES_RUN(&r2, dir, "model", store, "~ expression", "--gpa", "g", "--no-store", "--permutations", "0");
    ES_CHECK_MSG(r2.status == 0 && strstr(r2.out, "expression") && !strstr(r2.out, "stored"),
                 "%s%s", r2.out, r2.err);
    /* a nested formula: R's term labels in the table, its error term in the
     * error column; a malformed one names its column (exit 1) */
    ES_RUN(&r2, dir, "model", store, "~ expression/log(size)", "--error",
           "expression=log(size):expression", "--no-store", "-p", "0", "-o", "-");
    ES_CHECK_MSG(r2.status == 0 && strstr(r2.out, "\nexpression,2,") &&
                 strstr(r2.out, "\nexpression:log(size),3,") &&
                 strstr(r2.out, ",expression:log(size)\n"), "%s%s", r2.out, r2.err);
    ES_RUN(&r2, dir, "model", store, "~ expression//subject", "--no-store");
    ES_CHECK_MSG(r2.status == 1 && strstr(r2.err, "column 14: expected a term after the '/' at "
                                          "column 13, found '/'"), "%s", r2.err);

#if ES_HAVE_FIGURES
    ES_CHECK(is_png(fig));
    ES_RUN(&r, dir, "variation", store, "-o", var);
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "edgespace variation: "), "%s", r.err);
    ES_RUN(&r, dir, "pca", store);
    ES_CHECK(r.status == 0);
    ES_RUN(&r, dir, "variation", store, "--pcs", "1", "-o", var);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "axis 1: ") && is_png(var), "%s%s", r.out, r.err);
    /* a PCA that is not there: the message lists those that are */
    ES_RUN(&r, dir, "plot-pca", store, "--pca", "nope", "-o", var);
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "no PCA named 'nope' (pca results: default)"),
                 "%s", r.err);
    unlink(var);
    ES_RUN(&r, dir, "variation", store, "--coef", "m:expression=happy", "--sd", "1", "-o", var);
    ES_CHECK_MSG(r.status == 0 && is_png(var), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "variation", store, "--coef", "m:expression=sad", "-o", var);
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "sad"), "%s", r.err);
    ES_RUN(&r, dir, "variation", store, "--pcs", "1,x", "-o", var);
    ES_CHECK(r.status == 2 && strstr(r.err, "--pcs wants"));
#endif

    /* results: the list, and deletion all or nothing */
    ES_RUN(&r, dir, "results", store);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "model/m ") && strstr(r.out, "gpa/g ") &&
                 strstr(r.out, "edgespace model "), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "results", store, "--delete", "gpa/g", "--delete", "model/none");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "no result model/none") &&
                 strstr(r.err, "(model results: m)"), "%s", r.err);
    ES_RUN(&r, dir, "results", store, "--delete", "point/nothere");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "(no point results; the store has: ") &&
                 strstr(r.err, "gpa") && strstr(r.err, "model"), "%s", r.err);
    ES_RUN(&r, dir, "results", store, "--delete", "model/n");   /* one edit from 'm' */
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "(did you mean 'm'?)"), "%s", r.err);
    /* the message names the command once, not "mean: mean:" */
    ES_RUN(&r, dir, "mean", store, "--where", "expression=sad");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "\nedgespace mean: no rows match") &&
                 !strstr(r.err, "mean: mean:"), "%s", r.err);
    ES_RUN(&r, dir, "results", store, "--kind", "gpa");
    ES_CHECK(r.status == 0 && strstr(r.out, "gpa/g ") && !strstr(r.out, "model/m"));
    ES_RUN(&r, dir, "results", store, "--delete", "gpa/g");
    ES_CHECK(r.status == 0 && strstr(r.out, "deleted gpa/g"));
    ES_RUN(&r, dir, "results", store, "--kind", "gpa");
    ES_CHECK(r.status == 0 && strstr(r.out, "no results of kind gpa"));
    ES_RUN(&r, dir, "results", store, "--delete", "gpa");
    ES_CHECK(r.status == 2 && strstr(r.err, "KIND/NAME"));
    es_ctx_free(ctx);
    ES_TEST_END();
}
