/* tools/cmd/pca.c — edgespace pca: principal components of the normalized
 * edge lengths (Section 4 of Fisher et al.), stored as /analysis/pca/NAME,
 * with CSV exports of scores (with every label column), eigenvalues and
 * components. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace pca STORE [--name NAME] [--where FILTER] [--components K]\n"
    "                     [--method auto|gram|covariance|randomized] [--output PREFIX]\n"
    "\n"
    "PCA of the scale-normalized edge lengths of the rows of STORE (or of the\n"
    "rows matching FILTER). Eigenvalues use the divisor N-1; each component is\n"
    "a unit vector whose largest-magnitude entry is positive. The Gram route\n"
    "(N <= E) never forms the E x E covariance. Stored as /analysis/pca/NAME.\n"
    "\n"
    "  -n, --name NAME        result name (default: \"default\")\n"
    "  -w, --where FILTER     only rows matching \"col=value[,col=value...]\"\n"
    "                         (quote a value holding ',': col=\"a,b\")\n"
    "  -k, --components K     keep the top K, fewer if the numerical rank is lower\n"
    "                         (default: all, the numerical rank)\n"
    "  -m, --method M         auto (default), gram, covariance, or randomized\n"
    "                         (top K by randomized subspace iteration; needs -k)\n"
    "      --oversample P     randomized: extra sample vectors (10)\n"
    "      --power-iters Q    randomized: subspace iterations (4)\n"
    "      --seed S           seed of the randomized method\n"
    "  -o, --output PREFIX    write PREFIX_scores.csv (id, every label, PC1..PCK),\n"
    "                         PREFIX_eigenvalues.csv and PREFIX_components.csv\n"
    "      --replace          replace a stored result of that name (else refused)\n"
    "  -h, --help             show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_pca(int argc, char **argv)
{
    static const struct option lo[] = {
        {"name", required_argument, NULL, 'n'}, {"where", required_argument, NULL, 'w'},
        {"components", required_argument, NULL, 'k'}, {"method", required_argument, NULL, 'm'},
        {"oversample", required_argument, NULL, 'p'}, {"power-iters", required_argument, NULL, 'q'},
        {"seed", required_argument, NULL, 's'}, {"output", required_argument, NULL, 'o'},
        {"replace", no_argument, NULL, 'R'}, {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    const char *name = "default", *where = NULL, *csv = NULL;
    es_pca_opts o;
    es_pca_opts_init(&o);
    int64_t seed = -1;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "n:w:k:m:o:h", lo)) != -1) {
        switch (c) {
        case 'n': name = optarg; break;
        case 'w': where = optarg; break;
        case 'o': csv = optarg; break;
        case 'k':
            if (cli_parse_i64(optarg, &o.ncomp) || o.ncomp < 1)
                return cli_usage_error("pca", "--components wants a positive integer");
            break;
        case 'p':
            if (cli_parse_i64(optarg, &o.oversample) || o.oversample < 0)
                return cli_usage_error("pca", "--oversample wants an integer >= 0");
            break;
        case 'q':
            if (cli_parse_i64(optarg, &o.power_iters) || o.power_iters < 0)
                return cli_usage_error("pca", "--power-iters wants an integer >= 0");
            break;
        case 's':
            if (cli_parse_i64(optarg, &seed) || seed < 0)
                return cli_usage_error("pca", "--seed wants an integer >= 0");
            break;
        case 'm':
            if (!strcmp(optarg, "auto")) o.method = ES_PCA_AUTO;
            else if (!strcmp(optarg, "gram")) o.method = ES_PCA_GRAM;
            else if (!strcmp(optarg, "covariance")) o.method = ES_PCA_COVARIANCE;
            else if (!strcmp(optarg, "randomized")) o.method = ES_PCA_RANDOMIZED;
            else return cli_usage_error("pca", "unknown method '%s'", optarg);
            break;
        case 'R': wmode = ES_STORE_REPLACE; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("pca", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("pca", "give exactly one STORE");
    if (o.method == ES_PCA_RANDOMIZED && o.ncomp < 1)
        return cli_usage_error("pca", "--method randomized needs --components K");
    es_ctx *ctx = cli_ctx_new("pca");
    if (!ctx) return CLI_FAIL;
    if (seed >= 0) es_ctx_set_seed(ctx, (uint64_t)seed);
    char *cmdline = cli_command_line(argc, argv);
    es_store *st = NULL;
    es_pca *p = NULL;
    int64_t *rows = NULL, nrows = 0;
    int ret = CLI_FAIL;
    /* on the ranks of an MPI job every rank reads and fits (collectively),
     * rank 0 alone writes; a refusal before the fit is agreed on by all */
    const int writer = es_parallel_rank(ctx) == 0;
    es_status rc = es_store_open(ctx, argv[optind], writer ? wmode : ES_STORE_READ, &st);
    if (rc == ES_OK && writer) rc = es_store_result_check(ctx, st, "pca", name);
    rc = es_parallel_agree(ctx, rc);
    es_study_pca_opts so;
    es_study_pca_opts_init(&so);
    so.name = writer ? name : NULL;
    so.where = where;
    so.pca = o;
    so.command = cmdline;
    if (rc == ES_OK) rc = es_study_pca(ctx, st, &so, &p, &rows, &nrows);
    if (rc != ES_OK) {
        cli_fail("pca", ctx, rc);
        goto done;
    }
    static const char *const mn[] = {"auto", "gram", "covariance", "randomized"};
    printf("PCA '%s': %lld rows x %lld edges, %lld components (%s route), total variance %.6g\n",
           name, (long long)p->nrows, (long long)p->nedges, (long long)p->ncomp,
           mn[p->method], p->total_variance);
    double cum = 0;
    for (int64_t k = 0; k < p->ncomp && k < 10; k++) {
        cum += p->explained[k];
        printf("  PC%-3lld eigenvalue %.6g  explained %6.2f%%  cumulative %6.2f%%\n",
               (long long)(k + 1), p->eigenvalues[k], 100 * p->explained[k], 100 * cum);
    }
    if (p->ncomp > 10) printf("  ... (%lld more)\n", (long long)(p->ncomp - 10));
    /* the tables first: a failure leaves the store as it was */
    if (writer && ((csv && (rc = es_study_write_pca_tables(ctx, st, p, rows, csv)) != ES_OK) ||
                   (rc = es_store_commit(ctx, st)) != ES_OK)) {
        cli_fail("pca", ctx, rc);
        goto done;
    }
    printf("stored as /analysis/pca/%s\n", name);
    ret = CLI_OK;
done:
    es_pca_free(p);
    es_free(ctx, rows);
    if (ret == CLI_OK) es_store_close(st);
    else es_store_abort(st);   /* leave the store as it was */
    free(cmdline);
    es_ctx_free(ctx);
    return ret;
}
