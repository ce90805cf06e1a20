/* test_nodes.c — the standard node library (the .sg files of nodes/) through the real
 * front end: each node is instanced in a tiny material (sg_load_string +
 * sg_lower_material), and its CPU reference (ir_eval, double) is checked
 * against values computed by hand, at the ends of its range too; a few
 * interval checks show the ends are exact for the scene analysis.  Last,
 * Billingsley's selection (examples/billingsley) against Eq. 2 with his
 * Tables 1 and 2 computed directly.
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

/* ---- helpers ----------------------------------------------------------- */

/* Flat ground at the origin; textures read through `sample` if set. */
static ir_env flat_env(void)
{
    ir_env e;
    memset(&e, 0, sizeof e);
    e.normal[1] = 1;
    return e;
}

/* The material text: `import "nodes/FILE"`, node n of type NODE, and the
 * given output (mask by default). */
static char *material(const char *file, const char *output, const char *value,
                      const char *node)
{
    size_t n = strlen(file) + strlen(output) + strlen(value) + strlen(node) + 256;
    char *s = malloc(n);
    snprintf(s, n,
             "import \"nodes/masks.sg\"\n"
             "import \"nodes/%s\"\n"
             "material t {\n"
             "    node n : %s\n"
             "    out %s = %s\n"
             "}\n",
             file, node, output, value);
    return s;
}

/* Evaluate `value` (e.g. "n.out", "n.uv.x") as material t's mask. */
static double evalf(const char *file, const ir_env *env, const char *value,
                    const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static double evalf(const char *file, const ir_env *env, const char *value,
                    const char *fmt, ...)
{
    char node[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(node, sizeof node, fmt, ap);
    va_end(ap);
    char *text = material(file, "mask", value, node);
    lowered l;
    lowered_load(&l, text);
    double out[4];
    ir_eval(&l.ir, ir_find_root(&l.ir, "t.mask"), env, out);
    lowered_free(&l);
    free(text);
    return out[0];
}

/* Same for a vec3 value as the albedo. */
static void eval3(const char *file, const ir_env *env, const char *value,
                  const char *node, double out[4])
{
    char *text = material(file, "albedo", value, node);
    lowered l;
    lowered_load(&l, text);
    ir_eval(&l.ir, ir_find_root(&l.ir, "t.albedo"), env, out);
    lowered_free(&l);
    free(text);
}

/* Interval of `value` as the mask over a region. */
static ir_iv intervalv(const char *file, const ir_ienv *env, const char *value,
                       const char *node)
{
    char *text = material(file, "mask", value, node);
    lowered l;
    lowered_load(&l, text);
    ir_iv out[4];
    ir_interval(&l.ir, ir_find_root(&l.ir, "t.mask"), env, out);
    lowered_free(&l);
    free(text);
    return out[0];
}

static ir_iv intervalf(const char *file, const ir_ienv *env, const char *node)
{
    return intervalv(file, env, "n.out", node);
}

static ir_ienv wide_ienv(void)
{
    ir_ienv e;
    memset(&e, 0, sizeof e);
    e.height = (ir_iv){0, 5000};
    e.slope = (ir_iv){0, 1};
    for (int i = 0; i < 3; i++) {
        e.normal[i] = (ir_iv){-1, 1};
        e.position[i] = (ir_iv){0, 1000};
    }
    e.normal[1] = (ir_iv){0, 1};
    e.uv[0] = e.uv[1] = (ir_iv){0, 1};
    e.view_distance = (ir_iv){0, INFINITY};
    return e;
}

#define NEAR(a, b) do {                                                       \
        double a_ = (a), b_ = (b);                                            \
        if (!(fabs(a_ - b_) <= 1e-12 * (1 + fabs(b_))))                       \
            fail_msg("%s = %.17g, expected %.17g", #a, a_, b_);               \
    } while (0)

/* ---- masks.sg (Listing 2) ----------------------------------------------- */

static void test_listing2(void **state)
{
    ir_env e = flat_env();
    /* overlay: value1 < 0.5 ? 2 v1 v2 : 1 - 2 (1 - v1)(1 - v2), then lerp */
    NEAR(evalf("blend.sg", &e, "n.out", "overlay { base = 0.3, blend = 0.6 }"), 2 * 0.3 * 0.6);
    NEAR(evalf("blend.sg", &e, "n.out", "overlay { base = 0.7, blend = 0.6 }"), 1 - 2 * 0.3 * 0.4);
    NEAR(evalf("blend.sg", &e, "n.out", "overlay { base = 0.7, blend = 0.6, opacity = 0.25 }"),
         0.7 + (1 - 2 * 0.3 * 0.4 - 0.7) * 0.25);
    NEAR(evalf("blend.sg", &e, "n.out", "overlay { base = 0.5, blend = 0.2 }"), 1 - 2 * 0.5 * 0.8);
    /* it leaves 0 and 1 alone */
    NEAR(evalf("blend.sg", &e, "n.out", "overlay { base = 0.0, blend = 0.9 }"), 0.0);
    NEAR(evalf("blend.sg", &e, "n.out", "overlay { base = 1.0, blend = 0.1 }"), 1.0);
    /* scaleContrast = saturate((value - 0.5) * contrast + 0.5) */
    NEAR(evalf("blend.sg", &e, "n.out", "scale_contrast { value = 0.6, contrast = 2.0 }"), 0.7);
    NEAR(evalf("blend.sg", &e, "n.out", "scale_contrast { value = 0.9, contrast = 4.0 }"), 1.0);
    NEAR(evalf("blend.sg", &e, "n.out", "scale_contrast { value = 0.1, contrast = 4.0 }"), 0.0);
}

/* ---- bands.sg ------------------------------------------------------------ */

static void test_ramps(void **state)
{
    ir_env e = flat_env();
    const char *f = "bands.sg";
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = -3.0, lo = 0.2, hi = 0.6 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = 0.2, lo = 0.2, hi = 0.6 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = 0.5, lo = 0.2, hi = 0.6 }"), 0.75);
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = 0.6, lo = 0.2, hi = 0.6 }"), 1.0);
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = 7.0, lo = 0.2, hi = 0.6 }"), 1.0);
    /* lo == hi: a hard step, no 0/0 */
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = 0.4, lo = 0.4, hi = 0.4 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = 0.401, lo = 0.4, hi = 0.4 }"), 1.0);
    NEAR(evalf(f, &e, "n.out", "linear_ramp { x = 0.399, lo = 0.4, hi = 0.4 }"), 0.0);

    /* Hermite: t = 0.25 -> 0.25^2 (3 - 0.5) */
    NEAR(evalf(f, &e, "n.out", "smooth_ramp { x = 0.3, lo = 0.2, hi = 0.6 }"), 0.0625 * 2.5);
    NEAR(evalf(f, &e, "n.out", "smooth_ramp { x = 0.4, lo = 0.2, hi = 0.6 }"), 0.5);
    NEAR(evalf(f, &e, "n.out", "smooth_ramp { x = 0.1, lo = 0.2, hi = 0.6 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "smooth_ramp { x = 0.9, lo = 0.2, hi = 0.6 }"), 1.0);
    NEAR(evalf(f, &e, "n.out", "smooth_ramp { x = 0.5, lo = 0.5, hi = 0.5 }"), 0.0);
}

static void test_bands(void **state)
{
    ir_env e = flat_env();
    const char *f = "bands.sg";
    const char *b = "band { x = %g, lo = 10.0, hi = 20.0, fade = 4.0 }";
    NEAR(evalf(f, &e, "n.out", b, 15.0), 1.0);
    NEAR(evalf(f, &e, "n.out", b, 10.0), 1.0);
    NEAR(evalf(f, &e, "n.out", b, 20.0), 1.0);
    NEAR(evalf(f, &e, "n.out", b, 8.0), 0.5);
    NEAR(evalf(f, &e, "n.out", b, 21.0), 0.75);
    NEAR(evalf(f, &e, "n.out", b, 6.0), 0.0);
    NEAR(evalf(f, &e, "n.out", b, 24.0), 0.0);
    NEAR(evalf(f, &e, "n.out", b, -100.0), 0.0);
    /* fade 0: a hard band */
    NEAR(evalf(f, &e, "n.out", "band { x = 10.0, lo = 10.0, hi = 20.0, fade = 0.0 }"), 1.0);
    NEAR(evalf(f, &e, "n.out", "band { x = 9.999, lo = 10.0, hi = 20.0, fade = 0.0 }"), 0.0);

    e.height = 1030;
    NEAR(evalf(f, &e, "n.out", "height_band { lo = 1000.0, hi = 1020.0, fade = 40.0 }"), 0.75);
    e.height = 990;
    NEAR(evalf(f, &e, "n.out", "height_band { lo = 1000.0, hi = 1020.0, fade = 40.0 }"), 0.75);
    e.slope = 0.35;
    NEAR(evalf(f, &e, "n.out", "slope_band { lo = 0.1, hi = 0.3, fade = 0.1 }"), 0.5);
    e.slope = 0.0;
    NEAR(evalf(f, &e, "n.out", "slope_band { lo = 0.1, hi = 0.3, fade = 0.1 }"), 0.0);
}

static void test_facing(void **state)
{
    ir_env e = flat_env();
    const char *f = "bands.sg";
    NEAR(evalf(f, &e, "n.out", "facing { }"), 1.0);
    /* dir need not be unit length */
    e.normal[0] = 0; e.normal[1] = 0; e.normal[2] = -1;
    NEAR(evalf(f, &e, "n.out", "facing { dir = vec3(0.0, 0.0, -2.0) }"), 1.0);
    NEAR(evalf(f, &e, "n.out", "facing { dir = vec3(0.0, 0.0, 2.0) }"), 0.0);
    e.normal[0] = 1; e.normal[2] = 0;
    NEAR(evalf(f, &e, "n.out", "facing { }"), 0.0);
    e.normal[0] = 0.6; e.normal[1] = 0.8;
    NEAR(evalf(f, &e, "n.out", "facing { lo = 0.5, hi = 1.0 }"), 0.6);
    NEAR(evalf(f, &e, "n.out", "facing { dir = vec3(1.0, 0.0, 0.0), lo = 0.0, hi = 0.5 }"), 1.0);
}

static void test_altitude_slope(void **state)
{
    ir_env e = flat_env();
    const char *f = "bands.sg";
    const char *n = "altitude_slope { h_lo = 2000.0, h_hi = 2500.0, s_lo = 0.2, s_hi = 0.4 }";
    e.height = 2250; e.slope = 0.1;
    NEAR(evalf(f, &e, "n.out", "%s", n), 0.5);
    e.height = 2600; e.slope = 0.3;
    NEAR(evalf(f, &e, "n.out", "%s", n), 0.5);
    e.height = 2600; e.slope = 0.0;
    NEAR(evalf(f, &e, "n.out", "%s", n), 1.0);
    e.height = 1000; e.slope = 0.0;
    NEAR(evalf(f, &e, "n.out", "%s", n), 0.0);
    e.height = 3000; e.slope = 0.5;
    NEAR(evalf(f, &e, "n.out", "%s", n), 0.0);
}

static void test_band_intervals(void **state)
{
    /* the ends are exact, so the analysis can call a material absent or opaque */
    ir_ienv e = wide_ienv();
    e.height = (ir_iv){3000, 3100};
    ir_iv r = intervalf("bands.sg", &e, "height_band { lo = 1000.0, hi = 2000.0, fade = 50.0 }");
    assert_true(r.lo == 0 && r.hi == 0);
    e.height = (ir_iv){1200, 1800};
    r = intervalf("bands.sg", &e, "height_band { lo = 1000.0, hi = 2000.0, fade = 50.0 }");
    assert_true(r.lo >= 1 && r.hi <= 1);
    e.height = (ir_iv){950, 1200};
    r = intervalf("bands.sg", &e, "height_band { lo = 1000.0, hi = 2000.0, fade = 100.0 }");
    assert_true(r.lo <= 0.5 && r.hi >= 1 && r.lo >= 0);
    e.slope = (ir_iv){0.5, 0.6};
    r = intervalf("bands.sg", &e, "altitude_slope { }");
    assert_true(r.lo == 0 && r.hi == 0);
    /* the reference lies inside the bounds at sample points */
    for (int k = 0; k <= 10; k++) {
        ir_env p = flat_env();
        p.height = 950 + 25.0 * k;
        double v = evalf("bands.sg", &p, "n.out", "height_band { lo = 1000.0, hi = 2000.0, fade = 100.0 }");
        ir_ienv q = wide_ienv();
        q.height = (ir_iv){p.height, p.height};
        ir_iv b = intervalf("bands.sg", &q, "height_band { lo = 1000.0, hi = 2000.0, fade = 100.0 }");
        assert_true(b.lo <= v && v <= b.hi);
    }
}

/* ---- blend.sg ------------------------------------------------------------ */

static void test_blend(void **state)
{
    ir_env e = flat_env();
    const char *f = "blend.sg";
    NEAR(evalf(f, &e, "n.out", "screen { a = 0.3, b = 0.6 }"), 1 - 0.7 * 0.4);
    NEAR(evalf(f, &e, "n.out", "screen { a = 0.3, b = 0.6, opacity = 0.5 }"), 0.3 + (0.72 - 0.3) * 0.5);
    NEAR(evalf(f, &e, "n.out", "screen { a = 1.0, b = 0.2 }"), 1.0);
    NEAR(evalf(f, &e, "n.out", "screen { a = 0.0, b = 0.2 }"), 0.2);
    NEAR(evalf(f, &e, "n.out", "screen { a = 0.0, b = 0.0 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "blend_min { a = 0.3, b = 0.6 }"), 0.3);
    NEAR(evalf(f, &e, "n.out", "blend_min { a = 0.6, b = 0.3, opacity = 0.5 }"), 0.45);
    NEAR(evalf(f, &e, "n.out", "blend_max { a = 0.3, b = 0.6 }"), 0.6);
    NEAR(evalf(f, &e, "n.out", "blend_max { a = 0.3, b = 0.6, opacity = 0.5 }"), 0.45);
    NEAR(evalf(f, &e, "n.out", "blend_max { a = 0.8, b = 0.6 }"), 0.8);
    const char *r = "remap { x = %g, in_lo = 1.0, in_hi = 3.0, out_lo = 10.0, out_hi = 20.0 }";
    NEAR(evalf(f, &e, "n.out", r, 2.0), 15.0);
    NEAR(evalf(f, &e, "n.out", r, 1.0), 10.0);
    NEAR(evalf(f, &e, "n.out", r, 3.0), 20.0);
    NEAR(evalf(f, &e, "n.out", r, 5.0), 30.0);      /* unclamped */
    const char *rc = "remap_clamped { x = %g, in_lo = 1.0, in_hi = 3.0, out_lo = 1.0, out_hi = 0.0 }";
    NEAR(evalf(f, &e, "n.out", rc, 1.5), 0.75);
    NEAR(evalf(f, &e, "n.out", rc, 5.0), 0.0);
    NEAR(evalf(f, &e, "n.out", rc, -5.0), 1.0);
    double c[4];
    eval3(f, &e, "n.out", "tint { x = 0.25, dark = vec3(0.0, 0.2, 1.0), light = vec3(1.0, 0.6, 1.0) }", c);
    NEAR(c[0], 0.25);
    NEAR(c[1], 0.3);
    NEAR(c[2], 1.0);
    eval3(f, &e, "n.out", "tint { x = 1.0, dark = vec3(0.0, 0.2, 1.0), light = vec3(1.0, 0.6, 0.5) }", c);
    NEAR(c[1], 0.6);
}

/* ---- projection.sg -------------------------------------------------------- */

/* A texture that reads back its coordinates: rgba = (u, v, 0.25, 1). */
static void sample_uv(void *user, int tex, double u, double v, double rgba[4])
{
    rgba[0] = u;
    rgba[1] = v;
    rgba[2] = 0.25;
    rgba[3] = 1;
}

static void test_projection(void **state)
{
    ir_env e = flat_env();
    const char *f = "projection.sg";
    e.position[0] = 10; e.position[1] = 4; e.position[2] = 20;
    NEAR(evalf(f, &e, "n.uv.x", "top_down_uv { scale = 2.0 }"), 5.0);
    NEAR(evalf(f, &e, "n.uv.y", "top_down_uv { scale = 2.0 }"), 10.0);
    /* a quarter turn: (x, z) -> (-z, x) */
    const char *rot = "top_down_uv { scale = 2.0, rotation = 1.5707963267948966, offset = vec2(0.5, 0.25) }";
    NEAR(evalf(f, &e, "n.uv.x", "%s", rot), -10.0 + 0.5);
    NEAR(evalf(f, &e, "n.uv.y", "%s", rot), 5.0 + 0.25);

    e.sample = sample_uv;
    NEAR(evalf(f, &e, "n.out.g", "top_down { tex = \"textures/rock.png\", scale = 4.0 }"), 5.0);
    NEAR(evalf(f, &e, "n.out.r", "side_x { tex = \"textures/rock.png\", scale = 2.0 }"), 10.0);
    NEAR(evalf(f, &e, "n.out.g", "side_x { tex = \"textures/rock.png\", scale = 2.0 }"), 2.0);
    NEAR(evalf(f, &e, "n.out.r", "side_z { tex = \"textures/rock.png\", scale = 2.0 }"), 5.0);
    NEAR(evalf(f, &e, "n.out.g", "side_z { tex = \"textures/rock.png\", scale = 2.0 }"), 2.0);

    /* tri-planar: flat ground reads the top-down plane only */
    const char *tp = "triplanar { tex = \"textures/rock.png\", scale = 2.0, sharpness = %g }";
    NEAR(evalf(f, &e, "n.out.r", tp, 4.0), 5.0);
    NEAR(evalf(f, &e, "n.out.g", tp, 4.0), 10.0);
    /* a tilted normal: weights |n|^k / sum */
    e.normal[0] = 0.6; e.normal[1] = 0.8; e.normal[2] = 0;
    double wx = 0.6, wy = 0.8;    /* sharpness 1 */
    double ux = 20 / 2.0, uy = 10 / 2.0;   /* side_x reads z, top-down reads x */
    NEAR(evalf(f, &e, "n.out.r", tp, 1.0), (wx * ux + wy * uy) / (wx + wy));
    wx = 0.36; wy = 0.64;           /* sharpness 2 */
    NEAR(evalf(f, &e, "n.out.r", tp, 2.0), (wx * ux + wy * uy) / (wx + wy));
    /* weights sum to 1: the constant channel stays constant */
    NEAR(evalf(f, &e, "n.out.b", tp, 3.0), 0.25);
    /* below the cutoff (0.02 by default) a weight is 0, the rest
     * renormalised: n = (0.3, 0.954, 0) at sharpness 4 weighs x by 0.0097,
     * so only the top-down plane is read; cutoff 0 blends both */
    e.normal[0] = 0.3; e.normal[1] = sqrt(1 - 0.09); e.normal[2] = 0;
    NEAR(evalf(f, &e, "n.out.r", tp, 4.0), uy);
    const char *tp0 = "triplanar { tex = \"textures/rock.png\", scale = 2.0, sharpness = %g, "
                      "cutoff = 0.0 }";
    wx = pow(0.3, 4); wy = pow(1 - 0.09, 2);
    NEAR(evalf(f, &e, "n.out.r", tp0, 4.0), (wx * ux + wy * uy) / (wx + wy));
}

/* A normal map of one constant texel. */
static double map_rgb[3];
static void sample_const(void *user, int tex, double u, double v, double rgba[4])
{
    rgba[0] = map_rgb[0];
    rgba[1] = map_rgb[1];
    rgba[2] = map_rgb[2];
    rgba[3] = 1;
}

static void test_normal_map(void **state)
{
    ir_env e = flat_env();
    e.sample = sample_const;
    const char *f = "projection.sg";
    const char *nm = "normal_map { tex = \"textures/rock_normal.png\", uv = vec2(0.0, 0.0), strength = %g }";
    double n[4];
    char node[256];
    /* a flat texel gives the terrain normal back */
    map_rgb[0] = 0.5; map_rgb[1] = 0.5; map_rgb[2] = 1.0;
    e.normal[0] = -0.6; e.normal[1] = 0.8; e.normal[2] = 0;
    snprintf(node, sizeof node, nm, 1.0);
    eval3(f, &e, "n.normal", node, n);
    NEAR(n[0], -0.6); NEAR(n[1], 0.8); NEAR(n[2], 0.0);
    /* on flat ground the map's x is +x (u), its y is +z (v) */
    e.normal[0] = 0; e.normal[1] = 1;
    map_rgb[0] = 1.0; map_rgb[1] = 0.5; map_rgb[2] = 1.0;
    snprintf(node, sizeof node, nm, 0.5);
    eval3(f, &e, "n.normal", node, n);
    double l = sqrt(0.25 + 1);
    NEAR(n[0], 0.5 / l); NEAR(n[1], 1 / l); NEAR(n[2], 0.0);
    map_rgb[0] = 0.5; map_rgb[1] = 0.0; map_rgb[2] = 1.0;
    snprintf(node, sizeof node, nm, 1.0);
    eval3(f, &e, "n.normal", node, n);
    NEAR(n[0], 0.0); NEAR(n[1], 1 / sqrt(2.0)); NEAR(n[2], -1 / sqrt(2.0));
    /* strength 0: the terrain normal whatever the map says */
    snprintf(node, sizeof node, nm, 0.0);
    eval3(f, &e, "n.normal", node, n);
    NEAR(n[1], 1.0);
    /* on a slope the result stays unit length and the tangent follows the slope */
    e.normal[0] = -0.6; e.normal[1] = 0.8;
    map_rgb[0] = 1.0; map_rgb[1] = 0.5; map_rgb[2] = 0.5;   /* t = (1, 0, 0): the tangent */
    snprintf(node, sizeof node, nm, 1.0);
    eval3(f, &e, "n.normal", node, n);
    NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0);
    NEAR(n[0] * -0.6 + n[1] * 0.8, 0.0);     /* perpendicular to the normal */
    NEAR(n[0], 0.8); NEAR(n[1], 0.6);
}

/* ---- noise.sg ---------------------------------------------------------------- */

/* nodes/noise.sg's perm289 (lowered_hash_perm chains two) */
static double perm(double x) { return fmod((34 * x + 1) * x, 289); }

static void test_hashes(void **state)
{
    ir_env e = flat_env();
    const char *f = "noise.sg";
    NEAR(evalf(f, &e, "n.out", "perm289 { x = 0.0 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "perm289 { x = 1.0 }"), 35.0);
    NEAR(evalf(f, &e, "n.out", "perm289 { x = 10.0 }"), 3410.0 - 11 * 289);
    NEAR(evalf(f, &e, "n.out", "perm289 { x = 577.0 }"), perm(577));
    int pts[][2] = {{3, 7}, {0, 0}, {-1, -2}, {288, 288}, {1000, -999}};
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++) {
        double x = pts[k][0], y = pts[k][1];
        double h = evalf(f, &e, "n.out", "hash_perm { i = vec2(%g, %g) }", x, y);
        NEAR(h, lowered_hash_perm(x, y));
        assert_true(h >= 0 && h <= 288.0 / 289);
        /* periodic with 289 cells */
        NEAR(evalf(f, &e, "n.out", "hash_perm { i = vec2(%g, %g) }", x + 289, y - 578), h);
    }
    double d = 3 * 12.9898 + 7 * 78.233, s = sin(d) * 43758.5453;
    NEAR(evalf(f, &e, "n.out", "hash_sin { i = vec2(3.0, 7.0) }"), s - floor(s));
    NEAR(evalf(f, &e, "n.out.x", "fade_hermite { f = vec2(0.25, 1.0) }"), 0.15625);
    NEAR(evalf(f, &e, "n.out.y", "fade_hermite { f = vec2(0.25, 1.0) }"), 1.0);
    NEAR(evalf(f, &e, "n.out.x", "fade_quintic { f = vec2(0.25, 0.0) }"),
         0.25 * 0.25 * 0.25 * (0.25 * (0.25 * 6 - 15) + 10));
    NEAR(evalf(f, &e, "n.out.y", "fade_quintic { f = vec2(0.25, 0.0) }"), 0.0);
}

static double value_noise(double x, double y)
{
    double ix = floor(x), iy = floor(y), fx = x - ix, fy = y - iy;
    double ux = fx * fx * (3 - 2 * fx), uy = fy * fy * (3 - 2 * fy);
    double a = lowered_hash_perm(ix, iy), b = lowered_hash_perm(ix + 1, iy);
    double c = lowered_hash_perm(ix, iy + 1), d = lowered_hash_perm(ix + 1, iy + 1);
    double x0 = a + (b - a) * ux, x1 = c + (d - c) * ux;
    return x0 + (x1 - x0) * uy;
}

static double grad(double ix, double iy, double dx, double dy)
{
    double a = lowered_hash_perm(ix, iy) * 6.283185307179586;
    return cos(a) * dx + sin(a) * dy;
}

static double gradient_noise(double x, double y)
{
    double ix = floor(x), iy = floor(y), fx = x - ix, fy = y - iy;
    double ux = fx * fx * fx * (fx * (fx * 6 - 15) + 10);
    double uy = fy * fy * fy * (fy * (fy * 6 - 15) + 10);
    double a = grad(ix, iy, fx, fy), b = grad(ix + 1, iy, fx - 1, fy);
    double c = grad(ix, iy + 1, fx, fy - 1), d = grad(ix + 1, iy + 1, fx - 1, fy - 1);
    double x0 = a + (b - a) * ux, x1 = c + (d - c) * ux;
    return x0 + (x1 - x0) * uy;
}

static void test_alu_noise(void **state)
{
    ir_env e = flat_env();
    const char *f = "noise.sg";
    /* at lattice points: the hash / zero */
    NEAR(evalf(f, &e, "n.out", "value_noise { p = vec2(3.0, 7.0) }"), lowered_hash_perm(3, 7));
    NEAR(evalf(f, &e, "n.out", "value_noise { p = vec2(3.5, 7.0) }"),
         0.5 * (lowered_hash_perm(3, 7) + lowered_hash_perm(4, 7)));
    NEAR(evalf(f, &e, "n.out", "gradient_noise { p = vec2(3.0, 7.0) }"), 0.0);
    NEAR(evalf(f, &e, "n.unorm", "gradient_noise { p = vec2(3.0, 7.0) }"), 0.5);
    /* anywhere: the hand-written formula, and the stated ranges */
    unsigned s = 12345;
    for (int k = 0; k < 12; k++) {
        s = s * 1103515245u + 12345u;
        double x = (s >> 8) % 100000 / 997.0 - 40;
        s = s * 1103515245u + 12345u;
        double y = (s >> 8) % 100000 / 991.0 - 40;
        double v = evalf(f, &e, "n.out", "value_noise { p = vec2(%.17g, %.17g) }", x, y);
        NEAR(v, value_noise(x, y));
        assert_true(v >= 0 && v <= 1);
        double g = evalf(f, &e, "n.out", "gradient_noise { p = vec2(%.17g, %.17g) }", x, y);
        NEAR(g, gradient_noise(x, y));
        assert_true(fabs(g) <= 0.7072);
        double u = evalf(f, &e, "n.unorm", "gradient_noise { p = vec2(%.17g, %.17g) }", x, y);
        NEAR(u, fmin(1, fmax(0, 0.5 + 0.7071067811865476 * g)));
    }
}

static void test_alu_fbm(void **state)
{
    ir_env e = flat_env();
    const char *f = "noise.sg";
    double x = 2.3, y = -5.7;
    /* octave k at p * 2^k + shifts, amplitude 0.5^k, divided by the sum */
    double px = x, py = y, sum = 0, norm = 0, amp = 1;
    for (int k = 0; k < 4; k++) {
        sum += amp * value_noise(px, py);
        norm += amp;
        amp *= 0.5;
        px = px * 2 + 17.31;
        py = py * 2 + 9.77;
    }
    double v4 = evalf(f, &e, "n.out", "value_fbm4 { p = vec2(%g, %g) }", x, y);
    NEAR(v4, sum / norm);
    /* the octave count as an input: 4 is value_fbm4, 1 is value_noise */
    NEAR(evalf(f, &e, "n.out", "value_fbm { p = vec2(%g, %g), octaves = 4.0 }", x, y), v4);
    NEAR(evalf(f, &e, "n.out", "value_fbm { p = vec2(%g, %g), octaves = 1.0 }", x, y), value_noise(x, y));
    NEAR(evalf(f, &e, "n.out", "value_fbm { p = vec2(%g, %g), octaves = 8.0 }", x, y),
         evalf(f, &e, "n.out", "value_fbm8 { p = vec2(%g, %g) }", x, y));
    double v6 = evalf(f, &e, "n.out", "value_fbm6 { p = vec2(%g, %g) }", x, y);
    assert_true(v6 >= 0 && v6 <= 1 && fabs(v6 - v4) > 1e-9);

    px = x; py = y; sum = 0; norm = 0; amp = 1;
    for (int k = 0; k < 2; k++) {
        sum += amp * gradient_noise(px, py);
        norm += amp;
        amp *= 0.5;
        px = px * 2 + 17.31;
        py = py * 2 + 9.77;
    }
    NEAR(evalf(f, &e, "n.out", "gradient_fbm2 { p = vec2(%g, %g) }", x, y), sum / norm);
    double u = evalf(f, &e, "n.unorm", "gradient_fbm4 { p = vec2(%g, %g) }", x, y);
    assert_true(u >= 0 && u <= 1);
}

static void test_noise_intervals(void **state)
{
    /* over a wide region the bounds are the noises' stated ranges (not the
     * much wider ones interval arithmetic gives for the blends) */
    ir_ienv e = wide_ienv();
    const char *f = "noise.sg";
    ir_iv r = intervalv(f, &e, "n.out", "value_noise { p = terrain.position.xz }");
    assert_true(r.lo == 0 && r.hi == 1);
    r = intervalv(f, &e, "n.out", "gradient_noise { p = terrain.position.xz }");
    assert_true(r.lo == -0.7072 && r.hi == 0.7072);
    r = intervalv(f, &e, "n.unorm", "gradient_fbm4 { p = terrain.position.xz }");
    assert_true(r.lo >= 0 && r.hi <= 1);
    r = intervalv(f, &e, "n.out", "value_fbm6 { p = terrain.position.xz }");
    assert_true(r.lo >= 0 && r.hi <= 1 + 1e-12);
    /* tri-planar stays finite when the normal is unknown */
    r = intervalv("projection.sg", &e, "n.out.r", "triplanar { tex = \"textures/rock.png\" }");
    assert_true(isfinite(r.lo) && isfinite(r.hi));
}

/* A smooth, non-periodic "texture" for texture fBm: red = f(u, v). */
static double tex_f(double u, double v) { return 0.5 + 0.4 * sin(3.1 * u + 1.7 * v); }
static void sample_f(void *user, int tex, double u, double v, double rgba[4])
{
    rgba[0] = tex_f(u, v);
    rgba[1] = rgba[2] = 0;
    rgba[3] = 1;
}

static void test_texture_fbm(void **state)
{
    ir_env e = flat_env();
    e.sample = sample_f;
    const char *f = "noise.sg";
    for (int n = 2; n <= 8; n += 2) {
        double ux = 0.3, uy = 0.8, sum = 0, norm = 0, amp = 1;
        for (int k = 0; k < n; k++) {
            sum += amp * tex_f(ux, uy);
            norm += amp;
            amp *= 0.5;
            ux = ux * 2 + 0.37;
            uy = uy * 2 + 0.61;
        }
        NEAR(evalf(f, &e, "n.out", "texture_fbm%d { tex = \"textures/noise.png\", uv = vec2(0.3, 0.8) }", n),
             sum / norm);
    }
    /* lacunarity and gain are inputs */
    double s = tex_f(0.1, 0.2) + 0.25 * tex_f(0.1 * 3 + 0.37, 0.2 * 3 + 0.61);
    NEAR(evalf(f, &e, "n.out",
               "texture_fbm2 { tex = \"textures/noise.png\", uv = vec2(0.1, 0.2), lacunarity = 3.0, gain = 0.25 }"),
         s / 1.25);
    /* a constant texture gives its constant back (the fBm is normalised) */
    e.sample = sample_const;
    map_rgb[0] = 0.3;
    NEAR(evalf(f, &e, "n.out", "texture_fbm6 { tex = \"textures/noise.png\", uv = vec2(0.1, 0.2) }"), 0.3);
}

/* ---- masks.sg: multiply and linear_blend ------------------------------------ */

static void test_mask_products(void **state)
{
    ir_env e = flat_env();
    const char *f = "masks.sg";
    NEAR(evalf(f, &e, "n.out", "multiply { a = 0.6, b = 0.5 }"), 0.3);
    NEAR(evalf(f, &e, "n.out", "multiply { a = 0.25, b = 0.8 }"), 0.2);
    /* the ends: 0 cuts everything, 1 leaves the other mask alone */
    NEAR(evalf(f, &e, "n.out", "multiply { a = 0.0, b = 0.9 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "multiply { a = 1.0, b = 0.9 }"), 0.9);
    NEAR(evalf(f, &e, "n.out", "multiply { a = 1.0, b = 1.0 }"), 1.0);
    /* a wire too: slope 0.4 cut by 0.5 */
    e.slope = 0.4;
    NEAR(evalf(f, &e, "n.out", "multiply { a = terrain.slope, b = 0.5 }"), 0.2);

    /* linear_blend = a + (b - a) t, t = 0.5 by default */
    e = flat_env();
    NEAR(evalf(f, &e, "n.out", "linear_blend { a = 0.2, b = 0.6 }"), 0.4);
    NEAR(evalf(f, &e, "n.out", "linear_blend { a = 0.2, b = 0.6, t = 0.25 }"), 0.3);
    NEAR(evalf(f, &e, "n.out", "linear_blend { a = 0.2, b = 0.6, t = 0.0 }"), 0.2);
    NEAR(evalf(f, &e, "n.out", "linear_blend { a = 0.2, b = 0.6, t = 1.0 }"), 0.6);
    NEAR(evalf(f, &e, "n.out", "linear_blend { a = 0.0, b = 1.0, t = 0.7 }"), 0.7);
    NEAR(evalf(f, &e, "n.out", "linear_blend { a = 1.0, b = 0.0, t = 0.7 }"), 0.3);
}

/* ---- stochastic.sg ------------------------------------------------------------ */

/* pow2_cell by its definition: cell_min * 2^k, k = #{j = 1..15 : r >= 2^j}. */
static double pow2_cell(double footprint, double cell_min)
{
    double r = footprint / cell_min;
    int k = 0;
    for (int j = 1; j <= 15; j++)
        k += r >= ldexp(1, j);
    return cell_min * ldexp(1, k);
}

/* world_hash by hand: q = floor(p / cell); two chained hash_perm lookups
 * over (x, z) + seed, (y, x), (z, y), u = fract(h2 + h3 / 289). */
static double world_hash(const double p[3], double cell, double seed)
{
    double qx = floor(p[0] / cell), qy = floor(p[1] / cell), qz = floor(p[2] / cell);
    double h1 = lowered_hash_perm(qx + seed, qz + seed);
    double h2 = lowered_hash_perm(qy + 289 * h1, qx + 289 * h1);
    double h3 = lowered_hash_perm(qz + 289 * h2, qy + 289 * h2);
    double s = h2 + h3 / 289;
    return s - floor(s);
}

static void test_stochastic(void **state)
{
    ir_env e = flat_env();
    const char *f = "stochastic.sg";
    /* pow2_cell: the cell stays cell_min below twice it, then doubles at
     * every power of two of footprint / cell_min, up to 2^15 */
    const char *pc = "pow2_cell { footprint = %.17g, cell_min = 0.05 }";
    NEAR(evalf(f, &e, "n.out", pc, 0.0), 0.05);
    NEAR(evalf(f, &e, "n.out", pc, 0.0999), 0.05);
    NEAR(evalf(f, &e, "n.out", pc, 0.1), 0.1);
    NEAR(evalf(f, &e, "n.out", pc, 0.15), 0.1);
    NEAR(evalf(f, &e, "n.out", pc, 0.2), 0.2);
    NEAR(evalf(f, &e, "n.out", pc, 3.3), 3.2);           /* r = 66: 2^6 */
    NEAR(evalf(f, &e, "n.out", pc, 0.05 * 32768), 0.05 * 32768);
    NEAR(evalf(f, &e, "n.out", pc, 1e9), 0.05 * 32768);  /* capped at 2^15 */
    for (double fp = 0.01; fp < 3000; fp *= 2.7) {
        double c = evalf(f, &e, "n.out", pc, fp);
        NEAR(c, pow2_cell(fp, 0.05));
        assert_true(c <= fmax(fp, 0.05) && (c == 0.05 || 2 * c > fp));
    }

    /* world_hash: hand-computed, in [0, 1), constant inside a cell */
    const double pts[][3] = {{0, 0, 0}, {3.5, 120.25, -7.75}, {1000.2, 2000.7, 3000.9},
                             {-50.0, 0.5, 12.0}};
    for (size_t k = 0; k < sizeof pts / sizeof pts[0]; k++) {
        memcpy(e.position, pts[k], sizeof e.position);
        double u = evalf(f, &e, "n.out", "world_hash { cell = 2.0 }");
        NEAR(u, world_hash(pts[k], 2.0, 0));
        NEAR(evalf(f, &e, "n.out", "world_hash { cell = 2.0, seed = 74.0 }"),
             world_hash(pts[k], 2.0, 74));
        assert_true(u >= 0 && u < 1);
        double inside[3] = {2 * floor(pts[k][0] / 2) + 1.9, 2 * floor(pts[k][1] / 2) + 0.1,
                            2 * floor(pts[k][2] / 2) + 1.0};
        memcpy(e.position, inside, sizeof e.position);
        NEAR(evalf(f, &e, "n.out", "world_hash { cell = 2.0 }"), u);
    }
    e.position[0] = 0.5; e.position[1] = 0.5; e.position[2] = 0.5;
    double u0 = evalf(f, &e, "n.out", "world_hash { cell = 1.0 }");
    e.position[0] = 1.5;                                  /* the next cell along x */
    assert_true(fabs(evalf(f, &e, "n.out", "world_hash { cell = 1.0 }") - u0) > 1e-6);

    /* stochastic_select: a Bernoulli draw u < m per layer, u from the cell
     * of distance * pixel_angle and the layer's seed (37 id) */
    e = flat_env();
    const double pos[3] = {412.3, 95.1, 77.7};
    memcpy(e.position, pos, sizeof e.position);
    e.view_distance = 100.0;
    const double cell = pow2_cell(100.0 * 0.0016, 0.05);
    const char *ss = "stochastic_select { T = %.17g, m = %.17g, id = %d.0 }";
    for (int id = 0; id < 3; id++) {
        double u = world_hash(pos, cell, 37.0 * id);
        assert_true(u > 0.01 && u < 0.99);
        /* m = 0: never drawn, coverage unchanged; m = 1: always */
        NEAR(evalf(f, &e, "n.weight", ss, 1.0, 0.0, id), 0.0);
        NEAR(evalf(f, &e, "n.T_next", ss, 1.0, 0.0, id), 1.0);
        NEAR(evalf(f, &e, "n.weight", ss, 1.0, 1.0, id), 1.0);
        NEAR(evalf(f, &e, "n.T_next", ss, 1.0, 1.0, id), 0.0);
        /* 0 < m < 1: drawn iff u < m */
        NEAR(evalf(f, &e, "n.weight", ss, 1.0, u + 0.005, id), 1.0);
        NEAR(evalf(f, &e, "n.T_next", ss, 1.0, u + 0.005, id), 0.0);
        NEAR(evalf(f, &e, "n.weight", ss, 1.0, u - 0.005, id), 0.0);
        NEAR(evalf(f, &e, "n.T_next", ss, 1.0, u - 0.005, id), 1.0);
        /* below a drawn layer (T = 0): nothing */
        NEAR(evalf(f, &e, "n.weight", ss, 0.0, 1.0, id), 0.0);
        NEAR(evalf(f, &e, "n.weight", ss, 0.0, u + 0.005, id), 0.0);
    }
    /* The draw frequencies are the alpha weights: a stack of a (id 1,
     * m 0.3) over b (id 2, m 0.6) over the bottom draws a with p 0.3, b
     * with 0.7 * 0.6 = 0.42, the bottom with 0.28, over 4000 cells; within
     * 4 sigma, which also needs the two seeds' fields independent. */
    int na = 0, nb = 0, ncells = 4000;
    for (int k = 0; k < ncells; k++) {
        const double q[3] = {cell * (k % 71) + 0.5 * cell, 3.0, cell * (k / 71) + 0.5 * cell};
        bool a = world_hash(q, cell, 37.0) < 0.3;
        bool b = !a && world_hash(q, cell, 74.0) < 0.6;
        na += a;
        nb += b;
    }
    const double pa = 0.3, pb = 0.42;
    assert_true(fabs(na - ncells * pa) < 4 * sqrt(ncells * pa * (1 - pa)));
    assert_true(fabs(nb - ncells * pb) < 4 * sqrt(ncells * pb * (1 - pb)));
    /* and the graph draws what the hand-computed hash says, at a few cells */
    for (int k = 0; k < 4; k++) {
        const double q[3] = {cell * (7 * k + 3) + 0.25 * cell, 3.0, cell * (13 * k) + 0.75 * cell};
        memcpy(e.position, q, sizeof e.position);
        NEAR(evalf(f, &e, "n.weight", ss, 1.0, 0.3, 1), world_hash(q, cell, 37.0) < 0.3);
    }
}

/* ---- noise.sg: the longer fBms ---------------------------------------------- */

static void test_fbm_octaves(void **state)
{
    ir_env e = flat_env();
    const char *f = "noise.sg";
    const double x = -1.7, y = 4.2;
    for (int n = 6; n <= 8; n += 2) {
        double px = x, py = y, sum = 0, norm = 0, amp = 1;
        for (int k = 0; k < n; k++) {
            sum += amp * gradient_noise(px, py);
            norm += amp;
            amp *= 0.5;
            px = px * 2 + 17.31;
            py = py * 2 + 9.77;
        }
        double g = evalf(f, &e, "n.out", "gradient_fbm%d { p = vec2(%g, %g) }", n, x, y);
        NEAR(g, sum / norm);
        assert_true(fabs(g) <= 0.7072);
        double un = evalf(f, &e, "n.unorm", "gradient_fbm%d { p = vec2(%g, %g) }", n, x, y);
        NEAR(un, fmin(1, fmax(0, 0.5 + 0.7071067811865476 * sum / norm)));
        /* lacunarity and gain are inputs: gain 0 leaves the first octave */
        NEAR(evalf(f, &e, "n.out", "gradient_fbm%d { p = vec2(%g, %g), gain = 0.0 }", n, x, y),
             gradient_noise(x, y));
    }
    /* at a lattice point the first octave is 0 (gradient noise vanishes
     * there); the later ones, shifted off the lattice, are not */
    double px = 3, py = 5, sum = 0, norm = 0, amp = 1;
    for (int k = 0; k < 8; k++) {
        sum += amp * gradient_noise(px, py);
        norm += amp;
        amp *= 0.5;
        px = px * 2 + 17.31;
        py = py * 2 + 9.77;
    }
    NEAR(evalf(f, &e, "n.out", "gradient_fbm8 { p = vec2(3.0, 5.0) }"), sum / norm);

    /* texture fBm 4 and 8 at the ends of their range: all-0 and all-1
     * textures give 0 and 1 exactly (normalised sums) */
    e.sample = sample_const;
    for (int n = 4; n <= 8; n += 4)
        for (int v = 0; v <= 1; v++) {
            map_rgb[0] = v;
            NEAR(evalf(f, &e, "n.out", "texture_fbm%d { tex = \"textures/noise.png\", uv = vec2(0.4, 0.9) }", n),
                 (double)v);
        }
}


/* ---- compositors ------------------------------------------------------------- */

static void test_compositors(void **state)
{
    ir_env e = flat_env();
    const char *f = "compositors_extra.sg";
    NEAR(evalf("compositors.sg", &e, "n.weight", "linear_alpha { T = 0.5, m = 0.3 }"), 0.15);
    NEAR(evalf("compositors.sg", &e, "n.T_next", "linear_alpha { T = 0.5, m = 0.3 }"), 0.35);
    const char *hb = "height_blend { T = %g, m = %g, h = %g, sharpness = %g }";
    /* 0 and 1 are left alone whatever the height */
    for (double h = 0; h <= 1; h += 0.25) {
        NEAR(evalf(f, &e, "n.weight", hb, 1.0, 0.0, h, 4.0), 0.0);
        NEAR(evalf(f, &e, "n.T_next", hb, 1.0, 0.0, h, 4.0), 1.0);
        NEAR(evalf(f, &e, "n.weight", hb, 1.0, 1.0, h, 4.0), 1.0);
        NEAR(evalf(f, &e, "n.T_next", hb, 1.0, 1.0, h, 4.0), 0.0);
    }
    NEAR(evalf(f, &e, "n.weight", hb, 1.0, 0.3, 0.5, 4.0), 0.3);        /* h = 0.5: alpha = m */
    NEAR(evalf(f, &e, "n.weight", hb, 1.0, 0.3, 0.9, 0.0), 0.3);        /* sharpness 0: linear alpha */
    NEAR(evalf(f, &e, "n.weight", hb, 0.5, 0.3, 1.0, 4.0), 0.5 * pow(0.3, 0.25));
    NEAR(evalf(f, &e, "n.T_next", hb, 0.5, 0.3, 0.0, 4.0), 0.5 - 0.5 * pow(0.3, 4.0));
    NEAR(evalf(f, &e, "n.weight", hb, 1.0, 1.5, 0.2, 4.0), 1.0);        /* masks saturate first */
    NEAR(evalf(f, &e, "n.out", "max_height_mask { h = 2.0, below = 1.0 }"), 1.0);
    NEAR(evalf(f, &e, "n.out", "max_height_mask { h = 1.0, below = 1.0 }"), 0.0);
    NEAR(evalf(f, &e, "n.out", "max_height_mask { h = -1.0, below = 1.0 }"), 0.0);
}

/* ---- Billingsley (Billingsley 2009): Eq. 2 with Tables 1 and 2 ---------------------- */

/* Table 1 (M1, M2, M3, Offset) and Table 2 (Scaling), dirt sand grass rock. */
static const double table1[4][4] = {
    {0.3, 0.2, 0.03, 1},
    {0.5, 0.1, 0.025, 0},
    {0, 0, 2, -0.7},
    {0.8, 2, 0.06, -1.5},
};
static const double table2[4] = {1, 1, 0.5, 3};

typedef struct bl_tex { const struct ir *ir; } bl_tex;

/* Smooth pseudo-random texture contents, one function per texture and
 * channel, so the test can recompute every sample. */
static double bl_fn(int which, int c, double u, double v)
{
    return 0.5 + 0.5 * sin(u * (7.1 + 3.3 * which + 1.3 * c) + v * (5.3 + 2.1 * c) + which + 0.7 * c);
}

static int bl_which(const char *file)
{
    return strstr(file, "perlin") ? 0 : strstr(file, "uniform") ? 1 : 2;
}

static void sample_bl(void *user, int tex, double u, double v, double rgba[4])
{
    const bl_tex *t = user;
    int w = bl_which(t->ir->textures[tex].file);
    for (int c = 0; c < 4; c++)
        rgba[c] = bl_fn(w, c, u, v);
}

static void test_billingsley(void **state)
{
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load("examples/billingsley/billingsley.sg", search, &d);
    assert_non_null(p);
    const char *names[4] = {"dirt", "sand", "grass", "rock"};
    ir ir;
    ir_init(&ir);
    for (int i = 0; i < 4; i++)
        if (!sg_lower_material(p, names[i], &ir, &d) || d.nerrors) {
            sg_diags_print(&d, stderr);
            fail();
        }
    ir_ref mask[4], height[4];
    for (int i = 0; i < 4; i++) {
        char r[64];
        snprintf(r, sizeof r, "%s.mask", names[i]);
        mask[i] = ir_find_root(&ir, r);
        snprintf(r, sizeof r, "%s.height", names[i]);
        height[i] = ir_find_root(&ir, r);
    }
    /* the three textures are the perlin, uniform and mapping files */
    bool seen[3] = {false, false, false};
    for (int t = 0; t < ir.ntextures; t++)
        seen[bl_which(ir.textures[t].file)] = true;
    assert_true(seen[0] && seen[1] && seen[2]);

    bl_tex user = {&ir};
    int chosen[4] = {0, 0, 0, 0};
    unsigned s = 777;
    int compared = 0;
    for (int k = 0; k < 3000; k++) {
        ir_env e;
        memset(&e, 0, sizeof e);
        e.sample = sample_bl;
        e.sample_user = &user;
        s = s * 1664525u + 1013904223u;
        e.position[0] = (s >> 8) % 40000 / 10.0;
        s = s * 1664525u + 1013904223u;
        e.position[2] = (s >> 8) % 40000 / 10.0;
        s = s * 1664525u + 1013904223u;
        e.height = (s >> 8) % 3000 / 10.0;
        s = s * 1664525u + 1013904223u;
        double a = (s >> 8) % 1000 / 1000.0 * 1.2, b = 0.7 * sin(3.0 * k);
        double n[3] = {sin(a) * cos(b), cos(a), sin(a) * sin(b)};
        memcpy(e.normal, n, sizeof n);
        e.position[1] = e.height;

        /* Eq. 2, directly: V from the texture samples, Weight from the
         * material mapping at (incline, 1 - (height - water) * 0.005) */
        double x = e.position[0], z = e.position[2];
        double V[4] = {bl_fn(0, 3, x * 0.001, z * 0.001), bl_fn(0, 3, x * 0.004, z * 0.004),
                       bl_fn(1, 0, x * 0.032, z * 0.032), 1};
        double incline = sqrt(n[0] * n[0] + n[2] * n[2]);
        double elev = 1 - (e.height - 45.0) * 0.005;
        double W[4] = {0, bl_fn(2, 0, incline, elev), bl_fn(2, 1, incline, elev),
                       bl_fn(2, 2, incline, elev)};
        double h[4];
        for (int i = 0; i < 4; i++)
            h[i] = V[0] * table1[i][0] + V[1] * table1[i][1] + V[2] * table1[i][2] +
                   table1[i][3] + W[i] * table2[i];
        int best = 0;                       /* his loop: the first maximum wins */
        for (int i = 1; i < 4; i++)
            if (h[i] > h[best])
                best = i;

        /* the graph: heights, and the selection made by the masks under
         * linear alpha, top first */
        double T = 1, w[4], hg[4], out[4];
        for (int i = 0; i < 4; i++) {
            ir_eval(&ir, height[i], &e, out);
            hg[i] = out[0];
            if (fabs(hg[i] - h[i]) > 1e-12)
                fail_msg("sample %d: %s height %.17g, Eq. 2 gives %.17g", k, names[i], hg[i], h[i]);
        }
        for (int i = 3; i >= 0; i--) {
            ir_eval(&ir, mask[i], &e, out);
            w[i] = T * out[0];
            T -= w[i];
        }
        /* skip exact near-ties, where rounding order could decide */
        double second = -INFINITY;
        for (int i = 0; i < 4; i++)
            if (i != best && h[i] > second)
                second = h[i];
        if (h[best] - second < 1e-9)
            continue;
        compared++;
        for (int i = 0; i < 4; i++)
            if (w[i] != (i == best ? 1.0 : 0.0))
                fail_msg("sample %d: weight of %s is %g, Eq. 2 picks %s", k, names[i], w[i], names[best]);
        assert_true(T == 0);
        chosen[best]++;
    }
    /* every material was selected somewhere, so the test can tell them apart */
    for (int i = 0; i < 4; i++)
        if (chosen[i] == 0)
            fail_msg("%s was never the highest material", names[i]);
    assert_true(compared > 2900);
    ir_free(&ir);
    sg_free(p);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_listing2),
        cmocka_unit_test(test_ramps),
        cmocka_unit_test(test_bands),
        cmocka_unit_test(test_facing),
        cmocka_unit_test(test_altitude_slope),
        cmocka_unit_test(test_band_intervals),
        cmocka_unit_test(test_blend),
        cmocka_unit_test(test_projection),
        cmocka_unit_test(test_normal_map),
        cmocka_unit_test(test_hashes),
        cmocka_unit_test(test_alu_noise),
        cmocka_unit_test(test_alu_fbm),
        cmocka_unit_test(test_texture_fbm),
        cmocka_unit_test(test_noise_intervals),
        cmocka_unit_test(test_mask_products),
        cmocka_unit_test(test_stochastic),
        cmocka_unit_test(test_fbm_octaves),
        cmocka_unit_test(test_compositors),
        cmocka_unit_test(test_billingsley),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
