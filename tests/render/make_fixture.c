/* make_fixture — writes a small, valid shader pack (compiler/PACK.md) for
 * the runtime's tests, without the scene compiler: a generated 256x192
 * heightfield with non-square texels, three materials written by hand in
 * GLSL over the ABI prelude (grass at the bottom, rock and snow by height
 * bands), the per-cell analysis done here exactly (height bands are exact
 * on the cell's texel range), the quadtree levels, one composite per
 * combination (front to back, compiler/DESIGN.md §6), the multi-pass reference passes,
 * the über-shader, a texture and a param.
 *
 *   make_fixture OUTDIR
 */
#include "rt_internal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <jansson.h>
#include <stb_image_write.h>

enum { W = 256, H = 192, CELL = 16, NMAT = 3 };
static const double SIZE_X = 2048.0, SIZE_Z = 1200.0, MAXH = 300.0;

/* height bands (metres): mask = smoothstep(lo, hi, height) */
static const double band_lo[NMAT] = { 0, 110, 205 };
static const double band_hi[NMAT] = { 0, 150, 235 };
static const char *const names[NMAT] = { "grass", "rock", "snow" };

/* GLSL of each material: mask_i() and surf_i(). */
static const char *const material_glsl[NMAT] = {
    "float mask_0() { return 1.0; }\n"
    "void surf_0(out vec3 a, out vec3 n, out float r, out float h) {\n"
    "    float s = splat_slope();\n"
    "    a = mix(vec3(0.16, 0.30, 0.07), vec3(0.30, 0.27, 0.14), clamp(s * 4.0, 0.0, 1.0));\n"
    "    n = splat_normal(); r = 0.9; h = 0.3;\n"
    "}\n",
    "float mask_1() { return smoothstep(110.0, 150.0, splat_height()); }\n"
    "void surf_1(out vec3 a, out vec3 n, out float r, out float h) {\n"
    "    vec3 t = textureGrad(u_tex0, vec3(g_detail_uv, 0.0), g_detail_dx, g_detail_dy).rgb;\n"
    "    a = t * u_params.p[0].rgb;\n"
    "    n = splat_normal(); r = 0.7; h = t.r;\n"
    "}\n",
    "float mask_2() { return smoothstep(205.0, 235.0, splat_height()); }\n"
    "void surf_2(out vec3 a, out vec3 n, out float r, out float h) {\n"
    "    a = vec3(0.85, 0.88, 0.92);\n"
    "    n = normalize(splat_normal() + vec3(0.0, 0.5, 0.0)); r = 0.4; h = 0.9;\n"
    "}\n",
};

static const char common_glsl[] =
    "layout(set = 1, binding = 0, std140) uniform splat_params_block { vec4 p[1]; } u_params;\n"
    "layout(set = 1, binding = 1) uniform sampler2DArray u_tex0;\n"
    /* gradients taken in uniform control flow, used inside branches */
    "vec2 g_detail_uv, g_detail_dx, g_detail_dy;\n"
    "void detail_setup() {\n"
    "    g_detail_uv = v_local.xz / 24.0;\n"
    "    g_detail_dx = dFdx(g_detail_uv); g_detail_dy = dFdy(g_detail_uv);\n"
    "}\n";

static double hash2(int x, int z)
{
    uint32_t h = (uint32_t)x * 374761393u + (uint32_t)z * 668265263u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return (double)((h ^ (h >> 16)) & 0xffffff) / (double)0xffffff;
}

static double height01(int x, int z)
{
    double u = (double)x / W, v = (double)z / H;
    double h = 0.42 + 0.28 * sin(u * 7.0 + 0.3) * cos(v * 5.0 - 0.4)
             + 0.16 * sin(u * 23.0 + v * 17.0) + 0.06 * cos(u * 61.0 - v * 43.0)
             + 0.02 * hash2(x, z);
    /* a ridge so that the top band occurs */
    double d = fabs(u - 0.7 - 0.1 * sin(v * 6.0));
    h += 0.35 * exp(-d * d * 400.0) * (0.6 + 0.4 * sin(v * 9.0));
    return h < 0 ? 0 : h > 1 ? 1 : h;
}

static bool write_file(const char *dir, const char *rel, const void *data, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "make_fixture: cannot write %s: %s\n", path, strerror(errno));
        return false;
    }
    bool ok = fwrite(data, 1, n, f) == n;
    ok = fclose(f) == 0 && ok;
    return ok;
}

/* The bottom material's mask is 1 (compiler/DESIGN.md §6). */
static void mask_call(int m, char out[32])
{
    if (m == 0)
        snprintf(out, 32, "1.0");
    else
        snprintf(out, 32, "mask_%d()", m);
}

/* Shader source of a composite (materials top first, `multipass` < 0) or
 * of the reference pass of material `multipass`. */
static char *shader_source(const int *mats, int n, int multipass)
{
    size_t cap = 65536;
    char *s = malloc(cap);
    size_t len = 0;
#define PUT(...) len += (size_t)snprintf(s + len, cap - len, __VA_ARGS__)
    PUT("#version 450\n");
    if (multipass >= 0)
        PUT("#define SPLAT_MULTIPASS 1\n");
    PUT("%s%s", SPLAT_GLSL_PRELUDE, common_glsl);
    for (int i = 0; i < NMAT; i++)
        PUT("%s", material_glsl[i]);
    PUT("void main() {\n    detail_setup();\n");
    char mask[32];
    if (multipass >= 0) {
        mask_call(multipass, mask);
        PUT("    vec3 a, n; float r, h;\n    surf_%d(a, n, r, h);\n", multipass);
        PUT("    splat_finish(a, n, r, h, %s);\n}\n", mask);
        return s;
    }
    /* the mask view: this combination's masks (absent materials are 0) */
    PUT("    if (u_frame.view.x == %uu) {\n        float m = 0.0;\n", (unsigned)SPLAT_VIEW_MASK);
    for (int k = 0; k < n; k++)
        PUT("        if (u_frame.view.y == %du) m = mask_%d();\n", mats[k], mats[k]);
    PUT("        o_color = vec4(vec3(m), 1.0);\n        return;\n    }\n");
    PUT("    vec3 A = vec3(0.0), N = vec3(0.0); float R = 0.0, Hh = 0.0, T = 1.0;\n");
    PUT("    do {\n");
    for (int k = 0; k < n; k++) {
        int m = mats[k];
        mask_call(m, mask);
        PUT("        {\n            float w = T * %s;\n", mask);
        PUT("            if (w > 0.0) {\n");
        PUT("                vec3 a, n; float r, h; surf_%d(a, n, r, h);\n", m);
        PUT("                A += w * a; N += w * n; R += w * r; Hh += w * h;\n");
        PUT("            }\n            T -= w;\n            if (T <= 0.0) break;\n        }\n");
    }
    PUT("    } while (false);\n    splat_finish(A, N, R, Hh, 1.0);\n}\n");
#undef PUT
    return s;
}

static bool emit_shader(const char *dir, const char *base, const char *src,
                        VkShaderStageFlagBits stage, const char *ext_glsl, const char *ext_spv)
{
    char rel[256];
    snprintf(rel, sizeof rel, "shaders/%s%s", base, ext_glsl);
    if (!write_file(dir, rel, src, strlen(src)))
        return false;
    uint32_t *words;
    size_t n;
    rt_error e = { 0 };
    if (!rt_glsl_compile(src, stage, rel, &words, &n, &e)) {
        fprintf(stderr, "make_fixture: %s\n", e.msg);
        rt_error_clear(&e);
        return false;
    }
    snprintf(rel, sizeof rel, "shaders/%s%s", base, ext_spv);
    bool ok = write_file(dir, rel, words, n * 4);
    free(words);
    return ok;
}

typedef struct node { unsigned present, opaque; } node;

/* Materials of a node's combination, top first: present ones down to the
 * first opaque one. */
static int combo_of(node nd, int *mats)
{
    int n = 0;
    for (int i = NMAT - 1; i >= 0; i--) {
        if (!(nd.present & (1u << i)))
            continue;
        mats[n++] = i;
        if (nd.opaque & (1u << i))
            break;
    }
    return n;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_fixture OUTDIR\n");
        return 2;
    }
    const char *dir = argv[1];
    char sub[1024];
    mkdir(dir, 0755);
    snprintf(sub, sizeof sub, "%s/shaders", dir);
    mkdir(sub, 0755);
    snprintf(sub, sizeof sub, "%s/textures", dir);
    mkdir(sub, 0755);

    /* heightfield */
    static uint16_t hf[W * H];
    static uint8_t hf_le[W * H * 2];
    for (int z = 0; z < H; z++)
        for (int x = 0; x < W; x++) {
            uint16_t v = (uint16_t)lrint(height01(x, z) * 65535.0);
            hf[z * W + x] = v;
            hf_le[2 * (z * W + x)] = (uint8_t)v;
            hf_le[2 * (z * W + x) + 1] = (uint8_t)(v >> 8);
        }
    if (!write_file(dir, "heightfield.r16", hf_le, sizeof hf_le))
        return 1;

    /* detail texture: tileable value noise, greyish brown */
    static uint8_t tex[64 * 64 * 4];
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            double n = 0.5 * hash2(x, y) + 0.3 * hash2(x / 4 + 100, y / 4) + 0.2 * hash2(x / 16 + 7, y / 16);
            tex[(y * 64 + x) * 4 + 0] = (uint8_t)(90 + 120 * n);
            tex[(y * 64 + x) * 4 + 1] = (uint8_t)(80 + 110 * n);
            tex[(y * 64 + x) * 4 + 2] = (uint8_t)(70 + 100 * n);
            tex[(y * 64 + x) * 4 + 3] = 255;
        }
    snprintf(sub, sizeof sub, "%s/textures/rock.png", dir);
    if (!stbi_write_png(sub, 64, 64, 4, tex, 64 * 4))
        return 1;

    /* analysis: leaf cells from the texels their vertices can sample, with
     * half a metre of margin for the GPU's filtering */
    int cx = W / CELL, cz = H / CELL;
    int nlev = rt_level_count(cx, cz);
    node *lv[16];
    int lw[16], lh[16];
    lw[0] = cx;
    lh[0] = cz;
    lv[0] = calloc((size_t)cx * cz, sizeof(node));
    for (int z = 0; z < cz; z++)
        for (int x = 0; x < cx; x++) {
            double lo = 1e9, hi = -1e9;
            for (int tz = z * CELL - 1; tz <= (z + 1) * CELL; tz++)
                for (int tx = x * CELL - 1; tx <= (x + 1) * CELL; tx++) {
                    int qx = tx < 0 ? 0 : tx >= W ? W - 1 : tx;
                    int qz = tz < 0 ? 0 : tz >= H ? H - 1 : tz;
                    double h = hf[qz * W + qx] / 65535.0 * MAXH;
                    lo = h < lo ? h : lo;
                    hi = h > hi ? h : hi;
                }
            node nd = { 1u, 1u };
            for (int m = 1; m < NMAT; m++) {
                if (hi > band_lo[m] - 0.5)
                    nd.present |= 1u << m;
                if (lo >= band_hi[m] + 0.5)
                    nd.opaque |= 1u << m;
            }
            lv[0][z * cx + x] = nd;
        }
    for (int L = 1; L < nlev; L++) {
        lw[L] = (lw[L - 1] + 1) / 2;
        lh[L] = (lh[L - 1] + 1) / 2;
        lv[L] = calloc((size_t)lw[L] * lh[L], sizeof(node));
        for (int z = 0; z < lh[L]; z++)
            for (int x = 0; x < lw[L]; x++) {
                node u = { 0, ~0u };
                for (int c = 0; c < 4; c++) {
                    int qx = 2 * x + (c & 1), qz = 2 * z + (c >> 1);
                    if (qx >= lw[L - 1] || qz >= lh[L - 1])
                        continue;
                    node k = lv[L - 1][qz * lw[L - 1] + qx];
                    u.present |= k.present;
                    u.opaque &= k.opaque;
                }
                lv[L][z * lw[L] + x] = u;
            }
    }
    /* combinations in order of first occurrence, leaves first */
    int combos[64][NMAT], ncm[64], ncombos = 0, cells[64] = { 0 };
    size_t total = 0;
    for (int L = 0; L < nlev; L++)
        total += (size_t)lw[L] * lh[L];
    uint8_t *bin = malloc(total * 2);
    size_t off = 0;
    json_t *levels = json_array();
    for (int L = 0; L < nlev; L++) {
        json_array_append_new(levels, json_pack("{s:i, s:i, s:i, s:i}", "level", L, "width", lw[L],
                                                "height", lh[L], "offset", (int)off));
        for (int i = 0; i < lw[L] * lh[L]; i++) {
            int mats[NMAT], n = combo_of(lv[L][i], mats), id = -1;
            for (int c = 0; c < ncombos && id < 0; c++)
                if (ncm[c] == n && !memcmp(combos[c], mats, (size_t)n * sizeof(int)))
                    id = c;
            if (id < 0) {
                id = ncombos++;
                ncm[id] = n;
                memcpy(combos[id], mats, sizeof mats);
            }
            if (L == 0)
                cells[id]++;
            bin[off++] = (uint8_t)id;
            bin[off++] = (uint8_t)(id >> 8);
        }
    }
    if (!write_file(dir, "combos.bin", bin, off))
        return 1;
    free(bin);

    /* shaders */
    json_t *jc = json_array();
    for (int c = 0; c < ncombos; c++) {
        char base[16], glsl[64], spv[64];
        snprintf(base, sizeof base, "%04d", c);
        char *src = shader_source(combos[c], ncm[c], -1);
        if (!emit_shader(dir, base, src, VK_SHADER_STAGE_FRAGMENT_BIT, ".frag", ".spv"))
            return 1;
        free(src);
        json_t *jm = json_array();
        for (int k = 0; k < ncm[c]; k++)
            json_array_append_new(jm, json_integer(combos[c][k]));
        snprintf(glsl, sizeof glsl, "shaders/%s.frag", base);
        snprintf(spv, sizeof spv, "shaders/%s.spv", base);
        json_array_append_new(jc, json_pack("{s:i, s:o, s:s, s:s, s:[i], s:[i], s:i}",
                                            "id", c, "materials", jm, "glsl", glsl, "spirv", spv,
                                            "textures", 0, "params", 0, "cells", cells[c]));
    }
    json_t *jmat = json_array();
    for (int m = 0; m < NMAT; m++) {
        char base[32], glsl[64], spv[64];
        snprintf(base, sizeof base, "ref_%04d", m);
        char *src = shader_source(NULL, 0, m);
        if (!emit_shader(dir, base, src, VK_SHADER_STAGE_FRAGMENT_BIT, ".frag", ".spv"))
            return 1;
        free(src);
        snprintf(glsl, sizeof glsl, "shaders/%s.frag", base);
        snprintf(spv, sizeof spv, "shaders/%s.spv", base);
        json_array_append_new(jmat, json_pack("{s:s, s:s, s:{s:s, s:s}}", "name", names[m],
                                              "source", "fixture", "reference", "glsl", glsl,
                                              "spirv", spv));
    }
    int all[NMAT] = { 2, 1, 0 };
    char *src = shader_source(all, NMAT, -1);
    if (!emit_shader(dir, "uber", src, VK_SHADER_STAGE_FRAGMENT_BIT, ".frag", ".spv") ||
        !emit_shader(dir, "terrain", SPLAT_GLSL_VERTEX, VK_SHADER_STAGE_VERTEX_BIT, ".vert", ".vert.spv"))
        return 1;
    free(src);

    double hx = SIZE_X * 0.7;
    json_t *root = json_pack(
        "{s:s, s:i, s:i, s:s,"
        " s:{s:s, s:{s:s, s:i, s:i}, s:[f, f], s:f, s:f, s:i,"
        "    s:[{s:s, s:[f, f, f], s:[f, f, f]}, {s:s, s:[f, f, f], s:[f, f, f]}], s:n},"
        " s:o, s:[{s:s, s:s, s:[f, f, f, f], s:f, s:f, s:i}], s:i,"
        " s:[{s:s, s:i, s:s, s:s, s:s, s:b}], s:[], s:o,"
        " s:{s:s, s:s}, s:{s:s, s:s}, s:{s:s, s:o}}",
        "format", "splatc-pack", "version", SPLAT_PACK_VERSION, "abi", SPLAT_ABI_VERSION, "compiler", "make_fixture",
        "scene", "name", "fixture", "heightfield", "file", "heightfield.r16", "width", W, "height", H,
        "size", SIZE_X, SIZE_Z, "max_height", MAXH, "height_offset", 0.0, "cell_texels", CELL,
        "cameras",
        "name", "overview", "position", -200.0, 700.0, SIZE_Z + 300.0, "look", SIZE_X * 0.5, 80.0, SIZE_Z * 0.5,
        "name", "ridge", "position", hx - 150.0, 330.0, SIZE_Z * 0.8, "look", hx, 200.0, SIZE_Z * 0.45,
        "destruction",
        "materials", jmat,
        "params", "name", "rock.tint", "type", "vec3", "default", 0.9, 0.82, 0.75, 0.0,
        "min", 0.0, "max", 1.0, "offset", 0,
        "params_size", 16,
        "textures", "file", "textures/rock.png", "binding", 1, "filter", "linear", "mip", "linear",
        "wrap", "repeat", "srgb", 1,
        "painted",
        "combinations", jc,
        "uber", "glsl", "shaders/uber.frag", "spirv", "shaders/uber.spv",
        "vertex", "glsl", "shaders/terrain.vert", "spirv", "shaders/terrain.vert.spv",
        "quadtree", "file", "combos.bin", "levels", levels);
    if (!root) {
        fprintf(stderr, "make_fixture: json_pack failed\n");
        return 1;
    }
    snprintf(sub, sizeof sub, "%s/manifest.json", dir);
    if (json_dump_file(root, sub, JSON_INDENT(2) | JSON_SORT_KEYS) != 0)
        return 1;
    json_decref(root);
    for (int L = 0; L < nlev; L++)
        free(lv[L]);
    printf("make_fixture: %s: %d combinations over %d levels\n", dir, ncombos, nlev);
    return 0;
}
