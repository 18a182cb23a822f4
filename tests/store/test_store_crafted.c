/* tests/store/test_store_crafted.c — the crafted-store suite: stores that are
 * well-formed HDF5 but disagree with themselves (crafted.c: wrong shapes,
 * counts, types, indices, negative counts, faces past the vertex count,
 * missing datasets, rows claimed without data, heap objects with wrong sizes)
 * are refused at open with one line naming what disagrees, or, where the
 * variant is another writer's valid choice, read correctly; and a valid
 * store with bytes changed at random (seeded) or cut short opens or is
 * refused, never crashes. Run under ASan by CI (build-asan), so a read or
 * write out of bounds anywhere in the library fails it. */
#include "crafted.h"

#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"

#include <unistd.h>

/* Open (read, then write a result and commit) whatever is at path. */
static es_status try_store(es_ctx *ctx, const char *path, const char *what, int write)
{
    es_store *s = NULL;
    es_status rc = es_store_open(ctx, path, ES_STORE_READ, &s);
    if (rc != ES_OK) {
        ES_CHECK_MSG(s == NULL && crafted_message_ok(es_ctx_errmsg(ctx)), "%s: open: %s", what,
                     es_ctx_errmsg(ctx));
        return rc;
    }
    ES_CHECK_MSG(crafted_read_all(ctx, s) == 0, "%s: a read failed without a clean message: %s",
                 what, es_ctx_errmsg(ctx));
    es_store_close(s);
    if (!write) return ES_OK;
    s = NULL;
    if (es_store_open(ctx, path, ES_STORE_REPLACE, &s) == ES_OK) {
        es_provenance prov = {"crafted", NULL, -1, NULL};
        const double x[2] = {1, 2};
        es_status w = es_store_result_begin(ctx, s, "mean", "again", &prov);
        if (w == ES_OK) w = es_store_put_vector(ctx, s, "mean/again/x", x, 2);
        if (w == ES_OK) w = es_store_commit(ctx, s);
        ES_CHECK_MSG(w == ES_OK || crafted_message_ok(es_ctx_errmsg(ctx)), "%s: write: %s",
                     what, es_ctx_errmsg(ctx));
        es_store_abort(s);
        s = NULL;
        if (es_store_open(ctx, path, ES_STORE_READ, &s) == ES_OK)
            ES_CHECK_MSG(crafted_read_all(ctx, s) == 0, "%s: reread: %s", what,
                         es_ctx_errmsg(ctx));
        else
            ES_CHECK_MSG(crafted_message_ok(es_ctx_errmsg(ctx)), "%s: reopen: %s", what,
                         es_ctx_errmsg(ctx));
        es_store_close(s);
    }
    return ES_OK;
}

static void write_bytes(const char *path, const char *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    ES_CHECK(f && fwrite(b, 1, n, f) == n);
    if (f) fclose(f);
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    const char *dir = es_test_tmpdir("store-crafted");
    char base[700], path[700];
    size_t nbase = 0;
    int refused = 0, opened = 0, variants = 0;
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    snprintf(base, sizeof base, "%s/base.h5", dir);
    snprintf(path, sizeof path, "%s/crafted.h5", dir);
    ES_CHECK(crafted_base(base) == 0);
    char *bytes = es_test_slurp(base, &nbase);
    ES_CHECK(bytes != NULL);
    if (!bytes) ES_TEST_END();
    /* the base itself opens and reads */
    ES_CHECK(try_store(ctx, base, "base", 0) == ES_OK);

    /* ---- every mutation, every variant ---- */
    for (int k = 0; k < crafted_nmutations; k++) {
        const crafted_mutation *m = &crafted_mutations[k];
        for (int p = 0; p < m->nparams; p++) {
            char what[200];
            snprintf(what, sizeof what, "%s (variant %d)", m->name, p);
            write_bytes(path, bytes, nbase);
            if (crafted_apply(path, k, (uint32_t)p) != 0) {
                ES_CHECK_MSG(0, "%s: could not be crafted", what);
                continue;
            }
            variants++;
            es_status rc = try_store(ctx, path, what, m->expect != CRAFTED_REFUSE);
            if (m->expect == CRAFTED_REFUSE) {
                ES_CHECK_MSG(rc != ES_OK && es_test_contains(es_ctx_errmsg(ctx), m->needle) &&
                             es_test_contains(es_ctx_errmsg(ctx), "store: "),
                             "%s: want a refusal naming \"%s\", got %d: %s", what,
                             m->needle ? m->needle : "", (int)rc, es_ctx_errmsg(ctx));
            } else if (m->expect == CRAFTED_OPEN) {
                ES_CHECK_MSG(rc == ES_OK, "%s: want it to open: %s", what, es_ctx_errmsg(ctx));
            }
            refused += rc != ES_OK;
            opened += rc == ES_OK;
        }
    }
    printf("crafted stores: %d variants of %d mutations, %d refused at open, %d opened\n",
           variants, crafted_nmutations, refused, opened);

    /* ---- the base with bytes changed at random, and cut short ---- */
    uint64_t state = 0x9E3779B97F4A7C15u;
    int crashes_guarded = 0;
    for (int t = 0; t < 300; t++) {
        char *b = malloc(nbase);
        size_t len = nbase;
        if (!b) break;
        memcpy(b, bytes, nbase);
        state = state * 6364136223846793005u + 1442695040888963407u;
        int k = 1 + (int)((state >> 60) % 4);
        for (int q = 0; q < k; q++) {
            state = state * 6364136223846793005u + 1442695040888963407u;
            b[(state >> 17) % nbase] = (char)(state >> 9);
        }
        if (t % 10 == 9) len = (size_t)((state >> 23) % nbase);   /* truncated */
        write_bytes(path, b, len);
        char what[64];
        snprintf(what, sizeof what, "random bytes %d", t);
        try_store(ctx, path, what, t % 3 == 0);
        crashes_guarded++;
        free(b);
    }
    printf("changed bytes: %d stores opened or refused cleanly\n", crashes_guarded);
    free(bytes);
    es_ctx_free(ctx);
    ES_TEST_END();
}
