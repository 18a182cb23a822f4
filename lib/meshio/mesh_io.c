/* lib/meshio/mesh_io.c — mesh file reading and writing: format dispatch, the
 * shared builder, whole-file reading, es_meshio_read and es_meshio_write.
 *
 * Files are read whole into memory and parsed in place: for the OBJ files
 * this project reads (tens of MB per study) that is far faster than stdio
 * line reading and lets the parsers report exact line numbers. Numbers are
 * parsed by mesh_io_num.c.
 *
 * Formats (datasets-spec/mesh-formats.md): mesh_io_obj.c, mesh_io_ply.c,
 * mesh_io_off.c; written only: mesh_io_stl_glb.c.
 */
#include "meshio/meshio_pkg.h"
#include "edgespace/es_geom.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <strings.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#define INITIAL_CAP 64

void es__mdbuild_init(es__mdbuild *b, es_ctx *ctx, es_meshdata *md)
{
    memset(md, 0, sizeof *md);
    b->ctx = ctx;
    b->md = md;
    b->vcap = 0;
    b->fcap = 0;
}

static es_status grow(es_ctx *ctx, void **arr, int64_t *cap, int64_t need, size_t elem)
{
    int64_t ncap = *cap == 0 ? INITIAL_CAP : *cap > INT64_MAX / 2 ? INT64_MAX : 2 * *cap;
    size_t bytes;
    void *p;
    if (ncap < need) ncap = need;   /* an exact reservation is not rounded up */
    if (!es__mul_size((size_t)ncap, elem, &bytes))
        ES_FAIL(ctx, ES_ERANGE, "mesh too large (%lld elements)", (long long)need);
    p = es__realloc(ctx, *arr, bytes);
    if (!p) return ES_ENOMEM;
    *arr = p;
    *cap = ncap;
    return ES_OK;
}

es_status es__mdbuild_reserve_verts(es__mdbuild *b, int64_t more)
{
    int64_t need;
    if (more < 0 || __builtin_add_overflow(b->md->nverts, more, &need))
        ES_FAIL(b->ctx, ES_ERANGE, "vertex count overflows");
    if (need <= b->vcap) return ES_OK;
    void *p = b->md->xyz;
    es_status rc = grow(b->ctx, &p, &b->vcap, need, 3 * sizeof(double));
    b->md->xyz = p;
    return rc;
}

es_status es__mdbuild_reserve_faces(es__mdbuild *b, int64_t more)
{
    int64_t need;
    if (more < 0 || __builtin_add_overflow(b->md->nfaces, more, &need))
        ES_FAIL(b->ctx, ES_ERANGE, "face count overflows");
    if (need <= b->fcap) return ES_OK;
    void *p = b->md->faces;
    es_status rc = grow(b->ctx, &p, &b->fcap, need, 3 * sizeof(int64_t));
    b->md->faces = p;
    return rc;
}

/* Hand back slack capacity; a failed shrink leaves the block as it was. */
void es__mdbuild_finish(es__mdbuild *b)
{
    es_meshdata *md = b->md;
    void *p;
    if (md->xyz && md->nverts > 0 && md->nverts < b->vcap &&
        (p = es__realloc(b->ctx, md->xyz, (size_t)md->nverts * 3 * sizeof(double))))
        md->xyz = p;
    if (md->faces && md->nfaces > 0 && md->nfaces < b->fcap &&
        (p = es__realloc(b->ctx, md->faces, (size_t)md->nfaces * 3 * sizeof(int64_t))))
        md->faces = p;
}

/* ---------------------------------------------------------------- files */

/* ---------------------------------------------------------------- dispatch */

es_mesh_format es_meshio_format_from_path(const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (!dot || (slash && slash > dot)) return ES_FORMAT_AUTO;
    if (!strcasecmp(dot, ".obj")) return ES_FORMAT_OBJ;
    if (!strcasecmp(dot, ".ply")) return ES_FORMAT_PLY;
    if (!strcasecmp(dot, ".off")) return ES_FORMAT_OFF;
    if (!strcasecmp(dot, ".stl")) return ES_FORMAT_STL;
    if (!strcasecmp(dot, ".glb")) return ES_FORMAT_GLB;
    return ES_FORMAT_AUTO;
}

/* Guess from the contents when the name does not tell. */
static es_mesh_format sniff(const char *buf, size_t len)
{
    size_t i = 0;
    if (len >= 4 && !memcmp(buf, "ply", 3) && (buf[3] == '\n' || buf[3] == '\r'))
        return ES_FORMAT_PLY;
    for (;;) {
        while (i < len && (buf[i] == ' ' || buf[i] == '\t' || buf[i] == '\r' || buf[i] == '\n'))
            i++;
        if (i < len && buf[i] == '#') {
            while (i < len && buf[i] != '\n') i++;
            continue;
        }
        break;
    }
    if (i >= len) return ES_FORMAT_AUTO;
    size_t j = i;
    while (j < len && !es__is_delim(buf[j])) j++;
    if (j - i >= 3 && !memcmp(buf + j - 3, "OFF", 3)) return ES_FORMAT_OFF;
    if (j - i == 1 && (buf[i] == 'v' || buf[i] == 'f' || buf[i] == 'o' || buf[i] == 'g'))
        return ES_FORMAT_OBJ;
    if (j - i == 2 && buf[i] == 'v') return ES_FORMAT_OBJ;
    if (j - i == 6 && !memcmp(buf + i, "mtllib", 6)) return ES_FORMAT_OBJ;
    return ES_FORMAT_AUTO;
}

void es_meshdata_clear(es_ctx *ctx, es_meshdata *md)
{
    if (!md) return;
    es__free(ctx, md->xyz);
    es__free(ctx, md->faces);
    memset(md, 0, sizeof *md);
}

es_status es_meshdata_parse(es_ctx *ctx, const char *name, const char *buf, size_t len,
                            es_mesh_format format, es_meshdata *out)
{
    es_status rc;
    if (!out) ES_FAIL(ctx, ES_EINVAL, "es_meshdata_parse: out is NULL");
    memset(out, 0, sizeof *out);
    if (!name) name = "<memory>";
    if (!buf && len) ES_FAIL(ctx, ES_EINVAL, "%s: buffer is NULL", name);
    if (!buf) buf = "";
    if (format == ES_FORMAT_AUTO) format = es_meshio_format_from_path(name);
    /* a UTF-8 byte order mark before a text format (editors on Windows);
     * PLY keeps it so that binary byte offsets stay those of the file */
    if (len >= 3 && !memcmp(buf, "\xEF\xBB\xBF", 3) && format != ES_FORMAT_PLY &&
        format != ES_FORMAT_PLY_ASCII) {
        buf += 3;
        len -= 3;
    }
    if (format == ES_FORMAT_AUTO) format = sniff(buf, len);
    switch (format) {
    case ES_FORMAT_OBJ: rc = es__obj_parse(ctx, name, buf, len, out); break;
    case ES_FORMAT_PLY:
    case ES_FORMAT_PLY_ASCII: rc = es__ply_parse(ctx, name, buf, len, out); break;
    case ES_FORMAT_OFF: rc = es__off_parse(ctx, name, buf, len, out); break;
    case ES_FORMAT_STL:
    case ES_FORMAT_GLB:
        /* float32 positions and (STL) unshared vertices: not a study's input */
        ES_FAIL(ctx, ES_EFORMAT, "%s: %s files are written for viewers and printers, not read "
                "(use .obj, .ply or .off)", name, format == ES_FORMAT_STL ? "STL" : "GLB");
    case ES_FORMAT_AUTO:
    default:
        ES_FAIL(ctx, ES_EFORMAT, "%s: unknown mesh format (extension is not .obj, .ply or "
                ".off and the contents do not tell)", name);
    }
    if (rc == ES_OK && out->nverts == 0) rc = es__fail(ctx, ES_EFORMAT, "%s: no vertices", name);
    if (rc == ES_OK && out->nfaces == 0) rc = es__fail(ctx, ES_EFORMAT, "%s: no faces", name);
    if (rc != ES_OK) {
        es_meshdata_clear(ctx, out);
        return rc;
    }
    return ES_OK;
}

es_status es_meshdata_read(es_ctx *ctx, const char *path, es_mesh_format format,
                           es_meshdata *out)
{
    char *buf;
    size_t len;
    es_status rc;
    if (!out) ES_FAIL(ctx, ES_EINVAL, "es_meshdata_read: out is NULL");
    memset(out, 0, sizeof *out);
    if (!path) ES_FAIL(ctx, ES_EINVAL, "es_meshdata_read: path is NULL");
    if ((rc = es__read_file(ctx, path, 0, &buf, &len)) != ES_OK) return rc;
    rc = es_meshdata_parse(ctx, path, buf, len, format, out);
    es__free(ctx, buf);
    return rc;
}

/* set: NULL to replace path at once, else staged in the set */
static es_status meshdata_write(es_ctx *ctx, const char *path, es_mesh_format format,
                                int64_t nverts, int64_t nfaces, const int64_t *faces,
                                const double *xyz, const uint8_t *rgb, es__file_set *set)
{
    es__file_replace w;
    FILE *f;
    es_status rc;
    if (!path || !faces || !xyz || nverts <= 0 || nfaces < 0)
        ES_FAIL(ctx, ES_EINVAL, "mesh write: missing path, faces or positions");
    if (format == ES_FORMAT_AUTO) format = es_meshio_format_from_path(path);
    if (format == ES_FORMAT_AUTO)
        ES_FAIL(ctx, ES_EINVAL, "'%s': cannot tell the format (use .obj, .ply, .off, .stl or "
                ".glb)", path);
    for (int64_t i = 0; i < 3 * nfaces; i++)
        if (faces[i] < 0 || faces[i] >= nverts)
            ES_FAIL(ctx, ES_ERANGE, "'%s': face %lld has vertex %lld out of range (%lld vertices)",
                    path, (long long)(i / 3), (long long)faces[i], (long long)nverts);
    /* a failed write leaves a file that was there before as it was */
    if ((rc = es__replace_begin(ctx, path, &w)) != ES_OK) return rc;
    f = w.f;
    switch (format) {
    case ES_FORMAT_OBJ: rc = es__obj_write(ctx, path, f, nverts, nfaces, faces, xyz); break;
    case ES_FORMAT_PLY:
    case ES_FORMAT_PLY_ASCII:
        rc = es__ply_write(ctx, path, f, format == ES_FORMAT_PLY, nverts, nfaces, faces, xyz,
                           rgb);
        break;
    case ES_FORMAT_OFF: rc = es__off_write(ctx, path, f, nverts, nfaces, faces, xyz); break;
    case ES_FORMAT_STL: rc = es__stl_write(ctx, path, f, nverts, nfaces, faces, xyz); break;
    case ES_FORMAT_GLB: rc = es__glb_write(ctx, path, f, nverts, nfaces, faces, xyz, rgb); break;
    case ES_FORMAT_AUTO:
    default: rc = es__fail(ctx, ES_EINVAL, "'%s': unknown format %d", path, (int)format);
    }
    return set ? es__replace_end_staged(ctx, &w, rc, set) : es__replace_end(ctx, &w, rc);
}

es_status es__meshdata_write(es_ctx *ctx, const char *path, es_mesh_format format,
                             int64_t nverts, int64_t nfaces, const int64_t *faces,
                             const double *xyz, const uint8_t *rgb)
{
    return meshdata_write(ctx, path, format, nverts, nfaces, faces, xyz, rgb, NULL);
}

es_status es__mesh_write_staged(es_ctx *ctx, const char *path, es_mesh_format format,
                                const es_mesh *mesh, const double *xyz, es__file_set *set)
{
    if (!mesh || !xyz) ES_FAIL(ctx, ES_EINVAL, "mesh write: no mesh or positions");
    return meshdata_write(ctx, path, format, es_mesh_nverts(mesh), es_mesh_nfaces(mesh),
                          es_mesh_faces(mesh), xyz, NULL, set);
}

/* ---------------------------------------------------------------- meshes */

es_status es_meshio_read(es_ctx *ctx, const char *path, es_mesh **out)
{
    es_meshdata md;
    es_status rc;
    if (!out) ES_FAIL(ctx, ES_EINVAL, "es_meshio_read: out is NULL");
    *out = NULL;
    if ((rc = es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md)) != ES_OK) return rc;
    rc = es_mesh_new(ctx, md.nverts, md.nfaces, md.faces, md.xyz, out);
    if (rc != ES_OK) {
        /* name the file: topology messages only know faces and vertices */
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", es_ctx_errmsg(ctx));
        es__fail(ctx, rc, "%s: %s", path, msg);
    }
    es_meshdata_clear(ctx, &md);
    return rc;
}

es_status es_meshio_read_positions(es_ctx *ctx, const es_mesh *mesh, const char *path,
                                   double *xyz)
{
    es_meshdata md;
    char want[17], got[17];
    es_status rc = es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md);
    if (rc != ES_OK) return rc;
    es_mesh_fingerprint(mesh, want);
    es_faces_fingerprint(md.nverts, md.nfaces, md.faces, got);
    if (strcmp(want, got))
        rc = es__fail(ctx, ES_EMISMATCH, "'%s': %lld vertices and %lld faces do not match the "
                      "store's topology (%lld vertices, %lld faces, same face list required)",
                      path, (long long)md.nverts, (long long)md.nfaces,
                      (long long)es_mesh_nverts(mesh), (long long)es_mesh_nfaces(mesh));
    else
        memcpy(xyz, md.xyz, 3 * (size_t)md.nverts * sizeof *xyz);
    es_meshdata_clear(ctx, &md);
    return rc;
}

es_status es_meshio_write(es_ctx *ctx, const char *path, es_mesh_format format,
                          const es_mesh *mesh, const double *xyz, const uint8_t *vertex_rgb)
{
    if (!mesh) ES_FAIL(ctx, ES_EINVAL, "es_meshio_write: mesh is NULL");
    if (!xyz) xyz = es_mesh_xyz(mesh);
    if (!xyz) ES_FAIL(ctx, ES_EINVAL, "'%s': no positions given and the mesh has none", path);
    return es__meshdata_write(ctx, path, format, es_mesh_nverts(mesh), es_mesh_nfaces(mesh),
                              es_mesh_faces(mesh), xyz, vertex_rgb);
}

es_status es_meshio_lengths_from_file(es_ctx *ctx, const es_mesh *mesh, const char *path,
                                      double *len, double *scale)
{
    double *xyz = es__alloc_array(ctx, 3 * es_mesh_nverts(mesh), sizeof *xyz);
    es_status rc;
    if (!xyz) return ES_ENOMEM;
    if ((rc = es_meshio_read_positions(ctx, mesh, path, xyz)) == ES_OK &&
        (rc = es_edge_lengths(ctx, mesh, xyz, len)) == ES_OK)
        rc = es_lengths_normalize(ctx, es_mesh_nedges(mesh), len, len, scale);
    es__free(ctx, xyz);
    return rc;
}
