/* tools/edgespace.c — the edgespace command: dispatches to subcommands, git
 * style. Each subcommand lives in tools/cmd/<verb>.c and stays thin over the
 * library. */
#include "blas_spin.h"
#include "cli.h"
#include "commands.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct command {
    const char *name;
    cli_cmd_fn fn;
    const char *summary;
} command;

static const command commands[] = {
    /* -- topology, geometry, synthetic data */
    {"synth", cmd_synth, "write a synthetic family of meshes in correspondence"},
    /* -- mesh I/O */
    /* -- store, manifest, ingest */
    {"ingest", cmd_ingest, "read meshes (manifest or files) into an HDF5 store"},
    {"info", cmd_info, "describe a store: topology, rows, labels, results"},
    {"export", cmd_export, "write a store's lengths as CSV or its meshes as files"},
    {"results", cmd_results, "list a store's analysis results, or delete some"},
    /* -- statistics, point syntax */
    {"mean", cmd_mean, "mean edge lengths of all rows, a filter, or per label value"},
    {"pca", cmd_pca, "principal components of the edge lengths (stored, CSV)"},
    {"diff", cmd_diff, "mean paired difference (to - from) with per-edge t statistics"},
    {"project", cmd_project, "scores of rows or mesh files on a stored PCA, with residuals"},
    {"point", cmd_point, "evaluate and store a point expression (mean + 2*pc:1, ...)"},
    {"model", cmd_model, "linear model of the shapes on label columns, permutation tests"},
#if ES_HAVE_FIGURES
    {"plot-pca", cmd_plot_pca, "PCA score scatter coloured by a label, or scree plot, from a store"},
#endif
    /* -- procrustes, landmarks, comparison */
    {"gpa", cmd_gpa, "generalized Procrustes analysis of a store's positions"},
    {"compare", cmd_compare, "Procrustes vs edge-length space: distances, Mantel, groups"},
    {"ingest-landmarks", cmd_ingest_landmarks, "landmarks (TPS, CSV) into a store (+ triangles or edges)"},
    /* -- embedding, interpolation */
    {"embed", cmd_embed, "realize a point of edge-length space as a mesh, with a quality report"},
    {"interp", cmd_interp, "interpolate/extrapolate stored shapes in edge-length space and embed"},
    {"explore", cmd_explore, "explore a store by hand in a browser: sliders, scatter, meshes as you drag"},
    /* -- plotting, rendering */
#if ES_HAVE_FIGURES
    {"render", cmd_render, "draw meshes side by side to PNG/SVG/PDF"},
    {"plot", cmd_plot, "scatter, lines, scree, histogram or heat map of a CSV table"},
    {"variation", cmd_variation, "mean +- k sd along PCs or a model coefficient, embedded, one figure"},
#endif
    {NULL, NULL, NULL}
};

static void print_help(FILE *f)
{
    fputs("usage: edgespace <command> [options]\n"
          "       edgespace help [command] | --version\n\n"
          "Statistical shape analysis in edge-length shape space.\n\ncommands:\n", f);
    for (const command *c = commands; c->name; c++)
        fprintf(f, "  %-18s %s\n", c->name, c->summary);
    fputs("\nRun 'edgespace <command> --help' for a command's options.\n", f);
}

int main(int argc, char **argv)
{
    short_blas_spin(argv);
    if (argc < 2) {
        print_help(stderr);
        return CLI_USAGE;
    }
    const char *verb = argv[1];
    if (!strcmp(verb, "--version") || !strcmp(verb, "version")) {
        printf("edgespace %s\n", es_version());
        return CLI_OK;
    }
    if (!strcmp(verb, "help") || !strcmp(verb, "--help") || !strcmp(verb, "-h")) {
        if (argc > 2) {
            for (const command *c = commands; c->name; c++) {
                if (!strcmp(c->name, argv[2])) {
                    char help[] = "--help";
                    char *sub[] = {argv[2], help, NULL};
                    return c->fn(2, sub);
                }
            }
            fprintf(stderr, "edgespace: unknown command '%s'\n", argv[2]);
            return CLI_USAGE;
        }
        print_help(stdout);
        return CLI_OK;
    }
    for (const command *c = commands; c->name; c++)
        if (!strcmp(c->name, verb)) return c->fn(argc - 1, argv + 1);
    fprintf(stderr, "edgespace: unknown command '%s'\nTry 'edgespace help'.\n", verb);
    return CLI_USAGE;
}
