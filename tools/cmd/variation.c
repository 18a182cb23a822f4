/* tools/cmd/variation.c — edgespace variation: mean +- k sd along principal
 * components, or along a model coefficient, embedded near the data and
 * drawn in one frame beside the per-vertex displacement
 * (es_figure_variation). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define VERB "variation"

static const char usage[] =
    "usage: edgespace variation STORE -o OUT.png|.svg|.pdf [options]\n"
    "\n"
    "Embed the mean and mean +- k sd along principal components of a stored PCA\n"
    "(or mean +- k x a model coefficient) near the data, and draw them in one\n"
    "frame, one row per axis: minus, mean, plus, and the mean coloured by each\n"
    "vertex's displacement from the minus to the plus shape.\n"
    "\n"
    "  -o, --output PATH      the figure; the extension picks the format\n"
    "  -p, --pca NAME         the PCA of the components (default: the only one)\n"
    "      --pcs LIST         components, e.g. 1,2,3 (default: 1; at most 8)\n"
    "      --coef MODEL:COEF  instead of components: a coefficient of a stored\n"
    "                         model in edge-length space (k in its units)\n"
    "      --sd K             how far, in standard deviations (2)\n"
    "      --panel PIXELS     panel width and height (360)\n"
    "      --title TEXT       title (default: automatic)\n"
CLI_EMBED_HELP
    "  -h, --help             show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

static int parse_pcs(const char *s, int64_t *pcs, int64_t *n)
{
    char buf[256], *save = NULL;
    if (strlen(s) >= sizeof buf) return -1;
    strcpy(buf, s);
    *n = 0;
    for (char *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        if (*n == ES_VARIATION_MAX_AXES || cli_parse_i64(t, &pcs[*n]) || pcs[*n] < 1) return -1;
        (*n)++;
    }
    return *n > 0 ? 0 : -1;
}

int cmd_variation(int argc, char **argv)
{
    enum { O_COEF = 256, O_PANEL, O_TITLE };
    static const struct option lo[] = {
        {"output", required_argument, NULL, 'o'}, {"pca", required_argument, NULL, 'p'},
        {"pcs", required_argument, NULL, 'c'}, {"coef", required_argument, NULL, O_COEF},
        {"sd", required_argument, NULL, 'k'}, {"panel", required_argument, NULL, O_PANEL},
        {"title", required_argument, NULL, O_TITLE}, {"help", no_argument, NULL, 'h'},
        CLI_EMBED_LONGOPTS, {NULL, 0, NULL, 0}};
    es_figure_variation_opts o;
    es_figure_variation_opts_init(&o);
    int64_t pcs[ES_VARIATION_MAX_AXES], panel = 0;
    const char *out = NULL;
    int c, e;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "o:p:h", lo)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'p': o.pca_name = optarg; break;
        case 'c':
            if (parse_pcs(optarg, pcs, &o.npcs))
                return cli_usage_error(VERB, "--pcs wants 1 to %d component numbers like 1,2",
                                       ES_VARIATION_MAX_AXES);
            o.pcs = pcs;
            break;
        case O_COEF: o.coef = optarg; break;
        case 'k':
            if (cli_parse_double(optarg, &o.k) || !(o.k > 0))
                return cli_usage_error(VERB, "--sd needs a number > 0");
            break;
        case O_PANEL:
            if (cli_parse_i64(optarg, &panel) || panel < 64 || panel > 4096)
                return cli_usage_error(VERB, "--panel needs 64..4096 pixels");
            o.panel = (int)panel;
            break;
        case O_TITLE: o.title = optarg; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default:
            if ((e = cli_embed_option(VERB, c, optarg, &o.embed)) >= 0) {
                if (e) return e;
                break;
            }
            return cli_usage_error(VERB, "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error(VERB, "give exactly one STORE");
    if (!out) return cli_usage_error(VERB, "missing -o OUT.png|.svg|.pdf");
    if (o.coef && (o.npcs || o.pca_name))
        return cli_usage_error(VERB, "--coef goes without --pcs and --pca");
    es_ctx *ctx = cli_ctx_new(VERB);
    if (!ctx) return CLI_FAIL;
    es_store *st = NULL;
    es_figure_variation_report r;
    int ret = CLI_OK;
    es_status rc = es_store_open(ctx, argv[optind], ES_STORE_READ, &st);
    if (rc == ES_OK) rc = es_figure_variation(ctx, st, &o, out, &r);
    if (rc != ES_OK) ret = cli_fail(VERB, ctx, rc);
    else {
        printf("mean: length RMS %.3g %%\n", 100 * r.mean.rms_ratio);
        for (int64_t a = 0; a < r.naxes; a++)
            printf("axis %lld: -k length RMS %.3g %%, +k %.3g %%, largest displacement %.6g\n",
                   (long long)(a + 1), 100 * r.minus[a].rms_ratio, 100 * r.plus[a].rms_ratio,
                   r.max_displacement[a]);
        printf("figure: %s\n", out);
    }
    es_store_close(st);
    es_ctx_free(ctx);
    return ret;
}
