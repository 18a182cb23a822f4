/* tests/common/es_test.c — see es_test.h. */
#include "es_test.h"
#include <math.h>

#include <sys/stat.h>

int es_test_failures;

int es_test_contains(const char *s, const char *needle)
{
    return !needle || strstr(s, needle) != NULL;
}

const char *es_test_shared_data(void)
{
    static char buf[4096];
    const char *root = getenv("EDGESPACE_SHARED");
    struct stat st;
#ifdef ES_SHARED_DIR
    if (!root) root = ES_SHARED_DIR;
#endif
    if (!root) return NULL;
    snprintf(buf, sizeof buf, "%s/data", root);
    return stat(buf, &st) == 0 && S_ISDIR(st.st_mode) ? buf : NULL;
}

const char *es_test_shared_path(const char *sub, char *buf, size_t n)
{
    const char *data = es_test_shared_data();
    struct stat st;
    if (!data) return NULL;
    snprintf(buf, n, "%s/../%s", data, sub);
    return stat(buf, &st) == 0 ? buf : NULL;
}

double es_test_maxdiff(const double *a, const double *b, int64_t n)
{
    double m = 0;
    for (int64_t i = 0; i < n; i++) m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

double es_test_maxabs(const double *a, int64_t n)
{
    double m = 0;
    for (int64_t i = 0; i < n; i++) m = fmax(m, fabs(a[i]));
    return m;
}
