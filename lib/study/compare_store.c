/* lib/study/compare_store.c — the comparison study on a store: a GPA result's
 * aligned configurations against the same rows' normalized edge lengths,
 * grouped by a label column; results to /analysis/compare/<name> and to CSV
 * files (compare_tables.c). */
#include "core/core_private.h"
#include "core/strmap.h"
#include "edgespace/es_study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Group index per row from a label column, in order of first appearance;
 * names copied (ngroups of them, es__free each). */
static es_status groups_of(es_ctx *ctx, es_store *s, const int64_t *rows, int64_t n,
                           const char *by, int64_t *group, char ***names, int64_t *ng)
{
    int64_t col = es_store_find_column(s, by), g = 0, prev;
    es__strmap map;
    es_status rc;
    char **nm;
    *names = NULL;
    *ng = 0;
    if (col < 0) {
        char hint[400];
        es_store_column_hint(s, by, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "compare: no label column '%s'%s", by, hint);
    }
    if (!(nm = es__calloc(ctx, (size_t)(n > 0 ? n : 1), sizeof *nm))) return ES_ENOMEM;
    if ((rc = es__strmap_init(ctx, &map, n)) != ES_OK) {
        es__free(ctx, nm);
        return rc;
    }
    for (int64_t j = 0; j < n && rc == ES_OK; j++) {
        const char *v = es_store_label(s, rows[j], col);
        if ((rc = es__strmap_put(ctx, &map, v, g, &prev)) != ES_OK) break;
        if (prev >= 0) {
            group[j] = prev;
        } else if (!(nm[g] = es__strdup(ctx, v))) {
            rc = ES_ENOMEM;
        } else {
            group[j] = g++;
        }
    }
    es__strmap_clear(ctx, &map);
    if (rc != ES_OK) {
        for (int64_t q = 0; q < g; q++) es__free(ctx, nm[q]);
        es__free(ctx, nm);
        return rc;
    }
    *names = nm;
    *ng = g;
    return ES_OK;
}

/* rho of every pair (es_compare_rho) in the GPA's dimension, reflections
 * counted as the GPA counted them (its params, "allow_reflection=1"). */
static es_status add_rho(es_ctx *ctx, es_store *store, const char *gpa_name, es_mat al,
                         es_compare_result *r)
{
    char path[512], dim[32] = "", params[512] = "";
    snprintf(path, sizeof path, "gpa/%s", gpa_name);
    es_status rc = es_store_get_attr(ctx, store, path, "dim", dim, sizeof dim);
    if (rc != ES_OK) return rc;
    /* a GPA stored before its params said so counts reflections apart */
    if (es_store_get_attr(ctx, store, path, "params", params, sizeof params) != ES_OK)
        params[0] = '\0';
    if (!(r->d_rho = es__alloc_array(ctx, r->n * r->n, sizeof *r->d_rho))) return ES_ENOMEM;
    return es_compare_rho(ctx, al, atoi(dim), strstr(params, "allow_reflection=1") != NULL,
                          (es_mat){r->d_rho, r->n, r->n, r->n});
}

void es_study_compare_opts_init(es_study_compare_opts *o)
{
    memset(o, 0, sizeof *o);
    es_compare_opts_init(&o->compare);
}

es_status es_study_compare(es_ctx *ctx, es_store *store, const es_study_compare_opts *opts,
                           es_compare_result **res)
{
    if (res) *res = NULL;
    if (!opts) ES_FAIL(ctx, ES_EINVAL, "compare: bad GPA result name ''");
    const char *gpa_name = opts->gpa_name, *by = opts->by, *name = opts->name,
               *out_dir = opts->out_dir, *command = opts->command;
    char path[1024];
    es_status rc;
    es_mat al = {0}, len = {0};
    int64_t *rows = NULL, n = 0, *group = NULL, ng = 0, e = es_store_nedges(store);
    char **gnames = NULL, **ids = NULL;
    es_compare_result *r = NULL;
    if (!gpa_name || !*gpa_name || strchr(gpa_name, '/'))
        ES_FAIL(ctx, ES_EINVAL, "compare: bad GPA result name '%s'", gpa_name ? gpa_name : "");
    if (e < 1) ES_FAIL(ctx, ES_EINVAL, "compare: store '%s' has no edges: it holds landmarks "
                       "only; give --edges or --triangles at ingest", es_store_path(store));
    /* a taken result name is refused before the permutations run */
    if (name && (rc = es_store_result_check(ctx, store, "compare", name)) != ES_OK) return rc;
    snprintf(path, sizeof path, "gpa/%s", gpa_name);
    if (!es_store_has(store, path)) {
        char hint[400];
        es_store_result_hint(ctx, store, "gpa", gpa_name, hint, sizeof hint);
        ES_FAIL(ctx, ES_ENOTFOUND, "compare: no GPA result '%s' in the store%s (run 'edgespace "
                "gpa --name %s' first)", gpa_name, hint, gpa_name);
    }
    snprintf(path, sizeof path, "gpa/%s/input_rows", gpa_name);
    if ((rc = es_store_get_ints(ctx, store, path, &rows, &n)) != ES_OK) return rc;
    snprintf(path, sizeof path, "gpa/%s/aligned", gpa_name);
    if ((rc = es_store_get_matrix(ctx, store, path, &al)) != ES_OK) goto done;
    if (al.cols != n) {
        rc = es__fail(ctx, ES_EFORMAT, "compare: GPA result '%s' has %lld configurations for "
                      "%lld rows", gpa_name, (long long)al.cols, (long long)n);
        goto done;
    }
    for (int64_t j = 0; j < n; j++)
        if (rows[j] < 0 || rows[j] >= es_store_nrows(store)) {
            rc = es__fail(ctx, ES_EFORMAT, "compare: GPA result '%s' names row %lld, the store "
                          "has %lld", gpa_name, (long long)rows[j], (long long)es_store_nrows(store));
            goto done;
        }
    len.data = es__alloc_array(ctx, e * n, sizeof *len.data);
    group = es__alloc_array(ctx, n, sizeof *group);
    ids = es__calloc(ctx, (size_t)(n > 0 ? n : 1), sizeof *ids);
    if (!len.data || !group || !ids) { rc = ES_ENOMEM; goto done; }
    len.rows = e; len.cols = n; len.ld = e;
    if ((rc = es_store_read_lengths_rows(ctx, store, rows, n, len)) != ES_OK) goto done;
    for (int64_t j = 0; j < n; j++)
        if (!(ids[j] = es__strdup(ctx, es_store_row_id(store, rows[j])))) {
            rc = ES_ENOMEM;
            goto done;
        }
    if (by && *by) {
        if ((rc = groups_of(ctx, store, rows, n, by, group, &gnames, &ng)) != ES_OK) goto done;
        if (ng < 2) {
            es__warn(ctx, "compare: column '%s' has one value on these rows; no group tests", by);
            for (int64_t g = 0; g < ng; g++) es__free(ctx, gnames[g]);
            es__free(ctx, gnames);
            gnames = NULL;
            ng = 0;
        }
    }
    if ((rc = es_compare_study(ctx, len, al, ng ? group : NULL, ng, &opts->compare, &r)) != ES_OK) goto done;
    if ((rc = add_rho(ctx, store, gpa_name, al, r)) != ES_OK) goto done;
    if (out_dir && (rc = es_study_compare_write(ctx, r, (const char *const *)ids,
                                                ng ? group : NULL,
                                                (const char *const *)gnames, out_dir)) != ES_OK)
        goto done;
    if (name) {
        char params[512], grp[512];
        snprintf(params, sizeof params, "gpa=%s; by=%s; permutations=%lld", gpa_name,
                 by ? by : "", (long long)opts->compare.permutations);
        es_provenance prov = {command ? command : "es_study_compare", rows, n, params};
        if ((rc = es_store_result_begin(ctx, store, "compare", name, &prov)) != ES_OK) goto done;
        snprintf(grp, sizeof grp, "compare/%s", name);
#define PUT(call) do { if ((rc = (call)) != ES_OK) goto done; } while (0)
#define P(ds) (snprintf(path, sizeof path, "%s/%s", grp, ds), path)
        PUT(es_store_put_matrix(ctx, store, P("d_lengths"), (es_mat){r->d_len, n, n, n}));
        PUT(es_store_put_matrix(ctx, store, P("d_procrustes"), (es_mat){r->d_proc, n, n, n}));
        PUT(es_store_put_matrix(ctx, store, P("d_rho"), (es_mat){r->d_rho, n, n, n}));
        if (ng) {
            PUT(es_store_put_matrix(ctx, store, P("group_means_lengths"), (es_mat){r->mean_len, ng, ng, ng}));
            PUT(es_store_put_matrix(ctx, store, P("group_means_procrustes"), (es_mat){r->mean_proc, ng, ng, ng}));
            PUT(es_store_put_matrix(ctx, store, P("p_lengths"), (es_mat){r->p_len, ng, ng, ng}));
            PUT(es_store_put_matrix(ctx, store, P("p_procrustes"), (es_mat){r->p_proc, ng, ng, ng}));
            PUT(es_store_put_strings(ctx, store, P("group_names"), (const char *const *)gnames, ng));
        }
        PUT(es_store_put_attr_double(ctx, store, grp, "spearman_rho", r->mantel_rho));
        PUT(es_store_put_attr_double(ctx, store, grp, "mantel_p", r->mantel_p));
        PUT(es_store_put_attr_double(ctx, store, grp, "nn_agreement", r->nn_agreement));
        PUT(es_store_put_attr(ctx, store, grp, "gpa", gpa_name));
        PUT(es_store_put_attr(ctx, store, grp, "by", by ? by : ""));
#undef PUT
#undef P
    }
done:
    if (r) {   /* the result owns the labels from here */
        r->ids = ids;
        r->group = ng ? group : NULL;
        r->group_names = gnames;
        ids = gnames = NULL;
        if (ng) group = NULL;
    }
    if (rc == ES_OK && res) {
        *res = r;
        r = NULL;
    }
    es_compare_result_free(r);
    for (int64_t j = 0; ids && j < n; j++) es__free(ctx, ids[j]);
    for (int64_t g = 0; gnames && g < ng; g++) es__free(ctx, gnames[g]);
    es__free(ctx, al.data);
    es__free(ctx, len.data);
    es__free(ctx, rows);
    es__free(ctx, group);
    es__free(ctx, gnames);
    es__free(ctx, ids);
    return rc;
}
