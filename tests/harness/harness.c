/* harness.c — the harness's Vulkan device and compute dispatch (harness.h).
 *
 * One instance, one device, one compute queue, one command buffer reused for
 * every run.  A run creates its buffers, images, pipeline and descriptor set,
 * submits once, waits on a fence, reads back and destroys what it created:
 * simple and leak-free rather than fast (tests dispatch a few times). */
#include "harness.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt_internal.h"
#include "spv.h"

struct harness {
    rt_device       rt;         /* instance, device, queue, pool, messenger:
                                   libsplatrt's (runtime/device.c)       */
    VkCommandBuffer cmd;
    VkFence         fence;
    bool            validate;
};

/* ---- errors ------------------------------------------------------------ */

__attribute__((format(printf, 2, 3)))
static void set_err(char **err, const char *fmt, ...)
{
    if (!err || *err)          /* keep the first message */
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0 || !(*err = malloc((size_t)n + 1)))
        return;
    va_start(ap, fmt);
    vsnprintf(*err, (size_t)n + 1, fmt, ap);
    va_end(ap);
}

/* Check a VkResult at run time (never inside assert); on failure record
 * "harness.c:LINE: call: VK_ERROR_…" and jump to the function's `fail`. */
#define VK(call)                                                          \
    do {                                                                  \
        VkResult vk_r_ = (call);                                          \
        if (vk_r_ != VK_SUCCESS) {                                        \
            set_err(err, "%s:%d: %s: %s", __FILE__, __LINE__, #call,      \
                    rt_vk_result_name(vk_r_));                               \
            goto fail;                                                    \
        }                                                                 \
    } while (0)

/* A failed runtime call's message into *err; returns false. */
static bool rt_err(char **err, rt_error *e)
{
    set_err(err, "%s", e->msg ? e->msg : "splatrt call failed");
    rt_error_clear(e);
    return false;
}

/* ---- instance and device ------------------------------------------------ */

/* The device is libsplatrt's (rt_device_create: validation layer and
 * messenger, SPLAT_DEVICE, discrete GPU first; validation asked for but not
 * installed is its error RT_E_NO_VALIDATION). */
harness *harness_create(const harness_desc *desc, char **err)
{
    harness_desc dd = desc ? *desc : (harness_desc){0};
    if (err)
        *err = NULL;
    harness *h = calloc(1, sizeof *h);
    if (!h) {
        set_err(err, "out of memory");
        return NULL;
    }
    const char *env = getenv("SPLAT_VALIDATE");
    h->validate = dd.validate || (env && strcmp(env, "1") == 0);
    if (!dd.device)
        dd.device = getenv("SPLAT_DEVICE");
    rt_device_desc rd = { .validate = h->validate, .select = dd.device };
    rt_error e = { 0 };
    if (!rt_device_create(&h->rt, &rd, &e)) {
        if (e.id == RT_E_NO_DEVICE && dd.device && *dd.device)
            set_err(err, "no Vulkan 1.2 device named like '%s'", dd.device);
        rt_err(err, &e);    /* keeps the first message */
        goto fail;
    }
    VkCommandBufferAllocateInfo cai = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = h->rt.pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VK(vkAllocateCommandBuffers(h->rt.dev, &cai, &h->cmd));
    VkFenceCreateInfo fci = { .sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO };
    VK(vkCreateFence(h->rt.dev, &fci, NULL, &h->fence));
    return h;
fail:
    harness_destroy(h);
    return NULL;
}

int harness_destroy(harness *h)
{
    if (!h)
        return 0;
    if (h->rt.dev) {
        vkDeviceWaitIdle(h->rt.dev);
        if (h->fence)
            vkDestroyFence(h->rt.dev, h->fence, NULL);
    }
    rt_device_destroy(&h->rt);      /* the command buffer goes with its pool */
    int n = rt_device_messages(&h->rt);
    free(h);
    return n;
}

const char *harness_device_name(const harness *h) { return h->rt.props.deviceName; }
bool harness_validating(const harness *h) { return h->validate; }
int harness_validation_count(const harness *h) { return rt_device_messages(&h->rt); }

/* ---- resources of one run ----------------------------------------------- */

/* Buffers and images are libsplatrt's (rt_buffer, rt_image); an image
 * here also carries its sampler. */
typedef struct himage {
    rt_image  im;
    VkSampler sampler;
} himage;

/* A host-visible, coherent buffer, mapped, zero-filled. */
static bool buffer_create(harness *h, VkDeviceSize size, VkBufferUsageFlags usage,
                          rt_buffer *b, char **err)
{
    rt_error e = { 0 };
    if (!rt_buffer_create(&h->rt, size, usage, true, b, &e))
        return rt_err(err, &e);
    memset(b->map, 0, size);
    return true;
}

/* An RGBA32F image with its view and sampler; the texels are copied in by
 * the run's command buffer from `staging` (see record_upload). */
static bool image_create(harness *h, const harness_image *src, himage *im,
                         char **err)
{
    const VkFormat fmt = VK_FORMAT_R32G32B32A32_SFLOAT;
    VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
    if (src->filter == IR_FILTER_LINEAR)
        need |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
    if (!rt_format_supports(&h->rt, fmt, need)) {
        set_err(err, "%s cannot sample RGBA32F images with this filter",
                h->rt.props.deviceName);
        return false;
    }
    rt_error e = { 0 };
    if (!rt_image_create(&h->rt, (uint32_t)src->width, (uint32_t)src->height, 1, false, 1,
                         fmt, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                         VK_IMAGE_ASPECT_COLOR_BIT, &im->im, &e))
        return rt_err(err, &e);
    VkFilter f = src->filter == IR_FILTER_NEAREST ? VK_FILTER_NEAREST : VK_FILTER_LINEAR;
    VkSamplerAddressMode am = rt_sampler_wrap(src->wrap);
    VkSamplerCreateInfo sci = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = f,
        .minFilter = f,
        .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = am,
        .addressModeV = am,
        .addressModeW = am,
        .maxLod = 0.0f,
    };
    VK(vkCreateSampler(h->rt.dev, &sci, NULL, &im->sampler));
    return true;
fail:
    return false;
}

static void image_destroy(harness *h, himage *im)
{
    if (im->sampler)
        vkDestroySampler(h->rt.dev, im->sampler, NULL);
    rt_image_destroy(&h->rt, &im->im);
    im->sampler = VK_NULL_HANDLE;
}

/* ---- the run ------------------------------------------------------------- */

static bool check_dispatch(const harness_dispatch *d, char **err)
{
    if (!d->spv || d->nwords < 5) {
        set_err(err, "harness_run: no SPIR-V");
        return false;
    }
    /* Invalid SPIR-V is undefined behaviour for the driver: refuse it. */
    char *log = NULL;
    if (!spv_validate(d->spv, d->nwords, &log)) {
        set_err(err, "harness_run: invalid SPIR-V: %s", log ? log : "");
        free(log);
        return false;
    }
    if (!d->input || !d->input_bytes || !d->output || !d->output_bytes) {
        set_err(err, "harness_run: input and output buffers are required");
        return false;
    }
    if (d->push_bytes > 128 || d->push_bytes % 4 || (d->push_bytes && !d->push)) {
        set_err(err, "harness_run: push constants must be 4-byte multiples, at most 128");
        return false;
    }
    for (int i = 0; i < d->nimages; i++) {
        const harness_image *im = &d->images[i];
        if (im->width <= 0 || im->height <= 0 || !im->rgba) {
            set_err(err, "harness_run: image %d has no texels", i);
            return false;
        }
    }
    return true;
}

bool harness_run(harness *h, const harness_dispatch *d, char **err)
{
    if (err)
        *err = NULL;
    if (!check_dispatch(d, err))
        return false;

    const int nimg = d->nimages;
    const uint32_t nbind = 2 + (uint32_t)nimg;
    bool ok = false;
    rt_buffer in = {0}, out = {0};
    rt_buffer *staging = calloc((size_t)nimg + 1, sizeof *staging);
    himage *images = calloc((size_t)nimg + 1, sizeof *images);
    VkDescriptorSetLayoutBinding *binds = calloc(nbind, sizeof *binds);
    VkDescriptorImageInfo *iinfo = calloc((size_t)nimg + 1, sizeof *iinfo);
    VkWriteDescriptorSet *writes = calloc(nbind, sizeof *writes);
    VkShaderModule module = VK_NULL_HANDLE;
    VkDescriptorSetLayout dsl = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkDescriptorPool dpool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    if (!staging || !images || !binds || !iinfo || !writes) {
        set_err(err, "out of memory");
        goto fail;
    }

    /* Buffers and images. */
    if (!buffer_create(h, d->input_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, &in, err) ||
        !buffer_create(h, d->output_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, &out, err))
        goto fail;
    memcpy(in.map, d->input, d->input_bytes);
    for (int i = 0; i < nimg; i++) {
        const harness_image *src = &d->images[i];
        size_t bytes = (size_t)src->width * (size_t)src->height * 4 * sizeof(float);
        if (!buffer_create(h, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, &staging[i], err) ||
            !image_create(h, src, &images[i], err))
            goto fail;
        memcpy(staging[i].map, src->rgba, bytes);
    }

    /* Pipeline. */
    VkShaderModuleCreateInfo smci = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = d->nwords * sizeof(uint32_t),
        .pCode = d->spv,
    };
    VK(vkCreateShaderModule(h->rt.dev, &smci, NULL, &module));
    for (uint32_t b = 0; b < nbind; b++)
        binds[b] = (VkDescriptorSetLayoutBinding){
            .binding = b,
            .descriptorType = b < 2 ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                    : VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
            .descriptorCount = 1,
            .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT,
        };
    VkDescriptorSetLayoutCreateInfo dslci = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = nbind,
        .pBindings = binds,
    };
    VK(vkCreateDescriptorSetLayout(h->rt.dev, &dslci, NULL, &dsl));
    VkPushConstantRange pcr = {
        .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT,
        .offset = 0,
        .size = d->push_bytes,
    };
    VkPipelineLayoutCreateInfo plci = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = 1,
        .pSetLayouts = &dsl,
        .pushConstantRangeCount = d->push_bytes ? 1 : 0,
        .pPushConstantRanges = &pcr,
    };
    VK(vkCreatePipelineLayout(h->rt.dev, &plci, NULL, &layout));
    VkComputePipelineCreateInfo cpci = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
            .stage = VK_SHADER_STAGE_COMPUTE_BIT,
            .module = module,
            .pName = "main",
        },
        .layout = layout,
    };
    VK(vkCreateComputePipelines(h->rt.dev, VK_NULL_HANDLE, 1, &cpci, NULL, &pipeline));

    /* Descriptors. */
    VkDescriptorPoolSize sizes[2] = {
        { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 },
        { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, (uint32_t)nimg },
    };
    VkDescriptorPoolCreateInfo dpci = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = 1,
        .poolSizeCount = nimg ? 2 : 1,
        .pPoolSizes = sizes,
    };
    VK(vkCreateDescriptorPool(h->rt.dev, &dpci, NULL, &dpool));
    VkDescriptorSetAllocateInfo dsai = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = dpool,
        .descriptorSetCount = 1,
        .pSetLayouts = &dsl,
    };
    VK(vkAllocateDescriptorSets(h->rt.dev, &dsai, &set));
    VkDescriptorBufferInfo binfo[2] = {
        { in.buf, 0, VK_WHOLE_SIZE },
        { out.buf, 0, VK_WHOLE_SIZE },
    };
    for (uint32_t b = 0; b < nbind; b++) {
        writes[b] = (VkWriteDescriptorSet){
            .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
            .dstSet = set,
            .dstBinding = b,
            .descriptorCount = 1,
            .descriptorType = binds[b].descriptorType,
        };
        if (b < 2) {
            writes[b].pBufferInfo = &binfo[b];
        } else {
            iinfo[b - 2] = (VkDescriptorImageInfo){
                images[b - 2].sampler, images[b - 2].im.view,
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
            };
            writes[b].pImageInfo = &iinfo[b - 2];
        }
    }
    vkUpdateDescriptorSets(h->rt.dev, nbind, writes, 0, NULL);

    /* Record: upload images, dispatch, make the output visible to the host. */
    VK(vkResetCommandBuffer(h->cmd, 0));
    VkCommandBufferBeginInfo cbbi = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    VK(vkBeginCommandBuffer(h->cmd, &cbbi));
    for (int i = 0; i < nimg; i++) {
        rt_cmd_image_barrier(h->cmd, images[i].im.img, 0, 1, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                      VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                      VK_PIPELINE_STAGE_TRANSFER_BIT);
        VkBufferImageCopy region = {
            .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
            .imageExtent = { (uint32_t)d->images[i].width,
                             (uint32_t)d->images[i].height, 1 },
        };
        vkCmdCopyBufferToImage(h->cmd, staging[i].buf, images[i].im.img,
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        rt_cmd_image_barrier(h->cmd, images[i].im.img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                      VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                      VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT,
                      VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    }
    vkCmdBindPipeline(h->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(h->cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1,
                            &set, 0, NULL);
    if (d->push_bytes)
        vkCmdPushConstants(h->cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                           d->push_bytes, d->push);
    vkCmdDispatch(h->cmd, d->groups, 1, 1);
    VkMemoryBarrier mb = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
    };
    vkCmdPipelineBarrier(h->cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
    VK(vkEndCommandBuffer(h->cmd));

    VkSubmitInfo si = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .commandBufferCount = 1,
        .pCommandBuffers = &h->cmd,
    };
    VK(vkResetFences(h->rt.dev, 1, &h->fence));
    VK(vkQueueSubmit(h->rt.queue, 1, &si, h->fence));
    /* 60 s: lavapipe on two busy cores is slow, but never that slow. */
    VK(vkWaitForFences(h->rt.dev, 1, &h->fence, VK_TRUE, 60ull * 1000000000ull));
    memcpy(d->output, out.map, d->output_bytes);
    ok = true;

fail:
    if (h->rt.dev)
        vkQueueWaitIdle(h->rt.queue);
    if (pipeline)
        vkDestroyPipeline(h->rt.dev, pipeline, NULL);
    if (layout)
        vkDestroyPipelineLayout(h->rt.dev, layout, NULL);
    if (dpool)
        vkDestroyDescriptorPool(h->rt.dev, dpool, NULL);
    if (dsl)
        vkDestroyDescriptorSetLayout(h->rt.dev, dsl, NULL);
    if (module)
        vkDestroyShaderModule(h->rt.dev, module, NULL);
    for (int i = 0; images && staging && i < nimg; i++) {
        image_destroy(h, &images[i]);
        rt_buffer_destroy(&h->rt, &staging[i]);
    }
    rt_buffer_destroy(&h->rt, &in);
    rt_buffer_destroy(&h->rt, &out);
    free(staging);
    free(images);
    free(binds);
    free(iinfo);
    free(writes);
    return ok;
}
