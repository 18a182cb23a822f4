/* tests/store/test_store_layout.c — the file layout is what
 * datasets-spec/store-format.md says, as HDF5's own h5dump (Debian
 * hdf5-tools) reads it: names, types, shapes, unlimited rows, chunking,
 * attributes and values. Skips when h5dump is not installed. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "edgespace/edgespace.h"

static char store[4200], store_file[4300];
static const char *target = store;   /* the file dumped: the store or a result beside it */

/* Output of `h5dump ARGS target` (malloc'd), or NULL. */
static char *dump(const char *args)
{
    char cmd[8600], *buf = NULL;
    size_t n = 0, cap = 0, r;
    FILE *p;
    snprintf(cmd, sizeof cmd, "h5dump %s '%s' 2>&1", args, target);
    if (!(p = popen(cmd, "r"))) return NULL;
    do {
        if (n + 4096 + 1 > cap) {
            cap = cap ? 2 * cap : 65536;
            buf = realloc(buf, cap);
            if (!buf) break;
        }
        r = fread(buf + n, 1, 4096, p);
        n += r;
    } while (r > 0);
    pclose(p);
    if (buf) buf[n] = '\0';
    return buf;
}

/* Every needle must occur in `h5dump ARGS`. */
static void expect(const char *args, const char *const *needles)
{
    char *out = dump(args);
    ES_CHECK_MSG(out != NULL, "h5dump %s failed", args);
    for (int k = 0; out && needles[k]; k++)
        ES_CHECK_MSG(strstr(out, needles[k]) != NULL, "h5dump %s lacks \"%s\":\n%s", args,
                     needles[k], out);
    free(out);
}
#define EXPECT(args, ...) do { const char *es_n_[] = {__VA_ARGS__, NULL}; \
    expect((args), es_n_); } while (0)

#define VSTR "STRSIZE H5T_VARIABLE;", "CSET H5T_CSET_UTF8;"

int main(void)
{
    es_ctx *ctx = NULL;
    es_store *s = NULL;
    char m[4300], p[4300];
    const char *dir;
    ES_TEST_BEGIN();
    if (system("h5dump --version >/dev/null 2>&1") != 0)
        ES_TEST_SKIP("h5dump (Debian hdf5-tools) is not installed");
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    dir = es_test_tmpdir("layout");
    snprintf(store, sizeof store, "%s/s.h5", dir);
    for (int k = 0; k < 3; k++) {
        snprintf(p, sizeof p, "%s/shape%d.obj", dir, k);
        ES_CHECK(es_test_write_torus(p, 10, 6, k) == 0);
    }
    snprintf(m, sizeof m, "%s/m.csv", dir);
    es_test_write_file(m, "file,subject,expression\nshape0.obj,s1,neutral\n"
                          "shape1.obj,s1,happy\nshape2.obj,s2,neutral\n");
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, m, NULL, NULL));
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
    if (s) {
        es_provenance prov = {"edgespace pca", NULL, -1, "k=2"};
        double v[3] = {1, 2, 3};
        ES_CHECK_OK(ctx, es_store_result_begin(ctx, s, "pca", "all", &prov));
        ES_CHECK_OK(ctx, es_store_put_vector(ctx, s, "pca/all/eigenvalues", v, 3));
    }
    es_store_close(s);

    /* root: format version 3, its topology kind and id */
    EXPECT("-a /format_version", "H5T_STD_I64LE", "SCALAR", "(0): 3");
    EXPECT("-a /topology_kind", VSTR, "\"mesh\"");
    EXPECT("-a /store_id", VSTR, "SCALAR");
    EXPECT("-a /creator", VSTR, "\"edgespace ");
    /* topology: F x 3 and E x 2 int64, nverts, fingerprint */
    EXPECT("-p -H -d /topology/faces", "H5T_STD_I64LE", "SIMPLE { ( 120, 3 ) / ( 120, 3 ) }");
    EXPECT("-p -H -d /topology/edges", "H5T_STD_I64LE", "SIMPLE { ( 180, 2 ) / ( 180, 2 ) }");
    EXPECT("-d /topology/edges -k 1,1 -c 1,2", "(0,0): 0, 1");
    EXPECT("-a /topology/nverts", "H5T_STD_I64LE", "(0): 60");
    EXPECT("-a /topology/fingerprint", VSTR, "SCALAR");
    /* rows: chunked, extendable */
    EXPECT("-p -H -d /shapes/lengths", "H5T_IEEE_F64LE",
           "SIMPLE { ( 3, 180 ) / ( H5S_UNLIMITED, 180 ) }", "CHUNKED ( 64, 180 )");
    EXPECT("-p -H -d /shapes/positions", "H5T_IEEE_F64LE",
           "SIMPLE { ( 3, 60, 3 ) / ( H5S_UNLIMITED, 60, 3 ) }", "CHUNKED ( 64, 60, 3 )");
    EXPECT("-p -H -d /shapes/scales", "H5T_IEEE_F64LE",
           "SIMPLE { ( 3 ) / ( H5S_UNLIMITED ) }", "CHUNKED ( 256 )");
    EXPECT("-d /shapes/ids", VSTR, "SIMPLE { ( 3 ) / ( H5S_UNLIMITED ) }",
           "(0): \"shape0\", \"shape1\", \"shape2\"");
    EXPECT("-d /shapes/source_paths", VSTR, "shape2.obj\"");
    EXPECT("-d /shapes/content_hash", VSTR, "(0): \"fnv1a64:");
    /* labels: one string column per manifest column, order recorded */
    EXPECT("-a /labels/columns", VSTR, "SIMPLE { ( 3 ) / ( 3 ) }",
           "(0): \"file\", \"subject\", \"expression\"");
    EXPECT("-d /labels/expression", VSTR, "SIMPLE { ( 3 ) / ( H5S_UNLIMITED ) }",
           "(0): \"neutral\", \"happy\", \"neutral\"");
    EXPECT("-d /labels/subject", "(0): \"s1\", \"s1\", \"s2\"");
    /* analysis results with provenance, each in its own file beside the
     * store (format 3) that carries the store's id; none inside the store */
    EXPECT("-g /analysis/pca", "unable to open group");
    snprintf(store_file, sizeof store_file, "%s.results/pca/all.h5", store);
    target = store_file;
    EXPECT("-a /store_id", VSTR, "SCALAR");
    EXPECT("-a /analysis/pca/all/command", VSTR, "\"edgespace pca\"");
    EXPECT("-a /analysis/pca/all/tool_version", "\"edgespace ");
    EXPECT("-a /analysis/pca/all/time", "Z\"");
    EXPECT("-a /analysis/pca/all/params", "\"k=2\"");
    EXPECT("-d /analysis/pca/all/input_rows", "H5T_STD_I64LE", "(0): 0, 1, 2");
    EXPECT("-d /analysis/pca/all/eigenvalues", "H5T_IEEE_F64LE", "(0): 1, 2, 3");
    target = store;
    /* the lengths read by h5dump are the library's: row 1 sums to 1 */
    {
        char *out = dump("-d /shapes/lengths -s 1,0 -c 1,180 -m %.17g");
        double sum = 0;
        int count = 0;
        char *q = out ? strstr(out, "DATA {") : NULL;
        while (q && (q = strchr(q, ':'))) {
            char *end;
            q++;
            for (;;) {
                double v = strtod(q, &end);
                if (end == q) break;
                sum += v;
                count++;
                q = end;
                while (*q == ',' || *q == ' ' || *q == '\n') q++;
                if (*q == '(' || *q == '}') break;
            }
        }
        ES_CHECK_MSG(count == 180, "read %d values", count);
        ES_CHECK_CLOSE(sum, 1.0, 1e-12, 0);
        free(out);
    }
    es_ctx_free(ctx);
    ES_TEST_END();
}
