/* tests/ingest/test_ingest.c — ingest into a store: what is stored equals a direct
 * computation from the files (lengths to 1e-12 relative, rows summing to 1,
 * scale x row = raw lengths, positions exact), labels and ids, duplicate
 * detection, and all-or-nothing failures: every malformed CSV or mesh, or a
 * mesh not in correspondence, gives its error and leaves the store
 * byte-for-byte unchanged. Runs on synthetic tori, and on ../shared/data
 * (face-study, facecap_arkit, sumner_cat_poses, goast_spacetime_faces) when
 * it is present. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_alloc.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "edgespace/edgespace.h"

#include <limits.h>

enum { NU = 12, NV = 8 };


/* Two stores hold the same rows, bit for bit. */
static void check_same_stores(es_ctx *ctx, const char *a, const char *b)
{
    es_store *s = NULL, *t = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, a, ES_STORE_READ, &s));
    ES_CHECK_OK(ctx, es_store_open(ctx, b, ES_STORE_READ, &t));
    if (s && t && es_store_nrows(s) == es_store_nrows(t)) {
        int64_t N = es_store_nrows(s), E = es_store_nedges(s), V = es_store_nverts(s);
        double *x = malloc((size_t)(E * N) * sizeof *x), *y = malloc((size_t)(E * N) * sizeof *y);
        double *p = malloc((size_t)(3 * V) * sizeof *p), *q = malloc((size_t)(3 * V) * sizeof *q);
        es_mat mx = {x, E, N, E}, my = {y, E, N, E};
        ES_CHECK_OK(ctx, es_store_read_lengths(ctx, s, 0, N, mx));
        ES_CHECK_OK(ctx, es_store_read_lengths(ctx, t, 0, N, my));
        ES_CHECK(!memcmp(x, y, (size_t)(E * N) * sizeof *x));
        for (int64_t i = 0; i < N; i++) {
            ES_CHECK(!strcmp(es_store_row_id(s, i), es_store_row_id(t, i)));
            ES_CHECK(!strcmp(es_store_content_hash(s, i), es_store_content_hash(t, i)));
            ES_CHECK_OK(ctx, es_store_read_positions(ctx, s, i, p));
            ES_CHECK_OK(ctx, es_store_read_positions(ctx, t, i, q));
            ES_CHECK(!memcmp(p, q, (size_t)(3 * V) * sizeof *p));
        }
        free(x);
        free(y);
        free(p);
        free(q);
    } else {
        ES_CHECK(0);
    }
    es_store_close(s);
    es_store_close(t);
}

/* Every row of the store against its source file, read independently. */
static void check_against_files(es_ctx *ctx, const char *store_path, int64_t want_rows,
                                int64_t want_edges)
{
    es_store *s = NULL;
    int64_t N, E, V, *edges = NULL;
    double *len = NULL, *raw = NULL, *scales = NULL, *xyz = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, store_path, ES_STORE_READ, &s));
    if (!s) return;
    N = es_store_nrows(s);
    E = es_store_nedges(s);
    V = es_store_nverts(s);
    ES_CHECK_MSG(N == want_rows, "%s: %lld rows, want %lld", store_path, (long long)N,
                 (long long)want_rows);
    if (want_edges > 0) ES_CHECK(E == want_edges);
    edges = malloc((size_t)(2 * E) * sizeof *edges);
    len = malloc((size_t)E * sizeof *len);
    raw = malloc((size_t)E * sizeof *raw);
    scales = malloc((size_t)(N + 1) * sizeof *scales);
    xyz = malloc((size_t)(3 * V) * sizeof *xyz);
    ES_CHECK_OK(ctx, es_store_read_edges(ctx, s, edges));
    ES_CHECK_OK(ctx, es_store_read_scales(ctx, s, scales));
    for (int64_t i = 0; i < N; i++) {
        int64_t nv = 0;
        double *file_xyz = es_test_obj_positions(es_store_source_path(s, i), &nv);
        double sum_raw = 0, sum_row = 0, worst = 0, worst_raw = 0;
        es_mat m = {len, E, 1, E};
        char hash[25];
        size_t nbytes;
        char *bytes = es_test_slurp(es_store_source_path(s, i), &nbytes);
        ES_CHECK_MSG(file_xyz && nv == V, "row %s: cannot read %s", es_store_row_id(s, i),
                     es_store_source_path(s, i));
        if (!file_xyz || nv != V || !bytes) {
            free(file_xyz);
            free(bytes);
            continue;
        }
        es_content_hash(bytes, nbytes, hash);
        ES_CHECK(!strcmp(hash, es_store_content_hash(s, i)));
        free(bytes);
        ES_CHECK_OK(ctx, es_store_read_lengths(ctx, s, i, 1, m));
        ES_CHECK_OK(ctx, es_store_read_positions(ctx, s, i, xyz));
        ES_CHECK_MSG(!memcmp(xyz, file_xyz, (size_t)(3 * V) * sizeof *xyz),
                     "row %s: positions differ from the file", es_store_row_id(s, i));
        es_test_lengths(E, edges, file_xyz, raw);
        for (int64_t e = 0; e < E; e++) sum_raw += raw[e];
        for (int64_t e = 0; e < E; e++) {
            double d = fabs(len[e] - raw[e] / sum_raw) / (raw[e] / sum_raw);
            double dr = fabs(scales[i] * len[e] - raw[e]) / raw[e];
            if (d > worst) worst = d;
            if (dr > worst_raw) worst_raw = dr;
            sum_row += len[e];
        }
        ES_CHECK_MSG(worst <= 1e-12, "row %s: lengths differ by %g relative",
                     es_store_row_id(s, i), worst);
        ES_CHECK_MSG(worst_raw <= 1e-12, "row %s: scale x row differs from raw by %g",
                     es_store_row_id(s, i), worst_raw);
        ES_CHECK_CLOSE(sum_row, 1.0, 1e-12, 0);
        ES_CHECK_CLOSE(scales[i], sum_raw, 1e-12, 0);
        free(file_xyz);
    }
    free(edges);
    free(len);
    free(raw);
    free(scales);
    free(xyz);
    es_store_close(s);
}

/* A call that must fail with `code` (es_status_any_error: any failure) and
 * `needle` and leave `store` byte-for-byte as it was, with no working
 * copies left behind. */
#define es_status_any_error ((es_status)-1)
#define CHECK_REFUSED(call, code, needle) do {                                     \
        size_t n_ = 0;                                                             \
        char *before_ = es_test_slurp(store, &n_);                                 \
        if ((code) == es_status_any_error) {                                       \
            es_status rc_ = (call);                                                \
            ES_CHECK_MSG(rc_ != ES_OK && strstr(es_ctx_errmsg(ctx), (needle)),     \
                         "rc %d, message \"%s\", want \"%s\"", (int)rc_,          \
                         es_ctx_errmsg(ctx), (needle));                            \
        } else {                                                                   \
            ES_CHECK_FAILS(ctx, (call), (code), (needle));                         \
        }                                                                          \
        ES_CHECK_MSG(before_ && es_test_same_bytes(store, before_, n_),            \
                     "store changed by a refused ingest (%s)", needle);            \
        ES_CHECK(es_test_count_entries(dir, ".tmp-") == 0);                        \
        free(before_);                                                             \
    } while (0)

static void shared_sets(es_ctx *ctx, const char *dir)
{
    const char *data = es_test_shared_data();
    struct { const char *set, *manifest; int64_t rows, edges; } sets[] = {
        {"face-study", "manifest.csv", 90, 27871},
        {"facecap_arkit", "metadata.csv", 120, 0},
        {"sumner_cat_poses", "metadata.csv", 10, 0},
        {"goast_spacetime_faces", "metadata.csv", 4, 0},
    };
    if (!data) {
        fprintf(stderr, "skipping ../shared/data sets: ../shared/data is absent\n");
        return;
    }
    for (size_t k = 0; k < sizeof sets / sizeof sets[0]; k++) {
        char manifest[4200], store[4200];
        es_ingest_report rep;
        snprintf(manifest, sizeof manifest, "%s/%s/%s", data, sets[k].set, sets[k].manifest);
        snprintf(store, sizeof store, "%s/%s.h5", dir, sets[k].set);
        ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, manifest, NULL, &rep));
        ES_CHECK(rep.rows_added == sets[k].rows && rep.created == 1);
        check_against_files(ctx, store, sets[k].rows, sets[k].edges);
        /* ingesting again is detected and changes nothing */
        {
            size_t n0;
            char *before = es_test_slurp(store, &n0);
            ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, manifest, NULL, &rep));
            ES_CHECK(rep.rows_added == 0 && rep.rows_skipped == sets[k].rows);
            ES_CHECK(before && es_test_same_bytes(store, before, n0));
            free(before);
        }
        if (!strcmp(sets[k].set, "face-study")) {
            es_store *s = NULL;
            ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
            if (s) {
                int64_t c = es_store_find_column(s, "expression");
                ES_CHECK(c >= 0 && !strcmp(es_store_label(s, 2, c), "angry"));
                ES_CHECK(!strcmp(es_store_row_id(s, 0), "s001_neutral"));
                ES_CHECK(es_store_nverts(s) == 9409 && es_store_nfaces(s) == 18460);
            }
            es_store_close(s);
        }
        remove(store);
    }
}

/* A byte-for-byte copy (a second file with the same content). */
static void copy_file(const char *from, const char *to)
{
    size_t n;
    char *bytes = es_test_slurp(from, &n);
    FILE *f = fopen(to, "wb");
    ES_CHECK(bytes && f && fwrite(bytes, 1, n, f) == n);
    if (f) fclose(f);
    free(bytes);
}

typedef struct {
    char text[4096];
    size_t n;
} log_capture;

static void capture_log(void *ud, es_log_level level, const char *msg)
{
    log_capture *c = ud;
    (void)level;
    int k = snprintf(c->text + c->n, sizeof c->text - c->n, "%s\n", msg);
    if (k > 0) c->n = c->n + (size_t)k < sizeof c->text ? c->n + (size_t)k : sizeof c->text - 1;
}

int main(void)
{
    es_ctx *ctx = NULL;
    char store[4200], path[4300], manifest[4300], real[PATH_MAX];
    const char *dir;
    es_ingest_report rep;
    es_store *s = NULL;
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    dir = es_test_tmpdir("ingest");
    snprintf(store, sizeof store, "%s/s.h5", dir);
    snprintf(path, sizeof path, "%s/meshes", dir);
    mkdir(path, 0777);
    for (int k = 0; k < 10; k++) {
        snprintf(path, sizeof path, "%s/meshes/t%d.obj", dir, k);
        ES_CHECK(es_test_write_torus(path, NU, NV, k) == 0);
    }

    /* ---- a manifest with BOM, CRLF, quoting; a new store ---- */
    snprintf(manifest, sizeof manifest, "%s/m.csv", dir);
    es_test_write_file(manifest, "\xef\xbb\xbf" "file,group,note\r\n"
                                 "meshes/t0.obj,A,\"first, \"\"quoted\"\"\"\r\n"
                                 "meshes/t1.obj,A,\r\n"
                                 "meshes/t2.obj,B,caf\xc3\xa9\r\n"
                                 "meshes/t3.obj,B,\r\n"
                                 "meshes/t4.obj,A,\r\n"
                                 "meshes/t5.obj,B,\"two\r\nlines\"\r\n");
    {
        es_ingest_opts o;
        es_ingest_opts_init(&o);
        o.create = 0;
        ES_CHECK_FAILS(ctx, es_ingest_manifest(ctx, store, manifest, &o, &rep), ES_ENOTFOUND,
                       "does not exist");
        ES_CHECK(access(store, F_OK) != 0);
    }
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, manifest, NULL, &rep));
    ES_CHECK(rep.rows_added == 6 && rep.rows_skipped == 0 && rep.rows_total == 6 && rep.created);
    ES_CHECK(rep.bytes_read > 6 * 1000);
    check_against_files(ctx, store, 6, 3 * NU * NV);
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
    if (s) {
        int64_t g = es_store_find_column(s, "group"), note = es_store_find_column(s, "note");
        ES_CHECK(es_store_ncolumns(s) == 3 && es_store_find_column(s, "file") == 0);
        ES_CHECK(!strcmp(es_store_row_id(s, 2), "t2") && !strcmp(es_store_label(s, 2, g), "B"));
        ES_CHECK(!strcmp(es_store_label(s, 0, note), "first, \"quoted\""));
        ES_CHECK(!strcmp(es_store_label(s, 2, note), "caf\xc3\xa9"));
        ES_CHECK(!strcmp(es_store_label(s, 5, note), "two\r\nlines"));
        snprintf(path, sizeof path, "%s/meshes/t3.obj", dir);
        ES_CHECK(realpath(path, real) && !strcmp(es_store_source_path(s, 3), real));
        ES_CHECK(strlen(es_store_fingerprint(s)) == 16);
        /* the topology comes back as a mesh with the stored edges */
        es_mesh *mesh = NULL;
        ES_CHECK_OK(ctx, es_store_mesh(ctx, s, &mesh));
        if (mesh) {
            int64_t *edges = malloc((size_t)(2 * es_store_nedges(s)) * sizeof *edges);
            char fp[17];
            ES_CHECK_OK(ctx, es_store_read_edges(ctx, s, edges));
            ES_CHECK(es_mesh_nedges(mesh) == es_store_nedges(s) &&
                     !memcmp(edges, es_mesh_edges(mesh),
                             (size_t)(2 * es_mesh_nedges(mesh)) * sizeof *edges));
            es_mesh_fingerprint(mesh, fp);
            ES_CHECK(!strcmp(fp, es_store_fingerprint(s)));
            free(edges);
        }
        /* asked again it is the same (built once, shared); each caller's
         * reference outlives the others' and the store's (ASan in CI would
         * see a use after free): row 0's positions, read independently */
        es_mesh *again = NULL, *other_ctx = NULL;
        es_ctx *ctx2 = NULL;
        ES_CHECK_OK(ctx, es_store_mesh(ctx, s, &again));
        ES_CHECK(again == mesh);
        ES_CHECK(es_ctx_new(&ctx2) == ES_OK);
        ES_CHECK_OK(ctx2, es_store_mesh(ctx2, s, &other_ctx));
        ES_CHECK(other_ctx && other_ctx != mesh);   /* another context: its own */
        es_mesh_free(mesh);
        es_store_close(s);
        s = NULL;
        if (again && es_mesh_xyz(again)) {
            double *row0 = NULL;
            es_store *s2 = NULL;
            ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s2));
            if (s2 && (row0 = malloc((size_t)(3 * es_store_nverts(s2)) * sizeof *row0))) {
                ES_CHECK_OK(ctx, es_store_read_positions(ctx, s2, 0, row0));
                ES_CHECK(!memcmp(row0, es_mesh_xyz(again),
                                 (size_t)(3 * es_mesh_nverts(again)) * sizeof *row0));
            }
            free(row0);
            es_store_close(s2);
        }
        es_mesh_free(again);
        es_mesh_free(other_ctx);
        es_ctx_free(ctx2);
    }
    es_store_close(s);
    s = NULL;

    /* ---- threads change nothing: serial and 4 threads give the same rows,
     * and the error of the first bad input (in manifest order) ---- */
    {
        char s1[4300], s4[4300], m3[4300];
        es_ingest_opts o;
        es_ingest_opts_init(&o);
        snprintf(s1, sizeof s1, "%s/serial.h5", dir);
        snprintf(s4, sizeof s4, "%s/threads.h5", dir);
        o.threads = 1;
        ES_CHECK_OK(ctx, es_ingest_manifest(ctx, s1, manifest, &o, &rep));
        o.threads = 4;
        ES_CHECK_OK(ctx, es_ingest_manifest(ctx, s4, manifest, &o, &rep));
        check_same_stores(ctx, s1, s4);
        check_same_stores(ctx, s1, store);
        snprintf(m3, sizeof m3, "%s/twobad.csv", dir);
        es_test_write_file(m3, "file\nmeshes/t0.obj\nmeshes/t1.obj\nmeshes/gone1.obj\n"
                               "meshes/t2.obj\nmeshes/gone2.obj\nmeshes/t3.obj\n");
        for (int k = 0; k < 5; k++) {
            char s5[4300];
            snprintf(s5, sizeof s5, "%s/never.h5", dir);
            ES_CHECK_FAILS(ctx, es_ingest_manifest(ctx, s5, m3, &o, &rep), ES_ENOTFOUND,
                           "gone1.obj");
            ES_CHECK(access(s5, F_OK) != 0);
        }
        remove(s1);
        remove(s4);
    }

    /* ---- allocation failures: ES_ENOMEM, no store, no leak (ASan) ---- */
    {
        char s6[4300];
        failing_alloc fa = {0, 0, 0};
        es_allocator a = {fa_malloc, fa_realloc, fa_free, &fa};
        es_ingest_opts o;
        es_status rc = ES_ENOMEM;
        int64_t k;
        es_ingest_opts_init(&o);
        o.threads = 1;
        snprintf(s6, sizeof s6, "%s/sweep.h5", dir);
        for (k = 1; k < 100000; k++) {
            fa.count = 0;
            fa.fail_at = k;
            es_ctx_set_allocator(ctx, &a);
            rc = es_ingest_manifest(ctx, s6, manifest, &o, &rep);
            es_ctx_set_allocator(ctx, NULL);
            if (rc == ES_OK) break;
            ES_CHECK_MSG(rc == ES_ENOMEM, "allocation %lld: %d %s", (long long)k, (int)rc,
                         es_ctx_errmsg(ctx));
            ES_CHECK(access(s6, F_OK) != 0);
            if (rc != ES_ENOMEM) break;
        }
        ES_CHECK(rc == ES_OK && k > 10);
        ES_CHECK(es_test_count_entries(dir, ".tmp-") == 0);
        check_same_stores(ctx, s6, store);
        remove(s6);
    }

    /* ---- re-ingesting identical content: detected, file untouched ---- */
    {
        size_t n0;
        char *before = es_test_slurp(store, &n0);
        ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, manifest, NULL, &rep));
        ES_CHECK(rep.rows_added == 0 && rep.rows_skipped == 6 && rep.rows_total == 6);
        ES_CHECK(before && es_test_same_bytes(store, before, n0));
        free(before);
    }

    /* ---- files, ids from names, appended without labels ---- */
    {
        char p6[4300], p7[4300];
        const char *files[2] = {p6, p7};
        snprintf(p6, sizeof p6, "%s/meshes/t6.obj", dir);
        snprintf(p7, sizeof p7, "%s/meshes/t7.obj", dir);
        ES_CHECK_OK(ctx, es_ingest_files(ctx, store, 2, files, NULL, &rep));
        ES_CHECK(rep.rows_added == 2 && rep.rows_total == 8 && !rep.created);
        check_against_files(ctx, store, 8, 3 * NU * NV);
        ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
        if (s) {
            ES_CHECK(!strcmp(es_store_row_id(s, 7), "t7"));
            ES_CHECK(!strcmp(es_store_label(s, 7, es_store_find_column(s, "group")), ""));
        }
        es_store_close(s);
        s = NULL;
    }

    /* ---- refusals leave the store byte-for-byte unchanged ---- */
    {
        char bad[4300], m2[4300];
        int64_t V = NU * NV, F = 2 * V;
        double *xyz = malloc((size_t)(3 * V) * sizeof *xyz);
        int64_t *faces = malloc((size_t)(3 * F) * sizeof *faces);
        const char *files[2];
        char p8[4300];
        snprintf(p8, sizeof p8, "%s/meshes/t8.obj", dir);
        files[0] = p8;
        files[1] = bad;

        /* connectivity differs at face 5 (a valid mesh, other diagonal) */
        es_test_torus(NU, NV, 9, xyz, faces);
        {
            int64_t a = faces[3 * 4], b = faces[3 * 4 + 1], c = faces[3 * 4 + 2],
                    d = faces[3 * 5 + 2];
            int64_t t[6] = {a, b, d, b, c, d};
            memcpy(faces + 3 * 4, t, sizeof t);
        }
        snprintf(bad, sizeof bad, "%s/meshes/flip.obj", dir);
        es_test_write_obj(bad, V, xyz, F, faces);
        CHECK_REFUSED(es_ingest_files(ctx, store, 2, files, NULL, &rep), ES_EMISMATCH,
                      "flip.obj': connectivity differs from the store");
        ES_CHECK(strstr(es_ctx_errmsg(ctx), "at face 4") != NULL);

        /* vertex count differs */
        snprintf(bad, sizeof bad, "%s/meshes/big.obj", dir);
        es_test_write_torus(bad, NU, NV + 1, 0);
        CHECK_REFUSED(es_ingest_files(ctx, store, 2, files, NULL, &rep), ES_EMISMATCH,
                      "big.obj' has 108 vertices");

        /* malformed OBJ */
        snprintf(bad, sizeof bad, "%s/meshes/broken.obj", dir);
        es_test_write_file(bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1.5.5\nf 1 2 3\n");
        CHECK_REFUSED(es_ingest_files(ctx, store, 2, files, NULL, &rep), ES_EFORMAT,
                      "broken.obj");

        /* a file that does not exist */
        snprintf(bad, sizeof bad, "%s/meshes/absent.obj", dir);
        CHECK_REFUSED(es_ingest_files(ctx, store, 2, files, NULL, &rep), ES_ENOTFOUND,
                      "absent.obj");

        /* an id that is stored with other content */
        snprintf(path, sizeof path, "%s/other", dir);
        mkdir(path, 0777);
        snprintf(bad, sizeof bad, "%s/other/t1.obj", dir);
        es_test_write_torus(bad, NU, NV, 9);
        CHECK_REFUSED(es_ingest_files(ctx, store, 2, files, NULL, &rep), ES_EEXIST,
                      "id 't1' is in the store already with different content");

        /* malformed CSV: a stray quote on line 3 */
        snprintf(m2, sizeof m2, "%s/bad.csv", dir);
        es_test_write_file(m2, "file,group\nmeshes/t8.obj,A\nmeshes/t9.obj,B\"x\n");
        CHECK_REFUSED(es_ingest_manifest(ctx, store, m2, NULL, &rep), ES_EFORMAT,
                      "bad.csv' line 3: malformed CSV");
        /* a row with a missing field */
        es_test_write_file(m2, "file,group\nmeshes/t8.obj,A\nmeshes/t9.obj\n");
        CHECK_REFUSED(es_ingest_manifest(ctx, store, m2, NULL, &rep), ES_EFORMAT,
                      "line 3: 1 fields, but the header has 2");
        /* no file column */
        es_test_write_file(m2, "path,group\nmeshes/t8.obj,A\n");
        CHECK_REFUSED(es_ingest_manifest(ctx, store, m2, NULL, &rep), ES_EFORMAT,
                      "no 'file' column");
        /* a manifest naming a file that is missing, after a good one */
        es_test_write_file(m2, "file,group\nmeshes/t8.obj,A\nmeshes/nope.obj,B\n");
        CHECK_REFUSED(es_ingest_manifest(ctx, store, m2, NULL, &rep), ES_ENOTFOUND,
                      "nope.obj");
        /* ids given twice in one manifest */
        es_test_write_file(m2, "file,id\nmeshes/t8.obj,x\nmeshes/t9.obj,x\n");
        CHECK_REFUSED(es_ingest_manifest(ctx, store, m2, NULL, &rep), ES_EFORMAT,
                      "id 'x' repeats line 2");
        /* every file of the reader's malformed corpus: its own error (the
         * one tests/data/malformed/EXPECTED lists), store unchanged */
        {
            char exp[4300], line[1024];
            FILE *f;
            int nfiles = 0;
            snprintf(exp, sizeof exp, "%s/tests/data/malformed/EXPECTED", ES_SOURCE_ROOT);
            f = fopen(exp, "r");
            ES_CHECK(f != NULL);
            while (f && fgets(line, sizeof line, f)) {
                char *tab = strchr(line, '\t'), *nl;
                if (line[0] == '#' || !tab) continue;
                *tab = '\0';
                if ((nl = strchr(tab + 1, '\n'))) *nl = '\0';
                snprintf(bad, sizeof bad, "%s/tests/data/malformed/%s", ES_SOURCE_ROOT, line);
                CHECK_REFUSED(es_ingest_files(ctx, store, 2, files, NULL, &rep),
                              es_status_any_error, tab + 1);
                ES_CHECK_MSG(strstr(es_ctx_errmsg(ctx), line) != NULL, "%s: %s", line,
                             es_ctx_errmsg(ctx));
                nfiles++;
            }
            if (f) fclose(f);
            ES_CHECK(nfiles >= 40);
        }
        free(xyz);
        free(faces);
    }

    /* ---- a new store from a mesh that is not a manifold: not created ---- */
    {
        char bad[4300], st2[4300];
        const char *files[1] = {bad};
        snprintf(bad, sizeof bad, "%s/meshes/nonmanifold.obj", dir);
        /* three triangles on one edge */
        es_test_write_file(bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\n"
                                "f 1 2 3\nf 2 1 4\nf 1 2 5\n");
        snprintf(st2, sizeof st2, "%s/new.h5", dir);
        ES_CHECK_FAILS(ctx, es_ingest_files(ctx, st2, 1, files, NULL, &rep), ES_ETOPOLOGY,
                       "nonmanifold.obj");
        ES_CHECK(access(st2, F_OK) != 0);
        ES_CHECK(es_test_count_entries(dir, ".tmp-") == 0);
    }

    /* ---- export: CSV rows read back to the stored values ---- */
    {
        char csv[4300];
        size_t n;
        char *text;
        double buf[3 * NU * NV];
        es_mat m = {buf, 3 * NU * NV, 1, 3 * NU * NV};
        snprintf(csv, sizeof csv, "%s/lengths.csv", dir);
        ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
        if (s) {
            int64_t rows[1] = {3};
            ES_CHECK_OK(ctx, es_export_lengths_csv(ctx, s, rows, 1, 0, csv));
            ES_CHECK_OK(ctx, es_store_read_lengths(ctx, s, 3, 1, m));
            text = es_test_slurp(csv, &n);
            ES_CHECK(text && !strncmp(text, "id,scale,0-1,", 13));
            if (text) {
                char *line = strchr(text, '\n') + 1, *p, *end;
                ES_CHECK(!strncmp(line, "t3,", 3));
                p = strchr(line + 3, ',') + 1;
                for (int64_t e = 0; e < 3 * NU * NV; e++) {
                    double v = strtod(p, &end);
                    if (v != buf[e]) {
                        ES_CHECK_MSG(0, "edge %lld: csv %.17g, store %.17g", (long long)e, v, buf[e]);
                        break;
                    }
                    p = end + 1;
                }
            }
            free(text);
        }
        es_store_close(s);
        s = NULL;
    }

    /* ---- coincident vertices: ingested, with a warning naming the file
     * and the zero-length edge (first input and a later one) ---- */
    {
        int64_t V = NU * NV, F = 2 * V;
        double *xyz = malloc(3 * (size_t)V * sizeof *xyz);
        int64_t *faces = malloc(3 * (size_t)F * sizeof *faces);
        char pz[4300], p0[4300], sz[4300];
        log_capture cap = {{0}, 0};
        es_test_torus(NU, NV, 0, xyz, faces);
        memcpy(xyz + 3, xyz, 3 * sizeof *xyz);   /* vertex 1 onto vertex 0 */
        snprintf(pz, sizeof pz, "%s/meshes/zero.obj", dir);
        snprintf(p0, sizeof p0, "%s/meshes/t0.obj", dir);
        ES_CHECK(es_test_write_obj(pz, V, xyz, F, faces) == 0);
        es_ctx_set_log(ctx, capture_log, &cap);
        for (int order = 0; order < 2; order++) {
            const char *files[2] = {order ? p0 : pz, order ? pz : p0};
            snprintf(sz, sizeof sz, "%s/zero%d.h5", dir, order);
            cap.n = 0;
            cap.text[0] = 0;
            ES_CHECK_OK(ctx, es_ingest_files(ctx, sz, 2, files, NULL, &rep));
            ES_CHECK(rep.rows_added == 2);
            ES_CHECK_MSG(strstr(cap.text, "zero.obj': 1 edge of length 0 (first: edge") &&
                         strstr(cap.text, "vertices 0-1"), "order %d: warnings '%s'", order,
                         cap.text);
            remove(sz);
        }
        /* a vertex in no face: one warning naming the first file, none
         * when later files are added to that store */
        {
            double *x1 = malloc(3 * (size_t)(V + 1) * sizeof *x1);
            char pa[4300], pb[4300];
            const char *one[1];
            for (int k = 0; k < 2; k++) {
                es_test_torus(NU, NV, k, x1, faces);
                x1[3 * V] = 9, x1[3 * V + 1] = 9, x1[3 * V + 2] = 9;
                snprintf(k ? pb : pa, sizeof pa, "%s/meshes/spare%d.obj", dir, k);
                ES_CHECK(es_test_write_obj(k ? pb : pa, V + 1, x1, F, faces) == 0);
            }
            snprintf(sz, sizeof sz, "%s/spare.h5", dir);
            cap.n = 0;
            cap.text[0] = 0;
            one[0] = pa;
            ES_CHECK_OK(ctx, es_ingest_files(ctx, sz, 1, one, NULL, &rep));
            char want[128];
            snprintf(want, sizeof want, "spare0.obj': 1 of %lld vertices are in no face",
                     (long long)(V + 1));
            const char *w = strstr(cap.text, want);
            ES_CHECK_MSG(w && !strstr(w + strlen(want), "in no face"), "first ingest: '%s'",
                         cap.text);
            cap.n = 0;
            cap.text[0] = 0;
            one[0] = pb;
            ES_CHECK_OK(ctx, es_ingest_files(ctx, sz, 1, one, NULL, &rep));
            ES_CHECK_MSG(rep.rows_total == 2 && !strstr(cap.text, "in no face"),
                         "second ingest: '%s'", cap.text);
            remove(sz);
            free(x1);
        }
        es_ctx_set_log(ctx, NULL, NULL);
        free(xyz), free(faces);
    }

    /* ---- blocks change nothing: rows go to the working copy a block at a
     * time (block_rows 1, 2, 4; 1 or 4 threads) and the store equals the one
     * a single block makes (the default for these small meshes). A failure
     * in a later block, after earlier blocks were written to the working
     * copy, leaves no new store, an old store byte for byte, and no working
     * copy. Warnings come in input order across blocks. ---- */
    {
        char one[4300], sb[4300], m4[4300], pz[4300], pc[4300], pz2[4300];
        es_ingest_opts o;
        es_ingest_opts_init(&o);
        snprintf(one, sizeof one, "%s/oneblock.h5", dir);
        snprintf(sb, sizeof sb, "%s/blocks.h5", dir);
        ES_CHECK_OK(ctx, es_ingest_manifest(ctx, one, manifest, &o, &rep));
        for (int t = 1; t <= 4; t += 3)
            for (int64_t bs = 1; bs <= 4; bs *= 2) {
                o.threads = t;
                o.block_rows = bs;
                ES_CHECK_OK(ctx, es_ingest_manifest(ctx, sb, manifest, &o, &rep));
                ES_CHECK(rep.rows_added == 6 && rep.rows_total == 6 && rep.created);
                check_same_stores(ctx, sb, one);
                remove(sb);
            }
        snprintf(m4, sizeof m4, "%s/lastbad.csv", dir);
        es_test_write_file(m4, "file\nmeshes/t0.obj\nmeshes/t1.obj\nmeshes/t2.obj\n"
                               "meshes/t3.obj\nmeshes/gone.obj\n");
        o.block_rows = 2;
        ES_CHECK_FAILS(ctx, es_ingest_manifest(ctx, sb, m4, &o, &rep), ES_ENOTFOUND,
                       "gone.obj");
        ES_CHECK(access(sb, F_OK) != 0 && es_test_count_entries(dir, ".tmp-") == 0);
        {
            size_t n0;
            char *before = es_test_slurp(store, &n0);
            es_test_write_file(m4, "file,id\nmeshes/t8.obj,b8\nmeshes/t9.obj,b9\n"
                                   "meshes/t1.obj,b1\nmeshes/gone.obj,b0\n");
            o.block_rows = 1;
            ES_CHECK_FAILS(ctx, es_ingest_manifest(ctx, store, m4, &o, &rep), ES_ENOTFOUND,
                           "gone.obj");
            ES_CHECK(before && es_test_same_bytes(store, before, n0));
            ES_CHECK(es_test_count_entries(dir, ".tmp-") == 0);
            free(before);
        }
        /* warnings: zero-length edges (read) and duplicates (kept rows) of
         * inputs 1..3 land in input order with one row per block; one block
         * gives the same warnings */
        snprintf(pz, sizeof pz, "%s/meshes/zero.obj", dir);
        snprintf(pz2, sizeof pz2, "%s/meshes/zero2.obj", dir);
        snprintf(pc, sizeof pc, "%s/meshes/t0.obj", dir);
        snprintf(m4, sizeof m4, "%s/meshes/t0copy.obj", dir);
        copy_file(pz, pz2);
        copy_file(pc, m4);
        {
            const char *files[4] = {pc, pz, m4, pz2};
            log_capture cap = {{0}, 0};
            const char *want[4] = {"zero.obj': 1 edge of length 0",
                                   "t0copy.obj' has the same content as",
                                   "zero2.obj': 1 edge of length 0",
                                   "zero2.obj' has the same content as"};
            es_ctx_set_log(ctx, capture_log, &cap);
            for (int64_t bs = 1; bs <= 4; bs += 3) {
                const char *at[4];
                o.block_rows = bs;
                o.threads = 4;
                cap.n = 0;
                cap.text[0] = 0;
                ES_CHECK_OK(ctx, es_ingest_files(ctx, sb, 4, files, &o, &rep));
                ES_CHECK(rep.rows_added == 4);
                for (int w = 0; w < 4; w++) {
                    at[w] = strstr(cap.text, want[w]);
                    ES_CHECK_MSG(at[w] && !strstr(at[w] + 1, want[w]), "block %lld: '%s' in '%s'",
                                 (long long)bs, want[w], cap.text);
                }
                for (int w = 1; bs == 1 && w < 4; w++)
                    ES_CHECK_MSG(at[w - 1] && at[w] && at[w - 1] < at[w], "order: '%s'",
                                 cap.text);
                remove(sb);
            }
            es_ctx_set_log(ctx, NULL, NULL);
        }
        remove(one);
    }

    shared_sets(ctx, dir);
    es_ctx_free(ctx);
    ES_TEST_END();
}
