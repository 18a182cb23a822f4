/* lib/h5/h5_headers.c — every message of an object header checked
 * before HDF5 decodes any of it.
 *
 * Why: libhdf5 1.10 (Debian 12) decodes what an object header says with
 * few checks. A layout message whose version byte changed from 3 to 1 is
 * read as the old format, with chunk dimensions of 0, and H5Dopen divides
 * by them (SIGFPE in every reader of the store); a fill value, compact
 * layout or filter parameter that claims more bytes than its message is
 * copied past it. So the store never lets HDF5 open an object whose header
 * it has not walked itself: every message is decoded here by the HDF5 File
 * Format Specification 3.0 (IV.A.2), each size, count and version checked
 * against the message, the file and the other messages, and anything
 * edgespace does not write or read (shared or external data, links to
 * other files, dense attribute or link storage, datatypes other than
 * integers, IEEE reals and strings, filters other than deflate, shuffle and
 * Fletcher-32) is refused by name. The object's address comes from its
 * link, so HDF5 has not even loaded the header when it is checked.
 */
#include "h5/h5_pkg.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

enum {
    MAX_RANK = 32,            /* H5S_MAX_RANK */
    MSG_SHARED = 0x02         /* message flag: the message lives elsewhere */
};

/* What the messages of one header said, for the checks across messages. */
typedef struct hdr {
    es__h5_raw *r;
    unsigned sa, ss;
    int superblock_ext;       /* the superblock extension's header: its own messages */
    const char *why;          /* the first problem (static text) */
    char whybuf[160];
    int nspace, ntype, nlayout, nfill, npline, ngroup, nstab, nlinfo;
    int rank;
    uint64_t npoints, elem;   /* elements of the dataspace; bytes of one on disk */
    int layout;               /* 0 compact, 1 contiguous, 2 chunked */
    unsigned chunk_ndims;
    uint64_t chunk_last;      /* a chunk's last dimension: the element size */
    uint64_t storage;         /* compact or contiguous bytes (UINT64_MAX: computed) */
    uint64_t addr;            /* contiguous data address (UINT64_MAX: none yet) */
    uint64_t fill;            /* bytes of the fill value (0: none) */
} hdr;

static uint64_t le(const uint8_t *p, unsigned n) { return es__h5_le(p, n); }

static int bad(hdr *h, const char *why)
{
    if (!h->why) h->why = why;
    return -1;
}

static bool undefined(const hdr *h, uint64_t a)
{
    return h->sa == 8 ? a == UINT64_MAX : a == 0xffffffffu;
}

/* An address of n bytes inside the file (or the undefined address). */
static bool addr_ok(const hdr *h, uint64_t a, uint64_t n)
{
    uint64_t eof = es__h5_raw_file_size(h->r);
    return undefined(h, a) || (a <= eof && n <= eof - a);
}

/* ---- datatypes (IV.A.2.d) -------------------------------------------------------
 * Integers of 1, 2, 4 or 8 bytes with every bit used, IEEE binary32 and
 * binary64 reals, fixed-length strings and variable-length strings of
 * bytes: what edgespace writes and reads, and what h5py, R and MATLAB
 * write for them. HDF5 converts the others with bit-field arithmetic on
 * what their properties claim. *used: bytes of the message; *elem: bytes
 * of one element on disk. */
static const char *check_dtype(const hdr *h, const uint8_t *m, uint64_t n, int depth,
                               uint64_t *used, uint64_t *elem)
{
    unsigned cls, version, b0, b1, b2;
    uint64_t size;
    if (n < 8) return "a truncated datatype";
    cls = m[0] & 0x0f;
    version = m[0] >> 4;
    b0 = m[1];
    b1 = m[2];
    b2 = m[3];
    size = le(m + 4, 4);
    if (version < 1 || version > 3) return "a datatype of an unknown version";
    switch (cls) {
    case 0:   /* fixed-point: byte order, padding (0), signed; offset, precision */
        if (n < 12) return "a truncated integer datatype";
        if ((size != 1 && size != 2 && size != 4 && size != 8) || (b0 & 0xf6) || b1 || b2 ||
            le(m + 8, 2) != 0 || le(m + 10, 2) != 8 * size)
            return "an integer datatype of an unusual size or bit layout";
        *used = 12;
        *elem = size;
        return NULL;
    case 1: { /* floating-point: exactly IEEE 754 binary32 or binary64 */
        static const unsigned ieee[2][7] = {{4, 32, 23, 8, 0, 23, 127},
                                            {8, 64, 52, 11, 0, 52, 1023}};
        const unsigned *f = size == 4 ? ieee[0] : size == 8 ? ieee[1] : NULL;
        if (n < 20) return "a truncated real datatype";
        /* byte order in bit 0 (bit 6, VAX order, is refused), padding bits
         * 1-3 zero, mantissa normalization 2 (implied), sign bit */
        if (!f || (b0 & 0x4e) || (b0 & 0x30) != 0x20 || b1 != 8 * size - 1 || b2 ||
            le(m + 8, 2) != 0 || le(m + 10, 2) != f[1] || m[12] != f[2] || m[13] != f[3] ||
            m[14] != f[4] || m[15] != f[5] || le(m + 16, 4) != f[6])
            return "a real datatype that is not IEEE binary32 or binary64";
        *used = 20;
        *elem = size;
        return NULL;
    }
    case 3:   /* fixed-length string: padding 0-2, ASCII or UTF-8 */
        if (size < 1 || (b0 & 0x0f) > 2 || (b0 >> 4) > 1 || b1 || b2)
            return "a string datatype of a wrong size, padding or character set";
        *used = 8;
        *elem = size;
        return NULL;
    case 9: { /* variable length: only strings, of single bytes */
        uint64_t bu = 0, be = 0;
        const char *why;
        if ((b0 & 0x0f) != 1 || (b0 >> 4) > 2 || b1 > 1 || b2 || depth > 0)
            return "a variable-length datatype that is not a string";
        /* its size is the descriptor's (length, collection address, index):
         * libhdf5 1.10 copies an attribute's value at the size written here
         * (72 for 16 read past the message: found by the store fuzzer) */
        if (size != 8u + h->sa) return "a variable-length string of a wrong size";
        if ((why = check_dtype(h, m + 8, n - 8, depth + 1, &bu, &be))) return why;
        if ((m[8] & 0x0f) != 0 || be != 1) return "a variable-length string not of bytes";
        *used = 8 + bu;
        *elem = 8 + h->sa;   /* length, collection address, object index */
        return NULL;
    }
    default:
        return "a datatype edgespace does not read (not an integer, real or string)";
    }
}

/* ---- dataspaces (IV.A.2.b) ---------------------------------------------------- */
static const char *check_space(const hdr *h, const uint8_t *m, uint64_t n, uint64_t *used,
                               int *rank_out, uint64_t *npoints)
{
    unsigned version, rank, flags, at;
    uint64_t np = 1;
    bool null = false;
    if (n < 4) return "a truncated dataspace";
    version = m[0];
    rank = m[1];
    flags = m[2];
    if (version < 1 || version > 2 || rank > MAX_RANK || (flags & ~1u))
        return "a dataspace of an unknown version, a rank over 32 or unknown flags";
    if (version == 2) {
        if (m[3] > 2 || (m[3] != 1 && rank != 0) || (m[3] == 1 && rank == 0))
            return "a dataspace whose type and rank disagree";
        null = m[3] == 2;
        at = 4;
    } else {
        at = 8;
    }
    if (n < at + (uint64_t)rank * h->ss * ((flags & 1) ? 2 : 1))
        return "a dataspace shorter than its dimensions";
    for (unsigned k = 0; k < rank; k++) {
        uint64_t d = le(m + at + k * h->ss, h->ss);
        if (flags & 1) {
            uint64_t mx = le(m + at + (rank + k) * h->ss, h->ss);
            bool unlimited = h->ss == 8 ? mx == UINT64_MAX : mx == 0xffffffffu;
            if (!unlimited && d > mx) return "a dataspace larger than its maximum";
        }
        if (__builtin_mul_overflow(np, d, &np)) return "a dataspace of too many elements";
    }
    *used = at + (uint64_t)rank * h->ss * ((flags & 1) ? 2 : 1);
    *rank_out = (int)rank;
    *npoints = null ? 0 : np;
    return NULL;
}

/* ---- attributes (IV.A.2.m) -----------------------------------------------------
 * libhdf5 1.10 strdup()s the name wherever its NUL is and copies the value
 * at the size the datatype and dataspace claim, past the message if they
 * claim more (found by the store fuzzer on a changed byte of /topology's
 * header): the name ends inside the message, and datatype, dataspace and
 * value each lie inside it, of the kinds checked above. */
static uint64_t pad8(int version, uint64_t n) { return version == 1 ? (n + 7) & ~(uint64_t)7 : n; }

static int check_attr(hdr *h, const uint8_t *m, uint64_t n)
{
    uint64_t nsz, tsz, ssz, p, dt, ds, used, esize = 0, npoints = 0, value;
    const char *why;
    int v, rank;
    if (n < 9 || (v = m[0]) < 1 || v > 3 || (v > 1 && (m[1] & 3)))
        return bad(h, "a malformed or shared attribute");
    if (v == 3 && m[8] > 1) return bad(h, "an attribute name of an unknown character set");
    nsz = le(m + 2, 2);
    tsz = le(m + 4, 2);
    ssz = le(m + 6, 2);
    p = v == 3 ? 9 : 8;
    if (nsz == 0 || nsz > n - p || m[p + nsz - 1] != '\0')
        return bad(h, "an attribute whose name leaves its message");
    dt = p + pad8(v, nsz);
    ds = dt + pad8(v, tsz);
    p = ds + pad8(v, ssz);
    if (dt > n || tsz > n - dt || ds > n || ssz > n - ds || p > n)
        return bad(h, "an attribute whose parts leave its message");
    if ((why = check_dtype(h, m + dt, tsz, 0, &used, &esize)) || used > tsz ||
        (why = check_space(h, m + ds, ssz, &used, &rank, &npoints)) || used > ssz) {
        snprintf(h->whybuf, sizeof h->whybuf, "an attribute with %s",
                 why ? why : "a datatype or dataspace larger than its part");
        return bad(h, h->whybuf);
    }
    if (__builtin_mul_overflow(npoints, esize, &value) || value > n - p)
        return bad(h, "an attribute whose value is larger than its message");
    return 0;
}

/* ---- raw data: layout, fill value, filters (IV.A.2.i, f/e, l) --------------- */
static int check_layout(hdr *h, const uint8_t *m, uint64_t n)
{
    unsigned version, ndims, p;
    if (n < 2) return bad(h, "a truncated layout message");
    version = m[0];
    h->storage = UINT64_MAX;
    h->addr = UINT64_MAX;
    if (version == 1 || version == 2) {
        /* dimensionality, class, 5 reserved, [address], dims (4 bytes each),
         * [compact size and data] */
        if (n < 8) return bad(h, "a truncated layout message");
        ndims = m[1];
        h->layout = m[2];
        if (ndims < 1 || ndims > MAX_RANK + 1 || h->layout > 2 || (h->layout == 2 && ndims < 2))
            return bad(h, "a layout message of a wrong dimensionality or class");
        p = 8;
        if (h->layout != 0) {
            if (n < p + h->sa) return bad(h, "a truncated layout message");
            h->addr = le(m + p, h->sa);
            p += h->sa;
        }
        if (n < p + 4u * ndims) return bad(h, "a truncated layout message");
        h->chunk_ndims = ndims;
        for (unsigned k = 0; k < ndims; k++)
            if (h->layout == 2 && le(m + p + 4 * k, 4) == 0)
                return bad(h, "a chunked layout with a chunk dimension of 0");
        h->chunk_last = le(m + p + 4 * (ndims - 1), 4);
        p += 4 * ndims;
        if (h->layout == 0) {
            if (n < p + 4u || le(m + p, 4) > n - p - 4)
                return bad(h, "a compact layout whose data leaves its message");
            h->storage = le(m + p, 4);
        }
        return 0;
    }
    if (version != 3 && version != 4) return bad(h, "a layout message of an unknown version");
    h->layout = m[1];
    switch (h->layout) {
    case 0:   /* compact: size (2), data */
        if (n < 4 || le(m + 2, 2) > n - 4) return bad(h, "a compact layout whose data leaves "
                                                       "its message");
        h->storage = le(m + 2, 2);
        return 0;
    case 1:   /* contiguous: address, size */
        if (n < 2u + h->sa + h->ss) return bad(h, "a truncated layout message");
        h->addr = le(m + 2, h->sa);
        h->storage = le(m + 2 + h->sa, h->ss);
        return 0;
    case 2:
        break;
    default:
        return bad(h, "a layout edgespace does not read (virtual or unknown)");
    }
    if (version == 3) {
        /* dimensionality, B-tree address, dimensions (4 bytes each) */
        if (n < 3u + h->sa) return bad(h, "a truncated layout message");
        ndims = m[2];
        if (ndims < 2 || ndims > MAX_RANK + 1 || n < 3u + h->sa + 4u * ndims)
            return bad(h, "a chunked layout of a wrong dimensionality");
        if (!addr_ok(h, le(m + 3, h->sa), 1)) return bad(h, "a chunk index outside the file");
        for (unsigned k = 0; k < ndims; k++)
            if (le(m + 3 + h->sa + 4 * k, 4) == 0)
                return bad(h, "a chunked layout with a chunk dimension of 0");
        h->chunk_ndims = ndims;
        h->chunk_last = le(m + 3 + h->sa + 4 * (ndims - 1), 4);
        return 0;
    }
    /* version 4: flags, dimensionality, bytes per dimension, dimensions,
     * index type and its parameters, index address */
    {
        unsigned flags, enc, idx;
        uint64_t need;
        if (n < 5) return bad(h, "a truncated layout message");
        flags = m[2];
        ndims = m[3];
        enc = m[4];
        if ((flags & ~3u) || ndims < 2 || ndims > MAX_RANK + 1 || enc < 1 || enc > 8 ||
            n < 5u + (uint64_t)enc * ndims + 1)
            return bad(h, "a chunked layout of wrong flags, dimensionality or sizes");
        for (unsigned k = 0; k < ndims; k++)
            if (le(m + 5 + enc * k, enc) == 0)
                return bad(h, "a chunked layout with a chunk dimension of 0");
        h->chunk_ndims = ndims;
        h->chunk_last = le(m + 5 + enc * (ndims - 1), enc);
        p = 5 + enc * ndims;
        idx = m[p++];
        switch (idx) {
        case 1: need = (flags & 2) ? h->ss + 4u : 0; break;   /* single chunk */
        case 2: need = 0; break;                              /* implicit */
        case 3: need = 1; break;                              /* fixed array */
        case 4: need = 5; break;                              /* extensible array */
        case 5: need = 6; break;                              /* version 2 B-tree */
        default: return bad(h, "a chunk index of an unknown type");
        }
        if (idx == 3 && (m[p] < 1 || m[p] > 32)) return bad(h, "a fixed-array chunk index of "
                                                            "a wrong page size");
        if (idx == 4 && (p + 5 > n || !m[p] || m[p] > 64 || !m[p + 1] || !m[p + 2] ||
                         !m[p + 3] || !m[p + 4] || m[p + 4] > 32))
            return bad(h, "an extensible-array chunk index of wrong parameters");
        if (idx == 5 && (p + 6 > n || le(m + p, 4) < 64 || m[p + 4] > 100 || m[p + 5] > 100))
            return bad(h, "a B-tree chunk index of wrong parameters");
        if (n < p + need + h->sa) return bad(h, "a truncated layout message");
        if (!addr_ok(h, le(m + p + need, h->sa), 1))
            return bad(h, "a chunk index outside the file");
        return 0;
    }
}

/* The fill value: its size, recorded for the check against the datatype. */
static int check_fill(hdr *h, unsigned type, const uint8_t *m, uint64_t n)
{
    uint64_t at;
    bool has_value;
    if (type == 0x04) {   /* old fill value: size, value */
        at = 0;
        has_value = true;
    } else {
        if (n < 1) return bad(h, "a truncated fill value");
        if (m[0] == 1 || m[0] == 2) {
            /* allocation time, write time, defined, [size, value] */
            if (n < 4 || m[1] > 3 || m[2] > 2 || m[3] > 1)
                return bad(h, "a fill value of unknown times");
            at = 4;
            has_value = m[0] == 1 || m[3];
        } else if (m[0] == 3) {
            /* flags: allocation time, write time, undefined, defined */
            if (n < 2 || (m[1] & 0xc0) || (m[1] & 3) > 3 || ((m[1] >> 2) & 3) > 2 ||
                ((m[1] & 0x10) && (m[1] & 0x20)))
                return bad(h, "a fill value of unknown flags");
            at = 2;
            has_value = (m[1] & 0x20) != 0;
        } else {
            return bad(h, "a fill value of an unknown version");
        }
    }
    if (!has_value) return 0;
    if (n < at + 4 || le(m + at, 4) > n - at - 4)
        return bad(h, "a fill value larger than its message");
    h->fill = le(m + at, 4);
    return 0;
}

/* The filter pipeline: deflate, shuffle and Fletcher-32 only (what h5py and
 * HDF5's own tools write for compressed stores; the others' parameters drive
 * buffer arithmetic in HDF5's filters). */
static int check_pline(hdr *h, const uint8_t *m, uint64_t n)
{
    unsigned version, nf;
    uint64_t p;
    if (n < 2) return bad(h, "a truncated filter pipeline");
    version = m[0];
    nf = m[1];
    if ((version != 1 && version != 2) || nf < 1 || nf > 32)
        return bad(h, "a filter pipeline of an unknown version or count");
    p = version == 1 ? 8 : 2;
    for (unsigned k = 0; k < nf; k++) {
        uint64_t id, namelen = 0, ncd;
        if (p + 2 > n) return bad(h, "a truncated filter pipeline");
        id = le(m + p, 2);
        p += 2;
        if (version == 1 || id >= 256) {
            if (p + 2 > n) return bad(h, "a truncated filter pipeline");
            namelen = le(m + p, 2);
            p += 2;
        }
        if (p + 4 > n) return bad(h, "a truncated filter pipeline");
        ncd = le(m + p + 2, 2);
        p += 4;
        if (version == 1) namelen = (namelen + 7) & ~(uint64_t)7;
        if (namelen > n - p) return bad(h, "a filter name that leaves its message");
        p += namelen;
        if (ncd > (n - p) / 4) return bad(h, "filter parameters that leave their message");
        if ((id == 1 && (ncd != 1 || le(m + p, 4) > 9)) ||
            (id == 2 && (ncd > 1 || (ncd == 1 && le(m + p, 4) == 0))) || (id == 3 && ncd != 0) ||
            id < 1 || id > 3)
            return bad(h, "a filter edgespace does not read (deflate, shuffle and Fletcher-32 "
                       "are read)");
        p += 4 * ncd + (version == 1 && (ncd & 1) ? 4 : 0);
        if (p > n) return bad(h, "filter parameters that leave their message");
    }
    return 0;
}

/* ---- groups (IV.A.2.c, g, r, v; links in the header) ------------------------- */

/* Link info and attribute info: creation order fields, then the fractal
 * heap and B-tree addresses of dense storage, which must be undefined:
 * links and attributes are read from the header only. */
static int check_dense_info(hdr *h, const uint8_t *m, uint64_t n, unsigned order_bytes,
                            const char *what)
{
    uint64_t p;
    if (n < 2 || m[0] != 0 || (m[1] & ~3u)) return bad(h, what);
    p = 2 + ((m[1] & 1) ? order_bytes : 0);
    if (n < p + 2u * h->sa + ((m[1] & 2) ? h->sa : 0)) return bad(h, what);
    if (!undefined(h, le(m + p, h->sa)))
        return bad(h, order_bytes == 8 ? "links in dense storage, which edgespace does not read"
                                       : "attributes in dense storage, which edgespace does "
                                         "not read");
    return 0;
}

/* A link: hard links only (a soft link is a path HDF5 resolves, an
 * external one opens another file). */
static int check_link(hdr *h, const uint8_t *m, uint64_t n)
{
    unsigned flags;
    uint64_t p = 2, lsize, len;
    if (n < 2 || m[0] != 1 || ((flags = m[1]) & ~0x1fu)) return bad(h, "a malformed link");
    if (flags & 0x08) {
        if (n < 3 || m[2] != 0) return bad(h, "a soft or external link, which edgespace does "
                                              "not follow");
        p++;
    }
    if (flags & 0x04) p += 8;
    if (flags & 0x10) {
        if (p >= n || m[p] > 1) return bad(h, "a link name of an unknown character set");
        p++;
    }
    lsize = 1u << (flags & 3);
    if (p + lsize > n) return bad(h, "a malformed link");
    len = le(m + p, (unsigned)lsize);
    p += lsize;
    if (len == 0 || len > n - p || n - p - len < h->sa ||
        !addr_ok(h, le(m + p + len, h->sa), 1))
        return bad(h, "a link whose name or object leaves its message or the file");
    return 0;
}

static int check_msg(void *ud, unsigned type, unsigned flags, const uint8_t *m, uint64_t n)
{
    hdr *h = ud;
    uint64_t used = 0;
    const char *why = NULL;
    if ((flags & MSG_SHARED) && type != 0x00)
        return bad(h, "a shared message, which edgespace does not read");
    switch (type) {
    case 0x00: return 0;                                          /* NIL */
    case 0x01:                                                    /* dataspace */
        h->nspace++;
        why = check_space(h, m, n, &used, &h->rank, &h->npoints);
        break;
    case 0x03:                                                    /* datatype */
        h->ntype++;
        why = check_dtype(h, m, n, 0, &used, &h->elem);
        break;
    case 0x04: case 0x05:                                         /* fill value */
        h->nfill++;
        return check_fill(h, type, m, n);
    case 0x08:                                                    /* layout */
        h->nlayout++;
        return check_layout(h, m, n);
    case 0x0B:                                                    /* filters */
        h->npline++;
        return check_pline(h, m, n);
    case 0x0C: return check_attr(h, m, n);                        /* attribute */
    case 0x0D:                                                    /* comment */
        return n > 0 && memchr(m, '\0', (size_t)n) ? 0 : bad(h, "an unterminated comment");
    case 0x0E: return n >= 14 ? 0 : bad(h, "a truncated modification time");
    case 0x12: return n >= 8 && m[0] == 1 ? 0 : bad(h, "a malformed modification time");
    case 0x16: return n >= 5 && m[0] == 0 ? 0 : bad(h, "a malformed reference count");
    case 0x15: return check_dense_info(h, m, n, 2, "a malformed attribute info message");
    case 0x02:                                                    /* link info */
        h->nlinfo++;
        return check_dense_info(h, m, n, 8, "a malformed link info message");
    case 0x06: h->ngroup++; return check_link(h, m, n);
    case 0x0A:                                                    /* group info */
        h->ngroup++;
        return n >= 2 && m[0] == 0 && !(m[1] & ~3u) &&
                       n >= 2u + ((m[1] & 1) ? 4 : 0) + ((m[1] & 2) ? 4 : 0)
                   ? 0
                   : bad(h, "a malformed group info message");
    case 0x11:                                                    /* symbol table */
        h->nstab++;
        return n >= 2u * h->sa && addr_ok(h, le(m, h->sa), 1) &&
                       addr_ok(h, le(m + h->sa, h->sa), 1)
                   ? 0
                   : bad(h, "a symbol table outside the file");
    case 0x07: return bad(h, "data in external files, which edgespace does not read");
    case 0x13:                                                    /* B-tree 'K' values */
        return h->superblock_ext && n >= 7 && m[0] == 0 ? 0 : bad(h, "a misplaced B-tree K message");
    case 0x17:                                                    /* file space info */
        return h->superblock_ext && n >= 2 && m[0] <= 1 ? 0
                                                         : bad(h, "a misplaced file space message");
    default:
        snprintf(h->whybuf, sizeof h->whybuf, "a message of type %u, which edgespace does not "
                 "read", type);
        return bad(h, h->whybuf);
    }
    if (why) return bad(h, why);
    if (used > n) return bad(h, "a message shorter than its contents");
    return 0;
}

/* The messages against each other: a dataset has one dataspace, datatype
 * and layout, whose chunks have one dimension more than the dataspace and
 * the element's size as the last, whose stored bytes are those of its
 * elements, and whose fill value is one element; a group has none of them. */
static const char *check_whole(hdr *h)
{
    uint64_t bytes;
    bool dataset = h->nspace || h->ntype || h->nlayout || h->nfill || h->npline;
    if (!dataset) return h->nstab > 1 || h->nlinfo > 1 ? "two symbol tables" : NULL;
    if (h->nstab || h->nlinfo || h->ngroup) return "both group and dataset messages";
    if (h->nspace != 1 || h->ntype != 1 || h->nlayout != 1 || h->npline > 1)
        return h->nlayout == 0 && h->nspace == 0 ? "a named datatype, which edgespace does not "
                                                   "read"
                                                 : "not one dataspace, datatype and layout";
    if (h->nfill > 1) return "two fill values";
    if (h->fill && h->fill != h->elem) return "a fill value that is not one element";
    if (__builtin_mul_overflow(h->npoints, h->elem, &bytes)) return "too many bytes of data";
    if (h->layout == 2) {
        if (h->chunk_ndims != (unsigned)h->rank + 1 || h->chunk_last != h->elem)
            return "chunks of another rank or element size than the dataset";
        return NULL;
    }
    if (h->npline) return "filters on data that is not chunked";
    if (h->layout == 0 && h->storage != bytes)
        return "compact data of another size than the dataset";
    if (h->layout == 1) {
        if (h->storage != UINT64_MAX && h->storage != bytes)
            return "contiguous data of another size than the dataset";
        if (h->addr != UINT64_MAX && !addr_ok(h, h->addr, bytes))
            return "contiguous data past the end of the file";
    }
    return NULL;
}

static es_status check_header(es__h5_raw *raw, uint64_t oaddr, const char *name, int ext)
{
    es_ctx *ctx = es__h5_raw_ctx(raw);
    hdr h;
    es_status rc;
    const char *why;
    memset(&h, 0, sizeof h);
    h.superblock_ext = ext;
    h.r = raw;
    h.sa = es__h5_raw_addr_size(raw);
    h.ss = es__h5_raw_length_size(raw);
    h.rank = -1;
    h.storage = h.addr = UINT64_MAX;
    rc = es__h5_raw_messages(raw, oaddr, check_msg, &h);
    if (rc == ES_ENOTFOUND) rc = ES_OK;   /* every message walked */
    if (rc == ES_EFORMAT)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' is corrupt: %s has %s (object header at %llu)",
                es__h5_raw_path(raw), name, h.why ? h.why : "a malformed object header",
                (unsigned long long)oaddr);
    if (rc != ES_OK) return rc;
    if ((why = check_whole(&h)))
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' is corrupt: %s has %s (object header at %llu)",
                es__h5_raw_path(raw), name, why, (unsigned long long)oaddr);
    return ES_OK;
}

es_status es__h5_check_header(es__h5_raw *raw, uint64_t oaddr, const char *name)
{
    return check_header(raw, oaddr, name, 0);
}

/* ---- the superblock (III.A.1), read before HDF5 opens the file ------------------ */

static es_status sb_fail(es_ctx *ctx, const char *path, const char *why)
{
    ES_FAIL(ctx, ES_EFORMAT, "store: '%s' is corrupt: %s", path, why);
}

es_status es__h5_check_file(es_ctx *ctx, const char *path)
{
    static const uint8_t sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    uint8_t b[96];
    uint64_t at = 0, size, root, ext = UINT64_MAX;
    unsigned version, sa, ss, p;
    es__h5_raw *raw = NULL;
    es_status rc = ES_OK;
    struct stat st;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0 || fstat(fd, &st) != 0) {
        rc = es__fail(ctx, ES_EIO, "store: cannot read '%s': %s", path, strerror(errno));
        goto done;
    }
    size = (uint64_t)st.st_size;
    /* the signature at 0, 512, 1024, 2048, ... (a user block before it) */
    for (;; at = at ? 2 * at : 512) {
        if (at + sizeof b > size) {
            rc = sb_fail(ctx, path, "no HDF5 superblock");
            goto done;
        }
        if (pread(fd, b, sizeof b, (off_t)at) != (ssize_t)sizeof b) {
            rc = es__fail(ctx, ES_EIO, "store: cannot read '%s': %s", path, strerror(errno));
            goto done;
        }
        if (!memcmp(b, sig, 8)) break;
    }
    version = b[8];
    if (version <= 1) {
        sa = b[13];
        ss = b[14];
        p = version == 0 ? 24 : 28;          /* base, free space, end of file, driver, */
        if (sa != 4 && sa != 8) {             /* then the root's symbol table entry */
            rc = sb_fail(ctx, path, "a superblock of an unusual address size");
            goto done;
        }
        root = le(b + p + 5 * sa, sa);
    } else if (version == 2 || version == 3) {
        sa = b[9];
        ss = b[10];
        if (sa != 4 && sa != 8) {
            rc = sb_fail(ctx, path, "a superblock of an unusual address size");
            goto done;
        }
        ext = le(b + 12 + sa, sa);
        root = le(b + 12 + 3 * sa, sa);
    } else {
        rc = sb_fail(ctx, path, "a superblock of an unknown version");
        goto done;
    }
    if ((rc = es__h5_raw_open_fd(ctx, fd, path, at, sa, ss, &raw)) != ES_OK) goto done;
    rc = check_header(raw, root, "the root group", 0);
    if (rc == ES_OK && ext != UINT64_MAX && !(sa == 4 && ext == 0xffffffffu))
        rc = check_header(raw, ext, "the superblock extension", 1);
done:
    es__h5_raw_close(raw);
    if (fd >= 0) close(fd);
    return rc;
}

es_status es__h5_check_object(es__h5_raw *raw, hid_t obj, const char *name)
{
    uint64_t oaddr;
    es_status rc = es__h5_object_addr(es__h5_raw_ctx(raw), obj, &oaddr);
    return rc ? rc : es__h5_check_header(raw, oaddr, name);
}

/* The address comes from the link (H5Lget_info), not from the object:
 * HDF5 loading a header allocates what its chunks claim (a changed byte of
 * a continuation message made it allocate 21 GB before refusing), and the
 * raw walk checks every chunk against the file first. */
es_status es__h5_check_named(es__h5_raw *raw, hid_t loc, const char *name)
{
    es_ctx *ctx = es__h5_raw_ctx(raw);
    uint64_t addr;
#if H5_VERSION_GE(1, 12, 0)
    H5L_info2_t li;
    haddr_t a = HADDR_UNDEF;
    if (H5Lget_info2(loc, name, &li, H5P_DEFAULT) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: '%s': %s is missing or unreadable",
                           es__h5_raw_path(raw), name);
    if (li.type == H5L_TYPE_HARD && H5VLnative_token_to_addr(loc, li.u.token, &a) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: '%s': %s is unreadable",
                           es__h5_raw_path(raw), name);
    addr = a;
#else
    H5L_info_t li;
    if (H5Lget_info(loc, name, &li, H5P_DEFAULT) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: '%s': %s is missing or unreadable",
                           es__h5_raw_path(raw), name);
    addr = li.u.address;
#endif
    if (li.type != H5L_TYPE_HARD)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s': %s is a soft or external link, which edgespace "
                "does not follow", es__h5_raw_path(raw), name);
    return es__h5_check_header(raw, addr, name);
}
