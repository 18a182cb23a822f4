/* tests/tools/test_cli_store.c — the ingest, info and export commands: --help,
 * exit statuses (0 ok, 1 failure, 2 usage), messages, and what they write. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "es_test_run.h"
#include "edgespace/edgespace.h"

int main(void)
{
    static es_test_out r;
    char store[4200], m[4200], p[4400], csv[4300], outdir[4300];
    const char *dir;
    ES_TEST_BEGIN();
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE is not set");
    dir = es_test_tmpdir("cli-store");
    snprintf(store, sizeof store, "%s/s.h5", dir);
    for (int k = 0; k < 4; k++) {
        snprintf(p, sizeof p, "%s/mesh-%d.obj", dir, k);
        ES_CHECK(es_test_write_torus(p, 10, 6, k) == 0);
    }
    snprintf(m, sizeof m, "%s/m.csv", dir);
    es_test_write_file(m, "file,group\nmesh-0.obj,a\nmesh-1.obj,b\nmesh-2.obj,a\n");

    /* --help on each command, and through `edgespace help` */
    const char *verbs[3] = {"ingest", "info", "export"};
    for (int k = 0; k < 3; k++) {
        ES_RUN(&r, dir, verbs[k], "--help");
        ES_CHECK_MSG(r.status == 0 && strstr(r.out, "usage: edgespace ") &&
                     strstr(r.out, verbs[k]), "%s --help: %d %s", verbs[k], r.status, r.out);
        ES_RUN(&r, dir, "help", verbs[k]);
        ES_CHECK(r.status == 0 && strstr(r.out, "usage: edgespace "));
        ES_RUN(&r, dir, verbs[k], "--bogus");
        ES_CHECK(r.status == 2);
    }
    ES_RUN(&r, dir, "help");
    ES_CHECK(strstr(r.out, "ingest") && strstr(r.out, "export") && strstr(r.out, "info"));

    /* usage errors: exit 2 */
    ES_RUN(&r, dir, "ingest", store);
    ES_CHECK(r.status == 2 && strstr(r.err, "edgespace ingest: nothing to ingest"));
    ES_RUN(&r, dir, "ingest", store, "--manifest", m, "x.obj");
    ES_CHECK(r.status == 2 && strstr(r.err, "not both"));
    ES_RUN(&r, dir, "ingest");
    ES_CHECK(r.status == 2);
    ES_RUN(&r, dir, "export", store);
    ES_CHECK(r.status == 2 && strstr(r.err, "--lengths"));
    ES_RUN(&r, dir, "info");
    ES_CHECK(r.status == 2);
    ES_CHECK(access(store, F_OK) != 0);

    /* ingest a manifest, then files */
    ES_RUN(&r, dir, "ingest", store, "--manifest", m);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "3 added, 0 skipped") &&
                 strstr(r.out, "(new store)"), "%d: %s %s", r.status, r.out, r.err);
    ES_RUN(&r, dir, "ingest", store, "--manifest", m);
    ES_CHECK(r.status == 0 && strstr(r.out, "0 added, 3 skipped"));
    snprintf(p, sizeof p, "%s/mesh-3.obj", dir);
    ES_RUN(&r, dir, "ingest", "-q", store, p);
    ES_CHECK(r.status == 0 && r.out[0] == '\0');

    /* failure: exit 1 with "edgespace ingest: <message naming the file>" */
    snprintf(p, sizeof p, "%s/odd.obj", dir);
    ES_CHECK(es_test_write_torus(p, 10, 7, 0) == 0);
    {
        size_t n0;
        char *before = es_test_slurp(store, &n0);
        ES_RUN(&r, dir, "ingest", store, p);
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "edgespace ingest: ") &&
                     strstr(r.err, "odd.obj"), "%d: %s", r.status, r.err);
        ES_CHECK(before && es_test_same_bytes(store, before, n0));
        free(before);
        /* nor another HDF5 file (another store) */
        snprintf(p, sizeof p, "%s/other.h5", dir);
        es_test_write_file(p, "\x89HDF\r\n\x1a\nnot CSV\n");
        ES_RUN(&r, dir, "export", store, "--lengths", p);
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "HDF5"), "export onto another store: %d %s",
                     r.status, r.err);
        before = es_test_slurp(p, &n0);
        ES_CHECK(before && n0 == 16 && !memcmp(before, "\x89HDF", 4));
        free(before);
    }
    ES_RUN(&r, dir, "ingest", "--no-create", "nothere.h5", p);
    ES_CHECK(r.status == 1 && strstr(r.err, "does not exist"));

    /* info */
    ES_RUN(&r, dir, "info", store);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "rows         4: mesh-0, mesh-1, mesh-2, mesh-3") &&
                 strstr(r.out, "60 vertices, 120 faces, 180 edges") &&
                 strstr(r.out, "group            3 distinct: a (2), b (1), \"\" (1)"),
                 "%s", r.out);
    {
        /* results show up in info */
        es_ctx *ctx = NULL;
        es_store *s = NULL;
        es_provenance prov = {"test", NULL, -1, NULL};
        ES_CHECK(es_ctx_new(&ctx) == ES_OK);
        ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
        ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "pca", "all", &prov));
        ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "pca", "by-group", &prov));
        ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "mean", "a", &prov));
        ES_CHECK_OK(ctx, es_store_commit(ctx, s));
        es_store_close(s);
        es_ctx_free(ctx);
        ES_RUN(&r, dir, "info", store);
        ES_CHECK_MSG(r.status == 0 && strstr(r.out, "  mean             a\n") &&
                     strstr(r.out, "  pca              all by-group\n"), "%s", r.out);
    }
    ES_RUN(&r, dir, "info", "--rows", store);
    ES_CHECK(r.status == 0 && strstr(r.out, "\nmesh-1\t") && strstr(r.out, "\tb\n"));
    ES_RUN(&r, dir, "info", m);
    ES_CHECK(r.status == 1 && strstr(r.err, "edgespace info: ") && strstr(r.err, "not an HDF5"));

    /* export lengths (all, selected) and meshes */
    snprintf(csv, sizeof csv, "%s/l.csv", dir);
    ES_RUN(&r, dir, "export", store, "--lengths", csv, "--where", "group=a");
    ES_CHECK(r.status == 0);
    {
        size_t n;
        char *text = es_test_slurp(csv, &n);
        int lines = 0, commas = 0;
        for (size_t i = 0; text && i < n; i++) {
            lines += text[i] == '\n';
            if (!lines) commas += text[i] == ',';
        }
        ES_CHECK(lines == 3 && commas == 181);
        ES_CHECK(text && strstr(text, "\nmesh-0,") && strstr(text, "\nmesh-2,"));
        free(text);
    }
    ES_RUN(&r, dir, "export", store, "--lengths", csv, "--where", "colour=red");
    ES_CHECK(r.status == 1 && strstr(r.err, "colour"));
    /* the store given as the output (by mistake) is refused and left as it was,
     * and so for a stats command's --csv */
    {
        size_t n0;
        char *before = es_test_slurp(store, &n0);
        ES_RUN(&r, dir, "export", store, "--lengths", store);
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "store itself"), "export onto the store: %d %s",
                     r.status, r.err);
        ES_RUN(&r, dir, "mean", store, "--no-store", "--output", store);
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "HDF5"), "mean --output onto the store: %d %s",
                     r.status, r.err);
        ES_CHECK(before && es_test_same_bytes(store, before, n0));
        free(before);
    }
    snprintf(outdir, sizeof outdir, "%s/out", dir);
    ES_RUN(&r, dir, "export", store, "--meshes", outdir);
    ES_CHECK(r.status == 0);
    {
        /* the exported mesh carries the stored positions exactly */
        int64_t nv0 = 0, nv1 = 0;
        double *a, *b;
        snprintf(p, sizeof p, "%s/mesh-2.obj", outdir);
        a = es_test_obj_positions(p, &nv0);
        snprintf(p, sizeof p, "%s/mesh-2.obj", dir);
        b = es_test_obj_positions(p, &nv1);
        ES_CHECK(a && b && nv0 == 60 && nv1 == 60 && !memcmp(a, b, 180 * sizeof *a));
        free(a);
        free(b);
        ES_CHECK(es_test_count_entries(outdir, ".obj") == 4);
    }

    /* writers racing on one store: each either commits (and its result is
     * there afterwards) or is refused with a clear message; nothing is lost
     * unseen and the store stays readable */
    {
        int ok[16] = {0}, nok = 0;
        for (int round = 0; round < 8; round++) {
            char names[2][32], outf[2][4400], errf[2][4400];
            pid_t pid[2];
            for (int w = 0; w < 2; w++) {
                snprintf(names[w], sizeof names[w], "race%d_%d", round, w);
                snprintf(outf[w], sizeof outf[w], "%s/race%d.out", dir, w);
                snprintf(errf[w], sizeof errf[w], "%s/race%d.err", dir, w);
                const char *args[] = {es_test_edgespace(), "mean", store, "--name", names[w],
                                      NULL};
                pid[w] = es_test_spawn(args, outf[w], errf[w]);
            }
            for (int w = 0; w < 2; w++) {
                char err[1024];
                int st = es_test_wait(pid[w]);
                es_test_read_small(errf[w], err, sizeof err);
                ES_CHECK_MSG(st == 0 || (st == 1 && strstr(err, "changed by another writer")),
                             "racing writer %s: status %d: %s", names[w], st, err);
                ok[2 * round + w] = st == 0;
                nok += st == 0;
            }
            /* a writer is refused only because the other committed */
            ES_CHECK_MSG(ok[2 * round] || ok[2 * round + 1], "round %d: both writers refused",
                         round);
        }
        ES_CHECK(nok >= 8);
        es_ctx *ctx = NULL;
        es_store *st = NULL;
        ES_CHECK(es_ctx_new(&ctx) == ES_OK);
        if (ctx) ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &st));
        for (int i = 0; st && i < 16; i++) {
            char path[64];
            snprintf(path, sizeof path, "mean/race%d_%d", i / 2, i % 2);
            ES_CHECK_MSG(!!es_store_has(st, path) == ok[i], "%s: committed %d, in the store %d",
                         path, ok[i], es_store_has(st, path));
        }
        es_store_close(st);
        es_ctx_free(ctx);
    }
    ES_TEST_END();
}
