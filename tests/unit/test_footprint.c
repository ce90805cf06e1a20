/* test_footprint.c — footprint-filtered masks (issue 31: mask edges at 73 m
 * texels show no moiré at any distance): .sg's fwidth and nodes/footprint.sg.
 *   - fwidth lowers to |d/dx| + |d/dy| of its operand (ir_footprint): equal
 *     to that sum over the DINPUT leaves at random points, for position and
 *     height and for slope, which follows the normal one pixel over;
 *   - texture gradients still take slope and normal as fixed;
 *   - aa_ramp equals its formula (the ramp widened by min(fwidth, blur *
 *     (hi - lo)), centred), and the plain ramp where nothing moves;
 *   - the analysis stays sound and keeps its plateaus: over a slope region
 *     the interval of aa_altitude_slope holds every value at random points
 *     with any derivatives (huge ones too), and is exactly [0, 0] past the
 *     widest transition;
 *   - a composite of footprint masks compiles for every stage (glslang,
 *     spirv-val), reading splat_d_normal where it has gradients.
 * Runs from the repository root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compose.h"
#include "lowered.h"
#include "glsl_check.h"
#include "spv.h"

static double rnd(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rand() / RAND_MAX);
}

/* material t's mask = `value`, after the nodes `nodes` (footprint.sg
 * imported) */
static void load(lowered *l, const char *nodes, const char *value)
{
    char text[2048];
    snprintf(text, sizeof text,
             "import \"nodes/footprint.sg\"\n"
             "material t {\n%s\n    out mask = %s\n}\n", nodes, value);
    lowered_load(l, text);
}

/* a random terrain point with random derivatives of every moving input */
static ir_env random_env(double dscale)
{
    ir_env e;
    memset(&e, 0, sizeof e);
    double nx = rnd(-0.8, 0.8), nz = rnd(-0.8, 0.8), ny = rnd(0.2, 1.0);
    double len = sqrt(nx * nx + ny * ny + nz * nz);
    e.normal[0] = nx / len;
    e.normal[1] = ny / len;
    e.normal[2] = nz / len;
    e.slope = 1.0 - e.normal[1];
    e.height = rnd(2000, 4300);
    e.position[0] = rnd(0, 1e5);
    e.position[1] = e.height;
    e.position[2] = rnd(0, 1e5);
    e.view_distance = rnd(1, 1e4);
    for (int a = 0; a < 2; a++) {
        for (int k = 0; k < 3; k++) {
            e.d_input[a][IR_IN_POSITION][k] = rnd(-dscale, dscale) * 50;
            e.d_input[a][IR_IN_NORMAL][k] = rnd(-dscale, dscale);
        }
        e.d_input[a][IR_IN_HEIGHT][0] = e.d_input[a][IR_IN_POSITION][1];
        e.d_input[a][IR_IN_SLOPE][0] = -e.d_input[a][IR_IN_NORMAL][1];
    }
    return e;
}

static double mask_at(lowered *l, const ir_env *e)
{
    double out[4];
    ir_eval(&l->ir, ir_find_root(&l->ir, "t.mask"), e, out);
    return out[0];
}

static void test_fwidth_is_the_derivative_sum(void **state)
{
    (void)state;
    lowered a, s;
    load(&a, "    node k : mul { a = terrain.height, b = 3.0 }\n"
             "    node p : add { a = k.out, b = terrain.position.x }\n"
             "    node f : fwidth { x = p.out }", "f.out");
    load(&s, "    node f : fwidth { x = terrain.slope }", "f.out");
    for (int i = 0; i < 200; i++) {
        ir_env e = random_env(0.3);
        double want = 0, ws = 0;
        for (int ax = 0; ax < 2; ax++) {
            want += fabs(3 * e.d_input[ax][IR_IN_HEIGHT][0] + e.d_input[ax][IR_IN_POSITION][0]);
            /* slope = 1 - normal.y: the normal's step, not the slope's slot */
            ws += fabs(e.d_input[ax][IR_IN_NORMAL][1]);
        }
        CLOSE(mask_at(&a, &e), want, 1e-9 * (1 + want));
        CLOSE(mask_at(&s, &e), ws, 1e-12);
    }
    /* nothing moves: 0 */
    ir_env z = random_env(0);
    CLOSE(mask_at(&a, &z), 0, 0);
    CLOSE(mask_at(&s, &z), 0, 0);
    lowered_free(&a);
    lowered_free(&s);
}

/* texture gradients (the differentiate pass) keep taking the normal as
 * fixed: a uv made of the normal gets no gradient from it */
static void test_texture_gradients_ignore_curvature(void **state)
{
    (void)state;
    ir ir;
    ir_init(&ir);
    ir_ref n = ir_input(&ir, IR_IN_NORMAL);
    ir_ref s = ir_input(&ir, IR_IN_SLOPE);
    for (int a = 0; a < 2; a++) {
        ir_ref d = ir_derivative(&ir, n, a);
        const ir_node *dn = ir_get(&ir, d);
        assert_int_equal(dn->op, IR_OP_CONST);
        d = ir_derivative(&ir, s, a);
        assert_int_equal(ir_get(&ir, d)->op, IR_OP_CONST);
    }
    /* the footprint follows them */
    ir_ref f = ir_footprint(&ir, s);
    assert_int_not_equal(ir_get(&ir, f)->op, IR_OP_CONST);
    ir_free(&ir);
}

static double sat(double x) { return x < 0 ? 0 : x > 1 ? 1 : x; }

static void test_aa_ramp_formula(void **state)
{
    (void)state;
    lowered l, plain;
    load(&l, "    node r : aa_ramp { x = terrain.slope, lo = 0.1, hi = 0.16, blur = 3.0 }", "r.out");
    lowered_load(&plain, "import \"nodes/masks.sg\"\n"
                         "material t {\n"
                         "    node r : ramp { x = terrain.slope, lo = 0.1, hi = 0.16 }\n"
                         "    out mask = r.out\n}\n");
    for (int i = 0; i < 400; i++) {
        ir_env e = random_env(i < 200 ? 0.02 : 0.5);
        double f = fabs(e.d_input[0][IR_IN_NORMAL][1]) + fabs(e.d_input[1][IR_IN_NORMAL][1]);
        double w = 0.16 - 0.1, fc = f < 3 * w ? f : 3 * w;
        double want = sat((e.slope - (0.1 - fc / 2)) / (w + fc));
        CLOSE(mask_at(&l, &e), want, 1e-9);
        /* no footprint: the plain ramp */
        ir_env z = e;
        memset(z.d_input, 0, sizeof z.d_input);
        CLOSE(mask_at(&l, &z), mask_at(&plain, &z), 1e-12);
    }
    lowered_free(&l);
    lowered_free(&plain);
}

static void test_analysis_sound_with_plateaus(void **state)
{
    (void)state;
    lowered l;
    load(&l, "    node m : aa_altitude_slope { h_lo = 3300.0, h_hi = 3600.0, s_lo = 0.12, "
             "s_hi = 0.2, blur = 2.0 }", "m.out");
    ir_ref r = ir_find_root(&l.ir, "t.mask");
    for (int i = 0; i < 300; i++) {
        ir_ienv ie;
        memset(&ie, 0, sizeof ie);
        ir_ienv_domain(&ie);
        double s0 = rnd(0, 0.9), s1 = s0 + rnd(0, 0.1), h0 = rnd(2500, 4200), h1 = h0 + rnd(0, 200);
        ie.slope = (ir_iv){s0, s1};
        ie.height = (ir_iv){h0, h1};
        ir_iv b[4];
        ir_interval(&l.ir, r, &ie, b);
        for (int k = 0; k < 40; k++) {
            ir_env e = random_env(k & 1 ? 1e3 : 0.05);
            e.slope = rnd(s0, s1);
            e.height = rnd(h0, h1);
            e.position[1] = e.height;
            double v = mask_at(&l, &e);
            if (!(v >= b[0].lo && v <= b[0].hi))
                fail_msg("%.17g outside [%.17g, %.17g]", v, b[0].lo, b[0].hi);
        }
        /* past the widest transitions (blur 2: half of 2 widths beyond
         * each end) the analysis proves the mask 0 */
        bool low = h1 < 3300 - 300;                 /* height: lo - w */
        bool steep = s0 > 0.2 + 0.08;               /* slope:  hi + w */
        if (low || steep)
            assert_true(b[0].lo == 0 && b[0].hi == 0);
    }
    lowered_free(&l);
}

static const char LOOK[] =
    "import \"nodes/compositors.sg\"\n"
    "import \"nodes/footprint.sg\"\n"
    "material base {\n"
    "    out albedo = vec3(0.2, 0.3, 0.1)\n"
    "    out height = 0.5\n"
    "}\n"
    "material top {\n"
    "    node a : aa_altitude_slope { h_lo = 3300.0, h_hi = 3600.0, s_lo = 0.12, s_hi = 0.2 }\n"
    "    node f : aa_facing { dir = vec3(0.0, 0.0, -1.0), lo = 0.02, hi = 0.12 }\n"
    "    node b : aa_slope_band { lo = 0.05, hi = 0.14, fade = 0.03 }\n"
    "    node m1 : mul { a = a.out, b = f.out }\n"
    "    node m : max { a = m1.out, b = b.out }\n"
    "    out mask = m.out\n"
    "    out albedo = vec3(0.9, 0.9, 0.95)\n"
    "    out height = 0.7\n"
    "}\n";

static void test_composite_compiles(void **state)
{
    (void)state;
    static const char *const names[] = {"base", "top"};
    static const char *const search[] = {".", NULL};
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("footprint.sg", LOOK, search, &d);
    assert_non_null(p);
    ir src;
    ir_init(&src);
    bool ok = true;
    for (int i = 0; i < 2; i++)
        ok = ok && sg_lower_material(p, names[i], &src, &d);
    sg_diags_print(&d, stderr);
    assert_true(ok);
    splat_layout L;
    assert_true(splat_layout_init(&L, &src, p, "linear_alpha", names, 2, NULL, 0, &d));
    static const int mats[] = {1, 0};
    splat_compose_desc desc = {.materials = mats, .nmaterials = 2};
    splat_composite c;
    bool composed = splat_compose(&L, &desc, &c, &d);
    sg_diags_print(&d, stderr);
    assert_true(composed);
    int ug_slot[2] = {0, -1};
    static const char *const needles[] = {"splat_d_normal(0)", "splat_d_normal(1)", NULL};
    glsl_check_every_stage(&L, &c, ug_slot, needles);
    splat_composite_free(&c);
    splat_layout_free(&L);
    ir_free(&src);
    sg_free(p);
    sg_diags_free(&d);
}

int main(void)
{
    srand(31);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fwidth_is_the_derivative_sum),
        cmocka_unit_test(test_texture_gradients_ignore_curvature),
        cmocka_unit_test(test_aa_ramp_formula),
        cmocka_unit_test(test_analysis_sound_with_plateaus),
        cmocka_unit_test(test_composite_compiles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
