/* test_far_atlas.c — the far atlas's pieces that do not need a scene
 * (the bake itself and the runtime are tests/far/far.sh's):
 *   - the reference's sample_grad hook (ir.h): after ir_differentiate, a
 *     SAMPLE_GRAD hands the hook its uv and the uv's screen derivatives,
 *     which are the DINPUT leaves' values pushed through the uv
 *     expression (here uv * 8: gradients 8 x the uv step), and a plain
 *     `sample` hook still serves SAMPLE;
 *   - the file layout (far_atlas.h): level count and byte sizes for sides
 *     that are and are not multiples of 4, down to 1 x 1.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "far_atlas.h"
#include "ir.h"

typedef struct seen {
    int    calls;
    double uv[2], dx[2], dy[2];
} seen;

static void grad_hook(void *user, int texture, const double uv[2], const double dx[2],
                      const double dy[2], double rgba[4])
{
    seen *s = user;
    (void)texture;
    s->calls++;
    memcpy(s->uv, uv, sizeof s->uv);
    memcpy(s->dx, dx, sizeof s->dx);
    memcpy(s->dy, dy, sizeof s->dy);
    rgba[0] = 0.25;   /* a value the default texture never reads */
    rgba[1] = rgba[2] = 0.0;
    rgba[3] = 1.0;
}

static void plain_hook(void *user, int texture, double u, double v, double rgba[4])
{
    (void)user, (void)texture, (void)u, (void)v;
    rgba[0] = rgba[1] = rgba[2] = 0.75;
    rgba[3] = 1.0;
}

static void test_sample_grad_hook(void **state)
{
    (void)state;
    ir g;
    ir_init(&g);
    ir_texture t = {.file = "x.png", .lo = 0, .hi = 1};
    int ti = ir_add_texture(&g, &t);
    ir_ref uv = ir_op2(&g, IR_OP_MUL, ir_input(&g, IR_IN_UV),
                      ir_splat(&g, ir_constf(&g, 8.0), IR_T_VEC2));
    ir_ref s = ir_op2(&g, IR_OP_SAMPLE, ir_texture_ref(&g, ti), uv);
    ir_set_root(&g, "out", ir_swizzle(&g, s, "r"));

    seen got = {0};
    ir_env env = {.uv = {0.125, 0.5}, .sample_grad = grad_hook, .sample_user = &got,
                  .sample = plain_hook};
    env.d_input[0][IR_IN_UV][0] = 1.0 / 64;
    env.d_input[1][IR_IN_UV][1] = 1.0 / 32;
    double v[4];
    /* before the pass: SAMPLE goes to the plain hook */
    ir_eval(&g, ir_find_root(&g, "out"), &env, v);
    assert_int_equal(got.calls, 0);
    assert_true(v[0] == 0.75);

    assert_true(ir_differentiate(&g));
    ir_optimize(&g, NULL);
    ir_eval(&g, ir_find_root(&g, "out"), &env, v);
    assert_int_equal(got.calls, 1);
    assert_true(v[0] == 0.25);
    assert_true(fabs(got.uv[0] - 1.0) < 1e-12 && fabs(got.uv[1] - 4.0) < 1e-12);
    assert_true(fabs(got.dx[0] - 8.0 / 64) < 1e-12 && fabs(got.dx[1]) < 1e-12);
    assert_true(fabs(got.dy[0]) < 1e-12 && fabs(got.dy[1] - 8.0 / 32) < 1e-12);

    /* without the hook the reference samples as before (level 0) */
    env.sample_grad = NULL;
    ir_eval(&g, ir_find_root(&g, "out"), &env, v);
    assert_true(v[0] == 0.75);
    ir_free(&g);
}

static void test_layout(void **state)
{
    (void)state;
    assert_int_equal(far_atlas_levels_max(1, 1), 1);
    assert_int_equal(far_atlas_levels_max(601, 301), 10);     /* 601 -> 1 in 9 halvings */
    assert_int_equal(far_atlas_levels_max(2401, 1201), 12);
    /* level 0 of 601 x 301: 151 x 76 blocks of 8 + 16 + 8 bytes */
    assert_true(far_atlas_level_bytes(601, 301, 0) == 151ull * 76 * 32);
    /* the last levels are one block each */
    assert_true(far_atlas_level_bytes(601, 301, 9) == 32);
    assert_true(far_atlas_level_bytes(4, 4, 0) == 32);
    assert_true(far_atlas_level_bytes(5, 4, 0) == 64);
    uint64_t n = FAR_ATLAS_HEADER;
    for (int l = 0; l < 10; l++)
        n += far_atlas_level_bytes(601, 301, l);
    assert_true(far_atlas_file_bytes(601, 301, 10) == n);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sample_grad_hook),
        cmocka_unit_test(test_layout),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
