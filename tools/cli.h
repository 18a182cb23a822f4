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

/* Subcommand entry points: argv[0] is the verb. */
typedef int (*cli_cmd_fn)(int argc, char **argv);

#endif
