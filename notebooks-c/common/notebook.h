/* notebooks-c/common/notebook.h — the frame every C notebook runs in.
 *
 * A notebook (notebooks-c/NN_<question>.c) is a study written as a C
 * program: it opens a notebook (nb_open), runs its steps in reading order
 * (nb_step names each one and times it), writes its report as it goes
 * (nb_h, nb_p, nb_image, nb_table/nb_row), the CSV behind every figure
 * (nb_csv_open/nb_csv_close), records self-checks (nb_check) and ends with
 * nb_close, which writes the self-check table, run.json and returns the
 * exit status of main (non-zero when a check missed its bound or a step
 * failed). This file is glue for reports, never computation: the studies
 * call libedgespace's public API only.
 *
 * Output directory: --out DIR, else $EDGESPACE_NOTEBOOK_OUT/<name>, else
 * out/<name> (relative to the working directory).
 * Data: --data DIR (a folder holding the data sets, e.g. ../shared/data),
 * else $EDGESPACE_SHARED/data, else the NB_SHARED_DIR given at build time
 * (../shared beside the source tree) + /data; --synthetic ignores it all
 * and makes the project's own synthetic data. --small picks the small
 * sizes the test suite runs (also $EDGESPACE_NOTEBOOK_SMALL=1); --all adds
 * the inputs a default run leaves out because they take minutes.
 */
#ifndef EDGESPACE_NOTEBOOK_H
#define EDGESPACE_NOTEBOOK_H

#include <edgespace/edgespace.h>

#include <stdint.h>
#include <stdio.h>

#if defined(__GNUC__)
#define NB_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define NB_PRINTF(a, b)
#endif

#define NB_MAX_STEPS 64
#define NB_MAX_ITEMS 64
#define NB_MAX_CHECKS 32

typedef struct nb_checkrec {
    char name[160];
    double metric, bound;
    char op[3];          /* "<", "<=", ">", ">=" */
    int pass;
} nb_checkrec;

typedef struct notebook {
    const char *name;           /* "01_faces" */
    char outdir[4096];
    char datadir[4096];         /* folder of the data sets, "" if none */
    int synthetic;              /* --synthetic given */
    int small;                  /* --small given */
    int all;                    /* --all given: inputs a default run leaves out for time */
    uint64_t seed;
    es_ctx *ctx;
    FILE *report;               /* report.md */
    double t_start;
    char steps[NB_MAX_STEPS][96];
    double step_seconds[NB_MAX_STEPS];
    int nsteps;
    double t_step;              /* start of the current step */
    char inputs[NB_MAX_ITEMS][2][512];
    int ninputs;
    char outputs[NB_MAX_ITEMS][256];
    int noutputs;
    nb_checkrec checks[NB_MAX_CHECKS];
    int nchecks;
    int failed;                 /* a step failed (nb_fail) */
    int in_table;
} notebook;

/* Parse argv, create the output directory, open report.md (with `title`
 * as its heading), make the es_ctx (seeded). Returns 0, or 2 after a usage
 * message (the caller returns it from main), or 1 on an I/O failure. */
int nb_open(notebook *nb, const char *name, const char *title, int argc, char **argv);

/* Write the self-check section, run.json, close everything. Returns 0 when
 * every check passed and no step failed, else 1. */
int nb_close(notebook *nb);

/* Path of a data set folder (<datadir>/<set>) when it exists and
 * --synthetic was not given, else NULL. Records it as an input. */
const char *nb_dataset(notebook *nb, const char *set);

/* Record an input (data set, parameter) for run.json and the report. */
void nb_input(notebook *nb, const char *key, const char *fmt, ...) NB_PRINTF(3, 4);

/* <outdir>/<file>: one of 8 rotating static buffers. */
const char *nb_path(notebook *nb, const char *fmt, ...) NB_PRINTF(2, 3);

/* Start the next step (ends and times the previous one); prints it. */
void nb_step(notebook *nb, const char *fmt, ...) NB_PRINTF(2, 3);

/* A library call failed: print "<name>: <what>: <errmsg>", note it in
 * the report, mark the notebook failed. Returns 1 (for `return nb_fail()`). */
int nb_fail(notebook *nb, es_status rc, const char *what);

/* Report text. nb_h: heading of `level` (2 or 3); nb_p: a paragraph
 * (printf format, numbers formatted at run time); nb_image: an image by
 * its path relative to the report, with a caption. */
void nb_h(notebook *nb, int level, const char *fmt, ...) NB_PRINTF(3, 4);
void nb_p(notebook *nb, const char *fmt, ...) NB_PRINTF(2, 3);
void nb_image(notebook *nb, const char *file, const char *fmt, ...) NB_PRINTF(3, 4);
/* A table: header cells separated by '|' ("step|seconds"), then rows of
 * cells separated by '|' (printf format). The table ends at the next
 * nb_h, nb_p or nb_image. */
void nb_table(notebook *nb, const char *header);
void nb_row(notebook *nb, const char *fmt, ...) NB_PRINTF(2, 3);

/* CSV behind a figure: opens <outdir>/<file>, writes the header line,
 * records it as an output. NULL (and nb_fail) if it cannot be opened. */
FILE *nb_csv_open(notebook *nb, const char *file, const char *header);
/* Close; returns 0, or 1 (and marks the notebook failed) on a write error. */
int nb_csv_close(notebook *nb, FILE *f);
/* Record an output file (figures) for run.json. */
void nb_output(notebook *nb, const char *file);

/* Self-check: record metric `op` bound ("<", "<=", ">", ">=") and print
 * it; a miss makes nb_close return 1. NaN metrics fail. Returns pass. */
int nb_check(notebook *nb, const char *name, double metric, const char *op, double bound);

/* Read the mesh file <dir>/<file> (an input of the study): its positions
 * into a malloc'd 3 x V array *xyz and, when *mesh is NULL, its topology
 * (with these positions as reference) into *mesh; a later file must have
 * the same face list. Returns 0, or 1 after nb_fail. */
int nb_read_mesh(notebook *nb, const char *dir, const char *file, es_mesh **mesh, double **xyz);

/* Seconds on a monotonic clock. */
double nb_now(void);

#endif
