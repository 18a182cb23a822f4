/* lib/embed/linsolve.c — the linear solves of the embedding, on lib/sparse's
 * solver service: status translation, factorization and solve, and the
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

/* The solver reports through its workspace's status; translate it here. */
es_status es__solver_check(es_embedder *emb, const char *what)
{
    int code, st = es__sparse_status(emb->sp, &code);
    if (st == ES__SPARSE_OK || st == ES__SPARSE_NOT_POSDEF || st == ES__SPARSE_DSMALL) return ES_OK;
    if (st == ES__SPARSE_NOMEM)
        ES_FAIL(emb->ctx, ES_ENOMEM, "embed: CHOLMOD out of memory in %s", what);
    ES_FAIL(emb->ctx, ES_ENUMERIC, "embed: CHOLMOD failed in %s (status %d)", what, code);
}

/* A failed factorization is only "not positive definite" for the damping
 * loops (they raise the damping and try again); a real solver failure
 * carries its message up. */
int es__factor_solve(es_embedder *emb, es__sparse_mat *A, es__sparse_factor *L,
                     es__sparse_dense *B, int64_t ncol)
{
    es__sparse_clear_status(emb->sp);
    if (!es__sparse_factorize(emb->sp, A, L)) return es__solver_check(emb, "factorize") ? -1 : 1;
    if (es__sparse_status(emb->sp, NULL) == ES__SPARSE_NOT_POSDEF) return 1;
    if (!es__sparse_solve(emb->sp, L, B, ncol, &emb->sol))
        return es__solver_check(emb, "solve") ? -1 : 1;
    return 0;
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
int es__lagged_pcg(es_embedder *emb, const es__sparse_mat *A, es__sparse_factor *Lf,
                   es__sparse_dense *B, const double *b, double *d, double eta, int max_it)
{
    int64_t n = es__sparse_mat_n(A);
    double *r = emb->pcg, *z = r + n, *p = z + n, *q = p + n, rz = 0, bn;
    double *bx = es__sparse_dense_values(B);
    int ret = -1;
    bn = sqrt(es__dot(b, b, n));
    for (int64_t i = 0; i < n; i++) {
        d[i] = 0;
        r[i] = b[i];
    }
    if (!(bn > 0)) return 0;
    for (int it = 0; it < max_it; it++) {
        memcpy(bx, r, (size_t)n * sizeof *bx);
        if (!es__sparse_solve(emb->sp, Lf, B, 1, &emb->sol)) break;
        memcpy(z, es__sparse_solution_values(&emb->sol), (size_t)n * sizeof *z);
        if (it == 0) {
            memcpy(p, z, (size_t)n * sizeof *p);
            rz = es__dot(r, z, n);
        } else {
            double rz_new = es__dot(r, z, n), beta = rz_new / rz;
            rz = rz_new;
            for (int64_t i = 0; i < n; i++) p[i] = z[i] + beta * p[i];
        }
        es__sparse_sym_matvec(A, p, q);
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
    return ret;
}
