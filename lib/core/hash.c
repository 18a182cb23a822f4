/* lib/core/hash.c — see hash.h. */
#include "core/hash.h"

uint64_t es__fnv1a64_i64(uint64_t h, const int64_t *vals, int64_t n)
{
    for (int64_t i = 0; i < n; i++) {
        uint64_t u = (uint64_t)vals[i];
        for (int b = 0; b < 8; b++) h = (h ^ ((u >> (8 * b)) & 0xffu)) * ES__FNV_PRIME;
    }
    return h;
}

void es__hex16(uint64_t h, char out[17])
{
    static const char hex[] = "0123456789abcdef";
    for (int i = 0; i < 16; i++) out[i] = hex[(h >> (60 - 4 * i)) & 0xfu];
    out[16] = '\0';
}

void es__fingerprint_i64(const int64_t *head, int nhead, const int64_t *vals, int64_t nvals,
                         char out[17])
{
    uint64_t h = es__fnv1a64_i64(ES__FNV_OFFSET, head, nhead);
    es__hex16(es__fnv1a64_i64(h, vals, nvals), out);
}
