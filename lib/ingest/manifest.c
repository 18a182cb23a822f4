/* lib/ingest/manifest.c — the CSV manifest of an ingest (datasets-spec/
 * manifest-format.md).
 *
 * The table comes from core/csv_table.h in strict mode with UTF-8 checked
 * (the store keeps labels as UTF-8 strings): RFC 4180 quoting, CR, LF and
 * CRLF record ends, blank lines skipped, a leading byte-order mark dropped,
 * and the line every record starts on, so that every message names the
 * manifest and a line. This file adds the manifest's own rules: a header
 * with unique names and a `file` column, one field per column in every row,
 * and unique row ids.
 */
#include "core/core_private.h"
#include "core/csv_table.h"
#include "core/files.h"
#include "core/strmap.h"
#include "edgespace/es_ingest.h"

void es_id_from_path(const char *path, char *buf, size_t n)
{
    es__path_stem(path, buf, n);
}

void es_manifest_free(es_ctx *ctx, es_manifest *m)
{
    if (!m) return;
    for (int64_t c = 0; m->colnames && c < m->ncols; c++) es__free(ctx, m->colnames[c]);
    for (int64_t i = 0; m->cells && i < m->nrows * m->ncols; i++) es__free(ctx, m->cells[i]);
    for (int64_t r = 0; m->ids && r < m->nrows; r++) es__free(ctx, m->ids[r]);
    es__free(ctx, m->colnames);
    es__free(ctx, m->cells);
    es__free(ctx, m->lines);
    es__free(ctx, m->ids);
    es__free(ctx, m->path);
    es__free(ctx, m->dir);
    es__free(ctx, m);
}

/* Header and row checks once the whole file is parsed. */
static es_status check(es_ctx *ctx, es_manifest *m, const char *name)
{
    m->file_col = m->id_col = -1;
    if (m->ncols == 0) ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' is empty (no header line)", name);
    for (int64_t c = 0; c < m->ncols; c++) {
        const char *h = m->colnames[c];
        if (!*h)
            ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' line %lld: header field %lld is empty",
                    name, (long long)1, (long long)c + 1);
        if (strchr(h, '/') || !strcmp(h, ".") || !strcmp(h, ".."))
            ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' header: column name '%s' may not contain "
                    "'/' or be '.' or '..'", name, h);
        for (int64_t d = 0; d < c; d++)
            if (!strcmp(h, m->colnames[d]))
                ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' header: column '%s' appears twice",
                        name, h);
        if (!strcmp(h, "file")) m->file_col = c;
        if (!strcmp(h, "id")) m->id_col = c;
    }
    if (m->file_col < 0)
        ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' header has no 'file' column (columns: %s%s)",
                name, m->colnames[0], m->ncols > 1 ? ", ..." : "");
    if (m->nrows > 0 && !(m->ids = es__alloc_array(ctx, m->nrows, sizeof *m->ids)))
        return ES_ENOMEM;
    for (int64_t r = 0; r < m->nrows; r++) {
        const char *file = m->cells[r * m->ncols + m->file_col];
        char idbuf[1024];  /* a file name's stem: NAME_MAX (255) bytes at most */
        const char *id;
        if (!*file)
            ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' line %lld: empty 'file' field", name,
                    (long long)m->lines[r]);
        if (m->id_col >= 0) {
            /* the cell itself: a copy into a fixed buffer would cut long ids */
            id = m->cells[r * m->ncols + m->id_col];
            if (!*id)
                ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' line %lld: empty 'id' field", name,
                        (long long)m->lines[r]);
        } else {
            es_id_from_path(file, idbuf, sizeof idbuf);
            id = idbuf;
            if (!*id)
                ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' line %lld: cannot make an id from "
                        "file '%s'", name, (long long)m->lines[r], file);
        }
        if (!(m->ids[r] = es__strdup(ctx, id))) return ES_ENOMEM;
    }
    /* Ids name rows everywhere: refuse repeats, naming the first line */
    es__strmap seen;
    es_status rc = es__strmap_init(ctx, &seen, m->nrows);
    for (int64_t r = 0; r < m->nrows && rc == ES_OK; r++) {
        int64_t q;
        if ((rc = es__strmap_put(ctx, &seen, m->ids[r], r, &q)) == ES_OK && q >= 0)
            rc = es__fail(ctx, ES_EFORMAT, "manifest '%s' line %lld: id '%s' repeats line "
                          "%lld%s", name, (long long)m->lines[r], m->ids[r],
                          (long long)m->lines[q], m->id_col < 0 ? " (ids are file names "
                          "without extension; add an 'id' column)" : "");
    }
    es__strmap_clear(ctx, &seen);
    return rc;
}

/* Move the table's fields into m: the header into colnames, the other
 * records into cells, each checked to have the header's field count. */
static es_status take_table(es_ctx *ctx, es__csv_table *t, es_manifest *m, const char *name)
{
    if (t->nrecords == 0) return ES_OK;   /* no header: check() says so */
    m->ncols = es__csv_nfields(t, 0);
    for (int64_t r = 1; r < t->nrecords; r++)
        if (es__csv_nfields(t, r) != m->ncols)
            ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' line %lld: %lld fields, but the header "
                    "has %lld", name, (long long)t->line[r], (long long)es__csv_nfields(t, r),
                    (long long)m->ncols);
    /* the records are contiguous in t->fields: header first, then the rows */
    int64_t nrows = t->nrecords - 1, ncells = nrows * m->ncols;
    char **colnames = es__alloc_array(ctx, m->ncols, sizeof *colnames);
    char **cells = es__alloc_array(ctx, ncells + 1, sizeof *cells);
    int64_t *lines = es__alloc_array(ctx, nrows + 1, sizeof *lines);
    if (!colnames || !cells || !lines) {
        es__free(ctx, colnames);
        es__free(ctx, cells);
        es__free(ctx, lines);
        return ES_ENOMEM;
    }
    memcpy(colnames, t->fields, (size_t)m->ncols * sizeof *colnames);
    memcpy(cells, t->fields + m->ncols, (size_t)ncells * sizeof *cells);
    memcpy(lines, t->line + 1, (size_t)nrows * sizeof *lines);
    /* the strings are m's now: the table's clear must not free them */
    memset(t->fields, 0, (size_t)(m->ncols + ncells) * sizeof *t->fields);
    m->colnames = colnames;
    m->cells = cells;
    m->lines = lines;
    m->nrows = nrows;
    return ES_OK;
}

es_status es_manifest_parse(es_ctx *ctx, const char *name, const char *dir, const char *buf,
                            size_t len, es_manifest **out)
{
    es__csv_table t;
    es_manifest *m;
    es_status rc;
    *out = NULL;
    if (!name) name = "(memory)";
    if (!(m = es__calloc(ctx, 1, sizeof *m))) return ES_ENOMEM;
    if (!(m->path = es__strdup(ctx, name)) || !(m->dir = es__strdup(ctx, dir ? dir : "."))) {
        es_manifest_free(ctx, m);
        return ES_ENOMEM;
    }
    if ((rc = es__csv_parse(ctx, "manifest", name, buf, len, ES__CSV_STRICT | ES__CSV_UTF8,
                            &t)) == ES_OK) {
        rc = take_table(ctx, &t, m, name);
        es__csv_table_clear(ctx, &t);
    }
    if (rc == ES_OK) rc = check(ctx, m, name);
    if (rc != ES_OK) {
        es_manifest_free(ctx, m);
        return rc;
    }
    *out = m;
    return ES_OK;
}

es_status es_manifest_read(es_ctx *ctx, const char *path, es_manifest **out)
{
    char *buf, *dir;
    size_t len;
    es_status rc;
    *out = NULL;
    if (!path) ES_FAIL(ctx, ES_EINVAL, "manifest: NULL path");
    /* not ES__READ_REGULAR: a manifest may come through a pipe */
    if ((rc = es__read_file(ctx, path, ES__READ_NOTFOUND, &buf, &len)) != ES_OK)
        return es__fail(ctx, rc, "manifest: %s", es_ctx_errmsg(ctx));
    if (!(dir = es__path_dir(ctx, path))) {
        es__free(ctx, buf);
        return ES_ENOMEM;
    }
    rc = es_manifest_parse(ctx, path, dir, buf, len, out);
    es__free(ctx, dir);
    es__free(ctx, buf);
    return rc;
}
