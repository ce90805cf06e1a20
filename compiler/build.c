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
 *   write     everything into OUT.tmp-XXXXXX, then swapped into place
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

/* ---- nothing changed? ---------------------------------------------------- */

static bool hash_file(XXH3_state_t *st, const char *path)
{
    /* a regular file of bounded size: a texture linked to /dev/zero must
     * not spin here (util.h) */
    char why[256];
    FILE *f = splat_input_fopen(path, SPLAT_MAX_RASTER_BYTES, why, sizeof why);
    if (!f)
        return false;
    char buf[1 << 16];
    size_t n, total = 0;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        XXH3_128bits_update(st, buf, n);
        total += n;
    }
    bool ok = !ferror(f);
    fclose(f);
    /* the length separates one file from the next */
    XXH3_128bits_update(st, &total, sizeof total);
    return ok;
}

/* Every file the pack is made from, in a fixed order: the graph files the
 * program read (scene and imports), the heightfield, the painted rasters,
 * each texture and its mips.  NULL-terminated, malloc'd (the key and the
 * depfile both read this list, so they cannot disagree). */
static char **input_files(const splat_scene *s)
{
    int cap = 8, n = 0;
    char **v = xcalloc((size_t)cap, sizeof *v);
#define ADD(path) do {                                                     \
        if (n + 2 > cap)                                                   \
            v = xrealloc(v, (size_t)(cap *= 2) * sizeof *v);              \
        v[n++] = (path);                                                   \
        v[n] = NULL;                                                       \
    } while (0)
    for (int i = 0; i < sg_file_count(s->prog); i++)
        ADD(xstrdup(sg_file_path(s->prog, i)));
    ADD(xstrdup(s->desc->heightfield));
    if (s->desc->holes)
        ADD(xstrdup(s->desc->holes));
    for (int i = 0; i < s->desc->npainted; i++)
        ADD(xstrdup(s->desc->painted[i].file));
    for (int i = 0; i < s->ir.ntextures; i++) {
        ADD(xstrdup(s->ir.textures[i].file));
        for (int k = 1, m = build_mip_count(s->ir.textures[i].file); k <= m; k++)
            ADD(build_mip_path(s->ir.textures[i].file, k));
    }
    /* undergrowth meshes from OBJ files, and their textures */
    for (int m = 0; m < sg_material_count(s->prog); m++)
        for (int k = 0; k < sg_undergrowth_count(s->prog, m); k++) {
            const sg_undergrowth *g = sg_undergrowth_get(s->prog, m, k);
            if (g->obj)
                ADD(xstrdup(g->obj));
            if (g->texture)
                ADD(xstrdup(g->texture));
        }
#undef ADD
    return v;
}

static void free_list(char **v)
{
    for (int i = 0; v && v[i]; i++)
        free(v[i]);
    free(v);
}

/* The key of everything the pack is made from (contents, not names or
 * times, so a moved or touched scene is still up to date).  False if a
 * file cannot be read (then there is no shortcut). */
static bool inputs_key(build *b)
{
    XXH3_state_t *st = XXH3_createState();
    if (!st)
        abort();
    XXH3_128bits_reset(st);
    char head[256];
    static const char *const bakes[] = {"auto", "cpu", "gpu"};
    int n = snprintf(head, sizeof head,
                     "splatc %s\nabi %d\nflat %d\nlazy %d\npainted %s\ncompute-spirv %d\nfar-atlas %d %s\ndclasses %d\nmax-combinations %d\npreview ",
                     SPLATC_VERSION, SPLAT_ABI_VERSION, b->desc->flat, !b->desc->no_lazy,
                     splat_painted_format_name(b->desc->painted), !b->desc->glsl_compute,
                     b->desc->far_atlas, b->desc->far_atlas > 0 ? bakes[b->desc->far_bake] : "-",
                     !b->desc->no_dclasses, b->desc->max_combos);
    XXH3_128bits_update(st, head, (size_t)n);
    if (b->desc->preview)   /* the name and its end */
        XXH3_128bits_update(st, b->desc->preview, strlen(b->desc->preview) + 1);
    /* the ABI's GLSL too: a changed prelude is a changed compiler */
    XXH3_128bits_update(st, SPLAT_GLSL_PRELUDE, strlen(SPLAT_GLSL_PRELUDE));
    XXH3_128bits_update(st, SPLAT_GLSL_VERTEX, strlen(SPLAT_GLSL_VERTEX));
    /* and this splatc's own bytes, where the system shows them: a compiler
     * rebuilt from changed sources under the same version number must not
     * call an older pack up to date (the same binary gives the same key) */
    hash_file(st, "/proc/self/exe");
    bool ok = true;
    char **files = input_files(&b->scene);
    for (int i = 0; ok && files[i]; i++)
        ok = hash_file(st, files[i]);
    free_list(files);
    XXH128_hash_t h = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    snprintf(b->inputs, sizeof b->inputs, "%016llx%016llx", (unsigned long long)h.high64,
             (unsigned long long)h.low64);
    if (!ok)
        b->inputs[0] = 0;  /* recorded as "": never up to date */
    return ok;
}

/* The shader's files are there: every file it names, "spirv" named
 * where `spirv` (a compute variant may be GLSL alone, a reference pass
 * SPIR-V alone). */
static bool shader_files(const char *pack, json_t *shader, bool spirv)
{
    if (!json_is_object(shader))
        return false;
    const char *keys[] = {"glsl", "spirv"};
    for (int i = 0; i < 2; i++) {
        const char *rel = json_string_value(json_object_get(shader, keys[i]));
        if (!rel && (i == 0 || !spirv))
            continue;
        if (!rel)
            return false;
        char *path = xasprintf("%s/%s", pack, rel);
        bool ok = access(path, R_OK) == 0;
        free(path);
        if (!ok)
            return false;
    }
    return true;
}

static bool has_files(const char *pack, json_t *shader)
{
    return shader_files(pack, shader, true);
}

/* Does the pack at desc->out already hold what this build would write?
 * On yes, *ncombos is its combination count. */
static bool up_to_date(build *b, int *ncombos)
{
    char *mf = xasprintf("%s/manifest.json", b->out);
    json_t *m = json_load_file(mf, 0, NULL);
    free(mf);
    if (!m)
        return false;
    const char *key = json_string_value(json_object_get(m, "inputs"));
    bool ok = key && strcmp(key, b->inputs) == 0;
    json_t *combos = json_object_get(m, "combinations");
    ok = ok && json_is_array(combos);
    for (size_t i = 0; ok && i < json_array_size(combos); i++) {
        json_t *c = json_array_get(combos, i);
        ok = has_files(b->out, c) &&
             shader_files(b->out, json_object_get(c, "compute"), !b->desc->glsl_compute) &&
             (!b->desc->flat || has_files(b->out, json_object_get(c, "flat")));
        json_t *cls = json_object_get(c, "classes");   /* distance classes */
        for (size_t k = 0; ok && k < json_array_size(cls); k++)
            ok = shader_files(b->out, json_array_get(cls, k), !b->desc->glsl_compute) &&
                 shader_files(b->out, json_object_get(json_array_get(cls, k), "compute"),
                              !b->desc->glsl_compute);
    }
    json_t *mats = json_object_get(m, "materials");
    for (size_t i = 0; ok && i < json_array_size(mats); i++)
        ok = has_files(b->out, json_object_get(json_array_get(mats, i), "reference"));
    ok = ok && has_files(b->out, json_object_get(m, "uber")) &&
         shader_files(b->out, json_object_get(json_object_get(m, "uber"), "compute"),
                      !b->desc->glsl_compute) &&
         has_files(b->out, json_object_get(m, "vertex"));
    if (ok && b->desc->far_atlas > 0) {   /* the key says it was baked */
        char *fa = xasprintf("%s/far.atlas", b->out);
        ok = access(fa, R_OK) == 0;
        free(fa);
    }
    *ncombos = ok ? (int)json_array_size(combos) : 0;
    json_decref(m);
    return ok;
}

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

/* A Make/Ninja path: spaces, '#' and '\\' before them escaped, '$' doubled. */
static void dep_path(ir_buf *o, const char *p)
{
    for (; *p; p++) {
        if (*p == ' ' || *p == '#' || *p == '\\')
            ir_buf_printf(o, "\\");
        ir_buf_printf(o, *p == '$' ? "$$" : "%c", *p);
    }
}

/* --depfile: "PACKDIR/manifest.json: every input", so Make and Ninja
 * rebuild the pack when any file it was made from changes (build.h: the
 * pack writer calls it before its swap). */
bool build_write_depfile(build *b)
{
    if (!b->desc->depfile)
        return true;
    ir_buf o = {0};
    dep_path(&o, b->out);
    ir_buf_printf(&o, "/manifest.json:");
    char **files = input_files(&b->scene);
    for (int i = 0; files[i]; i++) {
        ir_buf_printf(&o, " \\\n  ");
        dep_path(&o, files[i]);
    }
    free_list(files);
    ir_buf_printf(&o, "\n");
    bool ok = splat_write_atomic(b->desc->depfile, o.s, o.len);
    if (!ok)
        sg_error(b->d, (sg_loc){.file = b->desc->depfile}, SG_E_WRITE, b->desc->depfile,
                 strerror(errno));
    ir_buf_free(&o);
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
    bool same = !b->failed && inputs_key(b) && up_to_date(b, &b->st->combos);
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
