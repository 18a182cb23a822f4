/* tools/cmd/export.c — edgespace export: a store's rows as a CSV of edge
 * lengths or as mesh files (es_export_lengths_csv, es_export_meshes), or a
 * stored PCA as a statismo shape model (es_study_export_statismo), or a
 * stored result as a labelled table (es_study_export_result). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace export STORE (--lengths CSV | --meshes DIR) [options]\n"
    "       edgespace export STORE --statismo MODEL.h5 [--pca NAME | --gpa NAME]\n"
    "                        [--components K] [--sd C] [--noise-variance V]\n"
    "       edgespace export STORE --result KIND/NAME [--table TABLE] --output PATH\n"
    "\n"
    "Write rows of a store: their edge lengths as CSV (id, scale, then one column\n"
    "per edge named by its 0-based vertex pair 'a-b'), or their positions as they\n"
    "were ingested, one mesh file per row named <id>.<ext>.\n"
    "\n"
    "  -l, --lengths CSV     write normalized edge lengths (rows sum to 1)\n"
    "      --raw             with --lengths: write scale x length instead\n"
    "  -M, --meshes DIR      write meshes into DIR (created if absent)\n"
    "  -f, --format FMT      mesh format: obj (default), ply, ply-ascii, off; stl,\n"
    "                        glb (float32, for viewers and printers)\n"
    "  -w, --where FILTER    only rows matching col=value[,col=value...]\n"
    "                        (--where FILTER, as in the other commands)\n"
    "                        (quote a value holding ',': col=\"a,b\")\n"
    "      --statismo FILE   write a statismo shape model (datasets-spec/statismo.md)\n"
    "                        that statismo and scalismo load: of an edge-length PCA\n"
    "      --pca NAME        (default: the only one, else 'default'), linearized by\n"
    "                        embedding its mean -/+ C sd along each PC; or of the\n"
    "      --gpa NAME        Procrustes PCA of a GPA result (its tangent modes; of a\n"
    "                        landmark store, a POINT_SET model). FILE must end in\n"
    "                        .h5: scalismo opens no other name\n"
    "  -k, --components K    modes to export (default: 10 of a PCA, every PC the GPA\n"
    "                        stored)\n"
    "      --sd C            the step along each PC, in sd (default 1)\n"
    "      --noise-variance V  the model's noise variance (default: 0 for a PCA,\n"
    "                        the PPCA estimate for a GPA)\n"
    "  with --statismo --pca, how the points are embedded:\n"
    CLI_EMBED_HELP
    "  -r, --result KIND/NAME  a stored result (gpa/all, model/m, ...) as a table\n"
    "      --table TABLE     which of its tables (default: the kind's first;\n"
    "                        'attributes' for any result; a wrong name lists them)\n"
    "  -o, --output PATH     where the result's table goes (- for stdout)\n"
    "  -h, --help            show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

/* --statismo: one library call; the report on standard output. */
static int export_statismo(const char *store, const char *path, es_study_statismo_opts *so,
                           int other, int argc, char **argv)
{
    es_study_statismo_report r;
    es_store *s = NULL;
    es_ctx *ctx;
    es_status rc;
    char *cmd;
    if (other) return cli_usage_error("export", "--statismo goes alone (no --lengths, "
                                      "--meshes or --where)");
    if (so->pca_name && so->gpa_name) return cli_usage_error("export", "give --pca or --gpa");
    if (!(ctx = cli_ctx_new("export"))) return CLI_FAIL;
    so->command = cmd = cli_command_line(argc, argv);
    if ((rc = es_store_open(ctx, store, ES_STORE_READ, &s)) == ES_OK)
        rc = es_study_export_statismo(ctx, s, so, path, &r);
    es_store_close(s);
    free(cmd);
    if (rc != ES_OK) {
        cli_fail("export", ctx, rc);
        es_ctx_free(ctx);
        return CLI_FAIL;
    }
    printf("%s: %lld modes of %s, %lld vertices, %lld triangles, noise variance %.6g\n", path,
           (long long)r.ncomp, r.source, (long long)r.nverts, (long long)r.nfaces,
           r.noise_variance);
    if (!so->gpa_name)
        printf("embeddings: worst RMS ratio %.3g, worst bending %.3f x the prior's; "
               "nonlinearity over -/+%g sd %.3g\n", r.worst_rms_ratio, r.worst_bend_ratio,
               so->sd, r.nonlinearity);
    es_ctx_free(ctx);
    return CLI_OK;
}

int cmd_export(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"lengths", required_argument, NULL, 'l'}, {"raw", no_argument, NULL, 'R'},
        {"meshes", required_argument, NULL, 'M'},  {"format", required_argument, NULL, 'f'},
        {"help", no_argument, NULL, 'h'},
        {"statismo", required_argument, NULL, 'S'}, {"pca", required_argument, NULL, 'P'},
        {"gpa", required_argument, NULL, 'G'},      {"components", required_argument, NULL, 'k'},
        {"sd", required_argument, NULL, 'c'}, {"noise-variance", required_argument, NULL, 'n'},
        {"result", required_argument, NULL, 'r'},  {"table", required_argument, NULL, 't'},
        {"output", required_argument, NULL, 'o'},    {"where", required_argument, NULL, 'w'},
        CLI_EMBED_LONGOPTS, {NULL, 0, NULL, 0}};
    const char *lengths = NULL, *meshes = NULL, *filter = NULL, *statismo = NULL;
    const char *result = NULL, *table = NULL, *csv = NULL;
    es_study_statismo_opts so;
    es_mesh_format fmt = ES_FORMAT_OBJ;
    es_store *s = NULL;
    es_ctx *ctx;
    es_status rc;
    int64_t *rows = NULL, nrows = 0;
    int c, e, raw = 0, embed_opts = 0;
    es_study_statismo_opts_init(&so);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "l:M:f:w:r:o:k:h", longopts)) != -1) {
        switch (c) {
        case 'l': lengths = optarg; break;
        case 'R': raw = 1; break;
        case 'M': meshes = optarg; break;
        case 'w': filter = optarg; break;
        case 'r': result = optarg; break;
        case 't': table = optarg; break;
        case 'o': csv = optarg; break;
        case 'f':
            if (!strcmp(optarg, "obj")) fmt = ES_FORMAT_OBJ;
            else if (!strcmp(optarg, "ply")) fmt = ES_FORMAT_PLY;
            else if (!strcmp(optarg, "ply-ascii")) fmt = ES_FORMAT_PLY_ASCII;
            else if (!strcmp(optarg, "off")) fmt = ES_FORMAT_OFF;
            else if (!strcmp(optarg, "stl")) fmt = ES_FORMAT_STL;
            else if (!strcmp(optarg, "glb")) fmt = ES_FORMAT_GLB;
            else return cli_usage_error("export", "unknown format '%s' (obj, ply, ply-ascii, "
                                        "off, stl, glb)", optarg);
            break;
        case 'S': statismo = optarg; break;
        case 'P': so.pca_name = optarg; break;
        case 'G': so.gpa_name = optarg; break;
        case 'k':
            if (cli_parse_i64(optarg, &so.ncomp) || so.ncomp < 1)
                return cli_usage_error("export", "--components wants a count >= 1");
            break;
        case 'c':
            if (cli_parse_double(optarg, &so.sd) || so.sd <= 0)
                return cli_usage_error("export", "--sd wants a number > 0");
            break;
        case 'n':
            if (cli_parse_double(optarg, &so.noise_variance) || so.noise_variance < 0)
                return cli_usage_error("export", "--noise-variance wants a number >= 0");
            break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default:
            if ((e = cli_embed_option("export", c, optarg, &so.embed)) >= 0) {
                if (e) return e;
                embed_opts = 1;
                break;
            }
            return cli_usage_error("export", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("export", "give exactly one STORE");
    if (embed_opts && (!statismo || so.gpa_name))
        return cli_usage_error("export", "--iters, --refine-iters, --fast, --solver and "
                               "--bending go with --statismo of a PCA (its points are "
                               "embedded)");
    if (statismo) return export_statismo(argv[optind], statismo, &so,
                                         filter || lengths || meshes || result, argc, argv);
    if (so.pca_name || so.gpa_name)
        return cli_usage_error("export", "--pca and --gpa go with --statismo");
    if (result) {
        if (lengths || meshes || filter)
            return cli_usage_error("export", "--result goes alone (with --table and --output)");
        if (!csv) return cli_usage_error("export", "--result needs --output PATH (- for stdout)");
    } else if (table || csv) {
        return cli_usage_error("export", "--table and --output go with --result KIND/NAME");
    } else if (!lengths == !meshes)
        return cli_usage_error("export", "give one of --lengths CSV or --meshes DIR");
    if (raw && !lengths) return cli_usage_error("export", "--raw goes with --lengths");
    if (!(ctx = cli_ctx_new("export"))) return CLI_FAIL;
    if ((rc = es_store_open(ctx, argv[optind], ES_STORE_READ, &s)) ||
        (!result && (rc = es_store_select(ctx, s, filter, &rows, &nrows))))
        goto fail;
    if (result) rc = es_study_export_result(ctx, s, result, table, csv);
    else if (lengths) rc = es_export_lengths_csv(ctx, s, rows, nrows, raw, lengths);
    else rc = es_export_meshes(ctx, s, rows, nrows, meshes, fmt);
    if (rc) goto fail;
    es_free(ctx, rows);
    es_store_close(s);
    es_ctx_free(ctx);
    return CLI_OK;
fail:
    cli_fail("export", ctx, rc);
    es_free(ctx, rows);
    es_store_close(s);
    es_ctx_free(ctx);
    return CLI_FAIL;
}
