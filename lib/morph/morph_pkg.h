/* lib/morph/morph_pkg.h — what the files of lib/morph share: the patch
 * hierarchy of the multi-scale interpolation (multiscale_tree.c builds it,
 * multiscale.c solves on it, multiscale_register.c registers a patch's
 * children), and small vector helpers. Never installed.
 */
#ifndef EDGESPACE_MORPH_PKG_H
#define EDGESPACE_MORPH_PKG_H

#ifndef ES_MODULE_MORPH
#error "morph/morph_pkg.h is private to lib/morph/ (see lib/README.md)"
#endif

#include "core/core_private.h"
#include "core/vec3.h"
#include "embed/embed_private.h"     /* the nearest rotation */
#include "sparse/sparse_private.h"   /* sparse SPD solves */
#include "edgespace/es_morph.h"

/* ---- the multi-scale hierarchy --------------------------------------------- */

/* One patch. Its vertices are numbered locally 0 .. nv-1 in increasing
 * mesh order (verts), its edges likewise (edges, with local endpoints). */
typedef struct ms_node {
    int64_t nf, nv, ne;
    int64_t *faces;         /* nf mesh faces */
    int64_t *verts;         /* nv mesh vertices, sorted */
    int64_t *edges;         /* ne mesh edges, sorted */
    int64_t *eloc;          /* 2 ne: local endpoints (a < b in mesh order) */
    int64_t nchild;
    int64_t *child;         /* nchild node indices; none: a leaf */
    /* leaf: the gluing walk, one step per face: face, the edge it is
     * reached over (-1: it starts a piece), the face it is reached from */
    int64_t *walk;          /* 3 nf */
    /* inner: where each local vertex occurs in the children, CSR:
     * occ[occ_off[p] .. occ_off[p+1]) = pairs (child slot k, its local vertex) */
    int64_t *occ_off, *occ;
    /* inner: each local edge's occurrences in the children, CSR: triples
     * (child slot k, its local a, its local b) */
    int64_t *eocc_off, *eocc;
    int64_t *pin;           /* nv: 1 for the vertex held in the blending of its piece */
    int64_t spd;            /* the blending matrix in the set (inner) */
    int64_t level;
    double *x;              /* 3 nv: positions of the last solve, this patch's frame */
} ms_node;

struct es_multiscale {
    es_ctx *ctx;
    const es_mesh *mesh;
    es_multiscale_opts opts;
    uint64_t seed;          /* of this hierarchy's seed faces */
    es_multiscale **alt;    /* the other tries' hierarchies (opts.tries - 1) */
    double *scratch;        /* with alternatives: 3V + 2E for comparing their results */
    ms_node *node;          /* node 0 is the root */
    int64_t nnode, cap;
    es__spd *spd;
    es_multiscale_info info;
    /* work sized by the largest patch */
    int64_t maxm, maxnv;
    double *work;           /* registration and blending scratch */
    int64_t *iwork;
};

/* Build the hierarchy and factorize the blending matrices (multiscale_tree.c). */
es_status es__ms_build(es_multiscale *ms);
void es__ms_free_nodes(es_multiscale *ms);

/* Register the children of inner node n (their x in their own frames):
 * rotations r (9 per child, row-major) and translations t (3 per child)
 * taking child k's frame into the first child's (multiscale_register.c).
 * work: es__ms_register_work(m) doubles, iwork: m^2 + 2m. */
es_status es__ms_register(es_multiscale *ms, const ms_node *n, double *r, double *t,
                          double *work, int64_t *iwork);
int64_t es__ms_register_work(int64_t m);

/* ---- small vector helpers --------------------------------------------------- */

/* es__v3_sub, es__v3_cross, es__v3_dot: core/vec3.h */

/* Normalize in place; returns the length before (0 leaves v alone). */
double es__v3_normalize(double *v);

/* Apex of triangle (p, q, r) counter-clockwise about unit normal n, with
 * side lengths l_pq, l_pr, l_qr, placed on the line through p and q at its
 * midpoint (so a side pq that the positions stretch is split evenly). A
 * triangle that breaks the triangle inequality is flattened. (morph_geom.c) */
void es__apex(const double *p, const double *q, const double *n, double l_pq, double l_pr,
              double l_qr, double *r);

/* v rotated about the unit axis u by angle a (right hand). */
void es__rotate_axis(const double *v, const double *u, double a, double *out);

/* Unit normal of the triangle (a, b, c) (counter-clockwise); 0 if degenerate. */
double es__tri_normal(const double *a, const double *b, const double *c, double *n);

#endif
