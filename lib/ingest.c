/* lib/ingest.c — meshes (and a manifest's labels) into an HDF5 store.
 *
 * All-or-nothing in two phases. Phase 1 reads every input into memory:
 * the file's bytes (hashed for duplicate detection, then parsed from the
 * buffer so the file is read once), the check that its vertex count and
 * face list equal the store's (or the first input's, for a new store), and
 * its normalized edge lengths (es_edge_lengths, es_lengths_normalize;
 * Section 4, eq. 12 of Rojas et al.). Any failure returns before the store
 * is touched. Phase 2 appends all rows in one es_store_append and commits,
 * which replaces the store by an atomic rename (store.c), so a kill during
 * phase 2 also leaves the old store intact.
 */
#include "es_internal.h"
#include "edgespace/es_geom.h"
#include "edgespace/es_ingest.h"
#include "edgespace/es_io.h"
#include "edgespace/es_mesh.h"
#include "edgespace/es_store.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

void es_ingest_opts_init(es_ingest_opts *opts)
{
    memset(opts, 0, sizeof *opts);
    opts->create = 1;
    opts->format = ES_FORMAT_AUTO;
}

void es_content_hash(const void *buf, size_t len, char out[25])
{
    const unsigned char *p = buf;
    uint64_t h = 0xcbf29ce484222325ULL;
    for (size_t i = 0; i < len; i++) {
        h ^= p[i];
        h *= 0x100000001b3ULL;
    }
    snprintf(out, 25, "fnv1a64:%016llx", (unsigned long long)h);
}

/* One input: where to read it, its id and (manifest) label row. */
typedef struct input {
    const char *id;
    const char *path;           /* path to open */
    const char *const *labels;  /* ncols values or NULL */
} input;

static es_status slurp(es_ctx *ctx, const char *path, char **buf, size_t *len)
{
    FILE *f = fopen(path, "rb");
    struct stat st;
    *buf = NULL;
    *len = 0;
    if (!f)
        ES_FAIL(ctx, errno == ENOENT ? ES_ENOTFOUND : ES_EIO, "cannot open '%s': %s", path,
                strerror(errno));
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(f);
        ES_FAIL(ctx, ES_EIO, "'%s' is not a regular file", path);
    }
    if (!(*buf = es__malloc(ctx, (size_t)st.st_size + 1))) {
        fclose(f);
        return ES_ENOMEM;
    }
    *len = fread(*buf, 1, (size_t)st.st_size, f);
    if (ferror(f) || *len != (size_t)st.st_size) {
        fclose(f);
        es__free(ctx, *buf);
        *buf = NULL;
        ES_FAIL(ctx, ES_EIO, "cannot read '%s'", path);
    }
    (*buf)[*len] = '\0';
    fclose(f);
    return ES_OK;
}

typedef struct batch {
    int64_t n, cap, V, F, E;
    double *xyz, *len, *scale;
    const char **ids, **labels;
    char **sources, **hashes;
} batch;

static void batch_free(es_ctx *ctx, batch *b)
{
    for (int64_t i = 0; i < b->n; i++) {
        es__free(ctx, b->sources[i]);
        es__free(ctx, b->hashes[i]);
    }
    es__free(ctx, b->xyz);
    es__free(ctx, b->len);
    es__free(ctx, b->scale);
    es__free(ctx, b->ids);
    es__free(ctx, b->labels);
    es__free(ctx, b->sources);
    es__free(ctx, b->hashes);
}

static es_status batch_alloc(es_ctx *ctx, batch *b, int64_t cap, int64_t ncols)
{
    int64_t nx, nl, nlab;
    if (!es__mul_i64(3 * b->V, cap, &nx) || !es__mul_i64(b->E, cap, &nl) ||
        !es__mul_i64(ncols > 0 ? ncols : 1, cap, &nlab))
        ES_FAIL(ctx, ES_ERANGE, "ingest: %lld shapes of %lld vertices are too many",
                (long long)cap, (long long)b->V);
    b->cap = cap;
    if (!(b->xyz = es__alloc_array(ctx, nx, sizeof(double))) ||
        !(b->len = es__alloc_array(ctx, nl, sizeof(double))) ||
        !(b->scale = es__alloc_array(ctx, cap, sizeof(double))) ||
        !(b->ids = es__alloc_array(ctx, cap, sizeof(char *))) ||
        !(b->labels = es__alloc_array(ctx, nlab, sizeof(char *))) ||
        !(b->sources = es__alloc_array(ctx, cap, sizeof(char *))) ||
        !(b->hashes = es__alloc_array(ctx, cap, sizeof(char *))))
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

static es_status ingest(es_ctx *ctx, const char *store_path, int64_t n, const input *in,
                        int64_t ncols, const char *const *colnames, const es_ingest_opts *o,
                        es_ingest_report *rep)
{
    es_store *st = NULL;
    int64_t *store_faces = NULL, *ref_faces = NULL;
    es_meshdata md;
    batch b;
    ref r;
    es_status rc = ES_OK;
    char *buf = NULL;
    size_t len = 0;
    bool exists;
    memset(&md, 0, sizeof md);
    memset(&b, 0, sizeof b);
    memset(&r, 0, sizeof r);
    memset(rep, 0, sizeof *rep);
    if (!store_path || !*store_path) ES_FAIL(ctx, ES_EINVAL, "ingest: no store path");
    if (n < 1) ES_FAIL(ctx, ES_EINVAL, "ingest: no meshes to ingest");
    exists = access(store_path, F_OK) == 0;
    if (!exists && !o->create)
        ES_FAIL(ctx, ES_ENOTFOUND, "ingest: store '%s' does not exist", store_path);
    if (exists) {
        int64_t nf3;
        if ((rc = es_store_open(ctx, store_path, ES_STORE_WRITE, &st))) return rc;
        r.V = es_store_nverts(st);
        r.F = es_store_nfaces(st);
        if (!es__mul_i64(r.F, 3, &nf3) || !(store_faces = es__alloc_array(ctx, nf3, sizeof(int64_t)))) {
            rc = ES_ENOMEM;
            goto done;
        }
        if ((rc = es_store_read_faces(ctx, st, store_faces)) ||
            (rc = es_mesh_new(ctx, r.V, r.F, store_faces, NULL, &r.mesh)))
            goto done;
        r.faces = store_faces;
        snprintf(r.what, sizeof r.what, "the store '%s'", store_path);
    }

    /* ---- phase 1: read and validate everything ---- */
    for (int64_t i = 0; i < n; i++) {
        const char *path = in[i].path;
        char hash[25], real[PATH_MAX];
        int64_t row = st ? es_store_find_row(st, in[i].id) : -1;
        es__progress(ctx, "reading meshes", i, n);
        if ((rc = slurp(ctx, path, &buf, &len))) goto done;
        rep->bytes_read += (int64_t)len;
        es_content_hash(buf, len, hash);
        if (row >= 0) {
            if (!strcmp(es_store_content_hash(st, row), hash)) {
                rep->rows_skipped++;
                es__free(ctx, buf);
                buf = NULL;
                continue;
            }
            rc = es__fail(ctx, ES_EEXIST, "'%s': id '%s' is in the store already with "
                          "different content (ingested from '%s'); give it another id",
                          path, in[i].id, es_store_source_path(st, row));
            goto done;
        }
        if ((rc = es_meshdata_parse(ctx, path, buf, len, o->format, &md))) goto done;
        es__free(ctx, buf);
        buf = NULL;
        if (!r.faces) {
            /* New store: the first input defines the topology. */
            int64_t nf3;
            r.V = md.nverts;
            r.F = md.nfaces;
            if (!es__mul_i64(r.F, 3, &nf3) ||
                !(ref_faces = es__alloc_array(ctx, nf3, sizeof(int64_t)))) {
                rc = ES_ENOMEM;
                goto done;
            }
            memcpy(ref_faces, md.faces, (size_t)nf3 * sizeof *ref_faces);
            r.faces = ref_faces;
            snprintf(r.what, sizeof r.what, "the first input '%s'", path);
            if ((rc = es_mesh_new(ctx, r.V, r.F, r.faces, md.xyz, &r.mesh))) {
                char msg[900];
                snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
                rc = es__fail(ctx, rc, "'%s': %s", path, msg);
                goto done;
            }
        } else if ((rc = check_topology(ctx, &r, path, &md))) {
            goto done;
        }
        if (!b.cap) {
            b.V = r.V;
            b.F = r.F;
            b.E = es_mesh_nedges(r.mesh);
            if ((rc = batch_alloc(ctx, &b, n, ncols))) goto done;
        }
        {
            double *len_i = b.len + b.n * b.E;
            if ((rc = es_edge_lengths(ctx, r.mesh, md.xyz, len_i)) ||
                (rc = es_lengths_normalize(ctx, b.E, len_i, len_i, &b.scale[b.n]))) {
                char msg[900];
                snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
                rc = es__fail(ctx, rc, "'%s': %s", path, msg);
                goto done;
            }
        }
        memcpy(b.xyz + b.n * 3 * b.V, md.xyz, (size_t)(3 * b.V) * sizeof(double));
        es_meshdata_clear(ctx, &md);
        for (int64_t k = 0; st && k < es_store_nrows(st); k++)
            if (!strcmp(es_store_content_hash(st, k), hash))
                es__warn(ctx, "'%s' has the same content as row '%s' of the store", path,
                         es_store_row_id(st, k));
        for (int64_t k = 0; k < b.n; k++)
            if (!strcmp(b.hashes[k], hash))
                es__warn(ctx, "'%s' has the same content as '%s'", path, b.sources[k]);
        b.ids[b.n] = in[i].id;
        for (int64_t c = 0; c < ncols; c++) b.labels[b.n * ncols + c] = in[i].labels[c];
        if (!(b.sources[b.n] = es__strdup(ctx, realpath(path, real) ? real : path)) ||
            !(b.hashes[b.n] = es__strdup(ctx, hash))) {
            es__free(ctx, b.sources[b.n]);
            rc = ES_ENOMEM;
            goto done;
        }
        b.n++;
    }
    es__progress(ctx, "reading meshes", n, n);

    /* ---- phase 2: write (to a working copy), then commit atomically ---- */
    if (b.n > 0) {
        es_store_rows rows = {b.n, b.ids, (const char *const *)b.sources,
                              (const char *const *)b.hashes, b.len, b.scale, b.xyz,
                              ncols, colnames, b.labels};
        es__progress(ctx, "writing store", 0, 1);
        if (!st) {
            if ((rc = es_store_create(ctx, store_path, r.mesh, &st))) goto done;
            rep->created = 1;
        }
        if ((rc = es_store_append(ctx, st, &rows)) || (rc = es_store_commit(ctx, st))) {
            rep->created = 0;
            goto done;
        }
        es__progress(ctx, "writing store", 1, 1);
    }
    rep->rows_added = b.n;
    rep->rows_total = es_store_nrows(st);
done:
    if (rc != ES_OK) rep->rows_added = 0;
    es_meshdata_clear(ctx, &md);
    es__free(ctx, buf);
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
    es_status rc = ES_OK;
    if (!opts) {
        es_ingest_opts_init(&defaults);
        opts = &defaults;
    }
    if (!report) report = &dummy;
    memset(report, 0, sizeof *report);
    if (nfiles < 1 || !files) ES_FAIL(ctx, ES_EINVAL, "ingest: no files given");
    if (!(in = es__alloc_array(ctx, nfiles, sizeof *in)) ||
        !(ids = es__alloc_array(ctx, nfiles, sizeof *ids))) {
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
        for (int64_t k = 0; k < i; k++)
            if (!strcmp(ids[k], id)) {
                rc = es__fail(ctx, ES_EINVAL, "ingest: '%s' and '%s' would both get the id "
                              "'%s'; use a manifest with an 'id' column", files[k], files[i],
                              id);
                goto done;
            }
        if (!(ids[i] = es__strdup(ctx, id))) { rc = ES_ENOMEM; goto done; }
        in[i].id = ids[i];
        in[i].path = files[i];
        in[i].labels = NULL;
    }
    rc = ingest(ctx, store_path, nfiles, in, 0, NULL, opts, report);
done:
    for (int64_t i = 0; ids && i < nfiles; i++) es__free(ctx, ids[i]);
    es__free(ctx, ids);
    es__free(ctx, in);
    return rc;
}
