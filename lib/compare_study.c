/* lib/compare_study.c — the GPA-vs-edge-length comparison study as one call,
 * and its CSV and figure outputs.
 *
 * The study of the paper's Section 4 (Figs. 7-8): the same shapes measured
 * in scale-normalized edge-length space and in Procrustes space (Euclidean
 * distances of GPA-aligned configurations). It runs the statistics of
 * compare.c on both distance matrices and writes what a morphometrician
 * reads: the matrices, every pair with both distances and its group pair,
 * the disagreeing pairs, nearest neighbours, group-mean distances with
 * permutation p-values, and three figures (two heat maps, the scatter of
 * distance pairs coloured by group pair) through es_plot.
 */
#include "es_internal.h"
#include "edgespace/es_compare.h"
#include "edgespace/es_io.h"
#include "edgespace/es_plot.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

void es_compare_opts_init(es_compare_opts *opts)
{
    opts->permutations = 999;
    opts->top_pairs = 20;
    opts->normalize_lengths = 1;
}

void es_compare_result_free(es_compare_result *res)
{
    if (!res) return;
    es_ctx *ctx = res->ctx;
    es__free(ctx, res->d_len);
    es__free(ctx, res->nn_len);
    es__free(ctx, res->top_pairs);
    es__free(ctx, res->top_diff);
    es__free(ctx, res->mean_len);
    es__free(ctx, res);
}

es_status es_compare_study(es_ctx *ctx, es_mat lengths, es_mat aligned, const int64_t *group,
                           int64_t ngroups, const es_compare_opts *opts, es_compare_result **out)
{
    es_compare_opts o;
    es_status rc;
    int64_t n = lengths.cols;
    *out = NULL;
    if (opts) o = *opts; else es_compare_opts_init(&o);
    if (aligned.cols != n)
        ES_FAIL(ctx, ES_EMISMATCH, "compare: %lld edge-length vectors but %lld configurations",
                (long long)n, (long long)aligned.cols);
    if (n < 3) ES_FAIL(ctx, ES_EINVAL, "compare: needs at least 3 shapes, got %lld", (long long)n);
    if ((group == NULL) != (ngroups == 0))
        ES_FAIL(ctx, ES_EINVAL, "compare: group labels and group count must come together");
    es_compare_result *r = es__calloc(ctx, 1, sizeof *r);
    if (!r) return ES_ENOMEM;
    r->ctx = ctx;
    r->n = n;
    int64_t m = n * (n - 1) / 2;
    r->ntop = o.top_pairs < m ? (o.top_pairs > 0 ? o.top_pairs : 0) : m;
    r->d_len = es__alloc_array(ctx, 2 * n * n, sizeof *r->d_len);
    r->nn_len = es__alloc_array(ctx, 2 * n, sizeof *r->nn_len);
    r->top_pairs = es__alloc_array(ctx, 2 * (r->ntop > 0 ? r->ntop : 1), sizeof *r->top_pairs);
    r->top_diff = es__alloc_array(ctx, r->ntop > 0 ? r->ntop : 1, sizeof *r->top_diff);
    if (!r->d_len || !r->nn_len || !r->top_pairs || !r->top_diff) { rc = ES_ENOMEM; goto fail; }
    r->d_proc = r->d_len + n * n;
    r->nn_proc = r->nn_len + n;
    es__progress(ctx, "compare", 0, 4);
    if ((rc = es_compare_distances(ctx, lengths, o.normalize_lengths,
                                   (es_mat){r->d_len, n, n, n})) != ES_OK ||
        (rc = es_compare_distances(ctx, aligned, 0, (es_mat){r->d_proc, n, n, n})) != ES_OK)
        goto fail;
    es__progress(ctx, "compare", 1, 4);
    if ((rc = es_compare_mantel(ctx, n, r->d_len, r->d_proc, o.permutations, &r->mantel_rho,
                                &r->mantel_p)) != ES_OK ||
        (rc = es_compare_nn_agreement(ctx, n, r->d_len, r->d_proc, r->nn_len, r->nn_proc,
                                      &r->nn_agreement)) != ES_OK ||
        (rc = es_compare_disagreement(ctx, n, r->d_len, r->d_proc, r->ntop, r->top_pairs,
                                      r->top_diff)) != ES_OK)
        goto fail;
    es__progress(ctx, "compare", 2, 4);
    if (ngroups > 0) {
        int64_t gg = ngroups * ngroups;
        r->ngroups = ngroups;
        r->mean_len = es__alloc_array(ctx, 4 * gg, sizeof *r->mean_len);
        if (!r->mean_len) { rc = ES_ENOMEM; goto fail; }
        r->mean_proc = r->mean_len + gg;
        r->p_len = r->mean_proc + gg;
        r->p_proc = r->p_len + gg;
        if ((rc = es_compare_groups(ctx, n, r->d_len, group, ngroups, o.permutations,
                                    r->mean_len, r->p_len, &r->groups_len)) != ES_OK ||
            (rc = es_compare_groups(ctx, n, r->d_proc, group, ngroups, o.permutations,
                                    r->mean_proc, r->p_proc, &r->groups_proc)) != ES_OK)
            goto fail;
    }
    es__progress(ctx, "compare", 4, 4);
    *out = r;
    return ES_OK;
fail:
    es_compare_result_free(r);
    return rc;
}

/* ---- output ---------------------------------------------------------------- */

static es_status make_dir(es_ctx *ctx, const char *dir)
{
    char buf[4096];
    size_t n = strlen(dir);
    if (n == 0 || n >= sizeof buf) ES_FAIL(ctx, ES_EIO, "compare: bad output directory '%s'", dir);
    memcpy(buf, dir, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (buf[i] == '/' || buf[i] == 0) {
            char c = buf[i];
            buf[i] = 0;
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                ES_FAIL(ctx, ES_EIO, "compare: cannot create '%s': %s", buf, strerror(errno));
            buf[i] = c;
        }
    }
    return ES_OK;
}

typedef struct outfile { FILE *f; char path[4096]; } outfile;

static es_status out_open(es_ctx *ctx, outfile *o, const char *dir, const char *name)
{
    int len = snprintf(o->path, sizeof o->path, "%s/%s", dir, name);
    if (len < 0 || (size_t)len >= sizeof o->path)
        ES_FAIL(ctx, ES_EIO, "compare: path too long in '%s'", dir);
    o->f = fopen(o->path, "w");
    if (!o->f) ES_FAIL(ctx, ES_EIO, "compare: cannot write '%s': %s", o->path, strerror(errno));
    return ES_OK;
}

static es_status out_close(es_ctx *ctx, outfile *o)
{
    int bad = ferror(o->f);
    if (fclose(o->f) != 0 || bad)
        ES_FAIL(ctx, ES_EIO, "compare: error writing '%s'", o->path);
    return ES_OK;
}

typedef struct names {
    const char *const *s;
    char buf[32];
} names;

static const char *name_of(names *nm, int64_t i)
{
    if (nm->s) return nm->s[i];
    snprintf(nm->buf, sizeof nm->buf, "%lld", (long long)i + 1);
    return nm->buf;
}

typedef struct keyed { double v; int64_t t; } keyed;

static int cmp_keyed(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->v < y->v) return -1;
    if (x->v > y->v) return 1;
    return x->t < y->t ? -1 : x->t > y->t;
}

/* Rank (1 + number of smaller distances) of every pair of the upper
 * triangle, pair t = j(j-1)/2 + i. Falls back to 0 ranks without memory. */
static void upper_min_ranks(es_ctx *ctx, int64_t n, const double *d, int64_t *rank)
{
    int64_t m = n * (n - 1) / 2;
    keyed *k = es__alloc_array(ctx, m, sizeof *k);
    if (!k) {
        memset(rank, 0, (size_t)m * sizeof *rank);
        return;
    }
    for (int64_t j = 1, t = 0; j < n; j++)
        for (int64_t i = 0; i < j; i++, t++) k[t] = (keyed){d[i + j * n], t};
    qsort(k, (size_t)m, sizeof *k, cmp_keyed);
    for (int64_t q = 0; q < m; q++)
        rank[k[q].t] = q > 0 && k[q].v == k[q - 1].v ? rank[k[q - 1].t] : q + 1;
    es__free(ctx, k);
}

static es_status write_matrix(es_ctx *ctx, const char *dir, const char *file, int64_t n,
                              const double *d, const char *const *ids)
{
    outfile o;
    es_status rc;
    names nm = {ids, {0}};
    if ((rc = out_open(ctx, &o, dir, file)) != ES_OK) return rc;
    fputs("id", o.f);
    for (int64_t j = 0; j < n; j++) {
        fputc(',', o.f);
        es_csv_write_field(o.f, name_of(&nm, j));
    }
    fputc('\n', o.f);
    for (int64_t i = 0; i < n; i++) {
        es_csv_write_field(o.f, name_of(&nm, i));
        for (int64_t j = 0; j < n; j++) fprintf(o.f, ",%.17g", d[i + j * n]);
        fputc('\n', o.f);
    }
    return out_close(ctx, &o);
}

/* "a|b" with the names in order, for the scatter's legend. */
static char *pair_label(es_ctx *ctx, const char *a, const char *b)
{
    if (strcmp(a, b) > 0) { const char *t = a; a = b; b = t; }
    size_t la = strlen(a), lb = strlen(b);
    char *s = es__malloc(ctx, la + lb + 2);
    if (!s) return NULL;
    memcpy(s, a, la);
    s[la] = '|';
    memcpy(s + la + 1, b, lb + 1);
    return s;
}

static es_status write_figures(es_ctx *ctx, const es_compare_result *r, const char *const *ids,
                               const int64_t *group, const char *const *gnames, const char *dir)
{
    char path[4096];
    es_status rc;
    int64_t n = r->n, m = n * (n - 1) / 2;
    const char *files[2] = {"heatmap_lengths.svg", "heatmap_procrustes.svg"};
    const char *titles[2] = {"edge-length distances (scale-normalized)",
                             "Procrustes distances (GPA-aligned)"};
    double *mats[2] = {r->d_len, r->d_proc};
    for (int s = 0; s < 2; s++) {
        es_heatmap_spec h;
        es_heatmap_spec_init(&h);
        h.frame.title = titles[s];
        h.values = (es_mat){mats[s], n, n, n};
        h.row_labels = n <= 60 ? ids : NULL;
        h.col_labels = n <= 60 ? ids : NULL;
        h.colorbar_label = "distance";
        snprintf(path, sizeof path, "%s/%s", dir, files[s]);
        if ((rc = es_plot_heatmap(ctx, &h, path, NULL)) != ES_OK) return rc;
    }
    double *x = es__alloc_array(ctx, 2 * m, sizeof *x);
    char **lab = group ? es__calloc(ctx, (size_t)m, sizeof *lab) : NULL;
    if (!x || (group && !lab)) {
        es__free(ctx, x);
        es__free(ctx, lab);
        return ES_ENOMEM;
    }
    double *y = x + m;
    names g1 = {gnames, {0}}, g2 = {gnames, {0}};
    rc = ES_OK;
    for (int64_t j = 1, t = 0; j < n; j++)
        for (int64_t i = 0; i < j; i++, t++) {
            x[t] = r->d_len[i + j * n];
            y[t] = r->d_proc[i + j * n];
            if (group && rc == ES_OK) {
                char a[32], b[32];
                snprintf(a, sizeof a, "%s", name_of(&g1, group[i]));
                snprintf(b, sizeof b, "%s", name_of(&g2, group[j]));
                if (!(lab[t] = pair_label(ctx, gnames ? gnames[group[i]] : a,
                                          gnames ? gnames[group[j]] : b)))
                    rc = ES_ENOMEM;
            }
        }
    if (rc == ES_OK) {
        es_scatter_spec sc;
        es_scatter_spec_init(&sc);
        sc.frame.title = "pairs of shapes in both spaces";
        sc.frame.xlabel = "edge-length distance";
        sc.frame.ylabel = "Procrustes distance";
        sc.n = m;
        sc.x = x;
        sc.y = y;
        sc.labels = (const char *const *)lab;
        sc.legend_title = group ? "group pair" : NULL;
        sc.marker_radius = m > 2000 ? 2 : 4;
        snprintf(path, sizeof path, "%s/pairs_scatter.svg", dir);
        rc = es_plot_scatter(ctx, &sc, path, NULL);
    }
    if (lab)
        for (int64_t t = 0; t < m; t++) es__free(ctx, lab[t]);
    es__free(ctx, lab);
    es__free(ctx, x);
    return rc;
}

es_status es_compare_write(es_ctx *ctx, const es_compare_result *r, const char *const *ids,
                           const int64_t *group, const char *const *group_names, const char *dir,
                           int figures)
{
    es_status rc;
    outfile o;
    int64_t n = r->n;
    names a = {ids, {0}}, b = {ids, {0}}, ga = {group_names, {0}}, gb = {group_names, {0}};
    if ((rc = make_dir(ctx, dir)) != ES_OK) return rc;
    if ((rc = write_matrix(ctx, dir, "distances_lengths.csv", n, r->d_len, ids)) != ES_OK ||
        (rc = write_matrix(ctx, dir, "distances_procrustes.csv", n, r->d_proc, ids)) != ES_OK)
        return rc;

    int64_t m = n * (n - 1) / 2, *rank = es__alloc_array(ctx, 2 * m, sizeof *rank);
    if (!rank) return ES_ENOMEM;
    upper_min_ranks(ctx, n, r->d_len, rank);
    upper_min_ranks(ctx, n, r->d_proc, rank + m);
    if ((rc = out_open(ctx, &o, dir, "pairs.csv")) != ES_OK) { es__free(ctx, rank); return rc; }
    fputs("i,j,id_i,id_j,d_lengths,d_procrustes,rank_lengths,rank_procrustes", o.f);
    fputs(group ? ",group_pair\n" : "\n", o.f);
    for (int64_t j = 1; j < n; j++)
        for (int64_t i = 0; i < j; i++) {
            fprintf(o.f, "%lld,%lld,", (long long)i + 1, (long long)j + 1);
            es_csv_write_field(o.f, name_of(&a, i));
            fputc(',', o.f);
            es_csv_write_field(o.f, name_of(&b, j));
            int64_t t = j * (j - 1) / 2 + i;
            fprintf(o.f, ",%.17g,%.17g,%lld,%lld", r->d_len[i + j * n], r->d_proc[i + j * n],
                    (long long)rank[t], (long long)rank[m + t]);
            if (group) {
                fputc(',', o.f);
                const char *x = name_of(&ga, group[i]);
                char xa[256];
                snprintf(xa, sizeof xa, "%s", x);
                const char *y = name_of(&gb, group[j]);
                char *pl = pair_label(ctx, xa, y);
                if (!pl) { fclose(o.f); es__free(ctx, rank); return ES_ENOMEM; }
                es_csv_write_field(o.f, pl);
                es__free(ctx, pl);
            }
            fputc('\n', o.f);
        }
    es__free(ctx, rank);
    if ((rc = out_close(ctx, &o)) != ES_OK) return rc;

    if ((rc = out_open(ctx, &o, dir, "summary.csv")) != ES_OK) return rc;
    fprintf(o.f, "statistic,value\nn,%lld\nspearman_rho,%.17g\nmantel_p,%.17g\n"
            "nn_agreement,%.17g\n", (long long)n, r->mantel_rho, r->mantel_p, r->nn_agreement);
    if (r->ngroups > 0) {
        const es_group_stats *s[2] = {&r->groups_len, &r->groups_proc};
        const char *sp[2] = {"lengths", "procrustes"};
        for (int q = 0; q < 2; q++)
            fprintf(o.f, "groups_%s_F,%.17g\ngroups_%s_p,%.17g\ngroups_%s_R2,%.17g\n", sp[q],
                    s[q]->f, sp[q], s[q]->p, sp[q], s[q]->r2);
    }
    if ((rc = out_close(ctx, &o)) != ES_OK) return rc;

    if ((rc = out_open(ctx, &o, dir, "nearest.csv")) != ES_OK) return rc;
    fputs("id,nearest_lengths,nearest_procrustes,agree\n", o.f);
    for (int64_t i = 0; i < n; i++) {
        es_csv_write_field(o.f, name_of(&a, i));
        fputc(',', o.f);
        es_csv_write_field(o.f, name_of(&a, r->nn_len[i]));
        fputc(',', o.f);
        es_csv_write_field(o.f, name_of(&a, r->nn_proc[i]));
        fprintf(o.f, ",%d\n", r->nn_len[i] == r->nn_proc[i]);
    }
    if ((rc = out_close(ctx, &o)) != ES_OK) return rc;

    if ((rc = out_open(ctx, &o, dir, "disagreement.csv")) != ES_OK) return rc;
    fputs("id_i,id_j,d_lengths,d_procrustes,rank_difference\n", o.f);
    for (int64_t q = 0; q < r->ntop; q++) {
        int64_t i = r->top_pairs[2 * q], j = r->top_pairs[2 * q + 1];
        es_csv_write_field(o.f, name_of(&a, i));
        fputc(',', o.f);
        es_csv_write_field(o.f, name_of(&a, j));
        fprintf(o.f, ",%.17g,%.17g,%.17g\n", r->d_len[i + j * n], r->d_proc[i + j * n],
                r->top_diff[q]);
    }
    if ((rc = out_close(ctx, &o)) != ES_OK) return rc;

    if (r->ngroups > 0) {
        int64_t g = r->ngroups;
        if ((rc = out_open(ctx, &o, dir, "group_means.csv")) != ES_OK) return rc;
        fputs("space,group_a,group_b,distance,p\n", o.f);
        for (int q = 0; q < 2; q++)
            for (int64_t c = 1; c < g; c++)
                for (int64_t x = 0; x < c; x++) {
                    const double *md = q ? r->mean_proc : r->mean_len;
                    const double *pv = q ? r->p_proc : r->p_len;
                    fputs(q ? "procrustes," : "lengths,", o.f);
                    es_csv_write_field(o.f, name_of(&ga, x));
                    fputc(',', o.f);
                    es_csv_write_field(o.f, name_of(&gb, c));
                    fprintf(o.f, ",%.17g,%.17g\n", md[x + c * g], pv[x + c * g]);
                }
        if ((rc = out_close(ctx, &o)) != ES_OK) return rc;
    }
    if (figures) return write_figures(ctx, r, ids, group, group_names, dir);
    return ES_OK;
}
