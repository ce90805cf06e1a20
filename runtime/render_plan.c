/* render_plan.c — the frame as a plan (a frame graph, after Frostbite's
 * FrameGraph, O'Donnell 2017, and Granite's render graph, much reduced):
 * rt_render_plan turns the renderer's state (path, view, knobs, what the
 * selection found) into the list of passes this frame runs, each
 * declaring the resources it reads and writes with the stage, access and
 * layout; a pass that does not apply this frame is not in the list.
 * render_record.c walks the list, and the barriers between passes come
 * from the declarations through a resource-state tracker (render_track.c):
 * per resource the last write not yet visible, the reads since, the
 * layout.
 *
 * A group (rt_pass.group) is passes recorded in one Vulkan render pass
 * (forward, far, uber, sky) or that write disjoint pixels (the screen
 * path's lists and its far list): one barrier before the group, none
 * between its passes.
 *
 * The screen path at 1280x720 with the far atlas on, as --print-plan
 * shows it (reads, then writes):
 *   destruction upload   host  reads -            writes frame
 *   depth                      reads frame height  writes depth
 *   tile lists reset           writes tiles (and the classification's view)
 *   classification             reads depth tiles   writes tiles color
 *   shading, far               reads tiles ...     writes color tiles
 *   tile counts                reads tiles         writes tiles-host */
#include "render_int.h"

#include <string.h>

#include "render_sync.h"

static void reads(rt_pass *p, rt_resource res, VkPipelineStageFlags st, VkAccessFlags a)
{
    rt_pass_use(p, res, false, st, a, NONE, NONE);
}

/* What every terrain shader reads (set 0): the frame block, the
 * heightfield, the craters, the shadow map. */
static void terrain_reads(rt_pass *p, VkPipelineStageFlags st)
{
    reads(p, RT_RES_FRAME, st, UREAD);
    reads(p, RT_RES_HEIGHT, st, SREAD);
    reads(p, RT_RES_DESTRUCTION, st, SREAD);
    reads(p, RT_RES_SHADOW, st, SREAD);
}

/* A draw into the main render pass (colour and depth, both written). */
static rt_pass *main_pass(rt_plan *pl, rt_pass_kind k, bool terrain)
{
    rt_pass *p = rt_plan_add(pl, k);
    p->group = 1;
    if (terrain)
        terrain_reads(p, VERT | FRAG);
    else
        reads(p, RT_RES_FRAME, FRAG, UREAD);
    rt_pass_use(p, RT_RES_COLOR, true, OUTPUT, CWRITE, NONE, SRC);
    rt_pass_use(p, RT_RES_DEPTH, true, TESTS, DREAD | DWRITE, NONE, ATT);
    return p;
}

static void plan_screen(const rt_renderer *r, const rt_frame_setup *fs, rt_plan *pl)
{
    rt_pass *p;
    if (fs->raycast) {
        p = rt_plan_add(pl, RT_PASS_RAYCAST);
        reads(p, RT_RES_FRAME, COMP, UREAD);
        reads(p, RT_RES_HEIGHT, COMP, SREAD);
        rt_pass_use(p, RT_RES_RAYDEPTH, true, COMP, SWRITE, NONE, GEN);
    } else {
        p = rt_plan_add(pl, RT_PASS_DEPTH);
        reads(p, RT_RES_FRAME, VERT | FRAG, UREAD);
        reads(p, RT_RES_HEIGHT, VERT | FRAG, SREAD);
        rt_pass_use(p, RT_RES_DEPTH, true, TESTS, DREAD | DWRITE, NONE, RO);
    }
    p = rt_plan_add(pl, RT_PASS_TILES_RESET);
    rt_pass_use(p, RT_RES_TILES, true, XFER, XWRITE, NONE, NONE);
    p = rt_plan_add(pl, RT_PASS_CLASSIFY);
    terrain_reads(p, COMP);
    rt_pass_use(p, fs->raycast ? RT_RES_RAYDEPTH : RT_RES_DEPTH, false, COMP, SREAD,
                fs->raycast ? GEN : RO, NONE);
    rt_pass_use(p, RT_RES_TILES, true, COMP, SREAD | SWRITE, NONE, NONE);
    rt_pass_use(p, RT_RES_COLOR, true, COMP, SWRITE, GEN, GEN);
    p->use[p->nuse - 1].discard = true;   /* every pixel: background or a tile */
    p = rt_plan_add(pl, RT_PASS_SHADE);
    p->group = 2;
    terrain_reads(p, COMP);
    reads(p, RT_RES_TILES, INDIRECT | COMP, IREAD | SREAD);
    rt_pass_use(p, RT_RES_TILES, true, COMP, SWRITE, NONE, NONE);   /* the counters */
    rt_pass_use(p, RT_RES_COLOR, true, COMP, SWRITE, GEN, GEN);
    if (rt_screen_far_on(r->screen)) {
        p = rt_plan_add(pl, RT_PASS_SHADE_FAR);
        p->group = 2;
        reads(p, RT_RES_FRAME, COMP, UREAD);
        reads(p, RT_RES_FAR, COMP, SREAD);
        reads(p, RT_RES_TILES, INDIRECT | COMP, IREAD | SREAD);
        rt_pass_use(p, RT_RES_TILES, true, COMP, SWRITE, NONE, NONE);
        rt_pass_use(p, RT_RES_COLOR, true, COMP, SWRITE, GEN, GEN);
    }
    p = rt_plan_add(pl, RT_PASS_TILE_COUNTS);
    reads(p, RT_RES_TILES, XFER, XREAD);
    rt_pass_use(p, RT_RES_TILES_HOST, true, XFER, XWRITE, NONE, NONE);
}

static void plan_forward(const rt_renderer *r, const rt_frame_setup *fs, rt_plan *pl)
{
    rt_pass *p;
    if (fs->count) {
        p = rt_plan_add(pl, RT_PASS_COUNT_RESET);
        rt_pass_use(p, RT_RES_COUNTERS, true, XFER, XWRITE, NONE, NONE);
    }
    p = main_pass(pl, RT_PASS_FORWARD, true);
    if (fs->count)
        rt_pass_use(p, RT_RES_COUNTERS, true, FRAG, SREAD | SWRITE, NONE, NONE);
    if (fs->composites && r->far_patches > 0) {
        p = main_pass(pl, RT_PASS_FAR, false);
        reads(p, RT_RES_FAR, FRAG, SREAD);
        reads(p, RT_RES_HEIGHT, VERT, SREAD);
    }
    if (fs->composites && r->uber_patches > 0)
        main_pass(pl, RT_PASS_UBER, true);
    if (fs->sky)
        main_pass(pl, RT_PASS_SKY, false);
    if (fs->count) {
        p = rt_plan_add(pl, RT_PASS_COUNT_READ);
        reads(p, RT_RES_COUNTERS, XFER, XREAD);
        rt_pass_use(p, RT_RES_COUNTERS_HOST, true, XFER, XWRITE, NONE, NONE);
    }
}

static void plan_multipass(rt_plan *pl)
{
    rt_pass *p = rt_plan_add(pl, RT_PASS_MULTIPASS);
    terrain_reads(p, VERT | FRAG);
    rt_pass_use(p, RT_RES_GBUFFER, true, OUTPUT, CWRITE | CREAD, NONE, RO);
    rt_pass_use(p, RT_RES_DEPTH, true, TESTS, DREAD | DWRITE, NONE, ATT);
    p = rt_plan_add(pl, RT_PASS_RESOLVE);
    reads(p, RT_RES_FRAME, FRAG, UREAD);
    reads(p, RT_RES_SHADOW, FRAG, SREAD);
    reads(p, RT_RES_GBUFFER, FRAG, SREAD);
    rt_pass_use(p, RT_RES_COLOR, true, OUTPUT, CWRITE, NONE, SRC);
}

/* The variant of the compute shading pipelines this frame needs. */
unsigned rt_render_compute_variant(const rt_renderer *r)
{
    return (r->view != SPLAT_VIEW_FINAL ? RT_CVARIANT_DEBUG : 0) |
           (r->counting || r->view == SPLAT_VIEW_COST || r->view == SPLAT_VIEW_LAYERS ? RT_CVARIANT_COUNT : 0) |
           (r->screen && rt_screen_sorting(r->screen) ? RT_CVARIANT_SORT : 0);
}

void rt_render_setup(const rt_renderer *r, rt_frame_setup *fs)
{
    memset(fs, 0, sizeof *fs);
    fs->screen = r->screen && r->shading == RT_SHADING_SCREEN &&
                 r->desc.reference != RT_REF_MULTIPASS && !r->wireframe;
    fs->multipass = !fs->screen && r->desc.reference == RT_REF_MULTIPASS;
    /* the far atlas on the forward path: composites only (not the
     * references, not the mask view, which the über-shader draws) */
    fs->far = !fs->screen && r->far && r->desc.far_atlas_distance > 0 &&
              r->desc.reference == RT_REF_NONE && r->view != SPLAT_VIEW_MASK;
    /* split_uncovered is the forward path's: the screen path classifies
     * its tiles from leaf cells whatever the patches */
    fs->split = !fs->screen && r->desc.split_uncovered;
    fs->composites = r->desc.reference != RT_REF_UBER && r->view != SPLAT_VIEW_MASK;
    /* the multi-pass reference has no counting variant */
    fs->count = (r->counting || r->view == SPLAT_VIEW_COST || r->view == SPLAT_VIEW_LAYERS) && !fs->screen &&
                r->d->count_fragments && !fs->multipass;
    fs->raycast = fs->screen && rt_screen_raycasting(r->screen);
    fs->sky = !fs->screen && !fs->multipass && rt_render_sky_drawn(r);
    fs->ug = r->ug && !r->ug_off && r->view == SPLAT_VIEW_FINAL && !r->wireframe;
    fs->shadow = rt_render_shadow_due(r);
    fs->cvariant = rt_render_compute_variant(r);
    fs->upscale = r->scale > 1;
}

void rt_render_plan(const rt_renderer *r, const rt_frame_setup *fs, rt_plan *pl)
{
    memset(pl, 0, sizeof *pl);
    pl->path = fs->screen ? "screen" : fs->multipass ? "multipass" : "forward";
    pl->width = r->desc.width;
    pl->height = r->desc.height;
    rt_pass *p;
    if (fs->shadow) {
        p = rt_plan_add(pl, RT_PASS_SHADOW);
        p->host = true;
        reads(p, RT_RES_HEIGHT, HOST, 0);
        rt_pass_use(p, RT_RES_SHADOW, true, r->shadow_on_gpu ? COMP | XFER : XFER,
                    r->shadow_on_gpu ? SWRITE | XWRITE : XWRITE, NONE, NONE);
    }
    if (r->destr) {
        p = rt_plan_add(pl, RT_PASS_DESTRUCTION);
        p->host = true;
        rt_pass_use(p, RT_RES_FRAME, true, HOST, VK_ACCESS_HOST_WRITE_BIT, NONE, NONE);
    }
    if (fs->ug) {
        p = rt_plan_add(pl, RT_PASS_UG_GENERATE);
        reads(p, RT_RES_FRAME, COMP, UREAD);
        reads(p, RT_RES_HEIGHT, COMP, SREAD);
        rt_pass_use(p, RT_RES_UG, true, COMP | XFER, SREAD | SWRITE | XWRITE, NONE, NONE);
    }
    if (fs->screen)
        plan_screen(r, fs, pl);
    else if (fs->multipass)
        plan_multipass(pl);
    else
        plan_forward(r, fs, pl);
    if (fs->ug_draw && fs->screen && fs->raycast) {
        p = rt_plan_add(pl, RT_PASS_DEPTH_COPY);
        reads(p, RT_RES_RAYDEPTH, XFER, XREAD);
        rt_pass_use(p, RT_RES_DEPTH, true, XFER, XWRITE, NONE, RO);
        p->use[p->nuse - 1].discard = true;
    }
    if (fs->ug_draw) {
        p = rt_plan_add(pl, RT_PASS_UG_DRAW);
        reads(p, RT_RES_FRAME, VERT | FRAG, UREAD);
        reads(p, RT_RES_UG, INDIRECT | VERT, IREAD | SREAD);
        reads(p, RT_RES_HEIGHT, VERT, SREAD);
        reads(p, RT_RES_SHADOW, FRAG, SREAD);
        /* the screen path's depth is read only (left SHADER_READ_ONLY) */
        rt_pass_use(p, RT_RES_DEPTH, !fs->screen, TESTS,
                    fs->screen ? DREAD : DREAD | DWRITE, fs->screen ? RO : ATT, NONE);
        rt_pass_use(p, RT_RES_COLOR, true, OUTPUT, CWRITE | CREAD, SRC, SRC);
    }
    if (fs->upscale) {
        p = rt_plan_add(pl, RT_PASS_UPSCALE);
        /* the screen path's depth: the ray caster's, else the geometry
         * pass's (left SHADER_READ_ONLY) */
        if (fs->screen)
            rt_pass_use(p, fs->raycast ? RT_RES_RAYDEPTH : RT_RES_DEPTH, false, COMP, SREAD,
                        fs->raycast ? GEN : RO, NONE);
        rt_pass_use(p, RT_RES_COLOR, false, COMP, SREAD, GEN, NONE);
        rt_pass_use(p, RT_RES_OUTPUT, true, COMP, SWRITE, GEN, NONE);
        /* every pixel (the window leaves it SHADER_READ_ONLY after its
         * tone map, which the tracker does not see) */
        p->use[p->nuse - 1].discard = true;
    }
    if (fs->readback)
        rt_plan_readback(pl, fs->upscale);
}

void rt_plan_readback(rt_plan *pl, bool scaled)
{
    rt_pass *p = rt_plan_add(pl, RT_PASS_READBACK);
    rt_pass_use(p, scaled ? RT_RES_OUTPUT : RT_RES_COLOR, false, XFER, XREAD, SRC, NONE);
    rt_pass_use(p, RT_RES_READBACK, true, XFER, XWRITE, NONE, NONE);
}

