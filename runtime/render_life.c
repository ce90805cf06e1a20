/* render_life.c — the renderer's lifetime: its targets, geometry,
 * textures, descriptors and command buffer, made at creation; the pack's
 * own objects (undergrowth, far atlas, screen-space path), made by one
 * helper at creation and again when a hot reload swaps the pack. */
#include "render_int.h"
#include "vk_build.h"
#include "util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- render passes -------------------------------------------------------- */

/* The renderer's render passes: ncolor RGBA32F targets (cleared, kept,
 * ending in color_final) and a cleared D32 depth if `depth` (kept: the
 * undergrowth tests it). */
static bool make_pass(rt_device *d, uint32_t ncolor, bool depth, VkImageLayout color_final,
                      VkRenderPass *out, rt_error *e)
{
    /* Earlier reads (copies, resolve, viewer) finish before we write again;
     * our writes are visible to whatever reads the targets next. */
    static const VkSubpassDependency dep[2] = {
        { VK_SUBPASS_EXTERNAL, 0,
          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT |
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT,
          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT |
          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT, 0 },
        { 0, VK_SUBPASS_EXTERNAL,
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT, 0 },
    };
    rt_vk_pass_desc pd = { .label = "renderer", .ncolor = ncolor, .deps = dep, .ndeps = 2 };
    for (uint32_t i = 0; i < ncolor; i++)
        pd.color[i] = (rt_vk_attachment){ .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                          .load = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                          .final = color_final };
    if (depth)
        pd.depth = (rt_vk_attachment){ .format = VK_FORMAT_D32_SFLOAT,
                                       .load = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                       .final = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    return rt_vk_pass(d, NULL, &pd, out, e);   /* destroyed by hand (renderer teardown) */
}

static bool make_fb(rt_device *d, VkRenderPass pass, const VkImageView *views, uint32_t n,
                    int w, int h, VkFramebuffer *out, rt_error *e)
{
    return rt_vk_fb(d, NULL, &(rt_vk_fb_desc){ .label = "renderer", .pass = pass, .views = views,
                        .nviews = n, .width = (uint32_t)w, .height = (uint32_t)h }, out, e);
}

static bool make_targets(rt_renderer *r, rt_error *e)
{
    rt_device *d = r->d;
    int w = r->desc.width, h = r->desc.height;
    const VkFormat cf = VK_FORMAT_R32G32B32A32_SFLOAT;
    VkFormatFeatureFlags need = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
    if (r->desc.reference == RT_REF_MULTIPASS)
        need |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT;
    if (!rt_format_supports(d, cf, need))
        return rt_fail(e, RT_E_NO_FORMAT, "render (and blend) to R32G32B32A32_SFLOAT");
    if (!rt_format_supports(d, VK_FORMAT_D32_SFLOAT, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT))
        return rt_fail(e, RT_E_NO_FORMAT, "use D32_SFLOAT depth");
    bool screen = r->desc.shading == RT_SHADING_SCREEN;
    if (screen && !rt_format_supports(d, cf, VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT))
        return rt_fail(e, RT_E_NO_FORMAT, "store to R32G32B32A32_SFLOAT images (--shading screen)");
    if (screen && !rt_format_supports(d, VK_FORMAT_D32_SFLOAT, VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT))
        return rt_fail(e, RT_E_NO_FORMAT, "sample D32_SFLOAT depth (--shading screen)");
    if (r->scale > 1 &&
        (!rt_format_supports(d, cf, VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT) ||
         !rt_image_create(d, (uint32_t)r->out_w, (uint32_t)r->out_h, 1, false, 1, cf,
                          VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                          VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT, &r->out, e)))
        return e->id ? false
                     : rt_fail(e, RT_E_NO_FORMAT, "store to R32G32B32A32_SFLOAT images (--preview-scale)");
    if (!rt_image_create(d, (uint32_t)w, (uint32_t)h, 1, false, 1, cf,
                         VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                         VK_IMAGE_USAGE_SAMPLED_BIT |
                         (screen ? VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT : 0),
                         VK_IMAGE_ASPECT_COLOR_BIT, &r->color, e) ||
        !rt_image_create(d, (uint32_t)w, (uint32_t)h, 1, false, 1, VK_FORMAT_D32_SFLOAT,
                         VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                         (screen ? VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT : 0),
                         VK_IMAGE_ASPECT_DEPTH_BIT,
                         &r->depth, e))
        return false;
    if (!make_pass(d, 1, true, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, &r->rp.main, e))
        return false;
    VkImageView mv[2] = { r->color.view, r->depth.view };
    if (!make_fb(d, r->rp.main, mv, 2, w, h, &r->fb_main, e))
        return false;
    if (r->desc.reference != RT_REF_MULTIPASS)
        return true;
    for (int i = 0; i < 3; i++)
        if (!rt_image_create(d, (uint32_t)w, (uint32_t)h, 1, false, 1, cf,
                             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                             VK_IMAGE_ASPECT_COLOR_BIT, &r->mp[i], e))
            return false;
    if (!make_pass(d, 3, true, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, &r->rp.multi, e) ||
        !make_pass(d, 1, false, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, &r->rp.resolve, e))
        return false;
    VkImageView tv[4] = { r->mp[0].view, r->mp[1].view, r->mp[2].view, r->depth.view };
    return make_fb(d, r->rp.multi, tv, 4, w, h, &r->fb_multi, e) &&
           make_fb(d, r->rp.resolve, &r->color.view, 1, w, h, &r->fb_resolve, e);
}

/* ---- geometry, textures, descriptors --------------------------------------- */

static bool make_geometry(rt_renderer *r, rt_error *e)
{
    rt_device *d = r->d;
    const size_t nv = SPLAT_GRID * SPLAT_GRID;
    uint32_t total = 0;
    for (int i = 0; i < RT_PERMS; i++) {
        r->perm_first[i] = total;
        r->perm_count[i] = rt_grid_indices(r->desc.no_stitch ? 0 : i, NULL);
        total += r->perm_count[i];
    }
    if (!rt_buffer_create(d, nv * 8, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, true, &r->vbuf, e) ||
        !rt_buffer_create(d, total * 2u, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, true, &r->ibuf, e))
        return false;
    rt_grid_vertices(r->vbuf.map);
    for (int i = 0; i < RT_PERMS; i++)
        rt_grid_indices(r->desc.no_stitch ? 0 : i, (uint16_t *)r->ibuf.map + r->perm_first[i]);
    return true;
}

/* One image and sampler per texture array (abi.h set 1): its textures'
 * levels, one layer each; pack_load.c checked they are alike. */
static bool make_textures(rt_renderer *r, rt_error *e)
{
    rt_device *d = r->d;
    const rt_pack *p = r->p;
    r->ntex = p->narrays;
    r->tex = calloc((size_t)r->ntex + 1, sizeof *r->tex);
    r->tex_smp = calloc((size_t)r->ntex + 1, sizeof *r->tex_smp);
    if (!r->tex || !r->tex_smp)
        return rt_fail(e, RT_E_VULKAN, "textures", "out of memory");
    for (int a = 0; a < r->ntex; a++) {
        const rt_pack_array *A = &p->arrays[a];
        const rt_pack_texture *t = &p->textures[A->textures[0]];
        uint32_t nl = (uint32_t)A->nlayers;
        VkFormat f = t->srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
        uint32_t mips = 1;
        if (t->nmips > 0) {
            /* the pack's own levels (e.g. nearest-neighbour reduced noise) */
            mips = 1 + (uint32_t)t->nmips;
        } else if (rt_format_supports(d, f, VK_FORMAT_FEATURE_BLIT_SRC_BIT |
                                            VK_FORMAT_FEATURE_BLIT_DST_BIT |
                                            VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)) {
            for (int s = t->width > t->height ? t->width : t->height; s > 1; s /= 2)
                mips++;
        }
        if (!rt_image_create(d, (uint32_t)t->width, (uint32_t)t->height, nl, true, mips, f,
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                             VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT, &r->tex[a], e))
            return false;
        bool up;
        if (t->nmips > 0) {
            const uint8_t **levels = calloc((size_t)mips * nl, sizeof *levels);
            if (!levels)
                return rt_fail(e, RT_E_VULKAN, "textures", "out of memory");
            for (uint32_t l = 0; l < nl; l++) {
                const rt_pack_texture *x = &p->textures[A->textures[l]];
                levels[l * mips] = x->rgba;
                for (int k = 0; k < x->nmips; k++)
                    levels[l * mips + 1 + (uint32_t)k] = x->mips[k];
            }
            up = rt_image_upload_levels(d, &r->tex[a], levels, e);
            free(levels);
        } else {
            size_t one = (size_t)t->width * (size_t)t->height * 4;
            uint8_t *all = nl == 1 ? NULL : malloc(one * nl);
            if (nl > 1 && !all)
                return rt_fail(e, RT_E_VULKAN, "textures", "out of memory");
            for (uint32_t l = 0; l < nl && all; l++)
                memcpy(all + one * l, p->textures[A->textures[l]].rgba, one);
            up = rt_image_upload(d, &r->tex[a], all ? all : t->rgba, one * nl, e);
            free(all);
        }
        if (!up)
            return false;
        /* the CPU shading LOD (rt_shading_lod): the nearest level, half
         * the texel fetches of llvmpipe's software sampler */
        bool mip_linear = t->mip_linear && !r->shading_lod;
        if (!rt_vk_sampler(d, NULL, &(rt_vk_sampler_desc){ .label = "texture array",
                               .filter = t->linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST,
                               .mip = mip_linear ? VK_SAMPLER_MIPMAP_MODE_LINEAR
                                                 : VK_SAMPLER_MIPMAP_MODE_NEAREST,
                               .wrap = t->wrap, .max_lod = (float)mips }, &r->tex_smp[a], e))
            return false;
    }
    return true;
}

/* The params block: the pack's values, zero between them. */
static void write_params(rt_renderer *r, const rt_pack *p, size_t bytes)
{
    memset(r->params_ubo.map, 0, bytes);
    for (int i = 0; i < p->nparams; i++)
        memcpy((uint8_t *)r->params_ubo.map + p->params[i].offset, p->params[i].value, 16);
}

/* The frame and params blocks, the counters and the vector shapes. */
static bool make_buffers(rt_renderer *r, rt_error *e)
{
    rt_device *d = r->d;
    const rt_pack *p = r->p;
    if (!rt_buffer_create(d, sizeof(splat_frame), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true,
                          &r->frame_ubo, e) ||
        !rt_buffer_create(d, p->params_size, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true,
                          &r->params_ubo, e))
        return false;
    /* the forward path's counters (abi.h SPLAT_COUNT) */
    if (!rt_buffer_create(d, sizeof(splat_counters), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          false, &r->counters, e) ||
        !rt_buffer_create(d, sizeof(splat_counters), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true,
                          &r->counters_host, e))
        return false;
    memset(r->counters_host.map, 0, sizeof(splat_counters));
    /* the vector shapes, host-visible (read once per pixel that needs
     * them); a pack without shapes binds one word no shader reads */
    VkDeviceSize vbytes = p->vectors ? 4 * (VkDeviceSize)p->nvectors : 16;
    if (!rt_buffer_create(d, vbytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, &r->vectors, e))
        return false;
    if (p->vectors)
        memcpy(r->vectors.map, p->vectors, 4 * p->nvectors);
    else
        memset(r->vectors.map, 0, 16);
    write_params(r, p, p->params_size);
    return true;
}

/* Sets 0 and 1 (2 for the multi-pass reference's resolve, 0c for the
 * screen path's compute), their pool. */
static bool make_sets(rt_renderer *r, rt_error *e)
{
    rt_device *d = r->d;
    VkDescriptorPoolSize sizes[4] = {
        { VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 3 },
        { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2 * 10 + (uint32_t)r->ntex + 3 },
        { VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1 },
        { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3 + 2 },   /* + the vectors', two sets */
    };
    bool multi = r->desc.reference == RT_REF_MULTIPASS;
    bool screen = r->desc.shading == RT_SHADING_SCREEN;
    VkDescriptorSetLayout layouts[4] = { r->pl.set_terrain, r->pl.set_material };
    uint32_t n = 2;
    if (multi)
        layouts[n++] = r->pl.set_resolve;
    if (screen)
        layouts[n++] = r->pl.set_terrain;   /* set 0c */
    VkDescriptorSet sets[4];
    if (!rt_vk_sets(d, NULL, &(rt_vk_sets_desc){ .label = "renderer", .sizes = sizes,
                        .nsizes = 4, .layouts = layouts, .nsets = n }, &r->dpool, sets, e))
        return false;   /* the pool: destroyed by hand (renderer teardown) */
    r->set0 = sets[0];
    r->set1 = sets[1];
    r->set2 = multi ? sets[2] : VK_NULL_HANDLE;
    r->set0c = screen ? sets[n - 1] : VK_NULL_HANDLE;
    return true;
}

/* What sets 0, 1 and 2 bind (abi.h SPLAT_BIND_*). */
static bool write_sets(rt_renderer *r, rt_error *e)
{
    rt_device *d = r->d;
    const rt_pack *p = r->p;
    const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    const rt_terrain_gpu *t = &r->terrain;
    int n = 0;
    VkDescriptorImageInfo img[11 + 3];
    VkDescriptorImageInfo *timg = calloc((size_t)r->ntex + 1, sizeof *timg);
    VkWriteDescriptorSet *w = calloc((size_t)r->ntex + 16, sizeof *w);
    if (!timg || !w) {
        free(timg);
        free(w);
        return rt_fail(e, RT_E_VULKAN, "descriptors", "out of memory");
    }
    VkDescriptorBufferInfo fb = { r->frame_ubo.buf, 0, sizeof(splat_frame) };
    VkDescriptorBufferInfo pb = { r->params_ubo.buf, 0, p->params_size };
    VkDescriptorBufferInfo cb = { r->counters.buf, 0, sizeof(splat_counters) };
    VkDescriptorBufferInfo vb = { r->vectors.buf, 0, VK_WHOLE_SIZE };
    img[0] = (VkDescriptorImageInfo){ t->linear_clamp, t->height.view, ro };
    img[1] = (VkDescriptorImageInfo){ t->linear_clamp, t->painted.view, ro };
    img[2] = (VkDescriptorImageInfo){ t->linear_clamp, t->destr_atlas.view, ro };
    img[3] = (VkDescriptorImageInfo){ t->nearest_clamp, t->destr_index.view, ro };
    if (r->destr)
        rt_destruction_views(r->destr, &img[2].imageView, &img[3].imageView);
#define W(set_, b_, type_, img_, buf_) \
    w[n++] = (VkWriteDescriptorSet){ .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, \
        .dstSet = set_, .dstBinding = b_, .descriptorCount = 1, .descriptorType = type_, \
        .pImageInfo = img_, .pBufferInfo = buf_ }
    const VkDescriptorType smp = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    const VkDescriptorType ubo = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    W(r->set0, SPLAT_BIND_HEIGHTFIELD, smp, &img[0], NULL);
    W(r->set0, SPLAT_BIND_FRAME, ubo, NULL, &fb);
    W(r->set0, SPLAT_BIND_PAINTED, smp, &img[1], NULL);
    W(r->set0, SPLAT_BIND_DESTRUCTION_ATLAS, smp, &img[2], NULL);
    W(r->set0, SPLAT_BIND_DESTRUCTION_INDEX, smp, &img[3], NULL);
    img[7] = (VkDescriptorImageInfo){ t->nearest_clamp, t->painted_index.view, ro };
    img[8] = (VkDescriptorImageInfo){ t->nearest_clamp, t->painted_level.view, ro };
    W(r->set0, SPLAT_BIND_PAINTED_INDEX, smp, &img[7], NULL);
    W(r->set0, SPLAT_BIND_PAINTED_LEVEL, smp, &img[8], NULL);
    img[9] = (VkDescriptorImageInfo){ t->linear_clamp, t->holes.view, ro };
    W(r->set0, SPLAT_BIND_HOLES, smp, &img[9], NULL);
    img[10] = (VkDescriptorImageInfo){ t->linear_clamp, t->shadow.view, ro };
    W(r->set0, SPLAT_BIND_SHADOW, smp, &img[10], NULL);
    W(r->set0, SPLAT_BIND_COUNTERS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, NULL, &cb);
    W(r->set0, SPLAT_BIND_VECTORS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, NULL, &vb);
    W(r->set1, SPLAT_BIND_PARAMS, ubo, NULL, &pb);
    for (int i = 0; i < r->ntex; i++) {
        timg[i] = (VkDescriptorImageInfo){ r->tex_smp[i], r->tex[i].view, ro };
        W(r->set1, (uint32_t)(SPLAT_BIND_TEXTURE0 + i), smp, &timg[i], NULL);
    }
    if (r->set2)
        for (uint32_t i = 0; i < 3; i++) {
            img[4 + i] = (VkDescriptorImageInfo){ t->nearest_clamp, r->mp[i].view, ro };
            W(r->set2, i, smp, &img[4 + i], NULL);
        }
#undef W
    vkUpdateDescriptorSets(d->dev, (uint32_t)n, w, 0, NULL);
    free(timg);
    free(w);
    return true;
}

static bool make_descriptors(rt_renderer *r, rt_error *e)
{
    if (!make_buffers(r, e) || !make_sets(r, e) || !write_sets(r, e))
        return false;
    if (r->set0c) {
        /* the compute set 0: the same terrain bindings (screen.c adds 7-10) */
        static const uint32_t terrain[] = {
            SPLAT_BIND_HEIGHTFIELD, SPLAT_BIND_FRAME, SPLAT_BIND_PAINTED,
            SPLAT_BIND_DESTRUCTION_ATLAS, SPLAT_BIND_DESTRUCTION_INDEX,
            SPLAT_BIND_PAINTED_INDEX, SPLAT_BIND_PAINTED_LEVEL, SPLAT_BIND_HOLES,
            SPLAT_BIND_SHADOW, SPLAT_BIND_VECTORS,
        };
        enum { N = sizeof terrain / sizeof *terrain };
        VkCopyDescriptorSet cp[N];
        for (int i = 0; i < N; i++)
            cp[i] = (VkCopyDescriptorSet){ .sType = VK_STRUCTURE_TYPE_COPY_DESCRIPTOR_SET,
                .srcSet = r->set0, .srcBinding = terrain[i], .dstSet = r->set0c,
                .dstBinding = terrain[i], .descriptorCount = 1 };
        vkUpdateDescriptorSets(r->d->dev, 0, NULL, N, cp);
    }
    return true;
}

static bool make_commands(rt_renderer *r, rt_error *e)
{
    rt_device *d = r->d;
    VkCommandBufferAllocateInfo ai = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = d->pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    RT_VK(e, vkAllocateCommandBuffers(d->dev, &ai, &r->cb));
    VkFenceCreateInfo fi = { .sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO };
    RT_VK(e, vkCreateFence(d->dev, &fi, NULL, &r->fence));
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d->phys, &n, NULL);
    VkQueueFamilyProperties *qf = calloc(n ? n : 1, sizeof *qf);
    if (qf) {
        vkGetPhysicalDeviceQueueFamilyProperties(d->phys, &n, qf);
        r->timestamps = qf[d->queue_family].timestampValidBits > 0 &&
                        d->props.limits.timestampPeriod > 0;
        free(qf);
    }
    if (r->timestamps) {
        VkQueryPoolCreateInfo qi = {
            .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
            .queryType = VK_QUERY_TYPE_TIMESTAMP,
            .queryCount = RT_PLAN_MAX_PASSES + 1,   /* the start, each pass's end */
        };
        RT_VK(e, vkCreateQueryPool(d->dev, &qi, NULL, &r->qpool));
    }
    return rt_buffer_create(d, (VkDeviceSize)r->out_w * (VkDeviceSize)r->out_h * 16,
                            VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &r->readback, e);
}

/* ---- the pack's objects, creation ---------------------------------------- */

/* The screen path's depth (rt_screen_depth): ray cast where asked, or by
 * default on GPUs when the terrain has no holes (the ray caster does not
 * cut them). */
bool rt_render_use_raycast(const rt_renderer *r)
{
    if (r->desc.screen_depth == RT_DEPTH_RAYCAST)
        return true;
    return r->desc.screen_depth == RT_DEPTH_AUTO && !r->p->holes &&
           r->d->props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
}

static bool make_undergrowth(rt_renderer *r, rt_error *e)
{
    if (r->desc.no_undergrowth || r->p->ug.nslots == 0)
        return true;
    rt_ug_targets t = {
        .color = &r->color, .depth = &r->depth, .height = &r->terrain.height,
        .width = r->desc.width, .height_px = r->desc.height,
        .nearest = r->terrain.nearest_clamp, .set0 = r->set0, .timestamps = r->timestamps,
        .compute = r->desc.undergrowth_compute && r->set0c != VK_NULL_HANDLE,
    };
    return rt_ug_create(r->d, r->p, &r->pl, &r->qt, &t, r->desc.undergrowth_radius,
                        r->desc.undergrowth_thin, &r->ug, e);
}

/* The objects made of the pack's own data, beside what a hot reload keeps
 * (reload_refused): the far atlas (the pack's bake; a reload's pack has
 * none until the next --far-atlas build), the screen-space path, which
 * borrows it and whose combination map and sets are the pack's, and the
 * undergrowth (blocks, meshes and mask shaders).  Made by create and
 * again by swap_pack; on failure none is left. */
static void drop_pack_objects(rt_renderer *r)
{
    rt_upscale_destroy(r->upscale);
    r->upscale = NULL;
    rt_ug_destroy(r->ug);
    rt_screen_destroy(r->screen);
    rt_far_destroy(r->far);
    r->ug = NULL;
    r->screen = NULL;
    r->far = NULL;
}

/* The preview scale's upsample (upscale.c), guided by the screen path's
 * depth: the ray caster's, else the geometry pass's D32. */
static bool make_upscale(rt_renderer *r, rt_error *e)
{
    if (r->scale <= 1)
        return true;
    const rt_image *ray = r->screen ? rt_screen_ray_depth(r->screen) : NULL;
    const rt_image *guide = ray ? ray : r->screen ? &r->depth : NULL;
    return rt_upscale_create(r->d, r->pl.cache, r->terrain.nearest_clamp, &r->color, guide,
                             ray ? VK_IMAGE_LAYOUT_GENERAL
                                 : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                             &r->out, &r->upscale, e);
}

static bool make_pack_objects(rt_renderer *r, bool screen, rt_error *e)
{
    rt_device *d = r->d;
    const rt_pack *p = r->p;
    if (!rt_far_create(d, p, &r->pl, &r->far, e) || !rt_launch_mark("far") ||
        (screen && !rt_screen_create(d, p, &r->pl, &r->color, &r->depth,
                                     r->terrain.nearest_clamp, r->set0c, r->far,
                                     rt_render_use_raycast(r), r->desc.pixel_sort,
                                     r->desc.sort_tiles, &r->screen, e)) ||
        !rt_launch_mark("screen path") ||
        !make_undergrowth(r, e) || !make_upscale(r, e) || !rt_launch_mark("undergrowth, upscale")) {
        drop_pack_objects(r);
        return false;
    }
    if (r->screen) {
        rt_screen_far(r->screen, r->desc.far_atlas_distance);
        rt_screen_tile_blocks(r->screen, r->desc.tile_blocks);
        r->pl.sort_tiles = rt_screen_sort_tiles(r->screen);
    }
    return true;
}

/* The pack's objects with their fixed pipelines (classification, ray
 * caster, list padding, undergrowth, upscale) made together on every core
 * (vk_build.c's batch) instead of one after another: none is used before
 * the first frame. */
static bool make_fixed_pipelines(rt_renderer *r, rt_error *e)
{
    const char *batch = getenv("SPLAT_PIPELINE_BATCH");   /* 0: one after another (timing) */
    if (batch && !strcmp(batch, "0"))
        return make_pack_objects(r, r->set0c != VK_NULL_HANDLE, e);
    if (!rt_vk_batch_begin(r->d, e))
        return false;
    bool ok = make_pack_objects(r, r->set0c != VK_NULL_HANDLE, e);
    rt_launch_mark("pack objects");
    /* and the stand-in of the first frame's lists, with async pipelines:
     * the flat one's or the far atlas's */
    if (ok && r->screen && r->pl.async)
        ok = rt_screen_prepare_stand_in(r->screen, &r->pl,
                                        rt_pipelines_stand_in(r->d, r->p, &r->pl, NULL, 0,
                                                              rt_render_compute_variant(r),
                                                              rt_screen_has_far(r->screen)),
                                        rt_render_compute_variant(r), e);
    rt_launch_mark("stand-in");
    rt_error e2 = { 0 };
    if (!rt_vk_batch_end(r->d, ok, ok ? e : &e2)) {
        rt_error_clear(&e2);
        if (ok)
            drop_pack_objects(r);
        return false;
    }
    return ok;
}

bool rt_renderer_create(rt_device *d, const rt_pack *p, const rt_render_desc *desc,
                        rt_renderer **out, rt_error *e)
{
    *out = NULL;
    if (!rt_pack_check_device(p, d, e))
        return false;
    rt_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return rt_fail(e, RT_E_VULKAN, "renderer", "out of memory");
    r->shadow_stale = true;
    r->d = d;
    r->p = p;
    r->desc = *desc;
    rt_render_pack_light(r, p);
    const char *sh = getenv("SPLAT_SHADOW");   /* cpu | gpu over the default */
    r->shadow_auto = r->desc.shadow == RT_SHADOW_AUTO && !sh;
    if (r->desc.shadow == RT_SHADOW_AUTO)
        r->desc.shadow = sh && !strcmp(sh, "cpu") ? RT_SHADOW_CPU : RT_SHADOW_GPU;
    r->shadow_on_gpu = r->desc.shadow == RT_SHADOW_GPU;
    if (r->desc.width <= 0)
        r->desc.width = 1280;
    if (r->desc.height <= 0)
        r->desc.height = 720;
    /* the preview scale: everything drawn at the internal size, the
     * output made by upscale.c */
    r->out_w = r->desc.width;
    r->out_h = r->desc.height;
    r->scale = r->desc.preview_scale > 1 ? r->desc.preview_scale : 1;
    if (r->scale != 1 && r->scale != 2 && r->scale != 4) {
        free(r);
        return rt_fail(e, RT_E_VULKAN, "preview scale", "must be 1, 2 or 4");
    }
    r->desc.width = (r->out_w + r->scale - 1) / r->scale;
    r->desc.height = (r->out_h + r->scale - 1) / r->scale;
    /* the CPU shading LOD (rt_shading_lod) halves the geometry's detail:
     * llvmpipe runs the vertex stage on one thread */
    r->shading_lod = rt_shading_lod_on(d, r->desc.shading_lod);
    if (r->desc.lod_pixels <= 0)
        r->desc.lod_pixels = r->shading_lod ? 6.0 : 3.0;
    if (r->desc.clear[3] == 0 && r->desc.clear[0] == 0 && r->desc.clear[1] == 0 && r->desc.clear[2] == 0) {
        /* the final view draws the analytic sky; the others this colour */
        static const float sky[4] = { 0.35f, 0.52f, 0.85f, 1.0f };
        memcpy(r->desc.clear, sky, sizeof sky);
        r->default_clear = true;
    }
    r->ncombos = p->ncombos;
    r->combo_ids = calloc((size_t)p->nlevels, sizeof *r->combo_ids);
    r->sorted = malloc(sizeof *r->sorted * (size_t)(p->levels[0].width * p->levels[0].height));
    r->counts = calloc((size_t)p->ncombos + 3, sizeof *r->counts);
    if (!r->combo_ids || !r->sorted || !r->counts ||
        !rt_bounds_build(&r->bounds, p->heights, p->hf_width, p->hf_height, p->cell_texels,
                         p->max_height, p->height_offset) ||
        !rt_quadtree_init(&r->qt, &r->bounds, p->cell_texels, p->hf_width, p->hf_height, p->size)) {
        rt_renderer_destroy(r);
        return rt_fail(e, RT_E_VULKAN, "renderer", "out of memory");
    }
    for (int L = 0; L < p->nlevels; L++)
        r->combo_ids[L] = p->levels[L].ids;
    r->qt.combo_ids = r->combo_ids;
    /* Split while a grid step would cover more than lod_pixels pixels. */
    double k = r->desc.height / (2.0 * tan(M_PI / 6.0));
    r->lod_distance = k / ((SPLAT_GRID - 1) * r->desc.lod_pixels);

    /* rt_launch_mark: where the first picture's time goes ($SPLAT_LAUNCH_TRACE) */
    if (!rt_terrain_upload(d, p, &r->terrain, e) ||
        !rt_destruction_create(d, p, r->desc.destruction_pool, &r->terrain.height, &r->bounds,
                               &r->destr, e) ||
        !make_targets(r, e) || !rt_launch_mark("terrain and targets") ||
        !rt_pipelines_create(d, p, &r->rp, r->desc.reference, r->desc.pipeline_cache,
                             p->narrays, r->shading_lod, &r->pl, e) ||
        !make_geometry(r, e) || !rt_launch_mark("pipelines and geometry") ||
        !make_textures(r, e) || !rt_launch_mark("textures") || !make_descriptors(r, e) ||
        !make_commands(r, e) || !rt_launch_mark("descriptors, commands") ||
        /* the workers first: the stand-in is chosen with them there */
        (r->set0c && r->desc.async_pipelines &&
         !rt_async_start(d, p, &r->pl, rt_pipelines_compute_make, e)) ||
        !rt_launch_mark("pipeline workers") ||
        !make_fixed_pipelines(r, e) || !rt_launch_mark("fixed pipelines")) {
        rt_renderer_destroy(r);
        return false;
    }
    r->shading = r->screen ? RT_SHADING_SCREEN : RT_SHADING_FORWARD;
    rt_tracker_init(&r->tracker, r->color.img);
    if (r->scale > 1) {
        r->tracker.image[RT_RES_OUTPUT] = r->out.img;
        r->tracker.rest[RT_RES_OUTPUT] = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    }
    *out = r;
    return true;
}

void rt_renderer_destroy(rt_renderer *r)
{
    if (!r)
        return;
    free(r->shadow_map);
    rt_device *d = r->d;
    if (d->dev) {
        vkDeviceWaitIdle(d->dev);
        rt_shadow_gpu_destroy(r->shadow_gpu);
        rt_ug_destroy(r->ug);
        rt_screen_destroy(r->screen);
        rt_far_destroy(r->far);
        rt_pipelines_destroy(d, &r->pl);
        if (r->fence)
            vkDestroyFence(d->dev, r->fence, NULL);
        if (r->qpool)
            vkDestroyQueryPool(d->dev, r->qpool, NULL);
        if (r->cb)
            vkFreeCommandBuffers(d->dev, d->pool, 1, &r->cb);
        if (r->dpool)
            vkDestroyDescriptorPool(d->dev, r->dpool, NULL);
        VkFramebuffer fbs[3] = { r->fb_main, r->fb_multi, r->fb_resolve };
        for (int i = 0; i < 3; i++)
            if (fbs[i])
                vkDestroyFramebuffer(d->dev, fbs[i], NULL);
        VkRenderPass rps[3] = { r->rp.main, r->rp.multi, r->rp.resolve };
        for (int i = 0; i < 3; i++)
            if (rps[i])
                vkDestroyRenderPass(d->dev, rps[i], NULL);
        for (int i = 0; i < r->ntex; i++) {
            rt_image_destroy(d, &r->tex[i]);
            if (r->tex_smp[i])
                vkDestroySampler(d->dev, r->tex_smp[i], NULL);
        }
        rt_upscale_destroy(r->upscale);
        rt_image_destroy(d, &r->out);
        rt_image_destroy(d, &r->color);
        rt_image_destroy(d, &r->depth);
        for (int i = 0; i < 3; i++)
            rt_image_destroy(d, &r->mp[i]);
        rt_buffer_destroy(d, &r->vbuf);
        rt_buffer_destroy(d, &r->ibuf);
        rt_buffer_destroy(d, &r->frame_ubo);
        rt_buffer_destroy(d, &r->params_ubo);
        rt_buffer_destroy(d, &r->readback);
        rt_buffer_destroy(d, &r->counters);
        rt_buffer_destroy(d, &r->counters_host);
        rt_buffer_destroy(d, &r->vectors);
        rt_destruction_destroy(r->destr);
        rt_terrain_destroy(d, &r->terrain);
    }
    rt_quadtree_free(&r->qt);
    rt_bounds_free(&r->bounds);
    free(r->tex);
    free(r->tex_smp);
    free(r->combo_ids);
    free(r->sorted);
    free(r->counts);
    free(r);
}


static bool same_bytes(const void *a, const void *b, size_t n)
{
    return (!a && !b) || (a && b && !memcmp(a, b, n));
}

/* What of the new pack differs from the data the renderer uploaded at
 * creation (heights, bounds, textures and samplers, painted masks,
 * vector shapes, destruction settings, terrain scale), or NULL: only shaders, params and
 * combination ids may change in a hot reload, never old data under new
 * shaders. */
static const char *reload_refused(const rt_pack *o, const rt_pack *p)
{
    if (p->hf_width != o->hf_width || p->hf_height != o->hf_height ||
        p->cell_texels != o->cell_texels || p->nlevels != o->nlevels)
        return "the heightfield's size or cell changed";
    if (!same_bytes(p->heights, o->heights, (size_t)p->hf_width * p->hf_height * 2))
        return "the heightfield's contents changed";
    if (!p->holes != !o->holes ||
        (p->holes && !same_bytes(p->holes, o->holes, (size_t)p->hf_width * p->hf_height)))
        return "the terrain's holes changed";
    if (p->size[0] != o->size[0] || p->size[1] != o->size[1] ||
        p->max_height != o->max_height || p->height_offset != o->height_offset)
        return "the terrain's size, max_height or height_offset changed";
    if (p->ntextures != o->ntextures)
        return "the number of textures changed";
    for (int i = 0; i < p->ntextures; i++) {
        const rt_pack_texture *a = &o->textures[i], *b = &p->textures[i];
        bool same = a->binding == b->binding && a->layer == b->layer &&
                    a->width == b->width && a->height == b->height && a->linear == b->linear &&
                    a->mip_linear == b->mip_linear && a->srgb == b->srgb && a->wrap == b->wrap &&
                    a->nmips == b->nmips &&
                    same_bytes(a->rgba, b->rgba, (size_t)a->width * a->height * 4);
        for (int k = 0; same && k < a->nmips; k++) {
            size_t w = (size_t)(a->width >> (k + 1) > 0 ? a->width >> (k + 1) : 1);
            size_t h = (size_t)(a->height >> (k + 1) > 0 ? a->height >> (k + 1) : 1);
            same = same_bytes(a->mips[k], b->mips[k], w * h * 4);
        }
        if (!same)
            return "a texture (its pixels, mip levels or sampler settings) changed";
    }
    if (p->npainted != o->npainted || !p->sparse != !o->sparse)
        return "the painted masks' count or format changed";
    if (!same_bytes(p->painted, o->painted, (size_t)p->npainted * p->hf_width * p->hf_height))
        return "a painted mask changed";
    if (p->sparse) {
        const sparse_masks *a = o->sparse, *b = p->sparse;
        size_t idx = (size_t)a->cells_x * a->cells_z * 4 * a->layers;
        if (a->format != b->format || a->atlas_cols != b->atlas_cols ||
            a->atlas_rows != b->atlas_rows || a->cells_x != b->cells_x ||
            a->cells_z != b->cells_z || a->layers != b->layers ||
            !same_bytes(a->atlas, b->atlas, a->atlas_bytes) ||
            !same_bytes(a->index, b->index, idx * 2) || !same_bytes(a->level, b->level, idx) ||
            !same_bytes(a->place, b->place, (size_t)a->nmasks * sizeof *a->place))
            return "a painted mask changed";
    }
    if (p->has_destruction != o->has_destruction ||
        (p->has_destruction &&
         (p->destr_origin[0] != o->destr_origin[0] || p->destr_origin[1] != o->destr_origin[1] ||
          p->destr_size[0] != o->destr_size[0] || p->destr_size[1] != o->destr_size[1] ||
          p->destr_cell != o->destr_cell)))
        return "the destructible area changed";
    if (p->nvectors != o->nvectors || !p->vectors != !o->vectors ||
        (p->vectors && !same_bytes(p->vectors, o->vectors, 4 * p->nvectors)))
        return "the spline or polygon shapes changed";
    if (p->params_size > o->params_size)
        return "the params block grew";
    return NULL;
}

bool rt_renderer_swap_pack(rt_renderer *r, const rt_pack *p, rt_error *e)
{
    const rt_pack *o = r->p;
    const char *why = reload_refused(o, p);
    if (why) {
        char msg[256];
        snprintf(msg, sizeof msg, "%s: restart splatview to see it (hot reload swaps shaders and "
                 "parameters, not the data uploaded at start)", why);
        return rt_fail(e, RT_E_RELOAD, msg);
    }
    int *counts = calloc((size_t)p->ncombos + 3, sizeof *counts);
    if (!counts)
        return rt_fail(e, RT_E_RELOAD, "out of memory");
    vkDeviceWaitIdle(r->d->dev);
    /* the workers stop with the old pack's pipelines; new ones for the new */
    bool async = r->pl.async != NULL;
    if (!rt_pipelines_reset_combos(r->d, p, &r->pl, e) ||
        (async && !rt_async_start(r->d, p, &r->pl, rt_pipelines_compute_make, e))) {
        free(counts);
        return false;
    }
    free(r->counts);
    r->counts = counts;
    r->ncombos = p->ncombos;
    for (int L = 0; L < p->nlevels; L++)
        r->combo_ids[L] = p->levels[L].ids;
    write_params(r, p, o->params_size);
    r->p = p;
    if (!r->light_set)
        rt_render_pack_light(r, p);
    bool screen = r->screen != NULL;
    drop_pack_objects(r);
    return make_pack_objects(r, screen, e);
}
