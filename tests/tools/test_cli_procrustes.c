/* tests/tools/test_cli_procrustes.c — edgespace gpa, compare and ingest-landmarks:
 * help, exit statuses (0 ok, 1 failure, 2 usage), messages, and a whole run
 * on synthetic barbells and on a landmark CSV with a fan triangulation. */
#include "core/core_private.h"
#include "es_test.h"
#include "es_test_run.h"
#include "edgespace/edgespace.h"

#include <sys/stat.h>

static int exists(const char *dir, const char *f)
{
    char p[1024];
    struct stat st;
    snprintf(p, sizeof p, "%s/%s", dir, f);
    return stat(p, &st) == 0 && st.st_size > 0;
}

int main(void)
{
    ES_TEST_BEGIN();
    if (!es_test_edgespace()) ES_TEST_SKIP("EDGESPACE not set");
    static es_test_out r;
    char dir[512], bb[600], store[600], out[600], lm[600], tri[600], spec[600], lstore[600];
    snprintf(dir, sizeof dir, "%s/test-cli-procrustes", ES_BUILD_ROOT);
    mkdir(dir, 0777);
    snprintf(bb, sizeof bb, "%s/bb", dir);
    snprintf(store, sizeof store, "%s/bb.h5", dir);
    snprintf(out, sizeof out, "%s/out", dir);
    unlink(store);

    /* help and usage errors */
    static const char *verbs[] = {"gpa", "compare", "ingest-landmarks"};
    for (int i = 0; i < 3; i++) {
        ES_RUN(&r, dir, verbs[i], "--help");
        ES_CHECK(r.status == 0 && strstr(r.out, "usage: edgespace"));
    }
    ES_RUN(&r, dir, "gpa", store);
    ES_CHECK(r.status == 2 && strstr(r.err, "edgespace gpa: missing --name"));
    ES_RUN(&r, dir, "gpa", store, "--name", "g", "--tol", "x");
    ES_CHECK(r.status == 2 && strstr(r.err, "bad --tol 'x'"));
    ES_RUN(&r, dir, "compare", store);
    ES_CHECK(r.status == 2 && strstr(r.err, "missing --gpa"));
    ES_RUN(&r, dir, "ingest-landmarks", store, "--tps", "a", "--csv", "b");
    ES_CHECK(r.status == 2 && strstr(r.err, "one of --tps or --csv"));
    ES_RUN(&r, dir, "gpa", store, "--name", "g");
    ES_CHECK(r.status == 1 && strstr(r.err, "edgespace gpa: "));

    /* barbells: synth, ingest, gpa, compare */
    ES_RUN(&r, dir, "synth", "barbell", "-o", bb, "--replace");   /* (a re-run finds it) */
    ES_CHECK(r.status == 0);
    char manifest[700];
    snprintf(manifest, sizeof manifest, "%s/manifest.csv", bb);
    ES_RUN(&r, dir, "ingest", store, "--manifest", manifest, "-q");
    ES_CHECK(r.status == 0);
    ES_RUN(&r, dir, "gpa", store, "--name", "g", "--where", "bar=long");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "gpa 'g': 2 rows, 3D, full GPA"), "%s%s", r.out,
                 r.err);
    ES_RUN(&r, dir, "compare", store, "--gpa", "g");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "at least 3"), "%s", r.err);
    /* a result is never written over silently: refused, then --replace */
    ES_RUN(&r, dir, "gpa", store, "--name", "g", "--no-scale", "--allow-reflection", "--components", "2");
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "result gpa/g exists already") &&
                 strstr(r.err, "--replace"), "%s", r.err);
    ES_RUN(&r, dir, "gpa", store, "--name", "g", "--no-scale", "--allow-reflection", "--components", "2",
           "--replace");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "4 rows, 3D, partial GPA with reflection") &&
                 strstr(r.out, "PC variance"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "compare", store, "--gpa", "g", "--permutations", "1099511627776");
    ES_CHECK_MSG(r.status == 2 && strstr(r.err, "(0 to 100000000)"), "%s", r.err);
    ES_RUN(&r, dir, "compare", store, "--gpa", "nope");
    ES_CHECK(r.status == 1 && strstr(r.err, "no GPA result 'nope'"));
    ES_RUN(&r, dir, "compare", store, "--gpa", "g", "--by", "end", "--permutations", "23", "-o",
           out, "--seed", "5");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "groups by 'end'"), "%s%s", r.out, r.err);
    static const char *files[] = {"summary.csv", "pairs.csv", "group_means.csv",
                                  "heatmap_lengths.svg", "heatmap_procrustes.svg",
                                  "heatmap_rho.svg", "pairs_scatter.svg"};
    /* the figures only in a build with figures (cairo) */
    for (int i = 0; i < (ES_HAVE_FIGURES ? 7 : 3); i++)
        ES_CHECK_MSG(exists(out, files[i]), "%s missing", files[i]);
    ES_RUN(&r, dir, "info", store);
    ES_CHECK(r.status == 0 && strstr(r.out, "compare") && strstr(r.out, "gpa"));

    /* landmarks: a CSV of 4 specimens x 5 landmarks with a fan triangulation */
    snprintf(lm, sizeof lm, "%s/lm.csv", dir);
    snprintf(spec, sizeof spec, "%s/spec.csv", dir);
    snprintf(tri, sizeof tri, "%s/tri.txt", dir);
    snprintf(lstore, sizeof lstore, "%s/lm.h5", dir);
    unlink(lstore);
    FILE *f = fopen(lm, "w");
    fputs("specimen,landmark,x,y\n", f);
    for (int j = 0; j < 4; j++)
        for (int v = 0; v < 5; v++)
            fprintf(f, "s%d,%d,%g,%g\n", j, v + 1, cos(v * 1.2566) * (1 + 0.1 * j * (v == 2)),
                    sin(v * 1.2566) + 0.05 * j);
    fclose(f);
    f = fopen(spec, "w");
    fputs("specimen,group\ns0,a\ns1,a\ns2,b\ns3,b\n", f);
    fclose(f);
    f = fopen(tri, "w");
    fputs("# fan around landmark 1\n1 2 3\n1 3 4\n1,4,5\n", f);
    fclose(f);
    /* no topology: a landmarks-only store (tests/tools/test_cli_landmarks.c has more) */
    ES_RUN(&r, dir, "ingest-landmarks", lstore, "--csv", lm, "--specimens", spec);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "(landmarks only)"), "%s%s", r.out, r.err);
    unlink(lstore);
    ES_RUN(&r, dir, "ingest-landmarks", lstore, "--csv", lm, "--specimens", spec, "--triangles",
           tri);
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "4 specimens x 5 landmarks (2D), 3 triangles"),
                 "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "gpa", lstore, "--name", "lg");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "4 rows, 2D"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "compare", lstore, "--gpa", "lg", "--by", "group", "--permutations", "5", "--no-figures");
    ES_CHECK_MSG(r.status == 0 && strstr(r.out, "4 shapes"), "%s%s", r.out, r.err);
    ES_RUN(&r, dir, "ingest-landmarks", lstore, "--csv", lm, "--triangles", tri);
    ES_CHECK(r.status == 1 && strstr(r.err, "edgespace ingest-landmarks: "));
    f = fopen(tri, "w");
    fputs("1 2 3\n1 3\n", f);
    fclose(f);
    unlink(lstore);
    ES_RUN(&r, dir, "ingest-landmarks", lstore, "--csv", lm, "--triangles", tri);
    ES_CHECK_MSG(r.status == 1 && strstr(r.err, "tri.txt:2: expected 3 landmark numbers"), "%s",
                 r.err);
    ES_TEST_END();
}
