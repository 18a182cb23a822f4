/* lib/ingest/ingest.c — meshes (and a manifest's labels) into an HDF5 store.
 *
 * All-or-nothing, in bounded memory. Inputs go through in blocks of rows
 * (about 64 MB of positions and lengths, or es_ingest_opts.block_rows).
 * Each block is read and checked: the file's bytes (hashed for duplicate
 * detection, then parsed from the buffer so the file is read once), its
 * vertex count and face list against the store's (or the first input's, for
 * a new store), and its normalized edge lengths (es_edge_lengths,
 * es_lengths_normalize; Section 4, eq. 12 of Rojas et al.). Its rows are
 * then appended to the store's working copy, and the block's memory serves
 * the next block: memory does not grow with the number of inputs beyond a
 * few dozen bytes of ids and hashes per row. Only after the last block is
 * the copy committed, by an atomic rename (lib/store/store_publish.c); any
 * failure, or a kill at any moment, leaves the store as it was.
 */
#include "core/core_private.h"
#include "core/files.h"
#include "core/hash.h"
#include "core/strmap.h"
#include "mesh/mesh_private.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_ingest.h"
#include "edgespace/es_io.h"
#include "edgespace/es_mesh.h"
#include "edgespace/es_store.h"

#include <pthread.h>
#include <stdatomic.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

void es_ingest_opts_init(es_ingest_opts *opts)
{
    memset(opts, 0, sizeof *opts);
    opts->create = 1;
    opts->format = ES_FORMAT_AUTO;
}

void es_content_hash(const void *buf, size_t len, char out[25])
{
    char hex[17];
    es__hex16(es__fnv1a64(ES__FNV_OFFSET, buf, len), hex);
    snprintf(out, 25, "fnv1a64:%s", hex);
}

/* One input: where to read it, its id and (manifest) label row. */
typedef struct input {
    const char *id;
    const char *path;           /* path to open */
    const char *const *labels;  /* ncols values or NULL */
} input;

/* Read a whole mesh file into *buf (grown as needed and reused across
 * files, so that one buffer's pages serve every input). A missing file is
 * ES_ENOTFOUND; anything but a regular file is refused. */
static es_status slurp(es_ctx *ctx, const char *path, char **buf, size_t *cap, size_t *len)
{
    return es__read_file_reuse(ctx, path, ES__READ_REGULAR | ES__READ_NOTFOUND, buf, cap, len);
}

/* What reading produces: the current block's values, one slot per input
 * of the block (slot = input - first input of the block), and per input
 * (all n, a few bytes each) the content hash and whether it is skipped. */
typedef struct batch {
    int64_t cap, V, E;
    double *xyz, *len, *scale;   /* 3V x cap, E x cap, cap */
    char (*hash)[25];            /* content hash per input */
    uint8_t *skip;               /* 1: already in the store, same content */
} batch;

static void batch_free(es_ctx *ctx, batch *b)
{
    es__free(ctx, b->xyz);
    es__free(ctx, b->len);
    es__free(ctx, b->scale);
    es__free(ctx, b->hash);
    es__free(ctx, b->skip);
}

/* Ask for transparent huge pages on the page-aligned middle of a large
 * buffer: first touch of tens of MB then costs hundreds of page faults
 * instead of thousands (it dominated the CPU time of this phase on a VM). A
 * hint only: nothing depends on it. */
static void hint_huge_pages(void *p, size_t bytes)
{
#ifdef MADV_HUGEPAGE
    long page = sysconf(_SC_PAGESIZE);
    uintptr_t a = (uintptr_t)p, b = a + bytes;
    if (!p || page <= 0 || bytes < ((size_t)4 << 20)) return;
    a = (a + (uintptr_t)page - 1) & ~((uintptr_t)page - 1);
    b &= ~((uintptr_t)page - 1);
    if (b > a) madvise((void *)a, b - a, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

/* Uninitialized arrays (every kept slot is written in full): calloc would
 * touch tens of MB of pages only to overwrite them. */
static void *alloc_uninit(es_ctx *ctx, int64_t a, int64_t b, size_t elem)
{
    int64_t n;
    size_t bytes;
    void *p;
    if (!es__mul_i64(a, b, &n) || n < 0 || !es__mul_size((size_t)n, elem, &bytes)) {
        es__fail(ctx, ES_ENOMEM, "ingest: %lld x %lld values are too many", (long long)a,
                 (long long)b);
        return NULL;
    }
    p = es__malloc(ctx, bytes);
    hint_huge_pages(p, bytes);
    return p;
}

/* Rows per block: opts->block_rows, or about 64 MB of positions and
 * lengths; never fewer than the threads that fill it, nor more than n. */
static int64_t block_rows(const es_ingest_opts *o, int64_t n, int64_t nthreads, int64_t V,
                          int64_t E)
{
    int64_t per = (3 * V + E) * (int64_t)sizeof(double);
    int64_t b = o->block_rows > 0 ? o->block_rows : ((int64_t)64 << 20) / (per > 0 ? per : 1);
    if (o->block_rows <= 0 && b < nthreads) b = nthreads;
    if (b > n) b = n;
    return b < 1 ? 1 : b;
}

static es_status batch_alloc(es_ctx *ctx, batch *b, int64_t cap, int64_t n, int64_t V,
                             int64_t E)
{
    b->cap = cap;
    b->V = V;
    b->E = E;
    if (!(b->xyz = alloc_uninit(ctx, 3 * V, cap, sizeof(double))) ||
        !(b->len = alloc_uninit(ctx, E, cap, sizeof(double))) ||
        !(b->scale = alloc_uninit(ctx, cap, 1, sizeof(double))) ||
        !(b->hash = alloc_uninit(ctx, n, 1, sizeof *b->hash)) ||
        !(b->skip = es__alloc_array(ctx, n, 1)))
        return ES_ENOMEM;
    return ES_OK;
}

/* The first face where two face lists differ, or -1. */
static int64_t first_diff_face(const int64_t *a, const int64_t *b, int64_t nfaces)
{
    if (!memcmp(a, b, (size_t)nfaces * 3 * sizeof *a)) return -1;
    for (int64_t f = 0; f < nfaces; f++)
        if (a[3 * f] != b[3 * f] || a[3 * f + 1] != b[3 * f + 1] || a[3 * f + 2] != b[3 * f + 2])
            return f;
    return -1;
}

typedef struct ref {
    es_mesh *mesh;
    const int64_t *faces;
    int64_t V, F;
    char what[600];       /* "the store 's.h5'" or "the first input 'a.obj'" */
} ref;

static es_status check_topology(es_ctx *ctx, const ref *r, const char *path,
                                const es_meshdata *md)
{
    int64_t f;
    if (md->nverts != r->V)
        ES_FAIL(ctx, ES_EMISMATCH, "'%s' has %lld vertices, %s has %lld: not in "
                "correspondence", path, (long long)md->nverts, r->what, (long long)r->V);
    if (md->nfaces != r->F)
        ES_FAIL(ctx, ES_EMISMATCH, "'%s' has %lld faces, %s has %lld: not in correspondence",
                path, (long long)md->nfaces, r->what, (long long)r->F);
    if ((f = first_diff_face(md->faces, r->faces, r->F)) >= 0)
        ES_FAIL(ctx, ES_EMISMATCH, "'%s': connectivity differs from %s at face %lld: "
                "(%lld %lld %lld) instead of (%lld %lld %lld) (0-based face and vertex "
                "indices)", path, r->what, (long long)f, (long long)md->faces[3 * f],
                (long long)md->faces[3 * f + 1], (long long)md->faces[3 * f + 2],
                (long long)r->faces[3 * f], (long long)r->faces[3 * f + 1],
                (long long)r->faces[3 * f + 2]);
    return ES_OK;
}

/* ---- phase 1, possibly on several threads ------------------------------
 * Inputs are handed out by an atomic counter. Each worker has its own
 * context (the main thread's worker uses the caller's), a reused read
 * buffer, and writes only its inputs' slots of the batch. The store handle
 * is only read (ids, hashes in memory). An error is kept for the lowest
 * failing input, so the message is the one a serial run would give;
 * warnings are collected and replayed in input order on the caller's
 * context after the join. */

typedef struct note { int64_t index, seq; char *msg; } note;

/* Input order, and the order of arrival within an input. */
static int cmp_note(const void *a, const void *b)
{
    const note *x = a, *y = b;
    if (x->index != y->index) return x->index < y->index ? -1 : 1;
    return x->seq < y->seq ? -1 : x->seq > y->seq;
}

typedef struct job {
    const input *in;
    int64_t n;                  /* end of the current block */
    int64_t slot0;              /* its first input: slot 0 of the batch */
    const ref *r;
    const es_store *st;
    const es_ingest_opts *o;
    batch *b;
    atomic_llong next, done;
    pthread_mutex_t mu;
    int64_t err_index;          /* lowest failing input, all inputs' count if none */
    es_status err_rc;
    char err_msg[1200];
    note *notes;                /* warnings (malloc'd, main ctx not touched) */
    int64_t nnotes, capnotes;
    int64_t bytes_read;
    int64_t ntotal;             /* inputs in all (progress) */
} job;

typedef struct worker {
    job *j;
    es_ctx *ctx;                /* own context, or the caller's (worker 0) */
    bool main;
    es_ctx *main_ctx;
    int64_t current;            /* input being processed, for warnings */
} worker;

static void on_worker_log(void *ud, es_log_level level, const char *msg)
{
    worker *w = ud;
    job *j = w->j;
    char *copy = malloc(strlen(msg) + 1);
    (void)level;
    if (!copy) return;
    strcpy(copy, msg);
    pthread_mutex_lock(&j->mu);
    if (j->nnotes == j->capnotes) {
        int64_t cap = j->capnotes ? 2 * j->capnotes : 16;
        note *p = realloc(j->notes, (size_t)cap * sizeof *p);
        if (!p) {
            pthread_mutex_unlock(&j->mu);
            free(copy);
            return;
        }
        j->notes = p;
        j->capnotes = cap;
    }
    j->notes[j->nnotes].index = w->current;
    j->notes[j->nnotes].seq = j->nnotes;
    j->notes[j->nnotes].msg = copy;
    j->nnotes++;
    pthread_mutex_unlock(&j->mu);
}

static void record_error(job *j, int64_t i, es_status rc, const char *msg)
{
    pthread_mutex_lock(&j->mu);
    if (i < j->err_index) {
        j->err_index = i;
        j->err_rc = rc;
        snprintf(j->err_msg, sizeof j->err_msg, "%s", msg);
    }
    pthread_mutex_unlock(&j->mu);
}

/* Coincident vertices give edges of length 0: valid in the statistics, but
 * no mesh realizes a point with a zero length, so embedding such a row (or
 * a point that keeps the zero) fails later; say so while the file is known. */
static void warn_zero_edges(es_ctx *ctx, const char *path, const es_mesh *mesh,
                            const double *len, int64_t ne)
{
    const int64_t *ev = es_mesh_edges(mesh);
    int64_t n = 0, first = -1;
    for (int64_t e = 0; e < ne; e++)
        if (len[e] == 0 && n++ == 0) first = e;
    if (n)
        es__warn(ctx, "'%s': %lld edge%s of length 0 (first: edge %lld, vertices %lld-%lld); "
                 "such a shape cannot be embedded", path, (long long)n, n == 1 ? "" : "s",
                 (long long)first, (long long)ev[2 * first], (long long)ev[2 * first + 1]);
}

/* A triangle whose corners are collinear (or coincide) has zero area: its
 * lengths sit on the triangle inequality's boundary, so its angles are
 * undefined and an embedding cannot hold it; say so at ingest. */
static void warn_flat_faces(es_ctx *ctx, const char *path, int64_t nfaces, const int64_t *faces,
                            const double *xyz)
{
    int64_t n = 0, first = -1;
    for (int64_t f = 0; f < nfaces; f++) {
        const double *a = xyz + 3 * faces[3 * f], *b = xyz + 3 * faces[3 * f + 1];
        const double *c = xyz + 3 * faces[3 * f + 2];
        double u[3], v[3], x[3], uu = 0, vv = 0, ww = 0;
        for (int k = 0; k < 3; k++) {
            u[k] = b[k] - a[k];
            v[k] = c[k] - a[k];
            uu += u[k] * u[k];
            vv += v[k] * v[k];
            ww += (c[k] - b[k]) * (c[k] - b[k]);
        }
        x[0] = u[1] * v[2] - u[2] * v[1];
        x[1] = u[2] * v[0] - u[0] * v[2];
        x[2] = u[0] * v[1] - u[1] * v[0];
        /* |u x v| (twice the area) against the longest side squared: 0 up
         * to rounding for collinear corners, whatever the mesh's scale */
        double l2 = fmax(uu, fmax(vv, ww));
        if (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] <= 1e-24 * l2 * l2 && n++ == 0) first = f;
    }
    if (n)
        es__warn(ctx, "'%s': %lld triangle%s of zero area (first: face %lld, vertices %lld %lld "
                 "%lld): their angles are undefined, and such a shape cannot be embedded",
                 path, (long long)n, n == 1 ? "" : "s", (long long)first,
                 (long long)faces[3 * first], (long long)faces[3 * first + 1],
                 (long long)faces[3 * first + 2]);
}

/* One input into slot i. */
static es_status process_one(worker *w, int64_t i, char **buf, size_t *cap, es_meshdata *md)
{
    job *j = w->j;
    es_ctx *ctx = w->ctx;
    const char *path = j->in[i].path;
    batch *b = j->b;
    size_t len;
    int64_t row;
    es_status rc;
    if ((rc = slurp(ctx, path, buf, cap, &len))) return rc;
    pthread_mutex_lock(&j->mu);
    j->bytes_read += (int64_t)len;
    pthread_mutex_unlock(&j->mu);
    es_content_hash(*buf, len, b->hash[i]);
    row = j->st ? es_store_find_row(j->st, j->in[i].id) : -1;
    if (row >= 0) {
        if (!strcmp(es_store_content_hash(j->st, row), b->hash[i])) {
            b->skip[i] = 1;
            return ES_OK;
        }
        ES_FAIL(ctx, ES_EEXIST, "'%s': id '%s' is in the store already with different "
                "content (ingested from '%s'); give it another id", path, j->in[i].id,
                es_store_source_path(j->st, row));
    }
    if ((rc = es_meshdata_parse(ctx, path, *buf, len, j->o->format, md))) return rc;
    if (!(rc = check_topology(ctx, j->r, path, md))) {
        const int64_t slot = i - j->slot0;
        double *li = b->len + slot * b->E;
        if ((rc = es_edge_lengths(ctx, j->r->mesh, md->xyz, li)) ||
            (rc = es_lengths_normalize(ctx, b->E, li, li, &b->scale[slot]))) {
            char msg[900];
            snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
            rc = es__fail(ctx, rc, "'%s': %s", path, msg);
        } else {
            warn_zero_edges(ctx, path, j->r->mesh, li, b->E);
            warn_flat_faces(ctx, path, j->r->F, j->r->faces, md->xyz);
            memcpy(b->xyz + slot * 3 * b->V, md->xyz, (size_t)(3 * b->V) * sizeof(double));
        }
    }
    es_meshdata_clear(ctx, md);
    return rc;
}

static void *work(void *arg)
{
    worker *w = arg;
    job *j = w->j;
    char *buf = NULL;
    size_t cap = 0;
    es_meshdata md;
    memset(&md, 0, sizeof md);
    for (;;) {
        int64_t i = (int64_t)atomic_fetch_add(&j->next, 1);
        es_status rc;
        if (i >= j->n) break;
        pthread_mutex_lock(&j->mu);
        rc = i > j->err_index ? ES_EINVAL : ES_OK;  /* a lower input failed: stop */
        pthread_mutex_unlock(&j->mu);
        if (rc) break;
        w->current = i;
        if ((rc = process_one(w, i, &buf, &cap, &md)))
            record_error(j, i, rc, es_ctx_errmsg(w->ctx));
        atomic_fetch_add(&j->done, 1);
        if (w->main)   /* (a cancel is seen after the block) */
            es__progress(w->main_ctx, "reading meshes", (int64_t)atomic_load(&j->done), j->ntotal);
    }
    es__free(w->ctx, buf);
    return NULL;
}

static int64_t auto_threads(const es_ingest_opts *o, int64_t n)
{
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    int64_t t = o->threads > 0 ? o->threads : cpus > 0 ? cpus : 1;
    if (t > 16) t = 16;
    if (t > n) t = n;
    return t < 1 ? 1 : t;
}

/* Inputs [first, j->n) into their slots. */
static es_status run_phase1(es_ctx *ctx, job *j, int64_t first)
{
    int64_t nt = auto_threads(j->o, j->n - first);
    worker w[16];
    pthread_t tid[16];
    bool started[16] = {false};
    es_status rc = ES_OK;
    es_log_fn user_log;
    void *user_ud;
    atomic_store(&j->next, first);
    atomic_store(&j->done, first);
    memset(w, 0, sizeof w);
    /* the caller's thread collects its warnings too, so that all of them
     * come back in input order (its own used to come first) */
    es__ctx_get_log(ctx, &user_log, &user_ud);
    es_ctx_set_log(ctx, on_worker_log, &w[0]);
    for (int64_t t = 0; t < nt; t++) {
        w[t].j = j;
        w[t].main = t == 0;
        w[t].main_ctx = ctx;
        w[t].ctx = ctx;
        if (t == 0) continue;
        if (es_ctx_new(&w[t].ctx) != ES_OK) break;
        es_ctx_set_log(w[t].ctx, on_worker_log, &w[t]);
        if (pthread_create(&tid[t], NULL, work, &w[t]) != 0) {
            es_ctx_free(w[t].ctx);
            w[t].ctx = NULL;
            break;
        }
        started[t] = true;
    }
    work(&w[0]);
    for (int64_t t = 1; t < nt; t++) {
        if (!started[t]) continue;
        pthread_join(tid[t], NULL);
        es_ctx_free(w[t].ctx);
    }
    es_ctx_set_log(ctx, user_log, user_ud);
    if (j->err_index < j->ntotal) rc = es__fail(ctx, j->err_rc, "%s", j->err_msg);
    return rc;
}

/* The rows kept so far, in input order (pointer arrays for all n inputs:
 * the ids and labels are the inputs', the hashes the batch's, the real
 * source paths made here), and the content hashes seen: the store's rows
 * (as it was opened) and the inputs kept (keys borrowed from the store and
 * the batch; a map, not a scan of every earlier row for each input). */
typedef struct kept {
    int64_t n;
    const char **ids, **hashes, **labels;   /* labels: ncols per row */
    char **sources;
    es__strmap seen_store, seen_new;
} kept;

static es_status kept_init(es_ctx *ctx, kept *k, const es_store *st, int64_t n, int64_t ncols)
{
    es_status rc;
    if (!(k->ids = es__alloc_array(ctx, n, sizeof *k->ids)) ||
        !(k->sources = es__alloc_array(ctx, n, sizeof *k->sources)) ||
        !(k->hashes = es__alloc_array(ctx, n, sizeof *k->hashes)) ||
        !(k->labels = es__alloc_array(ctx, ncols > 0 ? n * ncols : 1, sizeof *k->labels)))
        return ES_ENOMEM;
    if ((rc = es__strmap_init(ctx, &k->seen_store, st ? es_store_nrows(st) : 0)) ||
        (rc = es__strmap_init(ctx, &k->seen_new, n)))
        return rc;
    for (int64_t r = 0; st && r < es_store_nrows(st); r++)
        if ((rc = es__strmap_put(ctx, &k->seen_store, es_store_content_hash(st, r), r, NULL)))
            return rc;
    return ES_OK;
}

static void kept_clear(es_ctx *ctx, kept *k)
{
    es__strmap_clear(ctx, &k->seen_store);
    es__strmap_clear(ctx, &k->seen_new);
    for (int64_t i = 0; k->sources && i < k->n; i++) es__free(ctx, k->sources[i]);
    es__free(ctx, k->sources);
    es__free(ctx, k->ids);
    es__free(ctx, k->hashes);
    es__free(ctx, k->labels);
}

/* Inputs [b0, b1), read into the batch: duplicate warnings, the kept rows
 * moved to the front of the batch and appended to the store's working copy
 * (made now, for a new store). */
static es_status keep_block(es_ctx *ctx, const char *store_path, es_store **st, const ref *r,
                            const input *in, int64_t b0, int64_t b1, int64_t ncols,
                            const char *const *colnames, batch *b, kept *k,
                            es_ingest_report *rep)
{
    const int64_t k0 = k->n;
    int64_t m = 0;
    es_status rc;
    for (int64_t i = b0; i < b1; i++) {
        char real[PATH_MAX];
        const int64_t slot = i - b0;
        int64_t prev;
        if (b->skip[i]) {
            rep->rows_skipped++;
            continue;
        }
        if ((prev = es__strmap_get(&k->seen_store, b->hash[i])) >= 0)
            es__warn(ctx, "'%s' has the same content as row '%s' of the store",
                     in[i].path, es_store_row_id(*st, prev));
        if ((rc = es__strmap_put(ctx, &k->seen_new, b->hash[i], k->n, &prev))) return rc;
        if (prev >= 0)
            es__warn(ctx, "'%s' has the same content as '%s'", in[i].path, k->sources[prev]);
        if (m != slot) {
            memmove(b->len + m * b->E, b->len + slot * b->E, (size_t)b->E * sizeof(double));
            memmove(b->xyz + m * 3 * b->V, b->xyz + slot * 3 * b->V,
                    (size_t)(3 * b->V) * sizeof(double));
            b->scale[m] = b->scale[slot];
        }
        k->ids[k->n] = in[i].id;
        k->hashes[k->n] = b->hash[i];
        for (int64_t c = 0; c < ncols; c++) k->labels[k->n * ncols + c] = in[i].labels[c];
        if (!(k->sources[k->n] = es__strdup(ctx, realpath(in[i].path, real) ? real : in[i].path)))
            return ES_ENOMEM;
        k->n++;
        m++;
    }
    if (m == 0) return ES_OK;
    if (!*st && (rc = es_store_create(ctx, store_path, r->mesh, st))) return rc;
    {
        es_store_rows rows = {m, k->ids + k0, (const char *const *)(k->sources + k0),
                              k->hashes + k0, b->len, b->scale, b->xyz, ncols, colnames,
                              k->labels + k0 * ncols};
        return es_store_append(ctx, *st, &rows);
    }
}

static es_status ingest(es_ctx *ctx, const char *store_path, int64_t n, const input *in,
                        int64_t ncols, const char *const *colnames, const es_ingest_opts *o,
                        es_ingest_report *rep)
{
    es_store *st = NULL;
    int64_t *store_faces = NULL, *ref_faces = NULL, first = 0;
    es_meshdata md;
    batch b;
    ref r;
    job j;
    kept k;
    es_status rc = ES_OK;
    bool exists, mu_init = false, created;
    memset(&md, 0, sizeof md);
    memset(&b, 0, sizeof b);
    memset(&r, 0, sizeof r);
    memset(&j, 0, sizeof j);
    memset(&k, 0, sizeof k);
    memset(rep, 0, sizeof *rep);
    if (!store_path || !*store_path) ES_FAIL(ctx, ES_EINVAL, "ingest: no store path");
    if (n < 1) ES_FAIL(ctx, ES_EINVAL, "ingest: no meshes to ingest");
    if (ncols > ES_STORE_MAX_COLUMNS)   /* (the store's refusal, before any mesh is read) */
        ES_FAIL(ctx, ES_ERANGE, "ingest: %lld label columns; a store holds at most %d",
                (long long)ncols, ES_STORE_MAX_COLUMNS);
    exists = access(store_path, F_OK) == 0;
    created = !exists;
    if (!exists && !o->create)
        ES_FAIL(ctx, ES_ENOTFOUND, "ingest: store '%s' does not exist", store_path);
    if (exists) {
        int64_t nf3, E;
        if ((rc = es_store_open(ctx, store_path, ES_STORE_WRITE, &st))) return rc;
        if (es_store_topology_kind(st) != ES_TOPOLOGY_MESH) {
            rc = es__fail(ctx, ES_EMISMATCH, "ingest: store '%s' holds landmarks without faces "
                          "(topology kind '%s'): meshes cannot be added to it", store_path,
                          es_topology_kind_name(es_store_topology_kind(st)));
            goto done;
        }
        r.V = es_store_nverts(st);
        r.F = es_store_nfaces(st);
        if (!es__mul_i64(r.F, 3, &nf3) ||
            !(store_faces = es__alloc_array(ctx, nf3, sizeof(int64_t)))) {
            rc = ES_ENOMEM;
            goto done;
        }
        /* quiet: vertices in no face were warned about at the store's first ingest */
        if ((rc = es_store_read_faces(ctx, st, store_faces)) ||
            (rc = es__mesh_new(ctx, r.V, r.F, store_faces, NULL, 0, &r.mesh)))
            goto done;
        r.faces = store_faces;
        snprintf(r.what, sizeof r.what, "the store '%s'", store_path);
        E = es_mesh_nedges(r.mesh);
        if ((rc = batch_alloc(ctx, &b, block_rows(o, n, auto_threads(o, n), r.V, E), n, r.V,
                              E)))
            goto done;
    }
    if (pthread_mutex_init(&j.mu, NULL) != 0) {
        rc = es__fail(ctx, ES_ENOMEM, "ingest: cannot make a mutex");
        goto done;
    }
    mu_init = true;
    j.in = in;
    j.ntotal = n;
    j.r = &r;
    j.st = st;
    j.o = o;
    j.b = &b;
    j.err_index = n;
    if ((rc = kept_init(ctx, &k, st, n, ncols))) goto done;

    if (!st) {
        /* New store: the first input defines the topology. */
        char *buf = NULL;
        size_t cap = 0, len = 0;
        int64_t nf3, E;
        es__progress(ctx, "reading meshes", 0, n);
        if ((rc = slurp(ctx, in[0].path, &buf, &cap, &len)) ||
            (rc = es_meshdata_parse(ctx, in[0].path, buf, len, o->format, &md))) {
            es__free(ctx, buf);
            goto done;
        }
        j.bytes_read += (int64_t)len;
        r.V = md.nverts;
        r.F = md.nfaces;
        if (!es__mul_i64(r.F, 3, &nf3) ||
            !(ref_faces = es__alloc_array(ctx, nf3, sizeof(int64_t)))) {
            es__free(ctx, buf);
            rc = ES_ENOMEM;
            goto done;
        }
        memcpy(ref_faces, md.faces, (size_t)nf3 * sizeof *ref_faces);
        r.faces = ref_faces;
        snprintf(r.what, sizeof r.what, "the first input '%s'", in[0].path);
        if ((rc = es__mesh_new(ctx, r.V, r.F, r.faces, md.xyz, 0, &r.mesh))) {
            char msg[900];
            snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
            rc = es__fail(ctx, rc, "'%s': %s", in[0].path, msg);
            es__free(ctx, buf);
            goto done;
        }
        {
            es_mesh_summary sum;
            es_mesh_summarize(r.mesh, &sum);
            if (sum.n_unreferenced > 0)
                es__warn(ctx, "'%s': %lld of %lld vertices are in no face (kept, with their "
                         "positions; they have no edges)", in[0].path,
                         (long long)sum.n_unreferenced, (long long)r.V);
        }
        E = es_mesh_nedges(r.mesh);
        if ((rc = batch_alloc(ctx, &b, block_rows(o, n, auto_threads(o, n), r.V, E), n, r.V,
                              E))) {
            es__free(ctx, buf);
            goto done;
        }
        es_content_hash(buf, len, b.hash[0]);
        es__free(ctx, buf);
        if ((rc = es_edge_lengths(ctx, r.mesh, md.xyz, b.len)) ||
            (rc = es_lengths_normalize(ctx, b.E, b.len, b.len, &b.scale[0]))) {
            char msg[900];
            snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
            rc = es__fail(ctx, rc, "'%s': %s", in[0].path, msg);
            goto done;
        }
        warn_zero_edges(ctx, in[0].path, r.mesh, b.len, b.E);
        warn_flat_faces(ctx, in[0].path, r.F, r.faces, md.xyz);
        memcpy(b.xyz, md.xyz, (size_t)(3 * b.V) * sizeof(double));
        es_meshdata_clear(ctx, &md);
        first = 1;
    }

    /* ---- block by block: read and check, then write to the working copy ---- */
    for (int64_t b0 = 0; b0 < n; b0 += b.cap) {
        const int64_t b1 = n - b0 > b.cap ? b0 + b.cap : n;
        j.n = b1;
        j.slot0 = b0;
        if (b0 < first && first < b1) rc = run_phase1(ctx, &j, first);
        else if (b0 >= first) rc = run_phase1(ctx, &j, b0);
        /* the block's warnings, in input order (sorted: 10^5 inputs with a
         * warning each took minutes with the exchange sort this replaced) */
        if (j.nnotes > 1) qsort(j.notes, (size_t)j.nnotes, sizeof *j.notes, cmp_note);
        for (int64_t q = 0; q < j.nnotes; q++) {
            es__warn(ctx, "%s", j.notes[q].msg);
            free(j.notes[q].msg);
        }
        j.nnotes = 0;
        rep->bytes_read = j.bytes_read;
        if (rc || (rc = es__cancelled(ctx, "ingest")) ||
            (rc = keep_block(ctx, store_path, &st, &r, in, b0, b1, ncols, colnames, &b, &k, rep)))
            goto done;
    }
    es__progress(ctx, "reading meshes", n, n);

    /* ---- publish the working copy, atomically ---- */
    if (k.n > 0) {
        es__progress(ctx, "writing store", 0, 1);
        if ((rc = es_store_commit(ctx, st))) goto done;
        es__progress(ctx, "writing store", 1, 1);
    }
    rep->created = created;
    rep->rows_added = k.n;
    rep->rows_total = es_store_nrows(st);
done:
    if (rc != ES_OK) rep->rows_added = 0;
    kept_clear(ctx, &k);
    if (mu_init) pthread_mutex_destroy(&j.mu);
    for (int64_t q = 0; q < j.nnotes; q++) free(j.notes[q].msg);
    free(j.notes);
    es_meshdata_clear(ctx, &md);
    if (rc != ES_OK) es_store_abort(st);
    else es_store_close(st);
    es_mesh_free(r.mesh);
    es__free(ctx, store_faces);
    es__free(ctx, ref_faces);
    batch_free(ctx, &b);
    return rc;
}

es_status es_ingest_manifest(es_ctx *ctx, const char *store_path, const char *manifest_path,
                             const es_ingest_opts *opts, es_ingest_report *report)
{
    es_ingest_opts defaults;
    es_ingest_report dummy;
    es_manifest *m = NULL;
    input *in = NULL;
    char **paths = NULL;
    es_status rc;
    if (!opts) {
        es_ingest_opts_init(&defaults);
        opts = &defaults;
    }
    if (!report) report = &dummy;
    memset(report, 0, sizeof *report);
    if ((rc = es_manifest_read(ctx, manifest_path, &m))) return rc;
    if (m->nrows == 0) {
        es_manifest_free(ctx, m);
        ES_FAIL(ctx, ES_EINVAL, "manifest '%s' lists no meshes", manifest_path);
    }
    if (!(in = es__alloc_array(ctx, m->nrows, sizeof *in)) ||
        !(paths = es__alloc_array(ctx, m->nrows, sizeof *paths))) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t r = 0; r < m->nrows; r++) {
        const char *file = m->cells[r * m->ncols + m->file_col];
        size_t nb = strlen(m->dir) + strlen(file) + 2;
        if (!(paths[r] = es__malloc(ctx, nb))) { rc = ES_ENOMEM; goto done; }
        if (file[0] == '/') snprintf(paths[r], nb, "%s", file);
        else snprintf(paths[r], nb, "%s/%s", m->dir, file);
        in[r].id = m->ids[r];
        in[r].path = paths[r];
        in[r].labels = (const char *const *)(m->cells + r * m->ncols);
    }
    rc = ingest(ctx, store_path, m->nrows, in, m->ncols, (const char *const *)m->colnames,
                opts, report);
done:
    for (int64_t r = 0; paths && r < m->nrows; r++) es__free(ctx, paths[r]);
    es__free(ctx, paths);
    es__free(ctx, in);
    es_manifest_free(ctx, m);
    return rc;
}

es_status es_ingest_files(es_ctx *ctx, const char *store_path, int64_t nfiles,
                          const char *const *files, const es_ingest_opts *opts,
                          es_ingest_report *report)
{
    es_ingest_opts defaults;
    es_ingest_report dummy;
    input *in = NULL;
    char **ids = NULL;
    es__strmap seen = {0};
    int64_t k;
    es_status rc = ES_OK;
    if (!opts) {
        es_ingest_opts_init(&defaults);
        opts = &defaults;
    }
    if (!report) report = &dummy;
    memset(report, 0, sizeof *report);
    if (nfiles < 1 || !files) ES_FAIL(ctx, ES_EINVAL, "ingest: no files given");
    if (!(in = es__alloc_array(ctx, nfiles, sizeof *in)) ||
        !(ids = es__alloc_array(ctx, nfiles, sizeof *ids)) ||
        es__strmap_init(ctx, &seen, nfiles) != ES_OK) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t i = 0; i < nfiles; i++) {
        char id[1024];
        es_id_from_path(files[i], id, sizeof id);
        if (!*id) {
            rc = es__fail(ctx, ES_EINVAL, "ingest: cannot make an id from '%s'", files[i]);
            goto done;
        }
        if (!(ids[i] = es__strdup(ctx, id))) { rc = ES_ENOMEM; goto done; }
        if ((rc = es__strmap_put(ctx, &seen, ids[i], i, &k)) != ES_OK) goto done;
        if (k >= 0) {
            rc = es__fail(ctx, ES_EINVAL, "ingest: '%s' and '%s' would both get the id '%s'; "
                          "use a manifest with an 'id' column", files[k], files[i], id);
            goto done;
        }
        in[i].id = ids[i];
        in[i].path = files[i];
        in[i].labels = NULL;
    }
    rc = ingest(ctx, store_path, nfiles, in, 0, NULL, opts, report);
done:
    es__strmap_clear(ctx, &seen);
    for (int64_t i = 0; ids && i < nfiles; i++) es__free(ctx, ids[i]);
    es__free(ctx, ids);
    es__free(ctx, in);
    return rc;
}
