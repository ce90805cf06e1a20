/* test_gpu_agree.c — the GLSL back end agrees with the CPU reference.
 *
 * Random well-typed IR graphs over every op (tests/unit/random_ir.h, the
 * same generator as the CPU agreement test test_random_agree.c) are emitted
 * by the compiler's GLSL emitter into a compute shader (harness_eval_ir)
 * and run on the Vulkan device (lavapipe here, a GPU elsewhere) over random
 * inputs (rounded to fp32, as the device receives them); each value is
 * compared with ir_eval's double-precision value.  The generator's texture
 * is baked into a 128x128 RGBA32F image that the device samples and the
 * reference samples through the sampler's CPU twin (harness_image_sample).
 *
 * Tolerance, and why: the device computes in fp32, whose rounding differs
 * per op (Vulkan spec precision table: most ops 0.5-3 ulp, exp2/pow/sin/cos
 * far looser), and a random graph can amplify rounding without bound
 * (cancellation before a division, a floor or step right at its jump).  So
 * each value's fp32 sensitivity is estimated with harness_reference (every
 * node perturbed by its op's fp32 error bound, 16 samples; the bounds are
 * listed in harness_ref.c) and, per component:
 *   - excluded: values that are NaN/Inf in double, or that depend on a
 *     value on the way that is NaN/Inf, beyond 1e30 / below 1e-30 in
 *     magnitude, or undefined in GLSL (smoothstep e0 >= e1, clamp lo > hi,
 *     pow of x < 0, a sample at NaN uv) — GLSL promises nothing there;
 *     "depends" means replacing that value with garbage changes the result;
 *   - excluded: ill-conditioned values, spread > 1e-3 * max(1, |ref|);
 *   - every other value must satisfy
 *         |gpu - ref| <= 2^-20 * max(1, |ref|) + 4 * spread
 *     (a floor of a few fp32 ulps, plus 4x the modelled rounding spread:
 *     the spread is a sample of the rounding, not its worst case).
 * Each exclusion is counted and reported.  The generator draws every op
 * with unconstrained operands, so many values are NaN or undefined by
 * construction (pow of negatives, unordered smoothstep edges, sqrt of
 * negatives); still at least 60% of all values (MIN_COMPARED_PCT), and
 * some values of at least 75% of the graphs, must be compared, so the test
 * cannot pass by excluding most of them.  Every exclusion is decided on the
 * CPU reference (seeded draws), so the fraction does not depend on the
 * device: 65.9% of 500736 values and 153 of 192 graphs are compared; 60%
 * leaves room for a changed generator, not for a third of the values to go.  A control compares each graph's device values
 * with another graph's reference, which must fail nearly everywhere, so the
 * tolerance is not vacuous.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "random_ir.h"

enum {
    BATCHES = 12,      /* one compute shader each                       */
    MIN_COMPARED_PCT = 60, /* values that must be compared (see the top)  */
    ROOTS = 16,        /* random graphs per batch (one IR, shared leaves) */
    POINTS = 1024,     /* random inputs per batch                       */
    REGION = 32,       /* points drawn from one random input region     */
    TEX = 128,         /* texture size                                  */
    SAMPLES = 16,      /* rounding-perturbation samples per value       */
    MAX_DEPTH = 6,     /* graph k is 2 + k % 5 ops deep: shallow and deep */
};

#define FLOOR_TOL (1.0 / 1048576.0)   /* 2^-20 */
#define ILL_COND  1e-3

static harness *H;

typedef struct batch {
    ir      ir;
    ir_ref  roots[ROOTS];
    ir_env  env[POINTS];
    double  params[POINTS][4 * RANDOM_IR_NPARAMS];
    double  painted[POINTS][RANDOM_IR_NPAINTED];
    float   texels[TEX * TEX * 4];
    harness_image image;    /* the generator's one texture */
    harness_ref_opts ref;   /* its texel step and size, samples */
    float  *gpu;            /* POINTS * ROOTS * 4 */
    char   *glsl;
} batch;

static double f32(double x) { return (double)(float)x; }

/* The device receives fp32 inputs: give the reference the same values. */
static void round_point(ir_env *e, double *params, double *painted)
{
    e->height = f32(e->height);
    e->slope = f32(e->slope);
    e->view_distance = f32(e->view_distance);
    e->destruction = f32(e->destruction);
    for (int c = 0; c < 3; c++) {
        e->normal[c] = f32(e->normal[c]);
        e->position[c] = f32(e->position[c]);
    }
    for (int c = 0; c < 2; c++)
        e->uv[c] = f32(e->uv[c]);
    for (int i = 0; i < 4 * RANDOM_IR_NPARAMS; i++)
        params[i] = f32(params[i]);
    for (int i = 0; i < RANDOM_IR_NPAINTED; i++)
        painted[i] = f32(painted[i]);
}

static void batch_build(batch *b, uint64_t seed)
{
    random_ir_rng r = { seed };
    ir_init(&b->ir);
    random_ir_setup(&b->ir);
    assert_int_equal(b->ir.ntextures, 1);
    assert_true(b->ir.nparams <= RANDOM_IR_NPARAMS);
    for (int k = 0; k < ROOTS; k++) {
        b->roots[k] = random_ir_expr(&b->ir, &r, random_ir_type(&r, 1),
                                     2 + k % (MAX_DEPTH - 1), NULL);
        char name[16];
        snprintf(name, sizeof name, "g%d", k);
        ir_set_root(&b->ir, name, b->roots[k]);
    }
    /* The generator's texture function at texel centres. */
    for (int y = 0; y < TEX; y++)
        for (int x = 0; x < TEX; x++) {
            double rgba[4];
            random_ir_sample(NULL, 0, (x + 0.5) / TEX, (y + 0.5) / TEX, rgba);
            for (int c = 0; c < 4; c++)
                b->texels[(y * TEX + x) * 4 + c] = (float)rgba[c];
        }
    b->image = (harness_image){ TEX, TEX, b->texels, b->ir.textures[0].filter,
                                b->ir.textures[0].wrap };
    b->ref = (harness_ref_opts){ .samples = SAMPLES, .texels = TEX,
                                 .texel_step = harness_image_max_step(&b->image) };
    b->gpu = calloc((size_t)POINTS * ROOTS * 4, sizeof(float));
    assert_non_null(b->gpu);
    ir_ienv box;
    ir_iv piv[RANDOM_IR_NPARAMS], miv[RANDOM_IR_NPAINTED];
    for (int p = 0; p < POINTS; p++) {
        if (p % REGION == 0)
            random_ir_box(&b->ir, &r, &box, piv, miv);
        random_ir_point(&b->ir, &r, &box, &b->env[p], b->params[p], b->painted[p]);
        round_point(&b->env[p], b->params[p], b->painted[p]);
        b->env[p].sample = harness_sample_images;
        b->env[p].sample_user = &b->image;
    }
}

static void batch_run(batch *b)
{
    char *err = NULL;
    harness_ir_desc d = {
        .ir = &b->ir, .roots = b->roots, .nroots = ROOTS,
        .points = b->env, .npoints = POINTS, .images = &b->image,
    };
    bool ok = harness_eval_ir(H, &d, b->gpu, &b->glsl, &err);
    if (!ok) {
        fprintf(stderr, "harness_eval_ir: %s\n", err ? err : "?");
        if (b->glsl)
            fprintf(stderr, "---- generated shader ----\n%s\n", b->glsl);
    }
    free(err);
    assert_true(ok);
}

static void batch_free(batch *b)
{
    ir_free(&b->ir);
    free(b->gpu);
    free(b->glsl);
}

typedef struct stats {
    long values, compared, failed, graphs_compared;
    long nonfinite, range, undefined, ill, mismatch;
    double max_abs, max_rel, max_ratio;
} stats;

/* Compare root k's device values with the reference of root `refk`. */
static void compare(batch *b, int k, int refk, uint64_t seed, stats *s,
                    bool report)
{
    ir_ref root = b->roots[refk];
    int w = ir_type_width(ir_typeof(&b->ir, root));
    long compared_before = s->compared;
    for (int p = 0; p < POINTS; p++) {
        harness_refval rv;
        b->ref.seed = seed + (uint64_t)p;
        harness_reference(&b->ir, root, &b->env[p], &b->ref, &rv);
        for (int c = 0; c < w; c++) {
            s->values++;
            unsigned f = rv.flags[c];
            if (f & HARNESS_REF_MISMATCH) {
                s->mismatch++;
                continue;
            }
            if (f & HARNESS_REF_NONFINITE) { s->nonfinite++; continue; }
            if (f & HARNESS_REF_RANGE)     { s->range++; continue; }
            if (f & HARNESS_REF_UNDEFINED) { s->undefined++; continue; }
            double ref = rv.value[c];
            double scale = fmax(1.0, fabs(ref));
            if (!(rv.spread[c] <= ILL_COND * scale)) {
                s->ill++;
                continue;
            }
            s->compared++;
            double gpu = b->gpu[((size_t)p * ROOTS + (size_t)k) * 4 + (size_t)c];
            double err = fabs(gpu - ref);
            if (isnan(err))
                err = INFINITY;
            double tol = FLOOR_TOL * scale + 4 * rv.spread[c];
            if (err > s->max_abs)
                s->max_abs = err;
            if (err / scale > s->max_rel)
                s->max_rel = err / scale;
            if (err / tol > s->max_ratio)
                s->max_ratio = err / tol;
            if (err > tol) {
                if (report && s->failed < 10)
                    fprintf(stderr, "  graph g%d point %d component %d: gpu %.9g, "
                            "reference %.17g, |error| %.3g > tolerance %.3g "
                            "(spread %.3g)\n", k, p, c, gpu, ref, err, tol,
                            rv.spread[c]);
                s->failed++;
            }
        }
    }
    if (s->compared > compared_before)
        s->graphs_compared++;
}

static void test_random_graphs_agree(void **state)
{
    stats total = {0};
    bool shown = false;
    for (int i = 0; i < BATCHES; i++) {
        batch *b = calloc(1, sizeof *b);
        assert_non_null(b);
        batch_build(b, 0x5eed0000u + (uint64_t)i);
        batch_run(b);
        stats s = {0};
        for (int k = 0; k < ROOTS; k++)
            compare(b, k, k, 77u * (uint64_t)i, &s, true);
        printf("batch %2d: %6ld values, %6ld compared, max |err| %.3g, "
               "max err/tol %.3g, %ld failed\n", i, s.values, s.compared,
               s.max_abs, s.max_ratio, s.failed);
        if (s.failed && !shown) {
            fprintf(stderr, "---- shader of batch %d ----\n%s\n", i, b->glsl);
            shown = true;
        }
        total.values += s.values;
        total.compared += s.compared;
        total.graphs_compared += s.graphs_compared;
        total.failed += s.failed;
        total.nonfinite += s.nonfinite;
        total.range += s.range;
        total.undefined += s.undefined;
        total.ill += s.ill;
        total.mismatch += s.mismatch;
        total.max_abs = fmax(total.max_abs, s.max_abs);
        total.max_rel = fmax(total.max_rel, s.max_rel);
        total.max_ratio = fmax(total.max_ratio, s.max_ratio);
        batch_free(b);
        free(b);
    }
    printf("device %s: %d graphs, %ld values\n", harness_device_name(H),
           BATCHES * ROOTS, total.values);
    printf("  compared              %8ld (%.1f%%), in %ld of %d graphs\n",
           total.compared, 100.0 * (double)total.compared / (double)total.values,
           total.graphs_compared, BATCHES * ROOTS);
    printf("  excluded: NaN/Inf     %8ld\n", total.nonfinite);
    printf("  excluded: fp32 range  %8ld\n", total.range);
    printf("  excluded: undefined   %8ld\n", total.undefined);
    printf("  excluded: ill-cond.   %8ld\n", total.ill);
    printf("  max |gpu - ref|       %.3g (max relative to max(1,|ref|): %.3g)\n",
           total.max_abs, total.max_rel);
    printf("  max error/tolerance   %.3g\n", total.max_ratio);
    printf("  failed                %8ld\n", total.failed);
    assert_int_equal(total.mismatch, 0);
    assert_true(100 * total.compared >= MIN_COMPARED_PCT * total.values);
    assert_true(4 * total.graphs_compared >= 3 * BATCHES * ROOTS);
    assert_int_equal(total.failed, 0);
}

/* Control: another graph's reference must not pass for this graph. */
static void test_tolerance_is_not_vacuous(void **state)
{
    batch *b = calloc(1, sizeof *b);
    assert_non_null(b);
    batch_build(b, 0x5eed0000u);
    batch_run(b);
    stats s = {0};
    for (int k = 0; k < ROOTS; k++) {
        /* the next root of the same type */
        ir_type t = ir_typeof(&b->ir, b->roots[k]);
        for (int j = 1; j < ROOTS; j++) {
            int other = (k + j) % ROOTS;
            if (ir_typeof(&b->ir, b->roots[other]) == t &&
                !ir_ref_eq(b->roots[other], b->roots[k])) {
                compare(b, k, other, 1, &s, false);
                break;
            }
        }
    }
    printf("control: %ld of %ld compared values fail against another graph\n",
           s.failed, s.compared);
    assert_true(s.compared > 0);
    assert_true(s.failed * 4 >= s.compared * 3);
    batch_free(b);
    free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_graphs_agree),
        cmocka_unit_test(test_tolerance_is_not_vacuous),
    };
    char *err = NULL;
    H = harness_create(NULL, &err);
    if (!H) {
        fprintf(stderr, "harness_create: %s\n", err ? err : "?");
        free(err);
        return 1;
    }
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    int messages = harness_destroy(H);
    if (messages)
        fprintf(stderr, "FAILED: %d Vulkan validation message(s)\n", messages);
    return failed || messages ? 1 : 0;
}
