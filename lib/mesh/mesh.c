/* lib/mesh/mesh.c — topology of a triangle mesh: validation of the face list,
 * canonical edges, face<->edge maps, accessors and the fingerprint.
 *
 * Edges are found by bucketing the 3F half-edges by their smaller vertex
 * (a counting sort, O(V + F)) and sorting each bucket by the larger one;
 * buckets hold a vertex's degree, so this is O(F log max-degree) overall.
 * Duplicate faces share all three edges, so they are found by comparing
 * the faces within each edge's group. Vertex stars are built in mesh_stars.c, boundary
 * loops and components in mesh_boundary.c. The conventions (edge order,
 * edge_faces rows, fan order) are those of es_mesh.h and of the embedding
 * oracle (../shared/oracle/README.md, conventions 2 and 6).
 */
#include "mesh/mesh_pkg.h"
#include "core/hash.h"

#include <math.h>
#include <stdlib.h>

/* ---- validation of the raw face list ---- */

static es_status check_indices(es_ctx *ctx, int64_t nv, int64_t nf, const int64_t *faces)
{
    for (int64_t f = 0; f < nf; f++) {
        const int64_t *t = faces + 3 * f;
        for (int k = 0; k < 3; k++)
            if (t[k] < 0 || t[k] >= nv)
                ES_FAIL(ctx, ES_ETOPOLOGY,
                        "mesh: face %lld: vertex index %lld out of range [0, %lld)",
                        (long long)f, (long long)t[k], (long long)nv);
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            ES_FAIL(ctx, ES_ETOPOLOGY, "mesh: face %lld (%lld, %lld, %lld) repeats a vertex",
                    (long long)f, (long long)t[0], (long long)t[1], (long long)t[2]);
    }
    return ES_OK;
}

/* Two faces with the same vertex set (in any order). */
static int same_vertex_set(const int64_t *faces, int64_t f, int64_t g)
{
    const int64_t *a = faces + 3 * f, *b = faces + 3 * g;
    for (int k = 0; k < 3; k++)
        if (a[k] != b[0] && a[k] != b[1] && a[k] != b[2]) return 0;
    return 1;
}

/* ---- canonical edges ---- */

/* A half-edge: corner k of face f, going faces[3f+k] -> faces[3f+(k+1)%3];
 * he = 3f + k. Keyed by its larger vertex inside the bucket of the smaller. */
typedef struct half { int64_t hi, he; } half;

static int cmp_half(const void *pa, const void *pb)
{
    const half *a = pa, *b = pb;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->he < b->he ? -1 : a->he > b->he;
}

static void sort_bucket(half *h, int64_t n)
{
    if (n > 24) {
        qsort(h, (size_t)n, sizeof *h, cmp_half);
        return;
    }
    for (int64_t i = 1; i < n; i++) {
        half x = h[i];
        int64_t j = i;
        for (; j > 0 && cmp_half(&h[j - 1], &x) > 0; j--) h[j] = h[j - 1];
        h[j] = x;
    }
}

static inline int64_t he_from(const int64_t *faces, int64_t he) { return faces[he]; }
static inline int64_t he_to(const int64_t *faces, int64_t he)
{
    return faces[he - he % 3 + (he % 3 + 1) % 3];
}

static inline int64_t he_lo(const int64_t *faces, int64_t he)
{
    int64_t a = he_from(faces, he), b = he_to(faces, he);
    return a < b ? a : b;
}

static es_status build_edges(es_ctx *ctx, es_mesh *m)
{
    es_status rc = ES_OK;
    int64_t nv = m->nv, nf = m->nf, nh = 3 * nf;
    const int64_t *faces = m->faces;
    int64_t *start = es__alloc_array(ctx, nv + 1, sizeof *start);
    half *h = es__alloc_array(ctx, nh > 0 ? nh : 1, sizeof *h);
    int64_t *fill = es__alloc_array(ctx, nv + 1, sizeof *fill);
    if (!start || !h || !fill) { rc = ES_ENOMEM; goto done; }

    /* counting sort by smaller vertex; stable in he */
    memset(start, 0, (size_t)(nv + 1) * sizeof *start);
    for (int64_t he = 0; he < nh; he++) {
        int64_t a = he_from(faces, he), b = he_to(faces, he);
        start[(a < b ? a : b) + 1]++;
    }
    for (int64_t v = 0; v < nv; v++) start[v + 1] += start[v];
    memcpy(fill, start, (size_t)(nv + 1) * sizeof *fill);
    for (int64_t he = 0; he < nh; he++) {
        int64_t a = he_from(faces, he), b = he_to(faces, he);
        int64_t lo = a < b ? a : b, hi = a < b ? b : a;
        h[fill[lo]++] = (half){hi, he};
    }
    for (int64_t v = 0; v < nv; v++) sort_bucket(h + start[v], start[v + 1] - start[v]);

    /* count edges, check multiplicity and orientation */
    int64_t ne = 0;
    for (int64_t i = 0; i < nh;) {
        int64_t j = i + 1;
        while (j < nh && h[j].hi == h[i].hi && he_lo(faces, h[j].he) == he_lo(faces, h[i].he))
            j++;
        int64_t a = he_from(faces, h[i].he), b = he_to(faces, h[i].he);
        int64_t emin = a < b ? a : b, emax = a < b ? b : a;
        /* duplicated faces share all their edges, so they meet in a group */
        for (int64_t p = i; p < j && j - i <= 16; p++)
            for (int64_t q = p + 1; q < j; q++)
                if (same_vertex_set(faces, h[p].he / 3, h[q].he / 3)) {
                    const int64_t *t = faces + h[p].he - h[p].he % 3;
                    rc = es__fail(ctx, ES_ETOPOLOGY,
                                  "mesh: faces %lld and %lld are duplicates "
                                  "(vertices %lld, %lld, %lld)",
                                  (long long)(h[p].he / 3), (long long)(h[q].he / 3),
                                  (long long)t[0], (long long)t[1], (long long)t[2]);
                    goto done;
                }
        if (j - i > 2) {
            rc = es__fail(ctx, ES_ETOPOLOGY,
                          "mesh: edge (%lld, %lld) is shared by %lld faces (%lld, %lld, %lld%s)",
                          (long long)emin, (long long)emax, (long long)(j - i),
                          (long long)(h[i].he / 3), (long long)(h[i + 1].he / 3),
                          (long long)(h[i + 2].he / 3), j - i > 3 ? ", ..." : "");
            goto done;
        }
        if (j - i == 2 && he_from(faces, h[i].he) == he_from(faces, h[i + 1].he)) {
            rc = es__fail(ctx, ES_ETOPOLOGY,
                          "mesh: faces %lld and %lld both traverse edge %lld->%lld: "
                          "inconsistent orientation",
                          (long long)(h[i].he / 3), (long long)(h[i + 1].he / 3),
                          (long long)a, (long long)b);
            goto done;
        }
        ne++;
        i = j;
    }

    m->ne = ne;
    m->edges = es__alloc_array(ctx, 2 * ne, sizeof *m->edges);
    m->edge_faces = es__alloc_array(ctx, 2 * ne, sizeof *m->edge_faces);
    m->face_edges = es__alloc_array(ctx, nh, sizeof *m->face_edges);
    m->edge_start = es__alloc_array(ctx, nv + 1, sizeof *m->edge_start);
    if ((!m->edges || !m->edge_faces) && ne > 0) { rc = ES_ENOMEM; goto done; }
    if ((!m->face_edges && nh > 0) || !m->edge_start) { rc = ES_ENOMEM; goto done; }

    /* assign ids: buckets are in (min, max) order already */
    int64_t e = -1, prev_lo = -1, prev_hi = -1;
    for (int64_t v = 0; v <= nv; v++) m->edge_start[v] = 0;
    for (int64_t i = 0; i < nh; i++) {
        int64_t a = he_from(faces, h[i].he), b = he_to(faces, h[i].he);
        int64_t lo = a < b ? a : b, hi = a < b ? b : a;
        if (lo != prev_lo || hi != prev_hi) {
            e++;
            m->edges[2 * e] = lo;
            m->edges[2 * e + 1] = hi;
            m->edge_faces[2 * e] = m->edge_faces[2 * e + 1] = -1;
            m->edge_start[lo + 1]++;
            prev_lo = lo;
            prev_hi = hi;
        }
        m->edge_faces[2 * e + (a < b ? 0 : 1)] = h[i].he / 3;
        m->face_edges[h[i].he] = e;
    }
    for (int64_t v = 0; v < nv; v++) m->edge_start[v + 1] += m->edge_start[v];
done:
    es__free(ctx, start);
    es__free(ctx, h);
    es__free(ctx, fill);
    return rc;
}

static es_status build_flags(es_ctx *ctx, es_mesh *m)
{
    m->vert_bnd = es__calloc(ctx, (size_t)(m->nv > 0 ? m->nv : 1), 1);
    m->edge_bnd = es__calloc(ctx, (size_t)(m->ne > 0 ? m->ne : 1), 1);
    if (!m->vert_bnd || !m->edge_bnd) return ES_ENOMEM;
    for (int64_t e = 0; e < m->ne; e++)
        if (m->edge_faces[2 * e] < 0 || m->edge_faces[2 * e + 1] < 0) {
            m->edge_bnd[e] = 1;
            m->vert_bnd[m->edges[2 * e]] = m->vert_bnd[m->edges[2 * e + 1]] = 1;
        }
    return ES_OK;
}

/* ---- construction ---- */

es_status es_mesh_new(es_ctx *ctx, int64_t nverts, int64_t nfaces, const int64_t *faces,
                      const double *xyz, es_mesh **out)
{
    return es__mesh_new(ctx, nverts, nfaces, faces, xyz, 1, out);
}

es_status es__mesh_new(es_ctx *ctx, int64_t nverts, int64_t nfaces, const int64_t *faces,
                       const double *xyz, int warn_unreferenced, es_mesh **out)
{
    es_status rc;
    int64_t n3;
    es_mesh *m;
    *out = NULL;
    if (nverts < 0 || nfaces < 0)
        ES_FAIL(ctx, ES_EINVAL, "mesh: negative vertex or face count (%lld, %lld)",
                (long long)nverts, (long long)nfaces);
    if (!faces && nfaces > 0) ES_FAIL(ctx, ES_EINVAL, "mesh: face list is NULL");
    if (!es__mul_i64(nfaces, 3, &n3) || !es__mul_i64(nverts, 3, &n3))
        ES_FAIL(ctx, ES_ERANGE, "mesh: %lld faces / %lld vertices overflow",
                (long long)nfaces, (long long)nverts);
    if ((rc = check_indices(ctx, nverts, nfaces, faces)) != ES_OK) return rc;
    /* reference positions are what embeddings align to and put unused
     * vertices at: one NaN would spread through the alignment */
    if (xyz)
        for (int64_t i = 0; i < 3 * nverts; i++)
            if (!isfinite(xyz[i]))
                ES_FAIL(ctx, ES_EINVAL, "mesh: vertex %lld has a non-finite coordinate (%g)",
                        (long long)(i / 3), xyz[i]);

    m = es__calloc(ctx, 1, sizeof *m);
    if (!m) return ES_ENOMEM;
    m->ctx = ctx;
    atomic_init(&m->refs, 1);
    m->nv = nverts;
    m->nf = nfaces;
    m->faces = es__alloc_array(ctx, 3 * nfaces > 0 ? 3 * nfaces : 1, sizeof *m->faces);
    if (!m->faces) { rc = ES_ENOMEM; goto fail; }
    if (nfaces > 0) memcpy(m->faces, faces, (size_t)(3 * nfaces) * sizeof *faces);
    if (xyz) {
        m->xyz = es__alloc_array(ctx, 3 * nverts > 0 ? 3 * nverts : 1, sizeof *m->xyz);
        if (!m->xyz) { rc = ES_ENOMEM; goto fail; }
        if (nverts > 0) memcpy(m->xyz, xyz, (size_t)(3 * nverts) * sizeof *xyz);
    }
    if ((rc = build_edges(ctx, m)) != ES_OK || (rc = build_flags(ctx, m)) != ES_OK ||
        (rc = es__mesh_build_stars(ctx, m)) != ES_OK ||
        (rc = es__mesh_build_boundary(ctx, m)) != ES_OK)
        goto fail;
    if (warn_unreferenced && m->sum.n_unreferenced > 0) {
        int64_t first = -1;
        for (int64_t v = 0; v < nverts && first < 0; v++)
            if (m->star_off[v + 1] == m->star_off[v]) first = v;
        es__warn(ctx, "mesh: %lld of %lld vertices are in no face (first: %lld)",
                 (long long)m->sum.n_unreferenced, (long long)nverts, (long long)first);
    }
    *out = m;
    return ES_OK;
fail:
    es_mesh_free(m);
    return rc;
}

es_mesh *es__mesh_ref(es_mesh *m)
{
    if (m) atomic_fetch_add(&m->refs, 1);
    return m;
}

void es_mesh_free(es_mesh *m)
{
    if (!m || atomic_fetch_sub(&m->refs, 1) > 1) return;
    es_ctx *ctx = m->ctx;
    es__free(ctx, m->faces);
    es__free(ctx, m->xyz);
    es__free(ctx, m->edges);
    es__free(ctx, m->edge_start);
    es__free(ctx, m->face_edges);
    es__free(ctx, m->edge_faces);
    es__free(ctx, m->vert_bnd);
    es__free(ctx, m->edge_bnd);
    es__free(ctx, m->star_off);
    es__free(ctx, m->star_verts);
    es__free(ctx, m->star_edges);
    es__free(ctx, m->star_faces);
    es__free(ctx, m->loop_off);
    es__free(ctx, m->loop_verts);
    es__free(ctx, m->comp);
    es__free(ctx, m);
}

/* ---- accessors ---- */

int64_t es_mesh_nverts(const es_mesh *m) { return m->nv; }
int64_t es_mesh_nfaces(const es_mesh *m) { return m->nf; }
int64_t es_mesh_nedges(const es_mesh *m) { return m->ne; }
const int64_t *es_mesh_faces(const es_mesh *m) { return m->faces; }
const int64_t *es_mesh_edges(const es_mesh *m) { return m->edges; }
const int64_t *es_mesh_face_edges(const es_mesh *m) { return m->face_edges; }
const int64_t *es_mesh_edge_faces(const es_mesh *m) { return m->edge_faces; }
const double *es_mesh_xyz(const es_mesh *m) { return m->xyz; }
const int64_t *es_mesh_star_offsets(const es_mesh *m) { return m->star_off; }
const int64_t *es_mesh_star_verts(const es_mesh *m) { return m->star_verts; }
const int64_t *es_mesh_star_edges(const es_mesh *m) { return m->star_edges; }
const int64_t *es_mesh_star_faces(const es_mesh *m) { return m->star_faces; }
const uint8_t *es_mesh_vertex_on_boundary(const es_mesh *m) { return m->vert_bnd; }
const uint8_t *es_mesh_edge_on_boundary(const es_mesh *m) { return m->edge_bnd; }
const int64_t *es_mesh_vertex_component(const es_mesh *m) { return m->comp; }

void es_mesh_summarize(const es_mesh *m, es_mesh_summary *out) { *out = m->sum; }

int64_t es_mesh_boundary_loops(const es_mesh *m, const int64_t **loop_offsets,
                               const int64_t **loop_verts)
{
    if (loop_offsets) *loop_offsets = m->loop_off;
    if (loop_verts) *loop_verts = m->loop_verts;
    return m->nloops;
}

int64_t es_mesh_find_edge(const es_mesh *m, int64_t a, int64_t b)
{
    if (a < 0 || b < 0 || a >= m->nv || b >= m->nv || a == b) return -1;
    int64_t lo = a < b ? a : b, hi = a < b ? b : a;
    int64_t l = m->edge_start[lo], r = m->edge_start[lo + 1];
    while (l < r) {
        int64_t mid = l + (r - l) / 2;
        if (m->edges[2 * mid + 1] < hi) l = mid + 1;
        else r = mid;
    }
    return l < m->edge_start[lo + 1] && m->edges[2 * l + 1] == hi ? l : -1;
}

/* ---- fingerprint: FNV-1a 64 over nverts and the 3F face indices (core/hash.h) */

void es_faces_fingerprint(int64_t nverts, int64_t nfaces, const int64_t *faces, char out[17])
{
    es__fingerprint_i64(&nverts, 1, faces, 3 * nfaces, out);
}

void es_mesh_fingerprint(const es_mesh *m, char out[17])
{
    es_faces_fingerprint(m->nv, m->nf, m->faces, out);
}
