/* test_texgen_surfaces.c — the colour PBR surface sets (texgen_surfaces.c):
 * the albedo is colour and its mean linear albedo lies in the surface's
 * measured range; normals are unit length and agree with the height's
 * slopes; the sets are deterministic and tile; the committed files in
 * graphs/textures/surfaces/ are exactly what the generator makes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

#include "texgen.h"

enum { SIZE = 128 };

static texgen_surface_set sets[64];

static int setup(void **state)
{
    (void)state;
    for (int i = 0; i < texgen_surface_count(); i++)
        if (!texgen_surface_make(i, SIZE, 1, &sets[i]))
            return -1;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    for (int i = 0; i < texgen_surface_count(); i++)
        texgen_surface_free(&sets[i]);
    return 0;
}

static void test_names(void **state)
{
    static const char *const want[] = {"grass", "dry_grass", "dirt", "mud", "sand", "gravel",
                                       "rock", "cliff_rock", "snow", "moss", "forest_floor",
                                       "asphalt"};
    assert_true(texgen_surface_count() >= 12);
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++) {
        bool found = false;
        for (int i = 0; i < texgen_surface_count(); i++)
            found |= !strcmp(texgen_surface_name(i), want[k]);
        if (!found)
            fail_msg("no surface '%s'", want[k]);
    }
    texgen_surface_set bad;
    assert_false(texgen_surface_make(0, 100, 1, &bad));   /* not a power of two */
    assert_false(texgen_surface_make(texgen_surface_count(), 64, 1, &bad));
}

/* Mean chroma (max - min of the sRGB channels, 0..255). */
static double mean_chroma(const texgen_image *img)
{
    double s = 0;
    size_t n = (size_t)img->width * img->height;
    for (size_t p = 0; p < n; p++) {
        const uint8_t *q = img->pixels + p * img->channels;
        int mx = q[0], mn = q[0];
        for (int c = 1; c < 3; c++) {
            mx = q[c] > mx ? q[c] : mx;
            mn = q[c] < mn ? q[c] : mn;
        }
        s += mx - mn;
    }
    return s / n;
}

static void test_albedo_colour_and_range(void **state)
{
    for (int i = 0; i < texgen_surface_count(); i++) {
        const texgen_image *a = &sets[i].albedo;
        assert_int_equal(a->channels, 4);
        /* its alpha is the height */
        for (int p = 0; p < SIZE * SIZE; p++)
            assert_int_equal(a->pixels[4 * p + 3], sets[i].height.pixels[p]);
        double chroma = mean_chroma(a);
        if (chroma < 3.0)
            fail_msg("%s: albedo is grey (mean chroma %.2f / 255)", texgen_surface_name(i), chroma);
        double lo, hi, m = texgen_mean_albedo(a);
        texgen_surface_albedo_range(i, &lo, &hi);
        assert_true(lo > 0 && hi > lo && hi <= 1);
        if (m < lo || m > hi)
            fail_msg("%s: mean linear albedo %.3f outside [%.2f, %.2f]", texgen_surface_name(i), m, lo, hi);
        /* the texture has detail: not a flat colour */
        double s = 0, s2 = 0;
        size_t n = (size_t)a->width * a->height;
        for (size_t p = 0; p < n; p++) {
            double g = a->pixels[4 * p + 1];
            s += g;
            s2 += g * g;
        }
        double sd = sqrt(s2 / n - (s / n) * (s / n));
        if (sd < 4)
            fail_msg("%s: albedo nearly flat (sd %.2f)", texgen_surface_name(i), sd);
    }
    /* the checks can fail: a grey image has no chroma, and the mean
     * albedo is computed in linear (sRGB 128 is 0.216, not 0.5) */
    texgen_image grey;
    assert_true(texgen_image_alloc(&grey, 4, 4, 3));
    memset(grey.pixels, 128, 48);
    assert_true(mean_chroma(&grey) == 0);
    assert_true(fabs(texgen_mean_albedo(&grey) - 0.2158605) < 1e-4);
    texgen_image_free(&grey);
}

static double hpx(const texgen_image *h, int x, int y)
{
    x = (x + h->width) % h->width;
    y = (y + h->height) % h->height;
    return h->pixels[(size_t)y * h->width + x] / 255.0;
}

static void test_normals(void **state)
{
    for (int i = 0; i < texgen_surface_count(); i++) {
        const texgen_image *nm = &sets[i].normal, *h = &sets[i].height;
        long agree = 0, total = 0;
        for (int y = 0; y < SIZE; y++)
            for (int x = 0; x < SIZE; x++) {
                const uint8_t *q = nm->pixels + ((size_t)y * SIZE + x) * 3;
                double n[3] = {q[0] / 127.5 - 1, q[1] / 127.5 - 1, q[2] / 127.5 - 1};
                double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                if (fabs(len - 1) > 0.02)
                    fail_msg("%s: normal at (%d, %d) has length %.3f", texgen_surface_name(i), x, y, len);
                assert_true(n[2] > 0);                       /* +z out of the surface */
                /* uphill towards +x means the normal leans to -x */
                double dx = hpx(h, x + 1, y) - hpx(h, x - 1, y);
                double dy = hpx(h, x, y + 1) - hpx(h, x, y - 1);
                if (fabs(dx) > 0.06) {
                    total++;
                    agree += (dx > 0) == (n[0] < 0);
                }
                if (fabs(dy) > 0.06) {
                    total++;
                    agree += (dy > 0) == (n[1] < 0);
                }
            }
        if (total < 100 || agree < 0.97 * total)
            fail_msg("%s: normal agrees with the height slope at %ld of %ld texels",
                     texgen_surface_name(i), agree, total);
        /* the AO is darker in hollows: mean height where AO is low is below
         * the mean height where it is high */
        const texgen_image *ao = &sets[i].ao;
        double lo_h = 0, hi_h = 0;
        long lo_n = 0, hi_n = 0;
        for (int p = 0; p < SIZE * SIZE; p++) {
            if (ao->pixels[p] < 235) {
                lo_h += h->pixels[p];
                lo_n++;
            } else {
                hi_h += h->pixels[p];
                hi_n++;
            }
        }
        if (lo_n > 50 && hi_n > 50 && lo_h / lo_n >= hi_h / hi_n)
            fail_msg("%s: AO not darker in the hollows", texgen_surface_name(i));
    }
}

static void test_deterministic(void **state)
{
    for (int i = 0; i < texgen_surface_count(); i++) {
        texgen_surface_set b, c;
        assert_true(texgen_surface_make(i, SIZE, 1, &b));
        assert_true(texgen_surface_make(i, SIZE, 2, &c));
        const texgen_image *x[5] = {&sets[i].albedo, &sets[i].normal, &sets[i].height,
                                    &sets[i].roughness, &sets[i].ao};
        const texgen_image *y[5] = {&b.albedo, &b.normal, &b.height, &b.roughness, &b.ao};
        for (int k = 0; k < 5; k++)
            assert_memory_equal(x[k]->pixels, y[k]->pixels,
                                (size_t)SIZE * SIZE * x[k]->channels);
        assert_true(memcmp(sets[i].albedo.pixels, c.albedo.pixels, (size_t)SIZE * SIZE * 4) != 0);
        texgen_surface_free(&b);
        texgen_surface_free(&c);
    }
}

/* Mean absolute step between neighbouring columns (or rows) b and b + 1,
 * per b: the last one is across the wrap.  *inner is the largest of the
 * others, *edge the one across the wrap. */
static void steps(const texgen_image *img, bool vertical, double *inner, double *edge)
{
    int w = img->width, h = img->height, ch = img->channels;
    int nb = vertical ? h : w, na = vertical ? w : h;
    *inner = 0;
    for (int b = 0; b < nb; b++) {
        double s = 0;
        for (int a = 0; a < na; a++) {
            int x0 = vertical ? a : b, y0 = vertical ? b : a;
            int x1 = vertical ? a : (b + 1) % w, y1 = vertical ? (b + 1) % h : a;
            for (int c = 0; c < ch; c++)
                s += fabs((double)img->pixels[((size_t)y0 * w + x0) * ch + c] -
                          img->pixels[((size_t)y1 * w + x1) * ch + c]);
        }
        s /= (double)na * ch;
        if (b == nb - 1)
            *edge = s;
        else if (s > *inner)
            *inner = s;
    }
}

static void test_tileable(void **state)
{
    for (int i = 0; i < texgen_surface_count(); i++) {
        const texgen_image *x[5] = {&sets[i].albedo, &sets[i].normal, &sets[i].height,
                                    &sets[i].roughness, &sets[i].ao};
        for (int k = 0; k < 5; k++)
            for (int vertical = 0; vertical < 2; vertical++) {
                double inner, edge;
                steps(x[k], vertical, &inner, &edge);
                /* across the seam the texture steps like between any
                 * other two columns (rows) */
                if (edge > inner * 1.1 + 0.5)
                    fail_msg("%s image %d: seam step %.2f vs interior at most %.2f", texgen_surface_name(i),
                             k, edge, inner);
            }
    }
    assert_string_equal(texgen_surface_name(4), "sand");
    /* the check can fail: three quarters of the sand height, stretched
     * to the full width, does not continue across the wrap */
    texgen_image cut;
    assert_true(texgen_image_alloc(&cut, SIZE, SIZE, 1));
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            cut.pixels[y * SIZE + x] = sets[4].height.pixels[y * SIZE + x * 3 / 4];
    double inner, edge;
    steps(&cut, false, &inner, &edge);
    assert_true(edge > inner * 1.1 + 0.5);
    texgen_image_free(&cut);
}

/* graphs/textures/surfaces/ holds `splatc texgen --out graphs/textures`
 * (seed 1, surface size 256) output, byte for byte in its pixels. */
static void test_committed(void **state)
{
    static const char *const what[5] = {"albedo", "normal", "height", "roughness", "ao"};
    for (int i = 0; i < texgen_surface_count(); i++) {
        texgen_surface_set s;
        assert_true(texgen_surface_make(i, 256, 1, &s));
        const texgen_image *x[5] = {&s.albedo, &s.normal, &s.height, &s.roughness, &s.ao};
        for (int k = 0; k < 5; k++) {
            char path[256];
            snprintf(path, sizeof path, "graphs/textures/surfaces/%s_%s.png",
                     texgen_surface_name(i), what[k]);
            int w, h, n;
            unsigned char *file = stbi_load(path, &w, &h, &n, 0);
            if (!file)
                fail_msg("%s missing: run splatc texgen --out graphs/textures", path);
            assert_int_equal(w, 256);
            assert_int_equal(n, x[k]->channels);
            if (memcmp(file, x[k]->pixels, (size_t)w * h * n))
                fail_msg("%s differs from the generator: rerun splatc texgen", path);
            stbi_image_free(file);
        }
        texgen_surface_free(&s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_albedo_colour_and_range),
        cmocka_unit_test(test_normals),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_tileable),
        cmocka_unit_test(test_committed),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
