/* tests/fuzz/fuzz_manifest.c — libFuzzer target of the CSV manifest reader
 * (es_manifest_parse, from an exact-size copy so that ASan sees a read past
 * the end). A manifest that parses has a header with a file column, rows of
 * the header's width with non-empty file cells, and unique non-empty ids; a
 * refusal names the manifest. Seeds: tests/data/fuzz-manifest. */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    es_ctx *ctx = fuzz_ctx();
    es_manifest *m = NULL;
    char *copy = malloc(size ? size : 1);
    if (!copy) return 0;
    memcpy(copy, data, size);
    if (es_manifest_parse(ctx, "fuzz.csv", "/nonexistent", copy, size, &m) == ES_OK) {
        if (!m || m->ncols < 1 || m->nrows < 0 || m->file_col < 0 || m->file_col >= m->ncols ||
            m->id_col >= m->ncols)
            __builtin_trap();
        for (int64_t r = 0; r < m->nrows; r++) {
            if (!m->ids[r] || !*m->ids[r] || !*m->cells[r * m->ncols + m->file_col])
                __builtin_trap();
            for (int64_t q = 0; q < r && q < 64; q++)   /* unique (checked near r) */
                if (!strcmp(m->ids[q], m->ids[r])) __builtin_trap();
        }
        es_manifest_free(ctx, m);
    } else {
        if (m) __builtin_trap();
        fuzz_check_message(ctx, "fuzz.csv");
    }
    free(copy);
    return 0;
}
