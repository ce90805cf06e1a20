/* light.c — preview lighting: the scene's `light` block (PACK.md
 * "scene.light"), splatview's --sun / --exposure / --fog-density and the
 * viewer's keys, turned into the frame's lighting fields (abi.h
 * splat_frame: sun_dir, sun_color, sky_color, fog, light).  The shading
 * itself is the ABI prelude's splat_light (compiler/abi.c).
 *
 * Defaults, for any scene: a sun 21 degrees up in the south-east (azimuth
 * 144, clockwise from north = -z), warm, irradiance 2.9 (times pi: a white
 * surface facing it shows 2.9 before the tone map); a blue sky; fog
 * towards the background colour that hides 31 % of the colour at the
 * distance the scene's cameras look from (rt_light_fog_default), the same
 * at every height unless the scene gives a fog_height (then it halves
 * every 0.17 x max_height above it); exposure 0 EV.
 *
 * The fog follows the cameras, not the terrain's extent alone: a 1 km
 * terrain seen from 1.4 km away was 88 % fog at 1.5 / extent.  It is never
 * denser than that old default (a quarter of the extent is the shortest D
 * taken), which is what scenes without presets keep: a lighter fog there
 * shows the screen path's mip-selection differences on far terrain past
 * the tolerances its tests hold (runtime/DESIGN.md).
 */
#include "rt_internal.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>

void rt_light_default(rt_light *l)
{
    *l = (rt_light){
        .sun = { 144.0, 21.0 },
        .sun_color = { 1.0, 0.93, 0.81 },
        .intensity = 2.9,
        .sky = { 0.16, 0.22, 0.34 },
        .fog_density = NAN,
        .fog_height = NAN,
        .exposure = 0.0,
    };
}

double rt_light_fog_default(const rt_pack *p)
{
    double ext = p->size[0] > p->size[1] ? p->size[0] : p->size[1];
    double d = 0.25 * ext;   /* rt_default_camera's distance without presets */
    for (int i = 0; i < p->ncameras; i++) {
        double s = 0;
        for (int k = 0; k < 3; k++) {
            double t = p->cameras[i].look[k] - p->cameras[i].position[k];
            s += t * t;
        }
        if (sqrt(s) > d)
            d = sqrt(s);
    }
    return d > 0 ? 0.375 / d : 0.0;
}

void rt_light_sun_dir(const rt_light *l, double dir[3])
{
    double az = l->sun[0] * M_PI / 180.0, el = l->sun[1] * M_PI / 180.0;
    dir[0] = sin(az) * cos(el);
    dir[1] = sin(el);
    dir[2] = -cos(az) * cos(el);
}

void rt_light_frame(const rt_light *l, const rt_pack *p, const float background[3],
                    splat_frame *fr)
{
    double dir[3];
    rt_light_sun_dir(l, dir);
    double density = isnan(l->fog_density) ? rt_light_fog_default(p) : l->fog_density;
    double base = isnan(l->fog_height) ? p->height_offset : l->fog_height;
    /* with a fog height: halving every 0.17 max_height above it (k = ln 2
     * / (0.17 max_height)); without, the same density everywhere */
    double falloff = !isnan(l->fog_height) && p->max_height > 1.0 ? 4.0 / p->max_height : 0.0;
    for (int i = 0; i < 3; i++) {
        fr->sun_dir[i] = (float)dir[i];
        fr->sun_color[i] = (float)(l->sun_color[i] * l->intensity);
        fr->sky_color[i] = (float)l->sky[i];
        fr->fog[i] = background[i];   /* far terrain fades into it */
    }
    fr->fog[3] = (float)density;
    fr->light[0] = (float)base;
    fr->light[1] = (float)falloff;
    fr->light[2] = (float)exp2(l->exposure);
    fr->light[3] = 0.0f;
}

/* rt_light's fields in abi.h SPLAT_LIGHT_KEYS order. */
static const size_t field_of[SPLAT_LIGHT_COUNT] = {
    offsetof(rt_light, sun), offsetof(rt_light, sun_color), offsetof(rt_light, intensity),
    offsetof(rt_light, sky), offsetof(rt_light, fog_density), offsetof(rt_light, fog_height),
    offsetof(rt_light, exposure),
};

double *rt_light_values(rt_light *l, int key)
{
    return (double *)((char *)l + field_of[key]);
}

const char *rt_light_check(const rt_light *l)
{
    static char why[160];
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++)
        for (int i = 0; i < splat_light_keys[k].n; i++) {
            double v = rt_light_values((rt_light *)l, k)[i], lo, hi;
            splat_light_range(k, i, &lo, &hi);
            bool unset = isnan(v) && (k == SPLAT_LIGHT_FOG_DENSITY || k == SPLAT_LIGHT_FOG_HEIGHT);
            if (!unset && !(v >= lo && v <= hi)) {
                snprintf(why, sizeof why, "%s: %g is outside %g..%g", splat_light_keys[k].key,
                         v, lo, hi);
                return why;
            }
        }
    return NULL;
}
