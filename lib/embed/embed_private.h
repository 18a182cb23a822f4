/* lib/embed/embed_private.h — what lib/embed offers the modules above it
 * beyond its public headers (es_embed.h, es_interp.h): the nearest
 * rotation, for the other papers' methods in lib/morph, and what a prior
 * solve reads, for the embedding session of lib/study. (Sparse SPD solves
 * are lib/sparse's: sparse/sparse_private.h.) Library-private.
 */
#ifndef EDGESPACE_EMBED_PRIVATE_H
#define EDGESPACE_EMBED_PRIVATE_H

#include "core/core_private.h"
#include "edgespace/es_embed.h"

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
