/* far_bake.c — the far atlas baked on the device (`splatc build
 * --far-bake`; abi.h "far atlas bake").
 *
 * The compiler's CPU bake (compiler/far_atlas.c) evaluates every atlas
 * point with its double reference evaluator.  Here each combination's
 * compute variant, with SPLAT_FAR_BAKE defined, shades the same points on
 * the device with the same inputs: the bake grid is the atlas's 2 x 2
 * points per texel, each point shaded by the combination of the leaf cell
 * it falls in (the CPU's rule, evaluated here on the CPU so both pick the
 * same cell), one dispatch per leaf cell and band of rows.  The points
 * come back in bands of at most BAND_BYTES, and far_atlas_reduce (the
 * compiler's) makes the texels of them, as the CPU bake does: the mip
 * chain and the BC blocks stay the compiler's.
 *
 * Set 0 is the terrain's (the renderer's bindings copied) with a frame
 * block of its own whose camera and world sites are the origin and whose
 * destructible area is empty; set 1 the renderer's materials; set 2 the
 * points. */
#include "rt_internal.h"
#include "vk_build.h"
#include "far_atlas.h"
#include "util.h"   /* splat_now */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BAND_BYTES ((VkDeviceSize)32 << 20)
#define POINT_FLOATS 8

typedef struct far_baker {
    rt_device            *d;
    const rt_pack        *p;
    rt_pipelines         *pl;
    VkDescriptorSetLayout set_terrain, set_out;
    VkPipelineLayout      layout;
    VkPipeline           *pipes;        /* per base combination, on first use
                                           (on worker threads: not in keep)  */
    VkDescriptorPool      dpool;
    VkDescriptorSet       set0, set_points;
    rt_buffer             frame, points;
    rt_vk_list            keep;         /* layouts, pool                     */
} far_baker;

static bool bake_pipeline(far_baker *fb, int combo, VkPipeline *out, rt_error *e)
{
    if (!fb->pipes[combo]) {
        const rt_text *t = &fb->p->combos[combo].compute;
        char name[64];
        snprintf(name, sizeof name, "combination %d (far atlas bake)", combo);
        if (!t->mod) {
            char what[160];
            snprintf(what, sizeof what, "the pack has no compute variant of %s", name);
            return rt_fail(e, RT_E_PACK_FIELD, fb->p->dir, what);
        }
        const char *glsl = rt_pack_text(fb->p, t, e);
        if (!glsl)
            return false;
        char *src = rt_glsl_with_defines(glsl, "#define SPLAT_FAR_BAKE 1\n");
        rt_interface in;
        if (!src || !rt_interface_for(fb->p, RT_ROLE_FAR_BAKE, &in)) {
            free(src);
            return rt_fail(e, RT_E_VULKAN, "far atlas bake", "out of memory");
        }
        /* no destroy list: the workers make these at once (the list is
         * not thread-safe); rt_far_bake_destroy destroys them */
        bool ok = rt_vk_compute(fb->d, NULL, &(rt_vk_compute_desc){ .label = name, .glsl = src,
                                    .check = &in, .layout = fb->layout, .cache = fb->pl->cache },
                                &fb->pipes[combo], e);
        rt_interface_free(&in);
        free(src);
        if (!ok)
            return false;
    }
    *out = fb->pipes[combo];
    return true;
}

/* One job of compile_all: the k-th combination the leaf cells name. */
typedef struct compile_jobs {
    far_baker *fb;
    const int *combos;
} compile_jobs;

static bool compile_one(void *ctx, int k, rt_error *e)
{
    compile_jobs *j = ctx;
    VkPipeline pipe;
    return bake_pipeline(j->fb, j->combos[k], &pipe, e);
}

/* The combinations the leaf cells name, each once (*n of them), or NULL
 * when out of memory. */
static int *named_combos(const rt_pack *p, int *n)
{
    const rt_pack_level *L0 = &p->levels[0];
    int *combos = malloc(((size_t)p->nbase + 1) * sizeof *combos);
    bool *seen = calloc((size_t)p->nbase + 1, 1);
    *n = 0;
    for (size_t i = 0; combos && seen && i < (size_t)L0->width * (size_t)L0->height; i++) {
        unsigned id = L0->ids[i];
        if (id != SPLAT_COMBO_HOLE && (int)id < p->nbase && !seen[id]) {
            seen[id] = true;
            combos[(*n)++] = (int)id;
        }
    }
    if (!seen) {
        free(combos);
        combos = NULL;
    }
    free(seen);
    return combos;
}

static bool compile_all(far_baker *fb, int *ncombos, rt_error *e)
{
    int n;
    int *combos = named_combos(fb->p, &n);
    if (!combos)
        return rt_fail(e, RT_E_VULKAN, "far atlas bake", "out of memory");
    compile_jobs j = { .fb = fb, .combos = combos };
    *ncombos = n;
    /* most of a bake's time: glslang, validation and the driver's compiler
     * per combination, on all cores (jobs.c) */
    bool ok = rt_parallel(n, compile_one, &j, e);
    free(combos);
    return ok;
}

static bool make_baker(far_baker *fb, VkDescriptorSet set0_src, const splat_frame *frame,
                       VkDeviceSize band_bytes, rt_error *e)
{
    rt_device *d = fb->d;
    fb->pipes = calloc((size_t)fb->p->nbase + 1, sizeof *fb->pipes);
    if (!fb->pipes)
        return rt_fail(e, RT_E_VULKAN, "far atlas bake", "out of memory");
    VkDescriptorSetLayoutBinding out = { 0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
                                         VK_SHADER_STAGE_COMPUTE_BIT, NULL };
    rt_vk_list *k = &fb->keep;
    if (!rt_terrain_compute_layout(d, &fb->set_terrain, e) ||
        !rt_vk_keep(d, k, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, RT_VK_H(fb->set_terrain), e) ||
        !rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "far atlas bake", &out, 1 },
                          &fb->set_out, e))
        return false;
    VkDescriptorSetLayout sets[3] = { fb->set_terrain, fb->pl->set_material, fb->set_out };
    if (!rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "far atlas bake", .sets = sets,
                          .nsets = 3, .push_stages = VK_SHADER_STAGE_COMPUTE_BIT,
                          .push_bytes = sizeof(splat_push) }, &fb->layout, e))
        return false;
    if (!rt_buffer_create(d, sizeof(splat_frame), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true,
                          &fb->frame, e) ||
        !rt_buffer_create(d, band_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &fb->points, e))
        return false;
    memcpy(fb->frame.map, frame, sizeof *frame);
    VkDescriptorPoolSize sizes[3] = {
        { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 },   /* points, vector shapes */
        { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16 },
        { VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1 },
    };
    VkDescriptorSetLayout ls[2] = { fb->set_terrain, fb->set_out };
    VkDescriptorSet ds[2];
    if (!rt_vk_sets(d, k, &(rt_vk_sets_desc){ .label = "far atlas bake", .sizes = sizes,
                        .nsizes = 3, .layouts = ls, .nsets = 2 }, &fb->dpool, ds, e))
        return false;
    fb->set0 = ds[0];
    fb->set_points = ds[1];
    rt_terrain_compute_set(d, set0_src, fb->set0, fb->frame.buf);
    rt_vk_write_sets(d, &(rt_vk_write){ .set = fb->set_points, .binding = 0,
                                        .type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                        .buf = fb->points.buf }, 1);
    return true;
}

static void destroy_baker(far_baker *fb)
{
    rt_device *d = fb->d;
    for (int k = 0; fb->pipes && k < fb->p->nbase; k++)
        if (fb->pipes[k])
            vkDestroyPipeline(d->dev, fb->pipes[k], NULL);
    free(fb->pipes);
    rt_vk_list_destroy(d, &fb->keep);
    rt_buffer_destroy(d, &fb->points);
    rt_buffer_destroy(d, &fb->frame);
}

/* The leaf cell of each point column (row) of a grid of n points over
 * `texels` heightfield texels: far_atlas.c's rule, in double. */
static int *cells_of(int n, int texels, int cell_texels, int cells)
{
    int *c = malloc((size_t)n * sizeof *c);
    for (int i = 0; c && i < n; i++) {
        int k = (int)((i + 0.5) / n * texels) / cell_texels;
        c[i] = k < 0 ? 0 : k < cells ? k : cells - 1;
    }
    return c;
}

/* Record the dispatches of point rows [j0, j1) into the band buffer. */
static bool record_band(far_baker *fb, VkCommandBuffer cb, const int *cx, const int *cz, int nx,
                        int j0, int j1, const float step[2], rt_error *e)
{
    const rt_pack_level *L0 = &fb->p->levels[0];
    for (int ja = j0; ja < j1;) {
        int jb = ja;
        while (jb < j1 && cz[jb] == cz[ja])
            jb++;
        for (int ia = 0; ia < nx;) {
            int ib = ia;
            while (ib < nx && cx[ib] == cx[ia])
                ib++;
            unsigned id = L0->ids[(size_t)cz[ja] * (size_t)L0->width + (size_t)cx[ia]];
            if (id != SPLAT_COMBO_HOLE && (int)id < fb->p->nbase) {
                VkPipeline pipe = VK_NULL_HANDLE;
                if (!bake_pipeline(fb, (int)id, &pipe, e))
                    return false;
                vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
                splat_push push = {
                    .patch_xz = { step[0], step[1], (float)nx, (float)(ja - j0) },
                    .info = { (uint32_t)ia, (uint32_t)ja, (uint32_t)(ib - ia), (uint32_t)(jb - ja) },
                };
                vkCmdPushConstants(cb, fb->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push,
                                   &push);
                vkCmdDispatch(cb, (uint32_t)(ib - ia + 7) / 8, (uint32_t)(jb - ja + 7) / 8, 1);
            }
            ia = ib;
        }
        ja = jb;
    }
    return true;
}

bool rt_far_bake(rt_device *d, const rt_pack *p, rt_pipelines *pl, VkDescriptorSet set0,
                 VkDescriptorSet set1, const splat_frame *frame, int w, int h, float *albedo,
                 float *normal, float *rough, rt_far_bake_stats *st, rt_error *e)
{
    rt_far_bake_stats ignored;
    st = st ? st : &ignored;
    memset(st, 0, sizeof *st);
    if (w < 1 || h < 1 || w > FAR_ATLAS_MAX_SIDE || h > FAR_ATLAS_MAX_SIDE)
        return rt_fail(e, RT_E_PACK_LIMIT, p->dir, "far atlas side (texels)",
                       (unsigned long long)(w > h ? w : h), "the far atlas's limit",
                       (unsigned long long)FAR_ATLAS_MAX_SIDE);
    if (p->cell_texels < 1)
        return rt_fail(e, RT_E_PACK_FIELD, p->dir, "a leaf cell of no texels");
    enum { SS = FAR_ATLAS_SS };   /* points per texel side */
    int nx = SS * w, nz = SS * h;
    VkDeviceSize row = (VkDeviceSize)nx * POINT_FLOATS * sizeof(float);
    VkDeviceSize limit = d->props.limits.maxStorageBufferRange < BAND_BYTES
                             ? d->props.limits.maxStorageBufferRange : BAND_BYTES;
    int band = (int)(limit / row) / SS * SS;   /* whole texel rows */
    if (band < SS)
        return rt_fail(e, RT_E_PACK_LIMIT, p->dir, "far atlas bake row (bytes)",
                       (unsigned long long)(SS * row), "the device's storage buffer range",
                       (unsigned long long)limit);
    band = band < nz ? band : nz;
    const rt_pack_level *L0 = &p->levels[0];
    int *cx = cells_of(nx, p->hf_width, p->cell_texels, L0->width);
    int *cz = cells_of(nz, p->hf_height, p->cell_texels, L0->height);
    far_baker fb = { .d = d, .p = p, .pl = pl };
    double t0 = splat_now();
    bool ok = cx && cz ? make_baker(&fb, set0, frame, (VkDeviceSize)band * row, e) &&
                             compile_all(&fb, &st->combos, e)
                       : rt_fail(e, RT_E_VULKAN, "far atlas bake", "out of memory");
    double t1 = splat_now();
    st->compile_s = t1 - t0;
    float step[2] = { (float)(p->size[0] / nx), (float)(p->size[1] / nz) };
    for (int j0 = 0; ok && j0 < nz; j0 += band) {
        int j1 = j0 + band < nz ? j0 + band : nz;
        VkCommandBuffer cb;
        ok = rt_oneshot_begin(d, &cb, e);
        if (!ok)
            break;
        vkCmdFillBuffer(cb, fb.points.buf, 0, VK_WHOLE_SIZE, 0);
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
        VkDescriptorSet sets[3] = { fb.set0, set1, fb.set_points };
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, fb.layout, 0, 3, sets, 0, NULL);
        ok = record_band(&fb, cb, cx, cz, nx, j0, j1, step, e);
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
        rt_error scratch = {0};   /* after a recording error: keep that one */
        bool ended = rt_oneshot_end(d, cb, ok ? e : &scratch);
        rt_error_clear(&scratch);
        ok = ok && ended;
        for (int z = j0 / SS; ok && z < j1 / SS; z++)
            far_atlas_reduce((const float *)fb.points.map + (size_t)(SS * z - j0) * nx * POINT_FLOATS,
                             w, albedo + (size_t)z * w * 3, normal + (size_t)z * w * 3,
                             rough + (size_t)z * w);
    }
    st->shade_s = splat_now() - t1;
    destroy_baker(&fb);
    free(cx);
    free(cz);
    return ok;
}

/* How many combinations the leaf cells name (each once): the bake's
 * pipelines; 0 when out of memory. */
int rt_far_bake_combos(const rt_pack *p)
{
    int n;
    int *c = named_combos(p, &n);
    if (!c)
        return 0;
    free(c);
    return n;
}
