/* tests/stats/test_formula_nest.c — R's nesting operators in formulas,
 * a/b (= a + a:b) and b %in% a (= b:a), against R:
 *  - each form's expansion equals the term labels R 4.2.2 printed for
 *    attr(terms(FORMULA), "term.labels") (the table below), and, where
 *    Rscript runs here, the labels R prints now (skipped without it);
 *  - the sums of squares, degrees of freedom, F and R^2 of nested designs
 *    equal vegan 2.6-4's adonis2(dist(Y) ~ ..., by = "terms") on the same
 *    data (the R commands above the table), and an error term of the
 *    nested factor gives F = MS_pop / MS_pop:ind of those numbers;
 *  - types II and III of ~ w + pop/ind against their definitions on R's
 *    model.matrix, and pop's LS means in ~ pop/ind against the means of
 *    each population's own cells (R's aggregate), as emmeans nests;
 *  - the malformed forms (a/, /b, a//b, %in% without a side, an unknown
 *    %op%) are refused naming their column.
 */
#include "es_test.h"
#include "es_test_files.h"
#include "edgespace/es_model.h"

#include <math.h>

/* R 4.2.2: for (f in FORMULAS) cat(attr(terms(as.formula(f)), "term.labels"), sep = " | ") */
static const struct {
    const char *formula, *labels;
} expansions[] = {
    {"~ a/b", "a | a:b"},
    {"~ a/(b+c)", "a | a:b | a:c"},
    {"~ (a+b)/c", "a | b | a:b:c"},
    {"~ a/b/c", "a | a:b | a:b:c"},
    {"~ b %in% a", "b:a"},
    {"~ a + b %in% a", "a | a:b"},
    {"~ a*b/c", "a | b | a:b | a:b:c"},
    {"~ a/b*c", "a | c | a:b | a:c | a:b:c"},
    {"~ a:b/c", "a:b | a:b:c"},
    {"~ a/b + c", "a | c | a:b"},
    {"~ a/b:c", "a | a:b:c"},
    {"~ (a/b)/c", "a | a:b | a:b:c"},
    {"~ a/(b/c)", "a | a:b | a:b:c"},
    {"~ a/b %in% c", "a | a:b:c"},
    {"~ b %in% a/c", "b:a | b:a:c"},
    {"~ a + b %in% a + c %in% b %in% a", "a | a:b | a:b:c"},
    {"~ b %in% (a+c)", "b:a:c"},
    {"~ (b+c) %in% a", "b:a | c:a"},
    {"~ b %in% a:c", "b:a:c"},
    {"~ a/(b*c)", "a | a:b | a:c | a:b:c"},
    {"~ b/a + a", "b | a | b:a"},
    {"~ a/a", "a"},
    {"~ a/b + a:b", "a | a:b"},
    {"~ b:a + a/b", "a | b:a"},
    {"~ a/b + b", "a | b | a:b"},
    {"~ b %in% a + a", "a | b:a"},
    {"~ factor(x)/b", "factor(x) | factor(x):b"},
    {"~ population/individual", "population | population:individual"},
};
enum { NEXP = sizeof expansions / sizeof *expansions };

/* The formula's terms as R prints term.labels joined by " | ". */
static void joined_terms(const es_formula *f, char *buf, size_t n)
{
    buf[0] = '\0';
    for (int64_t j = 0; j < es_formula_nterms(f); j++) {
        if (j) strncat(buf, " | ", n - strlen(buf) - 1);
        strncat(buf, es_formula_term(f, j), n - strlen(buf) - 1);
    }
}

static void test_expansions(es_ctx *ctx, char got[NEXP][200])
{
    for (int k = 0; k < NEXP; k++) {
        es_formula *f = NULL;
        got[k][0] = '\0';
        ES_CHECK_OK(ctx, es_formula_parse(ctx, expansions[k].formula, &f));
        if (!f) continue;
        joined_terms(f, got[k], 200);
        ES_CHECK_MSG(!strcmp(got[k], expansions[k].labels), "%s: %s, R: %s",
                     expansions[k].formula, got[k], expansions[k].labels);
        es_formula_free(f);
    }
}

/* The same formulas through the R of this machine, when there is one: its
 * labels must equal ours (a newer R that changed them would show here). */
static void test_expansions_live(char got[NEXP][200])
{
    if (system("Rscript --version >/dev/null 2>&1")) {
        fprintf(stderr, "note: no Rscript here; the expansions were compared with R 4.2.2's "
                "labels only\n");
        return;
    }
    const char *dir = es_test_tmpdir("formula-nest");
    char script[600], out[600], cmd[1400];
    snprintf(script, sizeof script, "%s/terms.R", dir);
    snprintf(out, sizeof out, "%s/terms.txt", dir);
    FILE *fp = fopen(script, "w");
    ES_CHECK(fp != NULL);
    if (!fp) return;
    fputs("for (f in c(", fp);
    for (int k = 0; k < NEXP; k++) fprintf(fp, "%s'%s'", k ? ", " : "", expansions[k].formula);
    fputs(")) cat(paste(attr(terms(as.formula(f)), 'term.labels'), collapse = ' | '), "
          "'\\n', sep = '')\n", fp);
    fclose(fp);
    snprintf(cmd, sizeof cmd, "Rscript '%s' > '%s' 2>&1", script, out);
    ES_CHECK_MSG(system(cmd) == 0, "%s failed", cmd);
    fp = fopen(out, "r");
    ES_CHECK(fp != NULL);
    char line[400];
    for (int k = 0; fp && k < NEXP; k++) {
        if (!fgets(line, sizeof line, fp)) {
            ES_CHECK_MSG(0, "R printed %d lines of %d", k, NEXP);
            break;
        }
        line[strcspn(line, "\n")] = '\0';
        ES_CHECK_MSG(!strcmp(line, got[k]), "%s: ours %s, this R's %s", expansions[k].formula,
                     got[k], line);
    }
    if (fp) fclose(fp);
}

/* Each malformed use and what its error must say, column first. */
static const struct {
    const char *formula, *error;
} malformed[] = {
    {"~ a/", "column 5: expected a term after the '/' at column 4, found the end"},
    {"~ /b", "column 3: '/' has no term before it"},
    {"~ a//b", "column 5: expected a term after the '/' at column 4, found '/'"},
    {"~ a + (/b)", "column 8: '/' has no term before it"},
    {"~ b %in%", "column 9: expected a term after the '%in%' at column 5, found the end"},
    {"~ %in% a", "column 3: '%in%' has no term before it"},
    {"~ a %o% b", "column 5: unknown operator '%o%'"},
    {"~ a/b)", "column 6: unexpected ')'"},
};

static void test_malformed(es_ctx *ctx)
{
    es_formula *f = NULL;
    for (size_t k = 0; k < sizeof malformed / sizeof *malformed; k++)
        ES_CHECK_FAILS(ctx, es_formula_parse(ctx, malformed[k].formula, &f), ES_EFORMAT,
                       malformed[k].error);
    ES_CHECK(f == NULL);
    /* a/b expands to |a| + |b| terms: bounded like a product */
    ES_CHECK_OK(ctx, es_formula_parse(ctx, "~ (a*b*c*d*e*f*g*h*i*j)/k", &f));
    ES_CHECK(f && es_formula_nterms(f) == 1024);   /* 1023 + the one nested term */
    es_formula_free(f);
    f = NULL;
    ES_CHECK_FAILS(ctx, es_formula_parse(ctx, "~ (a*b*c*d*e*f*g*h*i*j)/(k + l)", &f), ES_EFORMAT,
                   "column 24: the formula expands to more than 1024 terms");
}

/* ---- the nested design against adonis2 -------------------------------------- */

enum { N = 20, P = 4 };

/* Three populations of 8, 6 and 6 rows; individuals i1..i3 within each (the
 * same names in every population: only nesting tells them apart), with
 * unequal replicates; a covariate w; Y with a population effect on one
 * variable and an individual effect on all. The same in R:
 *   pop <- rep(c("A", "B", "C"), c(8, 6, 6))
 *   ind <- c("i1","i1","i1","i2","i2","i2","i3","i3", "i1","i1","i1","i2","i2","i2",
 *            "i1","i1","i2","i2","i2","i2")
 *   P <- 4; N <- 20
 *   Y <- outer(0:(N-1), 0:(P-1), function(i, e) sin(1.3 * i + 0.7 * e)) +
 *        outer(match(pop, c("A","B","C")) - 1, 0:(P-1), function(g, e) 0.8 * g * (e == 1)) +
 *        outer(as.integer(factor(paste(pop, ind))), 0:(P-1),
 *              function(k, e) 0.3 * sin(k * (e + 2)))
 *   d <- data.frame(pop = pop, ind = ind, w = cos(0.9 * (0:(N-1))) + 0.1 * (0:(N-1)))
 */
typedef struct nested {
    const char *pop[N], *ind[N];
    double w[N], yt[N * P];   /* yt: row-major, N x P */
} nested;

static void make(nested *d)
{
    static const char *ind[N] = {"i1", "i1", "i1", "i2", "i2", "i2", "i3", "i3", "i1", "i1",
                                 "i1", "i2", "i2", "i2", "i1", "i1", "i2", "i2", "i2", "i2"};
    for (int i = 0; i < N; i++) {
        int g = i < 8 ? 0 : i < 14 ? 1 : 2;
        d->pop[i] = g == 0 ? "A" : g == 1 ? "B" : "C";
        d->ind[i] = ind[i];
        /* the cell's rank among the sorted "pop ind" names, 1..7 (R's factor codes) */
        int cell = (g == 0 ? 0 : g == 1 ? 3 : 5) + (ind[i][1] - '0');
        d->w[i] = cos(0.9 * i) + 0.1 * i;
        for (int e = 0; e < P; e++)
            d->yt[e + i * P] = sin(1.3 * i + 0.7 * e) + 0.8 * g * (e == 1) +
                               0.3 * sin(cell * (e + 2.0));
    }
}

/* R: r <- adonis2(as.formula(f), data = d, by = "terms", permutations = 0);
 *    r$Df, sprintf("%.17g", r$SumOfSqs), sprintf("%.17g", r$F)
 * (rows: the terms, then Residual, then Total). */
static const struct {
    const char *formula;
    int nterms;
    const char *terms[3];
    int df[5];
    double ss[5], f[3];
} adonis[] = {
    {"~ pop/ind", 2, {"pop", "pop:ind"}, {2, 4, 13, 19},
     {9.0723236836165242, 10.467863887014463, 28.749949527772596, 48.290137098403576},
     {2.0511376510954218, 1.1833258211438937}},
    {"~ pop + ind %in% pop", 2, {"pop", "pop:ind"}, {2, 4, 13, 19},
     {9.0723236836165242, 10.467863887014463, 28.749949527772596, 48.290137098403576},
     {2.0511376510954218, 1.1833258211438937}},
    {"~ pop/w", 2, {"pop", "pop:w"}, {2, 3, 14, 19},
     {9.0723236836165242, 12.70682927139687, 26.510984143390182, 48.290137098403576},
     {2.3954699471671366, 2.2367535010817994}},
    {"~ w + pop/ind", 3, {"w", "pop", "pop:ind"}, {1, 2, 4, 12, 19},
     {3.4223541823944434, 5.8117741078693594, 12.875450018646552, 26.180558789493226,
      48.290137098403576},
     {1.5686544553516109, 1.3319289678878217, 1.4753829498643538}},
    {"~ (w + pop)/ind", 3, {"w", "pop", "w:pop:ind"}, {1, 2, 6, 10, 19},
     {3.4223541823944434, 5.8117741078693594, 19.524565790963322, 19.531443017176461,
      48.290137098403576},
     {1.7522280250285327, 1.4877994684669058, 1.6660798158293537}},
};

static es_model *fit(es_ctx *ctx, const nested *x, const char *formula, es_design **d,
                     const int64_t *error, es_ss_type type)
{
    es_model_column cols[3] = {{"pop", x->pop, NULL, NULL}, {"ind", x->ind, NULL, NULL},
                               {"w", NULL, x->w, NULL}};
    es_formula *f = NULL;
    es_model *m = NULL;
    *d = NULL;
    ES_CHECK_OK(ctx, es_formula_parse(ctx, formula, &f));
    if (f) ES_CHECK_OK(ctx, es_design_build(ctx, f, N, cols, 3, ES_CONTRASTS_TREATMENT, d));
    es_formula_free(f);
    if (!*d) return NULL;
    es_source src = es_source_matrix((es_mat){(double *)x->yt, P, N, P}, NULL, 0);
    es_model_opts o;
    es_model_opts_init(&o);
    o.permutations = 0;
    o.error = error;
    o.ss_type = type;
    ES_CHECK_OK(ctx, es_model_fit(ctx, *d, &src, &o, &m));
    return m;
}

/* The largest relative difference from adonis2's SS and F (reported). */
static double maxrel;
static void track(double got, double want)
{
    double d = fabs(got - want) / fabs(want);
    if (!(d <= maxrel)) maxrel = d;
}

static void test_adonis(es_ctx *ctx, const nested *x)
{
    for (size_t k = 0; k < sizeof adonis / sizeof *adonis; k++) {
        es_design *d = NULL;
        es_model *m = fit(ctx, x, adonis[k].formula, &d, NULL, ES_SS_TYPE_I);
        const int t = adonis[k].nterms;
        ES_CHECK_MSG(m && m->nterms == t, "%s: %lld terms", adonis[k].formula,
                     m ? (long long)m->nterms : -1LL);
        for (int j = 0; m && m->nterms == t && j < t; j++) {
            ES_CHECK_MSG(!strcmp(d->terms[j], adonis[k].terms[j]), "%s: term %d is %s, R: %s",
                         adonis[k].formula, j, d->terms[j], adonis[k].terms[j]);
            ES_CHECK_MSG(m->df[j] == adonis[k].df[j], "%s: df of %s %lld, R: %d",
                         adonis[k].formula, d->terms[j], (long long)m->df[j], adonis[k].df[j]);
            ES_CHECK_CLOSE(m->ss[j], adonis[k].ss[j], 1e-10, 0);
            ES_CHECK_CLOSE(m->f[j], adonis[k].f[j], 1e-10, 0);
            track(m->ss[j], adonis[k].ss[j]);
            track(m->f[j], adonis[k].f[j]);
            ES_CHECK_CLOSE(m->r2[j], adonis[k].ss[j] / adonis[k].ss[t + 1], 1e-10, 0);
        }
        if (m) {
            ES_CHECK(m->df_resid == adonis[k].df[t]);
            ES_CHECK_CLOSE(m->rss, adonis[k].ss[t], 1e-10, 0);
            track(m->rss, adonis[k].ss[t]);
            ES_CHECK_CLOSE(m->tss, adonis[k].ss[t + 1], 1e-10, 0);
        }
        es_model_free(m);
        es_design_free(d);
    }
    fprintf(stderr, "nested designs against adonis2: largest relative difference of SS, RSS "
            "and F %.1e\n", maxrel);
}

/* Types II and III of ~ w + pop/ind: pop:ind contains pop, so pop's type
 * II is after w alone, its type III after w and pop:ind as coded (treatment
 * contrasts, ind by indicators within pop). R, the definitions on
 * model.matrix (d and Y as above):
 *   X <- model.matrix(~ w + pop/ind, d); a <- attr(X, "assign")
 *   rss <- function(keep) sum(qr.resid(qr(X[, keep, drop = FALSE]), Y)^2)
 *   type III of term j: rss(a != j) - rss(a >= 0)
 *   type II: the same within the columns of the terms not containing j */
static void test_types(es_ctx *ctx, const nested *x)
{
    static const double ss2[3] = {2.5693907382793668, 5.8117741078693612, 12.875450018646546};
    static const double ss3[3] = {2.5693907382793668, 5.5139318288640595, 12.875450018646546};
    const double rss = 26.180558789493226, df_resid = 12;   /* adonis[3] */
    const int df[3] = {1, 2, 4};
    for (int type = 2; type <= 3; type++) {
        es_design *d = NULL;
        es_model *m = fit(ctx, x, "~ w + pop/ind", &d, NULL, (es_ss_type)type);
        for (int j = 0; m && m->nterms == 3 && j < 3; j++) {
            const double want = type == 2 ? ss2[j] : ss3[j];
            ES_CHECK(m->df[j] == df[j]);
            ES_CHECK_CLOSE(m->ss[j], want, 1e-10, 0);
            ES_CHECK_CLOSE(m->f[j], (want / df[j]) / (rss / df_resid), 1e-10, 0);
        }
        ES_CHECK(m && m->nterms == 3);
        es_model_free(m);
        es_design_free(d);
    }
}

/* --error pop=pop:ind: the population tested against the individuals
 * within it, F = (SS_pop / 2) / (SS_pop:ind / 4) of adonis2's sums. */
static void test_error_term(es_ctx *ctx, const nested *x)
{
    const int64_t error[2] = {1, -1};
    es_design *d = NULL;
    es_model *m = fit(ctx, x, "~ pop/ind", &d, error, ES_SS_TYPE_I);
    if (m) {
        ES_CHECK(m->error[0] == 1 && m->error[1] == -1);
        ES_CHECK_CLOSE(m->f[0], (9.0723236836165242 / 2) / (10.467863887014463 / 4), 1e-10, 0);
        ES_CHECK_CLOSE(m->f[1], adonis[0].f[1], 1e-10, 0);
    }
    es_model_free(m);
    es_design_free(d);
}

/* Pairwise LS means of pop in ~ pop/ind: each population's mean of its own
 * individuals' cell means (ind is nested: A has i1..i3, B and C only i1,
 * i2), as emmeans averages a nested factor. The model is saturated in the
 * cells, so these are the data's cell means; R (Y, pop, ind as above):
 *   cm <- aggregate(Y, list(pop = pop, ind = ind), mean)
 *   t(as.matrix(aggregate(cm[, 3:6], list(cm$pop), mean)[, -1]))
 * The distances are those of the rows; ind itself cannot be compared, pop
 * in ~ w/pop (held only with a covariate) can. */
static void test_pairwise(es_ctx *ctx, const nested *x)
{
    static const double want[3][P] = {
        {0.22057697577724733, 0.19070247621726119, -0.013842426753334296, -0.22325544420934623},
        {-0.10057299836295805, 0.63192207992489846, -0.022068500153252735, 0.12504881164059733},
        {-0.0049828019600954565, 1.7636017808861653, 0.20848932939120812, 0.10136651111740463}};
    es_design *d = NULL;
    es_model *m = fit(ctx, x, "~ pop/ind", &d, NULL, ES_SS_TYPE_I);
    es_model_pairwise *pw = NULL;
    if (m) ES_CHECK_OK(ctx, es_model_pairwise_fit(ctx, m, "pop", NULL, &pw));
    for (int a = 0; pw && a < 3; a++) {
        for (int e = 0; e < P; e++) ES_CHECK_CLOSE(pw->lsmeans[a + e * 3], want[a][e], 1e-10, 1e-12);
        for (int b = 0; b < 3; b++) {
            double dd = 0;
            for (int e = 0; e < P; e++) dd += (want[a][e] - want[b][e]) * (want[a][e] - want[b][e]);
            ES_CHECK_CLOSE(pw->dist[a + b * 3], sqrt(dd), 1e-10, 1e-12);
        }
    }
    es_model_pairwise_free(pw);
    pw = NULL;
    if (m) ES_CHECK_FAILS(ctx, es_model_pairwise_fit(ctx, m, "ind", NULL, &pw), ES_EINVAL,
                          "'ind' is nested in 'pop'");
    es_model_free(m);
    es_design_free(d);
    /* pop held only with the covariate (~ w/pop: slopes by population) is
     * not nested: its levels are the same at every w, and are compared */
    m = fit(ctx, x, "~ w/pop", &d, NULL, ES_SS_TYPE_I);
    if (m) ES_CHECK_OK(ctx, es_model_pairwise_fit(ctx, m, "pop", NULL, &pw));
    ES_CHECK(pw && pw->nlevels == 3);
    es_model_pairwise_free(pw);
    es_model_free(m);
    es_design_free(d);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    static char got[NEXP][200];
    test_expansions(ctx, got);
    test_expansions_live(got);
    test_malformed(ctx);
    static nested x;
    make(&x);
    test_adonis(ctx, &x);
    test_types(ctx, &x);
    test_error_term(ctx, &x);
    test_pairwise(ctx, &x);
    es_ctx_free(ctx);
    ES_TEST_END();
}
