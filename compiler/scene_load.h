/* scene_load.h — a loaded scene: its file, heightfield, rasters and
 * lowered materials (scene.c), how its painted masks are stored
 * (painted.c), and where imports are found (search.c).
 */
#ifndef SPLAT_SCENE_LOAD_H
#define SPLAT_SCENE_LOAD_H

#include "sparse.h"
#include "terrain.h"

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

typedef enum splat_painted_format {
    SPLAT_PAINTED_BC4 = 0,     /* default: sparse quad-tree, BC4 atlas      */
    SPLAT_PAINTED_R8,          /* sparse quad-tree, R8 atlas (exact)        */
    SPLAT_PAINTED_DENSE,       /* painted.r8: one W*H layer per mask        */
} splat_painted_format;

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

/* The import search path, the one every entry point uses (splatc's
 * commands, splat_scene_load without one, the viewer's hot reload): the
 * `include` folders (-I) in order, $SPLATC_PATH (':'-separated), the
 * current folder, the nearest folder at or above `file`'s that has a
 * nodes/ folder, and the installed node library (splat_data_dir).
 * NULL-terminated, malloc'd: free with splat_search_path_free. */
char **splat_search_path(const char *const *include, int ninclude, const char *file);
/* What a scene's imports are resolved against: the scene's folder, then
 * `search` (NULL: splat_search_path's defaults).  Free with
 * splat_search_path_free. */
char **splat_import_path(const char *scene, const char *const *search);
void   splat_search_path_free(char **paths);
/* The installed data folder, PREFIX/share/splatc when this program runs
 * from PREFIX/bin and the folder holds nodes/; else NULL.  malloc'd. */
char  *splat_data_dir(void);

#endif
