/* tests/fuzz/fuzz_store.c — libFuzzer target of the store opener: a valid
 * store (the crafted suite's base) with bytes changed and possibly cut
 * short. The input is byte 0 (bit 0: truncate to the length in the last
 * two bytes, as a fraction of the file), then patches of three bytes:
 * a 16-bit offset into the file and the byte to put there. The store
 * must open and read in full, or be refused with one clean line; libhdf5
 * itself is not instrumented, so a crash inside it is found as a signal.
 * Seeds: tests/data/fuzz-store. */
#include "fuzz_store.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t nbase, len;
    const unsigned char *base = fuzz_base_store(&nbase);
    unsigned char *b;
    if (size < 1 || !(b = malloc(nbase))) return 0;
    memcpy(b, base, nbase);
    len = nbase;
    for (size_t i = 1; i + 3 <= size; i += 3)
        b[((size_t)data[i] << 8 | data[i + 1]) % nbase] = data[i + 2];
    if ((data[0] & 1) && size >= 3)
        len = nbase * ((size_t)data[size - 2] << 8 | data[size - 1]) / 65536;
    fuzz_open_and_read(fuzz_store_file(b, len));
    free(b);
    return 0;
}
