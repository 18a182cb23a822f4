/* lib/figure/render_files.c — mesh files drawn side by side, coloured by
 * scalars from CSV files (es_figure_render_files, behind `edgespace
 * render`): the meshes are read, each scalar file's values are matched to
 * the vertices, faces or edges of its mesh by their count, and es_render
 * draws them. Here rather than in the command so that notebooks and the
 * Python package colour a mesh from the same files the same way.
 *
 * A scalar file is one value per line (the first CSV column). CSV records
 * skip blank lines, and a blank line is a missing value here (a one-column
 * file has no other way to write one), so the values are laid out by the
 * line each record starts on, not by record number.
 */
#include "figure/figure_pkg.h"
#include "core/csv_table.h"
#include "core/files.h"
#include "edgespace/es_figure.h"
#include "edgespace/es_io.h"

#include <math.h>
#include <stdlib.h>

/* Line ends in s[0..n) as the CSV reader counts them: LF, CRLF or a lone CR. */
static int64_t line_ends(const char *s, size_t n)
{
    int64_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (s[i] == '\n' || s[i] == '\r') {
            k++;
            if (s[i] == '\r' && i + 1 < n && s[i + 1] == '\n') i++;
        }
    return k;
}

/* Extra lines a record spans: the line breaks inside its quoted fields. */
static int64_t record_breaks(const es__csv_table *t, int64_t r)
{
    int64_t k = 0;
    for (int64_t c = 0; c < es__csv_nfields(t, r); c++) {
        const char *f = es__csv_field(t, r, c);
        k += line_ends(f, strlen(f));
    }
    return k;
}

/* The 0-based index of column `want` (a header name or a 1-based number;
 * NULL: 0) of a table whose first record is `head` (NULL: no header). */
static es_status pick_column(es_ctx *ctx, const char *path, const es__csv_table *t, int has_head,
                             const char *want, int64_t *col)
{
    char *end;
    long k;
    *col = 0;
    if (!want) return ES_OK;
    k = strtol(want, &end, 10);
    if (*want && !*end) {
        if (k < 1 || (t->nrecords > 0 && k > es__csv_nfields(t, 0)))
            ES_FAIL(ctx, ES_ERANGE, "%s: no column %ld (it has %lld)", path, k,
                    (long long)(t->nrecords > 0 ? es__csv_nfields(t, 0) : 0));
        *col = k - 1;
        return ES_OK;
    }
    if (has_head)
        for (int64_t c = 0; c < es__csv_nfields(t, 0); c++)
            if (!strcmp(es__csv_field(t, 0, c), want)) {
                *col = c;
                return ES_OK;
            }
    char cols[300] = "";
    for (int64_t c = 0; has_head && c < es__csv_nfields(t, 0); c++)
        snprintf(cols + strlen(cols), sizeof cols - strlen(cols), "%s%s", c ? ", " : "",
                 es__csv_field(t, 0, c));
    ES_FAIL(ctx, ES_ENOTFOUND, "%s: no column '%s' (%s%s)", path, want,
            has_head ? "columns: " : "no header line; name a column by its number", cols);
}

/* The values of column `want` (pick_column) of a scalar file into *out
 * (es__free), *n of them: one per line after an optional header line, NaN
 * for blank lines and missing cells; the column's header into head[hn]. */
es_status es__read_scalars(es_ctx *ctx, const char *path, const char *want, double **out,
                           int64_t *n, char *head, size_t hn)
{
    char *buf = NULL;
    size_t len, bom;
    es__csv_table t;
    double v, *vals = NULL;
    int64_t nv = 0, next = 1, r = 0, col = 0;
    es_status rc;
    *out = NULL;
    *n = 0;
    /* any readable file, a pipe too: es__read_file's message is
     * "cannot open 'x': why" */
    if ((rc = es__read_file(ctx, path, 0, &buf, &len)) != ES_OK) return rc;
    rc = es__csv_parse(ctx, "scalars", path, buf, len, ES__CSV_STRICT, &t);
    bom = len >= 3 && !memcmp(buf, "\xef\xbb\xbf", 3) ? 3 : 0;
    /* a last line without an end counts */
    int64_t nlines = line_ends(buf + bom, len - bom) +
                     (len > bom && buf[len - 1] != '\n' && buf[len - 1] != '\r');
    es__free(ctx, buf);
    if (rc != ES_OK) return rc;
    /* a first line that is not a number names the column */
    if (t.nrecords > 0 && t.line[0] == 1 &&
        es__figure_cell_number(es__csv_field(&t, 0, 0), &v) != 0) {
        next = 2 + record_breaks(&t, 0);
        r = 1;
    }
    if ((rc = pick_column(ctx, path, &t, r == 1, want, &col)) != ES_OK) {
        es__csv_table_clear(ctx, &t);
        return rc;
    }
    if (head && hn) snprintf(head, hn, "%s", r == 1 ? es__csv_field(&t, 0, col) : "");
    if (!(vals = es__alloc_array(ctx, nlines > 0 ? nlines : 1, sizeof *vals))) rc = ES_ENOMEM;
    for (; rc == ES_OK && r < t.nrecords; r++) {
        const char *f = col < es__csv_nfields(&t, r) ? es__csv_field(&t, r, col) : "";
        for (; next < t.line[r]; next++) vals[nv++] = NAN;   /* blank lines */
        if (es__figure_cell_number(f, &vals[nv++]) != 0)
            rc = es__fail(ctx, ES_EFORMAT, "%s:%lld: '%s' is not a number", path,
                          (long long)t.line[r], f);
        next = t.line[r] + 1 + record_breaks(&t, r);
    }
    for (; rc == ES_OK && next <= nlines; next++) vals[nv++] = NAN;
    es__csv_table_clear(ctx, &t);
    if (rc != ES_OK) {
        es__free(ctx, vals);
        return rc;
    }
    *out = vals;
    *n = nv;
    return ES_OK;
}

/* What the n scalars of file sf colour on mesh i: its vertices, faces or
 * (through the topology, which mesh_out then holds) its edges. */
es_status es__match_scalars(es_ctx *ctx, const char *mesh_path, const es_meshdata *md,
                            const char *sf, int64_t n, es_mesh **mesh_out, es_render_mesh *it)
{
    es_status rc;
    if (n == md->nverts) {
        it->scalar_kind = ES_SCALARS_VERTEX;
        return ES_OK;
    }
    if (n == md->nfaces) {
        it->scalar_kind = ES_SCALARS_FACE;
        return ES_OK;
    }
    /* per edge: the edges of the topology, in es_mesh order */
    if ((rc = es_mesh_new(ctx, md->nverts, md->nfaces, md->faces, NULL, mesh_out)) != ES_OK)
        return es__fail(ctx, rc, "%s: %s", mesh_path, es_ctx_errmsg(ctx));
    int64_t ne = es_mesh_nedges(*mesh_out);
    if (n != ne)
        ES_FAIL(ctx, ES_EMISMATCH, "'%s' has %lld values; '%s' has %lld vertices, %lld edges, "
                "%lld faces", sf, (long long)n, mesh_path, (long long)md->nverts, (long long)ne,
                (long long)md->nfaces);
    it->scalar_kind = ES_SCALARS_EDGE;
    it->nedges = ne;
    it->edges = es_mesh_edges(*mesh_out);
    return ES_OK;
}

/* The colour bar's label for a column header: the quantity and its units for
 * the columns `embed --residuals` writes (lib/study/embed_point.c), the
 * header itself for any other. */
static const char *column_label(const char *head)
{
    static const struct { const char *column, *label; } known[] = {
        {"closure", "closure energy at the vertex (no unit)"},
        {"edge_error", "mean relative edge-length error at the vertex"},
        {"deviation", "distance from the prior / bounding-box diagonal"},
    };
    for (size_t i = 0; i < sizeof known / sizeof *known; i++)
        if (!strcmp(head, known[i].column)) return known[i].label;
    return head;
}

static es_status check_args(es_ctx *ctx, const es_render_spec *spec, int64_t n,
                            const char *const *mesh_paths, int64_t nscalars,
                            const char *const *scalar_paths, const char *out_path)
{
    if (!spec || !out_path || n < 1 || !mesh_paths)
        ES_FAIL(ctx, ES_EINVAL, "render: no meshes, spec or output path");
    if (nscalars != 0 && nscalars != 1 && nscalars != n)
        ES_FAIL(ctx, ES_EINVAL, "render: %lld scalar files for %lld meshes (give one, or one "
                "per mesh)", (long long)nscalars, (long long)n);
    for (int64_t i = 0; i < n; i++)
        if (!mesh_paths[i]) ES_FAIL(ctx, ES_EINVAL, "render: mesh path %lld is NULL",
                                    (long long)i + 1);
    for (int64_t i = 0; i < nscalars; i++)
        if (!scalar_paths || !scalar_paths[i])
            ES_FAIL(ctx, ES_EINVAL, "render: scalar path %lld is NULL", (long long)i + 1);
    return ES_OK;
}

es_status es_figure_render_files(es_ctx *ctx, const es_render_spec *spec, int64_t n,
                                 const char *const *mesh_paths, int64_t nscalars,
                                 const char *const *scalar_paths, const char *const *labels,
                                 const char *out_path, es_render_report *rep)
{
    es_status rc = check_args(ctx, spec, n, mesh_paths, nscalars, scalar_paths, out_path);
    char head[200] = "";   /* the first scalar file's column header */
    if (rc != ES_OK) return rc;
    es_meshdata *md = es__calloc(ctx, (size_t)n, sizeof *md);
    es_mesh **mesh = es__calloc(ctx, (size_t)n, sizeof *mesh);
    es_render_mesh *items = es__calloc(ctx, (size_t)n, sizeof *items);
    /* one array per scalar file: a single file is read once for all meshes */
    double **scal = es__calloc(ctx, (size_t)(nscalars ? nscalars : 1), sizeof *scal);
    int64_t *nscal = es__calloc(ctx, (size_t)(nscalars ? nscalars : 1), sizeof *nscal);
    if (!md || !mesh || !items || !scal || !nscal) rc = ES_ENOMEM;
    for (int64_t i = 0; i < n && rc == ES_OK; i++) {
        const char *path = mesh_paths[i];
        es_render_mesh *it = &items[i];
        if ((rc = es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md[i])) != ES_OK) break;
        it->nverts = md[i].nverts;
        it->nfaces = md[i].nfaces;
        it->xyz = md[i].xyz;
        it->faces = md[i].faces;
        it->label = labels && labels[i] ? labels[i] : n > 1 ? es__path_base(path) : NULL;
        if (nscalars == 0) continue;
        int64_t s = nscalars == 1 ? 0 : i;
        if (!scal[s] && (rc = es__read_scalars(ctx, scalar_paths[s], spec->scalar_column, &scal[s],
                                           &nscal[s], *head ? NULL : head, sizeof head)) != ES_OK)
            break;
        it->scalars = scal[s];
        rc = es__match_scalars(ctx, path, &md[i], scalar_paths[s], nscal[s], &mesh[i], it);
    }
    if (rc == ES_OK) {
        es_render_spec sp = *spec;
        if (!sp.colorbar_label && *head) sp.colorbar_label = column_label(head);
        sp.meshes = items;
        sp.nmeshes = n;
        rc = es_render(ctx, &sp, out_path, rep);
    }
    for (int64_t i = 0; md && mesh && i < n; i++) {
        es_meshdata_clear(ctx, &md[i]);
        es_mesh_free(mesh[i]);
    }
    for (int64_t s = 0; scal && s < nscalars; s++) es__free(ctx, scal[s]);
    es__free(ctx, md);
    es__free(ctx, mesh);
    es__free(ctx, items);
    es__free(ctx, scal);
    es__free(ctx, nscal);
    return rc;
}
