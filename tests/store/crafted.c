/* tests/store/crafted.c — see crafted.h. Every mutation starts from the
 * base store's own bytes and changes one thing with the HDF5 API (or, for
 * the heap, its bytes), so each variant isolates one disagreement. */
#include "crafted.h"

#include "edgespace/edgespace.h"

#include <hdf5.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { V = 4, F = 4, E = 6, N = 3 };
static const int64_t faces[3 * F] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
static const int64_t edges[2 * E] = {0, 1, 0, 2, 0, 3, 1, 2, 1, 3, 2, 3};

int crafted_make_legacy(const char *path)
{
    const int64_t two = 2;
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT), a = -1;
    int bad = f < 0;
    if (!bad && H5Aexists(f, "store_id") > 0) bad |= H5Adelete(f, "store_id") < 0;
    if (!bad) bad |= (a = H5Aopen(f, "format_version", H5P_DEFAULT)) < 0 ||
                     H5Awrite(a, H5T_NATIVE_INT64, &two) < 0;
    if (a >= 0) H5Aclose(a);
    if (f >= 0) H5Fclose(f);
    return bad ? -1 : 0;
}

int crafted_base(const char *path)
{
    static const double base[3 * V] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    double xyz[3 * V * N], len[E * N], scale[N];
    const char *ids[N] = {"r0", "r1", "r2"}, *cols[2] = {"grp", "subj"};
    const char *labels[2 * N] = {"a", "s1", "b", "s1", "a", "s2"};
    const char *groups[2] = {"a", "b"};
    const int64_t counts[2] = {2, 1};
    es_ctx *ctx = NULL;
    es_mesh *mesh = NULL;
    es_store *s = NULL;
    int bad = 1;
    for (int i = 0; i < N; i++) {
        double sum = 0;
        for (int k = 0; k < 3 * V; k++) xyz[3 * V * i + k] = base[k] * (1 + 0.1 * i + (k == 3) * 0.2 * i);
        for (int e = 0; e < E; e++) {
            const double *a = xyz + 3 * V * i + 3 * edges[2 * e];
            const double *b = xyz + 3 * V * i + 3 * edges[2 * e + 1];
            double d2 = 0;
            for (int q = 0; q < 3; q++) d2 += (a[q] - b[q]) * (a[q] - b[q]);
            sum += len[E * i + e] = sqrt(d2);
        }
        for (int e = 0; e < E; e++) len[E * i + e] /= sum;
        scale[i] = sum;
    }
    es_store_rows r = {N, ids, NULL, NULL, len, scale, xyz, 2, cols, labels};
    es_provenance prov = {"crafted", NULL, -1, "k=1"};
    remove(path);
    if (es_ctx_new(&ctx) != ES_OK) return -1;
    /* a version-2 store (results inside it): the layout this suite crafts;
     * results beside a version-3 store are crafted by test_store_results */
    if (es_mesh_new(ctx, V, F, faces, base, &mesh) == ES_OK &&
        es_store_create(ctx, path, mesh, &s) == ES_OK && es_store_append(ctx, s, &r) == ES_OK &&
        es_store_commit(ctx, s) == ES_OK && (es_store_close(s), s = NULL, 1) &&
        crafted_make_legacy(path) == 0 &&
        es_store_open(ctx, path, ES_STORE_WRITE, &s) == ES_OK &&
        es_store_result_begin(ctx, s, "mean", "m", &prov) == ES_OK &&
        es_store_put_matrix(ctx, s, "mean/m/means", (es_mat){len, E, 2, E}) == ES_OK &&
        es_store_put_ints(ctx, s, "mean/m/counts", counts, 2) == ES_OK &&
        es_store_put_strings(ctx, s, "mean/m/groups", groups, 2) == ES_OK &&
        es_store_put_attr(ctx, s, "mean/m", "by", "grp") == ES_OK &&
        es_store_commit(ctx, s) == ES_OK)
        bad = 0;
    if (bad) fprintf(stderr, "crafted_base: %s\n", es_ctx_errmsg(ctx));
    es_store_close(s);
    es_mesh_free(mesh);
    es_ctx_free(ctx);
    return bad ? -1 : 0;
}

int crafted_message_ok(const char *m)
{
    return m && *m && !strchr(m, '\n') && !strstr(m, "()") && !strstr(m, "HDF5-DIAG");
}

int crafted_read_all(es_ctx *ctx, es_store *s)
{
    int64_t n = es_store_nrows(s), ne = es_store_nedges(s), nv = es_store_nverts(s);
    int64_t Fn = es_store_nfaces(s), *iv = NULL, ni = 0, *sel = NULL, ns = 0;
    double *buf = calloc((size_t)(ne * (n + 1) + 3 * nv + n + 1), sizeof *buf), *v = NULL;
    int64_t *ib = calloc((size_t)(3 * Fn + 2 * ne + 1), sizeof *ib);
    es_mat m = {0};
    es_mesh *mesh = NULL;
    char attr[256], **names = NULL;
    int bad = 0;
#define TRY(call) do { if (!bad && (call) != ES_OK && !crafted_message_ok(es_ctx_errmsg(ctx))) \
        bad = 1; } while (0)
    if (!buf || !ib) {
        free(buf);
        free(ib);
        return 0;
    }
    if (ne > 0 && n > 0) TRY(es_store_read_lengths(ctx, s, 0, n, (es_mat){buf, ne, n, ne}));
    if (ne > 0) TRY(es_store_read_scales(ctx, s, buf));
    for (int64_t i = 0; i < n; i++) TRY(es_store_read_positions(ctx, s, i, buf));
    TRY(es_store_read_faces(ctx, s, ib));
    TRY(es_store_read_edges(ctx, s, ib + 3 * Fn));
    if (Fn > 0) {
        TRY(es_store_mesh(ctx, s, &mesh));
        es_mesh_free(mesh);
    }
    TRY(es_store_select(ctx, s, "grp=a", &sel, &ns));
    es_free(ctx, sel);
    TRY(es_store_get_matrix(ctx, s, "mean/m/means", &m));
    es_free(ctx, m.data);
    TRY(es_store_get_vector(ctx, s, "mean/m/means", &v, &ni));
    es_free(ctx, v);
    TRY(es_store_get_ints(ctx, s, "mean/m/counts", &iv, &ni));
    es_free(ctx, iv);
    iv = NULL;
    TRY(es_store_get_ints(ctx, s, "mean/m/input_rows", &iv, &ni));
    es_free(ctx, iv);
    TRY(es_store_get_attr(ctx, s, "mean/m", "command", attr, sizeof attr));
    TRY(es_store_get_attr(ctx, s, "mean/m", "store_nrows", attr, sizeof attr));
    ni = 0;
    if (es_store_list_results(ctx, s, NULL, &names, &ni) == ES_OK) {
        for (int64_t i = 0; i < ni; i++) es_free(ctx, names[i]);
        es_free(ctx, names);
    } else if (!crafted_message_ok(es_ctx_errmsg(ctx))) {
        bad = 1;
    }
    for (int64_t c = 0; c < es_store_ncolumns(s); c++)
        for (int64_t i = 0; i < n; i++)
            if (!es_store_label(s, i, c)) bad = 1;
#undef TRY
    free(buf);
    free(ib);
    return bad ? -1 : 0;
}

/* ---- HDF5 helpers: each replaces what it writes ------------------------- */

static void del_link(hid_t f, const char *path)
{
    if (H5Lexists(f, path, H5P_DEFAULT) > 0) H5Ldelete(f, path, H5P_DEFAULT);
}

static void del_attr(hid_t f, const char *obj, const char *name)
{
    if (H5Aexists_by_name(f, obj, name, H5P_DEFAULT) > 0)
        H5Adelete_by_name(f, obj, name, H5P_DEFAULT);
}

static hid_t str_type(void)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    return t;
}

/* An attribute of n (0: scalar) values of type mtype (stored as ftype). */
static int put_attr(hid_t f, const char *obj, const char *name, hid_t ftype, hid_t mtype,
                    int n, const void *v)
{
    hsize_t d = (hsize_t)n;
    hid_t o = H5Oopen(f, obj, H5P_DEFAULT), sp, a;
    int rc = -1;
    if (o < 0) return -1;
    del_attr(f, obj, name);
    sp = n ? H5Screate_simple(1, &d, NULL) : H5Screate(H5S_SCALAR);
    a = H5Acreate2(o, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT);
    if (a >= 0 && H5Awrite(a, mtype, v) >= 0) rc = 0;
    if (a >= 0) H5Aclose(a);
    H5Sclose(sp);
    H5Oclose(o);
    return rc;
}

static int put_attr_i64(hid_t f, const char *obj, const char *name, int n, const int64_t *v)
{
    return put_attr(f, obj, name, H5T_STD_I64LE, H5T_NATIVE_INT64, n, v);
}

static int put_attr_strs(hid_t f, const char *obj, const char *name, int n,
                         const char *const *v)
{
    hid_t t = str_type();
    int rc = put_attr(f, obj, name, t, t, n, n ? (const void *)v : (const void *)&v[0]);
    H5Tclose(t);
    return rc;
}

/* Layouts of a recreated dataset. */
enum { CONTIG, CHUNKED, COMPACT, DEFLATE };

/* Replace dataset path by one of type ftype (data in mtype), rank dims. */
static int put_ds(hid_t f, const char *path, hid_t ftype, hid_t mtype, int rank,
                  const hsize_t *dims, const void *data, int layout)
{
    hsize_t maxd[3], chunk[3];
    hid_t sp, dcpl = H5Pcreate(H5P_DATASET_CREATE), ds;
    int rc = -1;
    for (int k = 0; k < rank; k++) {
        maxd[k] = k == 0 && layout != CONTIG && layout != COMPACT ? H5S_UNLIMITED : dims[k];
        chunk[k] = dims[k] ? dims[k] : 1;
    }
    if (layout == CHUNKED || layout == DEFLATE) {
        H5Pset_chunk(dcpl, rank, chunk);
        if (layout == DEFLATE) H5Pset_deflate(dcpl, 6);
    } else if (layout == COMPACT) {
        H5Pset_layout(dcpl, H5D_COMPACT);
    }
    del_link(f, path);
    sp = H5Screate_simple(rank, dims, maxd);
    ds = H5Dcreate2(f, path, ftype, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds >= 0 && (!data || H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0))
        rc = 0;
    if (ds >= 0) H5Dclose(ds);
    H5Sclose(sp);
    H5Pclose(dcpl);
    return rc;
}

static int put_strs(hid_t f, const char *path, int n, const char *const *v, int layout)
{
    hsize_t d = (hsize_t)n;
    hid_t t = str_type();
    int rc = put_ds(f, path, t, t, 1, &d, v, layout);
    H5Tclose(t);
    return rc;
}

/* Read a whole int64 or double dataset into buf (at most cap values). */
static int64_t get_ds(hid_t f, const char *path, hid_t mtype, void *buf, int64_t cap,
                      hsize_t *dims, int *rank)
{
    hid_t ds = H5Dopen2(f, path, H5P_DEFAULT), sp;
    int64_t n = 1;
    if (ds < 0) return -1;
    sp = H5Dget_space(ds);
    *rank = H5Sget_simple_extent_dims(sp, dims, NULL);
    for (int k = 0; k < *rank; k++) n *= (int64_t)dims[k];
    if (n > cap || H5Dread(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) n = -1;
    H5Sclose(sp);
    H5Dclose(ds);
    return n;
}

/* Rows claimed without data: a chunked dataset's extent grown to rows. */
static int extend(hid_t f, const char *path, hsize_t rows)
{
    hid_t ds = H5Dopen2(f, path, H5P_DEFAULT), sp;
    hsize_t d[3];
    int rank, rc = -1;
    if (ds < 0) return -1;
    sp = H5Dget_space(ds);
    rank = H5Sget_simple_extent_dims(sp, d, NULL);
    H5Sclose(sp);
    /* only ever grown: shrinking makes libhdf5 look up every chunk of the
     * old extent (H5D__chunk_prune_by_extent), which after an earlier
     * mutation claimed 2^40 rows hung the generator (found by fuzz_crafted) */
    if (rank > 0 && rows >= d[0]) {
        d[0] = rows;
        if (H5Dset_extent(ds, d) >= 0) rc = 0;
    }
    H5Dclose(ds);
    return rc;
}

/* Change one int64 or double element (flat index) of a dataset. */
static int poke(hid_t f, const char *path, hid_t mtype, int64_t at, const void *v)
{
    int64_t buf[256];
    hsize_t dims[3];
    int rank;
    int64_t n = get_ds(f, path, mtype, buf, 256, dims, &rank);
    hid_t ds;
    int rc = -1;
    if (n < 1) return -1;
    memcpy((char *)buf + (size_t)(at % n) * 8, v, 8);
    if ((ds = H5Dopen2(f, path, H5P_DEFAULT)) < 0) return -1;
    if (H5Dwrite(ds, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0) rc = 0;
    H5Dclose(ds);
    return rc;
}

/* ---- the mutations ---------------------------------------------------- */

#define REFUSE CRAFTED_REFUSE
#define OPEN CRAFTED_OPEN
#define ANY CRAFTED_ANY

const crafted_mutation crafted_mutations[] = {
    {"version missing", REFUSE, "not an edgespace store", 1},
    {"version a string", REFUSE, "format_version", 1},
    {"version an array", REFUSE, "format_version", 1},
    {"version value", REFUSE, "format version", 4},
    {"kind bad", REFUSE, "topology_kind", 4},
    {"nverts missing", REFUSE, "nverts", 1},
    {"nverts value", REFUSE, NULL, 6},
    {"nverts type", REFUSE, "nverts", 3},
    {"fingerprint an integer", ANY, NULL, 1},
    {"faces missing", REFUSE, "/topology/faces", 1},
    {"faces shape", REFUSE, "/topology/faces", 3},
    {"faces type", REFUSE, "/topology/faces", 2},
    {"faces index", REFUSE, "/topology/faces", 4},
    {"faces rows claimed", REFUSE, "/topology/faces", 1},
    {"edges missing", REFUSE, "/topology/edges", 1},
    {"edges shape", REFUSE, "/topology/edges", 2},
    {"edges unsorted", REFUSE, "/topology/edges", 1},
    {"edges repeated", REFUSE, "/topology/edges", 1},
    {"edges reversed", REFUSE, "/topology/edges", 1},
    {"edges range", REFUSE, "/topology/edges", 2},
    {"edges one dropped", REFUSE, NULL, 1},
    {"lengths missing", REFUSE, "/shapes/lengths", 1},
    {"lengths width", REFUSE, "/shapes/lengths", 1},
    {"lengths rows", REFUSE, "/shapes/lengths", 1},
    {"lengths integers", REFUSE, "/shapes/lengths", 1},
    {"every row claimed 20 M times", REFUSE, "claims", 1},
    {"lengths rows claimed", REFUSE, "claims", 1},
    {"scales missing", REFUSE, "/shapes/scales", 1},
    {"scales rows", REFUSE, "/shapes/scales", 1},
    {"scales value", REFUSE, "/shapes/scales", 4},
    {"positions missing", REFUSE, "/shapes/positions", 1},
    {"positions shape", REFUSE, "/shapes/positions", 3},
    {"ids missing", REFUSE, "/shapes/ids", 1},
    {"ids rows", REFUSE, "/shapes/ids", 2},
    {"ids empty", REFUSE, "/shapes/ids", 1},
    {"ids repeated", REFUSE, "repeats", 1},
    {"ids integers", REFUSE, "/shapes/ids", 1},
    {"ids fixed-length", OPEN, NULL, 1},
    {"ids contiguous", OPEN, NULL, 1},
    {"ids compact", REFUSE, "compact", 1},
    {"ids compressed", REFUSE, "compressed", 1},
    {"source_paths rows", REFUSE, "/shapes/source_paths", 1},
    {"content_hash missing", REFUSE, "/shapes/content_hash", 1},
    {"columns missing", REFUSE, "columns", 1},
    {"columns name a missing dataset", REFUSE, "/labels/nope", 1},
    {"columns repeated", REFUSE, "twice", 1},
    {"columns bad name", REFUSE, "bad name", 3},
    {"columns integers", REFUSE, "columns", 1},
    {"label rows", REFUSE, "/labels/grp", 1},
    {"label integers", REFUSE, "/labels/grp", 1},
    {"truss with faces", REFUSE, "topology kind 'truss'", 1},
    {"shapes group missing", REFUSE, "/shapes/", 1},
    {"result matrix claimed", ANY, NULL, 1},
    {"result matrix strings", ANY, NULL, 1},
    {"result attribute an integer", ANY, NULL, 1},
    {"result input_rows out of range", ANY, NULL, 1},
    {"result store_nrows negative", ANY, NULL, 1},
    {"heap object size", ANY, NULL, 8},
    {"heap object index", ANY, NULL, 8},
    {"heap collection size", ANY, NULL, 4},
    {"heap free space of size 0", ANY, NULL, 1},
    {"string length", ANY, NULL, 4},
    {"group local heap free list loops", REFUSE, "local heap", 1},
    {"group local heap free block too big", REFUSE, "local heap", 1},
    {"group B-tree child points up", REFUSE, "B-tree", 1},
    {"group link name outside its heap", REFUSE, "outside its local heap", 1},
    {"attribute value larger than its message", REFUSE, "/topology has an attribute", 2},
    {"positions chunks larger than the dataset", REFUSE, "the chunks of /shapes/positions", 1},
};
const int crafted_nmutations = (int)(sizeof crafted_mutations / sizeof crafted_mutations[0]);

/* Heap mutations: bytes of the file's global heap collections ("GCOL"),
 * object headers at 16 + 24 k (index 2 bytes, refcount 2, reserved 4,
 * size 8, data padded to 8; the first object starts at 16). */
static int patch_heap(const char *path, int what, uint32_t p)
{
    FILE *fp = fopen(path, "r+b");
    unsigned char *b;
    long n;
    int done = 0;
    if (!fp) return -1;
    fseek(fp, 0, SEEK_END);
    n = ftell(fp);
    rewind(fp);
    if (n <= 0 || !(b = malloc((size_t)n))) { fclose(fp); return -1; }
    if (fread(b, 1, (size_t)n, fp) != (size_t)n) { free(b); fclose(fp); return -1; }
    for (long i = 0; i + 32 < n; i++) {
        if (memcmp(b + i, "GCOL", 4)) continue;
        unsigned char *obj = b + i + 16;
        /* walk to object p % 8 of this collection */
        for (uint32_t k = 0; k < p % 8 && obj + 16 < b + n; k++) {
            uint64_t sz = 0;
            for (int q = 7; q >= 0; q--) sz = sz << 8 | obj[8 + q];
            if (sz > (uint64_t)n) break;
            obj += 16 + ((sz + 7) & ~(uint64_t)7);
        }
        if (obj + 16 >= b + n) continue;
        if (what == 0) {                        /* object size */
            uint64_t big = (p & 1) ? 0x7fffffffffffffffull : 4096 + p;
            for (int q = 0; q < 8; q++) obj[8 + q] = (unsigned char)(big >> (8 * q));
        } else if (what == 1) {                 /* object index */
            obj[0] = (unsigned char)(p * 37 + 1);
            obj[1] = (unsigned char)(p & 1 ? 0xff : 0);
        } else if (what == 2) {                 /* collection size */
            uint64_t big = (p & 1) ? 0xffffffffffffull : 17 + p;
            for (int q = 0; q < 8; q++) b[i + 8 + q] = (unsigned char)(big >> (8 * q));
        } else {                                /* a free-space object of size 0 */
            obj[0] = obj[1] = 0;
            memset(obj + 8, 0, 8);
        }
        done = 1;
    }
    rewind(fp);
    if (fwrite(b, 1, (size_t)n, fp) != (size_t)n) done = 0;
    free(b);
    fclose(fp);
    return done ? 0 : -1;
}

/* Group symbol tables (HDF5 III.A.1, III.B, III.D), patched in every group
 * of the file: a local heap whose free list loops (libhdf5 1.10 follows it
 * until memory runs out) or has a block past the heap, a B-tree node whose
 * first child is itself (libhdf5 recurses without end), a symbol whose name
 * offset is past the heap. Addresses and lengths are 8 bytes, base 0. */
static int patch_groups(const char *path, int what)
{
    FILE *fp = fopen(path, "r+b");
    unsigned char *b;
    long n;
    int done = 0;
    if (!fp) return -1;
    fseek(fp, 0, SEEK_END);
    n = ftell(fp);
    rewind(fp);
    if (n <= 0 || !(b = malloc((size_t)n))) { fclose(fp); return -1; }
    if (fread(b, 1, (size_t)n, fp) != (size_t)n) { free(b); fclose(fp); return -1; }
#define PUT8(at, v) do { uint64_t v_ = (v); for (int q_ = 0; q_ < 8; q_++) \
        b[(at) + q_] = (unsigned char)(v_ >> (8 * q_)); } while (0)
#define GET8(at) (((uint64_t)b[(at)] | (uint64_t)b[(at) + 1] << 8 | (uint64_t)b[(at) + 2] << 16 | \
        (uint64_t)b[(at) + 3] << 24 | (uint64_t)b[(at) + 4] << 32 | (uint64_t)b[(at) + 5] << 40 | \
        (uint64_t)b[(at) + 6] << 48 | (uint64_t)b[(at) + 7] << 56))
    for (long i = 0; i + 48 < n; i++) {
        if (what <= 1 && !memcmp(b + i, "HEAP", 4) && b[i + 4] == 0) {
            uint64_t dsize = GET8(i + 8), data = GET8(i + 24);
            if (dsize < 48 || data + dsize > (uint64_t)n) continue;
            PUT8(i + 16, 16);                          /* the free list starts at 16 */
            PUT8(data + 16, what == 0 ? 16 : 1);       /* next: itself, or the end */
            PUT8(data + 24, what == 0 ? 16 : dsize);   /* size: 16, or past the heap */
            done = 1;
        } else if (what == 2 && !memcmp(b + i, "TREE", 4) && b[i + 4] == 0) {
            PUT8(i + 24 + 8, (uint64_t)i);             /* child 0 (after key 0) = this node */
            b[i + 5] = 0;                              /* a leaf: its children are symbol nodes */
            done = 1;
        } else if (what == 3 && !memcmp(b + i, "SNOD", 4) && b[i + 4] == 1 &&
                   (b[i + 6] | b[i + 7] << 8) > 0) {
            PUT8(i + 8, 0xffffffull);                  /* the first symbol's name offset */
            done = 1;
        }
    }
#undef PUT8
#undef GET8
    rewind(fp);
    if (fwrite(b, 1, (size_t)n, fp) != (size_t)n) done = 0;
    free(b);
    fclose(fp);
    return done ? 0 : -1;
}

/* The nverts attribute of /topology claims more than its message holds:
 * its datatype's element size (variant 0) or its dataspace's rank (1).
 * In a version 1 attribute message the name is padded to 8 bytes and the
 * datatype follows it (8 bytes of header, the size in bytes 4..7). */
static int patch_attribute(const char *path, uint32_t p)
{
    FILE *fp = fopen(path, "r+b");
    unsigned char *b;
    long n;
    int done = 0;
    if (!fp) return -1;
    fseek(fp, 0, SEEK_END);
    n = ftell(fp);
    rewind(fp);
    if (n <= 0 || !(b = malloc((size_t)n))) { fclose(fp); return -1; }
    if (fread(b, 1, (size_t)n, fp) != (size_t)n) { free(b); fclose(fp); return -1; }
    for (long i = 8; i + 40 < n && !done; i++) {
        if (memcmp(b + i, "nverts", 7) || b[i - 8] != 1 || b[i - 6] != 7) continue;
        unsigned tsz = b[i - 4] | b[i - 3] << 8;
        if (p == 0) {
            b[i + 8 + 5] = 0x10;                   /* 8 -> 4104 bytes an element */
        } else {
            unsigned char *ds = b + i + 8 + ((tsz + 7) & ~7u);
            ds[1] = 1;                             /* scalar -> one dimension */
            memset(ds + 8, 0xff, 4);               /* of about 4 G elements */
            ds[12] = ds[13] = ds[14] = ds[15] = 0;
        }
        done = 1;
    }
    rewind(fp);
    if (fwrite(b, 1, (size_t)n, fp) != (size_t)n) done = 0;
    free(b);
    fclose(fp);
    return done ? 0 : -1;
}

/* The layout message of /shapes/positions (version 3, chunked, 4 chunk
 * dimensions after the B-tree address: 64 rows, V = 4, 3, 8 bytes) claims
 * chunks of 6147 coordinates where the dataset has 3. */
static int patch_layout(const char *path)
{
    static const unsigned char dims[16] = {64, 0, 0, 0, V, 0, 0, 0, 3, 0, 0, 0, 8, 0, 0, 0};
    FILE *fp = fopen(path, "r+b");
    unsigned char *b;
    long n;
    int done = 0;
    if (!fp) return -1;
    fseek(fp, 0, SEEK_END);
    n = ftell(fp);
    rewind(fp);
    if (n <= 0 || !(b = malloc((size_t)n))) { fclose(fp); return -1; }
    if (fread(b, 1, (size_t)n, fp) != (size_t)n) { free(b); fclose(fp); return -1; }
    for (long i = 0; i + 27 < n && !done; i++)
        if (b[i] == 3 && b[i + 1] == 2 && b[i + 2] == 4 && !memcmp(b + i + 11, dims, 16)) {
            b[i + 11 + 8] = 0x03;
            b[i + 11 + 9] = 0x18;
            done = 1;
        }
    rewind(fp);
    if (fwrite(b, 1, (size_t)n, fp) != (size_t)n) done = 0;
    free(b);
    fclose(fp);
    return done ? 0 : -1;
}

/* A string dataset's descriptor lengths: the first row of /shapes/ids
 * claims p-dependent bytes; the descriptors are the chunk's first bytes. */
static int patch_string_length(hid_t f, const char *path, uint32_t p)
{
    hid_t ds = H5Dopen2(f, "/shapes/ids", H5P_DEFAULT);
    haddr_t a = HADDR_UNDEF;
    hsize_t off = 0, size = 0;
    unsigned mask = 0;
    if (ds < 0) return -1;
    H5Dget_chunk_info_by_coord(ds, &off, &mask, &a, &size);
    H5Dclose(ds);
    if (a == HADDR_UNDEF) return -1;
    H5Fclose(f);
    FILE *fp = fopen(path, "r+b");
    uint32_t lens[4] = {0, 1, 0xffffffffu, 3};
    uint32_t v = lens[p % 4];
    unsigned char le[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                           (unsigned char)(v >> 24)};
    int rc = -1;
    if (fp && fseek(fp, (long)a, SEEK_SET) == 0 && fwrite(le, 1, 4, fp) == 4) rc = 0;
    if (fp) fclose(fp);
    return rc;
}

static int mutate(hid_t f, const char *path, int k, uint32_t p, int *closed)
{
    const char *name = crafted_mutations[k].name;
    int64_t i64[64];
    double d[64];
    hsize_t dims[3];
    int rank;
#define IS(s) (!strcmp(name, s))
    if (IS("version missing")) { del_attr(f, "/", "format_version"); return 0; }
    if (IS("version a string")) {
        const char *v[1] = {"1"};
        return put_attr_strs(f, "/", "format_version", 0, v);
    }
    if (IS("version an array")) {
        const int64_t v[2] = {1, 1};
        return put_attr_i64(f, "/", "format_version", 2, v);
    }
    if (IS("version value")) {
        const int64_t v[4] = {0, 3, -1, INT64_MAX};
        return put_attr_i64(f, "/", "format_version", 0, &v[p]);
    }
    if (IS("kind bad")) {
        const int64_t two = 2, seven = 7;
        const char *v[2] = {p == 0 ? "blob" : "", "mesh"};
        if (put_attr_i64(f, "/", "format_version", 0, &two)) return -1;
        if (p < 2) return put_attr_strs(f, "/", "topology_kind", 0, v);
        if (p == 2) return put_attr_i64(f, "/", "topology_kind", 0, &seven);
        v[0] = "mesh";
        return put_attr_strs(f, "/", "topology_kind", 2, v);
    }
    if (IS("nverts missing")) { del_attr(f, "/topology", "nverts"); return 0; }
    if (IS("nverts value")) {
        const int64_t v[6] = {0, -5, 3, 5, INT64_MAX, (int64_t)1 << 40};
        return put_attr_i64(f, "/topology", "nverts", 0, &v[p]);
    }
    if (IS("nverts type")) {
        const char *s[1] = {"4"};
        const double four = 4;
        const int64_t v[2] = {4, 4};
        if (p == 0) return put_attr_strs(f, "/topology", "nverts", 0, s);
        if (p == 1)
            return put_attr(f, "/topology", "nverts", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0,
                            &four);
        return put_attr_i64(f, "/topology", "nverts", 2, v);
    }
    if (IS("fingerprint an integer")) {
        const int64_t v = 12345;
        return put_attr_i64(f, "/topology", "fingerprint", 0, &v);
    }
    if (IS("faces missing")) { del_link(f, "/topology/faces"); return 0; }
    if (IS("faces shape")) {
        hsize_t d1[1] = {3 * F}, d4[2] = {3, 4}, d2[2] = {6, 2};
        if (p == 0) return put_ds(f, "/topology/faces", H5T_STD_I64LE, H5T_NATIVE_INT64, 1, d1, faces, CONTIG);
        if (p == 1) return put_ds(f, "/topology/faces", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, d4, faces, CONTIG);
        return put_ds(f, "/topology/faces", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, d2, faces, CONTIG);
    }
    if (IS("faces type")) {
        hsize_t d2[2] = {F, 3};
        for (int i = 0; i < 3 * F; i++) d[i] = (double)faces[i];
        if (p == 0) return put_ds(f, "/topology/faces", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d2, d, CONTIG);
        const char *s[3 * F];
        for (int i = 0; i < 3 * F; i++) s[i] = "1";
        hid_t t = str_type();
        int rc = put_ds(f, "/topology/faces", t, t, 2, d2, s, CONTIG);
        H5Tclose(t);
        return rc;
    }
    if (IS("faces index")) {
        /* past the vertices, negative, far out, a corner repeated */
        const int64_t v[4] = {V, -1, (int64_t)1e12, 2};
        return poke(f, "/topology/faces", H5T_NATIVE_INT64, p == 3 ? 0 : 5, &v[p]);
    }
    if (IS("faces rows claimed")) {
        hsize_t d2[2] = {F, 3};
        return put_ds(f, "/topology/faces", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, d2, faces, CHUNKED) ||
               extend(f, "/topology/faces", (hsize_t)1 << 33);
    }
    if (IS("edges missing")) { del_link(f, "/topology/edges"); return 0; }
    if (IS("edges shape")) {
        hsize_t d3[2] = {4, 3}, d1[1] = {2 * E};
        if (p == 0) return put_ds(f, "/topology/edges", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, d3, edges, CONTIG);
        return put_ds(f, "/topology/edges", H5T_STD_I64LE, H5T_NATIVE_INT64, 1, d1, edges, CONTIG);
    }
    if (IS("edges unsorted") || IS("edges repeated") || IS("edges reversed") || IS("edges range")) {
        hsize_t d2[2] = {E, 2};
        memcpy(i64, edges, sizeof edges);
        if (IS("edges unsorted")) { int64_t t0 = i64[0], t1 = i64[1]; i64[0] = i64[2]; i64[1] = i64[3]; i64[2] = t0; i64[3] = t1; }
        if (IS("edges repeated")) { i64[2] = i64[0]; i64[3] = i64[1]; }
        if (IS("edges reversed")) { int64_t t = i64[4]; i64[4] = i64[5]; i64[5] = t; }
        if (IS("edges range")) i64[11] = p ? -1 : V;
        return put_ds(f, "/topology/edges", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, d2, i64, CONTIG);
    }
    if (IS("edges one dropped")) {
        hsize_t d2[2] = {E - 1, 2};
        return put_ds(f, "/topology/edges", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, d2, edges + 2, CONTIG);
    }
    if (IS("lengths missing")) { del_link(f, "/shapes/lengths"); return 0; }
    if (IS("lengths width") || IS("lengths rows") || IS("lengths integers")) {
        hsize_t dw[2] = {N, E + 1}, dr[2] = {N + 1, E}, di[2] = {N, E};
        for (int i = 0; i < 64; i++) d[i] = 0.1, i64[i] = 1;
        if (IS("lengths width")) return put_ds(f, "/shapes/lengths", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, dw, d, CHUNKED);
        if (IS("lengths rows")) return put_ds(f, "/shapes/lengths", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, dr, d, CHUNKED);
        return put_ds(f, "/shapes/lengths", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, di, i64, CHUNKED);
    }
    if (IS("every row claimed 20 M times")) {
        static const char *const all[] = {"/shapes/lengths", "/shapes/scales", "/shapes/positions",
                                          "/shapes/ids", "/shapes/source_paths",
                                          "/shapes/content_hash", "/labels/grp", "/labels/subj"};
        for (int i = 0; i < 8; i++)
            if (extend(f, all[i], 20000000)) return -1;
        return 0;
    }
    if (IS("lengths rows claimed")) return extend(f, "/shapes/lengths", (hsize_t)1 << 40);
    if (IS("scales missing")) { del_link(f, "/shapes/scales"); return 0; }
    if (IS("scales rows")) {
        hsize_t d1[1] = {N - 1};
        const double v[2] = {1, 1};
        return put_ds(f, "/shapes/scales", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, d1, v, CHUNKED);
    }
    if (IS("scales value")) {
        const double v[4] = {NAN, -1, 0, INFINITY};
        return poke(f, "/shapes/scales", H5T_NATIVE_DOUBLE, 1, &v[p]);
    }
    if (IS("positions missing")) { del_link(f, "/shapes/positions"); return 0; }
    if (IS("positions shape")) {
        hsize_t d2[3] = {N, V, 2}, dv[3] = {N, V + 1, 3}, dr[2] = {N, 3 * V};
        for (int i = 0; i < 64; i++) d[i] = 0.5;
        if (p == 0) return put_ds(f, "/shapes/positions", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 3, d2, d, CHUNKED);
        if (p == 1) return put_ds(f, "/shapes/positions", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 3, dv, d, CHUNKED);
        return put_ds(f, "/shapes/positions", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, dr, d, CHUNKED);
    }
    if (IS("ids missing")) { del_link(f, "/shapes/ids"); return 0; }
    if (IS("ids rows")) {
        const char *v[N + 1] = {"r0", "r1", "r2", "r3"};
        return put_strs(f, "/shapes/ids", p ? N + 1 : N - 1, v, CHUNKED);
    }
    if (IS("ids empty")) {
        const char *v[N] = {"r0", "", "r2"};
        return put_strs(f, "/shapes/ids", N, v, CHUNKED);
    }
    if (IS("ids repeated")) {
        const char *v[N] = {"r0", "r1", "r0"};
        return put_strs(f, "/shapes/ids", N, v, CHUNKED);
    }
    if (IS("ids integers")) {
        hsize_t d1[1] = {N};
        const int64_t v[N] = {0, 1, 2};
        return put_ds(f, "/shapes/ids", H5T_STD_I64LE, H5T_NATIVE_INT64, 1, d1, v, CHUNKED);
    }
    if (IS("ids fixed-length")) {
        hsize_t d1[1] = {N};
        hid_t t = H5Tcopy(H5T_C_S1);
        H5Tset_size(t, 3);
        int rc = put_ds(f, "/shapes/ids", t, t, 1, d1, "r0\0r1\0r2", CHUNKED);
        H5Tclose(t);
        return rc;
    }
    if (IS("ids contiguous") || IS("ids compact") || IS("ids compressed")) {
        const char *v[N] = {"r0", "r1", "r2"};
        return put_strs(f, "/shapes/ids", N, v,
                        IS("ids contiguous") ? CONTIG : IS("ids compact") ? COMPACT : DEFLATE);
    }
    if (IS("source_paths rows")) {
        const char *v[N] = {"a", "b", "c"};
        return put_strs(f, "/shapes/source_paths", N - 1, v, CHUNKED);
    }
    if (IS("content_hash missing")) { del_link(f, "/shapes/content_hash"); return 0; }
    if (IS("columns missing")) { del_attr(f, "/labels", "columns"); return 0; }
    if (IS("columns name a missing dataset")) {
        const char *v[3] = {"grp", "subj", "nope"};
        return put_attr_strs(f, "/labels", "columns", 3, v);
    }
    if (IS("columns repeated")) {
        const char *v[2] = {"grp", "grp"};
        return put_attr_strs(f, "/labels", "columns", 2, v);
    }
    if (IS("columns bad name")) {
        const char *bad[3] = {"a/b", "", ".."};
        const char *v[2] = {"grp", bad[p]};
        return put_attr_strs(f, "/labels", "columns", 2, v);
    }
    if (IS("columns integers")) {
        const int64_t v[2] = {1, 2};
        return put_attr_i64(f, "/labels", "columns", 2, v);
    }
    if (IS("label rows")) {
        const char *v[N + 1] = {"a", "b", "a", "c"};
        return put_strs(f, "/labels/grp", N + 1, v, CHUNKED);
    }
    if (IS("label integers")) {
        hsize_t d1[1] = {N};
        const int64_t v[N] = {0, 1, 2};
        return put_ds(f, "/labels/grp", H5T_STD_I64LE, H5T_NATIVE_INT64, 1, d1, v, CHUNKED);
    }
    if (IS("truss with faces")) {
        const int64_t two = 2;
        const char *v[1] = {"truss"};
        return put_attr_i64(f, "/", "format_version", 0, &two) ||
               put_attr_strs(f, "/", "topology_kind", 0, v);
    }
    if (IS("shapes group missing")) { del_link(f, "/shapes"); return 0; }
    if (IS("result matrix claimed")) {
        hsize_t d2[2] = {2, E};
        for (int i = 0; i < 64; i++) d[i] = 0.25;
        return put_ds(f, "/analysis/mean/m/means", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 2, d2, d, CHUNKED) ||
               extend(f, "/analysis/mean/m/means", (hsize_t)1 << 31);
    }
    if (IS("result matrix strings")) {
        const char *v[2] = {"x", "y"};
        return put_strs(f, "/analysis/mean/m/means", 2, v, CONTIG);
    }
    if (IS("result attribute an integer")) {
        const int64_t v = 7;
        return put_attr_i64(f, "/analysis/mean/m", "command", 0, &v);
    }
    if (IS("result input_rows out of range")) {
        hsize_t d1[1] = {3};
        const int64_t v[3] = {-1, 99, INT64_MAX};
        return put_ds(f, "/analysis/mean/m/input_rows", H5T_STD_I64LE, H5T_NATIVE_INT64, 1, d1, v, CONTIG);
    }
    if (IS("result store_nrows negative")) {
        const int64_t v = -3;
        return put_attr_i64(f, "/analysis/mean/m", "store_nrows", 0, &v);
    }
    if (IS("string length")) {
        *closed = 1;
        return patch_string_length(f, path, p);
    }
    (void)dims;
    (void)rank;
#undef IS
    return -1;
}

int crafted_patches_bytes(int k)
{
    const char *name = k >= 0 && k < crafted_nmutations ? crafted_mutations[k].name : "";
    if (!strcmp(name, "string length")) return 1;   /* finds its chunk with HDF5 */
    return !strncmp(name, "heap ", 5) || !strncmp(name, "group ", 6) ||
           !strncmp(name, "attribute ", 10) || !strncmp(name, "positions chunks", 16) ? 2 : 0;
}

int crafted_apply(const char *path, int k, uint32_t param)
{
    const crafted_mutation *m;
    int rc = -1, closed = 0;
    hid_t f;
    if (k < 0 || k >= crafted_nmutations) return -1;
    m = &crafted_mutations[k];
    param %= (uint32_t)(m->nparams > 0 ? m->nparams : 1);
    if (!strncmp(m->name, "attribute ", 10)) return patch_attribute(path, param);
    if (!strcmp(m->name, "positions chunks larger than the dataset")) return patch_layout(path);
    if (!strncmp(m->name, "group ", 6)) {
        int what = strstr(m->name, "loops") ? 0 : strstr(m->name, "too big") ? 1 :
                   strstr(m->name, "B-tree") ? 2 : 3;
        return patch_groups(path, what);
    }
    if (!strncmp(m->name, "heap ", 5)) {
        int what = !strcmp(m->name, "heap object size") ? 0 :
                   !strcmp(m->name, "heap object index") ? 1 :
                   !strcmp(m->name, "heap collection size") ? 2 : 3;
        return patch_heap(path, what, param);
    }
    H5E_BEGIN_TRY {
        f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
        if (f >= 0) {
            rc = mutate(f, path, k, param, &closed);
            if (!closed && H5Fclose(f) < 0) rc = -1;
        }
    } H5E_END_TRY
    return rc;
}
