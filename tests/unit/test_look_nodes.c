/* test_look_nodes.c — the look nodes of the library against CPU references
 * written out here from their papers' formulas, at random points:
 *   nodes/detile.sg        hex_tile (Mikkelsen 2022) and detile's two
 *                          scales blended by view distance;
 *   nodes/variation.sg     macro_variation;
 *   nodes/normal_blend.sg  reoriented normal mapping and whiteout
 *                          (Barré-Brisebois and Hill 2012), tangent_to_world;
 *   nodes/cavity.sg        occlusion and ridge light from terrain.cavity.
 * The graphs are lowered through the real front end and evaluated with
 * ir_eval (double); textures read a smooth procedural function of the raw
 * uv, so a wrong offset or weight shows.  Runs from the repository root. */
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

/* ---- helpers ------------------------------------------------------------- */

static double rnd(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rand() / RAND_MAX);
}

static ir_env env_at(double x, double y, double z, double dist)
{
    ir_env e = lowered_env(x, y, z);
    e.view_distance = dist;
    return e;
}

/* ---- hex tiling ------------------------------------------------------------ */

/* Mikkelsen 2022, Listing 1 (TriangleGrid) and the blend of his hex2colTex
 * without rotation or contrast: three reads at per-vertex random offsets,
 * weights w^sharpness renormalised. */
static void hex_ref(double u, double v, double grid, double sharp, double out[4])
{
    double gx = u * grid, gy = v * grid;
    double skx = gx, sky = -0.57735027 * gx + 1.15470054 * gy;
    double bx = floor(skx), by = floor(sky);
    double fx = skx - bx, fy = sky - by, z = 1.0 - fx - fy;
    double s = -z >= 0 ? 1 : 0, s2 = 2 * s - 1;
    double w[3] = {-z * s2, s - fy * s2, s - fx * s2};
    double vx[3] = {bx + s, bx + s, bx + 1 - s}, vy[3] = {by + s, by + 1 - s, by + s};
    double sum = 0;
    for (int c = 0; c < 4; c++)
        out[c] = 0;
    for (int k = 0; k < 3; k++) {
        double h1 = lowered_hash_perm(vx[k], vy[k]);
        double k1 = floor(289 * h1 + 0.5);        /* the integer h1 stands for */
        double h2 = lowered_hash_perm(vy[k] + k1, vx[k] + k1);
        double c[4];
        lowered_texture(u + h1, v + h2, c);
        double p = pow(fabs(w[k]), sharp);
        sum += p;
        for (int j = 0; j < 4; j++)
            out[j] += p * c[j];
    }
    for (int c = 0; c < 4; c++)
        out[c] /= sum;
}

static void test_hex_tile(void **state)
{
    (void)state;
    srand(2022);
    int far_apart = 0;
    for (int i = 0; i < 300; i++) {
        double u = rnd(-40, 40), v = rnd(-40, 40);
        double sharp = i % 3 == 0 ? 4.0 : rnd(1, 12);
        ir_env e = env_at(0, 0, 0, 0);
        char node[256];
        snprintf(node, sizeof node,
                 "hex_tile { tex = tx, uv = vec2(%.17g, %.17g), sharpness = %.17g }", u, v,
                 sharp);
        double got[4], want[4];
        lowered_eval_node("detile.sg", &e, "albedo", "n.out.rgb", node, got);
        hex_ref(u, v, 3.4641016, sharp, want);
        for (int c = 0; c < 3; c++)
            CLOSE(got[c], want[c], 1e-9);
        /* not the plain read: the offsets move it */
        double plain[4];
        lowered_texture(u, v, plain);
        far_apart += fabs(plain[0] - want[0]) > 0.02;
    }
    assert_true(far_apart > 100);

    /* at a triangle-grid vertex one copy alone shows (its weight is 1):
     * skewed (3, 5) is uv (3, (5 + 3 / sqrt3 ... )): take the vertex's uv */
    double sk[2] = {3, 5};
    double gx = sk[0], gy = (sk[1] + 0.57735027 * gx) / 1.15470054;
    double u = gx / 3.4641016, v = gy / 3.4641016;
    ir_env e = env_at(0, 0, 0, 0);
    char node[256];
    snprintf(node, sizeof node, "hex_tile { tex = tx, uv = vec2(%.17g, %.17g) }", u, v);
    double got[4], one[4];
    lowered_eval_node("detile.sg", &e, "albedo", "n.out.rgb", node, got);
    double h1 = lowered_hash_perm(3, 5), k1 = floor(289 * h1 + 0.5);
    double h2 = lowered_hash_perm(5 + k1, 3 + k1);
    lowered_texture(u + h1, v + h2, one);
    for (int c = 0; c < 3; c++)
        CLOSE(got[c], one[c], 1e-6);
}

/* detile: top-down projection at two scales, mixed by smoothstep of the
 * view distance times far_amount. */
static void test_detile(void **state)
{
    (void)state;
    srand(5);
    for (int i = 0; i < 120; i++) {
        double x = rnd(-500, 500), z = rnd(-500, 500), d = rnd(0, 150);
        double amount = i % 2 ? 1.0 : 0.6;
        ir_env e = env_at(x, rnd(0, 50), z, d);
        char node[256];
        snprintf(node, sizeof node, "detile { tex = tx, far_amount = %.17g }", amount);
        double got[4], near[4], far[4];
        lowered_eval_node("detile.sg", &e, "albedo", "n.out.rgb", node, got);
        hex_ref(x / 2.0, z / 2.0, 3.4641016, 4.0, near);
        hex_ref(x / 9.0, z / 9.0, 3.4641016, 4.0, far);
        double t = fmin(1, fmax(0, (d - 25.0) / 55.0));
        t = t * t * (3 - 2 * t) * amount;
        for (int c = 0; c < 3; c++)
            CLOSE(got[c], near[c] + (far[c] - near[c]) * t, 1e-9);
        if (d < 25)
            for (int c = 0; c < 3; c++)
                CLOSE(got[c], near[c], 1e-12);
    }
}

/* ---- macro variation ------------------------------------------------------- */

static double fade(double f) { return f * f * (3 - 2 * f); }

static double value_noise(double x, double y)
{
    double ix = floor(x), iy = floor(y), fx = fade(x - ix), fy = fade(y - iy);
    double a = lowered_hash_perm(ix, iy), b = lowered_hash_perm(ix + 1, iy);
    double c = lowered_hash_perm(ix, iy + 1), d = lowered_hash_perm(ix + 1, iy + 1);
    double x0 = a + (b - a) * fx, x1 = c + (d - c) * fx;
    return fmin(1, fmax(0, x0 + (x1 - x0) * fy));
}

static void test_macro_variation(void **state)
{
    (void)state;
    srand(77);
    const double alb[3] = {0.45, 0.38, 0.22}, tint[3] = {0.8, 1.0, 0.6};
    double lo = 1, hi = 0;
    for (int i = 0; i < 200; i++) {
        double x = rnd(-5000, 5000), z = rnd(-5000, 5000);
        ir_env e = env_at(x, 0, z, 0);
        char node[512];
        snprintf(node, sizeof node,
                 "macro_variation { albedo = vec3(%g, %g, %g), scale = 150.0, brightness = 0.3,"
                 " tint = vec3(%g, %g, %g), tint_amount = 0.5, seed = 3.0 }",
                 alb[0], alb[1], alb[2], tint[0], tint[1], tint[2]);
        double got[4];
        lowered_eval_node("variation.sg", &e, "albedo", "n.out", node, got);
        double px = x / 150 + 3, pz = z / 150 + 3;
        double n = (value_noise(px, pz) + 0.5 * value_noise(2 * px + 17.31, 2 * pz + 9.77)) / 1.5;
        double f = 1 + 0.3 * (2 * n - 1);
        for (int c = 0; c < 3; c++) {
            double tm = 1 + (tint[c] - 1) * (0.5 * n);
            CLOSE(got[c], fmin(1, fmax(0, alb[c] * f * tm)), 1e-9);
        }
        lo = fmin(lo, got[1] / alb[1]);
        hi = fmax(hi, got[1] / alb[1]);
    }
    /* it varies: the green channel (tint 1) swings by the brightness */
    assert_true(lo < 0.9 && hi > 1.1);
    /* brightness 0, tint_amount 0: unchanged */
    ir_env e = env_at(123, 0, 456, 0);
    double got[4];
    lowered_eval_node("variation.sg", &e, "albedo", "n.out",
              "macro_variation { albedo = vec3(0.3, 0.2, 0.1), brightness = 0.0 }", got);
    CLOSE(got[0], 0.3, 1e-12);
    CLOSE(got[2], 0.1, 1e-12);
}

/* ---- normal blending -------------------------------------------------------- */

static void norm3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] /= l;
}

/* A random unpacked tangent-space normal, z > 0.2. */
static void rnd_normal(double n[3])
{
    n[0] = rnd(-0.8, 0.8);
    n[1] = rnd(-0.8, 0.8);
    n[2] = rnd(0.2, 1.0);
    norm3(n);
}

/* Rotate d by the rotation that takes (0, 0, 1) to b (Rodrigues about
 * (0,0,1) x b): RNM's definition, computed another way than its formula. */
static void rotate_to(const double b[3], const double d[3], double r[3])
{
    double k[3] = {-b[1], b[0], 0};       /* (0,0,1) x b, |k| = sin */
    double s = sqrt(k[0] * k[0] + k[1] * k[1]), c = b[2];
    if (s < 1e-12) {
        memcpy(r, d, 3 * sizeof *d);
        return;
    }
    for (int i = 0; i < 2; i++)
        k[i] /= s;
    double kd = k[0] * d[0] + k[1] * d[1];
    double kx[3] = {k[1] * d[2], -k[0] * d[2], k[0] * d[1] - k[1] * d[0]};
    for (int i = 0; i < 3; i++)
        r[i] = d[i] * c + kx[i] * s + k[i] * kd * (1 - c);
}

static void test_normal_blend(void **state)
{
    (void)state;
    srand(2012);
    ir_env e = env_at(0, 0, 0, 0);
    for (int i = 0; i < 200; i++) {
        double b[3], d[3], want[3], got[4];
        rnd_normal(b);
        rnd_normal(d);
        char node[512];
        snprintf(node, sizeof node,
                 "rnm_blend { base = vec3(%.17g, %.17g, %.17g), detail = vec3(%.17g, %.17g, %.17g) }",
                 b[0], b[1], b[2], d[0], d[1], d[2]);
        lowered_eval_node("normal_blend.sg", &e, "albedo", "n.out", node, got);
        rotate_to(b, d, want);
        for (int c = 0; c < 3; c++)
            CLOSE(got[c], want[c], 1e-9);
        snprintf(node, sizeof node,
                 "whiteout_blend { a = vec3(%.17g, %.17g, %.17g), b = vec3(%.17g, %.17g, %.17g) }",
                 b[0], b[1], b[2], d[0], d[1], d[2]);
        lowered_eval_node("normal_blend.sg", &e, "albedo", "n.out", node, got);
        double w[3] = {b[0] + d[0], b[1] + d[1], b[2] * d[2]};
        norm3(w);
        for (int c = 0; c < 3; c++)
            CLOSE(got[c], w[c], 1e-12);
    }
    /* a flat detail leaves the base; a flat base gives the detail */
    double got[4];
    lowered_eval_node("normal_blend.sg", &e, "albedo", "n.out",
              "rnm_blend { base = vec3(0.6, 0.0, 0.8), detail = vec3(0.0, 0.0, 1.0) }", got);
    CLOSE(got[0], 0.6, 1e-12);
    CLOSE(got[2], 0.8, 1e-12);
    lowered_eval_node("normal_blend.sg", &e, "albedo", "n.out",
              "rnm_blend { base = vec3(0.0, 0.0, 1.0), detail = vec3(0.0, 0.6, 0.8) }", got);
    CLOSE(got[1], 0.6, 1e-12);
    CLOSE(got[2], 0.8, 1e-12);
    /* unpack: 2c - 1, slopes scaled */
    lowered_eval_node("normal_blend.sg", &e, "albedo", "n.out",
              "unpack_normal { c = vec3(0.75, 0.25, 1.0), strength = 0.5 }", got);
    CLOSE(got[0], 0.25, 1e-12);
    CLOSE(got[1], -0.25, 1e-12);
    CLOSE(got[2], 1.0, 1e-12);
    /* tangent_to_world on a slope: the tangent-space z is the terrain normal,
     * x follows +x (tangent T ∝ (n.y, -n.x, 0)) */
    e.normal[0] = -0.6;
    e.normal[1] = 0.8;
    e.normal[2] = 0;
    lowered_eval_node("normal_blend.sg", &e, "albedo", "n.out",
              "tangent_to_world { n = vec3(0.0, 0.0, 1.0) }", got);
    CLOSE(got[0], -0.6, 1e-12);
    CLOSE(got[1], 0.8, 1e-12);
    lowered_eval_node("normal_blend.sg", &e, "albedo", "n.out",
              "tangent_to_world { n = vec3(1.0, 0.0, 0.0) }", got);
    CLOSE(got[0], 0.8, 1e-12);
    CLOSE(got[1], 0.6, 1e-12);
}

/* ---- cavity ------------------------------------------------------------------ */

static void test_cavity_ao(void **state)
{
    (void)state;
    static const double cav[] = {-30, -10, -4, 0, 2.5, 5, 9.9, 10, 40};
    for (size_t i = 0; i < sizeof cav / sizeof cav[0]; i++) {
        ir_env e = env_at(0, 0, 0, 0);
        e.cavity = cav[i];
        double got[4];
        lowered_eval_node("cavity.sg", &e, "mask", "n.out",
                  "cavity_ao { depth = 10.0, strength = 0.6, ridge = 0.2 }", got);
        double o = fmin(1, fmax(0, cav[i] / 10)), r = fmin(1, fmax(0, -cav[i] / 10));
        CLOSE(got[0], 1 - 0.6 * o + 0.2 * r, 1e-12);
        lowered_eval_node("cavity.sg", &e, "albedo", "n.out",
                  "cavity_darken { albedo = vec3(0.5, 0.4, 0.3), depth = 10.0, strength = 0.6 }",
                  got);
        CLOSE(got[1], 0.4 * (1 - 0.6 * o), 1e-12);
    }
}

/* ---- in a composite: every GLSL variant compiles ------------------------------ */

static const char LOOK[] =
    "import \"nodes/compositors.sg\"\n"
    "import \"nodes/height_softmax.sg\"\n"
    "import \"nodes/detile.sg\"\n"
    "import \"nodes/variation.sg\"\n"
    "import \"nodes/normal_blend.sg\"\n"
    "import \"nodes/cavity.sg\"\n"
    "import \"nodes/projection.sg\"\n"
    "texture noise { file = \"graphs/textures/noise.png\" }\n"
    "texture nrm { file = \"graphs/textures/rock_normal.png\" }\n"
    "material base {\n"
    "    node d : detile { tex = noise, scale = 3.0 }\n"
    "    node v : macro_variation { albedo = d.out.rgb, tint = vec3(0.9, 1.0, 0.7), tint_amount = 0.4 }\n"
    "    node c : cavity_darken { albedo = v.out, ridge = 0.1 }\n"
    "    node u1 : top_down_uv { scale = 4.0 }\n"
    "    node a : sample { tex = nrm, uv = u1.uv }\n"
    "    node u2 : mul { a = u1.uv, b = 5.0 }\n"
    "    node b : sample { tex = nrm, uv = u2.out }\n"
    "    node na : unpack_normal { c = a.rgb }\n"
    "    node nb : unpack_normal { c = b.rgb, strength = 0.5 }\n"
    "    node r : rnm_blend { base = na.out, detail = nb.out }\n"
    "    node w : whiteout_blend { a = na.out, b = nb.out }\n"
    "    node m : mix { a = r.out, b = w.out, t = 0.5 }\n"
    "    node n : tangent_to_world { n = m.out }\n"
    "    out albedo = c.out\n"
    "    out normal = n.out\n"
    "    out height = d.out.r\n"
    "}\n"
    "material top {\n"
    "    node k : mul { a = terrain.cavity, b = 0.1 }\n"
    "    node m : saturate { x = k.out }\n"
    "    out mask = m.out\n"
    "    out albedo = vec3(0.3, 0.3, 0.3)\n"
    "    out height = 0.7\n"
    "}\n";

static void test_composite_compiles(void **state)
{
    (void)state;
    static const char *const names[] = {"base", "top"};
    static const char *const search[] = {".", NULL};
    static const char *const compositors[] = {"linear_alpha", "height_softmax"};
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("look.sg", LOOK, search, &d);
    assert_non_null(p);
    ir src;
    ir_init(&src);
    bool ok = true;
    for (int i = 0; i < 2; i++)
        ok = ok && sg_lower_material(p, names[i], &src, &d);
    sg_diags_print(&d, stderr);
    assert_true(ok);
    assert_int_equal(d.nerrors, 0);
    for (int k = 0; k < 2; k++) {
        splat_layout L;
        assert_true(splat_layout_init(&L, &src, p, compositors[k], names, 2, NULL, 0, &d));
        static const int mats[] = {1, 0};
        splat_compose_desc desc = {.materials = mats, .nmaterials = 2};
        splat_composite c;
        assert_true(splat_compose(&L, &desc, &c, &d));
        int ug_slot[2] = {0, -1};
        static const char *const needles[] = {"splat_cavity()", NULL};
        glsl_check_every_stage(&L, &c, ug_slot, needles);
        splat_composite_free(&c);
        splat_layout_free(&L);
    }
    ir_free(&src);
    sg_free(p);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hex_tile),
        cmocka_unit_test(test_detile),
        cmocka_unit_test(test_macro_variation),
        cmocka_unit_test(test_normal_blend),
        cmocka_unit_test(test_cavity_ao),
        cmocka_unit_test(test_composite_compiles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
