/* tests/core/test_ctx.c — the context: messages, allocator hooks, RNG. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"


int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK && ctx);
    ES_CHECK(strcmp(es_ctx_errmsg(ctx), "") == 0);
    ES_CHECK(es__fail(ctx, ES_EINVAL, "bad %d", 7) == ES_EINVAL);
    ES_CHECK(strcmp(es_ctx_errmsg(ctx), "bad 7") == 0);
    /* a message is one line: control characters it quotes are escaped */
    ES_CHECK(es__fail(ctx, ES_EFORMAT, "column '%s'", "a\nb\tc\rd\001e\x7f") == ES_EFORMAT);
    ES_CHECK_MSG(!strcmp(es_ctx_errmsg(ctx), "column 'a\\nb\\tc\\rd\\x01e\\x7f'"), "%s",
                 es_ctx_errmsg(ctx));
    {
        /* escapes never overrun the buffer: 2000 newlines make a full,
         * terminated message */
        char many[2001];
        memset(many, '\n', 2000);
        many[2000] = '\0';
        es__fail(ctx, ES_EFORMAT, "%s", many);
        ES_CHECK(strlen(es_ctx_errmsg(ctx)) < 1024 && !strchr(es_ctx_errmsg(ctx), '\n'));
    }
    ES_CHECK(strcmp(es_strerror(ES_OK), "success") == 0);
    ES_CHECK(strlen(es_version()) > 0);

    /* overflow and negative counts are refused, not wrapped */
    ES_CHECK(es__calloc(ctx, SIZE_MAX / 2, 4) == NULL);
    ES_CHECK(strstr(es_ctx_errmsg(ctx), "overflow") != NULL);
    ES_CHECK(es__alloc_array(ctx, -1, 8) == NULL);
    int li;
    ES_CHECK(es__lapack_int(ctx, (int64_t)1 << 33, &li) == ES_ERANGE);

    /* allocator hooks see every allocation and can fail one */
    failing_alloc fa = {0, 2, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    es_ctx_set_allocator(ctx, &a);
    void *p1 = es__malloc(ctx, 16);
    void *p2 = es__malloc(ctx, 16);
    ES_CHECK(p1 != NULL && p2 == NULL);
    ES_CHECK(strstr(es_ctx_errmsg(ctx), "out of memory") != NULL);
    es__free(ctx, p1);
    es_ctx_set_allocator(ctx, NULL);

    /* RNG: same seed, same stream; moments of the normal are right */
    es_rng r1, r2;
    es_rng_init(&r1, 42);
    es_rng_init(&r2, 42);
    for (int i = 0; i < 100; i++) ES_CHECK(es_rng_next(&r1) == es_rng_next(&r2));
    double s = 0, s2 = 0;
    int n = 200000;
    for (int i = 0; i < n; i++) {
        double z = es_rng_normal(&r1);
        s += z;
        s2 += z * z;
    }
    ES_CHECK_CLOSE(s / n, 0.0, 0, 0.01);
    ES_CHECK_CLOSE(s2 / n, 1.0, 0.02, 0);
    for (int i = 0; i < 1000; i++) ES_CHECK(es_rng_below(&r1, 7) < 7);
    es_ctx_free(ctx);
    ES_TEST_END();
}
