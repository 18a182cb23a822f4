/* lib/embed/embed_private.h — what lib/embed offers the modules above it
 * beyond its public headers (es_embed.h, es_interp.h): sparse symmetric
 * positive definite solves and the nearest rotation, for the other papers'
 * methods in lib/morph. CHOLMOD stays inside lib/embed (lib/README.md), so
 * a module above it that needs a sparse factorization asks for one here.
 * Library-private.
 */
#ifndef EDGESPACE_EMBED_PRIVATE_H
#define EDGESPACE_EMBED_PRIVATE_H

#include "core/core_private.h"
#include "edgespace/es_embed.h"

/* ---- sparse SPD systems (spd.c) ---------------------------------------------
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

/* ---- the prior's dihedrals, only where a solve reads them (prior.c) ----------
 * Whether es_embed_prior_solve(emb, target, scale, prior, opts) reads
 * prior->alpha and prior->sd, for a prior with these positions and start
 * (NULL: none): on a closed mesh without the bending term (the dihedral
 * path), with the Levenberg-Marquardt solver or polish, or where the start
 * is too far off the lengths (prior_start_max_rms: stages 2-3 from the
 * dihedrals are tried). Otherwise they may be NULL and the output is the
 * same; only report.closure_before, then measured at the prior positions'
 * own dihedrals, differs. A study's session spares the circular means over
 * its rows that way (face-study, 87 rows: a seventh of a slider step). */
int es__prior_solve_reads_dihedrals(es_embedder *emb, const double *target, double scale,
                                    const double *prior_xyz, const double *start,
                                    const es_embed_opts *opts);

/* Whether it reads prior->span_lo and span_hi: the crease guard of a closed
 * mesh without the bending term (crease_mu > 0). Without them it takes its
 * band from prior->sd. */
int es__prior_solve_reads_span(const es_embedder *emb, const es_embed_opts *opts);

/* ---- rotations (align.c) ----------------------------------------------------- */

/* Nearest proper rotation (Frobenius) to the row-major 3 x 3 matrix m, in
 * place; returns 0, or -1 when m is degenerate (then m becomes I). */
int es__rotation_nearest(double m[9]);

#endif
