/* light.c — preview lighting: the scene's `light` block (PACK.md
 * "scene.light"), splatview's --sun / --exposure / --fog-density and the
 * viewer's keys, turned into the frame's lighting fields (abi.h
 * splat_frame: sun_dir, sun_color, sky_color, fog, light).  The shading
 * itself is the ABI prelude's splat_light (compiler/abi.c).
 *
 * Defaults, for any scene: a sun 21 degrees up in the south-east (azimuth
 * 144, clockwise from north = -z), warm, irradiance 2.9 (times pi: a white
 * surface facing it shows 2.9 before the tone map); a blue sky; fog of
 * 1.5 / the terrain's extent per metre, towards the background colour,
 * the same at every height unless the scene gives a fog_height (then it
 * halves every 0.17 x max_height above it); exposure 0 EV.  These are
 * the values the runtime always used: a lighter default fog shows the
 * screen path's mip-selection differences on far terrain past the
 * tolerances its tests hold (runtime/DESIGN.md).
 */
#include "rt_internal.h"

#include <math.h>

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
    double ext = p->size[0] > p->size[1] ? p->size[0] : p->size[1];
    double density = isnan(l->fog_density) ? 1.5 / ext : l->fog_density;
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

const char *rt_light_check(const rt_light *l)
{
    for (int i = 0; i < 3; i++)
        if (!(l->sun_color[i] >= 0 && l->sun_color[i] <= 1e4) ||
            !(l->sky[i] >= 0 && l->sky[i] <= 1e4))
            return "colours must be 0 or more (linear)";
    if (!(fabs(l->sun[0]) <= 360.0) || !(l->sun[1] >= -90.0 && l->sun[1] <= 90.0))
        return "sun must be AZIMUTH (-360..360) ELEVATION (-90..90) degrees";
    if (!(l->intensity >= 0 && l->intensity <= 1e4))
        return "intensity must be 0..10000";
    if (!isnan(l->fog_density) && !(l->fog_density >= 0 && l->fog_density <= 1))
        return "fog_density must be 0..1 per metre";
    if (!isnan(l->fog_height) && !isfinite(l->fog_height))
        return "fog_height must be finite";
    if (!(l->exposure >= -20 && l->exposure <= 20))
        return "exposure must be -20..20 EV";
    return NULL;
}
