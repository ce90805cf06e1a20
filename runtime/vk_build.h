/* vk_build.h — the runtime's one builder for Vulkan objects (internal to
 * the runtime, vk_build.c).
 *
 * Each kind of object is made from a desc struct that is zero-initialised
 * with designated initialisers; a zero field means the default written
 * beside it (sokol_gfx's sg_make_*), so a call site names only what is
 * particular to it, instead of a Vk*CreateInfo block written out per file.
 *
 * Every maker takes a destroy list (may be NULL): a handle made with one
 * is recorded there, and rt_vk_list_destroy destroys the whole list, last
 * made first, in one call; with NULL the caller destroys the handle.
 * Every maker returns false with *e set ("vkCreateX(label)" and the
 * VkResult) on failure, with nothing left made by that call.
 *
 *     rt_vk_list keep = { 0 };
 *     ok = rt_vk_layout(d, &keep, &(rt_vk_layout_desc){ .label = "decal",
 *                          .push_stages = VK_SHADER_STAGE_FRAGMENT_BIT,
 *                          .push_bytes = 32 }, &layout, e) && ...;
 *     ...
 *     rt_vk_list_destroy(d, &keep);
 */
#ifndef SPLAT_VK_BUILD_H
#define SPLAT_VK_BUILD_H

#include "rt_internal.h"

/* ---- destroy lists ---------------------------------------------------- */

typedef struct rt_vk_obj {
    VkObjectType type;
    uint64_t     handle;
} rt_vk_obj;

typedef struct rt_vk_list {
    rt_vk_obj *v;
    int        n, cap;
} rt_vk_list;

/* Record a handle made elsewhere (an image view, a query pool, a
 * semaphore ...).  Out of memory: the handle is destroyed at once and
 * false returned with *e set. */
bool rt_vk_keep(rt_device *d, rt_vk_list *l, VkObjectType type, uint64_t handle, rt_error *e);
/* Destroy every recorded handle, last recorded first, and empty the list. */
void rt_vk_list_destroy(rt_device *d, rt_vk_list *l);
/* A non-dispatchable handle as the list stores it. */
#define RT_VK_H(h) rt_vk_u64(&(h), sizeof(h))
uint64_t rt_vk_u64(const void *handle, size_t size);

/* ---- render passes and framebuffers ----------------------------------- */

typedef struct rt_vk_attachment {
    VkFormat            format;    /* VK_FORMAT_UNDEFINED: none (depth)      */
    VkAttachmentLoadOp  load;      /* default LOAD                           */
    VkAttachmentStoreOp store;     /* default STORE                          */
    VkImageLayout       initial;   /* default UNDEFINED                      */
    VkImageLayout       final;     /* required                               */
} rt_vk_attachment;

#define RT_VK_MAX_COLOR 4

/* One subpass: colour attachments 0..ncolor-1 (COLOR_ATTACHMENT_OPTIMAL),
 * then the depth attachment (DEPTH_STENCIL_ATTACHMENT_OPTIMAL) if any;
 * one sample, stencil not cared for. */
typedef struct rt_vk_pass_desc {
    const char                *label;
    rt_vk_attachment           color[RT_VK_MAX_COLOR];
    uint32_t                   ncolor;
    rt_vk_attachment           depth;
    const VkSubpassDependency *deps;   /* default none                 */
    uint32_t                   ndeps;
} rt_vk_pass_desc;

bool rt_vk_pass(rt_device *d, rt_vk_list *l, const rt_vk_pass_desc *desc, VkRenderPass *out,
                rt_error *e);

typedef struct rt_vk_fb_desc {
    const char        *label;
    VkRenderPass       pass;
    const VkImageView *views;          /* in the pass's attachment order */
    uint32_t           nviews;
    uint32_t           width, height;  /* one layer                      */
} rt_vk_fb_desc;

bool rt_vk_fb(rt_device *d, rt_vk_list *l, const rt_vk_fb_desc *desc, VkFramebuffer *out,
              rt_error *e);

/* ---- samplers ---------------------------------------------------------- */

typedef struct rt_vk_sampler_desc {
    const char          *label;
    VkFilter             filter;   /* magnification and minification; default NEAREST */
    VkSamplerMipmapMode  mip;      /* default NEAREST                      */
    VkSamplerAddressMode wrap;     /* U, V and W; default REPEAT           */
    float                max_lod;  /* default 0 (VK_LOD_CLAMP_NONE: all)   */
} rt_vk_sampler_desc;

bool rt_vk_sampler(rt_device *d, rt_vk_list *l, const rt_vk_sampler_desc *desc, VkSampler *out,
                   rt_error *e);

/* ---- layouts ----------------------------------------------------------- */

typedef struct rt_vk_set_layout_desc {
    const char                         *label;
    const VkDescriptorSetLayoutBinding *bindings;
    uint32_t                            n;
} rt_vk_set_layout_desc;

bool rt_vk_set_layout(rt_device *d, rt_vk_list *l, const rt_vk_set_layout_desc *desc,
                      VkDescriptorSetLayout *out, rt_error *e);

typedef struct rt_vk_layout_desc {
    const char                  *label;
    const VkDescriptorSetLayout *sets;        /* default none              */
    uint32_t                     nsets;
    VkShaderStageFlags           push_stages; /* one push constant range   */
    uint32_t                     push_bytes;  /* 0: no push constants      */
} rt_vk_layout_desc;

bool rt_vk_layout(rt_device *d, rt_vk_list *l, const rt_vk_layout_desc *desc,
                  VkPipelineLayout *out, rt_error *e);

/* ---- pipelines --------------------------------------------------------- */

/* Shaders are modules (kept by the caller) or GLSL compiled here
 * (rt_glsl_module: glslang and spirv-val).  One sample, line width 1. */
typedef struct rt_vk_gfx_desc {
    const char                        *label;    /* names shaders and errors  */
    VkShaderModule                     vs, fs;
    const char                        *vs_glsl, *fs_glsl;   /* instead of vs, fs */
    const VkSpecializationInfo        *fs_spec;  /* default none              */
    const VkVertexInputBindingDescription   *vbufs;   /* default none        */
    uint32_t                           nvbufs;
    const VkVertexInputAttributeDescription *attrs;
    uint32_t                           nattrs;
    VkPrimitiveTopology                topology; /* default (0) TRIANGLE_LIST */
    VkPolygonMode                      polygon;  /* default FILL               */
    VkCullModeFlags                    cull;     /* default NONE               */
    VkFrontFace                        front;    /* default COUNTER_CLOCKWISE  */
    bool                               depth_test, depth_write;
    VkCompareOp                        depth_compare;
    uint32_t                           ncolor;   /* colour attachments written */
    /* per colour attachment; NULL: no blending, every channel written */
    const VkPipelineColorBlendAttachmentState *blend;
    VkExtent2D                         viewport; /* 0 x 0: dynamic viewport and scissor */
    VkPipelineLayout                   layout;
    VkRenderPass                       pass;     /* subpass 0                   */
    VkPipelineCache                    cache;    /* default none                */
} rt_vk_gfx_desc;

bool rt_vk_gfx(rt_device *d, rt_vk_list *l, const rt_vk_gfx_desc *desc, VkPipeline *out,
               rt_error *e);

struct rt_interface;
typedef struct rt_vk_compute_desc {
    const char                 *label;
    VkShaderModule              module;
    const char                 *glsl;     /* instead of module            */
    const uint32_t             *spirv;    /* or: SPIR-V already validated and
                                             checked (a pack's, at load)  */
    size_t                      nwords;
    const struct rt_interface  *check;    /* glsl: rt_spirv_check against it */
    const VkSpecializationInfo *spec;
    VkPipelineLayout            layout;
    VkPipelineCache             cache;
} rt_vk_compute_desc;

bool rt_vk_compute(rt_device *d, rt_vk_list *l, const rt_vk_compute_desc *desc, VkPipeline *out,
                   rt_error *e);

/* A batch: between rt_vk_batch_begin and rt_vk_batch_end, on the thread
 * that began it, rt_vk_gfx and rt_vk_compute of shaders given as GLSL or
 * SPIR-V words (not as modules, nor with an interface check) only record
 * what to make (the desc deep-copied) and return true; rt_vk_batch_end
 * makes them all at once on every core (rt_parallel: glslang, spirv-val
 * and the driver's compiler per pipeline), fills each *out and keeps it in
 * its list, the first failure in *e.  The caller uses none of those
 * handles before the end, and the structs they are written into stay put.
 * `run` false drops what is recorded (a create that failed before). */
bool rt_vk_batch_begin(rt_device *d, rt_error *e);
bool rt_vk_batch_end(rt_device *d, bool run, rt_error *e);

/* ---- descriptor sets --------------------------------------------------- */

/* A pool of exactly these sizes holding one set of each layout. */
typedef struct rt_vk_sets_desc {
    const char                  *label;
    const VkDescriptorPoolSize  *sizes;
    uint32_t                     nsizes;
    const VkDescriptorSetLayout *layouts;
    uint32_t                     nsets;
} rt_vk_sets_desc;

bool rt_vk_sets(rt_device *d, rt_vk_list *l, const rt_vk_sets_desc *desc, VkDescriptorPool *pool,
                VkDescriptorSet *sets, rt_error *e);

/* One descriptor write: a buffer (from offset 0, `range` bytes or the
 * whole), one image (sampler, view, layout), or `count` images. */
typedef struct rt_vk_write {
    VkDescriptorSet               set;
    uint32_t                      binding;
    VkDescriptorType              type;
    VkBuffer                      buf;
    VkDeviceSize                  range;    /* default VK_WHOLE_SIZE          */
    VkSampler                     sampler;
    VkImageView                   view;
    VkImageLayout                 layout;   /* default SHADER_READ_ONLY_OPTIMAL */
    const VkDescriptorImageInfo  *images;   /* instead of sampler and view    */
    uint32_t                      count;    /* of images                      */
} rt_vk_write;

void rt_vk_write_sets(rt_device *d, const rt_vk_write *w, uint32_t n);

#endif
