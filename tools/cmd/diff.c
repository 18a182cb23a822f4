/* tools/cmd/diff.c — edgespace diff: the mean "to minus from" edge-length
 * difference over rows paired by a key column (Fig. 10 of Fisher et al.:
 * happy minus neutral, per subject, averaged), with per-edge standard error
 * and t statistic; stored as /analysis/diff/NAME. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace diff STORE --pair-by KEY --from VALUE --to VALUE [--column COLUMN]\n"
    "                      [--name NAME] [--where FILTER] [--output PATH]\n"
    "\n"
    "Pair the rows whose label COLUMN is VALUE(from) with those whose COLUMN is\n"
    "VALUE(to) by their label KEY (e.g. subject), take to - from per pair and\n"
    "average. Reports the number of pairs and every unpaired row; a key with two\n"
    "'from' (or two 'to') rows is an error. Stores mean, sd, se and t per edge\n"
    "as /analysis/diff/NAME (default NAME: TO-minus-FROM).\n"
    "\n"
    "      --pair-by KEY    label column that pairs rows\n"
    "      --from VALUE     value of COLUMN of the rows subtracted\n"
    "      --to VALUE       value of COLUMN of the rows subtracted from\n"
    "      --column COLUMN  label column holding VALUE (default: the one column\n"
    "                       other than KEY in which both values occur)\n"
    "  -n, --name NAME      result name\n"
    "  -w, --where FILTER   only rows matching \"col=value[,...]\"\n"
    "                       (quote a value holding ',': col=\"a,b\")\n"
    "  -o, --output PATH    write edge,v0,v1,mean,sd,se,t (- for stdout)\n"
    "      --replace        replace a stored result of that name (else refused)\n"
    "  -h, --help           show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

static int has_value(es_store *st, int64_t col, const char *v)
{
    for (int64_t i = 0; i < es_store_nrows(st); i++)
        if (!strcmp(es_store_label(st, i, col), v)) return 1;
    return 0;
}

int cmd_diff(int argc, char **argv)
{
    static const struct option lo[] = {
        {"pair-by", required_argument, NULL, 'p'}, {"from", required_argument, NULL, 'f'},
        {"to", required_argument, NULL, 't'}, {"column", required_argument, NULL, 'c'},
        {"name", required_argument, NULL, 'n'}, {"where", required_argument, NULL, 'w'},
        {"output", required_argument, NULL, 'o'}, {"replace", no_argument, NULL, 'R'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *key = NULL, *from = NULL, *to = NULL, *column = NULL, *name = NULL,
               *where = NULL, *csv = NULL;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "n:w:o:h", lo)) != -1) {
        switch (c) {
        case 'p': key = optarg; break;
        case 'f': from = optarg; break;
        case 't': to = optarg; break;
        case 'c': column = optarg; break;
        case 'n': name = optarg; break;
        case 'w': where = optarg; break;
        case 'o': csv = optarg; break;
        case 'R': wmode = ES_STORE_REPLACE; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("diff", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("diff", "give exactly one STORE");
    if (!key || !from || !to) return cli_usage_error("diff", "--pair-by, --from and --to are required");
    es_ctx *ctx = cli_ctx_new("diff");
    if (!ctx) return CLI_FAIL;
    char *cmdline = cli_command_line(argc, argv), defname[256];
    es_store *st = NULL;
    es_diff *d = NULL;
    int ret = CLI_FAIL;
    if (!name) {
        snprintf(defname, sizeof defname, "%s-minus-%s", to, from);
        name = defname;
    }
    es_status rc = es_store_open(ctx, argv[optind], wmode, &st);
    if (rc != ES_OK) {
        cli_fail("diff", ctx, rc);
        goto done;
    }
    if (!column) {
        int64_t found = -1, nfound = 0, kc = es_store_find_column(st, key);
        for (int64_t col = 0; col < es_store_ncolumns(st); col++)
            if (col != kc && has_value(st, col, from) && has_value(st, col, to)) found = col, nfound++;
        if (nfound != 1) {
            fprintf(stderr, "edgespace diff: %s label column holds both '%s' and '%s'; name it "
                    "with --column\n", nfound ? "more than one" : "no", from, to);
            goto done;
        }
        column = es_store_column_name(st, found);
    }
    es_study_diff_opts so;
    es_study_diff_opts_init(&so);
    so.name = name;
    so.where = where;
    so.key = key;
    so.column = column;
    so.from = from;
    so.to = to;
    so.command = cmdline;
    if ((rc = es_study_diff(ctx, st, &so, &d)) != ES_OK) {
        cli_fail("diff", ctx, rc);
        goto done;
    }
    FILE *out = cli_report_stream(csv);   /* "-o -": stdout is the CSV alone */
    fprintf(out, "diff '%s': %s=%s minus %s=%s, paired by %s: %lld pairs\n", name, column, to,
            column, from, key, (long long)d->npairs);
    if (d->nunpaired) {
        fprintf(out, "%lld unpaired rows:", (long long)d->nunpaired);
        for (int64_t i = 0; i < d->nunpaired; i++)
            fprintf(out, " %s", es_store_row_id(st, d->unpaired[i]));
        fprintf(out, "\n");
    }
    double norm = 0, tmax = 0;
    int64_t emax = -1;
    for (int64_t e = 0; e < d->nedges; e++) {
        norm += d->mean[e] * d->mean[e];
        if (fabs(d->t[e]) > tmax) tmax = fabs(d->t[e]), emax = e;
    }
    if (emax >= 0)
        fprintf(out, "|mean difference| = %.6g; largest |t| = %.3g at edge %lld (%lld degrees of "
                "freedom)\n", sqrt(norm), tmax, (long long)emax, (long long)(d->npairs - 1));
    else   /* one pair: no spread, so no t */
        fprintf(out, "|mean difference| = %.6g; no t statistics (%lld pair)\n", sqrt(norm),
                (long long)d->npairs);
    /* the table first: a failure leaves the store as it was */
    if ((csv && (rc = es_study_write_diff_table(ctx, st, d, csv)) != ES_OK) ||
        (rc = es_store_commit(ctx, st)) != ES_OK) {
        cli_fail("diff", ctx, rc);
        goto done;
    }
    fprintf(out, "stored as /analysis/diff/%s\n", name);
    ret = CLI_OK;
done:
    es_diff_free(d);
    if (ret == CLI_OK) es_store_close(st);
    else es_store_abort(st);   /* leave the store as it was */
    free(cmdline);
    es_ctx_free(ctx);
    return ret;
}
