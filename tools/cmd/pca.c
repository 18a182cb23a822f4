/* tools/cmd/pca.c — edgespace pca: principal components of the normalized
 * edge lengths (Section 4 of Fisher et al.), stored as /analysis/pca/NAME,
 * with CSV exports of scores (with every label column), eigenvalues and
 * components. */
#include "cli.h"
#include "commands.h"
#include "stats_cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace pca STORE [--name NAME] [--where FILTER] [--components K]\n"
    "                     [--method auto|gram|covariance|randomized] [--csv PREFIX]\n"
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
    "  -o, --csv PREFIX       write PREFIX_scores.csv (id, every label, PC1..PCK),\n"
    "                         PREFIX_eigenvalues.csv and PREFIX_components.csv\n"
    "  -h, --help             show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

static int write_csvs(es_ctx *ctx, es_store *st, const es_pca *p, const int64_t *rows,
                      const char *prefix)
{
    size_t n = strlen(prefix) + 32;
    char *path = malloc(n);
    int ret = CLI_FAIL;
    if (!path) return CLI_FAIL;
    const int64_t N = p->nrows, K = p->ncomp, ncols = es_store_ncolumns(st);
    /* scores */
    snprintf(path, n, "%s_scores.csv", prefix);
    FILE *f = stats_csv_open("pca", path);
    if (!f) goto done;
    stats_csv_field(f, "id", 1);
    for (int64_t c = 0; c < ncols; c++) stats_csv_field(f, es_store_column_name(st, c), 0);
    for (int64_t k = 0; k < K; k++) fprintf(f, ",PC%lld", (long long)(k + 1));
    fputc('\n', f);
    for (int64_t i = 0; i < N; i++) {
        stats_csv_field(f, es_store_row_id(st, rows[i]), 1);
        for (int64_t c = 0; c < ncols; c++) stats_csv_field(f, es_store_label(st, rows[i], c), 0);
        for (int64_t k = 0; k < K; k++) stats_csv_number(f, p->scores[i + k * N]);
        fputc('\n', f);
    }
    if (stats_csv_close("pca", f, path)) goto done;
    /* eigenvalues */
    snprintf(path, n, "%s_eigenvalues.csv", prefix);
    if (!(f = stats_csv_open("pca", path))) goto done;
    fputs("component,eigenvalue,explained,cumulative\n", f);
    double cum = 0;
    for (int64_t k = 0; k < K; k++) {
        cum += p->explained[k];
        fprintf(f, "%lld", (long long)(k + 1));
        stats_csv_number(f, p->eigenvalues[k]);
        stats_csv_number(f, p->explained[k]);
        stats_csv_number(f, cum);
        fputc('\n', f);
    }
    if (stats_csv_close("pca", f, path)) goto done;
    /* components: mean then PC1..PCK per edge */
    snprintf(path, n, "%s_components.csv", prefix);
    {
        const int64_t E = p->nedges;
        double *vals = malloc((size_t)(E * (K + 1)) * sizeof *vals);
        char **names = calloc((size_t)K + 1, sizeof *names);
        if (!vals || !names) {
            free(vals);
            free(names);
            fprintf(stderr, "edgespace pca: out of memory\n");
            goto done;
        }
        memcpy(vals, p->mean, (size_t)E * sizeof *vals);
        memcpy(vals + E, p->components, (size_t)(E * K) * sizeof *vals);
        names[0] = strdup("mean");
        for (int64_t k = 0; k < K; k++) {
            names[k + 1] = malloc(24);
            if (names[k + 1]) snprintf(names[k + 1], 24, "PC%lld", (long long)(k + 1));
        }
        ret = stats_write_edge_csv("pca", ctx, st, path, K + 1, (const char *const *)names, vals);
        for (int64_t k = 0; k <= K; k++) free(names[k]);
        free(names);
        free(vals);
    }
done:
    free(path);
    return ret;
}

int cmd_pca(int argc, char **argv)
{
    static const struct option lo[] = {
        {"name", required_argument, NULL, 'n'}, {"where", required_argument, NULL, 'w'},
        {"components", required_argument, NULL, 'k'}, {"method", required_argument, NULL, 'm'},
        {"oversample", required_argument, NULL, 'p'}, {"power-iters", required_argument, NULL, 'q'},
        {"seed", required_argument, NULL, 's'}, {"csv", required_argument, NULL, 'o'},
        {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    const char *name = "default", *where = NULL, *csv = NULL;
    es_pca_opts o;
    es_pca_opts_init(&o);
    int64_t seed = -1;
    int c;
    optind = 1;
    while ((c = getopt_long(argc, argv, "n:w:k:m:o:h", lo, NULL)) != -1) {
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
    es_status rc = es_store_open(ctx, argv[optind], ES_STORE_WRITE, &st);
    if (rc == ES_OK) rc = es_study_pca(ctx, st, name, where, &o, cmdline, &p, &rows, &nrows);
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
    if ((rc = es_store_commit(ctx, st)) != ES_OK) {
        cli_fail("pca", ctx, rc);
        goto done;
    }
    printf("stored as /analysis/pca/%s\n", name);
    ret = csv ? write_csvs(ctx, st, p, rows, csv) : CLI_OK;
done:
    es_pca_free(p);
    es_free(ctx, rows);
    if (ret == CLI_OK) es_store_close(st);
    else es_store_abort(st);   /* leave the store as it was */
    free(cmdline);
    es_ctx_free(ctx);
    return ret;
}
