/* bench_tools.c — splatbench's file tools: upscale (a heightfield or mask
 * K times larger), analytic-hf (the analytic heightfield as raw R16) and
 * compare (the error between two --float-out images). */
#include "bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

/* ---- upscale ---------------------------------------------------------------- */

int bench_upscale(int argc, char **argv)
{
    if (argc != 5 || atoi(argv[3]) < 1) {
        fprintf(stderr, "usage: splatbench upscale IN.png K OUT\n");
        return 2;
    }
    const char *in = argv[2], *outp = argv[4];
    int k = atoi(argv[3]), w, h, ch;
    bool sixteen = stbi_is_16_bit(in);
    void *px = sixteen ? (void *)stbi_load_16(in, &w, &h, &ch, 1) : (void *)stbi_load(in, &w, &h, &ch, 1);
    if (!px) {
        fprintf(stderr, "splatbench: cannot read '%s': %s\n", in, stbi_failure_reason());
        return 1;
    }
    /* texel centres stay aligned: output texel i samples input (i + 0.5)/k - 0.5 */
    size_t W = (size_t)w * (size_t)k, H = (size_t)h * (size_t)k;
    int status = 0;
    if (sixteen) {
        const uint16_t *s = px;
        uint16_t *o = xcalloc(W * H, 2);
        for (size_t j = 0; j < H; j++) {
            double v = fmin(fmax((j + 0.5) / k - 0.5, 0), h - 1);
            int j0 = (int)v, j1 = j0 + 1 < h ? j0 + 1 : j0;
            double fv = v - j0;
            for (size_t i = 0; i < W; i++) {
                double u = fmin(fmax((i + 0.5) / k - 0.5, 0), w - 1);
                int i0 = (int)u, i1 = i0 + 1 < w ? i0 + 1 : i0;
                double fu = u - i0;
                double a = s[(size_t)j0 * w + i0] * (1 - fu) + s[(size_t)j0 * w + i1] * fu;
                double b = s[(size_t)j1 * w + i0] * (1 - fu) + s[(size_t)j1 * w + i1] * fu;
                o[j * W + i] = (uint16_t)lround(a * (1 - fv) + b * fv);   /* little-endian host */
            }
        }
        FILE *f = fopen(outp, "wb");
        if (!f || fwrite(o, 2, W * H, f) != W * H) {
            fprintf(stderr, "splatbench: cannot write '%s'\n", outp);
            status = 1;
        }
        if (f)
            fclose(f);
        free(o);
    } else {
        const uint8_t *s = px;
        uint8_t *o = xcalloc(W * H, 1);
        for (size_t j = 0; j < H; j++)
            for (size_t i = 0; i < W; i++)
                o[j * W + i] = s[(j / (size_t)k) * (size_t)w + i / (size_t)k];
        stbi_write_png_compression_level = 1;
        if (!stbi_write_png(outp, (int)W, (int)H, 1, o, (int)W)) {
            fprintf(stderr, "splatbench: cannot write '%s'\n", outp);
            status = 1;
        }
        free(o);
    }
    stbi_image_free(px);
    printf("%s: %zu x %zu\n", outp, W, H);
    return status;
}

/* ---- analytic-hf ----------------------------------------------------------- */

int bench_analytic_hf(int argc, char **argv)
{
    int w = argc == 5 ? atoi(argv[2]) : 0, h = argc == 5 ? atoi(argv[3]) : 0;
    if (w < 1 || h < 1) {
        fprintf(stderr, "usage: splatbench analytic-hf W H OUT.r16\n");
        return 2;
    }
    FILE *f = fopen(argv[4], "wb");
    if (!f) {
        fprintf(stderr, "splatbench: cannot write '%s'\n", argv[4]);
        return 1;
    }
    bool ok = true;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            long q = lround(analytic_height((i + 0.5) / w, (j + 0.5) / h) * 65535.0);
            uint8_t b[2] = {(uint8_t)(q & 255), (uint8_t)(q >> 8)};
            ok = ok && fwrite(b, 1, 2, f) == 2;
        }
    if (fclose(f) != 0 || !ok) {
        fprintf(stderr, "splatbench: cannot write '%s'\n", argv[4]);
        return 1;
    }
    return 0;
}

/* ---- compare ------------------------------------------------------------------ */

int bench_compare(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: splatbench compare A.f32 B.f32\n");
        return 2;
    }
    float *a = NULL, *b = NULL;
    int wa, ha, wb, hb;
    rt_error e = {0};
    int status = 1;
    if (!rt_read_float(argv[2], &a, &wa, &ha, &e) || !rt_read_float(argv[3], &b, &wb, &hb, &e))
        goto done;
    if (wa != wb || ha != hb) {
        fprintf(stderr, "splatbench: images differ in size (%dx%d, %dx%d)\n", wa, ha, wb, hb);
        goto done;
    }
    err_acc acc = {0};
    err_add(&acc, a, b, (size_t)wa * (size_t)ha);
    printf("max_abs %.6g mean_abs %.6g psnr_db %.2f nonfinite %ld\n", acc.max_abs,
           acc.n ? acc.sum_abs / (double)acc.n : 0.0, err_psnr(&acc), acc.nonfinite);
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    free(a);
    free(b);
    return status;
}
