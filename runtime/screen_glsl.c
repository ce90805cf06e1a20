/* screen_glsl.c — the screen-space path's own compute shaders (screen.c
 * describes the path): the classification, pixel sorting's list pass and
 * the ray caster's depth. */
#include "screen_glsl.h"

/* The classification shader: SPLAT_GLSL_TERRAIN (frame block) + this. */
const char rt_screen_classify_glsl[] =
    "layout(set = 0, binding = 7) uniform sampler2D u_depth;\n"
    "layout(set = 2, binding = 0, std430) readonly buffer cls_info_block {\n"
    "    uint ncombos, words, cells_x, cells_z;\n"
    "    uint ntiles, nbase, cell_texels, tiles_x;\n"
    "    uint data[];   /* distance[ncombos][2] (float bits), cells[], the view\n"
    "                      (screen.c): ncand, words, 0, 0, cand[ncombos],\n"
    "                      rec[ncombos][1 + WORDS] */\n"
    "} u_info;\n"
    "layout(set = 2, binding = 1, std430) writeonly buffer cls_tiles_block {\n"
    "    uint tiles[];\n"
    "} u_lists;\n"
    "layout(set = 2, binding = 2, std430) buffer cls_args_block {\n"
    "    uint args[];   /* per list: x y z of vkCmdDispatchIndirect */\n"
    "} u_args;\n"
    "layout(set = 0, binding = 8, rgba32f) uniform writeonly image2D u_out;\n"
    "uint mask[WORDS];\n"
    "uint last = 0xffffffffu;\n"
    "bool any_cell = false;\n"
    "bool outside = false;   /* a cell with a material outside the view */\n"
    "uint view_at() { return 2u * u_info.ncombos + u_info.cells_x * u_info.cells_z; }\n"
    "uint rec_at(uint c) { return view_at() + 4u + u_info.ncombos + c * uint(1 + WORDS); }\n"
    "float dmin = 3.0e38, dmax = 0.0;   /* the tile's terrain pixels' distances */\n"
    "float dfar = 3.0e38;   /* dmin, but 0 over the destructible area (far atlas) */\n"
    "void add_cell(ivec2 c) {\n"
    "    c = clamp(c, ivec2(0), ivec2(u_info.cells_x, u_info.cells_z) - 1);\n"
    "    uint i = uint(c.y) * u_info.cells_x + uint(c.x);\n"
    "    if (i == last) return;   /* most pixels of a tile share a cell */\n"
    "    last = i;\n"
    "    uint id = u_info.data[2u * u_info.ncombos + i];\n"
    "    if (id >= u_info.ncombos) return;   /* all hole: never drawn */\n"
    "    uint at = rec_at(id);\n"
    "    if ((u_info.data[at] & 1u) != 0u) outside = true;\n"
    "    for (int w = 0; w < WORDS; w++)\n"
    "        mask[w] |= u_info.data[at + 1u + uint(w)];\n"
    "    any_cell = true;\n"
    "}\n"
    /* Appending a tile: one atomic per list and subgroup where the
     * subgroup operations allow (AGGREGATE), since tiles of one list hit
     * one counter and a GPU serialises atomics on one address; the lowest
     * list first, then the next, until every tile of the subgroup is in. */
    "#ifdef AGGREGATE\n"
    "bool pending = false;\n"
    "void append(uint list, uint entry) {\n"
    "    pending = true;\n"
    "    while (subgroupAny(pending)) {\n"
    "        uint leader = subgroupMin(pending ? list : 0xffffffffu);\n"
    "        bool mine = pending && list == leader;\n"
    "        uvec4 b = subgroupBallot(mine);\n"
    "        uint rank = subgroupBallotExclusiveBitCount(b), base = 0u;\n"
    "        if (mine && rank == 0u)\n"
    "            base = atomicAdd(u_args.args[leader * 3u], subgroupBallotBitCount(b));\n"
    "        base = subgroupMax(base);\n"
    "        if (mine) {\n"
    "            u_lists.tiles[leader * u_info.ntiles + base + rank] = entry;\n"
    "            pending = false;\n"
    "        }\n"
    "    }\n"
    "}\n"
    "#else\n"
    "void append(uint list, uint entry) {\n"
    "    uint slot = atomicAdd(u_args.args[list * 3u], 1u);\n"
    "    u_lists.tiles[list * u_info.ntiles + slot] = entry;\n"
    "}\n"
    "#endif\n"
    /* one pixel: the background where empty, else its cell(s) */
    "void pixel(ivec2 px) {\n"
    "    float d = texelFetch(u_depth, px, 0).r;\n"
    "    vec2 ndc = (vec2(px) + 0.5) / u_frame.screen.xy * 2.0 - 1.0;\n"
    "    if (d == u_frame.screen.z) {   /* empty: the sky, or the background colour */\n"
    "        vec4 q = u_frame.inv_view_proj * vec4(ndc, 0.5, 1.0);\n"
    "        imageStore(u_out, px, u_frame.sky_color.a > 0.0\n"
    "            ? vec4(splat_sky(normalize(q.xyz / q.w)) * u_frame.light.z, 1.0)\n"
    "            : u_push.patch_xz);\n"
    "        return;\n"
    "    }\n"
    "    vec4 p = u_frame.inv_view_proj * vec4(ndc, d, 1.0);\n"
    /* view.distance as the compute variants reconstruct it (abi.c
     * splat_unproject): the same depth, the same pixel centre */
    "    float dist = length(p.xyz / p.w);\n"
    "    dmin = min(dmin, dist);\n"
    "    dmax = max(dmax, dist);\n"
    "    vec2 local = p.xz / p.w + u_frame.camera.xz;\n"
    /* far atlas: never over the destructible area (patch_uv), craters
     * change what the bake saw */
    "    dfar = min(dfar, dist);\n"
    "    if (all(greaterThanEqual(local, u_push.patch_uv.xy)) &&\n"
    "        all(lessThan(local, u_push.patch_uv.zw))) dfar = 0.0;\n"
    "    vec2 cf = local / u_frame.terrain.xy * u_frame.texel.xy / float(u_info.cell_texels);\n"
    /* a pixel within 1/64 cell of an edge counts for both cells: the
     * position from depth is rounded, the analysis is per closed cell */
    "    ivec2 lo = ivec2(floor(cf - 1.0 / 64.0)), hi = ivec2(floor(cf + 1.0 / 64.0));\n"
    "    add_cell(lo);\n"
    "    if (hi.x != lo.x) add_cell(ivec2(hi.x, lo.y));\n"
    "    if (hi.y != lo.y) add_cell(ivec2(lo.x, hi.y));\n"
    "    if (hi.x != lo.x && hi.y != lo.y) add_cell(hi);\n"
    "}\n"
    /* distance classes (c >= nbase, PACK.md): only where the tile's
     * distances, widened by SLACK, lie inside the class's interval, and
     * not at all with push info.z set (--no-distance-classes) */
    "bool fits(uint c) {\n"
    "    if (c < u_info.nbase) return true;\n"
    "    if (u_push.info.z != 0u) return false;\n"
    "    uint at = 2u * c;\n"
    "    return dmin * (1.0 - SLACK) >= uintBitsToFloat(u_info.data[at]) &&\n"
    "           dmax * (1.0 + SLACK) <= uintBitsToFloat(u_info.data[at + 1u]);\n"
    "}\n"
    /* whether combination c's set covers mask and its distances fit */
    "bool usable(uint c) {\n"
    "    uint at = rec_at(c) + 1u;\n"
    "    for (int w = 0; w < WORDS; w++)\n"
    "        if ((mask[w] & ~u_info.data[at + uint(w)]) != 0u)\n"
    "            return false;\n"
    "    return fits(c);\n"
    "}\n"
    /* the cheapest combination whose set covers mask, else the
     * über-shader: the view's candidates (screen.c rt_class_view) in cost
     * order, the first that covers */
    "uint ncand() { return u_info.data[view_at()]; }\n"
    "uint cand(uint i) { return u_info.data[view_at() + 4u + i]; }\n"
    "uint pick() {\n"
    "    if (u_push.info.x != 0u || u_info.words == 0u || outside) return u_info.ncombos;\n"
    "    uint n = ncand();\n"
    "    for (uint i = 0u; i < n; i++)\n"
    "        if (usable(cand(i))) return cand(i);\n"
    "    return u_info.ncombos;\n"
    "}\n"
    /* The tile order (push info.w 1, rt_render_desc.tile_blocks): the
     * dispatch's n-th tile in blocks of 4x4 tiles, block after block along
     * rows of blocks, so the tiles a list gets one after another lie close
     * together (a sorting workgroup's 16, the shading's neighbours);
     * false past the screen's tiles (the dispatch is padded to whole
     * blocks).  The tiles and what each is given do not change. */
    "bool block_tile(uint n, out uvec2 tile) {\n"
    "    uint bx = (u_info.tiles_x + 3u) / 4u, b = n / 16u, i = n % 16u;\n"
    "    tile = uvec2((b % bx) * 4u + (i & 3u), (b / bx) * 4u + (i >> 2u));\n"
    "    return tile.x < u_info.tiles_x && tile.y < (uint(u_frame.screen.y) + 7u) / 8u;\n"
    "}\n"
    /* a tile wholly beyond the far distance (info.y, float bits; 0: off)
     * goes to the far atlas's list */
    "bool far_tile() {\n"
    "    float fd = uintBitsToFloat(u_push.info.y);\n"
    "    return fd > 0.0 && dfar >= fd;\n"
    "}\n"
    "#ifdef WIDE\n"
    /* GPUs: one workgroup per tile, one invocation per pixel; the sets
     * ORed over each subgroup, then over the workgroup in shared memory;
     * the cover search split over the invocations (each takes every 64th
     * combination in cost order, the first that covers wins) */
    "layout(local_size_x = 64) in;\n"
    "shared uint s_mask[WORDS];\n"
    "shared uint s_any, s_dmin, s_dmax, s_dfar;   /* distances as bits: >= 0 orders as uint */\n"
    "shared uint s_first;   /* the first covering position in cost order */\n"
    "uint pick_wide(uint li) {\n"
    "    if (u_push.info.x != 0u || u_info.words == 0u || outside) return u_info.ncombos;\n"
    "    uint first = 0xffffffffu, n = ncand();\n"
    "    for (uint i = li; i < n && first == 0xffffffffu; i += 64u)\n"
    "        if (usable(cand(i))) first = i;\n"
    "    first = subgroupMin(first);\n"
    "    if (subgroupElect()) atomicMin(s_first, first);\n"
    "    barrier();\n"
    "    return s_first == 0xffffffffu ? u_info.ncombos : cand(s_first);\n"
    "}\n"
    "void main() {\n"
    "    uint li = gl_LocalInvocationIndex;\n"
    "    if (li < uint(WORDS)) s_mask[li] = 0u;\n"
    "    if (li == 0u) {\n"
    "        s_any = 0u; s_dmin = floatBitsToUint(3.0e38); s_dmax = 0u;\n"
    "        s_dfar = floatBitsToUint(3.0e38);\n"
    "        s_first = 0xffffffffu;\n"
    "    }\n"
    "    uvec2 tile = gl_WorkGroupID.xy;\n"
    "    if (u_push.info.w != 0u &&\n"   /* uniform: the whole workgroup */
    "        !block_tile(gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x, tile))\n"
    "        return;\n"
    "    for (int w = 0; w < WORDS; w++) mask[w] = 0u;\n"
    "    barrier();\n"
    "    ivec2 px = ivec2(tile * 8u + uvec2(li & 7u, li >> 3u));\n"
    "    if (all(lessThan(px, ivec2(u_frame.screen.xy)))) pixel(px);\n"
    "    for (int w = 0; w < WORDS; w++) {\n"
    "        uint v = subgroupOr(mask[w]);\n"
    "        if (subgroupElect() && v != 0u) atomicOr(s_mask[w], v);\n"
    "    }\n"
    "    if (subgroupAny(any_cell) && subgroupElect()) atomicOr(s_any, 1u);\n"
    "    if (subgroupAny(outside) && subgroupElect()) atomicOr(s_any, 2u);\n"
    "    float a = subgroupMin(dmin), b = subgroupMax(dmax), f = subgroupMin(dfar);\n"
    "    if (subgroupElect()) {\n"
    "        atomicMin(s_dmin, floatBitsToUint(a));\n"
    "        atomicMax(s_dmax, floatBitsToUint(b));\n"
    "        atomicMin(s_dfar, floatBitsToUint(f));\n"
    "    }\n"
    "    barrier();\n"
    "    if (s_any == 0u) return;   /* sky tile: skipped (uniform) */\n"
    "    outside = (s_any & 2u) != 0u;\n"
    "    for (int w = 0; w < WORDS; w++) mask[w] = s_mask[w];\n"
    "    dmin = uintBitsToFloat(s_dmin);\n"
    "    dmax = uintBitsToFloat(s_dmax);\n"
    "    dfar = uintBitsToFloat(s_dfar);\n"
    "    uint list = far_tile() ? u_info.ncombos + 1u : pick_wide(li);\n"
    "    if (li == 0u) append(list, tile.x | (tile.y << 16u));\n"
    "}\n"
    "#else\n"
    /* CPU drivers (lavapipe): one invocation per tile, no shared memory
     * and no barriers, which they pay for dearly */
    "layout(local_size_x = 64) in;\n"
    "void classify(uvec2 tile) {\n"
    "    for (int w = 0; w < WORDS; w++) mask[w] = 0u;\n"
    "    ivec2 size = ivec2(u_frame.screen.xy);\n"
    "    for (int y = 0; y < 8; y++)\n"
    "        for (int x = 0; x < 8; x++) {\n"
    "            ivec2 px = ivec2(tile * 8u) + ivec2(x, y);\n"
    "            if (all(lessThan(px, size))) pixel(px);\n"
    "        }\n"
    "    if (any_cell) append(far_tile() ? u_info.ncombos + 1u : pick(), tile.x | (tile.y << 16u));\n"
    "}\n"
    /* every invocation reaches append's subgroup loop or none past it */
    "void main() {\n"
    "    uint t = gl_GlobalInvocationID.x;\n"
    "    uvec2 tile;\n"
    "    if (u_push.info.w != 0u) {\n"
    "        if (block_tile(t, tile)) classify(tile);\n"
    "    } else if (t < u_info.ntiles) {\n"
    "        classify(uvec2(t % u_info.tiles_x, t / u_info.tiles_x));\n"
    "    }\n"
    "}\n"
    "#endif\n";

/* Pixel sorting's list pass (one invocation per list): pad list k with
 * empty entries (0xffffffff) to a multiple of G tiles and write its
 * grouped dispatch size at args[3 * (nlists + k)]; info.x = nlists. */
const char rt_screen_group_glsl[] =
    "layout(local_size_x = 64) in;\n"
    "layout(set = 2, binding = 0, std430) readonly buffer cls_info_block {\n"
    "    uint ncombos, words, cells_x, cells_z;\n"
    "    uint stride;\n"
    "} u_info;\n"
    "layout(set = 2, binding = 1, std430) writeonly buffer cls_tiles_block {\n"
    "    uint tiles[];\n"
    "} u_lists;\n"
    "layout(set = 2, binding = 2, std430) buffer cls_args_block {\n"
    "    uint args[];\n"
    "} u_args;\n"
    "void main() {\n"
    "    uint k = gl_GlobalInvocationID.x, nlists = u_push.info.x;\n"
    "    if (k >= nlists) return;\n"
    "    uint n = u_args.args[3u * k], g = (n + G - 1u) / G;\n"
    "    u_args.args[3u * (nlists + k)] = g;\n"
    "    u_args.args[3u * (nlists + k) + 1u] = 1u;\n"
    "    u_args.args[3u * (nlists + k) + 2u] = 1u;\n"
    "    for (uint i = n; i < g * G; i++) u_lists.tiles[k * u_info.stride + i] = 0xffffffffu;\n"
    "}\n";

/* Depth by ray casting (Tevs et al. 2008, "Maximum mipmaps"): the ray
 * through each pixel centre walks a pyramid of maximum heights from the
 * top level down, skipping cells it passes above, and at the finest level
 * meets the two triangles of the mesh quad exactly as the patches'
 * finest LOD draws them (corners at texel edges, heights bilinear there,
 * diagonal from (i, j) to (i+1, j+1): rt_grid_indices).  It writes the
 * reversed-Z depth of the hit, or the clear value 0, into an R32F image
 * that classification and shading read in place of the geometry pass's
 * depth.  Level 0 holds, per quad, the highest of its four corners (plus
 * a margin for the GPU's rounding; craters only lower the terrain, so the
 * bound stays valid under destruction); each level the largest of
 * four, 8 levels up; the grid is padded to a multiple of 256 so every level
 * halves exactly (Vulkan's mip sizes round down). */
const char rt_screen_raycast_glsl[] =
    "layout(local_size_x = 8, local_size_y = 8) in;\n"
    "layout(set = 2, binding = 3) uniform sampler2D u_maxmip;\n"
    "layout(set = 2, binding = 4, r32f) uniform writeonly image2D u_rdepth;\n"
    "float corner(ivec2 k) { return splat_height_at(vec2(k) * u_frame.texel.zw); }\n"
    /* The ray against mesh quad k's two triangles, in the quad's own
     * coordinates (u, v in [0, 1]: precise however far the quad is):
     * (0,0) (1,0) (1,1) where u >= v, (0,0) (1,1) (0,1) where v >= u.
     * The nearest hit with t in [t0, t1], else -1. */
    "float quad_hit(vec3 O, vec3 D, ivec2 k, float t0, float t1) {\n"
    "    float ha = corner(k), hb = corner(k + ivec2(1, 0));\n"
    "    float hc = corner(k + ivec2(1, 1)), hd = corner(k + ivec2(0, 1));\n"
    "    vec2 o = O.xz - vec2(k);\n"
    "    const float eps = 1e-4;\n"
    "    float best = -1.0;\n"
    "    for (int s = 0; s < 2; s++) {\n"
    "        float A = s == 0 ? hb - ha : hc - hd, B = s == 0 ? hc - hb : hd - ha;\n"
    "        float den = D.y - A * D.x - B * D.z;\n"
    "        if (den == 0.0) continue;\n"
    "        float t = (ha + A * o.x + B * o.y - O.y) / den;\n"
    "        if (t < t0 || t > t1) continue;\n"
    "        vec2 uv = o + D.xz * t;\n"
    "        vec2 w = s == 0 ? uv : uv.yx;   /* w.x >= w.y in the triangle */\n"
    "        if (w.x < -eps || w.x > 1.0 + eps || w.y < -eps || w.y > w.x + eps) continue;\n"
    "        best = best < 0.0 ? t : min(best, t);\n"
    "    }\n"
    "    return best;\n"
    "}\n"
    "void main() {\n"
    "    ivec2 px = ivec2(gl_GlobalInvocationID.xy);\n"
    "    if (any(greaterThanEqual(px, ivec2(u_frame.screen.xy)))) return;\n"
    "    vec2 ndc = (vec2(px) + 0.5) / u_frame.screen.xy * 2.0 - 1.0;\n"
    "    vec4 q = u_frame.inv_view_proj * vec4(ndc, 1.0, 1.0);\n"
    "    vec3 dir = normalize(q.xyz / q.w);\n"
    "    vec2 sc = u_frame.texel.xy / u_frame.terrain.xy;   /* texels per metre */\n"
    "    vec3 O = vec3(u_frame.camera.x * sc.x, u_frame.camera.y, u_frame.camera.z * sc.y);\n"
    "    vec3 D = vec3(dir.x * sc.x, dir.y, dir.z * sc.y);   /* t: metres along dir */\n"
    "    const int top = TOP;\n"
    /* the box [0, W] x (-inf, highest height] x [0, H] */
    "    vec3 lo = vec3(0.0, -1e30, 0.0);\n"
    "    vec3 hi = vec3(u_frame.texel.x, u_frame.terrain.z + u_frame.terrain.w, u_frame.texel.y);\n"
    "    vec3 inv = 1.0 / D;\n"
    "    vec3 ta = (lo - O) * inv, tb = (hi - O) * inv;\n"
    "    vec3 tn = min(ta, tb), tf = max(ta, tb);\n"
    "    float t = max(max(max(tn.x, tn.y), tn.z), 0.0), tend = min(min(tf.x, tf.y), tf.z);\n"
    "    float hit = -1.0;\n"
    "    int L = top;\n"
    /* a walk over cells by index (a DDA), so rounding in the position can
     * never hold it in place: down into the child under the ray where
     * the ray may meet the cell's contents, else across to the neighbour
     * on the exit side, up to the parent when that leaves this one */
    "    ivec2 c = clamp(ivec2(floor((O.xz + D.xz * t) / float(1 << L))), ivec2(0),\n"
    "                    (ivec2(PW, PH) >> L) - 1);\n"
    "    for (int it = 0; it < 16384 && t <= tend && hit < 0.0; it++) {\n"
    "        float size = float(1 << L);\n"
    "        vec2 b0 = vec2(c) * size, b1 = b0 + size;\n"
    "        vec2 tx = (mix(b0, b1, greaterThan(D.xz, vec2(0.0))) - O.xz) * inv.xz;\n"
    "        tx = mix(tx, vec2(1e30), equal(D.xz, vec2(0.0)));\n"
    "        int axis = tx.x < tx.y ? 0 : 1;\n"
    "        float te = min(min(tx.x, tx.y), tend);\n"
    "        float top_h = texelFetch(u_maxmip, c, L).r;\n"
    "        if (min(O.y + D.y * t, O.y + D.y * te) <= top_h) {\n"
    "            if (L > 0) {   /* the ray may meet something in here: look closer */\n"
    "                L--;\n"
    "                vec2 p = (O.xz + D.xz * t) / (size * 0.5);\n"
    "                c = clamp(ivec2(floor(p)), 2 * c, 2 * c + 1);\n"
    "                continue;\n"
    "            }\n"
    "            float slack = 1e-5 * te + 1e-4;\n"
    "            hit = quad_hit(O, D, c, t - slack, te + slack);\n"
    "        }\n"
    "        t = max(t, te);\n"
    "        ivec2 cn = c;\n"
    "        if (axis == 0) cn.x += D.x > 0.0 ? 1 : -1; else cn.y += D.z > 0.0 ? 1 : -1;\n"
    "        if (any(lessThan(cn, ivec2(0))) || any(greaterThanEqual(cn, ivec2(PW, PH) >> L)))\n"
    "            break;   /* off the terrain */\n"
    "        if (L < top && any(notEqual(cn >> 1, c >> 1))) {\n"
    "            L++;\n"
    "            c = cn >> 1;\n"
    "        } else {\n"
    "            c = cn;\n"
    "        }\n"
    "    }\n"
    "    float depth = 0.0;   /* the clear value: sky */\n"
    "    if (hit >= 0.0) {\n"
    "        vec4 clip = u_frame.view_proj * vec4(dir * hit, 1.0);\n"
    "        depth = clip.z / clip.w;\n"
    "    }\n"
    "    imageStore(u_rdepth, px, vec4(depth));\n"
    "}\n";
