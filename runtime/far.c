/* far.c — the far atlas on the device (compiler/far_atlas.h): its three
 * BC images with their stored mip chains (one upload, read by both
 * paths), and the far shading shader: the screen path sends tiles wholly
 * beyond the far distance to its compute variant (screen.c), the forward
 * path draws quadtree patches wholly beyond it with its fragment variant
 * (render_record.c).  The shader is the prelude of the stage (abi.h) around a
 * main that reads albedo, normal and roughness from the atlas with the
 * pixel's own gradients (FC5's plane-through-the-pixel derivatives, as the
 * composites take theirs) and calls splat_finish: the same lighting, fog
 * and views as the composites, from three samples.  Its text, and the
 * flat stand-in's, are the compiler's (compiler/stand_in.c): the pack
 * carries their compute SPIR-V (rt_pipelines_stand_in_spirv); the forward
 * path's fragment variant is made here from the über-shader's fragment
 * GLSL. */
#include "rt_internal.h"
#include "vk_build.h"
#include "far_atlas.h"

#include <stdlib.h>
#include <string.h>

static const VkFormat far_formats[3] = {
    VK_FORMAT_BC1_RGB_SRGB_BLOCK,   /* albedo, sRGB-encoded by the bake   */
    VK_FORMAT_BC5_UNORM_BLOCK,      /* normal x, z                         */
    VK_FORMAT_BC4_UNORM_BLOCK,      /* roughness                           */
};
static const int far_block[3] = {8, 16, 8};

/* The device samples BC1 sRGB, BC5 and BC4 with linear filtering. */
static bool far_supported(rt_device *d)
{
    for (int i = 0; i < 3; i++)
        if (!rt_format_supports(d, far_formats[i], VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                                VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
                                VK_FORMAT_FEATURE_TRANSFER_DST_BIT))
            return false;
    return true;
}

struct rt_far {
    rt_device            *d;
    rt_image              img[3];        /* albedo, normal, roughness        */
    VkSampler             sampler;
    /* the forward path's: set 2 = bindings 5-7, sets 0-1 and the push
     * range as the composites' layout (rt_pipelines.layout) */
    VkDescriptorSetLayout set_layout;
    VkDescriptorPool      pool;
    VkDescriptorSet       set;
    VkPipelineLayout      layout;
    VkPipeline            pipe[RT_VARIANTS];
    rt_vk_list            keep;          /* every Vulkan object but the images */
};

static bool upload(rt_device *d, const rt_pack *p, rt_image img[3], rt_error *e)
{
    const rt_pack_far *f = &p->far;
    uint32_t w = (uint32_t)f->width, h = (uint32_t)f->height;
    int levels = f->levels;
    /* the loader checked the file's size: every level is inside it */
    size_t total = f->n - FAR_ATLAS_HEADER;
    VkBufferImageCopy *regions = calloc((size_t)levels * 3, sizeof *regions);
    if (!regions)
        return rt_fail(e, RT_E_VULKAN, "far atlas upload", "out of memory");
    /* the file interleaves the three per level; the staging buffer holds
     * each image's levels together, every region at a multiple of 16
     * bytes (a copy's offset is a multiple of the block size) */
    size_t out = 0;
    for (int l = 0; l < levels; l++) {
        uint32_t lw = w >> l ? w >> l : 1, lh = h >> l ? h >> l : 1;
        size_t blocks = (size_t)((lw + 3) / 4) * ((lh + 3) / 4);
        for (int k = 0; k < 3; k++) {
            size_t n = blocks * (size_t)far_block[k];
            regions[k * levels + l] = (VkBufferImageCopy){
                .bufferOffset = n,   /* its size for now: placed below */
                .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, (uint32_t)l, 0, 1 },
                .imageExtent = { lw, lh, 1 },
            };
        }
    }
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < levels; l++) {
            size_t n = regions[k * levels + l].bufferOffset;
            regions[k * levels + l].bufferOffset = out;
            out += (n + 15) & ~(size_t)15;
        }
    if (out > total + 16 * 3 * (size_t)levels) {   /* cannot happen: sizes checked */
        free(regions);
        return rt_fail(e, RT_E_VULKAN, "far atlas upload", "size mismatch");
    }
    rt_buffer staging;
    if (!rt_buffer_create(d, out, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, &staging, e)) {
        free(regions);
        return false;
    }
    const uint8_t *src = f->data + FAR_ATLAS_HEADER;
    for (int l = 0; l < levels; l++) {
        uint32_t lw = w >> l ? w >> l : 1, lh = h >> l ? h >> l : 1;
        size_t blocks = (size_t)((lw + 3) / 4) * ((lh + 3) / 4);
        for (int k = 0; k < 3; k++) {
            size_t n = blocks * (size_t)far_block[k];
            memcpy((uint8_t *)staging.map + regions[k * levels + l].bufferOffset, src, n);
            src += n;
        }
    }
    bool ok = true;
    for (int k = 0; ok && k < 3; k++)
        ok = rt_image_create(d, w, h, 1, false, (uint32_t)levels, far_formats[k],
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                             VK_IMAGE_ASPECT_COLOR_BIT, &img[k], e);
    VkCommandBuffer cb;
    ok = ok && rt_oneshot_begin(d, &cb, e);
    if (ok) {
        for (int k = 0; k < 3; k++) {
            rt_cmd_image_barrier(cb, img[k].img, 0, (uint32_t)levels, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                                 VK_PIPELINE_STAGE_TRANSFER_BIT);
            vkCmdCopyBufferToImage(cb, staging.buf, img[k].img,
                                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, (uint32_t)levels,
                                   &regions[k * levels]);
            rt_cmd_image_barrier(cb, img[k].img, 0, (uint32_t)levels, 1,
                                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT,
                                 VK_PIPELINE_STAGE_TRANSFER_BIT,
                                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
                                     VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT);
        }
        ok = rt_oneshot_end(d, cb, e);
    }
    rt_buffer_destroy(d, &staging);
    free(regions);
    return ok;
}

bool rt_far_create(rt_device *d, const rt_pack *p, const rt_pipelines *pl, rt_far **out,
                   rt_error *e)
{
    *out = NULL;
    if (!p->far.data || !far_supported(d))
        return true;
    rt_far *f = calloc(1, sizeof *f);
    if (!f)
        return rt_fail(e, RT_E_VULKAN, "far atlas", "out of memory");
    f->d = d;
    *out = f;
    rt_vk_list *k = &f->keep;
    if (!rt_vk_sampler(d, k, &(rt_vk_sampler_desc){ .label = "far atlas", .filter = VK_FILTER_LINEAR,
                           .mip = VK_SAMPLER_MIPMAP_MODE_LINEAR,
                           .wrap = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                           .max_lod = VK_LOD_CLAMP_NONE }, &f->sampler, e) ||
        !upload(d, p, f->img, e))
        return false;
    const VkDescriptorType cis = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    VkDescriptorSetLayoutBinding b[3];
    VkDescriptorImageInfo ii[3];
    for (uint32_t i = 0; i < 3; i++) {
        b[i] = (VkDescriptorSetLayoutBinding){ 5 + i, cis, 1, VK_SHADER_STAGE_FRAGMENT_BIT, NULL };
        ii[i] = rt_far_image_info(f, (int)i);
    }
    VkDescriptorPoolSize size = { cis, 3 };
    if (!rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "far atlas", b, 3 }, &f->set_layout, e) ||
        !rt_vk_sets(d, k, &(rt_vk_sets_desc){ .label = "far atlas", .sizes = &size, .nsizes = 1,
                        .layouts = &f->set_layout, .nsets = 1 }, &f->pool, &f->set, e))
        return false;
    rt_vk_write w[3];
    for (uint32_t i = 0; i < 3; i++)
        w[i] = (rt_vk_write){ .set = f->set, .binding = 5 + i, .type = cis, .images = &ii[i],
                              .count = 1 };
    rt_vk_write_sets(d, w, 3);
    VkDescriptorSetLayout sets[3] = { pl->set_terrain, pl->set_material, f->set_layout };
    return rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "far atlas", .sets = sets,
                            .nsets = 3,
                            .push_stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                            .push_bytes = sizeof(splat_push) }, &f->layout, e);
}

VkDescriptorImageInfo rt_far_image_info(const rt_far *f, int k)
{
    return (VkDescriptorImageInfo){ f->sampler, f->img[k].view,
                                    VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL };
}

bool rt_far_bind_forward(rt_far *f, const rt_pack *p, const rt_passes *rp, rt_pipelines *pl,
                         VkCommandBuffer cb, unsigned variant, rt_error *e)
{
    VkPipeline *slot = &f->pipe[variant % RT_VARIANTS];
    if (!*slot) {
        if (!p->uber_frag_path)
            return rt_fail(e, RT_E_PACK_FIELD, p->dir,
                           "the pack has no fragment GLSL of the uber-shader");
        char *uber = rt_pack_read_glsl(p, "uber.glsl", p->uber_frag_path, e);
        if (!uber)
            return false;
        /* the gradients' main (abi.c FRAGMENT_MAIN) sets splat_dpdx/y */
        char defs[96];
        snprintf(defs, sizeof defs, "%s#ifndef SPLAT_GRADIENTS\n#define SPLAT_GRADIENTS 1\n#endif\n",
                 (variant & RT_VARIANT_COUNT) ? "#define SPLAT_COUNT 1\n" : "");
        char *src = splat_prelude_source(uber, defs, splat_stand_in_main(SPLAT_STAND_IN_ATLAS));
        free(uber);
        if (!src)
            return rt_fail(e, RT_E_VULKAN, "far atlas shader", "no prelude in the uber GLSL");
        bool ok = rt_pipelines_glsl_fragment(f->d, pl, rp, f->layout, src, "far.frag", variant,
                                             slot, e);
        free(src);
        if (!ok || !rt_vk_keep(f->d, &f->keep, VK_OBJECT_TYPE_PIPELINE, RT_VK_H(*slot), e))
            return false;
    }
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, *slot);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, f->layout, 2, 1, &f->set, 0, NULL);
    return true;
}

void rt_far_destroy(rt_far *f)
{
    if (!f)
        return;
    rt_device *d = f->d;
    rt_vk_list_destroy(d, &f->keep);
    for (int k = 0; k < 3; k++)
        rt_image_destroy(d, &f->img[k]);
    free(f);
}
