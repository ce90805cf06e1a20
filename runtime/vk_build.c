/* vk_build.c — desc structs to Vulkan objects, and destroy lists
 * (vk_build.h).  Each maker fills the Vk*CreateInfo from the desc's
 * fields and defaults, creates, and records the handle in the list;
 * pipelines within a batch are made together on every core. */
#include "vk_build.h"

#include <assert.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- destroy lists ---------------------------------------------------- */

uint64_t rt_vk_u64(const void *handle, size_t size)
{
    uint64_t v = 0;
    memcpy(&v, handle, size < sizeof v ? size : sizeof v);
    return v;
}

static void *from_u64_ptr(uint64_t h)
{
    void *p = NULL;
    memcpy(&p, &h, sizeof p < sizeof h ? sizeof p : sizeof h);
    return p;
}

static void destroy_one(rt_device *d, VkObjectType t, uint64_t h)
{
    VkDevice dev = d->dev;
    /* non-dispatchable handles: pointers on 64-bit hosts, uint64_t else */
#if VK_USE_64_BIT_PTR_DEFINES
#define H(type) ((type)from_u64_ptr(h))
#else
#define H(type) ((type)h)
#endif
    switch (t) {
    case VK_OBJECT_TYPE_RENDER_PASS:           vkDestroyRenderPass(dev, H(VkRenderPass), NULL); break;
    case VK_OBJECT_TYPE_FRAMEBUFFER:           vkDestroyFramebuffer(dev, H(VkFramebuffer), NULL); break;
    case VK_OBJECT_TYPE_SAMPLER:               vkDestroySampler(dev, H(VkSampler), NULL); break;
    case VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT:
        vkDestroyDescriptorSetLayout(dev, H(VkDescriptorSetLayout), NULL);
        break;
    case VK_OBJECT_TYPE_PIPELINE_LAYOUT:       vkDestroyPipelineLayout(dev, H(VkPipelineLayout), NULL); break;
    case VK_OBJECT_TYPE_PIPELINE:              vkDestroyPipeline(dev, H(VkPipeline), NULL); break;
    case VK_OBJECT_TYPE_DESCRIPTOR_POOL:       vkDestroyDescriptorPool(dev, H(VkDescriptorPool), NULL); break;
    case VK_OBJECT_TYPE_SHADER_MODULE:         vkDestroyShaderModule(dev, H(VkShaderModule), NULL); break;
    case VK_OBJECT_TYPE_IMAGE_VIEW:            vkDestroyImageView(dev, H(VkImageView), NULL); break;
    case VK_OBJECT_TYPE_QUERY_POOL:            vkDestroyQueryPool(dev, H(VkQueryPool), NULL); break;
    case VK_OBJECT_TYPE_SEMAPHORE:             vkDestroySemaphore(dev, H(VkSemaphore), NULL); break;
    case VK_OBJECT_TYPE_FENCE:                 vkDestroyFence(dev, H(VkFence), NULL); break;
    default:
        assert(!"rt_vk_list: a handle type it cannot destroy");
        break;
    }
#undef H
}

bool rt_vk_keep(rt_device *d, rt_vk_list *l, VkObjectType type, uint64_t handle, rt_error *e)
{
    if (!l || !handle)
        return true;
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 16;
        rt_vk_obj *v = realloc(l->v, (size_t)cap * sizeof *v);
        if (!v) {
            destroy_one(d, type, handle);
            return rt_fail(e, RT_E_VULKAN, "destroy list", "out of memory");
        }
        l->v = v;
        l->cap = cap;
    }
    l->v[l->n++] = (rt_vk_obj){ type, handle };
    return true;
}

void rt_vk_list_destroy(rt_device *d, rt_vk_list *l)
{
    if (!l)
        return;
    if (d->dev)
        for (int i = l->n - 1; i >= 0; i--)
            destroy_one(d, l->v[i].type, l->v[i].handle);
    free(l->v);
    memset(l, 0, sizeof *l);
}

/* A failed vkCreate*: "call(label)" and the result into *e. */
static bool failed(rt_error *e, const char *call, const char *label, VkResult r)
{
    char what[160];
    snprintf(what, sizeof what, "%s(%s)", call, label ? label : "");
    return rt_fail(e, RT_E_VULKAN, what, rt_vk_result_name(r));
}

/* After a vkCreate*: fail, or record the handle (*out zeroed when the
 * list cannot grow: the handle is destroyed then). */
static bool made(rt_device *d, rt_vk_list *l, VkResult r, const char *call, const char *label,
                 VkObjectType type, void *out, size_t size, rt_error *e)
{
    if (r != VK_SUCCESS)
        return failed(e, call, label, r);
    if (rt_vk_keep(d, l, type, rt_vk_u64(out, size), e))
        return true;
    memset(out, 0, size);
    return false;
}
#define MADE(r, call, desc, type, out) \
    made(d, l, r, call, (desc)->label, type, out, sizeof *(out), e)

/* ---- render passes and framebuffers ----------------------------------- */

static VkAttachmentDescription attachment(const rt_vk_attachment *a)
{
    return (VkAttachmentDescription){
        .format = a->format,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .loadOp = a->load,
        .storeOp = a->store,
        .stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
        .stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
        .initialLayout = a->initial,
        .finalLayout = a->final,
    };
}

bool rt_vk_pass(rt_device *d, rt_vk_list *l, const rt_vk_pass_desc *desc, VkRenderPass *out,
                rt_error *e)
{
    assert(desc->ncolor <= RT_VK_MAX_COLOR);
    VkAttachmentDescription att[RT_VK_MAX_COLOR + 1];
    VkAttachmentReference cref[RT_VK_MAX_COLOR];
    uint32_t n = 0;
    for (; n < desc->ncolor; n++) {
        att[n] = attachment(&desc->color[n]);
        cref[n] = (VkAttachmentReference){ n, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL };
    }
    bool depth = desc->depth.format != VK_FORMAT_UNDEFINED;
    VkAttachmentReference dref = { n, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    if (depth)
        att[n++] = attachment(&desc->depth);
    VkSubpassDescription sub = {
        .pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS,
        .colorAttachmentCount = desc->ncolor,
        .pColorAttachments = desc->ncolor ? cref : NULL,
        .pDepthStencilAttachment = depth ? &dref : NULL,
    };
    VkRenderPassCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO,
        .attachmentCount = n, .pAttachments = att,
        .subpassCount = 1, .pSubpasses = &sub,
        .dependencyCount = desc->ndeps, .pDependencies = desc->deps,
    };
    VkResult r = vkCreateRenderPass(d->dev, &ci, NULL, out);
    return MADE(r, "vkCreateRenderPass", desc, VK_OBJECT_TYPE_RENDER_PASS, out);
}

bool rt_vk_fb(rt_device *d, rt_vk_list *l, const rt_vk_fb_desc *desc, VkFramebuffer *out,
              rt_error *e)
{
    VkFramebufferCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO,
        .renderPass = desc->pass,
        .attachmentCount = desc->nviews, .pAttachments = desc->views,
        .width = desc->width, .height = desc->height, .layers = 1,
    };
    VkResult r = vkCreateFramebuffer(d->dev, &ci, NULL, out);
    return MADE(r, "vkCreateFramebuffer", desc, VK_OBJECT_TYPE_FRAMEBUFFER, out);
}

/* ---- samplers ---------------------------------------------------------- */

bool rt_vk_sampler(rt_device *d, rt_vk_list *l, const rt_vk_sampler_desc *desc, VkSampler *out,
                   rt_error *e)
{
    VkSamplerCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = desc->filter, .minFilter = desc->filter,
        .mipmapMode = desc->mip,
        .addressModeU = desc->wrap, .addressModeV = desc->wrap, .addressModeW = desc->wrap,
        .maxLod = desc->max_lod,
    };
    VkResult r = vkCreateSampler(d->dev, &ci, NULL, out);
    return MADE(r, "vkCreateSampler", desc, VK_OBJECT_TYPE_SAMPLER, out);
}

/* ---- layouts ----------------------------------------------------------- */

bool rt_vk_set_layout(rt_device *d, rt_vk_list *l, const rt_vk_set_layout_desc *desc,
                      VkDescriptorSetLayout *out, rt_error *e)
{
    VkDescriptorSetLayoutCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = desc->n, .pBindings = desc->bindings,
    };
    VkResult r = vkCreateDescriptorSetLayout(d->dev, &ci, NULL, out);
    return MADE(r, "vkCreateDescriptorSetLayout", desc, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, out);
}

bool rt_vk_layout(rt_device *d, rt_vk_list *l, const rt_vk_layout_desc *desc,
                  VkPipelineLayout *out, rt_error *e)
{
    VkPushConstantRange pr = { desc->push_stages, 0, desc->push_bytes };
    VkPipelineLayoutCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = desc->nsets, .pSetLayouts = desc->sets,
        .pushConstantRangeCount = desc->push_bytes ? 1 : 0,
        .pPushConstantRanges = desc->push_bytes ? &pr : NULL,
    };
    VkResult r = vkCreatePipelineLayout(d->dev, &ci, NULL, out);
    return MADE(r, "vkCreatePipelineLayout", desc, VK_OBJECT_TYPE_PIPELINE_LAYOUT, out);
}

/* ---- pipelines --------------------------------------------------------- */

/* The desc's module, or its GLSL compiled into *own (the caller frees). */
static bool stage_module(rt_device *d, VkShaderModule m, const char *glsl,
                         VkShaderStageFlagBits stage, const char *label, VkShaderModule *use,
                         VkShaderModule *own, rt_error *e)
{
    *use = m;
    if (m || !glsl)
        return true;
    char name[128];
    snprintf(name, sizeof name, "%s.%s", label ? label : "shader",
             stage == VK_SHADER_STAGE_VERTEX_BIT     ? "vert"
             : stage == VK_SHADER_STAGE_FRAGMENT_BIT ? "frag" : "comp");
    if (!rt_glsl_module(d, glsl, stage, name, NULL, own, e))
        return false;
    *use = *own;
    return true;
}

static bool make_gfx(rt_device *d, const rt_vk_gfx_desc *desc, VkShaderModule vs,
                     VkShaderModule fs, VkPipeline *out, rt_error *e)
{
    VkPipelineShaderStageCreateInfo st[2] = {
        { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
          .stage = VK_SHADER_STAGE_VERTEX_BIT, .module = vs, .pName = "main" },
        { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
          .stage = VK_SHADER_STAGE_FRAGMENT_BIT, .module = fs, .pName = "main",
          .pSpecializationInfo = desc->fs_spec },
    };
    VkPipelineVertexInputStateCreateInfo vi = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
        .vertexBindingDescriptionCount = desc->nvbufs, .pVertexBindingDescriptions = desc->vbufs,
        .vertexAttributeDescriptionCount = desc->nattrs, .pVertexAttributeDescriptions = desc->attrs,
    };
    VkPipelineInputAssemblyStateCreateInfo ia = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = desc->topology ? desc->topology : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
    };
    VkViewport vp = { 0, 0, (float)desc->viewport.width, (float)desc->viewport.height, 0, 1 };
    VkRect2D sc = { { 0, 0 }, desc->viewport };
    bool fixed = desc->viewport.width && desc->viewport.height;
    VkPipelineViewportStateCreateInfo vps = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1, .pViewports = fixed ? &vp : NULL,
        .scissorCount = 1, .pScissors = fixed ? &sc : NULL,
    };
    VkPipelineRasterizationStateCreateInfo rs = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
        .polygonMode = desc->polygon, .cullMode = desc->cull, .frontFace = desc->front,
        .lineWidth = 1.0f,
    };
    VkPipelineMultisampleStateCreateInfo ms = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT,
    };
    VkPipelineDepthStencilStateCreateInfo ds = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = desc->depth_test, .depthWriteEnable = desc->depth_write,
        .depthCompareOp = desc->depth_compare,
    };
    assert(desc->ncolor <= RT_VK_MAX_COLOR);
    VkPipelineColorBlendAttachmentState opaque[RT_VK_MAX_COLOR];
    for (uint32_t i = 0; i < RT_VK_MAX_COLOR; i++)
        opaque[i] = (VkPipelineColorBlendAttachmentState){ .colorWriteMask = 0xf };
    VkPipelineColorBlendStateCreateInfo cb = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = desc->ncolor, .pAttachments = desc->blend ? desc->blend : opaque,
    };
    VkDynamicState dyn[2] = { VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR };
    VkPipelineDynamicStateCreateInfo dy = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
        .dynamicStateCount = 2, .pDynamicStates = dyn,
    };
    VkGraphicsPipelineCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
        .stageCount = fs ? 2 : 1, .pStages = st,
        .pVertexInputState = &vi, .pInputAssemblyState = &ia, .pViewportState = &vps,
        .pRasterizationState = &rs, .pMultisampleState = &ms, .pDepthStencilState = &ds,
        .pColorBlendState = &cb, .pDynamicState = fixed ? NULL : &dy,
        .layout = desc->layout, .renderPass = desc->pass,
    };
    VkResult r = vkCreateGraphicsPipelines(d->dev, desc->cache, 1, &ci, NULL, out);
    return r == VK_SUCCESS || failed(e, "vkCreateGraphicsPipelines", desc->label, r);
}

/* ---- batches: pipelines made together on every core -------------------- */

typedef struct batch_job {
    bool                 gfx;
    rt_vk_gfx_desc       g;        /* deep copies: the strings and arrays below */
    rt_vk_compute_desc   c;
    rt_vk_list          *l;
    VkPipeline          *out;
    VkSpecializationInfo spec;
    void                *own[6];   /* what the copies own                      */
    rt_error             e;
} batch_job;

struct rt_vk_batch {
    pthread_t  owner;
    batch_job *jobs;
    int        n, cap;
};

bool rt_vk_batch_begin(rt_device *d, rt_error *e)
{
    if (d->batch)
        return rt_fail(e, RT_E_VULKAN, "pipeline batch", "already begun");
    d->batch = calloc(1, sizeof *d->batch);
    if (!d->batch)
        return rt_fail(e, RT_E_VULKAN, "pipeline batch", "out of memory");
    d->batch->owner = pthread_self();
    return true;
}

static void *dup_bytes(const void *p, size_t n, bool *ok)
{
    if (!p || !n)
        return NULL;
    void *q = malloc(n);
    if (!q) {
        *ok = false;
        return NULL;
    }
    memcpy(q, p, n);
    return q;
}

static char *dup_str(const char *s, bool *ok)
{
    return s ? dup_bytes(s, strlen(s) + 1, ok) : NULL;
}

/* A copy of `sp` into j (entries and data owned in j->own[4..5]). */
static const VkSpecializationInfo *dup_spec(batch_job *j, const VkSpecializationInfo *sp,
                                            bool *ok)
{
    if (!sp)
        return NULL;
    j->spec = *sp;
    j->spec.pMapEntries = j->own[4] =
        dup_bytes(sp->pMapEntries, sp->mapEntryCount * sizeof *sp->pMapEntries, ok);
    j->spec.pData = j->own[5] = dup_bytes(sp->pData, sp->dataSize, ok);
    return &j->spec;
}

/* The job slot for a deferred pipeline, or NULL: no batch on this thread,
 * or a desc that cannot wait (modules the caller destroys, a check). */
static batch_job *batch_slot(rt_device *d, bool deferrable)
{
    struct rt_vk_batch *b = d->batch;
    if (!b || !deferrable || !pthread_equal(b->owner, pthread_self()))
        return NULL;
    if (b->n == b->cap) {
        int cap = b->cap ? 2 * b->cap : 16;
        batch_job *v = realloc(b->jobs, (size_t)cap * sizeof *v);
        if (!v)
            return NULL;   /* made at once instead */
        b->jobs = v;
        b->cap = cap;
    }
    batch_job *j = &b->jobs[b->n];
    memset(j, 0, sizeof *j);
    return j;
}

static void job_free(batch_job *j)
{
    for (int i = 0; i < 6; i++)
        free(j->own[i]);
}

static bool defer_gfx(rt_device *d, rt_vk_list *l, const rt_vk_gfx_desc *desc, VkPipeline *out)
{
    batch_job *j = batch_slot(d, !desc->vs && !desc->fs);
    if (!j)
        return false;
    bool ok = true;
    j->gfx = true;
    j->g = *desc;
    j->g.label = j->own[0] = dup_str(desc->label, &ok);
    j->g.vs_glsl = j->own[1] = dup_str(desc->vs_glsl, &ok);
    j->g.fs_glsl = j->own[2] = dup_str(desc->fs_glsl, &ok);
    /* one block for the three arrays */
    size_t nv = desc->nvbufs * sizeof *desc->vbufs, na = desc->nattrs * sizeof *desc->attrs;
    size_t nb = desc->blend ? desc->ncolor * sizeof *desc->blend : 0;
    char *arr = j->own[3] = nv + na + nb ? malloc(nv + na + nb) : NULL;
    if (nv + na + nb && !arr)
        ok = false;
    if (arr) {
        if (nv)
            j->g.vbufs = memcpy(arr, desc->vbufs, nv);
        if (na)
            j->g.attrs = memcpy(arr + nv, desc->attrs, na);
        if (nb)
            j->g.blend = memcpy(arr + nv + na, desc->blend, nb);
    }
    j->g.fs_spec = dup_spec(j, desc->fs_spec, &ok);
    if (!ok) {
        job_free(j);
        return false;   /* made at once instead */
    }
    j->l = l;
    j->out = out;
    *out = VK_NULL_HANDLE;
    d->batch->n++;
    return true;
}

static bool defer_compute(rt_device *d, rt_vk_list *l, const rt_vk_compute_desc *desc,
                          VkPipeline *out)
{
    batch_job *j = batch_slot(d, !desc->module && !desc->check);
    if (!j)
        return false;
    bool ok = true;
    j->c = *desc;
    j->c.label = j->own[0] = dup_str(desc->label, &ok);
    j->c.glsl = j->own[1] = dup_str(desc->glsl, &ok);
    j->c.spirv = j->own[2] = dup_bytes(desc->spirv, desc->nwords * 4, &ok);
    j->c.spec = dup_spec(j, desc->spec, &ok);
    if (!ok) {
        job_free(j);
        return false;
    }
    j->l = l;
    j->out = out;
    *out = VK_NULL_HANDLE;
    d->batch->n++;
    return true;
}

static bool gfx_now(rt_device *d, rt_vk_list *l, const rt_vk_gfx_desc *desc, VkPipeline *out,
                    rt_error *e);
static bool compute_now(rt_device *d, rt_vk_list *l, const rt_vk_compute_desc *desc,
                        VkPipeline *out, rt_error *e);

typedef struct batch_run {
    rt_device *d;
    batch_job *jobs;
} batch_run;

/* One job on a worker: the pipeline alone (its list is filled after). */
static bool run_job(void *ctx, int k, rt_error *e)
{
    batch_run *r = ctx;
    batch_job *j = &r->jobs[k];
    double t0 = rt_launch_tracing() ? rt_seconds_since_launch() : 0;
    bool ok = j->gfx ? gfx_now(r->d, NULL, &j->g, j->out, e)
                     : compute_now(r->d, NULL, &j->c, j->out, e);
    if (rt_launch_tracing())
        rt_launch_mark("  pipeline %s: %.1f ms", j->gfx ? j->g.label : j->c.label,
                       1e3 * (rt_seconds_since_launch() - t0));
    return ok;
}

bool rt_vk_batch_end(rt_device *d, bool run, rt_error *e)
{
    struct rt_vk_batch *b = d->batch;
    if (!b)
        return true;
    d->batch = NULL;
    bool ok = true;
    if (run && b->n > 0) {
        batch_run r = { d, b->jobs };
        ok = rt_parallel(b->n, run_job, &r, e);
        /* every pipeline made goes to its list, also after a failure,
         * so its owner destroys it */
        for (int k = 0; k < b->n; k++) {
            batch_job *j = &b->jobs[k];
            if (*j->out && !rt_vk_keep(d, j->l, VK_OBJECT_TYPE_PIPELINE, RT_VK_H(*j->out),
                                       ok ? e : &j->e)) {
                *j->out = VK_NULL_HANDLE;
                rt_error_clear(&j->e);
                ok = false;
            }
        }
    }
    for (int k = 0; k < b->n; k++)
        job_free(&b->jobs[k]);
    free(b->jobs);
    free(b);
    return ok;
}

bool rt_vk_gfx(rt_device *d, rt_vk_list *l, const rt_vk_gfx_desc *desc, VkPipeline *out,
               rt_error *e)
{
    return defer_gfx(d, l, desc, out) || gfx_now(d, l, desc, out, e);
}

bool rt_vk_compute(rt_device *d, rt_vk_list *l, const rt_vk_compute_desc *desc, VkPipeline *out,
                   rt_error *e)
{
    return defer_compute(d, l, desc, out) || compute_now(d, l, desc, out, e);
}

static bool gfx_now(rt_device *d, rt_vk_list *l, const rt_vk_gfx_desc *desc, VkPipeline *out,
                    rt_error *e)
{
    VkShaderModule vs, fs, own_vs = VK_NULL_HANDLE, own_fs = VK_NULL_HANDLE;
    bool ok = stage_module(d, desc->vs, desc->vs_glsl, VK_SHADER_STAGE_VERTEX_BIT, desc->label,
                           &vs, &own_vs, e) &&
              stage_module(d, desc->fs, desc->fs_glsl, VK_SHADER_STAGE_FRAGMENT_BIT, desc->label,
                           &fs, &own_fs, e) &&
              make_gfx(d, desc, vs, fs, out, e) &&
              made(d, l, VK_SUCCESS, "", NULL, VK_OBJECT_TYPE_PIPELINE, out, sizeof *out, e);
    if (own_vs)
        vkDestroyShaderModule(d->dev, own_vs, NULL);
    if (own_fs)
        vkDestroyShaderModule(d->dev, own_fs, NULL);
    return ok;
}

static bool compute_now(rt_device *d, rt_vk_list *l, const rt_vk_compute_desc *desc,
                        VkPipeline *out, rt_error *e)
{
    VkShaderModule m = desc->module, own = VK_NULL_HANDLE;
    if (!m && desc->spirv) {
        VkShaderModuleCreateInfo mi = {
            .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
            .codeSize = desc->nwords * 4, .pCode = desc->spirv,
        };
        VkResult r = vkCreateShaderModule(d->dev, &mi, NULL, &own);
        if (r != VK_SUCCESS)
            return rt_fail(e, RT_E_VULKAN, "vkCreateShaderModule", rt_vk_result_name(r));
    } else if (!m && !rt_glsl_module(d, desc->glsl, VK_SHADER_STAGE_COMPUTE_BIT,
                                     desc->label ? desc->label : "compute", desc->check, &own,
                                     e)) {
        return false;
    }
    VkComputePipelineCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                   .stage = VK_SHADER_STAGE_COMPUTE_BIT, .module = m ? m : own, .pName = "main",
                   .pSpecializationInfo = desc->spec },
        .layout = desc->layout,
    };
    VkResult r = vkCreateComputePipelines(d->dev, desc->cache, 1, &ci, NULL, out);
    if (own)
        vkDestroyShaderModule(d->dev, own, NULL);
    return MADE(r, "vkCreateComputePipelines", desc, VK_OBJECT_TYPE_PIPELINE, out);
}

/* ---- descriptor sets --------------------------------------------------- */

bool rt_vk_sets(rt_device *d, rt_vk_list *l, const rt_vk_sets_desc *desc, VkDescriptorPool *pool,
                VkDescriptorSet *sets, rt_error *e)
{
    VkDescriptorPoolCreateInfo pci = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = desc->nsets, .poolSizeCount = desc->nsizes, .pPoolSizes = desc->sizes,
    };
    VkResult r = vkCreateDescriptorPool(d->dev, &pci, NULL, pool);
    if (!MADE(r, "vkCreateDescriptorPool", desc, VK_OBJECT_TYPE_DESCRIPTOR_POOL, pool))
        return false;
    VkDescriptorSetAllocateInfo ai = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = *pool, .descriptorSetCount = desc->nsets, .pSetLayouts = desc->layouts,
    };
    r = vkAllocateDescriptorSets(d->dev, &ai, sets);
    return r == VK_SUCCESS || failed(e, "vkAllocateDescriptorSets", desc->label, r);
}

void rt_vk_write_sets(rt_device *d, const rt_vk_write *w, uint32_t n)
{
    enum { CHUNK = 16 };
    VkWriteDescriptorSet vw[CHUNK];
    VkDescriptorBufferInfo bi[CHUNK];
    VkDescriptorImageInfo ii[CHUNK];
    for (uint32_t at = 0; at < n; at += CHUNK) {
        uint32_t k = n - at < CHUNK ? n - at : CHUNK;
        for (uint32_t i = 0; i < k; i++) {
            const rt_vk_write *x = &w[at + i];
            bi[i] = (VkDescriptorBufferInfo){ x->buf, 0, x->range ? x->range : VK_WHOLE_SIZE };
            ii[i] = (VkDescriptorImageInfo){ x->sampler, x->view,
                x->layout ? x->layout : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL };
            vw[i] = (VkWriteDescriptorSet){
                .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
                .dstSet = x->set, .dstBinding = x->binding,
                .descriptorCount = x->images ? x->count : 1, .descriptorType = x->type,
                .pBufferInfo = x->buf ? &bi[i] : NULL,
                .pImageInfo = x->images ? x->images : x->buf ? NULL : &ii[i],
            };
        }
        vkUpdateDescriptorSets(d->dev, k, vw, 0, NULL);
    }
}
