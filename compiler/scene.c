/* scene.c — a loaded scene: the scene file and its imports parsed and
 * checked, the heightfield and painted rasters loaded, every material of
 * the stack lowered into one shared IR.
 *
 * Pipeline (splat_scene_load):
 *   sg_load(scene.sg)            parse, resolve imports, type-check
 *   check_materials              the stack's names against the program
 *   splat_terrain_load           the heightfield (terrain.c)
 *   load_painted                 8-bit greyscale rasters, heightfield size
 *   lower_materials              "<name>.mask", ".albedo", … roots in s->ir
 *
 * s->ir.painted[i] is the scene's painted mask i (registered first, in the
 * scene's order), so a painted index is the same everywhere: the scene, the
 * IR, the analysis and the pack's painted layers.
 *
 * Imports are searched relative to the importing file, then the scene's
 * folder, then the caller's search paths; without any, splat_search_path's
 * (search.c: $SPLATC_PATH, ".", the project root, the installed nodes).
 */
#include "compose.h"
#include "abi.h"
#include "util.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <stb_image.h>

/* ---- checks ------------------------------------------------------------- */



/* What sg_scene_check (scene_check.c, at parse time) cannot see: the
 * material names against the program. */
static void check_materials(sg_program *p, const sg_scene *sc, sg_diags *d)
{
    for (int i = 0; i < sc->nmaterials; i++) {
        sg_loc loc = sc->material_locs ? sg_loc_or(sc->material_locs[i], sc->loc)
                                       : sc->loc;
        if (sg_material_find(p, sc->materials[i]) < 0) {
            sg_error(d, loc, SG_E_UNKNOWN_NAME, sc->materials[i]);
            sg_suggest sg;
            sg_suggest_init(&sg, sc->materials[i]);
            for (int k = 0; k < sg_material_count(p); k++)
                sg_suggest_offer(&sg, sg_material_name(p, k));
            sg_hint_suggest(d, sg_suggest_best(&sg));
            continue;
        }
        for (int j = 0; j < i; j++) {
            if (strcmp(sc->materials[i], sc->materials[j]) == 0) {
                sg_loc first = sc->material_locs ? sc->material_locs[j] : sc->loc;
                sg_error(d, loc, SG_E_DUPLICATE, "material in the stack",
                         sc->materials[i], first.file, first.line, first.col);
                break;
            }
        }
    }
}

/* The stack's texture files, before any work: each readable and an image,
 * else an error at the string that names it (in whichever file that is). */
static bool check_textures(const splat_scene *s, sg_diags *d)
{
    bool ok = true;
    for (int i = 0; i < s->ir.ntextures; i++) {
        const char *file = s->ir.textures[i].file;
        bool first = true;
        for (int k = 0; k < i; k++)
            first &= strcmp(s->ir.textures[k].file, file) != 0;
        if (!first)
            continue;
        sg_loc loc = sg_loc_or(sg_texture_file_loc(s->prog, file), s->desc->loc);
        struct stat st;
        int w, h, comp;
        if (stat(file, &st) != 0) {
            sg_error(d, loc, SG_E_IO, file, strerror(errno));
            ok = false;
        } else if (!S_ISREG(st.st_mode) || !stbi_info(file, &w, &h, &comp)) {
            sg_error(d, loc, SG_E_IO, file, "not an image (PNG, JPEG, TGA or BMP)");
            ok = false;
        }
    }
    return ok;
}

/* ---- rasters ------------------------------------------------------------ */

static bool is_png(const char *file)
{
    const char *dot = strrchr(file, '.');
    return dot && strcmp(dot, ".png") == 0;
}

/* An 8-bit greyscale raster of exactly *w x *h texels (any size, returned
 * in *w, *h, when *w is 0), or NULL (error at loc): a PNG through
 * stb_image, anything else through GDAL (raster.c). */
static uint8_t *load_mask(const char *name, const char *file, int *pw, int *ph,
                          sg_loc loc, sg_diags *d)
{
    bool any = *pw == 0;
    int w = *pw, h = *ph;
    if (!is_png(file)) {
        char what[160];
        snprintf(what, sizeof what, "painted mask '%s'", name);
        int fw = 0, fh = 0;
        uint8_t *px = splat_raster_mask(what, file, &fw, &fh, loc, d);
        if (px && any) {
            *pw = fw;
            *ph = fh;
        } else if (px && (fw != w || fh != h)) {
            sg_errorf(d, loc, SG_E_RASTER, "painted mask '%s' ('%s') is %d x %d texels; the "
                        "heightfield is %d x %d", name, file, fw, fh, w, h);
            free(px);
            px = NULL;
        }
        return px;
    }
    int fw, fh, comp;
    if (!stbi_info(file, &fw, &fh, &comp)) {
        FILE *f = fopen(file, "rb");
        if (!f) {
            sg_error(d, loc, SG_E_IO, file, strerror(errno));
        } else {
            fclose(f);
            sg_error(d, loc, SG_E_IO, file, "not a PNG image");
        }
        return NULL;
    }
    if (comp != 1 || stbi_is_16_bit(file)) {
        sg_errorf(d, loc, SG_E_RASTER, "painted mask '%s' ('%s') must be an 8-bit "
                    "greyscale image, found %d channels of %d bits", name, file,
                    comp, stbi_is_16_bit(file) ? 16 : 8);
        return NULL;
    }
    if (any) {
        *pw = w = fw;
        *ph = h = fh;
    } else if (fw != w || fh != h) {
        sg_errorf(d, loc, SG_E_RASTER, "painted mask '%s' ('%s') is %d x %d texels; the "
                    "heightfield is %d x %d (or place it: { origin = X Z, size = W H })",
                    name, file, fw, fh, w, h);
        return NULL;
    }
    if (!splat_raster_check_size("painted mask", file, fw, fh, loc, d))
        return NULL;
    int lw, lh, lc;
    uint8_t *px = stbi_load(file, &lw, &lh, &lc, 1);
    if (!px) {
        /* the header read, the data did not */
        char why[160];
        snprintf(why, sizeof why, "truncated or corrupt PNG (stb_image: %s)",
                 stbi_failure_reason());
        sg_error(d, loc, SG_E_IO, file, why);
        return NULL;
    }
    /* Own the pixels with malloc so splat_scene_free needs no stb. */
    size_t n = (size_t)w * (size_t)h;
    uint8_t *out = malloc(n);
    if (out) memcpy(out, px, n);
    else sg_error(d, loc, SG_E_OUT_OF_MEMORY, "painted mask does not fit in memory");
    stbi_image_free(px);
    return out;
}

/* The holes mask (texels > 127) joins GDAL's nodata in s->terrain.holes;
 * then the hole texels get heights from their neighbours. */
static bool load_holes(splat_scene *s, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    splat_terrain *t = &s->terrain;
    sg_loc loc = sg_loc_or(sc->holes_loc, sc->loc);
    if (sc->holes) {
        int w = t->width, h = t->height;
        uint8_t *m = load_mask("holes", sc->holes, &w, &h, loc, d);
        if (!m) return false;
        size_t n = (size_t)t->width * (size_t)t->height;
        for (size_t i = 0; i < n; i++)
            m[i] = m[i] > 127 || (t->holes && t->holes[i]);
        free(t->holes);
        t->holes = m;
    }
    if (!splat_terrain_fill_holes(t)) {
        sg_error(d, loc, SG_E_OUT_OF_MEMORY, "the terrain's holes do not fit in memory");
        return false;
    }
    return true;
}

static bool load_painted(splat_scene *s, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    if (sc->npainted == 0) return true;
    s->painted = calloc((size_t)sc->npainted, sizeof *s->painted);
    s->painted_size = calloc((size_t)sc->npainted, sizeof *s->painted_size);
    if (!s->painted || !s->painted_size) {
        sg_error(d, sc->loc, SG_E_OUT_OF_MEMORY, "painted masks do not fit in memory");
        return false;
    }
    bool ok = true;
    for (int i = 0; i < sc->npainted; i++) {
        const sg_scene_painted *pm = &sc->painted[i];
        int *wh = s->painted_size[i];
        bool placed = pm->place_loc.line > 0;
        wh[0] = placed ? 0 : s->terrain.width;
        wh[1] = placed ? 0 : s->terrain.height;
        s->painted[i] = load_mask(pm->name, pm->file, &wh[0], &wh[1],
                                  sg_loc_or(pm->loc, sc->loc), d);
        ok &= s->painted[i] != NULL;
    }
    return ok;
}

/* ---- materials ---------------------------------------------------------- */

static bool lower_materials(splat_scene *s, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    for (int i = 0; i < sc->npainted; i++) {
        int k = ir_add_painted(&s->ir, sc->painted[i].name);
        (void)k;   /* == i: names are unique (check_scene) */
    }
    bool ok = true;
    for (int i = 0; i < sc->nmaterials; i++) {
        int before = s->ir.npainted;
        if (!sg_lower_material(s->prog, sc->materials[i], &s->ir, d)) {
            ok = false;
            continue;
        }
        /* Painted masks first named by this material are not the scene's:
         * the error at the stack entry, a note at the material. */
        for (int k = before; k < s->ir.npainted; k++) {
            sg_loc loc = sc->material_locs ? sg_loc_or(sc->material_locs[i], sc->loc)
                                           : sc->loc;
            sg_errorf(d, loc, SG_E_UNDECLARED, "material '%s' reads painted mask '%s', which "
                        "scene '%s' does not declare (painted %s = \"FILE.png\")",
                        sc->materials[i], s->ir.painted[k].name, sc->name,
                        s->ir.painted[k].name);
            int m = sg_material_find(s->prog, sc->materials[i]);
            if (m >= 0)
                sg_note(d, sg_material_loc(s->prog, m), "material '%s' is "
                        "defined here", sc->materials[i]);
            ok = false;
        }
    }
    return ok;
}

/* ---- the scene ---------------------------------------------------------- */

bool splat_scene_load(splat_scene *s, const char *path,
                      const char *const *search_paths, sg_diags *d)
{
    memset(s, 0, sizeof *s);
    ir_init(&s->ir);
    int errors = d->nerrors;
    s->path = xstrdup(path);
    char **paths = splat_import_path(path, search_paths);

    s->prog = sg_load(path, (const char *const *)paths, d);
    if (!s->prog) {
        sg_error(d, (sg_loc){ path, 0, 0 }, SG_E_OUT_OF_MEMORY, "out of memory");
        goto fail;
    }
    if (d->nerrors > errors) goto fail;
    s->desc = sg_program_scene(s->prog);
    if (!s->desc) {
        sg_errorf(d, (sg_loc){ path, 1, 1 }, SG_E_MISSING_SETTING, "'%s' declares no scene "
                    "(scene NAME { heightfield = …, materials = […] })", path);
        goto fail;
    }
    const sg_scene *sc = s->desc;
    s->nmaterials = sc->nmaterials;
    check_materials(s->prog, sc, d);
    if (d->nerrors > errors) goto fail;

    /* 0: a GDAL raster's size comes from its geotransform */
    s->terrain.size[0] = sc->size_loc.line > 0 ? sc->size[0] : 0;
    s->terrain.size[1] = sc->size_loc.line > 0 ? sc->size[1] : 0;
    s->terrain.max_height = sc->max_height;
    s->terrain.height_offset = sc->height_offset;
    if (!splat_terrain_load(&s->terrain, sc->heightfield, sc->hf_format,
                            sc->hf_width, sc->hf_height,
                            sg_loc_or(sc->heightfield_loc, sc->loc), d))
        goto fail;
    if (sc->hf_format != SG_HF_R16 &&
        !sg_scene_cells_fit(sc, s->terrain.width, s->terrain.height, d))
        goto fail;
    if (!load_holes(s, d) || !load_painted(s, d) || !lower_materials(s, d) ||
        !check_textures(s, d) || d->nerrors > errors)
        goto fail;
    if (!splat_compositor_check(s->prog, sc->compositor ? sc->compositor : "linear_alpha",
                                sg_loc_or(sc->compositor_loc, sc->loc), d))
        goto fail;

    splat_search_path_free(paths);
    return true;
fail:
    splat_search_path_free(paths);
    splat_scene_free(s);
    return false;
}

void splat_scene_free(splat_scene *s)
{
    if (s->painted && s->desc) {
        for (int i = 0; i < s->desc->npainted; i++)
            free(s->painted[i]);
    }
    free(s->painted);
    free(s->painted_size);
    if (s->own_desc) {
        free(s->own_desc->cameras);
        free(s->own_desc);
    }
    splat_terrain_free(&s->terrain);
    ir_free(&s->ir);
    if (s->prog) sg_free(s->prog);
    free(s->path);
    memset(s, 0, sizeof *s);
}
