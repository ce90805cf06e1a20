/* gen_terrain.c — the rasters of the billingsley example (Billingsley 2009),
 * deterministic (no clock, no rand()):
 *
 *   billingsley_gen_terrain OUTDIR
 *
 * heightfield.png  513 x 513, 16-bit: Musgrave's "large-scale model for
 *     terrain" multifractal with Billingsley's parameters (§2.1): octaves 8,
 *     spectral exponent H 0.75, lacunarity 2, offset 1.5, threshold 0.9.
 *     The model is Musgrave's hybrid multifractal (Texturing & Modeling):
 *         result = (n(p) + offset) * f0^-H;  weight = result
 *         for octave i >= 1:  weight = min(weight, threshold)
 *                             signal = (n(p * L^i) + offset) * fi^-H
 *                             result += weight * signal;  weight *= signal
 *     Our reading of "threshold" is that weight clamp (Musgrave's code
 *     clamps at 1.0).  n is 2D gradient noise (texgen_gradient) scaled to
 *     about [-1, 1] like the GPU improved noise he used; p = xz / 1500 m.
 *     The result is normalised over the map to the full 16-bit range
 *     (scene: max_height 300 m over 4104 m x 4104 m, 8 m texels).
 * mapping.png  64 x 64 RGB: the material-mapping lookup (his Fig. 4):
 *     x = incline (length of the normal's xz, 0 flat .. 1 vertical),
 *     y = elevation parameter 1 - (height - water) * 0.005 (1 at the water
 *     line, 0 at 200 m above it).  R = sand weight, G = grass, B = rock
 *     (dirt has weight 0): sand on low flat ground near the water, rock on
 *     steep or high ground, grass between.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "texgen.h"

enum { N = 513, MAP = 64 };
static const double SPACING = 8.0;      /* metres per texel           */
static const double FEATURE = 1500.0;   /* metres per noise cell      */

static double noise(double x, double y)
{
    /* a period far beyond the map: plain (non-tiling) noise */
    return 1.41 * texgen_gradient(x, y, 1 << 20, 1 << 20, 2009);
}

static double multifractal(double x, double y)
{
    const int octaves = 8;
    const double H = 0.75, lacunarity = 2.0, offset = 1.5, threshold = 0.9;
    double freq = 1.0;
    double result = (noise(x, y) + offset) * pow(freq, -H);
    double weight = result;
    for (int i = 1; i < octaves; i++) {
        x *= lacunarity;
        y *= lacunarity;
        freq *= lacunarity;
        if (weight > threshold)
            weight = threshold;
        double signal = (noise(x, y) + offset) * pow(freq, -H);
        result += weight * signal;
        weight *= signal;
    }
    return result;
}

static double smooth(double e0, double e1, double x)
{
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUTDIR\n", argv[0]);
        return 2;
    }
    double *h = malloc(sizeof(double) * N * N);
    uint16_t *t = malloc(sizeof(uint16_t) * N * N);
    texgen_image map;
    if (!h || !t || !texgen_image_alloc(&map, MAP, MAP, 3)) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    double mn = INFINITY, mx = -INFINITY;
    for (int z = 0; z < N; z++)
        for (int x = 0; x < N; x++) {
            double v = multifractal((x + 0.5) * SPACING / FEATURE, (z + 0.5) * SPACING / FEATURE);
            h[z * N + x] = v;
            mn = v < mn ? v : mn;
            mx = v > mx ? v : mx;
        }
    for (int i = 0; i < N * N; i++)
        t[i] = (uint16_t)floor((h[i] - mn) / (mx - mn) * 65535.0 + 0.5);

    for (int j = 0; j < MAP; j++)
        for (int i = 0; i < MAP; i++) {
            double incline = (i + 0.5) / MAP, elev = (j + 0.5) / MAP;
            double rock = fmin(1.0, smooth(0.30, 0.50, incline) + smooth(0.30, 0.05, elev));
            double sand = smooth(0.78, 0.92, elev) * (1 - smooth(0.15, 0.35, incline));
            double grass = (1 - rock) * (1 - sand) * smooth(0.95, 0.75, elev + 0.1 * incline);
            double w[3] = {sand, grass, rock};
            for (int c = 0; c < 3; c++)
                map.pixels[(j * MAP + i) * 3 + c] = (uint8_t)floor(w[c] * 255.0 + 0.5);
        }

    char path[4096], *err = NULL;
    int status = 0;
    snprintf(path, sizeof path, "%s/heightfield.png", argv[1]);
    if (!texgen_write_png16(path, N, N, t, &err))
        status = 1;
    snprintf(path, sizeof path, "%s/mapping.png", argv[1]);
    if (!status && !texgen_write_png(path, &map, &err))
        status = 1;
    if (status) {
        fprintf(stderr, "%s\n", err ? err : "write failed");
        free(err);
    } else {
        printf("%s/heightfield.png %dx%d (multifractal range %.4f .. %.4f)\n", argv[1], N, N, mn, mx);
        printf("%s/mapping.png %dx%d\n", argv[1], MAP, MAP);
    }
    free(h);
    free(t);
    texgen_image_free(&map);
    return status;
}
