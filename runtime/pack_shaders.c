/* pack_shaders.c — the pack's shaders (compiler/PACK.md): SPIR-V modules
 * read, validated on all cores (spirv-val) and checked against what they
 * are bound to; GLSL text; the combinations, their distance classes and
 * combos.bin's quadtree levels (pack_internal.h). */
#include "pack_internal.h"
#include "cache.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* {"glsl": …, "spirv": …} → a validated SPIR-V module. */
bool rt_pk_read_spirv(rt_pk_reader *r, json_t *obj, const char *where, rt_spirv *out)
{
    const char *rel;
    if (!rt_pk_get_string(r, obj, "spirv", where, &rel))
        return false;
    char field[256];
    snprintf(field, sizeof field, "%s.spirv", where);
    size_t n = 0;
    uint8_t *data = rt_pk_pack_file(r, field, rel, 0, MAX_SPIRV, &n);
    if (!data)
        return false;
    out->path = rt_pk_strdup(rel);
    if (n % 4) {
        free(data);
        char path[512];
        snprintf(path, sizeof path, "%s/%s", r->p->dir, rel);
        return rt_fail(r->e, RT_E_PACK_SPIRV, path, "size is not a multiple of 4 bytes");
    }
    out->words = (uint32_t *)data;
    out->nwords = n / 4;
    if (r->nunchecked == r->capunchecked) {
        int cap = r->capunchecked ? 2 * r->capunchecked : 64;
        struct rt_pk_unchecked *u = realloc(r->unchecked, (size_t)cap * sizeof *u);
        if (!u)
            return false;
        r->unchecked = u;
        r->capunchecked = cap;
    }
    r->unchecked[r->nunchecked++] =
        (struct rt_pk_unchecked){ out->words, out->nwords, rt_pk_strdup(rel) };
    return true;
}

/* One job of validate_all: spirv-val on module k, its failure in errs[k]
 * (none where the compiler's cache holds that the module's shape passed
 * spirv-val before: cache.h splat_cache_valid; then marked so). */
typedef struct validate_jobs {
    rt_pk_reader    *r;
    rt_error  *errs;
    splat_cache     *cache;   /* NULL: none */
} validate_jobs;

static bool validate_one(void *ctx, int k, rt_error *e)
{
    validate_jobs *j = ctx;
    const struct rt_pk_unchecked *s = &j->r->unchecked[k];
    char key[SPLAT_KEY_CHARS + 1];
    bool keyed = j->cache && splat_spirv_shape_key(s->words, s->nwords, key);
    if (keyed && splat_cache_valid(j->cache, key))
        return true;
    char path[512];
    snprintf(path, sizeof path, "%s/%s", j->r->p->dir, s->path);
    (void)e;   /* every module is validated: the first failure by index is reported */
    if (rt_spirv_validate(s->words, s->nwords, path, &j->errs[k]) && keyed)
        splat_cache_mark_valid(j->cache, key);
    return true;
}

/* Every module read, validated before any reaches the driver: spirv-val
 * on all cores (jobs.c), the failure reported that of the first module in
 * manifest order, so the message does not depend on the threads. */
bool rt_pk_validate_all(rt_pk_reader *r)
{
    rt_error *errs = calloc((size_t)r->nunchecked + 1, sizeof *errs);
    if (!errs)
        return false;
    /* the compiler's cache ($SPLATC_CACHE, ...): a module of a shape that
     * passed spirv-val on this machine before is not validated again, so
     * loading a pack costs spirv-val once per module shape, not per load */
    splat_cache cache;
    bool cached = splat_cache_open(&cache, NULL);
    validate_jobs j = { r, errs, cached ? &cache : NULL };
    bool ok = rt_parallel(r->nunchecked, validate_one, &j, r->e);
    if (cached)
        splat_cache_close(&cache);
    for (int k = 0; k < r->nunchecked; k++) {
        if (ok && errs[k].id != RT_OK) {
            *r->e = errs[k];
            ok = false;
        } else {
            rt_error_clear(&errs[k]);
        }
    }
    free(errs);
    return ok;
}

/* {"compute": {"glsl": …}} of a combination or the über-shader: the
 * compute variant's GLSL text (PACK.md), NUL-terminated; optional (a pack
 * without it cannot be drawn by the screen-space path). */
static bool read_glsl_at(rt_pk_reader *r, json_t *c, const char *w, char **out);

static bool read_glsl(rt_pk_reader *r, json_t *obj, const char *key, const char *where, char **out)
{
    json_t *c = rt_pk_get(r, obj, key, where, false);
    if (!c || json_is_null(c))
        return true;
    char w[96];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return read_glsl_at(r, c, w, out);
}

/* read_glsl, and the variant's SPIR-V where the build made it
 * ({"glsl": …, "spirv": …}; `spv` words NULL without): validated with
 * every module of the pack, so the runtime compiles nothing for it. */
bool rt_pk_read_compute(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                         char **out, rt_spirv *spv)
{
    if (!read_glsl(r, obj, key, where, out))
        return false;
    json_t *c = json_object_get(obj, key);
    if (!json_is_object(c) || !json_object_get(c, "spirv"))
        return true;
    char w[96];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return rt_pk_read_spirv(r, c, w, spv);
}

/* c["glsl"], the fragment GLSL beside c["spirv"]: optional, and only its
 * path is kept (the forward path's counting variant reads it on first use:
 * rt_pack_read_glsl). */
bool rt_pk_read_fragment_glsl(rt_pk_reader *r, json_t *c, const char *where, char **path)
{
    const char *rel;
    if (!rt_pk_get(r, c, "glsl", where, false))
        return true;
    if (!rt_pk_get_string(r, c, "glsl", where, &rel))
        return false;
    *path = rt_pk_strdup(rel);
    return true;
}

/* The file's bytes as GLSL text: NUL-terminated, no NUL inside; NULL with
 * `why` set if not.  Takes `data` (n bytes, one spare byte allocated). */
static char *glsl_text(uint8_t *data, size_t n, char *why, size_t nwhy)
{
    char *text = (char *)data;
    text[n] = '\0';
    if (strlen(text) != n) {
        snprintf(why, nwhy, "holds a NUL byte: not GLSL text");
        free(text);
        return NULL;
    }
    return text;
}

/* The text of c["glsl"] (`w` names c in errors). */
static bool read_glsl_at(rt_pk_reader *r, json_t *c, const char *w, char **out)
{
    const char *rel;
    if (!rt_pk_get_string(r, c, "glsl", w, &rel))
        return false;
    char field[128], why[96];
    snprintf(field, sizeof field, "%s.glsl", w);
    size_t n = 0;
    uint8_t *data = rt_pk_pack_file(r, field, rel, 0, MAX_SPIRV, &n);
    if (!data)
        return false;
    if (!(*out = glsl_text(data, n, why, sizeof why)))
        return rt_pk_field_fail(r, field, why);
    return true;
}

char *rt_pack_read_glsl(const rt_pack *p, const char *field, const char *rel, rt_error *e)
{
    char why[256];
    size_t n = 0;
    uint8_t *data = NULL;
    int dirfd = open(p->dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dirfd < 0) {
        snprintf(why, sizeof why, "cannot open the pack folder (%s)", strerror(errno));
    } else {
        data = rt_pack_read_content(dirfd, rel, MAX_SPIRV, &n, why, sizeof why);
        close(dirfd);
    }
    char *text = data ? glsl_text(data, n, why, sizeof why) : NULL;
    if (!text) {
        char manifest[512];
        snprintf(manifest, sizeof manifest, "%s/manifest.json", p->dir);
        rt_fail(e, RT_E_PACK_FILE, manifest, field, rel, why);
    }
    return text;
}

/* The combinations' distance classes (PACK.md "Distance classes"),
 * appended to p->combos after the nbase combinations. */
static bool read_classes(rt_pk_reader *r, json_t *cs)
{
    rt_pack *p = r->p;
    int total = p->nbase;
    for (int i = 0; i < p->nbase; i++) {
        char where[64];
        snprintf(where, sizeof where, "combinations[%d]", i);
        json_t *c = json_array_get(cs, (size_t)i);
        json_t *cl = rt_pk_get_array(r, c, "classes", where, false);
        if (!cl && json_object_get(c, "classes"))
            return false;   /* not an array: get_array said so */
        if (cl && json_array_size(cl) > 16)
            return rt_pk_field_fail(r, where, "classes: has more than 16 entries");
        total += cl ? (int)json_array_size(cl) : 0;
    }
    if (total > 65534)
        return rt_pk_field_fail(r, "combinations:", "with their classes, more than 65534 shaders");
    if (total == p->nbase)
        return true;
    rt_pack_combo *all = realloc(p->combos, (size_t)total * sizeof *all);
    if (!all)
        return false;
    memset(all + p->nbase, 0, (size_t)(total - p->nbase) * sizeof *all);
    p->combos = all;
    int n = p->nbase;
    for (int i = 0; i < p->nbase; i++) {
        json_t *cl = json_object_get(json_array_get(cs, (size_t)i), "classes");
        p->combos[i].first_class = n;
        for (size_t k = 0; k < json_array_size(cl); k++) {
            json_t *c = json_array_get(cl, k);
            char where[96];
            snprintf(where, sizeof where, "combinations[%d].classes[%zu]", i, k);
            rt_pack_combo *co = &p->combos[n];
            p->ncombos = ++n;   /* freed with the pack from here on */
            co->base = i;
            co->nmaterials = p->combos[i].nmaterials;
            co->materials = calloc((size_t)co->nmaterials + 1, sizeof *co->materials);
            if (!co->materials)
                return false;
            memcpy(co->materials, p->combos[i].materials,
                   (size_t)co->nmaterials * sizeof *co->materials);
            json_t *dist = rt_pk_get_array(r, c, "distance", where, true);
            if (!dist)
                return false;
            json_t *lo = json_array_get(dist, 0), *hi = json_array_get(dist, 1);
            if (json_array_size(dist) != 2 || !json_is_number(lo) ||
                !(json_is_number(hi) || json_is_null(hi)))
                return rt_pk_field_fail(r, where, "distance: must be [lo, hi or null]");
            co->dlo = json_number_value(lo);
            co->dhi = json_is_null(hi) ? INFINITY : json_number_value(hi);
            if (!(co->dlo >= 0) || !(co->dhi >= co->dlo))
                return rt_pk_field_fail(r, where, "distance: must have 0 <= lo <= hi");
            if (rt_pk_get(r, c, "spirv", where, false)
                    ? !rt_pk_read_spirv(r, c, where, &co->spirv) ||
                          !rt_pk_read_fragment_glsl(r, c, where, &co->frag_path)
                    : !read_glsl_at(r, c, where, &co->glsl))
                return false;
            if (!rt_pk_read_compute(r, c, "compute", where, &co->compute, &co->compute_spirv) ||
                !rt_pk_get_number(r, c, "cost", where, &co->cost))
                return false;
            if (!(co->cost >= 0) || co->cost > 1e12)
                return rt_pk_field_fail(r, where, "cost: must be a number >= 0");
        }
        p->combos[i].nclasses = n - p->combos[i].first_class;
    }
    return true;
}

bool rt_pk_read_combos(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *cs = rt_pk_get_array(r, root, "combinations", "manifest", true);
    if (!cs)
        return false;
    p->ncombos = (int)json_array_size(cs);
    if (p->ncombos == 0)
        return rt_pk_field_fail(r, "combinations:", "is empty");
    if (p->ncombos > 65535)
        return rt_pk_field_fail(r, "combinations:", "has more than 65535 entries");
    p->combos = calloc((size_t)p->ncombos, sizeof *p->combos);
    if (!p->combos)
        return false;
    for (int i = 0; i < p->ncombos; i++) {
        json_t *c = json_array_get(cs, (size_t)i);
        char where[64];
        snprintf(where, sizeof where, "combinations[%d]", i);
        int id;
        if (!rt_pk_get_int(r, c, "id", where, 0, 65535, &id))
            return false;
        if (id != i)
            return rt_pk_field_fail(r, where, "id must equal its index");
        json_t *ms = rt_pk_get_array(r, c, "materials", where, true);
        if (!ms)
            return false;
        rt_pack_combo *co = &p->combos[i];
        co->nmaterials = (int)json_array_size(ms);
        co->materials = calloc((size_t)co->nmaterials + 1, sizeof *co->materials);
        if (!co->materials)
            return false;
        for (int k = 0; k < co->nmaterials; k++) {
            json_t *m = json_array_get(ms, (size_t)k);
            if (!json_is_integer(m) || json_integer_value(m) < 0 ||
                json_integer_value(m) >= p->nmaterials)
                return rt_pk_field_fail(r, where, "materials: index out of range");
            co->materials[k] = (int)json_integer_value(m);
        }
        if (!rt_pk_read_spirv(r, c, where, &co->spirv) ||
            !rt_pk_read_fragment_glsl(r, c, where, &co->frag_path) ||
            !rt_pk_read_compute(r, c, "compute", where, &co->compute, &co->compute_spirv) ||
            !rt_pk_read_compute(r, c, "undergrowth", where, &co->ug_compute, &co->ug_spirv))
            return false;
        json_t *cost = rt_pk_get(r, c, "cost", where, false);
        if (cost && (!json_is_number(cost) || !(json_number_value(cost) >= 0) ||
                     json_number_value(cost) > 1e12))
            return rt_pk_field_fail(r, where, "cost: must be a number >= 0");
        co->cost = cost ? json_number_value(cost) : 0;
        co->base = i;
        co->dhi = INFINITY;
    }
    p->nbase = p->ncombos;
    return read_classes(r, cs);
}

bool rt_combos_parse(const uint8_t *data, size_t n, int cells_x, int cells_z,
                     const int64_t *offsets, int ncombos, bool holes,
                     rt_pack_level *levels, const char *path, rt_error *e)
{
    int nlevels = rt_level_count(cells_x, cells_z), w = cells_x, h = cells_z;
    for (int L = 0; L < nlevels; L++) {
        size_t nodes = (size_t)w * (size_t)h, off = (size_t)offsets[L];
        if (offsets[L] < 0 || off > n || nodes * 2 > n - off) {
            char what[200];
            snprintf(what, sizeof what, "level %d (%dx%d nodes at offset %lld) runs past the "
                     "end of the file (%zu bytes)", L, w, h, (long long)offsets[L], n);
            return rt_fail(e, RT_E_PACK_FIELD, path, what);
        }
        rt_pack_level *pl = &levels[L];
        pl->width = w;
        pl->height = h;
        pl->ids = malloc(nodes * 2);
        if (!pl->ids)
            return rt_fail(e, RT_E_PACK_FIELD, path, "does not fit in memory");
        for (size_t i = 0; i < nodes; i++) {
            pl->ids[i] = (uint16_t)(data[off + 2 * i] | data[off + 2 * i + 1] << 8);
            /* a node all hole (PACK.md) only where the terrain has holes;
             * a coarse node without a combination (über-shaded) above the
             * leaves only */
            if (pl->ids[i] >= ncombos && !(pl->ids[i] == SPLAT_COMBO_HOLE && holes) &&
                !(pl->ids[i] == SPLAT_COMBO_UBER && L > 0)) {
                char at[160];
                snprintf(at, sizeof at, "level %d node (%zu, %zu)", L, i % (size_t)w,
                         i / (size_t)w);
                return rt_fail(e, RT_E_PACK_COMBO, path, pl->ids[i], ncombos, at);
            }
        }
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    return true;
}

bool rt_pk_read_quadtree(rt_pk_reader *r, json_t *root)
{
    rt_pack *p = r->p;
    json_t *qt = rt_pk_get(r, root, "quadtree", "manifest", true);
    const char *file;
    if (!qt || !rt_pk_get_string(r, qt, "file", "quadtree", &file))
        return false;
    json_t *lv = rt_pk_get_array(r, qt, "levels", "quadtree", true);
    if (!lv)
        return false;
    int cx = (p->hf_width + p->cell_texels - 1) / p->cell_texels;
    int cz = (p->hf_height + p->cell_texels - 1) / p->cell_texels;
    int want = rt_level_count(cx, cz);
    if ((int)json_array_size(lv) != want) {
        char what[96];
        snprintf(what, sizeof what, "must have %d levels for %dx%d cells", want, cx, cz);
        return rt_pk_field_fail(r, "quadtree.levels", what);
    }
    int64_t *offsets = calloc((size_t)want, sizeof *offsets);
    p->levels = calloc((size_t)want, sizeof *p->levels);
    if (!offsets || !p->levels) {
        free(offsets);
        return false;
    }
    p->nlevels = want;
    int w = cx, h = cz;
    for (int L = 0; L < want; L++) {
        json_t *l = json_array_get(lv, (size_t)L);
        char where[64];
        snprintf(where, sizeof where, "quadtree.levels[%d]", L);
        int lw, lh, off;
        if (!rt_pk_get_int(r, l, "width", where, 1, 1 << 20, &lw) ||
            !rt_pk_get_int(r, l, "height", where, 1, 1 << 20, &lh) ||
            !rt_pk_get_int(r, l, "offset", where, 0, 0x7fffffff, &off)) {
            free(offsets);
            return false;
        }
        if (lw != w || lh != h) {
            char what[96];
            snprintf(what, sizeof what, "must be %dx%d nodes", w, h);
            free(offsets);
            return rt_pk_field_fail(r, where, what);
        }
        offsets[L] = off;
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    size_t n = 0;
    uint8_t *data = rt_pk_pack_file(r, "quadtree.file", file, 0, MAX_BINARY, &n);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", p->dir, file);
    bool ok = data && rt_combos_parse(data, n, cx, cz, offsets, p->nbase, p->holes != NULL,
                                      p->levels, path,
                                      r->e);
    free(data);
    free(offsets);
    return ok;
}

/* Every shader against the interface of its role (spirv_check.c), so
 * that no module reaches the driver unchecked. */
static bool check_one(rt_pk_reader *r, const rt_spirv *s, const rt_interface *in)
{
    if (!s->words)
        return true;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", r->p->dir, s->path);
    return rt_spirv_check(s->words, s->nwords, path, in, r->e);
}

bool rt_pk_check_shaders(rt_pk_reader *r)
{
    rt_pack *p = r->p;
    rt_interface in[RT_ROLE_COUNT];
    bool ok = true;
    int made = 0;
    for (; made < RT_ROLE_COUNT && ok; made++)
        ok = rt_interface_for(p, (rt_shader_role)made, &in[made]);
    if (!ok) {
        made--;
        rt_fail(r->e, RT_E_PACK_FIELD, r->manifest, "out of memory");
    }
    ok = ok && check_one(r, &p->vertex, &in[RT_ROLE_VERTEX]) &&
         check_one(r, &p->uber, &in[RT_ROLE_COMPOSITE]);
    for (int i = 0; ok && i < p->ncombos; i++)
        ok = check_one(r, &p->combos[i].spirv, &in[RT_ROLE_COMPOSITE]) &&
             check_one(r, &p->combos[i].compute_spirv, &in[RT_ROLE_COMPUTE]) &&
             check_one(r, &p->combos[i].ug_spirv, &in[RT_ROLE_UNDERGROWTH]);
    ok = ok && check_one(r, &p->uber_compute_spirv, &in[RT_ROLE_COMPUTE]);
    for (int i = 0; ok && i < p->nmaterials; i++)
        ok = check_one(r, &p->materials[i].reference, &in[RT_ROLE_REFERENCE]);
    for (int i = 0; i < made; i++)
        rt_interface_free(&in[i]);
    return ok;
}
