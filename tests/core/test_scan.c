/* tests/core/test_scan.c — the scanner of the small input languages
 * (core/scan.h): a table of inputs, each read by a small tokenizer written
 * here on the scanner (space, numbers, quoted text, names, punctuation)
 * under each whitespace rule, against the tokens, their columns and the
 * errors written out by hand; numbers against strtod bit for bit (the
 * oracle), also on random tokens of the number grammar; the limits of a
 * number; the next token described; closing brackets; the messages with
 * their column.
 */
#include "core/scan.h"
#include "es_test.h"

#include <stdlib.h>

/* The tokens of s, one "KIND(text)@column" each, space-separated:
 * N(number as %.17g) Q(quoted) W(name) P(byte) E(end); an error stops it
 * as "!MALFORMED@column" and the like. */
static void tokens(const char *s, es__scan_space space, char *out, size_t n)
{
    es__scan sc;
    size_t o = 0;
    es__scan_init(&sc, NULL, s, "test", "the end", space);
    out[0] = '\0';
    for (;;) {
        es__scan_skip_space(&sc);
        size_t at = sc.pos + 1, len = 0;
        const char *w = NULL;
        double v = 0;
        es__scan_result r;
        char tok[160];
        if (es__scan_at_end(&sc)) {
            snprintf(tok, sizeof tok, "E@%zu", at);
        } else if ((r = es__scan_number(&sc, 24, &v, &len)) != ES__SCAN_NONE) {
            if (r == ES__SCAN_OK) snprintf(tok, sizeof tok, "N(%.17g)@%zu", v, at);
            else snprintf(tok, sizeof tok, "!%s@%zu", r == ES__SCAN_TOO_LONG ? "LONG" :
                          "MALFORMED", at);
        } else if ((r = es__scan_quoted(&sc, &w, &len)) != ES__SCAN_NONE) {
            if (r == ES__SCAN_OK) snprintf(tok, sizeof tok, "Q(%.*s)@%zu", (int)len, w, at);
            else snprintf(tok, sizeof tok, "!%s@%zu", r == ES__SCAN_EMPTY ? "EMPTY" :
                          "UNTERMINATED", at);
        } else if ((r = es__scan_word(&sc, es__scan_ident_char, &w, &len)) == ES__SCAN_OK) {
            snprintf(tok, sizeof tok, "W(%.*s)@%zu", (int)len, w, at);
        } else {
            char c = es__scan_peek(&sc);
            ES_CHECK(es__scan_accept(&sc, c));
            snprintf(tok, sizeof tok, "P(%c)@%zu", c, at);
        }
        o += (size_t)snprintf(out + o, n - o, "%s%s", o ? " " : "", tok);
        if (tok[0] == 'E' || tok[0] == '!' || o >= n) return;
    }
}

static void test_table(void)
{
    static const struct {
        const char *in;
        es__scan_space space;
        const char *want;
    } t[] = {
        {"mean + 2*pc:1", ES__SCAN_SPACE_BLANKS,
         "W(mean)@1 P(+)@6 N(2)@8 P(*)@9 W(pc)@10 P(:)@12 N(1)@13 E@14"},
        {"~ expression + age", ES__SCAN_SPACE_C, "P(~)@1 W(expression)@3 P(+)@14 W(age)@16 E@19"},
        {"  1.5e3 .25 7. 1E-2", ES__SCAN_SPACE_BLANKS,
         "N(1500)@3 N(0.25)@9 N(7)@13 N(0.01)@16 E@20"},
        /* the three whitespace rules: \v and \f are space only to isspace() */
        {"a\t\n\rb", ES__SCAN_SPACE_BLANKS, "W(a)@1 W(b)@5 E@6"},
        {"a\vb", ES__SCAN_SPACE_BLANKS, "W(a)@1 P(\v)@2 W(b)@3 E@4"},
        {"a\v\fb", ES__SCAN_SPACE_C, "W(a)@1 W(b)@4 E@5"},
        {"a b", ES__SCAN_SPACE_NONE, "W(a)@1 P( )@2 W(b)@3 E@4"},
        {"", ES__SCAN_SPACE_C, "E@1"},
        {"   ", ES__SCAN_SPACE_C, "E@4"},
        /* quoted text: any byte but '"', no escapes */
        {"\"a b,c\" x", ES__SCAN_SPACE_BLANKS, "Q(a b,c)@1 W(x)@9 E@10"},
        {"f(\"x\\\")", ES__SCAN_SPACE_BLANKS, "W(f)@1 P(()@2 Q(x\\)@3 P())@7 E@8"},
        {"x \"\" y", ES__SCAN_SPACE_BLANKS, "W(x)@1 !EMPTY@3"},
        {"x \"open", ES__SCAN_SPACE_BLANKS, "W(x)@1 !UNTERMINATED@3"},
        /* numbers: the grammar's edges */
        {"1e", ES__SCAN_SPACE_BLANKS, "!MALFORMED@1"},
        {"2e+", ES__SCAN_SPACE_BLANKS, "!MALFORMED@1"},
        {". 1", ES__SCAN_SPACE_BLANKS, "!MALFORMED@1"},
        {".e5", ES__SCAN_SPACE_BLANKS, "!MALFORMED@1"},
        {"1.5.2", ES__SCAN_SPACE_BLANKS, "N(1.5)@1 N(0.20000000000000001)@4 E@6"},
        {"12x", ES__SCAN_SPACE_BLANKS, "N(12)@1 W(x)@3 E@4"},
        {"1e999", ES__SCAN_SPACE_BLANKS, "N(inf)@1 E@6"},
        {"1e-400", ES__SCAN_SPACE_BLANKS, "N(0)@1 E@7"},
        {"123456789012345678901234", ES__SCAN_SPACE_BLANKS, "!LONG@1"},
        {"12345678901234567890123", ES__SCAN_SPACE_BLANKS, "N(1.2345678901234568e+22)@1 E@24"},
        {"-3", ES__SCAN_SPACE_BLANKS, "P(-)@1 N(3)@2 E@3"},
        {"pc_2.x", ES__SCAN_SPACE_BLANKS, "W(pc_2)@1 !MALFORMED@5"},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        char got[1024];
        tokens(t[i].in, t[i].space, got, sizeof got);
        ES_CHECK_MSG(!strcmp(got, t[i].want), "input %zu: got \"%s\", want \"%s\"", i, got,
                     t[i].want);
    }
}

/* Random tokens of the number grammar: the scanner's value is strtod's, bit
 * for bit, and the cursor ends where strtod stops. */
static void test_numbers_random(void)
{
    uint64_t st = 30;
    int bad = 0;
    for (int k = 0; k < 200000; k++) {
        char s[64];
        size_t n = 0;
        int nint = 0, nfrac = 0;
#define R() (st = st * 6364136223846793005ULL + 1442695040888963407ULL, (unsigned)(st >> 33))
        nint = (int)(R() % 20);
        for (int i = 0; i < nint; i++) s[n++] = (char)('0' + R() % 10);
        if (R() % 2 || !nint) {
            s[n++] = '.';
            nfrac = 1 + (int)(R() % 20);
            for (int i = 0; i < nfrac; i++) s[n++] = (char)('0' + R() % 10);
        }
        if (R() % 3 == 0) {
            s[n++] = R() % 2 ? 'e' : 'E';
            if (R() % 2) s[n++] = R() % 2 ? '-' : '+';
            int ne = 1 + (int)(R() % 3);
            for (int i = 0; i < ne; i++) s[n++] = (char)('0' + R() % 10);
        }
        s[n++] = '+';   /* what follows a number in an expression */
        s[n] = '\0';
        es__scan sc;
        es__scan_init(&sc, NULL, s, "test", "the end", ES__SCAN_SPACE_NONE);
        char *stop;
        double want = strtod(s, &stop), got = 0;
        size_t len = 0;
        if (es__scan_number(&sc, 0, &got, &len) != ES__SCAN_OK || memcmp(&got, &want, sizeof got) ||
            len != (size_t)(stop - s) || sc.pos != len) {
            if (bad++ < 5) ES_CHECK_MSG(0, "'%s': got %a (%zu bytes), strtod %a (%zu bytes)", s,
                                         got, len, want, (size_t)(stop - s));
        }
#undef R
    }
    ES_CHECK_MSG(bad == 0, "%d of 200000 random numbers differ from strtod", bad);
}

static void test_messages(es_ctx *ctx)
{
    es__scan sc;
    char b[8];
    es__scan_init(&sc, ctx, "ab %in% c", "formula", "the end of the formula", ES__SCAN_SPACE_C);
    ES_CHECK(!strcmp(es__scan_describe(&sc, b, sizeof b), "'a'"));
    ES_CHECK(es__scan_span(&sc, es__scan_ident_char) == 2 && sc.pos == 2);
    ES_CHECK(!es__scan_accept_lit(&sc, "%in%"));   /* a blank first */
    es__scan_skip_space(&sc);
    ES_CHECK(es__scan_accept_lit(&sc, "%in%") && sc.pos == 7);
    ES_CHECK(!es__scan_accept(&sc, 'c') && es__scan_accept(&sc, ' ') && es__scan_accept(&sc, 'c'));
    ES_CHECK(es__scan_at_end(&sc) && !es__scan_accept(&sc, '\0'));
    ES_CHECK(!strcmp(es__scan_describe(&sc, b, sizeof b), "the end of the formula"));
    ES_CHECK_FAILS(ctx, es__scan_fail(&sc, 3, "unexpected %s", "'%'"), ES_EFORMAT,
                   "formula: column 4: unexpected '%'");
    ES_CHECK(!strcmp(es_ctx_errmsg(ctx), "formula: column 4: unexpected '%'"));
    ES_CHECK_FAILS(ctx, es__scan_fail_code(&sc, ES_ENOTFOUND, 0, "no such label column"),
                   ES_ENOTFOUND, "formula: column 1: no such label column");
    /* a closing bracket after space, or the message naming both places */
    es__scan_init(&sc, ctx, "(a  ) (b,", "point", "the end of the expression",
                  ES__SCAN_SPACE_BLANKS);
    sc.pos = 2;
    ES_CHECK(es__scan_expect_close(&sc, '(', ')', 0) == ES_OK && sc.pos == 5);
    sc.pos = 8;
    ES_CHECK_FAILS(ctx, es__scan_expect_close(&sc, '(', ')', 6), ES_EFORMAT,
                   "point: column 9: expected ')' to close the '(' at column 7, found ','");
    sc.pos = 9;
    ES_CHECK_FAILS(ctx, es__scan_expect_close(&sc, '[', ']', 6), ES_EFORMAT,
                   "column 10: expected ']' to close the '[' at column 7, found the end of the "
                   "expression");
    /* a failed scan leaves the cursor; empty quotes move past them */
    es__scan_init(&sc, ctx, "\"abc", "point", "the end", ES__SCAN_SPACE_BLANKS);
    const char *w = NULL;
    size_t len = 0;
    ES_CHECK(es__scan_word(&sc, es__scan_ident_char, &w, &len) == ES__SCAN_UNTERMINATED &&
             sc.pos == 0);
    es__scan_init(&sc, ctx, "\"\"x", "point", "the end", ES__SCAN_SPACE_BLANKS);
    ES_CHECK(es__scan_word(&sc, es__scan_ident_char, &w, &len) == ES__SCAN_EMPTY && sc.pos == 2 &&
             len == 0);
    es__scan_init(&sc, ctx, "1e+x", "point", "the end", ES__SCAN_SPACE_BLANKS);
    double v = 0;
    ES_CHECK(es__scan_number(&sc, 0, &v, &len) == ES__SCAN_MALFORMED && sc.pos == 0);
    ES_CHECK(es__scan_word(&sc, es__scan_ident_char, &w, &len) == ES__SCAN_OK && len == 2);
    ES_CHECK(es__scan_word(&sc, es__scan_ident_char, &w, &len) == ES__SCAN_NONE && sc.pos == 2);
}

int main(void)
{
    es_ctx *ctx;
    ES_TEST_BEGIN();
    if (es_ctx_new(&ctx) != ES_OK) return 1;
    test_table();
    test_numbers_random();
    test_messages(ctx);
    es_ctx_free(ctx);
    ES_TEST_END();
}
