/* test_far.c — shading far from the origin (compiler/precision.c) on a
 * Vulkan device (lavapipe here; SPLAT_VALIDATE=1, any validation message
 * fails).
 *
 *   test_far OUTDIR
 *
 * A flat scene 10,240 km wide (1024 x 1024 texels of 10 km, cell 1) with
 * tests/world/far.sg's materials: a 1 m top-down texture, an 8 m
 * tri-planar one and ALU value noise of 2 m cells.  The same local view
 * (straight down from 30 m) near the origin and 100 km, 1,000 km and
 * 5,000 km away (along x and z: multiples of every period and of the
 * patch size):
 *   - the albedo views, forward and screen-space, match the forward one
 *     near the origin within 8/255 on at least 99.5 % of the pixels;
 *   - the noise material's mask view matches the double-precision
 *     reference (ir_eval, what `splatc eval` prints) within 1e-3 at 64
 *     pixels of each view.
 * Without the pass the 5,000 km view fails both (position's fp32 ulp
 * there is 0.5 m).  Pictures go to OUTDIR. */
#include "rt_internal.h"
#include "../check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { N = 1024, W = 256, H = 256 };
static const double SIZE = 10240000.0, FOVY = M_PI / 3.0, ABOVE = 30.0;
static const double X0 = 41234.5, Z0 = 47876.25;    /* near the origin */
static const double OFFSETS[] = { 0.0, 1e5, 1e6, 5e6 };

/* The flat heightfield and two scenes over it: "tex" (far_base alone:
 * its albedo must not change with the offset) and "noise" (far_spots on
 * top: value noise's 289-cell period does not divide the offsets, so it
 * is held to the double reference instead). */
static bool write_inputs(const char *dir)
{
    uint8_t *hf = malloc((size_t)N * N);
    if (!hf) return false;
    memset(hf, 128, (size_t)N * N);
    char *png = join(dir, "flat.png");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0;
    free(hf);
    free(png);
    static const char *const names[2] = { "tex", "noise" };
    static const char *const stacks[2] = { "far_base", "far_base, far_spots" };
    for (int i = 0; ok && i < 2; i++) {
        char file[32];
        snprintf(file, sizeof file, "%s.sg", names[i]);
        char *sg = join(dir, file);
        FILE *f = fopen(sg, "w");
        ok = f != NULL;
        if (f) {
            fprintf(f, "import \"nodes/compositors.sg\"\nimport \"tests/world/far.sg\"\n"
                    "scene far_%s {\n    heightfield = \"flat.png\"\n"
                    "    size = %.1f %.1f\n    max_height = 100\n"
                    "    materials = [%s]\n    cell = 1\n}\n", names[i], SIZE, SIZE,
                    stacks[i]);
            fclose(f);
        }
        free(sg);
    }
    return ok;
}

/* Build DIR/NAME.sg into DIR/NAME.pack (fresh: an old pack with the same
 * inputs would be kept as it is) and load it on the device. */
static bool build(const char *dir, const char *name, rt_pack *pack)
{
    char file[64];
    snprintf(file, sizeof file, "%s.sg", name);
    char *sg = join(dir, file);
    snprintf(file, sizeof file, "%s.pack", name);
    char *packdir = join(dir, file);
    sg_diags d;
    bool ok = build_pack(sg, packdir, SPLAT_PAINTED_BC4, &d);
    if (!ok) sg_diags_print(&d, stderr);
    /* far.sg's uses of position are all periodic: no warning */
    for (int i = 0; i < d.n; i++)
        CHECK(d.items[i].severity != SG_WARNING, "warning: %s", d.items[i].msg);
    sg_diags_free(&d);
    rt_error e = { 0 };
    ok = ok && rt_pack_load(pack, packdir, &e);
    if (e.msg) fprintf(stderr, "%s\n", e.msg);
    rt_error_clear(&e);
    free(sg);
    free(packdir);
    return ok;
}

/* Where the ray of pixel (px, py) of the straight-down camera at (cx, cy,
 * cz) meets the plane y (render.c's matrix: image x = +x, image y = +z). */
static void ground_at(double cx, double cy, double cz, double px, double py,
                      double y, double *x, double *z)
{
    double t = 1.0 / tan(FOVY / 2.0), aspect = (double)W / H;
    double nx = (px + 0.5) / W * 2.0 - 1.0, ny = (py + 0.5) / H * 2.0 - 1.0;
    *x = cx + nx * aspect / t * (cy - y);
    *z = cz + ny / t * (cy - y);
}

static bool render(rt_renderer *r, const double cam[3], splat_view view, int m,
                   float *rgba, const char *png)
{
    rt_error e = { 0 };
    rt_camera c = { .position = { cam[0], cam[1], cam[2] },
                    .look = { cam[0], 0, cam[2] }, .fovy = FOVY };
    rt_renderer_set_view(r, view, m);
    bool ok = rt_renderer_frame(r, &c, NULL, &e) && rt_renderer_read(r, rgba, &e);
    if (ok && png) {
        uint8_t *px = malloc((size_t)W * H * 4);
        rt_tonemap_rgba8(rgba, W, H, RT_TONEMAP_NONE, px);
        ok = px && rt_write_png(png, px, W, H, &e);
        free(px);
    }
    CHECK(ok, "render: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return ok;
}

/* The albedo view against the one near the origin: 99.5 % of the pixels
 * within 8/255. */
static void compare(const float *img, const float *base, const char *path, double offset)
{
    int close = 0;
    double worst = 0;
    for (int i = 0; i < W * H; i++) {
        double m = 0;
        for (int c = 0; c < 3; c++)
            m = fmax(m, fabs((double)img[4 * i + c] - base[4 * i + c]));
        close += m <= 8.0 / 255.0;
        worst = fmax(worst, m);
    }
    double frac = (double)close / (W * H);
    printf("albedo at %5.0f km, %s: %.3f %% of pixels within 8/255 of the forward view "
           "near the origin (largest difference %.4f)\n", offset / 1000, path, 100 * frac,
           worst);
    CHECK(frac >= 0.995, "%.0f km, %s: only %.3f %% within 8/255", offset / 1000, path,
          100 * frac);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_far OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    static const char *const search[] = { ".", NULL };
    rt_pack tex, noise;
    rt_device dev;
    rt_error e = { 0 };
    splat_scene s;
    sg_diags d;
    sg_diags_init(&d);
    char *noise_sg = join(dir, "noise.sg");
    if (!write_inputs(dir) || !build(dir, "tex", &tex) || !build(dir, "noise", &noise) ||
        !splat_scene_load(&s, noise_sg, search, &d) || !rt_device_create(&dev, NULL, &e)) {
        sg_diags_print(&d, stderr);
        fprintf(stderr, "FAIL: setup: %s\n", e.msg ? e.msg : "the scenes do not build");
        return 1;
    }
    sg_diags_free(&d);
    CHECK(tex.nsites == 4, "%d sites (1 m, three tri-planar)", tex.nsites);
    CHECK(noise.nsites == 5, "%d sites (and the noise's)", noise.nsites);
    rt_render_desc rd = { .width = W, .height = H };
    rt_render_desc sd = { .width = W, .height = H, .shading = RT_SHADING_SCREEN };
    rt_renderer *rt = NULL, *rn = NULL, *rs = NULL;
    CHECK(rt_renderer_create(&dev, &tex, &rd, &rt, &e) &&
          rt_renderer_create(&dev, &noise, &rd, &rn, &e) &&
          rt_renderer_create(&dev, &tex, &sd, &rs, &e), "renderer: %s",
          e.msg ? e.msg : "?");
    double h0 = splat_terrain_height(&s.terrain, 0.5, 0.5);
    ir_ref mask = ir_find_root(&s.ir, "far_spots.mask");
    float *base = malloc((size_t)W * H * 16), *img = malloc((size_t)W * H * 16);
    for (size_t k = 0; rt && rn && k < sizeof OFFSETS / sizeof *OFFSETS; k++) {
        double cam[3] = { X0 + OFFSETS[k], h0 + ABOVE, Z0 + OFFSETS[k] };
        char name[64];
        snprintf(name, sizeof name, "albedo_%.0fkm.png", OFFSETS[k] / 1000);
        char *png = join(dir, name);
        bool ok = render(rt, cam, SPLAT_VIEW_ALBEDO, 0, k ? img : base, png);
        free(png);
        if (ok && k > 0)
            compare(img, base, "forward", OFFSETS[k]);
        /* the screen path (compute: the same sites, gradients from its
         * own derivatives), against the forward view near the origin */
        snprintf(name, sizeof name, "albedo_screen_%.0fkm.png", OFFSETS[k] / 1000);
        png = join(dir, name);
        if (render(rs, cam, SPLAT_VIEW_ALBEDO, 0, img, png))
            compare(img, base, "screen", OFFSETS[k]);
        free(png);
        /* the noise's mask against the double reference */
        snprintf(name, sizeof name, "mask_%.0fkm.png", OFFSETS[k] / 1000);
        png = join(dir, name);
        ok = render(rn, cam, SPLAT_VIEW_MASK, 1, img, png);
        free(png);
        double worst = 0;
        for (int j = 0; ok && j < 64; j++) {
            int px = 8 + 32 * (j % 8) + j / 8 % 3, py = 8 + 32 * (j / 8) + j % 5;
            double x, z;
            ground_at(cam[0], cam[1], cam[2], px, py, h0, &x, &z);
            ir_env env = { .height = h0, .slope = 0, .normal = { 0, 1, 0 },
                           .position = { x, h0, z }, .uv = { x / SIZE, z / SIZE },
                           .view_distance = ABOVE };
            double ref[4];
            ir_eval(&s.ir, mask, &env, ref);
            double got = img[4 * ((size_t)py * W + px)];
            worst = fmax(worst, fabs(got - ref[0]));
        }
        printf("noise mask at %5.0f km: largest |GPU - double reference| %.2e at 64 pixels\n",
               OFFSETS[k] / 1000, worst);
        CHECK(worst <= 1e-3, "%.0f km: noise mask off by %g", OFFSETS[k] / 1000, worst);
    }
    free(base);
    free(img);
    if (rt) rt_renderer_destroy(rt);
    if (rn) rt_renderer_destroy(rn);
    if (rs) rt_renderer_destroy(rs);
    CHECK(rt_device_messages(&dev) == 0, "%d validation messages", rt_device_messages(&dev));
    rt_device_destroy(&dev);
    rt_pack_free(&tex);
    rt_pack_free(&noise);
    splat_scene_free(&s);
    free(noise_sg);
    if (failures) {
        fprintf(stderr, "%d failures\n", failures);
        return 1;
    }
    printf("far from the origin: all checks passed\n");
    return 0;
}
