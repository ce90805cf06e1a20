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
 * entries are [e[k], e[k + 1]) (a key: a block's near, far or
 * single-triangle mesh, drawn by the graphics pipeline or, UG_CS_KEY + the
 * level, in compute); its mesh at e[UG_KEYINFO + 4k]: index count, first
 * index, vertex offset, the end of its entries with contact shadows; the
 * entries from e[UG_ENT0]: a cell's block, slot * blocks + block
 * (undergrowth.c "cull"). */
#define UG_LEVELS    3                           /* near, far, single triangles */
#define UG_CS_KEY    UG_LEVELS                   /* a key's level + this: in compute */
#define UG_MAX_KEYS  (2 * UG_LEVELS * SPLAT_MAX_UG_BLOCKS)
#define UG_KEYINFO   388
#define UG_KEYINFO_S "388u"
#define UG_ENT0      (UG_KEYINFO + 4 * UG_MAX_KEYS)
#define UG_ENT0_S    "1924u"
_Static_assert(UG_KEYINFO > UG_MAX_KEYS && UG_ENT0 == 1924, "the cull table's strings");
/* Beyond LOD_TRI times the LOD distance (a cell's nearest point) a block
 * whose far mesh is made of tapered quads draws them as single triangles
 * (undergrowth.c tri_mesh). */
#define LOD_TRI 2.0
/* The compute rasteriser (undergrowth_craster.c): a cell whose every
 * instance projects within UG_CR_CAP pixels a side is drawn in compute
 * when its block is opaque or cut out as a frond and the mesh its distance
 * picks has at most 1 << UG_CR_TBITS triangles; a payload is the cull
 * list's position << UG_CR_PSHIFT | the mesh's level << UG_CR_TBITS | the
 * triangle. */
#define UG_CR_CAP    64      /* the default ($SPLAT_UG_CAP: up to UG_CR_CAP_MAX) */
#define UG_CR_CAP_MAX   128
#define UG_CR_TBITS  4
#define UG_CR_PSHIFT 6
/* The compute keys are made only when their visible cells hold at least
 * UG_CR_MIN candidates (times the LOD's fraction): below it the resolve's
 * pass over every pixel costs more than the graphics draw saves. */
#define UG_CR_MIN    16384.0
_Static_assert(UG_LEVELS <= 1 << (UG_CR_PSHIFT - UG_CR_TBITS), "the payload's level bits");

/* The vertex stage's fade and wind (the top comment), shared by the draw,
 * the compute rasteriser and the probe pass so that the tests count what the draw keeps. */
#define UG_GLSL_FUNCS \
    "float ug_hash01(vec3 root) {\n" \
    "    uint x = floatBitsToUint(root.x) * 0x9e3779b1u ^ floatBitsToUint(root.z) * 0x85ebca77u;\n" \
    "    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;\n" \
    "    return float(x >> 8) * (1.0 / 16777216.0);\n" \
    "}\n" \
    "float ug_fade(float d, float r) {\n" \
    "    float r1 = max(r - " UG_FADE_MARGIN_S ", 0.5 * r);\n" \
    "    return 1.0 - smoothstep(" UG_FADE_START_S " * r1, r1, d);\n" \
    "}\n" \
    "float ug_far(float d, float r) {\n" \
    "    float r1 = max(r - " UG_FADE_MARGIN_S ", 0.5 * r);\n" \
    "    return smoothstep(0.35 * r1, 0.8 * r1, d);\n" \
    "}\n" \
    "float ug_fade_scale(vec3 root, float d, float r) {\n" \
    "    return clamp((ug_fade(d, r) - ug_hash01(root)) * 5.0, 0.0, 1.0);\n" \
    "}\n" \
    "float ug_gust(vec2 xz, vec2 dir, float t) {\n" \
    "    float along = dot(xz, dir), across = dot(xz, vec2(-dir.y, dir.x));\n" \
    "    float p1 = 6.2831853 * fract(along / 24.0 - t / 5.7);\n" \
    "    float p2 = 6.2831853 * fract(along / 9.1 + across / 37.0 - t / 2.3);\n" \
    "    return 0.5 + 0.3 * sin(p1) + 0.2 * sin(p2);\n" \
    "}\n" \
    "vec3 ug_wind(vec3 root, float h, vec4 w, float t) {\n" \
    "    h = max(h, 0.0);\n" \
    "    float a = w.z * h * h * (1.0 - w.w + w.w * ug_gust(root.xz, w.xy, t));\n" \
    "    return vec3(w.x * a, -min(0.5 * a * a / max(h, 1e-3), 0.5 * h), w.y * a);\n" \
    "}\n"
/* One blade vertex placed in the world, as the draw's vertex stage and the
 * compute rasteriser's resolve both need it (after UG_GLSL_FUNCS, with
 * Inst, u_blocks, u_lod, u_push and u_frame declared): the fade, the LOD's
 * widening, the turn, the terrain alignment, the wind and the colour
 * towards the ground's at the radius. */
#define UG_GLSL_PLACE \
    "struct UgP { vec3 local; vec3 color; vec3 nrm; vec3 tnrm; float far; uint flags; };\n" \
    "UgP ug_place(uint ii, Inst it, vec3 a_pos, vec3 a_nrm, vec2 a_uv) {\n" \
    "    uint bi = 5u * it.q.w;\n" \
    "    vec4 b0 = u_blocks.b[bi], b1 = u_blocks.b[bi + 1u], b4 = u_blocks.b[bi + 4u];\n" \
    "    uint flags = uint(u_blocks.b[bi + 2u].z);\n" \
    "    vec3 n = normalize(unpackSnorm4x8(it.q.x).xyz + vec3(0.0, 1e-4, 0.0));\n" \
    "    float a = uintBitsToFloat(it.q.z), c = cos(a), s = sin(a);\n" \
    /* the distance fade (push patch_xz.x: the radius) */ \
    "    float r = u_push.patch_xz.x, d = length(it.p.xz - u_frame.camera.xz);\n" \
    /* the LOD's growth (u_push.info.x: instances per cell) */ \
    "    float grow = min(inversesqrt(u_lod.f[ii / u_push.info.x]), " LOD_GROW_S ");\n" \
    /* the growth widens, it does not raise: far cover, not a hedge */ \
    "    vec3 p = a_pos * it.p.w * ug_fade_scale(it.p.xyz, d, r) * vec3(grow, 1.0, grow);\n" \
    "    p = vec3(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);\n" \
    "    vec3 m = vec3(c * a_nrm.x + s * a_nrm.z, a_nrm.y, -s * a_nrm.x + c * a_nrm.z);\n" \
    "    if ((flags & 4u) != 0u) {   /* aligned to the terrain normal: a rotation (t, n, b) */\n" \
    "        vec3 t = normalize(cross(n, vec3(0.0, 0.0, 1.0)));\n" \
    "        vec3 bt = cross(t, n);\n" \
    "        p = t * p.x + n * p.y + bt * p.z;\n" \
    "        m = t * m.x + n * m.y + bt * m.z;\n" \
    "    }\n" \
    /* the wind (block vec4 3; push patch_xz.y: the time in seconds) */ \
    "    p += ug_wind(it.p.xyz, p.y, u_blocks.b[bi + 3u], u_push.patch_xz.y);\n" \
    "    UgP o;\n" \
    "    o.local = it.p.xyz + p;\n" \
    /* towards the radius the colour becomes the ground's (the cover thins \
     * into the terrain it stands on, the root darkening goes with it) */ \
    "    o.far = ug_far(d, r);\n" \
    "    float share = mix(mix(b4.x, b0.w, clamp(a_uv.y, 0.0, 1.0)), 1.0, o.far);\n" \
    "    o.color = mix(b1.rgb, unpackUnorm4x8(it.q.y).rgb, share);\n" \
    "    o.nrm = (flags & 2u) != 0u ? n : m;\n" \
    "    o.tnrm = n;\n" \
    "    o.flags = flags;\n" \
    "    return o;\n" \
    "}\n"
/* A blade's contact shadow, a square on the ground under it, as the
 * graphics shadow draw and the compute rasteriser's shadow pass both need
 * it (after UG_GLSL_FUNCS, with Inst, u_blocks, u_lod, u_push and u_frame
 * declared): the terrain normal n, the square's axes t and bt, its half
 * size (faded and widened with the blade) and its darkness a. */
#define UG_GLSL_SHADOW \
    "struct UgS { vec3 n; vec3 t; vec3 bt; float size; float a; };\n" \
    "UgS ug_shadow_square(uint ii, Inst it) {\n" \
    "    vec4 b4 = u_blocks.b[5u * it.q.w + 4u];\n" \
    "    UgS s;\n" \
    "    s.n = normalize(unpackSnorm4x8(it.q.x).xyz + vec3(0.0, 1e-4, 0.0));\n" \
    "    float r = u_push.patch_xz.x, d = length(it.p.xz - u_frame.camera.xz);\n" \
    "    float grow = min(inversesqrt(u_lod.f[ii / u_push.info.x]), " LOD_GROW_S ");\n" \
    "    s.size = 1.3 * b4.z * it.p.w * grow * ug_fade_scale(it.p.xyz, d, r);\n" \
    "    s.a = b4.y * (1.0 - ug_far(d, r));\n" \
    "    s.t = normalize(cross(s.n, vec3(0.0, 0.0, 1.0)));\n" \
    "    s.bt = cross(s.t, s.n);\n" \
    "    return s;\n" \
    "}\n"
#define UG_FADE_MARGIN_S "12.0"   /* 0.75 CELL */
#define UG_FADE_START_S "0.6"

enum { CELL_FREE, CELL_PENDING, CELL_READY };

typedef struct ug_cell {
    int   ix, iz;      /* cell index: origin (ix, iz) * CELL metres        */
    int   state;
    bool  wanted;      /* within the radius this frame                     */
    double dist;       /* 2D distance of its centre from the camera        */
    bool  visible;     /* in the frustum this frame                        */
} ug_cell;

/* Push constants of the scatter pass (std430, 48 bytes); the cells it
 * generates are in gtab (undergrowth.c rt_ug_generate). */
typedef struct ug_push {
    uint32_t nw, cap, nblocks, pad;
    float    terrain[4];      /* size x, size z, max height, offset       */
    int32_t  hf[2], pad2[2];
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
    uint8_t              *cell_level;          /* this frame's, per slot and
                                                  block: the key's level
                                                  (undergrowth_cull.c)       */
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
    /* the scatter pass's table (host): per block its mesh's index count,
     * first index and first vertex, then per cell generated this frame
     * its index x, z and slot (uvec4s) */
    rt_buffer             gtab;
    uint32_t              tri[SPLAT_MAX_UG_BLOCKS][3];   /* per block: its single-
                                               triangle mesh's index count
                                               (0: none), first index, first
                                               vertex (tri_mesh)              */
    int                   nkeys, nent;         /* this frame's               */
    int                   key_block[UG_MAX_KEYS];   /* each key's block       */
    bool                  key_used[UG_MAX_KEYS];    /* it has entries         */
    bool                  mdraw_valid;         /* mdraw_host holds this frame's */
    /* the compute rasteriser (undergrowth_craster.c; NULL pipes: off) */
    bool                  compute;             /* asked for and possible     */
    bool                  cr64;                /* one pass, 64-bit atomics   */
    bool                  cr_frame;            /* this frame has compute keys */
    int                   cr_cap;              /* pixels a side a cell's
                                                  instances fit (fits)       */
    bool                  key_cs[UG_MAX_KEYS]; /* the key is drawn in compute */
    bool                  key_sh[UG_MAX_KEYS]; /* its contact shadows are drawn */
    bool                  key_shc[UG_MAX_KEYS];/* ... in compute                */
    uint8_t               key_level[UG_MAX_KEYS];   /* its mesh: near, far, triangles */
    float                 cr_proj[3];          /* pixels per unit at depth 1,
                                                  cos of the half diagonal   */
    int                   width, height_px;    /* the colour target's        */
    const rt_image       *color, *depth;
    VkSampler             cr_nearest;
    VkDescriptorSetLayout set_cr;
    VkPipelineLayout      cr_layout;
    VkPipeline            cr_pipe[2];          /* depth and id, resolve      */
    VkDescriptorSet       cr_set;
    rt_buffer             zbuf, idbuf, shbuf, cdisp, crtab, crstat, crstat_host;
    bool                  cr_ran;              /* this frame's ran           */
    bool                  cr_clear;            /* the per-pixel buffers were
                                                  filled once (the resolve
                                                  clears what it reads)      */
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

/* Block b's mesh at level lv (0 near, 1 far, 2 single triangles; one it
 * has): index count, first index, vertex offset. */
void rt_ug_level_mesh(const rt_ug *u, int b, int lv, uint32_t out[3]);

/* ---- undergrowth_craster.c: the far blades in compute ------------------- */

/* The compute rasteriser's pipelines, set and buffers (after make_buffers
 * and make_textures; u->compute false leaves them unmade). */
bool rt_ug_craster_create(rt_ug *u, rt_error *e);
void rt_ug_craster_destroy(rt_ug *u);
/* This frame's distance per block beyond which its single-triangle cells
 * go to compute: fills u->cr_proj from the frame's projection. */
void rt_ug_craster_frame(rt_ug *u, const splat_frame *fr);
/* Whether a single-triangle cell of block b whose nearest point is `near`
 * metres away (and its LOD fraction f) projects every blade within the cap. */
bool rt_ug_craster_fits(const rt_ug *u, int b, double near, float f);
/* After the graphics draw's render pass: the compute keys' blades
 * rasterised against the depth (SHADER_READ_ONLY), resolved into the
 * colour (left TRANSFER_SRC). */
void rt_ug_craster_record(rt_ug *u, VkCommandBuffer cb, VkDescriptorSet set0c,
                          VkDescriptorSet set1);

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
