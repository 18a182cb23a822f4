/* tests/embed/test_rotation.c — the nearest rotation lib/embed offers the
 * modules above it (embed_private.h): a scaled rotation gives the rotation
 * back (the polar factor, known in closed form), and a reflection gives a
 * proper rotation (determinant 1, computed here by cofactors).
 */
#include "embed/embed_private.h"
#include "es_test.h"

#include <math.h>

static void test_rotation(void)
{
    /* 2 x a rotation about z by 0.3: the rotation comes back */
    double c = cos(0.3), s = sin(0.3);
    double m[9] = {2 * c, -2 * s, 0, 2 * s, 2 * c, 0, 0, 0, 2};
    double r[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
    double f[9] = {1, 0, 0, 0, 1, 0, 0, 0, -1}, det;
    ES_CHECK(es__rotation_nearest(m) == 0);
    for (int i = 0; i < 9; i++) ES_CHECK_CLOSE(m[i], r[i], 0, 1e-12);
    /* a reflection: the result is a proper rotation */
    es__rotation_nearest(f);
    det = f[0] * (f[4] * f[8] - f[5] * f[7]) - f[1] * (f[3] * f[8] - f[5] * f[6]) +
          f[2] * (f[3] * f[7] - f[4] * f[6]);
    ES_CHECK_CLOSE(det, 1.0, 0, 1e-12);
}

int main(void)
{
    ES_TEST_BEGIN();
    test_rotation();
    ES_TEST_END();
}
