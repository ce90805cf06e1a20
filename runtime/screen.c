/* screen.c — screen-space terrain shading (Moore 2018, "Screen Space
 * Shading"): after a depth-only geometry pass (render_record.c draws the patches
 * with rt_pipelines_depth), a classification compute pass takes, per 8x8
 * pixel tile, the union of the material sets of the leaf cells its terrain
 * pixels fall in (the pack's level-0 combination map), picks the cheapest
 * compiled combination whose set covers it (else the über-shader) and
 * appends the tile to that combination's list with an indirect dispatch
 * count; then one indirect dispatch per list runs that composite's compute
 * variant (abi.h "compute stage"), which lights and writes the pixels.
 *
 * The search follows the view, not the world (issue 29): each frame the
 * materials of the leaf cells that the selection's frustum holds are
 * renumbered densely (one mask word while at most 32 are in view), and
 * the search tries only the candidates, the combinations no cheaper one
 * dominates over those materials (rt_class_view); it picks what the
 * search over every combination would, so pictures do not change.
 *
 * Lists live in one buffer, a region of `stride` entries per list (list
 * k at k * stride; k = ncombos is the über-shader's; stride is the tile
 * count rounded up to SPLAT_SORT_TILES_MAX), so one pass with one atomic per
 * tile builds them, no prefix sum.  With pixel sorting (abi.h SPLAT_SORT,
 * rt_pixel_sort) a workgroup shades sort_tiles (4 to 16) tiles of a list:
 * a one-workgroup pass after the classification pads each list to that
 * multiple and writes the grouped dispatch sizes beside the counts.  Pipelines are compiled on
 * first use: a list that gets tiles but has no pipeline yet is compiled
 * after the frame and the frame is drawn again (rt_screen_missing), so a
 * returned frame is always complete and the steady state reads back only
 * the list counts.  The classification visits the tiles by rows, or in
 * 4x4 blocks of tiles (rt_screen_tile_blocks), so a list's consecutive
 * tiles, a sorting workgroup's 16, lie together; pictures do not change. */
#include "rt_internal.h"
#include "vk_build.h"
#include "screen_glsl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_WORDS 16     /* material set bits per tile: 512 materials */

struct rt_screen {
    rt_device            *d;
    const rt_pack        *p;
    int                   width, height, tiles_x, tiles_y, ntiles;
    int                   stride;            /* entries per list             */
    bool                  sort;              /* pixels sorted (SPLAT_SORT)   */
    int                   sort_tiles;        /* tiles per sorting workgroup  */
    VkPipeline            group;             /* pads lists, grouped args     */
    int                   nlists;            /* ncombos + 1 (über)          */
    int                   words;             /* material set words; 0: every
                                                tile goes to the über list  */
    VkRenderPass          depth_pass;
    VkFramebuffer         depth_fb;
    VkDescriptorSetLayout set_layout;        /* set 2 of the classification */
    VkPipelineLayout      layout;
    VkPipeline            classify;
    VkDescriptorPool      pool;
    VkDescriptorSet       set;
    /* device-local: info (uploaded once), tiles, args, counters (a GPU
     * reads and atomically updates them; host memory would go over the
     * bus); host-visible: args_reset (the per-frame reset source) and
     * readback (args and counters copied back after the frame) */
    rt_buffer             info, tiles, args, args_reset, counters, readback;
    unsigned             *dispatched;        /* per list: variant + 1 drawn  */
    unsigned char        *stand_in;          /* per list: the rt_stand_in that
                                                drew it while its pipeline is
                                                made (async_compile.c)      */
    VkImage               color_img;
    bool                  raycast;           /* depth by ray casting          */
    VkPipeline            raycaster;
    rt_image              maxmip, rdepth;    /* pyramid; R32F depth           */
    rt_buffer             depth_copy;        /* rdepth on its way to a D32    */
    VkSampler             mip_sampler;       /* every level (texelFetch)      */
    int                   mip_levels;
    bool                  rdepth_ready;      /* in GENERAL layout             */
    bool                  wide;              /* classification: a workgroup
                                                per tile (GPUs), else an
                                                invocation per tile (CPUs)   */
    bool                  blocks;            /* tiles classified in 4x4
                                                blocks (rt_screen_tile_blocks) */
    /* the classification's view (rt_class_view): recomputed where the
     * selection's materials change, uploaded each frame */
    VkPipeline            classify1;         /* WORDS 1: <= 32 in view; NULL:
                                                classify is that one         */
    uint32_t             *order;             /* combinations, cost order     */
    float                *dist;              /* [lo, hi] per combination     */
    uint32_t            **node_masks;        /* per level, per node: words   */
    uint32_t             *vmask, *vmask_last; /* materials in view (words)   */
    bool                  view_built, view_no_classes;
    double                view_margin;       /* m: 1/16 cell                 */
    rt_class_view         view;
    uint32_t              view_at;           /* the view block in info, words */
    /* the far atlas (far.c): list ncombos + 1 when far_ok */
    bool                  far_ok;            /* the pack has one, the device
                                                samples BC formats          */
    float                 far_distance;      /* m; 0: off (rt_screen_far)    */
    const rt_far         *far;               /* the renderer's               */
    VkPipeline            far_pipe[2];       /* plain, counting              */
    rt_vk_list            keep;              /* every Vulkan object but buffers
                                                and images                    */
};


/* Cheapest first: the pack's cost, then fewer materials, then id. */
static const rt_pack *sort_pack;
static int by_cost(const void *a, const void *b)
{
    const rt_pack_combo *x = &sort_pack->combos[*(const uint32_t *)a];
    const rt_pack_combo *y = &sort_pack->combos[*(const uint32_t *)b];
    if (x->cost != y->cost)
        return x->cost < y->cost ? -1 : 1;
    if (x->nmaterials != y->nmaterials)
        return x->nmaterials - y->nmaterials;
    return (*(const uint32_t *)a > *(const uint32_t *)b) - (*(const uint32_t *)a < *(const uint32_t *)b);
}

/* The classification's data (info): the header, per combination its
 * distance interval [lo, hi] (float bits), the leaf cells' combinations,
 * then the view block (rt_class_view) the frame uploads: ncand, words, 0,
 * 0, cand[ncombos], rec[ncombos][1 + words]. */
static bool fill_info(rt_screen *s, rt_error *e)
{
    const rt_pack *p = s->p;
    const rt_pack_level *leaf = &p->levels[0];
    size_t n = (size_t)p->ncombos;
    size_t cells = (size_t)leaf->width * (size_t)leaf->height;
    int fw = s->words > 0 ? s->words : 1;
    s->view_at = (uint32_t)(2 * n + cells);
    size_t words = 8 + 2 * n + cells + 4 + n + n * (size_t)(1 + fw);
    rt_buffer staging;
    if (!rt_buffer_create(s->d, words * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, &s->info, e) ||
        !rt_buffer_create(s->d, words * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, &staging, e))
        return false;
    uint32_t *u = staging.map;
    memset(u, 0, words * 4);
    u[0] = (uint32_t)n;
    u[1] = (uint32_t)s->words;
    u[2] = (uint32_t)leaf->width;
    u[3] = (uint32_t)leaf->height;
    u[4] = (uint32_t)s->stride;   /* the list stride; >= the tile count */
    u[5] = (uint32_t)p->nbase;
    u[6] = (uint32_t)p->cell_texels;
    u[7] = (uint32_t)s->tiles_x;
    for (size_t i = 0; i < n; i++)
        s->order[i] = (uint32_t)i;
    sort_pack = p;
    qsort(s->order, n, sizeof *s->order, by_cost);
    float *dist = (float *)(u + 8);   /* [lo, hi] per combination */
    for (size_t i = 0; i < n; i++) {
        /* rounded inwards: a class is never used outside its interval */
        float lo = (float)p->combos[i].dlo, hi = (float)p->combos[i].dhi;
        dist[2 * i] = lo < p->combos[i].dlo ? nextafterf(lo, INFINITY) : lo;
        dist[2 * i + 1] = hi > p->combos[i].dhi ? nextafterf(hi, 0.0f) : hi;
        s->dist[2 * i] = dist[2 * i];
        s->dist[2 * i + 1] = dist[2 * i + 1];
    }
    uint32_t *map = u + 8 + 2 * n;
    for (size_t i = 0; i < cells; i++)
        map[i] = leaf->ids[i];
    VkCommandBuffer cb;
    bool ok = rt_oneshot_begin(s->d, &cb, e);
    if (ok) {
        VkBufferCopy c = { 0, 0, words * 4 };
        vkCmdCopyBuffer(cb, staging.buf, s->info.buf, 1, &c);
        ok = rt_oneshot_end(s->d, cb, e);
    }
    rt_buffer_destroy(s->d, &staging);
    return ok;
}

/* ---- the materials in view (runtime/class_view.c builds the search's view) --- */

/* Node (L, x, z)'s visible leaves' materials into s->vmask: down the
 * quadtree under a selected patch, past nodes the frustum does not hold
 * and nodes with nothing new. */
static void view_node(rt_screen *s, const rt_quadtree *q, int L, int x, int z)
{
    const rt_pack *p = s->p;
    int W = s->words;
    const uint32_t *m = s->node_masks[L] +
                        ((size_t)z * (size_t)p->levels[L].width + (size_t)x) * (size_t)W;
    bool fresh = false;
    for (int w = 0; w < W && !fresh; w++)
        fresh = (m[w] & ~s->vmask[w]) != 0;
    if (!fresh || !rt_quadtree_node_visible(q, L, x, z, s->view_margin))
        return;
    if (L == 0) {
        for (int w = 0; w < W; w++)
            s->vmask[w] |= m[w];
        return;
    }
    for (int c = 0; c < 4; c++) {
        int cx = 2 * x + (c & 1), cz = 2 * z + (c >> 1);
        if (cx < p->levels[L - 1].width && cz < p->levels[L - 1].height)
            view_node(s, q, L - 1, cx, cz);
    }
}

/* The materials in view (s->vmask): those of the leaf cells under the
 * selected patches whose boxes, widened by 1/16 cell, the frustum holds
 * (a pixel within 1/64 cell of an edge counts for the cell beyond).  A
 * cell outside that would send its tile to the über-shader
 * (RT_CLASS_OUTSIDE): the boxes hold everything drawn, so none should. */
static void view_materials(rt_screen *s, const rt_quadtree *q)
{
    memset(s->vmask, 0, (size_t)s->words * sizeof *s->vmask);
    for (int i = 0; i < q->npatches; i++) {
        const rt_patch *pt = &q->patches[i];
        if (pt->level < s->p->nlevels)
            view_node(s, q, pt->level, pt->x, pt->z);
    }
}

/* Per level, per node, the materials of the leaf cells under it. */
static bool make_node_masks(rt_screen *s)
{
    const rt_pack *p = s->p;
    int W = s->words;
    s->node_masks = calloc((size_t)p->nlevels, sizeof *s->node_masks);
    if (!s->node_masks)
        return false;
    for (int L = 0; L < p->nlevels; L++) {
        const rt_pack_level *lv = &p->levels[L];
        s->node_masks[L] = calloc((size_t)lv->width * (size_t)lv->height * (size_t)W,
                                  sizeof **s->node_masks);
        if (!s->node_masks[L])
            return false;
        for (int z = 0; z < lv->height; z++)
            for (int x = 0; x < lv->width; x++) {
                uint32_t *m = s->node_masks[L] + ((size_t)z * (size_t)lv->width + (size_t)x) * (size_t)W;
                if (L == 0) {
                    int id = lv->ids[(size_t)z * (size_t)lv->width + (size_t)x];
                    for (int k = 0; id < p->ncombos && k < p->combos[id].nmaterials; k++) {
                        int mat = p->combos[id].materials[k];
                        if (mat >= 0 && mat < p->nmaterials)
                            m[mat / 32] |= 1u << (mat % 32);
                    }
                    continue;
                }
                const rt_pack_level *below = &p->levels[L - 1];
                for (int c = 0; c < 4; c++) {
                    int cx = 2 * x + (c & 1), cz = 2 * z + (c >> 1);
                    if (cx >= below->width || cz >= below->height)
                        continue;
                    const uint32_t *k = s->node_masks[L - 1] +
                                        ((size_t)cz * (size_t)below->width + (size_t)cx) * (size_t)W;
                    for (int w = 0; w < W; w++)
                        m[w] |= k[w];
                }
            }
    }
    return true;
}

/* The mesh's height at corner (x, z) in metres, as the shaders read it:
 * the heightfield sampled bilinearly at uv = (x / W, z / H), the mean of
 * the (clamped) texels x-1..x, z-1..z (weights of exactly one half). */
static double corner_height(const rt_pack *p, int x, int z)
{
    int W = p->hf_width, H = p->hf_height;
    double sum = 0;
    for (int k = 0; k < 4; k++) {
        int cx = x - 1 + (k & 1), cz = z - 1 + (k >> 1);
        cx = cx < 0 ? 0 : cx >= W ? W - 1 : cx;
        cz = cz < 0 ? 0 : cz >= H ? H - 1 : cz;
        sum += p->heights[(size_t)cz * (size_t)W + (size_t)cx];
    }
    return sum / 4.0 / 65535.0 * p->max_height + p->height_offset;
}

/* The maximum-height pyramid of the ray caster (rt_screen_raycast_glsl), metres. */
static bool make_maxmip(rt_screen *s, rt_error *e)
{
    const rt_pack *p = s->p;
    int W = p->hf_width, H = p->hf_height, K = 8;
    while (K > 0 && ((W >> K) < 1 || (H >> K) < 1))
        K--;
    int PW = ((W + (1 << K) - 1) >> K) << K, PH = ((H + (1 << K) - 1) >> K) << K;
    if ((uint32_t)PW > s->d->props.limits.maxImageDimension2D ||
        (uint32_t)PH > s->d->props.limits.maxImageDimension2D)
        return rt_fail(e, RT_E_PACK_LIMIT, p->dir, "the ray caster's height pyramid width",
                       (unsigned long long)(PW > PH ? PW : PH), "maxImageDimension2D",
                       (unsigned long long)s->d->props.limits.maxImageDimension2D);
    size_t total = 0;
    for (int k = 0; k <= K; k++)
        total += (size_t)(PW >> k) * (size_t)(PH >> k);
    float *all = malloc(total * sizeof *all);
    const uint8_t **levels = calloc((size_t)K + 1, sizeof *levels);
    if (!all || !levels) {
        free(all);
        free(levels);
        return rt_fail(e, RT_E_VULKAN, "ray caster", "out of memory");
    }
    /* a margin for the GPU's float rounding of texel * max_height */
    double margin = 1e-4 * (fabs(p->max_height) + fabs(p->height_offset)) + 1e-3;
    float *l0 = all;
    /* Texel (i, j) holds the highest of its four corners, each the mean
     * of the four texels around it (corner_height).  Metres grow with the
     * corner's integer sum where max_height >= 0, so the highest sum is
     * converted once, to the same double as the highest of the four
     * conversions; corner rows are summed once each (two rows kept), not
     * 16 reads a texel: colorado's 2401 x 1201 took 0.2-0.3 s on the H100's
     * host, before the first picture. */
    uint32_t *crow = p->max_height >= 0 ? malloc(2 * ((size_t)W + 1) * sizeof *crow) : NULL;
    for (int j = 0; j < PH; j++) {
        float *out = l0 + (size_t)j * (size_t)PW;
        if (j >= H) {
            for (int i = 0; i < PW; i++)
                out[i] = -1e30f;
            continue;
        }
        if (!crow) {   /* a negative max_height: the plain definition */
            for (int i = 0; i < PW; i++) {
                double m = -1e30;
                for (int k = 0; k < 4 && i < W; k++)
                    m = fmax(m, corner_height(p, i + (k & 1), j + (k >> 1)));
                out[i] = (float)(m > -1e30 ? m + margin : -1e30);
            }
            continue;
        }
        for (int r = 0; r < 2; r++) {   /* corner rows j and j + 1 */
            uint32_t *c = crow + (size_t)r * ((size_t)W + 1);
            int cz0 = j + r - 1, cz1 = j + r;
            cz0 = cz0 < 0 ? 0 : cz0 >= H ? H - 1 : cz0;
            cz1 = cz1 >= H ? H - 1 : cz1;
            const uint16_t *a = p->heights + (size_t)cz0 * (size_t)W;
            const uint16_t *b = p->heights + (size_t)cz1 * (size_t)W;
            for (int x = 0; x <= W; x++) {
                int x0 = x - 1 < 0 ? 0 : x - 1, x1 = x >= W ? W - 1 : x;
                c[x] = (uint32_t)a[x0] + a[x1] + b[x0] + b[x1];
            }
        }
        const uint32_t *c0 = crow, *c1 = crow + (size_t)W + 1;
        for (int i = 0; i < PW; i++) {
            if (i >= W) {
                out[i] = -1e30f;
                continue;
            }
            uint32_t m = c0[i] > c0[i + 1] ? c0[i] : c0[i + 1];
            m = c1[i] > m ? c1[i] : m;
            m = c1[i + 1] > m ? c1[i + 1] : m;
            double h = (double)m / 4.0 / 65535.0 * p->max_height + p->height_offset;
            out[i] = (float)(h + margin);
        }
    }
    free(crow);
    levels[0] = (const uint8_t *)l0;
    float *prev = l0;
    for (int k = 1; k <= K; k++) {
        int w = PW >> k, h = PH >> k, pw = PW >> (k - 1);
        float *cur = prev + (size_t)pw * (size_t)(PH >> (k - 1));
        for (int j = 0; j < h; j++)
            for (int i = 0; i < w; i++) {
                const float *q = prev + (size_t)(2 * j) * (size_t)pw + (size_t)(2 * i);
                float m = q[0] > q[1] ? q[0] : q[1];
                m = q[pw] > m ? q[pw] : m;
                m = q[pw + 1] > m ? q[pw + 1] : m;
                cur[(size_t)j * (size_t)w + (size_t)i] = m;
            }
        levels[k] = (const uint8_t *)cur;
        prev = cur;
    }
    s->mip_levels = K + 1;
    if (!rt_vk_sampler(s->d, &s->keep, &(rt_vk_sampler_desc){ .label = "height pyramid",
                           .wrap = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                           .max_lod = VK_LOD_CLAMP_NONE }, &s->mip_sampler, e)) {
        free(levels);
        free(all);
        return false;
    }
    bool ok = rt_image_create(s->d, (uint32_t)PW, (uint32_t)PH, 1, false, (uint32_t)K + 1,
                              VK_FORMAT_R32_SFLOAT,
                              VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT, &s->maxmip, e) &&
              rt_image_upload_levels(s->d, &s->maxmip, levels, e);
    free(levels);
    free(all);
    return ok;
}

static bool make_depth_pass(rt_screen *s, const rt_image *depth, rt_error *e)
{
    /* The last frame's compute reads finish before the depth is written;
     * the depth is visible to this frame's compute passes. */
    VkSubpassDependency dep[2] = {
        { VK_SUBPASS_EXTERNAL, 0, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
          VK_ACCESS_SHADER_READ_BIT,
          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT, 0 },
        { 0, VK_SUBPASS_EXTERNAL,
          VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT, 0 },
    };
    return rt_vk_pass(s->d, &s->keep, &(rt_vk_pass_desc){ .label = "screen depth",
                          .depth = { .format = VK_FORMAT_D32_SFLOAT,
                                     .load = VK_ATTACHMENT_LOAD_OP_CLEAR,
                                     .final = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL },
                          .deps = dep, .ndeps = 2 }, &s->depth_pass, e) &&
           rt_vk_fb(s->d, &s->keep, &(rt_vk_fb_desc){ .label = "screen depth",
                        .pass = s->depth_pass, .views = &depth->view, .nviews = 1,
                        .width = (uint32_t)s->width, .height = (uint32_t)s->height },
                    &s->depth_fb, e);
}

/* A compute pipeline of the runtime's own GLSL over s->layout. */
static bool own_pipeline(rt_screen *s, const rt_pipelines *pl, const char *head, const char *body,
                         const char *name, VkPipeline *out, rt_error *e)
{
    rt_device *d = s->d;
    size_t n = strlen(head) + strlen(SPLAT_GLSL_TERRAIN) + strlen(SPLAT_GLSL_SKY) +
               strlen(body) + 32;
    char *src = malloc(n);
    if (!src)
        return rt_fail(e, RT_E_VULKAN, name, "out of memory");
    snprintf(src, n, "#version 450\n%s%s%s%s", head, SPLAT_GLSL_TERRAIN, SPLAT_GLSL_SKY, body);
    bool ok = rt_vk_compute(d, &s->keep, &(rt_vk_compute_desc){ .label = name, .glsl = src,
                                .layout = s->layout, .cache = pl->cache }, out, e);
    free(src);
    return ok;
}

/* Whether the classification may append through subgroup operations. */
static bool can_aggregate(rt_device *d)
{
    VkPhysicalDeviceSubgroupProperties sp = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES,
    };
    VkPhysicalDeviceProperties2 p2 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
        .pNext = &sp,
    };
    vkGetPhysicalDeviceProperties2(d->phys, &p2);
    const VkSubgroupFeatureFlags need = VK_SUBGROUP_FEATURE_VOTE_BIT |
        VK_SUBGROUP_FEATURE_BALLOT_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
    return (sp.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
           (sp.supportedOperations & need) == need;
}

/* Set 2 (lists, counts, the pyramid and the ray-cast depth), the layout,
 * the classification and ray-casting pipelines. */
static bool make_compute(rt_screen *s, const rt_pipelines *pl, VkSampler nearest, rt_error *e)
{
    rt_device *d = s->d;
    const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType cis = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    VkDescriptorSetLayoutBinding b[8] = {
        { 0, sb, 1, cs, NULL }, { 1, sb, 1, cs, NULL }, { 2, sb, 1, cs, NULL },
        { 3, cis, 1, cs, NULL }, { 4, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs, NULL },
    };
    uint32_t nb = s->raycast ? 5 : 3;
    for (uint32_t k = 0; s->far_ok && k < 3; k++)   /* far.c's atlas, bindings 5-7 */
        b[nb++] = (VkDescriptorSetLayoutBinding){ 5 + k, cis, 1, cs, NULL };
    VkDescriptorSetLayout sets[3] = { pl->set_terrain, pl->set_material, VK_NULL_HANDLE };
    VkDescriptorPoolSize sizes[3] = {
        { sb, 3 }, { cis, (s->raycast ? 1 : 0) + (s->far_ok ? 3 : 0) },
        { VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1 },
    };
    rt_vk_list *k = &s->keep;
    if (!rt_vk_set_layout(d, k, &(rt_vk_set_layout_desc){ "classification", b, nb },
                          &s->set_layout, e))
        return false;
    sets[2] = s->set_layout;
    if (!rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "classification", .sets = sets,
                          .nsets = 3, .push_stages = cs, .push_bytes = sizeof(splat_push) },
                      &s->layout, e) ||
        !rt_vk_sets(d, k, &(rt_vk_sets_desc){ .label = "classification", .sizes = sizes,
                        .nsizes = s->raycast ? 3 : s->far_ok ? 2 : 1,
                        .layouts = &s->set_layout, .nsets = 1 }, &s->pool, &s->set, e))
        return false;
    VkBuffer bufs[3] = { s->info.buf, s->tiles.buf, s->args.buf };
    VkDescriptorImageInfo ii[8] = {
        [3] = { s->mip_sampler, s->maxmip.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL },
        [4] = { VK_NULL_HANDLE, s->rdepth.view, VK_IMAGE_LAYOUT_GENERAL },
    };
    for (int i = 0; s->far_ok && i < 3; i++)
        ii[5 + i] = rt_far_image_info(s->far, i);
    rt_vk_write w[8];
    for (uint32_t i = 0; i < nb; i++) {
        uint32_t at = b[i].binding;
        w[i] = (rt_vk_write){ .set = s->set, .binding = at, .type = b[i].descriptorType };
        if (at < 3)
            w[i].buf = bufs[at];
        else
            w[i].images = &ii[at], w[i].count = 1;
    }
    rt_vk_write_sets(d, w, nb);

    char head[320];
    bool sub = can_aggregate(d);
    s->wide = sub && d->props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
    const char *force = getenv("SPLAT_CLASSIFY");   /* tests: wide | tile */
    if (force && sub)
        s->wide = !strcmp(force, "wide");
    /* two variants of the classification: WORDS 1 for views of at most
     * 32 materials (rt_class_view), WORDS the pack's for the others */
    char head1[320];
    const char *ext = sub ? "#extension GL_KHR_shader_subgroup_vote : require\n"
                            "#extension GL_KHR_shader_subgroup_ballot : require\n"
                            "#extension GL_KHR_shader_subgroup_arithmetic : require\n" : "";
    const char *mode = s->wide ? "#define WIDE 1\n" : sub ? "#define AGGREGATE 1\n" : "";
    snprintf(head, sizeof head, "#define WORDS %d\n#define SLACK %.9g\n%s%s",
             s->words > 0 ? s->words : 1, RT_DCLASS_SLACK, ext, mode);
    snprintf(head1, sizeof head1, "#define WORDS 1\n#define SLACK %.9g\n%s%s",
             RT_DCLASS_SLACK, ext, mode);
    char rhead[128];
    snprintf(rhead, sizeof rhead, "#define TOP %d\n#define PW %u\n#define PH %u\n",
             s->mip_levels - 1, s->maxmip.width, s->maxmip.height);
    char ghead[64];
    snprintf(ghead, sizeof ghead, "#define G %du\n", s->sort_tiles);
    bool one = s->words <= 1;
    return own_pipeline(s, pl, head, rt_screen_classify_glsl, "classify.comp", &s->classify, e) &&
           /* (not a copy of classify's handle: a batch makes it later) */
           (one || own_pipeline(s, pl, head1, rt_screen_classify_glsl, "classify1.comp",
                                &s->classify1, e)) &&
           (!s->sort ||
            own_pipeline(s, pl, ghead, rt_screen_group_glsl, "group.comp", &s->group, e)) &&
           (!s->raycast ||
            own_pipeline(s, pl, rhead, rt_screen_raycast_glsl, "raycast.comp", &s->raycaster, e));
}

bool rt_screen_create(rt_device *d, const rt_pack *p, const rt_pipelines *pl,
                      const rt_image *color, const rt_image *depth, VkSampler nearest,
                      VkDescriptorSet set0, const rt_far *far, bool raycast,
                      rt_pixel_sort sort, int sort_tiles, rt_screen **out, rt_error *e)
{
    *out = NULL;
    rt_screen *s = calloc(1, sizeof *s);
    if (!s)
        return rt_fail(e, RT_E_VULKAN, "screen-space shading", "out of memory");
    s->d = d;
    s->p = p;
    s->color_img = color->img;
    s->raycast = raycast;
    s->width = (int)color->width;
    s->height = (int)color->height;
    s->tiles_x = (s->width + SPLAT_TILE - 1) / SPLAT_TILE;
    s->tiles_y = (s->height + SPLAT_TILE - 1) / SPLAT_TILE;
    s->ntiles = s->tiles_x * s->tiles_y;
    /* every list padded to the largest group (SPLAT_SORT_TILES_MAX) */
    s->stride = (s->ntiles + SPLAT_SORT_TILES_MAX - 1) / SPLAT_SORT_TILES_MAX * SPLAT_SORT_TILES_MAX;
    int most = SPLAT_SORT_TILES_MAX;   /* power of two, within the device's limits */
    while (most >= SPLAT_SORT_TILES_MIN &&
           ((uint32_t)most * 64 > d->props.limits.maxComputeWorkGroupInvocations ||
            (uint32_t)most * 64 > d->props.limits.maxComputeWorkGroupSize[0]))
        most /= 2;
    s->sort_tiles = sort_tiles > 0 ? sort_tiles : most;
    bool can_sort = can_aggregate(d) && s->sort_tiles >= SPLAT_SORT_TILES_MIN &&
                    s->sort_tiles <= most && (s->sort_tiles & (s->sort_tiles - 1)) == 0;
    s->sort = sort == RT_SORT_ON && can_sort;
    if (!s->sort)
        s->sort_tiles = 0;
    s->far = far;
    s->far_ok = far && p->uber_compute.mod;
    s->nlists = p->ncombos + 1 + s->far_ok;   /* + the far atlas's list */
    s->words = (p->nmaterials + 31) / 32;
    if (s->words > MAX_WORDS)
        s->words = 0;   /* too many materials to classify: über-shader only */
    s->dispatched = calloc((size_t)s->nlists, sizeof *s->dispatched);
    s->stand_in = calloc((size_t)s->nlists, 1);
    s->order = calloc((size_t)p->ncombos + 1, sizeof *s->order);
    s->dist = calloc(2 * (size_t)p->ncombos + 2, sizeof *s->dist);
    s->vmask = calloc((size_t)s->words + 1, sizeof *s->vmask);
    s->vmask_last = calloc((size_t)s->words + 1, sizeof *s->vmask_last);
    s->view_margin = p->cell_texels * fmax(p->size[0] / p->hf_width, p->size[1] / p->hf_height) /
                     16.0;
    *out = s;
    if (!s->dispatched || !s->stand_in || !s->order || !s->dist || !s->vmask ||
        !s->vmask_last || (s->words > 0 && !make_node_masks(s)))
        return rt_fail(e, RT_E_VULKAN, "screen-space shading", "out of memory");
    VkDeviceSize list_bytes = (VkDeviceSize)s->nlists * (VkDeviceSize)s->stride * 4;
    if (list_bytes > d->props.limits.maxStorageBufferRange)
        return rt_fail(e, RT_E_PACK_LIMIT, p->dir, "the tile lists (combinations x tiles x 4 bytes)",
                       (unsigned long long)list_bytes, "maxStorageBufferRange",
                       (unsigned long long)d->props.limits.maxStorageBufferRange);
    const VkBufferUsageFlags sb = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    if (!rt_buffer_create(d, list_bytes, sb, false, &s->tiles, e) ||
        !rt_buffer_create(d, (VkDeviceSize)s->nlists * 24,   /* counts, grouped */
                          sb | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false, &s->args, e) ||
        !rt_buffer_create(d, (VkDeviceSize)s->nlists * 12, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true,
                          &s->args_reset, e) ||
        !rt_buffer_create(d, sizeof(splat_counters), sb | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false, &s->counters, e) ||
        !rt_buffer_create(d, (VkDeviceSize)s->nlists * 12 + sizeof(splat_counters),
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &s->readback, e) ||
        !fill_info(s, e))
        return false;
    uint32_t *reset = s->args_reset.map;
    for (int k = 0; k < s->nlists; k++) {
        reset[3 * k] = 0;
        reset[3 * k + 1] = 1;
        reset[3 * k + 2] = 1;
    }
    memset(s->readback.map, 0, (size_t)s->nlists * 12 + sizeof(splat_counters));
    if (raycast &&
        (!make_maxmip(s, e) ||
         !rt_image_create(d, color->width, color->height, 1, false, 1, VK_FORMAT_R32_SFLOAT,
                          VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                              VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                          VK_IMAGE_ASPECT_COLOR_BIT, &s->rdepth, e) ||
         !rt_buffer_create(d, (VkDeviceSize)color->width * color->height * 4,
                           VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                           false, &s->depth_copy, e)))
        return false;
    if (!make_depth_pass(s, depth, e) || !make_compute(s, pl, nearest, e))
        return false;

    /* set 0's compute bindings (abi.h): depth, colour, tiles, counters */
    rt_vk_write w[4] = {
        { set0, SPLAT_BIND_DEPTH, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .sampler = nearest,
          .view = raycast ? s->rdepth.view : depth->view,
          .layout = raycast ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL },
        { set0, SPLAT_BIND_OUT, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, .view = color->view,
          .layout = VK_IMAGE_LAYOUT_GENERAL },
        { set0, SPLAT_BIND_TILES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, s->tiles.buf },
        { set0, SPLAT_BIND_COUNTERS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, s->counters.buf },
    };
    rt_vk_write_sets(d, w, 4);
    return true;
}

void rt_screen_destroy(rt_screen *s)
{
    if (!s)
        return;
    rt_device *d = s->d;
    rt_vk_list_destroy(d, &s->keep);
    if (d->dev) {
        rt_image_destroy(d, &s->maxmip);
        rt_image_destroy(d, &s->rdepth);
        rt_buffer_destroy(d, &s->depth_copy);
        rt_buffer_destroy(d, &s->info);
        rt_buffer_destroy(d, &s->tiles);
        rt_buffer_destroy(d, &s->args);
        rt_buffer_destroy(d, &s->args_reset);
        rt_buffer_destroy(d, &s->counters);
        rt_buffer_destroy(d, &s->readback);
    }
    free(s->dispatched);
    free(s->stand_in);
    free(s->order);
    free(s->dist);
    free(s->vmask);
    free(s->vmask_last);
    for (int L = 0; s->node_masks && L < s->p->nlevels; L++)
        free(s->node_masks[L]);
    free(s->node_masks);
    rt_class_view_free(&s->view);
    free(s);
}

VkRenderPass rt_screen_depth_pass(const rt_screen *s, VkFramebuffer *fb)
{
    *fb = s->depth_fb;
    return s->depth_pass;
}

bool rt_screen_raycasting(const rt_screen *s) { return s->raycast; }

bool rt_screen_sorting(const rt_screen *s) { return s->sort; }

int rt_screen_sort_tiles(const rt_screen *s) { return s->sort_tiles; }

void rt_screen_raycast(rt_screen *s, VkCommandBuffer cb, VkDescriptorSet set0)
{
    /* the last frame's reads end before this write; this write before
     * this frame's reads (classification, shading) */
    rt_cmd_image_barrier(cb, s->rdepth.img, 0, 1, 1,
                         s->rdepth_ready ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_SHADER_READ_BIT,
                         VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    s->rdepth_ready = true;
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->raycaster);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 0, 1, &set0, 0, NULL);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 2, 1, &s->set, 0, NULL);
    vkCmdDispatch(cb, (uint32_t)s->tiles_x, (uint32_t)s->tiles_y, 1);
    rt_cmd_image_barrier(cb, s->rdepth.img, 0, 1, 1, VK_IMAGE_LAYOUT_GENERAL,
                         VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_SHADER_WRITE_BIT,
                         VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
}

static void depth_barrier(VkCommandBuffer cb, VkImage img, VkImageLayout from, VkImageLayout to,
                          VkAccessFlags sa, VkAccessFlags da, VkPipelineStageFlags src,
                          VkPipelineStageFlags dst)
{
    VkImageMemoryBarrier b = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER,
        .srcAccessMask = sa, .dstAccessMask = da, .oldLayout = from, .newLayout = to,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = img, .subresourceRange = { VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1 },
    };
    vkCmdPipelineBarrier(cb, src, dst, 0, 0, NULL, 0, NULL, 1, &b);
}

void rt_screen_depth_out(rt_screen *s, VkCommandBuffer cb, const rt_image *depth)
{
    rt_cmd_image_barrier(cb, s->rdepth.img, 0, 1, 1, VK_IMAGE_LAYOUT_GENERAL,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT,
                         VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy c = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { s->rdepth.width, s->rdepth.height, 1 },
    };
    vkCmdCopyImageToBuffer(cb, s->rdepth.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           s->depth_copy.buf, 1, &c);
    rt_cmd_image_barrier(cb, s->rdepth.img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_TRANSFER_READ_BIT, 0,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    depth_barrier(cb, depth->img, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  0, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                  VK_PIPELINE_STAGE_TRANSFER_BIT);
    c.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
    vkCmdCopyBufferToImage(cb, s->depth_copy.buf, depth->img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           1, &c);
    depth_barrier(cb, depth->img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                  VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                      VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                  VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                      VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT);
}

bool rt_screen_begin(rt_screen *s, VkCommandBuffer cb, bool count, const rt_quadtree *q,
                     bool no_classes, rt_error *e)
{
    VkBufferCopy c = { 0, 0, (VkDeviceSize)s->nlists * 12 };
    vkCmdCopyBuffer(cb, s->args_reset.buf, s->args.buf, 1, &c);
    if (count)
        vkCmdFillBuffer(cb, s->counters.buf, 0, sizeof(splat_counters), 0);
    if (s->words == 0)
        return true;   /* every tile to the über-shader */
    /* the view: rebuilt where the selection's materials changed */
    view_materials(s, q);
    size_t vb = (size_t)s->words * sizeof *s->vmask;
    if (!s->view_built || no_classes != s->view_no_classes ||
        memcmp(s->vmask, s->vmask_last, vb)) {
        if (!rt_class_view_build(s->p, s->order, s->dist, s->vmask, s->words, no_classes,
                                 &s->view))
            return rt_fail(e, RT_E_VULKAN, "screen-space shading", "out of memory");
        memcpy(s->vmask_last, s->vmask, vb);
        s->view_built = true;
        s->view_no_classes = no_classes;
    }
    /* uploaded every frame (a few kB, recorded in the command buffer):
     * ncand, words, 0, 0, the candidates, the records */
    const rt_class_view *v = &s->view;
    size_t n = (size_t)s->p->ncombos;
    uint32_t head[4] = { (uint32_t)v->ncand, (uint32_t)v->words, 0, 0 };
    VkDeviceSize at = (VkDeviceSize)(8 + s->view_at) * 4;
    vkCmdUpdateBuffer(cb, s->info.buf, at, sizeof head, head);
    const uint8_t *parts[2] = { (const uint8_t *)v->cand, (const uint8_t *)v->rec };
    size_t bytes[2] = { (size_t)v->ncand * 4, n * (size_t)(1 + v->words) * 4 };
    VkDeviceSize to[2] = { at + 16, at + 16 + n * 4 };
    for (int k = 0; k < 2; k++)
        for (size_t o = 0; o < bytes[k]; o += 65536) {
            size_t len = bytes[k] - o < 65536 ? bytes[k] - o : 65536;
            vkCmdUpdateBuffer(cb, s->info.buf, to[k] + o, len, parts[k] + o);
        }
    return true;
}

const rt_class_view *rt_screen_class_view(const rt_screen *s)
{
    return s->view_built ? &s->view : NULL;
}

void rt_screen_classify(rt_screen *s, VkCommandBuffer cb, VkDescriptorSet set0,
                        const float clear[4], bool force_uber, bool no_classes, int *binds)
{
    /* the colour image is GENERAL (render_plan.c): the classification
     * writes the background of empty pixels, shading the terrain's */
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE,
                      s->view_built && s->view.words == 1 && s->classify1 ? s->classify1
                                                                           : s->classify);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 0, 1, &set0, 0, NULL);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 2, 1, &s->set, 0, NULL);
    /* abi.h's push block, read as: patch_xz the background colour,
     * info.x 1 to send every tile to the über-shader, info.y the far
     * atlas's distance (float bits), info.z 1 for no distance classes,
     * patch_uv the destructible rectangle */
    splat_push push;
    memset(&push, 0, sizeof push);
    memcpy(push.patch_xz, clear, 3 * sizeof(float));
    push.patch_xz[3] = 1.0f;
    push.info[0] = force_uber || s->words == 0;
    /* the far atlas's distance (0: off) and the destructible area */
    float fd = s->far_ok && !force_uber ? s->far_distance : 0.0f;
    memcpy(&push.info[1], &fd, sizeof fd);
    push.info[2] = no_classes;
    push.info[3] = s->blocks;   /* the tile order */
    const rt_pack *p = s->p;
    float rect[4] = { 1.0f, 1.0f, 0.0f, 0.0f };   /* empty */
    if (p->has_destruction) {
        rect[0] = (float)p->destr_origin[0];
        rect[1] = (float)p->destr_origin[1];
        rect[2] = (float)(p->destr_origin[0] + p->destr_size[0]);
        rect[3] = (float)(p->destr_origin[1] + p->destr_size[1]);
    }
    memcpy(push.patch_uv, rect, sizeof rect);
    vkCmdPushConstants(cb, s->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    /* in blocks: padded to whole 4x4 blocks of tiles */
    uint32_t bx = ((uint32_t)s->tiles_x + 3) / 4 * 4, by = ((uint32_t)s->tiles_y + 3) / 4 * 4;
    if (s->wide)
        vkCmdDispatch(cb, s->blocks ? bx : (uint32_t)s->tiles_x,
                      s->blocks ? by : (uint32_t)s->tiles_y, 1);
    else
        vkCmdDispatch(cb, ((s->blocks ? bx * by : (uint32_t)s->ntiles) + 63) / 64, 1, 1);
    (*binds)++;
    if (!s->sort)
        return;   /* the shading's wait for the lists: render_plan.c */
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->group);
    memset(&push, 0, sizeof push);
    push.info[0] = (uint32_t)s->nlists;
    vkCmdPushConstants(cb, s->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(cb, (uint32_t)(s->nlists + 63) / 64, 1, 1);
    (*binds)++;
}

/* List k's indirect dispatch with the pipeline bound: workgroup g shades
 * tiles[k * stride + g], or sort_tiles of them from there times g
 * with `grouped` (abi.h's push block: info.y the list, info.z the
 * material count, info.w its first tile). */
static void dispatch_list(rt_screen *s, VkCommandBuffer cb, VkPipelineLayout layout, int k,
                          unsigned variant, bool grouped)
{
    splat_push push;
    memset(&push, 0, sizeof push);
    push.info[1] = (uint32_t)k;
    push.info[2] = (uint32_t)s->p->nmaterials;
    push.info[3] = (uint32_t)k * (uint32_t)s->stride;
    vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatchIndirect(cb, s->args.buf, (VkDeviceSize)(grouped ? s->nlists + k : k) * 12);
    s->dispatched[k] = variant + 1;
}

/* The far shader's compute pipeline (c: the counting variant), made on
 * first use: the far list's, and the atlas stand-in's; the plain one from
 * the pack's SPIR-V where it has it (rt_pipelines_stand_in_spirv). */
static bool far_pipeline(rt_screen *s, rt_pipelines *pl, int c, rt_error *e)
{
    if (s->far_pipe[c])
        return true;
    uint32_t *words = NULL;
    size_t n = 0;
    bool ok = rt_pipelines_stand_in_spirv(s->p, pl, SPLAT_STAND_IN_ATLAS, c != 0, &words, &n, e) &&
              rt_vk_compute(s->d, &s->keep, &(rt_vk_compute_desc){ .label = "far.comp",
                                .spirv = words, .nwords = n, .layout = s->layout,
                                .cache = pl->cache }, &s->far_pipe[c], e);
    free(words);
    return ok;
}

bool rt_screen_prepare_stand_in(rt_screen *s, rt_pipelines *pl, rt_stand_in stand_in,
                                unsigned variant, rt_error *e)
{
    VkPipeline pipe;
    if (stand_in == RT_STAND_ATLAS && s->far_ok)
        return far_pipeline(s, pl, (variant & RT_CVARIANT_COUNT) != 0, e);
    if (stand_in == RT_STAND_ATLAS || stand_in == RT_STAND_FLAT)
        return rt_pipelines_flat(s->d, s->p, pl, variant, &pipe, e);
    return true;
}

bool rt_screen_dispatch(rt_screen *s, VkCommandBuffer cb, rt_pipelines *pl,
                        const VkDescriptorSet sets[2], unsigned variant, rt_stand_in stand_in,
                        int *binds, rt_error *e)
{
    rt_device *d = s->d;
    const rt_pack *p = s->p;
    if (stand_in == RT_STAND_ATLAS && !s->far_ok)
        stand_in = RT_STAND_FLAT;

    /* one indirect dispatch per list whose pipeline exists (the others
     * are found empty or compiled after the frame: rt_screen_missing);
     * with a stand-in, the others by its pipeline meanwhile: the
     * über-shader's or the flat one's here, the far atlas's after them
     * (its own layout, set 2 the classification's with the atlas) */
    bool bound_sets = false, atlas = false;
    VkPipeline bound = VK_NULL_HANDLE;
    for (int k = 0; k < s->nlists; k++) {
        s->dispatched[k] = 0;
        s->stand_in[k] = RT_STAND_NONE;
        if (k > p->ncombos)   /* the far list, below */
            continue;
        bool have = rt_pipelines_has_compute(pl, k, variant);
        if (!have && stand_in == RT_STAND_NONE)
            continue;
        if (!have && stand_in == RT_STAND_ATLAS) {
            s->stand_in[k] = RT_STAND_ATLAS;
            atlas = true;
            continue;
        }
        VkPipeline pipe;
        if (!have && stand_in == RT_STAND_FLAT
                ? !rt_pipelines_flat(d, p, pl, variant, &pipe, e)
                : !rt_pipelines_compute(d, p, pl, have ? k : p->ncombos, variant, &pipe, e))
            return false;
        s->stand_in[k] = have ? RT_STAND_NONE : (unsigned char)stand_in;
        if (!bound_sets) {
            vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pl->compute_layout, 0, 2,
                                    sets, 0, NULL);
            bound_sets = true;
        }
        if (pipe != bound) {
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
            (*binds)++;
            bound = pipe;
        }
        /* the flat stand-in is not sorted: a tile a workgroup, the list's
         * own args; the über-shader is, as the composites */
        dispatch_list(s, cb, pl->compute_layout, k, variant,
                      s->stand_in[k] != RT_STAND_FLAT && (variant & RT_CVARIANT_SORT) != 0);
    }
    if (atlas) {
        int c = (variant & RT_CVARIANT_COUNT) != 0;
        if (!far_pipeline(s, pl, c, e))
            return false;
        VkDescriptorSet all[3] = { sets[0], sets[1], s->set };
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 0, 3, all, 0, NULL);
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->far_pipe[c]);
        (*binds)++;
        for (int k = 0; k <= p->ncombos; k++)
            if (s->stand_in[k] == RT_STAND_ATLAS)
                dispatch_list(s, cb, s->layout, k, variant, false);
    }
    return true;
}

void rt_screen_tile_blocks(rt_screen *s, bool on) { s->blocks = on; }

bool rt_screen_far_on(const rt_screen *s) { return s->far_ok && s->far_distance > 0; }

bool rt_screen_dispatch_far(rt_screen *s, VkCommandBuffer cb, rt_pipelines *pl,
                            const VkDescriptorSet sets[2], unsigned variant, int *binds,
                            rt_error *e)
{
    const rt_pack *p = s->p;
    int k = p->ncombos + 1, c = (variant & RT_CVARIANT_COUNT) != 0;
    if (!far_pipeline(s, pl, c, e))
        return false;
    VkDescriptorSet all[3] = { sets[0], sets[1], s->set };
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 0, 3, all, 0, NULL);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->far_pipe[c]);
    (*binds)++;
    dispatch_list(s, cb, s->layout, k, variant, false);
    return true;
}

void rt_screen_counts(rt_screen *s, VkCommandBuffer cb)
{
    VkBufferCopy ca = { 0, 0, (VkDeviceSize)s->nlists * 12 };
    VkBufferCopy cc = { 0, (VkDeviceSize)s->nlists * 12, sizeof(splat_counters) };
    vkCmdCopyBuffer(cb, s->args.buf, s->readback.buf, 1, &ca);
    vkCmdCopyBuffer(cb, s->counters.buf, s->readback.buf, 1, &cc);
}

int rt_screen_missing(rt_screen *s, rt_pipelines *pl, unsigned variant, rt_error *e)
{
    const uint32_t *args = s->readback.map;
    int *lists = malloc((size_t)s->nlists * sizeof *lists), made = 0;
    if (!lists) {
        rt_fail(e, RT_E_VULKAN, "screen-space shading", "out of memory");
        return -1;
    }
    for (int k = 0; k < s->nlists && k <= s->p->ncombos; k++) {
        if (args[3 * k] == 0)
            continue;
        if (s->stand_in[k])   /* drawn meanwhile: made on the workers */
            rt_async_request(pl, k, variant);
        else if (s->dispatched[k] != variant + 1)
            lists[made++] = k;
    }
    bool ok = rt_pipelines_make(s->d, s->p, NULL, pl, true, lists, made, variant, e);
    free(lists);
    return ok ? made : -1;
}

void rt_screen_far(rt_screen *s, double distance)
{
    s->far_distance = distance > 0 ? (float)distance : 0.0f;
}

bool rt_screen_has_far(const rt_screen *s) { return s->far_ok; }

void rt_screen_read_stats(const rt_screen *s, rt_screen_stats *st)
{
    const uint32_t *args = s->readback.map;
    memset(st, 0, sizeof *st);
    st->tiles_total = s->ntiles;
    for (int k = 0; k < s->nlists; k++) {
        st->tiles += (int)args[3 * k];
        st->lists += args[3 * k] > 0;
        if (s->stand_in[k])
            st->tiles_stand_in += (int)args[3 * k];
        if (s->stand_in[k] == RT_STAND_UBER)
            st->tiles_stand_in_uber += (int)args[3 * k];
        else if (s->stand_in[k] == RT_STAND_ATLAS)
            st->tiles_stand_in_atlas += (int)args[3 * k];
        else if (s->stand_in[k] == RT_STAND_FLAT)
            st->tiles_stand_in_flat += (int)args[3 * k];
        if (k >= s->p->nbase && k < s->p->ncombos)
            st->tiles_class += (int)args[3 * k];
    }
    st->tiles_uber = (int)args[3 * s->p->ncombos];
    if (s->view_built) {
        st->class_candidates = s->view.ncand;
        st->class_materials = s->view.nview;
        st->class_words = s->view.words;
    }
    st->tiles_far = s->far_ok ? (int)args[3 * (s->p->ncombos + 1)] : 0;
    rt_counters_read(args + 3 * s->nlists, st);
}

void rt_counters_read(const void *counters, rt_screen_stats *st)
{
    splat_counters c;
    memcpy(&c, counters, sizeof c);
    st->pixels = c.pixels;
    st->layers_evaluated = c.layers_evaluated;
    st->layers_needed = c.layers_needed;
    st->samples = c.samples;
    st->branches = c.branches;
    st->branches_uniform = c.branches_uniform;
}

const rt_image *rt_screen_ray_depth(const rt_screen *s)
{
    return s->raycast ? &s->rdepth : NULL;
}
