/* render.c — offscreen frames: RGBA32F colour + D32 depth (reversed Z),
 * the quadtree selection per frame, patches grouped by combination and
 * drawn with one pipeline bind per group, camera-relative patch corners
 * computed in double and pushed as floats, GPU time from timestamp
 * queries.  The reference modes draw the same patches with the multi-pass
 * alpha-blended material passes (+ a resolve pass) or the über-shader.
 *
 * Nothing in the frame loop allocates or uploads textures: the per-frame
 * work is the selection (preallocated arrays), a counting sort by
 * combination, a uniform write into mapped memory and one command buffer. */
#include "rt_internal.h"
#include "util.h"
#include "sg.h"     /* sg_suggest: "did you mean" for --param */

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

struct rt_renderer {
    rt_device        *d;
    const rt_pack    *p;
    rt_render_desc    desc;
    rt_light          light;           /* the pack's, or set_light's        */
    bool              light_set;
    bool              shadow_stale;    /* the whole map is to be made       */
    int               shadow_rect[4];  /* texels craters changed since      */
    uint8_t          *shadow_map;      /* the CPU copy of the last map      */
    bool              shadow_on_gpu;   /* marched by shadow_gpu              */
    bool              shadow_auto;     /* the path was not asked for         */
    rt_shadow_gpu    *shadow_gpu;      /* made at the first GPU map          */
    bool              default_clear;   /* no background given: the sky      */
    double            shadow_sun[3];   /* the sun the map was made for      */
    rt_terrain_gpu    terrain;
    rt_destruction   *destr;           /* NULL: no destructible area        */
    rt_bounds         bounds;
    rt_quadtree       qt;
    const uint16_t  **combo_ids;       /* per level, into the pack          */
    int               ncombos;
    rt_buffer         vbuf, ibuf;
    uint32_t          perm_first[RT_PERMS], perm_count[RT_PERMS];
    rt_buffer         frame_ubo, params_ubo, readback;
    rt_buffer         counters;        /* forward counting variant: device  */
    rt_buffer         vectors;         /* the pack's vector shapes (abi.h
                                          SPLAT_BIND_VECTORS), or one word */
    rt_buffer         counters_host;   /* its copy for the host             */
    rt_image         *tex;
    VkSampler        *tex_smp;
    int               ntex;
    rt_image          color, depth, mp[3];
    rt_passes         rp;
    VkFramebuffer     fb_main, fb_multi, fb_resolve;
    rt_pipelines      pl;
    VkDescriptorPool  dpool;
    VkDescriptorSet   set0, set1, set2;
    VkDescriptorSet   set0c;           /* set 0 with the compute bindings   */
    rt_screen        *screen;          /* NULL: forward shading only        */
    rt_far           *far;             /* NULL: no far atlas (far.c)        */
    int               far_patches;     /* forward: the far group, far.c's   */
    int               uber_patches;    /* forward: the last group, nodes no
                                          compiled combination covers
                                          (SPLAT_COMBO_UBER), über-shaded  */
    rt_ug            *ug;              /* NULL: no undergrowth (undergrowth.c) */
    bool              ug_off;          /* not drawn (the viewer's U)        */
    VkCommandBuffer   cb;
    VkFence           fence;
    VkQueryPool       qpool;
    bool              timestamps;
    rt_patch         *sorted;          /* patches grouped by combination    */
    int              *counts;          /* ncombos + 3: the groups, the far
                                          group and the über group          */
    splat_view        view;
    int               view_material;
    bool              wireframe;
    bool              counting;        /* counting variant (stats)          */
    rt_shading        shading;         /* the path in use                   */
    double            lod_distance;
};

/* ---- render passes -------------------------------------------------------- */

static bool make_pass(rt_device *d, uint32_t ncolor, bool depth, VkImageLayout color_final,
                      VkRenderPass *out, rt_error *e)
{
    VkAttachmentDescription att[4];
    VkAttachmentReference cref[3], dref = { ncolor, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    for (uint32_t i = 0; i < ncolor; i++) {
        att[i] = (VkAttachmentDescription){
            .format = VK_FORMAT_R32G32B32A32_SFLOAT,
            .samples = VK_SAMPLE_COUNT_1_BIT,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
            .stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
            .stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
            .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
            .finalLayout = color_final,
        };
        cref[i] = (VkAttachmentReference){ i, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL };
    }
    if (depth)
        att[ncolor] = (VkAttachmentDescription){
            .format = VK_FORMAT_D32_SFLOAT,
            .samples = VK_SAMPLE_COUNT_1_BIT,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,   /* undergrowth tests it */
            .stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE,
            .stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE,
            .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
            .finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
        };
    VkSubpassDescription sub = {
        .pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS,
        .colorAttachmentCount = ncolor,
        .pColorAttachments = cref,
        .pDepthStencilAttachment = depth ? &dref : NULL,
    };
    /* Earlier reads (copies, resolve, viewer) finish before we write again;
     * our writes are visible to whatever reads the targets next. */
    VkSubpassDependency dep[2] = {
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
    VkRenderPassCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO,
        .attachmentCount = ncolor + (depth ? 1 : 0),
        .pAttachments = att,
        .subpassCount = 1,
        .pSubpasses = &sub,
        .dependencyCount = 2,
        .pDependencies = dep,
    };
    RT_VK(e, vkCreateRenderPass(d->dev, &ci, NULL, out));
    return true;
}

static bool make_fb(rt_device *d, VkRenderPass pass, const VkImageView *views, uint32_t n,
                    int w, int h, VkFramebuffer *out, rt_error *e)
{
    VkFramebufferCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO,
        .renderPass = pass,
        .attachmentCount = n,
        .pAttachments = views,
        .width = (uint32_t)w,
        .height = (uint32_t)h,
        .layers = 1,
    };
    RT_VK(e, vkCreateFramebuffer(d->dev, &ci, NULL, out));
    return true;
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
 * levels, one layer each; pack_textures.c checked they are alike. */
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
        VkFilter filt = t->linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
        VkSamplerCreateInfo ci = {
            .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
            .magFilter = filt,
            .minFilter = filt,
            .mipmapMode = t->mip_linear ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST,
            .addressModeU = t->wrap,
            .addressModeV = t->wrap,
            .addressModeW = t->wrap,
            .maxLod = (float)mips,
        };
        RT_VK(e, vkCreateSampler(d->dev, &ci, NULL, &r->tex_smp[a]));
    }
    return true;
}

static bool make_descriptors(rt_renderer *r, rt_error *e)
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
    memset(r->params_ubo.map, 0, p->params_size);
    for (int i = 0; i < p->nparams; i++)
        memcpy((uint8_t *)r->params_ubo.map + p->params[i].offset, p->params[i].value, 16);

    VkDescriptorPoolSize sizes[4] = {
        { VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 3 },
        { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2 * 10 + (uint32_t)r->ntex + 3 },
        { VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1 },
        { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3 + 2 },   /* + the vectors', two sets */
    };
    VkDescriptorPoolCreateInfo pci = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = 4,
        .poolSizeCount = 4,
        .pPoolSizes = sizes,
    };
    RT_VK(e, vkCreateDescriptorPool(d->dev, &pci, NULL, &r->dpool));
    VkDescriptorSetLayout layouts[3] = { r->pl.set_terrain, r->pl.set_material, r->pl.set_resolve };
    VkDescriptorSet sets[3];
    VkDescriptorSetAllocateInfo ai = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = r->dpool,
        .descriptorSetCount = r->desc.reference == RT_REF_MULTIPASS ? 3 : 2,
        .pSetLayouts = layouts,
    };
    RT_VK(e, vkAllocateDescriptorSets(d->dev, &ai, sets));
    r->set0 = sets[0];
    r->set1 = sets[1];
    r->set2 = r->desc.reference == RT_REF_MULTIPASS ? sets[2] : VK_NULL_HANDLE;
    if (r->desc.shading == RT_SHADING_SCREEN) {
        ai.descriptorSetCount = 1;
        RT_VK(e, vkAllocateDescriptorSets(d->dev, &ai, &r->set0c));
    }

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
        vkUpdateDescriptorSets(d->dev, 0, NULL, N, cp);
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
            .queryCount = 4,
        };
        RT_VK(e, vkCreateQueryPool(d->dev, &qi, NULL, &r->qpool));
    }
    return rt_buffer_create(d, (VkDeviceSize)r->desc.width * (VkDeviceSize)r->desc.height * 16,
                            VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &r->readback, e);
}

/* ---- public ---------------------------------------------------------------- */

/* The screen path's depth (rt_screen_depth): ray cast where asked, or by
 * default on GPUs when the terrain has no holes (the ray caster does not
 * cut them). */
static bool use_raycast(const rt_renderer *r)
{
    if (r->desc.screen_depth == RT_DEPTH_RAYCAST)
        return true;
    return r->desc.screen_depth == RT_DEPTH_AUTO && !r->p->holes &&
           r->d->props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
}

static void pack_light(rt_renderer *r, const rt_pack *p);

static bool make_undergrowth(rt_renderer *r, rt_error *e)
{
    if (r->desc.no_undergrowth || r->p->ug.nslots == 0)
        return true;
    rt_ug_targets t = {
        .color = &r->color, .depth = &r->depth, .height = &r->terrain.height,
        .width = r->desc.width, .height_px = r->desc.height,
        .nearest = r->terrain.nearest_clamp, .set0 = r->set0, .timestamps = r->timestamps,
    };
    return rt_ug_create(r->d, r->p, &r->pl, &r->qt, &t, r->desc.undergrowth_radius, &r->ug, e);
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
    pack_light(r, p);
    const char *sh = getenv("SPLAT_SHADOW");   /* cpu | gpu over the default */
    r->shadow_auto = r->desc.shadow == RT_SHADOW_AUTO && !sh;
    if (r->desc.shadow == RT_SHADOW_AUTO)
        r->desc.shadow = sh && !strcmp(sh, "cpu") ? RT_SHADOW_CPU : RT_SHADOW_GPU;
    r->shadow_on_gpu = r->desc.shadow == RT_SHADOW_GPU;
    if (r->desc.width <= 0)
        r->desc.width = 1280;
    if (r->desc.height <= 0)
        r->desc.height = 720;
    if (r->desc.lod_pixels <= 0)
        r->desc.lod_pixels = 3.0;
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

    if (!rt_terrain_upload(d, p, &r->terrain, e) ||
        !rt_destruction_create(d, p, r->desc.destruction_pool, &r->terrain.height, &r->bounds,
                               &r->destr, e) ||
        !make_targets(r, e) ||
        !rt_pipelines_create(d, p, &r->rp, r->desc.reference, r->desc.pipeline_cache,
                             p->narrays, &r->pl, e) ||
        !make_geometry(r, e) || !make_textures(r, e) || !make_descriptors(r, e) ||
        !make_commands(r, e) || !rt_far_create(d, p, &r->pl, &r->far, e) ||
        (r->set0c && !rt_screen_create(d, p, &r->pl, &r->color, &r->depth,
                                       r->terrain.nearest_clamp, r->set0c, r->far, use_raycast(r),
                                       r->desc.pixel_sort, r->desc.sort_tiles, &r->screen, e))) {
        rt_renderer_destroy(r);
        return false;
    }
    if (r->screen && r->desc.async_pipelines && !rt_async_start(d, p, &r->pl, e)) {
        rt_renderer_destroy(r);
        return false;
    }
    if (r->screen) {
        rt_screen_far(r->screen, r->desc.far_atlas_distance);
        r->pl.sort_tiles = rt_screen_sort_tiles(r->screen);
    }
    r->shading = r->screen ? RT_SHADING_SCREEN : RT_SHADING_FORWARD;
    if (!make_undergrowth(r, e)) {
        rt_renderer_destroy(r);
        return false;
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

void rt_default_camera(const rt_pack *p, rt_camera *c)
{
    memset(c, 0, sizeof *c);
    /* The scene's own overview: its preset named "overview", else its first
     * preset (the scene's author knows where the terrain is worth seeing). */
    int k = rt_pack_camera_find(p, "overview");
    if (k < 0 && p->ncameras > 0)
        k = 0;
    if (k >= 0) {
        memcpy(c->position, p->cameras[k].position, sizeof c->position);
        memcpy(c->look, p->cameras[k].look, sizeof c->look);
        return;
    }
    /* Else from the south (z large: row 0 is north), 30 degrees down onto
     * the centre from a quarter of the extent: the default fog without
     * presets (1.5 / extent, rt_light_fog_default) hides about 31 % there
     * and less in front, where a camera seeing the whole terrain would see
     * mostly fog.
     * Never below the highest point. */
    double sx = p->size[0], sz = p->size[1], ext = sx > sz ? sx : sz;
    double top = p->height_offset + p->max_height, d = 0.25 * ext;
    c->look[0] = 0.5 * sx;
    c->look[1] = p->height_offset + 0.5 * p->max_height;
    c->look[2] = 0.5 * sz;
    c->position[0] = c->look[0];
    c->position[1] = c->look[1] + 0.5 * d;            /* sin 30 */
    c->position[2] = c->look[2] + 0.8660254037844386 * d;
    if (c->position[1] < top + 0.02 * ext)
        c->position[1] = top + 0.02 * ext;
}

void rt_renderer_set_view(rt_renderer *r, splat_view view, int material)
{
    r->view = view;
    r->view_material = material;
}

void rt_renderer_set_counting(rt_renderer *r, bool on) { r->counting = on; }

bool rt_renderer_set_shading(rt_renderer *r, rt_shading s)
{
    if (s == RT_SHADING_SCREEN && !r->screen)
        return false;
    r->shading = s;
    return true;
}

rt_shading rt_renderer_shading(const rt_renderer *r) { return r->shading; }

/* The pack's light with the desc's overrides. */
static void pack_light(rt_renderer *r, const rt_pack *p)
{
    r->light = p->light;
    if (r->desc.sun_set)
        memcpy(r->light.sun, r->desc.sun, sizeof r->light.sun);
    if (r->desc.exposure_set)
        r->light.exposure = r->desc.exposure;
    if (r->desc.fog_set)
        r->light.fog_density = r->desc.fog_density;
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++)
        if (r->desc.light_keys & (1u << k))
            memcpy(rt_light_values(&r->light, k), r->desc.light[k],
                   (size_t)splat_light_keys[k].n * sizeof(double));
}

void rt_renderer_set_light(rt_renderer *r, const rt_light *l)
{
    r->light = *l;
    r->light_set = true;
}

void rt_renderer_set_shadows(rt_renderer *r, bool on)
{
    r->desc.no_shadows = !on;
}

const rt_light *rt_renderer_light(const rt_renderer *r)
{
    return &r->light;
}

void rt_renderer_set_wireframe(rt_renderer *r, bool on)
{
    if (on && !r->d->wireframe) {
        fprintf(stderr, "splatrt: wireframe unavailable (no fillModeNonSolid)\n");
        on = false;
    }
    r->wireframe = on;
}

/* A param by its full name ("snowcap.snowline"), or, failing that, by the
 * name after its material's ("snowline") when one material has it. */
static int find_param(const rt_pack *p, const char *name, int *nsuffix)
{
    int found = -1;
    *nsuffix = 0;
    for (int i = 0; i < p->nparams; i++)
        if (!strcmp(p->params[i].name, name))
            return i;
    for (int i = 0; i < p->nparams; i++) {
        const char *dot = strchr(p->params[i].name, '.');
        if (dot && !strcmp(dot + 1, name)) {
            found = i;
            (*nsuffix)++;
        }
    }
    return -1 - found;   /* <= -1: not found; -1 - index of a short match */
}

bool rt_renderer_set_param(rt_renderer *r, const char *name, const float value[4], rt_error *e)
{
    char what[512];
    int nsuffix;
    int i = find_param(r->p, name, &nsuffix);
    if (i >= 0) {
        const rt_pack_param *pp = &r->p->params[i];
        for (int k = 0; pp->has_range && k < pp->width; k++)
            if (!(value[k] >= pp->min && value[k] <= pp->max)) {
                /* the pack's combinations were culled for values in the range */
                snprintf(what, sizeof what, "param '%s' = %g is outside its declared range "
                         "[%g, %g] (the pack was analysed for that range; widen `range` in "
                         "the material and rebuild)", name, (double)value[k], pp->min, pp->max);
                return rt_fail(e, RT_E_PACK_FIELD, r->p->dir, what);
            }
        memcpy((uint8_t *)r->params_ubo.map + pp->offset, value, 16);
        rt_ug_invalidate(r->ug, NULL);   /* the masks may have changed */
        return true;
    }
    const char *near = NULL;
    if (nsuffix == 1) {
        near = r->p->params[-1 - i].name;
    } else {
        sg_suggest sg;
        sg_suggest_init(&sg, name);
        for (int k = 0; k < r->p->nparams; k++)
            sg_suggest_offer(&sg, r->p->params[k].name);
        near = sg_suggest_best(&sg);
    }
    if (near)
        snprintf(what, sizeof what, "no param named '%s'; did you mean '%s'?", name, near);
    else if (nsuffix > 1)
        snprintf(what, sizeof what, "no param named '%s' (%d materials have one: write "
                 "MATERIAL.%s)", name, nsuffix, name);
    else
        snprintf(what, sizeof what, "no param named '%s' (the pack has %d param%s%s%s)", name,
                 r->p->nparams, r->p->nparams == 1 ? "" : "s",
                 r->p->nparams ? ", e.g. " : "", r->p->nparams ? r->p->params[0].name : "");
    return rt_fail(e, RT_E_PACK_FIELD, r->p->dir, what);
}

const rt_image *rt_renderer_target(const rt_renderer *r) { return &r->color; }

/* Camera-relative view-projection: rotation only (positions reach the GPU
 * relative to the camera), perspective with reversed infinite Z and
 * Vulkan's downward y.  Column-major. */
double rt_camera_fovy(const rt_camera *c)
{
    return c->fovy > 0 ? c->fovy : M_PI / 3.0;
}

static void camera_matrix(const rt_camera *c, double aspect, double m[16])
{
    double f[3], len = 0;
    for (int i = 0; i < 3; i++) {
        f[i] = c->look[i] - c->position[i];
        len += f[i] * f[i];
    }
    len = sqrt(len);
    if (len <= 0) {
        f[0] = 0; f[1] = 0; f[2] = -1; len = 1;
    }
    for (int i = 0; i < 3; i++)
        f[i] /= len;
    double up[3] = { 0, 1, 0 };
    if (fabs(f[1]) > 0.999) {
        up[1] = 0;
        up[2] = -1;
    }
    double s[3] = { f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0] };
    double sl = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; i++)
        s[i] /= sl;
    double u[3] = { s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0] };
    double fovy = rt_camera_fovy(c);
    double znear = c->znear > 0 ? c->znear : 0.25;
    double t = 1.0 / tan(fovy / 2.0);
    /* rows of view: s, u, -f; clip = P * view */
    double v[3][3] = { { s[0], s[1], s[2] }, { u[0], u[1], u[2] }, { -f[0], -f[1], -f[2] } };
    memset(m, 0, 16 * sizeof *m);
    for (int col = 0; col < 3; col++) {
        m[col * 4 + 0] = t / aspect * v[0][col];
        m[col * 4 + 1] = -t * v[1][col];
        m[col * 4 + 2] = 0.0;
        m[col * 4 + 3] = -v[2][col];
    }
    m[3 * 4 + 2] = znear;
}

/* Gauss-Jordan with partial pivoting, column-major 4x4, in double. */
static void invert4(const double m[16], double out[16])
{
    double a[4][8];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            a[r][c] = m[c * 4 + r];
            a[r][4 + c] = r == c;
        }
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        for (int k = 0; k < 8; k++) {
            double t = a[c][k];
            a[c][k] = a[piv][k];
            a[piv][k] = t;
        }
        double d = a[c][c];
        for (int k = 0; k < 8; k++)
            a[c][k] /= d;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double f = a[r][c];
                for (int k = 0; k < 8; k++)
                    a[r][k] -= f * a[c][k];
            }
    }
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            out[c * 4 + r] = a[r][4 + c];
}

/* The analytic sky (abi.c splat_sky) is the background of the final view
 * unless the caller gave a background colour. */
static bool sky_drawn(const rt_renderer *r)
{
    return r->default_clear && r->view == SPLAT_VIEW_FINAL && !r->wireframe;
}

static void fill_frame(rt_renderer *r, const rt_camera *c, splat_frame *fr)
{
    const rt_pack *p = r->p;
    memset(fr, 0, sizeof *fr);
    double vp[16], inv[16];
    camera_matrix(c, (double)r->desc.width / r->desc.height, vp);
    invert4(vp, inv);
    for (int i = 0; i < 16; i++) {
        fr->view_proj[i] = (float)vp[i];
        fr->inv_view_proj[i] = (float)inv[i];
    }
    fr->screen[0] = (float)r->desc.width;
    fr->screen[1] = (float)r->desc.height;
    fr->screen[2] = 0.0f;   /* the depth clear value (reversed Z) */
    fr->screen[3] = (float)(2.0 * tan(rt_camera_fovy(c) / 2.0) / r->desc.height);
    for (int i = 0; i < 3; i++)
        fr->camera[i] = (float)c->position[i];
    rt_light_frame(&r->light, p, r->desc.clear, fr);
    fr->light[3] = r->desc.no_shadows ? 0.0f : 1.0f;
    fr->sky_color[3] = sky_drawn(r) ? 1.0f : 0.0f;
    fr->terrain[0] = (float)p->size[0];
    fr->terrain[1] = (float)p->size[1];
    fr->terrain[2] = (float)p->max_height;
    fr->terrain[3] = (float)p->height_offset;
    fr->texel[0] = (float)p->hf_width;
    fr->texel[1] = (float)p->hf_height;
    fr->texel[2] = 1.0f / (float)p->hf_width;
    fr->texel[3] = 1.0f / (float)p->hf_height;
    fr->destruction_atlas[0] = 64.0f;
    fr->destruction_atlas[1] = 1.0f;
    fr->destruction_atlas[2] = 1.0f;
    if (r->destr)
        rt_destruction_frame(r->destr, fr);
    /* precision far from the origin (compiler/precision.c): per site, the
     * camera's whole cells and fraction in double; the scale as the
     * shader reads it (float) */
    for (int k = 0; k < p->nsites; k++) {
        const rt_pack_site *st = &p->sites[k];
        for (int a = 0; a < 2; a++) {
            double s = st->param >= 0
                ? (double)*(const float *)((const uint8_t *)r->params_ubo.map +
                                           p->params[st->param].offset)
                : (double)(float)st->scale[a];
            double v = st->mul ? c->position[st->axes[a]] * s : c->position[st->axes[a]] / s;
            double cell = floor(v);
            fr->world[4 * k + a] = (float)cell;
            fr->world[4 * k + 2 + a] = (float)(v - cell);
        }
    }
    fr->view[0] = (uint32_t)r->view;
    fr->view[1] = (uint32_t)(r->view_material > 0 ? r->view_material : 0);
}

/* A patch's push constants: its corner and side on the vertex lattice
 * and the camera's lattice point and offset from it (abi.h splat_push),
 * all in double here.  Every lattice index is whole, so neighbouring
 * patches compute their shared vertices from the same numbers. */
static void push_patch(rt_renderer *r, VkCommandBuffer cb, VkPipelineLayout layout,
                       const rt_camera *c, const rt_patch *pt)
{
    const rt_pack *p = r->p;
    const double texels = (double)r->qt.cell_texels * (double)(1 << pt->level);
    const double width[2] = { (double)p->hf_width, (double)p->hf_height };
    const double cam[2] = { c->position[0], c->position[2] };
    const int idx[2] = { pt->x, pt->z };
    splat_push push;
    for (int a = 0; a < 2; a++) {
        /* the step as the vertex stage computes it (terrain * texel /
         * lattice, floats), so the offset and the steps agree */
        double step = (double)((float)p->size[a] * (1.0f / (float)width[a])) / SPLAT_LATTICE;
        /* the camera's lattice point, kept where floats hold whole numbers */
        double at = fmin(fmax(floor(cam[a] / step), -8388608.0), 8388608.0);
        push.patch_xz[a] = (float)(idx[a] * texels * SPLAT_LATTICE);
        push.patch_uv[a] = (float)at;
        push.patch_uv[2 + a] = (float)(cam[a] - at * step);
    }
    push.patch_xz[2] = (float)(texels * SPLAT_LATTICE);
    push.patch_xz[3] = 0.0f;
    push.info[0] = pt->level;
    push.info[1] = pt->combo;
    push.info[2] = (uint32_t)p->nmaterials;
    push.info[3] = 0;
    vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof push, &push);
}

/* Back faces may be culled without changing a pixel when the camera is
 * above the terrain mesh at its own position: the mesh is a continuous
 * height function over the (convex) footprint, so a ray from there meets a
 * face from above before it can meet one from below, and that nearer face
 * hides it (only where depth rounding let a back face win a near tie at a
 * ridge does a pixel change: colorado, 3 to 6 pixels per 1280x720 view,
 * by at most 0.005).  The mesh under the camera is the selected node containing it
 * (drawn or frustum-culled), whose vertices sample no texel above the
 * node's bound (rt_bounds).  Call after selection. */
static bool camera_above_terrain(const rt_renderer *r, const rt_camera *c)
{
    const rt_quadtree *q = &r->qt;
    double x = c->position[0], z = c->position[2];
    if (!(x >= 0 && z >= 0 && x <= q->size[0] && z <= q->size[1]))
        return false;
    int L = q->nlevels - 1, nx = 0, nz = 0;
    while (L > 0 && q->split[L][(size_t)nz * (size_t)q->width[L] + (size_t)nx]) {
        /* the child containing the camera (the last one on a shared edge) */
        int cx = 2 * nx, cz = 2 * nz;
        double x0, z0, sx, sz;
        rt_node_rect(q, L - 1, cx + 1, cz + 1, &x0, &z0, &sx, &sz);
        if (x >= x0 && cx + 1 < q->width[L - 1])
            cx++;
        if (z >= z0 && cz + 1 < q->height[L - 1])
            cz++;
        L--;
        nx = cx;
        nz = cz;
    }
    double top = r->bounds.hmax[L][(size_t)nz * (size_t)r->bounds.width[L] + (size_t)nx];
    /* a margin for the float rounding of the vertex heights */
    double margin = 1e-4 * (fabs(r->p->max_height) + fabs(r->p->height_offset)) + 1e-3;
    return c->position[1] > top + margin;
}

static void draw_patches(rt_renderer *r, VkCommandBuffer cb, const rt_camera *c,
                         const rt_patch *pts, int n)
{
    for (int i = 0; i < n; i++) {
        push_patch(r, cb, r->pl.layout, c, &pts[i]);
        vkCmdDrawIndexed(cb, r->perm_count[pts[i].perm], 1, r->perm_first[pts[i].perm], 0, 0);
    }
}

/* Begin the pass `rb` over the whole target and bind what every terrain
 * draw reads: sets 0 and 1, the grid's vertex and index buffers. */
static void begin_terrain_pass(rt_renderer *r, VkCommandBuffer cb,
                               const VkRenderPassBeginInfo *rb, const VkViewport *vp,
                               const VkDescriptorSet *sets)
{
    VkDeviceSize zero = 0;
    vkCmdBeginRenderPass(cb, rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdSetViewport(cb, 0, 1, vp);
    vkCmdSetScissor(cb, 0, 1, &rb->renderArea);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pl.layout, 0, 2, sets, 0, NULL);
    vkCmdBindVertexBuffers(cb, 0, 1, &r->vbuf.buf, &zero);
    vkCmdBindIndexBuffer(cb, r->ibuf.buf, 0, VK_INDEX_TYPE_UINT16);
}

/* A pipeline could not be made mid-pass: end the pass and the command
 * buffer (reset by the next frame).  Returns false for the caller. */
static bool abandon_frame(VkCommandBuffer cb)
{
    vkCmdEndRenderPass(cb);
    vkEndCommandBuffer(cb);
    return false;
}

/* The variant of the compute shading pipelines this frame needs. */
static unsigned compute_variant(const rt_renderer *r)
{
    return (r->view != SPLAT_VIEW_FINAL ? RT_CVARIANT_DEBUG : 0) |
           (r->counting || r->view == SPLAT_VIEW_COST ? RT_CVARIANT_COUNT : 0) |
           (r->screen && rt_screen_sorting(r->screen) ? RT_CVARIANT_SORT : 0);
}

/* The screen-space path (screen.c): the geometry pass draws the patches
 * depth only, then classification and one dispatch per combination. */
static bool record_screen(rt_renderer *r, VkCommandBuffer cb, const rt_camera *c,
                          const VkViewport *vp, const VkRect2D *area, bool cull, int *binds,
                          rt_error *e)
{
    unsigned cv = compute_variant(r);
    rt_screen_begin(r->screen, cb, (cv & RT_CVARIANT_COUNT) != 0);
    VkFramebuffer fb;
    VkRenderPass pass = rt_screen_depth_pass(r->screen, &fb);
    VkClearValue clear = { .depthStencil = { 0.0f, 0 } };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = pass, .framebuffer = fb,
        .renderArea = *area, .clearValueCount = 1, .pClearValues = &clear,
    };
    VkDescriptorSet sets[2] = { r->set0, r->set1 };
    if (rt_screen_raycasting(r->screen)) {
        rt_screen_raycast(r->screen, cb, r->set0c);
        (*binds)++;
    } else {
        begin_terrain_pass(r, cb, &rb, vp, sets);
        int n = r->qt.npatches;
        if (n > 0) {
            VkPipeline pipe;
            if (!rt_pipelines_depth(r->d, &r->pl, pass, cull, &pipe, e))
                return abandon_frame(cb);
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
            (*binds)++;
            draw_patches(r, cb, c, r->sorted, n);
        }
        vkCmdEndRenderPass(cb);
    }
    if (r->timestamps)
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r->qpool, 1);
    rt_screen_classify(r->screen, cb, r->set0c, r->desc.clear,
                       r->desc.reference == RT_REF_UBER || r->view == SPLAT_VIEW_MASK,
                       r->desc.no_distance_classes, binds);
    if (r->timestamps)
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, r->qpool, 2);
    VkDescriptorSet csets[2] = { r->set0c, r->set1 };
    if (!rt_screen_dispatch(r->screen, cb, &r->pl, csets, cv, r->pl.async != NULL, binds, e)) {
        vkEndCommandBuffer(cb);
        return false;
    }
    return true;
}

/* Distance classes on the forward path (PACK.md): the cheapest class of
 * combination `combo` whose interval holds the patch's whole distance
 * range (its node's box, widened by RT_DCLASS_SLACK), else `combo`. */
static int class_pick(const rt_pack *p, int combo, const rt_quadtree *q, const rt_patch *pt,
                      const double camera[3])
{
    const rt_pack_combo *c = &p->combos[combo];
    if (c->nclasses == 0)
        return combo;
    double dmin, dmax;
    rt_node_distance(q, pt->level, pt->x, pt->z, camera, &dmin, &dmax);
    dmin *= 1 - RT_DCLASS_SLACK;
    dmax *= 1 + RT_DCLASS_SLACK;
    int best = combo;
    for (int k = c->first_class; k < c->first_class + c->nclasses; k++)
        if (p->combos[k].dlo <= dmin && dmax <= p->combos[k].dhi &&
            p->combos[k].cost < p->combos[best].cost)
            best = k;
    return best;
}

/* The far atlas on the forward path (far.c): a patch whose node's box is
 * wholly at least `distance` away and misses the destructible area
 * (craters change what the bake saw), as the screen path's tiles. */
static bool patch_far(const rt_renderer *r, const rt_patch *pt, const double camera[3],
                      double distance)
{
    double dmin, dmax, x0, z0, sx, sz;
    rt_node_distance(&r->qt, pt->level, pt->x, pt->z, camera, &dmin, &dmax);
    if (dmin < distance)
        return false;
    const rt_pack *p = r->p;
    if (!p->has_destruction)
        return true;
    rt_node_rect(&r->qt, pt->level, pt->x, pt->z, &x0, &z0, &sx, &sz);
    return x0 + sx <= p->destr_origin[0] || p->destr_origin[0] + p->destr_size[0] <= x0 ||
           z0 + sz <= p->destr_origin[1] || p->destr_origin[1] + p->destr_size[1] <= z0;
}

/* The quadtree selection, then the patches sorted by combination (a
 * counting sort: one pipeline bind per group); returns how many
 * combinations are in view.  Afterwards counts[k] ends group k, which
 * starts at counts[k-1] (0 for k = 0); with `far`, group ncombos holds
 * the patches shaded from the far atlas (r->far_patches of them), and
 * group ncombos + 1 the coarse patches that no compiled combination
 * covers (SPLAT_COMBO_UBER: the pack compiles leaf cells' combinations
 * only), drawn with the über-shader (r->uber_patches of them). */
static int select_and_sort(rt_renderer *r, const rt_camera *c, const splat_frame *fr, bool far,
                           bool split, double *select_ms)
{
    /* coarse nodes without a combination: the über-shader draws them (the
     * last group below), or with `split` they are split down to covered
     * nodes, except those far enough for the far atlas */
    rt_select_desc sd = { .lod_distance = r->lod_distance, .cull = true,
                          .split_uncovered = split,
                          .uncovered_far = far ? r->desc.far_atlas_distance : 0.0 };
    memcpy(sd.camera, c->position, sizeof sd.camera);
    memcpy(sd.view_proj, fr->view_proj, sizeof sd.view_proj);
    double ts = 1e3 * splat_now();
    rt_quadtree_select(&r->qt, &sd);
    *select_ms = 1e3 * splat_now() - ts;
    int n = r->qt.npatches;
    if (!r->desc.no_distance_classes)
        for (int i = 0; i < n; i++)
            if (r->qt.patches[i].combo < r->ncombos)
                r->qt.patches[i].combo = (uint16_t)class_pick(
                    r->p, r->qt.patches[i].combo, &r->qt, &r->qt.patches[i], c->position);
    for (int i = 0; far && i < n; i++)
        if (patch_far(r, &r->qt.patches[i], c->position, r->desc.far_atlas_distance))
            r->qt.patches[i].combo = (uint16_t)r->ncombos;
    for (int i = 0; i < n; i++)
        if (r->qt.patches[i].combo == SPLAT_COMBO_UBER)
            r->qt.patches[i].combo = (uint16_t)(r->ncombos + 1);
    memset(r->counts, 0, sizeof *r->counts * (size_t)(r->ncombos + 3));
    for (int i = 0; i < n; i++)
        r->counts[r->qt.patches[i].combo + 1]++;
    r->far_patches = r->counts[r->ncombos + 1];
    r->uber_patches = r->counts[r->ncombos + 2];
    int in_view = 0;
    for (int k = 0; k <= r->ncombos + 1; k++) {
        in_view += k < r->ncombos && r->counts[k + 1] > 0;
        r->counts[k + 1] += r->counts[k];
    }
    for (int i = 0; i < n; i++)
        r->sorted[r->counts[r->qt.patches[i].combo]++] = r->qt.patches[i];
    return in_view;
}

/* The multi-pass reference: each material blended over every patch,
 * bottom to top, then the resolve pass lights the blended surface. */
static bool record_multipass(rt_renderer *r, VkCommandBuffer cb, const rt_camera *c,
                             const VkViewport *vp, const VkRect2D *area, bool cull, int *binds,
                             rt_error *e)
{
    VkClearValue clears[4];
    VkDescriptorSet sets[3] = { r->set0, r->set1, r->set2 };
    for (int i = 0; i < 3; i++)
        clears[i].color = (VkClearColorValue){ { 0, 0, 0, 0 } };
    clears[3].depthStencil = (VkClearDepthStencilValue){ 0.0f, 0 };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = r->rp.multi, .framebuffer = r->fb_multi,
        .renderArea = *area, .clearValueCount = 4, .pClearValues = clears,
    };
    begin_terrain_pass(r, cb, &rb, vp, sets);
    for (int m = 0; m < r->pl.nref; m++) {
        VkPipeline pipe;
        if (!rt_pipelines_ref(r->d, r->p, &r->rp, &r->pl, m, cull, &pipe, e))
            return abandon_frame(cb);
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
        (*binds)++;
        draw_patches(r, cb, c, r->sorted, r->qt.npatches);
    }
    vkCmdEndRenderPass(cb);
    clears[0].color = (VkClearColorValue){ { r->desc.clear[0], r->desc.clear[1], r->desc.clear[2], 1 } };
    rb.renderPass = r->rp.resolve;
    rb.framebuffer = r->fb_resolve;
    rb.clearValueCount = 1;
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdSetViewport(cb, 0, 1, vp);
    vkCmdSetScissor(cb, 0, 1, area);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pl.resolve);
    (*binds)++;
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pl.resolve_layout, 0, 3, sets, 0, NULL);
    splat_push none;
    memset(&none, 0, sizeof none);
    vkCmdPushConstants(cb, r->pl.resolve_layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof none, &none);
    vkCmdDraw(cb, 3, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    return true;
}

/* The forward path's counters: zeroed before the pass, copied back after. */
static void count_begin(rt_renderer *r, VkCommandBuffer cb)
{
    vkCmdFillBuffer(cb, r->counters.buf, 0, sizeof(splat_counters), 0);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

static void count_end(rt_renderer *r, VkCommandBuffer cb)
{
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy c = { 0, 0, sizeof(splat_counters) };
    vkCmdCopyBuffer(cb, r->counters.buf, r->counters_host.buf, 1, &c);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

/* The composites this frame draws that are not made yet, made first on all
 * cores (jobs.c; each has its own slot), so a cold view pays glslang and
 * the driver's compiler in parallel rather than one after the other. */
static bool make_forward_pipelines(rt_renderer *r, unsigned variant, rt_error *e)
{
    int n = 0, start = 0;
    for (int k = 0; k < r->ncombos; start = r->counts[k++])
        n += r->counts[k] > start && !rt_pipelines_has_combo(&r->pl, k, variant);
    if (n == 0)   /* the usual frame: nothing to make, nothing allocated */
        return true;
    int *ids = malloc((size_t)n * sizeof *ids);
    if (!ids)
        return rt_fail(e, RT_E_VULKAN, "forward path", "out of memory");
    n = start = 0;
    for (int k = 0; k < r->ncombos; start = r->counts[k++])
        if (r->counts[k] > start && !rt_pipelines_has_combo(&r->pl, k, variant))
            ids[n++] = k;
    bool ok = rt_pipelines_make(r->d, r->p, &r->rp, &r->pl, false, ids, n, variant, e);
    free(ids);
    return ok;
}

/* The forward path: each group of patches with its composite (or every
 * patch with the über-shader: --reference uber, and the MASK view, which
 * composites do not carry: compiler/build_jobs.c). */
static bool record_forward(rt_renderer *r, VkCommandBuffer cb, const rt_camera *c,
                           const VkViewport *vp, const VkRect2D *area, unsigned variant,
                           int *binds, rt_error *e)
{
    VkClearValue clears[2];
    VkDescriptorSet sets[2] = { r->set0, r->set1 };
    clears[0].color = (VkClearColorValue){ { r->desc.clear[0], r->desc.clear[1], r->desc.clear[2], 1 } };
    clears[1].depthStencil = (VkClearDepthStencilValue){ 0.0f, 0 };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = r->rp.main, .framebuffer = r->fb_main,
        .renderArea = *area, .clearValueCount = 2, .pClearValues = clears,
    };
    bool composites = r->desc.reference != RT_REF_UBER && r->view != SPLAT_VIEW_MASK;
    if (composites && !make_forward_pipelines(r, variant, e)) {
        vkEndCommandBuffer(cb);   /* no pass begun yet */
        return false;
    }
    if (variant & RT_VARIANT_COUNT)
        count_begin(r, cb);
    begin_terrain_pass(r, cb, &rb, vp, sets);
    int n = r->qt.npatches;
    if (!composites) {
        if (n > 0) {
            VkPipeline pipe;
            if (!rt_pipelines_uber(r->d, r->p, &r->rp, &r->pl, variant, &pipe, e))
                return abandon_frame(cb);
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
            (*binds)++;
        }
        draw_patches(r, cb, c, r->sorted, n);
    } else {
        int start = 0;
        for (int k = 0; k < r->ncombos; k++) {
            int end = r->counts[k];
            if (end > start) {
                VkPipeline pipe;
                if (!rt_pipelines_combo(r->d, r->p, &r->rp, &r->pl, k, variant, &pipe, e))
                    return abandon_frame(cb);
                vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
                (*binds)++;
                draw_patches(r, cb, c, r->sorted + start, end - start);
            }
            start = end;
        }
        if (r->far_patches > 0) {   /* the far group (select_and_sort) */
            if (!rt_far_bind_forward(r->far, r->p, &r->rp, &r->pl, cb, variant, e))
                return abandon_frame(cb);
            (*binds)++;
            draw_patches(r, cb, c, r->sorted + start, r->far_patches);
        }
        start += r->far_patches;
        if (r->uber_patches > 0) {  /* no combination covers them: last */
            VkPipeline pipe;
            if (!rt_pipelines_uber(r->d, r->p, &r->rp, &r->pl, variant, &pipe, e))
                return abandon_frame(cb);
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
            (*binds)++;
            draw_patches(r, cb, c, r->sorted + start, r->uber_patches);
        }
    }
    if (sky_drawn(r)) {   /* where no terrain wrote depth */
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pl.sky);
        (*binds)++;
        vkCmdDraw(cb, 3, 1, 0, 0);
    }
    vkCmdEndRenderPass(cb);
    if (variant & RT_VARIANT_COUNT)
        count_end(r, cb);
    return true;
}

/* GPU times from the timestamps: the whole frame, and on the screen path
 * its three passes (queries 0 top, 1 after the depth, 2 after the
 * classification, 3 bottom). */
static bool read_times(rt_renderer *r, bool screen, rt_frame_stats *st, rt_error *e)
{
    rt_device *d = r->d;
    st->gpu_ms = -1;
    for (int i = 0; i < 3; i++)
        st->pass_ms[i] = -1;
    if (!r->timestamps)
        return true;
    double ms = d->props.limits.timestampPeriod * 1e-6;
    const VkQueryResultFlags fl = VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT;
    uint64_t q[4];
    if (screen) {
        RT_VK(e, vkGetQueryPoolResults(d->dev, r->qpool, 0, 4, sizeof q, q, sizeof q[0], fl));
        for (int i = 0; i < 3; i++)
            st->pass_ms[i] = (double)(q[i + 1] - q[i]) * ms;
    } else {
        RT_VK(e, vkGetQueryPoolResults(d->dev, r->qpool, 0, 1, sizeof q[0], &q[0], sizeof q[0], fl));
        RT_VK(e, vkGetQueryPoolResults(d->dev, r->qpool, 3, 1, sizeof q[3], &q[3], sizeof q[3], fl));
    }
    st->gpu_ms = (double)(q[3] - q[0]) * ms;
    return true;
}

static bool draw_frame(rt_renderer *r, const rt_camera *c, rt_frame_stats *st, rt_error *e)
{
    rt_device *d = r->d;
    double t0 = 1e3 * splat_now(), select_ms;
    splat_frame *fr = r->frame_ubo.map;
    fill_frame(r, c, fr);
    bool screen = r->screen && r->shading == RT_SHADING_SCREEN &&
                  r->desc.reference != RT_REF_MULTIPASS && !r->wireframe;
    /* the far atlas on the forward path: composites only (not the
     * references, not the mask view, which the über-shader draws) */
    bool far = !screen && r->far && r->desc.far_atlas_distance > 0 &&
               r->desc.reference == RT_REF_NONE && r->view != SPLAT_VIEW_MASK;
    /* split_uncovered is the forward path's: the screen path classifies
     * its tiles from leaf cells whatever the patches */
    int in_view = select_and_sort(r, c, fr, far, !screen && r->desc.split_uncovered,
                                  &select_ms);

    VkCommandBuffer cb = r->cb;
    RT_VK(e, vkResetCommandBuffer(cb, 0));
    VkCommandBufferBeginInfo bi = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    RT_VK(e, vkBeginCommandBuffer(cb, &bi));
    if (r->timestamps) {
        vkCmdResetQueryPool(cb, r->qpool, 0, 4);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, r->qpool, 0);
    }
    VkViewport vp = { 0, 0, (float)r->desc.width, (float)r->desc.height, 0, 1 };
    VkRect2D area = { { 0, 0 }, { (uint32_t)r->desc.width, (uint32_t)r->desc.height } };
    int binds = 0;
    bool ug = r->ug && !r->ug_off && r->view == SPLAT_VIEW_FINAL && !r->wireframe;
    if (ug && !rt_ug_generate(r->ug, cb, c, fr, r->set1, 0, e))
        return abandon_frame(cb);
    bool cull = !r->desc.no_cull && camera_above_terrain(r, c);
    /* the multi-pass reference has no counting variant */
    bool count = (r->counting || r->view == SPLAT_VIEW_COST) && !screen &&
                 r->d->count_fragments && r->desc.reference != RT_REF_MULTIPASS;
    unsigned variant = (r->wireframe ? RT_VARIANT_WIRE : 0) |
                       (r->view != SPLAT_VIEW_FINAL ? RT_VARIANT_DEBUG : 0) |
                       (cull ? RT_VARIANT_CULL : 0) | (count ? RT_VARIANT_COUNT : 0);
    bool ok = screen ? record_screen(r, cb, c, &vp, &area, cull, &binds, e)
            : r->desc.reference == RT_REF_MULTIPASS
                     ? record_multipass(r, cb, c, &vp, &area, cull, &binds, e)
                     : record_forward(r, cb, c, &vp, &area, variant, &binds, e);
    if (!ok)
        return false;
    bool ug_draw = ug && rt_ug_visible(r->ug);
    if (ug_draw && screen && rt_screen_raycasting(r->screen))
        rt_screen_depth_out(r->screen, cb, &r->depth);
    if (ug_draw)
        rt_ug_draw(r->ug, cb, screen, r->set0, r->set1, &vp, &area);
    if (r->timestamps)
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r->qpool, 3);
    RT_VK(e, vkEndCommandBuffer(cb));
    VkSubmitInfo si = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .commandBufferCount = 1,
        .pCommandBuffers = &cb,
    };
    double cpu_ms = 1e3 * splat_now() - t0;
    RT_VK(e, vkQueueSubmit(d->queue, 1, &si, r->fence));
    RT_VK(e, vkWaitForFences(d->dev, 1, &r->fence, VK_TRUE, UINT64_MAX));
    RT_VK(e, vkResetFences(d->dev, 1, &r->fence));
    if (!st)
        return true;
    memset(st, 0, sizeof *st);
    st->patches = r->qt.npatches;
    st->culled = r->qt.nculled;
    st->pipelines = binds;
    st->combos_in_view = in_view;
    for (int i = 0; i < r->qt.npatches && !screen; i++)
        st->class_patches += r->qt.patches[i].combo >= r->p->nbase &&
                             r->qt.patches[i].combo < r->ncombos;
    st->far_patches = screen ? 0 : r->far_patches;
    st->uber_patches = screen ? 0 : r->uber_patches;
    st->split_uncovered = r->qt.nsplit_uncovered;
    st->backfaces_culled = cull;
    st->select_ms = select_ms;
    st->cpu_ms = cpu_ms;
    st->screen = screen;
    st->sorted = screen && rt_screen_sorting(r->screen);
    if (screen)
        rt_screen_read_stats(r->screen, &st->tiles);
    else if (count)
        rt_counters_read(r->counters_host.map, &st->tiles);
    rt_ug_read_stats(ug ? r->ug : NULL, &st->undergrowth);
    return read_times(r, screen, st, e);
}

/* A new shadow map when the sun moved, or its texels a crater may have
 * changed since the last: marched on the device (shadow_gpu.c) or the CPU
 * (shadow.c, the reference); its wall time in *ms (0: none was needed). */
static bool update_shadow(rt_renderer *r, double *ms, rt_error *e)
{
    *ms = 0;
    double sun[3];
    rt_light_sun_dir(&r->light, sun);
    if (r->desc.no_shadows)
        return true;
    bool full = r->shadow_stale || memcmp(sun, r->shadow_sun, sizeof sun);
    bool part = r->shadow_rect[0] < r->shadow_rect[2] && r->shadow_rect[1] < r->shadow_rect[3];
    if (!full && !part)
        return true;
    const rt_pack *p = r->p;
    size_t n = (size_t)p->hf_width * (size_t)p->hf_height;
    /* both paths wait for the queue (an upload, a one-time submission):
     * the last frame's work is not the map's time */
    RT_VK(e, vkQueueWaitIdle(r->d->queue));
    double t0 = splat_now();
    if (r->shadow_on_gpu) {
        if (!r->shadow_gpu &&
            !rt_shadow_gpu_create(r->d, p, rt_renderer_heights(r), &r->terrain.height,
                                  r->pl.cache, &r->shadow_gpu, e)) {
            rt_shadow_gpu_destroy(r->shadow_gpu);
            r->shadow_gpu = NULL;
            if (!r->shadow_auto || e->id != RT_E_PACK_LIMIT)
                return false;
            /* a heightfield over the device's storage buffer limit: the
             * CPU march, unless the device's was asked for */
            rt_error_clear(e);
            r->shadow_on_gpu = false;
            return update_shadow(r, ms, e);
        }
        t0 = splat_now();   /* the pyramid and the pipeline are made once */
        if (!rt_shadow_gpu_map(r->shadow_gpu, sun, r->bounds.hmax[r->bounds.nlevels - 1][0],
                               full ? NULL : r->shadow_rect, &r->terrain.shadow, e))
            return false;
        *ms = 1e3 * (splat_now() - t0);
    } else {
        if (!r->shadow_map && !(r->shadow_map = malloc(n)))
            return rt_fail(e, RT_E_VULKAN, "shadow map", "out of memory");
        rt_shadow_map(rt_renderer_heights(r), p, &r->bounds, sun, full ? NULL : r->shadow_rect,
                      r->shadow_map);
        *ms = 1e3 * (splat_now() - t0);
        if (!rt_image_upload(r->d, &r->terrain.shadow, r->shadow_map, n, e))
            return false;
    }
    memcpy(r->shadow_sun, sun, sizeof sun);
    r->shadow_stale = false;
    memset(r->shadow_rect, 0, sizeof r->shadow_rect);
    return true;
}

bool rt_renderer_shadow_read(rt_renderer *r, uint8_t *out, rt_error *e)
{
    size_t n = (size_t)r->p->hf_width * (size_t)r->p->hf_height;
    if (r->shadow_on_gpu && r->shadow_gpu)
        return rt_shadow_gpu_read(r->shadow_gpu, out, e);
    if (!r->shadow_on_gpu && r->shadow_map) {
        memcpy(out, r->shadow_map, n);
        return true;
    }
    return rt_fail(e, RT_E_VULKAN, "shadow map", "none made yet");
}

void rt_renderer_shadow_reference(rt_renderer *r, uint8_t *out)
{
    double sun[3];
    rt_light_sun_dir(&r->light, sun);
    rt_shadow_map(rt_renderer_heights(r), r->p, &r->bounds, sun, NULL, out);
}

/* A frame; on the screen-space path, drawn again while lists got tiles
 * whose pipelines did not exist yet (compiled in between): at most once
 * per variant in practice, since the classification is deterministic. */
bool rt_renderer_frame(rt_renderer *r, const rt_camera *c, rt_frame_stats *st, rt_error *e)
{
    rt_frame_stats local;
    if (!st)
        st = &local;
    double shadow_ms;
    if (!update_shadow(r, &shadow_ms, e))
        return false;
    double compile_ms = 0;
    for (int redraws = 0;; redraws++) {
        if (!draw_frame(r, c, st, e))
            return false;
        st->redraws = redraws;
        st->shadow_ms = shadow_ms;
        st->compile_ms = compile_ms;
        st->spirv_cached = atomic_load(&r->pl.spirv_cached);
        st->spirv_compiled = atomic_load(&r->pl.spirv_compiled);
        if (rt_async_failed(&r->pl, e))
            return false;
        st->shadow_gpu = r->shadow_on_gpu;
        if (!st->screen)
            return true;
        double t0 = splat_now();
        int made = rt_screen_missing(r->screen, &r->pl, compute_variant(r), e);
        compile_ms += 1e3 * (splat_now() - t0);
        st->pipelines_pending = rt_async_pending(&r->pl);
        if (made < 0)
            return false;
        if (made == 0)
            return true;
        if (redraws >= 3)
            return rt_fail(e, RT_E_VULKAN, "screen-space shading",
                           "tile lists still need new pipelines after 3 redraws");
    }
}

bool rt_renderer_read(rt_renderer *r, float *rgba, rt_error *e)
{
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(r->d, &cb, e))
        return false;
    VkBufferImageCopy copy = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { (uint32_t)r->desc.width, (uint32_t)r->desc.height, 1 },
    };
    vkCmdCopyImageToBuffer(cb, r->color.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           r->readback.buf, 1, &copy);
    VkBufferMemoryBarrier b = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
        .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .buffer = r->readback.buf,
        .size = VK_WHOLE_SIZE,
    };
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0,
                         0, NULL, 1, &b, 0, NULL);
    if (!rt_oneshot_end(r->d, cb, e))
        return false;
    memcpy(rgba, r->readback.map, (size_t)r->desc.width * (size_t)r->desc.height * 16);
    return true;
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
        (async && !rt_async_start(r->d, p, &r->pl, e))) {
        free(counts);
        return false;
    }
    free(r->counts);
    r->counts = counts;
    r->ncombos = p->ncombos;
    for (int L = 0; L < p->nlevels; L++)
        r->combo_ids[L] = p->levels[L].ids;
    memset(r->params_ubo.map, 0, o->params_size);
    for (int i = 0; i < p->nparams; i++)
        memcpy((uint8_t *)r->params_ubo.map + p->params[i].offset, p->params[i].value, 16);
    r->p = p;
    if (!r->light_set)
        pack_light(r, p);
    rt_ug_destroy(r->ug);   /* blocks, meshes and mask shaders are the pack's */
    r->ug = NULL;
    if (!make_undergrowth(r, e))
        return false;
    /* the far atlas is the pack's bake (a reload's pack has none until
     * the next --far-atlas build); the screen path borrows it */
    bool had_screen = r->screen != NULL;
    rt_screen_destroy(r->screen);
    r->screen = NULL;
    rt_far_destroy(r->far);
    r->far = NULL;
    if (!rt_far_create(r->d, p, &r->pl, &r->far, e)) {
        rt_far_destroy(r->far);
        r->far = NULL;
        return false;
    }
    if (had_screen) {
        /* the classification's combination map and sets are the pack's */
        if (!rt_screen_create(r->d, p, &r->pl, &r->color, &r->depth, r->terrain.nearest_clamp,
                              r->set0c, r->far, use_raycast(r), r->desc.pixel_sort,
                              r->desc.sort_tiles, &r->screen, e)) {
            rt_screen_destroy(r->screen);
            r->screen = NULL;
            return false;
        }
        rt_screen_far(r->screen, r->desc.far_atlas_distance);
        r->pl.sort_tiles = rt_screen_sort_tiles(r->screen);
    }
    return true;
}

bool rt_renderer_crater(rt_renderer *r, const rt_crater *c, rt_crater_stats *st, rt_error *e)
{
    if (!r->destr) {
        if (st) {
            memset(st, 0, sizeof *st);
            st->result = RT_CRATER_OUTSIDE;
        }
        return true;
    }
    rt_crater_stats local;
    if (!st)
        st = &local;
    if (!rt_destruction_crater(r->destr, c, st, e))
        return false;
    if (st->result == RT_CRATER_DONE) {
        double rect[4] = { c->x - c->radius, c->z - c->radius, c->x + c->radius,
                           c->z + c->radius };
        rt_ug_invalidate(r->ug, rect);
    }
    /* the shadow map's texels the lowered disc can shade or unshade */
    double sun[3];
    int rect[4], *d = r->shadow_rect;
    rt_light_sun_dir(&r->light, sun);
    if (st->result == RT_CRATER_DONE &&
        rt_shadow_crater_rect(r->p, &r->bounds, sun, c->x, c->z, c->radius, rect)) {
        bool empty = d[0] >= d[2] || d[1] >= d[3];
        for (int k = 0; k < 4; k++)
            d[k] = empty ? rect[k] : k < 2 ? (rect[k] < d[k] ? rect[k] : d[k])
                                           : (rect[k] > d[k] ? rect[k] : d[k]);
    }
    return true;
}

rt_destruction *rt_renderer_destruction(rt_renderer *r) { return r->destr; }

void rt_renderer_set_undergrowth(rt_renderer *r, bool on) { r->ug_off = !on; }

int rt_renderer_undergrowth_cell(rt_renderer *r, int ix, int iz, rt_ug_instance *out, int max,
                                 rt_error *e)
{
    return rt_ug_read_cell(r->ug, ix, iz, out, max, e);
}

int rt_renderer_undergrowth_rings(rt_renderer *r, double width, int nrings, uint32_t *counts,
                                  rt_error *e)
{
    return rt_ug_probe_rings(r->ug, width, nrings, counts, e);
}

bool rt_renderer_undergrowth_wind(rt_renderer *r, float *points, int n, double time,
                                  rt_error *e)
{
    return r->ug ? rt_ug_probe_wind(r->ug, points, n, time, e) : false;
}

const uint16_t *rt_renderer_heights(const rt_renderer *r)
{
    return r->destr ? rt_destruction_heights(r->destr) : r->p->heights;
}

bool rt_renderer_pick(const rt_renderer *r, const double o[3], const double dir[3],
                      double hit[3])
{
    return rt_heightfield_pick(rt_renderer_heights(r), r->p, o, dir, hit);
}

bool rt_renderer_bake_far(rt_renderer *r, int w, int h, float *albedo, float *normal,
                          float *rough, rt_far_bake_stats *st, rt_error *e)
{
    rt_camera c;
    rt_default_camera(r->p, &c);
    splat_frame fr;
    fill_frame(r, &c, &fr);
    /* seen from the origin (abi.h "far atlas bake"), no craters */
    memset(fr.camera, 0, sizeof fr.camera);
    memset(fr.world, 0, sizeof fr.world);
    memset(fr.destruction, 0, sizeof fr.destruction);
    return rt_far_bake(r->d, r->p, &r->pl, r->set0, r->set1, &fr, w, h, albedo, normal, rough,
                       st, e);
}

bool rt_renderer_read_heights(rt_renderer *r, uint16_t *out, rt_error *e)
{
    return rt_destruction_wait(r->destr, e) && rt_read_r16(r->d, &r->terrain.height, out, e);
}

static const struct view_row {
    const char *name;
    int         key;
    rt_tonemap  tonemap;
} view_rows[SPLAT_VIEW_COUNT] = {
#define X(id, num, name, key, tm, where, glsl) [num] = { name, key, RT_TONEMAP_##tm },
    SPLAT_VIEWS(X)
#undef X
};

const char *rt_view_name(splat_view v)
{
    return (unsigned)v < SPLAT_VIEW_COUNT ? view_rows[v].name : "?";
}

rt_tonemap rt_view_tonemap(splat_view v)
{
    return (unsigned)v < SPLAT_VIEW_COUNT ? view_rows[v].tonemap : RT_TONEMAP_NONE;
}

int rt_view_by_key(int key)
{
    for (int v = 0; v < SPLAT_VIEW_COUNT; v++)
        if (view_rows[v].key == key)
            return v;
    return -1;
}

void rt_view_list(char *buf, size_t n)
{
    size_t len = 0;
    if (n)
        buf[0] = 0;
    for (int v = 0; v < SPLAT_VIEW_COUNT && len < n; v++)
        len += (size_t)snprintf(buf + len, n - len, "%s%s%s", v ? "|" : "", view_rows[v].name,
                                v == SPLAT_VIEW_MASK ? ":MATERIAL" : "");
}

bool rt_parse_view(const char *s, const rt_pack *p, splat_view *view, int *material, rt_error *e)
{
    *material = 0;
    if (!strncmp(s, "mask:", 5)) {
        int m = rt_pack_material_find(p, s + 5);
        if (m < 0) {
            char what[256];
            snprintf(what, sizeof what, "--view %s: the pack has no material '%s'", s, s + 5);
            return rt_fail(e, RT_E_PACK_FIELD, p->dir, what);
        }
        *view = SPLAT_VIEW_MASK;
        *material = m;
        return true;
    }
    for (int v = 0; v < SPLAT_VIEW_COUNT; v++)
        if (v != SPLAT_VIEW_MASK && !strcmp(s, rt_view_name((splat_view)v))) {
            *view = (splat_view)v;
            return true;
        }
    char what[512], list[256];
    rt_view_list(list, sizeof list);
    snprintf(what, sizeof what, "unknown view '%s' (%s)", s, list);
    return rt_fail(e, RT_E_PACK_FIELD, "--view", what);
}
