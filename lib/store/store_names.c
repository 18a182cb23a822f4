/* lib/store/store_names.c — the one rule for the name of a result (and of
 * its kind): /analysis/<kind>/<name> is an HDF5 path and <name> a file
 * name beside the store (format 3), so neither may be empty, "." or "..",
 * hold a '/', or a control character (it would print as a broken line in
 * every table and log that names the result), and each stays short enough
 * to be a file name with the store's suffixes (120 bytes). The analyses
 * (lib/study) and the store's own writers both ask it; they used to keep
 * two rules, and a name refused by one was accepted by the other. */
#include "store/store_pkg.h"
#include "store/store_private.h"

#include <string.h>

#define ES__MAX_RESULT_NAME 120

static const char *name_fault(const char *name)
{
    if (!name || !*name) return "empty";
    if (!strcmp(name, ".") || !strcmp(name, "..")) return "'.' and '..' name folders";
    if (strlen(name) > ES__MAX_RESULT_NAME) return "longer than 120 bytes";
    for (const char *c = name; *c; c++) {
        if (*c == '/') return "no '/'";
        if ((unsigned char)*c < 32) return "no control characters";
    }
    return NULL;
}

es_status es__result_name_check(es_ctx *ctx, const char *kind, const char *name)
{
    const char *why;
    if (kind && (why = name_fault(kind)))
        ES_FAIL(ctx, ES_EINVAL, "store: bad result kind '%s' (%s)", kind, why);
    if ((why = name_fault(name)))
        ES_FAIL(ctx, ES_EINVAL, "store: bad result name '%s' (%s)", name ? name : "", why);
    return ES_OK;
}
