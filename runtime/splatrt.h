/* splatrt.h — libsplatrt, the Vulkan terrain runtime: a shader pack
 * (compiler/PACK.md) turned into pictures (compiler/DESIGN.md §8, Andersson 2007 §5.4).
 *
 * The public API (installed): a device, a pack, a renderer that draws it
 * from a camera (forward or screen-space shading, debug views, craters),
 * pictures written out, and the GLFW viewer.  Everything is prefixed rt_.
 * Library code never exits: a failing call returns false and fills an
 * rt_error (id + message).  The device and the pack are opaque handles
 * (rt_device_open, rt_pack_open; what tools need of them through
 * rt_device_info and the rt_pack_ accessors), and no Vulkan type appears
 * here.  The library's internals (the two structs, Vulkan helpers, shader
 * checks, uploads, the quadtree, pipelines, the screen path) are in
 * rt_internal.h, as Lua keeps lstate.h beside lua.h.
 *
 * Sections: errors + device.c, image.c, pack_load.c (the handles and their
 * accessors in handles.c), render.c, destruction.c, viewer.c.
 */
#ifndef SPLAT_RT_H
#define SPLAT_RT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "abi.h"

/* ---- errors (device.c) -------------------------------------------------
 * X(id, format): one list so tests and callers can switch on the id. */
#define RT_ERRORS(X)                                                        \
    X(VULKAN,       "%s failed: %s")                                        \
    X(NO_DEVICE,    "no usable Vulkan device: %s")                          \
    X(NO_VALIDATION, "validation requested (SPLAT_VALIDATE=1) but %s is not installed (Debian: vulkan-validationlayers)") \
    X(NO_FORMAT,    "the device cannot %s")                                 \
    X(IO,           "cannot %s '%s': %s")                                   \
    X(PACK_JSON,    "%s:%d:%d: error: %s")                                  \
    X(PACK_FIELD,   "%s: error: %s")                                        \
    X(PACK_FILE,    "%s: error: %s names '%s', which %s")                   \
    X(PACK_SPIRV,   "%s: error: corrupt SPIR-V: %s")                        \
    X(PACK_COMBO,   "%s: error: combination id %d out of range (the pack has %d) at %s") \
    X(PACK_VERSION, "%s: error: %s")                                        \
    X(PACK_SHADER,  "%s: error: %s does not fit the runtime: %s")           \
    X(PACK_LIMIT,   "%s: error: %s is %llu, over %s (%llu)")                \
    X(SHADER,       "shader '%s' does not compile:\n%s")                    \
    X(WINDOW,       "window: %s")                                           \
    X(RELOAD,       "reload: %s")

typedef enum rt_error_id {
    RT_OK = 0,
#define X(id, fmt) RT_E_##id,
    RT_ERRORS(X)
#undef X
    RT_E_COUNT
} rt_error_id;

typedef struct rt_error {
    rt_error_id id;
    char       *msg;   /* formatted message, owned; NULL when id == RT_OK */
} rt_error;

void        rt_error_clear(rt_error *e);
/* Record an error (printf arguments for the id's format); returns false so
 * that `return rt_fail(e, RT_E_IO, ...)` reads naturally.  `e` may be NULL. */
bool        rt_fail(rt_error *e, rt_error_id id, ...);

/* ---- device.c, handles.c: the device ----------------------------------- */

typedef struct rt_device_desc {
    bool         validate;      /* validation layer + messenger; default: env
                                   SPLAT_VALIDATE=1.  Asked for but not
                                   installed: RT_E_NO_VALIDATION, so a "no
                                   validation messages" test cannot pass
                                   without the layer                      */
    const char  *select;        /* device index or name substring; default:
                                   env SPLAT_DEVICE; else discrete GPU first */
    const char *const *instance_exts;  /* extra instance extensions (GLFW) */
    uint32_t     ninstance_exts;
    bool         swapchain;     /* enable VK_KHR_swapchain                  */
} rt_device_desc;

/* A Vulkan instance and device with its queue (opaque; rt_internal.h). */
typedef struct rt_device rt_device;

/* Make one (desc may be NULL: the defaults); *out stays NULL on failure. */
bool rt_device_open(const rt_device_desc *desc, rt_device **out, rt_error *e);
/* Wait for it to be idle and free it; returns the validation messages
 * counted over its whole life, teardown included (0 when not validating
 * or d is NULL), which is what a "validation stays silent" check asks. */
int  rt_device_close(rt_device *d);
/* Validation messages counted so far (0 when not validating). */
int  rt_device_messages(const rt_device *d);

/* What the device is and what it enabled. */
typedef struct rt_device_info {
    const char *name;            /* the driver's device name (owned by d)  */
    bool        cpu;             /* a CPU implementation (lavapipe)        */
    bool        wireframe;       /* fillModeNonSolid: wireframe drawing    */
    bool        bc;              /* BC textures (painted_format bc4)       */
    bool        count_fragments; /* the forward counting variant           */
    bool        validating;      /* the validation layer is on             */
} rt_device_info;
void rt_device_info_get(const rt_device *d, rt_device_info *out);

/* ---- image.c: writing pictures ---------------------------------------- */

/* How float colours become 8-bit PNG pixels. */
typedef enum rt_tonemap {
    RT_TONEMAP_FILMIC,   /* lit colour: exposure 0.8, ACES fit, sRGB encode */
    RT_TONEMAP_SRGB,     /* linear colour (albedo): clamp, sRGB encode      */
    RT_TONEMAP_NONE,     /* display values (debug views): clamp only        */
} rt_tonemap;

void rt_tonemap_rgba8(const float *rgba, int w, int h, rt_tonemap tm,
                      uint8_t *out);
bool rt_write_png(const char *path, const uint8_t *rgba8, int w, int h,
                  rt_error *e);
/* The raw float image: PFM ("PF\n<w> <h>\n-1.0\n", little-endian floats,
 * bottom row first) is RGB only, so the runtime writes its own tiny format:
 *   bytes 0..7   "SPLATF32"
 *   bytes 8..15  uint32 width, uint32 height (little-endian)
 *   then         width*height*4 little-endian float32, RGBA, top row first
 * rt_read_float reads it back (tests, benchmarks). */
bool rt_write_float(const char *path, const float *rgba, int w, int h,
                    rt_error *e);
bool rt_read_float(const char *path, float **rgba, int *w, int *h, rt_error *e);

/* ---- pack_load.c, handles.c: reading a shader pack ----------------------- */

/* Preview lighting (light.c): the scene's `light` block, splatview's
 * --sun, --exposure and --fog-density, the viewer's keys.  NAN fog
 * fields: the defaults light.c derives from the terrain. */
typedef struct rt_light {
    double sun[2];         /* azimuth (degrees clockwise from north, -z),
                              elevation (degrees)                         */
    double sun_color[3];   /* linear; times intensity                      */
    double intensity;      /* the sun's irradiance times pi                */
    double sky[3];         /* zenith colour (linear): sky and ambient      */
    double fog_density;    /* per metre at fog_height; NAN: default        */
    double fog_height;     /* terrain-local metres; NAN: lowest terrain    */
    double exposure;       /* EV: the lit colour times 2^exposure          */
} rt_light;

void rt_light_default(rt_light *l);
/* The unit vector towards the sun. */
void rt_light_sun_dir(const rt_light *l, double dir[3]);
/* Key k's numbers (abi.h SPLAT_LIGHT_KEYS order: sun, sun_color, …). */
double *rt_light_values(rt_light *l, int key);
/* NULL if every field is within abi.h's ranges (NAN fog fields: the
 * defaults), else what is wrong (a static string). */
const char *rt_light_check(const rt_light *l);

/* A shader pack as loaded (opaque; rt_internal.h). */
typedef struct rt_pack rt_pack;

/* Read and check the pack in folder `dir`, untrusted input (every file it
 * names inside the folder and of the right size, every size within the
 * pack limits of abi.h, every combination id in range); errors name the
 * pack file and what is wrong.  *out stays NULL on failure.  Its shaders
 * are read, decompressed and validated against their role on first use
 * (a module that fails then fails the call that needed it); none reaches
 * the driver unchecked. */
bool rt_pack_open(const char *dir, rt_pack **out, rt_error *e);
/* Read and validate every shader of the pack now, on all cores (what
 * splatview --check does): false with the failure of the first in
 * manifest order. */
bool rt_pack_validate(const rt_pack *p, rt_error *e);
/* Free it; NULL does nothing. */
void rt_pack_close(rt_pack *p);

/* What a tool or test asks of a pack. */
typedef struct rt_pack_info {
    const char *name, *dir;       /* owned by the pack                      */
    const char *scene_path;       /* scene.sg relative to the pack, or NULL */
    int    hf_width, hf_height;   /* heightfield texels                     */
    double size[2];               /* terrain metres along x and z           */
    double max_height, height_offset;
    int    ncameras, nmaterials, nparams, ntextures;
    int    ncombos;               /* combinations, then distance classes    */
    int    nbase;                 /* combinations of combos.bin             */
    int    nlevels;               /* combination levels (quadtree depths)   */
    int    npainted;              /* painted masks                          */
    int    nsites;                /* periodic sites of terrain.position
                                     (u_frame.world, abi.h)                 */
    bool   has_holes, has_destruction, has_uber, has_far_atlas;
    bool   has_undergrowth, has_vectors;
    int    ug_slots, ug_blocks;   /* undergrowth slots and blocks (PACK.md)  */
    bool   has_reference;         /* every material has a multi-pass pass   */
    bool   has_compute;           /* screen-path (compute) variants         */
    /* the far atlas (PACK.md "Far atlas"), when has_far_atlas */
    int    far_width, far_height, far_levels;
    double far_texel[2];          /* metres per level-0 texel               */
    size_t far_bytes;             /* its BC blocks, the header left out     */
    int    shaders;               /* shader files the pack names            */
    int    shaders_read;          /* of them, read and checked so far (on
                                     first use, or all by rt_pack_validate) */
} rt_pack_info;
void rt_pack_info_get(const rt_pack *p, rt_pack_info *out);
/* Material i's name (0 <= i < nmaterials; else NULL). */
const char *rt_pack_material_name(const rt_pack *p, int i);
/* Camera preset i: its name (NULL out of range), and where it stands and
 * looks (terrain-local metres). */
const char *rt_pack_camera_name(const rt_pack *p, int i);
bool rt_pack_camera_at(const rt_pack *p, int i, double position[3], double look[3]);
/* The scene's lighting over the defaults. */
const rt_light *rt_pack_light(const rt_pack *p);
/* The heightfield as loaded (hf_width * hf_height, x fastest, row z = 0
 * first): metres = height_offset + h / 65535 * max_height.
 * rt_renderer_heights has it with a renderer's craters. */
const uint16_t *rt_pack_heights(const rt_pack *p);
/* Each size of the pack against the device's limits (maxImageDimension2D,
 * maxImageArrayLayers, samplers per stage, uniform range), before any of
 * it is created; RT_E_PACK_LIMIT naming the limit. */
bool rt_pack_check_device(const rt_pack *p, const rt_device *d, rt_error *e);
/* Print the bytes of each painted mask representation next to dense. */
void rt_painted_print_stats(const rt_pack *p, FILE *out);
int  rt_pack_material_find(const rt_pack *p, const char *name);   /* -1 */
int  rt_pack_camera_find(const rt_pack *p, const char *name);     /* -1 */
/* The default fog density (per metre; light.c), for a scene without
 * `light { fog_density = … }`: 0.375 / D, so the fog hides 31 % of the
 * colour (1 - e^-0.375) at distance D, where D is the farthest any camera
 * preset stands from the point it looks at, and at least a quarter of the
 * terrain's larger side (the default camera's distance when there is no
 * preset, where this is the old default 1.5 / extent). */
double rt_light_fog_default(const rt_pack *p);

/* ---- render.c: drawing ------------------------------------------------- */


typedef struct rt_camera {
    double position[3];   /* terrain-local metres                           */
    double time;          /* seconds: animates the undergrowth's wind (0: the
                             still picture of a headless frame)             */
    double look[3];       /* a point looked at                              */
    double fovy;          /* radians; default 60 degrees                    */
    double znear;         /* metres; default 0.25                           */
} rt_camera;

typedef enum rt_shading {
    RT_SHADING_FORWARD = 0,   /* each patch shaded by its node's composite  */
    RT_SHADING_SCREEN,        /* depth pass, 8x8 tiles classified, compute
                                 shading (screen.c); the multi-pass
                                 reference and wireframe stay forward       */
} rt_shading;

typedef enum rt_screen_depth {
    RT_DEPTH_AUTO = 0,   /* ray cast on GPUs (their raster front end is the
                            floor), geometry pass on CPU drivers and for
                            terrains with holes                           */
    RT_DEPTH_RASTER,     /* the patches drawn depth only                  */
    RT_DEPTH_RAYCAST,    /* maximum-mipmap ray casting in compute          */
} rt_screen_depth;

/* The screen path's shading order within a workgroup (abi.h SPLAT_SORT).
 * Off by default: sorting raises the layers' SIMD efficiency (colorado
 * top-down on an H100: 56 -> 84 %) but its first, masks-only run costs
 * more than the surfaces it saves there and on lavapipe
 * (tests/bench/HISTORY.md "Pixels sorted by layer set"). */
typedef enum rt_pixel_sort {
    RT_SORT_OFF = 0,     /* each workgroup shades one tile in pixel order  */
    RT_SORT_ON,          /* sort_tiles tiles per workgroup, pixels sorted by
                            the layers they need before shading; needs
                            subgroup arithmetic in compute (else off)    */
} rt_pixel_sort;

/* Where the terrain's shadow map is marched (shadow.c, shadow_gpu.c); the
 * two maps agree within 1/255 (render.shadow_gpu). */
typedef enum rt_shadow_path {
    RT_SHADOW_AUTO = 0,  /* on the device; $SPLAT_SHADOW=cpu|gpu overrides */
    RT_SHADOW_GPU,       /* a compute pass over a pyramid of maxima        */
    RT_SHADOW_CPU,       /* the reference march, rows over the CPU's cores */
} rt_shadow_path;

/* The CPU shading LOD (runtime/DESIGN.md "CPU shading LOD"): on CPU
 * devices (lavapipe), where both sides of every branch run, the footprint
 * filter's derivatives off (abi.h SPLAT_SPEC_LOD), material textures from
 * their nearest mip level and the geometry at twice the screen error
 * (lod_pixels 6, unless lod_pixels is given).  GPUs draw the full
 * shading. */
typedef enum rt_shading_lod {
    RT_SHADING_LOD_AUTO = 0,  /* on for CPU devices; $SPLAT_SHADING_LOD=0|1
                                 overrides it                              */
    RT_SHADING_LOD_OFF,       /* the full shading on every device          */
    RT_SHADING_LOD_ON,        /* the CPU's on every device (tests, bench)   */
} rt_shading_lod;

typedef enum rt_reference {
    RT_REF_NONE = 0,      /* per-combination composites                     */
    RT_REF_MULTIPASS,     /* one blended pass per material + resolve        */
    RT_REF_UBER,          /* every patch with the über-shader               */
} rt_reference;

/* The screen-space path's tiles and counters of a frame (screen.c). */
typedef struct rt_screen_stats {
    int      tiles, tiles_total;  /* terrain tiles shaded; all tiles         */
    int      tiles_uber;          /* tiles no combination covered            */
    int      tiles_far;           /* tiles shaded from the far atlas         */
    int      tiles_class;         /* tiles shaded by a distance class        */
    int      tiles_stand_in;      /* tiles a stand-in shaded while their
                                     combination's pipeline was being made
                                     (rt_render_desc.async_pipelines): the
                                     sum of the three below                 */
    int      tiles_stand_in_uber; /* ... by the über-shader                  */
    int      tiles_stand_in_atlas;/* ... from the far atlas                  */
    int      tiles_stand_in_flat; /* ... by the flat stand-in (lit terrain,
                                     one neutral albedo)                    */
    int      lists;               /* combinations (and über) with tiles      */
    /* The classification's view (issue 29): the combinations its cover
     * search tries, the materials in view and the mask words per set. */
    int      class_candidates, class_materials, class_words;
    /* Counting frames (rt_renderer_set_counting, the cost view), both
     * paths; on the forward path "pixels" are the fragments shaded. */
    uint32_t pixels, layers_evaluated, layers_needed, samples;
    uint32_t branches, branches_uniform;   /* splat_counters (abi.h)         */
} rt_screen_stats;

typedef struct rt_render_desc {
    int          width, height;
    rt_reference reference;
    float        clear[4];          /* background (linear); default sky       */
    const char  *pipeline_cache;    /* file; NULL: $XDG_CACHE_HOME/splatc/…   */
    bool         no_stitch;         /* tests: draw every patch unstitched     */
    bool         no_cull;           /* tests: never cull back faces           */
    double       lod_pixels;        /* screen error per grid step; default 3  */
    int          destruction_pool;  /* destruction tiles; 0: RT_DESTR_POOL_DEFAULT */
    rt_shading   shading;           /* forward (default) or screen-space      */
    rt_screen_depth screen_depth;   /* screen path: where its depth comes from */
    rt_pixel_sort pixel_sort;       /* screen path: pixels sorted by layer set */
    int          sort_tiles;        /* tiles a sorting workgroup takes (4, 8
                                       or 16); 0: the most the device allows */
    bool         tile_blocks;       /* screen path: tiles classified, so
                                       listed, in 4x4 blocks of tiles rather
                                       than rows: a list's consecutive tiles
                                       (a sorting workgroup's) lie together;
                                       the same picture (--tile-order)      */
    /* lighting over the pack's (splatview --sun, --exposure, --fog-density) */
    bool         sun_set, exposure_set, fog_set;
    double       sun[2], exposure, fog_density;
    bool         no_shadows;        /* the sun casts none (splatview --no-shadows) */
    rt_shadow_path shadow;          /* where the shadow map is marched
                                       (splatview --shadow cpu|gpu)         */
    bool         no_undergrowth;    /* draw no undergrowth (--no-undergrowth)  */
    bool         no_distance_classes; /* shade with the combinations only, not
                                       their distance classes (PACK.md;
                                       splatview --no-distance-classes)     */
    bool         async_pipelines;   /* screen path: compute pipelines made on
                                       worker threads, the über-shader's
                                       drawing their tiles meanwhile (the
                                       viewer's default; headless waits)   */
    double       undergrowth_radius; /* m around the camera; 0: RT_UG_RADIUS    */
    bool         undergrowth_compute; /* screen path: instances that fit 64 px
                                       drawn in compute, not by the graphics
                                       pipeline (runtime/undergrowth_craster.c;
                                       splatbench ugcompute=1)              */
    double       undergrowth_thin;  /* m: beyond it a cell draws the fraction
                                       (thin / d)^2 of its instances (at
                                       least 8 %), widened; 0: 14 (the far
                                       meshes' distance, which stays;
                                       runtime/DESIGN.md)                   */
    bool         split_uncovered;   /* forward: coarse quadtree nodes that
                                       no compiled combination covers (the
                                       pack composes leaf cells only) are
                                       split down to nodes that have one;
                                       default: drawn with the über-shader,
                                       the same picture with the same
                                       geometry (splatview --uncovered split) */
    int          preview_scale;     /* 2 or 4: depth, classification and
                                       shading at 1/scale of width and height,
                                       upsampled to the full size guided by
                                       the depth edges (upscale.c); 0 or 1:
                                       full resolution (splatview
                                       --preview-scale)                     */
    rt_shading_lod shading_lod;     /* the CPU shading LOD (above); splatview
                                       --shading-lod auto|off|on            */
    double       far_atlas_distance; /* screen tiles, forward patches at least
                                    this far (m) are shaded from the pack's
                                    far atlas; 0: off (the default)          */
    /* any light key over the pack's (splatview --light KEY=V,...): bit k
     * of light_keys set = abi.h SPLAT_LIGHT_KEYS row k given, its values
     * in light[k]; applied after sun / exposure / fog_density above */
    unsigned     light_keys;
    double       light[SPLAT_LIGHT_COUNT][3];
} rt_render_desc;

/* One undergrowth instance as the GPU stores it (32 bytes). */
typedef struct rt_ug_instance {
    float    pos[3];      /* root, terrain-local metres                  */
    float    scale;
    uint32_t normal;      /* packSnorm4x8 of the terrain normal          */
    uint32_t color;       /* packUnorm4x8: the terrain's albedo at the root, 1 */
    float    angle;       /* radians about the up (or normal) axis       */
    uint32_t block;       /* pack undergrowth block                      */
} rt_ug_instance;

/* Undergrowth of a frame (runtime/undergrowth.c). */
#define RT_UG_RADIUS SPLAT_UG_RADIUS /* default radius of the cells around the camera
                                        (abi.h: splatc checks packs at it) */
#define RT_UG_KEYS_MAX 16
typedef struct rt_ug_stats {
    int    cells;             /* cells allocated around the camera          */
    int    generated;         /* of them, generated in this frame           */
    long   instances;         /* instances in the allocated cells           */
    long   candidates;        /* the scatter pass's candidates in them      */
    long   drawn;             /* instances drawn (after LOD, fade, frustum) */
    long   triangles;         /* triangles drawn, contact shadows included  */
    int    draws;             /* indirect draws                             */
    long   drawn_compute;     /* of drawn, those drawn in compute (those
                                 that fit the cap; undergrowth_compute)     */
    long   cr_overflow;       /* compute triangles and contact shadows
                                 clipped to the cap (0)                     */
    /* per key (a block's near, far or single-triangle mesh, by the
     * graphics pipeline or in compute; in the draw's order; the first
     * RT_UG_KEYS_MAX): its block, index count, instances drawn, whether
     * in compute */
    int    keys;
    int    key_block[RT_UG_KEYS_MAX];
    bool   key_compute[RT_UG_KEYS_MAX];
    uint32_t key_indices[RT_UG_KEYS_MAX], key_drawn[RT_UG_KEYS_MAX];
    double gen_ms, draw_ms;   /* GPU ms (timestamps; < 0 if unsupported)    */
    double draw_gfx_ms;       /* of draw_ms: the graphics pipeline's pass   */
    double draw_cs_ms;        /* the compute raster and shadow passes, and  */
    double resolve_ms;        /* the resolve (< 0: not run)                 */
    size_t bytes_per_cell;    /* masks + instance capacity + draw arguments */
} rt_ug_stats;

typedef struct rt_frame_stats {
    int    patches, culled, pipelines, combos_in_view;
    int    class_patches;     /* forward: patches shaded by a distance class */
    int    far_patches;       /* forward: patches shaded from the far atlas  */
    int    uber_patches;      /* forward: coarse patches no compiled
                                 combination covers, über-shaded (a fallback) */
    int    split_uncovered;   /* quadtree nodes split only because no
                                 compiled combination covers them          */
    bool   backfaces_culled;  /* the camera was above the terrain            */
    double gpu_ms;            /* timestamps; < 0 if unsupported              */
    double select_ms;         /* CPU quadtree selection + culling            */
    double cpu_ms;            /* whole CPU side of the frame                 */
    double pass_ms[3];        /* screen: geometry, classification, shading
                                 GPU ms (timestamps; < 0 if unsupported)     */
    bool   screen;            /* drawn by the screen-space path              */
    bool   sorted;            /* its pixels sorted by layer set (rt_pixel_sort) */
    rt_screen_stats tiles;    /* its tiles (screen only) and counters        */
    int    redraws;           /* frames drawn again after compiling pipelines */
    double compile_ms;        /* wall ms of this call making those pipelines */
    int    spirv_cached;      /* compute modules so far from the pack (the
                                 build's SPIR-V) or the SPIR-V cache */
    int    spirv_compiled;    /* ... and compiled from GLSL (glslang)        */
    int    pipelines_pending; /* being made on workers after this frame     */
    double shadow_ms;         /* wall ms of a new shadow map (the sun moved or
                                 a crater changed heights), marched on the
                                 CPU or submitted to the device and waited
                                 for; 0: none needed                        */
    bool   shadow_gpu;        /* the map is marched on the device          */
    rt_ug_stats undergrowth;  /* cells, instances, generation and draw     */
    double first_picture_s;   /* seconds from the process's launch to the
                                 end of this renderer's first complete frame
                                 (rt_seconds_since_launch); the same in
                                 every later frame's stats                  */
} rt_frame_stats;

/* Seconds since this process was launched (its start time in
 * /proc/self/stat, 10 ms steps; where that cannot be read, since the first
 * call: call it first thing in main). */
double rt_seconds_since_launch(void);
/* With $SPLAT_LAUNCH_TRACE set (rt_launch_tracing), prints "launch S s:
 * WHAT" to stderr (S: rt_seconds_since_launch; WHAT printf's FMT), so the
 * first picture's time can be split by phase.  Returns true, to sit in a
 * chain of steps. */
bool rt_launch_tracing(void);
bool rt_launch_mark(const char *fmt, ...);

typedef struct rt_renderer rt_renderer;

bool rt_renderer_create(rt_device *d, const rt_pack *p,
                        const rt_render_desc *desc, rt_renderer **out,
                        rt_error *e);
void rt_renderer_destroy(rt_renderer *r);
/* The default camera: the pack's preset named "overview", else its first
 * preset, else a view from the south down onto the centre, close enough
 * that the distance fog stays light there. */
void rt_default_camera(const rt_pack *p, rt_camera *c);
/* Debug view and the material of the MASK view. */
void rt_renderer_set_view(rt_renderer *r, splat_view view, int material);
void rt_renderer_set_wireframe(rt_renderer *r, bool on);
/* The lighting of the next frames (default: the pack's); a hot reload
 * keeps one set here. */
void rt_renderer_set_light(rt_renderer *r, const rt_light *l);
/* Undergrowth drawn or not (the viewer's U); a renderer created with
 * rt_render_desc.no_undergrowth has none to draw. */
void rt_renderer_set_undergrowth(rt_renderer *r, bool on);
/* The instances of undergrowth cell (ix, iz), the 16 m cell whose origin
 * is (16 ix, 16 iz) terrain-local metres, as generated (up to max; 0 when
 * that cell is not allocated and generated, -1 on error): for tests. */
int  rt_renderer_undergrowth_cell(rt_renderer *r, int ix, int iz, rt_ug_instance *out, int max,
                                  rt_error *e);
/* For tests: the undergrowth instances the last frame drew, after the
 * distance LOD and the distance fade (runtime/undergrowth.c), counted
 * per ring of `width` m around its camera (counts[k]: [k, k + 1) widths;
 * farther ones not counted), and in counts[nrings + k] the LOD's before
 * the fade (2 nrings counts): the cells counted, -1 on error. */
int  rt_renderer_undergrowth_rings(rt_renderer *r, double width, int nrings, uint32_t *counts,
                                   rt_error *e);
/* For tests: the undergrowth instances the last frame drew (after the
 * distance LOD, the fade and the frustum: runtime/undergrowth.c "cull"),
 * in the draw's order, up to max, each one's key (rt_ug_stats.key_*: the
 * block's near or far mesh) in key[] when not NULL; returns how many it
 * drew (may exceed max), -1 on error. */
int  rt_renderer_undergrowth_drawn(rt_renderer *r, rt_ug_instance *out, int *key, int max,
                                   rt_error *e);
/* For tests: the vertex stage's wind offset on the device at n points (12
 * floats each: root xyz, h metres above the root, a block's wind: unit
 * direction x, z, sway, gust; out: the offset xyz, the gust in [0, 1]).
 * false without undergrowth or on error. */
bool rt_renderer_undergrowth_wind(rt_renderer *r, float *points, int n, double time,
                                  rt_error *e);
/* Terrain shadows on or off (rt_render_desc.no_shadows; the viewer's H). */
void rt_renderer_set_shadows(rt_renderer *r, bool on);
const rt_light *rt_renderer_light(const rt_renderer *r);
/* Frames with the counting variant of the shaders (abi.h SPLAT_COUNT),
 * whose counters rt_frame_stats.tiles carries: the screen path's compute
 * shaders, or the forward path's composites and über-shader (needs
 * rt_device.count_fragments; not the multi-pass reference). */
void rt_renderer_set_counting(rt_renderer *r, bool on);
/* Switch paths; screen needs a renderer created with RT_SHADING_SCREEN
 * (false otherwise). */
bool rt_renderer_set_shading(rt_renderer *r, rt_shading s);
rt_shading rt_renderer_shading(const rt_renderer *r);
bool rt_renderer_set_param(rt_renderer *r, const char *name,
                           const float value[4], rt_error *e);
/* Render one frame offscreen and wait for it. */
bool rt_renderer_frame(rt_renderer *r, const rt_camera *c,
                       rt_frame_stats *st, rt_error *e);
/* With async pipelines: until the workers have made every pipeline asked
 * for so far (the next frame draws no stand-in for those lists); false,
 * *e set, where one failed. */
bool rt_renderer_wait_pipelines(rt_renderer *r, rt_error *e);
/* The last frame's colour as RGBA32F, top row first (w * h * 4 floats). */
bool rt_renderer_read(rt_renderer *r, float *rgba, rt_error *e);
/* The last frame's plan (runtime/render_plan.c): its passes in order, what
 * each reads and writes; with `times` each one's GPU time, measured when
 * set_pass_times is on (a timestamp after every pass; off by default:
 * a few, the frame's and the screen path's three parts). */
void rt_renderer_print_plan(const rt_renderer *r, FILE *out, bool times);
void rt_renderer_set_pass_times(rt_renderer *r, bool on);
/* Replace the combination pipelines with those of a new pack of the same
 * terrain (hot reload); on failure the old ones stay.  Refused
 * (RT_E_RELOAD naming the input) when the pack's data differ from what was
 * uploaded: heightfield contents or size, terrain scale, textures (pixels,
 * mips, samplers), painted masks, the destructible area. */
bool rt_renderer_swap_pack(rt_renderer *r, const rt_pack *p, rt_error *e);
/* The debug views' tables (abi.h SPLAT_VIEWS): --view name ("?" if not a
 * view), how a screenshot of it is tone-mapped, the view the viewer's key
 * selects (-1: none), and the --view list for help texts
 * ("final|combos|…|mask:MATERIAL|…") into buf (truncated to n). */
const char *rt_view_name(splat_view v);
rt_tonemap  rt_view_tonemap(splat_view v);
int         rt_view_by_key(int key);
void        rt_view_list(char *buf, size_t n);
/* The viewer's on-screen help (key H; overlay.c). */
typedef struct rt_overlay_info {
    const char *pack;       /* the pack's name                              */
    splat_view  view;
    const char *material;   /* the mask view's material, or NULL            */
    bool        screen;     /* screen-space path (else forward)            */
    bool        wire;
    double      frame_ms;   /* <= 0: not shown (headless: no frame rate)    */
    int         pending;    /* pipelines still compiling (rt_frame_stats)   */
    const char *status;     /* the viewer's last status line, or NULL       */
} rt_overlay_info;
/* The overlay's text: the state on top, then every key. */
void rt_overlay_text(const rt_overlay_info *in, char *buf, size_t n);
/* Draw `text` onto a tone-mapped w x h RGBA8 picture, on the device (the
 * same pipeline as the window; `splatview --headless --overlay`). */
bool rt_overlay_draw_rgba8(rt_device *d, const char *text, uint8_t *rgba, int w, int h,
                           rt_error *e);

/* Craters (destruction.c) on the renderer's terrain: a pack without a
 * destructible area answers RT_CRATER_OUTSIDE. */
typedef struct rt_crater rt_crater;
typedef struct rt_crater_stats rt_crater_stats;
typedef struct rt_destruction rt_destruction;
bool rt_renderer_crater(rt_renderer *r, const rt_crater *c, rt_crater_stats *st,
                        rt_error *e);
/* NULL when the pack has no destructible area. */
rt_destruction *rt_renderer_destruction(rt_renderer *r);
/* The destruction mask's memory: this area, and the slides' configuration. */
void rt_destruction_print_stats(const rt_destruction *ds, FILE *out);
/* The heightfield as the renderer has it now (craters included). */
const uint16_t *rt_renderer_heights(const rt_renderer *r);
/* Where the ray from `o` along `dir` first meets the terrain (CPU march
 * on the current heightfield); false if it misses. */
bool rt_renderer_pick(const rt_renderer *r, const double o[3], const double dir[3],
                      double hit[3]);
/* A crater of `radius` m (depth radius / 4) where the ray through pixel
 * (px, py) of a w x h view of camera c meets the terrain (viewer clicks). */
bool rt_renderer_crater_at_pixel(rt_renderer *r, const rt_camera *c, double px, double py,
                                 int w, int h, double radius, rt_crater_stats *st,
                                 rt_error *e);
/* The GPU heightfield read back (tests): W*H texels. */
bool rt_renderer_read_heights(rt_renderer *r, uint16_t *out, rt_error *e);
/* The far atlas baked on this device (`splatc build --far-bake`; abi.h
 * "far atlas bake", far_bake.c): w x h texels over the terrain, each the
 * mean of its 2 x 2 points as compiler/far_atlas.c's CPU bake makes it,
 * into albedo (3 floats a texel), unit normal (3) and roughness (1),
 * row-major.  Uses the pack's parameters at their defaults and no craters.
 * st (may be NULL): where the time went. */
typedef struct rt_far_bake_stats {
    int    combos;        /* combinations compiled (those the leaf cells name) */
    double compile_s;     /* their pipelines, on all cores                  */
    double shade_s;       /* dispatches, read back and texels               */
} rt_far_bake_stats;
bool rt_renderer_bake_far(rt_renderer *r, int w, int h, float *albedo, float *normal,
                          float *rough, rt_far_bake_stats *st, rt_error *e);
/* `splatc build --far-bake`'s device (compiler/scene.h far_device; user:
 * an rt_far_bake_host): rt_renderer_bake_far on the pack in pack_dir, on
 * host->device (the viewer's, for a hot reload) or on one of its own. */
typedef struct rt_far_bake_host {
    int            mode;      /* a splat_far_bake (compiler/far_atlas.h,
                                 not needed here): auto, a CPU's device
                                 declines                                  */
    rt_device     *device;    /* NULL: create one (splatc)                */
} rt_far_bake_host;
bool rt_far_bake_device(void *user, const char *pack_dir, int w, int h, float *albedo,
                        float *normal, float *rough, char *msg, size_t nmsg);
bool rt_parse_view(const char *s, const rt_pack *p, splat_view *view,
                   int *material, rt_error *e);

/* ---- destruction.c: the destruction mask (Andersson 2007 §5.2.5) -------------
 * Fixed-grid indirection over the destructible area, 64x64 R8 tiles from a
 * fixed pool, crater decals rendered into them, heightfield and node bounds
 * updated in the same event (destruction.c explains).  Pool exhausted: the
 * crater is refused as a whole (warning on stderr, nothing changes). */

enum { RT_DESTR_TILE = 64, RT_DESTR_POOL_DEFAULT = 256 };

struct rt_crater {
    double x, z;       /* centre, terrain-local metres                      */
    double radius;     /* metres                                            */
    double depth;      /* metres lowered at the centre (0: mask only)       */
    double strength;   /* mask at the centre, 0..1; 0 means 1               */
};

typedef enum rt_crater_result {
    RT_CRATER_DONE = 0,
    RT_CRATER_OUTSIDE,   /* misses the destructible area (or none)          */
    RT_CRATER_REFUSED,   /* the tile pool has too few free tiles            */
} rt_crater_result;

struct rt_crater_stats {
    rt_crater_result result;
    int    cells;        /* grid cells the disc meets                       */
    int    tiles_new;    /* tiles allocated by this crater                  */
    int    tiles_used, pool;
    int    texels;       /* heightfield texels lowered                      */
    int    upload[4];    /* x, z, w, h of the uploaded texel rectangle      */
    double cpu_ms;       /* the event on the CPU (record + submit), without
                            wait_ms                                         */
    double wait_ms;      /* waiting for the event four back to finish       */
};

/* Memory of a destruction mask configuration (the slides' figures). */
typedef struct rt_destruction_figures {
    int    side_px, cells, tile_px, tiles;
    double dense_bytes, indirection_bytes, tile_bytes, sparse_bytes;
} rt_destruction_figures;

void rt_destruction_memory(double area_m, double px_per_m, double cell_m,
                           double coverage, rt_destruction_figures *f);
/* Helpers shared with the renderer and tests. */
double rt_height_at(const uint16_t *heights, const rt_pack *p, double x, double z);
bool   rt_heightfield_pick(const uint16_t *heights, const rt_pack *p, const double o[3],
                           const double dir[3], double hit[3]);

/* ---- viewer.c: the GLFW window ---------------------------------------- */

typedef struct rt_viewer_desc {
    const char *pack_dir;
    const char *scene;        /* scene.sg to watch for hot reload; NULL: the
                                 manifest's scene.source, if any           */
    int         width, height;
    const char *script;       /* "frames=30;screenshot=out.png;quit" or NULL  */
    rt_render_desc render;
    bool        shading_set;  /* render.shading asked for; else the screen
                                 path where the pack has compute variants
                                 and no multi-pass reference, as headless */
    bool        have_camera;  /* camera below is set; else preset/default   */
    rt_camera   camera;
    const char *preset;       /* manifest camera name or NULL               */
    splat_view  view;
    const char *view_name;    /* --view text, parsed against the pack       */
    const char *const *include; /* -I folders for the scene's imports, as   */
    int         ninclude;       /* splatc has them (splat_search_path)      */
    const char *preview;        /* a material's swatch pack: hot reload
                                   rebuilds it with splatc build --preview  */
} rt_viewer_desc;

/* Runs until the window closes or the script quits; returns the exit
 * status (0 ok). */
int rt_viewer_run(const rt_viewer_desc *desc);

#endif
