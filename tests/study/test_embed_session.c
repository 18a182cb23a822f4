/* tests/study/test_embed_session.c — the embedding session and its cache
 * (lib/study/embed_session.c, embed_cache.c) on the synthetic faces:
 *  - a session without the cache, one that writes it and one that reads it
 *    embed every point bit for bit alike, and es_study_embed gives the same
 *    mesh as the session (one code path);
 *  - the cache file appears beside the store, and is made again when the
 *    store's rows change (a row appended: the new session's rows are the
 *    store's, checked against a session without the cache), when it is cut
 *    short, when its magic is wrong, when it holds a NaN behind a valid
 *    header, when one position's sign is flipped (the check word; finite, so
 *    only it can tell) and when its vertex order repeats a vertex under a
 *    check word the test recomputes (datasets-spec/cache-format.md's rule,
 *    written out here): each time the results equal the cache-free ones;
 *  - a cache that cannot be written (a folder where the file would go) only
 *    costs the time: the embedding works and says why in the log;
 *  - warm starts along a walk of 9 points of PC 1: each frame within 0.1 %
 *    of the bbox diagonal of the same point embedded cold (0.08 % measured),
 *    a frame after one that folded (bending > 1.1) from its own prior, and
 *    in fewer local-global iterations in total.
 */
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_stores.h"

#include <edgespace/edgespace.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int saw_cache_note;
static char cache_notes[4096];   /* the notes since saw_cache_note was cleared */
static void log_fn(void *ud, es_log_level lv, const char *msg)
{
    (void)ud, (void)lv;
    if (!strstr(msg, "cache")) return;
    if (!saw_cache_note++) cache_notes[0] = '\0';
    strncat(cache_notes, msg, sizeof cache_notes - strlen(cache_notes) - 1);
}

static const char *const points[3] = {"mean", "mean + 2*pc:1",
                                      "lerp(row:face_s01_neutral, row:face_s02_happy, 0.3)"};

/* The three points through a fresh session; out: 3 x 3V. */
static void embed_all(es_ctx *ctx, es_store *s, int cache, double *out, int64_t nv)
{
    es_study_embedder *se = NULL;
    es_study_embed_result r;
    ES_CHECK_OK(ctx, es_study_embedder_open(ctx, s, cache, &se));
    for (int k = 0; se && k < 3; k++)
        ES_CHECK_OK(ctx, es_study_embedder_point(ctx, se, points[k], NULL, 0, NULL, 0,
                                                 out + 3 * nv * k, &r));
    es_study_embedder_free(se);
}

static int same(const double *a, const double *b, int64_t n)
{
    return memcmp(a, b, (size_t)n * sizeof *a) == 0;
}

static void corrupt(const char *path, long at, const void *bytes, size_t n)
{
    FILE *f = fopen(path, "r+b");
    ES_CHECK(f != NULL);
    if (!f) return;
    fseek(f, at, SEEK_SET);
    fwrite(bytes, 1, n, f);
    fclose(f);
}

/* The cache's check word, computed here from the format's description
 * (datasets-spec/cache-format.md): FNV-1a's step over the body's 64-bit
 * words in four lanes (word i into lane i mod 4), the lanes folded by the
 * same step. */
static uint64_t check_word(const unsigned char *body, size_t bytes)
{
    const uint64_t basis = 0xcbf29ce484222325ull, prime = 0x100000001b3ull;
    uint64_t lane[4] = {basis, basis, basis, basis}, w, h = basis;
    for (size_t i = 0; i + 8 <= bytes; i += 8) {
        memcpy(&w, body + i, 8);
        lane[(i / 8) % 4] = (lane[(i / 8) % 4] ^ w) * prime;
    }
    for (int k = 0; k < 4; k++) h = (h ^ lane[k]) * prime;
    return h;
}

/* n bytes written at `at` (or, bytes NULL, the vertex order's second entry
 * made the first's), the check word rewritten to match: so that only the
 * checks after it (a permutation, finite values) can refuse the file. */
static void change_and_recheck(const char *path, long size, long at, const void *bytes, size_t n)
{
    unsigned char *b = malloc((size_t)size);
    FILE *f = fopen(path, "r+b");
    ES_CHECK(b && f && fread(b, 1, (size_t)size, f) == (size_t)size);
    if (b && f) {
        uint64_t check;
        if (bytes) memcpy(b + at, bytes, n);
        else memcpy(b + 56 + 8, b + 56, 8);
        check = check_word(b + 56, (size_t)size - 56);
        memcpy(b + 48, &check, 8);
        rewind(f);
        ES_CHECK(fwrite(b, 1, (size_t)size, f) == (size_t)size);
    }
    if (f) fclose(f);
    free(b);
}

int main(void)
{
    es_ctx *ctx = NULL;
    es_store *s = NULL;
    char store[4200], cache[4300];
    ES_TEST_BEGIN();
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    const char *dir = es_test_tmpdir("embed-session");
    snprintf(store, sizeof store, "%s/faces.h5", dir);
    snprintf(cache, sizeof cache, "%s.es-cache", store);
    es_test_face_store(ctx, dir, store, 8, 7);
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_WRITE, &s));
    if (!s) ES_TEST_END();
    es_pca_opts po;
    es_pca_opts_init(&po);
    po.ncomp = 4;
    es_study_pca_opts spo;
    es_study_pca_opts_init(&spo);
    spo.name = "p";
    spo.pca = po;
    spo.command = "test";
    ES_CHECK_OK(ctx, es_study_pca(ctx, s, &spo, NULL, NULL, NULL));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    int64_t nv = es_store_nverts(s), n3 = 3 * nv;
    double *ref = malloc(3 * (size_t)n3 * sizeof *ref), *got = malloc(3 * (size_t)n3 * sizeof *got);
    struct stat st;

    /* without, writing, reading: the same meshes */
    remove(cache);
    embed_all(ctx, s, 0, ref, nv);
    ES_CHECK(stat(cache, &st) != 0);   /* no cache without asking */
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(stat(cache, &st) == 0 && st.st_size > 48);
    ES_CHECK(same(ref, got, 3 * n3));
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(same(ref, got, 3 * n3));
    {   /* es_study_embed: the session's mesh */
        es_study_embed_opts eo;
        es_study_embed_result r;
        es_study_embed_opts_init(&eo);
        eo.point = points[1];
        ES_CHECK_OK(ctx, es_study_embed(ctx, s, &eo, got, &r));
        ES_CHECK(same(ref + n3, got, n3));
    }

    /* damaged caches are made again */
    long size = (long)st.st_size;
    double nan = NAN;
    uint64_t bad = 0x1234;
    corrupt(cache, 0, &bad, sizeof bad);                  /* magic */
    saw_cache_note = 0;
    es_ctx_set_log(ctx, log_fn, NULL);
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(same(ref, got, 3 * n3) && saw_cache_note > 0);
    corrupt(cache, size - 16, &nan, sizeof nan);          /* a NaN among the dihedrals */
    saw_cache_note = 0;
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(same(ref, got, 3 * n3) && saw_cache_note > 0);
    {   /* one position's sign flipped: finite, caught by the check word */
        double x = 0;
        long at = 56 + 8 * (long)nv;   /* the first row's positions */
        FILE *f = fopen(cache, "rb");
        ES_CHECK(f && fseek(f, at, SEEK_SET) == 0);
        while (f && x == 0 && fread(&x, sizeof x, 1, f) == 1) at += 8;
        if (f) fclose(f);
        x = -x;
        ES_CHECK(x != 0 && isfinite(x));
        corrupt(cache, at - 8, &x, sizeof x);
        saw_cache_note = 0;
        embed_all(ctx, s, 1, got, nv);
        ES_CHECK(same(ref, got, 3 * n3) && strstr(cache_notes, "check word"));
    }
    change_and_recheck(cache, size, 0, NULL, 0);          /* not a permutation */
    saw_cache_note = 0;
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK_MSG(same(ref, got, 3 * n3) && strstr(cache_notes, "not a permutation"),
                 "notes: %s", cache_notes);
    for (int k = 0; k < 2; k++) {   /* an infinity among the positions, a NaN among the
                                       dihedrals, each under a matching check word */
        const double v = k ? nan : INFINITY;
        change_and_recheck(cache, size, k ? size - 8 : 56 + 8 * (long)nv + 8, &v, sizeof v);
        saw_cache_note = 0;
        embed_all(ctx, s, 1, got, nv);
        ES_CHECK_MSG(same(ref, got, 3 * n3) && strstr(cache_notes, "not finite"), "notes: %s",
                     cache_notes);
    }
    ES_CHECK(truncate(cache, size / 2) == 0);             /* cut short */
    saw_cache_note = 0;
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(same(ref, got, 3 * n3) && saw_cache_note > 0);
    ES_CHECK(stat(cache, &st) == 0 && st.st_size == size);   /* written whole again */
    {   /* longer than its sizes say (the cache is read mapped: its length is checked) */
        FILE *f = fopen(cache, "ab");
        ES_CHECK(f && fwrite("trailing", 1, 8, f) == 8 && fclose(f) == 0);
        saw_cache_note = 0;
        embed_all(ctx, s, 1, got, nv);
        ES_CHECK_MSG(same(ref, got, 3 * n3) && strstr(cache_notes, "longer than"), "notes: %s",
                     cache_notes);
        ES_CHECK(stat(cache, &st) == 0 && st.st_size == size);
    }
    ES_CHECK(truncate(cache, 0) == 0);                    /* empty */
    saw_cache_note = 0;
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(same(ref, got, 3 * n3) && saw_cache_note > 0);
    ES_CHECK(stat(cache, &st) == 0 && st.st_size == size);

    /* a cache that cannot be written: a folder in its place */
    remove(cache);
    ES_CHECK(mkdir(cache, 0755) == 0);
    saw_cache_note = 0;
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(same(ref, got, 3 * n3) && saw_cache_note > 0);
    rmdir(cache);
    es_ctx_set_log(ctx, NULL, NULL);

    /* the rows change: a row appended (the first one's lengths again, under
     * another id): the cache is made again for the new rows */
    embed_all(ctx, s, 1, got, nv);   /* a current cache for the old rows */
    {
        int64_t ne = es_store_nedges(s);
        double *len = malloc((size_t)ne * sizeof *len), *xyz = malloc((size_t)n3 * sizeof *xyz), sc;
        const char *ids[1] = {"copy"}, *cols[2] = {"subject", "expression"}, *labels[2] = {"x", "neutral"};
        ES_CHECK_OK(ctx, es_store_read_lengths(ctx, s, 0, 1, (es_mat){len, ne, 1, ne}));
        ES_CHECK_OK(ctx, es_store_read_positions(ctx, s, 0, xyz));
        double *scales = malloc((size_t)es_store_nrows(s) * sizeof *scales);
        ES_CHECK_OK(ctx, es_store_read_scales(ctx, s, scales));
        sc = scales[0];
        es_store_rows r = {1, ids, NULL, NULL, len, &sc, xyz, 2, cols, labels};
        ES_CHECK_OK(ctx, es_store_append(ctx, s, &r));
        ES_CHECK_OK(ctx, es_store_commit(ctx, s));
        free(len), free(xyz), free(scales);
    }
    embed_all(ctx, s, 0, ref, nv);
    embed_all(ctx, s, 1, got, nv);
    ES_CHECK(same(ref, got, 3 * n3));

    /* warm starts along PC 1 */
    {
        es_study_embedder *se = NULL;
        es_study_embed_result r;
        int64_t warm_it = 0, cold_it = 0;
        double worst = 0, *walk = malloc(9 * (size_t)n3 * sizeof *walk), wbend[9];
        ES_CHECK_OK(ctx, es_study_embedder_open(ctx, s, 1, &se));
        for (int i = 0; se && i < 9; i++) {
            char pt[64];
            snprintf(pt, sizeof pt, "mean + %g*pc:1", -2.0 + 0.5 * i);
            ES_CHECK_OK(ctx, es_study_embedder_point(ctx, se, pt, "p", 0, NULL, 1, walk + n3 * i, &r));
            warm_it += r.report.lg_iters;
            wbend[i] = r.report.bend_ratio;
            /* a frame after one that folded (bending > 1.1) starts from its prior */
            ES_CHECK(i == 0 || (strstr(r.init, "last output") != NULL) == (wbend[i - 1] <= 1.1));
        }
        for (int i = 0; se && i < 9; i++) {
            char pt[64];
            snprintf(pt, sizeof pt, "mean + %g*pc:1", -2.0 + 0.5 * i);
            ES_CHECK_OK(ctx, es_study_embedder_point(ctx, se, pt, "p", 0, NULL, 0, ref, &r));
            cold_it += r.report.lg_iters;
            double ss = 0;
            for (int64_t j = 0; j < n3; j++) ss += pow(walk[n3 * i + j] - ref[j], 2);
            worst = fmax(worst, sqrt(ss / (double)nv) / es_bbox_diagonal(nv, ref));
            fprintf(stderr, "  frame %d: %.3g %% (cold %lld it, rms %.3g %%, bending %.3f, warm %.3f, "
                    "%lld faces break the triangle inequality)\n", i,
                    100 * sqrt(ss / (double)nv) / es_bbox_diagonal(nv, ref), (long long)r.report.lg_iters,
                    100 * r.report.rms_ratio, r.report.bend_ratio, wbend[i],
                    (long long)r.report.n_bad_faces);
        }
        fprintf(stderr, "warm walk: %lld local-global iterations against %lld cold; frames at "
                "most %.3g %% of the diagonal from the cold ones\n", (long long)warm_it,
                (long long)cold_it, 100 * worst);
        ES_CHECK(warm_it < cold_it && worst <= 1e-3);
        es_study_embedder_free(se);
        free(walk);
    }
    {   /* local-global alone (--fast, a slider): the session does not form the
         * circular means of the rows' dihedrals, which such a solve does not
         * read, and its mesh is the very one es_embed_prior_solve makes given
         * them (the oracle: the whole prior, es_study_prior) */
        es_study_embedder *se = NULL;
        es_study_embed_result r;
        es_embed_report rep;
        es_embed_opts fo;
        int64_t ne = es_store_nedges(s), N = es_store_nrows(s);
        double *l0 = malloc((size_t)(ne + N) * sizeof *l0), *w0 = l0 + ne, sc;
        double *pri = malloc((size_t)(n3 + 2 * ne) * sizeof *pri), *al = pri + n3, *sd = al + ne;
        es_embed_opts_fast(&fo);
        ES_CHECK_OK(ctx, es_study_embedder_open(ctx, s, 1, &se));
        for (int k = 0; k < 3; k++) {
            ES_CHECK_OK(ctx, es_study_point_weights(ctx, s, points[k], "p", l0, &sc, w0));
            ES_CHECK_OK(ctx, es_study_embedder_solve(ctx, se, l0, sc, w0, &fo, 0, 0, got, &r));
            ES_CHECK_OK(ctx, es_study_prior(ctx, es_study_embedder_rows(se), w0, pri, al, sd));
            es_embed_prior pr = {pri, al, sd, NULL, NULL, NULL};
            ES_CHECK_OK(ctx, es_embed_prior_solve(ctx, es_study_embedder_embedder(se), l0, sc,
                                                  &pr, &fo, ref, &rep));
            ES_CHECK(same(ref, got, n3) && r.report.lg_iters == rep.lg_iters);
        }
        es_study_embedder_free(se);
        free(l0), free(pri);
    }
    {   /* the session keeps a point's leaves (embed_leaves.c): its embedding of an
         * expression is the one of the lengths, scale and row weights that
         * es_study_point_weights reads afresh from the store (the oracle), on every
         * repeat (leaves from the cache), and after the PCA is replaced through the
         * handle (the store's generation drops the kept leaves) */
        es_study_embedder *se = NULL;
        es_study_embed_result r;
        int64_t ne = es_store_nedges(s), N = es_store_nrows(s);
        double *l0 = malloc((size_t)(ne + N) * sizeof *l0), *w0 = l0 + ne, sc;
        const char *pt = "mean + 1.5*pc:2 - 0.5*pc:1";
        ES_CHECK_OK(ctx, es_study_embedder_open(ctx, s, 1, &se));
        for (int pca = 0; pca < 2; pca++) {
            uint64_t gen = es_store_generation(s);
            ES_CHECK_OK(ctx, es_study_point_weights(ctx, s, pt, "p", l0, &sc, w0));
            ES_CHECK_OK(ctx, es_study_embedder_solve(ctx, se, l0, sc, w0, NULL, 0, 0, ref, &r));
            for (int pass = 0; pass < 3; pass++) {
                ES_CHECK_OK(ctx, es_study_embedder_point(ctx, se, pt, "p", 0, NULL, 0, got, &r));
                ES_CHECK(same(ref, got, n3));
            }
            ES_CHECK(es_store_generation(s) == gen);   /* reading writes nothing */
            if (pca == 0) {   /* the PCA replaced (of the neutral rows, 3 components) */
                memcpy(got + n3, ref, (size_t)n3 * sizeof *ref);
                ES_CHECK_OK(ctx, es_store_delete_result(ctx, s, "pca", "p"));
                spo.where = "expression=neutral";
                spo.pca.ncomp = 3;
                ES_CHECK_OK(ctx, es_study_pca(ctx, s, &spo, NULL, NULL, NULL));
                ES_CHECK(es_store_generation(s) != gen);
            } else {
                ES_CHECK(!same(got + n3, got, n3));   /* not the old PCA's point */
            }
        }
        es_study_embedder_free(se);
        free(l0);
        es_store_abort(s);   /* the replaced PCA is not kept */
        s = NULL;
    }
    es_store_close(s);
    free(ref), free(got);
    es_ctx_free(ctx);
    ES_TEST_END();
}
