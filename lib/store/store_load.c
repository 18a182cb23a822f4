/* lib/store/store_load.c — what opening a store reads and checks: the
 * format version and topology kind, every dataset's type, shape and row
 * count against the others and against the bytes the file holds for it, the
 * topology's indices (faces inside the vertex range, edges canonical,
 * sorted, unique and, in a mesh store, exactly the edges of the faces), the
 * scales, and the row metadata (ids, source paths, content hashes, label
 * columns) that the handle keeps in memory.
 *
 * A store is a file users exchange, so nothing in it is trusted: each check
 * runs once, here, before any array sized by the file is allocated or used,
 * and a failure names the store, the dataset and what disagrees. The bulk
 * data (lengths, positions) is not read at open; its readers check what
 * they read (store_rows.c). Strings go through lib/h5/h5_vlen.c, never through
 * HDF5's global heap reader.
 */
#include "store/store_pkg.h"

#include <math.h>
#include <stdlib.h>

/* Dataset `name` must exist with type class cls, the given rank and
 * trailing dimensions (d1, d2), and storage for all of its rows (elem: bytes
 * per element on disk); its row count goes to *rows. what: "F x 3
 * integers", for messages. */
static es_status check_ds(es_store *s, es__h5_raw *raw, const char *name, es__h5_class cls,
                          int rank, uint64_t d1, uint64_t d2, const char *what, int64_t *rows)
{
    es_ctx *ctx = s->ctx;
    es__h5_info in;
    const uint64_t *dims = in.dims;
    es__h5_id ds = -1;
    es_status rc = ES_OK;
    uint64_t elem = 0, need = 1, have;
    *rows = -1;
    if ((rc = es__h5_check_named(raw, s->file, name))) return rc;
    if ((ds = es__h5_dataset_open(s->file, name)) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: '%s': %s is missing or unreadable", s->path, name);
    if (es__h5_dataset_info(ds, &in) < 0 || in.rank != rank || in.cls != cls ||
        (rank > 1 && dims[1] != d1) || (rank > 2 && dims[2] != d2)) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': %s is not %s", s->path, name, what);
        goto done;
    }
    elem = in.vlen ? es__h5_raw_vlen_size(raw) : in.size;
    if ((rc = es__h5_check_chunks(ctx, ds, s->path, name, elem))) goto done;
    for (int k = 0; k < rank; k++)
        if (__builtin_mul_overflow(need, (uint64_t)dims[k], &need)) need = UINT64_MAX;
    if (__builtin_mul_overflow(need, elem, &need)) need = UINT64_MAX;
    /* a count the file cannot hold (20 million rows of a 132 KB store) is
     * refused here, before anything of that size is allocated */
    have = es__h5_covered_bytes(ds, rank, elem);
    if (dims[0] > (uint64_t)INT64_MAX || (need > 0 && have < need)) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: %s claims %llu rows (%llu "
                      "bytes) but the file holds %llu bytes of it", s->path, name,
                      (unsigned long long)dims[0], (unsigned long long)need,
                      (unsigned long long)have);
        goto done;
    }
    *rows = (int64_t)dims[0];
done:
    es__h5_close(ds);
    return rc;
}

/* A whole integer (i) or real (f) dataset, already checked by check_ds. */
static es_status read_all(es_store *s, const char *name, double *f, int64_t *i)
{
    if ((f ? es__h5_read_f64(s->file, name, f) : es__h5_read_i64(s->file, name, i)) < 0)
        return es__h5_fail(s->ctx, ES_EFORMAT, "store: cannot read %s of '%s'", name, s->path);
    return ES_OK;
}

static int cmp_edge(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    return x[0] != y[0] ? (x[0] < y[0] ? -1 : 1) : (x[1] < y[1] ? -1 : x[1] > y[1]);
}

/* Faces inside [0, V) with three distinct corners; edges (min, max) below
 * V, strictly sorted; in a mesh store, the edges are exactly those of the
 * faces (each stored edge in some face, each face's edges stored). */
static es_status check_topology(es_store *s)
{
    es_ctx *ctx = s->ctx;
    const int64_t V = s->nverts, F = s->nfaces, E = s->nedges;
    int64_t *faces = NULL, *edges = NULL;
    unsigned char *used = NULL;
    es_status rc = ES_OK;
    if (!(faces = es__alloc_array(ctx, 3 * F + 1, sizeof *faces)) ||
        !(edges = es__alloc_array(ctx, 2 * E + 1, sizeof *edges)) ||
        !(used = es__calloc(ctx, (size_t)E + 1, 1))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((F > 0 && (rc = read_all(s, "/topology/faces", NULL, faces))) ||
        (E > 0 && (rc = read_all(s, "/topology/edges", NULL, edges))))
        goto done;
    for (int64_t f = 0; f < F; f++) {
        const int64_t *c = faces + 3 * f;
        if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= V || c[1] >= V || c[2] >= V ||
            c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: /topology/faces row %lld is "
                          "(%lld, %lld, %lld), not three distinct vertices below %lld", s->path,
                          (long long)f, (long long)c[0], (long long)c[1], (long long)c[2],
                          (long long)V);
            goto done;
        }
    }
    for (int64_t e = 0; e < E; e++) {
        const int64_t *p = edges + 2 * e;
        if (p[0] < 0 || p[0] >= p[1] || p[1] >= V || (e > 0 && cmp_edge(p - 2, p) >= 0)) {
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: /topology/edges row %lld is "
                          "(%lld, %lld), not a (min, max) pair of vertices below %lld after "
                          "the previous one", s->path, (long long)e, (long long)p[0],
                          (long long)p[1], (long long)V);
            goto done;
        }
    }
    /* stored edges are sorted: each face edge is found by bisection */
    for (int64_t f = 0; f < F; f++)
        for (int k = 0; k < 3; k++) {
            int64_t a = faces[3 * f + k], b = faces[3 * f + (k + 1) % 3];
            int64_t key[2] = {a < b ? a : b, a < b ? b : a};
            const int64_t *hit = bsearch(key, edges, (size_t)E, 2 * sizeof *edges, cmp_edge);
            if (!hit) {
                rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: /topology/edges lacks "
                              "the edge (%lld, %lld) of face %lld", s->path,
                              (long long)key[0], (long long)key[1], (long long)f);
                goto done;
            }
            used[(hit - edges) / 2] = 1;
        }
    for (int64_t e = 0; F > 0 && e < E; e++)
        if (!used[e]) {
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: /topology/edges row %lld "
                          "(%lld, %lld) is in no face", s->path, (long long)e,
                          (long long)edges[2 * e], (long long)edges[2 * e + 1]);
            goto done;
        }
done:
    es__free(ctx, faces);
    es__free(ctx, edges);
    es__free(ctx, used);
    return rc;
}

static es_status load_columns(es_store *s, es__h5_raw *raw)
{
    es_ctx *ctx = s->ctx;
    es__h5_id g = -1;
    char **names = NULL;
    int64_t n = 0, rows;
    es_status rc = ES_OK;
    if ((g = es__h5_group_open(s->file, "/labels")) < 0)
        return es__h5_fail(ctx, ES_EFORMAT, "store: '%s' has no /labels group", s->path);
    if ((rc = es__h5_read_attr_strings(ctx, raw, g, "columns", &names, &n))) {
        if (rc == ES_ENOTFOUND)
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s': /labels lacks its 'columns' attribute",
                          s->path);
        goto done;
    }
    for (int64_t c = 0; c < n; c++) {
        char full[600];
        if (es__h5_bad_name(names[c]) || strlen(names[c]) > ES__MAX_COLUMN_NAME) {
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s': /labels column %lld has the bad name "
                          "'%.40s'", s->path, (long long)c, names[c]);
            goto done;
        }
        for (int64_t d = 0; d < c; d++)
            if (!strcmp(names[c], names[d])) {
                rc = es__fail(ctx, ES_EFORMAT, "store: '%s': /labels column '%s' is listed "
                              "twice", s->path, names[c]);
                goto done;
            }
        snprintf(full, sizeof full, "/labels/%s", names[c]);
        if ((rc = check_ds(s, raw, full, ES__H5_CLASS_STRING, 1, 0, 0, "N strings", &rows)))
            goto done;
        if (rows != s->nrows) {
            rc = es__fail(ctx, ES_EFORMAT, "store: '%s': %s has %lld rows, /shapes/ids %lld",
                          s->path, full, (long long)rows, (long long)s->nrows);
            goto done;
        }
    }
    if (n > 0 && (!(s->colnames = es__alloc_array(ctx, n, sizeof *s->colnames)) ||
                  !(s->labels = es__alloc_array(ctx, n, sizeof *s->labels)))) {
        rc = ES_ENOMEM;
        goto done;
    }
    for (int64_t c = 0; c < n; c++) s->labels[c] = NULL;
    for (int64_t c = 0; c < n; c++) {
        s->colnames[c] = names[c];   /* handed over: freed with the handle */
        names[c] = NULL;
        s->ncols = c + 1;
        if (!(s->labels[c] = es__alloc_array(ctx, s->cap ? s->cap : 1, sizeof(char *)))) {
            rc = ES_ENOMEM;
            break;
        }
        memset(s->labels[c], 0, (size_t)(s->cap ? s->cap : 1) * sizeof(char *));
        if ((rc = es__h5_read_strings(ctx, raw, g, s->colnames[c], s->nrows, s->labels[c])))
            break;
    }
done:
    for (int64_t c = 0; names && c < n; c++) es__free(ctx, names[c]);
    es__free(ctx, names);
    es__h5_close(g);
    return rc;
}

/* The row metadata: ids (non-empty, unique), source paths, hashes. */
static es_status load_rows(es_store *s, es__h5_raw *raw)
{
    es_ctx *ctx = s->ctx;
    es_status rc;
    int64_t n = s->nrows;
    s->nrows = 0;
    if ((rc = es__store_reserve_rows(s, n > 0 ? n : 1))) return rc;
    s->nrows = n;
    if ((rc = es__h5_read_strings(ctx, raw, s->file, "/shapes/ids", n, s->ids)) ||
        (rc = es__h5_read_strings(ctx, raw, s->file, "/shapes/source_paths", n, s->sources)) ||
        (rc = es__h5_read_strings(ctx, raw, s->file, "/shapes/content_hash", n, s->hashes)))
        return rc;
    for (int64_t i = 0; i < n; i++)
        if (!*s->ids[i])
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /shapes/ids row %lld is empty", s->path,
                    (long long)i);
    return es__store_index_ids(s);
}

static es_status check_scales(es_store *s)
{
    double *sc;
    es_status rc;
    if (s->nedges == 0 || s->nrows == 0) return ES_OK;
    if (!(sc = es__alloc_array(s->ctx, s->nrows, sizeof *sc))) return ES_ENOMEM;
    if (!(rc = read_all(s, "/shapes/scales", sc, NULL)))
        for (int64_t i = 0; i < s->nrows; i++)
            if (!(sc[i] > 0) || !isfinite(sc[i])) {
                rc = es__fail(s->ctx, ES_EFORMAT, "store: '%s' is corrupt: /shapes/scales row "
                              "%lld is %g (must be finite and > 0)", s->path, (long long)i,
                              sc[i]);
                break;
            }
    es__free(s->ctx, sc);
    return rc;
}

static es_status load_kind(es_store *s, es__h5_raw *raw)
{
    es_ctx *ctx = s->ctx;
    int64_t version = 0;
    char kind[16];
    if (es__h5_read_attr_i64(ctx, s->file, "the root group", "format_version", &version))
        return es__fail(ctx, ES_EFORMAT, "store: '%s' is not an edgespace store (%s)", s->path,
                        es_ctx_errmsg(ctx));
    if (version != ES__FORMAT_VERSION && version != ES__FORMAT_VERSION_KIND &&
        version != ES__FORMAT_VERSION_BESIDE)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' has format version %lld; this edgespace reads "
                "versions %d to %d", s->path, (long long)version, ES__FORMAT_VERSION,
                ES__FORMAT_VERSION_BESIDE);
    s->kind = ES_TOPOLOGY_MESH;
    s->version = (int)version;
    if (version == ES__FORMAT_VERSION) return ES_OK;
    if (version == ES__FORMAT_VERSION_BESIDE) {
        size_t n;
        es_status rc = es__h5_read_attr_text(ctx, raw, s->file, "store_id", s->store_id,
                                             sizeof s->store_id);
        if (rc == ES_ENOMEM) return rc;
        if (rc || (n = strlen(s->store_id)) < 8 || strspn(s->store_id, "0123456789abcdef") != n)
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s' has format version 3 but no store_id of "
                    "hex digits", s->path);
        s->beside = true;
    }
    es_status krc = es__h5_read_attr_text(ctx, raw, s->file, "topology_kind", kind, sizeof kind);
    if (krc == ES_ENOMEM) return krc;
    if (krc)
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' has format version %lld but no topology_kind "
                "attribute", s->path, (long long)version);
    if (!strcmp(kind, "mesh")) s->kind = ES_TOPOLOGY_MESH;
    else if (!strcmp(kind, "truss")) s->kind = ES_TOPOLOGY_TRUSS;
    else if (!strcmp(kind, "none")) s->kind = ES_TOPOLOGY_NONE;
    else
        ES_FAIL(ctx, ES_EFORMAT, "store: '%s' has topology_kind '%s' (want mesh, truss or "
                "none)", s->path, kind);
    return ES_OK;
}

/* The per-row datasets all hold n rows, of E lengths and V x 3 positions. */
static es_status check_shapes(es_store *s, es__h5_raw *raw, int64_t *n)
{
    es_ctx *ctx = s->ctx;
    static const char *const strs[3] = {"/shapes/ids", "/shapes/source_paths",
                                        "/shapes/content_hash"};
    char what[64];
    int64_t r;
    es_status rc;
    snprintf(what, sizeof what, "N x %lld x 3 reals", (long long)s->nverts);
    if ((rc = check_ds(s, raw, "/shapes/positions", ES__H5_CLASS_FLOAT, 3, (uint64_t)s->nverts,
                       3, what, n)))
        return rc;
    if (s->kind != ES_TOPOLOGY_NONE) {
        snprintf(what, sizeof what, "N x %lld reals", (long long)s->nedges);
        if ((rc = check_ds(s, raw, "/shapes/lengths", ES__H5_CLASS_FLOAT, 2,
                           (uint64_t)s->nedges, 0, what, &r)))
            return rc;
        if (r != *n)
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /shapes/lengths has %lld rows, "
                    "/shapes/positions %lld", s->path, (long long)r, (long long)*n);
        if ((rc = check_ds(s, raw, "/shapes/scales", ES__H5_CLASS_FLOAT, 1, 0, 0, "N reals", &r)))
            return rc;
        if (r != *n)
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s': /shapes/scales does not have %lld rows",
                    s->path, (long long)*n);
    }
    for (int k = 0; k < 3; k++) {
        if ((rc = check_ds(s, raw, strs[k], ES__H5_CLASS_STRING, 1, 0, 0, "N strings", &r)))
            return rc;
        if (r != *n)
            ES_FAIL(ctx, ES_EFORMAT, "store: '%s': %s has %lld rows, /shapes/positions %lld",
                    s->path, strs[k], (long long)r, (long long)*n);
    }
    return ES_OK;
}

/* The groups every open looks names up in: the root, then each of the
 * store's groups, each header and symbol table checked before HDF5
 * searches the group, opens it or decodes its attributes (h5_headers.c,
 * h5_groups.c). */
static es_status check_groups(es_store *s, es__h5_raw *raw)
{
    static const char *const names[] = {"/topology", "/shapes", "/labels", "/analysis"};
    return es__h5_check_groups(raw, s->file, names, sizeof names / sizeof names[0]);
}

es_status es__store_load(es_store *s)
{
    es_ctx *ctx = s->ctx;
    es__h5_raw *raw = NULL;
    int64_t n = 0;
    es_status rc;
    es__h5_id g;
    char fp[64];
    if ((rc = es__h5_raw_open(ctx, s->file, s->path, &raw))) return rc;
    if ((rc = check_groups(s, raw)) || (rc = load_kind(s, raw))) goto done;
    if ((g = es__h5_group_open(s->file, "/topology")) < 0) {
        rc = es__h5_fail(ctx, ES_EFORMAT, "store: '%s' has no /topology", s->path);
        goto done;
    }
    rc = es__h5_read_attr_i64(ctx, g, "/topology", "nverts", &s->nverts);
    if (!rc) rc = es__h5_read_attr_text(ctx, raw, g, "fingerprint", fp, sizeof fp);
    es__h5_close(g);
    if (rc) goto done;
    snprintf(s->fingerprint, sizeof s->fingerprint, "%.16s", fp);
    /* every vertex has 24 bytes of positions in each row; an empty store
     * has no rows to bound it, so the file's size does */
    if (s->nverts < 1 || (uint64_t)s->nverts > es__h5_raw_file_size(raw)) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s' is corrupt: /topology says %lld vertices",
                      s->path, (long long)s->nverts);
        goto done;
    }
    if ((rc = check_ds(s, raw, "/topology/faces", ES__H5_CLASS_INTEGER, 2, 3, 0, "F x 3 integers",
                       &s->nfaces)) ||
        (rc = check_ds(s, raw, "/topology/edges", ES__H5_CLASS_INTEGER, 2, 2, 0, "E x 2 integers",
                       &s->nedges)))
        goto done;
    if ((s->kind == ES_TOPOLOGY_MESH) != (s->nfaces > 0) ||
        (s->kind == ES_TOPOLOGY_NONE) != (s->nedges == 0)) {
        rc = es__fail(ctx, ES_EFORMAT, "store: '%s': topology kind '%s' with %lld faces and %lld "
                      "edges", s->path, es_topology_kind_name(s->kind), (long long)s->nfaces,
                      (long long)s->nedges);
        goto done;
    }
    if ((rc = check_topology(s)) || (rc = check_shapes(s, raw, &n))) goto done;
    s->nrows = n;
    if ((rc = check_scales(s)) || (rc = load_rows(s, raw))) goto done;
    rc = load_columns(s, raw);
done:
    es__h5_raw_close(raw);
    return rc;
}
