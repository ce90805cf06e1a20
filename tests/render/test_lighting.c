/* test_lighting.c — preview lighting (runtime/light.c, the prelude's
 * splat_light) on a Vulkan device, SPLAT_VALIDATE=1: any validation
 * message fails.
 *
 *   test_lighting OUTDIR   (run from the repository root)
 *
 * Builds examples/minimal twice, as is and with a `light` block
 * (exposure = 1, sun = 200 35, fog_density = 0), and checks:
 *   - the manifest carries the block and the pack loader reads it;
 *   - exposure is a factor on the linear image: +1 EV doubles every
 *     terrain pixel (the background keeps its clear colour);
 *   - the block and splatview's overrides (rt_render_desc: --sun etc. and
 *     the generic --light KEY=V keys) give the same image: the scene's
 *     light = the same light set from outside;
 *   - the sun matters: a high sun lights the terrain more than one 5
 *     degrees up, and turning it 180 degrees changes the picture;
 *   - no fog (fog_density 0) leaves far terrain its own colour, default
 *     fog pulls it towards the sky;
 *   - a `light` value out of range is a located scene error. */
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 320, H = 200 };

/* The scene with a light block (and `extra` lines in it), next to the
 * example so its imports and rasters resolve. */
static bool write_scene(const char *path, const char *light)
{
    FILE *in = fopen("examples/minimal/scene.sg", "r"), *out = fopen(path, "w");
    bool ok = in && out;
    char line[1024];
    while (ok && fgets(line, sizeof line, in)) {
        fputs(line, out);
        if (!strncmp(line, "scene ", 6))
            fprintf(out, "    light { %s }\n", light);
    }
    if (in) fclose(in);
    if (out) ok &= fclose(out) == 0;
    return ok;
}

static float *render(rt_device *dev, const rt_pack *p, const rt_render_desc *rdin,
                     const rt_camera *cam)
{
    rt_render_desc rd = *rdin;
    rd.width = W;
    rd.height = H;
    rd.clear[0] = 1.0f, rd.clear[2] = 1.0f, rd.clear[3] = 1.0f;   /* magenta */
    return kit_render(dev, p, &rd, SPLAT_VIEW_FINAL, 0, cam);
}

static bool background(const float *c)
{
    return c[0] == 1.0f && c[1] == 0.0f && c[2] == 1.0f;
}

/* mean luminance over terrain pixels; *n of them */
static double mean_lum(const float *px, int *n)
{
    double s = 0;
    *n = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        if (!background(px + 4 * i)) {
            s += 0.2126 * px[4 * i] + 0.7152 * px[4 * i + 1] + 0.0722 * px[4 * i + 2];
            (*n)++;
        }
    return *n ? s / *n : 0;
}

static double max_diff(const float *a, const float *b)
{
    return kit_max_diff(a, b, (size_t)W * H * 4);
}

static void check_bad_light(const char *dir)
{
    char sg[512];
    snprintf(sg, sizeof sg, "%s/bad.sg", dir);
    CHECK(write_scene(sg, "sun = 144 120"), "%s", sg);
    char out[512];
    snprintf(out, sizeof out, "%s/bad_pack", dir);
    sg_diags d;
    CHECK(!kit_build_pack(sg, out, SPLAT_PAINTED_BC4, &d), "an elevation of 120 built");
    bool found = false;
    for (int i = 0; i < d.n; i++)
        found |= d.items[i].id == SG_E_SETTING && d.items[i].loc.line > 0 &&
                 strstr(d.items[i].msg, "light sun: 120 is outside") != NULL;
    CHECK(found, "no located SETTING error for the sun");
    sg_diags_free(&d);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_lighting OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    char plain[512], lit[512], sg[512];
    snprintf(plain, sizeof plain, "%s/plain", dir);
    snprintf(lit, sizeof lit, "%s/lit", dir);
    snprintf(sg, sizeof sg, "examples/minimal/.lighting_test.sg");
    bool ok = write_scene(sg, "exposure = 1, sun = 200 35, fog_density = 0") &&
              kit_build_pack_ok("examples/minimal/scene.sg", plain) && kit_build_pack_ok(sg, lit);
    remove(sg);
    if (!ok) {
        fprintf(stderr, "FAIL: the packs do not build\n");
        return 1;
    }
    rt_pack *pp = kit_pack(plain), *pl = kit_pack(lit);
    rt_device *dev = pp && pl ? kit_device() : NULL;
    if (!dev)
        return kit_finish("lighting");
    const rt_light *ll = rt_pack_light(pl);
    CHECK(ll->exposure == 1 && ll->sun[0] == 200 && ll->sun[1] == 35 &&
          ll->fog_density == 0 && rt_pack_light(pp)->exposure == 0,
          "pack light: exposure %g sun %g %g fog %g", ll->exposure, ll->sun[0],
          ll->sun[1], ll->fog_density);
    rt_pack_info pi = kit_pack_info(pp);
    rt_camera cam;
    rt_default_camera(pp, &cam);
    rt_render_desc base = { 0 };

    /* exposure: +1 EV doubles the linear image */
    rt_render_desc ev1 = base;
    ev1.exposure_set = true, ev1.exposure = 1.0;
    float *a = render(dev, pp, &base, &cam), *b = render(dev, pp, &ev1, &cam);
    if (a && b) {
        int n = 0, off = 0;
        for (size_t i = 0; i < (size_t)W * H; i++) {
            if (background(a + 4 * i)) continue;
            n++;
            for (int k = 0; k < 3; k++)
                off += fabsf(b[4 * i + k] - 2.0f * a[4 * i + k]) > 1e-6f * (1 + b[4 * i + k]);
        }
        printf("exposure +1 EV: %d terrain pixels, %d values not doubled\n", n, off);
        CHECK(n > W * H / 4 && off == 0, "%d of %d pixels not doubled", off, n);
    }
    /* the scene's block = the same light set from outside */
    rt_render_desc same = base;
    same.exposure_set = true, same.exposure = 1.0;
    same.sun_set = true, same.sun[0] = 200, same.sun[1] = 35;
    same.fog_set = true, same.fog_density = 0;
    float *c = render(dev, pl, &base, &cam), *d = render(dev, pp, &same, &cam);
    /* and through the generic keys (splatview --light KEY=V,...) */
    rt_render_desc keyed = base;
    keyed.light_keys = 1u << SPLAT_LIGHT_EXPOSURE | 1u << SPLAT_LIGHT_SUN |
                       1u << SPLAT_LIGHT_FOG_DENSITY;
    keyed.light[SPLAT_LIGHT_EXPOSURE][0] = 1.0;
    keyed.light[SPLAT_LIGHT_SUN][0] = 200, keyed.light[SPLAT_LIGHT_SUN][1] = 35;
    keyed.light[SPLAT_LIGHT_FOG_DENSITY][0] = 0;
    float *k = render(dev, pp, &keyed, &cam);
    if (c && d && k) {
        printf("light block vs the same overrides: max difference %.3g, through the keys "
               "%.3g\n", max_diff(c, d), max_diff(c, k));
        kit_image_equal(c, d, W, H, "the light block against the same overrides");
        kit_image_equal(c, k, W, H, "the light block against the same keys");
    }
    free(k);
    /* the sun: high vs low, and turned */
    rt_render_desc hi = base, lo = base, turned = base;
    hi.sun_set = lo.sun_set = turned.sun_set = true;
    hi.sun[0] = lo.sun[0] = 144, hi.sun[1] = 70, lo.sun[1] = 5;
    turned.sun[0] = 324, turned.sun[1] = 21;
    float *sh = render(dev, pp, &hi, &cam), *sl = render(dev, pp, &lo, &cam);
    float *st = render(dev, pp, &turned, &cam);
    if (sh && sl && st && a) {
        int n;
        double lh = mean_lum(sh, &n), ll = mean_lum(sl, &n);
        printf("sun 70 deg up: mean %.4f, 5 deg up: %.4f; turned 180: max difference %.3g\n",
               lh, ll, max_diff(st, a));
        CHECK(lh > 1.5 * ll, "high sun %g, low sun %g", lh, ll);
        CHECK(max_diff(st, a) > 0.05, "turning the sun changed little");
    }
    /* fog: none vs default at the far side of a grazing view */
    rt_render_desc nofog = base;
    nofog.fog_set = true, nofog.fog_density = 0;
    rt_camera graze = { .position = { -50, pi.height_offset + pi.max_height * 0.6, -50 },
                        .look = { pi.size[0], pi.height_offset, pi.size[1] } };
    float *f0 = render(dev, pp, &nofog, &graze), *f1 = render(dev, pp, &base, &graze);
    if (f0 && f1) {
        printf("fog: default vs none max difference %.3g\n", max_diff(f0, f1));
        CHECK(max_diff(f0, f1) > 1e-3, "the default fog does nothing");
    }
    check_bad_light(dir);
    float *all[] = { a, b, c, d, sh, sl, st, f0, f1 };
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        free(all[i]);
    kit_device_close(dev);
    rt_pack_close(pp);
    rt_pack_close(pl);
    return kit_finish("lighting");
}
