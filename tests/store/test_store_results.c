/* tests/store/test_store_results.c — numeric attributes and deleting results.
 *
 * Numeric attributes are stored as HDF5 numbers (checked with h5dump, Debian
 * hdf5-tools, when it is there), read back as text and as numbers, and a
 * number stored as text by older versions still reads as a number. Deleting
 * a result removes it and, with the last of its kind, the kind's group; it
 * is invisible until the commit, discarded by an abort (the store
 * byte-for-byte as it was), and refused for a result that is not there. */
#include "es_test.h"
#include "es_test_files.h"
#include "edgespace/es_store.h"

#include <stdlib.h>

static char *h5dump(const char *args, const char *path)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "h5dump %s '%s' 2>&1", args, path);
    FILE *p = popen(cmd, "r");
    if (!p) return NULL;
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - 1 - n, p)) > 0) n += got;
    if (buf) buf[n] = '\0';
    pclose(p);
    return buf;
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    es_store *s = NULL;
    char path[1024];
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    snprintf(path, sizeof path, "%s/r.h5", es_test_tmpdir("store_results"));
    remove(path);
    ES_CHECK_OK(ctx, es_store_create_edges(ctx, path, 3, 0, NULL, &s));
    es_provenance prov = {"test", NULL, -1, NULL};
    ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "model", "m", &prov));
    ES_CHECK_OK(ctx, es_store_put_attr_double(ctx, s, "model/m", "rss", 0.1));
    ES_CHECK_OK(ctx, es_store_put_attr_int(ctx, s, "model/m", "permutations", 999));
    ES_CHECK_OK(ctx, es_store_put_attr(ctx, s, "model/m", "old", "2.5"));
    ES_CHECK_OK(ctx, es_store_put_attr(ctx, s, "model/m", "formula", "~ g"));
    ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "model", "k", &prov));
    ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "point", "p", &prov));
    ES_CHECK_FAILS(ctx, es_store_put_attr_double(ctx, s, "model/none", "x", 1), ES_ENOTFOUND,
                   "no result object");
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));

    char buf[64];
    double v = 0;
    ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "model/m", "rss", buf, sizeof buf));
    ES_CHECK(!strcmp(buf, "0.10000000000000001"));
    ES_CHECK_OK(ctx, es_store_get_attr_double(ctx, s, "model/m", "rss", &v));
    ES_CHECK(v == 0.1);
    ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "model/m", "permutations", buf, sizeof buf));
    ES_CHECK(!strcmp(buf, "999"));
    ES_CHECK_OK(ctx, es_store_get_attr_double(ctx, s, "model/m", "permutations", &v));
    ES_CHECK(v == 999);
    ES_CHECK_OK(ctx, es_store_get_attr_double(ctx, s, "model/m", "old", &v));
    ES_CHECK(v == 2.5);
    ES_CHECK_FAILS(ctx, es_store_get_attr_double(ctx, s, "model/m", "formula", &v), ES_EFORMAT,
                   "'~ g', not a number");

    if (system("h5dump --version >/dev/null 2>&1") == 0) {
        /* the result is its own file beside the store (format 3) */
        char side[1100];
        snprintf(side, sizeof side, "%s.results/model/m.h5", path);
        char *out = h5dump("-a /analysis/model/m/rss", side);
        ES_CHECK_MSG(out && strstr(out, "H5T_IEEE_F64LE") && strstr(out, "0.1"), "%s", out);
        free(out);
        out = h5dump("-a /analysis/model/m/permutations", side);
        ES_CHECK_MSG(out && strstr(out, "H5T_STD_I64LE") && strstr(out, "999"), "%s", out);
        free(out);
    } else {
        fprintf(stderr, "note: h5dump not installed; the attribute types were not dumped\n");
    }

    /* delete, then abort: the store is as it was */
    size_t n0 = 0;
    char *before = es_test_slurp(path, &n0);
    ES_CHECK_OK(ctx, es_store_delete_result(ctx, s, "model", "m"));
    ES_CHECK(!es_store_has(s, "model/m") && es_store_has(s, "model/k"));
    es_store_abort(s);
    s = NULL;
    ES_CHECK(before && es_test_same_bytes(path, before, n0));
    free(before);

    /* delete and commit; the last of a kind takes the kind */
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (s) {
        ES_CHECK_OK(ctx, es_store_delete_result(ctx, s, "model", "m"));
        ES_CHECK_OK(ctx, es_store_delete_result(ctx, s, "point", "p"));
        ES_CHECK_FAILS(ctx, es_store_delete_result(ctx, s, "point", "p"), ES_ENOTFOUND,
                       "no result point/p");
        ES_CHECK_FAILS(ctx, es_store_delete_result(ctx, s, "model", "../x"), ES_EINVAL, "bad");
        es_store_close(s);
    }
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_READ, &s));
    if (s) {
        char **names = NULL;
        int64_t n = 0;
        ES_CHECK_OK(ctx, es_store_list_results(ctx, s, "", &names, &n));
        ES_CHECK(n == 1 && !strcmp(names[0], "model"));
        for (int64_t i = 0; i < n; i++) es_free(ctx, names[i]);
        es_free(ctx, names);
        ES_CHECK(es_store_has(s, "model/k") && !es_store_has(s, "model/m"));
        ES_CHECK_FAILS(ctx, es_store_delete_result(ctx, s, "model", "k"), ES_EINVAL, "read-only");
        es_store_close(s);
    }
    es_ctx_free(ctx);
    ES_TEST_END();
}
