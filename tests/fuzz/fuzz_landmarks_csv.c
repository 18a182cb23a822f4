/* tests/fuzz/fuzz_landmarks_csv.c — libFuzzer target of the long-CSV
 * landmark reader with its specimens table (es_landmarks_read_csv). The
 * input is the landmark table, then, after a line "====", the specimens
 * table (none without it). A table that reads has unique specimen ids,
 * finite coordinates, and with specimens one label row per specimen; a
 * refusal is one line naming the landmarks reader. Seeds:
 * tests/data/fuzz-lmcsv. */
#include "fuzz_util.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char sep[] = "\n====\n";
    es_ctx *ctx = fuzz_ctx();
    es_landmarks *lm = NULL;
    char p1[64], p2[64];
    const uint8_t *cut = NULL;
    for (size_t i = 0; i + sizeof sep - 1 <= size && !cut; i++)
        if (!memcmp(data + i, sep, sizeof sep - 1)) cut = data + i;
    size_t n1 = cut ? (size_t)(cut - data) + 1 : size;
    fuzz_file(0, data, n1, p1, sizeof p1);
    if (cut) fuzz_file(1, cut + sizeof sep - 1, size - (size_t)(cut - data) - (sizeof sep - 1), p2,
                       sizeof p2);
    if (es_landmarks_read_csv(ctx, p1, cut ? p2 : NULL, &lm) == ES_OK) {
        if (!lm || lm->n < 1 || lm->k < 1 || (lm->d != 2 && lm->d != 3)) __builtin_trap();
        for (int64_t i = 0; i < lm->n * lm->k * lm->d; i++)
            if (!isfinite(lm->xyz[i])) __builtin_trap();
        for (int64_t j = 0; j < lm->n; j++) {
            if (!lm->ids[j]) __builtin_trap();
            for (int64_t q = j > 64 ? j - 64 : 0; q < j; q++)
                if (!strcmp(lm->ids[q], lm->ids[j])) __builtin_trap();
            for (int64_t c = 0; c < lm->ncols; c++)
                if (!lm->labels[j * lm->ncols + c]) __builtin_trap();
        }
        es_landmarks_free(lm);
    } else {
        if (lm) __builtin_trap();
        fuzz_check_message(ctx, "landmarks");
    }
    return 0;
}
