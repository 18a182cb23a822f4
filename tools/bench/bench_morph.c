/* tools/bench/bench_morph.c — the interpolation methods side by side on
 * the real pairs of ../shared/data (the core paper's Fig. 12 and Table 1 for
 * every method): each dataset's meshes are ingested into a scratch store,
 * then `interp --method M` (es_study_interp) walks the pair in `steps`
 * frames with each method. Per method and pair: wall and process CPU time
 * of the whole walk (setup included: the multi-scale hierarchy, the
 * data-driven path, the embedder), the mean time per inner frame, and the
 * edge-length errors against each frame's own target (RMS ratio and max
 * relative, es_embed_report) at the midpoint and the worst inner frame.
 * The data-driven rows also print how far the path stays from the rows
 * against the straight line (the frame heading). Frames are written to a
 * scratch folder; nothing is stored.
 *
 *   bench_morph [steps]     (default 9; data from ../shared/data)
 */
#include <edgespace/edgespace.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_clock.h"


#ifndef ES_SHARED_DIR
#define ES_SHARED_DIR "../shared"
#endif

typedef struct acc {
    int64_t n;
    double t_inner, mid_rms, mid_max, worst_rms, worst_max;
    char heading[256];
} acc;

static void on_frame(void *ud, int64_t i, int64_t n, const char *path, const char *heading,
                     const es_embed_report *rep)
{
    acc *a = ud;
    (void)path;
    if (i == 0 || i == n - 1) return;   /* the ends are the rows themselves */
    a->n++;
    a->t_inner += rep->t_total;
    if (i == (n - 1) / 2) {
        a->mid_rms = rep->rms_ratio, a->mid_max = rep->max_rel;
        snprintf(a->heading, sizeof a->heading, "%s", heading);
    }
    if (rep->rms_ratio > a->worst_rms) a->worst_rms = rep->rms_ratio;
    if (rep->max_rel > a->worst_max) a->worst_max = rep->max_rel;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The dataset's meshes ingested into dir/<name>.h5; 0 on success. */
static int ingest(es_ctx *ctx, const char *data, const char *store)
{
    DIR *d = opendir(data);
    struct dirent *e;
    char **files = NULL;
    int64_t n = 0, cap = 0;
    es_ingest_opts o;
    int bad;
    if (!d) return -1;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l < 5 || strcmp(e->d_name + l - 4, ".obj") != 0) continue;
        if (n == cap) files = realloc(files, (size_t)(cap = cap ? 2 * cap : 64) * sizeof *files);
        files[n] = malloc(strlen(data) + l + 2);
        sprintf(files[n++], "%s/%s", data, e->d_name);
    }
    closedir(d);
    qsort(files, (size_t)n, sizeof *files, by_name);
    es_ingest_opts_init(&o);
    bad = es_ingest_files(ctx, store, n, (const char *const *)files, &o, NULL) != ES_OK;
    for (int64_t i = 0; i < n; i++) free(files[i]);
    free(files);
    return bad ? -1 : 0;
}

static void run(es_ctx *ctx, const char *tmp, const char *set, const char *a, const char *b,
                int64_t steps)
{
    /* the published pipeline (ES_MORPH_PAPER) takes minutes per frame at these sizes:
     * notebooks-c/10_table1 --all measures it on single midpoints */
    static const es_morph_method methods[] = {ES_MORPH_EDGE_LENGTH, ES_MORPH_MULTISCALE,
                                              ES_MORPH_SHAPE_SPACE, ES_MORPH_DATA_DRIVEN,
                                              ES_MORPH_DATA_DRIVEN_EL};
    char data[4096], store[4096], pat[4096], from[256], to[256];
    es_store *s = NULL;
    snprintf(data, sizeof data, "%s/data/%s", ES_SHARED_DIR, set);
    snprintf(store, sizeof store, "%s/%s.h5", tmp, set);
    snprintf(pat, sizeof pat, "%s/frame_%%02d.obj", tmp);
    snprintf(from, sizeof from, "row:%s", a);
    snprintf(to, sizeof to, "row:%s", b);
    if (access(data, R_OK) != 0) {
        printf("%-22s (not found)\n", set);
        return;
    }
    if (ingest(ctx, data, store) || es_store_open(ctx, store, ES_STORE_READ, &s) != ES_OK) {
        printf("%-22s %s\n", set, es_ctx_errmsg(ctx));
        return;
    }
    for (size_t m = 0; m < sizeof methods / sizeof methods[0]; m++) {
        es_study_interp_opts o;
        acc ac = {0};
        double w0 = bench_wall_s(), c0 = bench_process_cpu_s();
        es_study_interp_opts_init(&o);
        o.from = from, o.to = to, o.steps = steps, o.output = pat, o.method = methods[m];
        o.frame = on_frame, o.userdata = &ac;
        es_status rc = es_study_interp(ctx, s, &o);
        double wall = bench_wall_s() - w0, cpu = bench_process_cpu_s() - c0;
        printf("%-22s %-12s %4lld %-12s", set, b, (long long)es_store_nverts(s),
               es_morph_method_name(methods[m]));
        if (rc != ES_OK) {
            printf("  failed: %s\n", es_ctx_errmsg(ctx));
            continue;
        }
        printf("  %7.2f %7.2f %8.3f   %8.4f%% %8.3f%%   %8.4f%% %8.3f%%\n", wall, cpu,
               ac.n ? ac.t_inner / (double)ac.n : 0, 100 * ac.mid_rms, 100 * ac.mid_max,
               100 * ac.worst_rms, 100 * ac.worst_max);
        if (methods[m] == ES_MORPH_DATA_DRIVEN || methods[m] == ES_MORPH_DATA_DRIVEN_EL)
            printf("    %s\n", ac.heading);
    }
    es_store_close(s);
    remove(store);
}

int main(int argc, char **argv)
{
    es_ctx *ctx;
    int64_t steps = argc > 1 ? atoll(argv[1]) : 9;
    char tmp[] = "/tmp/bench_morph.XXXXXX";
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (steps < 3 || !mkdtemp(tmp) || es_ctx_new(&ctx) != ES_OK) {
        fprintf(stderr, "usage: bench_morph [steps >= 3]\n");
        return 2;
    }
    printf("# %lld frames per walk; time: wall, CPU of the walk (s), mean per inner frame (s);\n"
           "# edge-length error against the frame's target: midpoint RMS ratio, max; worst inner"
           " frame RMS, max\n", (long long)steps);
    printf("%-22s %-12s %4s %-12s  %7s %7s %8s   %9s %9s   %9s %9s\n", "dataset", "to", "V",
           "method", "wall", "cpu", "frame", "mid RMS", "mid max", "worst RMS", "worst max");
    run(ctx, tmp, "facecap_arkit", "anim_000", "anim_100", steps);
    run(ctx, tmp, "sfm_surrey_face_3448", "mean_neutral", "expr_happiness", steps);
    run(ctx, tmp, "goast_cactus", "cactus0", "cactus1", steps);
    run(ctx, tmp, "sumner_cat_poses", "cat-01", "cat-02", steps);
    run(ctx, tmp, "face-study", "s001_neutral", "s001_happy", steps);
    for (int64_t i = 0; i < steps; i++) {
        char p[4200];
        snprintf(p, sizeof p, "%s/frame_%02lld.obj", tmp, (long long)i);
        remove(p);
    }
    rmdir(tmp);
    es_ctx_free(ctx);
    return 0;
}
