/* tools/cli.c — shared glue of the edgespace subcommands (see cli.h). */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A progress stream ("interp: frames", "embedding"): when it started, when
 * it last wrote a log line, and the tenth it had reached then. */
typedef struct cli_stream {
    char what[64];
    double start, last_line;
    int64_t tenth;
} cli_stream;

typedef struct cli_state {
    const char *verb;
    int tty;
    double last_draw;
    cli_stream streams[4];
} cli_state;

static cli_state state;

static void on_log(void *ud, es_log_level level, const char *msg)
{
    cli_state *st = ud;
    fprintf(stderr, "edgespace %s: %s%s\n", st->verb,
            level == ES_LOG_WARNING ? "warning: " : "", msg);
}

/* The stream of this name, made (or the oldest reused) when done is 0. */
static cli_stream *stream_of(cli_state *st, const char *what, int64_t done, double t)
{
    cli_stream *s = NULL, *oldest = &st->streams[0];
    for (int i = 0; i < 4; i++) {
        if (!strncmp(st->streams[i].what, what, sizeof st->streams[i].what - 1)) s = &st->streams[i];
        if (st->streams[i].start < oldest->start) oldest = &st->streams[i];
    }
    if (!s || done == 0) {
        if (!s) s = oldest;
        snprintf(s->what, sizeof s->what, "%s", what);
        s->start = s->last_line = t;
        s->tenth = 0;
    }
    return s;
}

/* Without a terminal (a log, a pipe): one line per tenth of the work or per
 * 5 s, whichever comes first, and one at the end, for work that has run a
 * second or more; a short embedding stays quiet. */
static void log_progress(cli_state *st, const char *what, int64_t done, int64_t total, double t)
{
    cli_stream *s = stream_of(st, what, done, t);
    int64_t tenth = total > 0 ? 10 * done / total : 10;
    if (t - s->start < 1.0) {
        s->tenth = tenth;
        return;
    }
    if (done >= total || tenth > s->tenth || t - s->last_line >= 5.0) {
        fprintf(stderr, "edgespace %s: %s %lld of %lld (%.0f %%, %.1f s)\n", st->verb, what,
                (long long)done, (long long)total, total > 0 ? 100.0 * done / total : 100.0,
                t - s->start);
        fflush(stderr);
        s->last_line = t;
        s->tenth = tenth;
    }
}

/* A one-line bar ("interp: frames [###...] 3 of 21") redrawn at most ten
 * times a second on a terminal; log lines otherwise (log_progress). */
static void on_progress(void *ud, const char *what, int64_t done, int64_t total)
{
    cli_state *st = ud;
    double t = es_clock_seconds();
    if (!st->tty) {
        log_progress(st, what, done, total, t);
        return;
    }
    if (done < total && t - st->last_draw < 0.1) return;
    st->last_draw = t;
    int width = 30, filled = total > 0 ? (int)(width * done / total) : width;
    fprintf(stderr, "\r%-24.24s [", what);
    for (int i = 0; i < width; i++) fputc(i < filled ? '#' : '.', stderr);
    fprintf(stderr, "] %lld of %lld", (long long)done, (long long)total);
    if (done >= total) fputs("\r\033[K", stderr);
    fflush(stderr);
}

static void finalize_mpi(void) { es_parallel_finalize(); }

/* The commands that run on the ranks of an MPI job (datasets-spec/parallel.md). */
static int runs_parallel(const char *verb)
{
    return !strcmp(verb, "pca") || !strcmp(verb, "model") || !strcmp(verb, "gpa") || !strcmp(verb, "ingest");
}

/* Started by mpirun (a library built with -Dmpi=enabled): the context joins
 * the job, and only rank 0 speaks (the others' stdout and stderr go to
 * /dev/null: their messages are rank 0's, agreed on). A command that does
 * not run on ranks yet is refused rather than run P times over one store. */
static int join_job(es_ctx *ctx, const char *verb)
{
    static int registered;
    if (!es_parallel_available() || !es_parallel_launched()) return 0;
    if (es_parallel_init(ctx, NULL, NULL) != ES_OK || es_parallel_join(ctx) != ES_OK) {
        fprintf(stderr, "edgespace %s: cannot join the MPI job: %s\n", verb, es_ctx_errmsg(ctx));
        return -1;
    }
    if (!registered++) atexit(finalize_mpi);
    if (es_parallel_rank(ctx) != 0 &&
        (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)))
        return -1;
    if (es_parallel_nranks(ctx) > 1 && !runs_parallel(verb)) {
        fprintf(stderr, "edgespace %s: does not run on the ranks of an MPI job yet (pca, model, gpa and ingest do); "
                "run it as one process\n", verb);
        return -1;
    }
    return 0;
}

es_ctx *cli_ctx_new(const char *verb)
{
    es_ctx *ctx = NULL;
    if (es_ctx_new(&ctx) != ES_OK) {
        fprintf(stderr, "edgespace %s: out of memory\n", verb);
        return NULL;
    }
    if (join_job(ctx, verb) != 0) {
        es_ctx_free(ctx);
        return NULL;
    }
    state.verb = verb;
    state.tty = isatty(STDERR_FILENO) && es_parallel_rank(ctx) == 0;
    es_ctx_set_log(ctx, on_log, &state);
    es_ctx_set_progress(ctx, on_progress, &state);
    /* the memory a command may plan to use (embeddings refuse above it) */
    const char *limit = getenv("EDGESPACE_MAX_MEMORY");
    uint64_t bytes;
    if (limit && *limit) {
        if (cli_parse_size(limit, &bytes) == 0) es_ctx_set_memory_limit(ctx, bytes);
        else fprintf(stderr, "edgespace %s: warning: EDGESPACE_MAX_MEMORY='%s' is not a size "
                     "(like 8G); ignored\n", verb, limit);
    }
    return ctx;
}

FILE *cli_report_stream(const char *csv)
{
    return csv && !strcmp(csv, "-") ? stderr : stdout;
}

/* msg without a leading "VERB: " (the library names the analysis, which is
 * often the command: "edgespace mean: mean: ..." says it twice). */
static const char *without_verb(const char *verb, const char *msg)
{
    size_t n = strlen(verb);
    if (strncmp(msg, verb, n) == 0 && msg[n] == ':' && msg[n + 1] == ' ') return msg + n + 2;
    return msg;
}

int cli_fail(const char *verb, es_ctx *ctx, es_status rc)
{
    const char *msg = ctx ? es_ctx_errmsg(ctx) : "";
    fprintf(stderr, "edgespace %s: %s\n", verb,
            msg && *msg ? without_verb(verb, msg) : es_strerror(rc));
    return CLI_FAIL;
}

int cli_usage_error(const char *verb, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "edgespace %s: ", verb);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nTry 'edgespace %s --help'.\n", verb);
    return CLI_USAGE;
}

/* An argument as a POSIX shell reads it back: as it is when it holds only
 * characters no shell treats specially, else in single quotes with each '
 * written '\'' (a name like "a'; touch PWNED; echo '" was stored as a
 * command that ran touch when replayed). */
static size_t shell_quote(char *out, const char *arg)
{
    static const char safe[] = "@%+=:,./-_";
    size_t n = 0;
    int plain = *arg != '\0';
    for (const char *p = arg; *p && plain; p++)
        plain = ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
                 (*p >= '0' && *p <= '9') || strchr(safe, *p));
    if (plain) {
        if (out) memcpy(out, arg, strlen(arg));
        return strlen(arg);
    }
    if (out) out[n] = '\'';
    n++;
    for (const char *p = arg; *p; p++) {
        if (*p == '\'') {
            if (out) memcpy(out + n, "'\\''", 4);
            n += 4;
        } else {
            if (out) out[n] = *p;
            n++;
        }
    }
    if (out) out[n] = '\'';
    return n + 1;
}

char *cli_command_line(int argc, char **argv)
{
    size_t n = strlen("edgespace") + 1, k;
    for (int i = 0; i < argc; i++) n += shell_quote(NULL, argv[i]) + 1;
    char *s = malloc(n);
    if (!s) return NULL;
    strcpy(s, "edgespace");
    k = strlen(s);
    for (int i = 0; i < argc; i++) {
        s[k++] = ' ';
        k += shell_quote(s + k, argv[i]);
    }
    s[k] = '\0';
    return s;
}

int cli_parse_i64(const char *s, int64_t *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno || end == s || *end) return -1;
    *out = v;
    return 0;
}

int cli_parse_size(const char *s, uint64_t *out)
{
    char *end;
    double v, unit = 1;
    errno = 0;
    v = strtod(s, &end);
    if (errno || end == s || !isfinite(v) || v <= 0) return -1;
    switch (*end) {
    case 'k': case 'K': unit = 1024.0; end++; break;
    case 'm': case 'M': unit = 1024.0 * 1024; end++; break;
    case 'g': case 'G': unit = 1024.0 * 1024 * 1024; end++; break;
    case 't': case 'T': unit = 1024.0 * 1024 * 1024 * 1024; end++; break;
    default: break;
    }
    if ((*end == 'B' || *end == 'b') && end[1] == '\0') end++;
    if (*end || v * unit >= 1.8e19 || v * unit < 1) return -1;
    *out = (uint64_t)(v * unit);
    return 0;
}

int cli_parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

int cli_embed_option(const char *verb, int c, const char *arg, es_embed_opts *o)
{
    int64_t n;
    double w;
    switch (c) {
    case 0x101:
        if (cli_parse_double(arg, &w) || !(w >= 0))
            return cli_usage_error(verb, "--bending wants a weight >= 0");
        o->prior_mu = w;
        return 0;
    case 0x102:
        if (cli_parse_i64(arg, &n) || n < 0 || n > 100000)
            return cli_usage_error(verb, "--refine-iters wants a count >= 0");
        o->refine_max_iter = (int)n;
        return 0;
    case 0x103:
        if (cli_parse_i64(arg, &n) || n < 0 || n > 1000000)
            return cli_usage_error(verb, "--iters wants a count >= 0");
        o->lg_max_iter = o->lg_max_iter_large = (int)n;   /* at every size */
        return 0;
    case 0x104: {
        es_embed_opts f;
        es_embed_opts_fast(&f);
        o->lg_polish = f.lg_polish;
        o->lg_max_iter = f.lg_max_iter;
        o->lg_max_iter_large = f.lg_max_iter_large;
        o->lg_rms_tol = f.lg_rms_tol;
        o->lg_max_tol = f.lg_max_tol;
        return 0;
    }
    case 0x105:
        if (!strcmp(arg, "auto")) o->solver = ES_EMBED_SOLVER_AUTO;
        else if (!strcmp(arg, "lm")) o->solver = ES_EMBED_SOLVER_LM;
        else return cli_usage_error(verb, "--solver wants auto or lm (got '%s')", arg);
        return 0;
    case 0x106:
        if (cli_parse_double(arg, &w) || !(w >= 0))
            return cli_usage_error(verb, "--crease-guard wants a weight >= 0");
        o->crease_mu = w;
        return 0;
    default:
        return -1;
    }
}
