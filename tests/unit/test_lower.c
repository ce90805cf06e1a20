/* test_lower.c — AST -> IR: instance inlining (nested), hash-consing that
 * makes a subtree computed through two instances one node (and one line
 * of GLSL), params / textures / painted masks, material defaults, splats,
 * the node library against Andersson 2007 Listing 2 computed directly, the
 * compositor through sg_lower_shader, and lowering staying linear. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sg_internal.h"
#include "shader.h"

static const char *const search[] = { ".", NULL };

static sg_program *load(const char *text)
{
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("t.sg", text, search, &d);
    if (d.nerrors) {
        sg_diags_print(&d, stderr);
        fail_msg("unexpected errors");
    }
    sg_diags_free(&d);
    return p;
}

static void lower(sg_program *p, const char *material, ir *ir)
{
    sg_diags d;
    sg_diags_init(&d);
    bool ok = sg_lower_material(p, material, ir, &d);
    sg_diags_print(&d, stderr);
    assert_true(ok);
    assert_int_equal(d.nerrors, 0);
    sg_diags_free(&d);
    assert_true(ir_validate(ir, stderr));
}

static ir_ref root(const ir *ir, const char *name)
{
    ir_ref r = ir_find_root(ir, name);
    if (!ir_ref_ok(r))
        fail_msg("no root '%s'", name);
    return r;
}

static int count_ops(const ir *ir, ir_op op)
{
    int n = 0;
    for (uint32_t i = 1; i < ir->nnodes; i++)
        n += ir->nodes[i].op == op;
    return n;
}

static int count_substr(const char *s, const char *sub)
{
    int n = 0;
    for (const char *p = strstr(s, sub); p; p = strstr(p + 1, sub))
        n++;
    return n;
}

static const char ramp_src[] =
    "import \"nodes/masks.sg\"\n"
    "material twice {\n"
    "  node s  : terrain.slope\n"
    "  node r1 : ramp { x = s.out, lo = 0.6, hi = 0.8 }\n"
    "  node r2 : ramp { x = s.out, lo = 0.60, hi = 8e-1 }\n"
    "  node m  : mul { a = r1.out, b = r2.out }\n"
    "  out mask = m.out\n"
    "}\n"
    "material once {\n"
    "  node s  : terrain.slope\n"
    "  node r1 : ramp { x = s.out, lo = 0.6, hi = 0.8 }\n"
    "  node m  : mul { a = r1.out, b = r1.out }\n"
    "  out mask = m.out\n"
    "}\n";

static void test_hash_consing_shares_instances(void **state)
{
    sg_program *p = load(ramp_src);
    ir a, b;
    ir_init(&a);
    ir_init(&b);
    lower(p, "twice", &a);
    lower(p, "once", &b);
    /* the two instances are one subtree: mul's operands are the same node */
    const ir_node *m = ir_get(&a, root(&a, "twice.mask"));
    assert_int_equal(m->op, IR_OP_MUL);
    assert_true(ir_ref_eq(m->arg[0], m->arg[1]));
    assert_int_equal(a.nnodes, b.nnodes);
    assert_int_equal(count_ops(&a, IR_OP_SATURATE), 1);
    assert_int_equal(count_ops(&a, IR_OP_DIV), 1);

    /* and the GLSL computes the ramp once */
    ir_optimize(&a, NULL);
    ir_buf glsl = { 0 };
    glsl_material_shader(&a, "twice", &glsl);
    /* the material's main, after the prelude (whose compute variants
     * define mains of their own) */
    const char *body = NULL;
    for (const char *at = glsl.s; (at = strstr(at, "void main()")); at++)
        body = at;
    assert_non_null(body);
    assert_int_equal(count_substr(body, "clamp("), 1);
    assert_int_equal(count_substr(body, "splat_slope()"), 1);
    ir_buf_free(&glsl);

    /* a second material lowered into the same ir reuses its nodes: `once`
     * is the same graph as `twice`, so it adds none */
    ir_free(&a);
    ir_init(&a);
    lower(p, "twice", &a);
    uint32_t before = a.nnodes;
    lower(p, "once", &a);
    assert_true(ir_ref_eq(root(&a, "twice.mask"), root(&a, "once.mask")));
    assert_int_equal(a.nnodes, before);
    ir_free(&a);
    ir_free(&b);
    sg_free(p);
}

static void test_material_defaults_and_tables(void **state)
{
    sg_program *p = load("texture rock { file = \"tex/rock.png\", wrap = clamp, srgb = true }\n"
                         "material empty { }\n"
                         "material m {\n"
                         "  param float wet = 0.25 range 0 1\n"
                         "  param vec3 tint = 0.5\n"
                         "  node a : sample { tex = rock, uv = terrain.uv }\n"
                         "  node b : sample { tex = \"tex/d.png\", uv = terrain.uv }\n"
                         "  node c : sample { tex = \"tex/d.png\", uv = a.xy }\n"
                         "  node f : painted { mask = \"fields\" }\n"
                         "  node t : mul { a = b.rgb, b = tint }\n"
                         "  node w : mul { a = f.out, b = wet }\n"
                         "  out albedo = t.out\n"
                         "  out mask = w.out\n"
                         "  out height = c.a\n"
                         "}\n");
    ir ir;
    ir_init(&ir);
    lower(p, "empty", &ir);
    ir_env env = { .normal = { 0.6, 0.8, 0 } };
    double v[4];
    ir_eval(&ir, root(&ir, "empty.mask"), &env, v);
    assert_true(v[0] == 1);
    ir_eval(&ir, root(&ir, "empty.albedo"), &env, v);
    assert_true(v[0] == 0.5 && v[1] == 0.5 && v[2] == 0.5);
    ir_eval(&ir, root(&ir, "empty.normal"), &env, v);
    assert_true(v[0] == 0.6 && v[1] == 0.8);
    ir_eval(&ir, root(&ir, "empty.roughness"), &env, v);
    assert_true(v[0] == 0.8);
    ir_eval(&ir, root(&ir, "empty.height"), &env, v);
    assert_true(v[0] == 0.5);

    lower(p, "m", &ir);
    assert_int_equal(ir.nparams, 2);
    assert_string_equal(ir.params[0].name, "m.wet");
    assert_true(ir.params[0].def[0] == 0.25 && ir.params[0].lo == 0 && ir.params[0].hi == 1);
    assert_string_equal(ir.params[1].name, "m.tint");
    assert_int_equal(ir.params[1].type, IR_T_VEC3);
    assert_true(ir.params[1].def[2] == 0.5);
    assert_true(ir.params[1].lo == 0.5 && ir.params[1].hi == 0.5);   /* fixed */
    /* one texture per declaration and per inline file */
    assert_int_equal(ir.ntextures, 2);
    assert_string_equal(ir.textures[0].file, "tex/rock.png");
    assert_int_equal(ir.textures[0].wrap, IR_WRAP_CLAMP);
    assert_true(ir.textures[0].srgb);
    assert_string_equal(ir.textures[1].file, "tex/d.png");
    assert_int_equal(ir.textures[1].wrap, IR_WRAP_REPEAT);
    assert_int_equal(ir.npainted, 1);
    assert_string_equal(ir.painted[0].name, "fields");

    /* values: the sample reads (0.5, 0.5, 0.5, 1) without a sampler */
    double painted[1] = { 0.8 };
    ir_env e2 = { .painted = painted };
    ir_eval(&ir, root(&ir, "m.mask"), &e2, v);
    assert_true(fabs(v[0] - 0.2) < 1e-15);
    ir_eval(&ir, root(&ir, "m.albedo"), &e2, v);
    assert_true(v[0] == 0.25 && v[2] == 0.25);
    ir_eval(&ir, root(&ir, "m.height"), &e2, v);
    assert_true(v[0] == 1);
    ir_free(&ir);
    sg_free(p);
}

static void test_splat(void **state)
{
    sg_program *p = load("material m {\n"
                         "  node s : terrain.slope\n"
                         "  node a : mul { a = terrain.normal, b = s.out }\n"
                         "  node b : add { a = a.out, b = 1 }\n"
                         "  out albedo = b.out\n"
                         "}\n");
    ir ir;
    ir_init(&ir);
    lower(p, "m", &ir);
    assert_int_equal(count_ops(&ir, IR_OP_SPLAT), 1);   /* the wire      */
    const ir_node *b = ir_get(&ir, root(&ir, "m.albedo"));
    assert_int_equal(b->type, IR_T_VEC3);
    ir_env env = { .slope = 0.5, .normal = { 0.2, 0.4, 0.6 } };
    double v[4];
    ir_eval(&ir, root(&ir, "m.albedo"), &env, v);
    assert_true(v[0] == 1.1 && v[1] == 1.2 && v[2] == 1.3);
    ir_free(&ir);
    sg_free(p);
}

/* Seed 000 Listing 2, in double precision. */
static double overlay_ref(double value1, double value2, double opacity)
{
    double blend = value1 < 0.5 ? 2 * value1 * value2 : 1 - 2 * (1 - value1) * (1 - value2);
    return value1 + (blend - value1) * opacity;   /* lerp */
}

static double scale_contrast_ref(double value, double contrast)
{
    double x = (value - 0.5) * contrast + 0.5;
    return x < 0 ? 0 : x > 1 ? 1 : x;
}

/* Evaluate shader `name` of nodes/masks.sg with constant inputs. */
static double eval_shader(sg_program *p, const char *name, const char *const *ins,
                          const double *vals, int n)
{
    ir ir;
    ir_init(&ir);
    ir_ref in[4], out;
    for (int i = 0; i < n; i++)
        in[i] = ir_constf(&ir, vals[i]);
    const char *outs[] = { "out" };
    sg_diags d;
    sg_diags_init(&d);
    assert_true(sg_lower_shader(p, name, &ir, ins, in, n, outs, &out, 1, &d));
    sg_diags_free(&d);
    ir_env env = { 0 };
    double v[4];
    ir_eval(&ir, out, &env, v);
    ir_free(&ir);
    return v[0];
}

static void test_listing2_nodes(void **state)
{
    sg_program *p = load("import \"nodes/masks.sg\"\n");
    const double grid[] = { 0, 0.1, 0.25, 0.4999, 0.5, 0.5001, 0.75, 0.9, 1 };
    const char *ov[] = { "base", "blend", "opacity" };
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 9; j++)
            for (int k = 0; k < 9; k += 2) {
                double in[3] = { grid[i], grid[j], grid[k] };
                double got = eval_shader(p, "overlay", ov, in, 3);
                double want = overlay_ref(in[0], in[1], in[2]);
                if (fabs(got - want) > 1e-15)
                    fail_msg("overlay(%g, %g, %g) = %.17g, Listing 2 gives %.17g", in[0],
                             in[1], in[2], got, want);
            }
    /* overlay leaves 0 and 1 alone, whatever the detail */
    for (int j = 0; j < 9; j++) {
        double in0[3] = { 0, grid[j], 1 }, in1[3] = { 1, grid[j], 1 };
        assert_true(eval_shader(p, "overlay", ov, in0, 3) == 0);
        assert_true(eval_shader(p, "overlay", ov, in1, 3) == 1);
    }
    const char *sc[] = { "value", "contrast" };
    const double contrasts[] = { 0, 0.5, 1, 2, 8, 1e6 };
    for (int i = 0; i < 9; i++)
        for (int k = 0; k < 6; k++) {
            double in[2] = { grid[i], contrasts[k] };
            assert_true(eval_shader(p, "scale_contrast", sc, in, 2) ==
                        scale_contrast_ref(in[0], in[1]));
        }
    /* ramp: ends, middle, and lo == hi is a step (no NaN) */
    const char *rp[] = { "x", "lo", "hi" };
    double r0[3] = { 0.5, 0.6, 0.8 }, r1[3] = { 0.7, 0.6, 0.8 }, r2[3] = { 0.9, 0.6, 0.8 };
    double r3[3] = { 0.61, 0.6, 0.6 }, r4[3] = { 0.6, 0.6, 0.6 };
    assert_true(eval_shader(p, "ramp", rp, r0, 3) == 0);
    assert_true(fabs(eval_shader(p, "ramp", rp, r1, 3) - 0.5) < 1e-12);
    assert_true(eval_shader(p, "ramp", rp, r2, 3) == 1);
    assert_true(eval_shader(p, "ramp", rp, r3, 3) == 1);
    assert_true(eval_shader(p, "ramp", rp, r4, 3) == 0);
    sg_free(p);
}

static void test_compositor_shader(void **state)
{
    sg_program *p = load("import \"nodes/compositors.sg\"\n");
    ir ir;
    ir_init(&ir);
    const char *in_names[] = { "T", "m" };
    ir_ref in[2] = { ir_input(&ir, IR_IN_DESTRUCTION), ir_input(&ir, IR_IN_SLOPE) };
    const char *out_names[] = { "T_next", "weight" };
    ir_ref out[2];
    sg_diags d;
    sg_diags_init(&d);
    assert_true(sg_lower_shader(p, "linear_alpha", &ir, in_names, in, 2, out_names, out, 2, &d));
    ir_env env = { .destruction = 0.75, .slope = 0.5 };
    double v[4];
    ir_eval(&ir, out[1], &env, v);
    assert_true(v[0] == 0.375);
    ir_eval(&ir, out[0], &env, v);
    assert_true(v[0] == 0.375);
    /* errors: unknown shader, port, wrong type, missing input */
    assert_false(sg_lower_shader(p, "nope", &ir, NULL, NULL, 0, NULL, NULL, 0, &d));
    assert_int_equal(d.items[d.n - 1].id, SG_E_UNKNOWN_NODE);
    const char *bad_out[] = { "w" };
    assert_false(sg_lower_shader(p, "linear_alpha", &ir, in_names, in, 2, bad_out, out, 1, &d));
    assert_int_equal(d.items[d.n - 1].id, SG_E_UNKNOWN_PORT);
    ir_ref vec = ir_input(&ir, IR_IN_NORMAL);
    assert_false(sg_lower_shader(p, "linear_alpha", &ir, in_names, &vec, 1, out_names, out, 1, &d));
    assert_int_equal(d.items[d.n - 1].id, SG_E_TYPE_MISMATCH);
    assert_false(sg_lower_shader(p, "linear_alpha", &ir, in_names + 1, in + 1, 1, out_names, out,
                                 1, &d));
    assert_int_equal(d.items[d.n - 1].id, SG_E_MISSING_INPUT);
    assert_int_equal(d.nerrors, 4);
    sg_diags_free(&d);
    ir_free(&ir);
    sg_free(p);
}

static void test_nested_doubling_is_linear(void **state)
{
    /* s0 uses s1 twice, s1 uses s2 twice … 60 levels: 2^60 instances
     * written, one subtree per level after memo + hash-consing */
    int n = 60;
    size_t cap = (size_t)n * 200 + 200;
    char *s = malloc(cap);
    size_t o = 0;
    for (int i = 0; i < n; i++)
        o += (size_t)snprintf(s + o, cap - o,
                              "shader s%d { in float x\n node a : s%d { x = x }\n"
                              " node b : s%d { x = x }\n node c : add { a = a.out, b = b.out }\n"
                              " out float out = c.out }\n", i, i + 1, i + 1);
    o += (size_t)snprintf(s + o, cap - o,
                          "shader s%d { in float x node y : sin { x = x } out float out = y.out }\n", n);
    snprintf(s + o, cap - o, "material m { node s : terrain.slope\n"
                             " node t : s0 { x = s.out } out mask = t.out }\n");
    sg_program *p = load(s);
    ir ir;
    ir_init(&ir);
    lower(p, "m", &ir);
    assert_true(ir.nnodes < 200);
    assert_int_equal(count_ops(&ir, IR_OP_ADD), n);
    ir_free(&ir);
    sg_free(p);
    free(s);
}

static void test_example_graphs(void **state)
{
    const char *files[] = { "graphs/cliff.sg", "graphs/grass.sg", "graphs/snow.sg" };
    const char *mats[] = { "cliff", "grass", "snow" };
    for (int i = 0; i < 3; i++) {
        sg_diags d;
        sg_diags_init(&d);
        sg_program *p = sg_load(files[i], search, &d);
        sg_diags_print(&d, stderr);
        assert_int_equal(d.nerrors, 0);
        ir ir;
        ir_init(&ir);
        lower(p, mats[i], &ir);
        for (int k = 0; k < SG_OUT_COUNT; k++) {
            char name[64];
            snprintf(name, sizeof name, "%s.%s", mats[i], sg_output_names[k]);
            ir_ref r = root(&ir, name);
            static const ir_type types[] = { IR_T_FLOAT, IR_T_VEC3, IR_T_VEC3, IR_T_FLOAT,
                                             IR_T_FLOAT };
            assert_int_equal(ir_typeof(&ir, r), types[k]);
        }
        /* texture paths are relative to the graph file, as given */
        for (int t = 0; t < ir.ntextures; t++)
            assert_memory_equal(ir.textures[t].file, "graphs/textures/", 16);
        ir_free(&ir);
        sg_free(p);
        sg_diags_free(&d);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hash_consing_shares_instances),
        cmocka_unit_test(test_material_defaults_and_tables),
        cmocka_unit_test(test_splat),
        cmocka_unit_test(test_listing2_nodes),
        cmocka_unit_test(test_compositor_shader),
        cmocka_unit_test(test_nested_doubling_is_linear),
        cmocka_unit_test(test_example_graphs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
