/* scene.h — the compiler's scene-to-pack API, one header per component:
 *   terrain.h     heightfield and terrain inputs (terrain.c, raster.c)
 *   scene_load.h  a loaded scene, its painted masks, import search
 *                 (scene.c, painted.c, search.c)
 *   analysis.h    the combinations a scene has (analysis.c, precision.c)
 *   compose.h     composite shaders (compose.c)
 *   cache.h       the SPIR-V cache (cache.c)
 * and here `splatc build`, the shader pack (build.c; PACK.md).
 */
#ifndef SPLAT_SCENE_H
#define SPLAT_SCENE_H

#include <stdio.h>

#include "cache.h"
#include "compose.h"
#include "far_atlas.h"

/* ---- build.c: `splatc build`, the shader pack (PACK.md) ---------------- */

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

#endif
