/* abi.c — the shared GLSL text of the shader ABI (see abi.h). */
#include "abi.h"
#include "far_atlas.h"
#include "sparse.h"

#include <math.h>

#define SPLAT_STR_(x) #x
#define SPLAT_STR(x) SPLAT_STR_(x)


/* The prelude's own textures have one mip level: texture() where the
 * stage has implicit derivatives, level 0 where it has none (compute;
 * the vertex stage has none either, but its level is 0 already). */
#define SPLAT_GLSL_TEXTURE0                                                 \
    "#ifdef SPLAT_COMPUTE\n"                                                \
    "#define splat_texture0(s, p) textureLod(s, p, 0.0)\n"                  \
    "#else\n"                                                               \
    "#define splat_texture0(s, p) texture(s, p)\n"                          \
    "#endif\n"

/* ---- compute stage (abi.h "compute stage"): declarations and main --------- */

/* The undergrowth mask variant (SPLAT_UNDERGROWTH, with SPLAT_COMPUTE;
 * abi.h "undergrowth masks"): one invocation per texel of a cell's
 * SPLAT_UG_TEXELS^2 grid, seen from straight above at a fixed distance,
 * so the masks depend on the cell alone, never on the camera.  Each
 * undergrowth material's composited weight (splat_ug_weight, called by
 * the composite where the layer's weight is computed), the terrain normal
 * and the composite's albedo are packed into u_ug.words. */
#define UG_DECLS                                                            \
    "layout(set = 2, binding = 0, std430) writeonly buffer splat_ug_block {\n" \
    "    uint words[];\n"                                                   \
    "} u_ug;\n"                                                             \
    "float splat_ug_w[" SPLAT_STR(SPLAT_UG_SLOTS) "];\n"                     \
    "vec3 splat_ug_albedo;\n"                                               \
    "void splat_ug_weight(int s, float w) { splat_ug_w[s] = w; }\n"

#define UG_MAIN                                                             \
    "void splat_begin() {\n"                                                \
    "    splat_pixel = ivec2(gl_GlobalInvocationID.xy);\n"                  \
    "    float step = u_push.patch_xz.z / " SPLAT_STR(SPLAT_UG_TEXELS) ".0;\n" \
    "    vec2 xz = u_push.patch_xz.xy + (vec2(splat_pixel) + 0.5) * step;\n" \
    "    v_uv = xz / u_frame.terrain.xy;\n"                                 \
    "    splat_terrain_at(v_uv, splat_hgt, splat_nrm);\n"                   \
    "    v_local = vec3(xz.x, splat_hgt, xz.y);\n"                          \
    "    v_rel = v_local - u_frame.camera.xyz;\n"                           \
    "    float ny = max(splat_nrm.y, 0.05);\n"                              \
    "    splat_dpdx = vec3(step, -step * splat_nrm.x / ny, 0.0);\n"         \
    "    splat_dpdy = vec3(0.0, -step * splat_nrm.z / ny, step);\n"         \
    "    for (int i = 0; i < " SPLAT_STR(SPLAT_UG_SLOTS) "; i++) splat_ug_w[i] = 0.0;\n" \
    "    splat_ug_albedo = vec3(0.0);\n"                                    \
    "}\n"                                                                   \
    "void splat_main();\n"                                                  \
    "void main() {\n"                                                       \
    "    vec2 q = u_push.patch_xz.xy + (vec2(gl_GlobalInvocationID.xy) + 0.5)\n" \
    "             * (u_push.patch_xz.z / " SPLAT_STR(SPLAT_UG_TEXELS) ".0);\n"  \
    "    if (any(lessThan(q, u_push.patch_uv.xy)) ||\n"                     \
    "        any(greaterThanEqual(q, u_push.patch_uv.zw))) return;\n"       \
    "    splat_begin();\n"                                                  \
    "    splat_main();\n"                                                   \
    "    uint nw = u_push.info.z;\n"                                        \
    "    uint at = u_push.info.x + (uint(splat_pixel.y) * " SPLAT_STR(SPLAT_UG_TEXELS) "u\n" \
    "              + uint(splat_pixel.x)) * (nw + 2u);\n"                   \
    "    for (uint k = 0u; k < nw; k++)\n"                                  \
    "        u_ug.words[at + k] = packUnorm4x8(vec4(splat_ug_w[4u * k], splat_ug_w[4u * k + 1u],\n" \
    "                                               splat_ug_w[4u * k + 2u], splat_ug_w[4u * k + 3u]));\n" \
    "    u_ug.words[at + nw] = packSnorm4x8(vec4(splat_nrm, 0.0));\n"        \
    "    u_ug.words[at + nw + 1u] = packUnorm4x8(vec4(clamp(splat_ug_albedo, 0.0, 1.0), 1.0));\n" \
    "}\n"                                                                   \
    "#define main splat_main\n"

/* The far atlas bake variant (SPLAT_FAR_BAKE, with SPLAT_COMPUTE; abi.h
 * "far atlas bake"): one invocation per bake point of a rectangle of the
 * point grid, point (i, j) at ((i, j) + 0.5) * patch_xz.xy terrain-local
 * metres, seen from straight above at FAR_ATLAS_BAKE_DISTANCE as the CPU
 * reference sees it (far_atlas.c eval_point), one point step as the pixel
 * step of the texture gradients.  Writes the composite's albedo, unit
 * normal and roughness, clamped, and 1 (a point shaded) into u_far.v. */
#define FAR_DECLS                                                           \
    "layout(set = 2, binding = 0, std430) writeonly buffer splat_far_block {\n" \
    "    float v[];\n"                                                      \
    "} u_far;\n"                                                            \
    "vec3 splat_far_albedo, splat_far_normal;\n"                            \
    "float splat_far_rough;\n"

#define FAR_MAIN                                                            \
    "void splat_main();\n"                                                  \
    "void main() {\n"                                                       \
    "    if (any(greaterThanEqual(gl_GlobalInvocationID.xy, u_push.info.zw))) return;\n" \
    "    uvec2 q = u_push.info.xy + gl_GlobalInvocationID.xy;\n"            \
    "    splat_pixel = ivec2(q);\n"                                         \
    "    vec2 step = u_push.patch_xz.xy;\n"                                 \
    "    vec2 xz = (vec2(q) + 0.5) * step;\n"                               \
    "    v_uv = xz / u_frame.terrain.xy;\n"                                 \
    "    splat_terrain_at(v_uv, splat_hgt, splat_nrm);\n"                   \
    "    v_local = vec3(xz.x, splat_hgt, xz.y);\n"                          \
    "    v_rel = v_local;   /* the frame's camera is the origin */\n"      \
    "    float ny = max(splat_nrm.y, 0.05);\n"                              \
    "    splat_dpdx = vec3(step.x, -step.x * splat_nrm.x / ny, 0.0);\n"     \
    "    splat_dpdy = vec3(0.0, -step.y * splat_nrm.z / ny, step.y);\n"     \
    "    splat_far_albedo = vec3(0.0);\n"                                   \
    "    splat_far_normal = vec3(0.0, 1.0, 0.0);\n"                         \
    "    splat_far_rough = 1.0;\n"                                          \
    "    splat_main();\n"                                                   \
    "    uint at = ((q.y - u_push.info.y + uint(u_push.patch_xz.w)) * uint(u_push.patch_xz.z)\n" \
    "               + q.x) * 8u;\n"                                          \
    "    float l = length(splat_far_normal);\n"                             \
    "    vec3 n = l > 0.0 ? splat_far_normal / l : vec3(0.0, 1.0, 0.0);\n"  \
    "    vec3 a = clamp(splat_far_albedo, 0.0, 1.0);\n"                     \
    "    u_far.v[at] = a.r; u_far.v[at + 1u] = a.g; u_far.v[at + 2u] = a.b;\n" \
    "    u_far.v[at + 3u] = n.x; u_far.v[at + 4u] = n.y; u_far.v[at + 5u] = n.z;\n" \
    "    u_far.v[at + 6u] = clamp(splat_far_rough, 0.0, 1.0);\n"            \
    "    u_far.v[at + 7u] = 1.0;\n"                                         \
    "}\n"                                                                   \
    "#define main splat_main\n"

/* Bindings 7-10 and the globals that stand for the fragment varyings. */
#define COMPUTE_DECLS                                                       \
    "#ifdef SPLAT_SORT\n"                                                   \
    "layout(local_size_x = SPLAT_SORT_LANES) in;\n"                         \
    "#else\n"                                                               \
    "layout(local_size_x = 8, local_size_y = 8) in;\n"                      \
    "#endif\n"                                                              \
    "#if defined(SPLAT_UNDERGROWTH)\n"                                      \
    UG_DECLS                                                                \
    "#elif defined(SPLAT_FAR_BAKE)\n"                                       \
    FAR_DECLS                                                               \
    "#else\n"                                                               \
    "layout(set = 0, binding = 7) uniform sampler2D u_depth;\n"             \
    "layout(set = 0, binding = 8, rgba32f) uniform writeonly image2D u_out;\n" \
    "layout(set = 0, binding = 9, std430) readonly buffer splat_tiles_block {\n" \
    "    uint tiles[];\n"                                                   \
    "} u_tiles;\n"                                                          \
    "#endif\n"                                                              \
    "vec3 v_rel;      /* camera-relative position (m), from depth */\n"     \
    "vec2 v_uv;       /* heightfield uv */\n"                               \
    "vec3 v_local;    /* terrain-local position (m) */\n"                   \
    "vec4 o_color;    /* what main() stores into u_out */\n"                \
    "ivec2 splat_pixel;\n"                                                  \
    "vec3 splat_nrm;  /* the terrain normal (Listing 1) at v_uv */\n"      \
    "float splat_hgt; /* the terrain height (m) at v_uv, smooth */\n"      \
    "vec3 splat_dpdx; /* position one pixel right, minus the position */\n" \
    "vec3 splat_dpdy; /* position one pixel down, minus the position */\n"

/* The counting variant (abi.h SPLAT_COUNT), both stages: binding 10 and
 * this invocation's counts, added to it after the composite ran. */
#define COUNT_DECLS                                                         \
    "#ifdef SPLAT_COUNT\n"                                                  \
    "layout(set = 0, binding = 10, std430) buffer splat_counters_block {\n" \
    "    uint pixels;\n"                                                    \
    "    uint layers_evaluated;\n"                                          \
    "    uint layers_needed;\n"                                             \
    "    uint samples;\n"                                                   \
    "    uint branches;\n"                                                  \
    "    uint branches_uniform;\n"                                          \
    "} u_counters;\n"                                                       \
    "uint splat_n_evaluated = 0u, splat_n_needed = 0u, splat_n_samples = 0u;\n" \
    "uint splat_n_branches = 0u, splat_n_uniform = 0u;\n"                   \
    "#endif\n"
#define COUNT_ADD                                                           \
    "#ifdef SPLAT_COUNT\n"                                                  \
    "    atomicAdd(u_counters.pixels, 1u);\n"                               \
    "    atomicAdd(u_counters.layers_evaluated, splat_n_evaluated);\n"      \
    "    atomicAdd(u_counters.layers_needed, splat_n_needed);\n"            \
    "    atomicAdd(u_counters.samples, splat_n_samples);\n"                 \
    "    atomicAdd(u_counters.branches, splat_n_branches);\n"               \
    "    atomicAdd(u_counters.branches_uniform, splat_n_uniform);\n"        \
    "#endif\n"

/* The sorted variant's main (abi.h SPLAT_SORT): each invocation takes a
 * pixel of its workgroup's SPLAT_SORT_TILES tiles and runs the composite
 * with splat_sorting set, which only collects the pixel's layer set; a
 * counting sort by that set in shared memory (per-key counts, their
 * exclusive prefix sum over the subgroups, a scatter); then invocation i
 * shades the i-th pixel of that order, so a subgroup's lanes mostly need
 * the same layers.  Pixels without terrain take key SORT_KEYS, which is
 * never scattered: they are off the end of the order. */
#define SORT_KEYS 256    /* SPLAT_SORT_KEYS, as text; <= the lanes (4 tiles) */
#define SORT_TILES_MIN 4 /* SPLAT_SORT_TILES_MIN, as text */
_Static_assert(SORT_KEYS == SPLAT_SORT_KEYS && SORT_TILES_MIN == SPLAT_SORT_TILES_MIN &&
               SORT_KEYS <= 64 * SORT_TILES_MIN,
               "the sorted variant's sizes (abi.h)");
#define SORT_MAIN                                                           \
    "shared uint s_sort_n[" SPLAT_STR(SORT_KEYS) " + 1];   /* per key */\n" \
    "shared uint s_sort_part[SPLAT_SORT_LANES];   /* per subgroup */\n"     \
    "shared uint s_sort_px[SPLAT_SORT_LANES];\n"                            \
    "void main() {\n"                                                       \
    "    uint li = gl_LocalInvocationIndex;\n"                              \
    "    uint t = u_tiles.tiles[u_push.info.w + gl_WorkGroupID.x * uint(SPLAT_SORT_TILES)\n" \
    "                           + li / 64u];\n"                             \
    "    ivec2 px = splat_tile_pixel(t, uvec2(li & 7u, (li >> 3u) & 7u));\n" \
    "    if (li < " SPLAT_STR(SORT_KEYS) "u) s_sort_n[li] = 0u;\n"          \
    "    if (li == 0u) s_sort_n[" SPLAT_STR(SORT_KEYS) "] = 0u;\n"          \
    "    barrier();\n"                                                      \
    "    uint key = " SPLAT_STR(SORT_KEYS) "u;   /* no terrain: past every key */\n" \
    "    if (splat_begin_at(px)) {\n"                                       \
    "        splat_sorting = true;\n"                                       \
    "        splat_main();\n"                                               \
    "        splat_sorting = false;\n"                                      \
    "        uint b = splat_layer_bits;\n"                                  \
    "        b ^= b >> 16u;\n"                                              \
    "        key = (b ^ (b >> 8u)) & 255u;\n"                               \
    "    }\n"                                                               \
    "#ifdef SPLAT_COUNT\n"   /* the first run's work, its layers excepted */ \
    "    atomicAdd(u_counters.samples, splat_n_samples);\n"                 \
    "    atomicAdd(u_counters.branches, splat_n_branches);\n"               \
    "    atomicAdd(u_counters.branches_uniform, splat_n_uniform);\n"        \
    "    splat_n_samples = 0u;\n"                                           \
    "    splat_n_branches = 0u;\n"                                          \
    "    splat_n_uniform = 0u;\n"                                           \
    "#endif\n"                                                              \
    "    uint rank = atomicAdd(s_sort_n[key], 1u);\n"                       \
    "    barrier();\n"                                                      \
    "    uint n = li < " SPLAT_STR(SORT_KEYS) "u ? s_sort_n[li] : 0u;\n"    \
    "    uint below = subgroupExclusiveAdd(n);\n"                           \
    "    if (gl_SubgroupInvocationID == gl_SubgroupSize - 1u)\n"            \
    "        s_sort_part[gl_SubgroupID] = below + n;\n"                     \
    "    barrier();\n"                                                      \
    "    uint total = 0u;\n"                                                \
    "    for (uint k = 0u; k < gl_NumSubgroups; k++) {\n"                   \
    "        if (k == gl_SubgroupID) below += total;\n"                     \
    "        total += s_sort_part[k];\n"                                    \
    "    }\n"                                                               \
    "    if (li < " SPLAT_STR(SORT_KEYS) "u)\n"                             \
    "        s_sort_n[li] = below;   /* every count was read before the barrier */\n" \
    "    barrier();\n"                                                      \
    "    if (key < " SPLAT_STR(SORT_KEYS) "u)\n"                            \
    "        s_sort_px[s_sort_n[key] + rank] = uint(px.x) | (uint(px.y) << 16u);\n" \
    "    barrier();\n"                                                      \
    "    if (li >= total) return;\n"                                        \
    "    uint q = s_sort_px[li];\n"                                         \
    "    splat_begin_at(ivec2(q & 0xffffu, q >> 16u));\n"                   \
    "    splat_main();\n"                                                   \
    COUNT_ADD                                                               \
    "    imageStore(u_out, splat_pixel, o_color);\n"                        \
    "}\n"

/* After splat_finish: depth reconstruction, FC5's position derivatives
 * (the prelude's splat_plane_step), the real main() around the
 * composite's (renamed splat_main). */
#define COMPUTE_MAIN                                                        \
    "bool splat_begin_at(ivec2 px) {\n"                                     \
    "    splat_pixel = px;\n"                                               \
    "    if (any(greaterThanEqual(splat_pixel, ivec2(u_frame.screen.xy)))) return false;\n" \
    "    float d = texelFetch(u_depth, splat_pixel, 0).r;\n"                \
    "    if (d == u_frame.screen.z) return false;\n"                        \
    "    vec2 c = vec2(splat_pixel) + 0.5;\n"                               \
    "    v_rel = splat_unproject(c, d);\n"                                  \
    "    v_local = v_rel + u_frame.camera.xyz;\n"                           \
    "    v_uv = v_local.xz / u_frame.terrain.xy;\n"                         \
    "    splat_terrain_at(v_uv, splat_hgt, splat_nrm);\n"                   \
    "    splat_dpdx = splat_plane_step(splat_nrm, v_rel, c + vec2(1.0, 0.0), d);\n" \
    "    splat_dpdy = splat_plane_step(splat_nrm, v_rel, c + vec2(0.0, 1.0), d);\n" \
    "    return true;\n"                                                    \
    "}\n"                                                                   \
    "ivec2 splat_tile_pixel(uint t, uvec2 q) {\n"                           \
    "    return ivec2(uvec2(t & 0xffffu, t >> 16u) * 8u + q);\n"            \
    "}\n"                                                                   \
    "void splat_main();\n"                                                  \
    "#ifdef SPLAT_SORT\n"                                                   \
    SORT_MAIN                                                               \
    "#else\n"                                                               \
    "void main() {\n"                                                       \
    "    uint t = u_tiles.tiles[u_push.info.w + gl_WorkGroupID.x];\n"       \
    "    if (!splat_begin_at(splat_tile_pixel(t, gl_LocalInvocationID.xy))) return;\n" \
    "    splat_main();\n"                                                   \
    COUNT_ADD                                                               \
    "    imageStore(u_out, splat_pixel, o_color);\n"                        \
    "}\n"                                                                   \
    "#endif\n"                                                              \
    "#define main splat_main\n"

/* A fragment shader that samples with gradients (SPLAT_GRADIENTS, which
 * the composite defines when it has any): the normal and the position
 * derivatives once per pixel, as compute's splat_begin does, then the
 * composite's main (renamed splat_main).  The plane goes through the
 * pixel's own unprojected depth, not the interpolated v_rel: the
 * difference of two points must come from one computation (far from the
 * origin v_rel carries the vertex stage's rounding, a fifth of a 13 cm
 * pixel at 1,000 km in tests/world/test_far.c). */
#define FRAGMENT_MAIN                                                       \
    "void splat_main();\n"                                                  \
    "void main() {\n"                                                       \
    "#ifdef SPLAT_GRADIENTS\n"                                              \
    "    vec3 p = splat_unproject(gl_FragCoord.xy, gl_FragCoord.z);\n"      \
    "    splat_terrain_at(v_uv, splat_hgt, splat_nrm);\n"                   \
    "    splat_dpdx = splat_plane_step(splat_nrm, p, gl_FragCoord.xy + vec2(1.0, 0.0),\n" \
    "                                  gl_FragCoord.z);\n"                  \
    "    splat_dpdy = splat_plane_step(splat_nrm, p, gl_FragCoord.xy + vec2(0.0, 1.0),\n" \
    "                                  gl_FragCoord.z);\n"                  \
    "#endif\n"                                                              \
    "    splat_main();\n"                                                   \
    "#ifdef SPLAT_COUNT\n"                                                  \
    "    if (gl_HelperInvocation) return;\n"                                \
    "#endif\n"                                                              \
    COUNT_ADD                                                               \
    "}\n"                                                                   \
    "#define main splat_main\n"

/* Declarations common to the vertex and fragment stages. */
#define SPLAT_GLSL_COMMON                                                   \
    "layout(set = 0, binding = 0) uniform sampler2D u_height;\n"            \
    "layout(set = 0, binding = 1, std140) uniform splat_frame_block {\n"    \
    "    mat4 view_proj;\n"                                                 \
    "    vec4 camera;\n"                                                    \
    "    vec4 sun_dir;\n"                                                   \
    "    vec4 sun_color;\n"                                                 \
    "    vec4 sky_color;\n"                                                 \
    "    vec4 fog;\n"                                                       \
    "    vec4 terrain;\n"                                                   \
    "    vec4 texel;\n"                                                     \
    "    vec4 destruction;\n"                                               \
    "    vec4 destruction_atlas;\n"                                         \
    "    uvec4 view;\n"                                                     \
    "    mat4 inv_view_proj;\n"                                             \
    "    vec4 screen;\n"                                                    \
    "    vec4 world[" SPLAT_STR(SPLAT_WORLD_SITES) "];\n"                   \
    "    vec4 light;\n"                                                     \
    "} u_frame;\n"                                                          \
    "layout(push_constant, std430) uniform splat_push_block {\n"            \
    "    vec4 patch_xz;\n"                                                  \
    "    vec4 patch_uv;\n"                                                  \
    "    uvec4 info;\n"                                                     \
    "} u_push;\n"                                                           \
    SPLAT_GLSL_TEXTURE0                                                     \
    "float splat_height_at(vec2 uv) {\n"                                    \
    "    return splat_texture0(u_height, uv).r * u_frame.terrain.z + u_frame.terrain.w;\n" \
    "}\n"

#define COMBO_COLOR_TEXT \
    "vec3 splat_combo_color(uint id) {\n" \
    "    uint h = id * 2654435761u + 0x9e3779b9u;\n" \
    "    h ^= h >> 15; h *= 0x85ebca6bu; h ^= h >> 13;\n" \
    "    return vec3(float(h & 255u), float((h >> 8) & 255u),\n" \
    "                float((h >> 16) & 255u)) / 255.0 * 0.8 + 0.2;\n" \
    "}\n"

/* Preview lighting in linear radiance, before the tone map (runtime/
 * image.c, viewer.c).  Sun: GGX / Trowbridge-Reitz distribution D with
 * alpha = rough^2, Smith height-correlated visibility V (Heitz 2014),
 * Schlick Fresnel F with F0 = 0.04 (dielectrics); diffuse Lambert weighted
 * by 1 - F so reflected energy is not counted twice:
 *     Lo = (albedo (1 - F) + pi D V F) * sun * ndl
 *        + albedo * splat_sky_ambient(n)             (the sky, below)
 * with sun = u_frame.sun_color, the sun's irradiance / pi, times the
 * sun's visibility from the shadow map (runtime/shadow.c).  Specular
 * anti-aliasing, the same in every shading path: alpha^2 is widened by
 * the normal variance a pixel averages and no path sees, which grows with
 * the pixel's footprint over a heightfield texel:
 *     alpha^2 += min(0.01 * (footprint / texel)^2, 0.18)
 * (footprint = dist * u_frame.screen.w, radians per pixel; 0.18: the
 * clamp of Kaplanyan et al. 2016).  Then fog towards what is drawn
 * behind the terrain: the sky along the view ray when it is drawn, else
 * the background colour u_frame.fog (far terrain fades into it):
 * density fog.a at height light.x, falling off by exp(-light.y * (y -
 * light.x)) (0: the same everywhere), integrated exactly along the ray
 * (Quilez, "Better fog"); then the exposure factor light.z.
 * v: surface -> camera.  tests/render/test_lighting.c holds a double
 * twin of this model. */
/* The analytic sky, radiance along unit direction d (before exposure): a
 * gradient from the horizon's haze (the zenith colour half way to grey
 * of 1.5 times its luminance) up to the zenith, 2.2 times the scene's
 * `sky` (mix by elevation^0.45), plus a sun glow (the sun's colour times
 * 0.02 mu^8 + 0.25 mu^256, mu the cosine to the sun); below the horizon
 * the haze.  The ambient light of a surface of normal n is the same
 * gradient seen by a hemisphere: 0.5 mix(horizon, zenith, 0.5 + 0.5 n.y)
 * (irradiance / pi of the gradient between its horizon and zenith
 * radiance, halved for the sky that surrounding terrain hides, which the
 * preview does not trace; glow left out).
 * Drawn behind the terrain when u_frame.sky_color.a is 1 (the default
 * background of the final view: runtime/render.c), and then the colour
 * fog fades into, so far terrain meets the sky behind it. */
#define SKY_TEXT \
    "vec3 splat_sky_zenith() { return u_frame.sky_color.rgb * 2.2; }\n" \
    "vec3 splat_sky_horizon() {\n" \
    "    vec3 zen = splat_sky_zenith();\n" \
    "    return mix(zen, vec3(dot(zen, vec3(0.2126, 0.7152, 0.0722)) * 1.5), 0.5);\n" \
    "}\n" \
    "vec3 splat_sky(vec3 d) {\n" \
    "    vec3 c = mix(splat_sky_horizon(), splat_sky_zenith(), pow(max(d.y, 0.0), 0.45));\n" \
    "    float mu = max(dot(d, u_frame.sun_dir.xyz), 0.0);\n" \
    "    return c + u_frame.sun_color.rgb * (0.02 * pow(mu, 8.0) + 0.25 * pow(mu, 256.0));\n" \
    "}\n" \
    "vec3 splat_sky_ambient(vec3 n) {\n" \
    "    return 0.5 * mix(splat_sky_horizon(), splat_sky_zenith(), 0.5 + 0.5 * n.y);\n" \
    "}\n"

#define LIGHTING_TEXT \
    SKY_TEXT \
    "float splat_fog(float dist, vec3 v) {\n" \
    "    float k = u_frame.light.y;\n" \
    "    float at_cam = u_frame.fog.a * exp(-k * (u_frame.camera.y - u_frame.light.x));\n" \
    "    float t = -k * v.y * dist;   /* k times the height from camera to surface */\n" \
    "    float path = abs(t) > 1e-4 ? (1.0 - exp(-t)) / t : 1.0;\n" \
    "    return 1.0 - exp(-max(at_cam * dist * path, 0.0));\n" \
    "}\n" \
    "float splat_alpha2(float rough, float dist) {\n" \
    "    float a = clamp(rough, 0.02, 1.0);\n" \
    "    float texel = u_frame.terrain.x * u_frame.texel.z;\n" \
    "    float r = dist * u_frame.screen.w / texel;\n" \
    "    return min(a * a * a * a + min(0.01 * r * r, 0.18), 1.0);\n" \
    "}\n" \
    "vec3 splat_sun_brdf(vec3 albedo, vec3 n, float a2, vec3 l, vec3 v) {\n" \
    "    float ndl = max(dot(n, l), 0.0);\n" \
    "    if (ndl <= 0.0) return vec3(0.0);\n" \
    "    float ndv = max(dot(n, v), 1e-4);\n" \
    "    vec3 h = normalize(l + v);\n" \
    "    float ndh = max(dot(n, h), 0.0), vdh = max(dot(v, h), 0.0);\n" \
    "    float q = ndh * ndh * (a2 - 1.0) + 1.0;\n" \
    "    float d = a2 / (3.14159265 * q * q);\n" \
    "    float vis = 0.5 / (ndl * sqrt(ndv * ndv * (1.0 - a2) + a2)\n" \
    "                       + ndv * sqrt(ndl * ndl * (1.0 - a2) + a2));\n" \
    "    float f = 0.04 + 0.96 * pow(1.0 - vdh, 5.0);\n" \
    "    return (albedo * (1.0 - f) + 3.14159265 * d * vis * f) * ndl;\n" \
    "}\n" \
    "layout(set = 0, binding = 11) uniform sampler2D u_shadow;\n" \
    "float splat_sun_visible(float dist, vec3 v) {\n" \
    "    if (u_frame.light.w <= 0.0) return 1.0;\n" \
    "    vec2 p = u_frame.camera.xz - v.xz * dist;   /* terrain-local metres */\n" \
    "    return textureLod(u_shadow, p / u_frame.terrain.xy, 0.0).r;\n" \
    "}\n" \
    "vec3 splat_light(vec3 albedo, vec3 n, float rough, float dist, vec3 v) {\n" \
    "    vec3 c = u_frame.sun_color.rgb * splat_sun_visible(dist, v)\n" \
    "             * splat_sun_brdf(albedo, n, splat_alpha2(rough, dist), u_frame.sun_dir.xyz, v);\n" \
    "    c += albedo * splat_sky_ambient(n);\n" \
    "    vec3 fog = u_frame.sky_color.a > 0.0 ? splat_sky(-v) : u_frame.fog.rgb;\n" \
    "    c = mix(c, fog, splat_fog(dist, v));\n" \
    "    return c * u_frame.light.z;\n" \
    "}\n"

_Static_assert(SPLAT_BIND_SHADOW == 11, "LIGHTING_TEXT's u_shadow binding");
_Static_assert(SPLAT_BIND_VECTORS == 13 && SPLAT_VEC_HEADER == 8 && SPLAT_VEC_SHAPE == 4 &&
               SPLAT_VEC_CELL == 6 && SPLAT_VEC_SEG == 6 && SPLAT_VEC_POLYGON == 1 &&
               SPLAT_VEC_SMOOTHSTEP == 1, "the prelude's vector buffer layout");

const splat_light_key splat_light_keys[SPLAT_LIGHT_COUNT] = {
#define X(id, key, n, lo, hi) { key, n, lo, hi },
    SPLAT_LIGHT_KEYS(X)
#undef X
};

void splat_light_range(int k, int i, double *lo, double *hi)
{
    bool azimuth = k == SPLAT_LIGHT_SUN && i == 0;
    *lo = azimuth ? -360.0 : splat_light_keys[k].lo;
    *hi = azimuth ? 360.0 : splat_light_keys[k].hi;
}

const char SPLAT_GLSL_COMBO_COLOR[] = COMBO_COLOR_TEXT;
const char SPLAT_GLSL_TERRAIN[] = SPLAT_GLSL_COMMON;
const char SPLAT_GLSL_LIGHTING[] = LIGHTING_TEXT;
const char SPLAT_GLSL_SKY[] = SKY_TEXT;

/* abi.h SPLAT_LATTICE, as text: a vertex of the grid (a_grid = i / 32,
 * exact) is a whole number of lattice steps from its patch's corner */
#define LATTICE 32
_Static_assert(LATTICE == SPLAT_LATTICE && LATTICE == SPLAT_GRID - 1,
               "the vertex lattice (abi.h splat_push)");

const char SPLAT_GLSL_VERTEX[] =
    "#version 450\n"
    SPLAT_GLSL_COMMON
    "layout(set = 0, binding = 12) uniform sampler2D u_holes;\n"
    "out gl_PerVertex { vec4 gl_Position; float gl_ClipDistance[1]; };\n"
    "layout(location = 0) in vec2 a_grid;\n"
    "layout(location = 0) out vec3 v_rel;\n"
    "layout(location = 1) out vec2 v_uv;\n"
    "layout(location = 2) out vec3 v_local;\n"
    "void main() {\n"
    /* the vertex's lattice index (abi.h splat_push), whole and exact:
     * shared vertices of neighbouring patches are the same number;
     * patches of the quadtree may overhang the terrain: clamp to its edge */
    "    vec2 edge = u_frame.texel.xy * " SPLAT_STR(LATTICE) ".0;\n"
    "    vec2 q = min(u_push.patch_xz.xy + a_grid * u_push.patch_xz.z, edge);\n"
    "    vec2 uv = q * (u_frame.texel.zw * (1.0 / " SPLAT_STR(LATTICE) ".0));\n"
    "    float h = splat_height_at(uv);\n"
    "    vec2 step = u_frame.terrain.xy * u_frame.texel.zw * (1.0 / " SPLAT_STR(LATTICE) ".0);\n"
    "    vec2 rel_xz = (q - u_push.patch_uv.xy) * step - u_push.patch_uv.zw;\n"
    "    vec3 rel = vec3(rel_xz.x, h - u_frame.camera.y, rel_xz.y);\n"
    "    v_rel = rel;\n"
    "    v_uv = uv;\n"
    "    v_local = vec3(uv.x * u_frame.terrain.x, h, uv.y * u_frame.terrain.y);\n"
    "    gl_Position = u_frame.view_proj * vec4(rel, 1.0);\n"
    /* terrain holes: cut along the 0.5 contour (abi.h, binding 12) */
    "    gl_ClipDistance[0] = 0.5 - textureLod(u_holes, uv, 0.0).r;\n"
    "}\n";

const char SPLAT_GLSL_PRELUDE[] =
    /* the counting variant's branches are subgroup-uniform (abi.h); its
     * fragments count where the depth test let them through */
    "#ifdef SPLAT_COUNT\n"
    "#extension GL_KHR_shader_subgroup_vote : require\n"
    "#if !defined(SPLAT_COMPUTE)\n"
    "layout(early_fragment_tests) in;\n"
    "#endif\n"
    "#endif\n"
    "#ifdef SPLAT_SORT\n"
    "#extension GL_KHR_shader_subgroup_arithmetic : require\n"
    "#ifndef SPLAT_SORT_TILES\n"
    "#define SPLAT_SORT_TILES " SPLAT_STR(SORT_TILES_MIN) "\n"
    "#endif\n"
    "#define SPLAT_SORT_LANES (64 * SPLAT_SORT_TILES)\n"
    "#endif\n"
    SPLAT_GLSL_COMMON
    /* painted masks: dense layers, or the sparse quad-tree (sparse.h) */
    "#ifdef SPLAT_PAINTED_SPARSE\n"
    "layout(set = 0, binding = 2) uniform sampler2D u_painted_atlas;\n"
    "layout(set = 0, binding = 5) uniform usampler2DArray u_painted_index;\n"
    "layout(set = 0, binding = 6) uniform usampler2DArray u_painted_level;\n"
    "#else\n"
    "layout(set = 0, binding = 2) uniform sampler2DArray u_painted;\n"
    "#endif\n"
    "layout(set = 0, binding = 3) uniform sampler2D u_destruction_atlas;\n"
    "layout(set = 0, binding = 4) uniform sampler2D u_destruction_index;\n"
    COUNT_DECLS
    "#ifdef SPLAT_COMPUTE\n"
    COMPUTE_DECLS
    "#else\n"
    "layout(location = 0) in vec3 v_rel;\n"
    "layout(location = 1) in vec2 v_uv;\n"
    "layout(location = 2) in vec3 v_local;\n"
    "#endif\n"
    "#if defined(SPLAT_COMPUTE)\n"
    "#elif defined(SPLAT_MULTIPASS)\n"
    "layout(location = 0) out vec4 o_albedo;   /* rgb albedo, a mask */\n"
    "layout(location = 1) out vec4 o_normal;   /* xyz normal, a mask */\n"
    "layout(location = 2) out vec4 o_misc;     /* roughness, height, distance */\n"
    "#else\n"
    "layout(location = 0) out vec4 o_color;\n"
    "#endif\n"
    /* the view: fixed at pipeline creation, or read per frame (abi.h) */
    "layout(constant_id = " SPLAT_STR(SPLAT_SPEC_VIEW) ") const uint splat_spec_view = "
    SPLAT_STR(SPLAT_SPEC_VIEW_DYNAMIC) ";\n"
    /* the CPU shading LOD (abi.h SPLAT_SPEC_LOD): 0 on GPUs */
    "layout(constant_id = " SPLAT_STR(SPLAT_SPEC_LOD) ") const uint splat_spec_lod = 0u;\n"
    /* a footprint's derivative (fwidth's leaves, ir.h IR_DINPUT_FOOTPRINT):
     * itself, or 0 under the CPU shading LOD, so the ramps are the plain
     * ones and the derivatives' code is dead */
    "float splat_fp(float d) { return splat_spec_lod != 0u ? 0.0 : d; }\n"
    "vec2 splat_fp(vec2 d) { return splat_spec_lod != 0u ? vec2(0.0) : d; }\n"
    "vec3 splat_fp(vec3 d) { return splat_spec_lod != 0u ? vec3(0.0) : d; }\n"
    "vec4 splat_fp(vec4 d) { return splat_spec_lod != 0u ? vec4(0.0) : d; }\n"
    /* view.shading_lod: 1 under the CPU shading LOD, else 0; a constant
     * once the pipeline is made, so the side of a mix or select on it
     * that the device does not draw is dead code (nodes/detile.sg) */
    "float splat_shading_lod() { return splat_spec_lod != 0u ? 1.0 : 0.0; }\n"
    "uint splat_view() {\n"
    "    return splat_spec_view == " SPLAT_STR(SPLAT_SPEC_VIEW_DYNAMIC)
    " ? u_frame.view.x : splat_spec_view;\n"
    "}\n"
    /* A composite's branch condition, made uniform over each 2x2 quad:
     * true for all four pixels if it holds for any.  It kept implicit
     * derivatives defined inside the branch (NVIDIA picked wrong mip
     * levels at material borders without it); material samples take the
     * compiler's gradients now, and it stays because a quad's lanes run
     * together anyway.  Fine derivatives of a 0/1 flag are the OR with
     * the horizontal, then the vertical neighbour; the caller is in
     * quad-uniform control flow by induction.  Pixels with weight 0 that
     * run the branch add 0 * surface. */
    "#if defined(SPLAT_COUNT)\n"
    "bool splat_quad_any(bool c) {\n"
    "    bool a = subgroupAny(c);\n"
    "    splat_n_branches += 1u;\n"
    "    if (a == subgroupAll(c)) splat_n_uniform += 1u;   /* the subgroup agreed */\n"
    "    return a;\n"
    "}\n"
    "#elif defined(SPLAT_COMPUTE)\n"
    "bool splat_quad_any(bool c) { return c; }\n"
    "#else\n"
    "bool splat_quad_any(bool c) {\n"
    "    float f = c ? 1.0 : 0.0;\n"
    "    f = max(f, abs(dFdxFine(f)));\n"
    "    f = max(f, abs(dFdyFine(f)));\n"
    "    return f > 0.0;\n"
    "}\n"
    "#endif\n"
    /* A composite's layer j: its surface block runs where this is true
     * (abi.h SPLAT_SORT: the sort's first run only collects the layers) */
    "#ifdef SPLAT_SORT\n"
    "bool splat_sorting = false;\n"
    "uint splat_layer_bits = 0u;\n"
    "bool splat_surface(uint j, bool c) {\n"
    "    if (!splat_sorting) return splat_quad_any(c);\n"
    "    if (c) splat_layer_bits |= 1u << (j & 31u);\n"
    "    return false;\n"
    "}\n"
    "bool splat_opaque(uint j) {\n"
    "    if (!splat_sorting) return true;\n"
    "    splat_layer_bits |= 1u << (j & 31u);\n"
    "    return false;\n"
    "}\n"
    "#elif defined(SPLAT_COUNT)\n"
    /* the counting variant: the layer whose block runs, for the layers
     * view's per-pixel set (splat_count_layer) */
    "uint splat_cur_layer = 0xffffffffu;\n"
    "bool splat_surface(uint j, bool c) {\n"
    "    splat_cur_layer = j;\n"
    "    return splat_quad_any(c);\n"
    "}\n"
    "bool splat_opaque(uint j) {\n"
    "    splat_cur_layer = j;\n"
    "    return true;\n"
    "}\n"
    "#else\n"
    "#define splat_surface(j, c) splat_quad_any(c)\n"
    "#define splat_opaque(j) true\n"
    "#endif\n"
    /* The shading pass's terrain inputs, smooth between texels (issue 31):
     * the uniform cubic B-spline over the heightfield's texels (C2, and a
     * convex combination of the 4x4 texels around uv, so the analysis's
     * texel min / max bound it: terrain.c), and Listing 1's cross filter
     * (Andersson 2007, with the texel aspect in metres) on that surface.
     * H(x-1) - H(x+1) is the same B-spline over the per-texel differences
     * h(i-1) - h(i+1), so the normal takes the 6x6 texels around uv: 9
     * gathers, each 2x2 texels, no filtering, the weights in float (the
     * CPU twins: terrain.c splat_terrain_height / _normal).  The mesh and
     * its depth stay bilinear (splat_height_at). */
    "vec4 splat_bspline_w(float t) {\n"
    "    float s = 1.0 - t, t2 = t * t, t3 = t2 * t;\n"
    "    return vec4(s * s * s, 3.0 * t3 - 6.0 * t2 + 4.0,\n"
    "                -3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0, t3) * (1.0 / 6.0);\n"
    "}\n"
    /* texels (k.x, k.y) .. (k.x+1, k.y+1), row k.y in .xy, row k.y+1 in
     * .zw; gathered at their shared corner, so rounding picks no other */
    "vec4 splat_quad(vec2 k) {\n"
    "    return textureGather(u_height, (k + 1.0) * u_frame.texel.zw).wzxy;\n"
    "}\n"
    /* texel coordinate of uv, split into the first tap - 1 and fractions */
    "vec2 splat_bspline_at(vec2 uv, out vec4 wx, out vec4 wz) {\n"
    "    vec2 x = clamp(uv * u_frame.texel.xy - 0.5, vec2(-1.0), u_frame.texel.xy);\n"
    "    vec2 i = floor(x), f = x - i;\n"
    "    wx = splat_bspline_w(f.x);\n"
    "    wz = splat_bspline_w(f.y);\n"
    "    return i;\n"
    "}\n"
    "float splat_height_smooth_at(vec2 uv) {\n"
    "    vec4 wx, wz;\n"
    "    vec2 i = splat_bspline_at(uv, wx, wz);\n"
    "    vec4 a = splat_quad(i + vec2(-1.0, -1.0)), b = splat_quad(i + vec2(1.0, -1.0));\n"
    "    vec4 c = splat_quad(i + vec2(-1.0, 1.0)), d = splat_quad(i + vec2(1.0, 1.0));\n"
    "    vec4 r = vec4(dot(wx, vec4(a.xy, b.xy)), dot(wx, vec4(a.zw, b.zw)),\n"
    "                  dot(wx, vec4(c.xy, d.xy)), dot(wx, vec4(c.zw, d.zw)));\n"
    "    return dot(wz, r) * u_frame.terrain.z + u_frame.terrain.w;\n"
    "}\n"
    /* rows z-2 .. z+3 of columns x-2 .. x+3: row r is lo[r] (columns
     * x-2 .. x+1) and hi[r] (x .. x+3) */
    "void splat_terrain_at(vec2 uv, out float h, out vec3 n) {\n"
    "    vec4 wx, wz;\n"
    "    vec2 i = splat_bspline_at(uv, wx, wz);\n"
    "    vec4 lo[6], hi[6];\n"
    "    for (int q = 0; q < 3; q++) {\n"
    "        vec2 k = i + vec2(-2.0, float(2 * q - 2));\n"
    "        vec4 a = splat_quad(k), b = splat_quad(k + vec2(2.0, 0.0));\n"
    "        vec4 c = splat_quad(k + vec2(4.0, 0.0));\n"
    "        lo[2 * q] = vec4(a.xy, b.xy);  hi[2 * q] = vec4(b.xy, c.xy);\n"
    "        lo[2 * q + 1] = vec4(a.zw, b.zw);  hi[2 * q + 1] = vec4(b.zw, c.zw);\n"
    "    }\n"
    "    vec4 m[6];   /* columns x-1 .. x+2 */\n"
    "    for (int r = 0; r < 6; r++) m[r] = vec4(lo[r].yzw, hi[r].z);\n"
    "    vec4 ha, ga, gb;\n"
    "    for (int r = 0; r < 4; r++) {\n"
    "        ha[r] = dot(wx, m[r + 1]);\n"
    "        ga[r] = dot(wx, lo[r + 1] - hi[r + 1]);\n"
    "        gb[r] = dot(wx, m[r] - m[r + 2]);\n"
    "    }\n"
    "    h = dot(wz, ha) * u_frame.terrain.z + u_frame.terrain.w;\n"
    "    vec2 t = u_frame.texel.zw;\n"
    "    float dx = u_frame.terrain.x * t.x;\n"
    "    float dz = u_frame.terrain.y * t.y;\n"
    "    n = normalize(vec3(dot(wz, ga) * u_frame.terrain.z / dx, 2.0,\n"
    "                       dot(wz, gb) * u_frame.terrain.z / dz));\n"
    "}\n"
    "vec3 splat_normal_at(vec2 uv) {\n"
    "    float h;\n"
    "    vec3 n;\n"
    "    splat_terrain_at(uv, h, n);\n"
    "    return n;\n"
    "}\n"
    /* compute, and fragments with gradients: computed once per pixel
     * before the composite (for the derivatives) */
    "#if defined(SPLAT_COMPUTE)\n"
    "vec3 splat_normal() { return splat_nrm; }\n"
    "float splat_height() { return splat_hgt; }\n"
    "#elif defined(SPLAT_GRADIENTS)\n"
    "vec3 splat_nrm, splat_dpdx, splat_dpdy;  /* FRAGMENT_MAIN sets them */\n"
    "float splat_hgt;\n"
    "vec3 splat_normal() { return splat_nrm; }\n"
    "float splat_height() { return splat_hgt; }\n"
    "#else\n"
    "vec3 splat_normal() { return splat_normal_at(v_uv); }\n"
    "float splat_height() { return splat_height_smooth_at(v_uv); }\n"
    "#endif\n"
    "float splat_slope() { return 1.0 - splat_normal().y; }\n"
    /* terrain.cavity (splat_terrain_cavity is its CPU twin): the mean of
     * 4 diagonal taps 2 texels away minus the height here, in metres;
     * positive in hollows, negative on ridges */
    "float splat_cavity() {\n"
    "    vec2 t = 2.0 * u_frame.texel.zw;\n"
    "    float s = splat_texture0(u_height, v_uv - t).r\n"
    "            + splat_texture0(u_height, v_uv + t).r\n"
    "            + splat_texture0(u_height, v_uv + vec2(t.x, -t.y)).r\n"
    "            + splat_texture0(u_height, v_uv + vec2(-t.x, t.y)).r;\n"
    "    return (0.25 * s - splat_texture0(u_height, v_uv).r) * u_frame.terrain.z;\n"
    "}\n"
    "vec3 splat_position() { return vec3(v_local.x, splat_height(), v_local.z); }\n"
    "vec2 splat_uv() { return v_uv; }\n"
    "vec3 splat_offset() { return v_rel; }\n"
    /* undergrowth masks: seen from SPLAT_UG_DISTANCE straight above */
    "#ifdef SPLAT_UNDERGROWTH\n"
    "float splat_view_distance() { return " SPLAT_STR(SPLAT_UG_DISTANCE) "; }\n"
    "vec3 splat_view_direction() { return vec3(0.0, 1.0, 0.0); }\n"
    /* the far atlas bake: as the CPU reference (far_atlas.c) sees it */
    "#elif defined(SPLAT_FAR_BAKE)\n"
    "float splat_view_distance() { return " SPLAT_STR(FAR_ATLAS_BAKE_DISTANCE) "; }\n"
    "vec3 splat_view_direction() { return vec3(0.0, 1.0, 0.0); }\n"
    "#else\n"
    "float splat_view_distance() { return length(v_rel); }\n"
    /* v_rel = surface - camera (terrain-local axes), so surface -> camera
     * is its negation; the camera exactly on the surface reads straight up */
    "vec3 splat_view_direction() {\n"
    "    float l = length(v_rel);\n"
    "    return l > 0.0 ? -v_rel / l : vec3(0.0, 1.0, 0.0);\n"
    "}\n"
    "#endif\n"
    /* Position derivatives (Moore 2018, "Shading Pass Derivatives"): the
     * plane through the pixel's position with the terrain normal (Listing
     * 1), intersected with the ray from the camera (the origin of
     * camera-relative space) through the centre of the pixel to the right
     * / below; the difference to the position is what a quad's dFdx / dFdy
     * of the position would be on that plane.  A ray that misses the plane
     * (grazing, or parallel) takes the far cap t = 1e4: the coarsest mips,
     * as a quad would pick next to a silhouette.  Both stages use it, so
     * the forward and screen paths pick the same mip levels (a quad's
     * finite differences of an interpolated position differ at grazing
     * angles and across triangle edges). */
    "vec3 splat_unproject(vec2 px, float depth) {\n"
    "    vec2 ndc = px / u_frame.screen.xy * 2.0 - 1.0;\n"
    "    vec4 p = u_frame.inv_view_proj * vec4(ndc, depth, 1.0);\n"
    "    return p.xyz / p.w;\n"
    "}\n"
    "vec3 splat_plane_step(vec3 n, vec3 p, vec2 px, float depth) {\n"
    "    vec3 q = splat_unproject(px, depth);\n"
    "    float t = dot(n, p) / dot(n, q);\n"
    "    t = t > 0.0 ? min(t, 1e4) : 1e4;\n"
    "    return q * t - p;\n"
    "}\n"
    /* Screen-space derivatives of the inputs (d/dx: axis 0, d/dy: 1), the
     * leaves ir_differentiate writes.  All follow from the position's.
     * normal, slope, destruction and painted masks have derivative 0 (the
     * pass writes constants for them). */
    /* A sample with explicit gradients (IR SAMPLE_GRAD), one textureLod
     * tap: the level the Vulkan spec gives for textureGrad without
     * anisotropy is log2 of the longer gradient in texels, which blurs
     * grazing views (a footprint many times longer than wide takes the
     * long side's mip).  This takes the level of the footprint's short
     * side (its area over the long side) where that is finer, at most one
     * level below the long side's: anisotropy 2 for one tap, sharper
     * cliffs and ground at grazing angles with little aliasing, and the
     * same level as before where the footprint is round.  textureLod, not
     * textureGrad with an anisotropic sampler: NVIDIA runs textureGrad
     * several times slower (H100, colorado top-down forward: 14.7 ms with
     * textureGrad against 9.7 ms with implicit derivatives). */
    "float splat_grad_lod(vec2 a, vec2 b) {\n"
    "    float r = max(max(dot(a, a), dot(b, b)), 1e-30);\n"
    "    float area = max(abs(a.x * b.y - a.y * b.x), 1e-30);\n"
    "    float major = 0.5 * log2(r);\n"
    "    return max(major - 1.0, log2(area) - major);\n"
    "}\n"
    "vec4 splat_texture_grad(sampler2D t, vec2 uv, vec2 dx, vec2 dy) {\n"
    "    vec2 s = vec2(textureSize(t, 0));\n"
    "    return textureLod(t, uv, splat_grad_lod(dx * s, dy * s));\n"
    "}\n"
    /* the same on a layer of a texture array: uvl = (uv, layer) */
    "vec4 splat_texture_grad(sampler2DArray t, vec3 uvl, vec2 dx, vec2 dy) {\n"
    "    vec2 s = vec2(textureSize(t, 0).xy);\n"
    "    return textureLod(t, uvl, splat_grad_lod(dx * s, dy * s));\n"
    "}\n"
    "#if defined(SPLAT_COMPUTE) || defined(SPLAT_GRADIENTS)\n"
    "vec3 splat_d_rel(int a) { return a == 0 ? splat_dpdx : splat_dpdy; }\n"
    "#else\n"
    "vec3 splat_d_rel(int a) { return vec3(0.0); }   /* no gradients taken */\n"
    "#endif\n"
    "vec3 splat_d_position(int a) { return splat_d_rel(a); }\n"
    "float splat_d_height(int a) { return splat_d_rel(a).y; }\n"
    "vec2 splat_d_uv(int a) { return splat_d_rel(a).xz / u_frame.terrain.xy; }\n"
    /* normal and slope (footprints only: .sg's fwidth): the smooth normal
     * at the neighbouring pixel's uv minus this one's, what a quad's dFdx
     * of it would be (9 more gathers; none where no gradients are taken) */
    "vec3 splat_d_normal(int a) {\n"
    "    vec2 du = splat_d_uv(a);\n"
    "    if (du == vec2(0.0)) return vec3(0.0);\n"
    "    return splat_normal_at(splat_uv() + du) - splat_normal();\n"
    "}\n"
    "float splat_d_slope(int a) { return -splat_d_normal(a).y; }\n"
    "#ifdef SPLAT_FAR_BAKE\n"   /* the reference's view does not move */
    "float splat_d_view_distance(int a) { return 0.0; }\n"
    "vec3 splat_d_view_direction(int a) { return vec3(0.0); }\n"
    "#else\n"
    "float splat_d_view_distance(int a) {\n"
    "    float l = length(v_rel);\n"
    "    return l > 0.0 ? dot(v_rel, splat_d_rel(a)) / l : 0.0;\n"
    "}\n"
    "vec3 splat_d_view_direction(int a) {\n"
    "    float l = length(v_rel);\n"
    "    if (!(l > 0.0)) return vec3(0.0);\n"
    "    vec3 r = v_rel / l, d = splat_d_rel(a);\n"
    "    return (r * dot(r, d) - d) / l;\n"
    "}\n"
    "#endif\n"
    /* The counting variant's hooks (abi.h); nothing elsewhere. */
    "#if defined(SPLAT_COUNT)\n"
    /* the layers view: the set of layers the pixel needs (weight > 0),
     * layer j as bit j (48 and up as bit 47); a flat composite has no
     * layer blocks, its layers come in order */
    "uint splat_need_lo = 0u, splat_need_hi = 0u;\n"
    "void splat_count_layer(float w) {\n"
    "#ifndef SPLAT_SORT\n"
    "    uint j = splat_cur_layer != 0xffffffffu ? splat_cur_layer : splat_n_evaluated;\n"
    "    splat_cur_layer = 0xffffffffu;\n"
    "    if (w > 0.0) {\n"
    "        if (j < 24u) splat_need_lo |= 1u << j;\n"
    "        else splat_need_hi |= 1u << min(j - 24u, 23u);\n"
    "    }\n"
    "#endif\n"
    "    splat_n_evaluated += 1u;\n"
    "    if (w > 0.0) splat_n_needed += 1u;\n"
    "}\n"
    "void splat_count_samples(uint n) { splat_n_samples += n; }\n"
    "#else\n"
    "void splat_count_layer(float w) {}\n"
    "void splat_count_samples(uint n) {}\n"
    "#endif\n"
    /* The cost view (shader complexity): texture samples of this pixel as
     * a heat colour, 0 black, 4 blue, 8 green, 16 yellow, 32 red, 64 and
     * more white; only the counting variant counts (0 elsewhere). */
    "vec3 splat_heat(float x) {\n"
    "    float t = clamp(log2(1.0 + x) / 6.0, 0.0, 1.0) * 5.0;\n"
    "    vec3 k[6] = vec3[6](vec3(0.0), vec3(0.0, 0.2, 1.0), vec3(0.0, 0.9, 0.2),\n"
    "                        vec3(1.0, 0.9, 0.0), vec3(1.0, 0.1, 0.0), vec3(1.0));\n"
    "    int i = min(int(t), 4);\n"
    "    return mix(k[i], k[i + 1], t - float(i));\n"
    "}\n"
    /* The tiles view: the combination that shades the pixel, darker on
     * the edges of its 8x8 tile in compute (the tile's choice); the
     * patch's combination in fragments, as the combos view. */
    "vec3 splat_combo_color(uint id);\n"
    "vec3 splat_tile_color() {\n"
    "#ifdef SPLAT_COMPUTE\n"
    "    uvec2 q = uvec2(splat_pixel) & 7u;\n"
    "    bool edge = q.x == 0u || q.y == 0u;\n"
    "    return splat_combo_color(u_push.info.y) * (edge ? 0.6 : 1.0);\n"
    "#else\n"
    "    return splat_combo_color(u_push.info.y);\n"
    "#endif\n"
    "}\n"
    "#if defined(SPLAT_COUNT)\n"
    "vec3 splat_cost_color() { return splat_heat(float(splat_n_samples)); }\n"
    /* The layers view (counting variant, read back as floats, exact to
     * 2^24): r layers 0-23 of the needed set, g layers 24-47, b 256 times
     * 16 plus the combination (push info.y), plus the layers this pixel's
     * lane evaluated (its subgroup ran them; at most 255);
     * tests/bench/bench_lanes.c predicts other lane assignments from it */
    "vec3 splat_layers_color() {\n"
    "    return vec3(float(splat_need_lo), float(splat_need_hi),\n"
    "                256.0 * float(16u + u_push.info.y) + float(min(splat_n_evaluated, 255u)));\n"
    "}\n"
    "#else\n"
    "vec3 splat_cost_color() { return splat_heat(0.0); }\n"
    "vec3 splat_layers_color() { return vec3(0.0); }\n"
    "#endif\n"
    "#ifdef SPLAT_PAINTED_SPARSE\n"
    SPARSE_GLSL_FUNCTIONS
    "float splat_painted(int layer) {\n"
    "#ifdef SPLAT_PAINTED_PLACED\n"
    /* a placed mask: its own uv over its rectangle, 0 outside */
    "    vec4 r = splat_painted_rect[layer];\n"
    "    vec2 muv = (v_uv - r.xy) * r.zw;\n"
    "    if (any(lessThan(muv, vec2(0.0))) || any(greaterThan(muv, vec2(1.0)))) return 0.0;\n"
    "    return splat_sparse_painted(muv, splat_painted_size[layer], layer);\n"
    "#else\n"
    "    return splat_sparse_painted(v_uv, u_frame.texel.xy, layer);\n"
    "#endif\n"
    "}\n"
    "#else\n"
    "float splat_painted(int layer) {\n"
    "    return splat_texture0(u_painted, vec3(v_uv, float(layer))).r;\n"
    "}\n"
    "#endif\n"
    /* The vector shapes (vector.c, abi.h "vector shapes' buffer"):
     * shape s's distance at the surface point from its grid cell's
     * segments, a polygon's inside parity from the cell's reference point;
     * mask and across from the distance as splat_vector_profile does. */
    "#ifdef SPLAT_VECTORS\n"
    "layout(set = 0, binding = 13, std430) readonly buffer "
    "splat_vectors_block { uint w[]; } u_vectors;\n"
    "float splat_vf(uint i) { return uintBitsToFloat(u_vectors.w[i]); }\n"
    "float splat_vector_distance(int s) {\n"
    "    vec2 p = v_local.xz;\n"
    "    uint ncx = u_vectors.w[0], ncz = u_vectors.w[1], nsh = u_vectors.w[2];\n"
    "    vec2 g = floor((p - vec2(splat_vf(5u), splat_vf(6u))) / splat_vf(7u));\n"
    "    if (g.x < 0.0 || g.y < 0.0 || g.x >= float(ncx) || g.y >= float(ncz)) return 1e30;\n"
    "    uint cells = 8u + 4u * nsh;\n"
    "    uint cb = cells + 6u * (uint(g.y) * ncx + uint(g.x));\n"
    "    uint first = u_vectors.w[cb], count = u_vectors.w[cb + 1u];\n"
    "    bool inside = ((u_vectors.w[cb + 2u] >> uint(s)) & 1u) != 0u;\n"
    "    vec2 r = vec2(splat_vf(cb + 4u), splat_vf(cb + 5u));\n"
    "    uint ent = cells + 6u * ncx * ncz, segs = ent + u_vectors.w[4];\n"
    "    float d = 1e30;\n"
    "    for (uint k = 0u; k < count; k++) {\n"
    "        uint b = segs + 6u * u_vectors.w[ent + first + k];\n"
    "        if (u_vectors.w[b + 4u] != uint(s)) continue;\n"
    "        vec2 a = vec2(splat_vf(b), splat_vf(b + 1u));\n"
    "        vec2 ab = vec2(splat_vf(b + 2u), splat_vf(b + 3u)) - a, ap = p - a;\n"
    "        float l2 = dot(ab, ab);\n"
    "        float t = l2 > 0.0 ? clamp(dot(ap, ab) / l2, 0.0, 1.0) : 0.0;\n"
    "        d = min(d, length(ap - t * ab));\n"
    "        vec2 pr = r - p, ar = r - a, pb = a + ab - p, pa = -ap;\n"
    "        float o1 = ab.x * ap.y - ab.y * ap.x, o2 = ab.x * ar.y - ab.y * ar.x;\n"
    "        float o3 = pr.x * pa.y - pr.y * pa.x, o4 = pr.x * pb.y - pr.y * pb.x;\n"
    "        if ((o1 > 0.0) != (o2 > 0.0) && (o3 > 0.0) != (o4 > 0.0)) inside = !inside;\n"
    "    }\n"
    "    uint kind = u_vectors.w[8u + 4u * uint(s) + 2u] >> 8u;\n"
    "    return kind == 1u && inside ? 0.0 : d;\n"
    "}\n"
    "float splat_vector_mask(int s) {\n"
    "    uint b = 8u + 4u * uint(s);\n"
    "    float hw = splat_vf(b), f = splat_vf(b + 1u), d = splat_vector_distance(s);\n"
    "    float t = f > 0.0 ? clamp((d - hw) / f, 0.0, 1.0) : (d > hw ? 1.0 : 0.0);\n"
    "    if ((u_vectors.w[b + 2u] & 255u) == 1u) t = t * t * (3.0 - 2.0 * t);\n"
    "    return 1.0 - t;\n"
    "}\n"
    "float splat_vector_across(int s) {\n"
    "    uint b = 8u + 4u * uint(s);\n"
    "    float reach = max(splat_vf(b) + splat_vf(b + 1u), 1e-6);\n"
    "    return clamp(splat_vector_distance(s) / reach, 0.0, 1.0);\n"
    "}\n"
    "#endif\n"
    "float splat_destruction() {\n"
    "    if (u_frame.destruction.w <= 0.0) return 0.0;\n"
    "    vec2 p = (v_local.xz - u_frame.destruction.xy) / u_frame.destruction.z;\n"
    "    if (any(lessThan(p, vec2(0.0))) ||\n"
    "        any(greaterThanEqual(p, vec2(u_frame.destruction.w)))) return 0.0;\n"
    "    vec4 e = texelFetch(u_destruction_index, ivec2(p), 0);\n"
    "    if (e.a < 0.5) return 0.0;\n"
    "    float tile = u_frame.destruction_atlas.x;\n"
    "    vec2 inner = clamp(fract(p) * tile, vec2(0.5), vec2(tile - 0.5));\n"
    "    vec2 px = floor(e.rg * 255.0 + 0.5) * tile + inner;\n"
    "    return splat_texture0(u_destruction_atlas, px / u_frame.destruction_atlas.y).r;\n"
    "}\n"
    LIGHTING_TEXT
    COMBO_COLOR_TEXT
    "void splat_finish(vec3 albedo, vec3 normal, float rough, float height,\n"
    "                  float coverage) {\n"
    "#ifdef SPLAT_SORT\n"
    "    if (splat_sorting) return;\n"
    "#endif\n"
    "    float dist = splat_view_distance();\n"
    "#if defined(SPLAT_UNDERGROWTH)\n"
    "    splat_ug_albedo = albedo;\n"
    "#elif defined(SPLAT_FAR_BAKE)\n"
    "    splat_far_albedo = albedo;\n"
    "    splat_far_normal = normal;\n"
    "    splat_far_rough = rough;\n"
    "#elif defined(SPLAT_MULTIPASS)\n"
    "    o_albedo = vec4(albedo, coverage);\n"
    "    o_normal = vec4(normal, coverage);\n"
    "    o_misc = vec4(rough, height, dist, coverage);\n"
    "#else\n"
    "    vec3 n = normalize(normal), to_cam = splat_view_direction();\n"
    "    vec3 c;\n"
    "    switch (splat_view()) {\n"
    SPLAT_VIEWS(SPLAT_VIEW_CASE_FORWARD)   /* abi.h */
    "    default: c = splat_light(albedo, n, rough, dist, to_cam); break;\n"
    "    }\n"
    "    o_color = vec4(c, 1.0);\n"
    "#endif\n"
    "}\n"
    "#if defined(SPLAT_UNDERGROWTH)\n"
    UG_MAIN
    "#elif defined(SPLAT_FAR_BAKE)\n"
    FAR_MAIN
    "#elif defined(SPLAT_COMPUTE)\n"
    COMPUTE_MAIN
    "#elif defined(SPLAT_GRADIENTS) || defined(SPLAT_COUNT)\n"
    FRAGMENT_MAIN
    "#endif\n";

void splat_normal_filter(double hl, double hr, double hd, double hu,
                         double maxh, double dx, double dz, double n[3])
{
    n[0] = (hl - hr) * maxh / dx;
    n[1] = 2.0;
    n[2] = (hd - hu) * maxh / dz;
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int i = 0; i < 3; i++)
        n[i] /= len;
}
