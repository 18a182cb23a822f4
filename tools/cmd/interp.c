/* tools/cmd/interp.c — edgespace interp: interpolate (or extrapolate)
 * stored shapes in edge-length space, embed each result, print and store
 * the quality reports (es_interp_embed). */
#include "cli.h"
#include "commands.h"
#include "stats_cli.h"

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
    "extrapolate; between rows, lengths driven to 0 or below are clamped (with a\n"
    "warning). Between two points that are not both rows (a stored point, a\n"
    "mean, an expression) each frame starts from the previous frame's dihedrals\n"
    "(the first from the nearest stored row; a frame at a row end from that\n"
    "row's), and a walk that leaves edge-length space is refused before any\n"
    "frame is written. Sequences are aligned frame to frame. Reports are printed\n"
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
    "      --refine-iters N  refinement iterations per frame (default 12)\n"
    "  -h, --help            show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

#define MAX_IN 64

/* Parse "w*row:id + w*row:id - row:id ...". Returns the count, -1 on error. */
static int parse_weights(const char *expr, double *w, char ids[][256])
{
    const char *p = expr;
    int n = 0;
    while (*p) {
        double sign = 1, coef = 1;
        char *end;
        while (isspace((unsigned char)*p)) p++;
        if (!*p) break;
        if (*p == '+' || *p == '-') {
            sign = *p == '-' ? -1 : 1;
            p++;
            while (isspace((unsigned char)*p)) p++;
        } else if (n > 0) {
            return -1;
        }
        if (strncmp(p, "row:", 4)) {
            coef = strtod(p, &end);
            if (end == p) return -1;
            p = end;
            while (isspace((unsigned char)*p)) p++;
            if (*p++ != '*') return -1;
            while (isspace((unsigned char)*p)) p++;
        }
        if (strncmp(p, "row:", 4) || n == MAX_IN) return -1;
        p += 4;
        {
            int k = 0;
            while (*p && !isspace((unsigned char)*p) && *p != '+' && k < 255) ids[n][k++] = *p++;
            ids[n][k] = 0;
            if (!k) return -1;
        }
        w[n++] = sign * coef;
    }
    return n;
}

/* Expand a pattern with one %d, %Nd or %0Nd conversion (%% is a literal
 * percent sign); -1 if malformed. */
static int expand_pattern(const char *pat, int i, char *out, size_t n)
{
    size_t k = 0;
    int seen = 0;
    for (const char *p = pat; *p; p++) {
        char num[32];
        int zero = 0, width = 0, w;
        if (*p != '%') {
            if (k + 1 >= n) return -1;
            out[k++] = *p;
            continue;
        }
        if (p[1] == '%') {
            if (k + 1 >= n) return -1;
            out[k++] = '%';
            p++;
            continue;
        }
        if (seen++) return -1;
        p++;
        if (*p == '0') zero = 1, p++;
        while (isdigit((unsigned char)*p)) width = width * 10 + (*p++ - '0');
        if (*p != 'd' || width > 20) return -1;
        w = zero ? snprintf(num, sizeof num, "%0*d", width, i)
                 : snprintf(num, sizeof num, "%*d", width, i);
        if (k + (size_t)w >= n) return -1;
        memcpy(out + k, num, (size_t)w);
        k += (size_t)w;
    }
    out[k] = 0;
    return seen == 1 ? 0 : -1;
}

static void base_name(const char *path, char *buf, size_t n)
{
    const char *b = strrchr(path, '/');
    char *q;
    snprintf(buf, n, "%s", b ? b + 1 : path);
    if ((q = strrchr(buf, '.')) && q != buf) *q = 0;
    q = strchr(buf, '%');   /* the conversion, skipping literal %% */
    while (q && q[1] == '%') q = strchr(q + 2, '%');
    if (q) {
        *q = 0;   /* 'cat_%02d' -> 'cat' (frames become cat_00, cat_01, ...) */
        while (q > buf && (q[-1] == '_' || q[-1] == '-')) *--q = 0;
    }
    if (!*buf) snprintf(buf, n, "interp");
}

/* Frame i of `steps`: its mesh file (the pattern expanded), its report on
 * stdout after `head`, and, when storing, the result NAME (NAME_<i> in a
 * sequence) with the provenance and the initialization's description. */
static es_status emit_frame(es_ctx *ctx, es_store *s, const es_mesh *mesh, es_embedder *emb,
                            const char *out, const char *name, int64_t steps, int64_t i,
                            const char *head, const double *target, const double *xyz,
                            const es_embed_report *rep, const es_provenance *prov,
                            const char *init)
{
    char fname[1024], rname[300], text[1024];
    es_status rc;
    if (steps > 1) {
        expand_pattern(out, (int)i, fname, sizeof fname);
        snprintf(rname, sizeof rname, "%s_%02d", name, (int)i);
    } else {
        snprintf(fname, sizeof fname, "%s", out);
        snprintf(rname, sizeof rname, "%s", name);
    }
    if ((rc = es_mesh_write(ctx, fname, ES_FORMAT_AUTO, mesh, xyz, NULL))) return rc;
    printf("%s: %s\n%s", fname, head, es_embed_report_format(rep, text, sizeof text));
    if (!prov) return ES_OK;
    return es_study_store_embedding(ctx, s, rname, prov, emb, target, xyz, rep, init);
}

/* Commit the stored frames and say where they are. */
static es_status commit_frames(es_ctx *ctx, es_store *s, const char *name, int64_t steps)
{
    es_status rc = es_store_commit(ctx, s);
    if (rc == ES_OK) printf("stored: /analysis/embed/%s%s\n", name, steps > 1 ? "_NN" : "");
    return rc;
}

/* t of frame i of `steps` from t0 to t1 inclusive. */
static double frame_t(double t0, double t1, int64_t steps, int64_t i)
{
    return steps == 1 ? t0 : t0 + (t1 - t0) * (double)i / (double)(steps - 1);
}

/* The dihedrals of a row end point ("row:ID"; NULL for another kind): a
 * frame at that end starts from them, so it is the row itself again. */
static es_status row_end_dihedrals(es_ctx *ctx, es_store *s, const es_mesh *mesh,
                                   const char *spec, double *xyz, double **alpha)
{
    int64_t row;
    es_status rc;
    *alpha = NULL;
    if (strncmp(spec, "row:", 4) || (row = es_store_find_row(s, spec + 4)) < 0) return ES_OK;
    if (!(*alpha = malloc((size_t)es_mesh_nedges(mesh) * sizeof **alpha))) return ES_ENOMEM;
    if ((rc = es_store_read_positions(ctx, s, row, xyz)) ||
        (rc = es_dihedral_angles(ctx, mesh, xyz, *alpha))) {
        free(*alpha);
        *alpha = NULL;
    }
    return rc;
}

/* Frame t of a walk from a (scale sa) to b (scale sb): v = (1 - t) a + t b
 * at the scale (1 - t) sa + t sb. Past the positive orthant (extrapolated
 * too far) it says so, naming t and the edge, and fails. */
static es_status lerp_frame(const double *a, const double *b, double sa, double sb, int64_t ne,
                            double t, double *v, double *scale)
{
    *scale = (1 - t) * sa + t * sb;
    for (int64_t e = 0; e < ne; e++) {
        v[e] = (1 - t) * a[e] + t * b[e];
        if (!(v[e] > 0)) {
            fprintf(stderr, "edgespace interp: at t = %.4g the length of edge %lld is %g: "
                    "outside edge-length space (extrapolated too far)\n", t, (long long)e, v[e]);
            return ES_EINVAL;
        }
    }
    if (!(*scale > 0)) {
        fprintf(stderr, "edgespace interp: at t = %.4g the scale is %g\n", t, *scale);
        return ES_EINVAL;
    }
    return ES_OK;
}

/* --from/--to points that are not both rows (stored points, means,
 * expressions): frame t embeds (1 - t) a + t b at the scale (1 - t) s_a +
 * t s_b (lerp in datasets-spec/point-syntax.md), its dihedrals started from
 * the previous frame (the first from the stored row nearest to it) and
 * aligned to it, so the sequence does not jump. command: the provenance of
 * stored frames, NULL to store nothing. Prints its own messages. */
typedef struct walk {
    const char *from, *to, *pca;   /* the end points, and the PCA pc:K refers to */
    double t0, t1;
    int64_t steps;
} walk;

static es_status interp_points(es_ctx *ctx, es_store *s, const es_mesh *mesh, es_embedder *emb,
                               const es_embed_opts *opts, const walk *wk, const char *out,
                               const char *name, const char *command, double *res)
{
    const char *from = wk->from, *to = wk->to;
    double t0 = wk->t0, t1 = wk->t1;
    int64_t steps = wk->steps;
    int64_t ne = es_mesh_nedges(mesh), nv = es_mesh_nverts(mesh);
    char initd[320], params[1024];
    double *a = malloc((size_t)ne * sizeof *a), *b = malloc((size_t)ne * sizeof *b);
    double *v = malloc((size_t)ne * sizeof *v), *start = malloc(3 * (size_t)nv * sizeof *start);
    double sa, sb, scale, *end_alpha[2] = {NULL, NULL};
    int64_t row = -1;   /* the first frame's nearest row: the only row used */
    es_status rc = ES_OK;
    if (!a || !b || !v || !start) {
        fprintf(stderr, "edgespace interp: out of memory\n");
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = stats_point_lengths("interp", ctx, s, from, wk->pca, ne, a, &sa)) ||
        (rc = stats_point_lengths("interp", ctx, s, to, wk->pca, ne, b, &sb)))
        goto done;
    if ((rc = row_end_dihedrals(ctx, s, mesh, from, start, &end_alpha[0])) ||
        (rc = row_end_dihedrals(ctx, s, mesh, to, start, &end_alpha[1])))
        goto fail;
    /* every frame is checked before the first is written: a refused walk
     * leaves no partial sequence behind */
    for (int64_t i = 0; i < steps; i++)
        if ((rc = lerp_frame(a, b, sa, sb, ne, frame_t(t0, t1, steps, i), v, &scale))) goto done;
    for (int64_t i = 0; i < steps; i++) {
        double t = frame_t(t0, t1, steps, i);
        es_embed_report rep;
        lerp_frame(a, b, sa, sb, ne, t, v, &scale);
        if (i == 0) {
            double d;
            if ((rc = es_study_nearest_row(ctx, s, v, NULL, 0, &row, &d)) ||
                (rc = es_store_read_positions(ctx, s, row, start)))
                goto fail;
            snprintf(initd, sizeof initd, "first frame: nearest row %s; then the previous frame",
                     es_store_row_id(s, row));
        }
        /* from the second frame on, the previous frame (res itself) is both
         * the start and the alignment reference; a frame at a row end starts
         * from that row's dihedrals */
        const double *at_end = t == 0 ? end_alpha[0] : t == 1 ? end_alpha[1] : NULL;
        if ((rc = es_embed_solve(ctx, emb, v, scale, at_end, i ? res : start, opts, res, &rep)))
            goto fail;
        {
            es_provenance prov = {command, &row, 1, params};
            char head[64], endd[320];
            snprintf(params, sizeof params, "from=%s; to=%s; t=%.17g", from, to, t);
            snprintf(head, sizeof head, "t = %.4g", t);
            if (at_end) snprintf(endd, sizeof endd, "the dihedrals of %s", t == 0 ? from : to);
            if ((rc = emit_frame(ctx, s, mesh, emb, out, name, steps, i, head, v, res, &rep,
                                 command ? &prov : NULL, at_end ? endd : initd)))
                goto fail;
        }
    }
    goto done;
fail:
    cli_fail("interp", ctx, rc);
done:
    free(a), free(b), free(v), free(start), free(end_alpha[0]), free(end_alpha[1]);
    return rc;
}

int cmd_interp(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"from", required_argument, NULL, 'f'}, {"to", required_argument, NULL, 't'},
        {"steps", required_argument, NULL, 'k'}, {"t0", required_argument, NULL, '0'},
        {"t1", required_argument, NULL, '1'},   {"weights", required_argument, NULL, 'w'},
        {"output", required_argument, NULL, 'o'}, {"name", required_argument, NULL, 'n'},
        {"no-store", no_argument, NULL, 'N'},   {"help", no_argument, NULL, 'h'},
        {"refine-iters", required_argument, NULL, 'R'}, {"pca", required_argument, NULL, 'c'},
        {NULL, 0, NULL, 0}};
    const char *from = NULL, *to = NULL, *weights = NULL, *out = NULL, *name = NULL;
    const char *pca = NULL;
    char ids[MAX_IN][256], namebuf[256], fname[1024];
    double w[MAX_IN], t0 = 0, t1 = 1, *xyz[MAX_IN] = {0}, *res = NULL, *len = NULL, *alpha = NULL;
    char *cmd = NULL;   /* the command line, the provenance of stored frames */
    int64_t steps = 9, rows[MAX_IN], nin = 0, nv, ne;
    int c, store_it = 1, points = 0;
    int64_t refine_iters;
    es_embed_opts opts;
    es_ctx *ctx;
    es_store *s = NULL;
    es_mesh *mesh = NULL;
    es_embedder *emb = NULL;
    es_status rc = ES_OK;
    es_embed_opts_init(&opts);
    optind = 1;
    while ((c = getopt_long(argc, argv, "f:t:k:w:o:n:h", longopts, NULL)) != -1) {
        switch (c) {
        case 'f': from = optarg; break;
        case 't': to = optarg; break;
        case 'k':
            if (cli_parse_i64(optarg, &steps) || steps < 1 || steps > 100000)
                return cli_usage_error("interp", "--steps wants a count >= 1");
            break;
        case '0':
            if (cli_parse_double(optarg, &t0)) return cli_usage_error("interp", "bad --t0");
            break;
        case '1':
            if (cli_parse_double(optarg, &t1)) return cli_usage_error("interp", "bad --t1");
            break;
        case 'w': weights = optarg; break;
        case 'c': pca = optarg; break;
        case 'o': out = optarg; break;
        case 'n': name = optarg; break;
        case 'N': store_it = 0; break;
        case 'R':
            if (cli_parse_i64(optarg, &refine_iters) || refine_iters < 0 || refine_iters > 100000)
                return cli_usage_error("interp", "--refine-iters wants a count >= 0");
            opts.refine_max_iter = (int)refine_iters;
            break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("interp", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("interp", "give exactly one STORE");
    if (!out) return cli_usage_error("interp", "--output is required");
    if (weights) {
        if (from || to) return cli_usage_error("interp", "--weights excludes --from/--to");
        nin = parse_weights(weights, w, ids);
        if (nin < 2)
            return cli_usage_error("interp", "--weights wants 'w1*row:a + w2*row:b ...' with "
                                   "two or more rows");
        steps = 1;
    } else {
        if (!from || !to)
            return cli_usage_error("interp", "give --from A --to B, or --weights");
        if (!strncmp(from, "row:", 4) && !strncmp(to, "row:", 4)) {
            snprintf(ids[0], sizeof ids[0], "%s", from + 4);
            snprintf(ids[1], sizeof ids[1], "%s", to + 4);
            nin = 2;
        } else {
            points = 1;   /* points of the space: no meshes to take dihedrals from */
        }
    }
    if (steps > 1 && expand_pattern(out, 0, fname, sizeof fname))
        return cli_usage_error("interp", "with several frames, --output must be a pattern "
                               "with one integer conversion, like 'out_%%02d.obj'");
    if (!name) {
        base_name(out, namebuf, sizeof namebuf);
        name = namebuf;
    }
    if (!(ctx = cli_ctx_new("interp"))) return CLI_FAIL;
    if ((rc = es_store_open(ctx, argv[optind], store_it ? ES_STORE_WRITE : ES_STORE_READ, &s)) ||
        (rc = es_store_mesh(ctx, s, &mesh)) || (rc = es_embedder_new(ctx, mesh, &emb)))
        goto fail;
    nv = es_mesh_nverts(mesh);
    ne = es_mesh_nedges(mesh);
    res = malloc(3 * (size_t)nv * sizeof *res);
    len = malloc((size_t)ne * sizeof *len);
    alpha = malloc((size_t)ne * sizeof *alpha);
    if (!res || !len || !alpha || (store_it && !(cmd = cli_command_line(argc, argv)))) {
        rc = ES_ENOMEM;
        goto fail;
    }
    if (points) {
        walk wk = {from, to, pca, t0, t1, steps};
        if ((rc = interp_points(ctx, s, mesh, emb, &opts, &wk, out, name, cmd, res)))
            goto done;   /* it said why */
        goto commit;
    }
    for (int64_t k = 0; k < nin; k++) {
        if ((rows[k] = es_store_find_row(s, ids[k])) < 0) {
            fprintf(stderr, "edgespace interp: no row '%s' in the store\n", ids[k]);
            rc = ES_ENOTFOUND;
            goto done;
        }
        if (!(xyz[k] = malloc(3 * (size_t)nv * sizeof *xyz[k]))) {
            rc = ES_ENOMEM;
            goto fail;
        }
        if ((rc = es_store_read_positions(ctx, s, rows[k], xyz[k]))) goto fail;
    }
    for (int64_t i = 0; i < steps; i++) {
        double t = frame_t(t0, t1, steps, i);
        double wi[MAX_IN];
        es_embed_report rep;
        es_interp_info info;
        const double *const *in = (const double *const *)xyz;
        if (weights) memcpy(wi, w, (size_t)nin * sizeof *wi);
        else wi[0] = 1 - t, wi[1] = t;
        /* the targets once (es_interp_embed would not hand the lengths back
         * for storing); frames align to the previous frame so that the
         * sequence does not jump, the first to the reference input */
        if ((rc = es_interp_targets(ctx, mesh, nin, in, wi, len, alpha, &info)) ||
            (rc = es_embed_solve(ctx, emb, len, 0, alpha, i ? res : in[info.reference], &opts, res,
                                 &rep)))
            goto fail;
        {
            char params[512], head[128];
            es_provenance prov = {cmd, rows, nin, params};
            int off = 0;
            for (int64_t k = 0; k < nin && off < (int)sizeof params - 40; k++)
                off += snprintf(params + off, sizeof params - (size_t)off, "%sw[%s]=%.6g",
                                k ? "; " : "", ids[k], wi[k]);
            if (weights)
                snprintf(head, sizeof head, "weights (%lld dihedrals wrapped, %lld lengths "
                         "clamped)", (long long)info.n_wrapped, (long long)info.n_clamped);
            else
                snprintf(head, sizeof head, "t = %.4g (%lld dihedrals wrapped, %lld lengths "
                         "clamped)", t, (long long)info.n_wrapped, (long long)info.n_clamped);
            if ((rc = emit_frame(ctx, s, mesh, emb, out, name, steps, i, head, len, res, &rep,
                                 cmd ? &prov : NULL, "circular mean of the inputs' dihedrals")))
                goto fail;
        }
    }
commit:
    if (store_it && (rc = commit_frames(ctx, s, name, steps))) goto fail;
    goto done;
fail:
    cli_fail("interp", ctx, rc);
done:
    es_embedder_free(emb);
    es_mesh_free(mesh);
    if (rc) es_store_abort(s);
    else es_store_close(s);
    for (int k = 0; k < MAX_IN; k++) free(xyz[k]);
    free(res), free(len), free(alpha), free(cmd);
    es_ctx_free(ctx);
    return rc ? CLI_FAIL : CLI_OK;
}
