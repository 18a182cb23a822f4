/* tools/cmd/plot_pca.c — edgespace plot-pca: figures of a stored PCA
 * (es_figure_pca): scores on two components coloured by a label column
 * (Fig. 9 of Fisher et al.) or the scree plot; PNG, SVG or PDF by the
 * output's extension. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>

static const char usage[] =
    "usage: edgespace plot-pca STORE [--pca NAME] [--pcs A,B] [--color COLUMN] -o OUT\n"
    "       edgespace plot-pca STORE [--pca NAME] --scree -o OUT\n"
    "\n"
    "Scatter of the PCA scores on components A and B (default 1,2), one colour\n"
    "per value of label COLUMN, or the scree plot (explained variance per\n"
    "component and cumulative). OUT ends in .png, .svg or .pdf.\n"
    "\n"
    "  -p, --pca NAME      the PCA (default: the only one, or \"default\")\n"
    "      --pcs A,B       components on the x and y axes (1-based)\n"
    "      --color COLUMN  colour points by this label column\n"
    "      --scree         draw the scree plot instead\n"
    "      --title TEXT    figure title\n"
    "  -o, --output OUT    the figure file (required)\n"
    "  -h, --help          show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_plot_pca(int argc, char **argv)
{
    static const struct option lo[] = {
        {"pca", required_argument, NULL, 'p'}, {"pcs", required_argument, NULL, 'c'},
        {"color", required_argument, NULL, 'l'}, {"colour", required_argument, NULL, 'l'},
        {"scree", no_argument, NULL, 's'}, {"title", required_argument, NULL, 'T'},
        {"output", required_argument, NULL, 'o'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *pca_name = NULL, *color = NULL, *out = NULL, *title = NULL;
    long long a = 1, b = 2;
    int c, scree = 0;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "p:o:h", lo)) != -1) {
        switch (c) {
        case 'p': pca_name = optarg; break;
        case 'l': color = optarg; break;
        case 's': scree = 1; break;
        case 'T': title = optarg; break;
        case 'o': out = optarg; break;
        case 'c': {
            char tail;
            if (sscanf(optarg, "%lld,%lld%c", &a, &b, &tail) != 2 || a < 1 || b < 1)
                return cli_usage_error("plot-pca", "--pcs wants two component numbers, e.g. 1,2");
            break;
        }
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("plot-pca", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("plot-pca", "give exactly one STORE");
    if (!out) return cli_usage_error("plot-pca", "--output OUT is required");
    es_ctx *ctx = cli_ctx_new("plot-pca");
    if (!ctx) return CLI_FAIL;
    es_store *st = NULL;
    es_status rc = es_store_open(ctx, argv[optind], ES_STORE_READ, &st);
    if (rc == ES_OK) rc = es_figure_pca(ctx, st, pca_name, a, b, color, scree, title, out);
    int ret = rc == ES_OK ? CLI_OK : cli_fail("plot-pca", ctx, rc);
    if (rc == ES_OK) printf("wrote %s\n", out);
    es_store_close(st);
    es_ctx_free(ctx);
    return ret;
}
