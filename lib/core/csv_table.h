/* lib/core/csv_table.h — a CSV file as a table of strings with the line of
 * each record, on libcsv (RFC 4180: quoted fields holding commas, doubled
 * quotes and line breaks; CR, LF and CRLF record ends). Written once for
 * every CSV the library reads: manifests, landmark tables and specimen
 * lists, the tables plot and render read. Library-private.
 *
 * libcsv does not report positions, so the buffer is fed one physical line
 * at a time and each record remembers the line it started on: every
 * message names the file and a line. Blank lines make no record. A leading
 * UTF-8 byte order mark is dropped; a NUL byte inside a field is an error
 * (it would silently cut the field). */
#ifndef EDGESPACE_CORE_CSV_TABLE_H
#define EDGESPACE_CORE_CSV_TABLE_H

#include "core/core_private.h"

enum {
    ES__CSV_STRICT = 1,   /* refuse a quote inside an unquoted field, text after a
                             closing quote, an unterminated quoted field */
    ES__CSV_UTF8 = 2      /* refuse fields that are not valid UTF-8 */
};

typedef struct es__csv_table {
    int64_t nrecords;
    int64_t *field_off;   /* nrecords + 1: record r is fields[field_off[r] .. field_off[r+1]) */
    char **fields;        /* NUL-terminated, owned */
    int64_t *line;        /* nrecords: 1-based line where the record starts */
} es__csv_table;

/* Parse buf[0..len). Messages read "<what> '<name>' line N: ...". On
 * failure t is empty. */
es_status es__csv_parse(es_ctx *ctx, const char *what, const char *name, const char *buf,
                        size_t len, unsigned flags, es__csv_table *t);
/* Read and parse the file at path (a regular file). */
es_status es__csv_read(es_ctx *ctx, const char *what, const char *path, unsigned flags,
                       es__csv_table *t);
void es__csv_table_clear(es_ctx *ctx, es__csv_table *t);

static inline int64_t es__csv_nfields(const es__csv_table *t, int64_t r)
{
    return t->field_off[r + 1] - t->field_off[r];
}
/* Field c of record r ("" past the end of a short record). */
static inline const char *es__csv_field(const es__csv_table *t, int64_t r, int64_t c)
{
    return c < es__csv_nfields(t, r) ? t->fields[t->field_off[r] + c] : "";
}

#endif
