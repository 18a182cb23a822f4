/* tests/fuzz/fuzz_obj.c — libFuzzer target for the OBJ reader
 * (es_meshdata_parse). Built with -Dfuzz=true and clang; run by
 * tests/fuzz/run-fuzzers.sh. Besides memory errors (ASan) it traps when a
 * successful parse breaks the reader's contract. */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_parse(data, size, "fuzz.obj", ES_FORMAT_OBJ);
}
