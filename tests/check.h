/* check.h — what the device test programs share (tests/world, the
 * lighting and destruction tests; each is one file): CHECK, which counts
 * a failure and goes on; join; and build_pack, a
 * fresh pack built with splatc's library (an old pack with the same inputs
 * would be kept as it is), its diagnostics left in *d for the caller. */
#ifndef SPLAT_TESTS_CHECK_H
#define SPLAT_TESTS_CHECK_H

#include "splatc.h"   /* libsplatc's public header: splat_build, diagnostics */
#include "splatrt.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;

#define CHECK(cond, ...)                                                    \
    do {                                                                    \
        if (!(cond)) {                                                      \
            failures++;                                                     \
            fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                   \
            fputc('\n', stderr);                                            \
        }                                                                   \
    } while (0)

static inline char *join(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (p) snprintf(p, n, "%s/%s", dir, name);
    return p;
}

/* Build scene file `sg` into `pack` (removed first), imports searched in
 * "." (the repository root); the diagnostics in *d (free them). */
static inline bool build_pack(const char *sg, const char *pack, splat_painted_format painted,
                              sg_diags *d)
{
    char rm[1200];
    snprintf(rm, sizeof rm, "rm -rf '%s'", pack);
    static const char *const search[] = { ".", NULL };
    splat_build_desc bd = { .scene = sg, .out = pack, .search_paths = search,
                            .jobs = 2, .no_cache = true, .painted = painted };
    splat_build_stats st;
    sg_diags_init(d);
    return system(rm) == 0 && splat_build(&bd, &st, d);
}

/* build_pack for a scene that must build: diagnostics printed if not. */
static inline bool build_pack_ok(const char *sg, const char *pack)
{
    sg_diags d;
    bool ok = build_pack(sg, pack, SPLAT_PAINTED_BC4, &d);
    if (!ok) sg_diags_print(&d, stderr);
    sg_diags_free(&d);
    return ok;
}

/* One frame of renderer r from cam, read back (w x h RGBA32F, free it);
 * NULL, counted as a failure, if it cannot be drawn. */
static inline float *frame_of(rt_renderer *r, const rt_camera *cam, int w, int h)
{
    rt_error e = { 0 };
    float *rgba = malloc((size_t)w * (size_t)h * 16);
    bool ok = rgba && rt_renderer_frame(r, cam, NULL, &e) && rt_renderer_read(r, rgba, &e);
    CHECK(ok, "frame: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    if (!ok) {
        free(rgba);
        return NULL;
    }
    return rgba;
}

/* One frame of `view` (`material` for the MASK view) from `cam` with
 * `rd` (its width, height, reference, shading, clear, light), read back
 * as RGBA32F; NULL (and a failure counted) if any step fails. */
static inline float *render_frame(rt_device *dev, const rt_pack *p, const rt_render_desc *rd,
                                  splat_view view, int material, const rt_camera *cam)
{
    rt_error e = { 0 };
    rt_renderer *r = NULL;
    bool ok = rt_renderer_create(dev, p, rd, &r, &e);
    CHECK(ok, "renderer: %s", e.msg ? e.msg : "?");
    rt_error_clear(&e);
    if (!ok)
        return NULL;
    rt_renderer_set_view(r, view, material);
    float *rgba = frame_of(r, cam, rd->width, rd->height);
    rt_renderer_destroy(r);
    return rgba;
}

/* DIR/NAME as a PNG, tone-mapped as the view's screenshots are. */
static inline void write_picture(const char *dir, const char *name, const float *rgba,
                                 int w, int h, splat_view view)
{
    rt_error e = { 0 };
    uint8_t *px = malloc((size_t)w * (size_t)h * 4);
    char *png = join(dir, name);
    if (px) rt_tonemap_rgba8(rgba, w, h, rt_view_tonemap(view), px);
    CHECK(px && rt_write_png(png, px, w, h, &e), "%s: %s", png, e.msg ? e.msg : "");
    rt_error_clear(&e);
    free(png);
    free(px);
}

#endif
