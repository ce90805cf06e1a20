/* splatbench — speed and accuracy of shader-pack variants, side by side on
 * the same frames of a fixed camera path (compiler/DESIGN.md §9).
 *
 *   splatbench render --variant LABEL=KIND[,pack=DIR][,lod=P] ... [options]
 *       Renders every variant on every frame of a camera path, frames
 *       interleaved (frame f of every variant, then frame f + 1), so a
 *       change of machine load hits all variants alike.  Per variant: GPU
 *       ms per frame from timestamp queries (median, p10, p90), CPU ms per
 *       frame, and the error of its lit RGBA32F image against the reference
 *       variant's image of the same frame (max and mean absolute error over
 *       RGB, PSNR with peak 1, count of NaN/Inf values).  One CSV row per
 *       variant.  KIND:
 *         composite   per-combination composites (the pack's shaders)
 *         multipass   the multi-pass alpha-blended reference (Andersson 2007 §5.3)
 *         uber        the über-shader for every patch
 *         flat        composites without dynamic branches (pack built --flat)
 *         fp16        composites recompiled with `precision mediump float`
 *         sobel       composites recompiled with a 3x3 Sobel normal filter
 *                     in place of Listing 1's 4-tap cross
 *         analytic    composites recompiled with the exact normal of the
 *                     function `splatbench analytic-hf` samples (only for
 *                     a pack built on such a heightfield)
 *         lambert     composites recompiled with the lighting before issue
 *                     16 (Lambert sun, a small lobe, no shadow tap): the
 *                     baseline the GGX sun and the shadows are timed against
 *         screen      screen-space shading (--shading screen): depth pass,
 *                     tile classification, compute composites; its rows
 *                     add the three passes' GPU medians
 *       Rows of screen, composite and uber add, from one counting frame
 *       after the timed ones (abi.h SPLAT_COUNT), layers evaluated /
 *       needed and samples per pixel (forward: per fragment shaded).
 *         screen_uber the same with every tile on the über-shader
 *         screen_raster, screen_raycast   the screen path with its depth
 *                     from the patches drawn depth only, or ray cast in
 *                     compute (screen: the runtime's choice for the device)
 *       pack=DIR renders another pack of the same terrain (compositors, fBm
 *       knobs); lod=P sets the LOD error threshold in pixels per grid step;
 *       noshadow renders without the terrain's shadows (--no-shadows); ug
 *       draws the pack's undergrowth (off otherwise, so the other groups
 *       time what they always timed), ugradius=R within R metres of the
 *       camera instead of the runtime's 96: its rows add the generation GPU ms
 *       per frame and per generated cell, the draw GPU ms per frame, the
 *       instances and the memory per cell.  far=D shades screen tiles
 *       (screen kinds) or quadtree patches (composite) at least D m away
 *       from the pack's far atlas (splatc build --far-atlas); its rows add
 *       the distance and the tiles (patches) the atlas shaded (from the
 *       counting frame).  distclass=0 shades with the
 *       combinations only (--no-distance-classes; PACK.md "Distance
 *       classes"), distclass=1 (the default) with their distance classes;
 *       async (screen kinds) makes compute pipelines on worker threads,
 *       the über-shader shading their tiles meanwhile (first pictures);
 *       sort=on|off (screen kinds) sorts each workgroup's pixels by the
 *       layers they need before shading (rt_pixel_sort; default off),
 *       sort=N on with N tiles per workgroup (4, 8 or 16; on: the most
 *       the device allows, 16 on GPUs and lavapipe);
 *       the kinds that recompile the composites (flat fp16 sobel analytic
 *       lambert) always run without them.
 *       Paths (--path): ground (2 m above the terrain looking 150 m ahead,
 *       from --start-preset NAME or --start x,z,dx,dz), topdown, grazing.
 *       --warmup N (default 1) untimed frames at the path's start first;
 *       --warmup path: every frame of the path once, untimed, so nothing a
 *       view needs is made or JIT-compiled inside a timed frame (llvmpipe
 *       compiles shader variants when a draw or dispatch first needs them,
 *       inside the GPU timestamps).
 *   splatbench far-bake --pack P [--far-atlas N] [--runs K] [--out PREFIX]
 *       the far atlas baked on the device (cmd_far_bake says more).
 *   splatbench shadow --pack P [--runs K] [--sun AZ,EL]
 *       the shadow map marched on the CPU and on the device, side by side
 *       (cmd_shadow says more).
 *   splatbench upscale IN.png K OUT
 *       K times the texels per side, bilinear: a 16-bit PNG becomes raw
 *       little-endian R16 (OUT), an 8-bit one an 8-bit PNG (nearest).
 *   splatbench analytic-hf W H OUT.r16
 *       a W x H raw R16 heightfield sampling analytic_height() at texel
 *       centres (the reference of the normal-filter knob).
 *   splatbench compare A.f32 B.f32
 *       max/mean abs error and PSNR of two --float-out images.
 *
 * Exit status: 0 ok, 1 a failure (message on stderr), 2 usage. */
#include "rt_internal.h"
#include "zst.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

/* ---- small helpers ------------------------------------------------------- */

static void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size);
    if (!p) {
        fprintf(stderr, "splatbench: out of memory\n");
        abort();
    }
    return p;
}

/* A pack file's bytes (NUL after them), decompressed where its name ends
 * in ".zst" (compiler/PACK.md "Compressed shaders"). */
static uint8_t *read_pack_file(const char *path, size_t *n)
{
    *n = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long bytes = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *data = bytes >= 0 ? xcalloc((size_t)bytes + 1, 1) : NULL;
    if (data && bytes > 0 && fread(data, 1, (size_t)bytes, f) != (size_t)bytes) {
        free(data);
        data = NULL;
    }
    fclose(f);
    if (data && splat_zst_name(path)) {
        char why[256];
        size_t raw = 0;
        uint8_t *d = splat_zst_decompress(data, (size_t)bytes, (size_t)64 << 20, &raw, why,
                                          sizeof why);
        if (!d)
            fprintf(stderr, "splatbench: %s %s\n", path, why);
        free(data);
        *n = raw;
        return d;
    }
    *n = data ? (size_t)bytes : 0;
    return data;
}

static char *read_text(const char *path)
{
    size_t n;
    return (char *)read_pack_file(path, &n);
}

static bool read_words(const char *path, uint32_t **words, size_t *n)
{
    size_t bytes = 0;
    uint8_t *data = read_pack_file(path, &bytes);
    if (!data || bytes == 0 || bytes % 4) {
        free(data);
        return false;
    }
    *words = (uint32_t *)data;
    *n = bytes / 4;
    return true;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* median, 10th and 90th percentile of n samples (sorted in place) */
static void percentiles(double *v, int n, double *med, double *p10, double *p90)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    *med = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    *p10 = v[(int)floor(0.1 * (n - 1))];
    *p90 = v[(int)ceil(0.9 * (n - 1))];
}

/* resident set size now, MB (lavapipe's "GPU" memory is host memory) */
static double rss_mb(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &res) != 2)
            res = 0;
        fclose(f);
    }
    return (double)res * (double)sysconf(_SC_PAGESIZE) / (1024.0 * 1024.0);
}

/* ---- image error ---------------------------------------------------------- */

typedef struct err_acc {
    double max_abs, sum_abs, sum_sq;
    long   n, nonfinite;
} err_acc;

/* RGB of `img` against `ref` (w*h RGBA floats).  A NaN/Inf in img counts
 * as nonfinite and as an error of 1 (so it cannot hide in the mean). */
static void err_add(err_acc *a, const float *img, const float *ref, size_t npx)
{
    for (size_t i = 0; i < npx; i++)
        for (int c = 0; c < 3; c++) {
            float v = img[4 * i + c], r = ref[4 * i + c];
            double d;
            if (!isfinite(v) || !isfinite(r)) {
                a->nonfinite++;
                d = 1.0;
            } else {
                d = fabs((double)v - (double)r);
            }
            a->max_abs = d > a->max_abs ? d : a->max_abs;
            a->sum_abs += d;
            a->sum_sq += d * d;
            a->n++;
        }
}

static double err_psnr(const err_acc *a)
{
    double mse = a->n ? a->sum_sq / (double)a->n : 0;
    return mse > 0 ? 10.0 * log10(1.0 / mse) : 999.0;
}

/* ---- variants -------------------------------------------------------------- */

typedef enum kind { K_COMPOSITE, K_MULTIPASS, K_UBER, K_FLAT, K_FP16, K_SOBEL, K_ANALYTIC,
                    K_LAMBERT, K_SCREEN, K_SCREEN_UBER, K_SCREEN_RASTER, K_SCREEN_RAYCAST } kind;
static const char *const kind_names[] = {"composite", "multipass", "uber", "flat", "fp16", "sobel",
                                         "analytic", "lambert", "screen", "screen_uber",
                                         "screen_raster", "screen_raycast"};
#define IS_SCREEN(k) ((k) >= K_SCREEN)

typedef struct variant {
    char        *label;
    kind         k;
    const char  *pack_dir;
    double       lod;
    bool         no_shadows;
    rt_pixel_sort sort;
    int          sort_tiles;
    bool         no_dclass; /* distclass=0                                 */
    bool         async;     /* async: pipelines made on workers, the über-
                               shader standing in (screen kinds)          */
    bool         ug;        /* draw the undergrowth                         */
    double       ug_radius; /* its radius (m); 0: the runtime's default     */
    double       far;       /* screen: the far atlas's distance (m); 0: off */
    double       shadow_ms; /* ms of the shadow map (the first frame)       */
    double      *ug_gen, *ug_draw; /* per timed frame, GPU ms               */
    long         ug_cells;  /* cells generated over the timed frames        */
    rt_ug_stats  ug_last;   /* the last frame's                             */
    rt_pack     *base;      /* loaded pack (shared by variants of one dir)  */
    rt_pack      view;      /* shallow copy with this variant's combos      */
    rt_pack_combo *combos;  /* owned when the shaders differ, else NULL     */
    rt_renderer *r;
    double      *gpu, *cpu, *sel;
    double      *pass[3];   /* screen: geometry, classification, shading */
    rt_screen_stats tiles;  /* screen: the last frame's tiles (counted)  */
    int          patches, pipelines;
    err_acc      err;
    double       rss_delta;
} variant;

/* The 3x3 Sobel filter replacing the prelude's splat_normal_at (abi.c):
 * x and z differences of the three rows/columns weighted 1 2 1, over 4. */
static const char sobel_normal[] =
    "vec3 splat_normal_at(vec2 uv) {\n"
    "    vec2 t = u_frame.texel.zw;\n"
    "    float h00 = texture(u_height, uv + vec2(-t.x, -t.y)).r;\n"
    "    float h10 = texture(u_height, uv + vec2(0.0, -t.y)).r;\n"
    "    float h20 = texture(u_height, uv + vec2(t.x, -t.y)).r;\n"
    "    float h01 = texture(u_height, uv + vec2(-t.x, 0.0)).r;\n"
    "    float h21 = texture(u_height, uv + vec2(t.x, 0.0)).r;\n"
    "    float h02 = texture(u_height, uv + vec2(-t.x, t.y)).r;\n"
    "    float h12 = texture(u_height, uv + vec2(0.0, t.y)).r;\n"
    "    float h22 = texture(u_height, uv + vec2(t.x, t.y)).r;\n"
    "    float dx = u_frame.terrain.x * t.x;\n"
    "    float dz = u_frame.terrain.y * t.y;\n"
    "    float gx = ((h00 + 2.0 * h01 + h02) - (h20 + 2.0 * h21 + h22)) * 0.25;\n"
    "    float gz = ((h00 + 2.0 * h10 + h20) - (h02 + 2.0 * h12 + h22)) * 0.25;\n"
    "    vec3 n = vec3(gx * u_frame.terrain.z / dx, 2.0, gz * u_frame.terrain.z / dz);\n"
    "    return normalize(n);\n"
    "}\n"
    "void splat_terrain_at(vec2 uv, out float h, out vec3 n) {\n"
    "    h = splat_height_smooth_at(uv);\n"
    "    n = splat_normal_at(uv);\n"
    "}\n";

/* The preview lighting before issue 16 (abi.c's splat_light then). */
static const char lambert_light[] =
    "vec3 splat_light(vec3 albedo, vec3 n, float rough, float dist, vec3 v) {\n"
    "    vec3 l = u_frame.sun_dir.xyz;\n"
    "    float ndl = max(dot(n, l), 0.0);\n"
    "    vec3 c = albedo * (u_frame.sun_color.rgb * ndl\n"
    "                       + u_frame.sky_color.rgb * (0.5 + 0.5 * n.y));\n"
    "    c += u_frame.sun_color.rgb * 0.04 * (1.0 - rough) * pow(ndl, 8.0);\n"
    "    c = mix(c, u_frame.fog.rgb, splat_fog(dist, v));\n"
    "    return c * u_frame.light.z;\n"
    "}\n";

/* The analytic heightfield: normalised height at heightfield uv (u, v),
 * within 0.1 .. 0.9, and its exact normal in GLSL (terrain.x, .y: size in
 * metres, .z: max height), written from the same formula. */
static double analytic_height(double u, double v)
{
    const double tau = 6.283185307179586;
    return 0.5 + 0.25 * sin(tau * 3 * u) * cos(tau * 2 * v) + 0.15 * sin(tau * 7 * (u + v));
}

static const char analytic_normal[] =
    "vec3 splat_normal_at(vec2 uv) {\n"
    "    const float TAU = 6.283185307179586;\n"
    "    float c7 = 0.15 * TAU * 7.0 * cos(TAU * 7.0 * (uv.x + uv.y));\n"
    "    float du = 0.25 * TAU * 3.0 * cos(TAU * 3.0 * uv.x) * cos(TAU * 2.0 * uv.y) + c7;\n"
    "    float dv = -0.25 * TAU * 2.0 * sin(TAU * 3.0 * uv.x) * sin(TAU * 2.0 * uv.y) + c7;\n"
    "    vec3 n = vec3(-du * u_frame.terrain.z / u_frame.terrain.x, 1.0,\n"
    "                  -dv * u_frame.terrain.z / u_frame.terrain.y);\n"
    "    return normalize(n);\n"
    "}\n"
    "void splat_terrain_at(vec2 uv, out float h, out vec3 n) {\n"
    "    h = splat_height_smooth_at(uv);\n"
    "    n = splat_normal_at(uv);\n"
    "}\n";

/* GLSL of a combination with the variant's change; NULL if the text does
 * not have the expected shape (message on stderr). */
static char *transform_glsl(const char *src, kind k, const char *name)
{
    const char *at, *end;
    const char *insert;
    if (k == K_FP16) {
        /* Every float of the shader at mediump (RelaxedPrecision in SPIR-V:
         * drivers may use fp16 arithmetic; exact fp32 ones ignore it). */
        at = strstr(src, "#version 450\n");
        if (!at) {
            fprintf(stderr, "splatbench: %s: no '#version 450' line\n", name);
            return NULL;
        }
        at += strlen("#version 450\n");
        end = at;
        insert = "precision mediump float;\n";
    } else if (k == K_LAMBERT) {
        const char *fn = "vec3 splat_light(vec3 albedo, vec3 n, float rough,";
        at = strstr(src, fn);
        end = at ? strstr(at, "\n}\n") : NULL;
        if (!end) {
            fprintf(stderr, "splatbench: %s: no '%s' to replace\n", name, fn);
            return NULL;
        }
        end += 3;
        insert = lambert_light;
    } else {
        /* the prelude's splat_terrain_at (height and normal, one pass over
         * the texels) and the splat_normal_at after it: the variant's
         * normal, the height apart */
        const char *fn = "void splat_terrain_at(vec2 uv, out float h, out vec3 n) {\n";
        at = strstr(src, fn);
        const char *nf = at ? strstr(at, "vec3 splat_normal_at(vec2 uv) {\n") : NULL;
        end = nf ? strstr(nf, "\n}\n") : NULL;
        if (!end) {
            fprintf(stderr, "splatbench: %s: no '%s' to replace\n", name, fn);
            return NULL;
        }
        end += 3;
        insert = k == K_SOBEL ? sobel_normal : analytic_normal;
    }
    size_t a = (size_t)(at - src), b = strlen(end), c = strlen(insert);
    char *out = xcalloc(a + b + c + 1, 1);
    memcpy(out, src, a);
    memcpy(out + a, insert, c);
    memcpy(out + a + c, end, b);
    return out;
}

/* The combination shaders a variant draws with: the pack's own, the flat
 * ones of the manifest, or recompiled GLSL. */
static bool variant_shaders(variant *v)
{
    v->view = *v->base;
    if (v->k != K_FLAT && v->k != K_FP16 && v->k != K_SOBEL && v->k != K_ANALYTIC &&
        v->k != K_LAMBERT)
        return true;
    char path[4096];
    snprintf(path, sizeof path, "%s/manifest.json", v->pack_dir);
    json_error_t jerr;
    json_t *m = json_load_file(path, 0, &jerr);
    json_t *combos = m ? json_object_get(m, "combinations") : NULL;
    /* the combinations only: their distance classes (entries nbase.. of
     * combos, shared with the base pack) are left out (no_dclass) */
    v->no_dclass = true;
    if (!json_is_array(combos) || (int)json_array_size(combos) != v->base->nbase) {
        fprintf(stderr, "splatbench: %s: no combinations list matching the pack\n", path);
        json_decref(m);
        return false;
    }
    v->combos = xcalloc((size_t)v->base->ncombos, sizeof *v->combos);
    bool ok = true;
    for (int i = v->base->nbase; i < v->base->ncombos; i++)
        v->combos[i] = v->base->combos[i];
    for (int i = 0; i < v->base->nbase && ok; i++) {
        json_t *c = json_array_get(combos, (size_t)i);
        v->combos[i] = v->base->combos[i];
        v->combos[i].spirv.words = NULL;
        if (v->k == K_FLAT) {
            const char *spv = json_string_value(json_object_get(json_object_get(c, "flat"), "spirv"));
            if (!spv) {
                fprintf(stderr, "splatbench: %s: combination %d has no flat shader "
                        "(build the pack with splatc build --flat)\n", path, i);
                ok = false;
                break;
            }
            snprintf(path, sizeof path, "%s/%s", v->pack_dir, spv);
            if (!read_words(path, &v->combos[i].spirv.words, &v->combos[i].spirv.nwords)) {
                fprintf(stderr, "splatbench: cannot read '%s'\n", path);
                ok = false;
            }
        } else {
            const char *glsl = json_string_value(json_object_get(c, "glsl"));
            snprintf(path, sizeof path, "%s/%s", v->pack_dir, glsl ? glsl : "?");
            char *src = glsl ? read_text(path) : NULL;
            char *text = src ? transform_glsl(src, v->k, path) : NULL;
            rt_error e = {0};
            if (!text || !rt_glsl_compile(text, VK_SHADER_STAGE_FRAGMENT_BIT, path,
                                          &v->combos[i].spirv.words,
                                          &v->combos[i].spirv.nwords, &e)) {
                fprintf(stderr, "splatbench: %s: %s\n", path, e.msg ? e.msg : "unreadable");
                ok = false;
            }
            rt_error_clear(&e);
            free(src);
            free(text);
        }
    }
    json_decref(m);
    v->view.combos = v->combos;
    return ok;
}

static void variant_free(variant *v)
{
    rt_renderer_destroy(v->r);
    if (v->combos)
        for (int i = 0; i < v->base->nbase; i++)
            free(v->combos[i].spirv.words);
    free(v->combos);
    free(v->label);
    free(v->gpu);
    free(v->cpu);
    free(v->sel);
    free(v->ug_gen);
    free(v->ug_draw);
    for (int k = 0; k < 3; k++)
        free(v->pass[k]);
}

/* LABEL=KIND[,pack=DIR][,lod=P] */
static bool parse_variant(const char *s, const char *default_pack, variant *v)
{
    memset(v, 0, sizeof *v);
    const char *eq = strchr(s, '=');
    if (!eq || eq == s)
        return false;
    v->label = strndup(s, (size_t)(eq - s));
    v->pack_dir = default_pack;
    char *rest = strdup(eq + 1), *save = NULL;
    bool ok = true, have_kind = false;
    for (char *t = strtok_r(rest, ",", &save); t && ok; t = strtok_r(NULL, ",", &save)) {
        if (!strncmp(t, "pack=", 5)) {
            v->pack_dir = strdup(t + 5);   /* lives as long as the process */
        } else if (!strcmp(t, "noshadow")) {
            v->no_shadows = true;
        } else if (!strcmp(t, "async")) {
            v->async = true;
        } else if (!strcmp(t, "distclass=0") || !strcmp(t, "distclass=1")) {
            v->no_dclass = t[10] == '0';
        } else if (!strcmp(t, "sort=on") || !strcmp(t, "sort=off")) {
            v->sort = t[6] == 'n' ? RT_SORT_ON : RT_SORT_OFF;
        } else if (!strncmp(t, "sort=", 5)) {   /* sort=N: on, N tiles per workgroup */
            v->sort = RT_SORT_ON;
            v->sort_tiles = atoi(t + 5);
            ok = v->sort_tiles > 0;
        } else if (!strcmp(t, "ug")) {
            v->ug = true;
        } else if (!strncmp(t, "ugradius=", 9)) {
            v->ug = true;
            v->ug_radius = atof(t + 9);
            ok = v->ug_radius > 0;
        } else if (!strncmp(t, "far=", 4)) {
            v->far = atof(t + 4);
            ok = v->far > 0;
        } else if (!strncmp(t, "lod=", 4)) {
            v->lod = atof(t + 4);
            ok = v->lod > 0;
        } else {
            ok = false;
            for (int k = 0; k < (int)(sizeof kind_names / sizeof *kind_names); k++)
                if (!strcmp(t, kind_names[k])) {
                    v->k = (kind)k;
                    ok = have_kind = true;
                }
        }
    }
    free(rest);
    return ok && have_kind && v->pack_dir;
}

/* ---- camera paths ------------------------------------------------------------ */

/* Terrain height (metres) at terrain-local x, z: bilinear between texel
 * centres, clamped to the edge (PACK.md "Coordinates"). */
static double ground(const rt_pack *p, double x, double z)
{
    double u = x / p->size[0] * p->hf_width - 0.5, v = z / p->size[1] * p->hf_height - 0.5;
    u = fmin(fmax(u, 0), p->hf_width - 1);
    v = fmin(fmax(v, 0), p->hf_height - 1);
    int i = (int)u, j = (int)v;
    int i1 = i + 1 < p->hf_width ? i + 1 : i, j1 = j + 1 < p->hf_height ? j + 1 : j;
    double fu = u - i, fv = v - j;
#define H(a, b) (p->heights[(size_t)(b) * (size_t)p->hf_width + (size_t)(a)] / 65535.0)
    double h = (H(i, j) * (1 - fu) + H(i1, j) * fu) * (1 - fv) +
               (H(i, j1) * (1 - fu) + H(i1, j1) * fu) * fv;
#undef H
    return h * p->max_height + p->height_offset;
}

typedef struct path_desc {
    const char *name;          /* ground | topdown | grazing                */
    const char *preset;        /* ground: start at this camera preset       */
    bool        have_start;    /* ground: start here instead (--start)      */
    double      start[4];      /* x, z, direction x, z                      */
} path_desc;

/* Camera of frame f of n.  ground: 2 m above the terrain, looking 150 m
 * ahead along a straight line (Billingsley 2009 §3.2), 1.5 % of the terrain per
 * path; topdown: straight down from above the highest point, covering
 * about half the terrain, drifting east; grazing: 40 m above a corner,
 * looking across the terrain at about 1-3 degrees below the horizon. */
static bool path_camera(const rt_pack *p, const path_desc *pd, int f, int n, rt_camera *c)
{
    memset(c, 0, sizeof *c);
    double sx = p->size[0], sz = p->size[1], smax = fmax(sx, sz);
    double t = n > 1 ? (double)f / (n - 1) : 0;
    double top = p->max_height + p->height_offset;
    if (!strcmp(pd->name, "ground")) {
        double x0 = 0.3 * sx, z0 = 0.3 * sz, dx = 0.7071, dz = 0.7071;
        if (pd->have_start) {
            x0 = pd->start[0], z0 = pd->start[1];
            double l = hypot(pd->start[2], pd->start[3]);
            dx = l > 0 ? pd->start[2] / l : 1, dz = l > 0 ? pd->start[3] / l : 0;
        } else if (pd->preset) {
            int k = rt_pack_camera_find(p, pd->preset);
            if (k < 0) {
                fprintf(stderr, "splatbench: no camera preset '%s'\n", pd->preset);
                return false;
            }
            x0 = p->cameras[k].position[0];
            z0 = p->cameras[k].position[2];
            dx = p->cameras[k].look[0] - x0;
            dz = p->cameras[k].look[2] - z0;
            double l = hypot(dx, dz);
            if (l <= 0)
                dx = 1, dz = 0, l = 1;
            dx /= l, dz /= l;
        }
        double x = x0 + dx * 0.015 * smax * t, z = z0 + dz * 0.015 * smax * t;
        double ahead = fmin(150.0, 0.1 * smax);
        double lx = x + dx * ahead, lz = z + dz * ahead;
        c->position[0] = x, c->position[1] = ground(p, x, z) + 2.0, c->position[2] = z;
        c->look[0] = lx, c->look[1] = ground(p, lx, lz) + 1.0, c->look[2] = lz;
    } else if (!strcmp(pd->name, "topdown")) {
        double x = 0.5 * sx + 0.05 * sx * (t - 0.5), z = 0.5 * sz;
        c->position[0] = x, c->position[1] = top + 0.5 * smax, c->position[2] = z;
        /* slightly off vertical so the view's up vector is defined */
        c->look[0] = x, c->look[1] = p->height_offset, c->look[2] = z + 0.001 * smax;
    } else if (!strcmp(pd->name, "grazing")) {
        double x = 0.05 * sx + 0.02 * sx * t, z = 0.05 * sz + 0.02 * sz * t;
        double lx = 0.7 * sx, lz = 0.7 * sz;
        c->position[0] = x, c->position[1] = ground(p, x, z) + 40.0, c->position[2] = z;
        c->look[0] = lx, c->look[1] = ground(p, lx, lz), c->look[2] = lz;
        if (c->look[1] > c->position[1] - 1.0)
            c->look[1] = c->position[1] - 0.02 * hypot(lx - x, lz - z);
    } else {
        fprintf(stderr, "splatbench: unknown path '%s' (ground, topdown, grazing)\n", pd->name);
        return false;
    }
    return true;
}

/* ---- render ---------------------------------------------------------------- */

static int cmd_render(int argc, char **argv)
{
    const char *pack_dir = NULL, *csv = NULL, *scene = NULL, *save = NULL, *ref_label = NULL;
    const char *view_name = "final";
    path_desc pd = {.name = "ground"};
    int width = 1280, height = 720, frames = 5, warmup = 1;
    char **specs = xcalloc((size_t)argc, sizeof *specs);
    int nspecs = 0;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (!next) {
            fprintf(stderr, "splatbench render: %s needs a value\n", a);
            return 2;
        }
        i++;
        if (!strcmp(a, "--pack")) pack_dir = next;
        else if (!strcmp(a, "--variant")) specs[nspecs++] = (char *)next;
        else if (!strcmp(a, "--ref")) ref_label = next;
        else if (!strcmp(a, "--path")) pd.name = next;
        else if (!strcmp(a, "--start-preset")) pd.preset = next;
        else if (!strcmp(a, "--start")) {
            if (sscanf(next, "%lf,%lf,%lf,%lf", &pd.start[0], &pd.start[1], &pd.start[2],
                       &pd.start[3]) != 4) {
                fprintf(stderr, "splatbench render: --start expects x,z,dx,dz\n");
                return 2;
            }
            pd.have_start = true;
        }
        else if (!strcmp(a, "--csv")) csv = next;
        else if (!strcmp(a, "--view")) view_name = next;
        else if (!strcmp(a, "--scene")) scene = next;
        else if (!strcmp(a, "--save")) save = next;
        else if (!strcmp(a, "--frames")) frames = atoi(next);
        else if (!strcmp(a, "--warmup")) warmup = !strcmp(next, "path") ? -1 : atoi(next);
        else if (!strcmp(a, "--size")) {
            if (sscanf(next, "%dx%d", &width, &height) != 2 || width <= 0 || height <= 0) {
                fprintf(stderr, "splatbench render: --size expects WxH\n");
                return 2;
            }
        } else {
            fprintf(stderr, "splatbench render: unknown option '%s'\n", a);
            return 2;
        }
    }
    if (nspecs == 0 || frames < 1 || warmup < -1) {
        fprintf(stderr, "splatbench render: needs --variant LABEL=KIND... and --frames >= 1\n");
        return 2;
    }
    variant *v = xcalloc((size_t)nspecs, sizeof *v);
    for (int i = 0; i < nspecs; i++)
        if (!parse_variant(specs[i], pack_dir, &v[i])) {
            fprintf(stderr, "splatbench render: bad variant '%s' (LABEL=KIND[,pack=DIR][,lod=P];"
                    " KIND composite|multipass|uber|flat|fp16|sobel|analytic|screen|screen_uber|"
                    "screen_raster|screen_raycast;"
                    " a pack from --pack"
                    " or pack=)\n",
                    specs[i]);
            return 2;
        }
    int ref = 0;
    if (ref_label) {
        ref = -1;
        for (int i = 0; i < nspecs; i++)
            if (!strcmp(v[i].label, ref_label))
                ref = i;
        if (ref < 0) {
            fprintf(stderr, "splatbench render: --ref '%s' is not a variant\n", ref_label);
            return 2;
        }
    }

    int status = 1;
    rt_error e = {0};
    rt_device dev;
    bool have_dev = false;
    rt_pack *packs = xcalloc((size_t)nspecs, sizeof *packs);
    const char **pack_dirs = xcalloc((size_t)nspecs, sizeof *pack_dirs);
    int npacks = 0;
    size_t npx = (size_t)width * (size_t)height;
    float *img = xcalloc(npx * 4, sizeof *img), *refimg = xcalloc(npx * 4, sizeof *refimg);

    /* every distinct pack once */
    for (int i = 0; i < nspecs; i++) {
        int k = 0;
        while (k < npacks && strcmp(pack_dirs[k], v[i].pack_dir))
            k++;
        if (k == npacks) {
            if (!rt_pack_load(&packs[k], v[i].pack_dir, &e))
                goto done;
            pack_dirs[npacks++] = v[i].pack_dir;
        }
        v[i].base = &packs[k];
        if (packs[k].hf_width != packs[0].hf_width || packs[k].hf_height != packs[0].hf_height) {
            fprintf(stderr, "splatbench: pack '%s' has another terrain than '%s'\n",
                    v[i].pack_dir, pack_dirs[0]);
            goto done;
        }
        if (!variant_shaders(&v[i]))
            goto done;
    }
    if (!rt_device_create(&dev, NULL, &e))
        goto done;
    have_dev = true;
    char cache[4096];
    if (save)
        snprintf(cache, sizeof cache, "%s/pipeline-cache.bin", save);
    for (int i = 0; i < nspecs; i++) {
        rt_render_desc rd = {
            .width = width, .height = height, .lod_pixels = v[i].lod,
            .no_shadows = v[i].no_shadows, .no_undergrowth = !v[i].ug,
            .no_distance_classes = v[i].no_dclass, .pixel_sort = v[i].sort,
            .async_pipelines = v[i].async,
            .sort_tiles = v[i].sort_tiles,
            .undergrowth_radius = v[i].ug_radius, .far_atlas_distance = v[i].far,
            .reference = v[i].k == K_MULTIPASS ? RT_REF_MULTIPASS
                       : v[i].k == K_UBER || v[i].k == K_SCREEN_UBER ? RT_REF_UBER : RT_REF_NONE,
            .pipeline_cache = save ? cache : NULL,
            .shading = IS_SCREEN(v[i].k) ? RT_SHADING_SCREEN : RT_SHADING_FORWARD,
            .screen_depth = v[i].k == K_SCREEN_RASTER ? RT_DEPTH_RASTER
                          : v[i].k == K_SCREEN_RAYCAST ? RT_DEPTH_RAYCAST : RT_DEPTH_AUTO,
        };
        double before = rss_mb();
        if (!rt_renderer_create(&dev, &v[i].view, &rd, &v[i].r, &e))
            goto done;
        splat_view view;
        int material = 0;
        if (!rt_parse_view(view_name, &v[i].view, &view, &material, &e))
            goto done;
        rt_renderer_set_view(v[i].r, view, material);
        v[i].gpu = xcalloc((size_t)frames, sizeof(double));
        v[i].cpu = xcalloc((size_t)frames, sizeof(double));
        v[i].sel = xcalloc((size_t)frames, sizeof(double));
        for (int k = 0; k < 3; k++)
            v[i].pass[k] = xcalloc((size_t)frames, sizeof(double));
        v[i].ug_gen = xcalloc((size_t)frames, sizeof(double));
        v[i].ug_draw = xcalloc((size_t)frames, sizeof(double));
        /* warm-up frames: pipelines are made (and JIT-compiled) on first use */
        rt_camera cam;
        rt_frame_stats st;
        for (int w = 0; w < (warmup < 0 ? frames : warmup); w++) {
            if (!path_camera(&v[i].view, &pd, warmup < 0 ? w : 0, frames, &cam))
                goto done;
            if (!rt_renderer_frame(v[i].r, &cam, &st, &e))
                goto done;
            v[i].shadow_ms += st.shadow_ms;
        }
        v[i].rss_delta = rss_mb() - before;
    }
    for (int f = 0; f < frames; f++) {
        rt_camera cam;
        if (!path_camera(&packs[0], &pd, f, frames, &cam))
            goto done;
        /* the reference first, so the others compare against this frame */
        for (int o = 0; o < nspecs; o++) {
            int i = o == 0 ? ref : o == ref ? 0 : o;
            rt_frame_stats st;
            if (!rt_renderer_frame(v[i].r, &cam, &st, &e))
                goto done;
            v[i].gpu[f] = st.gpu_ms;
            v[i].cpu[f] = st.cpu_ms;
            v[i].sel[f] = st.select_ms;
            for (int k = 0; k < 3; k++)
                v[i].pass[k][f] = st.pass_ms[k];
            v[i].ug_gen[f] = st.undergrowth.gen_ms;
            v[i].ug_draw[f] = st.undergrowth.draw_ms;
            v[i].ug_cells += st.undergrowth.generated;
            v[i].ug_last = st.undergrowth;
            v[i].patches = st.patches;
            v[i].pipelines = st.pipelines;
            if (!rt_renderer_read(v[i].r, i == ref ? refimg : img, &e))
                goto done;
            err_add(&v[i].err, i == ref ? refimg : img, refimg, npx);
            if (save && f == frames - 1) {
                char path[4096];
                snprintf(path, sizeof path, "%s/%s.f32", save, v[i].label);
                if (!rt_write_float(path, i == ref ? refimg : img, width, height, &e))
                    goto done;
            }
        }
    }

    /* one counting frame per variant the pack's GLSL shades (the screen
     * kinds, composite and uber), after the timed ones */
    for (int i = 0; i < nspecs; i++) {
        if (!IS_SCREEN(v[i].k) && !(dev.count_fragments &&
                                    (v[i].k == K_COMPOSITE || v[i].k == K_UBER)))
            continue;
        rt_camera cam;
        rt_frame_stats st;
        if (!path_camera(&packs[0], &pd, frames - 1, frames, &cam))
            goto done;
        rt_renderer_set_counting(v[i].r, true);
        if (!rt_renderer_frame(v[i].r, &cam, &st, &e))
            goto done;
        v[i].tiles = st.tiles;
        if (!st.screen)   /* forward: the far column counts patches */
            v[i].tiles.tiles_far = st.far_patches;
    }

    FILE *out = stdout;
    bool header = true;
    if (csv) {
        struct stat sb;
        header = stat(csv, &sb) != 0 || sb.st_size == 0;
        out = fopen(csv, "a");
        if (!out) {
            fprintf(stderr, "splatbench: cannot write '%s': %s\n", csv, strerror(errno));
            goto done;
        }
    }
    if (header)
        fprintf(out, "device,scene,path,width,height,variant,kind,pack,lod_pixels,frames,"
                     "gpu_med_ms,gpu_p10_ms,gpu_p90_ms,cpu_med_ms,select_med_ms,patches,"
                     "pipelines,max_abs,mean_abs,psnr_db,nonfinite,rss_delta_mb,reference,view,"
                     "geometry_ms,classify_ms,shade_ms,tiles,tiles_uber,layers_evaluated,"
                     "layers_needed,samples_per_px,branches_uniform_pct,shadow_map_ms,"
                     "ug_gen_med_ms,ug_gen_ms_per_cell,ug_draw_med_ms,ug_cells_per_frame,"
                     "ug_instances,ug_bytes_per_cell,far_distance,tiles_far,distclass,tiles_class\n");
    /* the device name in CSV: its commas become ';' */
    char devname[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE];
    snprintf(devname, sizeof devname, "%s", dev.props.deviceName);
    for (char *c = devname; *c; c++)
        if (*c == ',' || *c == '"')
            *c = ';';
    for (int i = 0; i < nspecs; i++) {
        double gm, g10, g90, cm, c10, c90, sm, s10, s90;
        percentiles(v[i].gpu, frames, &gm, &g10, &g90);
        percentiles(v[i].cpu, frames, &cm, &c10, &c90);
        percentiles(v[i].sel, frames, &sm, &s10, &s90);
        double pm[3] = { -1, -1, -1 }, lo, hi;
        bool scr = IS_SCREEN(v[i].k);
        for (int k = 0; k < 3 && scr; k++)
            percentiles(v[i].pass[k], frames, &pm[k], &lo, &hi);
        double px = v[i].tiles.pixels ? (double)v[i].tiles.pixels : 1.0;
        double ugm = -1, ugd = -1, gen_sum = 0;
        if (v[i].ug) {
            percentiles(v[i].ug_gen, frames, &ugm, &lo, &hi);
            percentiles(v[i].ug_draw, frames, &ugd, &lo, &hi);
            for (int f = 0; f < frames; f++)
                gen_sum += v[i].ug_gen[f];
        }
        const char *pk = strrchr(v[i].pack_dir, '/');
        fprintf(out, "\"%s\",%s,%s,%d,%d,%s,%s,%s,%g,%d,%.3f,%.3f,%.3f,%.3f,%.4f,%d,%d,"
                     "%.6g,%.6g,%.2f,%ld,%.1f,%s,%s,%.3f,%.3f,%.3f,%d,%d,%.4f,%.4f,%.3f,%.1f,"
                     "%.2f,%.4f,%.4f,%.4f,%.2f,%ld,%zu,%g,%d,%d,%d\n",
                devname, scene ? scene : v[i].base->name, pd.name, width, height,
                v[i].label, kind_names[v[i].k], pk ? pk + 1 : v[i].pack_dir,
                v[i].lod > 0 ? v[i].lod : 3.0, frames, gm, g10, g90, cm, sm,
                v[i].patches, v[i].pipelines, v[i].err.max_abs,
                v[i].err.n ? v[i].err.sum_abs / (double)v[i].err.n : 0.0,
                err_psnr(&v[i].err), v[i].err.nonfinite, v[i].rss_delta, v[ref].label,
                view_name, pm[0], pm[1], pm[2], v[i].tiles.tiles, v[i].tiles.tiles_uber,
                v[i].tiles.layers_evaluated / px, v[i].tiles.layers_needed / px,
                v[i].tiles.samples / px,
                v[i].tiles.branches ? 100.0 * v[i].tiles.branches_uniform / v[i].tiles.branches
                                    : 100.0,
                v[i].shadow_ms, ugm, v[i].ug_cells ? gen_sum / (double)v[i].ug_cells : -1.0,
                ugd, (double)v[i].ug_cells / frames, v[i].ug_last.instances,
                v[i].ug_last.bytes_per_cell, v[i].far, v[i].tiles.tiles_far, !v[i].no_dclass,
                v[i].tiles.tiles_class);
    }
    if (csv)
        fclose(out);
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    for (int i = 0; i < nspecs; i++)
        variant_free(&v[i]);
    if (have_dev) {
        if (dev.validating && dev.messages) {
            fprintf(stderr, "splatbench: %d validation message(s)\n", dev.messages);
            status = status ? status : 3;
        }
        rt_device_destroy(&dev);
    }
    for (int k = 0; k < npacks; k++)
        rt_pack_free(&packs[k]);
    free(packs);
    free(pack_dirs);
    free(v);
    free(specs);
    free(img);
    free(refimg);
    return status;
}

/* ---- upscale ---------------------------------------------------------------- */

static int cmd_upscale(int argc, char **argv)
{
    if (argc != 5 || atoi(argv[3]) < 1) {
        fprintf(stderr, "usage: splatbench upscale IN.png K OUT\n");
        return 2;
    }
    const char *in = argv[2], *outp = argv[4];
    int k = atoi(argv[3]), w, h, ch;
    bool sixteen = stbi_is_16_bit(in);
    void *px = sixteen ? (void *)stbi_load_16(in, &w, &h, &ch, 1) : (void *)stbi_load(in, &w, &h, &ch, 1);
    if (!px) {
        fprintf(stderr, "splatbench: cannot read '%s': %s\n", in, stbi_failure_reason());
        return 1;
    }
    /* texel centres stay aligned: output texel i samples input (i + 0.5)/k - 0.5 */
    size_t W = (size_t)w * (size_t)k, H = (size_t)h * (size_t)k;
    int status = 0;
    if (sixteen) {
        const uint16_t *s = px;
        uint16_t *o = xcalloc(W * H, 2);
        for (size_t j = 0; j < H; j++) {
            double v = fmin(fmax((j + 0.5) / k - 0.5, 0), h - 1);
            int j0 = (int)v, j1 = j0 + 1 < h ? j0 + 1 : j0;
            double fv = v - j0;
            for (size_t i = 0; i < W; i++) {
                double u = fmin(fmax((i + 0.5) / k - 0.5, 0), w - 1);
                int i0 = (int)u, i1 = i0 + 1 < w ? i0 + 1 : i0;
                double fu = u - i0;
                double a = s[(size_t)j0 * w + i0] * (1 - fu) + s[(size_t)j0 * w + i1] * fu;
                double b = s[(size_t)j1 * w + i0] * (1 - fu) + s[(size_t)j1 * w + i1] * fu;
                o[j * W + i] = (uint16_t)lround(a * (1 - fv) + b * fv);   /* little-endian host */
            }
        }
        FILE *f = fopen(outp, "wb");
        if (!f || fwrite(o, 2, W * H, f) != W * H) {
            fprintf(stderr, "splatbench: cannot write '%s'\n", outp);
            status = 1;
        }
        if (f)
            fclose(f);
        free(o);
    } else {
        const uint8_t *s = px;
        uint8_t *o = xcalloc(W * H, 1);
        for (size_t j = 0; j < H; j++)
            for (size_t i = 0; i < W; i++)
                o[j * W + i] = s[(j / (size_t)k) * (size_t)w + i / (size_t)k];
        stbi_write_png_compression_level = 1;
        if (!stbi_write_png(outp, (int)W, (int)H, 1, o, (int)W)) {
            fprintf(stderr, "splatbench: cannot write '%s'\n", outp);
            status = 1;
        }
        free(o);
    }
    stbi_image_free(px);
    printf("%s: %zu x %zu\n", outp, W, H);
    return status;
}

/* ---- analytic-hf ----------------------------------------------------------- */

static int cmd_analytic_hf(int argc, char **argv)
{
    int w = argc == 5 ? atoi(argv[2]) : 0, h = argc == 5 ? atoi(argv[3]) : 0;
    if (w < 1 || h < 1) {
        fprintf(stderr, "usage: splatbench analytic-hf W H OUT.r16\n");
        return 2;
    }
    FILE *f = fopen(argv[4], "wb");
    if (!f) {
        fprintf(stderr, "splatbench: cannot write '%s'\n", argv[4]);
        return 1;
    }
    bool ok = true;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            long q = lround(analytic_height((i + 0.5) / w, (j + 0.5) / h) * 65535.0);
            uint8_t b[2] = {(uint8_t)(q & 255), (uint8_t)(q >> 8)};
            ok = ok && fwrite(b, 1, 2, f) == 2;
        }
    if (fclose(f) != 0 || !ok) {
        fprintf(stderr, "splatbench: cannot write '%s'\n", argv[4]);
        return 1;
    }
    return 0;
}

/* ---- compare ------------------------------------------------------------------ */

static int cmd_compare(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: splatbench compare A.f32 B.f32\n");
        return 2;
    }
    float *a = NULL, *b = NULL;
    int wa, ha, wb, hb;
    rt_error e = {0};
    int status = 1;
    if (!rt_read_float(argv[2], &a, &wa, &ha, &e) || !rt_read_float(argv[3], &b, &wb, &hb, &e))
        goto done;
    if (wa != wb || ha != hb) {
        fprintf(stderr, "splatbench: images differ in size (%dx%d, %dx%d)\n", wa, ha, wb, hb);
        goto done;
    }
    err_acc acc = {0};
    err_add(&acc, a, b, (size_t)wa * (size_t)ha);
    printf("max_abs %.6g mean_abs %.6g psnr_db %.2f nonfinite %ld\n", acc.max_abs,
           acc.n ? acc.sum_abs / (double)acc.n : 0.0, err_psnr(&acc), acc.nonfinite);
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    free(a);
    free(b);
    return status;
}

/* splatbench far-bake --pack P [--far-atlas N] [--runs K] [--out PREFIX]:
 * the far atlas baked on the device (runtime/far_bake.c) from pack P, one
 * texel per N x N heightfield texels, K times (the first compiles with a
 * cold pipeline cache of its own, the later ones hit it): per run the
 * combinations compiled and the seconds of compiling and of shading.
 * --out writes the last run's level 0 for `splatbench compare`:
 * PREFIX.albedo.f32 (albedo rgb, roughness) and PREFIX.normal.f32 (xyz, 1). */
static int cmd_far_bake(int argc, char **argv)
{
    const char *pack_dir = NULL, *out = NULL;
    int n = 1, runs = 1;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--pack") && next)
            pack_dir = argv[++i];
        else if (!strcmp(a, "--far-atlas") && next)
            n = atoi(argv[++i]);
        else if (!strcmp(a, "--runs") && next)
            runs = atoi(argv[++i]);
        else if (!strcmp(a, "--out") && next)
            out = argv[++i];
        else {
            fprintf(stderr, "usage: splatbench far-bake --pack P [--far-atlas N] [--runs K] "
                            "[--out PREFIX]\n");
            return 2;
        }
    }
    if (!pack_dir || n < 1 || n > 64 || runs < 1) {
        fprintf(stderr, "splatbench far-bake: --pack, N in 1..64 and K >= 1 needed\n");
        return 2;
    }
    rt_error e = {0};
    rt_pack p;
    rt_device dev;
    rt_renderer *r = NULL;
    bool have_pack = false, have_dev = false;
    int status = 1;
    float *al = NULL, *no = NULL, *ro = NULL, *img = NULL;
    char cache[64];
    snprintf(cache, sizeof cache, "/tmp/splatbench-farbake-%d.bin", (int)getpid());
    remove(cache);
    if (!(have_pack = rt_pack_load(&p, pack_dir, &e)) ||
        !(have_dev = rt_device_create(&dev, NULL, &e)))
        goto done;
    int w = (p.hf_width + n - 1) / n, h = (p.hf_height + n - 1) / n;
    size_t texels = (size_t)w * (size_t)h;
    al = xcalloc(texels * 3, sizeof *al);
    no = xcalloc(texels * 3, sizeof *no);
    ro = xcalloc(texels, sizeof *ro);
    printf("device %s, far atlas %d x %d texels (N = %d)\n", dev.props.deviceName, w, h, n);
    printf("run,combos,compile_s,shade_s,total_s\n");
    for (int k = 0; k < runs; k++) {
        rt_render_desc rd = { .width = 8, .height = 8, .no_undergrowth = true, .no_shadows = true,
                              .pipeline_cache = cache };
        rt_far_bake_stats st;
        if (!rt_renderer_create(&dev, &p, &rd, &r, &e) ||
            !rt_renderer_bake_far(r, w, h, al, no, ro, &st, &e))
            goto done;
        rt_renderer_destroy(r);   /* saves the pipeline cache */
        r = NULL;
        printf("%d,%d,%.3f,%.3f,%.3f\n", k + 1, st.combos, st.compile_s, st.shade_s,
               st.compile_s + st.shade_s);
    }
    if (out) {
        img = xcalloc(texels * 4, sizeof *img);
        char path[4096];
        for (size_t i = 0; i < texels; i++) {
            memcpy(img + 4 * i, al + 3 * i, 3 * sizeof *img);
            img[4 * i + 3] = ro[i];
        }
        snprintf(path, sizeof path, "%s.albedo.f32", out);
        if (!rt_write_float(path, img, w, h, &e))
            goto done;
        for (size_t i = 0; i < texels; i++) {
            memcpy(img + 4 * i, no + 3 * i, 3 * sizeof *img);
            img[4 * i + 3] = 1.0f;
        }
        snprintf(path, sizeof path, "%s.normal.f32", out);
        if (!rt_write_float(path, img, w, h, &e))
            goto done;
    }
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    rt_renderer_destroy(r);
    if (have_dev)
        rt_device_destroy(&dev);
    if (have_pack)
        rt_pack_free(&p);
    remove(cache);
    free(al);
    free(no);
    free(ro);
    free(img);
    return status;
}

/* splatbench shadow --pack P [--runs K] [--sun AZ,EL]: the terrain's
 * shadow map marched on the CPU (shadow.c, the reference) and on the
 * device (shadow_gpu.c), side by side: K maps each, the two paths
 * interleaved (map k of the CPU, then of the device, so a change of machine
 * load hits both), the sun turned by 0.01 degree between maps so each is
 * made whole.  Prints one CSV row per map, then per path the median, p10
 * and p90 wall milliseconds, the ratio of the medians, and the largest
 * difference of the last two maps (1/255). */
static int cmd_shadow(int argc, char **argv)
{
    const char *pack_dir = NULL;
    int runs = 5;
    double sun[2] = { 144, 21 };
    bool sun_set = false;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--pack") && next)
            pack_dir = argv[++i];
        else if (!strcmp(a, "--runs") && next)
            runs = atoi(argv[++i]);
        else if (!strcmp(a, "--sun") && next && sscanf(argv[++i], "%lf,%lf", &sun[0], &sun[1]) == 2)
            sun_set = true;
        else {
            fprintf(stderr, "usage: splatbench shadow --pack P [--runs K] [--sun AZ,EL]\n");
            return 2;
        }
    }
    if (!pack_dir || runs < 1) {
        fprintf(stderr, "splatbench shadow: --pack and K >= 1 needed\n");
        return 2;
    }
    rt_error e = {0};
    rt_pack p;
    rt_device dev;
    rt_renderer *r[2] = { NULL, NULL };
    bool have_pack = false, have_dev = false;
    int status = 1;
    double *ms = NULL;
    uint8_t *map[2] = { NULL, NULL };
    static const char *const names[2] = { "cpu", "gpu" };
    if (!(have_pack = rt_pack_load(&p, pack_dir, &e)) ||
        !(have_dev = rt_device_create(&dev, NULL, &e)))
        goto done;
    size_t n = (size_t)p.hf_width * (size_t)p.hf_height;
    ms = xcalloc((size_t)runs * 2, sizeof *ms);
    map[0] = xcalloc(n, 1);
    map[1] = xcalloc(n, 1);
    for (int k = 0; k < 2; k++) {
        rt_render_desc rd = { .width = 8, .height = 8, .no_undergrowth = true,
                              .shading = RT_SHADING_FORWARD,
                              .shadow = k ? RT_SHADOW_GPU : RT_SHADOW_CPU };
        if (!rt_renderer_create(&dev, &p, &rd, &r[k], &e))
            goto done;
    }
    rt_light l = *rt_renderer_light(r[0]);
    if (sun_set)
        memcpy(l.sun, sun, sizeof sun);
    printf("device %s, heightfield %d x %d, sun %g/%g, %d maps per path\n", dev.props.deviceName,
           p.hf_width, p.hf_height, l.sun[0], l.sun[1], runs);
    rt_camera cam;
    rt_default_camera(&p, &cam);
    /* an untimed map each: the device's pyramid and pipeline are made,
     * llvmpipe compiles the shader at its first dispatch */
    for (int k = 0; k < 2; k++) {
        rt_renderer_set_light(r[k], &l);
        if (!rt_renderer_frame(r[k], &cam, NULL, &e))
            goto done;
    }
    printf("run,path,ms\n");
    for (int i = 0; i < runs; i++) {
        l.sun[0] += 0.01;
        for (int k = 0; k < 2; k++) {
            rt_frame_stats st;
            rt_renderer_set_light(r[k], &l);
            if (!rt_renderer_frame(r[k], &cam, &st, &e))
                goto done;
            ms[k * runs + i] = st.shadow_ms;
            printf("%d,%s,%.2f\n", i + 1, names[k], st.shadow_ms);
        }
    }
    int worst = 0;
    for (int k = 0; k < 2; k++)
        if (!rt_renderer_shadow_read(r[k], map[k], &e))
            goto done;
    for (size_t i = 0; i < n; i++) {
        int d = abs((int)map[0][i] - (int)map[1][i]);
        worst = d > worst ? d : worst;
    }
    double med[2], lo[2], hi[2];
    for (int k = 0; k < 2; k++) {
        percentiles(ms + k * runs, runs, &med[k], &lo[k], &hi[k]);
        printf("shadow map %s ms: median %.1f  p10 %.1f  p90 %.1f\n", names[k], med[k], lo[k],
               hi[k]);
    }
    printf("shadow map cpu / gpu: %.2fx; largest difference %d/255\n", med[0] / med[1], worst);
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    rt_renderer_destroy(r[0]);
    rt_renderer_destroy(r[1]);
    if (have_dev)
        rt_device_destroy(&dev);
    if (have_pack)
        rt_pack_free(&p);
    free(ms);
    free(map[0]);
    free(map[1]);
    return status;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && !strcmp(argv[1], "far-bake"))
        return cmd_far_bake(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "shadow"))
        return cmd_shadow(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "render"))
        return cmd_render(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "upscale"))
        return cmd_upscale(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "compare"))
        return cmd_compare(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "analytic-hf"))
        return cmd_analytic_hf(argc, argv);
    fprintf(stderr, "usage: splatbench render|upscale|compare|far-bake|shadow ... (see tests/bench/splatbench.c)\n");
    return 2;
}
