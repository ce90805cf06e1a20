/* build_inputs.c — what a build is made from: every input file in a fixed
 * order, their key (the manifest's "inputs", build_inputs_key), the check
 * that the pack at the output already holds what this build would write
 * (build_up_to_date), and the --depfile listing the same files
 * (build_write_depfile).  The key and the depfile read one list, so they
 * cannot disagree.  build.c's pipeline and pack_write.c call it; it calls
 * nothing above it (the texture mips: texture_mips.c).
 */
#include "build.h"

#include <errno.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <xxhash.h>

#include "abi.h"
#include "stand_in.h"

#ifndef SPLATC_VERSION
#define SPLATC_VERSION "0"
#endif

/* ---- the key ------------------------------------------------------------ */

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
bool build_inputs_key(build *b)
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
bool build_up_to_date(build *b, int *ncombos)
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
    /* the stand-ins' modules (PACK.md "Stand-ins") */
    json_t *si = json_object_get(json_object_get(m, "uber"), "stand_in");
    for (int k = 0; ok && !b->desc->glsl_compute && k < SPLAT_STAND_IN_KINDS; k++)
        if (k != SPLAT_STAND_IN_ATLAS || b->desc->far_atlas > 0)
            ok = has_files(b->out,
                           json_object_get(si, splat_stand_in_name((splat_stand_in_kind)k)));
    if (ok && b->desc->far_atlas > 0) {   /* the key says it was baked */
        char *fa = xasprintf("%s/far.atlas", b->out);
        ok = access(fa, R_OK) == 0;
        free(fa);
    }
    *ncombos = ok ? (int)json_array_size(combos) : 0;
    json_decref(m);
    return ok;
}

/* ---- the depfile ---------------------------------------------------------- */

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
