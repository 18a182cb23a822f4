/* tests/fuzz/fuzz_common.h — what the parser fuzz targets share: parse the
 * input from an exact-size copy (so ASan sees any read past the end), then
 * check the contract of a successful parse: counts positive, indices in
 * range, coordinates finite; a failure must leave the output empty. */
#ifndef EDGESPACE_FUZZ_COMMON_H
#define EDGESPACE_FUZZ_COMMON_H

#include "edgespace/edgespace.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int fuzz_parse(const uint8_t *data, size_t size, const char *name, es_mesh_format fmt)
{
    static es_ctx *ctx;
    es_meshdata md;
    char *copy;
    if (!ctx && es_ctx_new(&ctx) != ES_OK) return 0;
    copy = malloc(size ? size : 1);
    if (!copy) return 0;
    memcpy(copy, data, size);
    if (es_meshdata_parse(ctx, name, copy, size, fmt, &md) == ES_OK) {
        if (md.nverts <= 0 || md.nfaces <= 0 || !md.xyz || !md.faces) __builtin_trap();
        for (int64_t i = 0; i < 3 * md.nfaces; i++)
            if (md.faces[i] < 0 || md.faces[i] >= md.nverts) __builtin_trap();
        for (int64_t i = 0; i < 3 * md.nverts; i++)
            if (!isfinite(md.xyz[i])) __builtin_trap();
        es_meshdata_clear(ctx, &md);
    } else if (md.xyz || md.faces || md.nverts || md.nfaces ||
               strncmp(es_ctx_errmsg(ctx), name, strlen(name)) != 0) {
        __builtin_trap();   /* failures are clean and name the input */
    }
    free(copy);
    return 0;
}

#endif
