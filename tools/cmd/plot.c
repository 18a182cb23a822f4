/* tools/cmd/plot.c — `edgespace plot`: the figures of es_plot.h from a CSV
 * table (parsed with libcsv): scatter, lines, scree, histogram, heatmap. */
#include "cli.h"
#include "commands.h"

#include <csv.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define VERB "plot"
#define MAX_Y 32

static void usage(FILE *f)
{
    fputs("usage: edgespace plot KIND TABLE.csv -o OUT.png|.svg|.pdf [options]\n"
          "       edgespace plot STORE.h5 --pca NAME [--pcs A,B] [--color COL | --scree] -o OUT\n"
          "               (the PCA figures; see 'edgespace plot-pca --help')\n\n"
          "KIND is one of:\n"
          "  scatter    points (--x, --y), coloured by the category in --label\n"
          "  lines      one curve per --y column against --x (legend: column names)\n"
          "  scree      bars of --y (variances) as percent of the total, and cumulative\n"
          "  histogram  distribution of --y\n"
          "  heatmap    the table as a matrix; a non-numeric first row / first column\n"
          "             are column / row labels\n\n"
          "Columns are named by header or 1-based number. The first row is a header\n"
          "when it is not all numbers. Empty cells and 'nan' are missing values.\n\n"
          "options:\n"
          "  -o, --output PATH   output file; the extension picks the format\n"
          "      --x COL         x column (default: 1; lines without --x: row number)\n"
          "      --y COL[,COL]   y column(s) (default: 2, or 1 for scree/histogram)\n"
          "      --label COL     category column (scatter)\n"
          "      --title TEXT, --xlabel TEXT, --ylabel TEXT\n"
          "      --logy          log10 y axis (lines)\n"
          "      --bins N        histogram bins (default: Freedman-Diaconis)\n"
          "      --total V       total variance for scree percentages (default: sum)\n"
          "      --cmap NAME     heatmap colours: viridis (default), rdbu, greys\n"
          "      --equal         equal scales on x and y (scatter)\n"
          "      --width W, --height H   size (default 640 x 480)\n"
          "  -h, --help          show this help\n", f);
}

/* ---- a CSV table of strings ---------------------------------------------- */

typedef struct table {
    char **cell;              /* row-major, nrows x ncols, NULL where a row was short */
    int64_t nrows, ncols, cap;
    char **row;               /* the row being read */
    int64_t rowlen, rowcap;
    int oom;
} table;

static void on_field(void *s, size_t len, void *ud)
{
    table *t = ud;
    if (t->oom) return;
    if (t->rowlen == t->rowcap) {
        int64_t nc = t->rowcap ? 2 * t->rowcap : 16;
        char **r = realloc(t->row, (size_t)nc * sizeof *r);
        if (!r) { t->oom = 1; return; }
        t->row = r;
        t->rowcap = nc;
    }
    char *c = malloc(len + 1);
    if (!c) { t->oom = 1; return; }
    memcpy(c, s, len);
    c[len] = 0;
    t->row[t->rowlen++] = c;
}

static void on_row(int term, void *ud)
{
    table *t = ud;
    (void)term;
    if (t->oom) return;
    if (t->nrows == 0 && t->ncols == 0) t->ncols = t->rowlen;
    if (t->rowlen == 0) return;
    if (t->nrows == t->cap) {
        int64_t nc = t->cap ? 2 * t->cap : 64;
        char **c = realloc(t->cell, (size_t)(nc * t->ncols) * sizeof *c);
        if (!c) { t->oom = 1; return; }
        t->cell = c;
        t->cap = nc;
    }
    for (int64_t j = 0; j < t->ncols; j++)
        t->cell[t->nrows * t->ncols + j] = j < t->rowlen ? t->row[j] : NULL;
    for (int64_t j = t->ncols; j < t->rowlen; j++) free(t->row[j]);
    t->rowlen = 0;
    t->nrows++;
}

static void table_free(table *t)
{
    for (int64_t i = 0; i < t->nrows * t->ncols; i++) free(t->cell[i]);
    for (int64_t j = 0; j < t->rowlen; j++) free(t->row[j]);
    free(t->cell);
    free(t->row);
}

static int table_read(const char *path, table *t)
{
    struct csv_parser p;
    char buf[65536];
    size_t n;
    memset(t, 0, sizeof *t);
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "edgespace %s: cannot open '%s': %s\n", VERB, path, strerror(errno));
        return -1;
    }
    if (csv_init(&p, CSV_APPEND_NULL) != 0) {
        fclose(f);
        fprintf(stderr, "edgespace %s: out of memory\n", VERB);
        return -1;
    }
    int bad = 0;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        if (csv_parse(&p, buf, n, on_field, on_row, t) != n) { bad = 1; break; }
    if (!bad) csv_fini(&p, on_field, on_row, t);
    if (bad)
        fprintf(stderr, "edgespace %s: '%s': malformed CSV: %s\n", VERB, path,
                csv_strerror(csv_error(&p)));
    csv_free(&p);
    fclose(f);
    if (t->oom) fprintf(stderr, "edgespace %s: out of memory reading '%s'\n", VERB, path);
    return bad || t->oom ? -1 : 0;
}

static const char *cell(const table *t, int64_t i, int64_t j)
{
    const char *c = t->cell[i * t->ncols + j];
    return c ? c : "";
}

/* NaN for empty/nan/na; 0 and *ok = 0 for text. */
static double to_number(const char *s, int *ok)
{
    char *end;
    while (*s == ' ') s++;
    *ok = 1;
    if (!*s || !strcasecmp(s, "nan") || !strcasecmp(s, "na")) return NAN;
    double v = strtod(s, &end);
    while (*end == ' ') end++;
    if (*end) *ok = 0;
    return v;
}

static int row_is_numeric(const table *t, int64_t i, int64_t from)
{
    int ok;
    for (int64_t j = from; j < t->ncols; j++) {
        to_number(cell(t, i, j), &ok);
        if (!ok) return 0;
    }
    return 1;
}

/* Column index of a header name or 1-based number; -1 if none. */
static int64_t find_column(const table *t, int header, const char *name)
{
    int64_t k;
    if (header)
        for (int64_t j = 0; j < t->ncols; j++)
            if (!strcmp(cell(t, 0, j), name)) return j;
    if (cli_parse_i64(name, &k) == 0 && k >= 1 && k <= t->ncols) return k - 1;
    return -1;
}

/* Numbers of column j from row `first` on; prints an error for text. */
static double *column_values(const table *t, int64_t first, int64_t j, const char *path)
{
    int64_t n = t->nrows - first;
    double *v = malloc((size_t)(n > 0 ? n : 1) * sizeof *v);
    if (!v) return NULL;
    for (int64_t i = 0; i < n; i++) {
        int ok;
        v[i] = to_number(cell(t, first + i, j), &ok);
        if (!ok) {
            fprintf(stderr, "edgespace %s: %s: row %lld, column %lld: '%s' is not a number\n",
                    VERB, path, (long long)(first + i + 1), (long long)(j + 1),
                    cell(t, first + i, j));
            free(v);
            return NULL;
        }
    }
    return v;
}

/* "edgespace plot STORE --pca NAME ..." (issue 3's form) is the PCA figure:
 * any argument ending in .h5, or a --pca/--scree option, sends it there. */
static int wants_pca_figure(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        size_t n = strlen(argv[i]);
        if (!strcmp(argv[i], "--pca") || !strncmp(argv[i], "--pca=", 6) ||
            !strcmp(argv[i], "--scree") || (n > 3 && !strcmp(argv[i] + n - 3, ".h5")))
            return 1;
    }
    return 0;
}

int cmd_plot(int argc, char **argv)
{
    if (wants_pca_figure(argc, argv)) return cmd_plot_pca(argc, argv);

    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'}, {"x", required_argument, NULL, 'x'},
        {"y", required_argument, NULL, 'y'}, {"label", required_argument, NULL, 'l'},
        {"title", required_argument, NULL, 't'}, {"xlabel", required_argument, NULL, 'X'},
        {"ylabel", required_argument, NULL, 'Y'}, {"logy", no_argument, NULL, 'L'},
        {"bins", required_argument, NULL, 'b'}, {"total", required_argument, NULL, 'T'},
        {"cmap", required_argument, NULL, 'c'}, {"equal", no_argument, NULL, 'e'},
        {"width", required_argument, NULL, 'W'}, {"height", required_argument, NULL, 'H'},
        {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    const char *out = NULL, *xcol = NULL, *ycols = NULL, *lcol = NULL;
    es_plot_frame frame = {640, 480, NULL, NULL, NULL, 12};
    int logy = 0, equal = 0, c;
    int64_t bins = 0, v64;
    double total = 0;
    es_colormap cmap = ES_CMAP_VIRIDIS;

    optind = 1;
    while ((c = getopt_long(argc, argv, "o:h", opts, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'x': xcol = optarg; break;
        case 'y': ycols = optarg; break;
        case 'l': lcol = optarg; break;
        case 't': frame.title = optarg; break;
        case 'X': frame.xlabel = optarg; break;
        case 'Y': frame.ylabel = optarg; break;
        case 'L': logy = 1; break;
        case 'e': equal = 1; break;
        case 'b':
            if (cli_parse_i64(optarg, &bins) || bins < 1 || bins > 10000)
                return cli_usage_error(VERB, "--bins wants an integer in 1..10000");
            break;
        case 'T':
            if (cli_parse_double(optarg, &total) || !(total > 0))
                return cli_usage_error(VERB, "--total wants a positive number");
            break;
        case 'c':
            if (!strcmp(optarg, "viridis")) cmap = ES_CMAP_VIRIDIS;
            else if (!strcmp(optarg, "rdbu")) cmap = ES_CMAP_RDBU;
            else if (!strcmp(optarg, "greys")) cmap = ES_CMAP_GREYS;
            else return cli_usage_error(VERB, "unknown colour map '%s'", optarg);
            break;
        case 'W':
        case 'H':
            if (cli_parse_i64(optarg, &v64) || v64 < 16 || v64 > 16384)
                return cli_usage_error(VERB, "--%s wants an integer in 16..16384",
                                       c == 'W' ? "width" : "height");
            if (c == 'W') frame.width = (int)v64;
            else frame.height = (int)v64;
            break;
        case 'h': usage(stdout); return CLI_OK;
        default: return cli_usage_error(VERB, "unknown option");
        }
    }
    if (argc - optind != 2) return cli_usage_error(VERB, "want KIND and TABLE.csv");
    if (!out) return cli_usage_error(VERB, "no output file (-o)");
    const char *kind = argv[optind], *path = argv[optind + 1];
    static const char *const kinds[] = {"scatter", "lines", "scree", "histogram", "heatmap"};
    int k = 0;
    while (k < 5 && strcmp(kind, kinds[k])) k++;
    if (k == 5) return cli_usage_error(VERB, "unknown plot kind '%s'", kind);

    table t;
    if (table_read(path, &t)) {
        table_free(&t);
        return CLI_FAIL;
    }
    int rc = CLI_FAIL;
    es_ctx *ctx = NULL;
    double *x = NULL, *ys[MAX_Y] = {NULL};
    const char **labels = NULL, **names = NULL;
    es_series series[MAX_Y];
    int64_t yj[MAX_Y], ny = 0, xj = -1;
    int header = t.nrows > 0 && !row_is_numeric(&t, 0, 0);
    int64_t first = header ? 1 : 0, n = t.nrows - first;
    es_status st = ES_OK;
    if (t.ncols < 1 || n < 1) {
        fprintf(stderr, "edgespace %s: '%s' has no data rows\n", VERB, path);
        goto done;
    }
    if (!(ctx = cli_ctx_new(VERB))) goto done;

    if (k != 4) {
        /* columns */
        char buf[4096], *save = NULL;
        const char *yd = ycols ? ycols : (k == 2 || k == 3) ? "1" : "2";
        snprintf(buf, sizeof buf, "%s", yd);
        for (char *s = strtok_r(buf, ",", &save); s; s = strtok_r(NULL, ",", &save)) {
            if (ny == MAX_Y) {
                rc = cli_usage_error(VERB, "at most %d --y columns", MAX_Y);
                goto done;
            }
            if ((yj[ny] = find_column(&t, header, s)) < 0) {
                fprintf(stderr, "edgespace %s: '%s' has no column '%s'\n", VERB, path, s);
                goto done;
            }
            if (!(ys[ny] = column_values(&t, first, yj[ny], path))) goto done;
            ny++;
        }
        if (k <= 1 && (xcol || k == 0)) {
            if ((xj = find_column(&t, header, xcol ? xcol : "1")) < 0) {
                fprintf(stderr, "edgespace %s: '%s' has no column '%s'\n", VERB, path,
                        xcol ? xcol : "1");
                goto done;
            }
            if (!(x = column_values(&t, first, xj, path))) goto done;
        } else if (k == 1) {
            if (!(x = malloc((size_t)n * sizeof *x))) goto oom;
            for (int64_t i = 0; i < n; i++) x[i] = (double)(i + 1);
        }
    }
    switch (k) {
    case 0: {
        es_scatter_spec s;
        es_scatter_spec_init(&s);
        s.frame = frame;
        if (!s.frame.xlabel && header) s.frame.xlabel = cell(&t, 0, xj);
        if (!s.frame.ylabel && header) s.frame.ylabel = cell(&t, 0, yj[0]);
        s.n = n, s.x = x, s.y = ys[0], s.equal_aspect = equal;
        if (lcol) {
            int64_t lj = find_column(&t, header, lcol);
            if (lj < 0) {
                fprintf(stderr, "edgespace %s: '%s' has no column '%s'\n", VERB, path, lcol);
                goto done;
            }
            if (!(labels = malloc((size_t)n * sizeof *labels))) goto oom;
            for (int64_t i = 0; i < n; i++) labels[i] = cell(&t, first + i, lj);
            s.labels = labels;
            s.legend_title = header ? cell(&t, 0, lj) : NULL;
        }
        st = es_plot_scatter(ctx, &s, out, NULL);
        break;
    }
    case 1: {
        es_lines_spec s;
        es_lines_spec_init(&s);
        s.frame = frame;
        if (!s.frame.xlabel && header && xj >= 0) s.frame.xlabel = cell(&t, 0, xj);
        for (int64_t j = 0; j < ny; j++)
            series[j] = (es_series){header ? cell(&t, 0, yj[j]) : NULL, n, x, ys[j]};
        s.nseries = ny, s.series = series, s.logy = logy, s.markers = n <= 50;
        st = es_plot_lines(ctx, &s, out, NULL);
        break;
    }
    case 2: {
        es_scree_spec s;
        es_scree_spec_init(&s);
        if (frame.title) s.frame.title = frame.title;
        if (frame.xlabel) s.frame.xlabel = frame.xlabel;
        if (frame.ylabel) s.frame.ylabel = frame.ylabel;
        s.frame.width = frame.width, s.frame.height = frame.height;
        s.n = n, s.variance = ys[0], s.total = total;
        st = es_plot_scree(ctx, &s, out, NULL);
        break;
    }
    case 3: {
        es_histogram_spec s;
        es_histogram_spec_init(&s);
        if (frame.title) s.frame.title = frame.title;
        s.frame.xlabel = frame.xlabel ? frame.xlabel : header ? cell(&t, 0, yj[0]) : NULL;
        if (frame.ylabel) s.frame.ylabel = frame.ylabel;
        s.frame.width = frame.width, s.frame.height = frame.height;
        s.n = n, s.values = ys[0], s.nbins = bins;
        st = es_plot_histogram(ctx, &s, out, NULL);
        break;
    }
    case 4: {
        int rowlab = 1;
        for (int64_t i = first; i < t.nrows && rowlab; i++) {
            int ok;
            to_number(cell(&t, i, 0), &ok);
            rowlab = !ok;
        }
        int64_t c0 = rowlab ? 1 : 0, nc = t.ncols - c0;
        if (nc < 1) {
            fprintf(stderr, "edgespace %s: '%s' has no numeric columns\n", VERB, path);
            goto done;
        }
        double *m = malloc((size_t)(n * nc) * sizeof *m);
        if (!m) goto oom;
        ys[0] = m;
        for (int64_t j = 0; j < nc; j++) {
            double *col = column_values(&t, first, c0 + j, path);
            if (!col) goto done;
            memcpy(m + j * n, col, (size_t)n * sizeof *m);
            free(col);
        }
        if (!(labels = malloc((size_t)n * sizeof *labels))) goto oom;
        if (!(names = malloc((size_t)nc * sizeof *names))) goto oom;
        for (int64_t i = 0; i < n; i++) labels[i] = cell(&t, first + i, 0);
        for (int64_t j = 0; j < nc; j++) names[j] = header ? cell(&t, 0, c0 + j) : "";
        es_heatmap_spec s;
        es_heatmap_spec_init(&s);
        s.frame = frame;
        s.values = (es_mat){m, n, nc, n};
        s.row_labels = rowlab ? labels : NULL;
        s.col_labels = header ? names : NULL;
        s.cmap = cmap;
        st = es_plot_heatmap(ctx, &s, out, NULL);
        break;
    }
    }
    rc = st == ES_OK ? CLI_OK : cli_fail(VERB, ctx, st);
    goto done;
oom:
    fprintf(stderr, "edgespace %s: out of memory\n", VERB);
done:
    free(x);
    for (int j = 0; j < MAX_Y; j++) free(ys[j]);
    free(labels);
    free(names);
    table_free(&t);
    es_ctx_free(ctx);
    return rc;
}
