/* lib/core/strmap.h — a map from strings to int64 values, written once for
 * the whole library (store row ids, landmark specimens, group labels,
 * pairing keys, manifest ids). Library-private.
 *
 * Open addressing with linear probing over a power-of-two table kept at
 * most half full; hash FNV-1a 64 (core/hash.h). Keys are borrowed: the
 * caller keeps them alive and unchanged while they are in the map. Each
 * slot keeps the key pointer next to its value, so a lookup compares the
 * probed slot's own key: the value is never used as an index into another
 * array (which is how the landmark specimens map used to read the wrong
 * entry on a collision). Tested against a linear-scan reference with 10^5
 * random and colliding keys (tests/core/test_strmap.c).
 */
#ifndef EDGESPACE_CORE_STRMAP_H
#define EDGESPACE_CORE_STRMAP_H

#include "core/core_private.h"

typedef struct es__strmap {
    int64_t cap;          /* slots, a power of two (0 before the first put) */
    int64_t n;            /* keys held */
    const char **keys;    /* cap: the key of each slot, NULL if empty */
    int64_t *vals;        /* cap: its value */
} es__strmap;

/* An empty map with room for `expected` keys before it grows (0: small).
 * ES_ENOMEM (recorded) or ES_OK. */
es_status es__strmap_init(es_ctx *ctx, es__strmap *m, int64_t expected);
void es__strmap_clear(es_ctx *ctx, es__strmap *m);

/* The value of key, or -1 when absent. */
int64_t es__strmap_get(const es__strmap *m, const char *key);

/* Insert key -> val unless key is present. *prev (may be NULL) gets the
 * value already stored for key, or -1 when it was inserted now. Grows the
 * table as needed (ES_ENOMEM leaves the map as it was). */
es_status es__strmap_put(es_ctx *ctx, es__strmap *m, const char *key, int64_t val,
                         int64_t *prev);

#endif
