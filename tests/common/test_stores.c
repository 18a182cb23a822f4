/* tests/common/test_stores.c — see es_test_stores.h. */
#include "es_test.h"
#include "es_test_stores.h"

#include <stdio.h>

void es_test_face_store(es_ctx *ctx, const char *dir, const char *store, int64_t n,
                        uint64_t seed)
{
    es_synth_set set;
    es_synth_opts so;
    char man[4200];
    es_synth_opts_init(&so);
    so.n = n;
    es_ctx_set_seed(ctx, seed);
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_FACE, &so, &set));
    ES_CHECK_OK(ctx, es_synth_write(ctx, &set, dir));
    es_synth_set_clear(ctx, &set);
    snprintf(man, sizeof man, "%s/manifest.csv", dir);
    es_ingest_opts io;
    es_ingest_opts_init(&io);
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, man, &io, NULL));
}
