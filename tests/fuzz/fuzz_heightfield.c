/* fuzz_heightfield.c — libFuzzer target for the compiler's raster loaders:
 * the first byte picks the loader, the rest is the file (written to a
 * temporary file, as the loaders read paths):
 *   0  splat_terrain_load, PNG heightfield
 *   1  splat_terrain_load, raw R16 of W x H (next bytes: u16 W, u16 H)
 *   2  sparse_load_raster, 8-bit painted mask of W x H (same)
 *   3  splat_terrain_load through GDAL (the file named .tif: GeoTIFF, or
 *      whatever GDAL's drivers recognise in the bytes) */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene.h"
#include "sparse.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char path[64], tif[64];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    if (!path[0]) {
        snprintf(path, sizeof path, "/tmp/splat-fuzz-hf-%d", (int)getpid());
        snprintf(tif, sizeof tif, "/tmp/splat-fuzz-hf-%d.tif", (int)getpid());
    }
    int mode = data[0] % 4, w = 0, h = 0;
    data++, size--;
    if (mode == 1 || mode == 2) {
        if (size < 4)
            return 0;
        w = data[0] | data[1] << 8;
        h = data[2] | data[3] << 8;
        data += 4, size -= 4;
    }
    const char *file = mode == 3 ? tif : path;
    FILE *f = fopen(file, "wb");
    if (!f)
        return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    sg_diags d;
    sg_diags_init(&d);
    sg_loc loc = { .file = "fuzz.sg", .line = 1, .col = 1 };
    if (mode != 2) {
        static const int formats[4] = { SG_HF_PNG, SG_HF_R16, 0, SG_HF_GDAL };
        splat_terrain t = { .size = { 100, 100 }, .max_height = 10 };
        if (splat_terrain_load(&t, file, formats[mode], w, h, loc, &d)) {
            volatile double v = splat_terrain_height(&t, 0.5, 0.25);
            (void)v;
            splat_terrain_free(&t);
        }
    } else {
        uint8_t *texels = NULL;
        sparse_error err;
        if (sparse_load_raster(path, w, h, &texels, &err))
            free(texels);
    }
    sg_diags_free(&d);
    return 0;
}
