/* tests/core/test_text.c — numbers and UTF-8 in text (core/text.h):
 * es__parse_double equals strtod bit for bit on edge cases and 600000
 * random decimal strings of every shape, stops at a delimiter or at `end`;
 * es__parse_int64 at the limits of int64; es__parse_finite and
 * es__parse_int64_field take whole fields (blanks around them allowed) and
 * refuse what is not one finite number; es__utf8_valid_prefix stops at the
 * first byte of an invalid sequence. (The number tests lived in
 * tests/meshio/test_io.c until the parser moved to core.) */
#include "core/text.h"
#include "es_test.h"

#include <float.h>
#include <inttypes.h>

/* Our parse of the whole of s must equal strtod's, bit for bit. */
static void check_number(const char *s)
{
    char *stop;
    double want = strtod(s, &stop), got = 0;
    size_t n = strlen(s);
    const char *q = es__parse_double(s, s + n, &got);
    if (*stop != '\0' || n == 0) {
        ES_CHECK_MSG(q == NULL, "'%s' is not a whole number token but parsed", s);
        return;
    }
    ES_CHECK_MSG(q == s + n, "'%s' not consumed", s);
    ES_CHECK_MSG(!memcmp(&got, &want, sizeof got) || (isnan(got) && isnan(want)),
                 "'%s': got %a, strtod %a", s, got, want);
}

static void test_numbers(void)
{
    static const char *const edge[] = {
        "0", "-0", "+0", "0.0", "-0.0", "00000", "1", "-1", "+1", "1.", ".5", "-.5", "1.5",
        "0.1", "0.2", "0.3", "1e5", "1E-5", "1e+22", "1e22", "1e23", "1e-22", "1e-23",
        "9007199254740992", "9007199254740993", "9007199254740991", "9007199254740994",
        "18014398509481985", "123456789012345678", "1234567890123456789",
        "12345678901234567890", "99999999999999999999", "0.9999999999999999999",
        "2.2250738585072014e-308", "2.2250738585072011e-308", "4.9e-324", "5e-324",
        "2.4703282292062327e-324", "2.4703282292062328e-324", "1e-400", "-1e-400",
        "1.7976931348623157e308", "1.7976931348623158e308", "1.7976931348623159e308",
        "1e309", "0x1.8p1", "0X10", "inf", "-inf", "Infinity", "nan", "-NaN",
        "000000000000000000000000001.5", "0.000000000000000000000000000123",
        "3.14159265358979323846264338327950288",
        "1.00000000000000011102230246251565404236316680908203125",
        "1.00000000000000011102230246251565404236316680908203124",
        "9.999999999999999e22", "8.98846567431158e307", "4503599627370496.5",
        "4503599627370497.5", "-3.587471", "18.037172", "0.000001", "1e0", "1e-0",
        "100000000000000000000000", "0.0000000000000000000000001", "7e-10", "1.2e-7",
        "123.456e2", "123.456e-2", "1e100000", "1e-100000", "0e100000", "",
        "-", "+", ".", "e5", "1e", "1e+", "1.2.3", "abc", "--1", "1x", "1..2", "+-1", ".e1"};
    for (size_t i = 0; i < sizeof edge / sizeof *edge; i++) check_number(edge[i]);

    /* random decimal strings of every shape */
    es_rng rng;
    char s[128];
    es_rng_init(&rng, 12345);
    for (int it = 0; it < 600000; it++) {
        int kind = (int)es_rng_below(&rng, 11);
        uint64_t bits = es_rng_next(&rng);
        double d;
        memcpy(&d, &bits, sizeof d);
        if (kind == 0 && isfinite(d)) {
            snprintf(s, sizeof s, "%.17g", d);
        } else if (kind == 1 && isfinite(d)) {
            snprintf(s, sizeof s, "%.*g", 1 + (int)es_rng_below(&rng, 17), d);
        } else if (kind == 2) {
            snprintf(s, sizeof s, "%.*f", (int)es_rng_below(&rng, 10),
                     (es_rng_uniform(&rng) - 0.5) * pow(10, (double)es_rng_below(&rng, 12)));
        } else if (kind == 3 && isfinite(d)) {
            snprintf(s, sizeof s, "%a", d);
        } else if (kind == 6) {
            /* what the writers produce: %.17g of coordinate-sized values */
            snprintf(s, sizeof s, "%.17g", (es_rng_uniform(&rng) - 0.5) *
                     pow(10, (double)es_rng_below(&rng, 81) - 40));
        } else if (kind == 7) {
            snprintf(s, sizeof s, "%.*e", 15 + (int)es_rng_below(&rng, 4),
                     (es_rng_uniform(&rng) - 0.5) *
                         pow(10, (double)es_rng_below(&rng, 221) - 110));
        } else if (kind == 8) {
            /* 16 to 19 digit mantissas with exponents around the table's
             * range (+-100) and beyond */
            uint64_t w = es_rng_next(&rng) % UINT64_C(10000000000000000000);
            snprintf(s, sizeof s, "%" PRIu64 "e%d", w, (int)es_rng_below(&rng, 261) - 130);
        } else if (kind == 9) {
            /* exact halfway cases: odd integers in (2^53, 2^54) and those
             * = 2 mod 4 in (2^54, 2^55), times small powers of ten */
            uint64_t w = (UINT64_C(1) << 53) + (es_rng_next(&rng) >> 11);
            if (es_rng_below(&rng, 2)) w = ((UINT64_C(1) << 54) + (es_rng_next(&rng) >> 10)) | 2;
            w |= 1 & ~(w >> 54);
            int q = (int)es_rng_below(&rng, 8) - 4;
            if (q < 0 && es_rng_below(&rng, 2)) q = 0;
            snprintf(s, sizeof s, "%" PRIu64 "e%d", w, q);
        } else {
            /* digits with a random point, sign and exponent */
            int nd = 1 + (int)es_rng_below(&rng, 24), dot = (int)es_rng_below(&rng, nd + 2);
            size_t k = 0;
            if (es_rng_below(&rng, 3) == 0) s[k++] = '-';
            for (int j = 0; j < nd; j++) {
                if (j == dot) s[k++] = '.';
                s[k++] = (char)('0' + es_rng_below(&rng, j == 0 && es_rng_below(&rng, 2)
                                                              ? 1 : 10));
            }
            if (es_rng_below(&rng, 3) == 0)
                k += (size_t)snprintf(s + k, sizeof s - k, "e%d",
                                      (int)es_rng_below(&rng, 80) - 40);
            s[k] = '\0';
        }
        check_number(s);
    }

    /* the token ends at a delimiter or at `end`, never reading beyond */
    double v = 0;
    const char *t = "1.5 2";
    ES_CHECK(es__parse_double(t, t + 5, &v) == t + 3 && v == 1.5);
    t = "-2.25/7";
    ES_CHECK(es__parse_double(t, t + 7, &v) == t + 5 && v == -2.25);
    t = "1.23456";
    ES_CHECK(es__parse_double(t, t + 4, &v) == t + 4 && v == 1.23);
    t = "1.234567890123456789012345xyz";
    ES_CHECK(es__parse_double(t, t + 26, &v) == t + 26 &&
             v == strtod("1.234567890123456789012345", NULL));

    int64_t n = 0;
    t = "9223372036854775807";
    ES_CHECK(es__parse_int64(t, t + strlen(t), &n) && n == INT64_MAX);
    t = "-9223372036854775808";
    ES_CHECK(es__parse_int64(t, t + strlen(t), &n) && n == INT64_MIN);
    t = "9223372036854775808";
    ES_CHECK(es__parse_int64(t, t + strlen(t), &n) == NULL);
    t = "-";
    ES_CHECK(es__parse_int64(t, t + 1, &n) == NULL);
    t = "+42/";
    ES_CHECK(es__parse_int64(t, t + 4, &n) == t + 3 && n == 42);
}

/* Whole fields as finite numbers. */
static void test_finite(void)
{
    double v = -1;
    static const struct { const char *s; double want; } good[] = {
        {"0", 0}, {"-0", -0.0}, {" 1.5", 1.5}, {"1.5 ", 1.5}, {"\t-2e3\r\n", -2e3},
        {"  +7  ", 7}, {"0x1p-2", 0.25}, {"1e308", 1e308}, {"-1.7976931348623157e308", -DBL_MAX},
        /* subnormal values are numbers (strtod sets ERANGE for them) */
        {"1e-310", 1e-310}, {"4.9e-324", 4.9e-324},
        {"-2.2250738585072011e-308", -2.2250738585072011e-308},
        /* underflow to zero is zero, as strtod rounds it */
        {"1e-400", 0},
    };
    for (size_t i = 0; i < sizeof good / sizeof *good; i++) {
        v = -1;
        ES_CHECK_MSG(es__parse_finite(good[i].s, &v) == 0 && v == good[i].want &&
                     signbit(v) == signbit(good[i].want), "'%s' -> %.17g", good[i].s, v);
    }
    ES_CHECK(es__parse_finite("1e-310", &v) == 0 && fpclassify(v) == FP_SUBNORMAL);
    static const char *const bad[] = {
        "", " ", "\t\r\n", "1e309", "-1e309", "1e100000", "inf", "-inf", "Infinity", "nan",
        "NaN", "1 2", "1,5", "1.5x", "x1.5", "--1", "1e", ".", "-", "0x", "1.5\v"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        v = 42;
        ES_CHECK_MSG(es__parse_finite(bad[i], &v) == -1 && v == 42, "'%s' accepted", bad[i]);
    }
}

/* Whole fields as int64. */
static void test_int_field(void)
{
    int64_t n = 0;
    ES_CHECK(es__parse_int64_field("42", &n) == 0 && n == 42);
    ES_CHECK(es__parse_int64_field(" \t-7\r\n", &n) == 0 && n == -7);
    ES_CHECK(es__parse_int64_field("+0", &n) == 0 && n == 0);
    ES_CHECK(es__parse_int64_field("9223372036854775807", &n) == 0 && n == INT64_MAX);
    ES_CHECK(es__parse_int64_field("-9223372036854775808", &n) == 0 && n == INT64_MIN);
    static const char *const bad[] = {"", "  ", "9223372036854775808", "-9223372036854775809",
                                      "1.0", "1e3", "0x10", "1 2", "12a", "+", "-", "--1"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        n = 5;
        ES_CHECK_MSG(es__parse_int64_field(bad[i], &n) == -1 && n == 5, "'%s' accepted", bad[i]);
    }
}

/* The valid prefix ends at the first byte of an invalid sequence. */
static void test_utf8(void)
{
    static const struct { const char *s; size_t n, want; } cases[] = {
        {"plain ascii", 11, 11},
        {"caf\xc3\xa9", 5, 5},
        {"\xe2\x82\xac\xf0\x9f\x98\x80", 7, 7},       /* U+20AC, U+1F600 */
        {"\xf4\x8f\xbf\xbf", 4, 4},                      /* U+10FFFF */
        {"ab\xc3", 3, 2},                                 /* cut short */
        {"ab\xc3(", 4, 2},                                /* bad continuation */
        {"\xc0\xaf", 2, 0}, {"\xe0\x80\xaf", 3, 0},       /* overlong */
        {"x\xed\xa0\x80", 4, 1},                          /* surrogate U+D800 */
        {"\xf4\x90\x80\x80", 4, 0},                        /* past U+10FFFF */
        {"\xff", 1, 0}, {"a\x80", 2, 1},
        {"", 0, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++)
        ES_CHECK_MSG(es__utf8_valid_prefix((const unsigned char *)cases[i].s, cases[i].n) ==
                     cases[i].want, "case %zu", i);
}

int main(void)
{
    ES_TEST_BEGIN();
    test_numbers();
    test_finite();
    test_int_field();
    test_utf8();
    ES_TEST_END();
}
