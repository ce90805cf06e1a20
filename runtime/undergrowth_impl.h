/* undergrowth_impl.h — what the undergrowth files share (internal to
 * undergrowth.c, undergrowth_glsl.c and undergrowth_probe.c): the cell
 * pool's constants, struct rt_ug, and the runtime's own shaders.  The
 * method is described at the top of undergrowth.c. */
#ifndef SPLAT_UNDERGROWTH_IMPL_H
#define SPLAT_UNDERGROWTH_IMPL_H

#include "rt_internal.h"
#include "vk_build.h"

#define UG_TODO 1024   /* cells generated per frame at most */
#define CELL    SPLAT_UG_CELL        /* metres per cell side (abi.h)        */
#define TEXELS  SPLAT_UG_TEXELS      /* mask texels per cell side           */
/* Distance LOD: beyond LOD_NEAR metres (rt_render_desc.undergrowth_thin
 * may set another distance for the fraction, not the meshes) a cell draws
 * the fraction
 * (LOD_NEAR / d)^2 of its instances (at least LOD_MIN), each widened by
 * 1 / sqrt(fraction) (at most LOD_GROW) but not raised: about as many
 * instances per pixel at every distance and the same cover seen from
 * above, without a wall of tall far clumps at a grazing view (a far tiny
 * triangle costs a whole quad of fragments; the H100 paid 0.25 us per
 * instance drawn). */
#define LOD_NEAR 14.0
#define LOD_MIN  0.08
#define LOD_GROW 3.0
#define LOD_GROW_S "3.0"
#define UG_BLOCK_VEC4 5   /* vec4s per block of the block table (fill_blocks) */
/* The cull passes' table (host-visible, written each frame): key k's
 * entries are [e[k], e[k + 1]) (a key: a block's near or far mesh); its
 * mesh at e[UG_KEYINFO + 4k]: index count, first index, vertex offset,
 * the end of its entries with contact shadows; the entries from
 * e[UG_ENT0]: a cell's block,
 * slot * blocks + block (undergrowth.c "cull"). */
#define UG_MAX_KEYS  (3 * SPLAT_MAX_UG_BLOCKS)
#define UG_KEYINFO   256
#define UG_KEYINFO_S "256u"
#define UG_ENT0      (UG_KEYINFO + 4 * UG_MAX_KEYS)
#define UG_ENT0_S    "1024u"
/* Beyond LOD_TRI times the LOD distance (a cell's nearest point) a block
 * whose far mesh is made of tapered quads draws them as single triangles
 * (undergrowth.c tri_mesh). */
#define LOD_TRI 2.0

enum { CELL_FREE, CELL_PENDING, CELL_READY };

typedef struct ug_cell {
    int   ix, iz;      /* cell index: origin (ix, iz) * CELL metres        */
    int   state;
    bool  wanted;      /* within the radius this frame                     */
    double dist;       /* 2D distance of its centre from the camera        */
    bool  visible;     /* in the frustum this frame                        */
} ug_cell;

/* Push constants of the scatter pass (std430, 64 bytes). */
typedef struct ug_push {
    float    origin[2];
    int32_t  cell[2];
    uint32_t slot, nw, cap, mask_base;
    float    terrain[4];      /* size x, size z, max height, offset       */
    int32_t  hf[2];
    uint32_t nblocks, pad;
} ug_push;

/* Push constants of the cull passes (std430, 112 bytes). */
typedef struct ug_cull_push {
    float    plane[5][4];     /* camera-relative, normalised              */
    float    cam[4];          /* the frame's camera xyz; the radius       */
    uint32_t info[4];         /* blocks, entries                          */
} ug_cull_push;

struct rt_ug {
    rt_device            *d;
    const rt_pack        *p;
    rt_pipelines         *pl;
    const rt_quadtree    *qt;
    int                   pool, nblocks, nw;   /* nw: weight words per texel */
    uint32_t              cap;                 /* instances per cell         */
    uint32_t             *block_base;          /* first instance in a cell   */
    uint32_t             *block_grid;          /* candidates per side        */
    double                radius;
    double                thin;                /* the fraction's distance: LOD_NEAR
                                                  or the renderer's          */
    ug_cell              *cells;
    int                  *order;               /* draw order, front to back  */
    /* device-local: masks, instances, draw arguments (the GPU writes
     * them and reads them every frame); host-visible: args_host (the
     * arguments copied back after a generation, for the counts), blocks,
     * meshes, the mask pass's frame block */
    rt_buffer             masks, inst, args, args_host, blocks, vbuf, ibuf, frame;
    rt_buffer             draw_args;           /* args with the LOD's counts */
    rt_buffer             lod;                 /* per slot: fraction drawn   */
    /* the cull passes: their table (host), the entries' counts and
     * offsets, the drawn instances' indices, the draws per key (and a
     * host copy of them, for the stats) */
    rt_buffer             ent, cnt, vis, mdraw, mdraw_host;
    uint32_t              tri[SPLAT_MAX_UG_BLOCKS][3];   /* per block: its single-
                                               triangle mesh's index count
                                               (0: none), first index, first
                                               vertex (tri_mesh)              */
    int                   nkeys, nent;         /* this frame's               */
    int                   key_block[UG_MAX_KEYS];   /* each key's block       */
    bool                  key_used[UG_MAX_KEYS];    /* it has entries         */
    bool                  mdraw_valid;         /* mdraw_host holds this frame's */
    VkDescriptorSetLayout set_terrain;         /* set 0 of the mask pass     */
    VkDescriptorSetLayout set_mask, set_gen, set_draw, set_lod, set_cull, set_scan;
    VkPipelineLayout      mask_layout, gen_layout, draw_layout, lod_layout, cull_layout,
                          scan_layout;
    VkPipeline           *mask_pipes;          /* per combination            */
    VkPipeline            gen_pipe, lod_pipe;
    VkPipeline            count_pipe, write_pipe, scan_pipe;   /* the cull passes */
    VkPipeline            draw_pipe[2];        /* opaque (early depth), cut out */
    VkPipeline            shadow_pipe;         /* contact shadows (if shadows) */
    rt_image              tex[SPLAT_MAX_UG_TEXTURES + 1];   /* the pack's, then white */
    VkSampler             tex_smp;             /* trilinear, repeat          */
    bool                  shadows;             /* the colour target blends   */
    VkDescriptorPool      dpool;
    VkDescriptorSet       set0, mask_set, gen_set, draw_set, lod_set, cull_set, scan_set;
    VkRenderPass          pass_att, pass_ro;   /* depth in attachment / read */
    VkFramebuffer         fb;
    VkQueryPool           qpool;               /* VK_NULL_HANDLE: no timestamps */
    int                   generated;           /* this frame                 */
    double                time;                /* the camera's (the wind)    */
    float                 cam_xz[2];           /* the camera's, this frame   */
    /* the probe pass (tests only; made on first use) */
    VkDescriptorSetLayout probe_sl;
    VkPipelineLayout      probe_layout;
    VkPipeline            probe_pipe;
    VkDescriptorPool      probe_pool;
    VkDescriptorSet       probe_set;
    rt_buffer             probe_out;
    bool                  drawn;
    rt_vk_list            keep;                /* every Vulkan object but buffers and images */
};

/* ---- undergrowth_cull.c: the cull passes -------------------------------- */

/* The count, write and scan pipelines (u->count_pipe, write_pipe,
 * scan_pipe). */
bool rt_ug_cull_pipelines(rt_ug *u, rt_error *e);
/* This frame's keys and entries, then count, scan and write recorded
 * into cb, and the draws per key copied back for the stats. */
void rt_ug_record_cull(rt_ug *u, VkCommandBuffer cb, const splat_frame *fr);

/* ---- undergrowth_mesh.c: the block table and the far meshes ------------ */

/* Fills the block table b (UG_BLOCK_VEC4 vec4s a block), u->block_grid,
 * u->block_base and u->cap. */
void rt_ug_fill_blocks(rt_ug *u, float *b);
/* The single-triangle version of far mesh m into vout (8 floats a
 * vertex) and iout; the triangles, 0 when m is not made of tapered quads. */
uint32_t rt_ug_tri_mesh(const rt_pack_ug *pu, const rt_pack_ug_mesh *m, float *vout,
                        uint32_t *iout);

/* ---- undergrowth_glsl.c: the runtime's own shaders ---------------------- */

extern const char rt_ug_gen_glsl[];          /* the scatter pass             */
extern const char rt_ug_lod_glsl[];          /* the LOD's draw arguments     */
extern const char rt_ug_cull_glsl[];         /* count / write (UG_WRITE)     */
extern const char rt_ug_scan_glsl[];         /* offsets, draws per key       */
extern const char rt_ug_draw_vert_main[];    /* after SPLAT_GLSL_TERRAIN      */
extern const char rt_ug_draw_frag_main[];    /* after SPLAT_GLSL_PRELUDE      */
extern const char rt_ug_probe_glsl[];        /* the probe pass (tests)       */
extern const char rt_ug_shadow_vert_main[];  /* contact shadows              */
extern const char rt_ug_shadow_frag[];

#endif
