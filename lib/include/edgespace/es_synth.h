/* lib/include/edgespace/es_synth.h — synthetic families of meshes in
 * correspondence, with known structure, that the project makes itself
 * (datasets-spec/synthetic.md describes them), and 1-to-4 subdivision.
 *
 * Every member of a family shares one face list; members differ only in
 * their positions. Families:
 *  - ES_SYNTH_BARBELL: closed genus-0 barbells (the paper's Fig. 7): a bar
 *    with two end bulbs, sphere-like or cube-like ends x n bar lengths
 *    (n = 2: short, long). In Procrustes space the long barbells are closer
 *    to each other than the short ones.
 *  - ES_SYNTH_TUBE: an open cylinder (two boundary loops) bent along a
 *    circular arc by angle theta; n members, theta = 0 .. pi.
 *  - ES_SYNTH_TUBE_CLOSED: the same with hemispherical caps (genus 0).
 *  - ES_SYNTH_FACE: a face-like bumpy dome with three holes (eyes, mouth;
 *    4 boundary loops), n subjects x {neutral, happy, angry}; subjects are
 *    random smooth bumps plus scale and rigid motion, expressions a fixed
 *    displacement field at a per-subject intensity in [0.6, 1.0].
 *  - ES_SYNTH_TUBE_TWIST: an open tube of elliptic cross-section (half-axes
 *    1 and 0.5) bent by s x 180 degrees and twisted about its axis by
 *    s x 270 degrees (growing along its length), s = 0 .. 1 over n members:
 *    a rotation past 180 degrees (Winkler et al. 2010, Figs. 1, 6, 10).
 *  - ES_SYNTH_STRIP: a triangulated 3D polygon (a strip; its dual graph is a
 *    path): the curve y = a sin x, x in [0, 2 pi], 2 thick along z, a
 *    from 1 to -1 over n members (n = 2: Wuhrer et al. 2010, Fig. 6).
 * Randomness comes from the context's seed (es_ctx_set_seed): same seed,
 * same set, bit for bit.
 */
#ifndef EDGESPACE_ES_SYNTH_H
#define EDGESPACE_ES_SYNTH_H

#include "es_core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum es_synth_family {
    ES_SYNTH_BARBELL = 1,
    ES_SYNTH_TUBE,
    ES_SYNTH_TUBE_CLOSED,
    ES_SYNTH_FACE,
    ES_SYNTH_TUBE_TWIST,
    ES_SYNTH_STRIP
} es_synth_family;

typedef struct es_synth_opts {
    int64_t n;          /* barbell: bar lengths (default 2); tube: angles (7);
                           face: subjects (10). 0 = default */
    int64_t resolution; /* mesh density, 1 .. 64; 0 = the family's default */
    double noise;       /* per-vertex Gaussian noise, sd relative to the shape's
                           size; < 0 = family default (0, face: 1e-4) */
    double span;        /* tubes and strip: members run s = 0 .. span, where s = 1
                           is the family's largest deformation (1; up to 4: s = 2
                           is a tube bent twice as far, for extrapolation) */
} es_synth_opts;

/* A generated family. All arrays are allocated through the context that
 * made it and released by es_synth_set_clear with that context. */
typedef struct es_synth_set {
    int64_t nverts, nfaces, nmembers, nlabels;
    int64_t *faces;      /* 3 x nfaces, 0-based, counter-clockwise outward */
    double *xyz;         /* 3 x nverts per member: member i at xyz + 3*nverts*i */
    char **names;        /* nmembers file stems, e.g. "barbell_cube_long" */
    char **label_names;  /* nlabels column names, e.g. "end", "bar" */
    char **labels;       /* labels[i * nlabels + j]: label j of member i */
} es_synth_set;

ES_API void es_synth_opts_init(es_synth_opts *opts);

/* Family from its name ("barbell", "tube", "tube-closed", "face",
 * "tube-twist", "strip").
 * ES_ENOTFOUND for an unknown name (the message lists the known ones). */
ES_API es_status es_synth_family_from_name(es_ctx *ctx, const char *name,
                                           es_synth_family *out);
/* Static name of a family, or NULL. */
ES_API const char *es_synth_family_name(es_synth_family family);

/* Generate a family. opts NULL: defaults. On failure *out is left empty.
 * Fails with ES_EINVAL on out-of-range options. */
ES_API es_status es_synth_generate(es_ctx *ctx, es_synth_family family,
                                   const es_synth_opts *opts, es_synth_set *out);
ES_API void es_synth_set_clear(es_ctx *ctx, es_synth_set *set);

/* Replace every member by its 1-to-4 subdivision, `levels` times. */
ES_API es_status es_synth_subdivide(es_ctx *ctx, es_synth_set *set, int levels);

/* Write <dir>/<name>.obj for each member and <dir>/manifest.csv (columns:
 * file, then the label columns). Creates dir (and its parents) if missing;
 * existing files are overwritten. ES_EIO names the path on failure. */
ES_API es_status es_synth_write(es_ctx *ctx, const es_synth_set *set, const char *dir);


#ifdef __cplusplus
}
#endif
#endif
