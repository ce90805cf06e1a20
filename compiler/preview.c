/* preview.c — a material's swatch scene (`splatc build --preview M`,
 * `splatview --material M`): the loaded scene with its terrain replaced by
 * a built-in test hill and its materials by M alone, under the scene's
 * light, so an artist sees one graph on every slope while editing it.
 *
 * The hill: a 128 m square of 257 x 257 texels holding a hemisphere of
 * radius 40 m in the middle (every slope from flat at the top to vertical
 * at its foot) on a flat ring.  M is the only layer, so the compositor
 * gives it full coverage (the bottom layer's mask is 1): the swatch shows
 * M's surface; its mask is what the scene's own views show.  Painted
 * masks read 0 (the scene's rasters do not cover the hill), there are no
 * holes, no destructible area, no fog (a 128 m swatch is not a landscape),
 * and one camera preset, "swatch". */
#include "scene_load.h"
#include "util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { HILL_TEXELS = 257 };
static const double HILL_SIZE = 128.0, HILL_RADIUS = 40.0;

static void make_hill(splat_terrain *t)
{
    splat_terrain_free(t);
    memset(t, 0, sizeof *t);
    t->width = t->height = HILL_TEXELS;
    t->size[0] = t->size[1] = HILL_SIZE;
    t->max_height = HILL_RADIUS;
    t->texels = xmalloc((size_t)HILL_TEXELS * HILL_TEXELS * sizeof *t->texels);
    for (int z = 0; z < HILL_TEXELS; z++)
        for (int x = 0; x < HILL_TEXELS; x++) {
            double dx = (x + 0.5) / HILL_TEXELS * HILL_SIZE - HILL_SIZE / 2;
            double dz = (z + 0.5) / HILL_TEXELS * HILL_SIZE - HILL_SIZE / 2;
            double r2 = dx * dx + dz * dz, R2 = HILL_RADIUS * HILL_RADIUS;
            double h = r2 < R2 ? sqrt(R2 - r2) / HILL_RADIUS : 0.0;
            t->texels[(size_t)z * HILL_TEXELS + (size_t)x] = (uint16_t)lrint(h * 65535.0);
        }
}

bool splat_scene_preview(splat_scene *s, const char *material, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    int k = 0;
    while (k < sc->nmaterials && strcmp(sc->materials[k], material))
        k++;
    if (k == sc->nmaterials) {
        size_t n = 1;
        for (int i = 0; i < sc->nmaterials; i++)
            n += strlen(sc->materials[i]) + 2;
        char *list = xcalloc(n, 1);
        for (int i = 0; i < sc->nmaterials; i++) {
            if (i) strcat(list, ", ");
            strcat(list, sc->materials[i]);
        }
        sg_errorf(d, sg_loc_or(sc->materials_loc, sc->loc), SG_E_UNDECLARED,
                  "no material '%s' in scene '%s' to preview (it has: %s)", material, sc->name,
                  list);
        free(list);
        return false;
    }
    sg_scene *pv = xmalloc(sizeof *pv);
    *pv = *sc;
    pv->materials = &sc->materials[k];
    pv->material_locs = &sc->material_locs[k];
    pv->nmaterials = 1;
    pv->holes = NULL;
    pv->has_destruction = false;
    pv->cell_texels = 32;
    pv->size[0] = pv->size[1] = HILL_SIZE;
    pv->max_height = HILL_RADIUS;
    pv->height_offset = 0;
    static const char swatch[] = "swatch";
    sg_scene_camera *cam = xcalloc(1, sizeof *cam);
    *cam = (sg_scene_camera){
        .name = (char *)swatch,
        .position = { HILL_SIZE / 2 - 66, 50, HILL_SIZE / 2 + 70 },   /* south-west */
        .look = { HILL_SIZE / 2, 14, HILL_SIZE / 2 },
        .loc = sc->loc,
    };
    pv->cameras = cam;
    pv->ncameras = 1;
    pv->has_light = true;
    pv->light.given |= 1u << SPLAT_LIGHT_FOG_DENSITY;
    pv->light.v[SPLAT_LIGHT_FOG_DENSITY][0] = 0.0;
    s->own_desc = pv;
    s->desc = pv;
    s->nmaterials = 1;

    make_hill(&s->terrain);
    /* painted masks read 0: heightfield-sized ones become the hill's size,
     * placed ones keep theirs */
    for (int i = 0; i < sc->npainted; i++) {
        bool placed = sc->painted[i].place_loc.line > 0;
        if (!placed) {
            s->painted_size[i][0] = s->painted_size[i][1] = HILL_TEXELS;
            free(s->painted[i]);
            s->painted[i] = xmalloc((size_t)HILL_TEXELS * HILL_TEXELS);
        }
        memset(s->painted[i], 0, (size_t)s->painted_size[i][0] * (size_t)s->painted_size[i][1]);
    }
    return true;
}
