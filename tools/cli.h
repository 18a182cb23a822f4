/* tools/cli.h — glue shared by the edgespace subcommands: context set-up with
 * warnings and progress on stderr, error reporting, option helpers. */
#ifndef EDGESPACE_TOOLS_CLI_H
#define EDGESPACE_TOOLS_CLI_H

#include <edgespace/edgespace.h>
#include <stdio.h>

/* Exit statuses of every subcommand. */
enum { CLI_OK = 0, CLI_FAIL = 1, CLI_USAGE = 2 };

/* A context whose warnings print as "edgespace VERB: warning: ..." and whose
 * progress shows as a bar on stderr when stderr is a terminal, with the
 * memory limit of $EDGESPACE_MAX_MEMORY when set. NULL if out of memory
 * (after printing why). */
es_ctx *cli_ctx_new(const char *verb);

/* Where a command's report goes: stdout, or stderr when the CSV table is
 * written to stdout ("-o -"), so that stdout is the CSV alone. */
FILE *cli_report_stream(const char *csv);

/* Print "edgespace VERB: <errmsg>" (or the status text) and return CLI_FAIL. */
int cli_fail(const char *verb, es_ctx *ctx, es_status rc);

/* Print "edgespace VERB: <message>" plus a hint to run --help; CLI_USAGE. */
int cli_usage_error(const char *verb, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* "edgespace VERB ARG..." with arguments quoted where they hold blanks or
 * quotes, for the provenance of stored results. malloc'd (free it); NULL if
 * out of memory. argv[0] is the verb, as subcommands receive it. */
char *cli_command_line(int argc, char **argv);

/* Parse a whole string as int64 / double; 0 on success, -1 otherwise. */
int cli_parse_i64(const char *s, int64_t *out);
int cli_parse_double(const char *s, double *out);
/* A size in bytes: a number with an optional K, M, G or T (powers of 1024)
 * and B ("8G", "512MB", "1.5e9"); 0 or -1. */
int cli_parse_size(const char *s, uint64_t *out);

/* The embedding options embed, interp and variation share, as getopt codes
 * (CLI_EMBED_LONGOPTS in their option tables):
 *   --bending W  --refine-iters N  --iters N  --fast  --solver NAME
 * cli_embed_option applies code c with argument arg to o: 0 if it was one
 * of them, CLI_USAGE after printing why the value is wrong, -1 if c is not
 * an embedding option. CLI_EMBED_HELP is their help text. */
#define CLI_EMBED_LONGOPTS \
    {"bending", required_argument, NULL, 0x101}, {"refine-iters", required_argument, NULL, 0x102}, \
    {"iters", required_argument, NULL, 0x103}, {"fast", no_argument, NULL, 0x104}, \
    {"solver", required_argument, NULL, 0x105}, {"crease-guard", required_argument, NULL, 0x106}
#define CLI_EMBED_HELP \
    "      --iters N        local-global iterations at most (default 40, 70 from\n" \
    "                       50,000 vertices; the solver: lib/embed/local_global.c)\n" \
    "      --refine-iters N Levenberg-Marquardt iterations that finish where the\n" \
    "                       local-global ones did not reach RMS 0.05 % / max 1 %\n" \
    "                       (default 12; 0: none; none from 50,000 vertices, where\n" \
    "                       local-global iterations do as well in less time)\n" \
    "      --fast           a slider's accuracy: local-global alone, RMS 0.1 % / max\n" \
    "                       2 %, at most 30 iterations\n" \
    "      --solver NAME    auto (the above) or lm (Levenberg-Marquardt from the prior,\n" \
    "                       the solver before: a 3V x 3V factorization per iteration)\n" \
    "      --bending W      weight of the prior's bending term in the Levenberg-\n" \
    "                       Marquardt iterations (default 0.0025)\n" \
    "      --crease-guard W closed meshes: weight of the term that keeps each edge's\n" \
    "                       bending within the blended rows' (default 0.001; more:\n" \
    "                       fewer folds, more length error; 0: off)\n"
int cli_embed_option(const char *verb, int c, const char *arg, es_embed_opts *o);

/* getopt_long for a subcommand (argv[0] is the verb), with the old option
 * spellings of README "Options" rewritten in argv to their new ones and
 * each one used said once on stderr ("edgespace gpa: --pcs N is now
 * --components N; the old spelling will go"). tools/cli_options.c holds the
 * table. Returns what getopt_long does; '?' after printing why. */
struct option;
/* "edgespace VERB: OLD is now NEW; the old spelling will go" on stderr, for
 * an old form no option table can rewrite (plot STORE --pca). */
void cli_deprecated(const char *verb, const char *old, const char *new_);
int cli_getopt(int argc, char **argv, const char *shortopts, const struct option *longopts);

/* Subcommand entry points: argv[0] is the verb. */
typedef int (*cli_cmd_fn)(int argc, char **argv);

#endif
