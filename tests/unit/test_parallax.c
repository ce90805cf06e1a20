/* test_parallax.c — steep parallax mapping (nodes/parallax.sg) and the
 * view.direction input it reads, through the real front end.
 *
 * parallax4/8/16 unroll McGuire's loop (`t = 1; while (h(uv) < t) { t -= 1/N;
 * uv += offset/N }`); their CPU reference is checked against steps worked
 * out by hand on a step-shaped height texture, and against that loop written
 * directly in C on a few more textures; the interval bounds must hold the
 * reference and stay within [uv0, uv0 + offset].  parallax_offset is checked
 * against -V.xz / max(V.y, 0.25) * depth / scale with its distance fade.
 *
 * Runs from the repository root (CTest's working directory). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lowered.h"
#include "sg.h"

static const char *const search[] = {".", NULL};

#define NEAR(a, b) do {                                                       \
        double a_ = (a), b_ = (b);                                            \
        if (!(fabs(a_ - b_) <= 1e-12 * (1 + fabs(b_))))                       \
            fail_msg("%s = %.17g, expected %.17g", #a, a_, b_);               \
    } while (0)

/* Material t with node `px` as given; its mask is `mx`, its height `my`. */
static void lower(lowered *l, const char *node, const char *mx, const char *my)
{
    char text[1024];
    snprintf(text, sizeof text,
             "import \"nodes/parallax.sg\"\n"
             "material t {\n"
             "    node px : %s\n"
             "    out mask = %s\n"
             "    out height = %s\n"
             "}\n", node, mx, my);
    lowered_load(l, text);
}

/* ---- height textures (.r is the relief; every channel the same) --------- */

typedef double (*height_fn)(double u, double v);

static double h_step(double u, double v) { (void)v; return u < 0.3 ? 0.2 : 0.9; }
static double h_low(double u, double v) { (void)u; (void)v; return 0.0; }
static double h_high(double u, double v) { (void)u; (void)v; return 1.0; }
static double h_wave(double u, double v) { return 0.5 + 0.45 * sin(9.0 * u + 4.0 * v); }
static double h_ramp(double u, double v) { (void)v; return fmin(1.0, fmax(0.0, 1.2 - 2.0 * u)); }

static void sample_h(void *user, int tex, double u, double v, double rgba[4])
{
    (void)tex;
    height_fn h = *(height_fn *)user;
    rgba[0] = rgba[1] = rgba[2] = h(u, v);
    rgba[3] = 1.0;
}

/* The loop itself, written directly. */
static void loop_uv(height_fn h, int n, const double uv0[2], const double off[2],
                    double out[2])
{
    double t = 1.0, u = uv0[0], v = uv0[1];
    for (int k = 0; k < n && h(u, v) < t; k++) {
        t -= 1.0 / n;
        u += off[0] / n;
        v += off[1] / n;
    }
    out[0] = u;
    out[1] = v;
}

/* parallaxN's uv at uv0 with `off`, on height `h` (CPU reference). */
static void eval_uv(int n, height_fn h, const double uv0[2], const double off[2],
                    double out[2])
{
    char node[256];
    snprintf(node, sizeof node,
             "parallax%d { tex = \"textures/rock.png\", uv = terrain.uv, offset = vec2(%.17g, %.17g) }",
             n, off[0], off[1]);
    lowered l;
    lower(&l, node, "px.out.x", "px.out.y");
    ir_env e;
    memset(&e, 0, sizeof e);
    e.uv[0] = uv0[0];
    e.uv[1] = uv0[1];
    e.sample = sample_h;
    e.sample_user = &h;
    double x[4], y[4];
    ir_eval(&l.ir, ir_find_root(&l.ir, "t.mask"), &e, x);
    ir_eval(&l.ir, ir_find_root(&l.ir, "t.height"), &e, y);
    out[0] = x[0];
    out[1] = y[0];
    lowered_free(&l);
}

/* ---- tests --------------------------------------------------------------- */

/* Worked by hand: h = 0.2 for u < 0.3 and 0.9 after, uv0 = (0, 0.5),
 * offset = (1, 0).  Step k samples u = k/N against the layer 1 - k/N:
 *   N = 4:  u = 0, .25 (0.2 < 1, 0.2 < .75: misses), .5 (0.9 >= .5: hit)  -> u = 0.5
 *   N = 8:  u = 0 .. .25 miss (t >= .75), .375 (0.9 >= .625: hit)          -> u = 0.375
 *   N = 16: u = 0 .. .25 miss (t >= .75), .3125 (0.9 >= .6875: hit)        -> u = 0.3125 */
static void test_hand_steps(void **state)
{
    (void)state;
    const double uv0[2] = { 0.0, 0.5 }, off[2] = { 1.0, 0.0 };
    double uv[2];
    eval_uv(4, h_step, uv0, off, uv);
    NEAR(uv[0], 0.5);
    NEAR(uv[1], 0.5);
    eval_uv(8, h_step, uv0, off, uv);
    NEAR(uv[0], 0.375);
    eval_uv(16, h_step, uv0, off, uv);
    NEAR(uv[0], 0.3125);

    /* along -v at u = 0 the step is never reached: the ray meets the 0.2
     * floor at the first layer at or below it, k = 7 (t = 0.125), so
     * v = 0.5 - 0.25 * 7/8 */
    const double back[2] = { 0.0, -0.25 };
    eval_uv(8, h_step, uv0, back, uv);
    NEAR(uv[0], 0.0);
    NEAR(uv[1], 0.5 - 0.25 * 7.0 / 8.0);
    /* the ends of the range: no relief at all, and relief at the top */
    eval_uv(4, h_low, uv0, off, uv);
    NEAR(uv[0], 1.0);
    eval_uv(16, h_high, uv0, off, uv);
    NEAR(uv[0], 0.0);
    NEAR(uv[1], 0.5);
}

/* The unrolled graphs against the loop, on several textures and rays. */
static void test_against_loop(void **state)
{
    (void)state;
    const height_fn hs[] = { h_step, h_wave, h_ramp, h_low, h_high };
    const double rays[][4] = {   /* uv0, offset */
        { 0.0, 0.0, 1.0, 0.0 }, { 0.1, 0.3, 0.35, -0.2 }, { 0.7, 0.2, -0.6, 0.45 },
        { 0.25, 0.75, 0.05, 0.02 },
    };
    const int ns[] = { 4, 8, 16 };
    for (size_t h = 0; h < sizeof hs / sizeof hs[0]; h++)
        for (size_t r = 0; r < sizeof rays / sizeof rays[0]; r++)
            for (size_t i = 0; i < 3; i++) {
                double got[2], want[2];
                eval_uv(ns[i], hs[h], rays[r], rays[r] + 2, got);
                loop_uv(hs[h], ns[i], rays[r], rays[r] + 2, want);
                /* the graph computes uv0 + offset * (count / N), the loop
                 * adds offset / N count times: equal up to rounding */
                for (int c = 0; c < 2; c++)
                    if (!(fabs(got[c] - want[c]) <= 1e-12))
                        fail_msg("h %zu ray %zu N %d: uv[%d] = %.17g, loop %.17g",
                                 h, r, ns[i], c, got[c], want[c]);
            }
}

/* parallax_adaptive's uv (texels per repeat `texels`, 1 texel a step). */
static void eval_adaptive(height_fn h, double texels, const double uv0[2],
                          const double off[2], double out[2])
{
    char node[256];
    snprintf(node, sizeof node,
             "parallax_adaptive { tex = \"textures/rock.png\", uv = terrain.uv, "
             "offset = vec2(%.17g, %.17g), texels = %.17g }", off[0], off[1], texels);
    lowered l;
    lower(&l, node, "px.out.x", "px.out.y");
    ir_env e;
    memset(&e, 0, sizeof e);
    e.uv[0] = uv0[0];
    e.uv[1] = uv0[1];
    e.sample = sample_h;
    e.sample_user = &h;
    double x[4], y[4];
    ir_eval(&l.ir, ir_find_root(&l.ir, "t.mask"), &e, x);
    ir_eval(&l.ir, ir_find_root(&l.ir, "t.height"), &e, y);
    out[0] = x[0];
    out[1] = y[0];
    lowered_free(&l);
}

/* Steps by the ray's length in texels: the loop with N = clamp(ceil(|offset|
 * * texels), 1, 16) (the unrolled 16 steps, those from N on dead). */
static void test_adaptive_against_loop(void **state)
{
    (void)state;
    const height_fn hs[] = { h_step, h_wave, h_ramp, h_low, h_high };
    const double rays[][4] = {
        { 0.0, 0.0, 1.0, 0.0 }, { 0.1, 0.3, 0.35, -0.2 }, { 0.7, 0.2, -0.6, 0.45 },
        { 0.25, 0.75, 0.05, 0.02 }, { 0.5, 0.5, 0.0, 0.0 },
    };
    const double texels[] = { 2.0, 9.0, 30.0, 256.0 };
    int seen[17] = {0};
    for (size_t h = 0; h < sizeof hs / sizeof hs[0]; h++)
        for (size_t r = 0; r < sizeof rays / sizeof rays[0]; r++)
            for (size_t i = 0; i < sizeof texels / sizeof texels[0]; i++) {
                const double *o = rays[r] + 2;
                int n = (int)fmin(16, fmax(1, ceil(hypot(o[0], o[1]) * texels[i])));
                seen[n] = 1;
                double got[2], want[2];
                eval_adaptive(hs[h], texels[i], rays[r], o, got);
                loop_uv(hs[h], n, rays[r], o, want);
                for (int c = 0; c < 2; c++)
                    if (!(fabs(got[c] - want[c]) <= 1e-12))
                        fail_msg("h %zu ray %zu texels %g (N %d): uv[%d] = %.17g, loop %.17g",
                                 h, r, texels[i], n, c, got[c], want[c]);
            }
    /* the rays cover 1 step, a few, and the full 16 */
    assert_true(seen[1] && seen[2] && seen[9] && seen[16]);
}

/* Bounds: whatever the texture, the uv lies between uv0 and uv0 + offset. */
static void test_intervals(void **state)
{
    (void)state;
    lowered l;
    lower(&l, "parallax8 { tex = \"textures/rock.png\", uv = terrain.uv, offset = vec2(0.5, -0.25) }",
          "px.out.x", "px.out.y");
    ir_ienv e;
    memset(&e, 0, sizeof e);
    e.uv[0] = (ir_iv){ 0.1, 0.2 };
    e.uv[1] = (ir_iv){ 0.6, 0.7 };
    ir_iv x[4], y[4];
    ir_interval(&l.ir, ir_find_root(&l.ir, "t.mask"), &e, x);
    ir_interval(&l.ir, ir_find_root(&l.ir, "t.height"), &e, y);
    NEAR(x[0].lo, 0.1);
    NEAR(x[0].hi, 0.7);
    NEAR(y[0].lo, 0.35);
    NEAR(y[0].hi, 0.7);
    lowered_free(&l);

    /* parallax_offset over any camera: finite, at most 4 * depth / scale */
    lower(&l, "parallax_offset { scale = 2.0, depth = 0.5, fade = 100.0 }",
          "px.offset.x", "px.offset.y");
    e.view_distance = (ir_iv){ 0, INFINITY };
    ir_interval(&l.ir, ir_find_root(&l.ir, "t.mask"), &e, x);
    ir_interval(&l.ir, ir_find_root(&l.ir, "t.height"), &e, y);
    NEAR(x[0].lo, -1.0);
    NEAR(x[0].hi, 1.0);
    NEAR(y[0].lo, -1.0);
    NEAR(y[0].hi, 1.0);
    lowered_free(&l);
}

/* offset = -V.xz / max(V.y, 0.25) * depth * saturate(1 - dist / fade) / scale */
static void test_offset(void **state)
{
    (void)state;
    lowered l;
    lower(&l, "parallax_offset { scale = 2.0, depth = 0.5, fade = 100.0 }",
          "px.offset.x", "px.offset.y");
    ir_ref rx = ir_find_root(&l.ir, "t.mask"), ry = ir_find_root(&l.ir, "t.height");
    ir_env e;
    memset(&e, 0, sizeof e);
    double x[4], y[4];
    /* unset direction reads straight down: no shift */
    ir_eval(&l.ir, rx, &e, x);
    ir_eval(&l.ir, ry, &e, y);
    NEAR(x[0], 0.0);
    NEAR(y[0], 0.0);
    /* camera up and to the east (+x): the ray goes west into the relief */
    e.view_direction[0] = 0.6;
    e.view_direction[1] = 0.8;
    ir_eval(&l.ir, rx, &e, x);
    ir_eval(&l.ir, ry, &e, y);
    NEAR(x[0], -0.6 / 0.8 * 0.5 / 2.0);
    NEAR(y[0], 0.0);
    e.view_distance = 50.0;                      /* half faded */
    ir_eval(&l.ir, rx, &e, x);
    NEAR(x[0], -0.6 / 0.8 * 0.25 / 2.0);
    e.view_distance = 100.0;                     /* gone */
    ir_eval(&l.ir, rx, &e, x);
    NEAR(x[0], 0.0);
    /* grazing, camera to the south (+z): V.y held at 0.25 */
    e.view_distance = 0.0;
    e.view_direction[0] = 0.0;
    e.view_direction[1] = 0.1;
    e.view_direction[2] = sqrt(0.99);
    ir_eval(&l.ir, ry, &e, y);
    NEAR(y[0], -sqrt(0.99) / 0.25 * 0.5 / 2.0);
    lowered_free(&l);
}

/* The rock material uses it: its albedo depends on the view direction. */
static void test_rock_uses_parallax(void **state)
{
    (void)state;
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load("graphs/rock.sg", search, &d);
    ir g;
    ir_init(&g);
    assert_non_null(p);
    assert_true(sg_lower_material(p, "rock", &g, &d));
    assert_int_equal(d.nerrors, 0);
    ir_ref albedo = ir_find_root(&g, "rock.albedo"), mask = ir_find_root(&g, "rock.mask");
    height_fn h = h_wave;
    ir_env e;
    memset(&e, 0, sizeof e);
    e.normal[1] = 1.0;
    e.slope = 0.3;
    e.position[0] = 1.5;
    e.position[2] = 2.25;
    e.view_distance = 10.0;
    e.sample = sample_h;
    e.sample_user = &h;
    double a0[4], a1[4], m0[4], m1[4];
    e.view_direction[1] = 1.0;                       /* from straight above */
    ir_eval(&g, albedo, &e, a0);
    ir_eval(&g, mask, &e, m0);
    e.view_direction[0] = 0.8;                       /* from the east, low */
    e.view_direction[1] = 0.6;
    ir_eval(&g, albedo, &e, a1);
    ir_eval(&g, mask, &e, m1);
    assert_true(fabs(a0[0] - a1[0]) > 1e-6);         /* the surface moved */
    NEAR(m1[0], m0[0]);                              /* its border did not */
    ir_free(&g);
    sg_free(p);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_steps),
        cmocka_unit_test(test_against_loop),
        cmocka_unit_test(test_adaptive_against_loop),
        cmocka_unit_test(test_intervals),
        cmocka_unit_test(test_offset),
        cmocka_unit_test(test_rock_uses_parallax),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
