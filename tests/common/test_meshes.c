/* tests/common/test_meshes.c — see es_test_meshes.h. */
#include "es_test_meshes.h"

void es_test_torus(int nu, int nv, int k, double *xyz, int64_t *faces)
{
    double R = 2.0 + 0.1 * k, r = 0.6 + 0.03 * (k % 5);
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
            double w = 1.0 + 0.05 * sin(3 * u + k) * cos(2 * v - 0.3 * k);
            double *p = xyz + 3 * (i * nv + j);
            p[0] = (R + r * w * cos(v)) * cos(u) * (1.0 + 0.02 * k);
            p[1] = (R + r * w * cos(v)) * sin(u);
            p[2] = r * w * sin(v) + 0.01 * k;
        }
    if (!faces) return;
    for (int i = 0, f = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            int64_t a = i * nv + j, b = ((i + 1) % nu) * nv + j, c = ((i + 1) % nu) * nv + (j + 1) % nv,
                    d = i * nv + (j + 1) % nv;
            int64_t t[6] = {a, b, c, a, c, d};
            memcpy(faces + 6 * f, t, sizeof t);
            f++;
        }
}

int es_test_write_obj(const char *path, int64_t nv, const double *xyz, int64_t nf,
                                    const int64_t *faces)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    for (int64_t v = 0; v < nv; v++)
        fprintf(f, "v %.17g %.17g %.17g\n", xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    for (int64_t t = 0; t < nf; t++)
        fprintf(f, "f %lld %lld %lld\n", (long long)faces[3 * t] + 1,
                (long long)faces[3 * t + 1] + 1, (long long)faces[3 * t + 2] + 1);
    return fclose(f);
}

int es_test_write_torus(const char *path, int nu, int nv, int k)
{
    int64_t V = (int64_t)nu * nv, F = 2 * V;
    double *xyz = malloc((size_t)(3 * V) * sizeof *xyz);
    int64_t *faces = malloc((size_t)(3 * F) * sizeof *faces);
    int rc = -1;
    if (xyz && faces) {
        es_test_torus(nu, nv, k, xyz, faces);
        rc = es_test_write_obj(path, V, xyz, F, faces);
    }
    free(xyz);
    free(faces);
    return rc;
}

double *es_test_obj_positions(const char *path, int64_t *nverts)
{
    FILE *f = fopen(path, "r");
    char line[512];
    double *xyz = NULL;
    int64_t n = 0, cap = 0;
    *nverts = 0;
    if (!f) return NULL;
    while (fgets(line, sizeof line, f)) {
        char *p = line, *end;
        if (line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 4096;
            xyz = realloc(xyz, (size_t)(3 * cap) * sizeof *xyz);
            if (!xyz) break;
        }
        p += 2;
        for (int k = 0; k < 3; k++) {
            xyz[3 * n + k] = strtod(p, &end);
            p = end;
        }
        n++;
    }
    fclose(f);
    *nverts = n;
    return xyz;
}

void es_test_lengths(int64_t E, const int64_t *edges, const double *xyz, double *len)
{
    for (int64_t e = 0; e < E; e++) {
        const double *a = xyz + 3 * edges[2 * e], *b = xyz + 3 * edges[2 * e + 1];
        double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
        len[e] = sqrt(dx * dx + dy * dy + dz * dz);
    }
}
