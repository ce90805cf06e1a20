/* test_interval.c — interval bounds: exact where they can be (the
 * analysis needs "mask is exactly 0 / exactly 1" to decide presence and
 * opacity), critical points inside the interval, NaN-capable cases full,
 * the environment's leaves, and soundness of every op on random samples. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ir.h"
#include "random_ir.h"

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

/* Float operands as intervals: the heights input carries operand 0's
 * interval, slope operand 1's, view distance operand 2's. */
static ir_iv bound(ir_op op, int n, ir_iv a, ir_iv b, ir_iv c)
{
    ir_ref args[3] = {ir_input(&g_ir, IR_IN_HEIGHT), ir_input(&g_ir, IR_IN_SLOPE),
                      ir_input(&g_ir, IR_IN_VIEW_DISTANCE)};
    ir_ienv env = {.height = a, .slope = b, .view_distance = c};
    ir_iv out[4];
    ir_interval(&g_ir, ir_opn(&g_ir, op, args, n), &env, out);
    return out[0];
}

static ir_iv I(double lo, double hi) { return (ir_iv){lo, hi}; }
static const ir_iv NONE = {0, 0};

#define assert_iv(got, lo_, hi_)                                             \
    do {                                                                     \
        ir_iv g_ = (got);                                                    \
        if (!(g_.lo == (lo_) && g_.hi == (hi_))) {                           \
            fprintf(stderr, "got [%.17g, %.17g]\n", g_.lo, g_.hi);           \
            fail();                                                          \
        }                                                                    \
    } while (0)

static bool is_full(ir_iv x) { return x.lo == -INFINITY && x.hi == INFINITY; }

static void test_monotone_exact(void **state)
{
    assert_iv(bound(IR_OP_ADD, 2, I(1, 2), I(10, 20), NONE), 11, 22);
    assert_iv(bound(IR_OP_SUB, 2, I(1, 2), I(10, 20), NONE), -19, -8);
    assert_iv(bound(IR_OP_MUL, 2, I(-1, 2), I(-3, 4), NONE), -6, 8);   /* 4 products */
    assert_iv(bound(IR_OP_DIV, 2, I(1, 2), I(4, 8), NONE), 0.125, 0.5);
    assert_iv(bound(IR_OP_NEG, 1, I(1, 2), NONE, NONE), -2, -1);
    assert_iv(bound(IR_OP_FLOOR, 1, I(-1.5, 2.5), NONE, NONE), -2, 2);
    assert_iv(bound(IR_OP_SQRT, 1, I(4, 9), NONE, NONE), 2, 3);
    assert_iv(bound(IR_OP_SATURATE, 1, I(-3, 0.5), NONE, NONE), 0, 0.5);
    assert_iv(bound(IR_OP_CLAMP, 3, I(-3, 9), I(0, 1), I(2, 4)), 0, 4);
    assert_iv(bound(IR_OP_MIN, 2, I(-3, 9), I(0, 1), NONE), -3, 1);
    assert_iv(bound(IR_OP_MAX, 2, I(-3, 9), I(0, 1), NONE), 0, 9);
}

static void test_critical_points(void **state)
{
    assert_iv(bound(IR_OP_ABS, 1, I(-2, 1), NONE, NONE), 0, 2);
    assert_iv(bound(IR_OP_ABS, 1, I(-2, -1), NONE, NONE), 1, 2);
    /* sin over [0, pi] peaks at pi/2; cos over [-1, 4] dips at pi */
    ir_iv s = bound(IR_OP_SIN, 1, I(0, M_PI), NONE, NONE);
    assert_true(s.hi == 1 && s.lo <= 0 && s.lo > -1e-15);
    ir_iv c = bound(IR_OP_COS, 1, I(-1, 4), NONE, NONE);
    assert_true(c.lo == -1 && c.hi == 1);
    ir_iv c2 = bound(IR_OP_COS, 1, I(0.5, 1), NONE, NONE);       /* monotone part */
    assert_true(c2.lo <= cos(1) && c2.lo > cos(1) - 1e-15 && c2.hi >= cos(0.5));
    assert_iv(bound(IR_OP_SIN, 1, I(-100, 100), NONE, NONE), -1, 1);
    /* fract: within one integer step it is x - n, else [0, 1] */
    assert_iv(bound(IR_OP_FRACT, 1, I(2.25, 2.75), NONE, NONE), 0.25, 0.75);
    assert_iv(bound(IR_OP_FRACT, 1, I(-0.75, -0.25), NONE, NONE), 0.25, 0.75);
    assert_iv(bound(IR_OP_FRACT, 1, I(0.5, 1.5), NONE, NONE), 0, 1);
    /* mod by a constant within one period */
    assert_iv(bound(IR_OP_MOD, 2, I(7, 7.5), I(2, 2), NONE), 1, 1.5);
    ir_iv m = bound(IR_OP_MOD, 2, I(0, 10), I(2, 3), NONE);
    assert_true(m.lo <= 0 && m.lo > -1e-12 && m.hi >= 3 && m.hi < 3 + 1e-12);
    /* pow: monotone pieces, corners */
    ir_iv p = bound(IR_OP_POW, 2, I(0.5, 2), I(-1, 2), NONE);
    assert_true(p.lo <= 0.25 && p.lo > 0.25 - 1e-15 && p.hi >= 4 && p.hi < 4 + 1e-14);
}

static void test_exact_masks(void **state)
{
    /* A ramp fully below / above its band is exactly 0 / 1, so the
     * analysis can call a material absent / opaque. */
    assert_iv(bound(IR_OP_SMOOTHSTEP, 3, I(0.5, 0.5), I(0.8, 0.8), I(0.1, 0.4)), 0, 0);
    assert_iv(bound(IR_OP_SMOOTHSTEP, 3, I(0.5, 0.5), I(0.8, 0.8), I(0.9, 3)), 1, 1);
    ir_iv h = bound(IR_OP_SMOOTHSTEP, 3, I(0, 0), I(1, 1), I(0.25, 0.5));
    assert_true(h.lo <= 0.15625 && h.lo > 0.15625 - 1e-14 && h.hi >= 0.5 && h.hi < 0.5 + 1e-14);
    assert_iv(bound(IR_OP_STEP, 2, I(0.5, 0.5), I(0.6, 0.9), NONE), 1, 1);
    assert_iv(bound(IR_OP_STEP, 2, I(0.5, 0.5), I(0.1, 0.4), NONE), 0, 0);
    assert_iv(bound(IR_OP_STEP, 2, I(0.5, 0.5), I(0.1, 0.9), NONE), 0, 1);
    assert_iv(bound(IR_OP_LESS, 2, I(0, 1), I(2, 3), NONE), 1, 1);
    assert_iv(bound(IR_OP_LESS, 2, I(2, 3), I(0, 2), NONE), 0, 0);
    /* mix of equal ends is that value whatever t is */
    assert_iv(bound(IR_OP_MIX, 3, I(1, 1), I(1, 1), I(0, 1)), 1, 1);
    assert_iv(bound(IR_OP_MIX, 3, I(0, 0), I(1, 1), I(0.25, 0.5)), 0.25, 0.5);
    /* select decided by its condition, else the union */
    assert_iv(bound(IR_OP_SELECT, 3, I(1, 2), I(5, 6), I(-1, 0)), 5, 6);
    assert_iv(bound(IR_OP_SELECT, 3, I(0, 0), I(5, 6), I(-1, 0)), -1, 0);
    assert_iv(bound(IR_OP_SELECT, 3, I(0, 1), I(5, 6), I(-1, 0)), -1, 6);
}

static void test_nan_cases_full(void **state)
{
    assert_true(is_full(bound(IR_OP_DIV, 2, I(1, 2), I(-1, 1), NONE)));
    assert_true(is_full(bound(IR_OP_SQRT, 1, I(-1, 4), NONE, NONE)));
    assert_true(is_full(bound(IR_OP_POW, 2, I(-1, 4), I(2, 2), NONE)));
    assert_true(is_full(bound(IR_OP_POW, 2, I(0, 4), I(0, 2), NONE)));
    assert_true(is_full(bound(IR_OP_MUL, 2, I(0, 1), I(1, INFINITY), NONE)));   /* 0 * inf */
    assert_true(is_full(bound(IR_OP_SIN, 1, I(0, INFINITY), NONE, NONE)));
    /* saturate turns even a possible NaN into [0, 1] (minNum/maxNum) */
    ir_ref q = ir_op2(&g_ir, IR_OP_DIV, ir_input(&g_ir, IR_IN_HEIGHT), ir_input(&g_ir, IR_IN_SLOPE));
    ir_ienv env = {.height = I(-1, 1), .slope = I(-1, 1)};
    ir_iv out[4];
    ir_interval(&g_ir, q, &env, out);
    assert_true(is_full(out[0]));
    ir_interval(&g_ir, ir_op1(&g_ir, IR_OP_SATURATE, q), &env, out);
    assert_iv(out[0], 0, 1);
    ir_interval(&g_ir, ir_op1(&g_ir, IR_OP_ABS, q), &env, out);   /* abs(NaN) = NaN */
    assert_true(is_full(out[0]));
    /* normalize of a vector that may be zero */
    ir_ienv nenv = {.normal = {I(-1, 1), I(0, 1), I(-1, 1)}};
    ir_interval(&g_ir, ir_op1(&g_ir, IR_OP_NORMALIZE, ir_input(&g_ir, IR_IN_NORMAL)), &nenv, out);
    assert_true(is_full(out[1]));
    nenv.normal[1] = I(0.5, 1);                                   /* now never zero */
    ir_interval(&g_ir, ir_op1(&g_ir, IR_OP_NORMALIZE, ir_input(&g_ir, IR_IN_NORMAL)), &nenv, out);
    assert_true(out[1].lo > 0.333 && out[1].lo <= 0.5 / sqrt(0.25 + 2) && out[1].hi >= 1 &&
                out[1].hi < 1 + 1e-14);
}

static void test_vectors(void **state)
{
    ir_ienv env = {.normal = {I(-1, 1), I(0.5, 1), I(0, 0)}};
    ir_ref n = ir_input(&g_ir, IR_IN_NORMAL);
    ir_iv out[4];
    ir_interval(&g_ir, ir_op2(&g_ir, IR_OP_DOT, n, n), &env, out);   /* squares, not products */
    assert_iv(out[0], 0.25, 2);
    ir_interval(&g_ir, ir_op1(&g_ir, IR_OP_LENGTH, n), &env, out);
    assert_iv(out[0], 0.5, sqrt(2));
    ir_interval(&g_ir, ir_swizzle(&g_ir, n, "zy"), &env, out);
    assert_iv(out[0], 0, 0);
    assert_iv(out[1], 0.5, 1);
}

static void test_leaves(void **state)
{
    ir_param free_p = {.name = "m.k", .type = IR_T_FLOAT, .def = {0.2}, .lo = -1, .hi = 3};
    ir_param fixed = {.name = "m.c", .type = IR_T_VEC2, .def = {4, 5}, .lo = 4, .hi = 4};
    int pk = ir_add_param(&g_ir, &free_p), pc = ir_add_param(&g_ir, &fixed);
    ir_texture t = {.file = "t.png", .lo = 0.25, .hi = 0.75};
    ir_ref tex = ir_texture_ref(&g_ir, ir_add_texture(&g_ir, &t));
    int m = ir_add_painted(&g_ir, "fields");
    ir_ienv env = {.uv = {I(0, 1), I(0, 1)}};
    ir_iv out[4];
    ir_interval(&g_ir, ir_param_ref(&g_ir, pk), &env, out);
    assert_iv(out[0], -1, 3);                                   /* its range */
    ir_interval(&g_ir, ir_param_ref(&g_ir, pc), &env, out);
    assert_iv(out[0], 4, 4);                                    /* fixed: the default */
    assert_iv(out[1], 5, 5);
    ir_interval(&g_ir, ir_painted_ref(&g_ir, m), &env, out);
    assert_iv(out[0], 0, 1);
    ir_interval(&g_ir, ir_op2(&g_ir, IR_OP_SAMPLE, tex, ir_input(&g_ir, IR_IN_UV)), &env, out);
    for (int c = 0; c < 4; c++)
        assert_iv(out[c], 0.25, 0.75);
    ir_iv piv[2] = {I(0.5, 0.5), I(1, 2)}, miv[1] = {I(0.125, 0.25)};
    env.params = piv;
    env.painted = miv;
    ir_interval(&g_ir, ir_param_ref(&g_ir, pk), &env, out);
    assert_iv(out[0], 0.5, 0.5);
    ir_interval(&g_ir, ir_painted_ref(&g_ir, m), &env, out);
    assert_iv(out[0], 0.125, 0.25);
    ir_interval(&g_ir, ir_constf(&g_ir, NAN), &env, out);
    assert_true(is_full(out[0]));
}

/* Every op alone, on random operand boxes: the value at random points of
 * the box lies inside the bounds. */
static void test_each_op_sound(void **state)
{
    random_ir_rng rng = {99};
    ir_ref in[3] = {ir_input(&g_ir, IR_IN_HEIGHT), ir_input(&g_ir, IR_IN_SLOPE),
                    ir_input(&g_ir, IR_IN_VIEW_DISTANCE)};
    long checks = 0;
    for (int op = IR_OP_ADD; op <= IR_OP_SELECT; op++) {
        const ir_opinfo *info = ir_opinfo_get((ir_op)op);
        ir_ref r = ir_opn(&g_ir, (ir_op)op, in, info->nargs);
        for (int b = 0; b < 2000; b++) {
            ir_ienv box = {0};
            ir_iv *iv[3] = {&box.height, &box.slope, &box.view_distance};
            double scale = b % 3 == 0 ? 1 : b % 3 == 1 ? 10 : 1e6;
            for (int i = 0; i < 3; i++)
                *iv[i] = random_ir_subrange(&rng, -scale, scale);
            ir_iv out[4];
            ir_interval(&g_ir, r, &box, out);
            for (int p = 0; p < 50; p++) {
                ir_env env = {.height = random_ir_in(&rng, box.height),
                              .slope = random_ir_in(&rng, box.slope),
                              .view_distance = random_ir_in(&rng, box.view_distance)};
                double v[4];
                ir_eval(&g_ir, r, &env, v);
                bool ok = isnan(v[0]) ? is_full(out[0]) : out[0].lo <= v[0] && v[0] <= out[0].hi;
                if (!ok) {
                    fprintf(stderr, "%s(%.17g, %.17g, %.17g) = %.17g outside [%.17g, %.17g]\n",
                            info->name, env.height, env.slope, env.view_distance, v[0],
                            out[0].lo, out[0].hi);
                    fail();
                }
                checks++;
            }
        }
    }
    assert_true(checks > 1000000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_monotone_exact, setup, teardown),
        cmocka_unit_test_setup_teardown(test_critical_points, setup, teardown),
        cmocka_unit_test_setup_teardown(test_exact_masks, setup, teardown),
        cmocka_unit_test_setup_teardown(test_nan_cases_full, setup, teardown),
        cmocka_unit_test_setup_teardown(test_vectors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_leaves, setup, teardown),
        cmocka_unit_test_setup_teardown(test_each_op_sound, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
