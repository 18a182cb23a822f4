/* tools/cmd/embed.c — edgespace embed: realize a point of edge-length space
 * (a stored row or a stored point) as a mesh, print and store the quality
 * report (es_embed_solve, es_study_store_embedding). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace embed STORE --point SPEC -o OUT [options]\n"
    "\n"
    "Realize a point of edge-length space as a mesh, print the quality report\n"
    "and store it with per-vertex residuals under /analysis/embed/NAME. Every\n"
    "point is a combination of stored rows; by default the same row weights\n"
    "applied to the rows (GPA-aligned) and their dihedrals give a prior that\n"
    "starts the solve, keeps the surface near the data's bending where the\n"
    "lengths leave it free (open meshes), and puts the output in the store's\n"
    "frame (the first row's pose), so outputs of nearby points overlay.\n"
    "\n"
    "      --point SPEC     row:ID (a stored row's lengths), NAME (a stored point,\n"
    "                       /analysis/point/NAME), or an expression such as\n"
    "                       \"mean[expression=neutral] + diff:smile\" (see\n"
    "                       datasets-spec/point-syntax.md)\n"
    "  -o, --output OUT     mesh file (.obj, .ply, .off)\n"
    "      --pca NAME       the PCA whose components pc:K in SPEC means (needed when\n"
    "                       several are stored and none is named 'default'); or\n"
    "                       name it in SPEC: pc:NAME:K\n"
    "  -i, --init HOW       prior (default, see above); or an explicit start without\n"
    "                       the prior: nearest (the stored row nearest in edge-length\n"
    "                       distance), row:ID, mean or mean[FILTER] as in a point\n"
    "                       (circular mean of the dihedrals of the selected rows;\n"
    "                       mean:FILTER is the old spelling), or mesh:FILE (a mesh with\n"
    "                       the store's face list: its dihedrals, and the output is\n"
    "                       aligned to it)\n"
    "  -s, --scale S        sum of edge lengths of the output (default: the point's\n"
    "                       scale, else the mean scale of the store)\n"
    "  -n, --name NAME      result name in the store (default: the output's base name)\n"
    "      --no-store       do not write the report into the store\n";

/* the help in two strings: one is longer than C99 compilers must accept */
static const char usage2[] =
CLI_EMBED_HELP
    "      --residuals CSV  per vertex of the output: closure energy, mean relative\n"
    "                       edge error and, with the prior, distance from the prior's\n"
    "                       realization / bbox diagonal (header closure,edge_error\n"
    "                       [,deviation]; render MESH --scalars CSV draws the first)\n"
    "  -m, --method M       default (the above) or paper: the published pipeline\n"
    "                       for comparison (L-BFGS on the closure energy from the\n"
    "                       start's dihedrals, frames and positions by least squares,\n"
    "                       no refinement; open meshes too)\n"
    "      --paper          the same as --method paper\n"
    "      --no-cache       neither read nor write STORE.es-cache (the embedder's\n"
    "                       vertex order and the rows made ready for priors, kept\n"
    "                       beside the store so the next command skips them)\n"
    "      --replace        replace a stored result of that name (else refused)\n"
    "      --max-memory SIZE  refuse a mesh whose embedding needs more (default: the\n"
    "                       machine's memory, or $EDGESPACE_MAX_MEMORY; e.g. 8G)\n"
    "  -h, --help           show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_embed(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"point", required_argument, NULL, 'p'}, {"output", required_argument, NULL, 'o'},
        {"init", required_argument, NULL, 'i'},  {"scale", required_argument, NULL, 's'},
        {"name", required_argument, NULL, 'n'},  {"no-store", no_argument, NULL, 'N'},
        {"paper", no_argument, NULL, 'P'},       {"replace", no_argument, NULL, 'X'},
        {"help", no_argument, NULL, 'h'},        CLI_EMBED_LONGOPTS,
        {"residuals", required_argument, NULL, 'r'}, {"pca", required_argument, NULL, 'c'},
        {"no-cache", no_argument, NULL, 'C'},    {"method", required_argument, NULL, 'm'},
        {"max-memory", required_argument, NULL, 'M'}, {NULL, 0, NULL, 0}};
    char namebuf[256], text[1024], *cmd = NULL;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c, e, store_it = 1;
    uint64_t max_memory = 0;
    es_ctx *ctx;
    es_store *s = NULL;
    es_study_embed_opts o;
    es_study_embed_result res;
    es_status rc;
    es_study_embed_opts_init(&o);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "o:i:s:n:m:h", longopts)) != -1) {
        switch (c) {
        case 'p': o.point = optarg; break;
        case 'o': o.output = optarg; break;
        case 'i': o.init = optarg; break;
        case 'r': o.residuals = optarg; break;
        case 'c': o.pca_name = optarg; break;
        case 's':
            if (cli_parse_double(optarg, &o.scale) || !(o.scale > 0))
                return cli_usage_error("embed", "--scale wants a positive number");
            break;
        case 'n': o.name = optarg; break;
        case 'N': store_it = 0; break;
        case 'P': o.paper = 1; break;
        case 'm':
            if (strcmp(optarg, "default") && strcmp(optarg, "paper"))
                return cli_usage_error("embed", "--method wants default or paper");
            o.paper = !strcmp(optarg, "paper");
            break;
        case 'C': o.cache = 0; break;
        case 'X': wmode = ES_STORE_REPLACE; break;
        case 'M':
            if (cli_parse_size(optarg, &max_memory))
                return cli_usage_error("embed", "--max-memory wants a size such as 8G");
            break;
        case 'h':
            fputs(usage, stdout);
            fputs(usage2, stdout);
            return CLI_OK;
        default:
            if ((e = cli_embed_option("embed", c, optarg, &o.embed)) >= 0) {
                if (e) return e;
                break;
            }
            return cli_usage_error("embed", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("embed", "give exactly one STORE");
    if (!o.point || !o.output) return cli_usage_error("embed", "--point and --output are required");
    if (strcmp(o.init, "prior") && strcmp(o.init, "nearest") && strncmp(o.init, "row:", 4) &&
        strncmp(o.init, "mesh:", 5) &&
        !(!strncmp(o.init, "mean", 4) && (o.init[4] == 0 || o.init[4] == ':' || o.init[4] == '[')))
        return cli_usage_error("embed", "--init wants prior, nearest, row:ID, mean[FILTER] or "
                               "mesh:FILE");
    if (!o.name) {
        es_id_from_path(o.output, namebuf, sizeof namebuf);   /* its base name */
        o.name = namebuf;
    }
    if (!(ctx = cli_ctx_new("embed"))) return CLI_FAIL;
    if (max_memory) es_ctx_set_memory_limit(ctx, max_memory);
    if (store_it) o.command = cmd = cli_command_line(argc, argv);
    const char *name = o.name;
    if (!store_it) o.name = NULL;
    if (!(rc = es_store_open(ctx, argv[optind], store_it ? wmode : ES_STORE_READ, &s)))
        rc = es_study_embed(ctx, s, &o, NULL, &res);
    if (!rc && store_it) rc = es_store_commit(ctx, s);   /* the mesh appears with it */
    if (rc) {
        cli_fail("embed", ctx, rc);
        es_store_abort(s);
    } else {
        printf("embedded %s (%s) -> %s\ninit: %s\n%s", o.point, name, o.output, res.init,
               es_embed_report_format(&res.report, text, sizeof text));
        if (o.residuals)
            printf("per-vertex residuals: %s (render --scalars draws the closure)\n", o.residuals);
        if (store_it) printf("stored: /analysis/embed/%s\n", name);
        es_store_close(s);
    }
    free(cmd);
    es_ctx_free(ctx);
    return rc ? CLI_FAIL : CLI_OK;
}
