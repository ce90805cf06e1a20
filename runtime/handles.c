/* handles.c — the public handles of splatrt.h: rt_device_open/close and
 * rt_pack_open/close allocate the structs that rt_internal.h defines
 * around the library's in-place rt_device_create and rt_pack_load, and the
 * accessors answer what tools and tests ask of a device or a pack
 * (counts, names, camera presets, lighting) without their fields.
 */
#include "rt_internal.h"

#include <stdlib.h>
#include <string.h>

bool rt_device_open(const rt_device_desc *desc, rt_device **out, rt_error *e)
{
    *out = NULL;
    rt_device_desc none = { 0 };
    rt_device *d = calloc(1, sizeof *d);
    if (!d)
        return rt_fail(e, RT_E_IO, "allocate", "a device", "out of memory");
    if (!rt_device_create(d, desc ? desc : &none, e)) {
        free(d);
        return false;
    }
    *out = d;
    return true;
}

int rt_device_close(rt_device *d)
{
    if (!d)
        return 0;
    rt_device_destroy(d);   /* keeps the count readable after teardown */
    int messages = d->validating ? d->messages : 0;
    free(d);
    return messages;
}

void rt_device_info_get(const rt_device *d, rt_device_info *out)
{
    *out = (rt_device_info){
        .name = d->props.deviceName,
        .cpu = d->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU,
        .wireframe = d->wireframe,
        .bc = d->bc,
        .count_fragments = d->count_fragments,
        .validating = d->validating,
    };
}

bool rt_pack_open(const char *dir, rt_pack **out, rt_error *e)
{
    *out = NULL;
    rt_pack *p = calloc(1, sizeof *p);
    if (!p)
        return rt_fail(e, RT_E_IO, "allocate", dir, "out of memory");
    if (!rt_pack_load(p, dir, e)) {
        free(p);
        return false;
    }
    *out = p;
    return true;
}

void rt_pack_close(rt_pack *p)
{
    if (!p)
        return;
    rt_pack_free(p);
    free(p);
}

void rt_pack_info_get(const rt_pack *p, rt_pack_info *out)
{
    bool reference = p->nmaterials > 0;
    for (int i = 0; i < p->nmaterials; i++)
        reference = reference && rt_spirv_present(&p->materials[i].reference);
    *out = (rt_pack_info){
        .name = p->name,
        .dir = p->dir,
        .scene_path = p->scene_path,
        .hf_width = p->hf_width,
        .hf_height = p->hf_height,
        .size = { p->size[0], p->size[1] },
        .max_height = p->max_height,
        .height_offset = p->height_offset,
        .ncameras = p->ncameras,
        .nmaterials = p->nmaterials,
        .nparams = p->nparams,
        .ntextures = p->ntextures,
        .ncombos = p->ncombos,
        .nbase = p->nbase,
        .nlevels = p->nlevels,
        .npainted = p->npainted,
        .nsites = p->nsites,
        .has_holes = p->holes != NULL,
        .has_destruction = p->has_destruction,
        .has_uber = rt_spirv_present(&p->uber),
        .has_far_atlas = p->far.data != NULL,
        .has_undergrowth = p->ug.nslots > 0,
        .has_vectors = p->vectors != NULL,
        .ug_slots = p->ug.nslots,
        .ug_blocks = p->ug.nblocks,
        .has_reference = reference,
        .has_compute = p->uber_compute.mod != NULL,
        .far_width = p->far.width,
        .far_height = p->far.height,
        .far_levels = p->far.levels,
        .far_texel = { p->far.texel[0], p->far.texel[1] },
        .far_bytes = p->far.data ? p->far.n - FAR_ATLAS_HEADER : 0,
    };
    out->shaders = rt_pack_shader_count(p, &out->shaders_read);
}

const char *rt_pack_material_name(const rt_pack *p, int i)
{
    return i >= 0 && i < p->nmaterials ? p->materials[i].name : NULL;
}

const char *rt_pack_camera_name(const rt_pack *p, int i)
{
    return i >= 0 && i < p->ncameras ? p->cameras[i].name : NULL;
}

bool rt_pack_camera_at(const rt_pack *p, int i, double position[3], double look[3])
{
    if (i < 0 || i >= p->ncameras)
        return false;
    memcpy(position, p->cameras[i].position, sizeof p->cameras[i].position);
    memcpy(look, p->cameras[i].look, sizeof p->cameras[i].look);
    return true;
}

const rt_light *rt_pack_light(const rt_pack *p)
{
    return &p->light;
}

const uint16_t *rt_pack_heights(const rt_pack *p)
{
    return p->heights;
}
