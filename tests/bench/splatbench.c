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
 *       RGB, PSNR with peak 1, count of NaN/Inf values); the last column,
 *       proc_cpu_med_ms, is the process's CPU time per frame over every
 *       thread (on lavapipe the rendering's work itself, which a loaded
 *       machine does not inflate as it does wall and timestamp times).  One
 *       CSV row per variant.  KIND:
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
 *       camera instead of the runtime's 96, ugcompute=1 draws the
 *       instances that fit 64 pixels in compute (runtime/undergrowth_craster.c;
 *       ug_drawn_compute: how many of ug_drawn; the draw's parts
 *       ug_gfx_ms, ug_cs_raster_ms (and the contact shadows), ug_cs_resolve_ms,
 *       -1 where not run), ugthin=D thins it (the distance
 *       LOD's fraction (D / d)^2) from D metres instead of 14, the far
 *       meshes staying at 14 m (rt_render_desc.undergrowth_thin): its rows add
 *       the generation GPU ms per frame and per generated cell, the draw GPU
 *       ms per frame, the instances and the memory per cell, and of the last
 *       frame the candidates, the instances and triangles drawn and the
 *       indirect draws.  far=D shades screen tiles
 *       (screen kinds) or quadtree patches (composite) at least D m away
 *       from the pack's far atlas (splatc build --far-atlas); its rows add
 *       the distance and the tiles (patches) the atlas shaded (from the
 *       counting frame).  preview=S renders at 1/S of the size (2 or 4)
 *       and upsamples with the depth edges (--preview-scale).  cpulod=on|off
 *       turns the CPU shading LOD on or off (rt_shading_lod; by default on
 *       CPU devices only: footprint derivatives off, nearest mip level,
 *       lod_pixels 6 unless lod= is given).  distclass=0 shades with the
 *       combinations only (--no-distance-classes; PACK.md "Distance
 *       classes"), distclass=1 (the default) with their distance classes;
 *       async (screen kinds) makes compute pipelines on worker threads,
 *       a stand-in shading their tiles meanwhile (first pictures; the far
 *       atlas, the flat stand-in or the über-shader: $SPLAT_STAND_IN,
 *       rt_pipelines_stand_in; the columns stand_in_uber, _atlas, _flat
 *       count the last timed frame's tiles each drew, first_picture_s the
 *       seconds from the process's launch to the variant's first complete
 *       frame);
 *       sort=on|off (screen kinds) sorts each workgroup's pixels by the
 *       layers they need before shading (rt_pixel_sort; default off),
 *       sort=N on with N tiles per workgroup (4, 8 or 16; on: the most
 *       the device allows, 16 on GPUs and lavapipe); tiles=blocks|rows
 *       (screen kinds) classifies, so lists, the tiles in 4x4 blocks of
 *       tiles or by rows (the default; rt_render_desc.tile_blocks): the
 *       same picture, neighbouring tiles one after another in each list;
 *       the kinds that recompile the composites (flat fp16 sobel analytic
 *       lambert) always run without them.
 *       --lanes (screen kinds, unsorted, full size) renders the path's last
 *       two frames again in the layers view and prints, per variant, the
 *       layer efficiency measured on this device beside the efficiency
 *       predicted for subgroups of 8, 32 and 64 lanes and other pixel
 *       orders within the 8x8 tile (bench_lanes.c), lines "lanes LABEL:";
 *       --lanes-step K takes the frame before 1/K of a frame step earlier.
 *       Paths (--path): ground (2 m above the terrain looking 150 m ahead,
 *       from --start-preset NAME or --start x,z,dx,dz), topdown, grazing,
 *       preset (--start-preset NAME's camera itself, still).
 *       --warmup N (default 1) untimed frames at the path's start first;
 *       --warmup path: every frame of the path once, untimed, so nothing a
 *       view needs is made or JIT-compiled inside a timed frame (llvmpipe
 *       compiles shader variants when a draw or dispatch first needs them,
 *       inside the GPU timestamps).
 *   splatbench far-bake --pack P [--far-atlas N] [--runs K] [--out PREFIX]
 *       the far atlas baked on the device (bench_device.c says more).
 *   splatbench shadow --pack P [--runs K] [--sun AZ,EL]
 *       the shadow map marched on the CPU and on the device, side by side
 *       (bench_device.c says more).
 *   splatbench upscale IN.png K OUT
 *       K times the texels per side, bilinear: a 16-bit PNG becomes raw
 *       little-endian R16 (OUT), an 8-bit one an 8-bit PNG (nearest).
 *   splatbench analytic-hf W H OUT.r16
 *       a W x H raw R16 heightfield sampling analytic_height() at texel
 *       centres (the reference of the normal-filter knob).
 *   splatbench compare A.f32 B.f32
 *       max/mean abs error and PSNR of two --float-out images.
 *
 * The options of render, far-bake and shadow are tables (compiler/args.h):
 * `splatbench COMMAND --help` lists them.  This file is the render command
 * (variants, camera paths, the run); bench.h names the other files.
 * Exit status: 0 ok, 1 a failure (message on stderr), 2 usage. */
#include "bench.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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
    bool         tile_blocks; /* tiles=blocks                               */
    bool         no_dclass; /* distclass=0                                 */
    bool         async;     /* async: pipelines made on workers, the über-
                               shader standing in (screen kinds)          */
    bool         ug;        /* draw the undergrowth                         */
    double       ug_radius; /* its radius (m); 0: the runtime's default     */
    double       ug_thin;   /* its thinning distance (m); 0: the runtime's  */
    bool         ug_compute; /* small instances drawn in compute           */
    double       far;       /* screen: the far atlas's distance (m); 0: off */
    int          preview;   /* the preview scale (2, 4); 0: full resolution */
    rt_shading_lod cpulod;  /* cpulod=on|off: the CPU shading LOD; default auto */
    double       shadow_ms; /* ms of the shadow map (the first frame)       */
    double      *ug_gen, *ug_draw; /* per timed frame, GPU ms               */
    double      *ug_part[3];       /* the draw's graphics pass, compute raster
                                      and shadows, resolve (ms; < 0: none)  */
    long         ug_cells;  /* cells generated over the timed frames        */
    rt_ug_stats  ug_last;   /* the last frame's                             */
    rt_pack     *base;      /* loaded pack (shared by variants of one dir)  */
    rt_pack      view;      /* shallow copy with this variant's combos      */
    rt_pack_combo *combos;  /* owned when the shaders differ, else NULL     */
    rt_renderer *r;
    double      *gpu, *cpu, *sel;
    double      *proc;      /* process CPU ms of each frame (all threads)   */
    double      *pass[3];   /* screen: geometry, classification, shading */
    rt_screen_stats tiles;  /* screen: the last frame's tiles (counted)  */
    double       first_picture_s; /* launch to its first complete frame   */
    int          stand_in[3];     /* the last timed frame's stand-in tiles:
                                     über-shader, far atlas, flat         */
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

/* The analytic heightfield's exact normal in GLSL (terrain.x, .y: size in
 * metres, .z: max height), written from analytic_height's formula. */
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
    free(v->proc);
    free(v->sel);
    free(v->ug_gen);
    free(v->ug_draw);
    for (int k = 0; k < 3; k++)
        free(v->ug_part[k]);
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
        } else if (!strcmp(t, "tiles=blocks") || !strcmp(t, "tiles=rows")) {
            v->tile_blocks = t[6] == 'b';
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
        } else if (!strncmp(t, "ugcompute=", 10)) {
            v->ug = true;
            v->ug_compute = atoi(t + 10) != 0;
            ok = !strcmp(t + 10, "0") || !strcmp(t + 10, "1");
        } else if (!strncmp(t, "ugthin=", 7)) {
            v->ug = true;
            v->ug_thin = atof(t + 7);
            ok = v->ug_thin > 0;
        } else if (!strncmp(t, "far=", 4)) {
            v->far = atof(t + 4);
            ok = v->far > 0;
        } else if (!strncmp(t, "preview=", 8)) {
            v->preview = atoi(t + 8);
            ok = v->preview == 1 || v->preview == 2 || v->preview == 4;
        } else if (!strcmp(t, "cpulod=on") || !strcmp(t, "cpulod=off")) {
            v->cpulod = t[9] == 'n' ? RT_SHADING_LOD_ON : RT_SHADING_LOD_OFF;
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
    } else if (!strcmp(pd->name, "preset")) {
        /* the camera preset itself, still: every frame the same view */
        int k = pd->preset ? rt_pack_camera_find(p, pd->preset) : -1;
        if (k < 0) {
            fprintf(stderr, "splatbench: path 'preset' needs --start-preset NAME of the pack\n");
            return false;
        }
        memcpy(c->position, p->cameras[k].position, sizeof c->position);
        memcpy(c->look, p->cameras[k].look, sizeof c->look);
    } else {
        fprintf(stderr, "splatbench: unknown path '%s' (ground, topdown, grazing, preset)\n",
                pd->name);
        return false;
    }
    return true;
}

/* ---- render ---------------------------------------------------------------- */

/* `splatbench render`'s options (the table below). */
typedef struct render_opts {
    const char *pack_dir, *csv, *scene, *save, *ref_label, *view_name;
    path_desc   pd;
    int         width, height, frames, warmup;   /* warmup -1: the whole path */
    const char *specs[128];                      /* --variant LABEL=KIND,...  */
    int         nspecs;
    bool        lanes;                           /* --lanes                   */
    bool        print_plan;                      /* --print-plan              */
    int         lanes_step;                      /* --lanes-step K            */
} render_opts;

static bool parse_start(const char *v, void *o_, splat_arg_why *why)
{
    render_opts *o = o_;
    char tail;
    (void)why;
    return sscanf(v, "%lf,%lf,%lf,%lf%c", &o->pd.start[0], &o->pd.start[1], &o->pd.start[2],
                  &o->pd.start[3], &tail) == 4;
}

static bool parse_warmup(const char *v, void *o_, splat_arg_why *why)
{
    render_opts *o = o_;
    char *end;
    (void)why;
    long n = strtol(v, &end, 10);
    o->warmup = !strcmp(v, "path") ? -1 : (int)n;
    return !strcmp(v, "path") || (*v && !*end && n >= 0 && n <= 100000);
}

static bool parse_size(const char *v, void *o_, splat_arg_why *why)
{
    render_opts *o = o_;
    char tail;
    (void)why;
    return sscanf(v, "%dx%d%c", &o->width, &o->height, &tail) == 2 && o->width > 0 &&
           o->height > 0 && o->width <= 16384 && o->height <= 16384;
}

#define F(field) offsetof(render_opts, field)
static const splat_arg render_rows[] = {
    { "--variant", SPLAT_ARG_LIST, "LABEL=KIND[,KNOB...]", "a variant to render (repeatable; "
      "the kinds and knobs: the comment atop tests/bench/splatbench.c)", F(specs),
      .count = F(nspecs), .capacity = 128 },
    { "--pack", SPLAT_ARG_STRING, "DIR", "the pack of the variants without pack=",
      F(pack_dir) },
    { "--ref", SPLAT_ARG_STRING, "LABEL", "the variant the others are compared against "
      "(default the first)", F(ref_label) },
    { "--path", SPLAT_ARG_STRING, "ground|topdown|grazing", "the camera path (default "
      "ground)", F(pd.name) },
    { "--start-preset", SPLAT_ARG_STRING, "NAME", "ground: start at this camera preset",
      F(pd.preset) },
    { "--start", SPLAT_ARG_CUSTOM, "X,Z,DX,DZ", "ground: start here, heading along DX,DZ",
      .parse = parse_start, .given = SPLAT_ARG_GIVEN(render_opts, pd.have_start) },
    { "--frames", SPLAT_ARG_INT, "N", "timed frames along the path (default 5)", F(frames),
      .min = 1, .max = 1e6, .expects = "a positive count" },
    { "--warmup", SPLAT_ARG_CUSTOM, "N|path", "N untimed frames at the path's start first "
      "(default 1), or every frame of the path once", .parse = parse_warmup,
      .expects = "a count >= 0 or 'path'" },
    { "--size", SPLAT_ARG_CUSTOM, "WxH", "image size (default 1280x720)", .parse = parse_size,
      .expects = "WxH (1..16384 each)" },
    { "--view", SPLAT_ARG_STRING, "V", "the view rendered (default final)", F(view_name) },
    { "--csv", SPLAT_ARG_STRING, "FILE", "append the rows to FILE (header when new) instead "
      "of stdout", F(csv) },
    { "--scene", SPLAT_ARG_STRING, "NAME", "the scene column (default the pack's name)",
      F(scene) },
    { "--print-plan", SPLAT_ARG_FLAG, NULL, "print each variant's last timed frame's plan "
      "with each pass's GPU time (as splatview --print-plan --stats) to stderr", F(print_plan) },
    { "--lanes", SPLAT_ARG_FLAG, NULL, "screen kinds: print the layer efficiency predicted "
      "for 8, 32 and 64 lanes per subgroup and other pixel orders (bench_lanes.c)", F(lanes) },
    { "--lanes-step", SPLAT_ARG_INT, "K", "--lanes: the frame before is 1/K of a frame step "
      "earlier on the path (default 1), as a slower camera would see it", F(lanes_step),
      .min = 1, .max = 1000, .expects = "1 to 1000" },
    { "--save", SPLAT_ARG_STRING, "DIR", "write each variant's last frame as DIR/LABEL.f32 "
      "and keep a pipeline cache there", F(save) },
};
#undef F

static const splat_args_desc render_args = {
    .prog = "splatbench render",
    .usage = "usage: splatbench render --variant LABEL=KIND[,pack=DIR][,lod=P]... [options]\n",
    .args = render_rows, .nargs = (int)(sizeof render_rows / sizeof render_rows[0]),
    .column = 28,
};

/* One render run: the variants, their packs, the device and the images. */
typedef struct bench_run {
    const render_opts *o;
    variant *v;
    int      nv, ref;
    rt_pack *packs;
    const char **pack_dirs;
    int      npacks;
    rt_device dev;
    bool     have_dev;
    float   *img, *refimg;
    size_t   npx;
} bench_run;

/* The variants of --variant, --ref's index, every distinct pack loaded
 * once.  Exit status 2 on a bad variant or --ref. */
static int load_variants(bench_run *b, rt_error *e)
{
    const render_opts *o = b->o;
    for (int i = 0; i < b->nv; i++)
        if (!parse_variant(o->specs[i], o->pack_dir, &b->v[i])) {
            fprintf(stderr, "splatbench render: bad variant '%s' (LABEL=KIND[,pack=DIR][,lod=P];"
                    " KIND composite|multipass|uber|flat|fp16|sobel|analytic|screen|screen_uber|"
                    "screen_raster|screen_raycast; a pack from --pack or pack=)\n", o->specs[i]);
            return 2;
        }
    if (o->ref_label) {
        b->ref = -1;
        for (int i = 0; i < b->nv; i++)
            if (!strcmp(b->v[i].label, o->ref_label))
                b->ref = i;
        if (b->ref < 0) {
            fprintf(stderr, "splatbench render: --ref '%s' is not a variant\n", o->ref_label);
            return 2;
        }
    }
    for (int i = 0; i < b->nv; i++) {
        int k = 0;
        while (k < b->npacks && strcmp(b->pack_dirs[k], b->v[i].pack_dir))
            k++;
        if (k == b->npacks) {
            if (!rt_pack_load(&b->packs[k], b->v[i].pack_dir, e))
                return 1;
            b->pack_dirs[b->npacks++] = b->v[i].pack_dir;
        }
        b->v[i].base = &b->packs[k];
        if (b->packs[k].hf_width != b->packs[0].hf_width ||
            b->packs[k].hf_height != b->packs[0].hf_height) {
            fprintf(stderr, "splatbench: pack '%s' has another terrain than '%s'\n",
                    b->v[i].pack_dir, b->pack_dirs[0]);
            return 1;
        }
        if (!variant_shaders(&b->v[i]))
            return 1;
    }
    return 0;
}

/* Variant i's renderer, its per-frame arrays and its warm-up frames
 * (pipelines are made, and JIT-compiled, on first use). */
static bool make_renderer(bench_run *b, int i, const char *cache, rt_error *e)
{
    const render_opts *o = b->o;
    variant *v = &b->v[i];
    rt_render_desc rd = {
        .width = o->width, .height = o->height, .lod_pixels = v->lod,
        .no_shadows = v->no_shadows, .no_undergrowth = !v->ug,
        .no_distance_classes = v->no_dclass, .pixel_sort = v->sort,
        .async_pipelines = v->async,
        .sort_tiles = v->sort_tiles, .tile_blocks = v->tile_blocks,
        .undergrowth_radius = v->ug_radius, .undergrowth_thin = v->ug_thin,
        .undergrowth_compute = v->ug_compute, .far_atlas_distance = v->far,
        .preview_scale = v->preview, .shading_lod = v->cpulod,
        .reference = v->k == K_MULTIPASS ? RT_REF_MULTIPASS
                   : v->k == K_UBER || v->k == K_SCREEN_UBER ? RT_REF_UBER : RT_REF_NONE,
        .pipeline_cache = cache,
        .shading = IS_SCREEN(v->k) ? RT_SHADING_SCREEN : RT_SHADING_FORWARD,
        .screen_depth = v->k == K_SCREEN_RASTER ? RT_DEPTH_RASTER
                      : v->k == K_SCREEN_RAYCAST ? RT_DEPTH_RAYCAST : RT_DEPTH_AUTO,
    };
    double before = rss_mb();
    if (!rt_renderer_create(&b->dev, &v->view, &rd, &v->r, e))
        return false;
    splat_view view;
    int material = 0;
    if (!rt_parse_view(o->view_name, &v->view, &view, &material, e))
        return false;
    rt_renderer_set_view(v->r, view, material);
    size_t n = (size_t)o->frames;
    v->gpu = xcalloc(n, sizeof(double));
    v->cpu = xcalloc(n, sizeof(double));
    v->proc = xcalloc(n, sizeof(double));
    v->sel = xcalloc(n, sizeof(double));
    for (int k = 0; k < 3; k++)
        v->pass[k] = xcalloc(n, sizeof(double));
    v->ug_gen = xcalloc(n, sizeof(double));
    v->ug_draw = xcalloc(n, sizeof(double));
    for (int k = 0; k < 3; k++)
        v->ug_part[k] = xcalloc(n, sizeof(double));
    rt_camera cam;
    rt_frame_stats st;
    for (int w = 0; w < (o->warmup < 0 ? o->frames : o->warmup); w++) {
        if (!path_camera(&v->view, &o->pd, o->warmup < 0 ? w : 0, o->frames, &cam) ||
            !rt_renderer_frame(v->r, &cam, &st, e))
            return false;
        v->shadow_ms += st.shadow_ms;
        if (v->first_picture_s <= 0)
            v->first_picture_s = st.first_picture_s;
    }
    v->rss_delta = rss_mb() - before;
    return true;
}

/* Frame f of every variant, the reference first so the others compare
 * against this frame; --save writes the last. */
static bool timed_frame(bench_run *b, int f, rt_error *e)
{
    const render_opts *o = b->o;
    rt_camera cam;
    if (!path_camera(&b->packs[0], &o->pd, f, o->frames, &cam))
        return false;
    for (int k = 0; k < b->nv; k++) {
        int i = k == 0 ? b->ref : k == b->ref ? 0 : k;
        variant *v = &b->v[i];
        float *img = i == b->ref ? b->refimg : b->img;
        rt_frame_stats st;
        double c0 = process_cpu_ms();
        if (!rt_renderer_frame(v->r, &cam, &st, e))
            return false;
        v->proc[f] = process_cpu_ms() - c0;
        v->gpu[f] = st.gpu_ms;
        v->cpu[f] = st.cpu_ms;
        v->sel[f] = st.select_ms;
        for (int p = 0; p < 3; p++)
            v->pass[p][f] = st.pass_ms[p];
        v->ug_gen[f] = st.undergrowth.gen_ms;
        v->ug_draw[f] = st.undergrowth.draw_ms;
        v->ug_part[0][f] = st.undergrowth.draw_gfx_ms;
        v->ug_part[1][f] = st.undergrowth.draw_cs_ms;
        v->ug_part[2][f] = st.undergrowth.resolve_ms;
        v->ug_cells += st.undergrowth.generated;
        v->ug_last = st.undergrowth;
        v->patches = st.patches;
        v->pipelines = st.pipelines;
        if (v->first_picture_s <= 0)
            v->first_picture_s = st.first_picture_s;
        v->stand_in[0] = st.tiles.tiles_stand_in_uber;
        v->stand_in[1] = st.tiles.tiles_stand_in_atlas;
        v->stand_in[2] = st.tiles.tiles_stand_in_flat;
        if (!rt_renderer_read(v->r, img, e))
            return false;
        err_add(&v->err, img, b->refimg, b->npx);
        if (o->print_plan && f == o->frames - 1) {
            fprintf(stderr, "variant %s:\n", v->label);
            rt_renderer_print_plan(v->r, stderr, true);
        }
        if (o->save && f == o->frames - 1) {
            char path[4096];
            snprintf(path, sizeof path, "%s/%s.f32", o->save, v->label);
            if (!rt_write_float(path, img, o->width, o->height, e))
                return false;
        }
    }
    return true;
}

/* One counting frame per variant the pack's GLSL shades (the screen
 * kinds, composite and uber), after the timed ones. */
static bool counting_frames(bench_run *b, rt_error *e)
{
    for (int i = 0; i < b->nv; i++) {
        variant *v = &b->v[i];
        if (!IS_SCREEN(v->k) && !(b->dev.count_fragments &&
                                  (v->k == K_COMPOSITE || v->k == K_UBER)))
            continue;
        rt_camera cam;
        rt_frame_stats st;
        if (!path_camera(&b->packs[0], &b->o->pd, b->o->frames - 1, b->o->frames, &cam))
            return false;
        rt_renderer_set_counting(v->r, true);
        if (!rt_renderer_frame(v->r, &cam, &st, e))
            return false;
        v->tiles = st.tiles;
        if (!st.screen)   /* forward: the far column counts patches */
            v->tiles.tiles_far = st.far_patches;
    }
    return true;
}

/* --lanes: per screen variant, the layers view (abi.h SPLAT_VIEW_LAYERS)
 * of the path's last two frames, and the efficiencies bench_lanes.c
 * predicts from them, on stdout; the view is put back after. */
static bool lanes_frames(bench_run *b, rt_error *e)
{
    const render_opts *o = b->o;
    float *prev = xcalloc(b->npx * 4, sizeof *prev);
    bool ok = true;
    for (int i = 0; i < b->nv && ok; i++) {
        variant *v = &b->v[i];
        if (!IS_SCREEN(v->k) || v->preview > 1 || v->sort == RT_SORT_ON)
            continue;   /* the sorted variant records no sets */
        splat_view view;
        int material = 0;
        ok = rt_parse_view(o->view_name, &v->view, &view, &material, e);
        rt_renderer_set_view(v->r, SPLAT_VIEW_LAYERS, 0);
        rt_renderer_set_counting(v->r, true);
        /* the frame before at path step (n - 1) K - 1 of (n - 1) K (K =
         * --lanes-step), then the last frame */
        int K = o->lanes_step > 0 ? o->lanes_step : 1, last = o->frames - 1;
        bool two = o->frames >= 2;
        for (int k = two ? 0 : 1; k < 2 && ok; k++) {
            rt_camera cam;
            rt_frame_stats st;
            ok = (k ? path_camera(&b->packs[0], &o->pd, last, o->frames, &cam)
                    : path_camera(&b->packs[0], &o->pd, last * K - 1, last * K + 1, &cam)) &&
                 rt_renderer_frame(v->r, &cam, &st, e) &&
                 rt_renderer_read(v->r, k ? b->img : prev, e);
        }
        if (ok)
            lanes_predict(stdout, v->label, b->img, two ? prev : NULL, o->width, o->height);
        rt_renderer_set_view(v->r, view, material);
    }
    free(prev);
    return ok;
}

/* One CSV row of variant i. */
static void csv_row(FILE *out, const bench_run *b, int i, const char *devname)
{
    const render_opts *o = b->o;
    variant *v = &b->v[i];
    int frames = o->frames;
    double gm, g10, g90, cm, c10, c90, sm, s10, s90;
    percentiles(v->gpu, frames, &gm, &g10, &g90);
    percentiles(v->cpu, frames, &cm, &c10, &c90);
    percentiles(v->sel, frames, &sm, &s10, &s90);
    double procm, lo0, hi0;
    percentiles(v->proc, frames, &procm, &lo0, &hi0);
    double pm[3] = { -1, -1, -1 }, lo, hi;
    for (int k = 0; k < 3 && IS_SCREEN(v->k); k++)
        percentiles(v->pass[k], frames, &pm[k], &lo, &hi);
    double px = v->tiles.pixels ? (double)v->tiles.pixels : 1.0;
    double ugm = -1, ugd = -1, gen_sum = 0, ugp[3] = { -1, -1, -1 };
    if (v->ug) {
        percentiles(v->ug_gen, frames, &ugm, &lo, &hi);
        percentiles(v->ug_draw, frames, &ugd, &lo, &hi);
        for (int k = 0; k < 3; k++)
            percentiles(v->ug_part[k], frames, &ugp[k], &lo, &hi);
        for (int f = 0; f < frames; f++)
            gen_sum += v->ug_gen[f];
    }
    const char *pk = strrchr(v->pack_dir, '/');
    fprintf(out, "\"%s\",%s,%s,%d,%d,%s,%s,%s,%g,%d,%.3f,%.3f,%.3f,%.3f,%.4f,%d,%d,"
                 "%.6g,%.6g,%.2f,%ld,%.1f,%s,%s,%.3f,%.3f,%.3f,%d,%d,%.4f,%.4f,%.3f,%.1f,"
                 "%.2f,%.4f,%.4f,%.4f,%.2f,%ld,%zu,%g,%d,%d,%d,%.3f,%ld,%ld,%ld,%d,%.3f,%d,%d,%d,%ld,"
                 "%.4f,%.4f,%.4f\n",
            devname, o->scene ? o->scene : v->base->name, o->pd.name, o->width, o->height,
            v->label, kind_names[v->k], pk ? pk + 1 : v->pack_dir,
            v->lod > 0 ? v->lod : 3.0, frames, gm, g10, g90, cm, sm,
            v->patches, v->pipelines, v->err.max_abs,
            v->err.n ? v->err.sum_abs / (double)v->err.n : 0.0,
            err_psnr(&v->err), v->err.nonfinite, v->rss_delta, b->v[b->ref].label,
            o->view_name, pm[0], pm[1], pm[2], v->tiles.tiles, v->tiles.tiles_uber,
            v->tiles.layers_evaluated / px, v->tiles.layers_needed / px,
            v->tiles.samples / px,
            v->tiles.branches ? 100.0 * v->tiles.branches_uniform / v->tiles.branches : 100.0,
            v->shadow_ms, ugm, v->ug_cells ? gen_sum / (double)v->ug_cells : -1.0,
            ugd, (double)v->ug_cells / frames, v->ug_last.instances,
            v->ug_last.bytes_per_cell, v->far, v->tiles.tiles_far, !v->no_dclass,
            v->tiles.tiles_class, procm, v->ug_last.candidates, v->ug_last.drawn, v->ug_last.triangles,
            v->ug_last.draws, v->first_picture_s, v->stand_in[0], v->stand_in[1], v->stand_in[2],
            v->ug_last.drawn_compute, ugp[0], ugp[1], ugp[2]);
}

/* The rows, on stdout or appended to --csv (a header when it is new). */
static bool write_csv(const bench_run *b)
{
    const char *csv = b->o->csv;
    FILE *out = stdout;
    bool header = true;
    if (csv) {
        struct stat sb;
        header = stat(csv, &sb) != 0 || sb.st_size == 0;
        out = fopen(csv, "a");
        if (!out) {
            fprintf(stderr, "splatbench: cannot write '%s': %s\n", csv, strerror(errno));
            return false;
        }
    }
    if (header)
        fprintf(out, "device,scene,path,width,height,variant,kind,pack,lod_pixels,frames,"
                     "gpu_med_ms,gpu_p10_ms,gpu_p90_ms,cpu_med_ms,select_med_ms,patches,"
                     "pipelines,max_abs,mean_abs,psnr_db,nonfinite,rss_delta_mb,reference,view,"
                     "geometry_ms,classify_ms,shade_ms,tiles,tiles_uber,layers_evaluated,"
                     "layers_needed,samples_per_px,branches_uniform_pct,shadow_map_ms,"
                     "ug_gen_med_ms,ug_gen_ms_per_cell,ug_draw_med_ms,ug_cells_per_frame,"
                     "ug_instances,ug_bytes_per_cell,far_distance,tiles_far,distclass,tiles_class,"
                     "proc_cpu_med_ms,ug_candidates,ug_drawn,ug_triangles,ug_draws,first_picture_s,"
                     "stand_in_uber,stand_in_atlas,stand_in_flat,ug_drawn_compute,ug_gfx_ms,"
                     "ug_cs_raster_ms,ug_cs_resolve_ms\n");
    /* the device name in CSV: its commas become ';' */
    char devname[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE];
    snprintf(devname, sizeof devname, "%s", b->dev.props.deviceName);
    for (char *c = devname; *c; c++)
        if (*c == ',' || *c == '"')
            *c = ';';
    for (int i = 0; i < b->nv; i++)
        csv_row(out, b, i, devname);
    if (csv)
        fclose(out);
    return true;
}

/* Every variant on every frame of a camera path, frames interleaved (the
 * comment atop this file); one CSV row per variant. */
static int cmd_render(int argc, char **argv)
{
    render_opts o = { .view_name = "final", .pd = { .name = "ground" }, .width = 1280,
                      .height = 720, .frames = 5, .warmup = 1 };
    int rc = splat_args_parse(&render_args, argc, argv, 2, &o);
    if (rc)
        return rc == SPLAT_ARGS_HELP ? 0 : rc;
    if (o.nspecs == 0) {
        fprintf(stderr, "splatbench render: needs --variant LABEL=KIND...\n");
        return 2;
    }
    bench_run b = { .o = &o, .nv = o.nspecs, .npx = (size_t)o.width * (size_t)o.height };
    b.v = xcalloc((size_t)b.nv, sizeof *b.v);
    b.packs = xcalloc((size_t)b.nv, sizeof *b.packs);
    b.pack_dirs = xcalloc((size_t)b.nv, sizeof *b.pack_dirs);
    b.img = xcalloc(b.npx * 4, sizeof *b.img);
    b.refimg = xcalloc(b.npx * 4, sizeof *b.refimg);
    rt_error e = {0};
    int status = load_variants(&b, &e);
    if (status)
        goto done;
    rt_launch_mark("packs loaded");
    status = 1;
    if (!(b.have_dev = rt_device_create(&b.dev, NULL, &e)))
        goto done;
    rt_launch_mark("device");
    char cache[4096];
    if (o.save)
        snprintf(cache, sizeof cache, "%s/pipeline-cache.bin", o.save);
    for (int i = 0; i < b.nv; i++)
        if (!make_renderer(&b, i, o.save ? cache : NULL, &e))
            goto done;
    for (int f = 0; f < o.frames; f++)
        if (!timed_frame(&b, f, &e))
            goto done;
    if (counting_frames(&b, &e) && (!o.lanes || lanes_frames(&b, &e)) && write_csv(&b))
        status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatbench: %s\n", e.msg);
    rt_error_clear(&e);
    for (int i = 0; i < b.nv; i++)
        variant_free(&b.v[i]);
    if (b.have_dev) {
        if (b.dev.validating && b.dev.messages) {
            fprintf(stderr, "splatbench: %d validation message(s)\n", b.dev.messages);
            status = status ? status : 3;
        }
        rt_device_destroy(&b.dev);
    }
    for (int k = 0; k < b.npacks; k++)
        rt_pack_free(&b.packs[k]);
    free(b.packs);
    free(b.pack_dirs);
    free(b.v);
    free(b.img);
    free(b.refimg);
    return status;
}

/* The commands: argv[1] names one; each takes its own --help. */
static const struct {
    const char *name;
    int (*run)(int argc, char **argv);
} commands[] = {
    { "render", cmd_render },           { "far-bake", bench_far_bake },
    { "shadow", bench_shadow },         { "upscale", bench_upscale },
    { "compare", bench_compare },       { "analytic-hf", bench_analytic_hf },
};

int main(int argc, char **argv)
{
    rt_seconds_since_launch();   /* the fallback's origin, where /proc is not read */
    for (size_t i = 0; argc >= 2 && i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(argv[1], commands[i].name))
            return commands[i].run(argc, argv);
    fprintf(stderr, "usage: splatbench render|far-bake|shadow|upscale|compare|analytic-hf ... "
                    "(render, far-bake, shadow: COMMAND --help; tests/bench/splatbench.c)\n");
    return 2;
}
