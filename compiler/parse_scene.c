/* parse_scene.c — the `scene NAME { … }` block: heightfield, sizes,
 * materials and compositor, painted masks, splines and polygons (vector
 * layers), destruction, cameras and the light; paths are taken relative
 * to the scene file's folder. */
#include "parse.h"
#include "sg_internal.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <limits.h>

/* ---- scenes -------------------------------------------------------------- */

typedef struct scene_parse {
    sg_scene *sc;
    int cap_materials, cap_material_locs, cap_painted, cap_cameras, cap_vectors;
} scene_parse;

static void scene_error(parser *ps, sg_error_id id, sg_loc loc, const char *fmt,
                        const char *a)
{
    char msg[256];
    snprintf(msg, sizeof msg, fmt, a);
    sg_error(ps->d, loc, id, msg);
}

static bool parse_numbers(parser *ps, double *out, int n)
{
    for (int i = 0; i < n; i++)
        if (!ps_number(ps, &out[i]))
            return false;
    return true;
}

static char *scene_path(parser *ps, const char *rel)
{
    char *path = splat_path_join(ps->f->dir, rel);
    char *r = sg_strdup(ps->a, path);
    free(path);
    return r;
}

/* painted_opts = "{" { ("max_level" "=" NUM | "max_error" "=" NUM |
 *                "near" "=" NUM NUM NUM NUM | "origin" "=" NUM NUM |
 *                "size" "=" NUM NUM) [","] } "}" */
static bool painted_stmt(parser *ps, void *user)
{
    sg_scene_painted *pm = user;
    sg_token *key = ps_cur(ps);
    sg_loc kloc = ps_loc_of(ps, key);
    const char *keys = "'max_level', 'max_error', 'near', 'origin', 'size' or '}'";
    if (key->kind != SG_TK_IDENT) {
        ps_expected(ps, keys);
        return false;
    }
    bool ok;
    if (ps_is_kw(key, "max_level")) {
        ps_next(ps);
        double v = -1;
        ok = ps_expect(ps, SG_TK_EQ, "'='") && ps_number(ps, &v);
        pm->max_level = v >= 0 && v <= 7 && v == (int)v ? (int)v : -1;
        pm->max_level_loc = kloc;
    } else if (ps_is_kw(key, "max_error")) {
        ps_next(ps);
        ok = ps_expect(ps, SG_TK_EQ, "'='") && ps_number(ps, &pm->max_error);
        pm->max_error_loc = kloc;
    } else if (ps_is_kw(key, "near")) {
        ps_next(ps);
        ok = ps_expect(ps, SG_TK_EQ, "'='") && parse_numbers(ps, pm->near, 4);
        pm->has_near = ok;
        pm->near_loc = kloc;
    } else if (ps_is_kw(key, "origin") || ps_is_kw(key, "size")) {
        bool size = ps_is_kw(key, "size");
        ps_next(ps);
        ok = ps_expect(ps, SG_TK_EQ, "'='") && parse_numbers(ps, size ? pm->place : pm->origin, 2);
        if (ok) *(size ? &pm->place_loc : &pm->origin_loc) = kloc;
    } else {
        ps_expected(ps, keys);
        ps_hint_key(ps, key, sg_painted_keys);
        return false;
    }
    if (ok)
        ps_accept(ps, SG_TK_COMMA);
    return ok;
}

/* destruction = "destruction" "{" { ("origin" NUM NUM | "size" NUM NUM |
 *               "cell" NUM) [","] } "}"
 * camera = "camera" IDENT "{" { ("position" | "look") "=" NUM NUM NUM
 *          [","] } "}"
 * Both use this statement function on their own little block. */
typedef struct sub_block { scene_parse *sp; sg_scene_camera *cam; } sub_block;

static bool sub_stmt(parser *ps, void *user)
{
    sub_block *b = user;
    sg_scene *sc = b->sp->sc;
    sg_token *key = ps_cur(ps);
    if (key->kind != SG_TK_IDENT) {
        ps_expected(ps, b->cam ? "'position', 'look' or '}'" : "'origin', 'size', 'cell' or '}'");
        return false;
    }
    bool ok;
    if (b->cam && (ps_is_kw(key, "position") || ps_is_kw(key, "look"))) {
        ps_next(ps);
        ok = ps_expect(ps, SG_TK_EQ, "'='") &&
             parse_numbers(ps, ps_is_kw(key, "look") ? b->cam->look : b->cam->position, 3);
    } else if (!b->cam && (ps_is_kw(key, "origin") || ps_is_kw(key, "size"))) {
        ps_next(ps);
        ok = ps_expect(ps, SG_TK_EQ, "'='") &&
             parse_numbers(ps, ps_is_kw(key, "origin") ? sc->destruction_origin
                                                    : sc->destruction_size, 2);
    } else if (!b->cam && ps_is_kw(key, "cell")) {
        ps_next(ps);
        sc->destruction_cell_loc = ps_loc_of(ps, key);
        ok = ps_expect(ps, SG_TK_EQ, "'='") && ps_number(ps, &sc->destruction_cell);
    } else {
        ps_expected(ps, b->cam ? "'position', 'look' or '}'" : "'origin', 'size', 'cell' or '}'");
        ps_hint_key(ps, key, b->cam ? sg_camera_keys : sg_destruction_keys);
        return false;
    }
    if (ok)
        ps_accept(ps, SG_TK_COMMA);
    return ok;
}

/* light = "light" "{" { KEY "=" NUM... [","] } "}" (abi.h SPLAT_LIGHT_KEYS) */
static bool light_stmt(parser *ps, void *user)
{
    sg_scene_light *l = user;
    sg_token *key = ps_cur(ps);
    int k = 0;
    while (key->kind == SG_TK_IDENT && k < SPLAT_LIGHT_COUNT &&
           !ps_is_kw(key, splat_light_keys[k].key))
        k++;
    if (key->kind != SG_TK_IDENT || k == SPLAT_LIGHT_COUNT) {
        ps_expected(ps, "'sun', 'sun_color', 'intensity', 'sky', 'fog_density', "
                     "'fog_height', 'exposure' or '}'");
        const char *keys[SPLAT_LIGHT_COUNT + 1];
        for (int i = 0; i < SPLAT_LIGHT_COUNT; i++)
            keys[i] = splat_light_keys[i].key;
        keys[SPLAT_LIGHT_COUNT] = NULL;
        ps_hint_key(ps, key, keys);
        return false;
    }
    l->loc[k] = ps_loc_of(ps, key);
    ps_next(ps);
    bool ok = ps_expect(ps, SG_TK_EQ, "'='") && parse_numbers(ps, l->v[k], splat_light_keys[k].n);
    if (ok) {
        l->given |= 1u << k;
        ps_accept(ps, SG_TK_COMMA);
    }
    return ok;
}

/* camera NAME { position = X Y Z, look = X Y Z }, after "camera" */
static bool camera_decl(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "a camera name"))
        return false;
    sg_scene_camera *cam = SG_PUSH(ps->a, sc->cameras, sc->ncameras, sp->cap_cameras);
    cam->name = ps_tok_text(ps, name);
    cam->loc = ps_loc_of(ps, name);
    sub_block b = { sp, cam };
    ps_block(ps, "block of camera", sub_stmt, &b);
    return true;
}

/* painted NAME = "FILE" [painted_opts], after "painted"; NAME holes is
 * the terrain's holes mask, which takes no options */
static bool painted_decl(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "a painted mask name") || !ps_expect(ps, SG_TK_EQ, "'='"))
        return false;
    sg_token *file = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_STRING, "a file name in quotes"))
        return false;
    if (ps_is_kw(name, "holes")) {
        if (sc->holes)
            sg_error(ps->d, ps_loc_of(ps, name), SG_E_DUPLICATE, "painted mask", "holes",
                     sc->holes_loc.file, sc->holes_loc.line, sc->holes_loc.col);
        sc->holes = scene_path(ps, file->str);
        sc->holes_loc = ps_loc_of(ps, name);
        if (ps_cur(ps)->kind == SG_TK_LBRACE) {
            scene_error(ps, SG_E_SETTING, ps_loc_of(ps, ps_cur(ps)), "the holes mask takes no "
                        "options (it is not stored as a painted layer)%s", "");
            return false;
        }
        return true;
    }
    sg_scene_painted *pm = SG_PUSH(ps->a, sc->painted, sc->npainted, sp->cap_painted);
    pm->name = ps_tok_text(ps, name);
    pm->file = scene_path(ps, file->str);
    pm->loc = ps_loc_of(ps, name);
    pm->max_error = 1.0;
    if (ps_cur(ps)->kind == SG_TK_LBRACE)
        ps_block(ps, "block of painted mask options", painted_stmt, pm);
    return true;
}

/* The parse of one spline or polygon block: its capacities. */
typedef struct vector_parse {
    sg_scene_vector *v;
    int cap_points, cap_curves, cap_locs;
} vector_parse;

/* points = "[" NUM NUM { "," NUM NUM } "]": x z pairs, terrain-local m;
 * each `points` adds a curve */
static bool vector_points(parser *ps, vector_parse *vp, sg_loc kloc)
{
    sg_scene_vector *v = vp->v;
    sg_token *open = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_LBRACK, "'['"))
        return false;
    int n = 2 * v->npoints;      /* doubles pushed */
    while (ps_cur(ps)->kind != SG_TK_RBRACK) {
        double xz[2];
        if (!parse_numbers(ps, xz, 2))
            return false;
        if (n < 2 * SPLAT_MAX_VECTOR_POINTS + 2) {   /* sg_scene_check says when over */
            SG_PUSH(ps->a, v->points, n, vp->cap_points)[0] = xz[0];
            SG_PUSH(ps->a, v->points, n, vp->cap_points)[0] = xz[1];
            v->npoints = n / 2;
        }
        if (!ps_accept(ps, SG_TK_COMMA))
            break;
    }
    if (ps_cur(ps)->kind != SG_TK_RBRACK) {
        if (ps_cur(ps)->kind == SG_TK_EOF)
            sg_error(ps->d, ps_loc_of(ps, open), SG_E_UNTERMINATED, "'['", open->line);
        else
            ps_expected(ps, "',' or ']'");
        return false;
    }
    ps_next(ps);
    int c = v->ncurves;
    *SG_PUSH(ps->a, v->curve_end, v->ncurves, vp->cap_curves) = v->npoints;
    *SG_PUSH(ps->a, v->curve_loc, c, vp->cap_locs) = kloc;
    if (v->points_loc.line == 0)
        v->points_loc = kloc;
    return true;
}

/* vector_stmt = "points" "=" "[" ... "]" | "width" "=" NUM
 *             | "falloff" "=" NUM | "profile" "=" ("linear" | "smoothstep") */
static bool vector_stmt(parser *ps, void *user)
{
    vector_parse *vp = user;
    sg_scene_vector *v = vp->v;
    sg_token *key = ps_cur(ps);
    sg_loc kloc = ps_loc_of(ps, key);
    bool spline = v->kind == SPLAT_VEC_SPLINE;
    const char *keys = spline ? "'points', 'width', 'falloff', 'profile' or '}'"
                              : "'points', 'falloff', 'profile' or '}'";
    bool ok;
    if (key->kind == SG_TK_IDENT && ps_is_kw(key, "points")) {
        ps_next(ps);
        ok = ps_expect(ps, SG_TK_EQ, "'='") && vector_points(ps, vp, kloc);
    } else if (key->kind == SG_TK_IDENT && spline && ps_is_kw(key, "width")) {
        ps_next(ps);
        v->width_loc = kloc;
        ok = ps_expect(ps, SG_TK_EQ, "'='") && ps_number(ps, &v->width);
    } else if (key->kind == SG_TK_IDENT && ps_is_kw(key, "falloff")) {
        ps_next(ps);
        v->falloff_loc = kloc;
        ok = ps_expect(ps, SG_TK_EQ, "'='") && ps_number(ps, &v->falloff);
    } else if (key->kind == SG_TK_IDENT && ps_is_kw(key, "profile")) {
        ps_next(ps);
        v->profile_loc = kloc;
        ok = ps_expect(ps, SG_TK_EQ, "'='");
        sg_token *p = ps_cur(ps);
        if (ok && !ps_expect(ps, SG_TK_IDENT, "'linear' or 'smoothstep'"))
            return false;
        if (ok)
            v->profile = ps_is_kw(p, "linear") ? SPLAT_VEC_LINEAR
                       : ps_is_kw(p, "smoothstep") ? SPLAT_VEC_SMOOTHSTEP : -1;
        if (ok && v->profile < 0)
            v->profile_loc = ps_loc_of(ps, p);
    } else {
        ps_expected(ps, keys);
        static const char *const sk[] = { "points", "width", "falloff", "profile", NULL };
        static const char *const pk[] = { "points", "falloff", "profile", NULL };
        if (key->kind == SG_TK_IDENT)
            ps_hint_key(ps, key, spline ? sk : pk);
        return false;
    }
    if (ok)
        ps_accept(ps, SG_TK_COMMA);
    return ok;
}

/* spline NAME "{" { vector_stmt } "}" | polygon NAME "{" ... "}", after
 * the keyword */
static bool vector_decl(parser *ps, scene_parse *sp, int kind)
{
    sg_scene *sc = sp->sc;
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, kind == SPLAT_VEC_SPLINE ? "a spline name" : "a polygon name"))
        return false;
    sg_scene_vector *v = SG_PUSH(ps->a, sc->vectors, sc->nvectors, sp->cap_vectors);
    memset(v, 0, sizeof *v);
    v->name = ps_tok_text(ps, name);
    v->loc = ps_loc_of(ps, name);
    v->kind = kind;
    v->profile = SPLAT_VEC_SMOOTHSTEP;
    if (ps_cur(ps)->kind != SG_TK_LBRACE) {
        ps_expected(ps, "'{'");
        return false;
    }
    vector_parse vp = { .v = v };
    ps_block(ps, kind == SPLAT_VEC_SPLINE ? "block of spline" : "block of polygon",
                vector_stmt, &vp);
    return true;
}

/* heightfield = "FILE": the format from the extension */
static bool heightfield_value(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *file = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_STRING, "a file name in quotes"))
        return false;
    sc->heightfield = scene_path(ps, file->str);
    sc->heightfield_loc = ps_loc_of(ps, file);
    const char *dot = strrchr(file->str, '.');
    if (dot && !strcmp(dot, ".png"))
        sc->hf_format = SG_HF_PNG;
    else if (dot && (!strcmp(dot, ".r16") || !strcmp(dot, ".raw")))
        sc->hf_format = SG_HF_R16;
    else
        sc->hf_format = SG_HF_GDAL;   /* .tif, .hgt, .asc, …: raster.c */
    return true;
}

/* materials = "[" [ IDENT { "," IDENT } ] "]", after "=".  A second
 * `materials =` replaces the first, as every setting does (both lists
 * keep their capacity: found by fuzz_parse). */
static bool materials_list(parser *ps, scene_parse *sp)
{
    sg_scene *sc = sp->sc;
    sg_token *open = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_LBRACK, "'['"))
        return false;
    sc->nmaterials = 0;
    if (ps_accept(ps, SG_TK_RBRACK))
        return true;
    do {
        sg_token *m = ps_cur(ps);
        if (!ps_expect(ps, SG_TK_IDENT, "a material name"))
            return false;
        int n = sc->nmaterials;
        *SG_PUSH(ps->a, sc->materials, sc->nmaterials, sp->cap_materials) = ps_tok_text(ps, m);
        *SG_PUSH(ps->a, sc->material_locs, n, sp->cap_material_locs) = ps_loc_of(ps, m);
    } while (ps_accept(ps, SG_TK_COMMA));
    if (ps_cur(ps)->kind != SG_TK_RBRACK) {
        if (ps_cur(ps)->kind == SG_TK_EOF)
            sg_error(ps->d, ps_loc_of(ps, open), SG_E_UNTERMINATED, "'['", open->line);
        else
            ps_expected(ps, "',' or ']'");
        return false;
    }
    ps_next(ps);
    return true;
}

/* scene_stmt = "heightfield" "=" STRING | "heightfield_size" "=" NUM NUM
 *            | "size" "=" NUM NUM | "max_height" "=" NUM
 *            | "height_offset" "=" NUM | "cell" "=" NUM
 *            | "materials" "=" "[" IDENT { "," IDENT } "]"
 *            | "compositor" "=" IDENT
 *            | "painted" IDENT "=" STRING [painted_opts]
 *            | ("spline" | "polygon") IDENT "{" { vector_stmt } "}"
 *            | destruction | camera */
static bool scene_stmt(parser *ps, void *user)
{
    scene_parse *sp = user;
    sg_scene *sc = sp->sc;
    sg_token *key = ps_cur(ps);
    sg_loc kloc = ps_loc_of(ps, key);
    if (key->kind != SG_TK_IDENT) {
        ps_expected(ps, "a scene setting or '}'");
        return false;
    }
    if (ps_is_kw(key, "destruction")) {
        ps_next(ps);
        sub_block b = { sp, NULL };
        sc->has_destruction = true;
        sc->destruction_loc = kloc;
        ps_block(ps, "block of destruction", sub_stmt, &b);
        return true;
    }
    if (ps_is_kw(key, "light")) {
        ps_next(ps);
        sc->has_light = true;
        sc->light_loc = kloc;
        ps_block(ps, "block of light", light_stmt, &sc->light);
        return true;
    }
    if (ps_is_kw(key, "camera")) {
        ps_next(ps);
        return camera_decl(ps, sp);
    }
    if (ps_is_kw(key, "painted")) {
        ps_next(ps);
        return painted_decl(ps, sp);
    }
    if (ps_is_kw(key, "spline") || ps_is_kw(key, "polygon")) {
        ps_next(ps);
        return vector_decl(ps, sp, ps_is_kw(key, "spline") ? SPLAT_VEC_SPLINE : SPLAT_VEC_POLYGON);
    }
    ps_next(ps);
    if (!ps_expect(ps, SG_TK_EQ, "'='"))
        return false;
    if (ps_is_kw(key, "heightfield"))
        return heightfield_value(ps, sp);
    if (ps_is_kw(key, "heightfield_size")) {
        double wh[2];
        if (!parse_numbers(ps, wh, 2))
            return false;
        bool whole = wh[0] >= 1 && wh[1] >= 1 && wh[0] <= INT_MAX && wh[1] <= INT_MAX &&
                     wh[0] == (int)wh[0] && wh[1] == (int)wh[1];
        sc->hf_width = whole ? (int)wh[0] : -1;
        sc->hf_height = whole ? (int)wh[1] : -1;
        sc->hf_size_loc = kloc;
        return true;
    }
    if (ps_is_kw(key, "size")) {
        if (!parse_numbers(ps, sc->size, 2))
            return false;
        sc->size_loc = kloc;
        return true;
    }
    if (ps_is_kw(key, "max_height")) {
        if (!ps_number(ps, &sc->max_height))
            return false;
        sc->max_height_loc = kloc;
        return true;
    }
    if (ps_is_kw(key, "height_offset")) {
        sc->height_offset_loc = kloc;
        return ps_number(ps, &sc->height_offset);
    }
    if (ps_is_kw(key, "cell")) {
        double c;
        if (!ps_number(ps, &c))
            return false;
        sc->cell_texels_loc = kloc;
        sc->cell_texels = c >= 1 && c <= 65536 && c == (int)c ? (int)c : -1;
        return true;
    }
    if (ps_is_kw(key, "compositor")) {
        sg_token *name = ps_cur(ps);
        if (!ps_expect(ps, SG_TK_IDENT, "a compositor shader name"))
            return false;
        sc->compositor = ps_tok_text(ps, name);
        sc->compositor_loc = ps_loc_of(ps, name);
        return true;
    }
    if (ps_is_kw(key, "materials")) {
        sc->materials_loc = kloc;
        return materials_list(ps, sp);
    }
    char buf[96];
    sg_error(ps->d, kloc, SG_E_SYNTAX,
             "a scene setting (heightfield, heightfield_size, size, max_height, "
             "height_offset, materials, compositor, painted, spline, polygon, destruction, "
             "cell, camera, light)",
             sg_tok_describe(key, buf, sizeof buf));
    ps_hint_key(ps, key, sg_scene_keys);
    return false;
}

/* scene = "scene" IDENT "{" { scene_stmt } "}" */
bool ps_scene(parser *ps)
{
    ps_next(ps);
    sg_token *name = ps_cur(ps);
    if (!ps_expect(ps, SG_TK_IDENT, "a scene name"))
        return false;
    sg_scene *sc = sg_alloc(ps->a, sizeof *sc);
    sc->name = ps_tok_text(ps, name);
    sc->loc = ps_loc_of(ps, name);
    sc->compositor = "linear_alpha";
    sc->compositor_loc = sc->loc;
    sc->cell_texels = 32;
    sc->cell_texels_loc = sc->loc;
    sc->destruction_cell = 16;
    scene_parse sp = { .sc = sc };
    char what[160];
    snprintf(what, sizeof what, "block of scene '%s'", sc->name);
    ps_block(ps, sg_strdup(ps->a, what), scene_stmt, &sp);

    sg_scene_check(sc, ps->d);
    if (ps->fi == 0) {
        if (ps->p->scene) {
            sg_error(ps->d, sc->loc, SG_E_DUPLICATE, "scene", sc->name,
                     ps->p->scene->loc.file, ps->p->scene->loc.line, ps->p->scene->loc.col);
        } else {
            ps->p->scene = sc;
        }
    }
    return true;
}
