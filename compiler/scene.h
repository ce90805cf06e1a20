/* scene.h — scenes: the heightfield and rasters on the CPU, terrain
 * parameters per cell, the interval analysis that finds the material
 * combinations a scene really has (DESIGN §7), the compositor that turns a
 * combination into one composite shader (DESIGN §6), and the shader pack
 * (compiler/PACK.md).
 *
 * Sections: terrain.c, scene.c, analysis.c, compose.c, pack.c.
 */
#ifndef SPLAT_SCENE_H
#define SPLAT_SCENE_H

#include <stdbool.h>
#include <stdint.h>

#include "ir.h"
#include "sg.h"

/* ---- terrain.c: heightfield and terrain parameters --------------------- */

typedef struct splat_terrain {
    int       width, height;   /* texels                                   */
    uint16_t *texels;          /* row-major, row 0 = z 0                   */
    double    size[2];         /* world metres, x and z                    */
    double    max_height;      /* metres for normalised height 1           */
    double    height_offset;   /* metres added to every height             */
} splat_terrain;

/* Load 16-bit PNG, 8-bit PNG (scaled to 16 bits) or raw little-endian R16
 * (width and height given).  Errors at `loc`. */
bool splat_terrain_load(splat_terrain *t, const char *path, sg_hf_format fmt,
                        int raw_width, int raw_height, sg_loc loc, sg_diags *d);
void splat_terrain_free(splat_terrain *t);

/* Normalised height (0..1) of texel (x, z), clamped to the edges. */
double splat_terrain_texel(const splat_terrain *t, int x, int z);
/* The CPU twins of the ABI's splat_height_at / splat_normal_at: bilinear
 * (clamp to edge) at heightfield uv, and Listing 1's cross filter. */
double splat_terrain_height(const splat_terrain *t, double u, double v);
void   splat_terrain_normal(const splat_terrain *t, double u, double v, double n[3]);

/* Sound ranges of the terrain inputs over a rectangle of texels
 * [x0, x1) x [z0, z1): every fragment whose uv falls in that rectangle
 * has its height, slope, normal and position inside the returned bounds. */
void splat_terrain_ranges(const splat_terrain *t, int x0, int z0, int x1, int z1,
                          ir_ienv *out);
/* Widen `env` (from splat_terrain_ranges) for an area whose heights change
 * at run time (craters only lower texels, down to 0): normal and slope to
 * every value the filter can give on this terrain, height down to the
 * offset.  Used for cells the destructible area reaches. */
void splat_terrain_any_shape(const splat_terrain *t, ir_ienv *env);

/* ---- scene.c: a loaded scene ------------------------------------------- */

typedef struct splat_scene {
    char          *path;       /* the scene file                              */
    sg_program    *prog;
    const sg_scene *desc;      /* owned by prog                               */
    splat_terrain  terrain;
    uint8_t      **painted;    /* desc->npainted dense rasters, W*H bytes      */
    int            nmaterials; /* desc->nmaterials, bottom (0) first          */
    /* Every material lowered into one shared ir: roots "<name>.mask", … */
    ir             ir;
} splat_scene;

/* Parse and check the scene file and its imports, load the heightfield and
 * the rasters, lower every material.  All errors carry the scene file's
 * locations.  On failure the scene is left freed. */
bool splat_scene_load(splat_scene *s, const char *path,
                      const char *const *search_paths, sg_diags *d);
void splat_scene_free(splat_scene *s);

/* ---- analysis.c: combinations ------------------------------------------ */

typedef struct splat_combo {
    int     *materials;    /* scene material indices, top first             */
    int      nmaterials;
    int      ncells;       /* leaf cells with exactly this combination       */
    int      nnodes;       /* quadtree nodes (all levels) using it           */
} splat_combo;

typedef struct splat_level {
    int       width, height;   /* nodes at this level                        */
    uint16_t *ids;             /* combination id per node, row-major        */
} splat_level;

typedef struct splat_analysis {
    int          cells_x, cells_z, cell_texels;
    splat_combo *combos;       /* in a deterministic order                   */
    int          ncombos;
    splat_level *levels;       /* 0 = leaf cells, up to a single root node   */
    int          nlevels;
    int          largest;      /* most materials in one combination          */
    double       naive_subsets; /* 2^(n-1): every subset above the base       */
    double       seconds;      /* wall time of the analysis                  */
} splat_analysis;

bool splat_analyze(const splat_scene *s, splat_analysis *a, sg_diags *d);
void splat_analysis_free(splat_analysis *a);
void splat_analysis_report(const splat_scene *s, const splat_analysis *a, FILE *out);

#endif
