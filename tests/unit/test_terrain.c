/* test_terrain.c — the heightfield on the CPU (compiler/terrain.c): the
 * loaders and their errors, the CPU twins of the ABI's height and normal
 * functions (Listing 1 worked by hand), and the soundness of the per-region
 * ranges, also under a model of the GPU's sub-texel weight precision. */
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
#include "scene.h"

/* ---- fixtures ------------------------------------------------------------ */

/* From stb_image_write (libstb); the header declares it only in its
 * implementation part. */
unsigned char *stbi_zlib_compress(unsigned char *data, int data_len,
                                  int *out_len, int quality);

static void put_be32(FILE *f, uint32_t v)
{
    fputc((int)(v >> 24), f);
    fputc((int)(v >> 16 & 255), f);
    fputc((int)(v >> 8 & 255), f);
    fputc((int)(v & 255), f);
}

static uint32_t crc32_bytes(uint32_t crc, const unsigned char *p, size_t n)
{
    crc = ~crc;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++)
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1)));
    }
    return ~crc;
}

static void chunk(FILE *f, const char *type, const unsigned char *data, size_t n)
{
    put_be32(f, (uint32_t)n);
    fwrite(type, 1, 4, f);
    if (n) fwrite(data, 1, n, f);
    uint32_t crc = crc32_bytes(0, (const unsigned char *)type, 4);
    crc = crc32_bytes(crc, data, n);
    put_be32(f, crc);
}

/* A greyscale PNG of `channels` (1 or 3) 16-bit samples, written by hand
 * so the loader is checked against an independent writer. */
static void write_png16(const char *path, int w, int h, int channels,
                        const uint16_t *px)
{
    size_t row = (size_t)w * channels * 2 + 1;
    unsigned char *raw = malloc(row * h);
    assert_non_null(raw);
    for (int y = 0; y < h; y++) {
        unsigned char *r = raw + row * y;
        r[0] = 0;                                   /* filter: none */
        for (int x = 0; x < w * channels; x++) {
            uint16_t v = px[(size_t)y * w * channels + x];
            r[1 + 2 * x] = (unsigned char)(v >> 8);
            r[2 + 2 * x] = (unsigned char)(v & 255);
        }
    }
    int zlen = 0;
    unsigned char *z = stbi_zlib_compress(raw, (int)(row * h), &zlen, 5);
    free(raw);
    assert_non_null(z);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    static const unsigned char sig[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    fwrite(sig, 1, 8, f);
    unsigned char ihdr[13] = { 0 };
    ihdr[0] = (unsigned char)(w >> 24); ihdr[1] = (unsigned char)(w >> 16);
    ihdr[2] = (unsigned char)(w >> 8);  ihdr[3] = (unsigned char)w;
    ihdr[4] = (unsigned char)(h >> 24); ihdr[5] = (unsigned char)(h >> 16);
    ihdr[6] = (unsigned char)(h >> 8);  ihdr[7] = (unsigned char)h;
    ihdr[8] = 16;
    ihdr[9] = channels == 3 ? 2 : 0;                /* RGB or grey */
    chunk(f, "IHDR", ihdr, 13);
    chunk(f, "IDAT", z, (size_t)zlen);
    chunk(f, "IEND", NULL, 0);
    fclose(f);
    free(z);
}

static char tmpdir[64];

static int make_tmpdir(void **state)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/test_terrain.XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int remove_tmpdir(void **state)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *tmp_path(const char *name)
{
    static char buf[8][128];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 128, "%s/%s", tmpdir, name);
    return p;
}

static const sg_loc LOC = { "scene.sg", 7, 19 };

/* The one error the call must have left, with id and location. */
static void assert_one_error(const sg_diags *d, sg_error_id id)
{
    assert_int_equal(d->nerrors, 1);
    assert_int_equal(d->items[0].id, id);
    assert_string_equal(d->items[0].loc.file, "scene.sg");
    assert_int_equal(d->items[0].loc.line, 7);
    assert_int_equal(d->items[0].loc.col, 19);
}

/* Deterministic pseudo-random numbers (tests must not depend on libc). */
static uint64_t rng = 0x9e3779b97f4a7c15ull;
static uint32_t rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 16);
}
static double rnd01(void) { return rnd() / 4294967296.0; }

static void make_terrain(splat_terrain *t, int w, int h, double sx, double sz,
                         double maxh, double off)
{
    memset(t, 0, sizeof *t);
    t->width = w;
    t->height = h;
    t->size[0] = sx;
    t->size[1] = sz;
    t->max_height = maxh;
    t->height_offset = off;
    t->texels = calloc((size_t)w * h, sizeof *t->texels);
    assert_non_null(t->texels);
}

/* ---- loaders ------------------------------------------------------------- */

static void test_load_png16(void **state)
{
    enum { W = 7, H = 5 };
    uint16_t px[W * H];
    for (int i = 0; i < W * H; i++)
        px[i] = (uint16_t)(i * 1871u);
    px[0] = 0;
    px[W * H - 1] = 65535;
    const char *path = tmp_path("hf16.png");
    write_png16(path, W, H, 1, px);

    splat_terrain t = { .size = { 10, 20 }, .max_height = 3 };
    sg_diags d;
    sg_diags_init(&d);
    assert_true(splat_terrain_load(&t, path, SG_HF_PNG, 0, 0, LOC, &d));
    assert_int_equal(d.nerrors, 0);
    assert_int_equal(t.width, W);
    assert_int_equal(t.height, H);
    assert_memory_equal(t.texels, px, sizeof px);
    /* The scene's values survive loading. */
    assert_true(t.size[1] == 20 && t.max_height == 3);
    assert_true(splat_terrain_texel(&t, W - 1, H - 1) == 1.0);
    assert_true(splat_terrain_texel(&t, 2, 1) == px[W + 2] / 65535.0);
    /* Clamped to the edges. */
    assert_true(splat_terrain_texel(&t, -5, -1) == 0.0);
    assert_true(splat_terrain_texel(&t, 99, 99) == 1.0);
    splat_terrain_free(&t);
    sg_diags_free(&d);
}

static void test_load_png8_scales_by_257(void **state)
{
    enum { W = 4, H = 3 };
    unsigned char px[W * H] = { 0, 1, 2, 3, 100, 128, 200, 254, 255, 7, 70, 170 };
    const char *path = tmp_path("hf8.png");
    assert_true(stbi_write_png(path, W, H, 1, px, W) != 0);

    splat_terrain t = { 0 };
    sg_diags d;
    sg_diags_init(&d);
    assert_true(splat_terrain_load(&t, path, SG_HF_PNG, 0, 0, LOC, &d));
    assert_int_equal(t.width, W);
    assert_int_equal(t.height, H);
    for (int i = 0; i < W * H; i++)
        assert_int_equal(t.texels[i], px[i] * 257);
    splat_terrain_free(&t);
    sg_diags_free(&d);
}

static void test_load_raw_r16(void **state)
{
    enum { W = 3, H = 2 };
    const unsigned char bytes[W * H * 2] = {
        0x00, 0x00, 0x34, 0x12, 0xff, 0xff,     /* 0, 0x1234, 65535 */
        0x01, 0x00, 0x00, 0x01, 0xcd, 0xab,     /* 1, 0x0100, 0xabcd */
    };
    const char *path = tmp_path("hf.r16");
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fwrite(bytes, 1, sizeof bytes, f);
    fclose(f);

    splat_terrain t = { 0 };
    sg_diags d;
    sg_diags_init(&d);
    assert_true(splat_terrain_load(&t, path, SG_HF_R16, W, H, LOC, &d));
    const uint16_t want[W * H] = { 0, 0x1234, 65535, 1, 0x0100, 0xabcd };
    assert_memory_equal(t.texels, want, sizeof want);
    splat_terrain_free(&t);
    sg_diags_free(&d);

    /* The wrong size, and no size at all, are errors at the location. */
    sg_diags_init(&d);
    assert_false(splat_terrain_load(&t, path, SG_HF_R16, 4, 2, LOC, &d));
    assert_one_error(&d, SG_E_RASTER);
    assert_non_null(strstr(d.items[0].msg, "12 bytes"));
    assert_null(t.texels);
    sg_diags_free(&d);
    sg_diags_init(&d);
    assert_false(splat_terrain_load(&t, path, SG_HF_R16, 0, 0, LOC, &d));
    assert_one_error(&d, SG_E_RASTER);
    sg_diags_free(&d);
}

static void test_load_errors(void **state)
{
    splat_terrain t = { 0 };
    sg_diags d;

    /* Missing file. */
    sg_diags_init(&d);
    assert_false(splat_terrain_load(&t, tmp_path("nope.png"), SG_HF_PNG, 0, 0,
                                    LOC, &d));
    assert_one_error(&d, SG_E_IO);
    assert_non_null(strstr(d.items[0].msg, "nope.png"));
    sg_diags_free(&d);

    /* Not an image. */
    const char *junk = tmp_path("junk.png");
    FILE *f = fopen(junk, "wb");
    assert_non_null(f);
    fputs("this is not a PNG file at all", f);
    fclose(f);
    sg_diags_init(&d);
    assert_false(splat_terrain_load(&t, junk, SG_HF_PNG, 0, 0, LOC, &d));
    assert_one_error(&d, SG_E_IO);
    sg_diags_free(&d);

    /* Colour images are not heightfields: 16-bit RGB and 8-bit RGB. */
    uint16_t rgb16[2 * 2 * 3] = { 0 };
    write_png16(tmp_path("rgb16.png"), 2, 2, 3, rgb16);
    sg_diags_init(&d);
    assert_false(splat_terrain_load(&t, tmp_path("rgb16.png"), SG_HF_PNG, 0, 0,
                                    LOC, &d));
    assert_one_error(&d, SG_E_RASTER);
    assert_non_null(strstr(d.items[0].msg, "3 channels"));
    sg_diags_free(&d);
    unsigned char rgb8[2 * 2 * 3] = { 0 };
    assert_true(stbi_write_png(tmp_path("rgb8.png"), 2, 2, 3, rgb8, 6) != 0);
    sg_diags_init(&d);
    assert_false(splat_terrain_load(&t, tmp_path("rgb8.png"), SG_HF_PNG, 0, 0,
                                    LOC, &d));
    assert_one_error(&d, SG_E_RASTER);
    sg_diags_free(&d);
    assert_null(t.texels);
}

/* ---- the CPU twins of the ABI's height and normal ----------------------- */

/* terrain.cavity (splat_cavity's twin): at a texel centre, the mean of the
 * texels 2 away diagonally minus this one, in metres (the offset cancels);
 * a bowl is positive at its bottom, a dome negative at its top, a plane 0. */
static void test_cavity(void **state)
{
    splat_terrain t;
    make_terrain(&t, 9, 9, 90, 90, 200, 1000);
    for (int z = 0; z < 9; z++)
        for (int x = 0; x < 9; x++)
            t.texels[z * 9 + x] = (uint16_t)(1000 * ((x - 4) * (x - 4) + (z - 4) * (z - 4)));
    /* bowl: centre 0, diagonal taps 2 away (8 * 1000 each) */
    double want = 8000.0 / 65535 * 200;
    assert_float_equal(splat_terrain_cavity(&t, 4.5 / 9, 4.5 / 9), want, 1e-9);
    /* off centre, (3, 5): taps (1,3) (5,3) (1,7) (5,7): 9+1, 1+1, 9+9, 1+9 */
    double mean = (10 + 2 + 18 + 10) / 4.0, here = 1 + 1;
    assert_float_equal(splat_terrain_cavity(&t, 3.5 / 9, 5.5 / 9),
                       (mean - here) * 1000 / 65535 * 200, 1e-9);
    /* dome: negative */
    for (int i = 0; i < 81; i++)
        t.texels[i] = (uint16_t)(65535 - t.texels[i]);
    assert_float_equal(splat_terrain_cavity(&t, 4.5 / 9, 4.5 / 9), -want, 1e-9);
    /* a plane: 0 (inside, and at the clamped edge it is not a plane) */
    for (int z = 0; z < 9; z++)
        for (int x = 0; x < 9; x++)
            t.texels[z * 9 + x] = (uint16_t)(3000 * x + 500 * z);
    assert_float_equal(splat_terrain_cavity(&t, 4.5 / 9, 3.5 / 9), 0.0, 1e-9);
    assert_float_equal(splat_terrain_cavity(&t, 4.2 / 9, 3.7 / 9), 0.0, 1e-9);
    splat_terrain_free(&t);
}

/* The mesh's height (splat_height_at): bilinear between texel centres. */
static void test_mesh_height_bilinear_clamped(void **state)
{
    splat_terrain t;
    make_terrain(&t, 4, 2, 40, 20, 100, -10);
    const uint16_t px[8] = { 0, 65535, 13107, 26214,
                             65535, 0, 39321, 52428 };
    memcpy(t.texels, px, sizeof px);
    /* Texel centres: the texel, scaled and offset. */
    assert_float_equal(splat_terrain_mesh_height(&t, 1.5 / 4, 0.5 / 2), 90.0, 1e-9);
    assert_float_equal(splat_terrain_mesh_height(&t, 3.5 / 4, 1.5 / 2), 70.0, 1e-9);
    /* Halfway between texels 2 and 3 of row 0: (20 + 40) / 2 - 10. */
    assert_float_equal(splat_terrain_mesh_height(&t, 3.0 / 4, 0.5 / 2), 20.0, 1e-9);
    /* The middle of four texels 0, 1 (row 0) and 0, 1 (row 1): all 0.5. */
    assert_float_equal(splat_terrain_mesh_height(&t, 1.0 / 4, 1.0 / 2), 40.0, 1e-9);
    /* Clamp to edge: uv 0 and beyond read the corner texel. */
    assert_float_equal(splat_terrain_mesh_height(&t, 0, 0), -10.0, 1e-9);
    assert_float_equal(splat_terrain_mesh_height(&t, -3, -7), -10.0, 1e-9);
    assert_float_equal(splat_terrain_mesh_height(&t, 1, 1), 70.0, 1e-9);
    assert_float_equal(splat_terrain_mesh_height(&t, 1e30, 1e30), 70.0, 1e-9);
    splat_terrain_free(&t);
}

/* The shading height: the uniform cubic B-spline.  By hand: at a texel
 * centre its weights are 1/6, 4/6, 1/6 per axis; halfway between two
 * centres 1/48, 23/48, 23/48, 1/48.  Row z = 1 of a 5 x 3 field varies
 * (0, 0.6, 0.3, 0.9, 0.6); rows 0 and 2 equal it, so z drops out. */
static void test_height_bspline_by_hand(void **state)
{
    splat_terrain t;
    make_terrain(&t, 5, 3, 50, 30, 100, -10);
    const double row[5] = { 0, 0.6, 0.3, 0.9, 0.6 };
    for (int z = 0; z < 3; z++)
        for (int x = 0; x < 5; x++)
            t.texels[z * 5 + x] = (uint16_t)lround(row[x] * 65535);
    double r[5];
    for (int x = 0; x < 5; x++) r[x] = t.texels[5 + x] / 65535.0;
    /* texel 2's centre: (0.6 + 4 * 0.3 + 0.9) / 6 */
    assert_float_equal(splat_terrain_height(&t, 2.5 / 5, 1.5 / 3),
                       (r[1] + 4 * r[2] + r[3]) / 6 * 100 - 10, 1e-9);
    /* between texels 2 and 3 */
    assert_float_equal(splat_terrain_height(&t, 3.0 / 5, 0.5 / 3),
                       (r[1] + 23 * r[2] + 23 * r[3] + r[4]) / 48 * 100 - 10, 1e-9);
    /* clamp to edge: texel 0's centre reads texel 0 twice on its left */
    assert_float_equal(splat_terrain_height(&t, 0.5 / 5, 2.5 / 3),
                       (5 * r[0] + r[1]) / 6 * 100 - 10, 1e-9);
    assert_float_equal(splat_terrain_height(&t, -3, 1e30), r[0] * 100 - 10, 1e-9);
    assert_float_equal(splat_terrain_height(&t, 1e30, -7), r[4] * 100 - 10, 1e-9);

    /* Smooth: the height's slope along x is continuous across the texel
     * boundaries, where a bilinear height's jumps.  Central differences
     * just left and right of the centre of texel 2 (x = 2.5): */
    double e = 1e-4 / 5, u = 2.5 / 5, v = 1.5 / 3;
    double sl = (splat_terrain_height(&t, u, v) - splat_terrain_height(&t, u - e, v)) / e;
    double sr = (splat_terrain_height(&t, u + e, v) - splat_terrain_height(&t, u, v)) / e;
    assert_true(fabs(sl - sr) < 1e-2 * (fabs(sl) + fabs(sr)) + 1e-6);
    double ml = (splat_terrain_mesh_height(&t, u, v) - splat_terrain_mesh_height(&t, u - e, v)) / e;
    double mr = (splat_terrain_mesh_height(&t, u + e, v) - splat_terrain_mesh_height(&t, u, v)) / e;
    assert_true(fabs(ml - mr) > 100);   /* 0.3 -> 0.9 after 0.6 -> 0.3: a kink */
    splat_terrain_free(&t);
}

/* Listing 1 on the B-spline surface, by hand: the B-spline reproduces a
 * plane, so away from the edges the normal of a planar heightfield is the
 * plane's, at any uv.  9 x 9 texels, dx = 90 m / 9 = 10 m, dz = 180 m / 9
 * = 20 m, max height 100 m, h = 0.1 + 0.02 x + 0.05 z (texel units): one
 * texel further along x the height grows 0.02 * 100 = 2 m over 10 m, so
 *   n.x = (h(x-1) - h(x+1)) * 100 / 10 = -0.4,  n.z = -0.1 * 100 / 20 = -0.5. */
static void test_normal_listing1_by_hand(void **state)
{
    splat_terrain t;
    make_terrain(&t, 9, 9, 90, 180, 100, 0);
    /* 65535 * 0.02 and 65535 * 0.05 are not whole, so the 16-bit texels
     * hold steps of 1311 and 3277: the plane is exact in those. */
    for (int z = 0; z < 9; z++)
        for (int x = 0; x < 9; x++)
            t.texels[z * 9 + x] = (uint16_t)(6554 + 1311 * x + 3277 * z);
    double a = -2 * 1311 / 65535.0 * 100 / 10, b = -2 * 3277 / 65535.0 * 100 / 20;
    double len = sqrt(a * a + 4 + b * b);
    for (int k = 0; k < 50; k++) {
        /* taps reach 3 texels either side: x in [3, 5] keeps them inside */
        double x = 3 + 2 * rnd01(), z = 3 + 2 * rnd01(), n[3];
        splat_terrain_normal(&t, (x + 0.5) / 9, (z + 0.5) / 9, n);
        assert_float_equal(n[0], a / len, 1e-12);
        assert_float_equal(n[1], 2 / len, 1e-12);
        assert_float_equal(n[2], b / len, 1e-12);
        double h = (6554 + 1311 * x + 3277 * z) / 65535.0 * 100;
        assert_float_equal(splat_terrain_height(&t, (x + 0.5) / 9, (z + 0.5) / 9), h, 1e-9);
    }

    /* The ABI's C helper is Listing 1's formula. */
    double m[3], k3 = 1 / sqrt(3.0);
    splat_normal_filter(0.6, 0.4, 0.6, 0.2, 100, 10, 20, m);
    for (int c = 0; c < 3; c++) assert_float_equal(m[c], k3, 1e-12);

    /* Flat terrain: straight up. */
    for (int i = 0; i < 81; i++) t.texels[i] = 777;
    double n[3];
    splat_terrain_normal(&t, 0.37, 0.81, n);
    assert_true(n[0] == 0 && n[1] == 1 && n[2] == 0);
    splat_terrain_free(&t);
}

/* The slope is smooth across texel boundaries: one raised texel makes a
 * bump whose slope, sampled densely along a line through it, never jumps
 * between neighbouring samples by more than a smooth function's step
 * would (the bilinear cross filter's slope has kinks there, not jumps, so
 * the check is on the second difference: bounded for the B-spline). */
static void test_slope_smooth(void **state)
{
    splat_terrain t;
    make_terrain(&t, 16, 16, 160, 160, 10, 0);
    for (int i = 0; i < 256; i++) t.texels[i] = 20000;
    t.texels[8 * 16 + 8] = 40000;
    const int N = 4000;
    double prev[2] = { 0, 0 }, worst = 0;
    for (int k = 0; k < N; k++) {
        double x = 5 + 7.0 * k / N, n[3];
        splat_terrain_normal(&t, x / 16, 8.3 / 16, n);
        double s = 1 - n[1];
        if (k >= 2) {
            double d2 = fabs(s - 2 * prev[1] + prev[0]) * (N / 7.0) * (N / 7.0);
            worst = fmax(worst, d2);
        }
        prev[0] = prev[1];
        prev[1] = s;
    }
    /* A C1 slope has a bounded second difference (about 0.05 here); a
     * kinked one's grows with N (about N / 7 * the kink, hundreds). */
    assert_true(worst < 1.0);
    splat_terrain_free(&t);
}

/* ---- ranges ------------------------------------------------------------- */

static bool in(ir_iv r, double v) { return v >= r.lo && v <= r.hi; }

static void random_terrain(splat_terrain *t, int w, int h, double sx, double sz,
                           double maxh, double off, int roughness)
{
    make_terrain(t, w, h, sx, sz, maxh, off);
    for (int z = 0; z < h; z++)
        for (int x = 0; x < w; x++) {
            double base = 20000 + 15000 * sin(x * 0.3) * cos(z * 0.2);
            double v = base + (double)(rnd() % (unsigned)(2 * roughness + 1)) - roughness;
            if (x > w / 2 && x < w / 2 + 2) v += 30000;     /* a cliff */
            t->texels[z * w + x] = (uint16_t)(v < 0 ? 0 : v > 65535 ? 65535 : v);
        }
}

/* Every sample point in the rectangle (its closed uv extent) lies inside
 * the bounds; and the bounds are not vacuous. */
static void check_ranges(const splat_terrain *t, int x0, int z0, int x1, int z1,
                         int samples)
{
    ir_ienv e;
    memset(&e, 0, sizeof e);
    splat_terrain_ranges(t, x0, z0, x1, z1, &e);
    double hmin = INFINITY, hmax = -INFINITY;
    for (int s = 0; s < samples; s++) {
        double fu = rnd01(), fv = rnd01();
        if (s % 7 == 0) fu = s % 2;           /* the rectangle's edges too */
        if (s % 11 == 0) fv = (s / 2) % 2;
        double u = (x0 + fu * (x1 - x0)) / t->width;
        double v = (z0 + fv * (z1 - z0)) / t->height;
        double h = splat_terrain_height(t, u, v), n[3];
        splat_terrain_normal(t, u, v, n);
        assert_true(in(e.height, h));
        assert_true(in(e.position[1], h));
        for (int c = 0; c < 3; c++) assert_true(in(e.normal[c], n[c]));
        assert_true(in(e.slope, 1 - n[1]));
        assert_true(in(e.uv[0], u) && in(e.uv[1], v));
        assert_true(in(e.position[0], u * t->size[0]));
        assert_true(in(e.position[2], v * t->size[1]));
        hmin = fmin(hmin, h);
        hmax = fmax(hmax, h);
    }
    /* Not vacuous: the height bounds are those of the footprint texels. */
    int lo = 65535, hi = 0;
    for (int z = z0 - 2; z <= z1 + 1; z++)
        for (int x = x0 - 2; x <= x1 + 1; x++) {
            int v = (int)lround(splat_terrain_texel(t, x, z) * 65535);
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
    double slack = 1e-3 * fabs(t->max_height) + 1e-3 * fabs(t->height_offset) + 1e-9;
    assert_true(e.height.lo >= lo / 65535.0 * t->max_height + t->height_offset - slack);
    assert_true(e.height.hi <= hi / 65535.0 * t->max_height + t->height_offset + slack);
    assert_true(e.slope.lo >= -1e-5 && e.slope.hi <= 1 + 1e-5);
    assert_true(e.view_distance.lo == 0 && isinf(e.view_distance.hi));
    assert_true(e.destruction.lo == 0 && e.destruction.hi == 0);
}

static void test_ranges_sound_random(void **state)
{
    splat_terrain t;
    random_terrain(&t, 67, 41, 670, 820, 400, -50, 3000);
    for (int iter = 0; iter < 300; iter++) {
        int x0 = (int)(rnd() % 67), z0 = (int)(rnd() % 41);
        int x1 = x0 + 1 + (int)(rnd() % 9), z1 = z0 + 1 + (int)(rnd() % 9);
        if (x1 > 67) x1 = 67;
        if (z1 > 41) z1 = 41;
        check_ranges(&t, x0, z0, x1, z1, 200);
    }
    /* The corners and whole terrain. */
    check_ranges(&t, 0, 0, 1, 1, 500);
    check_ranges(&t, 66, 40, 67, 41, 500);
    check_ranges(&t, 0, 0, 67, 41, 2000);
    splat_terrain_free(&t);
}

static void test_ranges_flat_and_tight(void **state)
{
    splat_terrain t;
    make_terrain(&t, 16, 16, 160, 160, 200, 5);
    for (int i = 0; i < 256; i++) t.texels[i] = 32768;
    ir_ienv e;
    splat_terrain_ranges(&t, 4, 4, 8, 8, &e);
    double h = 32768 / 65535.0 * 200 + 5;
    assert_float_equal(e.height.lo, h, 1e-3);
    assert_float_equal(e.height.hi, h, 1e-3);
    /* Flat: slope 0 and straight up, up to the GPU-error margins (one
     * 16-bit step of gradient: 20 m per unit / 2 -> 1.5e-4 in n.x). */
    assert_true(e.slope.lo <= 0 && e.slope.hi >= 0 && e.slope.hi < 1e-5);
    assert_true(e.normal[1].lo > 0.9999 && e.normal[1].hi >= 1);
    assert_true(e.normal[0].lo > -2e-4 && e.normal[0].hi < 2e-4);
    assert_true(e.normal[2].lo > -2e-4 && e.normal[2].hi < 2e-4);

    /* A single steep texel just outside the rectangle's two-texel ring does
     * not widen it; one inside the ring does (the B-spline's footprint). */
    t.texels[4 * 16 + 10] = 65535;                 /* x = 10: three away */
    splat_terrain_ranges(&t, 4, 4, 8, 8, &e);
    assert_true(e.height.hi < h + 1e-3);
    t.texels[4 * 16 + 9] = 65535;                  /* x = 9: the ring */
    splat_terrain_ranges(&t, 4, 4, 8, 8, &e);
    assert_true(e.height.hi >= 205 - 1e-9);
    assert_true(e.slope.hi > 0.1);
    splat_terrain_free(&t);
}

/* A model of the GPU (abi.c splat_terrain_at): the texel coordinate, the
 * B-spline's weights and every sum in float, the fraction nudged by a few
 * ulps either way (mode) as a different rounding order would.  The ranges
 * must still hold. */
static void gpu_smooth(const splat_terrain *t, float u, float v, int mode, double *hgt,
                       double n[3])
{
    float x = u * (float)t->width - 0.5f, z = v * (float)t->height - 0.5f;
    x = fminf(fmaxf(x, -1.0f), (float)t->width);
    z = fminf(fmaxf(z, -1.0f), (float)t->height);
    float ix = floorf(x), iz = floorf(z), f[2] = { x - ix, z - iz }, w[2][4];
    for (int a = 0; a < 2; a++) {
        float q = f[a];
        if (mode & (1 << a)) q = nextafterf(nextafterf(q, 2.0f), 2.0f);
        if (mode & (4 << a)) q = nextafterf(nextafterf(q, -1.0f), -1.0f);
        q = fminf(fmaxf(q, 0.0f), 1.0f);
        float s = 1.0f - q, q2 = q * q, q3 = q2 * q;
        w[a][0] = s * s * s * (1.0f / 6.0f);
        w[a][1] = (3.0f * q3 - 6.0f * q2 + 4.0f) * (1.0f / 6.0f);
        w[a][2] = (-3.0f * q3 + 3.0f * q2 + 3.0f * q + 1.0f) * (1.0f / 6.0f);
        w[a][3] = q3 * (1.0f / 6.0f);
    }
#define TX(i, j) ((float)splat_terrain_texel(t, (int)ix + (i), (int)iz + (j)))
    float h = 0, ga = 0, gb = 0;
    for (int j = 0; j < 4; j++) {
        float rh = 0, ra = 0, rb = 0;
        for (int i = 0; i < 4; i++) {
            rh += w[0][i] * TX(i - 1, j - 1);
            ra += w[0][i] * (TX(i - 2, j - 1) - TX(i, j - 1));
            rb += w[0][i] * (TX(i - 1, j - 2) - TX(i - 1, j));
        }
        h += w[1][j] * rh;
        ga += w[1][j] * ra;
        gb += w[1][j] * rb;
    }
#undef TX
    *hgt = (float)(h * (float)t->max_height + (float)t->height_offset);
    float dx = (float)t->size[0] / t->width, dz = (float)t->size[1] / t->height;
    float m[3] = { ga * (float)t->max_height / dx, 2.0f, gb * (float)t->max_height / dz };
    float len = sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    for (int c = 0; c < 3; c++) n[c] = m[c] / len;
}

static void test_ranges_sound_gpu_model(void **state)
{
    splat_terrain t;
    /* Uniformly random texels and gentle gradients (2 m over 1-2 m texels)
     * keep the normal sensitive to every error of the taps. */
    make_terrain(&t, 33, 33, 33, 66, 2, 0);
    for (int i = 0; i < 33 * 33; i++) t.texels[i] = (uint16_t)rnd();
    for (int iter = 0; iter < 400; iter++) {
        int x0 = (int)(rnd() % 30), z0 = (int)(rnd() % 30);
        int x1 = x0 + 1 + (int)(rnd() % 2), z1 = z0 + 1 + (int)(rnd() % 2);
        ir_ienv e;
        splat_terrain_ranges(&t, x0, z0, x1, z1, &e);
        for (int s = 0; s < 300; s++) {
            double fu = x0 + rnd01() * (x1 - x0), fv = z0 + rnd01() * (z1 - z0);
            if (s % 2) {    /* near texel centres, where the taps change */
                fu = floor(fu) + 0.5 + (rnd01() - 0.5) * 0.01;
                fv = floor(fv) + 0.5 + (rnd01() - 0.5) * 0.01;
            }
            double h, n[3];
            gpu_smooth(&t, (float)(fu / 33), (float)(fv / 33), (int)(rnd() % 16), &h, n);
            for (int c = 0; c < 3; c++) assert_true(in(e.normal[c], n[c]));
            assert_true(in(e.slope, 1 - n[1]));
            assert_true(in(e.height, h));
        }
    }
    /* A flat area stays flat in float: slope within the margin of 0. */
    for (int i = 0; i < 33 * 33; i++) t.texels[i] = 40000;
    ir_ienv e;
    splat_terrain_ranges(&t, 10, 10, 12, 12, &e);
    for (int s = 0; s < 1000; s++) {
        double h, n[3];
        gpu_smooth(&t, (float)((10 + 2 * rnd01()) / 33), (float)((10 + 2 * rnd01()) / 33),
                   (int)(rnd() % 16), &h, n);
        assert_true(in(e.slope, 1 - n[1]) && in(e.height, h));
    }
    splat_terrain_free(&t);
}

/* Cells the destructible area reaches: any slope the filter can give,
 * heights down to the offset. */
static void test_any_shape(void **state)
{
    splat_terrain t;
    make_terrain(&t, 8, 8, 8, 8, 10, 100);           /* 1 m texels */
    for (int i = 0; i < 64; i++) t.texels[i] = 40000;
    ir_ienv e;
    splat_terrain_ranges(&t, 0, 0, 8, 8, &e);
    assert_true(e.slope.hi < 1e-4);
    splat_terrain_any_shape(&t, &e);
    assert_true(e.height.lo <= 100 && e.height.lo > 99.99);
    assert_true(e.position[1].lo == e.height.lo);
    /* The steepest cliff: 0 next to 65535 on both axes' taps. */
    double n[3];
    splat_normal_filter(1, 0, 1, 0, 10, 1, 1, n);
    assert_true(in(e.slope, 1 - n[1]) && in(e.normal[0], n[0]) && in(e.normal[2], n[2]));
    splat_normal_filter(0, 1, 0, 1, 10, 1, 1, n);
    assert_true(in(e.normal[0], n[0]) && in(e.normal[2], n[2]));
    assert_true(in(e.slope, 0.0));
    splat_terrain_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_load_png16),
        cmocka_unit_test(test_load_png8_scales_by_257),
        cmocka_unit_test(test_load_raw_r16),
        cmocka_unit_test(test_load_errors),
        cmocka_unit_test(test_mesh_height_bilinear_clamped),
        cmocka_unit_test(test_height_bspline_by_hand),
        cmocka_unit_test(test_cavity),
        cmocka_unit_test(test_normal_listing1_by_hand),
        cmocka_unit_test(test_slope_smooth),
        cmocka_unit_test(test_ranges_sound_random),
        cmocka_unit_test(test_ranges_flat_and_tight),
        cmocka_unit_test(test_ranges_sound_gpu_model),
        cmocka_unit_test(test_any_shape),
    };
    return cmocka_run_group_tests(tests, make_tmpdir, remove_tmpdir);
}
