/* lib/core/text.c — see text.h (es__parse_double and es__parse_int64 are in
 * numparse.c). */
#include "core/text.h"

#include <math.h>

/* The field s without the blanks around it: [*b, *e); false if nothing is left. */
static bool trim_blanks(const char *s, const char **b, const char **e)
{
    const char *p = s, *end;
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
    if (!*p) return false;
    end = p + strlen(p);
    while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r' || end[-1] == '\n'))
        end--;
    *b = p;
    *e = end;
    return true;
}

int es__parse_finite(const char *s, double *out)
{
    const char *p, *end, *q;
    double v;
    if (!trim_blanks(s, &p, &end)) return -1;
    if (!(q = es__parse_double(p, end, &v)) || q != end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

int es__parse_int64_field(const char *s, int64_t *out)
{
    const char *p, *end, *q;
    int64_t v;
    if (!trim_blanks(s, &p, &end)) return -1;
    if (!(q = es__parse_int64(p, end, &v)) || q != end) return -1;
    *out = v;
    return 0;
}

size_t es__utf8_valid_prefix(const unsigned char *s, size_t n)
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
