/* tests/common/es_test_parallel.h — what the tests of lib/parallel share: a
 * context joined to the MPI job the test runs in (mpirun -n P; alone in a
 * build without MPI, rank 0 of 1) beside a context that is not joined, the
 * one-process oracle the job's results are compared with; seeded GPA
 * configurations that every rank makes alike. */
#ifndef EDGESPACE_TESTS_ES_TEST_PARALLEL_H
#define EDGESPACE_TESTS_ES_TEST_PARALLEL_H

#include "edgespace/edgespace.h"

typedef struct es_test_job {
    es_ctx *job;     /* joined to the job: the library's calls are collective */
    es_ctx *alone;   /* not joined: the serial code, on every rank */
    int P, me;       /* the job's ranks and this one's */
} es_test_job;

/* Starts MPI (when the library has it), makes both contexts and joins
 * one; a failure is a failed check (es_test_failures). */
void es_test_job_begin(es_test_job *t, int *argc, char ***argv);

/* Frees both contexts and finalizes MPI; the test's exit status (1 if any
 * check failed, else 0): `return es_test_job_end(&t);`. */
int es_test_job_end(es_test_job *t);

/* n noisy copies of one random k x d template, each scaled, turned by a
 * random angle about the z axis and shifted: k*d x n, column-major k x d per
 * column (malloc'd; the same on every rank for the same seed). GPA's input. */
double *es_test_configurations(int64_t k, int d, int64_t n, uint64_t seed);

#endif
