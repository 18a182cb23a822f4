/* tests/common/test_parallel.c — es_test_parallel.h. */
#include "es_test_parallel.h"
#include "es_test.h"

void es_test_job_begin(es_test_job *t, int *argc, char ***argv)
{
    t->job = t->alone = NULL;
    ES_CHECK(es_ctx_new(&t->job) == ES_OK && es_ctx_new(&t->alone) == ES_OK);
    ES_CHECK_OK(t->job, es_parallel_init(t->job, argc, argv));
    ES_CHECK_OK(t->job, es_ctx_join_parallel(t->job));
    t->P = es_ctx_nranks(t->job);
    t->me = es_ctx_rank(t->job);
    ES_CHECK(t->P >= 1 && t->me >= 0 && t->me < t->P);
    ES_CHECK(es_ctx_rank(t->alone) == 0 && es_ctx_nranks(t->alone) == 1);
    if (!es_parallel_available()) ES_CHECK(t->P == 1);
}

int es_test_job_end(es_test_job *t)
{
    es_ctx_free(t->job);
    es_ctx_free(t->alone);
    t->job = t->alone = NULL;
    int failed = es_test_failures;
    es_parallel_finalize();
    return failed ? 1 : 0;
}
