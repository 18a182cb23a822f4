/* lib/core/suggest.h — "did you mean": the names closest to a misspelt
 * one, for the messages of every lookup by name (label columns, label
 * values, row ids, table columns). Library-private.
 *
 * Closeness is the Levenshtein edit distance (insertions, deletions and
 * substitutions, each 1) between the lower-cased names; a name is offered
 * when its distance is at most max(2, length / 3) of the word looked up,
 * the three closest first. When none is that close, the message lists the
 * first few names that exist instead, so that it always says what to type.
 */
#ifndef EDGESPACE_CORE_SUGGEST_H
#define EDGESPACE_CORE_SUGGEST_H

#include "core/core_private.h"

/* Edit distance between a and b (case-insensitive), or limit + 1 when it
 * exceeds limit (computed in O(len(a) * len(b)) without allocation; names
 * longer than 255 bytes count as further than any limit). */
size_t es__edit_distance(const char *a, const char *b, size_t limit);

/* Collect candidates one by one (repeats are ignored), then format. */
typedef struct es__suggest {
    const char *word;
    size_t limit;
    const char *best[3];       /* closest so far, nearest first (borrowed) */
    size_t dist[3];
    int nbest;
    const char *some[6];       /* the first distinct candidates (borrowed) */
    int nsome;
    int64_t ncand;             /* distinct candidates seen (approximately: repeats
                                  among the first six and the closest are skipped) */
} es__suggest;
void es__suggest_init(es__suggest *s, const char *word);
void es__suggest_add(es__suggest *s, const char *cand);
/* " (did you mean 'a' or 'b'?)" when some candidate is close, else
 * " (<what>: a, b, c, ...)" listing the first few, else "" (no candidates).
 * Truncated to n bytes. Candidates must still be alive. */
void es__suggest_format(const es__suggest *s, const char *what, char *buf, size_t n);

#endif
