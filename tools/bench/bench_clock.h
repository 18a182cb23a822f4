/* tools/bench/bench_clock.h — the clocks every benchmark reads: wall time,
 * CPU time (of the process, or of the calling thread) and peak resident
 * memory. On a machine shared with other jobs the CPU time is the fairer
 * figure; the wall time includes waiting for a core, so the benchmarks
 * print both. */
#ifndef EDGESPACE_BENCH_CLOCK_H
#define EDGESPACE_BENCH_CLOCK_H

#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

static inline double bench_clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline double bench_wall_s(void) { return bench_clock_s(CLOCK_MONOTONIC); }

/* user + system time of all threads of the process */
static inline double bench_process_cpu_s(void) { return bench_clock_s(CLOCK_PROCESS_CPUTIME_ID); }

static inline double bench_thread_cpu_s(void) { return bench_clock_s(CLOCK_THREAD_CPUTIME_ID); }

static inline double bench_peak_rss_mib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

static inline int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Repeated timings sorted in place, and their median (one run of a second
 * or two swings by 15 % on a shared machine). */
static inline void bench_sort(double *v, int n) { qsort(v, (size_t)n, sizeof *v, bench_cmp_double); }

static inline double bench_median(double *v, int n)
{
    bench_sort(v, n);
    return v[n / 2];
}

#endif
