/* undergrowth_craster.c — undergrowth drawn in compute, not through the
 * graphics pipeline (issue 33: on the H100 the graphics front end paid
 * about 23 ns an instance whatever its size, and a blade past 14 m is a
 * few pixels).
 *
 * The cull passes give each block, for each of its mesh levels (near, far,
 * single triangles) that has at most 1 << UG_CR_TBITS triangles and is
 * opaque or cut out as a frond, a compute key: the cells whose distance
 * picks that level and whose every instance projects within UG_CR_CAP
 * pixels a side (rt_ug_craster_fits: the cull's own bounding sphere, which
 * holds the contact shadow too, at the cell's nearest point, seen at the
 * corner of the view).  Those keys are not drawn; after the graphics
 * draw, compute passes over their instances (the cull's list, an indirect dispatch the scan pass writes;
 * the per-pixel buffers filled once, then left clear by the resolve):
 *   1. depth: a thread per instance and triangle; the triangle's pixels
 *      (centres inside its edges, its bounding box clipped to the cap: a
 *      blade beyond it is counted in the stats' overflow, which the tests
 *      hold at 0; a frond's pixels also inside the fragment stage's
 *      outline, by perspective-correct uv) whose depth passes the depth
 *      attachment's (the terrain's and the graphics blades', reversed Z:
 *      greater is nearer) atomicMax their depth, as a uint (positive
 *      floats order as their bits), into a per-pixel buffer;
 *   2. id: the same pixels whose depth equals the buffer's atomicMin a
 *      payload, the list position << UG_CR_PSHIFT | the mesh level <<
 *      UG_CR_TBITS | the triangle: the nearest blade per pixel, ties to
 *      the lowest payload (the same on every run, whatever the order the
 *      threads ran in);
 *   after them, the contact shadows (ug_shadow): a thread per instance
 *      that casts one, its quad's pixels nearer than the depth attachment
 *      and the compute blades' depth add -log2(1 - a) in fixed point to a
 *      third per-pixel buffer;
 *   3. resolve, a thread per pixel: where a payload landed, the blade's
 *      three vertices again (the vertex stage's own transform: fade,
 *      widening, wind, colour, ug_far), perspective-correct barycentrics
 *      at the pixel's centre, the fragment stage's shading (texture by
 *      analytic gradients, root darkening, splat_light), stored into the
 *      colour; elsewhere the colour; both times 2^-(the shadows' sum).
 * With 64-bit storage buffer atomics passes 1 and 2 are one: atomicMax of
 * depth << 32 | ~payload ($SPLAT_UG_ATOMICS=32: the two passes anyway).
 * The compute blades are not written into the depth attachment (nothing
 * after the undergrowth reads it).  Screen path only (the depth is
 * sampled there); rt_render_desc.undergrowth_compute (splatbench
 * ugcompute=1) turns it on. */
#include "undergrowth_impl.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Set 2 of the three passes (sets 0 and 1: the renderer's compute set 0
 * and its material set, for the prelude's frame block and splat_light). */
#define CR_GLSL_DECLS                                                                  \
    "struct Inst { vec4 p; uvec4 q; };\n"                                              \
    "layout(set = 2, binding = 0, std430) readonly buffer B { vec4 b[]; } u_blocks;\n" \
    "layout(set = 2, binding = 1, std430) readonly buffer I { Inst v[]; } u_inst;\n"   \
    "layout(set = 2, binding = 2, std430) readonly buffer F { float f[]; } u_lod;\n"   \
    "layout(set = 2, binding = 3, std430) readonly buffer V { uint i[]; } u_vis;\n"    \
    "layout(set = 2, binding = 4, std430) readonly buffer D { uint a[]; } u_md;\n"     \
    "layout(set = 2, binding = 5, std430) readonly buffer VB { float f[]; } u_vb;\n"   \
    "layout(set = 2, binding = 6, std430) readonly buffer IB { uint i[]; } u_ib;\n"    \
    "#ifdef UG_I64\n"                                                                  \
    "layout(set = 2, binding = 7, std430) coherent buffer Z { uint64_t z[]; } u_z;\n"  \
    "#else\n"                                                                          \
    "layout(set = 2, binding = 7, std430) coherent buffer Z { uint z[]; } u_z;\n"      \
    "#endif\n"                                                                         \
    "layout(set = 2, binding = 8, std430) coherent buffer ID { uint i[]; } u_id;\n"    \
    "layout(set = 2, binding = 9) uniform sampler2D u_zs;\n"                            \
    "layout(set = 2, binding = 10) uniform sampler2D u_ugtex[" SPLAT_STR(SPLAT_MAX_UG_TEXTURES) "];\n" \
    "layout(set = 2, binding = 11, std430) readonly buffer T { uvec4 t[]; } u_tri;\n"  \
    "layout(set = 2, binding = 12, std430) buffer S { uint s[]; } u_stat;\n"                 \
    "layout(set = 2, binding = 13, std430) coherent buffer SH { uint s[]; } u_sh;\n"

/* The raster passes need no more of set 0 than the frame block's first
 * two members (a block may be shorter than its buffer), so they are
 * compiled without the prelude, 64 invocations in a row. */
#define CR_GLSL_RASTER_DECLS                                                           \
    "layout(local_size_x = 64) in;\n"                                                  \
    "layout(set = 0, binding = 1, std140) uniform splat_frame_block {\n"               \
    "    mat4 view_proj;\n"                                                            \
    "    vec4 camera;\n"                                                               \
    "} u_frame;\n"                                                                     \
    "layout(push_constant, std430) uniform splat_push_block {\n"                       \
    "    vec4 patch_xz;\n"                                                             \
    "    vec4 patch_uv;\n"                                                             \
    "    uvec4 info;\n"                                                                \
    "} u_push;\n"

/* u_push: patch_xz (radius, time, width, height), patch_uv (the keys'
 * count: where the shadows' draws start; the cap), info (instances per cell, key,
 * the key's mesh level, the pass: 0 depth, 1 id, 3 the contact shadows).
 * u_tri: per block and level its mesh (index
 * count, first index, vertex offset). */
static const char cr_glsl_main[] =
    UG_GLSL_FUNCS
    UG_GLSL_PLACE
    UG_GLSL_SHADOW
    "struct UgV { vec4 clip; vec3 rel; vec3 color; vec3 nrm; vec3 tnrm; vec2 uv; float far; uint flags; };\n"
    /* the vertex stage's transform (undergrowth_glsl.c rt_ug_draw_vert_main) */
    "UgV ug_vertex(uint ii, Inst it, uint vi) {\n"
    "    vec3 a_pos = vec3(u_vb.f[8u * vi], u_vb.f[8u * vi + 1u], u_vb.f[8u * vi + 2u]);\n"
    "    vec3 a_nrm = vec3(u_vb.f[8u * vi + 3u], u_vb.f[8u * vi + 4u], u_vb.f[8u * vi + 5u]);\n"
    "    vec2 a_uv = vec2(u_vb.f[8u * vi + 6u], u_vb.f[8u * vi + 7u]);\n"
    "    UgP q = ug_place(ii, it, a_pos, a_nrm, a_uv);\n"
    "    UgV o;\n"
    "    o.rel = q.local - u_frame.camera.xyz;\n"
    "    o.far = q.far;\n"
    "    o.color = q.color;\n"
    "    o.nrm = q.nrm;\n"
    "    o.tnrm = q.tnrm;\n"
    "    o.uv = a_uv;\n"
    "    o.flags = q.flags;\n"
    "    o.clip = u_frame.view_proj * vec4(o.rel, 1.0);\n"
    "    return o;\n"
    "}\n"
    /* triangle t of list position j, its mesh at level lv: its three vertices */
    /* three variables, no array: nothing indexed at run time */
    "void ug_tri(uint j, uint lv, uint t, out UgV v0, out UgV v1, out UgV v2) {\n"
    "    uint ii = u_vis.i[j];\n"
    "    Inst it = u_inst.v[ii];\n"
    "    uvec4 tm = u_tri.t[" SPLAT_STR(UG_LEVELS) "u * it.q.w + lv];   /* index count, first index, vertex offset */\n"
    "    uint i0 = tm.y + 3u * t;\n"
    "    v0 = ug_vertex(ii, it, u_ib.i[i0] + tm.z);\n"
    "    v1 = ug_vertex(ii, it, u_ib.i[i0 + 1u] + tm.z);\n"
    "    v2 = ug_vertex(ii, it, u_ib.i[i0 + 2u] + tm.z);\n"
    "}\n"
    "vec2 ug_screen(vec4 c) { return (c.xy / c.w * 0.5 + 0.5) * u_push.patch_xz.zw; }\n"
    "float ug_edge(vec2 a, vec2 b, vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }\n"
    "#ifndef UG_RESOLVE\n"
    /* A compute key's contact shadows (the graphics path's shadow quad and
     * fragment stage, rt_ug_shadow_vert_main): a thread per instance of
     * the key's entries that cast one, its quad's pixel centres (inside
     * its first triangle, else its second: none counted twice) nearer
     * than the depth attachment (the terrain's, and the graphics blades'
     * in front of it) and than the compute blades (their depth pass has
     * finished) add -log2(1 - a) in fixed point to the pixel's sum; the
     * resolve multiplies the pixel's colour by 2^-sum: the draw's shadows,
     * drawn after its plants, hide behind them alike.  The same product
     * as the blending's, in any order. */
    "void ug_shadow(uint g) {\n"
    "    uint k = u_push.info.y, s = 5u * (uint(u_push.patch_uv.x) + k);\n"
    "    uint cnt = u_md.a[s + 1u], first = u_md.a[s + 4u];\n"
    "    if (g >= cnt) return;\n"
    "    uint ii = u_vis.i[first + g];\n"
    "    Inst it = u_inst.v[ii];\n"
    "    UgS sq = ug_shadow_square(ii, it);\n"
    "    float size = sq.size, sa = sq.a;\n"
    "    if (!(size > 0.0) || !(sa > 0.0)) return;\n"
    "    vec3 n = sq.n, t = sq.t, bt = sq.bt;\n"
    "    vec3 o = it.p.xyz + n * 0.04;\n"
    "    vec4 c0 = u_frame.view_proj * vec4(o + (-t - bt) * size - u_frame.camera.xyz, 1.0);\n"
    "    vec4 c1 = u_frame.view_proj * vec4(o + (t - bt) * size - u_frame.camera.xyz, 1.0);\n"
    "    vec4 c2 = u_frame.view_proj * vec4(o + (t + bt) * size - u_frame.camera.xyz, 1.0);\n"
    "    vec4 c3 = u_frame.view_proj * vec4(o + (-t + bt) * size - u_frame.camera.xyz, 1.0);\n"
    "    if (min(min(c0.w, c1.w), min(c2.w, c3.w)) <= 1e-4) return;\n"
    "    vec2 s0 = ug_screen(c0), s1 = ug_screen(c1), s2 = ug_screen(c2), s3 = ug_screen(c3);\n"
    "    vec4 z = vec4(c0.z / c0.w, c1.z / c1.w, c2.z / c2.w, c3.z / c3.w);\n"
    "    vec4 iw = 1.0 / vec4(c0.w, c1.w, c2.w, c3.w);\n"
    "    float aa = ug_edge(s0, s1, s2), ab = ug_edge(s0, s2, s3);\n"
    "    if (abs(aa) < 1e-12 || abs(ab) < 1e-12) return;\n"
    "    vec2 lo = min(min(s0, s1), min(s2, s3)), hi = max(max(s0, s1), max(s2, s3));\n"
    "    ivec2 size2 = ivec2(u_push.patch_xz.zw);\n"
    "    ivec2 a = max(ivec2(ceil(lo - 0.5)), ivec2(0)), b = min(ivec2(floor(hi - 0.5)), size2 - 1);\n"
    "    if (any(greaterThan(b - a, ivec2(int(u_push.patch_uv.y) - 1)))) {\n"
    "        atomicAdd(u_stat.s[0], 1u);\n"
    "        b = min(b, a + int(u_push.patch_uv.y) - 1);\n"
    "    }\n"
    "    float ia = 1.0 / aa, ib = 1.0 / ab;\n"
    "    for (int y = a.y; y <= b.y; y++)\n"
    "        for (int x = a.x; x <= b.x; x++) {\n"
    "            vec2 p = vec2(x, y) + 0.5;\n"
    /* q: the quad's corner coordinates, (-1, -1) (1, -1) (1, 1) (-1, 1) */
    "            vec3 w = vec3(ug_edge(s1, s2, p), ug_edge(s2, s0, p), ug_edge(s0, s1, p)) * ia;\n"
    "            vec2 q;\n"
    "            float dz;\n"
    "            if (min(w.x, min(w.y, w.z)) >= 0.0) {\n"
    "                vec3 pw = w * iw.xyz;\n"
    "                q = mat3x2(vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0)) * (pw / (pw.x + pw.y + pw.z));\n"
    "                dz = dot(w, z.xyz);\n"
    "            } else {\n"
    "                w = vec3(ug_edge(s2, s3, p), ug_edge(s3, s0, p), ug_edge(s0, s2, p)) * ib;\n"
    "                if (min(w.x, min(w.y, w.z)) < 0.0) continue;\n"
    "                vec3 pw = w * iw.xzw;\n"
    "                q = mat3x2(vec2(-1.0, -1.0), vec2(1.0, 1.0), vec2(-1.0, 1.0)) * (pw / (pw.x + pw.y + pw.z));\n"
    "                dz = dot(w, z.xzw);\n"
    "            }\n"
    "            uint at = uint(y) * uint(size2.x) + uint(x);\n"
    "#ifdef UG_I64\n"
    "            float bz = uintBitsToFloat(uint(u_z.z[at] >> 32));\n"
    "#else\n"
    "            float bz = uintBitsToFloat(u_z.z[at]);\n"
    "#endif\n"
    "            if (!(dz > max(texelFetch(u_zs, ivec2(x, y), 0).r, bz)) || dz > 1.0) continue;\n"
    "            float sh = sa * (1.0 - smoothstep(0.2, 1.0, dot(q, q)));\n"
    "            if (sh > 0.0)\n"
    "                atomicAdd(u_sh.s[at], uint(-log2(1.0 - sh) * 262144.0 + 0.5));\n"
    "        }\n"
    "}\n"
    "void main() {\n"
    "    uint g = gl_WorkGroupID.x * 64u + gl_LocalInvocationIndex;\n"

    "    if (u_push.info.w == 3u) {   /* the contact shadows */\n"
    "        ug_shadow(g);\n"
    "        return;\n"
    "    }\n"
    "    uint k = u_push.info.y, lv = u_push.info.z, nt = u_md.a[5u * k] / 3u;\n"
    "    uint cnt = u_md.a[5u * k + 1u], first = u_md.a[5u * k + 4u];\n"
    "    if (g >= cnt * nt) return;\n"
    "    uint j = first + g / nt, t = g % nt;\n"
    "    UgV v0, v1, v2;\n"
    "    ug_tri(j, lv, t, v0, v1, v2);\n"
    "    if (min(v0.clip.w, min(v1.clip.w, v2.clip.w)) <= 1e-4) return;\n"
    "    vec2 s0 = ug_screen(v0.clip), s1 = ug_screen(v1.clip), s2 = ug_screen(v2.clip);\n"
    "    vec3 z = vec3(v0.clip.z / v0.clip.w, v1.clip.z / v1.clip.w, v2.clip.z / v2.clip.w);\n"
    "    float area = ug_edge(s0, s1, s2);\n"
    "    if (abs(area) < 1e-12) return;\n"
    "    vec2 lo = min(s0, min(s1, s2)), hi = max(s0, max(s1, s2));\n"
    "    ivec2 size = ivec2(u_push.patch_xz.zw);\n"
    "    ivec2 a = max(ivec2(ceil(lo - 0.5)), ivec2(0)), b = min(ivec2(floor(hi - 0.5)), size - 1);\n"
    "    if (any(greaterThan(b - a, ivec2(int(u_push.patch_uv.y) - 1)))) {\n"
    "        if (u_push.info.w == 0u) atomicAdd(u_stat.s[0], 1u);\n"
    "        b = min(b, a + int(u_push.patch_uv.y) - 1);\n"
    "    }\n"
    "    float ia = 1.0 / area;\n"
    "    uint payload = (j << " SPLAT_STR(UG_CR_PSHIFT) ") | (lv << " SPLAT_STR(UG_CR_TBITS) ") | t;\n"
    /* a frond (a block cut out by its uv, the fragment stage's test) */
    "    bool frond = (v0.flags & 1u) != 0u;\n"
    "    vec3 iw = vec3(1.0 / v0.clip.w, 1.0 / v1.clip.w, 1.0 / v2.clip.w);\n"
    "    for (int y = a.y; y <= b.y; y++)\n"
    "        for (int x = a.x; x <= b.x; x++) {\n"
    "            vec2 p = vec2(x, y) + 0.5;\n"
    "            vec3 w = vec3(ug_edge(s1, s2, p), ug_edge(s2, s0, p), ug_edge(s0, s1, p)) * ia;\n"
    "            if (min(w.x, min(w.y, w.z)) < 0.0) continue;\n"
    "            float d = dot(w, z);\n"
    "            if (!(d > texelFetch(u_zs, ivec2(x, y), 0).r) || d > 1.0) continue;\n"
    "            if (frond) {\n"
    "                vec3 pw = w * iw;\n"
    "                vec2 uv = mat3x2(v0.uv, v1.uv, v2.uv) * (pw / (pw.x + pw.y + pw.z));\n"
    "                float fx = abs(uv.x * 2.0 - 1.0), ft = clamp(uv.y, 0.0, 1.0);\n"
    "                if (fx > 0.9 * sin(ft * 3.14159) || (fx > 0.08 && fract(ft * 7.0 - fx * 2.5) > 0.6)) continue;\n"
    "            }\n"
    "            uint at = uint(y) * uint(size.x) + uint(x), du = floatBitsToUint(d);\n"
    /* one pipeline for both passes (u_push.info.w), so that the id pass
     * computes the very depth the depth pass stored */
    "#ifdef UG_I64\n"   /* one pass: depth above, the lowest payload wins a tie */
    "            atomicMax(u_z.z[at], (uint64_t(du) << 32) | uint64_t(~payload));\n"
    "#else\n"
    "            if (u_push.info.w == 0u) atomicMax(u_z.z[at], du);\n"
    "            else if (u_z.z[at] == du) atomicMin(u_id.i[at], payload);\n"
    "#endif\n"
    "        }\n"
    "}\n"
    "#else\n"
    /* the fragment stage's texture lookup (rt_ug_draw_frag_main), by gradients */
    "vec4 ug_texture(uint t, vec2 uv, vec2 dx, vec2 dy) {\n"
    "    switch (t) {\n"
    "    case 1u: return textureGrad(u_ugtex[0], uv, dx, dy);\n"
    "    case 2u: return textureGrad(u_ugtex[1], uv, dx, dy);\n"
    "    case 3u: return textureGrad(u_ugtex[2], uv, dx, dy);\n"
    "    case 4u: return textureGrad(u_ugtex[3], uv, dx, dy);\n"
    "    case 5u: return textureGrad(u_ugtex[4], uv, dx, dy);\n"
    "    case 6u: return textureGrad(u_ugtex[5], uv, dx, dy);\n"
    "    case 7u: return textureGrad(u_ugtex[6], uv, dx, dy);\n"
    "    case 8u: return textureGrad(u_ugtex[7], uv, dx, dy);\n"
    "    }\n"
    "    return vec4(1.0);\n"
    "}\n"
    /* perspective-correct barycentrics at screen point p */
    "vec3 ug_bary(vec2 s0, vec2 s1, vec2 s2, vec3 iw, float ia, vec2 p) {\n"
    "    vec3 w = vec3(ug_edge(s1, s2, p), ug_edge(s2, s0, p), ug_edge(s0, s1, p)) * ia * iw;\n"
    "    return w / (w.x + w.y + w.z);\n"
    "}\n"
    "void main() {\n"
    "    ivec2 px = ivec2(gl_GlobalInvocationID.xy), size = ivec2(u_push.patch_xz.zw);\n"
    "    if (any(greaterThanEqual(px, size))) return;\n"
    "    uint at = uint(px.y) * uint(size.x) + uint(px.x);\n"
    "#ifdef UG_I64\n"
    "    uint64_t zv = u_z.z[at];\n"
    "    bool hit = zv != uint64_t(0);\n"
    "    uint id = ~uint(zv & uint64_t(0xffffffffu));\n"
    "#else\n"
    "    uint id = u_id.i[at];\n"
    "    bool hit = id != 0xffffffffu;\n"
    "#endif\n"
    /* the buffers left clear for the next frame (no clear pass) */
    "    if (!hit) {   /* the compute keys' contact shadows on what is there */\n"
    "        uint sh = u_sh.s[at];\n"
    "        if (sh != 0u) {\n"
    "            u_sh.s[at] = 0u;\n"
    "            vec4 c = imageLoad(u_out, px);\n"
    "            imageStore(u_out, px, vec4(c.rgb * exp2(-float(sh) * (1.0 / 262144.0)), c.a));\n"
    "        }\n"
    "        return;\n"
    "    }\n"
    "    float shade = exp2(-float(u_sh.s[at]) * (1.0 / 262144.0));\n"
    "    u_sh.s[at] = 0u;\n"
    "#ifdef UG_I64\n"
    "    u_z.z[at] = uint64_t(0);\n"
    "#else\n"
    "    u_z.z[at] = 0u;\n"
    "    u_id.i[at] = 0xffffffffu;\n"
    "#endif\n"
    "    UgV v0, v1, v2;\n"
    "    ug_tri(id >> " SPLAT_STR(UG_CR_PSHIFT) ", (id >> " SPLAT_STR(UG_CR_TBITS) ") & ((1u << " SPLAT_STR(UG_CR_PSHIFT) "u - " SPLAT_STR(UG_CR_TBITS) "u) - 1u), id & ((1u << " SPLAT_STR(UG_CR_TBITS) "u) - 1u), v0, v1, v2);\n"
    "    vec2 s0 = ug_screen(v0.clip), s1 = ug_screen(v1.clip), s2 = ug_screen(v2.clip);\n"
    "    float area = ug_edge(s0, s1, s2), ia = 1.0 / area;\n"
    "    vec3 iw = vec3(1.0 / v0.clip.w, 1.0 / v1.clip.w, 1.0 / v2.clip.w);\n"
    "    vec2 p = vec2(px) + 0.5;\n"
    "    vec3 w = ug_bary(s0, s1, s2, iw, ia, p);\n"
    "    vec3 wx = ug_bary(s0, s1, s2, iw, ia, p + vec2(1.0, 0.0));\n"
    "    vec3 wy = ug_bary(s0, s1, s2, iw, ia, p + vec2(0.0, 1.0));\n"
    "    mat3x2 uvs = mat3x2(v0.uv, v1.uv, v2.uv);\n"
    "    vec2 uv = uvs * w;\n"
    "    vec2 dx = uvs * wx - uv, dy = uvs * wy - uv;\n"
    /* a sliver's neighbours extrapolate wildly: at most the whole texture
     * a pixel (its coarsest mip, as the hardware's quads reach there) */
    "    dx = all(lessThan(abs(dx), vec2(1.0))) ? dx : vec2(1.0, 0.0);\n"
    "    dy = all(lessThan(abs(dy), vec2(1.0))) ? dy : vec2(0.0, 1.0);\n"
    "    vec3 rel = mat3(v0.rel, v1.rel, v2.rel) * w;\n"
    "    vec3 color = mat3(v0.color, v1.color, v2.color) * w;\n"
    "    vec3 gn = mat3(v0.nrm, v1.nrm, v2.nrm) * w;\n"
    "    vec3 tn = mat3(v0.tnrm, v1.tnrm, v2.tnrm) * w;\n"
    "    float far = dot(vec3(v0.far, v1.far, v2.far), w);\n"
    "    uint flags = v0.flags;\n"
    "    vec4 tex = ug_texture(flags >> 8, vec2(uv.x, 1.0 - uv.y), vec2(dx.x, -dx.y), vec2(dy.x, -dy.y));\n"
    "    float dist = length(rel);\n"
    "    vec3 vv = dist > 0.0 ? -rel / dist : vec3(0.0, 1.0, 0.0);\n"
    "    vec3 n = normalize(gn);\n"
    /* front facing: counter-clockwise in framebuffer coordinates (y down)
     * is a negative edge area (the draw pipeline's front face) */
    "    if ((flags & 2u) == 0u && !(area < 0.0)) n = -n;\n"
    "    n = normalize(mix(n, normalize(tn), far));\n"
    "    float ao = mix(mix(0.5, 1.0, clamp(uv.y, 0.0, 1.0)), 1.0, far);\n"
    "    imageStore(u_out, px, vec4(splat_light(color * tex.rgb * ao, n, 0.9, dist, vv) * shade, 1.0));\n"
    "}\n"
    "#endif\n";

_Static_assert(SPLAT_BIND_OUT == 8, "the resolve's u_out binding");

bool rt_ug_craster_create(rt_ug *u, rt_error *e)
{
    if (!u->compute)
        return true;
    rt_device *d = u->d;
    /* one pass with 64-bit atomics where the device has them
     * ($SPLAT_UG_ATOMICS=32: the two-pass fallback, for the tests) */
    const char *env = getenv("SPLAT_UG_ATOMICS");
    u->cr64 = d->int64_atomics && !(env && !strcmp(env, "32"));
    /* the cap a cell's instances must fit (pixels a side): UG_CR_CAP, or
     * $SPLAT_UG_CAP from 8 to UG_CR_CAP_MAX (the H100's A/B of the cap: a
     * larger one takes nearer cells, whose triangles loop over more pixels
     * in one thread) */
    const char *cap = getenv("SPLAT_UG_CAP");
    u->cr_cap = cap && atoi(cap) >= 8 && atoi(cap) <= UG_CR_CAP_MAX ? atoi(cap) : UG_CR_CAP;
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType sb = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    const VkDescriptorType cis = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    VkDescriptorSetLayoutBinding b[14];
    for (uint32_t i = 0; i < 14; i++)
        b[i] = (VkDescriptorSetLayoutBinding){ i, sb, 1, cs, NULL };
    b[9].descriptorType = cis;
    b[10].descriptorType = cis;
    b[10].descriptorCount = SPLAT_MAX_UG_TEXTURES;
    size_t npx = (size_t)u->width * (size_t)u->height_px;
    const VkBufferUsageFlags st = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    if (!rt_vk_set_layout(d, &u->keep, &(rt_vk_set_layout_desc){ "undergrowth compute raster", b, 14 },
                          &u->set_cr, e))
        return false;
    VkDescriptorSetLayout sets[3] = { u->pl->set_terrain, u->pl->set_material, u->set_cr };
    if (!rt_vk_layout(d, &u->keep, &(rt_vk_layout_desc){ .label = "undergrowth compute raster",
                          .sets = sets, .nsets = 3, .push_stages = cs,
                          .push_bytes = sizeof(splat_push) }, &u->cr_layout, e) ||
        !rt_buffer_create(d, npx * (u->cr64 ? 8 : 4), st | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false,
                          &u->zbuf, e) ||
        !rt_buffer_create(d, npx * 4, st | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, &u->idbuf, e) ||
        !rt_buffer_create(d, npx * 4, st | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, &u->shbuf, e) ||
        !rt_buffer_create(d, (VkDeviceSize)SPLAT_MAX_UG_BLOCKS * UG_LEVELS * 16, st, true, &u->crtab, e) ||
        !rt_buffer_create(d, 16, st | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          false, &u->crstat, e) ||
        !rt_buffer_create(d, 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, &u->crstat_host, e))
        return false;
    memset(u->crstat_host.map, 0, 16);
    uint32_t *tab = u->crtab.map;   /* the levels a block has (the others: zeros) */
    memset(tab, 0, (size_t)u->nblocks * UG_LEVELS * 16);
    for (int i = 0; i < u->nblocks; i++)
        for (int lv = 0; lv < UG_LEVELS; lv++)
            if ((lv == 0 || u->p->ug.meshes[u->p->ug.blocks[i].mesh].far >= 0) &&
                (lv < 2 || u->tri[i][0]))
                rt_ug_level_mesh(u, i, lv, tab + 4 * (UG_LEVELS * i + lv));
    VkDescriptorPoolSize sizes[2] = { { sb, 12 }, { cis, 1 + SPLAT_MAX_UG_TEXTURES } };
    VkDescriptorPool pool;
    if (!rt_vk_sets(d, &u->keep, &(rt_vk_sets_desc){ .label = "undergrowth compute raster",
                        .sizes = sizes, .nsizes = 2, .layouts = &u->set_cr, .nsets = 1 },
                    &pool, &u->cr_set, e))
        return false;
    VkDescriptorImageInfo ti[SPLAT_MAX_UG_TEXTURES];
    for (int i = 0; i < SPLAT_MAX_UG_TEXTURES; i++) {
        int k = i < u->p->ug.ntextures ? i : SPLAT_MAX_UG_TEXTURES;
        ti[i] = (VkDescriptorImageInfo){ u->tex_smp, u->tex[k].view,
                                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL };
    }
    rt_vk_write w[] = {
        { u->cr_set, 0, sb, u->blocks.buf }, { u->cr_set, 1, sb, u->inst.buf },
        { u->cr_set, 2, sb, u->lod.buf }, { u->cr_set, 3, sb, u->vis.buf },
        { u->cr_set, 4, sb, u->mdraw.buf }, { u->cr_set, 5, sb, u->vbuf.buf },
        { u->cr_set, 6, sb, u->ibuf.buf }, { u->cr_set, 7, sb, u->zbuf.buf },
        { u->cr_set, 8, sb, u->idbuf.buf },
        { u->cr_set, 9, cis, .sampler = u->cr_nearest, .view = u->depth->view },
        { u->cr_set, 10, cis, .images = ti, .count = SPLAT_MAX_UG_TEXTURES },
        { u->cr_set, 11, sb, u->crtab.buf }, { u->cr_set, 12, sb, u->crstat.buf },
        { u->cr_set, 13, sb, u->shbuf.buf },
    };
    rt_vk_write_sets(d, w, sizeof w / sizeof *w);
    size_t n = strlen(SPLAT_GLSL_TERRAIN) + strlen(SPLAT_GLSL_LIGHTING) + strlen(cr_glsl_main) +
               strlen(CR_GLSL_DECLS) + strlen(CR_GLSL_RASTER_DECLS) + 512;
    const char *i64 = u->cr64 ? "#extension GL_ARB_gpu_shader_int64 : require\n"
                                "#extension GL_EXT_shader_atomic_int64 : require\n"
                                "#define UG_I64 1\n" : "";
    char *src = malloc(n);
    if (!src)
        return rt_fail(e, RT_E_VULKAN, "undergrowth", "out of memory");
    bool ok = true;
    static const char *const defs[2] = { "", "#define UG_RESOLVE 1\n" };
    static const char *const labels[2] = { "undergrowth compute raster",
                                           "undergrowth compute raster resolve" };
    for (int k = 0; k < 2 && ok; k++) {
        /* the resolve: the frame block, splat_light and the colour, not the
         * whole prelude, whose own main would run this one as a composite
         * body on terrain pixels only (runtime/DESIGN.md) */
        snprintf(src, n, "#version 450\n%s%s%s%s%s%s%s", i64, defs[k],
                 k ? "layout(local_size_x = 8, local_size_y = 8) in;\n" : CR_GLSL_RASTER_DECLS,
                 k ? SPLAT_GLSL_TERRAIN : "", k ? SPLAT_GLSL_LIGHTING : "",
                 k ? "layout(set = 0, binding = 8, rgba32f) uniform image2D u_out;\n"
                   : "",
                 CR_GLSL_DECLS);
        strncat(src, cr_glsl_main, n - strlen(src) - 1);
        ok = rt_vk_compute(d, &u->keep, &(rt_vk_compute_desc){ .label = labels[k], .glsl = src,
                               .layout = u->cr_layout }, &u->cr_pipe[k], e);
    }
    free(src);
    return ok;
}

void rt_ug_craster_destroy(rt_ug *u)
{
    rt_buffer *bufs[] = { &u->zbuf, &u->idbuf, &u->shbuf, &u->crtab, &u->crstat, &u->crstat_host };
    for (size_t i = 0; i < sizeof bufs / sizeof *bufs; i++)
        rt_buffer_destroy(u->d, bufs[i]);
}

void rt_ug_craster_frame(rt_ug *u, const splat_frame *fr)
{
    const float *m = fr->view_proj;   /* column-major: row r is m[r], m[4 + r], m[8 + r] */
    double r0 = sqrt(m[0] * m[0] + m[4] * m[4] + m[8] * m[8]);
    double r1 = sqrt(m[1] * m[1] + m[5] * m[5] + m[9] * m[9]);
    double px = fmax(r0 * u->width * 0.5, r1 * u->height_px * 0.5);
    double c = r0 > 0 && r1 > 0 ? 1.0 / sqrt(1.0 + 1.0 / (r0 * r0) + 1.0 / (r1 * r1)) : 0.0;
    u->cr_proj[0] = (float)px;
    u->cr_proj[1] = (float)c;
}

bool rt_ug_craster_fits(const rt_ug *u, int b, double near, float f)
{
    if (!u->compute || u->cr_proj[1] <= 0)
        return false;
    const float *bl = (const float *)u->blocks.map + 4 * UG_BLOCK_VEC4 * b;
    double grow = f > 0 ? 1.0 / sqrt(f) : LOD_GROW;
    grow = grow < 1.0 ? 1.0 : grow > LOD_GROW ? LOD_GROW : grow;
    double h = bl[2] * bl[19];   /* the largest scale times the farthest vertex */
    double rad = h * grow + bl[14] * h * h + 0.05;
    double z = near * u->cr_proj[1] - rad;   /* the least view depth of the cell's spheres */
    /* the sphere's diameter in pixels, two pixels' margin for the rounding */
    return z > 0 && 2.0 * rad * u->cr_proj[0] / z <= u->cr_cap - 2;
}

void rt_ug_craster_record(rt_ug *u, VkCommandBuffer cb, VkDescriptorSet set0c, VkDescriptorSet set1)
{
    u->cr_ran = false;
    bool any = false;
    for (int k = 0; k < u->nkeys; k++)
        any |= u->key_used[k] && u->key_cs[k];
    if (!u->compute || !any)
        return;
    const VkPipelineStageFlags cs = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    vkCmdFillBuffer(cb, u->crstat.buf, 0, 16, 0);
    if (!u->cr_clear) {   /* once: the resolve leaves them clear after */
        vkCmdFillBuffer(cb, u->zbuf.buf, 0, VK_WHOLE_SIZE, 0);
        vkCmdFillBuffer(cb, u->idbuf.buf, 0, VK_WHOLE_SIZE, 0xffffffffu);
        vkCmdFillBuffer(cb, u->shbuf.buf, 0, VK_WHOLE_SIZE, 0);
        u->cr_clear = true;
    }
    /* the fills, and the cull passes' list and draws (their own barrier
     * reaches the graphics stages only) */
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | cs,
                   VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, cs,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    /* the draw's depth and colour writes before the passes read them; the
     * colour to GENERAL for the resolve's stores */
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT,
                   VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, cs, VK_ACCESS_SHADER_READ_BIT);
    rt_cmd_image_barrier(cb, u->color->img, 0, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         VK_IMAGE_LAYOUT_GENERAL, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, cs);
    VkDescriptorSet sets[3] = { set0c, set1, u->cr_set };
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->cr_layout, 0, 3, sets, 0, NULL);
    splat_push push = { .patch_xz = { (float)u->radius, (float)u->time, (float)u->width,
                                      (float)u->height_px },
                        .patch_uv = { 0, (float)u->cr_cap, 0, 0 },
                        .info = { u->cap, 0, 0, 0 } };
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->cr_pipe[0]);
    for (int pass = 0; pass < (u->cr64 ? 1 : 2); pass++) {
        push.info[3] = (uint32_t)pass;
        for (int k = 0; k < u->nkeys; k++) {
            if (!u->key_used[k] || !u->key_cs[k])
                continue;
            push.info[1] = (uint32_t)k;
            push.info[2] = u->key_level[k];
            vkCmdPushConstants(cb, u->cr_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
            vkCmdDispatchIndirect(cb, u->cdisp.buf, 12 * (VkDeviceSize)k);
        }
        rt_cmd_barrier(cb, cs, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT, cs,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    }
    /* the compute keys' contact shadows: their own buffer, on what is
     * nearest after the passes (hidden by a nearer blade, as the graphics
     * draw's shadows after its plants) */
    push.info[3] = 3;
    push.patch_uv[0] = (float)u->nkeys;
    bool shadows = false;
    for (int k = 0; k < u->nkeys; k++) {
        if (!u->key_used[k] || !u->key_shc[k])
            continue;
        push.info[1] = (uint32_t)k;
        vkCmdPushConstants(cb, u->cr_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatchIndirect(cb, u->cdisp.buf, 12 * (VkDeviceSize)(u->nkeys + k));
        shadows = true;
    }
    if (shadows)
        rt_cmd_barrier(cb, cs, VK_ACCESS_SHADER_WRITE_BIT, cs,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    if (u->qpool)   /* the raster and shadow passes' end (the stats) */
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, u->qpool, 5);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, u->cr_pipe[1]);
    push.info[3] = 1;
    vkCmdPushConstants(cb, u->cr_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(cb, ((uint32_t)u->width + 7) / 8, ((uint32_t)u->height_px + 7) / 8, 1);
    rt_cmd_image_barrier(cb, u->color->img, 0, 1, 1, VK_IMAGE_LAYOUT_GENERAL,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT,
                         VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT |
                             VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                         cs, VK_PIPELINE_STAGE_TRANSFER_BIT | cs | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT |
                                 VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT);
    /* the stats */
    rt_cmd_barrier(cb, cs, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy all = { 0, 0, 16 };
    vkCmdCopyBuffer(cb, u->crstat.buf, u->crstat_host.buf, 1, &all);
    rt_cmd_barrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    u->cr_ran = true;
}
