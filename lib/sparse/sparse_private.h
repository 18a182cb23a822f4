/* lib/sparse/sparse_private.h — sparse symmetric positive definite linear
 * algebra for the modules above (library-private): the one module that
 * includes cholmod.h (lib/README.md), so CHOLMOD's types and settings stay
 * here and embed and morph see only the handles below.
 *
 * Two levels:
 *  - the solver service (sparse.c), for a caller that builds its own
 *    patterns and drives each step (the embedder, lib/embed): a workspace,
 *    matrices in compressed-column form whose arrays the caller fills,
 *    symbolic analysis with the ordering it asks for, numeric
 *    factorization, solves into a reused solution;
 *  - sets of SPD matrices given as triplets (spd.c), for a caller that only
 *    wants A x = b solved (lib/morph).
 * Neither is thread-safe: one workspace or set per thread.
 */
#ifndef EDGESPACE_SPARSE_PRIVATE_H
#define EDGESPACE_SPARSE_PRIVATE_H

#include "core/core_private.h"

#include <stdint.h>

/* ---- the solver service (sparse.c) ------------------------------------------ */

/* A workspace: CHOLMOD's settings and status, shared by every matrix,
 * factor and dense block made with it (free them with it, before it). */
typedef struct es__sparse es__sparse;
/* An n x n symmetric matrix, one triangle in compressed-column form
 * (int64 column pointers and row indices, double values), rows sorted. */
typedef struct es__sparse_mat es__sparse_mat;
/* A Cholesky factor: symbolic after es__sparse_analyze, numeric after
 * es__sparse_factorize. */
typedef struct es__sparse_factor es__sparse_factor;
/* A dense column-major block (right-hand sides, solutions). */
typedef struct es__sparse_dense es__sparse_dense;

/* Settings that differ from CHOLMOD's defaults. */
typedef struct es__sparse_opts {
    /* supernodal amalgamation (CHOLMOD's nrelax / zrelax) in place of the
     * defaults when relax is set */
    int relax;
    int64_t nrelax[3];
    double zrelax[3];
    /* numeric factorization with OpenMP's parallel regions inactive
     * (es__sparse_factorize says why) */
    int serial_regions;
} es__sparse_opts;

/* A workspace with CHOLMOD's defaults changed by o (NULL: none); quiet
 * (CHOLMOD prints nothing and calls no error handler). */
es_status es__sparse_new(es_ctx *ctx, const es__sparse_opts *o, es__sparse **out);
void es__sparse_free(es__sparse *ws);

/* What the last operation left in the workspace's status: success, the
 * two soft outcomes (a matrix not positive definite, a tiny diagonal), out
 * of memory (or too large), or another failure; *code (may be NULL) gets
 * CHOLMOD's own number for messages. es__sparse_clear_status sets it to
 * success before an operation whose outcome the caller reads. */
enum { ES__SPARSE_OK, ES__SPARSE_NOT_POSDEF, ES__SPARSE_DSMALL, ES__SPARSE_NOMEM,
       ES__SPARSE_FAILED };
int es__sparse_status(const es__sparse *ws, int *code);
void es__sparse_clear_status(es__sparse *ws);

/* An n x n matrix with room for nzmax entries, its values zero. upper: the
 * upper triangle is stored (else the lower). NULL when CHOLMOD's
 * allocation fails (status set). The caller writes the pattern into the
 * arrays below (colptr: n + 1; rowind, values: nzmax). */
es__sparse_mat *es__sparse_mat_new(es__sparse *ws, int64_t n, int64_t nzmax, int upper);
/* A copy of A (pattern and values); NULL on failure (status set). */
es__sparse_mat *es__sparse_mat_copy(es__sparse *ws, const es__sparse_mat *A);
/* Free *A (may be NULL) and set it to NULL. */
void es__sparse_mat_free(es__sparse *ws, es__sparse_mat **A);
int64_t *es__sparse_mat_colptr(es__sparse_mat *A);
int64_t *es__sparse_mat_rowind(es__sparse_mat *A);
double *es__sparse_mat_values(es__sparse_mat *A);
int64_t es__sparse_mat_nzmax(const es__sparse_mat *A);
int64_t es__sparse_mat_n(const es__sparse_mat *A);

/* y = A x for the symmetric A held in one triangle. */
void es__sparse_sym_matvec(const es__sparse_mat *A, const double *x, double *y);

/* How es__sparse_analyze orders A's rows and columns. */
enum {
    ES__SPARSE_ORDER_DEFAULT,   /* CHOLMOD's own choice among its methods */
    ES__SPARSE_ORDER_NATURAL,   /* as they are (A is already ordered) */
    ES__SPARSE_ORDER_AMD,
    ES__SPARSE_ORDER_METIS,
    ES__SPARSE_ORDER_GIVEN      /* the permutation perm */
};
typedef struct es__sparse_analysis {
    int ordering;             /* ES__SPARSE_ORDER_* */
    const int64_t *perm;      /* ORDER_GIVEN: n entries, a permutation */
    int postorder;            /* postorder the elimination tree (not with ORDER_GIVEN:
                                 the order given is taken as it is) */
    int simplicial;           /* 1: a simplicial factor; 0: CHOLMOD picks (supernodal
                                 for matrices with enough fill) */
    int values_now;           /* a supernodal factor's values allocated now, with the
                                 huge-page hint, rather than on first factorization */
} es__sparse_analysis;

/* The symbolic factor of A; NULL on failure (status set). The workspace's
 * settings are as before when it returns. */
es__sparse_factor *es__sparse_analyze(es__sparse *ws, es__sparse_mat *A,
                                      const es__sparse_analysis *an);
/* A copy of L (its analysis and values); NULL on failure (status set). */
es__sparse_factor *es__sparse_factor_copy(es__sparse *ws, const es__sparse_factor *L);
void es__sparse_factor_free(es__sparse *ws, es__sparse_factor **L);
/* The fill-reducing permutation the analysis chose (n entries): row j of
 * the factor is row perm[j] of A. */
const int64_t *es__sparse_factor_perm(const es__sparse_factor *L);

/* Numeric factorization of A into L (analysed from A's pattern). Returns 1,
 * or 0 on failure; a matrix that is not positive definite returns 1 with
 * the status ES__SPARSE_NOT_POSDEF. */
int es__sparse_factorize(es__sparse *ws, es__sparse_mat *A, es__sparse_factor *L);

/* An nrow x ncol block (leading dimension nrow); NULL on failure. */
es__sparse_dense *es__sparse_dense_new(es__sparse *ws, int64_t nrow, int64_t ncol);
void es__sparse_dense_free(es__sparse *ws, es__sparse_dense **D);
double *es__sparse_dense_values(es__sparse_dense *D);

/* The solution of a solve and CHOLMOD's workspaces for it, allocated on
 * the first solve and reused by later ones (zero-initialize; free with
 * es__sparse_solution_free). */
typedef struct es__sparse_solution {
    es__sparse_dense *X, *Y, *E;
} es__sparse_solution;
void es__sparse_solution_free(es__sparse *ws, es__sparse_solution *s);
/* X's values: column-major, leading dimension the factor's n. */
const double *es__sparse_solution_values(const es__sparse_solution *s);

/* Solve A X = B with L's numeric factor, for the first ncol columns of B,
 * into s->X. Returns 1, or 0 on failure (status set). */
int es__sparse_solve(es__sparse *ws, es__sparse_factor *L, es__sparse_dense *B, int64_t ncol,
                     es__sparse_solution *s);

/* ---- sparse SPD systems given as triplets (spd.c) ----------------------------
 * A set of sparse symmetric positive definite matrices that share one
 * CHOLMOD workspace: each is given once as triplets (its pattern analysed
 * and its values factorized then), may be refactorized with new values on
 * the same triplets (a Newton iteration), and solved any number of times
 * (the t-independent matrices of Winkler et al.'s blending, factorized once
 * per topology). Not thread-safe: one set per thread. */
typedef struct es__spd es__spd;

es_status es__spd_new(es_ctx *ctx, es__spd **out);
void es__spd_free(es__spd *s);

/* Add the n x n matrix sum_k v[k] e_{i[k]} e_{j[k]}^T + its transpose's
 * off-diagonal part: each off-diagonal entry is given once, in either
 * triangle; repeated (i, j) pairs are summed. Analyses and factorizes it;
 * *id gets its index in the set. ES_ENUMERIC (naming `what`) when it is not
 * positive definite, ES_EINVAL on an index out of range. */
es_status es__spd_add(es__spd *s, int64_t n, int64_t nz, const int64_t *i, const int64_t *j,
                      const double *v, const char *what, int64_t *id);

/* New values v (nz, in the order of es__spd_add's triplets) for matrix id:
 * numeric refactorization only. */
es_status es__spd_refactor(es__spd *s, int64_t id, const double *v);

/* Solve A x = b for nrhs right-hand sides, b (n x nrhs, leading dimension
 * ldb) overwritten by x. */
es_status es__spd_solve(es__spd *s, int64_t id, int64_t nrhs, double *b, int64_t ldb);

/* Matrices in the set and their order. */
int64_t es__spd_count(const es__spd *s);
int64_t es__spd_size(const es__spd *s, int64_t id);

#endif
