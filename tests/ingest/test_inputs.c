/* tests/ingest/test_inputs.c — what a user or a file can feed ingest that
 * is not what it should be:
 *   - a NUL byte in a TPS file, an edge list or a triangle list is refused
 *     naming the file and line (the rest of the file used to be dropped);
 *     in a manifest field too;
 *   - a SCALE that makes coordinates overflow is refused naming the specimen;
 *   - a FIFO listed in a manifest is refused at once (it used to hang);
 *   - triangles of zero area are warned about at ingest, naming the first;
 *   - 20,000 inputs of the same content (each with a flat triangle) are
 *     warned about once each, the warnings of the reading threads come back
 *     in input order, in time linear in the inputs (the duplicate checks
 *     and the replay of warnings were quadratic). */
#include "core/core_private.h"
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_run.h"

#include <sys/stat.h>
#include <unistd.h>

static const char *dir;

static void write_bytes(const char *path, const char *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    ES_CHECK(f && fwrite(b, 1, n, f) == n);
    if (f) fclose(f);
}

static const char *in_dir(const char *name, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", dir, name);
    return buf;
}

static void test_nul_bytes(es_ctx *ctx)
{
    char p[4200];
    es_landmarks *lm = NULL;
    int64_t *idx = NULL, n = 0;
    es_manifest *m = NULL;
    static const char tps[] = "LM=2\n1 2\n3 4\nID=a\nLM=2\n5 6\n7 \0 8\nID=b\n";
    write_bytes(in_dir("nul.tps", p, sizeof p), tps, sizeof tps - 1);
    ES_CHECK_FAILS(ctx, es_landmarks_read_tps(ctx, p, 1, &lm), ES_EFORMAT,
                   "nul.tps' line 7: NUL byte");
    ES_CHECK(lm == NULL);
    static const char edges[] = "1 2\n2 3\n3\0 1\n";
    write_bytes(in_dir("edges.txt", p, sizeof p), edges, sizeof edges - 1);
    ES_CHECK_FAILS(ctx, es_landmarks_read_index_list(ctx, p, 2, &idx, &n), ES_EFORMAT,
                   "edges.txt' line 3: NUL byte");
    ES_CHECK(idx == NULL && n == 0);
    static const char tri[] = "1 2 3\n\0";
    write_bytes(in_dir("tri.txt", p, sizeof p), tri, sizeof tri - 1);
    ES_CHECK_FAILS(ctx, es_landmarks_read_index_list(ctx, p, 3, &idx, &n), ES_EFORMAT,
                   "tri.txt' line 2: NUL byte");
    static const char man[] = "file,label\na.obj,x\nb.obj,y\0z\n";
    write_bytes(in_dir("m.csv", p, sizeof p), man, sizeof man - 1);
    ES_CHECK_FAILS(ctx, es_manifest_read(ctx, p, &m), ES_EFORMAT, "line 3, field 2: NUL byte");
    ES_CHECK(m == NULL);
}

static void test_scale_overflow(es_ctx *ctx)
{
    char p[4200];
    es_landmarks *lm = NULL;
    es_test_write_file(in_dir("big.tps", p, sizeof p),
                       "LM=2\n1 2\n3 4\nID=fine\nSCALE=2\nLM=2\n1 2\n3 4\nID=huge\nSCALE=1e308\n");
    ES_CHECK_FAILS(ctx, es_landmarks_read_tps(ctx, p, 1, &lm), ES_ERANGE,
                   "big.tps: specimen 2 ('huge'): SCALE=1e+308 makes its coordinates overflow");
    ES_CHECK(lm == NULL);
    /* without applying SCALE the coordinates are as written */
    ES_CHECK_OK(ctx, es_landmarks_read_tps(ctx, p, 0, &lm));
    ES_CHECK(lm && lm->n == 2 && lm->xyz[lm->k * lm->d] == 1);
    es_landmarks_free(lm);
}

static void test_fifo_in_manifest(es_ctx *ctx)
{
    char p[4200], m[4200], store[4200];
    es_ingest_report rep;
    in_dir("pipe.obj", p, sizeof p);
    if (mkfifo(p, 0600) != 0) {
        fprintf(stderr, "SKIP (FIFO part): mkfifo failed\n");
        return;
    }
    es_test_write_file(in_dir("fifo.csv", m, sizeof m), "file\npipe.obj\n");
    in_dir("fifo.h5", store, sizeof store);
    double t = es_test_now();
    ES_CHECK_FAILS(ctx, es_ingest_manifest(ctx, store, m, NULL, &rep), ES_EIO,
                   "pipe.obj' is not a regular file");
    ES_CHECK(es_test_now() - t < 5 && access(store, F_OK) != 0);
    remove(p);
}

/* A warning sink that keeps every message. */
typedef struct sink { char **msg; int64_t n, cap; } sink;

static void keep(void *ud, es_log_level level, const char *msg)
{
    sink *s = ud;
    (void)level;
    if (s->n == s->cap) {
        int64_t cap = s->cap ? 2 * s->cap : 64;
        char **q = realloc(s->msg, (size_t)cap * sizeof *q);
        if (!q) return;
        s->msg = q;
        s->cap = cap;
    }
    s->msg[s->n] = malloc(strlen(msg) + 1);
    if (s->msg[s->n]) strcpy(s->msg[s->n++], msg);
}

static void sink_clear(sink *s)
{
    for (int64_t i = 0; i < s->n; i++) free(s->msg[i]);
    free(s->msg);
    memset(s, 0, sizeof *s);
}

static void test_flat_triangles(es_ctx *ctx)
{
    char a[4200], b[4200], store[4200];
    sink w = {0};
    es_ingest_report rep;
    /* a tetrahedron, then one with a corner moved onto the line of two
     * others: face 2, (0 3 2), becomes flat */
    es_test_write_file(in_dir("t0.obj", a, sizeof a),
                       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    es_test_write_file(in_dir("t1.obj", b, sizeof b),
                       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 2 0\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    in_dir("flat.h5", store, sizeof store);
    const char *files[2] = {a, b};
    es_ctx_set_log(ctx, keep, &w);
    ES_CHECK_OK(ctx, es_ingest_files(ctx, store, 2, files, NULL, &rep));
    es_ctx_set_log(ctx, NULL, NULL);
    int found = 0;
    for (int64_t i = 0; i < w.n; i++) {
        ES_CHECK_MSG(!strstr(w.msg[i], "t0.obj") || !strstr(w.msg[i], "zero area"), "%s",
                     w.msg[i]);
        found += strstr(w.msg[i], "t1.obj': 1 triangle of zero area (first: face 2, vertices "
                        "0 3 2)") != NULL;
    }
    ES_CHECK_MSG(found == 1, "%lld warnings, none about t1's flat triangles", (long long)w.n);
    sink_clear(&w);
}

/* The "/fNNNNNN.obj" of a copy's name in a message, or NULL. Searched for
 * by its whole shape, not the first "/f": the checkout's own path may hold
 * one (/home/fred/...). */
static const char *copy_file_name(const char *msg)
{
    for (const char *q = strstr(msg, "/f"); q; q = strstr(q + 1, "/f")) {
        int digits = 0;
        while (digits < 6 && q[2 + digits] >= '0' && q[2 + digits] <= '9') digits++;
        if (digits == 6 && strncmp(q + 8, ".obj", 4) == 0) return q;
    }
    return NULL;
}

/* n copies of one tiny mesh with a flat triangle, each in its own file,
 * under a manifest: each copy warns about its flat triangle (on whichever
 * thread read it; replayed in input order) and each after the first about
 * its content. Returns the seconds the ingest took. */
static double ingest_copies(es_ctx *ctx, int n)
{
    char m[4200], store[4200], p[4300], home[4100];
    sink w = {0};
    es_ingest_report rep;
    FILE *f;
    /* Under a folder whose name starts "/f" and has digits, as a checkout in
     * /home/fred/ or /f000001/ would: the warnings' file numbers still read. */
    snprintf(home, sizeof home, "%s/f000001x/fred", dir);
    snprintf(p, sizeof p, "%s/f000001x", dir);
    mkdir(p, 0777);
    mkdir(home, 0777);
    snprintf(m, sizeof m, "%s/copies-%d.csv", home, n);
    snprintf(store, sizeof store, "%s/copies-%d.h5", home, n);
    if (!(f = fopen(m, "w"))) return 0;
    fputs("file\n", f);
    for (int i = 0; i < n; i++) {
        snprintf(p, sizeof p, "%s/f%06d.obj", home, i);
        if (access(p, F_OK) != 0)
            es_test_write_file(p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 2 0\nf 1 3 2\nf 1 2 4\n"
                                  "f 1 4 3\nf 2 3 4\n");
        fprintf(f, "f%06d.obj\n", i);
    }
    fclose(f);
    es_ctx_set_log(ctx, keep, &w);
    double t = es_test_now();
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, m, NULL, &rep));
    t = es_test_now() - t;
    es_ctx_set_log(ctx, NULL, NULL);
    ES_CHECK(rep.rows_added == n);
    int64_t same = 0, flat = 0, last = -1, ordered = 1;
    for (int64_t i = 0; i < w.n; i++) {
        const char *q = copy_file_name(w.msg[i]);
        if (strstr(w.msg[i], "has the same content as")) same++;
        if (strstr(w.msg[i], "triangle of zero area") && q) {
            long k = strtol(q + 2, NULL, 10);
            ordered &= k > last;
            last = k;
            flat++;
        }
    }
    ES_CHECK_MSG(same == n - 1 && flat == n && ordered, "%d copies: %lld same-content and %lld "
                 "flat-triangle warnings, %s", n, (long long)same, (long long)flat,
                 ordered ? "in order" : "out of order");
    remove(store);
    remove(m);
    sink_clear(&w);
    return t;
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    dir = es_test_tmpdir("inputs");
    test_nul_bytes(ctx);
    test_scale_overflow(ctx);
    test_fifo_in_manifest(ctx);
    test_flat_triangles(ctx);
    /* linear, not quadratic: four times the inputs take about four times as
     * long (quadratic: sixteen; 20,000 took 6 s, now under 2 s) */
    double t1 = ingest_copies(ctx, 5000), t4 = ingest_copies(ctx, 20000);
    fprintf(stderr, "same-content ingest: 5000 inputs %.2f s, 20000 inputs %.2f s\n", t1, t4);
    ES_CHECK_MSG(t4 < 9 * t1 + 1, "20000 inputs took %.2f s, 5000 took %.2f s", t4, t1);
    es_ctx_free(ctx);
    ES_TEST_END();
}
