/* terrain_upload.c — the heightfield on the GPU (R16_UNORM, fetched by the shared
 * vertex shader) with the other images of the terrain descriptor set, and
 * the min/max height of every quadtree node for frustum culling and LOD
 * distances.
 *
 * A patch vertex at uv = k / W samples bilinearly between the texel
 * centres around it, so a leaf cell covering texels [x0, x1) can show any
 * height of texels [x0 - 1, x1] (clamped): those are the texels its bounds
 * take.  Coarser nodes take the union of their children. */
#include "rt_internal.h"
#include "vk_build.h"

#include <stdlib.h>
#include <string.h>

int rt_level_count(int cells_x, int cells_z)
{
    int n = 1;
    while (cells_x > 1 || cells_z > 1) {
        cells_x = (cells_x + 1) / 2;
        cells_z = (cells_z + 1) / 2;
        n++;
    }
    return n;
}

bool rt_bounds_build(rt_bounds *b, const uint16_t *texels, int w, int h,
                     int cell_texels, double max_height, double offset)
{
    memset(b, 0, sizeof *b);
    int cx = (w + cell_texels - 1) / cell_texels, cz = (h + cell_texels - 1) / cell_texels;
    b->nlevels = rt_level_count(cx, cz);
    b->width = calloc((size_t)b->nlevels, sizeof *b->width);
    b->height = calloc((size_t)b->nlevels, sizeof *b->height);
    b->hmin = calloc((size_t)b->nlevels, sizeof *b->hmin);
    b->hmax = calloc((size_t)b->nlevels, sizeof *b->hmax);
    if (!b->width || !b->height || !b->hmin || !b->hmax) {
        rt_bounds_free(b);
        return false;
    }
    for (int L = 0; L < b->nlevels; L++) {
        b->width[L] = cx;
        b->height[L] = cz;
        b->hmin[L] = malloc((size_t)cx * (size_t)cz * sizeof(float));
        b->hmax[L] = malloc((size_t)cx * (size_t)cz * sizeof(float));
        if (!b->hmin[L] || !b->hmax[L]) {
            rt_bounds_free(b);
            return false;
        }
        cx = (cx + 1) / 2;
        cz = (cz + 1) / 2;
    }
    /* Leaves from the texels.  Row minima/maxima first would be faster; a
     * 4096^2 field still takes only a few milliseconds at load. */
    for (int z = 0; z < b->height[0]; z++)
        for (int x = 0; x < b->width[0]; x++)
            rt_bounds_leaf(b, texels, w, h, cell_texels, max_height, offset, x, z);
    for (int L = 1; L < b->nlevels; L++)
        for (int z = 0; z < b->height[L]; z++)
            for (int x = 0; x < b->width[L]; x++)
                rt_bounds_merge(b, L, x, z);
    return true;
}

void rt_bounds_leaf(rt_bounds *b, const uint16_t *texels, int w, int h, int cell_texels,
                    double max_height, double offset, int x, int z)
{
    int x0 = x * cell_texels - 1, x1 = (x + 1) * cell_texels;
    int z0 = z * cell_texels - 1, z1 = (z + 1) * cell_texels;
    x0 = x0 < 0 ? 0 : x0;
    z0 = z0 < 0 ? 0 : z0;
    x1 = x1 >= w ? w - 1 : x1;
    z1 = z1 >= h ? h - 1 : z1;
    unsigned lo = 65535, hi = 0;
    for (int tz = z0; tz <= z1; tz++)
        for (int tx = x0; tx <= x1; tx++) {
            unsigned v = texels[(size_t)tz * (size_t)w + (size_t)tx];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
    size_t i = (size_t)z * (size_t)b->width[0] + (size_t)x;
    b->hmin[0][i] = (float)(lo / 65535.0 * max_height + offset);
    b->hmax[0][i] = (float)(hi / 65535.0 * max_height + offset);
}

void rt_bounds_merge(rt_bounds *b, int L, int x, int z)
{
    int pw = b->width[L - 1], ph = b->height[L - 1];
    float lo = 1e30f, hi = -1e30f;
    for (int c = 0; c < 4; c++) {
        int qx = 2 * x + (c & 1), qz = 2 * z + (c >> 1);
        if (qx >= pw || qz >= ph)
            continue;
        size_t j = (size_t)qz * (size_t)pw + (size_t)qx;
        lo = b->hmin[L - 1][j] < lo ? b->hmin[L - 1][j] : lo;
        hi = b->hmax[L - 1][j] > hi ? b->hmax[L - 1][j] : hi;
    }
    size_t i = (size_t)z * (size_t)b->width[L] + (size_t)x;
    b->hmin[L][i] = lo;
    b->hmax[L][i] = hi;
}

void rt_bounds_free(rt_bounds *b)
{
    for (int L = 0; L < b->nlevels; L++) {
        if (b->hmin)
            free(b->hmin[L]);
        if (b->hmax)
            free(b->hmax[L]);
    }
    free(b->hmin);
    free(b->hmax);
    free(b->width);
    free(b->height);
    memset(b, 0, sizeof *b);
}

static bool make_sampler(rt_device *d, VkFilter filter, VkSampler *s, rt_error *e)
{
    return rt_vk_sampler(d, NULL, &(rt_vk_sampler_desc){ .label = "terrain", .filter = filter,
                             .wrap = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE }, s, e);
}

bool rt_terrain_upload(rt_device *d, const rt_pack *p, rt_terrain_gpu *t,
                       rt_error *e)
{
    memset(t, 0, sizeof *t);
    const VkImageUsageFlags use = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    const VkFormatFeatureFlags filt = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                                      VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
    if (!rt_format_supports(d, VK_FORMAT_R16_UNORM, filt))
        return rt_fail(e, RT_E_NO_FORMAT, "sample R16_UNORM with linear filtering");
    uint32_t W = (uint32_t)p->hf_width, H = (uint32_t)p->hf_height;
    /* transfer source too: tests read back the texels craters lowered */
    if (!rt_image_create(d, W, H, 1, false, 1, VK_FORMAT_R16_UNORM,
                         use | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                         VK_IMAGE_ASPECT_COLOR_BIT, &t->height, e) ||
        !rt_image_upload(d, &t->height, p->heights, (size_t)W * H * 2, e))
        return false;

    /* Painted masks: the sparse quad-tree (painted_upload.c), or dense: one layer
     * each, one zero layer when the scene has none (index and level then
     * 1x1 placeholders for bindings 5 and 6). */
    uint8_t zero8[8] = { 0 };
    if (p->sparse) {
        if (!rt_painted_upload(d, p, &t->painted, &t->painted_index, &t->painted_level, e))
            return false;
    } else if (!rt_image_create(d, 1, 1, 1, true, 1, VK_FORMAT_R16G16B16A16_UINT, use,
                                VK_IMAGE_ASPECT_COLOR_BIT, &t->painted_index, e) ||
               !rt_image_upload(d, &t->painted_index, zero8, 8, e) ||
               !rt_image_create(d, 1, 1, 1, true, 1, VK_FORMAT_R8G8B8A8_UINT, use,
                                VK_IMAGE_ASPECT_COLOR_BIT, &t->painted_level, e) ||
               !rt_image_upload(d, &t->painted_level, zero8, 4, e))
        return false;
    uint32_t layers = p->npainted > 0 ? (uint32_t)p->npainted : 1;
    size_t pbytes = p->npainted > 0 ? (size_t)layers * W * H : 1;
    uint8_t zero4[4] = { 0, 0, 0, 0 };
    if (!p->sparse &&
        (!rt_image_create(d, p->npainted > 0 ? W : 1, p->npainted > 0 ? H : 1, layers, true, 1,
                         VK_FORMAT_R8_UNORM, use, VK_IMAGE_ASPECT_COLOR_BIT, &t->painted, e) ||
         !rt_image_upload(d, &t->painted, p->npainted > 0 ? p->painted : zero4, pbytes, e)))
        return false;
    /* Holes (abi.h binding 12): the pack's, or one texel of 0 (none). */
    if (!rt_format_supports(d, VK_FORMAT_R8_UNORM, filt))
        return rt_fail(e, RT_E_NO_FORMAT, "sample R8_UNORM with linear filtering");
    if (!rt_image_create(d, p->holes ? W : 1, p->holes ? H : 1, 1, false, 1,
                         VK_FORMAT_R8_UNORM, use, VK_IMAGE_ASPECT_COLOR_BIT, &t->holes, e) ||
        !rt_image_upload(d, &t->holes, p->holes ? p->holes : zero4,
                         p->holes ? (size_t)W * H : 1, e))
        return false;
    /* Sun visibility (binding 11): all lit until the renderer's first
     * shadow map (shadow.c) replaces it. */
    uint8_t *lit = malloc((size_t)W * H);
    bool made = lit && rt_image_create(d, W, H, 1, false, 1, VK_FORMAT_R8_UNORM, use,
                                       VK_IMAGE_ASPECT_COLOR_BIT, &t->shadow, e);
    if (made) memset(lit, 255, (size_t)W * H);
    made = made && rt_image_upload(d, &t->shadow, lit, (size_t)W * H, e);
    free(lit);
    if (!made)
        return e->msg ? false : rt_fail(e, RT_E_VULKAN, "shadow map", "out of memory");
    /* Destruction: nothing destroyed (index alpha 0) until a crater fills it
     * (destruction.c). */
    if (!rt_image_create(d, 1, 1, 1, false, 1, VK_FORMAT_R8_UNORM, use,
                         VK_IMAGE_ASPECT_COLOR_BIT, &t->destr_atlas, e) ||
        !rt_image_upload(d, &t->destr_atlas, zero4, 1, e) ||
        !rt_image_create(d, 1, 1, 1, false, 1, VK_FORMAT_R8G8B8A8_UNORM, use,
                         VK_IMAGE_ASPECT_COLOR_BIT, &t->destr_index, e) ||
        !rt_image_upload(d, &t->destr_index, zero4, 4, e))
        return false;
    return make_sampler(d, VK_FILTER_LINEAR, &t->linear_clamp, e) &&
           make_sampler(d, VK_FILTER_NEAREST, &t->nearest_clamp, e);
}

void rt_terrain_destroy(rt_device *d, rt_terrain_gpu *t)
{
    rt_image_destroy(d, &t->height);
    rt_image_destroy(d, &t->painted);
    rt_image_destroy(d, &t->painted_index);
    rt_image_destroy(d, &t->painted_level);
    rt_image_destroy(d, &t->destr_atlas);
    rt_image_destroy(d, &t->destr_index);
    rt_image_destroy(d, &t->holes);
    rt_image_destroy(d, &t->shadow);
    if (t->linear_clamp)
        vkDestroySampler(d->dev, t->linear_clamp, NULL);
    if (t->nearest_clamp)
        vkDestroySampler(d->dev, t->nearest_clamp, NULL);
    memset(t, 0, sizeof *t);
}
