/* lib/core/scan.c — the scanner of the small input languages (scan.h). */
#include "core/scan.h"
#include "core/text.h"

#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void es__scan_init(es__scan *sc, es_ctx *ctx, const char *s, const char *lang,
                   const char *end_name, es__scan_space space)
{
    sc->ctx = ctx;
    sc->s = s;
    sc->pos = 0;
    sc->lang = lang;
    sc->end_name = end_name;
    sc->space = space;
}

bool es__scan_is_space(const es__scan *sc, char c)
{
    switch (sc->space) {
    case ES__SCAN_SPACE_BLANKS: return c == ' ' || c == '\t' || c == '\n' || c == '\r';
    case ES__SCAN_SPACE_C: return c && isspace((unsigned char)c);
    case ES__SCAN_SPACE_NONE: break;
    }
    return false;
}

void es__scan_skip_space(es__scan *sc)
{
    while (es__scan_is_space(sc, sc->s[sc->pos])) sc->pos++;
}

bool es__scan_accept(es__scan *sc, char c)
{
    if (!c || sc->s[sc->pos] != c) return false;
    sc->pos++;
    return true;
}

bool es__scan_accept_lit(es__scan *sc, const char *lit)
{
    size_t n = strlen(lit);
    if (!n || strncmp(sc->s + sc->pos, lit, n)) return false;
    sc->pos += n;
    return true;
}

const char *es__scan_describe(const es__scan *sc, char *buf, size_t n)
{
    char c = sc->s[sc->pos];
    if (!c) return sc->end_name;
    snprintf(buf, n, "'%c'", c);
    return buf;
}

static es_status failv(const es__scan *sc, es_status code, size_t at, const char *fmt,
                       va_list ap) ES__PRINTF(4, 0);
static es_status failv(const es__scan *sc, es_status code, size_t at, const char *fmt,
                       va_list ap)
{
    char msg[512];
    vsnprintf(msg, sizeof msg, fmt, ap);
    return es__fail(sc->ctx, code, "%s: column %zu: %s", sc->lang, at + 1, msg);
}

es_status es__scan_fail(const es__scan *sc, size_t at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    es_status rc = failv(sc, ES_EFORMAT, at, fmt, ap);
    va_end(ap);
    return rc;
}

es_status es__scan_fail_code(const es__scan *sc, es_status code, size_t at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    es_status rc = failv(sc, code, at, fmt, ap);
    va_end(ap);
    return rc;
}

es_status es__scan_expect_close(es__scan *sc, char open, char close, size_t open_at)
{
    char b[8];
    es__scan_skip_space(sc);
    if (es__scan_accept(sc, close)) return ES_OK;
    return es__scan_fail(sc, sc->pos, "expected '%c' to close the '%c' at column %zu, found %s",
                         close, open, open_at + 1, es__scan_describe(sc, b, sizeof b));
}

size_t es__scan_span(es__scan *sc, int (*ok)(char))
{
    size_t at = sc->pos;
    while (sc->s[sc->pos] && ok(sc->s[sc->pos])) sc->pos++;
    return sc->pos - at;
}

es__scan_result es__scan_quoted(es__scan *sc, const char **w, size_t *len)
{
    const char *open = sc->s + sc->pos, *close;
    if (*open != '"') return ES__SCAN_NONE;
    if (!(close = strchr(open + 1, '"'))) return ES__SCAN_UNTERMINATED;
    *w = open + 1;
    *len = (size_t)(close - *w);
    sc->pos = (size_t)(close - sc->s) + 1;
    return *len ? ES__SCAN_OK : ES__SCAN_EMPTY;
}

es__scan_result es__scan_word(es__scan *sc, int (*ok)(char), const char **w, size_t *len)
{
    size_t at = sc->pos;
    if (sc->s[at] == '"') return es__scan_quoted(sc, w, len);
    if (!es__scan_span(sc, ok)) return ES__SCAN_NONE;
    *w = sc->s + at;
    *len = sc->pos - at;
    return ES__SCAN_OK;
}

static bool digit(char c) { return isdigit((unsigned char)c); }

es__scan_result es__scan_number(es__scan *sc, size_t max_len, double *v, size_t *len)
{
    const char *s = sc->s;
    size_t at = sc->pos, i = at;
    if (!digit(s[at]) && s[at] != '.') return ES__SCAN_NONE;
    while (digit(s[i])) i++;
    if (s[i] == '.') {
        i++;
        while (digit(s[i])) i++;
    }
    if (i == at + 1 && s[at] == '.') return ES__SCAN_MALFORMED;
    if (s[i] == 'e' || s[i] == 'E') {
        size_t j = i + 1;
        if (s[j] == '+' || s[j] == '-') j++;
        if (!digit(s[j])) return ES__SCAN_MALFORMED;
        while (digit(s[j])) j++;
        i = j;
    }
    if (max_len && i - at >= max_len) return ES__SCAN_TOO_LONG;
    /* the token is one strtod reads whole, so the exact parser reads it
     * whole too (its slow path is strtod, for tokens up to 512 bytes) */
    if (es__parse_double(s + at, s + i, v) != s + i) return ES__SCAN_TOO_LONG;
    *len = i - at;
    sc->pos = i;
    return ES__SCAN_OK;
}

int es__scan_ident_char(char c) { return isalnum((unsigned char)c) || c == '_'; }
