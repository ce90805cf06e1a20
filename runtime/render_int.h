/* render_int.h — the renderer's state, shared by its files:
 *   render_life.c    creation, destruction, the pack swap (hot reload)
 *   render_views.c   cameras, the frame block, the debug views' table
 *   render_plan.c    the frame plan: passes, their reads and writes, barriers
 *   render_record.c  selection and the recording of a plan's passes
 *   render.c         the state the caller changes: light, params, craters,
 *                    shadows
 * Not installed; runtime/ only. */
#ifndef SPLAT_RENDER_INT_H
#define SPLAT_RENDER_INT_H
#include "rt_internal.h"
#include "render_plan.h"

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
    bool              shading_lod;     /* the CPU shading LOD is on         */
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
    rt_image          color, depth, mp[3];  /* at the internal size: the
                                          output's / preview_scale     */
    int               scale;           /* the preview scale; 1: none        */
    int               out_w, out_h;    /* the output picture's size         */
    rt_image          out;             /* scale > 1: the output picture     */
    rt_upscale       *upscale;         /* scale > 1: color into out         */
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
    rt_tracker        tracker;         /* the resources' state between passes */
    rt_plan           plan;            /* the last frame's (render_plan.c)  */
    bool              pass_times;      /* a timestamp after every pass      */
    double            first_picture_s; /* rt_frame_stats.first_picture_s; 0:
                                          no frame completed yet            */
};

/* What this frame does, worked out once from the state (render_plan.c). */
typedef struct rt_frame_setup {
    bool     screen;       /* the screen-space path                         */
    bool     multipass;    /* the multi-pass reference                      */
    bool     far;          /* forward: far patches from the far atlas       */
    bool     split;        /* forward: uncovered nodes split                */
    bool     composites;   /* forward: each combination's composite (not the
                              über-shader: --reference uber, the MASK view) */
    bool     count;        /* forward: the counting variant                 */
    bool     cull;         /* back faces culled (after the selection)       */
    bool     raycast;      /* screen: the depth by ray casting              */
    bool     sky;          /* the analytic sky drawn                        */
    bool     ug, ug_draw;  /* undergrowth generated; drawn (cells in view)  */
    bool     shadow;       /* the shadow map is due                         */
    bool     readback;     /* the target copied for the host in the frame   */
    bool     upscale;      /* the preview scale: colour into the output     */
    unsigned variant;      /* forward: RT_VARIANT_*                         */
    unsigned cvariant;     /* screen: RT_CVARIANT_*                         */
} rt_frame_setup;

/* render.c */
void rt_render_pack_light(rt_renderer *r, const rt_pack *p);
bool rt_render_shadow_due(const rt_renderer *r);
bool rt_render_update_shadow(rt_renderer *r, double *ms, rt_error *e);
/* render_plan.c: the path and switches before the selection, then the
 * passes after it */
void rt_render_setup(const rt_renderer *r, rt_frame_setup *fs);
unsigned rt_render_compute_variant(const rt_renderer *r);
void rt_render_plan(const rt_renderer *r, const rt_frame_setup *fs, rt_plan *pl);
/* render_life.c */
bool rt_render_use_raycast(const rt_renderer *r);
/* render_views.c */
bool rt_render_sky_drawn(const rt_renderer *r);
void rt_render_fill_frame(rt_renderer *r, const rt_camera *c, splat_frame *fr);
/* the direction through (nx, ny) in -1..1, y down */
void rt_camera_ray(const rt_camera *c, double aspect, double nx, double ny, double dir[3]);

#endif
