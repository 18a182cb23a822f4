/* tests/common/es_test_alloc.h — an allocator that fails its k-th allocation, for
 * the allocation-failure sweeps (after CHOLMOD's t_memory.c and SQLite's
 * test_malloc.c): fail allocation k = 1, 2, ... until the call succeeds,
 * asserting ES_ENOMEM each time and, through `live`, that nothing leaked.
 *
 *   failing_alloc fa = {0, k, 0};
 *   es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
 *   es_ctx_set_allocator(ctx, &a);
 */
#ifndef EDGESPACE_TESTS_ES_TEST_ALLOC_H
#define EDGESPACE_TESTS_ES_TEST_ALLOC_H

#include <stdint.h>
#include <stdlib.h>

/* count: allocations so far; fail_at: the one to refuse (0: none);
 * live: blocks allocated and not yet freed. */
typedef struct failing_alloc { int64_t count, fail_at, live; } failing_alloc;

void *fa_malloc(void *ud, size_t n);

void *fa_realloc(void *ud, void *p, size_t n);

void fa_free(void *ud, void *p);

#endif
