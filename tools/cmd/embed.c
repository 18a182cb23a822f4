/* tools/cmd/embed.c — edgespace embed: realize a point of edge-length space
 * (a stored row or a stored point) as a mesh, print and store the quality
 * report (es_embed_solve, es_study_store_embedding). */
#include "cli.h"
#include "commands.h"
#include "stats_cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace embed STORE --point SPEC -o OUT [options]\n"
    "\n"
    "Realize a point of edge-length space as a mesh (dihedral solve, frames and\n"
    "positions by sparse least squares, Gauss-Newton refinement of the lengths),\n"
    "print the quality report and store it with per-vertex residuals under\n"
    "/analysis/embed/NAME.\n"
    "\n"
    "  -p, --point SPEC     row:ID (a stored row's lengths), NAME (a stored point,\n"
    "                       /analysis/point/NAME), or an expression such as\n"
    "                       \"mean[expression=neutral] + diff:smile\" (see\n"
    "                       datasets-spec/point-syntax.md)\n"
    "  -o, --output OUT     mesh file (.obj, .ply, .off)\n"
    "      --pca NAME       the PCA whose components pc:K in SPEC means (needed when\n"
    "                       several are stored and none is named 'default')\n"
    "  -i, --init HOW       nearest (default: the stored row nearest in edge-length\n"
    "                       distance), row:ID, mean[:FILTER] (circular mean of the\n"
    "                       dihedrals of the selected rows), or mesh:FILE (a mesh with\n"
    "                       the store's face list: its dihedrals, and the output is\n"
    "                       aligned to it; the previous frame of a walk of points,\n"
    "                       e.g. \"mean + T*pc:1\", keeps the frames from jumping)\n"
    "  -s, --scale S        sum of edge lengths of the output (default: the point's\n"
    "                       scale, else the mean scale of the store)\n"
    "  -n, --name NAME      result name in the store (default: the output's base name)\n"
    "      --no-store       do not write the report into the store\n"
    "      --refine-iters N refinement iterations (default 12; more for accuracy,\n"
    "                       0 for the linear stages only)\n"
    "      --residuals CSV  per-vertex closure energy and mean relative edge error of\n"
    "                       the output (header closure,edge_error; one row per vertex;\n"
    "                       render MESH --scalars CSV draws the closure as a heat map)\n"
    "      --paper          the published method's stages only (stage 1 always, no\n"
    "                       refinement), for comparison\n"
    "  -h, --help           show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

static char *base_name(const char *path, char *buf, size_t n)
{
    const char *b = strrchr(path, '/');
    char *dot;
    snprintf(buf, n, "%s", b ? b + 1 : path);
    if ((dot = strrchr(buf, '.')) && dot != buf) *dot = 0;
    return buf;
}

/* --residuals CSV: per vertex of the output, its vertex-figure closure
 * energy and the mean relative error of its edges; the closure comes first
 * because render --scalars colours by the first column. */
static int write_residuals(const char *path, const es_embedder *emb, int64_t nv)
{
    const double *closure = es_embedder_vertex_closure(emb);
    const double *edge_error = es_embedder_vertex_edge_error(emb);
    FILE *f = stats_csv_open("embed", path);
    if (!f) return 1;
    fputs("closure,edge_error\n", f);
    for (int64_t v = 0; v < nv; v++) fprintf(f, "%.17g,%.17g\n", closure[v], edge_error[v]);
    return stats_csv_close("embed", f, path) ? 1 : 0;
}

int cmd_embed(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"point", required_argument, NULL, 'p'}, {"output", required_argument, NULL, 'o'},
        {"init", required_argument, NULL, 'i'},  {"scale", required_argument, NULL, 's'},
        {"name", required_argument, NULL, 'n'},  {"no-store", no_argument, NULL, 'N'},
        {"paper", no_argument, NULL, 'P'},       {"help", no_argument, NULL, 'h'},
        {"refine-iters", required_argument, NULL, 'R'},
        {"residuals", required_argument, NULL, 'r'}, {"pca", required_argument, NULL, 'c'},
        {NULL, 0, NULL, 0}};
    const char *point = NULL, *out = NULL, *init = "nearest", *name = NULL, *residuals = NULL;
    const char *pca = NULL;
    char namebuf[256], initdesc[512], text[1024];
    double scale = 0, *target = NULL, *xyz = NULL, *init_xyz = NULL, *alpha = NULL;
    int c, store_it = 1, paper = 0;
    int64_t refine_iters;
    es_ctx *ctx;
    es_store *s = NULL;
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    es_embed_opts opts;
    es_embed_report rep;
    es_status rc = ES_OK;
    int64_t ne, nv, initrow = -1, *sel = NULL, nsel = 0;
    es_embed_opts_init(&opts);
    optind = 1;
    while ((c = getopt_long(argc, argv, "p:o:i:s:n:h", longopts, NULL)) != -1) {
        switch (c) {
        case 'p': point = optarg; break;
        case 'o': out = optarg; break;
        case 'i': init = optarg; break;
        case 'r': residuals = optarg; break;
        case 'c': pca = optarg; break;
        case 's':
            if (cli_parse_double(optarg, &scale) || !(scale > 0))
                return cli_usage_error("embed", "--scale wants a positive number");
            break;
        case 'n': name = optarg; break;
        case 'N': store_it = 0; break;
        case 'P': paper = 1; break;
        case 'R':
            if (cli_parse_i64(optarg, &refine_iters) || refine_iters < 0 || refine_iters > 100000)
                return cli_usage_error("embed", "--refine-iters wants a count >= 0");
            opts.refine_max_iter = (int)refine_iters;
            break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("embed", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("embed", "give exactly one STORE");
    if (!point || !out) return cli_usage_error("embed", "--point and --output are required");
    if (!name) name = base_name(out, namebuf, sizeof namebuf);
    if (!(ctx = cli_ctx_new("embed"))) return CLI_FAIL;
    if ((rc = es_store_open(ctx, argv[optind], store_it ? ES_STORE_WRITE : ES_STORE_READ, &s)) ||
        (rc = es_store_mesh(ctx, s, &mesh)))
        goto fail;
    ne = es_mesh_nedges(mesh);
    nv = es_mesh_nverts(mesh);
    target = malloc((size_t)ne * sizeof *target);
    xyz = malloc(3 * (size_t)nv * sizeof *xyz);
    init_xyz = malloc(3 * (size_t)nv * sizeof *init_xyz);
    alpha = malloc((size_t)ne * sizeof *alpha);
    if (!target || !xyz || !init_xyz || !alpha) {
        rc = ES_ENOMEM;
        goto fail;
    }
    /* the target: at the point's own scale unless --scale gives one */
    {
        double own;
        if ((rc = stats_point_lengths("embed", ctx, s, point, pca, ne, target, &own))) goto done;
        if (scale == 0) scale = own;
    }
    /* the initialization */
    if (!strcmp(init, "nearest")) {
        double d;
        if ((rc = es_study_nearest_row(ctx, s, target, NULL, 0, &initrow, &d))) goto fail;
        snprintf(initdesc, sizeof initdesc, "nearest row %s (edge-length distance %.3g)",
                 es_store_row_id(s, initrow), d);
    } else if (!strncmp(init, "row:", 4)) {
        if ((initrow = es_store_find_row(s, init + 4)) < 0) {
            fprintf(stderr, "edgespace embed: no row '%s' in the store\n", init + 4);
            rc = ES_ENOTFOUND;
            goto done;
        }
        snprintf(initdesc, sizeof initdesc, "row %s", init + 4);
    } else if (!strncmp(init, "mean", 4) && (init[4] == 0 || init[4] == ':')) {
        if ((rc = es_store_select(ctx, s, init[4] ? init + 5 : NULL, &sel, &nsel))) goto fail;
        if (nsel == 0) {
            fprintf(stderr, "edgespace embed: --init %s selects no rows\n", init);
            rc = ES_ENOTFOUND;
            goto done;
        }
        if ((rc = es_study_mean_dihedrals(ctx, s, mesh, sel, nsel, alpha))) goto fail;
        initrow = sel[0];
        snprintf(initdesc, sizeof initdesc, "circular mean of dihedrals of %lld rows (%s)",
                 (long long)nsel, init);
    } else if (!strncmp(init, "mesh:", 5)) {
        if ((rc = es_mesh_read_positions(ctx, mesh, init + 5, init_xyz))) goto fail;
        snprintf(initdesc, sizeof initdesc, "mesh %s", init + 5);
    } else {
        rc = ES_EINVAL;
        cli_usage_error("embed", "--init wants nearest, row:ID, mean[:FILTER] or mesh:FILE");
        goto done;
    }
    if (initrow >= 0 && (rc = es_store_read_positions(ctx, s, initrow, init_xyz))) goto fail;
    if (paper) {
        opts.dihedral_mode = ES_EMBED_DIHEDRAL_ON;
        opts.refine_max_iter = 0;
    }
    if ((rc = es_embedder_new(ctx, mesh, &emb)) ||
        (rc = es_embed_solve(ctx, emb, target, scale, sel ? alpha : NULL, init_xyz, &opts, xyz, &rep)) ||
        (rc = es_mesh_write(ctx, out, ES_FORMAT_AUTO, mesh, xyz, NULL)))
        goto fail;
    printf("embedded %s (%s) -> %s\ninit: %s\n%s", point, name, out, initdesc,
           es_embed_report_format(&rep, text, sizeof text));
    if (residuals) {
        if (write_residuals(residuals, emb, nv)) {
            rc = ES_EIO;
            goto done;
        }
        printf("per-vertex residuals: %s (render --scalars draws the closure)\n", residuals);
    }
    if (store_it) {
        /* the rows whose positions started the embedding (none for a mesh:
         * rows non-NULL with 0, as NULL would record every row) */
        es_provenance prov = {NULL, sel ? sel : &initrow, sel ? nsel : initrow >= 0 ? 1 : 0,
                              NULL};
        char *cmd = cli_command_line(argc, argv), params[256];
        snprintf(params, sizeof params, "point=%s; scale=%.17g", point, scale);
        prov.command = cmd ? cmd : "edgespace embed";
        prov.params = params;
        rc = es_study_store_embedding(ctx, s, name, &prov, emb, target, xyz, &rep, initdesc);
        free(cmd);
        if (rc || (rc = es_store_commit(ctx, s)))
            goto fail;
        printf("stored: /analysis/embed/%s\n", name);
    }
    goto done;
fail:
    cli_fail("embed", ctx, rc);
done:
    es_embedder_free(emb);
    es_mesh_free(mesh);
    if (rc) es_store_abort(s);
    else es_store_close(s);
    es_free(ctx, sel);
    free(target), free(xyz), free(init_xyz), free(alpha);
    es_ctx_free(ctx);
    return rc ? CLI_FAIL : CLI_OK;
}
