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
    "       edgespace interp STORE --from row:ID --method conformal -o PATTERN\n"
    "       edgespace interp STORE --weights \"0.2*row:a + 0.3*row:b + 0.5*row:c\" -o OUT\n"
    "\n"
    "Interpolate stored shapes in edge-length space (weighted mean of normalized\n"
    "lengths at the weighted mean scale; dihedrals averaged on the circle as the\n"
    "start) and embed each result as a mesh. Weights or t outside [0, 1]\n"
    "extrapolate; a walk that leaves edge-length space (a length reaches 0 or\n"
    "below) is refused, naming t and the edge, before any frame is written.\n"
    "Each frame is embedded near the prior of its row weights, in the store's\n"
    "frame (as embed does), starting from the last frame's correction of its\n"
    "prior (--cold: from its own prior). Reports are printed\n"
    "and stored under /analysis/embed/NAME_<i> (per-vertex residuals included).\n"
    "\n"
    "      --from A          first shape (t = 0): row:ID, a stored point's name, or\n"
    "                        an expression such as \"mean[expression=neutral]\"\n"
    "      --to B            second shape (t = 1), the same kinds\n"
    "      --pca NAME        the PCA whose components pc:K in A or B means (needed\n"
    "                        when several are stored and none is named 'default');\n"
    "                        or name it in A or B: pc:NAME:K\n"
    "      --steps N         frames from t0 to t1 inclusive (default 9)\n"
    "      --t0 T, --t1 T    range of t (default 0 and 1)\n"
    "      --weights EXPR    w1*row:a + w2*row:b + ... (two or more rows)\n"
    "  -o, --output PATTERN  mesh file; with several frames a printf pattern with\n"
    "                        one integer conversion, e.g. 'cat_%02d.obj' (%% for %)\n"
    "  -n, --name NAME       result name in the store (default: output base name)\n"
    "      --no-store        do not write reports into the store\n"
;

static const char usage2[] =
CLI_EMBED_HELP
    "      --cold            every frame from its own prior, as embed starts the same\n"
    "                        point (default: from the last frame's correction of its\n"
    "                        prior, a warm start)\n"
    "      --replace         replace a stored result of that name (else refused)\n"
    "      --max-memory SIZE refuse a mesh whose embedding needs more (default: the\n"
    "                        machine's memory, or $EDGESPACE_MAX_MEMORY; e.g. 8G)\n"
    "  -m, --method M        edge-length (default: the above), or another paper's\n"
    "                        way between two rows (--from/--to row:ID):\n"
    "                        multiscale (Winkler et al. 2010), shape-space (Wuhrer\n"
    "                        et al. 2010), each frame put together by the method,\n"
    "                        in A's frame; data-driven (Gao et al. 2017): a path\n"
    "                        through the store's rows in the paper's rotation-\n"
    "                        invariant coordinates, each frame decoded from them;\n"
    "                        data-driven-el: the same path in edge-length space,\n"
    "                        each frame embedded as above;\n"
    "                        paper: the published pipeline (embed --paper) on each\n"
    "                        frame from the rows' averaged dihedrals; conformal\n"
    "                        (--from row:ID only): the row mapped to the sphere by\n"
    "                        discrete conformal factors, t = their k (an open mesh\n"
    "                        closed off first; frame files of the closed mesh)\n"
    "      --knn K           data-driven: neighbours per row in the path's graph (6)\n"
    "      --sigma S         data-driven: the examples' pull falls off as exp(-d / S),\n"
    "                        d in mean neighbour distances (default 1)\n"
    "      --seed S          seed of the multiscale hierarchies' random seed faces\n"
    "                        (default the library's)\n"
    "      --tries N         multiscale: hierarchies from seeds S .. S+N-1, each frame\n"
    "                        kept from the one of least energy (its length and\n"
    "                        dihedral misfit; default 4, 1: one hierarchy)\n"
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
        {"help", no_argument, NULL, 'h'},       CLI_EMBED_LONGOPTS,
        {"pca", required_argument, NULL, 'c'},  {"cold", no_argument, NULL, 'C'},
        {"method", required_argument, NULL, 'm'}, {"seed", required_argument, NULL, 'S'},
        {"tries", required_argument, NULL, 'T'}, {"knn", required_argument, NULL, 'K'},
        {"sigma", required_argument, NULL, 'G'}, {"max-memory", required_argument, NULL, 'M'},
        {NULL, 0, NULL, 0}};
    es_study_interp_opts o;
    es_store_mode wmode = ES_STORE_WRITE;   /* --replace: ES_STORE_REPLACE */
    int c, e, store_it = 1;
    int64_t seed = -1, tries;
    uint64_t max_memory = 0;
    es_ctx *ctx;
    es_store *s = NULL;
    es_status rc;
    char *cmd = NULL;
    const char *method = NULL;
    es_study_interp_opts_init(&o);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "o:n:m:h", longopts)) != -1) {
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
        case 'C': o.cold = 1; break;
        case 'S':
            if (cli_parse_i64(optarg, &seed) || seed < 0)
                return cli_usage_error("interp", "--seed wants an integer >= 0");
            break;
        case 'T':
            if (cli_parse_i64(optarg, &tries) || tries < 1 || tries > 64)
                return cli_usage_error("interp", "--tries wants 1 .. 64");
            o.multiscale.tries = (int)tries;
            break;
        case 'K':
            if (cli_parse_i64(optarg, &o.path.knn) || o.path.knn < 1)
                return cli_usage_error("interp", "--knn wants a count >= 1");
            break;
        case 'G':
            if (cli_parse_double(optarg, &o.path.sigma) || !(o.path.sigma > 0))
                return cli_usage_error("interp", "--sigma wants a positive number");
            break;
        case 'X': wmode = ES_STORE_REPLACE; break;
        case 'M':
            if (cli_parse_size(optarg, &max_memory))
                return cli_usage_error("interp", "--max-memory wants a size such as 8G");
            break;
        case 'h': fputs(usage, stdout), fputs(usage2, stdout); return CLI_OK;
        default:
            if ((e = cli_embed_option("interp", c, optarg, &o.embed)) >= 0) {
                if (e) return e;
                break;
            }
            return cli_usage_error("interp", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("interp", "give exactly one STORE");
    if (!o.output) return cli_usage_error("interp", "--output is required");
    if (o.weights && (o.from || o.to))
        return cli_usage_error("interp", "--weights excludes --from/--to");
    if (!o.weights && (!o.from || (!o.to && !(method && !strcmp(method, "conformal")))))
        return cli_usage_error("interp", "give --from A --to B, or --weights");
    if (o.weights) o.steps = 1;
    char probe[4096], stored[300];
    if (o.steps > 1 && es_study_frame_path(o.output, 0, probe, sizeof probe))
        return cli_usage_error("interp", "with several frames, --output must be a pattern "
                               "with one integer conversion, like 'out_%%02d.obj'");
    if (!(ctx = cli_ctx_new("interp"))) return CLI_FAIL;
    if (max_memory) es_ctx_set_memory_limit(ctx, max_memory);
    if (seed >= 0) es_ctx_set_seed(ctx, (uint64_t)seed);
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
    /* stored under --name, else the output's base name; the frames appear
     * with the commit */
    char defname[256];
    if (!store_it) o.name = NULL;
    else if (!o.name) o.name = es_study_interp_default_name(o.output, defname, sizeof defname);
    if ((rc = es_store_open(ctx, argv[optind], store_it ? wmode : ES_STORE_READ, &s)) ||
        (rc = es_study_interp(ctx, s, &o)) || (store_it && (rc = es_store_commit(ctx, s))))
        cli_fail("interp", ctx, rc);
    else if (store_it)
        printf("stored: /analysis/embed/%s\n", es_study_interp_name(&o, stored, sizeof stored));
    if (rc) es_store_abort(s);
    else es_store_close(s);
    free(cmd);
    es_ctx_free(ctx);
    return rc ? CLI_FAIL : CLI_OK;
}
