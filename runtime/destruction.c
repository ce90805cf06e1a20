/* destruction.c — the dynamic destruction mask (Andersson 2007 §5.2.5, slides 003
 * "Destruction mask"): craters change the material and the geometry at run
 * time.
 *
 * The mask.  A fixed grid of n x n cells (cell_size metres, 16 by default)
 * starts at the scene's destructible area's origin; n is what the longer
 * side of the area needs (the analysis assumes exactly this grid).  The
 * indirection texture (RGBA8, n x n, set 0 binding 4) holds per cell
 * .rg = the tile's column and row in the atlas (/255), .a = 1 when the cell
 * has a tile.  The atlas (R8, binding 3) is a square of cols x cols tiles of
 * RT_DESTR_TILE^2 texels; only `pool` of its slots are used, handed out on
 * demand from a free list.  A cell without a tile reads 0 (untouched).
 *
 * A crater event (rt_destruction_crater), all in one command buffer that
 * is submitted without waiting (the next frame is ordered after it on the
 * queue; events rotate over a ring of command buffers and staging buffers,
 * so an event waits only when the one four events back still runs):
 *   1. the cells the crater's disc meets get tiles (new ones cleared to 0);
 *      if the pool has fewer free tiles than needed the crater is REFUSED:
 *      a warning, nothing changes (mask and geometry stay consistent);
 *   2. the indirection texels that changed are uploaded (their rectangle);
 *   3. the decal is rendered into each affected tile, the viewport set to
 *      the tile: a radial gradient broken up by value noise, strength at
 *      the centre, exactly 0 from the radius on, combined with MAX blending
 *      so overlapping craters keep the stronger mark;
 *   4. the heightfield texels whose centres lie inside the disc (and inside
 *      the grid: the analysis widened only the area and two texels around
 *      it) are lowered by depth * (1 - d^2)^2 (d = distance / radius), on
 *      the CPU copy, and only their texel rectangle is uploaded — never the
 *      whole texture;
 *   5. the quadtree min/max heights of the leaves reading those texels and
 *      of their ancestors are recomputed.
 *
 * Memory (slides: 2048 m at 4 px/m is 64 MB dense): rt_destruction_memory
 * gives the figures for any configuration. */
#include "rt_internal.h"
#include "vk_build.h"
#include "util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { RT_DESTR_RING = 4 };

struct rt_destruction {
    rt_device *d;
    int        n;              /* cells per side                           */
    double     origin[2], cell; /* metres                                   */
    int        cols;           /* tiles per atlas row (and column)          */
    int        pool, used;     /* tiles available / allocated               */
    int       *free_tiles;     /* stack of free tile slots                  */
    int        nfree;
    int       *cell_tile;      /* n*n: slot or -1                           */
    uint8_t   *index;          /* n*n RGBA8, the indirection on the CPU     */
    rt_image   atlas, indir;
    rt_image  *height;         /* the terrain's R16 heightfield image       */
    rt_bounds *bounds;
    uint16_t  *heights;        /* CPU copy, lowered by craters              */
    int        hw, hh, cell_texels;
    double     size[2], max_height, offset;
    VkRenderPass     pass;
    VkFramebuffer    fb;
    VkPipelineLayout layout;
    VkPipeline       pipe;
    rt_vk_list       keep;     /* pass, fb, layout, pipe                    */
    /* RT_DESTR_RING events in flight, each with its command buffer, fence
     * and staging memory; an event waits only when the oldest is still
     * running (reported as wait_ms, not part of the event's cpu_ms) */
    VkCommandBuffer  cb[RT_DESTR_RING];
    VkFence          fence[RT_DESTR_RING];
    bool             pending[RT_DESTR_RING];
    rt_buffer        staging[RT_DESTR_RING];
    int              slot;     /* the ring entry the next event uses        */
    int             *touched;  /* scratch: cells of the current crater      */
    VkClearRect     *clears;   /* scratch: rects of its new tiles           */
    int              craters, refused;
    double           last_ms, max_ms, total_ms;
};

/* Push constants of the decal pipeline. */
typedef struct decal_push {
    float crater[4];  /* xy: centre in cell units from the cell's corner,
                         z: radius (cells), w: strength at the centre      */
    float world[4];   /* xy: cell corner - area origin (m), z: cell (m)    */
} decal_push;

static const char decal_vert[] =
    "#version 450\n"
    "layout(location = 0) out vec2 v_cell;\n"
    "void main() {\n"
    "    vec2 c = vec2(gl_VertexIndex & 1, (gl_VertexIndex >> 1) & 1);\n"
    "    v_cell = c;                          /* the whole tile */\n"
    "    gl_Position = vec4(c * 2.0 - 1.0, 0.0, 1.0);\n"
    "}\n";

static const char decal_frag[] =
    "#version 450\n"
    "layout(push_constant, std430) uniform decal_push {\n"
    "    vec4 crater;\n"
    "    vec4 world;\n"
    "} u;\n"
    "layout(location = 0) in vec2 v_cell;\n"
    "layout(location = 0) out vec4 o_mask;\n"
    "float hash(vec2 p) {\n"
    "    vec3 q = fract(vec3(p.xyx) * 0.1031);\n"
    "    q += dot(q, q.yzx + 33.33);\n"
    "    return fract((q.x + q.y) * q.z);\n"
    "}\n"
    "float vnoise(vec2 p) {\n"
    "    vec2 i = floor(p), f = fract(p);\n"
    "    f = f * f * (3.0 - 2.0 * f);\n"
    "    return mix(mix(hash(i), hash(i + vec2(1, 0)), f.x),\n"
    "               mix(hash(i + vec2(0, 1)), hash(i + vec2(1, 1)), f.x), f.y);\n"
    "}\n"
    "void main() {\n"
    "    float d = length(v_cell - u.crater.xy) / u.crater.z;\n"
    "    float edge = max(1.0 - d, 0.0);\n"
    "    vec2 w = u.world.xy + v_cell * u.world.z;\n"
    "    float n = 0.65 * vnoise(w * 0.6) + 0.35 * vnoise(w * 1.9);\n"
    "    o_mask = vec4(u.crater.w * clamp(edge * 4.0 * (0.5 + n), 0.0, 1.0));\n"
    "}\n";

/* ---- memory figures --------------------------------------------------------- */

void rt_destruction_memory(double area_m, double px_per_m, double cell_m,
                           double coverage, rt_destruction_figures *f)
{
    memset(f, 0, sizeof *f);
    f->side_px = (int)ceil(area_m * px_per_m);
    f->cells = (int)ceil(area_m / cell_m);
    f->tile_px = (int)ceil(cell_m * px_per_m);
    f->dense_bytes = (double)f->side_px * f->side_px;
    f->indirection_bytes = 2.0 * f->cells * f->cells;  /* RG88 as the slides */
    f->tiles = (int)ceil(coverage * f->cells * f->cells);
    f->tile_bytes = (double)f->tiles * f->tile_px * f->tile_px;
    f->sparse_bytes = f->indirection_bytes + f->tile_bytes;
}

/* ---- creation ---------------------------------------------------------------- */

static bool make_pipeline(rt_destruction *ds, rt_error *e)
{
    rt_device *d = ds->d;
    rt_vk_list *k = &ds->keep;
    const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    /* Earlier frames' reads of the atlas finish before the decals write;
     * the decals are visible to the fragment shaders of later frames. */
    VkSubpassDependency dep[2] = {
        { VK_SUBPASS_EXTERNAL, 0, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_SHADER_READ_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, 0 },
        { 0, VK_SUBPASS_EXTERNAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
          VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
          VK_ACCESS_SHADER_READ_BIT, 0 },
    };
    /* MAX: overlapping craters keep the stronger mark */
    VkPipelineColorBlendAttachmentState blend = {
        .blendEnable = VK_TRUE,
        .srcColorBlendFactor = VK_BLEND_FACTOR_ONE, .dstColorBlendFactor = VK_BLEND_FACTOR_ONE,
        .colorBlendOp = VK_BLEND_OP_MAX,
        .srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE, .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE,
        .alphaBlendOp = VK_BLEND_OP_MAX,
        .colorWriteMask = VK_COLOR_COMPONENT_R_BIT,
    };
    return rt_vk_pass(d, k, &(rt_vk_pass_desc){ .label = "decal",
                          .color = { { .format = VK_FORMAT_R8_UNORM, .initial = ro, .final = ro } },
                          .ncolor = 1, .deps = dep, .ndeps = 2 }, &ds->pass, e) &&
           rt_vk_fb(d, k, &(rt_vk_fb_desc){ .label = "decal", .pass = ds->pass,
                        .views = &ds->atlas.view, .nviews = 1, .width = ds->atlas.width,
                        .height = ds->atlas.height }, &ds->fb, e) &&
           rt_vk_layout(d, k, &(rt_vk_layout_desc){ .label = "decal",
                            .push_stages = VK_SHADER_STAGE_FRAGMENT_BIT,
                            .push_bytes = sizeof(decal_push) }, &ds->layout, e) &&
           rt_vk_gfx(d, k, &(rt_vk_gfx_desc){ .label = "decal", .vs_glsl = decal_vert,
                         .fs_glsl = decal_frag, .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP,
                         .ncolor = 1, .blend = &blend, .layout = ds->layout, .pass = ds->pass },
                     &ds->pipe, e);
}

/* One decal of strength 0 (MAX blend: no change) at load time, so that
 * drivers that compile pipeline variants on first use (lavapipe's JIT) do
 * it now rather than in the first crater event. */
static bool warm_up(rt_destruction *ds, rt_error *e)
{
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(ds->d, &cb, e))
        return false;
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = ds->pass, .framebuffer = ds->fb,
        .renderArea = { { 0, 0 }, { ds->atlas.width, ds->atlas.height } },
    };
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, ds->pipe);
    VkViewport vp = { 0, 0, RT_DESTR_TILE, RT_DESTR_TILE, 0, 1 };
    VkRect2D sc = { { 0, 0 }, { RT_DESTR_TILE, RT_DESTR_TILE } };
    vkCmdSetViewport(cb, 0, 1, &vp);
    vkCmdSetScissor(cb, 0, 1, &sc);
    decal_push push = { { 0.5f, 0.5f, 0.5f, 0.0f }, { 0, 0, 1, 0 } };
    vkCmdPushConstants(cb, ds->layout, VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push, &push);
    vkCmdDraw(cb, 4, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    return rt_oneshot_end(ds->d, cb, e);
}

/* Staging for one event: the whole indirection and the heightfield
 * texels under the grid (a crater never writes outside it). */
static VkDeviceSize staging_bytes(const rt_destruction *ds)
{
    size_t ncell = (size_t)ds->n * (size_t)ds->n;
    int tx0, tz0, tx1, tz1;
    tx0 = (int)floor(ds->origin[0] / ds->size[0] * ds->hw) - 1;
    tz0 = (int)floor(ds->origin[1] / ds->size[1] * ds->hh) - 1;
    tx1 = (int)ceil((ds->origin[0] + ds->n * ds->cell) / ds->size[0] * ds->hw) + 1;
    tz1 = (int)ceil((ds->origin[1] + ds->n * ds->cell) / ds->size[1] * ds->hh) + 1;
    tx0 = tx0 < 0 ? 0 : tx0;
    tz0 = tz0 < 0 ? 0 : tz0;
    tx1 = tx1 > ds->hw ? ds->hw : tx1;
    tz1 = tz1 > ds->hh ? ds->hh : tz1;
    size_t hbytes = tx1 > tx0 && tz1 > tz0 ? (size_t)(tx1 - tx0) * (size_t)(tz1 - tz0) * 2 : 0;
    return (VkDeviceSize)(ncell * 4 + hbytes + 16);
}

/* The atlas and indirection images (cleared), the decal pipeline, the
 * ring's command buffers, fences and staging, and the warm-up decal. */
static bool make_gpu(rt_destruction *ds, rt_error *e)
{
    rt_device *d = ds->d;
    size_t ncell = (size_t)ds->n * (size_t)ds->n;
    const VkImageUsageFlags use = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    uint32_t aside = (uint32_t)(ds->cols * RT_DESTR_TILE);
    if (!rt_format_supports(d, VK_FORMAT_R8_UNORM, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                                                   VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
        return rt_fail(e, RT_E_NO_FORMAT, "render with blending into R8_UNORM (destruction mask)");
    uint8_t *zero = calloc((size_t)aside * aside > ncell * 4 ? (size_t)aside * aside : ncell * 4, 1);
    if (!zero)
        return rt_fail(e, RT_E_VULKAN, "destruction", "out of memory");
    VkCommandBufferAllocateInfo ai = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = d->pool, .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = RT_DESTR_RING,
    };
    VkFenceCreateInfo fi = { .sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO };
    bool ok = rt_image_create(d, aside, aside, 1, false, 1, VK_FORMAT_R8_UNORM,
                              use | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT, &ds->atlas, e) &&
              rt_image_upload(d, &ds->atlas, zero, (size_t)aside * aside, e) &&
              rt_image_create(d, (uint32_t)ds->n, (uint32_t)ds->n, 1, false, 1,
                              VK_FORMAT_R8G8B8A8_UNORM, use, VK_IMAGE_ASPECT_COLOR_BIT,
                              &ds->indir, e) &&
              rt_image_upload(d, &ds->indir, zero, ncell * 4, e) &&
              make_pipeline(ds, e);
    free(zero);
    if (ok) {
        VkResult r = vkAllocateCommandBuffers(d->dev, &ai, ds->cb);
        for (int i = 0; r == VK_SUCCESS && i < RT_DESTR_RING; i++)
            r = vkCreateFence(d->dev, &fi, NULL, &ds->fence[i]);
        if (r != VK_SUCCESS)
            ok = rt_fail(e, RT_E_VULKAN, "destruction commands", rt_vk_result_name(r));
    }
    VkDeviceSize sbytes = staging_bytes(ds);
    for (int i = 0; ok && i < RT_DESTR_RING; i++)
        ok = rt_buffer_create(d, sbytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true,
                              &ds->staging[i], e);
    return ok && warm_up(ds, e);
}

bool rt_destruction_create(rt_device *d, const rt_pack *p, int pool_tiles,
                           rt_image *height, rt_bounds *bounds, rt_destruction **out,
                           rt_error *e)
{
    *out = NULL;
    if (!p->has_destruction)
        return true;
    rt_destruction *ds = calloc(1, sizeof *ds);
    if (!ds)
        return rt_fail(e, RT_E_VULKAN, "destruction", "out of memory");
    ds->d = d;
    ds->cell = p->destr_cell;
    ds->origin[0] = p->destr_origin[0];
    ds->origin[1] = p->destr_origin[1];
    double side = p->destr_size[0] > p->destr_size[1] ? p->destr_size[0] : p->destr_size[1];
    ds->n = (int)ceil(side / ds->cell);
    ds->pool = pool_tiles > 0 ? pool_tiles : RT_DESTR_POOL_DEFAULT;
    /* square atlas (the ABI has one atlas size); a tile's column and row
     * are 8-bit in the indirection texture */
    uint32_t maxdim = d->props.limits.maxImageDimension2D;
    ds->cols = (int)ceil(sqrt((double)ds->pool));
    int max_cols = (int)(maxdim / RT_DESTR_TILE) < 255 ? (int)(maxdim / RT_DESTR_TILE) : 255;
    if (ds->cols > max_cols) {
        ds->cols = max_cols;
        ds->pool = max_cols * max_cols;
        fprintf(stderr, "splatrt: warning: destruction pool limited to %d tiles\n", ds->pool);
    }
    ds->height = height;
    ds->bounds = bounds;
    ds->hw = p->hf_width;
    ds->hh = p->hf_height;
    ds->cell_texels = p->cell_texels;
    ds->size[0] = p->size[0];
    ds->size[1] = p->size[1];
    ds->max_height = p->max_height;
    ds->offset = p->height_offset;
    size_t ncell = (size_t)ds->n * (size_t)ds->n;
    size_t texels = (size_t)ds->hw * (size_t)ds->hh;
    ds->free_tiles = malloc((size_t)ds->pool * sizeof *ds->free_tiles);
    ds->cell_tile = malloc(ncell * sizeof *ds->cell_tile);
    ds->index = calloc(ncell, 4);
    ds->heights = malloc(texels * 2);
    ds->touched = malloc(ncell * sizeof *ds->touched);
    ds->clears = malloc(ncell * sizeof *ds->clears);
    if (!ds->free_tiles || !ds->cell_tile || !ds->index || !ds->heights || !ds->touched ||
        !ds->clears) {
        rt_destruction_destroy(ds);
        return rt_fail(e, RT_E_VULKAN, "destruction", "out of memory");
    }
    for (int i = 0; i < ds->pool; i++)
        ds->free_tiles[i] = ds->pool - 1 - i;   /* slot 0 is handed out first */
    ds->nfree = ds->pool;
    for (size_t i = 0; i < ncell; i++)
        ds->cell_tile[i] = -1;
    memcpy(ds->heights, p->heights, texels * 2);

    if (!make_gpu(ds, e)) {
        rt_destruction_destroy(ds);
        return false;
    }
    *out = ds;
    return true;
}

void rt_destruction_destroy(rt_destruction *ds)
{
    if (!ds)
        return;
    rt_device *d = ds->d;
    if (d && d->dev) {
        for (int i = 0; i < RT_DESTR_RING; i++) {
            if (ds->pending[i])
                vkWaitForFences(d->dev, 1, &ds->fence[i], VK_TRUE, UINT64_MAX);
            if (ds->fence[i])
                vkDestroyFence(d->dev, ds->fence[i], NULL);
            if (ds->cb[i])
                vkFreeCommandBuffers(d->dev, d->pool, 1, &ds->cb[i]);
            rt_buffer_destroy(d, &ds->staging[i]);
        }
        rt_vk_list_destroy(d, &ds->keep);
        rt_image_destroy(d, &ds->atlas);
        rt_image_destroy(d, &ds->indir);
    }
    free(ds->free_tiles);
    free(ds->cell_tile);
    free(ds->index);
    free(ds->heights);
    free(ds->touched);
    free(ds->clears);
    free(ds);
}

void rt_destruction_frame(const rt_destruction *ds, splat_frame *fr)
{
    fr->destruction[0] = (float)ds->origin[0];
    fr->destruction[1] = (float)ds->origin[1];
    fr->destruction[2] = (float)ds->cell;
    fr->destruction[3] = (float)ds->n;
    fr->destruction_atlas[0] = (float)RT_DESTR_TILE;
    fr->destruction_atlas[1] = (float)ds->atlas.width;
    fr->destruction_atlas[2] = (float)ds->cols;
    fr->destruction_atlas[3] = 0.0f;
}

void rt_destruction_views(const rt_destruction *ds, VkImageView *atlas, VkImageView *index)
{
    *atlas = ds->atlas.view;
    *index = ds->indir.view;
}

const uint16_t *rt_destruction_heights(const rt_destruction *ds) { return ds->heights; }

/* ---- a crater ------------------------------------------------------------------ */

/* Copy `rows` x `bytes_per_row` bytes from staging offset `off` into the
 * rectangle (x, y, w, h) of `img` (SHADER_READ_ONLY before and after). */
static void upload_rect(rt_destruction *ds, VkImage img, VkDeviceSize off, int x, int y,
                        int w, int h)
{
    VkCommandBuffer cb = ds->cb[ds->slot];
    const VkPipelineStageFlags shaders = VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                                         VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
    rt_cmd_image_barrier(cb, img, 0, 1, 1, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_ACCESS_SHADER_READ_BIT,
                  VK_ACCESS_TRANSFER_WRITE_BIT, shaders, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy copy = {
        .bufferOffset = off,
        .bufferRowLength = (uint32_t)w,
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageOffset = { x, y, 0 },
        .imageExtent = { (uint32_t)w, (uint32_t)h, 1 },
    };
    vkCmdCopyBufferToImage(cb, ds->staging[ds->slot].buf, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &copy);
    rt_cmd_image_barrier(cb, img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                  VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, shaders);
}

/* Leaves reading texels [tx0, tx1] x [tz0, tz1], then their ancestors. */
static void update_bounds(rt_destruction *ds, int tx0, int tz0, int tx1, int tz1)
{
    rt_bounds *b = ds->bounds;
    int T = ds->cell_texels;
    int lx0 = tx0 / T - 1, lx1 = (tx1 + 1) / T, lz0 = tz0 / T - 1, lz1 = (tz1 + 1) / T;
    lx0 = lx0 < 0 ? 0 : lx0;
    lz0 = lz0 < 0 ? 0 : lz0;
    lx1 = lx1 >= b->width[0] ? b->width[0] - 1 : lx1;
    lz1 = lz1 >= b->height[0] ? b->height[0] - 1 : lz1;
    for (int z = lz0; z <= lz1; z++)
        for (int x = lx0; x <= lx1; x++)
            rt_bounds_leaf(b, ds->heights, ds->hw, ds->hh, T, ds->max_height, ds->offset,
                           x, z);
    for (int L = 1; L < b->nlevels; L++) {
        lx0 /= 2; lx1 /= 2; lz0 /= 2; lz1 /= 2;
        for (int z = lz0; z <= lz1; z++)
            for (int x = lx0; x <= lx1; x++)
                rt_bounds_merge(b, L, x, z);
    }
}

/* One crater's work between the steps of rt_destruction_crater: the disc
 * in cell units, the touched cells (ds->touched), and the rectangles of
 * index texels and height texels that changed (x1 < 0: none). */
typedef struct crater_work {
    double lx, lz, rc, strength;      /* centre and radius in cells       */
    int    ntouched, nnew, nclear;
    int    ix0, iz0, ix1, iz1;        /* indirection texels               */
    int    hx0, hz0, hx1, hz1;        /* height texels                    */
    VkDeviceSize index_off, height_off;   /* in the staging buffer        */
} crater_work;

/* 1. The cells the disc meets, into ds->touched; how many lack a tile. */
static void crater_cells(rt_destruction *ds, const rt_crater *c, crater_work *w)
{
    int n = ds->n;
    w->lx = (c->x - ds->origin[0]) / ds->cell;
    w->lz = (c->z - ds->origin[1]) / ds->cell;
    w->rc = c->radius / ds->cell;
    double lx = w->lx, lz = w->lz, rc = w->rc;
    int cx0 = (int)floor(lx - rc), cx1 = (int)floor(lx + rc);
    int cz0 = (int)floor(lz - rc), cz1 = (int)floor(lz + rc);
    cx0 = cx0 < 0 ? 0 : cx0;
    cz0 = cz0 < 0 ? 0 : cz0;
    cx1 = cx1 >= n ? n - 1 : cx1;
    cz1 = cz1 >= n ? n - 1 : cz1;
    for (int z = cz0; z <= cz1; z++)
        for (int x = cx0; x <= cx1; x++) {
            double qx = lx < x ? x : lx > x + 1 ? x + 1 : lx;   /* nearest point */
            double qz = lz < z ? z : lz > z + 1 ? z + 1 : lz;
            if ((qx - lx) * (qx - lx) + (qz - lz) * (qz - lz) >= rc * rc)
                continue;
            ds->touched[w->ntouched++] = z * n + x;
            w->nnew += ds->cell_tile[z * n + x] < 0;
        }
}

/* 2. A tile for each touched cell without one (cleared in the atlas), and
 * the rectangle of indirection texels that changed, staged at offset 0. */
static void crater_tiles(rt_destruction *ds, uint8_t *staging, crater_work *w)
{
    int n = ds->n;
    w->ix0 = n, w->iz0 = n, w->ix1 = -1, w->iz1 = -1;
    for (int i = 0; i < w->ntouched; i++) {
        int cell = ds->touched[i];
        if (ds->cell_tile[cell] >= 0)
            continue;
        int slot = ds->free_tiles[--ds->nfree];
        ds->cell_tile[cell] = slot;
        ds->used++;
        int tx = slot % ds->cols, tz = slot / ds->cols;
        uint8_t *px = ds->index + (size_t)cell * 4;
        px[0] = (uint8_t)tx;
        px[1] = (uint8_t)tz;
        px[2] = 0;
        px[3] = 255;
        int x = cell % n, z = cell / n;
        w->ix0 = x < w->ix0 ? x : w->ix0;
        w->ix1 = x > w->ix1 ? x : w->ix1;
        w->iz0 = z < w->iz0 ? z : w->iz0;
        w->iz1 = z > w->iz1 ? z : w->iz1;
        ds->clears[w->nclear++] = (VkClearRect){
            { { tx * RT_DESTR_TILE, tz * RT_DESTR_TILE }, { RT_DESTR_TILE, RT_DESTR_TILE } }, 0, 1 };
    }
    VkDeviceSize off = 0;
    w->index_off = 0;
    if (w->ix1 >= 0) {
        int rw = w->ix1 - w->ix0 + 1;
        for (int z = w->iz0; z <= w->iz1; z++)
            memcpy(staging + off + (size_t)(z - w->iz0) * (size_t)rw * 4,
                   ds->index + ((size_t)z * (size_t)n + (size_t)w->ix0) * 4, (size_t)rw * 4);
        off += (VkDeviceSize)rw * (VkDeviceSize)(w->iz1 - w->iz0 + 1) * 4;
    }
    w->height_off = (off + 3) & ~(VkDeviceSize)3;
}

/* 3. Heights: texel centres inside the disc and inside the grid sink by
 * depth * (1 - d^2)^2; the changed rectangle is staged after the index. */
static void crater_heights(rt_destruction *ds, const rt_crater *c, double depth,
                           uint8_t *staging, crater_work *w, rt_crater_stats *st)
{
    double r = c->radius, gx0 = ds->origin[0], gz0 = ds->origin[1], ext = ds->n * ds->cell;
    double dx = ds->size[0] / ds->hw, dz = ds->size[1] / ds->hh;
    double ax0 = fmax(c->x - r, gx0), ax1 = fmin(c->x + r, gx0 + ext);
    double az0 = fmax(c->z - r, gz0), az1 = fmin(c->z + r, gz0 + ext);
    int tx0 = (int)ceil(ax0 / dx - 0.5), tx1 = (int)floor(ax1 / dx - 0.5);
    int tz0 = (int)ceil(az0 / dz - 0.5), tz1 = (int)floor(az1 / dz - 0.5);
    tx0 = tx0 < 0 ? 0 : tx0;
    tz0 = tz0 < 0 ? 0 : tz0;
    tx1 = tx1 >= ds->hw ? ds->hw - 1 : tx1;
    tz1 = tz1 >= ds->hh ? ds->hh - 1 : tz1;
    double units = depth / (ds->max_height > 0 ? ds->max_height : 1.0) * 65535.0;
    w->hx0 = ds->hw, w->hz0 = ds->hh, w->hx1 = -1, w->hz1 = -1;
    for (int z = tz0; depth > 0 && z <= tz1; z++)
        for (int x = tx0; x <= tx1; x++) {
            double wx = (x + 0.5) * dx, wz = (z + 0.5) * dz;
            if (wx < gx0 || wx > gx0 + ext || wz < gz0 || wz > gz0 + ext)
                continue;
            double d2 = ((wx - c->x) * (wx - c->x) + (wz - c->z) * (wz - c->z)) / (r * r);
            if (d2 >= 1.0)
                continue;
            double k = (1.0 - d2) * (1.0 - d2);
            uint16_t *h = &ds->heights[(size_t)z * (size_t)ds->hw + (size_t)x];
            double v = *h - units * k;
            uint16_t nv = (uint16_t)(v <= 0 ? 0 : lrint(v));
            if (nv == *h)
                continue;
            *h = nv;
            st->texels++;
            w->hx0 = x < w->hx0 ? x : w->hx0;
            w->hx1 = x > w->hx1 ? x : w->hx1;
            w->hz0 = z < w->hz0 ? z : w->hz0;
            w->hz1 = z > w->hz1 ? z : w->hz1;
        }
    if (w->hx1 >= 0) {
        int rw = w->hx1 - w->hx0 + 1;
        for (int z = w->hz0; z <= w->hz1; z++)
            memcpy(staging + w->height_off + (size_t)(z - w->hz0) * (size_t)rw * 2,
                   ds->heights + (size_t)z * (size_t)ds->hw + (size_t)w->hx0, (size_t)rw * 2);
        st->upload[0] = w->hx0;
        st->upload[1] = w->hz0;
        st->upload[2] = rw;
        st->upload[3] = w->hz1 - w->hz0 + 1;
    }
}

/* 4. Record and submit on ring slot k: the uploads, then the decals. */
static bool crater_submit(rt_destruction *ds, int k, const crater_work *w, rt_error *e)
{
    VkCommandBuffer cb = ds->cb[k];
    RT_VK(e, vkResetCommandBuffer(cb, 0));
    VkCommandBufferBeginInfo bi = { .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                    .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT };
    RT_VK(e, vkBeginCommandBuffer(cb, &bi));
    if (w->ix1 >= 0)
        upload_rect(ds, ds->indir.img, w->index_off, w->ix0, w->iz0, w->ix1 - w->ix0 + 1,
                    w->iz1 - w->iz0 + 1);
    if (w->hx1 >= 0)
        upload_rect(ds, ds->height->img, w->height_off, w->hx0, w->hz0, w->hx1 - w->hx0 + 1,
                    w->hz1 - w->hz0 + 1);
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = ds->pass, .framebuffer = ds->fb,
        .renderArea = { { 0, 0 }, { ds->atlas.width, ds->atlas.height } },
    };
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    if (w->nclear > 0) {
        VkClearAttachment ca = { VK_IMAGE_ASPECT_COLOR_BIT, 0, { .color = { { 0, 0, 0, 0 } } } };
        vkCmdClearAttachments(cb, 1, &ca, (uint32_t)w->nclear, ds->clears);
    }
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, ds->pipe);
    for (int i = 0; i < w->ntouched; i++) {
        int cell = ds->touched[i], x = cell % ds->n, z = cell / ds->n;
        int slot = ds->cell_tile[cell];
        float tx = (float)(slot % ds->cols * RT_DESTR_TILE);
        float tz = (float)(slot / ds->cols * RT_DESTR_TILE);
        VkViewport vp = { tx, tz, RT_DESTR_TILE, RT_DESTR_TILE, 0, 1 };
        VkRect2D sc = { { (int32_t)tx, (int32_t)tz }, { RT_DESTR_TILE, RT_DESTR_TILE } };
        vkCmdSetViewport(cb, 0, 1, &vp);
        vkCmdSetScissor(cb, 0, 1, &sc);
        decal_push push = {
            { (float)(w->lx - x), (float)(w->lz - z), (float)w->rc, (float)w->strength },
            { (float)(x * ds->cell), (float)(z * ds->cell), (float)ds->cell, 0.0f },
        };
        vkCmdPushConstants(cb, ds->layout, VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push, &push);
        vkCmdDraw(cb, 4, 1, 0, 0);
    }
    vkCmdEndRenderPass(cb);
    RT_VK(e, vkEndCommandBuffer(cb));
    VkSubmitInfo si = { .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
                        .commandBufferCount = 1, .pCommandBuffers = &cb };
    RT_VK(e, vkQueueSubmit(ds->d->queue, 1, &si, ds->fence[k]));
    return true;
}

bool rt_destruction_crater(rt_destruction *ds, const rt_crater *c, rt_crater_stats *st,
                           rt_error *e)
{
    double t0 = 1e3 * splat_now();
    rt_crater_stats local;
    if (!st)
        st = &local;
    memset(st, 0, sizeof *st);
    st->pool = ds->pool;
    st->tiles_used = ds->used;
    if (!(c->radius > 0) || !isfinite(c->radius) || !isfinite(c->x) || !isfinite(c->z)) {
        st->result = RT_CRATER_OUTSIDE;
        return true;
    }
    double depth = c->depth > 0 ? c->depth : 0.0;
    crater_work w = { .strength = c->strength > 0 ? (c->strength < 1 ? c->strength : 1.0)
                                                  : 1.0 };
    crater_cells(ds, c, &w);
    if (w.ntouched == 0) {
        st->result = RT_CRATER_OUTSIDE;
        st->cpu_ms = 1e3 * splat_now() - t0;
        return true;
    }
    if (w.nnew > ds->nfree) {
        /* Documented behaviour: refuse the whole crater, change nothing. */
        fprintf(stderr, "splatrt: warning: destruction tile pool exhausted (%d of %d tiles "
                "used, this crater needs %d more): crater at (%.1f, %.1f) m refused\n",
                ds->used, ds->pool, w.nnew, c->x, c->z);
        ds->refused++;
        st->result = RT_CRATER_REFUSED;
        st->cells = w.ntouched;
        st->cpu_ms = 1e3 * splat_now() - t0;
        return true;
    }
    int k = ds->slot;
    if (ds->pending[k]) {   /* the oldest event still runs: its memory */
        double tw = 1e3 * splat_now();
        RT_VK(e, vkWaitForFences(ds->d->dev, 1, &ds->fence[k], VK_TRUE, UINT64_MAX));
        RT_VK(e, vkResetFences(ds->d->dev, 1, &ds->fence[k]));
        ds->pending[k] = false;
        st->wait_ms = 1e3 * splat_now() - tw;
    }
    crater_tiles(ds, ds->staging[k].map, &w);
    crater_heights(ds, c, depth, ds->staging[k].map, &w, st);
    if (!crater_submit(ds, k, &w, e))
        return false;
    ds->pending[k] = true;
    ds->slot = (k + 1) % RT_DESTR_RING;
    if (w.hx1 >= 0)     /* 5. node bounds */
        update_bounds(ds, w.hx0, w.hz0, w.hx1, w.hz1);

    st->result = RT_CRATER_DONE;
    st->cells = w.ntouched;
    st->tiles_new = w.nclear;
    st->tiles_used = ds->used;
    st->cpu_ms = 1e3 * splat_now() - t0 - st->wait_ms;
    ds->craters++;
    ds->last_ms = st->cpu_ms;
    ds->max_ms = st->cpu_ms > ds->max_ms ? st->cpu_ms : ds->max_ms;
    ds->total_ms += st->cpu_ms;
    return true;
}

/* ---- reading back, picking, reporting -------------------------------------- */

bool rt_destruction_wait(rt_destruction *ds, rt_error *e)
{
    for (int i = 0; ds && i < RT_DESTR_RING; i++)
        if (ds->pending[i]) {
            RT_VK(e, vkWaitForFences(ds->d->dev, 1, &ds->fence[i], VK_TRUE, UINT64_MAX));
            RT_VK(e, vkResetFences(ds->d->dev, 1, &ds->fence[i]));
            ds->pending[i] = false;
        }
    return true;
}

bool rt_read_r16(rt_device *d, const rt_image *img, uint16_t *out, rt_error *e)
{
    size_t bytes = (size_t)img->width * img->height * 2;
    rt_buffer buf;
    if (!rt_buffer_create(d, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &buf, e))
        return false;
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(d, &cb, e)) {
        rt_buffer_destroy(d, &buf);
        return false;
    }
    const VkPipelineStageFlags shaders = VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                                         VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
    rt_cmd_image_barrier(cb, img->img, 0, 1, 1, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_READ_BIT |
                  VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                  shaders | VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy copy = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { img->width, img->height, 1 },
    };
    vkCmdCopyImageToBuffer(cb, img->img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf.buf, 1, &copy);
    rt_cmd_image_barrier(cb, img->img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_READ_BIT,
                  VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, shaders);
    VkBufferMemoryBarrier hb = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER,
        .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT, .dstAccessMask = VK_ACCESS_HOST_READ_BIT,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .buffer = buf.buf, .size = VK_WHOLE_SIZE,
    };
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                         NULL, 1, &hb, 0, NULL);
    bool ok = rt_oneshot_end(d, cb, e);
    if (ok)
        memcpy(out, buf.map, bytes);
    rt_buffer_destroy(d, &buf);
    return ok;
}

void rt_destruction_print_stats(const rt_destruction *ds, FILE *out)
{
    double dens = RT_DESTR_TILE / ds->cell;
    fprintf(out, "destruction: %d x %d cells of %g m from (%g, %g) m, %.2f px/m; "
            "indirection RGBA8 %d B; atlas %ux%u R8 = %u B, pool %d tiles of %dx%d, "
            "%d used\n", ds->n, ds->n, ds->cell, ds->origin[0], ds->origin[1], dens,
            ds->n * ds->n * 4, ds->atlas.width, ds->atlas.height,
            ds->atlas.width * ds->atlas.height, ds->pool, RT_DESTR_TILE, RT_DESTR_TILE,
            ds->used);
    if (ds->craters || ds->refused)
        fprintf(out, "crater events: %d (%d refused), cpu ms/event: last %.3f  max %.3f  "
                "mean %.3f\n", ds->craters, ds->refused, ds->last_ms, ds->max_ms,
                ds->craters ? ds->total_ms / ds->craters : 0.0);
    /* this scene's area, and the slides' configuration (Andersson 2007 (slides)) */
    double side = ds->n * ds->cell;
    rt_destruction_figures f;
    rt_destruction_memory(side, dens, ds->cell, 0.10, &f);
    fprintf(out, "destruction memory, this area at 10%% coverage: dense 8-bit %.0f B, "
            "sparse %.0f B (%d tiles + RG88 indirection) = %.1f %%\n", f.dense_bytes,
            f.sparse_bytes, f.tiles, 100.0 * f.sparse_bytes / f.dense_bytes);
    rt_destruction_memory(2048, 4, 16, 0.10, &f);
    fprintf(out, "destruction memory, slides' configuration (2048 m, 4 px/m, 16 m cells, "
            "%dx%d RG88 indirection, %dx%d L8 tiles, 10%% scattered): dense %.1f MB, "
            "sparse %.2f MB = %.1f %%\n", f.cells, f.cells, f.tile_px, f.tile_px,
            f.dense_bytes / 1e6, f.sparse_bytes / 1e6, 100.0 * f.sparse_bytes / f.dense_bytes);
}
