/* lib/mesh_io.c — mesh file reading and writing: format dispatch, the
 * shared builder, the exact fast number parser, whole-file reading.
 *
 * Files are read whole into memory and parsed in place: for the OBJ files
 * this project reads (tens of MB per study) that is far faster than stdio
 * line reading and lets the parsers report exact line numbers. Numbers go
 * through es__parse_double, which is Clinger's fast path (Clinger 1990,
 * "How to read floating point numbers accurately"): a decimal with at most
 * 19 significant digits whose value m * 10^e has m <= 2^53 and |e| <= 22 is
 * m and 10^|e| exactly represented, so one IEEE multiply or divide gives the
 * correctly rounded result, identical to strtod's. Everything else (long
 * mantissas, large exponents, hex, inf/nan) goes to strtod on a
 * NUL-terminated copy of the token. strtod follows LC_NUMERIC; programs
 * that change it must expect '.' decimals to fail on the slow path.
 *
 * Formats (datasets-spec/mesh-formats.md): mesh_io_obj.c, mesh_io_ply.c,
 * mesh_io_off.c.
 */
#include "mesh_io_internal.h"

#include <errno.h>
#include <float.h>
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

/* ---------------------------------------------------------------- numbers */

static const double pow10_exact[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

#define MAX_TOKEN 512

static const char *parse_double_slow(const char *p, const char *end, double *out)
{
    char tok[MAX_TOKEN + 1];
    size_t n = 0;
    char *stop;
    while (p + n < end && !es__is_delim(p[n])) {
        if (n == MAX_TOKEN) return NULL;
        tok[n] = p[n];
        n++;
    }
    if (n == 0) return NULL;
    tok[n] = '\0';
    errno = 0;
    *out = strtod(tok, &stop);
    /* ERANGE is not an error here: strtod's rounded result (0, a
     * subnormal or inf) is the value, and the callers reject inf. */
    if (stop != tok + n) return NULL;
    return p + n;
}

const char *es__parse_double(const char *p, const char *end, double *out)
{
    const char *s = p, *d0;
    bool neg = false, any;
    uint64_t m = 0;
    int nd = 0, e10 = 0;

    if (p < end && (*p == '-' || *p == '+')) neg = *p++ == '-';
    d0 = p;
    for (; p < end && (unsigned)(*p - '0') < 10; p++) {
        if (nd == 19) return parse_double_slow(s, end, out);
        m = m * 10 + (uint64_t)(*p - '0');
        nd += m != 0;
    }
    any = p > d0;
    if (p < end && *p == '.') {
        const char *f0 = ++p;
        for (; p < end && (unsigned)(*p - '0') < 10; p++) {
            if (nd == 19) return parse_double_slow(s, end, out);
            m = m * 10 + (uint64_t)(*p - '0');
            nd += m != 0;
            e10--;
        }
        any = any || p > f0;
    }
    if (!any) return parse_double_slow(s, end, out);
    if (p < end && (*p == 'e' || *p == 'E')) {
        bool eneg = false;
        int x = 0;
        const char *x0;
        p++;
        if (p < end && (*p == '-' || *p == '+')) eneg = *p++ == '-';
        x0 = p;
        for (; p < end && (unsigned)(*p - '0') < 10; p++)
            if (x < 100000) x = x * 10 + (*p - '0');
        if (p == x0) return parse_double_slow(s, end, out);
        e10 += eneg ? -x : x;
    }
    if (p < end && !es__is_delim(*p)) return parse_double_slow(s, end, out);
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
    if (m == 0) {
        *out = neg ? -0.0 : 0.0;
        return p;
    }
    if (m <= (UINT64_C(1) << 53) && e10 >= -22 && e10 <= 22) {
        double v = (double)m;
        v = e10 < 0 ? v / pow10_exact[-e10] : v * pow10_exact[e10];
        *out = neg ? -v : v;
        return p;
    }
#endif
    return parse_double_slow(s, end, out);
}

const char *es__parse_int64(const char *p, const char *end, int64_t *out)
{
    bool neg = false;
    uint64_t v = 0;
    const char *d0;
    if (p < end && (*p == '-' || *p == '+')) neg = *p++ == '-';
    d0 = p;
    for (; p < end && (unsigned)(*p - '0') < 10; p++) {
        if (v > (UINT64_MAX - 9) / 10) return NULL;
        v = v * 10 + (uint64_t)(*p - '0');
    }
    if (p == d0) return NULL;
    if (neg) {
        if (v > (uint64_t)INT64_MAX + 1) return NULL;
        *out = v == (uint64_t)INT64_MAX + 1 ? INT64_MIN : -(int64_t)v;
    } else {
        if (v > (uint64_t)INT64_MAX) return NULL;
        *out = (int64_t)v;
    }
    return p;
}

/* ---------------------------------------------------------------- files */

es_status es__read_file(es_ctx *ctx, const char *path, char **buf, size_t *len)
{
    struct stat st;
    char *b = NULL;
    size_t cap, n = 0;
    int fd;
    *buf = NULL;
    *len = 0;
    if ((fd = open(path, O_RDONLY)) < 0)
        ES_FAIL(ctx, ES_EIO, "cannot open '%s': %s", path, strerror(errno));
    if (fstat(fd, &st) != 0 || S_ISDIR(st.st_mode)) {
        int e = S_ISDIR(st.st_mode) ? EISDIR : errno;
        close(fd);
        ES_FAIL(ctx, ES_EIO, "cannot read '%s': %s", path, strerror(e));
    }
    /* regular files: one buffer of the right size; pipes and the like grow */
    cap = S_ISREG(st.st_mode) && st.st_size > 0 && (uintmax_t)st.st_size < SIZE_MAX
              ? (size_t)st.st_size + 1 : 65536;
    for (;;) {
        if (!b || n + 1 == cap) {
            char *nb;
            if (b) {
                /* a full buffer of the stat'ed size grows only if more follows */
                char c;
                ssize_t got = read(fd, &c, 1);
                if (got == 0) break;
                if (got < 0 && errno == EINTR) continue;
                if (got < 0) goto read_error;
                if (cap > SIZE_MAX / 2) {
                    es__free(ctx, b);
                    close(fd);
                    ES_FAIL(ctx, ES_ERANGE, "'%s' is too large", path);
                }
                cap *= 2;
                nb = es__realloc(ctx, b, cap);
                if (nb) nb[n++] = c;
            } else {
                nb = es__malloc(ctx, cap);
            }
            if (!nb) {
                es__free(ctx, b);
                close(fd);
                return ES_ENOMEM;
            }
            b = nb;
        }
        ssize_t got = read(fd, b + n, cap - 1 - n);
        if (got == 0) break;
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) goto read_error;
        n += (size_t)got;
    }
    close(fd);
    b[n] = '\0';
    *buf = b;
    *len = n;
    return ES_OK;
read_error: {
        int e = errno;
        es__free(ctx, b);
        close(fd);
        ES_FAIL(ctx, ES_EIO, "cannot read '%s': %s", path, strerror(e));
    }
}

/* ---------------------------------------------------------------- dispatch */

es_mesh_format es_mesh_format_from_path(const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (!dot || (slash && slash > dot)) return ES_FORMAT_AUTO;
    if (!strcasecmp(dot, ".obj")) return ES_FORMAT_OBJ;
    if (!strcasecmp(dot, ".ply")) return ES_FORMAT_PLY;
    if (!strcasecmp(dot, ".off")) return ES_FORMAT_OFF;
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
    if (format == ES_FORMAT_AUTO) format = es_mesh_format_from_path(name);
    if (format == ES_FORMAT_AUTO) format = sniff(buf, len);
    switch (format) {
    case ES_FORMAT_OBJ: rc = es__obj_parse(ctx, name, buf, len, out); break;
    case ES_FORMAT_PLY:
    case ES_FORMAT_PLY_ASCII: rc = es__ply_parse(ctx, name, buf, len, out); break;
    case ES_FORMAT_OFF: rc = es__off_parse(ctx, name, buf, len, out); break;
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
    if ((rc = es__read_file(ctx, path, &buf, &len)) != ES_OK) return rc;
    rc = es_meshdata_parse(ctx, path, buf, len, format, out);
    es__free(ctx, buf);
    return rc;
}

es_status es__meshdata_write(es_ctx *ctx, const char *path, es_mesh_format format,
                             int64_t nverts, int64_t nfaces, const int64_t *faces,
                             const double *xyz, const uint8_t *rgb)
{
    FILE *f;
    es_status rc;
    if (!path || !faces || !xyz || nverts <= 0 || nfaces < 0)
        ES_FAIL(ctx, ES_EINVAL, "mesh write: missing path, faces or positions");
    if (format == ES_FORMAT_AUTO) format = es_mesh_format_from_path(path);
    if (format == ES_FORMAT_AUTO)
        ES_FAIL(ctx, ES_EINVAL, "'%s': cannot tell the format (use .obj, .ply or .off)", path);
    for (int64_t i = 0; i < 3 * nfaces; i++)
        if (faces[i] < 0 || faces[i] >= nverts)
            ES_FAIL(ctx, ES_ERANGE, "'%s': face %lld has vertex %lld out of range (%lld vertices)",
                    path, (long long)(i / 3), (long long)faces[i], (long long)nverts);
    f = fopen(path, "wb");
    if (!f) ES_FAIL(ctx, ES_EIO, "cannot create '%s': %s", path, strerror(errno));
    switch (format) {
    case ES_FORMAT_OBJ: rc = es__obj_write(ctx, path, f, nverts, nfaces, faces, xyz); break;
    case ES_FORMAT_PLY:
    case ES_FORMAT_PLY_ASCII:
        rc = es__ply_write(ctx, path, f, format == ES_FORMAT_PLY, nverts, nfaces, faces, xyz,
                           rgb);
        break;
    case ES_FORMAT_OFF: rc = es__off_write(ctx, path, f, nverts, nfaces, faces, xyz); break;
    case ES_FORMAT_AUTO:
    default: rc = es__fail(ctx, ES_EINVAL, "'%s': unknown format %d", path, (int)format);
    }
    if (rc == ES_OK && ferror(f))
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", path, strerror(errno));
    if (fclose(f) != 0 && rc == ES_OK)
        rc = es__fail(ctx, ES_EIO, "cannot write '%s': %s", path, strerror(errno));
    if (rc != ES_OK) remove(path);
    return rc;
}

/* ---------------------------------------------------------------- meshes */

es_status es_mesh_read(es_ctx *ctx, const char *path, es_mesh **out)
{
    es_meshdata md;
    es_status rc;
    if (!out) ES_FAIL(ctx, ES_EINVAL, "es_mesh_read: out is NULL");
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

es_status es_mesh_write(es_ctx *ctx, const char *path, es_mesh_format format,
                        const es_mesh *mesh, const double *xyz, const uint8_t *vertex_rgb)
{
    if (!mesh) ES_FAIL(ctx, ES_EINVAL, "es_mesh_write: mesh is NULL");
    if (!xyz) xyz = es_mesh_xyz(mesh);
    if (!xyz) ES_FAIL(ctx, ES_EINVAL, "'%s': no positions given and the mesh has none", path);
    return es__meshdata_write(ctx, path, format, es_mesh_nverts(mesh), es_mesh_nfaces(mesh),
                              es_mesh_faces(mesh), xyz, vertex_rgb);
}
