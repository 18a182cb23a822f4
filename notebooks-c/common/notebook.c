/* notebooks-c/common/notebook.c — output directory, report.md, run.json,
 * CSV files, step timers, data location and self-checks for the C
 * notebooks (notebook.h says how they are used). Plain C and POSIX; the
 * only library calls are es_ctx_* and es_version.
 */
#include "notebook.h"

#include <cjson/cJSON.h>
#include "nb_version.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef NB_SHARED_DIR
#define NB_SHARED_DIR ""
#endif

double nb_now(void) { return es_clock_seconds(); }

double nb_worst(const double *v, int64_t n)
{
    double m = 0;
    for (int64_t i = 0; i < n; i++) m = fmax(m, v[i]);
    return m;
}

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}


static void log_to_stderr(void *userdata, es_log_level level, const char *msg)
{
    const notebook *n = userdata;
    if (level != ES_LOG_WARNING) return;   /* notes are the library's chatter */
    fprintf(stderr, "%s: warning: %s\n", n->name, msg);
}

static void usage(FILE *f, const char *name)
{
    fprintf(f, "usage: %s [--out DIR] [--data DIR] [--synthetic] [--small | --all] [--seed N]\n\n"
               "  --out DIR     where report.md, figures, CSV and run.json go\n"
               "                (default: $EDGESPACE_NOTEBOOK_OUT/%s, else out/%s)\n"
               "  --data DIR    folder holding the data sets (default: $EDGESPACE_SHARED/data,\n"
               "                else ../shared/data beside the source tree)\n"
               "  --synthetic   ignore real data; use the project's synthetic data\n"
               "  --small       the small sizes the test suite runs\n"
               "  --all         also the inputs a default run leaves out for time\n"
               "  --seed N      seed of everything random (default 0x5eed)\n", name, name,
            name);
}

static void set_datadir(notebook *n, const char *root, const char *sub)
{
    char buf[4096];
    if (!root || !*root) return;
    snprintf(buf, sizeof buf, "%s%s", root, sub);
    if (is_dir(buf)) snprintf(n->datadir, sizeof n->datadir, "%s", buf);
}

int nb_open(notebook *n, const char *name, const char *title, int argc, char **argv)
{
    static const struct option opts[] = {
        {"out", required_argument, NULL, 'o'}, {"data", required_argument, NULL, 'd'},
        {"synthetic", no_argument, NULL, 'S'}, {"small", no_argument, NULL, 's'},
        {"seed", required_argument, NULL, 'r'}, {"help", no_argument, NULL, 'h'},
        {"all", no_argument, NULL, 'A'}, {NULL, 0, NULL, 0}};
    const char *out = NULL, *data = NULL, *env;
    int c;

    memset(n, 0, sizeof *n);
    n->name = name;
    setvbuf(stdout, NULL, _IOLBF, 0);   /* progress lines show up in logs as they happen */
    n->seed = 0x5eed;
    env = getenv("EDGESPACE_NOTEBOOK_SMALL");
    n->small = env && *env && strcmp(env, "0") != 0;
    while ((c = getopt_long(argc, argv, "o:d:h", opts, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'd': data = optarg; break;
        case 'S': n->synthetic = 1; break;
        case 's': n->small = 1; break;
        case 'A': n->all = 1; break;
        case 'r': {
            char *end;
            errno = 0;
            n->seed = strtoull(optarg, &end, 0);
            if (errno || *end || !*optarg) {
                fprintf(stderr, "%s: --seed: not a number: '%s'\n", name, optarg);
                return 2;
            }
            break;
        }
        case 'h': usage(stdout, name); exit(0);
        default: usage(stderr, name); return 2;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "%s: unexpected argument '%s'\n", name, argv[optind]);
        usage(stderr, name);
        return 2;
    }
    if (out) snprintf(n->outdir, sizeof n->outdir, "%s", out);
    else if ((env = getenv("EDGESPACE_NOTEBOOK_OUT")) && *env)
        snprintf(n->outdir, sizeof n->outdir, "%s/%s", env, name);
    else snprintf(n->outdir, sizeof n->outdir, "out/%s", name);

    if (data) {
        if (!is_dir(data)) {
            fprintf(stderr, "%s: --data: not a directory: '%s'\n", name, data);
            return 2;
        }
        snprintf(n->datadir, sizeof n->datadir, "%s", data);
    } else if ((env = getenv("EDGESPACE_SHARED")) && *env) {
        set_datadir(n, env, "/data");
    } else {
        set_datadir(n, NB_SHARED_DIR, "/data");
    }

    if (es_ctx_new(&n->ctx) != ES_OK) {
        fprintf(stderr, "%s: out of memory\n", name);
        return 1;
    }
    if (es_make_dirs(n->ctx, n->outdir) != ES_OK) {
        fprintf(stderr, "%s: cannot create output directory: %s\n", name, es_ctx_errmsg(n->ctx));
        return 1;
    }
    n->report = fopen(nb_path(n, "report.md"), "w");
    if (!n->report) {
        fprintf(stderr, "%s: cannot write '%s': %s\n", name, nb_path(n, "report.md"),
                strerror(errno));
        return 1;
    }
    es_ctx_set_seed(n->ctx, n->seed);
    es_ctx_set_log(n->ctx, log_to_stderr, n);
    n->t_start = nb_now();
    n->t_step = n->t_start;
    fprintf(n->report, "# %s\n\n", title);
    fprintf(n->report, "*Notebook `notebooks-c/%s.c`, libedgespace %s (%s), seed %#llx%s.*\n\n",
            name, es_version(), NB_GIT_DESCRIBE, (unsigned long long)n->seed,
            n->small ? ", small run" : n->all ? ", every input (--all)" : "");
    printf("%s: writing %s/\n", name, n->outdir);
    return 0;
}

const char *nb_path(notebook *n, const char *fmt, ...)
{
    static char bufs[8][4096 + 256];
    static int next;
    char file[256];
    char *buf = bufs[next++ & 7];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(file, sizeof file, fmt, ap);
    va_end(ap);
    snprintf(buf, sizeof bufs[0], "%s/%s", n->outdir, file);
    return buf;
}

const char *nb_dataset(notebook *n, const char *set)
{
    static char buf[4096 + 256];
    if (n->synthetic || !n->datadir[0]) return NULL;
    snprintf(buf, sizeof buf, "%s/%s", n->datadir, set);
    if (!is_dir(buf)) return NULL;
    nb_input(n, "dataset", "%s", buf);
    return buf;
}

int nb_read_mesh(notebook *n, const char *dir, const char *file, es_mesh **mesh, double **xyz)
{
    char path[8192];
    es_meshdata md;
    es_status rc;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    *xyz = NULL;
    if ((rc = es_meshdata_read(n->ctx, path, ES_FORMAT_AUTO, &md)) != ES_OK)
        return nb_fail(n, rc, path);
    if (!*mesh) {
        rc = es_mesh_new(n->ctx, md.nverts, md.nfaces, md.faces, md.xyz, mesh);
    } else if (md.nverts != es_mesh_nverts(*mesh) || md.nfaces != es_mesh_nfaces(*mesh) ||
               memcmp(md.faces, es_mesh_faces(*mesh), 3 * sizeof(int64_t) * (size_t)md.nfaces)) {
        es_meshdata_clear(n->ctx, &md);
        fprintf(stderr, "%s: %s: another face list than the study's first mesh\n", n->name,
                path);
        return nb_fail(n, ES_EMISMATCH, path);
    }
    if (rc == ES_OK && !(*xyz = malloc(3 * sizeof(double) * (size_t)md.nverts))) rc = ES_ENOMEM;
    if (rc == ES_OK) memcpy(*xyz, md.xyz, 3 * sizeof(double) * (size_t)md.nverts);
    es_meshdata_clear(n->ctx, &md);
    return rc == ES_OK ? 0 : nb_fail(n, rc, path);
}

void nb_input(notebook *n, const char *key, const char *fmt, ...)
{
    va_list ap;
    if (n->ninputs >= NB_MAX_ITEMS) return;
    snprintf(n->inputs[n->ninputs][0], sizeof n->inputs[0][0], "%s", key);
    va_start(ap, fmt);
    vsnprintf(n->inputs[n->ninputs][1], sizeof n->inputs[0][1], fmt, ap);
    va_end(ap);
    n->ninputs++;
}

void nb_output(notebook *n, const char *file)
{
    if (n->noutputs >= NB_MAX_ITEMS) return;
    snprintf(n->outputs[n->noutputs++], sizeof n->outputs[0], "%s", file);
}

static void end_step(notebook *n)
{
    double t = nb_now();
    if (n->nsteps > 0) n->step_seconds[n->nsteps - 1] = t - n->t_step;
    n->t_step = t;
}

void nb_step(notebook *n, const char *fmt, ...)
{
    va_list ap;
    end_step(n);
    if (n->nsteps >= NB_MAX_STEPS) return;
    va_start(ap, fmt);
    vsnprintf(n->steps[n->nsteps], sizeof n->steps[0], fmt, ap);
    va_end(ap);
    n->step_seconds[n->nsteps] = 0;
    printf("%s: step %d: %s\n", n->name, n->nsteps + 1, n->steps[n->nsteps]);
    fflush(stdout);
    n->nsteps++;
}

static void end_table(notebook *n)
{
    if (n->in_table) fputc('\n', n->report);
    n->in_table = 0;
}

int nb_fail(notebook *n, es_status rc, const char *what)
{
    const char *msg = es_ctx_errmsg(n->ctx);
    fprintf(stderr, "%s: %s: %s%s%s\n", n->name, what, es_strerror(rc), *msg ? ": " : "", msg);
    if (n->report) {
        end_table(n);
        fprintf(n->report, "> **Failed:** %s: %s%s%s\n\n", what, es_strerror(rc),
                *msg ? ": " : "", msg);
    }
    n->failed = 1;
    return 1;
}

void nb_h(notebook *n, int level, const char *fmt, ...)
{
    va_list ap;
    end_table(n);
    for (int i = 0; i < level; i++) fputc('#', n->report);
    fputc(' ', n->report);
    va_start(ap, fmt);
    vfprintf(n->report, fmt, ap);
    va_end(ap);
    fputs("\n\n", n->report);
}

void nb_p(notebook *n, const char *fmt, ...)
{
    va_list ap;
    end_table(n);
    va_start(ap, fmt);
    vfprintf(n->report, fmt, ap);
    va_end(ap);
    fputs("\n\n", n->report);
}

void nb_image(notebook *n, const char *file, const char *fmt, ...)
{
    char caption[1024];
    va_list ap;
    end_table(n);
    va_start(ap, fmt);
    vsnprintf(caption, sizeof caption, fmt, ap);
    va_end(ap);
    fprintf(n->report, "![%s](%s)\n\n*%s*\n\n", caption, file, caption);
    nb_output(n, file);
}

static void put_cells(FILE *f, const char *cells)
{
    fputs("| ", f);
    for (const char *c = cells; *c; c++) {
        if (*c == '|') fputs(" | ", f);
        else fputc(*c, f);
    }
    fputs(" |\n", f);
}

void nb_table(notebook *n, const char *header)
{
    int ncols = 1;
    end_table(n);
    for (const char *c = header; *c; c++) ncols += *c == '|';
    put_cells(n->report, header);
    fputc('|', n->report);
    for (int i = 0; i < ncols; i++) fputs("---|", n->report);
    fputc('\n', n->report);
    n->in_table = 1;
}

void nb_row(notebook *n, const char *fmt, ...)
{
    char cells[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cells, sizeof cells, fmt, ap);
    va_end(ap);
    put_cells(n->report, cells);
}

FILE *nb_csv_open(notebook *n, const char *file, const char *header)
{
    const char *path = nb_path(n, "%s", file);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "%s: cannot write '%s': %s\n", n->name, path, strerror(errno));
        n->failed = 1;
        return NULL;
    }
    fprintf(f, "%s\n", header);
    nb_output(n, file);
    return f;
}

int nb_csv_close(notebook *n, FILE *f)
{
    int bad;
    if (!f) return 1;
    bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad) {
        fprintf(stderr, "%s: error writing a CSV file\n", n->name);
        n->failed = 1;
    }
    return bad;
}

int nb_check(notebook *n, const char *name, double metric, const char *op, double bound)
{
    int pass;
    if (!strcmp(op, "<")) pass = metric < bound;
    else if (!strcmp(op, "<=")) pass = metric <= bound;
    else if (!strcmp(op, ">")) pass = metric > bound;
    else pass = metric >= bound;
    if (isnan(metric)) pass = 0;
    printf("%s: check %s: %.6g %s %.6g: %s\n", n->name, name, metric, op, bound,
           pass ? "ok" : "FAILED");
    if (n->nchecks < NB_MAX_CHECKS) {
        nb_checkrec *c = &n->checks[n->nchecks++];
        snprintf(c->name, sizeof c->name, "%s", name);
        snprintf(c->op, sizeof c->op, "%s", op);
        c->metric = metric;
        c->bound = bound;
        c->pass = pass;
    }
    return pass;
}

/* A number, or null where JSON has none (NaN, infinities). */
static cJSON *json_number(double v)
{
    return isfinite(v) ? cJSON_CreateNumber(v) : cJSON_CreateNull();
}

static cJSON *run_json(const notebook *n, double total)
{
    cJSON *root = cJSON_CreateObject(), *inputs, *steps, *checks, *outputs;
    if (!root) return NULL;
    cJSON_AddStringToObject(root, "notebook", n->name);
    cJSON_AddStringToObject(root, "version", es_version());
    cJSON_AddStringToObject(root, "git_describe", NB_GIT_DESCRIBE);
    cJSON_AddNumberToObject(root, "seed", (double)n->seed);
    cJSON_AddBoolToObject(root, "small", n->small);
    cJSON_AddBoolToObject(root, "all", n->all);
    cJSON_AddBoolToObject(root, "synthetic_requested", n->synthetic);
    cJSON_AddStringToObject(root, "data_dir", n->datadir);
    inputs = cJSON_AddObjectToObject(root, "inputs");
    for (int i = 0; inputs && i < n->ninputs; i++)
        cJSON_AddStringToObject(inputs, n->inputs[i][0], n->inputs[i][1]);
    steps = cJSON_AddArrayToObject(root, "steps");
    for (int i = 0; steps && i < n->nsteps; i++) {
        cJSON *st = cJSON_CreateObject();
        cJSON_AddStringToObject(st, "name", n->steps[i]);
        cJSON_AddItemToObject(st, "seconds", json_number(n->step_seconds[i]));
        cJSON_AddItemToArray(steps, st);
    }
    cJSON_AddItemToObject(root, "total_seconds", json_number(total));
    checks = cJSON_AddArrayToObject(root, "checks");
    for (int i = 0; checks && i < n->nchecks; i++) {
        const nb_checkrec *c = &n->checks[i];
        cJSON *ck = cJSON_CreateObject();
        cJSON_AddStringToObject(ck, "name", c->name);
        cJSON_AddItemToObject(ck, "metric", json_number(c->metric));
        cJSON_AddStringToObject(ck, "op", c->op);
        cJSON_AddItemToObject(ck, "bound", json_number(c->bound));
        cJSON_AddBoolToObject(ck, "pass", c->pass);
        cJSON_AddItemToArray(checks, ck);
    }
    outputs = cJSON_AddArrayToObject(root, "outputs");
    for (int i = 0; outputs && i < n->noutputs; i++)
        cJSON_AddItemToArray(outputs, cJSON_CreateString(n->outputs[i]));
    cJSON_AddBoolToObject(root, "failed", n->failed);
    return root;
}

/* run.json (cJSON): inputs, seed, timings and checks of this run. */
static int write_run_json(notebook *n, double total)
{
    cJSON *root = run_json(n, total);
    char *text = root ? cJSON_Print(root) : NULL;
    FILE *f = text ? fopen(nb_path(n, "run.json"), "w") : NULL;
    int bad = !f;
    if (f) {
        fputs(text, f);
        fputc('\n', f);
        bad = ferror(f);
        bad |= fclose(f) != 0;
    }
    cJSON_free(text);
    cJSON_Delete(root);
    return bad;
}

int nb_close(notebook *n)
{
    int npass = 0;
    double total;
    end_step(n);
    total = nb_now() - n->t_start;
    for (int i = 0; i < n->nchecks; i++) npass += n->checks[i].pass;

    nb_h(n, 2, "Self-check");
    if (n->nchecks) {
        nb_table(n, "check|value|bound|result");
        for (int i = 0; i < n->nchecks; i++) {
            const nb_checkrec *c = &n->checks[i];
            nb_row(n, "%s|%.4g|%s %.4g|%s", c->name, c->metric, c->op, c->bound,
                   c->pass ? "pass" : "**FAIL**");
        }
    }
    nb_p(n, "%d of %d checks passed%s.", npass, n->nchecks,
         n->failed ? "; a step failed (see above)" : "");
    nb_h(n, 2, "Run");
    nb_table(n, "step|seconds");
    for (int i = 0; i < n->nsteps; i++) nb_row(n, "%s|%.2f", n->steps[i], n->step_seconds[i]);
    nb_row(n, "**total**|%.2f", total);
    nb_p(n, "Inputs, seed, timings and checks are in `run.json`.");
    if (write_run_json(n, total) != 0) {
        fprintf(stderr, "%s: cannot write run.json\n", n->name);
        n->failed = 1;
    }
    if (fclose(n->report) != 0) n->failed = 1;
    n->report = NULL;
    es_ctx_free(n->ctx);
    n->ctx = NULL;
    printf("%s: %d/%d checks passed, %.1f s; report: %s/report.md\n", n->name, npass,
           n->nchecks, total, n->outdir);
    return (n->failed || npass != n->nchecks) ? 1 : 0;
}
