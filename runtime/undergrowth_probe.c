/* undergrowth_probe.c — the probe pass (tests only, made on first use):
 * counts the instances the last frame's draw keeps per ring around the
 * camera, and evaluates the vertex stage's wind at given points, both
 * with the draw's own GLSL functions (undergrowth_glsl.c UG_GLSL_FUNCS). */
#include "undergrowth_impl.h"

#include <stdlib.h>
#include <string.h>

/* ---- the probe pass (tests) -------------------------------------------------------- */

/* The probe's pipeline and an output buffer of at least `bytes`. */
static bool probe_make(rt_ug *u, VkDeviceSize bytes, rt_error *e)
{
    rt_device *d = u->d;
    if (!u->probe_pipe) {
        const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
        const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        VkDescriptorSetLayoutBinding b[] = {
            { 0, sb, 1, cs, NULL }, { 1, sb, 1, cs, NULL }, { 2, sb, 1, cs, NULL },
        };
        VkDescriptorPoolSize size = { sb, 3 };
        if (!rt_vk_set_layout(d, &u->keep, &(rt_vk_set_layout_desc){ "undergrowth probe", b, 3 },
                              &u->probe_sl, e) ||
            !rt_vk_layout(d, &u->keep, &(rt_vk_layout_desc){ .label = "undergrowth probe",
                              .sets = &u->probe_sl, .nsets = 1, .push_stages = cs,
                              .push_bytes = 32 }, &u->probe_layout, e) ||
            !rt_vk_sets(d, &u->keep, &(rt_vk_sets_desc){ .label = "undergrowth probe",
                            .sizes = &size, .nsizes = 1, .layouts = &u->probe_sl, .nsets = 1 },
                        &u->probe_pool, &u->probe_set, e) ||
            !rt_vk_compute(d, &u->keep, &(rt_vk_compute_desc){ .label = "undergrowth probe",
                               .glsl = rt_ug_probe_glsl, .layout = u->probe_layout },
                           &u->probe_pipe, e))
            return false;
    }
    if (u->probe_out.size < bytes) {
        rt_buffer_destroy(d, &u->probe_out);
        if (!rt_buffer_create(d, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, &u->probe_out, e))
            return false;
        const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        rt_vk_write w[3] = { { u->probe_set, 0, sb, u->inst.buf },
                             { u->probe_set, 1, sb, u->draw_args.buf },
                             { u->probe_set, 2, sb, u->probe_out.buf } };
        rt_vk_write_sets(d, w, 3);
    }
    return true;
}

typedef struct probe_push {
    float    ring[4];     /* camera x, z; radius (mode 0) or time (1); ring width */
    uint32_t info[4];     /* mode, rings or points, cell slot, blocks          */
} probe_push;

static bool probe_run(rt_ug *u, const probe_push *pp, const int *slots, int nslots,
                      uint32_t groups, rt_error *e)
{
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(u->d, &cb, e))
        return false;
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->probe_pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->probe_layout, 0, 1,
                            &u->probe_set, 0, NULL);
    for (int i = 0; i < (slots ? nslots : 1); i++) {
        probe_push q = *pp;
        if (slots)
            q.info[2] = (uint32_t)slots[i];
        vkCmdPushConstants(cb, u->probe_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof q, &q);
        vkCmdDispatch(cb, groups, 1, 1);
    }
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    return rt_oneshot_end(u->d, cb, e);
}

int rt_ug_probe_rings(rt_ug *u, double width, int nrings, uint32_t *counts, rt_error *e)
{
    if (!u || nrings <= 0 || !(width > 0))
        return 0;
    if (!probe_make(u, (VkDeviceSize)nrings * 8, e))
        return -1;
    memset(u->probe_out.map, 0, (size_t)nrings * 8);
    int *slots = malloc(sizeof *slots * (size_t)u->pool), n = 0;
    if (!slots) {
        rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
        return -1;
    }
    for (int i = 0; i < u->pool; i++)
        if (u->cells[i].state == CELL_READY)
            slots[n++] = i;
    probe_push pp = { { u->cam_xz[0], u->cam_xz[1], (float)u->radius, (float)width },
                      { 0, (uint32_t)nrings, 0, (uint32_t)u->nblocks } };
    bool ok = n == 0 || probe_run(u, &pp, slots, n, (uint32_t)u->nblocks, e);
    free(slots);
    if (!ok)
        return -1;
    memcpy(counts, u->probe_out.map, (size_t)nrings * 8);
    return n;
}

bool rt_ug_probe_wind(rt_ug *u, float *points, int n, double time, rt_error *e)
{
    if (!u || n <= 0)
        return true;
    if (!probe_make(u, (VkDeviceSize)n * 48, e))
        return false;
    memcpy(u->probe_out.map, points, (size_t)n * 48);
    probe_push pp = { { 0, 0, (float)time, 0 }, { 1, (uint32_t)n, 0, 0 } };
    if (!probe_run(u, &pp, NULL, 0, ((uint32_t)n + 63) / 64, e))
        return false;
    memcpy(points, u->probe_out.map, (size_t)n * 48);
    return true;
}

/* ---- the drawn list (tests) --------------------------------------------------------- */

int rt_ug_read_drawn(rt_ug *u, rt_ug_instance *out, int *key, int max, rt_error *e)
{
    if (!u || !u->mdraw_valid)
        return 0;
    const uint32_t *md = u->mdraw_host.map;
    uint32_t total = 0;
    for (int k = 0; k < u->nkeys; k++)
        total += md[5 * k + 1];
    uint32_t n = total < (uint32_t)(max > 0 ? max : 0) ? total : (uint32_t)(max > 0 ? max : 0);
    if (n == 0)
        return (int)total;
    rt_buffer iv, ii;
    VkDeviceSize ib = u->inst.size;
    if (!rt_buffer_create(u->d, (VkDeviceSize)n * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &iv, e))
        return -1;
    if (!rt_buffer_create(u->d, ib, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &ii, e)) {
        rt_buffer_destroy(u->d, &iv);
        return -1;
    }
    VkCommandBuffer cb;
    bool ok = rt_oneshot_begin(u->d, &cb, e);
    if (ok) {
        /* the keys' lists are contiguous from the first key's first
         * instance (the scan pass's offsets start at 0) */
        VkBufferCopy a = { 0, 0, (VkDeviceSize)n * 4 }, b = { 0, 0, ib };
        vkCmdCopyBuffer(cb, u->vis.buf, iv.buf, 1, &a);
        vkCmdCopyBuffer(cb, u->inst.buf, ii.buf, 1, &b);
        ok = rt_oneshot_end(u->d, cb, e);
    }
    for (uint32_t i = 0; ok && i < n; i++) {
        uint32_t at = ((const uint32_t *)iv.map)[i];
        memcpy(&out[i], (const uint8_t *)ii.map + 32 * (size_t)at, 32);
        if (key) {
            int k = 0;
            while (k + 1 < u->nkeys && i >= md[5 * k + 4] + md[5 * k + 1])
                k++;
            key[i] = k;
        }
    }
    rt_buffer_destroy(u->d, &iv);
    rt_buffer_destroy(u->d, &ii);
    return ok ? (int)total : -1;
}
