/* tools/cmd/explore.c — edgespace explore: a store's shape space explored by
 * hand in a browser (sliders over PCs, differences and model coefficients,
 * each position embedded as it moves).
 *
 * The server is the Python package's (python/edgespace/explore): its
 * computations are shared with the Jupyter widget (edgespace.widgets), and
 * its HTTP and WebSocket layer is aiohttp's. So this command checks its
 * options and runs `python3 -m edgespace.explore` in its place, with the
 * library it is linked to (found by dladdr, so that a build directory other
 * than build/ serves its own library) and this checkout's python/ folder. */
#define _GNU_SOURCE   /* dladdr */
#include "cli.h"
#include "commands.h"

#include <dlfcn.h>
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef ES_PYTHON_DIR
#define ES_PYTHON_DIR ""
#endif

static const char usage[] =
    "usage: edgespace explore STORE [--port N] [--pca NAME] [--components K] [options]\n"
    "\n"
    "Serve a page to explore the store's shape space by hand, and print its URL.\n"
    "The page has the PCA scatter of the rows coloured by a label column (hover:\n"
    "the row, click: its mesh), a slider per principal component (+-3 sd), per\n"
    "stored difference and per coefficient of a stored model, the point\n"
    "expression of the position (copyable into edgespace embed), the mesh (drag\n"
    "to turn it) with a heat map of the distance from the mean shape or from the\n"
    "prior, a warning when the point breaks the triangle inequality, 'save this\n"
    "shape' (a mesh file beside the store and a stored point; the store is opened\n"
    "read-only until then) and a PNG of the view. Each position is embedded on\n"
    "the server as the slider moves, from the last one's (a warm start); a newer\n"
    "position replaces one still waiting.\n"
    "\n"
    "The server listens on 127.0.0.1 only and answers only requests that carry\n"
    "the random token of the printed URL. Ctrl-C stops it.\n"
    "\n"
    "      --port N       TCP port (default 0: any free one)\n"
    "      --pca NAME     the PCA of the sliders and the scatter (needed when several\n"
    "                     are stored and none is named 'default')\n"
    "  -k, --components K     a slider for each of the first K components (default 20;\n"
    "                     0: all)\n"
    "      --host ADDR    listen on ADDR instead of 127.0.0.1 (anyone who reaches it\n"
    "                     with the URL can read the store)\n"
    "      --cold         every position from its own prior, as edgespace embed does\n"
    "                     (the same mesh as the copied command; slower)\n"
    "      --accurate     the default embedding accuracy instead of the slider's\n"
    "                     (edgespace embed without --fast)\n"
    "      --no-cache     neither read nor write STORE.es-cache\n"
    "  -h, --help         show this help\n"
    "\n"
    "Runs /usr/bin/python3 (or $EDGESPACE_PYTHON) with the Python package and\n"
    "Debian's python3-aiohttp; three.js is served from the npm package that\n"
    "tools/setup.sh installs. In Jupyter: edgespace.widgets.explore(STORE).\n"
    "\n"
    "Exit status: 0 stopped, 1 failure, 2 usage error.\n";

/* PYTHONPATH with this checkout's python/ first, when it holds the package
 * (an installed command relies on the interpreter's own path). */
static int set_python_path(void)
{
    char probe[4096], value[8192];
    const char *old = getenv("PYTHONPATH");
    snprintf(probe, sizeof probe, "%s/edgespace/explore/__main__.py", ES_PYTHON_DIR);
    if (!ES_PYTHON_DIR[0] || access(probe, R_OK) != 0) return 0;
    snprintf(value, sizeof value, "%s%s%s", ES_PYTHON_DIR, old && *old ? ":" : "",
             old ? old : "");
    return setenv("PYTHONPATH", value, 1);
}

/* EDGESPACE_LIBRARY: the libedgespace this command runs with, unless set. */
static int set_library(void)
{
    Dl_info info;
    const char *(*fn)(void) = es_version;
    void *addr;
    if (getenv("EDGESPACE_LIBRARY")) return 0;
    memcpy(&addr, &fn, sizeof addr);   /* POSIX: a function's address fits a void *; ISO C
                                          has no cast for it */
    if (!dladdr(addr, &info) || !info.dli_fname || !strchr(info.dli_fname, '/'))
        return 0;   /* not found: the package looks for it itself */
    return setenv("EDGESPACE_LIBRARY", info.dli_fname, 1);
}

int cmd_explore(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"port", required_argument, NULL, 'p'}, {"pca", required_argument, NULL, 'c'},
        {"host", required_argument, NULL, 'H'}, {"cold", no_argument, NULL, 'C'},
        {"accurate", no_argument, NULL, 'A'},   {"no-cache", no_argument, NULL, 'N'},
        {"components", required_argument, NULL, 'k'},  {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    const char *pca = NULL, *host = "127.0.0.1", *port = "0", *pcs = "20";
    int c, cold = 0, accurate = 0, no_cache = 0;
    int64_t n;
    optind = 1;
    while ((c = cli_getopt(argc, argv, "k:h", longopts)) != -1) {
        switch (c) {
        case 'p':
            if (cli_parse_i64(optarg, &n) || n < 0 || n > 65535)
                return cli_usage_error("explore", "--port wants 0 (any free port) to 65535");
            port = optarg;
            break;
        case 'c': pca = optarg; break;
        case 'k':
            if (cli_parse_i64(optarg, &n) || n < 0)
                return cli_usage_error("explore", "--components wants 0 (all) or a count");
            pcs = optarg;
            break;
        case 'H':
            if (!*optarg) return cli_usage_error("explore", "--host wants an address");
            host = optarg;
            break;
        case 'C': cold = 1; break;
        case 'A': accurate = 1; break;
        case 'N': no_cache = 1; break;
        case 'h': fputs(usage, stdout); return CLI_OK;
        default: return cli_usage_error("explore", "bad option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("explore", "give exactly one STORE");
    const char *python = getenv("EDGESPACE_PYTHON");
    if (!python || !*python) python = "/usr/bin/python3";
    if (set_python_path() || set_library()) {
        fprintf(stderr, "edgespace explore: cannot set the environment: %s\n", strerror(errno));
        return CLI_FAIL;
    }
    const char *args[20];
    int k = 0;
    args[k++] = python;
    args[k++] = "-m";
    args[k++] = "edgespace.explore";
    args[k++] = "--port";
    args[k++] = port;
    args[k++] = "--host";
    args[k++] = host;
    args[k++] = "--components";
    args[k++] = pcs;
    if (pca) {
        args[k++] = "--pca";
        args[k++] = pca;
    }
    if (cold) args[k++] = "--cold";
    if (accurate) args[k++] = "--accurate";
    if (no_cache) args[k++] = "--no-cache";
    args[k++] = "--";           /* a store named "-x.h5" is not an option */
    args[k++] = argv[optind];
    args[k] = NULL;
    fflush(NULL);
    execv(python, (char *const *)args);
    fprintf(stderr, "edgespace explore: cannot run %s: %s (the explorer is the Python "
            "package's: bash tools/setup.sh installs Python and the packages it needs)\n",
            python, strerror(errno));
    return CLI_FAIL;
}
