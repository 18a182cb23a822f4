/* lib/core/text.h — numbers and UTF-8 in text, written once for every
 * reader of the library (mesh formats, manifests, landmark tables, CSV
 * tables, point expressions). Library-private.
 *
 * es__parse_double is exact (strtod's correctly rounded result, bit for
 * bit: tests/core/test_text.c) and several times faster than strtod on the
 * "%.6f" and "%.17g" numbers mesh files hold (core/numparse.c). */
#ifndef EDGESPACE_CORE_TEXT_H
#define EDGESPACE_CORE_TEXT_H

#include "core/core_private.h"

/* Parse a number (anything strtod accepts) starting at p, not reading at
 * or past end. Returns the end of the token, or NULL on a syntax error. The
 * token must be followed by a delimiter (es__is_delim) or end. */
const char *es__parse_double(const char *p, const char *end, double *out);

/* Parse an optionally signed decimal integer (no exponent, no fraction);
 * NULL on syntax error or overflow of int64. */
const char *es__parse_int64(const char *p, const char *end, int64_t *out);

/* Bytes that may end a number token: whitespace, '/', '#', '\\' (OBJ line
 * continuation), NUL. */
static inline bool es__is_delim(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f' ||
           c == '/' || c == '#' || c == '\\' || c == '\0';
}

/* A whole field as a finite number: optional blanks around one number and
 * nothing else. Subnormal values (1e-310) are numbers; values that
 * overflow to infinity, "inf" and "nan" are not. 0 on success, -1 if the
 * field is not a finite number. */
int es__parse_finite(const char *s, double *out);

/* A whole field as an int64: optional blanks around one optionally signed
 * decimal integer (es__parse_int64) and nothing else. 0 on success, -1 if
 * the field is not such an integer or overflows int64. */
int es__parse_int64_field(const char *s, int64_t *out);

/* Length of the valid UTF-8 prefix of s[0..n) (n if all of it is valid):
 * shortest forms only, no surrogates, nothing past U+10FFFF. */
size_t es__utf8_valid_prefix(const unsigned char *s, size_t n);

#endif
