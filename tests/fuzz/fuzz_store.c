/* tests/fuzz/fuzz_store.c — libFuzzer target of the store opener: a valid
 * store (the crafted suite's base) with bytes changed and possibly cut
 * short. The input is byte 0, then patches of three bytes: a 16-bit
 * position and the byte to put there. Byte 0's bit 0 truncates the file
 * to the length in the last two bytes (a fraction of the file); its bit 1
 * aims the patches at object headers: the position picks one of the
 * base's object headers and a byte inside it, where a changed byte is a
 * message HDF5 decodes (a layout message's version byte made libhdf5 1.10
 * divide by zero; over the whole file such bytes are 1 in 100 and were
 * found after 103 s, in the headers within seconds). The store must open
 * and read in full, or be refused with one clean line; libhdf5 itself is
 * not instrumented, so a crash inside it is found as a signal.
 * Seeds: tests/data/fuzz-store. */
#include "fuzz_store.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t nbase, len, nhdr;
    const unsigned char *base = fuzz_base_store(&nbase);
    const fuzz_header *hdr = fuzz_base_headers(&nhdr);
    unsigned char *b;
    if (size < 1 || !(b = malloc(nbase))) return 0;
    memcpy(b, base, nbase);
    len = nbase;
    for (size_t i = 1; i + 3 <= size; i += 3) {
        size_t at = (size_t)data[i] << 8 | data[i + 1];
        if ((data[0] & 2) && nhdr > 0) {
            const fuzz_header *h = &hdr[at % nhdr];
            at = h->addr + (at / nhdr) % h->len;
        }
        b[at % nbase] = data[i + 2];
    }
    if ((data[0] & 1) && size >= 3)
        len = nbase * ((size_t)data[size - 2] << 8 | data[size - 1]) / 65536;
    fuzz_open_and_read(fuzz_store_file(b, len));
    free(b);
    return 0;
}
