/* pack_write.c — the pack writer (compiler/PACK.md): every file of the
 * pack into OUT.tmp-XXXXXX (manifest.json with keys in a fixed order and
 * reals at 15 significant digits, shaders, heightfield, painted masks,
 * textures and their mips), then swapped into place in one step where the
 * file system can (renameat2 RENAME_EXCHANGE), else by two renames; an
 * existing folder is replaced only if it is empty or a pack.
 */
#define _GNU_SOURCE 1   /* renameat2 */
#include "build.h"
#include "util.h"

#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb_image.h>

#include "far_atlas.h"

#include "abi.h"
#include "spv.h"
#include "stand_in.h"
#include "zst.h"

#ifndef SPLATC_VERSION
#define SPLATC_VERSION "0"
#endif

/* ---- writing -------------------------------------------------------------- */

static void write_error(build *b, const char *path)
{
    sg_error(b->d, b->loc, SG_E_WRITE, path, strerror(errno));
}

/* Write dir/name through fn(f, user); a failure is reported with the path. */
static bool write_with(build *b, const char *dir, const char *name,
                       bool (*fn)(FILE *f, const void *user), const void *user)
{
    char *path = xasprintf("%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    bool ok = f && fn(f, user);
    if (f && fclose(f) != 0)
        ok = false;
    if (!ok)
        write_error(b, path);
    b->st->files_written += ok;
    free(path);
    return ok;
}

typedef struct bytes { const void *data; size_t n; } bytes;

static bool put_bytes(FILE *f, const void *user)
{
    const bytes *by = user;
    return fwrite(by->data, 1, by->n, f) == by->n;
}

/* ---- keeping the old pack's files ------------------------------------------
 * A rebuild after a small edit writes mostly what the old pack already holds.
 * A file whose bytes would be the same is hard-linked from the old pack into
 * the new temporary folder (the swap stays atomic, and the old pack's removal
 * leaves the link); a compressed file is compared by its content, so it is not
 * compressed again.  The result is the same bytes a cold build writes. */

/* The old pack's dir/name, whole, if it is a regular file of at most `max`
 * bytes; NULL otherwise. */
static uint8_t *old_bytes(build *b, const char *name, size_t max, size_t *n)
{
    if (!b->old_pack)
        return NULL;
    char *path = xasprintf("%s/%s", b->old_pack, name);
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    free(path);
    if (fd < 0)
        return NULL;
    struct stat sb;
    uint8_t *buf = NULL;
    if (fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode) && (uint64_t)sb.st_size <= max) {
        *n = (size_t)sb.st_size;
        buf = xmalloc(*n + 1);
        size_t got = 0;
        while (got < *n) {
            ssize_t r = read(fd, buf + got, *n - got);
            if (r <= 0)
                break;
            got += (size_t)r;
        }
        if (got != *n) {
            free(buf);
            buf = NULL;
        }
    }
    close(fd);
    return buf;
}

static bool write_file_now(build *b, const char *dir, const char *name, const void *data,
                           size_t n)
{
    bytes by = {data, n};
    return write_with(b, dir, name, put_bytes, &by);
}

/* dir/name as a link to the old pack's file of the same name, which holds
 * `old` (its bytes, what this build writes there); written if the file
 * system has no links. */
static bool keep_old(build *b, const char *dir, const char *name, const void *old,
                     size_t n)
{
    char *from = xasprintf("%s/%s", b->old_pack, name), *to = xasprintf("%s/%s", dir, name);
    bool linked = link(from, to) == 0;
    free(from);
    free(to);
    if (!linked)
        return write_file_now(b, dir, name, old, n);
    b->st->files_kept++;
    return true;
}

static bool write_file(build *b, const char *dir, const char *name, const void *data,
                       size_t n)
{
    size_t on;
    uint8_t *old = old_bytes(b, name, n, &on);
    bool ok = old && on == n && memcmp(old, data, n) == 0 ? keep_old(b, dir, name, old, n)
                                                         : write_file_now(b, dir, name, data, n);
    free(old);
    return ok;
}

/* A shader's files in the pack (PACK.md "Compressed shaders"): its GLSL
 * text ("X.frag.zst" for a fragment shader, "X.comp.zst", "X.vert.zst")
 * and its SPIR-V ("X.spv.zst"), each one zstd frame (zst.h). */
static char *glsl_file(const char *file, bool fragment)
{
    return xasprintf("%s%s" SPLAT_ZST_SUFFIX, file, fragment ? ".frag" : "");
}

static char *spirv_file(const char *file)
{
    return xasprintf("%s.spv" SPLAT_ZST_SUFFIX, file);
}

static bool write_compressed(build *b, const char *dir, const char *name, const void *data,
                             size_t n)
{
    uint8_t *z;
    size_t zn;
    /* the old pack's frame of the same content is kept, once this libzstd
     * is seen to make that frame byte for byte (the first such file is
     * compressed again and compared: a libzstd upgrade may make others) */
    uint8_t *old = b->keep_zst >= 0 ? old_bytes(b, name, splat_zst_bound(n), &zn) : NULL;
    if (old && splat_zst_holds(old, zn, data, n)) {
        if (b->keep_zst == 0) {
            uint8_t *again;
            size_t an;
            b->keep_zst = splat_zst_compress(data, n, &again, &an) && an == zn &&
                          memcmp(again, old, an) == 0 ? 1 : -1;
            free(again);
        }
        if (b->keep_zst > 0) {
            bool ok = keep_old(b, dir, name, old, zn);
            free(old);
            return ok;
        }
    }
    free(old);
    if (!splat_zst_compress(data, n, &z, &zn)) {
        char *path = xasprintf("%s/%s", dir, name);
        errno = ENOMEM;
        write_error(b, path);
        free(path);
        return false;
    }
    bool ok = write_file_now(b, dir, name, z, zn);
    free(z);
    return ok;
}

static bool copy_file(build *b, const char *from, const char *dir, const char *name)
{
    char why[256];
    FILE *f = splat_input_fopen(from, SPLAT_MAX_IMAGE_BYTES, why, sizeof why);
    if (!f) {
        sg_error(b->d, b->loc, SG_E_IO, from, why);
        return false;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = xmalloc(cap);
    size_t got;
    while ((got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            cap *= 2;
            buf = xrealloc(buf, cap);
        }
    }
    bool ok = !ferror(f);
    fclose(f);
    if (!ok)
        sg_error(b->d, b->loc, SG_E_IO, from, strerror(errno));
    ok = ok && write_file(b, dir, name, buf, n);
    free(buf);
    return ok;
}

/* dir/name made by fn(f, user) in memory first, so that write_file can keep
 * the old pack's file when the bytes are the same. */
static bool write_made(build *b, const char *dir, const char *name,
                       bool (*fn)(FILE *f, const void *user), const void *user)
{
    if (!b->old_pack)
        return write_with(b, dir, name, fn, user);
    char *buf = NULL;
    size_t n = 0;
    FILE *m = open_memstream(&buf, &n);
    bool made = m && fn(m, user);
    if (m && fclose(m) != 0)
        made = false;
    bool ok = made ? write_file(b, dir, name, buf, n) : write_with(b, dir, name, fn, user);
    free(buf);
    return ok;
}

/* Little-endian uint16 array. */
static uint8_t *le16(const uint16_t *v, size_t n)
{
    uint8_t *out = xcalloc(n, 2);
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = (uint8_t)(v[i] & 0xff);
        out[2 * i + 1] = (uint8_t)(v[i] >> 8);
    }
    return out;
}

/* Every number of the manifest goes through jreal: JSON has no NaN or
 * infinity (json_real returns NULL for them and the key would silently go
 * missing), and a pack that builds must load.  A non-finite value is
 * counted here (per thread: builds may run side by side in one process)
 * and write_manifest fails the build; the checks before (scene.c's
 * limits, the settings' ranges) name the value and its place first. */
static _Thread_local int nonfinite;

static json_t *jreal(double v)
{
    if (!isfinite(v)) {
        nonfinite++;
        v = 0;
    }
    return json_real(v);
}

static json_t *jreals(const double *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, jreal(v[i]));
    return a;
}

static json_t *jints(const int *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, json_integer(v[i]));
    return a;
}

/* {"glsl", "spirv"} of a shader; `glsl` false: the SPIR-V alone (a
 * reference pass, whose text the runtime never reads). */
static json_t *jshader(const char *file, bool fragment, bool glsl)
{
    json_t *o = json_object();
    char *name;
    if (glsl) {
        name = glsl_file(file, fragment);
        json_object_set_new(o, "glsl", json_string(name));
        free(name);
    }
    name = spirv_file(file);
    json_object_set_new(o, "spirv", json_string(name));
    free(name);
    return o;
}

/* A compute variant's manifest entry (PACK.md). */
static json_t *jcompute(const job *j)
{
    json_t *o = json_object();
    char *name = glsl_file(j->file, false);
    json_object_set_new(o, "glsl", json_string(name));
    free(name);
    if (!j->glsl_only) {
        char *spv = spirv_file(j->file);
        json_object_set_new(o, "spirv", json_string(spv));
        free(spv);
    }
    json_object_set_new(o, "hash", json_string(j->key));
    return o;
}

/* Pack names of the texture files: textures/<basename>, "-N" added before
 * the extension when two different files share a basename. */
static char **texture_names(build *b)
{
    const splat_layout *L = &b->layout;
    char **names = xcalloc((size_t)L->ntextures, sizeof *names);
    for (int i = 0; i < L->ntextures; i++) {
        const char *file = L->src->textures[L->textures[i]].file;
        for (int k = 0; k < i && !names[i]; k++)
            if (strcmp(L->src->textures[L->textures[k]].file, file) == 0)
                names[i] = strdup(names[k]);
        if (names[i])
            continue;
        const char *base = strrchr(file, '/') ? strrchr(file, '/') + 1 : file;
        for (int n = 0; !names[i]; n++) {
            const char *dot = strrchr(base, '.');
            int stem = dot ? (int)(dot - base) : (int)strlen(base);
            char *cand = n ? xasprintf("textures/%.*s-%d%s", stem, base, n, dot ? dot : "")
                           : xasprintf("textures/%s", base);
            bool taken = false;
            for (int k = 0; k < i; k++)
                taken |= strcmp(names[k], cand) == 0;
            if (taken)
                free(cand);
            else
                names[i] = cand;
        }
    }
    return names;
}

/* ---- manifest.json, one function per section (PACK.md) -------------------- */

static json_t *jscene(build *b, const char *dir)
{
    const splat_scene *s = &b->scene;
    const sg_scene *sc = s->desc;
    json_t *scene = json_object();
    json_object_set_new(scene, "name", json_string(sc->name ? sc->name : ""));
    /* relative to the pack folder (`dir` is its sibling: same answer) */
    char *scene_src = splat_path_relative_real(dir, b->desc->scene);
    json_object_set_new(scene, "source", json_string(scene_src));
    free(scene_src);
    if (b->desc->pack_search && b->desc->pack_search[0]) {
        json_t *search = json_array();
        for (int i = 0; b->desc->pack_search[i]; i++) {
            char *rel = splat_path_relative_real(dir, b->desc->pack_search[i]);
            json_array_append_new(search, json_string(rel));
            free(rel);
        }
        json_object_set_new(scene, "search", search);
    }
    json_t *hf = json_object();
    json_object_set_new(hf, "file", json_string("heightfield.r16"));
    json_object_set_new(hf, "width", json_integer(s->terrain.width));
    json_object_set_new(hf, "height", json_integer(s->terrain.height));
    if (s->terrain.holes)
        json_object_set_new(hf, "holes", json_string("holes.r8"));
    json_object_set_new(scene, "heightfield", hf);
    json_object_set_new(scene, "size", jreals(s->terrain.size, 2));
    json_object_set_new(scene, "max_height", jreal(s->terrain.max_height));
    json_object_set_new(scene, "height_offset", jreal(s->terrain.height_offset));
    json_object_set_new(scene, "cell_texels", json_integer(b->analysis.cell_texels));
    json_t *cams = json_array();
    for (int i = 0; i < sc->ncameras; i++) {
        json_t *c = json_object();
        json_object_set_new(c, "name", json_string(sc->cameras[i].name));
        json_object_set_new(c, "position", jreals(sc->cameras[i].position, 3));
        json_object_set_new(c, "look", jreals(sc->cameras[i].look, 3));
        json_array_append_new(cams, c);
    }
    json_object_set_new(scene, "cameras", cams);
    if (sc->has_light) {   /* the keys given; the runtime has the rest */
        json_t *l = json_object();
        for (int k = 0; k < SPLAT_LIGHT_COUNT; k++) {
            const splat_light_key *lk = &splat_light_keys[k];
            if (sc->light.given & 1u << k)
                json_object_set_new(l, lk->key, lk->n == 1 ? jreal(sc->light.v[k][0])
                                                           : jreals(sc->light.v[k], lk->n));
        }
        json_object_set_new(scene, "light", l);
    }
    if (sc->has_destruction) {
        json_t *dd = json_object();
        json_object_set_new(dd, "origin", jreals(sc->destruction_origin, 2));
        json_object_set_new(dd, "size", jreals(sc->destruction_size, 2));
        json_object_set_new(dd, "cell_size", jreal(sc->destruction_cell));
        json_object_set_new(scene, "destruction", dd);
    } else {
        json_object_set_new(scene, "destruction", json_null());
    }
    return scene;
}

static json_t *jmaterials(build *b)
{
    const splat_layout *L = &b->layout;
    char *scene_dir = splat_path_dir(b->desc->scene);
    json_t *mats = json_array();
    for (int k = 0; k < L->nmaterials; k++) {
        json_t *o = json_object();
        json_object_set_new(o, "name", json_string(L->materials[k]));
        int pi = sg_material_find(b->scene.prog, L->materials[k]);
        sg_loc ml = pi >= 0 ? sg_material_loc(b->scene.prog, pi) : (sg_loc){0};
        char *src = ml.file ? splat_path_relative_real(scene_dir, ml.file) : xstrdup("");
        json_object_set_new(o, "source", json_string(src));
        free(src);
        char file[64];
        snprintf(file, sizeof file, "shaders/ref_%04d", k);
        json_object_set_new(o, "reference", jshader(file, true, false));
        json_array_append_new(mats, o);
    }
    free(scene_dir);
    return mats;
}

static json_t *jparams(const splat_layout *L)
{
    static const char *const tnames[IR_T_COUNT] = {
        [IR_T_FLOAT] = "float", [IR_T_VEC2] = "vec2", [IR_T_VEC3] = "vec3",
        [IR_T_VEC4] = "vec4"};
    json_t *params = json_array();
    for (int i = 0; i < L->nparams; i++) {
        const ir_param *p = &L->src->params[i];
        json_t *o = json_object();
        json_object_set_new(o, "name", json_string(p->name));
        json_object_set_new(o, "type", json_string(tnames[p->type] ? tnames[p->type] : "float"));
        json_object_set_new(o, "default", jreals(p->def, 4));
        json_object_set_new(o, "min", jreal(p->lo));
        json_object_set_new(o, "max", jreal(p->hi));
        json_object_set_new(o, "offset", json_integer(16 * i));
        json_array_append_new(params, o);
    }
    return params;
}

static json_t *jtextures(const splat_layout *L, char **tex_names)
{
    json_t *texs = json_array();
    for (int i = 0; i < L->ntextures; i++) {
        const ir_texture *t = &L->src->textures[L->textures[i]];
        json_t *o = json_object();
        json_object_set_new(o, "file", json_string(tex_names[i]));
        json_object_set_new(o, "binding", json_integer(SPLAT_BIND_TEXTURE0 + L->tex_array[i]));
        json_object_set_new(o, "layer", json_integer(L->tex_layer[i]));
        json_object_set_new(o, "filter", json_string(ir_filter_name(t->filter)));
        json_object_set_new(o, "mip", json_string(ir_filter_name(t->mip)));
        json_object_set_new(o, "wrap", json_string(ir_wrap_name(t->wrap)));
        json_object_set_new(o, "srgb", json_boolean(t->srgb));
        int mips = build_mip_count(t->file);
        if (mips > 0)
            json_object_set_new(o, "mips", json_integer(mips));
        json_array_append_new(texs, o);
    }
    return texs;
}

static json_t *jpainted(const splat_layout *L)
{
    json_t *painted = json_array();
    for (int i = 0; i < L->npainted; i++) {
        json_t *o = json_object();
        json_object_set_new(o, "name", json_string(L->painted[i]));
        json_object_set_new(o, "layer", json_integer(i));
        json_array_append_new(painted, o);
    }
    return painted;
}

static json_t *jsites(const splat_layout *L)
{
    json_t *sites = json_array();
    for (int i = 0; i < L->nsites; i++) {
        const splat_site *st = &L->sites[i];
        json_t *o = json_object();
        char ax[3] = { "xyzw"[IR_SWZ_C(st->swz, 0)], "xyzw"[IR_SWZ_C(st->swz, 1)], 0 };
        json_object_set_new(o, "axes", json_string(ax));
        json_object_set_new(o, "op", json_string(st->mul ? "mul" : "div"));
        if (st->param >= 0)
            json_object_set_new(o, "param", json_integer(st->param));
        else
            json_object_set_new(o, "scale", jreals(st->value, 2));
        json_array_append_new(sites, o);
    }
    return sites;
}

/* The job of `kind` for combination i, or NULL. */
static const job *find_job(const build *b, int i, int kind)
{
    for (int k = 0; k < b->njobs; k++)
        if (b->jobs[k].index == i && (int)b->jobs[k].kind == kind)
            return &b->jobs[k];
    return NULL;
}

static const job *find_class_job(build *b, int i, int k, job_kind kind)
{
    for (int n = 0; n < b->njobs; n++)
        if (b->jobs[n].index == i && b->jobs[n].kind == kind && b->jobs[n].dclass == k)
            return &b->jobs[n];
    return NULL;
}

/* A combination's distance classes (PACK.md "Distance classes"), or NULL. */
static json_t *jclasses(build *b, int i)
{
    const combo_info *ci = &b->combos[i];
    if (ci->nclasses == 0)
        return NULL;
    json_t *a = json_array();
    for (int k = 0; k < ci->nclasses; k++) {
        const job *fj = find_class_job(b, i, k, JOB_CLASS);
        const job *xj = find_class_job(b, i, k, JOB_CLASS_COMPUTE);
        json_t *o = json_object();
        json_t *dist = json_array();
        json_array_append_new(dist, jreal(ci->dlo[k]));
        json_array_append_new(dist, isinf(ci->dhi[k]) ? json_null() : jreal(ci->dhi[k]));
        json_object_set_new(o, "distance", dist);
        char *name = glsl_file(fj->file, true);
        json_object_set_new(o, "glsl", json_string(name));
        free(name);
        if (!fj->glsl_only) {
            name = spirv_file(fj->file);
            json_object_set_new(o, "spirv", json_string(name));
            free(name);
        }
        json_object_set_new(o, "hash", json_string(fj->key));
        json_object_set_new(o, "cost", jreal(ci->dcost[k]));
        json_object_set_new(o, "compute", jcompute(xj));
        json_array_append_new(a, o);
    }
    return a;
}

static json_t *jcombinations(build *b)
{
    const splat_analysis *a = &b->analysis;
    json_t *combos = json_array();
    for (int i = 0; i < a->ncombos; i++) {
        const job *cj = find_job(b, i, JOB_COMBO), *fj = find_job(b, i, JOB_FLAT);
        const job *xj = find_job(b, i, JOB_COMBO_COMPUTE);
        json_t *o = json_object();
        json_object_set_new(o, "id", json_integer(i));
        json_object_set_new(o, "materials", jints(a->combos[i].materials,
                                                  a->combos[i].nmaterials));
        char *name = glsl_file(cj->file, true);
        json_object_set_new(o, "glsl", json_string(name));
        free(name);
        name = spirv_file(cj->file);
        json_object_set_new(o, "spirv", json_string(name));
        free(name);
        if (fj)
            json_object_set_new(o, "flat", jshader(fj->file, true, true));
        json_object_set_new(o, "textures", jints(b->combos[i].textures, b->combos[i].ntextures));
        json_object_set_new(o, "params", jints(b->combos[i].params, b->combos[i].nparams));
        json_object_set_new(o, "cells", json_integer(a->combos[i].ncells));
        json_object_set_new(o, "nodes", json_integer(a->combos[i].nnodes));
        json_object_set_new(o, "hash", json_string(cj->key));
        json_object_set_new(o, "cost", jreal(b->combos[i].cost));
        json_object_set_new(o, "compute", jcompute(xj));
        const job *uj = find_job(b, i, JOB_COMBO_UG);
        if (uj)
            json_object_set_new(o, "undergrowth", jcompute(uj));
        json_t *cls = jclasses(b, i);
        if (cls)
            json_object_set_new(o, "classes", cls);
        json_array_append_new(combos, o);
    }
    return combos;
}

/* The undergrowth table (PACK.md "Undergrowth"), or NULL when no material
 * carries any. */
static json_t *jundergrowth(const splat_ug *u)
{
    if (u->nblocks == 0)
        return NULL;
    json_t *o = json_object();
    json_object_set_new(o, "file", json_string("meshes.bin"));
    json_object_set_new(o, "slots", json_integer(u->nslots));
    json_object_set_new(o, "texels", json_integer(SPLAT_UG_TEXELS));
    json_t *meshes = json_array();
    for (int i = 0; i < u->nmeshes; i++) {
        json_t *m = json_object();
        json_object_set_new(m, "name", json_string(u->mesh_names[i]));
        json_object_set_new(m, "vertices", json_integer(u->meshes[i].nv));
        json_object_set_new(m, "indices", json_integer(u->meshes[i].nidx));
        if (u->far[i] >= 0)
            json_object_set_new(m, "far", json_integer(u->far[i]));
        json_array_append_new(meshes, m);
    }
    json_object_set_new(o, "meshes", meshes);
    json_t *blocks = json_array();
    for (int i = 0; i < u->nblocks; i++) {
        const splat_ug_block *k = &u->blocks[i];
        json_t *m = json_object();
        json_object_set_new(m, "material", json_integer(k->material));
        json_object_set_new(m, "slot", json_integer(k->slot));
        json_object_set_new(m, "mesh", json_integer(k->mesh));
        json_object_set_new(m, "density", jreal(k->u->density));
        json_object_set_new(m, "scale", jreals(k->u->scale, 2));
        json_object_set_new(m, "align", json_string(k->u->align_normal ? "normal" : "upright"));
        json_object_set_new(m, "blend", jreal(k->u->blend));
        json_object_set_new(m, "root_blend", jreal(k->u->root_blend));
        json_object_set_new(m, "color", jreals(k->u->color, 3));
        json_object_set_new(m, "lighting", json_string(k->u->light_terrain ? "terrain" : "mesh"));
        static const char *const cuts[] = { "none", "frond", "alpha" };
        json_object_set_new(m, "cutout", json_string(cuts[k->u->cutout]));
        json_object_set_new(m, "texture", json_integer(k->texture));
        double wind[4] = { k->u->wind_dir[0], k->u->wind_dir[1], k->u->wind, k->u->gust };
        json_object_set_new(m, "wind", jreals(wind, 4));
        json_object_set_new(m, "shadow", jreal(k->u->shadow));
        json_array_append_new(blocks, m);
    }
    json_object_set_new(o, "blocks", blocks);
    if (u->ntextures > 0) {
        json_t *tex = json_array();
        for (int i = 0; i < u->ntextures; i++) {
            json_t *t = json_object();
            json_object_set_new(t, "width", json_integer(u->textures[i].width));
            json_object_set_new(t, "height", json_integer(u->textures[i].height));
            json_array_append_new(tex, t);
        }
        json_object_set_new(o, "textures", tex);
        json_object_set_new(o, "texture_file", json_string("ugtex.bin"));
    }
    return o;
}

static json_t *jquadtree(const splat_analysis *a)
{
    json_t *qt = json_object();
    json_object_set_new(qt, "file", json_string("combos.bin"));
    json_t *levels = json_array();
    size_t offset = 0;
    for (int l = 0; l < a->nlevels; l++) {
        json_t *o = json_object();
        json_object_set_new(o, "level", json_integer(l));
        json_object_set_new(o, "width", json_integer(a->levels[l].width));
        json_object_set_new(o, "height", json_integer(a->levels[l].height));
        json_object_set_new(o, "offset", json_integer((json_int_t)offset));
        json_array_append_new(levels, o);
        offset += 2 * (size_t)a->levels[l].width * (size_t)a->levels[l].height;
    }
    json_object_set_new(qt, "levels", levels);
    return qt;
}

/* "uber"."stand_in": {"flat": {"spirv", "hash"}, "atlas": …} (PACK.md
 * "Stand-ins"); NULL without (--glsl-compute). */
static json_t *jstand_ins(const build *b)
{
    json_t *o = NULL;
    for (int k = 0; k < b->njobs; k++) {
        const job *j = &b->jobs[k];
        /* the atlas's with the far atlas only: not in the manifest the
         * device bake reads before the atlas exists (build_write_pack) */
        if (j->kind != JOB_STAND_IN || (j->index == SPLAT_STAND_IN_ATLAS && !b->far.data))
            continue;
        if (!o)
            o = json_object();
        json_t *e = json_object();
        char *spv = spirv_file(j->file);
        json_object_set_new(e, "spirv", json_string(spv));
        free(spv);
        json_object_set_new(e, "hash", json_string(j->key));
        json_object_set_new(o, splat_stand_in_name((splat_stand_in_kind)j->index), e);
    }
    return o;
}

static json_t *manifest(build *b, char **tex_names, const char *dir)
{
    const splat_layout *L = &b->layout;
    json_t *m = json_object();
    json_object_set_new(m, "format", json_string("splatc-pack"));
    json_object_set_new(m, "version", json_integer(SPLAT_PACK_VERSION));
    json_object_set_new(m, "abi", json_integer(SPLAT_ABI_VERSION));
    json_object_set_new(m, "compiler", json_string("splatc " SPLATC_VERSION));
    json_object_set_new(m, "inputs", json_string(b->inputs));
    json_object_set_new(m, "scene", jscene(b, dir));
    json_object_set_new(m, "materials", jmaterials(b));
    json_object_set_new(m, "params", jparams(L));
    json_object_set_new(m, "params_size", json_integer(16 * (L->nparams > 0 ? L->nparams : 1)));
    json_object_set_new(m, "textures", jtextures(L, tex_names));
    json_object_set_new(m, "painted", jpainted(L));
    json_object_set_new(m, "world_sites", jsites(L));
    /* how the painted masks are stored: dense layers or the sparse quad-tree */
    json_object_set_new(m, "painted_format",
                        json_string(splat_painted_format_name(b->desc->painted)));
    json_object_set_new(m, "painted_file",
                        json_string(b->sparse_ok ? "painted.sparse" : "painted.r8"));
    json_object_set_new(m, "combinations", jcombinations(b));
    json_t *uber = jshader("shaders/uber", true, true);
    for (int k = 0; k < b->njobs; k++)
        if (b->jobs[k].kind == JOB_UBER_COMPUTE)
            json_object_set_new(uber, "compute", jcompute(&b->jobs[k]));
    json_t *stand_in = jstand_ins(b);
    if (stand_in)
        json_object_set_new(uber, "stand_in", stand_in);
    json_object_set_new(m, "uber", uber);
    json_object_set_new(m, "vertex", jshader("shaders/terrain.vert", false, true));
    json_object_set_new(m, "quadtree", jquadtree(&b->analysis));
    json_t *ug = jundergrowth(&b->ug);
    if (ug)
        json_object_set_new(m, "undergrowth", ug);
    const splat_vectors *vs = &b->scene.vectors;
    if (vs->words) {   /* vector.c, abi.h: the shapes' buffer */
        json_t *vo = json_object(), *names = json_array();
        const sg_scene *sc = b->scene.desc;
        for (int i = 0; i < sc->nvectors; i++)
            json_array_append_new(names, json_string(sc->vectors[i].name));
        json_object_set_new(vo, "file", json_string("vectors.bin"));
        json_object_set_new(vo, "words", json_integer((json_int_t)vs->nwords));
        json_object_set_new(vo, "shapes", names);
        json_object_set_new(m, "vectors", vo);
    }
    if (b->far.data) {   /* far_atlas.h */
        json_t *fa = json_object();
        json_object_set_new(fa, "file", json_string("far.atlas"));
        json_object_set_new(fa, "width", json_integer(b->far.width));
        json_object_set_new(fa, "height", json_integer(b->far.height));
        json_object_set_new(fa, "levels", json_integer(b->far.levels));
        json_object_set_new(fa, "texel", json_pack("[f, f]", b->far.texel[0], b->far.texel[1]));
        json_object_set_new(fa, "bake_distance", jreal(FAR_ATLAS_BAKE_DISTANCE));
        json_object_set_new(fa, "bytes", json_integer((json_int_t)b->far.n));
        json_object_set_new(m, "far_atlas", fa);
    }
    return m;
}

static bool put_sparse(FILE *f, const void *user)
{
    return sparse_write(user, f);
}

static bool put_meshes(FILE *f, const void *user)
{
    return splat_ug_write_meshes(user, f);
}

static bool put_ug_textures(FILE *f, const void *user)
{
    return splat_ug_write_textures(user, f);
}

static bool write_sparse(build *b, const char *dir)
{
    return write_made(b, dir, "painted.sparse", put_sparse, &b->sparse);
}

static bool write_manifest(build *b, const char *dir)
{
    char **tex_names = texture_names(b);
    nonfinite = 0;
    json_t *m = manifest(b, tex_names, dir);
    for (int i = 0; i < b->layout.ntextures; i++)
        free(tex_names[i]);
    free(tex_names);
    if (nonfinite > 0) {
        json_decref(m);
        sg_errorf(b->d, b->loc, SG_E_OVER_LIMIT, "the manifest would hold %d number%s "
                  "that %s not finite (NaN or infinity); the runtime refuses such a pack",
                  nonfinite, nonfinite == 1 ? "" : "s", nonfinite == 1 ? "is" : "are");
        return false;
    }
    char *text = json_dumps(m, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(15));
    json_decref(m);
    if (!text)
        abort();
    size_t n = strlen(text);
    char *withnl = xasprintf("%s\n", text);
    free(text);
    bool ok = write_file(b, dir, "manifest.json", withnl, n + 1);
    free(withnl);
    return ok;
}

static bool write_contents(build *b, const char *dir)
{
    const splat_scene *s = &b->scene;
    const splat_analysis *a = &b->analysis;
    bool ok = true;
    char *sub = xasprintf("%s/shaders", dir);
    if (mkdir(sub, 0777) != 0) {
        write_error(b, sub);
        ok = false;
    }
    free(sub);
    sub = xasprintf("%s/textures", dir);
    if (ok && mkdir(sub, 0777) != 0) {
        write_error(b, sub);
        ok = false;
    }
    free(sub);
    if (!ok)
        return false;

    size_t ntex = (size_t)s->terrain.width * (size_t)s->terrain.height;
    uint8_t *hf = le16(s->terrain.texels, ntex);
    ok = write_file(b, dir, "heightfield.r16", hf, 2 * ntex);
    free(hf);
    if (ok && s->terrain.holes) {
        uint8_t *holes = xcalloc(ntex, 1);
        for (size_t i = 0; i < ntex; i++)
            holes[i] = s->terrain.holes[i] ? 255 : 0;
        ok = write_file(b, dir, "holes.r8", holes, ntex);
        free(holes);
    }

    if (b->sparse_ok) {
        ok = ok && write_sparse(b, dir);
    } else {
        int np = s->desc->npainted;
        uint8_t *painted = xcalloc(ntex * (size_t)np, 1);
        for (int i = 0; i < np; i++)
            if (s->painted && s->painted[i])
                memcpy(painted + ntex * (size_t)i, s->painted[i], ntex);
        ok = ok && write_file(b, dir, "painted.r8", painted, ntex * (size_t)np);
        free(painted);
    }

    size_t total = 0;
    for (int l = 0; l < a->nlevels; l++)
        total += (size_t)a->levels[l].width * (size_t)a->levels[l].height;
    uint16_t *ids = xcalloc(total, sizeof *ids);
    size_t at = 0;
    for (int l = 0; l < a->nlevels; l++) {
        size_t n = (size_t)a->levels[l].width * (size_t)a->levels[l].height;
        memcpy(ids + at, a->levels[l].ids, n * sizeof *ids);
        at += n;
    }
    uint8_t *bytes = le16(ids, total);
    ok = ok && write_file(b, dir, "combos.bin", bytes, 2 * total);
    free(bytes);
    free(ids);

    if (ok && b->ug.nblocks > 0)
        ok = write_made(b, dir, "meshes.bin", put_meshes, &b->ug);
    if (ok && b->ug.ntextures > 0)
        ok = write_made(b, dir, "ugtex.bin", put_ug_textures, &b->ug);
    if (ok && s->vectors.words) {
        /* vectors.bin: "SPLATVEC", u32 version 1, u32 words, the words */
        size_t nw = s->vectors.nwords, n = 16 + 4 * nw;
        uint8_t *vb = xmalloc(n);
        memcpy(vb, "SPLATVEC", 8);
        uint32_t head[2] = { 1, (uint32_t)nw };
        for (size_t i = 0; i < 2 + nw; i++) {
            uint32_t w = i < 2 ? head[i] : s->vectors.words[i - 2];
            for (int k = 0; k < 4; k++)
                vb[8 + 4 * i + k] = (uint8_t)(w >> (8 * k));
        }
        ok = write_file(b, dir, "vectors.bin", vb, n);
        free(vb);
    }
    if (ok && b->far.data)
        ok = write_file(b, dir, "far.atlas", b->far.data, b->far.n);

    for (int i = 0; ok && i < b->njobs; i++) {
        const job *j = &b->jobs[i];
        char *name;
        if (j->kind != JOB_REF && j->kind != JOB_STAND_IN) {   /* SPIR-V only */
            name = glsl_file(j->file, j->stage == SPV_STAGE_FRAGMENT);
            ok = write_compressed(b, dir, name, j->glsl.s, j->glsl.len);
            free(name);
        }
        if (j->glsl_only)
            continue;
        name = spirv_file(j->file);
        ok = ok && write_compressed(b, dir, name, j->words, 4 * j->nwords);
        free(name);
    }

    char **tex_names = texture_names(b);
    for (int i = 0; ok && i < b->layout.ntextures; i++) {
        bool first = true;
        for (int k = 0; k < i; k++)
            first &= strcmp(tex_names[k], tex_names[i]) != 0;
        const char *src = b->layout.src->textures[b->layout.textures[i]].file;
        if (first)
            ok = copy_file(b, src, dir, tex_names[i]);   /* checked: scene.c */
        for (int k = 1, n = first ? build_mip_count(src) : 0; ok && k <= n; k++) {
            char *from = build_mip_path(src, k), *to = build_mip_path(tex_names[i], k);
            ok = copy_file(b, from, dir, to);
            free(from);
            free(to);
        }
    }
    for (int i = 0; i < b->layout.ntextures; i++)
        free(tex_names[i]);
    free(tex_names);
    return ok && write_manifest(b, dir);
}

static int rm_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb; (void)flag; (void)ftw;
    remove(path);
    return 0;
}

static void remove_tree(const char *path)
{
    nftw(path, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
}

/* May `path` be replaced?  Yes if absent, an empty folder, or a pack. */
static bool replaceable(build *b, const char *path, bool *exists)
{
    struct stat sb;
    *exists = lstat(path, &sb) == 0;
    if (!*exists)
        return true;
    if (S_ISDIR(sb.st_mode)) {
        char *mf = xasprintf("%s/manifest.json", path);
        json_t *m = json_load_file(mf, 0, NULL);
        free(mf);
        const char *fmt = m ? json_string_value(json_object_get(m, "format")) : NULL;
        bool pack = fmt && strcmp(fmt, "splatc-pack") == 0;
        json_decref(m);
        if (pack)
            return true;
        if (rmdir(path) == 0) {  /* empty: gone, nothing lost */
            *exists = false;
            return true;
        }
    }
    char msg[PATH_MAX + 64];
    snprintf(msg, sizeof msg, "refusing to replace '%s': it is not a shader pack", path);
    sg_error(b->d, b->loc, SG_E_NOT_A_PACK, msg);
    return false;
}

bool build_check_out(build *b)
{
    const char *out = b->out;
    sg_loc none = { NULL, 0, 0 };
    char *parent = splat_path_dir(out);
    struct stat sb;
    bool ok = true;
    if (stat(parent, &sb) != 0) {
        char why[PATH_MAX + 96];
        snprintf(why, sizeof why, "its folder '%s' does not exist (create it first: "
                 "mkdir -p '%s')", parent, parent);
        sg_error(b->d, none, SG_E_WRITE, out, why);
        ok = false;
    } else if (!S_ISDIR(sb.st_mode)) {
        char why[PATH_MAX + 64];
        snprintf(why, sizeof why, "'%s' is not a folder", parent);
        sg_error(b->d, none, SG_E_WRITE, out, why);
        ok = false;
    } else if (access(parent, W_OK | X_OK) != 0) {
        char why[PATH_MAX + 64];
        snprintf(why, sizeof why, "folder '%s': %s", parent, strerror(errno));
        sg_error(b->d, none, SG_E_WRITE, out, why);
        ok = false;
    } else if (lstat(out, &sb) == 0 && !S_ISDIR(sb.st_mode)) {
        char msg[PATH_MAX + 64];
        snprintf(msg, sizeof msg, "refusing to replace '%s': it is not a shader pack", out);
        sg_error(b->d, b->loc, SG_E_NOT_A_PACK, msg);
        ok = false;
    }
    free(parent);
    return ok;
}

bool build_write_pack(build *b)
{
    const char *out = b->out;
    bool exists;
    if (!replaceable(b, out, &exists))
        return false;
    char *tmp = xasprintf("%s.tmp-XXXXXX", out);
    if (!mkdtemp(tmp)) {
        write_error(b, tmp);
        free(tmp);
        return false;
    }
    chmod(tmp, 0755);
    b->old_pack = exists ? out : NULL;   /* replaceable: a pack, or absent */
    bool ok = write_contents(b, tmp);
    /* the device bake reads the pack written so far, then the atlas and
     * the manifest naming it join it, all before the swap */
    if (ok && b->far.pending)
        ok = build_far_atlas_device(b, tmp) && b->far.data &&
             write_file(b, tmp, "far.atlas", b->far.data, b->far.n) && write_manifest(b, tmp);
    /* everything is written before the swap, the depfile included: a
     * depfile that cannot be written leaves the old pack byte-identical */
    ok = ok && build_write_depfile(b);
    if (ok && exists) {
        /* Swap old and new in one step where the file system can. */
        if (renameat2(AT_FDCWD, tmp, AT_FDCWD, out, RENAME_EXCHANGE) == 0) {
            remove_tree(tmp);  /* now the old pack */
        } else {
            char *old = xasprintf("%s.old-XXXXXX", out);
            if (!mkdtemp(old) || rmdir(old) != 0 || rename(out, old) != 0) {
                write_error(b, out);
                ok = false;
            } else if (rename(tmp, out) != 0) {
                write_error(b, out);
                rename(old, out);  /* put the old pack back */
                ok = false;
            } else {
                remove_tree(old);
            }
            free(old);
        }
    } else if (ok && rename(tmp, out) != 0) {
        write_error(b, out);
        ok = false;
    }
    if (!ok)
        remove_tree(tmp);
    free(tmp);
    return ok;
}
