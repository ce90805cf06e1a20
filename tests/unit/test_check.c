/* test_check.c — name resolution and type checking: each error id at its
 * line and column, the splat rules, cycles with their paths, and nesting
 * depth.  Types of built-in ops come from the op table's rule. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "sg_internal.h"

/* Load `text`; the diagnostics are left in *d. */
static sg_program *load(const char *text, sg_diags *d)
{
    sg_diags_init(d);
    sg_program *p = sg_load_string("t.sg", text, NULL, d);
    assert_non_null(p);
    return p;
}

/* Exactly one error, with this id, place and message. */
static void expect_one(const char *text, sg_error_id id, int line, int col, const char *msg)
{
    sg_diags d;
    sg_program *p = load(text, &d);
    if (d.nerrors != 1 || d.items[0].id != id || d.items[0].loc.line != line ||
        d.items[0].loc.col != col || (msg && strcmp(d.items[0].msg, msg))) {
        sg_diags_print(&d, stderr);
        fail_msg("want one error id %d at %d:%d: %s", id, line, col, msg ? msg : "");
    }
    sg_free(p);
    sg_diags_free(&d);
}

static void expect_ok(const char *text)
{
    sg_diags d;
    sg_program *p = load(text, &d);
    if (d.nerrors) {
        sg_diags_print(&d, stderr);
        fail_msg("unexpected errors");
    }
    sg_free(p);
    sg_diags_free(&d);
}

static void test_unknown_names(void **state)
{
    expect_one("material m {\n  node r : rampp { x = 1 }\n}\n", SG_E_UNKNOWN_NODE, 2, 12,
               "unknown node type 'rampp'");
    expect_one("material m {\n  node a : add { a = 1, c = 2 }\n}\n", SG_E_UNKNOWN_PORT, 2, 25,
               "'add' has no input port 'c'");
    expect_one("material m {\n  node a : abs { x = 1 }\n  out mask = a.value\n}\n",
               SG_E_UNKNOWN_PORT, 3, 14, "'a' has no output port 'value'");
    expect_one("material m {\n  node a : abs { x = wetness }\n}\n", SG_E_UNKNOWN_NAME, 2, 22,
               "unknown name 'wetness'");
    expect_one("material m {\n  node a : abs { x = terrain.hieght }\n}\n", SG_E_UNKNOWN_NAME,
               2, 22, "unknown name 'terrain.hieght'; did you mean 'terrain.height'?");
    expect_one("material m {\n  out colour = 1\n}\n", SG_E_BAD_OUTPUT, 2, 7, NULL);
    expect_one("material m {\n  node s : terrain.slope\n  out mask = s.out.q\n}\n",
               SG_E_BAD_SWIZZLE, 3, 14, NULL);
    expect_one("material a { }\nmaterial m {\n  node x : a\n}\n", SG_E_BAD_REFERENCE, 3, 12,
               "'a' is a material; only shaders can be instantiated as nodes");
}

/* "did you mean": the distance, the limit, ties and prefixes. */
static void test_suggest(void **state)
{
    assert_int_equal(sg_edit_distance("ramp", "ramp"), 0);
    assert_int_equal(sg_edit_distance("slope_rmap", "slope_ramp"), 1);  /* a swap */
    assert_int_equal(sg_edit_distance("inlo", "in_lo"), 1);
    assert_int_equal(sg_edit_distance("Ramp", "ramp"), 0);              /* case */
    assert_int_equal(sg_edit_distance("", "abc"), 3);
    assert_int_equal(sg_edit_distance("kitten", "sitting"), 3);
    sg_suggest sg;
    sg_suggest_init(&sg, "positon");
    sg_suggest_offer(&sg, "normal");
    sg_suggest_offer(&sg, "position");
    sg_suggest_offer(&sg, "positions");
    assert_string_equal(sg_suggest_best(&sg), "position");
    sg_suggest_init(&sg, "quux");            /* nothing near */
    sg_suggest_offer(&sg, "mix");
    sg_suggest_offer(&sg, "abs");
    assert_null(sg_suggest_best(&sg));
    sg_suggest_init(&sg, "c");               /* too short to guess */
    sg_suggest_offer(&sg, "a");
    assert_null(sg_suggest_best(&sg));
    sg_suggest_init(&sg, "output");          /* a prefix passes */
    sg_suggest_offer(&sg, "out");
    assert_string_equal(sg_suggest_best(&sg), "out");
    sg_suggest_init(&sg, "e2");              /* not itself, first of a tie */
    sg_suggest_offer(&sg, "e2");
    assert_null(sg_suggest_best(&sg));
    sg_suggest_init(&sg, "lox");
    sg_suggest_offer(&sg, "lo");
    sg_suggest_offer(&sg, "lx");
    assert_string_equal(sg_suggest_best(&sg), "lo");
}

static void test_types(void **state)
{
    /* the op table's rule: componentwise operands of one width */
    expect_one("material m {\n  node n : terrain.normal\n"
               "  node a : add { a = n.out, b = terrain.uv }\n}\n",
               SG_E_TYPE_MISMATCH, 3, 33,
               "type mismatch: port 'b' of 'a' (add) expects vec3, found vec2");
    /* sample wants a texture first */
    expect_one("material m {\n  node s : sample { tex = terrain.normal, uv = terrain.uv }\n}\n",
               SG_E_TYPE_MISMATCH, 2, 27,
               "type mismatch: port 'tex' of 's' (sample) expects texture, found vec3");
    /* floats splat into componentwise ops: wires and literals */
    expect_ok("material m {\n  node s : terrain.slope\n"
              "  node a : mul { a = terrain.position, b = s.out }\n"
              "  node b : mix { a = a.out, b = vec3(1, 2, 3), t = 0.5 }\n"
              "  out albedo = b.out\n}\n");
    /* shader inputs: exact, except a float literal into vecN */
    const char *sh = "shader tint { in vec3 c\n  in float k = 1\n  node m : mul { a = c, b = k }\n"
                     "  out vec3 out = m.out }\n";
    char buf[1024];
    snprintf(buf, sizeof buf, "%smaterial m {\n  node t : tint { c = 0.5 }\n"
                              "  out albedo = t.out\n}\n", sh);
    expect_ok(buf);
    snprintf(buf, sizeof buf, "%smaterial m {\n  node s : terrain.slope\n"
                              "  node t : tint { c = s.out }\n}\n", sh);
    expect_one(buf, SG_E_TYPE_MISMATCH, 7, 23,
               "type mismatch: input 'c' of 't' (tint) expects vec3, found float");
    /* material outputs have fixed types */
    expect_one("material m {\n  out albedo = terrain.uv\n}\n", SG_E_TYPE_MISMATCH, 2, 16,
               "type mismatch: output 'albedo' expects vec3, found vec2");
    expect_ok("material m {\n  out albedo = 0.5\n  out roughness = 0.2\n}\n");
    /* a swizzle past the end */
    expect_one("material m {\n  out mask = terrain.uv.z\n}\n", SG_E_BAD_SWIZZLE, 2, 14,
               "swizzle '.z' reads past the end of a vec2");
    /* param defaults and ranges */
    expect_one("material m {\n  param vec2 p = vec3(1, 2, 3)\n}\n", SG_E_TYPE_MISMATCH, 2, 18,
               NULL);
    expect_one("material m {\n  param float p = 0.5 range 1 0\n}\n", SG_E_EMPTY_RANGE, 2, 19,
               NULL);
}

static void test_missing_and_duplicate(void **state)
{
    expect_one("material m {\n  node a : sub { a = 1 }\n}\n", SG_E_MISSING_INPUT, 2, 8,
               "'a' needs a value for input 'b'");
    expect_one("shader s { in float x\n  in float y = 2\n  out float o = x }\n"
               "material m {\n  node i : s { y = 1 }\n}\n",
               SG_E_MISSING_INPUT, 5, 8, "'i' needs a value for input 'x'");
    expect_one("material m {\n  node a : terrain.slope\n  node a : terrain.height\n}\n",
               SG_E_DUPLICATE, 3, 8, "duplicate node 'a' (first defined at t.sg:2:8)");
    expect_one("material m {\n  node a : add { a = 1, a = 2, b = 3 }\n}\n", SG_E_DUPLICATE, 2,
               25, "duplicate port 'a' (first defined at t.sg:2:18)");
    expect_one("shader s { out float o = 1 }\n\nshader s { out float o = 2 }\n",
               SG_E_DUPLICATE, 3, 8, "duplicate shader 's' (first defined at t.sg:1:8)");
    expect_one("material m {\n  out mask = 1\n  out mask = 0\n}\n", SG_E_DUPLICATE, 3, 7,
               NULL);
    expect_one("shader mix { out float o = 1 }\n", SG_E_REDEFINED, 1, 8,
               "'mix' is a built-in node type and cannot be redefined");
}

static void test_cycles(void **state)
{
    expect_one("material m {\n  node a : add { a = b.out, b = 1 }\n"
               "  node b : mul { a = c.out, b = 2 }\n  node c : abs { x = a.out }\n}\n",
               SG_E_CYCLE, 2, 8, "cycle: a -> b -> c -> a");
    expect_one("material m {\n  node a : add { a = a.out, b = 1 }\n}\n", SG_E_CYCLE, 2, 8,
               "cycle: a -> a");
    expect_one("shader p { node q : q { } out float out = 1 }\n"
               "shader q { node p : p { } out float out = 1 }\n",
               SG_E_CYCLE, 1, 8, "cycle: p -> q -> p");
}

/* Text of a chain of `n` shaders, each instantiating the next. */
static char *chain(int n)
{
    size_t cap = (size_t)n * 120 + 200;
    char *s = malloc(cap);
    size_t o = 0;
    for (int i = 0; i < n; i++)
        o += (size_t)snprintf(s + o, cap - o,
                              "shader s%d { in float x node n : s%d { x = x } out float out = n.out }\n",
                              i, i + 1);
    o += (size_t)snprintf(s + o, cap - o, "shader s%d { in float x out float out = x }\n", n);
    snprintf(s + o, cap - o, "material m { node n : s0 { x = 1 } out mask = n.out }\n");
    return s;
}

static void test_depth(void **state)
{
    char *ok = chain(SG_MAX_DEPTH - 1);
    expect_ok(ok);
    free(ok);

    /* 10 000 levels: one TOO_DEEP error (no stack overflow) */
    char *deep = chain(10000);
    sg_diags d;
    sg_program *p = load(deep, &d);
    assert_int_equal(d.nerrors, 1);
    assert_int_equal(d.items[0].id, SG_E_TOO_DEEP);
    assert_string_equal(d.items[0].msg, "nesting deeper than 256 levels");
    /* lowering refuses a program with errors, with a diagnostic */
    ir ir;
    ir_init(&ir);
    assert_false(sg_lower_material(p, "m", &ir, &d));
    assert_int_equal(d.nerrors, 2);
    ir_free(&ir);
    sg_free(p);
    sg_diags_free(&d);
    free(deep);
}

static void test_large_scope_is_linear(void **state)
{
    /* 200 000 chained nodes in one material: resolves (iteratively) */
    int n = 200000;
    size_t cap = (size_t)n * 64 + 100;
    char *s = malloc(cap);
    size_t o = (size_t)snprintf(s, cap, "material m {\n node n0 : terrain.slope\n");
    for (int i = 1; i < n; i++)
        o += (size_t)snprintf(s + o, cap - o, " node n%d : abs { x = n%d.out }\n", i, i - 1);
    snprintf(s + o, cap - o, " out mask = n%d.out\n}\n", n - 1);
    expect_ok(s);
    free(s);
}

static void test_several_errors(void **state)
{
    sg_diags d;
    sg_program *p = load("material m {\n"
                         "  node a : nope\n"
                         "  node b : add { a = 1, b = zz }\n"
                         "  node c : add { a = terrain.uv, b = terrain.normal }\n"
                         "  out mask = q.out\n"
                         "}\n", &d);
    assert_int_equal(d.nerrors, 4);
    int lines[4] = { 0 };
    for (int i = 0; i < 4; i++)
        lines[i] = d.items[i].loc.line;
    /* one error per bad line, in any order */
    for (int want = 2; want <= 5; want++) {
        bool seen = false;
        for (int i = 0; i < 4; i++)
            seen |= lines[i] == want;
        assert_true(seen);
    }
    sg_free(p);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unknown_names),
        cmocka_unit_test(test_suggest),
        cmocka_unit_test(test_types),
        cmocka_unit_test(test_missing_and_duplicate),
        cmocka_unit_test(test_cycles),
        cmocka_unit_test(test_depth),
        cmocka_unit_test(test_large_scope_is_linear),
        cmocka_unit_test(test_several_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
