/* splatview — render a shader pack: headless to PNG (and raw floats), or in
 * a GLFW window with a fly camera and hot reload.  See usage() below. */
#include "splatrt.h"
#include "far_atlas.h"
#include "scene.h"
#include "util.h"

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

static void usage(FILE *f)
{
    char views[256];
    rt_view_list(views, sizeof views);
    fprintf(f,
        "usage: splatview PACK [options]\n"
        "  --headless -o OUT.png     render offscreen and write a PNG\n"
        "  --size WxH                image or window size (default 1280x720)\n"
        "  --camera x,y,z --look x,y,z   camera in terrain-local metres\n"
        "  --camera-preset NAME      a camera of the manifest's scene.cameras\n"
        "                            (default: the preset 'overview', else the first)\n"
        "  --view V                  %s\n"
        "  --frames N                render N frames (stats over them)\n"
        "  --overlay                 headless: draw the window's help overlay (key H)\n"
        "                            onto the PNG, as the window shows it\n"
        "  --stats                   patches, pipelines, GPU and CPU times, device;\n"
        "                            layers and texture samples per pixel from one\n"
        "                            counting frame (both paths, not multipass)\n"
        "  --reference multipass|uber   the multi-pass alpha reference or the uber-shader\n"
        "  --shading forward|screen  forward: each patch shaded by its composite;\n"
        "                            screen: depth pass, 8x8 tiles classified by\n"
        "                            combination, shaded in compute (default: screen\n"
        "                            where the pack has compute variants and no\n"
        "                            --reference multipass, else forward;\n"
        "                            $SPLAT_SHADING=forward|screen sets it)\n"
        "  --screen-depth auto|raster|raycast   the screen path's depth: the patches\n"
        "                            drawn depth only, or the heightfield ray cast in\n"
        "                            compute (auto: ray cast on GPUs without holes)\n"
        "  --pixel-sort on|off       the screen path: sort each 16 tiles' pixels by\n"
        "                            the layers they need before shading them, so\n"
        "                            SIMD lanes skip the same surfaces (default off:\n"
        "                            the sort's masks-only run costs more than it\n"
        "                            saves on the devices measured)\n"
        "  --float-out FILE          also write the RGBA32F image (SPLATF32 format)\n"
        "  --param NAME=v[,v,v,v]    set a material param\n"
        "  --lod-pixels P            screen error per grid step (default 3)\n"
        "  --far-atlas-distance D    screen tiles and forward patches wholly at least\n"
        "                            D m away are shaded from the pack's far atlas\n"
        "                            (splatc build --far-atlas); 0: off (default)\n"
        "  --sun AZ,EL               the sun: azimuth (degrees clockwise from north)\n"
        "                            and elevation, over the scene's light block\n"
        "  --exposure EV             exposure in stops (default: the scene's, or 0)\n"
        "  --fog-density D           fog per metre at the fog height (0: none)\n"
        "  --no-shadows              the sun casts no terrain shadows\n"
        "  --shadow gpu|cpu          where the shadow map is marched when the sun\n"
        "                            moves or a crater lands: a compute pass (the\n"
        "                            default; $SPLAT_SHADOW=cpu|gpu sets it) or the\n"
        "                            CPU reference\n"
        "  --no-undergrowth          draw no undergrowth (grass, plants, stones)\n"
        "  --check                   load the pack and set up a renderer on the\n"
        "                            device, draw nothing: exit 0 if the runtime\n"
        "                            takes the pack\n"
        "  --async-pipelines on|off  screen path: make compute pipelines on worker\n"
        "                            threads, the uber-shader drawing their tiles\n"
        "                            meanwhile (default: on in the window, off\n"
        "                            headless, which waits for every pipeline)\n"
        "  --no-distance-classes     shade with the combinations only, not their\n"
        "                            distance classes (compiler/PACK.md)\n"
        "  --uncovered uber|split    forward coarse patches no compiled combination\n"
        "                            covers: drawn with the uber-shader (default) or\n"
        "                            split down to nodes that have one\n"
        "  --light KEY=V[,V,V]       any key of the scene's light block (sun, sun_color,\n"
        "                            intensity, sky, fog_density, fog_height, exposure)\n"
        "  --clear r,g,b             background colour (linear)\n"
        "  --pipeline-cache FILE     pipeline cache file\n"
        "  --scene FILE              scene.sg to watch for hot reload (viewer)\n"
        "  --material M              material M alone on a built-in test hill under the\n"
        "                            scene's light (a swatch; the pack's scene.source or\n"
        "                            --scene is built with splatc build --preview M\n"
        "                            into the cache; hot reload rebuilds it)\n"
        "  -I DIR                    search DIR for the scene's imports, as splatc\n"
        "                            build -I does (repeatable; also $SPLATC_PATH)\n"
        "  --script S                viewer script: \"frames=30;screenshot=out.png;quit\"\n"
        "  --no-stitch               draw patches without stitching (tests)\n"
        "  --no-cull                 never cull back faces (tests)\n"
        "  --crater x,z,r[,depth]    a crater before the frames (metres; repeatable;\n"
        "                            depth defaults to r/4)\n"
        "  --crater-at-view R        a crater of radius R where the view's centre ray\n"
        "                            meets the terrain\n"
        "  --destruction-pool N      destruction mask tiles (default 256); when full,\n"
        "                            a crater needing more is refused with a warning\n"
        "environment: SPLAT_DEVICE=<index|name>, SPLAT_VALIDATE=1\n", views);
}

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
    bool no_distance_classes;
    bool check;            /* --check: load and set up, draw nothing       */
    int async_pipelines;   /* --async-pipelines: 1 on, 0 off, -1 default */
    bool split_uncovered;
    int width, height, frames;
    double camera[3], look[3], lod_pixels;
    double far_distance;   /* --far-atlas-distance */
    float clear[4];
    rt_reference ref;
    rt_shading shading;
    bool shading_set;      /* --shading given; else screen where the pack can */
    rt_screen_depth screen_depth;
    rt_shadow_path shadow;
    rt_pixel_sort pixel_sort;
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

/* --light KEY=V[,V,V]: any key of the scene's light block (abi.h
 * SPLAT_LIGHT_KEYS), its values in range. */
static bool parse_light(const char *s, opts *o)
{
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
                fprintf(stderr, "splatview: --light %s expects %d number%s (number %d in "
                        "%g..%g), found '%s'\n", key->key, key->n,
                        key->n > 1 ? "s separated by commas" : "", i + 1, lo, hi, s);
                return false;
            }
            o->light[k][i] = v;
            p = end + 1;
        }
        o->light_keys |= 1u << k;
        return true;
    }
    fprintf(stderr, "splatview: --light expects KEY=VALUES with KEY one of");
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++)
        fprintf(stderr, " %s", splat_light_keys[k].key);
    fprintf(stderr, ", found '%s'\n", s);
    return false;
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

/* "x,z,radius[,depth]" in metres; depth defaults to radius / 4. */
static bool parse_crater(const char *s, rt_crater *c)
{
    double v[4] = { 0, 0, 0, -1 };
    int n = 0;
    char *end;
    while (n < 4) {
        v[n] = strtod(s, &end);
        if (end == s)
            return false;
        n++;
        if (*end != ',')
            break;
        s = end + 1;
    }
    if (*end || n < 3 || !(v[2] > 0))
        return false;
    memset(c, 0, sizeof *c);
    c->x = v[0];
    c->z = v[1];
    c->radius = v[2];
    c->depth = n == 4 ? v[3] : v[2] / 4;
    return true;
}

static int parse_args(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    o->frames = 1;
    o->async_pipelines = -1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED() do { if (!v) { fprintf(stderr, "splatview: %s needs a value\n", a); return 2; } i++; } while (0)
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            exit(0);
        } else if (!strcmp(a, "--headless")) {
            o->headless = true;
        } else if (!strcmp(a, "--check")) {
            o->check = o->headless = true;
        } else if (!strcmp(a, "--stats")) {
            o->stats = true;
        } else if (!strcmp(a, "--overlay")) {
            o->overlay = true;
        } else if (!strcmp(a, "--no-stitch")) {
            o->no_stitch = true;
        } else if (!strcmp(a, "--no-cull")) {
            o->no_cull = true;
        } else if (!strcmp(a, "--no-shadows")) {
            o->no_shadows = true;
        } else if (!strcmp(a, "--no-undergrowth")) {
            o->no_undergrowth = true;
        } else if (!strcmp(a, "--no-distance-classes")) {
            o->no_distance_classes = true;
        } else if (!strcmp(a, "--async-pipelines")) {
            NEED();
            if (strcmp(v, "on") && strcmp(v, "off")) {
                fprintf(stderr, "splatview: --async-pipelines takes on or off, not '%s'\n", v);
                return 2;
            }
            o->async_pipelines = !strcmp(v, "on");
        } else if (!strcmp(a, "--uncovered")) {
            NEED();
            if (!strcmp(v, "split") || !strcmp(v, "uber")) {
                o->split_uncovered = !strcmp(v, "split");
            } else {
                fprintf(stderr, "splatview: --uncovered expects split or uber, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "-o")) {
            NEED(); o->out = v;
        } else if (!strcmp(a, "--float-out")) {
            NEED(); o->float_out = v;
        } else if (!strcmp(a, "--size")) {
            NEED();
            if (sscanf(v, "%dx%d", &o->width, &o->height) != 2 || o->width <= 0 ||
                o->height <= 0 || o->width > 16384 || o->height > 16384) {
                fprintf(stderr, "splatview: --size expects WxH, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--camera")) {
            NEED();
            if (!parse_vec(v, o->camera, 3)) {
                fprintf(stderr, "splatview: --camera expects x,y,z, found '%s'\n", v);
                return 2;
            }
            o->have_camera = true;
        } else if (!strcmp(a, "--look")) {
            NEED();
            if (!parse_vec(v, o->look, 3)) {
                fprintf(stderr, "splatview: --look expects x,y,z, found '%s'\n", v);
                return 2;
            }
            o->have_look = true;
        } else if (!strcmp(a, "--clear")) {
            NEED();
            double c[3];
            if (!parse_vec(v, c, 3)) {
                fprintf(stderr, "splatview: --clear expects r,g,b, found '%s'\n", v);
                return 2;
            }
            for (int k = 0; k < 3; k++)
                o->clear[k] = (float)c[k];
            o->clear[3] = 1.0f;
        } else if (!strcmp(a, "--camera-preset")) {
            NEED(); o->preset = v;
        } else if (!strcmp(a, "--view")) {
            NEED(); o->view = v;
        } else if (!strcmp(a, "--frames")) {
            NEED();
            o->frames = atoi(v);
            if (o->frames < 1) {
                fprintf(stderr, "splatview: --frames expects a positive count, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--far-atlas-distance")) {
            NEED();
            char *end;
            o->far_distance = strtod(v, &end);
            if (*end || !(o->far_distance >= 0) || !isfinite(o->far_distance)) {
                fprintf(stderr, "splatview: --far-atlas-distance expects metres >= 0, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--lod-pixels")) {
            NEED();
            o->lod_pixels = atof(v);
            if (!(o->lod_pixels > 0)) {
                fprintf(stderr, "splatview: --lod-pixels expects a positive number\n");
                return 2;
            }
        } else if (!strcmp(a, "--sun")) {
            NEED();
            char *end;
            o->sun[0] = strtod(v, &end);
            o->sun[1] = *end == ',' ? strtod(end + 1, &end) : NAN;
            if (*end || !(fabs(o->sun[0]) <= 360) || !(o->sun[1] >= -90 && o->sun[1] <= 90)) {
                fprintf(stderr, "splatview: --sun expects AZIMUTH,ELEVATION in degrees "
                        "(-360..360, -90..90), found '%s'\n", v);
                return 2;
            }
            o->sun_set = true;
        } else if (!strcmp(a, "--light")) {
            NEED();
            if (!parse_light(v, o))
                return 2;
        } else if (!strcmp(a, "--exposure") || !strcmp(a, "--fog-density")) {
            NEED();
            char *end;
            double x = strtod(v, &end);
            bool fog = !strcmp(a, "--fog-density");
            if (*end || end == v || (fog ? !(x >= 0 && x <= 1) : !(x >= -20 && x <= 20))) {
                fprintf(stderr, "splatview: %s expects %s, found '%s'\n", a,
                        fog ? "a density 0..1 per metre" : "stops -20..20", v);
                return 2;
            }
            *(fog ? &o->fog_density : &o->exposure) = x;
            *(fog ? &o->fog_set : &o->exposure_set) = true;
        } else if (!strcmp(a, "--shading")) {
            NEED();
            if (!strcmp(v, "forward"))
                o->shading = RT_SHADING_FORWARD, o->shading_set = true;
            else if (!strcmp(v, "screen"))
                o->shading = RT_SHADING_SCREEN, o->shading_set = true;
            else {
                fprintf(stderr, "splatview: --shading expects forward or screen, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--shadow")) {
            NEED();
            if (!strcmp(v, "gpu"))
                o->shadow = RT_SHADOW_GPU;
            else if (!strcmp(v, "cpu"))
                o->shadow = RT_SHADOW_CPU;
            else {
                fprintf(stderr, "splatview: --shadow expects gpu or cpu, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--screen-depth")) {
            NEED();
            if (!strcmp(v, "auto"))
                o->screen_depth = RT_DEPTH_AUTO;
            else if (!strcmp(v, "raster"))
                o->screen_depth = RT_DEPTH_RASTER;
            else if (!strcmp(v, "raycast"))
                o->screen_depth = RT_DEPTH_RAYCAST;
            else {
                fprintf(stderr, "splatview: --screen-depth expects auto, raster or raycast, "
                        "found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--pixel-sort")) {
            NEED();
            if (!strcmp(v, "on"))
                o->pixel_sort = RT_SORT_ON;
            else if (!strcmp(v, "off"))
                o->pixel_sort = RT_SORT_OFF;
            else {
                fprintf(stderr, "splatview: --pixel-sort expects on or off, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--reference")) {
            NEED();
            if (!strcmp(v, "multipass"))
                o->ref = RT_REF_MULTIPASS;
            else if (!strcmp(v, "uber"))
                o->ref = RT_REF_UBER;
            else {
                fprintf(stderr, "splatview: --reference expects multipass or uber, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--param")) {
            NEED();
            if (o->nparams == 64) {
                fprintf(stderr, "splatview: more than 64 --param options\n");
                return 2;
            }
            o->params[o->nparams++] = v;
        } else if (!strcmp(a, "--pipeline-cache")) {
            NEED(); o->cache = v;
        } else if (!strcmp(a, "--scene")) {
            NEED(); o->scene = v;
        } else if (!strcmp(a, "--material")) {
            NEED(); o->material = v;
            if (!*v || strspn(v, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                 "0123456789_") != strlen(v)) {
                fprintf(stderr, "splatview: --material expects a material's name, found "
                        "'%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "-I")) {
            NEED();
            if (o->ninclude == 64) {
                fprintf(stderr, "splatview: too many -I folders (at most 64)\n");
                return 2;
            }
            o->include[o->ninclude++] = v;
        } else if (!strcmp(a, "--script")) {
            NEED(); o->script = v;
        } else if (!strcmp(a, "--crater")) {
            NEED();
            if (o->ncraters == 64 || !parse_crater(v, &o->craters[o->ncraters])) {
                fprintf(stderr, "splatview: --crater expects x,z,radius[,depth] in metres "
                        "(radius > 0, at most 64), found '%s'\n", v);
                return 2;
            }
            o->ncraters++;
        } else if (!strcmp(a, "--crater-at-view")) {
            NEED();
            char *end;
            o->crater_at_view = strtod(v, &end);
            if (*end || !(o->crater_at_view > 0)) {
                fprintf(stderr, "splatview: --crater-at-view expects a radius in metres, found '%s'\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--destruction-pool")) {
            NEED();
            char *end;
            long n = strtol(v, &end, 10);
            if (*end || n < 1 || n > 65025) {
                fprintf(stderr, "splatview: --destruction-pool expects 1..65025 tiles, found '%s'\n", v);
                return 2;
            }
            o->destruction_pool = (int)n;
        } else if (a[0] == '-') {
            fprintf(stderr, "splatview: unknown option '%s' (see --help)\n", a);
            return 2;
        } else if (!o->pack) {
            o->pack = a;
        } else {
            fprintf(stderr, "splatview: more than one pack given ('%s')\n", a);
            return 2;
        }
#undef NEED
    }
    if (!o->pack) {
        usage(stderr);
        return 2;
    }
    if (o->have_camera != o->have_look) {
        fprintf(stderr, "splatview: --camera and --look go together\n");
        return 2;
    }
    if (o->headless && !o->out && !o->float_out && !o->stats && !o->check) {
        fprintf(stderr, "splatview: --headless needs -o OUT.png, --float-out or --stats\n");
        return 2;
    }
    return 0;
}

static bool pick_camera(const opts *o, const rt_pack *p, rt_camera *cam)
{
    rt_default_camera(p, cam);
    if (o->preset) {
        int c = rt_pack_camera_find(p, o->preset);
        if (c < 0) {
            fprintf(stderr, "splatview: the pack has no camera preset '%s'", o->preset);
            for (int i = 0; i < p->ncameras; i++)
                fprintf(stderr, "%s'%s'", i ? ", " : " (it has ", p->cameras[i].name);
            fprintf(stderr, "%s\n", p->ncameras ? ")" : "");
            return false;
        }
        memcpy(cam->position, p->cameras[c].position, sizeof cam->position);
        memcpy(cam->look, p->cameras[c].look, sizeof cam->look);
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

static int headless(const opts *o)
{
    rt_error e = { 0 };
    rt_pack pack;
    rt_device dev;
    rt_renderer *r = NULL;
    int status = 1;
    float *rgba = NULL;
    uint8_t *png = NULL;
    double *gpu = NULL, *sel = NULL, *cpu = NULL;
    bool have_dev = false;

    if (!rt_pack_load(&pack, o->pack, &e)) {
        fprintf(stderr, "splatview: %s\n", e.msg);
        rt_error_clear(&e);
        return 1;
    }
    splat_view view = SPLAT_VIEW_FINAL;
    int material = 0;
    rt_camera cam;
    if ((o->view && !rt_parse_view(o->view, &pack, &view, &material, &e)) ||
        !pick_camera(o, &pack, &cam))
        goto done;
    if (!rt_device_create(&dev, NULL, &e))
        goto done;
    have_dev = true;
    rt_render_desc rd = {
        .width = o->width, .height = o->height, .reference = o->ref,
        .pipeline_cache = o->cache, .no_stitch = o->no_stitch,
        .no_cull = o->no_cull, .lod_pixels = o->lod_pixels, .no_shadows = o->no_shadows,
        .shadow = o->shadow,
        .no_undergrowth = o->no_undergrowth,
        .no_distance_classes = o->no_distance_classes,
        .async_pipelines = o->async_pipelines == 1,
        .split_uncovered = o->split_uncovered,
        .destruction_pool = o->destruction_pool, .shading = o->shading,
        .screen_depth = o->screen_depth, .pixel_sort = o->pixel_sort, .far_atlas_distance = o->far_distance,
    };
    if (!shading_chosen(o, &rd.shading))
        rd.shading = pack.uber_compute && o->ref != RT_REF_MULTIPASS ? RT_SHADING_SCREEN
                                                                     : RT_SHADING_FORWARD;
    light_options(o, &rd);
    memcpy(rd.clear, o->clear, sizeof rd.clear);
    if (!rt_renderer_create(&dev, &pack, &rd, &r, &e) || !apply_params(o, r, &e) ||
        !apply_craters(o, r, &cam, &e))
        goto done;
    if (o->check) {   /* the pack loads and a renderer stands on this device */
        printf("%s: loads (%d combinations, %d materials, %s path)\n", o->pack, pack.ncombos,
               pack.nmaterials, rd.shading == RT_SHADING_SCREEN ? "screen" : "forward");
        status = 0;
        goto done;
    }
    rt_renderer_set_view(r, view, material);
    int W = o->width > 0 ? o->width : 1280, H = o->height > 0 ? o->height : 720;
    gpu = calloc((size_t)o->frames * 7, sizeof *gpu);
    if (!gpu)
        goto done;
    sel = gpu + o->frames;
    cpu = sel + o->frames;
    double *pass = cpu + o->frames;   /* 3 per frame: geometry, classify, shade */
    double *ug_draw = pass + 3 * o->frames;
    rt_frame_stats st = { 0 };
    double shadow_ms = 0;   /* the first frame makes the shadow map */
    double ug_gen_ms = 0;   /* and generates the undergrowth's cells */
    int ug_generated = 0;
    double compile_ms = 0;
    /* the cost view needs the counting variant's counters */
    rt_renderer_set_counting(r, view == SPLAT_VIEW_COST);
    for (int f = 0; f < o->frames; f++) {
        if (!rt_renderer_frame(r, &cam, &st, &e))
            goto done;
        gpu[f] = st.gpu_ms;
        shadow_ms += st.shadow_ms;
        compile_ms += st.compile_ms;
        sel[f] = st.select_ms;
        cpu[f] = st.cpu_ms;
        for (int k = 0; k < 3; k++)
            pass[k * o->frames + f] = st.pass_ms[k];
        ug_draw[f] = st.undergrowth.draw_ms;
        if (st.undergrowth.generated > 0) {
            ug_gen_ms += st.undergrowth.gen_ms;
            ug_generated += st.undergrowth.generated;
        }
    }
    if (o->out || o->float_out) {
        rgba = malloc((size_t)W * (size_t)H * 16);
        png = malloc((size_t)W * (size_t)H * 4);
        if (!rgba || !png || !rt_renderer_read(r, rgba, &e))
            goto done;
        if (o->float_out && !rt_write_float(o->float_out, rgba, W, H, &e))
            goto done;
        if (o->out) {
            rt_tonemap_rgba8(rgba, W, H, tonemap_for(view), png);
            if (o->overlay) {   /* no frame rate: the picture stays reproducible */
                char text[2048];
                rt_overlay_info in = {
                    .pack = pack.name, .view = view, .screen = st.screen,
                    .material = view == SPLAT_VIEW_MASK ? pack.materials[material].name : NULL,
                    .pending = st.pipelines_pending, .status = "headless",
                };
                rt_overlay_text(&in, text, sizeof text);
                if (!rt_overlay_draw_rgba8(&dev, text, png, W, H, &e))
                    goto done;
            }
            if (!rt_write_png(o->out, png, W, H, &e))
                goto done;
        }
    }
    if (o->stats) {
        double gm, gl, gh, sm, sl, sh, cm, cl, ch;
        summary(gpu, o->frames, &gm, &gl, &gh);
        summary(sel, o->frames, &sm, &sl, &sh);
        summary(cpu, o->frames, &cm, &cl, &ch);
        printf("device: %s\n", dev.props.deviceName);
        printf("size: %dx%d  view: %s  reference: %s  frames: %d\n", W, H, rt_view_name(view),
               o->ref == RT_REF_MULTIPASS ? "multipass" : o->ref == RT_REF_UBER ? "uber" : "none",
               o->frames);
        printf("patches drawn: %d  culled: %d\n", st.patches, st.culled);
        printf("back faces culled: %s\n", st.backfaces_culled ? "yes" : "no");
        printf("pipelines bound: %d\n", st.pipelines);
        if (st.screen)
            printf("compute modules: %d from the pack or the SPIR-V cache, %d compiled from GLSL; "
                   "%.1f ms making pipelines between frames\n", st.spirv_cached,
                   st.spirv_compiled, compile_ms);
        printf("combinations in view: %d of %d\n", st.combos_in_view, pack.ncombos);
        if (!st.screen) {
            printf("distance classes: %d of %d patches\n", st.class_patches, st.patches);
            printf("far atlas: %d of %d patches\n", st.far_patches, st.patches);
            printf("uber-shader fallback: %d of %d patches (no compiled combination "
                   "covers their node)\n", st.uber_patches, st.patches);
            printf("uncovered nodes split: %d\n", st.split_uncovered);
        }
        if (gm >= 0)
            printf("gpu ms/frame: median %.3f  p10 %.3f  p90 %.3f\n", gm, gl, gh);
        else
            printf("gpu ms/frame: n/a (no timestamp support)\n");
        if (st.screen) {
            static const char *const names[3] = { "depth", "classification",
                                                  "shading (compute)" };
            for (int k = 0; k < 3 && gm >= 0; k++) {
                double m, l, h;
                summary(pass + k * o->frames, o->frames, &m, &l, &h);
                printf("  %-18s gpu ms: median %.3f  p10 %.3f  p90 %.3f\n", names[k], m, l, h);
            }
            printf("tiles: %d of %d shaded, %d lists, %d by the uber-shader, %d from the far "
                   "atlas\n", st.tiles.tiles, st.tiles.tiles_total, st.tiles.lists,
                   st.tiles.tiles_uber, st.tiles.tiles_far);
            printf("distance classes: %d of %d tiles\n", st.tiles.tiles_class, st.tiles.tiles);
            printf("pipelines pending: %d (tiles the uber-shader stood in for: %d)\n",
                   st.pipelines_pending, st.tiles.tiles_stand_in);
        }
        printf("quadtree cpu ms/frame: median %.4f  p10 %.4f  p90 %.4f\n", sm, sl, sh);
        if (o->no_shadows)
            printf("shadow map: off\n");
        else
            printf("shadow map %s ms: %.2f (when the sun moves or a crater lands; "
                   "per frame a texture tap)\n", st.shadow_gpu ? "gpu" : "cpu", shadow_ms);
        if (pack.ug.nslots > 0 && !o->no_undergrowth && view == SPLAT_VIEW_FINAL) {
            double um, ul, uh;
            summary(ug_draw, o->frames, &um, &ul, &uh);
            printf("undergrowth: %d cells, %ld instances, %.3f ms generation\n",
                   st.undergrowth.cells, st.undergrowth.instances, ug_gen_ms);
            printf("  generated %d cells (%.4f ms per cell), draw gpu ms/frame: median %.3f  "
                   "p10 %.3f  p90 %.3f, %zu bytes per cell\n", ug_generated,
                   ug_generated ? ug_gen_ms / ug_generated : 0.0, um, ul, uh,
                   st.undergrowth.bytes_per_cell);
        } else if (pack.ug.nslots > 0) {
            printf("undergrowth: off\n");
        }
        printf("cpu ms/frame (record): median %.3f  p10 %.3f  p90 %.3f\n", cm, cl, ch);
        if (st.screen || (dev.count_fragments && o->ref != RT_REF_MULTIPASS)) {
            /* one more frame with the counting variant (not timed) */
            rt_renderer_set_counting(r, true);
            rt_frame_stats cs;
            if (!rt_renderer_frame(r, &cam, &cs, &e))
                goto done;
            rt_renderer_set_counting(r, view == SPLAT_VIEW_COST);
            double px = cs.tiles.pixels ? (double)cs.tiles.pixels : 1.0;
            printf("layers per pixel: evaluated %.3f, needed %.3f (efficiency %.1f %%)\n",
                   cs.tiles.layers_evaluated / px, cs.tiles.layers_needed / px,
                   cs.tiles.layers_evaluated
                       ? 100.0 * cs.tiles.layers_needed / cs.tiles.layers_evaluated : 100.0);
            printf("texture samples per pixel: %.3f\n", cs.tiles.samples / px);
            printf("dynamic branches uniform over the subgroup: %.1f %% of %.2f per pixel\n",
                   cs.tiles.branches ? 100.0 * cs.tiles.branches_uniform / cs.tiles.branches : 100.0,
                   cs.tiles.branches / px);
        }
        printf("shading: %s%s\n", st.screen ? "screen" : "forward",
               st.sorted ? ", pixels sorted by layer set" : "");
        if (pack.far.data)   /* the BC blocks as uploaded (PACK.md "Far atlas") */
            printf("far atlas: %d x %d texels of %.1f x %.1f m, %d levels, %zu bytes; %s\n",
                   pack.far.width, pack.far.height, pack.far.texel[0], pack.far.texel[1],
                   pack.far.levels, pack.far.n - FAR_ATLAS_HEADER,
                   o->far_distance <= 0 ? "not used"
                   : st.screen ? "screen tiles beyond --far-atlas-distance use it"
                               : "forward patches beyond --far-atlas-distance use it");
        rt_painted_print_stats(&pack, stdout);
        if (rt_renderer_destruction(r))
            rt_destruction_print_stats(rt_renderer_destruction(r), stdout);
    }
    status = 0;
done:
    if (e.msg)
        fprintf(stderr, "splatview: %s\n", e.msg);
    rt_error_clear(&e);
    rt_renderer_destroy(r);
    if (have_dev) {
        rt_device_destroy(&dev);
        if (dev.validating && dev.messages) {
            fprintf(stderr, "splatview: %d validation message(s)\n", dev.messages);
            status = status ? status : 3;
        }
    }
    rt_pack_free(&pack);
    free(rgba);
    free(png);
    free(gpu);
    return status;
}

/* --material: the scene (--scene, else the pack's scene.source) built as
 * that material's swatch pack (splatc build --preview) under the cache
 * folder; o->pack then names it.  Exit status, 0 when built. */
static int build_preview(opts *o)
{
    char *scene = o->scene ? strdup(o->scene) : NULL;
    if (!scene) {
        rt_pack p;
        rt_error e = { 0 };
        if (!rt_pack_load(&p, o->pack, &e)) {
            fprintf(stderr, "splatview: %s\n", e.msg);
            rt_error_clear(&e);
            return 1;
        }
        scene = p.scene_path ? splat_path_join(o->pack, p.scene_path) : NULL;
        rt_pack_free(&p);
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
                    .no_shadows = o.no_shadows, .shadow = o.shadow,
                    .no_undergrowth = o.no_undergrowth,
                    .far_atlas_distance = o.far_distance,
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
