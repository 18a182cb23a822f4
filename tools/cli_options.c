/* tools/cli_options.c — the one option vocabulary of the edgespace command
 * (README "Options") and the old spellings it replaced. Every subcommand
 * parses with cli_getopt, which rewrites an old spelling to its new one
 * before getopt_long sees it and says so once on stderr, so a script written
 * for an older release keeps working while it is being updated, and no
 * command keeps a second copy of the table. */
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>

/* One old spelling: in the commands of `verbs` (blank-separated), `old`
 * ("-p" or "--pcs") is now `new_` (a long option), whose value is `metavar`
 * (NULL for a flag). */
typedef struct {
    const char *verbs, *old, *new_, *metavar;
} cli_alias;

static const cli_alias aliases[] = {
    /* -o is the file or folder a command writes; --csv said it for some. */
    {"diff export mean model pca point project", "--csv", "--output", "PATH"},
    /* --components N is a count of principal components everywhere. */
    {"gpa explore", "--pcs", "--components", "N"},
    /* --where FILTER selects rows everywhere. */
    {"export", "--select", "--where", "FILTER"},
    {"export", "-s", "--where", "FILTER"},
    /* variation's distance along a component is in sd, as export's --sd. */
    {"variation", "--k", "--sd", "K"},
    {"variation", "-k", "--sd", "K"},
    {"synth", "--n", "--count", "N"},
    {"synth", "-n", "--count", "N"},
    /* -p is --pca; what else it meant is long only. */
    {"compare model", "-p", "--permutations", "N"},
    {"diff", "-p", "--pair-by", "KEY"},
    {"embed", "-p", "--point", "SPEC"},
    {"variation", "-P", "--pca", "NAME"},
    /* -k is --components; -f is --format; -w is --where; -b is --by; -s is
     * --scale; -m is --method; -c, -t and -r are dropped (each meant several
     * things). */
    {"interp", "-k", "--steps", "N"},
    {"results", "-k", "--kind", "KIND"},
    {"diff interp", "-f", "--from", "VALUE"},
    {"model", "-f", "--figure", "PATH"},
    {"diff interp", "-t", "--to", "VALUE"},
    {"export", "-t", "--table", "TABLE"},
    {"model", "-t", "--type", "TYPE"},
    {"ingest-landmarks", "-t", "--tps", "FILE"},
    {"diff", "-c", "--column", "COLUMN"},
    {"plot-pca variation", "-c", "--pcs", "LIST"},
    {"ingest-landmarks", "-c", "--csv", "FILE"},
    {"interp", "-w", "--weights", "EXPR"},
    {"model", "-b", "--block", "COLUMN"},
    {"ingest-landmarks", "-s", "--specimens", "FILE"},
    {"plot-pca", "-s", "--scree", NULL},
    {"synth", "-s", "--seed", "S"},
    {"ingest", "-m", "--manifest", "CSV"},
    {"info", "-r", "--rows", NULL},
    {"synth", "-r", "--resolution", "R"},
    {"plot-pca", "-l", "--color", "COLUMN"},
};
enum { N_ALIASES = sizeof aliases / sizeof aliases[0] };

/* Whether blank-separated `list` holds `word`. */
static int has_word(const char *list, const char *word)
{
    size_t n = strlen(word);
    for (const char *p = list; (p = strstr(p, word)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
    return 0;
}

static const cli_alias *find_alias(const char *verb, const char *old, size_t len)
{
    for (int i = 0; i < N_ALIASES; i++)
        if (strlen(aliases[i].old) == len && !strncmp(aliases[i].old, old, len) &&
            has_word(aliases[i].verbs, verb))
            return &aliases[i];
    return NULL;
}

void cli_deprecated(const char *verb, const char *old, const char *new_)
{
    fprintf(stderr, "edgespace %s: %s is now %s; the old spelling will go\n", verb, old, new_);
}

/* The deprecation line, once per old spelling and run. */
static void warn_alias(const char *verb, const cli_alias *a)
{
    static unsigned char said[N_ALIASES];
    if (said[a - aliases]) return;
    said[a - aliases] = 1;
    char old[64], new_[64];
    const char *m = a->metavar ? a->metavar : "", *sp = a->metavar ? " " : "";
    snprintf(old, sizeof old, "%s%s%s", a->old, sp, m);
    snprintf(new_, sizeof new_, "%s%s%s", a->new_, sp, m);
    cli_deprecated(verb, old, new_);
}

/* Whether long option `name` (up to '=' or its end; getopt_long's unique
 * prefixes included) takes a value in the next word. */
static int long_wants_next(const char *name, const struct option *lo)
{
    size_t n = strcspn(name, "=");
    if (name[n] == '=') return 0;
    const struct option *hit = NULL;
    for (; lo->name; lo++) {
        if (strncmp(lo->name, name, n)) continue;
        if (strlen(lo->name) == n) return lo->has_arg == required_argument;
        hit = hit ? hit : lo;
    }
    return hit && hit->has_arg == required_argument;
}

/* "--NEW" or "--NEW=VALUE" in memory that lives as long as the run (argv's
 * strings do): a static arena, so nothing is left for a leak checker to
 * report; NULL when the old spellings of one command line (values
 * included) pass its 8 KiB. */
static char *spelled(const char *new_, const char *value)
{
    static char arena[8192];
    static size_t used;
    size_t n = strlen(new_) + (value ? strlen(value) + 1 : 0) + 1;
    if (n > sizeof arena - used) return NULL;
    char *s = arena + used;
    used += n;
    if (value) snprintf(s, n, "%s=%s", new_, value);
    else snprintf(s, n, "%s", new_);
    return s;
}

/* Rewrite the old spellings in argv in place (argv[0] is the verb). A short
 * old letter must stand first in its word ("-qp 5" cannot be split without
 * changing argc). 0, CLI_USAGE after printing why, or CLI_FAIL when the arena is full. */
static int rewrite(int argc, char **argv, const char *shortopts, const struct option *lo)
{
    const char *verb = argv[0];
    for (int i = 1; i < argc; i++) {
        char *w = argv[i];
        if (!strcmp(w, "--")) break;
        if (w[0] != '-' || w[1] == '\0') continue;
        if (w[1] == '-') {
            const cli_alias *a = find_alias(verb, w, strcspn(w, "="));
            if (a) {
                char *eq = strchr(w, '=');
                if (!(argv[i] = spelled(a->new_, eq ? eq + 1 : NULL))) return CLI_FAIL;
                warn_alias(verb, a);
            }
            if (long_wants_next(argv[i] + 2, lo)) i++;
            continue;
        }
        for (int j = 1; w[j]; j++) {
            const cli_alias *a = find_alias(verb, (char[]){'-', w[j], 0}, 2);
            if (a && j > 1)
                return cli_usage_error(verb, "-%c in %s is now %s; write it apart", w[j], w,
                                       a->new_);
            if (a) {
                const char *rest = w[2] && a->metavar ? w + 2 : NULL;
                if (w[2] && !a->metavar)
                    return cli_usage_error(verb, "-%c in %s is now %s; write it apart", w[j], w,
                                           a->new_);
                if (!(argv[i] = spelled(a->new_, rest))) return CLI_FAIL;
                warn_alias(verb, a);
                if (a->metavar && !rest) i++;
                break;
            }
            const char *o = strchr(shortopts, w[j]);
            if (o && o[1] == ':') {
                if (!w[j + 1]) i++;
                break;
            }
        }
    }
    return 0;
}

int cli_getopt(int argc, char **argv, const char *shortopts, const struct option *lo)
{
    /* getopt starts a parse at optind 1 (0 after a reset); rewriting is
     * idempotent, so a second parse of the same argv finds nothing to say. */
    if (optind <= 1) {
        int rc = rewrite(argc, argv, shortopts, lo);
        if (rc == CLI_FAIL) {
            fprintf(stderr, "edgespace %s: the old option spellings of this command line "
                    "are too long to rewrite; write them as README \"Options\" says\n", argv[0]);
            return '?';
        }
        if (rc) return '?';
    }
    return getopt_long(argc, argv, shortopts, lo, NULL);
}
