/* tests/fuzz/fuzz_crafted.c — libFuzzer target of the crafted-store
 * generator (tests/store/crafted.c): inconsistent but well-formed stores.
 * The input picks up to four mutations (a byte each: which, then a byte:
 * its variant) applied to the base store, then byte patches as
 * fuzz_store.c reads them (16-bit offset, value). The store must
 * open and read in full, or be refused with one clean line.
 * Seeds: tests/data/fuzz-crafted. */
#include "fuzz_store.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t nbase, i = 0;
    const unsigned char *base = fuzz_base_store(&nbase);
    unsigned char *b;
    const char *path = fuzz_store_file(base, nbase);
    /* the mutations made through HDF5 first, then those that patch bytes
     * (heaps, symbol tables, descriptors): the generator's own HDF5 calls
     * would otherwise walk a heap a patch has made loop */
    for (int pass = 0; pass < 3; pass++)
        for (size_t m = 0; m < 4 && 2 * m + 2 <= size; m++) {
            int k = data[2 * m] % crafted_nmutations;
            if (crafted_patches_bytes(k) == pass) crafted_apply(path, k, data[2 * m + 1]);
        }
    i = size < 8 ? size - size % 2 : 8;
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
