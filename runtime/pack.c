/* pack.c — read a shader pack (compiler/PACK.md) and check it before the
 * GPU sees any of it: the manifest's fields and types, every file it names
 * (present, right size), every SPIR-V module (spirv-val), every
 * combination id in combos.bin (in range).  A bad pack is a message that
 * names the file and the field, never a crash or a validation error. */
#include "splatrt.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>
#include <stb_image.h>

typedef struct reader {
    const char *manifest;   /* path, for messages */
    rt_pack    *p;
    rt_error   *e;
} reader;

static char *dup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static char *join(const char *dir, const char *rel)
{
    size_t n = strlen(dir) + strlen(rel) + 2;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s/%s", dir, rel);
    return s;
}

/* Read a whole file; NULL with errno set on failure. */
static uint8_t *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    uint8_t *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n == cap) {
            cap = cap ? cap * 2 : 65536;
            uint8_t *nb = realloc(buf, cap);
            if (!nb) {
                free(buf);
                fclose(f);
                errno = ENOMEM;
                return NULL;
            }
            buf = nb;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0)
            break;
    }
    bool err = ferror(f);
    fclose(f);
    if (err) {
        free(buf);
        errno = EIO;
        return NULL;
    }
    *size = n;
    return buf;
}

/* ---- typed field access with messages naming the field ------------------ */

static bool field_fail(reader *r, const char *where, const char *what)
{
    char msg[512];
    snprintf(msg, sizeof msg, "%s %s", where, what);
    return rt_fail(r->e, RT_E_PACK_FIELD, r->manifest, msg);
}

static json_t *get(reader *r, json_t *obj, const char *key, const char *where,
                   bool required)
{
    json_t *v = json_is_object(obj) ? json_object_get(obj, key) : NULL;
    if (!v && required) {
        char w[256];
        snprintf(w, sizeof w, "%s: missing field", where);
        field_fail(r, w, key);
    }
    return v;
}

static bool get_number(reader *r, json_t *obj, const char *key, const char *where,
                       double *out)
{
    json_t *v = get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_number(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        return field_fail(r, w, "must be a number");
    }
    *out = json_number_value(v);
    return true;
}

static bool get_int(reader *r, json_t *obj, const char *key, const char *where,
                    int lo, int hi, int *out)
{
    json_t *v = get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi) {
        char w[256], what[96];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        snprintf(what, sizeof what, "must be an integer in [%d, %d]", lo, hi);
        return field_fail(r, w, what);
    }
    *out = (int)json_integer_value(v);
    return true;
}

static bool get_string(reader *r, json_t *obj, const char *key, const char *where,
                       const char **out)
{
    json_t *v = get(r, obj, key, where, true);
    if (!v)
        return false;
    if (!json_is_string(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        return field_fail(r, w, "must be a string");
    }
    *out = json_string_value(v);
    return true;
}

static json_t *get_array(reader *r, json_t *obj, const char *key, const char *where,
                         bool required)
{
    json_t *v = get(r, obj, key, where, required);
    if (v && !json_is_array(v)) {
        char w[256];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        field_fail(r, w, "must be an array");
        return NULL;
    }
    return v;
}

static bool get_vec(reader *r, json_t *obj, const char *key, const char *where,
                    int n, double *out)
{
    json_t *a = get_array(r, obj, key, where, true);
    if (!a)
        return false;
    if ((int)json_array_size(a) != n) {
        char w[256], what[64];
        snprintf(w, sizeof w, "%s.%s:", where, key);
        snprintf(what, sizeof what, "must have %d numbers", n);
        return field_fail(r, w, what);
    }
    for (int i = 0; i < n; i++) {
        json_t *v = json_array_get(a, (size_t)i);
        if (!json_is_number(v)) {
            char w[256];
            snprintf(w, sizeof w, "%s.%s[%d]:", where, key, i);
            return field_fail(r, w, "must be a number");
        }
        out[i] = json_number_value(v);
    }
    return true;
}

/* A file of the pack: present, of the expected size if size > 0. */
static uint8_t *pack_file(reader *r, const char *field, const char *rel,
                          size_t want, size_t *got)
{
    if (strstr(rel, "..") || rel[0] == '/') {
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, "is outside the pack");
        return NULL;
    }
    char *path = join(r->p->dir, rel);
    size_t n = 0;
    uint8_t *data = path ? slurp(path, &n) : NULL;
    free(path);
    if (!data) {
        char why[160];
        snprintf(why, sizeof why, "cannot be read (%s)", strerror(errno));
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, why);
        return NULL;
    }
    if (want && n != want) {
        char why[160];
        snprintf(why, sizeof why, "has %zu bytes, expected %zu", n, want);
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, why);
        free(data);
        return NULL;
    }
    if (got)
        *got = n;
    return data;
}

/* {"glsl": …, "spirv": …} → a validated SPIR-V module. */
static bool read_spirv(reader *r, json_t *obj, const char *where, rt_spirv *out)
{
    const char *rel;
    if (!get_string(r, obj, "spirv", where, &rel))
        return false;
    char field[256];
    snprintf(field, sizeof field, "%s.spirv", where);
    size_t n = 0;
    uint8_t *data = pack_file(r, field, rel, 0, &n);
    if (!data)
        return false;
    out->path = dup(rel);
    if (n % 4) {
        free(data);
        char path[512];
        snprintf(path, sizeof path, "%s/%s", r->p->dir, rel);
        return rt_fail(r->e, RT_E_PACK_SPIRV, path, "size is not a multiple of 4 bytes");
    }
    out->words = (uint32_t *)data;
    out->nwords = n / 4;
    char path[512];
    snprintf(path, sizeof path, "%s/%s", r->p->dir, rel);
    return rt_spirv_validate(out->words, out->nwords, path, r->e);
}

/* ---- sections ------------------------------------------------------------ */

static bool read_scene(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *scene = get(r, root, "scene", "manifest", true);
    if (!scene)
        return false;
    const char *name = "";
    json_t *nm = get(r, scene, "name", "scene", false);
    if (json_is_string(nm))
        name = json_string_value(nm);
    p->name = dup(name);
    json_t *sp = get(r, scene, "source", "scene", false);
    if (json_is_string(sp))
        p->scene_path = dup(json_string_value(sp));

    json_t *hf = get(r, scene, "heightfield", "scene", true);
    const char *file;
    if (!hf || !get_string(r, hf, "file", "scene.heightfield", &file) ||
        !get_int(r, hf, "width", "scene.heightfield", 1, 1 << 16, &p->hf_width) ||
        !get_int(r, hf, "height", "scene.heightfield", 1, 1 << 16, &p->hf_height))
        return false;
    double size[2];
    if (!get_vec(r, scene, "size", "scene", 2, size) ||
        !get_number(r, scene, "max_height", "scene", &p->max_height))
        return false;
    if (!(size[0] > 0 && size[1] > 0))
        return field_fail(r, "scene.size:", "must be positive");
    p->size[0] = size[0];
    p->size[1] = size[1];
    p->height_offset = 0;
    if (get(r, scene, "height_offset", "scene", false) &&
        !get_number(r, scene, "height_offset", "scene", &p->height_offset))
        return false;
    if (!get_int(r, scene, "cell_texels", "scene", 1, 1 << 16, &p->cell_texels))
        return false;

    size_t texels = (size_t)p->hf_width * (size_t)p->hf_height;
    uint8_t *raw = pack_file(r, "scene.heightfield.file", file, texels * 2, NULL);
    if (!raw)
        return false;
    p->heights = malloc(texels * sizeof *p->heights);
    if (!p->heights) {
        free(raw);
        return field_fail(r, "heightfield:", "out of memory");
    }
    for (size_t i = 0; i < texels; i++)
        p->heights[i] = (uint16_t)(raw[2 * i] | raw[2 * i + 1] << 8);
    free(raw);

    /* the destructible area (destruction.c), or null */
    json_t *dd = get(r, scene, "destruction", "scene", false);
    if (dd && !json_is_null(dd)) {
        if (!get_vec(r, dd, "origin", "scene.destruction", 2, p->destr_origin) ||
            !get_vec(r, dd, "size", "scene.destruction", 2, p->destr_size) ||
            !get_number(r, dd, "cell_size", "scene.destruction", &p->destr_cell))
            return false;
        if (!(p->destr_cell > 0) || !(p->destr_size[0] > 0) || !(p->destr_size[1] > 0))
            return field_fail(r, "scene.destruction:", "needs a positive size and cell_size");
        p->has_destruction = true;
    }
    json_t *cams = get_array(r, scene, "cameras", "scene", false);
    if (cams) {
        p->ncameras = (int)json_array_size(cams);
        p->cameras = calloc((size_t)p->ncameras + 1, sizeof *p->cameras);
        for (int i = 0; i < p->ncameras; i++) {
            json_t *c = json_array_get(cams, (size_t)i);
            char where[64];
            snprintf(where, sizeof where, "scene.cameras[%d]", i);
            const char *cn;
            if (!get_string(r, c, "name", where, &cn) ||
                !get_vec(r, c, "position", where, 3, p->cameras[i].position) ||
                !get_vec(r, c, "look", where, 3, p->cameras[i].look))
                return false;
            p->cameras[i].name = dup(cn);
        }
    }
    return true;
}

static bool read_materials(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *mats = get_array(r, root, "materials", "manifest", true);
    if (!mats)
        return false;
    p->nmaterials = (int)json_array_size(mats);
    if (p->nmaterials == 0)
        return field_fail(r, "materials:", "is empty");
    p->materials = calloc((size_t)p->nmaterials, sizeof *p->materials);
    for (int i = 0; i < p->nmaterials; i++) {
        json_t *m = json_array_get(mats, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "materials[%d]", i);
        const char *name;
        if (!get_string(r, m, "name", where, &name))
            return false;
        p->materials[i].name = dup(name);
        json_t *src = get(r, m, "source", where, false);
        if (json_is_string(src))
            p->materials[i].source = dup(json_string_value(src));
        json_t *ref = get(r, m, "reference", where, false);
        if (ref && !json_is_null(ref)) {
            char w2[96];
            snprintf(w2, sizeof w2, "%s.reference", where);
            if (!read_spirv(r, ref, w2, &p->materials[i].reference))
                return false;
        }
    }
    return true;
}

static bool read_params(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    int size = 16;
    if (get(r, root, "params_size", "manifest", false) &&
        !get_int(r, root, "params_size", "manifest", 0, 1 << 16, &size))
        return false;
    p->params_size = size < 16 ? 16 : (uint32_t)size;
    json_t *ps = get_array(r, root, "params", "manifest", false);
    if (!ps)
        return !r->e->msg;
    p->nparams = (int)json_array_size(ps);
    p->params = calloc((size_t)p->nparams + 1, sizeof *p->params);
    for (int i = 0; i < p->nparams; i++) {
        json_t *q = json_array_get(ps, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "params[%d]", i);
        const char *name;
        double def[4];
        int off;
        if (!get_string(r, q, "name", where, &name) ||
            !get_vec(r, q, "default", where, 4, def) ||
            !get_int(r, q, "offset", where, 0, (int)p->params_size - 16, &off))
            return false;
        if (off % 16)
            return field_fail(r, where, "offset must be a multiple of 16");
        p->params[i].name = dup(name);
        p->params[i].offset = (uint32_t)off;
        for (int k = 0; k < 4; k++)
            p->params[i].value[k] = (float)def[k];
    }
    return true;
}

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
static bool read_mips(reader *r, json_t *t, const char *where, rt_pack_texture *tx)
{
    int n;
    if (!get_int(r, t, "mips", where, 1, 31, &n))
        return false;
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
        uint8_t *data = pack_file(r, field, file, 0, &bytes);
        int w = 0, h = 0, ch;
        if (data)
            tx->mips[k - 1] = stbi_load_from_memory(data, (int)bytes, &w, &h, &ch, 4);
        free(data);
        int ww = tx->width >> k > 0 ? tx->width >> k : 1;
        int wh = tx->height >> k > 0 ? tx->height >> k : 1;
        bool ok = data && tx->mips[k - 1];
        if (data && !ok)
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

static bool read_textures(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *ts = get_array(r, root, "textures", "manifest", false);
    if (!ts)
        return !r->e->msg;
    p->ntextures = (int)json_array_size(ts);
    p->textures = calloc((size_t)p->ntextures + 1, sizeof *p->textures);
    for (int i = 0; i < p->ntextures; i++) {
        json_t *t = json_array_get(ts, (size_t)i);
        rt_pack_texture *tx = &p->textures[i];
        char where[64];
        snprintf(where, sizeof where, "textures[%d]", i);
        const char *file, *filter = "linear", *mip = "linear", *wrap = "repeat";
        int binding;
        if (!get_string(r, t, "file", where, &file) ||
            !get_int(r, t, "binding", where, 1, 1 << 16, &binding))
            return false;
        if (binding != SPLAT_BIND_TEXTURE0 + i)
            return field_fail(r, where, "binding must be 1 + its index");
        if (get(r, t, "filter", where, false) && !get_string(r, t, "filter", where, &filter))
            return false;
        if (get(r, t, "mip", where, false) && !get_string(r, t, "mip", where, &mip))
            return false;
        if (get(r, t, "wrap", where, false) && !get_string(r, t, "wrap", where, &wrap))
            return false;
        tx->file = dup(file);
        tx->binding = (uint32_t)binding;
        tx->linear = strcmp(filter, "nearest") != 0;
        tx->mip_linear = strcmp(mip, "nearest") != 0;
        tx->wrap = !strcmp(wrap, "clamp") ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
                 : !strcmp(wrap, "mirror") ? VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT
                 : VK_SAMPLER_ADDRESS_MODE_REPEAT;
        json_t *srgb = get(r, t, "srgb", where, false);
        tx->srgb = json_is_true(srgb);
        char field[96];
        snprintf(field, sizeof field, "%s.file", where);
        size_t n;
        uint8_t *data = pack_file(r, field, file, 0, &n);
        if (!data)
            return false;
        int ch;
        tx->rgba = stbi_load_from_memory(data, (int)n, &tx->width, &tx->height, &ch, 4);
        free(data);
        if (!tx->rgba)
            return rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, file,
                           "is not an image stb_image can read");
        if (get(r, t, "mips", where, false) && !read_mips(r, t, where, tx))
            return false;
    }
    return true;
}

static bool read_painted(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *pa = get_array(r, root, "painted", "manifest", false);
    if (!pa || json_array_size(pa) == 0)
        return !r->e->msg;
    p->npainted = (int)json_array_size(pa);
    /* sparse quad-tree (painted.c) unless painted_format says dense */
    json_t *fmt = get(r, root, "painted_format", "manifest", false);
    if (fmt && strcmp(json_string_value(fmt) ? json_string_value(fmt) : "", "dense")) {
        const char *file;
        return get_string(r, root, "painted_file", "manifest", &file) &&
               rt_painted_read(p, file, r->e);
    }
    size_t bytes = (size_t)p->npainted * (size_t)p->hf_width * (size_t)p->hf_height;
    p->painted = pack_file(r, "painted", "painted.r8", bytes, NULL);
    return p->painted != NULL;
}

static bool read_combos(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *cs = get_array(r, root, "combinations", "manifest", true);
    if (!cs)
        return false;
    p->ncombos = (int)json_array_size(cs);
    if (p->ncombos == 0)
        return field_fail(r, "combinations:", "is empty");
    if (p->ncombos > 65535)
        return field_fail(r, "combinations:", "has more than 65535 entries");
    p->combos = calloc((size_t)p->ncombos, sizeof *p->combos);
    for (int i = 0; i < p->ncombos; i++) {
        json_t *c = json_array_get(cs, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "combinations[%d]", i);
        int id;
        if (!get_int(r, c, "id", where, 0, 65535, &id))
            return false;
        if (id != i)
            return field_fail(r, where, "id must equal its index");
        json_t *ms = get_array(r, c, "materials", where, true);
        if (!ms)
            return false;
        rt_pack_combo *co = &p->combos[i];
        co->nmaterials = (int)json_array_size(ms);
        co->materials = calloc((size_t)co->nmaterials + 1, sizeof *co->materials);
        for (int k = 0; k < co->nmaterials; k++) {
            json_t *m = json_array_get(ms, (size_t)k);
            if (!json_is_integer(m) || json_integer_value(m) < 0 ||
                json_integer_value(m) >= p->nmaterials)
                return field_fail(r, where, "materials: index out of range");
            co->materials[k] = (int)json_integer_value(m);
        }
        if (!read_spirv(r, c, where, &co->spirv))
            return false;
    }
    return true;
}

static bool read_quadtree(reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *qt = get(r, root, "quadtree", "manifest", true);
    const char *file;
    if (!qt || !get_string(r, qt, "file", "quadtree", &file))
        return false;
    json_t *lv = get_array(r, qt, "levels", "quadtree", true);
    if (!lv)
        return false;
    int cx = (p->hf_width + p->cell_texels - 1) / p->cell_texels;
    int cz = (p->hf_height + p->cell_texels - 1) / p->cell_texels;
    int want = rt_level_count(cx, cz);
    if ((int)json_array_size(lv) != want) {
        char what[96];
        snprintf(what, sizeof what, "must have %d levels for %dx%d cells", want, cx, cz);
        return field_fail(r, "quadtree.levels", what);
    }
    size_t n = 0;
    uint8_t *data = pack_file(r, "quadtree.file", file, 0, &n);
    if (!data)
        return false;
    p->nlevels = want;
    p->levels = calloc((size_t)want, sizeof *p->levels);
    bool ok = true;
    int w = cx, h = cz;
    for (int L = 0; L < want && ok; L++) {
        json_t *l = json_array_get(lv, (size_t)L);
        char where[64];
        snprintf(where, sizeof where, "quadtree.levels[%d]", L);
        int lw, lh, off;
        if (!get_int(r, l, "width", where, 1, 1 << 20, &lw) ||
            !get_int(r, l, "height", where, 1, 1 << 20, &lh) ||
            !get_int(r, l, "offset", where, 0, 0x7fffffff, &off)) {
            ok = false;
            break;
        }
        if (lw != w || lh != h) {
            char what[96];
            snprintf(what, sizeof what, "must be %dx%d nodes", w, h);
            ok = field_fail(r, where, what);
            break;
        }
        size_t bytes = (size_t)lw * (size_t)lh * 2;
        if ((size_t)off + bytes > n) {
            char path[512];
            snprintf(path, sizeof path, "%s/%s", p->dir, file);
            ok = rt_fail(r->e, RT_E_PACK_FILE, r->manifest, where, file,
                         "is too short for this level");
            break;
        }
        rt_pack_level *pl = &p->levels[L];
        pl->width = lw;
        pl->height = lh;
        pl->ids = malloc(bytes);
        for (size_t i = 0; i < (size_t)lw * (size_t)lh; i++) {
            pl->ids[i] = (uint16_t)(data[off + 2 * i] | data[off + 2 * i + 1] << 8);
            if (pl->ids[i] >= p->ncombos) {
                char at[160], path[512];
                snprintf(at, sizeof at, "level %d node (%zu, %zu)", L,
                         i % (size_t)lw, i / (size_t)lw);
                snprintf(path, sizeof path, "%s/%s", p->dir, file);
                ok = rt_fail(r->e, RT_E_PACK_COMBO, path, pl->ids[i], p->ncombos, at);
                break;
            }
        }
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    free(data);
    return ok;
}

bool rt_pack_load(rt_pack *p, const char *dir, rt_error *e)
{
    rt_error local = { 0 };
    if (!e)
        e = &local;
    memset(p, 0, sizeof *p);
    p->dir = dup(dir);
    char *manifest = join(dir, "manifest.json");
    reader r = { manifest, p, e };
    rt_error_clear(e);
    json_error_t je;
    json_t *root = json_load_file(manifest, 0, &je);
    bool ok = false;
    if (!root) {
        FILE *f = fopen(manifest, "rb");
        if (!f)
            rt_fail(e, RT_E_IO, "read", manifest, strerror(errno));
        else {
            fclose(f);
            rt_fail(e, RT_E_PACK_JSON, manifest, je.line, je.column, je.text);
        }
        goto done;
    }
    const char *format;
    int version, abi;
    if (!get_string(&r, root, "format", "manifest", &format))
        goto done;
    if (strcmp(format, "splatc-pack")) {
        rt_fail(e, RT_E_PACK_VERSION, manifest, "format is not \"splatc-pack\"");
        goto done;
    }
    if (!get_int(&r, root, "version", "manifest", 0, 1 << 20, &version) ||
        !get_int(&r, root, "abi", "manifest", 0, 1 << 20, &abi))
        goto done;
    if (version != 1 || abi != SPLAT_ABI_VERSION) {
        char what[128];
        snprintf(what, sizeof what, "pack version %d / abi %d; this runtime reads version 1 / abi %d",
                 version, abi, SPLAT_ABI_VERSION);
        rt_fail(e, RT_E_PACK_VERSION, manifest, what);
        goto done;
    }
    ok = read_scene(&r, root) && read_materials(&r, root) && read_params(&r, root) &&
         read_textures(&r, root) && read_painted(&r, root) && read_combos(&r, root) &&
         read_quadtree(&r, root);
    if (ok) {
        json_t *vx = get(&r, root, "vertex", "manifest", true);
        ok = vx && read_spirv(&r, vx, "vertex", &p->vertex);
    }
    if (ok) {
        json_t *ub = get(&r, root, "uber", "manifest", false);
        if (ub && !json_is_null(ub))
            ok = read_spirv(&r, ub, "uber", &p->uber);
    }
done:
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
    free(s->words);
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
    for (int i = 0; i < p->ncombos && p->combos; i++) {
        free(p->combos[i].materials);
        free_spirv(&p->combos[i].spirv);
    }
    for (int i = 0; i < p->nlevels && p->levels; i++)
        free(p->levels[i].ids);
    free_spirv(&p->uber);
    free_spirv(&p->vertex);
    free(p->cameras);
    free(p->materials);
    free(p->params);
    free(p->textures);
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
