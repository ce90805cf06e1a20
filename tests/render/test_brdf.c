/* test_brdf.c — the preview lighting model (the prelude's splat_light,
 * compiler/abi.c) against its double-precision twin below, on a Vulkan
 * device with SPLAT_VALIDATE=1 (any validation message fails).
 *
 *   test_brdf OUTDIR   (run from the repository root)
 *
 * A flat 256 m terrain under one material of albedo (0.5, 0.4, 0.3) and
 * roughness R, for R = 0.2, 0.5 and 0.9, lit by a known sun (30 degrees
 * up, straight ahead of the camera, so its highlight is in view), sky and
 * exposure, no fog.  From a known camera 20 m up, the linear image (what
 * --float-out writes) is read back and 64 terrain pixels are compared
 * with the model evaluated in double at the point where the pixel's
 * centre ray meets the plane: within 1e-3 (relative above 1, where the
 * highlight is brighter than white).  Forward, screen-space and
 * multi-pass reference paths alike.  Also checks that the model is what
 * the issue asks of it: roughness moves the highlight's peak, and the
 * highlight follows the camera. */
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { W = 320, H = 200, N = 64 };
static const double SIZE = 256.0, ABOVE = 20.0, FOVY = M_PI / 3.0;
static const double ALBEDO[3] = { 0.5, 0.4, 0.3 }, SUN_EL = 30.0, INTENSITY = 3.0;
static const double SKY[3] = { 0.2, 0.3, 0.5 }, EXPOSURE = 0.5;
static const double ROUGH[3] = { 0.2, 0.5, 0.9 };

static bool write_scene(const char *dir, int k)
{
    char name[32];
    snprintf(name, sizeof name, "r%d.sg", k);
    char *sg = kit_join(dir, name);
    FILE *f = fopen(sg, "w");
    free(sg);
    if (!f) return false;
    fprintf(f, "import \"nodes/compositors.sg\"\nmaterial plate {\n    out albedo = vec3(%g, %g, %g)\n"
               "    out roughness = %g\n}\n"
               "scene brdf {\n    heightfield = \"flat.png\"\n    size = %g %g\n"
               "    max_height = 100\n    materials = [plate]\n    cell = 32\n"
               "    light { sun = 0 %g, sun_color = 1 1 1, intensity = %g, "
               "sky = %g %g %g, fog_density = 0, exposure = %g }\n}\n",
            ALBEDO[0], ALBEDO[1], ALBEDO[2], ROUGH[k], SIZE, SIZE, SUN_EL, INTENSITY,
            SKY[0], SKY[1], SKY[2], EXPOSURE);
    return fclose(f) == 0;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize3(double a[3])
{
    double l = sqrt(dot3(a, a));
    for (int i = 0; i < 3; i++)
        a[i] /= l;
}

/* The lighting model in double (abi.c's comment is its specification):
 * radiance leaving a surface of normal up at distance `dist` towards v
 * (surface -> camera), no fog. */
static void model(double rough, double dist, double pixel_angle, double texel,
                  const double v[3], double out[3])
{
    double el = SUN_EL * M_PI / 180.0, l[3] = { 0, sin(el), -cos(el) }, n[3] = { 0, 1, 0 };
    double a = fmin(fmax(rough, 0.02), 1.0), r = dist * pixel_angle / texel;
    double a2 = fmin(pow(a, 4) + fmin(0.01 * r * r, 0.18), 1.0);
    double h[3] = { l[0] + v[0], l[1] + v[1], l[2] + v[2] };
    normalize3(h);
    double ndl = fmax(dot3(n, l), 0), ndv = fmax(dot3(n, v), 1e-4);
    double ndh = fmax(dot3(n, h), 0), vdh = fmax(dot3(v, h), 0);
    double q = ndh * ndh * (a2 - 1) + 1, d = a2 / (M_PI * q * q);
    double vis = 0.5 / (ndl * sqrt(ndv * ndv * (1 - a2) + a2) +
                        ndv * sqrt(ndl * ndl * (1 - a2) + a2));
    double f = 0.04 + 0.96 * pow(1 - vdh, 5);
    /* the sky's ambient: 0.5 mix(horizon, zenith, 0.5 + 0.5 n.y), the
     * zenith 2.2 sky, the horizon half way to grey of 1.5 its luminance */
    double zen[3], lum = 0;
    for (int i = 0; i < 3; i++) {
        zen[i] = 2.2 * SKY[i];
        lum += zen[i] * (i == 0 ? 0.2126 : i == 1 ? 0.7152 : 0.0722);
    }
    for (int i = 0; i < 3; i++) {
        double sun = (ALBEDO[i] * (1 - f) + M_PI * d * vis * f) * ndl * INTENSITY;
        double hor = 0.5 * zen[i] + 0.5 * 1.5 * lum, t = 0.5 + 0.5 * n[1];
        double sky = 0.5 * (hor * (1 - t) + zen[i] * t);
        out[i] = (sun + ALBEDO[i] * sky) * exp2(EXPOSURE);
    }
}

/* The centre ray of pixel (px, py) from camera c (render.c's matrix),
 * unit length. */
static void pixel_ray(const rt_camera *c, int px, int py, double d[3])
{
    double f[3], up[3] = { 0, 1, 0 };
    for (int i = 0; i < 3; i++)
        f[i] = c->look[i] - c->position[i];
    normalize3(f);
    double s[3] = { f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2],
                    f[0] * up[1] - f[1] * up[0] };
    normalize3(s);
    double u[3] = { s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2],
                    s[0] * f[1] - s[1] * f[0] };
    double t = 1.0 / tan(FOVY / 2.0), aspect = (double)W / H;
    double nx = (px + 0.5) / W * 2.0 - 1.0, ny = (py + 0.5) / H * 2.0 - 1.0;
    for (int i = 0; i < 3; i++)
        d[i] = f[i] + nx * aspect / t * s[i] - ny / t * u[i];
    normalize3(d);
}

/* The image row where the point (x = the camera's, h0, z) shows. */
static int mirror_row(const rt_camera *c, double z, double h0)
{
    int best = 0;
    double bd = 1e9;
    for (int y = 0; y < H; y++) {
        double d[3];
        pixel_ray(c, W / 2, y, d);
        double t = (h0 - c->position[1]) / d[1];
        double err = d[1] < 0 ? fabs(c->position[2] + t * d[2] - z) : 1e9;
        if (err < bd) bd = err, best = y;
    }
    return best;
}

/* Compares 64 terrain pixels of `img` with the model; returns the largest
 * error (relative above 1) and the brightest pixel's value in *peak. */
static double compare(const float *img, const rt_camera *c, double h0, double rough,
                      double *peak)
{
    double worst = 0, pixel_angle = 2.0 * tan(FOVY / 2.0) / H, texel = SIZE / N;
    *peak = 0;
    int n = 0;
    for (int j = 0; j < 64; j++) {
        int px = 12 + 37 * (j % 8) + j % 3, py = H / 2 - 8 + 13 * (j / 8) + j % 5;
        double d[3];
        pixel_ray(c, px, py, d);
        if (d[1] >= -1e-3) continue;
        double dist = (h0 - c->position[1]) / d[1];
        double x = c->position[0] + dist * d[0], z = c->position[2] + dist * d[2];
        if (x < 1 || z < 1 || x > SIZE - 1 || z > SIZE - 1) continue;
        double v[3] = { -d[0], -d[1], -d[2] }, want[3];
        model(rough, dist, pixel_angle, texel, v, want);
        const float *got = img + 4 * ((size_t)py * W + px);
        for (int i = 0; i < 3; i++) {
            double err = fabs(got[i] - want[i]) / fmax(1.0, want[i]);
            worst = fmax(worst, err);
            *peak = fmax(*peak, got[i]);
        }
        n++;
    }
    CHECK(n >= 48, "only %d sampled pixels on the terrain", n);
    return worst;
}

static const struct { const char *name; rt_shading shading; rt_reference ref; } PATHS[] = {
    { "forward", RT_SHADING_FORWARD, RT_REF_NONE },
    { "screen", RT_SHADING_SCREEN, RT_REF_NONE },
    { "multipass", RT_SHADING_FORWARD, RT_REF_MULTIPASS },
};

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_brdf OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    uint8_t hf[N * N];
    memset(hf, 128, sizeof hf);
    char *png = kit_join(dir, "flat.png");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0;
    free(png);
    rt_pack *packs[3] = { 0 };
    for (int k = 0; ok && k < 3; k++) {
        char name[32];
        snprintf(name, sizeof name, "r%d.sg", k);
        char *sg = kit_join(dir, name);
        snprintf(name, sizeof name, "r%d.pack", k);
        char *pack = kit_join(dir, name);
        ok = write_scene(dir, k) && kit_build_pack_ok(sg, pack) && (packs[k] = kit_pack(pack));
        free(sg);
        free(pack);
    }
    CHECK(ok, "the scenes do not build into packs");
    rt_device *dev = ok ? kit_device() : NULL;
    if (!dev)
        return kit_finish("brdf");
    /* the plane: 128/255 of max_height above the offset (an 8-bit PNG) */
    rt_pack_info pi = kit_pack_info(packs[0]);
    double h0 = pi.height_offset + pi.max_height * 128.0 / 255.0;
    rt_camera cam = { .position = { SIZE / 2, h0 + ABOVE, SIZE - 20 },
                      .look = { SIZE / 2, h0, SIZE / 2 }, .fovy = FOVY };
    double peaks[3] = { 0 };
    for (int k = 0; k < 3; k++)
        for (size_t p = 0; p < sizeof PATHS / sizeof *PATHS; p++) {
            rt_render_desc rd = { .width = W, .height = H, .shading = PATHS[p].shading,
                                  .reference = PATHS[p].ref };
            float *img = kit_render(dev, packs[k], &rd, SPLAT_VIEW_FINAL, 0, &cam);
            if (!img) continue;
            double peak, err = compare(img, &cam, h0, ROUGH[k], &peak);
            printf("roughness %.1f, %-9s: largest error %.3g against the double model "
                   "(peak %.3f)\n", ROUGH[k], PATHS[p].name, err, peak);
            CHECK(err <= 1e-3, "roughness %.1f %s: error %g", ROUGH[k], PATHS[p].name, err);
            if (p == 0) {
                peaks[k] = peak;
                char name[32];
                snprintf(name, sizeof name, "r%d.png", k);
                kit_write_picture(dir, name, img, W, H, SPLAT_VIEW_FINAL);
            }
            free(img);
        }
    /* roughness matters: the smoother, the brighter its highlight */
    CHECK(peaks[0] > 2 * peaks[1] && peaks[1] > peaks[2], "peaks %g %g %g", peaks[0],
          peaks[1], peaks[2]);
    /* the highlight follows the camera: the brightest row of the glossy
     * plate is where the sun's mirror point projects, from 20 and 60 m up */
    rt_camera high = cam;
    high.position[1] = h0 + 60;
    rt_render_desc rd = { .width = W, .height = H };
    float *lo = kit_render(dev, packs[0], &rd, SPLAT_VIEW_FINAL, 0, &cam);
    float *hi = kit_render(dev, packs[0], &rd, SPLAT_VIEW_FINAL, 0, &high);
    for (int s = 0; lo && hi && s < 2; s++) {
        const float *img = s ? hi : lo;
        const rt_camera *c = s ? &high : &cam;
        int row = 0;
        for (int y = 0; y < H; y++)
            if (img[4 * ((size_t)y * W + W / 2) + 1] > img[4 * ((size_t)row * W + W / 2) + 1])
                row = y;
        double up = c->position[1] - h0, z = c->position[2] - up / tan(SUN_EL * M_PI / 180.0);
        int want = mirror_row(c, z, h0);
        printf("highlight from %.0f m up: brightest row %d, the mirror point's %d\n", up, row,
               want);
        CHECK(abs(row - want) <= 3, "%.0f m up: highlight at row %d, mirror point at %d", up,
              row, want);
    }
    free(lo);
    free(hi);
    kit_device_close(dev);
    for (int k = 0; k < 3; k++)
        rt_pack_close(packs[k]);
    return kit_finish("brdf");
}
