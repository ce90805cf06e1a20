/* test_passes.c — each pass on IR built with the builder: it makes
 * progress where it should, reports none on a second run, and leaves
 * valid IR whose values are unchanged. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ir.h"

static double value(const ir *ir, const char *root)
{
    double v[4];
    ir_env env = {.height = 120, .slope = 0.3, .normal = {0, 1, 0}, .uv = {0.25, 0.5}};
    ir_eval(ir, ir_find_root(ir, root), &env, v);
    return v[0];
}

static const ir_node *root_node(const ir *ir, const char *root)
{
    return ir_get(ir, ir_find_root(ir, root));
}

static void test_fold_constants(void **state)
{
    ir ir;
    ir_init(&ir);
    /* (2 + 0.5) * smoothstep(0, 4, 1) -> 2.5 * 0.15625 */
    ir_ref k = ir_op2(&ir, IR_OP_MUL, ir_op2(&ir, IR_OP_ADD, ir_constf(&ir, 2), ir_constf(&ir, 0.5)),
                      ir_op3(&ir, IR_OP_SMOOTHSTEP, ir_constf(&ir, 0), ir_constf(&ir, 4),
                             ir_constf(&ir, 1)));
    ir_set_root(&ir, "k", k);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT);
    ir_set_root(&ir, "h", ir_op2(&ir, IR_OP_ADD, h, ir_op1(&ir, IR_OP_SQRT, ir_constf(&ir, 16))));
    double before = value(&ir, "h");
    assert_true(opt_fold(&ir));
    assert_true(ir_validate(&ir, stderr));
    assert_int_equal(root_node(&ir, "k")->op, IR_OP_CONST);
    assert_true(root_node(&ir, "k")->val[0] == 2.5 * 0.15625);
    assert_int_equal(root_node(&ir, "h")->op, IR_OP_ADD);
    assert_true(value(&ir, "h") == before);
    assert_false(opt_fold(&ir));                 /* fixed point */
    ir_free(&ir);
}

static void test_fold_keeps_non_finite(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_set_root(&ir, "inf", ir_op2(&ir, IR_OP_DIV, ir_constf(&ir, 1), ir_constf(&ir, 0)));
    ir_set_root(&ir, "nan", ir_op1(&ir, IR_OP_SQRT, ir_constf(&ir, -1)));
    assert_false(opt_fold(&ir));
    assert_int_equal(root_node(&ir, "inf")->op, IR_OP_DIV);
    assert_int_equal(root_node(&ir, "nan")->op, IR_OP_SQRT);
    ir_free(&ir);
}

static void test_fold_identities(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT), s = ir_input(&ir, IR_IN_SLOPE);
    ir_ref zero = ir_constf(&ir, 0), one = ir_constf(&ir, 1);
    ir_set_root(&ir, "mul1", ir_op2(&ir, IR_OP_MUL, h, one));
    ir_set_root(&ir, "add0", ir_op2(&ir, IR_OP_ADD, zero, s));
    ir_set_root(&ir, "sub0", ir_op2(&ir, IR_OP_SUB, s, zero));
    ir_set_root(&ir, "div1", ir_op2(&ir, IR_OP_DIV, h, one));
    ir_set_root(&ir, "minxx", ir_op2(&ir, IR_OP_MIN, h, h));
    ir_set_root(&ir, "negneg", ir_op1(&ir, IR_OP_NEG, ir_op1(&ir, IR_OP_NEG, h)));
    ir_ref sat = ir_op1(&ir, IR_OP_SATURATE, h);
    ir_set_root(&ir, "satsat", ir_op1(&ir, IR_OP_SATURATE, sat));
    /* x * 0: gone where x is finite (an input), kept where x may be inf */
    ir_set_root(&ir, "mul0_finite", ir_op2(&ir, IR_OP_MUL, s, zero));
    ir_set_root(&ir, "mul0_maybe_inf",
                ir_op2(&ir, IR_OP_MUL, ir_op2(&ir, IR_OP_DIV, one, s), zero));
    ir_set_root(&ir, "select", ir_op3(&ir, IR_OP_SELECT, one, h, s));
    assert_true(opt_fold(&ir));
    assert_true(ir_validate(&ir, stderr));
    const char *to_h[] = {"mul1", "div1", "minxx", "negneg", "select"};
    for (int i = 0; i < 5; i++)
        assert_int_equal(root_node(&ir, to_h[i])->op, IR_OP_INPUT);
    assert_int_equal(root_node(&ir, "add0")->imm, IR_IN_SLOPE);
    assert_int_equal(root_node(&ir, "sub0")->imm, IR_IN_SLOPE);
    assert_int_equal(root_node(&ir, "satsat")->op, IR_OP_SATURATE);
    assert_int_equal(ir_get(&ir, root_node(&ir, "satsat")->arg[0])->op, IR_OP_INPUT);
    assert_int_equal(root_node(&ir, "mul0_finite")->op, IR_OP_CONST);
    assert_int_equal(root_node(&ir, "mul0_maybe_inf")->op, IR_OP_MUL);
    assert_false(opt_fold(&ir));
    ir_free(&ir);
}

static void test_fold_shapes(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT), s = ir_input(&ir, IR_IN_SLOPE);
    ir_ref args[3] = {h, s, ir_constf(&ir, 7)};
    ir_ref v = ir_construct(&ir, IR_T_VEC3, args, 3);
    ir_set_root(&ir, "pick", ir_swizzle(&ir, v, "y"));           /* -> slope */
    ir_set_root(&ir, "zx", ir_swizzle(&ir, v, "zx"));             /* -> vec2(7, h) */
    ir_set_root(&ir, "splatc", ir_splat(&ir, ir_constf(&ir, 0.5), IR_T_VEC3));
    ir_ref n = ir_input(&ir, IR_IN_NORMAL);
    ir_set_root(&ir, "swzswz", ir_swizzle(&ir, ir_swizzle(&ir, n, "zyx"), "xy")); /* n.zy */
    ir_set_root(&ir, "swzsplat", ir_swizzle(&ir, ir_splat(&ir, h, IR_T_VEC4), "xy"));
    assert_true(opt_fold(&ir));
    assert_true(ir_validate(&ir, stderr));
    assert_int_equal(root_node(&ir, "pick")->op, IR_OP_INPUT);
    assert_int_equal(root_node(&ir, "pick")->imm, IR_IN_SLOPE);
    const ir_node *zx = root_node(&ir, "zx");
    assert_int_equal(zx->op, IR_OP_CONSTRUCT);
    assert_int_equal(ir_get(&ir, zx->arg[0])->op, IR_OP_CONST);
    assert_int_equal(ir_get(&ir, zx->arg[1])->imm, IR_IN_HEIGHT);
    const ir_node *c = root_node(&ir, "splatc");
    assert_int_equal(c->op, IR_OP_CONST);
    assert_int_equal(c->type, IR_T_VEC3);
    assert_true(c->val[0] == 0.5 && c->val[1] == 0.5 && c->val[2] == 0.5);
    const ir_node *sw = root_node(&ir, "swzswz");
    assert_int_equal(sw->op, IR_OP_SWIZZLE);
    assert_int_equal(ir_get(&ir, sw->arg[0])->op, IR_OP_INPUT);
    assert_int_equal(sw->imm, IR_SWZ(2, 2, 1, 0, 0));
    assert_int_equal(root_node(&ir, "swzsplat")->op, IR_OP_SPLAT);
    assert_int_equal(root_node(&ir, "swzsplat")->type, IR_T_VEC2);
    ir_free(&ir);
}

static void test_dce(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_param unused = {.name = "m.unused", .type = IR_T_FLOAT, .def = {1}, .lo = 1, .hi = 1};
    ir_param wet = {.name = "m.wet", .type = IR_T_FLOAT, .def = {0.2}, .lo = 0, .hi = 1};
    int pu = ir_add_param(&ir, &unused), pw = ir_add_param(&ir, &wet);
    ir_texture t0 = {.file = "a.png", .lo = 0, .hi = 1}, t1 = {.file = "b.png", .lo = 0, .hi = 1};
    ir_add_texture(&ir, &t0);
    int tb = ir_add_texture(&ir, &t1);
    ir_add_painted(&ir, "gone");
    int mk = ir_add_painted(&ir, "kept");
    ir_ref s = ir_input(&ir, IR_IN_SLOPE);
    ir_op2(&ir, IR_OP_ADD, ir_param_ref(&ir, pu), s);            /* dead */
    ir_ref tex = ir_swizzle(&ir, ir_op2(&ir, IR_OP_SAMPLE, ir_texture_ref(&ir, tb),
                                        ir_input(&ir, IR_IN_UV)), "x");
    ir_ref live = ir_op2(&ir, IR_OP_MUL, ir_op2(&ir, IR_OP_MUL, ir_param_ref(&ir, pw), s),
                         ir_op2(&ir, IR_OP_MUL, tex, ir_painted_ref(&ir, mk)));
    ir_set_root(&ir, "m.mask", live);
    double pv[8] = {0, 0, 0, 0, 0.5, 0, 0, 0}, mv[2] = {0, 0.75};
    ir_env env = {.slope = 0.4, .params = pv, .painted = mv};
    double before[4], after[4];
    ir_eval(&ir, live, &env, before);
    uint32_t nodes = ir.nnodes;

    assert_true(opt_dce(&ir));
    assert_true(ir_validate(&ir, stderr));
    assert_true(ir.nnodes < nodes);
    assert_int_equal(ir.nparams, 1);
    assert_string_equal(ir.params[0].name, "m.wet");
    assert_int_equal(ir.ntextures, 1);
    assert_string_equal(ir.textures[0].file, "b.png");
    assert_int_equal(ir.npainted, 1);
    assert_string_equal(ir.painted[0].name, "kept");
    double pv2[4] = {0.5}, mv2[1] = {0.75};
    env.params = pv2;
    env.painted = mv2;
    ir_eval(&ir, ir_find_root(&ir, "m.mask"), &env, after);
    assert_true(before[0] == after[0] && after[0] == 0.5 * 0.4 * 0.5 * 0.75);
    assert_false(opt_dce(&ir));
    ir_free(&ir);
}

static void test_dedup(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_texture rock = {.file = "rock.png", .wrap = IR_WRAP_REPEAT, .lo = 0, .hi = 1};
    ir_texture clamped = rock;
    clamped.wrap = IR_WRAP_CLAMP;                     /* other sampler state */
    int a = ir_add_texture(&ir, &rock), b = ir_add_texture(&ir, &rock);
    int c = ir_add_texture(&ir, &clamped);
    ir_ref uv = ir_input(&ir, IR_IN_UV);
    ir_ref sa = ir_op2(&ir, IR_OP_SAMPLE, ir_texture_ref(&ir, a), uv);
    ir_ref sb = ir_op2(&ir, IR_OP_SAMPLE, ir_texture_ref(&ir, b), uv);
    ir_ref sc = ir_op2(&ir, IR_OP_SAMPLE, ir_texture_ref(&ir, c), uv);
    assert_false(ir_ref_eq(sa, sb));
    ir_set_root(&ir, "r", ir_op2(&ir, IR_OP_ADD, ir_op2(&ir, IR_OP_ADD, sa, sb), sc));

    assert_true(opt_dedup(&ir));
    assert_true(ir_validate(&ir, stderr));
    int samples = 0;
    for (uint32_t id = 1; id < ir.nnodes; id++)
        samples += ir.nodes[id].op == IR_OP_SAMPLE;
    assert_int_equal(samples, 2);                     /* rock once, clamped once */
    assert_false(opt_dedup(&ir));
    assert_true(opt_dce(&ir));                        /* drops the orphan */
    assert_int_equal(ir.ntextures, 2);
    assert_int_equal(ir.textures[1].wrap, IR_WRAP_CLAMP);
    ir_free(&ir);
}

static void test_optimize_fixed_point_and_stop_after(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT);
    ir_ref k = ir_op2(&ir, IR_OP_MUL, ir_constf(&ir, 0.5), ir_constf(&ir, 2));   /* 1 */
    ir_set_root(&ir, "r", ir_op2(&ir, IR_OP_MUL, h, k));
    ir_op1(&ir, IR_OP_SIN, h);                                  /* dead */

    ir_optimize(&ir, "dedup");                                   /* nothing to do */
    assert_int_equal(root_node(&ir, "r")->op, IR_OP_MUL);
    ir_optimize(&ir, NULL);                                      /* h * 1 -> h */
    assert_int_equal(root_node(&ir, "r")->op, IR_OP_INPUT);
    assert_int_equal(ir.nnodes, 2);
    for (const ir_pass *p = ir_passes; p->name; p++)
        if (p->pipeline)
            assert_false(p->run(&ir, NULL));                     /* at its fixed point */
    ir_free(&ir);
}

static char *dump_text(const ir *ir)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    ir_dump(ir, f);
    fclose(f);
    return text;
}

static void test_dump(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_param p = {.name = "cliff.wetness", .type = IR_T_FLOAT, .def = {0.2}, .lo = 0, .hi = 1};
    ir_ref w = ir_param_ref(&ir, ir_add_param(&ir, &p));
    ir_ref s = ir_input(&ir, IR_IN_SLOPE);
    ir_ref m = ir_op3(&ir, IR_OP_MIX, s, ir_constf(&ir, 0.5), w);
    ir_set_root(&ir, "cliff.mask", m);
    /* a root that is no material output goes into a shader block */
    ir_ref pos = ir_input(&ir, IR_IN_POSITION);
    ir_set_root(&ir, "r", ir_op2(&ir, IR_OP_MUL, ir_constf(&ir, 2), ir_swizzle(&ir, pos, "z")));
    char *a = dump_text(&ir), *b = dump_text(&ir);
    assert_string_equal(a, b);                                   /* deterministic */
    assert_non_null(strstr(a, "\nmaterial cliff {\n"
                              "    param float wetness = 0.2 range 0.0 1.0\n"
                              "    node n1 : terrain.slope  # float\n"
                              "    node n2 : mix { a = n1.out, b = 0.5, t = wetness }  # float\n"
                              "    out mask = n2.out\n}\n"));
    /* node operands of a commutative op first, whatever their ids */
    assert_non_null(strstr(a, "\nshader dump {\n"
                              "    node n3 : terrain.position  # vec3\n"
                              "    node n4 : mul { a = n3.out.z, b = 2.0 }  # float\n"
                              "    out float r = n4.out\n}\n"));
    free(a);
    free(b);
    ir_free(&ir);
}

/* Every transformation is in the table (issue 32): the pipeline's three in
 * order, then differentiate and pin, each run by name through ir_pass_run. */
static void test_pass_table(void **state)
{
    (void)state;
    static const char *names[] = {"dedup", "fold", "dce", "differentiate", "pin"};
    int n = 0;
    for (const ir_pass *p = ir_passes; p->name; p++, n++) {
        assert_true(n < 5);
        assert_string_equal(p->name, names[n]);
        assert_int_equal(p->pipeline, n < 3);
        assert_ptr_equal(ir_pass_find(p->name), p);
    }
    assert_int_equal(n, 5);
    assert_null(ir_pass_find("cse"));

    /* pin through the table: h pinned to 2 over [2, 2] folds h * 3 to 6 */
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT);
    ir_set_root(&ir, "r", ir_op2(&ir, IR_OP_MUL, h, ir_constf(&ir, 3.0)));
    ir_ienv env;
    memset(&env, 0, sizeof env);
    ir_ienv_domain(&env);
    env.height = (ir_iv){2.0, 2.0};
    assert_true(ir_pass_run(&ir, "pin", &env));
    ir_optimize(&ir, NULL);
    assert_int_equal(root_node(&ir, "r")->op, IR_OP_CONST);
    /* differentiate through the table: no sample, no progress */
    assert_false(ir_pass_run(&ir, "differentiate", NULL));
    ir_free(&ir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fold_constants),
        cmocka_unit_test(test_fold_keeps_non_finite),
        cmocka_unit_test(test_fold_identities),
        cmocka_unit_test(test_fold_shapes),
        cmocka_unit_test(test_dce),
        cmocka_unit_test(test_dedup),
        cmocka_unit_test(test_optimize_fixed_point_and_stop_after),
        cmocka_unit_test(test_dump),
        cmocka_unit_test(test_pass_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
