/* tools/stats_cli.c — see stats_cli.h. */
#include "stats_cli.h"
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

FILE *stats_csv_open(const char *verb, const char *path)
{
    if (!strcmp(path, "-")) return stdout;
    /* Refuse to truncate an HDF5 file (the store given as --csv by mistake). */
    if (es_file_is_hdf5(path)) {
        fprintf(stderr, "edgespace %s: '%s' is an HDF5 file (a store?); not overwriting it "
                "with CSV\n", verb, path);
        return NULL;
    }
    FILE *f = fopen(path, "w");
    if (!f) fprintf(stderr, "edgespace %s: cannot write '%s': %s\n", verb, path, strerror(errno));
    return f;
}

int stats_csv_close(const char *verb, FILE *f, const char *path)
{
    int bad = ferror(f);
    if (f == stdout) return bad ? -1 : (fflush(f) ? -1 : 0);
    if (fclose(f) != 0) bad = 1;
    if (bad) fprintf(stderr, "edgespace %s: error writing '%s'\n", verb, path);
    return bad ? -1 : 0;
}

void stats_csv_field(FILE *f, const char *s, int first)
{
    if (!first) fputc(',', f);
    es_csv_write_field(f, s);
}

void stats_csv_number(FILE *f, double v)
{
    fprintf(f, ",%.17g", v);
}

int64_t *stats_edges(const char *verb, es_ctx *ctx, es_store *store)
{
    /* the stored edge list, not es_store_mesh: truss stores have no faces */
    int64_t E = es_store_nedges(store);
    int64_t *e = malloc((size_t)(2 * E > 0 ? 2 * E : 1) * sizeof *e);
    if (!e) {
        fprintf(stderr, "edgespace %s: out of memory\n", verb);
        return NULL;
    }
    es_status rc = es_store_read_edges(ctx, store, e);
    if (rc != ES_OK) {
        cli_fail(verb, ctx, rc);
        free(e);
        return NULL;
    }
    return e;
}

int stats_write_edge_csv(const char *verb, es_ctx *ctx, es_store *store, const char *path,
                         int64_t ncol, const char *const *names, const double *values)
{
    int64_t *edges = stats_edges(verb, ctx, store);
    if (!edges) return CLI_FAIL;
    FILE *f = stats_csv_open(verb, path);
    if (!f) {
        free(edges);
        return CLI_FAIL;
    }
    const int64_t E = es_store_nedges(store);
    fputs("edge,v0,v1", f);
    for (int64_t c = 0; c < ncol; c++) stats_csv_field(f, names[c], 0);
    fputc('\n', f);
    for (int64_t e = 0; e < E; e++) {
        fprintf(f, "%lld,%lld,%lld", (long long)e, (long long)edges[2 * e],
                (long long)edges[2 * e + 1]);
        for (int64_t c = 0; c < ncol; c++) stats_csv_number(f, values[e + c * E]);
        fputc('\n', f);
    }
    free(edges);
    return stats_csv_close(verb, f, path) ? CLI_FAIL : CLI_OK;
}

/* The mean scale of the store's rows: the scale of a point without one. */
static es_status mean_row_scale(es_ctx *ctx, es_store *store, double *scale)
{
    int64_t n = es_store_nrows(store);
    double *scales = malloc((size_t)(n + 1) * sizeof *scales);
    es_status rc;
    if (!scales) return ES_ENOMEM;
    *scale = 0;
    if ((rc = es_store_read_scales(ctx, store, scales)) == ES_OK)
        for (int64_t i = 0; i < n; i++) *scale += scales[i] / (double)n;
    free(scales);
    return rc;
}

es_status stats_point_lengths(const char *verb, es_ctx *ctx, es_store *store, const char *spec,
                              const char *pca, int64_t ne, double *lengths, double *scale)
{
    char path[512];
    double *v = NULL;
    int64_t n = 0;
    es_status rc = ES_OK;
    *scale = 0;
    snprintf(path, sizeof path, "point/%s/lengths", spec);
    if (!strncmp(spec, "row:", 4)) {
        int64_t r = es_store_find_row(store, spec + 4);
        if (r < 0) {
            fprintf(stderr, "edgespace %s: no row '%s' in the store\n", verb, spec + 4);
            return ES_ENOTFOUND;
        }
        double *scales = malloc((size_t)(es_store_nrows(store) + 1) * sizeof *scales);
        if (!scales) rc = ES_ENOMEM;
        else if (!(rc = es_store_read_lengths(ctx, store, r, 1, (es_mat){lengths, ne, 1, ne})) &&
                 !(rc = es_store_read_scales(ctx, store, scales)))
            *scale = scales[r];
        free(scales);
    } else if (es_store_has(store, path)) {   /* a stored point */
        if (!(rc = es_store_get_vector(ctx, store, path, &v, &n)) && n != ne) {
            fprintf(stderr, "edgespace %s: point '%s' has %lld lengths, the store's topology "
                    "%lld edges\n", verb, spec, (long long)n, (long long)ne);
            es_free(ctx, v);
            return ES_EMISMATCH;
        }
        if (rc == ES_OK) memcpy(lengths, v, (size_t)ne * sizeof *lengths);
        es_free(ctx, v);
        v = NULL;
        snprintf(path, sizeof path, "point/%s/scale", spec);
        if (rc == ES_OK && es_store_has(store, path) &&
            !(rc = es_store_get_vector(ctx, store, path, &v, &n)) && n >= 1 && v[0] > 0)
            *scale = v[0];
        es_free(ctx, v);
    } else {   /* an expression (es_point.h syntax) */
        es_point_info info;
        if (!(rc = es_study_point(ctx, store, NULL, spec, pca, 0, "edgespace", &v, &info))) {
            memcpy(lengths, v, (size_t)ne * sizeof *lengths);
            if (isfinite(info.scale) && info.scale > 0) *scale = info.scale;
        }
        es_free(ctx, v);
    }
    if (rc == ES_OK && *scale == 0) rc = mean_row_scale(ctx, store, scale);
    if (rc != ES_OK) {
        cli_fail(verb, ctx, rc);
        return rc;
    }
    /* beyond the positive orthant (extrapolation) no mesh realizes the point */
    for (int64_t e = 0; e < ne; e++)
        if (!(lengths[e] > 0)) {
            fprintf(stderr, "edgespace %s: the point has length %g at edge %lld: it is outside "
                    "edge-length space (not realizable)\n", verb, lengths[e], (long long)e);
            return ES_EINVAL;
        }
    return ES_OK;
}
