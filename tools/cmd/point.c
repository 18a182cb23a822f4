/* tools/cmd/point.c — edgespace point: evaluate a point expression
 * (datasets-spec/point-syntax.md) on a store, report its scale and validity,
 * and store it as /analysis/point/NAME for embedding. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace point STORE EXPRESSION [--name NAME] [--pca NAME] [--scale S]\n"
    "                       [--output PATH]\n"
    "\n"
    "Evaluate a point of edge-length space, e.g.\n"
    "    \"mean[expression=neutral] + diff:smile\"   \"mean + 2*pc:1\"\n"
    "    \"lerp(row:s001_neutral, row:s001_happy, 1.5)\"   \"(file:scan.obj + mean) / 2\"\n"
    "(syntax: datasets-spec/point-syntax.md). Prints the scale to embed it at\n"
    "(the shapes' weights applied to their scales) and a validity report\n"
    "(non-positive lengths, faces violating the triangle inequality). With\n"
    "--name the point is stored as /analysis/point/NAME.\n"
    "\n"
    "  -n, --name NAME   store the point under this name\n"
    "  -p, --pca NAME    the PCA of pc:K (default: the only one, or \"default\");\n"
    "                    pc:NAME:K names it in the expression\n"
    "  -s, --scale S     embed at scale S instead of the rule\n"
    "  -o, --output PATH write edge,v0,v1,length (normalized) as CSV (- for stdout)\n"
    "      --replace     replace a stored result of that name (else refused)\n"
    "  -h, --help        show this help\n"
    "\n"
    "Exit status: 0 ok (also for an invalid point), 1 failure, 2 usage error.\n";

int cmd_point(int argc, char **argv)
{
    static const struct option lo[] = {
        {"name", required_argument, NULL, 'n'}, {"pca", required_argument, NULL, 'p'},
        {"scale", required_argument, NULL, 's'}, {"output", required_argument, NULL, 'o'},
        {"replace", no_argument, NULL, 'R'}, {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    const char *name = NULL, *pca = NULL, *csv = NULL;
    double scale = 0;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "n:p:s:o:h", lo)) != -1) {
        switch (c) {
        case 'n': name = optarg; break;
        case 'p': pca = optarg; break;
        case 'o': csv = optarg; break;
        case 's':
            if (cli_parse_double(optarg, &scale) || !(scale > 0))
                return cli_usage_error("point", "--scale wants a positive number");
            break;
        case 'R': wmode = ES_STORE_REPLACE; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("point", "bad option");
        }
    }
    if (optind != argc - 2) return cli_usage_error("point", "give a STORE and an EXPRESSION");
    es_ctx *ctx = cli_ctx_new("point");
    if (!ctx) return CLI_FAIL;
    char *cmdline = cli_command_line(argc, argv);
    es_store *st = NULL;
    double *vec = NULL;
    es_point_info info;
    int ret = CLI_FAIL;
    es_status rc = es_store_open(ctx, argv[optind], name ? wmode : ES_STORE_READ, &st);
    es_study_point_opts po;
    es_study_point_opts_init(&po);
    po.name = name;
    po.expr = argv[optind + 1];
    po.pca_name = pca;
    po.scale = scale;
    po.command = cmdline;
    if (rc == ES_OK) rc = es_study_point(ctx, st, &po, &vec, NULL, &info);
    if (rc != ES_OK) {
        cli_fail("point", ctx, rc);
        goto done;
    }
    FILE *out = cli_report_stream(csv);   /* "-o -": stdout is the CSV alone */
    fprintf(out, "point %s: %lld shape and %lld direction terms, weights sum to %.6g\n",
            argv[optind + 1], (long long)info.nshapes, (long long)info.ndirections, info.weight);
    if (isnan(info.scale))
        fprintf(out, "scale: none (no shapes with non-zero total weight; use --scale)\n");
    else fprintf(out, "scale: %.9g%s\n", info.scale, scale > 0 ? " (given)" : "");
    fprintf(out, "lengths sum to %.12g\n", info.length_sum);
    const es_validity *v = &info.validity;
    if (!info.checked) {
        fprintf(out, "validity: not checked (a truss store has no faces for the triangle "
                "inequality)\n");
    } else if (v->valid) {
        fprintf(out, "valid: every length positive, every face satisfies the triangle "
                "inequality\n");
    } else {
        fprintf(out, "INVALID: %lld non-finite, %lld non-positive lengths; %lld faces violate the "
                "triangle inequality", (long long)v->n_nonfinite, (long long)v->n_nonpositive,
                (long long)v->n_bad_faces);
        if (v->worst_face >= 0)
            fprintf(out, " (worst: face %lld by %.3g of its perimeter)", (long long)v->worst_face,
                    v->worst_violation);
        fprintf(out, "\n");
    }
    /* the table first: a failure leaves the store as it was */
    static const char *const names[1] = {"length"};
    if ((csv && (rc = es_study_write_edge_table(ctx, st, csv, 1, names, vec)) != ES_OK) ||
        (rc = es_store_commit(ctx, st)) != ES_OK) {
        cli_fail("point", ctx, rc);
        goto done;
    }
    if (name) fprintf(out, "stored as /analysis/point/%s\n", name);
    ret = CLI_OK;
done:
    es_free(ctx, vec);
    if (ret == CLI_OK) es_store_close(st);
    else es_store_abort(st);   /* leave the store as it was */
    free(cmdline);
    es_ctx_free(ctx);
    return ret;
}
