/* tools/cmd/compare.c — edgespace compare: Procrustes space against
 * scale-normalized edge-length space on a store's rows (es_study_compare). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace compare STORE --gpa NAME [--by COLUMN] [-o DIR] [options]\n"
    "\n"
    "Compare the Procrustes distances of a GPA result (edgespace gpa) with the\n"
    "distances of the same rows in scale-normalized edge-length space: Spearman\n"
    "rank correlation with a Mantel permutation test, nearest-neighbour agreement,\n"
    "the pairs the spaces disagree on most, and with --by the distances between\n"
    "group means in both spaces with permutation p-values and an F test.\n"
    "Results go to /analysis/compare/NAME in the store; -o DIR writes CSV files\n"
    "and figures (heat maps of the edge-length, Procrustes and Riemannian rho\n"
    "distances, rows ordered by --by's groups, and a scatter of distance pairs).\n"
    "\n"
    "  -g, --gpa NAME          GPA result to use (required)\n"
    "  -b, --by COLUMN         label column defining groups\n"
    "      --permutations N    permutations of the tests (default 999)\n"
    "  -o, --output DIR        write CSV files and figures to DIR\n"
    "      --name NAME         result name (default: the GPA name)\n"
    "      --top N             disagreeing pairs reported (default 20)\n"
    "      --figures FMT       figure format: svg (default), png or pdf\n"
    "      --no-figures        CSV files only\n"
    "      --seed S            seed of the permutations (default the library's)\n"
    "  -q, --quiet             print nothing on success\n"
    "      --replace           replace a stored result of that name (else refused)\n"
    "  -h, --help              show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of the upper triangle of an n x n matrix (NaN when n < 2 or out
 * of memory: a figure of the report, not of the study). */
static double upper_median(int64_t n, const double *d)
{
    int64_t m = n * (n - 1) / 2, t = 0;
    double *v = m > 0 ? malloc((size_t)m * sizeof *v) : NULL, med = NAN;
    if (!v) return med;
    for (int64_t j = 1; j < n; j++)
        for (int64_t i = 0; i < j; i++) v[t++] = d[i + j * n];
    qsort(v, (size_t)m, sizeof *v, cmp_double);
    med = m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
    free(v);
    return med;
}

int cmd_compare(int argc, char **argv)
{
    enum { O_NAME = 256, O_TOP, O_NOFIG, O_SEED, O_FIGFMT };
    static const struct option longopts[] = {
        {"gpa", required_argument, NULL, 'g'},     {"by", required_argument, NULL, 'b'},
        {"permutations", required_argument, NULL, 'p'},
        {"output", required_argument, NULL, 'o'},  {"name", required_argument, NULL, O_NAME},
        {"top", required_argument, NULL, O_TOP},   {"no-figures", no_argument, NULL, O_NOFIG},
        {"figures", required_argument, NULL, O_FIGFMT},
        {"seed", required_argument, NULL, O_SEED}, {"quiet", no_argument, NULL, 'q'},
        {"replace", no_argument, NULL, 'R'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *gpa = NULL, *by = NULL, *out = NULL, *name = NULL, *format = "svg";
    es_compare_opts o;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c, quiet = 0, figures = 1, have_seed = 0;
    int64_t seed = 0;
    es_compare_opts_init(&o);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "g:b:o:qh", longopts)) != -1) {
        switch (c) {
        case 'g': gpa = optarg; break;
        case 'b': by = optarg; break;
        case 'o': out = optarg; break;
        case O_NAME: name = optarg; break;
        case 'p':
            if (cli_parse_i64(optarg, &o.permutations) || o.permutations < 0 ||
                o.permutations > ES_MAX_PERMUTATIONS)
                return cli_usage_error("compare", "bad --permutations '%s' (0 to %d)", optarg,
                                       ES_MAX_PERMUTATIONS);
            break;
        case O_TOP:
            if (cli_parse_i64(optarg, &o.top_pairs) || o.top_pairs < 0)
                return cli_usage_error("compare", "bad --top '%s'", optarg);
            break;
        case O_NOFIG: figures = 0; break;
        case O_FIGFMT:
            if (strcmp(optarg, "svg") && strcmp(optarg, "png") && strcmp(optarg, "pdf"))
                return cli_usage_error("compare", "bad --figures '%s' (svg, png or pdf)", optarg);
            format = optarg;
            break;
        case O_SEED:
            if (cli_parse_i64(optarg, &seed)) return cli_usage_error("compare", "bad --seed '%s'", optarg);
            have_seed = 1;
            break;
        case 'q': quiet = 1; break;
        case 'R': wmode = ES_STORE_REPLACE; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("compare", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("compare", "give exactly one STORE");
    if (!gpa || !*gpa) return cli_usage_error("compare", "missing --gpa NAME");
    es_ctx *ctx = cli_ctx_new("compare");
    if (!ctx) return CLI_FAIL;
    if (have_seed) es_ctx_set_seed(ctx, (uint64_t)seed);
    es_store *s = NULL;
    es_compare_result *r = NULL;
    char *cmd = cli_command_line(argc, argv);
    es_study_compare_opts so;
    es_study_compare_opts_init(&so);
    so.gpa_name = gpa;
    so.by = by;
    so.compare = o;
    /* stored as its GPA's name unless --name says (--name "": not stored) */
    so.name = !name ? gpa : *name ? name : NULL;
    so.out_dir = out;
    so.command = cmd;
    es_status rc = es_store_open(ctx, argv[optind], wmode, &s);
#if ES_HAVE_FIGURES
    if (rc == ES_OK && figures)
        rc = es_figure_compare(ctx, s, &so, format, &r);
    else
#else
    (void)figures;   /* a build without figures writes the tables only */
    (void)format;
#endif
    if (rc == ES_OK)
        rc = es_study_compare(ctx, s, &so, &r);
    if (rc == ES_OK) rc = es_store_commit(ctx, s);
    if (rc != ES_OK) {
        cli_fail("compare", ctx, rc);
        es_store_abort(s);
    } else {
        if (!quiet) {
            printf("compare '%s': %lld shapes; Spearman rho %.4f (Mantel p %.4g, %lld "
                   "permutations); nearest-neighbour agreement %.3f\n", name ? name : gpa,
                   (long long)r->n, r->mantel_rho, r->mantel_p, (long long)o.permutations,
                   r->nn_agreement);
            if (r->ngroups > 0)
                printf("groups by '%s': edge lengths F %.4g (p %.4g, R2 %.3f); Procrustes F "
                       "%.4g (p %.4g, R2 %.3f)\n", by, r->groups_len.f, r->groups_len.p,
                       r->groups_len.r2, r->groups_proc.f, r->groups_proc.p, r->groups_proc.r2);
            if (r->d_rho)   /* the data-unit figures beside Kendall's rho (unit size) */
                printf("Procrustes distances: median %.4g data units, median rho %.4g rad "
                       "(Riemannian, unit centroid size)\n", upper_median(r->n, r->d_proc),
                       upper_median(r->n, r->d_rho));
            if (out) printf("outputs in %s\n", out);
        }
        es_store_close(s);
    }
    es_compare_result_free(r);
    free(cmd);
    es_ctx_free(ctx);
    return rc == ES_OK ? CLI_OK : CLI_FAIL;
}
