/* lib/study/embed_cache.c — the per-store work of embedding kept in a file
 * beside the store, so that a command in a fresh process does not redo it:
 * the embedder's fill-reducing vertex order and the rows made ready for
 * priors (GPA-aligned positions and dihedrals: on face-study, 90 rows of
 * 9,409 vertices, 0.6 s of CPU to make, 40 MB to read back).
 *
 * The file (datasets-spec/cache-format.md) is STORE.es-cache: a header of
 * little-endian 64-bit words (magic, format version, key, V, E, N, the
 * body's check word) and the arrays. The key hashes what the cached values
 * depend on: the format and algorithm version, the topology fingerprint,
 * the sizes, and every row's id with its content hash, or, when a row has
 * none (rows appended through the API), its stored positions. A file whose
 * key, sizes or length disagree is stale and made again, as is one whose
 * body fails its check word or whose vertex order is not a permutation; one
 * that cannot be written (a read-only folder) only costs the time. Written
 * whole or not at all (es__replace_begin).
 */
#include "study/study_pkg.h"
#include "core/hash.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#define CACHE_MAGIC 0x3165686361437365ull   /* "esCache1" */
#define CACHE_VERSION 3                     /* bump when the cached values or the check change */
#define CACHE_HEAD 7                        /* header words */

/* The cache file's path: the store's with ".es-cache" appended. */
static void cache_path(const es_store *s, char *buf, size_t n)
{
    snprintf(buf, n, "%s.es-cache", es_store_path(s));
}

es_status es__study_cache_key(es_ctx *ctx, es_store *s, uint64_t *key)
{
    int64_t n = es_store_nrows(s), nv = es_store_nverts(s), ne = es_store_nedges(s);
    int64_t sizes[4] = {CACHE_VERSION, nv, ne, n};
    uint64_t h = es__fnv1a64(0xcbf29ce484222325ull, "es-cache", 8);
    double *xyz = NULL;
    h = es__fnv1a64_i64(h, sizes, 4);
    h = es__fnv1a64(h, es_store_fingerprint(s), strlen(es_store_fingerprint(s)));
    for (int64_t i = 0; i < n; i++) {
        const char *id = es_store_row_id(s, i), *ch = es_store_content_hash(s, i);
        h = es__fnv1a64(h, id, strlen(id) + 1);
        if (ch && *ch) {
            h = es__fnv1a64(h, ch, strlen(ch) + 1);
            continue;
        }
        if (!xyz && !(xyz = es__alloc_array(ctx, 3 * nv, sizeof *xyz))) return ES_ENOMEM;
        es_status rc = es_store_read_positions(ctx, s, i, xyz);
        if (rc != ES_OK) {
            es__free(ctx, xyz);
            return rc;
        }
        h = es__fnv1a64(h, xyz, (size_t)(3 * nv) * sizeof *xyz);
    }
    es__free(ctx, xyz);
    *key = h;
    return ES_OK;
}

/* The body's check word: FNV-1a's step over whole 64-bit words (h ^ w,
 * times the FNV prime) in four lanes, word i into lane i mod 4, the lanes
 * folded with the same step at the end. Both steps are bijections, so a
 * body that differs in any one word always gives another check; a changed
 * value that stays finite (a flipped sign) would otherwise be taken as a
 * row's. Four lanes because one is a chain of multiplications each
 * waiting for the last: 25 ms of a fresh command's 0.3 s on face-study's
 * 40 MB (format 2), against a quarter of that. */
typedef struct check_lanes {
    uint64_t h[4];
    int64_t next;        /* the lane of the next word */
    uint64_t nonfinite;  /* non-zero once a double word was an infinity or a NaN */
} check_lanes;

/* A double's exponent bits all set: an infinity or a NaN. */
#define NONFINITE(w) (((w) & 0x7ff0000000000000ull) == 0x7ff0000000000000ull)

/* The words into the lanes; doubles: also whether one is not finite (in the
 * same pass: the rows are read from memory once, not three times) */
static void check_words(check_lanes *c, const void *p, int64_t nwords, int doubles)
{
    const uint64_t *w = p;
    uint64_t bad = 0;
    int64_t i = 0;
    for (; i < nwords && c->next != 0; i++, c->next = (c->next + 1) & 3) {
        c->h[c->next] = (c->h[c->next] ^ w[i]) * ES__FNV_PRIME;
        bad |= NONFINITE(w[i]);
    }
    uint64_t h0 = c->h[0], h1 = c->h[1], h2 = c->h[2], h3 = c->h[3];
    for (; i + 4 <= nwords; i += 4) {
        h0 = (h0 ^ w[i]) * ES__FNV_PRIME;
        h1 = (h1 ^ w[i + 1]) * ES__FNV_PRIME;
        h2 = (h2 ^ w[i + 2]) * ES__FNV_PRIME;
        h3 = (h3 ^ w[i + 3]) * ES__FNV_PRIME;
        bad |= NONFINITE(w[i]) | NONFINITE(w[i + 1]) | NONFINITE(w[i + 2]) | NONFINITE(w[i + 3]);
    }
    c->h[0] = h0, c->h[1] = h1, c->h[2] = h2, c->h[3] = h3;
    for (; i < nwords; i++, c->next = (c->next + 1) & 3) {
        c->h[c->next] = (c->h[c->next] ^ w[i]) * ES__FNV_PRIME;
        bad |= NONFINITE(w[i]);
    }
    if (doubles) c->nonfinite |= bad;
}

/* The check word of the body; *nonfinite: whether a position or dihedral
 * is not finite. */
static uint64_t body_check(int64_t nv, int64_t ne, int64_t n, const int64_t *order,
                           const double *aligned, const double *alpha, int *nonfinite)
{
    check_lanes c = {{ES__FNV_OFFSET, ES__FNV_OFFSET, ES__FNV_OFFSET, ES__FNV_OFFSET}, 0, 0};
    check_words(&c, order, nv, 0);
    check_words(&c, aligned, 3 * nv * n, 1);
    check_words(&c, alpha, ne * n, 1);
    uint64_t h = ES__FNV_OFFSET;
    for (int k = 0; k < 4; k++) h = (h ^ c.h[k]) * ES__FNV_PRIME;
    if (nonfinite) *nonfinite = c.nonfinite != 0;
    return h;
}

/* Whether order is a permutation of 0 .. nv-1 (a corrupt cache's would be
 * refused by es_embedder_new_ordered and fail the command; the cache is
 * made again instead). *rc: ES_ENOMEM when it cannot tell. */
static int is_permutation(es_ctx *ctx, const int64_t *order, int64_t nv, es_status *rc)
{
    unsigned char *seen = es__calloc(ctx, (size_t)nv + 1, 1);
    int ok = 1;
    if (!seen) {
        *rc = ES_ENOMEM;
        return 0;
    }
    for (int64_t j = 0; ok && j < nv; j++) {
        ok = order[j] >= 0 && order[j] < nv && !seen[order[j]];
        if (ok) seen[order[j]] = 1;
    }
    es__free(ctx, seen);
    return ok;
}

/* The cache file mapped whole, read-only (the pages are the page cache's:
 * a writable private mapping would have MAP_POPULATE copy every page), or
 * NULL when it is absent or cannot be mapped. Mapping instead of reading
 * spares a fresh command zeroing and copying the rows (40 MB on face-study:
 * a third of `embed --fast`'s CPU went to the kernel's page work). The
 * writer replaces the file by a rename, so a mapped cache keeps its old
 * contents when another process makes a new one. */
static void *map_file(const char *path, size_t *len)
{
    struct stat st;
    void *p;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    *len = 0;
    if (fd < 0) return NULL;
    if (fstat(fd, &st) != 0 || st.st_size < (off_t)(CACHE_HEAD * sizeof(uint64_t))) {
        close(fd);
        return NULL;
    }
    p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    close(fd);
    if (p == MAP_FAILED) return NULL;
    *len = (size_t)st.st_size;
    return p;
}

es_status es__study_cache_load(es_ctx *ctx, es_store *s, uint64_t key, int64_t **order,
                               es_study_rows **rows)
{
    char path[4200];
    int64_t nv = es_store_nverts(s), ne = es_store_nedges(s), n = es_store_nrows(s);
    size_t len, want;
    es_status rc = ES_OK;
    int64_t *ord = NULL;
    *order = NULL;
    *rows = NULL;
    cache_path(s, path, sizeof path);
    uint64_t *head = map_file(path, &len);
    if (!head) {
        if (access(path, F_OK) == 0)
            es__info(ctx, "embed: the cache %s cannot be read; made again", path);
        return ES_OK;   /* no cache: made afresh */
    }
    if (head[0] != CACHE_MAGIC || head[1] != CACHE_VERSION || head[2] != key ||
        (int64_t)head[3] != nv || (int64_t)head[4] != ne || (int64_t)head[5] != n) {
        munmap(head, len);
        es__info(ctx, "embed: the cache %s is stale; made again", path);
        return ES_OK;
    }
    want = sizeof(uint64_t) * (size_t)(CACHE_HEAD + nv + 3 * nv * n + ne * n);
    if (len != want) {
        munmap(head, len);
        es__info(ctx, "embed: the cache %s is %s; made again", path,
                 len < want ? "cut short" : "longer than its sizes say");
        return ES_OK;
    }
    const int64_t *map_ord = (const int64_t *)(head + CACHE_HEAD);
    double *aligned = (double *)(head + CACHE_HEAD + nv), *alpha = aligned + 3 * nv * n;
    const char *bad = NULL;
    int nonfinite = 0;
    if (body_check(nv, ne, n, map_ord, aligned, alpha, &nonfinite) != head[6])
        bad = "does not match its check word (changed since it was written)";
    else if (!is_permutation(ctx, map_ord, nv, &rc))
        bad = rc == ES_OK ? "holds a vertex order that is not a permutation" : NULL;
    else if (nonfinite)
        bad = "holds values that are not finite";
    if (!bad && rc == ES_OK && !(ord = es__alloc_array(ctx, nv, sizeof *ord))) rc = ES_ENOMEM;
    if (bad || rc != ES_OK) {
        munmap(head, len);
        if (bad) es__info(ctx, "embed: the cache %s %s; made again", path, bad);
        return rc;
    }
    memcpy(ord, map_ord, (size_t)nv * sizeof *ord);
    if ((rc = es__study_rows_mapped(ctx, n, nv, ne, head, len, aligned, alpha, rows)) != ES_OK) {
        es__free(ctx, ord);
        return rc;   /* (the rows unmapped it) */
    }
    *order = ord;
    return ES_OK;
}

void es__study_cache_save(es_ctx *ctx, es_store *s, uint64_t key, const int64_t *order,
                          const es_study_rows *rows)
{
    char path[4200];
    int64_t nv = es_store_nverts(s), ne = es_store_nedges(s), n = es_store_nrows(s);
    const double *aligned, *alpha;
    es__file_replace w;
    es_ctx *quiet;
    cache_path(s, path, sizeof path);
    es__study_rows_arrays(rows, &aligned, &alpha);
    uint64_t head[CACHE_HEAD] = {CACHE_MAGIC, CACHE_VERSION, key, (uint64_t)nv, (uint64_t)ne,
                                 (uint64_t)n, body_check(nv, ne, n, order, aligned, alpha, NULL)};
    /* a cache that cannot be written is no failure of the command: its
     * message goes to a context of its own and into the log */
    if (es_ctx_new(&quiet) != ES_OK) return;
    es_status rc = es__replace_begin(quiet, path, &w);
    if (rc == ES_OK) {
        int ok = fwrite(head, sizeof head, 1, w.f) == 1 &&
                 fwrite(order, sizeof *order, (size_t)nv, w.f) == (size_t)nv &&
                 fwrite(aligned, sizeof *aligned, (size_t)(3 * nv * n), w.f) == (size_t)(3 * nv * n) &&
                 fwrite(alpha, sizeof *alpha, (size_t)(ne * n), w.f) == (size_t)(ne * n);
        rc = es__replace_end(quiet, &w, ok ? ES_OK : es__fail(quiet, ES_EIO, "cannot write %s: %s",
                                                             path, strerror(errno)));
    }
    if (rc != ES_OK)
        es__info(ctx, "embed: no cache kept (%s)", es_ctx_errmsg(quiet));
    es_ctx_free(quiet);
}
