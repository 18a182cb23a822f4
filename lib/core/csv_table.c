/* lib/core/csv_table.c — see csv_table.h. */
#include "core/csv_table.h"
#include "core/files.h"
#include "core/text.h"

#include <csv.h>

typedef struct parse_state {
    es_ctx *ctx;
    const char *what, *name;
    unsigned flags;
    es_status rc;
    int64_t line;          /* physical line being fed (1-based) */
    int64_t rec_line;      /* line where the current record started */
    int64_t field_line;    /* line where the record's last complete field ended */
    int64_t rec_fields;    /* fields of the current record so far */
    es__csv_table *t;
    int64_t cap_fields, cap_records;
} parse_state;

static void on_field(void *s, size_t len, void *data)
{
    parse_state *st = data;
    es__csv_table *t = st->t;
    es_ctx *ctx = st->ctx;
    size_t ok;
    char *f;
    if (st->rc) return;
    st->field_line = st->line;
    if (len && memchr(s, '\0', len)) {
        st->rc = es__fail(ctx, ES_EFORMAT, "%s '%s' line %lld, field %lld: NUL byte",
                          st->what, st->name, (long long)st->rec_line,
                          (long long)st->rec_fields + 1);
        return;
    }
    if ((st->flags & ES__CSV_UTF8) && (ok = es__utf8_valid_prefix(s, s ? len : 0)) < len) {
        st->rc = es__fail(ctx, ES_EFORMAT, "%s '%s' line %lld, field %lld: invalid UTF-8 at "
                          "byte %zu", st->what, st->name, (long long)st->rec_line,
                          (long long)st->rec_fields + 1, ok + 1);
        return;
    }
    int64_t nf = t->field_off[t->nrecords] + st->rec_fields;
    if (nf == st->cap_fields) {
        int64_t cap = st->cap_fields ? 2 * st->cap_fields : 64;
        char **p = es__realloc(ctx, t->fields, (size_t)cap * sizeof *p);
        if (!p) { st->rc = ES_ENOMEM; return; }
        t->fields = p;
        st->cap_fields = cap;
    }
    if (!(f = es__malloc(ctx, len + 1))) { st->rc = ES_ENOMEM; return; }
    if (len) memcpy(f, s, len);
    f[len] = '\0';
    t->fields[nf] = f;
    st->rec_fields++;
}

/* Forget the current record's fields. */
static void drop_record(parse_state *st)
{
    es__csv_table *t = st->t;
    int64_t base = t->field_off[t->nrecords];
    for (int64_t i = 0; i < st->rec_fields; i++) es__free(st->ctx, t->fields[base + i]);
    st->rec_fields = 0;
}

static void on_record(int c, void *data)
{
    parse_state *st = data;
    es__csv_table *t = st->t;
    (void)c;
    if (st->rc) { drop_record(st); return; }
    /* a blank line (libcsv may report it as one empty field) makes no record */
    if (st->rec_fields == 0 ||
        (st->rec_fields == 1 && !t->fields[t->field_off[t->nrecords]][0])) {
        drop_record(st);
        return;
    }
    if (t->nrecords + 1 >= st->cap_records) {
        int64_t cap = st->cap_records ? 2 * st->cap_records : 64;
        int64_t *o = es__realloc(st->ctx, t->field_off, (size_t)(cap + 1) * sizeof *o);
        if (o) t->field_off = o;
        int64_t *l = o ? es__realloc(st->ctx, t->line, (size_t)cap * sizeof *l) : NULL;
        if (!o || !l) { st->rc = ES_ENOMEM; drop_record(st); return; }
        t->line = l;
        st->cap_records = cap;
    }
    t->line[t->nrecords] = st->rec_line;
    t->field_off[t->nrecords + 1] = t->field_off[t->nrecords] + st->rec_fields;
    t->nrecords++;
    st->rec_fields = 0;
}

void es__csv_table_clear(es_ctx *ctx, es__csv_table *t)
{
    if (!t) return;
    for (int64_t i = 0; t->field_off && i < t->field_off[t->nrecords]; i++)
        es__free(ctx, t->fields[i]);
    es__free(ctx, t->fields);
    es__free(ctx, t->field_off);
    es__free(ctx, t->line);
    memset(t, 0, sizeof *t);
}

es_status es__csv_parse(es_ctx *ctx, const char *what, const char *name, const char *buf,
                        size_t len, unsigned flags, es__csv_table *t)
{
    struct csv_parser p;
    parse_state st;
    size_t pos = 0;
    memset(t, 0, sizeof *t);
    memset(&st, 0, sizeof st);
    st.ctx = ctx;
    st.what = what;
    st.name = name ? name : "(memory)";
    st.flags = flags;
    st.t = t;
    st.line = 1;
    if (!(t->field_off = es__calloc(ctx, 65, sizeof *t->field_off))) return ES_ENOMEM;
    st.cap_records = 64;
    if (!(t->line = es__calloc(ctx, 64, sizeof *t->line))) {
        es__csv_table_clear(ctx, t);
        return ES_ENOMEM;
    }
    if (csv_init(&p, ((flags & ES__CSV_STRICT) ? CSV_STRICT | CSV_STRICT_FINI : 0) |
                         CSV_APPEND_NULL) != 0) {
        es__csv_table_clear(ctx, t);
        ES_FAIL(ctx, ES_ENOMEM, "%s '%s': cannot start the CSV parser", what, st.name);
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
        /* between records (libcsv's ROW_NOT_BEGUN state is 0), a record that
         * starts now starts on this line, even if its first field is quoted
         * over several lines */
        if (p.pstate == 0) st.rec_line = st.line;
        if (csv_parse(&p, buf + pos, seg, on_field, on_record, &st) != seg && !st.rc)
            st.rc = es__fail(ctx, ES_EFORMAT, "%s '%s' line %lld: malformed CSV (%s; a quote "
                             "inside an unquoted field, or text after a closing quote)", what,
                             st.name, (long long)st.line, csv_strerror(csv_error(&p)));
        pos += seg;
        if (eol) st.line++;
    }
    /* an open quoted field began right after the record's last complete
     * field (on the line of its comma), or with the record */
    if (!st.rc && csv_fini(&p, on_field, on_record, &st) != 0 && !st.rc)
        st.rc = es__fail(ctx, ES_EFORMAT, "%s '%s' line %lld: unterminated quoted field "
                         "(opened on line %lld)", what, st.name, (long long)st.line,
                         (long long)(st.rec_fields ? st.field_line : st.rec_line));
    csv_free(&p);
    drop_record(&st);
    if (st.rc) es__csv_table_clear(ctx, t);
    return st.rc;
}

es_status es__csv_read(es_ctx *ctx, const char *what, const char *path, unsigned flags,
                       es__csv_table *t)
{
    char *buf;
    size_t len;
    es_status rc;
    memset(t, 0, sizeof *t);
    if ((rc = es__read_file(ctx, path, ES__READ_REGULAR, &buf, &len)) != ES_OK)
        return es__fail(ctx, rc, "%s: %s", what, es_ctx_errmsg(ctx));
    rc = es__csv_parse(ctx, what, path, buf, len, flags, t);
    es__free(ctx, buf);
    return rc;
}

/* Spreadsheets run a cell that starts with = + - @ (or a tab or carriage
 * return before one) as a formula: a label "=cmd|' /C calc'!A0" written as
 * it is ran a command when the CSV was opened (CSV injection, OWASP). Such a
 * field, unless it is a number ("-1.5"), is written quoted with a leading
 * apostrophe, which spreadsheets show as text and do not evaluate. */
static int formula_like(const char *s)
{
    double v;
    if (!strchr("=+-@\t\r", *s) || !*s) return 0;
    return es__parse_finite(s, &v) != 0;
}

void es_csv_write_field(FILE *f, const char *s)
{
    int guard;
    if (!s) s = "";
    guard = formula_like(s);
    if (!guard && !strpbrk(s, ",\"\r\n")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    if (guard) fputc('\'', f);
    for (; *s; s++) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}
