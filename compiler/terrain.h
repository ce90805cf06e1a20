/* terrain.h — the heightfield on the CPU and the terrain inputs' ranges
 * per cell (terrain.c), rasters read through libgdal (raster.c).
 */
#ifndef SPLAT_TERRAIN_H
#define SPLAT_TERRAIN_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "abi.h"
#include "ir.h"
#include "sg.h"

/* ---- terrain.c: heightfield and terrain parameters --------------------- */

typedef struct splat_terrain {
    int       width, height;   /* texels                                   */
    uint16_t *texels;          /* row-major, row 0 = z 0                   */
    double    size[2];         /* world metres, x and z                    */
    double    max_height;      /* metres for normalised height 1           */
    double    height_offset;   /* metres added to every height             */
    /* 1 where the terrain is cut (GDAL nodata, the scene's holes mask), or
     * NULL when it has no holes; hole texels hold heights filled in from
     * their neighbours (splat_terrain_fill_holes), so every filter and
     * bound that reads them sees plausible heights. */
    uint8_t  *holes;
    double    origin[2];       /* a GDAL raster's corner in its CRS units
                                  (east, north); 0 0 for PNG and raw       */
} splat_terrain;

/* Every raster loader (PNG, raw, GDAL; heightfields and masks) checks its
 * size against the pack limit (abi.h SPLAT_MAX_HEIGHTFIELD a side) here,
 * before allocating. */
bool splat_raster_check_size(const char *what, const char *path, long long w,
                             long long h, sg_loc loc, sg_diags *d);

/* An image's header, read from an open file (left at its start): what
 * stb_image says, or, for a PNG whose header stb_image refuses (a size it
 * will not decode, such as 100000 x 100000), the IHDR's own width and
 * height with *comp = 0, so the caller's limit check still sees the real
 * size.  False when the file is no image stb_image reads. */
bool splat_image_info(FILE *f, long long *w, long long *h, int *comp, bool *is16);
/* A PNG raster opened as an untrusted input (util.h splat_input_fopen),
 * its header read (splat_image_info) and its size checked
 * (splat_raster_check_size, `what` names it); the file at its start, or
 * NULL with the error at loc. */
FILE *splat_png_open(const char *what, const char *path, int *w, int *h, int *comp,
                     bool *is16, sg_loc loc, sg_diags *d);

/* Load 16-bit PNG, 8-bit PNG (scaled to 16 bits) or raw little-endian R16
 * (width and height given).  Errors at `loc`. */
bool splat_terrain_load(splat_terrain *t, const char *path, sg_hf_format fmt,
                        int raw_width, int raw_height, sg_loc loc, sg_diags *d);
void splat_terrain_free(splat_terrain *t);
/* Give every hole texel the mean of its already known 4-neighbours,
 * breadth first from the valid texels (deterministic, O(texels)).  False
 * only when out of memory. */
bool splat_terrain_fill_holes(splat_terrain *t);
/* 1 if texel (x, z) is a hole (clamped to the edges), else 0. */
int  splat_terrain_hole(const splat_terrain *t, int x, int z);

/* ---- raster.c: rasters through libgdal --------------------------------- */

/* Any raster GDAL reads (band 1): width, height, texels, size (unless
 * `size_given`: then t->size is kept), origin, max_height and
 * height_offset from the file, nodata as t->holes (not yet filled).
 * Conversions are reported as notes at `loc`. */
bool splat_raster_heightfield(splat_terrain *t, const char *path, bool size_given,
                              sg_loc loc, sg_diags *d);
/* A raster's size in texels, checked against the pack limit, without
 * reading its data; false with the error at loc. */
bool splat_raster_size(const char *what, const char *path, int *w, int *h,
                       sg_loc loc, sg_diags *d);
/* An 8-bit mask (band 1) of any size, malloc'd; `what` names it in
 * errors ("painted mask 'road'").  NULL on error. */
uint8_t *splat_raster_mask(const char *what, const char *path, int *w, int *h,
                           sg_loc loc, sg_diags *d);

/* Normalised height (0..1) of texel (x, z), clamped to the edges. */
double splat_terrain_texel(const splat_terrain *t, int x, int z);
/* The CPU twins of the ABI's shading inputs (abi.c splat_terrain_at,
 * splat_height_smooth_at, splat_normal_at): the uniform cubic B-spline
 * over the texels (clamp to edge) at heightfield uv, and Listing 1's cross
 * filter on it.  splat_terrain_mesh_height: the mesh's bilinear height
 * (splat_height_at), which the geometry and its depth use. */
double splat_terrain_height(const splat_terrain *t, double u, double v);
void   splat_terrain_normal(const splat_terrain *t, double u, double v, double n[3]);
double splat_terrain_mesh_height(const splat_terrain *t, double u, double v);
/* ... and of splat_cavity (terrain.cavity): the mean of the 4 diagonal
 * taps 2 texels away minus the height at (u, v), in metres. */
double splat_terrain_cavity(const splat_terrain *t, double u, double v);

/* Sound ranges of the terrain inputs over a rectangle of texels
 * [x0, x1) x [z0, z1): every fragment whose uv falls in that rectangle
 * has its height, slope, normal and position inside the returned bounds
 * (widened for the GPU's filtering and float error: terrain.c).  Inputs
 * the heightfield does not bound get their domain (IR_INPUTS:
 * view_distance [0, inf]), except destruction: [0, 0]; the analysis makes
 * it [0, 1] where the destructible area reaches.  Leaves params and
 * painted alone. */
void splat_terrain_ranges(const splat_terrain *t, int x0, int z0, int x1, int z1,
                          ir_ienv *out);
/* Widen `env` (from splat_terrain_ranges) for an area whose heights change
 * at run time (craters only lower texels, down to 0): normal and slope to
 * every value the filter can give on this terrain, height down to the
 * offset.  Used for cells the destructible area reaches. */
void splat_terrain_any_shape(const splat_terrain *t, ir_ienv *env);

#endif
