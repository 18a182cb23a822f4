/* lib/core/scan.h — one scanner for the library's small input languages:
 * model formulas (stats/formula.c), the point syntax (stats/point.c) and the
 * store's row filter (store/store_rows.c). Library-private.
 *
 * A cursor over a NUL-terminated string with what every hand-written
 * parser of them needs: whitespace skipped by the language's rule, runs of
 * the bytes a language allows in a name, double-quoted text, numbers (their
 * value from core's exact parser, text.h: strtod's correctly rounded
 * result), single bytes and literals accepted, the next token described,
 * and messages that name the column ("point: column 12: expected ')'").
 * Each parser keeps its grammar and its own words for each failure; the
 * scanner says what it found (es__scan_result).
 *
 * The languages skip different whitespace, and each keeps what it accepted
 * before the scanner was shared (es__scan_space).
 */
#ifndef EDGESPACE_CORE_SCAN_H
#define EDGESPACE_CORE_SCAN_H

#include "core/core_private.h"

#include <stdbool.h>
#include <stddef.h>

typedef enum es__scan_space {
    ES__SCAN_SPACE_NONE,     /* nothing is skipped: the row filter, whose names and
                                values may hold blanks */
    ES__SCAN_SPACE_BLANKS,   /* ' ', '\t', '\n', '\r': the point syntax */
    ES__SCAN_SPACE_C         /* isspace(), also '\v' and '\f': model formulas */
} es__scan_space;

typedef struct es__scan {
    es_ctx *ctx;
    const char *s;           /* the text, NUL-terminated */
    size_t pos;              /* the cursor (byte offset; messages say column pos + 1) */
    const char *lang;        /* "point": messages begin "point: column N: " */
    const char *end_name;    /* the end in messages: "the end of the expression" */
    es__scan_space space;
} es__scan;

/* What a scan found. A scan that fails leaves the cursor where it was,
 * except ES__SCAN_EMPTY (past the empty quotes). */
typedef enum es__scan_result {
    ES__SCAN_OK,
    ES__SCAN_NONE,           /* nothing of the kind at the cursor */
    ES__SCAN_UNTERMINATED,   /* a '"' with no closing '"' */
    ES__SCAN_EMPTY,          /* "" */
    ES__SCAN_MALFORMED,      /* a number that is not one ("." alone, "1e") */
    ES__SCAN_TOO_LONG        /* a number longer than its limit */
} es__scan_result;

void es__scan_init(es__scan *sc, es_ctx *ctx, const char *s, const char *lang,
                   const char *end_name, es__scan_space space);

static inline char es__scan_peek(const es__scan *sc) { return sc->s[sc->pos]; }
static inline bool es__scan_at_end(const es__scan *sc) { return !sc->s[sc->pos]; }

/* Whether c is whitespace by sc's rule; skip the run of it at the cursor. */
bool es__scan_is_space(const es__scan *sc, char c);
void es__scan_skip_space(es__scan *sc);

/* Consume c (or the literal lit) if it is next; whether it was. */
bool es__scan_accept(es__scan *sc, char c);
bool es__scan_accept_lit(es__scan *sc, const char *lit);

/* After space, the `close` that ends what the `open` at column open_at + 1
 * began: consumed, or "expected ')' to close the '(' at column 3, found
 * ','" (ES_EFORMAT). */
es_status es__scan_expect_close(es__scan *sc, char open, char close, size_t open_at);

/* The next byte for a message: "'c'" in buf, or sc->end_name at the end. */
const char *es__scan_describe(const es__scan *sc, char *buf, size_t n);

/* Record "<lang>: column <at + 1>: <message>" on the context and return
 * ES_EFORMAT (es__scan_fail) or code. */
es_status es__scan_fail(const es__scan *sc, size_t at, const char *fmt, ...) ES__PRINTF(3, 4);
es_status es__scan_fail_code(const es__scan *sc, es_status code, size_t at, const char *fmt,
                             ...) ES__PRINTF(4, 5);

/* The run of bytes that ok accepts (never the NUL) from the cursor, which
 * moves past it; its length (0: none). */
size_t es__scan_span(es__scan *sc, int (*ok)(char));

/* At a '"': the text up to the next '"' (no escapes; any byte else) in
 * *w, *len, the cursor past the closing quote. ES__SCAN_NONE when the
 * cursor is not at a '"'. */
es__scan_result es__scan_quoted(es__scan *sc, const char **w, size_t *len);

/* A word: quoted text (es__scan_quoted) or else a run of bytes ok
 * accepts (ES__SCAN_NONE: not one). */
es__scan_result es__scan_word(es__scan *sc, int (*ok)(char), const char **w, size_t *len);

/* An unsigned decimal number: digits, an optional '.' and digits (one of
 * the two runs not empty), an optional exponent ('e' or 'E', a sign, at
 * least one digit). Its value in *v (es__parse_double: exactly strtod's,
 * inf past the range), its length in *len, the cursor past it.
 * ES__SCAN_NONE when no digit or '.' is at the cursor; ES__SCAN_TOO_LONG
 * for max_len bytes or more (0: no limit), before it is converted, and
 * past the 512 bytes the exact parser reads. */
es__scan_result es__scan_number(es__scan *sc, size_t max_len, double *v, size_t *len);

/* isalnum() (letters and digits in the C locale) or '_'. */
int es__scan_ident_char(char c);

#endif
