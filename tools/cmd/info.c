/* tools/cmd/info.c — edgespace info: what a store holds (topology, rows,
 * label columns, analysis results). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace info [--rows] STORE\n"
    "\n"
    "Describe an edgespace HDF5 store: topology (vertices, faces, edges,\n"
    "fingerprint), rows, label columns with their distinct values, and the\n"
    "analysis results it holds.\n"
    "\n"
    "      --rows   also list every row: id, scale and labels (tab-separated)\n"
    "  -h, --help   show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

/* Distinct values of a column (first few), counted. */
static void print_column(es_store *s, int64_t col)
{
    int64_t n = es_store_nrows(s), ndistinct = 0;
    const char *shown[6];
    int64_t counts[6] = {0};
    int nshown = 0;
    for (int64_t i = 0; i < n; i++) {
        const char *v = es_store_label(s, i, col);
        int64_t first = -1;
        for (int64_t k = 0; k < i && first < 0; k++)
            if (!strcmp(es_store_label(s, k, col), v)) first = k;
        if (first < 0) {
            ndistinct++;
            if (nshown < 6) {
                shown[nshown] = v;
                counts[nshown++] = 1;
            }
        } else {
            for (int k = 0; k < nshown; k++)
                if (!strcmp(shown[k], v)) counts[k]++;
        }
    }
    printf("  %-16s %lld distinct:", es_store_column_name(s, col), (long long)ndistinct);
    for (int k = 0; k < nshown; k++)
        printf("%s %s (%lld)", k ? "," : "", *shown[k] ? shown[k] : "\"\"",
               (long long)counts[k]);
    printf("%s\n", ndistinct > nshown ? ", ..." : "");
}

int cmd_info(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"rows", no_argument, NULL, 'r'}, {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    es_store *s = NULL;
    es_ctx *ctx;
    es_status rc;
    int c, rows = 0;
    char **kinds = NULL;
    int64_t nkinds = 0;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "h", longopts)) != -1) {
        switch (c) {
        case 'r': rows = 1; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("info", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("info", "give exactly one STORE");
    if (!(ctx = cli_ctx_new("info"))) return CLI_FAIL;
    if ((rc = es_store_open(ctx, argv[optind], ES_STORE_READ, &s))) {
        cli_fail("info", ctx, rc);
        es_ctx_free(ctx);
        return CLI_FAIL;
    }
    printf("store        %s\n", es_store_path(s));
    printf("topology     %s: %lld vertices, %lld faces, %lld edges, fingerprint %s\n",
           es_topology_kind_name(es_store_topology_kind(s)), (long long)es_store_nverts(s),
           (long long)es_store_nfaces(s), (long long)es_store_nedges(s),
           es_store_fingerprint(s));
    if (es_store_topology_kind(s) == ES_TOPOLOGY_NONE)
        printf("             landmarks only: no edge lengths (gpa runs; length statistics "
               "need --edges or --triangles at ingest)\n");
    else if (es_store_topology_kind(s) == ES_TOPOLOGY_TRUSS)
        printf("             truss: lengths of landmark pairs, no faces (no embed)\n");
    printf("rows         %lld", (long long)es_store_nrows(s));
    for (int64_t i = 0; i < es_store_nrows(s) && i < 4; i++)
        printf("%s%s", i ? ", " : ": ", es_store_row_id(s, i));
    printf("%s\n", es_store_nrows(s) > 4 ? ", ..." : "");
    printf("columns      %lld\n", (long long)es_store_ncolumns(s));
    for (int64_t col = 0; col < es_store_ncolumns(s); col++) print_column(s, col);
    if ((rc = es_store_list_results(ctx, s, NULL, &kinds, &nkinds))) goto fail;
    printf("results      %s\n", nkinds ? "" : "none");
    for (int64_t k = 0; k < nkinds; k++) {
        char **names = NULL;
        int64_t nn = 0;
        if ((rc = es_store_list_results(ctx, s, kinds[k], &names, &nn))) goto fail;
        printf("  %-16s", kinds[k]);
        for (int64_t j = 0; j < nn; j++) {
            printf(" %s", names[j]);
            es_free(ctx, names[j]);
        }
        printf("\n");
        es_free(ctx, names);
    }
    if (rows) {
        double *scales = malloc((size_t)(es_store_nrows(s) + 1) * sizeof *scales);
        if (!scales ||
            (es_store_nedges(s) > 0 && (rc = es_store_read_scales(ctx, s, scales)))) {
            free(scales);
            if (!scales) rc = ES_ENOMEM;
            goto fail;
        }
        printf("\nid\tscale");
        for (int64_t col = 0; col < es_store_ncolumns(s); col++)
            printf("\t%s", es_store_column_name(s, col));
        printf("\n");
        for (int64_t i = 0; i < es_store_nrows(s); i++) {
            if (es_store_nedges(s) > 0) printf("%s\t%.17g", es_store_row_id(s, i), scales[i]);
            else printf("%s\t-", es_store_row_id(s, i));
            for (int64_t col = 0; col < es_store_ncolumns(s); col++)
                printf("\t%s", es_store_label(s, i, col));
            printf("\n");
        }
        free(scales);
    }
    for (int64_t k = 0; k < nkinds; k++) es_free(ctx, kinds[k]);
    es_free(ctx, kinds);
    es_store_close(s);
    es_ctx_free(ctx);
    return CLI_OK;
fail:
    for (int64_t k = 0; k < nkinds; k++) es_free(ctx, kinds[k]);
    es_free(ctx, kinds);
    cli_fail("info", ctx, rc);
    es_store_close(s);
    es_ctx_free(ctx);
    return CLI_FAIL;
}
