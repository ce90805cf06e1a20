/* painted.c — the scene's painted masks in the form the pack stores them:
 * the sparse quad-tree of sparse.h (BC4 or R8 atlas), built from the dense
 * rasters splat_scene_load read, with the per-mask options of the scene
 * file.  The analysis bounds cells from the same data (sparse_range), so
 * what it proves holds for what the GPU samples.
 *
 *   painted fields = "masks/fields.png" { max_level = 2, max_error = 0.05,
 *                                         near = 1000 1000 3000 3000 }
 *   -> sparse_mask_desc { .max_level = 2, .max_error = 0.05,
 *                         .near = texels under those metres }
 *   painted road = "road.tif" { origin = 60000 40000, size = 10000 10000 }
 *   -> .width, .height = the raster's, .rect = that square in terrain uv
 */
#include "scene_load.h"
#include "util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const format_names[] = {
    [SPLAT_PAINTED_BC4] = "bc4", [SPLAT_PAINTED_R8] = "r8", [SPLAT_PAINTED_DENSE] = "dense",
};

const char *splat_painted_format_name(splat_painted_format f)
{
    return (unsigned)f <= SPLAT_PAINTED_DENSE ? format_names[f] : "?";
}

bool splat_painted_format_parse(const char *s, splat_painted_format *f)
{
    for (int i = 0; i <= SPLAT_PAINTED_DENSE; i++)
        if (strcmp(s, format_names[i]) == 0) {
            *f = (splat_painted_format)i;
            return true;
        }
    return false;
}

/* Metres -> the texel whose centre is at or after it (x0) / before it (x1). */
static int texel_at(double m, double size, int n)
{
    double t = floor(m / size * n);
    return t < 0 ? 0 : t > n ? n : (int)t;
}

bool splat_painted_check_format(const splat_scene *s, splat_painted_format f,
                                sg_diags *d)
{
    const sg_scene *sc = s->desc;
    bool ok = true;
    for (int i = 0; f == SPLAT_PAINTED_DENSE && i < sc->npainted; i++)
        if (sc->painted[i].place_loc.line > 0) {
            char msg[256];
            snprintf(msg, sizeof msg, "painted mask '%s' is placed (origin, size); "
                     "--painted dense stores heightfield-sized layers only (use bc4 "
                     "or r8)", sc->painted[i].name);
            sg_error(d, sc->painted[i].place_loc, SG_E_SETTING, msg);
            ok = false;
        }
    return ok;
}

bool splat_painted_build(const splat_scene *s, splat_painted_format f,
                         sparse_masks *out, sg_diags *d)
{
    memset(out, 0, sizeof *out);
    const sg_scene *sc = s->desc;
    const splat_terrain *t = &s->terrain;
    int n = sc->npainted;
    sparse_mask_desc *md = xcalloc((size_t)(n ? n : 1), sizeof *md);
    for (int i = 0; i < n; i++) {
        const sg_scene_painted *pm = &sc->painted[i];
        md[i].name = pm->name;
        md[i].texels = s->painted[i];
        md[i].max_level = pm->max_level;
        md[i].max_error = pm->max_error;
        /* a placed mask: its raster over origin .. origin + size, as
         * terrain uv; `near` then in its own texels */
        int w = t->width, h = t->height;
        double o[2] = { 0, 0 }, sz[2] = { t->size[0], t->size[1] };
        if (pm->place_loc.line > 0) {
            w = md[i].width = s->painted_size[i][0];
            h = md[i].height = s->painted_size[i][1];
            memcpy(o, pm->origin, sizeof o);
            memcpy(sz, pm->place, sizeof sz);
            md[i].rect[0] = o[0] / t->size[0];
            md[i].rect[1] = o[1] / t->size[1];
            md[i].rect[2] = (o[0] + sz[0]) / t->size[0];
            md[i].rect[3] = (o[1] + sz[1]) / t->size[1];
        }
        if (pm->has_near) {
            md[i].near[0] = texel_at(pm->near[0] - o[0], sz[0], w);
            md[i].near[1] = texel_at(pm->near[1] - o[1], sz[1], h);
            md[i].near[2] = texel_at(pm->near[2] - o[0], sz[0], w) + 1;
            md[i].near[3] = texel_at(pm->near[3] - o[1], sz[1], h) + 1;
        }
    }
    sparse_desc sd = {
        .width = t->width, .height = t->height, .masks = md, .nmasks = n,
        .format = f == SPLAT_PAINTED_R8 ? SPARSE_R8 : SPARSE_BC4,
    };
    sparse_error err;
    bool ok = sparse_build(out, &sd, &err);
    if (!ok) {
        sg_loc loc = n > 0 && sc->painted[0].loc.file ? sc->painted[0].loc : sc->loc;
        sg_error(d, loc, SG_E_RASTER, err.msg);
    }
    free(md);
    return ok;
}
