/* undergrowth_glsl.c — the undergrowth's own shaders (undergrowth.c
 * describes what each pass does). */
#include "undergrowth_impl.h"

/* ---- shaders ---------------------------------------------------------------- */

/* An inclusive prefix sum of s_scan[] over the workgroup's 64 lanes
 * (Hillis-Steele), after each lane has written its own entry. */
#define SCAN64                                                              \
    "        barrier();\n"                                                  \
    "        for (uint o = 1u; o < 64u; o <<= 1u) {\n"                      \
    "            uint v = lid >= o ? s_scan[lid - o] : 0u;\n"               \
    "            barrier();\n"                                              \
    "            s_scan[lid] += v;\n"                                       \
    "            barrier();\n"                                              \
    "        }\n"

const char rt_ug_gen_glsl[] =
    "#version 450\n"
    "layout(local_size_x = 64) in;\n"
    "layout(set = 0, binding = 0, std430) readonly buffer M { uint w[]; } u_mask;\n"
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 0, binding = 1, std430) writeonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 0, binding = 2, std430) buffer A { uint a[]; } u_args;\n"
    "layout(set = 0, binding = 3, std430) readonly buffer B { vec4 b[]; } u_blocks;\n"
    "layout(set = 0, binding = 4) uniform sampler2D u_height;\n"
    /* per block: its mesh's index count, first index, first vertex; then
     * per cell generated: its index x, z and pool slot (a workgroup row) */
    "layout(set = 0, binding = 5, std430) readonly buffer G { uvec4 g[]; } u_g;\n"
    "layout(push_constant, std430) uniform P {\n"
    "    uint nw, cap, nblocks; vec4 terrain; ivec2 hf;\n"
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
    "    uvec4 gc = u_g.g[u_p.nblocks + gl_WorkGroupID.y];\n"
    "    ivec2 cell = ivec2(gc.xy);\n"
    "    uint slot = gc.z, mask_base = slot * " SPLAT_STR(SPLAT_UG_TEXELS) "u * " SPLAT_STR(SPLAT_UG_TEXELS) "u * (u_p.nw + 2u);\n"
    "    vec2 origin = vec2(cell) * " SPLAT_STR(SPLAT_UG_CELL) ";\n"
    "    vec4 b0 = u_blocks.b[5u * b], b1 = u_blocks.b[5u * b + 1u], b2 = u_blocks.b[5u * b + 2u];\n"
    "    uint n = uint(b2.x), total = n * n, base = slot * u_p.cap + uint(b2.y);\n"
    "    uint ms = uint(b1.w);\n"
    "    float keep = b0.x * " "256.0" " / float(total);\n"
    "    float step = 16.0 / float(n);\n"
    "    uint seed0 = hash(uint(cell.x) * 73856093u ^ uint(cell.y) * 19349663u ^ b * 83492791u);\n"
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
    "            uint at = mask_base + uint(tx.y * 64 + tx.x) * (u_p.nw + 2u);\n"
    "            float w = unpackUnorm4x8(u_mask.w[at + ms / 4u])[ms % 4u];\n"
    "            ok = rnd(s) < w * keep;\n"
    "            vec3 nrm = unpackSnorm4x8(u_mask.w[at + u_p.nw]).xyz;\n"
    "            vec3 alb = unpackUnorm4x8(u_mask.w[at + u_p.nw + 1u]).rgb;\n"
    "            vec2 xz = origin + l;\n"
    "            float sc = mix(b0.y, b0.z, rnd(s));\n"
    "            float ang = rnd(s) * 6.2831853;\n"
    "            it.p = vec4(xz.x, height_at(xz), xz.y, sc);\n"
    "            it.q = uvec4(packSnorm4x8(vec4(nrm, 0.0)), packUnorm4x8(vec4(alb, 1.0)),\n"
    "                         floatBitsToUint(ang), b);\n"
    "        }\n"
    "        s_scan[lid] = ok ? 1u : 0u;\n"
    SCAN64
    "        if (ok) u_inst.v[base + run + s_scan[lid] - 1u] = it;\n"
    "        run += s_scan[63];\n"
    "        barrier();\n"
    "    }\n"
    /* the block's indexed indirect draw over the cell's instances */
    "    if (lid == 0u) {\n"
    "        uvec4 m = u_g.g[b];\n"
    "        uint a = (slot * u_p.nblocks + b) * 5u;\n"
    "        u_args.a[a] = m.x; u_args.a[a + 1u] = run; u_args.a[a + 2u] = m.y;\n"
    "        u_args.a[a + 3u] = m.z; u_args.a[a + 4u] = base;\n"
    "    }\n"
    "}\n";

/* The LOD pass, every frame: each cell's draw arguments from the
 * generated ones, its instance count times its fraction (a prefix: the
 * scatter pass keeps instances in a lattice order that spreads every
 * prefix).  The cull passes read the count and the first instance (and
 * the probe does); the mesh is the cull's key's (undergrowth.c
 * fill_entries). */
const char rt_ug_lod_glsl[] =
    "#version 450\n"
    "layout(local_size_x = 64) in;\n"
    "layout(set = 0, binding = 0, std430) readonly buffer A { uint a[]; } u_args;\n"
    "layout(set = 0, binding = 1, std430) writeonly buffer D { uint a[]; } u_draw;\n"
    "layout(set = 0, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"
    "layout(push_constant, std430) uniform P { uint n, nblocks, qidx, qvtx; } u_p;\n"
    "void main() {\n"
    "    uint i = gl_GlobalInvocationID.x;\n"
    "    if (i >= u_p.n) return;\n"
    "    for (uint k = 0u; k < 5u; k++) u_draw.a[5u * i + k] = u_args.a[5u * i + k];\n"
    "    float f = u_lod.f[i / u_p.nblocks];\n"
    "    u_draw.a[5u * i + 1u] = uint(ceil(float(u_args.a[5u * i + 1u]) * f));\n"
    "}\n";

/* UG_GLSL_FUNCS, the vertex stage's fade and wind: undergrowth_impl.h. */

/* The cull passes, every frame after the LOD pass (undergrowth.c "cull"):
 * one workgroup per entry (a visible cell's block, in the draw's order:
 * by key (block, LOD), cells front to back within a key); an instance of
 * the LOD's prefix is drawn when the fade leaves it a size (the vertex
 * stage's ug_fade_scale > 0) and its bounding sphere is inside the five
 * planes of the frustum (camera-relative, normalised: left, right, top,
 * bottom, near).  The sphere: at the root, radius s (grow r + sway s r^2)
 * + 5 cm, r the block's farthest vertex (or contact shadow) from the root
 * at scale 1 (block vec4 4 .w), s the instance's scale, grow the cell's
 * LOD widening: the vertex stage's sway moves a vertex h up by at most
 * sway h^2.  The count pass writes each entry's survivors, the scan pass
 * (one workgroup) their exclusive prefix and every key's indirect draw,
 * the write pass the survivors' instance indices at the prefix, in
 * instance order within an entry: the list is the same on every run. */
const char rt_ug_cull_glsl[] =
    "layout(local_size_x = 64) in;\n"
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 0, binding = 0, std430) readonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 0, binding = 1, std430) readonly buffer A { uint a[]; } u_draw;\n"
    "layout(set = 0, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"
    "layout(set = 0, binding = 3, std430) readonly buffer B { vec4 b[]; } u_blocks;\n"
    "layout(set = 0, binding = 4, std430) readonly buffer E { uint e[]; } u_ent;\n"
    "layout(set = 0, binding = 5, std430) buffer C { uint c[]; } u_cnt;\n"
    "layout(set = 0, binding = 6, std430) writeonly buffer V { uint v[]; } u_vis;\n"
    /* plane[5]; cam: the camera, the radius; info: blocks, entries */
    "layout(push_constant, std430) uniform P { vec4 plane[5]; vec4 cam; uvec4 info; } u_p;\n"
    UG_GLSL_FUNCS
    "shared uint s_scan[64];\n"
    "bool ug_keep(uint i, float grow) {\n"
    "    Inst it = u_inst.v[i];\n"
    "    float d = length(it.p.xz - u_p.cam.xz);\n"
    "    if (!(ug_fade_scale(it.p.xyz, d, u_p.cam.w) > 0.0)) return false;\n"
    "    uint bi = 5u * it.q.w;\n"
    "    float sway = u_blocks.b[bi + 3u].z, h = it.p.w * u_blocks.b[bi + 4u].w;\n"
    "    float rad = h * grow + sway * h * h + 0.05;\n"
    "    vec3 c = it.p.xyz - u_p.cam.xyz;\n"
    "    for (int k = 0; k < 5; k++)\n"
    "        if (dot(u_p.plane[k].xyz, c) + u_p.plane[k].w < -rad) return false;\n"
    "    return true;\n"
    "}\n"
    "void main() {\n"
    "    uint g = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;\n"
    "    uint lid = gl_LocalInvocationID.x, nent = u_p.info.y;\n"
    "    if (g >= nent) return;\n"
    "    uint idx = u_ent.e[" UG_ENT0_S " + g];\n"
    "    uint n = u_draw.a[5u * idx + 1u], first = u_draw.a[5u * idx + 4u];\n"
    "    float grow = clamp(inversesqrt(u_lod.f[idx / u_p.info.x]), 1.0, " LOD_GROW_S ");\n"
    "#ifdef UG_WRITE\n"
    "    uint at = u_cnt.c[nent + g];\n"
    "#endif\n"
    "    uint run = 0u;\n"
    "    for (uint c0 = 0u; c0 < n; c0 += 64u) {\n"
    "        uint k = c0 + lid;\n"
    "        bool ok = k < n && ug_keep(first + k, grow);\n"
    "        s_scan[lid] = ok ? 1u : 0u;\n"
    SCAN64
    "#ifdef UG_WRITE\n"
    "        if (ok) u_vis.v[at + run + s_scan[lid] - 1u] = first + k;\n"
    "#endif\n"
    "        run += s_scan[63];\n"
    "        barrier();\n"
    "    }\n"
    "#ifndef UG_WRITE\n"
    "    if (lid == 0u) u_cnt.c[g] = run;\n"
    "#endif\n"
    "}\n";

/* The scan pass (one workgroup of UG_LS invocations, a power of two):
 * the entries' counts into exclusive offsets after them (c[n + i], the
 * total at c[2n]), then per key its draw (indexed indirect: the mesh's
 * index count, first index and vertex offset from the key table, the
 * instances of its entries, the first at its first entry's offset) and
 * its contact shadows' after the nkeys draws: the instances of its
 * entries before the key table's shadow end (undergrowth.c fill_entries:
 * the first entry too far for a shadow to show, its first entry where
 * the block casts none); and per key the compute rasteriser's indirect
 * dispatch (undergrowth_craster.c), 64 threads a group. */
const char rt_ug_scan_glsl[] =
    "layout(local_size_x = UG_LS) in;\n"
    "layout(set = 0, binding = 0, std430) readonly buffer E { uint e[]; } u_ent;\n"
    "layout(set = 0, binding = 1, std430) coherent buffer C { uint c[]; } u_cnt;\n"
    "layout(set = 0, binding = 2, std430) writeonly buffer D { uint a[]; } u_md;\n"
    "layout(set = 0, binding = 3, std430) writeonly buffer DS { uint a[]; } u_ds;\n"
    "layout(push_constant, std430) uniform P { uint n, nkeys, qidx, qvtx; } u_p;\n"
    "shared uint s_sum[UG_LS];\n"
    "void main() {\n"
    "    uint lid = gl_LocalInvocationID.x, n = u_p.n;\n"
    "    uint ch = (n + uint(UG_LS) - 1u) / uint(UG_LS), a = min(lid * ch, n), b = min(a + ch, n);\n"
    "    uint sum = 0u;\n"
    "    for (uint i = a; i < b; i++) sum += u_cnt.c[i];\n"
    "    s_sum[lid] = sum;\n"
    "    barrier();\n"
    "    for (uint o = 1u; o < uint(UG_LS); o <<= 1u) {\n"
    "        uint v = lid >= o ? s_sum[lid - o] : 0u;\n"
    "        barrier();\n"
    "        s_sum[lid] += v;\n"
    "        barrier();\n"
    "    }\n"
    "    uint base = s_sum[lid] - sum;\n"
    "    for (uint i = a; i < b; i++) { uint c = u_cnt.c[i]; u_cnt.c[n + i] = base; base += c; }\n"
    "    if (lid == uint(UG_LS) - 1u) u_cnt.c[2u * n] = s_sum[lid];\n"
    "    memoryBarrierBuffer();\n"
    "    barrier();\n"
    "    for (uint k = lid; k < u_p.nkeys; k += uint(UG_LS)) {\n"
    "        uint e0 = u_ent.e[k], e1 = u_ent.e[k + 1u];\n"
    "        uint f = u_cnt.c[n + e0], cnt = u_cnt.c[n + e1] - f;\n"
    "        uint ki = " UG_KEYINFO_S " + 4u * k;\n"
    "        u_md.a[5u * k] = u_ent.e[ki];\n"
    "        u_md.a[5u * k + 1u] = cnt;\n"
    "        u_md.a[5u * k + 2u] = u_ent.e[ki + 1u];\n"
    "        u_md.a[5u * k + 3u] = u_ent.e[ki + 2u];\n"
    "        u_md.a[5u * k + 4u] = f;\n"
    "        uint s = 5u * (u_p.nkeys + k);\n"
    "        u_md.a[s] = 6u;\n"
    "        u_md.a[s + 1u] = u_cnt.c[n + max(u_ent.e[ki + 3u], e0)] - f;\n"
    "        u_md.a[s + 2u] = u_p.qidx;\n"
    "        u_md.a[s + 3u] = u_p.qvtx;\n"
    "        u_md.a[s + 4u] = f;\n"
    /* the compute rasteriser's dispatch: a thread per instance and triangle */
    "        u_ds.a[3u * k] = (cnt * (u_ent.e[ki] / 3u) + 63u) / 64u;\n"
    "        u_ds.a[3u * k + 1u] = 1u;\n"
    "        u_ds.a[3u * k + 2u] = 1u;\n"
    /* and its contact shadows': a thread per instance */
    "        u_ds.a[3u * (u_p.nkeys + k)] = (u_cnt.c[n + max(u_ent.e[ki + 3u], e0)] - f + 63u) / 64u;\n"
    "        u_ds.a[3u * (u_p.nkeys + k) + 1u] = 1u;\n"
    "        u_ds.a[3u * (u_p.nkeys + k) + 2u] = 1u;\n"
    "    }\n"
    "}\n";

/* The draw pass: SPLAT_GLSL_TERRAIN (frame block) + this vertex main; the
 * prelude + draw_frag_main as the fragment shader (it reads v_rel, v_uv,
 * v_local at locations 0-2, as the terrain's). */
const char rt_ug_draw_vert_main[] =
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 2, binding = 0, std430) readonly buffer B { vec4 b[]; } u_blocks;\n"
    "layout(set = 2, binding = 1, std430) readonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 2, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"
    "layout(set = 2, binding = 4, std430) readonly buffer V { uint i[]; } u_vis;\n"
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
    UG_GLSL_PLACE
    "void main() {\n"
    "    uint ii = u_vis.i[gl_InstanceIndex];   /* the cull passes' list */\n"
    "    UgP q = ug_place(ii, u_inst.v[ii], a_pos, a_nrm, a_uv);\n"
    "    v_local = q.local;\n"
    "    v_rel = v_local - u_frame.camera.xyz;\n"
    "    v_uv = v_local.xz / u_frame.terrain.xy;\n"
    "    g_far = q.far;\n"
    "    g_color = q.color;\n"
    "    g_normal = q.nrm;\n"
    "    g_tnormal = q.tnrm;\n"
    "    g_uv = a_uv;\n"
    "    g_flags = q.flags;\n"
    "    gl_Position = u_frame.view_proj * vec4(v_rel, 1.0);\n"
    "}\n";

const char rt_ug_draw_frag_main[] =
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
const char rt_ug_probe_glsl[] =
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
const char rt_ug_shadow_vert_main[] =
    "struct Inst { vec4 p; uvec4 q; };\n"
    "layout(set = 2, binding = 0, std430) readonly buffer B { vec4 b[]; } u_blocks;\n"
    "layout(set = 2, binding = 1, std430) readonly buffer I { Inst v[]; } u_inst;\n"
    "layout(set = 2, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"
    "layout(set = 2, binding = 4, std430) readonly buffer V { uint i[]; } u_vis;\n"
    "layout(location = 0) in vec3 a_pos;\n"
    "layout(location = 1) in vec3 a_nrm;   /* the vertex layout's; unused */\n"
    "layout(location = 2) in vec2 a_uv;\n"
    "out gl_PerVertex { vec4 gl_Position; };\n"
    "layout(location = 0) out vec2 s_q;\n"
    "layout(location = 1) out float s_a;\n"
    UG_GLSL_FUNCS
    UG_GLSL_SHADOW
    "void main() {\n"
    "    uint ii = u_vis.i[gl_InstanceIndex];   /* the cull passes' list */\n"
    "    Inst it = u_inst.v[ii];\n"
    "    UgS sq = ug_shadow_square(ii, it);\n"
    "    vec3 p = it.p.xyz + (sq.t * a_pos.x + sq.bt * a_pos.z) * sq.size + sq.n * 0.04;\n"
    "    s_q = a_uv * 2.0 - 1.0;\n"
    "    s_a = sq.a;\n"
    "    gl_Position = u_frame.view_proj * vec4(p - u_frame.camera.xyz, 1.0);\n"
    "}\n";

const char rt_ug_shadow_frag[] =
    "#version 450\n"
    "layout(early_fragment_tests) in;\n"
    "layout(location = 0) in vec2 s_q;\n"
    "layout(location = 1) in float s_a;\n"
    "layout(location = 0) out vec4 o_color;\n"
    "void main() {\n"
    "    float a = s_a * (1.0 - smoothstep(0.2, 1.0, dot(s_q, s_q)));\n"
    "    o_color = vec4(vec3(1.0 - a), 1.0);\n"
    "}\n";
