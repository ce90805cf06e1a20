/* gen_heightfield.c — the rasters of the minimal example (deterministic: no
 * clock, no rand(); the same program always writes the same bytes).
 *
 *   minimal_gen_heightfield OUTDIR
 *
 * writes
 *   heightfield.png  257 x 257 16-bit greyscale: rolling hills (a few sine
 *                    octaves and a hashed value noise) and a curved cliff,
 *                    about 60 m high, running north-south across the east;
 *   fields.png       257 x 257 8-bit greyscale painted mask: three fields
 *                    with soft 3-texel edges on the western lowland.
 * The scene (scene.sg) spans 1024 x 1024 m with max_height = 160 m.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

#include "texgen.h"

enum { N = 257 };

/* Height in metres (0 .. 160) at texel (x, z). */
static double height_at(int x, int z)
{
    double u = x / (double)(N - 1), v = z / (double)(N - 1);
    double h = 40 + 18 * sin(u * 5.1 + 0.3) * cos(v * 4.3 - 0.2)
                  + 9 * sin(u * 11.7 + v * 7.9)
                  + 16 * texgen_value_noise(x, z, 32) + 6 * texgen_value_noise(x, z, 9);
    /* The cliff: a curved line x = 170 + 20 sin(...) texels; the east side
     * is 60 m higher, reached over about two texels. */
    double edge = 170 + 20 * sin(v * 3.0);
    double t = (x - edge) / 2.0;
    h += 60 / (1 + exp(-4 * t));
    /* Lowland to the west: flatten for the fields. */
    if (u < 0.45) h = 30 + (h - 30) * (0.25 + 0.75 * u / 0.45);
    return fmin(fmax(h, 0), 160);
}

/* Soft rectangle: 1 inside, falling to 0 over `soft` texels outside. */
static double field(int x, int z, int x0, int z0, int x1, int z1, double soft)
{
    double dx = fmax(fmax(x0 - x, x - x1), 0), dz = fmax(fmax(z0 - z, z - z1), 0);
    double d = sqrt(dx * dx + dz * dz);
    return d >= soft ? 0 : 1 - d / soft;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUTDIR\n", argv[0]);
        return 2;
    }
    uint16_t *hf = malloc(sizeof *hf * N * N);
    uint8_t *mask = malloc(N * N);
    if (!hf || !mask) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    for (int z = 0; z < N; z++)
        for (int x = 0; x < N; x++) {
            hf[z * N + x] = (uint16_t)lround(height_at(x, z) / 160.0 * 65535.0);
            double m = fmax(fmax(field(x, z, 20, 30, 60, 80, 3),
                                 field(x, z, 75, 40, 100, 110, 3)),
                            field(x, z, 25, 150, 90, 190, 3));
            mask[z * N + x] = (uint8_t)lround(m * 255);
        }
    char path[4096], *err = NULL;
    snprintf(path, sizeof path, "%s/heightfield.png", argv[1]);
    if (!texgen_write_png16(path, N, N, hf, &err)) {
        fprintf(stderr, "%s\n", err);
        free(err);
        return 1;
    }
    snprintf(path, sizeof path, "%s/fields.png", argv[1]);
    if (!stbi_write_png(path, N, N, 1, mask, N)) {
        fprintf(stderr, "%s: cannot write\n", path);
        return 1;
    }
    printf("wrote %s/heightfield.png and %s/fields.png\n", argv[1], argv[1]);
    free(hf);
    free(mask);
    return 0;
}
