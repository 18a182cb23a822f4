/* tests/study/test_gpa_store.c — GPA and the comparison study on a store, and the
 * paper's barbell finding (Section 4, Fig. 7) as an assertion.
 *
 * A store is built from the synthetic barbells (es_synth: sphere-like and
 * cube-like ends x short and long bars, meshes in correspondence), GPA runs
 * on its vertex positions, and the study compares Procrustes space with
 * scale-normalized edge-length space. The finding: in Procrustes space the
 * two long barbells are clearly closer to each other than the two short
 * ones; in edge-length space the two distances are more comparable. Also:
 * what es_study_gpa writes reads back and agrees with es_gpa_align on
 * the same positions; planar rows are analysed in 2D; errors name what is
 * missing. */
#include "core/core_private.h"
#include "es_test.h"
#include "edgespace/edgespace.h"

#include <unistd.h>

const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig\n"; }

/* A store at path from a synthetic set: normalized lengths, positions,
 * labels. */
static es_status store_from_set(es_ctx *ctx, const es_synth_set *set, const char *path)
{
    es_mesh *mesh = NULL;
    es_store *s = NULL;
    es_status rc;
    unlink(path);
    if ((rc = es_mesh_new(ctx, set->nverts, set->nfaces, set->faces, set->xyz, &mesh)) != ES_OK)
        return rc;
    int64_t e = es_mesh_nedges(mesh), n = set->nmembers;
    double *len = malloc((size_t)(e * n) * sizeof *len), *sc = malloc((size_t)n * sizeof *sc);
    for (int64_t j = 0; j < n && rc == ES_OK; j++) {
        rc = es_edge_lengths(ctx, mesh, set->xyz + 3 * set->nverts * j, len + e * j);
        if (rc == ES_OK) rc = es_lengths_normalize(ctx, e, len + e * j, len + e * j, sc + j);
    }
    if (rc == ES_OK) rc = es_store_create(ctx, path, mesh, &s);
    if (rc == ES_OK) {
        es_store_rows rows = {0};
        rows.n = n;
        rows.ids = (const char *const *)set->names;
        rows.lengths = len;
        rows.scales = sc;
        rows.xyz = set->xyz;
        rows.ncols = set->nlabels;
        rows.colnames = (const char *const *)set->label_names;
        rows.labels = (const char *const *)set->labels;
        rc = es_store_append(ctx, s, &rows);
        if (rc == ES_OK) rc = es_store_commit(ctx, s);
    }
    es_store_close(s);
    es_mesh_free(mesh);
    free(len);
    free(sc);
    return rc;
}

static int64_t member(const es_synth_set *set, const char *end, const char *bar)
{
    for (int64_t i = 0; i < set->nmembers; i++) {
        int ok = 1;
        for (int64_t c = 0; c < set->nlabels; c++) {
            const char *v = set->labels[i * set->nlabels + c];
            if (!strcmp(set->label_names[c], "end")) ok &= !strcmp(v, end);
            if (!strcmp(set->label_names[c], "bar")) ok &= !strcmp(v, bar);
        }
        if (ok) return i;
    }
    return -1;
}

static void test_barbells(es_ctx *ctx)
{
    es_synth_set set = {0};
    char path[512], dir[512];
    snprintf(path, sizeof path, "%s/test-gpa-store-barbells.h5", ES_BUILD_ROOT);
    snprintf(dir, sizeof dir, "%s/test-gpa-store-out", ES_BUILD_ROOT);
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_BARBELL, NULL, &set));
    if (set.nmembers != 4) { ES_CHECK(set.nmembers == 4); es_synth_set_clear(ctx, &set); return; }
    ES_CHECK_OK(ctx, store_from_set(ctx, &set, path));
    es_store *s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) { es_synth_set_clear(ctx, &set); return; }
    es_gpa_report rep;
    es_study_gpa_opts go;
    es_study_gpa_opts_init(&go);
    go.name = "full";
    go.command = "test";
    ES_CHECK_OK(ctx, es_study_gpa(ctx, s, &go, &rep));
    ES_CHECK(rep.converged);
    es_study_compare_opts o;
    es_study_compare_opts_init(&o);
    o.gpa_name = "full";
    o.by = "end";
    o.compare.permutations = 23;   /* 4 shapes: 24 relabellings */
    o.name = "full";
    o.out_dir = dir;
    o.command = "test";
    es_compare_result *r = NULL;
    ES_CHECK_OK(ctx, es_study_compare(ctx, s, &o, &r));
    ES_CHECK_OK(ctx, es_store_commit(ctx, s));
    if (r) {
        int64_t ss = member(&set, "sphere", "short"), cs = member(&set, "cube", "short");
        int64_t sl = member(&set, "sphere", "long"), cl = member(&set, "cube", "long");
        ES_CHECK(ss >= 0 && cs >= 0 && sl >= 0 && cl >= 0);
        int64_t n = r->n;
        double p_short = r->d_proc[ss + cs * n], p_long = r->d_proc[sl + cl * n];
        double e_short = r->d_len[ss + cs * n], e_long = r->d_len[sl + cl * n];
        double rp = p_long / p_short, re = e_long / e_short;
        fprintf(stderr, "barbells: Procrustes short %.4g long %.4g (ratio %.3f); edge-length "
                "short %.4g long %.4g (ratio %.3f)\n", p_short, p_long, rp, e_short, e_long, re);
        /* Procrustes: the long pair clearly closer */
        ES_CHECK_MSG(rp < 0.75, "Procrustes ratio long/short %.3f", rp);
        /* edge lengths: more comparable, i.e. the ratio nearer 1 */
        ES_CHECK_MSG(fabs(log(re)) < 0.5 * fabs(log(rp)), "edge-length ratio %.3f vs "
                     "Procrustes %.3f", re, rp);
        es_compare_result_free(r);
    }
    es_store_close(s);
    es_synth_set_clear(ctx, &set);
}

/* What es_study_gpa writes: read back, compare with es_gpa_align on the
 * same positions, and the errors. */
static void test_results(es_ctx *ctx)
{
    es_synth_set set = {0};
    es_synth_opts so;
    char path[512];
    snprintf(path, sizeof path, "%s/test-gpa-store-tubes.h5", ES_BUILD_ROOT);
    es_synth_opts_init(&so);
    so.n = 5;
    ES_CHECK_OK(ctx, es_synth_generate(ctx, ES_SYNTH_TUBE, &so, &set));
    ES_CHECK_OK(ctx, store_from_set(ctx, &set, path));
    es_store *s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (!s) { es_synth_set_clear(ctx, &set); return; }
    int64_t rows[3] = {4, 1, 2}, k = set.nverts, kd = 3 * k;
    es_study_gpa_opts go;
    es_study_gpa_opts_init(&go);
    go.name = "partial";
    go.rows = rows;
    go.nrows = 3;
    go.gpa.scale = 0;
    go.npc = 2;
    go.command = "test";
    ES_CHECK_OK(ctx, es_study_gpa(ctx, s, &go, NULL));
    es_mat al = {0};
    int64_t *ir = NULL, nir = 0, nv = 0;
    double *rho = NULL, *sdev = NULL;
    char buf[64];
    ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, "gpa/partial/aligned", &al));
    ES_CHECK_OK(ctx, es_store_get_ints(ctx, s, "gpa/partial/input_rows", &ir, &nir));
    ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, "gpa/partial/rho", &rho, &nv));
    ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, "gpa/partial/pc_sdev", &sdev, &nv));
    ES_CHECK(nv == 2);
    ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "gpa/partial", "dim", buf, sizeof buf));
    ES_CHECK(!strcmp(buf, "3"));
    ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "gpa/partial", "params", buf, sizeof buf));
    ES_CHECK(strstr(buf, "scale=0") != NULL);
    ES_CHECK(al.rows == kd && al.cols == 3 && nir == 3 && ir && ir[0] == 4 && ir[2] == 2);
    /* the same GPA directly */
    double *x = malloc((size_t)(kd * 3) * sizeof *x), rho2[3];
    for (int j = 0; j < 3; j++) es_procrustes_from_xyz(k, set.xyz + kd * rows[j], x + kd * j);
    es_gpa_out out = {0};
    out.rho = rho2;
    ES_CHECK_OK(ctx, es_gpa_align(ctx, k, 3, (es_mat){x, kd, 3, kd}, &go.gpa, &out, NULL));
    if (al.data && rho) {
        double worst = 0;
        for (int64_t i = 0; i < kd * 3; i++) worst = fmax(worst, fabs(x[i] - al.data[i]));
        ES_CHECK(worst < 1e-12);
        for (int j = 0; j < 3; j++) ES_CHECK_CLOSE(rho[j], rho2[j], 1e-12, 0);
    }
    free(x);
    es_free(ctx, al.data);
    es_free(ctx, ir);
    es_free(ctx, rho);
    es_free(ctx, sdev);
    /* errors */
    ES_CHECK_FAILS(ctx, es_study_compare(ctx, s, &(es_study_compare_opts){.gpa_name = "nope"},
                                         NULL),
                   ES_ENOTFOUND, "no GPA result 'nope'");
    ES_CHECK_FAILS(ctx, es_study_compare(ctx, s,
                                         &(es_study_compare_opts){.gpa_name = "partial",
                                                                  .by = "colour"},
                                         NULL),
                   ES_ENOTFOUND, "no label column 'colour'");
    es_study_gpa_opts_init(&go);
    go.name = "a/b";
    ES_CHECK_FAILS(ctx, es_study_gpa(ctx, s, &go, NULL), ES_EINVAL, "has '/'");
    go.name = "one";
    go.rows = rows;
    go.nrows = 1;
    ES_CHECK_FAILS(ctx, es_study_gpa(ctx, s, &go, NULL), ES_EINVAL, "at least 2 rows");
    es_store_close(s);

    /* planar positions (z = 0) are analysed in 2D */
    for (int64_t j = 0; j < set.nmembers; j++)
        for (int64_t v = 0; v < k; v++) set.xyz[kd * j + 3 * v + 2] = 0.0;
    /* a flat tube is degenerate as a mesh, but GPA needs only positions */
    snprintf(path, sizeof path, "%s/test-gpa-store-flat.h5", ES_BUILD_ROOT);
    ES_CHECK_OK(ctx, store_from_set(ctx, &set, path));
    s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, path, ES_STORE_WRITE, &s));
    if (s) {
        es_study_gpa_opts_init(&go);
        go.name = "flat";
        go.command = "test";
        ES_CHECK_OK(ctx, es_study_gpa(ctx, s, &go, NULL));
        ES_CHECK_OK(ctx, es_store_get_attr(ctx, s, "gpa/flat", "dim", buf, sizeof buf));
        ES_CHECK(!strcmp(buf, "2"));
        es_store_close(s);
    }
    es_synth_set_clear(ctx, &set);
}

int main(void)
{
    es_ctx *ctx = NULL;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_barbells(ctx);
    test_results(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
