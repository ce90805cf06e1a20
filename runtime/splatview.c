/* splatview — render a shader pack: headless to PNG (and raw floats), or in
 * a GLFW window with a fly camera and hot reload.  The options are the
 * table `options` below (splatview --help). */
#include "splatrt.h"
#include "args.h"
#include "scene.h"
#include "util.h"

#include <jansson.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

static bool parse_vec(const char *s, double *v, int n)
{
    char *end;
    for (int i = 0; i < n; i++) {
        v[i] = strtod(s, &end);
        if (end == s || !isfinite(v[i]))
            return false;
        s = end;
        if (i + 1 < n) {
            if (*s != ',')
                return false;
            s++;
        }
    }
    return *s == '\0';
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* median and the 10th..90th percentile spread of n samples (sorted here) */
static void summary(double *v, int n, double *med, double *lo, double *hi)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    *med = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    *lo = v[(int)floor(0.1 * (n - 1))];
    *hi = v[(int)ceil(0.9 * (n - 1))];
}

typedef struct opts {
    const char *pack, *out, *float_out, *preset, *view, *cache, *scene, *script;
    const char *material;       /* --material M: its swatch pack instead    */
    char *preview_dir;          /* where that pack is built                 */
    char *owned_scene;          /* the scene path build_preview allocated   */
    bool overlay;
    bool headless, stats, have_camera, have_look, no_stitch, no_cull, no_shadows;
    bool no_undergrowth;
    bool ug_compute;       /* --ug-compute: small instances in compute     */
    double ug_radius, ug_thin;   /* --ug-radius, --ug-thin (0: default)    */
    bool no_distance_classes;
    bool wait_pipelines;   /* --wait-pipelines */
    bool check;            /* --check: load and set up, draw nothing       */
    bool print_plan;       /* --print-plan: the last frame's passes        */
    int async_pipelines;   /* --async-pipelines: 1 on, 0 off, -1 default */
    int split_uncovered;   /* --uncovered: 1 split, 0 uber                 */
    int width, height, frames;
    double camera[3], look[3], lod_pixels;
    double far_distance;   /* --far-atlas-distance */
    int preview_scale;     /* --preview-scale: 1, 2, 4 (0: 1) */
    rt_shading_lod shading_lod;   /* --shading-lod */
    float clear[4];
    rt_reference ref;
    rt_shading shading;
    bool shading_set;      /* --shading given; else screen where the pack can */
    rt_screen_depth screen_depth;
    rt_shadow_path shadow;
    rt_pixel_sort pixel_sort;
    int tile_blocks;       /* --tile-order: 1 blocks, 0 rows               */
    const char *params[64];
    int nparams;
    const char *include[64];    /* -I DIR: import folders for hot reload    */
    int ninclude;
    rt_crater craters[64];      /* --crater, applied in order before frames */
    int ncraters;
    double crater_at_view;      /* --crater-at-view RADIUS (0: none)        */
    int destruction_pool;       /* --destruction-pool N                      */
    bool sun_set, exposure_set, fog_set;   /* --sun, --exposure, --fog-density */
    double sun[2], exposure, fog_density;
    unsigned light_keys;                   /* --light KEY=V,...              */
    double light[SPLAT_LIGHT_COUNT][3];
} opts;

/* The table stores enums through int (args.h ENUM). */
_Static_assert(sizeof(rt_shading) == sizeof(int) && sizeof(rt_reference) == sizeof(int) &&
               sizeof(rt_screen_depth) == sizeof(int) && sizeof(rt_shadow_path) == sizeof(int) &&
               sizeof(rt_pixel_sort) == sizeof(int), "enum fields are int-sized");

/* ---- the parsers of the values the table's kinds do not cover ----------- */

static bool parse_size(const char *v, void *o_, splat_arg_why *why)
{
    opts *o = o_;
    char tail;
    (void)why;
    return sscanf(v, "%dx%d%c", &o->width, &o->height, &tail) == 2 && o->width > 0 &&
           o->height > 0 && o->width <= 16384 && o->height <= 16384;
}

static bool parse_camera(const char *v, void *o, splat_arg_why *why)
{
    (void)why;
    return parse_vec(v, ((opts *)o)->camera, 3);
}

static bool parse_look(const char *v, void *o, splat_arg_why *why)
{
    (void)why;
    return parse_vec(v, ((opts *)o)->look, 3);
}

static bool parse_clear(const char *v, void *o_, splat_arg_why *why)
{
    opts *o = o_;
    double c[3];
    (void)why;
    if (!parse_vec(v, c, 3))
        return false;
    for (int k = 0; k < 3; k++)
        o->clear[k] = (float)c[k];
    o->clear[3] = 1.0f;
    return true;
}

static bool parse_sun(const char *v, void *o_, splat_arg_why *why)
{
    opts *o = o_;
    char *end;
    (void)why;
    o->sun[0] = strtod(v, &end);
    o->sun[1] = *end == ',' ? strtod(end + 1, &end) : NAN;
    return !*end && fabs(o->sun[0]) <= 360 && o->sun[1] >= -90 && o->sun[1] <= 90;
}

/* --light KEY=V[,V,V]: any key of the scene's light block (abi.h
 * SPLAT_LIGHT_KEYS), its values in range. */
static bool parse_light(const char *s, void *o_, splat_arg_why *why)
{
    opts *o = o_;
    const char *eq = strchr(s, '=');
    for (int k = 0; eq && k < SPLAT_LIGHT_COUNT; k++) {
        const splat_light_key *key = &splat_light_keys[k];
        if (strlen(key->key) != (size_t)(eq - s) || strncmp(s, key->key, (size_t)(eq - s)))
            continue;
        const char *p = eq + 1;
        for (int i = 0; i < key->n; i++) {
            char *end;
            double v = strtod(p, &end), lo, hi;
            splat_light_range(k, i, &lo, &hi);
            if (end == p || !(v >= lo && v <= hi) || *end != (i + 1 < key->n ? ',' : '\0')) {
                snprintf(why->text, sizeof why->text, "--light %s expects %d number%s (number "
                         "%d in %g..%g), found '%s'", key->key, key->n,
                         key->n > 1 ? "s separated by commas" : "", i + 1, lo, hi, s);
                return false;
            }
            o->light[k][i] = v;
            p = end + 1;
        }
        o->light_keys |= 1u << k;
        return true;
    }
    size_t n = (size_t)snprintf(why->text, sizeof why->text,
                                "--light expects KEY=VALUES with KEY one of");
    for (int k = 0; k < SPLAT_LIGHT_COUNT && n < sizeof why->text; k++)
        n += (size_t)snprintf(why->text + n, sizeof why->text - n, " %s", splat_light_keys[k].key);
    if (n < sizeof why->text)
        snprintf(why->text + n, sizeof why->text - n, ", found '%s'", s);
    return false;
}

/* "x,z,radius[,depth]" in metres; depth defaults to radius / 4. */
static bool parse_crater(const char *s, void *o_, splat_arg_why *why)
{
    opts *o = o_;
    double v[4] = { 0, 0, 0, -1 };
    int n = 0;
    char *end;
    (void)why;
    while (n < 4) {
        v[n] = strtod(s, &end);
        if (end == s)
            return false;
        n++;
        if (*end != ',')
            break;
        s = end + 1;
    }
    if (*end || n < 3 || !(v[2] > 0) || o->ncraters == 64)
        return false;
    rt_crater *c = &o->craters[o->ncraters++];
    memset(c, 0, sizeof *c);
    c->x = v[0];
    c->z = v[1];
    c->radius = v[2];
    c->depth = n == 4 ? v[3] : v[2] / 4;
    return true;
}

static bool parse_material(const char *v, void *o, splat_arg_why *why)
{
    (void)why;
    ((opts *)o)->material = v;
    return *v && strspn(v, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") ==
                     strlen(v);
}

static bool check_implies_headless(const char *v, void *o, splat_arg_why *why)
{
    (void)v, (void)why;
    ((opts *)o)->headless = true;
    return true;
}

static bool parse_pack(const char *word, void *o_, splat_arg_why *why)
{
    opts *o = o_;
    if (o->pack) {
        snprintf(why->text, sizeof why->text, "more than one pack given ('%s')", word);
        return false;
    }
    o->pack = word;
    return true;
}

/* ---- the options: one row each (args.h); README.md's list is this table
 * (splatview --help-markdown, checked by docs.options) -------------------- */

#define F(field) offsetof(opts, field)
#define GIVEN(field) SPLAT_ARG_GIVEN(opts, field)
static const int on_off[] = { 1, 0 };
static const int sort_on_off[] = { RT_SORT_ON, RT_SORT_OFF };
static const int reference_values[] = { RT_REF_MULTIPASS, RT_REF_UBER };
static const int shadow_values[] = { RT_SHADOW_GPU, RT_SHADOW_CPU };
static const int preview_values[] = { 1, 2, 4 };
static const int shading_lod_values[] = { RT_SHADING_LOD_AUTO, RT_SHADING_LOD_OFF,
                                          RT_SHADING_LOD_ON };

static const splat_arg options[] = {
    { NULL, SPLAT_ARG_SECTION, .help = "Output:" },
    { "--headless", SPLAT_ARG_FLAG, NULL, "render offscreen (with -o, --float-out or --stats) "
      "instead of opening the window", F(headless) },
    { "-o", SPLAT_ARG_STRING, "OUT.png", "headless: write the picture as a PNG", F(out) },
    { "--float-out", SPLAT_ARG_STRING, "FILE", "also write the linear RGBA32F image (SPLATF32 "
      "format)", F(float_out) },
    { "--size", SPLAT_ARG_CUSTOM, "WxH", "image or window size (default 1280x720)",
      .parse = parse_size, .expects = "WxH (1..16384 each)" },
    { "--frames", SPLAT_ARG_INT, "N", "render N frames (--stats over them)", F(frames),
      .min = 1, .max = 1e9, .expects = "a positive count" },
    { "--stats", SPLAT_ARG_FLAG, NULL, "patches, pipelines, GPU and CPU times, the device; the "
      "screen path's GPU time per pass; layers and texture samples per pixel from one "
      "counting frame (both paths, not the multi-pass reference)", F(stats) },
    { "--overlay", SPLAT_ARG_FLAG, NULL, "headless: draw the window's help overlay (key H) "
      "onto the PNG, as the window shows it", F(overlay) },
    { "--check", SPLAT_ARG_FLAG, NULL, "load the pack, read and validate every shader in it "
      "(a frame reads only those it needs) and set up a renderer on the device, "
      "draw nothing: exit 0 if the runtime takes the pack", F(check),
      .parse = check_implies_headless },
    { "--print-plan", SPLAT_ARG_FLAG, NULL, "headless: print the frame's passes, what each "
      "reads and writes (with --stats each pass's GPU time)", F(print_plan),
      .parse = check_implies_headless },
    { NULL, SPLAT_ARG_SECTION, .help = "Camera and view:" },
    { "--camera", SPLAT_ARG_CUSTOM, "X,Y,Z", "camera position in terrain-local metres (with "
      "--look)", .parse = parse_camera, .given = GIVEN(have_camera) },
    { "--look", SPLAT_ARG_CUSTOM, "X,Y,Z", "the point the camera looks at (with --camera)",
      .parse = parse_look, .given = GIVEN(have_look) },
    { "--camera-preset", SPLAT_ARG_STRING, "NAME", "a camera of the manifest's scene.cameras "
      "(default: the preset 'overview', else the first)", F(preset) },
    { "--view", SPLAT_ARG_STRING, "V", "what to show (default final; --help lists the views)",
      F(view) },
    { "--lod-pixels", SPLAT_ARG_FLOAT, "P", "screen error per grid step (default 3)",
      F(lod_pixels), .min = 1e-9, .max = 1e9, .expects = "a positive number" },
    { NULL, SPLAT_ARG_SECTION, .help = "Shading:" },
    { "--shading", SPLAT_ARG_ENUM, NULL, "forward: each patch shaded by its composite; screen: "
      "a depth pass, 8x8 tiles classified by combination, shaded in compute (default, in the "
      "window as headless: screen where the pack has compute variants and no --reference "
      "multipass, else forward; $SPLAT_SHADING=forward|screen sets it)", F(shading),
      .choices = "forward|screen", .given = GIVEN(shading_set) },
    { "--screen-depth", SPLAT_ARG_ENUM, NULL, "the screen path's depth: the patches drawn "
      "depth only, or the heightfield ray cast in compute (auto: ray cast on GPUs, for "
      "terrains without holes; raster can be faster where few patches show a steep "
      "terrain whole)", F(screen_depth), .choices = "auto|raster|raycast" },
    { "--pixel-sort", SPLAT_ARG_ENUM, NULL, "the screen path: sort each 16 tiles' pixels by "
      "the layers they need before shading them, so SIMD lanes skip the same surfaces "
      "(default off: the sort costs more than it saves on the devices measured)",
      F(pixel_sort), .choices = "on|off", .values = sort_on_off },
    { "--tile-order", SPLAT_ARG_ENUM, NULL, "the screen path: tiles classified, so listed "
      "and shaded, by rows (default) or in 4x4 blocks of tiles, so a list's consecutive "
      "tiles (a sorting workgroup's 16) lie together; the same picture", F(tile_blocks),
      .choices = "rows|blocks" },
    { "--reference", SPLAT_ARG_ENUM, NULL, "the multi-pass alpha reference or the "
      "über-shader, to compare against", F(ref), .choices = "multipass|uber",
      .values = reference_values },
    { "--async-pipelines", SPLAT_ARG_ENUM, NULL, "the screen path: make shading pipelines "
      "on worker threads while a stand-in draws their tiles: the far atlas where the pack has "
      "one (on a GPU), else a flat lit terrain, or the über-shader once it is made (SPLAT_STAND_IN="
      "auto|always|uber|never|atlas|flat forces one; default on in the window, off headless, "
      "which waits for them; on: the quick first picture); the title and --stats say how many "
      "are pending and which stand-in drew how many tiles",
      F(async_pipelines), .choices = "on|off", .values = on_off },
    { "--wait-pipelines", SPLAT_ARG_FLAG, NULL, "headless, with --async-pipelines on: before "
      "each frame after the first, wait until the workers have made the pipelines the frames "
      "so far asked for (the first frame shows the stand-ins, SPLAT_STAND_IN picks them; the "
      "next the final picture)", F(wait_pipelines) },
    { "--no-distance-classes", SPLAT_ARG_FLAG, NULL, "shade with the combinations only, not "
      "their distance classes (compiler/PACK.md)", F(no_distance_classes) },
    { "--uncovered", SPLAT_ARG_ENUM, NULL, "forward path: a coarse patch no compiled "
      "combination covers is drawn by the über-shader (default) or split down to nodes that "
      "have one", F(split_uncovered), .choices = "uber|split" },
    { "--far-atlas-distance", SPLAT_ARG_FLOAT, "D", "screen tiles and forward patches wholly "
      "at least D m away are shaded from the pack's far atlas (splatc build --far-atlas); "
      "0: off (default)", F(far_distance), .min = 0, .max = 1e12,
      .expects = "metres >= 0" },
    { "--preview-scale", SPLAT_ARG_ENUM, NULL, "render depth, classification and shading at "
      "1/S of the width and height and upsample to the full size along the depth edges "
      "(faster, softer; the window's P key cycles it)", F(preview_scale), .choices = "1|2|4",
      .values = preview_values },
    { "--shading-lod", SPLAT_ARG_ENUM, NULL, "the CPU shading LOD: no footprint derivatives, "
      "the nearest mip level, the node library's one-read detiling, tri-planar and parallax "
      "(view.shading_lod), coarser geometry (auto: on CPU devices such as lavapipe only; "
      "$SPLAT_SHADING_LOD=0|1 sets auto's choice)", F(shading_lod), .choices = "auto|off|on",
      .values = shading_lod_values },
    { "--param", SPLAT_ARG_LIST, "NAME=V[,V,V,V]", "set a material param (repeatable)",
      F(params), .count = F(nparams), .capacity = 64 },
    { "--pipeline-cache", SPLAT_ARG_STRING, "FILE", "the Vulkan pipeline cache file",
      F(cache) },
    { NULL, SPLAT_ARG_SECTION, .help = "Light:" },
    { "--sun", SPLAT_ARG_CUSTOM, "AZ,EL", "the sun: azimuth (degrees clockwise from north) "
      "and elevation, over the scene's light block", .parse = parse_sun,
      .given = GIVEN(sun_set),
      .expects = "AZIMUTH,ELEVATION in degrees (-360..360, -90..90)" },
    { "--exposure", SPLAT_ARG_FLOAT, "EV", "exposure in stops (default: the scene's, or 0)",
      F(exposure), .min = -20, .max = 20, .given = GIVEN(exposure_set),
      .expects = "stops -20..20" },
    { "--fog-density", SPLAT_ARG_FLOAT, "D", "fog per metre at the fog height (0: none)",
      F(fog_density), .min = 0, .max = 1, .given = GIVEN(fog_set),
      .expects = "a density 0..1 per metre" },
    { "--light", SPLAT_ARG_CUSTOM, "KEY=V[,V,V]", "any key of the scene's light block (sun, "
      "sun_color, intensity, sky, fog_density, fog_height, exposure)", .parse = parse_light },
    { "--clear", SPLAT_ARG_CUSTOM, "R,G,B", "background colour (linear) instead of the sky",
      .parse = parse_clear },
    { "--no-shadows", SPLAT_ARG_FLAG, NULL, "the sun casts no terrain shadows",
      F(no_shadows) },
    { "--shadow", SPLAT_ARG_ENUM, NULL, "where the shadow map is marched when the sun moves "
      "or a crater lands: a compute pass (gpu, the default; $SPLAT_SHADOW=cpu|gpu sets it) or "
      "the CPU reference", F(shadow), .choices = "gpu|cpu", .values = shadow_values },
    { "--no-undergrowth", SPLAT_ARG_FLAG, NULL, "draw no undergrowth (grass, plants, stones)",
      F(no_undergrowth) },
    { "--ug-radius", SPLAT_ARG_FLOAT, "R", "undergrowth within R metres of the camera "
      "(default 96)", F(ug_radius), .min = 1, .max = 4096, .expects = "metres" },
    { "--ug-thin", SPLAT_ARG_FLOAT, "D", "undergrowth thinned (D / d)^2 beyond D metres "
      "(default 14)", F(ug_thin), .min = 1, .max = 1e6, .expects = "metres" },
    { "--ug-compute", SPLAT_ARG_FLAG, NULL, "screen path: undergrowth instances that fit 64 "
      "pixels drawn in compute, not by the graphics pipeline", F(ug_compute) },
    { NULL, SPLAT_ARG_SECTION, .help = "Destruction:" },
    { "--crater", SPLAT_ARG_CUSTOM, "X,Z,R[,DEPTH]", "a crater before the frames (metres; "
      "repeatable; depth defaults to R/4)", .parse = parse_crater,
      .expects = "x,z,radius[,depth] in metres (radius > 0, at most 64)" },
    { "--crater-at-view", SPLAT_ARG_FLOAT, "R", "a crater of radius R where the view's "
      "centre ray meets the terrain", F(crater_at_view), .min = 1e-9, .max = 1e12,
      .expects = "a radius in metres" },
    { "--destruction-pool", SPLAT_ARG_INT, "N", "destruction mask tiles (default 256); when "
      "full, a crater needing more is refused with a warning", F(destruction_pool), .min = 1,
      .max = 65025, .expects = "1..65025 tiles" },
    { NULL, SPLAT_ARG_SECTION, .help = "Window, hot reload and swatches:" },
    { "--scene", SPLAT_ARG_STRING, "FILE", "the scene.sg to watch for hot reload (default: "
      "the one the pack was built from)", F(scene) },
    { "--material", SPLAT_ARG_CUSTOM, "M", "material M alone on a built-in test hill under "
      "the scene's light (a swatch: the pack's scene.source or --scene is built with splatc "
      "build --preview M into the cache; hot reload rebuilds it)", .parse = parse_material,
      .expects = "a material's name" },
    { "-I", SPLAT_ARG_LIST, "DIR", "search DIR for the scene's imports, as splatc build -I "
      "does (repeatable; also $SPLATC_PATH)", F(include), .count = F(ninclude),
      .capacity = 64 },
    { "--script", SPLAT_ARG_STRING, "S", "drive the window without a person: "
      "\"frames=30;screenshot=out.png;quit\"", F(script) },
    { NULL, SPLAT_ARG_SECTION, .help = "Tests:" },
    { "--no-stitch", SPLAT_ARG_FLAG, NULL, "draw patches without stitching", F(no_stitch) },
    { "--no-cull", SPLAT_ARG_FLAG, NULL, "never cull back faces", F(no_cull) },
};
#undef F
#undef GIVEN

static const char usage_lines[] =
    "usage: splatview PACK --headless -o OUT.png [options]   render a picture\n"
    "       splatview PACK [options]                         the viewer window\n"
    "       splatview PACK --material M [options]            one material alone\n";

static int parse_args(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    o->frames = 1;
    o->async_pipelines = -1;
    char views[256], epilog[512];
    rt_view_list(views, sizeof views);
    snprintf(epilog, sizeof epilog, "views (--view): %s\n"
             "environment: SPLAT_DEVICE=<index|name>, SPLAT_VALIDATE=1, SPLAT_SHADING, "
             "SPLAT_SHADOW\n", views);
    splat_args_desc d = { .prog = "splatview", .usage = usage_lines, .epilog = epilog,
                          .args = options, .nargs = (int)(sizeof options / sizeof options[0]),
                          .positional = parse_pack };
    int rc = splat_args_parse(&d, argc, argv, 1, o);
    if (rc == SPLAT_ARGS_HELP)
        exit(0);
    if (rc)
        return rc;
    if (!o->pack) {
        splat_args_help(&d, stderr);
        return 2;
    }
    if (o->have_camera != o->have_look) {
        fprintf(stderr, "splatview: --camera and --look go together\n");
        return 2;
    }
    if (o->headless && !o->out && !o->float_out && !o->stats && !o->check && !o->print_plan) {
        fprintf(stderr, "splatview: --headless needs -o OUT.png, --float-out or --stats\n");
        return 2;
    }
    return 0;
}

/* --sun, --exposure, --fog-density into a render desc. */
static void light_options(const opts *o, rt_render_desc *rd)
{
    rd->light_keys = o->light_keys;
    memcpy(rd->light, o->light, sizeof rd->light);
    rd->sun_set = o->sun_set;
    rd->exposure_set = o->exposure_set;
    rd->fog_set = o->fog_set;
    memcpy(rd->sun, o->sun, sizeof rd->sun);
    rd->exposure = o->exposure;
    rd->fog_density = o->fog_density;
}

static bool pick_camera(const opts *o, const rt_pack *p, rt_camera *cam)
{
    rt_default_camera(p, cam);
    if (o->preset) {
        int c = rt_pack_camera_find(p, o->preset);
        if (c < 0) {
            fprintf(stderr, "splatview: the pack has no camera preset '%s'", o->preset);
            for (int i = 0; rt_pack_camera_name(p, i); i++)
                fprintf(stderr, "%s'%s'", i ? ", " : " (it has ", rt_pack_camera_name(p, i));
            fprintf(stderr, "%s\n", rt_pack_camera_name(p, 0) ? ")" : "");
            return false;
        }
        rt_pack_camera_at(p, c, cam->position, cam->look);
    }
    if (o->have_camera) {
        memcpy(cam->position, o->camera, sizeof cam->position);
        memcpy(cam->look, o->look, sizeof cam->look);
    }
    return true;
}

static bool apply_params(const opts *o, rt_renderer *r, rt_error *e)
{
    for (int i = 0; i < o->nparams; i++) {
        char name[256];
        const char *eq = strchr(o->params[i], '=');
        size_t n = eq ? (size_t)(eq - o->params[i]) : 0;
        if (!eq || n == 0 || n >= sizeof name)
            return rt_fail(e, RT_E_PACK_FIELD, "--param", "expects NAME=v[,v,v,v]");
        memcpy(name, o->params[i], n);
        name[n] = '\0';
        float v[4] = { 0, 0, 0, 0 };
        char *s = (char *)eq + 1, *end;
        for (int k = 0; k < 4 && *s; k++) {
            v[k] = strtof(s, &end);
            if (end == s)
                return rt_fail(e, RT_E_PACK_FIELD, "--param", "expects numbers after '='");
            s = *end == ',' ? end + 1 : end;
        }
        if (!rt_renderer_set_param(r, name, v, e))
            return false;
    }
    return true;
}

/* --crater in order, then --crater-at-view: where the view's centre ray
 * meets the terrain.  Each event is reported on stdout. */
static bool apply_craters(const opts *o, rt_renderer *r, const rt_camera *cam, rt_error *e)
{
    static const char *const results[] = { "done", "outside the destructible area",
                                           "refused (tile pool exhausted)" };
    int n = o->ncraters + (o->crater_at_view > 0);
    for (int i = 0; i < n; i++) {
        rt_crater c;
        if (i < o->ncraters) {
            c = o->craters[i];
        } else {
            double dir[3], hit[3];
            for (int k = 0; k < 3; k++)
                dir[k] = cam->look[k] - cam->position[k];
            if (!rt_renderer_pick(r, cam->position, dir, hit)) {
                printf("crater at view: the view's centre ray misses the terrain\n");
                continue;
            }
            memset(&c, 0, sizeof c);
            c.x = hit[0];
            c.z = hit[2];
            c.radius = o->crater_at_view;
            c.depth = c.radius / 4;
        }
        rt_crater_stats st;
        if (!rt_renderer_crater(r, &c, &st, e))
            return false;
        printf("crater (%.2f, %.2f) r %.2f depth %.2f: %s, %d cells, %d new tiles "
               "(%d of %d used), %d texels lowered in a %dx%d upload, %.3f ms cpu\n",
               c.x, c.z, c.radius, c.depth, results[st.result], st.cells, st.tiles_new,
               st.tiles_used, st.pool, st.texels, st.upload[2], st.upload[3], st.cpu_ms);
    }
    return true;
}

static rt_tonemap tonemap_for(splat_view v)
{
    return rt_view_tonemap(v);
}

/* The shading path asked for: --shading, else $SPLAT_SHADING
 * (forward|screen); false: neither, and the default is the screen-space
 * path wherever the pack has its compute variants and no --reference
 * multipass (faster on both devices: tests/bench/RESULTS.md), in the
 * window as headless. */
static bool shading_chosen(const opts *o, rt_shading *out)
{
    if (o->shading_set) {
        *out = o->shading;
        return true;
    }
    const char *env = getenv("SPLAT_SHADING");
    if (env && (!strcmp(env, "forward") || !strcmp(env, "screen"))) {
        *out = !strcmp(env, "screen") ? RT_SHADING_SCREEN : RT_SHADING_FORWARD;
        return true;
    }
    if (env && *env)
        fprintf(stderr, "splatview: warning: SPLAT_SHADING='%s' is neither forward nor screen; "
                "ignored\n", env);
    return false;
}

/* The timings of headless's frames, per frame (medians by summary()). */
typedef struct frame_times {
    double *gpu, *sel, *cpu;   /* GPU ms, quadtree selection and recording ms */
    double *pass[3];           /* screen path: depth, classification, shading */
    double *ug_draw;           /* undergrowth draw GPU ms                    */
    double shadow_ms;          /* the first frame makes the shadow map       */
    double ug_gen_ms;          /* and generates the undergrowth's cells      */
    int ug_generated;
    double compile_ms;
    int shaders_read;          /* the pack's shader files the frames read   */
} frame_times;

/* o->frames frames, their times into t; st: the last frame's stats. */
static bool run_frames(const opts *o, rt_renderer *r, const rt_camera *cam, frame_times *t,
                       rt_frame_stats *st, rt_error *e)
{
    for (int f = 0; f < o->frames; f++) {
        if ((f > 0 && o->wait_pipelines && !rt_renderer_wait_pipelines(r, e)) ||
            !rt_renderer_frame(r, cam, st, e))
            return false;
        t->gpu[f] = st->gpu_ms;
        t->shadow_ms += st->shadow_ms;
        t->compile_ms += st->compile_ms;
        t->sel[f] = st->select_ms;
        t->cpu[f] = st->cpu_ms;
        for (int k = 0; k < 3; k++)
            t->pass[k][f] = st->pass_ms[k];
        t->ug_draw[f] = st->undergrowth.draw_ms;
        if (st->undergrowth.generated > 0) {
            t->ug_gen_ms += st->undergrowth.gen_ms;
            t->ug_generated += st->undergrowth.generated;
        }
    }
    return true;
}

/* -o (tone-mapped, with --overlay's box) and --float-out of the last frame. */
static bool write_pictures(const opts *o, rt_device *dev, const rt_pack *pack, rt_renderer *r,
                           splat_view view, int material, const rt_frame_stats *st, int W,
                           int H, rt_error *e)
{
    rt_pack_info pi;
    rt_pack_info_get(pack, &pi);
    float *rgba = malloc((size_t)W * (size_t)H * 16);
    uint8_t *png = malloc((size_t)W * (size_t)H * 4);
    bool ok = rgba && png && rt_renderer_read(r, rgba, e) &&
              (!o->float_out || rt_write_float(o->float_out, rgba, W, H, e));
    if (ok && o->out) {
        rt_tonemap_rgba8(rgba, W, H, tonemap_for(view), png);
        if (o->overlay) {   /* no frame rate: the picture stays reproducible */
            char text[2048];
            rt_overlay_info in = {
                .pack = pi.name, .view = view, .screen = st->screen,
                .material = view == SPLAT_VIEW_MASK ? rt_pack_material_name(pack, material) : NULL,
                .pending = st->pipelines_pending, .status = "headless",
            };
            rt_overlay_text(&in, text, sizeof text);
            ok = rt_overlay_draw_rgba8(dev, text, png, W, H, e);
        }
        ok = ok && rt_write_png(o->out, png, W, H, e);
    }
    if (!rgba || !png)
        rt_fail(e, RT_E_IO, "hold the picture for", o->out ? o->out : o->float_out,
                "out of memory");
    free(rgba);
    free(png);
    return ok;
}

/* --stats: one more frame with the counting variant (not timed), its
 * layers and samples per pixel. */
static bool print_counts(rt_renderer *r, const rt_camera *cam, splat_view view, rt_error *e)
{
    rt_renderer_set_counting(r, true);
    rt_frame_stats cs;
    if (!rt_renderer_frame(r, cam, &cs, e))
        return false;
    rt_renderer_set_counting(r, view == SPLAT_VIEW_COST || view == SPLAT_VIEW_LAYERS);
    double px = cs.tiles.pixels ? (double)cs.tiles.pixels : 1.0;
    printf("layers per pixel: evaluated %.3f, needed %.3f (efficiency %.1f %%)\n",
           cs.tiles.layers_evaluated / px, cs.tiles.layers_needed / px,
           cs.tiles.layers_evaluated
               ? 100.0 * cs.tiles.layers_needed / cs.tiles.layers_evaluated : 100.0);
    printf("texture samples per pixel: %.3f\n", cs.tiles.samples / px);
    printf("dynamic branches uniform over the subgroup: %.1f %% of %.2f per pixel\n",
           cs.tiles.branches ? 100.0 * cs.tiles.branches_uniform / cs.tiles.branches : 100.0,
           cs.tiles.branches / px);
    return true;
}

/* --stats: the patches, paths and pipelines of the last frame. */
static void print_paths(const rt_pack_info *pi, const rt_frame_stats *st, const frame_times *t)
{
    printf("patches drawn: %d  culled: %d\n", st->patches, st->culled);
    printf("back faces culled: %s\n", st->backfaces_culled ? "yes" : "no");
    printf("pipelines bound: %d\n", st->pipelines);
    printf("shader files read: %d of %d (read and checked on first use)\n", t->shaders_read,
           pi->shaders);
    if (st->screen)
        printf("compute modules: %d from the pack or the SPIR-V cache, %d compiled from GLSL; "
               "%.1f ms making pipelines between frames\n", st->spirv_cached,
               st->spirv_compiled, t->compile_ms);
    printf("combinations in view: %d of %d\n", st->combos_in_view, pi->ncombos);
    if (!st->screen) {
        printf("distance classes: %d of %d patches\n", st->class_patches, st->patches);
        printf("far atlas: %d of %d patches\n", st->far_patches, st->patches);
        printf("uber-shader fallback: %d of %d patches (no compiled combination "
               "covers their node)\n", st->uber_patches, st->patches);
        printf("uncovered nodes split: %d\n", st->split_uncovered);
    }
}

/* --stats: the screen path's passes. */
static void print_passes(const opts *o, const frame_times *t)
{
    static const char *const names[3] = { "depth", "classification", "shading (compute)" };
    for (int k = 0; k < 3; k++) {
        double m, l, h;
        summary(t->pass[k], o->frames, &m, &l, &h);
        printf("  %-18s gpu ms: median %.3f  p10 %.3f  p90 %.3f\n", names[k], m, l, h);
    }
}

/* --stats: everything after the frames. */
static bool print_stats(const opts *o, rt_device *dev, const rt_pack *pack, rt_renderer *r,
                        const rt_camera *cam, splat_view view, const rt_frame_stats *st,
                        frame_times *t, int W, int H, rt_error *e)
{
    rt_pack_info pi;
    rt_device_info di;
    rt_pack_info_get(pack, &pi);
    rt_device_info_get(dev, &di);
    double gm, gl, gh, sm, sl, sh, cm, cl, ch;
    summary(t->gpu, o->frames, &gm, &gl, &gh);
    summary(t->sel, o->frames, &sm, &sl, &sh);
    summary(t->cpu, o->frames, &cm, &cl, &ch);
    printf("device: %s\n", di.name);
    printf("size: %dx%d  view: %s  reference: %s  frames: %d\n", W, H, rt_view_name(view),
           o->ref == RT_REF_MULTIPASS ? "multipass" : o->ref == RT_REF_UBER ? "uber" : "none",
           o->frames);
    print_paths(&pi, st, t);
    if (gm >= 0)
        printf("gpu ms/frame: median %.3f  p10 %.3f  p90 %.3f\n", gm, gl, gh);
    else
        printf("gpu ms/frame: n/a (no timestamp support)\n");
    if (st->screen) {
        if (gm >= 0)
            print_passes(o, t);
        printf("tiles: %d of %d shaded, %d lists, %d by the uber-shader, %d from the far "
               "atlas\n", st->tiles.tiles, st->tiles.tiles_total, st->tiles.lists,
               st->tiles.tiles_uber, st->tiles.tiles_far);
        printf("distance classes: %d of %d tiles\n", st->tiles.tiles_class, st->tiles.tiles);
        printf("classification: %d candidates, %d materials in view, %d words per set\n",
               st->tiles.class_candidates, st->tiles.class_materials, st->tiles.class_words);
        printf("pipelines pending: %d (tiles the uber-shader stood in for: %d)\n",
               st->pipelines_pending, st->tiles.tiles_stand_in_uber);
        printf("stand-ins: %d tiles (uber-shader %d, far atlas %d, flat %d)\n",
               st->tiles.tiles_stand_in, st->tiles.tiles_stand_in_uber,
               st->tiles.tiles_stand_in_atlas, st->tiles.tiles_stand_in_flat);
    }
    printf("first picture: %.3f s after launch\n", st->first_picture_s);
    printf("quadtree cpu ms/frame: median %.4f  p10 %.4f  p90 %.4f\n", sm, sl, sh);
    if (o->no_shadows)
        printf("shadow map: off\n");
    else
        printf("shadow map %s ms: %.2f (when the sun moves or a crater lands; "
               "per frame a texture tap)\n", st->shadow_gpu ? "gpu" : "cpu", t->shadow_ms);
    if (pi.has_undergrowth && !o->no_undergrowth && view == SPLAT_VIEW_FINAL) {
        double um, ul, uh;
        summary(t->ug_draw, o->frames, &um, &ul, &uh);
        printf("undergrowth: %d cells, %ld instances, %.3f ms generation\n",
               st->undergrowth.cells, st->undergrowth.instances, t->ug_gen_ms);
        printf("  generated %d cells (%.4f ms per cell), draw gpu ms/frame: median %.3f  "
               "p10 %.3f  p90 %.3f, %zu bytes per cell\n", t->ug_generated,
               t->ug_generated ? t->ug_gen_ms / t->ug_generated : 0.0, um, ul, uh,
               st->undergrowth.bytes_per_cell);
        printf("  drawn %ld instances (of %ld candidates; %ld in compute), %ld triangles, "
               "%d draws\n", st->undergrowth.drawn, st->undergrowth.candidates,
               st->undergrowth.drawn_compute, st->undergrowth.triangles, st->undergrowth.draws);
    } else if (pi.has_undergrowth) {
        printf("undergrowth: off\n");
    }
    printf("cpu ms/frame (record): median %.3f  p10 %.3f  p90 %.3f\n", cm, cl, ch);
    if ((st->screen || (di.count_fragments && o->ref != RT_REF_MULTIPASS)) &&
        !print_counts(r, cam, view, e))
        return false;
    printf("shading: %s%s\n", st->screen ? "screen" : "forward",
           st->sorted ? ", pixels sorted by layer set" : "");
    if (pi.has_far_atlas)   /* the BC blocks as uploaded (PACK.md "Far atlas") */
        printf("far atlas: %d x %d texels of %.1f x %.1f m, %d levels, %zu bytes; %s\n",
               pi.far_width, pi.far_height, pi.far_texel[0], pi.far_texel[1],
               pi.far_levels, pi.far_bytes,
               o->far_distance <= 0 ? "not used"
               : st->screen ? "screen tiles beyond --far-atlas-distance use it"
                            : "forward patches beyond --far-atlas-distance use it");
    rt_painted_print_stats(pack, stdout);
    if (rt_renderer_destruction(r))
        rt_destruction_print_stats(rt_renderer_destruction(r), stdout);
    return true;
}

/* The render desc of the options (the window's is built in window()). */
static rt_render_desc render_desc(const opts *o, const rt_pack_info *pi)
{
    rt_render_desc rd = {
        .width = o->width, .height = o->height, .reference = o->ref,
        .pipeline_cache = o->cache, .no_stitch = o->no_stitch,
        .no_cull = o->no_cull, .lod_pixels = o->lod_pixels, .no_shadows = o->no_shadows,
        .shadow = o->shadow,
        .no_undergrowth = o->no_undergrowth,
        .undergrowth_compute = o->ug_compute, .undergrowth_radius = o->ug_radius,
        .undergrowth_thin = o->ug_thin,
        .no_distance_classes = o->no_distance_classes,
        .async_pipelines = o->async_pipelines == 1,
        .split_uncovered = o->split_uncovered,
        .destruction_pool = o->destruction_pool, .shading = o->shading,
        .screen_depth = o->screen_depth, .pixel_sort = o->pixel_sort,
        .tile_blocks = o->tile_blocks != 0, .far_atlas_distance = o->far_distance,
        .preview_scale = o->preview_scale, .shading_lod = o->shading_lod,
    };
    if (!shading_chosen(o, &rd.shading))
        rd.shading = pi->has_compute && o->ref != RT_REF_MULTIPASS ? RT_SHADING_SCREEN
                                                                   : RT_SHADING_FORWARD;
    light_options(o, &rd);
    memcpy(rd.clear, o->clear, sizeof rd.clear);
    return rd;
}

static int headless(const opts *o)
{
    rt_error e = { 0 };
    rt_pack *pack = NULL;
    rt_pack_info pi;
    rt_device *dev = NULL;
    rt_renderer *r = NULL;
    int status = 1;
    double *times = NULL;

    if (!rt_pack_open(o->pack, &pack, &e)) {
        fprintf(stderr, "splatview: %s\n", e.msg);
        rt_error_clear(&e);
        return 1;
    }
    rt_pack_info_get(pack, &pi);
    /* --check: every shader read and validated now (a frame reads only
     * those it needs), before the device is opened, as a load did */
    if (o->check && !rt_pack_validate(pack, &e))
        goto done;
    splat_view view = SPLAT_VIEW_FINAL;
    int material = 0;
    rt_camera cam;
    if ((o->view && !rt_parse_view(o->view, pack, &view, &material, &e)) ||
        !pick_camera(o, pack, &cam))
        goto done;
    if (!rt_device_open(NULL, &dev, &e))
        goto done;
    rt_render_desc rd = render_desc(o, &pi);
    if (!rt_renderer_create(dev, pack, &rd, &r, &e) || !apply_params(o, r, &e) ||
        !apply_craters(o, r, &cam, &e))
        goto done;
    if (o->check) {   /* the pack loads, every shader passes, a renderer stands */
        printf("%s: loads (%d combinations, %d materials, %s path)\n", o->pack, pi.ncombos,
               pi.nmaterials, rd.shading == RT_SHADING_SCREEN ? "screen" : "forward");
        status = 0;
        goto done;
    }
    rt_renderer_set_view(r, view, material);
    int W = o->width > 0 ? o->width : 1280, H = o->height > 0 ? o->height : 720;
    times = calloc((size_t)o->frames * 7, sizeof *times);
    if (!times)
        goto done;
    frame_times t = { .gpu = times, .sel = times + o->frames, .cpu = times + 2 * o->frames,
                      .pass = { times + 3 * o->frames, times + 4 * o->frames,
                                times + 5 * o->frames },
                      .ug_draw = times + 6 * o->frames };
    rt_frame_stats st = { 0 };
    /* the cost view needs the counting variant's counters */
    rt_renderer_set_counting(r, view == SPLAT_VIEW_COST || view == SPLAT_VIEW_LAYERS);
    rt_renderer_set_pass_times(r, o->print_plan && o->stats);
    bool ran = run_frames(o, r, &cam, &t, &st, &e);
    rt_pack_info_get(pack, &pi);   /* before --stats' counting frame reads more */
    t.shaders_read = pi.shaders_read;
    if (!ran ||
        ((o->out || o->float_out) &&
         !write_pictures(o, dev, pack, r, view, material, &st, W, H, &e)))
        goto done;
    if (o->print_plan)   /* the last frame's, its readback; before --stats' counting frame */
        rt_renderer_print_plan(r, stdout, o->stats);
    if (o->stats && !print_stats(o, dev, pack, r, &cam, view, &st, &t, W, H, &e))
        goto done;
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatview: %s\n", e.msg);
    rt_error_clear(&e);
    rt_renderer_destroy(r);
    int messages = rt_device_close(dev);
    if (messages) {
        fprintf(stderr, "splatview: %d validation message(s)\n", messages);
        status = status ? status : 3;
    }
    rt_pack_close(pack);
    free(times);
    return status;
}

/* --material: the scene (--scene, else the pack's scene.source) built as
 * that material's swatch pack (splatc build --preview) under the cache
 * folder; o->pack then names it.  Exit status, 0 when built. */
static int build_preview(opts *o)
{
    char *scene = o->scene ? strdup(o->scene) : NULL;
    if (!scene) {
        rt_pack *p;
        rt_error e = { 0 };
        if (!rt_pack_open(o->pack, &p, &e)) {
            fprintf(stderr, "splatview: %s\n", e.msg);
            rt_error_clear(&e);
            return 1;
        }
        rt_pack_info pi;
        rt_pack_info_get(p, &pi);
        scene = pi.scene_path ? splat_path_join(o->pack, pi.scene_path) : NULL;
        rt_pack_close(p);
        if (!scene) {
            fprintf(stderr, "splatview: --material: the pack names no scene.source; "
                            "give --scene FILE\n");
            return 1;
        }
        o->scene = scene;   /* for hot reload */
    }
    o->owned_scene = scene;   /* freed by main */
    char *abs = splat_path_absolute(scene), *cache = splat_cache_default_dir();
    const char *key = abs ? abs : scene;   /* one folder per scene file */
    unsigned long long h = (unsigned long long)XXH3_64bits(key, strlen(key));
    char name[64];
    snprintf(name, sizeof name, "preview/%016llx-", h);
    char *dir = cache ? splat_path_join(cache, name) : NULL;
    free(abs);
    free(cache);
    if (!dir || !splat_make_dirs(dir)) {
        fprintf(stderr, "splatview: --material: no cache folder for the swatch pack "
                        "(set XDG_CACHE_HOME or SPLATC_CACHE)\n");
        free(dir);
        return 1;
    }
    o->preview_dir = xasprintf("%s/%s", dir, o->material);
    free(dir);
    char **paths = splat_search_path(o->include, o->ninclude, o->scene);
    splat_build_desc bd = { .scene = o->scene, .out = o->preview_dir,
                            .search_paths = (const char *const *)paths, .jobs = 2,
                            .preview = o->material };
    splat_build_stats st;
    sg_diags d;
    sg_diags_init(&d);
    bool ok = splat_build(&bd, &st, &d);
    sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    splat_search_path_free(paths);
    if (!ok)
        return 1;
    o->pack = o->preview_dir;
    return 0;
}

/* The folders the pack was built with (manifest scene.search, relative to
 * the pack: splatc build's -I and SPLATC_PATH) join -I's, after them, so a
 * swatch (--material) and hot reload find the imports the build found.
 * The strings live as long as the process. */
static void pack_search(opts *o)
{
    char *mf = splat_path_join(o->pack, "manifest.json");
    json_t *m = json_load_file(mf, 0, NULL);
    free(mf);
    json_t *search = json_object_get(json_object_get(m, "scene"), "search");
    for (size_t i = 0; i < json_array_size(search) && o->ninclude < 64; i++) {
        json_t *d = json_array_get(search, i);
        if (json_is_string(d))
            o->include[o->ninclude++] = splat_path_join(o->pack, json_string_value(d));
    }
    json_decref(m);
}

/* The viewer window with the options parsed (rt_viewer_run). */
static int window(const opts *o_)
{
    opts o = *o_;
    rt_viewer_desc vd = {
        .pack_dir = o.pack, .scene = o.scene, .width = o.width ? o.width : 1280,
        .height = o.height ? o.height : 720, .script = o.script,
        .render = { .reference = o.ref, .pipeline_cache = o.cache, .lod_pixels = o.lod_pixels,
                    .shading = o.shading, .screen_depth = o.screen_depth, .pixel_sort = o.pixel_sort,
                    .tile_blocks = o.tile_blocks != 0,
                    .no_shadows = o.no_shadows, .shadow = o.shadow,
                    .no_undergrowth = o.no_undergrowth,
                    .undergrowth_compute = o.ug_compute, .undergrowth_radius = o.ug_radius,
                    .undergrowth_thin = o.ug_thin,
                    .far_atlas_distance = o.far_distance,
                    .preview_scale = o.preview_scale, .shading_lod = o.shading_lod,
                    .no_distance_classes = o.no_distance_classes,
                    .async_pipelines = o.async_pipelines != 0,
                    .split_uncovered = o.split_uncovered },
        .view = SPLAT_VIEW_FINAL,
    };
    memcpy(vd.render.clear, o.clear, sizeof o.clear);
    vd.shading_set = shading_chosen(&o, &vd.render.shading);
    light_options(&o, &vd.render);
    vd.have_camera = o.have_camera || o.preset;
    if (o.have_camera) {
        memcpy(vd.camera.position, o.camera, sizeof o.camera);
        memcpy(vd.camera.look, o.look, sizeof o.look);
    }
    vd.preset = o.preset;
    vd.view_name = o.view;
    vd.include = o.include;
    vd.ninclude = o.ninclude;
    vd.preview = o.material;
    return rt_viewer_run(&vd);
}

int main(int argc, char **argv)
{
    rt_seconds_since_launch();   /* the fallback's origin, where /proc is not read */
    opts o;
    int rc = parse_args(argc, argv, &o);
    if (rc)
        return rc;
    pack_search(&o);
    if (!o.material || (rc = build_preview(&o)) == 0)
        rc = o.headless ? headless(&o) : window(&o);
    free(o.preview_dir);
    free(o.owned_scene);
    return rc;
}
