/* tests/common/test_files.c — see es_test_files.h. */
#include "es_test_files.h"

const char *es_test_tmpdir(const char *name)
{
    static char buf[4096];
    char base[4000];
#ifdef ES_BUILD_ROOT
    snprintf(base, sizeof base, "%s/test-tmp", ES_BUILD_ROOT);
#else
    snprintf(base, sizeof base, "/tmp");
#endif
    mkdir(base, 0777);
    snprintf(buf, sizeof buf, "%s/%s-XXXXXX", base, name);
    if (!mkdtemp(buf)) {
        perror("mkdtemp");
        exit(1);
    }
    return buf;
}

char *es_test_slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long len;
    *n = 0;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (buf = malloc((size_t)len + 1)) && fread(buf, 1, (size_t)len, f) == (size_t)len) {
        buf[len] = '\0';
        *n = (size_t)len;
    } else {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    return buf;
}

int es_test_same_bytes(const char *path, const char *buf, size_t n)
{
    size_t m;
    char *now = es_test_slurp(path, &m);
    int same = now && m == n && memcmp(now, buf, n) == 0;
    free(now);
    return same;
}

void es_test_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        perror(path);
        exit(1);
    }
}

int es_test_count_entries(const char *dir, const char *needle)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    if (!d) return -1;
    while ((e = readdir(d)))
        if (strstr(e->d_name, needle)) n++;
    closedir(d);
    return n;
}
