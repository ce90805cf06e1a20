/* pack_textures.c — the pack's textures (compiler/PACK.md "Textures and
 * their mip levels", "Texture arrays") and its painted masks
 * (painted.sparse or painted.r8), checked against the limits before
 * anything is decoded or allocated (pack_internal.h). */
#include "pack_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb_image.h>

/* "X.mipK.ext" beside "X.ext" (texgen.h's contract, as the pack writer
 * names them). */
static char *mip_name(const char *file, int k)
{
    const char *slash = strrchr(file, '/'), *dot = strrchr(file, '.');
    size_t stem = dot && (!slash || dot > slash) ? (size_t)(dot - file) : strlen(file);
    const char *ext = file + stem;
    size_t n = strlen(file) + 16;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%.*s.mip%d%s", (int)stem, file, k, ext);
    return s;
}

/* The stored mip levels of texture `tx` (manifest "mips": how many files);
 * each must have the size of its level. */
static bool read_mips(rt_pk_reader *r, json_t *t, const char *where, rt_pack_texture *tx)
{
    int n, side = tx->width > tx->height ? tx->width : tx->height, levels = 1;
    while (side >> levels)
        levels++;   /* floor(log2(side)) + 1 levels down to 1x1 */
    if (!rt_pk_get_int(r, t, "mips", where, 1, 31, &n))
        return false;
    if (n + 1 > levels) {
        char what[160];
        snprintf(what, sizeof what, "is %d: %d levels with the base, more than the %d "
                 "(log2(%d) + 1) a %dx%d texture has", n, n + 1, levels, side, tx->width,
                 tx->height);
        char w[96];
        snprintf(w, sizeof w, "%s.mips", where);
        return rt_pk_field_fail(r, w, what);
    }
    tx->mips = calloc((size_t)n, sizeof *tx->mips);
    if (!tx->mips)
        return rt_fail(r->e, RT_E_VULKAN, "textures", "out of memory");
    tx->nmips = n;
    for (int k = 1; k <= n; k++) {
        char *file = mip_name(tx->file, k), field[96];
        if (!file)
            return rt_fail(r->e, RT_E_VULKAN, "textures", "out of memory");
        snprintf(field, sizeof field, "%s.mips[%d]", where, k);
        size_t bytes;
        uint8_t *data = rt_pk_pack_file(r, field, file, 0, MAX_IMAGE, &bytes);
        int w = 0, h = 0, ch;
        if (data && stbi_info_from_memory(data, (int)bytes, &w, &h, &ch) &&
            w == (tx->width >> k > 0 ? tx->width >> k : 1) &&
            h == (tx->height >> k > 0 ? tx->height >> k : 1))
            tx->mips[k - 1] = stbi_load_from_memory(data, (int)bytes, &w, &h, &ch, 4);
        free(data);
        int ww = tx->width >> k > 0 ? tx->width >> k : 1;
        int wh = tx->height >> k > 0 ? tx->height >> k : 1;
        bool ok = data && tx->mips[k - 1];
        if (data && !ok && (w != ww || h != wh) && w > 0) {
            char msg[96];
            snprintf(msg, sizeof msg, "is %dx%d, its level needs %dx%d", w, h, ww, wh);
            rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file, msg);
        } else if (data && !ok)
            rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file,
                    "is not an image stb_image can read");
        else if (ok && (w != ww || h != wh)) {
            char msg[96];
            snprintf(msg, sizeof msg, "is %dx%d, its level needs %dx%d", w, h, ww, wh);
            rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file, msg);
            ok = false;
        }
        free(file);
        if (!ok)
            return false;
    }
    return true;
}

/* The textures' arrays (binding 1 + a, layer l): the bindings dense from
 * 1, each array's layers dense from 0, one texture a layer, and its
 * textures alike in size, mip levels and sampler state. */
static bool texture_arrays(rt_pk_reader *r)
{
    rt_pack *p = r->p;
    for (int i = 0; i < p->ntextures; i++) {
        int a = (int)p->textures[i].binding - SPLAT_BIND_TEXTURE0;
        if (a + 1 > p->narrays)
            p->narrays = a + 1;
    }
    p->arrays = calloc((size_t)p->narrays + 1, sizeof *p->arrays);
    if (!p->arrays)
        return rt_pk_field_fail(r, "textures:", "out of memory");
    for (int a = 0; a < p->narrays; a++) {
        rt_pack_array *A = &p->arrays[a];
        for (int i = 0; i < p->ntextures; i++)
            if ((int)p->textures[i].binding == SPLAT_BIND_TEXTURE0 + a)
                A->nlayers++;
        char where[64];
        snprintf(where, sizeof where, "textures (binding %d)", SPLAT_BIND_TEXTURE0 + a);
        if (!A->nlayers)
            return rt_pk_field_fail(r, where,
                                    "no texture has this binding: the bindings must be dense");
        A->textures = calloc((size_t)A->nlayers, sizeof *A->textures);
        if (!A->textures)
            return rt_pk_field_fail(r, "textures:", "out of memory");
        for (int l = 0; l < A->nlayers; l++)
            A->textures[l] = -1;
        for (int i = 0; i < p->ntextures; i++) {
            const rt_pack_texture *t = &p->textures[i];
            if ((int)t->binding != SPLAT_BIND_TEXTURE0 + a)
                continue;
            if (t->layer >= A->nlayers || A->textures[t->layer] >= 0)
                return rt_pk_field_fail(r, where, "its layers must be 0, 1, … once each");
            A->textures[t->layer] = i;
            const rt_pack_texture *u = &p->textures[A->textures[0] >= 0 ? A->textures[0] : i];
            if (t->width != u->width || t->height != u->height || t->nmips != u->nmips ||
                t->linear != u->linear || t->mip_linear != u->mip_linear ||
                t->srgb != u->srgb || t->wrap != u->wrap)
                return rt_pk_field_fail(r, where, "its textures differ in size, mip levels or "
                                        "sampler state");
        }
    }
    return true;
}

bool rt_pk_read_textures(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *ts = rt_pk_get_array(r, root, "textures", "manifest", false);
    if (!ts)
        return !r->e->msg;
    p->ntextures = (int)json_array_size(ts);
    if (p->ntextures > SPLAT_MAX_TEXTURES) {
        char what[96];
        snprintf(what, sizeof what, "has %d entries, over the pack limit of %d", p->ntextures,
                 SPLAT_MAX_TEXTURES);
        p->ntextures = 0;
        return rt_pk_field_fail(r, "textures:", what);
    }
    p->textures = calloc((size_t)p->ntextures + 1, sizeof *p->textures);
    if (!p->textures)
        return false;
    for (int i = 0; i < p->ntextures; i++) {
        json_t *t = json_array_get(ts, (size_t)i);
        rt_pack_texture *tx = &p->textures[i];
        char where[64];
        snprintf(where, sizeof where, "textures[%d]", i);
        const char *file, *filter = "linear", *mip = "linear", *wrap = "repeat";
        int binding, layer = 0;
        if (!rt_pk_get_string(r, t, "file", where, &file) ||
            !rt_pk_get_int(r, t, "binding", where, SPLAT_BIND_TEXTURE0,
                           SPLAT_BIND_TEXTURE0 + SPLAT_MAX_TEXTURE_ARRAYS - 1, &binding))
            return false;
        if (rt_pk_get(r, t, "layer", where, false) &&
            !rt_pk_get_int(r, t, "layer", where, 0, SPLAT_MAX_ARRAY_LAYERS - 1, &layer))
            return false;
        tx->layer = layer;
        if (rt_pk_get(r, t, "filter", where, false) &&
            !rt_pk_get_string(r, t, "filter", where, &filter))
            return false;
        if (rt_pk_get(r, t, "mip", where, false) && !rt_pk_get_string(r, t, "mip", where, &mip))
            return false;
        if (rt_pk_get(r, t, "wrap", where, false) && !rt_pk_get_string(r, t, "wrap", where, &wrap))
            return false;
        tx->file = rt_pk_strdup(file);
        tx->binding = (uint32_t)binding;
        int f = ir_filter_by_name(filter), mf = ir_filter_by_name(mip), wr = ir_wrap_by_name(wrap);
        if (f < 0 || mf < 0 || wr < 0)   /* ir.h's sampler names */
            return rt_pk_field_fail(r, where, "unknown filter, mip or wrap name");
        tx->linear = f == IR_FILTER_LINEAR;
        tx->mip_linear = mf == IR_FILTER_LINEAR;
        tx->wrap = rt_sampler_wrap((ir_wrap)wr);
        json_t *srgb = rt_pk_get(r, t, "srgb", where, false);
        tx->srgb = json_is_true(srgb);
        char field[96];
        snprintf(field, sizeof field, "%s.file", where);
        size_t n;
        uint8_t *data = rt_pk_pack_file(r, field, file, 0, MAX_IMAGE, &n);
        if (!data)
            return false;
        int ch, w, h;
        /* the size from the header before anything is decoded */
        if (stbi_info_from_memory(data, (int)n, &w, &h, &ch) &&
            (w > SPLAT_MAX_TEXTURE || h > SPLAT_MAX_TEXTURE)) {
            free(data);
            char msg[160];
            snprintf(msg, sizeof msg, "is %dx%d, over the pack limit of %d texels per side", w,
                     h, SPLAT_MAX_TEXTURE);
            return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file, msg);
        }
        tx->rgba = stbi_load_from_memory(data, (int)n, &tx->width, &tx->height, &ch, 4);
        free(data);
        if (!tx->rgba)
            return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file,
                           "is not an image stb_image can read");
        if (rt_pk_get(r, t, "mips", where, false) && !read_mips(r, t, where, tx))
            return false;
    }
    return texture_arrays(r);
}

bool rt_pk_read_painted(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *pa = rt_pk_get_array(r, root, "painted", "manifest", false);
    if (!pa && r->e->msg)
        return false;
    p->npainted = pa ? (int)json_array_size(pa) : 0;
    if (p->npainted > SPLAT_MAX_PAINTED) {
        char what[96];
        snprintf(what, sizeof what, "has %d masks, over the pack limit of %d", p->npainted,
                 SPLAT_MAX_PAINTED);
        return rt_pk_field_fail(r, "painted:", what);
    }
    /* sparse quad-tree (painted_upload.c) unless painted_format says dense;
     * absent: dense (PACK.md) */
    const char *fmt = "dense", *file = "painted.r8";
    if (rt_pk_get(r, root, "painted_format", "manifest", false) &&
        !rt_pk_get_string(r, root, "painted_format", "manifest", &fmt))
        return false;
    if (strcmp(fmt, "dense") && strcmp(fmt, "bc4") && strcmp(fmt, "r8"))
        return rt_pk_field_fail(r, "painted_format:", "must be \"dense\", \"bc4\" or \"r8\"");
    bool dense = !strcmp(fmt, "dense");
    if ((!dense || rt_pk_get(r, root, "painted_file", "manifest", false)) &&
        !rt_pk_get_string(r, root, "painted_file", "manifest", &file))
        return false;
    if (dense && p->npainted == 0)
        return true;   /* no masks: one zero layer (terrain_upload.c) */
    /* a sparse pack's shaders sample the atlas even without masks (the
     * file then holds none), so it is read and bound the same way */
    if (!dense) {
        size_t n = 0;
        uint8_t *data = rt_pk_pack_file(r, "painted_file", file, 0, MAX_BINARY, &n);
        bool ok = data && rt_painted_read(p, r->manifest, file, data, n, r->e);
        free(data);
        if (ok && (p->sparse->format == SPARSE_BC4) != !strcmp(fmt, "bc4")) {
            char what[160];
            snprintf(what, sizeof what, "holds %s masks, the manifest's painted_format is %s",
                     p->sparse->format == SPARSE_BC4 ? "bc4" : "r8", fmt);
            ok = rt_fail(r->e, RT_E_PACK_FILE, r->manifest, "painted_file", file, what);
        }
        return ok;
    }
    size_t bytes = (size_t)p->npainted * (size_t)p->hf_width * (size_t)p->hf_height;
    p->painted = rt_pk_pack_file(r, "painted_file", file, bytes, 0, NULL);
    return p->painted != NULL;
}
