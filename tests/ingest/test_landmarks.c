/* tests/ingest/test_landmarks.c — TPS and long-CSV landmark readers: good files,
 * a malformed corpus (tests/data/landmarks/) whose errors must name the file
 * and line, and, with ../shared present, the rshapes apes table against the
 * procGPA oracle input it came from. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"
#include "edgespace/edgespace.h"

#include <stdarg.h>

#define DATA ES_SOURCE_ROOT "/tests/data/landmarks/"

static int nwarn;
static char lastwarn[512];
static void on_log(void *ud, es_log_level level, const char *msg)
{
    (void)ud;
    if (level == ES_LOG_WARNING) {
        nwarn++;
        snprintf(lastwarn, sizeof lastwarn, "%s", msg);
    }
}

static void test_tps(es_ctx *ctx)
{
    es_landmarks *lm = NULL;
    nwarn = 0;
    ES_CHECK_OK(ctx, es_landmarks_read_tps(ctx, DATA "good2d.tps", 1, &lm));
    ES_CHECK(lm && lm->n == 2 && lm->k == 3 && lm->d == 2);
    if (lm) {
        /* SCALE=0.5 applied to specimen 1; column-major x-block, y-block */
        ES_CHECK(lm->xyz[0] == 0.5 && lm->xyz[1] == 1.5 && lm->xyz[2] == 2.75);
        ES_CHECK(lm->xyz[3] == 1.0 && lm->xyz[4] == 2.0 && lm->xyz[5] == -3.0);
        ES_CHECK(lm->xyz[6 + 1] == 1 && lm->xyz[6 + 5] == 1);
        ES_CHECK(!strcmp(lm->ids[0], "skull_01") && !strcmp(lm->ids[1], "skull_02"));
        ES_CHECK(!strcmp(lm->images[1], "skull_02.jpg"));
        ES_CHECK(lm->scale[0] == 0.5 && isnan(lm->scale[1]));
    }
    ES_CHECK(nwarn == 1 && strstr(lastwarn, "good2d.tps:13: CURVES"));
    es_landmarks_free(lm);
    ES_CHECK_OK(ctx, es_landmarks_read_tps(ctx, DATA "good2d.tps", 0, &lm));
    ES_CHECK(lm && lm->xyz[0] == 1.0);
    es_landmarks_free(lm);

    ES_CHECK_OK(ctx, es_landmarks_read_tps(ctx, DATA "good3d.tps", 1, &lm));
    ES_CHECK(lm && lm->n == 2 && lm->k == 2 && lm->d == 3);
    if (lm) {
        ES_CHECK(lm->xyz[0] == 1 && lm->xyz[1] == 4 && lm->xyz[2] == 2 && lm->xyz[5] == 6);
        ES_CHECK(lm->xyz[6 + 1] == 10 && lm->xyz[6 + 3] == -0.25 && lm->xyz[6 + 5] == 7);
        ES_CHECK(!strcmp(lm->ids[0], "a") && !strcmp(lm->ids[1], "2"));   /* no ID: ordinal */
    }
    es_landmarks_free(lm);
    ES_CHECK_OK(ctx, es_landmarks_read_tps(ctx, DATA "crlf.tps", 1, &lm));
    ES_CHECK(lm && !strcmp(lm->ids[0], "crlf") && lm->xyz[1] == 3);
    es_landmarks_free(lm);

    static const struct { const char *file; es_status code; const char *msg; } bad[] = {
        {"short_specimen.tps", ES_EFORMAT, "short_specimen.tps:4: expected 2 coordinates"},
        {"bad_number.tps", ES_EFORMAT, "bad_number.tps:3: expected 2 coordinates, found '3 abc'"},
        {"too_many.tps", ES_EFORMAT, "too_many.tps:3: expected 2 coordinates, found 3"},
        {"mixed_dims.tps", ES_EMISMATCH, "mixed_dims.tps:4: specimen 2 has 2 landmarks in 3D"},
        {"coords_first.tps", ES_EFORMAT, "coords_first.tps:1: unexpected line"},
        {"bad_count.tps", ES_EFORMAT, "bad_count.tps:1: bad landmark count '-2'"},
        {"bad_scale.tps", ES_EFORMAT, "bad_scale.tps:3: bad SCALE 'zero'"},
        {"id_first.tps", ES_EFORMAT, "id_first.tps:1: 'ID=5' before the first LM="},
        {"no_such_file.tps", ES_EIO, "cannot open"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s%s", DATA, bad[i].file);
        lm = (es_landmarks *)1;
        ES_CHECK_FAILS(ctx, es_landmarks_read_tps(ctx, path, 1, &lm), bad[i].code, bad[i].msg);
        ES_CHECK(lm == NULL);
    }
}

static void test_csv(es_ctx *ctx)
{
    es_landmarks *lm = NULL;
    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, DATA "good.csv", DATA "good_specimens.csv", &lm));
    ES_CHECK(lm && lm->n == 2 && lm->k == 2 && lm->d == 2 && lm->ncols == 2);
    if (lm) {
        ES_CHECK(!strcmp(lm->ids[0], "s 1") && !strcmp(lm->ids[1], "s2"));
        /* rows out of landmark order land in their place */
        ES_CHECK(lm->xyz[0] == 1 && lm->xyz[1] == 3 && lm->xyz[2] == 2 && lm->xyz[3] == 4);
        ES_CHECK(lm->xyz[4] == 5 && lm->xyz[5] == 7 && lm->xyz[7] == 8);
        ES_CHECK(es_landmarks_find_column(lm, "sex") == 1);
        ES_CHECK(es_landmarks_find_column(lm, "nope") == -1);
        ES_CHECK(!strcmp(lm->labels[0 * 2 + 0], "a") && !strcmp(lm->labels[1 * 2 + 1], "m"));
    }
    es_landmarks_free(lm);
    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, DATA "good3d.csv", NULL, &lm));
    ES_CHECK(lm && lm->d == 3 && lm->k == 2 && lm->n == 2 && lm->ncols == 0);
    if (lm) ES_CHECK(lm->xyz[1] == 4 && lm->xyz[5] == 6 && lm->xyz[6 + 1] == 1);
    es_landmarks_free(lm);

    static const struct { const char *file, *spec; es_status code; const char *msg; } bad[] = {
        {"missing_landmark.csv", NULL, ES_EFORMAT, "specimen 's2' lacks landmark 2 (of 2)"},
        {"duplicate.csv", NULL, ES_EFORMAT, "duplicate.csv:3: landmark 1 of specimen 's1' "
                                            "appears twice"},
        {"bad_header.csv", NULL, ES_EFORMAT, "bad_header.csv:1: header must name"},
        {"bad_number.csv", NULL, ES_EFORMAT, "bad_number.csv:3: y coordinate 'oops'"},
        {"bad_landmark.csv", NULL, ES_EFORMAT, "bad_landmark.csv:3: landmark '0'"},
        {"short_row.csv", NULL, ES_EFORMAT, "short_row.csv:3: 2 fields, expected 4"},
        {"good.csv", "specimens_missing.csv", ES_ENOTFOUND,
         "specimens_missing.csv: specimen 's 1' has no row"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char path[1024], spec[1024];
        snprintf(path, sizeof path, "%s%s", DATA, bad[i].file);
        if (bad[i].spec) snprintf(spec, sizeof spec, "%s%s", DATA, bad[i].spec);
        lm = (es_landmarks *)1;
        ES_CHECK_FAILS(ctx, es_landmarks_read_csv(ctx, path, bad[i].spec ? spec : NULL, &lm),
                       bad[i].code, bad[i].msg);
        ES_CHECK(lm == NULL);
    }
}

/* A landmark count from the file sizes the buffers: a count whose
 * k * d * sizeof(double) overflows is refused with the file's name, not
 * wrapped into a tiny allocation (2^56 landmarks used to crash the reader). */
static void test_size_overflow(es_ctx *ctx)
{
    const char *dir = es_test_tmpdir("landmarks");
    static const struct { const char *file, *text, *msg; } bad[] = {
        {"big.tps", "LM=72057594037927936\n1 2\nID=a\n",
         "landmarks: big.tps: 72057594037927936 landmarks in 2D are too many (LM= count)"},
        {"big3d.tps", "LM3=4611686018427387904\n1 2 3\n",
         "big3d.tps: 4611686018427387904 landmarks in 3D are too many"},
        {"big.csv", "specimen,landmark,x,y\na,1,0,0\na,2,1,0\na,72057594037927936,0,1\n",
         "landmarks: big.csv: 72057594037927936 landmarks in 2D are too many (largest "
         "landmark number)"},
        /* allocatable but absurd: more landmarks than the file has rows */
        {"many.csv", "specimen,landmark,x,y\na,1,0,0\na,2,1,0\na,99999999999,0,1\n",
         "landmarks: many.csv: 99999999999 landmarks in 2D are too many (largest landmark "
         "number) for 3 data rows (line 4)"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char path[4200];
        snprintf(path, sizeof path, "%s/%s", dir, bad[i].file);
        es_test_write_file(path, bad[i].text);
        es_landmarks *lm = (es_landmarks *)1;
        if (strstr(bad[i].file, ".tps"))
            ES_CHECK_FAILS(ctx, es_landmarks_read_tps(ctx, path, 1, &lm), ES_ERANGE, bad[i].msg);
        else
            ES_CHECK_FAILS(ctx, es_landmarks_read_csv(ctx, path, NULL, &lm), ES_ERANGE,
                           bad[i].msg);
        ES_CHECK(lm == NULL);
        remove(path);
    }
    /* many one-landmark specimens and one landmark number as large as the
     * rows: refused from the counts, before allocating specimens x landmarks */
    {
        char path[4200];
        FILE *f;
        es_landmarks *lm = (es_landmarks *)1;
        snprintf(path, sizeof path, "%s/sparse.csv", dir);
        if ((f = fopen(path, "w"))) {
            fputs("specimen,landmark,x,y\n", f);
            for (int i = 0; i < 3000; i++) fprintf(f, "s%d,1,0,0\n", i);
            fputs("z,3000,0,0\n", f);
            fclose(f);
        }
        ES_CHECK_FAILS(ctx, es_landmarks_read_csv(ctx, path, NULL, &lm), ES_EFORMAT,
                       "3001 specimens of 3000 landmarks need more than its 3001 data rows");
        ES_CHECK(lm == NULL);
        remove(path);
    }
    rmdir(dir);
}

/* A UTF-8 byte order mark (Excel's "CSV UTF-8") is not data. */
static void test_bom(es_ctx *ctx)
{
    const char *dir = es_test_tmpdir("landmarks-bom");
    char path[4200];
    es_landmarks *lm = NULL;
    snprintf(path, sizeof path, "%s/bom.csv", dir);
    es_test_write_file(path, "\xef\xbb\xbfspecimen,landmark,x,y\na,1,1,2\na,2,3,4\n");
    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, path, NULL, &lm));
    if (lm) ES_CHECK(lm->n == 1 && lm->k == 2 && lm->d == 2 && lm->xyz[3] == 4);
    es_landmarks_free(lm);
    lm = NULL;
    remove(path);
    snprintf(path, sizeof path, "%s/bom.tps", dir);
    es_test_write_file(path, "\xef\xbb\xbfLM=2\n1 2\n3 4\nID=a\n");
    ES_CHECK_OK(ctx, es_landmarks_read_tps(ctx, path, 1, &lm));
    if (lm)
        ES_CHECK_MSG(lm->n == 1 && lm->k == 2 && !strcmp(lm->ids[0], "a") && lm->xyz[0] == 1 &&
                     lm->xyz[3] == 4, "tps: n %lld k %lld id %s", (long long)lm->n,
                     (long long)lm->k, lm->ids[0]);
    es_landmarks_free(lm);
    remove(path);
    rmdir(dir);
}

/* The rshapes apes table holds gorf (specimens 1-30) and the oracle's
 * gorf_input.csv is the same data with numeric ids. */
static void test_shared(es_ctx *ctx)
{
    const char *data = es_test_shared_data();
    if (!data) {
        fprintf(stderr, "note: ../shared absent, rshapes comparison skipped\n");
        return;
    }
    char a[4096], s[4096], o[4096];
    int la = snprintf(a, sizeof a, "%s/landmarks_rshapes/apes_landmarks.csv", data);
    int ls = snprintf(s, sizeof s, "%s/landmarks_rshapes/apes_specimens.csv", data);
    int lo = snprintf(o, sizeof o, "%s/../oracle/gpa/gorf_input.csv", data);
    if (la >= (int)sizeof a || ls >= (int)sizeof s || lo >= (int)sizeof o) return;
    es_landmarks *apes = NULL, *gorf = NULL;
    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, a, s, &apes));
    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, o, NULL, &gorf));
    if (apes && gorf) {
        ES_CHECK(apes->n == 167 && apes->k == 8 && apes->d == 2);
        ES_CHECK(gorf->n == 30 && gorf->k == 8);
        ES_CHECK(memcmp(apes->xyz, gorf->xyz, 30 * 16 * sizeof(double)) == 0);
        int64_t g = es_landmarks_find_column(apes, "group");
        ES_CHECK(g >= 0 && !strcmp(apes->labels[0 * apes->ncols + g], "gorf"));
    }
    es_landmarks_free(apes);
    es_landmarks_free(gorf);
    int lm3 = snprintf(a, sizeof a, "%s/landmarks_rshapes/macaques_landmarks.csv", data);
    if (lm3 >= (int)sizeof a) return;
    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, a, NULL, &apes));
    ES_CHECK(apes && apes->n == 18 && apes->k == 7 && apes->d == 3);
    es_landmarks_free(apes);
}


/* Every allocation of the readers may fail: ES_ENOMEM, nothing returned,
 * nothing leaked (checked under ASan). */
static void test_alloc_sweep(void)
{
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) return;
    failing_alloc fa = {0, 0, 0};
    es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
    es_ctx_set_allocator(ctx, &a);
    static const char *what[] = {"tps", "csv"};
    for (int w = 0; w < 2; w++) {
        es_status rc = ES_ENOMEM;
        int64_t k;
        for (k = 1; k < 500 && rc == ES_ENOMEM; k++) {
            es_landmarks *lm = (es_landmarks *)1;
            fa.count = 0;
            fa.fail_at = k;
            rc = w == 0 ? es_landmarks_read_tps(ctx, DATA "good2d.tps", 1, &lm)
                        : es_landmarks_read_csv(ctx, DATA "good.csv", DATA "good_specimens.csv", &lm);
            ES_CHECK_MSG(rc == ES_OK || rc == ES_ENOMEM, "%s, allocation %lld: %s", what[w],
                         (long long)k, es_ctx_errmsg(ctx));
            ES_CHECK(rc == ES_OK ? lm != NULL : lm == NULL);
            if (rc == ES_OK) es_landmarks_free(lm);
        }
        ES_CHECK(rc == ES_OK && k > 3);
    }
    es_ctx_free(ctx);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    es_ctx_set_log(ctx, on_log, NULL);
    test_tps(ctx);
    test_csv(ctx);
    test_size_overflow(ctx);
    test_bom(ctx);
    test_shared(ctx);
    test_alloc_sweep();
    es_ctx_free(ctx);
    ES_TEST_END();
}
