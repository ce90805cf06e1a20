/* splatc.h — libsplatc's public interface, the one header it installs:
 * what a program that builds shader packs needs (splatview's hot reload,
 * a tool's build step), and nothing of the compiler's insides.
 *
 *   version      splatc_version
 *   diagnostics  sg_loc, the error ids (SG_ERRORS), sg_diags and printing
 *                them (GCC style with caret, or JSON Lines)
 *   programs     sg_load and the files a program read (what to watch for
 *                hot reload); the import search path
 *   the build    splat_build_desc, splat_build_stats, splat_build: scene
 *                file in, shader pack out (PACK.md)
 *
 * The compiler's own headers (sg.h, ir.h, scene.h, ...) include this one;
 * they are not installed.  Library calls never exit: errors go into an
 * sg_diags and the call returns false (or NULL).
 */
#ifndef SPLATC_H
#define SPLATC_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- version ------------------------------------------------------------ */

/* The library's version ("0.4.0"), as the build of libsplatc set it. */
const char *splatc_version(void);

/* ---- diagnostics (diag.c) ----------------------------------------------- */

typedef struct sg_loc {
    const char *file;   /* path as given (owned by the source registry) */
    int line, col;      /* 1-based; 0 if unknown                         */
} sg_loc;

/* Error identities, one X-macro list so tests can assert on the id.
 * X(id, format) — format is printf-style. */
#define SG_ERRORS(X)                                                        \
    X(IO,            "cannot read '%s': %s")                                \
    X(WRITE,         "cannot write '%s': %s")                               \
    X(COMPOSITOR_CONTRACT, "compositor '%s' breaks its contract: %s must be 0 where m = %d " \
                     "for every T in [0, 1], but at T = %g, h = %g it lies in [%g, %g]") \
    X(SYNTAX,        "expected %s, found %s")                               \
    X(UNTERMINATED,  "unterminated %s (opened at line %d)")                 \
    X(BAD_LITERAL,   "bad literal '%s': %s")                                \
    X(BAD_CHAR,      "unexpected character %s")                             \
    X(UNKNOWN_NODE,  "unknown node type '%s'")                              \
    X(UNKNOWN_PORT,  "'%s' has no %s port '%s'")                            \
    X(UNKNOWN_NAME,  "unknown name '%s'")                                   \
    X(DUPLICATE,     "duplicate %s '%s' (first defined at %s:%d:%d)")       \
    X(TYPE_MISMATCH, "type mismatch: %s expects %s, found %s")              \
    X(MISSING_INPUT, "'%s' needs a value for input '%s'")                   \
    X(CYCLE,         "cycle: %s")                                           \
    X(MISSING_IMPORT,"cannot import '%s': %s")                              \
    X(IMPORT_CYCLE,  "import cycle: %s")                                    \
    X(BAD_OUTPUT,    "'%s' is not a material output (mask, albedo, normal, roughness, height)") \
    X(TOO_DEEP,      "nesting deeper than %d levels")                       \
    X(BAD_SWIZZLE,   "%s")      /* .xyzw past a value's end, or no swizzle */ \
    X(BAD_REFERENCE, "%s")      /* a name of the wrong kind used here      */ \
    X(BAD_DEFAULT,   "%s")      /* a default a param or input cannot take  */ \
    X(BAD_COMPONENTS, "%s")     /* vecN(...) with the wrong count          */ \
    X(BAD_OPTION,    "%s")      /* a texture or node option's value        */ \
    X(EMPTY_RANGE,   "%s")      /* param range lo > hi                     */ \
    X(REDEFINED,     "%s")      /* a built-in node type defined again      */ \
    X(HAS_ERRORS,    "%s")      /* lowering a program that has errors      */ \
    X(SETTING,       "%s")      /* a scene setting's value                 */ \
    X(MISSING_SETTING, "%s")    /* a setting the scene needs               */ \
    X(UNDECLARED,    "%s")      /* a painted mask or compositor not there  */ \
    X(RASTER,        "%s")      /* a heightfield or mask raster's content  */ \
    X(OVER_LIMIT,    "%s")      /* over a pack or device limit (PACK.md)   */ \
    X(EMPTY_TERRAIN, "%s")      /* holes cover the whole terrain           */ \
    X(NOT_A_PACK,    "%s")      /* the output folder is not a shader pack  */ \
    X(NO_DEVICE,     "%s")      /* --far-bake gpu and no device to bake on */ \
    X(OUT_OF_MEMORY, "%s")                                                  \
    /* warnings (the input is accepted) */                                  \
    X(W_MASK_RANGE,  "%s")      /* a mask's values leave [0, 1] (lint.c)   */ \
    X(W_NAN,         "%s")      /* an output can be NaN or infinite        */ \
    X(W_LO_HI,       "%s")      /* a constant lo >= hi on a ramp-like node */ \
    X(W_PRECISION,   "%s")      /* position in fp32 past a quarter texel   */ \
    X(WARNING,       "%s")      /* any other warning                       */ \
    X(INTERNAL,      "internal compiler error: %s")

typedef enum sg_error_id {
#define X(id, fmt) SG_E_##id,
    SG_ERRORS(X)
#undef X
    SG_E_COUNT
} sg_error_id;

typedef enum sg_severity { SG_ERROR, SG_WARNING, SG_NOTE } sg_severity;

typedef struct sg_diag {
    sg_loc       loc;
    sg_severity  severity;
    sg_error_id  id;
    char        *msg;
    char        *src_line;  /* the source line at loc (for the caret), or NULL */
    char        *suggestion; /* "did you mean" replacement (sg_hint_suggest), or NULL */
} sg_diag;

typedef struct sg_diags {
    sg_diag *items;
    int      n, cap;
    int      nerrors;
    int      ndropped;  /* diagnostics counted but not stored (too many) */
    struct sg_sources *sources; /* source texts for carets (diag.c)      */
    bool     last_dropped; /* the latest diagnostic was not stored        */
    bool     unique;    /* do not store a diagnostic equal to one stored
                           (it still counts in nerrors): one list for
                           several loads of files that share imports
                           (`splatc check A B` prints each error once)    */
} sg_diags;

void sg_diags_init(sg_diags *d);
void sg_diags_free(sg_diags *d);

/* GCC style: "file:line:col: error: msg", the source line, a caret. */
void sg_diags_print(const sg_diags *d, FILE *out);
/* The same for the diagnostics from index `from` on (no "not shown" line). */
void sg_diags_print_from(const sg_diags *d, int from, FILE *out);
/* The same diagnostics for editors, one JSON object per line (JSON Lines):
 * {"file": …, "line": N, "column": N, "severity": "error", "id":
 * "UNKNOWN_NODE", "message": …} and, where the message says "did you
 * mean", "suggestion": the name; file is null and line/column 0 where
 * unknown; a last {"dropped": N} line if some were not stored. */
void sg_diags_print_json(const sg_diags *d, FILE *out);
/* The same from index `from` on (no "dropped" line). */
void sg_diags_print_json_from(const sg_diags *d, int from, FILE *out);
/* The id's name as in SG_ERRORS ("UNKNOWN_NODE"). */
const char *sg_error_name(sg_error_id id);
/* Make `text` the source of `path` for the caret lines of later
 * diagnostics at `path` (copied; sg_load does this for every file). */
void sg_diags_add_source(sg_diags *d, const char *path, const char *text,
                         size_t len);

/* ---- programs (load.c, sg_program.c, search.c) --------------------------- */

typedef struct sg_program sg_program;

/* Parse `path` and everything it imports (import paths are relative to the
 * importing file, then to the search paths), resolve names and type-check.
 * Returns NULL only on allocation failure; check d->nerrors. */
sg_program *sg_load(const char *path, const char *const *search_paths,
                    sg_diags *d);
void        sg_free(sg_program *p);
/* Every file the program read (for hot reload and cache keys). */
int         sg_file_count(const sg_program *p);
const char *sg_file_path(const sg_program *p, int i);

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

/* ---- the build (build.c; PACK.md) ---------------------------------------- */

/* How a pack stores the painted masks (painted.c). */
typedef enum splat_painted_format {
    SPLAT_PAINTED_BC4 = 0,     /* default: sparse quad-tree, BC4 atlas      */
    SPLAT_PAINTED_R8,          /* sparse quad-tree, R8 atlas (exact)        */
    SPLAT_PAINTED_DENSE,       /* painted.r8: one W*H layer per mask        */
} splat_painted_format;

/* Where `splatc build --far-bake` bakes it: the CPU reference
 * (far_atlas.c), the device (runtime/far_bake.c), or auto: a GPU when
 * the CLI finds one; a CPU's Vulkan device (lavapipe) where the atlas has
 * enough texels per combination to pay for its shader compiles
 * (runtime/far_bake.c cpu_device_pays); else the CPU reference. */
typedef enum splat_far_bake {
    SPLAT_FAR_BAKE_AUTO, SPLAT_FAR_BAKE_CPU, SPLAT_FAR_BAKE_GPU,
} splat_far_bake;

/* "auto", "cpu" or "gpu" (--far-bake, $SPLAT_FAR_BAKE); false otherwise. */
static inline bool splat_far_bake_parse(const char *s, splat_far_bake *out)
{
    static const char *const names[] = {"auto", "cpu", "gpu"};
    for (int m = 0; s && m < 3; m++)
        if (!strcmp(s, names[m])) {
            *out = (splat_far_bake)m;
            return true;
        }
    return false;
}


typedef struct splat_build_desc {
    const char        *scene;        /* scene.sg                              */
    const char        *out;          /* PACKDIR                               */
    const char *const *search_paths; /* for imports (NULL-terminated) or NULL */
    const char *const *pack_search;  /* the folders -I added (NULL-
                                        terminated) or NULL: the manifest's
                                        scene.search, relative to the pack,
                                        so swatches and hot reload find the
                                        same imports (SPLATC_PATH is the
                                        environment's: splatview reads it) */
    int                jobs;         /* glslang threads; 0 = 1                */
    const char        *cache_dir;    /* NULL = splat_cache_default_dir()      */
    bool               no_cache;
    bool               flat;         /* also write branch-free composites     */
    bool               no_lazy;      /* no lazy branches (compose.c)          */
    bool               glsl_compute; /* compute variants (and distance
                                        classes, undergrowth masks) as GLSL
                                        only, compiled by the runtime on
                                        first use (default: SPIR-V too) */
    splat_painted_format painted;    /* painted mask storage; default BC4     */
    bool               no_dclasses;  /* no distance classes (distance.c)     */
    int                max_combos;   /* > 0: cover the leaf-cell combinations
                                        with at most this many supersets
                                        (analysis.c "merging"); 0: none    */
    FILE              *report;       /* non-NULL: the analysis report here    */
    const char        *depfile;      /* non-NULL: write a Make/Ninja depfile
                                        of every input here (build.c)     */
    const char        *preview;      /* non-NULL: this material's swatch pack
                                        instead (preview.c)               */
    int                far_atlas;    /* > 0: bake the far atlas, one texel
                                        per N x N heightfield texels
                                        (far_atlas.c); 0: none            */
    splat_far_bake     far_bake;     /* where it is baked (far_atlas.h)     */
    /* The device bake (far_bake != CPU; the CLI sets it where the runtime
     * is built): w x h texels of albedo (3 floats), normal (3) and
     * roughness (1) from the pack written in `pack_dir` (complete but for
     * the far atlas); false with a message in `msg`: no device there. */
    bool (*far_device)(void *user, const char *pack_dir, int w, int h, float *albedo,
                       float *normal, float *rough, char *msg, size_t nmsg);
    void              *far_device_user;
} splat_build_desc;

typedef struct splat_build_stats {
    double load, analysis, compose, glslang, validate, write; /* seconds     */
    double far_atlas;        /* the far atlas bake (--far-atlas), seconds  */
    bool   far_on_device;    /* it was baked by desc->far_device           */
    int    combos, combos_cached, combos_compiled;  /* composite shaders     */
    int    combos_found;     /* distinct leaf-cell combinations the analysis
                                found (combos: those built, after merging) */
    int    largest, leaf_largest; /* most layers in a composite built, and
                                in one leaf cell                         */
    int    uber_nodes;       /* coarse quadtree nodes no combination covers */
    int    shaders, shaders_cached, shaders_compiled; /* every module         */
    int    shapes_known;     /* compiled ones not validated again: their
                                shape passed spirv-val before (cache.h)  */
    int    lazy_branches;    /* lazy branches in the composites compiled
                                (fragment variants; compose.c)          */
    int    dclasses;         /* distance class variants added (distance.c)  */
    int    files_written;    /* pack files written, and those kept: the old */
    int    files_kept;       /* pack held the same bytes (linked, not written) */
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

#ifdef __cplusplus
}
#endif

#endif
