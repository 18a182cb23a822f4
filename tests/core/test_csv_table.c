/* tests/core/test_csv_table.c — the CSV table every reader of the library
 * uses (manifests, landmark and specimen tables): records and fields, RFC
 * 4180 quoting (commas, doubled quotes and line breaks inside quotes), CR,
 * LF and CRLF record ends, blank lines, the byte order mark, the line each
 * record starts on, and the errors, each naming its line: a NUL byte, the
 * strict mode's malformed quotes, an unterminated quote (at the line that
 * opened it), invalid UTF-8; reading from a file; allocation failures. */
#include "core/csv_table.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"

static es_status parse(es_ctx *ctx, const char *text, unsigned flags, es__csv_table *t)
{
    return es__csv_parse(ctx, "table", "t.csv", text, strlen(text), flags, t);
}

/* The table as text: "line: field|field\n" per record. */
static void dump(const es__csv_table *t, char *out, size_t n)
{
    size_t k = 0;
    out[0] = '\0';
    for (int64_t r = 0; r < t->nrecords && k < n; r++) {
        k += (size_t)snprintf(out + k, n - k, "%lld:", (long long)t->line[r]);
        for (int64_t c = 0; c < es__csv_nfields(t, r) && k < n; c++)
            k += (size_t)snprintf(out + k, n - k, "%s%s", c ? "|" : "", es__csv_field(t, r, c));
        if (k < n) k += (size_t)snprintf(out + k, n - k, "\n");
    }
}

/* text parses (with flags) to the records `want` (dump's format). */
static void check_table(es_ctx *ctx, const char *text, unsigned flags, const char *want)
{
    es__csv_table t;
    char got[4096];
    es_status rc = parse(ctx, text, flags, &t);
    ES_CHECK_MSG(rc == ES_OK, "'%s': %s", text, es_ctx_errmsg(ctx));
    if (rc != ES_OK) return;
    dump(&t, got, sizeof got);
    ES_CHECK_MSG(!strcmp(got, want), "'%s' gave\n%s, want\n%s", text, got, want);
    es__csv_table_clear(ctx, &t);
}

static void test_records(es_ctx *ctx)
{
    check_table(ctx, "a,b,c\n1,2,3\n", 0, "1:a|b|c\n2:1|2|3\n");
    /* no final line break; a short record; empty fields */
    check_table(ctx, "a,b\nx\n,\n,,", 0, "1:a|b\n2:x\n3:|\n4:||\n");
    /* quoted commas, doubled quotes, line breaks inside quotes (kept as
     * written), an empty quoted field */
    check_table(ctx, "id,note\n\"a,b\",\"say \"\"hi\"\"\"\n\"two\nlines\",\"\"\nz,\"c\r\nd\"\n",
                ES__CSV_STRICT, "1:id|note\n2:a,b|say \"hi\"\n3:two\nlines|\n5:z|c\r\nd\n");
    /* LF, CRLF and lone CR end records alike and count lines alike */
    check_table(ctx, "a\nb\r\nc\rd", 0, "1:a\n2:b\n3:c\n4:d\n");
    check_table(ctx, "a\r\n\r\n\rb\n\nc", 0, "1:a\n4:b\n6:c\n");
    /* blank lines and lines of blanks make no record, anywhere */
    check_table(ctx, "\n\na,b\n\n  \n\t\nc,d\n\n", 0, "3:a|b\n7:c|d\n");
    check_table(ctx, "", 0, "");
    check_table(ctx, "\n\r\n", 0, "");
    /* a leading byte order mark is not data; one elsewhere is */
    check_table(ctx, "\xef\xbb\xbfid,x\n1,2\n", 0, "1:id|x\n2:1|2\n");
    check_table(ctx, "a,\xef\xbb\xbf\n", 0, "1:a|\xef\xbb\xbf\n");
    /* a record starts on the line of its first field, even when that field
     * is quoted over several lines */
    check_table(ctx, "h\n\"x\ny\nz\",w\nnext\n", ES__CSV_STRICT, "1:h\n2:x\ny\nz|w\n5:next\n");
    check_table(ctx, "h\r\"x\ry\",w\rnext\r", ES__CSV_STRICT, "1:h\n2:x\ry|w\n4:next\n");

    /* field access past the end of a short record is "" */
    es__csv_table t;
    ES_CHECK_OK(ctx, parse(ctx, "a,b,c\nx\n", 0, &t));
    ES_CHECK(t.nrecords == 2 && es__csv_nfields(&t, 1) == 1);
    ES_CHECK(!strcmp(es__csv_field(&t, 1, 0), "x") && !strcmp(es__csv_field(&t, 1, 2), ""));
    es__csv_table_clear(ctx, &t);
    ES_CHECK(t.nrecords == 0 && t.fields == NULL && t.line == NULL);
    es__csv_table_clear(ctx, &t);
    es__csv_table_clear(ctx, NULL);
}

/* Thousands of records and fields: the arrays grow, lines stay right. */
static void test_large(es_ctx *ctx)
{
    enum { R = 3000 };
    size_t cap = (size_t)R * 40, k = 0;
    char *text = malloc(cap);
    es__csv_table t;
    int64_t bad = 0;
    if (!text) { ES_CHECK(0); return; }
    for (int r = 0; r < R; r++) {
        /* every 7th record is preceded by a blank line, every 5th has a
         * quoted field with a line break */
        if (r % 7 == 3) k += (size_t)snprintf(text + k, cap - k, "\r\n");
        if (r % 5 == 0) k += (size_t)snprintf(text + k, cap - k, "r%d,\"p\nq\",%d\r\n", r, r);
        else k += (size_t)snprintf(text + k, cap - k, "r%d,x,%d\r\n", r, r);
    }
    ES_CHECK_OK(ctx, parse(ctx, text, ES__CSV_STRICT | ES__CSV_UTF8, &t));
    ES_CHECK(t.nrecords == R);
    int64_t line = 1;
    for (int r = 0; r < R && r < t.nrecords; r++) {
        char want[32];
        if (r % 7 == 3) line++;
        snprintf(want, sizeof want, "r%d", r);
        bad += es__csv_nfields(&t, r) != 3 || strcmp(es__csv_field(&t, r, 0), want) ||
               t.line[r] != line || strcmp(es__csv_field(&t, r, 1), r % 5 ? "x" : "p\nq");
        line += r % 5 == 0 ? 2 : 1;
    }
    ES_CHECK_MSG(bad == 0, "%lld records wrong", (long long)bad);
    es__csv_table_clear(ctx, &t);
    free(text);
}

/* Each error names the table, the file and the line (and the field). */
static void test_errors(es_ctx *ctx)
{
    es__csv_table t;
    static const char nul[] = "a,b\n\"x\ny\",c\0d\n";
    ES_CHECK_FAILS(ctx, es__csv_parse(ctx, "table", "t.csv", nul, sizeof nul - 1, 0, &t),
                   ES_EFORMAT, "table 't.csv' line 2, field 2: NUL byte");
    ES_CHECK(t.nrecords == 0 && t.fields == NULL);
    static const char nul_quoted[] = "a\n\n\"b\0\"\n";
    ES_CHECK_FAILS(ctx, es__csv_parse(ctx, "table", "t.csv", nul_quoted, sizeof nul_quoted - 1,
                                      ES__CSV_STRICT, &t),
                   ES_EFORMAT, "table 't.csv' line 3, field 1: NUL byte");

    /* strict: a quote inside an unquoted field, text after a closing quote */
    ES_CHECK_FAILS(ctx, parse(ctx, "a,b\nc,d\"e\n", ES__CSV_STRICT, &t), ES_EFORMAT,
                   "table 't.csv' line 2: malformed CSV");
    ES_CHECK_FAILS(ctx, parse(ctx, "a,b\n\n\"c\"d,e\n", ES__CSV_STRICT, &t), ES_EFORMAT,
                   "table 't.csv' line 3: malformed CSV");
    ES_CHECK(t.nrecords == 0);
    /* lenient: both read as text */
    check_table(ctx, "a,b\nc,d\"e\n", 0, "1:a|b\n2:c|d\"e\n");

    /* an unterminated quote is named at the line that opened it: with the
     * record, or after the record's last complete field */
    ES_CHECK_FAILS(ctx, parse(ctx, "a,b\nc,d\n\"open\nx\ny\n", ES__CSV_STRICT, &t), ES_EFORMAT,
                   "table 't.csv' line 6: unterminated quoted field (opened on line 3)");
    ES_CHECK_FAILS(ctx, parse(ctx, "a,b,c\nx,\"p\nq\",\"open\nmore\n", ES__CSV_STRICT, &t),
                   ES_EFORMAT, "unterminated quoted field (opened on line 3)");
    /* lenient: the open field runs to the end */
    check_table(ctx, "a,\"open\nmore\n", 0, "1:a|open\nmore\n\n");

    /* UTF-8: checked only when asked, naming the byte */
    ES_CHECK_FAILS(ctx, parse(ctx, "a,b\nok,caf\xc3\n", ES__CSV_UTF8, &t), ES_EFORMAT,
                   "table 't.csv' line 2, field 2: invalid UTF-8 at byte 4");
    ES_CHECK_FAILS(ctx, parse(ctx, "\"\xe2\x82\xac\n\xed\xa0\x80\"\n", ES__CSV_UTF8, &t),
                   ES_EFORMAT, "line 1, field 1: invalid UTF-8 at byte 5");   /* a surrogate */
    ES_CHECK_FAILS(ctx, parse(ctx, "\xc0\xaf\n", ES__CSV_UTF8, &t), ES_EFORMAT,
                   "invalid UTF-8 at byte 1");   /* an overlong '/' */
    check_table(ctx, "caf\xc3\xa9,\xe2\x82\xac,\xf0\x9f\x98\x80\n", ES__CSV_UTF8,
                "1:caf\xc3\xa9|\xe2\x82\xac|\xf0\x9f\x98\x80\n");
    check_table(ctx, "\xff,\xfe\n", 0, "1:\xff|\xfe\n");

    /* no name: "(memory)" */
    ES_CHECK_FAILS(ctx, es__csv_parse(ctx, "table", NULL, "\"x", 2, ES__CSV_STRICT, &t),
                   ES_EFORMAT, "table '(memory)' line 1");
}

/* From a file: a regular file only, its name in every message. */
static void test_read(es_ctx *ctx)
{
    const char *dir = es_test_tmpdir("csv-table");
    char path[4200], fifo[4200];
    es__csv_table t;
    snprintf(path, sizeof path, "%s/t.csv", dir);
    es_test_write_file(path, "\xef\xbb\xbfx,y\r\n1,2\r\n");
    ES_CHECK_OK(ctx, es__csv_read(ctx, "table", path, ES__CSV_STRICT, &t));
    ES_CHECK(t.nrecords == 2 && !strcmp(es__csv_field(&t, 0, 0), "x") && t.line[1] == 2);
    es__csv_table_clear(ctx, &t);
    es_test_write_file(path, "x,y\n\"1,2\n");
    ES_CHECK_FAILS(ctx, es__csv_read(ctx, "table", path, ES__CSV_STRICT, &t), ES_EFORMAT,
                   "/t.csv' line 3: unterminated quoted field (opened on line 2)");
    remove(path);
    ES_CHECK_FAILS(ctx, es__csv_read(ctx, "table", path, 0, &t), ES_EIO,
                   "table: cannot open '");
    ES_CHECK(t.nrecords == 0 && t.fields == NULL);
    ES_CHECK_FAILS(ctx, es__csv_read(ctx, "table", dir, 0, &t), ES_EIO, "table: ");
    snprintf(fifo, sizeof fifo, "%s/fifo.csv", dir);
    if (mkfifo(fifo, 0600) == 0) {
        /* refused at once: no writer is waited for */
        ES_CHECK_FAILS(ctx, es__csv_read(ctx, "table", fifo, 0, &t), ES_EIO,
                       "is not a regular file");
        remove(fifo);
    }
    rmdir(dir);
}

/* Every allocation may fail: ES_ENOMEM, an empty table, nothing leaked. */
static void test_alloc_sweep(void)
{
    es_ctx *ctx = NULL;
    failing_alloc fa = {0, 0, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    char text[8192];
    size_t k = 0;
    es_status rc = ES_ENOMEM;
    int64_t i;
    if (es_ctx_new(&ctx) != ES_OK) { ES_CHECK(0); return; }
    es_ctx_set_allocator(ctx, &a);
    for (int r = 0; r < 100; r++)
        k += (size_t)snprintf(text + k, sizeof text - k, "r%d,\"q,%d\",x\n", r, r);
    for (i = 1; i < 2000 && rc == ES_ENOMEM; i++) {
        es__csv_table t;
        fa.count = 0;
        fa.fail_at = i;
        rc = es__csv_parse(ctx, "table", "t.csv", text, k, ES__CSV_STRICT, &t);
        ES_CHECK_MSG(rc == ES_OK || rc == ES_ENOMEM, "allocation %lld: %s", (long long)i,
                     es_ctx_errmsg(ctx));
        if (rc == ES_OK) ES_CHECK(t.nrecords == 100 && !strcmp(es__csv_field(&t, 99, 1), "q,99"));
        else ES_CHECK(t.nrecords == 0 && t.fields == NULL && fa.live == 0);
        es__csv_table_clear(ctx, &t);
        ES_CHECK(fa.live == 0);
    }
    ES_CHECK(rc == ES_OK && i > 300);
    es_ctx_free(ctx);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_records(ctx);
    test_large(ctx);
    test_errors(ctx);
    test_read(ctx);
    test_alloc_sweep();
    es_ctx_free(ctx);
    ES_TEST_END();
}
