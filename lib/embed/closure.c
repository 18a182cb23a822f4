/* lib/embed/closure.c — vertex figures: corner angles, the ladybug walk of
 * edge-length-interpolation Section 2.1 (eq. 1-11), and its closure energy
 * with the energy's derivatives. Stage 1 of the embedding minimizes this
 * energy, stage 2 starts from the walk's frames (solve.c), and
 * es_embed_closure gives it to callers.
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

#include <math.h>
#include <string.h>

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
    es__mat3_identity(cur);
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
    es__mat3_identity(A);
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
    es__mat3_identity(B + 9 * nf);
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
