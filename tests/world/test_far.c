/* test_far.c — shading far from the origin (compiler/precision.c, the
 * vertex lattice of abi.h splat_push) on a Vulkan device (lavapipe here;
 * SPLAT_VALIDATE=1, any validation message fails).
 *
 *   test_far OUTDIR
 *
 * A flat terrain 10,240 km wide (1024 x 1024 texels of 10 km) with
 * tests/world/far.sg's materials: a 1 m top-down texture, an 8 m
 * tri-planar one and ALU value noise of 2 m cells; cell 1 (10 km
 * patches) and, for "coarse", cell 32 (320 km patches).  Three local
 * views, each near the origin and 100 km, 1,000 km and 5,000 km away
 * (along x and z: multiples of every period):
 *   - "down", straight down from 30 m, inside one 10 km patch;
 *   - "edges", 12 m up and looking 11 degrees down over the corner (40 km,
 *     40 km) where four 10 km patches meet, so two patch edges cross the
 *     picture; the camera's coordinates are not floats (39,978.3 m);
 *   - "coarse", the same over the corner (320 km, 320 km) of four 320 km
 *     patches (the offsets are not multiples of 320 km: far away the
 *     edges lie elsewhere).  Before the lattice its near view showed the
 *     sky through a crack along the patch edge, 12 pixels on one line.
 * Checks:
 *   - the albedo views, forward, screen-space with rasterised depth and
 *     screen-space with ray-cast depth (the GPUs' default), against the
 *     forward one near the origin: at most 0.5 % of the pixels over
 *     8/255, and no line of differing pixels (line_pixels, is_line; issue
 *     34: seams along patch edges, 0.8 % of the pixels, all in lines);
 *   - the line detector itself, on drawn lines and on scattered pixels;
 *   - the noise material's mask view matches the double-precision
 *     reference (ir_eval, what `splatc eval` prints) within 1e-3 at 64
 *     pixels of each view.
 * Without the precision pass the 5,000 km view fails both (position's
 * fp32 ulp there is 0.5 m).  Pictures go to OUTDIR: each view, and
 * diff_*.png (red: over 8/255, grey: the difference times 16). */
#include "kit.h"
#include "scene_load.h"   /* the compiler's scene, to sample its composite on the CPU */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { N = 1024, W = 256, H = 256, LINE = 8 };
static const double SIZE = 10240000.0, FOVY = M_PI / 3.0, ABOVE = 30.0;
static const double X0 = 41234.5, Z0 = 47876.25;    /* near the origin */
static const double OFFSETS[] = { 0.0, 1e5, 1e6, 5e6 };
/* "edges": over the patch corner (40 km, 40 km), relative to the ground */
static const double EDGE_CAM[3] = { 39978.3, 12.0, 39982.2 };   /* y: above the ground */
static const double EDGE_LOOK[3] = { 40028.3, 0.0, 40022.2 };
/* "coarse": the same view over the corner where four 320 km patches meet */
static const double COARSE_CORNER = 320000.0;

/* The flat heightfield and three scenes over it: "tex" (far_base alone:
 * its albedo must not change with the offset), "noise" (far_spots on
 * top: value noise's 289-cell period does not divide the offsets, so it
 * is held to the double reference instead) and "coarse" (far_base with
 * cells of 32 texels: 320 km patches). */
static bool write_inputs(const char *dir)
{
    uint8_t *hf = malloc((size_t)N * N);
    if (!hf) return false;
    memset(hf, 128, (size_t)N * N);
    char *png = kit_join(dir, "flat.png");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0;
    free(hf);
    free(png);
    static const char *const names[3] = { "tex", "noise", "coarse" };
    static const char *const stacks[3] = { "far_base", "far_base, far_spots", "far_base" };
    static const int cells[3] = { 1, 1, 32 };
    for (int i = 0; ok && i < 3; i++) {
        char file[32];
        snprintf(file, sizeof file, "%s.sg", names[i]);
        char *sg = kit_join(dir, file);
        FILE *f = fopen(sg, "w");
        ok = f != NULL;
        if (f) {
            fprintf(f, "import \"nodes/compositors.sg\"\nimport \"tests/world/far.sg\"\n"
                    "scene far_%s {\n    heightfield = \"flat.png\"\n"
                    "    size = %.1f %.1f\n    max_height = 100\n"
                    "    materials = [%s]\n    cell = %d\n}\n", names[i], SIZE, SIZE,
                    stacks[i], cells[i]);
            fclose(f);
        }
        free(sg);
    }
    return ok;
}

/* Build DIR/NAME.sg into DIR/NAME.pack (fresh: an old pack with the same
 * inputs would be kept as it is) and load it on the device. */
static bool build(const char *dir, const char *name, rt_pack **pack)
{
    char file[64];
    snprintf(file, sizeof file, "%s.sg", name);
    char *sg = kit_join(dir, file);
    snprintf(file, sizeof file, "%s.pack", name);
    char *packdir = kit_join(dir, file);
    sg_diags d;
    bool ok = kit_build_pack(sg, packdir, SPLAT_PAINTED_BC4, &d);
    if (!ok) sg_diags_print(&d, stderr);
    /* far.sg's uses of position are all periodic: no warning */
    for (int i = 0; i < d.n; i++)
        CHECK(d.items[i].severity != SG_WARNING, "warning: %s", d.items[i].msg);
    sg_diags_free(&d);
    ok = ok && (*pack = kit_pack(packdir));
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

static bool render(rt_renderer *r, const double cam[3], const double look[3], splat_view view,
                   int m, float *rgba, const char *png)
{
    rt_error e = { 0 };
    rt_camera c = { .position = { cam[0], cam[1], cam[2] },
                    .look = { look[0], look[1], look[2] }, .fovy = FOVY };
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

/* The most differing pixels on one straight line of the picture: pixel
 * centres in a band two pixels wide, over lines at every half degree and
 * every pixel of distance from the corner (a Hough transform).  A seam
 * along a patch edge, whole or dotted (a crack shows only where it
 * crosses pixel centres), puts all its pixels on one line; differences
 * scattered at density d put about d * 2 * length there (is_line). */
static int line_pixels(const uint8_t *bad, int w, int h)
{
    const int nr = 2 * (int)ceil(hypot(w, h)) + 2, na = 360;
    int *bins = malloc((size_t)nr * sizeof *bins), best = 0;
    if (!bins)
        return w * h;   /* no memory: report a line */
    for (int a = 0; a < na; a++) {
        double t = M_PI * a / na, ct = cos(t), st = sin(t);
        memset(bins, 0, (size_t)nr * sizeof *bins);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                if (bad[(size_t)y * w + x])
                    bins[(int)floor(x * ct + y * st) + nr / 2]++;
        for (int r = 0; r + 1 < nr; r++)
            best = bins[r] + bins[r + 1] > best ? bins[r] + bins[r + 1] : best;
    }
    free(bins);
    return best;
}

/* Whether n pixels on one line (line_pixels) of a w x h mask with `over`
 * set pixels make a line: at least LINE, and six times what scattered
 * pixels would put on the longest band (0.5 % of the pixels: 22). */
static bool is_line(int n, int over, int w, int h)
{
    double scattered = (double)over / ((double)w * h) * 2.0 * hypot(w, h);
    return n >= LINE && n >= 6.0 * scattered;
}

/* The detector finds what it is for: a dashed slanted line, a row, a
 * dotted line of LINE pixels 30 apart (a crack), and not 0.5 % of the
 * pixels scattered. */
static void check_detector(void)
{
    uint8_t *bad = calloc((size_t)W * H, 1);
    if (!bad) return;
    int over = 0;
    for (int t = 0; t < 40; t++)   /* every third pixel missing */
        if (t % 3 != 2) {
            bad[(size_t)(100 + t / 3) * W + 30 + t] = 1;
            over++;
        }
    CHECK(is_line(line_pixels(bad, W, H), over, W, H), "a dashed slanted line: %d px",
          line_pixels(bad, W, H));
    memset(bad, 0, (size_t)W * H);
    for (int x = 10; x < 10 + LINE; x++)
        bad[(size_t)7 * W + x] = 1;
    CHECK(is_line(line_pixels(bad, W, H), LINE, W, H), "a row of %d px: %d", LINE,
          line_pixels(bad, W, H));
    memset(bad, 0, (size_t)W * H);
    for (int k = 0; k < LINE; k++)
        bad[(size_t)(20 + 13 * k) * W + 5 + 30 * k / 2] = 1;
    CHECK(is_line(line_pixels(bad, W, H), LINE, W, H), "a dotted line of %d px: %d", LINE,
          line_pixels(bad, W, H));
    memset(bad, 0, (size_t)W * H);
    uint32_t seed = 12345u;
    over = 0;
    for (int i = 0; i < W * H / 200; i++) {
        seed = seed * 1664525u + 1013904223u;
        size_t at = (seed >> 8) % ((uint32_t)W * H);
        over += !bad[at];
        bad[at] = 1;
    }
    CHECK(!is_line(line_pixels(bad, W, H), over, W, H), "%d scattered pixels: %d on a line",
          over, line_pixels(bad, W, H));
    free(bad);
}

/* The albedo view against the forward one near the origin: at most 0.5 %
 * of the pixels over 8/255, none of them in a line; the difference goes
 * to diff (red over 8/255, else grey times 16). */
static void compare(const float *img, const float *base, const char *what, double offset,
                    const char *diff)
{
    int over = 0;
    double worst = 0;
    uint8_t *bad = malloc((size_t)W * H), *px = malloc((size_t)W * H * 4);
    if (!bad || !px) {
        free(bad);
        free(px);
        CHECK(false, "out of memory");
        return;
    }
    for (int i = 0; i < W * H; i++) {
        double m = 0;
        for (int c = 0; c < 3; c++)
            m = fmax(m, fabs((double)img[4 * i + c] - base[4 * i + c]));
        bad[i] = m > 8.0 / 255.0;
        over += bad[i];
        worst = fmax(worst, m);
        uint8_t g = (uint8_t)fmin(255.0, m * 255.0 * 16.0);
        px[4 * i + 0] = bad[i] ? 255 : g;
        px[4 * i + 1] = bad[i] ? 0 : g;
        px[4 * i + 2] = bad[i] ? 0 : g;
        px[4 * i + 3] = 255;
    }
    int line = line_pixels(bad, W, H);
    double frac = (double)over / (W * H);
    printf("albedo at %5.0f km, %-23s: %.3f %% of pixels over 8/255 of the forward view "
           "near the origin, %d on one line (largest difference %.4f)\n", offset / 1000,
           what, 100 * frac, line, worst);
    CHECK(frac <= 0.005, "%.0f km, %s: %.3f %% over 8/255", offset / 1000, what, 100 * frac);
    CHECK(!is_line(line, over, W, H), "%.0f km, %s: a line of %d differing pixels (see %s)",
          offset / 1000, what, line, diff);
    rt_error e = { 0 };
    CHECK(rt_write_png(diff, px, W, H, &e), "%s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    free(bad);
    free(px);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_far OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    static const char *const search[] = { ".", NULL };
    rt_pack *tex = NULL, *noise = NULL, *coarse = NULL;
    rt_device *dev = NULL;
    rt_error e = { 0 };
    splat_scene s;
    sg_diags d;
    sg_diags_init(&d);
    char *noise_sg = kit_join(dir, "noise.sg");
    if (!write_inputs(dir) || !build(dir, "tex", &tex) || !build(dir, "noise", &noise) ||
        !build(dir, "coarse", &coarse) || !splat_scene_load(&s, noise_sg, search, &d) ||
        !(dev = kit_device())) {
        sg_diags_print(&d, stderr);
        CHECK(false, "setup: the scenes do not build, load or find a device");
        return kit_finish("far from the origin");
    }
    sg_diags_free(&d);
    rt_pack_info ti = kit_pack_info(tex), ni = kit_pack_info(noise);
    CHECK(ti.nsites == 4, "%d sites (1 m, three tri-planar)", ti.nsites);
    CHECK(ni.nsites == 5, "%d sites (and the noise's)", ni.nsites);
    check_detector();
    rt_render_desc rd = { .width = W, .height = H };
    rt_render_desc sd = { .width = W, .height = H, .shading = RT_SHADING_SCREEN,
                          .screen_depth = RT_DEPTH_RASTER };
    rt_render_desc cd = { .width = W, .height = H, .shading = RT_SHADING_SCREEN,
                          .screen_depth = RT_DEPTH_RAYCAST };
    /* per pack (tex, coarse): forward, screen, screen with ray casting */
    rt_renderer *rp[2][3] = { { NULL } }, *rn = NULL;
    const rt_render_desc *descs[3] = { &rd, &sd, &cd };
    bool made = rt_renderer_create(dev, noise, &rd, &rn, &e);
    for (int i = 0; made && i < 6; i++)
        made = rt_renderer_create(dev, i < 3 ? tex : coarse, descs[i % 3], &rp[i / 3][i % 3],
                                  &e);
    CHECK(made, "renderer: %s", e.msg ? e.msg : "?");
    double h0 = splat_terrain_height(&s.terrain, 0.5, 0.5);
    ir_ref mask = ir_find_root(&s.ir, "far_spots.mask");
    float *base = malloc((size_t)W * H * 16), *img = malloc((size_t)W * H * 16);
    static const char *const views[3] = { "down", "edges", "coarse" };
    static const char *const paths[3] = { "forward", "screen", "screen_raycast" };
    for (int v = 0; made && base && img && v < 3; v++)
        for (size_t k = 0; k < sizeof OFFSETS / sizeof *OFFSETS; k++) {
            double o = OFFSETS[k];
            double cam[3] = { X0 + o, h0 + ABOVE, Z0 + o }, look[3] = { X0 + o, 0, Z0 + o };
            if (v > 0)   /* "coarse": over its corner at 320 km */
                for (int a = 0; a < 3; a++) {
                    double at = v == 2 && a != 1 ? COARSE_CORNER - 40000.0 : 0.0;
                    cam[a] = EDGE_CAM[a] + (a == 1 ? h0 : o + at);
                    look[a] = EDGE_LOOK[a] + (a == 1 ? h0 : o + at);
                }
            /* forward, then the screen path (compute: the same sites,
             * gradients from its own derivatives) with rasterised and
             * ray-cast depth, against the forward view near the origin */
            for (int q = 0; q < 3; q++) {
                char name[96], what[64];
                snprintf(name, sizeof name, "albedo_%s_%s_%.0fkm.png", views[v], paths[q], o / 1000);
                char *png = kit_join(dir, name);
                bool first = k == 0 && q == 0;
                bool ok = render(rp[v == 2][q], cam, look, SPLAT_VIEW_ALBEDO, 0,
                                 first ? base : img, png);
                free(png);
                if (!ok || first)
                    continue;
                snprintf(name, sizeof name, "diff_%s_%s_%.0fkm.png", views[v], paths[q], o / 1000);
                snprintf(what, sizeof what, "%s, %s", views[v], paths[q]);
                png = kit_join(dir, name);
                compare(img, base, what, o, png);
                free(png);
            }
            if (v != 0)
                continue;
            /* the noise's mask against the double reference */
            char name[64];
            snprintf(name, sizeof name, "mask_%.0fkm.png", o / 1000);
            char *png = kit_join(dir, name);
            bool ok = render(rn, cam, look, SPLAT_VIEW_MASK, 1, img, png);
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
                   o / 1000, worst);
            CHECK(worst <= 1e-3, "%.0f km: noise mask off by %g", o / 1000, worst);
        }
    free(base);
    free(img);
    if (rn) rt_renderer_destroy(rn);
    for (int i = 0; i < 6; i++)
        if (rp[i / 3][i % 3]) rt_renderer_destroy(rp[i / 3][i % 3]);
    kit_device_close(dev);
    rt_pack_close(tex);
    rt_pack_close(noise);
    rt_pack_close(coarse);
    splat_scene_free(&s);
    free(noise_sg);
    return kit_finish("far from the origin");
}
