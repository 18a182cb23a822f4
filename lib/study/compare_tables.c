/* lib/study/compare_tables.c — the comparison study's tables: CSV files a
 * morphometrician reads (the two distance matrices, every pair with both
 * distances and ranks, the summary, nearest neighbours, the most
 * disagreeing pairs, group-mean distances with p-values). Each file is
 * replaced only once written whole (es__replace_begin).
 */
#include "core/core_private.h"
#include "core/files.h"
#include "edgespace/es_study.h"

#include <stdio.h>
#include <stdlib.h>

/* Each output file goes through es__replace_begin/end: a failure part way
 * leaves the file that was there before. */
typedef struct outfile {
    es__file_replace w;
    FILE *f;
    char path[4096];
} outfile;

static es_status out_open(es_ctx *ctx, outfile *o, const char *dir, const char *name)
{
    int len = snprintf(o->path, sizeof o->path, "%s/%s", dir, name);
    es_status rc;
    if (len < 0 || (size_t)len >= sizeof o->path)
        ES_FAIL(ctx, ES_EIO, "compare: path too long in '%s'", dir);
    if ((rc = es__replace_begin(ctx, o->path, &o->w)) != ES_OK)
        return es__fail(ctx, rc, "compare: %s", es_ctx_errmsg(ctx));
    o->f = o->w.f;
    return ES_OK;
}

static es_status out_close(es_ctx *ctx, outfile *o)
{
    return es__replace_end(ctx, &o->w, ES_OK);
}

/* Give up on a file being written (the old one stays). */
static void out_abort(es_ctx *ctx, outfile *o)
{
    es__replace_end(ctx, &o->w, ES_EIO);
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

es_status es_study_compare_write(es_ctx *ctx, const es_compare_result *r, const char *const *ids,
                           const int64_t *group, const char *const *group_names, const char *dir)
{
    es_status rc;
    outfile o;
    int64_t n = r->n;
    names a = {ids, {0}}, b = {ids, {0}}, ga = {group_names, {0}}, gb = {group_names, {0}};
    if ((rc = es__mkdir_p(ctx, dir)) != ES_OK) return es__fail(ctx, rc, "compare: %s", es_ctx_errmsg(ctx));
    if ((rc = write_matrix(ctx, dir, "distances_lengths.csv", n, r->d_len, ids)) != ES_OK ||
        (rc = write_matrix(ctx, dir, "distances_procrustes.csv", n, r->d_proc, ids)) != ES_OK ||
        (r->d_rho && (rc = write_matrix(ctx, dir, "distances_rho.csv", n, r->d_rho, ids)) != ES_OK))
        return rc;

    int64_t m = n * (n - 1) / 2, *rank = es__alloc_array(ctx, 2 * m, sizeof *rank);
    if (!rank) return ES_ENOMEM;
    upper_min_ranks(ctx, n, r->d_len, rank);
    upper_min_ranks(ctx, n, r->d_proc, rank + m);
    if ((rc = out_open(ctx, &o, dir, "pairs.csv")) != ES_OK) { es__free(ctx, rank); return rc; }
    fputs("i,j,id_i,id_j,d_lengths,d_procrustes,rank_lengths,rank_procrustes", o.f);
    /* rho last: the columns before it keep their places */
    fputs(group ? ",group_pair" : "", o.f);
    fputs(r->d_rho ? ",rho\n" : "\n", o.f);
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
                char *pl = es_compare_pair_label(ctx, xa, y);
                if (!pl) { out_abort(ctx, &o); es__free(ctx, rank); return ES_ENOMEM; }
                es_csv_write_field(o.f, pl);
                es__free(ctx, pl);
            }
            if (r->d_rho) fprintf(o.f, ",%.17g", r->d_rho[i + j * n]);
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
    return ES_OK;
}
