/* lib/stats/stats_pkg.h — helpers shared by stats.c, pca.c and
 * pca_randomized.c: block sizes and checked reads from an es_source; by the
 * linear models (formula.c, design.c, model*.c): the formula's terms, the
 * permutations and the fitted model's bases. */
#ifndef EDGESPACE_STATS_PKG_H
#define EDGESPACE_STATS_PKG_H

#ifndef ES_MODULE_STATS
#error "stats/stats_pkg.h is private to lib/stats/ (see lib/README.md)"
#endif

#include "edgespace/es_stats.h"
#include "edgespace/es_model.h"
#include "core/core_private.h"

/* Check the source's shape and reader. `what` names the caller. */
es_status es__source_check(es_ctx *ctx, const es_source *src, const char *what);

/* Rows per block: src->block if set, else about 128 MiB of doubles; never
 * more than N, at least 1. */
int64_t es__source_block(const es_source *src);

/* Read rows [row0, row0+n) into buf (E x n, ld E) and check that every
 * value is finite (ES_ENUMERIC naming the row and edge otherwise). */
es_status es__source_read(es_ctx *ctx, const es_source *src, int64_t row0, int64_t n,
                          double *buf);

/* A source whose rows are columns of a matrix in memory (es_source_matrix):
 * fills *m and *rows (NULL: all columns in order) and returns true; false
 * for any other reader. */
bool es__source_matrix_of(const es_source *src, es_mat *m, const int64_t **rows);

/* Rows [*lo, *hi) of src that this rank of ctx's job reads (all of them
 * when alone), and in how many rounds of at most `block` rows every rank
 * reads its share: a collective reader (parallel HDF5) needs every rank to
 * call it as often as the others, with n = 0 once its rows are done. */
void es__source_share(es_ctx *ctx, const es_source *src, int64_t block, int64_t *lo,
                      int64_t *hi, int64_t *rounds);

/* Round k of a share: rows [*r0, *r0 + *n), n = 0 (at hi) once the share
 * is done. */
static inline void es__source_round(int64_t lo, int64_t hi, int64_t block, int64_t k,
                                    int64_t *r0, int64_t *n)
{
    int64_t a = lo + k * block;
    if (a > hi) a = hi;
    *r0 = a;
    *n = hi - a < block ? hi - a : block;
}

/* ---- the Gram route, in pieces (pca.c, pca_strip.c, pca_parallel.c) ---- */

/* Edges [edge0, edge0 + nedges) of the N rows, in memory: column j of the
 * strip is data + cols[j] * ld (cols NULL: j * ld). row0/edge0 name rows
 * and edges in messages. */
typedef struct es__strip {
    const double *data;
    int64_t ld, nedges, nrows;
    const int64_t *cols;
    int64_t row0, edge0;
} es__strip;

/* G (N x N, upper triangle) += Y^T Y and ysum[e] += sum_j Y[e, j] for
 * Y = strip - shift 1^T (shift: the strip's nedges values). */
es_status es__strip_gram(es_ctx *ctx, const es__strip *s, const double *shift, double *G,
                         double *ysum);
/* U (nedges x r, ld ldu) = (strip - centre 1^T) V, V N x r (ld N). */
es_status es__strip_project(es_ctx *ctx, const es__strip *s, const double *centre,
                            const double *V, int64_t r, double *U, int64_t ldu);
/* The whole Gram route on a strip of all E edges (alone: the fast path of
 * matrix sources), or, in a job, on this rank's strip of E_total edges:
 * partial Gram matrices summed on rank 0, which decomposes, and the fit
 * (components gathered) returned on every rank. */
es_status es__pca_fit_gram_strip(es_ctx *ctx, const es__strip *s, int64_t E_total, int64_t K,
                                 es_pca **out);

/* The same on the ranks of ctx's job for any source: rows read in shares,
 * exchanged into strips of edges (pca_parallel.c). */
es_status es__pca_fit_gram_parallel(es_ctx *ctx, const es_source *src, int64_t K,
                                    es_pca **out);
/* out (total x r, ld total) from every rank's rows of it: rank q holds rows
 * es__par_split(total, P, q) as mine (n_q x r, ld n_q). On every rank. */
es_status es__gather_split(es_ctx *ctx, const double *mine, int64_t total, int64_t r,
                           double *out);

/* The eigenpairs the Gram route keeps. */
typedef struct es__gram_fit {
    int64_t N, r;
    double trace;    /* of the centred Gram matrix: (N - 1) x total variance */
    double *w;       /* r eigenvalues of the centred Gram matrix, descending */
    double *V;       /* N x r unit eigenvectors (ld N) */
} es__gram_fit;
/* Double-centre G (N x N, upper triangle of Y^T Y; destroyed) and keep its
 * top eigenpairs: K of them (0: all), fewer where the numerical rank (E
 * edges) is lower. */
es_status es__gram_decompose(es_ctx *ctx, double *G, int64_t N, int64_t E, int64_t K,
                             es__gram_fit *g);
/* Rank 0's g (it decomposed) copied to every rank of ctx's job. */
es_status es__gram_share(es_ctx *ctx, es__gram_fit *g);
/* method, total variance, eigenvalues and scores of p from g. */
void es__gram_fill(const es__gram_fit *g, es_pca *p);
void es__gram_fit_clear(es_ctx *ctx, es__gram_fit *g);
/* Scale each of the r columns of U (n x r, ld ldu) to unit length, the
 * lengths summed over ctx's job when sum_ranks (each rank holds rows of U);
 * ES_ENUMERIC if one vanished. */
es_status es__unit_columns(es_ctx *ctx, double *U, int64_t n, int64_t r, int64_t ldu,
                           bool sum_ranks);

/* Fit helpers of the randomized route (pca_randomized.c). */
es_status es__pca_fit_randomized(es_ctx *ctx, const es_source *src, const es_pca_opts *opts,
                                 es_pca *pca);
/* Allocate an es_pca with E, N, K set and all arrays allocated. */
es_status es__pca_alloc(es_ctx *ctx, int64_t nedges, int64_t nrows, int64_t ncomp,
                        es_pca **out);
/* Flip components so the largest-magnitude entry is positive (scores too),
 * fill explained ratios. */
void es__pca_finish(es_pca *pca);

/* ---- linear models ---- */

/* The label of formula variable v ("factor(x)") and the variable mask of
 * term j (bit v: variable v). */
const char *es__formula_var_label(const es_formula *f, int64_t v);
uint64_t es__formula_term_mask(const es_formula *f, int64_t j);

/* Permutations within blocks (model_perm.c): es__perm_next writes the next
 * permutation (row i takes row perm[i]'s residual), the sequence that
 * es_model_permutations documents. */
typedef struct es__perm {
    es_rng rng;
    int64_t n, nblocks;
    int64_t *rows;       /* n: rows grouped by block, in row order within a block */
    int64_t *start;      /* nblocks + 1: where each block starts in rows */
    int64_t *buf;        /* n */
} es__perm;
es_status es__perm_init(es_ctx *ctx, es__perm *g, int64_t n, const int64_t *blocks,
                        uint64_t seed);
void es__perm_next(es__perm *g, int64_t *perm);
void es__perm_clear(es_ctx *ctx, es__perm *g);

/* A growing orthonormal basis (N x m, ld N, room for cap columns): x is
 * orthogonalized against it twice (classical Gram-Schmidt, "twice is
 * enough": Giraud et al. 2005) and appended when what is left is above
 * 1e-7 of its norm (the tolerance of R's qr and RRPP). r (m + 1, may be
 * NULL) gets x's coordinates: x = Q r. Returns 1 if appended. */
int es__basis_add(int64_t n, double *q, int64_t *m, const double *x, double *r);

/* Maximum columns of a whole design: 1024 terms (ES_FORMULA_MAX_TERMS) of
 * many-level factors could make N x 10^8 values, and the fit's QR costs N
 * q^2 (20,000 columns of 600 rows: 10^11 flops, a few minutes). */
#define ES__DESIGN_MAX_COLUMNS 20000

/* The columns formula term fj has in a design of f keeping the terms not
 * flagged in skip (its codes follow from the kept terms before it): N x
 * *ncol values into *buf, grown (*cap columns) as needed. d: the design of
 * every term of f (variables read; its term codings are scratch). */
es_status es__design_term_values(es_ctx *ctx, es_design *d, const es_formula *f, int64_t fj,
                                 const int *skip, double **buf, int64_t *cap, int64_t *ncol);

/* The terms of f that add no rank to the intercept and the kept terms
 * before them, in one pass in term order: each flagged in skip, why[fj]
 * (allocated) says what it duplicates ("duplicates 'sex'"), and a warning
 * names it (design_alias.c). d as for es__design_term_values. */
es_status es__design_find_aliased(es_ctx *ctx, es_design *d, const es_formula *f, int *skip,
                                  char **why);

/* p-value, Z and UCL of the observed statistic s[0] among s[0..n) (s[1..n)
 * permuted; effect_size.c): p = #{s_b >= s_0 - tie} / n, NULL outputs skipped. */
es_status es__perm_summary(es_ctx *ctx, const double *s, int64_t n, double confidence,
                           double *p, double *z, double *ucl);

/* What es_model_fit keeps for the analyses after it. */
struct es_model_priv {
    es_pca *pca;         /* the principal coordinates: scores Z (N x r), components U */
    int64_t r;
    double *qf, *rf;     /* the full design: X[:, kept] = Qf Rf (N x rank, rank x rank) */
    int64_t *kept;       /* rank design columns */
    int64_t *blocks;     /* N or NULL */
    double zz;           /* ||Z||^2 = the total sum of squares */
};

/* The orthonormal basis (N x *m, allocated) of the design columns whose
 * term is selected by `use` (nterms flags; the intercept always), in design
 * order. */
es_status es__model_basis(es_ctx *ctx, const es_design *d, const int *use, double **q,
                          int64_t *m);
/* Term j's bases by the model's type: *q (N x (mr + df), allocated) holds
 * the reduced model's basis, then D, the df columns the term adds. */
es_status es__model_term_basis(es_ctx *ctx, const es_model *m, int64_t j, double **q,
                               int64_t *mr, int64_t *df);
/* E = Z - Q Q^T Z (N x r), the residuals of the model of basis q. */
es_status es__model_residuals(es_ctx *ctx, const es_model *m, const double *q, int64_t mq,
                              double *e);

#endif
