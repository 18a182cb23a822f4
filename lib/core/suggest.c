/* lib/core/suggest.c — see suggest.h. */
#include "core/suggest.h"

#include <ctype.h>

size_t es__edit_distance(const char *a, const char *b, size_t limit)
{
    size_t na = strlen(a), nb = strlen(b), row[256];
    if (na > 255 || nb > 255) return limit + 1;
    if ((na > nb ? na - nb : nb - na) > limit) return limit + 1;
    for (size_t j = 0; j <= nb; j++) row[j] = j;
    for (size_t i = 1; i <= na; i++) {
        size_t diag = row[0], low;
        row[0] = i;
        low = row[0];
        for (size_t j = 1; j <= nb; j++) {
            size_t up = row[j];
            size_t sub = diag + (tolower((unsigned char)a[i - 1]) !=
                                 tolower((unsigned char)b[j - 1]));
            size_t best = sub < up + 1 ? sub : up + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
            if (best < low) low = best;
        }
        if (low > limit) return limit + 1;   /* every later row is at least this */
    }
    return row[nb] <= limit ? row[nb] : limit + 1;
}

void es__suggest_init(es__suggest *s, const char *word)
{
    size_t n = word ? strlen(word) : 0;
    memset(s, 0, sizeof *s);
    s->word = word ? word : "";
    s->limit = n / 3 > 2 ? n / 3 : 2;
}

void es__suggest_add(es__suggest *s, const char *cand)
{
    size_t d;
    int k;
    if (!cand) return;
    for (k = 0; k < s->nsome; k++)
        if (!strcmp(s->some[k], cand)) return;
    for (k = 0; k < s->nbest; k++)
        if (!strcmp(s->best[k], cand)) return;
    s->ncand++;
    if (s->nsome < 6) s->some[s->nsome++] = cand;
    d = es__edit_distance(s->word, cand, s->limit);
    if (d > s->limit || (s->nbest == 3 && d >= s->dist[2])) return;
    /* insert in distance order (ties keep the earlier candidate first) */
    k = s->nbest < 3 ? s->nbest++ : 2;
    for (; k > 0 && s->dist[k - 1] > d; k--) {
        s->best[k] = s->best[k - 1];
        s->dist[k] = s->dist[k - 1];
    }
    s->best[k] = cand;
    s->dist[k] = d;
}

void es__suggest_format(const es__suggest *s, const char *what, char *buf, size_t n)
{
    size_t at = 0;
#define PUT(...) do { int w_ = snprintf(buf + at, at < n ? n - at : 0, __VA_ARGS__); \
                      if (w_ > 0) at += (size_t)w_; } while (0)
    if (!n) return;
    buf[0] = '\0';
    if (s->nbest > 0) {
        PUT(" (did you mean ");
        for (int k = 0; k < s->nbest; k++)
            PUT("%s'%s'", k == 0 ? "" : k == s->nbest - 1 ? " or " : ", ", s->best[k]);
        PUT("?)");
    } else if (s->nsome > 0) {
        PUT(" (%s: ", what);
        for (int k = 0; k < s->nsome; k++) PUT("%s%s", k ? ", " : "", s->some[k]);
        PUT("%s)", s->ncand > s->nsome ? ", ..." : "");
    }
#undef PUT
    if (at >= n && n > 4) memcpy(buf + n - 5, "...)", 5);
}
