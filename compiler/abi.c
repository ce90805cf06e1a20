/* abi.c — the shared GLSL text of the shader ABI (see abi.h). */
#include "abi.h"
#include "sparse.h"

#include <math.h>


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
    "} u_frame;\n"                                                          \
    "layout(push_constant, std430) uniform splat_push_block {\n"            \
    "    vec4 patch_xz;\n"                                                  \
    "    vec4 patch_uv;\n"                                                  \
    "    uvec4 info;\n"                                                     \
    "} u_push;\n"                                                           \
    "float splat_height_at(vec2 uv) {\n"                                    \
    "    return texture(u_height, uv).r * u_frame.terrain.z + u_frame.terrain.w;\n" \
    "}\n"

#define COMBO_COLOR_TEXT \
    "vec3 splat_combo_color(uint id) {\n" \
    "    uint h = id * 2654435761u + 0x9e3779b9u;\n" \
    "    h ^= h >> 15; h *= 0x85ebca6bu; h ^= h >> 13;\n" \
    "    return vec3(float(h & 255u), float((h >> 8) & 255u),\n" \
    "                float((h >> 16) & 255u)) / 255.0 * 0.8 + 0.2;\n" \
    "}\n"

#define LIGHTING_TEXT \
    "vec3 splat_light(vec3 albedo, vec3 n, float rough, float dist) {\n" \
    "    vec3 l = u_frame.sun_dir.xyz;\n" \
    "    float ndl = max(dot(n, l), 0.0);\n" \
    "    float sky = 0.5 + 0.5 * n.y;\n" \
    "    vec3 c = albedo * (u_frame.sun_color.rgb * ndl\n" \
    "                       + u_frame.sky_color.rgb * sky);\n" \
    "    c += u_frame.sun_color.rgb * 0.04 * (1.0 - rough) * pow(ndl, 8.0);\n" \
    "    float f = 1.0 - exp(-max(dist, 0.0) * u_frame.fog.a);\n" \
    "    return mix(c, u_frame.fog.rgb, f);\n" \
    "}\n"

const char SPLAT_GLSL_COMBO_COLOR[] = COMBO_COLOR_TEXT;
const char SPLAT_GLSL_LIGHTING[] = LIGHTING_TEXT;

const char SPLAT_GLSL_VERTEX[] =
    "#version 450\n"
    SPLAT_GLSL_COMMON
    "layout(location = 0) in vec2 a_grid;\n"
    "layout(location = 0) out vec3 v_rel;\n"
    "layout(location = 1) out vec2 v_uv;\n"
    "layout(location = 2) out vec3 v_local;\n"
    "void main() {\n"
    /* patches of the quadtree may overhang the terrain: clamp to its edge */
    "    vec2 g = min(a_grid, (1.0 - u_push.patch_uv.xy) / u_push.patch_uv.zw);\n"
    "    vec2 uv = u_push.patch_uv.xy + g * u_push.patch_uv.zw;\n"
    "    float h = splat_height_at(uv);\n"
    "    vec2 rel_xz = u_push.patch_xz.xy + g * u_push.patch_xz.zw;\n"
    "    vec3 rel = vec3(rel_xz.x, h - u_frame.camera.y, rel_xz.y);\n"
    "    v_rel = rel;\n"
    "    v_uv = uv;\n"
    "    v_local = vec3(uv.x * u_frame.terrain.x, h, uv.y * u_frame.terrain.y);\n"
    "    gl_Position = u_frame.view_proj * vec4(rel, 1.0);\n"
    "}\n";

const char SPLAT_GLSL_PRELUDE[] =
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
    "layout(location = 0) in vec3 v_rel;\n"
    "layout(location = 1) in vec2 v_uv;\n"
    "layout(location = 2) in vec3 v_local;\n"
    "#ifdef SPLAT_MULTIPASS\n"
    "layout(location = 0) out vec4 o_albedo;   /* rgb albedo, a mask */\n"
    "layout(location = 1) out vec4 o_normal;   /* xyz normal, a mask */\n"
    "layout(location = 2) out vec4 o_misc;     /* roughness, height, distance */\n"
    "#else\n"
    "layout(location = 0) out vec4 o_color;\n"
    "#endif\n"
    /* the view: fixed at pipeline creation, or read per frame (abi.h) */
    "layout(constant_id = 0) const uint splat_spec_view = 0xffffffffu;\n"
    "uint splat_view() {\n"
    "    return splat_spec_view == 0xffffffffu ? u_frame.view.x : splat_spec_view;\n"
    "}\n"
    /* A composite's branch condition, made uniform over each 2x2 quad:
     * true for all four pixels if it holds for any.  Textures sampled
     * inside the branch take implicit derivatives, which are undefined
     * when only part of a quad runs it (NVIDIA then picks wrong mip levels
     * at material borders).  Fine derivatives of a 0/1 flag are the OR
     * with the horizontal, then the vertical neighbour; the caller is in
     * quad-uniform control flow by induction.  Pixels with weight 0 that
     * run the branch add 0 * surface. */
    "bool splat_quad_any(bool c) {\n"
    "    float f = c ? 1.0 : 0.0;\n"
    "    f = max(f, abs(dFdxFine(f)));\n"
    "    f = max(f, abs(dFdyFine(f)));\n"
    "    return f > 0.0;\n"
    "}\n"
    /* Listing 1 (seed 000), with the texel aspect in metres. */
    "vec3 splat_normal_at(vec2 uv) {\n"
    "    vec2 t = u_frame.texel.zw;\n"
    "    float hd = texture(u_height, uv + vec2(0.0, -t.y)).r;\n"
    "    float hl = texture(u_height, uv + vec2(-t.x, 0.0)).r;\n"
    "    float hr = texture(u_height, uv + vec2(t.x, 0.0)).r;\n"
    "    float hu = texture(u_height, uv + vec2(0.0, t.y)).r;\n"
    "    float dx = u_frame.terrain.x * t.x;\n"
    "    float dz = u_frame.terrain.y * t.y;\n"
    "    vec3 n = vec3((hl - hr) * u_frame.terrain.z / dx, 2.0,\n"
    "                  (hd - hu) * u_frame.terrain.z / dz);\n"
    "    return normalize(n);\n"
    "}\n"
    "float splat_height() { return splat_height_at(v_uv); }\n"
    "vec3 splat_normal() { return splat_normal_at(v_uv); }\n"
    "float splat_slope() { return 1.0 - splat_normal().y; }\n"
    "vec3 splat_position() { return vec3(v_local.x, splat_height(), v_local.z); }\n"
    "vec2 splat_uv() { return v_uv; }\n"
    "float splat_view_distance() { return length(v_rel); }\n"
    /* v_rel = surface - camera (terrain-local axes), so surface -> camera
     * is its negation; the camera exactly on the surface reads straight up */
    "vec3 splat_view_direction() {\n"
    "    float l = length(v_rel);\n"
    "    return l > 0.0 ? -v_rel / l : vec3(0.0, 1.0, 0.0);\n"
    "}\n"
    "#ifdef SPLAT_PAINTED_SPARSE\n"
    SPARSE_GLSL_FUNCTIONS
    "float splat_painted(int layer) {\n"
    "    return splat_sparse_painted(v_uv, u_frame.texel.xy, layer);\n"
    "}\n"
    "#else\n"
    "float splat_painted(int layer) {\n"
    "    return texture(u_painted, vec3(v_uv, float(layer))).r;\n"
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
    "    return texture(u_destruction_atlas, px / u_frame.destruction_atlas.y).r;\n"
    "}\n"
    LIGHTING_TEXT
    COMBO_COLOR_TEXT
    "void splat_finish(vec3 albedo, vec3 normal, float rough, float height,\n"
    "                  float coverage) {\n"
    "    float dist = splat_view_distance();\n"
    "#ifdef SPLAT_MULTIPASS\n"
    "    o_albedo = vec4(albedo, coverage);\n"
    "    o_normal = vec4(normal, coverage);\n"
    "    o_misc = vec4(rough, height, dist, coverage);\n"
    "#else\n"
    "    vec3 n = normalize(normal);\n"
    "    vec3 c;\n"
    "    switch (splat_view()) {\n"
    "    case 1u: c = splat_combo_color(u_push.info.y); break;\n"
    "    case 2u: c = splat_combo_color(u_push.info.x + 1000u); break;\n"
    "    case 3u: c = n * 0.5 + 0.5; break;\n"
    "    case 4u: c = vec3(splat_slope()); break;\n"
    "    case 6u: c = albedo; break;\n"
    "    default: c = splat_light(albedo, n, rough, dist); break;\n"
    "    }\n"
    "    o_color = vec4(c, 1.0);\n"
    "#endif\n"
    "}\n";

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
