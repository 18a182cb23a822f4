/* lib/ingest/manifest.c — the CSV manifest of an ingest (datasets-spec/
 * manifest-format.md), parsed with libcsv.
 *
 * libcsv does the RFC 4180 work (quoted fields with commas, doubled quotes
 * and newlines; CR, LF and CRLF record ends; blank lines). It does not
 * report positions, so the buffer is fed one physical line at a time and
 * each record remembers the line it started on: every message names the
 * manifest and a line. A leading UTF-8 byte-order mark is skipped, and every
 * field must be valid UTF-8 (the store keeps labels as UTF-8 strings).
 */
#include "core/core_private.h"
#include "edgespace/es_ingest.h"

#include <csv.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct mstate {
    es_ctx *ctx;
    const char *name;
    es_status rc;
    int64_t line;          /* physical line being fed (1-based) */
    int64_t rec_line;      /* line where the current record started */
    int64_t field_line;    /* line where the record's last complete field ended */
    char **fields;         /* current record */
    int64_t nf, capf;
    es_manifest *m;
    int64_t capr;          /* rows allocated in m->cells / m->lines */
    bool have_header;
} mstate;

/* Length of the valid UTF-8 prefix of s[0..n) (n if all valid). */
static size_t utf8_valid_prefix(const unsigned char *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        unsigned c = s[i];
        size_t k;
        uint32_t cp;
        if (c < 0x80) { i++; continue; }
        if (c >= 0xc2 && c <= 0xdf) { k = 1; cp = c & 0x1f; }
        else if (c >= 0xe0 && c <= 0xef) { k = 2; cp = c & 0x0f; }
        else if (c >= 0xf0 && c <= 0xf4) { k = 3; cp = c & 0x07; }
        else return i;
        for (size_t j = 1; j <= k; j++) {
            if (i + j >= n || (s[i + j] & 0xc0) != 0x80) return i;
            cp = (cp << 6) | (s[i + j] & 0x3f);
        }
        if ((k == 2 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) ||
            (k == 3 && (cp < 0x10000 || cp > 0x10ffff)))
            return i;
        i += k + 1;
    }
    return n;
}

static void on_field(void *s, size_t len, void *data)
{
    mstate *st = data;
    es_ctx *ctx = st->ctx;
    char *f;
    size_t ok;
    if (st->rc) return;
    st->field_line = st->line;
    if ((ok = utf8_valid_prefix(s, s ? len : 0)) < (s ? len : 0)) {
        st->rc = es__fail(ctx, ES_EFORMAT, "manifest '%s' line %lld, field %lld: invalid "
                          "UTF-8 at byte %zu", st->name, (long long)st->rec_line,
                          (long long)st->nf + 1, ok + 1);
        return;
    }
    if (st->nf == st->capf) {
        int64_t cap = st->capf ? 2 * st->capf : 16;
        char **p = es__realloc(ctx, st->fields, (size_t)cap * sizeof *p);
        if (!p) { st->rc = ES_ENOMEM; return; }
        st->fields = p;
        st->capf = cap;
    }
    if (!(f = es__malloc(ctx, len + 1))) { st->rc = ES_ENOMEM; return; }
    if (len) memcpy(f, s, len);
    f[len] = '\0';
    st->fields[st->nf++] = f;
}

static void drop_fields(mstate *st)
{
    for (int64_t i = 0; i < st->nf; i++) es__free(st->ctx, st->fields[i]);
    st->nf = 0;
}

static void on_record(int c, void *data)
{
    mstate *st = data;
    es_ctx *ctx = st->ctx;
    es_manifest *m = st->m;
    (void)c;
    if (st->rc) { drop_fields(st); return; }
    if (st->nf == 0 || (st->nf == 1 && !st->fields[0][0])) { drop_fields(st); return; }
    if (!st->have_header) {
        m->ncols = st->nf;
        m->colnames = st->fields;
        st->fields = NULL;
        st->nf = st->capf = 0;
        st->have_header = true;
        return;
    }
    if (st->nf != m->ncols) {
        st->rc = es__fail(ctx, ES_EFORMAT, "manifest '%s' line %lld: %lld fields, but the "
                          "header has %lld", st->name, (long long)st->rec_line,
                          (long long)st->nf, (long long)m->ncols);
        drop_fields(st);
        return;
    }
    if (m->nrows == st->capr) {
        int64_t cap = st->capr ? 2 * st->capr : 64, cells;
        char **p;
        int64_t *l;
        size_t bytes;
        if (!es__mul_i64(cap, m->ncols, &cells) ||
            !es__mul_size((size_t)cells, sizeof *p, &bytes)) {
            st->rc = es__fail(ctx, ES_ENOMEM, "manifest '%s': too large", st->name);
            drop_fields(st);
            return;
        }
        if (!(p = es__realloc(ctx, m->cells, bytes))) { st->rc = ES_ENOMEM; drop_fields(st); return; }
        m->cells = p;
        if (!(l = es__realloc(ctx, m->lines, (size_t)cap * sizeof *l))) {
            st->rc = ES_ENOMEM;
            drop_fields(st);
            return;
        }
        m->lines = l;
        st->capr = cap;
    }
    memcpy(m->cells + m->nrows * m->ncols, st->fields, (size_t)m->ncols * sizeof(char *));
    m->lines[m->nrows] = st->rec_line;
    m->nrows++;
    st->nf = 0;
}

void es_id_from_path(const char *path, char *buf, size_t n)
{
    const char *base = strrchr(path, '/'), *dot;
    size_t len;
    base = base ? base + 1 : path;
    dot = strrchr(base, '.');
    len = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (!n) return;
    if (len >= n) len = n - 1;
    memcpy(buf, base, len);
    buf[len] = '\0';
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
    /* Ids name rows everywhere: refuse repeats (O(n^2) compares; a manifest
     * holds thousands of rows at most). */
    for (int64_t r = 1; r < m->nrows; r++)
        for (int64_t q = 0; q < r; q++)
            if (!strcmp(m->ids[q], m->ids[r]))
                ES_FAIL(ctx, ES_EFORMAT, "manifest '%s' line %lld: id '%s' repeats line %lld%s",
                        name, (long long)m->lines[r], m->ids[r], (long long)m->lines[q],
                        m->id_col < 0 ? " (ids are file names without extension; add an "
                        "'id' column)" : "");
    return ES_OK;
}

es_status es_manifest_parse(es_ctx *ctx, const char *name, const char *dir, const char *buf,
                            size_t len, es_manifest **out)
{
    struct csv_parser p;
    mstate st;
    es_manifest *m;
    es_status rc = ES_OK;
    size_t pos = 0;
    *out = NULL;
    if (!name) name = "(memory)";
    if (!(m = es__calloc(ctx, 1, sizeof *m))) return ES_ENOMEM;
    if (!(m->path = es__strdup(ctx, name)) || !(m->dir = es__strdup(ctx, dir ? dir : "."))) {
        es_manifest_free(ctx, m);
        return ES_ENOMEM;
    }
    memset(&st, 0, sizeof st);
    st.ctx = ctx;
    st.name = name;
    st.m = m;
    st.line = 1;
    if (csv_init(&p, CSV_STRICT | CSV_STRICT_FINI | CSV_APPEND_NULL) != 0) {
        es_manifest_free(ctx, m);
        ES_FAIL(ctx, ES_ENOMEM, "manifest '%s': cannot start the CSV parser", name);
    }
    if (len >= 3 && !memcmp(buf, "\xef\xbb\xbf", 3)) pos = 3;
    while (pos < len && !st.rc) {
        /* one physical line: up to LF, CRLF or a lone CR (all record ends) */
        size_t e = pos;
        bool eol = false;
        while (e < len && buf[e] != '\n' && buf[e] != '\r') e++;
        if (e < len) {
            eol = true;
            e += buf[e] == '\r' && e + 1 < len && buf[e + 1] == '\n' ? 2 : 1;
        }
        size_t seg = e - pos;
        /* between records (libcsv's ROW_NOT_BEGUN state is 0), a record
         * that starts now starts on this line, even if its first field is
         * quoted over several lines */
        if (p.pstate == 0) st.rec_line = st.line;
        if (csv_parse(&p, buf + pos, seg, on_field, on_record, &st) != seg && !st.rc) {
            st.rc = es__fail(ctx, ES_EFORMAT, "manifest '%s' line %lld: malformed CSV (%s; "
                             "a quote inside an unquoted field, or text after a closing "
                             "quote)", name, (long long)st.line, csv_strerror(csv_error(&p)));
        }
        pos += seg;
        if (eol) st.line++;
    }
    /* an open quoted field began right after the record's last complete
     * field (on the line of its comma), or with the record */
    if (!st.rc && csv_fini(&p, on_field, on_record, &st) != 0 && !st.rc)
        st.rc = es__fail(ctx, ES_EFORMAT, "manifest '%s' line %lld: unterminated quoted field "
                         "(opened on line %lld)", name, (long long)st.line,
                         (long long)(st.nf ? st.field_line : st.rec_line));
    csv_free(&p);
    drop_fields(&st);
    es__free(ctx, st.fields);
    rc = st.rc;
    if (!rc) rc = check(ctx, m, name);
    if (rc) {
        es_manifest_free(ctx, m);
        return rc;
    }
    *out = m;
    return ES_OK;
}

es_status es_manifest_read(es_ctx *ctx, const char *path, es_manifest **out)
{
    FILE *f;
    char *buf = NULL, *dir;
    size_t cap = 0, len = 0;
    es_status rc;
    const char *slash;
    *out = NULL;
    if (!path) ES_FAIL(ctx, ES_EINVAL, "manifest: NULL path");
    if (!(f = fopen(path, "rb")))
        ES_FAIL(ctx, errno == ENOENT ? ES_ENOTFOUND : ES_EIO, "manifest '%s': cannot open: %s",
                path, strerror(errno));
    for (;;) {
        size_t r;
        if (len == cap) {
            char *p;
            cap = cap ? 2 * cap : 1 << 16;
            if (!(p = es__realloc(ctx, buf, cap))) {
                fclose(f);
                es__free(ctx, buf);
                return ES_ENOMEM;
            }
            buf = p;
        }
        r = fread(buf + len, 1, cap - len, f);
        len += r;
        if (r == 0) break;
    }
    if (ferror(f)) {
        fclose(f);
        es__free(ctx, buf);
        ES_FAIL(ctx, ES_EIO, "manifest '%s': read error", path);
    }
    fclose(f);
    slash = strrchr(path, '/');
    if (!slash) dir = es__strdup(ctx, ".");
    else if (slash == path) dir = es__strdup(ctx, "/");
    else if ((dir = es__malloc(ctx, (size_t)(slash - path) + 1))) {
        memcpy(dir, path, (size_t)(slash - path));
        dir[slash - path] = '\0';
    }
    if (!dir) {
        es__free(ctx, buf);
        return ES_ENOMEM;
    }
    rc = es_manifest_parse(ctx, path, dir, buf, len, out);
    es__free(ctx, dir);
    es__free(ctx, buf);
    return rc;
}
