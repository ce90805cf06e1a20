/* gpu_sparse.c — the sparse painted-mask sampler (SPARSE_GLSL_FUNCTIONS)
 * run on a Vulkan device (lavapipe here; any GPU through SPLAT_DEVICE)
 * with the real texture formats — atlas R8_UNORM or BC4_UNORM_BLOCK,
 * index RGBA16_UINT and level RGBA8_UINT 2D arrays — against the CPU twin
 * (sparse_sample) and the CPU reference (bilinear on the original raster).
 *
 * Prints, per option (R8, BC4, reduced levels), the max error of the GPU
 * against the reference and against the twin, and the largest jump across
 * tile borders.  Fails on any validation message (SPLAT_VALIDATE=1), on a
 * GPU-twin difference beyond the device's filtering precision, or on a
 * seam.
 *
 * The device, buffers and images are libsplatrt's (runtime/device.c); the
 * compute pipeline is its own: the shared harness (tests/harness) binds
 * RGBA32F sampler2Ds only, and this test needs integer arrays and
 * compressed textures.
 *
 * Measured (ctest -R gpu.sparse; on the H100 the same binary through the
 * device tool, 5 masks of 300 x 203, 191575 points each):
 *   option                  gpu-ref  gpu-twin  twin-ref  seam    (max abs)
 *   llvmpipe (LLVM 15.0.6, 256 bits), subTexelPrecisionBits 8
 *   R8                      0.00512  0.00513   0.00001   0.00000
 *   BC4                     0.07282  0.00795   0.06684   0.12349
 *   R8, levels <= 2 (0.05)  0.03137  0.00513   0.03137   0.00584
 *   BC4, levels <= 2 (1.0)  0.56395  0.00719   0.56447   0.07251
 *   NVIDIA H100 80GB HBM3, subTexelPrecisionBits 8
 *   R8                      0.00512  0.00512   0.00001   0.00000
 *   BC4                     0.07374  0.01184   0.06684   0.13872
 *   R8, levels <= 2 (0.05)  0.03137  0.00512   0.03137   0.00584
 *   BC4, levels <= 2 (1.0)  0.56422  0.01147   0.56447   0.07683
 * R8's GPU error is the 8-bit filtering weights alone; BC4's seams are
 * each side's own compression error (mask 1 is full-range noise, the
 * worst case); reduced levels jump where a reduced cell meets a full one.
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sparse.h"
#include "rt_internal.h"
#include "spv.h"

#define VK(call)                                                              \
    do {                                                                      \
        VkResult r_ = (call);                                                 \
        if (r_ != VK_SUCCESS) {                                               \
            fprintf(stderr, "%s:%d: %s failed: %d\n", __FILE__, __LINE__,     \
                    #call, (int)r_);                                          \
            exit(1);                                                          \
        }                                                                     \
    } while (0)

/* ---- device: libsplatrt's (runtime/device.c) -------------------------------- */

/* A runtime call that failed: print its message and stop. */
static void check(bool ok, rt_error *e)
{
    if (!ok) {
        fprintf(stderr, "%s\n", e->msg ? e->msg : "splatrt call failed");
        exit(1);
    }
}

static rt_buffer buffer_new(rt_device *g, size_t size, VkBufferUsageFlags usage)
{
    rt_buffer b;
    rt_error e = { 0 };
    check(rt_buffer_create(g, size, usage, true, &b, &e), &e);
    return b;
}

/* A sampled image (2D or 2D array) filled from `data` (tightly packed). */
static rt_image image_new(rt_device *g, VkFormat fmt, int w, int h, int layers, bool array,
                          const void *data, size_t bytes)
{
    rt_image im;
    rt_error e = { 0 };
    check(rt_image_create(g, (uint32_t)w, (uint32_t)h, (uint32_t)layers, array, 1, fmt,
                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                          VK_IMAGE_ASPECT_COLOR_BIT, &im, &e), &e);
    check(rt_image_upload(g, &im, data, bytes, &e), &e);
    return im;
}

/* ---- the sampling shader ---------------------------------------------------- */

static const char shader_src[] =
    "#version 450\n"
    "layout(local_size_x = 64) in;\n"
    "layout(set = 0, binding = 0) uniform sampler2D u_painted_atlas;\n"
    "layout(set = 0, binding = 1) uniform usampler2DArray u_painted_index;\n"
    "layout(set = 0, binding = 2) uniform usampler2DArray u_painted_level;\n"
    "layout(set = 0, binding = 3, std430) readonly buffer In { vec4 p[]; } pts;\n"
    "layout(set = 0, binding = 4, std430) writeonly buffer Out { float v[]; } res;\n"
    "layout(push_constant) uniform Push { vec2 size; uint n; } pc;\n"
    SPARSE_GLSL_FUNCTIONS
    "void main() {\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    if (i >= pc.n) return;\n"
    "    vec4 p = pts.p[i];\n"
    "    res.v[i] = splat_sparse_painted(p.xy, pc.size, int(p.z));\n"
    "}\n";

/* Sample every point (u, v, mask) on the device. */
static void gpu_sample(rt_device *g, const sparse_masks *s, const float *pts, int n, float *out)
{
    VkFormat afmt = s->format == SPARSE_BC4 ? VK_FORMAT_BC4_UNORM_BLOCK : VK_FORMAT_R8_UNORM;
    rt_image atlas = image_new(g, afmt, s->atlas_width, s->atlas_height, 1, false,
                            s->atlas, s->atlas_bytes);
    size_t ncell = (size_t)s->cells_x * s->cells_z * 4 * s->layers;
    rt_image index = image_new(g, VK_FORMAT_R16G16B16A16_UINT, s->cells_x, s->cells_z,
                            s->layers, true, s->index, ncell * 2);
    rt_image level = image_new(g, VK_FORMAT_R8G8B8A8_UINT, s->cells_x, s->cells_z,
                            s->layers, true, s->level, ncell);
    VkSamplerCreateInfo sci = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, .magFilter = VK_FILTER_LINEAR,
        .minFilter = VK_FILTER_LINEAR, .mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeV = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, .maxLod = 0.0f };
    VkSampler linear, nearest;
    VK(vkCreateSampler(g->dev, &sci, NULL, &linear));
    sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
    VK(vkCreateSampler(g->dev, &sci, NULL, &nearest));
    rt_buffer in = buffer_new(g, (size_t)n * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    rt_buffer res = buffer_new(g, (size_t)n * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    memcpy(in.map, pts, (size_t)n * 16);

    VkDescriptorSetLayoutBinding b[5];
    for (int i = 0; i < 5; i++)
        b[i] = (VkDescriptorSetLayoutBinding){
            .binding = (uint32_t)i, .descriptorCount = 1,
            .descriptorType = i < 3 ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
                                    : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
            .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT };
    VkDescriptorSetLayoutCreateInfo lci = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, .bindingCount = 5,
        .pBindings = b };
    VkDescriptorSetLayout dsl;
    VK(vkCreateDescriptorSetLayout(g->dev, &lci, NULL, &dsl));
    VkPushConstantRange pcr = { VK_SHADER_STAGE_COMPUTE_BIT, 0, 16 };
    VkPipelineLayoutCreateInfo plci = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, .setLayoutCount = 1,
        .pSetLayouts = &dsl, .pushConstantRangeCount = 1, .pPushConstantRanges = &pcr };
    VkPipelineLayout pl;
    VK(vkCreatePipelineLayout(g->dev, &plci, NULL, &pl));
    uint32_t *words;
    size_t nwords;
    char *log = NULL;
    if (!spv_compile(shader_src, SPV_STAGE_COMPUTE, "gpu_sparse", &words, &nwords, &log)) {
        fprintf(stderr, "%s\n", log);
        exit(1);
    }
    free(log);
    VkShaderModuleCreateInfo smci = { .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                      .codeSize = nwords * 4, .pCode = words };
    VkShaderModule sm;
    VK(vkCreateShaderModule(g->dev, &smci, NULL, &sm));
    free(words);
    VkComputePipelineCreateInfo cpci = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .stage = { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                   .stage = VK_SHADER_STAGE_COMPUTE_BIT, .module = sm, .pName = "main" },
        .layout = pl };
    VkPipeline pipe;
    VK(vkCreateComputePipelines(g->dev, VK_NULL_HANDLE, 1, &cpci, NULL, &pipe));

    VkDescriptorPoolSize sizes[2] = { { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 3 },
                                      { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 } };
    VkDescriptorPoolCreateInfo dpci = { .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
                                        .maxSets = 1, .poolSizeCount = 2, .pPoolSizes = sizes };
    VkDescriptorPool dp;
    VK(vkCreateDescriptorPool(g->dev, &dpci, NULL, &dp));
    VkDescriptorSetAllocateInfo dsai = { .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
                                         .descriptorPool = dp, .descriptorSetCount = 1,
                                         .pSetLayouts = &dsl };
    VkDescriptorSet ds;
    VK(vkAllocateDescriptorSets(g->dev, &dsai, &ds));
    VkDescriptorImageInfo ii[3] = {
        { linear, atlas.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL },
        { nearest, index.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL },
        { nearest, level.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL } };
    VkDescriptorBufferInfo bi[2] = { { in.buf, 0, VK_WHOLE_SIZE }, { res.buf, 0, VK_WHOLE_SIZE } };
    VkWriteDescriptorSet w[5];
    for (int i = 0; i < 5; i++)
        w[i] = (VkWriteDescriptorSet){
            .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = ds,
            .dstBinding = (uint32_t)i, .descriptorCount = 1, .descriptorType = b[i].descriptorType,
            .pImageInfo = i < 3 ? &ii[i] : NULL, .pBufferInfo = i < 3 ? NULL : &bi[i - 3] };
    vkUpdateDescriptorSets(g->dev, 5, w, 0, NULL);

    struct { float size[2]; uint32_t n, pad; } push = {
        { (float)s->width, (float)s->height }, (uint32_t)n, 0 };
    VkCommandBuffer cb;
    rt_error e = { 0 };
    check(rt_oneshot_begin(g, &cb, &e), &e);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pl, 0, 1, &ds, 0, NULL);
    vkCmdPushConstants(cb, pl, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(cb, (uint32_t)(n + 63) / 64, 1, 1);
    VkMemoryBarrier mb = { .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
                           .srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT,
                           .dstAccessMask = VK_ACCESS_HOST_READ_BIT };
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                         0, 1, &mb, 0, NULL, 0, NULL);
    check(rt_oneshot_end(g, cb, &e), &e);
    memcpy(out, res.map, (size_t)n * 4);

    vkDestroyPipeline(g->dev, pipe, NULL);
    vkDestroyShaderModule(g->dev, sm, NULL);
    vkDestroyDescriptorPool(g->dev, dp, NULL);
    vkDestroyPipelineLayout(g->dev, pl, NULL);
    vkDestroyDescriptorSetLayout(g->dev, dsl, NULL);
    vkDestroySampler(g->dev, linear, NULL);
    vkDestroySampler(g->dev, nearest, NULL);
    rt_buffer_destroy(g, &in);
    rt_buffer_destroy(g, &res);
    rt_image_destroy(g, &atlas);
    rt_image_destroy(g, &index);
    rt_image_destroy(g, &level);
}

/* ---- content and the checks ----------------------------------------------- */

static uint32_t rng_next(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    uint32_t x = *s;
    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15;
    return x;
}

static double rng_unit(uint32_t *s) { return (rng_next(s) >> 8) * (1.0 / 16777216.0); }

/* Mask 0: soft discs and a smooth wave over empty space; mask 1: noise
 * (every tile differs); mask 2: all 1; mask 3 (layer 0.a), mask 4 (layer
 * 1.r): a copy of mask 0, so the index's second layer is used. */
static uint8_t *gen(int w, int h, int kind, uint32_t seed)
{
    uint8_t *t = calloc((size_t)w * h, 1);
    uint32_t s = seed;
    if (kind == 1) {
        for (int i = 0; i < w * h; i++) t[i] = (uint8_t)(rng_next(&s) & 255);
        return t;
    }
    if (kind == 2) {
        memset(t, 255, (size_t)w * h);
        return t;
    }
    for (int d = 0; d < 12; d++) {
        double cx = rng_unit(&s) * w, cz = rng_unit(&s) * h, r = 8 + 30 * rng_unit(&s);
        for (int z = 0; z < h; z++)
            for (int x = 0; x < w; x++) {
                double e = (r - hypot(x + 0.5 - cx, z + 0.5 - cz)) / 6.0;
                double v = fmin(fmax(e, 0.0), 1.0) * 255.0;
                if (v > t[z * w + x]) t[z * w + x] = (uint8_t)lrint(v);
            }
    }
    for (int z = 0; z < h; z++)
        for (int x = w / 2; x < w; x++)
            if (z > h / 2)
                t[z * w + x] = (uint8_t)lrint(127.5 + 127.5 * sin(x * 0.07) * cos(z * 0.05));
    return t;
}

typedef struct result { double gpu_ref, gpu_twin, twin_ref, seam; } result;

static result run_option(rt_device *g, const char *name, sparse_format fmt, int max_level,
                         double max_error, int w, int h, uint8_t *const *rasters, int nm)
{
    sparse_mask_desc md[8];
    for (int m = 0; m < nm; m++)
        md[m] = (sparse_mask_desc){ .name = "m", .texels = rasters[m], .max_level = max_level,
                                    .max_error = max_error };
    sparse_desc d = { .width = w, .height = h, .masks = md, .nmasks = nm, .format = fmt };
    sparse_masks s;
    sparse_error err;
    if (!sparse_build(&s, &d, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        exit(1);
    }
    /* points: the half-texel lattice of a band across every tile border
     * (both axes), plus random points, for every mask */
    int cap = 1 << 20, n = 0;
    float *pts = malloc((size_t)cap * 16);
    uint32_t rs = 77;
    for (int m = 0; m < nm; m++) {
        for (int b = 32; b < w; b += 32)
            for (int j = 0; j <= 2 * h && n + 6 <= cap; j++)
                for (int k = -1; k <= 1; k++) {
                    double t = 0.5 * j, eps = k * 1e-3;
                    float p[2][4] = { { (float)((b + eps) / w), (float)(t / h), (float)m, 0 },
                                      { (float)(t / w), (float)((b + eps) / h), (float)m, 0 } };
                    memcpy(pts + 4 * n++, p[0], 16);
                    if (b < h) memcpy(pts + 4 * n++, p[1], 16);
                }
        for (int k = 0; k < 20000 && n < cap; k++) {
            float p[4] = { (float)rng_unit(&rs), (float)rng_unit(&rs), (float)m, 0 };
            memcpy(pts + 4 * n++, p, 16);
        }
    }
    float *out = malloc((size_t)n * 4);
    gpu_sample(g, &s, pts, n, out);
    result r = { 0 };
    for (int i = 0; i < n; i++) {
        double u = pts[4 * i], v = pts[4 * i + 1];
        int m = (int)pts[4 * i + 2];
        double twin = sparse_sample(&s, m, u, v);
        double ref = sparse_raster_bilinear(rasters[m], w, h, u, v);
        r.gpu_ref = fmax(r.gpu_ref, fabs(out[i] - ref));
        r.gpu_twin = fmax(r.gpu_twin, fabs(out[i] - twin));
        r.twin_ref = fmax(r.twin_ref, fabs(twin - ref));
    }
    /* seams: the three points at b - eps, b, b + eps are consecutive */
    for (int i = 0; i + 2 < n; i++) {
        if (pts[4 * i + 2] != pts[4 * (i + 2) + 2]) continue;
        bool xs = pts[4 * i + 1] == pts[4 * (i + 2) + 1] && pts[4 * i] < pts[4 * (i + 2)] &&
                  pts[4 * (i + 2)] - pts[4 * i] < 3e-3f / w;
        bool zs = pts[4 * i] == pts[4 * (i + 2)] && pts[4 * i + 1] < pts[4 * (i + 2) + 1] &&
                  pts[4 * (i + 2) + 1] - pts[4 * i + 1] < 3e-3f / h;
        if (xs || zs)
            r.seam = fmax(r.seam, fabs(out[i + 2] - out[i]) - 2e-3);
    }
    sparse_stats st;
    sparse_get_stats(&s, &st);
    printf("%-22s %8d %10.5f %10.5f %10.5f %10.5f %9.2f%%\n", name, n, r.gpu_ref, r.gpu_twin,
           r.twin_ref, r.seam, 100 * st.fraction);
    free(pts);
    free(out);
    sparse_free(&s);
    return r;
}

int main(void)
{
    rt_device g;
    rt_error e = { 0 };
    check(rt_device_create(&g, NULL, &e), &e);
    int w = 300, h = 203, nm = 5;
    uint8_t *r[5] = { gen(w, h, 0, 1), gen(w, h, 1, 2), gen(w, h, 2, 3), NULL, NULL };
    r[3] = r[0];
    r[4] = gen(w, h, 0, 4);
    printf("device: %s (subTexelPrecisionBits %u)\n", g.props.deviceName,
           g.props.limits.subTexelPrecisionBits);
    printf("%-22s %8s %10s %10s %10s %10s %10s\n", "option", "points", "gpu-ref",
           "gpu-twin", "twin-ref", "seam", "size");
    /* The GPU weights bilinear filtering with subTexelPrecisionBits bits:
     * a (possibly truncated) weight is off by up to 2^-bits per axis, the
     * value by that times the texel difference (<= 1) in each of the two
     * axes; a device may also keep the filtered value of an 8-bit texture
     * at 8 bits (llvmpipe does), off by up to 1/255 more. */
    double filt = 2.0 * ldexp(1.0, -(int)g.props.limits.subTexelPrecisionBits) + 1.0 / 255.0 + 1e-5;
    result r8 = run_option(&g, "R8", SPARSE_R8, 0, 0, w, h, r, nm);
    result bc4 = run_option(&g, "BC4", SPARSE_BC4, 0, 0, w, h, r, nm);
    result red = run_option(&g, "R8, levels <= 2 (0.05)", SPARSE_R8, 2, 0.05, w, h, r, nm);
    result redbc = run_option(&g, "BC4, levels <= 2 (1.0)", SPARSE_BC4, 2, 1.0, w, h, r, nm);
    printf("filtering precision bound %.5f; validation messages: %d\n", filt,
           rt_device_messages(&g));
    int fails = 0;
#define CHECK(c) do { if (!(c)) { fprintf(stderr, "FAILED: %s\n", #c); fails++; } } while (0)
    CHECK(r8.gpu_twin <= filt);
    CHECK(r8.gpu_ref <= filt);
    CHECK(r8.seam <= filt);
    /* BC4: the device may round palette entries to 8 bits (0.5 / 255) */
    CHECK(bc4.gpu_twin <= filt + 0.5 / 255.0);
    CHECK(red.gpu_twin <= filt);
    CHECK(red.twin_ref <= 0.05 + 1e-4);
    CHECK(redbc.gpu_twin <= filt + 0.5 / 255.0);
    CHECK(rt_device_messages(&g) == 0);
    for (int i = 0; i < 5; i++)
        if (i != 3) free(r[i]);
    rt_device_destroy(&g);
    return fails ? 1 : 0;
}
