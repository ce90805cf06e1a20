/* test_terrain_gpu.c — the shading pass's terrain inputs on the device
 * agree with their CPU twins, and stay inside the analysis's bounds.
 *
 * The ABI prelude's own text of splat_height_smooth_at and
 * splat_terrain_at (abi.c: the cubic B-spline over the heightfield, 4 and
 * 9 gathers, and Listing 1's cross filter on it) is cut out of
 * SPLAT_GLSL_PRELUDE and run in a compute shader over a random heightfield
 * (an RGBA32F image holding texel / 65535, clamp to edge, as the runtime's
 * R16_UNORM reads) at random uv, texel centres and edges, and outside
 * [0, 1].  Each height and normal must equal splat_terrain_height /
 * splat_terrain_normal (terrain.c, double) within fp32 rounding, and lie in
 * splat_terrain_ranges of the texel rectangle holding its uv (the
 * analysis's soundness on real device values).  A control checks the
 * comparison is not vacuous: the device's values against the CPU's at uv
 * moved by a tenth of a texel must differ.
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

#include "abi.h"
#include "harness.h"
#include "spv.h"
#include "terrain.h"

enum { W = 37, H = 29, N = 64 * 40 };

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double rnd01(void)
{
    rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* The prelude's text from `from` to the end of the function that starts
 * at `last` (malloc'd), or NULL. */
static char *cut(const char *from, const char *last)
{
    const char *a = strstr(SPLAT_GLSL_PRELUDE, from);
    const char *l = a ? strstr(a, last) : NULL;
    const char *e = l ? strstr(l, "\n}\n") : NULL;
    if (!e) return NULL;
    e += 3;
    char *s = malloc((size_t)(e - a) + 1);
    memcpy(s, a, (size_t)(e - a));
    s[e - a] = 0;
    return s;
}

static void test_terrain_inputs_agree(void **state)
{
    (void)state;
    splat_terrain t = { .width = W, .height = H };
    t.texels = malloc(sizeof *t.texels * W * H);
    t.size[0] = W * 73.5;
    t.size[1] = H * 92.6;
    t.max_height = 2962.242;
    t.height_offset = 1358.652;
    float *rgba = malloc(sizeof *rgba * 4 * W * H);
    for (int z = 0; z < H; z++)
        for (int x = 0; x < W; x++) {
            double v = 30000 + 15000 * sin(x * 0.4) * cos(z * 0.3) + 8000 * (rnd01() - 0.5);
            if (x == W / 2) v += 20000;   /* a cliff */
            uint16_t q = (uint16_t)(v < 0 ? 0 : v > 65535 ? 65535 : v);
            t.texels[z * W + x] = q;
            float *p = rgba + 4 * (z * W + x);
            p[0] = p[1] = p[2] = (float)(q / 65535.0);
            p[3] = 1;
        }

    char *fns = cut("vec4 splat_bspline_w(float t) {", "vec3 splat_normal_at(vec2 uv) {");
    assert_non_null(fns);
    size_t cap = strlen(fns) + 4096;
    char *src = malloc(cap);
    snprintf(src, cap,
             "#version 450\n"
             "layout(local_size_x = %d) in;\n"
             "layout(set = 0, binding = 0, std430) readonly buffer In { vec2 uv[]; } u_in;\n"
             "layout(set = 0, binding = 1, std430) buffer Out { vec4 v[]; } u_out;\n"
             "layout(set = 0, binding = 2) uniform sampler2D u_height;\n"
             "struct frame { vec4 terrain; vec4 texel; };\n"
             "frame u_frame;\n"
             "%s"
             "void main() {\n"
             "    uint i = gl_GlobalInvocationID.x;\n"
             "    u_frame.terrain = vec4(%.9g, %.9g, %.9g, %.9g);\n"
             "    u_frame.texel = vec4(%d.0, %d.0, 1.0 / %d.0, 1.0 / %d.0);\n"
             "    float h;\n"
             "    vec3 n;\n"
             "    splat_terrain_at(u_in.uv[i], h, n);\n"
             "    u_out.v[2u * i] = vec4(n, h);\n"
             "    u_out.v[2u * i + 1u] = vec4(splat_height_smooth_at(u_in.uv[i]), 0.0, 0.0, 0.0);\n"
             "}\n",
             HARNESS_LOCAL_SIZE, fns, t.size[0], t.size[1], t.max_height, t.height_offset,
             W, H, W, H);
    free(fns);
    uint32_t *spv = NULL;
    size_t nwords = 0;
    char *log = NULL;
    if (!spv_compile(src, SPV_STAGE_COMPUTE, "terrain_gpu", &spv, &nwords, &log))
        fail_msg("glslang: %s", log ? log : "?");
    free(log);
    assert_true(spv_validate(spv, nwords, &log));
    free(log);

    float *uv = malloc(sizeof *uv * 2 * N), *out = calloc((size_t)N * 8, sizeof *out);
    for (int i = 0; i < N; i++) {
        double u = rnd01(), v = rnd01();
        if (i % 5 == 1) {            /* texel centres and edges */
            u = (floor(u * W) + (i % 2 ? 0.5 : 0.0)) / W;
            v = (floor(v * H) + (i % 3 ? 0.5 : 0.0)) / H;
        }
        if (i % 17 == 3) {           /* outside: clamped to the edge */
            u = u * 1.4 - 0.2;
            v = v * 1.4 - 0.2;
        }
        uv[2 * i] = (float)u;
        uv[2 * i + 1] = (float)v;
    }
    char *err = NULL;
    harness *h = harness_create(&(harness_desc){0}, &err);
    if (!h) fail_msg("harness: %s", err ? err : "?");
    harness_image im = { W, H, rgba, IR_FILTER_LINEAR, IR_WRAP_CLAMP };
    harness_dispatch d = {
        .spv = spv, .nwords = nwords,
        .input = uv, .input_bytes = sizeof *uv * 2 * N,
        .output = out, .output_bytes = sizeof *out * 8 * N,
        .groups = N / HARNESS_LOCAL_SIZE, .images = &im, .nimages = 1,
    };
    if (!harness_run(h, &d, &err)) fail_msg("harness_run: %s", err ? err : "?");

    /* fp32: heights to a few ulps of max_height + offset, normals to a few
     * ulps of a unit vector times the slopes' magnification (73 m texels,
     * 3 km of height: a 16-bit step is 0.06 m over 147 m) */
    const double htol = 1e-6 * (t.max_height + t.height_offset), ntol = 2e-5;
    double worst_h = 0, worst_n = 0, moved = 0;
    int outside = 0;
    for (int i = 0; i < N; i++) {
        double u = uv[2 * i], v = uv[2 * i + 1], n[3];
        double hc = splat_terrain_height(&t, u, v);
        splat_terrain_normal(&t, u, v, n);
        const float *g = out + 8 * i;
        worst_h = fmax(worst_h, fmax(fabs(g[3] - hc), fabs(g[4] - hc)));
        for (int c = 0; c < 3; c++)
            worst_n = fmax(worst_n, fabs(g[c] - n[c]));
        /* the control: a tenth of a texel away */
        double m[3];
        splat_terrain_normal(&t, u + 0.1 / W, v, m);
        moved = fmax(moved, fabs(g[0] - m[0]) + fabs(g[2] - m[2]));
        /* the analysis: the texel rectangle holding uv (clamped inside) */
        int x = (int)floor(u * W), z = (int)floor(v * H);
        if (x < 0 || z < 0 || x >= W || z >= H) {
            outside++;
            x = x < 0 ? 0 : x >= W ? W - 1 : x;
            z = z < 0 ? 0 : z >= H ? H - 1 : z;
        }
        ir_ienv r;
        memset(&r, 0, sizeof r);
        splat_terrain_ranges(&t, x, z, x + 1, z + 1, &r);
        if (u < 0 || v < 0 || u > 1 || v > 1) continue;   /* in no cell */
        assert_true(g[3] >= r.height.lo && g[3] <= r.height.hi);
        assert_true(g[4] >= r.height.lo && g[4] <= r.height.hi);
        for (int c = 0; c < 3; c++)
            assert_true(g[c] >= r.normal[c].lo && g[c] <= r.normal[c].hi);
        assert_true(1 - g[1] >= r.slope.lo && 1 - g[1] <= r.slope.hi);
    }
    printf("terrain inputs on %s: %d points (%d outside [0, 1]); max |height - CPU| "
           "%.3g m (tolerance %.3g), max |normal - CPU| %.3g (tolerance %.3g); "
           "control (uv a tenth of a texel away) %.3g\n",
           harness_device_name(h), N, outside, worst_h, htol, worst_n, ntol, moved);
    assert_true(worst_h <= htol);
    assert_true(worst_n <= ntol);
    assert_true(moved > 100 * ntol);
    assert_int_equal(harness_destroy(h), 0);
    free(spv); free(src); free(uv); free(out); free(rgba); free(t.texels);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_terrain_inputs_agree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
