/* tests/meshio/test_io.c — mesh file I/O: every syntax variant of OBJ/PLY/OFF,
 * round trips that must be bit exact, the malformed-file corpus
 * (tests/data/malformed/EXPECTED), truncated prefixes, allocation failures,
 * and the real meshes of ../shared/data. The exact number parser the
 * readers use is tested against strtod in tests/core/test_text.c. */
#include "meshio/meshio_private.h"
#include "es_test.h"
#include "es_test_files.h"

#include <dirent.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#include <inttypes.h>

#define SRC ES_SOURCE_ROOT "/tests/data"

/* ---------------------------------------------------------------- helpers */

static int64_t n_warnings;
static char last_warning[1024];

static void count_log(void *ud, es_log_level level, const char *msg)
{
    (void)ud;
    if (level == ES_LOG_WARNING) {
        n_warnings++;
        snprintf(last_warning, sizeof last_warning, "%s", msg);
    }
}

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    long n;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    rewind(f);
    buf = malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    if (buf) buf[n] = '\0';
    *len = (size_t)n;
    return buf;
}

static bool same_data(const es_meshdata *a, const es_meshdata *b)
{
    return a->nverts == b->nverts && a->nfaces == b->nfaces &&
           !memcmp(a->xyz, b->xyz, (size_t)a->nverts * 3 * sizeof(double)) &&
           !memcmp(a->faces, b->faces, (size_t)a->nfaces * 3 * sizeof(int64_t));
}

static es_status parse_str(es_ctx *ctx, const char *name, const char *s, es_meshdata *md)
{
    return es_meshdata_parse(ctx, name, s, strlen(s), ES_FORMAT_AUTO, md);
}

/* ---------------------------------------------------------------- syntax */

static const double cube_xyz[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                    0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
/* fans from the first corner of the six quads of cube.obj / cube.off */
static const int64_t cube_faces[36] = {0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7,
                                       0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5,
                                       3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3};
static const double tet_xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const int64_t tet_faces[12] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};

static void check_arrays(const es_meshdata *md, int64_t nv, const double *xyz, int64_t nf,
                         const int64_t *faces, const char *what)
{
    ES_CHECK_MSG(md->nverts == nv && md->nfaces == nf, "%s: %" PRId64 " verts %" PRId64
                 " faces", what, md->nverts, md->nfaces);
    if (md->nverts != nv || md->nfaces != nf) return;
    ES_CHECK_MSG(!memcmp(md->xyz, xyz, (size_t)nv * 3 * sizeof(double)), "%s: xyz", what);
    ES_CHECK_MSG(!memcmp(md->faces, faces, (size_t)nf * 3 * sizeof(int64_t)), "%s: faces",
                 what);
}

static void test_syntax(es_ctx *ctx)
{
    es_meshdata md, md2;

    /* cube.obj: every corner form, negative indices, w and colour after
     * xyz, continuations, ignored statements, quads */
    n_warnings = 0;
    ES_CHECK_OK(ctx, es_meshdata_read(ctx, SRC "/valid/cube.obj", ES_FORMAT_AUTO, &md));
    check_arrays(&md, 8, cube_xyz, 12, cube_faces, "cube.obj");
    ES_CHECK(md.n_polygons_split == 6);
    ES_CHECK(n_warnings == 1 && strstr(last_warning, "cube.obj: 6 polygons") &&
             strstr(last_warning, "fan-triangulated"));
    es_meshdata_clear(ctx, &md);
    ES_CHECK(md.xyz == NULL && md.faces == NULL && md.nverts == 0);

    /* cube.off: the same cube, comments, blank line, trailing comment */
    n_warnings = 0;
    ES_CHECK_OK(ctx, es_meshdata_read(ctx, SRC "/valid/cube.off", ES_FORMAT_AUTO, &md));
    check_arrays(&md, 8, cube_xyz, 12, cube_faces, "cube.off");
    ES_CHECK(md.n_polygons_split == 6 && n_warnings == 1);
    es_meshdata_clear(ctx, &md);

    /* three PLY encodings of one tetrahedron with extra properties, lists
     * and elements to skip */
    const char *plys[] = {"/valid/tetra.ply", "/valid/tetra_le.ply", "/valid/tetra_be.ply"};
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s%s", SRC, plys[i]);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md));
        check_arrays(&md, 4, tet_xyz, 4, tet_faces, plys[i]);
        ES_CHECK(md.n_polygons_split == 0);
        es_meshdata_clear(ctx, &md);
    }

    /* OBJ: CRLF, tabs, no final newline, forward references, inline
     * comments, an unknown statement (one warning), vp and p skipped */
    n_warnings = 0;
    ES_CHECK_OK(ctx, parse_str(ctx, "crlf.obj",
                               "f 1 2 3 # forward\r\nfoo bar\r\nvp 0.5\r\np 1\r\n"
                               "v\t0 0 0\r\nv 1 0 0 # c\r\nv 0 1 0\r\n"
                               "v 0 0 1\r\nf\t1/1\t2/2\t4/4\r\nf -4 -3 -1", &md));
    {
        static const int64_t f[9] = {0, 1, 2, 0, 1, 3, 0, 1, 3};
        check_arrays(&md, 4, tet_xyz, 3, f, "crlf.obj");
    }
    ES_CHECK(n_warnings == 1 && strstr(last_warning, "unknown statement") &&
             strstr(last_warning, "line 2"));
    es_meshdata_clear(ctx, &md);

    /* a UTF-8 byte order mark is skipped */
    ES_CHECK_OK(ctx, parse_str(ctx, "bom.obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                               "f 1 2 3\n", &md));
    ES_CHECK(md.nverts == 3 && md.nfaces == 1);
    es_meshdata_clear(ctx, &md);

    /* a pentagon: fan (0,1,2) (0,2,3) (0,3,4) */
    ES_CHECK_OK(ctx, parse_str(ctx, "pent.obj", "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\n"
                               "v 0 1 0\nf 1 2 3 4 5\n", &md));
    {
        static const int64_t f[9] = {0, 1, 2, 0, 2, 3, 0, 3, 4};
        ES_CHECK(md.nfaces == 3 && !memcmp(md.faces, f, sizeof f) && md.n_polygons_split == 1);
    }
    es_meshdata_clear(ctx, &md);

    /* OFF variants: counts on the keyword line, no keyword, COFF with
     * colours, counts without ne; all give the same arrays */
    const char *offs[] = {
        "OFF 4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n",
        "# no keyword\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n",
        "COFF\n4 1\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n"
        "0 0 1 9 9 9 255\n3 0 2 1 0.5 0.5 0.5\n\n# end\n",
        "OFF\r\n4 1 6\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 1\r\n3 0 2 1\r\n"};
    for (int i = 0; i < 4; i++) {
        ES_CHECK_OK(ctx, es_meshdata_parse(ctx, "v.off", offs[i], strlen(offs[i]),
                                           ES_FORMAT_AUTO, &md));
        check_arrays(&md, 4, tet_xyz, 1, tet_faces, offs[i]);
        es_meshdata_clear(ctx, &md);
    }

    /* PLY ascii with a quad and vertex_index */
    n_warnings = 0;
    ES_CHECK_OK(ctx, parse_str(ctx, "quad.ply", "ply\nformat ascii 1.0\nelement vertex 4\n"
                               "property int x\nproperty int y\nproperty int z\n"
                               "element face 1\nproperty list uchar uint vertex_index\n"
                               "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n4 0 2 1 3\n", &md));
    {
        static const int64_t f[6] = {0, 2, 1, 0, 1, 3};
        check_arrays(&md, 4, tet_xyz, 2, f, "quad.ply");
        ES_CHECK(md.n_polygons_split == 1 && n_warnings == 1 &&
                 strstr(last_warning, "quad.ply: 1 polygon with more than 3 corners"));
    }
    es_meshdata_clear(ctx, &md);

    /* an element without properties costs nothing, whatever its count */
    ES_CHECK_OK(ctx, parse_str(ctx, "empty-elem.ply", "ply\nformat ascii 1.0\n"
                               "element nothing 1000000000000000\nelement vertex 3\n"
                               "property double x\nproperty double y\nproperty double z\n"
                               "element face 1\nproperty list uchar int vertex_indices\n"
                               "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 2 1\n", &md));
    ES_CHECK(md.nverts == 3 && md.nfaces == 1);
    es_meshdata_clear(ctx, &md);

    /* ascii: blank space after the last element is fine, a value is not,
     * even on the last element's line */
    {
        const char *head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\n"
                           "property double y\nproperty double z\nelement face 1\n"
                           "property list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n1 0 0\n0 1 0\n3 0 2 1";
        char text[512];
        snprintf(text, sizeof text, "%s \t\r\n\n  \n", head);
        ES_CHECK_OK(ctx, parse_str(ctx, "trailing-space.ply", text, &md));
        ES_CHECK(md.nverts == 3 && md.nfaces == 1);
        es_meshdata_clear(ctx, &md);
        snprintf(text, sizeof text, "%s 2\n", head);
        ES_CHECK_FAILS(ctx, parse_str(ctx, "extra.ply", text, &md), ES_EFORMAT,
                       "extra.ply:13: unexpected data after the last element");
        snprintf(text, sizeof text, "%s\n\n3 0 1 2\n", head);
        ES_CHECK_FAILS(ctx, parse_str(ctx, "extra.ply", text, &md), ES_EFORMAT,
                       "extra.ply:15: unexpected data after the last element");
    }

    /* format from the name, from the contents, or forced */
    ES_CHECK(es_meshio_format_from_path("a/b.OBJ") == ES_FORMAT_OBJ);
    ES_CHECK(es_meshio_format_from_path("x.ply") == ES_FORMAT_PLY);
    ES_CHECK(es_meshio_format_from_path("x.off") == ES_FORMAT_OFF);
    ES_CHECK(es_meshio_format_from_path("dir.obj/file") == ES_FORMAT_AUTO);
    ES_CHECK(es_meshio_format_from_path("noext") == ES_FORMAT_AUTO);
    ES_CHECK_OK(ctx, parse_str(ctx, "<memory>", offs[0], &md));
    ES_CHECK_OK(ctx, parse_str(ctx, "<memory>", "# c\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                               "v 0 0 1\nf 1 3 2\n", &md2));
    ES_CHECK(same_data(&md, &md2));
    es_meshdata_clear(ctx, &md);
    es_meshdata_clear(ctx, &md2);
    ES_CHECK_OK(ctx, es_meshdata_parse(ctx, "named.txt", offs[1], strlen(offs[1]),
                                       ES_FORMAT_OFF, &md));
    es_meshdata_clear(ctx, &md);
    ES_CHECK_FAILS(ctx, parse_str(ctx, "what.txt", "hello\n", &md), ES_EFORMAT,
                   "what.txt: unknown mesh format");
    ES_CHECK_FAILS(ctx, es_meshdata_read(ctx, SRC "/no/such/file.obj", ES_FORMAT_AUTO, &md),
                   ES_EIO, "no/such/file.obj");
    ES_CHECK(md.xyz == NULL && md.nverts == 0);
    ES_CHECK_FAILS(ctx, es_meshdata_read(ctx, SRC "/valid", ES_FORMAT_OBJ, &md), ES_EIO,
                   "tests/data/valid");
}

/* ---------------------------------------------------------------- round trips */

static void random_mesh(es_rng *rng, int64_t nv, int64_t nf, double *xyz, int64_t *faces)
{
    for (int64_t i = 0; i < 3 * nv; i++) {
        double u = es_rng_uniform(rng) - 0.5;
        switch (es_rng_below(rng, 6)) {
        case 0: xyz[i] = u * 40; break;                                    /* face scale */
        case 1: xyz[i] = ldexp(u, (int)es_rng_below(rng, 2000) - 1000); break;
        case 2: xyz[i] = (double)((int64_t)es_rng_below(rng, 2001) - 1000); break;
        case 3: xyz[i] = round(u * 1e6) / 1e6; break;                      /* %.6f data */
        case 4: xyz[i] = i % 7 ? 4.9406564584124654e-324 * (double)es_rng_below(rng, 100)
                               : -0.0; break;                              /* subnormal */
        default: {
            uint64_t b = es_rng_next(rng);
            memcpy(&xyz[i], &b, 8);
            if (!isfinite(xyz[i])) xyz[i] = u;
        }
        }
    }
    for (int64_t i = 0; i < 3 * nf; i++) faces[i] = (int64_t)es_rng_below(rng, (uint64_t)nv);
}

/* Rewrite a binary little-endian PLY written by us as big endian. */
static char *ply_to_big_endian(const char *le, size_t len, bool rgb)
{
    const char *hdr_end = strstr(le, "end_header\n") + strlen("end_header\n");
    const char *fmt = strstr(le, "binary_little_endian");
    size_t hlen = (size_t)(hdr_end - le);
    char *be = malloc(len + 8);
    long nv = strtol(strstr(le, "element vertex ") + 15, NULL, 10);
    long nf = strtol(strstr(le, "element face ") + 13, NULL, 10);
    size_t o = 0, i = hlen;
    memcpy(be, le, (size_t)(fmt - le));
    o = (size_t)(fmt - le);
    o += (size_t)sprintf(be + o, "binary_big_endian");
    memcpy(be + o, fmt + 20, (size_t)(hdr_end - fmt - 20));
    o += (size_t)(hdr_end - fmt - 20);
    for (long v = 0; v < nv; v++) {
        for (int k = 0; k < 3; k++, i += 8)
            for (int b = 0; b < 8; b++) be[o++] = le[i + 7 - b];
        if (rgb) for (int k = 0; k < 3; k++) be[o++] = le[i++];
    }
    for (long f = 0; f < nf; f++) {
        be[o++] = le[i++];
        for (int k = 0; k < 3; k++, i += 4)
            for (int b = 0; b < 4; b++) be[o++] = le[i + 3 - b];
    }
    return be;
}

static void test_round_trips(es_ctx *ctx)
{
    es_rng rng;
    const int64_t nv = 700, nf = 1300;
    double *xyz = malloc(nv * 3 * sizeof *xyz);
    int64_t *faces = malloc(nf * 3 * sizeof *faces);
    uint8_t *rgb = malloc(nv * 3);
    es_meshdata want = {nv, nf, xyz, faces, 0}, md;
    static const struct { const char *ext; es_mesh_format fmt; bool rgb; } cases[] = {
        {"obj", ES_FORMAT_AUTO, false}, {"ply", ES_FORMAT_AUTO, false},
        {"ply", ES_FORMAT_PLY, true}, {"ply", ES_FORMAT_PLY_ASCII, false},
        {"ply", ES_FORMAT_PLY_ASCII, true}, {"off", ES_FORMAT_AUTO, false},
        {"obj", ES_FORMAT_OBJ, false}};
    es_rng_init(&rng, 99);
    random_mesh(&rng, nv, nf, xyz, faces);
    for (int64_t i = 0; i < 3 * nv; i++) rgb[i] = (uint8_t)es_rng_below(&rng, 256);
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        char path[512];
        snprintf(path, sizeof path, "%s/test_io_rt%zu.%s", ES_BUILD_ROOT, c, cases[c].ext);
        ES_CHECK_OK(ctx, es__meshdata_write(ctx, path, cases[c].fmt, nv, nf, faces, xyz,
                                            cases[c].rgb ? rgb : NULL));
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md));
        ES_CHECK_MSG(same_data(&md, &want), "round trip through %s (case %zu)", path, c);
        es_meshdata_clear(ctx, &md);
        if (cases[c].ext[0] == 'p' && cases[c].fmt == ES_FORMAT_PLY) {
            /* the same file big endian */
            size_t len;
            char *le = slurp(path, &len), *be = ply_to_big_endian(le, len, cases[c].rgb);
            size_t belen = len - strlen("binary_little_endian") + strlen("binary_big_endian");
            ES_CHECK_OK(ctx, es_meshdata_parse(ctx, "be.ply", be, belen, ES_FORMAT_AUTO, &md));
            ES_CHECK_MSG(same_data(&md, &want), "big-endian round trip (case %zu)", c);
            es_meshdata_clear(ctx, &md);
            /* every proper prefix of a binary file is truncated; parse
             * exact-size copies so that ASan sees any overread */
            size_t hlen = (size_t)(strstr(le, "end_header\n") - le);
            for (size_t cut = 0; cut < len; cut += cut < hlen + 64 ? 1 : 997) {
                char *pre = malloc(cut ? cut : 1);
                memcpy(pre, le, cut);
                es_status rc = es_meshdata_parse(ctx, "cut.ply", pre, cut, ES_FORMAT_PLY, &md);
                ES_CHECK_MSG(rc == ES_EFORMAT, "prefix %zu of %zu parsed (%d)", cut, len, rc);
                free(pre);
            }
            free(le);
            free(be);
        }
        remove(path);
    }
    /* the writer refuses bad input */
    faces[5] = nv;
    ES_CHECK_FAILS(ctx, es__meshdata_write(ctx, ES_BUILD_ROOT "/test_io_bad.obj",
                                           ES_FORMAT_AUTO, nv, nf, faces, xyz, NULL),
                   ES_ERANGE, "face 1 has vertex 700 out of range");
    ES_CHECK_FAILS(ctx, es__meshdata_write(ctx, ES_BUILD_ROOT "/test_io_bad.xyz",
                                           ES_FORMAT_AUTO, nv, nf, faces, xyz, NULL),
                   ES_EINVAL, "cannot tell the format");
    ES_CHECK_FAILS(ctx, es__meshdata_write(ctx, "/nonexistent-dir/x.obj", ES_FORMAT_AUTO, nv,
                                           1, faces, xyz, NULL),
                   ES_EIO, "/nonexistent-dir/x.obj");
    faces[5] = 0;
    /* a write that fails part way (here: past a file-size limit) leaves the
     * file that was there before as it was, and no partial file beside it */
    {
        const char *keep = ES_BUILD_ROOT "/test_io_keep.obj";
        const int64_t tri[3] = {0, 1, 2};
        struct rlimit lim, small;
        es_meshdata back;
        ES_CHECK_OK(ctx, es__meshdata_write(ctx, keep, ES_FORMAT_AUTO, 3, 1, tri, xyz, NULL));
        if (getrlimit(RLIMIT_FSIZE, &lim) == 0) {
            void (*old)(int) = signal(SIGXFSZ, SIG_IGN);
            small = lim;
            small.rlim_cur = 4096;
            ES_CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0);
            ES_CHECK_FAILS(ctx, es__meshdata_write(ctx, keep, ES_FORMAT_AUTO, nv, nf, faces, xyz,
                                                   NULL),
                           ES_EIO, "test_io_keep.obj");
            ES_CHECK(setrlimit(RLIMIT_FSIZE, &lim) == 0);
            signal(SIGXFSZ, old);
            ES_CHECK_OK(ctx, es_meshdata_read(ctx, keep, ES_FORMAT_AUTO, &back));
            ES_CHECK_MSG(back.nverts == 3 && back.nfaces == 1, "kept file: %lld vertices",
                         (long long)back.nverts);
            es_meshdata_clear(ctx, &back);
            DIR *d = opendir(ES_BUILD_ROOT);
            struct dirent *de;
            while (d && (de = readdir(d)))
                ES_CHECK_MSG(!strstr(de->d_name, "test_io_keep.obj."), "left behind: %s",
                             de->d_name);
            if (d) closedir(d);
        }
        remove(keep);
    }
    /* replacing a file keeps its mode, writes through a symlink to its
     * target, and is not blocked by a part file a killed writer left */
    {
        const char *real = ES_BUILD_ROOT "/test_io_real.obj", *link_ = ES_BUILD_ROOT
            "/test_io_link.obj";
        const int64_t tri[3] = {0, 1, 2};
        char stale[600];
        struct stat st;
        es_meshdata back;
        remove(real), remove(link_);
        ES_CHECK_OK(ctx, es__meshdata_write(ctx, real, ES_FORMAT_AUTO, 3, 1, tri, xyz, NULL));
        ES_CHECK(chmod(real, 0600) == 0 && symlink("test_io_real.obj", link_) == 0);
        snprintf(stale, sizeof stale, "%s.%ld.part", real, (long)getpid());
        es_test_write_file(stale, "left by a killed writer");
        ES_CHECK_OK(ctx, es__meshdata_write(ctx, real, ES_FORMAT_AUTO, 3, 1, tri, xyz, NULL));
        ES_CHECK_MSG(stat(real, &st) == 0 && (st.st_mode & 0777) == 0600, "mode %o",
                     (unsigned)(st.st_mode & 0777));
        ES_CHECK_OK(ctx, es__meshdata_write(ctx, link_, ES_FORMAT_AUTO, nv, nf, faces, xyz, NULL));
        ES_CHECK(lstat(link_, &st) == 0 && S_ISLNK(st.st_mode));
        ES_CHECK_MSG(stat(real, &st) == 0 && (st.st_mode & 0777) == 0600, "mode %o",
                     (unsigned)(st.st_mode & 0777));
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, real, ES_FORMAT_AUTO, &back));
        ES_CHECK(back.nverts == nv);
        es_meshdata_clear(ctx, &back);
        remove(stale), remove(link_), remove(real);
    }
    free(xyz);
    free(faces);
    free(rgb);
}

/* ---------------------------------------------------------------- malformed */

static void test_malformed(es_ctx *ctx)
{
    char line[1024], path[2048];
    int listed = 0, files = 0;
    FILE *f = fopen(SRC "/malformed/EXPECTED", "r");
    ES_CHECK(f != NULL);
    if (!f) return;
    while (fgets(line, sizeof line, f)) {
        char *tab = strchr(line, '\t'), *nl = strchr(line, '\n'), want[1200];
        es_meshdata md;
        if (line[0] == '#' || !tab) continue;
        *tab = '\0';
        if (nl) *nl = '\0';
        snprintf(path, sizeof path, "%s/malformed/%s", SRC, line);
        snprintf(want, sizeof want, "%s%s", line, tab + 1);
        es_status rc = es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md);
        ES_CHECK_MSG((rc == ES_EFORMAT || rc == ES_EIO) && strstr(es_ctx_errmsg(ctx), want),
                     "%s: got %d '%s', want '%s'", line, (int)rc, es_ctx_errmsg(ctx), want);
        ES_CHECK(md.xyz == NULL && md.faces == NULL && md.nverts == 0 && md.nfaces == 0);
        listed++;
    }
    fclose(f);
    /* every file of the corpus is listed */
    DIR *d = opendir(SRC "/malformed");
    struct dirent *e;
    while (d && (e = readdir(d))) {
        const char *dot = strrchr(e->d_name, '.');
        if (dot && (!strcmp(dot, ".obj") || !strcmp(dot, ".ply") || !strcmp(dot, ".off")))
            files++;
    }
    if (d) closedir(d);
    ES_CHECK_MSG(listed == files && listed >= 20, "%d listed, %d files", listed, files);
}

/* Prefixes of text files must parse or fail cleanly (ASan watches). */
static void test_prefixes(es_ctx *ctx)
{
    const char *names[] = {"/valid/cube.obj", "/valid/cube.off", "/valid/tetra.ply",
                           "/valid/tetra_le.ply", "/valid/tetra_be.ply"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[512];
        size_t len;
        snprintf(path, sizeof path, "%s%s", SRC, names[i]);
        char *buf = slurp(path, &len);
        ES_CHECK(buf != NULL);
        if (!buf) continue;
        for (size_t cut = 0; cut <= len; cut++) {
            es_meshdata md;
            char *pre = malloc(cut ? cut : 1);
            memcpy(pre, buf, cut);
            es_status rc = es_meshdata_parse(ctx, path, pre, cut, ES_FORMAT_AUTO, &md);
            ES_CHECK(rc == ES_OK || rc == ES_EFORMAT);
            if (cut == len) ES_CHECK(rc == ES_OK);
            if (rc == ES_OK) ES_CHECK(md.nverts > 0 && md.nfaces > 0);
            es_meshdata_clear(ctx, &md);
            free(pre);
        }
        free(buf);
    }
}

/* ---------------------------------------------------------------- allocation failures */

typedef struct tracker { int64_t count, fail_at, live; } tracker;

static void *tr_malloc(void *ud, size_t n)
{
    tracker *t = ud;
    if (++t->count == t->fail_at) return NULL;
    void *p = malloc(n);
    if (p) t->live++;
    return p;
}
static void *tr_realloc(void *ud, void *p, size_t n)
{
    tracker *t = ud;
    if (++t->count == t->fail_at) return NULL;
    void *q = realloc(p, n);
    if (q && !p) t->live++;
    return q;
}
static void tr_free(void *ud, void *p)
{
    tracker *t = ud;
    if (p) t->live--;
    free(p);
}

static void test_alloc_failures(es_ctx *ctx)
{
    const char *names[] = {"/valid/cube.obj", "/valid/cube.off", "/valid/tetra.ply",
                           "/valid/tetra_be.ply"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s%s", SRC, names[i]);
        for (int64_t k = 1; k < 100; k++) {
            tracker t = {0, k, 0};
            es_allocator a = {tr_malloc, tr_realloc, tr_free, &t};
            es_meshdata md;
            es_ctx_set_allocator(ctx, &a);
            es_status rc = es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md);
            if (rc == ES_OK) {
                ES_CHECK(md.nverts > 0);
                es_meshdata_clear(ctx, &md);
                ES_CHECK(t.live == 0);
                es_ctx_set_allocator(ctx, NULL);
                ES_CHECK_MSG(k > 2, "%s: only %" PRId64 " allocations", names[i], k - 1);
                break;
            }
            ES_CHECK_MSG(rc == ES_ENOMEM && t.live == 0, "%s: fail at %" PRId64 ": rc %d, "
                         "%" PRId64 " blocks leaked", names[i], k, (int)rc, t.live);
            es_ctx_set_allocator(ctx, NULL);
        }
    }
}

/* ---------------------------------------------------------------- meshes */

static void test_mesh(es_ctx *ctx)
{
    es_mesh *mesh = NULL, *m2 = NULL;
    es_meshdata md;
    const char *tmp = ES_BUILD_ROOT "/test_io_mesh.ply";

    ES_CHECK_OK(ctx, es_meshio_read(ctx, SRC "/valid/cube.obj", &mesh));
    if (!mesh) return;
    ES_CHECK(es_mesh_nverts(mesh) == 8 && es_mesh_nfaces(mesh) == 12 &&
             es_mesh_nedges(mesh) == 18);
    ES_CHECK(!memcmp(es_mesh_faces(mesh), cube_faces, sizeof cube_faces));
    ES_CHECK(es_mesh_xyz(mesh) && !memcmp(es_mesh_xyz(mesh), cube_xyz, sizeof cube_xyz));

    /* the mesh's own positions, then given ones with colours */
    ES_CHECK_OK(ctx, es_meshio_write(ctx, tmp, ES_FORMAT_AUTO, mesh, NULL, NULL));
    ES_CHECK_OK(ctx, es_meshdata_read(ctx, tmp, ES_FORMAT_AUTO, &md));
    check_arrays(&md, 8, cube_xyz, 12, cube_faces, "es_meshio_write");
    es_meshdata_clear(ctx, &md);
    double moved[24];
    uint8_t rgb[24];
    for (int i = 0; i < 24; i++) {
        moved[i] = cube_xyz[i] * 0.1 + 1.0 / 3.0;
        rgb[i] = (uint8_t)(i * 10);
    }
    ES_CHECK_OK(ctx, es_meshio_write(ctx, tmp, ES_FORMAT_PLY_ASCII, mesh, moved, rgb));
    ES_CHECK_OK(ctx, es_meshio_read(ctx, tmp, &m2));
    if (m2) {
        ES_CHECK(!memcmp(es_mesh_xyz(m2), moved, sizeof moved));
        ES_CHECK(!memcmp(es_mesh_faces(m2), cube_faces, sizeof cube_faces));
    }
    es_mesh_free(m2);
    m2 = NULL;

    /* a parse error and a topology error both name the file */
    ES_CHECK_FAILS(ctx, es_meshio_read(ctx, SRC "/malformed/obj_face_2.obj", &m2), ES_EFORMAT,
                   "obj_face_2.obj:5:");
    ES_CHECK(m2 == NULL);
    FILE *f = fopen(ES_BUILD_ROOT "/test_io_nonmanifold.obj", "w");
    if (f) {
        fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n"
              "f 1 2 3\nf 1 2 4\nf 2 1 5\n", f);   /* edge 1-2 in three faces */
        fclose(f);
        ES_CHECK_FAILS(ctx, es_meshio_read(ctx, ES_BUILD_ROOT "/test_io_nonmanifold.obj", &m2),
                       ES_ETOPOLOGY, "test_io_nonmanifold.obj: ");
        ES_CHECK(m2 == NULL);
        remove(ES_BUILD_ROOT "/test_io_nonmanifold.obj");
    }
    remove(tmp);
    es_mesh_free(mesh);
}

/* ---------------------------------------------------------------- real data */

/* A plain reference reader: fgets and strtod, triangles only. */
static bool naive_obj(const char *path, es_meshdata *md)
{
    FILE *f = fopen(path, "r");
    char line[512];
    int64_t vcap = 1024, fcap = 1024;
    if (!f) return false;
    memset(md, 0, sizeof *md);
    md->xyz = malloc(vcap * 3 * sizeof(double));
    md->faces = malloc(fcap * 3 * sizeof(int64_t));
    while (fgets(line, sizeof line, f)) {
        char *p = line + 2;
        if (line[0] == 'v' && line[1] == ' ') {
            if (md->nverts == vcap) md->xyz = realloc(md->xyz, (vcap *= 2) * 3 * sizeof(double));
            for (int k = 0; k < 3; k++) md->xyz[3 * md->nverts + k] = strtod(p, &p);
            md->nverts++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            if (md->nfaces == fcap)
                md->faces = realloc(md->faces, (fcap *= 2) * 3 * sizeof(int64_t));
            for (int k = 0; k < 3; k++) md->faces[3 * md->nfaces + k] = strtoll(p, &p, 10) - 1;
            md->nfaces++;
        }
    }
    fclose(f);
    return true;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static void test_shared(es_ctx *ctx)
{
    const char *data = es_test_shared_data();
    if (!data) {
        fprintf(stderr, "SKIP (section): ../shared/data is absent\n");
        return;
    }
    /* counts from ../shared/data/SOURCES.md */
    static const struct { const char *file; int64_t nv, nf; } sets[] = {
        {"facecap_arkit/neutral.obj", 1919, 3706},
        {"goast_spacetime_faces/neutral.obj", 7118, 14037},
        {"sfm_surrey_face_3448/expr_anger.obj", 3448, 6736},
        {"sumner_cat_poses/cat-01.obj", 7207, 14410},
        {"goast_cactus/cactus0.obj", 5261, 10518},
        {"goast_finger/finger0.obj", 2046, 4088}};
    char path[8192];
    es_meshdata md, first = {0}, ref;
    for (size_t i = 0; i < sizeof sets / sizeof *sets; i++) {
        snprintf(path, sizeof path, "%s/%s", data, sets[i].file);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md));
        ES_CHECK_MSG(md.nverts == sets[i].nv && md.nfaces == sets[i].nf && !md.n_polygons_split,
                     "%s: %" PRId64 " verts %" PRId64 " faces", sets[i].file, md.nverts,
                     md.nfaces);
        es_meshdata_clear(ctx, &md);
        /* and they are oriented manifolds */
        es_mesh *mesh = NULL;
        ES_CHECK_OK(ctx, es_meshio_read(ctx, path, &mesh));
        ES_CHECK(mesh && es_mesh_nfaces(mesh) == sets[i].nf);
        es_mesh_free(mesh);
    }
    /* face-study: the first three files (sorted), same face list, and the
     * same arrays as a plain strtod reader */
    char *names[256];
    int n = 0;
    snprintf(path, sizeof path, "%s/face-study", data);
    DIR *d = opendir(path);
    struct dirent *e;
    while (d && (e = readdir(d)) && n < 256) {
        const char *dot = strrchr(e->d_name, '.');
        if (dot && !strcmp(dot, ".obj")) names[n++] = strdup(e->d_name);
    }
    if (d) closedir(d);
    qsort(names, (size_t)n, sizeof *names, cmp_str);
    ES_CHECK(n == 90);
    for (int i = 0; i < n && i < 3; i++) {
        snprintf(path, sizeof path, "%s/face-study/%s", data, names[i]);
        ES_CHECK_OK(ctx, es_meshdata_read(ctx, path, ES_FORMAT_AUTO, &md));
        ES_CHECK(md.nverts == 9409 && md.nfaces == 18460 && md.n_polygons_split == 0);
        if (i == 0) {
            ES_CHECK(naive_obj(path, &ref));
            ES_CHECK_MSG(same_data(&md, &ref), "%s differs from the strtod reader", names[i]);
            free(ref.xyz);
            free(ref.faces);
            first = md;
            continue;
        }
        ES_CHECK(md.nfaces == first.nfaces &&
                 !memcmp(md.faces, first.faces, (size_t)md.nfaces * 3 * sizeof(int64_t)));
        es_meshdata_clear(ctx, &md);
    }
    es_meshdata_clear(ctx, &first);
    for (int i = 0; i < n; i++) free(names[i]);
}

/* CSV fields: plain text as is, quoted (quotes doubled) when it holds a
 * comma, quote or line break, NULL as empty; what a spreadsheet would run as
 * a formula (issue 25: "=cmd|' /C calc'!A0") quoted behind an apostrophe,
 * numbers with a sign as they are. */
static void test_csv_field(void)
{
    static const char *in[] = {"s01", "a,b", "say \"hi\"", "two\nlines", "",
                               "=cmd|' /C calc'!A0", "@SUM(A1)", "+x", "-1.5", "+2e3", "a=b",
                               NULL};
    static const char *want = "s01|\"a,b\"|\"say \"\"hi\"\"\"|\"two\nlines\"||"
                              "\"'=cmd|' /C calc'!A0\"|\"'@SUM(A1)\"|\"'+x\"|-1.5|+2e3|a=b|";
    char buf[256] = {0};
    FILE *f = tmpfile();
    ES_CHECK(f != NULL);
    if (!f) return;
    for (size_t i = 0; i < sizeof in / sizeof in[0]; i++) {
        if (i) fputc('|', f);
        es_csv_write_field(f, in[i]);
    }
    rewind(f);
    ES_CHECK(fread(buf, 1, sizeof buf - 1, f) == strlen(want));
    ES_CHECK_MSG(strcmp(buf, want) == 0, "csv fields: got [%s]", buf);
    fclose(f);
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    es_ctx_set_log(ctx, count_log, NULL);
    test_csv_field();
    test_syntax(ctx);
    test_round_trips(ctx);
    test_malformed(ctx);
    test_prefixes(ctx);
    test_alloc_failures(ctx);
    test_mesh(ctx);
    test_shared(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
