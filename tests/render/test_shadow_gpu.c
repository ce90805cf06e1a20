/* test_shadow_gpu.c — the shadow map marched on the device
 * (runtime/shadow_gpu.c) against the CPU reference (runtime/shadow.c), with
 * SPLAT_VALIDATE=1 (any validation message fails).
 *
 *   test_shadow_gpu OUTDIR [PACK]   (run from the repository root)
 *
 * A hilly 300 x 170 texel terrain of 2 x 3 m texels (not square, not a
 * multiple of the march's 256-texel pyramid cells), 1200 m above zero:
 *   - under three suns (low from the south-east, 17 degrees from the
 *     west-south-west, 9 degrees from the north (along the grid)) the renderer's
 *     GPU map equals rt_shadow_map's within 1/255 in every texel, and each
 *     map has shade, light and penumbra (so the comparison means
 *     something);
 *   - a crater in a ridge changes the GPU map (the march reads the
 *     lowered heightfield; only the crater's rectangle is remade) and the
 *     map still equals the CPU reference made whole over the new heights.
 * With PACK (e.g. out/colorado.pack) the same comparison runs on that
 * pack's terrain and prints both marches' times. */
#include "rt_internal.h"
#include "kit.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { NX = 300, NZ = 170 };

static double hill(double x, double z)
{
    double h = 0.35 + 0.18 * sin(x * 0.043) * cos(z * 0.051) + 0.12 * sin(x * 0.11 + z * 0.07);
    h += 0.4 * exp(-((x - 150) * (x - 150) + (z - 80) * (z - 80)) / 300.0);   /* a peak */
    h += 0.25 * exp(-(x - 230) * (x - 230) / 40.0);                              /* a ridge */
    return h < 0 ? 0 : h > 1 ? 1 : h;
}

static bool write_inputs(const char *dir)
{
    static uint8_t hf[NX * NZ];
    for (int z = 0; z < NZ; z++)
        for (int x = 0; x < NX; x++)
            hf[z * NX + x] = (uint8_t)lrint(255.0 * hill(x, z));
    char *png = kit_join(dir, "hills.png"), *sg = kit_join(dir, "hills.sg");
    bool ok = stbi_write_png(png, NX, NZ, 1, hf, NX) != 0;
    FILE *f = fopen(sg, "w");
    ok = ok && f;
    if (f) {
        fprintf(f, "import \"nodes/compositors.sg\"\n"
                   "material ground {\n    out albedo = vec3(0.5, 0.5, 0.5)\n"
                   "    out roughness = 0.9\n}\n"
                   "scene hills {\n    heightfield = \"hills.png\"\n    size = %d %d\n"
                   "    max_height = 60\n    height_offset = 1200\n    materials = [ground]\n"
                   "    cell = 16\n"
                   "    destruction { origin = 380 120, size = 160 160, cell = 16 }\n}\n",
                NX * 2, NZ * 3);
        ok &= fclose(f) == 0;
    }
    free(png);
    free(sg);
    return ok;
}

/* The renderer's map against the CPU reference: the largest difference
 * (in 1/255) and how many texels differ; `what` names the case. */
static int compare(rt_renderer *r, const rt_pack *p, uint8_t *gpu, uint8_t *cpu, const char *what)
{
    size_t n = (size_t)p->hf_width * (size_t)p->hf_height;
    rt_error e = { 0 };
    rt_frame_stats st;
    rt_camera cam;
    rt_default_camera(p, &cam);
    CHECK(rt_renderer_frame(r, &cam, &st, &e), "%s: frame: %s", what, e.msg ? e.msg : "?");
    rt_error_clear(&e);
    CHECK(st.shadow_gpu && st.shadow_ms > 0, "%s: no map made on the device", what);
    if (!rt_renderer_shadow_read(r, gpu, &e)) {
        CHECK(false, "%s: read: %s", what, e.msg ? e.msg : "?");
        rt_error_clear(&e);
        return 255;
    }
    double t0 = splat_now();
    rt_renderer_shadow_reference(r, cpu);
    double cpu_ms = 1e3 * (splat_now() - t0);
    int worst = 0;
    size_t differ = 0, shade = 0, lit = 0, half = 0;
    for (size_t i = 0; i < n; i++) {
        int d = abs((int)gpu[i] - (int)cpu[i]);
        worst = d > worst ? d : worst;
        differ += d != 0;
        shade += cpu[i] == 0;
        lit += cpu[i] == 255;
        half += cpu[i] > 0 && cpu[i] < 255;
    }
    printf("%s: gpu %.1f ms, cpu %.1f ms; max difference %d/255, %zu of %zu texels differ; "
           "shade %zu, lit %zu, penumbra %zu\n", what, st.shadow_ms, cpu_ms, worst, differ, n,
           shade, lit, half);
    CHECK(worst <= 1, "%s: the GPU map differs from the CPU's by %d/255", what, worst);
    return worst;
}

int main(int argc, char **argv)
{
    if (argc != 2 && argc != 3) {
        fprintf(stderr, "usage: test_shadow_gpu OUTDIR [PACK] (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    char *sg = kit_join(dir, "hills.sg"), *packdir = argc == 3 ? strdup(argv[2]) : kit_join(dir, "hills.pack");
    bool built = argc == 3 || (write_inputs(dir) && kit_build_pack_ok(sg, packdir));
    rt_pack *p = built ? kit_pack(packdir) : NULL;
    rt_device *dev = p ? kit_device() : NULL;
    rt_error e = { 0 };
    if (!dev)
        return kit_finish("shadow_gpu");
    free(sg);
    free(packdir);
    size_t n = (size_t)p->hf_width * (size_t)p->hf_height;
    uint8_t *gpu = malloc(n), *cpu = malloc(n), *before = malloc(n);
    rt_render_desc rd = { .width = 32, .height = 32, .shading = RT_SHADING_FORWARD,
                          .shadow = RT_SHADOW_GPU, .no_undergrowth = true };
    rt_renderer *r = NULL;
    if (!gpu || !cpu || !before || !rt_renderer_create(dev, p, &rd, &r, &e)) {
        fprintf(stderr, "FAIL: renderer: %s\n", e.msg ? e.msg : "out of memory");
        return 1;
    }
    static const double suns[3][2] = { { 135, 4 }, { 250, 17 }, { 0, 9 } };
    rt_light l = *rt_renderer_light(r);
    for (int k = 0; k < 3; k++) {
        char what[64];
        snprintf(what, sizeof what, "sun %g/%g", suns[k][0], suns[k][1]);
        l.sun[0] = suns[k][0];
        l.sun[1] = suns[k][1];
        rt_renderer_set_light(r, &l);
        compare(r, p, gpu, cpu, what);
        if (argc == 2) {   /* the synthetic terrain has all three kinds of texel */
            size_t shade = 0, lit = 0, half = 0;
            for (size_t i = 0; i < n; i++) {
                shade += cpu[i] == 0;
                lit += cpu[i] == 255;
                half += cpu[i] > 0 && cpu[i] < 255;
            }
            CHECK(shade > n / 100 && lit > n / 10 && half > n / 1000,
                  "%s: a map without shade, light or penumbra (%zu, %zu, %zu)", what, shade, lit,
                  half);
        }
    }
    if (argc == 2) {
        /* a crater in the ridge at x = 460 m, under the second sun, whose
         * shadow falls east of the ridge */
        l.sun[0] = suns[1][0];
        l.sun[1] = suns[1][1];
        rt_renderer_set_light(r, &l);
        compare(r, p, gpu, cpu, "before the crater");
        memcpy(before, gpu, n);
        rt_crater c = { .x = 460, .z = 200, .radius = 30, .depth = 12 };
        rt_crater_stats cs;
        CHECK(rt_renderer_crater(r, &c, &cs, &e) && cs.result == RT_CRATER_DONE, "crater: %s",
              e.msg ? e.msg : "refused or outside");
        rt_error_clear(&e);
        compare(r, p, gpu, cpu, "after the crater");
        size_t changed = 0;
        for (size_t i = 0; i < n; i++)
            changed += gpu[i] != before[i];
        printf("the crater changed %zu texels of the map\n", changed);
        CHECK(changed > 100, "the crater changed only %zu texels of the GPU map", changed);
    }
    rt_renderer_destroy(r);
    free(gpu);
    free(cpu);
    free(before);
    kit_device_close(dev);
    rt_pack_close(p);
    return kit_finish("shadow_gpu");
}
