/* tests/parallel/test_parallel_cli.c — `mpirun -n P edgespace pca STORE`
 * (the -Dmpi=enabled build) stores the result one process stores: the same
 * eigenvalues, components and scores to 1e-12, for the Gram and the
 * randomized route, at P = 2 and 4; `mpirun -n P edgespace model` the same
 * ANOVA table (SS, F and every permuted F to 1e-12, p-values equal:
 * permutation b is drawn alike on every rank) with its pairwise table,
 * and its CSV; `mpirun -n P edgespace gpa` the one-process GPA (aligned
 * configurations, mean, scales, rotations, rho and the PCs to 1e-12); the
 * store file itself is untouched
 * (results live beside it), a taken name is refused by all ranks with one
 * message, and a command that does not run on ranks yet says so.
 *
 * Usage: test_parallel_cli MPIRUN (meson passes the mpirun it found). */
#include "edgespace/edgespace.h"
#include "es_test.h"
#include "es_test_files.h"
#include "es_test_meshes.h"
#include "es_test_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *mpirun, *dir;
static char store[800];

/* `mpirun -n P edgespace ARGS`, stderr into err; its exit status. */
static int run_mpi(int P, const char *args, char *err, size_t n)
{
    char cmd[4096], errfile[900];
    snprintf(errfile, sizeof errfile, "%s/mpi.err", dir);
    snprintf(cmd, sizeof cmd, "'%s' -n %d --oversubscribe --allow-run-as-root '%s' %s "
             ">'%s/mpi.out' 2>'%s'", mpirun, P, es_test_edgespace(), args, dir, errfile);
    int st = system(cmd);
    es_test_read_small(errfile, err, n);
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128;
}

/* <kind>/<a>/<ds> and <kind>/<b>/<ds> hold the same numbers, to tol(k) of
 * their scale: datasets ds[0 .. nvec-1] are vectors, the rest matrices. */
static void same_result(es_ctx *ctx, const char *kind, const char *a, const char *b,
                        const char *const *ds, int nds, int nvec, const double *tol)
{
    es_store *s = NULL;
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
    if (!s) return;
    for (int k = 0; k < nds; k++) {
        char pa[200], pb[200];
        es_mat ma = {0}, mb = {0};
        snprintf(pa, sizeof pa, "%s/%s/%s", kind, a, ds[k]);
        snprintf(pb, sizeof pb, "%s/%s/%s", kind, b, ds[k]);
        if (k < nvec) {
            ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, pa, &ma.data, &ma.rows));
            ES_CHECK_OK(ctx, es_store_get_vector(ctx, s, pb, &mb.data, &mb.rows));
            ma.cols = mb.cols = 1;
        } else {
            ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, pa, &ma));
            ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, pb, &mb));
        }
        int64_t n = ma.rows * ma.cols;
        ES_CHECK_MSG(ma.data && mb.data && ma.rows == mb.rows && ma.cols == mb.cols && n > 0,
                     "%s vs %s: %s/%s shapes differ", a, b, kind, ds[k]);
        if (ma.data && mb.data && ma.rows == mb.rows && ma.cols == mb.cols) {
            double t = tol[k] * es_test_maxabs(ma.data, n);
            ES_CHECK_MSG(es_test_maxdiff(ma.data, mb.data, n) <= t, "%s vs %s: %s/%s differ by %g", a, b,
                         kind, ds[k], es_test_maxdiff(ma.data, mb.data, n));
        }
        es_free(ctx, ma.data);
        es_free(ctx, mb.data);
    }
    es_store_close(s);
}

/* pca/<a> and pca/<b> agree: eigenvalues and scores to 1e-12 of their
 * scale, components to 1e-9 (unit vectors). */
static void same_pca(es_ctx *ctx, const char *a, const char *b)
{
    static const char *const ds[] = {"eigenvalues", "mean", "components", "scores"};
    static const double tol[] = {1e-12, 1e-12, 1e-9, 1e-12};
    same_result(ctx, "pca", a, b, ds, 4, 2, tol);
}

/* model/<a> and model/<b> agree: SS, F, Z, coefficients, LS means and
 * every permuted F to 1e-12 of their scale (the ranks reduce the response
 * in another order: the permuted F differ by 4e-13 of 14), p-values equal
 * (the same permutations counted); the oracle is the one-process run of
 * the same command and seed. */
static void same_model(es_ctx *ctx, const char *a, const char *b)
{
    static const char *const ds[] = {"ss", "f", "z", "p", "coefficients", "f_perm", "lsmeans"};
    static const double tol[] = {1e-12, 1e-12, 1e-12, 0, 1e-12, 1e-12, 1e-12};
    same_result(ctx, "model", a, b, ds, 7, 4, tol);
}

/* gpa/<a> and gpa/<b> agree to 1e-12 of their scale (the ranks run the
 * sweep's additions in one process's order: equal but for BLAS's own
 * threading). The PCs are compared component by component up to sign:
 * their convention (the largest-magnitude loading positive) meets a tie on
 * these symmetric tori (two loadings equal in magnitude to 1e-15), where a
 * rounding-level difference flips a component, in one process too.
 * Loadings to 1e-9 as same_pca's components (unit vectors; PCs 7 and 8 of
 * these tori, sdev 1e-3 beside 1.06, move by 5e-13 with a 3e-15 change of
 * the aligned set), scores to 1e-12 of all scores' scale. */
static void same_gpa(es_ctx *ctx, const char *a, const char *b)
{
    static const char *const ds[] = {"mean", "size", "rho", "scale", "pc_sdev", "aligned",
                                     "rotation", "centroid"};
    static const double tol[] = {1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12};
    same_result(ctx, "gpa", a, b, ds, 8, 5, tol);
    es_store *s = NULL;
    es_mat la = {0}, lb = {0}, sa = {0}, sb = {0};   /* loadings kd x npc, scores npc x n */
    char p[4][200];
    snprintf(p[0], 200, "gpa/%s/pc_loadings", a);
    snprintf(p[1], 200, "gpa/%s/pc_loadings", b);
    snprintf(p[2], 200, "gpa/%s/pc_scores", a);
    snprintf(p[3], 200, "gpa/%s/pc_scores", b);
    ES_CHECK_OK(ctx, es_store_open(ctx, store, ES_STORE_READ, &s));
    if (!s) return;
    ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, p[0], &la));
    ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, p[1], &lb));
    ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, p[2], &sa));
    ES_CHECK_OK(ctx, es_store_get_matrix(ctx, s, p[3], &sb));
    int ok = la.data && lb.data && sa.data && sb.data && la.rows == lb.rows &&
             la.cols == lb.cols && sa.rows == sb.rows && sa.cols == sb.cols && sa.rows == la.cols;
    ES_CHECK_MSG(ok, "%s vs %s: the PCs' shapes differ", a, b);
    double msc = ok ? es_test_maxabs(sa.data, sa.rows * sa.cols) : 0;   /* the scores' scale */
    for (int64_t c = 0; ok && c < la.cols; c++) {
        double dot = 0, dl = 0, dsc = 0, ml = 0;
        for (int64_t v = 0; v < la.rows; v++) dot += ES_AT(la, v, c) * ES_AT(lb, v, c);
        double sg = dot < 0 ? -1.0 : 1.0;
        for (int64_t v = 0; v < la.rows; v++) {
            dl = fmax(dl, fabs(ES_AT(la, v, c) - sg * ES_AT(lb, v, c)));
            ml = fmax(ml, fabs(ES_AT(la, v, c)));
        }
        for (int64_t j = 0; j < sa.cols; j++)
            dsc = fmax(dsc, fabs(ES_AT(sa, c, j) - sg * ES_AT(sb, c, j)));
        ES_CHECK_MSG(dl <= 1e-9 * ml && dsc <= 1e-12 * msc, "%s vs %s: PC %lld differs by %g "
                     "(loadings), %g (scores)", a, b, (long long)(c + 1), dl, dsc);
    }
    es_free(ctx, la.data);
    es_free(ctx, lb.data);
    es_free(ctx, sa.data);
    es_free(ctx, sb.data);
    es_store_close(s);
}

int main(int argc, char **argv)
{
    ES_TEST_BEGIN();
    if (argc < 2) ES_TEST_SKIP("give the mpirun to use");
    mpirun = argv[1];
    es_ctx *ctx = NULL;
    es_test_out r;
    char m[900], p[900], err[65536], args[4096];
    ES_CHECK(es_ctx_new(&ctx) == ES_OK);
    dir = es_test_tmpdir("parallel-cli");
    snprintf(store, sizeof store, "%s/s.h5", dir);
    snprintf(m, sizeof m, "%s/m.csv", dir);
    FILE *f = fopen(m, "w");
    ES_CHECK(f != NULL);
    if (!f) ES_TEST_END();
    fprintf(f, "file,grp\n");
    for (int k = 0; k < 9; k++) {
        snprintf(p, sizeof p, "%s/shape%d.obj", dir, k);
        ES_CHECK(es_test_write_torus(p, 14, 8, k) == 0);
        fprintf(f, "shape%d.obj,%c\n", k, "ab"[k % 2]);
    }
    fclose(f);
    ES_CHECK_OK(ctx, es_ingest_manifest(ctx, store, m, NULL, NULL));
    size_t nbase = 0;
    char *base = es_test_slurp(store, &nbase);

    ES_RUN(&r, dir, "pca", store, "--name", "serial");
    ES_CHECK_MSG(r.status == 0, "%s", r.err);
    ES_RUN(&r, dir, "pca", store, "--name", "serial_rand", "--method", "randomized",
           "--components", "4", "--seed", "7");
    ES_CHECK_MSG(r.status == 0, "%s", r.err);
    for (int P = 2; P <= 4; P += 2) {
        char name[32], rname[32];
        snprintf(name, sizeof name, "np%d", P);
        snprintf(rname, sizeof rname, "np%d_rand", P);
        snprintf(args, sizeof args, "pca '%s' --name %s", store, name);
        ES_CHECK_MSG(run_mpi(P, args, err, sizeof err) == 0, "mpirun -n %d pca: %s", P, err);
        same_pca(ctx, "serial", name);
        snprintf(args, sizeof args, "pca '%s' --name %s --method randomized --components 4 "
                 "--seed 7", store, rname);
        ES_CHECK_MSG(run_mpi(P, args, err, sizeof err) == 0, "mpirun -n %d pca randomized: %s",
                     P, err);
        same_pca(ctx, "serial_rand", rname);
        /* the name is taken now: every rank refuses, rank 0 says so once */
        snprintf(args, sizeof args, "pca '%s' --name %s", store, name);
        ES_CHECK_MSG(run_mpi(P, args, err, sizeof err) != 0 && strstr(err, "exists already"),
                     "mpirun -n %d pca again: %s", P, err);
        char *first = strstr(err, "exists already");
        ES_CHECK_MSG(first && !strstr(first + 1, "exists already"), "the refusal is not said "
                     "once: %s", err);
    }
    /* model: every rank shares the permutations, rank 0 stores and writes */
    ES_RUN(&r, dir, "model", store, "~ grp", "--name", "serial", "--seed", "5",
           "--permutations", "199", "--pairwise", "grp");
    ES_CHECK_MSG(r.status == 0, "%s", r.err);
    for (int P = 2; P <= 4; P += 2) {
        char name[32], csv[900];
        snprintf(name, sizeof name, "np%d", P);
        snprintf(csv, sizeof csv, "%s/model_np%d.csv", dir, P);
        snprintf(args, sizeof args, "model '%s' '~ grp' --name %s --seed 5 --permutations 199 "
                 "--pairwise grp -o '%s'", store, name, csv);
        ES_CHECK_MSG(run_mpi(P, args, err, sizeof err) == 0, "mpirun -n %d model: %s", P, err);
        same_model(ctx, "serial", name);
        size_t nc = 0;
        char *text = es_test_slurp(csv, &nc);
        ES_CHECK_MSG(text && strstr(text, "grp") && strstr(text, "Residual"),
                     "the CSV of mpirun -n %d model: %s", P, text ? text : "(none)");
        free(text);
        /* the name is taken now: refused once, before any permutation */
        ES_CHECK_MSG(run_mpi(P, args, err, sizeof err) != 0 && strstr(err, "exists already"),
                     "mpirun -n %d model again: %s", P, err);
        char *first = strstr(err, "exists already");
        ES_CHECK_MSG(first && !strstr(first + 1, "exists already"), "the refusal is not said "
                     "once: %s", err);
    }
    /* gpa: every rank reads and aligns its share, rank 0 takes the PCA and stores */
    ES_RUN(&r, dir, "gpa", store, "--name", "serial");
    ES_CHECK_MSG(r.status == 0, "%s", r.err);
    for (int P = 2; P <= 4; P += 2) {
        snprintf(args, sizeof args, "gpa '%s' --name np%d", store, P);
        ES_CHECK_MSG(run_mpi(P, args, err, sizeof err) == 0, "mpirun -n %d gpa: %s", P, err);
        char name[32];
        snprintf(name, sizeof name, "np%d", P);
        same_gpa(ctx, "serial", name);
        ES_CHECK_MSG(run_mpi(P, args, err, sizeof err) != 0 && strstr(err, "exists already"),
                     "mpirun -n %d gpa again: %s", P, err);
        char *first = strstr(err, "exists already");
        ES_CHECK_MSG(first && !strstr(first + 1, "exists already"), "the refusal is not said "
                     "once: %s", err);
    }
    /* a command that does not run on ranks yet */
    snprintf(args, sizeof args, "mean '%s' --no-store", store);
    ES_CHECK_MSG(run_mpi(2, args, err, sizeof err) != 0 && strstr(err, "does not run on the "
                 "ranks"), "mpirun mean: %s", err);
    /* results live beside the store: its file never changed */
    ES_CHECK(base && es_test_same_bytes(store, base, nbase));
    free(base);
    es_ctx_free(ctx);
    ES_TEST_END();
}
