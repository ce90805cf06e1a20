/* rt_internal.h — libsplatrt's internals, shared by its source files and
 * by the tests that reach inside (not installed; splatrt.h is the public
 * API, as Lua keeps lstate.h beside lua.h).
 *
 * Sections: the structs behind splatrt.h's rt_device and rt_pack (with
 * their in-place create/load; handles.c wraps them), errors, device.c
 * (buffers, images, one-shot commands),
 * shader_compile.c, spirv_check.c, pack_load.c (files inside the pack
 * folder, combos.bin), painted_upload.c, terrain_upload.c, quadtree.c,
 * pipelines.c, screen.c, destruction.c.
 */
#ifndef SPLAT_RT_INTERNAL_H
#define SPLAT_RT_INTERNAL_H

#include "splatrt.h"
#include "cache.h"

#include <pthread.h>
#include <stdatomic.h>
#include <vulkan/vulkan.h>

#include "far_atlas.h"
#include "sparse.h"
#include "stand_in.h"

/* ---- the device and the pack, behind splatrt.h's opaque handles ----------
 * (moved here from splatrt.h: the runtime's files and the tests of its
 * insides read the fields; tools go through rt_device_open, rt_pack_open
 * and the accessors.) */

struct rt_device {
    VkInstance               instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice         phys;
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceMemoryProperties mem;
    VkDevice                 dev;
    VkQueue                  queue;
    uint32_t                 queue_family;
    VkCommandPool            pool;       /* resettable command buffers      */
    bool                     wireframe;  /* fillModeNonSolid enabled        */
    bool                     bc;         /* textureCompressionBC enabled    */
    bool                     count_fragments; /* fragmentStoresAndAtomics and
                                            fragment subgroup votes: the
                                            forward counting variant       */
    bool                     int64_atomics; /* shaderInt64 and
                                            shaderBufferInt64Atomics enabled */
    bool                     validating;
    int                      messages;   /* validation warnings + errors    */
    struct rt_vk_batch      *batch;      /* pipelines deferred to run on all
                                            cores (vk_build.c rt_vk_batch_*) */
    pthread_t                glslang_warm; /* glslang's warm-up (below)     */
    bool                     warming;    /* ... started, not joined yet     */
};

/* glslang's first compile in a process sets up its built-in symbol tables
 * for every stage (85-174 ms on this project's 2-core machine: the
 * first picture's largest compile at load once the pack brings every
 * module it needs as SPIR-V).  rt_device_create starts a thread that
 * compiles a trivial shader meanwhile, so that setup overlaps the
 * device's creation and the pack's objects instead of delaying the
 * renderer's first GLSL compile (its own shaders: the decal, sky,
 * classification, undergrowth); rt_device_destroy joins it (device.c).
 * SPLAT_GLSLANG_WARM_UP=0 leaves it out (timing). */

/* In place, for the library's own devices (the viewer's, the far bake's);
 * rt_device_open allocates one around it. */
bool rt_device_create(rt_device *d, const rt_device_desc *desc, rt_error *e);
void rt_device_destroy(rt_device *d);

typedef struct rt_buffer {
    VkBuffer       buf;
    VkDeviceMemory mem;
    VkDeviceSize   size;
    void          *map;      /* persistently mapped when host visible       */
} rt_buffer;

typedef struct rt_image {
    VkImage        img;
    VkDeviceMemory mem;
    VkImageView    view;
    VkFormat       format;
    uint32_t       width, height, layers, mips;
} rt_image;


/* A shader file of the pack, read on first use (pack_shaders.c): loading
 * the pack checks its name, that it is a regular file inside the pack and
 * its size (a zstd frame's stated size) against the limits; the first
 * rt_pack_spirv / rt_pack_text reads it, decompresses it and, for SPIR-V,
 * runs spirv-val (once per module shape: cache.h) and the check against
 * its role's interface (rt_spirv_check), so no module reaches the driver
 * unchecked.  Thread-safe: pipelines are made on worker threads. */
typedef struct rt_module rt_module;

typedef struct rt_spirv {
    char      *path;      /* relative to the pack; NULL: absent            */
    uint32_t  *words;     /* a module the caller set (a tool's variant,
                             checked by it); NULL: the pack's, read on
                             first use through rt_pack_spirv             */
    size_t     nwords;
    rt_module *mod;       /* the pack's lazy module; NULL: none            */
} rt_spirv;

/* A GLSL text of the pack (compute variants, distance classes), read on
 * first use through rt_pack_text; mod NULL: absent. */
typedef struct rt_text {
    char      *path;
    rt_module *mod;
} rt_text;

static inline bool rt_spirv_present(const rt_spirv *s) { return s->words || s->mod; }

typedef struct rt_pack_camera {
    char  *name;
    double position[3], look[3];
} rt_pack_camera;

typedef struct rt_pack_material {
    char    *name;
    char    *source;      /* graph file, relative to the scene (hot reload) */
    rt_spirv reference;   /* SPLAT_MULTIPASS pass; may be absent            */
} rt_pack_material;

typedef struct rt_pack_param {
    char  *name;
    float  value[4];      /* default                                       */
    uint32_t offset;      /* bytes into the params block                    */
    int    width;         /* components (manifest "type"; 4 if absent)      */
    bool   has_range;     /* "min" < "max" given: the declared range, which
                             the pack's analysis assumed                    */
    double min, max;
} rt_pack_param;

typedef struct rt_pack_texture {
    char    *file;
    uint32_t binding;     /* 1 + its texture array (abi.h set 1)           */
    int      layer;       /* its layer in that array                       */
    bool     linear, mip_linear, srgb;
    VkSamplerAddressMode wrap;
    uint8_t *rgba;        /* decoded RGBA8                                 */
    int      width, height;
    uint8_t **mips;       /* stored levels 1..nmips (manifest "mips", files
                             "X.mipK.png"; level k is max(1, w >> k) x
                             max(1, h >> k)); NULL: the runtime blits them */
    int      nmips;
} rt_pack_texture;

/* A texture array of set 1: textures of one size, mip count and sampler
 * state, textures[layer] = the index of the texture at that layer. */
typedef struct rt_pack_array {
    int     *textures;
    int      nlayers;
} rt_pack_array;

typedef struct rt_pack_combo {
    int     *materials;   /* scene indices, top first                       */
    int      nmaterials;
    rt_spirv spirv;
    rt_text  compute;     /* compute variant's GLSL (PACK.md); mod NULL: none */
    rt_text  ug_compute;  /* undergrowth mask GLSL (PACK.md); mod NULL: none */
    rt_spirv compute_spirv; /* their SPIR-V as the build made it (absent:
                             compiled from the GLSL on first use)         */
    rt_spirv ug_spirv;
    double   cost;        /* per-pixel cost, op-table units; 0: not given   */
    /* Distance classes (PACK.md): entries nbase.. of rt_pack.combos are
     * the class variants, after the combinations of combos.bin; a class
     * holds where view.distance lies in [dlo, dhi] (base ones [0, inf]).
     * Its fragment shader may come as GLSL alone (spirv absent),
     * compiled on first use. */
    int      base;        /* the combination it is a variant of (own id)    */
    double   dlo, dhi;    /* metres; dhi INFINITY: and beyond               */
    rt_text  glsl;        /* a class's fragment GLSL; absent for the others */
    char    *frag_path;   /* "glsl" beside "spirv": the forward counting
                             variant's source, read on first use
                             (rt_pack_read_glsl); NULL: absent              */
    int      first_class, nclasses; /* a combination's classes, contiguous */
} rt_pack_combo;

typedef struct rt_pack_level {
    int       width, height;
    uint16_t *ids;        /* combination per node, row-major                */
} rt_pack_level;

/* A periodic site of terrain.position (compiler/precision.c). */
typedef struct rt_pack_site {
    int    axes[2];         /* camera components: 0 x, 1 y, 2 z          */
    bool   mul;             /* position * scale; else / scale            */
    int    param;           /* params index of the scale, or -1          */
    double scale[2];        /* constant scale per component              */
} rt_pack_site;


/* Undergrowth (PACK.md "Undergrowth"): a block of a material, and the
 * meshes, every one's vertices (8 floats: position, normal, uv) and
 * indices concatenated. */
typedef struct rt_pack_ug_block {
    int      material, slot, mesh;
    double   density, scale[2], blend, root_blend, color[3];
    bool     align_normal;
    bool     light_terrain;  /* lit with the terrain normal (else the mesh's) */
    int      cutout;         /* 0 none, 1 a leaf cut from the mesh's quads
                                (frond), 2 the texture's alpha, dithered  */
    int      texture;        /* index into the pack's textures, or -1       */
    double   wind[4];        /* direction x, z (unit), sway at 1 m, gust     */
    double   shadow;         /* darkening of the ground under an instance    */
} rt_pack_ug_block;

typedef struct rt_pack_ug_mesh {
    uint32_t nv, nidx;
    uint32_t first_vertex, first_index;
    int      far;          /* the mesh drawn beyond the LOD distance, or -1 */
} rt_pack_ug_mesh;

typedef struct rt_pack_ug_texture {
    int      width, height;
    uint8_t *rgba;                 /* rows top first; sRGB rgb, alpha       */
} rt_pack_ug_texture;

typedef struct rt_pack_ug {
    int               nslots;      /* 0: the pack has no undergrowth        */
    rt_pack_ug_texture *textures; int ntextures;   /* ugtex.bin             */
    rt_pack_ug_block *blocks;  int nblocks;
    rt_pack_ug_mesh  *meshes;  int nmeshes;
    float            *vertices;    /* 8 per vertex                          */
    uint32_t          nvertices;
    uint32_t         *indices;     /* per mesh, from its own vertex 0       */
    uint32_t          nindices;
} rt_pack_ug;

/* The far atlas (compiler/far_atlas.h): far.atlas as read, checked. */
typedef struct rt_pack_far {
    uint8_t *data;             /* the whole file; NULL: the pack has none  */
    size_t   n;
    int      width, height, levels;
    double   texel[2];         /* metres per level-0 texel                  */
} rt_pack_far;

struct rt_pack {
    char            *dir;
    char            *name;
    int              hf_width, hf_height;
    uint16_t        *heights;        /* hf_width * hf_height               */
    rt_pack_site     sites[SPLAT_WORLD_SITES];  /* u_frame.world (abi.h)  */
    int              nsites;
    uint8_t         *holes;          /* hf_width * hf_height, 255 = cut, or
                                        NULL: no holes (PACK.md)           */
    double           size[2], max_height, height_offset;
    int              cell_texels;
    rt_pack_camera  *cameras;   int ncameras;
    rt_pack_material *materials; int nmaterials;
    rt_pack_param   *params;    int nparams;
    uint32_t         params_size;
    rt_pack_texture *textures;  int ntextures;
    rt_pack_array   *arrays;    int narrays;     /* binding 1 + index    */
    int              npainted;
    uint8_t         *painted;        /* npainted * W * H, NULL if none or
                                        sparse                             */
    sparse_masks    *sparse;         /* painted.sparse (painted_format bc4
                                        or r8), NULL: dense painted         */
    bool             has_destruction; /* scene.destruction is not null      */
    double           destr_origin[2], destr_size[2], destr_cell; /* metres */
    rt_pack_combo   *combos;    int ncombos;  /* combinations, then their
                                                 distance classes           */
    int              nbase;          /* combinations of combos.bin          */
    rt_spirv         uber;           /* absent: no über-shader             */
    char            *uber_frag_path; /* its fragment GLSL ("glsl"); NULL if
                                        absent: read on first use          */
    rt_text          uber_compute;   /* its compute GLSL; mod NULL if absent */
    rt_spirv         uber_compute_spirv; /* its SPIR-V; may be absent       */
    rt_spirv         stand_in[SPLAT_STAND_IN_KINDS]; /* "uber"."stand_in": the
                                        stand-ins' SPIR-V (stand_in.h); mod
                                        NULL if absent (the runtime then
                                        compiles them from uber_compute)   */
    rt_spirv         vertex;
    rt_pack_level   *levels;    int nlevels;
    char            *scene_path;     /* scene.source: scene.sg relative to
                                        the pack (hot reload), or NULL      */
    rt_light         light;          /* scene.light over the defaults       */
    rt_pack_ug       ug;             /* undergrowth; ug.nslots 0: none      */
    rt_pack_far      far;            /* far atlas; far.data NULL: none      */
    uint32_t        *vectors;        /* vectors.bin's words (abi.h "vector
                                        shapes' buffer"), validated; NULL:
                                        the pack has no spline or polygon */
    size_t           nvectors;       /* words                               */
    struct rt_pack_shaders *shaders; /* the shader files read on first use
                                        (pack_shaders.c)                   */
};

/* Read and check a pack, untrusted input: every file it names is a
 * regular file inside the pack folder (rt_pack_read_file) of the right
 * size, every size within the pack limits (abi.h), every combination id
 * in combos.bin is in range.  Its shaders are read on first use
 * (rt_module): each SPIR-V module validates and fits the interface of its
 * role (rt_spirv_check) before it is handed out.  Errors name the pack
 * file and what is wrong. */
bool rt_pack_load(rt_pack *p, const char *dir, rt_error *e);
/* A shader module of the pack, read, validated and checked on its first
 * use (then kept); NULL with *e set when it does not pass, the same
 * message on every call.  `s->words`, where a caller set them, are
 * returned as they are. */
const uint32_t *rt_pack_spirv(const rt_pack *p, const rt_spirv *s, size_t *nwords, rt_error *e);
/* A GLSL text of the pack, read on first use (NUL-terminated, no NUL in
 * it); NULL with *e set. */
const char *rt_pack_text(const rt_pack *p, const rt_text *t, rt_error *e);
/* A shader's size in bytes as loading checked it (nothing is read): a
 * cost estimate of making its pipeline; 0 when absent. */
size_t rt_pack_spirv_size(const rt_spirv *s);
size_t rt_pack_text_size(const rt_text *t);
/* The shader files the pack names; *read: of them read and checked so far. */
int rt_pack_shader_count(const rt_pack *p, int *read);
/* Free what rt_pack_load allocated (not p itself); rt_pack_open and
 * rt_pack_close allocate and free the struct around these two. */
void rt_pack_free(rt_pack *p);

/* The offscreen colour image (TRANSFER_SRC_OPTIMAL after a frame). */
const rt_image *rt_renderer_target(const rt_renderer *r);

/* ---- errors (device.c) ------------------------------------------------- */

const char *rt_vk_result_name(VkResult r);

/* Check a VkResult at run time (never only inside assert). */
#define RT_VK(e, call)                                                      \
    do {                                                                    \
        VkResult rt_vk_r_ = (call);                                         \
        if (rt_vk_r_ != VK_SUCCESS)                                         \
            return rt_fail((e), RT_E_VULKAN, #call, rt_vk_result_name(rt_vk_r_)); \
    } while (0)

/* ---- device.c: buffers, images, one-shot commands ---------------------- */

bool rt_buffer_create(rt_device *d, VkDeviceSize size, VkBufferUsageFlags usage,
                      bool host_visible, rt_buffer *b, rt_error *e);
void rt_buffer_destroy(rt_device *d, rt_buffer *b);
/* A 2D image with a view of every layer and mip (a 2D_ARRAY view when
 * `array`, even for one layer). */
bool rt_image_create(rt_device *d, uint32_t w, uint32_t h, uint32_t layers,
                     bool array, uint32_t mips, VkFormat fmt, VkImageUsageFlags usage,
                     VkImageAspectFlags aspect, rt_image *img, rt_error *e);
void rt_image_destroy(rt_device *d, rt_image *img);
/* Upload tightly packed texels into mip 0 of every layer, then either build
 * the mip chain by blits (mips > 1) and leave the image in
 * SHADER_READ_ONLY_OPTIMAL.  Blocks until done (load time only). */
bool rt_image_upload(rt_device *d, rt_image *img, const void *data,
                     size_t bytes, rt_error *e);
/* Upload every mip level of every layer of an RGBA8 image from
 * `levels[layer * mips + m]`
 * (tightly packed, max(1, w >> m) x max(1, h >> m)) instead of blitting:
 * for mips that must not be box-filtered.  Leaves SHADER_READ_ONLY. */
bool rt_image_upload_levels(rt_device *d, rt_image *img, const uint8_t *const *levels,
                            rt_error *e);
/* One-time command buffer helpers (load time only). */
bool rt_oneshot_begin(rt_device *d, VkCommandBuffer *cb, rt_error *e);
bool rt_oneshot_end(rt_device *d, VkCommandBuffer cb, rt_error *e);
/* Record a global memory barrier: `sa` writes of stages `src` made
 * visible to `da` accesses of stages `dst`. */
void rt_cmd_barrier(VkCommandBuffer cb, VkPipelineStageFlags src, VkAccessFlags sa,
                    VkPipelineStageFlags dst, VkAccessFlags da);
/* Record a layout transition of mips [mip, mip + nmips) of the first
 * `layers` layers of a colour image. */
void rt_cmd_image_barrier(VkCommandBuffer cb, VkImage img, uint32_t mip, uint32_t nmips,
                          uint32_t layers, VkImageLayout from, VkImageLayout to,
                          VkAccessFlags src_access, VkAccessFlags dst_access,
                          VkPipelineStageFlags src, VkPipelineStageFlags dst);
bool rt_format_supports(rt_device *d, VkFormat f, VkFormatFeatureFlags need);
/* The sampler address mode of an ir_wrap (ir.h IR_WRAPS). */
VkSamplerAddressMode rt_sampler_wrap(int ir_wrap);

/* ---- shader_compile.c: GLSL -> SPIR-V for the runtime's shaders ------ */

/* stage: VK_SHADER_STAGE_VERTEX_BIT, _FRAGMENT_BIT or _COMPUTE_BIT.
 * *words is malloc'd. */
bool rt_glsl_compile(const char *glsl, VkShaderStageFlagBits stage,
                     const char *name, uint32_t **words, size_t *nwords,
                     rt_error *e);
/* SPIRV-Tools validation for Vulkan 1.2; message in e on failure. */
bool rt_spirv_validate(const uint32_t *words, size_t nwords, const char *name,
                       rt_error *e);
struct rt_interface;
/* The runtime's GLSL to a shader module: glslang, spirv-val, and when
 * `check` is given (a pack's shader) rt_spirv_check against it. */
bool rt_glsl_module(rt_device *d, const char *glsl, VkShaderStageFlagBits stage,
                    const char *name, const struct rt_interface *check, VkShaderModule *out,
                    rt_error *e);

/* ---- jobs.c: independent jobs on every core ------------------------- */

/* Job k of n; false with *e set stops the jobs not yet started. */
typedef bool (*rt_job_fn)(void *ctx, int k, rt_error *e);
/* Run fn for k = 0..n-1 on min(cores, 16, n) threads, the caller's among
 * them; false with the first failure in *e. */
bool rt_parallel(int n, rt_job_fn fn, void *ctx, rt_error *e);
/* The threads rt_parallel would use for n jobs. */
int  rt_job_threads(int n);

/* The pack's GLSL with `defs` (lines of #define) after its #version line
 * (abi.h: the counting, sorted and bake variants are never stored);
 * malloc'd, NULL when out of memory (pipelines.c). */
char *rt_glsl_with_defines(const char *glsl, const char *defs);
/* Set 0 of a terrain bake (undergrowth masks, far atlas; compute stage):
 * the terrain's bindings without the screen path's, copied from the
 * graphics set 0 `src`, and a frame block of the bake's own (pipelines.c). */
bool rt_terrain_compute_layout(rt_device *d, VkDescriptorSetLayout *out, rt_error *e);
void rt_terrain_compute_set(rt_device *d, VkDescriptorSet src, VkDescriptorSet dst,
                            VkBuffer frame);

/* ---- spirv_check.c: a pack shader against what it is bound to --------- */

typedef enum rt_res {
    RT_RES_UNIFORM = 1,       /* uniform block                              */
    RT_RES_SAMPLED,           /* combined image sampler                     */
    RT_RES_STORAGE_IMAGE,
    RT_RES_STORAGE_BUFFER,
} rt_res;

enum { RT_FLOAT = 1, RT_UINT, RT_INT };             /* image component types */
enum { RT_IMAGE_2D = 1 };                           /* SpvDim2D              */
typedef enum rt_painted_when {
    RT_PAINTED_ANY = 0, RT_PAINTED_DENSE, RT_PAINTED_SPARSE,
} rt_painted_when;

/* One binding of a pipeline layout, as a shader may declare it. */
typedef struct rt_binding_rule {
    uint32_t set, binding;
    rt_res   kind;
    uint8_t  dim;             /* images: SpvDim (RT_IMAGE_2D)               */
    bool     arrayed;         /* images: 2D array                           */
    uint8_t  comp;            /* images: RT_FLOAT / RT_UINT / RT_INT        */
    uint32_t bytes;           /* blocks: at most this many bytes declared   */
    VkShaderStageFlags stages; /* stages the layout makes it visible to     */
    rt_painted_when painted;  /* packs whose painted format has this row    */
} rt_binding_rule;

/* The ABI's set-0 rows (compiler/abi.h), one per binding and painted
 * format: a new set-0 binding (compute passes, shadows) is one more row. */
extern const rt_binding_rule rt_abi_bindings[];
extern const int rt_abi_nbindings;

typedef struct rt_varying {
    uint32_t location;
    int      components;      /* float vector size                          */
} rt_varying;

/* What a shader must fit. */
typedef struct rt_interface {
    const char *what;               /* "a composite fragment shader"        */
    VkShaderStageFlagBits stage;    /* entry point "main" of this stage     */
    const rt_binding_rule *bindings; int nbindings;
    rt_painted_when painted;        /* the pack's painted format            */
    uint32_t push_bytes;            /* push-constant block at most          */
    const uint32_t *spec_ids; int nspec;   /* constant_ids the runtime sets */
    const rt_varying *inputs; int ninputs;   /* allowed stage inputs        */
    const rt_varying *outputs; int noutputs; /* allowed stage outputs       */
    bool     outputs_exact;         /* every listed output written          */
    int      colour_targets;        /* fragment: float outputs at locations
                                       below this, instead of `outputs`     */
} rt_interface;

struct rt_pack;

typedef enum rt_shader_role {
    RT_ROLE_VERTEX, RT_ROLE_COMPOSITE, RT_ROLE_REFERENCE,
    RT_ROLE_COMPUTE,      /* the compute variants (*.comp.spv, abi.h)       */
    RT_ROLE_UNDERGROWTH,  /* undergrowth mask shaders (*.ug.comp, abi.h)    */
    RT_ROLE_FAR_BAKE,     /* far atlas bake variants (abi.h, far_bake.c)    */
    RT_ROLE_FAR,          /* the far atlas's compute shader (the far list, the
                             atlas stand-in): the compute role's bindings and
                             the atlas at set 2 bindings 5-7 (stand_in.h)  */
    RT_ROLE_COUNT,
} rt_shader_role;

/* The interface of a pack shader role: the ABI rows plus the pack's set 1
 * (params block of params_size bytes, its textures).  Free with
 * rt_interface_free; false: out of memory. */
bool rt_interface_for(const struct rt_pack *p, rt_shader_role role, rt_interface *out);
void rt_interface_free(rt_interface *in);
/* Reflect `words` (already through spirv-val) with SPIRV-Cross and check
 * it against `want`; RT_E_PACK_SHADER naming `path` and the mismatch. */
bool rt_spirv_check(const uint32_t *words, size_t nwords, const char *path,
                    const rt_interface *want, rt_error *e);

/* ---- pack_load.c: files inside the pack folder, combos.bin ----------- */

/* The runtime's one way into a pack folder: open `rel` below the folder
 * `dirfd` component by component with O_NOFOLLOW — no absolute path, no
 * "..", no symbolic link on the way, a regular file at the end (never a
 * FIFO or device).  Returns the descriptor, or -1 with `why` saying what
 * is wrong ("is a symbolic link ..."). */
int      rt_pack_open_file(int dirfd, const char *rel, char *why, size_t nwhy);
/* rt_pack_open_file, then the whole file if fstat says it has at most
 * `max` bytes (bounded reads; NUL appended, not counted in *n). */
uint8_t *rt_pack_read_file(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                           size_t nwhy);
/* rt_pack_read_file, or for a name ending in ".zst" its content (PACK.md
 * "Compressed shaders"): the file within the largest frame of `max`
 * bytes, the frame's stated size at most `max` before its buffer is
 * allocated, exactly one frame that decompresses to that size (its
 * checksum checked).  `max` bounds the content either way. */
uint8_t *rt_pack_read_content(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                              size_t nwhy);
/* What rt_pack_read_content checks before it reads: the file opened as
 * rt_pack_open_file does, its size (a ".zst" file's: its frame header's
 * stated content size) at most `max`, in *n; no content is read. */
bool     rt_pack_stat_content(int dirfd, const char *rel, size_t max, size_t *n, char *why,
                              size_t nwhy);
/* The GLSL text at `rel` in p's folder (the manifest's `field`), read now
 * under the same checks (malloc'd); NULL with `e` set if it cannot be. */
char    *rt_pack_read_glsl(const rt_pack *p, const char *field, const char *rel, rt_error *e);
/* combos.bin (PACK.md) of `n` bytes: the rt_level_count(cells_x, cells_z)
 * levels, level L (cells halved L times, rounding up) at offsets[L]; every
 * level inside the file and every id below ncombos, checked before each
 * level is allocated (SPLAT_COMBO_HOLE is also accepted when `holes`: the
 * pack has a holes raster; SPLAT_COMBO_UBER above level 0).  Fills levels[0..nlevels); errors name `path`. */
bool rt_combos_parse(const uint8_t *data, size_t n, int cells_x, int cells_z,
                     const int64_t *offsets, int ncombos, bool holes,
                     rt_pack_level *levels, const char *path, rt_error *e);
/* ---- painted_upload.c: the sparse painted masks ----------------------- */

/* Parse the `n` bytes of `file` (painted.sparse, read by the pack loader)
 * into p->sparse and check them against the manifest (heightfield size,
 * mask count); errors name `manifest` and `file`. */
bool rt_painted_read(rt_pack *p, const char *manifest, const char *file,
                     const uint8_t *data, size_t n, rt_error *e);
/* Upload p->sparse: atlas (BC4_UNORM_BLOCK, or R8_UNORM decoded on the
 * CPU when the device lacks BC textures), index RGBA16UI and level
 * RGBA8UI 2D arrays. */
bool rt_painted_upload(rt_device *d, const rt_pack *p, rt_image *atlas,
                       rt_image *index, rt_image *level, rt_error *e);

/* ---- terrain_upload.c: heightfield on the GPU, node height bounds ----- */

/* Min/max height (metres) of every quadtree node, from the texels its
 * vertices can sample (bilinear between texel centres, one texel border). */
typedef struct rt_bounds {
    int     nlevels;
    int    *width, *height;   /* nodes per level                            */
    float **hmin, **hmax;     /* per level, row-major                       */
} rt_bounds;

bool rt_bounds_build(rt_bounds *b, const uint16_t *texels, int w, int h,
                     int cell_texels, double max_height, double offset);
void rt_bounds_free(rt_bounds *b);
/* Leaf (x, z): the min and max height (metres) of the texels it can show,
 * its cell plus one texel around (the build, and destruction's update). */
void rt_bounds_leaf(rt_bounds *b, const uint16_t *texels, int w, int h, int cell_texels,
                    double max_height, double offset, int x, int z);
/* Node (x, z) of level L >= 1: the min and max of its (up to 4) children
 * on level L - 1 (the build, and destruction's update after a crater). */
void rt_bounds_merge(rt_bounds *b, int L, int x, int z);
/* Level grid of PACK.md: cells, then halve (rounding up) until 1x1. */
int  rt_level_count(int cells_x, int cells_z);

/* GPU resources of the terrain descriptor set (set 0) but the frame UBO. */
typedef struct rt_terrain_gpu {
    rt_image  height;       /* R16_UNORM                                    */
    rt_image  painted;      /* R8_UNORM array, >= 1 layer; sparse: the atlas */
    rt_image  painted_index; /* RGBA16UI array (1x1 when dense)              */
    rt_image  painted_level; /* RGBA8UI array (1x1 when dense)               */
    rt_image  destr_atlas;  /* R8_UNORM destruction mask tiles (destruction.c) */
    rt_image  destr_index;  /* RGBA8 1x1, a = 0: nothing destroyed          */
    rt_image  holes;        /* R8_UNORM W x H (1x1 of 0: none), binding 12  */
    rt_image  shadow;       /* R8_UNORM W x H sun visibility (shadow.c)     */
    VkSampler linear_clamp, nearest_clamp;
} rt_terrain_gpu;

bool rt_terrain_upload(rt_device *d, const rt_pack *p, rt_terrain_gpu *t,
                       rt_error *e);
void rt_terrain_destroy(rt_device *d, rt_terrain_gpu *t);

/* ---- quadtree.c: restricted quadtree LOD, culling, stitching ---------- */

/* Edges of a patch: N = z min, E = x max, S = z max, W = x min. */
enum { RT_EDGE_N = 1, RT_EDGE_E = 2, RT_EDGE_S = 4, RT_EDGE_W = 8 };
#define RT_PERMS 9   /* none, N, E, S, W, NE, ES, SW, WN (Andersson 2007 Fig. 18) */

/* The index-buffer permutation drawn for a set of coarser edges, and the
 * coarser edges of a permutation. */
int      rt_perm_of_edges(unsigned edges);   /* -1 for opposite edges       */
unsigned rt_edges_of_perm(int perm);
/* Vertices of the shared grid: SPLAT_GRID^2 vec2 in 0..1, x fastest. */
void     rt_grid_vertices(float *xy);
/* Triangle list of one permutation over the grid: odd vertices of the
 * coarser edges are folded onto their even neighbours (an edge collapse),
 * so those edges use only every other vertex, and the triangles that
 * became degenerate are dropped.  Returns the index count; `out` may be
 * NULL to ask for it (at most 6 * (SPLAT_GRID-1)^2). */
uint32_t rt_grid_indices(int perm, uint16_t *out);

typedef struct rt_patch {
    uint8_t  level, perm;
    uint16_t combo;
    int      x, z;            /* node at `level`                            */
} rt_patch;

typedef struct rt_select_desc {
    double camera[3];          /* terrain-local metres                       */
    float  view_proj[16];      /* camera-relative world -> clip             */
    double lod_distance;       /* split while distance < this * node size   */
    bool   cull;               /* frustum culling (default on by caller)   */
    int    max_level_bias;     /* tests: 0                                   */
    bool   split_uncovered;    /* split coarse nodes that no compiled
                                  combination covers (SPLAT_COMBO_UBER),
                                  down to nodes that have one             */
    double uncovered_far;      /* > 0: except nodes at least this far (m):
                                  the far atlas shades them               */
} rt_select_desc;

typedef struct rt_quadtree {
    int        nlevels;
    int       *width, *height;    /* nodes per level                         */
    int        cell_texels, hf_width, hf_height;
    double     size[2];           /* terrain metres                          */
    const rt_bounds *bounds;
    const uint16_t *const *combo_ids; /* per level (pack); NULL: all 0     */
    uint8_t  **split;             /* per level scratch, reused every frame   */
    rt_patch  *patches;           /* the selection (drawn patches)           */
    int        nsplit_uncovered;  /* nodes split only because no compiled
                                     combination covers them (last select) */
    int        npatches, cap;
    int        nculled;           /* leaves dropped by the frustum           */
    int        nholes;            /* nodes not drawn: all hole (PACK.md)     */
    double     planes[6][4];      /* the last selection's frustum (culling)  */
    double     camera[3];         /* and its camera                          */
    bool       culled;            /* whether it culled                       */
} rt_quadtree;

bool rt_quadtree_init(rt_quadtree *q, const rt_bounds *b, int cell_texels,
                      int hf_width, int hf_height, const double size[2]);
void rt_quadtree_free(rt_quadtree *q);
/* Select the patches for a camera: split by distance, restrict so that edge
 * neighbours differ by at most one level, cull, pick each patch's
 * permutation.  No allocation after init. */
void rt_quadtree_select(rt_quadtree *q, const rt_select_desc *s);
/* Distance classes (PACK.md) are used only where a node's or tile's
 * distance range, widened by this fraction, lies inside the class's
 * interval: the shaders' fp32 distance (length of an interpolated or
 * reconstructed position) differs from the runtime's by far less. */
#define RT_DCLASS_SLACK 1e-3

/* The nearest and farthest distance from `camera` (terrain-local metres)
 * to any point of node (level, x, z): its rectangle, not clipped to the
 * terrain, from its minimum to its maximum height (the box culling uses).
 * Everything its patch rasterises lies inside. */
void rt_node_distance(const rt_quadtree *q, int level, int x, int z, const double camera[3],
                      double *dmin, double *dmax);
/* Whether the last selection's frustum holds node (level, x, z)'s box
 * widened by `margin` m on every side (always true when it did not
 * cull): everything drawn of it lies inside. */
bool rt_quadtree_node_visible(const rt_quadtree *q, int level, int x, int z, double margin);
/* World rectangle of a node (metres; may overhang the terrain). */
void rt_node_rect(const rt_quadtree *q, int level, int x, int z,
                  double *x0, double *z0, double *sx, double *sz);

/* ---- pipelines.c: layouts, pipelines, the on-disk pipeline cache ------ */


/* Variants of a pipeline, as bits; each is made on first use. */
enum {
    RT_VARIANT_WIRE  = 1,  /* line fill                                     */
    RT_VARIANT_DEBUG = 2,  /* any debug view, read from u_frame each frame;
                              without it the fragment shader is specialised
                              to SPLAT_VIEW_FINAL (abi.h SPLAT_SPEC_VIEW) and
                              carries no debug-view code                    */
    RT_VARIANT_CULL  = 4,  /* back faces culled: only while the camera is
                              above the terrain (render.c), where it hides
                              nothing visible (a few ridge pixels change
                              where depth rounding let a back face win)     */
    RT_VARIANT_COUNT = 8,  /* the counting variant (abi.h SPLAT_COUNT),
                              compiled from the pack's fragment GLSL; needs
                              rt_device.count_fragments                     */
    RT_VARIANTS      = 16,
};

typedef struct rt_pipelines {
    VkDescriptorSetLayout set_terrain;   /* set 0 (abi.h)                    */
    VkDescriptorSetLayout set_material;  /* set 1: params + textures         */
    VkDescriptorSetLayout set_resolve;   /* set 2 of the resolve pass        */
    VkPipelineLayout      layout;        /* sets 0, 1 + splat_push           */
    VkPipelineLayout      resolve_layout;/* sets 0, 1, 2 + splat_push        */
    VkPipelineCache       cache;
    char                 *cache_path;    /* NULL: not saved                  */
    VkShaderModule        vertex;
    VkPipeline           *combo;         /* RT_VARIANTS per combination      */
    int                   ncombos;
    VkPipeline           *ref;           /* multi-pass: 2 per material
                                            (RT_VARIANT_CULL or not)         */
    int                   nref;
    VkPipeline            uber[RT_VARIANTS];
    VkPipeline            resolve;
    VkPipeline            sky;           /* the analytic sky, forward path  */
    VkPipelineLayout      compute_layout;/* sets 0, 1 + splat_push (compute) */
    int                   sort_tiles;    /* RT_CVARIANT_SORT: SPLAT_SORT_TILES */
    VkPipeline           *compute;       /* RT_CVARIANTS per combination, the
                                            über-shader's last              */
    VkPipeline            flat[8];       /* the flat stand-in, per RT_CVARIANTS */
    VkPipeline            depth[2];      /* geometry pass, [RT_VARIANT_CULL] */
    splat_cache           spv_cache;     /* compute variants' SPIR-V (cache.h) */
    struct rt_async      *async;         /* workers (async_compile.c) or NULL */
    atomic_int            spirv_cached;  /* compute modules found there      */
    atomic_int            spirv_compiled;/* ... and compiled with glslang    */
    uint32_t              shading_lod;   /* abi.h SPLAT_SPEC_LOD of the shading
                                            pipelines (rt_shading_lod_on)   */
} rt_pipelines;

/* Variants of a compute shading pipeline (screen-space path), as bits. */
enum {
    RT_CVARIANT_DEBUG = 1,  /* any debug view (else specialised to final)   */
    RT_CVARIANT_COUNT = 2,  /* the counting variant (abi.h SPLAT_COUNT)      */
    RT_CVARIANT_SORT  = 4,  /* the sorted variant (abi.h SPLAT_SORT)         */
    RT_CVARIANTS      = 8,
};

/* Render passes the pipelines are made for (render.c creates them). */
typedef struct rt_passes {
    VkRenderPass main;       /* RGBA32F colour + D32 depth                   */
    VkRenderPass multi;      /* three RGBA32F blend targets + D32 depth      */
    VkRenderPass resolve;    /* RGBA32F colour                               */
} rt_passes;

/* Layouts, the pipeline cache and the resolve pass for RT_REF_MULTIPASS;
 * checks that the shaders `ref` needs are in the pack.  Combination,
 * über-shader and reference pipelines are made on first use
 * (rt_pipelines_combo/uber/ref): a view of colorado needs 13-20 of its 137,
 * and lavapipe compiles each in tens of milliseconds or more. */
bool rt_shading_lod_on(const rt_device *d, rt_shading_lod want);
bool rt_pipelines_create(rt_device *d, const rt_pack *p, const rt_passes *rp,
                         rt_reference ref, const char *cache_path,
                         int ntextures, bool shading_lod, rt_pipelines *pl, rt_error *e);
/* The pipeline of combination `id` in `variant` (RT_VARIANT_* bits), made
 * now if it does not exist yet. */
/* A main-pass fragment pipeline from `glsl` over the terrain's vertex
 * shader, in `layout` (sets 0-1 and the push range as pl->layout's). */
bool rt_pipelines_glsl_fragment(rt_device *d, rt_pipelines *pl, const rt_passes *rp,
                                VkPipelineLayout layout, const char *glsl, const char *name,
                                unsigned variant, VkPipeline *out, rt_error *e);
/* The pipelines of combinations ids[0..n) in `variant`, made at once on
 * all cores: compute (screen path; rp unused) or composites (forward).
 * Compute with pl->async, where rt_pipelines_stand_in says the über-shader
 * costs less to make than they do: the über-shader's made instead; it
 * stands in for them from the next draw, after which they are queued on
 * the workers (rt_screen_missing). */
bool rt_pipelines_make(rt_device *d, const rt_pack *p, const rt_passes *rp, rt_pipelines *pl,
                       bool compute, const int *ids, int n, unsigned variant, rt_error *e);
/* What shades a screen list whose pipeline is not made yet, with async
 * pipelines (the lists' pipelines are made on the workers meanwhile). */
typedef enum rt_stand_in {
    RT_STAND_NONE = 0,  /* nothing: the list's pipeline is made before the
                           frame is drawn (again)                          */
    RT_STAND_UBER,      /* the über-shader (the final picture within 1/255) */
    RT_STAND_ATLAS,     /* the far atlas's shader (far.c), where the pack
                           has an atlas the device samples                 */
    RT_STAND_FLAT,      /* the flat stand-in: the lit terrain in one neutral
                           albedo (compiler/stand_in.h)                    */
} rt_stand_in;
/* The stand-in for compute pipelines ids[0..n) in `variant` (`atlas`: the
 * screen path can shade from a far atlas).  Before the frame (ids NULL,
 * the lists unknown): the über-shader where it is made already and the
 * device is a GPU (it costs nothing more to make; a CPU device pays for
 * its shading), else the far atlas where there is one and the device is
 * a GPU, else the flat stand-in, both nearly free to make, so the
 * über-shader is not compiled before the first picture.  After the frame, for the lists that got
 * tiles without a pipeline (only when nothing stood in before it): the
 * über-shader where making it costs less than making them (their
 * modules' bytes, over the cores that make them at once: one on a CPU
 * device, whose JIT runs in the frame on one thread), else none.
 * `SPLAT_STAND_IN` forces it (tests, benchmarks): `always` the
 * über-shader, `uber` the über-shader against the composites by that
 * cost (never a flat or atlas stand-in), `never` none (the composites
 * made at once), `atlas` the far atlas (else flat), `flat`; `auto` or
 * unset: the default above. */
rt_stand_in rt_pipelines_stand_in(const rt_device *d, const rt_pack *p, rt_pipelines *pl,
                                  const int *ids, int n, unsigned variant, bool atlas);
/* The SPIR-V of stand-in k (compiler/stand_in.h: the flat one, or the far
 * atlas's shader), `count`: its counting variant; *words malloc'd.  The
 * plain variant comes from the pack ("uber"."stand_in", read, validated
 * and checked against its role on first use) where the pack has it, so
 * nothing is compiled for the first picture; else (an older pack,
 * --glsl-compute, the counting variant) the über-shader's compute GLSL
 * cut at the prelude around the stand-in's main, from the SPIR-V cache or
 * glslang and spirv-val (counted in spirv_cached / spirv_compiled as the
 * compute variants are), checked against RT_ROLE_COMPUTE (flat) or
 * RT_ROLE_FAR (atlas). */
bool rt_pipelines_stand_in_spirv(const rt_pack *p, rt_pipelines *pl, splat_stand_in_kind k,
                                 bool count, uint32_t **words, size_t *n, rt_error *e);
/* The flat stand-in's compute pipeline in `variant` (compute layout),
 * made on first use from rt_pipelines_stand_in_spirv's module. */
bool rt_pipelines_flat(rt_device *d, const rt_pack *p, rt_pipelines *pl, unsigned variant,
                       VkPipeline *out, rt_error *e);
/* Whether combination id's pipeline of `variant` is made already. */
bool rt_pipelines_has_combo(const rt_pipelines *pl, int id, unsigned variant);
bool rt_pipelines_combo(rt_device *d, const rt_pack *p, const rt_passes *rp,
                        rt_pipelines *pl, int id, unsigned variant, VkPipeline *out,
                        rt_error *e);
/* The über-shader's pipeline in `variant`, made on first use. */
bool rt_pipelines_uber(rt_device *d, const rt_pack *p, const rt_passes *rp,
                       rt_pipelines *pl, unsigned variant, VkPipeline *out,
                       rt_error *e);
/* The multi-pass reference pass of scene material `m` (blended above
 * material 0), back faces culled or not, made on first use. */
bool rt_pipelines_ref(rt_device *d, const rt_pack *p, const rt_passes *rp,
                      rt_pipelines *pl, int m, bool cull, VkPipeline *out,
                      rt_error *e);
/* rt_pipelines_compute's pipeline (below) made and returned in *out, its
 * slot left alone: for the workers of async_compile.c. */
bool rt_pipelines_compute_make(rt_device *d, const rt_pack *p, rt_pipelines *pl, int id,
                               unsigned variant, VkPipeline *out, rt_error *e);

/* ---- async_compile.c: compute pipelines made on worker threads -------- */

/* Workers for pl (pl->async), each making what is requested with `make`
 * (rt_pipelines_compute_make: passed in, so this pool calls nothing of
 * pipelines.c by name); rt_async_stop joins them (destroy_combos does,
 * before a pack swap or the end) and drops what is still queued. */
typedef bool (*rt_async_make)(rt_device *d, const rt_pack *p, rt_pipelines *pl, int id,
                              unsigned variant, VkPipeline *out, rt_error *e);
bool       rt_async_start(rt_device *d, const rt_pack *p, rt_pipelines *pl, rt_async_make make,
                          rt_error *e);
void       rt_async_stop(rt_pipelines *pl);
/* Queue combination id's pipeline of `variant` unless made or queued. */
void       rt_async_request(rt_pipelines *pl, int id, unsigned variant);
/* Queued or being made. */
int        rt_async_pending(rt_pipelines *pl);
/* Until none is queued or being made. */
void       rt_async_wait(rt_pipelines *pl);
/* A worker's failure, handed over once (true, *e set). */
bool       rt_async_failed(rt_pipelines *pl, rt_error *e);
/* A compute slot read, and one filled (a pipeline made twice is destroyed;
 * returns what the slot holds), under the workers' lock while they run. */
VkPipeline rt_async_slot(rt_pipelines *pl, size_t slot);
VkPipeline rt_async_publish(rt_device *d, rt_pipelines *pl, size_t slot, VkPipeline pipe);

/* The compute shading pipeline of combination `id` (p->ncombos: the
 * über-shader) in `variant` (RT_CVARIANT_* bits), compiled from the pack's
 * compute GLSL on first use (PACK.md): glslang, spirv-val, the interface
 * check against set 0/1 and the push block, then the driver. */
bool rt_pipelines_compute(rt_device *d, const rt_pack *p, rt_pipelines *pl, int id,
                          unsigned variant, VkPipeline *out, rt_error *e);
/* The screen-space path's geometry pass: the shared vertex shader alone,
 * depth only (render pass `pass`), back faces culled or not. */
bool rt_pipelines_depth(rt_device *d, rt_pipelines *pl, VkRenderPass pass, bool cull,
                        VkPipeline *out, rt_error *e);
/* Whether that pipeline exists already. */
bool rt_pipelines_has_compute(rt_pipelines *pl, int id, unsigned variant);
/* Drop every combination pipeline (hot reload: the next frames make those
 * of the new pack); the array is resized to p->ncombos. */
bool rt_pipelines_reset_combos(rt_device *d, const rt_pack *p, rt_pipelines *pl,
                               rt_error *e);
/* Saves the cache (if it has a path) and destroys everything. */
void rt_pipelines_destroy(rt_device *d, rt_pipelines *pl);

/* ---- render_views.c: cameras ----------------------------------------------- */

/* The camera's vertical field of view in radians (its default if unset). */
double rt_camera_fovy(const rt_camera *c);

/* ---- screen.c: screen-space shading (render_record.c drives it) -------------- */

typedef struct rt_screen rt_screen;
typedef struct rt_far rt_far;   /* far.c */

/* The classification's view (issue 29): its cost follows the materials
 * in view, not the world's.  From the materials of the leaf cells under
 * the selected patches (and a ring of one cell around each), the
 * materials are renumbered in view order, so a set takes ceil(in view /
 * 32) words (1, or the pack's where more than 32 are in view), and the
 * cover search tries only the candidates: the combinations, in cost
 * order, that no earlier candidate dominates (one that covers all of its
 * materials in view and fits wherever it fits: a base combination, or a
 * class whose interval holds its interval).  Any set of materials in
 * view gets the combination the search over every combination would
 * pick.  A leaf cell whose combination has a material outside the view
 * (RT_CLASS_OUTSIDE; the selection's boxes hold every drawn pixel, so
 * none should) sends its tile to the über-shader. */
#define RT_CLASS_OUTSIDE 1u
typedef struct rt_class_view {
    int       words;      /* words per material set: 1, or the pack's       */
    int       nview;      /* materials in view                              */
    int       ncand;      /* candidates, in cost order                      */
    uint32_t *cand;       /* [ncombos] combination ids                      */
    uint32_t *rec;        /* [ncombos][1 + words]: RT_CLASS_OUTSIDE flag,
                             then the materials in view, renumbered         */
    int      *remap;      /* [nmaterials]: the bit in view, or -1           */
} rt_class_view;
/* The view of material set `vmask` (full_words words, scene indices);
 * `order`: the combinations in cost order; `dist`: [lo, hi] per
 * combination as the GPU compares them.  Reuses v's arrays; false when
 * out of memory. */
bool rt_class_view_build(const rt_pack *p, const uint32_t *order, const float *dist,
                         const uint32_t *vmask, int full_words, bool no_classes,
                         rt_class_view *v);
void rt_class_view_free(rt_class_view *v);


/* Buffers, the depth-only pass over `depth`, the classification pipeline;
 * writes set 0's compute bindings (abi.h 7-10) into `set0`.  `far`: the
 * far atlas (NULL: none), which must outlive the screen.  *out is set even
 * on failure (free with rt_screen_destroy). */
bool rt_screen_create(rt_device *d, const rt_pack *p, const rt_pipelines *pl,
                      const rt_image *color, const rt_image *depth, VkSampler nearest,
                      VkDescriptorSet set0, const rt_far *far, bool raycast,
                      rt_pixel_sort sort, int sort_tiles, rt_screen **out, rt_error *e);
/* raycast: the depth comes from ray casting the heightfield in compute
 * (screen.c) instead of the geometry pass. */
bool rt_screen_raycasting(const rt_screen *s);
/* Whether the shading dispatches take the sorted variant (RT_CVARIANT_SORT),
 * as `sort` and the device allow. */
bool rt_screen_sorting(const rt_screen *s);
/* Tiles per sorting workgroup (abi.h SPLAT_SORT_TILES); 0 when not sorting. */
int rt_screen_sort_tiles(const rt_screen *s);
/* The classification's tile order: rows of tiles (false, the default) or
 * 4x4 blocks of tiles, block after block (rt_render_desc.tile_blocks); the
 * lists then hold neighbours one after another.  Pictures do not change. */
void rt_screen_tile_blocks(rt_screen *s, bool on);
void rt_screen_raycast(rt_screen *s, VkCommandBuffer cb, VkDescriptorSet set0);
/* After the shading, when ray casting: the ray-cast depth copied into
 * `depth` (D32, through a buffer: a colour image cannot be copied into a
 * depth one), left SHADER_READ_ONLY_OPTIMAL as the geometry pass leaves
 * it, for the passes that depth-test against the terrain (undergrowth). */
void rt_screen_depth_out(rt_screen *s, VkCommandBuffer cb, const rt_image *depth);
void rt_screen_destroy(rt_screen *s);
/* The geometry pass: depth only, ends in SHADER_READ_ONLY_OPTIMAL. */
VkRenderPass rt_screen_depth_pass(const rt_screen *s, VkFramebuffer *fb);
/* The passes of the screen path (render_plan.c places the barriers
 * between them): reset the list counts (and the counters), by transfers,
 * and upload the classification's view of this frame's selection `q`
 * (rt_class_view; no_classes: without distance classes). */
bool rt_screen_begin(rt_screen *s, VkCommandBuffer cb, bool count, const rt_quadtree *q,
                     bool no_classes, rt_error *e);
/* The view of the last frame begun; NULL before one or when every tile
 * goes to the über-shader (more than 512 materials). */
const rt_class_view *rt_screen_class_view(const rt_screen *s);
/* The background, the classification (force_uber: every tile to the
 * über-shader's list; no_classes: no distance class variants); the colour
 * image is GENERAL. */
void rt_screen_classify(rt_screen *s, VkCommandBuffer cb, VkDescriptorSet set0,
                        const float clear[4], bool force_uber, bool no_classes, int *binds);
/* One indirect dispatch per list whose pipeline in `variant`
 * (RT_CVARIANT_*) exists; the others by `stand_in` (RT_STAND_NONE: left
 * for rt_screen_missing; RT_STAND_ATLAS without an atlas: flat). */
bool rt_screen_dispatch(rt_screen *s, VkCommandBuffer cb, rt_pipelines *pl,
                        const VkDescriptorSet sets[2], unsigned variant, rt_stand_in stand_in,
                        int *binds, rt_error *e);
/* The pipeline of `stand_in` in `variant` made now (renderer creation,
 * inside its batch), so the first frame does not make it. */
bool rt_screen_prepare_stand_in(rt_screen *s, rt_pipelines *pl, rt_stand_in stand_in,
                                unsigned variant, rt_error *e);
/* The far list from the far atlas, when it is on. */
bool rt_screen_far_on(const rt_screen *s);
bool rt_screen_dispatch_far(rt_screen *s, VkCommandBuffer cb, rt_pipelines *pl,
                            const VkDescriptorSet sets[2], unsigned variant, int *binds,
                            rt_error *e);
/* The list counts and counters copied for the host (rt_screen_read_stats). */
void rt_screen_counts(rt_screen *s, VkCommandBuffer cb);
/* After the frame completed: compiles the pipelines of lists that got
 * tiles but were not dispatched; returns how many (> 0: draw the frame
 * again), -1 on error.  Lists the über-shader stood in for are queued on
 * the workers instead (rt_async_request), not counted. */
int rt_screen_missing(rt_screen *s, rt_pipelines *pl, unsigned variant, rt_error *e);
void rt_screen_read_stats(const rt_screen *s, rt_screen_stats *st);
/* The counting variant's splat_counters (abi.h, any alignment) into the
 * stats' counting fields; both paths. */
void rt_counters_read(const void *counters, rt_screen_stats *st);
/* The far atlas (far.c): tiles whose nearest terrain pixel is at least
 * `distance` m away (0: off), outside the destructible area, are shaded
 * from it.  Nothing without an atlas in the pack (rt_screen_has_far). */
void rt_screen_far(rt_screen *s, double distance);
bool rt_screen_has_far(const rt_screen *s);
/* The ray caster's R32F depth (GENERAL once cast), NULL when the depth
 * comes from the geometry pass (upscale.c's guide). */
const rt_image *rt_screen_ray_depth(const rt_screen *s);

/* ---- upscale.c: the preview scale's depth-aware upsample ---------------- */

typedef struct rt_upscale rt_upscale;

/* `color` (the renderer's low-resolution target, read in GENERAL) into
 * `out` (the output size, written in GENERAL); `guide`: the low-resolution
 * reversed-Z depth in `guide_layout` (NULL: bilinear only).  *out is set
 * even on failure (free with rt_upscale_destroy). */
bool rt_upscale_create(rt_device *d, VkPipelineCache cache, VkSampler nearest,
                       const rt_image *color, const rt_image *guide, VkImageLayout guide_layout,
                       const rt_image *out, rt_upscale **u, rt_error *e);
/* One dispatch over the output; `guided`: the frame's path wrote the guide. */
void rt_upscale_record(rt_upscale *u, VkCommandBuffer cb, bool guided);
void rt_upscale_destroy(rt_upscale *u);

/* ---- far.c: the far atlas on the device ---------------------------------- */

/* p->far's three images (every stored level, SHADER_READ_ONLY) and the
 * forward path's set and layout; *out stays NULL without an atlas in the
 * pack or where the device does not sample BC1 sRGB, BC5 and BC4 with
 * linear filtering. */
bool  rt_far_create(rt_device *d, const rt_pack *p, const rt_pipelines *pl, rt_far **out,
                    rt_error *e);
void  rt_far_destroy(rt_far *f);
/* Image k (0 albedo, 1 normal, 2 roughness) with the atlas's sampler. */
VkDescriptorImageInfo rt_far_image_info(const rt_far *f, int k);
/* Forward path, inside the main pass: binds the far shading fragment
 * pipeline of `variant` (made on first use) and its set 2. */
bool  rt_far_bind_forward(rt_far *f, const rt_pack *p, const rt_passes *rp, rt_pipelines *pl,
                          VkCommandBuffer cb, unsigned variant, rt_error *e);

/* ---- undergrowth.c: cells, generation, drawing (render_record.c drives it) ---- */

typedef struct rt_ug rt_ug;

/* What the draw pass renders into and reads. */
/* ---- far_bake.c: the far atlas baked on the device -------------------- */

/* w x h texels of the far atlas (abi.h "far atlas bake"; far_atlas_reduce
 * of 2 x 2 points each) into albedo (3 floats a texel), normal (3) and
 * roughness (1), row-major; set0 / set1 the renderer's graphics sets,
 * `frame` a frame block whose camera and world sites are the origin. */
bool rt_far_bake(rt_device *d, const rt_pack *p, rt_pipelines *pl, VkDescriptorSet set0,
                 VkDescriptorSet set1, const splat_frame *frame, int w, int h, float *albedo,
                 float *normal, float *rough, rt_far_bake_stats *st, rt_error *e);
/* How many combinations the leaf cells name, each once. */
int rt_far_bake_combos(const rt_pack *p);

typedef struct rt_ug_targets {
    const rt_image *color, *depth, *height;
    int             width, height_px;
    VkSampler       nearest;
    VkDescriptorSet set0;         /* the graphics set 0 (terrain bindings)  */
    bool            timestamps;   /* the queue has them: GPU ms in the stats */
    bool            compute;      /* far blades in compute (screen path only:
                                     undergrowth_craster.c)                 */
} rt_ug_targets;

/* *out stays NULL when the pack has no undergrowth; set even on failure
 * (free with rt_ug_destroy).  radius 0: RT_UG_RADIUS. */
bool rt_ug_create(rt_device *d, const rt_pack *p, rt_pipelines *pl, const rt_quadtree *qt,
                  const rt_ug_targets *t, double radius, double thin, rt_ug **out,
                  rt_error *e);
void rt_ug_destroy(rt_ug *u);
/* Allocate the cells around the camera (on the CPU: which are visible),
 * then record the generation of up to `budget` pending ones (<= 0: all),
 * frustum first, near first. */
void rt_ug_prepare(rt_ug *u, const rt_camera *c, const splat_frame *fr);
bool rt_ug_generate(rt_ug *u, VkCommandBuffer cb, const splat_frame *fr, VkDescriptorSet set1,
                    int budget, rt_error *e);
/* After rt_ug_prepare: whether a cell generated by now or by this frame's
 * rt_ug_generate (budget 0) is in the frustum (else nothing to draw: the
 * pass and, on the screen path, the depth copy are left out). */
bool rt_ug_visible(const rt_ug *u);
/* After the terrain: the instances of the visible cells, front to back;
 * depth_read_only: the depth was left SHADER_READ_ONLY (screen path). */
/* depth_read_only (the screen path): the compute keys' blades drawn in
 * compute after the render pass with set0c, the compute set 0 whose
 * SPLAT_BIND_OUT is the colour (undergrowth_craster.c). */
void rt_ug_draw(rt_ug *u, VkCommandBuffer cb, bool depth_read_only, VkDescriptorSet set0,
                VkDescriptorSet set1, VkDescriptorSet set0c, const VkViewport *vp,
                const VkRect2D *area);
/* Regenerate the cells touching rect (x0, z0, x1, z1 terrain-local m) or,
 * NULL, every cell. */
void rt_ug_invalidate(rt_ug *u, const double *rect);
/* After the frame completed. */
void rt_ug_read_stats(rt_ug *u, rt_ug_stats *st);
/* The instances of cell (ix, iz) (its origin at 16 m times those), up to
 * max; 0 if the cell is not generated, -1 on error. */
int  rt_ug_read_cell(rt_ug *u, int ix, int iz, rt_ug_instance *out, int max, rt_error *e);
/* Tests: the instances the last frame's draw keeps (after the LOD and the
 * distance fade, as the vertex stage decides), counted per ring of `width`
 * metres around its camera: counts[k] for [k width, (k + 1) width), and
 * counts[nrings + k] all the LOD's there, kept or not; the generated
 * cells it counted, or -1 on error. */
int  rt_ug_probe_rings(rt_ug *u, double width, int nrings, uint32_t *counts, rt_error *e);
/* Tests: the instances the last frame drew, in the draw's order, up to
 * max, with each one's key (rt_ug_stats: a block's near or far mesh) in
 * key[] when not NULL; how many it drew (may exceed max), -1 on error. */
int  rt_ug_read_drawn(rt_ug *u, rt_ug_instance *out, int *key, int max, rt_error *e);
/* Tests: the vertex stage's wind at n points on the device, 12 floats
 * each: root xyz, h (m above the root), the block's wind (direction x, z,
 * sway, gust) in, then the offset xyz and the gust in [0, 1] out. */
bool rt_ug_probe_wind(rt_ug *u, float *points, int n, double time, rt_error *e);

/* ---- destruction.c: the renderer's side ------------------------------- */

/* *out stays NULL when the pack has no destructible area.  `height` and
 * `bounds` are the renderer's; they are updated by craters. */
bool rt_destruction_create(rt_device *d, const rt_pack *p, int pool_tiles,
                           rt_image *height, rt_bounds *bounds, rt_destruction **out,
                           rt_error *e);
void rt_destruction_destroy(rt_destruction *ds);
void rt_destruction_frame(const rt_destruction *ds, splat_frame *fr);
void rt_destruction_views(const rt_destruction *ds, VkImageView *atlas, VkImageView *index);
const uint16_t *rt_destruction_heights(const rt_destruction *ds);
bool rt_destruction_crater(rt_destruction *ds, const rt_crater *c, rt_crater_stats *st,
                           rt_error *e);
/* Wait until the last crater's commands are done. */
bool rt_destruction_wait(rt_destruction *ds, rt_error *e);
bool   rt_read_r16(rt_device *d, const rt_image *img, uint16_t *out, rt_error *e);

/* ---- shadow.c: the sun-visibility map ---------------------------------- */

/* out (hf_width x hf_height, 255 = sun fully visible) for the sun
 * direction `sun` (towards the sun, unit) over `heights` with their
 * quadtree bounds `b`: the texels of rect (x0, z0, x1, z1, end exclusive;
 * NULL: all), the others left as they are. */
void rt_shadow_map(const uint16_t *heights, const rt_pack *p, const rt_bounds *b,
                   const double sun[3], const int rect[4], uint8_t *out);
/* The texels whose map a change of heights inside the disc (x, z, radius
 * in metres) can change, for that sun: true and *rect set; false when no
 * texel's can (sun below the horizon or overhead). */
bool rt_shadow_crater_rect(const rt_pack *p, const rt_bounds *b, const double sun[3],
                           double x, double z, double radius, int rect[4]);

/* ---- shadow_gpu.c: the sun-visibility map marched on the device ------- */

typedef struct rt_shadow_gpu rt_shadow_gpu;
/* The march's pyramid (from `heights`, the current ones: craters only
 * lower them later), map buffer and pipeline; it reads the terrain's R16
 * `height` image (SHADER_READ_ONLY) at every update. */
bool rt_shadow_gpu_create(rt_device *d, const rt_pack *p, const uint16_t *heights,
                          const rt_image *height, VkPipelineCache cache, rt_shadow_gpu **out,
                          rt_error *e);
void rt_shadow_gpu_destroy(rt_shadow_gpu *s);
/* rt_shadow_map on the device into `shadow` (the R8 map, SHADER_READ_ONLY
 * before and after): the texels of rect (NULL: all; a part only once a
 * whole map was made), `top` the terrain's highest height (m: the
 * quadtree bounds' top, where the CPU march ends); waits until done. */
bool rt_shadow_gpu_map(rt_shadow_gpu *s, const double sun[3], double top, const int rect[4],
                       rt_image *shadow, rt_error *e);
/* The last map (hf_width x hf_height bytes) back to the host. */
bool rt_shadow_gpu_read(rt_shadow_gpu *s, uint8_t *out, rt_error *e);

/* ---- render.c: the renderer's shadow map, for tests -------------------- */

/* The map the renderer made last (its CPU copy, or read back from the
 * device) into out (hf_width x hf_height); false with e set on failure. */
bool rt_renderer_shadow_read(rt_renderer *r, uint8_t *out, rt_error *e);
/* The CPU reference (rt_shadow_map, whole) for the renderer's sun and
 * current heights. */
void rt_renderer_shadow_reference(rt_renderer *r, uint8_t *out);

/* ---- overlay.c: the viewer's on-screen help (key H) -------------------- */

typedef struct rt_overlay rt_overlay;   /* rt_overlay_info, rt_overlay_text: splatrt.h */
/* The overlay's pipeline for subpass 0 of `pass` (one colour attachment,
 * display-encoded UNORM).  On failure *out may still be set: destroy it. */
bool rt_overlay_create(rt_device *d, VkRenderPass pass, rt_overlay **out, rt_error *e);
void rt_overlay_destroy(rt_overlay *o);
/* Lay `text` out in a box at the top left of a w x h target into the
 * overlay's vertex buffer (waits for the device when it must grow). */
bool rt_overlay_layout(rt_overlay *o, const char *text, uint32_t w, uint32_t h, rt_error *e);
/* Draw it, inside the render pass the overlay was made for. */
void rt_overlay_record(rt_overlay *o, VkCommandBuffer cb, uint32_t w, uint32_t h);

/* ---- light.c: the frame's lighting fields ------------------------------ */

/* The frame's sun, sky, fog and exposure; fog towards `background`. */
void rt_light_frame(const rt_light *l, const rt_pack *p, const float background[3],
                    splat_frame *fr);

#endif
