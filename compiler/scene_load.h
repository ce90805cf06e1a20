/* scene_load.h — a loaded scene: its file, heightfield, rasters and
 * lowered materials (scene.c), how its painted masks are stored
 * (painted.c), and where imports are found (search.c).
 */
#ifndef SPLAT_SCENE_LOAD_H
#define SPLAT_SCENE_LOAD_H

#include "sparse.h"
#include "terrain.h"

/* ---- vector.c: the scene's splines and polygons -------------------------- */

/* The shapes as the shader's buffer (abi.h "vector shapes' buffer"), which
 * the pack stores as vectors.bin, and what the CPU needs to read it. */
typedef struct splat_vectors {
    uint32_t *words;        /* the buffer; NULL when the scene has no shapes */
    size_t    nwords;
    uint32_t *shape_first;  /* shape s's segments: [first[s], first[s + 1]) */
    double    margin;       /* metres added to distance bounds for the
                               shader's fp32 position and arithmetic      */
} splat_vectors;

/* Flatten the scene's shapes, bucket their segments in the grid.  Errors
 * (over a pack limit) at the shapes.  No shapes: words NULL, true. */
bool   splat_vectors_build(const sg_scene *sc, splat_vectors *v, sg_diags *d);
void   splat_vectors_free(splat_vectors *v);
/* Shape s's distance (m) at terrain-local x, z over all its segments (0
 * inside a polygon): the reference.  _grid: as the shader finds it
 * (its cell's segments; 1e30 where none of shape s is listed). */
double splat_vector_distance(const splat_vectors *v, int s, double x, double z);
double splat_vector_distance_grid(const splat_vectors *v, int s, double x, double z);
/* Its mask (across false) or across value at distance d. */
double splat_vector_profile(const splat_vectors *v, int s, double d, bool across);
void   splat_vector_shape(const splat_vectors *v, int s, double *half_width,
                          double *falloff, int *profile, int *kind);
/* Bounds dlo <= d <= dhi of shape s's distance, as the shader computes it
 * (margin included), over the rectangle x0 z0 x1 z1 (terrain-local m). */
void   splat_vector_range(const splat_vectors *v, int s, const double rect[4],
                          double *dlo, double *dhi);
/* The shape an IR painted leaf named "vector.NAME[.across]" reads, or -1
 * (not such a name, or no such shape). */
int    splat_vector_find(const sg_scene *sc, const char *painted_name, bool *across);

/* ---- scene.c: a loaded scene ------------------------------------------- */

typedef struct splat_scene {
    char          *path;       /* the scene file                              */
    sg_program    *prog;
    const sg_scene *desc;      /* owned by prog                               */
    splat_terrain  terrain;
    uint8_t      **painted;    /* desc->npainted dense rasters, row-major      */
    int          (*painted_size)[2]; /* each raster's texels: the heightfield's
                                  W, H unless the mask is placed             */
    /* The painted masks as the pack stores them (painted.c), or NULL: the
     * analysis then bounds the dense rasters.  Not owned by the scene:
     * whoever built it (build.c) frees it. */
    const sparse_masks *sparse;
    splat_vectors  vectors;    /* the spline and polygon shapes (vector.c)    */
    int          (*texture_size)[2]; /* ir.textures[i]'s texels, W and H, read
                                  when the scene checked the files          */
    int            nmaterials; /* desc->nmaterials, bottom (0) first          */
    /* Every material lowered into one shared ir: roots "<name>.mask", … */
    ir             ir;
    sg_scene      *own_desc;   /* a preview's altered copy that desc points
                                  to (preview.c), or NULL                   */
} splat_scene;

/* Parse and check the scene file and its imports, load the heightfield and
 * the rasters, lower every material.  All errors carry the scene file's
 * locations.  On failure the scene is left freed.  Imports are searched
 * next to the importing file, in the scene's folder, then `search_paths`
 * (NULL-terminated); with NULL, the nearest folder at or above the
 * scene's that holds nodes/ (the project root), then ".".  s->ir.painted[i]
 * is the scene's painted mask i. */
bool splat_scene_load(splat_scene *s, const char *path,
                      const char *const *search_paths, sg_diags *d);
void splat_scene_free(splat_scene *s);

/* preview.c: turn a loaded scene into material `material`'s swatch scene:
 * that material alone on a built-in test hill (a hemisphere of every
 * slope on a flat ring, 128 m), the scene's light without fog, painted
 * masks read as 0, one camera preset "swatch".  A located error if the
 * scene has no such material. */
bool splat_scene_preview(splat_scene *s, const char *material, sg_diags *d);

/* ---- painted.c: how a pack stores the painted masks -------------------- */

/* splat_painted_format: splatc.h. */
const char *splat_painted_format_name(splat_painted_format f);  /* "bc4" … */
bool splat_painted_format_parse(const char *s, splat_painted_format *f);

/* Whether format `f` can store the scene's masks: dense cannot store a
 * placed one (error at its `size`). */
bool splat_painted_check_format(const splat_scene *s, splat_painted_format f,
                                sg_diags *d);
/* The scene's painted rasters as sparse masks in format `f` (BC4 or R8),
 * with each mask's options from the scene file (max_level, max_error,
 * near in metres -> texels).  Errors at the scene's painted entries. */
bool splat_painted_build(const splat_scene *s, splat_painted_format f,
                         sparse_masks *out, sg_diags *d);

/* ---- search.c: where imports are found ---------------------------------- */

/* splat_search_path, splat_import_path, splat_search_path_free: splatc.h. */
/* The installed data folder, PREFIX/share/splatc when this program runs
 * from PREFIX/bin and the folder holds nodes/; else NULL.  malloc'd. */
char  *splat_data_dir(void);

#endif
