/* lib/ingest/export.c — rows of a store back out: edge lengths as CSV (for
 * spreadsheets, R, pandas) and stored positions as mesh files. The CSV
 * prints %.17g so that every double reads back to the same bits. */
#include "core/core_private.h"
#include "core/files.h"
#include "edgespace/es_ingest.h"
#include "edgespace/es_io.h"
#include "edgespace/es_store.h"
#include "meshio/meshio_private.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

/* rows/nrows as given, or all rows (allocated into *own). */
static es_status row_list(es_ctx *ctx, es_store *s, const int64_t *rows, int64_t nrows,
                          const int64_t **out, int64_t *n, int64_t **own)
{
    *own = NULL;
    if (rows) {
        for (int64_t j = 0; j < nrows; j++)
            if (rows[j] < 0 || rows[j] >= es_store_nrows(s))
                ES_FAIL(ctx, ES_ERANGE, "export: row %lld is out of range", (long long)rows[j]);
        *out = rows;
        *n = nrows;
        return ES_OK;
    }
    *n = es_store_nrows(s);
    if (!(*own = es__alloc_array(ctx, *n ? *n : 1, sizeof **own))) return ES_ENOMEM;
    for (int64_t i = 0; i < *n; i++) (*own)[i] = i;
    *out = *own;
    return ES_OK;
}

es_status es_export_lengths_csv(es_ctx *ctx, es_store *s, const int64_t *rows, int64_t nrows,
                                int raw, const char *path)
{
    int64_t E, n, *own = NULL, *edges = NULL;
    const int64_t *list;
    double *len = NULL, *scales = NULL;
    es_status rc;
    es__file_replace w = {0};
    FILE *f = NULL;
    if (!s || !path) ES_FAIL(ctx, ES_EINVAL, "export: NULL argument");
    E = es_store_nedges(s);
    if (E < 1)
        ES_FAIL(ctx, ES_EINVAL, "export: store '%s' has no edges: it holds landmarks only; give "
                "--edges or --triangles at ingest", es_store_path(s));
    {
        /* Never truncate the store itself (export STORE --lengths STORE), nor
         * another store */
        struct stat so, sp;
        if (stat(es_store_path(s), &so) == 0 && stat(path, &sp) == 0 &&
            so.st_dev == sp.st_dev && so.st_ino == sp.st_ino)
            ES_FAIL(ctx, ES_EINVAL, "export: '%s' is the store itself; not overwriting it", path);
        if (es_store_is_hdf5(path))
            ES_FAIL(ctx, ES_EINVAL, "export: '%s' is an HDF5 file (a store?); not overwriting it "
                    "with CSV", path);
    }
    if ((rc = row_list(ctx, s, rows, nrows, &list, &n, &own))) return rc;
    if (!(len = es__alloc_array(ctx, E, sizeof *len)) ||
        !(edges = es__alloc_array(ctx, 2 * E, sizeof *edges)) ||
        !(scales = es__alloc_array(ctx, es_store_nrows(s) ? es_store_nrows(s) : 1,
                                   sizeof *scales))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es_store_read_edges(ctx, s, edges)) || (rc = es_store_read_scales(ctx, s, scales)))
        goto done;
    /* a failed export leaves a file that was there before as it was */
    if ((rc = es__replace_begin(ctx, path, &w))) goto done;
    f = w.f;
    fputs("id,scale", f);
    for (int64_t e = 0; e < E; e++)
        fprintf(f, ",%lld-%lld", (long long)edges[2 * e], (long long)edges[2 * e + 1]);
    fputc('\n', f);
    for (int64_t j = 0; j < n; j++) {
        es_mat m = {len, E, 1, E};
        const char *id = es_store_row_id(s, list[j]);
        double sc = scales[list[j]];
        if ((rc = es__progress(ctx, "exporting lengths", j, n))) goto done;
        if ((rc = es_store_read_lengths(ctx, s, list[j], 1, m))) goto done;
        es_csv_write_field(f, id);
        fprintf(f, ",%.17g", sc);
        for (int64_t e = 0; e < E; e++) fprintf(f, ",%.17g", raw ? sc * len[e] : len[e]);
        fputc('\n', f);
    }
    es__progress(ctx, "exporting lengths", n, n);
done:
    rc = es__replace_end(ctx, &w, rc);
    es__free(ctx, own);
    es__free(ctx, len);
    es__free(ctx, edges);
    es__free(ctx, scales);
    return rc;
}

es_status es_export_meshes(es_ctx *ctx, es_store *s, const int64_t *rows, int64_t nrows,
                           const char *dir, es_mesh_format format)
{
    int64_t n, *own = NULL, *faces = NULL;
    const int64_t *list;
    double *xyz = NULL;
    es_status rc;
    const char *ext;
    if (!s || !dir) ES_FAIL(ctx, ES_EINVAL, "export: NULL argument");
    switch (format) {
    case ES_FORMAT_PLY: case ES_FORMAT_PLY_ASCII: ext = "ply"; break;
    case ES_FORMAT_OFF: ext = "off"; break;
    case ES_FORMAT_STL: ext = "stl"; break;
    case ES_FORMAT_GLB: ext = "glb"; break;
    default: ext = "obj"; format = ES_FORMAT_OBJ; break;
    }
    if ((rc = es__mkdir_p(ctx, dir)) != ES_OK)
        return es__fail(ctx, rc, "export: %s", es_ctx_errmsg(ctx));
    if ((rc = row_list(ctx, s, rows, nrows, &list, &n, &own))) return rc;
    if (!(xyz = es__alloc_array(ctx, 3 * es_store_nverts(s), sizeof *xyz)) ||
        !(faces = es__alloc_array(ctx, 3 * es_store_nfaces(s), sizeof *faces))) {
        rc = ES_ENOMEM;
        goto done;
    }
    if ((rc = es_store_read_faces(ctx, s, faces))) goto done;
    for (int64_t j = 0; j < n; j++) {
        const char *id = es_store_row_id(s, list[j]);
        size_t len = strlen(dir) + strlen(id) + 8;
        char *path;
        if ((rc = es__progress(ctx, "exporting meshes", j, n))) goto done;
        if (strchr(id, '/') || !strcmp(id, ".") || !strcmp(id, "..")) {
            rc = es__fail(ctx, ES_EINVAL, "export: id '%s' cannot be a file name", id);
            goto done;
        }
        if (!(path = es__malloc(ctx, len))) { rc = ES_ENOMEM; goto done; }
        snprintf(path, len, "%s/%s.%s", dir, id, ext);
        if (!(rc = es_store_read_positions(ctx, s, list[j], xyz)))
            rc = es__meshdata_write(ctx, path, format, es_store_nverts(s), es_store_nfaces(s),
                                    faces, xyz, NULL);
        es__free(ctx, path);
        if (rc) goto done;
    }
    es__progress(ctx, "exporting meshes", n, n);
done:
    es__free(ctx, faces);
    es__free(ctx, xyz);
    es__free(ctx, own);
    return rc;
}
