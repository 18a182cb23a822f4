/* tools/cmd/mean.c — edgespace mean: means of the normalized edge lengths
 * of all rows, of the rows matching a filter, or per value of a label
 * column; stored as /analysis/mean/NAME and exported as CSV. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace mean STORE [--by COLUMN] [--where FILTER] [--name NAME] [--output PATH]\n"
    "                            [--no-store]\n"
    "\n"
    "Mean scale-normalized edge lengths of the rows of STORE: of all rows, of\n"
    "the rows matching FILTER (\"col=value[,col=value...]\", all must hold; a\n"
    "value holding ',' is quoted: col=\"a,b\"), or one mean per value of label\n"
    "COLUMN. The means, row counts and mean scales are stored as\n"
    "/analysis/mean/NAME (default NAME: COLUMN, FILTER, COLUMN[FILTER], or\n"
    "\"all\").\n"
    "\n"
    "  -b, --by COLUMN    one mean per value of this label column\n"
    "  -w, --where FILTER only rows matching FILTER\n"
    "  -n, --name NAME    result name in the store\n"
    "      --no-store     compute and export only; leave the store unchanged\n"
    "  -o, --output PATH  write edge,v0,v1,<group>... (one column per group; - for stdout)\n"
    "      --replace      replace a stored result of that name (else refused)\n"
    "  -h, --help         show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_mean(int argc, char **argv)
{
    static const struct option lo[] = {
        {"by", required_argument, NULL, 'b'}, {"where", required_argument, NULL, 'w'},
        {"name", required_argument, NULL, 'n'}, {"output", required_argument, NULL, 'o'},
        {"no-store", no_argument, NULL, 'N'}, {"replace", no_argument, NULL, 'R'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *by = NULL, *where = NULL, *name = NULL, *csv = NULL;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c, nostore = 0;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "b:w:n:o:h", lo)) != -1) {
        switch (c) {
        case 'b': by = optarg; break;
        case 'w': where = optarg; break;
        case 'n': name = optarg; break;
        case 'o': csv = optarg; break;
        case 'N': nostore = 1; break;
        case 'R': wmode = ES_STORE_REPLACE; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("mean", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("mean", "give exactly one STORE");
    char defname[512];
    if (!name && !nostore) {
        /* by, the filter, both as "by[filter]", or "all" */
        if (by && where) snprintf(defname, sizeof defname, "%s[%s]", by, where);
        else snprintf(defname, sizeof defname, "%s", by ? by : where ? where : "all");
        name = defname;
    }
    if (nostore) name = NULL;
    es_ctx *ctx = cli_ctx_new("mean");
    if (!ctx) return CLI_FAIL;
    char *cmdline = cli_command_line(argc, argv);
    es_store *st = NULL;
    es_group_result *r = NULL;
    int ret = CLI_FAIL;
    es_status rc = es_store_open(ctx, argv[optind], name ? wmode : ES_STORE_READ, &st);
    es_study_mean_opts mo;
    es_study_mean_opts_init(&mo);
    mo.name = name;
    mo.where = where;
    mo.by = by;
    mo.command = cmdline;
    if (rc == ES_OK) rc = es_study_mean(ctx, st, &mo, &r);
    if (rc != ES_OK) {
        cli_fail("mean", ctx, rc);
        goto done;
    }
    FILE *out = cli_report_stream(csv);   /* "-o -": stdout is the CSV alone */
    /* the scale is the sum of edge lengths; centroid size is what GPA users know */
    fprintf(out, "%-20s %8s %14s %14s\n", by ? by : "group", "rows", "mean scale",
            "centroid size");
    for (int64_t g = 0; g < r->ngroups; g++)
        fprintf(out, "%-20s %8lld %14.6g %14.6g\n", r->names[g], (long long)r->counts[g],
                r->scales[g], r->centroid_sizes[g]);
    /* the table first: a failure leaves the store as it was */
    if ((csv && (rc = es_study_write_mean_table(ctx, st, r, csv)) != ES_OK) ||
        (rc = es_store_commit(ctx, st)) != ES_OK) {
        cli_fail("mean", ctx, rc);
        goto done;
    }
    if (name) fprintf(out, "stored as /analysis/mean/%s\n", name);
    ret = CLI_OK;
done:
    es_study_group_result_free(r);
    if (ret == CLI_OK) es_store_close(st);
    else es_store_abort(st);   /* leave the store as it was */
    free(cmdline);
    es_ctx_free(ctx);
    return ret;
}
