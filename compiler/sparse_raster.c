/* sparse_raster.c — the sparse masks' ground floor: their error messages
 * (SPARSE_ERRORS), 8-bit rasters sampled bilinearly at texel centres,
 * reduction to coarser levels (rounded block means), the 16 x 16 slots
 * cut from a raster, and a place's cell grid. */
#include "sparse_internal.h"
#include "ir.h"
#include "util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include <stb_image.h>

const char SPLAT_GLSL_SPARSE[] = SPARSE_GLSL_FUNCTIONS;


static const char *const error_formats[SPARSE_E_COUNT] = {
#define X(id, fmt) fmt,
    SPARSE_ERRORS(X)
#undef X
};

bool sparse_fail(sparse_error *err, sparse_error_id id, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, id);
        err->id = id;
        vsnprintf(err->msg, sizeof err->msg, error_formats[id], ap);
        va_end(ap);
    }
    return false;
}

int sparse_clampi(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* ---- rasters and bilinear sampling ------------------------------------- */


int sparse_texel(const raster *r, int x, int z)
{
    return r->t[(size_t)sparse_clampi(z, 0, r->h - 1) * (size_t)r->w + (size_t)sparse_clampi(x, 0, r->w - 1)];
}

/* Bilinear with clamp to edge at raster position (x, z), in texel units
 * where texel i has its centre at i + 0.5. */
double sparse_bilinear(const raster *r, double x, double z)
{
    double px = x - 0.5, pz = z - 0.5;
    double fx = floor(px), fz = floor(pz);
    int ix = (int)fx, iz = (int)fz;
    double ax = px - fx, az = pz - fz;
    double a = sparse_texel(r, ix, iz), b = sparse_texel(r, ix + 1, iz);
    double c = sparse_texel(r, ix, iz + 1), d = sparse_texel(r, ix + 1, iz + 1);
    double top = a + (b - a) * ax, bot = c + (d - c) * ax;
    return (top + (bot - top) * az) / 255.0;
}

double sparse_raster_bilinear(const uint8_t *texels, int width, int height,
                              double u, double v)
{
    raster r = { width, height, texels };
    return sparse_bilinear(&r, u * width, v * height);
}

/* D_L: each texel the rounded mean of the in-range texels of its
 * 2^L x 2^L block of the original. */
uint8_t *sparse_reduce(const raster *src, int level, raster *out)
{
    int s = 1 << level;
    int w = (src->w + s - 1) / s, h = (src->h + s - 1) / s;
    uint8_t *t = xcalloc((size_t)w * h, 1);
    for (int z = 0; z < h; z++)
        for (int x = 0; x < w; x++) {
            unsigned sum = 0, n = 0;
            for (int zz = z * s; zz < (z + 1) * s && zz < src->h; zz++)
                for (int xx = x * s; xx < (x + 1) * s && xx < src->w; xx++) {
                    sum += src->t[(size_t)zz * src->w + xx];
                    n++;
                }
            t[(size_t)z * w + x] = (uint8_t)((sum + n / 2) / n);
        }
    *out = (raster){ w, h, t };
    return t;
}

/* The 36 x 36 slot of block (bx, bz) of raster r: slot-local texel j in
 * -2..33 reads block texel clamp(j, -1, 32), clamped to the raster. */
void sparse_make_slot(const raster *r, int bx, int bz, uint8_t *slot)
{
    size_t col[SPARSE_SLOT];   /* each slot column's raster column, clamped */
    for (int i = 0; i < SPARSE_SLOT; i++)
        col[i] = (size_t)sparse_clampi(SPARSE_TILE * bx +
                                       sparse_clampi(i - SPARSE_PAD, -1, SPARSE_TILE),
                                       0, r->w - 1);
    for (int j = 0; j < SPARSE_SLOT; j++) {
        int z = SPARSE_TILE * bz + sparse_clampi(j - SPARSE_PAD, -1, SPARSE_TILE);
        const uint8_t *row = r->t + (size_t)sparse_clampi(z, 0, r->h - 1) * (size_t)r->w;
        for (int i = 0; i < SPARSE_SLOT; i++)
            slot[j * SPARSE_SLOT + i] = row[col[i]];
    }
}

/* 0 or 255 if every texel of the slot has that value, else -1. */
int sparse_slot_constant(const uint8_t *slot)
{
    int v = slot[0];
    if (v != 0 && v != 255)
        return -1;
    for (int i = 1; i < SLOT_TEXELS; i++)
        if (slot[i] != v)
            return -1;
    return v;
}



/* A place's cells from its raster; the grid grown to hold them. */
void sparse_place_cells(sparse_place *p, int *grid_x, int *grid_z)
{
    p->cells_x = (p->width + SPARSE_TILE - 1) / SPARSE_TILE;
    p->cells_z = (p->height + SPARSE_TILE - 1) / SPARSE_TILE;
    *grid_x = p->cells_x > *grid_x ? p->cells_x : *grid_x;
    *grid_z = p->cells_z > *grid_z ? p->cells_z : *grid_z;
}
