/* undergrowth_cull.c — the undergrowth's cull passes on the CPU side
 * (undergrowth.c's top comment says what they do; their GLSL is
 * undergrowth_glsl.c rt_ug_cull_glsl and rt_ug_scan_glsl): the
 * pipelines, the frame's table of keys and entries, the recording. */
#include "undergrowth_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The cull passes' pipelines: count and write (the same GLSL, UG_WRITE),
 * and the scan in one workgroup as wide as the device allows (up to 1024). */
bool rt_ug_cull_pipelines(rt_ug *u, rt_error *e)
{
    const VkPhysicalDeviceLimits *L = &u->d->props.limits;
    uint32_t ls = 1024;
    while (ls > 64 && (ls > L->maxComputeWorkGroupInvocations || ls > L->maxComputeWorkGroupSize[0]))
        ls >>= 1;
    size_t n = strlen(rt_ug_cull_glsl) + strlen(rt_ug_scan_glsl) + 64;
    char *src = malloc(n);
    if (!src)
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    bool ok = true;
    for (int k = 0; k < 3 && ok; k++) {
        if (k < 2)
            snprintf(src, n, "#version 450\n%s%s", k ? "#define UG_WRITE 1\n" : "", rt_ug_cull_glsl);
        else
            snprintf(src, n, "#version 450\n#define UG_LS %u\n%s", ls, rt_ug_scan_glsl);
        VkPipeline *out = k == 0 ? &u->count_pipe : k == 1 ? &u->write_pipe : &u->scan_pipe;
        ok = rt_vk_compute(u->d, &u->keep, &(rt_vk_compute_desc){
                               .label = k == 0 ? "undergrowth cull count"
                                      : k == 1 ? "undergrowth cull write" : "undergrowth cull scan",
                               .glsl = src, .layout = k < 2 ? u->cull_layout : u->scan_layout },
                           out, e);
    }
    free(src);
    return ok;
}

/* Whether block b's mesh at level lv (which it has) can be drawn in
 * compute: opaque or a frond (an alpha cut-out samples its texture per
 * pixel, which the raster pass does not), few enough triangles for the
 * payload's bits. */
static bool cs_level(const rt_ug *u, int b, int lv)
{
    uint32_t mesh[3];
    rt_ug_level_mesh(u, b, lv, mesh);
    return u->cr_frame && u->p->ug.blocks[b].cutout != 2 && mesh[0] / 3 <= (1u << UG_CR_TBITS);
}

/* The mesh level a cell whose nearest point is `near` metres away draws
 * block b with (0 near, 1 far, 2 single triangles), + UG_CS_KEY where
 * that goes to compute. */
static int cell_level(const rt_ug *u, int b, int slot, double near)
{
    const rt_pack_ug *pu = &u->p->ug;
    int far = pu->meshes[pu->blocks[b].mesh].far;
    int cv = near > LOD_NEAR && far >= 0;
    if (cv && u->tri[b][0] && near > LOD_TRI * LOD_NEAR)
        cv = 2;
    if (cs_level(u, b, cv) && rt_ug_craster_fits(u, b, near, ((float *)u->lod.map)[slot]))
        cv += UG_CS_KEY;
    return cv;
}

/* Each visible generated cell's level per block (u->cell_level; 0xff:
 * none), then whether this frame's compute keys would hold enough to pay
 * for the compute passes (a resolve over every pixel, whatever they
 * hold): their cells' candidates times the LOD's fraction, at least
 * UG_CR_MIN.  From the cells alone, not from counts read back, so that a
 * frame's picture does not depend on the frames before it.  Without
 * enough, the levels are those without compute. */
static void cell_levels(rt_ug *u)
{
    double cand = 0;
    for (int pass = 0; pass < 2; pass++) {
        u->cr_frame = u->compute && (pass == 0 || cand >= UG_CR_MIN);
        for (int i = 0; i < u->pool; i++) {
            const ug_cell *cl = &u->cells[i];
            uint8_t *lv = u->cell_level + (size_t)i * u->nblocks;
            bool on = cl->state == CELL_READY && cl->visible;
            double near = cl->dist - CELL * 0.7071;   /* its nearest point, about */
            for (int b = 0; b < u->nblocks; b++) {
                lv[b] = on ? (uint8_t)cell_level(u, b, i, near) : 0xff;
                if (pass == 0 && on && lv[b] >= UG_CS_KEY)
                    cand += (double)u->block_grid[b] * u->block_grid[b] * ((float *)u->lod.map)[i];
            }
        }
        if (!u->cr_frame || cand >= UG_CR_MIN)   /* the levels stand */
            break;
    }
}

/* The cull passes' table for this frame (UG_KEYINFO): keys in the draw's
 * order (opaque blocks first; a block's near mesh, then its far one, then
 * its single-triangle one, then with the compute rasteriser on the same
 * three levels drawn in compute), each key's entries the visible generated
 * cells front to back whose distance picks that mesh (their nearest point
 * beyond LOD_NEAR: the far mesh; beyond LOD_TRI LOD_NEAR: the single
 * triangles) and, for a compute key, whose every instance fits the compute
 * rasteriser's cap (rt_ug_craster_fits) where the block and that mesh can
 * go there (cs_level). */
static void fill_entries(rt_ug *u)
{
    cell_levels(u);
    const rt_pack_ug *pu = &u->p->ug;
    uint32_t *e = u->ent.map;
    int k = 0, n = 0;
    /* contact shadows end where ug_far reaches 1 (undergrowth_glsl.c: 0.8
     * r1, r1 = max(radius - 12, radius / 2)): a cell whose nearest point
     * is farther multiplies the colour by 1 */
    double shadow_end = 0.8 * fmax(u->radius - 12.0, 0.5 * u->radius);
    for (int cut = 0; cut < 2; cut++)
        for (int b = 0; b < u->nblocks; b++) {
            if ((pu->blocks[b].cutout != 0) != cut)
                continue;
            int far = pu->meshes[pu->blocks[b].mesh].far;
            for (int l = 0; l < 2 * UG_LEVELS; l++) {
                int lv = l % UG_LEVELS;
                if ((lv == 1 && far < 0) || (lv == 2 && (far < 0 || !u->tri[b][0])) ||
                    (l >= UG_CS_KEY && !cs_level(u, b, lv)))
                    continue;
                uint32_t *ki = e + UG_KEYINFO + 4 * k;
                rt_ug_level_mesh(u, b, lv, ki);
                /* a compute key's contact shadows are drawn in compute
                 * too (undergrowth_craster.c ug_shadow) */
                bool has = pu->blocks[b].shadow > 0 && u->shadows;
                bool shadows = has;
                e[k] = (uint32_t)n;
                u->key_block[k] = b;
                for (int i = 0; i < u->pool; i++) {
                    int slot = u->order[i];
                    const ug_cell *cl = &u->cells[slot];
                    double near = cl->dist - CELL * 0.7071;   /* its nearest point, about */
                    if (u->cell_level[(size_t)slot * u->nblocks + b] != l)
                        continue;
                    if (shadows && near >= shadow_end)   /* and every entry after */
                        shadows = false, ki[3] = (uint32_t)n;
                    e[UG_ENT0 + n++] = (uint32_t)(slot * u->nblocks + b);
                }
                if (shadows)
                    ki[3] = (uint32_t)n;
                else if (!has)
                    ki[3] = e[k];
                u->key_used[k] = e[k] != (uint32_t)n;
                u->key_cs[k] = l >= UG_CS_KEY;
                u->key_level[k] = (uint8_t)lv;
                u->key_sh[k] = has && l < UG_CS_KEY;
                u->key_shc[k] = has && l >= UG_CS_KEY;
                k++;
            }
        }
    e[k] = (uint32_t)n;
    u->nkeys = k;
    u->nent = n;
}

/* The cull passes (the top comment; undergrowth_glsl.c rt_ug_cull_glsl):
 * count, scan, write, then the draws per key copied back for the stats. */
void rt_ug_record_cull(rt_ug *u, VkCommandBuffer cb, const splat_frame *fr)
{
    if (u->compute)
        rt_ug_craster_frame(u, fr);
    fill_entries(u);
    u->mdraw_valid = false;
    if (u->nent == 0)
        return;
    ug_cull_push pc = { .cam = { fr->camera[0], fr->camera[1], fr->camera[2], (float)u->radius },
                        .info = { (uint32_t)u->nblocks, (uint32_t)u->nent, 0, 0 } };
    const float *m = fr->view_proj;   /* column-major: row r is m[r], m[4 + r], ... */
    static const int row[5] = { 0, 0, 1, 1, 2 };
    for (int k = 0; k < 5; k++) {
        double sg = k == 4 || (k & 1) ? -1.0 : 1.0, v[4], len = 0;
        for (int c = 0; c < 4; c++)
            v[c] = m[4 * c + 3] + sg * m[4 * c + row[k]];
        for (int c = 0; c < 3; c++)
            len += v[c] * v[c];
        len = len > 0 ? sqrt(len) : 1.0;
        for (int c = 0; c < 4; c++)
            pc.plane[k][c] = (float)(v[c] / len);
    }
    uint32_t gx = u->nent < 65535 ? (uint32_t)u->nent : 65535u;
    uint32_t gy = ((uint32_t)u->nent + gx - 1) / gx;
    const VkPipelineStageFlags cs = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->cull_layout, 0, 1, &u->cull_set,
                            0, NULL);
    vkCmdPushConstants(cb, u->cull_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->count_pipe);
    vkCmdDispatch(cb, gx, gy, 1);
    rt_cmd_barrier(cb, cs, VK_ACCESS_SHADER_WRITE_BIT, cs,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    uint32_t sp[4] = { (uint32_t)u->nent, (uint32_t)u->nkeys, u->p->ug.nindices,
                       u->p->ug.nvertices };   /* the shadow quad */
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->scan_pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->scan_layout, 0, 1, &u->scan_set,
                            0, NULL);
    vkCmdPushConstants(cb, u->scan_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof sp, sp);
    vkCmdDispatch(cb, 1, 1, 1);
    rt_cmd_barrier(cb, cs, VK_ACCESS_SHADER_WRITE_BIT, cs, VK_ACCESS_SHADER_READ_BIT);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->write_pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->cull_layout, 0, 1, &u->cull_set,
                            0, NULL);
    vkCmdPushConstants(cb, u->cull_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
    vkCmdDispatch(cb, gx, gy, 1);
    rt_cmd_barrier(cb, cs, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                       VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT |
                       VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy all = { 0, 0, (VkDeviceSize)u->nkeys * 40 };
    vkCmdCopyBuffer(cb, u->mdraw.buf, u->mdraw_host.buf, 1, &all);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    u->mdraw_valid = true;
}
