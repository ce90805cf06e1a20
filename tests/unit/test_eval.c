/* test_eval.c — the double-precision reference against hand-computed
 * values, GLSL's semantics at the edges, the environment, memoisation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ir.h"

static ir g_ir;

static int setup(void **state)
{
    ir_init(&g_ir);
    return 0;
}

static int teardown(void **state)
{
    ir_free(&g_ir);
    return 0;
}

static ir_ref K(double v) { return ir_constf(&g_ir, v); }

static double ev(ir_ref r)
{
    double v[4];
    ir_eval(&g_ir, r, NULL, v);
    return v[0];
}

static double op1(ir_op op, double a) { return ev(ir_op1(&g_ir, op, K(a))); }
static double op2(ir_op op, double a, double b) { return ev(ir_op2(&g_ir, op, K(a), K(b))); }
static double op3(ir_op op, double a, double b, double c)
{
    return ev(ir_op3(&g_ir, op, K(a), K(b), K(c)));
}

static void test_arithmetic(void **state)
{
    assert_true(op2(IR_OP_ADD, 1.5, 2.25) == 3.75);
    assert_true(op2(IR_OP_SUB, 1.5, 2.25) == -0.75);
    assert_true(op2(IR_OP_MUL, -1.5, 4) == -6);
    assert_true(op2(IR_OP_DIV, 1, 8) == 0.125);
    assert_true(isinf(op2(IR_OP_DIV, 1, 0)));
    assert_true(op1(IR_OP_NEG, 2) == -2);
    assert_true(op2(IR_OP_MIN, 3, -1) == -1);
    assert_true(op2(IR_OP_MAX, 3, -1) == 3);
    assert_true(op1(IR_OP_ABS, -2.5) == 2.5);
    assert_true(op1(IR_OP_FLOOR, -1.25) == -2);
    assert_true(op1(IR_OP_SQRT, 6.25) == 2.5);
    assert_true(isnan(op1(IR_OP_SQRT, -1)));
    assert_true(op1(IR_OP_EXP2, -3) == 0.125);
    assert_true(op1(IR_OP_SIN, 0) == 0);
    assert_true(op1(IR_OP_COS, 0) == 1);
}

static void test_glsl_semantics(void **state)
{
    /* fract(x) = x - floor(x); mod(x, y) = x - y * floor(x / y) */
    assert_true(op1(IR_OP_FRACT, -1.25) == 0.75);
    assert_true(op1(IR_OP_FRACT, 2.5) == 0.5);
    assert_true(op2(IR_OP_MOD, -1, 3) == 2);
    assert_true(op2(IR_OP_MOD, 7.5, 2) == 1.5);
    assert_true(op2(IR_OP_MOD, 1, -3) == -2);
    /* pow: undefined (NaN) for x < 0 and for x = 0, y <= 0 */
    assert_true(op2(IR_OP_POW, 2, 3) == 8);
    assert_true(op2(IR_OP_POW, 0, 2) == 0);
    assert_true(isnan(op2(IR_OP_POW, -2, 2)));
    assert_true(isnan(op2(IR_OP_POW, 0, 0)));
    assert_true(isnan(op2(IR_OP_POW, 0, -1)));
    /* mix, clamp, saturate */
    assert_true(op3(IR_OP_MIX, 2, 4, 0.25) == 2.5);
    assert_true(op3(IR_OP_MIX, 2, 4, 1.5) == 5);                /* extrapolates */
    assert_true(op3(IR_OP_CLAMP, 5, 0, 2) == 2);
    assert_true(op3(IR_OP_CLAMP, -5, 0, 2) == 0);
    assert_true(op1(IR_OP_SATURATE, 1.5) == 1);
    assert_true(op1(IR_OP_SATURATE, -0.5) == 0);
    assert_true(op1(IR_OP_SATURATE, NAN) == 0);                  /* minNum/maxNum */
    /* step(edge, x) = x < edge ? 0 : 1 */
    assert_true(op2(IR_OP_STEP, 0.5, 0.25) == 0);
    assert_true(op2(IR_OP_STEP, 0.5, 0.5) == 1);
    /* smoothstep: Hermite t*t*(3-2t) of the clamped ramp */
    assert_true(op3(IR_OP_SMOOTHSTEP, 0, 1, 0.25) == 0.15625);
    assert_true(op3(IR_OP_SMOOTHSTEP, 10, 20, 17.5) == 0.84375);
    assert_true(op3(IR_OP_SMOOTHSTEP, 0, 1, -3) == 0);
    assert_true(op3(IR_OP_SMOOTHSTEP, 0, 1, 3) == 1);
    /* less and select */
    assert_true(op2(IR_OP_LESS, 1, 2) == 1);
    assert_true(op2(IR_OP_LESS, 2, 2) == 0);
    assert_true(op2(IR_OP_LESS, NAN, 2) == 0);
    assert_true(op3(IR_OP_SELECT, 0, 7, 9) == 9);
    assert_true(op3(IR_OP_SELECT, -0.0, 7, 9) == 9);
    assert_true(op3(IR_OP_SELECT, 0.1, 7, 9) == 7);
    assert_true(op3(IR_OP_SELECT, NAN, 7, 9) == 7);              /* NaN != 0 */
}

static void test_vectors(void **state)
{
    double a[3] = {1, 2, 3}, b[3] = {4, -5, 6}, z[3] = {0, 0, 0}, v[4];
    ir_ref va = ir_const(&g_ir, IR_T_VEC3, a), vb = ir_const(&g_ir, IR_T_VEC3, b);
    assert_true(ev(ir_op2(&g_ir, IR_OP_DOT, va, vb)) == 4 - 10 + 18);
    double c2[2] = {3, 4};
    ir_ref v2 = ir_const(&g_ir, IR_T_VEC2, c2);
    assert_true(ev(ir_op1(&g_ir, IR_OP_LENGTH, v2)) == 5);
    ir_eval(&g_ir, ir_op1(&g_ir, IR_OP_NORMALIZE, v2), NULL, v);
    assert_true(v[0] == 0.6 && v[1] == 0.8);
    ir_eval(&g_ir, ir_op1(&g_ir, IR_OP_NORMALIZE, ir_const(&g_ir, IR_T_VEC3, z)), NULL, v);
    assert_true(isnan(v[0]) && isnan(v[1]) && isnan(v[2]));     /* 0/0 */
    ir_eval(&g_ir, ir_op2(&g_ir, IR_OP_CROSS, va, vb), NULL, v);
    assert_true(v[0] == 2 * 6 - 3 * -5 && v[1] == 3 * 4 - 1 * 6 && v[2] == 1 * -5 - 2 * 4);
    /* componentwise on vectors */
    ir_eval(&g_ir, ir_op2(&g_ir, IR_OP_MUL, va, vb), NULL, v);
    assert_true(v[0] == 4 && v[1] == -10 && v[2] == 18);
    /* shapes */
    ir_eval(&g_ir, ir_swizzle(&g_ir, vb, "zxx"), NULL, v);
    assert_true(v[0] == 6 && v[1] == 4 && v[2] == 4);
    ir_eval(&g_ir, ir_splat(&g_ir, K(0.5), IR_T_VEC4), NULL, v);
    assert_true(v[0] == 0.5 && v[3] == 0.5);
    ir_ref parts[2] = {v2, K(9)};
    ir_eval(&g_ir, ir_construct(&g_ir, IR_T_VEC3, parts, 2), NULL, v);
    assert_true(v[0] == 3 && v[1] == 4 && v[2] == 9);
}

static void sampler(void *user, int texture, double u, double v, double rgba[4])
{
    int *calls = user;
    (*calls)++;
    rgba[0] = u;
    rgba[1] = v;
    rgba[2] = texture;
    rgba[3] = 0.25;
}

static void test_environment(void **state)
{
    ir_param p = {.name = "m.tint", .type = IR_T_VEC3, .def = {0.1, 0.2, 0.3}, .lo = 0, .hi = 1};
    int pi = ir_add_param(&g_ir, &p);
    ir_ref tint = ir_param_ref(&g_ir, pi);
    ir_texture t = {.file = "x.png", .lo = 0, .hi = 1};
    ir_add_texture(&g_ir, &t);
    int ti = ir_add_texture(&g_ir, &t);
    int mi = ir_add_painted(&g_ir, "fields");
    ir_ref smp = ir_op2(&g_ir, IR_OP_SAMPLE, ir_texture_ref(&g_ir, ti), ir_input(&g_ir, IR_IN_UV));
    double v[4];

    /* defaults: params' def, painted 0, textures (0.5, 0.5, 0.5, 1) */
    ir_env env = {.height = 12, .slope = 0.25, .normal = {0, 1, 0}, .position = {1, 2, 3},
                  .uv = {0.125, 0.75}, .view_distance = 40, .destruction = 0.5};
    ir_eval(&g_ir, tint, &env, v);
    assert_true(v[0] == 0.1 && v[1] == 0.2 && v[2] == 0.3);
    ir_eval(&g_ir, ir_painted_ref(&g_ir, mi), &env, v);
    assert_true(v[0] == 0);
    ir_eval(&g_ir, smp, &env, v);
    assert_true(v[0] == 0.5 && v[1] == 0.5 && v[2] == 0.5 && v[3] == 1);

    double pv[4] = {0.7, 0.8, 0.9, 0}, mv[1] = {0.625};
    int calls = 0;
    env.params = pv;
    env.painted = mv;
    env.sample = sampler;
    env.sample_user = &calls;
    ir_eval(&g_ir, tint, &env, v);
    assert_true(v[0] == 0.7 && v[2] == 0.9);
    ir_eval(&g_ir, ir_painted_ref(&g_ir, mi), &env, v);
    assert_true(v[0] == 0.625);
    ir_eval(&g_ir, smp, &env, v);
    assert_true(v[0] == 0.125 && v[1] == 0.75 && v[2] == ti && v[3] == 0.25);
    assert_int_equal(calls, 1);

    static const struct { ir_input_kind in; double want; } ins[] = {
        {IR_IN_HEIGHT, 12}, {IR_IN_SLOPE, 0.25}, {IR_IN_VIEW_DISTANCE, 40},
        {IR_IN_DESTRUCTION, 0.5}};
    for (int i = 0; i < 4; i++) {
        ir_eval(&g_ir, ir_input(&g_ir, ins[i].in), &env, v);
        assert_true(v[0] == ins[i].want);
    }
    ir_eval(&g_ir, ir_input(&g_ir, IR_IN_POSITION), &env, v);
    assert_true(v[0] == 1 && v[1] == 2 && v[2] == 3);
    ir_eval(&g_ir, ir_input(&g_ir, IR_IN_NORMAL), &env, v);
    assert_true(v[1] == 1);
}

/* x_{i+1} = x_i + sample(x_i): 2^60 paths; only memoisation makes it
 * finish, and the sampler runs once per SAMPLE node. */
static void test_memoised(void **state)
{
    ir_texture t = {.file = "x.png", .lo = 0, .hi = 1};
    ir_ref tex = ir_texture_ref(&g_ir, ir_add_texture(&g_ir, &t));
    ir_ref x = ir_input(&g_ir, IR_IN_UV);
    for (int i = 0; i < 60; i++) {
        ir_ref s = ir_swizzle(&g_ir, ir_op2(&g_ir, IR_OP_SAMPLE, tex, x), "xy");
        x = ir_op2(&g_ir, IR_OP_MUL, ir_op2(&g_ir, IR_OP_ADD, x, s), ir_op2(&g_ir, IR_OP_SUB, x, s));
    }
    int calls = 0;
    ir_env env = {.uv = {0.5, 0.5}, .sample = sampler, .sample_user = &calls};
    double v[4];
    ir_eval(&g_ir, x, &env, v);
    assert_int_equal(calls, 60);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_arithmetic, setup, teardown),
        cmocka_unit_test_setup_teardown(test_glsl_semantics, setup, teardown),
        cmocka_unit_test_setup_teardown(test_vectors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_environment, setup, teardown),
        cmocka_unit_test_setup_teardown(test_memoised, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
