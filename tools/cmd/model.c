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
    "Fit FORMULA (\"~ expression + subject\", \"~ log(size) + species * sex\") to the\n"
    "shapes of STORE and test every term by permutation (model/<name> in\n"
    "datasets-spec/analysis-results.md).\n"
    "Variables are label columns: numeric when every value is a number, factor(COL)\n"
    "to make one categorical, log(COL); size is each row's size (scale, or centroid\n"
    "size with --gpa) unless a label column has that name.\n"
    "\n"
    "  -g, --gpa NAME         model the coordinates of GPA result NAME (Procrustes\n"
    "                         space) instead of the normalized edge lengths\n"
    "  -w, --where FILTER     only rows matching col=value[,col=value...]\n"
    "  -b, --block COLUMN     permute only within the values of COLUMN (repeated\n"
    "                         measures: the subject)\n"
    "  -t, --type I|II|III    sums of squares: sequential (I, default), each term\n"
    "                         after those not containing it (II), after all (III)\n"
    "      --permute rrpp|raw residuals of each term's reduced model (rrpp, default:\n"
    "                         geomorph, RRPP) or the rows themselves (raw: adonis2)\n"
    "  -p, --permutations N   permutations (999; 0: no p-values)\n"
    "      --contrasts treatment|sum   factor coding (treatment)\n"
    "      --pairwise FACTOR  compare the least-squares means of FACTOR's levels\n"
    "      --edges TERM       per-edge F of TERM with permutation p and FDR q values\n"
    "      --edge-permutations N       for --edges (default: --permutations)\n"
    "      --seed S           seed of the permutations (default: the library's)\n"
    "  -n, --name NAME        result name (default: model)\n"
    "      --no-store         leave the store unchanged\n"
    "      --replace          replace a stored result of that name (else refused)\n"
    "  -o, --csv PATH         write the ANOVA table as CSV (- for stdout)\n"
    "  -f, --figure PATH      with --edges: -log10 q of every edge on the mean mesh\n"
    "  -h, --help             show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

enum { O_PERMUTE = 256, O_CONTRASTS, O_PAIRWISE, O_EDGES, O_EDGE_PERM, O_SEED, O_NOSTORE };

static int print_table(FILE *out, const es_study_model_result *r)
{
    const es_model *m = r->model;
    fprintf(out, "%-24s %5s %14s %14s %8s %10s %8s\n", "term", "df", "SS", "MS", "R2", "F", "p");
    for (int64_t j = 0; j < m->nterms; j++) {
        fprintf(out, "%-24s %5lld %14.6g %14.6g %8.4f %10.4g ", r->design->terms[j],
                (long long)m->df[j], m->ss[j], m->ms[j], m->r2[j], m->f[j]);
        if (isnan(m->pval[j])) fprintf(out, "%8s\n", m->testable[j] ? "-" : "(block)");
        else fprintf(out, "%8.4g\n", m->pval[j]);
    }
    fprintf(out, "%-24s %5lld %14.6g %14.6g %8.4f\n", "Residual", (long long)m->df_resid, m->rss,
            m->rss / (double)m->df_resid, m->rss / m->tss);
    fprintf(out, "%-24s %5lld %14.6g\n", "Total", (long long)(m->n - 1), m->tss);
    if (r->pairwise) {
        const es_model_pairwise *pw = r->pairwise;
        fprintf(out, "pairwise distances of LS means (p):\n");
        for (int64_t a = 0; a < pw->nlevels; a++)
            for (int64_t b = a + 1; b < pw->nlevels; b++)
                fprintf(out, "  %-16s %-16s %12.6g  (p %.4g)\n", pw->levels[a], pw->levels[b],
                        pw->dist[a + b * pw->nlevels], pw->pval[a + b * pw->nlevels]);
    }
    if (r->edge_q) {
        int64_t n = 0, E = m->p;
        for (int64_t e = 0; e < E; e++) n += r->edge_q[e] < 0.05;
        fprintf(out, "edges with FDR q < 0.05: %lld of %lld\n", (long long)n, (long long)E);
    }
    return 0;
}

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
        {"no-store", no_argument, NULL, O_NOSTORE}, {"csv", required_argument, NULL, 'o'},
        {"figure", required_argument, NULL, 'f'}, {"help", no_argument, NULL, 'h'},
        {"replace", no_argument, NULL, 'R'}, {NULL, 0, NULL, 0}};
    es_study_model_opts o;
    es_study_model_opts_init(&o);
    const char *csv = NULL, *figure = NULL, *name = "model";
    int64_t seed = 0;
    int c, nostore = 0;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    optind = 1;
    while ((c = getopt_long(argc, argv, "g:w:b:t:p:n:o:f:h", lo, NULL)) != -1) {
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
    if (figure && !ES_HAVE_FIGURES)
        return cli_usage_error("model", "this build has no figures (cairo)");
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
    es_status rc = es_store_open(ctx, argv[optind], o.name ? wmode : ES_STORE_READ, &st);
    if (rc == ES_OK) rc = es_study_model(ctx, st, &o, &r);
    if (rc == ES_OK) rc = es_store_commit(ctx, st);
    if (rc != ES_OK) {
        cli_fail("model", ctx, rc);
        goto done;
    }
    FILE *out = cli_report_stream(csv);   /* "-o -": stdout is the CSV alone */
    print_table(out, r);
    if (o.name) fprintf(out, "stored as /analysis/model/%s\n", o.name);
    ret = CLI_OK;
    if (csv && (rc = es_study_write_model_table(ctx, r, csv)) != ES_OK)
        ret = cli_fail("model", ctx, rc);
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
