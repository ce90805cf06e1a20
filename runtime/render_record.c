/* render_record.c — a frame: the quadtree selection, patches grouped by
 * combination and drawn with one pipeline bind per group, camera-relative
 * patch corners computed in double and pushed as floats, GPU time from
 * timestamp queries.  The reference modes draw the same patches with the
 * multi-pass alpha-blended material passes (+ a resolve pass) or the
 * über-shader.
 *
 * Nothing in the frame loop allocates or uploads textures: the per-frame
 * work is the selection (preallocated arrays), a counting sort by
 * combination, a uniform write into mapped memory and one command buffer. */
#include "render_int.h"
#include "util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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

/* ---- the passes ------------------------------------------------------------------ */

/* What every pass's recorder reads. */
typedef struct rec {
    rt_renderer          *r;
    VkCommandBuffer       cb;
    const rt_camera      *c;
    splat_frame          *fr;
    const rt_frame_setup *fs;
    VkViewport            vp;
    VkRect2D              area;
    int                   binds;       /* pipelines bound (stats)            */
    double                shadow_ms;   /* the shadow update's wall time      */
} rec;

static bool pipe_bind(rec *x, VkPipeline pipe)
{
    vkCmdBindPipeline(x->cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
    x->binds++;
    return true;
}

static bool rec_shadow(rec *x, rt_error *e)
{
    return rt_render_update_shadow(x->r, &x->shadow_ms, e);
}

static bool rec_destruction(rec *x, rt_error *e)
{
    (void)e;
    rt_destruction_frame(x->r->destr, x->fr);
    return true;
}

static bool rec_ug_generate(rec *x, rt_error *e)
{
    return rt_ug_generate(x->r->ug, x->cb, x->fr, x->r->set1, 0, e);
}

/* The screen path's geometry pass: the patches, depth only. */
static bool rec_depth(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    VkFramebuffer fb;
    VkRenderPass pass = rt_screen_depth_pass(r->screen, &fb);
    VkClearValue clear = { .depthStencil = { 0.0f, 0 } };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = pass, .framebuffer = fb,
        .renderArea = x->area, .clearValueCount = 1, .pClearValues = &clear,
    };
    VkDescriptorSet sets[2] = { r->set0, r->set1 };
    begin_terrain_pass(r, x->cb, &rb, &x->vp, sets);
    VkPipeline pipe;
    bool ok = r->qt.npatches == 0 ||
              (rt_pipelines_depth(r->d, &r->pl, pass, x->fs->cull, &pipe, e) && pipe_bind(x, pipe));
    if (ok)
        draw_patches(r, x->cb, x->c, r->sorted, r->qt.npatches);
    vkCmdEndRenderPass(x->cb);
    return ok;
}

static bool rec_raycast(rec *x, rt_error *e)
{
    (void)e;
    rt_screen_raycast(x->r->screen, x->cb, x->r->set0c);
    x->binds++;
    return true;
}

static bool rec_tiles_reset(rec *x, rt_error *e)
{
    return rt_screen_begin(x->r->screen, x->cb, (x->fs->cvariant & RT_CVARIANT_COUNT) != 0,
                           &x->r->qt, x->r->desc.no_distance_classes, e);
}

static bool rec_classify(rec *x, rt_error *e)
{
    (void)e;
    rt_renderer *r = x->r;
    rt_screen_classify(r->screen, x->cb, r->set0c, r->desc.clear,
                       r->desc.reference == RT_REF_UBER || r->view == SPLAT_VIEW_MASK,
                       r->desc.no_distance_classes, &x->binds);
    return true;
}

static bool rec_shade(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    VkDescriptorSet csets[2] = { r->set0c, r->set1 };
    /* with async pipelines a stand-in shades the lists whose pipelines
     * are being made: the über-shader once it is made, else the far atlas
     * or the flat stand-in, nearly free to make (rt_pipelines_stand_in);
     * with none (SPLAT_STAND_IN=uber|always before the über-shader is
     * made, or never) a list without a pipeline is left for
     * rt_screen_missing, which makes the über-shader or the lists'
     * pipelines and draws again */
    rt_stand_in stand_in = rt_pipelines_stand_in(r->d, r->p, &r->pl, NULL, 0, x->fs->cvariant,
                                                 rt_screen_has_far(r->screen));
    return rt_screen_dispatch(r->screen, x->cb, &r->pl, csets, x->fs->cvariant, stand_in,
                              &x->binds, e);
}

static bool rec_shade_far(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    VkDescriptorSet csets[2] = { r->set0c, r->set1 };
    return rt_screen_dispatch_far(r->screen, x->cb, &r->pl, csets, x->fs->cvariant, &x->binds,
                                  e);
}

static bool rec_tile_counts(rec *x, rt_error *e)
{
    (void)e;
    rt_screen_counts(x->r->screen, x->cb);
    return true;
}

/* The forward path's counters: zeroed before the pass, copied back after. */
static bool rec_count_reset(rec *x, rt_error *e)
{
    (void)e;
    vkCmdFillBuffer(x->cb, x->r->counters.buf, 0, sizeof(splat_counters), 0);
    return true;
}

static bool rec_count_read(rec *x, rt_error *e)
{
    (void)e;
    VkBufferCopy c = { 0, 0, sizeof(splat_counters) };
    vkCmdCopyBuffer(x->cb, x->r->counters.buf, x->r->counters_host.buf, 1, &c);
    return true;
}

/* The main render pass (group 1: forward, far, uber, sky): begun before
 * its first pass, the composites it draws made first. */
static bool begin_main(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    if (x->fs->composites && !make_forward_pipelines(r, x->fs->variant, e))
        return false;
    VkClearValue clears[2];
    VkDescriptorSet sets[2] = { r->set0, r->set1 };
    clears[0].color = (VkClearColorValue){ { r->desc.clear[0], r->desc.clear[1], r->desc.clear[2], 1 } };
    clears[1].depthStencil = (VkClearDepthStencilValue){ 0.0f, 0 };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = r->rp.main, .framebuffer = r->fb_main,
        .renderArea = x->area, .clearValueCount = 2, .pClearValues = clears,
    };
    begin_terrain_pass(r, x->cb, &rb, &x->vp, sets);
    return true;
}

/* Where the far group starts in r->sorted (select_and_sort). */
static int far_start(const rt_renderer *r)
{
    return r->ncombos > 0 ? r->counts[r->ncombos - 1] : 0;
}

/* The forward path: each group of patches with its composite (or every
 * patch with the über-shader: --reference uber, and the MASK view, which
 * composites do not carry: compiler/build_jobs.c). */
static bool rec_forward(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    unsigned variant = x->fs->variant;
    VkPipeline pipe;
    if (!x->fs->composites) {
        int n = r->qt.npatches;
        if (n > 0 && !(rt_pipelines_uber(r->d, r->p, &r->rp, &r->pl, variant, &pipe, e) &&
                       pipe_bind(x, pipe)))
            return false;
        draw_patches(r, x->cb, x->c, r->sorted, n);
        return true;
    }
    for (int k = 0, start = 0; k < r->ncombos; start = r->counts[k++]) {
        int end = r->counts[k];
        if (end <= start)
            continue;
        if (!rt_pipelines_combo(r->d, r->p, &r->rp, &r->pl, k, variant, &pipe, e))
            return false;
        pipe_bind(x, pipe);
        draw_patches(r, x->cb, x->c, r->sorted + start, end - start);
    }
    return true;
}

static bool rec_far(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    if (!rt_far_bind_forward(r->far, r->p, &r->rp, &r->pl, x->cb, x->fs->variant, e))
        return false;
    x->binds++;
    draw_patches(r, x->cb, x->c, r->sorted + far_start(r), r->far_patches);
    return true;
}

/* The patches no combination covers (select_and_sort's last group). */
static bool rec_uber(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    VkPipeline pipe;
    if (!rt_pipelines_uber(r->d, r->p, &r->rp, &r->pl, x->fs->variant, &pipe, e))
        return false;
    pipe_bind(x, pipe);
    draw_patches(r, x->cb, x->c, r->sorted + far_start(r) + r->far_patches, r->uber_patches);
    return true;
}

/* Where no terrain wrote depth. */
static bool rec_sky(rec *x, rt_error *e)
{
    (void)e;
    pipe_bind(x, x->r->pl.sky);
    vkCmdDraw(x->cb, 3, 1, 0, 0);
    return true;
}

/* The multi-pass reference: each material blended over every patch,
 * bottom to top ... */
static bool rec_multipass(rec *x, rt_error *e)
{
    rt_renderer *r = x->r;
    VkClearValue clears[4];
    VkDescriptorSet sets[2] = { r->set0, r->set1 };
    for (int i = 0; i < 3; i++)
        clears[i].color = (VkClearColorValue){ { 0, 0, 0, 0 } };
    clears[3].depthStencil = (VkClearDepthStencilValue){ 0.0f, 0 };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = r->rp.multi, .framebuffer = r->fb_multi,
        .renderArea = x->area, .clearValueCount = 4, .pClearValues = clears,
    };
    begin_terrain_pass(r, x->cb, &rb, &x->vp, sets);
    bool ok = true;
    for (int m = 0; ok && m < r->pl.nref; m++) {
        VkPipeline pipe;
        ok = rt_pipelines_ref(r->d, r->p, &r->rp, &r->pl, m, x->fs->cull, &pipe, e);
        if (ok) {
            pipe_bind(x, pipe);
            draw_patches(r, x->cb, x->c, r->sorted, r->qt.npatches);
        }
    }
    vkCmdEndRenderPass(x->cb);
    return ok;
}

/* ... then the resolve pass lights the blended surface. */
static bool rec_resolve(rec *x, rt_error *e)
{
    (void)e;
    rt_renderer *r = x->r;
    VkCommandBuffer cb = x->cb;
    VkDescriptorSet sets[3] = { r->set0, r->set1, r->set2 };
    VkClearValue clear;
    clear.color = (VkClearColorValue){ { r->desc.clear[0], r->desc.clear[1], r->desc.clear[2], 1 } };
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = r->rp.resolve, .framebuffer = r->fb_resolve,
        .renderArea = x->area, .clearValueCount = 1, .pClearValues = &clear,
    };
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdSetViewport(cb, 0, 1, &x->vp);
    vkCmdSetScissor(cb, 0, 1, &x->area);
    pipe_bind(x, r->pl.resolve);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, r->pl.resolve_layout, 0, 3, sets, 0, NULL);
    splat_push none;
    memset(&none, 0, sizeof none);
    vkCmdPushConstants(cb, r->pl.resolve_layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof none, &none);
    vkCmdDraw(cb, 3, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    return true;
}

static bool rec_depth_copy(rec *x, rt_error *e)
{
    (void)e;
    rt_screen_depth_out(x->r->screen, x->cb, &x->r->depth);
    return true;
}

static bool rec_ug_draw(rec *x, rt_error *e)
{
    (void)e;
    rt_renderer *r = x->r;
    rt_ug_draw(r->ug, x->cb, x->fs->screen, r->set0, r->set1, r->set0c, &x->vp, &x->area);
    return true;
}

static bool rec_upscale(rec *x, rt_error *e)
{
    (void)e;
    rt_upscale_record(x->r->upscale, x->cb, x->fs->screen);
    x->binds++;
    return true;
}

static bool rec_readback(rec *x, rt_error *e)
{
    (void)e;
    rt_renderer *r = x->r;
    VkBufferImageCopy copy = {
        .imageSubresource = { VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1 },
        .imageExtent = { (uint32_t)r->out_w, (uint32_t)r->out_h, 1 },
    };
    vkCmdCopyImageToBuffer(x->cb, r->scale > 1 ? r->out.img : r->color.img,
                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           r->readback.buf, 1, &copy);
    return true;
}

static bool (*const recorders[RT_PASS_KINDS])(rec *, rt_error *) = {
    [RT_PASS_SHADOW] = rec_shadow,           [RT_PASS_DESTRUCTION] = rec_destruction,
    [RT_PASS_UG_GENERATE] = rec_ug_generate, [RT_PASS_DEPTH] = rec_depth,
    [RT_PASS_RAYCAST] = rec_raycast,         [RT_PASS_TILES_RESET] = rec_tiles_reset,
    [RT_PASS_CLASSIFY] = rec_classify,       [RT_PASS_SHADE] = rec_shade,
    [RT_PASS_SHADE_FAR] = rec_shade_far,     [RT_PASS_TILE_COUNTS] = rec_tile_counts,
    [RT_PASS_COUNT_RESET] = rec_count_reset, [RT_PASS_FORWARD] = rec_forward,
    [RT_PASS_FAR] = rec_far,                 [RT_PASS_UBER] = rec_uber,
    [RT_PASS_SKY] = rec_sky,                 [RT_PASS_MULTIPASS] = rec_multipass,
    [RT_PASS_RESOLVE] = rec_resolve,         [RT_PASS_COUNT_READ] = rec_count_read,
    [RT_PASS_DEPTH_COPY] = rec_depth_copy,   [RT_PASS_UG_DRAW] = rec_ug_draw,
    [RT_PASS_UPSCALE] = rec_upscale,         [RT_PASS_READBACK] = rec_readback,
};

/* ---- the walk ------------------------------------------------------------------ */

/* The passes [from, npasses) recorded into x->cb: host passes run, each
 * group after the barrier its declarations need; with `timed`, a
 * timestamp (query 0 is the start) after the last GPU pass, after the
 * screen path's depth and classification, and with r->pass_times after
 * every GPU pass (few timestamps by default: the frame's GPU time stays
 * what it measured before the plan).  On failure the
 * command buffer is ended (reset by the next frame). */
static bool stamped(const rt_renderer *r, const rt_plan *pl, int i)
{
    rt_pass_kind k = pl->pass[i].kind;
    bool last = true;
    for (int j = i + 1; j < pl->npasses; j++)
        last &= pl->pass[j].host || pl->pass[j].own;
    return r->pass_times || last || k == RT_PASS_DEPTH || k == RT_PASS_RAYCAST ||
           k == RT_PASS_CLASSIFY;
}

static bool record_plan(rec *x, rt_plan *pl, int from, bool timed, rt_error *e)
{
    rt_renderer *r = x->r;
    uint32_t q = 1;
    for (int i = from; i < pl->npasses;) {
        rt_pass *p = &pl->pass[i];
        if (p->host) {
            if (!recorders[p->kind](x, e))
                goto fail;
            for (int k = 0; k < p->nuse; k++)
                if (p->use[k].write && !(p->use[k].stage & VK_PIPELINE_STAGE_HOST_BIT))
                    rt_tracker_written(&r->tracker, (rt_resource)p->use[k].res, p->use[k].stage,
                                       p->use[k].access);
            i++;
            continue;
        }
        int n = 1;
        while (p->group && i + n < pl->npasses && pl->pass[i + n].group == p->group)
            n++;
        rt_tracker_before(&r->tracker, x->cb, p, n);
        bool main = p->group == 1;
        if (main && !begin_main(x, e))
            goto fail;
        for (int k = 0; k < n; k++) {
            if (!recorders[p[k].kind](x, e)) {
                if (main)
                    vkCmdEndRenderPass(x->cb);
                goto fail;
            }
            if (timed && stamped(r, pl, i + k)) {
                vkCmdWriteTimestamp(x->cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r->qpool, q);
                p[k].query = (int)q++;
            }
        }
        if (main)
            vkCmdEndRenderPass(x->cb);
        i += n;
    }
    rt_tracker_finish(&r->tracker, x->cb);
    return true;
fail:
    vkEndCommandBuffer(x->cb);
    return false;
}

/* GPU times from the timestamps: each pass's, the whole frame's, and on
 * the screen path its three parts (the depth and what came before it,
 * the classification, the shading and what follows). */
static bool read_times(rt_renderer *r, rt_plan *pl, rt_frame_stats *st, rt_error *e)
{
    st->gpu_ms = -1;
    for (int i = 0; i < 3; i++)
        st->pass_ms[i] = -1;
    if (!r->timestamps)
        return true;
    uint64_t q[RT_PLAN_MAX_PASSES + 1];
    int nq = 1;
    for (int i = 0; i < pl->npasses; i++)
        nq = pl->pass[i].query >= nq ? pl->pass[i].query + 1 : nq;
    RT_VK(e, vkGetQueryPoolResults(r->d->dev, r->qpool, 0, (uint32_t)nq, sizeof q, q,
                                   sizeof q[0], VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    double ms = r->d->props.limits.timestampPeriod * 1e-6;
    st->gpu_ms = (double)(q[nq - 1] - q[0]) * ms;
    int part = 0;
    if (st->screen)
        for (int i = 0; i < 3; i++)
            st->pass_ms[i] = 0;
    for (int i = 0, last = 0; i < pl->npasses; i++) {
        rt_pass *p = &pl->pass[i];
        if (!p->query)
            continue;
        p->gpu_ms = (double)(q[p->query] - q[last]) * ms;
        last = p->query;
        if (st->screen)
            st->pass_ms[part] += p->gpu_ms;
        if (p->kind == RT_PASS_DEPTH || p->kind == RT_PASS_RAYCAST)
            part = 1;
        else if (p->kind == RT_PASS_CLASSIFY)
            part = 2;
    }
    return true;
}

/* ---- a frame ------------------------------------------------------------------- */

static bool begin_commands(VkCommandBuffer cb, rt_error *e)
{
    RT_VK(e, vkResetCommandBuffer(cb, 0));
    VkCommandBufferBeginInfo bi = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    RT_VK(e, vkBeginCommandBuffer(cb, &bi));
    return true;
}

static void frame_stats(rt_renderer *r, const rt_frame_setup *fs, const rec *x, int in_view,
                        rt_frame_stats *st)
{
    memset(st, 0, sizeof *st);
    st->patches = r->qt.npatches;
    st->culled = r->qt.nculled;
    st->pipelines = x->binds;
    st->combos_in_view = in_view;
    for (int i = 0; i < r->qt.npatches && !fs->screen; i++)
        st->class_patches += r->qt.patches[i].combo >= r->p->nbase &&
                             r->qt.patches[i].combo < r->ncombos;
    st->far_patches = fs->screen ? 0 : r->far_patches;
    st->uber_patches = fs->screen ? 0 : r->uber_patches;
    st->split_uncovered = r->qt.nsplit_uncovered;
    st->backfaces_culled = fs->cull;
    st->screen = fs->screen;
    st->sorted = fs->screen && rt_screen_sorting(r->screen);
    if (fs->screen)
        rt_screen_read_stats(r->screen, &st->tiles);
    else if (fs->count)
        rt_counters_read(r->counters_host.map, &st->tiles);
    rt_ug_read_stats(fs->ug ? r->ug : NULL, &st->undergrowth);
}

/* The frame: the state worked out (rt_render_setup), the selection, the
 * plan (rt_render_plan), its recording and submission. */
static bool draw_frame(rt_renderer *r, const rt_camera *c, rt_frame_stats *st,
                       double *shadow_ms, rt_error *e)
{
    double t0 = 1e3 * splat_now(), select_ms;
    rt_frame_setup fs;
    rt_render_setup(r, &fs);
    splat_frame *fr = r->frame_ubo.map;
    rt_render_fill_frame(r, c, fr);
    int in_view = select_and_sort(r, c, fr, fs.far, fs.split, &select_ms);
    fs.cull = !r->desc.no_cull && camera_above_terrain(r, c);
    fs.variant = (r->wireframe ? RT_VARIANT_WIRE : 0) |
                 (r->view != SPLAT_VIEW_FINAL ? RT_VARIANT_DEBUG : 0) |
                 (fs.cull ? RT_VARIANT_CULL : 0) | (fs.count ? RT_VARIANT_COUNT : 0);
    if (fs.ug)
        rt_ug_prepare(r->ug, c, fr);
    fs.ug_draw = fs.ug && rt_ug_visible(r->ug);
    rt_render_plan(r, &fs, &r->plan);

    rec x = { .r = r, .cb = r->cb, .c = c, .fr = fr, .fs = &fs,
              .vp = { 0, 0, (float)r->desc.width, (float)r->desc.height, 0, 1 },
              .area = { { 0, 0 }, { (uint32_t)r->desc.width, (uint32_t)r->desc.height } } };
    if (!begin_commands(r->cb, e))
        return false;
    if (r->timestamps) {
        vkCmdResetQueryPool(r->cb, r->qpool, 0, RT_PLAN_MAX_PASSES + 1);
        vkCmdWriteTimestamp(r->cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, r->qpool, 0);
    }
    r->tracker.barriers = 0;
    if (!record_plan(&x, &r->plan, 0, r->timestamps, e))
        return false;
    r->plan.barriers = r->tracker.barriers;
    *shadow_ms = x.shadow_ms;
    RT_VK(e, vkEndCommandBuffer(r->cb));
    VkSubmitInfo si = {
        .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO,
        .commandBufferCount = 1,
        .pCommandBuffers = &r->cb,
    };
    double cpu_ms = 1e3 * splat_now() - t0 - x.shadow_ms;
    RT_VK(e, vkQueueSubmit(r->d->queue, 1, &si, r->fence));
    RT_VK(e, vkWaitForFences(r->d->dev, 1, &r->fence, VK_TRUE, UINT64_MAX));
    RT_VK(e, vkResetFences(r->d->dev, 1, &r->fence));
    frame_stats(r, &fs, &x, in_view, st);
    st->select_ms = select_ms;
    st->cpu_ms = cpu_ms;
    return read_times(r, &r->plan, st, e);
}

/* The first complete frame's time since launch, kept: the picture is on
 * the GPU (the fence waited for), before any readback. */
static bool first_picture(rt_renderer *r, rt_frame_stats *st)
{
    if (r->first_picture_s <= 0) {
        r->first_picture_s = rt_seconds_since_launch();
        rt_launch_mark("first picture");
    }
    st->first_picture_s = r->first_picture_s;
    return true;
}

/* A frame; on the screen-space path, drawn again while lists got tiles
 * whose pipelines did not exist yet (compiled in between): at most once
 * per variant in practice, since the classification is deterministic. */
bool rt_renderer_frame(rt_renderer *r, const rt_camera *c, rt_frame_stats *st, rt_error *e)
{
    rt_frame_stats local;
    if (!st)
        st = &local;
    double shadow_ms = 0, compile_ms = 0;
    for (int redraws = 0;; redraws++) {
        double ms = 0;   /* the shadow map: the first draw's plan */
        if (!draw_frame(r, c, st, &ms, e))
            return false;
        shadow_ms += ms;
        st->redraws = redraws;
        st->shadow_ms = shadow_ms;
        st->compile_ms = compile_ms;
        st->spirv_cached = atomic_load(&r->pl.spirv_cached);
        st->spirv_compiled = atomic_load(&r->pl.spirv_compiled);
        if (rt_async_failed(&r->pl, e))
            return false;
        st->shadow_gpu = r->shadow_on_gpu;
        if (!st->screen)
            return first_picture(r, st);
        double t0 = splat_now();
        int made = rt_screen_missing(r->screen, &r->pl, rt_render_compute_variant(r), e);
        compile_ms += 1e3 * (splat_now() - t0);
        st->pipelines_pending = rt_async_pending(&r->pl);
        if (made < 0)
            return false;
        if (made == 0)
            return first_picture(r, st);
        if (redraws >= 3)
            return rt_fail(e, RT_E_VULKAN, "screen-space shading",
                           "tile lists still need new pipelines after 3 redraws");
    }
}

bool rt_renderer_wait_pipelines(rt_renderer *r, rt_error *e)
{
    rt_async_wait(&r->pl);
    return !rt_async_failed(&r->pl, e);
}

/* The readback pass, in a command buffer of its own after the frame:
 * appended to the frame's plan (--print-plan shows it last). */
bool rt_renderer_read(rt_renderer *r, float *rgba, rt_error *e)
{
    rt_plan *pl = &r->plan;
    if (pl->npasses && pl->pass[pl->npasses - 1].own)
        pl->npasses--;   /* a second read of the same frame: its pass again */
    int from = pl->npasses;
    rt_plan_readback(pl, r->scale > 1);
    pl->pass[from].own = true;
    rec x = { .r = r };
    if (!rt_oneshot_begin(r->d, &x.cb, e))
        return false;
    int before = r->tracker.barriers;
    if (!record_plan(&x, pl, from, false, e) || !rt_oneshot_end(r->d, x.cb, e))
        return false;
    pl->barriers += r->tracker.barriers - before;
    memcpy(rgba, r->readback.map, (size_t)r->out_w * (size_t)r->out_h * 16);
    return true;
}

void rt_renderer_set_pass_times(rt_renderer *r, bool on) { r->pass_times = on; }

void rt_renderer_print_plan(const rt_renderer *r, FILE *out, bool times)
{
    rt_plan_print(&r->plan, out, times);
}
