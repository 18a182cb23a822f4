/* tools/blas_spin.h — the OpenBLAS worker spin cut short, for the edgespace
 * command and the benchmarks that measure the library as the command runs
 * it (blas_spin.c says why and how). */
#ifndef ES_TOOLS_BLAS_SPIN_H
#define ES_TOOLS_BLAS_SPIN_H

/* Call first in main: OPENBLAS_THREAD_TIMEOUT=4 unless the user set it,
 * applied to the running OpenBLAS (or, without the hooks, by running
 * argv again). */
void short_blas_spin(char **argv);

#endif
