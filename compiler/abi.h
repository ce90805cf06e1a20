/* abi.h — the shader ABI: the one place where generated shaders and the
 * runtime agree on the vertex-to-fragment interface, descriptor sets and
 * bindings, the uniform blocks and the push constants.
 *
 * The compiler's emitter pastes SPLAT_GLSL_PRELUDE (abi.c) into every
 * fragment shader; the runtime fills the C structs below (std140 layout:
 * every member is a vec4 or a mat4, so C and GLSL agree without padding
 * rules) and compiles SPLAT_GLSL_VERTEX for the shared vertex shader.
 *
 * Descriptor set 0 ("terrain"), the same for every pipeline:
 *   binding 0  sampler2D       heightfield, R16_UNORM, linear, clamp to edge
 *   binding 1  uniform block   splat_frame (camera, lights, terrain)
 *   binding 2  sampler2DArray  painted masks, R8_UNORM, one layer per mask,
 *                              linear, clamp (dense until the sparse atlas)
 *              With SPLAT_PAINTED_SPARSE defined before the prelude, the
 *              painted masks are the sparse quad-tree of sparse.h instead:
 *   binding 2  sampler2D       painted atlas, R8_UNORM or BC4_UNORM_BLOCK,
 *                              linear, clamp, one mip level
 *   binding 5  usampler2DArray painted index, RGBA16_UINT, one layer per
 *                              4 masks (mask m: layer m/4, channel m%4)
 *   binding 6  usampler2DArray painted levels, RGBA8_UINT, same shape
 *              and splat_painted(layer) samples them (sparse_sample on the
 *              CPU); the masks must be heightfield-sized (u_frame.texel.xy).
 *   binding 3  sampler2D       destruction atlas, R8_UNORM, linear, clamp
 *   binding 4  sampler2D       destruction indirection, RGBA8_UNORM, nearest:
 *                              .rg * 255 = tile x, y in the atlas; .a = 1 if
 *                              the cell has a tile, 0 if untouched
 * Descriptor set 1 ("material"), one for the whole pack:
 *   binding 0  uniform block   splat_params: every param of the scene, one
 *                              vec4 slot each, in manifest order
 *   binding 1+i sampler2D      the scene's texture resource i (manifest order)
 * Push constants (vertex and fragment stages): struct splat_push.
 *
 * Vertex input: location 0, vec2 (R32G32_SFLOAT): the grid position 0..1
 * inside the patch (the shared 33x33 grid).
 * Varyings: location 0 vec3 camera-relative position (m), location 1 vec2
 * heightfield uv, location 2 vec3 terrain-local position (m).
 *
 * Fragment outputs: SPLAT_OUTPUT_* below.  A single-pass shader writes one
 * RGBA32F colour; a multi-pass reference pass (compiled with
 * SPLAT_MULTIPASS defined) writes three targets blended with
 * SRC_ALPHA / ONE_MINUS_SRC_ALPHA that the resolve pass lights.
 */
#ifndef SPLAT_ABI_H
#define SPLAT_ABI_H

#include <stdint.h>

#define SPLAT_ABI_VERSION 1

enum {
    SPLAT_SET_TERRAIN = 0,
    SPLAT_SET_MATERIAL = 1,

    SPLAT_BIND_HEIGHTFIELD = 0,
    SPLAT_BIND_FRAME = 1,
    SPLAT_BIND_PAINTED = 2,
    SPLAT_BIND_DESTRUCTION_ATLAS = 3,
    SPLAT_BIND_DESTRUCTION_INDEX = 4,
    SPLAT_BIND_PAINTED_INDEX = 5,  /* only with SPLAT_PAINTED_SPARSE */
    SPLAT_BIND_PAINTED_LEVEL = 6,  /* only with SPLAT_PAINTED_SPARSE */

    SPLAT_BIND_PARAMS = 0,
    SPLAT_BIND_TEXTURE0 = 1,   /* texture i at binding 1 + i */

    SPLAT_GRID = 33,           /* vertices per patch side */
};

/* Specialization constant of every fragment shader that includes the
 * prelude: constant_id SPLAT_SPEC_VIEW, a uint, default
 * SPLAT_SPEC_VIEW_DYNAMIC.  splat_view() returns it, or u_frame.view.x when
 * it is left at the default.  A pipeline specialised to SPLAT_VIEW_FINAL
 * carries no debug-view code at all (lavapipe executes both sides of every
 * branch, so the dead MASK-view block alone cost ~40% of a frame); one left
 * dynamic serves every debug view. */
enum {
    SPLAT_SPEC_VIEW = 0,
};
#define SPLAT_SPEC_VIEW_DYNAMIC 0xffffffffu

/* Debug views (splat_view(): splat_frame.view.x or the spec constant). */
typedef enum splat_view {
    SPLAT_VIEW_FINAL = 0,  /* lit colour                                 */
    SPLAT_VIEW_COMBOS,     /* colour per combination id (seed 000 Fig. 14) */
    SPLAT_VIEW_LOD,        /* colour per quadtree level                  */
    SPLAT_VIEW_NORMAL,     /* world normal * 0.5 + 0.5                   */
    SPLAT_VIEW_SLOPE,      /* slope as grey                              */
    SPLAT_VIEW_MASK,       /* mask of scene material view.y, as grey     */
    SPLAT_VIEW_ALBEDO,     /* composited albedo, unlit                   */
    SPLAT_VIEW_COUNT
} splat_view;

/* Per-frame uniform block, set 0 binding 1. */
typedef struct splat_frame {
    float view_proj[16];     /* camera-relative world -> clip (column-major) */
    float camera[4];         /* xyz: camera, terrain-local metres            */
    float sun_dir[4];        /* xyz: unit vector towards the sun             */
    float sun_color[4];      /* rgb: sun radiance                            */
    float sky_color[4];      /* rgb: sky ambient (hemisphere, up)            */
    float fog[4];            /* rgb: fog colour; a: density per metre        */
    float terrain[4];        /* x: size x (m), y: size z (m), z: max height
                                (m), w: height offset (m)                   */
    float texel[4];          /* x: hf width, y: hf height (texels),
                                z: 1/width, w: 1/height                     */
    float destruction[4];    /* xy: area origin (terrain-local m), z: cell
                                size (m), w: cells per side                  */
    float destruction_atlas[4]; /* x: tile size (px), y: atlas size (px),
                                   z: tiles per atlas row, w: 0            */
    uint32_t view[4];        /* x: splat_view, y: material for MASK view   */
} splat_frame;

/* Push constants, vertex + fragment. */
typedef struct splat_push {
    float    patch_xz[4];  /* xy: patch corner x, z relative to the camera
                              (m); zw: patch size x, z (m)                  */
    float    patch_uv[4];  /* xy: heightfield uv of the corner; zw: extent */
    uint32_t info[4];      /* x: quadtree level, y: combination id,
                              z: scene material count, w: 0              */
} splat_push;

/* The shared GLSL text (abi.c).
 * SPLAT_GLSL_PRELUDE: version line excluded; declares set 0, push
 *   constants, varyings, fragment outputs and these functions:
 *     float splat_height()   vec3 splat_normal()   float splat_slope()
 *     vec3 splat_position()  vec2 splat_uv()        float splat_view_distance()
 *     vec3 splat_view_direction() (unit, surface -> camera, terrain-local)
 *     float splat_destruction()   float splat_painted(int layer)
 *     float splat_height_at(vec2 uv)  vec3 splat_normal_at(vec2 uv)
 *     void splat_finish(vec3 albedo, vec3 normal, float roughness,
 *                       float height, float coverage)
 *     uint splat_view()   the debug view (SPLAT_SPEC_VIEW above)
 *   splat_finish writes the outputs for the current view (single pass) or
 *   the three blend targets (SPLAT_MULTIPASS).
 * SPLAT_GLSL_LIGHTING: vec3 splat_light(vec3 albedo, vec3 n, float rough,
 *   float dist): sun + sky ambient + fog; used by the prelude and by the
 *   runtime's resolve pass.
 * SPLAT_GLSL_VERTEX: the complete shared vertex shader (#version included).
 * SPLAT_GLSL_COMBO_COLOR: vec3 splat_combo_color(uint id). */
extern const char SPLAT_GLSL_PRELUDE[];
extern const char SPLAT_GLSL_LIGHTING[];
extern const char SPLAT_GLSL_VERTEX[];
extern const char SPLAT_GLSL_COMBO_COLOR[];

/* The normal filter of seed 000 Listing 1, honouring texel aspect, on the
 * CPU.  `h` returns the normalised height (0..1) at a texel, clamped to the
 * edges; the result is what splat_normal_at() computes at texel centres:
 *   n = normalize((hl - hr) * maxh / dx, 2, (hd - hu) * maxh / dz)
 * where dx, dz are the texel spacings in metres (hl, hr: x-1, x+1; hd, hu:
 * z-1, z+1).  Shared by the analysis and the tests. */
void splat_normal_filter(double hl, double hr, double hd, double hu,
                         double maxh, double dx, double dz, double n[3]);

#endif
