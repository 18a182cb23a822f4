/* lib/study/model_tables.c — a model's tables as CSV (17 significant
 * digits), laid out as RRPP's anova and summary(pairwise) tables are: the
 * analysis of variance with effect sizes, error terms and the comparison
 * with a null model, and the pairwise comparisons with their confidence
 * limits. One writer for each, fed from a fit in memory (`model -o`) or
 * from the store (`export --result model/NAME`), so the two agree; and the
 * same as text for a terminal or a notebook (es_study_model_summary). */
#include "study/study_pkg.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void es__model_null_label(const es_design *d, char *buf, size_t len)
{
    size_t at = (size_t)snprintf(buf, len, "~ %s", d->nterms ? "" : "1");
    for (int64_t j = 0; j < d->nterms && at < len; j++)
        at += (size_t)snprintf(buf + at, len - at, "%s%s", j ? " + " : "", d->terms[j]);
}

/* The rows of an analysis-of-variance table. */
typedef struct anova_rows {
    int64_t nterms;
    char *const *terms, *const *error;   /* error: NULL or the error term's label */
    const int64_t *df;
    const double *ss, *ms, *r2, *f, *z, *p;
    double df_resid, rss, tss, n;
    const char *null_label;   /* with a null model: "~ a + b" */
    double null_row[7];       /* df, ss, ms, r2, f, z, p */
} anova_rows;

static es_status write_anova(es_ctx *ctx, const char *path, const anova_rows *a)
{
    es__table_out t;
    es_status rc = es__table_begin(ctx, path, &t);
    if (rc != ES_OK) return rc;
    fputs("term,df,ss,ms,r2,f,z,p,error\n", t.f);
    for (int64_t j = 0; j < a->nterms; j++) {
        es_csv_write_field(t.f, a->terms[j]);
        fprintf(t.f, ",%lld", (long long)a->df[j]);
        const double *v[6] = {a->ss, a->ms, a->r2, a->f, a->z, a->p};
        for (int k = 0; k < 6; k++) es__table_number(t.f, v[k] ? v[k][j] : NAN);
        fputc(',', t.f);
        es_csv_write_field(t.f, a->error && a->error[j] ? a->error[j] : "Residual");
        fputc('\n', t.f);
    }
    fprintf(t.f, "Residual,%.0f", a->df_resid);
    es__table_number(t.f, a->rss);
    es__table_number(t.f, a->rss / a->df_resid);
    es__table_number(t.f, a->rss / a->tss);
    fputs(",,,,\n", t.f);
    fprintf(t.f, "Total,%.0f", a->n - 1);
    es__table_number(t.f, a->tss);
    fputs(",,1,,,,\n", t.f);
    if (a->null_label) {
        char label[700];
        snprintf(label, sizeof label, "null model: %s", a->null_label);
        es_csv_write_field(t.f, label);
        fprintf(t.f, ",%.0f", a->null_row[0]);
        for (int k = 1; k < 7; k++) es__table_number(t.f, a->null_row[k]);
        fputs(",Residual\n", t.f);
    }
    return es__table_end(ctx, &t, ES_OK);
}

es_status es_study_write_model_table(es_ctx *ctx, const es_study_model_result *r,
                                     const char *path)
{
    if (!r || !r->model) ES_FAIL(ctx, ES_EINVAL, "model: no result to write");
    const es_model *m = r->model;
    const es_design *d = r->design;
    char **err = es__calloc(ctx, (size_t)(m->nterms > 0 ? m->nterms : 1), sizeof *err);
    char null_label[600] = "";
    if (!err) return ES_ENOMEM;
    for (int64_t j = 0; j < m->nterms; j++)
        if (m->error[j] >= 0) err[j] = d->terms[m->error[j]];
    anova_rows a = {m->nterms, d->terms, err, m->df, m->ss, m->ms, m->r2, m->f, m->z, m->pval,
                    (double)m->df_resid, m->rss, m->tss, (double)m->n, NULL, {0}};
    if (r->comparison) {
        const es_model_comparison *c = r->comparison;
        es__model_null_label(r->null_design, null_label, sizeof null_label);
        a.null_label = null_label;
        const double row[7] = {(double)c->df, c->ss, c->ms, c->r2, c->f, c->z, c->pval};
        memcpy(a.null_row, row, sizeof row);
    }
    es_status rc = write_anova(ctx, path, &a);
    es__free(ctx, err);
    return rc;
}

es_status es__t_model_anova(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                            const char *path)
{
    static const char *const ds[6] = {"ss", "ms", "r2", "f", "z", "p"};
    char **terms = NULL, **err = NULL, grp[300], label[600] = "";
    int64_t nt = 0, *df = NULL, ndf = 0, nv = 0, ne = 0;
    double *v[6] = {NULL}, dfr = 0, rss = 0, tss = 0, n = 0;
    snprintf(grp, sizeof grp, "%s/%s", kind, name);
    es_status rc = es__result_strings(ctx, s, kind, name, "terms", &terms, &nt);
    if (rc == ES_OK) rc = es__result_ints(ctx, s, kind, name, "df", &df, &ndf);
    for (int k = 0; k < 6 && rc == ES_OK; k++) {
        rc = es__result_vector(ctx, s, kind, name, ds[k], &v[k], &nv);
        if (rc == ES_ENOTFOUND && k == 4) {   /* z: stores written before effect sizes */
            rc = ES_OK;
            continue;
        }
        if (rc == ES_OK && (nv != nt || ndf != nt))
            rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/%s has %lld values for %lld terms",
                          name, ds[k], (long long)nv, (long long)nt);
    }
    if (rc == ES_OK && (rc = es__result_strings(ctx, s, kind, name, "error_terms", &err, &ne)) ==
                           ES_ENOTFOUND)
        rc = ES_OK;
    if (rc == ES_OK && err && ne != nt)
        rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/error_terms is inconsistent", name);
    if (rc == ES_OK && ((rc = es_store_get_attr_double(ctx, s, grp, "df_resid", &dfr)) != ES_OK ||
                        (rc = es_store_get_attr_double(ctx, s, grp, "rss", &rss)) != ES_OK ||
                        (rc = es_store_get_attr_double(ctx, s, grp, "tss", &tss)) != ES_OK ||
                        (rc = es_store_get_attr_double(ctx, s, grp, "n", &n)) != ES_OK))
        goto done;
    anova_rows a = {nt, terms, err, df, v[0], v[1], v[2], v[3], v[4], v[5], dfr, rss, tss, n,
                    NULL, {0}};
    if (rc == ES_OK && es_store_get_attr(ctx, s, grp, "null_model", label, sizeof label) == ES_OK &&
        *label) {
        static const char *const keys[7] = {"null_df", "null_ss", "null_ms", "null_r2",
                                            "null_f", "null_z", "null_p"};
        a.null_label = label;
        for (int k = 0; k < 7 && rc == ES_OK; k++)
            rc = es_store_get_attr_double(ctx, s, grp, keys[k], &a.null_row[k]);
    }
    if (rc == ES_OK) rc = write_anova(ctx, path, &a);
done:
    for (int64_t j = 0; j < nt; j++) es_free(ctx, terms[j]);
    for (int64_t j = 0; err && j < ne; j++) es_free(ctx, err[j]);
    es_free(ctx, terms);
    es_free(ctx, err);
    es_free(ctx, df);
    for (int k = 0; k < 6; k++) es_free(ctx, v[k]);
    return rc;
}

/* The pairwise statistics, L x L each (NULL: not there). */
typedef struct pair_rows {
    int64_t L;
    char *const *levels;
    int slopes;
    const double *m[13];   /* d, ucl, z, p, r, angle, angle_ucl, angle_z, angle_p, dlength,
                              dlength_ucl, dlength_z, dlength_p */
} pair_rows;

/* The stored names of pair_rows.m, and the CSV columns. */
static const char *const pair_ds[13] = {
    "pairwise_distances", "pairwise_ucl", "pairwise_z", "pairwise_p", "pairwise_vcor",
    "pairwise_angle", "pairwise_angle_ucl", "pairwise_angle_z", "pairwise_angle_p",
    "pairwise_dlength", "pairwise_dlength_ucl", "pairwise_dlength_z", "pairwise_dlength_p"};
static const char *const pair_cols[13] = {"d", "ucl", "z", "p", "r", "angle", "angle_ucl",
                                          "angle_z", "angle_p", "dlength", "dlength_ucl",
                                          "dlength_z", "dlength_p"};

static es_status write_pairs(es_ctx *ctx, const char *path, const pair_rows *pr)
{
    es__table_out t;
    es_status rc = es__table_begin(ctx, path, &t);
    if (rc != ES_OK) return rc;
    const int ncol = pr->slopes ? 13 : 4;
    const double deg = 180.0 / 3.14159265358979323846;
    fputs("level_a,level_b", t.f);
    for (int k = 0; k < ncol; k++) fprintf(t.f, ",%s", pair_cols[k]);
    fputc('\n', t.f);
    for (int64_t a = 0; a < pr->L; a++)
        for (int64_t b = a + 1; b < pr->L; b++) {
            es_csv_write_field(t.f, pr->levels[a]);
            fputc(',', t.f);
            es_csv_write_field(t.f, pr->levels[b]);
            for (int k = 0; k < ncol; k++) {
                /* angles in degrees, as summary(pairwise, angle.type = "deg") */
                const double x = pr->m[k] ? pr->m[k][a + b * pr->L] : NAN;
                es__table_number(t.f, k == 5 || k == 6 ? x * deg : x);
            }
            fputc('\n', t.f);
        }
    return es__table_end(ctx, &t, ES_OK);
}

es_status es_study_write_pairwise_table(es_ctx *ctx, const es_study_model_result *r,
                                        const char *path)
{
    if (!r || !r->pairwise) ES_FAIL(ctx, ES_EINVAL, "model: no pairwise comparisons to write");
    const es_model_pairwise *pw = r->pairwise;
    pair_rows pr = {pw->nlevels, pw->levels, pw->slopes,
                    {pw->dist, pw->ucl, pw->z, pw->pval, pw->vcor, pw->angle, pw->angle_ucl,
                     pw->angle_z, pw->angle_p, pw->dlength, pw->dlength_ucl, pw->dlength_z,
                     pw->dlength_p}};
    return write_pairs(ctx, path, &pr);
}

es_status es__t_model_pairwise(es_ctx *ctx, es_store *s, const char *kind, const char *name,
                               const char *path)
{
    char **lv = NULL;
    int64_t L = 0;
    es_mat mat[13];
    memset(mat, 0, sizeof mat);
    pair_rows pr = {0, NULL, 0, {NULL}};
    es_status rc = es__result_strings(ctx, s, kind, name, "pairwise_levels", &lv, &L);
    if (rc == ES_ENOTFOUND)
        rc = es__fail(ctx, ES_ENOTFOUND, "export: model/%s has no pairwise comparison (fit it "
                      "with --pairwise FACTOR)", name);
    for (int k = 0; k < 13 && rc == ES_OK; k++) {
        char p[700];
        if ((rc = es__result_path(ctx, p, sizeof p, kind, name, pair_ds[k])) != ES_OK) break;
        if (!es_store_has(s, p)) continue;   /* slopes only; z, ucl: older stores */
        if ((rc = es_store_get_matrix(ctx, s, p, &mat[k])) != ES_OK) break;
        if (mat[k].rows != L || mat[k].cols != L)
            rc = es__fail(ctx, ES_EFORMAT, "export: model/%s/%s is not %lld x %lld", name,
                          pair_ds[k], (long long)L, (long long)L);
        pr.m[k] = mat[k].data;
    }
    if (rc == ES_OK) {
        pr.L = L;
        pr.levels = lv;
        pr.slopes = pr.m[5] != NULL;
        rc = write_pairs(ctx, path, &pr);
    }
    for (int64_t i = 0; i < L; i++) es_free(ctx, lv[i]);
    es_free(ctx, lv);
    for (int k = 0; k < 13; k++) es_free(ctx, mat[k].data);
    return rc;
}

/* ---- the summary a terminal shows ---------------------------------------- */

typedef struct text {
    es_ctx *ctx;
    char *s;
    size_t len, cap;
    es_status rc;
} text;

static void add(text *t, const char *fmt, ...) ES__PRINTF(2, 3);
static void add(text *t, const char *fmt, ...)
{
    va_list ap;
    if (t->rc != ES_OK) return;
    va_start(ap, fmt);
    int n = vsnprintf(t->s ? t->s + t->len : NULL, t->s ? t->cap - t->len : 0, fmt, ap);
    va_end(ap);
    if (n < 0) return;
    if (!t->s || t->len + (size_t)n + 1 > t->cap) {
        size_t cap = 2 * (t->cap + (size_t)n + 64);
        char *s = es__realloc(t->ctx, t->s, cap);
        if (!s) {
            t->rc = ES_ENOMEM;
            return;
        }
        t->s = s;
        t->cap = cap;
        va_start(ap, fmt);
        vsnprintf(t->s + t->len, t->cap - t->len, fmt, ap);
        va_end(ap);
    }
    t->len += (size_t)n;
}

static void summary_pairwise(text *t, const es_study_model_result *r)
{
    const es_model_pairwise *pw = r->pairwise;
    const int64_t L = pw->nlevels;
    const double deg = 180.0 / 3.14159265358979323846;
    if (pw->slopes) {
        add(t, "pairwise slopes: distance (UCL %.0f%%, Z, p); angle in degrees (UCL, Z, p)\n",
            100 * pw->confidence);
    } else {
        add(t, "pairwise distances of LS means (UCL %.0f%%, Z, p) at", 100 * pw->confidence);
        int any = 0;
        for (int64_t v = 0; v < pw->nvars; v++)
            if (!isnan(pw->at[v])) add(t, "%s %s = %.6g", any++ ? "," : "", r->design->vars[v],
                                       pw->at[v]);
        add(t, "%s\n", any ? "" : " (no covariates)");
    }
    for (int64_t a = 0; a < L; a++)
        for (int64_t b = a + 1; b < L; b++) {
            const int64_t x = a + b * L;
            add(t, "  %-14s %-14s %11.5g (%.5g, %6.3f, %.4g)", pw->levels[a], pw->levels[b],
                pw->dist[x], pw->ucl[x], pw->z[x], pw->pval[x]);
            if (pw->slopes)
                add(t, "  %7.2f (%.2f, %6.3f, %.4g)", pw->angle[x] * deg, pw->angle_ucl[x] * deg,
                    pw->angle_z[x], pw->angle_p[x]);
            add(t, "\n");
        }
}

es_status es_study_model_summary(es_ctx *ctx, const es_study_model_result *r, char **out)
{
    *out = NULL;
    if (!r || !r->model) ES_FAIL(ctx, ES_EINVAL, "model: no result to summarize");
    const es_model *m = r->model;
    const es_design *d = r->design;
    text t = {ctx, NULL, 0, 0, ES_OK};
    add(&t, "%-24s %5s %14s %14s %8s %10s %7s %8s\n", "term", "df", "SS", "MS", "R2", "F", "Z",
        "p");
    for (int64_t j = 0; j < m->nterms; j++) {
        add(&t, "%-24s %5lld %14.6g %14.6g %8.4f %10.4g ", d->terms[j], (long long)m->df[j],
            m->ss[j], m->ms[j], m->r2[j], m->f[j]);
        if (isnan(m->z[j])) add(&t, "%7s ", "-");
        else add(&t, "%7.3f ", m->z[j]);
        /* untestable: constant within the blocks (the block itself) */
        if (isnan(m->pval[j])) add(&t, "%8s", m->testable[j] ? "-" : "(block)");
        else add(&t, "%8.4g", m->pval[j]);
        if (m->error[j] >= 0) add(&t, "  (over %s)", d->terms[m->error[j]]);
        add(&t, "\n");
    }
    add(&t, "%-24s %5lld %14.6g %14.6g %8.4f\n", "Residual", (long long)m->df_resid, m->rss,
        m->rss / (double)m->df_resid, m->rss / m->tss);
    add(&t, "%-24s %5lld %14.6g\n", "Total", (long long)(m->n - 1), m->tss);
    for (int64_t k = 0; k < d->ndropped; k++)
        add(&t, "left out: %s %s\n", d->dropped[k], d->dropped_why[k]);
    if (r->comparison) {
        const es_model_comparison *c = r->comparison;
        char label[600];
        es__model_null_label(r->null_design, label, sizeof label);
        add(&t, "against the null model %s: df %lld, SS %.6g, R2 %.4f, F %.4g, Z %.3f, p %.4g\n",
            label, (long long)c->df, c->ss, c->r2, c->f, c->z, c->pval);
    }
    if (r->pairwise) summary_pairwise(&t, r);
    if (r->edge_q) {
        int64_t n = 0, tested = 0;
        for (int64_t e = 0; e < r->ntests; e++) n += r->edge_q[e] < 0.05, tested += !isnan(r->edge_q[e]);
        const char *what = r->ntests == m->p ? "edges" : "landmarks";
        if (tested) add(&t, "%s with FDR q < 0.05: %lld of %lld\n", what, (long long)n,
                        (long long)r->ntests);
        else add(&t, "%s: F of each kept; no p or q values without permutations\n", what);
    }
    if (t.rc != ES_OK) {
        es__free(ctx, t.s);
        return t.rc;
    }
    *out = t.s;
    return ES_OK;
}
