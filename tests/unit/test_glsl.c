/* test_glsl.c — the GLSL emitter and the single-material shader: values
 * emitted once, leaves inlined, scopes, literals that round-trip a float,
 * resource declarations, and shaders (hand-built and random, every op)
 * that glslang compiles and SPIRV-Tools validates. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "ir.h"
#include "random_ir.h"
#include "shader.h"
#include "glsl_check.h"
#include "spv.h"

static int count(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle))
        n++;
    return n;
}

/* The prelude's view switch has a case for each view of abi.h's table
 * that the single-pass fragment shows, with the row's colour, and none for
 * the views a composite writes itself. */
static void test_prelude_views(void **state)
{
    int n = 0;
#define X(id, num, name, key, tm, where, glsl)                                     \
    do {                                                                           \
        const char *line = "case " #num "u: c = " glsl "; break;";               \
        bool want = strcmp(#where, "COMPOSITE") != 0;                             \
        assert_int_equal(strstr(SPLAT_GLSL_PRELUDE, line) != NULL, want);          \
        assert_int_equal(SPLAT_VIEW_##id, num);                                    \
        assert_int_equal(num, n++);                                                \
    } while (0);
    SPLAT_VIEWS(X)
#undef X
    assert_int_equal(n, SPLAT_VIEW_COUNT);
}

static void test_value_once_leaves_inline(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_param p = {.name = "m.k", .type = IR_T_FLOAT, .def = {2}, .lo = 0, .hi = 4};
    ir_ref k = ir_param_ref(&ir, ir_add_param(&ir, &p));
    ir_ref e = ir_op1(&ir, IR_OP_SATURATE, ir_op2(&ir, IR_OP_MUL, ir_input(&ir, IR_IN_SLOPE), k));
    ir_ref r1 = ir_op2(&ir, IR_OP_ADD, e, ir_constf(&ir, 1));
    ir_ref r2 = ir_op2(&ir, IR_OP_MUL, e, ir_constf(&ir, -2));
    ir_ref half = ir_constf(&ir, 0.5);
    const char *pnames[] = {"u_params.m_k.x"};
    glsl_names names = {.param = pnames};
    ir_buf out = {0};
    glsl_emitter *em = glsl_emitter_new(&ir, &names, &out);
    const char *a = glsl_value(em, r1, "  ");
    assert_string_equal(a, "v6");
    glsl_value(em, r2, "  ");
    assert_int_equal(count(out.s, "clamp("), 1);                  /* shared value once */
    /* (operands of commutative ops in id order: the param came first) */
    assert_non_null(strstr(out.s, "  float v3 = u_params.m_k.x * splat_slope();\n"));
    assert_non_null(strstr(out.s, "  float v4 = clamp(v3, 0.0, 1.0);\n"));
    assert_non_null(strstr(out.s, "  float v6 = v4 + 1.0;\n"));
    assert_non_null(strstr(out.s, "v4 * (-2.0)"));                 /* negative literal */
    assert_null(strstr(out.s, "= splat_slope();"));               /* leaves inline */
    /* a leaf asked for directly is its expression */
    assert_string_equal(glsl_value(em, half, ""), "0.5");
    glsl_emitter_free(em);
    ir_buf_free(&out);
    ir_free(&ir);
}

static void test_scopes(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_ref h = ir_input(&ir, IR_IN_HEIGHT);
    ir_ref outer = ir_op1(&ir, IR_OP_SIN, h);
    ir_ref inner = ir_op2(&ir, IR_OP_MUL, outer, outer);
    ir_buf out = {0};
    glsl_emitter *em = glsl_emitter_new(&ir, NULL, &out);
    glsl_value(em, outer, "");
    glsl_scope_push(em);
    glsl_value(em, inner, "    ");
    assert_int_equal(count(out.s, "sin("), 1);                    /* outer stays visible */
    glsl_scope_pop(em);
    glsl_value(em, inner, "");                                     /* forgotten: again */
    assert_int_equal(count(out.s, " v3 = v2 * v2;"), 2);
    assert_int_equal(count(out.s, "sin("), 1);
    glsl_emitter_free(em);
    ir_buf_free(&out);
    ir_free(&ir);
}

static void test_literals(void **state)
{
    static const double vals[] = {1.0, 0.1, -2.5, 1e20, 3e-8, 123456789.0, 0.0, -0.0,
                                  1.0 / 3.0, 65504.0, 1e-40};
    for (size_t i = 0; i < sizeof vals / sizeof vals[0]; i++) {
        ir_buf b = {0};
        glsl_literal(&b, IR_T_FLOAT, &vals[i]);
        assert_true(strpbrk(b.s, ".e") != NULL);                  /* a float literal */
        float back = strtof(b.s, NULL);
        assert_true(back == (float)vals[i]);
        assert_true(signbit(back) == signbit((float)vals[i]));
        ir_buf_free(&b);
    }
    ir_buf b = {0};
    double v3[3] = {0.5, 0.5, 0.5}, v2[2] = {1, -2};
    glsl_literal(&b, IR_T_VEC3, v3);
    glsl_literal(&b, IR_T_VEC2, v2);
    double inf = INFINITY;
    glsl_literal(&b, IR_T_FLOAT, &inf);
    assert_string_equal(b.s, "vec3(0.5)vec2(1.0, -2.0)uintBitsToFloat(0x7f800000u)");
    ir_buf_free(&b);
}

/* A material using every kind of leaf and the ops with special GLSL. */
static void build_material(ir *ir)
{
    ir_param wet = {.name = "cliff.wetness", .type = IR_T_FLOAT, .def = {0.2}, .lo = 0, .hi = 1};
    ir_param tint = {.name = "cliff.tint", .type = IR_T_VEC3, .def = {0.5, 0.4, 0.3}, .lo = 0, .hi = 1};
    ir_param clash = {.name = "cliff_tint", .type = IR_T_VEC2, .def = {1, 2}, .lo = 0, .hi = 4};
    ir_ref w = ir_param_ref(ir, ir_add_param(ir, &wet));
    ir_ref t = ir_param_ref(ir, ir_add_param(ir, &tint));
    ir_ref cl = ir_param_ref(ir, ir_add_param(ir, &clash));
    ir_texture rock = {.file = "textures/rock*/.png", .srgb = true, .lo = 0, .hi = 1};
    ir_ref tex = ir_texture_ref(ir, ir_add_texture(ir, &rock));
    ir_ref fields = ir_painted_ref(ir, ir_add_painted(ir, "fields"));
    ir_ref uv = ir_op2(ir, IR_OP_MUL, ir_input(ir, IR_IN_UV), cl);
    ir_ref s = ir_op2(ir, IR_OP_SAMPLE, tex, uv);
    ir_ref slope = ir_input(ir, IR_IN_SLOPE);
    ir_ref mask = ir_op1(ir, IR_OP_SATURATE,
                         ir_op2(ir, IR_OP_MUL, ir_op3(ir, IR_OP_SMOOTHSTEP, ir_constf(ir, 0.55),
                                                      ir_constf(ir, 0.75), slope), fields));
    ir_ref rgb = ir_swizzle(ir, s, "rgb");
    ir_ref cond = ir_op2(ir, IR_OP_LESS, rgb, t);                 /* vec3 less */
    ir_ref albedo = ir_op3(ir, IR_OP_SELECT, cond, rgb, ir_splat(ir, w, IR_T_VEC3));
    ir_ref n = ir_op1(ir, IR_OP_NORMALIZE,
                      ir_op2(ir, IR_OP_ADD, ir_input(ir, IR_IN_NORMAL),
                             ir_op2(ir, IR_OP_CROSS, ir_input(ir, IR_IN_POSITION), t)));
    ir_ref rough = ir_op3(ir, IR_OP_SELECT, ir_op2(ir, IR_OP_LESS, w, ir_constf(ir, 0.5)),
                          ir_constf(ir, 0.9), ir_constf(ir, -0.3));
    ir_set_root(ir, "cliff.mask", mask);
    ir_set_root(ir, "cliff.albedo", albedo);
    ir_set_root(ir, "cliff.normal", n);
    ir_set_root(ir, "cliff.roughness", rough);
    /* no height: the default */
}

static void test_material_shader(void **state)
{
    ir ir;
    ir_init(&ir);
    build_material(&ir);
    ir_buf a = {0}, b = {0};
    glsl_material_shader(&ir, "cliff", &a);
    glsl_material_shader(&ir, "cliff", &b);
    assert_string_equal(a.s, b.s);                                /* deterministic */
    assert_memory_equal(a.s, "#version 450\n", 13);
    assert_non_null(strstr(a.s, "layout(set = 1, binding = 0, std140) uniform splat_params {\n"
                                "    vec4 cliff_wetness;"));
    assert_non_null(strstr(a.s, "    vec4 cliff_tint;"));
    assert_non_null(strstr(a.s, "    vec4 cliff_tint_2;"));       /* made unique */
    assert_non_null(strstr(a.s, "layout(set = 1, binding = 1) uniform sampler2D t_tex0;"));
    assert_non_null(strstr(a.s, "u_params.cliff_tint_2.xy"));
    assert_non_null(strstr(a.s, "splat_painted(0)"));
    assert_non_null(strstr(a.s, " *   offset   16  u_params.cliff_tint.xyz"));
    assert_non_null(strstr(a.s, "rock* /.png"));                  /* comment stays closed */
    assert_non_null(strstr(a.s, "lessThan("));
    assert_non_null(strstr(a.s, "notEqual("));
    assert_non_null(strstr(a.s, ", 0.5, v"));                     /* default height */
    assert_non_null(strstr(a.s, "splat_finish("));
    glsl_check_compiles(a.s, SPV_STAGE_FRAGMENT, "cliff");
    ir_buf_free(&a);
    ir_buf_free(&b);
    ir_free(&ir);
}

static void test_empty_material_compiles(void **state)
{
    ir ir;
    ir_init(&ir);
    ir_buf a = {0};
    glsl_material_shader(&ir, "plain", &a);
    assert_null(strstr(a.s, "uniform splat_params"));             /* no empty block */
    assert_non_null(strstr(a.s, "splat_finish(vec3(0.5), splat_normal(), 0.8, 0.5, 1.0);"));
    glsl_check_compiles(a.s, SPV_STAGE_FRAGMENT, "plain");
    ir_buf_free(&a);
    ir_free(&ir);
}

/* Random graphs over every op as material outputs: all GLSL forms, for
 * every type, compile.  (The GPU harness checks their values.) */
static void test_random_graphs_compile(void **state)
{
    random_ir_rng rng = {2024};
    static const struct { const char *name; ir_type type; } outs[] = {
        {"rnd.mask", IR_T_FLOAT}, {"rnd.albedo", IR_T_VEC3}, {"rnd.normal", IR_T_VEC3},
        {"rnd.roughness", IR_T_FLOAT}, {"rnd.height", IR_T_FLOAT}};
    bool seen[IR_OP_COUNT] = {0};
    for (int g = 0; g < 12; g++) {
        ir ir;
        ir_init(&ir);
        random_ir_setup(&ir);
        for (int i = 0; i < 5; i++) {
            ir_ref r = random_ir_expr(&ir, &rng, outs[i].type, 5, NULL);
            /* a vec2 and a vec4 value too, folded in through a swizzle */
            if (i == 1)
                r = ir_op2(&ir, IR_OP_ADD, r,
                           ir_swizzle(&ir, random_ir_expr(&ir, &rng, IR_T_VEC4, 4, NULL), "wzy"));
            ir_set_root(&ir, outs[i].name, r);
        }
        for (uint32_t id = 1; id < ir.nnodes; id++)
            seen[ir.nodes[id].op] = true;
        ir_buf a = {0};
        glsl_material_shader(&ir, "rnd", &a);
        glsl_check_compiles(a.s, SPV_STAGE_FRAGMENT, "rnd");
        ir_buf_free(&a);
        ir_free(&ir);
    }
    /* the derivative pass's ops after CROSS are never generated here
     * (test_differentiate compiles compute variants, which have them) */
    for (int op = 0; op <= IR_OP_CROSS; op++)
        if (!seen[op]) {
            fprintf(stderr, "op %d never generated\n", op);
            fail();
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_value_once_leaves_inline),
        cmocka_unit_test(test_prelude_views),
        cmocka_unit_test(test_scopes),
        cmocka_unit_test(test_literals),
        cmocka_unit_test(test_material_shader),
        cmocka_unit_test(test_empty_material_compiles),
        cmocka_unit_test(test_random_graphs_compile),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
