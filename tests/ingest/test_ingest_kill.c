/* tests/ingest/test_ingest_kill.c — ingest is all-or-nothing even under SIGKILL.
 *
 * A store with 2 rows gets a large ingest (38 generated meshes of 10,000
 * vertices, ~40 MB of OBJ) that is killed with SIGKILL at moments spread over
 * a full run's duration: while reading, while writing the working copy, around
 * the commit. Rows go to the working copy 4 at a time (--block-rows 4), so
 * most kills land between blocks already written to the copy and blocks
 * still being read. After every kill the store must open, and be either
 * byte-for-byte the old store or (if the kill came after the atomic rename)
 * the complete new one with all 40 rows, never anything between. A later
 * successful ingest removes the working copies the killed processes left. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "es_test_run.h"
#include "edgespace/edgespace.h"


enum { NMESH = 40, NU = 100, NV = 100 };

static int64_t store_rows(es_ctx *ctx, const char *path)
{
    es_store *s = NULL;
    int64_t n;
    if (es_store_open(ctx, path, ES_STORE_READ, &s) != ES_OK) return -1;
    n = es_store_nrows(s);
    es_store_close(s);
    return n;
}

int main(void)
{
    es_ctx *ctx = NULL;
    char store[4200], m0[4300], m1[4300], p[4300], o[4300], e[4300];
    const char *dir;
    size_t nbase;
    char *base;
    FILE *f;
    double T;
    int unchanged = 0, completed = 0, during_write = 0;
    ES_TEST_BEGIN();
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE is not set");
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    dir = es_test_tmpdir("kill");
    snprintf(store, sizeof store, "%s/s.h5", dir);
    snprintf(o, sizeof o, "%s/.out", dir);
    snprintf(e, sizeof e, "%s/.err", dir);
    snprintf(m0, sizeof m0, "%s/first.csv", dir);
    snprintf(m1, sizeof m1, "%s/big.csv", dir);
    for (int k = 0; k < NMESH; k++) {
        snprintf(p, sizeof p, "%s/m%02d.obj", dir, k);
        ES_CHECK(es_test_write_torus(p, NU, NV, k) == 0);
    }
    es_test_write_file(m0, "file,batch\nm00.obj,first\nm01.obj,first\n");
    if (!(f = fopen(m1, "w"))) return 1;
    fputs("file,batch\n", f);
    for (int k = 2; k < NMESH; k++) fprintf(f, "m%02d.obj,big\n", k);
    fclose(f);

    {
        const char *argv[] = {es_test_edgespace(), "ingest", store, "--manifest", m0, NULL};
        ES_CHECK(es_test_wait(es_test_spawn(argv, o, e)) == 0);
    }
    base = es_test_slurp(store, &nbase);
    ES_CHECK(base && store_rows(ctx, store) == 2);
    if (!base) return 1;

    /* a full run, on a copy, to time it */
    {
        char copy[4300];
        const char *argv[] = {es_test_edgespace(), "ingest", copy, "--manifest", m1,
                              "--block-rows", "4", NULL};
        snprintf(copy, sizeof copy, "%s/copy.h5", dir);
        f = fopen(copy, "wb");
        fwrite(base, 1, nbase, f);
        fclose(f);
        T = es_test_now();
        ES_CHECK(es_test_wait(es_test_spawn(argv, o, e)) == 0);
        T = es_test_now() - T;
        ES_CHECK(store_rows(ctx, copy) == NMESH);
        remove(copy);
    }

    static const double at[] = {0.0, 0.05, 0.2, 0.4, 0.6, 0.75, 0.85, 0.9, 0.95, 0.98, 1.0, 1.05};
    for (size_t k = 0; k < sizeof at / sizeof at[0]; k++) {
        const char *argv[] = {es_test_edgespace(), "ingest", store, "--manifest", m1,
                              "--block-rows", "4", NULL};
        pid_t pid = es_test_spawn(argv, o, e);
        int status;
        int64_t n;
        es_test_sleep(at[k] * T);
        kill(pid, SIGKILL);
        status = es_test_wait(pid);
        {
            char mine[64];
            snprintf(mine, sizeof mine, ".tmp-%ld-", (long)pid);
            if (status == 128 + SIGKILL && es_test_count_entries(dir, mine) > 0) during_write++;
        }
        n = store_rows(ctx, store);
        ES_CHECK_MSG(n == 2 || n == NMESH, "killed at %.0f%% of %.2f s: store has %lld rows "
                     "(exit %d)", 100 * at[k], T, (long long)n, status);
        if (n == 2) {
            ES_CHECK_MSG(es_test_same_bytes(store, base, nbase), "killed at %.0f%%: store "
                         "opens with the old rows but its bytes changed", 100 * at[k]);
            unchanged++;
        } else if (n == NMESH) {
            completed++;
            f = fopen(store, "wb");  /* back to the old store for the next kill */
            fwrite(base, 1, nbase, f);
            fclose(f);
        }
    }
    fprintf(stderr, "full ingest %.2f s; %d kills left the store unchanged (%d of them with a "
            "working copy in progress), %d came after the commit\n", T, unchanged,
            during_write, completed);
    ES_CHECK(unchanged >= 3);

    /* the next ingest succeeds and removes the dead processes' copies */
    {
        const char *argv[] = {es_test_edgespace(), "ingest", store, "--manifest", m1, NULL};
        ES_CHECK(es_test_wait(es_test_spawn(argv, o, e)) == 0);
        ES_CHECK(store_rows(ctx, store) == NMESH);
        ES_CHECK(es_test_count_entries(dir, ".tmp-") == 0);
    }
    free(base);
    es_ctx_free(ctx);
    ES_TEST_END();
}
