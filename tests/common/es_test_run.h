/* tests/common/es_test_run.h — run the built `edgespace` command (path in the
 * EDGESPACE environment variable) from a test, capturing its output, and
 * start it in the background for the kill test. */
#ifndef EDGESPACE_TESTS_ES_TEST_RUN_H
#define EDGESPACE_TESTS_ES_TEST_RUN_H

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

typedef struct es_test_out {
    int status;      /* exit status, or 128 + signal */
    char out[65536]; /* stdout (truncated) */
    char err[65536]; /* stderr (truncated) */
} es_test_out;

const char *es_test_edgespace(void);

/* Start `edgespace argv...` with stdout/stderr to the given files. */
pid_t es_test_spawn(const char *const argv[], const char *outfile,
                                  const char *errfile);
/* The same with every write past fsize bytes of a file failing (EFBIG:
 * RLIMIT_FSIZE, SIGXFSZ ignored so that it is an error, not a kill);
 * fsize 0: no limit. */
pid_t es_test_spawn_limited(const char *const argv[], const char *outfile, const char *errfile,
                            unsigned long long fsize);

/* Monotonic seconds, and a sleep of s seconds (resumed after signals). */
double es_test_now(void);
void es_test_sleep(double s);

int es_test_wait(pid_t pid);

void es_test_read_small(const char *path, char *buf, size_t n);

/* Run `edgespace` with NULL-terminated arguments (argv[0] is added). */
void es_test_run(es_test_out *r, const char *tmpdir, const char *const *args);

#define ES_RUN(r, dir, ...) do { const char *es_a_[] = {__VA_ARGS__, NULL}; \
    es_test_run((r), (dir), es_a_); } while (0)

#endif
