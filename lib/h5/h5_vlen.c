/* lib/h5/h5_vlen.c — variable-length strings read without trusting
 * the file: the store decodes HDF5's on-disk string descriptors and global
 * heap collections itself instead of calling H5Dread/H5Aread on them.
 *
 * Why: libhdf5 1.10 (Debian 12) trusts a global heap collection's object
 * sizes and indices. H5HG_read copies an object's recorded size into a
 * buffer sized by the descriptor and dereferences objects it never found,
 * and a free-space object of size 0 loops for ever: one changed byte in a
 * collection made every command segfault, hang or allocate gigabytes.
 *
 * How: a string's descriptor (HDF5 File Format Specification 3.0, IV.A.2.d,
 * "variable-length"; 4-byte length, collection address, 4-byte object
 * index) is read raw — for datasets from their chunks or contiguous block,
 * found through HDF5's chunk index, for attributes from the attribute
 * message of the object header (IV.A.1.a/b, IV.A.2.m) — and resolved
 * against global heap collections (III.E) parsed here, every size checked
 * against the collection and the file. A string is accepted only when its
 * descriptor's length equals its heap object's size. Bytes are read with
 * pread() on HDF5's own descriptor of the file (the sec2 driver), after a
 * flush, so that what this handle wrote is seen too.
 */
#include "h5/h5_pkg.h"

#include <errno.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

/* A parsed collection: its bytes and its objects sorted by index. */
typedef struct gobj { uint32_t idx; uint64_t off, len; } gobj;
typedef struct gcol {
    uint64_t addr, size;
    uint8_t *buf;
    gobj *obj;
    int64_t nobj;
} gcol;

struct es__h5_raw {
    es_ctx *ctx;
    const char *path;        /* for messages */
    int fd;
    char *mem;               /* a file in memory (a result being written): its image */
    uint64_t base, eof;      /* addresses are relative to base; eof: file size */
    unsigned sa, ss;         /* sizes of addresses and lengths (8 and 8 as written) */
    gcol **map;              /* open addressing by collection address */
    int64_t cap, n;
    uint64_t loaded;         /* bytes of collections loaded: at most the file */
};

static uint64_t le(const uint8_t *p, unsigned n)
{
    uint64_t v = 0;
    for (unsigned k = n; k-- > 0;) v = v << 8 | p[k];
    return v;
}

static uint64_t align8(uint64_t n) { return (n + 7) & ~(uint64_t)7; }

es_status es__h5_raw_open(es_ctx *ctx, hid_t obj, const char *path, es__h5_raw **out)
{
    hid_t fid = -1, fcpl = -1, fapl = -1;
    es__h5_raw *r;
    size_t sa = 0, ss = 0;
    hsize_t ub = 0;
    unsigned intent = 0;
    void *handle = NULL;
    struct stat st;
    es_status rc = ES_OK;
    *out = NULL;
    if (!(r = es__calloc(ctx, 1, sizeof *r))) return ES_ENOMEM;
    r->ctx = ctx;
    r->path = path;
    r->fd = -1;
    if ((fid = H5Iget_file_id(obj)) < 0 || (fcpl = H5Fget_create_plist(fid)) < 0 ||
        (fapl = H5Fget_access_plist(fid)) < 0 || H5Pget_sizes(fcpl, &sa, &ss) < 0 ||
        H5Pget_userblock(fcpl, &ub) < 0 || H5Fget_intent(fid, &intent) < 0) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: '%s': cannot read the file's properties", path);
        goto done;
    }
    if (H5Pget_driver(fapl) == H5FD_CORE) {
        /* a result this handle is writing (store_beside.c): read its image */
        ssize_t size;
        if (H5Fflush(fid, H5F_SCOPE_LOCAL) < 0 || (size = H5Fget_file_image(fid, NULL, 0)) < 0 ||
            !(r->mem = es__malloc(ctx, size > 0 ? (size_t)size : 1)) ||
            H5Fget_file_image(fid, r->mem, (size_t)size) != size) {
            rc = r->mem ? es__h5_fail(ctx, ES_EIO, "store: cannot read '%s'", path) : ES_ENOMEM;
            goto done;
        }
        st.st_size = (off_t)size;
        goto sized;
    }
    if (H5Pget_driver(fapl) != H5FD_SEC2 || H5Fget_vfd_handle(fid, H5P_DEFAULT, &handle) < 0 ||
        !handle) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': not a plain file (HDF5 driver)", path);
        goto done;
    }
    /* what this handle wrote must be in the file before it is read raw */
    if ((intent & H5F_ACC_RDWR) && H5Fflush(fid, H5F_SCOPE_LOCAL) < 0) {
        rc = es__h5_fail(ctx, ES_EIO, "store: cannot flush '%s'", path);
        goto done;
    }
    r->fd = *(int *)handle;
    if (fstat(r->fd, &st) != 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot read '%s': %s", path, strerror(errno));
        goto done;
    }
sized:
    if ((sa != 4 && sa != 8) || (ss != 4 && ss != 8)) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': %zu-byte addresses and %zu-byte lengths "
                      "(edgespace reads 4 or 8)", path, sa, ss);
        goto done;
    }
    r->sa = (unsigned)sa;
    r->ss = (unsigned)ss;
    r->base = ub;
    r->eof = (uint64_t)st.st_size;
done:
    es__h5_close(fapl);
    es__h5_close(fcpl);
    es__h5_close(fid);
    if (rc != ES_OK) {
        es__free(ctx, r->mem);
        es__free(ctx, r);
        return rc;
    }
    *out = r;
    return ES_OK;
}

es_status es__h5_raw_open_fd(es_ctx *ctx, int fd, const char *path, uint64_t base, unsigned sa,
                             unsigned ss, es__h5_raw **out)
{
    es__h5_raw *r;
    struct stat st;
    *out = NULL;
    if (fstat(fd, &st) != 0)
        ES_FAIL(ctx, ES_EIO, "store: cannot read '%s': %s", path, strerror(errno));
    if ((sa != 4 && sa != 8) || (ss != 4 && ss != 8))
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': %u-byte addresses and %u-byte lengths (edgespace "
                "reads 4 or 8)", path, sa, ss);
    if (!(r = es__calloc(ctx, 1, sizeof *r))) return ES_ENOMEM;
    r->ctx = ctx;
    r->path = path;
    r->fd = fd;
    r->sa = sa;
    r->ss = ss;
    r->base = base;
    r->eof = (uint64_t)st.st_size;
    *out = r;
    return ES_OK;
}

unsigned es__h5_raw_vlen_size(const es__h5_raw *r) { return 8 + r->sa; }

es_status es__h5_object_addr(es_ctx *ctx, hid_t obj, uint64_t *addr)
{
#if H5_VERSION_GE(1, 12, 0)
    H5O_info2_t oi;
    haddr_t a = HADDR_UNDEF;
    if (H5Oget_info3(obj, &oi, H5O_INFO_BASIC) < 0 ||
        H5VLnative_token_to_addr(obj, oi.token, &a) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: cannot find an object header");
    *addr = a;
#else
    H5O_info_t oi;
    if (H5Oget_info2(obj, &oi, H5O_INFO_BASIC) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: cannot find an object header");
    *addr = oi.addr;
#endif
    return ES_OK;
}
uint64_t es__h5_raw_file_size(const es__h5_raw *r) { return r->eof; }

void es__h5_raw_close(es__h5_raw *r)
{
    if (!r) return;
    for (int64_t i = 0; i < r->cap; i++)
        if (r->map[i]) {
            es__free(r->ctx, r->map[i]->buf);
            es__free(r->ctx, r->map[i]->obj);
            es__free(r->ctx, r->map[i]);
        }
    es__free(r->ctx, r->map);
    es__free(r->ctx, r->mem);
    es__free(r->ctx, r);
}

/* n bytes at file address addr (relative to the base), inside the file. */
static es_status raw_read(es__h5_raw *r, uint64_t addr, uint64_t n, void *buf, const char *what)
{
    uint64_t at;
    if (__builtin_add_overflow(addr, r->base, &at) || at > r->eof || n > r->eof - at)
        ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: %s (%llu bytes at %llu) lies past "
                "the end of the file (%llu bytes)", r->path, what, (unsigned long long)n,
                (unsigned long long)at, (unsigned long long)r->eof);
    if (r->mem) {
        memcpy(buf, r->mem + at, (size_t)n);
        return ES_OK;
    }
    for (uint64_t done = 0; done < n;) {
        ssize_t k = pread(r->fd, (char *)buf + done, (size_t)(n - done), (off_t)(at + done));
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0)
            ES_FAIL(r->ctx, ES_EIO, "store: cannot read '%s': %s", r->path,
                    k < 0 ? strerror(errno) : "unexpected end of file");
        done += (uint64_t)k;
    }
    return ES_OK;
}

static int cmp_gobj(const void *a, const void *b)
{
    uint32_t x = ((const gobj *)a)->idx, y = ((const gobj *)b)->idx;
    return x < y ? -1 : x > y;
}

/* Parse a collection's objects the way HDF5 lays them out (III.E): each an
 * index, a reference count, its size and its data padded to 8 bytes; index
 * 0 is free space whose size counts its own header. Every object must lie
 * inside the collection and no index may repeat. */
static es_status parse_gcol(es__h5_raw *r, gcol *g)
{
    const uint64_t hdr = align8(8 + r->ss), objhdr = 8 + r->ss;
    uint64_t p = hdr;
    int64_t cap = (int64_t)(g->size / objhdr) + 1;
    if (!(g->obj = es__alloc_array(r->ctx, cap, sizeof *g->obj))) return ES_ENOMEM;
    while (p < g->size && g->size - p >= objhdr) {
        uint32_t idx = (uint32_t)le(g->buf + p, 2);
        uint64_t len = le(g->buf + p + 8, r->ss), need;
        if (idx == 0) need = len;
        else need = len > g->size ? UINT64_MAX : objhdr + align8(len);
        if (need < objhdr || need > g->size - p)
            ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: object %u of the global heap "
                    "collection at %llu has size %llu, which does not fit its %llu bytes",
                    r->path, idx, (unsigned long long)g->addr, (unsigned long long)len,
                    (unsigned long long)g->size);
        if (idx > 0) {
            g->obj[g->nobj].idx = idx;
            g->obj[g->nobj].off = p + objhdr;
            g->obj[g->nobj].len = len;
            g->nobj++;
        }
        p += need;
    }
    qsort(g->obj, (size_t)g->nobj, sizeof *g->obj, cmp_gobj);
    for (int64_t i = 1; i < g->nobj; i++)
        if (g->obj[i].idx == g->obj[i - 1].idx)
            ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: object %u appears twice in the "
                    "global heap collection at %llu", r->path, g->obj[i].idx,
                    (unsigned long long)g->addr);
    return ES_OK;
}

static es_status load_gcol(es__h5_raw *r, uint64_t addr, gcol **out)
{
    uint8_t head[16];
    const unsigned hn = 8 + r->ss;
    gcol *g;
    es_status rc;
    if ((rc = raw_read(r, addr, hn, head, "a global heap collection"))) return rc;
    if (memcmp(head, "GCOL", 4) || head[4] != 1)
        ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: no global heap collection at "
                "address %llu", r->path, (unsigned long long)addr);
    if (!(g = es__calloc(r->ctx, 1, sizeof *g))) return ES_ENOMEM;
    g->addr = addr;
    g->size = le(head + 8, r->ss);
    /* collections never overlap: more bytes than the file means a loop */
    if (g->size < align8(hn) || g->size > r->eof || r->loaded > r->eof - g->size) {
        es__free(r->ctx, g);
        ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: the global heap collection at "
                "%llu claims %llu bytes", r->path, (unsigned long long)addr,
                (unsigned long long)le(head + 8, r->ss));
    }
    r->loaded += g->size;
    if (!(g->buf = es__malloc(r->ctx, (size_t)g->size))) rc = ES_ENOMEM;
    else if (!(rc = raw_read(r, addr, g->size, g->buf, "a global heap collection")))
        rc = parse_gcol(r, g);
    if (rc) {
        es__free(r->ctx, g->buf);
        es__free(r->ctx, g->obj);
        es__free(r->ctx, g);
        return rc;
    }
    *out = g;
    return ES_OK;
}

/* The collection at addr, parsed once per raw reader. */
static es_status get_gcol(es__h5_raw *r, uint64_t addr, gcol **out)
{
    uint64_t h;
    es_status rc;
    if (r->cap) {
        for (h = (addr >> 3) * 0x9E3779B97F4A7C15u; r->map[h & (uint64_t)(r->cap - 1)]; h++)
            if (r->map[h & (uint64_t)(r->cap - 1)]->addr == addr) {
                *out = r->map[h & (uint64_t)(r->cap - 1)];
                return ES_OK;
            }
    }
    if (2 * (r->n + 1) > r->cap) {
        int64_t cap = r->cap ? 2 * r->cap : 16;
        gcol **m = es__alloc_array(r->ctx, cap, sizeof *m);
        if (!m) return ES_ENOMEM;
        memset(m, 0, (size_t)cap * sizeof *m);
        for (int64_t i = 0; i < r->cap; i++) {
            if (!r->map[i]) continue;
            for (h = (r->map[i]->addr >> 3) * 0x9E3779B97F4A7C15u; m[h & (uint64_t)(cap - 1)]; h++) {
            }
            m[h & (uint64_t)(cap - 1)] = r->map[i];
        }
        es__free(r->ctx, r->map);
        r->map = m;
        r->cap = cap;
    }
    if ((rc = load_gcol(r, addr, out))) return rc;
    for (h = (addr >> 3) * 0x9E3779B97F4A7C15u; r->map[h & (uint64_t)(r->cap - 1)]; h++) {
    }
    r->map[h & (uint64_t)(r->cap - 1)] = *out;
    r->n++;
    return ES_OK;
}

/* Decode n descriptors of elem bytes each into strings. *budget bounds
 * the bytes copied (each heap object is one string, so a valid file never
 * needs more than its own size). what/row0 name the strings in messages. */
static es_status decode(es__h5_raw *r, const uint8_t *d, int64_t n, int64_t row0,
                        const char *what, uint64_t *budget, char **out)
{
    const unsigned elem = 8 + r->sa;
    for (int64_t i = 0; i < n; i++, d += elem) {
        uint64_t len = le(d, 4), addr = le(d + 4, r->sa);
        uint32_t idx = (uint32_t)le(d + 4 + r->sa, 4);
        const uint8_t *src = NULL;
        es_status rc;
        if (addr == 0 || (r->sa == 4 ? addr == UINT32_MAX : addr == UINT64_MAX)) {
            /* never written (a fill value): the empty string */
            if (len != 0)
                ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: %s, row %lld: a string of "
                        "%llu bytes without heap data", r->path, what, (long long)(row0 + i),
                        (unsigned long long)len);
        } else {
            gcol *g = NULL;
            int64_t lo = 0, hi;
            if ((rc = get_gcol(r, addr, &g))) return rc;
            for (hi = g->nobj; lo < hi;) {
                int64_t mid = lo + (hi - lo) / 2;
                if (g->obj[mid].idx < idx) lo = mid + 1;
                else hi = mid;
            }
            if (lo == g->nobj || g->obj[lo].idx != idx || idx == 0 || g->obj[lo].len != len)
                ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: %s, row %lld: its string "
                        "(%llu bytes, heap object %u at %llu) is not in the global heap",
                        r->path, what, (long long)(row0 + i), (unsigned long long)len, idx,
                        (unsigned long long)addr);
            src = g->buf + g->obj[lo].off;
        }
        while (len > 0 && src[len - 1] == '\0') len--;   /* writers that store the NUL */
        if (len > *budget)
            ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: the strings of %s add up to "
                    "more than the file", r->path, what);
        *budget -= len;
        if (len && memchr(src, '\0', (size_t)len))
            ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s': %s, row %lld holds a NUL byte", r->path,
                    what, (long long)(row0 + i));
        if (!(out[i] = es__malloc(r->ctx, (size_t)len + 1))) return ES_ENOMEM;
        if (len) memcpy(out[i], src, (size_t)len);
        out[i][len] = '\0';
    }
    return ES_OK;
}

/* Fixed-length strings (h5py and others may write them): HDF5 converts
 * these without touching a heap. */
static es_status read_fixed(es__h5_raw *r, hid_t ds, hid_t ftype, const char *what,
                            int64_t n, char **out)
{
    size_t sz = H5Tget_size(ftype), bytes;
    hid_t mt = -1;
    char *buf;
    es_status rc = ES_OK;
    if (sz == 0 || sz > ((size_t)1 << 20) || !es__mul_size(sz, (size_t)n, &bytes) ||
        (uint64_t)bytes > r->eof)
        ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: %s has %lld strings of %zu bytes",
                r->path, what, (long long)n, sz);
    if (!(buf = es__malloc(r->ctx, bytes ? bytes : 1))) return ES_ENOMEM;
    if ((mt = H5Tcopy(ftype)) < 0 || H5Dread(ds, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
        rc = es__h5_fail(r->ctx, ES_EFORMAT, "store: cannot read %s in '%s'", what, r->path);
    for (int64_t i = 0; i < n && rc == ES_OK; i++) {
        const char *s = buf + (size_t)i * sz;
        size_t len = strnlen(s, sz);
        if (!(out[i] = es__malloc(r->ctx, len + 1))) rc = ES_ENOMEM;
        else {
            memcpy(out[i], s, len);
            out[i][len] = '\0';
        }
    }
    es__h5_close(mt);
    es__free(r->ctx, buf);
    return rc;
}

/* The descriptors of rows [0, n) of a 1-D variable-length string dataset:
 * from each allocated chunk (rows of an unallocated chunk are empty), or
 * from the contiguous block. Filtered or compact storage is refused. */
static es_status read_vlen_ds(es__h5_raw *r, hid_t ds, const char *what, int64_t n, char **out)
{
    const unsigned elem = 8 + r->sa;
    hid_t dcpl = H5Dget_create_plist(ds);
    uint64_t budget = r->eof;
    uint8_t *buf = NULL;
    es_status rc = ES_OK;
    H5D_layout_t layout;
    hsize_t cd = 0;
    if (dcpl < 0) return es__h5_fail(r->ctx, ES_EFORMAT, "store: cannot read %s", what);
    layout = H5Pget_layout(dcpl);
    if (H5Pget_nfilters(dcpl) != 0 || H5Pget_external_count(dcpl) != 0 ||
        (layout != H5D_CHUNKED && layout != H5D_CONTIGUOUS) ||
        (layout == H5D_CHUNKED && (H5Pget_chunk(dcpl, 1, &cd) != 1 || cd == 0))) {
        rc = es__fail(r->ctx, ES_EFORMAT, "store: '%s': %s is stored compressed, compact or "
                      "in another file, which edgespace does not read for strings", r->path,
                      what);
        goto done;
    }
    /* the descriptors alone must fit the file: a count from a crafted
     * dataspace is refused before anything is allocated */
    if ((uint64_t)n > r->eof / elem || cd > r->eof / elem) {
        rc = es__fail(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: %s claims %lld rows (chunks "
                      "of %llu), more than the file's %llu bytes hold", r->path, what,
                      (long long)n, (unsigned long long)cd, (unsigned long long)r->eof);
        goto done;
    }
    if (layout == H5D_CONTIGUOUS) {
        haddr_t a = H5Dget_offset(ds);
        uint64_t bytes = (uint64_t)n * elem;
        if (n == 0) goto done;
        if (!(buf = es__malloc(r->ctx, (size_t)bytes))) { rc = ES_ENOMEM; goto done; }
        if (a == HADDR_UNDEF) memset(buf, 0, (size_t)bytes);
        else if ((rc = raw_read(r, a, bytes, buf, what))) goto done;
        rc = decode(r, buf, n, 0, what, &budget, out);
        goto done;
    }
    if (!(buf = es__malloc(r->ctx, (size_t)(cd * elem)))) { rc = ES_ENOMEM; goto done; }
    for (int64_t row = 0; row < n && rc == ES_OK; row += (int64_t)cd) {
        hsize_t off = (hsize_t)row, size = 0;
        haddr_t a = HADDR_UNDEF;
        unsigned mask = 0;
        int64_t m = n - row < (int64_t)cd ? n - row : (int64_t)cd;
        if (H5Dget_chunk_info_by_coord(ds, &off, &mask, &a, &size) < 0) {
            rc = es__h5_fail(r->ctx, ES_EFORMAT, "store: '%s': cannot find the chunk of %s at "
                             "row %lld", r->path, what, (long long)row);
            break;
        }
        if (a == HADDR_UNDEF) memset(buf, 0, (size_t)(cd * elem));
        else if (size != cd * elem) {
            rc = es__fail(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: the chunk of %s at row "
                          "%lld has %llu bytes, not %llu", r->path, what, (long long)row,
                          (unsigned long long)size, (unsigned long long)(cd * elem));
            break;
        } else if ((rc = raw_read(r, a, size, buf, what))) {
            break;
        }
        rc = decode(r, buf, m, row, what, &budget, out + row);
    }
done:
    es__free(r->ctx, buf);
    es__h5_close(dcpl);
    return rc;
}

es_status es__h5_read_strings(es_ctx *ctx, es__h5_raw *raw, hid_t loc, const char *name,
                              int64_t n, char **out)
{
    hid_t ds = -1, sp = -1, t = -1;
    hsize_t d = 0;
    es_status rc = ES_OK;
    char what[300];
    snprintf(what, sizeof what, "%s", name);
    for (int64_t i = 0; i < n; i++) out[i] = NULL;
    if ((ds = es__h5_open_ds(loc, name)) < 0 || (sp = H5Dget_space(ds)) < 0 ||
        (t = H5Dget_type(ds)) < 0 || H5Sget_simple_extent_ndims(sp) != 1 ||
        H5Tget_class(t) != H5T_STRING) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: '%s': %s is not a 1-D string dataset",
                         raw->path, name);
        goto done;
    }
    H5Sget_simple_extent_dims(sp, &d, NULL);
    if (d != (hsize_t)n) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': %s has %llu rows, expected %lld",
                      raw->path, name, (unsigned long long)d, (long long)n);
        goto done;
    }
    if (H5Tis_variable_str(t) > 0) rc = read_vlen_ds(raw, ds, what, n, out);
    else rc = read_fixed(raw, ds, t, what, n, out);
done:
    es__h5_close(t);
    es__h5_close(sp);
    es__h5_close(ds);
    return rc;
}

/* ---- object headers and attributes ---------------------------------------- */

/* A chunk of an object header to scan: its messages lie in [addr, addr+len). */
typedef struct ochunk { uint64_t addr, len; } ochunk;

es_status es__h5_raw_read(es__h5_raw *r, uint64_t addr, uint64_t n, void *buf, const char *what)
{
    return raw_read(r, addr, n, buf, what);
}

uint64_t es__h5_le(const uint8_t *p, unsigned n) { return le(p, n); }
unsigned es__h5_raw_addr_size(const es__h5_raw *r) { return r->sa; }
unsigned es__h5_raw_length_size(const es__h5_raw *r) { return r->ss; }
es_ctx *es__h5_raw_ctx(const es__h5_raw *r) { return r->ctx; }
const char *es__h5_raw_path(const es__h5_raw *r) { return r->path; }

/* Walk the messages of the object header at oaddr (version 1, or 2 with
 * its "OHDR"/"OCHK" chunks; IV.A.1), following continuation messages (at
 * most 64 chunks). */
es_status es__h5_raw_messages(es__h5_raw *r, uint64_t oaddr, es__h5_msg_fn fn, void *ud)
{
    ochunk q[64];
    int nq = 0, v2 = 0, crt = 0;
    uint8_t pre[40];
    uint64_t avail = r->eof > oaddr + r->base ? r->eof - oaddr - r->base : 0;
    es_status rc;
    if ((rc = raw_read(r, oaddr, avail < sizeof pre ? avail : sizeof pre, pre,
                       "an object header")))
        return rc;
    if (avail >= 16 && !memcmp(pre, "OHDR", 4) && pre[4] == 2) {
        unsigned flags = pre[5], p = 6, w = 1u << (flags & 3);
        if (flags & 0x20) p += 16;
        if (flags & 0x10) p += 4;
        if (p + w > avail) goto corrupt;
        v2 = 1;
        crt = (flags & 0x04) != 0;
        q[nq++] = (ochunk){oaddr + p + w, le(pre + p, w)};
    } else if (avail >= 16 && pre[0] == 1) {
        q[nq++] = (ochunk){oaddr + 16, le(pre + 8, 4)};
    } else {
        goto corrupt;
    }
    for (int c = 0; c < nq; c++) {
        uint64_t len = q[c].len, p, end;
        uint8_t *b;
        if (len > r->eof) goto corrupt;
        if (!(b = es__malloc(r->ctx, (size_t)len + 1))) return ES_ENOMEM;
        if ((rc = raw_read(r, q[c].addr, len, b, "an object header"))) {
            es__free(r->ctx, b);
            return rc;
        }
        p = 0;
        end = len;
        if (v2 && c > 0) {           /* "OCHK", messages, checksum */
            if (len < 8 || memcmp(b, "OCHK", 4)) { es__free(r->ctx, b); goto corrupt; }
            p = 4;
            end = len - 4;
        }
        for (;;) {
            uint64_t hsz = v2 ? 4u + 2u * (unsigned)crt : 8u, type, msz;
            unsigned flags;
            int k;
            if (end - p < hsz) break;
            type = v2 ? b[p] : le(b + p, 2);
            msz = le(b + p + (v2 ? 1 : 2), 2);
            flags = b[p + (v2 ? 3 : 4)];
            p += hsz;
            if (msz > end - p) { es__free(r->ctx, b); goto corrupt; }
            if (type == 0x10) {                  /* continuation */
                if (msz < (uint64_t)r->sa + r->ss || nq == 64) { es__free(r->ctx, b); goto corrupt; }
                q[nq++] = (ochunk){le(b + p, r->sa), le(b + p + r->sa, r->ss)};
            } else if ((k = fn(ud, (unsigned)type, flags, b + p, msz)) != 0) {
                es__free(r->ctx, b);
                if (k < 0) goto corrupt;
                return ES_OK;
            }
            p += msz;
        }
        es__free(r->ctx, b);
    }
    return ES_ENOTFOUND;
corrupt:
    ES_FAIL(r->ctx, ES_EFORMAT, "store: '%s' is corrupt: an object header (at %llu) is "
            "malformed", r->path, (unsigned long long)oaddr);
}

/* The value bytes of attribute `key` in the attribute message msg[0..n). 0
 * if the name differs, 1 with *data and *dlen if it matches, -1 if malformed. */
static int attr_value(const uint8_t *m, uint64_t n, const char *key, const uint8_t **data,
                      uint64_t *dlen)
{
    uint64_t p, nsz, tsz, ssz;
    size_t klen = strlen(key);
    if (n < 9 || m[0] < 1 || m[0] > 3) return -1;
    nsz = le(m + 2, 2);
    tsz = le(m + 4, 2);
    ssz = le(m + 6, 2);
    p = m[0] == 3 ? 9 : 8;
    if (nsz == 0 || nsz > n - p) return -1;
    if (nsz - 1 < klen || memcmp(m + p, key, klen) || m[p + klen] != '\0') return 0;
    if (m[0] > 1 && (m[1] & 3)) return -1;   /* shared datatype or dataspace */
    if (m[0] == 1) p += align8(nsz) + align8(tsz) + align8(ssz);
    else p += nsz + tsz + ssz;
    if (p > n) return -1;
    *data = m + p;
    *dlen = n - p;
    return 1;
}

typedef struct attr_find {
    es__h5_raw *r;
    const char *key;
    uint8_t *val;
    uint64_t vlen;
    int nomem;
} attr_find;

static int find_attr(void *ud, unsigned type, unsigned flags, const uint8_t *m, uint64_t n)
{
    attr_find *a = ud;
    const uint8_t *d;
    uint64_t dl;
    int k;
    (void)flags;
    if (type != 0x0C) return 0;
    if ((k = attr_value(m, n, a->key, &d, &dl)) <= 0) return k;
    if (!(a->val = es__malloc(a->r->ctx, (size_t)dl + 1))) a->nomem = 1;
    else memcpy(a->val, d, (size_t)dl);
    a->vlen = dl;
    return 1;
}

/* The raw value of attribute key of the object at oaddr into *val. */
static es_status header_attr(es__h5_raw *r, uint64_t oaddr, const char *key, uint8_t **val,
                             uint64_t *vlen)
{
    attr_find a = {r, key, NULL, 0, 0};
    es_status rc = es__h5_raw_messages(r, oaddr, find_attr, &a);
    *val = a.val;
    *vlen = a.vlen;
    if (a.nomem) return ES_ENOMEM;
    if (rc == ES_ENOTFOUND)
        ES_FAIL(r->ctx, ES_ENOTFOUND, "store: '%s': attribute '%s' is not stored compactly, "
                "which edgespace does not read", r->path, key);
    return rc;
}

es_status es__h5_read_attr_strings(es_ctx *ctx, es__h5_raw *raw, hid_t obj, const char *key,
                                   char ***out, int64_t *n)
{
    hid_t a = -1, t = -1, sp = -1;
    es__h5_raw *r = raw;
    uint8_t *val = NULL;
    uint64_t vlen = 0, budget;
    hssize_t np = 0;
    char **s = NULL, what[300];
    es_status rc = ES_OK;
    *out = NULL;
    *n = 0;
    snprintf(what, sizeof what, "attribute '%s'", key);
    if ((a = H5Aopen(obj, key, H5P_DEFAULT)) < 0 || (t = H5Aget_type(a)) < 0 ||
        (sp = H5Aget_space(a)) < 0) {
        rc = es__h5_fail(ctx, ES_ENOTFOUND, "store: no attribute '%s'", key);
        goto done;
    }
    if (H5Tget_class(t) != H5T_STRING) {
        rc = es__fail(ctx, ES_EFORMAT, "store: attribute '%s' is not a string", key);
        goto done;
    }
    np = H5Sget_simple_extent_type(sp) == H5S_NULL ? 0 : H5Sget_simple_extent_npoints(sp);
    if (np < 0 || (uint64_t)np > r->eof) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: attribute '%s' claims %lld "
                      "strings", r->path, key, (long long)np);
        goto done;
    }
    if (!(s = es__alloc_array(ctx, np ? np : 1, sizeof *s))) { rc = ES_ENOMEM; goto done; }
    for (hssize_t i = 0; i < np; i++) s[i] = NULL;
    if (np > 0 && H5Tis_variable_str(t) > 0) {
        uint64_t oaddr = 0;
        budget = r->eof;
        if ((rc = es__h5_object_addr(ctx, obj, &oaddr)) ||
            (rc = header_attr(r, oaddr, key, &val, &vlen)))
            goto done;
        if (vlen < (uint64_t)np * (8 + r->sa)) {
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: attribute '%s' holds %llu "
                          "bytes for %lld strings", r->path, key, (unsigned long long)vlen,
                          (long long)np);
            goto done;
        }
        rc = decode(r, val, np, 0, what, &budget, s);
    } else if (np > 0) {
        size_t sz = H5Tget_size(t), bytes;
        char *buf;
        if (sz == 0 || sz > ((size_t)1 << 20) || !es__mul_size(sz, (size_t)np, &bytes) ||
            bytes > r->eof) {
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: attribute '%s'", r->path,
                          key);
            goto done;
        }
        if (!(buf = es__malloc(ctx, bytes))) { rc = ES_ENOMEM; goto done; }
        if (H5Aread(a, t, buf) < 0)
            rc = es__h5_fail(ctx, ES_EFORMAT, "store: cannot read attribute '%s'", key);
        for (hssize_t i = 0; i < np && rc == ES_OK; i++) {
            size_t len = strnlen(buf + (size_t)i * sz, sz);
            if (!(s[i] = es__malloc(ctx, len + 1))) rc = ES_ENOMEM;
            else {
                memcpy(s[i], buf + (size_t)i * sz, len);
                s[i][len] = '\0';
            }
        }
        es__free(ctx, buf);
    }
done:
    if (rc == ES_OK) {
        *out = s;
        *n = np;
    } else if (s) {
        for (hssize_t i = 0; i < np; i++) es__free(ctx, s[i]);
        es__free(ctx, s);
    }
    es__free(ctx, val);
    es__h5_close(sp);
    es__h5_close(t);
    es__h5_close(a);
    return rc;
}
