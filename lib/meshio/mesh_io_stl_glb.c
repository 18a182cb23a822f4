/* lib/meshio/mesh_io_stl_glb.c — writers for the formats other tools take
 * but this project never reads: binary STL (3D printing, CAD) and glTF 2.0
 * binary, GLB (web viewers, Blender, game engines).
 *
 * Both store float32 positions: they are for looking at and printing a
 * shape, not for reading it back exactly (OBJ, PLY and OFF are).
 *
 * STL: an 80-byte header, a uint32 face count, then per face a unit normal
 * (right-hand rule on the face's vertex order; zero for a degenerate face),
 * three vertices and a zero uint16 attribute count, all little endian.
 *
 * GLB (Khronos glTF 2.0 specification, section "GLB File Format
 * Specification"): a 12-byte header ("glTF", version 2, total length), a
 * JSON chunk padded with spaces to 4 bytes and a BIN chunk padded with
 * zeros, holding one mesh with one triangle primitive: POSITION (float32
 * VEC3, with the min and max the specification requires), indices (uint32
 * SCALAR) and, with colours, COLOR_0 (normalized uint8 VEC4: a VEC3 of
 * bytes would break the 4-byte alignment every vertex needs).
 */
#include "meshio/meshio_pkg.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void put_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static void put_f32(unsigned char *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    put_u32(p, u);
}

static es_status check_count(es_ctx *ctx, const char *path, const char *what, int64_t n,
                             int64_t max)
{
    if (n > max)
        ES_FAIL(ctx, ES_ERANGE, "'%s': %lld %s do not fit the format (at most %lld)", path,
                (long long)n, what, (long long)max);
    return ES_OK;
}

es_status es__stl_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts, int64_t nfaces,
                        const int64_t *faces, const double *xyz)
{
    (void)nverts;
    es_status rc = check_count(ctx, path, "faces", nfaces, UINT32_MAX);
    if (rc != ES_OK) return rc;
    unsigned char head[84] = {0}, rec[50];
    snprintf((char *)head, 80, "binary STL written by edgespace %s", es_version());
    put_u32(head + 80, (uint32_t)nfaces);
    fwrite(head, 1, sizeof head, f);
    for (int64_t t = 0; t < nfaces; t++) {
        const double *a = xyz + 3 * faces[3 * t], *b = xyz + 3 * faces[3 * t + 1],
                     *c = xyz + 3 * faces[3 * t + 2];
        double u[3], v[3], n[3];
        for (int k = 0; k < 3; k++) u[k] = b[k] - a[k], v[k] = c[k] - a[k];
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++) put_f32(rec + 4 * k, len > 0 ? (float)(n[k] / len) : 0.0f);
        const double *corner[3] = {a, b, c};
        for (int q = 0; q < 3; q++)
            for (int k = 0; k < 3; k++) put_f32(rec + 12 + 12 * q + 4 * k, (float)corner[q][k]);
        rec[48] = rec[49] = 0;
        fwrite(rec, 1, sizeof rec, f);
    }
    return ES_OK;
}

/* The glTF JSON of one mesh, its accessors reading the BIN chunk's views:
 * 0 positions, 1 indices[, 2 colours]. Returns the length (or -1 when it
 * does not fit n bytes). */
static int glb_json(char *buf, size_t n, int64_t nverts, int64_t nfaces, bool colours,
                    const float lo[3], const float hi[3], uint64_t pos_bytes, uint64_t idx_bytes,
                    uint64_t col_bytes)
{
    int len = snprintf(
        buf, n,
        "{\"asset\":{\"version\":\"2.0\",\"generator\":\"edgespace %s\"},"
        "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0%s},\"indices\":1,"
        "\"mode\":4}]}],\"buffers\":[{\"byteLength\":%llu}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%llu,\"target\":34962},"
        "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":34963}",
        es_version(), colours ? ",\"COLOR_0\":2" : "",
        (unsigned long long)(pos_bytes + idx_bytes + col_bytes), (unsigned long long)pos_bytes,
        (unsigned long long)pos_bytes, (unsigned long long)idx_bytes);
    if (len < 0 || (size_t)len >= n) return -1;
    if (colours) {
        int more = snprintf(buf + len, n - (size_t)len,
                            ",{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,"
                            "\"target\":34962}",
                            (unsigned long long)(pos_bytes + idx_bytes),
                            (unsigned long long)col_bytes);
        if (more < 0 || (size_t)(len += more) >= n) return -1;
    }
    /* float32 5126, uint32 5125, uint8 5121; %.9g keeps a float exactly */
    int more = snprintf(
        buf + len, n - (size_t)len,
        "],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%lld,"
        "\"type\":\"VEC3\",\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
        "{\"bufferView\":1,\"componentType\":5125,\"count\":%lld,\"type\":\"SCALAR\"}%s",
        (long long)nverts, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], (long long)(3 * nfaces),
        colours ? "" : "]}");
    if (more < 0 || (size_t)(len += more) >= n) return -1;
    if (colours) {
        more = snprintf(buf + len, n - (size_t)len,
                        ",{\"bufferView\":2,\"componentType\":5121,\"normalized\":true,"
                        "\"count\":%lld,\"type\":\"VEC4\"}]}", (long long)nverts);
        if (more < 0 || (size_t)(len += more) >= n) return -1;
    }
    return len;
}

es_status es__glb_write(es_ctx *ctx, const char *path, FILE *f, int64_t nverts, int64_t nfaces,
                        const int64_t *faces, const double *xyz, const uint8_t *rgb)
{
    es_status rc;
    /* every length is a uint32 in the file, the whole file's too */
    if ((rc = check_count(ctx, path, "vertices", nverts, UINT32_MAX / 16)) != ES_OK ||
        (rc = check_count(ctx, path, "faces", nfaces, UINT32_MAX / 16)) != ES_OK)
        return rc;
    const uint64_t pos_bytes = 12 * (uint64_t)nverts, idx_bytes = 12 * (uint64_t)nfaces,
                   col_bytes = rgb ? 4 * (uint64_t)nverts : 0;
    const uint64_t bin_bytes = pos_bytes + idx_bytes + col_bytes;   /* multiples of 4 */
    if (bin_bytes + 4096 > UINT32_MAX)
        ES_FAIL(ctx, ES_ERANGE, "'%s': %llu bytes of mesh data do not fit a GLB file (4 GiB)",
                path, (unsigned long long)bin_bytes);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int64_t v = 0; v < nverts; v++)
        for (int k = 0; k < 3; k++) {
            float x = (float)xyz[3 * v + k];
            if (!isfinite(x))
                ES_FAIL(ctx, ES_EINVAL, "'%s': vertex %lld has a coordinate that is not a "
                        "finite float", path, (long long)v);
            lo[k] = fminf(lo[k], x);
            hi[k] = fmaxf(hi[k], x);
        }
    char json[2048];
    int jlen = glb_json(json, sizeof json, nverts, nfaces, rgb != NULL, lo, hi, pos_bytes,
                        idx_bytes, col_bytes);
    if (jlen < 0) ES_FAIL(ctx, ES_ERANGE, "'%s': glTF JSON longer than expected", path);
    while (jlen % 4) json[jlen++] = ' ';   /* the JSON chunk is padded with spaces */
    unsigned char head[20];
    memcpy(head, "glTF", 4);
    put_u32(head + 4, 2);
    put_u32(head + 8, (uint32_t)(12 + 8 + (uint64_t)jlen + 8 + bin_bytes));
    put_u32(head + 12, (uint32_t)jlen);
    memcpy(head + 16, "JSON", 4);
    fwrite(head, 1, sizeof head, f);
    fwrite(json, 1, (size_t)jlen, f);
    put_u32(head, (uint32_t)bin_bytes);
    memcpy(head + 4, "BIN\0", 4);
    fwrite(head, 1, 8, f);
    unsigned char b[12];
    for (int64_t v = 0; v < nverts; v++) {
        for (int k = 0; k < 3; k++) put_f32(b + 4 * k, (float)xyz[3 * v + k]);
        fwrite(b, 1, 12, f);
    }
    for (int64_t t = 0; t < 3 * nfaces; t++) {
        put_u32(b, (uint32_t)faces[t]);
        fwrite(b, 1, 4, f);
    }
    for (int64_t v = 0; rgb && v < nverts; v++) {
        unsigned char c[4] = {rgb[3 * v], rgb[3 * v + 1], rgb[3 * v + 2], 255};
        fwrite(c, 1, 4, f);
    }
    return ES_OK;
}
