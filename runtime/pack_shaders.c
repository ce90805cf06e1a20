/* pack_shaders.c — the pack's shaders (compiler/PACK.md): SPIR-V modules
 * and GLSL texts registered at load and read on first use, each module
 * validated (spirv-val) and checked against what it is bound to before
 * it is handed out (rt_pack_spirv; rt_pack_validate: all of them, on all
 * cores); the combinations, their distance classes and combos.bin's
 * quadtree levels (pack_internal.h). */
#include "pack_internal.h"
#include "cache.h"

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- shaders read on first use (rt_module) ------------------------------
 * Loading the pack registers each shader file: its name, that it is a
 * regular file inside the pack and its size (a zstd frame's stated content
 * size) within MAX_SPIRV (module_add).  The first rt_pack_spirv or
 * rt_pack_text reads it, decompresses it and, for SPIR-V, validates it
 * (spirv-val, once per module shape: the compiler's cache, cache.h
 * splat_cache_valid) and checks it against its role's interface
 * (rt_spirv_check): no module reaches the driver unchecked, and a first
 * picture reads the few modules its view needs, not the pack's hundreds
 * (issue 29: colorado's 627 files took 7.5 s cold, 2.4 s warm to load).
 * Pipelines are made on worker threads, so the first use is under the
 * pack's lock: one thread reads a module while others needing it wait. */
enum { MOD_UNREAD, MOD_BUSY, MOD_READY, MOD_FAILED };

struct rt_module {
    char    *path;       /* pack-relative, as the manifest names it        */
    char    *field;      /* the manifest field naming it, for messages     */
    int      role;       /* rt_shader_role of a SPIR-V module; -1: GLSL    */
    size_t   size;       /* content bytes, as checked at load              */
    int      state;      /* MOD_*, under the pack's lock                   */
    void    *data;       /* the words, or the NUL-terminated text          */
    size_t   n;          /* words, or bytes of text                        */
    rt_error err;        /* its failure, handed to every caller            */
};

struct rt_pack_shaders {
    pthread_mutex_t lock;
    pthread_cond_t  done;      /* a module left MOD_BUSY                     */
    int             dirfd;     /* the pack folder, held open while it lives */
    char           *manifest;  /* its path, for messages                    */
    char           *dir;
    splat_cache     cache;     /* modules whose shape passed spirv-val      */
    bool            cached;
    rt_module     **all;       /* in manifest order                         */
    int             n, cap;
    atomic_int      read;      /* modules read and checked                  */
};

bool rt_pk_shaders_open(rt_pk_reader *r)
{
    struct rt_pack_shaders *s = calloc(1, sizeof *s);
    if (!s)
        return false;
    s->dirfd = fcntl(r->dirfd, F_DUPFD_CLOEXEC, 0);
    s->manifest = rt_pk_strdup(r->manifest);
    s->dir = rt_pk_strdup(r->p->dir);
    if (s->dirfd < 0 || !s->manifest || !s->dir || pthread_mutex_init(&s->lock, NULL)) {
        if (s->dirfd >= 0)
            close(s->dirfd);
        free(s->manifest);
        free(s->dir);
        free(s);
        return false;
    }
    pthread_cond_init(&s->done, NULL);
    /* the compiler's cache ($SPLATC_CACHE, ...): disabled if it cannot be made */
    s->cached = splat_cache_open(&s->cache, NULL);
    r->p->shaders = s;
    return true;
}

void rt_pk_shaders_free(struct rt_pack_shaders *s)
{
    if (!s)
        return;
    for (int k = 0; k < s->n; k++) {
        rt_module *m = s->all[k];
        free(m->path);
        free(m->field);
        free(m->data);
        rt_error_clear(&m->err);
        free(m);
    }
    free(s->all);
    if (s->cached)
        splat_cache_close(&s->cache);
    pthread_cond_destroy(&s->done);
    pthread_mutex_destroy(&s->lock);
    close(s->dirfd);
    free(s->manifest);
    free(s->dir);
    free(s);
}

size_t rt_pack_spirv_size(const rt_spirv *s)
{
    return s->words ? s->nwords * 4 : s->mod ? s->mod->size : 0;
}

size_t rt_pack_text_size(const rt_text *t)
{
    return t->mod ? t->mod->size : 0;
}

int rt_pack_shader_count(const rt_pack *p, int *read)
{
    struct rt_pack_shaders *s = p->shaders;
    *read = s ? atomic_load(&s->read) : 0;
    return s ? s->n : 0;
}

/* Register the shader file `rel` (the manifest's `field`) of `role`. */
static rt_module *module_add(rt_pk_reader *r, const char *field, const char *rel, int role)
{
    struct rt_pack_shaders *s = r->p->shaders;
    char why[256];
    size_t n = 0;
    if (!rt_pack_stat_content(r->dirfd, rel, MAX_SPIRV, &n, why, sizeof why)) {
        rt_fail(r->e, RT_E_PACK_FILE, r->manifest, field, rel, why);
        return NULL;
    }
    if (role >= 0 && n % 4) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", r->p->dir, rel);
        rt_fail(r->e, RT_E_PACK_SPIRV, path, "size is not a multiple of 4 bytes");
        return NULL;
    }
    if (s->n == s->cap) {
        int cap = s->cap ? 2 * s->cap : 64;
        rt_module **all = realloc(s->all, (size_t)cap * sizeof *all);
        if (!all)
            return NULL;
        s->all = all;
        s->cap = cap;
    }
    rt_module *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->path = rt_pk_strdup(rel);
    m->field = rt_pk_strdup(field);
    m->role = role;
    m->size = n;
    s->all[s->n++] = m;   /* freed with the pack from here on */
    return m->path && m->field ? m : NULL;
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

/* Read, decompress and check module m (outside the lock; m is MOD_BUSY). */
static bool module_read(const rt_pack *p, rt_module *m, rt_error *e)
{
    struct rt_pack_shaders *s = p->shaders;
    char why[256], path[1024];
    size_t n = 0;
    uint8_t *data = rt_pack_read_content(s->dirfd, m->path, m->size, &n, why, sizeof why);
    if (data && n != m->size) {
        snprintf(why, sizeof why, "has changed since the pack was loaded (%zu bytes, then %zu)",
                 n, m->size);
        free(data);
        data = NULL;
    }
    if (data && m->role < 0 && !(data = (uint8_t *)glsl_text(data, n, why, sizeof why))) {
        char msg[512];
        snprintf(msg, sizeof msg, "%s %s", m->field, why);
        return rt_fail(e, RT_E_PACK_FIELD, s->manifest, msg);
    }
    if (!data)
        return rt_fail(e, RT_E_PACK_FILE, s->manifest, m->field, m->path, why);
    m->data = data;
    m->n = m->role < 0 ? n : n / 4;
    if (m->role < 0)
        return true;
    snprintf(path, sizeof path, "%s/%s", s->dir, m->path);
    const uint32_t *words = m->data;
    /* spirv-val once per module shape on this machine (cache.h) */
    char key[SPLAT_KEY_CHARS + 1];
    bool keyed = s->cached && splat_spirv_shape_key(words, m->n, key);
    if (!(keyed && splat_cache_valid(&s->cache, key))) {
        if (!rt_spirv_validate(words, m->n, path, e))
            return false;
        if (keyed)
            splat_cache_mark_valid(&s->cache, key);
    }
    rt_interface in;
    if (!rt_interface_for(p, (rt_shader_role)m->role, &in))
        return rt_fail(e, RT_E_PACK_FIELD, s->manifest, "out of memory");
    bool ok = rt_spirv_check(words, m->n, path, &in, e);
    rt_interface_free(&in);
    return ok;
}

/* Module m, read and checked by whichever thread asks first. */
static bool module_get(const rt_pack *p, rt_module *m, rt_error *e)
{
    struct rt_pack_shaders *s = p->shaders;
    pthread_mutex_lock(&s->lock);
    while (m->state == MOD_BUSY)
        pthread_cond_wait(&s->done, &s->lock);
    if (m->state == MOD_UNREAD) {
        m->state = MOD_BUSY;
        pthread_mutex_unlock(&s->lock);
        rt_error err = { 0 };
        bool ok = module_read(p, m, &err);
        if (!ok && !err.msg)
            rt_fail(&err, RT_E_PACK_FIELD, s->manifest, "out of memory");
        if (ok)
            atomic_fetch_add(&s->read, 1);
        pthread_mutex_lock(&s->lock);
        m->state = ok ? MOD_READY : MOD_FAILED;
        m->err = err;
        pthread_cond_broadcast(&s->done);
    }
    bool ok = m->state == MOD_READY;
    pthread_mutex_unlock(&s->lock);
    if (!ok && e) {   /* the same message to every caller */
        rt_error_clear(e);
        e->id = m->err.id;
        e->msg = m->err.msg ? rt_pk_strdup(m->err.msg) : NULL;
    }
    return ok;
}

const uint32_t *rt_pack_spirv(const rt_pack *p, const rt_spirv *sp, size_t *nwords, rt_error *e)
{
    if (sp->words) {
        *nwords = sp->nwords;
        return sp->words;
    }
    if (!sp->mod) {
        rt_fail(e, RT_E_PACK_FIELD, p->dir, "a shader the pack does not have");
        return NULL;
    }
    if (!module_get(p, sp->mod, e))
        return NULL;
    *nwords = sp->mod->n;
    return sp->mod->data;
}

const char *rt_pack_text(const rt_pack *p, const rt_text *t, rt_error *e)
{
    if (!t->mod) {
        rt_fail(e, RT_E_PACK_FIELD, p->dir, "a GLSL text the pack does not have");
        return NULL;
    }
    return module_get(p, t->mod, e) ? t->mod->data : NULL;
}

/* One job of rt_pack_validate: module k, its failure in errs[k]. */
typedef struct validate_jobs {
    const rt_pack *p;
    rt_error      *errs;
} validate_jobs;

static bool validate_one(void *ctx, int k, rt_error *e)
{
    validate_jobs *j = ctx;
    (void)e;   /* every module is read: the first failure by index is reported */
    module_get(j->p, j->p->shaders->all[k], &j->errs[k]);
    return true;
}

bool rt_pack_validate(const rt_pack *p, rt_error *e)
{
    struct rt_pack_shaders *s = p->shaders;
    if (!s)
        return true;
    rt_error *errs = calloc((size_t)s->n + 1, sizeof *errs);
    if (!errs)
        return rt_fail(e, RT_E_PACK_FIELD, p->dir, "out of memory");
    validate_jobs j = { p, errs };
    bool ok = rt_parallel(s->n, validate_one, &j, e);
    for (int k = 0; k < s->n; k++) {
        if (ok && errs[k].id != RT_OK) {
            *e = errs[k];
            ok = false;
        } else {
            rt_error_clear(&errs[k]);
        }
    }
    free(errs);
    return ok;
}

/* obj[key], a shader file's path (`where` names obj in errors): its path
 * kept and its lazy module registered with `role` (-1: a GLSL text). */
static bool lazy_file(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                      int role, char **path, rt_module **mod)
{
    const char *rel;
    if (!rt_pk_get_string(r, obj, key, where, &rel))
        return false;
    char field[256];
    snprintf(field, sizeof field, "%s.%s", where, key);
    if (!(*path = rt_pk_strdup(rel)))
        return false;
    return (*mod = module_add(r, field, rel, role)) != NULL;
}

/* {"glsl": …, "spirv": …} → the SPIR-V module of `role`, read on first use. */
bool rt_pk_read_spirv(rt_pk_reader *r, json_t *obj, const char *where, rt_shader_role role,
                      rt_spirv *out)
{
    return lazy_file(r, obj, "spirv", where, (int)role, &out->path, &out->mod);
}

/* {"compute": {"glsl": …}} of a combination or the über-shader: the
 * compute variant's GLSL text (PACK.md), read on first use; optional (a
 * pack without it cannot be drawn by the screen-space path). */
static bool read_glsl_at(rt_pk_reader *r, json_t *c, const char *w, rt_text *out);

static bool read_glsl(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                      rt_text *out)
{
    json_t *c = rt_pk_get(r, obj, key, where, false);
    if (!c || json_is_null(c))
        return true;
    char w[96];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return read_glsl_at(r, c, w, out);
}

/* read_glsl, and the variant's SPIR-V where the build made it
 * ({"glsl": …, "spirv": …}; `spv` absent without), of `role`. */
bool rt_pk_read_compute(rt_pk_reader *r, json_t *obj, const char *key, const char *where,
                        rt_shader_role role, rt_text *out, rt_spirv *spv)
{
    if (!read_glsl(r, obj, key, where, out))
        return false;
    json_t *c = json_object_get(obj, key);
    if (!json_is_object(c) || !json_object_get(c, "spirv"))
        return true;
    char w[96];
    snprintf(w, sizeof w, "%s.%s", where, key);
    return rt_pk_read_spirv(r, c, w, role, spv);
}

/* uber["stand_in"] (PACK.md "Stand-ins"): optional, and so is each of
 * "flat" and "atlas" in it ({"spirv": …, "hash": …}, the module read on
 * first use and checked against its role; "atlas" only in a pack with a
 * far atlas); another key is refused.  Absent: the runtime compiles the
 * stand-ins from the über-shader's compute GLSL. */
bool rt_pk_read_stand_ins(rt_pk_reader *r, json_t *uber)
{
    json_t *si = rt_pk_get(r, uber, "stand_in", "uber", false);
    if (!si)
        return true;
    if (!json_is_object(si))
        return rt_pk_field_fail(r, "uber.stand_in:", "must be an object");
    const char *key;
    json_t *v;
    json_object_foreach(si, key, v) {
        int k = -1;
        for (int i = 0; i < SPLAT_STAND_IN_KINDS; i++)
            if (!strcmp(key, splat_stand_in_name((splat_stand_in_kind)i)))
                k = i;
        char where[64], what[160];
        if (k < 0) {
            snprintf(what, sizeof what, "'%.64s' is not a stand-in (\"flat\" or \"atlas\")", key);
            return rt_pk_field_fail(r, "uber.stand_in:", what);
        }
        snprintf(where, sizeof where, "uber.stand_in.%s", key);
        snprintf(what, sizeof what, "%s:", where);
        if (!json_is_object(v))
            return rt_pk_field_fail(r, what, "must be an object");
        if (k == SPLAT_STAND_IN_ATLAS && !r->p->far.data)
            return rt_pk_field_fail(r, what, "the pack has no far atlas (far_atlas)");
        json_t *h = json_object_get(v, "hash");
        if (h && !json_is_string(h)) {
            snprintf(what, sizeof what, "%s.hash:", where);
            return rt_pk_field_fail(r, what, "must be a string");
        }
        if (!rt_pk_read_spirv(r, v, where,
                              k == SPLAT_STAND_IN_ATLAS ? RT_ROLE_FAR : RT_ROLE_COMPUTE,
                              &r->p->stand_in[k]))
            return false;
    }
    return true;
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

/* c["glsl"] (`w` names c in errors), read on first use. */
static bool read_glsl_at(rt_pk_reader *r, json_t *c, const char *w, rt_text *out)
{
    return lazy_file(r, c, "glsl", w, -1, &out->path, &out->mod);
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
                    ? !rt_pk_read_spirv(r, c, where, RT_ROLE_COMPOSITE, &co->spirv) ||
                          !rt_pk_read_fragment_glsl(r, c, where, &co->frag_path)
                    : !read_glsl_at(r, c, where, &co->glsl))
                return false;
            if (!rt_pk_read_compute(r, c, "compute", where, RT_ROLE_COMPUTE, &co->compute,
                                    &co->compute_spirv) ||
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
        if (!rt_pk_read_spirv(r, c, where, RT_ROLE_COMPOSITE, &co->spirv) ||
            !rt_pk_read_fragment_glsl(r, c, where, &co->frag_path) ||
            !rt_pk_read_compute(r, c, "compute", where, RT_ROLE_COMPUTE, &co->compute,
                                &co->compute_spirv) ||
            !rt_pk_read_compute(r, c, "undergrowth", where, RT_ROLE_UNDERGROWTH,
                                &co->ug_compute, &co->ug_spirv))
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
