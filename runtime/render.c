/* render.c — the renderer's state the caller changes between frames:
 * the view, the light, params, wireframe, craters (and the shadow map's
 * texels they touch), the undergrowth's switch and probes. */
#include "render_int.h"
#include "util.h"
#include "sg.h"     /* sg_suggest: "did you mean" for --param */

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rt_renderer_set_view(rt_renderer *r, splat_view view, int material)
{
    r->view = view;
    r->view_material = material;
}

void rt_renderer_set_counting(rt_renderer *r, bool on) { r->counting = on; }

bool rt_renderer_set_shading(rt_renderer *r, rt_shading s)
{
    if (s == RT_SHADING_SCREEN && !r->screen)
        return false;
    r->shading = s;
    return true;
}

rt_shading rt_renderer_shading(const rt_renderer *r) { return r->shading; }

/* The pack's light with the desc's overrides. */
void rt_render_pack_light(rt_renderer *r, const rt_pack *p)
{
    r->light = p->light;
    if (r->desc.sun_set)
        memcpy(r->light.sun, r->desc.sun, sizeof r->light.sun);
    if (r->desc.exposure_set)
        r->light.exposure = r->desc.exposure;
    if (r->desc.fog_set)
        r->light.fog_density = r->desc.fog_density;
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++)
        if (r->desc.light_keys & (1u << k))
            memcpy(rt_light_values(&r->light, k), r->desc.light[k],
                   (size_t)splat_light_keys[k].n * sizeof(double));
}

void rt_renderer_set_light(rt_renderer *r, const rt_light *l)
{
    r->light = *l;
    r->light_set = true;
}

void rt_renderer_set_shadows(rt_renderer *r, bool on)
{
    r->desc.no_shadows = !on;
}

const rt_light *rt_renderer_light(const rt_renderer *r)
{
    return &r->light;
}

void rt_renderer_set_wireframe(rt_renderer *r, bool on)
{
    if (on && !r->d->wireframe) {
        fprintf(stderr, "splatrt: wireframe unavailable (no fillModeNonSolid)\n");
        on = false;
    }
    r->wireframe = on;
}

/* A param by its full name ("snowcap.snowline"), or, failing that, by the
 * name after its material's ("snowline") when one material has it. */
static int find_param(const rt_pack *p, const char *name, int *nsuffix)
{
    int found = -1;
    *nsuffix = 0;
    for (int i = 0; i < p->nparams; i++)
        if (!strcmp(p->params[i].name, name))
            return i;
    for (int i = 0; i < p->nparams; i++) {
        const char *dot = strchr(p->params[i].name, '.');
        if (dot && !strcmp(dot + 1, name)) {
            found = i;
            (*nsuffix)++;
        }
    }
    return -1 - found;   /* <= -1: not found; -1 - index of a short match */
}

bool rt_renderer_set_param(rt_renderer *r, const char *name, const float value[4], rt_error *e)
{
    char what[512];
    int nsuffix;
    int i = find_param(r->p, name, &nsuffix);
    if (i >= 0) {
        const rt_pack_param *pp = &r->p->params[i];
        for (int k = 0; pp->has_range && k < pp->width; k++)
            if (!(value[k] >= pp->min && value[k] <= pp->max)) {
                /* the pack's combinations were culled for values in the range */
                snprintf(what, sizeof what, "param '%s' = %g is outside its declared range "
                         "[%g, %g] (the pack was analysed for that range; widen `range` in "
                         "the material and rebuild)", name, (double)value[k], pp->min, pp->max);
                return rt_fail(e, RT_E_PACK_FIELD, r->p->dir, what);
            }
        memcpy((uint8_t *)r->params_ubo.map + pp->offset, value, 16);
        rt_ug_invalidate(r->ug, NULL);   /* the masks may have changed */
        return true;
    }
    const char *near = NULL;
    if (nsuffix == 1) {
        near = r->p->params[-1 - i].name;
    } else {
        sg_suggest sg;
        sg_suggest_init(&sg, name);
        for (int k = 0; k < r->p->nparams; k++)
            sg_suggest_offer(&sg, r->p->params[k].name);
        near = sg_suggest_best(&sg);
    }
    if (near)
        snprintf(what, sizeof what, "no param named '%s'; did you mean '%s'?", name, near);
    else if (nsuffix > 1)
        snprintf(what, sizeof what, "no param named '%s' (%d materials have one: write "
                 "MATERIAL.%s)", name, nsuffix, name);
    else
        snprintf(what, sizeof what, "no param named '%s' (the pack has %d param%s%s%s)", name,
                 r->p->nparams, r->p->nparams == 1 ? "" : "s",
                 r->p->nparams ? ", e.g. " : "", r->p->nparams ? r->p->params[0].name : "");
    return rt_fail(e, RT_E_PACK_FIELD, r->p->dir, what);
}

/* Whether the map is to be made again: all of it (the sun moved), or the
 * texels craters changed. */
static bool shadow_full(const rt_renderer *r, double sun[3])
{
    rt_light_sun_dir(&r->light, sun);
    return r->shadow_stale || memcmp(sun, r->shadow_sun, 3 * sizeof *sun);
}

bool rt_render_shadow_due(const rt_renderer *r)
{
    double sun[3];
    bool full = shadow_full(r, sun);
    bool part = r->shadow_rect[0] < r->shadow_rect[2] && r->shadow_rect[1] < r->shadow_rect[3];
    return !r->desc.no_shadows && (full || part);
}

bool rt_render_update_shadow(rt_renderer *r, double *ms, rt_error *e)
{
    *ms = 0;
    double sun[3];
    bool full = shadow_full(r, sun);
    if (!rt_render_shadow_due(r))
        return true;
    const rt_pack *p = r->p;
    size_t n = (size_t)p->hf_width * (size_t)p->hf_height;
    /* both paths wait for the queue (an upload, a one-time submission):
     * the last frame's work is not the map's time */
    RT_VK(e, vkQueueWaitIdle(r->d->queue));
    double t0 = splat_now();
    if (r->shadow_on_gpu) {
        if (!r->shadow_gpu &&
            !rt_shadow_gpu_create(r->d, p, rt_renderer_heights(r), &r->terrain.height,
                                  r->pl.cache, &r->shadow_gpu, e)) {
            rt_shadow_gpu_destroy(r->shadow_gpu);
            r->shadow_gpu = NULL;
            if (!r->shadow_auto || e->id != RT_E_PACK_LIMIT)
                return false;
            /* a heightfield over the device's storage buffer limit: the
             * CPU march, unless the device's was asked for */
            rt_error_clear(e);
            r->shadow_on_gpu = false;
            return rt_render_update_shadow(r, ms, e);
        }
        t0 = splat_now();   /* the pyramid and the pipeline are made once */
        if (!rt_shadow_gpu_map(r->shadow_gpu, sun, r->bounds.hmax[r->bounds.nlevels - 1][0],
                               full ? NULL : r->shadow_rect, &r->terrain.shadow, e))
            return false;
        *ms = 1e3 * (splat_now() - t0);
    } else {
        if (!r->shadow_map && !(r->shadow_map = malloc(n)))
            return rt_fail(e, RT_E_VULKAN, "shadow map", "out of memory");
        rt_shadow_map(rt_renderer_heights(r), p, &r->bounds, sun, full ? NULL : r->shadow_rect,
                      r->shadow_map);
        *ms = 1e3 * (splat_now() - t0);
        if (!rt_image_upload(r->d, &r->terrain.shadow, r->shadow_map, n, e))
            return false;
    }
    memcpy(r->shadow_sun, sun, sizeof sun);
    r->shadow_stale = false;
    memset(r->shadow_rect, 0, sizeof r->shadow_rect);
    return true;
}

bool rt_renderer_shadow_read(rt_renderer *r, uint8_t *out, rt_error *e)
{
    size_t n = (size_t)r->p->hf_width * (size_t)r->p->hf_height;
    if (r->shadow_on_gpu && r->shadow_gpu)
        return rt_shadow_gpu_read(r->shadow_gpu, out, e);
    if (!r->shadow_on_gpu && r->shadow_map) {
        memcpy(out, r->shadow_map, n);
        return true;
    }
    return rt_fail(e, RT_E_VULKAN, "shadow map", "none made yet");
}

void rt_renderer_shadow_reference(rt_renderer *r, uint8_t *out)
{
    double sun[3];
    rt_light_sun_dir(&r->light, sun);
    rt_shadow_map(rt_renderer_heights(r), r->p, &r->bounds, sun, NULL, out);
}

/* A frame; on the screen-space path, drawn again while lists got tiles
 * whose pipelines did not exist yet (compiled in between): at most once
 * per variant in practice, since the classification is deterministic. */
bool rt_renderer_crater(rt_renderer *r, const rt_crater *c, rt_crater_stats *st, rt_error *e)
{
    if (!r->destr) {
        if (st) {
            memset(st, 0, sizeof *st);
            st->result = RT_CRATER_OUTSIDE;
        }
        return true;
    }
    rt_crater_stats local;
    if (!st)
        st = &local;
    if (!rt_destruction_crater(r->destr, c, st, e))
        return false;
    if (st->result == RT_CRATER_DONE) {
        /* the next frame's readers wait for the crater's submission */
        rt_tracker_written(&r->tracker, RT_RES_HEIGHT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_ACCESS_TRANSFER_WRITE_BIT);
        rt_tracker_written(&r->tracker, RT_RES_DESTRUCTION,
                           VK_PIPELINE_STAGE_TRANSFER_BIT |
                               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                           VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
        double rect[4] = { c->x - c->radius, c->z - c->radius, c->x + c->radius,
                           c->z + c->radius };
        rt_ug_invalidate(r->ug, rect);
    }
    /* the shadow map's texels the lowered disc can shade or unshade */
    double sun[3];
    int rect[4], *d = r->shadow_rect;
    rt_light_sun_dir(&r->light, sun);
    if (st->result == RT_CRATER_DONE &&
        rt_shadow_crater_rect(r->p, &r->bounds, sun, c->x, c->z, c->radius, rect)) {
        bool empty = d[0] >= d[2] || d[1] >= d[3];
        for (int k = 0; k < 4; k++)
            d[k] = empty ? rect[k] : k < 2 ? (rect[k] < d[k] ? rect[k] : d[k])
                                           : (rect[k] > d[k] ? rect[k] : d[k]);
    }
    return true;
}

bool rt_renderer_crater_at_pixel(rt_renderer *r, const rt_camera *c, double px, double py,
                                 int w, int h, double radius, rt_crater_stats *st,
                                 rt_error *e)
{
    double dir[3], hit[3];
    rt_camera_ray(c, (double)w / h, (px + 0.5) / w * 2 - 1, (py + 0.5) / h * 2 - 1, dir);
    if (!rt_renderer_pick(r, c->position, dir, hit)) {
        if (st) {
            memset(st, 0, sizeof *st);
            st->result = RT_CRATER_OUTSIDE;
        }
        return true;
    }
    rt_crater cr = { .x = hit[0], .z = hit[2], .radius = radius, .depth = radius / 4 };
    return rt_renderer_crater(r, &cr, st, e);
}

rt_destruction *rt_renderer_destruction(rt_renderer *r) { return r->destr; }

void rt_renderer_set_undergrowth(rt_renderer *r, bool on) { r->ug_off = !on; }

int rt_renderer_undergrowth_cell(rt_renderer *r, int ix, int iz, rt_ug_instance *out, int max,
                                 rt_error *e)
{
    return rt_ug_read_cell(r->ug, ix, iz, out, max, e);
}

int rt_renderer_undergrowth_rings(rt_renderer *r, double width, int nrings, uint32_t *counts,
                                  rt_error *e)
{
    return rt_ug_probe_rings(r->ug, width, nrings, counts, e);
}

int rt_renderer_undergrowth_drawn(rt_renderer *r, rt_ug_instance *out, int *key, int max,
                                  rt_error *e)
{
    return r->ug ? rt_ug_read_drawn(r->ug, out, key, max, e) : 0;
}

bool rt_renderer_undergrowth_wind(rt_renderer *r, float *points, int n, double time,
                                  rt_error *e)
{
    return r->ug ? rt_ug_probe_wind(r->ug, points, n, time, e) : false;
}

const uint16_t *rt_renderer_heights(const rt_renderer *r)
{
    return r->destr ? rt_destruction_heights(r->destr) : r->p->heights;
}

bool rt_renderer_pick(const rt_renderer *r, const double o[3], const double dir[3],
                      double hit[3])
{
    return rt_heightfield_pick(rt_renderer_heights(r), r->p, o, dir, hit);
}

bool rt_renderer_bake_far(rt_renderer *r, int w, int h, float *albedo, float *normal,
                          float *rough, rt_far_bake_stats *st, rt_error *e)
{
    rt_camera c;
    rt_default_camera(r->p, &c);
    splat_frame fr;
    rt_render_fill_frame(r, &c, &fr);
    if (r->destr)
        rt_destruction_frame(r->destr, &fr);
    /* seen from the origin (abi.h "far atlas bake"), no craters */
    memset(fr.camera, 0, sizeof fr.camera);
    memset(fr.world, 0, sizeof fr.world);
    memset(fr.destruction, 0, sizeof fr.destruction);
    return rt_far_bake(r->d, r->p, &r->pl, r->set0, r->set1, &fr, w, h, albedo, normal, rough,
                       st, e);
}

bool rt_renderer_read_heights(rt_renderer *r, uint16_t *out, rt_error *e)
{
    return rt_destruction_wait(r->destr, e) && rt_read_r16(r->d, &r->terrain.height, out, e);
}

