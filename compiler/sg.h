/* sg.h — the graph language front end: diagnostics, sources, lexer, parser,
 * name resolution, type checking and lowering to the IR.
 *
 * Public part (used by the scene compiler, the CLI and the runtime's hot
 * reload).  The front end's internals (tokens, AST) are declared in
 * sg_internal.h.
 */
#ifndef SPLAT_SG_H
#define SPLAT_SG_H

#include <stdbool.h>
#include <stdio.h>

#include "abi.h"
#include "ir.h"
#include "splatc.h"   /* the public part: diagnostics, sg_load, the build */

/* ---- diagnostics (diag.c; the types and printing: splatc.h) ------------- */


/* Record a diagnostic; the message is formatted from the id's format. */
void sg_error(sg_diags *d, sg_loc loc, sg_error_id id, ...);
/* `loc` if it was given (line > 0), else `fallback`. */
static inline sg_loc sg_loc_or(sg_loc loc, sg_loc fallback)
{
    return loc.line > 0 ? loc : fallback;
}
/* An error of an id whose format is "%s", the message from `fmt`. */
void sg_errorf(sg_diags *d, sg_loc loc, sg_error_id id, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
void sg_note(sg_diags *d, sg_loc loc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* A warning: printed like an error, but the input is accepted (id
 * SG_E_WARNING; sg_warning_id for one of the W_ ids). */
void sg_warning(sg_diags *d, sg_loc loc, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
void sg_warning_id(sg_diags *d, sg_loc loc, sg_error_id id, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Append "; <text>" to the latest diagnostic's message (a hint on how to
 * fix it); nothing if it was dropped or there is none. */
void sg_hint(sg_diags *d, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Append "; did you mean 'word'?" and record `word` as the latest
 * diagnostic's suggestion (JSON "suggestion"); nothing if word is NULL. */
void sg_hint_suggest(sg_diags *d, const char *word);

/* "Did you mean": offer the names a misspelt `word` could have meant, one
 * by one; sg_suggest_best is the nearest by edit distance (Damerau-
 * Levenshtein: a swap of neighbours costs 1, a change of case 0; one name
 * starting with the other, "out" for "output", just passes), or NULL
 * when none is within about a third of the word's length (none at all
 * for words of 1 or 2 letters).  The first of equally near names wins, so
 * the result depends only on the order of the offers.  A name is not
 * copied: it must outlive the sg_suggest. */
typedef struct sg_suggest {
    const char *word;
    const char *best;
    int         dist;
} sg_suggest;
void        sg_suggest_init(sg_suggest *s, const char *word);
void        sg_suggest_offer(sg_suggest *s, const char *name);
const char *sg_suggest_best(const sg_suggest *s);
/* Edit distance of a and b as sg_suggest counts it (capped at 64). */
int         sg_edit_distance(const char *a, const char *b);


/* ---- programs ---------------------------------------------------------- */


/* Same, from memory (`name` is used in diagnostics and for imports). */
sg_program *sg_load_string(const char *name, const char *text,
                           const char *const *search_paths, sg_diags *d);
/* Texts held in memory (an editor's unsaved documents, `splatc lsp`):
 * sg_load_overlay asks `text` for every file it would read, the root and
 * each import candidate, before it looks at the disk; NULL means "not
 * held, read the disk".  The text (len bytes, NUL-terminated) must stay
 * valid until sg_load_overlay returns.  A path is asked as the loader
 * spells it (the import joined to the importing file's folder or to a
 * search folder), so `text` compares canonical forms. */
typedef struct sg_overlay {
    const char *(*text)(void *user, const char *path, size_t *len);
    void *user;
} sg_overlay;
sg_program *sg_load_overlay(const char *path, const char *const *search_paths,
                            const sg_overlay *ov, sg_diags *d);
/* Warnings about what builds but cannot be meant (lint.c): a mask whose
 * bounds over `region` leave [0, 1], an output that can be NaN or
 * infinite, a constant lo >= hi on a ramp-like node.  `region`: the
 * terrain's input bounds (params and painted unset), NULL for every
 * input's domain.  Nothing for a program with errors. */
void sg_lint(sg_program *p, const ir_ienv *region, sg_diags *d);
/* The node of `material` (or of a shader it instantiates, looked at
 * after its own nodes) of built-in op `op` (NULL: any) that reads terrain
 * input `input` (ir_input_kind) directly; its location and "node 'uv'
 * (mul)" or "node 'uv' (mul) of shader S" in `what`.  Falls back to any
 * node reading the input when none of `op` does.  False if none. */
bool sg_node_reading_input(const sg_program *p, const char *material, const char *op,
                           int input, sg_loc *loc, char *what, size_t n);
/* The checks `splatc check` runs after sg_load (and `splatc lsp` on every
 * change, sg_query.c): if the load had no errors, the texture files
 * (sg_check_texture_files), then, if still none, sg_lint over every
 * input's domain. */
void sg_check(sg_program *p, sg_diags *d);
/* Where texture file `file` (a path as in ir_texture.file) is named: the
 * string of its `texture { file = "…" }` or of an inline texture on a
 * port, the first such; line 0 if none. */
sg_loc sg_texture_file_loc(const sg_program *p, const char *file);
/* Every texture file the program names (declared or inline), each once:
 * readable and an image, else IO at the string naming it.  False if one
 * is not.  sg_load does not look at files (a graph library may name
 * textures its user never builds); `splatc check` and scene loading do. */
bool sg_check_texture_files(const sg_program *p, sg_diags *d);

int         sg_material_count(const sg_program *p);
const char *sg_material_name(const sg_program *p, int i);
sg_loc      sg_material_loc(const sg_program *p, int i);
int         sg_material_find(const sg_program *p, const char *name); /* -1 */

/* A material's `undergrowth` block (seed 000 §5.5): instances of a mesh
 * scattered where the material's composited weight says (DESIGN.md §3).
 * The OBJ file, if any, was loaded and checked by sg_load. */
typedef struct sg_undergrowth {
    const char *mesh;      /* built-in mesh name ("grass", "plant", "stone"), or NULL */
    const char *obj;       /* an OBJ file's path (resolved as texture paths are), or NULL */
    double density;        /* instances per m^2, (0, 64] */
    double scale[2];       /* lo, hi */
    bool   align_normal;   /* align = normal (else upright) */
    double blend;          /* 0..1: share of the terrain's albedo (at the tip) */
    double root_blend;     /* 0..1: that share at the root (default: blend) */
    double color[3];       /* linear */
    bool   light_terrain;  /* lighting = terrain (else mesh): lit with the
                              terrain normal; default: grass and plant */
    int    cutout;         /* SG_UG_CUT_*: `cutout = none | frond | alpha`;
                              default: frond for plant */
    const char *texture;   /* `texture = "file"`: an image's path (resolved
                              as the OBJ's), its rgb times the colour, its
                              alpha the cut-out (alpha), or NULL */
    double wind;           /* sway at 1 m above the root (m), [0, SPLAT_MAX_UG_WIND] */
    double wind_dir[2];    /* unit xz: where the wind blows to */
    double gust;           /* 0..1: share of the sway the gusts modulate */
    double shadow;         /* 0..1: darkening of the ground under an instance */
    sg_loc loc;            /* the `undergrowth` keyword */
} sg_undergrowth;
enum { SG_UG_CUT_NONE, SG_UG_CUT_FROND, SG_UG_CUT_ALPHA };
/* At most SG_MAX_UNDERGROWTH blocks per material, SG_MAX_UG_MATERIALS
 * undergrowth-bearing materials per program (OVER_LIMIT). */
#define SG_MAX_UNDERGROWTH  4
#define SG_MAX_UG_MATERIALS 16
/* The undergrowth blocks of material i (sg_material_name's index), in source order. */
int sg_undergrowth_count(const sg_program *p, int material);
const sg_undergrowth *sg_undergrowth_get(const sg_program *p, int material, int k);

/* Lower material `name` into `out` (which may already hold other
 * materials: shared subtrees are shared).  Sets the roots
 * "<name>.mask", ".albedo", ".normal", ".roughness", ".height", filling
 * missing outputs with the defaults (mask 1, albedo 0.5 grey, normal
 * terrain.normal, roughness 0.8, height 0.5).  Params are named
 * "<name>.<param>".  Returns false with diagnostics on error. */
bool sg_lower_material(sg_program *p, const char *name, ir *out, sg_diags *d);

/* Inline instance shader `name` into `out` with its inputs bound to
 * `in_vals` (by name; inputs not given take their defaults) and return
 * the refs of the outputs named in `out_names`.  Compositors are plain
 * shaders with agreed port names (nodes/compositors.sg), lowered this way
 * once per layer.  Returns false with diagnostics on error (unknown
 * shader or port, type mismatch). */
bool sg_lower_shader(sg_program *p, const char *name, ir *out,
                     const char *const *in_names, const ir_ref *in_vals, int nin,
                     const char *const *out_names, ir_ref *out_vals, int nout,
                     sg_diags *d);

/* Standard material outputs, in the order used everywhere. */
#define SG_OUTPUTS(X)            \
    X(MASK,      "mask",      IR_T_FLOAT) \
    X(ALBEDO,    "albedo",    IR_T_VEC3)  \
    X(NORMAL,    "normal",    IR_T_VEC3)  \
    X(ROUGHNESS, "roughness", IR_T_FLOAT) \
    X(HEIGHT,    "height",    IR_T_FLOAT)

typedef enum sg_output {
#define X(id, name, type) SG_OUT_##id,
    SG_OUTPUTS(X)
#undef X
    SG_OUT_COUNT
} sg_output;
extern const char *const sg_output_names[SG_OUT_COUNT];

/* Graphviz DOT of the program's graphs, or of one material if `material`
 * is non-NULL: its shader nodes are then boxes naming the shader and its
 * wired ports, and with `expand` the shaders it instantiates (transitively)
 * are drawn as clusters of their own too. */
void sg_write_dot(const sg_program *p, const char *material, bool expand, FILE *out);

/* ---- scenes ------------------------------------------------------------ */

/* A `scene` block (one per scene.sg).  Paths are resolved relative to the
 * scene file.  Every field keeps its location for later errors. */
typedef enum sg_hf_format {
    SG_HF_PNG,      /* .png: 16-bit (or 8-bit) greyscale, through stb_image   */
    SG_HF_R16,      /* .r16 / .raw: little-endian 16-bit, heightfield_size    */
    SG_HF_GDAL,     /* anything else (.tif, .hgt, .asc, …): through libgdal;
                       size, origin and heights come from the file (raster.c) */
} sg_hf_format;

typedef struct sg_scene_painted {
    char  *name;       /* the name materials use: painted { mask = "fields" } */
    char  *file;       /* 8-bit greyscale PNG (or any raster GDAL reads),
                          the heightfield's size unless placed               */
    sg_loc loc;
    /* { origin = X Z, size = W H }: the raster, of any size, covers that
     * rectangle (terrain-local metres) and reads 0 outside it.  Both or
     * neither; a location with line 0 means "not given". */
    double origin[2];  sg_loc origin_loc;
    double place[2];   sg_loc place_loc;   /* the `size`                   */
    /* Sparse storage options (sparse.h), from an optional block after the
     * file: painted NAME = "FILE" { max_level = 2, max_error = 0.05,
     * near = x0 z0 x1 z1, origin = X Z, size = W H }.  Defaults: max_level 0 (full resolution),
     * max_error 1 (no limit once max_level allows), no near rectangle. */
    int    max_level;  /* coarsest quad-tree level, 0..7 (-1: not a whole
                          number; sg_scene_check reports it)               */
    double max_error;  /* largest reduction error allowed, 0..1             */
    bool   has_near;
    double near[4];    /* terrain-local metres x0 z0 x1 z1 kept at level 0   */
    sg_loc max_level_loc, max_error_loc, near_loc;
} sg_scene_painted;

/* `spline NAME { points = [x z, x z, ...], width = W, falloff = F,
 * profile = linear|smoothstep }` and `polygon NAME { points = [...],
 * falloff = F, profile = ... }`: a vector shape (compiler/vector.c) of
 * one curve per `points` (a road network, a polygon with holes),
 * points in terrain-local metres, read by materials as vector.NAME (the
 * mask, 1 in the core, 0 past the falloff) and vector.NAME.across. */
typedef struct sg_scene_vector {
    char   *name;
    sg_loc  loc;
    int     kind;          /* SPLAT_VEC_SPLINE or SPLAT_VEC_POLYGON (abi.h) */
    double *points;        /* npoints x, z pairs, every curve's             */
    int     npoints;       sg_loc points_loc;   /* the first `points`     */
    int    *curve_end;     /* each `points = [...]` is a curve (a polygon's
                              ring: even-odd, so a second one cuts a hole):
                              curve c is points [curve_end[c-1],
                              curve_end[c]) (from 0 for c = 0)           */
    sg_loc *curve_loc;     int ncurves;
    double  width;         sg_loc width_loc;    /* spline only            */
    double  falloff;       sg_loc falloff_loc;  /* default 0              */
    int     profile;       sg_loc profile_loc;  /* SPLAT_VEC_*; -1: unknown */
} sg_scene_vector;

typedef struct sg_scene_camera {
    char  *name;
    double position[3], look[3];   /* terrain-local metres */
    sg_loc loc;
} sg_scene_camera;

/* The scene's light block: abi.h SPLAT_LIGHT_KEYS. */
typedef struct sg_scene_light {
    unsigned given;                  /* bit k: key k was set              */
    double   v[SPLAT_LIGHT_COUNT][3];
    sg_loc   loc[SPLAT_LIGHT_COUNT];
} sg_scene_light;

typedef struct sg_scene {
    char  *name;
    sg_loc loc;
    char  *heightfield;      sg_loc heightfield_loc;
    sg_hf_format hf_format;  /* from the extension: .png, .r16/.raw, else GDAL */
    int    hf_width, hf_height; /* required for raw R16, 0 otherwise (-1:
                                   not whole numbers)                     */
    sg_loc hf_size_loc;
    /* size and max_height: required for PNG and raw heightfields; for a
     * GDAL one size is optional (default: the geotransform's) and
     * max_height / height_offset are not allowed (the file's heights are
     * used as stored).  A location with line 0 means "not given". */
    double size[2];          sg_loc size_loc;      /* x, z metres          */
    double max_height;       sg_loc max_height_loc;
    double height_offset;    sg_loc height_offset_loc; /* default 0        */
    /* `painted holes = "FILE"`: texels > 127 cut the terrain (terrain.c);
     * not a painted layer.  NULL if none. */
    char  *holes;            sg_loc holes_loc;
    char **materials;        sg_loc *material_locs; int nmaterials; /* bottom first */
    sg_loc materials_loc;    /* the `materials` setting                   */
    char  *compositor;       sg_loc compositor_loc; /* default "linear_alpha" */
    sg_scene_painted *painted; int npainted;
    bool   has_destruction;  sg_loc destruction_loc; /* the block's keyword */
    double destruction_origin[2], destruction_size[2];
    double destruction_cell;                       /* default 16 m         */
    sg_loc destruction_cell_loc;
    int    cell_texels;      sg_loc cell_texels_loc; /* default 32         */
    sg_scene_camera *cameras; int ncameras;
    sg_scene_vector *vectors; int nvectors;     /* spline and polygon blocks */
    bool   has_light;        sg_loc light_loc;
    sg_scene_light light;
} sg_scene;

/* scene_check.c: every check of a scene block that needs neither files
 * nor the program (missing settings, ranges, contradictions, pack
 * limits), all errors at once; the parser calls it at the block's end.
 * sg_scene_cells_fit: the leaf cells of a w x h heightfield within the
 * pack limit (scene.c calls it again once a raster's size is known). */
bool sg_scene_check(const sg_scene *sc, sg_diags *d);
bool sg_scene_cells_fit(const sg_scene *sc, int w, int h, sg_diags *d);

/* The scene of the program's root file, or NULL if it declares none. */
const sg_scene *sg_program_scene(const sg_program *p);

#endif
