/* test_sparse.c — painted masks as sparse quad-tree textures
 * (compiler/sparse.c, bc4.c): the BC4 palette, constant and duplicate
 * tiles, the CPU twin of the GPU sampler against the raster's bilinear
 * sample per option (R8 exact, BC4 and reduced levels with their measured
 * error), seams at tile borders, per-cell ranges, determinism, the pack
 * file, bad rasters, and the sparse painted-mask size targets (a Fig. 10-like field mask
 * and the destruction-mask memory of Andersson 2007 §5.2.5). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image_write.h>

#include "abi.h"
#include "sparse.h"
#include "spv.h"

/* ---- deterministic content ------------------------------------------------ */

static uint32_t rng_next(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    uint32_t x = *s;
    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15;
    return x;
}

static double rng_unit(uint32_t *s)
{
    return (rng_next(s) >> 8) * (1.0 / 16777216.0);
}

/* Scattered fields like Andersson 2007 Fig. 10: rotated soft-edged rectangles
 * (255 inside, a 4-texel ramp at the edge); every second field is axis
 * aligned with crop rows of period 16 (so its inner tiles repeat).
 * Fields keep clear of the raster's edge. */
static uint8_t *gen_fields(int w, int h, int nfields, double size, uint32_t seed)
{
    uint8_t *t = calloc((size_t)w * h, 1);
    uint32_t s = seed;
    for (int f = 0; f < nfields; f++) {
        double margin = 2.5 * size;
        double cx = margin + rng_unit(&s) * (w - 2 * margin);
        double cz = margin + rng_unit(&s) * (h - 2 * margin);
        double a = size * (0.4 + rng_unit(&s)), b = size * (0.4 + rng_unit(&s));
        bool rows = f % 2 == 1;
        double th = rows ? 0.0 : rng_unit(&s) * 3.14159;
        double c = cos(th), sn = sin(th), r = a > b ? a : b;
        if (rows) { cx = floor(cx); cz = floor(cz); }
        for (int z = (int)fmax(0, cz - r * 1.5); z < (int)fmin(h, cz + r * 1.5); z++)
            for (int x = (int)fmax(0, cx - r * 1.5); x < (int)fmin(w, cx + r * 1.5); x++) {
                double dx = x + 0.5 - cx, dz = z + 0.5 - cz;
                double lx = c * dx + sn * dz, lz = -sn * dx + c * dz;
                double e = fmin(a - fabs(lx), b - fabs(lz)) / 4.0;
                if (e <= 0) continue;
                double v = fmin(e, 1.0) * 255.0;
                if (rows)
                    v *= (x % 16) < 8 ? 1.0 : 0.75;
                uint8_t *p = &t[(size_t)z * w + x];
                if (v > *p) *p = (uint8_t)lrint(v);
            }
    }
    return t;
}

/* A test raster with every kind of tile: fields, a smooth slope, a noisy
 * patch (tiles that all differ) and empty space. */
static uint8_t *gen_mixed(int w, int h, uint32_t seed)
{
    uint8_t *t = gen_fields(w, h, 10, 40.0, seed);
    uint32_t s = seed ^ 0x9e3779b9u;
    for (int z = 0; z < h; z++)
        for (int x = 0; x < w; x++) {
            uint8_t *p = &t[(size_t)z * w + x];
            if (x > w / 2 && z < h / 3)
                *p = (uint8_t)(rng_next(&s) & 255);               /* noise */
            else if (x < w / 3 && z > h / 2)
                *p = (uint8_t)lrint(127.5 + 127.5 * sin(x * 0.05) * cos(z * 0.037));
        }
    return t;
}

static sparse_masks build1(const uint8_t *t, int w, int h, sparse_format fmt,
                           int max_level, double max_error)
{
    sparse_mask_desc md = { .name = "m", .texels = t, .max_level = max_level,
                            .max_error = max_error };
    sparse_desc d = { .width = w, .height = h, .masks = &md, .nmasks = 1, .format = fmt };
    sparse_masks s;
    sparse_error err;
    bool ok = sparse_build(&s, &d, &err);
    if (!ok) fprintf(stderr, "%s\n", err.msg);
    assert_true(ok);
    return s;
}

/* Max |twin - reference| over the half-texel lattice (where the exact max
 * of a difference of bilinear interpolants lies) plus random points,
 * including points just outside 0..1. */
static double max_error(const sparse_masks *s, int mask, const uint8_t *t)
{
    int w = s->width, h = s->height;
    double err = 0.0;
    for (int j = 0; j <= 2 * h; j++)
        for (int i = 0; i <= 2 * w; i++) {
            double u = 0.5 * i / w, v = 0.5 * j / h;
            double e = fabs(sparse_sample(s, mask, u, v) - sparse_raster_bilinear(t, w, h, u, v));
            err = e > err ? e : err;
        }
    uint32_t rs = 7;
    for (int k = 0; k < 20000; k++) {
        double u = rng_unit(&rs) * 1.02 - 0.01, v = rng_unit(&rs) * 1.02 - 0.01;
        double e = fabs(sparse_sample(s, mask, u, v) - sparse_raster_bilinear(t, w, h, u, v));
        err = e > err ? e : err;
    }
    return err;
}

/* Float coordinates (t = uv * W in fp32, as the GPU) move a sample by up
 * to W * 2^-23 texels; a texel step is at most 1.0 in value. */
static double float_tolerance(int w, int h)
{
    return (w > h ? w : h) * ldexp(1.0, -22) + 1e-6;
}

/* ---- BC4 ------------------------------------------------------------------- */

static void test_bc4_palette(void **state)
{
    /* r0 > r1: eight-value palette; index 2 = (6 r0 + r1) / 7 */
    uint8_t blk[8] = { 255, 0, 0, 0, 0, 0, 0, 0 };
    blk[2] = 2 | 3 << 3;                 /* texel 0: index 2, texel 1: 3 */
    float out[16];
    sparse_bc4_decode(blk, out);
    assert_float_equal(out[0], 6.0f / 7.0f, 1e-6);
    assert_float_equal(out[1], 5.0f / 7.0f, 1e-6);
    assert_float_equal(out[2], 1.0f, 0);  /* index 0 = r0 */
    /* r0 <= r1: six values plus 0 and 255 (indices 6, 7) */
    uint8_t b6[8] = { 50, 100, 0, 0, 0, 0, 0, 0 };
    uint64_t bits = 2 | 6 << 3 | 7 << 6 | 1 << 9;
    for (int i = 0; i < 6; i++) b6[2 + i] = (uint8_t)(bits >> (8 * i));
    sparse_bc4_decode(b6, out);
    assert_float_equal(out[0], (4 * 50 + 1 * 100) / 5.0f / 255.0f, 1e-6);
    assert_float_equal(out[1], 0.0f, 0);
    assert_float_equal(out[2], 1.0f, 0);
    assert_float_equal(out[3], 100 / 255.0f, 1e-7);
    /* stb's encoder: constant blocks exact, a ramp within range / 14 */
    uint8_t in[16], enc[8];
    memset(in, 77, 16);
    sparse_bc4_encode(enc, in);
    sparse_bc4_decode(enc, out);
    for (int i = 0; i < 16; i++) assert_float_equal(out[i], 77 / 255.0f, 1e-7);
    for (int i = 0; i < 16; i++) in[i] = (uint8_t)(i * 17);
    sparse_bc4_encode(enc, in);
    sparse_bc4_decode(enc, out);
    for (int i = 0; i < 16; i++)
        assert_true(fabs(out[i] - in[i] / 255.0) <= 1.0 / 14.0 + 1e-6);
}

/* ---- tiles ------------------------------------------------------------------ */

static void test_constant_and_duplicate_tiles(void **state)
{
    /* 10 x 10 cells; texels 64..255 (cells 2..7) all 255; the rest 0 */
    int w = 320, h = 320;
    uint8_t *t = calloc((size_t)w * h, 1);
    for (int z = 64; z < 256; z++)
        for (int x = 64; x < 256; x++) t[z * w + x] = 255;
    sparse_masks s = build1(t, w, h, SPARSE_R8, 0, 0);
    assert_int_equal(s.cells_x, 10);
    assert_int_equal(s.index[(4 * 10 + 4) * 4], SPARSE_CONST1);  /* inner */
    assert_int_equal(s.index[(0 * 10 + 0) * 4], SPARSE_CONST0);  /* empty */
    /* cells next to the square read its edge in their bilinear footprint,
     * and the square's own border cells read the empty texels beside it */
    assert_true(s.index[(3 * 10 + 1) * 4] != SPARSE_CONST0);
    assert_true(s.index[(3 * 10 + 2) * 4] != SPARSE_CONST1);
    assert_true(s.index[(9 * 10 + 9) * 4] == SPARSE_CONST0);
    /* const 1: cells 3..6 in both axes.  Stored: cells 1..8 (their
     * footprints touch the square) but those.  A cell's slot depends only
     * on its class per axis: 1 (outside the edge), 2 (inside the edge),
     * 3..6 (interior), 7, 8: 5 x 5 classes less the constant one. */
    assert_int_equal(s.info[0].const1, 16);
    assert_int_equal(s.info[0].stored, 8 * 8 - 16);
    assert_int_equal(s.nslots, 5 * 5 - 1);
    double lo, hi;
    sparse_range(&s, 0, 96, 96, 128, 128, &lo, &hi);
    assert_true(lo == 1.0 && hi == 1.0);
    sparse_range(&s, 0, 0, 0, 32, 32, &lo, &hi);
    assert_true(lo == 0.0 && hi == 0.0);
    sparse_range(&s, 0, 32, 64, 64, 96, &lo, &hi);        /* left of square */
    assert_true(lo == 0.0 && hi == 1.0);
    sparse_free(&s);

    /* a pattern of period 32 everywhere: interior cells share one slot;
     * edge cells differ only by their clamped padding: 3 x 3 classes */
    uint32_t rs = 3;
    uint8_t pat[32 * 32];
    for (int i = 0; i < 32 * 32; i++) pat[i] = (uint8_t)(1 + rng_next(&rs) % 253);
    for (int z = 0; z < h; z++)
        for (int x = 0; x < w; x++) t[z * w + x] = pat[(z % 32) * 32 + x % 32];
    s = build1(t, w, h, SPARSE_BC4, 0, 0);
    assert_int_equal(s.info[0].stored, 100);
    assert_int_equal(s.nslots, 9);
    assert_int_equal(s.info[0].new_slots, 9);
    sparse_free(&s);
    free(t);
}

/* ---- accuracy per option ------------------------------------------------------ */

static void test_r8_equals_raster_bilinear(void **state)
{
    /* sizes that are and are not multiples of the tile */
    int sizes[][2] = { { 512, 384 }, { 300, 203 }, { 33, 31 }, { 1, 1 } };
    for (int k = 0; k < 4; k++) {
        int w = sizes[k][0], h = sizes[k][1];
        uint8_t *t = gen_mixed(w, h, 11 + k);
        sparse_masks s = build1(t, w, h, SPARSE_R8, 0, 0);
        double e = max_error(&s, 0, t);
        printf("R8  %4dx%-4d max |sparse - raster bilinear| = %.3g (float bound %.3g)\n",
               w, h, e, float_tolerance(w, h));
        assert_true(e <= float_tolerance(w, h));
        sparse_free(&s);
        free(t);
    }
}

static void test_bc4_error(void **state)
{
    int w = 512, h = 384;
    uint8_t *t = gen_mixed(w, h, 21);
    sparse_masks s = build1(t, w, h, SPARSE_BC4, 0, 0);
    double e = max_error(&s, 0, t);
    sparse_stats st;
    sparse_get_stats(&s, &st);
    printf("BC4 %dx%d max error %.4f (bound 1/14 = %.4f), atlas %zu B (R8 %zu B)\n",
           w, h, e, 1.0 / 14.0, st.atlas_bytes, st.atlas_r8);
    /* stb encodes with min/max endpoints and 8 levels: nearest would be
     * |err| <= range / 14; its index thresholds are biased by up to 2/7 of
     * a byte (stb__CompressAlphaBlock) */
    assert_true(e > 0.0);
    assert_true(e <= (255.0 / 14.0 + 2.0 / 7.0) / 255.0 + float_tolerance(w, h));
    assert_int_equal(st.atlas_bc4 * 2, st.atlas_r8);
    sparse_free(&s);
    free(t);
}

static void test_reduced_levels(void **state)
{
    int w = 512, h = 512;
    uint8_t *t = gen_mixed(w, h, 31);
    sparse_masks full = build1(t, w, h, SPARSE_R8, 0, 0);
    double limits[] = { 0.02, 0.1, 1.0 };
    for (int k = 0; k < 3; k++) {
        sparse_masks s = build1(t, w, h, SPARSE_R8, 3, limits[k]);
        double e = max_error(&s, 0, t);
        printf("reduced (max_level 3, max_error %.2f): %d of %d stored cells reduced, "
               "%d slots (full res %d), measured max error %.4f, build's %.4f\n",
               limits[k], s.info[0].reduced, s.info[0].stored, s.nslots, full.nslots,
               e, s.info[0].reduce_error);
        assert_true(s.info[0].reduced > 0);
        assert_true(s.nslots < full.nslots);
        /* the build's error is exact per cell; it counts a cell's far
         * border too, which the GPU samples from the next cell, so it
         * bounds the measured error from above */
        assert_true(s.info[0].reduce_error <= limits[k]);
        assert_true(e <= s.info[0].reduce_error + float_tolerance(w, h));
        assert_true(e >= 0.5 * s.info[0].reduce_error);
        sparse_free(&s);
    }
    /* the near rect keeps full resolution where the camera comes close */
    sparse_mask_desc md = { .name = "near", .texels = t, .max_level = 3,
                            .max_error = 1.0, .near = { 0, 0, 256, 256 } };
    sparse_desc d = { .width = w, .height = h, .masks = &md, .nmasks = 1,
                      .format = SPARSE_R8 };
    sparse_masks s;
    assert_true(sparse_build(&s, &d, NULL));
    for (int cz = 0; cz < 8; cz++)
        for (int cx = 0; cx < 8; cx++)
            assert_int_equal(s.level[(cz * s.cells_x + cx) * 4], 0);
    int far_reduced = 0;
    for (int i = 0; i < s.cells_x * s.cells_z; i++) far_reduced += s.level[i * 4] > 0;
    assert_true(far_reduced > 0);
    double e = 0.0;
    for (int j = 0; j < 512; j++)                 /* inside the near rect */
        for (int i = 0; i < 512; i++) {
            double u = 0.5 * i / w, v = 0.5 * j / h;
            e = fmax(e, fabs(sparse_sample(&s, 0, u, v) - sparse_raster_bilinear(t, w, h, u, v)));
        }
    assert_true(e <= float_tolerance(w, h));
    sparse_free(&s);
    sparse_free(&full);
    free(t);
}

/* ---- seams ------------------------------------------------------------------------- */

/* Noise everywhere (every tile differs); samples on and next to every tile
 * border in x and z: R8 equals the raster's bilinear sample there, and in
 * every option a step across the border changes the value only as much
 * as the interpolant itself changes (no jump). */
static void test_no_seams(void **state)
{
    int w = 256, h = 192;
    uint8_t *t = malloc((size_t)w * h);
    uint32_t rs = 5;
    for (int i = 0; i < w * h; i++) t[i] = (uint8_t)(rng_next(&rs) & 255);
    sparse_format fmts[] = { SPARSE_R8, SPARSE_BC4 };
    for (int f = 0; f < 2; f++) {
        sparse_masks s = build1(t, w, h, fmts[f], 0, 0);
        assert_int_equal(s.nslots, s.cells_x * s.cells_z);
        double eq = 0.0, jump = 0.0, eps = 1e-3;
        for (int b = 32; b < w; b += 32)
            for (int j = 0; j <= 4 * h; j++) {
                double z = 0.25 * j;
                for (int axis = 0; axis < 2; axis++) {
                    if (axis == 1 && b >= h) continue;
                    double bx = axis ? z : b, bz = axis ? b : z;
                    double dx = axis ? 0 : eps, dz = axis ? eps : 0;
                    double ref = sparse_raster_bilinear(t, w, h, bx / w, bz / h);
                    double on = sparse_sample(&s, 0, bx / w, bz / h);
                    double lo = sparse_sample(&s, 0, (bx - dx) / w, (bz - dz) / h);
                    double hi = sparse_sample(&s, 0, (bx + dx) / w, (bz + dz) / h);
                    eq = fmax(eq, fabs(on - ref));
                    /* the raster's own change over 2 eps is at most 2 eps */
                    jump = fmax(jump, fabs(hi - lo) - 2 * eps);
                }
            }
        printf("seams (%s): max |border sample - raster| = %.3g, max jump across a "
               "border beyond the slope = %.3g\n", f ? "BC4" : "R8", eq, jump);
        if (fmts[f] == SPARSE_R8) {
            assert_true(eq <= float_tolerance(w, h));
            assert_true(jump <= float_tolerance(w, h));
        } else {
            /* each side carries its own BC4 error, never more */
            assert_true(jump <= 2.0 / 14.0);
        }
        sparse_free(&s);
    }
    free(t);
}

/* ---- ranges --------------------------------------------------------------------------- */

/* Every value the twin or the reference gives for a point of a rectangle
 * lies in sparse_range's bounds, for every option. */
static void test_ranges_sound(void **state)
{
    int w = 300, h = 203;
    uint8_t *t = gen_mixed(w, h, 41);
    struct { sparse_format f; int level; double err; } opts[] = {
        { SPARSE_R8, 0, 0 }, { SPARSE_BC4, 0, 0 }, { SPARSE_BC4, 2, 0.1 },
    };
    uint32_t rs = 9;
    for (int o = 0; o < 3; o++) {
        sparse_masks s = build1(t, w, h, opts[o].f, opts[o].level, opts[o].err);
        int exact_zero = 0;
        for (int k = 0; k < 300; k++) {
            int x0 = (int)(rng_unit(&rs) * w), z0 = (int)(rng_unit(&rs) * h);
            int x1 = x0 + 1 + (int)(rng_unit(&rs) * 64), z1 = z0 + 1 + (int)(rng_unit(&rs) * 64);
            if (k % 3 == 0) {                      /* cell-aligned rects */
                x0 = x0 / 32 * 32; z0 = z0 / 32 * 32; x1 = x0 + 32; z1 = z0 + 32;
            }
            x1 = x1 > w ? w : x1; z1 = z1 > h ? h : z1;
            double lo, hi;
            sparse_range(&s, 0, x0, z0, x1, z1, &lo, &hi);
            exact_zero += hi == 0.0;
            for (int p = 0; p < 200; p++) {
                double u = (x0 + rng_unit(&rs) * (x1 - x0)) / w;
                double v = (z0 + rng_unit(&rs) * (z1 - z0)) / h;
                double a = sparse_sample(&s, 0, u, v);
                double b = sparse_raster_bilinear(t, w, h, u, v);
                assert_true(a >= lo && a <= hi);
                assert_true(b >= lo && b <= hi);
            }
        }
        assert_true(exact_zero > 0);   /* empty areas give [0, 0] */
        sparse_free(&s);
    }
    free(t);
}

static char *write_mem(const sparse_masks *s, size_t *n)
{
    char *buf = NULL;
    FILE *f = open_memstream(&buf, n);
    assert_true(sparse_write(s, f));
    fclose(f);
    return buf;
}

/* ---- placed masks ---------------------------------------------------------------------- */

/* A mask of its own size over a rectangle of the terrain: the twin reads
 * the raster at the mask's uv (0 outside the rectangle), sparse_range_terrain
 * bounds every sample of heightfield-texel rectangles, the file keeps the
 * place, and the GLSL constants name it. */
static void test_placed_masks(void **state)
{
    int w = 300, h = 203, mw = 500, mh = 260;
    uint8_t *t = gen_mixed(mw, mh, 61), *b = gen_fields(w, h, 6, 30, 62);
    sparse_mask_desc md[2] = {
        { .name = "placed", .texels = t, .width = mw, .height = mh,
          .rect = { 0.2, 0.3, 0.45, 0.55 } },
        { .name = "whole", .texels = b },
    };
    sparse_desc d = { .width = w, .height = h, .masks = md, .nmasks = 2, .format = SPARSE_R8 };
    sparse_masks s;
    assert_true(sparse_build(&s, &d, NULL));
    assert_true(sparse_placed(&s, 0));
    assert_false(sparse_placed(&s, 1));
    assert_int_equal(s.cells_x, (mw + 31) / 32);      /* the largest mask's */
    assert_int_equal(s.cells_z, (mh + 31) / 32);
    uint32_t rs = 5;
    double tol = float_tolerance(mw, mh) + 4.0 / mw;  /* + the fp32 mapping */
    int inside = 0;
    for (int k = 0; k < 40000; k++) {
        double u = rng_unit(&rs) * 1.02 - 0.01, v = rng_unit(&rs) * 1.02 - 0.01;
        double mu = (u - 0.2) / 0.25, mv = (v - 0.3) / 0.25;
        double a = sparse_sample(&s, 0, u, v);
        if (mu < -1e-5 || mv < -1e-5 || mu > 1 + 1e-5 || mv > 1 + 1e-5) {
            assert_true(a == 0.0);
            continue;
        }
        inside++;
        double want = sparse_raster_bilinear(t, mw, mh, mu, mv);
        if (mu > 1e-5 && mv > 1e-5 && mu < 1 - 1e-5 && mv < 1 - 1e-5 && fabs(a - want) > tol)
            fail_msg("u %g v %g: twin %g, raster %g", u, v, a, want);
        /* the whole-terrain mask is unchanged beside it */
        assert_true(fabs(sparse_sample(&s, 1, u, v) -
                         sparse_raster_bilinear(b, w, h, u, v)) <= float_tolerance(w, h));
    }
    assert_true(inside > 1500);
    /* bounds over heightfield-texel rectangles hold every sample in them */
    int zero = 0, some = 0;
    for (int k = 0; k < 400; k++) {
        int x0 = (int)(rng_unit(&rs) * w), z0 = (int)(rng_unit(&rs) * h);
        int x1 = x0 + 1 + (int)(rng_unit(&rs) * 24), z1 = z0 + 1 + (int)(rng_unit(&rs) * 24);
        x1 = x1 > w ? w : x1; z1 = z1 > h ? h : z1;
        double lo, hi;
        sparse_range_terrain(&s, 0, x0, z0, x1, z1, &lo, &hi);
        zero += hi == 0.0;
        some += hi > lo;
        for (int p = 0; p < 200; p++) {
            double u = (x0 + rng_unit(&rs) * (x1 - x0)) / w;
            double v = (z0 + rng_unit(&rs) * (z1 - z0)) / h;
            double a = sparse_sample(&s, 0, u, v);
            if (!(a >= lo && a <= hi))
                fail_msg("rect %d %d %d %d: %g outside [%g, %g]", x0, z0, x1, z1, a, lo, hi);
        }
    }
    assert_true(zero > 50 && some > 20);
    /* the file keeps the place; the GLSL names it */
    size_t n;
    char *f = write_mem(&s, &n);
    sparse_masks r;
    sparse_error err;
    assert_true(sparse_read(&r, (const uint8_t *)f, n, "mem", &err));
    assert_memory_equal(r.place, s.place, 2 * sizeof *s.place);
    for (int k = 0; k < 2000; k++) {
        double u = rng_unit(&rs), v = rng_unit(&rs);
        assert_true(sparse_sample(&r, 0, u, v) == sparse_sample(&s, 0, u, v));
    }
    char *glsl = sparse_glsl_places(&s);
    assert_non_null(glsl);
    assert_non_null(strstr(glsl, "#define SPLAT_PAINTED_PLACED"));
    assert_non_null(strstr(glsl, "vec2(500.0, 260.0), vec2(300.0, 203.0)"));
    assert_non_null(strstr(glsl, "vec4(0.200000003, 0.300000012, 4, 4)"));
    free(glsl);
    sparse_free(&r);
    free(f);
    /* a forged place (a raster of 0 texels) is refused */
    char *forged = write_mem(&s, &n);
    memset(forged + 8 + 4 * 11, 0, 4);
    assert_false(sparse_read(&r, (const uint8_t *)forged, n, "forged", &err));
    free(forged);
    sparse_free(&s);
    free(t); free(b);
}

/* ---- determinism and the pack file ------------------------------------------------------ */

static void test_deterministic_and_file(void **state)
{
    int w = 300, h = 203;
    uint8_t *a = gen_mixed(w, h, 51), *b = gen_fields(w, h, 6, 30, 52);
    sparse_mask_desc md[5] = {
        { .name = "a", .texels = a }, { .name = "b", .texels = b, .max_level = 2, .max_error = 0.05 },
        { .name = "a2", .texels = a }, { .name = "c", .texels = b }, { .name = "e", .texels = a },
    };
    sparse_desc d = { .width = w, .height = h, .masks = md, .nmasks = 5 };
    sparse_masks s1, s2;
    assert_true(sparse_build(&s1, &d, NULL));
    assert_true(sparse_build(&s2, &d, NULL));
    assert_int_equal(s1.layers, 2);
    assert_int_equal(s1.info[2].new_slots, 0);     /* a2 repeats a: no slots */
    size_t n1, n2;
    char *f1 = write_mem(&s1, &n1), *f2 = write_mem(&s2, &n2);
    assert_int_equal(n1, n2);
    assert_memory_equal(f1, f2, n1);
    /* read back: same samples, same ranges */
    sparse_masks r;
    sparse_error err;
    assert_true(sparse_read(&r, (const uint8_t *)f1, n1, "mem", &err));
    for (int m = 0; m < 5; m++)
        for (int k = 0; k < 500; k++) {
            double u = (k % 37) / 36.0, v = (k / 37) / 13.0;
            assert_true(sparse_sample(&r, m, u, v) == sparse_sample(&s1, m, u, v));
        }
    double lo1, hi1, lo2, hi2;
    sparse_range(&s1, 1, 10, 10, 90, 70, &lo1, &hi1);
    sparse_range(&r, 1, 10, 10, 90, 70, &lo2, &hi2);
    assert_true(lo1 == lo2 && hi1 == hi2);
    sparse_free(&r);
    /* truncated files are errors, never crashes */
    for (size_t cut = 0; cut < n1; cut += n1 / 7 + 1) {
        assert_false(sparse_read(&r, (const uint8_t *)f1, cut, "cut", &err));
        assert_int_equal(err.id, SPARSE_E_BAD_FILE);
    }
    /* a forged header (atlas rows raised) against the
     * same bytes: refused before allocating, naming the size */
    char *forged = malloc(n1);
    memcpy(forged, f1, n1);
    forged[8 + 4 * 10] = (char)200;                  /* atlas_rows 200       */
    assert_false(sparse_read(&r, (const uint8_t *)forged, n1, "forged", &err));
    assert_int_equal(err.id, SPARSE_E_BAD_FILE);
    assert_non_null(strstr(err.msg, "the header describes"));
    free(forged);
    free(f1); free(f2);
    sparse_free(&s1); sparse_free(&s2);
    free(a); free(b);
}

/* ---- bad input ----------------------------------------------------------------------------- */

unsigned char *stbi_zlib_compress(unsigned char *data, int data_len,
                                  int *out_len, int quality);

static void put_be32(FILE *f, uint32_t v)
{
    for (int i = 3; i >= 0; i--) fputc((int)(v >> (8 * i) & 255), f);
}

static uint32_t crc32_of(uint32_t crc, const unsigned char *p, size_t n)
{
    crc = ~crc;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1)));
    }
    return ~crc;
}

static void png_chunk(FILE *f, const char *type, const unsigned char *d, size_t n)
{
    put_be32(f, (uint32_t)n);
    fwrite(type, 1, 4, f);
    if (n) fwrite(d, 1, n, f);
    put_be32(f, crc32_of(crc32_of(0, (const unsigned char *)type, 4), d, n));
}

/* A 16-bit greyscale PNG (stb_image_write only writes 8-bit). */
static void write_png16(const char *path, int w, int h)
{
    size_t row = 1 + 2 * (size_t)w;
    unsigned char *raw = calloc(row * h, 1);
    int zn;
    unsigned char *z = stbi_zlib_compress(raw, (int)(row * h), &zn, 8);
    FILE *f = fopen(path, "wb");
    fwrite("\x89PNG\r\n\x1a\n", 1, 8, f);
    unsigned char ihdr[13] = { 0, 0, 0, (unsigned char)w, 0, 0, 0, (unsigned char)h, 16, 0, 0, 0, 0 };
    png_chunk(f, "IHDR", ihdr, 13);
    png_chunk(f, "IDAT", z, (size_t)zn);
    png_chunk(f, "IEND", NULL, 0);
    fclose(f);
    free(z);
    free(raw);
}

static void test_bad_rasters(void **state)
{
    char dir[] = "/tmp/test_sparse_XXXXXX", path[256];
    assert_non_null(mkdtemp(dir));
    uint8_t px[64 * 48 * 3] = { 0 };
    uint8_t *t;
    sparse_error err;

    snprintf(path, sizeof path, "%s/ok.png", dir);
    assert_true(stbi_write_png(path, 64, 48, 1, px, 64));
    assert_true(sparse_load_raster(path, 64, 48, &t, &err));
    free(t);
    assert_false(sparse_load_raster(path, 64, 32, &t, &err));
    assert_int_equal(err.id, SPARSE_E_BAD_SIZE);
    assert_non_null(strstr(err.msg, "64x48"));
    assert_null(t);

    snprintf(path, sizeof path, "%s/rgb.png", dir);
    assert_true(stbi_write_png(path, 64, 48, 3, px, 64 * 3));
    assert_false(sparse_load_raster(path, 64, 48, &t, &err));
    assert_int_equal(err.id, SPARSE_E_BAD_CHANNELS);

    snprintf(path, sizeof path, "%s/deep.png", dir);
    write_png16(path, 64, 48);
    assert_false(sparse_load_raster(path, 64, 48, &t, &err));
    assert_int_equal(err.id, SPARSE_E_BAD_DEPTH);

    snprintf(path, sizeof path, "%s/missing.png", dir);
    assert_false(sparse_load_raster(path, 64, 48, &t, &err));
    assert_int_equal(err.id, SPARSE_E_IO);

    snprintf(path, sizeof path, "%s/garbage.png", dir);
    FILE *f = fopen(path, "wb");
    fputs("not a png at all", f);
    fclose(f);
    assert_false(sparse_load_raster(path, 64, 48, &t, &err));
    assert_int_equal(err.id, SPARSE_E_IO);
    printf("bad raster message: %s\n", err.msg);

    /* bad options */
    sparse_mask_desc md = { .name = "fields", .texels = px, .max_level = 9 };
    sparse_desc d = { .width = 64, .height = 48, .masks = &md, .nmasks = 1 };
    sparse_masks s;
    assert_false(sparse_build(&s, &d, &err));
    assert_int_equal(err.id, SPARSE_E_BAD_OPTION);
    assert_non_null(strstr(err.msg, "fields"));
    md.max_level = 1;
    md.max_error = -0.5;
    assert_false(sparse_build(&s, &d, &err));
    assert_int_equal(err.id, SPARSE_E_BAD_OPTION);

    const char *names[] = { "ok.png", "rgb.png", "deep.png", "garbage.png" };
    for (int i = 0; i < 4; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
}

/* ---- figures ----------------------------------------------------------------------------- */

/* Seed 000 Fig. 10 / 11: a 2048 x 2048 field mask stored sparse.  The same
 * fields embedded in a 4x larger empty raster need exactly the same atlas:
 * constant tiles cost no atlas space, only their indirection texels. */
static void test_figure_fields(void **state)
{
    int w = 2048, h = 2048;
    uint8_t *t = gen_fields(w, h, 48, 60.0, 2007);
    size_t on = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) on += t[i] > 0;
    printf("\nFigure (Andersson 2007 Fig. 10): %d fields painted over %.1f %% of a %dx%d mask\n",
           48, 100.0 * on / ((double)w * h), w, h);
    sparse_masks bc4 = build1(t, w, h, SPARSE_BC4, 0, 0);
    sparse_print_stats(&bc4, stdout);
    sparse_stats sb;
    sparse_get_stats(&bc4, &sb);
    /* the options side by side; "far": everything but the centre quarter
     * may drop to level 1 or 2 whatever the error (max_error 1) */
    struct { const char *name; sparse_format f; int level; double err; bool far; } opt[] = {
        { "R8", SPARSE_R8, 0, 0, false },
        { "BC4", SPARSE_BC4, 0, 0, false },
        { "BC4, levels <= 2 where error <= 0.1", SPARSE_BC4, 2, 0.1, false },
        { "BC4, far area at level 1", SPARSE_BC4, 1, 1.0, true },
        { "BC4, far area at level <= 2", SPARSE_BC4, 2, 1.0, true },
    };
    printf("  %-38s %10s %8s %10s\n", "option", "bytes", "% dense", "reduce err");
    size_t bytes[5];
    for (int o = 0; o < 5; o++) {
        sparse_mask_desc md = { .name = "fields", .texels = t, .max_level = opt[o].level,
                                .max_error = opt[o].err };
        if (opt[o].far)
            memcpy(md.near, (int[4]){ w / 4, h / 4, 3 * w / 4, 3 * h / 4 }, sizeof md.near);
        sparse_desc d = { .width = w, .height = h, .masks = &md, .nmasks = 1, .format = opt[o].f };
        sparse_masks s;
        sparse_stats st;
        assert_true(sparse_build(&s, &d, NULL));
        sparse_get_stats(&s, &st);
        bytes[o] = st.total_bytes;
        printf("  %-38s %10zu %7.2f%% %10.4f\n", opt[o].name, st.total_bytes,
               100 * st.fraction, s.info[0].reduce_error);
        sparse_free(&s);
    }
    assert_true(sb.fraction < 0.15);
    assert_int_equal(bytes[1], sb.total_bytes);
    assert_true(bytes[0] > bytes[1]);
    assert_true(bytes[4] < bytes[3] && bytes[3] < bytes[1]);
    assert_true(bc4.nslots < bc4.info[0].stored);       /* crop rows repeat */

    int W = 2 * w, H = 2 * h;
    uint8_t *big = calloc((size_t)W * H, 1);
    for (int z = 0; z < h; z++) memcpy(big + (size_t)(z + h) * W + w, t + (size_t)z * w, w);
    sparse_masks bb = build1(big, W, H, SPARSE_BC4, 0, 0);
    sparse_stats sbb;
    sparse_get_stats(&bb, &sbb);
    printf("  the same fields in a %dx%d mask: atlas %zu B (was %zu B), index + level "
           "%zu B, total %.2f %% of dense\n", W, H, sbb.atlas_bytes, sb.atlas_bytes,
           sbb.index_bytes + sbb.level_bytes, 100 * sbb.fraction);
    assert_int_equal(bb.nslots, bc4.nslots);
    assert_int_equal(sbb.atlas_bytes, sb.atlas_bytes);
    sparse_free(&bb); sparse_free(&bc4);
    free(big);
    free(t);
}

/* Seed 000 §5.2.5 / slides 003: the destruction mask over 2048 m x 2048 m.
 * A CPU model of the fixed-grid allocator: 128 x 128 RG88 indirection
 * (16 m cells), 64 x 64 L8 tiles (4 px/m) allocated for every cell a
 * crater touches.  Craters (radius 2..8 m) fall at random, scattered over
 * the whole area, until 10 % of the area is destroyed. */
static void test_figure_destruction(void **state)
{
    const int cells = 128, tile = 64, px = cells * tile;   /* 8192 px */
    const double area = 2048.0, ppm = px / area;
    size_t dense = (size_t)px * px;                        /* L8 */
    /* coverage on a 1 px/m grid is enough for the 10 % stop criterion */
    int g = (int)area;
    uint8_t *hit = calloc((size_t)g * g, 1), *alloc = calloc((size_t)cells * cells, 1);
    size_t destroyed = 0, ntiles = 0;
    int ncraters = 0;
    uint32_t rs = 2048;
    while (destroyed < (size_t)(0.10 * g * g)) {
        double cx = rng_unit(&rs) * area, cz = rng_unit(&rs) * area;
        double r = 2.0 + 6.0 * rng_unit(&rs);
        ncraters++;
        for (int z = (int)fmax(0, cz - r); z < (int)fmin(g, cz + r + 1); z++)
            for (int x = (int)fmax(0, cx - r); x < (int)fmin(g, cx + r + 1); x++)
                if (hypot(x + 0.5 - cx, z + 0.5 - cz) <= r && !hit[z * g + x]) {
                    hit[z * g + x] = 1;
                    destroyed++;
                }
        int c0x = (int)fmax(0, (cx - r) / 16), c1x = (int)fmin(cells - 1, (cx + r) / 16);
        int c0z = (int)fmax(0, (cz - r) / 16), c1z = (int)fmin(cells - 1, (cz + r) / 16);
        for (int z = c0z; z <= c1z; z++)
            for (int x = c0x; x <= c1x; x++)
                if (!alloc[z * cells + x]) { alloc[z * cells + x] = 1; ntiles++; }
    }
    size_t index = (size_t)cells * cells * 2;
    size_t pool10 = (size_t)(0.10 * cells * cells + 0.5) * tile * tile;   /* slides' budget */
    size_t scattered = ntiles * (size_t)tile * tile;
    printf("\nFigure (Andersson 2007 5.2.5): destruction mask, 2048 m x 2048 m at %.0f px/m\n", ppm);
    printf("  dense 8-bit %dx%d: %zu B (%.1f MiB)\n", px, px, dense, dense / 1048576.0);
    printf("  sparse, RG88 %dx%d indirection (%zu B) + 64x64 L8 tiles of 16 m:\n",
           cells, cells, index);
    printf("    10 %% of the cells allocated (the slides' budget): %zu B = %.2f MB "
           "= %.1f %% of dense\n", index + pool10, (index + pool10) / 1e6,
           100.0 * (index + pool10) / dense);
    printf("    %d craters scattered until 10 %% of the area is destroyed touch %zu "
           "cells (%.1f %%): %zu B = %.2f MB\n", ncraters, ntiles,
           100.0 * ntiles / (cells * cells), index + scattered, (index + scattered) / 1e6);
    size_t dense2 = (size_t)4096 * 4096, pool2 = (size_t)(0.10 * cells * cells + 0.5) * 32 * 32;
    printf("  the slides quote 16.7 MB -> ~1.7 MB: 16.7 MB is a 4096^2 L8 texture, "
           "i.e. 2 px/m; at 4 px/m the 10 %% budget is %.2f MB = %.2f x 16.7 MB;\n"
           "  at 2 px/m (128x128 RG88 cells of 16 m, 32x32 L8 tiles) dense %.1f MB, "
           "10 %% budget %.2f MB = %.1f %% of 16.7 MB\n",
           (index + pool10) / 1e6, (index + pool10) / 16.7e6, dense2 / 1e6,
           (index + pool2) / 1e6, 100.0 * (index + pool2) / 16.7e6);
    assert_int_equal(dense, 64u << 20);                  /* 64 MB, as the seed */
    assert_true((double)(index + pool10) / dense < 0.11); /* about a tenth */
    assert_true(ntiles >= (size_t)(0.10 * cells * cells)); /* scattering costs more */
    free(hit);
    free(alloc);
}

/* The GLSL sampler compiles (glslang) and validates (SPIRV-Tools) inside
 * a compute shader that declares the three textures. */
static void test_glsl_compiles(void **state)
{
    static const char src[] =
        "#version 450\n"
        "layout(local_size_x = 64) in;\n"
        "layout(set = 0, binding = 0) uniform sampler2D u_painted_atlas;\n"
        "layout(set = 0, binding = 1) uniform usampler2DArray u_painted_index;\n"
        "layout(set = 0, binding = 2) uniform usampler2DArray u_painted_level;\n"
        "layout(set = 0, binding = 3, std430) buffer Out { float v[]; } o;\n"
        SPARSE_GLSL_FUNCTIONS
        "void main() {\n"
        "    uint i = gl_GlobalInvocationID.x;\n"
        "    o.v[i] = splat_sparse_painted(vec2(float(i) / 64.0, 0.5), vec2(300.0, 203.0), int(i % 5u));\n"
        "}\n";
    assert_string_equal(SPLAT_GLSL_SPARSE, SPARSE_GLSL_FUNCTIONS);
    uint32_t *words;
    size_t n;
    char *log = NULL;
    bool ok = spv_compile(src, SPV_STAGE_COMPUTE, "sparse", &words, &n, &log);
    if (!ok) fprintf(stderr, "%s\n", log);
    assert_true(ok);
    free(log);
    log = NULL;
    ok = spv_validate(words, n, &log);
    if (!ok) fprintf(stderr, "%s\n", log);
    assert_true(ok);
    free(log);
    free(words);
}

/* The ABI prelude compiles as a fragment shader with the dense painted
 * masks (default) and with SPLAT_PAINTED_SPARSE, where splat_painted()
 * reads the sparse textures at bindings 2, 5 and 6. */
static void test_abi_prelude_sparse(void **state)
{
    for (int sparse = 0; sparse < 2; sparse++) {
        size_t n = strlen(SPLAT_GLSL_PRELUDE) + 512;
        char *src = malloc(n);
        snprintf(src, n, "#version 450\n%s%s"
                 "void main() {\n"
                 "    float m = splat_painted(0) + splat_painted(5);\n"
                 "    splat_finish(vec3(m), splat_normal(), 0.8, 0.5, 1.0);\n"
                 "}\n", sparse ? "#define SPLAT_PAINTED_SPARSE 1\n" : "",
                 SPLAT_GLSL_PRELUDE);
        uint32_t *words;
        size_t nw;
        char *log = NULL;
        bool ok = spv_compile(src, SPV_STAGE_FRAGMENT, "prelude", &words, &nw, &log);
        if (!ok) fprintf(stderr, "%s\n", log);
        assert_true(ok);
        free(log);
        log = NULL;
        ok = spv_validate(words, nw, &log);
        if (!ok) fprintf(stderr, "%s\n", log);
        assert_true(ok);
        free(log);
        free(words);
        free(src);
    }
    assert_int_equal(SPLAT_BIND_PAINTED_INDEX, 5);
    assert_int_equal(SPLAT_BIND_PAINTED_LEVEL, 6);
}

/* The sparse painted-mask target on the example content: the painted masks of
 * examples/colorado in at most 15 % of their dense size (BC4), and the
 * reduced-level option (everything but the centre quarter of the map at
 * levels <= 2, whatever the error) at most half of that, with its error. */
static void test_colorado_masks(void **state)
{
    const char *names[] = { "field_wheat", "field_plowed", "field_fallow", "road" };
    int w = 2401, h = 1201;
    uint8_t *t[4];
    sparse_mask_desc md[4];
    sparse_error err;
    char path[256];
    snprintf(path, sizeof path, "examples/colorado/masks/%s.png", names[0]);
    if (access(path, R_OK) != 0) {
        printf("examples/colorado not here: skipped\n");
        skip();
    }
    for (int i = 0; i < 4; i++) {
        snprintf(path, sizeof path, "examples/colorado/masks/%s.png", names[i]);
        bool ok = sparse_load_raster(path, w, h, &t[i], &err);
        if (!ok) fprintf(stderr, "%s\n", err.msg);
        assert_true(ok);
        md[i] = (sparse_mask_desc){ .name = names[i], .texels = t[i] };
    }
    sparse_desc d = { .width = w, .height = h, .masks = md, .nmasks = 4, .format = SPARSE_BC4 };
    sparse_masks s;
    sparse_stats full, red;
    assert_true(sparse_build(&s, &d, &err));
    printf("\ncolorado painted masks, BC4, full resolution:\n");
    sparse_print_stats(&s, stdout);
    sparse_get_stats(&s, &full);
    sparse_free(&s);
    /* the far area (all but the centre quarter of the map) at level <= L,
     * whatever the error: the reduced-level option with its error */
    double frac[3] = { full.fraction, 0, 0 };
    for (int L = 1; L <= 2; L++) {
        for (int i = 0; i < 4; i++) {
            md[i].max_level = L;
            md[i].max_error = 1.0;
            memcpy(md[i].near, (int[4]){ w / 4, h / 4, 3 * w / 4, 3 * h / 4 }, sizeof md[i].near);
        }
        assert_true(sparse_build(&s, &d, &err));
        printf("colorado, BC4, levels <= %d outside the centre quarter:\n", L);
        sparse_print_stats(&s, stdout);
        sparse_get_stats(&s, &red);
        double e = 0.0;
        for (int i = 0; i < 4; i++) e = fmax(e, s.info[i].reduce_error);
        frac[L] = red.fraction;
        printf("  -> %.2f %% of dense (%.2f x full resolution), reduced-level max "
               "error %.3f\n", 100 * red.fraction, red.fraction / full.fraction, e);
        assert_true(e > 0.0 && e <= 1.0);
        sparse_free(&s);
    }
    printf("colorado: %.2f %% of dense at full resolution (target <= 15 %%); reduced "
           "levels %.2f %% (level 1), %.2f %% (level 2; target <= half)\n",
           100 * frac[0], 100 * frac[1], 100 * frac[2]);
    assert_true(frac[0] <= 0.15);
    assert_true(frac[1] < frac[0]);
    assert_true(frac[2] <= 0.5 * frac[0]);
    for (int i = 0; i < 4; i++) free(t[i]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc4_palette),
        cmocka_unit_test(test_constant_and_duplicate_tiles),
        cmocka_unit_test(test_r8_equals_raster_bilinear),
        cmocka_unit_test(test_bc4_error),
        cmocka_unit_test(test_reduced_levels),
        cmocka_unit_test(test_no_seams),
        cmocka_unit_test(test_ranges_sound),
        cmocka_unit_test(test_placed_masks),
        cmocka_unit_test(test_deterministic_and_file),
        cmocka_unit_test(test_bad_rasters),
        cmocka_unit_test(test_figure_fields),
        cmocka_unit_test(test_figure_destruction),
        cmocka_unit_test(test_colorado_masks),
        cmocka_unit_test(test_glsl_compiles),
        cmocka_unit_test(test_abi_prelude_sparse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
