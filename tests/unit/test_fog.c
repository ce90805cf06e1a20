/* test_fog.c — the default fog density (runtime/light.c,
 * rt_light_fog_default): 0.375 / D, D the farthest camera preset's
 * distance to its look point and at least a quarter of the terrain's
 * larger side, so that the fog hides 31 % of the colour at D. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "rt_internal.h"   /* builds an rt_pack by hand: its camera presets and size */

/* A camera `d` metres from its look point, along (3, 4, 12) / 13. */
static rt_pack_camera cam_at(double d)
{
    rt_pack_camera c = { .name = "c", .look = { 100, 50, 200 } };
    const double dir[3] = { 3.0 / 13, 4.0 / 13, 12.0 / 13 };
    for (int k = 0; k < 3; k++)
        c.position[k] = c.look[k] + d * dir[k];
    return c;
}

/* the share of the colour the fog hides at distance d */
static double hidden(double density, double d) { return 1.0 - exp(-density * d); }

static void test_no_presets(void **state)
{
    rt_pack p;
    memset(&p, 0, sizeof p);
    p.size[0] = 1024, p.size[1] = 600;
    /* the old default, 1.5 / extent: the default camera stands a quarter
     * of the extent away */
    assert_true(fabs(rt_light_fog_default(&p) - 1.5 / 1024) < 1e-12);
}

static void test_farthest_preset(void **state)
{
    rt_pack p;
    memset(&p, 0, sizeof p);
    p.size[0] = p.size[1] = 1024;
    rt_pack_camera cams[3] = { cam_at(500), cam_at(1400), cam_at(900) };
    p.cameras = cams, p.ncameras = 3;
    double f = rt_light_fog_default(&p);
    assert_true(fabs(f - 0.375 / 1400) < 1e-12);
    /* 31 % of the colour hidden at the farthest camera's look point, less
     * for the nearer cameras, and far less than the old 1.5 / extent
     * (which hid 87 % at 1400 m) */
    assert_true(fabs(hidden(f, 1400) - 0.3127) < 1e-3);
    assert_true(hidden(f, 500) < 0.13);
    assert_true(hidden(1.5 / 1024, 1400) > 0.85);
    /* the order of the presets does not matter */
    rt_pack_camera swapped[3] = { cams[1], cams[2], cams[0] };
    p.cameras = swapped;
    assert_true(rt_light_fog_default(&p) == f);
}

static void test_large_terrain(void **state)
{
    /* colorado's scale: 176 km, the overview 83 km from its look point */
    rt_pack p;
    memset(&p, 0, sizeof p);
    p.size[0] = 176473.5, p.size[1] = 111212.6;
    rt_pack_camera cams[2] = { cam_at(83000), cam_at(4600) };
    p.cameras = cams, p.ncameras = 2;
    assert_true(fabs(rt_light_fog_default(&p) - 0.375 / 83000) < 1e-15);
}

static void test_near_presets_only(void **state)
{
    /* presets that look at points close by (a ground camera 40 m from
     * its look point) never make the fog denser than 1.5 / extent */
    rt_pack p;
    memset(&p, 0, sizeof p);
    p.size[0] = p.size[1] = 4096;
    rt_pack_camera cams[1] = { cam_at(40) };
    p.cameras = cams, p.ncameras = 1;
    assert_true(fabs(rt_light_fog_default(&p) - 1.5 / 4096) < 1e-12);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_presets),
        cmocka_unit_test(test_farthest_preset),
        cmocka_unit_test(test_large_terrain),
        cmocka_unit_test(test_near_presets_only),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
