/* sparse_internal.h — the sparse masks' internals, shared by their files
 * (the interface is sparse.h):
 *
 *   sparse_raster.c  errors, 8-bit rasters, bilinear sampling, reduction
 *                    and slots
 *   sparse_query.c   reading the atlas: samples, ranges and bounds, the
 *                    GLSL places table
 *   sparse.c         the build: levels, the slot store, the atlas layout
 *   sparse_file.c    the pack file (.sparse) and rasters from files
 */
#ifndef SPLAT_SPARSE_INTERNAL_H
#define SPLAT_SPARSE_INTERNAL_H

#include "sparse.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum { SLOT_TEXELS = SPARSE_SLOT * SPARSE_SLOT };

/* An 8-bit raster: w x h texels, row-major. */
typedef struct raster {
    int w, h;
    const uint8_t *t;
} raster;

/* ---- sparse_raster.c ----------------------------------------------------- */

/* Fill *err (if any) with error `id` and its format's arguments; false. */
bool sparse_fail(sparse_error *err, sparse_error_id id, ...);
int sparse_clampi(int v, int lo, int hi);
int sparse_texel(const raster *r, int x, int z);
double sparse_bilinear(const raster *r, double x, double z);
uint8_t *sparse_reduce(const raster *src, int level, raster *out);
void sparse_make_slot(const raster *r, int bx, int bz, uint8_t *slot);
int sparse_slot_constant(const uint8_t *slot);
void sparse_place_cells(sparse_place *p, int *grid_x, int *grid_z);

/* ---- sparse_query.c ------------------------------------------------------ */

size_t sparse_cell_at(const sparse_masks *s, int mask, int cx, int cz);
void sparse_slot_origin(const sparse_masks *s, int slot, int *ox, int *oz);
void sparse_compute_bounds(sparse_masks *s, const sparse_desc *d);

#endif
