/* test_undergrowth.c — undergrowth from material masks (runtime/
 * undergrowth.c) on a Vulkan device with SPLAT_VALIDATE=1 (any validation
 * message fails).
 *
 *   test_undergrowth OUTDIR   (run from the repository root)
 *
 * A flat 128 m square: `ground` below, `meadow` above it with mask 0.5
 * everywhere and two undergrowth blocks (grass at 2 per m^2, stones at
 * 0.1), `burnt` on top where the destruction mask is.  Seen from above
 * the centre, every 16 m cell of the square is allocated (radius 96 m):
 *   - each cell's instance count of each block lies within 3 sigma of
 *     density x area x composited weight (the binomial of the jittered
 *     grid's candidates, each kept with probability keep x weight; the
 *     weight as the mask pass stores it, 128/255): of the 128 counts at
 *     most 2 beyond 3 sigma (0.35 expected), none beyond 4, and the mean
 *     per cell within 3 sigma of its own spread;
 *   - a second renderer (another run) gives byte-identical instances in
 *     every cell, and so does a camera 40 m away in the cells both share;
 *   - hot reload to the same scene with a quarter of the grass density
 *     regenerates every cell, with a quarter of the grass;
 *   - a crater (burnt's mask 1 inside) leaves fewer than 2 % of the
 *     instances that stood in its inner disc;
 *   - with rd.no_undergrowth the picture is byte for byte the picture of
 *     the same scene without undergrowth blocks;
 *   - the instances cover the same pixels (within 3 %) from a ground
 *     camera on the forward path and on the screen path with raster and
 *     with ray-cast depth;
 *   - with a 20 m radius, cells put into pool slots other cells used hold
 *     no instance where their combination grows nothing (half.sg's west
 *     half: their texels cleared, not left from the slot's last cell), and
 *     the bytes they held fresh where it grows. */
#include "kit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

enum { N = 129, W = 256, H = 192, CELLS = 8, MAXI = 4096 };
static const double WEIGHT = 128.0 / 255.0;

/* grass: the grass block's density (0: no undergrowth blocks at all);
 * mask: the meadow's mask lines */
static bool write_scene(const char *dir, const char *name, double grass, const char *mask)
{
    char *sg = kit_join(dir, name);
    FILE *f = fopen(sg, "w");
    free(sg);
    if (!f)
        return false;
    char blocks[256] = "";
    if (grass > 0)
        snprintf(blocks, sizeof blocks,
                 "    undergrowth grass { density = %g, scale = 0.8 1.2 }\n"
                 "    undergrowth stone { density = 0.1, align = normal }\n", grass);
    fprintf(f, "import \"nodes/compositors.sg\"\nimport \"nodes/masks.sg\"\n"
               "material ground {\n    out albedo = vec3(0.30, 0.25, 0.20)\n}\n"
               "material meadow {\n%s    out albedo = vec3(0.2, 0.4, 0.1)\n%s}\n"
               "material burnt {\n    node r : ramp { x = terrain.destruction, lo = 0.02, "
               "hi = 0.25 }\n    out mask = r.out\n    out albedo = vec3(0.03, 0.03, 0.03)\n}\n"
               "scene meadow {\n    heightfield = \"flat.png\"\n    size = 128 128\n"
               "    max_height = 10\n    materials = [ground, meadow, burnt]\n    cell = 16\n"
               "    destruction { origin = 0 0, size = 128 128, cell = 16 }\n}\n",
            mask, blocks);
    return fclose(f) == 0;
}

static bool write_inputs(const char *dir)
{
    static uint8_t hf[N * N];
    char *png = kit_join(dir, "flat.png");
    bool ok = stbi_write_png(png, N, N, 1, hf, N) != 0;
    free(png);
    static const char half[] = "    node h : ramp { x = terrain.position.x, lo = 63, hi = 65 }\n"
                               "    out mask = h.out\n";
    return ok && write_scene(dir, "meadow.sg", 2.0, "    out mask = 0.5\n") &&
           write_scene(dir, "bare.sg", 0, "    out mask = 0.5\n") &&
           write_scene(dir, "sparse.sg", 0.5, "    out mask = 0.5\n") &&
           write_scene(dir, "half.sg", 2.0, half);
}

static rt_renderer *renderer_on(rt_device *dev, const rt_pack *p, bool off, rt_shading sh,
                                rt_screen_depth depth)
{
    rt_render_desc rd = { .width = W, .height = H, .no_undergrowth = off, .shading = sh,
                          .screen_depth = depth };
    rt_error e = { 0 };
    rt_renderer *r = NULL;
    CHECK(rt_renderer_create(dev, p, &rd, &r, &e), "renderer: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return r;
}

static int cell_of(rt_renderer *r, int ix, int iz, rt_ug_instance *out)
{
    rt_error e = { 0 };
    int n = rt_renderer_undergrowth_cell(r, ix, iz, out, MAXI, &e);
    CHECK(n >= 0, "read cell %d %d: %s", ix, iz, e.msg ? e.msg : "?");
    rt_error_clear(&e);
    return n;
}

static rt_renderer *renderer(rt_device *dev, const rt_pack *p, bool off)
{
    return renderer_on(dev, p, off, RT_SHADING_FORWARD, RT_DEPTH_AUTO);
}

/* Instances of block b in cell (ix, iz), and those within `radius` of (x, z). */
static int count(const rt_ug_instance *v, int n, unsigned b, double x, double z, double radius)
{
    int c = 0;
    for (int i = 0; i < n; i++)
        c += v[i].block == b && hypot(v[i].pos[0] - x, v[i].pos[2] - z) <= radius;
    return c;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_undergrowth OUTDIR (run from the repository root)\n");
        return 2;
    }
    const char *dir = argv[1];
    char *sg = kit_join(dir, "meadow.sg"), *packdir = kit_join(dir, "meadow.pack");
    char *bsg = kit_join(dir, "bare.sg"), *bpackdir = kit_join(dir, "bare.pack");
    bool built = write_inputs(dir) && kit_build_pack_ok(sg, packdir) &&
                 kit_build_pack_ok(bsg, bpackdir);
    rt_pack *p = built ? kit_pack(packdir) : NULL, *bp = built ? kit_pack(bpackdir) : NULL;
    rt_device *dev = p && bp ? kit_device() : NULL;
    rt_error e = { 0 };
    if (!dev)
        return kit_finish("undergrowth");
    rt_pack_info pi = kit_pack_info(p), bpi = kit_pack_info(bp);
    CHECK(pi.ug_slots == 1 && pi.ug_blocks == 2, "pack undergrowth: %d slots, %d blocks",
          pi.ug_slots, pi.ug_blocks);
    CHECK(bpi.ug_slots == 0 && !bpi.has_undergrowth, "the bare pack has undergrowth");
    rt_camera cam = { .position = { 64, 60, 64 }, .look = { 64, 0, 64.01 } };
    rt_ug_instance *a = malloc(sizeof *a * MAXI), *b = malloc(sizeof *b * MAXI);
    rt_renderer *r1 = renderer(dev, p, false), *r2 = renderer(dev, p, false);
    if (!a || !b || !r1 || !r2)
        return 1;

    /* counts per cell against the binomial of each block */
    rt_frame_stats st;
    CHECK(rt_renderer_frame(r1, &cam, &st, &e), "frame: %s", e.msg ? e.msg : "?");
    printf("undergrowth: %d cells, %ld instances\n", st.undergrowth.cells,
           st.undergrowth.instances);
    CHECK(st.undergrowth.cells == CELLS * CELLS, "%d cells allocated, want %d",
          st.undergrowth.cells, CELLS * CELLS);
    static const double density[2] = { 2.0, 0.1 };
    double worst[2] = { 0, 0 }, sum[2] = { 0, 0 }, mean_of[2], sigma_of[2];
    int outliers = 0;
    for (int iz = 0; iz < CELLS; iz++)
        for (int ix = 0; ix < CELLS; ix++) {
            int n = cell_of(r1, ix, iz, a);
            for (unsigned k = 0; k < 2; k++) {
                double side = ceil(sqrt(density[k] * 256.0)), cand = side * side;
                double prob = density[k] * 256.0 / cand * WEIGHT;
                double mean = cand * prob, sigma = sqrt(cand * prob * (1 - prob));
                mean_of[k] = mean;
                sigma_of[k] = sigma;
                int c = count(a, n, k, 0, 0, 1e9);
                double z = fabs(c - mean) / sigma;
                worst[k] = z > worst[k] ? z : worst[k];
                sum[k] += c;
                outliers += z > 3.0;
                CHECK(z <= 4.0, "cell %d %d block %u: %d instances, expected %.1f +- %.1f", ix,
                      iz, k, c, mean, sigma);
            }
        }
    for (int k = 0; k < 2; k++) {
        double m = sum[k] / (CELLS * CELLS);
        printf("block %d: mean %.2f per cell, expected %.2f +- %.2f; worst cell %.2f sigma\n", k,
               m, mean_of[k], sigma_of[k], worst[k]);
        CHECK(fabs(m - mean_of[k]) <= 3 * sigma_of[k] / CELLS, "block %d: mean %.2f per cell, "
              "expected %.2f", k, m, mean_of[k]);
    }
    /* 128 cell counts: beyond 3 sigma expected 0.35 times, more than 2 with
     * probability 0.5 % */
    printf("cells beyond 3 sigma: %d of %d\n", outliers, 2 * CELLS * CELLS);
    CHECK(outliers <= 2, "%d cell counts beyond 3 sigma", outliers);

    /* the same instances from another run, and from another camera */
    rt_camera moved = cam;
    moved.position[0] += 40;
    moved.look[0] += 40;
    CHECK(rt_renderer_frame(r2, &cam, NULL, &e), "frame: %s", e.msg ? e.msg : "?");
    int same = 0, cells = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1)
            CHECK(rt_renderer_frame(r2, &moved, NULL, &e), "frame: %s", e.msg ? e.msg : "?");
        for (int iz = 0; iz < CELLS; iz++)
            for (int ix = 0; ix < CELLS; ix++) {
                int n = cell_of(r1, ix, iz, a), m = cell_of(r2, ix, iz, b);
                if (m == 0 && pass == 1)
                    continue;   /* not in the moved camera's disc */
                cells++;
                same += n == m && n > 0 && memcmp(a, b, sizeof *a * (size_t)n) == 0;
                CHECK(n == m && memcmp(a, b, sizeof *a * (size_t)n) == 0,
                      "cell %d %d differs (%s): %d vs %d instances", ix, iz,
                      pass ? "moved camera" : "second run", n, m);
            }
    }
    printf("identical cells: %d of %d (two runs, then a camera 40 m away)\n", same, cells);

    /* hot reload (rt_renderer_swap_pack): the grass at a quarter of the
     * density, every cell generated again */
    char *ssg = kit_join(dir, "sparse.sg"), *spackdir = kit_join(dir, "sparse.pack");
    rt_pack *sp = kit_build_pack_ok(ssg, spackdir) ? kit_pack(spackdir) : NULL;
    if (sp) {
        CHECK(rt_renderer_swap_pack(r2, sp, &e), "swap: %s", e.msg ? e.msg : "?");
        rt_error_clear(&e);
        CHECK(rt_renderer_frame(r2, &cam, &st, &e), "frame: %s", e.msg ? e.msg : "?");
        long grass = 0;
        for (int iz = 0; iz < CELLS; iz++)
            for (int ix = 0; ix < CELLS; ix++)
                grass += count(b, cell_of(r2, ix, iz, b), 0, 0, 0, 1e9);
        double want = sum[0] / 4.0;   /* density 0.5 instead of 2 */
        printf("hot reload: %d cells generated again, grass %ld (a quarter of before: %.0f)\n",
               st.undergrowth.generated, grass, want);
        CHECK(st.undergrowth.generated == CELLS * CELLS, "reload regenerated %d cells",
              st.undergrowth.generated);
        CHECK(fabs(grass - want) < 0.1 * want, "grass after the reload: %ld, want about %.0f",
              grass, want);
    }
    rt_renderer_destroy(r2);
    rt_pack_close(sp);
    free(ssg);
    free(spackdir);

    /* a crater: burnt covers its inner disc, the meadow's instances go */
    const double cx = 40, cz = 40, radius = 12, inner = 0.4 * radius;
    int before = 0, after = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            rt_crater c = { .x = cx, .z = cz, .radius = radius, .depth = 0 };
            rt_crater_stats cs;
            CHECK(rt_renderer_crater(r1, &c, &cs, &e) && cs.result == RT_CRATER_DONE,
                  "crater: %s", e.msg ? e.msg : "refused");
            CHECK(rt_renderer_frame(r1, &cam, &st, &e), "frame: %s", e.msg ? e.msg : "?");
            CHECK(st.undergrowth.generated > 0 && st.undergrowth.generated < CELLS * CELLS,
                  "the crater regenerated %d cells", st.undergrowth.generated);
        }
        for (int iz = 1; iz <= 3; iz++)
            for (int ix = 1; ix <= 3; ix++) {
                int n = cell_of(r1, ix, iz, a);
                for (unsigned k = 0; k < 2; k++)
                    *(pass ? &after : &before) += count(a, n, k, cx, cz, inner);
            }
    }
    printf("crater: %d instances within %.1f m before, %d after\n", before, inner, after);
    CHECK(before > 50 && after * 50 <= before, "crater: %d instances before, %d after", before,
          after);
    float *img = kit_frame(r1, &cam, W, H);
    if (img)
        kit_write_picture(dir, "meadow.png", img, W, H, SPLAT_VIEW_FINAL);
    free(img);
    rt_renderer_destroy(r1);

    /* undergrowth off: today's picture, to the byte */
    rt_renderer *off = renderer(dev, p, true), *bare = renderer(dev, bp, false);
    rt_camera low = { .position = { 20, 3, 20 }, .look = { 60, 0, 50 } };
    float *x = off ? kit_frame(off, &low, W, H) : NULL, *y = bare ? kit_frame(bare, &low, W, H) : NULL;
    CHECK(x && y && memcmp(x, y, (size_t)W * H * 16) == 0,
          "no_undergrowth differs from the scene without undergrowth");
    if (x)
        kit_write_picture(dir, "off.png", x, W, H, SPLAT_VIEW_FINAL);
    free(x);
    free(y);
    rt_renderer_destroy(off);
    rt_renderer_destroy(bare);

    /* the draw's depth test on every path: the pixels the undergrowth
     * covers (on differs from off) agree within 3 % between the forward
     * path (depth attachment), the screen path's geometry pass (read-only
     * attachment) and its ray-cast depth (copied into the attachment) */
    static const struct { rt_shading sh; rt_screen_depth d; const char *name; } path[3] = {
        { RT_SHADING_FORWARD, RT_DEPTH_AUTO, "forward" },
        { RT_SHADING_SCREEN, RT_DEPTH_RASTER, "screen, raster depth" },
        { RT_SHADING_SCREEN, RT_DEPTH_RAYCAST, "screen, ray-cast depth" },
    };
    long covered[3] = { 0 };
    for (int k = 0; k < 3; k++) {
        rt_renderer *ron = renderer_on(dev, p, false, path[k].sh, path[k].d);
        rt_renderer *roff = renderer_on(dev, p, true, path[k].sh, path[k].d);
        float *z = ron ? kit_frame(ron, &low, W, H) : NULL;
        float *o = roff ? kit_frame(roff, &low, W, H) : NULL;
        for (long i = 0; z && o && i < (long)W * H; i++)
            covered[k] += memcmp(z + 4 * i, o + 4 * i, 12) != 0;
        if (z && k == 0)
            kit_write_picture(dir, "ground.png", z, W, H, SPLAT_VIEW_FINAL);
        if (z && k == 2)
            kit_write_picture(dir, "ground_raycast.png", z, W, H, SPLAT_VIEW_FINAL);
        free(z);
        free(o);
        rt_renderer_destroy(ron);
        rt_renderer_destroy(roff);
    }
    printf("undergrowth covers %ld, %ld and %ld of %d pixels (forward, screen raster, "
           "screen ray-cast)\n", covered[0], covered[1], covered[2], W * H);
    for (int k = 0; k < 3; k++)
        CHECK(covered[k] > W * H / 50 && labs(covered[k] - covered[0]) * 100 <= 3 * covered[0],
              "%s: undergrowth covers %ld pixels, forward %ld", path[k].name, covered[k],
              covered[0]);

    /* recycled pool slots: at a 20 m radius the pool (25 slots) cannot
     * hold the square, so a walk from the east half (meadow, its ramp
     * 0 below x = 63 m and 1 above 65 m) to the west half and back puts
     * cells into slots other cells used.  A west cell's leaves' combination
     * grows nothing, so no mask dispatch writes its texels: they must be
     * cleared, not left from the slot's last cell (no instance there); an
     * east cell generated again holds the bytes it held fresh. */
    char *hsg = kit_join(dir, "half.sg"), *hpackdir = kit_join(dir, "half.pack");
    rt_pack *hp = kit_build_pack_ok(hsg, hpackdir) ? kit_pack(hpackdir) : NULL;
    rt_render_desc hd = { .width = W, .height = H, .undergrowth_radius = 20 };
    rt_renderer *rw = NULL;
    CHECK(hp && rt_renderer_create(dev, hp, &hd, &rw, &e), "the half meadow's renderer: %s",
          e.msg ? e.msg : "no pack");
    rt_error_clear(&e);
    enum { EAST = 6 };
    rt_ug_instance *fresh = malloc(sizeof *fresh * MAXI * EAST);
    int nfresh[EAST] = { 0 }, east_cells = 0, west_cells = 0, west_inst = 0, same_east = 0;
    for (int step = 0; rw && fresh && step <= 26; step++) {
        /* x: 104 m, west by 8 m a frame to 24 m (frames 0-10), three
         * frames there, back east to 104 m (frames 14-23), three there */
        double x = step <= 10 ? 104 - 8 * step : step <= 13 ? 24 : step <= 23 ? 24 + 8 * (step - 13) : 104;
        rt_camera walk = { .position = { x, 5, 64 }, .look = { x - 1, 4, 64 } };
        CHECK(rt_renderer_frame(rw, &walk, NULL, &e), "walk frame: %s", e.msg ? e.msg : "?");
        rt_error_clear(&e);
        for (int k = 0; k < EAST && (step == 0 || step == 26); k++) {
            int ix = 5 + k % 3, iz = 3 + k / 3;   /* the cells within 20 m of (104, 64) */
            int n = cell_of(rw, ix, iz, a);
            if (step == 0) {
                nfresh[k] = n;
                memcpy(fresh + (size_t)k * MAXI, a, sizeof *a * (size_t)(n > 0 ? n : 0));
                east_cells += n > 0;
            } else {
                same_east += n == nfresh[k] && n > 0 &&
                             memcmp(a, fresh + (size_t)k * MAXI, sizeof *a * (size_t)n) == 0;
            }
        }
        for (int k = 0; k < 6 && step == 13; k++) {   /* (0..2, 3..4): within 20 m of (24, 64) */
            int n = cell_of(rw, k % 3, 3 + k / 3, a);
            west_cells++;
            west_inst += n > 0 ? n : 0;
        }
    }
    printf("recycled slots: %d east cells grown fresh, %d the same after the walk; "
           "%d instances in %d west cells\n", east_cells, same_east, west_inst, west_cells);
    CHECK(east_cells == EAST && same_east == EAST, "east cells: %d grown, %d the same after the walk",
          east_cells, same_east);
    CHECK(west_cells == 6 && west_inst == 0, "%d instances in the west cells, which grow nothing",
          west_inst);
    free(fresh);
    rt_renderer_destroy(rw);
    rt_pack_close(hp);
    free(hsg);
    free(hpackdir);

    free(a);
    free(b);
    free(sg);
    free(packdir);
    free(bsg);
    free(bpackdir);
    rt_pack_close(p);
    rt_pack_close(bp);
    kit_device_close(dev);
    return kit_finish("undergrowth");
}
