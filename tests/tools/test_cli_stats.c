/* tests/tools/test_cli_stats.c — the statistics commands end to end: a small
 * study of grid meshes (7 subjects, neutral and happy, one subject without
 * a happy scan) is ingested, then mean, pca, diff, point, project and plot-pca
 * run through $EDGESPACE; the stored results are checked against the
 * library called directly, and the CSV exports and messages by content. */
#include "es_test.h"
#include "core/core_private.h"
#include "edgespace/edgespace.h"
#include "edgespace/es_study.h"

#include <stdarg.h>
#include <unistd.h>

enum { G = 5, NV = G * G, NS = 7 };

static char dir[256];
static const char *exe;

static void write_obj(const char *name, double scale, double bump, es_rng *rng)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) ES_TEST_SKIP("cannot write %s", path);
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            double x = i, y = j, r2 = (x - 2) * (x - 2) + (y - 2) * (y - 2);
            double z = 0.1 * es_rng_normal(rng) + bump * exp(-r2);
            fprintf(f, "v %.17g %.17g %.17g\n", scale * (x + 0.05 * es_rng_normal(rng)),
                    scale * y, scale * z);
        }
    for (int j = 0; j + 1 < G; j++)
        for (int i = 0; i + 1 < G; i++) {
            int a = 1 + i + G * j, b = a + 1, c = a + G, d = c + 1;
            fprintf(f, "f %d %d %d\nf %d %d %d\n", a, b, d, a, d, c);
        }
    fclose(f);
}

/* Run "$EDGESPACE ARGS" through the shell; output (stdout + stderr) into out. */
static int run(char *out, size_t n, const char *fmt, ...) ES__PRINTF(3, 4);
static int run(char *out, size_t n, const char *fmt, ...)
{
    char cmd[2048];
    int k = snprintf(cmd, sizeof cmd, "cd '%s' && '%s' ", dir, exe);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd + k, sizeof cmd - (size_t)k, fmt, ap);
    va_end(ap);
    strncat(cmd, " 2>&1", sizeof cmd - strlen(cmd) - 1);
    FILE *p = popen(cmd, "r");
    if (!p) return -1;
    size_t got = fread(out, 1, n - 1, p);
    out[got] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int count_lines(const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    int n = 0, c;
    while ((c = fgetc(f)) != EOF) n += c == '\n';
    fclose(f);
    return n;
}

static void first_line(const char *name, char *buf, size_t n)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "r");
    buf[0] = '\0';
    if (f && fgets(buf, (int)n, f)) buf[strcspn(buf, "\n")] = '\0';
    if (f) fclose(f);
}

int main(void)
{
    ES_TEST_BEGIN();
    exe = getenv("EDGESPACE");
    if (!exe) ES_TEST_SKIP("EDGESPACE is not set");
    snprintf(dir, sizeof dir, "/tmp/es_cli_stats_XXXXXX");
    if (!mkdtemp(dir)) ES_TEST_SKIP("no temporary directory");
    es_rng rng;
    es_rng_init(&rng, 2024);
    char path[512], out[16384];
    snprintf(path, sizeof path, "%s/manifest.csv", dir);
    FILE *m = fopen(path, "w");
    fprintf(m, "file,subject,expression\n");
    for (int s = 1; s <= NS; s++) {
        char name[64];
        double scale = 1 + 0.1 * es_rng_normal(&rng);
        snprintf(name, sizeof name, "s%d_neutral.obj", s);
        write_obj(name, scale, 0.0, &rng);
        fprintf(m, "%s,s%d,neutral\n", name, s);
        if (s == NS) continue;   /* s7 has no happy scan */
        snprintf(name, sizeof name, "s%d_happy.obj", s);
        write_obj(name, scale, 1.0 + 0.1 * es_rng_normal(&rng), &rng);
        fprintf(m, "%s,s%d,happy\n", name, s);
    }
    fclose(m);
    write_obj("new.obj", 1.0, 0.5, &rng);
    ES_CHECK(run(out, sizeof out, "ingest study.h5 --manifest manifest.csv -q") == 0);

    /* --help everywhere, usage errors exit 2 */
    static const char *const verbs[] = {"mean", "pca", "diff", "project", "point", "plot-pca"};
    for (int i = 0; i < (ES_HAVE_FIGURES ? 6 : 5); i++) {
        ES_CHECK(run(out, sizeof out, "%s --help", verbs[i]) == 0 && strstr(out, "usage:"));
        ES_CHECK(run(out, sizeof out, "%s --bogus study.h5", verbs[i]) == 2);
    }
    ES_CHECK(run(out, sizeof out, "pca study.h5 --method randomized") == 2);

    /* mean per expression */
    ES_CHECK(run(out, sizeof out, "mean study.h5 --by expression --output means.csv") == 0);
    ES_CHECK(strstr(out, "neutral") && strstr(out, "stored as /analysis/mean/expression"));
    char line[4096];
    first_line("means.csv", line, sizeof line);
    ES_CHECK(!strcmp(line, "edge,v0,v1,neutral,happy"));

    /* pca: stored result equals a direct fit */
    ES_CHECK(run(out, sizeof out, "pca study.h5 --name p --output p") == 0);
    ES_CHECK_MSG(strstr(out, "13 rows") != NULL, "%s", out);
    ES_CHECK(count_lines("p_scores.csv") == 14);
    first_line("p_scores.csv", line, sizeof line);
    ES_CHECK(!strncmp(line, "id,file,subject,expression,PC1,PC2", 34));
    ES_CHECK(count_lines("p_eigenvalues.csv") == 13);
    ES_CHECK(run(out, sizeof out, "pca study.h5 --name top --components 2 --method randomized") == 0);

    es_ctx *ctx;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    es_store *st = NULL;
    snprintf(path, sizeof path, "%s/study.h5", dir);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &st));
    if (st) {
        es_pca *stored = NULL, *direct = NULL, *top = NULL;
        es_source src;
        ES_CHECK_OK(ctx, es_study_pca_load(ctx, st, "p", &stored, NULL, NULL));
        ES_CHECK_OK(ctx, es_study_pca_load(ctx, st, "top", &top, NULL, NULL));
        ES_CHECK_OK(ctx, es_study_source(ctx, st, NULL, 0, &src));
        ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, NULL, &direct));
        if (stored && direct && top) {
            ES_CHECK(stored->ncomp == direct->ncomp && stored->nrows == 13);
            ES_CHECK(top->ncomp == 2);
            for (int64_t k = 0; k < direct->ncomp && k < stored->ncomp; k++)
                ES_CHECK(stored->eigenvalues[k] == direct->eigenvalues[k]);
            for (int64_t k = 0; k < 2; k++)
                ES_CHECK_CLOSE(top->eigenvalues[k], direct->eigenvalues[k], 1e-8, 0);
            for (int64_t i = 0; i < 13 * stored->ncomp; i++)
                ES_CHECK(stored->scores[i] == direct->scores[i]);
        }
        /* the store source read in blocks of 1 and 7 rows, and a subset */
        for (int64_t b = 1; b <= 7 && direct; b += 6) {
            es_pca *pb = NULL;
            src.block = b;
            ES_CHECK_OK(ctx, es_pca_fit(ctx, &src, NULL, &pb));
            for (int64_t k = 0; pb && k < direct->ncomp; k++)
                ES_CHECK_CLOSE(pb->eigenvalues[k], direct->eigenvalues[k], 1e-12,
                               1e-13 * direct->eigenvalues[0]);
            es_pca_free(pb);
        }
        const int64_t sub[4] = {12, 0, 5, 3};
        double msub[4096], want[4096];
        es_source ss;
        ES_CHECK_OK(ctx, es_study_source(ctx, st, sub, 4, &ss));
        int64_t E = es_store_nedges(st);
        if (E <= 1024) {
            double *blk = malloc((size_t)(4 * E) * sizeof *blk);
            ES_CHECK_OK(ctx, es_mean(ctx, &ss, msub));
            ES_CHECK_OK(ctx, es_store_read_lengths_rows(ctx, st, sub, 4, (es_mat){blk, E, 4, E}));
            for (int64_t e = 0; e < E; e++) {
                want[e] = (blk[e] + blk[e + E] + blk[e + 2 * E] + blk[e + 3 * E]) / 4;
                ES_CHECK_CLOSE(msub[e], want[e], 1e-14, 0);
            }
            free(blk);
        }
        es_pca_free(stored);
        es_pca_free(direct);
        es_pca_free(top);
        es_store_close(st);
        st = NULL;
    }

    /* diff: 6 pairs, s7 unpaired and named */
    ES_CHECK(run(out, sizeof out, "diff study.h5 --pair-by subject --from neutral --to happy "
                 "--name smile --output smile.csv") == 0);
    ES_CHECK_MSG(strstr(out, "6 pairs") && strstr(out, "1 unpaired rows: s7_neutral"), "%s", out);
    first_line("smile.csv", line, sizeof line);
    ES_CHECK(!strcmp(line, "edge,v0,v1,mean,sd,se,t"));
    ES_CHECK(run(out, sizeof out, "diff study.h5 --pair-by subject --from neutral --to sad") == 1);
    ES_CHECK(run(out, sizeof out, "diff study.h5 --pair-by expression --from neutral "
                 "--to happy --column expression") == 1);
    ES_CHECK_MSG(strstr(out, "two 'from' rows"), "%s", out);

    /* point: the stored point is mean(neutral) + smile */
    ES_CHECK(run(out, sizeof out, "point study.h5 'mean[expression=neutral] + diff:smile' "
                 "--name hm") == 0);
    ES_CHECK_MSG(strstr(out, "valid") && strstr(out, "weights sum to 1"), "%s", out);
    ES_CHECK(run(out, sizeof out, "point study.h5 'mean + 2*pc:1' --pca p") == 0);
    ES_CHECK(run(out, sizeof out, "point study.h5 'lerp(row:s1_neutral, row:s1_happy, 60)'") == 0);
    ES_CHECK_MSG(strstr(out, "INVALID"), "%s", out);
    ES_CHECK(run(out, sizeof out, "point study.h5 'mean + (row:s1_neutral'") == 1);
    ES_CHECK_MSG(strstr(out, "edgespace point: column 23: expected ')' to close the '(' at column 8"), "%s", out);
    ES_CHECK(run(out, sizeof out, "point study.h5 'row:nobody'") == 1);
    ES_CHECK_MSG(strstr(out, "row:nobody: no row with id 'nobody'"), "%s", out);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &st));
    if (st) {
        double *pt = NULL, *dm = NULL, *sc = NULL;
        int64_t n1 = 0, n2 = 0, n3 = 0;
        es_group_result *g = NULL;
        ES_CHECK_OK(ctx, es_store_get_vector(ctx, st, "point/hm/lengths", &pt, &n1));
        ES_CHECK_OK(ctx, es_store_get_vector(ctx, st, "diff/smile/mean", &dm, &n2));
        ES_CHECK_OK(ctx, es_store_get_vector(ctx, st, "point/hm/scale", &sc, &n3));
        ES_CHECK_OK(ctx, es_study_mean(ctx, st, &(es_study_mean_opts){.where = "expression=neutral"}, &g));
        if (pt && dm && g && n1 == n2 && n1 == es_store_nedges(st)) {
            for (int64_t e = 0; e < n1; e++) ES_CHECK_CLOSE(pt[e], g->means[e] + dm[e], 1e-14, 1e-17);
            ES_CHECK(n3 == 1 && sc[0] == g->scales[0]);
        }
        es_study_group_result_free(g);
        g = NULL;
        /* library-level refusals */
        es_pca *pp = NULL;
        es_study_pca_opts so;
        es_study_pca_opts_init(&so);
        so.name = "a/b";
        ES_CHECK_FAILS(ctx, es_study_mean(ctx, st, &(es_study_mean_opts){.by = "nope"}, &g),
                       ES_ENOTFOUND, "no label column 'nope'");
        ES_CHECK_FAILS(ctx, es_study_mean(ctx, st, &(es_study_mean_opts){.where = "expression=sad"},
                                          &g), ES_EINVAL, "no rows match");
        ES_CHECK_FAILS(ctx, es_study_pca(ctx, st, &so, &pp, NULL, NULL), ES_EINVAL,
                       "bad result name");
        ES_CHECK_FAILS(ctx, es_study_pca_load(ctx, st, "missing", &pp, NULL, NULL),
                       ES_ENOTFOUND, "no PCA named 'missing'");
        ES_CHECK_FAILS(ctx, es_study_pca_load(ctx, st, NULL, &pp, NULL, NULL), ES_ENOTFOUND,
                       "several PCAs");
        ES_CHECK_FAILS(ctx, es_study_point(ctx, st, &(es_study_point_opts){.expr = "mean + pc:1"},
                                           NULL, NULL, NULL),
                       ES_ENOTFOUND, "point: pc:1: pca: several");
        ES_CHECK_FAILS(ctx, es_study_point(ctx, st, &(es_study_point_opts){.expr = "mean + pc:99",
                                                                          .pca_name = "p"},
                                           NULL, NULL, NULL),
                       ES_ENOTFOUND, "the PCA has 12 components");
        ES_CHECK_FAILS(ctx, es_study_point(ctx, st, &(es_study_point_opts){.expr = "diff:frown"},
                                           NULL, NULL, NULL),
                       ES_ENOTFOUND, "no difference named 'frown'");
        snprintf(path, sizeof path, "%s/other.obj", dir);
        FILE *o = fopen(path, "w");
        if (o) {
            fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", o);
            fclose(o);
        }
        char expr[600];
        snprintf(expr, sizeof expr, "file:%s", path);
        ES_CHECK_FAILS(ctx, es_study_point(ctx, st, &(es_study_point_opts){.expr = expr}, NULL,
                                           NULL, NULL),
                       ES_EMISMATCH, "do not match the store's topology");
        snprintf(path, sizeof path, "%s/study.h5", dir);
        es_free(ctx, pt);
        es_free(ctx, dm);
        es_free(ctx, sc);
        es_store_close(st);
    }

    /* a label value holding ',' (quoted in the manifest) is selected
     * quoted, col="a,b", by --where and by mean[...] in a point; unquoted,
     * the ',' separates terms */
    snprintf(path, sizeof path, "%s/odd.csv", dir);
    if ((m = fopen(path, "w"))) {
        fputs("file,grp\ns1_neutral.obj,\"a,b\"\ns2_neutral.obj,a\ns3_neutral.obj,\"a,b\"\n"
              "s4_neutral.obj,b\n", m);
        fclose(m);
    }
    ES_CHECK(run(out, sizeof out, "ingest odd.h5 --manifest odd.csv -q") == 0);
    ES_CHECK(run(out, sizeof out, "mean odd.h5 --where 'grp=\"a,b\"' --name ab") == 0);
    ES_CHECK(run(out, sizeof out, "point odd.h5 'mean[grp=\"a,b\"]' --name ab") == 0);
    ES_CHECK(run(out, sizeof out, "mean odd.h5 --where 'grp=a,b'") == 1);
    ES_CHECK_MSG(strstr(out, "bad filter term 'b'"), "%s", out);
    snprintf(path, sizeof path, "%s/odd.h5", dir);
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &st));
    if (st) {
        const int64_t E = es_store_nedges(st), col = es_store_find_column(st, "grp");
        int64_t ab[4], nab = 0, *sel = NULL, nsel = 0, *counts = NULL, nc = 0, n1 = 0;
        for (int64_t i = 0; i < es_store_nrows(st) && nab < 4; i++)
            if (!strcmp(es_store_label(st, i, col), "a,b")) ab[nab++] = i;
        ES_CHECK(nab == 2 && !strcmp(es_store_row_id(st, ab[0]), "s1_neutral") &&
                 !strcmp(es_store_row_id(st, ab[1]), "s3_neutral"));
        ES_CHECK_OK(ctx, es_store_select(ctx, st, "grp=\"a,b\"", &sel, &nsel));
        ES_CHECK(nsel == nab && sel && !memcmp(sel, ab, (size_t)nab * sizeof *sel));
        double *want = malloc((size_t)E * sizeof *want), *pt = NULL;
        es_mat mm = {NULL, 0, 0, 0};
        es_source src;
        ES_CHECK_OK(ctx, es_study_source(ctx, st, ab, nab, &src));
        ES_CHECK_OK(ctx, es_mean(ctx, &src, want));
        ES_CHECK_OK(ctx, es_store_get_ints(ctx, st, "mean/ab/counts", &counts, &nc));
        ES_CHECK(nc == 1 && counts && counts[0] == 2);
        ES_CHECK_OK(ctx, es_store_get_matrix(ctx, st, "mean/ab/means", &mm));
        ES_CHECK_OK(ctx, es_store_get_vector(ctx, st, "point/ab/lengths", &pt, &n1));
        if (mm.data && mm.rows == E && mm.cols == 1 && pt && n1 == E)
            for (int64_t e = 0; e < E; e++) {
                ES_CHECK_CLOSE(mm.data[e], want[e], 1e-14, 0);
                ES_CHECK_CLOSE(pt[e], want[e], 1e-14, 0);
            }
        else
            ES_CHECK_MSG(0, "means %lld x %lld, point %lld, E %lld", (long long)mm.rows,
                         (long long)mm.cols, (long long)n1, (long long)E);
        free(want);
        es_free(ctx, sel);
        es_free(ctx, counts);
        es_free(ctx, mm.data);
        es_free(ctx, pt);
        es_store_close(st);
        st = NULL;
    }
    snprintf(path, sizeof path, "%s/study.h5", dir);

    /* project a new file and a stored row */
    ES_CHECK(run(out, sizeof out, "project study.h5 --pca p new.obj s2_happy --output proj.csv") == 0);
    ES_CHECK(count_lines("proj.csv") == 3);
    ES_CHECK(run(out, sizeof out, "project study.h5 --pca p nothing_here") == 1);
    /* a failure part way leaves no partial table */
    ES_CHECK(run(out, sizeof out, "project study.h5 --pca p s2_happy nothing_here --output part.csv")
             == 1);
    snprintf(path, sizeof path, "%s/part.csv", dir);
    ES_CHECK_MSG(access(path, F_OK) != 0, "project left %s behind", path);

#if ES_HAVE_FIGURES
    /* figures */
    ES_CHECK(run(out, sizeof out, "plot-pca study.h5 --pca p --pcs 1,2 --color expression "
                 "-o pca.png") == 0);
    ES_CHECK(run(out, sizeof out, "plot-pca study.h5 --pca p --scree -o scree.svg") == 0);
    ES_CHECK(run(out, sizeof out, "plot-pca study.h5 --pca p --pcs 1,99 -o x.png") == 1);
    struct stat sb;
    snprintf(path, sizeof path, "%s/pca.png", dir);
    ES_CHECK(stat(path, &sb) == 0 && sb.st_size > 1000);
#endif

    es_ctx_free(ctx);
    if (!es_test_failures) {
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    }
    ES_TEST_END();
}
