/* vk_build.c — desc structs to Vulkan objects, and destroy lists
 * (vk_build.h).  Each maker fills the Vk*CreateInfo from the desc's
 * fields and defaults, creates, and records the handle in the list. */
#include "vk_build.h"

#include <assert.h>
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

bool rt_vk_gfx(rt_device *d, rt_vk_list *l, const rt_vk_gfx_desc *desc, VkPipeline *out,
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

bool rt_vk_compute(rt_device *d, rt_vk_list *l, const rt_vk_compute_desc *desc, VkPipeline *out,
                   rt_error *e)
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
