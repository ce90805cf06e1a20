/* image.c — pictures out of the renderer: an 8-bit PNG after a simple tone
 * map and sRGB encode on the CPU, and the raw RGBA32F image (format in
 * splatrt.h) for exact comparisons. */
#include "rt_internal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>

static float srgb_encode(float c)
{
    c = c < 0.0f ? 0.0f : c > 1.0f ? 1.0f : c;
    return c <= 0.0031308f ? 12.92f * c : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

void rt_tonemap_rgba8(const float *rgba, int w, int h, rt_tonemap tm,
                      uint8_t *out)
{
    size_t n = (size_t)w * (size_t)h;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 4; c++) {
            float v = rgba[i * 4 + c];
            if (!(v == v))          /* NaN shows as black, never as garbage */
                v = 0.0f;
            if (c < 3) {
                if (tm == RT_TONEMAP_FILMIC) {
                    /* exposure, then Narkowicz's fit of the ACES curve */
                    v = v < 0.0f ? 0.0f : v * 0.8f;
                    v = srgb_encode(v * (2.51f * v + 0.03f) / (v * (2.43f * v + 0.59f) + 0.14f));
                } else if (tm == RT_TONEMAP_SRGB) {
                    v = srgb_encode(v);
                }
            }
            v = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
            out[i * 4 + c] = (uint8_t)lrintf(v * 255.0f);
        }
    }
}

bool rt_write_png(const char *path, const uint8_t *rgba8, int w, int h,
                  rt_error *e)
{
    if (!stbi_write_png(path, w, h, 4, rgba8, w * 4))
        return rt_fail(e, RT_E_IO, "write", path, "stbi_write_png failed");
    return true;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

bool rt_write_float(const char *path, const float *rgba, int w, int h,
                    rt_error *e)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return rt_fail(e, RT_E_IO, "write", path, strerror(errno));
    uint8_t head[16];
    memcpy(head, "SPLATF32", 8);
    put_u32(head + 8, (uint32_t)w);
    put_u32(head + 12, (uint32_t)h);
    size_t n = (size_t)w * (size_t)h * 4;
    bool ok = fwrite(head, 1, 16, f) == 16 && fwrite(rgba, sizeof(float), n, f) == n;
    ok = (fclose(f) == 0) && ok;
    if (!ok)
        return rt_fail(e, RT_E_IO, "write", path, "short write");
    return true;
}

bool rt_read_float(const char *path, float **rgba, int *w, int *h, rt_error *e)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return rt_fail(e, RT_E_IO, "read", path, strerror(errno));
    uint8_t head[16];
    if (fread(head, 1, 16, f) != 16 || memcmp(head, "SPLATF32", 8)) {
        fclose(f);
        return rt_fail(e, RT_E_IO, "read", path, "not a SPLATF32 float image");
    }
    uint32_t W = get_u32(head + 8), H = get_u32(head + 12);
    if (W == 0 || H == 0 || W > 65536 || H > 65536) {
        fclose(f);
        return rt_fail(e, RT_E_IO, "read", path, "bad image size");
    }
    size_t n = (size_t)W * H * 4;
    *rgba = malloc(n * sizeof(float));
    if (!*rgba || fread(*rgba, sizeof(float), n, f) != n) {
        free(*rgba);
        *rgba = NULL;
        fclose(f);
        return rt_fail(e, RT_E_IO, "read", path, "truncated");
    }
    fclose(f);
    *w = (int)W;
    *h = (int)H;
    return true;
}
