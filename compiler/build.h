/* build.h — `splatc build`'s internals, shared by its files (the public
 * entry point, splat_build, is in scene.h):
 *
 *   build.c         the pipeline in one function and its phases
 *   build_inputs.c  the input files, their key, the up-to-date check and
 *                   the depfile
 *   texture_mips.c  a texture's stored mip files
 *   build_jobs.c    the shaders to compile: composed per combination,
 *                   compiled on N threads, validated, cached (cache.c)
 *   build_report.c  --stats's report: each composite against the über-shader
 *   pack_write.c    the pack writer: manifest, files, the directory swap
 */
#ifndef SPLAT_BUILD_H
#define SPLAT_BUILD_H

#include "scene.h"
#include "undergrowth.h"
#include "util.h"

/* ---- shaders to compile (build_jobs.c) ----------------------------------- */

typedef enum job_kind {
    JOB_COMBO, JOB_FLAT, JOB_UBER, JOB_REF, JOB_VERTEX,
    JOB_COMBO_COMPUTE, JOB_UBER_COMPUTE,   /* abi.h "compute stage" */
    JOB_COMBO_UG,                          /* abi.h "undergrowth masks" */
    JOB_STAND_IN,                          /* a stand-in of the screen path
                                              (stand_in.h; index: its kind),
                                              SPIR-V only */
    JOB_CLASS, JOB_CLASS_COMPUTE,          /* a distance class of a combination
                                              (distance.c): fragment, compute */
} job_kind;

typedef struct job {
    job_kind  kind;
    int       index;          /* combination or material                   */
    int       dclass;         /* JOB_CLASS*: the class of combination index */
    char     *file;           /* "shaders/0003" (".frag" added for fragment
                                 shaders, ".spv" for the module)          */
    ir_buf    glsl;
    int       stage;          /* spv_stage                                 */
    char      key[SPLAT_KEY_CHARS + 1];
    uint32_t *words;
    size_t    nwords;
    bool      cached;         /* came from the cache (and validated)      */
    bool      shape_valid;    /* compiled, not validated: its shape passed
                                 spirv-val before (cache.h)               */
    bool      glsl_only;      /* a compute variant without --compute-spirv:
                                 GLSL written, not compiled                */
    const splat_composite *composite; /* its GLSL is written from this, on
                                 the pool (build_compose), with gdesc      */
    splat_glsl_desc gdesc;
    char      title[96];      /* gdesc.title                              */
    int       nlazy;          /* gdesc.lazy_branches: the lazy branches made */
    char     *log;            /* compile / validation failure             */
} job;

typedef struct combo_info {
    int *textures, ntextures; /* layout textures used                     */
    int *params, nparams;
    double cost;              /* splat_composite_cost                     */
    int    nclasses;          /* distance classes (distance.c)            */
    double dlo[SPLAT_MAX_DCLASSES], dhi[SPLAT_MAX_DCLASSES]; /* their intervals */
    double dcost[SPLAT_MAX_DCLASSES];                        /* their costs     */
} combo_info;

/* The far atlas as the pack stores it (far_atlas.h), when --far-atlas. */
typedef struct far_atlas_out {
    uint8_t *data;            /* the whole far.atlas file                 */
    size_t   n;
    int      width, height, levels;
    double   texel[2];        /* metres per level-0 texel, x and z        */
    double   seconds;         /* the bake's wall time                     */
    bool     pending;         /* for the device: build_write_pack bakes it */
    bool     on_device;       /* baked by desc->far_device                */
    char     cpu_why[256];    /* auto, baked on the CPU: why not a device */
} far_atlas_out;

typedef struct build {
    const splat_build_desc *desc;
    splat_build_stats *st;
    int            errors;    /* d->nerrors when the build started        */
    bool           failed;    /* a phase failed: the rest are skipped     */
    splat_scene    scene;
    bool           scene_ok;
    splat_analysis analysis;
    bool           analysis_ok;
    sparse_masks   sparse;    /* painted masks as stored (not dense)      */
    bool           sparse_ok;
    char          *painted_places; /* sparse_glsl_places, or NULL            */
    splat_layout   layout;
    bool           layout_ok;
    splat_ug       ug;        /* the undergrowth blocks and their meshes  */
    bool           ug_ok;
    combo_info    *combos;
    job           *jobs;
    int            njobs, capjobs;
    splat_composite **composites; /* the jobs' composites until their GLSL
                                 is written                               */
    int            ncomposites;
    splat_cache    cache;
    char           inputs[SPLAT_KEY_CHARS + 1]; /* key of every input file */
    sg_diags      *d;
    sg_loc         loc;       /* the scene file, for errors without a line */
    char          *out;       /* desc->out without trailing slashes        */
    far_atlas_out  far;       /* --far-atlas: far_atlas.c                 */
    const char    *old_pack;  /* the pack being replaced, or NULL: its files
                                 whose bytes this build would write again
                                 are linked, not written (pack_write.c)   */
    int            keep_zst;  /* 0: untried, 1: this libzstd remakes the old
                                 pack's frames byte for byte, -1: it does not */
} build;

/* Phases: each returns false on failure (with diagnostics in b->d). */
bool build_compose(build *b);    /* a job per shader, with its GLSL and key */
bool build_compile(build *b);    /* cache lookups, glslang on the misses    */
bool build_validate(build *b);   /* spirv-val on the compiled, cache puts   */
void build_jobs_free(build *b);

/* ---- the far atlas (far_atlas.c) ------------------------------------------ */

/* With desc->far_atlas > 0: bake every texel's composite into b->far,
 * on the CPU; with a device bake (desc->far_device, far_bake not CPU)
 * only mark it pending. */
bool build_far_atlas(build *b);
/* The pending device bake, from the pack written in `dir` (complete but
 * for the atlas); auto falls back to the CPU where the device cannot. */
bool build_far_atlas_device(build *b, const char *dir);
/* --stats: its size, density and bake time (nothing without an atlas). */
void build_report_far(const build *b, FILE *out);

/* ---- the inputs (build_inputs.c) ----------------------------------------- */

/* The key of everything the pack is made from (contents, not names or
 * times), into b->inputs; false if a file cannot be read ("": never up to
 * date). */
bool build_inputs_key(build *b);
/* Does the pack at b->out already hold what this build would write (same
 * key, every shader file there)?  On yes, *ncombos is its combination
 * count. */
bool build_up_to_date(build *b, int *ncombos);

/* --depfile (if given): "PACKDIR/manifest.json: every input", written
 * atomically.  build_write_pack calls it after the new pack is complete
 * and before the swap, so a depfile that cannot be written leaves the old
 * pack as it was; an up-to-date build writes it alone. */
bool build_write_depfile(build *b);

/* ---- the pack writer (pack_write.c) -------------------------------------- */

/* Write the pack into a temporary folder beside b->out, then the depfile,
 * then swap it in; on any failure the old pack (if any) stays as it was. */
bool build_write_pack(build *b);
/* Before any work: the output's parent folder exists and takes new
 * entries, and the output is absent, a folder or a pack (what
 * build_write_pack will refuse, it refuses first). */
bool build_check_out(build *b);

/* ---- a texture's mip files (texture_mips.c) ------------------------------- */

/* A texture's k-th mip file ("rock.mip1.png") and how many it has. */
char *build_mip_path(const char *path, int k);
int   build_mip_count(const char *src);

/* ---- the report (build_report.c) ----------------------------------------- */

void build_report_painted(build *b, FILE *out);
void build_report_shaders(build *b, FILE *out);
void build_report_shaders_from_pack(build *b, FILE *out);

#endif
