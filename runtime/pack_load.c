/* pack_load.c — read a shader pack (compiler/PACK.md) and check it before the
 * GPU sees any of it: the manifest's fields and types, every file it names
 * (present, right size), every combination id in combos.bin (in range);
 * each shader is read and checked (spirv-val, its role's interface) on
 * first use (pack_shaders.c).  A bad pack is a message that
 * names the file and the field, never a crash or a validation error.
 * This file holds the entry points; the readers of the pack's parts are
 * in pack_files.c, pack_shaders.c, pack_sections.c and pack_textures.c
 * (pack_internal.h). */
#include "pack_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <jansson.h>
#include <stb_image.h>

bool rt_pack_load(rt_pack *p, const char *dir, rt_error *e)
{
    rt_error local = { 0 };
    if (!e)
        e = &local;
    memset(p, 0, sizeof *p);
    p->dir = rt_pk_strdup(dir);
    char *manifest = rt_pk_join(dir, "manifest.json");
    rt_pk_reader r = { manifest, p, e, -1 };
    rt_error_clear(e);
    json_t *root = NULL;
    bool ok = false;
    if (!p->dir || !manifest)
        goto done;
    r.dirfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (r.dirfd < 0) {
        rt_fail(e, RT_E_IO, "open the pack folder", dir, strerror(errno));
        goto done;
    }
    char why[256];
    size_t mn = 0;
    char *text = (char *)rt_pack_read_file(r.dirfd, "manifest.json", MAX_MANIFEST, &mn, why,
                                           sizeof why);
    if (!text) {
        rt_fail(e, RT_E_IO, "read", manifest, why);
        goto done;
    }
    json_error_t je;
    root = json_loadb(text, mn, JSON_REJECT_DUPLICATES, &je);
    free(text);
    if (!root) {
        rt_fail(e, RT_E_PACK_JSON, manifest, je.line, je.column, je.text);
        goto done;
    }
    const char *format;
    int version, abi;
    if (!rt_pk_get_string(&r, root, "format", "manifest", &format))
        goto done;
    if (strcmp(format, "splatc-pack")) {
        rt_fail(e, RT_E_PACK_VERSION, manifest, "format is not \"splatc-pack\"");
        goto done;
    }
    if (!rt_pk_get_int(&r, root, "version", "manifest", 0, 1 << 20, &version) ||
        !rt_pk_get_int(&r, root, "abi", "manifest", 0, 1 << 20, &abi))
        goto done;
    if (version != SPLAT_PACK_VERSION || abi != SPLAT_ABI_VERSION) {
        char what[128];
        snprintf(what, sizeof what, "pack version %d / abi %d; this runtime reads version %d / "
                 "abi %d", version, abi, SPLAT_PACK_VERSION, SPLAT_ABI_VERSION);
        rt_fail(e, RT_E_PACK_VERSION, manifest, what);
        goto done;
    }
    ok = rt_pk_shaders_open(&r) && rt_pk_read_scene(&r, root) && rt_pk_read_materials(&r, root) &&
         rt_pk_read_params(&r, root) && rt_pk_read_textures(&r, root) &&
         rt_pk_read_painted(&r, root) && rt_pk_read_sites(&r, root) &&
         rt_pk_read_combos(&r, root) && rt_pk_read_quadtree(&r, root) &&
         rt_pk_read_undergrowth(&r, root) &&
         rt_pk_read_far(&r, root) && rt_pk_read_vectors(&r, root);
    if (ok) {
        json_t *vx = rt_pk_get(&r, root, "vertex", "manifest", true);
        ok = vx && rt_pk_read_spirv(&r, vx, "vertex", RT_ROLE_VERTEX, &p->vertex);
    }
    if (ok) {
        json_t *ub = rt_pk_get(&r, root, "uber", "manifest", false);
        if (ub && !json_is_null(ub))
            ok = rt_pk_read_spirv(&r, ub, "uber", RT_ROLE_COMPOSITE, &p->uber) &&
                 rt_pk_read_fragment_glsl(&r, ub, "uber", &p->uber_frag_path) &&
                 rt_pk_read_compute(&r, ub, "compute", "uber", RT_ROLE_COMPUTE,
                                    &p->uber_compute, &p->uber_compute_spirv) &&
                 rt_pk_read_stand_ins(&r, ub);
    }
    /* the shaders: read, validated and checked on first use (pack_shaders.c) */
done:
    if (r.dirfd >= 0)
        close(r.dirfd);
    json_decref(root);
    free(manifest);
    if (!ok) {
        if (!e->msg)
            rt_fail(e, RT_E_PACK_FIELD, dir, "out of memory");
        rt_pack_free(p);
    }
    rt_error_clear(&local);
    return ok;
}

static void free_spirv(rt_spirv *s)
{
    free(s->path);
    free(s->words);   /* the pack's own are in their rt_module */
}

void rt_pack_free(rt_pack *p)
{
    for (int i = 0; i < p->ncameras && p->cameras; i++)
        free(p->cameras[i].name);
    for (int i = 0; i < p->nmaterials && p->materials; i++) {
        free(p->materials[i].name);
        free(p->materials[i].source);
        free_spirv(&p->materials[i].reference);
    }
    for (int i = 0; i < p->nparams && p->params; i++)
        free(p->params[i].name);
    for (int i = 0; i < p->ntextures && p->textures; i++) {
        free(p->textures[i].file);
        stbi_image_free(p->textures[i].rgba);
        for (int k = 0; k < p->textures[i].nmips && p->textures[i].mips; k++)
            stbi_image_free(p->textures[i].mips[k]);
        free(p->textures[i].mips);
    }
    for (int a = 0; a < p->narrays && p->arrays; a++)
        free(p->arrays[a].textures);
    for (int i = 0; i < p->ncombos && p->combos; i++) {
        free(p->combos[i].materials);
        free(p->combos[i].compute.path);
        free(p->combos[i].ug_compute.path);
        free(p->combos[i].glsl.path);
        free(p->combos[i].frag_path);
        free_spirv(&p->combos[i].spirv);
        free_spirv(&p->combos[i].compute_spirv);
        free_spirv(&p->combos[i].ug_spirv);
    }
    for (int i = 0; i < p->nlevels && p->levels; i++)
        free(p->levels[i].ids);
    free(p->holes);
    free_spirv(&p->uber);
    free(p->uber_compute.path);
    free_spirv(&p->uber_compute_spirv);
    for (int k = 0; k < SPLAT_STAND_IN_KINDS; k++)
        free_spirv(&p->stand_in[k]);
    free(p->uber_frag_path);
    for (int i = 0; i < p->ug.ntextures; i++)
        free(p->ug.textures[i].rgba);
    free(p->ug.textures);
    free(p->ug.blocks);
    free(p->ug.meshes);
    free(p->ug.vertices);
    free(p->ug.indices);
    free(p->far.data);
    free(p->vectors);
    free_spirv(&p->vertex);
    free(p->cameras);
    free(p->materials);
    free(p->params);
    free(p->textures);
    free(p->arrays);
    free(p->combos);
    free(p->levels);
    free(p->painted);
    if (p->sparse)
        sparse_free(p->sparse);
    free(p->sparse);
    free(p->heights);
    free(p->name);
    free(p->scene_path);
    free(p->dir);
    rt_pk_shaders_free(p->shaders);
    memset(p, 0, sizeof *p);
}

int rt_pack_material_find(const rt_pack *p, const char *name)
{
    for (int i = 0; i < p->nmaterials; i++)
        if (!strcmp(p->materials[i].name, name))
            return i;
    return -1;
}

int rt_pack_camera_find(const rt_pack *p, const char *name)
{
    for (int i = 0; i < p->ncameras; i++)
        if (!strcmp(p->cameras[i].name, name))
            return i;
    return -1;
}

/* ---- the pack against the device ------------------------------------------ */

static bool limit(const rt_pack *p, const char *what, uint64_t v, const char *name,
                  uint64_t max, rt_error *e)
{
    if (v <= max)
        return true;
    char where[1024], lim[128];
    snprintf(where, sizeof where, "%s/manifest.json", p->dir);
    snprintf(lim, sizeof lim, "the device's %s", name);
    return rt_fail(e, RT_E_PACK_LIMIT, where, what, (unsigned long long)v, lim,
                   (unsigned long long)max);
}

bool rt_pack_check_device(const rt_pack *p, const rt_device *d, rt_error *e)
{
    const VkPhysicalDeviceLimits *L = &d->props.limits;
    const uint32_t dim = L->maxImageDimension2D, layers = L->maxImageArrayLayers;
    if (!limit(p, "the heightfield's width", (uint64_t)p->hf_width, "maxImageDimension2D", dim, e) ||
        !limit(p, "the heightfield's height", (uint64_t)p->hf_height, "maxImageDimension2D", dim, e))
        return false;
    for (int i = 0; i < p->ntextures; i++) {
        char what[256];
        snprintf(what, sizeof what, "textures[%d] (%s): the larger side", i, p->textures[i].file);
        int side = p->textures[i].width > p->textures[i].height ? p->textures[i].width
                                                                : p->textures[i].height;
        if (!limit(p, what, (uint64_t)side, "maxImageDimension2D", dim, e))
            return false;
    }
    if (p->painted && !limit(p, "the dense painted layer count", (uint64_t)p->npainted,
                             "maxImageArrayLayers", layers, e))
        return false;
    if (p->sparse) {
        const sparse_masks *s = p->sparse;
        int side = s->atlas_width > s->atlas_height ? s->atlas_width : s->atlas_height;
        int cells = s->cells_x > s->cells_z ? s->cells_x : s->cells_z;
        if (!limit(p, "the painted atlas's larger side", (uint64_t)side, "maxImageDimension2D",
                   dim, e) ||
            !limit(p, "the painted index's larger side", (uint64_t)cells, "maxImageDimension2D",
                   dim, e) ||
            !limit(p, "the painted index's layer count", (uint64_t)s->layers,
                   "maxImageArrayLayers", layers, e))
            return false;
    }
    if (p->has_destruction) {
        double side = p->destr_size[0] > p->destr_size[1] ? p->destr_size[0] : p->destr_size[1];
        if (!limit(p, "the destruction grid's cells per side", (uint64_t)ceil(side / p->destr_cell),
                   "maxImageDimension2D", dim, e))
            return false;
    }
    for (int a = 0; a < p->narrays; a++) {
        char what[96];
        snprintf(what, sizeof what, "texture array %d's layer count", a);
        if (!limit(p, what, (uint64_t)p->arrays[a].nlayers, "maxImageArrayLayers", layers, e))
            return false;
    }
    /* fragment stage: set 0's six samplers and set 1's texture arrays */
    uint64_t samplers = 6 + (uint64_t)p->narrays;
    return limit(p, "the fragment stage's sampler count (6 + texture arrays)", samplers,
                 "maxPerStageDescriptorSamplers", L->maxPerStageDescriptorSamplers, e) &&
           limit(p, "the fragment stage's sampled image count (6 + texture arrays)", samplers,
                 "maxPerStageDescriptorSampledImages", L->maxPerStageDescriptorSampledImages, e) &&
           limit(p, "params_size", p->params_size, "maxUniformBufferRange",
                 L->maxUniformBufferRange, e) &&
           limit(p, "the push-constant block (bytes)", sizeof(splat_push),
                 "maxPushConstantsSize", L->maxPushConstantsSize, e);
}
