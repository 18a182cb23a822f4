/* tests/store/test_store_headers.c — object-header messages are checked
 * before HDF5 decodes them (lib/h5/h5_headers.c).
 *
 * 1. The audit's store (issue 25): the base store with the version byte of
 *    /shapes/content_hash's layout message changed from 3 to 1 made libhdf5
 *    1.10 divide by zero in H5Dopen (SIGFPE in `edgespace info` and
 *    Python's Store()); it must be refused naming the dataset and the
 *    layout.
 * 2. Targeted changes to each kind of message of every object header of the
 *    base (layout versions and chunk dimensions, datatype classes and
 *    sizes, dataspace ranks, fill value sizes, the shared flag, message
 *    types HDF5 would follow elsewhere), each refused by name or opened.
 *    A local heap of a group the opener walks, whose size passes the
 *    file, is refused before it is allocated; no heap's crashes.
 * 3. Every byte of every object header set to three values (0xff, the byte
 *    with its low bit flipped, 0; the first two under ASan): each store
 *    opens and reads in full or is refused with one clean line. The root
 *    group's header is checked before HDF5 opens the file. Each object runs
 *    in a child
 *    process, so that a crash inside libhdf5 (not instrumented) fails the
 *    test with the byte that caused it instead of killing the suite.
 * The headers are found by HDF5 itself (H5Ovisit: address and size of
 * each), and their messages by an independent walk of the version 1 header
 * layout (HDF5 File Format Specification 3.0, IV.A.1.a). */
#include "crafted.h"

#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"

#include <hdf5.h>
#include <sys/wait.h>
#include <unistd.h>

/* Values per byte: 0xff, the low bit flipped and 0; two under AddressSanitizer,
 * whose every open costs five times as much (the suite's time in CI). */
#if defined(__SANITIZE_ADDRESS__)
#define NVALUES 2
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NVALUES 2
#endif
#endif
#ifndef NVALUES
#define NVALUES 3
#endif

typedef struct object { char name[200]; size_t addr, len; } object;
static object objs[64];
static int nobjs;

static herr_t visit(hid_t o, const char *name, const H5O_info_t *info, void *ud)
{
    (void)o;
    (void)ud;
    if (nobjs < 64) {
        snprintf(objs[nobjs].name, sizeof objs[nobjs].name, "/%s", name);
        objs[nobjs].addr = (size_t)info->addr;
        objs[nobjs].len = (size_t)info->hdr.space.total;
        nobjs++;
    }
    return 0;
}

/* The message of `type` in the version 1 header at addr (the first one):
 * the offset of its data in the file and its size, or 0. Messages: type
 * (2), size (2), flags (1), reserved (3), data; the first at addr + 16. */
static size_t find_msg(const unsigned char *b, size_t n, const object *o, unsigned type,
                       size_t *size, size_t *hdr_at)
{
    size_t p = o->addr + 16, end = o->addr + 16;
    if (o->addr + 16 > n || b[o->addr] != 1) return 0;
    end += (size_t)b[o->addr + 8] | (size_t)b[o->addr + 9] << 8 | (size_t)b[o->addr + 10] << 16;
    while (p + 8 <= end && end <= n) {
        unsigned t = b[p] | b[p + 1] << 8;
        size_t sz = b[p + 2] | b[p + 3] << 8;
        if (t == type) {
            *size = sz;
            if (hdr_at) *hdr_at = p;
            return p + 8;
        }
        p += 8 + sz;
    }
    return 0;
}

/* Open and read everything at path; 1 if it opened, 0 if refused cleanly;
 * a check fails for an unclean message. */
static int open_read(es_ctx *ctx, const char *path, const char *what)
{
    es_store *s = NULL;
    if (es_store_open(ctx, path, ES_STORE_READ, &s) != ES_OK) {
        ES_CHECK_MSG(!s && crafted_message_ok(es_ctx_errmsg(ctx)), "%s: %s", what,
                     es_ctx_errmsg(ctx));
        return 0;
    }
    ES_CHECK_MSG(crafted_read_all(ctx, s) == 0, "%s: a read failed uncleanly: %s", what,
                 es_ctx_errmsg(ctx));
    es_store_close(s);
    return 1;
}

static void put(const char *path, const unsigned char *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    ES_CHECK(f && fwrite(b, 1, n, f) == n);
    if (f) fclose(f);
}

/* The object's path inside /analysis (a result's), or NULL. */
static const char *result;

/* One change (up to two bytes), opened in a child; the child's failed
 * checks or a signal fail the test. want: 0 refuse (naming needle), 1 any. */
static void one(es_ctx *ctx, const char *path, const unsigned char *base, size_t n,
                size_t at, int v, size_t at2, int v2, int want, const char *needle,
                const char *what)
{
    unsigned char *b = malloc(n);
    pid_t pid;
    int st = 0;
    ES_CHECK(b != NULL);
    if (!b) return;
    memcpy(b, base, n);
    b[at] = (unsigned char)v;
    if (at2) b[at2] = (unsigned char)v2;
    put(path, b, n);
    free(b);
    fflush(NULL);
    if ((pid = fork()) == 0) {
        es_test_failures = 0;
        int opened = open_read(ctx, path, what);
        /* a result is read when asked for: the store opens, the result is
         * refused (its header is checked before HDF5 opens it) */
        if (want == 0 && opened && result) {
            es_store *s = NULL;
            char **keys = NULL;
            int64_t nk = 0;
            opened = es_store_open(ctx, path, ES_STORE_READ, &s) == ES_OK &&
                     es_store_list_attrs(ctx, s, result, &keys, &nk) == ES_OK;
            for (int64_t k = 0; k < nk; k++) es_free(ctx, keys[k]);
            es_free(ctx, keys);
            es_store_close(s);
        }
        if (want == 0)
            ES_CHECK_MSG(!opened && es_test_contains(es_ctx_errmsg(ctx), needle),
                         "%s: want a refusal naming '%s', got: %s", what, needle,
                         opened ? "(opened)" : es_ctx_errmsg(ctx));
        _exit(es_test_failures ? 1 : 0);
    }
    ES_CHECK(pid > 0 && waitpid(pid, &st, 0) == pid);
    ES_CHECK_MSG(WIFEXITED(st) && WEXITSTATUS(st) == 0, "%s: the child %s %d", what,
                 WIFSIGNALED(st) ? "died of signal" : "exited with",
                 WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st));
}

/* Every byte of object o's header set to NVALUES values, all
 * in one child (so a crash names the object and, on stderr, the byte). */
static void sweep(es_ctx *ctx, const char *path, const unsigned char *base, size_t n,
                  const object *o, int *opened, int *refused)
{
    int fd[2], st = 0, counts[2] = {0, 0};
    pid_t pid;
    ES_CHECK(pipe(fd) == 0);
    fflush(NULL);
    if ((pid = fork()) == 0) {
        unsigned char *b = malloc(n);
        int c[2] = {0, 0};
        close(fd[0]);
        es_test_failures = 0;
        for (size_t at = o->addr; b && at < o->addr + o->len && at < n; at++) {
            const int vals[3] = {0xff, base[at] ^ 1, 0};
            for (int k = 0; k < NVALUES; k++) {
                char what[200];
                if (vals[k] == base[at]) continue;
                memcpy(b, base, n);
                b[at] = (unsigned char)vals[k];
                put(path, b, n);
                snprintf(what, sizeof what, "%.150s: byte %zu (header + %zu) = %d", o->name, at,
                         at - o->addr, vals[k]);
                fprintf(stderr, "\r");   /* the last line names the byte if libhdf5 crashes */
                c[open_read(ctx, path, what)]++;
            }
        }
        free(b);
        if (write(fd[1], c, sizeof c) != (ssize_t)sizeof c) _exit(2);
        _exit(es_test_failures ? 1 : 0);
    }
    close(fd[1]);
    if (read(fd[0], counts, sizeof counts) != (ssize_t)sizeof counts) counts[0] = counts[1] = 0;
    close(fd[0]);
    ES_CHECK(pid > 0 && waitpid(pid, &st, 0) == pid);
    ES_CHECK_MSG(WIFEXITED(st) && WEXITSTATUS(st) == 0, "%s: the sweep's child %s %d",
                 o->name, WIFSIGNALED(st) ? "died of signal" : "exited with",
                 WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st));
    *refused += counts[0];
    *opened += counts[1];
}

int main(void)
{
    ES_TEST_BEGIN();
    es_ctx *ctx = NULL;
    const char *dir = es_test_tmpdir("store-headers");
    char base_path[700], path[700], what[400];
    size_t n = 0, at, sz, hdr_at;
    hid_t f;
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    snprintf(base_path, sizeof base_path, "%s/base.h5", dir);
    snprintf(path, sizeof path, "%s/changed.h5", dir);
    ES_CHECK(crafted_base(base_path) == 0);
    unsigned char *base = (unsigned char *)es_test_slurp(base_path, &n);
    ES_CHECK(base != NULL);
    if (!base) ES_TEST_END();
    f = H5Fopen(base_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    ES_CHECK(f >= 0 && H5Ovisit2(f, H5_INDEX_NAME, H5_ITER_NATIVE, visit, NULL,
                                 H5O_INFO_BASIC | H5O_INFO_HDR) >= 0);
    H5Fclose(f);
    ES_CHECK(nobjs >= 15);

    /* ---- 1. the audit's byte: content_hash's layout version 3 -> 1 ---- */
    for (int i = 0; i < nobjs; i++) {
        if (strcmp(objs[i].name, "/shapes/content_hash")) continue;
        at = find_msg(base, n, &objs[i], 0x08, &sz, NULL);
        ES_CHECK(at > 0 && base[at] == 3);
        /* the audit's copy of the base had it at 0x2f00 */
        printf("content_hash's layout version byte at 0x%zx\n", at);
        one(ctx, path, base, n, at, 1, 0, 0, 0, "/shapes/content_hash has a chunked layout",
            "content_hash layout version 1");
        one(ctx, path, base, n, at, 2, 0, 0, 0, "/shapes/content_hash has a chunked layout",
            "content_hash layout version 2");
    }

    /* ---- 2. each kind of message of every header, changed on purpose ---- */
    for (int i = 0; i < nobjs; i++) {
        const object *o = &objs[i];
        size_t sp, dt;
        result = strncmp(o->name, "/analysis/", 10) ? NULL : o->name + 10;
        if ((at = find_msg(base, n, o, 0x08, &sz, &hdr_at))) {   /* layout */
            for (int v = 0; v < 8; v++) {
                if (v == 3) continue;
                snprintf(what, sizeof what, "%.180s layout version %d", o->name, v);
                one(ctx, path, base, n, at, v, 0, 0, v == 4 ? 1 : 0, o->name, what);
            }
            if (base[at + 1] == 2) {   /* chunked: dimensionality, address, dims */
                snprintf(what, sizeof what, "%.180s chunk dimension 0", o->name);
                one(ctx, path, base, n, at + 3 + 8, 0, at + 3 + 9, 0, 0, "chunk dimension of 0",
                    what);
                snprintf(what, sizeof what, "%.180s chunk rank 40", o->name);
                one(ctx, path, base, n, at + 2, 40, 0, 0, 0, o->name, what);
            }
            snprintf(what, sizeof what, "%.180s layout class 3 (virtual)", o->name);
            one(ctx, path, base, n, at + 1, 3, 0, 0, 0, "virtual", what);
            snprintf(what, sizeof what, "%.180s layout shared", o->name);
            one(ctx, path, base, n, hdr_at + 4, 2, 0, 0, 0, "shared message", what);
            snprintf(what, sizeof what, "%.180s layout as external files", o->name);
            one(ctx, path, base, n, hdr_at, 0x07, 0, 0, 0, "external files", what);
            snprintf(what, sizeof what, "%.180s layout as an unknown message", o->name);
            one(ctx, path, base, n, hdr_at, 0x18, 0, 0, 0, "type 24", what);
        }
        if ((dt = find_msg(base, n, o, 0x03, &sz, NULL))) {      /* datatype */
            for (int cls = 2; cls <= 10; cls++) {
                if (cls == 3 || cls == 9) continue;
                snprintf(what, sizeof what, "%.180s datatype class %d", o->name, cls);
                one(ctx, path, base, n, dt, (base[dt] & 0xf0) | cls, 0, 0, 0, o->name, what);
            }
            snprintf(what, sizeof what, "%.180s datatype version 7", o->name);
            one(ctx, path, base, n, dt, (base[dt] & 0x0f) | 0x70, 0, 0, 0, "unknown version",
                what);
            /* (a string may have any size; a variable-length one's is not read) */
            snprintf(what, sizeof what, "%.180s datatype size 3", o->name);
            one(ctx, path, base, n, dt + 4, 3, 0, 0, (base[dt] & 0x0f) > 1, o->name, what);
        }
        if ((sp = find_msg(base, n, o, 0x01, &sz, NULL))) {      /* dataspace */
            snprintf(what, sizeof what, "%.180s dataspace rank 33", o->name);
            one(ctx, path, base, n, sp + 1, 33, 0, 0, 0, "rank over 32", what);
            snprintf(what, sizeof what, "%.180s dataspace version 3", o->name);
            one(ctx, path, base, n, sp, 3, 0, 0, 0, "dataspace of an unknown version", what);
        }
        if ((at = find_msg(base, n, o, 0x05, &sz, NULL)) && sz >= 8 && base[at] == 2 &&
            base[at + 3]) {                                     /* fill value, defined */
            snprintf(what, sizeof what, "%.180s fill value of 255 bytes", o->name);
            one(ctx, path, base, n, at + 4, 255, 0, 0, 0, "fill value", what);
        }
    }

    /* ---- 2b. a group's local heap claiming more than the file ---- */
    {
        /* its data segment size (after "HEAP", version, 3 reserved bytes;
         * 8-byte lengths in the base) made about 1 GiB: refused from the
         * file's size, not allocated and read (1.2 GB took the store
         * fuzzer 38 s under ASan) */
        int heaps = 0, named = 0;
        unsigned char *b = malloc(n);
        ES_CHECK(b != NULL);
        for (size_t i = 0; b && i + 16 <= n; i++) {
            if (memcmp(base + i, "HEAP", 4) || base[i + 4] != 0) continue;
            heaps++;
            snprintf(what, sizeof what, "local heap at %zu claiming 1 GiB", i);
            one(ctx, path, base, n, i + 8 + 3, 0x40, 0, 0, 1, NULL, what);   /* no crash */
            /* the heaps the opener walks itself (the root group's and the
             * groups below it) are refused by their size; others, of
             * groups HDF5 reads on demand, may open */
            memcpy(b, base, n);
            b[i + 8 + 3] = 0x40;
            put(path, b, n);
            es_store *st = NULL;
            if (es_store_open(ctx, path, ES_STORE_READ, &st) != ES_OK)
                named += es_test_contains(es_ctx_errmsg(ctx), "a local heap of a wrong size");
            es_store_close(st);
        }
        free(b);
        printf("local heaps: %d, %d refused by their size\n", heaps, named);
        ES_CHECK(heaps > 0 && named > 0);
        result = NULL;
    }

    /* ---- 3. every byte of every header ---- */
    int opened = 0, refused = 0;
    for (int i = 0; i < nobjs; i++) sweep(ctx, path, base, n, &objs[i], &opened, &refused);
    printf("object headers: %d objects, %d changed stores opened and read, %d refused\n",
           nobjs, opened, refused);
    ES_CHECK(refused > 0 && opened > 0);
    free(base);
    es_ctx_free(ctx);
    ES_TEST_END();
}
