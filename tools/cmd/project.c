/* tools/cmd/project.c — edgespace project: scores of stored rows or new mesh
 * files on a stored PCA, with the residual norm (the part of the shape the
 * kept components do not explain). */
#include "cli.h"
#include "commands.h"
#include "stats_cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char usage[] =
    "usage: edgespace project STORE [--pca NAME] [--where FILTER] [--csv PATH] [INPUT...]\n"
    "\n"
    "Project shapes onto a stored PCA: each INPUT is a mesh file (.obj, .ply,\n"
    ".off; the store's face list) or a stored row id; --where adds the rows\n"
    "matching a filter. Prints (or writes as CSV) the name, the score on every\n"
    "component and the residual norm |x - mean - U U^T (x - mean)|.\n"
    "\n"
    "  -p, --pca NAME      the PCA (default: the only one, or \"default\")\n"
    "  -w, --where FILTER  also project the stored rows matching FILTER\n"
    "  -o, --csv PATH      write name,PC1..PCK,residual as CSV (- for stdout)\n"
    "  -h, --help          show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

static int is_mesh_path(const char *s)
{
    size_t n = strlen(s);
    return n > 4 && (!strcasecmp(s + n - 4, ".obj") || !strcasecmp(s + n - 4, ".ply") ||
                     !strcasecmp(s + n - 4, ".off"));
}

int cmd_project(int argc, char **argv)
{
    static const struct option lo[] = {
        {"pca", required_argument, NULL, 'p'}, {"where", required_argument, NULL, 'w'},
        {"csv", required_argument, NULL, 'o'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *pca_name = NULL, *where = NULL, *csv = NULL;
    int c;
    optind = 1;
    while ((c = getopt_long(argc, argv, "p:w:o:h", lo, NULL)) != -1) {
        switch (c) {
        case 'p': pca_name = optarg; break;
        case 'w': where = optarg; break;
        case 'o': csv = optarg; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("project", "bad option");
        }
    }
    if (optind > argc - 1) return cli_usage_error("project", "give a STORE");
    if (optind == argc - 1 && !where)
        return cli_usage_error("project", "give mesh files, row ids or --where");
    es_ctx *ctx = cli_ctx_new("project");
    if (!ctx) return CLI_FAIL;
    es_store *st = NULL;
    es_pca *p = NULL;
    es_mesh *mesh = NULL;
    int64_t *rows = NULL, nrows = 0;
    double *x = NULL, *scores = NULL;
    FILE *f = NULL;
    int ret = CLI_FAIL;
    es_status rc;
    if ((rc = es_store_open(ctx, argv[optind], ES_STORE_READ, &st)) != ES_OK ||
        (rc = es_study_pca_load(ctx, st, pca_name, &p, NULL, NULL)) != ES_OK ||
        /* rows of a truss store project without a mesh; files need its faces */
        (es_store_nfaces(st) > 0 && (rc = es_store_mesh(ctx, st, &mesh)) != ES_OK) ||
        (where && (rc = es_store_select(ctx, st, where, &rows, &nrows)) != ES_OK)) {
        cli_fail("project", ctx, rc);
        goto done;
    }
    const int64_t E = p->nedges, K = p->ncomp;
    x = malloc((size_t)E * sizeof *x);
    scores = malloc((size_t)(K > 0 ? K : 1) * sizeof *scores);
    if (!x || !scores) {
        fprintf(stderr, "edgespace project: out of memory\n");
        goto done;
    }
    f = csv ? stats_csv_open("project", csv) : stdout;
    if (!f) goto done;
    fputs(csv ? "name" : "name\t", f);
    for (int64_t k = 0; k < K; k++) fprintf(f, csv ? ",PC%lld" : "PC%lld\t", (long long)(k + 1));
    fputs(csv ? ",residual\n" : "residual\n", f);
    int64_t ninputs = (argc - optind - 1) + nrows;
    for (int64_t i = 0; i < ninputs; i++) {
        const char *in;
        double scale, res;
        if (i < argc - optind - 1) {
            in = argv[optind + 1 + i];
            if (is_mesh_path(in)) {
                rc = mesh ? es_lengths_from_file(ctx, mesh, in, x, &scale)
                          : es_store_mesh(ctx, st, &mesh);   /* fails: says why */
            } else {
                int64_t row = es_store_find_row(st, in);
                if (row < 0) {
                    fprintf(stderr, "edgespace project: '%s' is neither a mesh file (.obj, "
                            ".ply, .off) nor a row id of the store\n", in);
                    goto done;
                }
                rc = es_store_read_lengths(ctx, st, row, 1, (es_mat){x, E, 1, E});
            }
        } else {
            int64_t row = rows[i - (argc - optind - 1)];
            in = es_store_row_id(st, row);
            rc = es_store_read_lengths(ctx, st, row, 1, (es_mat){x, E, 1, E});
        }
        if (rc == ES_OK) rc = es_pca_project(ctx, p, (es_mat){x, E, 1, E}, scores, &res);
        if (rc != ES_OK) {
            cli_fail("project", ctx, rc);
            goto done;
        }
        if (csv) {
            stats_csv_field(f, in, 1);
            for (int64_t k = 0; k < K; k++) stats_csv_number(f, scores[k]);
            stats_csv_number(f, res);
        } else {
            fprintf(f, "%s\t", in);
            for (int64_t k = 0; k < K; k++) fprintf(f, "%.6g\t", scores[k]);
            fprintf(f, "%.6g", res);
        }
        fputc('\n', f);
    }
    ret = CLI_OK;
done:
    if (f && csv && stats_csv_close("project", f, csv)) ret = CLI_FAIL;
    /* A failed run leaves no partial table behind. */
    if (f && csv && ret != CLI_OK && strcmp(csv, "-")) remove(csv);
    free(x);
    free(scores);
    es_free(ctx, rows);
    es_mesh_free(mesh);
    es_pca_free(p);
    es_store_close(st);
    es_ctx_free(ctx);
    return ret;
}
