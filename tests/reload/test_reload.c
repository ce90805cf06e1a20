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

#include "kit.h"

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
    rt_pack *base = kit_pack(argv[1]);
    rt_device *dev = base ? kit_device() : NULL;
    rt_renderer *r = NULL;
    if (!dev)
        return kit_finish("reload");
    rt_camera cam;
    rt_default_camera(base, &cam);
    if (!rt_renderer_create(dev, base, &rd, &r, &e) || !rt_renderer_frame(r, &cam, NULL, &e)) {
        CHECK(false, "renderer: %s", e.msg);
        return kit_finish("reload");
    }
    /* every pack handed over stays alive until the renderer is gone */
    rt_pack **packs = calloc((size_t)argc, sizeof *packs);
    int npacks = 0;
    for (int i = 2; i < argc; i++) {
        char *arg = strdup(argv[i]), *eq = strchr(arg, '=');
        if (!eq) {
            fprintf(stderr, "usage: VARIANT=PHRASE, not '%s'\n", arg);
            return 2;
        }
        *eq = '\0';
        const char *dir = arg, *phrase = eq + 1;
        rt_pack *p = kit_pack(dir);
        if (!p) {
            free(arg);
            continue;
        }
        packs[npacks++] = p;
        bool ok = rt_renderer_swap_pack(r, p, &e);
        printf("%s: %s\n", dir, ok ? "reloaded" : e.msg);
        if (!strcmp(phrase, "ok")) {
            CHECK(ok, "%s: a shader-only change was refused: %s", dir, e.msg);
            rt_frame_stats st;
            bool drawn = rt_renderer_frame(r, &cam, &st, &e);
            CHECK(drawn, "%s: %s", dir, e.msg);
            CHECK(!drawn || st.screen == (rd.shading == RT_SHADING_SCREEN),
                  "%s: drawn by the wrong path", dir);
        } else {
            CHECK(!ok && e.id == RT_E_RELOAD, "%s: reloaded with changed data", dir);
            CHECK(!ok && e.msg && strstr(e.msg, phrase),
                  "%s: the message does not name the input '%s'", dir, phrase);
        }
        rt_error_clear(&e);
        free(arg);
    }
    CHECK(rt_renderer_frame(r, &cam, NULL, &e), "a frame after the reloads: %s", e.msg);
    rt_renderer_destroy(r);
    kit_device_close(dev);
    for (int i = 0; i < npacks; i++)
        rt_pack_close(packs[i]);
    free(packs);
    rt_pack_close(base);
    rt_error_clear(&e);
    return kit_finish("reload");
}
