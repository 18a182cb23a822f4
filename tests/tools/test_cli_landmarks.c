/* tests/tools/test_cli_landmarks.c — edgespace ingest-landmarks in its three
 * modes (no topology, --edges, --triangles) and what each store supports:
 * info names the topology kind, gpa runs on all, length statistics refuse
 * a landmarks-only store with the "has no edges" message and run on a truss
 * store (mean, pca, diff, point), which reports that validity is unchecked. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_run.h"

#include <sys/stat.h>

int main(void)
{
    ES_TEST_BEGIN();
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE not set");
    static es_test_out r;
    char dir[512], lm[600], spec[600], ed[600], tri[600], none[600], truss[600], mesh[600];
    snprintf(dir, sizeof dir, "%s/test-cli-landmarks", ES_BUILD_ROOT);
    mkdir(dir, 0777);
    snprintf(lm, sizeof lm, "%s/lm.csv", dir);
    snprintf(spec, sizeof spec, "%s/spec.csv", dir);
    snprintf(ed, sizeof ed, "%s/edges.txt", dir);
    snprintf(tri, sizeof tri, "%s/tri.txt", dir);
    snprintf(none, sizeof none, "%s/none.h5", dir);
    snprintf(truss, sizeof truss, "%s/truss.h5", dir);
    snprintf(mesh, sizeof mesh, "%s/mesh.h5", dir);
    unlink(none), unlink(truss), unlink(mesh);
    FILE *f = fopen(lm, "w");
    fputs("specimen,landmark,x,y\n", f);
    for (int j = 0; j < 6; j++) {
        double p[5][2] = {{0, 0}, {2, 0}, {2.5, 1.5}, {1, 2.5 + 0.1 * j}, {-0.5, 1.5}};
        for (int v = 0; v < 5; v++)
            fprintf(f, "s%d,%d,%.6f,%.6f\n", j, v + 1, p[v][0] * (1 + 0.03 * j * (v % 2)),
                    p[v][1] + 0.02 * ((j * 7 + v * 3) % 5));
    }
    fclose(f);
    f = fopen(spec, "w");
    fputs("specimen,group,pair\ns0,a,p0\ns1,a,p1\ns2,a,p2\ns3,b,p0\ns4,b,p1\ns5,b,p2\n", f);
    fclose(f);
    f = fopen(ed, "w");
    fputs("# pentagon and two diagonals\n1 2\n2 3\n3 4\n4 5\n5 1\n1,3\n1 4\n", f);
    fclose(f);
    f = fopen(tri, "w");
    fputs("1 2 3\n1 3 4\n1 4 5\n", f);
    fclose(f);

    ES_RUN(&r, dir, "ingest-landmarks", "--help");
    ES_CHECK(r.status == 0 && strstr(r.out, "[--triangles FILE | --edges FILE]") &&
             strstr(r.out, "truss") && strstr(r.out, "landmark configurations only"));

    /* no topology */
    ES_RUN(&r, dir, "ingest-landmarks", none, "--csv", lm, "--specimens", spec);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "6 specimens x 5 landmarks (2D), 0 edges "
                                         "(landmarks only)"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "info", none, "--rows");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "none: 5 vertices, 0 faces, 0 edges") &&
                 strstr(r.out, "s0\t-\ta\tp0"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "gpa", none, "--name", "g");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "6 rows, 2D"), "%s%s", r.out, r.err);
    static const char *const len_verbs[] = {"pca", "mean"};
    for (int i = 0; i < 2; i++) {
        ES_RUN(&r, dir, len_verbs[i], none);
        ES_CHECK_MSG(r.status == 1 && strstr(r.err, "has no edges: it holds landmarks only; "
                                             "give --edges or --triangles at ingest"),
                     "%s: %s", len_verbs[i], r.err);
    }
    ES_RUN(&r, dir, "compare", none, "--gpa", "g", "--no-figures");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "has no edges"), "%s", r.err);

    /* truss */
    ES_RUN(&r, dir, "ingest-landmarks", truss, "--csv", lm, "--specimens", spec, "--edges", ed);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "7 edges (truss)"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "info", truss);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "truss: 5 vertices, 0 faces, 7 edges"), "%s%s",
                 r.out, r.err);
    ES_RUN(&r, dir, "pca", truss, "--name", "p");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "6 rows x 7 edges"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "mean", truss, "--by", "group");
    ES_CHECK_MSG(r.status == 0, "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "diff", truss, "--pair-by", "pair", "--column", "group", "--from", "a",
           "--to", "b", "--output", "-");
    /* stdout is the CSV alone; the summary goes to stderr */
    ES_CHECK_MSG(r.status == 0 && strstr(r.err, "3 pairs") &&
                 !strncmp(r.out, "edge,v0,v1,mean", 15), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "diff", none, "--pair-by", "pair", "--column", "group", "--from", "a",
           "--to", "b");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "has no edges"), "%s", r.err);
    ES_RUN(&r, dir, "point", truss, "row:s0");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "lengths sum to 1") &&
                 strstr(r.out, "validity: not checked"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "gpa", truss, "--name", "g");
    ES_CHECK_MSG(r.status == 0, "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "compare", truss, "--gpa", "g", "--by", "group", "--permutations", "5", "--no-figures");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "6 shapes"), "%s%s", r.out, r.err);

    /* triangles: a mesh store as before */
    ES_RUN(&r, dir, "ingest-landmarks", mesh, "--csv", lm, "--triangles", tri);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "3 triangles"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "info", mesh);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "mesh: 5 vertices, 3 faces, 7 edges"), "%s%s",
                 r.out, r.err);
    ES_RUN(&r, dir, "ingest-landmarks", mesh, "--csv", lm, "--edges", ed, "--triangles", tri);
    ES_CHECK(r.status == 2);
    ES_TEST_END();
}
