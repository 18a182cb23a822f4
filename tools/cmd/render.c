/* tools/cmd/render.c — `edgespace render`: draw one or several mesh files
 * side by side to PNG, SVG or PDF (es_figure_render_files), optionally
 * coloured by scalars read from CSV files (one value per vertex, edge or
 * face, in order). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#define VERB "render"

/* Fontconfig (under cairo's text) keeps process-lifetime caches that
 * LeakSanitizer would report at exit in sanitizer builds; they are not
 * ours. Without a sanitizer this hook is never called. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig.so\n"; }
#define MAX_MESHES 64

static void usage(FILE *f)
{
    fputs("usage: edgespace render MESH... -o OUT.png|.svg|.pdf [options]\n"
          "       edgespace render MESH --scalars CSV -o OUT.ply|.glb|.vtp [options]\n\n"
          "Draw meshes (OBJ, PLY, OFF) side by side, each seen along its smallest\n"
          "principal axis unless --view is given; one colour bar when scalars are.\n"
          "With a .ply, .glb or .vtp output, write the mesh itself with the same\n"
          "vertex colours (--cmap, --range, --percentiles, --column) for MeshLab,\n"
          "Blender or ParaView; the VTP also holds the values.\n\n"
          "options:\n"
          "  -o, --output PATH      output file; the extension picks the format\n"
          "      --view X,Y,Z       direction the camera looks along\n"
          "      --up X,Y,Z         screen up direction\n"
          "      --scalars CSV      values to colour by: one per vertex, edge or face\n"
          "                         (the count decides; edges in es_mesh order), a header\n"
          "                         line allowed, empty or nan = missing; once for all\n"
          "                         meshes or once per mesh\n"
          "      --column C         the scalars' column: a header name or a number\n"
          "                         (default: the first); its header labels the colour bar\n"
          "      --percentiles P,Q  colour range from the P-th to the Q-th percentile of\n"
          "                         the values (e.g. 2,98: a few large residuals do not\n"
          "                         leave the rest one colour); beyond: the end colours\n"
          "      --cmap NAME        viridis (default), rdbu (signed values), greys\n"
          "      --range LO,HI      colour range (default: the data's, symmetric for rdbu)\n"
          "      --label TEXT       label under a panel (repeat per mesh; default: file\n"
          "                         names when there are several meshes)\n"
          "      --title TEXT       title above the row\n"
          "      --colorbar-label T label of the colour bar\n"
          "      --width W          panel width (default 480)\n"
          "      --height H         panel height (default 480)\n"
          "      --ortho            orthographic instead of perspective projection\n"
          "      --fov DEG          perspective field of view (default 25)\n"
          "      --cull             leave back faces out (default: drawn darker)\n"
          "      --fit-each         each mesh fills its panel (default: one scale)\n"
          "      --same-view        all panels use the first mesh's automatic view\n"
          "      --columns N        wrap the panels into rows of N\n"
          "  -h, --help             show this help\n\n"
          "Exit status: 0 ok, 1 failure, 2 usage error.\n", f);
}

static int parse_vec3(const char *s, double v[3])
{
    char buf[256], *save = NULL;
    if (strlen(s) >= sizeof buf) return -1;
    strcpy(buf, s);
    int k = 0;
    for (char *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        if (k == 3 || cli_parse_double(t, &v[k])) return -1;
        k++;
    }
    /* a direction: 0,0,0 has none */
    return k == 3 && (v[0] != 0 || v[1] != 0 || v[2] != 0) ? 0 : -1;
}

int cmd_render(int argc, char **argv)
{
    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"view", required_argument, NULL, 'v'},
        {"up", required_argument, NULL, 'u'}, {"scalars", required_argument, NULL, 's'},
        {"cmap", required_argument, NULL, 'c'}, {"range", required_argument, NULL, 'r'},
        {"label", required_argument, NULL, 'l'}, {"title", required_argument, NULL, 't'},
        {"colorbar-label", required_argument, NULL, 'b'},
        {"column", required_argument, NULL, 'k'}, {"percentiles", required_argument, NULL, 'p'},
        {"width", required_argument, NULL, 'W'}, {"height", required_argument, NULL, 'H'},
        {"ortho", no_argument, NULL, 'O'}, {"fov", required_argument, NULL, 'F'},
        {"cull", no_argument, NULL, 'C'}, {"fit-each", no_argument, NULL, 'E'},
        {"same-view", no_argument, NULL, 'S'}, {"columns", required_argument, NULL, 'N'},
        {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    es_render_spec spec;
    const char *out = NULL, *scalar_files[MAX_MESHES], *labels[MAX_MESHES];
    int nscalar_files = 0, nlabels = 0, c, m;
    double range[3];
    int64_t v64;

    es_render_spec_init(&spec);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "o:h", opts)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'v':
            if (parse_vec3(optarg, spec.view))
                return cli_usage_error(VERB, "--view wants a direction X,Y,Z (not 0,0,0)");
            spec.has_view = 1;
            break;
        case 'u':
            if (parse_vec3(optarg, spec.up))
                return cli_usage_error(VERB, "--up wants a direction X,Y,Z (not 0,0,0)");
            spec.has_up = 1;
            break;
        case 's':
            if (nscalar_files == MAX_MESHES) return cli_usage_error(VERB, "too many --scalars");
            scalar_files[nscalar_files++] = optarg;
            break;
        case 'c':
            if ((m = es_colormap_from_name(optarg)) < 0)
                return cli_usage_error(VERB, "unknown colour map '%s'", optarg);
            spec.cmap = (es_colormap)m;
            break;
        case 'r': {
            char buf[256];
            snprintf(buf, sizeof buf, "%s,0", optarg);
            if (parse_vec3(buf, range) || !(range[0] < range[1]))
                return cli_usage_error(VERB, "--range wants LO,HI with LO < HI");
            spec.vmin = range[0];
            spec.vmax = range[1];
            break;
        }
        case 'l':
            if (nlabels == MAX_MESHES) return cli_usage_error(VERB, "too many --label");
            labels[nlabels++] = optarg;
            break;
        case 't': spec.title = optarg; break;
        case 'k': spec.scalar_column = optarg; break;
        case 'p': {
            char buf[256];
            snprintf(buf, sizeof buf, "%s,1", optarg);
            if (parse_vec3(buf, range) || !(range[0] >= 0 && range[0] < range[1] &&
                                            range[1] <= 100))
                return cli_usage_error(VERB, "--percentiles wants P,Q with 0 <= P < Q <= 100");
            spec.range_percentiles[0] = range[0];
            spec.range_percentiles[1] = range[1];
            break;
        }
        case 'b': spec.colorbar_label = optarg; break;
        case 'W':
        case 'H':
            if (cli_parse_i64(optarg, &v64) || v64 < 16 || v64 > 8192)
                return cli_usage_error(VERB, "--%s wants an integer in 16..8192",
                                       c == 'W' ? "width" : "height");
            if (c == 'W') spec.width = (int)v64;
            else spec.height = (int)v64;
            break;
        case 'O': spec.projection = ES_PROJ_ORTHOGRAPHIC; break;
        case 'F':
            if (cli_parse_double(optarg, &spec.fov_deg))
                return cli_usage_error(VERB, "--fov wants a number of degrees");
            break;
        case 'C': spec.backface = ES_BACKFACE_CULL; break;
        case 'E': spec.fit_each = 1; break;
        case 'S': spec.same_view = 1; break;
        case 'N':
            if (cli_parse_i64(optarg, &v64) || v64 < 1 || v64 > MAX_MESHES)
                return cli_usage_error(VERB, "--columns wants an integer in 1..%d", MAX_MESHES);
            spec.ncols = v64;
            break;
        case 'h': usage(stdout); return CLI_OK;
        default: return cli_usage_error(VERB, "unknown option");
        }
    }
    int nm = argc - optind;
    if (nm < 1) return cli_usage_error(VERB, "no mesh given");
    if (nm > MAX_MESHES) return cli_usage_error(VERB, "at most %d meshes", MAX_MESHES);
    if (!out) return cli_usage_error(VERB, "no output file (-o)");
    if (nscalar_files > 1 && nscalar_files != nm)
        return cli_usage_error(VERB, "%d --scalars for %d meshes (give one, or one per mesh)",
                               nscalar_files, nm);
    if (nlabels > nm) return cli_usage_error(VERB, "%d --label for %d meshes", nlabels, nm);

    es_ctx *ctx = cli_ctx_new(VERB);
    if (!ctx) return CLI_FAIL;
    const char *lab[MAX_MESHES] = {NULL};   /* NULL: the file name (several meshes) */
    for (int i = 0; i < nlabels; i++) lab[i] = labels[i];
    es_render_report rep;
    /* a mesh file out: the same colours on the mesh itself, for other viewers */
    const char *dot = strrchr(out, '.');
    int mesh_out = dot && (!strcasecmp(dot, ".ply") || !strcasecmp(dot, ".glb") ||
                           !strcasecmp(dot, ".vtp"));
    if (mesh_out && (nm != 1 || nscalar_files != 1)) {
        es_ctx_free(ctx);
        return cli_usage_error(VERB, "a coloured mesh (%s) takes one mesh and one --scalars",
                               dot);
    }
    es_status st = mesh_out ? es_figure_color_file(ctx, &spec, argv[optind], scalar_files[0], out,
                                                   &rep)
                            : es_figure_render_files(ctx, &spec, nm,
                                                     (const char *const *)argv + optind,
                                                     nscalar_files, scalar_files, lab, out, &rep);
    if (st != ES_OK) {
        cli_fail(VERB, ctx, st);
        es_ctx_free(ctx);
        return CLI_FAIL;
    }
    if (rep.n_nan_scalars)
        fprintf(stderr, "edgespace %s: warning: %lld missing or non-finite scalars drawn grey\n",
                VERB, (long long)rep.n_nan_scalars);
    if (mesh_out) printf("%s: coloured mesh", out);
    else
        printf("%s: %d x %d, view %.4g,%.4g,%.4g up %.4g,%.4g,%.4g", out, rep.width, rep.height,
               rep.view[0], rep.view[1], rep.view[2], rep.up[0], rep.up[1], rep.up[2]);
    if (nscalar_files) printf(", colour range %.4g..%.4g", rep.vmin, rep.vmax);
    printf("\n");
    es_ctx_free(ctx);
    return CLI_OK;
}
