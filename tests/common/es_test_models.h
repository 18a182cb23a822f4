/* tests/common/es_test_models.h — what the model oracle tests share: the
 * permutations a fit uses, written for an oracle in R (vegan's adonis2 takes
 * them as a matrix, RRPP through its perm.index) so its p-values must equal
 * ours exactly, and a landmark set of ../shared made into a store, a GPA
 * and the tables R reads. */
#ifndef ES_TEST_MODELS_H
#define ES_TEST_MODELS_H

#include "edgespace/edgespace.h"

/* The `count` permutations of a fit with this seed over the rows of CSV
 * table `rows_csv` (header, one record per model row, in model order),
 * within the blocks of its column `block` (NULL: none; block ids as
 * es_study_model makes them, es_groups_from_labels), written to `path` as
 * `count` lines of N 1-based row indices: row i of a permuted response takes
 * row perm[i]'s residual (es_model_permutations). Returns 1 on success. */
int es_test_write_permutations(es_ctx *ctx, const char *rows_csv, const char *block,
                               uint64_t seed, int64_t count, const char *path);

/* landmarks_rshapes/<set> ingested into dir/<set>.h5 (with `specimens` as
 * its specimens table, NULL: the set's own), aligned by `edgespace gpa`
 * (result g), and exported: store, aligned (the aligned coordinates' row
 * table) and spec (the GPA's specimen table, labels and centroid size) get
 * the paths, n bytes each. Returns 1 on success. */
int es_test_landmark_gpa(const char *dir, const char *set, const char *specimens, char *store,
                         char *aligned, char *spec, size_t n);

#endif
