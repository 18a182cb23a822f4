/* tests/common/test_images.h — helpers for the plot and render tests: an output
 * directory under the build tree, PNG read-back through cairo, pixel
 * access, file checks. */
#ifndef EDGESPACE_TESTS_TEST_IMAGES_H
#define EDGESPACE_TESTS_TEST_IMAGES_H

#include <cairo.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* $ES_BUILD_ROOT/test-out/<sub>/<name>, directories created. */
const char *tp_path(const char *sub, const char *name);

typedef struct tp_image {
    cairo_surface_t *s;
    int w, h, stride;
    const unsigned char *data;
} tp_image;

int tp_load(const char *path, tp_image *im);

void tp_free(tp_image *im);

/* RGB in [0, 1] of pixel (x, y) (opaque images). */
void tp_rgb(const tp_image *im, int x, int y, double rgb[3]);

double tp_dist(const double a[3], const double b[3]);

long tp_file_size(const char *path);

/* The file starts with `magic` and contains `needle` (NULL: any). */
int tp_file_has(const char *path, const char *magic, const char *needle);

/* Fontconfig (under cairo's toy text API) keeps process-lifetime caches
 * that LeakSanitizer reports at exit even after
 * cairo_debug_reset_static_data(); they are not ours. */

#endif
