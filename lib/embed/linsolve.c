/* lib/embed/linsolve.c — the sparse linear algebra of the embedding, on
 * CHOLMOD: status translation, numeric factorization, solves, and the
 * lagged-factor conjugate gradients that the two Levenberg-Marquardt
 * stages (Marquardt 1963) use between factorizations.
 *
 * The damped Gauss-Newton matrices of stages 1 and 4 change little from
 * one iteration (or one damping) to the next, so the factor of an earlier
 * matrix preconditions the current one well: a few CG steps cost a small
 * fraction of a refactorization.
 */
#include "embed/embed_pkg.h"

#include <math.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* CHOLMOD reports through cm->status; translate it here. */
es_status es__cm_check(es_embedder *emb, const char *what)
{
    int st = emb->cm.status;
    if (st == CHOLMOD_OK || st == CHOLMOD_NOT_POSDEF || st == CHOLMOD_DSMALL) return ES_OK;
    if (st == CHOLMOD_OUT_OF_MEMORY || st == CHOLMOD_TOO_LARGE)
        ES_FAIL(emb->ctx, ES_ENOMEM, "embed: CHOLMOD out of memory in %s", what);
    ES_FAIL(emb->ctx, ES_ENUMERIC, "embed: CHOLMOD failed in %s (status %d)", what, st);
}

/* Numeric factorization, with CHOLMOD's OpenMP regions made inactive.
 * CHOLMOD 3's supernodal code opens them with a thread count fixed at its
 * compile time (4), ignoring OMP_NUM_THREADS set from inside the process;
 * its dense work goes to BLAS, which the solve already holds to
 * opts->blas_threads (solve.c), so the regions only spread small loops and
 * their threads spin and wait. Measured on this project's 2-core machine,
 * quiet (face-study, 9.4K vertices, default solver, four points): CPU 0.40-
 * 0.53 s a point with the regions, 0.27-0.38 s without, and the wall time
 * 5-10 % lower too (0.30 -> 0.27 s); sfm_surrey subdivided to 54K: mean
 * 1.34 -> 1.14 s. max-active-levels 0 is OpenMP's way of saying "no
 * parallel region runs parallel" that a num_threads clause cannot
 * override; the caller's setting is restored. */
int es__factorize(es_embedder *emb, cholmod_sparse *A, cholmod_factor *L)
{
    int ok;
#ifdef _OPENMP
    int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(0);
#endif
    ok = cholmod_l_factorize(A, L, &emb->cm);
#ifdef _OPENMP
    omp_set_max_active_levels(levels);
#endif
    return ok;
}

/* A failed factorization is only "not positive definite" for the damping
 * loops (they raise the damping and try again); a real CHOLMOD failure
 * carries its message up. */
int es__factor_solve(es_embedder *emb, cholmod_sparse *A, cholmod_factor *L, cholmod_dense *B)
{
    emb->cm.status = CHOLMOD_OK;
    if (!es__factorize(emb, A, L)) return es__cm_check(emb, "factorize") ? -1 : 1;
    if (emb->cm.status == CHOLMOD_NOT_POSDEF) return 1;
    if (!cholmod_l_solve2(CHOLMOD_A, L, B, NULL, &emb->X, NULL, &emb->Y, &emb->Ew, &emb->cm))
        return es__cm_check(emb, "solve") ? -1 : 1;
    return 0;
}

/* y = A x for the symmetric matrix held in its upper triangle (CSC). */
void es__sym_matvec(const cholmod_sparse *A, const double *x, double *y)
{
    const int64_t *cp = A->p, *ri = A->i;
    const double *ax = A->x;
    int64_t n = (int64_t)A->ncol;
    for (int64_t i = 0; i < n; i++) y[i] = 0;
    for (int64_t j = 0; j < n; j++)
        for (int64_t p = cp[j]; p < cp[j + 1]; p++) {
            int64_t i = ri[p];
            y[i] += ax[p] * x[j];
            if (i != j) y[j] += ax[p] * x[i];
        }
}

double es__dot(const double *a, const double *b, int64_t n)
{
    double s = 0;
    for (int64_t i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* A (H3 or HA, its damped diagonal in place) by conjugate gradients
 * preconditioned with the factor of an earlier A: the Gauss-Newton matrix
 * changes little between iterations, so a lagged factor is a very good
 * preconditioner and one solve costs a small fraction of a factorization.
 * emb->pcg holds the 4 n work vectors; B is borrowed as the single
 * right-hand side of the preconditioner's solves. */
int es__lagged_pcg(es_embedder *emb, const cholmod_sparse *A, cholmod_factor *Lf,
                   cholmod_dense *B, const double *b, double *d, double eta, int max_it)
{
    int64_t n = (int64_t)A->ncol;
    double *r = emb->pcg, *z = r + n, *p = z + n, *q = p + n, rz = 0, bn;
    double *bx = B->x;
    size_t ncol = B->ncol;
    int ret = -1;
    bn = sqrt(es__dot(b, b, n));
    for (int64_t i = 0; i < n; i++) {
        d[i] = 0;
        r[i] = b[i];
    }
    if (!(bn > 0)) return 0;
    B->ncol = 1;
    for (int it = 0; it < max_it; it++) {
        memcpy(bx, r, (size_t)n * sizeof *bx);
        if (!cholmod_l_solve2(CHOLMOD_A, Lf, B, NULL, &emb->X, NULL, &emb->Y, &emb->Ew, &emb->cm))
            break;
        memcpy(z, emb->X->x, (size_t)n * sizeof *z);
        if (it == 0) {
            memcpy(p, z, (size_t)n * sizeof *p);
            rz = es__dot(r, z, n);
        } else {
            double rz_new = es__dot(r, z, n), beta = rz_new / rz;
            rz = rz_new;
            for (int64_t i = 0; i < n; i++) p[i] = z[i] + beta * p[i];
        }
        es__sym_matvec(A, p, q);
        {
            double pq = es__dot(p, q, n), a;
            if (!(pq > 0)) break;
            a = rz / pq;
            for (int64_t i = 0; i < n; i++) {
                d[i] += a * p[i];
                r[i] -= a * q[i];
            }
        }
        if (sqrt(es__dot(r, r, n)) <= eta * bn) {
            ret = it + 1;
            break;
        }
    }
    B->ncol = ncol;
    return ret;
}
