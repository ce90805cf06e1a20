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


/* ---- rasters ------------------------------------------------------------ */

static bool is_png(const char *file)
{
    const char *dot = strrchr(file, '.');
    return dot && strcmp(dot, ".png") == 0;
}

/* splatc's bound on the painted masks it holds (the decoded rasters: one
 * byte a texel), checked on the headers before any data is decoded:
 * eight full-size 16384^2 masks.  Placed masks that no material reads are
 * not decoded at all (load_painted). */
#define MAX_PAINTED_BYTES ((unsigned long long)2 << 30)

/* An 8-bit greyscale raster of exactly *w x *h texels (any size, returned
 * in *w, *h, when *w is 0), or NULL (error at loc): a PNG through
 * stb_image, anything else through GDAL (raster.c).  With !decode only
 * the header is read and checked (*w, *h as found) and the raster
 * returned is a single texel of 0. */
static uint8_t *load_mask(const char *name, const char *file, int *pw, int *ph,
                          bool decode, sg_loc loc, sg_diags *d)
{
    bool any = *pw == 0;
    int w = *pw, h = *ph, fw = 0, fh = 0;
    char what[160];
    snprintf(what, sizeof what, "painted mask '%s'", name);
    FILE *f = NULL;
    if (!is_png(file)) {
        if (!splat_raster_size(what, file, &fw, &fh, loc, d))
            return NULL;
    } else {
        int comp;
        bool is16;
        f = splat_png_open(what, file, &fw, &fh, &comp, &is16, loc, d);
        if (!f)
            return NULL;
        if (comp != 1 || is16) {
            fclose(f);
            sg_errorf(d, loc, SG_E_RASTER, "painted mask '%s' ('%s') must be an 8-bit "
                        "greyscale image, found %d channels of %d bits", name, file,
                        comp, is16 ? 16 : 8);
            return NULL;
        }
    }
    if (any) {
        w = fw;
        h = fh;
    } else if (fw != w || fh != h) {
        if (f)
            fclose(f);
        sg_errorf(d, loc, SG_E_RASTER, "painted mask '%s' ('%s') is %d x %d texels; the "
                    "heightfield is %d x %d (or place it: { origin = X Z, size = W H })",
                    name, file, fw, fh, w, h);
        return NULL;
    }
    *pw = w;
    *ph = h;
    if (!decode) {
        if (f)
            fclose(f);
        return xcalloc(1, 1);
    }
    size_t n = (size_t)w * (size_t)h;
    if (!f) {
        int gw = 0, gh = 0;
        uint8_t *px = splat_raster_mask(what, file, &gw, &gh, loc, d);
        if (px && (gw != w || gh != h)) {   /* changed since the probe */
            sg_error(d, loc, SG_E_IO, file, "changed while it was read");
            free(px);
            px = NULL;
        }
        return px;
    }
    int lw, lh, lc;
    uint8_t *px = stbi_load_from_file(f, &lw, &lh, &lc, 1);
    fclose(f);
    if (!px || lw != w || lh != h) {
        /* the header read, the data did not */
        char msg[160];
        snprintf(msg, sizeof msg, "truncated or corrupt PNG (stb_image: %s)",
                 stbi_failure_reason());
        sg_error(d, loc, SG_E_IO, file, msg);
        stbi_image_free(px);
        return NULL;
    }
    /* Own the pixels with malloc so splat_scene_free needs no stb. */
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
        uint8_t *m = load_mask("holes", sc->holes, &w, &h, true, loc, d);
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

/* The scene's painted masks, after the materials are lowered.  First
 * every header is read and checked; a placed mask that no material reads
 * (no OP_PAINTED node names it) stays at that: a single texel of 0 stands
 * for it in the pack.  The rest must fit MAX_PAINTED_BYTES together
 * before any is decoded. */
static bool load_painted(splat_scene *s, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    if (sc->npainted == 0) return true;
    s->painted = calloc((size_t)sc->npainted, sizeof *s->painted);
    s->painted_size = calloc((size_t)sc->npainted, sizeof *s->painted_size);
    uint8_t *decode = calloc((size_t)sc->npainted, 1);
    if (!s->painted || !s->painted_size || !decode) {
        free(decode);
        sg_error(d, sc->loc, SG_E_OUT_OF_MEMORY, "painted masks do not fit in memory");
        return false;
    }
    /* ir.painted[i] is scene mask i (lower_materials adds them first) */
    for (uint32_t id = 1; id < s->ir.nnodes; id++) {
        const ir_node *n = &s->ir.nodes[id];
        if (n->op == IR_OP_PAINTED && n->imm < (uint32_t)sc->npainted)
            decode[n->imm] = 1;
    }
    unsigned long long total = 0;
    bool ok = true;
    for (int i = 0; i < sc->npainted; i++) {       /* the headers */
        const sg_scene_painted *pm = &sc->painted[i];
        int *wh = s->painted_size[i];
        bool placed = pm->place_loc.line > 0;
        decode[i] |= !placed;
        wh[0] = placed ? 0 : s->terrain.width;
        wh[1] = placed ? 0 : s->terrain.height;
        sg_loc loc = sg_loc_or(pm->loc, sc->loc);
        s->painted[i] = load_mask(pm->name, pm->file, &wh[0], &wh[1], false, loc, d);
        if (!s->painted[i]) {
            ok = false;
            continue;
        }
        if (!decode[i]) {
            wh[0] = wh[1] = 1;
            continue;
        }
        total += (unsigned long long)wh[0] * (unsigned long long)wh[1];
        if (ok && total > MAX_PAINTED_BYTES) {
            sg_errorf(d, loc, SG_E_OVER_LIMIT, "with painted mask '%s' (%d x %d texels) the "
                      "painted masks that materials read would take %llu MiB, over "
                      "splatc's bound of %llu MiB; use fewer or smaller masks, or place "
                      "them over the area they cover", pm->name, wh[0], wh[1], total >> 20,
                      MAX_PAINTED_BYTES >> 20);
            ok = false;
        }
    }
    for (int i = 0; ok && i < sc->npainted; i++) {  /* the data */
        if (!decode[i])
            continue;
        const sg_scene_painted *pm = &sc->painted[i];
        free(s->painted[i]);
        s->painted[i] = load_mask(pm->name, pm->file, &s->painted_size[i][0],
                                  &s->painted_size[i][1], true, sg_loc_or(pm->loc, sc->loc), d);
        ok = s->painted[i] != NULL;
    }
    free(decode);
    return ok;
}

/* ---- materials ---------------------------------------------------------- */

static bool check_textures(splat_scene *s, const int *first_material, sg_diags *d);
static bool check_extent(const splat_scene *s, sg_diags *d);

static bool lower_materials(splat_scene *s, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    for (int i = 0; i < sc->npainted; i++) {
        int k = ir_add_painted(&s->ir, sc->painted[i].name);
        (void)k;   /* == i: names are unique (check_scene) */
    }
    for (int i = 0; i < sc->nvectors; i++) {   /* then the vector shapes' */
        char name[300];
        snprintf(name, sizeof name, "vector.%s", sc->vectors[i].name);
        ir_add_painted(&s->ir, name);
        snprintf(name, sizeof name, "vector.%s.across", sc->vectors[i].name);
        ir_add_painted(&s->ir, name);
    }
    bool ok = true;
    int *first_material = NULL;   /* per texture: the material that first samples it */
    for (int i = 0; i < sc->nmaterials; i++) {
        int before = s->ir.npainted, tex_before = s->ir.ntextures;
        bool lowered = sg_lower_material(s->prog, sc->materials[i], &s->ir, d);
        first_material = xrealloc(first_material, ((size_t)s->ir.ntextures + 1) *
                                                      sizeof *first_material);
        for (int k = tex_before; k < s->ir.ntextures; k++)
            first_material[k] = i;
        if (!lowered) {
            ok = false;
            continue;
        }
        /* Painted masks first named by this material are not the scene's:
         * the error at the stack entry, a note at the material.  (The
         * scene's vector shapes are registered above, both names each.) */
        for (int k = before; k < s->ir.npainted; k++) {
            sg_loc loc = sc->material_locs ? sg_loc_or(sc->material_locs[i], sc->loc)
                                           : sc->loc;
            const char *name = s->ir.painted[k].name;
            if (!strncmp(name, "vector.", 7)) {
                const char *dot = strchr(name + 7, '.');
                int n = dot ? (int)(dot - name - 7) : (int)strlen(name + 7);
                sg_errorf(d, loc, SG_E_UNDECLARED, "material '%s' reads %s, but scene '%s' "
                          "has no spline or polygon '%.*s' (spline %.*s { points = [...], "
                          "width = W })", sc->materials[i], name, sc->name, n, name + 7,
                          n, name + 7);
            } else
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
    ok = ok && check_textures(s, first_material, d);
    free(first_material);
    return ok;
}

/* ---- textures ------------------------------------------------------------ */

/* Every texture the materials sample, checked once here so that nothing
 * later (precision.c, far_atlas.c, the pack writer, the runtime) meets a
 * FIFO, a device or an image over the pack limit: a regular file within
 * SPLAT_MAX_IMAGE_BYTES, an image stb_image decodes, at most
 * SPLAT_MAX_TEXTURE texels a side (the header's size, read from the PNG
 * itself when stb_image refuses it).  Errors at the `texture`
 * declaration, or at the scene's material that samples an inline one. */
static bool check_textures(splat_scene *s, const int *first_material, sg_diags *d)
{
    const sg_scene *sc = s->desc;
    bool ok = true;
    s->texture_size = xcalloc((size_t)s->ir.ntextures + 1, sizeof *s->texture_size);
    for (int i = 0; i < s->ir.ntextures; i++) {
        const char *file = s->ir.textures[i].file;
        sg_loc loc = sg_texture_file_loc(s->prog, file);
        if (loc.line == 0) {
            int m = first_material[i];
            loc = sc->material_locs && m >= 0 ? sg_loc_or(sc->material_locs[m], sc->loc)
                                              : sc->loc;
        }
        char why[256];
        FILE *f = splat_input_fopen(file, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
        if (!f) {
            sg_errorf(d, loc, SG_E_IO, "cannot read texture '%s': %s", file, why);
            ok = false;
            continue;
        }
        long long w, h;
        int comp;
        bool is16;
        bool image = splat_image_info(f, &w, &h, &comp, &is16);
        fclose(f);
        if (image && w > 0 && h > 0 && w <= SPLAT_MAX_TEXTURE && h <= SPLAT_MAX_TEXTURE)
            s->texture_size[i][0] = (int)w, s->texture_size[i][1] = (int)h;
        if (!image) {
            sg_errorf(d, loc, SG_E_IO, "cannot read texture '%s': not an image "
                      "(PNG, JPEG, TGA, BMP, …)", file);
            ok = false;
        } else if (w < 1 || h < 1 || w > SPLAT_MAX_TEXTURE || h > SPLAT_MAX_TEXTURE) {
            sg_errorf(d, loc, SG_E_OVER_LIMIT, "texture '%s' is %lld x %lld texels, over "
                      "the pack limit of %d per side", file, w, h, SPLAT_MAX_TEXTURE);
            ok = false;
        } else if (comp == 0) {
            sg_errorf(d, loc, SG_E_IO, "cannot read texture '%s': stb_image does not "
                      "decode its %lld x %lld header", file, w, h);
            ok = false;
        }
    }
    return ok;
}

/* ---- the terrain's values ------------------------------------------------ */

/* The loaded terrain's size and heights within the pack limits (abi.h
 * SPLAT_MAX_EXTENT), finite: a GDAL raster brings its own (a Float64
 * band at +-1.7e308 spans an infinite max_height), and the manifest must
 * hold numbers the runtime accepts.  Errors at the heightfield. */
static bool check_extent(const splat_scene *s, sg_diags *d)
{
    const splat_terrain *t = &s->terrain;
    const sg_scene *sc = s->desc;
    sg_loc loc = sg_loc_or(sc->heightfield_loc, sc->loc);
    if (!(t->size[0] > 0 && t->size[0] <= SPLAT_MAX_EXTENT && t->size[1] > 0 &&
          t->size[1] <= SPLAT_MAX_EXTENT)) {
        sg_errorf(d, loc, SG_E_OVER_LIMIT, "heightfield '%s' gives a world size of %g x %g m; "
                  "the pack limit is %g m a side", sc->heightfield, t->size[0], t->size[1],
                  SPLAT_MAX_EXTENT);
        return false;
    }
    double lo = t->height_offset, hi = t->height_offset + t->max_height;
    if (!(t->max_height >= 0 && t->max_height <= SPLAT_MAX_EXTENT &&
          fabs(t->height_offset) <= SPLAT_MAX_EXTENT && fabs(hi) <= SPLAT_MAX_EXTENT)) {
        sg_errorf(d, loc, SG_E_OVER_LIMIT, "heightfield '%s' has heights from %g to %g m "
                  "(max_height %g, height_offset %g); the pack limit is finite heights "
                  "within %g m of 0", sc->heightfield, lo, hi, t->max_height,
                  t->height_offset, SPLAT_MAX_EXTENT);
        return false;
    }
    return true;
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
    if (!check_extent(s, d))
        goto fail;
    if (sc->hf_format != SG_HF_R16 &&
        !sg_scene_cells_fit(sc, s->terrain.width, s->terrain.height, d))
        goto fail;
    if (!load_holes(s, d) || !lower_materials(s, d) || !load_painted(s, d) ||
        !splat_vectors_build(sc, &s->vectors, d) || d->nerrors > errors)
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
    free(s->texture_size);
    if (s->own_desc) {
        free(s->own_desc->cameras);
        free(s->own_desc);
    }
    splat_terrain_free(&s->terrain);
    splat_vectors_free(&s->vectors);
    ir_free(&s->ir);
    if (s->prog) sg_free(s->prog);
    free(s->path);
    memset(s, 0, sizeof *s);
}
