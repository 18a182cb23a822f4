/* lib/sparse/spd.c — sparse symmetric positive definite systems on CHOLMOD
 * for the modules above (sparse_private.h): Winkler et al.'s
 * blending matrices, one per patch of the hierarchy and factorized once
 * per topology, and the cotangent Laplacians of the conformal map's Newton
 * iterations, refactorized on a fixed pattern.
 *
 * Triplets are turned into the upper triangle in compressed-column form
 * here (sorted, repeats summed) with the map from each triplet to its value
 * slot, so a refactorization only scatters new values. All matrices of a
 * set share one cholmod_common and its solve workspaces.
 */
#include "sparse/sparse_pkg.h"

#include <stdlib.h>

typedef struct spd_mat {
    cholmod_sparse *A;
    cholmod_factor *L;
    int64_t nz;              /* triplets */
    int64_t *slot;           /* nz: value slot of each triplet in A->x */
    char what[64];
} spd_mat;

struct es__spd {
    es_ctx *ctx;
    cholmod_common cm;
    int started;
    spd_mat *m;
    int64_t n, cap;
    cholmod_dense *X, *Y, *E;
};

static es_status cm_fail(es__spd *s, const char *what)
{
    if (s->cm.status == CHOLMOD_OUT_OF_MEMORY || s->cm.status == CHOLMOD_TOO_LARGE)
        ES_FAIL(s->ctx, ES_ENOMEM, "sparse solve: CHOLMOD out of memory (%s)", what);
    ES_FAIL(s->ctx, ES_ENUMERIC, "sparse solve: CHOLMOD failed (%s, status %d)", what,
            s->cm.status);
}

es_status es__spd_new(es_ctx *ctx, es__spd **out)
{
    es__spd *s = es__calloc(ctx, 1, sizeof *s);
    *out = NULL;
    if (!s) return ES_ENOMEM;
    s->ctx = ctx;
    es__sparse_start(&s->cm);
    s->started = 1;
    /* LL' also for the simplicial factors CHOLMOD picks for small matrices
     * (its default there is LDL', which factorizes indefinite matrices
     * without complaint) */
    s->cm.final_ll = 1;
    *out = s;
    return ES_OK;
}

void es__spd_free(es__spd *s)
{
    if (!s) return;
    for (int64_t k = 0; k < s->n; k++) {
        cholmod_l_free_sparse(&s->m[k].A, &s->cm);
        cholmod_l_free_factor(&s->m[k].L, &s->cm);
        es__free(s->ctx, s->m[k].slot);
    }
    cholmod_l_free_dense(&s->X, &s->cm);
    cholmod_l_free_dense(&s->Y, &s->cm);
    cholmod_l_free_dense(&s->E, &s->cm);
    if (s->started) cholmod_l_finish(&s->cm);
    es__free(s->ctx, s->m);
    es__free(s->ctx, s);
}

int64_t es__spd_count(const es__spd *s) { return s ? s->n : 0; }

int64_t es__spd_size(const es__spd *s, int64_t id)
{
    return s && id >= 0 && id < s->n ? (int64_t)s->m[id].A->nrow : 0;
}

/* Triplet k's key in the upper triangle: column-major order. */
typedef struct key { int64_t col, row, k; } key;

static int cmp_key(const void *a, const void *b)
{
    const key *x = a, *y = b;
    if (x->col != y->col) return x->col < y->col ? -1 : 1;
    if (x->row != y->row) return x->row < y->row ? -1 : 1;
    return 0;
}

static es_status factorize(es__spd *s, spd_mat *m)
{
    s->cm.status = CHOLMOD_OK;
    if (!cholmod_l_factorize(m->A, m->L, &s->cm)) return cm_fail(s, m->what);
    if (s->cm.status == CHOLMOD_NOT_POSDEF)
        ES_FAIL(s->ctx, ES_ENUMERIC, "%s: the matrix is not positive definite (column %lld)",
                m->what, (long long)m->L->minor);
    return ES_OK;
}

static void scatter(spd_mat *m, const double *v)
{
    double *x = m->A->x;
    for (int64_t p = 0; p < (int64_t)m->A->nzmax; p++) x[p] = 0;
    for (int64_t k = 0; k < m->nz; k++) x[m->slot[k]] += v[k];
}

es_status es__spd_add(es__spd *s, int64_t n, int64_t nz, const int64_t *ti, const int64_t *tj,
                      const double *v, const char *what, int64_t *id)
{
    es_ctx *ctx = s->ctx;
    key *keys;
    spd_mat m;
    int64_t nu = 0, *cp, *ri;
    es_status rc;
    if (n < 1 || nz < 0) ES_FAIL(ctx, ES_EINVAL, "%s: empty matrix", what);
    memset(&m, 0, sizeof m);
    snprintf(m.what, sizeof m.what, "%s", what);
    for (int64_t k = 0; k < nz; k++)
        if (ti[k] < 0 || ti[k] >= n || tj[k] < 0 || tj[k] >= n)
            ES_FAIL(ctx, ES_EINVAL, "%s: entry (%lld, %lld) outside %lld x %lld", what,
                    (long long)ti[k], (long long)tj[k], (long long)n, (long long)n);
    if (s->n == s->cap) {
        int64_t cap = s->cap ? 2 * s->cap : 16;
        spd_mat *nm = es__realloc(ctx, s->m, (size_t)cap * sizeof *nm);
        if (!nm) return ES_ENOMEM;
        s->m = nm;
        s->cap = cap;
    }
    keys = es__alloc_array(ctx, nz + 1, sizeof *keys);
    m.slot = es__alloc_array(ctx, nz + 1, sizeof *m.slot);
    if (!keys || !m.slot) {
        es__free(ctx, keys);
        es__free(ctx, m.slot);
        return ES_ENOMEM;
    }
    for (int64_t k = 0; k < nz; k++) {
        int64_t a = ti[k], b = tj[k];
        keys[k] = (key){a > b ? a : b, a > b ? b : a, k};
    }
    qsort(keys, (size_t)nz, sizeof *keys, cmp_key);
    for (int64_t k = 0; k < nz; k++)
        if (k == 0 || cmp_key(&keys[k], &keys[k - 1]) != 0) nu++;
    m.nz = nz;
    m.A = cholmod_l_allocate_sparse((size_t)n, (size_t)n, (size_t)(nu > 0 ? nu : 1), 1, 1, 1,
                                    CHOLMOD_REAL, &s->cm);
    if (!m.A) {
        es__free(ctx, keys);
        es__free(ctx, m.slot);
        return cm_fail(s, what);
    }
    cp = m.A->p;
    ri = m.A->i;
    for (int64_t c = 0; c <= n; c++) cp[c] = 0;
    for (int64_t k = 0, p = -1; k < nz; k++) {
        if (k == 0 || cmp_key(&keys[k], &keys[k - 1]) != 0) {
            p++;
            ri[p] = keys[k].row;
            cp[keys[k].col + 1]++;
        }
        m.slot[keys[k].k] = p;
    }
    for (int64_t c = 0; c < n; c++) cp[c + 1] += cp[c];
    es__free(ctx, keys);
    scatter(&m, v);
    m.L = cholmod_l_analyze(m.A, &s->cm);
    if (!m.L) rc = cm_fail(s, what);
    else rc = factorize(s, &m);
    if (rc != ES_OK) {
        cholmod_l_free_sparse(&m.A, &s->cm);
        cholmod_l_free_factor(&m.L, &s->cm);
        es__free(ctx, m.slot);
        return rc;
    }
    s->m[s->n] = m;
    *id = s->n++;
    return ES_OK;
}

es_status es__spd_refactor(es__spd *s, int64_t id, const double *v)
{
    if (id < 0 || id >= s->n) ES_FAIL(s->ctx, ES_EINVAL, "sparse solve: no matrix %lld",
                                      (long long)id);
    scatter(&s->m[id], v);
    return factorize(s, &s->m[id]);
}

es_status es__spd_solve(es__spd *s, int64_t id, int64_t nrhs, double *b, int64_t ldb)
{
    spd_mat *m;
    cholmod_dense B;
    int64_t n;
    if (id < 0 || id >= s->n) ES_FAIL(s->ctx, ES_EINVAL, "sparse solve: no matrix %lld",
                                      (long long)id);
    m = &s->m[id];
    n = (int64_t)m->A->nrow;
    if (nrhs < 1 || ldb < n) ES_FAIL(s->ctx, ES_EINVAL, "%s: bad right-hand side", m->what);
    /* a view of the caller's columns: no copy in */
    memset(&B, 0, sizeof B);
    B.nrow = (size_t)n;
    B.ncol = (size_t)nrhs;
    B.nzmax = (size_t)(ldb * nrhs);
    B.d = (size_t)ldb;
    B.x = b;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_l_solve2(CHOLMOD_A, m->L, &B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cm))
        return cm_fail(s, m->what);
    for (int64_t c = 0; c < nrhs; c++)
        memcpy(b + c * ldb, (double *)s->X->x + c * (int64_t)s->X->d, (size_t)n * sizeof *b);
    return ES_OK;
}
