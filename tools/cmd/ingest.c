/* tools/cmd/ingest.c — edgespace ingest: meshes (a manifest or a list of
 * files) into an HDF5 store, all-or-nothing (es_ingest.h). */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace ingest STORE (--manifest CSV | FILES...)\n"
    "\n"
    "Read meshes that share one connectivity into the HDF5 store STORE (created\n"
    "if absent): edge lengths normalized to sum 1, their scale, positions, ids\n"
    "and labels. Inputs are read and checked a block at a time, and each block\n"
    "is written to a working copy that replaces STORE only when every input is\n"
    "in: on any error (or if killed) the store is left exactly as it was.\n"
    "Inputs whose id and content are in the store already are skipped.\n"
    "Under mpirun -n P (the MPI build) each rank reads a share of the inputs and\n"
    "the ranks write the store together (parallel HDF5); the store is the same.\n"
    "\n"
    "      --manifest CSV  CSV with a 'file' column (paths relative to the CSV),\n"
    "                      an optional 'id' column and any label columns\n"
    "  -f, --format FMT    obj, ply or off (default: from each file's extension)\n"
    "      --no-create     fail if STORE does not exist\n"
    "      --block-rows N  inputs held in memory at once (default: about 64 MB\n"
    "                      of positions and lengths)\n"
    "  -q, --quiet         print nothing on success\n"
    "  -h, --help          show this help\n"
    "\n"
    "Ids are the manifest's 'id' column, else the file name without extension.\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_ingest(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"manifest", required_argument, NULL, 'm'}, {"format", required_argument, NULL, 'f'},
        {"no-create", no_argument, NULL, 'N'},      {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},           {"block-rows", required_argument, NULL, 'B'},
        {NULL, 0, NULL, 0}};
    const char *manifest = NULL, *store;
    es_ingest_opts opts;
    es_ingest_report rep;
    es_status rc;
    es_ctx *ctx;
    int c, quiet = 0;
    es_ingest_opts_init(&opts);
    optind = 1;
    while ((c = cli_getopt(argc, argv, "f:qh", longopts)) != -1) {
        switch (c) {
        case 'm': manifest = optarg; break;
        case 'f':
            if (!strcmp(optarg, "obj")) opts.format = ES_FORMAT_OBJ;
            else if (!strcmp(optarg, "ply")) opts.format = ES_FORMAT_PLY;
            else if (!strcmp(optarg, "off")) opts.format = ES_FORMAT_OFF;
            else return cli_usage_error("ingest", "unknown format '%s' (obj, ply, off)", optarg);
            break;
        case 'N': opts.create = 0; break;
        case 'B':
            if (cli_parse_i64(optarg, &opts.block_rows) != 0 || opts.block_rows < 1)
                return cli_usage_error("ingest", "--block-rows wants a positive integer, not "
                                       "'%s'", optarg);
            break;
        case 'q': quiet = 1; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("ingest", "bad option");
        }
    }
    if (optind >= argc) return cli_usage_error("ingest", "missing STORE");
    store = argv[optind++];
    if (manifest && optind < argc)
        return cli_usage_error("ingest", "give either --manifest or FILES, not both");
    if (!manifest && optind >= argc)
        return cli_usage_error("ingest", "nothing to ingest: give --manifest CSV or FILES");
    if (!(ctx = cli_ctx_new("ingest"))) return CLI_FAIL;
    if (manifest)
        rc = es_ingest_manifest(ctx, store, manifest, &opts, &rep);
    else
        rc = es_ingest_files(ctx, store, argc - optind, (const char *const *)(argv + optind),
                             &opts, &rep);
    if (rc != ES_OK) {
        cli_fail("ingest", ctx, rc);
        es_ctx_free(ctx);
        return CLI_FAIL;
    }
    if (!quiet)
        printf("%s: %lld added, %lld skipped (already in the store), %lld rows in all%s\n",
               store, (long long)rep.rows_added, (long long)rep.rows_skipped,
               (long long)rep.rows_total, rep.created ? " (new store)" : "");
    es_ctx_free(ctx);
    return CLI_OK;
}
