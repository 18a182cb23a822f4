/* lib/include/edgespace/es_morph.h — the other papers' ways between shapes,
 * beside the project's own (edge-length interpolation, each frame embedded:
 * es_interp.h, es_embed.h), on the same topology and arrays:
 *
 *  - multi-scale geometry interpolation (Winkler, Drieseberg, Alexa and
 *    Hormann 2010, ../shared/papers/multi-scale-geometry-interpolation):
 *    lengths and dihedrals interpolated per wedge, the mesh put together
 *    from a hierarchy of overlapping patches by multi-registration and
 *    least-squares blending, one factorization per patch and topology;
 *  - morphing in shape space (Wuhrer, Bose, Shu, O'Rourke and Brunton
 *    2010, morphing-triangular-meshes-in-shape-space): lengths interpolated
 *    linearly and face normals by SLERP, the mesh rebuilt by walking a
 *    minimum spanning tree of the dual graph, averaging the candidate
 *    positions of each vertex;
 *  - data-driven paths (Gao, Chen, Lai and Xia 2017,
 *    data-driven-shape-interpolation): a path through a collection of
 *    example shapes (a K-nearest-neighbour graph, Dijkstra, then an
 *    iterative smoothing that keeps it near the examples), each point of
 *    it a combination of the examples;
 *  - the conformal morph of edge-length-interpolation Sec. 5: a closed
 *    genus-0 mesh taken to the sphere by discrete conformal factors u,
 *    frame k of lengths e^(k (u_a + u_b) / 2) l_ab embedded;
 *
 * Where a paper is silent the choice made is written at the function. The
 * quality of a mesh made by any of them is measured as the embedder's
 * (es_morph_report fills an es_embed_report), so the methods compare on one
 * scale.
 */
#ifndef EDGESPACE_ES_MORPH_H
#define EDGESPACE_ES_MORPH_H

#include "es_core.h"
#include "es_mesh.h"
#include "es_embed.h"
#include "es_interp.h"

/* ---- data-driven paths (Gao et al. 2017) -------------------------------------
 * A path from example src to example dst through a collection of n
 * examples, given by their coordinates x (dim x n, column-major, leading
 * dimension ldx; the caller's: edgespace uses the rows' edge-length PCA
 * scores with every component, where distances are those of the lengths):
 *  1. the K-nearest-neighbour graph of the examples (L2), made connected
 *     by adding the shortest arc between the part holding example 0 and
 *     the rest, again until one part is left (Sec. 3.2.1, "similar to
 *     Prim's algorithm");
 *  2. Dijkstra from src to dst on it, the polyline resampled evenly by
 *     length to `samples` points (the ends held);
 *  3. iterations of eq. 2: each inner sample pulled toward its k~ nearest
 *     examples with weights exp(-distance / sigma), gamma times the squared
 *     lengths of the path's segments, lambda times its Laplacian (the
 *     paper's weights, L(i, i-1) = -d_{i-1} / (d_{i-1} + d_i), which at a
 *     fixed point are the uniform Laplacian, so the samples spread evenly),
 *     delta times the distance from the previous iterate; one SPD solve
 *     per iteration, until the mean move of a sample is below eps or
 *     max_iter;
 *  4. the path resampled evenly by length to nframes frames (Sec. 3.2.3).
 * The paper's sigma, gamma, lambda, delta and eps (0.01, 0.01, 100, 1e-4,
 * 1e-3) are in its coordinates' units, which it does not state; here the
 * coordinates are measured in `scale`, the mean length of the graph's
 * K-nearest-neighbour arcs, and sigma defaults to 1 of it (0.01 of it
 * left every weight below e^-50: a straight line). */
typedef struct es_data_path_opts {
    int64_t knn;        /* K: neighbours of each example in the graph (6) */
    int64_t near;       /* k~: examples pulling each sample (6) */
    int64_t samples;    /* points of the path while it is optimized (200) */
    double sigma;       /* weight fall-off, in units of scale (1) */
    double gamma;       /* segment lengths (0.01) */
    double lambda;      /* Laplacian (100) */
    double delta;       /* distance from the previous iterate (1e-4) */
    double eps;         /* convergence: mean move of a sample, in scale (1e-3) */
    int max_iter;       /* (200) */
} es_data_path_opts;

ES_API void es_data_path_opts_init(es_data_path_opts *opts);

typedef struct es_data_path_info {
    double scale;           /* the unit: mean length of a K-nearest-neighbour arc */
    int64_t arcs;           /* arcs of the connected graph (undirected) */
    int64_t bridges;        /* of them added to connect it */
    int64_t hops;           /* examples on the Dijkstra path, ends included */
    double graph_length;    /* its length (coordinates' units) */
    double length;          /* length of the optimized path */
    int iterations, converged;
    /* distance from a frame to its nearest example, in units of scale:
     * along the path and along the straight line src -> dst (as many
     * frames, evenly spaced) */
    double mean_near, max_near, line_mean_near, line_max_near;
} es_data_path_info;

/* Frames (dim x nframes, column-major) of the path from src to dst; frame
 * 0 is example src and frame nframes - 1 example dst, exactly. weights
 * (n x nframes, may be NULL): each frame as an affine combination of the
 * examples (sum 1, least norm; exact when the frame lies in their affine
 * span, as it does in PCA scores with every component), which is how
 * edgespace turns a frame into lengths. info may be NULL. ES_EINVAL on
 * src == dst or out of range, n < 2, nframes < 2, non-finite coordinates or
 * options out of range. */
ES_API es_status es_data_path(es_ctx *ctx, int64_t dim, int64_t n, const double *x,
                              int64_t ldx, int64_t src, int64_t dst,
                              const es_data_path_opts *opts, int64_t nframes, double *frames,
                              double *weights, es_data_path_info *info);

/* ---- Gao et al.'s shape representation (Sec. 3.1, eq. 1) ------------------------
 * Patch-based linear rotation-invariant coordinates (Baran et al. 2009) of
 * a mesh against a base mesh, without the mean position and rotation: per
 * face the scale/shear S_f of its deformation gradient (6 numbers) and
 * log(G_p(f)^T R_f) (3), per pair of adjacent patches log(G_i^T G_j) (3);
 * R_f the gradient's rotation, G_i the mean rotation of patch i. A rigid
 * motion of the mesh leaves them unchanged; reconstruction solves for the
 * patch rotations, then the positions, by two sparse least-squares systems
 * (lri.c says how, and how the patches are made). Coordinates of several
 * meshes blend linearly (Gao et al. interpolate and extrapolate them so). */
typedef struct es_lri es_lri;

typedef struct es_lri_opts {
    int64_t patches;    /* 0: faces / 12, at most 2000 (the paper's 2000 patches on
                           SCAPE's 25K faces) */
} es_lri_opts;

ES_API void es_lri_opts_init(es_lri_opts *opts);

/* The coordinate system of `mesh` (borrowed) against base positions (3 x V,
 * copied into what is kept). ES_EINVAL on a degenerate base face. */
ES_API es_status es_lri_new(es_ctx *ctx, const es_mesh *mesh, const double *base,
                            const es_lri_opts *opts, es_lri **out);
ES_API void es_lri_free(es_lri *lri);
/* Coordinates per mesh: 9 F + 3 (adjacent patch pairs). */
ES_API int64_t es_lri_dim(const es_lri *lri);
ES_API int64_t es_lri_npatches(const es_lri *lri);
/* Coordinates x (es_lri_dim) of positions xyz (3 x V). ES_EINVAL on a
 * degenerate face. */
ES_API es_status es_lri_encode(es_ctx *ctx, es_lri *lri, const double *xyz, double *x);
/* Positions (3 x V) of coordinates x, placed arbitrarily (the first patch
 * of each part unrotated, its lowest vertex at the origin): align them. */
ES_API es_status es_lri_decode(es_ctx *ctx, es_lri *lri, const double *x, double *xyz);
/* Place reconstructed positions y (3 x V) between the source xs and target
 * xt at s (Sec. 3.2.3): the rigid motions taking y onto each by least
 * squares, their rotations interpolated as quaternions (the shorter way)
 * and their translations linearly, applied to y: out (3 x V). */
ES_API es_status es_lri_place(es_ctx *ctx, int64_t nv, const double *y, const double *xs,
                              const double *xt, double s, double *out);

/* Coordinates for es_data_path from long vectors (dim x n, leading
 * dimension ldx, e.g. the rows' normalized edge lengths): the examples'
 * principal component scores with every component, by classical scaling
 * of their centred Gram matrix (n x n: cheap for a store's rows however
 * many edges), so that distances between them are those of the vectors.
 * coords: n x n (column j = example j; the first *ncoord rows used, the
 * components whose eigenvalue exceeds 1e-12 of the largest). */
ES_API es_status es_data_path_coords(es_ctx *ctx, int64_t dim, int64_t n, const double *x,
                                     int64_t ldx, double *coords, int64_t *ncoord);

#ifdef __cplusplus
extern "C" {
#endif

/* The interpolation methods `edgespace interp --method` offers. */
typedef enum es_morph_method {
    ES_MORPH_EDGE_LENGTH = 0,   /* the project's: lengths interpolated, each frame embedded */
    ES_MORPH_MULTISCALE,        /* Winkler et al. 2010 */
    ES_MORPH_SHAPE_SPACE,       /* Wuhrer et al. 2010 */
    ES_MORPH_DATA_DRIVEN,       /* Gao et al. 2017 as the paper: the path in the rows'
                                   patch-based rotation-invariant coordinates (es_lri),
                                   each frame decoded */
    ES_MORPH_PAPER,             /* edge-length-interpolation's pipeline as published: the
                                   lengths and averaged dihedrals of es_interp_targets,
                                   each frame by es_embed_paper_solve */
    ES_MORPH_CONFORMAL,         /* edge-length-interpolation Sec. 5: one shape to the sphere
                                   (es_conformal_*) */
    ES_MORPH_DATA_DRIVEN_EL     /* Gao et al.'s path in edge-length space, each frame
                                   embedded (ES_MORPH_DATA_DRIVEN: in the paper's own
                                   coordinates, es_lri, each frame decoded) */
} es_morph_method;

/* "edge-length", "multiscale", "shape-space", "data-driven", "paper",
 * "conformal", "data-driven-el". */
ES_API const char *es_morph_method_name(es_morph_method method);
/* The method of a name; ES_ENOTFOUND lists the known names. */
ES_API es_status es_morph_method_from_name(es_ctx *ctx, const char *name,
                                           es_morph_method *out);

/* ---- the quality of a mesh ----------------------------------------------------
 * How well positions xyz (3 x V) realize target lengths (E), on the
 * embedder's scale: rms_ratio, max_rel, p99_rel, worst_edge, n_bad_faces
 * (target faces breaking the triangle inequality), scale (sum of the
 * target), realized (max_rel <= realized_rtol and no bad face), and
 * closure_after (eq. 3 at the output's dihedrals and the target's corner
 * angles); the iteration and stage fields are 0 and t_total is left as
 * the caller set it. vertex_closure and vertex_edge_error (V each, may be
 * NULL) get what es_embedder_vertex_closure / _edge_error give for an
 * embedding. */
ES_API es_status es_morph_report(es_ctx *ctx, const es_mesh *mesh, const double *target,
                                 const double *xyz, double realized_rtol,
                                 es_embed_report *report, double *vertex_closure,
                                 double *vertex_edge_error);

/* ---- multi-scale geometry interpolation (Winkler et al. 2010) ----------------
 * Preprocessing (es_multiscale_new, once per topology): the mesh is split
 * into `patches` overlapping patches by region growing from random seed
 * faces (the context's seed; opts.tries hierarchies from consecutive
 * seeds, the best kept per solve), each patch in turn, until a patch has at most
 * leaf_faces faces (Sec. 3.3); neighbouring patches overlap by the faces
 * along their common border (each part grown by the faces across its
 * border edges: the paper's "strip of width one" on each side). Every
 * inner patch's blending matrix M^T M (Sec. 3.2, eq. 2; one row per edge
 * and occurrence in a child, one vertex per connected piece held) depends
 * on the topology only and is factorized here.
 * A solve (es_multiscale_solve) from target lengths l and dihedrals alpha
 * (E each, es_geom.h's signed bending angle; boundary edges ignored):
 *  1. leaves: the faces glued greedily along a breadth-first walk of the
 *     patch's faces, each new face placed by its three lengths and its
 *     dihedral with the face it is reached from (a vertex already placed
 *     keeps its place; the blending above evens such gaps out, Sec. 3.3);
 *  2. each inner patch, bottom up: its children registered simultaneously
 *     (Williams and Bennamoun 2000: the translations eliminated in closed
 *     form, one 3 x 3 polar decomposition per child and pass; the first
 *     child fixed). The paper starts every rotation at the identity; here
 *     each child is first placed by Kabsch onto the children placed before
 *     it, always the one sharing most vertices with them next, because the
 *     leaves' frames are arbitrary and 4 passes from the identity left
 *     deep hierarchies visibly unregistered (a mesh's own lengths and
 *     dihedrals came back 7 % of its diagonal off; placed first: 1e-12).
 *     Then `passes` passes over all (Sec. 3.1: 4), then the children are
 *     blended by least squares on the edges with their directions and the
 *     target lengths (eq. 3);
 *  3. the root patch is the mesh.
 * Vertices in no face come out at the origin. The output's placement and
 * orientation are arbitrary (those of the first leaf): align it. */
typedef struct es_multiscale es_multiscale;

typedef struct es_multiscale_opts {
    int64_t patches;      /* children per patch, m (6, the paper's choice) */
    int64_t leaf_faces;   /* a patch of at most this many faces is a leaf (0: m) */
    int passes;           /* registration passes after the first (4, Sec. 3.1) */
    int tries;            /* hierarchies built, from seeds s, s + 1, ..., s = the
                             context's seed; every solve runs each and keeps the
                             result of least energy: the mean squared relative length
                             error plus the mean squared dihedral error (rad^2) of the
                             output against the solve's own targets, what the method
                             sets out to reproduce (4; 1: the one hierarchy of seed
                             s, as the paper). The random seed faces make single
                             hierarchies differ widely; midpoints, 10 seeds or 10
                             disjoint blocks of 4 (bench_multiscale_seeds): cat-01 ->
                             cat-02 RMS ratio 2.2-12.2 % and max error 67-861 % alone,
                             2.2-9.5 % and 41-191 % best of 4; face-study s001 neutral
                             -> happy 0.21-0.79 % / 14-72 % alone, 0.18-0.28 % /
                             12-27 % best of 4 (energy and RMS ratio rank-correlate
                             0.66-0.83 over single seeds) */
} es_multiscale_opts;

ES_API void es_multiscale_opts_init(es_multiscale_opts *opts);

typedef struct es_multiscale_info {
    int64_t levels;         /* depth of the hierarchy (the root is level 0) */
    int64_t nodes, leaves;  /* patches in all, of them leaves */
    int64_t max_leaf;       /* faces in the largest leaf */
    double t_split;         /* preprocessing: building the hierarchy (s) */
    double t_factor;        /* preprocessing: factorizing the blending matrices (s) */
    double t_leaves;        /* last solve: gluing the leaves (s) */
    double t_register;      /* last solve: multi-registration (s) */
    double t_blend;         /* last solve: blending (s) */
    int tries;              /* hierarchies (opts.tries); the counts above are the
                               first's, the times the sums over all */
    int chosen;             /* last solve: the hierarchy kept (0: seed s, 1: s + 1, ...) */
    double energy;          /* last solve: its energy (see opts.tries) */
    double energy_max;      /* last solve: the largest energy among the tries */
} es_multiscale_info;

/* Build the hierarchy of `mesh` (borrowed; must outlive the object). opts
 * NULL: defaults. ES_EINVAL on a mesh without faces or options out of range
 * (patches < 2, passes < 0). */
ES_API es_status es_multiscale_new(es_ctx *ctx, const es_mesh *mesh,
                                   const es_multiscale_opts *opts, es_multiscale **out);
ES_API void es_multiscale_free(es_multiscale *ms);
ES_API void es_multiscale_get_info(const es_multiscale *ms, es_multiscale_info *info);

/* Positions xyz (3 x V) from target lengths len (E, positive) and dihedrals
 * alpha (E). ES_EINVAL names an edge whose length is not finite and
 * positive or whose dihedral is not finite. */
ES_API es_status es_multiscale_solve(es_ctx *ctx, es_multiscale *ms, const double *len,
                                     const double *alpha, double *xyz);

/* Interpolate nin inputs (positions 3 x V each) with weights w as Winkler
 * et al. do (Sec. 3, 3.4): lengths and dihedrals as es_interp_targets makes
 * them (the weighted mean of the scale-normalized lengths at the weighted
 * mean scale; dihedrals along the shortest arc), solved, and rigidly
 * aligned (each connected component) to align_to (NULL: input r, the one
 * of largest weight). Weights outside [0, 1] extrapolate (Sec. 3.5) while
 * every length stays positive. info may be NULL. */
ES_API es_status es_multiscale_interp(es_ctx *ctx, es_multiscale *ms, int64_t nin,
                                      const double *const *xyz, const double *w,
                                      const double *align_to, double *out,
                                      es_interp_info *info);

/* ---- morphing in shape space (Wuhrer et al. 2010) ----------------------------
 * Two poses A and B (B rigidly aligned to A first, each connected component
 * on its own, as Sec. 3 and 5 do) are points of a shape space of edge
 * lengths and unit face normals; frame t has lengths (1 - t) l_A + t l_B
 * (or the caller's) and normals SLERPed from A's to B's (an antipodal pair
 * turns about the face's first edge). The mesh is rebuilt by walking a
 * minimum spanning tree of the dual graph (arc weight: the change of the
 * dihedral across the edge from A to B, Sec. 5) depth first from the face
 * of each component's first vertex and first edge, whose position and
 * direction are interpolated linearly and by SLERP. Crossing an arc from a
 * placed face, the new face's third vertex gets candidate positions from
 * the latest candidate of the shared edge's more recently updated end and
 * every candidate of the other (the averaging algorithm, Sec. 6), each
 * placed by the face's lengths in the plane of its normal (on the line of
 * the two candidates, centred at their midpoint); a vertex ends at the mean
 * of its candidates. On a triangulated polygon (the dual graph a tree)
 * every vertex has one candidate and frame t realizes its lengths exactly
 * (Theorem 1). Vertices in no face come out at the origin.
 * The bound. Sec. 6 says the averaging makes O(n) candidates per vertex,
 * O(n^2) in all; it does not: a vertex reached across a shared edge takes
 * as many new candidates as the edge's older end has, and those counts add
 * up along the walk. Counted at the midpoints of real pairs
 * (info.paper_candidates, tools/bench/bench_shape_space.c): facecap (1,919
 * vertices) 3.9e5, finger (2,046) 5.6e7, sfm_surrey (3,448) 9.2e9, cactus
 * (5,261) 5.6e8, Spacetime Faces (7,118) 3.4e12, cat (7,207) 7.3e9,
 * face-study (9,409) 1.4e12: no power of V bounds it (the issue measured
 * 2.2e11 on an 8.4K horse and 4e13 on a 10K body; the old notes here said
 * O(V^2), wrong too). So a vertex stores at most opts.cap candidates, each
 * slot weighted by how many of the paper's it stands for: a candidate made
 * from a slot of weight w has weight w (the paper would make w there, one
 * per candidate the slot merged); a vertex's position is the weighted mean
 * of all its candidates (exactly the paper's mean while no slot merged);
 * a vertex one candidate over the cap merges its two oldest slots into
 * their weighted mean (the newest, which the next face takes as "the
 * latest", stay exact). Memory is then at most cap slots per vertex and
 * time O(cap) per tree arc. Measured: cap 32 is 2.9e-4 (RMS, of the
 * diagonal) from the unbounded rule on facecap and 3.5e-4 on the closed
 * test tube, within 4e-5 of cap 256 on every real pair; face-study's
 * midpoint 0.13 s and 99 MiB peak, where the rule itself would make 1.4e12
 * candidates (33 TB). */
typedef struct es_shape_space es_shape_space;

typedef struct es_shape_space_opts {
    int64_t cap;            /* stored candidates per vertex, >= 2 (32) */
} es_shape_space_opts;

ES_API void es_shape_space_opts_init(es_shape_space_opts *opts);

typedef struct es_shape_space_info {
    int64_t dual_arcs;      /* interior edges: arcs of the dual graph */
    int64_t tree_arcs;      /* arcs of the spanning forest */
    int64_t candidates;     /* candidate slots stored at the end of the last frame */
    int64_t max_candidates; /* most slots of one vertex (<= cap) */
    double paper_candidates; /* candidates the paper's averaging makes for that frame
                               (the slots' weights: exact, however many merged) */
    double paper_max;       /* the most of one vertex */
} es_shape_space_info;

/* The shape-space points of poses xa and xb (3 x V each, copied; B is
 * aligned to A) and the spanning forest. The mesh is borrowed. opts NULL:
 * defaults. ES_EINVAL on a non-finite position, a degenerate face (no
 * normal) or a cap below 2. */
ES_API es_status es_shape_space_new(es_ctx *ctx, const es_mesh *mesh, const double *xa,
                                    const double *xb, const es_shape_space_opts *opts,
                                    es_shape_space **out);
ES_API void es_shape_space_free(es_shape_space *ss);
ES_API void es_shape_space_get_info(const es_shape_space *ss, es_shape_space_info *info);

/* Frame t (any real: outside [0, 1] extrapolates) into xyz (3 x V, in A's
 * frame). len: the frame's lengths (E), or NULL for (1 - t) l_A + t l_B;
 * ES_EINVAL names an edge whose length is not positive. */
ES_API es_status es_shape_space_frame(es_ctx *ctx, es_shape_space *ss, const double *len,
                                      double t, double *xyz);

/* ---- the conformal morph (edge-length-interpolation Sec. 5, Fig. 11) ----------
 * A closed genus-0 mesh with lengths l is discretely conformally equivalent
 * (l~_ab = e^((u_a + u_b) / 2) l_ab, the paper's eq. 13, Springborn,
 * Schröder and Pinkall 2008) to a mesh inscribed in a sphere; frame k has
 * lengths e^(k (u_a + u_b) / 2) l_ab and is embedded from the two ends'
 * dihedrals interpolated (the paper: "as usual"), so k = 0 is the mesh and
 * k = 1 the sphere. How the factors are found (the paper cites [27, 4]
 * only) is written at conformal.c: one vertex to infinity, the disk left
 * flattened by CETM's Newton iteration with the boundary held by inversion,
 * inverse stereographic projection, Moebius centring, the factors read back
 * from the sphere's chordal lengths. An open mesh is closed first
 * (es_conformal_close), as the paper closes the back of its face. */
typedef struct es_conformal_info {
    int64_t infinity;       /* the vertex sent to infinity (the projection's pole) */
    int newton_iters;       /* flattening steps */
    double angle_defect;    /* max |angle sum - 2 pi| left at the flat map's interior
                               vertices (rad) */
    int mobius_iters;       /* centring steps */
    double centre_offset;   /* |area-weighted centroid| / radius after centring */
    double radius;          /* of the sphere (the edge lengths keep the input's sum) */
    double factor_residual; /* max_e |u_a + u_b - 2 log(s_e / l_e)|, s the sphere's
                               chordal lengths: how exactly the sphere realizes u
                               (rounding, unless faces are broken) */
    int64_t broken_faces;   /* faces whose flat lengths break the triangle inequality
                               (obtuse triangles where the scale changes fast): laid
                               out around, the sphere misses u on their long sides */
    double u_min, u_max;    /* range of the factors */
} es_conformal_info;

/* Factors u (V) taking lengths len (E) of `mesh` (closed, genus 0, one
 * piece) to the sphere, and the sphere's vertices (3 x V, centred at the
 * origin, faces counter-clockwise seen from outside; NULL to skip). infinity: the vertex sent to the pole (< 0: the
 * one of largest degree, e.g. a closed hole's apex). info may be NULL.
 * ES_EINVAL names what is wrong with the mesh or a length; ES_ENOCONV if
 * the flattening does not converge; ES_ENUMERIC from the factorizations,
 * and when the sphere misses the factors by more than 1e-6 without broken
 * faces (a long protrusion shrunk beyond double precision: the cat's
 * tail, goast's finger) or by more than 0.25 (log) with them. */
ES_API es_status es_conformal_sphere(es_ctx *ctx, const es_mesh *mesh, const double *len,
                                     int64_t infinity, double *u, double *sphere,
                                     es_conformal_info *info);

/* Lengths of frame k: out_e = len_e e^(k (u_a + u_b) / 2). ES_EINVAL
 * names an edge whose length is not finite and positive. */
ES_API es_status es_conformal_lengths(es_ctx *ctx, const es_mesh *mesh, const double *len,
                                      const double *u, double k, double *out);

/* Embed frame k: the lengths of xyz (3 x V, the mesh) under the factors u,
 * from the dihedrals of xyz and sphere interpolated along the shortest arc
 * with weights (1 - k, k), started and aligned as es_embed_solve does with
 * init positions `start` (the previous frame; NULL: xyz). opts and report
 * as es_embed_solve's. */
ES_API es_status es_conformal_frame(es_ctx *ctx, es_embedder *emb, const double *xyz,
                                    const double *sphere, const double *u, double k,
                                    const double *start, const es_embed_opts *opts,
                                    double *out, es_embed_report *report);

/* Close every boundary loop of `mesh` by a fan from a new vertex over the
 * loop's centroid (of xyz, or the mesh's positions when xyz is NULL),
 * raised along the fan's outward normal by the loop's largest distance
 * from its centroid (a cone; conformal_close.c says why): a new mesh
 * (*closed, caller frees)
 * whose positions (es_mesh_xyz) are xyz followed by one apex per loop; the
 * mesh's vertices keep their indices. A closed mesh comes back as a copy. */
ES_API es_status es_conformal_close(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                                    es_mesh **closed);

#ifdef __cplusplus
}
#endif
#endif
