/* test_reload — hot reload never draws old data under new shaders: a
 * renderer made from BASE is handed each VARIANT (a copy of BASE with one
 * input changed, reload.sh) through rt_renderer_swap_pack, which must
 * refuse it with RT_E_RELOAD and a message naming the input, or, for
 * variants whose PHRASE is "ok" (shader or parameter changes), take it and
 * render a frame.  SPLAT_VALIDATE=1: zero validation messages.
 *
 *   test_reload [--screen] BASE VARIANT=PHRASE ...
 *
 * --screen: the renderer draws with the screen-space path (its tile
 * classification holds the pack's combination map, which a reload must
 * replace too). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt_internal.h"

static int failures;

static void check(bool ok, const char *what, const char *detail)
{
    if (!ok) {
        fprintf(stderr, "FAIL: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
        failures++;
    }
}

int main(int argc, char **argv)
{
    rt_render_desc rd = { .width = 64, .height = 48 };
    if (argc > 1 && !strcmp(argv[1], "--screen")) {
        rd.shading = RT_SHADING_SCREEN;
        argv++;
        argc--;
    }
    if (argc < 3) {
        fprintf(stderr, "usage: test_reload [--screen] BASE VARIANT=PHRASE ...\n");
        return 2;
    }
    rt_error e = { 0 };
    rt_pack base;
    rt_device dev;
    rt_renderer *r = NULL;
    if (!rt_pack_load(&base, argv[1], &e) || !rt_device_create(&dev, NULL, &e)) {
        fprintf(stderr, "FAIL: setup: %s\n", e.msg);
        return 1;
    }
    rt_camera cam;
    rt_default_camera(&base, &cam);
    if (!rt_renderer_create(&dev, &base, &rd, &r, &e) || !rt_renderer_frame(r, &cam, NULL, &e)) {
        fprintf(stderr, "FAIL: renderer: %s\n", e.msg);
        return 1;
    }
    /* every pack handed over stays alive until the renderer is gone */
    rt_pack *packs = calloc((size_t)argc, sizeof *packs);
    int npacks = 0;
    for (int i = 2; i < argc; i++) {
        char *arg = strdup(argv[i]), *eq = strchr(arg, '=');
        if (!eq) {
            fprintf(stderr, "usage: VARIANT=PHRASE, not '%s'\n", arg);
            return 2;
        }
        *eq = '\0';
        const char *dir = arg, *phrase = eq + 1;
        rt_pack *p = &packs[npacks];
        rt_error_clear(&e);
        check(rt_pack_load(p, dir, &e), dir, e.msg);
        if (e.msg) {
            free(arg);
            continue;
        }
        npacks++;
        bool ok = rt_renderer_swap_pack(r, p, &e);
        printf("%s: %s\n", dir, ok ? "reloaded" : e.msg);
        if (!strcmp(phrase, "ok")) {
            check(ok, dir, "a shader-only change was refused");
            rt_frame_stats st;
            check(rt_renderer_frame(r, &cam, &st, &e), dir, e.msg);
            check(st.screen == (rd.shading == RT_SHADING_SCREEN), dir, "drawn by the wrong path");
        } else {
            check(!ok && e.id == RT_E_RELOAD, dir, "reloaded with changed data");
            check(!ok && e.msg && strstr(e.msg, phrase), dir, "the message does not name the input");
        }
        free(arg);
    }
    rt_error_clear(&e);
    check(rt_renderer_frame(r, &cam, NULL, &e), "a frame after the reloads", e.msg);
    rt_renderer_destroy(r);
    rt_device_destroy(&dev);
    check(!dev.validating || dev.messages == 0, "validation messages", NULL);
    for (int i = 0; i < npacks; i++)
        rt_pack_free(&packs[i]);
    free(packs);
    rt_pack_free(&base);
    rt_error_clear(&e);
    printf("%s\n", failures ? "FAILED" : "PASS");
    return failures ? 1 : 0;
}
