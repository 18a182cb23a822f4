/* lib/h5/h5_groups.c — the groups of a store checked before HDF5
 * looks a name up in them.
 *
 * An old-style HDF5 group (what every edgespace store, and h5py by default,
 * writes) keeps its links in a symbol table: a version 1 B-tree whose leaves
 * are symbol nodes ("SNOD"), each entry naming its link by an offset into
 * the group's local heap ("HEAP"). libhdf5 1.10 trusts all of it: a local
 * heap whose free list loops is followed until memory runs out (three
 * changed bytes of a store made `info` take 24 GB and be killed), and a
 * B-tree child may point anywhere, back up the tree included. This walks
 * the symbol table with every offset, size and count checked against the
 * heap and the file, each node's level one below its parent's and a bound
 * on the nodes, before HDF5 uses it (HDF5 File Format Specification 3.0,
 * III.A.1 B-trees, III.B symbol nodes, III.D local heaps, IV.A.2.r the
 * symbol table message). The messages of the group's own header are
 * checked by h5_headers.c.
 */
#include "h5/h5_pkg.h"

enum { MAX_NODES = 100000, MAX_LEVEL = 32 };

typedef struct stab {
    es__h5_raw *r;
    const char *name;       /* the group, for messages */
    uint64_t btree, heap;   /* from the symbol table message */
    int found;
    unsigned sa, ss;
    uint8_t *heapdata;      /* the local heap's data segment */
    uint64_t dsize;
    int64_t nodes;
} stab;

static int find_stab(void *ud, unsigned type, unsigned flags, const uint8_t *m, uint64_t n)
{
    stab *t = ud;
    (void)flags;
    if (type != 0x11) return 0;
    if (n < 2u * t->sa) return -1;
    t->btree = es__h5_le(m, t->sa);
    t->heap = es__h5_le(m + t->sa, t->sa);
    t->found = 1;
    return 1;
}

static es_status corrupt(stab *t, const char *what, uint64_t at)
{
    ES_FAIL(es__h5_raw_ctx(t->r), ES_EFORMAT, "store: '%s' is corrupt: the group %s has %s "
            "(at %llu)", es__h5_raw_path(t->r), t->name, what, (unsigned long long)at);
}

/* The local heap: its data segment loaded, its free list walked with each
 * block inside the segment and the walk bounded (a loop is corrupt). */
static es_status load_heap(stab *t)
{
    es_ctx *ctx = es__h5_raw_ctx(t->r);
    const unsigned ss = t->ss, sa = t->sa;
    uint8_t pre[48];
    uint64_t free_at, data_at, nfree = 0;
    es_status rc;
    if ((rc = es__h5_raw_read(t->r, t->heap, 8 + 2 * ss + sa, pre, "a local heap")))
        return rc;
    if (memcmp(pre, "HEAP", 4) || pre[4] != 0) return corrupt(t, "no local heap", t->heap);
    t->dsize = es__h5_le(pre + 8, ss);
    free_at = es__h5_le(pre + 8 + ss, ss);
    data_at = es__h5_le(pre + 8 + 2 * ss, sa);
    /* (against the file before it is allocated: a claim of 1.2 GB cost 38 s
     * under ASan, found by the store fuzzer) */
    if (t->dsize == 0 || t->dsize > ((uint64_t)1 << 32) || t->dsize > es__h5_raw_file_size(t->r))
        return corrupt(t, "a local heap of a wrong size", t->heap);
    if (!(t->heapdata = es__malloc(ctx, (size_t)t->dsize + 1))) return ES_ENOMEM;
    if ((rc = es__h5_raw_read(t->r, data_at, t->dsize, t->heapdata, "a local heap")))
        return rc;
    t->heapdata[t->dsize] = '\0';
    /* free blocks: (next offset, size) each; 1 ends the list */
    while (free_at != 1) {
        uint64_t size;
        if (t->dsize < 2 * ss || free_at > t->dsize - 2 * ss || ++nfree > t->dsize / (2 * ss))
            return corrupt(t, "a local heap whose free list leaves it or loops", t->heap);
        size = es__h5_le(t->heapdata + free_at + ss, ss);
        if (size < 2 * ss || size > t->dsize - free_at)
            return corrupt(t, "a local heap free block of a wrong size", t->heap);
        free_at = es__h5_le(t->heapdata + free_at, ss);
    }
    return ES_OK;
}

/* A name in the heap: an offset inside it, NUL-terminated before its end. */
static int name_ok(const stab *t, uint64_t off)
{
    return off < t->dsize && memchr(t->heapdata + off, '\0', (size_t)(t->dsize - off));
}

/* The node at addr: of level want_level (-1: any, the root; -2: a symbol
 * node, below level 0). */
static es_status walk(stab *t, uint64_t addr, int want_level)
{
    es_ctx *ctx = es__h5_raw_ctx(t->r);
    const unsigned sa = t->sa, ss = t->ss;
    uint8_t head[8 + 2 * 8], *b = NULL;
    uint64_t n, bytes;
    es_status rc;
    int level;
    if (++t->nodes > MAX_NODES) return corrupt(t, "a B-tree of too many nodes (a loop?)", addr);
    if ((rc = es__h5_raw_read(t->r, addr, 8, head, "a B-tree node"))) return rc;
    if (!memcmp(head, "SNOD", 4)) {
        /* a symbol node: entries of (name offset, object header, cache type,
         * reserved, scratch pad) */
        const uint64_t esz = ss + sa + 24;
        if (want_level != -2 || head[4] != 1) return corrupt(t, "a misplaced symbol node", addr);
        n = es__h5_le(head + 6, 2);
        bytes = n * esz;
        if (!(b = es__malloc(ctx, (size_t)bytes + 1))) return ES_ENOMEM;
        if ((rc = es__h5_raw_read(t->r, addr + 8, bytes, b, "a symbol node"))) goto done;
        for (uint64_t i = 0; i < n && rc == ES_OK; i++)
            if (!name_ok(t, es__h5_le(b + i * esz, ss)))
                rc = corrupt(t, "a link name outside its local heap", addr);
        goto done;
    }
    if (memcmp(head, "TREE", 4) || head[4] != 0)
        return corrupt(t, "no group B-tree node", addr);
    level = head[5];
    n = es__h5_le(head + 6, 2);
    if (want_level == -2 || (want_level >= 0 && level != want_level) || level > MAX_LEVEL)
        return corrupt(t, "a B-tree node at the wrong level", addr);
    /* after the siblings: key 0, then (child, key) pairs */
    bytes = (n + 1) * ss + n * sa;
    if (!(b = es__malloc(ctx, (size_t)bytes + 1))) return ES_ENOMEM;
    if ((rc = es__h5_raw_read(t->r, addr + 8 + 2 * sa, bytes, b, "a B-tree node"))) goto done;
    for (uint64_t i = 0; i <= n && rc == ES_OK; i++)
        if (!name_ok(t, es__h5_le(b + i * (ss + sa), ss)))
            rc = corrupt(t, "a B-tree key outside its local heap", addr);
    for (uint64_t i = 0; i < n && rc == ES_OK; i++) {
        uint64_t child = es__h5_le(b + ss + i * (ss + sa), sa);
        /* level 0 points at symbol nodes (-2), level k at nodes of level
         * k - 1: the recursion is at most MAX_LEVEL deep */
        rc = walk(t, child, level > 0 ? level - 1 : -2);
    }
done:
    es__free(ctx, b);
    return rc;
}

es_status es__h5_check_group(es__h5_raw *raw, hid_t group, const char *name)
{
    es_ctx *ctx = es__h5_raw_ctx(raw);
    stab t = {raw, name, 0, 0, 0, es__h5_raw_addr_size(raw), es__h5_raw_length_size(raw),
              NULL, 0, 0};
    uint64_t oaddr;
    es_status rc;
    if ((rc = es__h5_object_addr(ctx, group, &oaddr))) return rc;
    rc = es__h5_raw_messages(raw, oaddr, find_stab, &t);
    if (rc == ES_ENOTFOUND) return ES_OK;   /* links in the header: nothing to follow */
    if (rc == ES_OK && (rc = load_heap(&t)) == ES_OK) rc = walk(&t, t.btree, -1);
    es__free(ctx, t.heapdata);
    return rc;
}

es_status es__h5_check_groups(es__h5_raw *raw, hid_t file, const char *const *names, size_t n)
{
    es_status rc = es__h5_check_object(raw, file, "the root group");
    if (rc == ES_OK) rc = es__h5_check_group(raw, file, "/");
    for (size_t i = 0; rc == ES_OK && i < n; i++) {
        hid_t g;
        if (H5Lexists(file, names[i], H5P_DEFAULT) <= 0) continue;   /* said later */
        if ((rc = es__h5_check_named(raw, file, names[i])) != ES_OK) break;
        if ((g = H5Gopen2(file, names[i], H5P_DEFAULT)) < 0) continue;
        rc = es__h5_check_group(raw, g, names[i]);
        H5Gclose(g);
    }
    return rc;
}
