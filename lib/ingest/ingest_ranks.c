/* lib/ingest/ingest_ranks.c — mesh ingest on the ranks of an MPI job: the
 * store one process makes (ingest.c), each rank reading and measuring a
 * contiguous share of the inputs, the values written with collective
 * parallel-HDF5 writes (lib/store/store_ranks.c).
 *
 * 1. Every rank opens the store (rank 0 for writing, the others read-only)
 *    or, for a new one, reads the first input for the topology.
 * 2. The store rows the inputs will take: an input whose id is in the store
 *    already with the same content is skipped, as in one process, and only
 *    those inputs (ids the store has) are read now, for their hash; the
 *    skip flags of all shares go to every rank, so every rank knows the row
 *    of each kept input (the store's rows, then the kept inputs in input
 *    order).
 * 3. Rank 0 makes room for the kept rows in its working copy; every rank
 *    opens it with the MPI-IO driver.
 * 4. In rounds (the same count on every rank) each rank reads and checks a
 *    block of its share on threads (ingest_read.c: about 64 MB, the memory
 *    of one process's ingest) and all write their block's kept rows with
 *    one collective write per dataset. A failure on any rank (a bad mesh
 *    file: its message names the file and line) is agreed on by all ranks
 *    after the round, before anything more is written.
 * 5. The hashes and the other ranks' warnings go to rank 0, which warns of
 *    repeated contents, appends the rows' ids, sources, hashes and labels
 *    and commits: the working copy replaces the store, or becomes the new
 *    store, in one rename. On any failure, or if any rank is killed (mpirun
 *    then ends every rank), the store is as it was, or not made: only the
 *    working copy, a temporary sibling, was written.
 * Reading is shared; rank 0 alone writes the strings (a few dozen bytes a
 * row) and commits. Warnings come in input order, the repeated-content
 * ones last.
 */
#include "ingest/ingest_pkg.h"
#include "parallel/parallel_private.h"
#include "store/store_private.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Step 2 on this rank's share [lo, hi): the inputs the store holds by id. */
static es_status find_skipped(es_ctx *ctx, ingest_session *s, int64_t lo, int64_t hi)
{
    char *buf = NULL;
    size_t cap = 0, len;
    es_status rc = ES_OK;
    for (int64_t i = lo; s->st && i < hi && rc == ES_OK; i++) {
        int skip = 0;
        if (es_store_find_row(s->st, s->j.in[i].id) < 0) continue;
        if ((rc = es__ingest_slurp(ctx, s->j.in[i].path, &buf, &cap, &len)) == ES_OK) {
            s->j.bytes_read += (int64_t)len;   /* and again in its round */
            es_content_hash(buf, len, s->b.hash[i]);
            rc = es__ingest_known(ctx, s->st, &s->j.in[i], s->b.hash[i], &skip);
            s->b.skip[i] = (uint8_t)skip;
        }
    }
    es__free(ctx, buf);
    return rc;
}

/* Every rank's share of per-input bytes (elem each) onto every rank. */
static es_status share_all(es_ctx *ctx, void *v, size_t elem, int64_t n)
{
    es_status rc = ES_OK;
    for (int q = 0; q < es__par_size(ctx) && rc == ES_OK; q++) {
        int64_t a, b;
        es__par_split(n, es__par_size(ctx), q, &a, &b);
        rc = es__par_bcast(ctx, (char *)v + (size_t)a * elem, (size_t)(b - a) * elem, q);
    }
    return rc;
}

/* The other ranks' warnings, said on rank 0 in rank (= input) order. */
static es_status forward_warnings(es_ctx *ctx, const ingest_text *mine)
{
    es_status rc = ES_OK;
    for (int q = 1; q < es__par_size(ctx) && rc == ES_OK; q++) {
        int64_t len = es__par_rank(ctx) == q ? (int64_t)mine->n : 0;
        char *text;
        if ((rc = es__par_bcast(ctx, &len, sizeof len, q)) || len == 0) continue;
        text = es__malloc(ctx, (size_t)len + 1);
        if ((rc = es__par_agree(ctx, text ? ES_OK : ES_ENOMEM))) {
            es__free(ctx, text);
            break;
        }
        if (es__par_rank(ctx) == q) memcpy(text, mine->p, (size_t)len);
        text[len] = '\0';
        rc = es__par_bcast(ctx, text, (size_t)len, q);
        for (char *line = text, *nl; rc == ES_OK && es__par_rank(ctx) == 0 && *line;
             line = nl + 1) {
            if (!(nl = strchr(line, '\n'))) break;
            *nl = '\0';
            es__warn(ctx, "%s", line);
        }
        es__free(ctx, text);
    }
    return rc;
}

/* Steps 3 and 4: the kept rows' values into rank 0's working copy. dest[i]
 * is the store row of input i if kept (the store's rows before it plus the
 * inputs kept before it). */
static es_status write_values(es_ctx *ctx, ingest_session *s, int64_t lo, int64_t hi,
                              const int64_t *dest, int64_t nkept, ingest_text *notes)
{
    const int writer = es__par_rank(ctx) == 0;
    es__store_ranks *h = NULL;
    int64_t rounds = (hi - lo + s->b.cap - 1) / s->b.cap;
    es_status rc = ES_OK, crc;
    if (writer) {
        if (!s->st) rc = es_store_create(ctx, s->path, s->r.mesh, &s->st);
        if (rc == ES_OK) rc = es__store_reserve_values(ctx, s->st, nkept);
    }
    if ((rc = es__par_agree(ctx, rc)) ||
        (rc = es__store_ranks_open(ctx, writer ? s->st : NULL, &h)) ||
        (rc = es__par_max_i64(ctx, &rounds, 1)))
        goto done;
    for (int64_t t = 0; t < rounds && rc == ES_OK; t++) {
        int64_t b0 = lo + t * s->b.cap < hi ? lo + t * s->b.cap : hi;
        int64_t b1 = hi - b0 > s->b.cap ? b0 + s->b.cap : hi, m;
        rc = es__ingest_read_block(ctx, s, b0, b1, writer ? NULL : notes);
        if (rc == ES_OK) rc = es__cancelled(ctx, "ingest");
        if ((rc = es__par_agree(ctx, rc))) break;
        m = es__ingest_compact(&s->b, b0, b1);
        rc = es__store_ranks_write(ctx, h, b0 < hi ? dest[b0] : 0, m, s->b.len, s->b.scale,
                                   s->b.xyz);
    }
done:
    crc = es__store_ranks_close(ctx, writer ? s->st : NULL, h);
    return rc ? rc : crc;
}

es_status es__ingest_ranks(es_ctx *ctx, const char *store_path, int64_t n,
                           const ingest_input *in, int64_t ncols, const char *const *colnames,
                           const es_ingest_opts *o, es_ingest_report *rep)
{
    const int P = es__par_size(ctx), writer = es__par_rank(ctx) == 0;
    ingest_session s;
    ingest_kept k;
    ingest_text notes = {0};
    int64_t lo, hi, n0, nkept = 0, *dest = NULL, created;
    es_status rc;
    memset(&k, 0, sizeof k);
    es__par_split(n, P, es__par_rank(ctx), &lo, &hi);
    rc = es__ingest_begin(ctx, &s, store_path, writer ? ES_STORE_WRITE : ES_STORE_READ, in, n,
                          hi - lo, o);
    if ((rc = es__par_agree(ctx, rc))) goto done;
    /* whether the store is new: as rank 0 found it */
    created = writer ? s.st == NULL : 0;
    n0 = s.st ? es_store_nrows(s.st) : 0;
    if ((rc = es__par_bcast(ctx, &created, sizeof created, 0)) ||
        (rc = es__par_bcast(ctx, &n0, sizeof n0, 0)))
        goto done;
    if ((created != 0) != (s.st == NULL))
        rc = es__fail(ctx, ES_EIO, "ingest: store '%s' appeared or vanished while the ranks "
                      "opened it", store_path);

    /* step 2: the rows the kept inputs take */
    if (rc == ES_OK) rc = find_skipped(ctx, &s, lo, hi);
    if ((rc = es__par_agree(ctx, rc)) || (rc = share_all(ctx, s.b.skip, 1, n))) goto done;
    if ((rc = es__par_agree(ctx, (dest = es__alloc_array(ctx, n, sizeof *dest)) ? ES_OK
                                                                               : ES_ENOMEM)))
        goto done;
    for (int64_t i = 0; i < n; i++) {
        dest[i] = n0 + nkept;
        nkept += !s.b.skip[i];
    }

    /* steps 3 and 4: the values, written by all ranks together */
    if (nkept > 0 && (rc = write_values(ctx, &s, lo, hi, dest, nkept, &notes))) goto done;
    rep->bytes_read = rep->bytes_read_rank = s.j.bytes_read;
    if ((rc = es__par_sum_i64(ctx, &rep->bytes_read, 1))) goto done;
    es__progress(ctx, "reading meshes", n, n);

    /* step 5: rank 0 warns, appends the rows' strings and commits */
    if ((rc = share_all(ctx, s.b.hash, sizeof *s.b.hash, n)) ||
        (rc = forward_warnings(ctx, &notes)))
        goto done;
    if (writer && nkept > 0) {
        if ((rc = es__ingest_kept_init(ctx, &k, s.st, n, ncols)) == ES_OK &&
            (rc = es__ingest_keep(ctx, s.st, in, 0, n, ncols, &s.b, false, &k, rep)) == ES_OK) {
            es_store_rows rows = {k.n, k.ids, (const char *const *)k.sources, k.hashes, NULL,
                                  NULL, NULL, ncols, colnames, k.labels};
            es__progress(ctx, "writing store", 0, 1);
            if ((rc = es__store_append_written(ctx, s.st, &rows)) == ES_OK &&
                (rc = es_store_commit(ctx, s.st)) == ES_OK)
                es__progress(ctx, "writing store", 1, 1);
        }
    }
    rc = es__par_agree(ctx, rc);
done:
    rep->created = created != 0;
    rep->rows_added = rc == ES_OK ? nkept : 0;
    rep->rows_skipped = rc == ES_OK ? n - nkept : 0;
    rep->rows_total = rc == ES_OK ? n0 + nkept : n0;
    es__ingest_kept_clear(ctx, &k);
    if (rc != ES_OK) es_store_abort(s.st);   /* rank 0: the working copy removed */
    else es_store_close(s.st);
    es__ingest_end(ctx, &s);
    free(notes.p);
    es__free(ctx, dest);
    return rc;
}
