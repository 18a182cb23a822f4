/* tests/common/test_images.c — see test_images.h. */
#include "test_images.h"

#include <math.h>

const char *tp_path(const char *sub, const char *name)
{
    static char buf[8][2 * 4096 + 2]; /* room for dir + "/" + name */
    static int k;
    char dir[4096];
    k = (k + 1) % 8;
#ifdef ES_BUILD_ROOT
    snprintf(dir, sizeof dir, "%s/test-out", ES_BUILD_ROOT);
#else
    snprintf(dir, sizeof dir, "test-out");
#endif
    mkdir(dir, 0777);
    snprintf(dir + strlen(dir), sizeof dir - strlen(dir), "/%s", sub);
    mkdir(dir, 0777);
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

int tp_load(const char *path, tp_image *im)
{
    im->s = cairo_image_surface_create_from_png(path);
    if (cairo_surface_status(im->s) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(im->s);
        im->s = NULL;
        return -1;
    }
    cairo_surface_flush(im->s);
    im->w = cairo_image_surface_get_width(im->s);
    im->h = cairo_image_surface_get_height(im->s);
    im->stride = cairo_image_surface_get_stride(im->s);
    im->data = cairo_image_surface_get_data(im->s);
    return 0;
}

void tp_free(tp_image *im)
{
    if (im->s) cairo_surface_destroy(im->s);
    im->s = NULL;
}

void tp_rgb(const tp_image *im, int x, int y, double rgb[3])
{
    uint32_t p;
    memcpy(&p, im->data + (size_t)y * (size_t)im->stride + 4 * (size_t)x, 4);
    rgb[0] = ((p >> 16) & 0xff) / 255.0;
    rgb[1] = ((p >> 8) & 0xff) / 255.0;
    rgb[2] = (p & 0xff) / 255.0;
}

double tp_dist(const double a[3], const double b[3])
{
    double d = 0;
    for (int k = 0; k < 3; k++) d = fmax(d, fabs(a[k] - b[k]));
    return d;
}

long tp_file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

int tp_file_has(const char *path, const char *magic, const char *needle)
{
    static char buf[1 << 16];
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    if (n < strlen(magic) || memcmp(buf, magic, strlen(magic)) != 0) return 0;
    return !needle || strstr(buf, needle) != NULL;
}

/* Fontconfig (under cairo's text) keeps process-lifetime caches that
 * LeakSanitizer would report at exit in sanitizer builds; they are not
 * ours. Without a sanitizer this hook is never called. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig.so\n"; }
