/* tests/fuzz/fuzz_num.c — differential libFuzzer target: es__parse_double
 * against strtod. Whatever prefix our parser accepts, strtod must accept
 * whole and give the same bits. Built with -Dfuzz=true and clang. */
#include "core/text.h"

#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char buf[600], tok[600], *stop;
    double got, want;
    const char *q;
    if (size >= sizeof buf) return 0;
    memcpy(buf, data, size);
    q = es__parse_double(buf, buf + size, &got);
    if (!q) return 0;
    if (q <= buf || q > buf + size) __builtin_trap();
    memcpy(tok, buf, (size_t)(q - buf));
    tok[q - buf] = '\0';
    want = strtod(tok, &stop);
    if (stop != tok + (q - buf)) __builtin_trap();
    if (memcmp(&got, &want, sizeof got) && !(got != got && want != want)) __builtin_trap();
    return 0;
}
