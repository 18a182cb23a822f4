/* tools/cmd/gpa.c — edgespace gpa: generalized Procrustes analysis of a
 * store's vertex positions (es_study_gpa), results in the store. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace gpa STORE --name NAME [options]\n"
    "\n"
    "Generalized Procrustes analysis of the vertex positions (or landmarks) of the\n"
    "rows of STORE, with the PCA of the tangent coordinates; conventions of R's\n"
    "shapes::procGPA. Results go to /analysis/gpa/NAME in the store (aligned\n"
    "configurations, mean, centroid sizes, rho, rotations, scales, PCs) with the\n"
    "options and convergence. Planar data (z = 0) are analysed in 2D. Under\n"
    "mpirun -n P (the MPI build) each rank reads and aligns a share of the rows.\n"
    "\n"
    "  -n, --name NAME         result name (required)\n"
    "      --no-scale          partial GPA: rotation and translation only\n"
    "      --allow-reflection  allow reflections in the rotations\n"
    "  -w, --where FILTER      rows whose labels match col=value[,col=value...]\n"
    "                          (quote a value holding ',': col=\"a,b\")\n"
    "      --tol T             convergence tolerance (default 1e-10)\n"
    "      --max-iter N        iteration limit (default 1000)\n"
    "  -k, --components N      principal components stored (default min(10, n-1))\n"
    "  -q, --quiet             print nothing on success\n"
    "      --replace           replace a stored result of that name (else refused)\n"
    "  -h, --help              show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_gpa(int argc, char **argv)
{
    enum { O_NOSCALE = 256, O_REFLECT, O_TOL, O_MAXIT };
    static const struct option longopts[] = {
        {"name", required_argument, NULL, 'n'},   {"no-scale", no_argument, NULL, O_NOSCALE},
        {"allow-reflection", no_argument, NULL, O_REFLECT},
        {"where", required_argument, NULL, 'w'},  {"tol", required_argument, NULL, O_TOL},
        {"max-iter", required_argument, NULL, O_MAXIT},
        {"components", required_argument, NULL, 'k'},  {"quiet", no_argument, NULL, 'q'},
        {"replace", no_argument, NULL, 'R'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *name = NULL, *where = NULL;
    es_gpa_opts o;
    int64_t npc = 0;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c, quiet = 0;
    es_gpa_opts_init(&o);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "n:w:k:qh", longopts)) != -1) {
        switch (c) {
        case 'n': name = optarg; break;
        case 'w': where = optarg; break;
        case O_NOSCALE: o.scale = 0; break;
        case O_REFLECT: o.allow_reflection = 1; break;
        case O_TOL:
            if (cli_parse_double(optarg, &o.tol) || !(o.tol >= 0))
                return cli_usage_error("gpa", "bad --tol '%s'", optarg);
            break;
        case O_MAXIT:
            if (cli_parse_i64(optarg, &o.max_iter) || o.max_iter < 1)
                return cli_usage_error("gpa", "bad --max-iter '%s'", optarg);
            break;
        case 'k':
            if (cli_parse_i64(optarg, &npc) || npc < 1)
                return cli_usage_error("gpa", "bad --components '%s'", optarg);
            break;
        case 'q': quiet = 1; break;
        case 'R': wmode = ES_STORE_REPLACE; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("gpa", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("gpa", "give exactly one STORE");
    if (!name || !*name) return cli_usage_error("gpa", "missing --name");
    es_ctx *ctx = cli_ctx_new("gpa");
    if (!ctx) return CLI_FAIL;
    es_store *s = NULL;
    int64_t *rows = NULL, nrows = -1;
    es_gpa_report rep;
    char *cmd = cli_command_line(argc, argv);
    /* on the ranks of an MPI job every rank reads and aligns its share of
     * the rows, rank 0 alone writes; a refusal before the fit (a taken
     * name) and the outcome are agreed on by all */
    const int writer = es_parallel_rank(ctx) == 0;
    es_status rc = es_store_open(ctx, argv[optind], writer ? wmode : ES_STORE_READ, &s);
    if (rc == ES_OK && where && *where) rc = es_store_select(ctx, s, where, &rows, &nrows);
    if (rc == ES_OK && writer) rc = es_store_result_check(ctx, s, "gpa", name);
    rc = es_parallel_agree(ctx, rc);
    es_study_gpa_opts so;
    es_study_gpa_opts_init(&so);
    so.name = writer ? name : NULL;
    so.rows = rows;
    so.nrows = nrows;
    so.gpa = o;
    so.npc = npc;
    so.command = cmd;
    if (rc == ES_OK) rc = es_study_gpa(ctx, s, &so, &rep);
    if (rc == ES_OK && writer) rc = es_store_commit(ctx, s);
    rc = es_parallel_agree(ctx, rc);
    if (rc != ES_OK) {
        cli_fail("gpa", ctx, rc);
        es_store_abort(s);
    } else {
        if (!quiet) {
            char buf[64] = "";
            char path[512];
            snprintf(path, sizeof path, "gpa/%s", name);
            es_store_get_attr(ctx, s, path, "dim", buf, sizeof buf);
            printf("gpa '%s': %lld rows, %sD, %s GPA%s: %lld iterations (%s), rmsrho %.6g, "
                   "GSS %.6g\n", name, (long long)(nrows < 0 ? es_store_nrows(s) : nrows), buf,
                   o.scale ? "full" : "partial", o.allow_reflection ? " with reflection" : "",
                   (long long)rep.iterations, rep.converged ? "converged" : "NOT converged",
                   rep.rmsrho, rep.gss);
            double *pct = NULL;
            int64_t np = 0;
            /* centroid size: the data-unit scale; rho: unit-size shape distance */
            double *cs = NULL;
            int64_t ncs = 0;
            snprintf(path, sizeof path, "gpa/%s/size", name);
            if (es_store_get_vector(ctx, s, path, &cs, &ncs) == ES_OK && ncs > 0) {
                double sum = 0;
                for (int64_t i = 0; i < ncs; i++) sum += cs[i];
                printf("mean centroid size %.6g (data units); rho to the mean: rms %.6g rad\n",
                       sum / (double)ncs, rep.rmsrho);
            }
            es_free(ctx, cs);
            snprintf(path, sizeof path, "gpa/%s/pc_percent", name);
            if (es_store_get_vector(ctx, s, path, &pct, &np) == ES_OK) {
                printf("PC variance (%%):");
                for (int64_t i = 0; i < np; i++) printf(" %.2f", pct[i]);
                printf("\n");
                es_free(ctx, pct);
            }
        }
        es_store_close(s);
    }
    es_free(ctx, rows);
    free(cmd);
    es_ctx_free(ctx);
    return rc == ES_OK ? CLI_OK : CLI_FAIL;
}
