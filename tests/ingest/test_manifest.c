/* tests/ingest/test_manifest.c — CSV manifests through libcsv: quoting, UTF-8,
 * CRLF, BOM, ids, and one error per kind of bad file, each naming its line. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"
#include "edgespace/es_ingest.h"

static es_status parse(es_ctx *ctx, const char *text, es_manifest **m)
{
    return es_manifest_parse(ctx, "m.csv", "/data", text, strlen(text), m);
}

static const char *cell(const es_manifest *m, int64_t r, int64_t c)
{
    return m->cells[r * m->ncols + c];
}

/* Every allocation of a parse may fail: ES_ENOMEM, no manifest, nothing
 * leaked (the table's strings change hands on success). */
static void test_alloc_sweep(void)
{
    es_ctx *ctx = NULL;
    failing_alloc fa = {0, 0, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    const char *text = "id,file,g\nx1,a.obj,p\nx2,\"b,c.obj\",q\nx3,d.obj,r\n";
    es_status rc = ES_ENOMEM;
    int64_t k;
    if (es_ctx_new(&ctx) != ES_OK) { ES_CHECK(0); return; }
    es_ctx_set_allocator(ctx, &a);
    for (k = 1; k < 300 && rc == ES_ENOMEM; k++) {
        es_manifest *m = (es_manifest *)1;
        fa.count = 0;
        fa.fail_at = k;
        rc = es_manifest_parse(ctx, "m.csv", "/d", text, strlen(text), &m);
        ES_CHECK_MSG(rc == ES_OK || rc == ES_ENOMEM, "allocation %lld: %s", (long long)k,
                     es_ctx_errmsg(ctx));
        ES_CHECK(rc == ES_OK ? m && m->nrows == 3 && !strcmp(m->ids[1], "x2") : m == NULL);
        if (rc == ES_OK) es_manifest_free(ctx, m);
        ES_CHECK_MSG(fa.live == 0, "allocation %lld: %lld blocks leaked", (long long)k,
                     (long long)fa.live);
    }
    ES_CHECK(rc == ES_OK && k > 10);
    es_ctx_free(ctx);
}

int main(void)
{
    es_ctx *ctx = NULL;
    es_manifest *m = NULL;
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);

    /* plain manifest, ids from file names */
    ES_CHECK_OK(ctx, parse(ctx, "file,subject,expression\ns001_neutral.obj,s001,neutral\n"
                                "sub/s001_happy.obj,s001,happy\n", &m));
    if (m) {
        ES_CHECK(m->ncols == 3 && m->nrows == 2 && m->file_col == 0 && m->id_col == -1);
        ES_CHECK(!strcmp(m->ids[0], "s001_neutral") && !strcmp(m->ids[1], "s001_happy"));
        ES_CHECK(!strcmp(cell(m, 1, 2), "happy") && m->lines[1] == 3);
        ES_CHECK(!strcmp(m->dir, "/data") && !strcmp(m->colnames[1], "subject"));
    }
    es_manifest_free(ctx, m);
    m = NULL;

    /* BOM, CRLF, quoted commas, doubled quotes, a newline inside a field,
     * UTF-8, blank lines, an id column, trailing newline missing */
    ES_CHECK_OK(ctx, parse(ctx, "\xef\xbb\xbfid,file,note\r\n"
                                "cat-01,\"a,b.obj\",\"say \"\"hi\"\"\"\r\n"
                                "\r\n"
                                "cat-02,c.obj,\"two\r\nlines\"\r\n"
                                "caf\xc3\xa9,d.obj,\xe2\x82\xac", &m));
    if (m) {
        ES_CHECK(m->ncols == 3 && m->nrows == 3 && m->id_col == 0 && m->file_col == 1);
        ES_CHECK(!strcmp(m->colnames[0], "id"));
        ES_CHECK(!strcmp(cell(m, 0, 1), "a,b.obj") && !strcmp(cell(m, 0, 2), "say \"hi\""));
        ES_CHECK(!strcmp(cell(m, 1, 2), "two\r\nlines"));
        ES_CHECK(!strcmp(m->ids[2], "caf\xc3\xa9") && !strcmp(cell(m, 2, 2), "\xe2\x82\xac"));
        ES_CHECK(m->lines[0] == 2 && m->lines[1] == 4 && m->lines[2] == 6);
    }
    es_manifest_free(ctx, m);
    m = NULL;

    /* errors, each with its line */
    ES_CHECK_FAILS(ctx, parse(ctx, "path,label\na.obj,x\n", &m), ES_EFORMAT, "no 'file' column");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,label\na.obj,x\nb.obj\n", &m), ES_EFORMAT,
                   "line 3: 1 fields, but the header has 2");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,label\na.obj,x\nb.obj,y\"z\n", &m), ES_EFORMAT,
                   "line 3: malformed CSV");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,label\na.obj,x\n\nb.obj,\"open\n", &m), ES_EFORMAT,
                   "unterminated quoted field (opened on line 4)");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,label\na.obj,x\nb.obj,\xff\xfe\n", &m), ES_EFORMAT,
                   "line 3, field 2: invalid UTF-8");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,label\nx/a.obj,1\ny/a.ply,2\n", &m), ES_EFORMAT,
                   "line 3: id 'a' repeats line 2");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,id\na.obj,k\nb.obj,k\n", &m), ES_EFORMAT,
                   "id 'k' repeats");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,label\n,1\n", &m), ES_EFORMAT, "line 2: empty 'file'");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,id\na.obj,\n", &m), ES_EFORMAT, "line 2: empty 'id'");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,x,x\n", &m), ES_EFORMAT, "'x' appears twice");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,a/b\n", &m), ES_EFORMAT, "'a/b'");
    ES_CHECK_FAILS(ctx, parse(ctx, "", &m), ES_EFORMAT, "empty");
    ES_CHECK(m == NULL);
    ES_CHECK_FAILS(ctx, es_manifest_read(ctx, "/nonexistent/m.csv", &m), ES_ENOTFOUND,
                   "/nonexistent/m.csv");

    /* a record is reported at the line it starts on, also when its first
     * field is quoted over several lines, and an unterminated quote at the
     * line of the quote itself */
    ES_CHECK_OK(ctx, parse(ctx, "file,id\n\"sub/\nb.obj\",X\nc.obj,Y\n", &m));
    ES_CHECK(m && m->nrows == 2 && m->lines[0] == 2 && m->lines[1] == 4);
    es_manifest_free(ctx, m);
    m = NULL;
    ES_CHECK_FAILS(ctx, parse(ctx, "file,id\n\"sub/\nb.obj\",X,extra\n", &m), ES_EFORMAT,
                   "manifest 'm.csv' line 2: 3 fields, but the header has 2");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,label\n\"a\nb.obj\",\xff\n", &m), ES_EFORMAT,
                   "manifest 'm.csv' line 2, field 2: invalid UTF-8");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,id\nsub/a.obj,A\n\"sub/b.obj\",B\n\"sub/b.obj,B\nx\ny\n",
                              &m), ES_EFORMAT, "unterminated quoted field (opened on line 4)");
    ES_CHECK_FAILS(ctx, parse(ctx, "file,a,b\nx.obj,\"p\nq\",\"open\nmore\n", &m), ES_EFORMAT,
                   "unterminated quoted field (opened on line 3)");

    /* CR-only line ends count lines like LF and CRLF, inside quotes too */
    ES_CHECK_OK(ctx, parse(ctx, "file,note\ra.obj,\"x\ry\"\r\rb.obj,z\r", &m));
    ES_CHECK(m && m->nrows == 2 && m->lines[0] == 2 && m->lines[1] == 5);
    es_manifest_free(ctx, m);
    m = NULL;
    ES_CHECK_FAILS(ctx, parse(ctx, "file,id\rsub/a.obj,CR1\rsub/b.obj,CR1\r", &m), ES_EFORMAT,
                   "manifest 'm.csv' line 3: id 'CR1' repeats line 2");

    /* ids are kept whole, however long: two that share a 1100-byte prefix
     * differ, two equal ones repeat */
    {
        char id1[1102], id2[1102], text[2400];
        memset(id1, 'a', 1100);
        memcpy(id2, id1, 1100);
        memcpy(id1 + 1100, "1", 2);
        memcpy(id2 + 1100, "2", 2);
        snprintf(text, sizeof text, "file,id\na.obj,%s\nb.obj,%s\n", id1, id2);
        ES_CHECK_OK(ctx, parse(ctx, text, &m));
        ES_CHECK(m && m->nrows == 2 && !strcmp(m->ids[0], id1) && !strcmp(m->ids[1], id2));
        es_manifest_free(ctx, m);
        m = NULL;
        snprintf(text, sizeof text, "file,id\na.obj,%s\nb.obj,%s\n", id1, id1);
        ES_CHECK_FAILS(ctx, parse(ctx, text, &m), ES_EFORMAT, "manifest 'm.csv' line 3: id 'aaa");
    }

    /* header only: zero rows is a valid manifest */
    ES_CHECK_OK(ctx, parse(ctx, "file\n", &m));
    ES_CHECK(m && m->nrows == 0);
    es_manifest_free(ctx, m);
    m = NULL;

    /* ids from paths */
    {
        char id[16];
        es_id_from_path("a/b/cat-01.obj", id, sizeof id);
        ES_CHECK(!strcmp(id, "cat-01"));
        es_id_from_path("x.tar.gz", id, sizeof id);
        ES_CHECK(!strcmp(id, "x.tar"));
        es_id_from_path(".hidden", id, sizeof id);
        ES_CHECK(!strcmp(id, ".hidden"));
        es_id_from_path("noext", id, 4);
        ES_CHECK(!strcmp(id, "noe"));
    }

    /* from a file, with its directory */
    {
        const char *dir = es_test_tmpdir("manifest");
        char path[4200];
        snprintf(path, sizeof path, "%s/m.csv", dir);
        es_test_write_file(path, "file,g\nq.obj,1\n");
        ES_CHECK_OK(ctx, es_manifest_read(ctx, path, &m));
        ES_CHECK(m && !strcmp(m->dir, dir) && m->nrows == 1);
        es_manifest_free(ctx, m);
        m = NULL;
    }

    /* the real face-study manifest */
    {
        const char *data = es_test_shared_data();
        char path[4200];
        if (!data) {
            fprintf(stderr, "skipping face-study manifest: ../shared/data is absent\n");
        } else {
            snprintf(path, sizeof path, "%s/face-study/manifest.csv", data);
            ES_CHECK_OK(ctx, es_manifest_read(ctx, path, &m));
            if (m) {
                ES_CHECK(m->nrows == 90 && m->ncols == 3);
                ES_CHECK(!strcmp(m->ids[0], "s001_neutral"));
                ES_CHECK(!strcmp(cell(m, 89, 2), "angry"));
            }
            es_manifest_free(ctx, m);
            m = NULL;
        }
    }
    es_ctx_free(ctx);
    test_alloc_sweep();
    ES_TEST_END();
}
