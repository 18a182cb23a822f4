/* lib/core/strmap.c — see strmap.h. Linear probing with the table at most
 * half full keeps the expected probe count under 2.5 for a miss (Knuth,
 * TAOCP 3, 6.4); deletion is not needed by any user, so there are no
 * tombstones. */
#include "core/strmap.h"
#include "core/hash.h"

static es_status alloc_table(es_ctx *ctx, es__strmap *m, int64_t cap)
{
    const char **keys = es__alloc_array(ctx, cap, sizeof *keys);
    int64_t *vals = es__alloc_array(ctx, cap, sizeof *vals);
    if (!keys || !vals) {
        es__free(ctx, (void *)keys);
        es__free(ctx, vals);
        return ES_ENOMEM;
    }
    for (int64_t i = 0; i < cap; i++) keys[i] = NULL, vals[i] = -1;
    m->keys = keys;
    m->vals = vals;
    m->cap = cap;
    return ES_OK;
}

static int64_t capacity_for(int64_t n)
{
    int64_t cap = 16;
    while (cap < 2 * n && cap < ((int64_t)1 << 61)) cap *= 2;
    return cap;
}

es_status es__strmap_init(es_ctx *ctx, es__strmap *m, int64_t expected)
{
    memset(m, 0, sizeof *m);
    if (expected < 0) expected = 0;
    return alloc_table(ctx, m, capacity_for(expected));
}

void es__strmap_clear(es_ctx *ctx, es__strmap *m)
{
    if (!m) return;
    es__free(ctx, (void *)m->keys);
    es__free(ctx, m->vals);
    memset(m, 0, sizeof *m);
}

/* The slot holding key, or the empty slot where it would go. */
static int64_t probe(const es__strmap *m, const char *key)
{
    uint64_t mask = (uint64_t)m->cap - 1, i = es__fnv1a64_str(key) & mask;
    while (m->keys[i] && strcmp(m->keys[i], key) != 0) i = (i + 1) & mask;
    return (int64_t)i;
}

int64_t es__strmap_get(const es__strmap *m, const char *key)
{
    if (!m || m->cap == 0 || !key) return -1;
    int64_t i = probe(m, key);
    return m->keys[i] ? m->vals[i] : -1;
}

static es_status grow(es_ctx *ctx, es__strmap *m)
{
    es__strmap old = *m;
    es_status rc = alloc_table(ctx, m, old.cap ? 2 * old.cap : 16);
    if (rc != ES_OK) {
        *m = old;
        return rc;
    }
    for (int64_t j = 0; j < old.cap; j++)
        if (old.keys[j]) {
            int64_t i = probe(m, old.keys[j]);
            m->keys[i] = old.keys[j];
            m->vals[i] = old.vals[j];
        }
    es__free(ctx, (void *)old.keys);
    es__free(ctx, old.vals);
    return ES_OK;
}

es_status es__strmap_put(es_ctx *ctx, es__strmap *m, const char *key, int64_t val,
                         int64_t *prev)
{
    es_status rc;
    int64_t i;
    if (prev) *prev = -1;
    if (!key) ES_FAIL(ctx, ES_EINVAL, "string map: NULL key");
    if (m->cap == 0 || 2 * (m->n + 1) > m->cap) {
        if (m->cap && (i = probe(m, key), m->keys[i])) {   /* present: no need to grow */
            if (prev) *prev = m->vals[i];
            return ES_OK;
        }
        if ((rc = grow(ctx, m)) != ES_OK) return rc;
    }
    i = probe(m, key);
    if (m->keys[i]) {
        if (prev) *prev = m->vals[i];
        return ES_OK;
    }
    m->keys[i] = key;
    m->vals[i] = val;
    m->n++;
    return ES_OK;
}
