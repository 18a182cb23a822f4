/* tests/ingest/test_landmarks.c — TPS and long-CSV landmark readers: good files,
 * a malformed corpus (tests/data/landmarks/) whose errors must name the file
 * and line; specimens tables of thousands of ids that collide in the hash
 * table, listed in shuffled order (the bug that refused R's brains and dna
 * tables), with an empty first line, and with a real duplicate; and, with
 * ../shared present, the rshapes apes table against the procGPA oracle input
 * it came from and every rshapes table with its specimens. */
#include "core/core_private.h"
#include "core/hash.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"
#include "edgespace/edgespace.h"

#include <dirent.h>
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
        /* a count is bounded by the lines left to hold it, before any
         * allocation (LM=50000000 took 800 MB and 6 s to reach the end) */
        {"big.tps", "LM=72057594037927936\n1 2\nID=a\n",
         "landmarks: big.tps:1: 72057594037927936 landmarks (LM= count) are too many for the 3 "
         "lines that follow"},
        {"big3d.tps", "LM3=4611686018427387904\n1 2 3\n",
         "big3d.tps:1: 4611686018427387904 landmarks (LM= count) are too many"},
        {"lm50m.tps", "LM=50000000\n1 2\n3 4\n",
         "lm50m.tps:1: 50000000 landmarks (LM= count) are too many for the 3 lines"},
        {"late.tps", "LM=2\n1 2\n3 4\nLM=2\n1 2\n3 4\nLM=1000\n1 2\n",
         "late.tps:7: 1000 landmarks (LM= count) are too many for the 2 lines"},
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


/* n ids "spec_<digits>" in `groups` groups of n / groups whose FNV-1a
 * hashes share their low 14 bits: in every table of up to 2^14 slots (both
 * readers' maps, at 5000 ids) each group shares one probe chain. The
 * digits count up in place and are hashed on from the prefix's hash. */
static void colliding_ids(char (*ids)[24], int n, int groups)
{
    enum { BITS = 14 };
    const uint64_t mask = ((uint64_t)1 << BITS) - 1;
    const uint64_t h0 = es__fnv1a64_str("spec_");
    static int group_of[1 << BITS], count[1 << BITS];
    char digits[16] = "0";
    int len = 1, found = 0;
    for (int i = 0; i < 1 << BITS; i++) group_of[i] = -1, count[i] = 0;
    for (int g = 0; g < groups; g++) group_of[(g * 2654435761u) & mask] = g;   /* spread */
    while (found < n) {
        uint64_t h = es__fnv1a64(h0, digits, (size_t)len) & mask;
        if (group_of[h] >= 0 && count[h] < n / groups) {
            count[h]++;
            snprintf(ids[found++], sizeof ids[0], "spec_%s", digits);
        }
        int i = len - 1;   /* the next decimal number */
        while (i >= 0 && digits[i] == '9') digits[i--] = '0';
        if (i >= 0) {
            digits[i]++;
        } else {
            memmove(digits + 1, digits, (size_t)len + 1);
            digits[0] = '1';
            len++;
        }
    }
}

/* Thousands of specimens whose ids collide in groups of 100, the landmark
 * rows grouped by landmark (so that each specimen's rows are far apart) and
 * the specimens table in shuffled order: every specimen gets its own coordinates and its
 * own labels. The old private map read another row's id on a collision and
 * refused such a table with "specimen '...' listed twice". */
static void test_many_colliding(es_ctx *ctx)
{
    enum { N = 5000, K = 3 };
    static char ids[N][24];
    static int order[N];
    const char *dir = es_test_tmpdir("landmarks-many");
    char lpath[4200], spath[4200];
    es_landmarks *lm = NULL;
    es_rng rng;
    FILE *f;
    colliding_ids(ids, N, 50);
    /* ids in random order, so that rows of one group are not together */
    es_rng_init(&rng, 2024);
    for (int j = N - 1; j > 0; j--) {
        char t[24];
        int r = (int)es_rng_below(&rng, (uint64_t)j + 1);
        memcpy(t, ids[j], sizeof t);
        memcpy(ids[j], ids[r], sizeof t);
        memcpy(ids[r], t, sizeof t);
    }
    int64_t chain = 0;   /* ids sharing the low 14 bits with ids[0] */
    for (int j = 1; j < N; j++)
        chain += ((es__fnv1a64_str(ids[j]) ^ es__fnv1a64_str(ids[0])) & 0x3fff) == 0;
    ES_CHECK(chain == N / 50 - 1);
    snprintf(lpath, sizeof lpath, "%s/many_landmarks.csv", dir);
    snprintf(spath, sizeof spath, "%s/many_specimens.csv", dir);
    if (!(f = fopen(lpath, "w"))) { ES_CHECK(0); return; }
    fputs("specimen,landmark,x,y\n", f);
    static const int lmk_order[K] = {2, 0, 1};
    for (int q = 0; q < K; q++)
        for (int j = 0; j < N; j++)
            fprintf(f, "%s,%d,%.17g,%.17g\n", ids[j], lmk_order[q] + 1,
                    j + 0.25 * lmk_order[q], -0.5 * j + lmk_order[q]);
    fclose(f);
    for (int j = 0; j < N; j++) order[j] = j;
    for (int j = N - 1; j > 0; j--) {
        int r = (int)es_rng_below(&rng, (uint64_t)j + 1), t = order[j];
        order[j] = order[r];
        order[r] = t;
    }
    if (!(f = fopen(spath, "w"))) { ES_CHECK(0); return; }
    fputs("specimen,group,index\n", f);
    for (int i = 0; i < N; i++) fprintf(f, "%s,g%d,%d\n", ids[order[i]], order[i] % 7, order[i]);
    fclose(f);

    ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, lpath, spath, &lm));
    ES_CHECK(lm && lm->n == N && lm->k == K && lm->d == 2 && lm->ncols == 2);
    if (lm && lm->n == N && lm->k == K && lm->ncols == 2) {
        int64_t gcol = es_landmarks_find_column(lm, "group");
        int64_t icol = es_landmarks_find_column(lm, "index");
        int64_t bad = 0;
        ES_CHECK(gcol == 0 && icol == 1);
        for (int j = 0; j < N; j++) {
            char g[16], idx[16];
            const double *c = lm->xyz + j * K * 2;
            snprintf(g, sizeof g, "g%d", j % 7);
            snprintf(idx, sizeof idx, "%d", j);
            bad += strcmp(lm->ids[j], ids[j]) != 0;    /* order of first appearance */
            bad += strcmp(lm->labels[j * 2 + gcol], g) || strcmp(lm->labels[j * 2 + icol], idx);
            for (int l = 0; l < K; l++)
                bad += c[l] != j + 0.25 * l || c[K + l] != -0.5 * j + l;
        }
        ES_CHECK_MSG(bad == 0, "%lld wrong ids, labels or coordinates", (long long)bad);
    }
    es_landmarks_free(lm);
    lm = NULL;

    /* the same table with one id listed again, far from its first row: refused,
     * naming it and both lines */
    if ((f = fopen(spath, "w"))) {
        fputs("specimen,group,index\n", f);
        for (int i = 0; i < N; i++) {
            fprintf(f, "%s,g%d,%d\n", ids[order[i]], order[i] % 7, order[i]);
            if (i == N - 10) fprintf(f, "%s,again,0\n", ids[order[17]]);
        }
        fclose(f);
    }
    char msg[128];
    snprintf(msg, sizeof msg, "many_specimens.csv:%d: specimen '%s' listed twice (first on line "
             "19)", N - 10 + 3, ids[order[17]]);
    const char *want = msg;
    lm = (es_landmarks *)1;
    ES_CHECK_FAILS(ctx, es_landmarks_read_csv(ctx, lpath, spath, &lm), ES_EFORMAT, want);
    ES_CHECK(lm == NULL);
    remove(lpath);
    remove(spath);
    rmdir(dir);
}

/* Small specimens tables: ids that are prefixes of one another in another
 * order, a table starting with an empty line (it used to crash the reader),
 * a table without label columns, a short row, a real duplicate. */
static void test_specimens(es_ctx *ctx)
{
    const char *dir = es_test_tmpdir("landmarks-spec");
    char lpath[4200], spath[4200];
    es_landmarks *lm = NULL;
    snprintf(lpath, sizeof lpath, "%s/l.csv", dir);
    snprintf(spath, sizeof spath, "%s/s.csv", dir);
    es_test_write_file(lpath, "specimen,landmark,x,y\ns3,1,0,0\ns3,2,1,0\ns3,3,0,1\n"
                              "s10,1,0,0\ns10,2,2,0\ns10,3,0,2\ns1,1,0,0\ns1,2,3,0\ns1,3,0,3\n");
    static const struct { const char *text, *labels; } good[] = {
        {"specimen,group\ns10,b\ns3,a\ns1,c\n", "a b c"},
        {"\nspecimen,group\ns1,c\ns3,a\ns10,b\n", "a b c"},
        {"\n\r\n\ngroup,specimen,sex\nc,s1,f\nb,s10,m\na,s3,f\nz,unused,m\n", "a f b m c f"},
        {"id\ns10\ns1\ns3\n", ""},   /* no "specimen" column: the first; no labels */
    };
    for (size_t i = 0; i < sizeof good / sizeof *good; i++) {
        char got[64] = "";
        es_test_write_file(spath, good[i].text);
        lm = NULL;
        ES_CHECK_OK(ctx, es_landmarks_read_csv(ctx, lpath, spath, &lm));
        if (!lm) continue;
        ES_CHECK(lm->n == 3 && !strcmp(lm->ids[0], "s3") && !strcmp(lm->ids[1], "s10") &&
                 !strcmp(lm->ids[2], "s1") && lm->xyz[6 + 1] == 2);
        for (int64_t j = 0; j < lm->n * lm->ncols; j++) {
            size_t k = strlen(got);
            snprintf(got + k, sizeof got - k, "%s%s", k ? " " : "", lm->labels[j]);
        }
        ES_CHECK_MSG(!strcmp(got, good[i].labels), "table %zu: labels '%s'", i, got);
        es_landmarks_free(lm);
    }
    static const struct { const char *text; es_status code; const char *msg; } bad[] = {
        {"specimen,group\ns3,a\ns10,b\ns3,c\ns1,d\n", ES_EFORMAT,
         "s.csv:4: specimen 's3' listed twice (first on line 2)"},
        {"\nspecimen,group\ns3,a\n\ns10\ns1,d\n", ES_EFORMAT,
         "s.csv:5: 1 fields, the header has 2"},
        {"specimen,group\ns3,a\ns1,d\n", ES_ENOTFOUND, "s.csv: specimen 's10' has no row"},
        {"\n\n", ES_EFORMAT, "s.csv: empty"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        es_test_write_file(spath, bad[i].text);
        lm = (es_landmarks *)1;
        ES_CHECK_FAILS(ctx, es_landmarks_read_csv(ctx, lpath, spath, &lm), bad[i].code,
                       bad[i].msg);
        ES_CHECK(lm == NULL);
    }
    remove(lpath);
    remove(spath);
    rmdir(dir);
}

/* Every rshapes table (R's shapes data sets as long CSV) with its specimens
 * table: read whole, every specimen labelled from its own row. */
static void test_shared_all(es_ctx *ctx)
{
    const char *data = es_test_shared_data();
    char dir[4096];
    DIR *d;
    struct dirent *e;
    int tables = 0;
    if (!data || snprintf(dir, sizeof dir, "%s/landmarks_rshapes", data) >= (int)sizeof dir ||
        !(d = opendir(dir))) {
        fprintf(stderr, "note: ../shared/data/landmarks_rshapes absent, tables skipped\n");
        return;
    }
    while ((e = readdir(d))) {
        const char *suffix = "_landmarks.csv";
        size_t n = strlen(e->d_name), ls = strlen(suffix);
        char lpath[8300], spath[8300];
        if (n <= ls || strcmp(e->d_name + n - ls, suffix)) continue;
        snprintf(lpath, sizeof lpath, "%s/%s", dir, e->d_name);
        snprintf(spath, sizeof spath, "%s/%.*s_specimens.csv", dir, (int)(n - ls), e->d_name);
        if (access(spath, R_OK) != 0) continue;
        es_landmarks *lm = NULL;
        es_status rc = es_landmarks_read_csv(ctx, lpath, spath, &lm);
        ES_CHECK_MSG(rc == ES_OK, "%s: %s", e->d_name, es_ctx_errmsg(ctx));
        if (lm) {
            /* the specimens table lists each specimen once, in the same order */
            FILE *f = fopen(spath, "r");
            char line[1024];
            int64_t rows = 0, same = 0;
            if (f && fgets(line, sizeof line, f))
                while (fgets(line, sizeof line, f) && rows < lm->n) {
                    line[strcspn(line, ",\r\n")] = '\0';
                    same += !strcmp(line, lm->ids[rows++]);
                }
            if (f) fclose(f);
            ES_CHECK_MSG(lm->n >= 10 && lm->k >= 3 && same == lm->n, "%s: n %lld k %lld, "
                         "%lld ids in the specimens table's order", e->d_name,
                         (long long)lm->n, (long long)lm->k, (long long)same);
            for (int64_t j = 0; j < lm->n * lm->ncols; j++) ES_CHECK(lm->labels[j] != NULL);
        }
        es_landmarks_free(lm);
        tables++;
    }
    closedir(d);
    ES_CHECK(tables >= 5);
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
            ES_CHECK_MSG(fa.live == 0, "%s, allocation %lld: %lld blocks leaked", what[w],
                         (long long)k, (long long)fa.live);
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
    test_many_colliding(ctx);
    test_specimens(ctx);
    test_shared_all(ctx);
    test_alloc_sweep();
    es_ctx_free(ctx);
    ES_TEST_END();
}
