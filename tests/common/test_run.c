/* tests/common/test_run.c — see es_test_run.h. */
#include "es_test_run.h"

#include <sys/resource.h>
#include <time.h>

const char *es_test_edgespace(void)
{
    const char *p = getenv("EDGESPACE");
    return p && *p ? p : NULL;
}

pid_t es_test_spawn_limited(const char *const argv[], const char *outfile, const char *errfile,
                            unsigned long long fsize)
{
    pid_t pid = fork();
    if (pid == 0) {
        int o = open(outfile, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int e = open(errfile, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (o < 0 || e < 0) _exit(126);
        dup2(o, 1);
        dup2(e, 2);
        if (fsize > 0) {
            struct rlimit rl = {(rlim_t)fsize, (rlim_t)fsize};
            signal(SIGXFSZ, SIG_IGN);
            setrlimit(RLIMIT_FSIZE, &rl);
        }
        execv(es_test_edgespace(), (char *const *)argv);
        _exit(127);
    }
    return pid;
}

pid_t es_test_spawn(const char *const argv[], const char *outfile,
                                  const char *errfile)
{
    return es_test_spawn_limited(argv, outfile, errfile, 0);
}

double es_test_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void es_test_sleep(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&ts, &ts) != 0) {}
}

int es_test_wait(pid_t pid)
{
    int st;
    if (waitpid(pid, &st, 0) < 0) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

void es_test_read_small(const char *path, char *buf, size_t n)
{
    FILE *f = fopen(path, "rb");
    size_t r = f ? fread(buf, 1, n - 1, f) : 0;
    buf[r] = '\0';
    if (f) fclose(f);
}

void es_test_run(es_test_out *r, const char *tmpdir, const char *const *args)
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
