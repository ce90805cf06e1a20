/* parse_undergrowth.c — a material's `undergrowth MESH { settings }`
 * blocks: each setting checked against its range with a "did you mean"
 * for unknown keys, the mesh (built-in or an OBJ file beside the scene)
 * and its texture checked as they are parsed, so a bad file is reported at
 * the line that names it. */
#include "mesh.h"
#include "parse.h"
#include "sg_internal.h"
#include "util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

const char *const sg_destruction_keys[] = { "origin", "size", "cell", NULL };

enum { UG_NKEYS = 13 };
#define UG_KEY_LIST "density, scale, align, blend, color, root_blend, lighting, cutout, " \
                    "wind, wind_dir, gust, shadow, texture"

typedef struct ug_parse {
    sg_undergrowth *u;
    sg_loc          seen[UG_NKEYS];   /* where each key was set (line 0: not yet) */
} ug_parse;

/* A number in [lo, hi] (lo excluded if open_lo) for `key`, or SETTING. */
static bool ug_number(parser *ps, const char *key, double lo, double hi, bool open_lo,
                      double *x)
{
    sg_loc at = ps_loc_of(ps, ps_cur(ps));
    if (!ps_number(ps, x))
        return false;
    if ((open_lo ? *x > lo : *x >= lo) && *x <= hi)
        return true;
    sg_errorf(ps->d, at, SG_E_SETTING, "'%s' must be in %c%g, %g], found %g", key,
              open_lo ? '(' : '[', lo, hi, *x);
    return true;   /* well-formed: parsing goes on */
}

/* One of two keywords for `key` (*x = whether the first), or SETTING. */
static bool ug_choice(parser *ps, const char *key, const char *yes, const char *no, bool *x)
{
    sg_token *vt = ps_cur(ps);
    char buf[96];
    if (ps_is_kw(vt, yes) || ps_is_kw(vt, no)) {
        *x = ps_is_kw(vt, yes);
    } else {
        if (vt->kind != SG_TK_IDENT && vt->kind != SG_TK_NUMBER && vt->kind != SG_TK_STRING) {
            snprintf(buf, sizeof buf, "%s or %s", yes, no);
            ps_expected(ps, buf);
            return false;
        }
        sg_errorf(ps->d, ps_loc_of(ps, vt), SG_E_SETTING, "'%s' must be %s or %s, found %s", key,
                  yes, no, sg_tok_describe(vt, buf, sizeof buf));
    }
    ps_next(ps);
    return true;
}

/* Check an undergrowth texture now, so its errors are located at the
 * string: readable, an image, 1 to SPLAT_MAX_UG_TEXTURE texels a side. */
static void check_ug_texture(parser *ps, const char *path, sg_loc at)
{
    char why[160];
    FILE *f = splat_input_fopen(path, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f) {
        sg_error(ps->d, at, SG_E_IO, path, why);
        return;
    }
    int w, h, comp;
    if (!stbi_info_from_file(f, &w, &h, &comp))
        sg_error(ps->d, at, SG_E_IO, path, "not an image stb_image reads");
    else if (w < 1 || h < 1 || w > SPLAT_MAX_UG_TEXTURE || h > SPLAT_MAX_UG_TEXTURE)
        sg_errorf(ps->d, at, SG_E_OVER_LIMIT, "texture '%s' is %d x %d; an undergrowth texture "
                  "may have at most %d texels a side", path, w, h, SPLAT_MAX_UG_TEXTURE);
    fclose(f);
}

/* An unknown setting: reported with a "did you mean", then its value
 * skipped (vec3(…) whole), then to ',', '}' or the next line. */
static void ug_unknown(parser *ps, sg_token *key)
{
    sg_errorf(ps->d, ps_loc_of(ps, key), SG_E_BAD_OPTION, "unknown undergrowth setting '%.*s' "
              "(expected " UG_KEY_LIST ")", key->len, key->start);
    ps_hint_key(ps, key, sg_ug_keys);
    ps_next(ps);
    sg_value v;
    if (ps_accept(ps, SG_TK_EQ) && ps_cur(ps)->kind != SG_TK_RBRACE)
        ps_value(ps, &v);
    while (ps_cur(ps)->kind != SG_TK_EOF && ps_cur(ps)->kind != SG_TK_RBRACE &&
           ps_cur(ps)->kind != SG_TK_COMMA && ps_cur(ps)->line == key->line)
        ps_next(ps);
    ps_accept(ps, SG_TK_COMMA);
}

/* cutout = "none" | "frond" | "alpha" */
static bool ug_cutout(parser *ps, sg_undergrowth *u, sg_loc vloc)
{
    sg_token *vt = ps_cur(ps);
    char buf[96];
    if (ps_is_kw(vt, "none") || ps_is_kw(vt, "frond") || ps_is_kw(vt, "alpha")) {
        u->cutout = ps_is_kw(vt, "frond") ? SG_UG_CUT_FROND
                  : ps_is_kw(vt, "alpha") ? SG_UG_CUT_ALPHA : SG_UG_CUT_NONE;
    } else {
        if (vt->kind != SG_TK_IDENT && vt->kind != SG_TK_NUMBER && vt->kind != SG_TK_STRING) {
            ps_expected(ps, "none, frond or alpha");
            return false;
        }
        sg_errorf(ps->d, vloc, SG_E_SETTING, "'cutout' must be none, frond or alpha, "
                  "found %s", sg_tok_describe(vt, buf, sizeof buf));
    }
    ps_next(ps);
    return true;
}

/* wind_dir = NUM NUM, a direction in the ground plane (normalised) */
static bool ug_wind_dir(parser *ps, sg_undergrowth *u, sg_loc vloc)
{
    double x, z;
    if (!ps_number(ps, &x) || !ps_number(ps, &z))
        return false;
    double len = hypot(x, z);
    if (!(len > 1e-6 && len <= 1e6)) {
        sg_errorf(ps->d, vloc, SG_E_SETTING, "'wind_dir' must be X Z, a direction in the "
                  "ground plane (not 0 0, each at most 1e6), found %g %g", x, z);
        return true;
    }
    u->wind_dir[0] = x / len;
    u->wind_dir[1] = z / len;
    return true;
}

/* color = vec3(r, g, b), linear, each in [0, 1] */
static bool ug_color(parser *ps, sg_undergrowth *u, sg_loc vloc)
{
    sg_value v;
    if (!ps_value(ps, &v))
        return false;
    if (v.kind != SG_V_VEC || v.width != 3) {
        sg_errorf(ps->d, vloc, SG_E_SETTING, "'color' must be vec3(r, g, b), "
                  "linear, each in [0, 1]");
        return true;
    }
    if (!(v.num[0] >= 0 && v.num[0] <= 1 && v.num[1] >= 0 && v.num[1] <= 1 &&
          v.num[2] >= 0 && v.num[2] <= 1))
        sg_errorf(ps->d, vloc, SG_E_SETTING, "'color' components must be in [0, 1] "
                  "(linear), found vec3(%g, %g, %g)", v.num[0], v.num[1], v.num[2]);
    memcpy(u->color, v.num, sizeof u->color);
    return true;
}

/* ug_setting = "density" "=" NUM | "scale" "=" NUM [ NUM ]
 *            | "align" "=" ("normal" | "upright") | "blend" "=" NUM
 *            | "color" "=" "vec3" "(" NUM "," NUM "," NUM ")"
 *            | "root_blend" "=" NUM | "lighting" "=" ("terrain" | "mesh")
 *            | "cutout" "=" ("frond" | "alpha" | "none") | "wind" "=" NUM
 *            | "wind_dir" "=" NUM NUM | "gust" "=" NUM | "shadow" "=" NUM
 *            | "texture" "=" STRING */
static bool ug_stmt(parser *ps, void *user)
{
    ug_parse *up = user;
    sg_undergrowth *u = up->u;
    sg_token *key = ps_cur(ps);
    if (key->kind != SG_TK_IDENT) {
        ps_expected(ps, "an undergrowth setting (" UG_KEY_LIST ") or '}'");
        return false;
    }
    sg_loc kloc = ps_loc_of(ps, key);
    int k = 0;
    while (k < UG_NKEYS && !ps_is_kw(key, sg_ug_keys[k]))
        k++;
    if (k == UG_NKEYS) {
        ug_unknown(ps, key);
        return true;
    }
    if (up->seen[k].line)
        sg_error(ps->d, kloc, SG_E_DUPLICATE, "undergrowth setting", sg_ug_keys[k],
                 up->seen[k].file, up->seen[k].line, up->seen[k].col);
    else
        up->seen[k] = kloc;
    ps_next(ps);
    if (!ps_expect(ps, SG_TK_EQ, "'='"))
        return false;
    sg_loc vloc = ps_loc_of(ps, ps_cur(ps));
    switch (k) {
    case 0:
        if (!ug_number(ps, "density", 0, 64, true, &u->density))
            return false;
        break;
    case 1:
        if (!ps_number(ps, &u->scale[0]))
            return false;
        u->scale[1] = u->scale[0];
        if (ps_cur(ps)->kind == SG_TK_NUMBER)
            u->scale[1] = ps_next(ps)->num;
        if (!(u->scale[0] > 0 && u->scale[0] <= u->scale[1] && u->scale[1] <= 100))
            sg_errorf(ps->d, vloc, SG_E_SETTING, "'scale' must be LO HI with 0 < LO <= HI "
                      "<= 100, found %g %g", u->scale[0], u->scale[1]);
        break;
    case 2:
        if (!ug_choice(ps, "align", "normal", "upright", &u->align_normal))
            return false;
        break;
    case 3:
        if (!ug_number(ps, "blend", 0, 1, false, &u->blend))
            return false;
        break;
    case 5:
        if (!ug_number(ps, "root_blend", 0, 1, false, &u->root_blend))
            return false;
        break;
    case 6:
        if (!ug_choice(ps, "lighting", "terrain", "mesh", &u->light_terrain))
            return false;
        break;
    case 7:
        if (!ug_cutout(ps, u, vloc))
            return false;
        break;
    case 8:
        if (!ug_number(ps, "wind", 0, SPLAT_MAX_UG_WIND, false, &u->wind))
            return false;
        break;
    case 9:
        if (!ug_wind_dir(ps, u, vloc))
            return false;
        break;
    case 10:
        if (!ug_number(ps, "gust", 0, 1, false, &u->gust))
            return false;
        break;
    case 11:
        if (!ug_number(ps, "shadow", 0, 1, false, &u->shadow))
            return false;
        break;
    case 12: {
        sg_token *vt = ps_cur(ps);
        if (vt->kind != SG_TK_STRING) {
            ps_expected(ps, "an image file in quotes");
            return false;
        }
        char *path = splat_path_join(ps->f->dir, vt->str);
        u->texture = sg_strdup(ps->a, path);
        free(path);
        check_ug_texture(ps, u->texture, vloc);
        ps_next(ps);
        break;
    }
    case 4:
        if (!ug_color(ps, u, vloc))
            return false;
        break;
    }
    ps_accept(ps, SG_TK_COMMA);
    return true;
}

/* Load and check an undergrowth block's OBJ file now, so its errors are
 * located at the string (the pack writer loads it again). */
static void check_obj(parser *ps, const char *path, sg_loc at)
{
    splat_mesh m;
    char *err = NULL;
    if (!splat_mesh_obj(path, &m, &err)) {
        sg_error(ps->d, at, SG_E_IO, path, err);
        free(err);
        return;
    }
    if (m.nv > SPLAT_MAX_MESH_VERTICES || m.nidx > SPLAT_MAX_MESH_INDICES)
        sg_errorf(ps->d, at, SG_E_OVER_LIMIT, "mesh '%s' has %u vertices and %u indices; "
                  "an undergrowth mesh may have at most %d and %d", path, m.nv, m.nidx,
                  SPLAT_MAX_MESH_VERTICES, SPLAT_MAX_MESH_INDICES);
    /* meshes.bin's floats as the runtime's loader bounds them (abi.h) */
    for (uint32_t i = 0; i < m.nv; i++) {
        const splat_mesh_vertex *x = &m.v[i];
        const float v[5] = { x->pos[0], x->pos[1], x->pos[2], x->uv[0], x->uv[1] };
        for (int k = 0; k < 5; k++)
            if (!(fabsf(v[k]) <= (float)SPLAT_MAX_MESH_VALUE)) {
                sg_errorf(ps->d, at, SG_E_OVER_LIMIT, "mesh '%s' has a vertex %s of %g; the "
                          "pack limit is %g either way (metres at scale 1, and uv)", path,
                          k < 3 ? "coordinate" : "uv", (double)v[k], SPLAT_MAX_MESH_VALUE);
                splat_mesh_free(&m);
                return;
            }
    }
    splat_mesh_free(&m);
}

/* undergrowth = "undergrowth" (IDENT | STRING) [ "{" { ug_setting [","] } "}" ]
 * IDENT names a built-in mesh (mesh.h), STRING an OBJ file relative to
 * this file's folder (as a texture's file). */
bool ps_undergrowth(parser *ps, sg_shader *s)
{
    static const double colors[][3] = {      /* per built-in mesh, then OBJ */
        { 0.16, 0.30, 0.06 }, { 0.12, 0.26, 0.05 }, { 0.35, 0.33, 0.30 }, { 0.5, 0.5, 0.5 },
    };
    /* per built-in mesh, then OBJ: lit with the terrain normal, cut out,
     * contact shadow (defaults: each can be set in the block) */
    static const bool terrain_lit[] = { true, true, false, false };
    static const int cut[] = { SG_UG_CUT_NONE, SG_UG_CUT_FROND, SG_UG_CUT_NONE,
                               SG_UG_CUT_NONE };
    static const double shadows[] = { 0.35, 0.3, 0.5, 0.4 };
    /* blend at the tip and at the root: a stone keeps its own colour and
     * takes the ground's only at its foot */
    static const double blends[][2] = { { 0.5, -1 }, { 0.5, -1 }, { 0.15, 0.5 }, { 0.5, -1 } };
    sg_undergrowth u = { .density = 1, .scale = { 1, 1 }, .wind_dir = { 1, 0 }, .gust = 0.5 };
    u.loc = ps_loc_of(ps, ps_next(ps));
    bool seen_color = false;
    sg_token *m = ps_cur(ps);
    bool known = true;
    int kind = 0;
    if (m->kind == SG_TK_IDENT) {
        while (splat_mesh_builtins[kind] && !ps_is_kw(m, splat_mesh_builtins[kind]))
            kind++;
        if (splat_mesh_builtins[kind]) {
            u.mesh = splat_mesh_builtins[kind];
        } else {
            sg_errorf(ps->d, ps_loc_of(ps, m), SG_E_BAD_OPTION, "unknown undergrowth mesh "
                      "'%.*s' (built-in meshes: grass, plant, stone; or an OBJ file in quotes)",
                      m->len, m->start);
            known = false;
        }
    } else if (m->kind == SG_TK_STRING) {
        kind = (int)(sizeof colors / sizeof colors[0]) - 1;
        char *path = splat_path_join(ps->f->dir, m->str);
        u.obj = sg_strdup(ps->a, path);
        free(path);
        check_obj(ps, u.obj, ps_loc_of(ps, m));
    } else {
        ps_expected(ps, "a mesh (grass, plant, stone or an OBJ file in quotes)");
        return false;
    }
    ps_next(ps);
    memcpy(u.color, colors[kind], sizeof u.color);
    u.light_terrain = terrain_lit[kind];
    u.cutout = cut[kind];
    u.shadow = shadows[kind];
    u.blend = blends[kind][0];
    u.root_blend = blends[kind][1];
    if (ps_cur(ps)->kind == SG_TK_LBRACE) {
        ug_parse up = { &u, { { 0 } } };
        char what[160];
        snprintf(what, sizeof what, "block of undergrowth '%.*s'", m->len, m->start);
        ps_block_in(ps, what, ug_stmt, &up, true);
        seen_color = up.seen[4].line != 0;
        if (u.cutout == SG_UG_CUT_ALPHA && !u.texture)
            sg_errorf(ps->d, up.seen[7], SG_E_SETTING, "'cutout = alpha' needs a texture "
                      "(texture = \"file.png\") whose alpha cuts the mesh");
    }
    if (u.root_blend < 0)   /* not set: as the tip, unless a default of its own */
        u.root_blend = u.blend;
    if (u.texture && !seen_color)   /* the texture's own colour */
        u.color[0] = u.color[1] = u.color[2] = 1.0;
    if (!known)
        return true;
    if (s->nug == SG_MAX_UNDERGROWTH) {
        sg_errorf(ps->d, u.loc, SG_E_OVER_LIMIT, "material '%s' has more than %d "
                  "undergrowth blocks", s->name, SG_MAX_UNDERGROWTH);
        return true;
    }
    if (s->nug == 0 && ps->p->nug_materials == SG_MAX_UG_MATERIALS) {
        sg_errorf(ps->d, u.loc, SG_E_OVER_LIMIT, "more than %d materials have undergrowth "
                  "(the undergrowth masks hold %d weights)", SG_MAX_UG_MATERIALS,
                  SG_MAX_UG_MATERIALS);
        return true;
    }
    if (s->nug == 0)
        ps->p->nug_materials++;
    *SG_PUSH(ps->a, s->ug, s->nug, s->capug) = u;
    return true;
}
