/* painted_upload.c — the painted masks of a sparse pack (compiler/sparse.h) on the
 * GPU: painted.sparse (read by pack_load.c) parsed with sparse_read and checked against the
 * manifest, then three images for set 0 (abi.h, SPLAT_PAINTED_SPARSE):
 *   binding 2  atlas  BC4_UNORM_BLOCK (R8_UNORM where the device has no BC
 *              textures: the blocks decoded on the CPU, rounded to 8 bits,
 *              so within 1/510 of the BC4 values the analysis bounded)
 *   binding 5  index  RGBA16_UINT 2D array, one layer per four masks
 *   binding 6  level  RGBA8_UINT, same shape
 * Sampled with the linear clamp sampler (atlas) and texelFetch (index and
 * level: the sampler does not matter). */
#include "rt_internal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static void fill_info(sparse_masks *s);

bool rt_painted_read(rt_pack *p, const char *manifest, const char *file,
                     const uint8_t *data, size_t n, rt_error *e)
{
    p->sparse = calloc(1, sizeof *p->sparse);
    sparse_error err;
    if (!p->sparse || !sparse_read(p->sparse, data, n, "", &err)) {
        /* "'' is not a sparse mask file: …" read as "which is not …" */
        const char *why = !p->sparse ? "does not fit in memory"
                        : !strncmp(err.msg, "'' ", 3) ? err.msg + 3 : err.msg;
        rt_fail(e, RT_E_PACK_FILE, manifest, "painted_file", file, why);
        free(p->sparse);
        p->sparse = NULL;
        return false;
    }
    const sparse_masks *s = p->sparse;
    if (s->width != p->hf_width || s->height != p->hf_height || s->nmasks != p->npainted) {
        char what[256];
        snprintf(what, sizeof what, "holds %d masks of %dx%d texels, the manifest %d of %dx%d",
                 s->nmasks, s->width, s->height, p->npainted, p->hf_width, p->hf_height);
        rt_fail(e, RT_E_PACK_FILE, manifest, "painted_file", file, what);
        sparse_free(p->sparse);
        free(p->sparse);
        p->sparse = NULL;
        return false;
    }
    fill_info(p->sparse);
    return true;
}

/* The per-mask figures sparse_read does not store, recounted from the
 * index and level data for --stats (the reduction error is not in the
 * file: NaN, printed as "nan"). */
static void fill_info(sparse_masks *s)
{
    s->info = calloc((size_t)(s->nmasks ? s->nmasks : 1), sizeof *s->info);
    if (!s->info)
        return;
    size_t ncell = (size_t)s->cells_x * s->cells_z;
    for (int m = 0; m < s->nmasks; m++) {
        sparse_mask_info *in = &s->info[m];
        char name[32];
        snprintf(name, sizeof name, "mask %d", m);
        in->name = strdup(name);
        in->reduce_error = NAN;
        /* a placed mask's own cells, the first of each row of the grid */
        for (size_t c = 0; c < ncell; c++) {
            if ((int)(c % (size_t)s->cells_x) >= s->place[m].cells_x ||
                (int)(c / (size_t)s->cells_x) >= s->place[m].cells_z)
                continue;
            size_t at = ((size_t)(m / 4) * ncell + c) * 4 + (size_t)(m % 4);
            uint16_t e = s->index[at];
            in->const0 += e == SPARSE_CONST0;
            in->const1 += e == SPARSE_CONST1;
            if (e == SPARSE_CONST0 || e == SPARSE_CONST1)
                continue;
            in->stored++;
            in->reduced += s->level[at] > 0;
            in->max_level = s->level[at] > in->max_level ? s->level[at] : in->max_level;
        }
    }
}

/* The BC4 atlas as R8 bytes (devices without BC textures). */
static uint8_t *decode_bc4(const sparse_masks *s)
{
    size_t w = (size_t)s->atlas_width, h = (size_t)s->atlas_height;
    uint8_t *out = malloc(w * h);
    if (!out)
        return NULL;
    for (size_t bz = 0; bz < h / 4; bz++)
        for (size_t bx = 0; bx < w / 4; bx++) {
            float v[16];
            sparse_bc4_decode(s->atlas + (bz * (w / 4) + bx) * 8, v);
            for (int j = 0; j < 16; j++)
                out[(bz * 4 + (size_t)(j / 4)) * w + bx * 4 + (size_t)(j % 4)] =
                    (uint8_t)lrintf(v[j] * 255.0f);
        }
    return out;
}

bool rt_painted_upload(rt_device *d, const rt_pack *p, rt_image *atlas,
                       rt_image *index, rt_image *level, rt_error *e)
{
    const sparse_masks *s = p->sparse;
    const VkImageUsageFlags use = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    const VkFormatFeatureFlags filt = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                                      VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
    uint32_t aw = (uint32_t)s->atlas_width, ah = (uint32_t)s->atlas_height;
    bool bc4 = s->format == SPARSE_BC4 && d->bc &&
               rt_format_supports(d, VK_FORMAT_BC4_UNORM_BLOCK, filt);
    uint8_t *decoded = NULL;
    const void *bytes = s->atlas;
    size_t nbytes = s->atlas_bytes;
    if (s->format == SPARSE_BC4 && !bc4) {
        decoded = decode_bc4(s);
        if (!decoded)
            return rt_fail(e, RT_E_VULKAN, "painted atlas", "out of memory");
        bytes = decoded;
        nbytes = (size_t)aw * ah;
    }
    bool ok = rt_image_create(d, aw, ah, 1, false, 1,
                              bc4 ? VK_FORMAT_BC4_UNORM_BLOCK : VK_FORMAT_R8_UNORM, use,
                              VK_IMAGE_ASPECT_COLOR_BIT, atlas, e) &&
              rt_image_upload(d, atlas, bytes, nbytes, e);
    free(decoded);
    if (!ok)
        return false;
    const VkFormatFeatureFlags fetch = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
    if (!rt_format_supports(d, VK_FORMAT_R16G16B16A16_UINT, fetch) ||
        !rt_format_supports(d, VK_FORMAT_R8G8B8A8_UINT, fetch))
        return rt_fail(e, RT_E_NO_FORMAT, "sample RGBA16_UINT and RGBA8_UINT images");
    uint32_t cx = (uint32_t)s->cells_x, cz = (uint32_t)s->cells_z, L = (uint32_t)s->layers;
    size_t cells = (size_t)cx * cz * L * 4;
    return rt_image_create(d, cx, cz, L, true, 1, VK_FORMAT_R16G16B16A16_UINT, use,
                           VK_IMAGE_ASPECT_COLOR_BIT, index, e) &&
           rt_image_upload(d, index, s->index, cells * 2, e) &&
           rt_image_create(d, cx, cz, L, true, 1, VK_FORMAT_R8G8B8A8_UINT, use,
                           VK_IMAGE_ASPECT_COLOR_BIT, level, e) &&
           rt_image_upload(d, level, s->level, cells, e);
}

void rt_painted_print_stats(const rt_pack *p, FILE *out)
{
    if (p->sparse) {
        sparse_print_stats(p->sparse, out);
        return;
    }
    fprintf(out, "painted masks: %d stored dense (R8 array): %zu B\n", p->npainted,
            (size_t)p->npainted * (size_t)p->hf_width * (size_t)p->hf_height);
}
