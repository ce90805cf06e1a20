/* test_shadow.c — terrain shadows (runtime/shadow.c) on a Vulkan device
 * with SPLAT_VALIDATE=1 (any validation message fails).
 *
 *   test_shadow OUTDIR   (run from the repository root)
 *
 * A flat 128 m square, 1 m texels, with a box 4 m high on it (texels
 * 90..99 x 56..71), under a sun 5 degrees above the east and no sky: the
 * ground in the box's shadow is black, the rest lit.  Seen straight down:
 *   - the shadow behind the box's west edge (its top at x = 90.5 m, the
 *     texel centre) ends where the geometry says, 4 / tan 5 = 45.7 m
 *     further west, within 2 texels (the half-lit point along the row
 *     through the box), on the forward and the screen-space path;
 *   - rd.no_shadows (splatview --no-shadows) lights that ground;
 *   - a crater on the box (3 m deep) lowers it: the shadow gets shorter,
 *     and the map remade only where the crater can matter is the whole
 *     map made again (the sun turned away and back);
 *   - turning the sun to the west moves the shadow to the box's east. */
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { N = 128, W = 256, H = 256 };
static const double FOVY = M_PI / 3.0, ABOVE = 110.0, BOX = 4.0, EDGE = 90.5;
static const double SUN_EL = 5.0;

static bool write_inputs(const char *dir)
{
    uint8_t hf[N * N];
    memset(hf, 0, sizeof hf);
    for (int z = 56; z < 72; z++)
        for (int x = 90; x < 100; x++)
            hf[z * N + x] = 40;   /* 40 / 255 * 25.5 m = 4 m */
    char *png = kit_join(dir, "box.png"), *sg = kit_join(dir, "box.sg");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0;
    FILE *f = fopen(sg, "w");
    ok = ok && f;
    if (f) {
        fprintf(f, "import \"nodes/compositors.sg\"\n"
                   "material ground {\n    out albedo = vec3(0.5, 0.5, 0.5)\n"
                   "    out roughness = 0.9\n}\n"
                   "scene shadow_box {\n    heightfield = \"box.png\"\n    size = %d %d\n"
                   "    max_height = 25.5\n    materials = [ground]\n    cell = 16\n"
                   "    destruction { origin = 64 32, size = 64 64, cell = 16 }\n"
                   "    light { sun = 90 %g, sun_color = 1 1 1, intensity = 3, sky = 0 0 0, "
                   "fog_density = 0 }\n}\n", N, N, SUN_EL);
        ok &= fclose(f) == 0;
    }
    free(png);
    free(sg);
    return ok;
}

/* Ground x (m) of image column px from the straight-down camera over the
 * centre (render.c's matrix: image x = +x). */
static double ground_x(double px)
{
    double t = 1.0 / tan(FOVY / 2.0);
    return N / 2.0 + ((px + 0.5) / W * 2.0 - 1.0) / t * ABOVE;
}

static double lum(const float *img, int px, int py)
{
    const float *c = img + 4 * ((size_t)py * W + px);
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

/* Where, along the image row through the box's middle, going west from
 * column `from`, the ground first reaches half the lit level (metres,
 * interpolated between pixels); -1 if it never does. */
static double half_lit_x(const float *img, int from, int dir)
{
    int py = H / 2;
    double lit = lum(img, dir < 0 ? 4 : W - 5, py);
    for (int px = from; px > 0 && px < W - 1; px += dir) {
        double a = lum(img, px, py), b = lum(img, px + dir, py);
        if (a < 0.5 * lit && b >= 0.5 * lit) {
            double f = (0.5 * lit - a) / (b - a);
            return ground_x(px + dir * f);
        }
    }
    return -1;
}

/* Column of ground x. */
static int column(double x)
{
    double t = 1.0 / tan(FOVY / 2.0);
    return (int)floor(((x - N / 2.0) * t / ABOVE + 1.0) * W / 2.0);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_shadow OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    char *sg = kit_join(dir, "box.sg"), *packdir = kit_join(dir, "box.pack");
    rt_pack *p = write_inputs(dir) && kit_build_pack_ok(sg, packdir) ? kit_pack(packdir) : NULL;
    rt_device *dev = p ? kit_device() : NULL;
    rt_error e = { 0 };
    if (!dev)
        return kit_finish("shadow");
    free(sg);
    free(packdir);
    rt_camera cam = { .position = { N / 2.0, ABOVE, N / 2.0 }, .look = { N / 2.0, 0, N / 2.0 },
                      .fovy = FOVY };
    double want = EDGE - BOX / tan(SUN_EL * M_PI / 180.0);
    int edge_px = column(EDGE - 1.5), mid_px = column((EDGE + want) / 2);

    static const char *const paths[2] = { "forward", "screen" };
    for (int s = 0; s < 2; s++) {
        rt_render_desc rd = { .width = W, .height = H,
                              .shading = s ? RT_SHADING_SCREEN : RT_SHADING_FORWARD };
        float *img = kit_render(dev, p, &rd, SPLAT_VIEW_FINAL, 0, &cam);
        if (!img) continue;
        double end = half_lit_x(img, edge_px, -1);
        printf("%s: shadow ends at x = %.2f m, length %.2f m; geometry: %.2f m, length %.2f m\n",
               paths[s], end, EDGE - end, want, EDGE - want);
        CHECK(fabs(end - want) <= 2.0, "%s: shadow end %.2f m, geometry %.2f m", paths[s], end,
              want);
        CHECK(lum(img, mid_px, H / 2) < 1e-4, "%s: the shadow's middle is lit (%g)", paths[s],
              lum(img, mid_px, H / 2));
        if (s == 0) kit_write_picture(dir, "shadow.png", img, W, H, SPLAT_VIEW_FINAL);
        free(img);
    }

    /* --no-shadows */
    rt_render_desc off = { .width = W, .height = H, .no_shadows = true };
    float *img = kit_render(dev, p, &off, SPLAT_VIEW_FINAL, 0, &cam);
    if (img) {
        double mid = lum(img, mid_px, H / 2), lit = lum(img, 4, H / 2);
        printf("no shadows: the shadow's middle %.4f, lit ground %.4f\n", mid, lit);
        /* the same but for the sun's highlight, which follows the view */
        CHECK(lit > 0.05 && fabs(mid - lit) < 0.01 * lit, "no_shadows: %g against %g", mid, lit);
        free(img);
    }

    /* a crater on the box, and the sun turned to the west: one renderer */
    rt_render_desc rd = { .width = W, .height = H };
    rt_renderer *r = NULL;
    CHECK(rt_renderer_create(dev, p, &rd, &r, &e), "renderer: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    if (r) {
        float *before = kit_frame(r, &cam, W, H);
        rt_crater c = { .x = 95, .z = 64, .radius = 8, .depth = 3 };
        rt_crater_stats cs;
        CHECK(rt_renderer_crater(r, &c, &cs, &e) && cs.result == RT_CRATER_DONE, "crater: %s",
              e.msg ? e.msg : "refused or outside");
        rt_error_clear(&e);
        rt_frame_stats st;
        float *after = NULL;
        CHECK(rt_renderer_frame(r, &cam, &st, &e), "frame: %s", e.msg ? e.msg : "?");
        after = kit_frame(r, &cam, W, H);
        if (before && after) {
            double b = half_lit_x(before, edge_px, -1), a = half_lit_x(after, edge_px, -1);
            printf("crater on the box: the shadow ends at %.2f m (was %.2f m); map remade in "
                   "%.2f ms\n", a, b, st.shadow_ms);
            CHECK(a > b + 5.0, "the crater did not shorten the shadow (%.2f -> %.2f)", b, a);
            CHECK(st.shadow_ms > 0, "no new shadow map after the crater");
            kit_write_picture(dir, "crater.png", after, W, H, SPLAT_VIEW_FINAL);
        }
        /* the same map made whole: the sun turned by a degree and back */
        rt_light l = *rt_renderer_light(r), turned = l;
        turned.sun[0] += 1;
        rt_renderer_set_light(r, &turned);
        float *t = kit_frame(r, &cam, W, H);
        rt_renderer_set_light(r, &l);
        rt_frame_stats fs;
        CHECK(rt_renderer_frame(r, &cam, &fs, &e), "frame: %s", e.msg ? e.msg : "?");
        float *whole = kit_frame(r, &cam, W, H);
        if (after && whole) {
            double worst = 0;
            for (size_t i = 0; i < (size_t)W * H * 4; i++)
                worst = fmax(worst, fabs((double)after[i] - whole[i]));
            printf("the crater's part of the map (%.2f ms) against the whole map (%.2f ms): "
                   "max difference %g\n", st.shadow_ms, fs.shadow_ms, worst);
            CHECK(worst == 0, "the partial map differs from the whole by %g", worst);
        }
        free(t);
        free(whole);
        l.sun[0] = 270;
        rt_renderer_set_light(r, &l);
        float *west = kit_frame(r, &cam, W, H);
        if (west) {
            int east_px = column(100.5 + 10);
            printf("sun in the west: 10 m east of the box %.4f, 10 m west %.4f\n",
                   lum(west, east_px, H / 2), lum(west, column(EDGE - 11), H / 2));
            CHECK(lum(west, east_px, H / 2) < 1e-4 && lum(west, column(EDGE - 11), H / 2) > 0.05,
                  "the shadow did not follow the sun");
        }
        free(before);
        free(after);
        free(west);
        rt_renderer_destroy(r);
    }
    kit_device_close(dev);
    rt_pack_close(p);
    return kit_finish("shadow");
}
