/* test_harness.c — the Vulkan compute harness itself: dispatch and read
 * back, push constants, sampled images with their sampler state, errors.
 * Runs on lavapipe (or a GPU); with SPLAT_VALIDATE=1 any validation
 * message fails the test. */
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
#include "spv.h"

static harness *H;

static uint32_t *compile(const char *src, size_t *n)
{
    uint32_t *w = NULL;
    char *log = NULL;
    if (!spv_compile(src, SPV_STAGE_COMPUTE, "test", &w, n, &log))
        fprintf(stderr, "%s", log);
    free(log);
    assert_non_null(w);
    return w;
}

static void test_dispatch_reads_back(void **state)
{
    static const char src[] =
        "#version 450\n"
        "layout(local_size_x = 64) in;\n"
        "layout(std430, set = 0, binding = 0) readonly buffer I { float v[]; } i_;\n"
        "layout(std430, set = 0, binding = 1) buffer O { float v[]; } o_;\n"
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        "    if (i < uint(i_.v.length())) o_.v[i] = i_.v[i] * 2.0 + float(i);\n"
        "}\n";
    enum { N = 1000 };          /* not a multiple of the workgroup size */
    float in[N], out[N + 8];
    for (int i = 0; i < N; i++)
        in[i] = (float)i * 0.25f - 17.0f;
    memset(out, 0xff, sizeof out);
    size_t n;
    uint32_t *w = compile(src, &n);
    char *err = NULL;
    harness_dispatch d = {
        .spv = w, .nwords = n,
        .input = in, .input_bytes = sizeof in,
        .output = out, .output_bytes = sizeof out,
        .groups = (N + 63) / 64,
    };
    bool ok = harness_run(H, &d, &err);
    if (!ok)
        fprintf(stderr, "%s\n", err);
    assert_true(ok);
    for (int i = 0; i < N; i++)
        assert_true(out[i] == in[i] * 2.0f + (float)i);
    /* The output buffer starts zeroed: unwritten tail reads 0. */
    for (int i = N; i < N + 8; i++)
        assert_true(out[i] == 0.0f);
    free(w);
}

static void test_push_constants(void **state)
{
    static const char src[] =
        "#version 450\n"
        "layout(local_size_x = 64) in;\n"
        "layout(push_constant) uniform P { float scale; float bias; } p;\n"
        "layout(std430, set = 0, binding = 0) readonly buffer I { float v[]; } i_;\n"
        "layout(std430, set = 0, binding = 1) buffer O { float v[]; } o_;\n"
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        "    if (i < uint(i_.v.length())) o_.v[i] = i_.v[i] * p.scale + p.bias;\n"
        "}\n";
    float in[3] = { 1.0f, 2.0f, -4.0f }, out[3];
    float push[2] = { 3.0f, 0.5f };
    size_t n;
    uint32_t *w = compile(src, &n);
    char *err = NULL;
    harness_dispatch d = {
        .spv = w, .nwords = n, .input = in, .input_bytes = sizeof in,
        .output = out, .output_bytes = sizeof out, .groups = 1,
        .push = push, .push_bytes = sizeof push,
    };
    assert_true(harness_run(H, &d, &err));
    assert_true(out[0] == 3.5f && out[1] == 6.5f && out[2] == -11.5f);
    free(w);
}

/* A 2x2 image sampled at texel centres, between texels (linear), and
 * outside [0,1] (wrap modes). */
static void test_images_and_samplers(void **state)
{
    static const char src[] =
        "#version 450\n"
        "layout(local_size_x = 64) in;\n"
        "layout(std430, set = 0, binding = 0) readonly buffer I { vec2 uv[]; } i_;\n"
        "layout(std430, set = 0, binding = 1) buffer O { vec4 v[]; } o_;\n"
        "layout(set = 0, binding = 2) uniform sampler2D t_lin;\n"
        "layout(set = 0, binding = 3) uniform sampler2D t_near_clamp;\n"
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        "    if (i >= uint(i_.uv.length())) return;\n"
        "    o_.v[2u * i] = textureLod(t_lin, i_.uv[i], 0.0);\n"
        "    o_.v[2u * i + 1u] = textureLod(t_near_clamp, i_.uv[i], 0.0);\n"
        "}\n";
    /* red channel: 0 1 / 2 3 (row 0 = v in [0, 0.5)) */
    const float tex[16] = { 0, 0, 0, 1,  1, 0, 0, 1,  2, 0, 0, 1,  3, 0, 0, 1 };
    harness_image im[2] = {
        { 2, 2, tex, IR_FILTER_LINEAR, IR_WRAP_REPEAT },
        { 2, 2, tex, IR_FILTER_NEAREST, IR_WRAP_CLAMP },
    };
    const float uv[][2] = {
        { 0.25f, 0.25f },   /* texel 0 centre               */
        { 0.75f, 0.75f },   /* texel 3 centre               */
        { 0.5f, 0.5f },     /* between all four: mean 1.5   */
        { 0.5f, 0.25f },    /* between 0 and 1: 0.5         */
        { 1.25f, 0.25f },   /* repeat -> texel 0; clamp -> texel 1 */
    };
    const float want_lin[] = { 0.0f, 3.0f, 1.5f, 0.5f, 0.0f };
    const float want_near[] = { 0.0f, 3.0f, 3.0f, 1.0f, 1.0f };
    enum { N = sizeof uv / sizeof uv[0] };
    float out[N * 2][4];
    size_t n;
    uint32_t *w = compile(src, &n);
    char *err = NULL;
    harness_dispatch d = {
        .spv = w, .nwords = n, .input = uv, .input_bytes = sizeof uv,
        .output = out, .output_bytes = sizeof out, .groups = 1,
        .images = im, .nimages = 2,
    };
    bool ok = harness_run(H, &d, &err);
    if (!ok)
        fprintf(stderr, "%s\n", err);
    assert_true(ok);
    for (int i = 0; i < N; i++) {
        /* linear filtering has 8 bits of sub-texel precision in Vulkan */
        assert_true(fabsf(out[2 * i][0] - want_lin[i]) < 1e-2f);
        assert_true(out[2 * i][3] == 1.0f);
        /* (0.5, 0.5) is exactly on a texel edge: nearest may pick either side */
        if (i != 2)
            assert_true(out[2 * i + 1][0] == want_near[i]);
    }
    free(w);
}

static void test_errors_are_messages(void **state)
{
    float in[4] = {0}, out[4];
    uint32_t junk[16];
    for (int i = 0; i < 16; i++)
        junk[i] = 0xdeadbeefu * (uint32_t)(i + 1);
    char *err = NULL;
    harness_dispatch d = {
        .spv = junk, .nwords = 16, .input = in, .input_bytes = sizeof in,
        .output = out, .output_bytes = sizeof out, .groups = 1,
    };
    /* Invalid SPIR-V is refused before the driver sees it. */
    assert_false(harness_run(H, &d, &err));
    assert_non_null(err);
    assert_non_null(strstr(err, "invalid SPIR-V"));
    free(err);
    err = NULL;

    d.spv = NULL;
    assert_false(harness_run(H, &d, &err));
    assert_non_null(strstr(err, "no SPIR-V"));
    free(err);
    err = NULL;

    /* Bad push constant size. */
    size_t n;
    uint32_t *w = compile("#version 450\nlayout(local_size_x = 64) in;\nvoid main() {}\n", &n);
    d.spv = w;
    d.nwords = n;
    d.push = in;
    d.push_bytes = 6;
    assert_false(harness_run(H, &d, &err));
    assert_non_null(strstr(err, "push constants"));
    free(err);
    free(w);
}

/* harness_eval_ir hands every input, param and painted mask to the emitted
 * code exactly (fp32 values pass through unchanged), and binds textures. */
static void test_eval_ir_plumbing(void **state)
{
    ir g;
    ir_init(&g);
    ir_param pf = { .name = "m.f", .type = IR_T_FLOAT, .def = { 0.25 } };
    ir_param pv = { .name = "m.v", .type = IR_T_VEC3, .def = { 1, 2, 3 } };
    ir_add_param(&g, &pf);
    ir_add_param(&g, &pv);
    for (int k = 0; k < 5; k++) {           /* 5 masks: two record slots */
        char name[8];
        snprintf(name, sizeof name, "p%d", k);
        ir_add_painted(&g, name);
    }
    ir_texture tex = { .file = "t.png", .filter = IR_FILTER_NEAREST, .wrap = IR_WRAP_CLAMP };
    ir_add_texture(&g, &tex);
    ir_ref roots[] = {
        ir_input(&g, IR_IN_HEIGHT), ir_input(&g, IR_IN_SLOPE),
        ir_input(&g, IR_IN_NORMAL), ir_input(&g, IR_IN_POSITION),
        ir_input(&g, IR_IN_UV), ir_input(&g, IR_IN_VIEW_DISTANCE),
        ir_input(&g, IR_IN_DESTRUCTION), ir_input(&g, IR_IN_VIEW_DIRECTION),
        ir_param_ref(&g, 0), ir_param_ref(&g, 1),
        ir_painted_ref(&g, 0), ir_painted_ref(&g, 4),
        ir_op2(&g, IR_OP_SAMPLE, ir_texture_ref(&g, 0), ir_input(&g, IR_IN_UV)),
    };
    enum { R = sizeof roots / sizeof roots[0], P = 3 };
    double params[P][8], painted[P][5];
    ir_env env[P];
    for (int p = 0; p < P; p++) {
        env[p] = (ir_env){
            .height = 100.5 + p, .slope = 0.125 * p,
            .normal = { 0.25, 0.5 + p, -0.75 }, .position = { 10, 20 + p, 30 },
            .uv = { 0.25 + 0.5 * (p & 1), 0.25 }, .view_distance = 1000 + p,
            .destruction = 0.5 * p, .params = params[p], .painted = painted[p],
            /* point 0 leaves it unset: reads (0, 1, 0) on both sides */
            .view_direction = { 0.6 * p, 0, p ? -0.8 : 0 },
        };
        for (int i = 0; i < 8; i++)
            params[p][i] = i + 0.5 * p;
        for (int k = 0; k < 5; k++)
            painted[p][k] = 0.125 * k + 0.0625 * p;
    }
    const float texels[] = { 0.5f, 1, 0, 1,  0.25f, 0, 1, 1 };   /* 2x1 */
    harness_image im = { 2, 1, texels, IR_FILTER_NEAREST, IR_WRAP_CLAMP };
    float out[P * R * 4];
    char *err = NULL, *glsl = NULL;
    harness_ir_desc d = { .ir = &g, .roots = roots, .nroots = R, .points = env,
                          .npoints = P, .images = &im };
    bool ok = harness_eval_ir(H, &d, out, &glsl, &err);
    if (!ok)
        fprintf(stderr, "%s\n%s\n", err ? err : "", glsl ? glsl : "");
    assert_true(ok);
    assert_non_null(strstr(glsl, "splat_height()"));
    for (int p = 0; p < P; p++)
        for (int r = 0; r < R; r++) {
            double want[4];
            ir_env e = env[p];
            e.sample = harness_sample_images;
            e.sample_user = &im;
            ir_eval(&g, roots[r], &e, want);
            int w = ir_type_width(ir_typeof(&g, roots[r]));
            for (int c = 0; c < 4; c++)
                if (out[(p * R + r) * 4 + c] != (c < w ? (float)want[c] : 0.0f)) {
                    fprintf(stderr, "point %d root %d component %d: %g, want %g\n",
                            p, r, c, out[(p * R + r) * 4 + c], want[c]);
                    fail();
                }
        }
    free(glsl);
    ir_free(&g);
}

static void test_device_choice(void **state)
{
    char *err = NULL;
    harness *h = harness_create(&(harness_desc){ .device = "no such device name" }, &err);
    assert_null(h);
    assert_non_null(err);
    assert_non_null(strstr(err, "no such device name"));
    free(err);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dispatch_reads_back),
        cmocka_unit_test(test_push_constants),
        cmocka_unit_test(test_images_and_samplers),
        cmocka_unit_test(test_errors_are_messages),
        cmocka_unit_test(test_eval_ir_plumbing),
        cmocka_unit_test(test_device_choice),
    };
    char *err = NULL;
    H = harness_create(NULL, &err);
    if (!H) {
        fprintf(stderr, "harness_create: %s\n", err ? err : "?");
        free(err);
        return 1;
    }
    printf("device: %s%s\n", harness_device_name(H),
           harness_validating(H) ? " (validation on)" : "");
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    int messages = harness_destroy(H);
    if (messages)
        fprintf(stderr, "FAILED: %d Vulkan validation message(s)\n", messages);
    return failed || messages ? 1 : 0;
}
