/* tools/cmd/results.c — edgespace results: list a store's analysis results
 * (es_store_list_results) with when and how each was made, delete some
 * (es_store_delete_result: all or nothing, at the commit), or upgrade a
 * store of an earlier release so that its results live beside it
 * (es_store_upgrade). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>

#define VERB "results"
#define MAX_DELETE 64

static const char usage[] =
    "usage: edgespace results STORE [--kind KIND] [--delete KIND/NAME]... [--upgrade]\n"
    "\n"
    "List the analysis results of STORE, one line each: KIND/NAME, when it was\n"
    "made and the command that made it (export --result KIND/NAME writes its\n"
    "tables). With --delete, remove the named results instead: all of them or,\n"
    "when one is missing, none. Results are files beside the store\n"
    "(STORE.results/KIND/NAME.h5); a store of an earlier release (format 1 or 2)\n"
    "keeps them inside, and each stored result copies it, until --upgrade moves\n"
    "them out (one copy of the store).\n"
    "\n"
    "      --kind KIND        list only results of KIND (mean, pca, gpa, model, ...)\n"
    "  -d, --delete KIND/NAME delete this result (repeat for several)\n"
    "  -u, --upgrade          upgrade a store of format 1 or 2 to format 3\n"
    "  -h, --help             show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

static void free_names(es_ctx *ctx, char **v, int64_t n)
{
    for (int64_t i = 0; i < n; i++) es_free(ctx, v[i]);
    es_free(ctx, v);
}

static es_status list(es_ctx *ctx, es_store *s, const char *only)
{
    char **kinds = NULL, **names = NULL, path[600], when[64], cmd[1024];
    int64_t nk = 0, nn = 0, total = 0;
    es_status rc = es_store_list_results(ctx, s, NULL, &kinds, &nk);
    for (int64_t k = 0; rc == ES_OK && k < nk; k++) {
        if (only && strcmp(only, kinds[k])) continue;
        if ((rc = es_store_list_results(ctx, s, kinds[k], &names, &nn)) != ES_OK) break;
        for (int64_t i = 0; i < nn; i++, total++) {
            snprintf(path, sizeof path, "%s/%s", kinds[k], names[i]);
            if (es_store_get_attr(ctx, s, path, "time", when, sizeof when) != ES_OK) *when = '\0';
            if (es_store_get_attr(ctx, s, path, "command", cmd, sizeof cmd) != ES_OK) *cmd = '\0';
            printf("%-28s %-20s %s\n", path, when, cmd);
        }
        free_names(ctx, names, nn);
    }
    free_names(ctx, kinds, nk);
    if (rc == ES_OK && !total) printf("no results%s%s\n", only ? " of kind " : "", only ? only : "");
    return rc;
}

int cmd_results(int argc, char **argv)
{
    static const struct option lo[] = {
        {"kind", required_argument, NULL, 'k'}, {"delete", required_argument, NULL, 'd'},
        {"upgrade", no_argument, NULL, 'u'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *kind = NULL, *del[MAX_DELETE];
    int ndel = 0, c, upgrade = 0;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "d:uh", lo)) != -1) {
        switch (c) {
        case 'k': kind = optarg; break;
        case 'u': upgrade = 1; break;
        case 'd':
            if (ndel == MAX_DELETE) return cli_usage_error(VERB, "too many --delete");
            if (!strchr(optarg, '/') || strchr(optarg, '/') == optarg)
                return cli_usage_error(VERB, "--delete wants KIND/NAME, not '%s'", optarg);
            del[ndel++] = optarg;
            break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error(VERB, "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error(VERB, "give exactly one STORE");
    if (kind && ndel) return cli_usage_error(VERB, "--kind lists; it does not go with --delete");
    es_ctx *ctx = cli_ctx_new(VERB);
    if (!ctx) return CLI_FAIL;
    es_store *s = NULL;
    es_status rc = es_store_open(ctx, argv[optind], ndel || upgrade ? ES_STORE_WRITE : ES_STORE_READ,
                                 &s);
    int before = es_store_format_version(s);
    if (rc == ES_OK && upgrade && (rc = es_store_upgrade(ctx, s)) == ES_OK)
        printf("%s: format %d%s\n", argv[optind], es_store_format_version(s),
               before == es_store_format_version(s) ? " already" : " (upgraded)");
    for (int i = 0; rc == ES_OK && i < ndel; i++) {
        char k[128];
        size_t len = (size_t)(strchr(del[i], '/') - del[i]);
        snprintf(k, sizeof k, "%.*s", (int)(len < sizeof k ? len : sizeof k - 1), del[i]);
        rc = es_store_delete_result(ctx, s, k, del[i] + len + 1);
    }
    if (rc == ES_OK && ndel) rc = es_store_commit(ctx, s);
    if (rc == ES_OK && !ndel && !upgrade) rc = list(ctx, s, kind);
    if (rc == ES_OK)
        for (int i = 0; i < ndel; i++) printf("deleted %s\n", del[i]);
    int ret = rc == ES_OK ? CLI_OK : cli_fail(VERB, ctx, rc);
    if (ret == CLI_OK) es_store_close(s);
    else es_store_abort(s);
    es_ctx_free(ctx);
    return ret;
}
