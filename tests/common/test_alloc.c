/* tests/common/test_alloc.c — see es_test_alloc.h. */
#include "es_test_alloc.h"

void *fa_malloc(void *ud, size_t n)
{
    failing_alloc *fa = ud;
    void *p;
    if (++fa->count == fa->fail_at) return NULL;
    p = malloc(n);
    if (p) fa->live++;
    return p;
}

void *fa_realloc(void *ud, void *p, size_t n)
{
    failing_alloc *fa = ud;
    void *q;
    if (++fa->count == fa->fail_at) return NULL;
    q = realloc(p, n);
    if (q && !p) fa->live++;
    return q;
}

void fa_free(void *ud, void *p)
{
    failing_alloc *fa = ud;
    if (p) fa->live--;
    free(p);
}
