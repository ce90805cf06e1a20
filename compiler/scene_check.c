/* scene_check.c — every check of a scene block that needs neither its
 * files nor the rest of the program, in one place: what is missing, each
 * value's range, settings that contradict each other, the pack limits
 * (abi.h).  The parser stores what it reads as it is and calls this at the
 * block's end; scene.c adds what needs the program (material names) or
 * the files (raster sizes).  All errors at once, each at its setting.
 *
 *   scene s { size = 0 10 }
 *   -> 1:11 SETTING world size must be positive (x and z metres)
 *      1:7  MISSING_SETTING scene needs 'heightfield = ...'   (and so on)
 */
#include "abi.h"
#include "sg.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>


static bool is_pow2(int v) { return v > 0 && (v & (v - 1)) == 0; }

bool sg_scene_cells_fit(const sg_scene *sc, int w, int h, sg_diags *d)
{
    int side = w > h ? w : h, cell = sc->cell_texels > 0 ? sc->cell_texels : 32;
    if ((side + cell - 1) / cell <= SPLAT_MAX_CELLS)
        return true;
    sg_errorf(d, sg_loc_or(sc->cell_texels_loc, sc->loc), SG_E_OVER_LIMIT, "a cell of %d "
                "texels gives %d leaf cells per side over the %d x %d heightfield, over "
                "the pack limit of %d", cell, (side + cell - 1) / cell, w, h, SPLAT_MAX_CELLS);
    return false;
}

/* heightfield, size, max_height, materials; what a GDAL raster brings */
static void check_terrain(const sg_scene *sc, sg_diags *d)
{
    bool gdal = sc->heightfield && sc->hf_format == SG_HF_GDAL;
    const char *need[4] = { "heightfield", "size", "max_height", "materials" };
    bool has[4] = { sc->heightfield != NULL, sc->size_loc.line > 0 || gdal,
                    sc->max_height_loc.line > 0 || gdal, sc->materials_loc.line > 0 };
    for (int i = 0; i < 4; i++)
        if (!has[i])
            sg_errorf(d, sc->loc, SG_E_MISSING_SETTING, "scene needs '%s = ...'", need[i]);
    if (has[3] && sc->nmaterials == 0)
        sg_errorf(d, sc->materials_loc, SG_E_MISSING_SETTING, "scene needs at least one "
                    "material (materials = [BOTTOM, …, TOP])");
    if (sc->heightfield && sc->hf_format == SG_HF_R16 && sc->hf_size_loc.line == 0)
        sg_errorf(d, sc->heightfield_loc, SG_E_MISSING_SETTING, "raw heightfield '%s' "
                    "needs heightfield_size = WIDTH HEIGHT", sc->heightfield);
    if (sc->hf_size_loc.line > 0 && !(sc->hf_width >= 1 && sc->hf_height >= 1))
        sg_errorf(d, sc->hf_size_loc, SG_E_SETTING, "heightfield_size must be two positive "
                    "whole numbers");
    /* a GDAL raster's heights are used as stored (raster.c) */
    if (gdal && sc->max_height_loc.line > 0)
        sg_errorf(d, sc->max_height_loc, SG_E_SETTING, "max_height comes from the heights "
                    "stored in '%s' (a GDAL raster); remove it", sc->heightfield);
    if (gdal && sc->height_offset_loc.line > 0)
        sg_errorf(d, sc->height_offset_loc, SG_E_SETTING, "height_offset comes from the "
                    "heights stored in '%s' (a GDAL raster); remove it", sc->heightfield);
    /* finite and within the pack limit (abi.h SPLAT_MAX_EXTENT); what a
     * GDAL raster brings is checked once loaded (scene.c) */
    if (sc->size_loc.line > 0 && !(sc->size[0] > 0 && sc->size[1] > 0 &&
                                   sc->size[0] <= SPLAT_MAX_EXTENT &&
                                   sc->size[1] <= SPLAT_MAX_EXTENT))
        sg_errorf(d, sc->size_loc, SG_E_SETTING, "world size must be positive and at most "
                    "%g m (x and z metres), found %g %g", SPLAT_MAX_EXTENT, sc->size[0],
                    sc->size[1]);
    if (sc->max_height_loc.line > 0 && !(sc->max_height >= 0 &&
                                         sc->max_height <= SPLAT_MAX_EXTENT))
        sg_errorf(d, sc->max_height_loc, SG_E_SETTING, "max_height must be in [0, %g] m, "
                    "found %g", SPLAT_MAX_EXTENT, sc->max_height);
    if (!(fabs(sc->height_offset) <= SPLAT_MAX_EXTENT))
        sg_errorf(d, sg_loc_or(sc->height_offset_loc, sc->loc), SG_E_SETTING, "height_offset "
                    "must be finite and at most %g m either way, found %g", SPLAT_MAX_EXTENT,
                    sc->height_offset);
    if (!is_pow2(sc->cell_texels) || sc->cell_texels > 4096)
        sg_errorf(d, sg_loc_or(sc->cell_texels_loc, sc->loc), SG_E_SETTING, "cell must be a "
                    "power of two from 1 to 4096 heightfield texels");
    else if (sc->hf_format == SG_HF_R16 && sc->hf_width > 0 && sc->hf_height > 0)
        sg_scene_cells_fit(sc, sc->hf_width, sc->hf_height, d);
}

static void check_painted(const sg_scene *sc, const sg_scene_painted *pm, sg_diags *d)
{
    if (pm->max_level_loc.line > 0 && !(pm->max_level >= 0 && pm->max_level <= 7))
        sg_errorf(d, pm->max_level_loc, SG_E_SETTING, "max_level must be a whole number "
                    "0..7");
    if (!(pm->max_error >= 0 && pm->max_error <= 1))
        sg_errorf(d, sg_loc_or(pm->max_error_loc, pm->loc), SG_E_SETTING, "max_error must be "
                    "between 0 and 1");
    if (pm->has_near && !(pm->near[2] > pm->near[0] && pm->near[3] > pm->near[1]))
        sg_errorf(d, sg_loc_or(pm->near_loc, pm->loc), SG_E_SETTING, "near must be x0 z0 x1 z1 "
                    "with x1 > x0 and z1 > z0");
    const double *o = pm->origin, *s = pm->place;
    if (pm->place_loc.line > 0 && !(s[0] > 0 && s[1] > 0 && s[0] < 1e9 && s[1] < 1e9))
        sg_errorf(d, pm->place_loc, SG_E_SETTING, "a painted mask's size must be positive "
                    "metres, found %g %g", s[0], s[1]);
    if (pm->origin_loc.line > 0 && !(fabs(o[0]) < 1e9 && fabs(o[1]) < 1e9))
        sg_errorf(d, pm->origin_loc, SG_E_SETTING, "a painted mask's origin is out of range");
    if ((pm->origin_loc.line > 0) != (pm->place_loc.line > 0))
        sg_errorf(d, pm->origin_loc.line > 0 ? pm->origin_loc : pm->place_loc, SG_E_SETTING,
                    "painted mask '%s' is placed with both 'origin' and 'size' "
                    "(terrain-local metres) or neither", pm->name);
    for (const sg_scene_painted *q = sc->painted; q < pm; q++)
        if (strcmp(pm->name, q->name) == 0) {
            sg_error(d, sg_loc_or(pm->loc, sc->loc), SG_E_DUPLICATE, "painted mask", pm->name,
                     q->loc.file, q->loc.line, q->loc.col);
            break;
        }
}

static void check_destruction(const sg_scene *sc, sg_diags *d)
{
    sg_loc dloc = sg_loc_or(sc->destruction_loc, sc->loc);
    const double *o = sc->destruction_origin, *s = sc->destruction_size;
    double cell = sc->destruction_cell;
    if (!(s[0] > 0) || !(s[1] > 0) || !isfinite(s[0]) || !isfinite(s[1]) ||
        !isfinite(o[0]) || !isfinite(o[1]))
        sg_errorf(d, dloc, SG_E_SETTING, "the destructible area needs a finite origin and "
                    "a positive size, found origin %g %g, size %g %g", o[0], o[1], s[0], s[1]);
    if (!(cell > 0) || !isfinite(cell)) {
        sg_errorf(d, sg_loc_or(sc->destruction_cell_loc, dloc), SG_E_SETTING, "destruction "
                    "cell must be a positive size in metres, found %g", cell);
        return;
    }
    double side = fmax(s[0], s[1]), cells = ceil(side / cell);
    if (side > 0 && !(cells <= SPLAT_MAX_DESTRUCTION_CELLS))
        sg_errorf(d, dloc, SG_E_OVER_LIMIT, "the destructible area is %.0f cells of %g m "
                    "per side, over the pack limit of %d (a larger cell or a smaller area)",
                    cells, cell, SPLAT_MAX_DESTRUCTION_CELLS);
    /* a GDAL heightfield's size is known once it is read (scene.c) */
    if (sc->size_loc.line > 0 &&
        !(o[0] >= 0 && o[1] >= 0 && o[0] + s[0] <= sc->size[0] && o[1] + s[1] <= sc->size[1]))
        sg_errorf(d, dloc, SG_E_SETTING, "the destructible area (origin %g %g, size %g %g) "
                    "must lie inside the terrain (0 0 to %g %g)", o[0], o[1], s[0], s[1],
                    sc->size[0], sc->size[1]);
}

/* A spline or polygon block: enough points, finite and within the pack's
 * extent, width and falloff within their limits, a known profile, a
 * unique name (abi.h SPLAT_MAX_VECTOR_*). */
static void check_vector(const sg_scene *sc, const sg_scene_vector *v, sg_diags *d)
{
    bool spline = v->kind == SPLAT_VEC_SPLINE;
    const char *what = spline ? "spline" : "polygon";
    sg_loc loc = sg_loc_or(v->loc, sc->loc);
    sg_loc ploc = sg_loc_or(v->points_loc, loc);
    int need = spline ? 2 : 3;
    if (v->points_loc.line == 0)
        sg_errorf(d, loc, SG_E_MISSING_SETTING, "%s '%s' needs its points (points = "
                  "[x z, x z, ...], terrain-local metres)", what, v->name);
    for (int c = 0; c < v->ncurves; c++) {   /* each `points` is a curve */
        int n = v->curve_end[c] - (c ? v->curve_end[c - 1] : 0);
        if (n < need && v->npoints <= SPLAT_MAX_VECTOR_POINTS) {
            sg_errorf(d, sg_loc_or(v->curve_loc[c], loc), SG_E_SETTING, "%s '%s' has %d "
                      "point%s; a %s needs at least %d", what, v->name, n, n == 1 ? "" : "s",
                      v->ncurves > 1 ? "curve" : what, need);
            break;
        }
    }
    if (v->npoints > SPLAT_MAX_VECTOR_POINTS)
        sg_errorf(d, ploc, SG_E_OVER_LIMIT, "%s '%s' has more than %d points (all its curves), "
                  "the pack limit",
                  what, v->name, SPLAT_MAX_VECTOR_POINTS);
    for (int i = 0; i < 2 * v->npoints && i < 2 * SPLAT_MAX_VECTOR_POINTS; i++)
        if (!(fabs(v->points[i]) <= SPLAT_MAX_EXTENT)) {
            sg_errorf(d, ploc, SG_E_SETTING, "%s '%s': point %d's %s is %g; points must be "
                      "finite, within +-%g m", what, v->name, i / 2 + 1, i % 2 ? "z" : "x",
                      v->points[i], SPLAT_MAX_EXTENT);
            break;
        }
    if (spline && v->width_loc.line == 0)
        sg_errorf(d, loc, SG_E_MISSING_SETTING, "spline '%s' needs a width (metres)", v->name);
    else if (spline && !(v->width > 0 && v->width <= SPLAT_MAX_VECTOR_WIDTH))
        sg_errorf(d, v->width_loc, SG_E_SETTING, "spline '%s': width must be in (0, %g] "
                  "metres, found %g", v->name, SPLAT_MAX_VECTOR_WIDTH, v->width);
    if (!(v->falloff >= 0 && v->falloff <= SPLAT_MAX_VECTOR_WIDTH))
        sg_errorf(d, sg_loc_or(v->falloff_loc, loc), SG_E_SETTING, "%s '%s': falloff must be "
                  "in [0, %g] metres, found %g", what, v->name, SPLAT_MAX_VECTOR_WIDTH,
                  v->falloff);
    if (v->profile < 0)
        sg_errorf(d, sg_loc_or(v->profile_loc, loc), SG_E_SETTING, "%s '%s': profile must be "
                  "'linear' or 'smoothstep'", what, v->name);
    for (const sg_scene_vector *q = sc->vectors; q < v; q++)
        if (strcmp(v->name, q->name) == 0) {
            sg_error(d, loc, SG_E_DUPLICATE, "vector shape", v->name, q->loc.file,
                     q->loc.line, q->loc.col);
            break;
        }
}

static void check_light(const sg_scene_light *l, sg_diags *d)
{
    for (int k = 0; k < SPLAT_LIGHT_COUNT; k++)
        for (int i = 0; l->given & 1u << k && i < splat_light_keys[k].n; i++) {
            double v = l->v[k][i], lo, hi;
            splat_light_range(k, i, &lo, &hi);
            if (!(v >= lo && v <= hi)) {
                sg_errorf(d, l->loc[k], SG_E_SETTING, "light %s: %g is outside %g..%g%s",
                          splat_light_keys[k].key, v, lo, hi, k == SPLAT_LIGHT_SUN ?
                          " (AZIMUTH -360..360, ELEVATION -90..90 degrees)" : "");
                break;
            }
        }
}

bool sg_scene_check(const sg_scene *sc, sg_diags *d)
{
    int before = d->nerrors;
    check_terrain(sc, d);
    for (int i = 0; i < sc->npainted; i++)
        check_painted(sc, &sc->painted[i], d);
    if (sc->npainted > SPLAT_MAX_PAINTED)
        sg_errorf(d, sg_loc_or(sc->painted[SPLAT_MAX_PAINTED].loc, sc->loc), SG_E_OVER_LIMIT,
                    "scene '%s' declares %d painted masks, over the pack limit of %d",
                    sc->name, sc->npainted, SPLAT_MAX_PAINTED);
    for (int i = 0; i < sc->nvectors; i++)
        check_vector(sc, &sc->vectors[i], d);
    if (sc->nvectors > SPLAT_MAX_VECTORS)
        sg_errorf(d, sg_loc_or(sc->vectors[SPLAT_MAX_VECTORS].loc, sc->loc), SG_E_OVER_LIMIT,
                    "scene '%s' declares %d splines and polygons, over the pack limit of %d",
                    sc->name, sc->nvectors, SPLAT_MAX_VECTORS);
    if (sc->has_destruction)
        check_destruction(sc, d);
    if (sc->has_light)
        check_light(&sc->light, d);
    return d->nerrors == before;
}
