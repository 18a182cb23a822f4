/* tools/cmd/model.c — edgespace model: a linear model of the shapes on label
 * columns with permutation tests (es_study_model), in edge-length space or
 * on a GPA result's coordinates; prints the ANOVA table, stores
 * /analysis/model/NAME, writes the table as CSV and the per-edge heat map. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace model STORE FORMULA [options]\n"
    "\n"
    "Fit FORMULA (\"~ expression + subject\", \"~ log(size) * species\") to the shapes\n"
    "of STORE and test every term by permutation, with RRPP's effect size Z\n"
    "(model/<name> in datasets-spec/analysis-results.md). Variables are label\n"
    "columns: numeric when every value is a number, factor(COL) to make one\n"
    "categorical, log(COL); size is each row's size (scale, or centroid size with\n"
    "--gpa) unless a label column has that name. Terms join as in R: a:b, a*b =\n"
    "a + b + a:b, a/b = a + a:b (b nested in a; (a+b)/c = a + b + a:b:c), b %in% a =\n"
    "b:a. A term that duplicates earlier ones is left out with a warning.\n"
    "\n"
    "  -g, --gpa NAME         model the coordinates of GPA result NAME (Procrustes\n"
    "                         space) instead of the normalized edge lengths\n"
    "  -w, --where FILTER     only rows matching col=value[,col=value...]\n"
    "      --block COLUMN     permute only within the values of COLUMN (repeated\n"
    "                         measures: the subject)\n"
    "      --type I|II|III    sums of squares: sequential (I, default), each term\n"
    "                         after those not containing it (II), after all (III)\n"
    "      --permute rrpp|raw residuals of each term's reduced model (rrpp, default:\n"
    "                         geomorph, RRPP) or the rows themselves (raw: adonis2)\n"
    "      --permutations N   permutations (999; 0: no p-values)\n"
    "      --contrasts treatment|sum   factor coding (treatment)\n"
    "      --reference LEVELS the baseline level: LEVEL or FACTOR=LEVEL, comma-separated\n"
    "                         (default: the first level in byte order)\n"
    "      --error TERM=ERROR test TERM over ERROR's mean square (nested designs:\n"
    "                         \"~ population/colony\" --error\n"
    "                         population=population:colony); repeatable\n"
    "      --null FORMULA     compare the model with this nested one (RRPP's anova)\n"
    "      --pairwise FACTOR  compare the least-squares means of FACTOR's levels\n"
    "      --slopes VAR       with --pairwise: compare the levels' slopes on VAR\n"
    "                         instead (\"log(size)\"; the model needs VAR * FACTOR)\n"
    "      --at NAME=VALUE    LS means at VALUE (a number or mean) of a numeric\n"
    "                         variable (\"log(size)=mean\", the default) or of the\n"
    "                         column a log() reads (\"size=mean\": log of mean size)\n"
    "      --edges TERM       per-edge F of TERM with permutation p and FDR q values\n"
    "                         (with --gpa: per landmark, its coordinates together)\n"
    "      --edge-permutations N       for --edges (default: --permutations)\n"
    "      --seed S           seed of the permutations (default: the library's)\n"
    "  -n, --name NAME        result name (default: model)\n"
    "      --no-store         leave the store unchanged\n"
    "      --replace          replace a stored result of that name (else refused)\n"
    "  -o, --output PATH      write the ANOVA table as CSV (- for stdout); with\n"
    "                         --pairwise the pairwise table goes to PATH's stem +\n"
    "                         .pairwise.csv (after a blank line for -)\n"
    "      --figure PATH      with --edges: the F of every edge with q < 0.05 on the\n"
    "                         mean mesh (log colour scale), the others grey\n"
    "  -h, --help             show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

enum { O_PERMUTE = 256, O_CONTRASTS, O_PAIRWISE, O_EDGES, O_EDGE_PERM, O_SEED, O_NOSTORE,
       O_REFERENCE, O_ERROR, O_NULL, O_SLOPES, O_AT, MAX_ERRORS = 32 };

int cmd_model(int argc, char **argv)
{
    static const struct option lo[] = {
        {"gpa", required_argument, NULL, 'g'}, {"where", required_argument, NULL, 'w'},
        {"block", required_argument, NULL, 'b'}, {"type", required_argument, NULL, 't'},
        {"permute", required_argument, NULL, O_PERMUTE},
        {"permutations", required_argument, NULL, 'p'},
        {"contrasts", required_argument, NULL, O_CONTRASTS},
        {"pairwise", required_argument, NULL, O_PAIRWISE},
        {"edges", required_argument, NULL, O_EDGES},
        {"edge-permutations", required_argument, NULL, O_EDGE_PERM},
        {"seed", required_argument, NULL, O_SEED}, {"name", required_argument, NULL, 'n'},
        {"no-store", no_argument, NULL, O_NOSTORE}, {"output", required_argument, NULL, 'o'},
        {"figure", required_argument, NULL, 'f'}, {"help", no_argument, NULL, 'h'},
        {"replace", no_argument, NULL, 'R'}, {"reference", required_argument, NULL, O_REFERENCE},
        {"error", required_argument, NULL, O_ERROR}, {"null", required_argument, NULL, O_NULL},
        {"slopes", required_argument, NULL, O_SLOPES}, {"at", required_argument, NULL, O_AT},
        {NULL, 0, NULL, 0}};
    const char *errors[MAX_ERRORS];
    es_study_model_opts o;
    es_study_model_opts_init(&o);
    const char *csv = NULL, *figure = NULL, *name = "model";
    int64_t seed = 0;
    int c, nostore = 0;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    optind = 1;
    while ((c = cli_getopt(argc, argv, "g:w:n:o:h", lo)) != -1) {
        switch (c) {
        case 'g': o.gpa = optarg; break;
        case 'w': o.where = optarg; break;
        case 'b': o.block = optarg; break;
        case 't':
            if (!strcmp(optarg, "I") || !strcmp(optarg, "1")) o.ss_type = ES_SS_TYPE_I;
            else if (!strcmp(optarg, "II") || !strcmp(optarg, "2")) o.ss_type = ES_SS_TYPE_II;
            else if (!strcmp(optarg, "III") || !strcmp(optarg, "3")) o.ss_type = ES_SS_TYPE_III;
            else return cli_usage_error("model", "--type is I, II or III, not '%s'", optarg);
            break;
        case O_PERMUTE:
            if (!strcmp(optarg, "rrpp")) o.scheme = ES_PERM_RRPP;
            else if (!strcmp(optarg, "raw")) o.scheme = ES_PERM_RAW;
            else return cli_usage_error("model", "--permute is rrpp or raw, not '%s'", optarg);
            break;
        case 'p':
            if (cli_parse_i64(optarg, &o.permutations) || o.permutations < 0 ||
                o.permutations > ES_MAX_PERMUTATIONS)
                return cli_usage_error("model", "--permutations needs a count from 0 to %d",
                                       ES_MAX_PERMUTATIONS);
            break;
        case O_CONTRASTS:
            if (!strcmp(optarg, "treatment")) o.contrasts = ES_CONTRASTS_TREATMENT;
            else if (!strcmp(optarg, "sum")) o.contrasts = ES_CONTRASTS_SUM;
            else return cli_usage_error("model", "--contrasts is treatment or sum");
            break;
        case O_PAIRWISE: o.pairwise = optarg; break;
        case O_REFERENCE: o.reference = optarg; break;
        case O_NULL: o.null_formula = optarg; break;
        case O_SLOPES: o.slopes = optarg; break;
        case O_AT: o.at = optarg; break;
        case O_ERROR:
            if (o.nerrors == MAX_ERRORS) return cli_usage_error("model", "too many --error");
            errors[o.nerrors++] = optarg;
            break;
        case O_EDGES: o.edge_term = optarg; break;
        case O_EDGE_PERM:
            if (cli_parse_i64(optarg, &o.edge_permutations) || o.edge_permutations < 0 ||
                o.edge_permutations > ES_MAX_PERMUTATIONS)
                return cli_usage_error("model", "--edge-permutations needs a count from 0 to "
                                       "%d", ES_MAX_PERMUTATIONS);
            break;
        case O_SEED:
            if (cli_parse_i64(optarg, &seed) || seed < 1)
                return cli_usage_error("model", "--seed needs a number >= 1");
            break;
        case 'n': name = optarg; break;
        case O_NOSTORE: nostore = 1; break;
        case 'o': csv = optarg; break;
        case 'f': figure = optarg; break;
        case 'R': wmode = ES_STORE_REPLACE; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("model", "bad option");
        }
    }
    if (optind != argc - 2) return cli_usage_error("model", "give a STORE and a FORMULA");
    if (figure && !o.edge_term) return cli_usage_error("model", "--figure needs --edges TERM");
    if (figure && o.gpa) return cli_usage_error("model", "--figure draws edges: not with --gpa");
    if (figure && !ES_HAVE_FIGURES)
        return cli_usage_error("model", "this build has no figures (cairo)");
    if ((o.slopes || o.at) && !o.pairwise)
        return cli_usage_error("model", "--%s needs --pairwise FACTOR", o.slopes ? "slopes" : "at");
    o.errors = errors;
    o.formula = argv[optind + 1];
    o.name = nostore ? NULL : name;
    es_ctx *ctx = cli_ctx_new("model");
    if (!ctx) return CLI_FAIL;
    if (seed) es_ctx_set_seed(ctx, (uint64_t)seed);
    char *cmdline = cli_command_line(argc, argv);
    o.command = cmdline;
    es_store *st = NULL;
    es_study_model_result *r = NULL;
    int ret = CLI_FAIL;
    /* on the ranks of an MPI job every rank reads the shapes and fits, each
     * evaluating its share of every term's permutations (es_model_fit);
     * rank 0 alone writes the store and the files. A taken name is refused
     * before the fit, agreed on by all ranks, so none is left in a sum. */
    const int writer = es_parallel_rank(ctx) == 0;
    es_status rc = es_store_open(ctx, argv[optind], o.name && writer ? wmode : ES_STORE_READ, &st);
    if (rc == ES_OK && o.name && writer) rc = es_store_result_check(ctx, st, "model", o.name);
    rc = es_parallel_agree(ctx, rc);
    if (!writer) o.name = NULL;
    if (rc == ES_OK) rc = es_study_model(ctx, st, &o, &r);
    if (rc == ES_OK && writer) rc = es_store_commit(ctx, st);
    if (rc != ES_OK) {
        cli_fail("model", ctx, rc);
        goto done;
    }
    if (!writer) {   /* the tables and figures are rank 0's to write */
        ret = CLI_OK;
        goto done;
    }
    char *text = NULL;
    if ((rc = es_study_model_summary(ctx, r, &text)) != ES_OK) {
        cli_fail("model", ctx, rc);
        goto done;
    }
    FILE *out = cli_report_stream(csv);   /* "-o -": stdout is the CSV alone */
    fputs(text, out);
    es_free(ctx, text);
    if (o.name) fprintf(out, "stored as /analysis/model/%s\n", o.name);
    ret = CLI_OK;
    if (csv && (rc = es_study_write_model_table(ctx, r, csv)) != ES_OK)
        ret = cli_fail("model", ctx, rc);
    if (ret == CLI_OK && csv && r->pairwise) {
        /* the pairwise table beside the ANOVA table: x.csv -> x.pairwise.csv */
        char pw[4096];
        const char *dot = strrchr(csv, '.'), *slash = strrchr(csv, '/');
        int stem = dot && (!slash || dot > slash) ? (int)(dot - csv) : (int)strlen(csv);
        snprintf(pw, sizeof pw, "%.*s.pairwise.csv", stem, csv);
        if (!strcmp(csv, "-")) putchar('\n');
        if ((rc = es_study_write_pairwise_table(ctx, r, strcmp(csv, "-") ? pw : "-")) != ES_OK)
            ret = cli_fail("model", ctx, rc);
        else if (strcmp(csv, "-")) printf("pairwise table: %s\n", pw);
    }
#if ES_HAVE_FIGURES
    if (ret == CLI_OK && figure) {
        if ((rc = es_figure_edge_tests(ctx, st, r, figure)) != ES_OK) ret = cli_fail("model", ctx, rc);
        else fprintf(out, "figure: %s\n", figure);
    }
#endif
done:
    es_study_model_free(r);
    if (ret == CLI_OK) es_store_close(st);
    else es_store_abort(st);
    free(cmdline);
    es_ctx_free(ctx);
    return ret;
}
