/* tests/store/crafted.h — crafted stores: well-formed HDF5 files laid out
 * like an edgespace store but inconsistent in chosen ways (wrong shapes,
 * counts, types and indices, negative counts, faces past the vertex count,
 * missing datasets, rows claimed without data, heap objects with wrong
 * sizes). Written with HDF5 itself from a valid base store, so that what
 * reaches the store's checks is exactly what another program could write.
 * Used by the crafted-store suite (test_store_crafted.c) and its libFuzzer
 * target (tests/fuzz/fuzz_crafted.c). */
#ifndef EDGESPACE_TESTS_CRAFTED_H
#define EDGESPACE_TESTS_CRAFTED_H

#include <stddef.h>
#include <stdint.h>

/* What opening a store with a mutation must do. */
typedef enum crafted_expect {
    CRAFTED_REFUSE,   /* es_store_open fails with a message naming what disagrees */
    CRAFTED_OPEN,     /* a valid variant (another writer's choices): opens */
    CRAFTED_ANY       /* either, but never a crash, and reads fail cleanly */
} crafted_expect;

typedef struct crafted_mutation {
    const char *name;
    crafted_expect expect;
    const char *needle;   /* a substring of the refusal (NULL: any message) */
    int nparams;          /* variants: param is taken modulo this */
} crafted_mutation;

/* The base store (a tetrahedron, 3 rows, label columns grp and subj, a mean
 * result mean/m inside it: format version 2) at path; 0 on success. */
int crafted_base(const char *path);
/* Turn the store at path (no results yet) into format version 2, as
 * earlier releases wrote it (no store_id): results go inside it. 0 on
 * success. */
int crafted_make_legacy(const char *path);

extern const crafted_mutation crafted_mutations[];
extern const int crafted_nmutations;

/* Apply mutation k (variant param) to the store file at path, in place
 * through HDF5 (a heap mutation patches bytes). 0 on success, -1 if HDF5
 * refused to write it (the variant cannot be made). */
int crafted_apply(const char *path, int k, uint32_t param);

/* 0 if mutation k writes through HDF5, 1 if it finds what to patch with
 * HDF5 and patches bytes (string descriptors), 2 if it only patches bytes
 * (heaps, symbol tables): apply them in that order, since HDF5 would walk
 * what the patches break. */
int crafted_patches_bytes(int k);

/* 1 if a failure message is one line a user can act on: non-empty, no
 * newline, no HDF5 error-stack text or internal function names. */
int crafted_message_ok(const char *msg);

/* Read everything a command might from an open store (es_edgespace.h is
 * included by the caller): lengths, scales, positions, faces, edges, the
 * mesh, a selection, the base's result datasets and attributes, the list
 * of results, every label. Each call may fail, but only with a clean
 * message: returns 0, or -1 at the first failure whose message is not
 * crafted_message_ok (the context holds it). */
struct es_ctx;
struct es_store;
int crafted_read_all(struct es_ctx *ctx, struct es_store *s);

#endif
