/* scene.h — scenes: the heightfield and rasters on the CPU, terrain
 * parameters per cell, the interval analysis that finds the material
 * combinations a scene really has (compiler/DESIGN.md §7), the compositor that turns a
 * combination into one composite shader (compiler/DESIGN.md §6), and the shader pack
 * (compiler/PACK.md).
 *
 * Sections: terrain.c, scene.c, painted.c, analysis.c, compose.c, build.c (build.h).
 */
#ifndef SPLAT_SCENE_H
#define SPLAT_SCENE_H

#include <stdbool.h>
#include <stdint.h>

#include "abi.h"
#include "ir.h"
#include "sg.h"
#include "sparse.h"

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
/* An 8-bit mask (band 1) of any size, malloc'd; `what` names it in
 * errors ("painted mask 'road'").  NULL on error. */
uint8_t *splat_raster_mask(const char *what, const char *path, int *w, int *h,
                           sg_loc loc, sg_diags *d);

/* Normalised height (0..1) of texel (x, z), clamped to the edges. */
double splat_terrain_texel(const splat_terrain *t, int x, int z);
/* The CPU twins of the ABI's splat_height_at / splat_normal_at: bilinear
 * (clamp to edge) at heightfield uv, and Listing 1's cross filter. */
double splat_terrain_height(const splat_terrain *t, double u, double v);
void   splat_terrain_normal(const splat_terrain *t, double u, double v, double n[3]);

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
    int          hole_cells;   /* leaf cells entirely hole (with their one-
                                  texel ring): id SPLAT_COMBO_HOLE (abi.h),
                                  no combination; nodes all of whose
                                  children are holes are holes too         */
    double       naive_subsets; /* 2^(n-1): every subset above the base       */
    double       seconds;      /* wall time of the analysis                  */
} splat_analysis;

bool splat_analyze(const splat_scene *s, splat_analysis *a, sg_diags *d);
void splat_analysis_free(splat_analysis *a);
void splat_analysis_report(const splat_scene *s, const splat_analysis *a, FILE *out);

/* ---- precision.c: shading far from the origin -------------------------- */

/* A periodic site: terrain.position.AB / S (or * S), S a constant or a
 * float param; see precision.c. */
typedef struct splat_site {
    uint32_t swz;        /* IR_SWZ of the two position components         */
    bool     mul;        /* position * S; else position / S               */
    int      param;      /* layout param slot of S (a float), or -1       */
    double   value[2];   /* constant S per component (param: unused)      */
} splat_site;

/* ---- compose.c: composite shaders (compiler/DESIGN.md §6) -------------- */

/* The material-set resources every shader of a pack shares (abi.h, set 1):
 * one uniform slot per param of the source ir (in its order), one binding
 * per distinct texture (file + sampler state, in order of first use), one
 * painted layer per name.  The strings stay owned by the caller. */
typedef struct splat_layout {
    const ir      *src;        /* every material lowered: "<name>.mask", …    */
    sg_program    *prog;       /* holds the compositor; NULL: built-in alpha  */
    const char    *compositor; /* shader name; NULL = "linear_alpha"          */
    const char   **materials;  /* names, bottom (0) first                     */
    int            nmaterials;
    const char   **painted;    /* painted mask names, layer order             */
    int            npainted;
    int           *texture_of; /* src texture index -> layout texture index   */
    int           *textures;   /* layout texture -> its first src texture     */
    int            ntextures;
    int            nparams;    /* = src->nparams; slot i = src param i        */
    /* every material's precise sites, u_frame.world[k] (precision.c) */
    splat_site     sites[SPLAT_WORLD_SITES];
    int            nsites;
} splat_layout;

/* precision.c.  Find the layout's sites (splat_layout_init calls it). */
bool   splat_sites_find(splat_layout *L);
/* glsl_names.override for `ir` (a composite's emission copy; param_of:
 * its params -> layout slots, -1 for none; input_of: the terrain input a
 * param stands for, -1 for none): the camera-relative forms of the uses
 * of L's sites; free with splat_sites_overrides_free. */
char **splat_sites_overrides(const splat_layout *L, const ir *ir,
                             const int *param_of, const int *input_of,
                             const glsl_names *names);
void   splat_sites_overrides_free(const ir *ir, char **ov);
/* A warning per material whose terrain.position uses stay absolute fp32,
 * with the distance at which their error passes a quarter texel. */
struct splat_scene;
void   splat_sites_warn(const struct splat_scene *s, sg_diags *d);

/* `materials` and `painted` arrays are copied (not the strings). */
bool splat_layout_init(splat_layout *L, const ir *src, sg_program *prog,
                       const char *compositor,
                       const char *const *materials, int nmaterials,
                       const char *const *painted, int npainted, sg_diags *d);
bool splat_layout_from_scene(splat_layout *L, const splat_scene *s, sg_diags *d);
/* Compositor shader `name` of `prog` keeps its soundness contract (DESIGN
 * §6): weight 0 where m = 0, T_next 0 where m = 1, over T in [0, 1] —
 * proved with the interval evaluator, or a COMPOSITOR_CONTRACT error at
 * `at` where it proves the contract broken (compose.c says how; slack it
 * can neither prove nor refute passes).  splat_scene_load checks the
 * scene's compositor. */
bool splat_compositor_check(sg_program *prog, const char *name, sg_loc at, sg_diags *d);
void splat_layout_free(splat_layout *L);
/* Index of the layout texture equal (file + sampler state) to `t`, or -1. */
int  splat_layout_texture(const splat_layout *L, const ir_texture *t);

typedef struct splat_compose_desc {
    const int *materials;  /* scene material indices, top first; the last is
                              the bottom layer: opaque wherever the
                              combination is used, so its mask is taken as 1 */
    int        nmaterials;
    bool       reference;  /* one material alone: a multi-pass reference pass
                              (mask 1 only for scene material 0)             */
} splat_compose_desc;

typedef struct splat_layer {
    int    material;       /* scene material index                          */
    ir_ref T;              /* coverage left before this layer               */
    ir_ref mask;           /* the mask the compositor sees (clamped 0..1)   */
    ir_ref weight;         /* compositor weight                             */
    ir_ref T_next;         /* coverage left after it (NONE for the last)    */
    ir_ref view_mask;      /* its own mask, clamped, for SPLAT_VIEW_MASK    */
    ir_ref out[SG_OUT_COUNT];   /* mask (= .mask) and the surface outputs  */
} splat_layer;

/* One composite: the combination's materials imported into one ir (shared
 * subtrees are one node, duplicate textures merged, params by name), the
 * compositor inlined once per layer, then optimised.  Roots:
 *   "layer<j>.{T,mask,weight,T_next,view_mask,albedo,normal,roughness,height}"
 *   "composite.{albedo,normal,roughness,height}" = sum_j weight_j * s_j
 *   (the normal not yet normalised), for the CPU reference. */
typedef struct splat_composite {
    ir           ir;
    splat_layer *layers;      /* top first                                   */
    int          nlayers;
    bool         reference;
    int         *textures;    /* layout textures used, ascending             */
    int          ntextures;
    int         *params;      /* layout params used, ascending               */
    int          nparams;
} splat_composite;

bool splat_compose(const splat_layout *L, const splat_compose_desc *desc,
                   splat_composite *c, sg_diags *d);
void splat_composite_free(splat_composite *c);

/* Estimated per-pixel cost of shading with `c` when every layer runs
 * (the most a pixel pays): ir_cost over all its values, in the op table's
 * cost units (ir.h IR_OPS).  The manifest's "cost": the runtime picks the
 * cheapest combination covering a tile. */
double splat_composite_cost(const splat_composite *c);

typedef struct splat_glsl_desc {
    const char *title;        /* first header comment line                   */
    bool        flat;         /* no dynamic branches (benchmark variant)     */
    bool        no_mask_view; /* leave out the SPLAT_VIEW_MASK branch        */
    bool        painted_sparse; /* #define SPLAT_PAINTED_SPARSE before the
                                 prelude: painted masks read the sparse
                                 quad-tree (abi.h bindings 2, 5, 6)         */
    const char *painted_places; /* sparse_glsl_places: placed masks' rects
                                 and sizes before the prelude, or NULL      */
    bool        compute;      /* the compute variant: #define SPLAT_COMPUTE
                                 before the prelude (abi.h "compute stage") */
} splat_glsl_desc;

/* The complete Vulkan GLSL 450 fragment shader of `c`: for a composite,
 * front-to-back with every value placed in the innermost region that
 * dominates its uses (`if (T > 0.0)` per layer, nested; the surface under
 * `if (w > 0.0)`); for a reference, one pass under SPLAT_MULTIPASS. */
void splat_composite_glsl(const splat_layout *L, const splat_composite *c,
                          const splat_glsl_desc *desc, ir_buf *out);

/* ---- cache.c: content-addressed SPIR-V cache --------------------------- */

#define SPLAT_KEY_CHARS 32   /* hex digits of a shader key (XXH3-128)       */

/* The key of a shader: XXH3-128 of the compiler version, ABI version, stage
 * (spv_stage) and GLSL text, as 32 hex digits. */
void  splat_shader_key(const char *glsl, int stage, char key[SPLAT_KEY_CHARS + 1]);

typedef struct splat_cache {
    char *dir;                /* entries live under here; NULL = disabled    */
} splat_cache;

/* $SPLATC_CACHE, else $XDG_CACHE_HOME/splatc, else ~/.cache/splatc
 * (malloc'd), or NULL when none can be named. */
char *splat_cache_default_dir(void);
/* Open (creating folders) the cache under `dir` (NULL: the default).
 * False, with the cache disabled, if it cannot be created. */
bool  splat_cache_open(splat_cache *c, const char *dir);
void  splat_cache_close(splat_cache *c);
/* A hit gives a malloc'd module (a damaged entry is a miss). */
bool  splat_cache_get(const splat_cache *c, const char *key, uint32_t **words,
                      size_t *nwords);
/* Store atomically (temporary file + rename). */
bool  splat_cache_put(const splat_cache *c, const char *key,
                      const uint32_t *words, size_t nwords);

/* ---- build.c: `splatc build`, the shader pack (PACK.md) ---------------- */

typedef struct splat_build_desc {
    const char        *scene;        /* scene.sg                              */
    const char        *out;          /* PACKDIR                               */
    const char *const *search_paths; /* for imports (NULL-terminated) or NULL */
    int                jobs;         /* glslang threads; 0 = 1                */
    const char        *cache_dir;    /* NULL = splat_cache_default_dir()      */
    bool               no_cache;
    bool               flat;         /* also write branch-free composites     */
    bool               compute_spirv; /* also compile the compute variants
                                        (default: their GLSL only; PACK.md) */
    splat_painted_format painted;    /* painted mask storage; default BC4     */
    FILE              *report;       /* non-NULL: the analysis report here    */
    const char        *depfile;      /* non-NULL: write a Make/Ninja depfile
                                        of every input here (build.c)     */
} splat_build_desc;

typedef struct splat_build_stats {
    double load, analysis, compose, glslang, validate, write; /* seconds     */
    int    combos, combos_cached, combos_compiled;  /* composite shaders     */
    int    shaders, shaders_cached, shaders_compiled; /* every module         */
    bool   up_to_date;       /* the pack already held this build's output:
                                nothing after `load` ran (combos = its count) */
} splat_build_stats;

/* Load, analyse, compose every combination, compile (cache first, then
 * glslang on `jobs` threads), validate, and write the pack into
 * OUT.tmp-XXXXXX, then swap it into place.  When the pack at `out` was
 * built from the same input bytes, stop after loading (stats->up_to_date).
 * On any error (diagnostics in `d`) an existing pack at `out` is left
 * untouched. */
bool splat_build(const splat_build_desc *desc, splat_build_stats *stats,
                 sg_diags *d);

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
