/* pack.c — `splatc build`: from a scene to a shader pack (compiler/PACK.md).
 *
 * The pipeline, one phase after the other (each timed for --stats):
 *
 *   load      splat_scene_load: parse, check, heightfield, rasters, lower
 *   analysis  splat_painted_build: the painted masks as the pack stores
 *             them (sparse BC4 / R8, unless --painted dense), then
 *             splat_analyze on them: the combinations and quadtree grids
 *   compose   a composite per combination (+ flat variants), the über-shader,
 *             a reference pass per material and the vertex shader: GLSL,
 *             then each shader's key (cache.c)
 *   glslang   cache lookups first; only misses are compiled, on N threads
 *   validate  spv_validate on every newly compiled module, which is then
 *             stored in the cache (only validated modules are; a hit was
 *             validated when it was stored, and its entry is checksummed)
 *   write     everything into OUT.tmp-XXXXXX, then swapped into place
 *
 * Nothing changed: right after loading, the bytes of every input (the
 * graph files the program read, the heightfield, the painted rasters, the
 * texture files) are hashed with the compiler version and options; the
 * manifest records that "inputs" key, and when the existing pack carries
 * the same key and has all its shader files, the build stops there (with
 * --stats it still runs the analysis for the report and reads the shader
 * figures back from the pack).
 *
 * Determinism: every file is a function of the inputs only (no times, no
 * absolute paths: material sources are written relative to the scene's
 * folder); manifest keys in a fixed order, reals with 15 significant
 * digits (JSON_REAL_PRECISION).
 */
#define _GNU_SOURCE 1   /* renameat2 */
#include "scene.h"

#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <jansson.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <xxhash.h>

#include "abi.h"
#include "spv.h"

#ifndef SPLATC_VERSION
#define SPLATC_VERSION "0"
#endif

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size);
    if (!p)
        abort();
    return p;
}

static char *xasprintf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static char *xasprintf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *s = malloc((size_t)n + 1);
    if (!s)
        abort();
    va_start(ap, fmt);
    vsnprintf(s, (size_t)n + 1, fmt, ap);
    va_end(ap);
    return s;
}

/* ---- shaders to compile --------------------------------------------------- */

typedef enum job_kind { JOB_COMBO, JOB_FLAT, JOB_UBER, JOB_REF, JOB_VERTEX } job_kind;

typedef struct job {
    job_kind  kind;
    int       index;          /* combination or material                   */
    char     *file;           /* "shaders/0003" (".frag"/".spv" added)     */
    ir_buf    glsl;
    int       stage;          /* spv_stage                                 */
    char      key[SPLAT_KEY_CHARS + 1];
    uint32_t *words;
    size_t    nwords;
    bool      cached;         /* came from the cache (and validated)      */
    char     *log;            /* compile / validation failure             */
} job;

typedef struct combo_info {
    int *textures, ntextures; /* layout textures used                     */
    int *params, nparams;
} combo_info;

typedef struct build {
    const splat_build_desc *desc;
    splat_scene    scene;
    bool           scene_ok;
    splat_analysis analysis;
    bool           analysis_ok;
    sparse_masks   sparse;    /* painted masks as stored (not dense)      */
    bool           sparse_ok;
    splat_layout   layout;
    bool           layout_ok;
    combo_info    *combos;
    job           *jobs;
    int            njobs, capjobs;
    splat_cache    cache;
    char           inputs[SPLAT_KEY_CHARS + 1]; /* key of every input file */
    sg_diags      *d;
    sg_loc         loc;       /* the scene file, for errors without a line */
    char          *out;       /* desc->out without trailing slashes        */
} build;

static job *job_add(build *b, job_kind kind, int index, char *file, int stage)
{
    if (b->njobs == b->capjobs) {
        b->capjobs = b->capjobs ? 2 * b->capjobs : 16;
        b->jobs = realloc(b->jobs, (size_t)b->capjobs * sizeof *b->jobs);
        if (!b->jobs)
            abort();
    }
    job *j = &b->jobs[b->njobs++];
    memset(j, 0, sizeof *j);
    j->kind = kind;
    j->index = index;
    j->file = file;
    j->stage = stage;
    return j;
}

/* Run fn(b, job) for every job with `pending` set, on `threads` threads. */
typedef struct pool {
    build          *b;
    void          (*fn)(build *b, job *j);
    bool           *pending;
    int            *order;    /* job indices, largest GLSL first: the long
                                 compiles start early, the short ones fill
                                 the tail                                  */
    int             next;
    pthread_mutex_t lock;
} pool;

static const build *sort_build;  /* qsort has no context argument */

static int by_size_desc(const void *a, const void *b)
{
    const job *x = &sort_build->jobs[*(const int *)a];
    const job *y = &sort_build->jobs[*(const int *)b];
    if (x->glsl.len != y->glsl.len)
        return x->glsl.len < y->glsl.len ? 1 : -1;
    return *(const int *)a - *(const int *)b;
}

static void *pool_worker(void *arg)
{
    pool *p = arg;
    for (;;) {
        pthread_mutex_lock(&p->lock);
        while (p->next < p->b->njobs && !p->pending[p->order[p->next]])
            p->next++;
        int i = p->next < p->b->njobs ? p->order[p->next++] : -1;
        pthread_mutex_unlock(&p->lock);
        if (i < 0)
            return NULL;
        p->fn(p->b, &p->b->jobs[i]);
    }
}

static void run_pool(build *b, void (*fn)(build *, job *), bool *pending, int threads)
{
    pool p = {.b = b, .fn = fn, .pending = pending};
    p.order = xcalloc((size_t)b->njobs, sizeof *p.order);
    for (int i = 0; i < b->njobs; i++)
        p.order[i] = i;
    sort_build = b;  /* single-threaded here */
    qsort(p.order, (size_t)b->njobs, sizeof *p.order, by_size_desc);
    pthread_mutex_init(&p.lock, NULL);
    if (threads < 1)
        threads = 1;
    pthread_t *t = xcalloc((size_t)threads, sizeof *t);
    int started = 0;
    for (int i = 1; i < threads; i++)
        if (pthread_create(&t[i], NULL, pool_worker, &p) == 0)
            started = i;
        else
            break;
    pool_worker(&p);  /* the calling thread works too */
    for (int i = 1; i <= started; i++)
        pthread_join(t[i], NULL);
    free(t);
    free(p.order);
    pthread_mutex_destroy(&p.lock);
}

static void compile_job(build *b, job *j)
{
    spv_compile(j->glsl.s, j->stage, j->file, &j->words, &j->nwords, &j->log);
}

static void validate_job(build *b, job *j)
{
    if (!j->words)
        return;
    char *log = NULL;
    if (spv_validate(j->words, j->nwords, &log)) {
        free(log);
        return;
    }
    free(j->log);
    j->log = log;
    free(j->words);
    j->words = NULL;
}

/* ---- compose -------------------------------------------------------------- */

static bool add_composite(build *b, job_kind kind, int index, const int *materials,
                          int n, bool reference, combo_info *info)
{
    splat_composite c;
    splat_compose_desc cd = {.materials = materials, .nmaterials = n,
                             .reference = reference};
    if (!splat_compose(&b->layout, &cd, &c, b->d))
        return false;
    for (int pass = 0; pass < (kind == JOB_COMBO && b->desc->flat ? 2 : 1); pass++) {
        job_kind k = pass ? JOB_FLAT : kind;
        char title[96];
        char *file;
        if (k == JOB_REF) {
            snprintf(title, sizeof title, "multi-pass reference pass of material %d", index);
            file = xasprintf("shaders/ref_%04d", index);
        } else if (k == JOB_UBER) {
            snprintf(title, sizeof title, "über-shader: every material of the scene");
            file = xasprintf("shaders/uber");
        } else {
            snprintf(title, sizeof title, "composite of combination %d%s", index,
                     k == JOB_FLAT ? " (flat: no branches)" : "");
            file = xasprintf(k == JOB_FLAT ? "shaders/flat_%04d" : "shaders/%04d", index);
        }
        job *j = job_add(b, k, index, file, SPV_STAGE_FRAGMENT);
        /* The MASK debug view recomputes every layer's mask: only the
         * über-shader carries it (the runtime draws that view with it),
         * which keeps each composite about half as long for glslang. */
        splat_glsl_desc gd = {.title = title, .flat = k == JOB_FLAT,
                              .painted_sparse = b->sparse_ok,
                              .no_mask_view = k != JOB_UBER};
        splat_composite_glsl(&b->layout, &c, &gd, &j->glsl);
    }
    if (info) {
        info->ntextures = c.ntextures;
        info->textures = xcalloc((size_t)c.ntextures, sizeof *info->textures);
        memcpy(info->textures, c.textures, (size_t)c.ntextures * sizeof *c.textures);
        info->nparams = c.nparams;
        info->params = xcalloc((size_t)c.nparams, sizeof *info->params);
        memcpy(info->params, c.params, (size_t)c.nparams * sizeof *c.params);
    }
    splat_composite_free(&c);
    return true;
}

static bool compose_all(build *b)
{
    const splat_analysis *a = &b->analysis;
    int nm = b->scene.nmaterials;
    b->combos = xcalloc((size_t)a->ncombos, sizeof *b->combos);
    for (int i = 0; i < a->ncombos; i++)
        if (!add_composite(b, JOB_COMBO, i, a->combos[i].materials,
                           a->combos[i].nmaterials, false, &b->combos[i]))
            return false;
    int *all = xcalloc((size_t)nm, sizeof *all);
    for (int k = 0; k < nm; k++)
        all[k] = nm - 1 - k;
    bool ok = add_composite(b, JOB_UBER, 0, all, nm, false, NULL);
    free(all);
    for (int k = 0; ok && k < nm; k++)
        ok = add_composite(b, JOB_REF, k, &k, 1, true, NULL);
    if (!ok)
        return false;
    job *v = job_add(b, JOB_VERTEX, 0, xasprintf("shaders/terrain.vert"), SPV_STAGE_VERTEX);
    ir_buf_printf(&v->glsl, "%s", SPLAT_GLSL_VERTEX);
    for (int i = 0; i < b->njobs; i++)
        splat_shader_key(b->jobs[i].glsl.s, b->jobs[i].stage, b->jobs[i].key);
    return true;
}

/* ---- writing -------------------------------------------------------------- */

static void write_error(build *b, const char *path)
{
    char msg[PATH_MAX + 128];
    snprintf(msg, sizeof msg, "cannot write '%s': %s", path, strerror(errno));
    sg_error(b->d, b->loc, SG_E_SCENE, msg);
}

static bool write_file(build *b, const char *dir, const char *name, const void *data,
                       size_t n)
{
    char *path = xasprintf("%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    bool ok = f && fwrite(data, 1, n, f) == n;
    if (f && fclose(f) != 0)
        ok = false;
    if (!ok)
        write_error(b, path);
    free(path);
    return ok;
}

static bool copy_file(build *b, const char *from, const char *dir, const char *name)
{
    FILE *f = fopen(from, "rb");
    if (!f) {
        sg_error(b->d, b->loc, SG_E_IO, from, strerror(errno));
        return false;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    if (!buf)
        abort();
    size_t got;
    while ((got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            cap *= 2;
            buf = realloc(buf, cap);
            if (!buf)
                abort();
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

/* `path` relative to folder `base` when both resolve (for manifests that
 * do not depend on where the scene lives); else `path` as given. */
static char *relative_to(const char *base, const char *path)
{
    char rb[PATH_MAX], rp[PATH_MAX];
    if (!realpath(base, rb) || !realpath(path, rp))
        return strdup(path);
    size_t i = 0, last = 0;
    while (rb[i] && rb[i] == rp[i]) {
        if (rb[i] == '/')
            last = i;
        i++;
    }
    if (!rb[i] && (rp[i] == '/' || !rp[i]))
        last = i;  /* base is a prefix folder of path */
    size_t cap = strlen(rp) + 3 * 64 + 1;
    char *out = xcalloc(cap, 1);
    for (const char *s = rb + last; *s; s++)
        if (*s == '/' && strlen(out) + 4 < cap)
            strcat(out, "../");
    strncat(out, rp + last + (rp[last] == '/'), cap - strlen(out) - 1);
    return out;
}

static char *dir_of(const char *path)
{
    const char *s = strrchr(path, '/');
    if (!s)
        return strdup(".");
    if (s == path)
        return strdup("/");
    return strndup(path, (size_t)(s - path));
}

static json_t *jreals(const double *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static json_t *jints(const int *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, json_integer(v[i]));
    return a;
}

static json_t *jshader(const char *file, const char *vert_ext)
{
    json_t *o = json_object();
    char buf[128];
    snprintf(buf, sizeof buf, "%s%s", file, vert_ext ? "" : ".frag");
    json_object_set_new(o, "glsl", json_string(buf));
    snprintf(buf, sizeof buf, "%s.spv", file);
    json_object_set_new(o, "spirv", json_string(buf));
    return o;
}

static const char *filter_str(ir_filter f) { return f == IR_FILTER_NEAREST ? "nearest" : "linear"; }
static const char *wrap_str(ir_wrap w)
{
    return w == IR_WRAP_CLAMP ? "clamp" : w == IR_WRAP_MIRROR ? "mirror" : "repeat";
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

/* A texture's stored mip files (texgen.h's contract): "X.mipK.ext" beside
 * "X.ext" for K = 1, 2, … while they exist.  mip_path(path, k) is that name
 * for any path (source or pack); mip_count(src) how many the source has. */
static char *mip_path(const char *path, int k)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        return xasprintf("%s.mip%d", path, k);
    return xasprintf("%.*s.mip%d%s", (int)(dot - path), path, k, dot);
}

static int mip_count(const char *src)
{
    int k = 0;
    for (;;) {
        char *p = mip_path(src, k + 1);
        struct stat st;
        bool there = stat(p, &st) == 0 && S_ISREG(st.st_mode);
        free(p);
        if (!there || k >= 32)
            return k;
        k++;
    }
}

static json_t *manifest(build *b, char **tex_names, const char *dir)
{
    const splat_scene *s = &b->scene;
    const sg_scene *sc = s->desc;
    const splat_layout *L = &b->layout;
    const splat_analysis *a = &b->analysis;
    json_t *m = json_object();
    json_object_set_new(m, "format", json_string("splatc-pack"));
    json_object_set_new(m, "version", json_integer(1));
    json_object_set_new(m, "abi", json_integer(SPLAT_ABI_VERSION));
    json_object_set_new(m, "compiler", json_string("splatc " SPLATC_VERSION));
    json_object_set_new(m, "inputs", json_string(b->inputs));

    json_t *scene = json_object();
    json_object_set_new(scene, "name", json_string(sc->name ? sc->name : ""));
    /* relative to the pack folder (`dir` is its sibling: same answer) */
    char *scene_src = relative_to(dir, b->desc->scene);
    json_object_set_new(scene, "source", json_string(scene_src));
    free(scene_src);
    json_t *hf = json_object();
    json_object_set_new(hf, "file", json_string("heightfield.r16"));
    json_object_set_new(hf, "width", json_integer(s->terrain.width));
    json_object_set_new(hf, "height", json_integer(s->terrain.height));
    json_object_set_new(scene, "heightfield", hf);
    json_object_set_new(scene, "size", jreals(s->terrain.size, 2));
    json_object_set_new(scene, "max_height", json_real(s->terrain.max_height));
    json_object_set_new(scene, "height_offset", json_real(s->terrain.height_offset));
    json_object_set_new(scene, "cell_texels", json_integer(a->cell_texels));
    json_t *cams = json_array();
    for (int i = 0; i < sc->ncameras; i++) {
        json_t *c = json_object();
        json_object_set_new(c, "name", json_string(sc->cameras[i].name));
        json_object_set_new(c, "position", jreals(sc->cameras[i].position, 3));
        json_object_set_new(c, "look", jreals(sc->cameras[i].look, 3));
        json_array_append_new(cams, c);
    }
    json_object_set_new(scene, "cameras", cams);
    if (sc->has_destruction) {
        json_t *dd = json_object();
        json_object_set_new(dd, "origin", jreals(sc->destruction_origin, 2));
        json_object_set_new(dd, "size", jreals(sc->destruction_size, 2));
        json_object_set_new(dd, "cell_size", json_real(sc->destruction_cell));
        json_object_set_new(scene, "destruction", dd);
    } else {
        json_object_set_new(scene, "destruction", json_null());
    }
    json_object_set_new(m, "scene", scene);

    char *scene_dir = dir_of(b->desc->scene);
    json_t *mats = json_array();
    for (int k = 0; k < L->nmaterials; k++) {
        json_t *o = json_object();
        json_object_set_new(o, "name", json_string(L->materials[k]));
        int pi = sg_material_find(s->prog, L->materials[k]);
        sg_loc ml = pi >= 0 ? sg_material_loc(s->prog, pi) : (sg_loc){0};
        char *src = ml.file ? relative_to(scene_dir, ml.file) : strdup("");
        json_object_set_new(o, "source", json_string(src));
        free(src);
        char file[64];
        snprintf(file, sizeof file, "shaders/ref_%04d", k);
        json_object_set_new(o, "reference", jshader(file, NULL));
        json_array_append_new(mats, o);
    }
    free(scene_dir);
    json_object_set_new(m, "materials", mats);

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
        json_object_set_new(o, "min", json_real(p->lo));
        json_object_set_new(o, "max", json_real(p->hi));
        json_object_set_new(o, "offset", json_integer(16 * i));
        json_array_append_new(params, o);
    }
    json_object_set_new(m, "params", params);
    json_object_set_new(m, "params_size", json_integer(16 * (L->nparams > 0 ? L->nparams : 1)));

    json_t *texs = json_array();
    for (int i = 0; i < L->ntextures; i++) {
        const ir_texture *t = &L->src->textures[L->textures[i]];
        json_t *o = json_object();
        json_object_set_new(o, "file", json_string(tex_names[i]));
        json_object_set_new(o, "binding", json_integer(SPLAT_BIND_TEXTURE0 + i));
        json_object_set_new(o, "filter", json_string(filter_str(t->filter)));
        json_object_set_new(o, "mip", json_string(filter_str(t->mip)));
        json_object_set_new(o, "wrap", json_string(wrap_str(t->wrap)));
        json_object_set_new(o, "srgb", json_boolean(t->srgb));
        int mips = mip_count(t->file);
        if (mips > 0)
            json_object_set_new(o, "mips", json_integer(mips));
        json_array_append_new(texs, o);
    }
    json_object_set_new(m, "textures", texs);

    json_t *painted = json_array();
    for (int i = 0; i < L->npainted; i++) {
        json_t *o = json_object();
        json_object_set_new(o, "name", json_string(L->painted[i]));
        json_object_set_new(o, "layer", json_integer(i));
        json_array_append_new(painted, o);
    }
    json_object_set_new(m, "painted", painted);
    /* how they are stored: dense layers or the sparse quad-tree */
    json_object_set_new(m, "painted_format",
                        json_string(splat_painted_format_name(b->desc->painted)));
    json_object_set_new(m, "painted_file",
                        json_string(b->sparse_ok ? "painted.sparse" : "painted.r8"));

    json_t *combos = json_array();
    for (int i = 0; i < a->ncombos; i++) {
        const job *cj = NULL, *fj = NULL;
        for (int k = 0; k < b->njobs; k++) {
            if (b->jobs[k].index == i && b->jobs[k].kind == JOB_COMBO)
                cj = &b->jobs[k];
            if (b->jobs[k].index == i && b->jobs[k].kind == JOB_FLAT)
                fj = &b->jobs[k];
        }
        json_t *o = json_object();
        json_object_set_new(o, "id", json_integer(i));
        json_object_set_new(o, "materials", jints(a->combos[i].materials,
                                                  a->combos[i].nmaterials));
        char buf[160];
        snprintf(buf, sizeof buf, "%s.frag", cj->file);
        json_object_set_new(o, "glsl", json_string(buf));
        snprintf(buf, sizeof buf, "%s.spv", cj->file);
        json_object_set_new(o, "spirv", json_string(buf));
        if (fj)
            json_object_set_new(o, "flat", jshader(fj->file, NULL));
        json_object_set_new(o, "textures", jints(b->combos[i].textures, b->combos[i].ntextures));
        json_object_set_new(o, "params", jints(b->combos[i].params, b->combos[i].nparams));
        json_object_set_new(o, "cells", json_integer(a->combos[i].ncells));
        json_object_set_new(o, "nodes", json_integer(a->combos[i].nnodes));
        json_object_set_new(o, "hash", json_string(cj->key));
        json_array_append_new(combos, o);
    }
    json_object_set_new(m, "combinations", combos);
    json_object_set_new(m, "uber", jshader("shaders/uber", NULL));
    json_object_set_new(m, "vertex", jshader("shaders/terrain.vert", ""));

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
    json_object_set_new(m, "quadtree", qt);
    return m;
}

static bool write_sparse(build *b, const char *dir)
{
    char *path = xasprintf("%s/painted.sparse", dir);
    FILE *f = fopen(path, "wb");
    bool ok = f && sparse_write(&b->sparse, f);
    if (f && fclose(f) != 0)
        ok = false;
    if (!ok)
        write_error(b, path);
    free(path);
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

    for (int i = 0; ok && i < b->njobs; i++) {
        const job *j = &b->jobs[i];
        char *name = xasprintf("%s%s", j->file, j->stage == SPV_STAGE_VERTEX ? "" : ".frag");
        ok = write_file(b, dir, name, j->glsl.s, j->glsl.len);
        free(name);
        name = xasprintf("%s.spv", j->file);
        ok = ok && write_file(b, dir, name, j->words, 4 * j->nwords);
        free(name);
    }

    char **tex_names = texture_names(b);
    for (int i = 0; ok && i < b->layout.ntextures; i++) {
        bool first = true;
        for (int k = 0; k < i; k++)
            first &= strcmp(tex_names[k], tex_names[i]) != 0;
        const char *src = b->layout.src->textures[b->layout.textures[i]].file;
        if (first)
            ok = copy_file(b, src, dir, tex_names[i]);
        for (int k = 1, n = first ? mip_count(src) : 0; ok && k <= n; k++) {
            char *from = mip_path(src, k), *to = mip_path(tex_names[i], k);
            ok = copy_file(b, from, dir, to);
            free(from);
            free(to);
        }
    }
    if (ok) {
        json_t *m = manifest(b, tex_names, dir);
        char *text = json_dumps(m, JSON_INDENT(2) | JSON_PRESERVE_ORDER |
                                       JSON_REAL_PRECISION(15));
        json_decref(m);
        if (!text)
            abort();
        size_t n = strlen(text);
        char *withnl = xasprintf("%s\n", text);
        free(text);
        ok = write_file(b, dir, "manifest.json", withnl, n + 1);
        free(withnl);
    }
    for (int i = 0; i < b->layout.ntextures; i++)
        free(tex_names[i]);
    free(tex_names);
    return ok;
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
    sg_error(b->d, b->loc, SG_E_SCENE, msg);
    return false;
}

static bool write_pack(build *b)
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
    bool ok = write_contents(b, tmp);
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

/* ---- the report: what each composite costs against the über-shader ----- */

/* Instructions in a SPIR-V module (each one's first word holds its length). */
static int spirv_instructions(const uint32_t *w, size_t n)
{
    int count = 0;
    for (size_t i = 5; i < n; count++) {
        size_t len = w[i] >> 16;
        if (len == 0)
            break;  /* malformed: validation has said so already */
        i += len;
    }
    return count;
}

/* One composite's line of the report. */
typedef struct shader_row {
    int id, layers, instructions, ntextures, nparams;
} shader_row;

static void print_shader_report(FILE *out, int uber, int ntextures, int nparams,
                                const shader_row *rows, int n)
{
    fprintf(out, "shaders: SPIR-V instructions and resources per composite\n"
                 "  (the über-shader: %d instructions, %d textures, %d params)\n"
                 "  id  layers  instructions  of über  textures  params\n",
            uber, ntextures, nparams);
    double sum = 0;
    for (int i = 0; i < n; i++) {
        const shader_row *r = &rows[i];
        fprintf(out, "%4d  %6d  %12d  %6.0f%%  %4d/%-3d  %3d/%d\n", r->id, r->layers,
                r->instructions, 100.0 * r->instructions / uber, r->ntextures, ntextures,
                r->nparams, nparams);
        sum += (double)r->instructions / uber;
    }
    if (n)
        fprintf(out, "mean composite size: %.0f%% of the über-shader\n", 100.0 * sum / n);
}

static void report_shaders(build *b, FILE *out)
{
    const job *uber = NULL;
    for (int i = 0; i < b->njobs; i++)
        if (b->jobs[i].kind == JOB_UBER)
            uber = &b->jobs[i];
    if (!uber || !uber->words)
        return;
    shader_row *rows = xcalloc((size_t)b->njobs + 1, sizeof *rows);
    int n = 0;
    for (int i = 0; i < b->njobs; i++) {
        const job *j = &b->jobs[i];
        if (j->kind != JOB_COMBO || !j->words)
            continue;
        const combo_info *c = &b->combos[j->index];
        rows[n++] = (shader_row){j->index, b->analysis.combos[j->index].nmaterials,
                                 spirv_instructions(j->words, j->nwords), c->ntextures,
                                 c->nparams};
    }
    print_shader_report(out, spirv_instructions(uber->words, uber->nwords),
                        b->layout.ntextures, b->layout.nparams, rows, n);
    free(rows);
}

/* SPIR-V instructions of the pack's shader file `rel`, or -1. */
static int pack_spirv_instructions(const build *b, const char *rel)
{
    if (!rel)
        return -1;
    char *path = xasprintf("%s/%s", b->out, rel);
    FILE *f = fopen(path, "rb");
    free(path);
    if (!f)
        return -1;
    uint32_t *w = NULL;
    size_t n = 0, cap = 0, got;
    do {
        if (n == cap) {
            cap = cap ? 2 * cap : 4096;
            w = realloc(w, cap * sizeof *w);
            if (!w)
                abort();
        }
        got = fread(w + n, sizeof *w, cap - n, f);
        n += got;
    } while (got > 0);
    fclose(f);
    int count = spirv_instructions(w, n);
    free(w);
    return count;
}

/* The same report for a pack that is up to date, from its manifest and
 * SPIR-V files (nothing is composed or compiled). */
static void report_shaders_from_pack(build *b, FILE *out)
{
    char *mf = xasprintf("%s/manifest.json", b->out);
    json_t *m = json_load_file(mf, 0, NULL);
    free(mf);
    if (!m)
        return;
    json_t *combos = json_object_get(m, "combinations");
    int uber = pack_spirv_instructions(
        b, json_string_value(json_object_get(json_object_get(m, "uber"), "spirv")));
    size_t nc = json_array_size(combos);
    shader_row *rows = xcalloc(nc + 1, sizeof *rows);
    int n = 0;
    for (size_t i = 0; i < nc && uber > 0; i++) {
        json_t *c = json_array_get(combos, i);
        int k = pack_spirv_instructions(b, json_string_value(json_object_get(c, "spirv")));
        if (k < 0)
            continue;
        rows[n++] = (shader_row){(int)json_integer_value(json_object_get(c, "id")),
                                 (int)json_array_size(json_object_get(c, "materials")), k,
                                 (int)json_array_size(json_object_get(c, "textures")),
                                 (int)json_array_size(json_object_get(c, "params"))};
    }
    if (uber > 0)
        print_shader_report(out, uber, (int)json_array_size(json_object_get(m, "textures")),
                            (int)json_array_size(json_object_get(m, "params")), rows, n);
    free(rows);
    json_decref(m);
}

/* The painted masks' bytes in the pack next to their dense 8-bit size. */
static void report_painted(build *b, FILE *out)
{
    const splat_scene *s = &b->scene;
    if (b->sparse_ok) {
        sparse_print_stats(&b->sparse, out);
        return;
    }
    size_t dense = (size_t)s->desc->npainted * (size_t)s->terrain.width *
                   (size_t)s->terrain.height;
    fprintf(out, "painted masks: %d stored dense (painted.r8): %zu B\n",
            s->desc->npainted, dense);
}

/* ---- nothing changed? ---------------------------------------------------- */

static bool hash_file(XXH3_state_t *st, const char *path)
{
    FILE *f = fopen(path, "rb");
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

/* The key of everything the pack is made from (contents, not names or
 * times, so a moved or touched scene is still up to date).  False if a
 * file cannot be read (then there is no shortcut). */
static bool inputs_key(build *b)
{
    const splat_scene *s = &b->scene;
    XXH3_state_t *st = XXH3_createState();
    if (!st)
        abort();
    XXH3_128bits_reset(st);
    char head[128];
    int n = snprintf(head, sizeof head, "splatc %s\nabi %d\nflat %d\npainted %s\n",
                     SPLATC_VERSION, SPLAT_ABI_VERSION, b->desc->flat,
                     splat_painted_format_name(b->desc->painted));
    XXH3_128bits_update(st, head, (size_t)n);
    bool ok = true;
    for (int i = 0; ok && i < sg_file_count(s->prog); i++)
        ok = hash_file(st, sg_file_path(s->prog, i));
    ok = ok && hash_file(st, s->desc->heightfield);
    for (int i = 0; ok && i < s->desc->npainted; i++)
        ok = hash_file(st, s->desc->painted[i].file);
    for (int i = 0; ok && i < s->ir.ntextures; i++) {
        ok = hash_file(st, s->ir.textures[i].file);
        for (int k = 1, n = mip_count(s->ir.textures[i].file); ok && k <= n; k++) {
            char *m = mip_path(s->ir.textures[i].file, k);
            ok = hash_file(st, m);
            free(m);
        }
    }
    XXH128_hash_t h = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    snprintf(b->inputs, sizeof b->inputs, "%016llx%016llx", (unsigned long long)h.high64,
             (unsigned long long)h.low64);
    if (!ok)
        b->inputs[0] = 0;  /* recorded as "": never up to date */
    return ok;
}

static bool has_files(const char *pack, json_t *shader)
{
    const char *keys[] = {"glsl", "spirv"};
    for (int i = 0; i < 2; i++) {
        const char *rel = json_string_value(json_object_get(shader, keys[i]));
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
             (!b->desc->flat || has_files(b->out, json_object_get(c, "flat")));
    }
    json_t *mats = json_object_get(m, "materials");
    for (size_t i = 0; ok && i < json_array_size(mats); i++)
        ok = has_files(b->out, json_object_get(json_array_get(mats, i), "reference"));
    ok = ok && has_files(b->out, json_object_get(m, "uber")) &&
         has_files(b->out, json_object_get(m, "vertex"));
    *ncombos = ok ? (int)json_array_size(combos) : 0;
    json_decref(m);
    return ok;
}

/* ---- the pipeline --------------------------------------------------------- */

static void build_free(build *b)
{
    for (int i = 0; i < b->njobs; i++) {
        free(b->jobs[i].file);
        ir_buf_free(&b->jobs[i].glsl);
        free(b->jobs[i].words);
        free(b->jobs[i].log);
    }
    free(b->jobs);
    if (b->combos)
        for (int i = 0; i < b->analysis.ncombos; i++) {
            free(b->combos[i].textures);
            free(b->combos[i].params);
        }
    free(b->combos);
    if (b->layout_ok)
        splat_layout_free(&b->layout);
    if (b->analysis_ok)
        splat_analysis_free(&b->analysis);
    if (b->sparse_ok)
        sparse_free(&b->sparse);
    if (b->scene_ok)
        splat_scene_free(&b->scene);
    splat_cache_close(&b->cache);
    free(b->out);
}

/* glslang's message already says "internal compiler error: …". */
static void report_job_error(build *b, const job *j)
{
    const char *msg = j->log ? j->log : "no SPIR-V produced";
    static const char prefix[] = "internal compiler error: ";
    if (strncmp(msg, prefix, sizeof prefix - 1) == 0)
        msg += sizeof prefix - 1;
    char *m = xasprintf("%s: %s", j->file, msg);
    sg_error(b->d, b->loc, SG_E_INTERNAL, m);
    free(m);
}

/* The painted masks as the pack stores them (sparse unless --painted
 * dense), then the analysis over them. */
static bool analyse(build *b)
{
    if (b->desc->painted != SPLAT_PAINTED_DENSE) {
        b->sparse_ok = splat_painted_build(&b->scene, b->desc->painted, &b->sparse, b->d);
        if (!b->sparse_ok)
            return false;
        b->scene.sparse = &b->sparse;
    }
    b->analysis_ok = splat_analyze(&b->scene, &b->analysis, b->d);
    return b->analysis_ok;
}

bool splat_build(const splat_build_desc *desc, splat_build_stats *st, sg_diags *d)
{
    build b = {.desc = desc, .d = d, .loc = {.file = desc->scene}};
    /* "pack/" would put the temporary folder inside the old pack */
    b.out = strdup(desc->out);
    if (!b.out)
        abort();
    for (size_t n = strlen(b.out); n > 1 && b.out[n - 1] == '/'; n--)
        b.out[n - 1] = 0;
    splat_build_stats dummy;
    if (!st)
        st = &dummy;
    memset(st, 0, sizeof *st);
    int errors = d->nerrors;

    double t = now();
    b.scene_ok = splat_scene_load(&b.scene, desc->scene, desc->search_paths, d);
    st->load = now() - t;
    if (!b.scene_ok || d->nerrors > errors)
        goto out;
    if (inputs_key(&b) && up_to_date(&b, &st->combos)) {
        st->up_to_date = true;
        st->load = now() - t;
        /* nothing to rebuild; the report still wants the (cheap) analysis
         * and the shaders' figures, read back from the pack */
        if (desc->report) {
            t = now();
            bool ok = analyse(&b);
            st->analysis = now() - t;
            if (ok && d->nerrors == errors) {
                splat_analysis_report(&b.scene, &b.analysis, desc->report);
                report_painted(&b, desc->report);
                report_shaders_from_pack(&b, desc->report);
            }
        }
        goto out;
    }
    st->load = now() - t;

    t = now();
    b.analysis_ok = analyse(&b);
    st->analysis = now() - t;
    if (!b.analysis_ok || d->nerrors > errors)
        goto out;
    if (desc->report) {
        splat_analysis_report(&b.scene, &b.analysis, desc->report);
        report_painted(&b, desc->report);
    }

    t = now();
    b.layout_ok = splat_layout_from_scene(&b.layout, &b.scene, d);
    bool composed = b.layout_ok && compose_all(&b);
    st->compose = now() - t;
    if (!composed || d->nerrors > errors)
        goto out;

    t = now();
    if (!desc->no_cache)
        splat_cache_open(&b.cache, desc->cache_dir);  /* disabled on failure */
    bool *pending = xcalloc((size_t)b.njobs, sizeof *pending);
    for (int i = 0; i < b.njobs; i++) {
        job *j = &b.jobs[i];
        j->cached = splat_cache_get(&b.cache, j->key, &j->words, &j->nwords);
        pending[i] = !j->cached;
    }
    run_pool(&b, compile_job, pending, desc->jobs);
    st->glslang = now() - t;

    t = now();
    for (int i = 0; i < b.njobs; i++)
        pending[i] = !b.jobs[i].cached;
    run_pool(&b, validate_job, pending, desc->jobs);
    for (int i = 0; i < b.njobs; i++) {
        job *j = &b.jobs[i];
        if (!j->words) {
            report_job_error(&b, j);
            continue;
        }
        if (!j->cached)
            splat_cache_put(&b.cache, j->key, j->words, j->nwords);
        bool combo = j->kind == JOB_COMBO;
        st->shaders++;
        st->combos += combo;
        if (j->cached) {
            st->shaders_cached++;
            st->combos_cached += combo;
        } else {
            st->shaders_compiled++;
            st->combos_compiled += combo;
        }
    }
    free(pending);
    st->validate = now() - t;
    if (d->nerrors > errors)
        goto out;
    if (desc->report)
        report_shaders(&b, desc->report);

    t = now();
    write_pack(&b);
    st->write = now() - t;

out:
    build_free(&b);
    return d->nerrors == errors;
}
