/* build_jobs.c — the shaders a pack build compiles (build.h): a job per
 * shader (a composite per combination, its flat variant with --flat, the
 * über-shader, a reference pass per material, the vertex shader, the
 * compute variants) with its GLSL and cache key; the composites are built
 * one after the other, their GLSL written on N threads; cache lookups, then
 * glslang on the misses and spirv-val on what it produced, each on N
 * threads (largest GLSL first); validated modules go into the cache
 * (cache.c).
 */
#include "build.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abi.h"
#include "progress.h"
#include "spv.h"
#include "stand_in.h"

static job *job_add(build *b, job_kind kind, int index, char *file, int stage)
{
    if (b->njobs == b->capjobs) {
        b->capjobs = b->capjobs ? 2 * b->capjobs : 16;
        b->jobs = xrealloc(b->jobs, (size_t)b->capjobs * sizeof *b->jobs);
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
    int            *order;    /* job indices, largest GLSL (or composite)
                                 first: the long jobs start early, the
                                 short ones fill the tail                 */
    int             next;
    pthread_mutex_t lock;
    splat_progress  progress; /* under lock                               */
} pool;

static const build *sort_build;  /* qsort has no context argument */

static int by_size_desc(const void *a, const void *b)
{
    const job *x = &sort_build->jobs[*(const int *)a];
    const job *y = &sort_build->jobs[*(const int *)b];
    if (x->glsl.len != y->glsl.len)
        return x->glsl.len < y->glsl.len ? 1 : -1;
    /* before the GLSL exists (emit_job): the larger composite first */
    uint32_t nx = x->composite ? x->composite->ir.nnodes : 0;
    uint32_t ny = y->composite ? y->composite->ir.nnodes : 0;
    if (nx != ny)
        return nx < ny ? 1 : -1;
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
        pthread_mutex_lock(&p->lock);
        splat_progress_step(&p->progress);
        pthread_mutex_unlock(&p->lock);
    }
}

static void run_pool(build *b, const char *phase, void (*fn)(build *, job *), bool *pending,
                     int threads)
{
    pool p = {.b = b, .fn = fn, .pending = pending};
    int n = 0;
    for (int i = 0; i < b->njobs; i++)
        n += pending[i];
    splat_progress_begin(&p.progress, phase, n);
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
    splat_progress_end(&p.progress);
    pthread_mutex_destroy(&p.lock);
}

/* glslang, then spirv-val on what it produced, in one task of the pool:
 * the über-shader's long validation runs beside the composites' compiles
 * instead of after all of them (largest GLSL first).  A module whose
 * shape (cache.h splat_spirv_shape_key: its words but the float
 * constants' values) passed spirv-val before is not validated again. */
static void compile_job(build *b, job *j)
{
    if (!spv_compile(j->glsl.s, j->stage, j->file, &j->words, &j->nwords, &j->log))
        return;
    char shape[SPLAT_KEY_CHARS + 1];
    bool keyed = splat_spirv_shape_key(j->words, j->nwords, shape);
    if (keyed && splat_cache_valid(&b->cache, shape)) {
        j->shape_valid = true;
        return;
    }
    char *log = NULL;
    if (spv_validate(j->words, j->nwords, &log)) {
        free(log);
        if (keyed)
            splat_cache_mark_valid(&b->cache, shape);   /* failure: validated again */
        return;
    }
    free(j->log);
    j->log = log;
    free(j->words);
    j->words = NULL;
}

/* A job's GLSL from its composite (on the pool: splat_composite_glsl only
 * reads the composite and the layout, so the variants of one composite
 * and different composites are written at once). */
static void emit_job(build *b, job *j)
{
    splat_composite_glsl(&b->layout, j->composite, &j->gdesc, &j->glsl);
}

/* ---- compose -------------------------------------------------------------- */

static void keep_composite(build *b, splat_composite *pc)
{
    b->composites = xrealloc(b->composites, sizeof *b->composites * (size_t)(b->ncomposites + 1));
    b->composites[b->ncomposites++] = pc;
}

/* The distance classes of combination `index` (distance.c): each a
 * fragment and a compute job, shaders/NNNN.dK{.frag,.comp}. */
static void add_classes(build *b, int index, const splat_composite *c, combo_info *info)
{
    splat_dclass *v;
    int n = splat_distance_classes(&b->layout, c, &v, b->d);
    for (int k = 0; k < n; k++) {
        splat_composite *pc = xcalloc(1, sizeof *pc);
        *pc = v[k].comp;
        keep_composite(b, pc);
        info->dlo[k] = v[k].lo;
        info->dhi[k] = v[k].hi;
        info->dcost[k] = v[k].cost;
        for (int compute = 0; compute < 2; compute++) {
            char *file = xasprintf(compute ? "shaders/%04d.d%d.comp" : "shaders/%04d.d%d",
                                   index, k);
            job *j = job_add(b, compute ? JOB_CLASS_COMPUTE : JOB_CLASS, index, file,
                             compute ? SPV_STAGE_COMPUTE : SPV_STAGE_FRAGMENT);
            j->dclass = k;
            /* GLSL only, both stages, with --glsl-compute: the runtime
             * then compiles a class on first use (PACK.md "Distance classes") */
            j->glsl_only = b->desc->glsl_compute;
            snprintf(j->title, sizeof j->title,
                     "composite of combination %d, distance class %d (%g m and %s)%s", index, k,
                     v[k].lo == 0 ? v[k].hi : v[k].lo, v[k].lo == 0 ? "nearer" : "beyond",
                     compute ? " (compute)" : "");
            j->composite = pc;
            j->gdesc = (splat_glsl_desc){.painted_sparse = b->sparse_ok,
                                         .painted_places = b->painted_places,
                                         .no_mask_view = true, .compute = compute != 0};
        }
    }
    info->nclasses = n;
    b->st->dclasses += n;
    free(v);   /* the composites moved into b->composites */
}

static bool add_composite(build *b, job_kind kind, int index, const int *materials,
                          int n, bool reference, combo_info *info)
{
    splat_composite *pc = xcalloc(1, sizeof *pc);
    splat_compose_desc cd = {.materials = materials, .nmaterials = n,
                             .reference = reference};
    if (!splat_compose(&b->layout, &cd, pc, b->d)) {
        free(pc);
        return false;
    }
    keep_composite(b, pc);
    const splat_composite *c = pc;
    /* the variants of this composite: fragment, then flat (--flat) and
     * compute (composites and the über-shader) */
    job_kind kinds[4] = {kind};
    int nkinds = 1;
    if (kind == JOB_COMBO && b->desc->flat)
        kinds[nkinds++] = JOB_FLAT;
    if (kind == JOB_COMBO || kind == JOB_UBER)
        kinds[nkinds++] = kind == JOB_COMBO ? JOB_COMBO_COMPUTE : JOB_UBER_COMPUTE;
    if (kind == JOB_COMBO && splat_ug_in(&b->ug, materials, n))
        kinds[nkinds++] = JOB_COMBO_UG;
    for (int pass = 0; pass < nkinds; pass++) {
        job_kind k = kinds[pass];
        bool compute = k == JOB_COMBO_COMPUTE || k == JOB_UBER_COMPUTE || k == JOB_COMBO_UG;
        char *file;
        if (k == JOB_COMBO_UG)
            file = xasprintf("shaders/%04d.ug.comp", index);
        else if (k == JOB_REF)
            file = xasprintf("shaders/ref_%04d", index);
        else if (k == JOB_UBER || k == JOB_UBER_COMPUTE)
            file = xasprintf(compute ? "shaders/uber.comp" : "shaders/uber");
        else
            file = xasprintf(k == JOB_FLAT ? "shaders/flat_%04d"
                             : compute     ? "shaders/%04d.comp" : "shaders/%04d", index);
        job *j = job_add(b, k, index, file, compute ? SPV_STAGE_COMPUTE : SPV_STAGE_FRAGMENT);
        j->glsl_only = compute && b->desc->glsl_compute;
        if (k == JOB_REF)
            snprintf(j->title, sizeof j->title, "multi-pass reference pass of material %d",
                     index);
        else if (k == JOB_UBER || k == JOB_UBER_COMPUTE)
            snprintf(j->title, sizeof j->title, "über-shader: every material of the scene%s",
                     compute ? " (compute)" : "");
        else
            snprintf(j->title, sizeof j->title, "composite of combination %d%s", index,
                     k == JOB_FLAT ? " (flat: no branches)" :
                     k == JOB_COMBO_UG ? " (undergrowth masks)" : compute ? " (compute)" : "");
        /* The MASK debug view recomputes every layer's mask: only the
         * über-shader carries it (the runtime draws that view with it),
         * which keeps each composite about half as long for glslang. */
        j->composite = c;
        j->gdesc = (splat_glsl_desc){.flat = k == JOB_FLAT, .painted_sparse = b->sparse_ok,
                                     .painted_places = b->painted_places,
                                     .no_mask_view = k != JOB_UBER && k != JOB_UBER_COMPUTE,
                                     .compute = compute, .no_lazy = b->desc->no_lazy,
                                     .ug_slot = k == JOB_COMBO_UG ? b->ug.slot_of : NULL};
    }
    if (info) {
        info->ntextures = c->ntextures;
        info->textures = xcalloc((size_t)c->ntextures, sizeof *info->textures);
        memcpy(info->textures, c->textures, (size_t)c->ntextures * sizeof *c->textures);
        info->nparams = c->nparams;
        info->params = xcalloc((size_t)c->nparams, sizeof *info->params);
        memcpy(info->params, c->params, (size_t)c->nparams * sizeof *c->params);
        info->cost = splat_composite_cost(c);
        if (kind == JOB_COMBO && !b->desc->no_dclasses)
            add_classes(b, index, c, info);
    }
    return true;
}

static void composites_free(build *b)
{
    for (int i = 0; i < b->ncomposites; i++) {
        splat_composite_free(b->composites[i]);
        free(b->composites[i]);
    }
    free(b->composites);
    b->composites = NULL;
    b->ncomposites = 0;
    for (int i = 0; i < b->njobs; i++)
        b->jobs[i].composite = NULL;
}

/* The stand-ins of the screen path (stand_in.h, PACK.md "Stand-ins"): the
 * über-shader's compute GLSL cut at the prelude around the flat main, and
 * the far atlas's main when the pack has an atlas; SPIR-V only (the
 * runtime makes the text itself from the über-shader's for the counting
 * variant), so with --glsl-compute none: the runtime compiles them. */
static void add_stand_ins(build *b)
{
    if (b->desc->glsl_compute)
        return;
    const job *uber = NULL;
    for (int i = 0; i < b->njobs && !uber; i++)
        if (b->jobs[i].kind == JOB_UBER_COMPUTE)
            uber = &b->jobs[i];
    if (!uber)
        return;
    char *text = xstrdup(uber->glsl.s);   /* job_add may move the jobs */
    for (int k = 0; k < SPLAT_STAND_IN_KINDS; k++) {
        if (k == SPLAT_STAND_IN_ATLAS && b->desc->far_atlas <= 0)
            continue;
        char *src = splat_stand_in_glsl((splat_stand_in_kind)k, text, "");
        if (!src)
            abort();   /* the über-shader's GLSL always holds the prelude */
        job *j = job_add(b, JOB_STAND_IN, k, xstrdup(splat_stand_in_file((splat_stand_in_kind)k)),
                         SPV_STAGE_COMPUTE);
        ir_buf_printf(&j->glsl, "%s", src);
        free(src);
        snprintf(j->title, sizeof j->title, "%s stand-in (compute)",
                 splat_stand_in_name((splat_stand_in_kind)k));
    }
    free(text);
}

bool build_compose(build *b)
{
    const splat_analysis *a = &b->analysis;
    int nm = b->scene.nmaterials;
    b->combos = xcalloc((size_t)a->ncombos, sizeof *b->combos);
    splat_progress pr;
    splat_progress_begin(&pr, "compose", a->ncombos + 1 + nm);
    bool ok = true;
    for (int i = 0; ok && i < a->ncombos; i++, splat_progress_step(&pr))
        ok = add_composite(b, JOB_COMBO, i, a->combos[i].materials, a->combos[i].nmaterials,
                           false, &b->combos[i]);
    int *all = xcalloc((size_t)nm, sizeof *all);
    for (int k = 0; k < nm; k++)
        all[k] = nm - 1 - k;
    ok = ok && add_composite(b, JOB_UBER, 0, all, nm, false, NULL);
    splat_progress_step(&pr);
    free(all);
    for (int k = 0; ok && k < nm; k++, splat_progress_step(&pr))
        ok = add_composite(b, JOB_REF, k, &k, 1, true, NULL);
    splat_progress_end(&pr);
    if (!ok)
        return false;
    /* the GLSL of every variant, on the pool (composing itself lowers the
     * compositor through the front end, which is single-threaded) */
    bool *pending = xcalloc((size_t)b->njobs, sizeof *pending);
    for (int i = 0; i < b->njobs; i++) {
        b->jobs[i].gdesc.title = b->jobs[i].title;
        b->jobs[i].gdesc.lazy_branches = &b->jobs[i].nlazy;
        pending[i] = b->jobs[i].composite != NULL;
    }
    run_pool(b, "glsl", emit_job, pending, b->desc->jobs);
    free(pending);
    composites_free(b);
    add_stand_ins(b);
    job *v = job_add(b, JOB_VERTEX, 0, xasprintf("shaders/terrain.vert"), SPV_STAGE_VERTEX);
    ir_buf_printf(&v->glsl, "%s", SPLAT_GLSL_VERTEX);
    for (int i = 0; i < b->njobs; i++)
        splat_shader_key(b->jobs[i].glsl.s, b->jobs[i].stage, b->jobs[i].key);
    return true;
}

/* ---- compile and validate ------------------------------------------------- */

bool build_compile(build *b)
{
    if (!b->desc->no_cache)
        splat_cache_open(&b->cache, b->desc->cache_dir);  /* disabled on failure */
    bool *pending = xcalloc((size_t)b->njobs, sizeof *pending);
    for (int i = 0; i < b->njobs; i++) {
        job *j = &b->jobs[i];
        /* not even a cache hit for GLSL-only jobs: same inputs, same pack */
        j->cached = !j->glsl_only &&
                    splat_cache_get(&b->cache, j->key, &j->words, &j->nwords);
        pending[i] = !j->cached && !j->glsl_only;
    }
    run_pool(b, "glslang+spirv-val", compile_job, pending, b->desc->jobs);
    free(pending);
    return true;
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

bool build_validate(build *b)
{
    splat_build_stats *st = b->st;
    bool ok = true;
    for (int i = 0; i < b->njobs; i++) {
        job *j = &b->jobs[i];
        if (j->glsl_only)
            continue;
        if (!j->words) {
            report_job_error(b, j);
            ok = false;
            continue;
        }
        if (!j->cached)
            splat_cache_put(&b->cache, j->key, j->words, j->nwords);
        st->shapes_known += j->shape_valid;
        bool combo = j->kind == JOB_COMBO;
        st->shaders++;
        st->combos += combo;
        st->lazy_branches += combo ? j->nlazy : 0;
        if (j->cached) {
            st->shaders_cached++;
            st->combos_cached += combo;
        } else {
            st->shaders_compiled++;
            st->combos_compiled += combo;
        }
    }
    return ok;
}

void build_jobs_free(build *b)
{
    composites_free(b);
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
    splat_cache_close(&b->cache);
}

