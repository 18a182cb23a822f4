/* lib/synth/synth.c — synthetic families: options, the set's storage, writing a
 * family as OBJ files plus manifest.csv, and 1-to-4 midpoint subdivision.
 *
 * The shapes themselves are in synth_shapes.c. Subdivision numbers the new
 * vertices by edge id, so a subdivided family stays in correspondence and
 * the result is the same on every run. Members are written with the io
 * module's writer core es__meshdata_write (the body of es_meshio_write: OBJ,
 * %.17g, exact round trips), which takes the raw face list, so no topology
 * is built just to write files.
 */
#include "synth/synth_pkg.h"
#include "core/files.h"
#include "edgespace/es_io.h"
#include "edgespace/es_mesh.h"
#include "meshio/meshio_private.h"

#include <stdio.h>

static const char *const family_names[] = {NULL,   "barbell",    "tube", "tube-closed",
                                           "face", "tube-twist", "strip"};

void es_synth_opts_init(es_synth_opts *o)
{
    o->n = 0;
    o->resolution = 0;
    o->noise = -1;
    o->span = 1;
}

const char *es_synth_family_name(es_synth_family f)
{
    return f >= ES_SYNTH_BARBELL && f <= ES_SYNTH_STRIP ? family_names[f] : NULL;
}

es_status es_synth_family_from_name(es_ctx *ctx, const char *name, es_synth_family *out)
{
    /* Plural forms too: the issue and the paper say "barbells", "faces". */
    size_t n = name ? strlen(name) : 0;
    for (int f = ES_SYNTH_BARBELL; f <= ES_SYNTH_STRIP; f++) {
        size_t m = strlen(family_names[f]);
        if (name && (strcmp(name, family_names[f]) == 0 ||
                     (n == m + 1 && strncmp(name, family_names[f], m) == 0 && name[m] == 's'))) {
            *out = (es_synth_family)f;
            return ES_OK;
        }
    }
    ES_FAIL(ctx, ES_ENOTFOUND,
            "synth: unknown family '%s' (known: barbell, tube, tube-closed, face, "
            "tube-twist, strip)",
            name ? name : "(null)");
}

/* ---- storage ---- */

es_status es__synth_alloc(es_ctx *ctx, es_synth_set *s, int64_t nverts, int64_t nfaces,
                          int64_t nmembers, int64_t nlabels)
{
    int64_t nx, nl;
    if (!es__mul_i64(nverts, 3, &nx) || !es__mul_i64(nx, nmembers, &nx) ||
        !es__mul_i64(nmembers, nlabels, &nl))
        ES_FAIL(ctx, ES_ERANGE, "synth: %lld members of %lld vertices overflow",
                (long long)nmembers, (long long)nverts);
    s->nverts = nverts;
    s->nfaces = nfaces;
    s->nmembers = nmembers;
    s->nlabels = nlabels;
    s->faces = es__alloc_array(ctx, 3 * nfaces, sizeof *s->faces);
    s->xyz = es__alloc_array(ctx, nx, sizeof *s->xyz);
    s->names = es__calloc(ctx, (size_t)nmembers, sizeof *s->names);
    s->label_names = es__calloc(ctx, (size_t)(nlabels > 0 ? nlabels : 1), sizeof(char *));
    s->labels = es__calloc(ctx, (size_t)(nl > 0 ? nl : 1), sizeof(char *));
    if (!s->faces || !s->xyz || !s->names || !s->label_names || !s->labels) return ES_ENOMEM;
    return ES_OK;
}

es_status es__synth_str(es_ctx *ctx, char **slot, const char *fmt, ...)
{
    char buf[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    *slot = es__strdup(ctx, buf);
    return *slot ? ES_OK : ES_ENOMEM;
}

void es_synth_set_clear(es_ctx *ctx, es_synth_set *s)
{
    if (!s) return;
    if (s->names)
        for (int64_t i = 0; i < s->nmembers; i++) es__free(ctx, s->names[i]);
    if (s->label_names)
        for (int64_t j = 0; j < s->nlabels; j++) es__free(ctx, s->label_names[j]);
    if (s->labels)
        for (int64_t i = 0; i < s->nmembers * s->nlabels; i++) es__free(ctx, s->labels[i]);
    es__free(ctx, s->names);
    es__free(ctx, s->label_names);
    es__free(ctx, s->labels);
    es__free(ctx, s->faces);
    es__free(ctx, s->xyz);
    memset(s, 0, sizeof *s);
}

/* ---- generation ---- */

es_status es_synth_generate(es_ctx *ctx, es_synth_family family, const es_synth_opts *opts,
                            es_synth_set *out)
{
    es_synth_opts o;
    es_status rc;
    memset(out, 0, sizeof *out);
    if (opts) o = *opts;
    else es_synth_opts_init(&o);
    if (o.n < 0 || o.n > 10000)
        ES_FAIL(ctx, ES_EINVAL, "synth: n = %lld is not in [0, 10000]", (long long)o.n);
    if (o.resolution < 0 || o.resolution > 64)
        ES_FAIL(ctx, ES_EINVAL, "synth: resolution %lld is not in [0, 64]",
                (long long)o.resolution);
    if (!(o.noise < 1) || o.noise != o.noise)
        ES_FAIL(ctx, ES_EINVAL, "synth: noise %g is not < 1", o.noise);
    if (!(o.span > 0 && o.span <= 4))
        ES_FAIL(ctx, ES_EINVAL, "synth: span %g is not in (0, 4]", o.span);
    switch (family) {
    case ES_SYNTH_BARBELL:
        if (o.n == 1) ES_FAIL(ctx, ES_EINVAL, "synth: barbell needs n >= 2 bar lengths");
        rc = es__synth_barbell(ctx, &o, out);
        break;
    case ES_SYNTH_TUBE:
    case ES_SYNTH_TUBE_CLOSED:
    case ES_SYNTH_TUBE_TWIST:
        rc = es__synth_tube(ctx, &o, family == ES_SYNTH_TUBE_CLOSED ? 1
                                     : family == ES_SYNTH_TUBE_TWIST ? 2 : 0, out);
        break;
    case ES_SYNTH_STRIP:
        rc = es__synth_strip(ctx, &o, out);
        break;
    case ES_SYNTH_FACE:
        rc = es__synth_face(ctx, &o, out);
        break;
    default:
        ES_FAIL(ctx, ES_EINVAL, "synth: unknown family %d", (int)family);
    }
    if (rc != ES_OK) es_synth_set_clear(ctx, out);
    return rc;
}

/* ---- subdivision (es_mesh_subdivide, lib/mesh/mesh_subdivide.c) ---- */

es_status es_synth_subdivide(es_ctx *ctx, es_synth_set *s, int levels)
{
    if (levels < 0 || levels > 8)
        ES_FAIL(ctx, ES_EINVAL, "synth: subdivision levels %d not in [0, 8]", levels);
    for (int l = 0; l < levels; l++) {
        int64_t nv, *faces;
        double *xyz;
        es_status rc = es_mesh_subdivide(ctx, s->nverts, s->nfaces, s->faces, s->nmembers,
                                         s->xyz, &nv, &faces, &xyz);
        if (rc != ES_OK) return rc;
        es__free(ctx, s->faces);
        es__free(ctx, s->xyz);
        s->faces = faces;
        s->xyz = xyz;
        s->nverts = nv;
        s->nfaces *= 4;
    }
    return ES_OK;
}

/* ---- output ---- */

es_status es_synth_write(es_ctx *ctx, const es_synth_set *s, const char *dir)
{
    char path[4096];
    es_status rc;
    if (!dir || !*dir) ES_FAIL(ctx, ES_EINVAL, "synth: no output directory");
    if ((rc = es__mkdir_p(ctx, dir)) != ES_OK)
        return es__fail(ctx, rc, "synth: %s", es_ctx_errmsg(ctx));
    for (int64_t i = 0; i < s->nmembers; i++) {
        if (snprintf(path, sizeof path, "%s/%s.obj", dir, s->names[i]) >= (int)sizeof path)
            ES_FAIL(ctx, ES_ERANGE, "synth: path too long in '%s'", dir);
        rc = es__meshdata_write(ctx, path, ES_FORMAT_OBJ, s->nverts, s->nfaces, s->faces,
                                s->xyz + 3 * s->nverts * i, NULL);
        if (rc != ES_OK) return rc;
        if ((rc = es__progress(ctx, "synth write", i + 1, s->nmembers))) return rc;
    }
    if (snprintf(path, sizeof path, "%s/manifest.csv", dir) >= (int)sizeof path)
        ES_FAIL(ctx, ES_ERANGE, "synth: path too long in '%s'", dir);
    /* the manifest replaces an old one only once complete */
    es__file_replace w;
    if ((rc = es__replace_begin(ctx, path, &w)) != ES_OK)
        return es__fail(ctx, rc, "synth: %s", es_ctx_errmsg(ctx));
    fputs("file", w.f);
    for (int64_t j = 0; j < s->nlabels; j++) {
        fputc(',', w.f);
        es_csv_write_field(w.f, s->label_names[j]);
    }
    fputc('\n', w.f);
    for (int64_t i = 0; i < s->nmembers; i++) {
        fprintf(w.f, "%s.obj", s->names[i]);
        for (int64_t j = 0; j < s->nlabels; j++) {
            fputc(',', w.f);
            es_csv_write_field(w.f, s->labels[i * s->nlabels + j]);
        }
        fputc('\n', w.f);
    }
    if ((rc = es__replace_end(ctx, &w, ES_OK)) != ES_OK)
        return es__fail(ctx, rc, "synth: %s", es_ctx_errmsg(ctx));
    return ES_OK;
}
