/* pipelines.c — descriptor set layouts exactly as compiler/abi.h fixes
 * them, one graphics pipeline per combination over the pack's shared
 * vertex shader, the multi-pass reference pipelines (one blended pass per
 * material and a resolve pass that lights the blended surface with the
 * ABI's splat_light), the über-shader pipeline, and a pipeline cache kept
 * on disk between runs. */
#include "rt_internal.h"
#include "vk_build.h"
#include "util.h"   /* splat_write_atomic */

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cache.h"
#include "spv.h"

/* The resolve pass of the multi-pass reference: a fullscreen triangle that
 * reads the three blended targets and applies the same lighting as the
 * single-pass shaders (splat_finish), so both give the same image. */
static const char resolve_vert[] =
    "#version 450\n"
    "layout(location = 0) out vec3 v_rel;\n"
    "layout(location = 1) out vec2 v_uv;\n"
    "layout(location = 2) out vec3 v_local;\n"
    "void main() {\n"
    "    vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);\n"
    "    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
    "    v_rel = vec3(0.0); v_uv = p; v_local = vec3(0.0);\n"
    "}\n";

/* The sky behind the terrain (forward path): the same triangle at depth
 * 0, drawn last with depth test EQUAL, so only where no terrain wrote. */
static const char sky_frag_main[] =
    "void main() {\n"
    "    vec2 ndc = gl_FragCoord.xy / u_frame.screen.xy * 2.0 - 1.0;\n"
    "    vec4 q = u_frame.inv_view_proj * vec4(ndc, 0.5, 1.0);\n"
    "    o_color = vec4(splat_sky(normalize(q.xyz / q.w)) * u_frame.light.z, 1.0);\n"
    "}\n";

static const char resolve_frag_main[] =
    "layout(set = 2, binding = 0) uniform sampler2D r_albedo;\n"
    "layout(set = 2, binding = 1) uniform sampler2D r_normal;\n"
    "layout(set = 2, binding = 2) uniform sampler2D r_misc;\n"
    "void main() {\n"
    "    ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "    vec4 a = texelFetch(r_albedo, p, 0);\n"
    /* the pixel's ray, surface -> camera (v_rel is 0 in this pass) */
    "    vec2 ndc = gl_FragCoord.xy / u_frame.screen.xy * 2.0 - 1.0;\n"
    "    vec4 q = u_frame.inv_view_proj * vec4(ndc, 0.5, 1.0);\n"
    "    vec3 to_cam = -normalize(q.xyz / q.w);\n"
    "    if (a.a <= 0.0) {   /* no terrain: the sky, or keep the clear colour */\n"
    "        if (u_frame.sky_color.a <= 0.0) discard;\n"
    "        o_color = vec4(splat_sky(-to_cam) * u_frame.light.z, 1.0);\n"
    "        return;\n"
    "    }\n"
    "    vec4 ns = texelFetch(r_normal, p, 0);\n"
    "    vec4 m = texelFetch(r_misc, p, 0);\n"
    "    vec3 nn = normalize(ns.xyz);\n"
    "    vec3 albedo = a.rgb, n = nn, c;\n"
    "    float rough = m.r, dist = m.b;\n"
    "    switch (u_frame.view.x) {\n"
    SPLAT_VIEWS(SPLAT_VIEW_CASE_RESOLVE)   /* abi.h: the views it can show */
    "    default: c = splat_light(albedo, n, rough, dist, to_cam); break;\n"
    "    }\n"
    "    o_color = vec4(c, 1.0);\n"
    "}\n";

/* ---- pipeline cache on disk ---------------------------------------------- */

static char *default_cache_path(void)
{
    const char *env = getenv("SPLAT_PIPELINE_CACHE");
    if (env && *env)
        return strdup(env);
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    char dir[1024];
    if (xdg && *xdg)
        snprintf(dir, sizeof dir, "%s/splatc", xdg);
    else if (home && *home)
        snprintf(dir, sizeof dir, "%s/.cache/splatc", home);
    else
        return NULL;
    /* Create the folder and its parent; failure only disables saving. */
    char *slash = strrchr(dir, '/');
    if (slash) {
        *slash = '\0';
        mkdir(dir, 0755);
        *slash = '/';
    }
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return NULL;
    size_t n = strlen(dir) + 32;
    char *path = malloc(n);
    if (path)
        snprintf(path, n, "%s/pipelines.bin", dir);
    return path;
}

/* Cache data is only handed to the driver if its header names this device. */
static bool cache_matches(const rt_device *d, const uint8_t *data, size_t n)
{
    if (n < 32)
        return false;
    uint32_t len, version, vendor, device;
    memcpy(&len, data, 4);
    memcpy(&version, data + 4, 4);
    memcpy(&vendor, data + 8, 4);
    memcpy(&device, data + 12, 4);
    return len >= 32 && version == VK_PIPELINE_CACHE_HEADER_VERSION_ONE &&
           vendor == d->props.vendorID && device == d->props.deviceID &&
           !memcmp(data + 16, d->props.pipelineCacheUUID, VK_UUID_SIZE);
}

static bool open_cache(rt_device *d, rt_pipelines *pl, const char *path, rt_error *e)
{
    pl->cache_path = path ? strdup(path) : default_cache_path();
    uint8_t *data = NULL;
    size_t n = 0;
    FILE *f = pl->cache_path ? fopen(pl->cache_path, "rb") : NULL;
    if (f) {
        if (fseek(f, 0, SEEK_END) == 0) {
            long len = ftell(f);
            if (len > 0 && fseek(f, 0, SEEK_SET) == 0 && (data = malloc((size_t)len))) {
                n = fread(data, 1, (size_t)len, f);
                if (n != (size_t)len)
                    n = 0;
            }
        }
        fclose(f);
    }
    VkPipelineCacheCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO,
        .initialDataSize = cache_matches(d, data, n) ? n : 0,
        .pInitialData = data,
    };
    VkResult r = vkCreatePipelineCache(d->dev, &ci, NULL, &pl->cache);
    free(data);
    if (r != VK_SUCCESS)
        return rt_fail(e, RT_E_VULKAN, "vkCreatePipelineCache", rt_vk_result_name(r));
    return true;
}

static void save_cache(rt_device *d, rt_pipelines *pl)
{
    size_t n = 0;
    if (!pl->cache_path || vkGetPipelineCacheData(d->dev, pl->cache, &n, NULL) != VK_SUCCESS || !n)
        return;
    uint8_t *data = malloc(n);
    if (!data)
        return;
    /* a unique temporary beside it, renamed: readers never see half a file,
     * and two processes saving at once never write into one temporary */
    if (vkGetPipelineCacheData(d->dev, pl->cache, &n, data) == VK_SUCCESS)
        (void)splat_write_atomic(pl->cache_path, data, n);
    free(data);
}

/* ---- layouts ------------------------------------------------------------- */

static bool make_layouts(rt_device *d, int ntextures /* arrays */, rt_pipelines *pl, rt_error *e)
{
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkShaderStageFlags vf = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    const VkShaderStageFlags fs = VK_SHADER_STAGE_FRAGMENT_BIT | cs;
    const VkDescriptorType smp = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    const VkDescriptorType sbuf = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    /* One set 0 for both paths: the graphics passes leave the compute
     * bindings (7-9) unwritten in their set, which they never read; both
     * sets write the counters (10) for the counting variants. */
    VkDescriptorSetLayoutBinding terrain[] = {
        { SPLAT_BIND_HEIGHTFIELD, smp, 1, vf | cs, NULL },
        { SPLAT_BIND_FRAME, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, vf | cs, NULL },
        { SPLAT_BIND_PAINTED, smp, 1, fs, NULL },
        { SPLAT_BIND_DESTRUCTION_ATLAS, smp, 1, fs, NULL },
        { SPLAT_BIND_DESTRUCTION_INDEX, smp, 1, fs, NULL },
        { SPLAT_BIND_PAINTED_INDEX, smp, 1, fs, NULL },   /* sparse masks */
        { SPLAT_BIND_PAINTED_LEVEL, smp, 1, fs, NULL },
        { SPLAT_BIND_HOLES, smp, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL },
        { SPLAT_BIND_SHADOW, smp, 1, fs, NULL },
        { SPLAT_BIND_VECTORS, sbuf, 1, fs, NULL },   /* vector shapes */
        { SPLAT_BIND_DEPTH, smp, 1, cs, NULL },
        { SPLAT_BIND_OUT, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs, NULL },
        { SPLAT_BIND_TILES, sbuf, 1, cs, NULL },
        { SPLAT_BIND_COUNTERS, sbuf, 1, fs, NULL },
    };
    if (!rt_vk_set_layout(d, NULL, &(rt_vk_set_layout_desc){ "terrain", terrain,
                              sizeof terrain / sizeof *terrain }, &pl->set_terrain, e))
        return false;
    VkDescriptorSetLayoutBinding *mat = calloc((size_t)ntextures + 1, sizeof *mat);
    if (!mat)
        return rt_fail(e, RT_E_VULKAN, "layout", "out of memory");
    mat[0] = (VkDescriptorSetLayoutBinding){ SPLAT_BIND_PARAMS, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, fs, NULL };
    for (int i = 0; i < ntextures; i++)
        mat[i + 1] = (VkDescriptorSetLayoutBinding){ (uint32_t)(SPLAT_BIND_TEXTURE0 + i), smp, 1, fs, NULL };
    bool ok = rt_vk_set_layout(d, NULL, &(rt_vk_set_layout_desc){ "material", mat,
                                   (uint32_t)ntextures + 1 }, &pl->set_material, e);
    free(mat);
    VkDescriptorSetLayoutBinding res[] = {
        { 0, smp, 1, fs, NULL }, { 1, smp, 1, fs, NULL }, { 2, smp, 1, fs, NULL },
    };
    if (!ok || !rt_vk_set_layout(d, NULL, &(rt_vk_set_layout_desc){ "resolve", res, 3 },
                                 &pl->set_resolve, e))
        return false;
    VkDescriptorSetLayout sets[3] = { pl->set_terrain, pl->set_material, pl->set_resolve };
    return rt_vk_layout(d, NULL, &(rt_vk_layout_desc){ .label = "terrain", .sets = sets,
                            .nsets = 2, .push_stages = vf, .push_bytes = sizeof(splat_push) },
                        &pl->layout, e) &&
           rt_vk_layout(d, NULL, &(rt_vk_layout_desc){ .label = "resolve", .sets = sets,
                            .nsets = 3, .push_stages = vf, .push_bytes = sizeof(splat_push) },
                        &pl->resolve_layout, e) &&
           rt_vk_layout(d, NULL, &(rt_vk_layout_desc){ .label = "terrain compute", .sets = sets,
                            .nsets = 2, .push_stages = cs, .push_bytes = sizeof(splat_push) },
                        &pl->compute_layout, e);
}

/* ---- pipelines ----------------------------------------------------------- */

static bool make_module(rt_device *d, const uint32_t *words, size_t n,
                        VkShaderModule *m, rt_error *e)
{
    VkShaderModuleCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = n * 4,
        .pCode = words,
    };
    RT_VK(e, vkCreateShaderModule(d->dev, &ci, NULL, m));
    return true;
}

typedef enum kind {
    K_OPAQUE,       /* composites, über: depth test + write                  */
    K_BASE,         /* multi-pass bottom material: 3 targets, depth write     */
    K_BLEND,        /* multi-pass upper materials: blend, depth EQUAL         */
    K_RESOLVE,      /* fullscreen, no depth, no vertex input                  */
    K_DEPTH,        /* screen-space geometry pass: vertex stage, depth only   */
    K_SKY,          /* fullscreen, depth EQUAL the clear value, no write      */
} kind;

/* The specialization of a composite's (or the über-shader's, or a
 * reference pass's) pipeline: the final view unless `debug` (abi.h
 * SPLAT_SPEC_VIEW: the driver drops the debug views' code) and the CPU
 * shading LOD where it is on (SPLAT_SPEC_LOD; left at its default 0
 * otherwise).  Shaders without a constant ignore its entry.  NULL when
 * there is nothing to set. */
typedef struct spec_buf {
    uint32_t                 values[2];
    VkSpecializationMapEntry entries[2];
    VkSpecializationInfo     info;
} spec_buf;

static const VkSpecializationInfo *spec_for(const rt_pipelines *pl, bool debug, spec_buf *b)
{
    uint32_t n = 0;
    if (!debug) {
        b->entries[n] = (VkSpecializationMapEntry){ SPLAT_SPEC_VIEW, n * 4, 4 };
        b->values[n++] = SPLAT_VIEW_FINAL;
    }
    if (pl->shading_lod) {
        b->entries[n] = (VkSpecializationMapEntry){ SPLAT_SPEC_LOD, n * 4, 4 };
        b->values[n++] = pl->shading_lod;
    }
    b->info = (VkSpecializationInfo){ n, b->entries, n * 4, b->values };
    return n ? &b->info : NULL;
}

/* `layout`: VK_NULL_HANDLE for the pipelines' own (resolve or terrain). */
static bool make_pipeline_in(rt_device *d, rt_pipelines *pl, VkPipelineLayout layout,
                             VkShaderModule vs, VkShaderModule fs, VkRenderPass pass, kind k,
                             unsigned variant, VkPipeline *out, rt_error *e)
{
    /* Not RT_VARIANT_DEBUG: the fragment shader specialised to the final
     * view; the CPU shading LOD (spec_for) */
    spec_buf sb;
    const VkSpecializationInfo *fs_spec = spec_for(pl, (variant & RT_VARIANT_DEBUG) != 0, &sb);
    const VkColorComponentFlags all = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                      VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendAttachmentState att[3];
    for (int i = 0; i < 3; i++)
        att[i] = (VkPipelineColorBlendAttachmentState){
            .blendEnable = k == K_BLEND,   /* the base pass writes, mask 1 */
            .srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA,
            .dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
            .colorBlendOp = VK_BLEND_OP_ADD,
            .srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE,
            .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
            .alphaBlendOp = VK_BLEND_OP_ADD,
            .colorWriteMask = all,
        };
    VkVertexInputBindingDescription vb = { 0, 8, VK_VERTEX_INPUT_RATE_VERTEX };
    VkVertexInputAttributeDescription va = { 0, 0, VK_FORMAT_R32G32_SFLOAT, 0 };
    bool grid = k != K_RESOLVE && k != K_SKY;   /* vertex input: the grid's x, z */
    return rt_vk_gfx(d, NULL, &(rt_vk_gfx_desc){
        .label = "terrain", .vs = vs, .fs = k == K_DEPTH ? VK_NULL_HANDLE : fs,
        .fs_spec = fs_spec,
        .vbufs = &vb, .nvbufs = grid, .attrs = &va, .nattrs = grid,
        .polygon = (variant & RT_VARIANT_WIRE) ? VK_POLYGON_MODE_LINE : VK_POLYGON_MODE_FILL,
        /* Without RT_VARIANT_CULL terrain seen from below shows too.  The
         * grid's triangles are clockwise on screen seen from above (the
         * projection flips y). */
        .cull = (variant & RT_VARIANT_CULL) ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE,
        .front = VK_FRONT_FACE_CLOCKWISE,
        /* Reversed Z (1 at the near plane, 0 at infinity): greater is nearer. */
        .depth_test = k != K_RESOLVE,
        .depth_write = k == K_OPAQUE || k == K_BASE || k == K_DEPTH,
        .depth_compare = k == K_BLEND || k == K_SKY ? VK_COMPARE_OP_EQUAL
                                                    : VK_COMPARE_OP_GREATER_OR_EQUAL,
        .ncolor = (k == K_BASE || k == K_BLEND) ? 3 : k == K_DEPTH ? 0 : 1, .blend = att,
        .layout = layout ? layout : k == K_RESOLVE ? pl->resolve_layout : pl->layout,
        .pass = pass, .cache = pl->cache }, out, e);
}

static bool make_pipeline(rt_device *d, rt_pipelines *pl, VkShaderModule vs,
                          VkShaderModule fs, VkRenderPass pass, kind k,
                          unsigned variant, VkPipeline *out, rt_error *e)
{
    return make_pipeline_in(d, pl, VK_NULL_HANDLE, vs, fs, pass, k, variant, out, e);
}

/* The pack's module `s`, read and checked on its first use, as a
 * VkShaderModule. */
static bool pack_module(rt_device *d, const rt_pack *p, const rt_spirv *s, VkShaderModule *m,
                        rt_error *e)
{
    size_t n = 0;
    const uint32_t *words = rt_pack_spirv(p, s, &n, e);
    return words && make_module(d, words, n, m, e);
}

/* A pipeline from a pack module over the shared vertex shader. */
static bool pack_pipeline(rt_device *d, const rt_pack *p, rt_pipelines *pl, const rt_spirv *fs,
                          VkRenderPass pass, kind k, unsigned variant, VkPipeline *out,
                          rt_error *e)
{
    VkShaderModule m;
    if (!pack_module(d, p, fs, &m, e))
        return false;
    bool ok = make_pipeline(d, pl, pl->vertex, m, pass, k, variant, out, e);
    vkDestroyShaderModule(d->dev, m, NULL);
    return ok;
}

char *rt_glsl_with_defines(const char *glsl, const char *defs)
{
    const char *nl = strchr(glsl, '\n');
    size_t head = nl ? (size_t)(nl - glsl) + 1 : 0, n = strlen(glsl), nd = strlen(defs);
    char *s = malloc(n + nd + 1);
    if (!s)
        return NULL;
    memcpy(s, glsl, head);
    memcpy(s + head, defs, nd);
    memcpy(s + head + nd, glsl + head, n - head + 1);
    return s;
}

/* Whether the device draws `variant`: wireframe needs fillModeNonSolid,
 * the counting variant fragment stores and subgroup votes. */
static bool variant_supported(const rt_device *d, unsigned variant, rt_error *e)
{
    if ((variant & RT_VARIANT_WIRE) && !d->wireframe)
        return rt_fail(e, RT_E_NO_FORMAT, "draw wireframe (no fillModeNonSolid)");
    if ((variant & RT_VARIANT_COUNT) && !d->count_fragments)
        return rt_fail(e, RT_E_NO_FORMAT, "count on the forward path (fragmentStoresAndAtomics "
                       "and subgroup votes in fragment shaders)");
    return true;
}

/* A main-pass pipeline over the terrain's vertex shader from fragment
 * GLSL: compiled, validated, checked against `check` (NULL: not), in
 * `layout` (VK_NULL_HANDLE: the terrain's). */
static bool fragment_pipeline(rt_device *d, rt_pipelines *pl, const rt_passes *rp,
                              VkPipelineLayout layout, const char *glsl, const char *name,
                              const rt_interface *check, unsigned variant, VkPipeline *out,
                              rt_error *e)
{
    VkShaderModule m;
    if (!rt_glsl_module(d, glsl, VK_SHADER_STAGE_FRAGMENT_BIT, name, check, &m, e))
        return false;
    bool ok = make_pipeline_in(d, pl, layout, pl->vertex, m, rp->main, K_OPAQUE, variant, out, e);
    vkDestroyShaderModule(d->dev, m, NULL);
    return ok;
}

/* A composite's fragment pipeline from the pack's GLSL (`g`, else read
 * from the pack's file `path`), compiled, validated and checked against
 * the composite interface here, on first use: a distance class without
 * SPIR-V, and every counting variant. */
static bool glsl_pipeline(rt_device *d, const rt_pack *p, rt_pipelines *pl,
                          const rt_passes *rp, const rt_text *g, const char *field,
                          const char *path, const char *name, unsigned variant,
                          VkPipeline *slot, rt_error *e)
{
    bool count = (variant & RT_VARIANT_COUNT) != 0;
    if (!variant_supported(d, variant, e))
        return false;
    char *text = NULL;
    const char *glsl = NULL;
    if (g && g->mod && !(glsl = rt_pack_text(p, g, e)))
        return false;
    if (!glsl && path && !(glsl = text = rt_pack_read_glsl(p, field, path, e)))
        return false;
    if (!glsl) {
        char what[160];
        snprintf(what, sizeof what, "the pack has no fragment GLSL of %s", name);
        return rt_fail(e, RT_E_PACK_FIELD, p->dir, what);
    }
    char *src = count ? rt_glsl_with_defines(glsl, "#define SPLAT_COUNT 1\n") : NULL;
    rt_interface in;
    if ((count && !src) || !rt_interface_for(p, RT_ROLE_COMPOSITE, &in)) {
        free(src);
        free(text);
        return rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
    }
    bool ok = fragment_pipeline(d, pl, rp, VK_NULL_HANDLE, src ? src : glsl, name, &in, variant,
                                slot, e);
    rt_interface_free(&in);
    free(src);
    free(text);
    return ok;
}

bool rt_pipelines_glsl_fragment(rt_device *d, rt_pipelines *pl, const rt_passes *rp,
                                VkPipelineLayout layout, const char *glsl, const char *name,
                                unsigned variant, VkPipeline *out, rt_error *e)
{
    return variant_supported(d, variant, e) &&
           fragment_pipeline(d, pl, rp, layout, glsl, name, NULL, variant, out, e);
}

/* One job of rt_pipelines_make: the pipeline of combination ids[k]. */
typedef struct make_jobs {
    rt_device       *d;
    const rt_pack   *p;
    const rt_passes *rp;
    rt_pipelines    *pl;
    bool             compute;
    const int       *ids;
    unsigned         variant;
} make_jobs;

static bool make_one(void *ctx, int k, rt_error *e)
{
    const make_jobs *j = ctx;
    VkPipeline pipe;
    return j->compute ? rt_pipelines_compute(j->d, j->p, j->pl, j->ids[k], j->variant, &pipe, e)
                      : rt_pipelines_combo(j->d, j->p, j->rp, j->pl, j->ids[k], j->variant,
                                           &pipe, e);
}

/* The bytes of combination id's compute module (SPIR-V where the pack
 * has it, else its GLSL; id ncombos: the über-shader's). */
static size_t compute_cost(const rt_pack *p, int id)
{
    const rt_spirv *s = id < p->ncombos ? &p->combos[id].compute_spirv : &p->uber_compute_spirv;
    const rt_text *t = id < p->ncombos ? &p->combos[id].compute : &p->uber_compute;
    return rt_spirv_present(s) ? rt_pack_spirv_size(s) : rt_pack_text_size(t);
}

rt_stand_in rt_pipelines_stand_in(const rt_device *d, const rt_pack *p, rt_pipelines *pl,
                                  const int *ids, int n, unsigned variant, bool atlas)
{
    if (!pl->async || !p->uber_compute.mod)   /* the flat one takes the über's head */
        return RT_STAND_NONE;
    const char *force = getenv("SPLAT_STAND_IN");
    if (force && !*force)
        force = NULL;
    if (force && !strcmp(force, "never"))
        return RT_STAND_NONE;
    if (force && !strcmp(force, "flat"))
        return ids ? RT_STAND_NONE : RT_STAND_FLAT;
    if (force && !strcmp(force, "atlas"))
        return ids ? RT_STAND_NONE : atlas ? RT_STAND_ATLAS : RT_STAND_FLAT;
    bool uber_only = force && (!strcmp(force, "always") || !strcmp(force, "uber"));
    bool cpu = d->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    /* made: it costs nothing more to make, and on a GPU little to run; on
     * a CPU device its shading is the cost (the 257-material world's first
     * frame took 51 s of it on lavapipe), so there only when forced */
    if (rt_pipelines_has_compute(pl, p->ncombos, variant) && (uber_only || !cpu))
        return RT_STAND_UBER;
    /* before the frame: nearly free, unless forced to the über-shader; the
     * atlas on GPUs only: llvmpipe decodes its BC blocks in software at
     * every sample, and colorado's first picture took 1.2 s longer cold
     * with the atlas than flat on lavapipe (3 samples a pixel at 720p) */
    if (!ids)
        return uber_only ? RT_STAND_NONE : atlas && !cpu ? RT_STAND_ATLAS : RT_STAND_FLAT;
    if (force && !strcmp(force, "always"))
        return RT_STAND_UBER;
    if (!uber_only)   /* the cheap stand-ins took every list before the frame */
        return RT_STAND_NONE;
    /* Making a pipeline costs about its module's size: llvmpipe JIT-compiles
     * it in the frame (colorado's composites about 0.4 s each at 250 KB,
     * serially), a GPU driver on the cores rt_parallel gives it.  One
     * über-shader (491 KB on colorado, 694 KB for 257 materials) stands in
     * for 19 composites of colorado's valley; the 3 small ones that a view
     * of one biome of the 257-material world needs are made at once (the
     * über-shader took 51 s of shading there on lavapipe, the composites
     * 1.8 s: tests/bench/first_picture.sh). */
    size_t sum = 0;
    for (int k = 0; k < n; k++)
        sum += compute_cost(p, ids[k]);
    size_t par = cpu ? 1 : (size_t)rt_job_threads(n);
    return compute_cost(p, p->ncombos) < sum / par ? RT_STAND_UBER : RT_STAND_NONE;
}

bool rt_pipelines_make(rt_device *d, const rt_pack *p, const rt_passes *rp, rt_pipelines *pl,
                       bool compute, const int *ids, int n, unsigned variant, rt_error *e)
{
    if (compute && n > 0 &&
        rt_pipelines_stand_in(d, p, pl, ids, n, variant, false) == RT_STAND_UBER) {
        /* the über-shader now; it stands in for the others in the frame
         * drawn again, after which rt_screen_missing queues them on the
         * workers (not before: on a few cores they would compete with
         * that frame, and a one-frame process drops them unmade) */
        VkPipeline uber;
        return rt_pipelines_compute(d, p, pl, p->ncombos, variant, &uber, e);
    }
    /* each combination's slot is its own: made on all cores (jobs.c) */
    make_jobs j = { d, p, rp, pl, compute, ids, variant };
    return rt_parallel(n, make_one, &j, e);
}

bool rt_pipelines_has_combo(const rt_pipelines *pl, int id, unsigned variant)
{
    return pl->combo && id >= 0 && id < pl->ncombos &&
           pl->combo[(size_t)id * RT_VARIANTS + (variant % RT_VARIANTS)] != VK_NULL_HANDLE;
}

bool rt_pipelines_combo(rt_device *d, const rt_pack *p, const rt_passes *rp,
                        rt_pipelines *pl, int id, unsigned variant, VkPipeline *out,
                        rt_error *e)
{
    if (!variant_supported(d, variant, e))
        return false;
    VkPipeline *slot = &pl->combo[(size_t)id * RT_VARIANTS + (variant % RT_VARIANTS)];
    if (!*slot && (!rt_spirv_present(&p->combos[id].spirv) || (variant & RT_VARIANT_COUNT))) {
        /* a distance class (GLSL alone in the pack), or the counting variant */
        char name[64], field[64];
        snprintf(name, sizeof name, "combination %d (%s)", id,
                 rt_spirv_present(&p->combos[id].spirv) ? "counting" : "distance class");
        const rt_pack_combo *c = &p->combos[id], *b = &p->combos[c->base];
        if (id >= p->nbase)   /* a distance class, as the manifest nests it */
            snprintf(field, sizeof field, "combinations[%d].classes[%d].glsl", c->base,
                     id - b->first_class);
        else
            snprintf(field, sizeof field, "combinations[%d].glsl", id);
        if (!glsl_pipeline(d, p, pl, rp, &p->combos[id].glsl, field, p->combos[id].frag_path,
                           name, variant, slot, e))
            return false;
    }
    if (!*slot && !pack_pipeline(d, p, pl, &p->combos[id].spirv, rp->main, K_OPAQUE, variant,
                                 slot, e))
        return false;
    *out = *slot;
    return true;
}

bool rt_pipelines_uber(rt_device *d, const rt_pack *p, const rt_passes *rp,
                       rt_pipelines *pl, unsigned variant, VkPipeline *out,
                       rt_error *e)
{
    if (!variant_supported(d, variant, e))
        return false;
    if (!rt_spirv_present(&p->uber))
        return rt_fail(e, RT_E_PACK_FIELD, p->dir, "the pack has no uber shader");
    VkPipeline *slot = &pl->uber[variant % RT_VARIANTS];
    if (!*slot && (variant & RT_VARIANT_COUNT) &&
        !glsl_pipeline(d, p, pl, rp, NULL, "uber.glsl", p->uber_frag_path, "uber (counting)",
                       variant, slot, e))
        return false;
    if (!*slot && !pack_pipeline(d, p, pl, &p->uber, rp->main, K_OPAQUE, variant, slot, e))
        return false;
    *out = *slot;
    return true;
}

bool rt_pipelines_ref(rt_device *d, const rt_pack *p, const rt_passes *rp,
                      rt_pipelines *pl, int m, bool cull, VkPipeline *out,
                      rt_error *e)
{
    VkPipeline *slot = &pl->ref[2 * m + cull];
    if (!*slot && !pack_pipeline(d, p, pl, &p->materials[m].reference, rp->multi,
                                 m == 0 ? K_BASE : K_BLEND, cull ? RT_VARIANT_CULL : 0,
                                 slot, e))
        return false;
    *out = *slot;
    return true;
}

/* ---- compute shading (screen-space path) --------------------------------- */

bool rt_pipelines_has_compute(rt_pipelines *pl, int id, unsigned variant)
{
    return pl->compute && id >= 0 && id <= pl->ncombos &&
           rt_async_slot(pl, (size_t)id * RT_CVARIANTS + (variant % RT_CVARIANTS)) != VK_NULL_HANDLE;
}

/* The SPIR-V of a compute variant's GLSL `text`: from the SPIR-V cache
 * (cache.h) when the compiler (splatc build --compute-spirv) or an earlier
 * run compiled it, else glslang and spirv-val, stored for the next run.
 * The cache holds only validated modules, each under a checksum; the
 * runtime's own entries have a key of their own (stage RT_STAGE_COMPUTE),
 * so a build never takes a module the runtime compiled. */
#define RT_STAGE_COMPUTE (16 + SPV_STAGE_COMPUTE)

static bool compute_spirv(rt_pipelines *pl, const char *text, const char *name,
                          uint32_t **words, size_t *n, rt_error *e)
{
    char built[SPLAT_KEY_CHARS + 1], own[SPLAT_KEY_CHARS + 1];
    splat_shader_key(text, SPV_STAGE_COMPUTE, built);
    splat_shader_key(text, RT_STAGE_COMPUTE, own);
    if (splat_cache_get(&pl->spv_cache, built, words, n) ||
        splat_cache_get(&pl->spv_cache, own, words, n)) {
        atomic_fetch_add(&pl->spirv_cached, 1);
        return true;
    }
    if (!rt_glsl_compile(text, VK_SHADER_STAGE_COMPUTE_BIT, name, words, n, e) ||
        !rt_spirv_validate(*words, *n, name, e)) {
        free(*words);
        *words = NULL;
        return false;
    }
    atomic_fetch_add(&pl->spirv_compiled, 1);
    splat_cache_put(&pl->spv_cache, own, *words, *n);   /* failure: only slower next time */
    return true;
}

bool rt_pipelines_compute(rt_device *d, const rt_pack *p, rt_pipelines *pl, int id,
                          unsigned variant, VkPipeline *out, rt_error *e)
{
    if (id < 0 || id > pl->ncombos)
        return rt_fail(e, RT_E_PACK_FIELD, p->dir, "compute pipeline of an unknown combination");
    size_t slot = (size_t)id * RT_CVARIANTS + (variant % RT_CVARIANTS);
    if ((*out = rt_async_slot(pl, slot)))
        return true;
    VkPipeline pipe;
    if (!rt_pipelines_compute_make(d, p, pl, id, variant, &pipe, e))
        return false;
    *out = rt_async_publish(d, pl, slot, pipe);
    return true;
}

bool rt_pipelines_compute_make(rt_device *d, const rt_pack *p, rt_pipelines *pl, int id,
                               unsigned variant, VkPipeline *out, rt_error *e)
{
    *out = VK_NULL_HANDLE;
    const rt_text *text = id < p->ncombos ? &p->combos[id].compute : &p->uber_compute;
    const char *glsl = NULL;
    char name[64];
    if (id < p->ncombos)
        snprintf(name, sizeof name, "combination %d (compute)", id);
    else
        snprintf(name, sizeof name, "uber (compute)");
    if (!text->mod) {
        char what[160];
        snprintf(what, sizeof what, "the pack has no compute variant of %s: rebuild it with "
                 "this splatc for --shading screen", name);
        return rt_fail(e, RT_E_PACK_FIELD, p->dir, what);
    }
    const rt_spirv *built = id < p->ncombos ? &p->combos[id].compute_spirv
                                            : &p->uber_compute_spirv;
    char defs[96] = "", sort[64] = "";
    if (variant & RT_CVARIANT_SORT)
        snprintf(sort, sizeof sort, "#define SPLAT_SORT 1\n#define SPLAT_SORT_TILES %d\n",
                 pl->sort_tiles);
    snprintf(defs, sizeof defs, "%s%s", (variant & RT_CVARIANT_COUNT) ? "#define SPLAT_COUNT 1\n" : "",
             sort);
    /* the GLSL text only where the build's SPIR-V does not serve */
    if ((defs[0] || !rt_spirv_present(built)) && !(glsl = rt_pack_text(p, text, e)))
        return false;
    char *src = defs[0] ? rt_glsl_with_defines(glsl, defs) : NULL;
    if (defs[0] && !src)
        return rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
    uint32_t *words = NULL;
    size_t n = 0;
    rt_interface in;
    bool have_in = false;
    /* the plain variant: the build's SPIR-V where the pack has it (read,
     * validated and checked against the compute role on first use), so
     * nothing is compiled (issue 29) */
    if (!defs[0] && rt_spirv_present(built)) {   /* (src is NULL: no defines) */
        const uint32_t *bw = rt_pack_spirv(p, built, &n, e);
        if (!bw)
            return false;
        words = malloc(n * 4);
        if (!words)
            return rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
        memcpy(words, bw, n * 4);
        atomic_fetch_add(&pl->spirv_cached, 1);
        glsl = NULL;   /* checked by rt_pack_spirv: no second interface check */
    }
    bool ok = words || compute_spirv(pl, src ? src : glsl, name, &words, &n, e);
    free(src);
    if (ok && glsl) {
        have_in = rt_interface_for(p, RT_ROLE_COMPUTE, &in);
        ok = have_in ? rt_spirv_check(words, n, name, &in, e)
                     : rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
    }
    if (have_in)
        rt_interface_free(&in);
    VkShaderModule m = VK_NULL_HANDLE;
    if (ok && make_module(d, words, n, &m, e)) {
        spec_buf sb;   /* the final view (not RT_CVARIANT_DEBUG), the CPU LOD */
        ok = rt_vk_compute(d, NULL, &(rt_vk_compute_desc){ .label = name, .module = m,
                               .spec = spec_for(pl, (variant & RT_CVARIANT_DEBUG) != 0, &sb),
                               .layout = pl->compute_layout, .cache = pl->cache }, out, e);
        vkDestroyShaderModule(d->dev, m, NULL);
    } else {
        ok = false;
    }
    free(words);
    return ok;
}

bool rt_pipelines_stand_in_spirv(const rt_pack *p, rt_pipelines *pl, splat_stand_in_kind k,
                                 bool count, uint32_t **words, size_t *n, rt_error *e)
{
    *words = NULL;
    *n = 0;
    const char *name = k == SPLAT_STAND_IN_ATLAS ? "atlas stand-in (compute)"
                                                 : "flat stand-in (compute)";
    const rt_spirv *built = &p->stand_in[k];
    if (!count && rt_spirv_present(built)) {
        /* the build's module: checked against its role by rt_pack_spirv */
        const uint32_t *bw = rt_pack_spirv(p, built, n, e);
        if (!bw)
            return false;
        if (!(*words = malloc(*n * 4)))
            return rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
        memcpy(*words, bw, *n * 4);
        atomic_fetch_add(&pl->spirv_cached, 1);
        return true;
    }
    /* an older pack, --glsl-compute, or the counting variant: its GLSL */
    const char *uber = rt_pack_text(p, &p->uber_compute, e);
    if (!uber)
        return false;
    char *src = splat_stand_in_glsl(k, uber, count ? "#define SPLAT_COUNT 1\n" : "");
    if (!src)
        return rt_fail(e, RT_E_VULKAN, name, "no prelude in the uber compute GLSL");
    bool ok = compute_spirv(pl, src, name, words, n, e);
    free(src);
    rt_interface in;
    bool have_in = false;
    if (ok) {
        have_in = rt_interface_for(p, k == SPLAT_STAND_IN_ATLAS ? RT_ROLE_FAR : RT_ROLE_COMPUTE,
                                   &in);
        ok = have_in ? rt_spirv_check(*words, *n, name, &in, e)
                     : rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
    }
    if (have_in)
        rt_interface_free(&in);
    if (!ok) {
        free(*words);
        *words = NULL;
    }
    return ok;
}

bool rt_pipelines_flat(rt_device *d, const rt_pack *p, rt_pipelines *pl, unsigned variant,
                       VkPipeline *out, rt_error *e)
{
    VkPipeline *slot = &pl->flat[variant % RT_CVARIANTS];
    if (*slot) {
        *out = *slot;
        return true;
    }
    /* the sorted variant's lists are dispatched a tile a workgroup here
     * (rt_screen_dispatch): the flat stand-in is never sorted */
    uint32_t *words = NULL;
    size_t n = 0;
    bool ok = rt_pipelines_stand_in_spirv(p, pl, SPLAT_STAND_IN_FLAT,
                                          (variant & RT_CVARIANT_COUNT) != 0, &words, &n, e);
    /* from the words (copied): inside a batch (renderer creation) the
     * driver's compile runs beside the fixed pipelines' */
    static const uint32_t final_view = SPLAT_VIEW_FINAL;
    static const VkSpecializationMapEntry entry = { SPLAT_SPEC_VIEW, 0, sizeof final_view };
    static const VkSpecializationInfo spec = { 1, &entry, sizeof final_view, &final_view };
    ok = ok && rt_vk_compute(d, NULL, &(rt_vk_compute_desc){ .label = "flat stand-in",
                                 .spirv = words, .nwords = n,
                                 .spec = (variant & RT_CVARIANT_DEBUG) ? NULL : &spec,
                                 .layout = pl->compute_layout, .cache = pl->cache }, slot, e);
    free(words);
    *out = *slot;
    return ok;
}

bool rt_pipelines_depth(rt_device *d, rt_pipelines *pl, VkRenderPass pass, bool cull,
                        VkPipeline *out, rt_error *e)
{
    VkPipeline *slot = &pl->depth[cull];
    if (!*slot && !make_pipeline(d, pl, pl->vertex, VK_NULL_HANDLE, pass, K_DEPTH,
                                 cull ? RT_VARIANT_CULL : 0, slot, e))
        return false;
    *out = *slot;
    return true;
}

static void destroy_combos(rt_device *d, rt_pipelines *pl)
{
    rt_async_stop(pl);   /* no worker writes a slot from here on */
    for (size_t i = 0; pl->combo && i < (size_t)pl->ncombos * RT_VARIANTS; i++)
        if (pl->combo[i])
            vkDestroyPipeline(d->dev, pl->combo[i], NULL);
    for (size_t i = 0; pl->compute && i < ((size_t)pl->ncombos + 1) * RT_CVARIANTS; i++)
        if (pl->compute[i])
            vkDestroyPipeline(d->dev, pl->compute[i], NULL);
    for (int i = 0; i < RT_CVARIANTS; i++)   /* its head is the pack's über-shader's */
        if (pl->flat[i]) {
            vkDestroyPipeline(d->dev, pl->flat[i], NULL);
            pl->flat[i] = VK_NULL_HANDLE;
        }
    free(pl->combo);
    free(pl->compute);
    pl->combo = NULL;
    pl->compute = NULL;
    pl->ncombos = 0;
}

bool rt_pipelines_reset_combos(rt_device *d, const rt_pack *p, rt_pipelines *pl,
                               rt_error *e)
{
    destroy_combos(d, pl);
    pl->combo = calloc((size_t)p->ncombos * RT_VARIANTS + 1, sizeof *pl->combo);
    pl->compute = calloc(((size_t)p->ncombos + 1) * RT_CVARIANTS, sizeof *pl->compute);
    if (!pl->combo || !pl->compute)
        return rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
    pl->ncombos = p->ncombos;
    return true;
}

/* A fullscreen-triangle pipeline of the runtime's own: the resolve pass
 * (K_RESOLVE) or the sky (K_SKY), fragment = the prelude + `main_text`. */
static bool fullscreen_pipeline(rt_device *d, rt_pipelines *pl, VkRenderPass pass, kind k,
                                const char *main_text, const char *name, VkPipeline *out,
                                rt_error *e)
{
    size_t n = strlen(SPLAT_GLSL_PRELUDE) + strlen(main_text) + 32;
    char *src = malloc(n);
    if (!src)
        return rt_fail(e, RT_E_VULKAN, name, "out of memory");
    snprintf(src, n, "#version 450\n%s%s", SPLAT_GLSL_PRELUDE, main_text);
    uint32_t *vw = NULL, *fw = NULL;
    size_t vn = 0, fn = 0;
    bool ok = rt_glsl_compile(resolve_vert, VK_SHADER_STAGE_VERTEX_BIT, "fullscreen.vert", &vw, &vn, e) &&
              rt_glsl_compile(src, VK_SHADER_STAGE_FRAGMENT_BIT, name, &fw, &fn, e);
    free(src);
    VkShaderModule vm = VK_NULL_HANDLE, fm = VK_NULL_HANDLE;
    ok = ok && make_module(d, vw, vn, &vm, e) && make_module(d, fw, fn, &fm, e) &&
         make_pipeline(d, pl, vm, fm, pass, k, RT_VARIANT_DEBUG, out, e);
    if (vm)
        vkDestroyShaderModule(d->dev, vm, NULL);
    if (fm)
        vkDestroyShaderModule(d->dev, fm, NULL);
    free(vw);
    free(fw);
    return ok;
}

/* Whether the CPU shading LOD is on (splatrt.h rt_shading_lod): `want`,
 * or with RT_SHADING_LOD_AUTO $SPLAT_SHADING_LOD=0|1, else whether the
 * device is a CPU (lavapipe). */
bool rt_shading_lod_on(const rt_device *d, rt_shading_lod want)
{
    if (want != RT_SHADING_LOD_AUTO)
        return want == RT_SHADING_LOD_ON;
    const char *env = getenv("SPLAT_SHADING_LOD");
    if (env && (!strcmp(env, "0") || !strcmp(env, "1")))
        return env[0] == '1';
    return d->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}

bool rt_pipelines_create(rt_device *d, const rt_pack *p, const rt_passes *rp,
                         rt_reference ref, const char *cache_path,
                         int ntextures, bool shading_lod, rt_pipelines *pl, rt_error *e)
{
    memset(pl, 0, sizeof *pl);
    pl->shading_lod = shading_lod;
    splat_cache_open(&pl->spv_cache, NULL);   /* disabled when it cannot be made */
    if (!make_layouts(d, ntextures, pl, e) || !open_cache(d, pl, cache_path, e) ||
        !pack_module(d, p, &p->vertex, &pl->vertex, e))
        return false;
    if (!rt_pipelines_reset_combos(d, p, pl, e))
        return false;
    if (ref == RT_REF_MULTIPASS) {
        for (int i = 0; i < p->nmaterials; i++)
            if (!rt_spirv_present(&p->materials[i].reference)) {
                char what[256];
                snprintf(what, sizeof what, "materials[%d] (%s) has no reference shader",
                         i, p->materials[i].name);
                return rt_fail(e, RT_E_PACK_FIELD, p->dir, what);
            }
        pl->ref = calloc(2 * (size_t)p->nmaterials + 1, sizeof *pl->ref);
        if (!pl->ref)
            return rt_fail(e, RT_E_VULKAN, "pipelines", "out of memory");
        pl->nref = p->nmaterials;
        if (!fullscreen_pipeline(d, pl, rp->resolve, K_RESOLVE, resolve_frag_main, "resolve.frag",
                                 &pl->resolve, e))
            return false;
    }
    if (ref == RT_REF_UBER && !rt_spirv_present(&p->uber))
        return rt_fail(e, RT_E_PACK_FIELD, p->dir, "the pack has no uber shader");
    return fullscreen_pipeline(d, pl, rp->main, K_SKY, sky_frag_main, "sky.frag", &pl->sky, e);
}

void rt_pipelines_destroy(rt_device *d, rt_pipelines *pl)
{
    rt_async_stop(pl);   /* the workers use the pipeline cache */
    splat_cache_close(&pl->spv_cache);
    if (!d->dev)
        return;
    if (pl->cache) {
        save_cache(d, pl);
        vkDestroyPipelineCache(d->dev, pl->cache, NULL);
    }
    destroy_combos(d, pl);
    for (int i = 0; i < 2 * pl->nref; i++)
        if (pl->ref[i])
            vkDestroyPipeline(d->dev, pl->ref[i], NULL);
    for (int i = 0; i < RT_VARIANTS; i++)
        if (pl->uber[i])
            vkDestroyPipeline(d->dev, pl->uber[i], NULL);
    if (pl->resolve)
        vkDestroyPipeline(d->dev, pl->resolve, NULL);
    if (pl->sky)
        vkDestroyPipeline(d->dev, pl->sky, NULL);
    for (int i = 0; i < 2; i++)
        if (pl->depth[i])
            vkDestroyPipeline(d->dev, pl->depth[i], NULL);
    if (pl->vertex)
        vkDestroyShaderModule(d->dev, pl->vertex, NULL);
    if (pl->layout)
        vkDestroyPipelineLayout(d->dev, pl->layout, NULL);
    if (pl->resolve_layout)
        vkDestroyPipelineLayout(d->dev, pl->resolve_layout, NULL);
    if (pl->compute_layout)
        vkDestroyPipelineLayout(d->dev, pl->compute_layout, NULL);
    if (pl->set_terrain)
        vkDestroyDescriptorSetLayout(d->dev, pl->set_terrain, NULL);
    if (pl->set_material)
        vkDestroyDescriptorSetLayout(d->dev, pl->set_material, NULL);
    if (pl->set_resolve)
        vkDestroyDescriptorSetLayout(d->dev, pl->set_resolve, NULL);
    free(pl->ref);
    free(pl->cache_path);
    memset(pl, 0, sizeof *pl);
}

/* ---- set 0 of the terrain bakes (undergrowth masks, far atlas) ---------- */

/* The terrain's bindings, without the screen path's (7-10), which a
 * bake neither declares nor has to fill. */
static const uint32_t terrain_bindings[] = {
    SPLAT_BIND_HEIGHTFIELD, SPLAT_BIND_PAINTED, SPLAT_BIND_DESTRUCTION_ATLAS,
    SPLAT_BIND_DESTRUCTION_INDEX, SPLAT_BIND_PAINTED_INDEX, SPLAT_BIND_PAINTED_LEVEL,
    SPLAT_BIND_HOLES, SPLAT_BIND_SHADOW,
};
enum { NTERRAIN = sizeof terrain_bindings / sizeof *terrain_bindings };

bool rt_terrain_compute_layout(rt_device *d, VkDescriptorSetLayout *out, rt_error *e)
{
    VkDescriptorSetLayoutBinding b[NTERRAIN + 2];
    for (int i = 0; i < NTERRAIN; i++)
        b[i] = (VkDescriptorSetLayoutBinding){ terrain_bindings[i],
            VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL };
    b[NTERRAIN] = (VkDescriptorSetLayoutBinding){ SPLAT_BIND_FRAME,
        VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL };
    b[NTERRAIN + 1] = (VkDescriptorSetLayoutBinding){ SPLAT_BIND_VECTORS,
        VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, NULL };
    return rt_vk_set_layout(d, NULL, &(rt_vk_set_layout_desc){ "terrain bake", b, NTERRAIN + 2 },
                            out, e);
}

void rt_terrain_compute_set(rt_device *d, VkDescriptorSet src, VkDescriptorSet dst,
                            VkBuffer frame)
{
    VkCopyDescriptorSet cp[NTERRAIN + 1];
    for (int i = 0; i <= NTERRAIN; i++) {
        uint32_t bi = i < NTERRAIN ? terrain_bindings[i] : SPLAT_BIND_VECTORS;
        cp[i] = (VkCopyDescriptorSet){ .sType = VK_STRUCTURE_TYPE_COPY_DESCRIPTOR_SET,
            .srcSet = src, .srcBinding = bi, .dstSet = dst, .dstBinding = bi,
            .descriptorCount = 1 };
    }
    VkDescriptorBufferInfo fb = { frame, 0, sizeof(splat_frame) };
    VkWriteDescriptorSet w = {
        .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = dst,
        .dstBinding = SPLAT_BIND_FRAME, .descriptorCount = 1,
        .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, .pBufferInfo = &fb,
    };
    vkUpdateDescriptorSets(d->dev, 1, &w, NTERRAIN + 1, cp);
}
