/* upscale.c — the preview scale (rt_render_desc.preview_scale): the
 * renderer draws its whole frame at 1/s of the output's width and height
 * (s = 2 or 4: depth, classification and shading have s^2 times fewer
 * pixels), and this compute pass makes the output picture from it.
 *
 * A depth-aware upsample (the "nearest-depth" family of joint bilateral
 * upsampling, Kopf et al. 2007, with the low-resolution depth as the
 * only guide, since a full-resolution depth would cost what the preview
 * saves): each output pixel blends the 2x2 low-resolution pixels around
 * it with bilinear weights.  Where their four depths agree within 2 %
 * (sky, smooth ground: most pixels) that is all.  Elsewhere (an edge)
 * each weight is multiplied by how alike its depth is to those of the
 * side of the edge holding the most bilinear weight: the sample n whose
 * sum over i of w_i sim(i, n) is largest, then w_i *= sim(i, n), with
 * sim = exp(-((1 - ratio) / SIGMA)^2) and ratio the smaller over the
 * larger of two reversed-Z depths (the ratio of their distances; the sky,
 * depth 0, matches only the sky).  Across a ridge against the sky or a
 * nearer hill the far side gets no weight, so the edge stays sharp (on
 * the low resolution's pixel grid, along the bilinear weights' half-way
 * line) instead of blurring into a halo.  Paths without a depth image of
 * their own (forward, multi-pass) are upsampled bilinearly (`guided`
 * false), as every path is with SPLAT_UPSCALE=bilinear (tests).
 *
 *     colour (w/s x h/s, GENERAL) + depth (w/s x h/s)  ->  output (w x h, GENERAL)
 */
#include "rt_internal.h"
#include "vk_build.h"

#include <stdlib.h>
#include <string.h>

struct rt_upscale {
    rt_device            *d;
    uint32_t              src[2], dst[2];
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout      layout;
    VkPipeline            pipe;
    VkDescriptorPool      pool;
    VkDescriptorSet       set[2];     /* guided by the depth; bilinear only */
    bool                  has_guide;  /* set[0] was written               */
    rt_vk_list            keep;
};

typedef struct upscale_push {
    int32_t src[2], dst[2];
    int32_t guided;
} upscale_push;

/* SIGMA: the relative distance difference at which a neighbour's weight
 * falls to 1/e (tests/bench: PSNR against full resolution). */
static const char upscale_glsl[] =
    "#version 450\n"
    "layout(local_size_x = 8, local_size_y = 8) in;\n"
    "layout(set = 0, binding = 0) uniform sampler2D u_color;\n"
    "layout(set = 0, binding = 1) uniform sampler2D u_depth;\n"
    "layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D u_out;\n"
    "layout(push_constant) uniform P { ivec2 src; ivec2 dst; int guided; } u_pc;\n"
    "const float SIGMA = 0.08;\n"
    /* how alike two reversed-Z depths are: their distances' ratio */
    "float sim(float a, float b) {\n"
    "    float big = max(a, b);\n"
    "    float r = (big > 0.0 ? 1.0 - min(a, b) / big : 0.0) / SIGMA;\n"
    "    return exp(-r * r);\n"
    "}\n"
    "void main() {\n"
    "    ivec2 px = ivec2(gl_GlobalInvocationID.xy);\n"
    "    if (any(greaterThanEqual(px, u_pc.dst)))\n"
    "        return;\n"
    "    vec2 s = (vec2(px) + 0.5) * vec2(u_pc.src) / vec2(u_pc.dst) - 0.5;\n"
    "    ivec2 b = ivec2(floor(s));\n"
    "    vec2 f = s - vec2(b);\n"
    "    ivec2 hi = u_pc.src - 1;\n"
    "    ivec2 q[4] = ivec2[4](clamp(b, ivec2(0), hi), clamp(b + ivec2(1, 0), ivec2(0), hi),\n"
    "                          clamp(b + ivec2(0, 1), ivec2(0), hi), clamp(b + ivec2(1, 1), ivec2(0), hi));\n"
    "    float w[4] = float[4]((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y),\n"
    "                          (1.0 - f.x) * f.y, f.x * f.y);\n"
    "    if (u_pc.guided != 0) {\n"
    "        float d[4];\n"
    "        for (int i = 0; i < 4; i++)\n"
    "            d[i] = max(texelFetch(u_depth, q[i], 0).r, 0.0);\n"
    "        float lo = min(min(d[0], d[1]), min(d[2], d[3]));\n"
    "        float hi = max(max(d[0], d[1]), max(d[2], d[3]));\n"
    /* one surface (or all sky): bilinear; else an edge */
    "        if (lo < hi * (1.0 - 0.25 * SIGMA)) {\n"
    /* sim of each pair once (6 exps); then the side of the edge with the
     * most bilinear weight: sample n's depth cluster, its weight the sum
     * of its similar neighbours' */
    "            float s01 = sim(d[0], d[1]), s02 = sim(d[0], d[2]), s03 = sim(d[0], d[3]);\n"
    "            float s12 = sim(d[1], d[2]), s13 = sim(d[1], d[3]), s23 = sim(d[2], d[3]);\n"
    "            vec4 r0 = vec4(1.0, s01, s02, s03), r1 = vec4(s01, 1.0, s12, s13);\n"
    "            vec4 r2 = vec4(s02, s12, 1.0, s23), r3 = vec4(s03, s13, s23, 1.0);\n"
    "            vec4 wv = vec4(w[0], w[1], w[2], w[3]);\n"
    "            float m0 = dot(wv, r0), m1 = dot(wv, r1), m2 = dot(wv, r2), m3 = dot(wv, r3);\n"
    "            vec4 pick = m0 >= max(max(m1, m2), m3) ? r0 : m1 >= max(m2, m3) ? r1\n"
    "                      : m2 >= m3 ? r2 : r3;\n"
    "            wv *= pick;\n"
    "            w = float[4](wv.x, wv.y, wv.z, wv.w);\n"
    "        }\n"
    "    }\n"
    "    vec4 c = vec4(0.0);\n"
    "    float sum = 0.0;\n"
    "    for (int i = 0; i < 4; i++) {\n"
    "        c += w[i] * texelFetch(u_color, q[i], 0);\n"
    "        sum += w[i];\n"
    "    }\n"
    "    imageStore(u_out, px, c / max(sum, 1e-20));\n"
    "}\n";

bool rt_upscale_create(rt_device *d, VkPipelineCache cache, VkSampler nearest,
                       const rt_image *color, const rt_image *guide, VkImageLayout guide_layout,
                       const rt_image *out, rt_upscale **u_out, rt_error *e)
{
    *u_out = NULL;
    rt_upscale *u = calloc(1, sizeof *u);
    if (!u)
        return rt_fail(e, RT_E_VULKAN, "preview upscale", "out of memory");
    *u_out = u;
    u->d = d;
    u->src[0] = color->width;
    u->src[1] = color->height;
    u->dst[0] = out->width;
    u->dst[1] = out->height;
    /* SPLAT_UPSCALE=bilinear (tests: what the depth guide changes) */
    const char *env = getenv("SPLAT_UPSCALE");
    u->has_guide = guide != NULL && !(env && !strcmp(env, "bilinear"));
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType cis = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    const VkDescriptorType sti = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    VkDescriptorSetLayoutBinding b[3] = {
        { 0, cis, 1, cs, NULL }, { 1, cis, 1, cs, NULL }, { 2, sti, 1, cs, NULL },
    };
    VkDescriptorPoolSize sizes[2] = { { cis, 4 }, { sti, 2 } };
    rt_vk_list *k = &u->keep;
    if (!rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "preview upscale", b, 3 },
                          &u->set_layout, e))
        return false;
    VkDescriptorSetLayout layouts[2] = { u->set_layout, u->set_layout };
    if (!rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "preview upscale",
                          .sets = &u->set_layout, .nsets = 1, .push_stages = cs,
                          .push_bytes = sizeof(upscale_push) }, &u->layout, e) ||
        !rt_vk_sets(d, k, &(rt_vk_sets_desc){ .label = "preview upscale", .sizes = sizes,
                        .nsizes = 2, .layouts = layouts, .nsets = 2 }, &u->pool, u->set, e) ||
        !rt_vk_compute(d, k, &(rt_vk_compute_desc){ .label = "upscale.comp", .glsl = upscale_glsl,
                           .layout = u->layout, .cache = cache }, &u->pipe, e))
        return false;
    /* set 1 (bilinear) reads the colour as its unused guide */
    rt_vk_write w[6];
    int n = 0;
    for (int i = 0; i < 2; i++) {
        bool g = i == 0 && guide;
        if (i == 0 && !guide)
            continue;
        w[n++] = (rt_vk_write){ u->set[i], 0, cis, .sampler = nearest, .view = color->view,
                                .layout = VK_IMAGE_LAYOUT_GENERAL };
        w[n++] = (rt_vk_write){ u->set[i], 1, cis, .sampler = nearest,
                                .view = g ? guide->view : color->view,
                                .layout = g ? guide_layout : VK_IMAGE_LAYOUT_GENERAL };
        w[n++] = (rt_vk_write){ u->set[i], 2, sti, .view = out->view,
                                .layout = VK_IMAGE_LAYOUT_GENERAL };
    }
    rt_vk_write_sets(d, w, (uint32_t)n);
    return true;
}

void rt_upscale_record(rt_upscale *u, VkCommandBuffer cb, bool guided)
{
    guided = guided && u->has_guide;
    upscale_push pc = { { (int32_t)u->src[0], (int32_t)u->src[1] },
                        { (int32_t)u->dst[0], (int32_t)u->dst[1] }, guided };
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->layout, 0, 1,
                            &u->set[guided ? 0 : 1], 0, NULL);
    vkCmdPushConstants(cb, u->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
    vkCmdDispatch(cb, (u->dst[0] + 7) / 8, (u->dst[1] + 7) / 8, 1);
}

void rt_upscale_destroy(rt_upscale *u)
{
    if (!u)
        return;
    rt_vk_list_destroy(u->d, &u->keep);
    free(u);
}
