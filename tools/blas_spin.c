/* tools/blas_spin.c — the OpenBLAS worker spin cut short (blas_spin.h). */
#include "blas_spin.h"

#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* OpenBLAS (the pthreads build Debian links) starts its worker threads
 * when it is loaded, and each worker spins in sched_yield for 2^28 cycles
 * before it sleeps, then again after every threaded call: in a one-point
 * command a tenth of a second of CPU on the other core, for nothing
 * (face-study, `embed --point mean --fast`, quiet machine: 0.50 s CPU,
 * 0.37 s with the spin cut short; the same wall time). The spin's length
 * is OPENBLAS_THREAD_TIMEOUT (the exponent), which OpenBLAS reads while it
 * loads, before main. So main sets it to 4 (unless the user set it), asks
 * OpenBLAS to read its environment again (openblas_read_env) and stops the
 * pool it started (blas_thread_shutdown_): the next threaded call, a
 * PCA's, starts the pool again with the short spin, and idle workers then
 * sleep at once. Both are exported by OpenBLAS but not in its header, so
 * they are looked up: with another BLAS behind libblas.so.3 (Debian's
 * alternatives), or an OpenBLAS without them, the process runs itself
 * again with the variable set, as it did before (that costs a second
 * loading of every library: 0.03 s CPU). */
void short_blas_spin(char **argv)
{
    if (getenv("OPENBLAS_THREAD_TIMEOUT")) return;
    if (setenv("OPENBLAS_THREAD_TIMEOUT", "4", 1) != 0) return;
    void *read_env = dlsym(RTLD_DEFAULT, "openblas_read_env");
    void *shutdown = dlsym(RTLD_DEFAULT, "blas_thread_shutdown_");
    if (read_env && shutdown) {
        void (*reread)(void);
        int (*stop)(void);
        /* object to function pointer: POSIX dlsym's documented idiom */
        memcpy(&reread, &read_env, sizeof reread);
        memcpy(&stop, &shutdown, sizeof stop);
        reread();
        stop();
        return;
    }
    execv("/proc/self/exe", argv);
}
