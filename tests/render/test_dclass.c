/* test_dclass.c — distance classes (compiler/distance.c, PACK.md) against
 * the über-shader on a Vulkan device, SPLAT_VALIDATE=1 (any validation
 * message fails).
 *
 *   test_dclass PACKDIR   (colorado's pack, built by render.pack_colorado)
 *
 * At 20 random cameras (a fixed seed), at 128x72: half of them 2 to 400 m
 * above the ground (log-uniform) anywhere over the terrain, looking 5 to
 * 45 degrees down in any direction; the other half 20 to 250 m from a
 * random point of a leaf cell whose combination has rock on top and whose
 * slope is over rock's ramp (bare rock), looking at it from 2 to 50 m up (rock's parallax fades out at 300 m, so nodes
 * and tiles fall on both sides of its class boundary); each path (forward, screen) renders the picture
 * with the distance classes on and the picture with every patch / tile on
 * the über-shader (--reference uber); they must agree within 1/255 in
 * every channel of every pixel.  The classes must have been used (patches
 * and tiles shaded by one) and not everywhere, or the test proves nothing;
 * and with rd.no_distance_classes none is used. */
#include "rt_internal.h"   /* the leaf combination map: rt_pack.levels, combos */
#include "kit.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 128, H = 72, CAMERAS = 20 };

static uint64_t rng = 0x853c49e6748fea9bull;
static double rnd01(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* The highest of the four texels around (x, z) metres. */
static double ground(const rt_pack *p, double x, double z)
{
    int i = (int)(x / p->size[0] * p->hf_width), j = (int)(z / p->size[1] * p->hf_height);
    double h = 0;
    for (int k = 0; k < 4; k++) {
        int a = i + (k & 1), b = j + (k >> 1);
        a = a < 0 ? 0 : a >= p->hf_width ? p->hf_width - 1 : a;
        b = b < 0 ? 0 : b >= p->hf_height ? p->hf_height - 1 : b;
        h = fmax(h, p->heights[(size_t)b * (size_t)p->hf_width + (size_t)a]);
    }
    return h / 65535.0 * p->max_height + p->height_offset;
}

/* 1 - n.y of Listing 1's normal at the texel under (x, z) (abi.c). */
static double slope(const rt_pack *p, double x, double z)
{
    int i = (int)(x / p->size[0] * p->hf_width), j = (int)(z / p->size[1] * p->hf_height);
#define T(a, b) ((double)p->heights[(size_t)((b) < 0 ? 0 : (b) >= p->hf_height ? p->hf_height - 1 : (b)) * \
                 (size_t)p->hf_width + (size_t)((a) < 0 ? 0 : (a) >= p->hf_width ? p->hf_width - 1 : (a))] / 65535.0)
    double nx = (T(i - 1, j) - T(i + 1, j)) * p->max_height / (p->size[0] / p->hf_width);
    double nz = (T(i, j - 1) - T(i, j + 1)) * p->max_height / (p->size[1] / p->hf_height);
#undef T
    return 1 - 2 / sqrt(nx * nx + 4 + nz * nz);
}

static bool frame(rt_renderer *r, const rt_camera *c, rt_frame_stats *st, float *img)
{
    rt_error e = { 0 };
    bool ok = rt_renderer_frame(r, c, st, &e) && rt_renderer_read(r, img, &e);
    CHECK(ok, "frame: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_dclass PACKDIR\n");
        return 2;
    }
    rt_pack *p = kit_pack(argv[1]);
    rt_device *dev = p ? kit_device() : NULL;
    rt_error e = { 0 };
    if (!dev)
        return kit_finish("distance classes");
    CHECK(p->ncombos > p->nbase, "the pack has no distance classes (%d combinations)", p->nbase);
    /* texels whose leaf cell has rock as the top material of its
     * combination (nothing above it is present) and whose slope is over
     * rock's ramp (graphs/rock.sg: 0.16 .. 0.24), so bare rock: half the
     * cameras look at one from 20 to 250 m, where the parallax is on (a
     * class used there would show) */
    int rock = rt_pack_material_find(p, "rock");
    const rt_pack_level *leaf = &p->levels[0];
    int *texels = malloc(sizeof(int) * (size_t)p->hf_width * (size_t)p->hf_height), ntexels = 0;
    for (int tz = 0; texels && tz < p->hf_height; tz++)
        for (int tx = 0; tx < p->hf_width; tx++) {
            int cx = tx / p->cell_texels, cz = tz / p->cell_texels;
            int id = leaf->ids[(size_t)cz * (size_t)leaf->width + (size_t)cx];
            double x = (tx + 0.5) * p->size[0] / p->hf_width, z = (tz + 0.5) * p->size[1] / p->hf_height;
            if (id < p->nbase && p->combos[id].materials[0] == rock && slope(p, x, z) > 0.24)
                texels[ntexels++] = tz * p->hf_width + tx;
        }
    printf("%d texels of bare rock\n", ntexels);
    CHECK(rock >= 0 && ntexels > 0, "colorado has no bare rock");
    rt_camera cams[CAMERAS];
    for (int i = 0; i < CAMERAS; i++) {
        double x = p->size[0] * (0.02 + 0.96 * rnd01()), z = p->size[1] * (0.02 + 0.96 * rnd01());
        double above = 2.0 * pow(200.0, rnd01());
        double yaw = 2 * M_PI * rnd01(), pitch = (5 + 40 * rnd01()) * M_PI / 180;
        double y = ground(p, x, z) + above;
        double look[3] = { x + cos(yaw) * cos(pitch), y - sin(pitch), z + sin(yaw) * cos(pitch) };
        if (i % 2 && ntexels > 0) {   /* at bare rock */
            int t = texels[(int)(rnd01() * ntexels) % ntexels];
            look[0] = (t % p->hf_width + rnd01()) * p->size[0] / p->hf_width;
            look[2] = (t / p->hf_width + rnd01()) * p->size[1] / p->hf_height;
            look[1] = ground(p, look[0], look[2]);
            double d = 20 * pow(12.5, rnd01());
            x = look[0] + d * cos(yaw);
            z = look[2] + d * sin(yaw);
            y = fmax(ground(p, x, z), look[1]) + 2 + 48 * rnd01();
        }
        cams[i] = (rt_camera){ .position = { x, y, z }, .look = { look[0], look[1], look[2] },
                               .fovy = M_PI / 3, .znear = 0.25 };
    }
    free(texels);
    float *a = malloc(sizeof(float) * W * H * 4), *b = malloc(sizeof(float) * W * H * 4);
    static const char *const names[2] = { "forward", "screen" };
    for (int s = 0; s < 2 && a && b; s++) {
        rt_shading sh = s ? RT_SHADING_SCREEN : RT_SHADING_FORWARD;
        rt_render_desc on = { .width = W, .height = H, .shading = sh, .no_undergrowth = true };
        rt_render_desc uber = on, off = on;
        uber.reference = RT_REF_UBER;
        off.no_distance_classes = true;
        rt_renderer *ro = NULL, *ru = NULL, *rf = NULL;
        bool made = rt_renderer_create(dev, p, &on, &ro, &e) &&
                    rt_renderer_create(dev, p, &uber, &ru, &e) &&
                    rt_renderer_create(dev, p, &off, &rf, &e);
        CHECK(made, "%s renderers: %s", names[s], e.msg ? e.msg : "?");
        rt_error_clear(&e);
        long used = 0, total = 0, used_off = 0;
        double worst = 0;
        for (int i = 0; made && i < CAMERAS; i++) {
            rt_frame_stats so, su, sf;
            /* rf's picture is not compared (render.screen_* and the
             * example tests hold the plain composites to the über-shader):
             * only that it uses no class */
            if (!frame(ro, &cams[i], &so, a) || !frame(rf, &cams[i], &sf, b) ||
                !frame(ru, &cams[i], &su, b))
                break;
            int u = s ? so.tiles.tiles_class : so.class_patches;
            int t = s ? so.tiles.tiles : so.patches;
            used += u;
            total += t;
            used_off += s ? sf.tiles.tiles_class : sf.class_patches;
            double cam_worst = 0;
            size_t at = 0;
            for (size_t k = 0; k < (size_t)W * H * 4; k++) {
                double d = fabs((double)a[k] - b[k]);
                if (d > cam_worst || isnan(d)) {
                    cam_worst = isnan(d) ? INFINITY : d;
                    at = k / 4;
                }
            }
            printf("%s camera %2d (%.0f, %.0f, %.0f) -> (%.0f, %.0f, %.0f), %5.1f m up: "
                   "classes on %d of %d %s, max difference to the über-shader %.3g at "
                   "(%zu, %zu)\n", names[s], i,
                   cams[i].position[0], cams[i].position[1], cams[i].position[2],
                   cams[i].look[0], cams[i].look[1], cams[i].look[2],
                   cams[i].position[1] - ground(p, cams[i].position[0], cams[i].position[2]),
                   u, t, s ? "tiles" : "patches", cam_worst, at % W, at / W);
            CHECK(cam_worst <= 1.0 / 255, "%s camera %d: classes differ from the über-shader "
                  "by %g", names[s], i, cam_worst);
            worst = fmax(worst, cam_worst);
        }
        printf("%s: classes shaded %ld of %ld %s; largest difference %.3g\n", names[s], used,
               total, s ? "tiles" : "patches", worst);
        CHECK(used > 0 && used < total, "%s: classes used on %ld of %ld: the test proves "
              "nothing", names[s], used, total);
        CHECK(used_off == 0, "%s: no_distance_classes still used %ld", names[s], used_off);
        rt_renderer_destroy(ro);
        rt_renderer_destroy(ru);
        rt_renderer_destroy(rf);
    }
    free(a);
    free(b);
    kit_device_close(dev);
    rt_pack_close(p);
    return kit_finish("distance classes");
}
