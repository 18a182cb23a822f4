/* lib/core/hash.h — FNV-1a 64 (Fowler, Noll, Vo), the one hash of the
 * library: string map probing, content hashes of ingested files
 * ("fnv1a64:<16 hex>") and topology fingerprints (over the little-endian
 * bytes of int64 values). Library-private. FNV is not collision-resistant;
 * every use compares the data itself when it matters. */
#ifndef EDGESPACE_CORE_HASH_H
#define EDGESPACE_CORE_HASH_H

#include "core/core_private.h"

#define ES__FNV_OFFSET UINT64_C(0xcbf29ce484222325)
#define ES__FNV_PRIME UINT64_C(0x100000001b3)

/* Continue hash h (start with ES__FNV_OFFSET) over n bytes. */
static inline uint64_t es__fnv1a64(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) h = (h ^ p[i]) * ES__FNV_PRIME;
    return h;
}

/* Hash of a NUL-terminated string. */
static inline uint64_t es__fnv1a64_str(const char *s)
{
    uint64_t h = ES__FNV_OFFSET;
    for (; *s; s++) h = (h ^ (unsigned char)*s) * ES__FNV_PRIME;
    return h;
}

/* Continue h over the 8 little-endian bytes of each of n int64 values, so
 * that fingerprints do not depend on the machine's byte order. */
uint64_t es__fnv1a64_i64(uint64_t h, const int64_t *vals, int64_t n);

/* 16 lowercase hex digits of h and a NUL. */
void es__hex16(uint64_t h, char out[17]);

/* Fingerprint of head[0..nhead) followed by vals[0..nvals) as int64 values
 * (es_mesh_fingerprint, truss stores): 16 hex digits. */
void es__fingerprint_i64(const int64_t *head, int nhead, const int64_t *vals, int64_t nvals,
                         char out[17]);

#endif
