/* tools/cmd/interp.c — edgespace interp: interpolate (or extrapolate)
 * stored shapes in edge-length space, embed each result, print and store
 * the quality reports (es_interp_embed). */
#include "cli.h"
#include "commands.h"

#include <ctype.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace interp STORE --from A --to B [--steps N] -o PATTERN\n"
    "       edgespace interp STORE --weights \"0.2*row:a + 0.3*row:b + 0.5*row:c\" -o OUT\n"
    "\n"
    "Interpolate stored shapes in edge-length space (weighted mean of normalized\n"
    "lengths at the weighted mean scale; dihedrals averaged on the circle as the\n"
    "start) and embed each result as a mesh. Weights or t outside [0, 1]\n"
    "extrapolate; a walk that leaves edge-length space (a length reaches 0 or\n"
    "below) is refused, naming t and the edge, before any frame is written.\n"
    "Between two points that are not both rows (a stored point, a mean, an\n"
    "expression) each frame starts from the previous frame's dihedrals (the\n"
    "first from the nearest stored row; a frame at a row end from that row's).\n"
    "Sequences are aligned frame to frame. Reports are printed\n"
    "and stored under /analysis/embed/NAME_<i> (per-vertex residuals included).\n"
    "\n"
    "  -f, --from A          first shape (t = 0): row:ID, a stored point's name, or\n"
    "                        an expression such as \"mean[expression=neutral]\"\n"
    "  -t, --to B            second shape (t = 1), the same kinds\n"
    "      --pca NAME        the PCA whose components pc:K in A or B means (needed\n"
    "                        when several are stored and none is named 'default')\n"
    "  -k, --steps N         frames from t0 to t1 inclusive (default 9)\n"
    "      --t0 T, --t1 T    range of t (default 0 and 1)\n"
    "  -w, --weights EXPR    w1*row:a + w2*row:b + ... (two or more rows)\n"
    "  -o, --output PATTERN  mesh file; with several frames a printf pattern with\n"
    "                        one integer conversion, e.g. 'cat_%02d.obj' (%% for %)\n"
    "  -n, --name NAME       result name in the store (default: output base name)\n"
    "      --no-store        do not write reports into the store\n"
    "      --bending W      weight of the prior's bending term against the lengths\n"
    "                       (default 0.0025; 0: the prior only starts and frames it)\n"
    "      --refine-iters N  refinement iterations per frame (default 12)\n"
    "      --replace         replace a stored result of that name (else refused)\n"
    "      --max-memory SIZE refuse a mesh whose embedding needs more (default: the\n"
    "                        machine's memory, or $EDGESPACE_MAX_MEMORY; e.g. 8G)\n"
    "  -m, --method M        edge-length (default: the above), or another paper's\n"
    "                        way between two rows (--from/--to row:ID):\n"
    "                        multiscale (Winkler et al. 2010), shape-space (Wuhrer\n"
    "                        et al. 2010), each frame put together by the method,\n"
    "                        in A's frame; data-driven (Gao et al. 2017): a path\n"
    "                        through the store's rows, each frame embedded as above\n"
    "  -h, --help            show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

/* --weights is a point expression of two or more rows. */
static int weights_are_rows(es_ctx *ctx, const char *text)
{
    es_point_expr *expr;
    int ok;
    if (es_point_parse(ctx, text, &expr) != ES_OK) return 0;
    ok = es_point_expr_nterms(expr) >= 2;
    for (int64_t k = 0; ok && k < es_point_expr_nterms(expr); k++) {
        double coef;
        es_point_leaf kind;
        const char *arg;
        int64_t index;
        es_point_expr_term(expr, k, &coef, &kind, &arg, &index);
        ok = kind == ES_POINT_ROW;
    }
    es_point_expr_free(expr);
    return ok;
}

/* One frame written: its report on standard output. */
static void print_frame(void *ud, int64_t i, int64_t n, const char *path, const char *heading,
                        const es_embed_report *rep)
{
    char text[1024];
    (void)ud, (void)i, (void)n;
    printf("%s: %s\n%s", path, heading, es_embed_report_format(rep, text, sizeof text));
}

int cmd_interp(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"from", required_argument, NULL, 'f'}, {"to", required_argument, NULL, 't'},
        {"steps", required_argument, NULL, 'k'}, {"t0", required_argument, NULL, '0'},
        {"t1", required_argument, NULL, '1'},   {"weights", required_argument, NULL, 'w'},
        {"output", required_argument, NULL, 'o'}, {"name", required_argument, NULL, 'n'},
        {"no-store", no_argument, NULL, 'N'},   {"replace", no_argument, NULL, 'X'},
        {"help", no_argument, NULL, 'h'},       {"bending", required_argument, NULL, 'B'},
        {"refine-iters", required_argument, NULL, 'R'}, {"pca", required_argument, NULL, 'c'},
        {"method", required_argument, NULL, 'm'}, {"max-memory", required_argument, NULL, 'M'},
        {NULL, 0, NULL, 0}};
    es_study_interp_opts o;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c, store_it = 1;
    int64_t iters;
    uint64_t max_memory = 0;
    es_ctx *ctx;
    es_store *s = NULL;
    es_status rc;
    char *cmd = NULL;
    const char *method = NULL;
    es_study_interp_opts_init(&o);
    optind = 1;
    while ((c = getopt_long(argc, argv, "f:t:k:w:o:n:m:h", longopts, NULL)) != -1) {
        switch (c) {
        case 'f': o.from = optarg; break;
        case 't': o.to = optarg; break;
        case 'k':
            if (cli_parse_i64(optarg, &o.steps) || o.steps < 1 || o.steps > 100000)
                return cli_usage_error("interp", "--steps wants a count >= 1");
            break;
        case '0':
            if (cli_parse_double(optarg, &o.t0)) return cli_usage_error("interp", "bad --t0");
            break;
        case '1':
            if (cli_parse_double(optarg, &o.t1)) return cli_usage_error("interp", "bad --t1");
            break;
        case 'w': o.weights = optarg; break;
        case 'c': o.pca_name = optarg; break;
        case 'm': method = optarg; break;
        case 'o': o.output = optarg; break;
        case 'n': o.name = optarg; break;
        case 'N': store_it = 0; break;
        case 'B': {
            double mu;
            if (cli_parse_double(optarg, &mu) || !(mu >= 0))
                return cli_usage_error("interp", "--bending wants a weight >= 0");
            o.embed.prior_mu = mu;
            break;
        }
        case 'R':
            if (cli_parse_i64(optarg, &iters) || iters < 0 || iters > 100000)
                return cli_usage_error("interp", "--refine-iters wants a count >= 0");
            o.embed.refine_max_iter = (int)iters;
            break;
        case 'X': wmode = ES_STORE_REPLACE; break;
        case 'M':
            if (cli_parse_size(optarg, &max_memory))
                return cli_usage_error("interp", "--max-memory wants a size such as 8G");
            break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("interp", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("interp", "give exactly one STORE");
    if (!o.output) return cli_usage_error("interp", "--output is required");
    if (o.weights && (o.from || o.to))
        return cli_usage_error("interp", "--weights excludes --from/--to");
    if (!o.weights && (!o.from || !o.to))
        return cli_usage_error("interp", "give --from A --to B, or --weights");
    if (o.weights) o.steps = 1;
    char probe[4096], stored[300];
    if (o.steps > 1 && es_study_frame_path(o.output, 0, probe, sizeof probe))
        return cli_usage_error("interp", "with several frames, --output must be a pattern "
                               "with one integer conversion, like 'out_%%02d.obj'");
    if (!(ctx = cli_ctx_new("interp"))) return CLI_FAIL;
    if (max_memory) es_ctx_set_memory_limit(ctx, max_memory);
    if (o.weights && !weights_are_rows(ctx, o.weights)) {
        es_ctx_free(ctx);
        return cli_usage_error("interp", "--weights wants 'w1*row:a + w2*row:b ...' with two "
                               "or more rows");
    }
    if (method && es_morph_method_from_name(ctx, method, &o.method) != ES_OK) {
        rc = cli_usage_error("interp", "%s", es_ctx_errmsg(ctx));
        es_ctx_free(ctx);
        return (int)rc;
    }
    o.frame = print_frame;
    if (store_it && !(cmd = cli_command_line(argc, argv))) {
        es_ctx_free(ctx);
        return CLI_FAIL;
    }
    o.command = cmd;
    if ((rc = es_store_open(ctx, argv[optind], store_it ? wmode : ES_STORE_READ, &s)) ||
        (rc = es_study_interp(ctx, s, &o)))
        cli_fail("interp", ctx, rc);
    else if (store_it)
        printf("stored: /analysis/embed/%s\n", es_study_interp_name(&o, stored, sizeof stored));
    if (rc) es_store_abort(s);
    else es_store_close(s);
    free(cmd);
    es_ctx_free(ctx);
    return rc ? CLI_FAIL : CLI_OK;
}
