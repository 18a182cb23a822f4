/* tools/cmd/project.c — edgespace project: scores of stored rows or new mesh
 * files on a stored PCA, with the residual norm (the part of the shape the
 * kept components do not explain). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char usage[] =
    "usage: edgespace project STORE [--pca NAME] [--where FILTER] [--output PATH] [INPUT...]\n"
    "\n"
    "Project shapes onto a stored PCA: each INPUT is a mesh file (.obj, .ply,\n"
    ".off; the store's face list) or a stored row id; --where adds the rows\n"
    "matching a filter. Prints (or writes as CSV) the name, the score on every\n"
    "component and the residual norm |x - mean - U U^T (x - mean)|.\n"
    "\n"
    "  -p, --pca NAME      the PCA (default: the only one, or \"default\")\n"
    "  -w, --where FILTER  also project the stored rows matching FILTER\n"
    "  -o, --output PATH   write name,PC1..PCK,residual as CSV (- for stdout)\n"
    "  -h, --help          show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_project(int argc, char **argv)
{
    static const struct option lo[] = {
        {"pca", required_argument, NULL, 'p'}, {"where", required_argument, NULL, 'w'},
        {"output", required_argument, NULL, 'o'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *pca_name = NULL, *where = NULL, *csv = NULL;
    int c;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "p:w:o:h", lo)) != -1) {
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
    es_study_projection *p = NULL;
    es_status rc = es_store_open(ctx, argv[optind], ES_STORE_READ, &st);
    if (rc == ES_OK)
        rc = es_study_project(ctx, st, pca_name, argc - optind - 1,
                              (const char *const *)argv + optind + 1, where, &p);
    if (rc == ES_OK && csv) {
        rc = es_study_write_projection_table(ctx, p, csv);
    } else if (rc == ES_OK) {   /* a tab-separated table on the terminal */
        printf("name\t");
        for (int64_t k = 0; k < p->ncomp; k++) printf("PC%lld\t", (long long)(k + 1));
        printf("residual\n");
        for (int64_t i = 0; i < p->n; i++) {
            printf("%s\t", p->names[i]);
            for (int64_t k = 0; k < p->ncomp; k++) printf("%.6g\t", p->scores[i + k * p->n]);
            printf("%.6g\n", p->residuals[i]);
        }
    }
    if (rc != ES_OK) cli_fail("project", ctx, rc);
    es_study_projection_free(p);
    es_store_close(st);
    es_ctx_free(ctx);
    return rc == ES_OK ? CLI_OK : CLI_FAIL;
}
