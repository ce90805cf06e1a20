/* test_ug_compute.c — undergrowth drawn in compute
 * (runtime/undergrowth_craster.c, rt_render_desc.undergrowth_compute)
 * against the graphics path, on a Vulkan device with SPLAT_VALIDATE=1.
 *
 *   test_ug_compute OUTDIR   (run from the repository root)
 *
 * A flat 256 m meadow of dense grass (its far mesh tapered quads, so
 * single triangles past 28 m), stones and frond-cut plants, radius 160 m,
 * seen from a low camera on the screen path, once with the compute
 * rasteriser off and once on:
 *   - the counts add up: the same instances drawn both ways and the same
 *     triangles, contact shadows included (the compute keys cast theirs in
 *     compute); per block and mesh (a key's block and index count) the
 *     graphics path's instances are the compute path's graphics and compute
 *     keys' together; grass, stones and plants in compute, at least a third
 *     of all; fewer indirect draws; no compute triangle or shadow clipped
 *     to the cap;
 *   - the picture: the compute path's differs from the graphics path's in
 *     at most 2 % of the pixels the far blades cover, and by PSNR at
 *     least 45 dB over the frame (measured: 66 of 12,860 pixels, 56.1 dB:
 *     edge pixels of sub-pixel-wide blades, where the graphics rasteriser
 *     snaps vertices to its sub-pixel grid and the compute one does not);
 *   - the far blades are there: the compute frame differs from one with
 *     the far blades not drawn at all (radius 28 m) in as many pixels as
 *     the graphics frame does, within 2 %;
 *   - at radius 40 m the few cells that would go to compute hold fewer
 *     candidates than the compute passes pay for (UG_CR_MIN): none go,
 *     the picture is the graphics path's bit for bit;
 *   - deterministic: a second renderer with the compute path, which drew
 *     another view before, gives the same picture bit for bit.
 * $SPLAT_UG_ATOMICS=32 runs the two-pass path where the device has 64-bit
 * atomics (the suite runs both). */
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { N = 129, W = 320, H = 200 };

static bool write_inputs(const char *dir)
{
    static uint8_t hf[N * N];
    char *png = kit_join(dir, "flat.png"), *sg = kit_join(dir, "meadow.sg");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0;
    FILE *f = ok ? fopen(sg, "w") : NULL;
    free(png);
    free(sg);
    if (!f)
        return false;
    fprintf(f, "import \"nodes/compositors.sg\"\nimport \"nodes/masks.sg\"\n"
               "material ground {\n    out albedo = vec3(0.30, 0.25, 0.20)\n}\n"
               "material meadow {\n    out mask = 0.8\n    out albedo = vec3(0.2, 0.4, 0.1)\n"
               "    undergrowth grass { density = 4, scale = 0.8 1.2 }\n"
               "    undergrowth stone { density = 0.1, align = normal }\n"
               "    undergrowth plant { density = 0.05 }\n}\n"
               "scene meadow {\n    heightfield = \"flat.png\"\n    size = 256 256\n"
               "    max_height = 10\n    materials = [ground, meadow]\n    cell = 16\n}\n");
    return fclose(f) == 0;
}

static rt_renderer *renderer(rt_device *dev, const rt_pack *p, bool compute, double radius)
{
    rt_render_desc rd = { .width = W, .height = H, .shading = RT_SHADING_SCREEN,
                          .undergrowth_radius = radius, .undergrowth_thin = 1000,
                          .undergrowth_compute = compute };
    rt_error e = { 0 };
    rt_renderer *r = NULL;
    CHECK(rt_renderer_create(dev, p, &rd, &r, &e), "renderer: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return r;
}

static float *frame(rt_renderer *r, const rt_camera *cam, rt_frame_stats *st)
{
    rt_error e = { 0 };
    /* two frames: the first generates the cells, the second draws them */
    CHECK(rt_renderer_frame(r, cam, st, &e), "frame: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    float *img = kit_frame(r, cam, W, H);
    CHECK(rt_renderer_frame(r, cam, st, &e), "frame: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return img;
}

/* Pixels whose colour differs (rgb, beyond float noise). */
static long differ(const float *a, const float *b)
{
    long n = 0;
    for (long i = 0; a && b && i < (long)W * H; i++)
        n += fabsf(a[4 * i] - b[4 * i]) + fabsf(a[4 * i + 1] - b[4 * i + 1]) +
                 fabsf(a[4 * i + 2] - b[4 * i + 2]) > 1e-4f;
    return n;
}

static double psnr(const float *a, const float *b)
{
    double se = 0, peak = 0;
    for (long i = 0; i < (long)W * H; i++)
        for (int c = 0; c < 3; c++) {
            double d = a[4 * i + c] - b[4 * i + c];
            se += d * d;
            peak = fmax(peak, fmax(a[4 * i + c], b[4 * i + c]));
        }
    se /= 3.0 * W * H;
    return se > 0 ? 10 * log10(peak * peak / se) : 999;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_ug_compute OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    char *sg = kit_join(dir, "meadow.sg"), *packdir = kit_join(dir, "meadow.pack");
    bool built = write_inputs(dir) && kit_build_pack_ok(sg, packdir);
    rt_pack *p = built ? kit_pack(packdir) : NULL;
    rt_device *dev = p ? kit_device() : NULL;
    if (!dev)
        return kit_finish("ug_compute");
    rt_renderer *gfx = renderer(dev, p, false, 160), *cs = renderer(dev, p, true, 160);
    rt_renderer *cs2 = renderer(dev, p, true, 160), *near = renderer(dev, p, false, 28);
    if (!gfx || !cs || !cs2 || !near)
        return kit_finish("ug_compute");

    rt_camera cam = { .position = { 100, 1.7, 20 }, .look = { 130, 0, 200 } };
    rt_frame_stats sg_, sc, sc2, sn;
    /* the second compute renderer looks elsewhere first: the per-pixel
     * buffers that the resolve leaves clear must hold nothing of that
     * frame (its picture is compared with the first's bit for bit) */
    rt_camera away = { .position = { 100, 1.7, 20 }, .look = { 10, 0, 150 } };
    free(frame(cs2, &away, &sc2));
    CHECK(sc2.undergrowth.drawn_compute > 1000, "looking away: %ld drawn in compute",
          sc2.undergrowth.drawn_compute);
    float *a = frame(gfx, &cam, &sg_), *b = frame(cs, &cam, &sc), *c = frame(cs2, &cam, &sc2);
    float *z = frame(near, &cam, &sn);
    /* the compute keys only where they hold enough (UG_CR_MIN): at 40 m a
     * few far cells, drawn by the graphics pipeline, the same picture */
    rt_renderer *g40 = renderer(dev, p, false, 40), *c40 = renderer(dev, p, true, 40);
    rt_frame_stats s40g, s40c;
    float *y0 = g40 ? frame(g40, &cam, &s40g) : NULL, *y1 = c40 ? frame(c40, &cam, &s40c) : NULL;
    if (y0 && y1) {
        printf("radius 40: %ld drawn, %ld in compute\n", s40c.undergrowth.drawn,
               s40c.undergrowth.drawn_compute);
        CHECK(s40c.undergrowth.drawn == s40g.undergrowth.drawn && s40c.undergrowth.drawn > 100 &&
                  s40c.undergrowth.drawn_compute == 0,
              "radius 40: %ld drawn (graphics %ld), %ld in compute", s40c.undergrowth.drawn,
              s40g.undergrowth.drawn, s40c.undergrowth.drawn_compute);
        kit_image_equal(y0, y1, W, H, "radius 40, compute keys too few");
    }
    free(y0);
    free(y1);
    rt_renderer_destroy(g40);
    rt_renderer_destroy(c40);
    const rt_ug_stats *ug = &sg_.undergrowth, *uc = &sc.undergrowth;
    printf("graphics: drawn %ld, triangles %ld, %d draws; compute: drawn %ld (%ld in compute), "
           "triangles %ld, %d draws, %ld clipped\n", ug->drawn, ug->triangles, ug->draws,
           uc->drawn, uc->drawn_compute, uc->triangles, uc->draws, uc->cr_overflow);
    /* the same instances and the same triangles, contact shadows included */
    CHECK(ug->drawn > 1000 && uc->drawn == ug->drawn && uc->triangles == ug->triangles,
          "drawn %ld / %ld, triangles %ld / %ld", ug->drawn, uc->drawn, ug->triangles,
          uc->triangles);
    CHECK(ug->drawn_compute == 0 && uc->drawn_compute * 3 > uc->drawn,
          "drawn in compute: %ld of %ld (graphics path: %ld)", uc->drawn_compute, uc->drawn,
          ug->drawn_compute);
    CHECK(uc->draws < ug->draws, "%d indirect draws with compute, %d without", uc->draws,
          ug->draws);
    CHECK(uc->cr_overflow == 0, "%ld compute triangles clipped to the cap", uc->cr_overflow);
    /* per block and mesh (a key's block and index count): the graphics
     * path's instances are the compute path's graphics and compute keys'
     * together; in compute: the grass's single triangles, the stones' far
     * mesh and the plants (fronds cut out in the raster pass) */
    CHECK(ug->keys < RT_UG_KEYS_MAX && uc->keys < RT_UG_KEYS_MAX, "%d, %d keys", ug->keys,
          uc->keys);
    bool cs_block[3] = { false, false, false };
    long sum_cs = 0;
    for (int k = 0; k < uc->keys; k++) {
        long tg = 0, tc = 0;
        for (int j = 0; j < ug->keys; j++)
            tg += ug->key_block[j] == uc->key_block[k] && ug->key_indices[j] == uc->key_indices[k]
                      ? ug->key_drawn[j] : 0;
        for (int j = 0; j < uc->keys; j++)
            tc += uc->key_block[j] == uc->key_block[k] && uc->key_indices[j] == uc->key_indices[k]
                      ? uc->key_drawn[j] : 0;
        CHECK(tg == tc && !ug->key_compute[k], "block %d, %u indices: %ld (graphics), %ld "
              "(graphics + compute)", uc->key_block[k], uc->key_indices[k], tg, tc);
        if (uc->key_compute[k] && uc->key_drawn[k] > 0 && uc->key_block[k] < 3)
            cs_block[uc->key_block[k]] = true;
        sum_cs += uc->key_compute[k] ? uc->key_drawn[k] : 0;
    }
    CHECK(cs_block[0] && cs_block[1] && cs_block[2] && sum_cs == uc->drawn_compute,
          "in compute: grass %d, stones %d, plants %d; %ld of %ld", cs_block[0], cs_block[1],
          cs_block[2], sum_cs, uc->drawn_compute);

    long covered = differ(a, z), moved = differ(a, b), covered_cs = differ(b, z);
    double db = a && b ? psnr(a, b) : 0;
    printf("the far blades cover %ld pixels (graphics), %ld (compute); the two differ in %ld "
           "(%.2f %%), PSNR %.1f dB\n", covered, covered_cs, moved,
           covered ? 100.0 * moved / covered : 0.0, db);
    CHECK(covered > W * H / 50, "the far blades cover %ld pixels", covered);
    CHECK(moved * 100 <= 2 * covered && db >= 45.0,
          "compute against graphics: %ld of %ld covered pixels differ, PSNR %.1f dB", moved,
          covered, db);
    CHECK(labs(covered_cs - covered) * 50 <= covered, "far blades cover %ld (compute), %ld "
          "(graphics)", covered_cs, covered);
    kit_image_equal(b, c, W, H, "the compute path, a second renderer");
    if (a && b) {
        kit_write_picture(dir, "graphics.png", a, W, H, SPLAT_VIEW_FINAL);
        kit_write_picture(dir, "compute.png", b, W, H, SPLAT_VIEW_FINAL);
    }
    free(a);
    free(b);
    free(c);
    free(z);
    rt_renderer_destroy(gfx);
    rt_renderer_destroy(cs);
    rt_renderer_destroy(cs2);
    rt_renderer_destroy(near);
    free(sg);
    free(packdir);
    rt_pack_close(p);
    kit_device_close(dev);
    return kit_finish("ug_compute");
}
