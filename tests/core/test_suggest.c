/* tests/core/test_suggest.c — "did you mean": es__edit_distance against a
 * plain dynamic-programming reference on random and similar names (case
 * folded, the limit respected), and es__suggest: the closest three in
 * order, repeats ignored, the first few names listed when none is close,
 * nothing without candidates, and a bounded, terminated message. */
#include "core/suggest.h"
#include "es_test.h"

#include <ctype.h>

/* Levenshtein distance, the textbook table (case folded). */
static size_t reference(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b), d[40][40];
    for (size_t i = 0; i <= na; i++) d[i][0] = i;
    for (size_t j = 0; j <= nb; j++) d[0][j] = j;
    for (size_t i = 1; i <= na; i++)
        for (size_t j = 1; j <= nb; j++) {
            size_t sub = d[i - 1][j - 1] + (tolower((unsigned char)a[i - 1]) !=
                                            tolower((unsigned char)b[j - 1]));
            size_t del = d[i - 1][j] + 1, ins = d[i][j - 1] + 1;
            d[i][j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
        }
    return d[na][nb];
}

int main(void)
{
    ES_TEST_BEGIN();
    /* known distances */
    ES_CHECK(es__edit_distance("expresion", "expression", 5) == 1);
    ES_CHECK(es__edit_distance("Group", "group", 5) == 0);
    ES_CHECK(es__edit_distance("kitten", "sitting", 5) == 3);
    ES_CHECK(es__edit_distance("", "abc", 5) == 3);
    ES_CHECK(es__edit_distance("kitten", "sitting", 2) == 3);   /* limit + 1 */
    /* random names over a small alphabet (many near misses) */
    uint64_t st = 12345;
    for (int t = 0; t < 20000; t++) {
        char a[16], b[16];
        int na, nb;
        st = st * 6364136223846793005u + 1442695040888963407u;
        na = (int)(st >> 60) % 12;
        nb = (int)((st >> 55) & 15) % 12;
        for (int i = 0; i < na; i++) {
            st = st * 6364136223846793005u + 1442695040888963407u;
            a[i] = "abcAB"[(st >> 33) % 5];
        }
        for (int i = 0; i < nb; i++) {
            st = st * 6364136223846793005u + 1442695040888963407u;
            b[i] = "abcAB"[(st >> 33) % 5];
        }
        a[na] = b[nb] = '\0';
        size_t want = reference(a, b), limit = (size_t)(t % 7);
        size_t got = es__edit_distance(a, b, limit);
        ES_CHECK_MSG(want <= limit ? got == want : got == limit + 1,
                     "'%s' '%s' limit %zu: got %zu, want %zu", a, b, limit, got, want);
    }
    /* names longer than 255 bytes are never close */
    {
        char longname[300];
        memset(longname, 'x', 299);
        longname[299] = '\0';
        ES_CHECK(es__edit_distance(longname, longname, 3) == 4);
    }

    char buf[400];
    es__suggest sg;
    /* the closest first, at most three, repeats once */
    static const char *const cols[] = {"file", "subject", "expression", "expresion_2", "express",
                                       "expression", "id"};
    es__suggest_init(&sg, "expresion");
    for (size_t i = 0; i < sizeof cols / sizeof cols[0]; i++) es__suggest_add(&sg, cols[i]);
    es__suggest_format(&sg, "columns", buf, sizeof buf);
    ES_CHECK_MSG(!strcmp(buf, " (did you mean 'expression', 'expresion_2' or 'express'?)"),
                 "%s", buf);
    /* nothing close: the first names that exist */
    es__suggest_init(&sg, "zzzzzzzz");
    for (size_t i = 0; i < sizeof cols / sizeof cols[0]; i++) es__suggest_add(&sg, cols[i]);
    es__suggest_format(&sg, "columns", buf, sizeof buf);
    ES_CHECK_MSG(!strcmp(buf, " (columns: file, subject, expression, expresion_2, express, id)"),
                 "%s", buf);
    /* more than six: an ellipsis */
    es__suggest_init(&sg, "zzzzzzzz");
    static const char *const seven[] = {"a1", "a2", "a3", "a4", "a5", "a6", "a7"};
    for (int i = 0; i < 7; i++) es__suggest_add(&sg, seven[i]);
    es__suggest_format(&sg, "values", buf, sizeof buf);
    ES_CHECK_MSG(!strcmp(buf, " (values: a1, a2, a3, a4, a5, a6, ...)"), "%s", buf);
    /* no candidates: nothing to say */
    es__suggest_init(&sg, "x");
    es__suggest_format(&sg, "columns", buf, sizeof buf);
    ES_CHECK(buf[0] == '\0');
    /* a short buffer: terminated, marked as cut */
    es__suggest_init(&sg, "expresion");
    for (size_t i = 0; i < sizeof cols / sizeof cols[0]; i++) es__suggest_add(&sg, cols[i]);
    es__suggest_format(&sg, "columns", buf, 20);
    ES_CHECK_MSG(strlen(buf) == 19 && !strcmp(buf + 15, "...)"), "%s", buf);
    ES_TEST_END();
}
