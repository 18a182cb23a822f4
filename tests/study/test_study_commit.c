/* tests/study/test_study_commit.c — who commits (issue 30): no study call
 * does; the caller publishes with es_store_commit / es_store_close or
 * discards with es_store_rollback / es_store_abort, and the files
 * es_study_embed and es_study_interp write beside a stored result ride on
 * the store handle (store's es__store_publish_with), on the synthetic faces:
 *  - a stored embedding: after the call neither the result nor the mesh and
 *    residual files are there (an old mesh file byte for byte as it was),
 *    only staged parts; a rollback removes the parts; a commit publishes
 *    the result and then renames the files into place;
 *  - a commit that fails (another writer stored the name first) publishes
 *    nothing and leaves no mesh behind and the old file as it was;
 *  - without a name nothing is stored and the files appear before the call
 *    returns (a read-only handle);
 *  - stored frames of a walk: none appear until the commit, all appear with
 *    es_store_close, none (and no part) with es_store_abort;
 *  - the walk's command is provenance only: NULL records "es_study_interp".
 */
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_stores.h"

#include <edgespace/edgespace.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* es_study_embed of the mean to out (and residuals res), stored as name
 * (NULL: not stored). */
static es_status embed(es_ctx *ctx, es_store *s, const char *name, const char *out,
                       const char *res)
{
    es_study_embed_opts o;
    es_study_embed_result r;
    es_study_embed_opts_init(&o);
    o.point = "mean";
    o.output = out;
    o.residuals = res;
    o.name = name;
    o.cache = 0;
    return es_study_embed(ctx, s, &o, NULL, &r);
}

static void test_embed(es_ctx *ctx, const char *dir, const char *store)
{
    char out[4200], res[4200];
    es_store *s = NULL, *other = NULL;
    snprintf(out, sizeof out, "%s/e.obj", dir);
    snprintf(res, sizeof res, "%s/e.csv", dir);
    es_test_write_file(out, "old\n");

    /* stored: nothing appears until the commit; a rollback removes the parts */
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK_OK(ctx, embed(ctx, s, "e", out, res));
    ES_CHECK(es_store_pending(s));
    ES_CHECK(es_test_same_bytes(out, "old\n", 4) && !exists(res));
    ES_CHECK(es_test_count_entries(dir, ".part") == 2);   /* the two staged files */
    ES_CHECK_OK(ctx, es_store_rollback(ctx, s));
    ES_CHECK(!es_store_has(s, "embed/e"));
    ES_CHECK(es_test_same_bytes(out, "old\n", 4) && !exists(res));
    ES_CHECK(es_test_count_entries(dir, ".part") == 0);

    /* a commit that fails publishes nothing: no mesh, the old file kept
     * (another writer stored embed/e first) */
    ES_CHECK_OK(ctx, embed(ctx, s, "e", out, res));
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &other));
    if (other) {
        char theirs[4200];
        snprintf(theirs, sizeof theirs, "%s/theirs.obj", dir);
        ES_CHECK_OK(ctx, embed(ctx, other, "e", theirs, NULL));
        ES_CHECK_OK(ctx, es_store_commit(ctx, other));
        ES_CHECK(exists(theirs));
        es_store_close(other);
    }
    ES_CHECK_FAILS(ctx, es_store_commit(ctx, s), ES_EEXIST, "stored by another writer");
    ES_CHECK(es_test_same_bytes(out, "old\n", 4) && !exists(res));
    ES_CHECK(es_test_count_entries(dir, ".part") == 0);
    es_store_abort(s);

    /* the commit publishes the result, then the files */
    s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK_OK(ctx, embed(ctx, s, "e2", out, res));
    ES_CHECK(es_test_same_bytes(out, "old\n", 4) && !exists(res));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    ES_CHECK(es_store_has(s, "embed/e2") && exists(res) && !es_test_same_bytes(out, "old\n", 4));
    ES_CHECK(es_test_count_entries(dir, ".part") == 0);
    es_store_close(s);

    /* not stored: the files at once, on a read-only handle */
    remove(out);
    remove(res);
    s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
    if (!s) return;
    ES_CHECK_OK(ctx, embed(ctx, s, NULL, out, res));
    ES_CHECK(exists(out) && exists(res) && !es_store_pending(s));
    ES_CHECK(es_test_count_entries(dir, ".part") == 0);
    es_store_close(s);
}

static es_status walk(es_ctx *ctx, es_store *s, const char *name, const char *pattern)
{
    es_study_interp_opts o;
    es_study_interp_opts_init(&o);
    o.from = "row:face_s01_neutral";
    o.to = "row:face_s02_happy";
    o.steps = 3;
    o.output = pattern;
    o.name = name;
    return es_study_interp(ctx, s, &o);
}

static void test_interp(es_ctx *ctx, const char *dir, const char *store)
{
    char pattern[4200], frame[4300], buf[64];
    es_store *s = NULL;
    snprintf(pattern, sizeof pattern, "%s/w_%%02d.obj", dir);

    /* aborted: no frame, no part, nothing stored */
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK_OK(ctx, walk(ctx, s, "w", pattern));
    ES_CHECK(es_test_count_entries(dir, "w_0") == 3);   /* three staged parts */
    es_store_abort(s);
    ES_CHECK(es_test_count_entries(dir, "w_0") == 0);

    /* closed: the store published, then every frame */
    s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
    if (!s) return;
    ES_CHECK_OK(ctx, walk(ctx, s, "w", pattern));
    for (int i = 0; i < 3; i++) {
        snprintf(frame, sizeof frame, "%s/w_%02d.obj", dir, i);
        ES_CHECK(!exists(frame));
    }
    es_store_close(s);
    s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
    if (!s) return;
    for (int i = 0; i < 3; i++) {
        snprintf(frame, sizeof frame, "%s/w_%02d.obj", dir, i);
        ES_CHECK_MSG(exists(frame), "frame %d missing", i);
        snprintf(frame, sizeof frame, "embed/w_%02d", i);
        ES_CHECK_MSG(es_store_has(s, frame), "%s not stored", frame);
    }
    ES_CHECK(es_test_count_entries(dir, ".part") == 0);
    /* command NULL: the provenance's default */
    ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "embed/w_01", "command", buf, sizeof buf));
    ES_CHECK_MSG(!strcmp(buf, "es_study_interp"), "command '%s'", buf);
    es_store_close(s);

    /* the interp command's name for an output pattern */
    ES_CHECK(!strcmp(es_study_interp_default_name("out/cat_%02d.obj", buf, sizeof buf), "cat"));
    ES_CHECK(!strcmp(es_study_interp_default_name("%03d.ply", buf, sizeof buf), "interp"));
}

int main(void)
{
    es_ctx *ctx = NULL;
    char store[4200];
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    const char *dir = es_test_tmpdir("study-commit");
    snprintf(store, sizeof store, "%s/faces.h5", dir);
    remove(store);
    es_test_face_store(ctx, dir, store, 6, 3);
    test_embed(ctx, dir, store);
    test_interp(ctx, dir, store);
    es_ctx_free(ctx);
    ES_TEST_END();
}
