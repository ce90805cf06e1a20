/* build.c — `splatc build`: from a scene to a shader pack (compiler/PACK.md).
 *
 * The pipeline is splat_build at the bottom, one phase after the other
 * (each timed for --stats); build.h names the files the phases live in:
 *
 *   load      splat_scene_load: parse, check, heightfield, rasters, lower
 *   analysis  splat_painted_build: the painted masks as the pack stores
 *             them (sparse BC4 / R8, unless --painted dense), then
 *             splat_analyze on them: the combinations and quadtree grids
 *   compose   a composite per combination (+ flat variants), the über-shader,
 *             a reference pass per material and the vertex shader: GLSL,
 *             then each shader's key (cache.c)
 *   glslang   cache lookups first; only misses are compiled, on N threads,
 *             each followed at once by spv_validate in the same task (so
 *             the über-shader's long validation overlaps the composites'
 *             compiles), skipped for a module whose shape (its words but
 *             the float constants' values, cache.h) passed it before
 *   validate  errors reported; every newly compiled module stored in the
 *             cache (only validated modules are; a hit was validated when
 *             it was stored, and its entry is checksummed)
 *   write     everything into OUT.tmp-XXXXXX, then swapped into place; a
 *             file the old pack holds with the same bytes is linked from
 *             it instead (pack_write.c: a colour edit writes only the
 *             changed shaders' files and the manifest)
 *
 * Nothing changed: right after loading, the bytes of every input (the
 * graph files the program read, the heightfield, the painted rasters, the
 * texture files) are hashed with the compiler version, its own executable
 * and the options; the manifest records that "inputs" key, and when the existing pack carries
 * the same key and has all its shader files, the build stops there (with
 * --stats it still runs the analysis for the report and reads the shader
 * figures back from the pack).
 *
 * Determinism: every file is a function of the inputs and the splatc
 * binary only (the "inputs" key holds the binary's hash; no times, no
 * absolute paths: material sources are written relative to the scene's
 * folder); manifest keys in a fixed order, reals with 15 significant
 * digits (JSON_REAL_PRECISION).
 */
#include "build.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <xxhash.h>

#include "abi.h"

#ifndef SPLATC_VERSION
#define SPLATC_VERSION "0"
#endif

/* ---- the phases ----------------------------------------------------------- */

static bool load(build *b)
{
    b->scene_ok = splat_scene_load(&b->scene, b->desc->scene, b->desc->search_paths, b->d);
    if (b->scene_ok && b->desc->preview &&
        !splat_scene_preview(&b->scene, b->desc->preview, b->d)) {
        splat_scene_free(&b->scene);
        b->scene_ok = false;
    }
    if (b->scene_ok) {   /* here, so an up-to-date build warns the same */
        splat_sites_warn(&b->scene, b->d);   /* precision.c */
        ir_ienv region;                      /* lint.c, over this terrain */
        memset(&region, 0, sizeof region);
        splat_terrain_ranges(&b->scene.terrain, 0, 0, b->scene.terrain.width,
                             b->scene.terrain.height, &region);
        sg_lint(b->scene.prog, &region, b->d);
    }
    return b->scene_ok;
}

/* The painted masks as the pack stores them (sparse unless --painted
 * dense), then the analysis over them. */
static bool analyse(build *b)
{
    if (!splat_painted_check_format(&b->scene, b->desc->painted, b->d))
        return false;
    if (b->desc->painted != SPLAT_PAINTED_DENSE) {
        b->sparse_ok = splat_painted_build(&b->scene, b->desc->painted, &b->sparse, b->d);
        if (!b->sparse_ok)
            return false;
        b->scene.sparse = &b->sparse;
        b->painted_places = sparse_glsl_places(&b->sparse);
    }
    b->analysis_ok = splat_analyze_merged(&b->scene, b->desc->max_combos, &b->analysis, b->d);
    if (b->analysis_ok) {
        b->st->combos_found = b->analysis.nleaf;
        b->st->largest = b->analysis.largest;
        b->st->leaf_largest = b->analysis.leaf_largest;
        b->st->uber_nodes = b->analysis.uber_nodes;
    }
    if (b->analysis_ok && b->desc->report) {
        splat_analysis_report(&b->scene, &b->analysis, b->desc->report);
        build_report_painted(b, b->desc->report);
    }
    return b->analysis_ok;
}

/* The layout's textures into arrays (abi.h set 1) by size, mip files and
 * sampler state; scene.c has checked every file and read its size. */
static bool group_textures(build *b)
{
    splat_layout *L = &b->layout;
    int n = L->ntextures;
    int *w = xcalloc((size_t)n + 1, sizeof *w), *h = xcalloc((size_t)n + 1, sizeof *h);
    int *mips = xcalloc((size_t)n + 1, sizeof *mips);
    for (int t = 0; t < n; t++) {
        int src = L->textures[t];   /* sizes as splat_scene_load read them */
        w[t] = b->scene.texture_size[src][0], h[t] = b->scene.texture_size[src][1];
        mips[t] = build_mip_count(L->src->textures[src].file);
    }
    splat_layout_group_textures(L, w, h, mips);
    free(w);
    free(h);
    free(mips);
    sg_loc at = b->scene.desc->loc;
    if (n > SPLAT_MAX_TEXTURES) {
        sg_errorf(b->d, at, SG_E_OVER_LIMIT, "the scene's materials sample %d textures, "
                  "over the pack limit of %d", n, SPLAT_MAX_TEXTURES);
        return false;
    }
    if (L->narrays > SPLAT_MAX_TEXTURE_ARRAYS) {
        sg_errorf(b->d, at, SG_E_OVER_LIMIT, "the scene's %d textures need %d texture arrays "
                  "(one per size, mip files and sampler state), over the pack limit of %d: "
                  "use fewer sizes or sampler settings", n, L->narrays,
                  SPLAT_MAX_TEXTURE_ARRAYS);
        return false;
    }
    return true;
}

static bool layout(build *b)
{
    b->layout_ok = splat_layout_from_scene(&b->layout, &b->scene, b->d);
    b->ug_ok = b->layout_ok && group_textures(b) && splat_ug_init(&b->ug, &b->scene, b->d);
    return b->ug_ok;
}

static bool write_out(build *b)
{
    if (b->desc->report)
        build_report_shaders(b, b->desc->report);
    bool device = b->far.pending;
    bool ok = build_write_pack(b);
    if (device) {   /* the device bake ran inside: count it as the bake's */
        b->st->far_atlas += b->far.seconds;
        b->st->write -= b->far.seconds;
    }
    b->st->far_on_device = b->far.on_device;
    if (b->desc->report)
        build_report_far(b, b->desc->report);
    return ok;
}

/* Run phase `fn` unless one before failed, adding its time to *seconds.
 * A phase fails by returning false or by reporting an error. */
static void phase(build *b, bool (*fn)(build *), double *seconds)
{
    if (b->failed)
        return;
    double t = splat_now();
    b->failed = !fn(b) || b->d->nerrors > b->errors;
    *seconds += splat_now() - t;
}

/* Nothing changed: the existing pack is what this build would write.  The
 * report still wants the (cheap) analysis, and the shaders' figures read
 * back from the pack. */
static bool unchanged(build *b)
{
    double t = splat_now();
    bool same = !b->failed && build_inputs_key(b) && build_up_to_date(b, &b->st->combos);
    if (same) {
        /* Make and Ninja compare times: an input touched but not changed
         * must still leave the pack newer than it (--depfile's target). */
        char *mf = xasprintf("%s/manifest.json", b->out);
        utimensat(AT_FDCWD, mf, NULL, 0);
        free(mf);
    }
    b->st->load += splat_now() - t;
    if (same && b->desc->report) {
        phase(b, analyse, &b->st->analysis);
        if (!b->failed)
            build_report_shaders_from_pack(b, b->desc->report);
    }
    return b->st->up_to_date = same;
}

/* ---- the pipeline --------------------------------------------------------- */

static bool build_finish(build *b)
{
    build_jobs_free(b);
    if (b->layout_ok)
        splat_layout_free(&b->layout);
    splat_ug_free(&b->ug);
    if (b->analysis_ok)
        splat_analysis_free(&b->analysis);
    if (b->sparse_ok)
        sparse_free(&b->sparse);
    free(b->painted_places);
    free(b->far.data);
    if (b->scene_ok)
        splat_scene_free(&b->scene);
    free(b->out);
    return b->d->nerrors == b->errors;
}

bool splat_build(const splat_build_desc *desc, splat_build_stats *st, sg_diags *d)
{
    splat_build_stats ignored;
    st = st ? st : &ignored;
    memset(st, 0, sizeof *st);
    build b = {.desc = desc, .st = st, .d = d, .errors = d->nerrors,
               .loc = {.file = desc->scene}, .out = xstrdup(desc->out)};
    /* "pack/" would put the temporary folder inside the old pack */
    for (size_t n = strlen(b.out); n > 1 && b.out[n - 1] == '/'; n--)
        b.out[n - 1] = 0;

    phase(&b, build_check_out, &st->load);  /* -o can be written, first    */
    phase(&b, load, &st->load);             /* parse, check, lower, rasters */
    if (unchanged(&b)) {
        phase(&b, build_write_depfile, &st->write);
        return build_finish(&b);
    }
    phase(&b, analyse, &st->analysis);      /* painted masks, combinations  */
    phase(&b, layout, &st->compose);        /* the pack's params, textures  */
    phase(&b, build_compose, &st->compose); /* GLSL and key per shader      */
    phase(&b, build_compile, &st->glslang); /* cache, glslang and spirv-val */
    phase(&b, build_validate, &st->validate); /* errors, cache puts         */
    phase(&b, build_far_atlas, &st->far_atlas); /* --far-atlas: the bake    */
    phase(&b, write_out, &st->write);       /* manifest, files, depfile, swap */
    return build_finish(&b);
}
