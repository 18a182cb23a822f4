/* tools/cmd/ingest_landmarks.c — edgespace ingest-landmarks: a landmark set
 * (TPS or long CSV) into a new store, with a triangulation of its landmarks,
 * an edge list ("truss") or no topology at all. */
#include "cli.h"
#include "commands.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>

static const char usage[] =
    "usage: edgespace ingest-landmarks STORE (--tps FILE | --csv FILE [--specimens FILE])\n"
    "                                  [--triangles FILE | --edges FILE]\n"
    "\n"
    "Read landmarks, 2D or 3D, into the new HDF5 store STORE. 2D landmarks are\n"
    "stored with z = 0. What the store can do depends on the topology given:\n"
    "  --triangles  a mesh over the landmarks: every tool runs (gpa, mean, pca,\n"
    "               diff, point, compare, embed, export)\n"
    "  --edges      a \"truss\" of landmark pairs: normalized pair lengths are\n"
    "               stored, so gpa and the edge-length statistics (mean, pca,\n"
    "               diff, point, compare) run; no faces, so no embed\n"
    "  neither      landmark configurations only: gpa, info and export of\n"
    "               positions; length statistics refuse\n"
    "\n"
    "      --tps FILE        tpsDig file (LM=, LM3=, ID=, IMAGE=, SCALE=; CURVES ignored)\n"
    "      --csv FILE        long CSV: specimen, landmark, x, y[, z]\n"
    "      --specimens FILE  CSV of labels: specimen id, then label columns\n"
    "  -T, --triangles FILE  triangles of 1-based landmark numbers, 3 per line\n"
    "  -e, --edges FILE      landmark pairs, 1-based, 2 per line (truss lengths)\n"
    "      --no-tps-scale    keep TPS coordinates unscaled (SCALE= is recorded)\n"
    "  -q, --quiet           print nothing on success\n"
    "  -h, --help            show this help\n"
    "\n"
    "Exit status: 0 ok, 1 failure, 2 usage error.\n";

int cmd_ingest_landmarks(int argc, char **argv)
{
    enum { O_NOSCALE = 256 };
    static const struct option longopts[] = {
        {"tps", required_argument, NULL, 't'},       {"csv", required_argument, NULL, 'c'},
        {"specimens", required_argument, NULL, 's'}, {"triangles", required_argument, NULL, 'T'},
        {"edges", required_argument, NULL, 'e'},     {"no-tps-scale", no_argument, NULL, O_NOSCALE},
        {"quiet", no_argument, NULL, 'q'},           {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *tps = NULL, *csv = NULL, *spec = NULL, *tri = NULL, *edges = NULL;
    int c, quiet = 0, tps_scale = 1;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "T:e:qh", longopts)) != -1) {
        switch (c) {
        case 't': tps = optarg; break;
        case 'c': csv = optarg; break;
        case 's': spec = optarg; break;
        case 'T': tri = optarg; break;
        case 'e': edges = optarg; break;
        case O_NOSCALE: tps_scale = 0; break;
        case 'q': quiet = 1; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("ingest-landmarks", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("ingest-landmarks", "give exactly one STORE");
    if (!tps == !csv) return cli_usage_error("ingest-landmarks", "give one of --tps or --csv");
    if (tri && edges)
        return cli_usage_error("ingest-landmarks", "give --triangles or --edges, not both");
    es_ctx *ctx = cli_ctx_new("ingest-landmarks");
    if (!ctx) return CLI_FAIL;
    es_landmarks *lm = NULL;
    int64_t *idx = NULL, count = 0;
    es_status rc = tps ? es_landmarks_read_tps(ctx, tps, tps_scale, &lm)
                       : es_landmarks_read_csv(ctx, csv, spec, &lm);
    if (rc == ES_OK && tps && spec) rc = es_landmarks_read_specimens(ctx, lm, spec);
    if (rc == ES_OK && (tri || edges))
        rc = es_landmarks_read_index_list(ctx, tri ? tri : edges, tri ? 3 : 2, &idx, &count);
    if (rc == ES_OK)
        rc = edges ? es_landmarks_to_store_edges(ctx, lm, count, idx, argv[optind])
                   : es_landmarks_to_store(ctx, lm, count, idx, argv[optind]);
    if (rc != ES_OK) {
        cli_fail("ingest-landmarks", ctx, rc);
    } else if (!quiet) {
        printf("%s: %lld specimens x %lld landmarks (%dD), %lld %s, %lld label "
               "columns\n", argv[optind], (long long)lm->n, (long long)lm->k, lm->d,
               (long long)count, tri ? "triangles" : edges ? "edges (truss)" : "edges (landmarks only)",
               (long long)lm->ncols);
    }
    es_free(ctx, idx);
    es_landmarks_free(lm);
    es_ctx_free(ctx);
    return rc == ES_OK ? CLI_OK : CLI_FAIL;
}
