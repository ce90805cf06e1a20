/* far_bake_device.c — splatc build's device for the far atlas bake: a
 * renderer on the pack written so far, baking through far_bake.c.  Apart
 * from far_bake.c so that the bake does not call back into the renderer
 * (render.c -> far_bake.c, never the other way). */
#include "rt_internal.h"
#include "far_atlas.h"

#include <stdio.h>
#include <string.h>

/* ---- splatc build's device (compiler/scene.h far_device) ------------------ */

/* Linked into the splatc program where the runtime is built (libsplatc
 * stays free of Vulkan).  It opens the pack the build has written so far
 * (no far atlas yet) on the Vulkan device splatview would pick
 * (SPLAT_DEVICE picks another; with SPLAT_VALIDATE=1 any validation
 * message fails the bake).  For auto a CPU's device (lavapipe) bakes only
 * where it beats the compiler's CPU reference (cpu_device_pays). */
static bool fail_msg(rt_error *e, char *msg, size_t nmsg, const char *what)
{
    snprintf(msg, nmsg, "%s: %s", what, e->msg ? e->msg : "failed");
    rt_error_clear(e);
    return false;
}

/* Auto on a CPU's device (lavapipe): llvmpipe JIT-compiles each
 * combination on its first dispatch (about 0.22 s cold on the project's
 * VM), then shades a texel in about 1.7 us against the CPU reference's
 * 23 us (tests/bench/HISTORY.md "The far atlas baked on the device"):
 * the device pays from about CPU_DEVICE_TEXELS texels per combination.
 * Both costs scale with the same cores, so the ratio travels. */
#define CPU_DEVICE_TEXELS 10000.0

static bool cpu_device_pays(const rt_pack *p, int w, int h, const rt_device *d, char *msg,
                            size_t nmsg)
{
    int n = rt_far_bake_combos(p);
    double per = n > 0 ? (double)w * h / n : 0;
    if (per >= CPU_DEVICE_TEXELS)
        return true;
    snprintf(msg, nmsg, "the Vulkan device, %s, is a CPU, and %.0f texels a combination (%d) "
             "are under the %.0f from which it beats the CPU reference", d->props.deviceName,
             per, n, CPU_DEVICE_TEXELS);
    return false;
}

bool rt_far_bake_device(void *user, const char *pack_dir, int w, int h, float *albedo,
                        float *normal, float *rough, char *msg, size_t nmsg)
{
    const rt_far_bake_host *host = user;
    rt_error e = {0};
    rt_device own = {0}, *d = host->device;
    rt_device_desc dd = {0};
    if (!d) {
        if (!rt_device_create(&own, &dd, &e))
            return fail_msg(&e, msg, nmsg, "no Vulkan device");
        d = &own;
    }
    bool ok = false;
    int before = rt_device_messages(d);
    rt_pack p;
    rt_renderer *r = NULL;
    if (!rt_pack_load(&p, pack_dir, &e)) {
        fail_msg(&e, msg, nmsg, "the pack");
    } else if (host->mode == SPLAT_FAR_BAKE_AUTO &&
               d->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU &&
               !cpu_device_pays(&p, w, h, d, msg, nmsg)) {
        rt_pack_free(&p);
    } else {
        /* the atlas is the full shading on every device: not the CPU
         * shading LOD's cheaper nodes, nearest mips and footprints */
        rt_render_desc rd = { .width = 8, .height = 8, .no_undergrowth = true, .no_shadows = true,
                              .shading_lod = RT_SHADING_LOD_OFF };
        if (!rt_renderer_create(d, &p, &rd, &r, &e))
            fail_msg(&e, msg, nmsg, d->props.deviceName);
        else if (!rt_renderer_bake_far(r, w, h, albedo, normal, rough, NULL, &e))
            fail_msg(&e, msg, nmsg, d->props.deviceName);
        else
            ok = true;
        rt_renderer_destroy(r);
        rt_pack_free(&p);
    }
    int messages = rt_device_messages(d) - before;
    if (d == &own)
        rt_device_destroy(&own);
    if (ok && messages > 0) {
        snprintf(msg, nmsg, "%d validation messages while baking", messages);
        ok = false;
    }
    return ok;
}
