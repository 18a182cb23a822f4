/* tests/study/test_model_store.c — linear models on a store (es_study_model)
 * and their coefficients as points (coef:MODEL:COEF).
 *
 * A store of synthetic faces (es_synth: subjects x neutral/happy/angry, a
 * numeric label "age" per subject) is modelled in edge-length space with
 * subject as term and block: the expression SS is checked against the
 * balanced design's closed form computed here from the stored lengths
 * (sum over levels of n_l ||mean_l - mean||^2), what is stored reads back,
 * the per-edge tests and pairwise LS means are there. A coefficient as a
 * point equals the stored coefficient, and its row weights reproduce it
 * from the rows (the embedding's prior gets the right combination). In
 * Procrustes space (a GPA result) the response is the aligned coordinates,
 * and a coefficient there is refused as a point. log(size) brings the CAC.
 * A nested model (~ expression + age %in% expression) takes --error by the
 * term's variables in either order, F = MS_term / MS_error, and a term it
 * lacks is refused with the model's terms listed.
 * A model cancelled from its progress callback stops and stores nothing
 * (the store's bytes unchanged), and a rolled-back result is gone.
 */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_files.h"
#include "edgespace/edgespace.h"

#include <unistd.h>

/* A progress callback that cancels at its second report (es_ctx_cancel from
 * inside the work, as the Python binding does for an exception or Ctrl-C). */
static es_ctx *cancel_ctx;
static void cancel_after_two(void *ud, const char *what, int64_t done, int64_t total)
{
    int *reports = ud;
    (void)what;
    (void)done;
    (void)total;
    if (++*reports == 2) es_ctx_cancel(cancel_ctx);
}

static es_status make_store(es_ctx *ctx, const char *path, int64_t *nrows)
{
    es_synth_set set;
    es_synth_opts so;
    es_mesh *mesh = NULL;
    es_store *s = NULL;
    es_synth_opts_init(&so);
    so.n = 8;
    so.resolution = 6;
    es_status rc = es_synth_generate(ctx, ES_SYNTH_FACE, &so, &set);
    if (rc != ES_OK) return rc;
    unlink(path);
    rc = es_mesh_new(ctx, set.nverts, set.nfaces, set.faces, set.xyz, &mesh);
    int64_t e = rc == ES_OK ? es_mesh_nedges(mesh) : 0, n = set.nmembers;
    double *len = malloc((size_t)(e * n + 1) * sizeof *len), *sc = malloc((size_t)n * sizeof *sc);
    const char **labels = malloc((size_t)(3 * n) * sizeof *labels);
    char (*age)[16] = malloc((size_t)n * sizeof *age);
    for (int64_t j = 0; j < n && rc == ES_OK; j++) {
        rc = es_edge_lengths(ctx, mesh, set.xyz + 3 * set.nverts * j, len + e * j);
        if (rc == ES_OK) rc = es_lengths_normalize(ctx, e, len + e * j, len + e * j, sc + j);
        labels[3 * j] = set.labels[j * set.nlabels];
        labels[3 * j + 1] = set.labels[j * set.nlabels + 1];
        snprintf(age[j], sizeof age[j], "%d", 20 + 3 * (int)(j / 3));
        labels[3 * j + 2] = age[j];
    }
    if (rc == ES_OK) rc = es_store_create(ctx, path, mesh, &s);
    if (rc == ES_OK) {
        const char *cols[3] = {set.label_names[0], set.label_names[1], "age"};
        es_store_rows rows = {0};
        rows.n = n;
        rows.ids = (const char *const *)set.names;
        rows.lengths = len;
        rows.scales = sc;
        rows.xyz = set.xyz;
        rows.ncols = 3;
        rows.colnames = cols;
        rows.labels = labels;
        rc = es_store_append(ctx, s, &rows);
        if (rc == ES_OK) rc = es_store_commit(ctx, s);
    }
    *nrows = n;
    es_store_close(s);
    es_mesh_free(mesh);
    es_synth_set_clear(ctx, &set);
    free(len);
    free(sc);
    free(labels);
    free(age);
    return rc;
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    es_store *s = NULL;
    char path[1024];
    int64_t n = 0;
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    cancel_ctx = ctx;
    snprintf(path, sizeof path, "%s/faces.h5", es_test_tmpdir("model_store"));
    ES_CHECK_OK(ctx, make_store(ctx, path, &n));
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) return 1;
    ES_CHECK(es_store_find_column(s, "subject") == 0 && es_store_find_column(s, "expression") == 1);
    const int64_t E = es_store_nedges(s);

    /* ---- edge-length space, subject as term and block ---- */
    es_study_model_opts o;
    es_study_model_opts_init(&o);
    o.formula = "~ subject + expression";
    o.block = "subject";
    o.permutations = 199;
    o.pairwise = "expression";
    o.edge_term = "expression";
    o.edge_permutations = 99;
    o.name = "m";
    o.command = "test";
    es_study_model_result *r = NULL;
    ES_CHECK_OK(ctx, es_study_model(ctx, s, &o, &r));
    double *y = malloc(sizeof(double) * (size_t)(E * n));
    ES_CHECK_OK(ctx, es_store_read_lengths(ctx, s, 0, n, (es_mat){y, E, n, E}));
    if (r) {
        const es_model *m = r->model;
        ES_CHECK(r->nrows == n && m->nterms == 2 && m->df[0] == n / 3 - 1 && m->df[1] == 2);
        /* SS of expression after subject, balanced: sum_l n_l ||m_l - m||^2 */
        double *gm = calloc((size_t)(4 * E), sizeof *gm), ss = 0;
        int expr_col = 1;
        for (int64_t i = 0; i < n; i++) {
            const char *x = es_store_label(s, i, expr_col);
            int l = !strcmp(x, "neutral") ? 0 : !strcmp(x, "happy") ? 1 : 2;
            for (int64_t e = 0; e < E; e++) {
                gm[e + l * E] += y[e + i * E] / (double)(n / 3);
                gm[e + 3 * E] += y[e + i * E] / (double)n;
            }
        }
        for (int l = 0; l < 3; l++)
            for (int64_t e = 0; e < E; e++)
                ss += (double)(n / 3) * pow(gm[e + l * E] - gm[e + 3 * E], 2);
        ES_CHECK_CLOSE(m->ss[1], ss, 1e-9, 0);
        ES_CHECK(!m->testable[0] && isnan(m->pval[0]) && m->pval[1] < 0.01);
        /* LS means of expression: the expression means (balanced) */
        ES_CHECK(r->pairwise && r->pairwise->nlevels == 3);
        if (r->pairwise && !strcmp(r->pairwise->levels[1], "happy"))
            for (int64_t e = 0; e < E; e += 7)
                ES_CHECK_CLOSE(r->pairwise->lsmeans[1 + e * 3], gm[e + E], 1e-9, 1e-15);
        ES_CHECK(r->edge_f && r->edge_q && r->cac == NULL);
        int64_t nsig = 0;
        for (int64_t e = 0; r->edge_q && e < E; e++) nsig += r->edge_q[e] < 0.05;
        ES_CHECK_MSG(nsig > E / 10, "%lld of %lld edges differ by expression", (long long)nsig,
                     (long long)E);
        free(gm);
    }
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    {
        char buf[64];
        double v;
        char **terms = NULL;
        int64_t nt = 0;
        es_mat cm = {0};
        ES_CHECK_OK(ctx, es_store_get_strings(ctx, s, "model/m/terms", &terms, &nt));
        ES_CHECK(nt == 2 && !strcmp(terms[1], "expression"));
        for (int64_t j = 0; j < nt; j++) es_free(ctx, terms[j]);
        es_free(ctx, terms);
        ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "model/m", "space", buf, sizeof buf));
        ES_CHECK(!strcmp(buf, "lengths"));
        ES_CHECK_OK(ctx, es_store_get_attr_double(ctx, s, "model/m", "permutations", &v));
        ES_CHECK(v == 199);
        ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, "model/m/coefficients", &cm));
        ES_CHECK(cm.rows == E && r && cm.cols == r->model->ncoef);
        es_free(ctx, cm.data);
        ES_CHECK(es_store_has(s, "model/m/edge_q") && es_store_has(s, "model/m/pairwise_p") &&
                 es_store_has(s, "model/m/f_perm"));
    }

    /* ---- a coefficient as a point, with its row weights ---- */
    {
        double *vec = NULL, *w = calloc((size_t)n, sizeof *w), *coef = malloc(sizeof(double) * (size_t)E);
        es_point_info info;
        ES_CHECK_OK(ctx, es_study_point(ctx, s,
                                        &(es_study_point_opts){
                                            .expr = "mean + 2*coef:m:expression=happy"},
                                        &vec, w, &info));
        ES_CHECK_OK(ctx, es_study_model_coef(ctx, s, "m", "expression=happy", coef, NULL));
        if (vec) {
            double worst = 0, wsum = 0;
            for (int64_t i = 0; i < n; i++) wsum += w[i];
            for (int64_t e = 0; e < E; e++) {
                double mean = 0, comb = 0;
                for (int64_t i = 0; i < n; i++) mean += y[e + i * E] / (double)n;
                for (int64_t i = 0; i < n; i++) comb += w[i] * y[e + i * E];
                worst = fmax(worst, fabs(vec[e] - (mean + 2 * coef[e])));
                worst = fmax(worst, fabs(comb - vec[e]));
            }
            ES_CHECK_MSG(worst < 1e-14, "point and weights off by %g", worst);
            ES_CHECK_CLOSE(wsum, 1, 1e-12, 0);
            ES_CHECK(info.ndirections == 1 && info.nshapes == 1);
        }
        es_free(ctx, vec);
        vec = NULL;
        ES_CHECK_FAILS(ctx, es_study_point(ctx, s,
                                           &(es_study_point_opts){
                                               .expr = "mean + coef:m:expression=sad"},
                                           &vec, NULL, NULL),
                       ES_ENOTFOUND, "point: coef:m:expression=sad: model 'm' has no coefficient "
                       "'expression=sad' (it has: intercept");
        ES_CHECK_FAILS(ctx, es_study_point(ctx, s, &(es_study_point_opts){.expr = "mean + coef:zz:age"},
                                           &vec, NULL, NULL), ES_ENOTFOUND, "no model named 'zz'");
        free(w);
        free(coef);
    }
    es_study_model_free(r);
    r = NULL;

    /* ---- allometry: log(size), numeric age, type II ---- */
    o.formula = "~ log(size) + age + expression";
    o.block = NULL;
    o.pairwise = NULL;
    o.edge_term = NULL;
    o.ss_type = ES_SS_TYPE_II;
    o.name = "allo";
    ES_CHECK_OK(ctx, es_study_model(ctx, s, &o, &r));
    if (r) {
        ES_CHECK(r->cac && r->cac_scores && r->model->df[0] == 1 && r->model->df[1] == 1);
        double nrm = 0;
        for (int64_t e = 0; e < E; e++) nrm += r->cac[e] * r->cac[e];
        ES_CHECK_CLOSE(nrm, 1, 1e-12, 0);
    }
    es_study_model_free(r);
    r = NULL;
    ES_CHECK(es_store_has(s, "model/allo/cac") && es_store_has(s, "model/allo/cac_scores"));

    /* ---- nested: a slope of age within each expression; --error names a
     * term by its variables in any order (R labels age %in% expression
     * "expression:age" here: expression comes first) ---- */
    {
        const char *errs[2] = {"expression=age:expression", "expression=expression:ages"};
        o.formula = "~ expression + age %in% expression";
        o.ss_type = ES_SS_TYPE_I;
        o.errors = errs;
        o.nerrors = 1;
        o.name = NULL;
        ES_CHECK_OK(ctx, es_study_model(ctx, s, &o, &r));
        if (r) {
            ES_CHECK(r->model->nterms == 2 && !strcmp(r->design->terms[1], "expression:age"));
            ES_CHECK(r->model->error[0] == 1 && r->model->error[1] == -1);
            ES_CHECK_CLOSE(r->model->f[0], r->model->ms[0] / r->model->ms[1], 1e-12, 0);
        }
        es_study_model_free(r);
        r = NULL;
        o.errors = errs + 1;
        ES_CHECK_FAILS(ctx, es_study_model(ctx, s, &o, &r), ES_ENOTFOUND,
                       "no term 'expression:ages' (its terms: expression, expression:age, "
                       "and Residual)");
        o.errors = NULL;
        o.nerrors = 0;
    }

    /* ---- Procrustes space ---- */
    es_study_gpa_opts go;
    es_study_gpa_opts_init(&go);
    go.name = "g";
    go.command = "test";
    ES_CHECK_OK(ctx, es_study_gpa(ctx, s, &go, NULL));
    o.formula = "~ expression";
    o.gpa = "g";
    o.where = "expression=happy,subject=s01";
    o.name = "pm";
    o.ss_type = ES_SS_TYPE_I;
    ES_CHECK_FAILS(ctx, es_study_model(ctx, s, &o, &r), ES_EINVAL, "1 rows match");
    o.where = NULL;
    ES_CHECK_OK(ctx, es_study_model(ctx, s, &o, &r));
    if (r) ES_CHECK(r->model->p == 3 * es_store_nverts(s) && r->nrows == n);
    es_study_model_free(r);
    r = NULL;
    {
        double *vec = NULL;
        ES_CHECK_FAILS(ctx, es_study_point(ctx, s,
                                           &(es_study_point_opts){
                                               .expr = "mean + coef:pm:expression=happy"},
                                           &vec, NULL, NULL),
                       ES_EINVAL, "model 'pm' is in procrustes space");
    }
    /* per-landmark tests in Procrustes space: a vertex's 3 coordinates together */
    o.edge_term = "expression";
    o.formula = "~ expression + subject";
    o.name = NULL;
    ES_CHECK_OK(ctx, es_study_model(ctx, s, &o, &r));
    if (r) {
        int64_t sig = 0;
        ES_CHECK(r->ntests == es_store_nverts(s));
        for (int64_t k = 0; k < r->ntests; k++) sig += r->edge_q[k] < 0.05;
        ES_CHECK_MSG(sig > 0, "no vertex moves with expression (%lld of %lld; f %g p %g q %g)", (long long)sig,
                     (long long)r->ntests, r->edge_f[0], r->edge_p[0], r->edge_q[0]);
    }
    es_study_model_free(r);
    r = NULL;
    o.edge_term = NULL;
    o.gpa = "nope";
    ES_CHECK_FAILS(ctx, es_study_model(ctx, s, &o, &r), ES_ENOTFOUND, "no GPA result 'nope'");
    o.gpa = NULL;
    o.formula = "~ mood";
    ES_CHECK_FAILS(ctx, es_study_model(ctx, s, &o, &r), ES_ENOTFOUND, "no label column 'mood'");
    ES_CHECK(r == NULL);

    /* ---- cancelled from the progress callback: stops, stores nothing ---- */
    {
        int reports = 0;
        size_t nbefore = 0, nafter = 0;
        char *before, *after;
        ES_CHECK_OK(ctx, es_store_commit(ctx, s));
        before = es_test_slurp(path, &nbefore);
        es_ctx_set_progress(ctx, cancel_after_two, &reports);
        o.formula = "~ subject + expression";
        o.name = "cancelled";
        o.permutations = 99999;
        o.edge_term = NULL;
        o.pairwise = NULL;
        ES_CHECK_FAILS(ctx, es_study_model(ctx, s, &o, &r), ES_ECANCELED, "; nothing stored");
        ES_CHECK(r == NULL && reports == 2 && es_ctx_cancelled(ctx));
        /* while the request stands, writes and commits refuse */
        ES_CHECK_OK(ctx, es_store_commit(ctx, s));   /* nothing pending: nothing to refuse */
        ES_CHECK_FAILS(ctx, es_store_result_begin(ctx, s, "mean", "x",
                                                  &(es_provenance){"t", NULL, -1, NULL}),
                       ES_ECANCELED, "nothing stored");
        es_ctx_set_progress(ctx, NULL, NULL);
        es_ctx_cancel_clear(ctx);
        ES_CHECK(!es_ctx_cancelled(ctx) && !es_store_has(s, "model/cancelled") &&
                 !es_store_pending(s));
        after = es_test_slurp(path, &nafter);
        ES_CHECK(before && after && nbefore == nafter && !memcmp(before, after, nbefore));
        free(before);
        free(after);
        /* a result written and rolled back is gone; the handle writes again */
        ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "mean", "x",
                                               &(es_provenance){"t", NULL, -1, NULL}));
        ES_CHECK(es_store_pending(s) && es_store_has(s, "mean/x"));
        ES_CHECK_OK(ctx, es_store_rollback(ctx, s));
        ES_CHECK(!es_store_pending(s) && !es_store_has(s, "mean/x") && es_store_nrows(s) == n &&
                 es_store_find_column(s, "age") == 2);
        ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "mean", "y",
                                               &(es_provenance){"t", NULL, -1, NULL}));
        ES_CHECK_OK(ctx, es_store_commit(ctx, s));
        ES_CHECK(es_store_has(s, "mean/y") && !es_store_has(s, "mean/x"));
    }
    free(y);
    es_store_close(s);
    es_ctx_free(ctx);
    ES_TEST_END();
}
