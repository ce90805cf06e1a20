/* undergrowth.c — procedural undergrowth from the terrain's own material
 * masks (Andersson 2007 §5.5, seed 000): grass, plants and stones grow
 * wherever an undergrowth-bearing material's composited weight says,
 * follow repainting and craters, and need no index maps of their own.
 *
 * A fixed pool of 16 x 16 m cells is allocated by 2D distance from the
 * camera (every cell whose centre lies within the radius), never by the
 * frustum; cells in the frustum are generated first.  Generating a cell
 * happens on the GPU, in the frame's command buffer, with no read back:
 *   1. the mask pass: each leaf cell the cell overlaps runs its
 *      combination's undergrowth mask shader (abi.h "undergrowth masks")
 *      over the cell's 64 x 64 texels inside that leaf, writing every
 *      undergrowth material's composited weight, the terrain normal and
 *      the composite's albedo;
 *   2. the scatter pass, one workgroup per block (a material's
 *      `undergrowth`) and cell, one dispatch for the frame's new cells
 *      (their positions and slots in gtab): a jittered grid at the
 *      block's density, Russian roulette on the material's weight,
 *      scale and rotation from a hash
 *      of the cell's integer position (the same instances on every run
 *      and from every camera), the root on the heightfield (bilinear as
 *      the terrain), the terrain's albedo at the root.
 *      Instances are compacted by a workgroup prefix sum in candidate
 *      order, so the buffer is deterministic (no atomics), and the
 *      workgroup writes the block's indirect draw arguments (its mesh from
 *      gtab, the count).
 * Every frame a LOD pass scales each cell's counts by its distance, then
 * the cull passes ("cull", undergrowth_glsl.c rt_ug_cull_glsl) keep the
 * instances the fade leaves a size and whose bounds touch the frustum,
 * compacted into one list (deterministic: count, scan, write).  Drawing
 * is one indexed indirect draw per key (a block's near or far mesh) over
 * that list, cells front to back within a key, opaque blocks first,
 * after the terrain into its colour and depth; lit by splat_light
 * (abi.c) with the terrain normal (a block's `lighting = terrain`) or the
 * mesh's.  In the vertex stage (ug_glsl, which the probe pass runs too):
 *   - the distance fade: an instance at distance d from the camera stays
 *     with probability fade(d) = 1 - smoothstep(r0, r1, d), r1 = radius -
 *     0.75 cell (every cell holding a point nearer than r1 is allocated),
 *     r0 = 0.6 r1; it stays while its own hash h (of its root: stable as
 *     the camera moves) is below fade(d), and shrinks to nothing as
 *     fade(d) comes down to h (scale clamp((fade - h) * 5, 0, 1)): the
 *     density thins to zero before the radius, and no instance pops;
 *   - the wind: a vertex h metres above the root moves along the block's
 *     direction by a = sway * h^2 * (1 - gust + gust * g), g in [0, 1]
 *     gusts: two waves (24 m at 4.2 m/s along the wind, 9.1 m at 4 m/s
 *     slanted across it, fract() of their phases so that far from the
 *     origin float sin stays exact), and down by min(a^2 / 2h, h / 2)
 *     (about keeping the blade's length);
 *   - the colour: the block's, blended with the terrain's albedo at the
 *     root by mix(root_blend, blend, v) (v: the mesh's uv.y, 0 at the
 *     root, 1 at the tip), and wholly the terrain's (no root darkening
 *     either, and a mesh-lit instance's normal the terrain's) as ug_far
 *     goes from 0 at 0.35 r1 to 1 at 0.8 r1: the cover turns into the
 *     ground it stands on before it thins out.
 * The shaders are in undergrowth_glsl.c, the cull passes' recording in
 * undergrowth_cull.c, the block table and the far meshes in
 * undergrowth_mesh.c, the tests' probe pass in
 * undergrowth_probe.c, what they share in undergrowth_impl.h.
 */
#include "undergrowth_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- creation ----------------------------------------------------------------- */

static bool pipe_layout(rt_ug *u, const VkDescriptorSetLayout *sets, uint32_t n,
                        VkShaderStageFlags stages, uint32_t push, VkPipelineLayout *out,
                        rt_error *e)
{
    return rt_vk_layout(u->d, &u->keep, &(rt_vk_layout_desc){ .label = "undergrowth",
                            .sets = sets, .nsets = n, .push_stages = stages,
                            .push_bytes = push }, out, e);
}

/* Colour RGBA32F loaded and left TRANSFER_SRC (as every path leaves it);
 * depth loaded from `depth_in` (the forward and multi-pass paths leave
 * it an attachment, the screen path's geometry pass SHADER_READ_ONLY). */
static bool make_pass(rt_ug *u, VkImageLayout depth_in, VkRenderPass *out, rt_error *e)
{
    VkSubpassDependency dep[2] = {
        { VK_SUBPASS_EXTERNAL, 0,
          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
          VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
          VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT |
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT, 0 },
        /* the depth's store (and a final layout move) after its tests;
         * the compute rasteriser reads both (undergrowth_craster.c) */
        { 0, VK_SUBPASS_EXTERNAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
          VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT |
          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT, 0 },
    };
    const VkImageLayout src = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    return rt_vk_pass(u->d, &u->keep, &(rt_vk_pass_desc){ .label = "undergrowth",
                          .color = { { .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                       .initial = src, .final = src } }, .ncolor = 1,
                          .depth = { .format = VK_FORMAT_D32_SFLOAT, .initial = depth_in,
                                     .final = depth_in },
                          .deps = dep, .ndeps = 2 }, out, e);
}

/* The draw pipeline of opaque meshes (depth tested before shading: blades
 * hidden behind nearer ones cost no lighting), of cut-out ones (the
 * fragment shader discards, so the test waits for it: kind 1) or of the
 * contact shadows (kind 2: multiplied into the colour, no depth written). */
static bool draw_pipeline(rt_ug *u, int kind, rt_error *e)
{
    bool cutout = kind == 1, shadow = kind == 2;
    const char *vmain = shadow ? rt_ug_shadow_vert_main : rt_ug_draw_vert_main;
    size_t nv = strlen(SPLAT_GLSL_TERRAIN) + strlen(vmain) + 32;
    size_t nf = strlen(SPLAT_GLSL_PRELUDE) + strlen(rt_ug_draw_frag_main) + strlen(rt_ug_shadow_frag) + 96;
    char *vs = malloc(nv), *fs = malloc(nf);
    if (!vs || !fs) {
        free(vs);
        free(fs);
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    }
    snprintf(vs, nv, "#version 450\n%s%s", SPLAT_GLSL_TERRAIN, vmain);
    if (shadow)
        snprintf(fs, nf, "%s", rt_ug_shadow_frag);
    else
        snprintf(fs, nf, "#version 450\n%s%s%s",
                 cutout ? "#define UG_CUTOUT 1\n" : "layout(early_fragment_tests) in;\n",
                 SPLAT_GLSL_PRELUDE, rt_ug_draw_frag_main);
    VkVertexInputBindingDescription vb = { 0, 32, VK_VERTEX_INPUT_RATE_VERTEX };
    VkVertexInputAttributeDescription va[3] = {
        { 0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0 },
        { 1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12 },
        { 2, 0, VK_FORMAT_R32G32_SFLOAT, 24 },
    };
    /* shadows: dst * src, the colour darkened, its alpha kept */
    VkPipelineColorBlendAttachmentState mul = {
        .blendEnable = VK_TRUE, .srcColorBlendFactor = VK_BLEND_FACTOR_ZERO,
        .dstColorBlendFactor = VK_BLEND_FACTOR_SRC_COLOR, .colorBlendOp = VK_BLEND_OP_ADD,
        .srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO,
        .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE, .alphaBlendOp = VK_BLEND_OP_ADD,
        .colorWriteMask = 0xf };
    bool ok = rt_vk_gfx(u->d, &u->keep, &(rt_vk_gfx_desc){ .label = "undergrowth",
                            .vs_glsl = vs, .fs_glsl = fs, .vbufs = &vb, .nvbufs = 1,
                            .attrs = va, .nattrs = 3,
                            .depth_test = true, .depth_write = !shadow,   /* reversed Z */
                            .depth_compare = VK_COMPARE_OP_GREATER,
                            .ncolor = 1, .blend = shadow ? &mul : NULL,
                            .layout = u->draw_layout, .pass = u->pass_att },
                        shadow ? &u->shadow_pipe : &u->draw_pipe[cutout], e);
    free(vs);
    free(fs);
    return ok;
}

static bool make_sets(rt_ug *u, VkDescriptorSet set0_src, const rt_image *height,
                      VkSampler nearest, rt_error *e)
{
    rt_device *d = u->d;
    VkDescriptorPoolSize sizes[3] = {
        { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 26 + 1 },   /* + set 0's vector shapes */
        { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16 + SPLAT_MAX_UG_TEXTURES },
        { VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2 },
    };
    VkDescriptorSetLayout layouts[7] = { u->set_terrain, u->set_mask, u->set_gen, u->set_draw,
                                         u->set_lod, u->set_cull, u->set_scan };
    VkDescriptorSet sets[7];
    if (!rt_vk_sets(d, &u->keep, &(rt_vk_sets_desc){ .label = "undergrowth", .sizes = sizes,
                        .nsizes = 3, .layouts = layouts, .nsets = 7 }, &u->dpool, sets, e))
        return false;
    u->set0 = sets[0];
    u->mask_set = sets[1];
    u->gen_set = sets[2];
    u->draw_set = sets[3];
    u->lod_set = sets[4];
    u->cull_set = sets[5];
    u->scan_set = sets[6];
    /* set 0 of the mask pass: the terrain's, but the frame block whose
     * camera is the origin (abi.h "undergrowth masks") */
    rt_terrain_compute_set(d, set0_src, u->set0, u->frame.buf);
    /* the textures (every slot bound: the white one past the pack's) */
    VkDescriptorImageInfo ti[SPLAT_MAX_UG_TEXTURES];
    for (int i = 0; i < SPLAT_MAX_UG_TEXTURES; i++) {
        int k = i < u->p->ug.ntextures ? i : SPLAT_MAX_UG_TEXTURES;
        ti[i] = (VkDescriptorImageInfo){ u->tex_smp, u->tex[k].view,
                                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL };
    }
    const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    const VkDescriptorType cis = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    rt_vk_write w[] = {
        { u->mask_set, 0, sb, u->masks.buf },
        { u->gen_set, 0, sb, u->masks.buf }, { u->gen_set, 1, sb, u->inst.buf },
        { u->gen_set, 2, sb, u->args.buf }, { u->gen_set, 3, sb, u->blocks.buf },
        { u->gen_set, 4, cis, .sampler = nearest, .view = height->view },
        { u->gen_set, 5, sb, u->gtab.buf },
        { u->draw_set, 0, sb, u->blocks.buf }, { u->draw_set, 1, sb, u->inst.buf },
        { u->draw_set, 2, sb, u->lod.buf }, { u->draw_set, 4, sb, u->vis.buf },
        { u->lod_set, 0, sb, u->args.buf }, { u->lod_set, 1, sb, u->draw_args.buf },
        { u->lod_set, 2, sb, u->lod.buf },
        { u->cull_set, 0, sb, u->inst.buf }, { u->cull_set, 1, sb, u->draw_args.buf },
        { u->cull_set, 2, sb, u->lod.buf }, { u->cull_set, 3, sb, u->blocks.buf },
        { u->cull_set, 4, sb, u->ent.buf }, { u->cull_set, 5, sb, u->cnt.buf },
        { u->cull_set, 6, sb, u->vis.buf },
        { u->scan_set, 0, sb, u->ent.buf }, { u->scan_set, 1, sb, u->cnt.buf },
        { u->scan_set, 2, sb, u->mdraw.buf },
        { u->scan_set, 3, sb, u->cdisp.buf },
        { u->draw_set, 3, cis, .images = ti, .count = SPLAT_MAX_UG_TEXTURES },
    };
    rt_vk_write_sets(d, w, sizeof w / sizeof *w);
    return true;
}

/* The blocks' textures: sRGB with their mip chains, and a white texel. */
static bool make_textures(rt_ug *u, rt_error *e)
{
    rt_device *d = u->d;
    const rt_pack_ug *pu = &u->p->ug;
    const VkImageUsageFlags use = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                  VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    for (int i = 0; i <= pu->ntextures; i++) {
        static const uint8_t white[4] = { 255, 255, 255, 255 };
        bool own = i < pu->ntextures;
        uint32_t w = own ? (uint32_t)pu->textures[i].width : 1;
        uint32_t h = own ? (uint32_t)pu->textures[i].height : 1, mips = 1;
        while ((w > h ? w : h) >> mips)
            mips++;
        rt_image *img = &u->tex[own ? i : SPLAT_MAX_UG_TEXTURES];
        if (!rt_image_create(d, w, h, 1, false, mips, VK_FORMAT_R8G8B8A8_SRGB, use,
                             VK_IMAGE_ASPECT_COLOR_BIT, img, e) ||
            !rt_image_upload(d, img, own ? pu->textures[i].rgba : white, (size_t)w * h * 4, e))
            return false;
    }
    return rt_vk_sampler(d, &u->keep, &(rt_vk_sampler_desc){ .label = "undergrowth textures",
                             .filter = VK_FILTER_LINEAR, .mip = VK_SAMPLER_MIPMAP_MODE_LINEAR,
                             .wrap = VK_SAMPLER_ADDRESS_MODE_REPEAT, .max_lod = 16.0f },
                         &u->tex_smp, e);
}

static bool make_layouts(rt_ug *u, rt_error *e)
{
    rt_device *d = u->d;
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    VkDescriptorSetLayoutBinding mask[] = { { 0, sb, 1, cs, NULL } };
    VkDescriptorSetLayoutBinding gen[] = {
        { 0, sb, 1, cs, NULL }, { 1, sb, 1, cs, NULL }, { 2, sb, 1, cs, NULL },
        { 3, sb, 1, cs, NULL }, { 4, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs, NULL },
        { 5, sb, 1, cs, NULL },
    };
    VkDescriptorSetLayoutBinding draw[] = {
        { 0, sb, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL }, { 1, sb, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL },
        { 2, sb, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL },
        { 3, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, SPLAT_MAX_UG_TEXTURES,
          VK_SHADER_STAGE_FRAGMENT_BIT, NULL },
        { 4, sb, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL },
    };
    VkDescriptorSetLayoutBinding lod[] = {
        { 0, sb, 1, cs, NULL }, { 1, sb, 1, cs, NULL }, { 2, sb, 1, cs, NULL },
    };
    VkDescriptorSetLayoutBinding cull[7], scan[4];
    for (uint32_t i = 0; i < 7; i++)
        cull[i] = (VkDescriptorSetLayoutBinding){ i, sb, 1, cs, NULL };
    for (uint32_t i = 0; i < 4; i++)
        scan[i] = (VkDescriptorSetLayoutBinding){ i, sb, 1, cs, NULL };
    rt_vk_list *k = &u->keep;
    if (!rt_terrain_compute_layout(d, &u->set_terrain, e) ||
        !rt_vk_keep(d, k, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, RT_VK_H(u->set_terrain), e) ||
        !rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "undergrowth masks", mask, 1 },
                          &u->set_mask, e) ||
        !rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "undergrowth scatter", gen, 6 },
                          &u->set_gen, e) ||
        !rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "undergrowth draw", draw, 5 },
                          &u->set_draw, e) ||
        !rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "undergrowth cull", cull, 7 },
                          &u->set_cull, e) ||
        !rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "undergrowth scan", scan, 4 },
                          &u->set_scan, e) ||
        !rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "undergrowth lod", lod, 3 },
                          &u->set_lod, e))
        return false;
    VkDescriptorSetLayout ms[3] = { u->set_terrain, u->pl->set_material, u->set_mask };
    VkDescriptorSetLayout ds[3] = { u->pl->set_terrain, u->pl->set_material, u->set_draw };
    return pipe_layout(u, ms, 3, cs, sizeof(splat_push), &u->mask_layout, e) &&
           pipe_layout(u, &u->set_gen, 1, cs, sizeof(ug_push), &u->gen_layout, e) &&
           pipe_layout(u, &u->set_lod, 1, cs, 16, &u->lod_layout, e) &&
           pipe_layout(u, &u->set_cull, 1, cs, sizeof(ug_cull_push), &u->cull_layout, e) &&
           pipe_layout(u, &u->set_scan, 1, cs, 16, &u->scan_layout, e) &&
           pipe_layout(u, ds, 3, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       sizeof(splat_push), &u->draw_layout, e);
}

static bool make_buffers(rt_ug *u, rt_error *e)
{
    rt_device *d = u->d;
    const rt_pack_ug *pu = &u->p->ug;
    const VkBufferUsageFlags st = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkDeviceSize mask_bytes = (VkDeviceSize)u->pool * TEXELS * TEXELS * (u->nw + 2) * 4;
    VkDeviceSize inst_bytes = (VkDeviceSize)u->pool * u->cap * SPLAT_UG_INSTANCE_BYTES;
    VkDeviceSize range = d->props.limits.maxStorageBufferRange;
    VkDeviceSize inst_max = range < SPLAT_UG_MAX_INSTANCE_BYTES ? range : SPLAT_UG_MAX_INSTANCE_BYTES;
    if (inst_bytes > inst_max)
        return rt_fail(e, RT_E_PACK_LIMIT, u->p->dir, "undergrowth's instance buffer (bytes)",
                       (unsigned long long)inst_bytes,
                       range < SPLAT_UG_MAX_INSTANCE_BYTES
                           ? "the device's maxStorageBufferRange"
                           : "the runtime's instance buffer limit (abi.h)",
                       (unsigned long long)inst_max);
    if (mask_bytes > range)
        return rt_fail(e, RT_E_PACK_LIMIT, u->p->dir, "undergrowth's mask buffer (bytes)",
                       (unsigned long long)mask_bytes, "the device's maxStorageBufferRange",
                       (unsigned long long)range);
    if (!rt_buffer_create(d, mask_bytes, st | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, &u->masks, e) ||
        !rt_buffer_create(d, inst_bytes + 32, st | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false,
                          &u->inst, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * u->nblocks * 20,
                          st | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                              VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false, &u->args, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * u->nblocks * 20,
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &u->args_host, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * u->nblocks * 20, st, false, &u->draw_args,
                          e) ||
        !rt_buffer_create(d, (VkDeviceSize)(UG_ENT0 + u->pool * u->nblocks) * 4, st, true,
                          &u->ent, e) ||
        !rt_buffer_create(d, (VkDeviceSize)(2 * u->pool * u->nblocks + 1) * 4, st, false,
                          &u->cnt, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * u->cap * 4 + 4,
                          st | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false, &u->vis, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->nblocks * 4 * UG_LEVELS * 20,   /* + the shadows' */
                          st | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          false, &u->mdraw, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->nblocks * 4 * UG_LEVELS * 20, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                          true, &u->mdraw_host, e) ||
        !rt_buffer_create(d, (VkDeviceSize)UG_MAX_KEYS * 2 * 12,   /* the compute keys' dispatches, their shadows' */
                          st | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, false, &u->cdisp, e) ||
        !rt_buffer_create(d, (VkDeviceSize)(u->nblocks + UG_TODO) * 16, st, true, &u->gtab, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * 4, st, true, &u->lod, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->nblocks * 16 * UG_BLOCK_VEC4, st, true, &u->blocks,
                          e) ||
        /* + the shadow quad, + the single-triangle meshes (tri_mesh) */
        !rt_buffer_create(d, (VkDeviceSize)(pu->nvertices + 4 + pu->nindices / 2 + 3) * 32,
                          VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | st, true, &u->vbuf, e) ||
        !rt_buffer_create(d, (VkDeviceSize)(pu->nindices + 6 + pu->nindices / 2 + 3) * 4,
                          VK_BUFFER_USAGE_INDEX_BUFFER_BIT | st, true, &u->ibuf, e) ||
        !rt_buffer_create(d, sizeof(splat_frame), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true,
                          &u->frame, e))
        return false;
    memcpy(u->vbuf.map, pu->vertices, (size_t)pu->nvertices * 32);
    memcpy(u->ibuf.map, pu->indices, (size_t)pu->nindices * 4);
    /* the contact shadow's quad after the pack's meshes: [-1, 1]^2 in x, z */
    static const float quad[4][8] = { { -1, 0, -1, 0, 1, 0, 0, 0 }, { 1, 0, -1, 0, 1, 0, 1, 0 },
                                      { 1, 0, 1, 0, 1, 0, 1, 1 }, { -1, 0, 1, 0, 1, 0, 0, 1 } };
    static const uint32_t qi[6] = { 0, 1, 2, 0, 2, 3 };
    memcpy((float *)u->vbuf.map + (size_t)pu->nvertices * 8, quad, sizeof quad);
    memcpy((uint32_t *)u->ibuf.map + pu->nindices, qi, sizeof qi);
    /* each block's single-triangle mesh from its far mesh, after those */
    uint32_t nv = pu->nvertices + 4, ni = pu->nindices + 6;
    for (int b = 0; b < u->nblocks; b++) {
        int f = pu->meshes[pu->blocks[b].mesh].far;
        int done = -1;   /* a block before with the same far mesh */
        for (int c = 0; c < b && f >= 0 && done < 0; c++)
            done = pu->meshes[pu->blocks[c].mesh].far == f && u->tri[c][0] ? c : -1;
        if (done >= 0) {
            memcpy(u->tri[b], u->tri[done], sizeof u->tri[b]);
            continue;
        }
        uint32_t nt = f >= 0 ? rt_ug_tri_mesh(pu, &pu->meshes[f], (float *)u->vbuf.map + (size_t)nv * 8,
                                        (uint32_t *)u->ibuf.map + ni)
                             : 0;
        u->tri[b][0] = 3 * nt;
        u->tri[b][1] = ni;
        u->tri[b][2] = nv;
        nv += 3 * nt;
        ni += 3 * nt;
    }
    rt_ug_fill_blocks(u, u->blocks.map);
    for (int b = 0; b < u->nblocks; b++) {
        const rt_pack_ug_mesh *m = &pu->meshes[pu->blocks[b].mesh];
        uint32_t *g = (uint32_t *)u->gtab.map + 4 * (size_t)b;
        g[0] = m->nidx;
        g[1] = m->first_index;
        g[2] = m->first_vertex;
        g[3] = 0;
    }
    memset(u->args_host.map, 0, (size_t)u->args_host.size);
    memset(u->mdraw_host.map, 0, (size_t)u->mdraw_host.size);
    for (int i = 0; i < u->pool; i++)
        ((float *)u->lod.map)[i] = 1.0f;
    return true;
}

bool rt_ug_create(rt_device *d, const rt_pack *p, rt_pipelines *pl, const rt_quadtree *qt,
                  const rt_ug_targets *t, double radius, double thin, rt_ug **out,
                  rt_error *e)
{
    *out = NULL;
    if (p->ug.nslots == 0)
        return true;
    rt_ug *u = calloc(1, sizeof *u);
    if (!u)
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    *out = u;
    u->d = d;
    u->p = p;
    u->pl = pl;
    u->qt = qt;
    u->radius = radius > 0 ? radius : RT_UG_RADIUS;
    u->compute = t->compute;
    u->color = t->color;
    u->depth = t->depth;
    u->cr_nearest = t->nearest;
    u->width = t->width;
    u->height_px = t->height_px;
    u->thin = thin > 0 ? thin : LOD_NEAR;
    u->pool = (int)splat_ug_pool(u->radius);
    u->nblocks = p->ug.nblocks;
    u->nw = (p->ug.nslots + 3) / 4;
    u->cells = calloc((size_t)u->pool, sizeof *u->cells);
    u->order = calloc((size_t)u->pool, sizeof *u->order);
    u->cell_level = calloc((size_t)u->pool * (size_t)(u->nblocks > 0 ? u->nblocks : 1),
                           sizeof *u->cell_level);
    u->block_base = calloc((size_t)u->nblocks, sizeof *u->block_base);
    u->block_grid = calloc((size_t)u->nblocks, sizeof *u->block_grid);
    u->mask_pipes = calloc((size_t)p->ncombos + 1, sizeof *u->mask_pipes);
    if (!u->cells || !u->order || !u->cell_level || !u->block_base || !u->block_grid || !u->mask_pipes)
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    rt_ug_fill_blocks(u, (float[4 * UG_BLOCK_VEC4 * SPLAT_MAX_UG_BLOCKS]){0});   /* u->cap first */
    /* the compute rasteriser's payload holds a list position below
     * 2^(32 - UG_CR_PSHIFT): a larger pool draws by the graphics pipeline */
    if ((uint64_t)u->pool * u->cap >= (uint64_t)1 << (32 - UG_CR_PSHIFT))
        u->compute = false;
    /* contact shadows where the colour target blends (RGBA32F: most do) */
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(d->phys, VK_FORMAT_R32G32B32A32_SFLOAT, &fp);
    for (int b = 0; b < u->nblocks; b++)
        u->shadows |= p->ug.blocks[b].shadow > 0;
    u->shadows &= (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT) != 0;
    VkQueryPoolCreateInfo qi = {
        .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
        .queryType = VK_QUERY_TYPE_TIMESTAMP, .queryCount = 6,
    };
    VkImageView views[2] = { t->color->view, t->depth->view };
    if (!make_layouts(u, e) || !make_buffers(u, e) || !make_textures(u, e) ||
        !make_sets(u, t->set0, t->height, t->nearest, e) ||
        !make_pass(u, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, &u->pass_att, e) ||
        !make_pass(u, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, &u->pass_ro, e) ||
        !rt_vk_compute(d, &u->keep, &(rt_vk_compute_desc){ .label = "undergrowth scatter",
                           .glsl = rt_ug_gen_glsl, .layout = u->gen_layout }, &u->gen_pipe, e) ||
        !rt_vk_compute(d, &u->keep, &(rt_vk_compute_desc){ .label = "undergrowth lod",
                           .glsl = rt_ug_lod_glsl, .layout = u->lod_layout }, &u->lod_pipe, e) ||
        !rt_ug_cull_pipelines(u, e) ||
        !draw_pipeline(u, 0, e) || !draw_pipeline(u, 1, e) ||
        (u->shadows && !draw_pipeline(u, 2, e)) ||
        !rt_ug_craster_create(u, e) ||
        !rt_vk_fb(d, &u->keep, &(rt_vk_fb_desc){ .label = "undergrowth", .pass = u->pass_att,
                      .views = views, .nviews = 2, .width = (uint32_t)t->width,
                      .height = (uint32_t)t->height_px }, &u->fb, e))
        return false;
    if (t->timestamps) {
        RT_VK(e, vkCreateQueryPool(d->dev, &qi, NULL, &u->qpool));
        return rt_vk_keep(d, &u->keep, VK_OBJECT_TYPE_QUERY_POOL, RT_VK_H(u->qpool), e);
    }
    return true;
}

void rt_ug_destroy(rt_ug *u)
{
    if (!u)
        return;
    rt_device *d = u->d;
    rt_vk_list_destroy(d, &u->keep);
    rt_buffer *bufs[] = { &u->masks, &u->inst, &u->args, &u->args_host, &u->draw_args, &u->lod,
                          &u->blocks, &u->vbuf, &u->ibuf, &u->frame, &u->ent,
                          &u->cnt, &u->vis, &u->mdraw, &u->mdraw_host, &u->cdisp, &u->gtab };
    for (size_t i = 0; i < sizeof bufs / sizeof *bufs; i++)
        rt_buffer_destroy(d, bufs[i]);
    rt_buffer_destroy(d, &u->probe_out);
    rt_ug_craster_destroy(u);
    for (int i = 0; i <= SPLAT_MAX_UG_TEXTURES; i++)
        rt_image_destroy(d, &u->tex[i]);
    free(u->mask_pipes);
    free(u->cells);
    free(u->order);
    free(u->cell_level);
    free(u->block_base);
    free(u->block_grid);
    free(u);
}

/* ---- cells ---------------------------------------------------------------------- */

static ug_cell *find_cell(rt_ug *u, int ix, int iz)
{
    for (int i = 0; i < u->pool; i++)
        if (u->cells[i].state != CELL_FREE && u->cells[i].ix == ix && u->cells[i].iz == iz)
            return &u->cells[i];
    return NULL;
}

/* Whether the box [lo, hi] (camera-relative) is outside one clip plane. */
static bool box_outside(const float *m, const double lo[3], const double hi[3])
{
    for (int plane = 0; plane < 5; plane++) {
        bool all_out = true;
        for (int c = 0; c < 8 && all_out; c++) {
            double p[3] = { c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2] };
            double v[4];
            for (int r = 0; r < 4; r++)   /* column-major */
                v[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
            double d = plane == 0 ? v[3] + v[0] : plane == 1 ? v[3] - v[0]
                     : plane == 2 ? v[3] + v[1] : plane == 3 ? v[3] - v[1] : v[3] - v[2];
            all_out = d < 0;
        }
        if (all_out)
            return true;
    }
    return false;
}

/* Draw and generation order: visible before not, near before far. */
static bool before(const ug_cell *x, const ug_cell *y)
{
    if (x->visible != y->visible)
        return x->visible;
    return x->dist < y->dist;
}

/* Allocate every cell within the radius (freeing those outside), then
 * order the pool: visible before not, near before far. */
static void allocate(rt_ug *u, const rt_camera *c, const float view_proj[16])
{
    const rt_pack *p = u->p;
    for (int i = 0; i < u->pool; i++)
        u->cells[i].wanted = false;
    double r = u->radius, cx = c->position[0], cz = c->position[2];
    /* from higher above the ground than the radius nothing would show:
     * no cells (so views from the air pay nothing) */
    int tx = (int)(cx / p->size[0] * (p->hf_width - 1) + 0.5);
    int tz = (int)(cz / p->size[1] * (p->hf_height - 1) + 0.5);
    tx = tx < 0 ? 0 : tx >= p->hf_width ? p->hf_width - 1 : tx;
    tz = tz < 0 ? 0 : tz >= p->hf_height ? p->hf_height - 1 : tz;
    double below = p->heights[(size_t)tz * (size_t)p->hf_width + (size_t)tx] / 65535.0 *
                   p->max_height + p->height_offset;
    if (c->position[1] - below > r)
        r = 0;
    int x0 = (int)floor((cx - r) / CELL), x1 = (int)floor((cx + r) / CELL);
    int z0 = (int)floor((cz - r) / CELL), z1 = (int)floor((cz + r) / CELL);
    int maxx = (int)ceil(p->size[0] / CELL) - 1, maxz = (int)ceil(p->size[1] / CELL) - 1;
    for (int iz = z0 < 0 ? 0 : z0; iz <= z1 && iz <= maxz; iz++)
        for (int ix = x0 < 0 ? 0 : x0; ix <= x1 && ix <= maxx; ix++) {
            double dx = (ix + 0.5) * CELL - cx, dz = (iz + 0.5) * CELL - cz;
            if (dx * dx + dz * dz > r * r || r == 0)
                continue;
            ug_cell *cl = find_cell(u, ix, iz);
            if (!cl)
                for (int i = 0; i < u->pool && !cl; i++)
                    if (u->cells[i].state == CELL_FREE)
                        cl = &u->cells[i];
            if (!cl)
                continue;   /* the pool is sized for the disc: not reached */
            if (cl->state == CELL_FREE)
                *cl = (ug_cell){ .ix = ix, .iz = iz, .state = CELL_PENDING };
            cl->wanted = true;
            cl->dist = sqrt(dx * dx + dz * dz);
        }
    /* cells that left the disc are free now; the disc's new ones take
     * them next frame at the latest (a full pool frees before it fills) */
    for (int i = 0; i < u->pool; i++)
        if (!u->cells[i].wanted)
            u->cells[i].state = CELL_FREE;
    double hmin = p->height_offset, hmax = p->height_offset + p->max_height;
    for (int i = 0; i < u->pool; i++) {
        ug_cell *cl = &u->cells[i];
        u->order[i] = i;
        if (cl->state == CELL_FREE)
            continue;
        double lo[3] = { cl->ix * CELL - cx, hmin - c->position[1] - 2, cl->iz * CELL - cz };
        double hi[3] = { lo[0] + CELL, hmax - c->position[1] + 8, lo[2] + CELL };
        cl->visible = !box_outside(view_proj, lo, hi);
        double near = cl->dist - CELL * 0.7071;   /* the cell's nearest point, about */
        double f = near > u->thin ? (u->thin / near) * (u->thin / near) : 1.0;
        ((float *)u->lod.map)[i] = (float)(f > LOD_MIN ? f : LOD_MIN);
    }
    for (int i = 1; i < u->pool; i++)   /* insertion sort: a few hundred cells */
        for (int j = i; j > 0 && before(&u->cells[u->order[j]], &u->cells[u->order[j - 1]]); j--) {
            int t = u->order[j];
            u->order[j] = u->order[j - 1];
            u->order[j - 1] = t;
        }
}

void rt_ug_invalidate(rt_ug *u, const double *rect)
{
    if (!u)
        return;
    for (int i = 0; i < u->pool; i++) {
        ug_cell *cl = &u->cells[i];
        if (cl->state != CELL_READY)
            continue;
        if (rect && (cl->ix * CELL > rect[2] || (cl->ix + 1) * CELL < rect[0] ||
                     cl->iz * CELL > rect[3] || (cl->iz + 1) * CELL < rect[1]))
            continue;
        cl->state = CELL_PENDING;
    }
}

/* ---- generation ------------------------------------------------------------------- */

static bool mask_pipeline(rt_ug *u, int combo, VkPipeline *out, rt_error *e)
{
    if (!u->mask_pipes[combo]) {
        const rt_pack_combo *co = &u->p->combos[combo];
        char name[64];
        snprintf(name, sizeof name, "combination %d (undergrowth masks)", combo);
        if (!co->ug_compute.mod) {
            *out = VK_NULL_HANDLE;   /* grows nothing: the texels stay 0 */
            return true;
        }
        /* the build's SPIR-V (checked against the undergrowth role on its
         * first use), else the GLSL, compiled and checked here */
        const uint32_t *words = NULL;
        const char *glsl = NULL;
        size_t nwords = 0;
        if (rt_spirv_present(&co->ug_spirv)
                ? !(words = rt_pack_spirv(u->p, &co->ug_spirv, &nwords, e))
                : !(glsl = rt_pack_text(u->p, &co->ug_compute, e)))
            return false;
        rt_interface in;
        if (!rt_interface_for(u->p, RT_ROLE_UNDERGROWTH, &in))
            return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
        bool ok = rt_vk_compute(u->d, &u->keep, &(rt_vk_compute_desc){ .label = name,
                                    .glsl = glsl, .check = &in, .spirv = words,
                                    .nwords = nwords, .layout = u->mask_layout,
                                    .cache = u->pl->cache }, &u->mask_pipes[combo], e);
        rt_interface_free(&in);
        if (!ok)
            return false;
    }
    *out = u->mask_pipes[combo];
    return true;
}

/* One mask dispatch: a cell's texels inside one leaf cell. */
typedef struct ug_mask_job {
    VkPipeline pipe;
    int        slot, lx, lz;
    float      x0, z0;
} ug_mask_job;

/* The mask dispatches of cell `cl` (pool slot `slot`), one per leaf cell
 * it overlaps, appended to `jobs`; *covered says whether they write every
 * texel (else the cell's texels are cleared first: beyond the terrain, a
 * hole, or a combination that grows nothing).  False on an error. */
static bool mask_jobs(rt_ug *u, const ug_cell *cl, int slot, ug_mask_job *jobs, int *njobs,
                      bool *covered, rt_error *e)
{
    const rt_pack_level *L0 = &u->p->levels[0];
    double lx0, lz0, lsx, lsz;
    rt_node_rect(u->qt, 0, 0, 0, &lx0, &lz0, &lsx, &lsz);
    double x0 = cl->ix * CELL, z0 = cl->iz * CELL;
    int ax = (int)floor(x0 / lsx), bx = (int)floor((x0 + CELL) / lsx);
    int az = (int)floor(z0 / lsz), bz = (int)floor((z0 + CELL) / lsz);
    /* the texel centres' extent against the leaves' */
    double half = 0.5 * CELL / TEXELS;
    *covered = x0 + half >= 0 && z0 + half >= 0 && x0 + CELL - half < L0->width * lsx &&
               z0 + CELL - half < L0->height * lsz;
    for (int lz = az; lz <= bz; lz++)
        for (int lx = ax; lx <= bx; lx++) {
            if (lx < 0 || lz < 0 || lx >= L0->width || lz >= L0->height)
                continue;
            /* a leaf that starts at the cell's far edge holds none of its
             * texel centres: it needs no dispatch */
            if (lx * lsx >= x0 + CELL || lz * lsz >= z0 + CELL)
                continue;
            unsigned id = L0->ids[(size_t)lz * (size_t)L0->width + (size_t)lx];
            VkPipeline pipe = VK_NULL_HANDLE;
            if (id != SPLAT_COMBO_HOLE && !mask_pipeline(u, (int)id, &pipe, e))
                return false;
            if (!pipe) {
                *covered = false;
                continue;
            }
            jobs[(*njobs)++] = (ug_mask_job){ pipe, slot, lx, lz, (float)x0, (float)z0 };
        }
    return true;
}

static int job_order(const void *a, const void *b)
{
    const ug_mask_job *x = a, *y = b;
    uint64_t p = (uint64_t)(uintptr_t)x->pipe, q = (uint64_t)(uintptr_t)y->pipe;
    if (p != q)
        return p < q ? -1 : 1;
    return x->slot != y->slot ? (x->slot < y->slot ? -1 : 1)
         : x->lz != y->lz     ? (x->lz < y->lz ? -1 : 1)
                              : (x->lx > y->lx) - (x->lx < y->lx);
}

/* The mask pass of the cells todo[0..n): the cells some texel of which
 * no dispatch writes cleared, then every dispatch, grouped by pipeline. */
static bool record_masks(rt_ug *u, VkCommandBuffer cb, const int *todo, int n,
                         VkDescriptorSet set1, rt_error *e)
{
    double lx0, lz0, lsx, lsz;
    rt_node_rect(u->qt, 0, 0, 0, &lx0, &lz0, &lsx, &lsz);
    /* a 16 m cell overlaps at most 2 x 2 leaves of at least 16 m; more
     * where the leaves are smaller */
    int per = ((int)ceil(CELL / lsx) + 1) * ((int)ceil(CELL / lsz) + 1);
    ug_mask_job *jobs = malloc((size_t)n * (size_t)per * sizeof *jobs);
    if (!jobs)
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    int njobs = 0;
    VkDeviceSize bytes = (VkDeviceSize)TEXELS * TEXELS * (u->nw + 2) * 4;
    for (int i = 0; i < n; i++) {
        bool covered;
        if (!mask_jobs(u, &u->cells[todo[i]], todo[i], jobs, &njobs, &covered, e)) {
            free(jobs);
            return false;
        }
        if (!covered)
            vkCmdFillBuffer(cb, u->masks.buf, bytes * (VkDeviceSize)todo[i], bytes, 0);
    }
    /* after the clears, and after what read the slots before (the last
     * draws, probes and copies) */
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT |
                       VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT |
                       VK_ACCESS_SHADER_READ_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT);
    qsort(jobs, (size_t)njobs, sizeof *jobs, job_order);
    VkDescriptorSet sets[3] = { u->set0, set1, u->mask_set };
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->mask_layout, 0, 3, sets, 0, NULL);
    for (int j = 0; j < njobs; j++) {
        const ug_mask_job *m = &jobs[j];
        if (j == 0 || m->pipe != jobs[j - 1].pipe)
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, m->pipe);
        splat_push push = {
            .patch_xz = { m->x0, m->z0, (float)CELL, 0 },
            .patch_uv = { (float)(m->lx * lsx), (float)(m->lz * lsz), (float)((m->lx + 1) * lsx),
                          (float)((m->lz + 1) * lsz) },
            .info = { (uint32_t)m->slot * TEXELS * TEXELS * (uint32_t)(u->nw + 2), 0,
                      (uint32_t)u->nw, 0 },
        };
        vkCmdPushConstants(cb, u->mask_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatch(cb, TEXELS / 8, TEXELS / 8, 1);
    }
    free(jobs);
    return true;
}

void rt_ug_prepare(rt_ug *u, const rt_camera *c, const splat_frame *fr)
{
    u->time = c->time;
    u->cam_xz[0] = (float)c->position[0];
    u->cam_xz[1] = (float)c->position[2];
    allocate(u, c, fr->view_proj);
}

bool rt_ug_generate(rt_ug *u, VkCommandBuffer cb, const splat_frame *fr, VkDescriptorSet set1,
                    int budget, rt_error *e)
{
    /* the mask pass's frame block: this frame's (the craters' table
     * included), seen from the origin, in the final view (a debug view's
     * early return would leave the texels unwritten) */
    splat_frame *uf = u->frame.map;
    *uf = *fr;
    memset(uf->camera, 0, sizeof uf->camera);
    memset(uf->view, 0, sizeof uf->view);
    for (int k = 0; k < u->p->nsites; k++)
        for (int a = 0; a < 4; a++)
            uf->world[4 * k + a] = 0.0f;
    u->generated = 0;
    if (u->qpool) {
        vkCmdResetQueryPool(cb, u->qpool, 0, 6);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, u->qpool, 0);
    }
    int todo[UG_TODO], n = 0;
    for (int i = 0; i < u->pool && n < (int)(sizeof todo / sizeof *todo); i++) {
        int k = u->order[i];
        if (u->cells[k].state == CELL_PENDING && (budget <= 0 || n < budget))
            todo[n++] = k;
    }
    if (n > 0) {
        if (!record_masks(u, cb, todo, n, set1, e))
            return false;
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
        /* the scatter pass: a workgroup per block and cell */
        uint32_t *g = (uint32_t *)u->gtab.map + 4 * (size_t)u->nblocks;
        for (int i = 0; i < n; i++) {
            const ug_cell *cl = &u->cells[todo[i]];
            g[4 * i] = (uint32_t)cl->ix;
            g[4 * i + 1] = (uint32_t)cl->iz;
            g[4 * i + 2] = (uint32_t)todo[i];
            g[4 * i + 3] = 0;
            u->cells[todo[i]].state = CELL_READY;
        }
        const rt_pack *p = u->p;
        ug_push push = {
            .nw = (uint32_t)u->nw, .cap = u->cap, .nblocks = (uint32_t)u->nblocks,
            .terrain = { (float)p->size[0], (float)p->size[1], (float)p->max_height,
                         (float)p->height_offset },
            .hf = { p->hf_width, p->hf_height },
        };
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->gen_pipe);
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->gen_layout, 0, 1,
                                &u->gen_set, 0, NULL);
        vkCmdPushConstants(cb, u->gen_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatch(cb, (uint32_t)u->nblocks, (uint32_t)n, 1);
        /* the draw, the copy below, the LOD pass and the probes read them */
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                           VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT |
                           VK_ACCESS_TRANSFER_READ_BIT);
        /* the counts, for the stats and the tests (read after the frame) */
        VkBufferCopy all = { 0, 0, u->args.size };
        vkCmdCopyBuffer(cb, u->args.buf, u->args_host.buf, 1, &all);
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    }
    /* every frame: this camera's LOD of every cell's arguments */
    uint32_t pc[4] = { (uint32_t)(u->pool * u->nblocks), (uint32_t)u->nblocks, 0, 0 };
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->lod_pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->lod_layout, 0, 1, &u->lod_set,
                            0, NULL);
    vkCmdPushConstants(cb, u->lod_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, pc);
    vkCmdDispatch(cb, (pc[0] + 63) / 64, 1, 1);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
    rt_ug_record_cull(u, cb, fr);
    if (u->qpool)   /* bottom of pipe: when everything before has finished */
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 1);
    u->generated = n;
    return true;
}

bool rt_ug_visible(const rt_ug *u)
{
    /* ready, or pending and among those rt_ug_generate takes (all of
     * them, up to UG_TODO, in the pool's order) */
    for (int i = 0, pending = 0; u && i < u->pool; i++) {
        const ug_cell *cl = &u->cells[u->order[i]];
        bool ready = cl->state == CELL_READY ||
                     (cl->state == CELL_PENDING && pending++ < UG_TODO);
        if (ready && cl->visible)
            return true;
    }
    return false;
}

void rt_ug_draw(rt_ug *u, VkCommandBuffer cb, bool depth_read_only, VkDescriptorSet set0,
                VkDescriptorSet set1, VkDescriptorSet set0c, const VkViewport *vp,
                const VkRect2D *area)
{
    u->drawn = true;
    if (u->qpool)   /* after the terrain has finished, not when it started */
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 2);
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = depth_read_only ? u->pass_ro : u->pass_att, .framebuffer = u->fb,
        .renderArea = *area,
    };
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdSetViewport(cb, 0, 1, vp);
    vkCmdSetScissor(cb, 0, 1, area);
    VkDescriptorSet sets[3] = { set0, set1, u->draw_set };
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, u->draw_layout, 0, 3, sets, 0, NULL);
    splat_push push = { .patch_xz = { (float)u->radius, (float)u->time, 0, 0 },
                        .info = { u->cap, 0, 0, 0 } };
    vkCmdPushConstants(cb, u->draw_layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof push, &push);
    VkDeviceSize zero = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &u->vbuf.buf, &zero);
    vkCmdBindIndexBuffer(cb, u->ibuf.buf, 0, VK_INDEX_TYPE_UINT32);
    const rt_pack_ug *pu = &u->p->ug;
    /* one draw per key (a block's near or far mesh), opaque first: they
     * hide the rest; within a key the cells front to back */
    for (int cut = 0; cut < 2; cut++) {
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, u->draw_pipe[cut]);
        for (int k = 0; k < u->nkeys; k++)
            if (u->key_used[k] && !(u->key_cs[k] && depth_read_only) &&
                (pu->blocks[u->key_block[k]].cutout != 0) == cut)
                vkCmdDrawIndexedIndirect(cb, u->mdraw.buf, 20 * (VkDeviceSize)k, 1, 20);
    }
    /* the contact shadows on the ground the plants leave visible: after
     * them, so that the depth test drops the shadow's fragments they
     * cover before shading or blending (the same picture as shadows
     * first, covered by the plants: the quad lies on the ground, behind
     * every plant standing on it; the valley's draw took 0.95 ms with
     * the shadows first, 0.75 ms after, on the H100) */
    if (u->shadows) {
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, u->shadow_pipe);
        for (int k = 0; k < u->nkeys; k++)
            if (u->key_used[k] && (u->key_sh[k] || (u->key_shc[k] && !depth_read_only)))
                vkCmdDrawIndexedIndirect(cb, u->mdraw.buf, 20 * (VkDeviceSize)(u->nkeys + k), 1, 20);
    }
    vkCmdEndRenderPass(cb);
    if (u->qpool)   /* the graphics draw's end */
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 4);
    if (depth_read_only)   /* the far blades in compute (undergrowth_craster.c) */
        rt_ug_craster_record(u, cb, set0c, set1);
    if (u->qpool)
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 3);
}

void rt_ug_read_stats(rt_ug *u, rt_ug_stats *st)
{
    memset(st, 0, sizeof *st);
    st->gen_ms = st->draw_ms = st->draw_gfx_ms = st->draw_cs_ms = st->resolve_ms = -1;
    if (!u)
        return;
    st->generated = u->generated;
    const uint32_t *a = u->args_host.map;
    for (int i = 0; i < u->pool; i++) {
        if (u->cells[i].state != CELL_READY)
            continue;
        st->cells++;
        for (int b = 0; b < u->nblocks; b++)
            st->instances += a[((size_t)i * u->nblocks + b) * 5 + 1];
    }
    for (int i = 0; i < u->pool; i++)
        for (int b = 0; b < u->nblocks && u->cells[i].state == CELL_READY; b++)
            st->candidates += (long)u->block_grid[b] * u->block_grid[b];
    const uint32_t *md = u->mdraw_host.map;
    for (int k = 0; u->mdraw_valid && k < u->nkeys; k++) {
        const uint32_t *m = md + 5 * k, *sh = md + 5 * (u->nkeys + k);
        st->drawn += m[1];
        st->triangles += (long)m[1] * (m[0] / 3) + (long)sh[1] * 2;
        st->draws += u->key_used[k] ? !(u->key_cs[k] && u->cr_ran) +
                                          (u->key_sh[k] || (u->key_shc[k] && !u->cr_ran))
                                    : 0;
        if (u->key_cs[k] && u->cr_ran)
            st->drawn_compute += m[1];
        if (k < RT_UG_KEYS_MAX) {
            st->key_drawn[k] = m[1];
            st->key_indices[k] = m[0];
            st->key_block[k] = u->key_block[k];
            st->key_compute[k] = u->key_cs[k] && u->cr_ran;
        }
    }
    if (u->compute && u->cr_ran)
        st->cr_overflow = ((const uint32_t *)u->crstat_host.map)[0];
    st->keys = u->mdraw_valid ? (u->nkeys < RT_UG_KEYS_MAX ? u->nkeys : RT_UG_KEYS_MAX) : 0;
    st->bytes_per_cell = (size_t)TEXELS * TEXELS * (size_t)(u->nw + 2) * 4 +
                         (size_t)u->cap * (32 + 4) + (size_t)u->nblocks * 28;
    if (!u->qpool)
        return;
    uint64_t q[6];
    const VkQueryResultFlags fl = VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT;
    double ms = u->d->props.limits.timestampPeriod * 1e-6;
    if (vkGetQueryPoolResults(u->d->dev, u->qpool, 0, 2, sizeof q, q, sizeof q[0], fl) == VK_SUCCESS)
        st->gen_ms = (double)(q[1] - q[0]) * ms;
    if (u->drawn &&
        vkGetQueryPoolResults(u->d->dev, u->qpool, 2, 2, 2 * sizeof q[0], q + 2, sizeof q[0], fl) ==
            VK_SUCCESS)
        st->draw_ms = (double)(q[3] - q[2]) * ms;
    if (u->drawn &&
        vkGetQueryPoolResults(u->d->dev, u->qpool, 4, 1, sizeof q[0], q + 4, sizeof q[0], fl) ==
            VK_SUCCESS) {
        st->draw_gfx_ms = (double)(q[4] - q[2]) * ms;
        if (u->cr_ran &&
            vkGetQueryPoolResults(u->d->dev, u->qpool, 5, 1, sizeof q[0], q + 5, sizeof q[0], fl) ==
                VK_SUCCESS) {
            st->draw_cs_ms = (double)(q[5] - q[4]) * ms;
            st->resolve_ms = (double)(q[3] - q[5]) * ms;
        }
    }
    u->drawn = false;
}

int rt_ug_read_cell(rt_ug *u, int ix, int iz, rt_ug_instance *out, int max, rt_error *e)
{
    ug_cell *cl = u ? find_cell(u, ix, iz) : NULL;
    if (!cl || cl->state != CELL_READY)
        return 0;
    int slot = (int)(cl - u->cells);
    const uint32_t *a = (const uint32_t *)u->args_host.map + (size_t)slot * u->nblocks * 5;
    rt_buffer st;
    if (!rt_buffer_create(u->d, (VkDeviceSize)u->cap * 32, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true,
                          &st, e))
        return -1;
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(u->d, &cb, e)) {
        rt_buffer_destroy(u->d, &st);
        return -1;
    }
    VkBufferCopy region = { (VkDeviceSize)slot * u->cap * 32, 0, (VkDeviceSize)u->cap * 32 };
    vkCmdCopyBuffer(cb, u->inst.buf, st.buf, 1, &region);
    if (!rt_oneshot_end(u->d, cb, e)) {
        rt_buffer_destroy(u->d, &st);
        return -1;
    }
    int n = 0;
    for (int b = 0; b < u->nblocks; b++)
        for (uint32_t k = 0; k < a[5 * b + 1] && n < max; k++, n++) {
            const uint8_t *src = (const uint8_t *)st.map + 32 * (size_t)(u->block_base[b] + k);
            memcpy(&out[n], src, 32);
        }
    rt_buffer_destroy(u->d, &st);
    return n;
}
