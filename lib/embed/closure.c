/* lib/embed/closure.c — vertex figures: corner angles, the ladybug walk of
 * edge-length-interpolation Section 2.1 (eq. 1-11), closure energy and its
 * gradient, edge-length error metrics, Kabsch alignment.
 *
 * The walk around vertex v with fan spokes u_0..u_{k-1} (es_mesh.h order) is
 *   P = Z(theta_0) X(alpha_1) Z(theta_1) X(alpha_2) ... Z(theta_{k-1}) X(alpha_0)
 * with Z, X the rotations of eq. 6 and alpha_j the signed bending angle of
 * edge (v, u_j) (es_geom.h). E_v = ||P - I||_F^2 literally (eq. 2). The
 * derivatives use prefix and suffix products (O(k) per vertex) instead of
 * eq. 7-8's closed form, because stage 1 needs the whole 9 x k Jacobian.
 * Conventions and checks: ../shared/oracle/embed/README.
 */
#include "embed/embed_pkg.h"
#include "edgespace/es_embed.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>

/* ---- 3 x 3 helpers (row-major) --------------------------------------- */

void es__mat3_mul(const double *a, const double *b, double *out)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
}

void es__mat3_mul_bt(const double *a, const double *b, double *out)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = a[3 * i] * b[3 * j] + a[3 * i + 1] * b[3 * j + 1] +
                             a[3 * i + 2] * b[3 * j + 2];
}

static double det3(const double *m)
{
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}

static void set_identity(double *m)
{
    for (int i = 0; i < 9; i++) m[i] = (i % 4 == 0) ? 1.0 : 0.0;
}

/* Polar factor by SVD with the last singular vector flipped when needed
 * (the proper rotation nearest in Frobenius norm). */
static int nearest_rotation_svd(double *m)
{
    double a[9], s[3], u[9], vt[9], sup[2], r[9];
    for (int i = 0; i < 9; i++) a[i] = m[i];   /* row-major m = column-major m^T */
    if (LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'A', 'A', 3, 3, a, 3, s, u, 3, vt, 3, sup) != 0 ||
        !(s[0] > 0)) {
        set_identity(m);
        return -1;
    }
    /* column-major: m^T = U S V^T, so m = V S U^T; rotation V U^T (col-major r^T). */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            /* r = (U V^T)^T in col-major = V U^T: r[i][j] = sum_k vt[k][i] u[j][k] */
            r[3 * i + j] = 0;
            for (int k = 0; k < 3; k++) r[3 * i + j] += vt[k + 3 * i] * u[j + 3 * k];
        }
    if (det3(r) < 0) {
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                r[3 * i + j] = 0;
                for (int k = 0; k < 3; k++)
                    r[3 * i + j] += (k == 2 ? -1.0 : 1.0) * vt[k + 3 * i] * u[j + 3 * k];
            }
    }
    for (int i = 0; i < 9; i++) m[i] = r[i];
    return 0;
}

int es__mat3_nearest_rotation(double *m)
{
    /* Newton's iteration for the polar factor with Higham's scaling; it keeps
     * det > 0, so it returns the nearest proper rotation when det(m) > 0. */
    double x[9], inv_t[9];
    double d = det3(m);
    for (int i = 0; i < 9; i++)
        if (!isfinite(m[i])) {
            set_identity(m);
            return -1;
        }
    if (!(d > 1e-12 * pow(fabs(m[0]) + fabs(m[4]) + fabs(m[8]) + 1e-300, 3)))
        return nearest_rotation_svd(m);
    for (int i = 0; i < 9; i++) x[i] = m[i];
    for (int it = 0; it < 30; it++) {
        double dt = det3(x), nx = 0, ni = 0, g, diff = 0;
        /* inverse transpose = cofactor matrix / det */
        inv_t[0] = (x[4] * x[8] - x[5] * x[7]) / dt;
        inv_t[1] = -(x[3] * x[8] - x[5] * x[6]) / dt;
        inv_t[2] = (x[3] * x[7] - x[4] * x[6]) / dt;
        inv_t[3] = -(x[1] * x[8] - x[2] * x[7]) / dt;
        inv_t[4] = (x[0] * x[8] - x[2] * x[6]) / dt;
        inv_t[5] = -(x[0] * x[7] - x[1] * x[6]) / dt;
        inv_t[6] = (x[1] * x[5] - x[2] * x[4]) / dt;
        inv_t[7] = -(x[0] * x[5] - x[2] * x[3]) / dt;
        inv_t[8] = (x[0] * x[4] - x[1] * x[3]) / dt;
        for (int i = 0; i < 9; i++) {
            nx += x[i] * x[i];
            ni += inv_t[i] * inv_t[i];
        }
        g = it < 6 ? sqrt(sqrt(ni / nx)) : 1.0;
        for (int i = 0; i < 9; i++) {
            double y = 0.5 * (g * x[i] + inv_t[i] / g);
            diff += (y - x[i]) * (y - x[i]);
            x[i] = y;
        }
        if (diff < 1e-30) break;
    }
    for (int i = 0; i < 9; i++) m[i] = x[i];
    return 0;
}

/* ---- corner angles ---------------------------------------------------- */

/* Angle opposite side c in a triangle with sides a, b, c (Kahan). */
static double kahan_angle(double a, double b, double c)
{
    double mu, num, den;
    if (a < b) {
        double t = a;
        a = b;
        b = t;
    }
    if (c > a + b) return M_PI;            /* impossible: clamp */
    if (a > b + c) return 0.0;
    if (b >= c) mu = c - (a - b);
    else mu = b - (a - c);
    num = ((a - b) + c) * mu;
    den = (a + (b + c)) * ((a - c) + b);
    if (!(num > 0)) return 0.0;
    if (!(den > 0)) return M_PI;
    return 2.0 * atan(sqrt(num / den));
}

int64_t es__corner_angles(const es_mesh *mesh, const double *len, double rtol, double *ang)
{
    int64_t nf = es_mesh_nfaces(mesh), nbad = 0;
    const int64_t *fe = es_mesh_face_edges(mesh);
    for (int64_t f = 0; f < nf; f++) {
        double l[3];
        for (int k = 0; k < 3; k++) l[k] = len[fe[3 * f + k]];
        /* corner k sits between edges k and k+2 and faces edge k+1 */
        for (int k = 0; k < 3; k++)
            ang[3 * f + k] = kahan_angle(l[k], l[(k + 2) % 3], l[(k + 1) % 3]);
        {
            double p = l[0] + l[1] + l[2];
            double mx = fmax(l[0], fmax(l[1], l[2]));
            if (mx - (p - mx) > rtol * p) nbad++;
        }
    }
    return nbad;
}

int64_t es__slot_corner(const es_mesh *mesh, int64_t v, int64_t slot)
{
    const int64_t *sf = es_mesh_star_faces(mesh), *faces = es_mesh_faces(mesh);
    int64_t f = sf[slot];
    if (f < 0) return -1;
    for (int c = 0; c < 3; c++)
        if (faces[3 * f + c] == v) return 3 * f + c;
    return -1;
}

/* ---- walks ------------------------------------------------------------ */

void es__mat3_right_z(double *m, double t)
{
    double c = cos(t), s = sin(t);
    for (int i = 0; i < 3; i++) {
        double a = m[3 * i], b = m[3 * i + 1];
        m[3 * i] = c * a + s * b;
        m[3 * i + 1] = -s * a + c * b;
    }
}

static void right_x(double *m, double t)
{
    double c = cos(t), s = sin(t);
    for (int i = 0; i < 3; i++) {
        double a = m[3 * i + 1], b = m[3 * i + 2];
        m[3 * i + 1] = c * a + s * b;
        m[3 * i + 2] = -s * a + c * b;
    }
}

static void left_z(double *m, double t)
{
    double c = cos(t), s = sin(t);
    for (int j = 0; j < 3; j++) {
        double a = m[j], b = m[3 + j];
        m[j] = c * a - s * b;
        m[3 + j] = s * a + c * b;
    }
}

static void left_x(double *m, double t)
{
    double c = cos(t), s = sin(t);
    for (int j = 0; j < 3; j++) {
        double a = m[3 + j], b = m[6 + j];
        m[3 + j] = c * a - s * b;
        m[6 + j] = s * a + c * b;
    }
}

void es__fan_frames(int64_t k, int64_t nface, const double *theta, const double *alpha,
                    double *C, double *P)
{
    double cur[9];
    set_identity(cur);
    for (int64_t j = 0; j < k; j++) {
        memcpy(C + 9 * j, cur, sizeof cur);
        if (j == k - 1) {
            if (nface == k) {
                es__mat3_right_z(cur, theta[k - 1]);
                right_x(cur, alpha[0]);
            }
            break;
        }
        es__mat3_right_z(cur, theta[j]);
        if (nface == k || j + 1 < k - 1) right_x(cur, alpha[j + 1]);
    }
    if (P) memcpy(P, cur, sizeof cur);
}

double es__fan_closure(int64_t k, const double *theta, const double *alpha, double *r,
                       double *J, double *work)
{
    int64_t nf = 2 * k;
    double *A = work, *B = work + 9 * (nf + 1), e = 0;
    set_identity(A);
    for (int64_t i = 0; i < nf; i++) {
        memcpy(A + 9 * (i + 1), A + 9 * i, 9 * sizeof(double));
        if (i % 2 == 0) es__mat3_right_z(A + 9 * (i + 1), theta[i / 2]);
        else right_x(A + 9 * (i + 1), alpha[(i / 2 + 1) % k]);
    }
    for (int m = 0; m < 9; m++) {
        r[m] = A[9 * nf + m] - ((m % 4 == 0) ? 1.0 : 0.0);
        e += r[m] * r[m];
    }
    if (!J) return e;
    set_identity(B + 9 * nf);
    for (int64_t i = nf - 1; i >= 0; i--) {
        memcpy(B + 9 * i, B + 9 * (i + 1), 9 * sizeof(double));
        if (i % 2 == 0) left_z(B + 9 * i, theta[i / 2]);
        else left_x(B + 9 * i, alpha[(i / 2 + 1) % k]);
    }
    for (int64_t j = 0; j < k; j++) {
        /* factor 2j+1 is X(alpha_{(j+1) % k}) */
        int64_t i = 2 * j + 1, s = (j + 1) % k;
        const double *a = A + 9 * i;
        double c = cos(alpha[s]), sn = sin(alpha[s]), t[9];
        for (int row = 0; row < 3; row++) {
            double a1 = a[3 * row + 1], a2 = a[3 * row + 2];
            t[3 * row] = 0;
            t[3 * row + 1] = -sn * a1 + c * a2;
            t[3 * row + 2] = -c * a1 - sn * a2;
        }
        es__mat3_mul(t, B + 9 * (i + 1), J + 9 * s);
    }
    return e;
}

/* ---- public: closure energy ------------------------------------------ */

es_status es_embed_closure(es_ctx *ctx, const es_mesh *mesh, const double *len,
                           const double *alpha, double *energy, double *grad,
                           double *vertex_energy)
{
    int64_t nv, ne, nf, maxk = 0;
    const int64_t *off, *se;
    const uint8_t *vb;
    double *ang = NULL, *th = NULL, *al = NULL, *J = NULL, *work = NULL, total = 0;
    es_status rc = ES_OK;
    if (!mesh || !len || !alpha) ES_FAIL(ctx, ES_EINVAL, "embed closure: NULL argument");
    nv = es_mesh_nverts(mesh);
    ne = es_mesh_nedges(mesh);
    nf = es_mesh_nfaces(mesh);
    off = es_mesh_star_offsets(mesh);
    se = es_mesh_star_edges(mesh);
    vb = es_mesh_vertex_on_boundary(mesh);
    for (int64_t e = 0; e < ne; e++) {
        if (!(isfinite(len[e]) && len[e] > 0))
            ES_FAIL(ctx, ES_EINVAL, "embed closure: length of edge %lld is %g (not finite "
                    "and positive)", (long long)e, len[e]);
        if (!es_mesh_edge_on_boundary(mesh)[e] && !isfinite(alpha[e]))
            ES_FAIL(ctx, ES_EINVAL, "embed closure: angle of edge %lld is not finite",
                    (long long)e);
    }
    for (int64_t v = 0; v < nv; v++)
        if (off[v + 1] - off[v] > maxk) maxk = off[v + 1] - off[v];
    ang = es__alloc_array(ctx, 3 * nf, sizeof *ang);
    th = es__alloc_array(ctx, maxk + 1, sizeof *th);
    al = es__alloc_array(ctx, maxk + 1, sizeof *al);
    J = es__alloc_array(ctx, 9 * (maxk + 1), sizeof *J);
    work = es__alloc_array(ctx, 18 * (2 * maxk + 2), sizeof *work);
    if (!ang || !th || !al || !J || !work) {
        rc = ES_ENOMEM;
        goto done;
    }
    es__corner_angles(mesh, len, 0.0, ang);
    if (grad)
        for (int64_t e = 0; e < ne; e++) grad[e] = 0;
    for (int64_t v = 0; v < nv; v++) {
        int64_t k = off[v + 1] - off[v];
        double r[9], ev;
        if (vertex_energy) vertex_energy[v] = 0;
        if (k == 0 || vb[v]) continue;
        for (int64_t j = 0; j < k; j++) {
            th[j] = ang[es__slot_corner(mesh, v, off[v] + j)];
            al[j] = alpha[se[off[v] + j]];
        }
        ev = es__fan_closure(k, th, al, r, grad ? J : NULL, work);
        if (vertex_energy) vertex_energy[v] = ev;
        total += ev;
        if (grad)
            for (int64_t j = 0; j < k; j++) {
                double g = 0;
                for (int m = 0; m < 9; m++) g += 2.0 * r[m] * J[9 * j + m];
                grad[se[off[v] + j]] += g;
            }
    }
    if (energy) *energy = total;
done:
    es__free(ctx, ang);
    es__free(ctx, th);
    es__free(ctx, al);
    es__free(ctx, J);
    es__free(ctx, work);
    return rc;
}

/* ---- public: metrics, alignment -------------------------------------- */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

es_status es_embed_length_error(es_ctx *ctx, const es_mesh *mesh, const double *xyz,
                                 const double *target, int normalize, double *rms_ratio,
                                 double *max_rel, double *p99_rel)
{
    int64_t ne = es_mesh_nedges(mesh);
    const int64_t *ed = es_mesh_edges(mesh);
    double *rel, *len, sl = 0, st = 0, f = 1, ss = 0, mx = 0;
    if (ne <= 0) ES_FAIL(ctx, ES_EINVAL, "embed: mesh has no edges");
    rel = es__alloc_array(ctx, ne, sizeof *rel);
    len = es__alloc_array(ctx, ne, sizeof *len);
    if (!rel || !len) {
        es__free(ctx, rel);
        es__free(ctx, len);
        return ES_ENOMEM;
    }
    for (int64_t e = 0; e < ne; e++) {
        const double *a = xyz + 3 * ed[2 * e], *b = xyz + 3 * ed[2 * e + 1];
        len[e] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                      (a[2] - b[2]) * (a[2] - b[2]));
        sl += len[e];
        st += target[e];
    }
    if (normalize && sl > 0) f = st / sl;
    for (int64_t e = 0; e < ne; e++) {
        double d = len[e] * f - target[e];
        ss += d * d;
        rel[e] = fabs(d) / target[e];
        if (!(rel[e] <= mx)) mx = rel[e];
    }
    if (rms_ratio) *rms_ratio = sqrt(ss / (double)ne) / (st / (double)ne);
    if (max_rel) *max_rel = mx;
    if (p99_rel) {
        qsort(rel, (size_t)ne, sizeof *rel, cmp_double);
        *p99_rel = rel[(int64_t)floor(0.99 * (double)(ne - 1))];
    }
    es__free(ctx, rel);
    es__free(ctx, len);
    return ES_OK;
}

es_status es_kabsch_align(es_ctx *ctx, int64_t nverts, double *xyz, const double *ref,
                          const double *w, double *rms)
{
    return es_kabsch_align_parts(ctx, nverts, xyz, ref, w, NULL, rms);
}

/* One pass gathers every part's weighted centroids and cross-covariance,
 * one 3 x 3 SVD per part gives its rotation, one pass moves the vertices:
 * O(V + parts), so a mesh split into many pieces (seams cut open) costs no
 * more than one piece. */
es_status es_kabsch_align_parts(es_ctx *ctx, int64_t nverts, double *xyz, const double *ref,
                                const double *w, const int64_t *part, double *rms)
{
    int64_t np = 1;
    double *acc, ss = 0;   /* per part: sum w, centroid of xyz (3), of ref (3), h (9), r (9) */
    enum { SW = 0, CA = 1, CB = 4, H = 7, R = 16, STRIDE = 25 };
    if (nverts <= 0 || !xyz || !ref) ES_FAIL(ctx, ES_EINVAL, "kabsch: empty input");
    if (part)
        for (int64_t v = 0; v < nverts; v++)
            if (part[v] + 1 > np) np = part[v] + 1;
    acc = es__calloc(ctx, (size_t)np * STRIDE, sizeof *acc);
    if (!acc) return ES_ENOMEM;
    for (int64_t v = 0; v < nverts; v++) {
        double wv = w ? w[v] : 1.0, *a;
        if (part && part[v] < 0) continue;
        a = acc + STRIDE * (part ? part[v] : 0);
        a[SW] += wv;
        for (int i = 0; i < 3; i++) {
            a[CA + i] += wv * xyz[3 * v + i];
            a[CB + i] += wv * ref[3 * v + i];
        }
    }
    if (!part && !(acc[SW] > 0)) {
        es__free(ctx, acc);
        ES_FAIL(ctx, ES_EINVAL, "kabsch: weights sum to %g", acc[SW]);
    }
    for (int64_t p = 0; p < np; p++)
        for (int i = 0; i < 6; i++)
            if (acc[STRIDE * p + SW] > 0) acc[STRIDE * p + CA + i] /= acc[STRIDE * p + SW];
    /* h = sum w (ref - cb)(xyz - ca)^T; the rotation R maximizing tr(R^T h)
     * is the polar factor of h (Kabsch 1976). */
    for (int64_t v = 0; v < nverts; v++) {
        double wv = w ? w[v] : 1.0, *a;
        if (part && part[v] < 0) continue;
        a = acc + STRIDE * (part ? part[v] : 0);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                a[H + 3 * i + j] += wv * (ref[3 * v + i] - a[CB + i]) * (xyz[3 * v + j] - a[CA + j]);
    }
    for (int64_t p = 0; p < np; p++) {
        double *a = acc + STRIDE * p;
        for (int i = 0; i < 9; i++) a[R + i] = a[H + i];
        /* a part with no weight keeps its place (identity, no shift) */
        if (!(a[SW] > 0) || nearest_rotation_svd(a + R) != 0) set_identity(a + R);
        if (!(a[SW] > 0))
            for (int i = 0; i < 3; i++) a[CA + i] = a[CB + i] = 0;
    }
    for (int64_t v = 0; v < nverts; v++) {
        double p[3], q[3];
        const double *a, *r;
        if (part && part[v] < 0) continue;
        a = acc + STRIDE * (part ? part[v] : 0);
        r = a + R;
        for (int i = 0; i < 3; i++) p[i] = xyz[3 * v + i] - a[CA + i];
        for (int i = 0; i < 3; i++) {
            q[i] = r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2] + a[CB + i];
            xyz[3 * v + i] = q[i];
            if (!w || w[v] > 0) ss += (q[i] - ref[3 * v + i]) * (q[i] - ref[3 * v + i]);
        }
    }
    es__free(ctx, acc);
    if (rms) *rms = sqrt(ss / (double)nverts);
    return ES_OK;
}
