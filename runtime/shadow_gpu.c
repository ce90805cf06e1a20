/* shadow_gpu.c — the sun-visibility map (shadow.c) marched on the device.
 *
 * One compute invocation makes four consecutive texels of the map (one
 * uint of a storage buffer holding the W x H bytes row by row), marching
 * from each texel centre towards the sun exactly as shadow.c does: the
 * samples at t = k step (half the smaller texel side), the terrain read
 * bilinearly between texel centres from a copy of the terrain's own R16
 * heightfield made at each update (so craters, which lower that image in
 * place, are followed), the clearance's tangent (ray - h) / t, the
 * visibility 0.5 + lowest / (2 tan r), the end off the terrain or above
 * its highest point.  It skips over a pyramid of maximum heights shaped
 * like the ray caster's (screen.c make_maxmip: padded to a multiple of
 * 256 texels, 8 levels of the largest of four; here a storage buffer of
 * raw R16 units), one cell a step: a cell the ray clears is skipped and
 * its parent looked at next, one it does not clear sends the march to its
 * child at the same sample, and at level 0 the sample is taken (all lanes
 * run the same code; searching every level at every step was twice as
 * slow on lavapipe).  Level 0 differs from the ray caster's: per quad
 * between texel edges it holds the highest of the 3 x 3 texels the
 * bilinear surface there reads, not the highest mesh corner (a peak
 * texel stands above the four corner means around it, so the ray caster's
 * bound is not one for the bilinear surface).  Craters only lower the
 * terrain, so the pyramid stays a bound without being rebuilt.
 *
 * The skipping passes only over samples that cannot lower the lowest
 * clearance (shadow.c skip), so the result does not depend on the bound
 * used: in exact arithmetic the two maps are equal.  In floats the march
 * works relative to its start texel (integer texel plus a float offset,
 * heights as differences of raw units), so the 176 km colorado keeps
 * millimetre positions; the map equals the CPU's to within 1/255
 * (render.shadow_gpu holds it).
 *
 * An update is one command buffer: the crater uploads' transfer writes
 * made visible to the copy of the heights, the dispatch (a crater: only
 * the rows of its rectangle, the texels outside it kept from the buffer),
 * the buffer copied into the sampled R8 map after the last frame's
 * reads. */
#include "rt_internal.h"
#include "vk_build.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SUN_TAN 0.0047   /* shadow.c's: tan of the sun's angular radius */
#define LEVELS 8         /* the pyramid's levels above the finest        */

struct rt_shadow_gpu {
    rt_device            *d;
    int                   W, H;       /* the heightfield's texels          */
    double                size[2];    /* its metres (a hot reload's pack
                                         keeps them: render.c)             */
    double                max_height, hoffset;   /* metres per 65535; at 0 */
    int                   PW, PH;     /* the pyramid's padded level 0      */
    uint32_t              offset[LEVELS + 1];   /* floats to each level    */
    rt_buffer             bound;      /* the pyramid of raw maxima (float) */
    const rt_image       *height;     /* the terrain's R16 heightfield     */
    rt_buffer             heights;    /* its copy the march reads          */
    rt_buffer             map;        /* W x H bytes, in uints             */
    rt_buffer             readback;   /* host copy for rt_shadow_gpu_read  */
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout      layout;
    VkDescriptorPool      pool;
    VkDescriptorSet       set;
    VkPipeline            pipe;
    bool                  made;       /* the buffer holds a whole map      */
    rt_vk_list            keep;       /* layouts, pool, pipeline           */
};

/* The push block of march_glsl. */
typedef struct march_push {
    float    d[2];         /* texels per metre along the sun's direction */
    float    rise, step;   /* metres up per metre; metres per sample     */
    float    kh, eps;      /* metres per raw unit; the start's lift (m)  */
    float    tan_r, top;   /* tan of the sun's radius; highest (raw)     */
    int32_t  rect[4];      /* texels made: x0 z0 x1 z1, end exclusive    */
    int32_t  size[2];      /* W H                                        */
    uint32_t first, count; /* uints of the buffer this dispatch makes    */
    float    inv[2];       /* 1 / d (1e30 where d is 0): metres per texel */
} march_push;

static const char march_glsl[] =
    "layout(local_size_x = 64) in;\n"
    "layout(set = 0, binding = 0, std430) readonly buffer height_block { uint h[]; } u_height;\n"
    "layout(set = 0, binding = 1, std430) readonly buffer bound_block { float b[]; } u_bound;\n"
    "layout(set = 0, binding = 2, std430) buffer map_block { uint words[]; } u_map;\n"
    "layout(push_constant) uniform push_block {\n"
    "    vec2 d; float rise, step;\n"
    "    float kh, eps, tan_r, top;\n"
    "    ivec4 rect;\n"
    "    ivec2 size; uint first, count;\n"
    "    vec2 inv;   /* 1 / d, 1e30 where d is 0 */\n"
    "} u;\n"
    /* texel k of the heightfield, raw units, clamped to the edge (two R16
     * texels a word, as the image's bytes lie) */
    "float raw(ivec2 k) {\n"
    "    k = clamp(k, ivec2(0), u.size - 1);\n"
    "    uint i = uint(k.y) * uint(u.size.x) + uint(k.x);\n"
    "    return float((u_height.h[i >> 1u] >> (16u * (i & 1u))) & 0xffffu);\n"
    "}\n"
    /* bilinear between texel centres at texel base's centre + o (texels),
     * in raw units: shadow.c's rt_height_at */
    "float height(ivec2 base, vec2 o) {\n"
    "    vec2 f = floor(o), w = o - f;\n"
    "    ivec2 k = base + ivec2(f);\n"
    "    float a = raw(k), b = raw(k + ivec2(1, 0));\n"
    "    float c = raw(k + ivec2(0, 1)), e = raw(k + ivec2(1, 1));\n"
    "    return (a * (1.0 - w.x) + b * w.x) * (1.0 - w.y) + (c * (1.0 - w.x) + e * w.x) * w.y;\n"
    "}\n"
    /* distance along the ray from texel-space p to the exit of the box
     * [lo, hi] (texels) */
    "float box_exit(vec2 p, vec2 lo, vec2 hi) {\n"
    "    vec2 e = (mix(lo, hi, greaterThan(u.d, vec2(0.0))) - p) * u.inv;\n"
    "    e = mix(e, vec2(1e30), equal(u.d, vec2(0.0)));\n"
    "    return max(min(e.x, e.y), 0.0);\n"
    "}\n"
    /* no sample past t can lower the lowest clearance below thr where the
     * ray is `above` the highest height ahead (m) and leaves it at t + exit */
    "bool clear_of(float above, float t, float exit, float thr) {\n"
    "    return above > thr * (thr >= 0.0 ? t + exit : t);\n"
    "}\n"
    /* the pyramid's cell of level L around p: whether the march may skip
     * it (thr as clear_of), its exit, and its height above the start */
    "bool level_clear(int L, vec2 p, float ray, float h0, float t, float thr, out float exit,\n"
    "                 out float above) {\n"
    "    int s = 1 << L;\n"
    "    ivec2 n = ivec2(PW >> L, PH >> L);\n"
    "    ivec2 c = clamp(ivec2(floor(p / float(s))), ivec2(0), n - 1);\n"
    /* level L's first float: every level above it holds a quarter of
     * the one below (PW and PH are multiples of 2^LEVELS), so the levels
     * before L hold 4/3 (PW PH - n.x n.y); arithmetic, not a constant
     * array, which llvmpipe indexed per lane at 18 % of the map's time */
    "    uint off = (4u * (uint(PW * PH) - uint(n.x * n.y))) / 3u;\n"
    "    float hmax = u_bound.b[off + uint(c.y) * uint(n.x) + uint(c.x)];\n"
    "    exit = box_exit(p, vec2(c * s), vec2((c + 1) * s));\n"
    "    above = ray - (hmax - h0) * u.kh;\n"
    "    return clear_of(above, t, exit, thr);\n"
    "}\n"
    "uint visibility(ivec2 base) {\n"
    "    float h0 = raw(base);\n"
    "    float lowest = 1e30;\n"
    "    float k = 1.0;\n"
    "    vec2 size = vec2(u.size);\n"
    "    int L = 0;   /* the pyramid level looked at */\n"
    /* the ray leaves the terrain's rectangle at `whole` from the start */
    "    float whole = box_exit(vec2(base) + 0.5, vec2(0.0), size);\n"
    "    float top = (u.top - h0) * u.kh;   /* the highest point above the start (m) */\n"
    "    while (lowest > -u.tan_r) {\n"
    "        float t = k * u.step;\n"
    "        vec2 o = u.d * t;\n"
    "        vec2 p = vec2(base) + 0.5 + o;   /* texels from the terrain's corner */\n"
    "        if (any(lessThan(p, vec2(0.0))) || any(greaterThan(p, size))) break;\n"
    "        float ray = u.eps + u.rise * t;   /* metres above the start */\n"
    "        if (ray > top) break;   /* above the terrain: shadow.c's end */\n"
    "        float thr = min(lowest, u.tan_r);\n"
    /* the whole terrain below the ray: done */
    "        if (clear_of(ray - top, t, max(whole - t, 0.0), thr))\n"
    "            break;\n"
    /* one cell a step, so SIMD lanes run the same code: skipped, then
     * its parent next; else its child at the same sample; else, at the
     * finest level, the sample */
    "        float exit, above;\n"
    "        if (level_clear(L, p, ray, h0, t, thr, exit, above) && exit > 0.0) {\n"
    "            k = max(k + 1.0, floor((t + exit) / u.step) + 1.0);\n"
    "            L = min(L + 1, LEVELS);\n"
    "        } else if (L > 0) {\n"
    "            L--;\n"
    "        } else {\n"
    /* a sample the quad's bound says cannot lower the lowest: not read */
    "            if (above < lowest * t) {\n"
    "                float h = height(base, o);\n"
    "                lowest = min(lowest, (ray - (h - h0) * u.kh) / t);\n"
    "            }\n"
    "            k += 1.0;\n"
    "        }\n"
    "    }\n"
    "    float v = lowest >= 1e30 ? 1.0 : clamp(0.5 + lowest / (2.0 * u.tan_r), 0.0, 1.0);\n"
    "    return uint(roundEven(v * 255.0));\n"
    "}\n"
    "void main() {\n"
    "    uint g = gl_GlobalInvocationID.x;\n"
    "    if (g >= u.count) return;\n"
    "    uint w = u.first + g, word = u_map.words[w], n = uint(u.size.x * u.size.y);\n"
    "    for (uint b = 0u; b < 4u; b++) {\n"
    "        uint idx = 4u * w + b;\n"
    "        if (idx >= n) break;\n"
    "        ivec2 px = ivec2(idx % uint(u.size.x), idx / uint(u.size.x));\n"
    "        if (any(lessThan(px, u.rect.xy)) || any(greaterThanEqual(px, u.rect.zw))) continue;\n"
    "        word = (word & ~(0xffu << (8u * b))) | (visibility(px) << (8u * b));\n"
    "    }\n"
    "    u_map.words[w] = word;\n"
    "}\n";

/* The highest raw height of the bilinear surface over each quad between
 * texel edges (its 3 x 3 texels), then the largest of four per level,
 * into s->bound. */
static bool make_bound(rt_shadow_gpu *s, const uint16_t *heights, rt_error *e)
{
    int W = s->W, H = s->H, K = LEVELS;
    int PW = ((W + (1 << K) - 1) >> K) << K, PH = ((H + (1 << K) - 1) >> K) << K;
    s->PW = PW;
    s->PH = PH;
    size_t total = 0;
    for (int k = 0; k <= K; k++) {
        s->offset[k] = (uint32_t)total;
        /* the march's arithmetic for it (march_glsl level_clear) */
        assert(total == 4 * ((size_t)PW * (size_t)PH - (size_t)(PW >> k) * (size_t)(PH >> k)) / 3);
        total += (size_t)(PW >> k) * (size_t)(PH >> k);
    }
    rt_buffer staging;
    VkDeviceSize bytes = (VkDeviceSize)total * sizeof(float);
    if (bytes > s->d->props.limits.maxStorageBufferRange)
        return rt_fail(e, RT_E_PACK_LIMIT, "shadow march", "its height pyramid (bytes)",
                       (unsigned long long)bytes, "maxStorageBufferRange",
                       (unsigned long long)s->d->props.limits.maxStorageBufferRange);
    if (!rt_buffer_create(s->d, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, &staging, e))
        return false;
    float *l0 = staging.map;
    for (int j = 0; j < PH; j++)
        for (int i = 0; i < PW; i++) {
            unsigned m = 0;   /* padding: 0, off the terrain */
            for (int dz = -1; dz <= 1 && i < W && j < H; dz++) {
                int z = j + dz < 0 ? 0 : j + dz >= H ? H - 1 : j + dz;
                for (int dx = -1; dx <= 1; dx++) {
                    int x = i + dx < 0 ? 0 : i + dx >= W ? W - 1 : i + dx;
                    unsigned v = heights[(size_t)z * (size_t)W + (size_t)x];
                    m = v > m ? v : m;
                }
            }
            l0[(size_t)j * (size_t)PW + (size_t)i] = (float)m;
        }
    for (int k = 1; k <= K; k++) {
        int w = PW >> k, h = PH >> k, pw = PW >> (k - 1);
        const float *prev = l0 + s->offset[k - 1];
        float *cur = l0 + s->offset[k];
        for (int j = 0; j < h; j++)
            for (int i = 0; i < w; i++) {
                const float *q = prev + (size_t)(2 * j) * (size_t)pw + (size_t)(2 * i);
                cur[(size_t)j * (size_t)w + (size_t)i] =
                    fmaxf(fmaxf(q[0], q[1]), fmaxf(q[pw], q[pw + 1]));
            }
    }
    VkCommandBuffer cb;
    bool ok = rt_buffer_create(s->d, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                               VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, &s->bound, e) &&
              rt_oneshot_begin(s->d, &cb, e);
    if (ok) {
        VkBufferCopy c = { 0, 0, bytes };
        vkCmdCopyBuffer(cb, staging.buf, s->bound.buf, 1, &c);
        ok = rt_oneshot_end(s->d, cb, e);
    }
    rt_buffer_destroy(s->d, &staging);
    return ok;
}

bool rt_shadow_gpu_create(rt_device *d, const rt_pack *p, const uint16_t *heights,
                          const rt_image *height, VkPipelineCache cache, rt_shadow_gpu **out,
                          rt_error *e)
{
    rt_shadow_gpu *s = calloc(1, sizeof *s);
    *out = s;
    if (!s)
        return rt_fail(e, RT_E_VULKAN, "shadow march", "out of memory");
    s->d = d;
    s->W = p->hf_width;
    s->H = p->hf_height;
    s->size[0] = p->size[0];
    s->size[1] = p->size[1];
    s->max_height = p->max_height;
    s->hoffset = p->height_offset;
    s->height = height;
    size_t n = (size_t)p->hf_width * (size_t)p->hf_height, words = (n + 3) / 4;
    const VkBufferUsageFlags sb = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    if (!make_bound(s, heights, e) ||
        !rt_buffer_create(d, (n * 2 + 3) / 4 * 4, sb | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false,
                          &s->heights, e) ||
        !rt_buffer_create(d, words * 4, sb | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, &s->map, e))
        return false;
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType sbt = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    VkDescriptorSetLayoutBinding b[3] = {
        { 0, sbt, 1, cs, NULL }, { 1, sbt, 1, cs, NULL }, { 2, sbt, 1, cs, NULL },
    };
    VkDescriptorPoolSize sizes[1] = { { sbt, 3 } };
    rt_vk_list *k = &s->keep;
    if (!rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "shadow march", b, 3 },
                          &s->set_layout, e) ||
        !rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "shadow march",
                          .sets = &s->set_layout, .nsets = 1, .push_stages = cs,
                          .push_bytes = sizeof(march_push) }, &s->layout, e) ||
        !rt_vk_sets(d, k, &(rt_vk_sets_desc){ .label = "shadow march", .sizes = sizes,
                        .nsizes = 1, .layouts = &s->set_layout, .nsets = 1 },
                    &s->pool, &s->set, e))
        return false;
    rt_vk_write w[3] = { { s->set, 0, sbt, s->heights.buf }, { s->set, 1, sbt, s->bound.buf },
                         { s->set, 2, sbt, s->map.buf } };
    rt_vk_write_sets(d, w, 3);
    /* the pyramid's shape as constants */
    char head[128];
    snprintf(head, sizeof head, "#version 450\n#define LEVELS %d\n#define PW %d\n#define PH %d\n",
             LEVELS, s->PW, s->PH);
    char *src = malloc(strlen(head) + sizeof march_glsl);
    if (!src)
        return rt_fail(e, RT_E_VULKAN, "shadow march", "out of memory");
    strcpy(src, head);
    strcat(src, march_glsl);
    bool ok = rt_vk_compute(d, &s->keep, &(rt_vk_compute_desc){ .label = "shadow.comp",
                                .glsl = src, .layout = s->layout, .cache = cache }, &s->pipe, e);
    free(src);
    return ok;
}

void rt_shadow_gpu_destroy(rt_shadow_gpu *s)
{
    if (!s)
        return;
    rt_device *d = s->d;
    rt_vk_list_destroy(d, &s->keep);
    if (d->dev) {
        rt_buffer_destroy(d, &s->bound);
        rt_buffer_destroy(d, &s->heights);
        rt_buffer_destroy(d, &s->map);
        rt_buffer_destroy(d, &s->readback);
    }
    free(s);
}

bool rt_shadow_gpu_map(rt_shadow_gpu *s, const double sun[3], double top, const int rect[4],
                       rt_image *shadow, rt_error *e)
{
    int W = s->W, H = s->H;
    double flat = sqrt(sun[0] * sun[0] + sun[2] * sun[2]);
    bool constant = sun[1] <= -SUN_TAN * flat || flat < 1e-9;   /* below the horizon, or overhead */
    if (!rect || constant)
        rect = NULL;
    else if (!s->made)
        return rt_fail(e, RT_E_VULKAN, "shadow march", "a part of a map never made whole");
    int i0 = rect ? rect[0] : 0, j0 = rect ? rect[1] : 0;
    int i1 = rect ? rect[2] : W, j1 = rect ? rect[3] : H;
    if (i0 >= i1 || j0 >= j1)
        return true;
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(s->d, &cb, e))
        return false;
    /* the heights as craters left them (their uploads are transfers, the
     * frames' vertex, fragment and compute stages read the image), copied
     * where the march reads them; the last update's reads and copy of the
     * buffers this one writes are done */
    const VkPipelineStageFlags shaders = VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
        VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    rt_cmd_image_barrier(cb, s->height->img, 0, 1, 1, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_ACCESS_TRANSFER_READ_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT | shaders, VK_PIPELINE_STAGE_TRANSFER_BIT);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0);
    VkBufferImageCopy hc = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { (uint32_t)W, (uint32_t)H, 1 },
    };
    vkCmdCopyImageToBuffer(cb, s->height->img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           s->heights.buf, 1, &hc);
    rt_cmd_image_barrier(cb, s->height->img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, VK_ACCESS_SHADER_READ_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, shaders);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                       VK_ACCESS_TRANSFER_WRITE_BIT);
    if (constant) {
        vkCmdFillBuffer(cb, s->map.buf, 0, VK_WHOLE_SIZE, sun[1] > 0 ? 0xffffffffu : 0u);
    } else {
        double sx = s->size[0] / W, sz = s->size[1] / H;
        march_push push = {
            .d = { (float)(sun[0] / flat / sx), (float)(sun[2] / flat / sz) },
            .rise = (float)(sun[1] / flat), .step = (float)(0.5 * fmin(sx, sz)),
            .kh = (float)(s->max_height / 65535.0), .eps = (float)(1e-4 * (s->max_height + 1.0)),
            .tan_r = (float)SUN_TAN,
            .top = s->max_height > 0 ? (float)((top - s->hoffset) / (s->max_height / 65535.0)) : 0.0f,
            .rect = { i0, j0, i1, j1 }, .size = { W, H },
        };
        for (int a = 0; a < 2; a++)
            push.inv[a] = push.d[a] != 0 ? 1.0f / push.d[a] : 1e30f;
        size_t first = (size_t)j0 * (size_t)W / 4, end = ((size_t)j1 * (size_t)W + 3) / 4;
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->pipe);
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 0, 1, &s->set, 0,
                                NULL);
        /* in runs of at most 65,535 workgroups (the guaranteed
         * maxComputeWorkGroupCount: a 4096^2 map needs 65,536) */
        const size_t run = (size_t)65535 * 64;
        for (size_t at = first; at < end; at += run) {
            push.first = (uint32_t)at;
            push.count = (uint32_t)(end - at < run ? end - at : run);
            vkCmdPushConstants(cb, s->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
            vkCmdDispatch(cb, (push.count + 63) / 64, 1, 1);
        }
    }
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    /* the map: every frame's shaders read it until now */
    rt_cmd_image_barrier(cb, shadow->img, 0, 1, 1, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_ACCESS_SHADER_READ_BIT,
                         VK_ACCESS_TRANSFER_WRITE_BIT, shaders, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy copy = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { (uint32_t)W, (uint32_t)H, 1 },
    };
    vkCmdCopyBufferToImage(cb, s->map.buf, shadow->img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &copy);
    rt_cmd_image_barrier(cb, shadow->img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, shaders);
    if (!rt_oneshot_end(s->d, cb, e))
        return false;
    s->made = true;
    return true;
}

bool rt_shadow_gpu_read(rt_shadow_gpu *s, uint8_t *out, rt_error *e)
{
    size_t n = (size_t)s->W * (size_t)s->H, bytes = (n + 3) / 4 * 4;
    if (!s->readback.buf &&
        !rt_buffer_create(s->d, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &s->readback, e))
        return false;
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(s->d, &cb, e))
        return false;
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy c = { 0, 0, bytes };
    vkCmdCopyBuffer(cb, s->map.buf, s->readback.buf, 1, &c);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    if (!rt_oneshot_end(s->d, cb, e))
        return false;
    memcpy(out, s->readback.map, n);
    return true;
}
