/* tests/es_test_run.h — run the built `edgespace` command (path in the
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

static inline const char *es_test_edgespace(void)
{
    const char *p = getenv("EDGESPACE");
    return p && *p ? p : NULL;
}

/* Start `edgespace argv...` with stdout/stderr to the given files. */
static inline pid_t es_test_spawn(const char *const argv[], const char *outfile,
                                  const char *errfile)
{
    pid_t pid = fork();
    if (pid == 0) {
        int o = open(outfile, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int e = open(errfile, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (o < 0 || e < 0) _exit(126);
        dup2(o, 1);
        dup2(e, 2);
        execv(es_test_edgespace(), (char *const *)argv);
        _exit(127);
    }
    return pid;
}

static inline int es_test_wait(pid_t pid)
{
    int st;
    if (waitpid(pid, &st, 0) < 0) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

static inline void es_test_read_small(const char *path, char *buf, size_t n)
{
    FILE *f = fopen(path, "rb");
    size_t r = f ? fread(buf, 1, n - 1, f) : 0;
    buf[r] = '\0';
    if (f) fclose(f);
}

/* Run `edgespace` with NULL-terminated arguments (argv[0] is added). */
static inline void es_test_run(es_test_out *r, const char *tmpdir, const char *const *args)
{
    const char *argv[64];
    char o[4200], e[4200];
    int n = 0;
    argv[n++] = es_test_edgespace();
    while (args[n - 1] && n < 63) {
        argv[n] = args[n - 1];
        n++;
    }
    argv[n] = NULL;
    snprintf(o, sizeof o, "%s/.run.out", tmpdir);
    snprintf(e, sizeof e, "%s/.run.err", tmpdir);
    r->status = es_test_wait(es_test_spawn(argv, o, e));
    es_test_read_small(o, r->out, sizeof r->out);
    es_test_read_small(e, r->err, sizeof r->err);
}

#define ES_RUN(r, dir, ...) do { const char *es_a_[] = {__VA_ARGS__, NULL}; \
    es_test_run((r), (dir), es_a_); } while (0)

#endif
