/* gen_fixtures.c — the small rasters the scene tests load (deterministic).
 *
 *   scene_gen_fixtures OUTDIR
 *
 * writes hf16.png (16 x 16, 16-bit grey: a ramp east with a 1-texel cliff at
 * x = 8), hf.r16 (the same texels, raw little-endian), hf_rgb.png (16 x 16
 * 8-bit RGB: not a heightfield), mask.png (16 x 16 8-bit grey: the west half
 * painted) and mask8x8.png (8 x 8: the wrong size for the heightfield),
 * and hf_truncated.png, mask_truncated.png: hf16.png and mask.png cut 30
 * bytes short (a valid header, the image data cut off).
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <stb_image_write.h>

#include "texgen.h"

enum { N = 16 };

/* OUTDIR/to = OUTDIR/from without its last `drop` bytes. */
static int truncated_copy(const char *dir, const char *from, const char *to, long drop)
{
    char path[4096];
    unsigned char buf[1 << 16];
    snprintf(path, sizeof path, "%s/%s", dir, from);
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
    if (f)
        fclose(f);
    if ((long)n <= drop) {
        fprintf(stderr, "%s: cannot read\n", path);
        return 0;
    }
    snprintf(path, sizeof path, "%s/%s", dir, to);
    f = fopen(path, "wb");
    if (!f || fwrite(buf, 1, n - (size_t)drop, f) != n - (size_t)drop || fclose(f) != 0) {
        fprintf(stderr, "%s: cannot write\n", path);
        return 0;
    }
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUTDIR\n", argv[0]);
        return 2;
    }
    uint16_t hf[N * N];
    uint8_t raw[N * N * 2], rgb[N * N * 3], mask[N * N], small[8 * 8];
    for (int z = 0; z < N; z++)
        for (int x = 0; x < N; x++) {
            int v = x * 1000 + z * 10 + (x >= 8 ? 30000 : 0);
            hf[z * N + x] = (uint16_t)v;
            raw[2 * (z * N + x)] = (uint8_t)(v & 255);
            raw[2 * (z * N + x) + 1] = (uint8_t)(v >> 8);
            mask[z * N + x] = x < 8 ? 255 : 0;
            for (int c = 0; c < 3; c++) rgb[(z * N + x) * 3 + c] = (uint8_t)(x * 16 + c);
        }
    memset(small, 128, sizeof small);
    char path[4096], *err = NULL;
    snprintf(path, sizeof path, "%s/hf16.png", argv[1]);
    if (!texgen_write_png16(path, N, N, hf, &err)) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    snprintf(path, sizeof path, "%s/hf.r16", argv[1]);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(raw, 1, sizeof raw, f) != sizeof raw || fclose(f) != 0) {
        fprintf(stderr, "%s: cannot write\n", path);
        return 1;
    }
    struct { const char *name; int w, h, comp; const void *px; } out[] = {
        { "hf_rgb.png", N, N, 3, rgb },
        { "mask.png", N, N, 1, mask },
        { "mask8x8.png", 8, 8, 1, small },
    };
    for (size_t i = 0; i < sizeof out / sizeof out[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", argv[1], out[i].name);
        if (!stbi_write_png(path, out[i].w, out[i].h, out[i].comp, out[i].px,
                            out[i].w * out[i].comp)) {
            fprintf(stderr, "%s: cannot write\n", path);
            return 1;
        }
    }
    const char *cut[][2] = { { "hf16.png", "hf_truncated.png" },
                             { "mask.png", "mask_truncated.png" } };
    for (int i = 0; i < 2; i++)
        if (!truncated_copy(argv[1], cut[i][0], cut[i][1], 30))
            return 1;
    return 0;
}
