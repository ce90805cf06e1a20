/* far.c — the far atlas on the device (compiler/far_atlas.h): its three
 * BC images with their stored mip chains, and the far shading shader of
 * the screen path (screen.c sends tiles wholly beyond the far distance to
 * it).  The shader is the compute prelude (abi.h "compute stage") around a
 * main that reads albedo, normal and roughness from the atlas with the
 * pixel's own gradients (FC5's plane-through-the-pixel derivatives, as the
 * composites take theirs) and calls splat_finish: the same lighting, fog
 * and views as the composites, from three samples. */
#include "rt_internal.h"
#include "far_atlas.h"

#include <stdlib.h>
#include <string.h>

static const VkFormat far_formats[3] = {
    VK_FORMAT_BC1_RGB_SRGB_BLOCK,   /* albedo, sRGB-encoded by the bake   */
    VK_FORMAT_BC5_UNORM_BLOCK,      /* normal x, z                         */
    VK_FORMAT_BC4_UNORM_BLOCK,      /* roughness                           */
};
static const int far_block[3] = {8, 16, 8};

bool rt_far_supported(rt_device *d)
{
    for (int i = 0; i < 3; i++)
        if (!rt_format_supports(d, far_formats[i], VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                                VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
                                VK_FORMAT_FEATURE_TRANSFER_DST_BIT))
            return false;
    return true;
}

bool rt_far_upload(rt_device *d, const rt_pack *p, rt_image img[3], rt_error *e)
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
                                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
        }
        ok = rt_oneshot_end(d, cb, e);
    }
    rt_buffer_destroy(d, &staging);
    free(regions);
    return ok;
}

/* Set 2 bindings 5-7 of the screen path's layout (screen.c). */
static const char far_main[] =
    "layout(set = 2, binding = 5) uniform sampler2D u_far_albedo;\n"
    "layout(set = 2, binding = 6) uniform sampler2D u_far_normal;\n"
    "layout(set = 2, binding = 7) uniform sampler2D u_far_rough;\n"
    "void main() {\n"
    "    vec2 gx = splat_dpdx.xz / u_frame.terrain.xy, gy = splat_dpdy.xz / u_frame.terrain.xy;\n"
    "    vec3 albedo = textureGrad(u_far_albedo, v_uv, gx, gy).rgb;\n"
    "    vec2 nxz = textureGrad(u_far_normal, v_uv, gx, gy).rg * 2.0 - 1.0;\n"
    "    vec3 n = vec3(nxz.x, sqrt(max(1.0 - dot(nxz, nxz), 0.0)), nxz.y);\n"
    "    float rough = textureGrad(u_far_rough, v_uv, gx, gy).r;\n"
    "    splat_count_samples(3u);\n"
    "    splat_finish(albedo, n, rough, 0.0, 1.0);\n"
    "}\n";

char *rt_far_glsl(const rt_pack *p, bool count)
{
    /* the über-shader's head (its defines: painted storage and places)
     * before the prelude, so set 0 is declared as the composites do */
    const char *u = p->uber_compute, *v = u ? strstr(u, "#version 450\n") : NULL;
    const char *at = v ? strstr(v, SPLAT_GLSL_PRELUDE) : NULL;
    if (!at)
        return NULL;
    v += strlen("#version 450\n");
    size_t head = (size_t)(at - v);
    size_t n = 64 + head + strlen(SPLAT_GLSL_PRELUDE) + sizeof far_main;
    char *s = malloc(n);
    if (!s)
        return NULL;
    snprintf(s, n, "#version 450\n%s%.*s%s%s", count ? "#define SPLAT_COUNT 1\n" : "", (int)head,
             v, SPLAT_GLSL_PRELUDE, far_main);
    return s;
}
