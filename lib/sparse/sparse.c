/* lib/sparse/sparse.c — the sparse solver service on CHOLMOD (the long-
 * integer cholmod_l_ interface): a workspace, matrices, symbolic analysis,
 * numeric factorization and solves, for a caller that owns its patterns
 * (sparse_private.h).
 *
 * The handles are CHOLMOD's own objects under names of this module: an
 * es__sparse_mat is a cholmod_sparse, an es__sparse_factor a
 * cholmod_factor, an es__sparse_dense a cholmod_dense, so wrapping them
 * allocates nothing and every call reaches CHOLMOD as it did when the
 * embedder called it directly.
 */
#include "sparse/sparse_pkg.h"

#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

struct es__sparse {
    es_ctx *ctx;
    cholmod_common cm;
    int started;
    int serial_regions;
};

static cholmod_sparse *S(const es__sparse_mat *A) { return (cholmod_sparse *)A; }
static cholmod_factor *F(const es__sparse_factor *L) { return (cholmod_factor *)L; }
static cholmod_dense *D(const es__sparse_dense *B) { return (cholmod_dense *)B; }

es_status es__sparse_new(es_ctx *ctx, const es__sparse_opts *o, es__sparse **out)
{
    es__sparse *ws = es__calloc(ctx, 1, sizeof *ws);
    *out = NULL;
    if (!ws) return ES_ENOMEM;
    ws->ctx = ctx;
    es__sparse_start(&ws->cm);
    ws->started = 1;
    if (o && o->relax)
        for (int k = 0; k < 3; k++) {
            ws->cm.nrelax[k] = (size_t)o->nrelax[k];
            ws->cm.zrelax[k] = o->zrelax[k];
        }
    ws->serial_regions = o ? o->serial_regions : 0;
    *out = ws;
    return ES_OK;
}

void es__sparse_free(es__sparse *ws)
{
    if (!ws) return;
    if (ws->started) cholmod_l_finish(&ws->cm);
    es__free(ws->ctx, ws);
}

int es__sparse_status(const es__sparse *ws, int *code)
{
    int st = ws->cm.status;
    if (code) *code = st;
    if (st == CHOLMOD_OK) return ES__SPARSE_OK;
    if (st == CHOLMOD_NOT_POSDEF) return ES__SPARSE_NOT_POSDEF;
    if (st == CHOLMOD_DSMALL) return ES__SPARSE_DSMALL;
    if (st == CHOLMOD_OUT_OF_MEMORY || st == CHOLMOD_TOO_LARGE) return ES__SPARSE_NOMEM;
    return ES__SPARSE_FAILED;
}

void es__sparse_clear_status(es__sparse *ws) { ws->cm.status = CHOLMOD_OK; }

/* ---- matrices ------------------------------------------------------------- */

es__sparse_mat *es__sparse_mat_new(es__sparse *ws, int64_t n, int64_t nzmax, int upper)
{
    /* sorted, packed, real; stype 1 (upper) or -1 (lower) */
    return (es__sparse_mat *)cholmod_l_allocate_sparse((size_t)n, (size_t)n, (size_t)nzmax, 1,
                                                       1, upper ? 1 : -1, CHOLMOD_REAL,
                                                       &ws->cm);
}

es__sparse_mat *es__sparse_mat_copy(es__sparse *ws, const es__sparse_mat *A)
{
    return (es__sparse_mat *)cholmod_l_copy_sparse(S(A), &ws->cm);
}

void es__sparse_mat_free(es__sparse *ws, es__sparse_mat **A)
{
    cholmod_sparse *a = S(*A);
    cholmod_l_free_sparse(&a, &ws->cm);
    *A = NULL;
}

int64_t *es__sparse_mat_colptr(es__sparse_mat *A) { return S(A)->p; }
int64_t *es__sparse_mat_rowind(es__sparse_mat *A) { return S(A)->i; }
double *es__sparse_mat_values(es__sparse_mat *A) { return S(A)->x; }
int64_t es__sparse_mat_nzmax(const es__sparse_mat *A) { return (int64_t)S(A)->nzmax; }
int64_t es__sparse_mat_n(const es__sparse_mat *A) { return (int64_t)S(A)->ncol; }

/* Each stored entry (i, j) counts for (j, i) too, so either triangle
 * gives the whole product. */
void es__sparse_sym_matvec(const es__sparse_mat *M, const double *x, double *y)
{
    const cholmod_sparse *A = S(M);
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

/* ---- factors -------------------------------------------------------------- */

/* CHOLMOD's analysis with the ordering asked for; the workspace's settings
 * are changed for this one call and restored. Only a supernodal symbolic
 * factor may have its values allocated here: asking for to_super on a
 * simplicial one (small meshes) gave a factor whose solves were wrong
 * (residual 3 on the embedding oracle's hemi2 frames). */
es__sparse_factor *es__sparse_analyze(es__sparse *ws, es__sparse_mat *A,
                                      const es__sparse_analysis *an)
{
    static const int method[] = {0, CHOLMOD_NATURAL, CHOLMOD_AMD, CHOLMOD_METIS, CHOLMOD_GIVEN};
    cholmod_common *cm = &ws->cm;
    int nmethods = cm->nmethods, ord = cm->method[0].ordering, post = cm->postorder;
    int sup = cm->supernodal, given = an->ordering == ES__SPARSE_ORDER_GIVEN;
    cholmod_factor *L;
    if (an->simplicial) cm->supernodal = CHOLMOD_SIMPLICIAL;
    if (an->ordering != ES__SPARSE_ORDER_DEFAULT) {
        cm->nmethods = 1;
        cm->method[0].ordering = method[an->ordering];
    }
    cm->postorder = given ? 0 : an->postorder;
    L = given ? cholmod_l_analyze_p(S(A), (int64_t *)an->perm, NULL, 0, cm)
              : cholmod_l_analyze(S(A), cm);
    cm->nmethods = nmethods;
    cm->method[0].ordering = ord;
    cm->postorder = post;
    cm->supernodal = sup;
    if (L && an->values_now && L->is_super) {
        /* their first touch was ~3x the cost of a later factorization */
        if (!cholmod_l_change_factor(CHOLMOD_REAL, 1, 1, 1, 1, L, cm)) {
            int st = cm->status;
            cholmod_l_free_factor(&L, cm);
            cm->status = st;
            return NULL;
        }
        es__advise_huge(L->x, L->xsize * sizeof(double));
    }
    return (es__sparse_factor *)L;
}

es__sparse_factor *es__sparse_factor_copy(es__sparse *ws, const es__sparse_factor *L)
{
    return (es__sparse_factor *)cholmod_l_copy_factor(F(L), &ws->cm);
}

void es__sparse_factor_free(es__sparse *ws, es__sparse_factor **L)
{
    cholmod_factor *f = F(*L);
    cholmod_l_free_factor(&f, &ws->cm);
    *L = NULL;
}

const int64_t *es__sparse_factor_perm(const es__sparse_factor *L) { return F(L)->Perm; }

/* With serial_regions, CHOLMOD's OpenMP regions are made inactive for the
 * factorization. CHOLMOD 3's supernodal code opens them with a thread
 * count fixed at its compile time (4), ignoring OMP_NUM_THREADS set from
 * inside the process; its dense work goes to BLAS, which the embedder
 * already holds to its blas_threads (embed/solve.c), so the regions only
 * spread small loops and their threads spin and wait. Measured on this
 * project's 2-core machine, quiet (face-study, 9.4K vertices, default
 * solver, four points): CPU 0.40-0.53 s a point with the regions, 0.27-
 * 0.38 s without, and the wall time 5-10 % lower too (0.30 -> 0.27 s);
 * sfm_surrey subdivided to 54K: mean 1.34 -> 1.14 s. max-active-levels 0
 * is OpenMP's way of saying "no parallel region runs parallel" that a
 * num_threads clause cannot override; the caller's setting is restored. */
int es__sparse_factorize(es__sparse *ws, es__sparse_mat *A, es__sparse_factor *L)
{
    int ok;
#ifdef _OPENMP
    int levels = 0;
    if (ws->serial_regions) {
        levels = omp_get_max_active_levels();
        omp_set_max_active_levels(0);
    }
#endif
    ok = cholmod_l_factorize(S(A), F(L), &ws->cm);
#ifdef _OPENMP
    if (ws->serial_regions) omp_set_max_active_levels(levels);
#endif
    return ok;
}

/* ---- dense blocks and solves ----------------------------------------------- */

es__sparse_dense *es__sparse_dense_new(es__sparse *ws, int64_t nrow, int64_t ncol)
{
    return (es__sparse_dense *)cholmod_l_allocate_dense((size_t)nrow, (size_t)ncol,
                                                        (size_t)nrow, CHOLMOD_REAL, &ws->cm);
}

void es__sparse_dense_free(es__sparse *ws, es__sparse_dense **B)
{
    cholmod_dense *d = D(*B);
    cholmod_l_free_dense(&d, &ws->cm);
    *B = NULL;
}

double *es__sparse_dense_values(es__sparse_dense *B) { return D(B)->x; }

void es__sparse_solution_free(es__sparse *ws, es__sparse_solution *s)
{
    es__sparse_dense_free(ws, &s->X);
    es__sparse_dense_free(ws, &s->Y);
    es__sparse_dense_free(ws, &s->E);
}

const double *es__sparse_solution_values(const es__sparse_solution *s) { return D(s->X)->x; }

int es__sparse_solve(es__sparse *ws, es__sparse_factor *L, es__sparse_dense *B, int64_t ncol,
                     es__sparse_solution *s)
{
    cholmod_dense *b = D(B), *X = D(s->X), *Y = D(s->Y), *E = D(s->E);
    size_t keep = b->ncol;
    int ok;
    b->ncol = (size_t)ncol;
    ok = cholmod_l_solve2(CHOLMOD_A, F(L), b, NULL, &X, NULL, &Y, &E, &ws->cm);
    b->ncol = keep;
    s->X = (es__sparse_dense *)X;
    s->Y = (es__sparse_dense *)Y;
    s->E = (es__sparse_dense *)E;
    return ok;
}
