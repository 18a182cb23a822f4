/* tools/cmd/plot.c — `edgespace plot`: the figures of es_plot.h from a CSV
 * table (es_figure_table): scatter, lines, scree, histogram, heatmap. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>

#define VERB "plot"
#define MAX_Y 32

static void usage(FILE *f)
{
    fputs("usage: edgespace plot KIND TABLE.csv -o OUT.png|.svg|.pdf [options]\n"
          "(the PCA figures are 'edgespace plot-pca'; 'plot STORE --pca' is its old spelling)\n\n"
          "KIND is one of:\n"
          "  scatter    points (--x, --y), coloured by the category in --label\n"
          "  lines      one curve per --y column against --x (legend: column names)\n"
          "  scree      bars of --y (variances) as percent of the total, and cumulative\n"
          "  histogram  distribution of --y\n"
          "  heatmap    the table as a matrix; a non-numeric first row / first column\n"
          "             are column / row labels\n\n"
          "Columns are named by header or 1-based number. The first row is a header\n"
          "when it is not all numbers. Empty cells and 'nan' are missing values.\n\n"
          "options:\n"
          "  -o, --output PATH   output file; the extension picks the format\n"
          "      --x COL         x column (default: 1; lines without --x: row number)\n"
          "      --y COL[,COL]   y column(s) (default: 2, or 1 for scree/histogram)\n"
          "      --label COL     category column (scatter)\n"
          "      --title TEXT, --xlabel TEXT, --ylabel TEXT\n"
          "      --logy          log10 y axis (lines)\n"
          "      --bins N        histogram bins (default: Freedman-Diaconis)\n"
          "      --total V       total variance for scree percentages (default: sum)\n"
          "      --cmap NAME     heatmap colours: viridis (default), rdbu, greys\n"
          "      --equal         equal scales on x and y (scatter)\n"
          "      --width W, --height H   size (default 640 x 480)\n"
          "  -h, --help          show this help\n", f);
}

/* "edgespace plot STORE --pca NAME ..." (issue 3's form) is the PCA figure:
 * any argument ending in .h5, or a --pca/--scree option, sends it there. */
static int wants_pca_figure(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        size_t n = strlen(argv[i]);
        if (!strcmp(argv[i], "--pca") || !strncmp(argv[i], "--pca=", 6) ||
            !strcmp(argv[i], "--scree") || (n > 3 && !strcmp(argv[i] + n - 3, ".h5")))
            return 1;
    }
    return 0;
}

int cmd_plot(int argc, char **argv)
{
    if (wants_pca_figure(argc, argv)) {
        /* One command per figure kind (README "Options"): the old form
         * still draws, as plot-pca with plot-pca's own messages. */
        cli_deprecated(VERB, "plot STORE --pca ...", "plot-pca STORE ...");
        static char verb_pca[] = "plot-pca";
        argv[0] = verb_pca;
        return cmd_plot_pca(argc, argv);
    }

    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"x", required_argument, NULL, 'x'},
        {"y", required_argument, NULL, 'y'}, {"label", required_argument, NULL, 'l'},
        {"title", required_argument, NULL, 't'}, {"xlabel", required_argument, NULL, 'X'},
        {"ylabel", required_argument, NULL, 'Y'}, {"logy", no_argument, NULL, 'L'},
        {"bins", required_argument, NULL, 'b'}, {"total", required_argument, NULL, 'T'},
        {"cmap", required_argument, NULL, 'c'}, {"equal", no_argument, NULL, 'e'},
        {"width", required_argument, NULL, 'W'}, {"height", required_argument, NULL, 'H'},
        {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    const char *out = NULL, *ycols = NULL, *y[MAX_Y];
    es_figure_table_spec spec;
    int c, m;
    int64_t v64;
    char buf[4096], *save = NULL;

    es_figure_table_spec_init(&spec);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "o:h", opts)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'x': spec.x = optarg; break;
        case 'y': ycols = optarg; break;
        case 'l': spec.label = optarg; break;
        case 't': spec.frame.title = optarg; break;
        case 'X': spec.frame.xlabel = optarg; break;
        case 'Y': spec.frame.ylabel = optarg; break;
        case 'L': spec.logy = 1; break;
        case 'e': spec.equal = 1; break;
        case 'b':
            if (cli_parse_i64(optarg, &spec.bins) || spec.bins < 1 || spec.bins > 10000)
                return cli_usage_error(VERB, "--bins wants an integer in 1..10000");
            break;
        case 'T':
            if (cli_parse_double(optarg, &spec.total) || !(spec.total > 0))
                return cli_usage_error(VERB, "--total wants a positive number");
            break;
        case 'c':
            if ((m = es_colormap_from_name(optarg)) < 0)
                return cli_usage_error(VERB, "unknown colour map '%s'", optarg);
            spec.cmap = (es_colormap)m;
            break;
        case 'W':
        case 'H':
            if (cli_parse_i64(optarg, &v64) || v64 < 16 || v64 > 16384)
                return cli_usage_error(VERB, "--%s wants an integer in 16..16384",
                                       c == 'W' ? "width" : "height");
            if (c == 'W') spec.frame.width = (int)v64;
            else spec.frame.height = (int)v64;
            break;
        case 'h': usage(stdout); return CLI_OK;
        default: return cli_usage_error(VERB, "unknown option");
        }
    }
    if (argc - optind != 2) return cli_usage_error(VERB, "want KIND and TABLE.csv");
    if (!out) return cli_usage_error(VERB, "no output file (-o)");
    const char *kind = argv[optind], *path = argv[optind + 1];
    if ((m = es_figure_table_kind_from_name(kind)) < 0)
        return cli_usage_error(VERB, "unknown plot kind '%s'", kind);
    spec.kind = (es_table_kind)m;
    snprintf(buf, sizeof buf, "%s", ycols && m != ES_TABLE_HEATMAP ? ycols : "");
    for (char *s = strtok_r(buf, ",", &save); s; s = strtok_r(NULL, ",", &save)) {
        if (spec.ny == MAX_Y) return cli_usage_error(VERB, "at most %d --y columns", MAX_Y);
        y[spec.ny++] = s;
    }
    spec.y = y;

    es_ctx *ctx = cli_ctx_new(VERB);
    if (!ctx) return CLI_FAIL;
    es_status st = es_figure_table(ctx, &spec, path, out, NULL);
    int rc = st == ES_OK ? CLI_OK : cli_fail(VERB, ctx, st);
    es_ctx_free(ctx);
    return rc;
}
