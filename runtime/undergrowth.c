/* undergrowth.c — procedural undergrowth from the terrain's own material
 * masks (Andersson 2007 §5.5, seed 000): grass, plants and stones grow
 * wherever an undergrowth-bearing material's composited weight says,
 * follow repainting and craters, and need no index maps of their own.
 *
 * A fixed pool of 16 x 16 m cells is allocated by 2D distance from the
 * camera (every cell whose centre lies within the radius), never by the
 * frustum; cells in the frustum are generated first.  Generating a cell
 * happens on the GPU, in the frame's command buffer, with no read back:
 *   1. the mask pass: each leaf cell the cell overlaps runs its
 *      combination's undergrowth mask shader (abi.h "undergrowth masks")
 *      over the cell's 64 x 64 texels inside that leaf, writing every
 *      undergrowth material's composited weight, the terrain normal and
 *      the composite's albedo;
 *   2. the scatter pass, one workgroup per block (a material's
 *      `undergrowth`): a jittered grid at the block's density, Russian
 *      roulette on the material's weight, scale and rotation from a hash
 *      of the cell's integer position (the same instances on every run
 *      and from every camera), the root on the heightfield (bilinear as
 *      the terrain), the terrain's albedo at the root.
 *      Instances are compacted by a workgroup prefix sum in candidate
 *      order, so the buffer is deterministic (no atomics), and the count
 *      goes straight into the block's indirect draw arguments.
 * Drawing is one indexed indirect draw per block and cell, cells front to
 * back, after the terrain into its colour and depth; lit by splat_light
 * (abi.c) with the terrain normal (a block's `lighting = terrain`) or the
 * mesh's.  In the vertex stage (ug_glsl, which the probe pass runs too):
 *   - the distance fade: an instance at distance d from the camera stays
 *     with probability fade(d) = 1 - smoothstep(r0, r1, d), r1 = radius -
 *     0.75 cell (every cell holding a point nearer than r1 is allocated),
 *     r0 = 0.6 r1; it stays while its own hash h (of its root: stable as
 *     the camera moves) is below fade(d), and shrinks to nothing as
 *     fade(d) comes down to h (scale clamp((fade - h) * 5, 0, 1)): the
 *     density thins to zero before the radius, and no instance pops;
 *   - the wind: a vertex h metres above the root moves along the block's
 *     direction by a = sway * h^2 * (1 - gust + gust * g), g in [0, 1]
 *     gusts: two waves (24 m at 4.2 m/s along the wind, 9.1 m at 4 m/s
 *     slanted across it, fract() of their phases so that far from the
 *     origin float sin stays exact), and down by min(a^2 / 2h, h / 2)
 *     (about keeping the blade's length);
 *   - the colour: the block's, blended with the terrain's albedo at the
 *     root by mix(root_blend, blend, v) (v: the mesh's uv.y, 0 at the
 *     root, 1 at the tip), and wholly the terrain's (no root darkening
 *     either, and a mesh-lit instance's normal the terrain's) as ug_far
 *     goes from 0 at 0.35 r1 to 1 at 0.8 r1: the cover turns into the
 *     ground it stands on before it thins out.
 */
#include "rt_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CELL    SPLAT_UG_CELL        /* metres per cell side (abi.h)        */
#define TEXELS  SPLAT_UG_TEXELS      /* mask texels per cell side           */
/* Distance LOD: beyond LOD_NEAR metres a cell draws the fraction
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
    ug_cell              *cells;
    int                  *order;               /* draw order, front to back  */
    /* device-local: masks, instances, draw arguments (the GPU writes
     * them and reads them every frame); host-visible: args_host (the
     * arguments copied back after a generation, for the counts), blocks,
     * meshes, the mask pass's frame block */
    rt_buffer             masks, inst, args, args_host, blocks, vbuf, ibuf, frame;
    rt_buffer             draw_args;           /* args with the LOD's counts */
    rt_buffer             lod;                 /* per slot: fraction drawn   */
    rt_buffer             far;                 /* per block: far mesh (LOD)  */
    VkDescriptorSetLayout set_terrain;         /* set 0 of the mask pass     */
    VkDescriptorSetLayout set_mask, set_gen, set_draw, set_lod;
    VkPipelineLayout      mask_layout, gen_layout, draw_layout, lod_layout;
    VkPipeline           *mask_pipes;          /* per combination            */
    VkPipeline            gen_pipe, lod_pipe;
    VkPipeline            draw_pipe[2];        /* opaque (early depth), cut out */
    VkPipeline            shadow_pipe;         /* contact shadows (if shadows) */
    rt_image              tex[SPLAT_MAX_UG_TEXTURES + 1];   /* the pack's, then white */
    VkSampler             tex_smp;             /* trilinear, repeat          */
    bool                  shadows;             /* the colour target blends   */
    VkDescriptorPool      dpool;
    VkDescriptorSet       set0, mask_set, gen_set, draw_set, lod_set;
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
};

/* ---- shaders ---------------------------------------------------------------- */

static const char gen_glsl[] =
    "#version 450\n"
    "layout(local_size_x = 64) in;\n"
    "layout(set = 0, binding = 0, std430) readonly buffer M { uint w[]; } u_mask;\n"
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 0, binding = 1, std430) writeonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 0, binding = 2, std430) buffer A { uint a[]; } u_args;\n"
    "layout(set = 0, binding = 3, std430) readonly buffer B { vec4 b[]; } u_blocks;\n"
    "layout(set = 0, binding = 4) uniform sampler2D u_height;\n"
    "layout(push_constant, std430) uniform P {\n"
    "    vec2 origin; ivec2 cell; uint slot, nw, cap, mask_base;\n"
    "    vec4 terrain; ivec2 hf; uint nblocks;\n"
    "} u_p;\n"
    "shared uint s_scan[64];\n"
    "uint hash(uint x) {\n"
    "    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;\n"
    "    return x;\n"
    "}\n"
    "float rnd(inout uint s) { s = hash(s + 0x9e3779b9u); return float(s >> 8) * (1.0 / 16777216.0); }\n"
    /* bilinear between texel centres, as the terrain's vertices sample */
    "float height_at(vec2 xz) {\n"
    "    vec2 t = xz / u_p.terrain.xy * vec2(u_p.hf) - 0.5;\n"
    "    ivec2 i = ivec2(floor(t)), m = u_p.hf - 1;\n"
    "    vec2 f = t - vec2(i);\n"
    "    float h00 = texelFetch(u_height, clamp(i, ivec2(0), m), 0).r;\n"
    "    float h10 = texelFetch(u_height, clamp(i + ivec2(1, 0), ivec2(0), m), 0).r;\n"
    "    float h01 = texelFetch(u_height, clamp(i + ivec2(0, 1), ivec2(0), m), 0).r;\n"
    "    float h11 = texelFetch(u_height, clamp(i + ivec2(1, 1), ivec2(0), m), 0).r;\n"
    "    float h = mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);\n"
    "    return h * u_p.terrain.z + u_p.terrain.w;\n"
    "}\n"
    "void main() {\n"
    "    uint b = gl_WorkGroupID.x, lid = gl_LocalInvocationID.x;\n"
    "    vec4 b0 = u_blocks.b[5u * b], b1 = u_blocks.b[5u * b + 1u], b2 = u_blocks.b[5u * b + 2u];\n"
    "    uint n = uint(b2.x), total = n * n, base = u_p.slot * u_p.cap + uint(b2.y);\n"
    "    uint ms = uint(b1.w);\n"
    "    float keep = b0.x * " "256.0" " / float(total);\n"
    "    float step = 16.0 / float(n);\n"
    "    uint seed0 = hash(uint(u_p.cell.x) * 73856093u ^ uint(u_p.cell.y) * 19349663u ^ b * 83492791u);\n"
    "    uint run = 0u;\n"
    "    for (uint c = 0u; c < total; c += 64u) {\n"
    "        uint k = c + lid;\n"
    "        bool ok = false;\n"
    "        Inst it;\n"
    "        if (k < total) {\n"
    /* candidates in a lattice order (stride coprime with the count), so
     * that every prefix of the kept instances spreads over the cell: the
     * draw's distance LOD keeps a prefix */
    "            uint q = (k * uint(b2.w)) % total;\n"
    "            uint s = hash(seed0 ^ hash(q));\n"
    "            vec2 g = vec2(float(q % n), float(q / n));\n"
    "            vec2 l = (g + vec2(rnd(s), rnd(s))) * step;\n"
    "            ivec2 tx = min(ivec2(l * (64.0 / 16.0)), ivec2(63));\n"
    "            uint at = u_p.mask_base + uint(tx.y * 64 + tx.x) * (u_p.nw + 2u);\n"
    "            float w = unpackUnorm4x8(u_mask.w[at + ms / 4u])[ms % 4u];\n"
    "            ok = rnd(s) < w * keep;\n"
    "            vec3 nrm = unpackSnorm4x8(u_mask.w[at + u_p.nw]).xyz;\n"
    "            vec3 alb = unpackUnorm4x8(u_mask.w[at + u_p.nw + 1u]).rgb;\n"
    "            vec2 xz = u_p.origin + l;\n"
    "            float sc = mix(b0.y, b0.z, rnd(s));\n"
    "            float ang = rnd(s) * 6.2831853;\n"
    "            it.p = vec4(xz.x, height_at(xz), xz.y, sc);\n"
    "            it.q = uvec4(packSnorm4x8(vec4(nrm, 0.0)), packUnorm4x8(vec4(alb, 1.0)),\n"
    "                         floatBitsToUint(ang), b);\n"
    "        }\n"
    "        s_scan[lid] = ok ? 1u : 0u;\n"
    "        barrier();\n"
    "        for (uint o = 1u; o < 64u; o <<= 1u) {\n"
    "            uint v = lid >= o ? s_scan[lid - o] : 0u;\n"
    "            barrier();\n"
    "            s_scan[lid] += v;\n"
    "            barrier();\n"
    "        }\n"
    "        if (ok) u_inst.v[base + run + s_scan[lid] - 1u] = it;\n"
    "        run += s_scan[63];\n"
    "        barrier();\n"
    "    }\n"
    "    if (lid == 0u) u_args.a[(u_p.slot * u_p.nblocks + b) * 5u + 1u] = run;\n"
    "}\n";

/* The LOD pass, every frame: the draw arguments from the generated ones,
 * each cell's instance count times its fraction (a prefix: the scatter
 * pass keeps instances in a lattice order that spreads every prefix), and
 * beyond LOD_NEAR the block's far mesh where it has one (PACK.md: index
 * count, first index, vertex offset, and w = 1); after the n arguments,
 * the contact shadows' n: the same instances drawn with the shadow quad
 * (push qidx, qvtx), none for a block whose shadow is 0 (its second
 * uvec4 .x). */
static const char lod_glsl[] =
    "#version 450\n"
    "layout(local_size_x = 64) in;\n"
    "layout(set = 0, binding = 0, std430) readonly buffer A { uint a[]; } u_args;\n"
    "layout(set = 0, binding = 1, std430) writeonly buffer D { uint a[]; } u_draw;\n"
    "layout(set = 0, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"
    "layout(set = 0, binding = 3, std430) readonly buffer M { uvec4 m[]; } u_far;\n"
    "layout(push_constant, std430) uniform P { uint n, nblocks, qidx, qvtx; } u_p;\n"
    "void main() {\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    if (i >= u_p.n) return;\n"
    "    for (uint k = 0u; k < 5u; k++) u_draw.a[5u * i + k] = u_args.a[5u * i + k];\n"
    "    float f = u_lod.f[i / u_p.nblocks];\n"
    "    uint count = uint(ceil(float(u_args.a[5u * i + 1u]) * f));\n"
    "    u_draw.a[5u * i + 1u] = count;\n"
    "    uint s = 5u * (u_p.n + i);\n"
    "    u_draw.a[s] = 6u;\n"
    "    u_draw.a[s + 1u] = u_far.m[2u * (i % u_p.nblocks) + 1u].x != 0u ? count : 0u;\n"
    "    u_draw.a[s + 2u] = u_p.qidx;\n"
    "    u_draw.a[s + 3u] = u_p.qvtx;\n"
    "    u_draw.a[s + 4u] = u_args.a[5u * i + 4u];\n"
    "    uvec4 m = u_far.m[2u * (i % u_p.nblocks)];   /* the block's far mesh */\n"
    "    if (f < 1.0 && m.w != 0u) {\n"
    "        u_draw.a[5u * i] = m.x;\n"
    "        u_draw.a[5u * i + 2u] = m.y;\n"
    "        u_draw.a[5u * i + 3u] = m.z;\n"
    "    }\n"
    "}\n";

/* The vertex stage's fade and wind (the top comment), shared by the draw
 * and the probe pass so that the tests count what the draw keeps. */
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
#define UG_FADE_MARGIN_S "12.0"   /* 0.75 CELL */
#define UG_FADE_START_S "0.6"

/* The draw pass: SPLAT_GLSL_TERRAIN (frame block) + this vertex main; the
 * prelude + draw_frag_main as the fragment shader (it reads v_rel, v_uv,
 * v_local at locations 0-2, as the terrain's). */
static const char draw_vert_main[] =
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 2, binding = 0, std430) readonly buffer B { vec4 b[]; } u_blocks;\n"
    "layout(set = 2, binding = 1, std430) readonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 2, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "layout(location = 1) in vec3 a_nrm;\n"
    "layout(location = 2) in vec2 a_uv;\n"
    "out gl_PerVertex { vec4 gl_Position; };\n"
    "layout(location = 0) out vec3 v_rel;\n"
    "layout(location = 1) out vec2 v_uv;\n"
    "layout(location = 2) out vec3 v_local;\n"
    "layout(location = 3) out vec3 g_color;\n"
    "layout(location = 4) out vec3 g_normal;\n"
    "layout(location = 5) out vec2 g_uv;\n"
    "layout(location = 6) flat out uint g_flags;\n"
    "layout(location = 7) out float g_far;\n"
    "layout(location = 8) out vec3 g_tnormal;\n"
    UG_GLSL_FUNCS
    "void main() {\n"
    "    Inst it = u_inst.v[gl_InstanceIndex];\n"
    "    uint bi = 5u * it.q.w;\n"
    "    vec4 b0 = u_blocks.b[bi], b1 = u_blocks.b[bi + 1u], b4 = u_blocks.b[bi + 4u];\n"
    "    uint flags = uint(u_blocks.b[bi + 2u].z);\n"
    "    vec3 n = normalize(unpackSnorm4x8(it.q.x).xyz + vec3(0.0, 1e-4, 0.0));\n"
    "    float a = uintBitsToFloat(it.q.z), c = cos(a), s = sin(a);\n"
    /* the distance fade (push patch_xz.x: the radius) */
    "    float r = u_push.patch_xz.x, d = length(it.p.xz - u_frame.camera.xz);\n"
    /* the LOD's growth (u_push.info.x: instances per cell) */
    "    float grow = min(inversesqrt(u_lod.f[uint(gl_InstanceIndex) / u_push.info.x]), " LOD_GROW_S ");\n"
    /* the growth widens, it does not raise: far cover, not a hedge */
    "    vec3 p = a_pos * it.p.w * ug_fade_scale(it.p.xyz, d, r) * vec3(grow, 1.0, grow);\n"
    "    p = vec3(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);\n"
    "    vec3 m = vec3(c * a_nrm.x + s * a_nrm.z, a_nrm.y, -s * a_nrm.x + c * a_nrm.z);\n"
    "    if ((flags & 4u) != 0u) {   /* aligned to the terrain normal: a rotation (t, n, b) */\n"
    "        vec3 t = normalize(cross(n, vec3(0.0, 0.0, 1.0)));\n"
    "        vec3 bt = cross(t, n);\n"
    "        p = t * p.x + n * p.y + bt * p.z;\n"
    "        m = t * m.x + n * m.y + bt * m.z;\n"
    "    }\n"
    /* the wind (block vec4 3; push patch_xz.y: the time in seconds) */
    "    p += ug_wind(it.p.xyz, p.y, u_blocks.b[bi + 3u], u_push.patch_xz.y);\n"
    "    v_local = it.p.xyz + p;\n"
    "    v_rel = v_local - u_frame.camera.xyz;\n"
    "    v_uv = v_local.xz / u_frame.terrain.xy;\n"
    /* towards the radius the colour becomes the ground's (the cover thins
     * into the terrain it stands on, the root darkening goes with it) */
    "    float far = ug_far(d, r);\n"
    "    float share = mix(mix(b4.x, b0.w, clamp(a_uv.y, 0.0, 1.0)), 1.0, far);\n"
    "    g_far = far;\n"
    "    g_color = mix(b1.rgb, unpackUnorm4x8(it.q.y).rgb, share);\n"
    "    g_normal = (flags & 2u) != 0u ? n : m;\n"
    "    g_tnormal = n;\n"
    "    g_uv = a_uv;\n"
    "    g_flags = flags;\n"
    "    gl_Position = u_frame.view_proj * vec4(v_rel, 1.0);\n"
    "}\n";

static const char draw_frag_main[] =
    "layout(set = 2, binding = 3) uniform sampler2D u_ugtex[" SPLAT_STR(SPLAT_MAX_UG_TEXTURES) "];\n"
    "layout(location = 3) in vec3 g_color;\n"
    "layout(location = 4) in vec3 g_normal;\n"
    "layout(location = 5) in vec2 g_uv;\n"
    "layout(location = 6) flat in uint g_flags;\n"
    "layout(location = 7) in float g_far;\n"
    "layout(location = 8) in vec3 g_tnormal;\n"
    /* constant indices: no dynamic indexing feature needed (the index is
     * the block's, the same for a whole draw) */
    "vec4 ug_texture(uint t, vec2 uv) {\n"
    "    switch (t) {\n"
    "    case 1u: return texture(u_ugtex[0], uv);\n"
    "    case 2u: return texture(u_ugtex[1], uv);\n"
    "    case 3u: return texture(u_ugtex[2], uv);\n"
    "    case 4u: return texture(u_ugtex[3], uv);\n"
    "    case 5u: return texture(u_ugtex[4], uv);\n"
    "    case 6u: return texture(u_ugtex[5], uv);\n"
    "    case 7u: return texture(u_ugtex[6], uv);\n"
    "    case 8u: return texture(u_ugtex[7], uv);\n"
    "    }\n"
    "    return vec4(1.0);\n"
    "}\n"
    "void main() {\n"
    /* the texture with v up the mesh (OBJ: v = 0 at the image's bottom) */
    "    vec4 tex = ug_texture(g_flags >> 8, vec2(g_uv.x, 1.0 - g_uv.y));\n"
    "#ifdef UG_CUTOUT\n"
    "    if ((g_flags & 1u) != 0u) {\n"
    "        /* a frond cut from the quad: a lens-shaped outline, chevron leaflets */\n"
    "        float x = abs(g_uv.x * 2.0 - 1.0), t = clamp(g_uv.y, 0.0, 1.0);\n"
    "        if (x > 0.9 * sin(t * 3.14159) || (x > 0.08 && fract(t * 7.0 - x * 2.5) > 0.6)) discard;\n"
    "    } else {\n"
    "        /* the texture's alpha, dithered (interleaved gradient noise): a\n"
    "         * pixel is covered with that probability, as alpha to coverage\n"
    "         * would with samples */\n"
    "        float ign = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));\n"
    "        if (tex.a <= ign) discard;\n"
    "    }\n"
    "#endif\n"
    "    float dist = length(v_rel);\n"
    "    vec3 v = dist > 0.0 ? -v_rel / dist : vec3(0.0, 1.0, 0.0);\n"
    "    vec3 n = normalize(g_normal);\n"
    "    if ((g_flags & 2u) == 0u && !gl_FrontFacing) n = -n;\n"
    /* a mesh-lit instance shades as the ground as it turns into it */
    "    n = normalize(mix(n, normalize(g_tnormal), g_far));\n"
    "    float ao = mix(mix(0.5, 1.0, clamp(g_uv.y, 0.0, 1.0)), 1.0, g_far);   /* darker at the root */\n"
    "    o_color = vec4(splat_light(g_color * tex.rgb * ao, n, 0.9, dist, v), 1.0);\n"
    "}\n";

/* The probe pass, for the tests only (made on first use): mode 0 counts
 * the instances the last frame's draw keeps in cell `slot`, per ring of
 * width ring.w around the camera ring.xy (the draw's arguments after the
 * LOD, and ug_fade_scale > 0: exactly the instances the vertex stage does
 * not collapse) into out[ring], and all the LOD's into out[rings + ring];
 * mode 1 evaluates ug_wind at n points (12 floats each:
 * root, h, the block's wind vec4, then the offset and the gust written). */
static const char probe_glsl[] =
    "#version 450\n"
    "layout(local_size_x = 64) in;\n"
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 0, binding = 0, std430) readonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 0, binding = 1, std430) readonly buffer A { uint a[]; } u_draw;\n"
    "layout(set = 0, binding = 2, std430) buffer O { uint u[]; } u_out;\n"
    "layout(push_constant, std430) uniform P { vec4 ring; uvec4 info; } u_p;\n"
    UG_GLSL_FUNCS
    "void main() {\n"
    "    uint lid = gl_LocalInvocationID.x;\n"
    "    if (u_p.info.x == 1u) {\n"
    "        uint i = gl_GlobalInvocationID.x;\n"
    "        if (i >= u_p.info.y) return;\n"
    "        float v[8];\n"
    "        for (uint k = 0u; k < 8u; k++) v[k] = uintBitsToFloat(u_out.u[12u * i + k]);\n"
    "        vec3 o = ug_wind(vec3(v[0], v[1], v[2]), v[3], vec4(v[4], v[5], v[6], v[7]), u_p.ring.z);\n"
    "        u_out.u[12u * i + 8u] = floatBitsToUint(o.x);\n"
    "        u_out.u[12u * i + 9u] = floatBitsToUint(o.y);\n"
    "        u_out.u[12u * i + 10u] = floatBitsToUint(o.z);\n"
    "        u_out.u[12u * i + 11u] = floatBitsToUint(ug_gust(vec2(v[0], v[2]), vec2(v[4], v[5]), u_p.ring.z));\n"
    "        return;\n"
    "    }\n"
    "    uint at = 5u * (u_p.info.z * u_p.info.w + gl_WorkGroupID.x);\n"
    "    uint n = u_draw.a[at + 1u], first = u_draw.a[at + 4u];\n"
    "    for (uint k = lid; k < n; k += 64u) {\n"
    "        vec3 root = u_inst.v[first + k].p.xyz;\n"
    "        float d = length(root.xz - u_p.ring.xy);\n"
    "        uint ring = uint(d / u_p.ring.w);\n"
    "        if (ring >= u_p.info.y) continue;\n"
    "        atomicAdd(u_out.u[u_p.info.y + ring], 1u);\n"
    "        if (ug_fade_scale(root, d, u_p.ring.z) > 0.0) atomicAdd(u_out.u[ring], 1u);\n"
    "    }\n"
    "}\n";

/* Contact shadows (a block's `shadow`): before the plants, every kept
 * instance darkens the ground under it by a disc on the terrain plane at
 * its root, 1.3 times its footprint, 4 cm up the normal, multiplied into
 * the colour (dst * src): shadow * (1 - smoothstep(0.2, 1, r^2)), gone
 * with the instance (the fade's scale) and with ug_far, so overlapping
 * discs under dense cover darken the ground the more. */
static const char shadow_vert_main[] =
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 2, binding = 0, std430) readonly buffer B { vec4 b[]; } u_blocks;\n"
    "layout(set = 2, binding = 1, std430) readonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 2, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "layout(location = 1) in vec3 a_nrm;   /* the vertex layout's; unused */\n"
    "layout(location = 2) in vec2 a_uv;\n"
    "out gl_PerVertex { vec4 gl_Position; };\n"
    "layout(location = 0) out vec2 s_q;\n"
    "layout(location = 1) out float s_a;\n"
    UG_GLSL_FUNCS
    "void main() {\n"
    "    Inst it = u_inst.v[gl_InstanceIndex];\n"
    "    vec4 b4 = u_blocks.b[5u * it.q.w + 4u];\n"
    "    vec3 n = normalize(unpackSnorm4x8(it.q.x).xyz + vec3(0.0, 1e-4, 0.0));\n"
    "    float r = u_push.patch_xz.x, d = length(it.p.xz - u_frame.camera.xz);\n"
    "    float grow = min(inversesqrt(u_lod.f[uint(gl_InstanceIndex) / u_push.info.x]), " LOD_GROW_S ");\n"
    "    float size = 1.3 * b4.z * it.p.w * grow * ug_fade_scale(it.p.xyz, d, r);\n"
    "    vec3 t = normalize(cross(n, vec3(0.0, 0.0, 1.0))), bt = cross(t, n);\n"
    "    vec3 p = it.p.xyz + (t * a_pos.x + bt * a_pos.z) * size + n * 0.04;\n"
    "    s_q = a_uv * 2.0 - 1.0;\n"
    "    s_a = b4.y * (1.0 - ug_far(d, r));\n"
    "    gl_Position = u_frame.view_proj * vec4(p - u_frame.camera.xyz, 1.0);\n"
    "}\n";

static const char shadow_frag[] =
    "#version 450\n"
    "layout(early_fragment_tests) in;\n"
    "layout(location = 0) in vec2 s_q;\n"
    "layout(location = 1) in float s_a;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() {\n"
    "    float a = s_a * (1.0 - smoothstep(0.2, 1.0, dot(s_q, s_q)));\n"
    "    o_color = vec4(vec3(1.0 - a), 1.0);\n"
    "}\n";

/* ---- creation ----------------------------------------------------------------- */

static bool pipe_layout(rt_device *d, const VkDescriptorSetLayout *sets, uint32_t n,
                        VkShaderStageFlags stages, uint32_t push, VkPipelineLayout *out,
                        rt_error *e)
{
    VkPushConstantRange pr = { stages, 0, push };
    VkPipelineLayoutCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = n, .pSetLayouts = sets,
        .pushConstantRangeCount = 1, .pPushConstantRanges = &pr,
    };
    RT_VK(e, vkCreatePipelineLayout(d->dev, &ci, NULL, out));
    return true;
}

/* Colour RGBA32F loaded and left TRANSFER_SRC (as every path leaves it);
 * depth loaded from `depth_in` (the forward and multi-pass paths leave
 * it an attachment, the screen path's geometry pass SHADER_READ_ONLY). */
static bool make_pass(rt_device *d, VkImageLayout depth_in, VkRenderPass *out, rt_error *e)
{
    VkAttachmentDescription att[2] = {
        { 0, VK_FORMAT_R32G32B32A32_SFLOAT, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_LOAD,
          VK_ATTACHMENT_STORE_OP_STORE, VK_ATTACHMENT_LOAD_OP_DONT_CARE,
          VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
          VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL },
        { 0, VK_FORMAT_D32_SFLOAT, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_LOAD,
          VK_ATTACHMENT_STORE_OP_STORE, VK_ATTACHMENT_LOAD_OP_DONT_CARE,
          VK_ATTACHMENT_STORE_OP_DONT_CARE, depth_in, depth_in },
    };
    VkAttachmentReference cref = { 0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL };
    VkAttachmentReference dref = { 1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL };
    VkSubpassDescription sub = {
        .pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS,
        .colorAttachmentCount = 1, .pColorAttachments = &cref,
        .pDepthStencilAttachment = &dref,
    };
    VkSubpassDependency dep[2] = {
        { VK_SUBPASS_EXTERNAL, 0,
          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT |
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
          VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
          VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT |
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT, 0 },
        { 0, VK_SUBPASS_EXTERNAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT, 0 },
    };
    VkRenderPassCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO,
        .attachmentCount = 2, .pAttachments = att, .subpassCount = 1, .pSubpasses = &sub,
        .dependencyCount = 2, .pDependencies = dep,
    };
    RT_VK(e, vkCreateRenderPass(d->dev, &ci, NULL, out));
    return true;
}

/* The draw pipeline of opaque meshes (depth tested before shading: blades
 * hidden behind nearer ones cost no lighting), of cut-out ones (the
 * fragment shader discards, so the test waits for it: kind 1) or of the
 * contact shadows (kind 2: multiplied into the colour, no depth written). */
static bool draw_pipeline(rt_ug *u, int kind, rt_error *e)
{
    rt_device *d = u->d;
    bool cutout = kind == 1, shadow = kind == 2;
    const char *vmain = shadow ? shadow_vert_main : draw_vert_main;
    size_t nv = strlen(SPLAT_GLSL_TERRAIN) + strlen(vmain) + 32;
    size_t nf = strlen(SPLAT_GLSL_PRELUDE) + strlen(draw_frag_main) + strlen(shadow_frag) + 96;
    char *vs = malloc(nv), *fs = malloc(nf);
    if (!vs || !fs) {
        free(vs);
        free(fs);
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    }
    snprintf(vs, nv, "#version 450\n%s%s", SPLAT_GLSL_TERRAIN, vmain);
    if (shadow)
        snprintf(fs, nf, "%s", shadow_frag);
    else
        snprintf(fs, nf, "#version 450\n%s%s%s",
                 cutout ? "#define UG_CUTOUT 1\n" : "layout(early_fragment_tests) in;\n",
                 SPLAT_GLSL_PRELUDE, draw_frag_main);
    VkShaderModule vm = VK_NULL_HANDLE, fm = VK_NULL_HANDLE;
    bool ok = rt_glsl_module(d, vs, VK_SHADER_STAGE_VERTEX_BIT, "undergrowth.vert", NULL, &vm, e) &&
              rt_glsl_module(d, fs, VK_SHADER_STAGE_FRAGMENT_BIT, "undergrowth.frag", NULL, &fm, e);
    free(vs);
    free(fs);
    if (ok) {
        VkPipelineShaderStageCreateInfo st[2] = {
            { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
              .stage = VK_SHADER_STAGE_VERTEX_BIT, .module = vm, .pName = "main" },
            { .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
              .stage = VK_SHADER_STAGE_FRAGMENT_BIT, .module = fm, .pName = "main" },
        };
        VkVertexInputBindingDescription vb = { 0, 32, VK_VERTEX_INPUT_RATE_VERTEX };
        VkVertexInputAttributeDescription va[3] = {
            { 0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0 },
            { 1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12 },
            { 2, 0, VK_FORMAT_R32G32_SFLOAT, 24 },
        };
        VkPipelineVertexInputStateCreateInfo vi = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
            .vertexBindingDescriptionCount = 1, .pVertexBindingDescriptions = &vb,
            .vertexAttributeDescriptionCount = 3, .pVertexAttributeDescriptions = va,
        };
        VkPipelineInputAssemblyStateCreateInfo ia = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
            .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST,
        };
        VkPipelineViewportStateCreateInfo vps = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
            .viewportCount = 1, .scissorCount = 1,
        };
        VkPipelineRasterizationStateCreateInfo rs = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
            .polygonMode = VK_POLYGON_MODE_FILL, .cullMode = VK_CULL_MODE_NONE,
            .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE, .lineWidth = 1.0f,
        };
        VkPipelineMultisampleStateCreateInfo ms = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
            .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT,
        };
        VkPipelineDepthStencilStateCreateInfo ds = {   /* reversed Z */
            .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
            .depthTestEnable = VK_TRUE, .depthWriteEnable = shadow ? VK_FALSE : VK_TRUE,
            .depthCompareOp = VK_COMPARE_OP_GREATER,
        };
        VkPipelineColorBlendAttachmentState cba = { .colorWriteMask = 0xf };
        if (shadow)   /* dst * src: the colour darkened, its alpha kept */
            cba = (VkPipelineColorBlendAttachmentState){
                .blendEnable = VK_TRUE, .srcColorBlendFactor = VK_BLEND_FACTOR_ZERO,
                .dstColorBlendFactor = VK_BLEND_FACTOR_SRC_COLOR, .colorBlendOp = VK_BLEND_OP_ADD,
                .srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO,
                .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE, .alphaBlendOp = VK_BLEND_OP_ADD,
                .colorWriteMask = 0xf };
        VkPipelineColorBlendStateCreateInfo cb = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
            .attachmentCount = 1, .pAttachments = &cba,
        };
        VkDynamicState dyn[2] = { VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR };
        VkPipelineDynamicStateCreateInfo dy = {
            .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
            .dynamicStateCount = 2, .pDynamicStates = dyn,
        };
        VkGraphicsPipelineCreateInfo ci = {
            .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
            .stageCount = 2, .pStages = st, .pVertexInputState = &vi,
            .pInputAssemblyState = &ia, .pViewportState = &vps, .pRasterizationState = &rs,
            .pMultisampleState = &ms, .pDepthStencilState = &ds, .pColorBlendState = &cb,
            .pDynamicState = &dy, .layout = u->draw_layout, .renderPass = u->pass_att,
        };
        VkResult r = vkCreateGraphicsPipelines(d->dev, VK_NULL_HANDLE, 1, &ci, NULL,
                                               shadow ? &u->shadow_pipe : &u->draw_pipe[cutout]);
        if (r != VK_SUCCESS)
            ok = rt_fail(e, RT_E_VULKAN, "vkCreateGraphicsPipelines", rt_vk_result_name(r));
    }
    if (vm)
        vkDestroyShaderModule(d->dev, vm, NULL);
    if (fm)
        vkDestroyShaderModule(d->dev, fm, NULL);
    return ok;
}

/* The radius of a mesh's footprint on the ground (m at scale 1): the
 * farthest vertex from its axis, for the contact shadow's quad. */
static double footprint(const rt_pack_ug *pu, int mesh)
{
    const rt_pack_ug_mesh *m = &pu->meshes[mesh];
    double r = 0;
    for (uint32_t v = 0; v < m->nv; v++) {
        const float *x = pu->vertices + 8 * (size_t)(m->first_vertex + v);
        double h = hypot(x[0], x[2]);
        r = h > r ? h : r;
    }
    return r;
}

static uint32_t gcd(uint32_t a, uint32_t b)
{
    while (b) {
        uint32_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

/* The block table (set 0 binding 3 of the scatter pass, set 2 binding 0
 * of the draw and the probe): per block UG_BLOCK_VEC4 vec4s, (density,
 * scale lo, scale hi, blend), (colour, slot), (candidates per side, first
 * instance in the cell, flags, the stride of the candidates' lattice
 * order), (wind direction x, z, sway, gust), (root blend, shadow, the
 * mesh's footprint radius, 0).
 * Flags: 1 cut out (frond), 2 lit with the terrain normal, 4 aligned to
 * the terrain normal, 8 cut out by the texture's alpha; bits 8 and up the
 * texture + 1 (0: none). */
static void fill_blocks(rt_ug *u, float *b)
{
    const rt_pack_ug *pu = &u->p->ug;
    uint32_t at = 0;
    for (int i = 0; i < u->nblocks; i++) {
        const rt_pack_ug_block *k = &pu->blocks[i];
        /* enough candidates that keep = density * 256 / n^2 <= 1 */
        uint32_t nn = splat_ug_candidates(k->density), n = (uint32_t)lround(sqrt(nn));
        u->block_grid[i] = n;
        u->block_base[i] = at;
        at += nn;
        unsigned flags = (k->cutout == 1 ? 1u : 0u) | (k->light_terrain ? 2u : 0u) |
                         (k->align_normal ? 4u : 0u) | (k->cutout == 2 ? 8u : 0u) |
                         (unsigned)(k->texture + 1) << 8;
        uint32_t stride = (uint32_t)(0.618034 * n * n);
        while (stride > 1 && gcd(stride, n * n) != 1)
            stride++;
        float v[4 * UG_BLOCK_VEC4] = {
            (float)k->density, (float)k->scale[0], (float)k->scale[1], (float)k->blend,
            (float)k->color[0], (float)k->color[1], (float)k->color[2], (float)k->slot,
            (float)n, (float)u->block_base[i], (float)flags, (float)(stride ? stride : 1),
            (float)k->wind[0], (float)k->wind[1], (float)k->wind[2], (float)k->wind[3],
            (float)k->root_blend, (float)k->shadow, (float)footprint(pu, k->mesh), 0 };
        memcpy(b + 4 * UG_BLOCK_VEC4 * i, v, sizeof v);
    }
    u->cap = at;
}

static bool make_sets(rt_ug *u, VkDescriptorSet set0_src, const rt_image *height,
                      VkSampler nearest, rt_error *e)
{
    rt_device *d = u->d;
    VkDescriptorPoolSize sizes[3] = {
        { VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 13 + 1 },   /* + set 0's vector shapes */
        { VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16 + SPLAT_MAX_UG_TEXTURES },
        { VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2 },
    };
    VkDescriptorSetLayout layouts[5] = { u->set_terrain, u->set_mask, u->set_gen, u->set_draw,
                                         u->set_lod };
    VkDescriptorSet sets[5];
    if (!rt_descriptor_sets(d, sizes, 3, layouts, 5, &u->dpool, sets, e))
        return false;
    u->set0 = sets[0];
    u->mask_set = sets[1];
    u->gen_set = sets[2];
    u->draw_set = sets[3];
    u->lod_set = sets[4];
    /* set 0 of the mask pass: the terrain's, but the frame block whose
     * camera is the origin (abi.h "undergrowth masks") */
    rt_terrain_compute_set(d, set0_src, u->set0, u->frame.buf);
    VkDescriptorBufferInfo mb = { u->masks.buf, 0, VK_WHOLE_SIZE };
    VkDescriptorBufferInfo ib = { u->inst.buf, 0, VK_WHOLE_SIZE };
    VkDescriptorBufferInfo ab = { u->args.buf, 0, VK_WHOLE_SIZE };
    VkDescriptorBufferInfo bb = { u->blocks.buf, 0, VK_WHOLE_SIZE };
    VkDescriptorBufferInfo db = { u->draw_args.buf, 0, VK_WHOLE_SIZE };
    VkDescriptorBufferInfo lb = { u->lod.buf, 0, VK_WHOLE_SIZE };
    VkDescriptorBufferInfo fm = { u->far.buf, 0, VK_WHOLE_SIZE };
    VkDescriptorImageInfo hi = { nearest, height->view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL };
    const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
#define W(set_, b_, type_, img_, buf_) \
    (VkWriteDescriptorSet){ .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, \
        .dstSet = set_, .dstBinding = b_, .descriptorCount = 1, .descriptorType = type_, \
        .pImageInfo = img_, .pBufferInfo = buf_ }
    VkWriteDescriptorSet w[] = {
        W(u->mask_set, 0, sb, NULL, &mb),
        W(u->gen_set, 0, sb, NULL, &mb), W(u->gen_set, 1, sb, NULL, &ib),
        W(u->gen_set, 2, sb, NULL, &ab), W(u->gen_set, 3, sb, NULL, &bb),
        W(u->gen_set, 4, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, &hi, NULL),
        W(u->draw_set, 0, sb, NULL, &bb), W(u->draw_set, 1, sb, NULL, &ib),
        W(u->draw_set, 2, sb, NULL, &lb),
        W(u->lod_set, 0, sb, NULL, &ab), W(u->lod_set, 1, sb, NULL, &db),
        W(u->lod_set, 2, sb, NULL, &lb), W(u->lod_set, 3, sb, NULL, &fm),
    };
#undef W
    vkUpdateDescriptorSets(d->dev, sizeof w / sizeof *w, w, 0, NULL);
    /* the textures (every slot bound: the white one past the pack's) */
    VkDescriptorImageInfo ti[SPLAT_MAX_UG_TEXTURES];
    for (int i = 0; i < SPLAT_MAX_UG_TEXTURES; i++) {
        int k = i < u->p->ug.ntextures ? i : SPLAT_MAX_UG_TEXTURES;
        ti[i] = (VkDescriptorImageInfo){ u->tex_smp, u->tex[k].view,
                                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL };
    }
    VkWriteDescriptorSet tw = {
        .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, .dstSet = u->draw_set, .dstBinding = 3,
        .descriptorCount = SPLAT_MAX_UG_TEXTURES,
        .descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, .pImageInfo = ti,
    };
    vkUpdateDescriptorSets(d->dev, 1, &tw, 0, NULL);
    return true;
}

/* The blocks' textures: sRGB with their mip chains, and a white texel. */
static bool make_textures(rt_ug *u, rt_error *e)
{
    rt_device *d = u->d;
    const rt_pack_ug *pu = &u->p->ug;
    const VkImageUsageFlags use = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                  VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    for (int i = 0; i <= pu->ntextures; i++) {
        static const uint8_t white[4] = { 255, 255, 255, 255 };
        bool own = i < pu->ntextures;
        uint32_t w = own ? (uint32_t)pu->textures[i].width : 1;
        uint32_t h = own ? (uint32_t)pu->textures[i].height : 1, mips = 1;
        while ((w > h ? w : h) >> mips)
            mips++;
        rt_image *img = &u->tex[own ? i : SPLAT_MAX_UG_TEXTURES];
        if (!rt_image_create(d, w, h, 1, false, mips, VK_FORMAT_R8G8B8A8_SRGB, use,
                             VK_IMAGE_ASPECT_COLOR_BIT, img, e) ||
            !rt_image_upload(d, img, own ? pu->textures[i].rgba : white, (size_t)w * h * 4, e))
            return false;
    }
    VkSamplerCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = VK_FILTER_LINEAR, .minFilter = VK_FILTER_LINEAR,
        .mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR,
        .addressModeU = VK_SAMPLER_ADDRESS_MODE_REPEAT, .addressModeV = VK_SAMPLER_ADDRESS_MODE_REPEAT,
        .addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT, .maxLod = 16.0f,
    };
    RT_VK(e, vkCreateSampler(d->dev, &ci, NULL, &u->tex_smp));
    return true;
}

static bool make_layouts(rt_ug *u, rt_error *e)
{
    rt_device *d = u->d;
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    VkDescriptorSetLayoutBinding mask[] = { { 0, sb, 1, cs, NULL } };
    VkDescriptorSetLayoutBinding gen[] = {
        { 0, sb, 1, cs, NULL }, { 1, sb, 1, cs, NULL }, { 2, sb, 1, cs, NULL },
        { 3, sb, 1, cs, NULL }, { 4, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs, NULL },
    };
    VkDescriptorSetLayoutBinding draw[] = {
        { 0, sb, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL }, { 1, sb, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL },
        { 2, sb, 1, VK_SHADER_STAGE_VERTEX_BIT, NULL },
        { 3, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, SPLAT_MAX_UG_TEXTURES,
          VK_SHADER_STAGE_FRAGMENT_BIT, NULL },
    };
    VkDescriptorSetLayoutBinding lod[] = {
        { 0, sb, 1, cs, NULL }, { 1, sb, 1, cs, NULL }, { 2, sb, 1, cs, NULL },
        { 3, sb, 1, cs, NULL },
    };
    if (!rt_terrain_compute_layout(d, &u->set_terrain, e) ||
        !rt_set_layout(d, mask, 1, &u->set_mask, e) || !rt_set_layout(d, gen, 5, &u->set_gen, e) ||
        !rt_set_layout(d, draw, 4, &u->set_draw, e) || !rt_set_layout(d, lod, 4, &u->set_lod, e))
        return false;
    VkDescriptorSetLayout ms[3] = { u->set_terrain, u->pl->set_material, u->set_mask };
    VkDescriptorSetLayout ds[3] = { u->pl->set_terrain, u->pl->set_material, u->set_draw };
    return pipe_layout(d, ms, 3, cs, sizeof(splat_push), &u->mask_layout, e) &&
           pipe_layout(d, &u->set_gen, 1, cs, sizeof(ug_push), &u->gen_layout, e) &&
           pipe_layout(d, &u->set_lod, 1, cs, 16, &u->lod_layout, e) &&
           pipe_layout(d, ds, 3, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       sizeof(splat_push), &u->draw_layout, e);
}

static bool make_buffers(rt_ug *u, rt_error *e)
{
    rt_device *d = u->d;
    const rt_pack_ug *pu = &u->p->ug;
    const VkBufferUsageFlags st = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkDeviceSize mask_bytes = (VkDeviceSize)u->pool * TEXELS * TEXELS * (u->nw + 2) * 4;
    VkDeviceSize inst_bytes = (VkDeviceSize)u->pool * u->cap * SPLAT_UG_INSTANCE_BYTES;
    VkDeviceSize range = d->props.limits.maxStorageBufferRange;
    VkDeviceSize inst_max = range < SPLAT_UG_MAX_INSTANCE_BYTES ? range : SPLAT_UG_MAX_INSTANCE_BYTES;
    if (inst_bytes > inst_max)
        return rt_fail(e, RT_E_PACK_LIMIT, u->p->dir, "undergrowth's instance buffer (bytes)",
                       (unsigned long long)inst_bytes,
                       range < SPLAT_UG_MAX_INSTANCE_BYTES
                           ? "the device's maxStorageBufferRange"
                           : "the runtime's instance buffer limit (abi.h)",
                       (unsigned long long)inst_max);
    if (mask_bytes > range)
        return rt_fail(e, RT_E_PACK_LIMIT, u->p->dir, "undergrowth's mask buffer (bytes)",
                       (unsigned long long)mask_bytes, "the device's maxStorageBufferRange",
                       (unsigned long long)range);
    if (!rt_buffer_create(d, mask_bytes, st | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, &u->masks, e) ||
        !rt_buffer_create(d, inst_bytes + 32, st | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false,
                          &u->inst, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * u->nblocks * 20,
                          st | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                              VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false, &u->args, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * u->nblocks * 20,
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &u->args_host, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * u->nblocks * 40,   /* + the shadows' */
                          st | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, false, &u->draw_args, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->pool * 4, st, true, &u->lod, e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->nblocks * 16 * UG_BLOCK_VEC4, st, true, &u->blocks,
                          e) ||
        !rt_buffer_create(d, (VkDeviceSize)u->nblocks * 32, st, true, &u->far, e) ||
        !rt_buffer_create(d, (VkDeviceSize)(pu->nvertices + 4) * 32,
                          VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, true, &u->vbuf, e) ||
        !rt_buffer_create(d, (VkDeviceSize)(pu->nindices + 6) * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                          true, &u->ibuf, e) ||
        !rt_buffer_create(d, sizeof(splat_frame), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true,
                          &u->frame, e))
        return false;
    memcpy(u->vbuf.map, pu->vertices, (size_t)pu->nvertices * 32);
    memcpy(u->ibuf.map, pu->indices, (size_t)pu->nindices * 4);
    /* the contact shadow's quad after the pack's meshes: [-1, 1]^2 in x, z */
    static const float quad[4][8] = { { -1, 0, -1, 0, 1, 0, 0, 0 }, { 1, 0, -1, 0, 1, 0, 1, 0 },
                                      { 1, 0, 1, 0, 1, 0, 1, 1 }, { -1, 0, 1, 0, 1, 0, 0, 1 } };
    static const uint32_t qi[6] = { 0, 1, 2, 0, 2, 3 };
    memcpy((float *)u->vbuf.map + (size_t)pu->nvertices * 8, quad, sizeof quad);
    memcpy((uint32_t *)u->ibuf.map + pu->nindices, qi, sizeof qi);
    fill_blocks(u, u->blocks.map);
    for (int b = 0; b < u->nblocks; b++) {
        int f = pu->meshes[pu->blocks[b].mesh].far;
        const rt_pack_ug_mesh *m = &pu->meshes[f >= 0 ? f : 0];
        uint32_t v[8] = { m->nidx, m->first_index, m->first_vertex, f >= 0,
                          pu->blocks[b].shadow > 0 && u->shadows, 0, 0, 0 };
        memcpy((uint32_t *)u->far.map + 8 * b, v, sizeof v);
    }
    memset(u->args_host.map, 0, (size_t)u->args_host.size);
    for (int i = 0; i < u->pool; i++)
        ((float *)u->lod.map)[i] = 1.0f;
    return true;
}

bool rt_ug_create(rt_device *d, const rt_pack *p, rt_pipelines *pl, const rt_quadtree *qt,
                  const rt_ug_targets *t, double radius, rt_ug **out, rt_error *e)
{
    *out = NULL;
    if (p->ug.nslots == 0)
        return true;
    rt_ug *u = calloc(1, sizeof *u);
    if (!u)
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    *out = u;
    u->d = d;
    u->p = p;
    u->pl = pl;
    u->qt = qt;
    u->radius = radius > 0 ? radius : RT_UG_RADIUS;
    u->pool = (int)splat_ug_pool(u->radius);
    u->nblocks = p->ug.nblocks;
    u->nw = (p->ug.nslots + 3) / 4;
    u->cells = calloc((size_t)u->pool, sizeof *u->cells);
    u->order = calloc((size_t)u->pool, sizeof *u->order);
    u->block_base = calloc((size_t)u->nblocks, sizeof *u->block_base);
    u->block_grid = calloc((size_t)u->nblocks, sizeof *u->block_grid);
    u->mask_pipes = calloc((size_t)p->ncombos + 1, sizeof *u->mask_pipes);
    if (!u->cells || !u->order || !u->block_base || !u->block_grid || !u->mask_pipes)
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    fill_blocks(u, (float[4 * UG_BLOCK_VEC4 * SPLAT_MAX_UG_BLOCKS]){0});   /* u->cap first */
    /* contact shadows where the colour target blends (RGBA32F: most do) */
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(d->phys, VK_FORMAT_R32G32B32A32_SFLOAT, &fp);
    for (int b = 0; b < u->nblocks; b++)
        u->shadows |= p->ug.blocks[b].shadow > 0;
    u->shadows &= (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT) != 0;
    VkQueryPoolCreateInfo qi = {
        .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
        .queryType = VK_QUERY_TYPE_TIMESTAMP, .queryCount = 4,
    };
    if (!make_layouts(u, e) || !make_buffers(u, e) || !make_textures(u, e) ||
        !make_sets(u, t->set0, t->height, t->nearest, e) ||
        !make_pass(d, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, &u->pass_att, e) ||
        !make_pass(d, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, &u->pass_ro, e) ||
        !rt_glsl_compute_pipeline(d, VK_NULL_HANDLE, u->gen_layout, gen_glsl, "undergrowth scatter", NULL, &u->gen_pipe, e) ||
        !rt_glsl_compute_pipeline(d, VK_NULL_HANDLE, u->lod_layout, lod_glsl, "undergrowth lod", NULL, &u->lod_pipe, e) ||
        !draw_pipeline(u, 0, e) || !draw_pipeline(u, 1, e) ||
        (u->shadows && !draw_pipeline(u, 2, e)))
        return false;
    VkImageView views[2] = { t->color->view, t->depth->view };
    VkFramebufferCreateInfo fci = {
        .sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO,
        .renderPass = u->pass_att, .attachmentCount = 2, .pAttachments = views,
        .width = (uint32_t)t->width, .height = (uint32_t)t->height_px, .layers = 1,
    };
    RT_VK(e, vkCreateFramebuffer(d->dev, &fci, NULL, &u->fb));
    if (t->timestamps)
        RT_VK(e, vkCreateQueryPool(d->dev, &qi, NULL, &u->qpool));
    return true;
}

void rt_ug_destroy(rt_ug *u)
{
    if (!u)
        return;
    rt_device *d = u->d;
    for (int i = 0; u->mask_pipes && i <= u->p->ncombos; i++)
        if (u->mask_pipes[i])
            vkDestroyPipeline(d->dev, u->mask_pipes[i], NULL);
    VkPipeline pipes[5] = { u->gen_pipe, u->lod_pipe, u->draw_pipe[0], u->draw_pipe[1],
                            u->shadow_pipe };
    for (int i = 0; i < 5; i++)
        if (pipes[i])
            vkDestroyPipeline(d->dev, pipes[i], NULL);
    VkPipelineLayout pls[4] = { u->mask_layout, u->gen_layout, u->draw_layout, u->lod_layout };
    for (int i = 0; i < 4; i++)
        if (pls[i])
            vkDestroyPipelineLayout(d->dev, pls[i], NULL);
    VkDescriptorSetLayout sls[5] = { u->set_terrain, u->set_mask, u->set_gen, u->set_draw,
                                     u->set_lod };
    for (int i = 0; i < 5; i++)
        if (sls[i])
            vkDestroyDescriptorSetLayout(d->dev, sls[i], NULL);
    if (u->dpool)
        vkDestroyDescriptorPool(d->dev, u->dpool, NULL);
    if (u->fb)
        vkDestroyFramebuffer(d->dev, u->fb, NULL);
    if (u->pass_att)
        vkDestroyRenderPass(d->dev, u->pass_att, NULL);
    if (u->pass_ro)
        vkDestroyRenderPass(d->dev, u->pass_ro, NULL);
    if (u->qpool)
        vkDestroyQueryPool(d->dev, u->qpool, NULL);
    rt_buffer *bufs[] = { &u->masks, &u->inst, &u->args, &u->args_host, &u->draw_args, &u->lod,
                          &u->far, &u->blocks, &u->vbuf, &u->ibuf, &u->frame };
    for (size_t i = 0; i < sizeof bufs / sizeof *bufs; i++)
        rt_buffer_destroy(d, bufs[i]);
    if (u->probe_pipe)
        vkDestroyPipeline(d->dev, u->probe_pipe, NULL);
    if (u->probe_layout)
        vkDestroyPipelineLayout(d->dev, u->probe_layout, NULL);
    if (u->probe_sl)
        vkDestroyDescriptorSetLayout(d->dev, u->probe_sl, NULL);
    if (u->probe_pool)
        vkDestroyDescriptorPool(d->dev, u->probe_pool, NULL);
    rt_buffer_destroy(d, &u->probe_out);
    for (int i = 0; i <= SPLAT_MAX_UG_TEXTURES; i++)
        rt_image_destroy(d, &u->tex[i]);
    if (u->tex_smp)
        vkDestroySampler(d->dev, u->tex_smp, NULL);
    free(u->mask_pipes);
    free(u->cells);
    free(u->order);
    free(u->block_base);
    free(u->block_grid);
    free(u);
}

/* ---- cells ---------------------------------------------------------------------- */

static ug_cell *find_cell(rt_ug *u, int ix, int iz)
{
    for (int i = 0; i < u->pool; i++)
        if (u->cells[i].state != CELL_FREE && u->cells[i].ix == ix && u->cells[i].iz == iz)
            return &u->cells[i];
    return NULL;
}

/* Whether the box [lo, hi] (camera-relative) is outside one clip plane. */
static bool box_outside(const float *m, const double lo[3], const double hi[3])
{
    for (int plane = 0; plane < 5; plane++) {
        bool all_out = true;
        for (int c = 0; c < 8 && all_out; c++) {
            double p[3] = { c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2] };
            double v[4];
            for (int r = 0; r < 4; r++)   /* column-major */
                v[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
            double d = plane == 0 ? v[3] + v[0] : plane == 1 ? v[3] - v[0]
                     : plane == 2 ? v[3] + v[1] : plane == 3 ? v[3] - v[1] : v[3] - v[2];
            all_out = d < 0;
        }
        if (all_out)
            return true;
    }
    return false;
}

/* Draw and generation order: visible before not, near before far. */
static bool before(const ug_cell *x, const ug_cell *y)
{
    if (x->visible != y->visible)
        return x->visible;
    return x->dist < y->dist;
}

/* Allocate every cell within the radius (freeing those outside), then
 * order the pool: visible before not, near before far. */
static void allocate(rt_ug *u, const rt_camera *c, const float view_proj[16])
{
    const rt_pack *p = u->p;
    for (int i = 0; i < u->pool; i++)
        u->cells[i].wanted = false;
    double r = u->radius, cx = c->position[0], cz = c->position[2];
    /* from higher above the ground than the radius nothing would show:
     * no cells (so views from the air pay nothing) */
    int tx = (int)(cx / p->size[0] * (p->hf_width - 1) + 0.5);
    int tz = (int)(cz / p->size[1] * (p->hf_height - 1) + 0.5);
    tx = tx < 0 ? 0 : tx >= p->hf_width ? p->hf_width - 1 : tx;
    tz = tz < 0 ? 0 : tz >= p->hf_height ? p->hf_height - 1 : tz;
    double below = p->heights[(size_t)tz * (size_t)p->hf_width + (size_t)tx] / 65535.0 *
                   p->max_height + p->height_offset;
    if (c->position[1] - below > r)
        r = 0;
    int x0 = (int)floor((cx - r) / CELL), x1 = (int)floor((cx + r) / CELL);
    int z0 = (int)floor((cz - r) / CELL), z1 = (int)floor((cz + r) / CELL);
    int maxx = (int)ceil(p->size[0] / CELL) - 1, maxz = (int)ceil(p->size[1] / CELL) - 1;
    for (int iz = z0 < 0 ? 0 : z0; iz <= z1 && iz <= maxz; iz++)
        for (int ix = x0 < 0 ? 0 : x0; ix <= x1 && ix <= maxx; ix++) {
            double dx = (ix + 0.5) * CELL - cx, dz = (iz + 0.5) * CELL - cz;
            if (dx * dx + dz * dz > r * r || r == 0)
                continue;
            ug_cell *cl = find_cell(u, ix, iz);
            if (!cl)
                for (int i = 0; i < u->pool && !cl; i++)
                    if (u->cells[i].state == CELL_FREE)
                        cl = &u->cells[i];
            if (!cl)
                continue;   /* the pool is sized for the disc: not reached */
            if (cl->state == CELL_FREE)
                *cl = (ug_cell){ .ix = ix, .iz = iz, .state = CELL_PENDING };
            cl->wanted = true;
            cl->dist = sqrt(dx * dx + dz * dz);
        }
    /* cells that left the disc are free now; the disc's new ones take
     * them next frame at the latest (a full pool frees before it fills) */
    for (int i = 0; i < u->pool; i++)
        if (!u->cells[i].wanted)
            u->cells[i].state = CELL_FREE;
    double hmin = p->height_offset, hmax = p->height_offset + p->max_height;
    for (int i = 0; i < u->pool; i++) {
        ug_cell *cl = &u->cells[i];
        u->order[i] = i;
        if (cl->state == CELL_FREE)
            continue;
        double lo[3] = { cl->ix * CELL - cx, hmin - c->position[1] - 2, cl->iz * CELL - cz };
        double hi[3] = { lo[0] + CELL, hmax - c->position[1] + 8, lo[2] + CELL };
        cl->visible = !box_outside(view_proj, lo, hi);
        double near = cl->dist - CELL * 0.7071;   /* the cell's nearest point, about */
        double f = near > LOD_NEAR ? (LOD_NEAR / near) * (LOD_NEAR / near) : 1.0;
        ((float *)u->lod.map)[i] = (float)(f > LOD_MIN ? f : LOD_MIN);
    }
    for (int i = 1; i < u->pool; i++)   /* insertion sort: a few hundred cells */
        for (int j = i; j > 0 && before(&u->cells[u->order[j]], &u->cells[u->order[j - 1]]); j--) {
            int t = u->order[j];
            u->order[j] = u->order[j - 1];
            u->order[j - 1] = t;
        }
}

void rt_ug_invalidate(rt_ug *u, const double *rect)
{
    if (!u)
        return;
    for (int i = 0; i < u->pool; i++) {
        ug_cell *cl = &u->cells[i];
        if (cl->state != CELL_READY)
            continue;
        if (rect && (cl->ix * CELL > rect[2] || (cl->ix + 1) * CELL < rect[0] ||
                     cl->iz * CELL > rect[3] || (cl->iz + 1) * CELL < rect[1]))
            continue;
        cl->state = CELL_PENDING;
    }
}

/* ---- generation ------------------------------------------------------------------- */

static bool mask_pipeline(rt_ug *u, int combo, VkPipeline *out, rt_error *e)
{
    if (!u->mask_pipes[combo]) {
        const char *glsl = u->p->combos[combo].ug_compute;
        char name[64];
        snprintf(name, sizeof name, "combination %d (undergrowth masks)", combo);
        if (!glsl) {
            *out = VK_NULL_HANDLE;   /* grows nothing: the texels stay 0 */
            return true;
        }
        rt_interface in;
        if (!rt_interface_for(u->p, RT_ROLE_UNDERGROWTH, &in))
            return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
        const rt_spirv *spv = &u->p->combos[combo].ug_spirv;   /* the build's */
        bool ok = spv->words ? rt_spirv_compute_pipeline(u->d, u->pl->cache, u->mask_layout, spv,
                                                         &u->mask_pipes[combo], e)
                             : rt_glsl_compute_pipeline(u->d, u->pl->cache, u->mask_layout, glsl,
                                                        name, &in, &u->mask_pipes[combo], e);
        rt_interface_free(&in);
        if (!ok)
            return false;
    }
    *out = u->mask_pipes[combo];
    return true;
}

/* The mask dispatches of cell `cl` in pool slot `slot`: one per leaf cell
 * it overlaps, clipped to that leaf. */
static bool record_masks(rt_ug *u, VkCommandBuffer cb, const ug_cell *cl, int slot,
                         VkDescriptorSet set1, rt_error *e)
{
    const rt_pack *p = u->p;
    const rt_pack_level *L0 = &p->levels[0];
    double lx0, lz0, lsx, lsz;
    rt_node_rect(u->qt, 0, 0, 0, &lx0, &lz0, &lsx, &lsz);
    double x0 = cl->ix * CELL, z0 = cl->iz * CELL;
    int ax = (int)floor(x0 / lsx), bx = (int)floor((x0 + CELL) / lsx);
    int az = (int)floor(z0 / lsz), bz = (int)floor((z0 + CELL) / lsz);
    VkDescriptorSet sets[3] = { u->set0, set1, u->mask_set };
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->mask_layout, 0, 3, sets, 0, NULL);
    for (int lz = az; lz <= bz; lz++)
        for (int lx = ax; lx <= bx; lx++) {
            if (lx < 0 || lz < 0 || lx >= L0->width || lz >= L0->height)
                continue;
            unsigned id = L0->ids[(size_t)lz * (size_t)L0->width + (size_t)lx];
            if (id == SPLAT_COMBO_HOLE)
                continue;
            VkPipeline pipe;
            if (!mask_pipeline(u, (int)id, &pipe, e))
                return false;
            if (!pipe)
                continue;
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
            splat_push push = {
                .patch_xz = { (float)x0, (float)z0, (float)CELL, 0 },
                .patch_uv = { (float)(lx * lsx), (float)(lz * lsz), (float)((lx + 1) * lsx),
                              (float)((lz + 1) * lsz) },
                .info = { (uint32_t)slot * TEXELS * TEXELS * (uint32_t)(u->nw + 2), 0,
                          (uint32_t)u->nw, 0 },
            };
            vkCmdPushConstants(cb, u->mask_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
            vkCmdDispatch(cb, TEXELS / 8, TEXELS / 8, 1);
        }
    return true;
}

/* The draw arguments of a slot's blocks (instance counts 0 until its
 * scatter pass writes them). */
static void reset_args(rt_ug *u, VkCommandBuffer cb, int slot)
{
    uint32_t a[5 * 64];
    for (int b = 0; b < u->nblocks; b++) {
        const rt_pack_ug_mesh *m = &u->p->ug.meshes[u->p->ug.blocks[b].mesh];
        uint32_t v[5] = { m->nidx, 0, m->first_index, m->first_vertex,
                          (uint32_t)slot * u->cap + u->block_base[b] };
        memcpy(a + 5 * b, v, sizeof v);
    }
    vkCmdUpdateBuffer(cb, u->args.buf, (VkDeviceSize)slot * u->nblocks * 20,
                      (VkDeviceSize)u->nblocks * 20, a);
}

bool rt_ug_generate(rt_ug *u, VkCommandBuffer cb, const rt_camera *c, const splat_frame *fr,
                    VkDescriptorSet set1, int budget, rt_error *e)
{
    u->generated = 0;
    u->time = c->time;
    u->cam_xz[0] = (float)c->position[0];
    u->cam_xz[1] = (float)c->position[2];
    allocate(u, c, fr->view_proj);
    /* the mask pass's frame block: this frame's, seen from the origin */
    splat_frame *uf = u->frame.map;
    *uf = *fr;
    memset(uf->camera, 0, sizeof uf->camera);
    for (int k = 0; k < u->p->nsites; k++)
        for (int a = 0; a < 4; a++)
            uf->world[4 * k + a] = 0.0f;
    if (u->qpool) {
        vkCmdResetQueryPool(cb, u->qpool, 0, 4);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, u->qpool, 0);
    }
    int todo[1024], n = 0;
    for (int i = 0; i < u->pool && n < (int)(sizeof todo / sizeof *todo); i++) {
        int k = u->order[i];
        if (u->cells[k].state == CELL_PENDING && (budget <= 0 || n < budget))
            todo[n++] = k;
    }
    if (n > 0) {
        VkDeviceSize per = (VkDeviceSize)TEXELS * TEXELS * (u->nw + 2) * 4;
        for (int i = 0; i < n; i++) {
            vkCmdFillBuffer(cb, u->masks.buf, per * (VkDeviceSize)todo[i], per, 0);
            reset_args(u, cb, todo[i]);
        }
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT |
                           VK_PIPELINE_STAGE_VERTEX_SHADER_BIT,
                       VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT |
                           VK_ACCESS_SHADER_READ_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT);
        for (int i = 0; i < n; i++)
            if (!record_masks(u, cb, &u->cells[todo[i]], todo[i], set1, e))
                return false;
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->gen_pipe);
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->gen_layout, 0, 1,
                                &u->gen_set, 0, NULL);
        const rt_pack *p = u->p;
        for (int i = 0; i < n; i++) {
            const ug_cell *cl = &u->cells[todo[i]];
            ug_push push = {
                .origin = { (float)(cl->ix * CELL), (float)(cl->iz * CELL) },
                .cell = { cl->ix, cl->iz }, .slot = (uint32_t)todo[i], .nw = (uint32_t)u->nw,
                .cap = u->cap,
                .mask_base = (uint32_t)todo[i] * TEXELS * TEXELS * (uint32_t)(u->nw + 2),
                .terrain = { (float)p->size[0], (float)p->size[1], (float)p->max_height,
                             (float)p->height_offset },
                .hf = { p->hf_width, p->hf_height }, .nblocks = (uint32_t)u->nblocks,
            };
            vkCmdPushConstants(cb, u->gen_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
            vkCmdDispatch(cb, (uint32_t)u->nblocks, 1, 1);
            u->cells[todo[i]].state = CELL_READY;
        }
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                           VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT |
                           VK_ACCESS_TRANSFER_READ_BIT);
        /* the counts, for the stats and the tests (read after the frame) */
        VkBufferCopy all = { 0, 0, u->args.size };
        vkCmdCopyBuffer(cb, u->args.buf, u->args_host.buf, 1, &all);
        rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    }
    /* every frame: this camera's LOD of every cell's arguments */
    uint32_t pc[4] = { (uint32_t)(u->pool * u->nblocks), (uint32_t)u->nblocks,
                       u->p->ug.nindices, u->p->ug.nvertices };   /* the shadow quad */
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->lod_pipe);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->lod_layout, 0, 1, &u->lod_set,
                            0, NULL);
    vkCmdPushConstants(cb, u->lod_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, pc);
    vkCmdDispatch(cb, (pc[0] + 63) / 64, 1, 1);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                   VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
    if (u->qpool)   /* bottom of pipe: when everything before has finished */
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 1);
    u->generated = n;
    return true;
}

bool rt_ug_visible(const rt_ug *u)
{
    for (int i = 0; u && i < u->pool; i++)
        if (u->cells[i].state == CELL_READY && u->cells[i].visible)
            return true;
    return false;
}

void rt_ug_draw(rt_ug *u, VkCommandBuffer cb, bool depth_read_only, VkDescriptorSet set0,
                VkDescriptorSet set1, const VkViewport *vp, const VkRect2D *area)
{
    u->drawn = true;
    if (u->qpool)   /* after the terrain has finished, not when it started */
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 2);
    VkRenderPassBeginInfo rb = {
        .sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
        .renderPass = depth_read_only ? u->pass_ro : u->pass_att, .framebuffer = u->fb,
        .renderArea = *area,
    };
    vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdSetViewport(cb, 0, 1, vp);
    vkCmdSetScissor(cb, 0, 1, area);
    VkDescriptorSet sets[3] = { set0, set1, u->draw_set };
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, u->draw_layout, 0, 3, sets, 0, NULL);
    splat_push push = { .patch_xz = { (float)u->radius, (float)u->time, 0, 0 },
                        .info = { u->cap, 0, 0, 0 } };
    vkCmdPushConstants(cb, u->draw_layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof push, &push);
    VkDeviceSize zero = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &u->vbuf.buf, &zero);
    vkCmdBindIndexBuffer(cb, u->ibuf.buf, 0, VK_INDEX_TYPE_UINT32);
    const rt_pack_ug *pu = &u->p->ug;
    if (u->shadows) {   /* under the plants: before them */
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, u->shadow_pipe);
        VkDeviceSize shadows = (VkDeviceSize)u->pool * u->nblocks * 20;
        for (int i = 0; i < u->pool; i++) {
            int k = u->order[i];
            if (u->cells[k].state != CELL_READY || !u->cells[k].visible)
                continue;
            VkDeviceSize at = shadows + (VkDeviceSize)k * u->nblocks * 20;
            for (int b = 0; b < u->nblocks; b++)
                if (pu->blocks[b].shadow > 0)
                    vkCmdDrawIndexedIndirect(cb, u->draw_args.buf, at + 20 * (VkDeviceSize)b, 1, 20);
        }
    }
    for (int cut = 0; cut < 2; cut++) {   /* opaque first: they hide the rest */
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, u->draw_pipe[cut]);
        for (int i = 0; i < u->pool; i++) {   /* front to back */
            int k = u->order[i];
            if (u->cells[k].state != CELL_READY || !u->cells[k].visible)
                continue;
            VkDeviceSize at = (VkDeviceSize)k * u->nblocks * 20;
            for (int b = 0; b < u->nblocks; b++)
                if ((pu->blocks[b].cutout != 0) == cut)
                    vkCmdDrawIndexedIndirect(cb, u->draw_args.buf, at + 20 * (VkDeviceSize)b, 1, 20);
        }
    }
    vkCmdEndRenderPass(cb);
    if (u->qpool)
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 3);
}

void rt_ug_read_stats(rt_ug *u, rt_ug_stats *st)
{
    memset(st, 0, sizeof *st);
    st->gen_ms = st->draw_ms = -1;
    if (!u)
        return;
    st->generated = u->generated;
    const uint32_t *a = u->args_host.map;
    for (int i = 0; i < u->pool; i++) {
        if (u->cells[i].state != CELL_READY)
            continue;
        st->cells++;
        for (int b = 0; b < u->nblocks; b++)
            st->instances += a[((size_t)i * u->nblocks + b) * 5 + 1];
    }
    st->bytes_per_cell = (size_t)TEXELS * TEXELS * (size_t)(u->nw + 2) * 4 +
                         (size_t)u->cap * 32 + (size_t)u->nblocks * 20;
    if (!u->qpool)
        return;
    uint64_t q[4];
    const VkQueryResultFlags fl = VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT;
    double ms = u->d->props.limits.timestampPeriod * 1e-6;
    if (vkGetQueryPoolResults(u->d->dev, u->qpool, 0, 2, sizeof q, q, sizeof q[0], fl) == VK_SUCCESS)
        st->gen_ms = (double)(q[1] - q[0]) * ms;
    if (u->drawn &&
        vkGetQueryPoolResults(u->d->dev, u->qpool, 2, 2, 2 * sizeof q[0], q + 2, sizeof q[0], fl) ==
            VK_SUCCESS)
        st->draw_ms = (double)(q[3] - q[2]) * ms;
    u->drawn = false;
}

int rt_ug_read_cell(rt_ug *u, int ix, int iz, rt_ug_instance *out, int max, rt_error *e)
{
    ug_cell *cl = u ? find_cell(u, ix, iz) : NULL;
    if (!cl || cl->state != CELL_READY)
        return 0;
    int slot = (int)(cl - u->cells);
    const uint32_t *a = (const uint32_t *)u->args_host.map + (size_t)slot * u->nblocks * 5;
    rt_buffer st;
    if (!rt_buffer_create(u->d, (VkDeviceSize)u->cap * 32, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true,
                          &st, e))
        return -1;
    VkCommandBuffer cb;
    if (!rt_oneshot_begin(u->d, &cb, e)) {
        rt_buffer_destroy(u->d, &st);
        return -1;
    }
    VkBufferCopy region = { (VkDeviceSize)slot * u->cap * 32, 0, (VkDeviceSize)u->cap * 32 };
    vkCmdCopyBuffer(cb, u->inst.buf, st.buf, 1, &region);
    if (!rt_oneshot_end(u->d, cb, e)) {
        rt_buffer_destroy(u->d, &st);
        return -1;
    }
    int n = 0;
    for (int b = 0; b < u->nblocks; b++)
        for (uint32_t k = 0; k < a[5 * b + 1] && n < max; k++, n++) {
            const uint8_t *src = (const uint8_t *)st.map + 32 * (size_t)(u->block_base[b] + k);
            memcpy(&out[n], src, 32);
        }
    rt_buffer_destroy(u->d, &st);
    return n;
}

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
        if (!rt_set_layout(d, b, 3, &u->probe_sl, e) ||
            !pipe_layout(d, &u->probe_sl, 1, cs, 32, &u->probe_layout, e) ||
            !rt_descriptor_sets(d, &size, 1, &u->probe_sl, 1, &u->probe_pool, &u->probe_set, e) ||
            !rt_glsl_compute_pipeline(d, VK_NULL_HANDLE, u->probe_layout, probe_glsl,
                                      "undergrowth probe", NULL, &u->probe_pipe, e))
            return false;
    }
    if (u->probe_out.size < bytes) {
        rt_buffer_destroy(d, &u->probe_out);
        if (!rt_buffer_create(d, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, &u->probe_out, e))
            return false;
        VkDescriptorBufferInfo bi[3] = { { u->inst.buf, 0, VK_WHOLE_SIZE },
                                         { u->draw_args.buf, 0, VK_WHOLE_SIZE },
                                         { u->probe_out.buf, 0, VK_WHOLE_SIZE } };
        VkWriteDescriptorSet w[3];
        for (int i = 0; i < 3; i++)
            w[i] = (VkWriteDescriptorSet){ .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
                                           .dstSet = u->probe_set, .dstBinding = (uint32_t)i,
                                           .descriptorCount = 1,
                                           .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                           .pBufferInfo = &bi[i] };
        vkUpdateDescriptorSets(d->dev, 3, w, 0, NULL);
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
