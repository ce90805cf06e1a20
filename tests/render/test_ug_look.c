/* test_ug_look.c — what the undergrowth's vertex stage does to the look
 * (runtime/undergrowth.c's top comment), on a Vulkan device with
 * SPLAT_VALIDATE=1 (any validation message fails).
 *
 *   test_ug_look OUTDIR   (run from the repository root)
 *
 * A flat 128 m square, `meadow` (mask 1) with grass at 4 per m^2, seen
 * from 2 m above its centre with an undergrowth radius of 48 m:
 *   - the distance fade: the instances the draw keeps, counted on the
 *     device per 2 m ring (the probe pass runs the vertex stage's own
 *     ug_fade_scale over the draw's arguments), over all the LOD leaves
 *     there: in every ring the kept share is the fade 1 - smoothstep(r0,
 *     r1, d) at the ring (within 4 binomial sigma + 0.02), so it is 1
 *     inside r0, falls through the band and is 0 from r1 on; the kept
 *     density per m^2 never rises over the band and never drops by more
 *     than a third of its value at r0 from one ring to the next (a hard
 *     cut at the radius drops all of it at once), and the last ring
 *     before the radius holds none;
 *   - the wind: the vertex stage's ug_wind on the device at 400 random
 *     roots, heights, directions, sways, gusts and times equals the
 *     formula below, computed in double, within 1e-4 m + 1 % of the
 *     sway;
 *   - with wind 0 and with a wind the frame differs only where the
 *     undergrowth is (the wind moves the blades, not the ground), and
 *     the still picture is the same at every time;
 *   - contact shadows: seen from 1.6 m, the grass with its default
 *     shadow (0.35) against `shadow = 0`: no pixel brighter, more than a
 *     tenth of the pixels darker, by more than 0.2 and less than 0.85 at
 *     most (overlapping discs compound: 1 - 0.65^4 = 0.82);
 *   - a textured OBJ card (uv, `texture` red at alpha 0.5): opaque, the
 *     pixels it covers are red; with `cutout = alpha` it covers half as
 *     many (0.35 to 0.65 of them: the dithered alpha). */
#include "rt_internal.h"   /* asserts on the loaded undergrowth blocks (rt_pack.ug) */
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { N = 129, W = 256, H = 192, RINGS = 24 };
static const double RING = 2.0, RADIUS = 48.0;

static bool write_scene(const char *dir, const char *name, const char *wind)
{
    char *sg = kit_join(dir, name);
    FILE *f = fopen(sg, "w");
    free(sg);
    if (!f)
        return false;
    fprintf(f, "import \"nodes/compositors.sg\"\n"
               "material ground {\n    out albedo = vec3(0.30, 0.25, 0.20)\n}\n"
               "material meadow {\n    out mask = 1.0\n    out albedo = vec3(0.2, 0.4, 0.1)\n"
               "    undergrowth grass { density = 4, scale = 0.8 1.2%s }\n}\n"
               "scene meadow {\n    heightfield = \"flat.png\"\n    size = 128 128\n"
               "    max_height = 10\n    materials = [ground, meadow]\n    cell = 16\n}\n",
            wind);
    return fclose(f) == 0;
}

/* The fade of runtime/undergrowth.c (ug_fade), in double. */
static double fade(double d, double r)
{
    double r1 = fmax(r - 12.0, 0.5 * r), r0 = 0.6 * r1;
    double t = (d - r0) / (r1 - r0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return 1.0 - t * t * (3.0 - 2.0 * t);
}

static double fract(double x) { return x - floor(x); }

/* The wind of runtime/undergrowth.c (ug_gust, ug_wind), in double. */
static double gust(double x, double z, double dx, double dz, double t)
{
    double along = x * dx + z * dz, across = -x * dz + z * dx;
    double p1 = 2 * M_PI * fract(along / 24.0 - t / 5.7);
    double p2 = 2 * M_PI * fract(along / 9.1 + across / 37.0 - t / 2.3);
    return 0.5 + 0.3 * sin(p1) + 0.2 * sin(p2);
}

static void wind(const double root[3], double h, const double w[4], double t, double out[3])
{
    h = h > 0 ? h : 0;
    double a = w[2] * h * h * (1.0 - w[3] + w[3] * gust(root[0], root[2], w[0], w[1], t));
    out[0] = w[0] * a;
    out[1] = -fmin(0.5 * a * a / fmax(h, 1e-3), 0.5 * h);
    out[2] = w[1] * a;
}

static double unit(void) { return rand() / (RAND_MAX + 1.0); }

static rt_renderer *make(rt_device *dev, const rt_pack *p, bool off);

/* An upright 1 m card with uv, a red texture at alpha 0.5, and a scene of
 * them (cutout: "none" or "alpha"). */
static bool write_card(const char *dir, const char *name, const char *cutout)
{
    char *obj = kit_join(dir, "card.obj"), *png = kit_join(dir, "red.png"), *sg = kit_join(dir, name);
    FILE *f = fopen(obj, "w");
    bool ok = f != NULL;
    if (f) {
        fprintf(f, "v -0.5 0 0\nv 0.5 0 0\nv 0.5 1 0\nv -0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                   "vt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
        ok = fclose(f) == 0;
    }
    uint8_t red[4 * 4 * 4];
    for (int i = 0; i < 16; i++) {
        red[4 * i] = 230, red[4 * i + 1] = 20, red[4 * i + 2] = 20, red[4 * i + 3] = 128;
    }
    ok = ok && stbi_write_png(png, 4, 4, 4, red, 16) != 0;
    f = ok ? fopen(sg, "w") : NULL;
    if (f) {
        fprintf(f, "import \"nodes/compositors.sg\"\n"
                   "material ground {\n    out albedo = vec3(0.30, 0.25, 0.20)\n}\n"
                   "material meadow {\n    out mask = 1.0\n    out albedo = vec3(0.2, 0.4, 0.1)\n"
                   "    undergrowth \"card.obj\" { density = 0.3, texture = \"red.png\", "
                   "cutout = %s, blend = 0, shadow = 0 }\n}\n"
                   "scene meadow {\n    heightfield = \"flat.png\"\n    size = 128 128\n"
                   "    max_height = 10\n    materials = [ground, meadow]\n    cell = 16\n}\n",
                cutout);
        ok = fclose(f) == 0;
    } else {
        ok = false;
    }
    free(obj);
    free(png);
    free(sg);
    return ok;
}

static void check_texture(rt_device *dev, const char *dir)
{
    rt_pack *p[2];
    long covered[2] = { 0 }, red = 0;
    for (int k = 0; k < 2; k++) {
        char *sg = kit_join(dir, k ? "card_cut.sg" : "card.sg");
        char *pk = kit_join(dir, k ? "card_cut.pack" : "card.pack");
        bool ok = write_card(dir, k ? "card_cut.sg" : "card.sg", k ? "alpha" : "none") &&
                  kit_build_pack_ok(sg, pk) && (p[k] = kit_pack(pk));
        free(sg);
        free(pk);
        if (!ok)
            return;
        CHECK(p[k]->ug.ntextures == 1 && p[k]->ug.textures[0].width == 4 &&
              p[k]->ug.blocks[0].texture == 0 && p[k]->ug.blocks[0].cutout == (k ? 2 : 0),
              "card pack %d: %d textures", k, p[k]->ug.ntextures);
        rt_renderer *on = make(dev, p[k], false), *off = make(dev, p[k], true);
        rt_camera cam = { .position = { 64, 1.0, 50 }, .look = { 64, 0.5, 60 } };
        float *a = on ? kit_frame(on, &cam, W, H) : NULL, *b = off ? kit_frame(off, &cam, W, H) : NULL;
        for (long i = 0; a && b && i < (long)W * H; i++) {
            bool c = memcmp(a + 4 * i, b + 4 * i, 12) != 0;
            covered[k] += c;
            if (c && k == 0)
                red += a[4 * i] > 1.5 * a[4 * i + 1] && a[4 * i] > 1.5 * a[4 * i + 2];
        }
        if (a)
            kit_write_picture(dir, k ? "card_cut.png" : "card.png", a, W, H, SPLAT_VIEW_FINAL);
        free(a);
        free(b);
        rt_renderer_destroy(on);
        rt_renderer_destroy(off);
        rt_pack_free(p[k]);
    }
    double share = covered[0] ? (double)covered[1] / covered[0] : 0;
    printf("texture: the card covers %ld pixels (%ld of them red), cut by its alpha %ld (%.2f)\n",
           covered[0], red, covered[1], share);
    CHECK(covered[0] > W * H / 20, "the cards cover only %ld pixels", covered[0]);
    CHECK(red > 0.8 * covered[0], "only %ld of %ld card pixels are red", red, covered[0]);
    CHECK(share > 0.35 && share < 0.65, "the alpha 0.5 cut-out covers %.2f of the pixels", share);
}

static rt_renderer *make(rt_device *dev, const rt_pack *p, bool off)
{
    rt_render_desc rd = { .width = W, .height = H, .undergrowth_radius = RADIUS,
                          .no_undergrowth = off };
    rt_error e = { 0 };
    rt_renderer *r = NULL;
    CHECK(rt_renderer_create(dev, p, &rd, &r, &e), "renderer: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return r;
}

static void check_fade(rt_renderer *r, const rt_camera *cam)
{
    rt_error e = { 0 };
    rt_frame_stats st;
    CHECK(rt_renderer_frame(r, cam, &st, &e), "frame: %s", e.msg ? e.msg : "?");
    uint32_t c[2 * RINGS];
    int cells = rt_renderer_undergrowth_rings(r, RING, RINGS, c, &e);
    CHECK(cells > 0, "rings: %d cells: %s", cells, e.msg ? e.msg : "none");
    rt_error_clear(&e);
    double r1 = fmax(RADIUS - 12.0, 0.5 * RADIUS), r0 = 0.6 * r1;
    double start = 0;   /* kept per m^2 in the ring at r0 */
    double prev = INFINITY;
    long kept = 0, all = 0;
    printf("ring (m)   kept     all   share  fade   kept/m^2\n");
    for (int k = 0; k < RINGS; k++) {
        double a = k * RING, b = a + RING, mid = 0.5 * (a + b);
        double area = M_PI * (b * b - a * a);
        double share = c[RINGS + k] ? (double)c[k] / c[RINGS + k] : 0;
        /* the fade averaged over the ring's area */
        double f = 0;
        for (int s = 0; s < 16; s++) {
            double d = a + (s + 0.5) * RING / 16;
            f += fade(d, RADIUS) * d;
        }
        f /= 16 * mid;
        double dens = c[k] / area;
        kept += c[k];
        all += c[RINGS + k];
        printf("%4.0f-%-4.0f %6u  %6u  %5.3f  %5.3f  %7.4f\n", a, b, c[k], c[RINGS + k], share,
               f, dens);
        CHECK(c[RINGS + k] > 20 || b > r1, "ring %g-%g m: only %u instances drawn", a, b,
              c[RINGS + k]);
        double sigma = c[RINGS + k] ? sqrt(f * (1 - f) / c[RINGS + k]) : 1;
        CHECK(fabs(share - f) <= 4 * sigma + 0.02, "ring %g-%g m: %.3f of the instances kept, "
              "the fade is %.3f (+- %.3f)", a, b, share, f, sigma);
        if (a >= r1)
            CHECK(c[k] == 0, "ring %g-%g m, beyond r1 = %g m: %u instances kept", a, b, r1, c[k]);
        if (a <= r0 && b > r0)
            start = dens;
        if (a >= r0 && b <= r1 + RING) {
            /* over the band: never rising, never a step (the LOD's own
             * thinning per cell adds a few % of noise) */
            CHECK(dens <= prev * 1.15 + 1e-9, "ring %g-%g m: %.4f per m^2 after %.4f", a, b,
                  dens, prev);
            CHECK(prev - dens <= start / 3 + 1e-9, "ring %g-%g m: the kept density drops from "
                  "%.4f to %.4f per m^2 at once (%.4f at r0)", a, b, prev, dens, start);
        }
        if (b > r0)
            prev = dens;
    }
    printf("fade band %.1f-%.1f m (radius %.0f m): %ld of %ld LOD instances kept, %d cells\n",
           r0, r1, RADIUS, kept, all, cells);
    CHECK(start > 0.01, "the kept density at r0 is %.4f per m^2", start);
}

static void check_wind(rt_renderer *r)
{
    enum { P = 400 };
    float *pt = calloc(P, 12 * sizeof *pt);
    double (*want)[4] = calloc(P, sizeof *want);
    if (!pt || !want)
        return;
    srand(31);
    double t = 123.456;
    for (int i = 0; i < P; i++) {
        double ang = unit() * 2 * M_PI;
        float v[8] = { (float)(unit() * 4000), (float)(unit() * 100), (float)(unit() * 4000),
                       (float)(unit() * 1.6 - 0.1), (float)cos(ang), (float)sin(ang),
                       (float)(unit() * 2.0), (float)unit() };
        memcpy(pt + 12 * i, v, sizeof v);
        double root[3] = { v[0], v[1], v[2] }, w[4] = { v[4], v[5], v[6], v[7] }, o[3];
        wind(root, v[3], w, t, o);
        memcpy(want[i], o, sizeof o);
        want[i][3] = gust(v[0], v[2], v[4], v[5], t);
    }
    rt_error e = { 0 };
    CHECK(rt_renderer_undergrowth_wind(r, pt, P, t, &e), "wind: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    double worst = 0, moved = 0;
    for (int i = 0; i < P; i++) {
        const float *v = pt + 12 * i;
        double h = v[3] > 0 ? v[3] : 0, tol = 1e-4 + 0.01 * v[6] * h * h;
        for (int k = 0; k < 3; k++) {
            double d = fabs(v[8 + k] - want[i][k]);
            worst = d > worst ? d : worst;
            moved = fmax(moved, fabs(want[i][k]));
            CHECK(d <= tol, "point %d component %d: the device moves it %g m, the formula %g m",
                  i, k, v[8 + k], want[i][k]);
        }
        CHECK(fabs(v[11] - want[i][3]) <= 0.005 && v[11] >= 0 && v[11] <= 1,
              "point %d: gust %g on the device, %g by the formula", i, v[11], want[i][3]);
    }
    printf("wind: %d points, the device within %.2g m of the formula (offsets up to %.2f m)\n",
           P, worst, moved);
    CHECK(moved > 0.5, "the wind never moved a point more than %.2f m", moved);
    free(pt);
    free(want);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_ug_look OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    static uint8_t hf[N * N];
    char *png = kit_join(dir, "flat.png");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0 && write_scene(dir, "still.sg", "") &&
              write_scene(dir, "unshadowed.sg", ", shadow = 0") &&
              write_scene(dir, "windy.sg", ", wind = 1.5, wind_dir = 1 0.5, gust = 0.7");
    free(png);
    char *sg = kit_join(dir, "still.sg"), *pk = kit_join(dir, "still.pack");
    char *wsg = kit_join(dir, "windy.sg"), *wpk = kit_join(dir, "windy.pack");
    char *usg = kit_join(dir, "unshadowed.sg"), *upk = kit_join(dir, "unshadowed.pack");
    rt_pack *p = NULL, *wp = NULL, *up = NULL;
    rt_device *dev = NULL;
    if (!ok || !kit_build_pack_ok(sg, pk) || !kit_build_pack_ok(wsg, wpk) || !kit_build_pack_ok(usg, upk) ||
        !(p = kit_pack(pk)) || !(wp = kit_pack(wpk)) || !(up = kit_pack(upk)) ||
        !(dev = kit_device())) {
        CHECK(false, "setup: the scenes do not build or load, or no device");
        return kit_finish("ug_look");
    }
    CHECK(wp->ug.nblocks == 1 && fabs(wp->ug.blocks[0].wind[2] - 1.5) < 1e-9 &&
          fabs(hypot(wp->ug.blocks[0].wind[0], wp->ug.blocks[0].wind[1]) - 1) < 1e-9 &&
          fabs(wp->ug.blocks[0].wind[3] - 0.7) < 1e-9, "the windy pack's block has no wind");
    rt_renderer *r = make(dev, p, false), *wr = make(dev, wp, false);
    rt_renderer *off = make(dev, wp, true);
    if (!r || !wr || !off)
        return 1;
    rt_camera cam = { .position = { 64, 2, 64 }, .look = { 64, 1, 90 } };
    check_fade(r, &cam);
    check_wind(wr);

    /* the wind moves blades, not the ground; a still block stays still */
    rt_camera low = { .position = { 64, 1.2, 40 }, .look = { 64, 0.3, 52 } };
    float *still = kit_frame(r, &low, W, H), *bare = kit_frame(off, &low, W, H);
    low.time = 0;
    float *w0 = kit_frame(wr, &low, W, H);
    low.time = 2.5;
    float *w1 = kit_frame(wr, &low, W, H);
    float *still1 = kit_frame(r, &low, W, H);
    if (still && bare && w0 && w1 && still1) {
        long grass = 0, moved = 0, ground = 0;
        for (long i = 0; i < (long)W * H; i++) {
            bool g0 = memcmp(w0 + 4 * i, bare + 4 * i, 12) != 0;
            bool g1 = memcmp(w1 + 4 * i, bare + 4 * i, 12) != 0;
            grass += g0;
            moved += memcmp(w0 + 4 * i, w1 + 4 * i, 12) != 0;
            ground += !g0 && !g1 && memcmp(w0 + 4 * i, w1 + 4 * i, 12) != 0;
        }
        printf("wind: %ld pixels of grass, %ld change between t = 0 and 2.5 s, %ld of the "
               "ground\n", grass, moved, ground);
        CHECK(grass > W * H / 20 && moved > grass / 20, "the wind moves %ld of %ld grass pixels",
              moved, grass);
        CHECK(ground == 0, "the wind changed %ld pixels of bare ground", ground);
        CHECK(memcmp(still, still1, (size_t)W * H * 16) == 0, "a block without wind moves");
        kit_write_picture(dir, "still.png", still, W, H, SPLAT_VIEW_FINAL);
        kit_write_picture(dir, "windy0.png", w0, W, H, SPLAT_VIEW_FINAL);
        kit_write_picture(dir, "windy1.png", w1, W, H, SPLAT_VIEW_FINAL);
    } else {
        CHECK(false, "frames failed");
    }

    /* contact shadows: darker ground, nothing brighter */
    rt_renderer *ur = make(dev, up, false);
    rt_camera look = { .position = { 64, 1.6, 60 }, .look = { 64, 0, 64 } };
    float *sh = r ? kit_frame(r, &look, W, H) : NULL, *un = ur ? kit_frame(ur, &look, W, H) : NULL;
    if (sh && un) {
        long darker = 0, brighter = 0;
        double most = 0;
        for (long i = 0; i < (long)W * H; i++) {
            double a = sh[4 * i] + sh[4 * i + 1] + sh[4 * i + 2];
            double b = un[4 * i] + un[4 * i + 1] + un[4 * i + 2];
            darker += a < b * 0.995;
            brighter += a > b * 1.0001 + 1e-6;
            most = b > 0 && 1 - a / b > most ? 1 - a / b : most;
        }
        printf("contact shadows: %ld of %d pixels darker (by up to %.0f %%), %ld brighter\n",
               darker, W * H, 100 * most, brighter);
        CHECK(brighter == 0, "contact shadows brighten %ld pixels", brighter);
        CHECK(darker > W * H / 10, "contact shadows darken only %ld pixels", darker);
        CHECK(most > 0.2 && most < 0.85, "contact shadows darken by up to %.2f (shadow 0.35, "
              "overlapping discs compound)", most);
        kit_write_picture(dir, "shadowed.png", sh, W, H, SPLAT_VIEW_FINAL);
        kit_write_picture(dir, "unshadowed.png", un, W, H, SPLAT_VIEW_FINAL);
    } else {
        CHECK(false, "shadow frames failed");
    }
    free(sh);
    free(un);
    rt_renderer_destroy(ur);
    rt_pack_close(up);
    check_texture(dev, dir);
    free(usg);
    free(upk);
    free(still);
    free(bare);
    free(w0);
    free(w1);
    free(still1);
    rt_renderer_destroy(r);
    rt_renderer_destroy(wr);
    rt_renderer_destroy(off);
    rt_pack_close(p);
    rt_pack_close(wp);
    free(sg);
    free(pk);
    free(wsg);
    free(wpk);
    kit_device_close(dev);
    return kit_finish("ug_look");
}
