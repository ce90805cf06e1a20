/* far_atlas.h — the far atlas (Moore 2018's far shading from the terrain's
 * albedo / normal payload; Andersson's cached procedural textures): each
 * terrain texel's composited albedo, normal and roughness baked once at
 * build time (`splatc build --far-atlas`), so that far terrain is shaded
 * by three texture reads instead of the composite (runtime/screen.c).
 *
 * File `far.atlas` (compiler/PACK.md), little-endian:
 *   "SPLATFAR", u32 version 1, width, height, levels (level 0 texels; each
 *   level halves, rounding down, to 1), f64 texel size x, z (metres of
 *   level 0), then per level l: BC1 albedo (sRGB), BC5 normal (x, z as
 *   unorm, y = sqrt(1 - x^2 - z^2)), BC4 roughness blocks, ceil(w_l / 4) *
 *   ceil(h_l / 4) blocks each, row-major. */
#ifndef SPLAT_FAR_ATLAS_H
#define SPLAT_FAR_ATLAS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "splatc.h"

#define FAR_ATLAS_MAGIC      "SPLATFAR"
#define FAR_ATLAS_VERSION    1u
#define FAR_ATLAS_HEADER     40           /* bytes before the level data   */
#define FAR_ATLAS_MAX_SIDE   16384        /* one image (SPLAT_MAX_TEXTURE) */
/* The bake's view convention: view.distance reads this (metres), the
 * view straight down (view.direction (0, 1, 0)). */
#define FAR_ATLAS_BAKE_DISTANCE 2000.0

/* splat_far_bake (where it is baked) and splat_far_bake_parse: splatc.h. */

/* Points per texel side: each texel is the mean of FAR_ATLAS_SS^2 points
 * spread over it (a box filter of the composite over the texel). */
#define FAR_ATLAS_SS 2

/* One texel row of w texels from its FAR_ATLAS_SS rows of w *
 * FAR_ATLAS_SS points, 8 floats each (albedo rgb, unit normal, roughness,
 * 1 where the point was shaded, 0 over a hole): the mean albedo and
 * roughness and the renormalised mean normal of the shaded points (a
 * texel of none: albedo 0, normal up, roughness 1).  Both bakes. */
void far_atlas_reduce(const float *points, int w, float *albedo, float *normal, float *rough);

static inline int far_atlas_levels_max(uint32_t w, uint32_t h)
{
    int n = 1;
    while ((w >> n) > 0 || (h >> n) > 0)
        n++;
    return n;
}

/* Bytes of level l's three block arrays (0 when w or h is 0). */
static inline uint64_t far_atlas_level_bytes(uint32_t w, uint32_t h, int l)
{
    uint64_t lw = w >> l ? w >> l : 1, lh = h >> l ? h >> l : 1;
    return ((lw + 3) / 4) * ((lh + 3) / 4) * (8 + 16 + 8);
}

/* The whole file's size for a header saying w x h with `levels`. */
static inline uint64_t far_atlas_file_bytes(uint32_t w, uint32_t h, int levels)
{
    uint64_t n = FAR_ATLAS_HEADER;
    for (int l = 0; l < levels; l++)
        n += far_atlas_level_bytes(w, h, l);
    return n;
}

#endif
