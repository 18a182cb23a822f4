/* lib/ingest/ingest.c — meshes (and a manifest's labels) into an HDF5 store.
 *
 * All-or-nothing, in bounded memory. Inputs go through in blocks of rows
 * (about 64 MB of positions and lengths, or es_ingest_opts.block_rows).
 * Each block is read and checked: the file's bytes (hashed for duplicate
 * detection, then parsed from the buffer so the file is read once), its
 * vertex count and face list against the store's (or the first input's, for
 * a new store), and its normalized edge lengths (es_edge_lengths,
 * es_lengths_normalize; Section 4, eq. 12 of Rojas et al.; ingest_read.c).
 * Its rows are then appended to the store's working copy, and the block's memory serves
 * the next block: memory does not grow with the number of inputs beyond a
 * few dozen bytes of ids and hashes per row. Only after the last block is
 * the copy committed, by an atomic rename (lib/store/store_publish.c); any
 * failure, or a kill at any moment, leaves the store as it was. On the
 * ranks of an MPI job the same store is made by ingest_ranks.c.
 */
#include "ingest/ingest_pkg.h"
#include "core/hash.h"
#include "core/strmap.h"
#include "parallel/parallel_private.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
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

/* The rows kept so far, in input order (pointer arrays for all n inputs:
 * the ids and labels are the inputs', the hashes the batch's, the real
 * source paths made here), and the content hashes seen: the store's rows
 * (as it was opened) and the inputs kept (keys borrowed from the store and
 * the batch; a map, not a scan of every earlier row for each input). */
es_status es__ingest_kept_init(es_ctx *ctx, ingest_kept *k, const es_store *st, int64_t n,
                               int64_t ncols)
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

void es__ingest_kept_clear(es_ctx *ctx, ingest_kept *k)
{
    es__strmap_clear(ctx, &k->seen_store);
    es__strmap_clear(ctx, &k->seen_new);
    for (int64_t i = 0; k->sources && i < k->n; i++) es__free(ctx, k->sources[i]);
    es__free(ctx, k->sources);
    es__free(ctx, k->ids);
    es__free(ctx, k->hashes);
    es__free(ctx, k->labels);
}

es_status es__ingest_keep(es_ctx *ctx, const es_store *st, const ingest_input *in, int64_t b0,
                          int64_t b1, int64_t ncols, ingest_batch *b, bool values,
                          ingest_kept *k, es_ingest_report *rep)
{
    es_status rc;
    if (values) es__ingest_compact(b, b0, b1);
    for (int64_t i = b0; i < b1; i++) {
        char real[PATH_MAX];
        int64_t prev;
        if (b->skip[i]) {
            rep->rows_skipped++;
            continue;
        }
        if ((prev = es__strmap_get(&k->seen_store, b->hash[i])) >= 0)
            es__warn(ctx, "'%s' has the same content as row '%s' of the store",
                     in[i].path, es_store_row_id(st, prev));
        if ((rc = es__strmap_put(ctx, &k->seen_new, b->hash[i], k->n, &prev))) return rc;
        if (prev >= 0)
            es__warn(ctx, "'%s' has the same content as '%s'", in[i].path, k->sources[prev]);
        k->ids[k->n] = in[i].id;
        k->hashes[k->n] = b->hash[i];
        for (int64_t c = 0; c < ncols; c++) k->labels[k->n * ncols + c] = in[i].labels[c];
        if (!(k->sources[k->n] = es__strdup(ctx, realpath(in[i].path, real) ? real : in[i].path)))
            return ES_ENOMEM;
        k->n++;
    }
    return ES_OK;
}

/* Inputs [b0, b1), read into the batch: kept (es__ingest_keep) and
 * appended to the store's working copy (made now, for a new store). */
static es_status keep_block(es_ctx *ctx, const char *store_path, ingest_session *s,
                            const ingest_input *in, int64_t b0, int64_t b1, int64_t ncols,
                            const char *const *colnames, ingest_kept *k, es_ingest_report *rep)
{
    const int64_t k0 = k->n;
    ingest_batch *b = &s->b;
    es_status rc;
    if ((rc = es__ingest_keep(ctx, s->st, in, b0, b1, ncols, b, true, k, rep))) return rc;
    if (k->n == k0) return ES_OK;
    if (!s->st && (rc = es_store_create(ctx, store_path, s->r.mesh, &s->st))) return rc;
    es_store_rows rows = {k->n - k0, k->ids + k0, (const char *const *)(k->sources + k0),
                          k->hashes + k0, b->len, b->scale, b->xyz, ncols, colnames,
                          k->labels + k0 * ncols};
    return es_store_append(ctx, s->st, &rows);
}

static es_status ingest(es_ctx *ctx, const char *store_path, int64_t n, const ingest_input *in,
                        int64_t ncols, const char *const *colnames, const es_ingest_opts *o,
                        es_ingest_report *rep)
{
    ingest_session s;
    ingest_kept k;
    es_status rc = ES_OK;
    bool created;
    memset(&s, 0, sizeof s);
    memset(&k, 0, sizeof k);
    memset(rep, 0, sizeof *rep);
    if (!store_path || !*store_path) ES_FAIL(ctx, ES_EINVAL, "ingest: no store path");
    if (n < 1) ES_FAIL(ctx, ES_EINVAL, "ingest: no meshes to ingest");
    if (ncols > ES_STORE_MAX_COLUMNS)   /* (the store's refusal, before any mesh is read) */
        ES_FAIL(ctx, ES_ERANGE, "ingest: %lld label columns; a store holds at most %d",
                (long long)ncols, ES_STORE_MAX_COLUMNS);
    created = access(store_path, F_OK) != 0;
    if (created && !o->create)
        ES_FAIL(ctx, ES_ENOTFOUND, "ingest: store '%s' does not exist", store_path);
    if (es__par_size(ctx) > 1)
        return es__ingest_ranks(ctx, store_path, n, in, ncols, colnames, o, rep);
    if ((rc = es__ingest_begin(ctx, &s, store_path, ES_STORE_WRITE, in, n, n, o)) ||
        (rc = es__ingest_kept_init(ctx, &k, s.st, n, ncols)))
        goto done;

    /* ---- block by block: read and check, then write to the working copy ---- */
    for (int64_t b0 = 0; b0 < n; b0 += s.b.cap) {
        const int64_t b1 = n - b0 > s.b.cap ? b0 + s.b.cap : n;
        rc = es__ingest_read_block(ctx, &s, b0, b1, NULL);
        rep->bytes_read = rep->bytes_read_rank = s.j.bytes_read;
        if (rc || (rc = es__cancelled(ctx, "ingest")) ||
            (rc = keep_block(ctx, store_path, &s, in, b0, b1, ncols, colnames, &k, rep)))
            goto done;
    }
    es__progress(ctx, "reading meshes", n, n);

    /* ---- publish the working copy, atomically ---- */
    if (k.n > 0) {
        es__progress(ctx, "writing store", 0, 1);
        if ((rc = es_store_commit(ctx, s.st))) goto done;
        es__progress(ctx, "writing store", 1, 1);
    }
    rep->created = created;
    rep->rows_added = k.n;
    rep->rows_total = es_store_nrows(s.st);
done:
    if (rc != ES_OK) rep->rows_added = 0;
    es__ingest_kept_clear(ctx, &k);
    if (rc != ES_OK) es_store_abort(s.st);
    else es_store_close(s.st);
    es__ingest_end(ctx, &s);
    return rc;
}

es_status es_ingest_manifest(es_ctx *ctx, const char *store_path, const char *manifest_path,
                             const es_ingest_opts *opts, es_ingest_report *report)
{
    es_ingest_opts defaults;
    es_ingest_report dummy;
    es_manifest *m = NULL;
    ingest_input *in = NULL;
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
    ingest_input *in = NULL;
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
