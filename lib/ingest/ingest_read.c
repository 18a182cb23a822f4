/* lib/ingest/ingest_read.c — reading the meshes of an ingest, the part the
 * one-process ingest (ingest.c) and the ranks' (ingest_ranks.c) share: the
 * reference topology (the store's or the first input's), and blocks of
 * inputs read and checked on threads: the file's bytes (hashed for
 * duplicate detection, then parsed from the buffer so the file is read
 * once), its vertex count and face list against the reference, and its
 * normalized edge lengths (es_edge_lengths, es_lengths_normalize; Section 4,
 * eq. 12 of Rojas et al.) into the block's slots.
 */
#include "ingest/ingest_pkg.h"
#include "core/files.h"
#include "mesh/mesh_private.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_io.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

es_status es__ingest_known(es_ctx *ctx, const es_store *st, const ingest_input *in,
                           const char *hash, int *skip)
{
    int64_t row = st ? es_store_find_row(st, in->id) : -1;
    *skip = 0;
    if (row < 0) return ES_OK;
    if (!strcmp(es_store_content_hash(st, row), hash)) {
        *skip = 1;
        return ES_OK;
    }
    ES_FAIL(ctx, ES_EEXIST, "'%s': id '%s' is in the store already with different content "
            "(ingested from '%s'); give it another id", in->path, in->id,
            es_store_source_path(st, row));
}


/* A whole mesh file into *buf (grown as needed and reused across files, so
 * that one buffer's pages serve every input). A missing file is
 * ES_ENOTFOUND; anything but a regular file is refused. */
es_status es__ingest_slurp(es_ctx *ctx, const char *path, char **buf, size_t *cap, size_t *len)
{
    return es__read_file_reuse(ctx, path, ES__READ_REGULAR | ES__READ_NOTFOUND, buf, cap, len);
}



static void batch_free(es_ctx *ctx, ingest_batch *b)
{
    es__free(ctx, b->xyz);
    es__free(ctx, b->len);
    es__free(ctx, b->scale);
    es__free(ctx, b->hash);
    es__free(ctx, b->skip);
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
    /* first touch of tens of MB in 4 KiB pages dominated this phase's CPU
     * on a VM (core/os.c) */
    if (p && bytes >= ((size_t)4 << 20)) es__advise_huge(p, bytes);
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

static es_status batch_alloc(es_ctx *ctx, ingest_batch *b, int64_t cap, int64_t n, int64_t V,
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



static es_status check_topology(es_ctx *ctx, const ingest_ref *r, const char *path,
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



/* Input order, and the order of arrival within an input. */
static int cmp_note(const void *a, const void *b)
{
    const ingest_note *x = a, *y = b;
    if (x->index != y->index) return x->index < y->index ? -1 : 1;
    return x->seq < y->seq ? -1 : x->seq > y->seq;
}



typedef struct ingest_worker {
    ingest_job *j;
    es_ctx *ctx;                /* own context, or the caller's (worker 0) */
    bool main;
    es_ctx *main_ctx;
    int64_t current;            /* input being processed, for warnings */
} ingest_worker;

static void on_worker_log(void *ud, es_log_level level, const char *msg)
{
    ingest_worker *w = ud;
    ingest_job *j = w->j;
    char *copy = malloc(strlen(msg) + 1);
    (void)level;
    if (!copy) return;
    strcpy(copy, msg);
    pthread_mutex_lock(&j->mu);
    if (j->nnotes == j->capnotes) {
        int64_t cap = j->capnotes ? 2 * j->capnotes : 16;
        ingest_note *p = realloc(j->notes, (size_t)cap * sizeof *p);
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

static void record_error(ingest_job *j, int64_t i, es_status rc, const char *msg)
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

/* A parsed input's lengths (normalized) and positions into slot `slot` of
 * the batch, with the warnings a mesh may earn; the first input and every
 * later one go through here. */
static es_status measure_slot(es_ctx *ctx, const ingest_ref *r, ingest_batch *b, int64_t slot,
                              const char *path, const double *xyz)
{
    double *li = b->len + slot * b->E;
    es_status rc;
    if ((rc = es_edge_lengths(ctx, r->mesh, xyz, li)) ||
        (rc = es_lengths_normalize(ctx, b->E, li, li, &b->scale[slot]))) {
        char msg[900];
        snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
        return es__fail(ctx, rc, "'%s': %s", path, msg);
    }
    warn_zero_edges(ctx, path, r->mesh, li, b->E);
    warn_flat_faces(ctx, path, r->F, r->faces, xyz);
    memcpy(b->xyz + slot * 3 * b->V, xyz, (size_t)(3 * b->V) * sizeof(double));
    return ES_OK;
}

/* One input into slot i. */
static es_status process_one(ingest_worker *w, int64_t i, char **buf, size_t *cap, es_meshdata *md)
{
    ingest_job *j = w->j;
    es_ctx *ctx = w->ctx;
    const char *path = j->in[i].path;
    ingest_batch *b = j->b;
    size_t len;
    int skip;
    es_status rc;
    if ((rc = es__ingest_slurp(ctx, path, buf, cap, &len))) return rc;
    pthread_mutex_lock(&j->mu);
    j->bytes_read += (int64_t)len;
    pthread_mutex_unlock(&j->mu);
    es_content_hash(*buf, len, b->hash[i]);
    if ((rc = es__ingest_known(ctx, j->st, &j->in[i], b->hash[i], &skip))) return rc;
    if (skip) {
        b->skip[i] = 1;
        return ES_OK;
    }
    if ((rc = es_meshdata_parse(ctx, path, *buf, len, j->o->format, md))) return rc;
    if (!(rc = check_topology(ctx, j->r, path, md)))
        rc = measure_slot(ctx, j->r, b, i - j->slot0, path, md->xyz);
    es_meshdata_clear(ctx, md);
    return rc;
}

static void *work(void *arg)
{
    ingest_worker *w = arg;
    ingest_job *j = w->j;
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
    int64_t t = o->threads > 0 ? o->threads : es__cpu_count();
    if (t > 16) t = 16;
    if (t > n) t = n;
    return t < 1 ? 1 : t;
}

/* Inputs [first, j->n) into their slots. */
static es_status run_phase1(es_ctx *ctx, ingest_job *j, int64_t first)
{
    int64_t nt = auto_threads(j->o, j->n - first);
    ingest_worker w[16];
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

/* The store's topology as the reference. */
static es_status ref_from_store(es_ctx *ctx, ingest_session *s, const char *store_path)
{
    int64_t nf3;
    es_status rc;
    if (es_store_topology_kind(s->st) != ES_TOPOLOGY_MESH)
        ES_FAIL(ctx, ES_EMISMATCH, "ingest: store '%s' holds landmarks without faces (topology "
                "kind '%s'): meshes cannot be added to it", store_path,
                es_topology_kind_name(es_store_topology_kind(s->st)));
    s->r.V = es_store_nverts(s->st);
    s->r.F = es_store_nfaces(s->st);
    if (!es__mul_i64(s->r.F, 3, &nf3) || !(s->faces = es__alloc_array(ctx, nf3, sizeof(int64_t))))
        return ES_ENOMEM;
    /* quiet: vertices in no face were warned about at the store's first ingest */
    if ((rc = es_store_read_faces(ctx, s->st, s->faces)) ||
        (rc = es__mesh_new(ctx, s->r.V, s->r.F, s->faces, NULL, 0, &s->r.mesh)))
        return rc;
    s->r.faces = s->faces;
    snprintf(s->r.what, sizeof s->r.what, "the store '%s'", store_path);
    return ES_OK;
}

/* A new store: the first input defines the topology; its values go to
 * slot 0 of a batch made here. */
static es_status ref_from_first(es_ctx *ctx, ingest_session *s, const ingest_input *in,
                                int64_t n, int64_t nshare, const es_ingest_opts *o)
{
    es_meshdata md;
    char *buf = NULL;
    size_t cap = 0, len = 0;
    int64_t nf3;
    es_status rc;
    ingest_ref *r = &s->r;
    ingest_batch *b = &s->b;
    memset(&md, 0, sizeof md);
    es__progress(ctx, "reading meshes", 0, n);
    if ((rc = es__ingest_slurp(ctx, in[0].path, &buf, &cap, &len)) ||
        (rc = es_meshdata_parse(ctx, in[0].path, buf, len, o->format, &md)))
        goto done;
    s->j.bytes_read += (int64_t)len;
    r->V = md.nverts;
    r->F = md.nfaces;
    if (!es__mul_i64(r->F, 3, &nf3) || !(s->faces = es__alloc_array(ctx, nf3, sizeof(int64_t)))) {
        rc = ES_ENOMEM;
        goto done;
    }
    memcpy(s->faces, md.faces, (size_t)nf3 * sizeof *s->faces);
    r->faces = s->faces;
    snprintf(r->what, sizeof r->what, "the first input '%s'", in[0].path);
    if ((rc = es__mesh_new(ctx, r->V, r->F, r->faces, md.xyz, 0, &r->mesh))) {
        char msg[900];
        snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
        rc = es__fail(ctx, rc, "'%s': %s", in[0].path, msg);
        goto done;
    }
    {
        es_mesh_summary sum;
        es_mesh_summarize(r->mesh, &sum);
        if (sum.n_unreferenced > 0)
            es__warn(ctx, "'%s': %lld of %lld vertices are in no face (kept, with their "
                     "positions; they have no edges)", in[0].path,
                     (long long)sum.n_unreferenced, (long long)r->V);
    }
    int64_t E = es_mesh_nedges(r->mesh);
    if ((rc = batch_alloc(ctx, b, block_rows(o, nshare, auto_threads(o, nshare), r->V, E), n,
                          r->V, E)))
        goto done;
    es_content_hash(buf, len, b->hash[0]);
    if ((rc = measure_slot(ctx, r, b, 0, in[0].path, md.xyz))) goto done;
    s->first = 1;
done:
    es__free(ctx, buf);
    es_meshdata_clear(ctx, &md);
    return rc;
}

es_status es__ingest_begin(es_ctx *ctx, ingest_session *s, const char *store_path,
                           es_store_mode mode, const ingest_input *in, int64_t n,
                           int64_t nshare, const es_ingest_opts *o)
{
    es_status rc;
    memset(s, 0, sizeof *s);
    s->path = store_path;
    if (access(store_path, F_OK) == 0) {
        if ((rc = es_store_open(ctx, store_path, mode, &s->st)) ||
            (rc = ref_from_store(ctx, s, store_path)) ||
            (rc = batch_alloc(ctx, &s->b, block_rows(o, nshare, auto_threads(o, nshare), s->r.V,
                                                     es_mesh_nedges(s->r.mesh)),
                              n, s->r.V, es_mesh_nedges(s->r.mesh))))
            return rc;
    }
    if (pthread_mutex_init(&s->j.mu, NULL) != 0)
        ES_FAIL(ctx, ES_ENOMEM, "ingest: cannot make a mutex");
    s->mu_init = true;
    s->j.in = in;
    s->j.ntotal = n;   /* (on the ranks, rank 0's progress counts to its share's end) */
    s->j.r = &s->r;
    s->j.st = s->st;
    s->j.o = o;
    s->j.b = &s->b;
    s->j.err_index = n;
    return s->st ? ES_OK : ref_from_first(ctx, s, in, n, nshare, o);
}

void es__ingest_end(es_ctx *ctx, ingest_session *s)
{
    if (s->mu_init) pthread_mutex_destroy(&s->j.mu);
    for (int64_t q = 0; q < s->j.nnotes; q++) free(s->j.notes[q].msg);
    free(s->j.notes);
    es_mesh_free(s->r.mesh);
    es__free(ctx, s->faces);
    batch_free(ctx, &s->b);
    memset(&s->j, 0, sizeof s->j);
    s->mu_init = false;
    s->r.mesh = NULL;
    s->faces = NULL;
}

/* line + '\n' onto t (a line that does not fit in memory is dropped: a
 * warning, not the data). */
static void text_add(ingest_text *t, const char *line)
{
    size_t k = strlen(line);
    if (t->n + k + 2 > t->cap) {
        size_t cap = 2 * (t->n + k + 2) + 256;
        char *p = realloc(t->p, cap);
        if (!p) return;
        t->p = p;
        t->cap = cap;
    }
    memcpy(t->p + t->n, line, k);
    t->n += k;
    t->p[t->n++] = '\n';
    t->p[t->n] = '\0';
}

es_status es__ingest_read_block(es_ctx *ctx, ingest_session *s, int64_t b0, int64_t b1,
                                ingest_text *keep)
{
    ingest_job *j = &s->j;
    es_status rc = ES_OK;
    j->n = b1;
    j->slot0 = b0;
    if (b0 < s->first && s->first < b1) rc = run_phase1(ctx, j, s->first);
    else if (b0 >= s->first && b0 < b1) rc = run_phase1(ctx, j, b0);
    /* the block's warnings, in input order (sorted: 10^5 inputs with a
     * warning each took minutes with the exchange sort this replaced) */
    if (j->nnotes > 1) qsort(j->notes, (size_t)j->nnotes, sizeof *j->notes, cmp_note);
    for (int64_t q = 0; q < j->nnotes; q++) {
        if (keep) text_add(keep, j->notes[q].msg);
        else es__warn(ctx, "%s", j->notes[q].msg);
        free(j->notes[q].msg);
    }
    j->nnotes = 0;
    return rc;
}

int64_t es__ingest_compact(ingest_batch *b, int64_t b0, int64_t b1)
{
    int64_t m = 0;
    for (int64_t i = b0; i < b1; i++) {
        const int64_t slot = i - b0;
        if (b->skip[i]) continue;
        if (m != slot) {
            memmove(b->len + m * b->E, b->len + slot * b->E, (size_t)b->E * sizeof(double));
            memmove(b->xyz + m * 3 * b->V, b->xyz + slot * 3 * b->V,
                    (size_t)(3 * b->V) * sizeof(double));
            b->scale[m] = b->scale[slot];
        }
        m++;
    }
    return m;
}
