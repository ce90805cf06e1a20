/* test_look_gpu.c — the look nodes of issue 31 on the device: hex_tile and
 * detile (nodes/detile.sg), macro_variation (variation.sg), rnm_blend and
 * whiteout_blend (normal_blend.sg) and cavity_ao (cavity.sg, reading the
 * terrain.cavity input), each lowered from graph text, emitted by the
 * compiler's GLSL emitter into a compute shader (harness_eval_ir) and run
 * at random points; each value is compared with the double-precision
 * reference (ir_eval, with the sampler's CPU twin) within the tolerance of
 * test_gpu_agree.c:
 *     |gpu - ref| <= 2^-20 max(1, |ref|) + 4 spread
 * where spread is the reference's modelled fp32 rounding sensitivity
 * (harness_reference), for the normal blends and cavity_ao; every value
 * must be well-conditioned (spread within 1e-3 max(1, |ref|)) and pass.
 * The hashing nodes (hex_tile, detile, macro_variation) are held to an
 * absolute bound instead: their hash_perm is integer arithmetic, exact in
 * fp32 (harness_reference's mod bound, 4u(|x| + |y|), cannot know that and
 * calls every value ill-conditioned), and the hex grid's floor is harmless
 * at its jumps (the vertex that changes has weight 0 there), so what is
 * left is the sampler: lavapipe's 8-bit sub-texel weights and the texel
 * coordinate's rounding, (2^-8 + 4u TEX (1 + |uv|)) times the texture's
 * largest texel step, per read, and a floor of 2^-16 for the arithmetic.
 * The CPU side of the same formulas is tests/unit/test_look_nodes.c.
 * Last, the height_softmax composite's normalised sums the same way. */
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
#include "harness.h"
#include "sg.h"

enum { POINTS = 512, TEX = 64 };
#define FLOOR_TOL (1.0 / 1048576.0)
#define ILL_COND  1e-3

static const char GRAPH[] =
    "import \"nodes/detile.sg\"\n"
    "import \"nodes/variation.sg\"\n"
    "import \"nodes/normal_blend.sg\"\n"
    "import \"nodes/cavity.sg\"\n"
    "texture tx { file = \"graphs/textures/noise.png\" }\n"
    "material hex {\n"
    "    node u : div { a = terrain.position.xz, b = 2.5 }\n"
    "    node n : hex_tile { tex = tx, uv = u.out, sharpness = 5.0 }\n"
    "    out albedo = n.out.rgb\n"
    "}\n"
    "material det {\n"
    "    node n : detile { tex = tx, scale = 2.0, far_scale = 9.0, fade_start = 20.0, fade_end = 90.0 }\n"
    "    out albedo = n.out.rgb\n"
    "}\n"
    "material mac {\n"
    "    node n : macro_variation { albedo = vec3(0.4, 0.35, 0.2), scale = 90.0, brightness = 0.3,"
    " tint = vec3(0.8, 1.0, 0.6), tint_amount = 0.5 }\n"
    "    out albedo = n.out\n"
    "}\n"
    /* two unpacked normals from the terrain normal and the view direction
     * (random unit vectors), blended */
    "material rnm {\n"
    "    node a : mul { a = terrain.normal.xzy, b = vec3(0.6, 0.6, 1.0) }\n"
    "    node an : normalize { x = a.out }\n"
    "    node b : mul { a = view.direction.xzy, b = vec3(0.7, 0.7, 1.0) }\n"
    "    node bn : normalize { x = b.out }\n"
    "    node r : rnm_blend { base = an.out, detail = bn.out }\n"
    "    out albedo = r.out\n"
    "}\n"
    "material wo {\n"
    "    node a : mul { a = terrain.normal.xzy, b = vec3(0.6, 0.6, 1.0) }\n"
    "    node an : normalize { x = a.out }\n"
    "    node b : mul { a = view.direction.xzy, b = vec3(0.7, 0.7, 1.0) }\n"
    "    node bn : normalize { x = b.out }\n"
    "    node r : whiteout_blend { a = an.out, b = bn.out }\n"
    "    out albedo = r.out\n"
    "}\n"
    "material cav {\n"
    "    node c : cavity_ao { depth = 8.0, strength = 0.6, ridge = 0.2 }\n"
    "    out mask = c.out\n"
    "}\n";

static harness *H;

static double f32(double x) { return (double)(float)x; }
static double rnd(uint64_t *s, double lo, double hi)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(*s >> 11) / 9007199254740992.0;
}

static int setup(void **state)
{
    (void)state;
    char *err = NULL;
    harness_desc d = {0};
    H = harness_create(&d, &err);
    if (!H)
        fprintf(stderr, "harness_create: %s\n", err ? err : "?");
    free(err);
    return H ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    return harness_destroy(H) == 0 ? 0 : -1;
}

static void test_look_nodes_agree(void **state)
{
    (void)state;
    static const char *const mats[] = {"hex", "det", "mac", "rnm", "wo", "cav"};
    static const char *const outs[] = {"albedo", "albedo", "albedo", "albedo", "albedo", "mask"};
    enum { NR = 6 };
    static const char *const search[] = {".", NULL};
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("look.sg", GRAPH, search, &d);
    assert_non_null(p);
    ir ir;
    ir_init(&ir);
    bool ok = true;
    for (int i = 0; i < NR; i++)
        ok = ok && sg_lower_material(p, mats[i], &ir, &d);
    sg_diags_print(&d, stderr);
    assert_true(ok);
    assert_int_equal(d.nerrors, 0);
    ir_ref roots[NR];
    for (int i = 0; i < NR; i++) {
        char name[64];
        snprintf(name, sizeof name, "%s.%s", mats[i], outs[i]);
        roots[i] = ir_find_root(&ir, name);
        assert_true(ir_ref_ok(roots[i]));
    }
    /* one smooth-ish random texture for every texture of the ir */
    static float texels[TEX * TEX * 4];
    uint64_t s = 31;
    for (int i = 0; i < TEX * TEX; i++) {
        int x = i % TEX, y = i / TEX;
        for (int c = 0; c < 4; c++)
            texels[i * 4 + c] = (float)(0.5 + 0.3 * sin(6.283185307179586 * x / TEX * 2 + 1.1 * c) *
                                        cos(6.283185307179586 * y / TEX * 3 - c));
    }
    harness_image *im = calloc((size_t)ir.ntextures, sizeof *im);
    for (int t = 0; t < ir.ntextures; t++)
        im[t] = (harness_image){TEX, TEX, texels, ir.textures[t].filter, ir.textures[t].wrap};
    harness_ref_opts ro = {.samples = 16, .texels = TEX,
                           .texel_step = harness_image_max_step(&im[0])};
    static ir_env env[POINTS];
    for (int i = 0; i < POINTS; i++) {
        ir_env *e = &env[i];
        memset(e, 0, sizeof *e);
        e->position[0] = f32(rnd(&s, -300, 300));
        e->position[1] = f32(rnd(&s, 0, 500));
        e->position[2] = f32(rnd(&s, -300, 300));
        e->view_distance = f32(rnd(&s, 0, 150));
        double n[3] = {rnd(&s, -0.7, 0.7), rnd(&s, 0.3, 1), rnd(&s, -0.7, 0.7)};
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double v[3] = {rnd(&s, -0.7, 0.7), rnd(&s, 0.3, 1), rnd(&s, -0.7, 0.7)};
        double lv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int c = 0; c < 3; c++) {
            e->normal[c] = f32(n[c] / l);
            e->view_direction[c] = f32(v[c] / lv);
        }
        e->slope = f32(1 - e->normal[1]);
        e->cavity = f32(rnd(&s, -20, 20));
        e->sample = harness_sample_images;
        e->sample_user = im;
    }
    float *gpu = calloc((size_t)POINTS * NR * 4, sizeof *gpu);
    char *err = NULL, *glsl = NULL;
    harness_ir_desc hd = {.ir = &ir, .roots = roots, .nroots = NR, .points = env,
                          .npoints = POINTS, .images = im};
    ok = harness_eval_ir(H, &hd, gpu, &glsl, &err);
    if (!ok)
        fprintf(stderr, "harness_eval_ir: %s\n%s\n", err ? err : "?", glsl ? glsl : "");
    assert_true(ok);
    assert_non_null(strstr(glsl, "splat_cavity()"));
    /* reads per value of the hashing roots (hex 3, detile 6, macro 0) and
     * the largest |uv| they read at (positions / 2 plus the offsets) */
    static const int reads[] = {3, 6, 0, -1, -1, -1};
    double read_tol = (1.0 / 256 + 4.0 / 16777216 * TEX * (1 + 160)) * ro.texel_step;
    long values = 0, compared = 0, failed = 0;
    for (int r = 0; r < NR; r++) {
        int w = ir_type_width(ir_typeof(&ir, roots[r]));
        double worst = 0;
        for (int i = 0; i < POINTS; i++) {
            harness_refval rv;
            ro.seed = 1000u + (uint64_t)i;
            harness_reference(&ir, roots[r], &env[i], &ro, &rv);
            for (int c = 0; c < w; c++) {
                values++;
                double ref = rv.value[c], scale = fmax(1, fabs(ref));
                assert_int_equal(rv.flags[c], 0);
                double tol;
                if (reads[r] >= 0) {
                    tol = 1.0 / 65536 + reads[r] * read_tol;
                } else {
                    if (!(rv.spread[c] <= ILL_COND * scale))
                        fail_msg("%s point %d: ill-conditioned (spread %g)", mats[r], i,
                                 rv.spread[c]);
                    tol = FLOOR_TOL * scale + 4 * rv.spread[c];
                }
                compared++;
                double g = gpu[((size_t)i * NR + (size_t)r) * 4 + (size_t)c];
                double e = fabs(g - ref);
                worst = fmax(worst, e / tol);
                if (e > tol && failed++ < 10)
                    fprintf(stderr, "%s point %d [%d]: device %.9g, reference %.9g, |error| %.3g "
                            "> %.3g\n", mats[r], i, c, g, ref, e, tol);
            }
        }
        printf("%-4s worst error/tolerance %.3g\n", mats[r], worst);
    }
    printf("values %ld, compared %ld, failed %ld (texel step %.3g)\n", values, compared, failed,
           ro.texel_step);
    assert_int_equal(failed, 0);
    assert_int_equal(compared, values);
    free(gpu);
    free(glsl);
    free(err);
    free(im);
    ir_free(&ir);
    sg_free(p);
    sg_diags_free(&d);
}

/* The height_softmax composite (nodes/height_softmax.sg, compiler/DESIGN.md
 * §6.2), its "composite.albedo" and ".roughness" roots (the normalised sums
 * the GLSL accumulates), on the device against the double reference with
 * the spread-based tolerance; masks and heights are ramps of the inputs. */
static const char STACK[] =
    "import \"nodes/height_softmax.sg\"\n"
    "material base {\n"
    "    node h : mul { a = terrain.slope, b = 0.8 }\n"
    "    out albedo = vec3(0.4, 0.3, 0.2)\n"
    "    out roughness = 0.9\n"
    "    out height = h.out\n"
    "}\n"
    "material sand {\n"
    "    node k : mul { a = terrain.normal.x, b = 3.0 }\n"
    "    node m : saturate { x = k.out }\n"
    "    node h : mul { a = terrain.cavity, b = 0.05 }\n"
    "    out mask = m.out\n"
    "    out albedo = vec3(0.8, 0.7, 0.5)\n"
    "    out roughness = 0.7\n"
    "    out height = h.out\n"
    "}\n"
    "material rock {\n"
    "    node k : mul { a = terrain.normal.z, b = 2.5 }\n"
    "    node m : saturate { x = k.out }\n"
    "    node h : mul { a = view.distance, b = 0.01 }\n"
    "    out mask = m.out\n"
    "    out albedo = vec3(0.5, 0.5, 0.55)\n"
    "    out roughness = 0.5\n"
    "    out height = h.out\n"
    "}\n";

static void test_height_softmax_agrees(void **state)
{
    (void)state;
    static const char *const names[] = {"base", "sand", "rock"};
    static const char *const search[] = {".", NULL};
    sg_diags d;
    sg_diags_init(&d);
    sg_program *p = sg_load_string("stack.sg", STACK, search, &d);
    assert_non_null(p);
    ir src;
    ir_init(&src);
    bool ok = true;
    for (int i = 0; i < 3; i++)
        ok = ok && sg_lower_material(p, names[i], &src, &d);
    sg_diags_print(&d, stderr);
    assert_true(ok);
    splat_layout L;
    assert_true(splat_layout_init(&L, &src, p, "height_softmax", names, 3, NULL, 0, &d));
    static const int mats[] = {2, 1, 0};
    splat_compose_desc desc = {.materials = mats, .nmaterials = 3};
    splat_composite c;
    assert_true(splat_compose(&L, &desc, &c, &d));
    ir_ref roots[2] = {ir_find_root(&c.ir, "composite.albedo"),
                       ir_find_root(&c.ir, "composite.roughness")};
    assert_true(ir_ref_ok(roots[0]) && ir_ref_ok(roots[1]));
    static ir_env env[POINTS];
    uint64_t s = 7;
    for (int i = 0; i < POINTS; i++) {
        ir_env *e = &env[i];
        memset(e, 0, sizeof *e);
        double n[3] = {rnd(&s, -0.6, 0.6), rnd(&s, 0.3, 1), rnd(&s, -0.6, 0.6)};
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            e->normal[k] = f32(n[k] / l);
        e->slope = f32(1 - e->normal[1]);
        e->cavity = f32(rnd(&s, -5, 25));
        e->view_distance = f32(rnd(&s, 0, 120));
    }
    float *gpu = calloc((size_t)POINTS * 2 * 4, sizeof *gpu);
    char *err = NULL;
    harness_ir_desc hd = {.ir = &c.ir, .roots = roots, .nroots = 2, .points = env,
                          .npoints = POINTS};
    ok = harness_eval_ir(H, &hd, gpu, NULL, &err);
    if (!ok)
        fprintf(stderr, "harness_eval_ir: %s\n", err ? err : "?");
    assert_true(ok);
    harness_ref_opts ro = {.samples = 16};
    long compared = 0, partial = 0;
    double worst = 0;
    for (int i = 0; i < POINTS; i++) {
        for (int r = 0; r < 2; r++) {
            harness_refval rv;
            ro.seed = 77u + (uint64_t)i;
            harness_reference(&c.ir, roots[r], &env[i], &ro, &rv);
            for (int k = 0; k < (r ? 1 : 3); k++) {
                double ref = rv.value[k], scale = fmax(1, fabs(ref));
                assert_int_equal(rv.flags[k], 0);
                assert_true(rv.spread[k] <= ILL_COND * scale);
                double tol = FLOOR_TOL * scale + 4 * rv.spread[k];
                double e = fabs(gpu[((size_t)i * 2 + (size_t)r) * 4 + (size_t)k] - ref);
                worst = fmax(worst, e / tol);
                if (e > tol)
                    fail_msg("point %d root %d [%d]: device %.9g, reference %.9g", i, r, k,
                             gpu[((size_t)i * 2 + (size_t)r) * 4 + (size_t)k], ref);
                compared++;
            }
        }
        /* points where the roughness is a blend, not one layer's */
        double rr = gpu[(size_t)i * 8 + 4];
        partial += fabs(rr - 0.9) > 1e-3 && fabs(rr - 0.7) > 1e-3 && fabs(rr - 0.5) > 1e-3;
    }
    printf("height_softmax: %ld values compared, worst error/tolerance %.3g, %ld blended points\n",
           compared, worst, partial);
    assert_true(partial > POINTS / 8);
    free(gpu);
    free(err);
    splat_composite_free(&c);
    splat_layout_free(&L);
    ir_free(&src);
    sg_free(p);
    sg_diags_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_look_nodes_agree),
        cmocka_unit_test(test_height_softmax_agrees),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
