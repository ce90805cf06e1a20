/* test_texgen.c — the texture generator: determinism, tileability, the
 * nearest-neighbour mips of the uniform noise (Billingsley 2009 §2.2), histograms,
 * PNG round trips (8 and 16 bit), and the committed example textures in
 * graphs/textures/ being exactly what the generator makes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image.h>

#include "texgen.h"

static int example(const char *name)
{
    for (int i = 0; i < texgen_example_count(); i++)
        if (!strcmp(texgen_example_name(i), name))
            return i;
    fail_msg("no example texture '%s'", name);
    return -1;
}

static uint8_t px(const texgen_image *img, int x, int y, int c)
{
    return img->pixels[((size_t)y * img->width + x) * img->channels + c];
}

static void test_deterministic(void **state)
{
    for (int i = 0; i < texgen_example_count(); i++) {
        texgen_image a, b, c;
        assert_true(texgen_example_image(i, 64, 7, &a));
        assert_true(texgen_example_image(i, 64, 7, &b));
        assert_true(texgen_example_image(i, 64, 8, &c));
        size_t n = (size_t)a.width * a.height * a.channels;
        assert_int_equal(a.width, 64);
        assert_memory_equal(a.pixels, b.pixels, n);
        /* another seed gives another texture */
        assert_true(memcmp(a.pixels, c.pixels, n) != 0);
        texgen_image_free(&a);
        texgen_image_free(&b);
        texgen_image_free(&c);
    }
}

static void test_field_periodic(void **state)
{
    /* Shifting by a whole period gives the same value (up to rounding of
     * the fractional part). */
    for (int k = 0; k < 200; k++) {
        double x = k * 0.173, y = k * 0.311;
        double a = texgen_gradient(x, y, 8, 4, 3);
        assert_true(fabs(a - texgen_gradient(x + 8, y, 8, 4, 3)) < 1e-12);
        assert_true(fabs(a - texgen_gradient(x, y - 4, 8, 4, 3)) < 1e-12);
        assert_true(fabs(a) <= 0.75);
        double f = texgen_fbm(x, y, 4, 4, 5, 0.5, 9);
        assert_true(fabs(f - texgen_fbm(x + 4, y + 8, 4, 4, 5, 0.5, 9)) < 1e-12);
        double w[2], v[2];
        texgen_worley(x, y, 6, 5, w);
        texgen_worley(x - 6, y + 12, 6, 5, v);
        assert_true(fabs(w[0] - v[0]) < 1e-12 && fabs(w[1] - v[1]) < 1e-12);
        assert_true(w[0] <= w[1]);
    }
    /* seeds give independent fields */
    assert_true(fabs(texgen_gradient(0.3, 0.6, 8, 8, 1) - texgen_gradient(0.3, 0.6, 8, 8, 2)) > 1e-6);
}

/* Mean absolute step between horizontally (or vertically) adjacent texels,
 * over the interior, and across the wrap-around edge. */
static void edge_steps(const texgen_image *img, bool vertical, double *inner, double *edge)
{
    int w = img->width, h = img->height;
    double si = 0, se = 0;
    long ni = 0, ne = 0;
    for (int c = 0; c < img->channels; c++)
        for (int a = 0; a < (vertical ? w : h); a++)
            for (int b = 0; b < (vertical ? h : w); b++) {
                int x0 = vertical ? a : b, y0 = vertical ? b : a;
                int x1 = vertical ? a : (b + 1) % w, y1 = vertical ? (b + 1) % h : a;
                double d = fabs((double)px(img, x0, y0, c) - px(img, x1, y1, c));
                if (b == (vertical ? h : w) - 1) {
                    se += d;
                    ne++;
                } else {
                    si += d;
                    ni++;
                }
            }
    *inner = si / ni;
    *edge = se / ne;
}

static void test_tileable(void **state)
{
    const char *names[] = {"noise", "perlin", "rock", "grass", "dirt", "sand",
                           "snow", "gravel", "leaves", "rock_normal"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        texgen_image img;
        assert_true(texgen_example_image(example(names[k]), 128, 1, &img));
        for (int vertical = 0; vertical < 2; vertical++) {
            double inner, edge;
            edge_steps(&img, vertical, &inner, &edge);
            /* across the seam the texture continues like anywhere else */
            if (edge > inner * 1.6 + 0.5)
                fail_msg("%s: seam step %.2f vs interior %.2f (%s)", names[k], edge,
                         inner, vertical ? "vertical" : "horizontal");
        }
        texgen_image_free(&img);
    }
    /* The check can fail: a non-periodic field shows a seam. */
    texgen_image img;
    assert_true(texgen_image_alloc(&img, 64, 64, 1));
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++)
            img.pixels[y * 64 + x] = (uint8_t)(x * 4);
    double inner, edge;
    edge_steps(&img, false, &inner, &edge);
    assert_true(edge > inner * 1.6 + 0.5);
    texgen_image_free(&img);
}

static double stddev(const texgen_image *img)
{
    size_t n = (size_t)img->width * img->height * img->channels;
    double s = 0, s2 = 0;
    for (size_t i = 0; i < n; i++) {
        s += img->pixels[i];
        s2 += (double)img->pixels[i] * img->pixels[i];
    }
    double m = s / n;
    return sqrt(s2 / n - m * m);
}

static void test_uniform_nearest_mips(void **state)
{
    int u = example("uniform");
    assert_int_equal(texgen_example_reduce(u), TEXGEN_REDUCE_NEAREST);
    texgen_image lvl;
    assert_true(texgen_example_image(u, 64, 3, &lvl));
    double sd0 = stddev(&lvl);
    int levels = texgen_mip_levels(64, 64);
    assert_int_equal(levels, 7);
    for (int k = 1; k < levels; k++) {
        texgen_image next;
        assert_true(texgen_mip(&lvl, &next, TEXGEN_REDUCE_NEAREST));
        assert_int_equal(next.width, lvl.width / 2);
        /* every texel is one of the 2x2 texels above it */
        for (int y = 0; y < next.height; y++)
            for (int x = 0; x < next.width; x++) {
                uint8_t v = px(&next, x, y, 0);
                bool found = false;
                for (int dy = 0; dy < 2; dy++)
                    for (int dx = 0; dx < 2; dx++)
                        found |= px(&lvl, 2 * x + dx, 2 * y + dy, 0) == v;
                assert_true(found);
            }
        if (k == 1) {
            /* the contrast survives (box filtering would halve it) */
            assert_true(stddev(&next) > 0.85 * sd0);
            texgen_image box;
            assert_true(texgen_mip(&lvl, &box, TEXGEN_REDUCE_BOX));
            assert_true(stddev(&box) < 0.65 * sd0);
            texgen_image_free(&box);
        }
        texgen_image_free(&lvl);
        lvl = next;
    }
    assert_int_equal(lvl.width, 1);
    assert_int_equal(lvl.height, 1);
    texgen_image_free(&lvl);
}

static void test_box_mip_values(void **state)
{
    texgen_image a, b;
    assert_true(texgen_image_alloc(&a, 3, 2, 1));
    uint8_t v[6] = {0, 10, 200, 255, 11, 100};
    memcpy(a.pixels, v, 6);
    assert_true(texgen_mip(&a, &b, TEXGEN_REDUCE_BOX));
    assert_int_equal(b.width, 1);
    assert_int_equal(b.height, 1);
    assert_int_equal(b.pixels[0], (0 + 10 + 255 + 11 + 2) / 4);
    texgen_image_free(&b);
    assert_true(texgen_mip(&a, &b, TEXGEN_REDUCE_NEAREST));
    assert_int_equal(b.pixels[0], 0);
    texgen_image_free(&b);
    texgen_image_free(&a);
}

static void test_histograms(void **state)
{
    /* white noise: 16 bins, each within 15 % of the expectation */
    texgen_image img;
    assert_true(texgen_example_image(example("uniform"), 256, 1, &img));
    long bins[16] = {0};
    for (int i = 0; i < 256 * 256; i++)
        bins[img.pixels[i] >> 4]++;
    for (int b = 0; b < 16; b++)
        assert_true(labs(bins[b] - 4096) < 615);
    texgen_image_free(&img);

    /* noise and details use the whole range, centred, with many levels */
    const char *names[] = {"noise", "perlin", "rock", "grass", "dirt", "sand", "gravel", "leaves"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        assert_true(texgen_example_image(example(names[k]), 128, 1, &img));
        for (int c = 0; c < img.channels; c++) {
            int mn = 255, mx = 0, distinct = 0;
            long hist[256] = {0};
            double mean = 0;
            for (int i = 0; i < 128 * 128; i++) {
                int v = img.pixels[i * img.channels + c];
                hist[v]++;
                mn = v < mn ? v : mn;
                mx = v > mx ? v : mx;
                mean += v;
            }
            for (int v = 0; v < 256; v++)
                distinct += hist[v] > 0;
            mean /= 128 * 128 * 255.0;
            assert_int_equal(mn, 0);
            assert_int_equal(mx, 255);
            assert_true(distinct > 150);
            if (mean < 0.2 || mean > 0.8)
                fail_msg("%s channel %d: mean %.3f", names[k], c, mean);
        }
        texgen_image_free(&img);
    }
}

static void test_png_roundtrip(void **state)
{
    char dir[] = "/tmp/test_texgen_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256];

    texgen_image img;
    assert_true(texgen_example_image(example("perlin"), 32, 5, &img));
    snprintf(path, sizeof path, "%s/p.png", dir);
    char *err = NULL;
    assert_true(texgen_write_png(path, &img, &err));
    int w, h, n;
    unsigned char *back = stbi_load(path, &w, &h, &n, 0);
    assert_non_null(back);
    assert_int_equal(w, 32);
    assert_int_equal(n, 4);
    assert_memory_equal(back, img.pixels, 32 * 32 * 4);
    stbi_image_free(back);
    unlink(path);
    texgen_image_free(&img);

    /* 16-bit: our own writer, read back by stb_image */
    uint16_t t[7 * 5];
    for (int i = 0; i < 35; i++)
        t[i] = (uint16_t)(i * 1871u + (i % 3) * 40000u);
    snprintf(path, sizeof path, "%s/h.png", dir);
    assert_true(texgen_write_png16(path, 7, 5, t, &err));
    uint16_t *b16 = stbi_load_16(path, &w, &h, &n, 0);
    assert_non_null(b16);
    assert_int_equal(w, 7);
    assert_int_equal(h, 5);
    assert_int_equal(n, 1);
    assert_memory_equal(b16, t, sizeof t);
    stbi_image_free(b16);
    unlink(path);

    /* mip files of a chain */
    assert_true(texgen_example_image(example("uniform"), 8, 5, &img));
    assert_true(texgen_write_chain(dir, "u", &img, TEXGEN_REDUCE_NEAREST, true, &err));
    for (int k = 0; k < 4; k++) {
        snprintf(path, sizeof path, k ? "%s/u.mip%d.png" : "%s/u.png", dir, k);
        back = stbi_load(path, &w, &h, &n, 0);
        assert_non_null(back);
        assert_int_equal(w, 8 >> k);
        if (k == 1)
            assert_int_equal(back[0], img.pixels[0]);
        stbi_image_free(back);
        unlink(path);
    }
    snprintf(path, sizeof path, "%s/u.mip4.png", dir);
    assert_int_equal(access(path, F_OK), -1);
    texgen_image_free(&img);

    /* an unwritable path is an error, not a crash */
    assert_false(texgen_write_png("/nonexistent-dir/x.png", &img, &err));
    assert_non_null(err);
    free(err);
    rmdir(dir);
}

/* The textures the example graphs use are committed; they must be exactly
 * what `splatc texgen --out graphs/textures` (seed 1, size 256) writes. */
static void test_committed_textures(void **state)
{
    for (int i = 0; i < texgen_example_count(); i++) {
        char path[256];
        snprintf(path, sizeof path, "graphs/textures/%s.png", texgen_example_name(i));
        int w, h, n;
        unsigned char *file = stbi_load(path, &w, &h, &n, 0);
        if (!file)
            fail_msg("%s missing: run splatc texgen --out graphs/textures", path);
        texgen_image img;
        assert_true(texgen_example_image(i, 256, 1, &img));
        assert_int_equal(w, img.width);
        assert_int_equal(n, img.channels);
        if (memcmp(file, img.pixels, (size_t)w * h * n))
            fail_msg("%s differs from the generator: rerun splatc texgen", path);
        stbi_image_free(file);
        texgen_image_free(&img);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_field_periodic),
        cmocka_unit_test(test_tileable),
        cmocka_unit_test(test_uniform_nearest_mips),
        cmocka_unit_test(test_box_mip_values),
        cmocka_unit_test(test_histograms),
        cmocka_unit_test(test_png_roundtrip),
        cmocka_unit_test(test_committed_textures),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
