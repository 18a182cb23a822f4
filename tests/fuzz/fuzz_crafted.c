/* tests/fuzz/fuzz_crafted.c — libFuzzer target of the crafted-store
 * generator (tests/store/crafted.c): inconsistent but well-formed stores.
 * The input picks up to four mutations (a byte each: which, then a byte:
 * its variant) applied in turn to the base store through HDF5, then byte
 * patches as fuzz_store.c reads them (16-bit offset, value). The store must
 * open and read in full, or be refused with one clean line.
 * Seeds: tests/data/fuzz-crafted. */
#include "fuzz_store.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t nbase, i = 0;
    const unsigned char *base = fuzz_base_store(&nbase);
    unsigned char *b;
    const char *path = fuzz_store_file(base, nbase);
    for (int m = 0; m < 4 && i + 2 <= size; m++, i += 2)
        crafted_apply(path, data[i] % crafted_nmutations, data[i + 1]);
    if (i < size) {
        /* the file as the mutations left it, then the patches */
        FILE *f = fopen(path, "rb");
        long n;
        if (!f) abort();
        fseek(f, 0, SEEK_END);
        n = ftell(f);
        rewind(f);
        if (n <= 0 || !(b = malloc((size_t)n)) || fread(b, 1, (size_t)n, f) != (size_t)n) abort();
        fclose(f);
        for (; i + 3 <= size; i += 3) b[((size_t)data[i] << 8 | data[i + 1]) % (size_t)n] = data[i + 2];
        path = fuzz_store_file(b, (size_t)n);
        free(b);
    }
    fuzz_open_and_read(path);
    return 0;
}
