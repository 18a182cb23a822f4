/* tests/common/es_test_perms.h — the permutations a model fit uses, written
 * for an oracle in R (vegan's adonis2 takes them as a matrix, RRPP through
 * its perm.index), so the oracle's p-values must equal ours exactly. */
#ifndef ES_TEST_PERMS_H
#define ES_TEST_PERMS_H

#include "edgespace/edgespace.h"

/* The `count` permutations of a fit with this seed over the rows of CSV
 * table `rows_csv` (header, one record per model row, in model order),
 * within the blocks of its column `block` (NULL: none; block ids as
 * es_study_model makes them, es_groups_from_labels), written to `path` as
 * `count` lines of N 1-based row indices: row i of a permuted response takes
 * row perm[i]'s residual (es_model_permutations). Returns 1 on success. */
int es_test_write_permutations(es_ctx *ctx, const char *rows_csv, const char *block,
                               uint64_t seed, int64_t count, const char *path);

#endif
