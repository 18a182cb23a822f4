/* tests/fuzz/fuzz_tps.c — libFuzzer target of the TPS landmark reader
 * (es_landmarks_read_tps on a memory file). A file that reads has
 * specimens of k >= 1 landmarks in 2 or 3 dimensions, finite coordinates
 * (SCALE applied) and an id each; a refusal is one line naming the
 * landmarks reader. The first byte chooses whether SCALE is applied.
 * Seeds: tests/data/fuzz-tps and tests/data/landmarks. */
#include "fuzz_util.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    es_ctx *ctx = fuzz_ctx();
    es_landmarks *lm = NULL;
    char path[64];
    if (size < 1) return 0;
    fuzz_file(0, data + 1, size - 1, path, sizeof path);
    if (es_landmarks_read_tps(ctx, path, data[0] & 1, &lm) == ES_OK) {
        if (!lm || lm->n < 1 || lm->k < 1 || (lm->d != 2 && lm->d != 3)) __builtin_trap();
        for (int64_t i = 0; i < lm->n * lm->k * lm->d; i++)
            if (!isfinite(lm->xyz[i])) __builtin_trap();
        for (int64_t j = 0; j < lm->n; j++)
            if (!lm->ids[j]) __builtin_trap();
        es_landmarks_free(lm);
    } else {
        if (lm) __builtin_trap();
        fuzz_check_message(ctx, "landmarks: ");
    }
    return 0;
}
