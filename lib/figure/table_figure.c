/* lib/figure/table_figure.c — the figures of a CSV table (es_figure_table,
 * behind `edgespace plot`): the table is read once through core's CSV
 * reader, its header detected, columns found by name or number and turned
 * into numbers with missing values, and handed to one of es_plot.h's
 * plots. Here rather than in the command so that notebooks and the Python
 * package draw a table exactly as the command does.
 */
#include "figure/figure_pkg.h"
#include "core/csv_table.h"
#include "core/files.h"
#include "core/suggest.h"
#include "core/text.h"
#include "edgespace/es_figure.h"

#include <math.h>
#include <strings.h>

int es__figure_cell_number(const char *s, double *v)
{
    const char *e;
    while (*s == ' ' || *s == '\t') s++;
    e = s + strlen(s);
    while (e > s && (e[-1] == ' ' || e[-1] == '\t')) e--;
    size_t n = (size_t)(e - s);
    *v = 0;
    if (n == 0 || (n == 3 && !strncasecmp(s, "nan", 3)) || (n == 2 && !strncasecmp(s, "na", 2))) {
        *v = NAN;
        return 0;
    }
    /* es__parse_double is strtod's value; it stops at a delimiter, so
     * "1/2" or "3 4" ends early and is text */
    return es__parse_double(s, e, v) == e ? 0 : -1;
}

void es_figure_table_spec_init(es_figure_table_spec *spec)
{
    memset(spec, 0, sizeof *spec);
    spec->kind = ES_TABLE_SCATTER;
    spec->frame.width = 640;
    spec->frame.height = 480;
    spec->frame.font_size = 12;
    spec->cmap = ES_CMAP_VIRIDIS;
}

int es_figure_table_kind_from_name(const char *name)
{
    static const char *const names[] = {"scatter", "lines", "scree", "histogram", "heatmap"};
    for (int k = 0; name && k < 5; k++)
        if (!strcmp(name, names[k])) return k;
    return -1;
}

typedef struct table {
    es__csv_table csv;
    const char *path;
    int64_t ncols;   /* fields of the first record: the table's width */
    int header;      /* record 0 names the columns */
    int64_t first;   /* first data record (1 under a header) */
    int64_t n;       /* data rows */
} table;

/* Cell (i, j) of the records, i counting the header; "" where a record is
 * short. */
static const char *cell(const table *t, int64_t i, int64_t j)
{
    return es__csv_field(&t->csv, i, j);
}

static int row_is_numeric(const table *t, int64_t i)
{
    double v;
    for (int64_t j = 0; j < t->ncols; j++)
        if (es__figure_cell_number(cell(t, i, j), &v)) return 0;
    return 1;
}

/* Column index of a header name or 1-based number; ES_ENOTFOUND if none. */
static es_status find_column(es_ctx *ctx, const table *t, const char *name, int64_t *col)
{
    int64_t k;
    size_t len = strlen(name);
    if (t->header)
        for (int64_t j = 0; j < t->ncols; j++)
            if (!strcmp(cell(t, 0, j), name)) {
                *col = j;
                return ES_OK;
            }
    if (len && es__parse_int64(name, name + len, &k) == name + len && k >= 1 &&
        k <= t->ncols) {
        *col = k - 1;
        return ES_OK;
    }
    es__suggest sg;
    char hint[400];
    es__suggest_init(&sg, name);
    for (int64_t j = 0; t->header && j < t->ncols; j++) es__suggest_add(&sg, cell(t, 0, j));
    es__suggest_format(&sg, "columns", hint, sizeof hint);
    ES_FAIL(ctx, ES_ENOTFOUND, "'%s' has no column '%s'%s", t->path, name, hint);
}

/* The n numbers of column j into v; text is an error naming line and column. */
static es_status column_values(es_ctx *ctx, const table *t, int64_t j, double *v)
{
    for (int64_t i = 0; i < t->n; i++) {
        int64_t r = t->first + i;
        if (es__figure_cell_number(cell(t, r, j), &v[i]))
            ES_FAIL(ctx, ES_EFORMAT, "%s: line %lld, column %lld: '%s' is not a number",
                    t->path, (long long)t->csv.line[r], (long long)(j + 1), cell(t, r, j));
    }
    return ES_OK;
}

/* A column's header name, or NULL without a header. */
static const char *col_name(const table *t, int64_t j)
{
    return t->header && j >= 0 ? cell(t, 0, j) : NULL;
}

static es_status read_table(es_ctx *ctx, const char *path, table *t)
{
    char *buf = NULL;
    size_t len;
    es_status rc;
    memset(t, 0, sizeof *t);
    t->path = path;
    /* any readable file, a pipe too (`<(...)`): es__csv_read would want a
     * regular one; its message names the path as "cannot open 'x': why" */
    if ((rc = es__read_file(ctx, path, 0, &buf, &len)) != ES_OK) return rc;
    rc = es__csv_parse(ctx, "table", path, buf, len, ES__CSV_STRICT, &t->csv);
    es__free(ctx, buf);
    if (rc != ES_OK) return rc;
    t->ncols = t->csv.nrecords > 0 ? es__csv_nfields(&t->csv, 0) : 0;
    t->header = t->csv.nrecords > 0 && !row_is_numeric(t, 0);
    t->first = t->header ? 1 : 0;
    t->n = t->csv.nrecords - t->first;
    if (t->ncols < 1 || t->n < 1) ES_FAIL(ctx, ES_EFORMAT, "'%s' has no data rows", path);
    return ES_OK;
}

/* Frame of a plot whose spec_init set defaults (scree, histogram): the
 * caller's title, labels and font where given, its size always. */
static void frame_over(es_plot_frame *dst, const es_plot_frame *src)
{
    if (src->title) dst->title = src->title;
    if (src->xlabel) dst->xlabel = src->xlabel;
    if (src->ylabel) dst->ylabel = src->ylabel;
    dst->width = src->width;
    dst->height = src->height;
    dst->font_size = src->font_size;
}

static es_status draw_heatmap(es_ctx *ctx, const es_figure_table_spec *spec, const table *t,
                              const char *out, es_plot_info *info)
{
    double v;
    int rowlab = 1;   /* a first column of text only holds the row names */
    for (int64_t i = t->first; i < t->csv.nrecords && rowlab; i++)
        rowlab = es__figure_cell_number(cell(t, i, 0), &v) != 0;
    int64_t c0 = rowlab ? 1 : 0, nc = t->ncols - c0, n = t->n;
    if (nc < 1) ES_FAIL(ctx, ES_EFORMAT, "'%s' has no numeric columns", t->path);
    double *m = es__alloc_array(ctx, n * nc, sizeof *m);
    const char **rows = es__alloc_array(ctx, n, sizeof *rows);
    const char **cols = es__alloc_array(ctx, nc, sizeof *cols);
    es_status rc = m && rows && cols ? ES_OK : ES_ENOMEM;
    for (int64_t j = 0; j < nc && rc == ES_OK; j++) rc = column_values(ctx, t, c0 + j, m + j * n);
    if (rc == ES_OK) {
        for (int64_t i = 0; i < n; i++) rows[i] = cell(t, t->first + i, 0);
        for (int64_t j = 0; j < nc; j++) cols[j] = t->header ? cell(t, 0, c0 + j) : "";
        es_heatmap_spec s;
        es_heatmap_spec_init(&s);
        s.frame = spec->frame;
        s.values = (es_mat){m, n, nc, n};
        s.row_labels = rowlab ? rows : NULL;
        s.col_labels = t->header ? cols : NULL;
        s.cmap = spec->cmap;
        rc = es_plot_heatmap(ctx, &s, out, info);
    }
    es__free(ctx, m);
    es__free(ctx, rows);
    es__free(ctx, cols);
    return rc;
}

/* Scatter, lines, scree, histogram: x (if any) and the y columns as
 * numbers, then the plot. */
static es_status draw_xy(es_ctx *ctx, const es_figure_table_spec *spec, const table *t,
                         const char *out, es_plot_info *info)
{
    es_table_kind kind = spec->kind;
    int one_column = kind == ES_TABLE_SCREE || kind == ES_TABLE_HISTOGRAM;
    const char *ydefault = one_column ? "1" : "2";
    int64_t ny = spec->ny > 0 ? spec->ny : 1, n = t->n, xj = -1, lj = -1;
    const char *const *ynames = spec->ny > 0 ? spec->y : &ydefault;
    /* ny y columns, then x */
    double *v = es__alloc_array(ctx, (ny + 1) * n, sizeof *v), *x = v ? v + ny * n : NULL;
    int64_t *yj = es__alloc_array(ctx, ny, sizeof *yj);
    es_series *series = kind == ES_TABLE_LINES ? es__alloc_array(ctx, ny, sizeof *series) : NULL;
    const char **labels = NULL;
    es_status rc = v && yj && (series || kind != ES_TABLE_LINES) ? ES_OK : ES_ENOMEM;
    for (int64_t k = 0; k < ny && rc == ES_OK; k++)
        if ((rc = find_column(ctx, t, ynames[k], &yj[k])) == ES_OK)
            rc = column_values(ctx, t, yj[k], v + k * n);
    if (rc == ES_OK && (kind == ES_TABLE_SCATTER || (kind == ES_TABLE_LINES && spec->x))) {
        if ((rc = find_column(ctx, t, spec->x ? spec->x : "1", &xj)) == ES_OK)
            rc = column_values(ctx, t, xj, x);
    } else if (rc == ES_OK && kind == ES_TABLE_LINES) {
        for (int64_t i = 0; i < n; i++) x[i] = (double)(i + 1);
    }
    if (rc == ES_OK && kind == ES_TABLE_SCATTER && spec->label &&
        (rc = find_column(ctx, t, spec->label, &lj)) == ES_OK) {
        if (!(labels = es__alloc_array(ctx, n, sizeof *labels))) rc = ES_ENOMEM;
        for (int64_t i = 0; labels && i < n; i++) labels[i] = cell(t, t->first + i, lj);
    }
    if (rc != ES_OK) goto done;
    switch (kind) {
    case ES_TABLE_SCATTER: {
        es_scatter_spec s;
        es_scatter_spec_init(&s);
        s.frame = spec->frame;
        if (!s.frame.xlabel) s.frame.xlabel = col_name(t, xj);
        if (!s.frame.ylabel) s.frame.ylabel = col_name(t, yj[0]);
        s.n = n, s.x = x, s.y = v, s.equal_aspect = spec->equal;
        s.labels = labels;
        s.legend_title = labels ? col_name(t, lj) : NULL;
        rc = es_plot_scatter(ctx, &s, out, info);
        break;
    }
    case ES_TABLE_LINES: {
        es_lines_spec s;
        es_lines_spec_init(&s);
        s.frame = spec->frame;
        if (!s.frame.xlabel) s.frame.xlabel = col_name(t, xj);
        for (int64_t k = 0; k < ny; k++)
            series[k] = (es_series){col_name(t, yj[k]), n, x, v + k * n};
        /* dots help read a short curve and clutter a long one */
        s.nseries = ny, s.series = series, s.logy = spec->logy, s.markers = n <= 50;
        rc = es_plot_lines(ctx, &s, out, info);
        break;
    }
    case ES_TABLE_SCREE: {
        es_scree_spec s;
        es_scree_spec_init(&s);
        frame_over(&s.frame, &spec->frame);
        s.n = n, s.variance = v, s.total = spec->total;
        rc = es_plot_scree(ctx, &s, out, info);
        break;
    }
    default: {
        es_histogram_spec s;
        es_histogram_spec_init(&s);
        frame_over(&s.frame, &spec->frame);
        if (!spec->frame.xlabel) s.frame.xlabel = col_name(t, yj[0]);
        s.n = n, s.values = v, s.nbins = spec->bins;
        rc = es_plot_histogram(ctx, &s, out, info);
        break;
    }
    }
done:
    es__free(ctx, v);
    es__free(ctx, yj);
    es__free(ctx, series);
    es__free(ctx, labels);
    return rc;
}

es_status es_figure_table(es_ctx *ctx, const es_figure_table_spec *spec, const char *csv_path,
                          const char *out_path, es_plot_info *info)
{
    table t;
    es_status rc;
    if (!spec || !csv_path || !out_path)
        ES_FAIL(ctx, ES_EINVAL, "figure table: NULL spec or path");
    if ((int)spec->kind < 0 || spec->kind > ES_TABLE_HEATMAP)
        ES_FAIL(ctx, ES_EINVAL, "figure table: unknown kind %d", (int)spec->kind);
    if (spec->ny < 0 || (spec->ny > 0 && !spec->y))
        ES_FAIL(ctx, ES_EINVAL, "figure table: %lld y columns", (long long)spec->ny);
    for (int64_t k = 0; k < spec->ny; k++)
        if (!spec->y[k]) ES_FAIL(ctx, ES_EINVAL, "figure table: y column %lld is NULL",
                                 (long long)k + 1);
    if (spec->bins < 0) ES_FAIL(ctx, ES_EINVAL, "figure table: %lld bins", (long long)spec->bins);
    if ((rc = read_table(ctx, csv_path, &t)) == ES_OK)
        rc = spec->kind == ES_TABLE_HEATMAP ? draw_heatmap(ctx, spec, &t, out_path, info)
                                            : draw_xy(ctx, spec, &t, out_path, info);
    es__csv_table_clear(ctx, &t.csv);
    return rc;
}
